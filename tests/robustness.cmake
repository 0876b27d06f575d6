# Robustness (docs/ROBUSTNESS.md): bad-input classes of the core, the fuzz
# targets' CI mode, and transport faults in the closed loop over LCM.

# Every bad-input class: its exact status and a stop command.
spvs_add_test(NAME test_bad_input SOURCES test_bad_input.c LIBS spvs_sim LABELS unit robustness)

# libFuzzer targets (label fuzz), built with clang in a project of their own.
include(${CMAKE_CURRENT_LIST_DIR}/fuzz/fuzz.cmake)

# Transport faults in the closed loop over LCM (label faults): spvs-sim ->
# spvs-lcm-faults -> spvs-node, each scenario in a loopback-only network
# namespace, bounded in time, asserting the final errors.
if(TARGET spvs_node_lib AND TARGET spvs-sim)
  add_subdirectory(${CMAKE_SOURCE_DIR}/tools/lcm_faults ${CMAKE_BINARY_DIR}/tools/lcm_faults)
endif()
if(TARGET spvs-lcm-faults)
  foreach(scenario drop delay dup_reorder time_back pause restart pause_no_watchdog)
    add_test(NAME fault_${scenario}
             COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/faults/run_fault.sh
                     $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>
                     $<TARGET_FILE:spvs-lcm-faults> ${scenario}
                     ${CMAKE_CURRENT_BINARY_DIR}/faults/${scenario})
    # About 25 s of real time each (the simulator paces frames at 0.1 s).
    set_tests_properties(fault_${scenario} PROPERTIES LABELS "faults;lcm;process"
                         TIMEOUT 150)
  endforeach()
endif()

# Memcheck on spvs-sim (in process) and on spvs-sim with spvs-node over LCM
# (label valgrind).  Not in a sanitizer build: ASan and valgrind exclude
# each other.
find_program(SPVS_VALGRIND valgrind)
if(SPVS_VALGRIND AND NOT SPVS_SANITIZE AND TARGET spvs_node_lib AND TARGET spvs-sim)
  add_test(NAME valgrind_node_sim
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/faults/valgrind_loop.sh
                   $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>)
  set_tests_properties(valgrind_node_sim PROPERTIES LABELS "valgrind;lcm;process"
                       TIMEOUT 600)
endif()
