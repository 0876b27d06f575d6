# spvs_t (spvs.h) is storage of SPVS_INSTANCE_BYTES (spvs_config.h): the
# core's state fits it in float, double and fixed point, with the sizing
# settings at their defaults and overridden (tests/check_instance_size.sh).
add_test(NAME instance_size
         COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/check_instance_size.sh ${PROJECT_SOURCE_DIR}
                 ${CMAKE_C_COMPILER})
set_tests_properties(instance_size PROPERTIES LABELS "${spvs_variant};unit" TIMEOUT 60)
