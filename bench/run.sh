#!/bin/sh
# make bench: runs bench/rtbench over every model in $SHARED/bench/MANIFEST.md,
# primary and diffuse rays, 1 and 2 threads, single rays and ray streams
# (rtbench --stream: 4096 rays a call, the widest SIMD width the CPU runs;
# lanes column). Fails when any run mismatches.
# Mrays/s is the median run (wall clock), best the fastest, cpuMrays/s rays per
# CPU-second (steadier on a loaded machine).
# Environment: SHARED (default ../shared), RUNS (default 5).
set -u
SHARED=${SHARED:-../shared}
RUNS=${RUNS:-5}
manifest="$SHARED/bench/MANIFEST.md"
if [ ! -f "$manifest" ]; then
    echo "bench: no $manifest (set SHARED=dir to the shared material)" >&2
    exit 2
fi
status=0
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null)"
printf '%-28s %-8s %-6s %5s %3s %10s %9s %9s %8s %11s %10s %10s %10s\n' model kind mode lanes thr triangles build_ms bytes/tri load_ms Mrays/s best cpuMrays/s mismatches
grep -E '^\| [A-Za-z0-9_]+ \| `' "$manifest" | while IFS='|' read -r _ model glb _; do
    model=$(echo "$model" | tr -d ' ')
    glb=$(echo "$glb" | tr -d ' `')
    for kind in primary diffuse; do
        for t in 1 2; do
            for mode in single stream; do
                flag=; [ $mode = stream ] && flag=--stream
                out=$(./bench/rtbench "$SHARED/$glb" "$SHARED/bench/$model/$model.$kind.rays" \
                    --ref "$SHARED/bench/$model/$model.$kind.hits" -t "$t" --runs "$RUNS" $flag) || status=1
                get() { printf '%s\n' "$out" | sed -n "s/^$1: //p"; }
                lanes=$(get stream_lanes)
                printf '%-28s %-8s %-6s %5s %3s %10s %9s %9s %8s %11s %10s %10s %10s\n' "$model" "$kind" $mode \
                    "${lanes:--}" "$t" "$(get triangles)" "$(get build_ms)" "$(get bytes_per_triangle)" "$(get load_ms)" \
                    "$(get mrays_per_s)" "$(get mrays_per_s_best)" "$(get cpu_mrays_per_s)" "$(get mismatches)"
            done
        done
    done
    [ $status -eq 0 ] || exit 1
done
