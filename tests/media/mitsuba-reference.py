#!/usr/bin/env python3
"""Renders the Mitsuba 3 reference of a media test scene (docs/media.md).

    python3 tests/media/mitsuba-reference.py SCENE.xml OUT.exr [SPP [VARIANT]]

SCENE.xml reads the shared Cornell box meshes from $meshes, set here to
$SHARED/reference/cornell/meshes (SHARED defaults to ../shared, as make test's).
SPP (default 1024) is rendered in independent chunks of 256 with seeds 0, 1, ...
(plus $SEED, default 0) and averaged; VARIANT defaults to llvm_ad_rgb (scalar_rgb works too, slower).
Needs `pip install mitsuba` (3.9.1 made the figures in docs/media.md). Then:

    ./rt -s 1024 -o rt.pfm tests/media/cornell-smoke-sphere.txt
    ./rt compare rt.pfm OUT.exr
"""
import os
import sys
import time

import mitsuba as mi


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    spp = int(sys.argv[3]) if len(sys.argv) > 3 else 1024
    mi.set_variant(sys.argv[4] if len(sys.argv) > 4 else "llvm_ad_rgb")
    meshes = os.path.join(os.environ.get("SHARED", "../shared"), "reference", "cornell", "meshes")
    with open(sys.argv[1]) as f:
        takes_meshes = "$meshes" in f.read()
    params = {"meshes": os.path.abspath(meshes)} if takes_meshes else {}
    scene = mi.load_file(sys.argv[1], **params)
    seed0 = int(os.environ.get("SEED", "0"))
    chunk = min(256, spp)
    chunks = max(1, spp // chunk)
    start = time.time()
    total = None
    for k in range(chunks):
        img = mi.render(scene, spp=chunk, seed=seed0 + k)
        total = img if total is None else total + img
    mi.Bitmap(total / chunks).write(sys.argv[2])
    print(f"{chunks * chunk} spp in {time.time() - start:.1f} s ({mi.variant()})")


if __name__ == "__main__":
    main()
