#!/bin/sh
# make test-slurm: the Slurm launcher (examples/slurm/) against a real Slurm
# on this one machine. Installs Debian's slurm-wlm when it is missing, writes
# a throwaway slurm.conf in a temporary directory (auth/none and cred/none,
# so no munge; one node: this machine as `slurmd -C` reports it; state,
# spool, pid files and logs in the temporary directory; ports not in use),
# starts slurmctld and slurmd with it, submits the job array and the merge
# job through examples/slurm/submit.sh as a user would (one part already
# there, half rendered, as a task stopped by its time limit leaves it:
# submit.sh --resume) and, beside them, an array of frames
# (examples/slurm/render-frames.sbatch, one frame already there, one stopped
# and resumed), waits for
# them, and checks that the merged image and every frame are the
# single-machine render byte for byte.
# Whether it passes, fails, times out or is interrupted, it cancels its
# jobs, stops both daemons by their pid files, ends anything they left (found
# by a marker in the environment it gave them) and removes the directory.
# Needs root (slurmd starts jobs as their user). Environment: RT_BIN
# (default ./rt), RT_SLURM_PARTS (default 3), RT_SLURM_TIMEOUT (seconds for
# the jobs, default 300).
set -eu
# Slurm's daemons live in sbin, which a user's or a CI runner's PATH may lack
PATH=$PATH:/usr/local/sbin:/usr/sbin:/sbin
export PATH
. tests/launch-common.sh
launch_setup test-slurm
parts=${RT_SLURM_PARTS:-3}
timeout=${RT_SLURM_TIMEOUT:-300}

