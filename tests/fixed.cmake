# The fixed-point arithmetic and the Q-format kernels (firmware/src/fixed,
# docs/FIXED.md): against exact and double references and the float
# kernels, on random scenes and the golden vectors.
# (The float build only: the fixed-point build has no float twin.)
if(NOT SPVS_FIXED)
  spvs_add_test(NAME test_fixed_q SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_q.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_q PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)

  # The 3-point solver in Q format (solve3_q.c).
  spvs_add_test(NAME test_fixed_solve3 SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_solve3.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_solve3 PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)

  # The linear fits' solves in Q format (fit_q.c): the two-stage linear fit
  # and the joint fit's equilibrated Cholesky.
  spvs_add_test(NAME test_fixed_fit SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_fit.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_fit PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)

  # RANSAC on Q models (ransac_q.c) and its stopping rule in integers.
  spvs_add_test(NAME test_fixed_ransac SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_ransac.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_ransac PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)

  # The robust planar-motion H in fixed point (plane_h_q.c) against the
  # float estimator on the same frames.
  spvs_add_test(NAME test_fixed_plane_h SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_plane_h.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_plane_h PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)

  # Q values to the public API's float and double bits (q.h).
  spvs_add_test(NAME test_fixed_conv SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_conv.c
                LIBS spvs::fixed LABELS unit TIMEOUT 60)
  target_include_directories(test_fixed_conv PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)

  # The off-plane candidates, the epipole (offplane_q.c, epipole_q.c) and the
  # control law (control_q.c) in fixed point against the float stages.
  spvs_add_test(NAME test_fixed_epipole SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_epipole.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_epipole PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)
  spvs_add_test(NAME test_fixed_control SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fixed_control.c
                LIBS spvs::fixed LABELS unit TIMEOUT 120)
  target_include_directories(test_fixed_control PRIVATE ${PROJECT_SOURCE_DIR}/firmware/src)
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
