#!/bin/sh
# One image over a few machines by ssh, with GNU parallel (Debian
# `parallel`): N parts, one at a time on each host, then `rt merge` here.
#
#   RT_HOSTS=ws1,ws2,alice@ws3,: sh render.sh N SCENE IMAGE [rt flags...]
#   RT_HOSTS=ws1,ws2,: sh examples/parallel/render.sh 12 scene.txt image.png -s 1024
#
# It is this one line (with checks around it):
#
#   parallel -q -S 1/ws1,1/ws2,1/: --bf scene.txt --return image.part.{}.exr \
#       --return image.part.{}.exr.json --cleanup --halt now,fail=1 \
#       rt --part {}/12 -o image.part.{}.exr -s 1024 scene.txt ::: $(seq 0 11) &&
#   rt merge -o image.png image.part.*.exr
#
# RT_HOSTS is parallel's --sshlogin list: `:` is this machine, `N/host`
# runs N parts at once there (default 1: rt takes every core of a host).
# Each host needs rt on its PATH (or RT, the same path everywhere) and
# ssh without a password (keys, ssh-agent) and rsync (parallel copies
# files with it, as this machine needs it too); the scene goes to each host
# (--basefile, to the same path relative to its home) and the parts come
# back to the current directory (--return) as IMAGE's name with .part.I.exr
# and a sidecar (image.part.3.exr, image.part.3.exr.json); --cleanup
# removes both from the hosts. A scene that loads
# other files (meshes, textures) needs them there too: add `--bf FILE` for
# each to PARALLEL (the environment variable GNU parallel takes options from),
# or keep the scene on a file system all hosts share. A failed part stops
# the rest (--halt) and nothing is merged; the parts written stay, and
# `rt --part I/N` renders a missing one by hand. The argument checks are
# in checks.sh, beside this file.
set -eu
# shellcheck source=checks.sh source-path=SCRIPTDIR
. "$(dirname "$0")/checks.sh"
need_args render.sh $# 3 "RT_HOSTS=host1,host2,: sh render.sh N SCENE IMAGE [rt flags...]"
n=$1
scene=$2
image=$3
shift 3
case $n in
    '' | *[!0-9]* | 0) echo "render.sh: N must be a number of parts >= 1, not '$n'" >&2; exit 2 ;;
esac
need_scene render.sh "$scene"
need_gnu_parallel render.sh
rt=${RT:-rt}
stem=$(basename "${image%.*}")
for f in "$stem".part.*; do
    if [ -e "$f" ]; then
        echo "render.sh: $f is in the way (parts of an earlier render?): move or remove $stem.part.*" >&2
        exit 2
    fi
done
parallel -q -S "${RT_HOSTS:-:}" -j 1 --bf "$scene" --return "$stem.part.{}.exr" \
    --return "$stem.part.{}.exr.json" --cleanup --halt now,fail=1 \
    "$rt" --part "{}/$n" -o "$stem.part.{}.exr" "$@" "$scene" ::: $(seq 0 $((n - 1))) </dev/null
"$rt" merge -o "$image" "$stem".part.*.exr
