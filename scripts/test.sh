#!/usr/bin/env bash
# Installs dependencies, builds the float and double variants, the
# reference paths (SPVS_ACCEL=OFF) of the float and fixed-point cores, the
# fixed-point build and the sanitizer build, and runs every test with
# ctest.  This is the README's test command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install_deps.sh

jobs=$(nproc 2>/dev/null || echo 2)
status=0

# Float: the MCU's scalar type.  Everything is built and every test runs.
dir=build/test-float
echo "=== configure and build (float32 core, everything) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=OFF >/dev/null
cmake --build "$dir" -j "$jobs"
echo "=== ctest (float32 core, everything) ==="
ctest --test-dir "$dir" --output-on-failure -j "$jobs" || status=1

# Double: the core's own tests and the closed loop again, in double precision.
dir=build/test-double
core_tests="test_homography test_ransac test_epipole test_control test_spvs test_golden test_sim test_closed_loop"
echo "=== configure and build (double core, core tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target $core_tests
echo "=== ctest (double core, core tests) ==="
ctest --test-dir "$dir" --output-on-failure -j "$jobs" -R "^($(echo $core_tests | tr ' ' '|'))\$" || status=1

# The reference path (SPVS_ACCEL=OFF: nothing from firmware/src/accel, the
# Cortex-M4F's point layout, firmware/src/points.c): the core's tests again,
# and the closed loop must equal the accelerated build's bit for bit.
dir=build/test-reference
echo "=== configure and build (float32 core, reference path, core tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=OFF \
  -DSPVS_ACCEL=OFF >/dev/null
cmake --build "$dir" -j "$jobs" --target $core_tests spvs-sim
echo "=== ctest (float32 core, reference path, core tests) ==="
ctest --test-dir "$dir" --output-on-failure -j "$jobs" -R "^($(echo $core_tests | tr ' ' '|'))\$" || status=1
echo "=== closed loop: accelerated build against the reference path ==="
tests/compare_layouts.sh build/test-float/sim_host/spvs-sim "$dir/sim_host/spvs-sim" || status=1

# Fixed point (SPVS_FIXED=ON): spvs.h's pipeline on the Q stages, no float
# stage in the core: the closed loops and the scenarios with the float
# build's limits, and spvs-sim's in-process run equal to the Q pipeline's.
dir=build/test-fixed
fixed_tests="test_sim test_closed_loop test_scenarios test_golden_fixed test_fixed_spvs test_serial_bits"
echo "=== configure and build (fixed-point core, pipeline tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_FIXED=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target $fixed_tests spvs-sim
echo "=== ctest (fixed-point core, pipeline tests) ==="
ctest --test-dir "$dir" --output-on-failure -j "$jobs" \
  -R "^($(echo $fixed_tests | tr ' ' '|')|sim_fixed_build_is_q)\$" || status=1

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
ctest --test-dir "$dir" --output-on-failure -j "$jobs" \
  -R "^($(echo $fixed_tests | tr ' ' '|')|sim_fixed_build_is_q)\$" || status=1
echo "=== closed loop: accelerated fixed-point build against its reference path ==="
tests/compare_layouts.sh build/test-fixed/sim_host/spvs-sim "$dir/sim_host/spvs-sim" 1e-4 1e-3 || status=1

# Sanitizers: the core's tests and the closed loop under ASan and UBSan.
dir=build/test-sanitize
echo "=== configure and build (float32 core, ASan + UBSan, core tests) ==="
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DSPVS_DOUBLE=OFF -DSPVS_SANITIZE=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target $core_tests
echo "=== ctest (float32 core, ASan + UBSan, core tests) ==="
ctest --test-dir "$dir" --output-on-failure -j "$jobs" -R "^($(echo $core_tests | tr ' ' '|'))\$" || status=1

exit $status
