#!/bin/sh
# Replays every fuzz target's corpus (tests/fuzz/corpus/TARGET) through its
# replay driver, in the normal build and in the sanitizer build when it is
# there, so that every crash a fuzzer once found stays fixed.  One test per
# target and build.  Then, where the libFuzzer build is there (make
# FUZZ=1 fuzz-bin, which `make test` makes), runs each target for
# TK_FUZZ_SECONDS (default 10) from its seeds, so that a regression the
# seeds alone do not reach shows here too.  Ends with "fuzz: N passed, M
# failed, K skipped".
#   TK_BUILD=build TK_ASAN_BUILD=build/asan sh tests/fuzz/run.sh
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${TK_BUILD:-build}
asan=${TK_ASAN_BUILD:-}
passed=0
failed=0
skipped=0
for dir in "$build" $asan; do
    for corpus in "$root"/tests/fuzz/corpus/*/; do
        t=$(basename "$corpus")
        driver="$dir/fuzz/replay_$t"
        if [ ! -x "$driver" ]; then
            failed=$((failed + 1))
            echo "FAIL $driver is missing (make tests-bin builds it)"
            continue
        fi
        log=$(mktemp)
        if "$driver" "$corpus" >"$log" 2>&1; then
            passed=$((passed + 1))
            tail -n 1 "$log" | sed "s|^|$dir: |"
        else
            failed=$((failed + 1))
            echo "FAIL $driver on $corpus; the input it stopped at and the report:"
            grep -E '^replay: ' "$log" | tail -n 1
            grep -vE '^replay: ' "$log" | tail -n 20
        fi
        rm -f "$log"
    done
done
fuzz_build=${TK_FUZZ_BUILD:-$root/build/libfuzzer}
for corpus in "$root"/tests/fuzz/corpus/*/; do
    t=$(basename "$corpus")
    if [ ! -x "$fuzz_build/fuzz/fuzz_$t" ]; then
        echo "SKIP fuzz_$t: no libFuzzer build in $fuzz_build (make FUZZ=1 fuzz-bin)"
        skipped=$((skipped + 1))
        continue
    fi
    if "$root/tests/fuzz/fuzz.sh" "$fuzz_build" "${TK_FUZZ_SECONDS:-10}" "$t"; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
    fi
done
echo "fuzz: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
