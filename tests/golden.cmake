# Golden vectors (tools/gen_golden.py -> tests/golden/golden_vectors.h): the
# core's solver, refit and epipole against ground truth, in float and double.
spvs_add_test(NAME test_golden SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_golden.c LABELS unit TIMEOUT 60
              FLOAT_STAGES)
