#!/usr/bin/env python3
"""Seed corpora for make fuzz, from the shared assets and scenes/.

usage: fuzz_seeds.py SHARED_DIR OUT_DIR
Writes OUT_DIR/<target>/ files in the input layouts tests/fuzz/harness.h
describes. Large files are skipped (fuzzers want small seeds).
"""
import glob, json, os, struct, sys

shared, out = sys.argv[1], sys.argv[2]
LIMIT = 256 * 1024

def put(target, name, data):
    d = os.path.join(out, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)

def small(path):
    return os.path.getsize(path) <= LIMIT

for p in glob.glob("scenes/*.txt"):
    put("scene", os.path.basename(p), open(p, "rb").read())
for p in glob.glob(os.path.join(shared, "assets/gltf/*/glTF-Embedded/*.gltf")) + \
         glob.glob(os.path.join(shared, "assets/gltf/*/glTF/*.gltf")):
    if small(p):
        put("gltf", os.path.basename(os.path.dirname(os.path.dirname(p))) + "-" + os.path.basename(p),
            open(p, "rb").read())
for p in glob.glob(os.path.join(shared, "assets/gltf/*/glTF-Binary/*.glb")):
    if small(p):
        put("glb", os.path.basename(p), open(p, "rb").read())
# .gltf + one external .bin, renamed to buffer.bin
for p in glob.glob(os.path.join(shared, "assets/gltf/*/glTF/*.gltf")):
    try:
        doc = json.load(open(p))
    except Exception:
        continue
    bufs = doc.get("buffers", [])
    if len(bufs) != 1 or "uri" not in bufs[0] or bufs[0]["uri"].startswith("data:"):
        continue
    binpath = os.path.join(os.path.dirname(p), bufs[0]["uri"])
    if not os.path.exists(binpath) or os.path.getsize(binpath) > LIMIT:
        continue
    bufs[0]["uri"] = "buffer.bin"
    js = json.dumps(doc).encode()
    put("gltf_bin", os.path.basename(p), struct.pack("<I", len(js)) + js + open(binpath, "rb").read())
# pose: animated, skinned or morphed models, posed at 0.5 s of animation 0
# (index byte, signed 16-bit time in 1/64 s, then a .glb or a gltf_bin input)
POSE_HEAD = bytes([0]) + struct.pack("<h", 32)
def posable(doc):
    return bool(doc.get("animations") or doc.get("skins")) or \
        any("targets" in pr for m in doc.get("meshes", []) for pr in m.get("primitives", []))
for p in glob.glob(os.path.join(shared, "assets/gltf/*/glTF-Binary/*.glb")):
    if not small(p):
        continue
    data = open(p, "rb").read()
    try:
        doc = json.loads(data[20:20 + struct.unpack_from("<I", data, 12)[0]])
    except Exception:
        continue
    if posable(doc):
        put("pose", os.path.basename(p), POSE_HEAD + data)
for d in (os.path.join(out, "gltf_bin"),):
    for p in glob.glob(os.path.join(d, "*")):
        data = open(p, "rb").read()
        try:
            doc = json.loads(data[4:4 + struct.unpack_from("<I", data, 0)[0]])
        except Exception:
            continue
        if posable(doc):
            put("pose", os.path.basename(p), POSE_HEAD + data)
# json: every .gltf seed as plain text (mode 0)
for p in glob.glob(os.path.join(out, "gltf", "*")):
    put("json", os.path.basename(p), bytes([0, 0, 0]) + open(p, "rb").read())
for p in glob.glob(os.path.join(shared, "assets/cornell/*/*.obj")):
    obj = open(p, "rb").read()
    mtls = glob.glob(os.path.join(os.path.dirname(p), "*.mtl"))
    mtl = open(mtls[0], "rb").read() if mtls else b""
    lines = [b"mtllib m.mtl" if l.startswith(b"mtllib") else l for l in obj.split(b"\n")]
    obj = b"\n".join(lines)
    put("obj", os.path.basename(p), struct.pack("<I", len(obj)) + obj + mtl)
# small PLY and OFF seeds, written here (the shared scans are too large)
tri = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]
ascii_ply = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
    b"property uchar red\nproperty uchar green\nproperty uchar blue\n" \
    b"element face 1\nproperty list uchar int vertex_indices\nend_header\n" + \
    b"".join(b"%g %g %g 255 0 0\n" % v for v in tri) + b"4 0 1 3 2\n"
put("ply", "quad-ascii.ply", ascii_ply)
hdr = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
    b"element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
