#!/usr/bin/env bash
# cortex_m4f.sh - the consumer for the Cortex-M4F through find_package: the
# core cross-built and installed into a sysroot-like prefix, then
# examples/consumer configured with the toolchain file that prefix holds
# (share/spvs/cmake/) and linked into an ELF for the M4F's hard-float ABI.
# Exit 77 (skipped) without arm-none-eabi-gcc.
set -euo pipefail
. "$(dirname "$0")/common.sh"
if ! command -v arm-none-eabi-gcc >/dev/null; then
  echo "SKIP: arm-none-eabi-gcc not installed (scripts/install_deps.sh)"
  exit 77
fi
spvs_tmpdir
"$CMAKE" -S "$SPVS_SOURCE" -B "$tmp/lib" -G "$SPVS_GENERATOR" \
    -DCMAKE_TOOLCHAIN_FILE="$SPVS_SOURCE/cmake/toolchain-arm-none-eabi.cmake" \
    -DSPVS_CPU=cortex-m4f -DSPVS_HOST=OFF -DCMAKE_BUILD_TYPE=MinSizeRel >"$tmp/lib.log" 2>&1 &&
  "$CMAKE" --build "$tmp/lib" --target spvs_core >>"$tmp/lib.log" 2>&1 &&
  "$CMAKE" --install "$tmp/lib" --prefix "$tmp/m4f" --component core >>"$tmp/lib.log" 2>&1 ||
  { cat "$tmp/lib.log" >&2; fail "cross-building and installing the core"; }

tc=$tmp/m4f/share/spvs/cmake/toolchain-arm-none-eabi.cmake
[ -f "$tc" ] || fail "the toolchain file is not installed"
"$CMAKE" -S "$SPVS_SOURCE/examples/consumer" -B "$tmp/b" -G "$SPVS_GENERATOR" \
    -DCMAKE_TOOLCHAIN_FILE="$tc" -DCMAKE_FIND_ROOT_PATH="$tmp/m4f" \
    -DCMAKE_BUILD_TYPE=MinSizeRel >"$tmp/b.log" 2>&1 &&
  "$CMAKE" --build "$tmp/b" >>"$tmp/b.log" 2>&1 ||
  { cat "$tmp/b.log" >&2; fail "building the consumer for the Cortex-M4F"; }
elf=$tmp/b/spvs-consumer
attrs=$(arm-none-eabi-readelf -A "$elf")
echo "$attrs" | grep -q "Tag_CPU_arch: v7E-M" || fail "not a v7E-M image: $attrs"
echo "$attrs" | grep -q "Tag_ABI_VFP_args: VFP registers" || fail "not hard-float: $attrs"
echo "$attrs" | grep -q "Tag_FP_arch: VFPv4-D16" || fail "no FPv4-SP-D16: $attrs"
# The image links the float32 library of the default sizes.
sym=$(arm-none-eabi-nm "$elf" | awk '$3 ~ /^spvs_init__/ { print $3 }')
case $sym in
  spvs_init__float_matches*_median*) ;;
  *) fail "the image's spvs_init is '$sym', want spvs_init__float_..._median<N>" ;;
esac
echo "Cortex-M4F consumer linked: $(arm-none-eabi-size "$elf" | tail -n 1 | awk '{print $1 " B text, " $2 " B data, " $3 " B bss"}'), $sym"
