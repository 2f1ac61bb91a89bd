#!/bin/sh
# Lists the functions of src/ longer than N lines (default 100), longest
# first, as "lines  file:line  name", from Universal Ctags' end lines.
# The generated tables (ggx_albedo_*table.c, *_table.h) are left out.
#   sh tools/long-functions.sh [N]
n=${1:-100}
find src -name '*.c' -o -name '*.cc' | grep -v -E '_table\.(c|h)$' | sort |
    xargs ctags -x --c-kinds=f --c++-kinds=f --fields=+ne --_xformat='%N %F %n %e' -f - 2>/dev/null |
    awk -v n="$n" '$4 != "" { len = $4 - $3 + 1; if (len > n) printf "%5d  %s:%d  %s\n", len, $2, $3, $1 }' |
    sort -rn
