#!/usr/bin/env bash
# image_check.sh IMAGE CHECK_CMAKE [no-float]
# The controller application links no heap, no stdio and no double-precision
# helper: target/check_image.cmake on the image must pass, the symbols the
# application needs must be there (so the check looked at the right file),
# and the same check must refuse a copy of the symbol list with malloc in it.
# With no-float (the fixed-point build's application) the image must link
# no floating-point helper at all (FORBID_FLOAT=ON), and the check must
# refuse a copy of its symbol list with __aeabi_fmul in it.
set -euo pipefail
image=$1 check=$2 mode=${3:-}
command -v arm-none-eabi-nm >/dev/null || { echo "SKIP: arm-none-eabi-nm not installed"; exit 77; }
[ -f "$image" ] || { echo "SKIP: no application image $image"; exit 77; }
forbid=OFF
[ "$mode" = no-float ] && forbid=ON
cmake -DNM=arm-none-eabi-nm -DIMAGE="$image" -DFORBID_FLOAT=$forbid -P "$check"
# The symbol list is read once: grep -q leaving a pipe early would kill nm
# with SIGPIPE, which pipefail reports as a failure.
syms=$(arm-none-eabi-nm "$image")
for sym in spvs_update spvs_serial_unpack board_timer0_irq uart_write; do
  grep -qw "$sym" <<<"$syms" || { echo "FAIL: $sym missing from $image"; exit 1; }
done
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# A fake nm that adds a forbidden symbol to the real list: the check must
# fail on it.
refuse() {
  printf '#!/bin/sh\narm-none-eabi-nm "$@"; echo "00000000 T %s"\n' "$1" >"$work/nm"
  chmod +x "$work/nm"
  if cmake -DNM="$work/nm" -DIMAGE="$image" -DFORBID_FLOAT=$forbid -P "$check" >/dev/null 2>&1; then
    echo "FAIL: the image check did not refuse $1"; exit 1
  fi
}
refuse malloc
if [ $forbid = ON ]; then
  refuse __aeabi_fmul
  echo "image check: $(basename "$image") has no heap, stdio or floating-point helper; the check refuses malloc and __aeabi_fmul"
else
  echo "image check: $(basename "$image") has no heap, stdio or double helper; the check refuses malloc"
fi
