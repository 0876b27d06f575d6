#!/usr/bin/env bash
# Installs dependencies, builds the float and double variants and runs every
# test with ctest.  This is the README's test command and what CI runs.
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

exit $status
