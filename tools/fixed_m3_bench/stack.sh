#!/bin/sh
# Worst-case stack of the fixed-point update on the Cortex-M3: the Q
# stages (firmware/src/fixed without spvs_fixed.c), rng.c, common.c and
# params.c compiled at -Os with -fstack-usage -fcallgraph-info=su, linked
# with a main that calls spvs_q_init and spvs_q_update, and the deepest
# chain summed by tools/stack_depth.py (RANSAC's callbacks as the indirect
# calls).  docs/FIXED.md, "The update on the Cortex-M3".
#
#   tools/fixed_m3_bench/stack.sh [ROOT_FUNCTION ...]
#     default root: spvs_q_update; each further root is printed as well
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
src=$root/firmware/src
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
flags="-mcpu=cortex-m3 -mthumb -mfloat-abi=soft -Os -std=c11 -DNDEBUG -DSPVS_USE_DOUBLE=0"
for f in $(ls "$src"/fixed/*.c "$src"/fixed/accel/*.c | grep -v -e '/spvs_fixed\.c$' -e '/fixed/score_q\.c$' -e '/fixed/sums_q\.c$' -e '/fixed/load_q\.c$' -e '/fixed/offplane_test_q\.c$' -e '/fixed/epipole_cone_q\.c$') "$src/rng.c" "$src/common.c" "$src/params.c"; do
  arm-none-eabi-gcc $flags -I"$root/firmware/include" -I"$src" -fstack-usage -fcallgraph-info=su \
    -c "$f" -o "$work/$(basename "$f" .c).o"
done
cat > "$work/main.c" <<'EOC'
#include "fixed/spvs_q.h"
static spvs_q_t s;
static spvs_match_t m[8];
static spvs_output_t o;
int main(void);
int main(void)
{
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    if (spvs_q_init(&s, &p) != SPVS_OK) {
        return 1;
    }
    return spvs_q_update(&s, m, 8, 0.1f, &o);
}
EOC
arm-none-eabi-gcc $flags -I"$root/firmware/include" -I"$src" "$work/main.c" "$work"/*.o \
  --specs=nosys.specs -Wl,--gc-sections -o "$work/img.elf"
[ $# -gt 0 ] || set -- spvs_q_update
for r in "$@"; do
  /usr/bin/python3 "$root/tools/stack_depth.py" "$work" --root "$r" --image "$work/img.elf" \
    --indirect est_fit,est_score,est_cost,est_refine
done
