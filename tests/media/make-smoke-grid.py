#!/usr/bin/python3
"""Writes one smoke density grid in two formats, for the heterogeneous
comparison with Mitsuba 3 (docs/media.md): OUT.vol (Mitsuba's gridvolume
format) and OUT.vdb (OpenVDB, for `nanovdb_convert OUT.vdb OUT.nvdb`, which
rt reads). Debian's python3 with python3-openvdb and numpy.

    /usr/bin/python3 tests/media/make-smoke-grid.py smoke && nanovdb_convert smoke.vdb smoke.nvdb

The grid: 32 x 10 x 32 voxels of H = 350/32 scene units over the box
x, z in [100, 450], y in [340, 449.375] of the Cornell box (above the
blocks, 99 units under the light: closer, Mitsuba 3 loses shadow rays, see
docs/media.md); values at voxel centres, a lumpy blob that is zero on
the outer voxels, so the two renderers' edge rules (rt: zero outside,
Mitsuba: clamp) agree. OpenVDB puts voxel (i, j, k)'s value at its index
point: the map is scale H then translate by the box corner + H / 2;
Mitsuba spans the unit cube over the box, its values at (i + 0.5) / n.
"""
import struct
import sys

import numpy as np
import pyopenvdb as vdb

NX, NY, NZ = 32, 10, 32
H = 350.0 / 32.0
LO = (100.0, 340.0, 100.0)


def density():
    i, j, k = np.meshgrid(np.arange(NX), np.arange(NY), np.arange(NZ), indexing="ij")
    x, y, z = (i + 0.5) / NX, (j + 0.5) / NY, (k + 0.5) / NZ
    r = np.sqrt(((x - 0.5) / 0.45) ** 2 + ((y - 0.5) / 0.45) ** 2 + ((z - 0.5) / 0.45) ** 2)
    d = np.clip(1.0 - r, 0.0, None) * (0.6 + 0.4 * np.sin(9 * x) * np.sin(7 * y + 1) * np.sin(8 * z + 2))
    d = np.clip(d, 0.0, None) * 2.0
    d[0, :, :] = d[-1, :, :] = d[:, 0, :] = d[:, -1, :] = d[:, :, 0] = d[:, :, -1] = 0.0
    return d.astype(np.float32)  # [i, j, k]


def write_vol(path, d):
    with open(path, "wb") as f:
        f.write(b"VOL" + bytes([3]))
        f.write(struct.pack("<i", 1))  # float32
        f.write(struct.pack("<iiii", NX, NY, NZ, 1))
        f.write(struct.pack("<6f", LO[0], LO[1], LO[2], LO[0] + NX * H, LO[1] + NY * H, LO[2] + NZ * H))
        f.write(np.ascontiguousarray(d.transpose(2, 1, 0)).tobytes())  # x fastest, then y, then z


def write_vdb(path, d):
    g = vdb.FloatGrid()
    g.name = "density"
    g.gridClass = vdb.GridClass.FOG_VOLUME
    g.copyFromArray(d, ijk=(0, 0, 0), tolerance=0.0)
    m = [[H, 0, 0, 0], [0, H, 0, 0], [0, 0, H, 0], [LO[0] + H / 2, LO[1] + H / 2, LO[2] + H / 2, 1]]
    g.transform = vdb.createLinearTransform(matrix=m)
    vdb.write(path, grids=[g])


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = density()
    write_vol(sys.argv[1] + ".vol", d)
    write_vdb(sys.argv[1] + ".vdb", d)
    print(f"max {d.max():.3f}, mean {d.mean():.4f}, nonzero {int((d > 0).sum())}")
