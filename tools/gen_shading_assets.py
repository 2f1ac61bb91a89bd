#!/usr/bin/env python3
"""gen_shading_assets.py - writes the small textures and meshes the shading scenes use.

    python3 tools/gen_shading_assets.py [OUTDIR]      (default: assets/)

Deterministic (fixed seeds), standard library only (zlib for PNG), so the
committed files can be regenerated bit for bit:

  brick_color.png   256x256 sRGB colour: running-bond bricks, 4 courses of 2
                    bricks per tile, per-brick tint, mortar lines. Tiles
                    seamlessly (repeat wrap).
  brick_normal.png  256x256 tangent-space normal map of the same layout
                    (glTF convention: R = +u (right), G = +Y = towards the
                    top of the image, B = out of the surface; n = 2c - 1),
                    from a height field: flat brick faces (exactly
                    (128, 128, 255)), bevelled edges, recessed mortar.
  tiles_color.png   128x128 sRGB colour: a 4x4 grid of warm glazed tiles.
  vase.obj          a surface of revolution (a vase), 36 segments round and
                    24 up its profile (quads), with vertex normals and UVs: u once
                    round (a seam of duplicated vertices at u = 0/1), v along
                    the profile, written the OBJ way (v up: OBJ's v = 0 is
                    the bottom of the image; rt flips on load).
  donut.obj         a torus (R = 1, r = 0.35), 40 x 16 quads, normals and
                    UVs (u round the big circle, v round the tube).
"""
import math
import os
import random
import struct
import sys
import zlib


def png_write(path, width, height, rows):
    """rows: list of bytes objects, each width*3 RGB bytes, top row first."""
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", ihdr))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def to_srgb8(c):
    c = min(max(c, 0.0), 1.0)
    s = c * 12.92 if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
    return int(round(s * 255))


# ---------------------------------------------------------------- bricks

SIZE = 256
COURSES = 4          # brick rows per tile
BRICKS = 2           # bricks per row
MORTAR = 5           # mortar width in texels
BEVEL = 4            # bevel width in texels


