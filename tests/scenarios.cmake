# Section 5 of the paper as closed-loop scenarios (issue 5): Figure 5 poses,
# Method I's false zero, Table 1, 1 px noise from six poses, odometry drift,
# calibration.  In-process link; about a minute on 2 cores.
# tools/experiments.py runs the full-size experiments for docs/RESULTS.md.
# test_scenarios_fixed runs the same scenarios, with the same limits, on the
# fixed-point core (docs/FIXED.md).
if(TARGET spvs_sim)
  spvs_add_test(NAME test_scenarios SOURCES test_scenarios.c LIBS spvs_sim
                LABELS scenario TIMEOUT 240)
  if(NOT SPVS_FIXED)
    spvs_add_test(NAME test_scenarios_fixed SOURCES test_scenarios.c LIBS spvs_sim
                  LABELS "scenario;fixed" TIMEOUT 240)
    target_compile_definitions(test_scenarios_fixed PRIVATE SPVS_TEST_FIXED=1)
  endif()
endif()

# tools/experiments.py's arrival check (--arrival, --seed0) on a stand-in
# for spvs-sim with known results: the seeds it runs, the counts of its
# table and its exit status.
add_test(NAME experiments_arrival_check
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_experiments_arrival.py
                 ${PROJECT_SOURCE_DIR}/tools/experiments.py)
set_tests_properties(experiments_arrival_check PROPERTIES LABELS "unit;cli" TIMEOUT 120)
