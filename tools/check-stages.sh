#!/bin/sh
# Checks the house's one direction of dependency: every file of a stage
# (src/STAGE and include/rt/STAGE) includes only headers of its own stage
# and of the stages below it, in the order of the Makefile's STAGES line
# (lowest first), with the driver (src/driver) above them all. Prints each
# include that climbs and exits 1 when there is one; prints one line and
# exits 0 when there is none. Run by `make test`.
#   sh tools/check-stages.sh
cd "$(dirname "$0")/.." || exit 2
stages=$(sed -n 's/^STAGES *:= *//p' Makefile)
[ -n "$stages" ] || { echo "check-stages: no STAGES line in the Makefile" >&2; exit 2; }
stages="$stages driver"
rank() { # the position of stage $1 in $stages, or nothing
    i=0
    for s in $stages; do
        i=$((i + 1))
        [ "$s" = "$1" ] && { echo $i; return; }
    done
}
bad=0
for s in $stages; do
    r=$(rank "$s")
    for f in $(find "src/$s" "include/rt/$s" -name '*.[ch]' -o -name '*.cc' 2>/dev/null | sort); do
        for t in $(sed -n 's|^[[:space:]]*#[[:space:]]*include[[:space:]]*"rt/\([a-z_]*\)/.*|\1|p' "$f" | sort -u); do
            tr=$(rank "$t")
            if [ -z "$tr" ]; then
                echo "$f includes rt/$t/, which is no stage" >&2
                bad=1
            elif [ "$tr" -gt "$r" ]; then
                echo "$f ($s) includes rt/$t/, a stage above it" >&2
                bad=1
            fi
        done
    done
done
[ "$bad" -eq 0 ] && echo "stages: every include stays in its stage or goes down ($stages)"
exit $bad
