"""What the bench scripts share (imported by bench/compare.py, packets.py,
render.py and denoise.py, which run from the repository root):

    import common
    manifest, models = common.bench_models("bench-compare")  # [(model, glb), ...]
    common.ensure_embree("bench-compare")
    d = common.rtbench([glb, rays, "--ref", hits, "-t", "1", "--runs", common.runs])
    figures, err = common.rt_compare("./rt", "image.pfm", reference)
    print("load average: " + common.loadavg())

The shared assets, the Embree anchor's folders, the models of
$SHARED/bench/MANIFEST.md, Embree 3 installed when missing, bench/rtbench's
and `rt compare`'s `key: value` lines read into dicts, the machine's load
and the CPU time of finished child processes.
Environment: SHARED (default ../shared), RUNS (default 5), BUILD_EMBREE
(default /tmp/rt-embree, where the anchor and the triangle files go),
RTBENCH (the rtbench commands to time, '|'-separated, each a binary with
any flags, e.g. "old/bench/rtbench|./bench/rtbench --simd 8|./bench/rtbench":
bench-packets runs each configuration with each in turn, interleaved;
bench-compare takes the first; default ./bench/rtbench).
"""
import os, re, resource, subprocess, sys

shared = os.environ.get("SHARED", "../shared")
runs = os.environ.get("RUNS", "5")
embree_dir = os.path.join(shared, "bench", "embree")
build = os.environ.get("BUILD_EMBREE", "/tmp/rt-embree")
rtbench_cmds = [c.split() for c in os.environ.get("RTBENCH", "./bench/rtbench").split("|") if c.strip()]


def bench_models(tool):
    """$SHARED/bench/MANIFEST.md's text and its (model, glb) rows; exits, naming
    the tool, when it has none."""
    manifest = open(os.path.join(shared, "bench", "MANIFEST.md")).read()
    models = re.findall(r"^\| (\w+) \| `([^`]+)` \|", manifest, re.M)
    if not models:
        sys.exit("%s: no models in the manifest" % tool)
    return manifest, models


def ensure_embree(tool):
    """Installs Embree 3 and the converter's Python packages when Embree's
    header is missing, saying so."""
    if subprocess.call(["sh", "-c", "echo '#include <embree3/rtcore.h>' | cc -E -x c - >/dev/null 2>&1"]) != 0:
        print("%s: installing Embree 3 and the converter's Python packages (make -C %s deps)" % (tool, embree_dir),
              file=sys.stderr)
        subprocess.check_call(["make", "-C", embree_dir, "deps"])


def key_values(text):
    """The `key: value` lines of a tool's output as a dict of strings."""
    return dict(line.split(": ", 1) for line in text.splitlines() if ": " in line)


def rtbench(args, cmd=None):
    """Runs bench/rtbench (or cmd, one of rtbench_cmds; default the first)
    with args: its `key: value` lines, with its exit status under "status"
    and its standard error under "stderr"."""
    out = subprocess.run((cmd or rtbench_cmds[0]) + list(args), capture_output=True, text=True)
    d = key_values(out.stdout)
    d["status"] = out.returncode
    d["stderr"] = out.stderr
    return d


def rt_compare(rt, image, reference):
    """`rt compare IMAGE REFERENCE` with the rt binary rt: (its figures as
    strings by name, RMSE, relMSE, LDR-FLIP ..., or None when it failed;
    its standard error)."""
    p = subprocess.run([rt, "compare", image, reference], capture_output=True, text=True)
    d = key_values(p.stdout)
    return (d if p.returncode == 0 and "RMSE" in d else None), p.stderr.strip()


def loadavg():
    """The 1, 5 and 15 minute load averages, "?" where /proc has none."""
    try:
        return " ".join(open("/proc/loadavg").read().split()[:3])
    except OSError:
        return "?"


def children_cpu():
    """CPU seconds (user and system) of this process's finished children."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
