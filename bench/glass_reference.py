#!/usr/bin/env python3
"""The converged Mitsuba 3 reference of bench/cornell-glass.xml (the glass
and gold spheres in the Cornell box, issue 30), for bench/roulette.py.

Run with the Python of build/mitsuba-venv (make bench-render sets it up,
with DRJIT_LIBLLVM_PATH pointing at Debian's libLLVM-19.so):

    glass_reference.py RES CHUNKS SPP_PER_CHUNK OUT.pfm

Renders the scene with the `llvm_ad_rgb` variant, its `path` integrator
(unlimited depth, Russian roulette from depth 5, throughput weighed by
eta^2) and `independent` sampler, in CHUNKS independent renders of
SPP_PER_CHUNK samples (seeds 0, 1, ...), and writes their mean as a
colour PFM; it also prints the RMSE between the means of the even and the
odd chunks, halved: about the reference's own noise. The walls' meshes
come from $SHARED/reference/cornell (default ../shared).
"""
import os, sys, time


def write_pfm(path, a):
    import numpy as np
    a = np.ascontiguousarray(np.asarray(a, dtype=np.float32)[::-1, :, :3])
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (a.shape[1], a.shape[0]))
        f.write(a.astype("<f4").tobytes())


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    res, chunks, spp, out = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    import numpy as np
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    here = os.path.dirname(os.path.abspath(__file__))
    mi.file_resolver().prepend(os.path.join(os.environ.get("SHARED", "../shared"), "reference", "cornell"))
    scene = mi.load_file(os.path.join(here, "cornell-glass.xml"), spp=str(spp), res=str(res))
    sums = [np.zeros((res, res, 3)), np.zeros((res, res, 3))]
    t0 = time.perf_counter()
    for c in range(chunks):
        img = mi.render(scene, spp=spp, seed=c)
        sums[c % 2] += np.asarray(img, dtype=np.float64)[:, :, :3]
        print("chunk %d/%d, %.0f s" % (c + 1, chunks, time.perf_counter() - t0), file=sys.stderr, flush=True)
    mean = (sums[0] + sums[1]) / chunks
    half = chunks // 2
    if half:
        even, odd = sums[0] / (chunks - half), sums[1] / half
        print("half-difference RMSE %.5f, image mean %s" % (np.sqrt(np.mean((even - odd) ** 2)) / 2,
                                                            mean.reshape(-1, 3).mean(0)))
    write_pfm(out, mean)


main()
