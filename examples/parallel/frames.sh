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
# is here already is kept, so running it again renders what is missing.
# RT_HOSTS, rt, ssh and rsync as for render.sh (beside this file). It is
# this line, with F, NAME and F+1 linked (:::+) for the frames to render:
#
#   parallel -q -S 1/ws1,1/ws2,1/: --bf scene.gltf --return '{2}' --cleanup --halt now,fail=1 \
#       rt --frames {1}:{3} -o f.%04d.png scene.gltf ::: 0 1 ... :::+ f.0000.png f.0001.png ... :::+ 1 2 ...
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
frames=""
names=""
nexts=""
f=$a
while [ "$f" -lt "$b" ]; do
    # shellcheck disable=SC2059 # the pattern is the format, as rt reads it
    name=$(printf "$pattern" "$f")
    if [ -e "$name" ]; then
        echo "frames.sh: frame $f: $name is there, kept" >&2
    else
        frames="$frames $f"
        names="$names $name"
        nexts="$nexts $((f + 1))"
    fi
    f=$((f + 1))
done
if [ -z "$frames" ]; then
    echo "frames.sh: every frame of $range is there" >&2
    exit 0
fi
# shellcheck disable=SC2086 # the lists are words
parallel -q -S "${RT_HOSTS:-:}" -j 1 --bf "$scene" --return '{2}' --cleanup --halt now,fail=1 \
    "${RT:-rt}" --frames '{1}:{3}' -o "$pattern" "$@" "$scene" ::: $frames :::+ $names :::+ $nexts </dev/null
