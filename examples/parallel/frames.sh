#!/bin/sh
# An animation over a few machines by ssh, with GNU parallel: each frame a
# job, one at a time on each host; no merge.
#
#   RT_HOSTS=ws1,ws2,: sh frames.sh A:B SCENE PATTERN [rt flags...]
#   RT_HOSTS=ws1,ws2,: sh examples/parallel/frames.sh 0:240 scene.gltf 'f.%04d.png' -s 256
#
# Frames A .. B-1, each `rt --frames F:F+1 -o PATTERN` on some host, into
# the names PATTERN gives (`%04d`, `%d` or `%0Nd`, as rt's -o) in the
# current directory; the scene goes to each host (--basefile), every frame
# comes back (--return) and is removed there (--cleanup). A frame whose file
# is here already is kept, so running it again renders what is missing. A
# frame stopped (--time-limit in the rt flags, a host lost) comes back as
# NAME.partial.EXT and NAME.part.exr, never under its name, and running
# frames.sh again resumes it from that part. Each job renders its frame F
# with `--frames A:B --only-frames F:F+1`: the automatic camera frames the
# whole of A:B on every host (run it again with the same A:B).
# RT_HOSTS, rt, ssh and rsync as for render.sh (beside this file). It is
# this line, with F, NAME and F+1 linked (:::+) for the frames to render
# (and the stop files returned, below):
#
#   parallel -q -S 1/ws1,1/ws2,1/: --bf scene.gltf --return '{2}' --cleanup --halt now,fail=1 \
#       rt --frames 0:240 --only-frames {1}:{3} -o f.%04d.png scene.gltf ::: 0 1 ... :::+ f.0000.png ... :::+ 1 2 ...
set -eu
# shellcheck source=checks.sh source-path=SCRIPTDIR
. "$(dirname "$0")/checks.sh"
need_args frames.sh $# 3 "RT_HOSTS=host1,host2,: sh frames.sh A:B SCENE PATTERN [rt flags...]"
range=$1
scene=$2
pattern=$3
shift 3
a=${range%%:*}
b=${range#*:}
case $a:$b in
    *[!0-9:]* | :* | *: | *:*:*) echo "frames.sh: A:B must be two frame numbers, not '$range'" >&2; exit 2 ;;
esac
case $pattern in
    */* | *' '*) echo "frames.sh: PATTERN is a file name here, without / or spaces (the frames come back here), not '$pattern'" >&2; exit 2 ;;
    *%*) ;;
    *) echo "frames.sh: PATTERN needs a %04d (or %d, %0Nd) for the frame number: '$pattern'" >&2; exit 2 ;;
esac
[ "$a" -lt "$b" ] || { echo "frames.sh: no frames in $range (A < B, B not rendered)" >&2; exit 2; }
need_scene frames.sh "$scene"
need_gnu_parallel frames.sh
# The frames to render: those not here yet. A frame stopped earlier (a
# --time-limit among the rt flags, a host that went away) is not here under
# its name: rt left NAME.partial.EXT and its sums NAME.part.exr (with
# NAME.part.exr.json), which came back here; such a frame goes out again
# with its part and resumes from it (exact: a render never stopped).
fresh=""
stopped=""
f=$a
while [ "$f" -lt "$b" ]; do
    # shellcheck disable=SC2059 # the pattern is the format, as rt reads it
    name=$(printf "$pattern" "$f")
    part=${name%.*}.part.exr
    if [ -e "$name" ]; then
        echo "frames.sh: frame $f: $name is there, kept" >&2
    elif [ -f "$part.json" ]; then
        echo "frames.sh: frame $f: stopped earlier ($part): resuming it" >&2
        stopped="$stopped $f"
    else
        fresh="$fresh $f"
    fi
    f=$((f + 1))
done
if [ -z "$fresh$stopped" ]; then
    echo "frames.sh: every frame of $range is there" >&2
    exit 0
fi
# One job a frame F: `rt --frames A:B --only-frames F:F+1` (the automatic
# camera framed for all of A:B, whichever host renders F), then on the host
# an empty file for each of the frame, NAME.partial.EXT, NAME.part.exr and
# its sidecar that rt did not write, so that --return brings back what is
# there without rsync complaining of what is not; the empty ones are
# removed here. The stopped frames go out with their part (--transferfile).
# {2} NAME, {3} F+1, {4} NAME.partial.EXT, {5} NAME.part.exr.
# shellcheck disable=SC2016 # the script runs on the host
script='n=$1 p=$2 q=$3; shift 3; "$@"; s=$?; for x in "$n" "$p" "$q" "$q.json"; do [ -e "$x" ] || : > "$x"; done; exit $s'
status=0
for kind in fresh stopped; do
    if [ "$kind" = fresh ]; then list=$fresh tf=""; else list=$stopped tf="--tf {5} --tf {5}.json"; fi
    [ -n "$list" ] && [ "$status" -eq 0 ] || continue
    names=""
    nexts=""
    partials=""
    parts=""
    for f in $list; do
        # shellcheck disable=SC2059
        name=$(printf "$pattern" "$f")
        names="$names $name"
        nexts="$nexts $((f + 1))"
        partials="$partials ${name%.*}.partial.${name##*.}"
        parts="$parts ${name%.*}.part.exr"
    done
    # shellcheck disable=SC2086 # the lists and $tf are words
    parallel -q -S "${RT_HOSTS:-:}" -j 1 --bf "$scene" $tf --return '{2}' --return '{4}' --return '{5}' \
        --return '{5}.json' --cleanup --halt now,fail=1 \
        sh -c "$script" sh '{2}' '{4}' '{5}' "${RT:-rt}" --frames "$range" --only-frames '{1}:{3}' -o "$pattern" \
        "$@" "$scene" ::: $list :::+ $names :::+ $nexts :::+ $partials :::+ $parts </dev/null || status=$?
done
# What came back: the empty stand-ins removed; a finished frame's stop
# files (sent out to resume it) removed too.
for f in $fresh $stopped; do
    # shellcheck disable=SC2059
    name=$(printf "$pattern" "$f")
    for x in "$name" "${name%.*}.partial.${name##*.}" "${name%.*}.part.exr" "${name%.*}.part.exr.json"; do
        if [ -f "$x" ] && [ ! -s "$x" ]; then rm -f "$x"; fi
    done
    if [ -s "$name" ]; then
        rm -f "${name%.*}.partial.${name##*.}" "${name%.*}.part.exr" "${name%.*}.part.exr.json"
    elif [ -f "${name%.*}.part.exr.json" ]; then
        echo "frames.sh: frame $f stopped (${name%.*}.part.exr); run frames.sh again to resume it" >&2
    fi
done
exit "$status"
