#!/usr/bin/env python3
"""gen_ext_assets.py - small glTF files that isolate the PBR-next material extensions.

    python3 tools/gen_ext_assets.py [OUTDIR]      (default: assets/ext/)

Each file is a row of spheres (the layout of the Khronos sphere-grid test
models) under one camera and one directional light, each sphere a material
that varies one extension parameter; all share sphere.bin (a UV sphere of
radius 0.4, 24 x 12 segments, positions, normals, tangents and UVs, uint16
indices). Standard library only; deterministic, so the committed files
regenerate bit for bit:

  clearcoat.gltf      red base: no coat, coat roughness 0, 0.3, 0.7, half a coat
  specular.gltf       specularFactor 0, 0.5, 1; specularColorFactor blue-ish; F0 x 2
  sheen.gltf          dark blue base, sheen colour / roughness sweep
  anisotropy.gltf     white metal: strength 0, 0.5, 1, rotated by 90 degrees
  iridescence.gltf    film thickness 200, 400, 600 nm over a dark dielectric and a metal
  transmission.gltf   diffuse transmission 0, 0.5, 1 (green), and dispersion on glass
  gallery.gltf        one sphere of each: coat 0.3, gold sheen, blue F0, anisotropic
                      metal, 400 nm film, diffuse transmission (the README picture)
  scatter.gltf        KHR_materials_volume_scatter (draft) under KHR_materials_volume: amber
                      glass that only absorbs, orange wax, milk under diffuse transmission,
                      rough jade scattering forwards
  variants.gltf       KHR_materials_variants: two grey spheres; variant "blue" turns the
                      first blue, "red" the second red
"""
import json
import math
import os
import struct
import sys

SEG_U, SEG_V, R = 24, 12, 0.4


def sphere_bin():
    pos, nrm, tan, uv, idx = [], [], [], [], []
    for j in range(SEG_V + 1):
        v = j / SEG_V
        th = v * math.pi
        for i in range(SEG_U + 1):
            u = i / SEG_U
            ph = u * 2 * math.pi
            n = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
            pos.append(tuple(R * c for c in n))
            nrm.append(n)
            tan.append((-math.sin(ph), 0.0, -math.cos(ph), 1.0))
            uv.append((u, v))
    for j in range(SEG_V):
        for i in range(SEG_U):
            a = j * (SEG_U + 1) + i
            b = a + SEG_U + 1
            idx += [a, b, a + 1, a + 1, b, b + 1]
    data = b"".join(struct.pack("<3f", *p) for p in pos)
    data += b"".join(struct.pack("<3f", *p) for p in nrm)
    data += b"".join(struct.pack("<4f", *p) for p in tan)
    data += b"".join(struct.pack("<2f", *p) for p in uv)
    ib = b"".join(struct.pack("<H", k) for k in idx)
    nv = len(pos)
    return data + ib, nv, len(idx)


def document(materials, bin_len, nv, ni, extra_used=(), variants=None, spheres=None):
    n = spheres or len(materials)  # the first n materials get a sphere each
    off_n, off_t, off_uv = nv * 12, nv * 24, nv * 40
    off_i = nv * 48
    views = [
        {"buffer": 0, "byteOffset": 0, "byteLength": nv * 12},
        {"buffer": 0, "byteOffset": off_n, "byteLength": nv * 12},
        {"buffer": 0, "byteOffset": off_t, "byteLength": nv * 16},
        {"buffer": 0, "byteOffset": off_uv, "byteLength": nv * 8},
        {"buffer": 0, "byteOffset": off_i, "byteLength": ni * 2},
    ]
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3", "min": [-R, -R, -R], "max": [R, R, R]},
        {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": nv, "type": "VEC4"},
        {"bufferView": 3, "componentType": 5126, "count": nv, "type": "VEC2"},
        {"bufferView": 4, "componentType": 5123, "count": ni, "type": "SCALAR"},
    ]
    attrs = {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3}
    meshes, nodes = [], []
    for k in range(n):
        prim = {"attributes": attrs, "indices": 4, "material": k}
        if variants and k in variants["mappings"]:
            prim["extensions"] = {"KHR_materials_variants": {"mappings": variants["mappings"][k]}}
        meshes.append({"primitives": [prim]})
        nodes.append({"mesh": k, "translation": [(k - (n - 1) / 2) * 1.0, 0.0, 0.0]})
    width = max(n, 2) * 1.0
    dist = width / (2 * 2.0 * math.tan(0.5 * 0.5)) + 1.2  # horizontal half-width over tan of half the x fov
    nodes.append({"camera": 0, "translation": [0.0, 0.0, dist]})
    nodes.append({"extensions": {"KHR_lights_punctual": {"light": 0}},
                  "rotation": [-0.3826834, 0.0, 0.0, 0.9238795]})  # 45 degrees down, towards -z
    used = sorted({x for m in materials for x in m.get("extensions", {})} | set(extra_used) | {"KHR_lights_punctual"})
    doc = {
        "asset": {"version": "2.0", "generator": "rt tools/gen_ext_assets.py"},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"nodes": list(range(n + 2))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1}}],
        "buffers": [{"uri": "sphere.bin", "byteLength": bin_len}],
        "bufferViews": views,
        "accessors": accessors,
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 3.0}]}},
    }
    if variants:
        doc["extensions"]["KHR_materials_variants"] = {"variants": [{"name": v} for v in variants["names"]]}
    return doc


