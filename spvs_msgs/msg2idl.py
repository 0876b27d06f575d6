#!/usr/bin/env python3
"""msg2idl.py - the DDS IDL of a ROS 2 .msg file, as ROS 2's middleware names it.

A message `pkg/msg/T` becomes the struct `pkg::msg::dds_::T_` (module
`pkg { module msg { module dds_ { struct T_`), fields in order, fixed-size
arrays as IDL arrays.  Only what spvs_msgs uses is accepted: the primitive
types below, fixed-size arrays of them, and messages of the same or another
package (`Vector3`, `geometry_msgs/Vector3`).  No strings, no unbounded or
bounded sequences, no constants, no default values: such a line is an error.

  msg2idl.py MSG_FILE            print the IDL
  msg2idl.py --check MSG IDL...  exit 1 unless each IDL file equals the IDL of
                                 the .msg beside it (pairs: MSG IDL MSG IDL ...)
  msg2idl.py --write MSG...      write each MSG's IDL beside it (T.msg -> T.idl)
  msg2idl.py --c-defs OUT.h MSG...
                                 write a C header with each message's ROS 2
                                 definition text (ros2msg, as rosbag2 embeds
                                 it: the .msg, then each nested type after a
                                 line of 80 '=' and "MSG: pkg/Type"), macro
                                 SPVS_MSGDEF_<PKG>_<TYPE>, and its type name
                                 SPVS_MSGTYPE_<PKG>_<TYPE> ("pkg/msg/Type")
"""
import os
import re
import sys

# ROS 2 primitive -> IDL type (the ROS 2 IDL mapping, IDL 4.2 names that both
# Cyclone DDS's idlc and fastddsgen accept).
PRIMITIVES = {
    "bool": "boolean",
    "byte": "octet",
    "uint8": "octet",
    "int16": "short",
    "uint16": "unsigned short",
    "int32": "long",
    "uint32": "unsigned long",
    "int64": "long long",
    "uint64": "unsigned long long",
    "float32": "float",
    "float64": "double",
}

FIELD = re.compile(r"^([A-Za-z][A-Za-z0-9_/]*)(\[([0-9]+)\])?\s+([a-z][a-z0-9_]*)$")


class MsgError(Exception):
    pass


