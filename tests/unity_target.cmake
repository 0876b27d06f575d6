# The core's Unity tests on the emulated MCUs (target/unity.cmake): the
# images of each cross build of tests/target.cmake run under QEMU, judged
# by Unity's summary as on the host (tests/unit.cmake).  Names say the
# CPU: m4 (Cortex-M4F, mps2-an386), m3 (Cortex-M3, mps2-an385, the float
# core in soft-float), m3_fixed (the fixed-point build on the Cortex-M3).
# unity_self_fail_*: the image whose one assertion fails on purpose must
# fail under the same judgement, and say "1 Failures".
if(NOT SPVS_ARM_GCC OR NOT SPVS_QEMU_ARM OR SPVS_DOUBLE OR SPVS_SANITIZE)
  return()
endif()
set(spvs_unity_run ${CMAKE_CURRENT_SOURCE_DIR}/target/unity_run.sh)

# spvs_unity_target(SUFFIX CROSS_DIR FIXTURE SELF_FAIL_TESTS)
function(spvs_unity_target suffix cross fixture self_fail_tests)
  add_test(NAME unity_${suffix} COMMAND ${spvs_unity_run} ${cross} spvs_unit)
  add_test(NAME unity_self_fail_${suffix} COMMAND ${spvs_unity_run} ${cross} spvs_unit_self_fail)
  add_test(NAME unity_self_fail_count_${suffix}
           COMMAND ${spvs_unity_run} ${cross} spvs_unit_self_fail)
  set_tests_properties(unity_${suffix} unity_self_fail_${suffix} PROPERTIES
                       PASS_REGULAR_EXPRESSION "${SPVS_UNITY_PASS_REGEX}"
                       FAIL_REGULAR_EXPRESSION "${SPVS_UNITY_FAIL_REGEX};FAIL")
  set_tests_properties(unity_self_fail_${suffix} PROPERTIES WILL_FAIL TRUE)
  set_tests_properties(unity_self_fail_count_${suffix} PROPERTIES
                       PASS_REGULAR_EXPRESSION "\n${self_fail_tests} Tests 1 Failures 0 Ignored")
  set_tests_properties(unity_${suffix} unity_self_fail_${suffix} unity_self_fail_count_${suffix}
                       PROPERTIES LABELS "unity;target" TIMEOUT 660
                       FIXTURES_REQUIRED ${fixture})
endfunction()

spvs_unity_target(m3_fixed ${CMAKE_BINARY_DIR}/cortex-m3-fixed spvs_cross_m3_fixed 3)
if(NOT SPVS_FIXED)
  spvs_unity_target(m4 ${CMAKE_BINARY_DIR}/cortex-m4f spvs_cross 4)
  spvs_unity_target(m3 ${CMAKE_BINARY_DIR}/cortex-m3 spvs_cross_m3 4)
endif()
