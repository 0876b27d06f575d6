#!/usr/bin/env bash
# check_instance_size.sh SOURCE_DIR CC - spvs_t (spvs.h: storage of
# SPVS_INSTANCE_BYTES, spvs_config.h) holds the core's state
# (firmware/src/spvs/instance.h) in the float, double and both fixed-point
# builds, at the default sizes and with SPVS_MAX_* and the other sizing
# settings overridden to their small and large ends; and the storage wastes
# at most 512 bytes beyond the state.  Each configuration is compiled and
# run on the host; the core's own compile-time check is the same
# comparison, made in every build of spvs.c and spvs_fixed.c.
set -euo pipefail
src=$1
cc=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat >"$tmp/size.c" <<'EOC'
#include <stdio.h>
#include "spvs/instance.h"
int main(void)
{
    printf("%u %u\n", (unsigned)sizeof(spvs_state_t), (unsigned)sizeof(spvs_t));
    return 0;
}
EOC
n=0
for scalar in "0 0" "1 0" "0 1" "1 1"; do
  set -- $scalar
  for sizes in "" \
      "-DSPVS_MAX_MATCHES=16 -DSPVS_MAX_FEATURES=16 -DSPVS_MAX_OFFPLANE=4 -DSPVS_EPIPOLE_MAX_HYP=4 -DSPVS_LO_POINTS=8 -DSPVS_MIN_INLIERS=4 -DSPVS_EPIPOLE_MEDIAN=1" \
      "-DSPVS_MAX_MATCHES=64 -DSPVS_MAX_FEATURES=128 -DSPVS_MAX_OFFPLANE=16 -DSPVS_LO_POINTS=32 -DSPVS_EPIPOLE_MEDIAN=15" \
      "-DSPVS_MAX_MATCHES=4096 -DSPVS_MAX_FEATURES=65535 -DSPVS_MAX_OFFPLANE=128 -DSPVS_LO_POINTS=4096"; do
    # shellcheck disable=SC2086 # $sizes holds several flags
    if ! "$cc" -std=c11 -DSPVS_USE_DOUBLE=$1 -DSPVS_USE_FIXED=$2 -DSPVS_ACCEL=0 $sizes \
        -I"$src/firmware/include" -I"$src/firmware/src" "$tmp/size.c" -o "$tmp/size" 2>"$tmp/err"; then
      cat "$tmp/err" >&2
      echo "FAIL: the state does not compile into spvs_t (double $1, fixed $2, $sizes)" >&2
      exit 1
    fi
    read -r state storage < <("$tmp/size")
    if [ "$state" -gt "$storage" ] || [ $((storage - state)) -gt 512 ]; then
      echo "FAIL: state $state B in storage $storage B (double $1, fixed $2, $sizes)" >&2
      exit 1
    fi
    echo "double $1 fixed $2 ${sizes:-(defaults)}: state $state B, spvs_t $storage B"
    n=$((n + 1))
  done
done
echo "$n configurations: the state fits spvs_t with at most 512 B to spare"
