# common.sh - sourced by the install tests (tests/install.cmake).
#
# Environment from ctest: SPVS_SOURCE (the source tree), SPVS_BUILD (the
# build tree under test), SPVS_VERSION, SPVS_SCALAR (float or double),
# CMAKE (the cmake program), SPVS_GENERATOR, CC (the C compiler).

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

# A scratch folder of this test's own, removed at exit.
spvs_tmpdir() {
  tmp=$(mktemp -d "${TMPDIR:-/tmp}/spvs-install.XXXXXX") || fail "mktemp"
  trap 'rm -rf "$tmp"' EXIT
}

# value KEY FILE: the value of a "KEY value" line of the consumer's output.
value() {
  awk -v k="$1" '$1 == k { print $2; exit }' "$2"
}

# check_consumer_output FILE SCALAR: what examples/consumer printed, against
# the numbers the scene fixes (examples/consumer/main.c).
check_consumer_output() {
  out=$1
  want_scalar=$2
  [ "$(value result "$out")" = ok ] || fail "the consumer's own checks failed: $(cat "$out")"
  [ "$(value version "$out")" = "$SPVS_VERSION" ] ||
    fail "version $(value version "$out"), want $SPVS_VERSION (spvs/abi.h)"
  [ "$(value scalar "$out")" = "$want_scalar" ] ||
    fail "scalar $(value scalar "$out"), want $want_scalar"
  [ "$(value matches "$out")" = 125 ] || fail "matches $(value matches "$out"), want 125"
  [ "$(value inliers "$out")" = 100 ] || fail "inliers $(value inliers "$out"), want 100"
  [ "$(value step "$out")" = 1 ] || fail "step $(value step "$out"), want 1 (rotate)"
  awk -v v="$(value v_m_s "$out")" -v w="$(value w_rad_s "$out")" \
      -v we="$(value w_expected_rad_s "$out")" \
      -v ex="$(value e_x_px "$out")" -v exe="$(value e_x_expected_px "$out")" '
    function abs(x) { return x < 0 ? -x : x }
    BEGIN {
      if (v + 0 != 0) { print "v = " v " m/s, want 0"; exit 1 }
      if (!(w > 0) || abs(w - we) > 1e-3 * we) { print "w = " w " rad/s, want " we; exit 1 }
      if (abs(ex - exe) > 0.05) { print "e_x = " ex " px, want " exe " +- 0.05"; exit 1 }
    }' >&2 || fail "command or epipole off (output: $out)"
  echo "consumer: $(tr '\n' ' ' <"$out")"
}
