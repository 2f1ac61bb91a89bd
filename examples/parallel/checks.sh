# shellcheck shell=sh
# The checks render.sh and frames.sh (beside this file) make before they
# start GNU parallel; sourced, not run. Each prints "NAME: ..." on standard
# error and exits 2 when the check fails:
#   need_args NAME GIVEN LEAST USAGE   at least LEAST arguments were GIVEN
#   need_scene NAME SCENE              SCENE is a readable file
#   need_gnu_parallel NAME             `parallel` is GNU parallel

need_args() {
    if [ "$2" -lt "$3" ]; then
        echo "$1: usage: $4" >&2
        exit 2
    fi
}

need_scene() {
    [ -r "$2" ] || { echo "$1: cannot read the scene $2" >&2; exit 2; }
}

need_gnu_parallel() {
    if ! parallel --version 2>/dev/null | grep -q '^GNU parallel'; then
        echo "$1: GNU parallel is not installed (apt-get install parallel; moreutils' parallel is another program)" >&2
        exit 2
    fi
}
