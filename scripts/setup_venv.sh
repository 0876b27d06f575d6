#!/usr/bin/env bash
# Creates .venv/ at the top of the repository with the Python packages of the
# Zenoh side (sim_host/zenoh/requirements.txt) and of the rosbag2 tools
# (tools/rosbag/requirements.txt) and checks that they import.
# Idempotent: when the venv already holds what the requirements file asks for
# (a stamp file records its hash), it only re-checks the imports and exits.
# Needs /usr/bin/python3 with venv (Debian: python3-venv) and, the first time,
# network access to PyPI.
# Usage: scripts/setup_venv.sh [--force]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
venv="$root/.venv"
req="$root/sim_host/zenoh/requirements.txt"
req_rosbag="$root/tools/rosbag/requirements.txt"
stamp="$venv/.spvs-requirements.sha256"
py="$venv/bin/python"

if [ "${1:-}" = "--force" ]; then
  rm -f "$stamp"
elif [ $# -gt 0 ]; then
  echo "setup_venv.sh: unknown argument '$1' (usage: setup_venv.sh [--force])" >&2
  exit 2
fi

want="$(cat "$req" "$req_rosbag" | sha256sum | cut -d' ' -f1)"
check='import zenoh, lcm, mcap, mcap_ros2, rosbags; print(zenoh.__version__ if hasattr(zenoh, "__version__") else "zenoh")'

# Parallel test jobs may call this at the same time: one installs, the others
# wait for it (bounded by flock's timeout).
mkdir -p "$venv"
exec 9>"$venv/.setup.lock"
if ! flock -w 600 9; then
  echo "setup_venv.sh: another setup still holds $venv/.setup.lock after 600 s" >&2
  exit 1
fi

if [ -x "$py" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ] &&
   "$py" -c "$check" >/dev/null 2>&1; then
  exit 0
fi

if [ ! -x "$py" ]; then
  echo "[venv] creating $venv"
  if ! /usr/bin/python3 -m venv "$venv"; then
    echo "setup_venv.sh: 'python3 -m venv' failed (Debian: install python3-venv)" >&2
    exit 1
  fi
fi
echo "[venv] installing $(grep -hv '^#' "$req" "$req_rosbag" | tr '\n' ' ')"
if ! "$py" -m pip install --quiet --disable-pip-version-check -r "$req" -r "$req_rosbag"; then
  echo "setup_venv.sh: pip install failed (is PyPI reachable?)" >&2
  exit 1
fi
if ! "$py" -c "$check" >/dev/null; then
  echo "setup_venv.sh: the installed packages do not import" >&2
  exit 1
fi
echo "$want" >"$stamp"
echo "[venv] ready: $py"
