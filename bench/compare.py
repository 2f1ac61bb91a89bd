#!/usr/bin/env python3
"""make bench-compare: rt's kd-tree and Embree 3 on the same rays, back to back.

For every model in $SHARED/bench/MANIFEST.md, runs Embree (the shared
bench/embree/embree-figures script: rtcIntersect1 and the ray-stream API
rtcIntersect1M on chunks of 4096 rays, incoherent and coherent, high-quality
BVH) and then bench/rtbench on the primary and diffuse ray sets with 1 and 2
threads, single rays and ray streams (--stream, 4096 rays a call)
alternating, and prints Mrays/s with the ratios rt/Embree rtcIntersect1
(single rays), rt stream/Embree's best stream, and rt's best/Embree's best
of those APIs; then build time ratios against Embree's high-quality build,
and rt's bytes per triangle. The machines are shared and noisy, so only
ratios from one run mean much.
Environment: SHARED (default ../shared), RUNS (default 5), METRIC (wall, the
default: Mrays/s of the median run; cpu: rays per CPU-second of each
thread, summed over the threads, the steadier figure on a loaded machine:
Embree's cpu_mrays_s, and rt's cpu_mrays_per_s (rays per CPU-second of the
whole process) times the thread count, the same measure when the threads
share the work evenly).
"""
import json, os, subprocess, sys

import common
from common import shared, runs, embree_dir, build, loadavg

metric = os.environ.get("METRIC", "wall")
rt_key, emb_key = ("cpu_mrays_per_s", "cpu_mrays_s") if metric == "cpu" else ("mrays_per_s", "mrays_s")
manifest, models = common.bench_models("bench-compare")
common.ensure_embree("bench-compare")


def rtbench(glb, model, kind, threads, extra=()):
    return common.rtbench([os.path.join(shared, glb),
                           os.path.join(shared, "bench", model, "%s.%s.rays" % (model, kind)),
                           "--ref", os.path.join(shared, "bench", model, "%s.%s.hits" % (model, kind)),
                           "-t", str(threads), "--runs", runs] + list(extra))

print("load average at start: " + loadavg() + "; Mrays/s " + ("per CPU-second" if metric == "cpu" else "(wall clock)"))
print("%-28s %-8s %3s %9s %9s %6s %9s %9s %6s %6s %11s" % ("model", "kind", "thr", "rt 1", "Embree 1", "ratio",
                                                             "rt 1M", "Embree 1M", "ratio", "best", "mismatches"))
summary = []
for model, glb in models:
    emb = subprocess.run([os.path.join(embree_dir, "embree-figures"), model, runs], capture_output=True, text=True,
                         env=dict(os.environ, BUILD=build))
    if emb.returncode != 0:
        print(emb.stderr, file=sys.stderr)
        sys.exit("bench-compare: embree-figures failed for " + model)
    figures = {}
    for line in emb.stdout.splitlines():
        kind, _, js = line.partition(": ")
        figures[kind] = json.loads(js)["results"]
    build_js = json.loads(subprocess.run([os.path.join(build, "anchor"), "build", os.path.join(build, model + ".tri"),
                                          "--reps", "3"], capture_output=True, text=True, check=True).stdout)
    emb_build = build_js["build_ms"]["high_1T"]["median"]
    emb_build2 = build_js["build_ms"]["high_2T"]["median"]
    rt_build = bytes_tri = None
    for kind in ("primary", "diffuse"):
        for t in (1, 2):
            r = rtbench(glb, model, kind, t)
            rs = rtbench(glb, model, kind, t, ["--stream"])
            f = figures[kind]
            e = f["single_%dT" % t][emb_key]
            es = max(f.get("stream_%dT" % t, {}).get(emb_key, 0), f.get("stream_coherent_%dT" % t, {}).get(emb_key, 0))
            eb = max([e, es] + [v[emb_key] for k, v in f.items() if k.endswith("_%dT" % t) and emb_key in v])
            mr, ms = float(r.get(rt_key, 0)), float(rs.get(rt_key, 0))
            if metric == "cpu":
                mr, ms = mr * t, ms * t
            print("%-28s %-8s %3d %9.2f %9.2f %6.2f %9.2f %9.2f %6.2f %6.2f %11s" % (
                model, kind, t, mr, e, mr / e if e else 0, ms, es, ms / es if es else 0,
                max(mr, ms) / eb if eb else 0, "%s/%s" % (r.get("mismatches", "?"), rs.get("mismatches", "?"))))
            rt_build = float(r.get("build_ms", 0))
            bytes_tri = r.get("bytes_per_triangle")
    rt_build1 = float(rtbench(glb, model, "diffuse", 1, ["--build-threads", "1", "--runs", "1"]).get("build_ms", 0))
    summary.append((model, rt_build1, emb_build, rt_build, emb_build2, bytes_tri))
print()
print("%-28s %10s %10s %6s %10s %10s %6s %10s" % ("model", "rt 1T ms", "Embree 1T", "ratio", "rt 2T ms", "Embree 2T",
                                                 "ratio", "bytes/tri"))
for model, rb1, eb1, rb2, eb2, bt in summary:
    print("%-28s %10.1f %10.1f %6.2f %10.1f %10.1f %6.2f %10s" % (model, rb1, eb1, rb1 / eb1 if eb1 else 0, rb2, eb2,
                                                                 rb2 / eb2 if eb2 else 0, bt))
print("(build: rt's kd-tree vs Embree's high-quality BVH build, 1 and 2 threads)")
print("(rt 1: rt_kdtree_intersect, rt 1M: rt_kdtree_intersect_stream at the widest SIMD width, stream_lanes %s;"
      " Embree 1M: the better of rtcIntersect1M incoherent and coherent; best: rt's better API over Embree's best"
      " of all it timed, packets included)" % rs.get("stream_lanes", "?"))
print("load average at end: " + loadavg())
