"""ros2_keys.py - /cmd_vel on Zenoh as ROS 2's rmw_zenoh names it, so that a
ROS 2 robot running rmw_zenoh_cpp hears spvs's commands (docs/ROS2.md).

rmw_zenoh (ROS 2 Jazzy and later) puts a topic's samples on the key
    <domain>/<topic without its leading '/'>/<DDS type name>/<type hash>
e.g. 0/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45...8d2a, with the
CDR-encoded message as payload (4-byte encapsulation header, then the
fields) and an attachment of (sequence number: int64, source timestamp:
int64 nanoseconds, publisher gid: 16 bytes) in Zenoh's own serialization
(zenoh.ext).  A publisher announces itself and its node with liveliness
tokens under @ros2_lv/<domain>/..., which rmw_zenoh's graph cache reads.
"""

import hashlib
import struct
import time

TWIST_TOPIC = "/cmd_vel"
TWIST_TYPE = "geometry_msgs::msg::dds_::Twist_"
# geometry_msgs/msg/Twist's RIHS01 type hash (REP 2011), from its fields; the
# test rosbag/zenoh check recomputes it with rosbags from
# spvs_msgs/external/geometry_msgs/msg/Twist.msg.
TWIST_HASH = "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
# rmw_zenoh writes a QoS equal to ROS 2's default profile (reliable,
# volatile, keep last 10, no deadline, lifespan or lease) as empty fields.
DEFAULT_QOS = "::,:,:,:,,"
NODE_NAME = "spvs_zenoh_bridge"
DOMAIN_MAX = 232


def domain_from_env(environ):
    """ROS_DOMAIN_ID (0 when unset or empty), or raise ValueError."""
    s = environ.get("ROS_DOMAIN_ID", "")
    if s == "":
        return 0
    if not s.isdigit() or int(s) > DOMAIN_MAX:
        raise ValueError("ROS_DOMAIN_ID '%s' is not an integer 0..%d"
                         % (s, DOMAIN_MAX))
    return int(s)


def mangle(name):
    """rmw_zenoh's name mangling in liveliness tokens: '/' -> '%'."""
    return name.replace("/", "%")


def data_key(domain, topic, dds_type, type_hash):
    return "%d/%s/%s/%s" % (domain, topic.lstrip("/"), dds_type, type_hash)


def node_token(domain, zid, nid, node=NODE_NAME):
    return "@ros2_lv/%d/%s/%d/%d/NN/%%/%%/%s" % (domain, zid, nid, nid, node)


def publisher_token(domain, zid, nid, eid, topic, dds_type, type_hash,
                    node=NODE_NAME, qos=DEFAULT_QOS):
    return "@ros2_lv/%d/%s/%d/%d/MP/%%/%%/%s/%s/%s/%s/%s" % (
        domain, zid, nid, eid, node, mangle(topic), dds_type, type_hash, qos)


def twist_cdr(v, w):
    """geometry_msgs/msg/Twist, CDR little endian: linear (v, 0, 0),
    angular (0, 0, w).  REP 103: angular.z > 0 turns left, as w does."""
    return b"\x00\x01\x00\x00" + struct.pack("<6d", v, 0.0, 0.0, 0.0, 0.0, w)


class CmdVelPublisher:
    """The Twist of every command on the rmw_zenoh key of /cmd_vel."""

    def __init__(self, zenoh, session, domain):
        import zenoh.ext as zext
        self.zext = zext
        self.domain = domain
        zid = str(session.info.zid())
        self.key = data_key(domain, TWIST_TOPIC, TWIST_TYPE, TWIST_HASH)
        self.tokens_keys = [node_token(domain, zid, 0),
                            publisher_token(domain, zid, 0, 1, TWIST_TOPIC,
                                            TWIST_TYPE, TWIST_HASH)]
        # The gid rmw_zenoh derives from the token; any 16 bytes unique to
        # this publisher serve.
        self.gid = hashlib.sha256(self.tokens_keys[1].encode()).digest()[:16]
        self.seq = 0
        self.tokens = [session.liveliness().declare_token(k)
                       for k in self.tokens_keys]
        self.pub = session.declare_publisher(self.key)

    def put(self, v, w):
        self.seq += 1
        z = self.zext
        att = z.z_serialize((z.Int64(self.seq), z.Int64(time.time_ns()),
                             tuple(z.UInt8(b) for b in self.gid)))
        self.pub.put(twist_cdr(v, w), attachment=att)

    def close(self):
        for ent in [self.pub] + self.tokens:
            try:
                ent.undeclare()
            except Exception:
                pass
