#!/bin/sh
# Time to quality of rt against Mitsuba 3 on a media scene (docs/performance.md,
# "Media"): each renderer renders the scene twice at SPP samples per pixel with
# different seeds, interleaved (rt, Mitsuba, rt, Mitsuba) so that both see the
# same load; the RMSE between a renderer's two images over sqrt(2) is its noise
# sigma at SPP, and sigma^2 x CPU seconds (user + system) its cost: the CPU time
# to reach a noise sigma_t is that product over sigma_t^2.
#
#   sh tests/media/time-to-quality.sh RT_SCENE.txt MITSUBA_SCENE.xml [SPP [PYTHON]]
#
# PYTHON (default python3) must import mitsuba (pip's, 3.9.1 made the figures);
# the Mitsuba variant is llvm_ad_rgb. Run from the repository root after make
# (RT names another rt binary).
set -eu
rts=$1; mis=$2; spp=${3:-64}; py=${4:-python3}; rt=${RT:-./rt}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
here=$(dirname "$0")
cpu() { # label, command...: runs it, prints "label cpu wall"
    label=$1; shift
    /usr/bin/time -f "%U %S %e" -o "$out/t" "$@" >/dev/null 2>&1
    awk -v l="$label" '{printf "%s cpu %.1f s wall %.1f s\n", l, $1 + $2, $3}' "$out/t"
}
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
cpu "rt seed 1" "$rt" -q -s "$spp" --seed 1 -o "$out/rt1.pfm" "$rts"
SEED=1000 cpu "mitsuba seed 1" "$py" "$here/mitsuba-reference.py" "$mis" "$out/mi1.exr" "$spp"
cpu "rt seed 2" "$rt" -q -s "$spp" --seed 2 -o "$out/rt2.pfm" "$rts"
SEED=2000 cpu "mitsuba seed 2" "$py" "$here/mitsuba-reference.py" "$mis" "$out/mi2.exr" "$spp"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "rt: $("$rt" compare "$out/rt1.pfm" "$out/rt2.pfm" | grep '^RMSE\|mean (cand')"
echo "mitsuba: $("$rt" compare "$out/mi1.exr" "$out/mi2.exr" | grep '^RMSE\|mean (cand')"
echo "rt against mitsuba: $("$rt" compare "$out/rt1.pfm" "$out/mi1.exr" | grep '^RMSE')"
