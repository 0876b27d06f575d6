#!/usr/bin/env bash
# Installs dependencies, builds the float and double variants and runs every
# test with ctest.  This is the README's test command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install_deps.sh

jobs=$(nproc 2>/dev/null || echo 2)
status=0
for variant in float double; do
  dir=build/test-$variant
  dbl=OFF; [ "$variant" = double ] && dbl=ON
  echo "=== configure and build ($variant) ==="
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPVS_DOUBLE=$dbl >/dev/null
  cmake --build "$dir" -j "$jobs"
  echo "=== ctest ($variant) ==="
  # The double build runs the core's tests; the float build runs everything.
  if [ "$variant" = double ]; then
    ctest --test-dir "$dir" --output-on-failure -j "$jobs" -L double || status=1
  else
    ctest --test-dir "$dir" --output-on-failure -j "$jobs" || status=1
  fi
done
exit $status
