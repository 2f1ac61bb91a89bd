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