# The processes this test starts carry RT_SLURM_TEST=$work in their
# environment (the daemons, and through them the jobs' slurmstepd and
# scripts): the last resort of the clean-up ends exactly those.
marked() {
    for e in /proc/[0-9]*/environ; do
        if tr '\0' '\n' 2>/dev/null < "$e" | grep -qxF "RT_SLURM_TEST=$work"; then
            p=${e#/proc/}
            [ "${p%/environ}" = $$ ] || echo "${p%/environ}"
        fi
    done
}

stop_pidfile() { # FILE
    [ -s "$1" ] || return 0
    pid=$(cat "$1")
    kill "$pid" 2>/dev/null || return 0
    i=0
    while kill -0 "$pid" 2>/dev/null && [ $i -lt 50 ]; do sleep 0.2; i=$((i + 1)); done
    kill -9 "$pid" 2>/dev/null || true
}

cleanup() {
    status=$?
    trap '' INT TERM
    unset RT_SLURM_TEST   # (so that the clean-up's own commands are not marked)
    if [ -f "$work/slurm.conf" ]; then
        timeout 15 scancel --quiet --user="$(id -un)" 2>/dev/null || true
        stop_pidfile "$work/slurmd.pid"
        stop_pidfile "$work/slurmctld.pid"
        left=$(marked)
        if [ -n "$left" ]; then
            # shellcheck disable=SC2086 # a list of process ids
            kill -9 $left 2>/dev/null || true
        fi
    fi
    rm -rf "$work"
    exit $status
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM HUP

if [ "$(id -u)" -ne 0 ]; then
    launch_fail "needs root: slurmd runs the jobs as the user who submits them"
fi
sh tools/install-deps.sh slurm-wlm:slurmctld slurm-wlm:slurmd slurm-wlm:sbatch
plugins=$(dirname "$(find /usr/lib -name auth_none.so -path '*slurm*' 2>/dev/null | head -n 1)")
[ -f "$plugins/auth_none.so" ] && [ -f "$plugins/cred_none.so" ] ||
    launch_fail "this Slurm ($(slurmctld -V)) has no auth/none or cred/none plugin"

# Two free TCP ports from 16817 up (not Slurm's 6817/6818: a real Slurm may run here).
port_free() { [ -z "$(ss -Hltn "sport = :$1" 2>/dev/null)" ]; }
ctld_port=16817
while ! port_free $ctld_port || ! port_free $((ctld_port + 1)); do ctld_port=$((ctld_port + 2)); done

node=$(slurmd -C | sed -n '1s/^NodeName=[^ ]* //p')
host=$(hostname -s)
mkdir -p "$work/state" "$work/spool" "$work/run"
cat > "$work/slurm.conf" <<CONF
# written by tests/slurm.sh; removed with its directory
ClusterName=rttest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$((ctld_port + 1))
AuthType=auth/none
CredType=cred/none
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 $node State=UNKNOWN
PartitionName=rt Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf" RT_SLURM_TEST="$work"

show_logs() {
    for f in "$work"/slurmctld.log "$work"/slurmd.log "$work"/run/*.out; do
        [ -f "$f" ] || continue
        echo "--- $f (last lines)" >&2
        tail -n 15 "$f" >&2
    done
}

echo "test-slurm: $(slurmctld -V), a controller and a node on ports $ctld_port, $((ctld_port + 1))"
slurmctld -f "$SLURM_CONF" || { show_logs; launch_fail "slurmctld did not start"; }
slurmd -f "$SLURM_CONF" || { show_logs; launch_fail "slurmd did not start"; }
i=0
until [ "$(sinfo -h -o %t 2>/dev/null)" = idle ]; do
    i=$((i + 1))
    [ $i -le 60 ] || { show_logs; launch_fail "the node is not idle after 30 s: $(sinfo 2>&1)"; }
    sleep 0.5
done

cd "$work/run"
launch_scene scene.txt
launch_single scene.txt single.pfm
# Part 1 is there already with samples 0..2 of 8, as a task stopped by its
# time limit leaves it: submit.sh refuses the directory without --resume,
# and with it task 1 resumes the part while the others render theirs.
mkdir parts
"$RT" -q --part "1/$parts" --spp-range 0:3 -o parts/part.1.exr scene.txt || launch_fail "the partial part 1 was not rendered"
if RT="$RT" sh "$REPO/examples/slurm/submit.sh" "$parts" scene.txt parts image.pfm 2>/dev/null; then
    launch_fail "submit.sh took a directory with parts in it without --resume"
fi
ids=$(RT="$RT" sh "$REPO/examples/slurm/submit.sh" --resume "$parts" scene.txt parts image.pfm)
array=${ids% *}
merge=${ids#* }
# An animation beside it: 2 tasks of 2 frames (frames 0..3; the scene has no
# animation, so each is the single render), frame 1 already there, frame 2
# stopped after its first pass as a time limit's SIGTERM leaves it
# (f.0002.partial.pfm and the part f.0002.part.exr, no f.0002.pfm).
mkdir frames
cp single.pfm frames/f.0001.pfm
"$RT" -q --frames 0:4 --only-frames 2:3 --time-limit 0.000001 -o 'frames/f.%04d.pfm' scene.txt ||
    launch_fail "the stopped frame 2 was not rendered"
[ -f frames/f.0002.part.exr.json ] && [ ! -e frames/f.0002.pfm ] || launch_fail "the stopped frame 2 was not kept apart"
frames=$(RT="$RT" RT_FRAMES_PER_TASK=2 sbatch --parsable --array=0-1 \
    "$REPO/examples/slurm/render-frames.sbatch" scene.txt 'frames/f.%04d.pfm')
frames=${frames%%;*}

# the states of a job's tasks, sorted, one space after each
job_state() { scontrol -o show job "$1" 2>/dev/null | tr ' ' '\n' | sed -n 's/^JobState=//p' | sort -u | tr '\n' ' '; }
start=$(date +%s)
for job in "$merge" "$frames"; do
    while :; do
        state=$(job_state "$job")
        case $state in
            *PENDING* | *RUNNING* | *CONFIGURING* | *COMPLETING* | *REQUEUE* | *SUSPENDED* | '') ;;
            *) break ;;
        esac
        if [ $(($(date +%s) - start)) -ge "$timeout" ]; then
            show_logs
            launch_fail "the jobs did not finish in $timeout s (parts $array: $(job_state "$array"), merge $merge:" \
                "$(job_state "$merge"), frames $frames: $(job_state "$frames"))"
        fi
        sleep 1
    done
done
for job in "$array" "$merge" "$frames"; do
    if [ "$(job_state "$job")" != 'COMPLETED ' ]; then
        show_logs
        launch_fail "job $job ended $(job_state "$job")(parts $array, merge $merge, frames $frames)"
    fi
done
for i in $(seq 0 $((parts - 1))); do
    [ -f "parts/part.$i.exr" ] && [ -f "parts/part.$i.exr.json" ] || launch_fail "task $i left no part.$i.exr with its sidecar"
done
grep -q 'resuming it' rt-part-"${array}"_1.out || launch_fail "task 1 did not resume its part: $(cat rt-part-"${array}"_1.out)"
launch_same image.pfm single.pfm "$parts parts on Slurm (one resumed), merged"
grep -q 'frame 1: .* is there, kept' rt-frames-"${frames}"_0.out || launch_fail "frame 1 was rendered again"
grep -q 'frame 2: stopped at 4 of 8 samples .*: resuming it' rt-frames-"${frames}"_1.out ||
    launch_fail "task 1 did not resume the stopped frame 2: $(cat rt-frames-"${frames}"_1.out)"
[ ! -e frames/f.0002.part.exr ] || launch_fail "the resumed frame 2 left its part"
for f in 0 1 2 3; do
    launch_same "frames/f.000$f.pfm" single.pfm "frame $f of the frames array"
done
echo "test-slurm: 1 passed, 0 failed ($parts array tasks, a merge job and 2 tasks of frames in $(($(date +%s) - start)) s)"
