#!/usr/bin/env python3
"""Writes the assets of scenes/forest.txt: a forest as one glTF of two tree
meshes placed by EXT_mesh_gpu_instancing, and a sky to light it.

    python3 tools/gen-forest.py [--out assets] [--trees N] [--seed S]

assets/forest.glb: a conifer (a trunk and five tiers of jagged cones, 2,896
triangles) and a broadleaf tree (a trunk and a lumpy crown, 2,864
triangles), each one mesh kept once by rt (an object with its own kd-tree)
and placed N/2 times by its node's EXT_mesh_gpu_instancing accessors
(TRANSLATION, ROTATION about y, SCALE): random spots on a disc of radius 60
with a clearing in front of the camera, random yaw, height and girth. assets/sky.hdr: a 128x64 latitude-longitude Radiance image, a blue
sky paling to the horizon over dark ground (rt's environment, y up, row 0
the zenith). The same seed writes the same bytes. No dependencies beyond
Python 3.
"""
import argparse
import json
import math
import os
import random
import struct


def cone_tiers(rng):
    """A conifer: positions, normals, indices, and which are trunk (material 0)."""
    pos, nrm, idx, mats = [], [], [], []

    def ring_mesh(rings, segs, radius_at, height_at, mat, jag):
        base = len(pos)
        for r in range(rings + 1):
            for s in range(segs + 1):
                a = 2.0 * math.pi * s / segs
                rad = radius_at(r / rings) * (1.0 + jag * (0.5 - rng.random()) if 0 < r < rings else 1.0)
                y = height_at(r / rings)
                pos.append((rad * math.cos(a), y, rad * math.sin(a)))
                nrm.append((math.cos(a), 0.35, math.sin(a)))
        for r in range(rings):
            for s in range(segs):
                a = base + r * (segs + 1) + s
                b = a + segs + 1
                idx.extend([a, b, a + 1, a + 1, b, b + 1])
                mats.extend([mat, mat])

    ring_mesh(4, 12, lambda t: 0.22 - 0.08 * t, lambda t: 1.6 * t, 0, 0.0)  # trunk
    for k in range(5):  # tiers, wide at the bottom
        y0 = 1.0 + 1.15 * k
        w = 1.9 - 0.33 * k
        ring_mesh(7, 40, lambda t, w=w: w * (1.0 - t) + 0.02, lambda t, y0=y0: y0 + 1.9 * t, 1, 0.18)
    return pos, nrm, idx, mats


def broadleaf(rng):
    """A broadleaf tree: a trunk and a lumpy ellipsoid crown."""
    pos, nrm, idx, mats = [], [], [], []
    segs, rings = 10, 4
    base = len(pos)
    for r in range(rings + 1):
        for s in range(segs + 1):
            a = 2.0 * math.pi * s / segs
            rad = 0.28 - 0.1 * r / rings
            pos.append((rad * math.cos(a), 2.2 * r / rings, rad * math.sin(a)))
            nrm.append((math.cos(a), 0.0, math.sin(a)))
    for r in range(rings):
        for s in range(segs):
            a = base + r * (segs + 1) + s
            b = a + segs + 1
            idx.extend([a, b, a + 1, a + 1, b, b + 1])
            mats.extend([0, 0])
    segs, rings = 48, 30
    base = len(pos)
    bumps = [(rng.uniform(0, 2 * math.pi), rng.uniform(0.2, 2.8), rng.uniform(0.08, 0.16)) for _ in range(14)]
    for r in range(rings + 1):
        th = math.pi * r / rings
        for s in range(segs + 1):
            ph = 2.0 * math.pi * s / segs
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            lump = 1.0
            for (bp, bt, amp) in bumps:
                d = math.acos(max(-1.0, min(1.0, math.sin(th) * math.sin(bt) * math.cos(ph - bp)
                                            + math.cos(th) * math.cos(bt))))
                lump += amp * math.exp(-(d / 0.45) ** 2)
            pos.append((1.6 * lump * n[0], 3.4 + 1.7 * lump * n[1], 1.6 * lump * n[2]))
            nrm.append(n)
    for r in range(rings):
        for s in range(segs):
            a = base + r * (segs + 1) + s
            b = a + segs + 1
            if r > 0:
                idx.extend([a, b, a + 1])
                mats.append(2)
            if r < rings - 1:
                idx.extend([a + 1, b, b + 1])
                mats.append(2)
    return pos, nrm, idx, mats


def placements(rng, n, radius, clearing):
    out = []
    while len(out) < n:
        x, z = rng.uniform(-radius, radius), rng.uniform(-radius, radius)
        if x * x + z * z > radius * radius:
            continue
        if (x - clearing[0]) ** 2 + (z - clearing[1]) ** 2 < clearing[2] ** 2:
            continue
        ang = rng.uniform(0.0, 2.0 * math.pi)
        h = rng.uniform(0.7, 1.35)
        g = h * rng.uniform(0.85, 1.15)
        out.append(((x, 0.0, z), (0.0, math.sin(ang / 2.0), 0.0, math.cos(ang / 2.0)), (g, h, g)))
    return out


