#!/usr/bin/env python3
"""make bench-denoise: --denoise on the shared Cornell box against raw renders.

    bench/denoise.py [RT_BINARY]          (default ./rt; bench/denoise.sh runs it)

Renders scenes/cornell-reference.txt (the shared reference scene, 512x512)
at 4, 16 and 64 spp with --denoise (and --aov albedo,normal, which keeps the
noisy image beside the denoised one), and raw at 256 and 1024 spp, then
compares each image with the shared Mitsuba reference (`rt compare`: RMSE,
relMSE, LDR-FLIP) and prints a table with the times: the render and the
denoise as rt reports them with -v (wall clock), the process CPU seconds,
and the load average. Then, for each metric, the fewest samples whose
denoised image is at least as close to the reference as raw 1024 spp, and
the time it took against raw 1024's.

The raw renders are slow (1024 spp takes minutes even on a quiet machine):
an image already in OUT with its timing file (raw-N.pfm, raw-N.json) is
reused; delete them to measure again. rt's -v output goes to OUT/*.log. REUSE_DENOISED=1 reuses the
denoised renders the same way (dn-N.pfm, dn-N.json). Environment: SHARED (default
../shared), THREADS (default 2), DENOISED_SPP (default "4 16 64"), RAW_SPP
(default "256 1024"), OUT (default build/bench-denoise), CROP (a region
"x,y,w,h" of the 16-spp images written as PNGs for docs/images, default
none).
"""
import json, os, re, subprocess, sys

from common import shared, loadavg, children_cpu, rt_compare

here = os.path.dirname(os.path.abspath(__file__))
threads = os.environ.get("THREADS", "2")
den_spps = [int(s) for s in os.environ.get("DENOISED_SPP", "4 16 64").split()]
raw_spps = [int(s) for s in os.environ.get("RAW_SPP", "256 1024").split()]
out_dir = os.environ.get("OUT", "build/bench-denoise")
crop = os.environ.get("CROP", "")
reuse = os.environ.get("REUSE_DENOISED", "") == "1"
rt = sys.argv[1] if len(sys.argv) > 1 else "./rt"
scene = os.path.join(here, "..", "scenes", "cornell-reference.txt")
reference = os.path.join(shared, "reference", "cornell", "reference.pfm")
for path in (rt, reference):
    if not os.path.exists(path):
        sys.exit("bench-denoise: no %s (SHARED=dir for the shared material, the rt binary as argument)" % path)
os.makedirs(out_dir, exist_ok=True)