def brick_cell(x, y):
    """(row, column, distance to the nearest brick edge in texels) at texel (x, y)."""
    h = SIZE // COURSES
    w = SIZE // BRICKS
    row = y // h
    xs = (x + (w // 2 if row % 2 else 0)) % SIZE
    col = xs // w
    lx, ly = xs - col * w, y - row * h
    # mortar occupies the first MORTAR texels of each brick cell in x and y
    dx = min(lx - MORTAR, w - 1 - lx)
    dy = min(ly - MORTAR, h - 1 - ly)
    return row, col, min(dx, dy)


def brick_height(x, y):
    _, _, d = brick_cell(x % SIZE, y % SIZE)
    if d < 0:
        return 0.0                      # mortar
    if d >= BEVEL:
        return 1.0                      # flat brick face
    t = (d + 0.5) / BEVEL
    return 0.25 + 0.75 * math.sin(t * math.pi / 2)


def gen_bricks(outdir):
    rnd = random.Random(7)
    tints = {}
    for row in range(COURSES):
        for col in range(BRICKS):
            k = rnd.uniform(-1, 1)
            tints[(row, col)] = (0.45 + 0.10 * k, 0.16 + 0.05 * k + rnd.uniform(-0.02, 0.02), 0.10 + 0.03 * k)
    color_rows, normal_rows = [], []
    strength = 2.5  # height units per texel of slope
    for y in range(SIZE):
        crow, nrow = bytearray(), bytearray()
        for x in range(SIZE):
            row, col, d = brick_cell(x, y)
            if d < 0:
                c = (0.42, 0.40, 0.36)
            else:
                t = tints[(row, col)]
                shade = 0.92 + 0.08 * math.sin(0.31 * x + 0.17 * y) * math.sin(0.13 * x - 0.23 * y)
                c = tuple(v * shade for v in t)
            crow += bytes(to_srgb8(v) for v in c)
            # central differences of the height field (tiles: wrap around)
            dhdx = (brick_height(x + 1, y) - brick_height(x - 1, y)) * 0.5 * strength
            dhdy = (brick_height(x, y + 1) - brick_height(x, y - 1)) * 0.5 * strength
            # tangent space: +x right, +y up (image y grows downwards), +z out
            nx, ny, nz = -dhdx, dhdy, 1.0
            inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
            nx, ny, nz = nx * inv, ny * inv, nz * inv
            if dhdx == 0.0 and dhdy == 0.0:
                nrow += bytes((128, 128, 255))  # exactly flat
            else:
                nrow += bytes(min(255, max(0, int(round((v * 0.5 + 0.5) * 255)))) for v in (nx, ny, nz))
        color_rows.append(crow)
        normal_rows.append(nrow)
    png_write(os.path.join(outdir, "brick_color.png"), SIZE, SIZE, color_rows)
    png_write(os.path.join(outdir, "brick_normal.png"), SIZE, SIZE, normal_rows)


def gen_tiles(outdir):
    n, cells = 128, 4
    rnd = random.Random(11)
    colors = [(rnd.uniform(0.55, 0.8), rnd.uniform(0.3, 0.5), rnd.uniform(0.1, 0.25)) for _ in range(cells * cells)]
    rows = []
    step = n // cells
    for y in range(n):
        r = bytearray()
        for x in range(n):
            cx, cy = x // step, y // step
            lx, ly = x % step, y % step
            if lx < 2 or ly < 2:
                c = (0.85, 0.83, 0.78)  # grout
            else:
                base = colors[cy * cells + cx]
                g = 1.0 - 0.25 * ((lx + ly) / (2 * step))  # glaze gradient
                c = tuple(v * g for v in base)
            r += bytes(to_srgb8(v) for v in c)
        rows.append(r)
    png_write(os.path.join(outdir, "tiles_color.png"), n, n, rows)


# ---------------------------------------------------------------- meshes

def write_obj(path, header, verts, normals, uvs, faces):
    with open(path, "w") as f:
        f.write(header)
        for v in verts:
            f.write("v %.4f %.4f %.4f\n" % v)
        for t in uvs:
            f.write("vt %.4f %.4f\n" % t)
        for n in normals:
            f.write("vn %.3f %.3f %.3f\n" % n)
        for face in faces:
            f.write("f " + " ".join("%d/%d/%d" % (i + 1, i + 1, i + 1) for i in face) + "\n")


def lathe(profile, segments):
    """profile: list of (radius, height) bottom to top. Returns a quad grid
    with a seam column duplicated so u runs 0..1."""
    # arc length along the profile for v
    lengths = [0.0]
    for (r0, y0), (r1, y1) in zip(profile, profile[1:]):
        lengths.append(lengths[-1] + math.hypot(r1 - r0, y1 - y0))
    total = lengths[-1]
    verts, normals, uvs, faces = [], [], [], []
    rows = len(profile)
    for j, (r, y) in enumerate(profile):
        # profile tangent -> normal in the (r, y) plane
        a = profile[max(j - 1, 0)]
        b = profile[min(j + 1, rows - 1)]
        dr, dy = b[0] - a[0], b[1] - a[1]
        ln = math.hypot(dr, dy) or 1.0
        nr, ny = dy / ln, -dr / ln
        for i in range(segments + 1):
            u = i / segments
            phi = 2 * math.pi * u
            # u grows anticlockwise seen from above, starting at +z, so the
            # outside faces outwards with counter-clockwise faces below
            s, c = math.sin(phi), math.cos(phi)
            verts.append((r * s, y, r * c))
            normals.append((nr * s, ny, nr * c))
            uvs.append((u, lengths[j] / total))
    for j in range(rows - 1):
        for i in range(segments):
            a = j * (segments + 1) + i
            b = a + 1
            c = a + (segments + 1)
            d = c + 1
            faces.append((a, b, d, c))
    return verts, normals, uvs, faces


def gen_vase(outdir):
    profile = []
    n = 24
    for k in range(n + 1):
        t = k / n
        y = 1.6 * t
        r = 0.38 + 0.22 * math.sin(math.pi * (t * 1.15 + 0.05)) - 0.12 * math.exp(-((t - 0.82) / 0.08) ** 2)
        r = r + 0.06 * t ** 6
        profile.append((max(r, 0.05), y))
    verts, normals, uvs, faces = lathe(profile, 36)
    write_obj(os.path.join(outdir, "vase.obj"),
              "# vase.obj - written by tools/gen_shading_assets.py: a surface of revolution with normals and UVs\n",
              verts, normals, uvs, faces)


def gen_torus(outdir):
    R, r, nu, nv = 1.0, 0.35, 40, 16
    verts, normals, uvs, faces = [], [], [], []
    for j in range(nv + 1):
        v = j / nv
        th = 2 * math.pi * v
        for i in range(nu + 1):
            u = i / nu
            ph = 2 * math.pi * u
            cx, cz = math.sin(ph), math.cos(ph)
            nx, ny, nz = math.cos(th) * cx, math.sin(th), math.cos(th) * cz
            verts.append((R * cx + r * nx, r * ny, R * cz + r * nz))
            normals.append((nx, ny, nz))
            uvs.append((u, v))
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            b = a + 1
            c = a + (nu + 1)
            d = c + 1
            faces.append((a, b, d, c))
    write_obj(os.path.join(outdir, "donut.obj"),
              "# donut.obj - written by tools/gen_shading_assets.py: R = 1, r = 0.35, normals and UVs\n",
              verts, normals, uvs, faces)


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else "assets"
    os.makedirs(outdir, exist_ok=True)
    gen_bricks(outdir)
    gen_tiles(outdir)
    gen_vase(outdir)
    gen_torus(outdir)


if __name__ == "__main__":
    main()
