#!/bin/sh
# make reference: the path tracer checked against the shared Mitsuba 3
# reference (docs/path-tracer.md, section 6), with rt alone:
# scenes/cornell-reference.txt (that scene exactly) rendered at the
# reference's 512x512 with SPP samples a pixel, then `rt compare` against
# reference.pfm, which prints RMSE, relMSE, the image means and FLIP, and
# fails (exit 1) when the RMSE is over what noise alone explains:
# sqrt((0.073 / sqrt(SPP))^2 + 0.002^2) -- rt's per-sample standard
# deviation on this image with the independent sampler (sobol, the
# default, is lower) and the reference's own noise -- times 1.25.
# The render stays in build/reference/ for a look or another compare.
# Environment: SPP (default 64), THREADS (default: every CPU), SHARED
# (default ../shared), RT (default ./rt).
set -eu
RT=${RT:-./rt}
SHARED=${SHARED:-../shared}
SPP=${SPP:-64}
ref=$SHARED/reference/cornell/reference.pfm
if [ ! -f "$ref" ]; then
    echo "reference: no $ref (set SHARED to the shared assets)" >&2
    exit 2
fi
mkdir -p build/reference
out=build/reference/cornell-${SPP}spp.pfm
max=$(awk -v n="$SPP" 'BEGIN { printf "%.5f", 1.25 * sqrt(0.073 * 0.073 / n + 0.002 * 0.002) }')
threads=""
[ -n "${THREADS:-}" ] && threads="-t $THREADS"
echo "reference: $RT -s $SPP -o $out scenes/cornell-reference.txt"
# shellcheck disable=SC2086 # $threads is empty or two words
"$RT" -q -s "$SPP" $threads -o "$out" scenes/cornell-reference.txt
echo "reference: $RT compare $out $ref --max-rmse $max"
"$RT" compare "$out" "$ref" --max-rmse "$max"
