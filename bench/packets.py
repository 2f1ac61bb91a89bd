#!/usr/bin/env python3
"""make bench-packets (also the end of make bench-compare): rt's packet
traversal and Embree 3's packet queries on the same pixel tiles.

For every model in $SHARED/bench/MANIFEST.md, on its primary ray set (one
ray per pixel, row by row): Embree's `anchor bench ... --packets W H`
(rtcIntersect8 on 4x2 tiles, rtcIntersect16 on 4x4 tiles when the CPU runs
16-wide rays natively; without AVX-512 Embree has no native ray16 and the
anchor leaves it out), then bench/rtbench --packets 4 2
(rt_kdtree_intersect8) and --packets 4 4 (rt_kdtree_intersect16), each
with 1 and 2 threads, and --frustum 4 4 and --frustum 8 8
(rt_kdtree_intersect_frustum: a tile a call as one frustum). Prints Mrays/s (median of the runs, wall clock) and
CPU Mrays/s (each thread's rays per CPU-second of its own, summed over
the threads, as the anchor reports it: the steadier figure on a loaded
machine) for both, and the ratios rt/Embree; a 4x4 row is
compared with rtcIntersect16 when the anchor ran it, else with
rtcIntersect8 on 4x2 tiles (marked). Each tracer's answers are checked
against the reference hits (mismatches column: rt's, then Embree's).
Environment: SHARED (default ../shared), RUNS (default 5), BUILD_EMBREE
(default /tmp/rt-embree, where the anchor and the triangle files go),
RTBENCH (several rtbench builds or flags, '|'-separated: each row runs
with each in turn, interleaved, labelled by its index and the SIMD width
it ran at, `simd`; common.py).
"""
import json, os, re, subprocess, sys

import common
from common import shared, runs, embree_dir, build, loadavg

manifest, models = common.bench_models("bench-packets")
common.ensure_embree("bench-packets")
subprocess.check_call(["make", "-s", "-C", embree_dir, "BUILD=" + build], stdout=subprocess.DEVNULL)


def image_size(model):
    """The primary set's image size, from the model's camera line in the manifest."""
    sec = manifest.split("## " + model, 1)
    m = re.search(r"camera:.*?(\d+)x(\d+)\s*$", sec[1] if len(sec) > 1 else "", re.M)
    return (int(m.group(1)), int(m.group(2))) if m else (640, 480)


def rtbench(glb, model, threads, tw, th, how="--packets", cmd=None):
    w, _ = image_size(model)
    rays = os.path.join(shared, "bench", model, model + ".primary")
    d = common.rtbench([os.path.join(shared, glb), rays + ".rays", "--ref", rays + ".hits", "-t", str(threads),
                        "--runs", runs, how, str(tw), str(th), "--image-width", str(w)], cmd)
    if d["status"] != 0:
        print(d["stderr"], file=sys.stderr, end="")
    return d


def embree(model, glb):
    tri = os.path.join(build, model + ".tri")
    if not os.path.exists(tri) or os.path.getsize(tri) == 0:
        subprocess.check_call(["python3", os.path.join(embree_dir, "gltf2tri.py"), os.path.join(shared, glb), tri],
                              stdout=subprocess.DEVNULL)
    w, h = image_size(model)
    rays = os.path.join(shared, "bench", model, model + ".primary")
    out = subprocess.run([os.path.join(build, "anchor"), "bench", tri, rays + ".rays", rays + ".hits", "--reps", runs,
                          "--packets", str(w), str(h)], capture_output=True, text=True)
    if out.returncode != 0:
        print(out.stderr, file=sys.stderr)
        sys.exit("bench-packets: the Embree anchor failed for " + model)
    return json.loads(out.stdout)["results"]


print("load average at start: " + loadavg())
print("%-28s %5s %3s %-6s %9s %9s %-16s %9s %9s %6s %6s %8s" % (
    "model (primary)", "tiles", "thr", "rt", "rt Mray/s", "rt CPU", "Embree query", "Mray/s", "CPU", "ratio",
    "CPU r.", "mism."))
no16 = False
for model, glb in models:
    e = embree(model, glb)
    for tw, th, how in ((4, 2, "--packets"), (4, 4, "--packets"), (4, 4, "--frustum"), (8, 8, "--frustum")):
        for t in (1, 2):
            for ci, cmd in enumerate(common.rtbench_cmds):  # several builds: interleaved, row by row
                r = rtbench(glb, model, t, tw, th, how, cmd)
                # which rt ran: its index in RTBENCH and the packets' SIMD width (builds before it: "-")
                label = "%d/%s" % (ci, r.get("packet_simd", "-")) if len(common.rtbench_cmds) > 1 \
                    else r.get("packet_simd", "-")
                n16 = min(tw * th, 16)  # frustum tiles are compared with Embree's 16-ray packets
                key, query = ("packet%d_%dT" % (n16, t), "rtcIntersect%d" % n16)
                if key not in e:  # no native ray16: the 4x2 tiles' rtcIntersect8
                    key, query = "packet8_%dT" % t, "rtcIntersect8 (*)"
                    no16 = True
                ef = e.get(key, {})
                # rtbench's CPU figure is rays per CPU-second summed over threads, the anchor's the sum of each
                # thread's rate: the same footing is rtbench's times the threads
                mr, mc = float(r.get("mrays_per_s", 0)), float(r.get("cpu_mrays_per_s", 0)) * t
                er, ec = ef.get("mrays_s", 0.0), ef.get("cpu_mrays_s", 0.0)
                print("%-28s %5s %3d %-6s %9.2f %9.2f %-16s %9.2f %9.2f %6.2f %6.2f %8s" % (
                    model, "%dx%d%s" % (tw, th, "f" if how == "--frustum" else ""), t, label, mr, mc, query, er, ec,
                    mr / er if er else 0, mc / ec if ec else 0,
                    "%s/%s" % (r.get("mismatches", "?"), ef.get("mismatch_vs_ref", "?"))), flush=True)
print("(4x4f, 8x8f: rt's frustum walk on those tiles; rt: the packets' SIMD width, 16 AVX-512 or 8 AVX2, with"
      " the build's index in RTBENCH when there are several)")
if no16:
    print("(*) no native 16-wide rays for Embree on this CPU (they need AVX-512), so the anchor runs no"
          " rtcIntersect16: those 4x4 rows compare with rtcIntersect8 on 4x2 tiles")
print("load average at end: " + loadavg())
