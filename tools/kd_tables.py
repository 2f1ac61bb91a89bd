#!/usr/bin/env python3
"""Prints the three constant tables of the wide kd-tree step in
src/accel/kdtree_trace.c.

rt_kd_compress[m]: byte i = the lane of the i-th set bit of the 8-bit mask m
(compaction by a permute). rt_kd_cell_of_key[nb] / rt_kd_key_of_cell[nb]: the
front-to-back order of a wide node's 8 cells when the ray crosses the planes
in the 7-bit set nb towards -axis. A cell's key k (bit 2 = level 0) says on
which side of its plane at each level it lies, 0 = the side entered first;
the cell is c = 4 b0 + 2 b1 + b2 with b = k ^ neg(plane) at each level and
planes 0, 1 + b0, 3 + 2 b0 + b1. Byte L of rt_kd_cell_of_key[nb] is the cell
with key 7 - L (farthest first); byte c of rt_kd_key_of_cell[nb] is c's key.

    python3 tools/kd_tables.py   # compare with the tables in src/accel/kdtree_trace.c
"""


def cell_of(key, nb):
    n = [(nb >> p) & 1 for p in range(7)]
    b0 = (key >> 2 & 1) ^ n[0]
    b1 = (key >> 1 & 1) ^ n[1 + b0]
    b2 = (key & 1) ^ n[3 + 2 * b0 + b1]
    return 4 * b0 + 2 * b1 + b2


def pack(values):
    return sum(v << (8 * i) for i, v in enumerate(values))


def table(name, entries):
    print("const uint64_t %s[%d] = {" % (name, len(entries)))
    for i in range(0, len(entries), 4):
        print("    " + ", ".join("0x%016xull" % e for e in entries[i:i + 4]) + ",")
    print("};")


compress = []
for m in range(256):
    lanes = [i for i in range(8) if m >> i & 1]
    compress.append(pack(lanes + [0] * (8 - len(lanes))))
cell_of_key = [pack([cell_of(7 - lane, nb) for lane in range(8)]) for nb in range(128)]
key_of_cell = []
for nb in range(128):
    keys = [0] * 8
    for k in range(8):
        keys[cell_of(k, nb)] = k
    key_of_cell.append(pack(keys))
table("rt_kd_compress", compress)
table("rt_kd_cell_of_key", cell_of_key)
table("rt_kd_key_of_cell", key_of_cell)
