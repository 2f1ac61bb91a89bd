#!/usr/bin/env python3
"""Mitsuba 3's own noise on bench/cornell-glass.xml at a given sample count,
to set rt's beside (issue 24, "Variance where it is cheap";
docs/performance.md, "Glass box: rt against Mitsuba at equal samples").

Run with the Python of build/mitsuba-venv (make bench-render sets it up,
with DRJIT_LIBLLVM_PATH pointing at Debian's libLLVM-19.so):

    glass_equal_spp.py REF.pfm RES SPP SAMPLER SEED... [-- RT.pfm...]

Renders the scene with `llvm_ad_rgb` (its `path` integrator as in the
file) and sampler SAMPLER (independent, multijitter, stratified, ...) once
per SEED, and prints each render's RMSE against REF.pfm (the converged
reference of bench/glass_reference.py, whose chunks use seeds 0 to
CHUNKS - 1: pick seeds above them) and its CPU time; then the RMSE of each
rt image given after `--` (colour PFM, same resolution).
"""
import os, sys, time


def read_pfm(path):
    import numpy as np
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        a = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").reshape(h, w, 3)
    return a[::-1].astype(np.float64)


def rmse(a, b):
    import numpy as np
    return float(np.sqrt(np.mean((a - b) ** 2)))


def main():
    args = sys.argv[1:]
    rt_images = []
    if "--" in args:
        k = args.index("--")
        args, rt_images = args[:k], args[k + 1:]
    if len(args) < 5:
        sys.exit(__doc__)
    ref = read_pfm(args[0])
    res, spp, sampler, seeds = int(args[1]), int(args[2]), args[3], [int(s) for s in args[4:]]
    import numpy as np
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    here = os.path.dirname(os.path.abspath(__file__))
    mi.file_resolver().prepend(os.path.join(os.environ.get("SHARED", "../shared"), "reference", "cornell"))
    with open(os.path.join(here, "cornell-glass.xml")) as f:
        xml = f.read().replace('<sampler type="independent">', '<sampler type="%s">' % sampler)
    scene = mi.load_string(xml, spp=str(spp), res=str(res))
    mi.render(scene, spp=1, seed=9999)  # compile the kernels before timing
    for seed in seeds:
        c0 = time.process_time()
        img = np.asarray(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)[:, :, :3]
        print("mitsuba %s seed %d: RMSE %.5f, CPU %.2f s, mean %s" % (sampler, seed, rmse(img, ref),
              time.process_time() - c0, img.reshape(-1, 3).mean(0)), flush=True)
    for p in rt_images:
        img = read_pfm(p)
        print("rt %s: RMSE %.5f, mean %s" % (p, rmse(img, ref), img.reshape(-1, 3).mean(0)), flush=True)


main()