def parse_msg(path):
    """[(type, array_len or None, name)] of a .msg file, in order."""
    fields = []
    with open(path, encoding="utf-8") as f:
        for lineno, raw in enumerate(f, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            m = FIELD.match(re.sub(r"\s+", " ", line))
            if not m:
                raise MsgError("%s:%d: not a field spvs_msgs supports: %s"
                               % (path, lineno, line))
            typ, _, n, name = m.groups()
            fields.append((typ, int(n) if n else None, name))
    if not fields:
        raise MsgError("%s: no fields" % path)
    return fields


def msg_names(path):
    """(package, type name) from .../<package>/msg/<Type>.msg."""
    path = os.path.abspath(path)
    typ = os.path.splitext(os.path.basename(path))[0]
    msgdir = os.path.dirname(path)
    if os.path.basename(msgdir) != "msg":
        raise MsgError("%s: a .msg file must sit in <package>/msg/" % path)
    return os.path.basename(os.path.dirname(msgdir)), typ


def idl_type(pkg, typ):
    """The IDL type of a field type, and the included IDL file if nested."""
    if typ in PRIMITIVES:
        return PRIMITIVES[typ], None
    if typ in ("string", "wstring", "char") or "<=" in typ:
        raise MsgError("type %s is not supported (no strings)" % typ)
    other_pkg, name = typ.split("/", 1) if "/" in typ else (pkg, typ)
    if not re.match(r"^[A-Z][A-Za-z0-9]*$", name):
        raise MsgError("bad message type name: %s" % typ)
    return ("%s::msg::dds_::%s_" % (other_pkg, name),
            "%s/msg/%s.idl" % (other_pkg, name))


def msg_to_idl(path):
    pkg, typ = msg_names(path)
    fields = parse_msg(path)
    includes = []
    members = []
    for ftyp, n, name in fields:
        t, inc = idl_type(pkg, ftyp)
        if inc and inc not in includes:
            includes.append(inc)
        members.append("        %s %s%s;" % (t, name, "[%d]" % n if n else ""))
    guard = "%s__MSG__%s__IDL" % (pkg.upper(), typ.upper())
    out = ["// %s/msg/%s for DDS, generated from %s.msg by spvs_msgs/msg2idl.py:"
           % (pkg, typ, typ),
           "// edit the .msg and run msg2idl.py --write, never this file.",
           "#ifndef %s" % guard,
           "#define %s" % guard]
    out += ['#include "%s"' % inc for inc in includes]
    out += ["module %s {" % pkg,
            "  module msg {",
            "    module dds_ {",
            "      struct %s_ {" % typ]
    out += members
    out += ["      };", "    };", "  };", "};", "#endif", ""]
    return "\n".join(out)


def ros2msg_text(path):
    """The definition rosbag2 and Foxglove read: the .msg text, then every
    nested message type (depth first, each once) after a separator."""
    pkg, _ = msg_names(path)
    text = open(path, encoding="utf-8").read()
    seen = []

    def deps(p, pk):
        for ftyp, _, _ in parse_msg(p):
            if ftyp in PRIMITIVES:
                continue
            opkg, name = ftyp.split("/", 1) if "/" in ftyp else (pk, ftyp)
            key = "%s/%s" % (opkg, name)
            if key in seen:
                continue
            # A nested type of another package sits beside the package's
            # folder (spvs_msgs/external/geometry_msgs/msg/Vector3.msg).
            pkgdir = os.path.dirname(os.path.dirname(os.path.abspath(p)))
            dp = os.path.join(os.path.dirname(pkgdir), opkg, "msg", name + ".msg")
            if not os.path.exists(dp):
                raise MsgError("%s: nested type %s not found at %s" % (p, key, dp))
            seen.append(key)
            deps(dp, opkg)
            yield key, dp

    parts = [text]
    for key, dp in list(deps(path, pkg)):
        parts.append("=" * 80 + "\nMSG: %s\n" % key + open(dp, encoding="utf-8").read())
    return "\n".join(p.rstrip("\n") for p in parts) + "\n"


def c_defs(out_path, msgs):
    lines = ["/* Generated by spvs_msgs/msg2idl.py --c-defs: the ROS 2 definitions",
             " * of the messages spvs writes into rosbag2 files. */",
             "#ifndef SPVS_MSGDEFS_H", "#define SPVS_MSGDEFS_H", ""]
    for m in msgs:
        pkg, typ = msg_names(m)
        macro = "%s_%s" % (pkg.upper(), typ.upper())
        lines.append('#define SPVS_MSGTYPE_%s "%s/msg/%s"' % (macro, pkg, typ))
        lines.append("#define SPVS_MSGDEF_%s \\" % macro)
        body = ros2msg_text(m)
        for ln in body.splitlines(True):
            esc = ln.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
            lines.append('    "%s" \\' % esc)
        lines.append('    ""')
        lines.append("")
    lines += ["#endif", ""]
    with open(out_path, "w") as f:
        f.write("\n".join(lines))


def main(argv):
    if len(argv) == 2 and argv[1] in ("--help", "-h"):
        sys.stdout.write(__doc__)
        return 0
    try:
        if len(argv) == 2 and not argv[1].startswith("--"):
            sys.stdout.write(msg_to_idl(argv[1]))
            return 0
        if len(argv) >= 4 and argv[1] == "--c-defs":
            c_defs(argv[2], argv[3:])
            return 0
        if len(argv) >= 3 and argv[1] == "--write":
            for m in argv[2:]:
                with open(os.path.splitext(m)[0] + ".idl", "w") as f:
                    f.write(msg_to_idl(m))
            return 0
        if len(argv) >= 4 and argv[1] == "--check" and len(argv) % 2 == 0:
            bad = 0
            for m, idl in zip(argv[2::2], argv[3::2]):
                want = msg_to_idl(m)
                with open(idl, encoding="utf-8") as f:
                    have = f.read()
                if have != want:
                    print("%s differs from the IDL of %s (run msg2idl.py --write)"
                          % (idl, m))
                    bad += 1
                else:
                    print("%s equals the IDL of %s" % (idl, m))
            return 1 if bad else 0
    except (MsgError, OSError) as e:
        print("msg2idl.py: %s" % e, file=sys.stderr)
        return 1
    print("usage: msg2idl.py MSG | --write MSG... | --check MSG IDL [MSG IDL...] "
          "| --c-defs OUT.h MSG... (see --help)", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
