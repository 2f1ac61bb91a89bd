#!/usr/bin/env python3
"""One timed Mitsuba 3 render of the shared Cornell box, for bench/render.py.

Run with the Python of build/mitsuba-venv (bench/render.sh makes it):

    mitsuba_render.py SCENE_XML VARIANT SPP THREADS RES OUT.pfm

Loads SCENE_XML (the shared reference/cornell/scene.xml) with its sampler
switched from `independent` to `multijitter` (stratified, like rt's CMJ),
the given samples per pixel and resolution, sets Dr.Jit's thread pool to
THREADS, and renders it. For the `llvm_*` variants the first render in a
process traces the integrator and compiles it with LLVM (or finds it in
Dr.Jit's kernel cache on disk); a second render in the same process reuses
the compiled kernel, which is what a user sees from the second frame on (an
interactive session, an optimisation loop, a batch of renders in one
script). Both are timed: `first` and `warm`; bench/render.py takes `warm`
as the render time. `scalar_*` variants compile nothing: one render, timed
as both. Prints one JSON line: first_s, warm_s, cpu_s (process CPU seconds
of the warm render, all threads), and the variant's versions.
"""
import json, os, sys, time


def write_pfm(path, img):
    """The image as a colour PFM (rows bottom to top), by hand: Mitsuba's
    own EXR writer hung (a futex wait) with a one-thread Dr.Jit pool."""
    import numpy as np
    a = np.ascontiguousarray(np.array(img, dtype=np.float32)[::-1, :, :3])
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (a.shape[1], a.shape[0]))
        f.write(a.astype("<f4").tobytes())


def main():
    if len(sys.argv) != 7:
        sys.exit(__doc__)
    xml_path, variant, spp, threads, res, out = sys.argv[1:]
    spp, threads, res = int(spp), int(threads), int(res)
    import drjit as dr
    import mitsuba as mi
    dr.set_thread_count(threads)
    mi.set_variant(variant)
    scene_dir = os.path.dirname(os.path.abspath(xml_path))
    mi.file_resolver().prepend(scene_dir)
    with open(xml_path) as f:
        xml = f.read()
    if 'type="independent"' not in xml:
        sys.exit("mitsuba_render: %s has no independent sampler to replace" % xml_path)
    xml = xml.replace('type="independent"', 'type="multijitter"')
    scene = mi.load_string(xml, spp=str(spp), res=str(res))

    def render():
        t0, c0 = time.perf_counter(), time.process_time()
        img = mi.render(scene, spp=spp, seed=0)
        dr.eval(img)
        dr.sync_thread()
        return img, time.perf_counter() - t0, time.process_time() - c0

    img, first, cpu = render()
    warm = first
    if variant.startswith(("llvm", "cuda")):
        img, warm, cpu = render()
    write_pfm(out, img)
    print(json.dumps({"first_s": first, "warm_s": warm, "cpu_s": cpu, "mitsuba": mi.__version__,
                      "drjit": dr.__version__, "variant": variant, "threads": threads}))


if __name__ == "__main__":
    main()
