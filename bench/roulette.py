#!/usr/bin/env python3
"""Russian roulette's start depth (rr_depth 3, 5, 0 = adaptive) measured on
the shared Cornell box and on the glass scene of issue 30, for one or more
rt builds (docs/performance.md, "Russian roulette inside glass").

    bench/roulette.py RT_BINARY [RT_BINARY ...]

For each scene, rr_depth and seed (RUNS seeds, 0, 1, ...), every binary
renders in turn (A B A B: the builds interleaved, so a change in the
machine's load falls on all alike) with one thread (`-t 1`), and the row
of a build and rr_depth gets: the process CPU time (user + system) of the
render, the MSE against the scene's reference, both as the mean over the
seeds, and efficiency = 1 / (MSE x CPU time), relative to the first
binary's rr_depth 5 (the default). CPU time rather than wall time: the
machine may be shared; the load average is printed at the start and end.

Scenes: scenes/cornell-reference.txt at 512 x 512 and CORNELL_SPP
(default 16) against $SHARED/reference/cornell/reference.pfm;
bench/cornell-glass.txt at 256 x 256 and GLASS_SPP (default 64) against
GLASS_REF (default build/bench-roulette/glass-reference.pfm, which
bench/glass_reference.py renders with Mitsuba 3). Environment: SHARED
(default ../shared), RUNS (default 3), RR (default "3 5 0"), SCENES
(default "cornell glass"), OUT (the images, default build/bench-roulette).
"""
import os, subprocess, sys

from common import shared, loadavg, children_cpu, rt_compare

here = os.path.dirname(os.path.abspath(__file__))
runs = int(os.environ.get("RUNS", "3"))
rrs = [int(r) for r in os.environ.get("RR", "3 5 0").split()]
out_dir = os.environ.get("OUT", "build/bench-roulette")
rts = sys.argv[1:]
scenes = [
    ("cornell", os.path.join(here, "..", "scenes", "cornell-reference.txt"), 512,
     int(os.environ.get("CORNELL_SPP", "16")), os.path.join(shared, "reference", "cornell", "reference.pfm")),
    ("glass", os.path.join(here, "cornell-glass.txt"), 256, int(os.environ.get("GLASS_SPP", "64")),
     os.environ.get("GLASS_REF", os.path.join(out_dir, "glass-reference.pfm"))),
]
if not rts:
    sys.exit(__doc__)
only = os.environ.get("SCENES", "cornell glass").split()
scenes = [sc for sc in scenes if sc[0] in only]
for _, scene, _, _, ref in scenes:
    for path in [scene, ref] + rts:
        if not os.path.exists(path):
            sys.exit("roulette: no %s" % path)
os.makedirs(out_dir, exist_ok=True)


def run(binary, b, scene, res, spp, rr, seed, ref, tag):
    image = os.path.join(out_dir, "%s-b%d-rr%d-s%d.pfm" % (tag, b, rr, seed))
    c0 = children_cpu()
    p = subprocess.run([binary, "-q", "-t", "1", "-s", str(spp), "-r", "%dx%d" % (res, res), "--seed", str(seed),
                        "--set", "rr_depth=%d" % rr, "-o", image, scene], capture_output=True, text=True)
    cpu = children_cpu() - c0
    if p.returncode != 0:
        sys.exit("roulette: %s failed: %s" % (binary, p.stderr.strip()))
    d, err = rt_compare(rts[-1], image, ref)
    if d is None:
        sys.exit("roulette: rt compare %s: %s" % (image, err))
    return cpu, float(d["MSE"].split()[0])


print("load average at the start: " + loadavg())
for tag, scene, res, spp, ref in scenes:
    rows = {}
    for rr in rrs:
        for seed in range(runs):
            for b, binary in enumerate(rts):
                cpu, mse = run(binary, b, scene, res, spp, rr, seed, ref, tag)
                rows.setdefault((b, rr), []).append((cpu, mse))
                print("  %s rr_depth %d seed %d build %d: %.2f s CPU, MSE %.4g" % (tag, rr, seed, b, cpu, mse),
                      file=sys.stderr, flush=True)
    print("\n%s (%dx%d, %d spp, %d seeds, -t 1)\n" % (tag, res, res, spp, runs))
    print("| build | `rr_depth` | CPU s (min-max) | RMSE | efficiency |")
    print("| --- | --- | ---: | ---: | ---: |")
    for rr in rrs:
        for b, binary in enumerate(rts):
            r = rows[(b, rr)]
            cpu = sum(c for c, _ in r) / len(r)
            mse = sum(m for _, m in r) / len(r)
            eff = 1.0 / (mse * cpu)
            rows[(b, rr)] = (cpu, min(c for c, _ in r), max(c for c, _ in r), mse, eff)
    base = rows[(0, 5)][4] if (0, 5) in rows else rows[(0, rrs[0])][4]
    for rr in rrs:
        for b, binary in enumerate(rts):
            cpu, lo, hi, mse, eff = rows[(b, rr)]
            print("| %s | %d | %.2f (%.2f-%.2f) | %.5f | %.3f |" % (binary, rr, cpu, lo, hi, mse ** 0.5, eff / base))
    sys.stdout.flush()
print("\nload average at the end: " + loadavg())
