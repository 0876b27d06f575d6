# Robustness (docs/ROBUSTNESS.md): bad-input classes of the core, the fuzz
# targets' CI mode, and transport faults in the closed loop over LCM.

# Every bad-input class: its exact status and a stop command.
spvs_add_test(NAME test_bad_input SOURCES test_bad_input.c LIBS spvs_sim LABELS unit robustness)

# libFuzzer targets (label fuzz), built with clang in a project of their own.
include(${CMAKE_CURRENT_LIST_DIR}/fuzz/fuzz.cmake)