def mat(name, color, metallic=0.0, roughness=0.5, **ext):
    m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0],
                                                "metallicFactor": metallic, "roughnessFactor": roughness}}
    if ext:
        m["extensions"] = ext
    return m


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join("assets", "ext")
    os.makedirs(out, exist_ok=True)
    data, nv, ni = sphere_bin()
    with open(os.path.join(out, "sphere.bin"), "wb") as f:
        f.write(data)
    red = (0.6, 0.05, 0.05)
    files = {
        "clearcoat": [
            mat("no coat", red, roughness=0.6),
            mat("mirror coat", red, roughness=0.6, KHR_materials_clearcoat={"clearcoatFactor": 1.0}),
            mat("coat 0.3", red, roughness=0.6,
                KHR_materials_clearcoat={"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.3}),
            mat("coat 0.7", red, roughness=0.6,
                KHR_materials_clearcoat={"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.7}),
            mat("half coat", red, roughness=0.6, KHR_materials_clearcoat={"clearcoatFactor": 0.5}),
        ],
        "specular": [
            mat("specular 0", (0.5, 0.5, 0.5), roughness=0.3, KHR_materials_specular={"specularFactor": 0.0}),
            mat("specular 0.5", (0.5, 0.5, 0.5), roughness=0.3, KHR_materials_specular={"specularFactor": 0.5}),
            mat("specular 1", (0.5, 0.5, 0.5), roughness=0.3),
            mat("blue F0", (0.5, 0.5, 0.5), roughness=0.3,
                KHR_materials_specular={"specularColorFactor": [0.5, 1.0, 2.0]}),
            mat("F0 x 2", (0.5, 0.5, 0.5), roughness=0.3,
                KHR_materials_specular={"specularColorFactor": [2.0, 2.0, 2.0]}),
        ],
        "sheen": [
            mat("no sheen", (0.02, 0.03, 0.15), roughness=0.8),
            mat("white sheen 0.3", (0.02, 0.03, 0.15), roughness=0.8,
                KHR_materials_sheen={"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.3}),
            mat("white sheen 0.8", (0.02, 0.03, 0.15), roughness=0.8,
                KHR_materials_sheen={"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.8}),
            mat("gold sheen 0.5", (0.02, 0.03, 0.15), roughness=0.8,
                KHR_materials_sheen={"sheenColorFactor": [1.0, 0.7, 0.2], "sheenRoughnessFactor": 0.5}),
        ],
        "anisotropy": [
            mat("isotropic", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.3),
            mat("strength 0.5", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.3,
                KHR_materials_anisotropy={"anisotropyStrength": 0.5}),
            mat("strength 1", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.3,
                KHR_materials_anisotropy={"anisotropyStrength": 1.0}),
            mat("strength 1, rotated", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.3,
                KHR_materials_anisotropy={"anisotropyStrength": 1.0, "anisotropyRotation": 1.5707963}),
        ],
        "iridescence": [
            mat("200 nm", (0.02, 0.02, 0.02), roughness=0.2,
                KHR_materials_iridescence={"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": 200}),
            mat("400 nm", (0.02, 0.02, 0.02), roughness=0.2,
                KHR_materials_iridescence={"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": 400}),
            mat("600 nm", (0.02, 0.02, 0.02), roughness=0.2,
                KHR_materials_iridescence={"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": 600}),
            mat("metal 400 nm", (0.8, 0.8, 0.8), metallic=1.0, roughness=0.2,
                KHR_materials_iridescence={"iridescenceFactor": 1.0, "iridescenceIor": 1.8}),
        ],
        "transmission": [
            mat("opaque", (0.2, 0.8, 0.2), roughness=0.5),
            mat("half diffuse transmission", (0.2, 0.8, 0.2), roughness=0.5,
                KHR_materials_diffuse_transmission={"diffuseTransmissionFactor": 0.5,
                                                    "diffuseTransmissionColorFactor": [0.2, 0.8, 0.2]}),
            mat("full diffuse transmission", (0.2, 0.8, 0.2), roughness=0.5,
                KHR_materials_diffuse_transmission={"diffuseTransmissionFactor": 1.0,
                                                    "diffuseTransmissionColorFactor": [0.2, 0.8, 0.2]}),
            mat("dispersive glass", (1, 1, 1), roughness=0.0,
                KHR_materials_transmission={"transmissionFactor": 1.0},
                KHR_materials_volume={"thicknessFactor": 0.8},
                KHR_materials_dispersion={"dispersion": 0.5}),
        ],
        "scatter": [
            mat("amber glass", (1, 1, 1), roughness=0.0,
                KHR_materials_transmission={"transmissionFactor": 1.0},
                KHR_materials_volume={"thicknessFactor": 0.8, "attenuationColor": [0.9, 0.6, 0.3],
                                      "attenuationDistance": 0.5}),
            mat("wax", (1, 1, 1), roughness=0.0,
                KHR_materials_transmission={"transmissionFactor": 1.0},
                KHR_materials_volume={"thicknessFactor": 0.8, "attenuationColor": [0.2, 0.3, 0.4],
                                      "attenuationDistance": 0.1},
                KHR_materials_volume_scatter={"multiscatterColor": [0.95, 0.6, 0.25]}),
            mat("milk", (1, 1, 1), roughness=0.5,
                KHR_materials_diffuse_transmission={"diffuseTransmissionFactor": 1.0},
                KHR_materials_volume={"thicknessFactor": 0.8, "attenuationColor": [0.2, 0.2, 0.2],
                                      "attenuationDistance": 0.1},
                KHR_materials_volume_scatter={"multiscatterColor": [0.97, 0.96, 0.93]}),
            mat("jade", (1, 1, 1), roughness=0.3,
                KHR_materials_transmission={"transmissionFactor": 1.0},
                KHR_materials_ior={"ior": 1.6},
                KHR_materials_volume={"thicknessFactor": 0.8, "attenuationColor": [0.3, 0.5, 0.35],
                                      "attenuationDistance": 0.1},
                KHR_materials_volume_scatter={"multiscatterColor": [0.45, 0.85, 0.55], "scatterAnisotropy": 0.5}),
        ],
    }
    files["gallery"] = [  # one of each, for docs/images/gltf-extensions.png
        files["clearcoat"][2], files["sheen"][3], files["specular"][3], files["anisotropy"][2],
        files["iridescence"][1], files["transmission"][2],
    ]
    for name, mats in files.items():
        doc = document(mats, len(data), nv, ni)
        with open(os.path.join(out, name + ".gltf"), "w") as f:
            json.dump(doc, f, indent=1, sort_keys=True)
            f.write("\n")
    variants = {"names": ["red", "blue"], "mappings": {0: [{"material": 2, "variants": [1]}],
                                                      1: [{"material": 3, "variants": [0]}]}}
    vm = [mat("grey", (0.5, 0.5, 0.5)), mat("grey", (0.5, 0.5, 0.5)), mat("blue", (0.1, 0.1, 0.8)),
          mat("red", (0.8, 0.1, 0.1))]
    doc = document(vm, len(data), nv, ni, extra_used=["KHR_materials_variants"], variants=variants, spheres=2)
    with open(os.path.join(out, "variants.gltf"), "w") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()