body = b"".join(struct.pack("<3f", *v) for v in tri) + struct.pack("<i", 5) + struct.pack("<5i", 0, 1, 2, -1, 3)
put("ply", "strip-le.ply", hdr + body)
hdr_be = hdr.replace(b"binary_little_endian", b"binary_big_endian")
body_be = b"".join(struct.pack(">3f", *v) for v in tri) + struct.pack(">i", 4) + struct.pack(">4i", 0, 1, 2, 3)
put("ply", "strip-be.ply", hdr_be + body_be)
put("off", "quad.off", b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
put("off", "coff.off", b"COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n")
for p in glob.glob(os.path.join(shared, "assets/gltf/*/glTF/*.png")) + glob.glob("assets/*.png"):
    if os.path.getsize(p) <= 64 * 1024:
        put("image", os.path.basename(p), open(p, "rb").read())
for p in sorted(glob.glob("tests/corpus/exr/*.exr")):
    put("exr", os.path.basename(p), open(p, "rb").read())

# meshopt and draco streams, cut out of the compressed glTF test files
# (tools/gen_compressed_assets.sh) in the layouts of tests/fuzz/harness.h
MODES = {"ATTRIBUTES": 0, "TRIANGLES": 1, "INDICES": 2}
FILTERS = {"NONE": 0, "OCTAHEDRAL": 1, "QUATERNION": 2, "EXPONENTIAL": 3}
for p in sorted(glob.glob("tests/corpus/glb/compressed-*.glb")):
    data = open(p, "rb").read()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    bin_ = data[20 + jlen + 8:]
    base = os.path.basename(p)[:-4]
    for i, v in enumerate(doc.get("bufferViews", [])):
        mo = v.get("extensions", {}).get("EXT_meshopt_compression")
        if not mo or mo.get("buffer", 0) != 0 or mo["count"] > 65535:
            continue
        stream = bin_[mo.get("byteOffset", 0):mo.get("byteOffset", 0) + mo["byteLength"]]
        mode = MODES[mo["mode"]]
        stride = mo["byteStride"]
        code = stride // 4 - 1 if mode == 0 else (1 if stride == 4 else 0)
        head = bytes([mode, FILTERS[mo.get("filter", "NONE")], code]) + struct.pack("<H", mo["count"])
        put("meshopt", "%s-view%d" % (base, i), head + stream)
    for m in doc.get("meshes", []):
        for pr in m["primitives"]:
            dr = pr.get("extensions", {}).get("KHR_draco_mesh_compression")
            if dr:
                v = doc["bufferViews"][dr["bufferView"]]
                put("draco", "%s-view%d" % (base, dr["bufferView"]),
                    bin_[v.get("byteOffset", 0):v.get("byteOffset", 0) + v["byteLength"]])

# float images for image (textures, environment maps) and image_file (what
# rt compare and rt convert read, PFM too): small Radiance HDR files, run-length
# encoded (16 wide) and flat (4 wide), PFM in both byte orders and grey
def rgbe_pixels(w, h):
    return [[(16 + 7 * x + 3 * y) % 256, (40 + 5 * x) % 256, (90 + 11 * y) % 256, 128 + (x + y) % 3]
            for y in range(h) for x in range(w)]

def radiance(w, h, rle):
    out = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
    px = rgbe_pixels(w, h)
    for y in range(h):
        row = px[y * w:(y + 1) * w]
        if not rle:
            out += b"".join(bytes(p) for p in row)
            continue
        out += bytes([2, 2, w >> 8, w & 255])
        for c in range(4):
            vals = [p[c] for p in row]
            if c == 3:  # the exponents as one run
                out += bytes([128 + w, vals[0]]) if len(set(vals)) == 1 else bytes([w]) + bytes(vals)
            else:       # the mantissas as one dump
                out += bytes([w]) + bytes(vals)
    return out

def pfm(w, h, grey, big):
    ch = 1 if grey else 3
    vals = [((i * 37) % 101) / 17.0 for i in range(w * h * ch)]
    head = b"%s\n%d %d\n%s\n" % (b"Pf" if grey else b"PF", w, h, b"1.0" if big else b"-1.0")
    return head + struct.pack(("%s%df" % (">" if big else "<", len(vals))), *vals)

for target in ("image", "image_file"):
    put(target, "rle-16x4.hdr", radiance(16, 4, True))
    put(target, "flat-4x3.hdr", radiance(4, 3, False))
put("image_file", "rgb-le-5x3.pfm", pfm(5, 3, False, False))
put("image_file", "rgb-be-3x2.pfm", pfm(3, 2, False, True))
put("image_file", "grey-4x2.pfm", pfm(4, 2, True, False))
for p in sorted(glob.glob("tests/corpus/exr/*.exr")):
    put("image_file", os.path.basename(p), open(p, "rb").read())

# nvdb: a small density grid and a two-grid file, written by OpenVDB's own
# tools when they are here (python3-openvdb, libnanovdb-tools)
import subprocess, tempfile
NVDB_SCRIPT = """
import sys, pyopenvdb as vdb
g = vdb.FloatGrid(); g.name = 'density'; a = g.getAccessor()
for i in range(3):
    for j in range(2):
        a.setValueOn((i, j, i - j), 0.25 * (i + 1))
t = vdb.FloatGrid(); t.name = 'temperature'; t.getAccessor().setValueOn((9, 0, 0), 2.0)
vdb.write(sys.argv[1], grids=[g])
vdb.write(sys.argv[2], grids=[g, t])
"""
with tempfile.TemporaryDirectory() as tmp:
    one, two = os.path.join(tmp, "one.vdb"), os.path.join(tmp, "two.vdb")
    try:
        subprocess.run(["/usr/bin/python3", "-c", NVDB_SCRIPT, one, two], check=True, capture_output=True)
        for name, src in (("density.nvdb", one), ("two-grids.nvdb", two)):
            dst = os.path.join(tmp, name)
            subprocess.run(["nanovdb_convert", "-f", src, dst], check=True, capture_output=True)
            put("nvdb", name, open(dst, "rb").read())
    except (OSError, subprocess.CalledProcessError) as e:
        print("fuzz_seeds: no nvdb seeds (python3-openvdb and libnanovdb-tools make them): %s" % e, file=sys.stderr)
