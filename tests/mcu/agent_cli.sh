#!/usr/bin/env bash
# agent_cli.sh SPVS_SERIAL_AGENT
# spvs-serial-agent's command line: --help exits 0 with the usage; bad
# options exit 2 with a one-line error; a device that is not there exits 1
# once --reconnect runs out, naming the device.
set -uo pipefail
agent=$1
fails=0
check() { # expected-status description command...
  local want=$1 what=$2; shift 2
  local out rc
  out=$("$@" 2>&1); rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL: $what: exit $rc, expected $want: $out"; fails=$((fails + 1))
  else
    echo "ok: $what (exit $rc): $(echo "$out" | head -n 1)"
  fi
}
check 0 "--help" "$agent" --help
"$agent" --help | grep -q -- "--device DEV" || { echo "FAIL: --help lacks --device"; fails=$((fails + 1)); }
check 2 "no --device" "$agent"
check 2 "unknown option" "$agent" --device tcp:127.0.0.1:1 --bogus 1
check 2 "baud not a standard rate" "$agent" --device /dev/null --baud 12345
check 2 "method 4" "$agent" --device tcp:127.0.0.1:1 --method 4
check 2 "seed negative" "$agent" --device tcp:127.0.0.1:1 --seed -1
check 2 "alpha zero" "$agent" --device tcp:127.0.0.1:1 --alpha 0
check 2 "watchdog below 50 ms" "$agent" --device tcp:127.0.0.1:1 --watchdog-ms 49
check 2 "watchdog above 10 s" "$agent" --device tcp:127.0.0.1:1 --watchdog-ms 10001
check 2 "watchdog not an integer" "$agent" --device tcp:127.0.0.1:1 --watchdog-ms 300.5
check 2 "option without value" "$agent" --device
check 2 "stray argument" "$agent" foo
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# The LCM URL is memq:// (in process), so no multicast is needed here.
check 1 "device not there" "$agent" --device "unix:$work/none.sock" --reconnect 0.3 --lcm-url memq://
check 1 "a folder" "$agent" --device "$work" --lcm-url memq://
: >"$work/file"
check 1 "not a terminal" "$agent" --device "$work/file" --lcm-url memq://
[ $fails -eq 0 ] && echo "agent_cli: all refusals as documented"
exit $fails
