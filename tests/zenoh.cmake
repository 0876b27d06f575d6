# The Zenoh interface (docs/ZENOH.md): spvs-sim over Zenoh, spvs-zenoh-bridge,
# spvs-node over LCM.  Each check runs inside a network namespace with only
# loopback (tests/zenoh/netns.sh) with the venv's Python; the venv is made
# (or found ready) by the zenoh_venv fixture, which needs PyPI only once.
if(NOT TARGET spvs_zenoh_link OR NOT TARGET spvs-node)
  return()
endif()

if(SPVS_DOUBLE)
  # Matches travel as float32, so a double build's run over Zenoh differs
  # from the in-process one by that rounding (as over LCM, tests/lcm.cmake).
  set(zenoh_tol --tol-m 1e-3 --tol-deg 1e-2)
else()
  # float build: the wire carries exactly what the core computes with, so
  # the runs must be identical.
  set(zenoh_tol --tol-m 0 --tol-deg 0)
endif()
set(zenoh_root ${PROJECT_SOURCE_DIR})
set(zenoh_run sh ${CMAKE_CURRENT_SOURCE_DIR}/zenoh/netns.sh ${zenoh_root})
set(zenoh_check ${zenoh_root}/.venv/bin/python
    ${CMAKE_CURRENT_SOURCE_DIR}/zenoh/check_zenoh.py)
set(zenoh_dirs --build ${CMAKE_BINARY_DIR} --root ${zenoh_root} ${zenoh_tol})

add_test(NAME zenoh_venv COMMAND ${zenoh_root}/scripts/setup_venv.sh)
set_tests_properties(zenoh_venv PROPERTIES FIXTURES_SETUP zenoh_venv
                     LABELS "${spvs_variant};zenoh" TIMEOUT 600)

# name | seconds | check and its options
set(zenoh_cases
  "zenoh_loop_m3_seed3|120|loop --method 3 --seed 3"
  "zenoh_loop_m1_seed5_noise|120|loop --method 1 --seed 5 --noise 0.5"
  "zenoh_loop_m2_seed7|120|loop --method 2 --seed 7"
  "zenoh_bridge_restart|150|restart --method 3 --seed 3"
  "zenoh_bad_payloads|120|bad"
  "zenoh_cli|150|cli")
foreach(case IN LISTS zenoh_cases)
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 seconds)
  list(GET parts 2 args)
  separate_arguments(args UNIX_COMMAND "${args}")
  add_test(NAME ${name}
           COMMAND ${zenoh_run} ${seconds} ${zenoh_check} ${args} ${zenoh_dirs})
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED zenoh_venv
                       LABELS "${spvs_variant};zenoh" TIMEOUT ${seconds}
                       SKIP_RETURN_CODE 77)
endforeach()

# spvs-fleet and spvs-station (docs/ZENOH.md, "A fleet"): robots through one
# Zenoh router, each fleet with its own free port, work folder and LCM
# namespace (tests/zenoh/check_fleet.py).
set(fleet_check ${zenoh_root}/.venv/bin/python
    ${CMAKE_CURRENT_SOURCE_DIR}/zenoh/check_fleet.py)
# name | seconds | check and its options
set(fleet_cases
  "fleet_equal_4|240|equal --robots 4 --noise 0.5"
  "fleet_equal_8|300|equal --robots 8 --noise 0.5 --outliers 0.1"
  "fleet_isolation|240|isolation"
  "fleet_router_restart|300|router"
  "fleet_station|150|station"
  "fleet_station_decode|60|decode"
  "fleet_cleanup|120|cleanup"
  "fleet_bad_method|60|usage --case method"
  "fleet_bad_pose|60|usage --case pose"
  "fleet_bad_seed|60|usage --case seed"
  "fleet_bad_name|60|usage --case name"
  "fleet_name_twice|60|usage --case twice"
  "fleet_help|60|usage --case help")
foreach(case IN LISTS fleet_cases)
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 seconds)
  list(GET parts 2 args)
  separate_arguments(args UNIX_COMMAND "${args}")
  add_test(NAME ${name}
           COMMAND ${zenoh_run} ${seconds} ${fleet_check} ${args} ${zenoh_dirs})
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED zenoh_venv
                       LABELS "${spvs_variant};zenoh;fleet" TIMEOUT ${seconds}
                       SKIP_RETURN_CODE 77)
endforeach()
