#!/usr/bin/env python3
"""make bench-instances: rt's instanced kd-tree against the same scene
flattened, and against Embree 3's instances, on the same rays in one run.

Two scenes, written by tools/gen-instanced-gltf.py into build/bench-instances
(with the primary rays of a camera over the field, 640x480): `field`, 100
instances of a 9,800-triangle mesh (980,000 placed triangles), and
`helmets`, DamagedHelmet's mesh from the shared models placed 64 times
(989,000 placed triangles). For each scene, bench/rtbench writes rt's loaded
instanced scene (--write-scene: the objects' triangles and rt's own
transforms) and bench/embree_instances builds Embree's two levels from it
(an RTC_GEOMETRY_TYPE_INSTANCE per instance over one scene per object, high
quality) and its flattened single-level BVH; Embree's instanced hits are
the reference rt's runs are checked against (mismatches).

Then, per query kind (single rays: rt_kdtree_intersect and rtcIntersect1;
packets: 4x4-pixel tiles, rt_kdtree_intersect16 and rtcIntersect16;
frustum: rt's 8x8 tiles through rt_kdtree_intersect_frustum, beside
Embree's rtcIntersect16 on 4x4 tiles, Embree having no frustum call;
streams: rt_kdtree_intersect_stream and rtcIntersect1M, 4096 rays a call)
and thread count (1, 2), the four
configurations interleaved, ROUNDS times (A B C D A B C D): rt instanced,
rt flattened, Embree instanced, Embree flattened. Figures are rays per
CPU-second of the median run (summed over threads: on a shared, loaded
machine the steadier figure), with the ratios rt instanced / rt flattened
and rt instanced / Embree instanced.
Environment: SHARED (default ../shared), RUNS (default 3 runs per
process), ROUNDS (default 2), SCENES (default "field helmets"), KINDS
(default "single packets frustum stream"), THREADS (default "1 2").
"""
import os, subprocess, sys

import common
from common import shared, loadavg

out_dir = os.path.join("build", "bench-instances")
runs = os.environ.get("RUNS", "3")
rounds = int(os.environ.get("ROUNDS", "2"))
scenes = os.environ.get("SCENES", "field helmets").split()
kinds = os.environ.get("KINDS", "single packets frustum stream").split()
threads_list = [int(t) for t in os.environ.get("THREADS", "1 2").split()]
embree = os.path.join(out_dir, "embree_instances")

common.ensure_embree("bench-instances")
os.makedirs(out_dir, exist_ok=True)
subprocess.check_call(["cc", "-O3", "-march=native", "-std=c11", "-Wall", "-Wextra", "-o", embree,
                       "bench/embree_instances.c", "-lembree3", "-lpthread", "-lm"])

gen = {
    "field": ["--instances", "100", "--triangles", "10000"],
    "helmets": ["--instances", "64", "--mesh-from",
                os.path.join(shared, "assets/gltf/DamagedHelmet/glTF-Binary/DamagedHelmet.glb")],
}


def path(scene, ext):
    return os.path.join(out_dir, scene + "." + ext)


def rt(scene, kind, t, instanced):
    extra = {"single": [], "packets": ["--packets", "4", "4"], "frustum": ["--frustum", "8", "8"],
             "stream": ["--stream"]}[kind]
    d = common.rtbench([path(scene, "glb"), path(scene, "rays"), "--ref", path(scene, "emb.hits"), "-t", str(t),
                        "--runs", runs, "--build-threads", "2"] + (["--instances"] if instanced else []) + extra)
    if d["status"] not in (0, 1):
        sys.exit("bench-instances: rtbench failed: " + d["stderr"])
    return float(d["cpu_mrays_per_s"]), d.get("mismatches", "?"), d.get("hits", "?")


def emb(scene, kind, t, flat):
    mode = {"single": "single", "packets": "packets", "frustum": "packets", "stream": "stream"}[kind]
    p = subprocess.run([embree, path(scene, "inst"), path(scene, "rays"), "-t", str(t), "--runs", runs, "--mode", mode]
                       + (["--flat"] if flat else []), capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bench-instances: embree_instances failed: " + p.stderr)
    d = common.key_values(p.stdout)
    return float(d["cpu_mrays_per_s"]), d.get("hits", "?")


def median(xs):
    xs = sorted(xs)
    n = len(xs)
    return xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])


print("load average at start: " + loadavg() + "; Mrays per CPU-second (median run of " + runs + ", median of " +
      str(rounds) + " interleaved rounds)")
for scene in scenes:
    if not os.path.exists(path(scene, "rays")):
        subprocess.check_call([sys.executable, "tools/gen-instanced-gltf.py", path(scene, "glb"), "--rays",
                               path(scene, "rays")] + gen[scene])
    w = common.rtbench([path(scene, "glb"), path(scene, "rays"), "--instances", "--runs", "1", "--limit", "1000",
                        "--write-scene", path(scene, "inst")])
    if w["status"] != 0:
        sys.exit("bench-instances: rtbench --write-scene failed: " + w["stderr"])
    subprocess.check_call([embree, path(scene, "inst"), path(scene, "rays"), "--runs", "1", "--out",
                           path(scene, "emb.hits")], stdout=subprocess.DEVNULL)
    print("\n%s: %s instances, %s unique triangles" % (scene, w.get("instances"), w.get("triangles")))
    print("%-8s %3s %9s %9s %6s %9s %9s %6s %6s %10s" % ("kind", "thr", "rt inst", "rt flat", "ratio", "Emb inst",
                                                          "Emb flat", "ratio", "rt/Emb", "mismatches"))
    for kind in kinds:
        for t in threads_list:
            a, b, c, d, mm = [], [], [], [], []
            for _ in range(rounds):
                x, m1, _h = rt(scene, kind, t, True)
                y, m2, _h = rt(scene, kind, t, False)
                a.append(x), b.append(y), mm.append("%s/%s" % (m1, m2))
                c.append(emb(scene, kind, t, False)[0])
                d.append(emb(scene, kind, t, True)[0])
            ri, rf, ei, ef = median(a), median(b), median(c), median(d)
            print("%-8s %3d %9.3f %9.3f %6.2f %9.3f %9.3f %6.2f %6.2f %10s" % (
                kind, t, ri, rf, ri / rf, ei, ef, ei / ef, ri / ei, " ".join(mm)), flush=True)
print("\nload average at end: " + loadavg())
