#!/bin/sh
# make bench-helmet: the path tracer's rays per second, shading included, on
# DamagedHelmet under an environment map (a procedural sky) and a sun
# (issue 11's end-to-end figure; docs/performance.md, "Wavefront, session 5").
#   sh bench/helmet.sh [RT_BINARY ...]   default ./rt; several binaries run interleaved
# Writes build/bench/sky.hdr (Radiance HDR, 256 x 128 latitude-longitude
# sky: a blue zenith over a bright horizon over a dark ground) and
# build/bench/helmet-sun.txt (the model from SHARED, that sky, a directional
# sun, integrator path), then renders it RUNS times with each binary in
# turn and prints, per run, the load average, the render time, the rays
# traced (camera, bounce and shadow rays), rays per second of render time,
# and the CPU seconds of the whole run (loading and the kd-tree included):
# on a shared machine the CPU figure is the steadier one.
# Environment: SHARED (default ../shared), RUNS (3), THREADS (1), RES (128), SPP (16).
set -eu
SHARED=${SHARED:-../shared}
RUNS=${RUNS:-3}
THREADS=${THREADS:-1}
RES=${RES:-128}
SPP=${SPP:-16}
[ $# -gt 0 ] || set -- ./rt
model="$SHARED/assets/gltf/DamagedHelmet/glTF-Binary/DamagedHelmet.glb"
if [ ! -f "$model" ]; then
    echo "bench-helmet: $model not found (set SHARED to the shared assets)" >&2
    exit 2
fi
model=$(cd "$(dirname "$model")" && pwd)/$(basename "$model")
dir=build/bench
mkdir -p "$dir"
python3 - "$dir/sky.hdr" <<'PY'
import math, sys
W, H = 256, 128
rows = []
for j in range(H):                       # image row j from the top: elevation from +90 to -90 degrees
    el = math.pi / 2 - (j + 0.5) / H * math.pi
    s = math.sin(el)
    row = []
    for i in range(W):
        if s >= 0:                       # sky: horizon white-blue to zenith blue
            t = s ** 0.5
            c = (1.2 - 0.9 * t, 1.3 - 0.7 * t, 1.5 - 0.3 * t)
        else:                            # ground: warm grey, darker straight down
            t = (-s) ** 0.5
            c = (0.35 - 0.15 * t, 0.3 - 0.13 * t, 0.25 - 0.1 * t)
        row.append(c)
    rows.append(row)
def rgbe(c):                             # Radiance RGBE (Ward, Graphics Gems II), flat scanlines
    m = max(c)
    if m < 1e-32:
        return b"\0\0\0\0"
    e = math.frexp(m)[1]
    f = 256.0 / 2.0 ** e
    return bytes((int(c[0] * f), int(c[1] * f), int(c[2] * f), e + 128))
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (H, W))
    for row in rows:                     # top row first
        f.write(b"".join(rgbe(c) for c in row))
PY
cat > "$dir/helmet-sun.txt" <<SCENE
# DamagedHelmet under a sky and a sun: written by bench/helmet.sh (make bench-helmet)
model "$model"
environment sky.hdr strength 1
light directional -0.5 -1 -0.6  1 0.95 0.85  4
camera position 1.6 0.6 2.6 look_at 0 0 0 fov 40
integrator path
resolution $RES $RES
samples $SPP
SCENE
echo "bench-helmet: $dir/helmet-sun.txt, ${RES}x$RES, $SPP spp, $THREADS thread(s), $RUNS interleaved runs"
printf '%-28s %4s %6s %9s %10s %9s %7s\n' binary run load render_s rays Mrays/s cpu_s
cpu_file="$dir/times.txt"
cpu_now() { # user + system CPU seconds of this shell's children so far (`times` run here, not in a subshell)
    times > "$cpu_file"
    cpu=$(tail -n 1 "$cpu_file" | awk '{ s = 0; for (i = 1; i <= NF; i++) { split($i, a, "m"); s += a[1] * 60 + a[2] } print s }')
}
run=1
while [ "$run" -le "$RUNS" ]; do
    for bin in "$@"; do
        load=$(cut -d' ' -f1 /proc/loadavg)
        cpu_now
        c0=$cpu
        line=$("$bin" -v -t "$THREADS" -o "$dir/helmet-sun.pfm" "$dir/helmet-sun.txt" 2>&1 | grep 'rt: render:' || true)
        if [ -z "$line" ]; then
            echo "bench-helmet: $bin failed" >&2
            exit 1
        fi
        secs=$(echo "$line" | sed -n 's/.*render: \([0-9.]*\) s on.*/\1/p')
        rays=$(echo "$line" | sed -n 's/.* camera rays, \([0-9]*\) rays,.*/\1/p')
        cpu_now
        c1=$cpu
        printf '%-28s %4d %6s %9s %10s %9.3f %7.2f\n' "$bin" "$run" "$load" "$secs" "$rays" \
            "$(echo "$rays / $secs / 1000000" | bc -l)" "$(echo "$c1 - $c0" | bc -l)"
    done
    run=$((run + 1))
done
