#!/bin/sh
# make test-kubernetes: the Kubernetes launcher (examples/kubernetes/)
# without a cluster. Checks the manifests' structure (Indexed batch/v1 Jobs
# for the parts, whose completions equal the PARTS its command uses, and for
# the frames; a merge Job; restartPolicy Never or OnFailure; the shared
# ReadWriteMany claim of pvc.yaml mounted where WORK says in every pod; one
# image for all) and that the Dockerfile installs what tools/install-deps.sh
# checks for. Then runs the containers' commands locally as the kubelet would
# (the manifest's environment, requests.cpu through resourceFieldRef, $(VAR)
# expanded, JOB_COMPLETION_INDEX set; WORK, the mount, a local directory; rt
# on the PATH): the parts Job for every index, one part already half rendered
# as an evicted pod leaves it (resumed) and one pod started again (its
# complete part kept); the merge Job, checked against a single-machine render
# byte for byte, PNG as the manifest writes it and PFM (IMAGE=image.pfm) for
# the float pixels; the frames Job's pods 0, 1, 2 and the last, frame 1
# already there (kept), frame 2 stopped after its first pass (resumed), each
# frame against the single render (the scene has no animation).
# Needs python3 with PyYAML (Debian's python3-yaml, installed when missing).
# Environment: RT_BIN (default ./rt).
set -eu
. tests/launch-common.sh
launch_setup test-kubernetes
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

python3 -c 'import yaml' 2>/dev/null || sh tools/install-deps.sh python3-yaml
python3 -c 'import yaml' || launch_fail "python3 cannot import yaml (apt-get install python3-yaml)"

mkdir -p "$work/bin" "$work/volume/scene"
ln -s "$RT" "$work/bin/rt"
launch_scene "$work/volume/scene/scene.txt"
launch_single "$work/volume/scene/scene.txt" "$work/single.png"
launch_single "$work/volume/scene/scene.txt" "$work/single.pfm"

PATH="$work/bin:$PATH" python3 - examples/kubernetes "$work/volume" "$work/single.png" <<'PY' || launch_fail "see above"
import os, re, subprocess, sys, yaml

kdir, volume, single = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []

def check(cond, what):
    if not cond:
        failures.append(what)
    return cond

def load(name):
    with open(os.path.join(kdir, name)) as f:
        docs = [d for d in yaml.safe_load_all(f) if d is not None]
    check(len(docs) == 1, f"{name}: {len(docs)} documents, expected one")
    return docs[0]

pvc = load("pvc.yaml")
check(pvc.get("apiVersion") == "v1" and pvc.get("kind") == "PersistentVolumeClaim", "pvc.yaml: not a v1 PersistentVolumeClaim")
check("ReadWriteMany" in pvc["spec"].get("accessModes", []), "pvc.yaml: not ReadWriteMany (pods on several nodes share it)")
claim = pvc["metadata"]["name"]

