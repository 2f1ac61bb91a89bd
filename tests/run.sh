#!/bin/sh
# Runs each cmocka test binary given, shows its output, and ends with one
# summary line "tests: N passed, N failed, N skipped" over all of them. A
# test skips (cmocka's skip(), its reason printed just before) when what it
# needs is absent: the shared assets, a tool such as Xvfb or strace, the
# denoiser, or, in a sanitizer build, what that runtime cannot run. The
# skipped tests are listed by name after the summary.
# With RT_FAIL_ON_SKIP=1 (CI sets it) a skipped test fails the run unless
# its name is in RT_SKIPS_ALLOWED (space-separated; the Makefile's
# SANITIZER_SKIPS for make asan and make tsan); a name in that list that
# did not skip fails it too, so the list stays true.
# Environment: RT_SHARED (shared assets, default ../shared), RT_BIN (./rt),
# RT_FAIL_ON_SKIP, RT_SKIPS_ALLOWED.
passed=0
failed=0
skipped=0
broken=""
skipped_names=""
for t in "$@"; do
    out=$("$t" 2>&1)
    rc=$?
    printf '%s\n' "$out"
    p=$(printf '%s\n' "$out" | sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    f=$(printf '%s\n' "$out" | sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    k=$(printf '%s\n' "$out" | sed -n 's/^\[  SKIPPED \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    names=$(printf '%s\n' "$out" | sed -n 's/^\[  SKIPPED \] \(test_[A-Za-z0-9_]*\)$/\1/p' | sort -u)
    for n in $names; do
        skipped_names="$skipped_names $n"
    done
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
[ -n "$skipped_names" ] && echo "skipped:$skipped_names"
if [ "${RT_FAIL_ON_SKIP:-0}" = 1 ]; then
    for n in $skipped_names; do
        case " ${RT_SKIPS_ALLOWED:-} " in
            *" $n "*) ;;
            *) echo "tests: $n skipped, and only [${RT_SKIPS_ALLOWED:-}] may (RT_FAIL_ON_SKIP=1)"; failed=$((failed + 1)) ;;
        esac
    done
    for n in ${RT_SKIPS_ALLOWED:-}; do
        case " $skipped_names " in
            *" $n "*) ;;
            *) echo "tests: $n is in RT_SKIPS_ALLOWED but ran: take it off the list"; failed=$((failed + 1)) ;;
        esac
    done
fi
[ "$failed" -eq 0 ]
