#!/bin/sh
# check-doc-paths.sh - every source path the docs name exists.
#
# README.md, docs/*.md, the examples' and tools' comments name files of the
# repository (src/io/scene_parse.c, include/rt/io/mesh_io.h, rt/job/part.h,
# tests/..., tools/...); after files move, those names go stale and send a
# reader to nothing. This lists every such name that is not a file or a
# directory here and exits 1 if there is one. Names with a wildcard
# and placeholders (src/render/NAME.c) are not checked, nor paths outside
# the repository.
# Run from the repository's root; `make test` runs it.
set -u
status=0
files=$(ls README.md docs/*.md tools/*.sh tools/*.py examples/*/* 2>/dev/null)
for f in $files; do
    [ -f "$f" ] || continue
    grep -noE '(^|[^A-Za-z0-9_/.*-])((src|include|tests|tools|examples|bench)/[A-Za-z0-9_./-]*\.(c|cc|h|sh|py)|rt/(base|image|scene|accel|render|io|job)/[A-Za-z0-9_]+\.h)([^A-Za-z0-9_*]|$)' "$f" |
    while IFS=: read -r line path; do
        path=$(printf '%s' "$path" | sed 's/^[^A-Za-z]*//; s/[^A-Za-z0-9_]$//')
        case $path in
        rt/*) check=include/$path ;;
        *) check=$path ;;
        esac
        # a path written inside another (../shared/..., /usr/include/...) is not ours
        if [ -e "$check" ]; then continue; fi
        case $check in *NAME*|*FMT*|*TARGET*|*STAGE*) continue ;; esac
        echo "$f:$line: $path: no such file in the repository"
    done
done > /tmp/check-doc-paths.$$
if [ -s /tmp/check-doc-paths.$$ ]; then
    cat /tmp/check-doc-paths.$$
    status=1
fi
rm -f /tmp/check-doc-paths.$$
exit $status
