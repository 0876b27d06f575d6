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
      liblcm-java libjchart2d-java default-jdk-headless default-jre xvfb imagemagick)

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PKGS[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "[deps] installing: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq -o DPkg::Lock::Timeout=900 --no-install-recommends "${missing[@]}" >/dev/null
echo "[deps] done"
