#!/bin/sh
# make fuzz: builds one libFuzzer binary per target (tests/fuzz/harness.h)
# with clang -fsanitize=fuzzer,address,undefined, seeds each from
# ../shared/assets, scenes/ and tests/corpus/, and runs it for FUZZ_SECONDS
# (default 60). Prints executions per second and totals per target (also
# kept in build-fuzz/summary.txt); exits 1 if any target crashed, leaked,
# hung or ran out of memory in this run (the input is saved under
# build-fuzz/crashes/TARGET/: fix the bug, then keep the input in
# tests/corpus/TARGET/ so make test replays it). Reproduce one input with
# ./build-fuzz/fuzz_TARGET FILE.
# A run that fuzzed too little fails too: a target the harness does not
# know (tests/fuzz/harness.c's rt_fuzz_targets), a target whose run reports
# no execution count, or fewer executions than FUZZ_MIN_EXECS_PER_S (default
# 10) times FUZZ_SECONDS.
# Environment: FUZZ_SECONDS, FUZZ_TARGETS (space-separated subset), SHARED,
# FUZZ_MIN_EXECS_PER_S.
set -eu
SECONDS_EACH=${FUZZ_SECONDS:-60}
SHARED=${SHARED:-../shared}
MIN_RATE=${FUZZ_MIN_EXECS_PER_S:-10}
KNOWN=$(sed -n '/rt_fuzz_targets\[\] = {/,/};/p' tests/fuzz/harness.c | grep -o '"[a-z_]*"' | tr -d '"' | tr '\n' ' ')
TARGETS=${FUZZ_TARGETS:-$KNOWN}
B=build-fuzz
for t in $TARGETS; do
    case " $KNOWN " in
        *" $t "*) ;;
        *) echo "fuzz: unknown target '$t' (the harness has: $KNOWN)" >&2; exit 1 ;;
    esac
done
[ -n "$(echo $TARGETS)" ] || { echo "fuzz: no targets" >&2; exit 1; }

if ! command -v clang >/dev/null 2>&1 || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
    echo "fuzz: installing clang and its libFuzzer runtime (clang, libclang-rt-14-dev)" >&2
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
    $SUDO apt-get install -y -q clang libclang-rt-14-dev >&2 || { $SUDO apt-get update -q >&2 && $SUDO apt-get install -y -q clang libclang-rt-14-dev >&2; }
fi

SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined"
CFLAGS="-std=c11 -g -O1 -fno-omit-frame-pointer -Iinclude -Itests -D_POSIX_C_SOURCE=200809L $SAN"
mkdir -p $B/obj
# the library (every stage folder but the driver), instrumented for coverage
for src in src/*/*.c; do
    case $src in src/driver/*) continue ;; esac
    obj=$B/obj/$(echo "${src#src/}" | tr / _ | sed 's/\.c$/.o/')
    if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ -n "$(find include src -name "*.h" -newer "$obj" 2>/dev/null | head -n 1)" ]; then
        clang $CFLAGS -fsanitize=fuzzer-no-link -c -o "$obj" "$src"
    fi
done
# the one C++ file (the Draco wrapper)
for src in src/*/*.cc; do
    obj=$B/obj/$(echo "${src#src/}" | tr / _ | sed 's/\.cc$/.o/')
    if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ include/rt/io/draco.h -nt "$obj" ]; then
        clang++ -std=c++17 -g -O1 -fno-omit-frame-pointer -Iinclude $SAN -fno-sanitize=vptr -fsanitize=fuzzer-no-link -c -o "$obj" "$src"
    fi
done
clang $CFLAGS -fsanitize=fuzzer-no-link -c -o $B/harness.o tests/fuzz/harness.c

# seed corpora
python3 tools/fuzz_seeds.py "$SHARED" $B/seeds

status=0
summary=$B/summary.txt
printf '%-10s %12s %14s %8s\n' target execs/s total_execs crashes | tee "$summary"
for t in $TARGETS; do
    clang $CFLAGS -fsanitize=fuzzer -DRT_FUZZ_TARGET="\"$t\"" -o $B/fuzz_$t tests/fuzz/fuzz_main.c $B/harness.o $B/obj/*.o \
        -lstb -lOpenEXRCore -lmeshoptimizer -ldraco -lwebp -lstdc++ -ldl -lpthread -lm
    mkdir -p $B/corpus/$t $B/crashes/$t $B/seeds/$t
    dict=""
    case $t in
        gltf|glb|gltf_bin|pose) dict="-dict=tests/fuzz/gltf.dict" ;;
        scene) dict="-dict=tests/fuzz/scene.dict" ;;
    esac
    seeds="$B/seeds/$t"
    [ -d tests/corpus/$t ] && seeds="$seeds tests/corpus/$t"
    log=$B/fuzz_$t.log
    stamp=$B/crashes/$t/.started
    : >"$stamp"
    if ! ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 ./$B/fuzz_$t $dict -max_total_time="$SECONDS_EACH" \
        -rss_limit_mb=4096 -malloc_limit_mb=2048 -timeout=20 -print_final_stats=1 \
        -artifact_prefix=$B/crashes/$t/ $B/corpus/$t $seeds >"$log" 2>&1; then
        status=1
    fi
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
    # only this run's artifacts count (older ones stay for reference)
    crashes=$(find $B/crashes/$t -type f ! -name .started -newer "$stamp" | wc -l)
    printf '%-10s %12s %14s %8s\n' "$t" "${rate:-?}" "${execs:-?}" "$crashes" | tee -a "$summary"
    [ "$crashes" -eq 0 ] || { status=1; grep -m 3 -E 'ERROR|SUMMARY|runtime error' "$log" >&2 || true; }
    floor=$((MIN_RATE * SECONDS_EACH))
    if [ -z "$execs" ]; then
        echo "fuzz: $t reported no execution count (see $log)" >&2
        tail -n 3 "$log" >&2
        status=1
    elif [ "$execs" -lt "$floor" ]; then
        echo "fuzz: $t ran $execs executions in $SECONDS_EACH s, under the floor of $floor ($MIN_RATE a second)" >&2
        status=1
    fi
done
exit $status
