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
                     -DCHECK=${PROJECT_SOURCE_DIR}/firmware/check_symbols.cmake
                     -P ${PROJECT_SOURCE_DIR}/firmware/check_fixed_m3.cmake)
    set_tests_properties(fixed_m3_no_float_${dbl} PROPERTIES LABELS "unit;fixed" TIMEOUT 60)
  endforeach()
endif()

# The per-frame comparison of the fixed-point update with the M4F's
# (tools/fixed_m3_bench/spread_ratio.py) on made-up runs.
add_test(NAME fixed_spread_ratio
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/fixed_m3_bench/test_spread_ratio.py
                 ${CMAKE_CURRENT_BINARY_DIR}/fixed_spread_ratio)
set_tests_properties(fixed_spread_ratio PROPERTIES LABELS "unit;fixed" TIMEOUT 30)
