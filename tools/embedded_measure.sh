#!/usr/bin/env bash
# Measure the core on a Cortex-M: flash, static RAM, worst-case stack of
# spvs_update, and instructions per spvs_update under QEMU -icount.
# Results feed docs/EMBEDDED.md.
#
#   tools/embedded_measure.sh [--cpu CPU] [--fixed] [BUILD_DIR]
#
#   --cpu CPU   cmake/cpu/CPU.cmake: cortex-m4f (default; QEMU mps2-an386)
#               or cortex-m3 (no FPU, the float core on soft-float; QEMU
#               mps2-an385)
#   --fixed     the fixed-point build (SPVS_FIXED=ON, docs/FIXED.md): the
#               same figures for the fixed-point core (default BUILD_DIR
#               build/<cpu>-fixed-measure)
#   BUILD_DIR   the cross build made here (default build/m4f-measure for
#               the Cortex-M4F, build/m3-measure for the Cortex-M3)
#
# On a soft-float CPU it also lists the float helpers the image links and
# runs spvs_measure_fp.elf: calls and instructions per helper in the
# typical update (target/fp_helpers.h says how they are counted).
# Needs arm-none-eabi-gcc, qemu-system-arm and /usr/bin/python3.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cpu=cortex-m4f
fixed=OFF
build=
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help)
      sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    --fixed)
      fixed=ON
      shift
      ;;
    --cpu)
      [ $# -ge 2 ] || { echo "embedded_measure: --cpu needs a CPU name (--help)" >&2; exit 2; }
      cpu=$2
      shift 2
      ;;
    -*)
      echo "embedded_measure: unknown option $1 (--help)" >&2
      exit 2
      ;;
    *)
      [ -z "$build" ] || { echo "embedded_measure: one BUILD_DIR only (--help)" >&2; exit 2; }
      build=$1
      shift
      ;;
  esac
done
if [ ! -f "$root/cmake/cpu/$cpu.cmake" ]; then
  echo "embedded_measure: unknown CPU '$cpu' (cmake/cpu/ has: $(cd "$root/cmake/cpu" && ls | sed 's/\.cmake$//' | tr '\n' ' '))" >&2
  exit 2
fi
case "$cpu" in
  *) [ $fixed = OFF ] || build=${build:-$root/build/$cpu-fixed-measure} ;;
esac
case "$cpu" in
  cortex-m4f) build=${build:-$root/build/m4f-measure} ;;
  cortex-m3) build=${build:-$root/build/m3-measure} ;;
  *) build=${build:-$root/build/$cpu-measure} ;;
esac
shift_n=8

core=float
[ $fixed = OFF ] || core=fixed-point
echo "== cross build for $cpu, $core core (MinSizeRel, -fstack-usage -fcallgraph-info=su) in $build"
cmake -S "$root" -B "$build" -G Ninja \
  -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchain-arm-none-eabi.cmake" \
  -DSPVS_HOST=OFF -DSPVS_DOUBLE=OFF -DSPVS_FIXED=$fixed -DSPVS_CPU="$cpu" \
  -DCMAKE_BUILD_TYPE=MinSizeRel \
  -DSPVS_EXTRA_C_FLAGS="-fstack-usage -fcallgraph-info=su" >/dev/null
cmake --build "$build" >/dev/null
img=$build/target/spvs_measure.elf
machine=$(cat "$build/target/qemu_machine")

echo
echo "== flash and static data of the core objects (arm-none-eabi-size)"
arm-none-eabi-size -t "$build/firmware/libspvs_core.a"

echo
echo "== core code kept in the linked image (link map: gc-sections applied)"
# Sum the input sections the linker kept from libspvs_core.a, and the sizes
# of the library routines the core calls.
/usr/bin/python3 - "$build/target/spvs_measure.map" "$img" "$build/firmware/libspvs_core.a" <<'PY'
import re, subprocess, sys
text = open(sys.argv[1]).read()
section = r"^ (\.(?:text|rodata|data|bss)\S*)\s+0x[0-9a-f]+\s+(0x[0-9a-f]+)\s+(\S+)"
# The map lists the input sections --gc-sections discarded first, under
# "Discarded input sections", and the linked image after "Memory
# Configuration": only the latter are counted.
kept_at = text.find("Memory Configuration")
flash = ram = 0
for m in re.finditer(section, text[kept_at:], re.M):
    if "libspvs_core.a" in m.group(3):
        if m.group(1).startswith((".text", ".rodata")):
            flash += int(m.group(2), 16)
        else:
            ram += int(m.group(2), 16)
print("core in image (sections the linker kept): flash %d B, static RAM %d B" % (flash, ram))
want = {"sqrtf", "logf", "memset", "memcpy", "memmove", "__ieee754_logf",
        "__ieee754_sqrtf", "__math_divzerof", "__math_invalidf", "__errno"}
nm = subprocess.run(["arm-none-eabi-nm", "-S", sys.argv[2]], capture_output=True, text=True).stdout
tot = 0
print("library routines the core calls (bytes in the image):")
for line in nm.splitlines():
    f = line.split()
    if len(f) == 4 and f[3] in want:
        print("  %-18s %d" % (f[3], int(f[1], 16)))
        tot += int(f[1], 16)
