#!/usr/bin/python3
"""Writes the cumulus cloud of scenes/cloud.txt: a density grid made of
overlapping soft spheres (a flat-bottomed heap, as fair-weather cumulus
are) with fractal value noise eroding its edges, as OpenVDB, then
NanoVDB for rt with Debian's nanovdb_convert. Deterministic (fixed seed).
Needs /usr/bin/python3 with python3-openvdb and numpy, and libnanovdb-tools.

    /usr/bin/python3 tools/gen-cloud-grid.py assets/cloud && nanovdb_convert -f assets/cloud.vdb assets/cloud.nvdb && rm assets/cloud.vdb

The grid is 64 x 32 x 48 voxels of 1/16 scene unit (4 x 2 x 3 units), its
index space placed with voxel (0, 0, 0) at (-2, 0, -1.5) + half a voxel;
densities in [0, 1], zero on the outer voxels.
"""
import sys

import numpy as np
import pyopenvdb as vdb

NX, NY, NZ = 64, 32, 48
H = 1.0 / 16.0
LO = (-2.0, 0.0, -1.5)


def value_noise(shape, cells, rng):
    """Smoothly interpolated random lattice values in [0, 1]."""
    lattice = rng.random((cells + 2, cells + 2, cells + 2))
    axes = [np.linspace(0, cells, n, endpoint=False) for n in shape]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    i, j, k = x.astype(int), y.astype(int), z.astype(int)
    fx, fy, fz = [t * t * (3 - 2 * t) for t in (x - i, y - j, z - k)]
    out = 0.0
    for di in (0, 1):
        for dj in (0, 1):
            for dk in (0, 1):
                w = (fx if di else 1 - fx) * (fy if dj else 1 - fy) * (fz if dk else 1 - fz)
                out = out + w * lattice[i + di, j + dj, k + dk]
    return out


def density():
    rng = np.random.default_rng(28)
    x, y, z = np.meshgrid(*[LO[a] + (np.arange(n) + 0.5) * H for a, n in enumerate((NX, NY, NZ))], indexing="ij")
    # the heap: soft spheres (centre, radius), bottoms cut flat at y = 0.3
    puffs = [((0.0, 0.8, 0.0), 0.9), ((-0.9, 0.65, 0.2), 0.65), ((0.9, 0.7, -0.1), 0.7),
             ((0.3, 1.25, 0.3), 0.6), ((-0.4, 1.15, -0.4), 0.55), ((1.4, 0.55, 0.4), 0.45),
             ((-1.4, 0.5, -0.3), 0.4), ((0.2, 0.6, -0.8), 0.55)]
    field = np.zeros_like(x)
    for (cx, cy, cz), r in puffs:
        d = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / r
        field = np.maximum(field, 1.0 - d)
    field *= np.clip((y - 0.25) / 0.15, 0.0, 1.0)  # the flat base
    noise = sum(value_noise((NX, NY, NZ), c, rng) / (1 + o) for o, c in enumerate((4, 8, 16)))
    noise /= sum(1 / (1 + o) for o in range(3))
    d = np.clip((field - 0.35 * (1.0 - noise)) * 4.0, 0.0, 1.0)
    d[0, :, :] = d[-1, :, :] = d[:, 0, :] = d[:, -1, :] = d[:, :, 0] = d[:, :, -1] = 0.0
    return d.astype(np.float32)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = density()
    g = vdb.FloatGrid()
    g.name = "density"
    g.gridClass = vdb.GridClass.FOG_VOLUME
    g.copyFromArray(d, ijk=(0, 0, 0), tolerance=0.0)
    m = [[H, 0, 0, 0], [0, H, 0, 0], [0, 0, H, 0], [LO[0] + H / 2, LO[1] + H / 2, LO[2] + H / 2, 1]]
    g.transform = vdb.createLinearTransform(matrix=m)
    vdb.write(sys.argv[1] + ".vdb", grids=[g])
    print(f"max {d.max():.3f}, mean {d.mean():.4f}, nonzero {int((d > 0).sum())} of {d.size}")


if __name__ == "__main__":
    main()
