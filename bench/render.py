#!/usr/bin/env python3
"""make bench-render: rt's path tracer against Mitsuba 3 on the shared Cornell box.

    bench/render.py [RT_BINARY ...]      (bench/render.sh sets up Mitsuba first)

For each thread count and sample count, renders the shared Cornell box
($SHARED/reference/cornell) with Mitsuba 3 (scene.xml, `multijitter`
sampler, through bench/mitsuba_render.py in build/mitsuba-venv) and with
every rt binary given (default ./rt) on scenes/cornell-reference.txt, the
same scene, at the same resolution, samples per pixel and thread count, and
prints for each: the render time (rt: the `render` figure of its `wrote`
line; Mitsuba: the second render in its process, after the JIT compile, see
mitsuba_render.py), the time per sample per pixel over the whole image, the
process CPU seconds, the RMSE against the shared reference (`rt compare`,
only at the reference's 512x512), the efficiency 1 / (RMSE^2 x time) and
rt's ratios to Mitsuba `llvm_ad_rgb` (efficiency: higher is better for rt;
per-sample time: lower is better for rt). Timings are wall clock on a
machine that may be shared: the load average is printed with every row.

Environment: SHARED (default ../shared), SPP (default "16 64"), THREADS
(default "1 2"), RES (default 512), VARIANTS (default "llvm_ad_rgb
scalar_rgb"), SCALAR_SPP (the sample counts at which scalar variants run,
default 16: they are slow), MITSUBA_PYTHON (default
build/mitsuba-venv/bin/python), OUT (the images, default build/bench-render).
"""
import json, os, re, subprocess, sys, time

from common import shared, loadavg, children_cpu, rt_compare

here = os.path.dirname(os.path.abspath(__file__))
spps = [int(s) for s in os.environ.get("SPP", "16 64").split()]
threads_list = [int(t) for t in os.environ.get("THREADS", "1 2").split()]
res = int(os.environ.get("RES", "512"))
variants = os.environ.get("VARIANTS", "llvm_ad_rgb scalar_rgb").split()
scalar_spps = [int(s) for s in os.environ.get("SCALAR_SPP", "16").split()]
python = os.environ.get("MITSUBA_PYTHON", "build/mitsuba-venv/bin/python")
out_dir = os.environ.get("OUT", "build/bench-render")
rts = sys.argv[1:] or ["./rt"]
ref_dir = os.path.join(shared, "reference", "cornell")
reference = os.path.join(ref_dir, "reference.pfm")
scene_xml = os.path.join(ref_dir, "scene.xml")
scene_rt = os.path.join(here, "..", "scenes", "cornell-reference.txt")


def fail(msg):
    print("bench-render: " + msg, file=sys.stderr)
    sys.exit(2)


for path in [scene_xml, reference] + rts:
    if not os.path.exists(path):
        fail("no %s (SHARED=%s; rt binaries as arguments)" % (path, shared))
os.makedirs(out_dir, exist_ok=True)


def rmse(image):
    """RMSE against the shared reference, None at another resolution."""
    if res != 512:
        return None
    d, err = rt_compare(rts[0], image, reference)
    if d is None:
        fail("rt compare %s: %s" % (image, err))
    return float(d["RMSE"].split()[0])


def run_rt(binary, spp, threads, tag):
    image = os.path.join(out_dir, "rt-%s-%dspp-%dt.pfm" % (tag, spp, threads))
    c0 = children_cpu()
    out = subprocess.run([binary, "-t", str(threads), "-s", str(spp), "-r", "%dx%d" % (res, res), "--seed", "0",
                          "-o", image, scene_rt], capture_output=True, text=True)
    cpu = children_cpu() - c0
    m = re.search(r"\(render ([0-9.]+) s\)", out.stderr)
    if out.returncode != 0 or not m:
        fail("%s failed: %s" % (binary, out.stderr.strip()))
    return float(m.group(1)), cpu, rmse(image)


