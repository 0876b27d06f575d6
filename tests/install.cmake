# The installed package (cmake/install.cmake, docs/INSTALL.md): the build is
# installed into a prefix of its own (install_stage, a ctest fixture), then
# the example consumer (examples/consumer) is built against it with
# find_package and with pkg-config, and from the source tree with
# FetchContent; the installed headers compile alone; consumers built with
# another configuration than the library's fail to link (spvs/abi.h).
if(SPVS_DOUBLE)
  set(install_scalar double)
else()
  set(install_scalar float)
endif()
if(SPVS_FIXED)
  set(install_scalar fixed_${install_scalar})
endif()
set(install_dir ${CMAKE_CURRENT_SOURCE_DIR}/install)
set(install_prefix ${CMAKE_CURRENT_BINARY_DIR}/install_stage/prefix)
set(install_env
    SPVS_SOURCE=${PROJECT_SOURCE_DIR} SPVS_BUILD=${PROJECT_BINARY_DIR}
    SPVS_VERSION=${PROJECT_VERSION} SPVS_SCALAR=${install_scalar}
    CMAKE=${CMAKE_COMMAND} SPVS_GENERATOR=${CMAKE_GENERATOR} CC=${CMAKE_C_COMPILER})

add_test(NAME install_stage COMMAND ${install_dir}/stage.sh ${install_prefix})
set_tests_properties(install_stage PROPERTIES FIXTURES_SETUP spvs_installed)

add_test(NAME install_consumer_cmake COMMAND ${install_dir}/consumer.sh cmake ${install_prefix})
add_test(NAME install_consumer_pkgconfig COMMAND ${install_dir}/consumer.sh pkgconfig ${install_prefix})
add_test(NAME install_headers_alone COMMAND ${install_dir}/headers.sh ${install_prefix})
add_test(NAME install_abi_mismatch_matches COMMAND ${install_dir}/abi_mismatch.sh matches ${install_prefix})
set_tests_properties(install_consumer_cmake install_consumer_pkgconfig install_headers_alone
                     install_abi_mismatch_matches PROPERTIES FIXTURES_REQUIRED spvs_installed)

# These build the core again in folders of their own.
add_test(NAME install_consumer_fetchcontent COMMAND ${install_dir}/consumer.sh fetch)
add_test(NAME install_abi_mismatch_scalar COMMAND ${install_dir}/abi_mismatch.sh scalar)
add_test(NAME install_cortex_m4f COMMAND ${install_dir}/cortex_m4f.sh)
set_tests_properties(install_cortex_m4f PROPERTIES SKIP_RETURN_CODE 77)

set_tests_properties(install_stage install_consumer_cmake install_consumer_pkgconfig
                     install_headers_alone install_abi_mismatch_matches
                     install_consumer_fetchcontent install_abi_mismatch_scalar install_cortex_m4f
                     PROPERTIES LABELS "${install_scalar};install" TIMEOUT 300
                     ENVIRONMENT "${install_env}")

# Python: the documented lcm-gen -p and examples/python/decode_log.py.
if(TARGET spvs-node AND TARGET spvs-sim)
  add_test(NAME install_python_decode
           COMMAND ${install_dir}/python_decode.sh $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>)
  set_tests_properties(install_python_decode PROPERTIES LABELS "${install_scalar};install;lcm;process"
                       TIMEOUT 120 ENVIRONMENT "${install_env}")
endif()
