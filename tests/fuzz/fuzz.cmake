# CI mode of the fuzz targets (included by tests/robustness.cmake): one ctest
# entry builds tests/fuzz/ with clang into <build>/fuzz, then each target runs
# for SPVS_FUZZ_SECONDS of wall time from the committed seeds and fails on any
# crash, hang, leak or sanitizer report.  Label: fuzz.  Registered only where
# clang links -fsanitize=fuzzer (clang and libclang-rt-14-dev, see
# scripts/install_deps.sh); elsewhere a status line says they are skipped.
set(SPVS_FUZZ_SECONDS 20 CACHE STRING "Seconds each fuzz target runs under ctest")

find_program(SPVS_FUZZ_CLANG NAMES clang clang-14)
set(spvs_fuzz_ok FALSE)
if(SPVS_FUZZ_CLANG)
  set(probe_dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz-probe)
  file(MAKE_DIRECTORY ${probe_dir})
  file(WRITE ${probe_dir}/probe.c
       "#include <stddef.h>\n#include <stdint.h>\n"
       "int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n);\n"
       "int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n)"
       " { (void)d; (void)n; return 0; }\n")
  execute_process(
    COMMAND ${SPVS_FUZZ_CLANG} -fsanitize=fuzzer,address,undefined probe.c -o probe
    WORKING_DIRECTORY ${probe_dir}
    RESULT_VARIABLE probe_rc OUTPUT_QUIET ERROR_QUIET)
  if(probe_rc EQUAL 0)
    set(spvs_fuzz_ok TRUE)
  endif()
endif()

if(NOT spvs_fuzz_ok)
  message(STATUS "fuzz tests skipped: no clang with libFuzzer (libclang-rt-14-dev)")
  return()
endif()

set(spvs_fuzz_dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz)
set(spvs_fuzz_run ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.sh)
add_test(NAME fuzz_build COMMAND ${CMAKE_COMMAND} -E env SPVS_FUZZ_CC=${SPVS_FUZZ_CLANG}
         ${spvs_fuzz_run} build ${spvs_fuzz_dir})
set_tests_properties(fuzz_build PROPERTIES LABELS fuzz TIMEOUT 300
                     FIXTURES_SETUP spvs_fuzz_targets)
foreach(target fuzz_core fuzz_core_fixed fuzz_node fuzz_serial)
  add_test(NAME ${target} COMMAND ${spvs_fuzz_run} run ${spvs_fuzz_dir} ${target}
           ${SPVS_FUZZ_SECONDS})
  math(EXPR limit "${SPVS_FUZZ_SECONDS} * 3 + 60")
  set_tests_properties(${target} PROPERTIES LABELS fuzz TIMEOUT ${limit}
                       FIXTURES_REQUIRED spvs_fuzz_targets)
endforeach()
