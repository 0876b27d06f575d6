# The core's unit tests in Unity (tests/unit/, cmake/unity.cmake): one
# program per test file on the host, in every variant (float, double,
# fixed); the same sources run on the emulated Cortex-M4F and Cortex-M3
# (target/unity.cmake, tests/unity_target.cmake).  A run passes when it
# ends with Unity's summary "N Tests 0 Failures 0 Ignored" (N > 0) and no
# test reported FAIL.  Label unity.
include(${PROJECT_SOURCE_DIR}/cmake/unity.cmake)
spvs_unity_library(spvs_unity)
include(${PROJECT_SOURCE_DIR}/tests/support/support.cmake)

set(SPVS_UNITY_PASS_REGEX "[1-9][0-9]* Tests 0 Failures 0 Ignored")
set(SPVS_UNITY_FAIL_REGEX ":FAIL;[1-9][0-9]* Failures;[1-9][0-9]* Ignored")

# spvs_unity_test(NAME name SOURCES a.c ... [LIBS ...] [LABELS ...]
#                 [TIMEOUT s] [DEFINES ...] [FLOAT_STAGES])
# FLOAT_STAGES: a test of the float stages (or of a Q stage against its
# float twin), not in the fixed-point build, whose core has no float stage.
function(spvs_unity_test)
  cmake_parse_arguments(T "FLOAT_STAGES" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS;DEFINES" ${ARGN})
  if(SPVS_FIXED AND T_FLOAT_STAGES)
    return()
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_include_directories(${T_NAME} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}
                             ${PROJECT_SOURCE_DIR}/firmware/src)
  target_compile_definitions(${T_NAME} PRIVATE ${T_DEFINES})
  target_link_libraries(${T_NAME} PRIVATE spvs::core ${T_LIBS} spvs_test_support spvs_unity m)
  target_compile_options(${T_NAME} PRIVATE -Wall -Wextra)
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  set_tests_properties(${T_NAME} PROPERTIES LABELS "${spvs_variant};unity;unit;${T_LABELS}"
                       TIMEOUT ${T_TIMEOUT}
                       PASS_REGULAR_EXPRESSION "${SPVS_UNITY_PASS_REGEX}"
                       FAIL_REGULAR_EXPRESSION "${SPVS_UNITY_FAIL_REGEX}")
endfunction()

set(spvs_unit_dir ${CMAKE_CURRENT_SOURCE_DIR}/unit)

# The float core's stages, one file per module: the 3-point solver and
# refit (homography), RANSAC, the epipole, the control law, the pipeline
# (spvs), and the golden vectors of tools/gen_golden.py.
foreach(module homography:300 ransac:300 epipole:300 control:300 spvs:300 golden:60)
  string(REPLACE ":" ";" module ${module})
  list(GET module 0 name)
  list(GET module 1 seconds)
  spvs_unity_test(NAME test_${name} SOURCES ${spvs_unit_dir}/test_${name}.c
                  TIMEOUT ${seconds} FLOAT_STAGES)
endforeach()

# The fixed-point arithmetic and the Q-format stages (firmware/src/fixed,
# docs/FIXED.md) against exact and double references and their float
# twins (FLOAT_STAGES):
#   q        the arithmetic (q.h) and the per-point kernels (points_q.c)
#   solve3   the 3-point solver (solve3_q.c)
#   fit      the linear fits' solves (fit_q.c)
#   ransac   RANSAC on Q models (ransac_q.c) and its stopping rule
#   plane_h  the robust planar-motion H (plane_h_q.c) and spvs_q_estimate_h
#   conv     Q values to the public API's float and double bits (q.h)
#   epipole  the off-plane candidates and the epipole (offplane_q.c,
#            epipole_q.c)
#   control  the control law (control_q.c)
foreach(case q:120 solve3:120 fit:120 ransac:120 plane_h:120 conv:60 epipole:120 control:120)
  string(REPLACE ":" ";" case ${case})
  list(GET case 0 stage)
  list(GET case 1 seconds)
  spvs_unity_test(NAME test_fixed_${stage} SOURCES ${spvs_unit_dir}/test_fixed_${stage}.c
                  LIBS spvs::fixed LABELS fixed TIMEOUT ${seconds} FLOAT_STAGES)
endforeach()

# The fixed-point accelerators (firmware/src/fixed/accel) against the
# reference path compiled into the test: the loader's store and the inlier
# count bit for bit, the cost and the sums within stated bounds, the
# off-plane test bit for bit.  Only where the accelerators are built.
if(SPVS_ACCEL)
  spvs_unity_test(NAME test_fixed_accel SOURCES ${spvs_unit_dir}/test_fixed_accel.c
                  LIBS spvs::fixed LABELS fixed TIMEOUT 120 FLOAT_STAGES)
endif()

# In both builds, beside the float core and as the core (SPVS_FIXED=ON):
# the fixed-point core against the golden vectors with the integer checks
# of golden_check_q.h, and the fixed-point pipeline's spvs_update_with_h
# and spvs_inlier_px (in the float build also against the float core).
spvs_unity_test(NAME test_golden_fixed SOURCES ${spvs_unit_dir}/test_golden_fixed.c
                LIBS spvs::fixed LABELS fixed TIMEOUT 60)
spvs_unity_test(NAME test_fixed_spvs SOURCES ${spvs_unit_dir}/test_fixed_spvs.c
                LIBS spvs::fixed LABELS fixed TIMEOUT 300)

# The harness itself: test_golden built with SPVS_UNIT_SELF_FAIL, which
# makes one of its assertions fail on purpose.  Judged by the same
# expressions as every Unity run, it must fail (WILL_FAIL), and it must
# say "1 Failures" (unity_self_fail_count).
if(NOT SPVS_FIXED)
  spvs_unity_test(NAME unity_self_fail SOURCES ${spvs_unit_dir}/test_golden.c
                  DEFINES SPVS_UNIT_SELF_FAIL=1 TIMEOUT 60)
  set_tests_properties(unity_self_fail PROPERTIES WILL_FAIL TRUE)
  add_test(NAME unity_self_fail_count COMMAND unity_self_fail)
  set_tests_properties(unity_self_fail_count PROPERTIES
                       LABELS "${spvs_variant};unity;unit" TIMEOUT 60
                       PASS_REGULAR_EXPRESSION "\n4 Tests 1 Failures 0 Ignored")
endif()
if(SPVS_FIXED)
  spvs_unity_test(NAME unity_self_fail SOURCES ${spvs_unit_dir}/test_golden_fixed.c
                  LIBS spvs::fixed DEFINES SPVS_UNIT_SELF_FAIL=1 TIMEOUT 60)
  set_tests_properties(unity_self_fail PROPERTIES WILL_FAIL TRUE)
  add_test(NAME unity_self_fail_count COMMAND unity_self_fail)
  set_tests_properties(unity_self_fail_count PROPERTIES
                       LABELS "${spvs_variant};unity;unit" TIMEOUT 60
                       PASS_REGULAR_EXPRESSION "\n3 Tests 1 Failures 0 Ignored")
endif()
