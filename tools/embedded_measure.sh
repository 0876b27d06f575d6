#!/usr/bin/env bash
# Measure the core on the Cortex-M4F: flash, static RAM, worst-case stack of
# spvs_update, and instructions per spvs_update under QEMU -icount.
# Results feed docs/EMBEDDED.md.
#   tools/embedded_measure.sh [BUILD_DIR]      (default build/m4f-measure)
# Needs arm-none-eabi-gcc, qemu-system-arm and /usr/bin/python3.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/m4f-measure}
shift_n=8

echo "== cross build (MinSizeRel, -fstack-usage -fcallgraph-info=su) in $build"
cmake -S "$root" -B "$build" -G Ninja \
  -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchain-arm-none-eabi.cmake" \
  -DSPVS_HOST=OFF -DSPVS_DOUBLE=OFF -DSPVS_CPU=cortex-m4f \
  -DCMAKE_BUILD_TYPE=MinSizeRel \
  -DSPVS_EXTRA_C_FLAGS="-fstack-usage -fcallgraph-info=su" >/dev/null
cmake --build "$build" >/dev/null
img=$build/target/spvs_measure.elf

echo
echo "== flash and static data of the core objects (arm-none-eabi-size)"
arm-none-eabi-size -t "$build/firmware/libspvs_core.a"

echo
echo "== core code kept in the linked image (link map: gc-sections applied)"
# Sum the input sections the linker kept from libspvs_core.a, and the sizes
# of the library routines the core calls.
/usr/bin/python3 - "$build/target/spvs_measure.map" "$img" <<'PY'
import re, subprocess, sys
text = open(sys.argv[1]).read()
flash = ram = 0
for m in re.finditer(r"^ (\.(?:text|rodata|data|bss)\S*)\s+0x[0-9a-f]+\s+(0x[0-9a-f]+)\s+(\S+)", text, re.M):
    if "libspvs_core.a" in m.group(3):
        if m.group(1).startswith((".text", ".rodata")):
            flash += int(m.group(2), 16)
        else:
            ram += int(m.group(2), 16)
print("core in image: flash %d B, static RAM %d B" % (flash, ram))
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
PY

echo
echo "== worst-case stack (static: .su frames along the .ci call graph)"
/usr/bin/python3 "$root/tools/stack_depth.py" "$build/firmware" --root spvs_update --image "$img"

echo
echo "== instructions per call under QEMU (-icount shift=$shift_n; instructions = SysTick ticks x 40 / 2^$shift_n)"
timeout 300 qemu-system-arm -M mps2-an386 -nographic \
  -semihosting-config enable=on,target=native \
  -icount shift=$shift_n,align=off,sleep=off -kernel "$img"

echo
echo "== the controller application (target/app/, docs/SERIAL.md): flash and RAM"
arm-none-eabi-size "$build/target/spvs_app.elf"
/usr/bin/python3 - "$build/target/spvs_app.map" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
parts = {"core": "libspvs_core.a", "codec": "libspvs_serial.a"}
for name, lib in parts.items():
    flash = ram = 0
    for m in re.finditer(r"^ (\.(?:text|rodata|data|bss)\S*)\s+0x[0-9a-f]+\s+(0x[0-9a-f]+)\s+(\S+)", text, re.M):
        if lib in m.group(3):
            if m.group(1).startswith((".text", ".rodata")):
                flash += int(m.group(2), 16)
            else:
                ram += int(m.group(2), 16)
    print("%-6s in spvs_app.elf: flash %d B, static RAM %d B" % (name, flash, ram))
PY

echo
echo "== instructions per frame of the application: decode, update, encode (-icount shift=$shift_n)"
timeout 300 qemu-system-arm -M mps2-an386 -nographic \
  -semihosting-config enable=on,target=native \
  -icount shift=$shift_n,align=off,sleep=off -kernel "$build/target/spvs_link_measure.elf"
