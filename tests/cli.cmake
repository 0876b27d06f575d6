# The edge written once (sim/cli.h, sim/link_lockstep.h): the command-line
# helper's parsing (unit), the lock-step exchange of the links (unit), and
# the refusal of bad options by each program that uses the helper (cli):
# exit status 2 and one line on stderr that names the option.  spvs-sim's
# own refusals are in tests/sim.cmake.
spvs_add_test(NAME test_cli SOURCES test_cli.c LIBS spvs_cli LABELS unit cli TIMEOUT 60)
if(TARGET spvs_link_lockstep)
  spvs_add_test(NAME test_lockstep SOURCES test_lockstep.c LIBS spvs_link_lockstep
                LABELS unit lcm TIMEOUT 60)
endif()

set(cli_check /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_refused.py)

# cli_refused(NAME PROGRAM TARGET SAYS ARGS...): TARGET run with ARGS is
# refused with a line from PROGRAM that holds SAYS.
function(cli_refused name program target says)
  add_test(NAME cli_bad_${name}
           COMMAND ${cli_check} ${program} ${says} -- $<TARGET_FILE:${target}> ${ARGN})
  set_tests_properties(cli_bad_${name} PROPERTIES LABELS "${spvs_variant};cli" TIMEOUT 60)
endfunction()

# spvs-node: options and parameters, refused before LCM is opened.
if(TARGET spvs-node)
  cli_refused(node_method spvs-node spvs-node "--method: '4' is not an integer in 1..3"
              --method 4)
  cli_refused(node_watchdog spvs-node spvs-node "--watchdog: '0' is not a number in (0, 3600]"
              --watchdog 0)
  cli_refused(node_progress spvs-node spvs-node "--progress: '-1'" --progress -1)
  cli_refused(node_gain_junk spvs-node spvs-node "k_w: '0.5x' is not a finite number"
              --k-w 0.5x)
  cli_refused(node_param_overflow spvs-node spvs-node
              "max_iters: '4294967296' is not an integer in 0..4294967295"
              --param max_iters=4294967296)
  cli_refused(node_unknown spvs-node spvs-node "unknown option: --bogus" --bogus 1)
endif()

# spvs-lcm-faults (tools/lcm_faults, added by tests/robustness.cmake when
# the LCM parts are built).
if(TARGET spvs_node_lib AND TARGET spvs-sim)
  cli_refused(faults_drop spvs-lcm-faults spvs-lcm-faults "--drop: '2' is not a number in [0, 1]"
              --drop 2)
  cli_refused(faults_seed spvs-lcm-faults spvs-lcm-faults "--seed: '1.5' is not an integer"
              --seed 1.5)
  cli_refused(faults_period spvs-lcm-faults spvs-lcm-faults
              "--period: '0.0001' is not a number in [0.001, 60]" --period 0.0001)
  cli_refused(faults_same_channel spvs-lcm-faults spvs-lcm-faults "--in and --out must differ"
              --in A --out A)
endif()

# The bench programs (tools/bench, with OpenCV).
if(EXISTS ${PROJECT_SOURCE_DIR}/tools/bench/CMakeLists.txt AND NOT SPVS_FIXED)
  cli_refused(bench_n spvs-bench spvs-bench "--n: '3' is not an integer in 4.." --short --n 3)
  cli_refused(bench_sigma spvs-bench spvs-bench "--sigma: '1e999'" --short --sigma 1e999)
  cli_refused(homing_method spvs-bench-homing spvs-bench-homing
              "--method: '2.5' is not an integer in 1..3" --method 2.5)
  cli_refused(homing_outliers spvs-bench-homing spvs-bench-homing
              "--outliers: '0.95' is not a number in [0, 0.9]" --outliers 0.95)
endif()
