#!/bin/sh
# Instruction counts of the estimator's per-point kernels, float and Q
# (firmware/src/fixed/points_q.h), on an emulated Cortex-M3 (QEMU
# mps2-an385, soft float) and Cortex-M4F (mps2-an386, FPU), one frame per
# (N, mismatch share).  docs/FIXED.md, "Instruction counts".
#
#   tools/fixed_m3_bench/run.sh BUILD_DIR [CPU N SHARE]
#     BUILD_DIR  a host float build with spvs_fixed and spvs_core built
#     CPU N SHARE  one case only (m3 or m4f, matches, mismatch share);
#                  default: both CPUs, N = 64, 128, 256, shares 0, 0.2, 0.4
#
# QEMU's -icount shift=6 advances the virtual clock 64 ns per instruction;
# SysTick counts the 25 MHz clock (40 ns), so instructions = ticks * 40 / 64
# (an instruction count, not cycles: QEMU models no pipeline).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:?usage: run.sh BUILD_DIR [CPU N SHARE]}
cpus="m3 m4f"; ns="64 128 256"; shares="0 0.2 0.4"
if [ $# -ge 4 ]; then
  case $2 in m3|m4f) ;; *) echo "run.sh: CPU must be m3 or m4f, not '$2'" >&2; exit 2 ;; esac
  cpus=$2; ns=$3; shares=$4
elif [ $# -ne 1 ]; then
  echo "usage: run.sh BUILD_DIR [CPU N SHARE]" >&2; exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
src=$root/firmware/src
# The Q stages without spvs_fixed.c, which defines spvs_update only in the
# fixed-point build (SPVS_FIXED=ON); the image links the float core too.
qsrc=$(ls "$src"/fixed/*.c "$src"/fixed/accel/*.c | grep -v -e '/spvs_fixed\.c$' -e '/fixed/score_q\.c$' -e '/fixed/sums_q\.c$' -e '/fixed/load_q\.c$' -e '/fixed/offplane_test_q\.c$' -e '/fixed/epipole_cone_q\.c$')
cc -O2 -std=c11 -I"$root/firmware/include" -I"$src" -I"$root/tests" "$here/gen.c" -o "$work/gen" \
   "$build/firmware/libspvs_fixed.a" "$build/firmware/libspvs_core.a" -lm
for cpu in $cpus; do
  if [ $cpu = m3 ]; then
    flags="-mcpu=cortex-m3 -mthumb -mfloat-abi=soft"; machine=mps2-an385; fpu=0
  else
    flags="-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16"; machine=mps2-an386; fpu=1
  fi
  for n in $ns; do
    for out in $shares; do
      "$work/gen" $n $out > "$work/data.h"
      arm-none-eabi-gcc $flags -Os -std=c11 -ffunction-sections -fdata-sections \
        -I"$root/firmware/include" -I"$src" -I"$work" -DSPVS_USE_DOUBLE=0 -DNDEBUG -DENABLE_FPU=$fpu \
        -nostartfiles -T "$here/m3.ld" -Wl,--gc-sections "$here/m3.c" $qsrc \
        "$src/points.c" "$src/homography.c" "$src/plane_h.c" "$src/ransac.c" "$src/rng.c" "$src/common.c" \
        "$src/spvs.c" "$src/params.c" "$src/offplane.c" "$src/epipole.c" "$src/control.c" --specs=nano.specs -lm -lc -lgcc -lnosys -o "$work/k.elf"
      printf '%s N=%s out=%s ' $cpu $n $out
      timeout 120 qemu-system-arm -M $machine -nographic -monitor none -serial null \
        -semihosting-config enable=on,target=native -icount shift=6 -kernel "$work/k.elf" 2>&1 |
        awk '/^cnt/ {printf "%s=%s ", $1, $2; next} {printf "%s=%d ", $1, $2 * 40 / 64} END {print ""}'
    done
  done
done
