#!/bin/sh
# Replays every fuzz target's corpus (tests/fuzz/corpus/TARGET) through its
# replay driver, in the normal build and in the sanitizer build when it is
# there, so that every crash a fuzzer once found stays fixed.  One test per
# target and build; ends with "fuzz: N passed, M failed".
#   TK_BUILD=build TK_ASAN_BUILD=build/asan sh tests/fuzz/run.sh
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${TK_BUILD:-build}
asan=${TK_ASAN_BUILD:-}
passed=0
failed=0
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
echo "fuzz: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
