#!/usr/bin/env bash
# image_check.sh IMAGE CHECK_CMAKE
# The controller application links no heap, no stdio and no double-precision
# helper: target/check_image.cmake on the image must pass, the symbols the
# application needs must be there (so the check looked at the right file),
# and the same check must refuse a copy of the symbol list with malloc in it.
set -euo pipefail
image=$1 check=$2
command -v arm-none-eabi-nm >/dev/null || { echo "SKIP: arm-none-eabi-nm not installed"; exit 77; }
[ -f "$image" ] || { echo "SKIP: no application image $image"; exit 77; }
cmake -DNM=arm-none-eabi-nm -DIMAGE="$image" -P "$check"
for sym in spvs_update spvs_serial_unpack board_timer0_irq uart_write; do
  arm-none-eabi-nm "$image" | grep -qw "$sym" || { echo "FAIL: $sym missing from $image"; exit 1; }
done
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# A fake nm that adds malloc to the real list: the check must fail on it.
printf '#!/bin/sh\narm-none-eabi-nm "$@"; echo "00000000 T malloc"\n' >"$work/nm"
chmod +x "$work/nm"
if cmake -DNM="$work/nm" -DIMAGE="$image" -P "$check" >/dev/null 2>&1; then
  echo "FAIL: the image check did not refuse malloc"; exit 1
fi
echo "image check: $(basename "$image") has no heap, stdio or double helper; the check refuses malloc"
