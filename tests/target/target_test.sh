#!/usr/bin/env bash
# Cross-build the images of target/ and run them under QEMU: the Cortex-M4F
# on mps2-an386 (default) or the Cortex-M3 without FPU on mps2-an385.
#
#   tests/target/target_test.sh [--cpu CPU] [--fixed] [--accel ON|OFF] build SRC CROSS_DIR [SPVS_SIM]
#       configure and build the cross tree in CROSS_DIR: the root project
#       with the cortex-m4f (or --cpu's) preset settings (SPVS_HOST=OFF),
#       which adds target/ (images) and serial/ (the serial link's codec);
#       CPU names cmake/cpu/CPU.cmake: cortex-m4f (default) or cortex-m3;
#       --fixed: the fixed-point build (SPVS_FIXED=ON, docs/FIXED.md), whose
#       test image links no float helper and replays the host's fixed-point
#       core bit for bit;
#       --accel: the images' SPVS_ACCEL (default ON), the host build's, so
#       that an image replays the same path as the host core it is compared
#       with (the fixed-point reference sums round otherwise);
#       with SPVS_SIM (a host float32 spvs-sim), first record the replay run
#       with it (tools/make_replay.sh [--fixed]), so target and host run the
#       same core.
#   tests/target/target_test.sh run    CROSS_DIR      spvs_test.elf must exit 0
#   tests/target/target_test.sh tamper CROSS_DIR      spvs_test_tamper.elf (one golden
#       value perturbed) must report failed checks: exit 1..100, not a fault
#       (120), not a timeout (124)
#   tests/target/target_test.sh float-check CROSS_DIR CHECK_CMAKE
#       the image check's no-float mode bites: target/check_image.cmake
#       passes on spvs_test.elf in its default mode, and with
#       FORBID_FLOAT=ON refuses spvs_test.elf and libspvs_core.a, naming
#       __aeabi_fmul (a soft-float build, e.g. --cpu cortex-m3)
#
# run and tamper start the board the cross build was made for
# (CROSS_DIR/target/qemu_machine, written by target/CMakeLists.txt).
# Exit status 0 when the expectation holds, 2 on a usage error.  Each QEMU
# run is bounded by `timeout 120`, so a hung guest fails instead of
# blocking ctest.
set -euo pipefail

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
}

die_usage() {
  echo "target_test: $1 (--help for usage)" >&2
  exit 2
}

qemu_machine() {
  local file=$1/target/qemu_machine
  [ -f "$file" ] || { echo "target_test: no $file: build $1 first (target_test.sh build)" >&2; exit 1; }
  cat "$file"
}

qemu_run() {
  local machine=$1 elf=$2
  [ -f "$elf" ] || { echo "target_test: no image $elf" >&2; return 1; }
  set +e
  timeout 120 qemu-system-arm -M "$machine" -nographic \
    -semihosting-config enable=on,target=native -kernel "$elf"
  local rc=$?
  set -e
  return $rc
}

cpu=cortex-m4f
fixed=OFF
accel=ON
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --cpu)
      [ $# -ge 2 ] || die_usage "--cpu needs a CPU name"
      cpu=$2
      shift 2
      ;;
    --fixed)
      fixed=ON
      shift
      ;;
    --accel)
      [ $# -ge 2 ] || die_usage "--accel needs ON or OFF"
      case "$2" in
        ON|OFF) accel=$2 ;;
        *) die_usage "--accel: '$2' is not ON or OFF" ;;
      esac
      shift 2
      ;;
    *) break ;;
  esac
done

