#!/usr/bin/env bash
# Cross-build the Cortex-M4F images and run them under QEMU (mps2-an386).
#
#   tests/target/target_test.sh build  SRC CROSS_DIR [SPVS_SIM]
#       configure and build the cross tree in CROSS_DIR: the root project
#       with the cortex-m4f preset's settings (SPVS_HOST=OFF), which adds
#       target/ (images) and serial/ (the serial link's codec);
#       with SPVS_SIM (a host float32 spvs-sim), first record the replay run
#       with it (tools/make_replay.sh), so target and host run the same core.
#   tests/target/target_test.sh run    CROSS_DIR      spvs_test.elf must exit 0
#   tests/target/target_test.sh tamper CROSS_DIR      spvs_test_tamper.elf (one golden
#       value perturbed) must report failed checks: exit 1..100, not a fault
#       (120), not a timeout (124)
#
# Exit status 0 when the expectation holds.  Each QEMU run is bounded by
# `timeout 120`, so a hung guest fails instead of blocking ctest.
set -euo pipefail

qemu_run() {
  local elf=$1
  set +e
  timeout 120 qemu-system-arm -M mps2-an386 -nographic \
    -semihosting-config enable=on,target=native -kernel "$elf"
  local rc=$?
  set -e
  return $rc
}

mode=${1:-}
case "$mode" in
  build)
    src=$(cd "$2" && pwd)
    cross=$3
    sim=${4:-}
    extra=()
    if [ -n "$sim" ]; then
      "$src/tools/make_replay.sh" "$(dirname "$(dirname "$sim")")" "$cross/replay"
      extra=(-DSPVS_REPLAY_DIR="$cross/replay")
    fi
    cmake -S "$src" -B "$cross" -G Ninja \
      -DCMAKE_TOOLCHAIN_FILE="$src/cmake/toolchain-arm-none-eabi.cmake" \
      -DSPVS_HOST=OFF -DSPVS_DOUBLE=OFF -DSPVS_CPU=cortex-m4f \
      -DCMAKE_BUILD_TYPE=MinSizeRel "${extra[@]}" >/dev/null
    cmake --build "$cross"
    # The post-build step already refuses double helpers; say it here too.
    for elf in "$cross"/target/*.elf; do
      if arm-none-eabi-nm "$elf" | grep -E '__aeabi_(d|f2d)'; then
        echo "target_test: $elf contains double-precision operations" >&2
        exit 1
      fi
    done
    ;;
  run)
    if qemu_run "$2/target/spvs_test.elf"; then
      exit 0
    else
      rc=$?
      echo "target_test: spvs_test.elf exited with $rc (0 expected)" >&2
      exit 1
    fi
    ;;
  tamper)
    if qemu_run "$2/target/spvs_test_tamper.elf"; then
      rc=0
    else
      rc=$?
    fi
    if [ "$rc" -ge 1 ] && [ "$rc" -le 100 ]; then
      echo "target_test: the tampered image failed as it must (status $rc)"
      exit 0
    fi
    echo "target_test: the tampered image exited with $rc (1..100 expected)" >&2
    exit 1
    ;;
  *)
    echo "usage: target_test.sh build SRC CROSS_DIR [SPVS_SIM] | run CROSS_DIR | tamper CROSS_DIR" >&2
    exit 2
    ;;
esac
