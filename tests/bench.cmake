# The benchmark's short mode in CI, so that it cannot rot: one case (N = 200,
# 20 % mismatches, 1 px noise), few repeats, every estimator; the checker
# asserts that the output parses, says how it was timed, and that ours
# succeeds on every estimate with a mean corner transfer error under 2 px.
# The full run is a documented command (docs/BENCHMARKS.md), not a test.
if(EXISTS ${PROJECT_SOURCE_DIR}/tools/bench/CMakeLists.txt AND NOT SPVS_FIXED)
  set(spvs_bench_check "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/bench/check_short.py")

  # Each test runs in a scratch directory of its own, made afresh
  # (bench_work/NAME in the build tree), so that no two tests share a file
  # under `ctest -j`.
  set(spvs_bench_work ${CMAKE_CURRENT_BINARY_DIR}/bench_work)
  # SCRIPT run by bash in that directory (one quoted argument, so that its
  # semicolons stay shell syntax, not CMake list separators), with
  # pipefail: in `spvs-bench ... | check_short.py` a failing spvs-bench
  # fails the test, whatever the checker makes of its output.
  function(spvs_bench_add name script)
    add_test(NAME ${name}
      COMMAND /bin/bash -c "set -o pipefail; d=${spvs_bench_work}/${name}; rm -rf \"$d\" && mkdir -p \"$d\" && cd \"$d\" && ${script}")
  endfunction()

  # `spvs-bench RUN | check_short.py CHECK`.
  function(spvs_bench_test name run check timeout)
    spvs_bench_add(${name} "$<TARGET_FILE:spvs-bench> ${run} | ${spvs_bench_check} ${check}")
    set_tests_properties(${name} PROPERTIES LABELS "bench" TIMEOUT ${timeout})
  endfunction()

  # `spvs-bench ARGS` refused with status 2 and a message holding SAYS.
  function(spvs_bench_refuses name args says)
    spvs_bench_add(${name}
      "$<TARGET_FILE:spvs-bench> ${args} 2>err.txt; rc=$?; grep -q -- \"${says}\" err.txt && test $rc -eq 2")
    set_tests_properties(${name} PROPERTIES LABELS "bench" TIMEOUT 30)
  endfunction()

  spvs_bench_test(bench_short "--short" "" 60)
  # Each estimator's repeats back to back (--order blocks); every estimate
  # after one frame's feature extraction (--between frame).
  spvs_bench_test(bench_short_blocks "--short --order blocks" "--order blocks" 60)
  spvs_bench_test(bench_short_frame "--short --between frame" "--between frame" 120)
  # One case of the matrix as a case file (--generate --case 15: N = 200,
  # 20 %, 1 px, its 64 records) timed from the file as an outside harness
  # would (--cases).
  spvs_bench_test(bench_case_file
    "--generate case15.bin --case 15 && $<TARGET_FILE:spvs-bench> --cases case15.bin --json --repeats 1 --warmup 1"
    "--need spvs --records 64" 60)
  # A grazing case (63: N = 200, 20 %, 1 px, the goal image's centre 60-100
  # deg off the optical axis) through the same workflow: one instance is its
  # 48 poses (8 angles at each of the six Figure 5 starts), every line says
  # it is of the grazing family and carries both corner errors; and ours
  # keeps what it measures on those 48 seeded estimates: the success rate,
  # the mean corner error in the current image and the median in the target
  # image, each bound just beyond the measured figure (docs/TESTING.md).
  spvs_bench_test(bench_case_file_grazing
    "--generate case63.bin --case 63 --instances 1 && $<TARGET_FILE:spvs-bench> --cases case63.bin --json --repeats 1 --warmup 1 --estimators spvs,cv_usac_default,cv_usac_magsac"
    "--family grazing --need spvs,cv_usac_default,cv_usac_magsac --records 48 --min-success 0.04 --max-err 10 --max-err-tgt 0.5" 120)

  # Bad values, each named in the message.
  spvs_bench_refuses(bench_bad_order "--short --order sideways" "'sideways'")
  spvs_bench_refuses(bench_bad_between "--short --between lunch" "'lunch'")
  spvs_bench_refuses(bench_bad_case "--short --case 15" "--case goes with")
  spvs_bench_refuses(bench_bad_family "--full --family sideways" "'sideways'")
  spvs_bench_refuses(bench_bad_case_family "--generate x.bin --case 15 --family grazing"
                     "outside --family")

  # The rules of the every-cell accuracy table (tools/bench/accuracy.py):
  # the best OpenCV estimator, when ours is behind, the doc block rewritten
  # in place, on made-up cells.
  spvs_bench_add(bench_accuracy_rules
    "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/bench/test_accuracy.py .")
  set_tests_properties(bench_accuracy_rules PROPERTIES LABELS "bench" TIMEOUT 30)

  # The case file reader and writer: round trip, and bad files rejected.
  spvs_add_test(NAME test_bench_cases SOURCES test_bench_cases.c
                LIBS spvs_hombench LABELS bench TIMEOUT 60)
endif()
