#!/usr/bin/env sh
# Runs a Zenoh test inside a private network namespace that has only
# loopback, with multicast routed to lo (LCM's udpm, ttl=0), after making
# sure the project's venv exists (scripts/setup_venv.sh needs PyPI the first
# time, so it runs before the namespace is entered).
# usage: netns.sh REPO_ROOT SECONDS COMMAND [ARGS...]
# Exit status: the command's; 77 (skipped) when no namespace can be made.
set -eu
root="$1"; limit="$2"; shift 2
"$root/scripts/setup_venv.sh"
if ! unshare -r -n true 2>/dev/null; then
  echo "skipped: cannot create a network namespace (unshare -r -n)"
  exit 77
fi
# The whole test is bounded; the test itself bounds each process too.
exec timeout -k 5 "$limit" unshare -r -n sh -c '
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 77
  exec "$@"' netns "$@"
