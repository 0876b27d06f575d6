#!/usr/bin/env bash
# abi_mismatch.sh MODE [PREFIX] - a consumer compiled with another
# configuration than the library must not link, and the linker's message
# must name the configuration it wanted (spvs/abi.h).  A test that must fail:
# it passes only when the build fails for that reason.
#   scalar          against a library built here with the other scalar type
#                   (a double library for a float build under test, a float
#                   one for a double or a fixed-point build): a consumer compiled for this build's
#                   type must fail; with the library's pkg-config flags, or
#                   through find_package, it links and runs (the control).
#   matches PREFIX  find_package(spvs) against PREFIX, the consumer compiled
#                   with -DSPVS_MAX_MATCHES=128.
set -euo pipefail
. "$(dirname "$0")/common.sh"
mode=$1
prefix=${2:-}
spvs_tmpdir
example=$SPVS_SOURCE/examples/consumer

# expect_link_failure LOG WANTED_NAME_PREFIX
expect_link_failure() {
  grep -q "undefined reference to .$2" "$1" || {
    cat "$1" >&2
    fail "the build did not fail with an undefined reference to $2..."
  }
  echo "refused as wanted: $(grep -o "undefined reference to .$2[A-Za-z0-9_]*" "$1" | head -n 1)"
}

case $mode in
  scalar)
    # (For the fixed-point build, the other library is the float one.)
    case $SPVS_SCALAR in
      double|fixed_*) lib=float libdouble=OFF ;;
      *) lib=double libdouble=ON ;;
    esac
    "$CMAKE" -S "$SPVS_SOURCE" -B "$tmp/lib" -G "$SPVS_GENERATOR" -DSPVS_HOST=OFF \
        -DSPVS_DOUBLE=$libdouble -DCMAKE_BUILD_TYPE=Release >"$tmp/lib.log" 2>&1 &&
      "$CMAKE" --build "$tmp/lib" >>"$tmp/lib.log" 2>&1 &&
      "$CMAKE" --install "$tmp/lib" --prefix "$tmp/prefix" >>"$tmp/lib.log" 2>&1 ||
      { cat "$tmp/lib.log" >&2; fail "building the $lib library"; }
    libspvs=$(find "$tmp/prefix" -name libspvs_core.a | head -n 1)
    nm -g "$libspvs" | grep -q " T spvs_init__${lib}_" || fail "$libspvs has no spvs_init__${lib}_..."
    export PKG_CONFIG_PATH=$(dirname "$(find "$tmp/prefix" -name spvs.pc | head -n 1)")
    # The control: with the library's own flags the consumer links and runs.
    # shellcheck disable=SC2086
    "$CC" -std=c11 "$example/main.c" -o "$tmp/ok" $(pkg-config --cflags --libs spvs) ||
      fail "the consumer does not build with the $lib library's pkg-config flags"
    "$tmp/ok" >"$tmp/ok.txt" || fail "the consumer built for the $lib library fails"
    check_consumer_output "$tmp/ok.txt" "$lib"
    # ... and so it does through find_package: spvs::core carries the type.
    "$CMAKE" -S "$example" -B "$tmp/cm" -G "$SPVS_GENERATOR" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
        >"$tmp/cm.log" 2>&1 && "$CMAKE" --build "$tmp/cm" >>"$tmp/cm.log" 2>&1 ||
      { cat "$tmp/cm.log" >&2; fail "the consumer does not build with find_package against the $lib library"; }
    "$tmp/cm/spvs-consumer" >"$tmp/cm.txt" || fail "the find_package consumer of the $lib library fails"
    check_consumer_output "$tmp/cm.txt" "$lib"
    # The mismatch: this build's scalar type against the other library.
    def=$([ "$SPVS_SCALAR" = double ] && echo 1 || echo 0)
    this=()
    case $SPVS_SCALAR in
      # The fixed-point build's headers from the source tree, as its install
      # lays them out (spvs.h includes spvs_q.h).
      fixed_*) this=(-DSPVS_USE_FIXED=1 -I"$SPVS_SOURCE/firmware/src/fixed") ;;
    esac
    rc=0
    "$CC" -std=c11 -DSPVS_USE_DOUBLE=$def "${this[@]}" -I"$tmp/prefix/include" "$example/main.c" \
        -o "$tmp/bad" -L"$(dirname "$libspvs")" -lspvs_core -lm >"$tmp/bad.log" 2>&1 || rc=$?
    [ $rc -ne 0 ] && [ ! -e "$tmp/bad" ] ||
      fail "a $SPVS_SCALAR consumer linked against the $lib library"
    expect_link_failure "$tmp/bad.log" "spvs_init__${SPVS_SCALAR}_matches" ;;
  matches)
    rc=0
    "$CMAKE" -S "$example" -B "$tmp/b" -G "$SPVS_GENERATOR" -DCMAKE_PREFIX_PATH="$prefix" \
        -DCMAKE_C_FLAGS=-DSPVS_MAX_MATCHES=128 >"$tmp/build.log" 2>&1 || fail "configure"
    "$CMAKE" --build "$tmp/b" >>"$tmp/build.log" 2>&1 || rc=$?
    [ $rc -ne 0 ] && [ ! -e "$tmp/b/spvs-consumer" ] ||
      fail "a consumer with SPVS_MAX_MATCHES=128 linked against the library's 256"
    expect_link_failure "$tmp/build.log" "spvs_init__${SPVS_SCALAR}_matches128_" ;;
  *) fail "unknown mode $mode" ;;
esac
