#!/bin/sh
# Spreads one image over a Slurm cluster: a job array of N parts
# (render-array.sbatch) and a merge job that runs when all of them have
# succeeded (merge.sbatch). Run it on a login node, in a directory every
# node sees:
#
#   sh submit.sh [--resume] N SCENE PARTDIR IMAGE [rt flags...]
#   sh examples/slurm/submit.sh 16 scenes/cornell.txt parts cornell.png -s 1024
#
# PARTDIR must be new or empty, unless --resume: then it holds the parts of
# an earlier submission of the same N, SCENE and flags that did not finish
# (a task hit its time limit or failed, the merge was cancelled); the tasks
# complete what is missing (render-array.sbatch) and the merge runs again.
#
# Prints the two job IDs (array, merge) on standard output; squeue shows
# them. Extra sbatch options (partition, account, CPUs, time) go in SBATCH_*
# environment variables (SBATCH_PARTITION=gpu) or in the #SBATCH lines of the
# two scripts.
set -eu
resume=no
if [ "${1:-}" = --resume ]; then
    resume=yes
    shift
fi
if [ $# -lt 4 ]; then
    echo "submit.sh: usage: sh submit.sh [--resume] N SCENE PARTDIR IMAGE [rt flags...]" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
n=$1
scene=$2
dir=$3
image=$4
shift 4
case $n in
    '' | *[!0-9]* | 0) echo "submit.sh: N must be a number of parts >= 1, not '$n'" >&2; exit 2 ;;
esac
[ -r "$scene" ] || { echo "submit.sh: cannot read the scene $scene" >&2; exit 2; }
if [ $resume = no ] && [ -d "$dir" ] && [ -n "$(ls -A "$dir")" ]; then
    echo "submit.sh: $dir is not empty (the merge takes every part in it): give a new directory, or --resume" >&2
    exit 2
fi
mkdir -p "$dir"
array=$(sbatch --parsable --array="0-$((n - 1))" "$here/render-array.sbatch" "$scene" "$dir" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes "$here/merge.sbatch" "$dir" "$image")
merge=${merge%%;*}
echo "submit.sh: $n parts in job array $array, the merge into $image in job $merge" >&2
echo "$array $merge"
