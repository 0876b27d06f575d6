#!/usr/bin/python3
"""Write the seed corpora of the fuzz targets (tests/fuzz/corpus/{core,node}).

The seeds are small descriptions in each target's input format (see the
comments at the top of fuzz_core.c and fuzz_node.c), chosen so that every
branch of the input format is reached from the first run: consistent
scenes for each method, damaged matches, raw float bits, coincident and
collinear points, all mismatches, bad times, and for the node both raw
encoded SPVS_MATCHES messages and field-built ones.

usage: make_seeds.py [LCM_PYTHON_DIR]
LCM_PYTHON_DIR holds the lcm-gen Python module `spvs` (a build folder's
lcm_types/python); without it the raw-message node seeds are skipped.
"""
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def world(method, d_byte=128, pose=(160, 100, 160), normal=(200, 60, 190)):
    """Head, PRNG seed, plane normal (3 bytes), distance, point hash, pose
    (x = (b - 128) / 32 m, z = -b / 21 m, phi = (b - 128) / 100 rad)."""
    head = bytes([method - 1, 0])
    plane = bytes(normal) + bytes([d_byte]) + struct.pack(">I", 0x9E3779B9)
    return head + plane + bytes(pose)


def scene_frame(count=120, damage=b"", time_code=8, time_extra=b""):
    """Mode 4 (consistent scene), the time code and its extra bytes, the
    count, one damage code per match."""
    codes = (damage + bytes(count))[:count]
    return bytes([4, time_code]) + time_extra + bytes([count]) + codes


def core_seeds():
    seeds = {}
    for m in (1, 2, 3):
        body = b"".join(scene_frame() for _ in range(11))
        seeds["scene_m%d" % m] = world(m) + bytes([11]) + body
    # Facing the target from 2 m: the steps can end within a few frames.
    near = world(3, pose=(128, 6, 128))
    seeds["near_target"] = near + bytes([15]) + b"".join(
        scene_frame(time_code=6, time_extra=bytes([255])) for _ in range(15))
    # At the target position, turned by 0.3 rad: straight to step 3.
    at = world(3, pose=(128, 0, 158))
    seeds["at_target"] = at + bytes([15]) + b"".join(
        scene_frame(time_code=6, time_extra=bytes([255])) for _ in range(15))
    # A floor (n_z = 0) for Methods I and III, a wall (n_y = 0) for II.
    floor = world(1, d_byte=0, normal=(128, 255, 0))
    seeds["floor_m1"] = floor + bytes([6]) + b"".join(scene_frame() for _ in range(6))
    wall = world(2, normal=(128, 128, 255))
    seeds["wall_m2"] = wall + bytes([6]) + b"".join(scene_frame() for _ in range(6))
    # 40 s steps: past the step time bound.
    seeds["step_timeout"] = world(3) + bytes([6]) + b"".join(
        scene_frame(time_code=7 if k else 8) for k in range(6))
    # Every kind of per-match damage, one frame each.
    dmg = b"".join(scene_frame(damage=bytes([0] * 20 + [c] * 3)) for c in range(1, 11))
    seeds["damage"] = world(3) + bytes([10]) + dmg
    # Times: repeated, backwards, NaN, infinite, a long gap, raw bits.
    times = b"".join(scene_frame(time_code=c,
                                 time_extra=b"\x7f\xc0\x00\x00" if c == 5 else b"")
                     for c in (8, 0, 1, 2, 3, 4, 5, 8))
    seeds["times"] = world(1) + bytes([8]) + times
    # Raw float bits: a NaN, an infinity, a denormal, a huge value.
    raw = bytes([0, 8]) + struct.pack(">H", 5)
    for bits in (0x7FC00000, 0x7F800000, 0x00000001, 0x7F7FFFFF, 0x3F800000):
        raw += struct.pack(">IIII", bits, 0x3F800000, bits, 0x40000000) + b"\x00\x01"
    seeds["raw"] = world(2) + bytes([1]) + raw
    # Coincident points, collinear points, all mismatches, a count past the
    # capacity (raw mode reads zeros past the end of the input).
    seeds["coincident"] = world(3) + bytes([1, 1, 8, 30, 100, 100, 100, 100, 100])
    seeds["collinear"] = world(3) + bytes([1, 2, 8]) + struct.pack(">H", 200) + bytes(5)
    seeds["mismatches"] = world(3) + bytes([1, 3, 8]) + struct.pack(">H", 150) + b"\x12\x34\x56\x78"
    seeds["over_capacity"] = world(3) + bytes([1, 0, 8]) + struct.pack(">H", 260)
    seeds["estimate_only"] = world(3) + bytes([1, 0x82, 8]) + struct.pack(">H", 40) + bytes(5)
    return seeds


