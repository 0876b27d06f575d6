#!/bin/sh
# Where the instructions of one fixed-point update go: the typical update
# of tools/embedded_measure.sh's frame (N = 256, 20 % mismatches by
# default), on the Cortex-M3 under QEMU, counted per function from QEMU's
# translation-block log (profile.py).  docs/FIXED.md, "The update on the
# Cortex-M3".
#
#   tools/fixed_m3_bench/profile.sh [--m4f] [--spread POSE SEED] [MEASURE_BUILD_DIR [SIZE_INDEX SHARE_INDEX [TOP]]]
#     --m4f              the float core on the Cortex-M4F instead (the
#                        build embedded_measure.sh makes by default,
#                        build/m4f-measure), for the same frame's
#                        comparison function by function
#     --spread POSE SEED one of main_measure.c's 25 spread frames instead
#                        (POSE 0-4, SEED 0-4, as on its `spread:` lines;
#                        N = 256 / 20 %, SIZE_INDEX and SHARE_INDEX unused)
#     MEASURE_BUILD_DIR  the cross build embedded_measure.sh --cpu cortex-m3
#                        --fixed made (default build/cortex-m3-fixed-measure)
#     SIZE_INDEX         0, 1, 2 for N = 64, 128, 256 (default 2)
#     SHARE_INDEX        0, 1, 2 for 0, 20, 40 % mismatches (default 1)
#
# The frame is target/main_measure.c's (its generator is taken from that
# file), warmed up with one update as there; the second update is counted
# between prof_begin and prof_end.  The total agrees with
# embedded_measure.sh's update_typ within the markers' few instructions.
set -eu
m4f=0
if [ "${1:-}" = --m4f ]; then
  m4f=1
  shift
fi
spread=
if [ "${1:-}" = --spread ]; then
  [ $# -ge 3 ] || { echo "profile.sh: --spread needs POSE and SEED" >&2; exit 2; }
  case "$2$3" in
    [0-4][0-4]) spread="$2 $3" ;;
    *) echo "profile.sh: --spread POSE SEED, each 0-4" >&2; exit 2 ;;
  esac
  shift 3
fi
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
if [ $m4f = 1 ]; then
  build=${1:-$root/build/m4f-measure}
  arch="-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16"
  core="-DSPVS_TARGET_CPU_NAME=\"Cortex-M4F\" -DSPVS_USE_FIXED=0"
else
  build=${1:-$root/build/cortex-m3-fixed-measure}
  arch="-mcpu=cortex-m3 -mthumb -mfloat-abi=soft"
  core="-DSPVS_TARGET_CPU_NAME=\"Cortex-M3\" -DSPVS_USE_FIXED=1"
fi
case "${1:-}" in
  -*) echo "profile.sh: unknown option $1 (--m4f first, then --spread POSE SEED)" >&2; exit 2 ;;
esac
if [ ! -f "$build/firmware/libspvs_core.a" ]; then
  if [ $m4f = 1 ]; then how="tools/embedded_measure.sh"; else how="tools/embedded_measure.sh --cpu cortex-m3 --fixed"; fi
  echo "profile.sh: no measuring build in $build (make it with $how)" >&2
  exit 2
fi
pn=${2:-2}
pj=${3:-1}
top=${4:-40}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The frame generator of main_measure.c: from the core's instance to the
# measuring helpers.
/usr/bin/python3 - "$root/target/main_measure.c" "$work/prof_main.c" "$pn" "$pj" $spread <<'PY'
import sys
src = open(sys.argv[1]).read()
body = src[src.index("static spvs_t core;"):src.index("/* Keep the compiler")]
pn, pj = sys.argv[3], sys.argv[4]
head = """#include <math.h>
#include <stdint.h>
#include "board.h"
#include "fmt.h"
#include "spvs/ransac.h"
#include "spvs/spvs.h"
#define NS_PER_TICK 40u
#define MEASURE_ICOUNT_SHIFT 8
"""
tail = """
__attribute__((noinline)) void prof_begin(void) { __asm__ volatile("nop"); }
__attribute__((noinline)) void prof_end(void) { __asm__ volatile("nop"); }
int main(void)
{
    static const uint16_t sizes[3] = {64u, 128u, 256u};
    static const uint32_t bad_pct[3] = {0u, 20u, 40u};
    board_ticks_start();
    spvs_rng_seed(&gen, 1000u + (uint32_t)(%s * 3 + %s));
    uint16_t n = make_frame(sizes[%s], bad_pct[%s]);
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    spvs_output_t out;
    if (spvs_init(&core, &p) != SPVS_OK) {
        return 1;
    }
    int st = spvs_update(&core, frame, n, 0.0f, &out);
    prof_begin();
    st = spvs_update(&core, frame, n, 0.1f, &out);
    prof_end();
    out_str("status=");
    out_int(st);
    out_str(" inliers=");
    out_u32(out.n_inliers);
    out_str("\\n");
    (void)to_instructions;
    return 0;
}
""" % (pn, pj, pn, pj)
if len(sys.argv) > 5:
    # A spread frame: measure_spread's pose and seed (its tables read from
    # the same file), at N = 256 / 20 %.
    pose, seed = int(sys.argv[5]), int(sys.argv[6])
    f5 = src[src.index("fig5[SPREAD_POSES][3] = {"):]
    f5 = f5[f5.index("{") + 1:f5.index("};")]
    rows = [r.strip(" {}\n,") for r in f5.split("},")]
    x, z, phi = [c.strip() for c in rows[pose].split(",")]
    seeds = int(src[src.index("#define SPREAD_SEEDS") + 21:].split()[0].rstrip("u"))
    tail = tail.replace("spvs_rng_seed(&gen, 1000u + (uint32_t)(%s * 3 + %s));" % (pn, pj),
                        "spvs_rng_seed(&gen, %du);" % (2000 + pose * seeds + seed))
    tail = tail.replace("make_frame(sizes[%s], bad_pct[%s])" % (pn, pj),
                        "make_frame_at(256u, 20u, %s, %s, %s, 1)" % (x, z, phi))
    assert "make_frame_at" in tail and "1000u" not in tail
open(sys.argv[2], "w").write(head + body + tail)
PY
cflags="$arch -ffunction-sections -fdata-sections -Os -DNDEBUG -std=c11"
# shellcheck disable=SC2086 # $core holds several words
arm-none-eabi-gcc $cflags $core -DSPVS_USE_DOUBLE=0 \
  -I"$root/target" -I"$root/firmware/src/fixed" -I"$root/firmware/include" -I"$root/firmware/src" \
  -c "$work/prof_main.c" -o "$work/prof_main.o"
# shellcheck disable=SC2086
arm-none-eabi-gcc $arch -Wl,--gc-sections -nostartfiles --specs=nano.specs \
  -T "$root/target/mps2_an386.ld" "$work/prof_main.o" \
  -Wl,--whole-archive "$build/target/libspvs_board.a" -Wl,--no-whole-archive "$build/target/libspvs_board_float.a" \
  "$build/firmware/libspvs_core.a" -lm "$build/target/libspvs_board.a" "$build/firmware/libspvs_core.a" -o "$work/prof.elf"
timeout 300 qemu-system-arm -M "$(cat "$build/target/qemu_machine")" -nographic \
  -semihosting-config enable=on,target=native -icount shift=8,align=off,sleep=off \
  -d in_asm,exec,nochain -D "$work/log.txt" -kernel "$work/prof.elf"
/usr/bin/python3 "$here/profile.py" "$work/log.txt" "$work/prof.elf" "$top"