def pod_spec(name, doc):
    """The one container of a pod spec, its environment as the kubelet would
    set it, and the mount path of the claim."""
    spec = doc["spec"]["template"]["spec"] if doc["kind"] == "Job" else doc["spec"]
    conts = spec.get("containers", [])
    check(len(conts) == 1, f"{name}: {len(conts)} containers, expected one")
    c = conts[0]
    vols = {v["name"]: v for v in spec.get("volumes", [])}
    mount = None
    for m in c.get("volumeMounts", []):
        v = vols.get(m["name"], {})
        if v.get("persistentVolumeClaim", {}).get("claimName") == claim:
            mount = m["mountPath"]
    check(mount is not None, f"{name}: does not mount the claim {claim}")
    env = {}
    for e in c.get("env", []):
        if "value" in e:
            env[e["name"]] = str(e["value"])
        else:
            ref = e["valueFrom"]["resourceFieldRef"]
            kind, res = ref["resource"].split(".")
            q = str(c["resources"][kind][res])
            # cpu with the default divisor 1: whole cores, rounded up
            env[e["name"]] = str(-(-int(q[:-1]) // 1000)) if q.endswith("m") else str(int(-(-float(q) // 1)))
    if "WORK" in env:
        check(env["WORK"] == mount, f"{name}: WORK is {env['WORK']} but the volume is mounted at {mount}")
    return spec, c, env, mount

def job(name):
    doc = load(name)
    check(doc.get("apiVersion") == "batch/v1" and doc.get("kind") == "Job", f"{name}: not a batch/v1 Job")
    spec, c, env, mount = pod_spec(name, doc)
    check(spec.get("restartPolicy") in ("Never", "OnFailure"), f"{name}: restartPolicy must be Never or OnFailure")
    return doc, c, env, mount

def expand(s, env):
    """Kubernetes' $(VAR) expansion in command and args ($$ escapes)."""
    return re.sub(r"\$\$|\$\(([A-Za-z_][A-Za-z0-9_]*)\)",
                  lambda m: "$" if m.group(0) == "$$" else env.get(m.group(1), m.group(0)), s)

def run(name, c, env, extra):
    full = dict(os.environ)
    full.update(env)
    full.update(extra)
    argv = [expand(a, env) for a in c.get("command", []) + c.get("args", [])]
    r = subprocess.run(argv, env=full)
    check(r.returncode == 0, f"{name}: the container command failed (exit {r.returncode}) with {extra}")

render, rc, renv, rmount = job("render-job.yaml")
frames, fc, fenv, fmount = job("render-frames-job.yaml")
merge, mc, menv, mmount = job("merge-job.yaml")
shell = load("shell-pod.yaml")
check(shell.get("apiVersion") == "v1" and shell.get("kind") == "Pod", "shell-pod.yaml: not a v1 Pod")
_, sc, _, smount = pod_spec("shell-pod.yaml", shell)
check(rmount == mmount == smount == fmount, f"the volume is mounted at {rmount}, {mmount}, {smount}, {fmount}: use one path")
check(rc["image"] == mc["image"] == sc["image"] == fc["image"], "the pods run different images")
fspec = frames["spec"]
nf = fspec.get("completions")
check(fspec.get("completionMode") == "Indexed", "render-frames-job.yaml: completionMode is not Indexed")
check(isinstance(nf, int) and nf >= 3, "render-frames-job.yaml: completions is not a number of frames")
check("%" in fenv.get("OUTPUT", ""), "render-frames-job.yaml: OUTPUT is not a frame pattern")
fcmd = " ".join(fc.get("command", []) + fc.get("args", []))
check("JOB_COMPLETION_INDEX" in fcmd and "--only-frames" in fcmd, "render-frames-job.yaml: the command does not pass JOB_COMPLETION_INDEX to --only-frames")
check(fenv.get("FRAMES") == str(nf), f"render-frames-job.yaml: FRAMES is {fenv.get('FRAMES')} but completions is {nf}")

spec = render["spec"]
n = spec.get("completions")
check(spec.get("completionMode") == "Indexed", "render-job.yaml: completionMode is not Indexed")
check(isinstance(n, int) and n >= 1, "render-job.yaml: completions is not a count")
check(isinstance(spec.get("parallelism"), int) and 1 <= spec["parallelism"], "render-job.yaml: no parallelism")
check(renv.get("PARTS") == str(n), f"render-job.yaml: PARTS is {renv.get('PARTS')} but completions is {n}")
cmd = " ".join(rc.get("command", []) + rc.get("args", []))
check("JOB_COMPLETION_INDEX" in cmd and "--part" in cmd, "render-job.yaml: the command does not pass JOB_COMPLETION_INDEX to --part")
check(merge["spec"].get("completionMode", "NonIndexed") == "NonIndexed" and merge["spec"].get("completions", 1) == 1,
      "merge-job.yaml: the merge is one pod")

with open(os.path.join(kdir, "Dockerfile")) as f:
    docker = f.read()
with open("tools/install-deps.sh") as f:
    needed = re.findall(r"^check \S+ (\S+)$", f.read(), re.M)
check(len(needed) >= 4, "tools/install-deps.sh: its check lines were not found")
for p in needed:
    check(re.search(r"\b" + re.escape(p) + r"\b", docker), f"Dockerfile: does not install {p} (tools/install-deps.sh needs it)")
check(re.search(r"^FROM debian:", docker, re.M), "Dockerfile: not on Debian")
check("/usr/local/bin/rt" in docker, "Dockerfile: rt is not on the PATH as /usr/local/bin/rt")

if failures:
    for f in failures:
        print("test-kubernetes: " + f, file=sys.stderr)
    sys.exit(1)

# The pods, as the kubelet would start them, in an order of their own; pod 2
# finds its part there with samples 0..2 of 8, as an evicted pod leaves it
os.makedirs(os.path.join(volume, "parts"))
r = subprocess.run(["rt", "-q", "--part", f"2/{n}", "--spp-range", "0:3", "-o",
                    os.path.join(volume, "parts", "part.2.exr"), os.path.join(volume, renv["SCENE"])])
check(r.returncode == 0, "the partial part 2 was not rendered")
for i in reversed(range(n)):
    run("render-job.yaml", rc, dict(renv, WORK=volume), {"JOB_COMPLETION_INDEX": str(i)})
with open(os.path.join(volume, "parts", "part.2.exr.json")) as f:
    check('"samples": [0, 8]' in f.read(), "pod 2 did not complete the part it found")
# pods started again (a retry after the merge failed) keep the complete parts
stamp = os.stat(os.path.join(volume, "parts", "part.0.exr")).st_mtime_ns
run("render-job.yaml", rc, dict(renv, WORK=volume), {"JOB_COMPLETION_INDEX": "0"})
check(os.stat(os.path.join(volume, "parts", "part.0.exr")).st_mtime_ns == stamp, "pod 0 rendered its complete part again")
run("merge-job.yaml", mc, dict(menv, WORK=volume), {})
run("merge-job.yaml", mc, dict(menv, WORK=volume, IMAGE="image.pfm"), {})

# The frames Job (its scene, a glTF in the manifest, is the test's scene
# here): pods 0, 1, 2 and the last, frame 1 already there (kept, not
# rendered), frame 2 stopped by an eviction's SIGTERM after its first pass
# (here a time limit, which leaves the same files: f.0002.partial.png and
# the part f.0002.part.exr), resumed by its pod to the single render's bytes
with open(single, "rb") as f:
    want = f.read()
fdir = os.path.join(volume, "frames")
os.makedirs(fdir)
kept = os.path.join(fdir, "f.0001.png")
with open(kept, "wb") as f:
    f.write(want)
stamp = os.stat(kept).st_mtime_ns
r = subprocess.run(["rt", "-q", "--frames", f"0:{nf}", "--only-frames", "2:3", "--time-limit", "0.000001", "-o",
                    os.path.join(volume, fenv["OUTPUT"]), os.path.join(volume, renv["SCENE"])])
stopped = os.path.join(fdir, "f.0002.part.exr.json")
check(r.returncode == 0 and os.path.exists(stopped) and not os.path.exists(os.path.join(fdir, "f.0002.png")),
      "the stopped frame 2 was not kept apart (f.0002.part.exr, no f.0002.png)")
for i in (0, 1, 2, nf - 1):
    run("render-frames-job.yaml", fc, dict(fenv, WORK=volume, SCENE=renv["SCENE"]), {"JOB_COMPLETION_INDEX": str(i)})
check(os.stat(kept).st_mtime_ns == stamp, "frame 1 was there but its pod rendered it again")
check(not os.path.exists(stopped), "frame 2's pod left the part it resumed")
for i in (0, 1, 2, nf - 1):
    name = os.path.join(volume, fenv["OUTPUT"] % i)
    if check(os.path.exists(name), f"render-frames-job.yaml: pod {i} wrote no {name}"):
        with open(name, "rb") as f:
            check(f.read() == want, f"frame {i} differs from the single render (the scene has no animation)")

if failures:
    for f in failures:
        print("test-kubernetes: " + f, file=sys.stderr)
    sys.exit(1)
print(f"test-kubernetes: manifests checked; {n} indexed pods and the merge, 4 of {nf} frame pods run locally")
PY
[ -f "$work/volume/parts/part.0.exr.json" ] || launch_fail "no sidecar part.0.exr.json beside part.0.exr"
launch_same "$work/volume/image.png" "$work/single.png" "the Indexed Job's parts merged (PNG)"
launch_same "$work/volume/image.pfm" "$work/single.pfm" "the Indexed Job's parts merged (PFM)"
echo "test-kubernetes: 1 passed, 0 failed"