def node_built(seq_steps, count=40, codes=b"", run=0):
    """Field-built messages: mode 0, then dseq, dt, run, count, shift, codes."""
    out = b""
    for dseq in seq_steps:
        out += bytes([0, dseq & 0xFF, 10, run, count, 3]) + (codes + bytes(count))[:count]
    return out


def node_seeds(lcm_py):
    seeds = {}
    # head: method (low 2 bits), message count - 1 in the next bits.
    seeds["built_in_order"] = bytes([2 | (3 << 2)]) + node_built([1, 1, 1, 1])
    seeds["built_dup_old"] = bytes([2 | (3 << 2)]) + node_built([1, 1, 0, -1 & 0xFF])
    seeds["built_bad_values"] = bytes([0 | (2 << 2)]) + node_built(
        [1, 1, 1], codes=bytes([0, 2, 0, 3, 0, 4, 0xFF, 0xFF, 0xFF, 0xFF, 5]))
    seeds["built_count_negative"] = bytes([1]) + bytes([0, 1, 10, 0, 0xF0, 0xFF, 0xF0, 0])
    seeds["built_count_huge"] = bytes([1]) + bytes([0, 1, 10, 0, 0xF0, 0x7F, 0xFF, 0])
    seeds["built_cut_flip"] = bytes([2 | (1 << 2)]) + bytes([2, 1, 10, 0, 20, 0]) + bytes(20) + \
        bytes([3]) + bytes([6, 1, 10, 0, 20, 0]) + bytes(20) + bytes([0, 0, 0, 0x40])
    if lcm_py:
        sys.path.insert(0, lcm_py)
        from spvs import matches_t  # noqa: E402 (generated by lcm-gen)
        msg = matches_t()
        msg.seq, msg.utime, msg.run_id, msg.count = 7, 700000, 42, 12
        for i in range(12):
            msg.feature[i] = i
            msg.x_tgt[i] = float(i * 40 - 240)
            msg.y_tgt[i] = float((i * 29) % 200 - 100)
            msg.x_cur[i] = msg.x_tgt[i] + 5.0
            msg.y_cur[i] = msg.y_tgt[i]
        raw = msg.encode()
        seeds["raw_valid"] = bytes([2]) + b"\x01" + struct.pack(">H", len(raw)) + raw
        seeds["raw_short"] = bytes([2]) + b"\x01" + struct.pack(">H", 40) + raw[:40]
        seeds["raw_bad_fingerprint"] = bytes([2]) + b"\x01" + struct.pack(">H", 64) + \
            b"\x00" * 8 + raw[8:64]
    return seeds


def write(folder, seeds):
    path = os.path.join(HERE, "corpus", folder)
    os.makedirs(path, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(path, name), "wb") as f:
            f.write(data)
    print("%s: %d seeds, %d bytes" % (path, len(seeds), sum(len(d) for d in seeds.values())))


if __name__ == "__main__":
    write("core", core_seeds())
    write("node", node_seeds(sys.argv[1] if len(sys.argv) > 1 else None))
