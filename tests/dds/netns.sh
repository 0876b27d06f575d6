# netns.sh - sourced by the DDS test scripts.
#
# DDS traffic never leaves this machine: every DDS process of a test runs
# inside a network namespace of its own holding only a loopback interface
# (unshare -r works rootless), with multicast enabled on lo and a multicast
# route to it, and Cyclone DDS pinned to lo (spvs_dds_uri).  Each test also
# takes its own ROS_DOMAIN_ID, so ctest -j2 runs never hear each other even
# outside the namespace.  spvs_dds_in_netns SCRIPT runs SCRIPT (sh) there.

spvs_dds_in_netns() {
  unshare -r -n sh -c 'ip link set lo up && ip link set lo multicast on &&
    ip route add 224.0.0.0/4 dev lo && eval "$1"' sh "$1"
}

# Cyclone DDS on lo only, multicast allowed there (SPDP discovery).
spvs_dds_uri() {
  echo '<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'
}

# Fail (CI) or skip (77) when the namespace cannot be made here.
spvs_dds_require_netns() {
  if ! unshare -r -n true 2>/dev/null; then
    echo "cannot make a network namespace (unshare -r -n)"
    if [ "${CI:-}" = "true" ]; then exit 1; fi
    exit 77
  fi
}
