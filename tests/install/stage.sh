#!/usr/bin/env bash
# stage.sh PREFIX - installs the build under test into PREFIX (a folder of
# this test alone, emptied first) and checks the installed tree: every core
# header, the library, the CMake package, spvs.pc, the programs, the message
# types and the documents.  The other install tests use PREFIX read-only
# (ctest fixture spvs_installed).
set -euo pipefail
. "$(dirname "$0")/common.sh"
prefix=$1
rm -rf "$prefix"
mkdir -p "$prefix"
"$CMAKE" --install "$SPVS_BUILD" --prefix "$prefix" >"$prefix.log" 2>&1 ||
  { cat "$prefix.log" >&2; fail "cmake --install failed"; }

# The lib dir is lib or lib64 or lib/<triplet> depending on the platform.
libspvs=$(find "$prefix" -name libspvs_core.a | head -n 1)
[ -n "$libspvs" ] || fail "no libspvs_core.a under $prefix"
libdir=$(dirname "$libspvs")
for f in "$libdir/cmake/spvs/spvsConfig.cmake" "$libdir/cmake/spvs/spvsConfigVersion.cmake" \
         "$libdir/cmake/spvs/spvsTargets.cmake" "$libdir/pkgconfig/spvs.pc" \
         include/spvs/abi.h share/spvs/cmake/toolchain-arm-none-eabi.cmake \
         share/spvs/cmake/cpu/cortex-m4f.cmake \
         share/spvs/lcm_types/matches_t.lcm share/spvs/lcm_types/cmd_t.lcm \
         share/spvs/lcm_types/state_t.lcm share/doc/spvs/README.md share/doc/spvs/INSTALL.md; do
  case $f in /*) p=$f ;; *) p=$prefix/$f ;; esac
  [ -f "$p" ] || fail "not installed: ${p#"$prefix"/}"
done

# The message types for Python and, where the build made it, for Java.
[ -f "$prefix/share/spvs/python/spvs/state_t.py" ] || fail "not installed: share/spvs/python/spvs/"
if [ -f "$SPVS_BUILD/tools/lcm_spy/spvs_lcm_types.jar" ]; then
  [ -f "$prefix/share/spvs/java/spvs_lcm_types.jar" ] || fail "not installed: share/spvs/java/spvs_lcm_types.jar"
fi

# The installed API is the four headers of firmware/include/spvs/ (spvs.h,
# status.h, abi.h, spvs_config.h), in every build, and nothing from src/.
for h in spvs.h status.h abi.h spvs_config.h; do
  cmp -s "$SPVS_SOURCE/firmware/include/spvs/$h" "$prefix/include/spvs/$h" ||
    fail "header $h missing or different"
done
n_inst=$(find "$prefix/include" -name '*.h' | wc -l)
[ "$n_inst" -eq 4 ] || fail "$n_inst installed headers, want 4"
# Each includes only the others (and the C library's).
for h in "$prefix"/include/spvs/*.h; do
  bad=$(grep -oE '#include [<"][^>"]+[>"]' "$h" | grep -vE 'spvs/(spvs|status|abi|spvs_config)\.h|<[a-z]+\.h>' || true)
  [ -z "$bad" ] || fail "$(basename "$h") includes what is not installed: $bad"
done
# At most 12 functions, all of them spvs_ names.
n_fn=$(cat "$prefix"/include/spvs/*.h | grep -cE '^(SPVS_NODISCARD )?[a-z_]+[a-z_0-9 ]*[ *]spvs_[a-z0-9_]+\(')
[ "$n_fn" -le 12 ] || fail "$n_fn functions declared by the installed headers, want at most 12"

# The library holds the core's objects and spvs_init under its ABI name.
nm -g "$libspvs" | grep -q " T spvs_update$" || fail "spvs_update not defined in $libspvs"
abi=$(nm -g "$libspvs" | awk '$2 == "T" && $3 ~ /^spvs_init__/ { print $3 }')
case $abi in
  spvs_init__${SPVS_SCALAR}_matches*) ;;
  *) fail "spvs_init's ABI name is '$abi', want spvs_init__${SPVS_SCALAR}_..." ;;
esac

# abi.h says the project's version.
[ "$(grep -E '^#define SPVS_VERSION_(MAJOR|MINOR|PATCH) ' "$prefix/include/spvs/abi.h" |
     awk '{print $3}' | paste -sd.)" = "$SPVS_VERSION" ] ||
  fail "abi.h does not say $SPVS_VERSION"

# The programs run from the prefix.
for p in spvs-sim spvs-node spvs-zenoh-bridge spvs-lcm-spy; do
  [ -x "$prefix/bin/$p" ] || fail "not installed: bin/$p"
done
"$prefix/bin/spvs-sim" --help | grep -q -- "--method" || fail "installed spvs-sim --help"
"$prefix/bin/spvs-node" --help | grep -q -- "--lcm-url" || fail "installed spvs-node --help"
SPVS_PYTHON=/usr/bin/python3 "$prefix/bin/spvs-zenoh-bridge" --help | grep -q -- "--robot" ||
  fail "installed spvs-zenoh-bridge --help"
rc=0
"$prefix/bin/spvs-sim" --no-such-option >/dev/null 2>&1 || rc=$?
[ $rc -eq 2 ] || fail "installed spvs-sim exits $rc on a bad option, want 2"
echo "installed into $prefix: $(find "$prefix" -type f | wc -l) files, $abi"
