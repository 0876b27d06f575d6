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

  # One case of the matrix as a case file (--generate --case 15: N = 200,
  # 20 %, 1 px, its 64 records) timed from the file as an outside harness
  # would (--cases); --case with another mode refused.
  add_test(NAME bench_case_file
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --generate case15.bin --case 15 && $<TARGET_FILE:spvs-bench> --cases case15.bin --json --repeats 1 --warmup 1 | /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/bench/check_short.py --need spvs --records 64")
  set_tests_properties(bench_case_file PROPERTIES LABELS "bench" TIMEOUT 60)
  add_test(NAME bench_bad_case
    COMMAND sh -c "$<TARGET_FILE:spvs-bench> --short --case 15 2>err.txt; rc=$?; grep -q -- '--case goes with' err.txt && test $rc -eq 2")
  set_tests_properties(bench_bad_case PROPERTIES LABELS "bench" TIMEOUT 30)

  # The case file reader and writer: round trip, and bad files rejected.
  spvs_add_test(NAME test_bench_cases SOURCES test_bench_cases.c
                LIBS spvs_hombench LABELS bench TIMEOUT 60)
endif()