def run_mitsuba(variant, spp, threads):
    image = os.path.join(out_dir, "mitsuba-%s-%dspp-%dt.pfm" % (variant, spp, threads))
    out = subprocess.run([python, os.path.join(here, "mitsuba_render.py"), scene_xml, variant, str(spp),
                          str(threads), str(res), image], capture_output=True, text=True)
    if out.returncode != 0:
        fail("Mitsuba %s failed: %s" % (variant, out.stderr.strip()[-2000:]))
    d = json.loads(out.stdout.strip().splitlines()[-1])
    return d, rmse(image)


def fmt(x, f):
    return "-" if x is None else f % x


header = "%-26s %3s %4s %8s %8s %9s %8s %9s %9s %8s %8s %8s  %s" % (
    "renderer", "thr", "spp", "time_s", "first_s", "ms/spp", "cpu_s", "RMSE", "effic.", "eff/llvm", "spp/llvm",
    "cpu/llvm", "load")
print("Cornell box %dx%d; rt: %s; reference: %s" % (res, res, " ".join(rts), reference))
print("time_s: render (Mitsuba llvm: the second, compiled render; first_s: its first, with tracing and JIT)")
print("effic. = 1/(RMSE^2 x time_s); eff/llvm, spp/llvm: efficiency and ms/spp over Mitsuba llvm_ad_rgb's")
print("cpu_s: process CPU seconds (rt: the whole run; Mitsuba: its timed render); cpu/llvm: efficiency by CPU")
print("seconds over Mitsuba llvm_ad_rgb's, the steadier figure when the machine is busy")
print(header)
summary = []
for threads in threads_list:
    for spp in spps:
        base = None
        for variant in variants:
            if not variant.startswith("llvm") and spp not in scalar_spps:
                continue
            d, err = run_mitsuba(variant, spp, threads)
            t = d["warm_s"]
            eff = 1.0 / (err * err * t) if err else None
            if variant.startswith("llvm") and base is None:
                base = (eff, t / spp, 1.0 / (err * err * d["cpu_s"]) if err else None)
            print("%-26s %3d %4d %8.2f %8.2f %9.1f %8.2f %9s %9s %8s %8s %8s  %s" % (
                "mitsuba %s %s" % (d["mitsuba"], variant), threads, spp, t, d["first_s"], 1e3 * t / spp,
                d["cpu_s"], fmt(err, "%.5f"), fmt(eff, "%.0f"), "", "", "", loadavg()), flush=True)
        for i, binary in enumerate(rts):
            t, cpu, err = run_rt(binary, spp, threads, str(i))
            eff = 1.0 / (err * err * t) if err else None
            eff_ratio = eff / base[0] if base and eff and base[0] else None
            spp_ratio = (t / spp) / base[1] if base else None
            cpu_ratio = 1.0 / (err * err * cpu) / base[2] if base and base[2] and err else None
            print("%-26s %3d %4d %8.2f %8s %9.1f %8.2f %9s %9s %8s %8s %8s  %s" % (
                "rt " + binary, threads, spp, t, "", 1e3 * t / spp, cpu, fmt(err, "%.5f"), fmt(eff, "%.0f"),
                fmt(eff_ratio, "%.2fx"), fmt(spp_ratio, "%.2fx"), fmt(cpu_ratio, "%.2fx"), loadavg()), flush=True)
            summary.append((binary, threads, spp, eff_ratio, spp_ratio))
print("targets (issue 11): efficiency >= 1.5x Mitsuba llvm_ad_rgb, ms/spp <= Mitsuba llvm_ad_rgb's")
for binary, threads, spp, eff_ratio, spp_ratio in summary:
    ok = eff_ratio is not None and eff_ratio >= 1.5 and spp_ratio is not None and spp_ratio <= 1.0
    print("  %s, %d threads, %d spp: efficiency %s, per-sample time %s: %s" % (
        binary, threads, spp, fmt(eff_ratio, "%.2fx"), fmt(spp_ratio, "%.2fx"), "met" if ok else "not met"))
