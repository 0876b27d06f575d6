#!/usr/bin/env bash
# Installs dependencies, builds the float and double variants, the
# reference paths (SPVS_ACCEL=OFF) of the float and fixed-point cores, the
# fixed-point build and the sanitizer build, and runs every test with
# ctest.  This is the README's test command and what CI runs (with
# CI=true: a required test skipped or missing fails, run_ctest).
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install_deps.sh

jobs=$(nproc 2>/dev/null || echo 2)
status=0

# run_ctest VARIANT DIR [ctest selection ...]: runs ctest on DIR with
# --no-tests=error (a selection that matches nothing fails).  With CI=true
# a test that CI must run may be neither skipped (exit 77,
# SKIP_RETURN_CODE, or a fixture's skip) nor missing: every name in
# tests/ci/VARIANT.txt must be registered in DIR under the selection, and
# ctest's report may name no skipped or disabled test.  Sets status=1 on any failure.
run_ctest() {
  local variant=$1 dir=$2
  shift 2
  local log=$dir/ctest-$variant.log
  local rc=0
  ctest --test-dir "$dir" --no-tests=error --output-on-failure -j "$jobs" "$@" 2>&1 | tee "$log" ||
    rc=$?
  [ "$rc" -eq 0 ] || status=1
  if [ "${CI:-}" = true ]; then
    local expected=tests/ci/$variant.txt
    if [ ! -f "$expected" ]; then
      echo "CI: no list of required tests $expected" >&2
      status=1
      return
    fi
    local registered missing skipped
    registered=$(ctest --test-dir "$dir" --show-only=json-v1 "$@" |
      python3 -c 'import json, sys; print("\n".join(t["name"] for t in json.load(sys.stdin)["tests"]))' ||
      true)
    missing=$(grep -v -e '^#' -e '^$' "$expected" | sort | comm -23 - <(sort <<<"$registered") || true)
    if [ -n "$missing" ]; then
      echo "CI: required tests not registered in $dir ($variant):" $missing >&2
      status=1
    fi
    skipped=$(grep -E '\*\*\*Skipped|\(Skipped\)|\(Disabled\)' "$log" |
      sed -E 's/.*Test +#[0-9]+: ([^ ]+).*/\1/; s/^[[:space:]]*[0-9]+ - ([^ ]+).*/\1/' | sort -u || true)
    if [ -n "$skipped" ]; then
      echo "CI: required tests skipped ($variant):" $skipped >&2
      status=1
    fi
    if [ -z "$missing" ] && [ -z "$skipped" ]; then
      echo "CI: $variant: all $(grep -cv -e '^#' -e '^$' "$expected") required tests registered, none skipped"
    fi
  fi
}

# Float: the MCU's scalar type.  Everything is built and every test runs.
dir=build/test-float
echo "=== configure and build (float32 core, everything) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=OFF >/dev/null
cmake --build "$dir" -j "$jobs"
echo "=== ctest (float32 core, everything) ==="
run_ctest float "$dir"

# Double: the core's own tests and the closed loop again, in double precision.
dir=build/test-double
core_tests="test_homography test_ransac test_epipole test_control test_spvs test_golden test_sim test_closed_loop
  test_golden_fixed test_fixed_spvs test_fixed_q test_fixed_solve3 test_fixed_fit test_fixed_ransac
  test_fixed_plane_h test_fixed_conv test_fixed_epipole test_fixed_control unity_self_fail"
echo "=== configure and build (double core, core tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target $core_tests
echo "=== ctest (double core, core tests) ==="
run_ctest double "$dir" -R "^($(echo $core_tests | tr ' ' '|')|unity_self_fail_count)\$"

# The reference path (SPVS_ACCEL=OFF: nothing from firmware/src/accel, the
# Cortex-M4F's point layout, firmware/src/points.c): the core's tests again,
# the fixed-point image built on the same path in the closed loop on the
# emulated Cortex-M3, bit for bit the host's reference core, and the closed
# loop must equal the accelerated build's bit for bit.
dir=build/test-reference
ref_mcu_tests="target_m3_fixed_build target_m3_fixed_qemu mcu_closed_loop_fixed_m1
  mcu_closed_loop_fixed_m2 mcu_closed_loop_fixed_m3"
echo "=== configure and build (float32 core, reference path, core and MCU tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=OFF \
  -DSPVS_ACCEL=OFF >/dev/null
cmake --build "$dir" -j "$jobs" --target $core_tests spvs-sim spvs-serial-agent
echo "=== ctest (float32 core, reference path, core and MCU tests) ==="
run_ctest reference "$dir" -R "^($(echo $core_tests $ref_mcu_tests | tr ' ' '|')|unity_self_fail_count)\$"
echo "=== closed loop: accelerated build against the reference path ==="
tests/compare_layouts.sh build/test-float/sim_host/spvs-sim "$dir/sim_host/spvs-sim" || status=1

# Fixed point (SPVS_FIXED=ON): spvs.h's pipeline on the Q stages, no float
# stage in the core: the closed loops and the scenarios with the float
# build's limits, and spvs-sim's in-process run equal to the Q pipeline's.
dir=build/test-fixed
fixed_tests="test_sim test_closed_loop test_scenarios test_golden_fixed test_fixed_spvs test_serial_bits unity_self_fail"
echo "=== configure and build (fixed-point core, pipeline tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_FIXED=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target $fixed_tests spvs-sim
echo "=== ctest (fixed-point core, pipeline tests) ==="
run_ctest fixed "$dir" -R "^($(echo $fixed_tests | tr ' ' '|')|sim_fixed_build_is_q|unity_self_fail_count)\$"

# The fixed-point core's reference path (SPVS_FIXED=ON, SPVS_ACCEL=OFF:
# nothing from firmware/src/fixed/accel): the same pipeline tests, and the
# closed loops against the accelerated fixed build's, whose fast sums round
# otherwise (the same statuses, frames and step times; final errors within
# 0.1 mm and 0.001 deg).
dir=build/test-fixed-reference
echo "=== configure and build (fixed-point core, reference path, pipeline tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_FIXED=ON \
  -DSPVS_ACCEL=OFF >/dev/null
cmake --build "$dir" -j "$jobs" --target $fixed_tests spvs-sim
echo "=== ctest (fixed-point core, reference path, pipeline tests) ==="
run_ctest fixed-reference "$dir" -R "^($(echo $fixed_tests | tr ' ' '|')|sim_fixed_build_is_q|unity_self_fail_count)\$"
echo "=== closed loop: accelerated fixed-point build against its reference path ==="
tests/compare_layouts.sh build/test-fixed/sim_host/spvs-sim "$dir/sim_host/spvs-sim" 1e-4 1e-3 || status=1

# Sanitizers: the core's tests and the closed loop under ASan and UBSan.
dir=build/test-sanitize
echo "=== configure and build (float32 core, ASan + UBSan, core tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DSPVS_DOUBLE=OFF -DSPVS_SANITIZE=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target $core_tests
echo "=== ctest (float32 core, ASan + UBSan, core tests) ==="
run_ctest sanitize "$dir" -R "^($(echo $core_tests | tr ' ' '|')|unity_self_fail_count)\$"

exit $status
