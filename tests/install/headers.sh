#!/usr/bin/env bash
# headers.sh PREFIX - every installed header compiles on its own (a file
# that includes only it) with -Wall -Wextra -Werror -std=c11 -pedantic, in
# float and in double, and as C++ (extern "C").
set -euo pipefail
. "$(dirname "$0")/common.sh"
prefix=$1
spvs_tmpdir
n=0
# The fixed-point build's headers compile with its flag.
fixed_flags=()
case ${SPVS_SCALAR:-} in fixed_*) fixed_flags=(-DSPVS_USE_FIXED=1) ;; esac
for h in "$prefix"/include/spvs/*.h; do
  name=spvs/$(basename "$h")
  # (A declaration too: a header of macros alone leaves the unit empty.)
  printf '#include <%s>\ntypedef int spvs_one_header_t;\n' "$name" >"$tmp/one.c"
  for def in 0 1; do
    "$CC" -std=c11 -Wall -Wextra -Werror -pedantic -DSPVS_USE_DOUBLE=$def -I"$prefix/include" \
        "${fixed_flags[@]}" -c "$tmp/one.c" -o "$tmp/one.o" 2>"$tmp/err.txt" ||
      { cat "$tmp/err.txt" >&2; fail "$name does not compile alone (SPVS_USE_DOUBLE=$def)"; }
  done
  if command -v c++ >/dev/null; then
    cp "$tmp/one.c" "$tmp/one.cpp"
    c++ -std=c++17 -Wall -Wextra -Werror -I"$prefix/include" "${fixed_flags[@]}" -c "$tmp/one.cpp" -o "$tmp/one.o" \
        2>"$tmp/err.txt" || { cat "$tmp/err.txt" >&2; fail "$name does not compile alone as C++"; }
  fi
  n=$((n + 1))
done
[ $n -eq 4 ] || fail "$n headers under $prefix/include/spvs, want 4"
echo "$n installed headers compile on their own"