def write_glb(path, trees, rng, n):
    blob = bytearray()
    views, accessors = [], []

    def add(data, comp, count, typ, target=None, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        if target:
            views[-1]["target"] = target
        blob.extend(data)
        acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": typ}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    flat = lambda rows: [c for r in rows for c in r]
    meshes, nodes = [], []
    for ti, (pos, nrm, idx, mats) in enumerate(trees):
        nl = []
        for v in nrm:
            l = math.sqrt(sum(c * c for c in v)) or 1.0
            nl.append(tuple(c / l for c in v))
        lo = [min(p[i] for p in pos) for i in range(3)]
        hi = [max(p[i] for p in pos) for i in range(3)]
        a_pos = add(struct.pack("<%df" % (3 * len(pos)), *flat(pos)), 5126, len(pos), "VEC3", 34962, (lo, hi))
        a_nrm = add(struct.pack("<%df" % (3 * len(nl)), *flat(nl)), 5126, len(nl), "VEC3", 34962)
        prims = []
        for m in sorted(set(mats)):  # one primitive per material
            tri = [idx[3 * k:3 * k + 3] for k in range(len(mats)) if mats[k] == m]
            a_idx = add(struct.pack("<%dI" % (3 * len(tri)), *flat(tri)), 5125, 3 * len(tri), "SCALAR", 34963)
            prims.append({"attributes": {"POSITION": a_pos, "NORMAL": a_nrm}, "indices": a_idx, "material": m})
        meshes.append({"name": ["conifer", "broadleaf"][ti], "primitives": prims})
        place = placements(rng, n // 2 + (n % 2 if ti == 0 else 0), 60.0, (0.0, 40.0, 14.0))
        k = len(place)
        a_t = add(struct.pack("<%df" % (3 * k), *flat(p[0] for p in place)), 5126, k, "VEC3")
        a_r = add(struct.pack("<%df" % (4 * k), *flat(p[1] for p in place)), 5126, k, "VEC4")
        a_s = add(struct.pack("<%df" % (3 * k), *flat(p[2] for p in place)), 5126, k, "VEC3")
        nodes.append({"name": meshes[-1]["name"] + "s", "mesh": ti, "extensions": {"EXT_mesh_gpu_instancing": {
            "attributes": {"TRANSLATION": a_t, "ROTATION": a_r, "SCALE": a_s}}}})
    while len(blob) % 4:
        blob.append(0)
    doc = {
        "asset": {"version": "2.0", "generator": "rt tools/gen-forest.py"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "extensionsRequired": ["EXT_mesh_gpu_instancing"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [
            {"name": "bark", "pbrMetallicRoughness": {"baseColorFactor": [0.23, 0.15, 0.09, 1.0],
                                                      "metallicFactor": 0.0, "roughnessFactor": 0.9}},
            {"name": "needles", "pbrMetallicRoughness": {"baseColorFactor": [0.08, 0.22, 0.09, 1.0],
                                                         "metallicFactor": 0.0, "roughnessFactor": 0.8}},
            {"name": "leaves", "pbrMetallicRoughness": {"baseColorFactor": [0.15, 0.3, 0.07, 1.0],
                                                        "metallicFactor": 0.0, "roughnessFactor": 0.7}},
        ],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    js = json.dumps(doc, separators=(",", ":")).encode()
    while len(js) % 4:
        js += b" "
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob)))
        f.write(struct.pack("<II", len(js), 0x4E4F534A))
        f.write(js)
        f.write(struct.pack("<II", len(blob), 0x004E4942))
        f.write(blob)


def write_sky(path, w=128, h=64):
    """A clear sky over dark ground, as flat (not run-length) RGBE."""
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
    for y in range(h):
        elev = 90.0 - 180.0 * (y + 0.5) / h  # row 0: the zenith
        for _ in range(w):
            if elev >= 0.0:
                t = math.sqrt(elev / 90.0)
                horizon, zenith = (1.0, 1.05, 1.15), (0.28, 0.45, 0.95)
                c = [horizon[i] + (zenith[i] - horizon[i]) * t for i in range(3)]
            else:
                c = [0.12, 0.11, 0.09]
            v = max(c)
            m, e = math.frexp(v)
            s = m * 256.0 / v
            out += bytes([int(c[0] * s), int(c[1] * s), int(c[2] * s), e + 128])
    with open(path, "wb") as f:
        f.write(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="assets")
    ap.add_argument("--trees", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=27)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    trees = [cone_tiers(rng), broadleaf(rng)]
    write_glb(os.path.join(a.out, "forest.glb"), trees, rng, a.trees)
    write_sky(os.path.join(a.out, "sky.hdr"))
    for (name, t) in zip(("conifer", "broadleaf"), trees):
        print("%s: %d triangles" % (name, len(t[3])))


if __name__ == "__main__":
    main()
