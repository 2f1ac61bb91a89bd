#!/bin/sh
# Runs each cmocka test binary given, shows its output, and ends with one
# summary line "tests: N passed, N failed, N skipped" over all of them
# (a test skips when what it needs, such as the shared assets, is absent).
# Environment: RT_SHARED (shared assets, default ../shared), RT_BIN (./rt).
passed=0
failed=0
skipped=0
broken=""
for t in "$@"; do
    out=$("$t" 2>&1)
    rc=$?
    printf '%s\n' "$out"
    p=$(printf '%s\n' "$out" | sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    f=$(printf '%s\n' "$out" | sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    k=$(printf '%s\n' "$out" | sed -n 's/^\[  SKIPPED \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    passed=$((passed + ${p:-0}))
    skipped=$((skipped + ${k:-0}))
    failed=$((failed + ${f:-0}))
    if [ "$rc" -ne 0 ] && [ -z "$f" ]; then
        failed=$((failed + 1))   # crashed or aborted before cmocka could count
        broken="$broken $t"
    fi
done
[ -n "$broken" ] && echo "crashed:$broken"
echo "tests: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
