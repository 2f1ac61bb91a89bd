#!/usr/bin/env python3
"""Writes a GLB of one mesh placed many times: a field of copies.

    python3 tools/gen-instanced-gltf.py OUT.glb [--instances N] [--triangles T]
        [--nodes] [--rotation float|short|byte] [--grid SPACING] [--seed S]
        [--rays OUT.rays [--rays-size WxH]] [--animate SECONDS] [--mesh-from MODEL.glb]

The mesh is a sphere-like grid of about T triangles (a UV sphere squashed a
little, so rotations show), with normals. By default one node carries
EXT_mesh_gpu_instancing with N instances (TRANSLATION, ROTATION, SCALE
accessors; ROTATION as floats or normalized shorts or bytes); with --nodes
the same placements are N nodes sharing the mesh instead (core glTF: a
mesh used by many nodes). Placements lie on a square grid, each with a
random rotation about y and a random scale 0.6-1.4, from --seed, so two
runs write the same file. --rays also writes the primary rays of a
camera looking down at the field (one per pixel, row by row; the .rays
format of rtbench, rt/accel/rayset.h), so `bench/rtbench OUT.glb OUT.rays`
and `bench/rtbench OUT.glb OUT.rays --flatten` compare the instanced and
the flattened scene on the same rays. --animate adds an animation that
turns the whole field a quarter turn about y over SECONDS (the instancing
node's rotation, or a parent of the --nodes nodes): node animation that
moves instances and leaves the mesh as it is, for `rt --frames`. No
dependencies beyond Python 3.
"""
import argparse
import json
import math
import random
import struct


def sphere(triangles):
    """A UV sphere of about `triangles` triangles: positions, normals, indices."""
    rings = max(2, int(round(math.sqrt(triangles / 4.0))))
    segs = max(3, int(round(triangles / (2.0 * rings))))
    pos, nrm, idx = [], [], []
    for r in range(rings + 1):
        th = math.pi * r / rings
        for s in range(segs + 1):
            ph = 2.0 * math.pi * s / segs
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            pos.append((0.4 * n[0], 0.5 + 0.5 * n[1], 0.3 * n[2]))
            l = math.sqrt((n[0] / 0.4) ** 2 + (n[1] / 0.5) ** 2 + (n[2] / 0.3) ** 2) or 1.0
            nrm.append((n[0] / 0.4 / l, n[1] / 0.5 / l, n[2] / 0.3 / l))
    for r in range(rings):
        for s in range(segs):
            a = r * (segs + 1) + s
            b = a + segs + 1
            if r > 0:
                idx += [a, b, a + 1]
            if r < rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nrm, idx


