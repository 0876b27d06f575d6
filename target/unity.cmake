# The core's Unity tests on the emulated MCU (included by
# target/CMakeLists.txt): the host's test sources of tests/unit/, built
# with SPVS_UNIT_TARGET, under one main (unit_main.c) that sends Unity's
# output through semihosting.  tests/unity_target.cmake runs them under
# QEMU and judges Unity's summary line.
#
#   spvs_unit.elf            the suites below
#   spvs_unit_self_fail.elf  test_golden.c with SPVS_UNIT_SELF_FAIL=1: one
#                            assertion fails on purpose, and the run must
#                            say "1 Failures"
#
# Suites: in the float build (the Cortex-M4F, and the Cortex-M3 with
# soft-float) the float stages' files (homography, ransac, epipole,
# control, spvs, golden), the fixed-point golden vectors (golden_fixed),
# and the Q stages whose files run in seconds (solve3, fit, plane_h,
# conv); in the fixed-point build (Cortex-M3) golden_fixed.  Host only:
#   fixed_q                its exact references compute in __int128, which
#                          the ARM compiler lacks;
#   fixed_spvs, fixed_control, fixed_epipole, fixed_ransac
#                          Q stages against their float twins over
#                          thousands of random frames, too slow under
#                          emulation for the suite's time (docs/TESTING.md);
# and three tests of the files that run here, each saying why in its
# suite (test_lin_fit, test_q_ieee_bits; test_q_ransac_same_decisions is
# in fixed_ransac).  The test images keep the board's memory map but not
# the product budgets of mps2_an386.ld: they hold the suites' code, scenes
# and references (unit.ld; docs/EMBEDDED.md gives their sizes).
#
# The images link the test sources' double arithmetic (their references)
# and Unity; they are not checked by check_image.cmake.
include(${PROJECT_SOURCE_DIR}/cmake/unity.cmake)
spvs_unity_library(spvs_unity_target DEFINES SPVS_UNIT_TARGET=1)
target_compile_options(spvs_unity_target PRIVATE -w)

set(spvs_unit_src ${PROJECT_SOURCE_DIR}/tests/unit)
if(SPVS_FIXED)
  set(spvs_unit_suites golden_fixed)
else()
  set(spvs_unit_suites homography ransac epipole control spvs golden golden_fixed
      fixed_solve3 fixed_fit fixed_plane_h fixed_conv)
endif()
set(SPVS_UNIT_LD ${CMAKE_CURRENT_SOURCE_DIR}/unit.ld)

function(spvs_unit_image name)
  cmake_parse_arguments(I "" "" "SUITES;DEFINES" ${ARGN})
  set(dir ${CMAKE_CURRENT_BINARY_DIR}/${name}_gen)
  set(list "")
  set(sources ${CMAKE_CURRENT_SOURCE_DIR}/unit_main.c)
  foreach(s IN LISTS I_SUITES)
    string(APPEND list "SPVS_UNIT_SUITE(${s})\n")
    list(APPEND sources ${spvs_unit_src}/test_${s}.c)
  endforeach()
  file(WRITE ${dir}/unit_suites.h.in "${list}")
  configure_file(${dir}/unit_suites.h.in ${dir}/unit_suites.h COPYONLY)
  add_executable(${name} ${sources})
  set_target_properties(${name} PROPERTIES SUFFIX .elf LINK_DEPENDS ${SPVS_UNIT_LD})
  target_include_directories(${name} PRIVATE ${dir} ${CMAKE_CURRENT_SOURCE_DIR}
                             ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/firmware/src)
  target_compile_definitions(${name} PRIVATE ${I_DEFINES}
                             SPVS_TARGET_CPU_NAME="${SPVS_CPU_NAME}")
  target_compile_options(${name} PRIVATE -ffp-contract=off -Wall -Wextra -Wno-unused-variable
                         -Wno-unused-but-set-variable -Wno-unused-function)
  target_link_libraries(${name} PRIVATE -Wl,--whole-archive spvs_board -Wl,--no-whole-archive
                        spvs_unity_target spvs_board_float spvs_test_support spvs::fixed spvs::core m)
  target_link_options(${name} PRIVATE -nostartfiles --specs=nano.specs
                      -T${SPVS_UNIT_LD} -Wl,-Map=$<TARGET_FILE_DIR:${name}>/${name}.map
                      -Wl,--print-memory-usage)
endfunction()

spvs_unit_image(spvs_unit SUITES ${spvs_unit_suites})
if(SPVS_FIXED)
  spvs_unit_image(spvs_unit_self_fail SUITES golden_fixed DEFINES SPVS_UNIT_SELF_FAIL=1)
else()
  spvs_unit_image(spvs_unit_self_fail SUITES golden DEFINES SPVS_UNIT_SELF_FAIL=1)
endif()