def run(args):
    """rt with -v: (stderr, CPU seconds of the process)"""
    c0 = children_cpu()
    p = subprocess.run([rt, "-v", "-t", threads] + args, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bench-denoise: rt %s failed:\n%s" % (" ".join(args), p.stderr))
    return p.stderr, children_cpu() - c0


def seconds(pattern, text):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else None


def compare(image):
    d, err = rt_compare(rt, image, reference)
    if d is None:
        sys.exit("bench-denoise: rt compare %s: %s" % (image, err))
    return {k: float(d[k].split()[0]) for k in ("RMSE", "relMSE", "LDR-FLIP")}


rows = []
for spp in raw_spps:
    image, timing = os.path.join(out_dir, "raw-%d.pfm" % spp), os.path.join(out_dir, "raw-%d.json" % spp)
    if os.path.exists(image) and os.path.exists(timing):
        t = json.load(open(timing))
    else:
        load0 = loadavg()
        err, cpu = run(["-s", str(spp), "-o", image, scene])
        t = {"render_s": seconds(r"\(render ([0-9.]+) s\)", err), "cpu_s": cpu, "load": load0 + " / " + loadavg()}
        json.dump(t, open(timing, "w"))
        open(os.path.join(out_dir, "raw-%d.log" % spp), "w").write(err)
    rows.append(dict(name="%d spp, raw" % spp, spp=spp, denoised=False, render_s=t["render_s"], denoise_s=None,
                     denoise_cpu_s=None, cpu_s=t.get("cpu_s"), load=t["load"], **compare(image)))

for spp in den_spps:
    image, timing = os.path.join(out_dir, "dn-%d.pfm" % spp), os.path.join(out_dir, "dn-%d.json" % spp)
    if reuse and os.path.exists(image) and os.path.exists(timing):
        render_s, denoise_s, denoise_cpu, cpu, load = json.load(open(timing))
    else:
        load0 = loadavg()
        err, cpu = run(["-s", str(spp), "--denoise", "--aov", "albedo,normal", "-o", image, scene])
        render_s = seconds(r"\(render ([0-9.]+) s\)", err)
        denoise_s = seconds(r"rt: denoise: ([0-9.]+) s", err)
        denoise_cpu = seconds(r"execute [0-9.]+ ms \(CPU ([0-9.]+) ms\)", err)
        load = load0 + " / " + loadavg()
        json.dump([render_s, denoise_s, denoise_cpu, cpu, load], open(timing, "w"))
        open(os.path.join(out_dir, "dn-%d.log" % spp), "w").write(err)
    noisy = os.path.join(out_dir, "dn-%d.noisy.pfm" % spp)
    rows.append(dict(name="%d spp, raw" % spp, spp=spp, denoised=False, render_s=render_s, denoise_s=None,
                     denoise_cpu_s=None, cpu_s=None, load=load, **compare(noisy)))
    rows.append(dict(name="%d spp, denoised" % spp, spp=spp, denoised=True, render_s=render_s, denoise_s=denoise_s,
                     denoise_cpu_s=denoise_cpu and denoise_cpu / 1e3, cpu_s=cpu, load=load, **compare(image)))


def f(x, fmt):
    return "" if x is None else fmt % x


rows.sort(key=lambda r: (r["spp"], r["denoised"]))
print("scenes/cornell-reference.txt, 512x512, %s threads, against %s" % (threads, reference))
print("| image | render | denoise | process CPU | RMSE | relMSE | LDR-FLIP | load average (before / after) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
for r in rows:
    print("| %s | %s | %s | %s | %.5f | %.5f | %.4f | %s |" % (
        r["name"], f(r["render_s"], "%.1f s"),
        f(r["denoise_s"], "%.2f s") + f(r["denoise_cpu_s"], " (CPU %.2f s)"), f(r["cpu_s"], "%.1f s"),
        r["RMSE"], r["relMSE"], r["LDR-FLIP"], r["load"]))

target = [r for r in rows if not r["denoised"] and r["spp"] == max(raw_spps)]
if target:
    t = target[0]
    print("\nTo reach raw %d spp (render %.1f s):" % (t["spp"], t["render_s"] or 0))
    for metric in ("RMSE", "relMSE", "LDR-FLIP"):
        hit = [r for r in rows if r["denoised"] and r[metric] <= t[metric]]
        if hit:
            r = hit[0]
            total = (r["render_s"] or 0) + (r["denoise_s"] or 0)
            print("  %s: %d spp denoised, %.1f s (render %.1f s + denoise %.2f s), %.0fx less time" % (
                metric, r["spp"], total, r["render_s"] or 0, r["denoise_s"] or 0, (t["render_s"] or 0) / total))
        else:
            print("  %s: no denoised image here gets there (best %.5f, raw %d spp %.5f)" % (
                metric, min(r[metric] for r in rows if r["denoised"]), t["spp"], t[metric]))

if crop:
    x, y, w, h = (int(v) for v in crop.split(","))

    def crop_pfm(src, dst):
        """a region of a PFM (bottom-to-top rows) into a new PFM"""
        import array
        data = open(src, "rb").read()
        head = data.split(b"\n", 3)
        W, H = (int(v) for v in head[1].split())
        px = array.array("f")
        px.frombytes(data[len(b"\n".join(head[:3])) + 1:][:W * H * 12])
        out = array.array("f")
        for row in range(h):  # output row 0 = the bottom of the crop
            src_row = H - 1 - (y + h - 1 - row)
            out.extend(px[3 * (src_row * W + x):3 * (src_row * W + x + w)])
        with open(dst, "wb") as fo:
            fo.write(b"PF\n%d %d\n-1.0\n" % (w, h))
            fo.write(out.tobytes())

    for name, src in (("noisy", "dn-16.noisy.pfm"), ("denoised", "dn-16.pfm"), ("reference", reference)):
        tmp = os.path.join(out_dir, "crop-%s.pfm" % name)
        crop_pfm(src if os.path.isabs(src) or src == reference else os.path.join(out_dir, src), tmp)
        png = os.path.join(out_dir, "denoise-16spp-%s.png" % name)
        subprocess.run([rt, "convert", tmp, png], check=True)
        print("wrote " + png)
