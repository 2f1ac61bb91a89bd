#!/bin/sh
# make bench-load: load-time goals, timed here rather than in the unit tests
# (which also run under ASan and TSan, where any time bound is noise). An
# OBJ with 30000 distinct usemtl names and 30000 (v, vt) pairs on one
# position must load in under 2 s (hash tables, not linear searches): the
# loader's own load_ms from `rt --info`, the median of RUNS runs.
# Environment: RT (default ./rt), RUNS (default 3), MAX_MS (default 2000).
set -eu
RT=${RT:-./rt}
RUNS=${RUNS:-3}
MAX_MS=${MAX_MS:-2000}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
awk 'BEGIN { print "v 0 0 0\nv 1 0 0\nv 0 1 0"
             for (i = 0; i < 30000; i++) printf "vt %d 0\nusemtl m%d\nf 1/%d 2/1 3/1\n", i, i, i + 1 }' >"$dir/many.obj"
times=""
i=0
while [ "$i" -lt "$RUNS" ]; do
    ms=$("$RT" -q --info "$dir/many.obj" | sed -n 's/^load_ms: //p')
    [ -n "$ms" ] || { echo "bench-load: $RT --info printed no load_ms" >&2; exit 1; }
    times="$times $ms"
    i=$((i + 1))
done
median=$(printf '%s\n' $times | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
echo "bench-load: OBJ, 30000 materials and (v, vt) pairs: load_ms median $median (runs:$times), goal < $MAX_MS"
awk -v m="$median" -v max="$MAX_MS" 'BEGIN { exit !(m < max) }' || { echo "bench-load: over the goal" >&2; exit 1; }
