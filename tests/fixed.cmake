# The fixed-point arithmetic and the Q-format kernels (firmware/src/fixed,
# docs/FIXED.md): against exact and double references and the float
# kernels, on random scenes and the golden vectors.  Each is a Q stage
# against its float twin (FLOAT_STAGES: not in the fixed-point build).
#   q        the arithmetic (q.h) and the per-point kernels (points_q.c)
#   solve3   the 3-point solver (solve3_q.c)
#   fit      the linear fits' solves (fit_q.c): the two-stage linear fit and
#            the joint fit's equilibrated Cholesky
#   ransac   RANSAC on Q models (ransac_q.c) and its stopping rule in integers
#   plane_h  the robust planar-motion H (plane_h_q.c) against the float
#            estimator on the same frames, and spvs_q_estimate_h
#   conv     Q values to the public API's float and double bits (q.h)
#   epipole  the off-plane candidates and the epipole (offplane_q.c,
#            epipole_q.c)
#   control  the control law (control_q.c)
foreach(case q:120 solve3:120 fit:120 ransac:120 plane_h:120 conv:60 epipole:120 control:120)
  string(REPLACE ":" ";" case ${case})
  list(GET case 0 stage)
  list(GET case 1 seconds)
  spvs_add_test(NAME test_fixed_${stage}
                SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_${stage}.c
                LIBS spvs::fixed LABELS unit TIMEOUT ${seconds} FLOAT_STAGES)
  if(TARGET test_fixed_${stage})
    target_include_directories(test_fixed_${stage} PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)
  endif()
endforeach()

# The fixed-point accelerators (firmware/src/fixed/accel) against the
# reference path compiled into the test: the loader's store and the inlier
# count bit for bit, the cost and the sums within stated bounds.  Only
# where the accelerators are built.
if(SPVS_ACCEL)
  spvs_add_test(NAME test_fixed_accel
                SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_accel.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120 FLOAT_STAGES)
  if(TARGET test_fixed_accel)
    target_include_directories(test_fixed_accel PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)
  endif()
endif()

# The kernels compiled for a Cortex-M3 (no FPU, soft-float ABI) with the
# core's warnings reference no floating-point helper, in both scalar
# builds of the core's headers (the loader reads a float's or a double's
# bits).
find_program(SPVS_ARM_GCC arm-none-eabi-gcc)
find_program(SPVS_ARM_NM arm-none-eabi-nm)
if(SPVS_ARM_GCC AND SPVS_ARM_NM)
  foreach(dbl 0 1)
    add_test(NAME fixed_m3_no_float_${dbl}
             COMMAND ${CMAKE_COMMAND} -DCC=${SPVS_ARM_GCC} -DNM=${SPVS_ARM_NM}
                     -DSRCDIR=${PROJECT_SOURCE_DIR}/firmware/src/fixed
                     -DINC=${PROJECT_SOURCE_DIR}/firmware/include
                     -DOBJDIR=${CMAKE_CURRENT_BINARY_DIR}/fixed_m3_${dbl} -DDOUBLE=${dbl}
                     -DCHECK=${PROJECT_SOURCE_DIR}/firmware/check_fixed_symbols.cmake
                     -P ${PROJECT_SOURCE_DIR}/firmware/check_fixed_m3.cmake)
    set_tests_properties(fixed_m3_no_float_${dbl} PROPERTIES LABELS "unit;fixed" TIMEOUT 60)
  endforeach()
endif()

# The fixed-point pipeline's spvs_update_with_h and spvs_inlier_px: the
# estimate read back and given again, bad H, the threshold; in the float
# build also against the float core's spvs_update_with_h on the same H.
# In both builds: beside the float core, and as the core (SPVS_FIXED=ON),
# where it runs through spvs.h's names.
spvs_add_test(NAME test_fixed_spvs SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_spvs.c
              LIBS spvs::fixed LABELS "unit;fixed" TIMEOUT 300)
if(TARGET test_fixed_spvs)
  target_include_directories(test_fixed_spvs PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)
endif()

# The per-frame comparison of the fixed-point update with the M4F's
# (tools/fixed_m3_bench/spread_ratio.py) on made-up runs.
add_test(NAME fixed_spread_ratio
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/fixed_m3_bench/test_spread_ratio.py
                 ${CMAKE_CURRENT_BINARY_DIR}/fixed_spread_ratio)
set_tests_properties(fixed_spread_ratio PROPERTIES LABELS "unit;fixed" TIMEOUT 30)
