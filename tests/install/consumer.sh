#!/usr/bin/env bash
# consumer.sh MODE [PREFIX] - builds examples/consumer in a folder of its own
# and checks what it prints (common.sh, check_consumer_output).
#   cmake PREFIX      find_package(spvs) against the installed PREFIX
#   pkgconfig PREFIX  cc $(pkg-config --cflags) main.c $(pkg-config --libs spvs)
#   fetch             FetchContent of the source tree, SPVS_HOST=OFF (core only)
set -euo pipefail
. "$(dirname "$0")/common.sh"
mode=$1
prefix=${2:-}
spvs_tmpdir
example=$SPVS_SOURCE/examples/consumer
case $mode in
  cmake)
    "$CMAKE" -S "$example" -B "$tmp/b" -G "$SPVS_GENERATOR" -DCMAKE_PREFIX_PATH="$prefix" \
        >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log" >&2; fail "configure"; }
    "$CMAKE" --build "$tmp/b" >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log" >&2; fail "build"; }
    exe=$tmp/b/spvs-consumer ;;
  pkgconfig)
    pc=$(find "$prefix" -name spvs.pc | head -n 1)
    export PKG_CONFIG_PATH=$(dirname "$pc")
    [ "$(pkg-config --modversion spvs)" = "$SPVS_VERSION" ] ||
      fail "pkg-config --modversion spvs says $(pkg-config --modversion spvs)"
    flags=$(pkg-config --cflags --libs spvs)
    echo "pkg-config --cflags --libs spvs: $flags"
    # shellcheck disable=SC2086  # the flags are words
    "$CC" -std=c11 -Wall -Wextra -Werror "$example/main.c" -o "$tmp/spvs-consumer" $flags ||
      fail "building with pkg-config's flags"
    exe=$tmp/spvs-consumer ;;
  fetch)
    # FETCHCONTENT_SOURCE_DIR_SPVS makes FetchContent use this tree instead
    # of cloning SPVS_GIT_REPOSITORY: the README's snippet, on the tree under test.
    "$CMAKE" -S "$example" -B "$tmp/b" -G "$SPVS_GENERATOR" -DSPVS_CONSUMER_FETCH=ON \
        -DSPVS_GIT_REPOSITORY=unused -DFETCHCONTENT_SOURCE_DIR_SPVS="$SPVS_SOURCE" \
        -DSPVS_DOUBLE="$(case $SPVS_SCALAR in *double) echo ON ;; *) echo OFF ;; esac)" \
        -DSPVS_FIXED="$(case $SPVS_SCALAR in fixed_*) echo ON ;; *) echo OFF ;; esac)" \
        >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log" >&2; fail "configure"; }
    "$CMAKE" --build "$tmp/b" >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log" >&2; fail "build"; }
    # The core only: no host part was configured or built.
    for d in sim_host tests lcm_types; do
      [ ! -e "$tmp/b/_deps/spvs-build/$d" ] || fail "FetchContent with SPVS_HOST=OFF configured $d"
    done
    grep -q "libspvs_core.a" "$tmp/build.log" || fail "the core was not built"
    if "$CMAKE" --build "$tmp/b" --target help | grep -q -E "spvs-sim|spvs-node|cmocka"; then
      fail "FetchContent with SPVS_HOST=OFF has host targets"
    fi
    exe=$tmp/b/spvs-consumer ;;
  *) fail "unknown mode $mode" ;;
esac
rc=0
"$exe" >"$tmp/out.txt" 2>"$tmp/err.txt" || rc=$?
[ $rc -eq 0 ] || { cat "$tmp/out.txt" "$tmp/err.txt" >&2; fail "spvs-consumer exited $rc"; }
check_consumer_output "$tmp/out.txt" "$SPVS_SCALAR"
