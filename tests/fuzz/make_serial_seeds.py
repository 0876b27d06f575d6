#!/usr/bin/env python3
"""make_serial_seeds.py DIR - seed inputs of fuzz_serial: a CONFIG frame
followed by matches frames of docs/SERIAL.md (0, 3, 20 and 125 matches,
a repeat and an older seq), written with this script's own COBS and CRC."""
import os, random, struct, sys, zlib

def cobs(b):
    out, block = bytearray(), bytearray()
    for x in b:
        if x == 0:
            out += bytes([len(block) + 1]) + block; block = bytearray()
        else:
            block.append(x)
            if len(block) == 254:
                out += b"\xff" + block; block = bytearray()
    return bytes(out + bytes([len(block) + 1]) + block) + b"\x00"

def frame(t, body):
    p = bytes([1, t]) + struct.pack("<H", len(body)) + body
    return cobs(p + struct.pack("<I", zlib.crc32(p)))

def config(method=3, seed=0, alpha=800.0):
    return frame(4, struct.pack("<BBHIff", method, 0, 0, seed, alpha, alpha))

def matches(seq, n, rng, run=7):
    body = struct.pack("<IIIH", run, seq, 100 * seq, n)
    for i in range(n):
        body += struct.pack("<Hhhhh", i, *(rng.randrange(-5000, 5000) for _ in range(4)))
    return frame(1, body)

out = sys.argv[1]
rng = random.Random(20070601)
seeds = {
    "config_only": config(),
    "one_frame": config() + matches(0, 20, rng),
    "three_frames": config(1) + matches(0, 3, rng) + matches(1, 125, rng) + matches(1, 125, rng) + matches(0, 20, rng),
    "empty_frame": config(2) + matches(0, 0, rng),
    "no_config": matches(0, 20, rng),
}
for name, data in seeds.items():
    open(os.path.join(out, name), "wb").write(data)
