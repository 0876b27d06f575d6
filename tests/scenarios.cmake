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
