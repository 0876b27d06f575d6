#!/usr/bin/env bash
# Runs a Unity test image of target/unity.cmake under QEMU and prints what
# it says; ctest judges Unity's summary line (tests/unity_target.cmake).
#
#   tests/target/unity_run.sh CROSS_DIR IMAGE_NAME
#
# The board is the one the cross build was made for
# (CROSS_DIR/target/qemu_machine).  Exit status: the image's (Unity's count
# of failed tests), 124 when QEMU ran over `timeout 600`, 2 on a usage error.
set -euo pipefail
if [ $# -ne 2 ] || [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
  [ $# -eq 2 ] || exit 2
  exit 0
fi
cross=$1
elf=$cross/target/$2.elf
machine_file=$cross/target/qemu_machine
for f in "$machine_file" "$elf"; do
  [ -f "$f" ] || { echo "unity_run: no $f: build $cross first (target_test.sh build)" >&2; exit 1; }
done
exec timeout 600 qemu-system-arm -M "$(cat "$machine_file")" -nographic \
  -semihosting-config enable=on,target=native -kernel "$elf"
