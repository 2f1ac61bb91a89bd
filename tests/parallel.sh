#!/bin/sh
# make test-parallel: the GNU parallel launcher (examples/parallel/render.sh)
# with its real transfers but no network. Installs Debian's parallel (and
# rsync, which it copies files with) when missing. Two "ssh hosts" are a
# stand-in ssh that runs the command here in a home directory of the host's
# own, so the scene really travels there (--basefile), the parts really come
# back (--return) and are removed there (--cleanup); `:` (this machine) runs
# parts too. Checks the merged image against a single-machine render byte for
# byte, that the hosts' homes are left empty, and that the launcher refuses
# to run over the parts of an earlier render; then frames.sh, 4 frames over
# the same hosts with one already there (kept) and one stopped (resumed),
# each frame against the single render (the scene has no animation); then
# frames stopped on the hosts by a time limit, which come back apart and
# resume to the same bytes when frames.sh runs again. Environment: RT_BIN (./rt).
set -eu
. tests/launch-common.sh
launch_setup test-parallel
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
sh tools/install-deps.sh parallel rsync:rsync   # (the package: moreutils has a parallel too)

# ssh [OPTIONS] HOST COMMAND...: the command through sh in $work/hosts/HOST
cat > "$work/ssh" <<FAKE
#!/bin/sh
while [ \$# -gt 0 ]; do
    case \$1 in -l | -p | -o | -i | -F) shift 2 ;; --) shift; break ;; -*) shift ;; *) break ;; esac
done
host=\$1
shift
[ "\${1:-}" = -- ] && shift
mkdir -p "$work/hosts/\$host"
# sshd gives the remote command the user's HOME and login SHELL (GNU
# parallel's wrapper runs the command through \$SHELL): here, the host's home
cd "$work/hosts/\$host" && HOME=\$PWD SHELL=/bin/sh exec sh -c "\$*"
FAKE
chmod +x "$work/ssh"

mkdir -p "$work/run"
cd "$work/run"
launch_scene scene.txt
launch_single scene.txt single.pfm
export PARALLEL="--ssh $work/ssh" RT="$RT"
RT_HOSTS=1/hostA,1/hostB,1/: sh "$REPO/examples/parallel/render.sh" 5 scene.txt image.pfm ||
    launch_fail "examples/parallel/render.sh failed"
launch_same image.pfm single.pfm "5 parts over GNU parallel, merged"
for i in 0 1 2 3 4; do
    [ -f "image.part.$i.exr" ] && [ -f "image.part.$i.exr.json" ] || launch_fail "part $i did not come back with its sidecar"
done
for h in hostA hostB; do
    [ -d "$work/hosts/$h" ] || launch_fail "no part ran on $h"
    left=$(find "$work/hosts/$h" -type f)
    [ -z "$left" ] || launch_fail "--cleanup left on $h: $left"
done
if RT_HOSTS=: sh "$REPO/examples/parallel/render.sh" 5 scene.txt image.pfm 2>/dev/null; then
    launch_fail "render.sh ran over the parts of the earlier render"
fi
# An animation: frames 0..3 over the same hosts, frame 2 already here (kept),
# frame 1 stopped after its first pass (here, as a time limit or SIGTERM
# leaves it: f.0001.partial.pfm and the part f.0001.part.exr), resumed
"$RT" -q --frames 0:4 --only-frames 1:2 --time-limit 0.000001 -o 'f.%04d.pfm' scene.txt
[ -f f.0001.part.exr.json ] && [ ! -e f.0001.pfm ] || launch_fail "the stopped frame 1 was not kept apart"
cp single.pfm f.0002.pfm
RT_HOSTS=1/hostA,1/hostB,1/: sh "$REPO/examples/parallel/frames.sh" 0:4 scene.txt 'f.%04d.pfm' 2> frames.log ||
    { cat frames.log >&2; launch_fail "examples/parallel/frames.sh failed"; }
grep -q 'frame 2: f.0002.pfm is there, kept' frames.log || launch_fail "frame 2 was not kept: $(cat frames.log)"
grep -q 'frame 1: stopped earlier (f.0001.part.exr): resuming it' frames.log ||
    launch_fail "frame 1 was not resumed: $(cat frames.log)"
for f in 0 1 2 3; do
    launch_same "f.000$f.pfm" single.pfm "frame $f over GNU parallel"
done
left=$(ls f.000[0-3].part* 2>/dev/null || true; find . -name 'f.*' -empty)
[ -z "$left" ] || launch_fail "the stop files of frame 1 (or empty stand-ins) were left here: $left"
left=$(find "$work/hosts" -type f)
[ -z "$left" ] || launch_fail "--cleanup left frames on the hosts: $left"
# Frames stopped on the hosts (a time limit over before the first pass
# ends) come back apart, never under their names; run again, they resume
# there to the single render's bytes
RT_HOSTS=1/hostA,1/hostB sh "$REPO/examples/parallel/frames.sh" 4:6 scene.txt 'f.%04d.pfm' --time-limit 0.000001 \
    2> stop.log || { cat stop.log >&2; launch_fail "frames.sh with a time limit failed"; }
for f in 4 5; do
    [ ! -e "f.000$f.pfm" ] || launch_fail "the stopped frame $f took the finished frame's name"
    [ -s "f.000$f.partial.pfm" ] && [ -s "f.000$f.part.exr" ] && [ -s "f.000$f.part.exr.json" ] ||
        launch_fail "the stopped frame $f did not come back as f.000$f.partial.pfm and f.000$f.part.exr"
done
RT_HOSTS=1/hostA,1/hostB sh "$REPO/examples/parallel/frames.sh" 4:6 scene.txt 'f.%04d.pfm' 2> resume.log ||
    { cat resume.log >&2; launch_fail "frames.sh resuming the stopped frames failed"; }
for f in 4 5; do
    grep -q "frame $f: stopped earlier" resume.log || launch_fail "frame $f was not resumed: $(cat resume.log)"
    launch_same "f.000$f.pfm" single.pfm "frame $f, stopped on a host and resumed there"
    [ ! -e "f.000$f.part.exr" ] || launch_fail "frame $f's part was left here after its resume"
done
left=$(find "$work/hosts" -type f)
[ -z "$left" ] || launch_fail "--cleanup left files of the resumed frames on the hosts: $left"
echo "test-parallel: 1 passed, 0 failed"