def mesh_from(path):
    """The first primitive of a GLB's first mesh: positions (scaled and moved
    into the sphere's box, about 0.8 x 1 x 0.6), no normals, indices."""
    with open(path, "rb") as f:
        data = f.read()
    magic, _, _ = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67:
        raise SystemExit("%s: not a GLB" % path)
    jl, _ = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + jl])
    bl, _ = struct.unpack_from("<II", data, 20 + jl)
    blob = data[28 + jl:28 + jl + bl]

    def read(ai):
        acc = doc["accessors"][ai]
        view = doc["bufferViews"][acc["bufferView"]]
        fmt, size = {5126: ("f", 4), 5125: ("I", 4), 5123: ("H", 2), 5121: ("B", 1)}[acc["componentType"]]
        comps = {"SCALAR": 1, "VEC3": 3}[acc["type"]]
        stride = view.get("byteStride", size * comps)
        off = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        return [struct.unpack_from("<%d%s" % (comps, fmt), blob, off + k * stride) for k in range(acc["count"])]

    prim = doc["meshes"][0]["primitives"][0]
    pos = read(prim["attributes"]["POSITION"])
    idx = [i[0] for i in read(prim["indices"])]
    lo = [min(p[i] for p in pos) for i in range(3)]
    hi = [max(p[i] for p in pos) for i in range(3)]
    sc = 1.0 / max(hi[i] - lo[i] for i in range(3))
    pos = [((p[0] - 0.5 * (lo[0] + hi[0])) * sc, (p[1] - lo[1]) * sc, (p[2] - 0.5 * (lo[2] + hi[2])) * sc) for p in pos]
    return pos, None, idx


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--instances", type=int, default=100)
    ap.add_argument("--triangles", type=int, default=200)
    ap.add_argument("--nodes", action="store_true", help="one node per placement instead of EXT_mesh_gpu_instancing")
    ap.add_argument("--rotation", choices=["float", "short", "byte"], default="float")
    ap.add_argument("--grid", type=float, default=1.2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--rays")
    ap.add_argument("--rays-size", default="640x480")
    ap.add_argument("--animate", type=float, default=0.0)
    ap.add_argument("--mesh-from")
    a = ap.parse_args()

    pos, nrm, idx = mesh_from(a.mesh_from) if a.mesh_from else sphere(a.triangles)
    rng = random.Random(a.seed)
    side = max(1, int(math.ceil(math.sqrt(a.instances))))
    placements = []
    for k in range(a.instances):
        x = (k % side - (side - 1) / 2.0) * a.grid
        z = (k // side - (side - 1) / 2.0) * a.grid
        ang = rng.uniform(0.0, 2.0 * math.pi)
        q = (0.0, math.sin(ang / 2.0), 0.0, math.cos(ang / 2.0))
        sc = rng.uniform(0.6, 1.4)
        placements.append(((x, 0.0, z), q, (sc, sc, sc)))

    blob = bytearray()
    views, accessors = [], []

    def add(data, comp, count, typ, fmt, target=None, minmax=None, normalized=False):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(data)
        v = {"buffer": 0, "byteOffset": off, "byteLength": len(data)}
        if target:
            v["target"] = target
        views.append(v)
        acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": typ}
        if normalized:
            acc["normalized"] = True
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    flat = lambda rows: [c for r in rows for c in r]
    lo = [min(p[i] for p in pos) for i in range(3)]
    hi = [max(p[i] for p in pos) for i in range(3)]
    a_pos = add(struct.pack("<%df" % (3 * len(pos)), *flat(pos)), 5126, len(pos), "VEC3", None, 34962, (lo, hi))
    attributes = {"POSITION": a_pos}
    if nrm:
        attributes["NORMAL"] = add(struct.pack("<%df" % (3 * len(nrm)), *flat(nrm)), 5126, len(nrm), "VEC3", None,
                                   34962)
    a_idx = add(struct.pack("<%dI" % len(idx), *idx), 5125, len(idx), "SCALAR", None, 34963)
    mesh = {"primitives": [{"attributes": attributes, "indices": a_idx, "material": 0}]}
    doc = {
        "asset": {"version": "2.0", "generator": "rt tools/gen-instanced-gltf.py"},
        "scene": 0,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.6, 0.25, 1.0], "roughnessFactor": 0.7,
                                                "metallicFactor": 0.0}}],
        "meshes": [mesh],
    }
    if a.nodes:
        nodes = [{"mesh": 0, "translation": list(t), "rotation": list(q), "scale": list(s)} for t, q, s in placements]
        doc["nodes"] = nodes
        doc["scenes"] = [{"nodes": list(range(len(nodes)))}]
    else:
        n = len(placements)
        a_t = add(struct.pack("<%df" % (3 * n), *flat(p[0] for p in placements)), 5126, n, "VEC3", None)
        if a.rotation == "float":
            a_r = add(struct.pack("<%df" % (4 * n), *flat(p[1] for p in placements)), 5126, n, "VEC4", None)
        else:
            m = 32767 if a.rotation == "short" else 127
            vals = [int(round(c * m)) for c in flat(p[1] for p in placements)]
            code, f = (5122, "h") if a.rotation == "short" else (5120, "b")
            a_r = add(struct.pack("<%d%s" % (4 * n, f), *vals), code, n, "VEC4", None, normalized=True)
        a_s = add(struct.pack("<%df" % (3 * n), *flat(p[2] for p in placements)), 5126, n, "VEC3", None)
        doc["nodes"] = [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {
            "attributes": {"TRANSLATION": a_t, "ROTATION": a_r, "SCALE": a_s}}}}]
        doc["scenes"] = [{"nodes": [0]}]
        doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
        doc["extensionsRequired"] = ["EXT_mesh_gpu_instancing"]
    if a.animate > 0.0:
        if a.nodes:  # one parent turns them all
            doc["nodes"].append({"children": doc["scenes"][0]["nodes"]})
            doc["scenes"] = [{"nodes": [len(doc["nodes"]) - 1]}]
        target = len(doc["nodes"]) - 1 if a.nodes else 0
        a_in = add(struct.pack("<2f", 0.0, a.animate), 5126, 2, "SCALAR", None, None, ([0.0], [a.animate]))
        h = math.sqrt(0.5)
        a_out = add(struct.pack("<8f", 0, 0, 0, 1, 0, h, 0, h), 5126, 2, "VEC4", None)
        doc["animations"] = [{"samplers": [{"input": a_in, "output": a_out, "interpolation": "LINEAR"}],
                              "channels": [{"sampler": 0, "target": {"node": target, "path": "rotation"}}]}]
    while len(blob) % 4:
        blob.append(0)
    doc["buffers"] = [{"byteLength": len(blob)}]
    doc["bufferViews"] = views
    doc["accessors"] = accessors
    js = json.dumps(doc, separators=(",", ":")).encode()
    while len(js) % 4:
        js += b" "
    total = 12 + 8 + len(js) + 8 + len(blob)
    with open(a.out, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, total))
        f.write(struct.pack("<II", len(js), 0x4E4F534A))
        f.write(js)
        f.write(struct.pack("<II", len(blob), 0x004E4942))
        f.write(blob)
    if a.rays:
        write_rays(a.rays, a.rays_size, side, a.grid)


def write_rays(path, size, side, grid):
    """Primary rays of a pinhole camera above the field's front edge."""
    w, h = (int(v) for v in size.lower().split("x"))
    half = 0.5 * side * grid
    eye = (0.0, 0.8 * half + 1.0, 1.6 * half + 2.0)
    look = (0.0, 0.0, 0.0)
    f = [look[i] - eye[i] for i in range(3)]
    fl = math.sqrt(sum(c * c for c in f))
    f = [c / fl for c in f]
    r = [-f[2], 0.0, f[0]]
    rl = math.sqrt(sum(c * c for c in r))
    r = [c / rl for c in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    tv = math.tan(math.radians(20.0))
    th = tv * w / h
    out = bytearray(b"RTRAYS01" + struct.pack("<Q", w * h))
    for y in range(h):
        for x in range(w):
            sx = (2.0 * (x + 0.5) / w - 1.0) * th
            sy = (1.0 - 2.0 * (y + 0.5) / h) * tv
            d = [f[i] + sx * r[i] + sy * u[i] for i in range(3)]
            out += struct.pack("<8f", eye[0], eye[1], eye[2], d[0], d[1], d[2], 0.0, float("inf"))
    with open(path, "wb") as fp:
        fp.write(out)


if __name__ == "__main__":
    main()