mode=${1:-}
case "$mode" in
  build)
    [ $# -ge 3 ] || die_usage "build needs SRC and CROSS_DIR"
    src=$(cd "$2" && pwd)
    cross=$3
    sim=${4:-}
    [ -f "$src/cmake/cpu/$cpu.cmake" ] ||
      die_usage "unknown CPU '$cpu' (cmake/cpu/ has: $(cd "$src/cmake/cpu" && ls | sed 's/\.cmake$//' | tr '\n' ' '))"
    extra=()
    replay_opt=()
    if [ $fixed = ON ]; then
      replay_opt=(--fixed)
    fi
    if [ -n "$sim" ]; then
      "$src/tools/make_replay.sh" "${replay_opt[@]}" "$(dirname "$(dirname "$sim")")" "$cross/replay"
      extra=(-DSPVS_REPLAY_DIR="$cross/replay")
    else
      # The committed recording of this core (an existing tree keeps a
      # folder given before otherwise).
      extra=(-DSPVS_REPLAY_DIR="$src/tests/golden$([ $fixed = ON ] && echo /fixed)")
    fi
    cmake -S "$src" -B "$cross" -G Ninja \
      -DCMAKE_TOOLCHAIN_FILE="$src/cmake/toolchain-arm-none-eabi.cmake" \
      -DSPVS_HOST=OFF -DSPVS_DOUBLE=OFF -DSPVS_FIXED=$fixed -DSPVS_CPU="$cpu" \
      -DSPVS_ACCEL=$accel -DCMAKE_BUILD_TYPE=MinSizeRel "${extra[@]}" >/dev/null
    cmake --build "$cross"
    # The post-build step already refuses double helpers; say it here too.
    for elf in "$cross"/target/*.elf; do
      # The Unity test images (spvs_unit*.elf, target/unity.cmake) carry
      # the tests' double references, not product code.
      case $(basename "$elf") in spvs_unit*) continue ;; esac
      if arm-none-eabi-nm "$elf" | grep -E '__aeabi_(d|f2d)'; then
        echo "target_test: $elf contains double-precision operations" >&2
        exit 1
      fi
    done
    ;;
  run)
    [ $# -ge 2 ] || die_usage "run needs CROSS_DIR"
    if qemu_run "$(qemu_machine "$2")" "$2/target/spvs_test.elf"; then
      exit 0
    else
      rc=$?
      echo "target_test: spvs_test.elf exited with $rc (0 expected)" >&2
      exit 1
    fi
    ;;
  tamper)
    [ $# -ge 2 ] || die_usage "tamper needs CROSS_DIR"
    if qemu_run "$(qemu_machine "$2")" "$2/target/spvs_test_tamper.elf"; then
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
  float-check)
    [ $# -ge 3 ] || die_usage "float-check needs CROSS_DIR and CHECK_CMAKE"
    cross=$2 check=$3
    elf=$cross/target/spvs_test.elf
    core=$cross/firmware/libspvs_core.a
    for f in "$elf" "$core" "$check"; do
      [ -f "$f" ] || { echo "target_test: no $f" >&2; exit 1; }
    done
    # The image must carry the helper, or a refusal would prove nothing.
    if ! arm-none-eabi-nm "$elf" | grep -qw __aeabi_fmul; then
      echo "target_test: $elf links no __aeabi_fmul: not a soft-float build" >&2
      exit 1
    fi
    if ! cmake -DNM=arm-none-eabi-nm -DIMAGE="$elf" -P "$check"; then
      echo "target_test: the default image check refused $elf" >&2
      exit 1
    fi
    for f in "$elf" "$core"; do
      set +e
      out=$(cmake -DNM=arm-none-eabi-nm -DIMAGE="$f" -DFORBID_FLOAT=ON -P "$check" 2>&1)
      rc=$?
      set -e
      if [ "$rc" -eq 0 ]; then
        echo "target_test: FORBID_FLOAT=ON accepted $f, which calls float helpers" >&2
        exit 1
      fi
      if ! grep -q "__aeabi_fmul" <<<"$out"; then
        echo "target_test: FORBID_FLOAT=ON refused $f without naming __aeabi_fmul:" >&2
        echo "$out" >&2
        exit 1
      fi
      echo "target_test: FORBID_FLOAT=ON refuses $(basename "$f") as it must"
    done
    ;;
  "")
    die_usage "no mode given"
    ;;
  *)
    die_usage "unknown mode '$mode'"
    ;;
esac
