# Shared by the launcher tests (tests/slurm.sh, tests/kubernetes.sh,
# tests/parallel.sh); sourced, not run. Each test renders one small scene
# through a launcher in examples/ and checks that the merged image is the
# single-machine render, byte for byte (docs/farm.md: merging region parts
# is exact).
#   launch_setup NAME   RT (absolute path of ./rt, or RT_BIN), REPO, and
#                       $work, a new temporary directory removed on exit
#   launch_scene FILE   writes the test scene: the Cornell box, 64x48, path
#                       traced at 8 spp (small enough for CI's 2 cores)
#   launch_single SCENE OUT   the single-machine render to compare with
#   launch_same A B WHAT      fails unless files A and B are identical
# Environment: RT_BIN (default ./rt).

launch_setup() {
    launch_name=$1
    REPO=$(pwd)
    RT=${RT_BIN:-./rt}
    case $RT in /*) ;; *) RT=$REPO/$RT ;; esac
    [ -x "$RT" ] || launch_fail "no rt binary at $RT (make first)"
    # shellcheck disable=SC2034 # used by the tests that source this file
    work=$(mktemp -d "${TMPDIR:-/tmp}/rt-$launch_name.XXXXXX")
}

launch_fail() {
    echo "$launch_name: FAILED: $*" >&2
    exit 1
}

launch_scene() {
    sed -e 's/^resolution .*/resolution 64 48/' -e 's/^samples .*/samples 8/' \
        -e 's/^integrator .*/integrator path/' -e '/^output /d' -e '/^shadow_samples /d' \
        "$REPO/scenes/cornell.txt" > "$1"
}

launch_single() {
    "$RT" -q -o "$2" "$1" || launch_fail "the single-machine render of $1 failed"
}

launch_same() {
    [ -f "$1" ] || launch_fail "$3: $1 was not written"
    cmp "$1" "$2" >/dev/null || launch_fail "$3: $1 differs from the single-machine render $2"
}
