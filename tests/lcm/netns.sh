# netns.sh - sourced by the LCM test scripts.
#
# LCM's UDP multicast must never leave this machine, so every LCM process of
# a test runs inside a network namespace of its own holding only a loopback
# interface (unshare -r works rootless), with a multicast route on lo and
# ttl=0 on the URL.  spvs_in_netns SCRIPT runs SCRIPT (sh) in such a
# namespace.  spvs_lcm_url prints a URL on a port derived from the PID, so
# parallel ctest runs never share a bus (they are in different namespaces
# anyway; the port is a second guard).

spvs_in_netns() {
  unshare -r -n sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && eval "$1"' sh "$1"
}

spvs_lcm_url() {
  echo "udpm://239.255.76.67:$((20000 + $$ % 20000))?ttl=0"
}