print("  total              %d" % tot)
# On a soft-float CPU, libgcc's float helpers: the objects the linker kept
# (one object holds several entry points, e.g. _arm_addsubsf3.o has fadd,
# fsub, frsub and the int -> float conversions, so sizes come from the map,
# not from nm's overlapping symbols).  A hard-float image links none.
helpers = 0
print("float helpers in the image (libgcc objects kept, link map):")
for m in re.finditer(section, text[kept_at:], re.M):
    o = re.search(r"libgcc\.a\((_arm_\w*[sd]f\w*\.o)\)", m.group(3))
    if o and m.group(1).startswith((".text", ".rodata")) and int(m.group(2), 16) > 0:
        print("  %-18s %d" % (o.group(1), int(m.group(2), 16)))
        helpers += int(m.group(2), 16)
print("  total              %d" % helpers)
undef = subprocess.run(["arm-none-eabi-nm", "-u", sys.argv[3]], capture_output=True, text=True).stdout
if helpers and not re.search(r"\b__aeabi_([fd]|u?i2f|u?l2f)", undef):
    print("  (the core references none: these are the measuring harness's; not counted)")
    helpers = 0
# libgcc's integer routines that the core's objects pulled into the image
# (the fixed-point core's 64-bit divisions and __ctzdi2; the map's archive
# list says who pulled each member, and a member pulled by one of these is
# the core's too).  The float core pulls __ctzdi2 only.
members = re.findall(r"^(\S+\((\S+\.o)\))\n\s+(\S+)", text[:text.find("Discarded input sections")], re.M)
core_pulled = set()
for _ in range(3):
    for full, obj, by in members:
        if "libgcc.a" in full and ("libspvs_core.a" in by or any(o in by for o in core_pulled)):
            core_pulled.add(obj)
intl = 0
print("libgcc integer routines the core pulls (link map):")
for m in re.finditer(section, text[kept_at:], re.M):
    o = re.search(r"libgcc\.a\((\w+\.o)\)", m.group(3))
    if o and o.group(1) in core_pulled and not re.match(r"_arm_\w*[sd]f", o.group(1)) \
            and m.group(1).startswith((".text", ".rodata")) and int(m.group(2), 16) > 0:
        print("  %-18s %d" % (o.group(1), int(m.group(2), 16)))
        intl += int(m.group(2), 16)
print("  total              %d" % intl)
tot += intl
# The budget's figure: what the image holds of the core (kept sections:
# the public calls spvs_update does not reach, such as spvs_update_with_h, are
# dropped from an image that does not call them), plus the routines it
# calls.
print("flash, core kept + library routines + float helpers: %d B" % (flash + tot + helpers))
PY

echo
echo "== worst-case stack (static: .su frames along the .ci call graph)"
# The core's objects only: the fixed-point library beside it has functions
# of the same (static) names.
/usr/bin/python3 "$root/tools/stack_depth.py" "$build/firmware/CMakeFiles/spvs_core.dir" --root spvs_update --image "$img"

echo
echo "== instructions per call under QEMU $machine (-icount shift=$shift_n; instructions = SysTick ticks x 40 / 2^$shift_n)"
timeout 300 qemu-system-arm -M "$machine" -nographic \
  -semihosting-config enable=on,target=native \
  -icount shift=$shift_n,align=off,sleep=off -kernel "$img"

if [ -f "$build/target/spvs_measure_fp.elf" ]; then
  echo
  echo "== soft-float helpers linked (arm-none-eabi-nm: __aeabi_f*, __aeabi_d*, int -> float)"
  arm-none-eabi-nm "$img" | awk '$3 ~ /^__aeabi_([fd]|c[fd]|u?i2[fd]$|u?l2[fd]$)/ {print "  " $3}'
  echo "  referenced by the core (libspvs_core.a):"
  arm-none-eabi-nm "$build/firmware/libspvs_core.a" |
    awk '$1 == "U" && $2 ~ /^(__aeabi_|sqrtf$|logf$)/ {print $2}' | sort -u | sed 's/^/    /'
  echo
  echo "== instructions in the float helpers per typical update (spvs_measure_fp.elf, -icount shift=$shift_n)"
  timeout 600 qemu-system-arm -M "$machine" -nographic \
    -semihosting-config enable=on,target=native \
    -icount shift=$shift_n,align=off,sleep=off -kernel "$build/target/spvs_measure_fp.elf" 2>&1 |
    grep -E '^(fp|fp_total):'
fi

echo
echo "== the controller application (target/app/, docs/SERIAL.md): flash and RAM"
arm-none-eabi-size "$build/target/spvs_app.elf"
/usr/bin/python3 - "$build/target/spvs_app.map" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
parts = {"core": "libspvs_core.a", "codec": "libspvs_serial.a"}
for name, lib in parts.items():
    flash = ram = 0
    kept = text[text.find("Memory Configuration"):]
    for m in re.finditer(r"^ (\.(?:text|rodata|data|bss)\S*)\s+0x[0-9a-f]+\s+(0x[0-9a-f]+)\s+(\S+)", kept, re.M):
        if lib in m.group(3):
            if m.group(1).startswith((".text", ".rodata")):
                flash += int(m.group(2), 16)
            else:
                ram += int(m.group(2), 16)
    print("%-6s in spvs_app.elf: flash %d B, static RAM %d B" % (name, flash, ram))
PY

echo
echo "== instructions per frame of the application: decode, update, encode (-icount shift=$shift_n)"
timeout 300 qemu-system-arm -M "$machine" -nographic \
  -semihosting-config enable=on,target=native \
  -icount shift=$shift_n,align=off,sleep=off -kernel "$build/target/spvs_link_measure.elf"
