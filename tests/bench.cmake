# The benchmark's short mode in CI, so that it cannot rot: one case (N = 200,
# 20 % mismatches, 1 px noise), few repeats, every estimator; the checker
# asserts that the output parses and that ours succeeds on every estimate
# with a mean corner transfer error under 2 px.  The full run is a documented
# command (docs/BENCHMARKS.md), not a test.
if(EXISTS ${PROJECT_SOURCE_DIR}/tools/bench/CMakeLists.txt)
  add_test(NAME bench_short
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --short | /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/bench/check_short.py")
  set_tests_properties(bench_short PROPERTIES LABELS "bench" TIMEOUT 60)
  # The same with each estimator's repeats back to back (--order blocks), and
  # a bad --order value refused with status 2 and a message naming it.
  add_test(NAME bench_short_blocks
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --short --order blocks | /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/bench/check_short.py --order blocks")
  set_tests_properties(bench_short_blocks PROPERTIES LABELS "bench" TIMEOUT 60)
  # Every estimate after one frame's feature extraction (--between frame),
  # and a bad --between value refused like a bad --order.
  add_test(NAME bench_short_frame
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --short --between frame | /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/bench/check_short.py --between frame")
  set_tests_properties(bench_short_frame PROPERTIES LABELS "bench" TIMEOUT 120)
  add_test(NAME bench_bad_between
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --short --between lunch 2>err.txt; rc=$?; grep -q \"'lunch'\" err.txt && test $rc -eq 2")
  set_tests_properties(bench_bad_between PROPERTIES LABELS "bench" TIMEOUT 30)
  add_test(NAME bench_bad_order
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --short --order sideways 2>err.txt; rc=$?; grep -q \"'sideways'\" err.txt && test $rc -eq 2")
  set_tests_properties(bench_bad_order PROPERTIES LABELS "bench" TIMEOUT 30)

  # The case file reader and writer: round trip, and bad files rejected.
  spvs_add_test(NAME test_bench_cases SOURCES test_bench_cases.c
                LIBS spvs_hombench LABELS bench TIMEOUT 60)
endif()
