#!/usr/bin/env bash
# Installs what spvs needs on a Debian machine (root, or sudo).  Safe to re-run:
# packages already present are skipped quickly.
set -euo pipefail

PKGS=(cmake ninja-build gcc g++ make pkg-config libcmocka-dev
      liblcm-dev liblcm-bin libglib2.0-dev
      python3 python3-numpy python3-matplotlib python3-venv iproute2
      libopencv-dev
      opencv-doc visp-images-data
      gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm
      valgrind clang libclang-rt-14-dev
      liblcm-java libjchart2d-java default-jdk-headless default-jre xvfb imagemagick
      cyclonedds-dev cyclonedds-tools libfastrtps-dev fastddsgen)


# Unity (the unit-test framework of the core's tests, host and target) is
# in no package of its own: Debian's source package of cJSON carries it in
# tests/unity/.  A deb-src entry beside each of the machine's deb entries
# (the same URIs, suites, components and keyring, in a file of its own),
# then apt-get source (apt checks the signatures) and the original tarball
# unpacked; its tests/unity/src/ (unity.c, unity.h, unity_internals.h),
# examples/unity_config.h and the licence go to .deps/unity/ (ignored by
# git).  Skipped when they are there.
UNITY_DIR="$(cd "$(dirname "$0")/.." && pwd)/.deps/unity"
UNITY_PKG=cjson
fetch_unity() {
  if [ -f "$UNITY_DIR/src/unity.c" ] && [ -f "$UNITY_DIR/src/unity.h" ] &&
     [ -f "$UNITY_DIR/src/unity_internals.h" ]; then
    echo "[deps] Unity present in $UNITY_DIR"
    return 0
  fi
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  local list=/etc/apt/sources.list.d/spvs-deb-src.sources
  if [ ! -f "$list" ]; then
    local tmp
    tmp=$(mktemp)
    # deb822 files: every stanza whose Types holds deb, again as deb-src.
    for f in /etc/apt/sources.list.d/*.sources; do
      [ -f "$f" ] && [ "$f" != "$list" ] || continue
      awk 'BEGIN { RS = ""; ORS = "\n\n" }
           /(^|\n)Types:[^\n]*(^|[ \t])deb([ \t]|\n|$)/ {
             sub(/(^|\n)Types:[^\n]*/, "\nTypes: deb-src"); sub(/^\n/, ""); print }' "$f" >>"$tmp"
    done
    # One-line lists: each deb line again as deb-src.
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
      [ -f "$f" ] || continue
      grep -E '^[[:space:]]*deb[[:space:]]' "$f" | sed -E 's/^[[:space:]]*deb[[:space:]]/deb-src /' \
        >>"$tmp.list" || true
    done
    if [ -s "$tmp" ]; then
      $sudo install -m 644 "$tmp" "$list"
    fi
    if [ -s "$tmp.list" ]; then
      $sudo install -m 644 "$tmp.list" /etc/apt/sources.list.d/spvs-deb-src.list
    fi
    rm -f "$tmp" "$tmp.list"
  fi
  echo "[deps] fetching Unity from Debian's source package $UNITY_PKG"
  $sudo apt-get update -qq -o DPkg::Lock::Timeout=900
  local work
  work=$(mktemp -d)
  chmod 755 "$work"
  (cd "$work" && apt-get source -qq --download-only "$UNITY_PKG" >/dev/null)
  local orig
  orig=$(ls "$work"/"${UNITY_PKG}"_*.orig.tar.* 2>/dev/null | head -n 1)
  if [ -z "$orig" ]; then
    echo "[deps] apt-get source $UNITY_PKG gave no original tarball" >&2
    rm -rf "$work"
    return 1
  fi
  mkdir -p "$work/src"
  tar -xf "$orig" -C "$work/src"
  local top
  top=$(find "$work/src" -path '*/tests/unity/src/unity.c' | head -n 1)
  if [ -z "$top" ]; then
    echo "[deps] $orig holds no tests/unity/src/unity.c" >&2
    rm -rf "$work"
    return 1
  fi
  top=$(dirname "$(dirname "$top")")
  # The package's layout is kept: its unity_internals.h includes
  # ../examples/unity_config.h.
  rm -rf "$UNITY_DIR"
  mkdir -p "$UNITY_DIR/src"
  cp "$top/src/unity.c" "$top/src/unity.h" "$top/src/unity_internals.h" "$UNITY_DIR/src/"
  if [ -f "$top/examples/unity_config.h" ]; then
    mkdir -p "$UNITY_DIR/examples"
    cp "$top/examples/unity_config.h" "$UNITY_DIR/examples/"
  fi
  if [ -f "$top/docs/license.txt" ]; then
    cp "$top/docs/license.txt" "$UNITY_DIR/license.txt"
  fi
  basename "$orig" >"$UNITY_DIR/SOURCE"
  rm -rf "$work"
  echo "[deps] Unity in $UNITY_DIR (from $(cat "$UNITY_DIR/SOURCE"))"
}

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PKGS[@]} packages present"
  fetch_unity
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "[deps] installing: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq -o DPkg::Lock::Timeout=900 --no-install-recommends "${missing[@]}" >/dev/null
fetch_unity
echo "[deps] done"
