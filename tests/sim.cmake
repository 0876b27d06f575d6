# Simulator tests: the sim library (unit), closed loops through the
# in-process link (closedloop) and the spvs-sim command line (cli).
spvs_add_test(NAME test_sim SOURCES test_sim.c LIBS spvs_sim LABELS unit)
# The robot's latency and acceleration limits (sim_host/src/actuator.c).
spvs_add_test(NAME test_actuator SOURCES test_actuator.c LIBS spvs_sim LABELS unit)
spvs_add_test(NAME test_closed_loop SOURCES test_closed_loop.c LIBS spvs_sim
              LABELS closedloop TIMEOUT 120)
# The same closed loops on the fixed-point core (docs/FIXED.md), beside the
# float core.  (In the fixed-point build, test_closed_loop itself runs it.)
if(NOT SPVS_FIXED)
  spvs_add_test(NAME test_closed_loop_fixed SOURCES test_closed_loop.c LIBS spvs_sim
                LABELS "closedloop;fixed" TIMEOUT 120)
  target_compile_definitions(test_closed_loop_fixed PRIVATE SPVS_TEST_FIXED=1)
endif()

# The command line contract of spvs-sim, checked by a small script.
set(sim_cli_check /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_sim_cli.py)
add_test(NAME sim_cli_json
         COMMAND ${sim_cli_check} json -- $<TARGET_FILE:spvs-sim>
                 --method 3 --pose -3,-10,-30 --json)
add_test(NAME sim_cli_help
         COMMAND ${sim_cli_check} help -- $<TARGET_FILE:spvs-sim> --help)
add_test(NAME sim_cli_files
         COMMAND ${sim_cli_check} files -- $<TARGET_FILE:spvs-sim> --method 2
                 --json --quiet --trace ${CMAKE_CURRENT_BINARY_DIR}/sim_cli_trace.csv
                 --record ${CMAKE_CURRENT_BINARY_DIR}/sim_cli_record.bin)
# Bad options: exit 2 and exactly one line on stderr.
set(sim_cli_bad
  "method_7|--method|7"
  "noise_negative|--noise|-1"
  "outliers_one|--outliers|1"
  "distance_zero|--distance|0"
  "focal_negative|--focal-mm|-6"
  "normal_zero|--normal|0,0,0"
  "pose_two_values|--pose|1,2"
  "pose_not_numbers|--pose|a,b,c"
  "seed_negative|--seed|-1"
  "unknown_option|--bogus"
  "missing_value|--noise"
  "plane_behind_camera|--normal|0,0,1"
  "transport_unknown|--transport|carrier-pigeon")
foreach(case IN LISTS sim_cli_bad)
  string(REPLACE "|" ";" case_args "${case}")
  list(POP_FRONT case_args case_name)
  add_test(NAME sim_cli_bad_${case_name}
           COMMAND ${sim_cli_check} usage -- $<TARGET_FILE:spvs-sim> ${case_args})
endforeach()
if(NOT TARGET spvs_zenoh_link)
  add_test(NAME sim_cli_bad_no_zenoh
           COMMAND ${sim_cli_check} usage -- $<TARGET_FILE:spvs-sim> --transport zenoh)
endif()
get_property(sim_cli_tests DIRECTORY PROPERTY TESTS)
list(FILTER sim_cli_tests INCLUDE REGEX "^sim_cli_")
set_tests_properties(${sim_cli_tests} PROPERTIES LABELS "${spvs_variant};cli" TIMEOUT 60)
# A vertical plane gives Method II no signal (paper, Table 1): the run still
# completes, exit 0, with status failed and the core's reason.
add_test(NAME sim_cli_failed_run_exits_0
         COMMAND ${sim_cli_check} failed -- $<TARGET_FILE:spvs-sim> --method 2
                 --normal 0,0,-1 --json --quiet)
set_tests_properties(sim_cli_failed_run_exits_0 PROPERTIES LABELS "${spvs_variant};cli" TIMEOUT 60)
# From the paper's start (0, -8, -40 deg) a 640 x 480 camera sees one
# match: the robot stands still until --max-time, and the timeout names
# the core's status.
add_test(NAME sim_cli_timeout_names_status
         COMMAND ${sim_cli_check} timeout -- $<TARGET_FILE:spvs-sim> --method 1
                 --pose 0,-8,-40 --clip --max-time 2 --json --quiet)
set_tests_properties(sim_cli_timeout_names_status PROPERTIES LABELS "${spvs_variant};cli" TIMEOUT 60)

# The same run in process and across LCM (spvs-node) gives the same result.
# Runs in a private network namespace with only loopback; skipped (77) where
# the machine cannot make one.
if(TARGET spvs-node AND TARGET spvs_lcm_link)
  foreach(method 1 2 3)
    add_test(NAME sim_lcm_matches_inproc_m${method}
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_sim_lcm.py
                     $<TARGET_FILE:spvs-sim> $<TARGET_FILE:spvs-node> ${method} 1 1)
    set_tests_properties(sim_lcm_matches_inproc_m${method} PROPERTIES
                         LABELS "${spvs_variant};lcm" TIMEOUT 240 SKIP_RETURN_CODE 77)
  endforeach()
endif()

# The fixed-point build's pipeline is the Q pipeline: spvs-sim in process
# (spvs_update) and --transport fixed (spvs_q_update) give the same runs.
if(SPVS_FIXED)
  add_test(NAME sim_fixed_build_is_q
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_fixed_build.py
                   $<TARGET_FILE:spvs-sim>)
  set_tests_properties(sim_fixed_build_is_q PROPERTIES LABELS "fixed;cli" TIMEOUT 120)
endif()
