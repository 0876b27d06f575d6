# Golden vectors (tools/gen_golden.py -> tests/golden/golden_vectors.h): the
# core's solver, refit and epipole against ground truth, in float and double.
spvs_add_test(NAME test_golden SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_golden.c LABELS unit TIMEOUT 60
              FLOAT_STAGES)

# The fixed-point core against the same vectors, with the integer checks
# the Cortex-M3 image of the fixed-point build runs (golden_check_q.h).
# In both builds: beside the float core, and as the core (SPVS_FIXED=ON).
spvs_add_test(NAME test_golden_fixed SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_golden_fixed.c
              LIBS spvs::fixed LABELS "unit;fixed" TIMEOUT 60)
