#!/bin/sh
# Runs each libFuzzer target for SECONDS, from its seed corpus, and prints
# a line of figures per target (runs, runs per second, edges and features
# covered, corpus size).  Exit status 1 when any target found a crash, a
# leak or a timeout (its input is then in BUILD/artifacts; add it to
# tests/fuzz/corpus/TARGET once fixed, so that `make test` replays it).
#   tests/fuzz/fuzz.sh BUILD SECONDS TARGET...
# FUZZ_FROM=empty starts each target from nothing (a new, empty corpus,
# the seeds left out): what the fuzzer finds on its own, not only near
# the seeds.  Otherwise it starts from the seeds and what earlier runs
# kept in BUILD/corpus.
set -u
build=$1
seconds=$2
shift 2
root=$(cd "$(dirname "$0")/../.." && pwd)
status=0
mkdir -p "$build/artifacts"
from=${FUZZ_FROM:-seeds}
for t in "$@"; do
    work="$build/corpus/$t"
    seeds="$root/tests/fuzz/corpus/$t"
    if [ "$from" = empty ]; then
        work="$build/corpus-empty/$t"
        rm -rf "$work"
        seeds=""
    fi
    mkdir -p "$work"
    log="$build/fuzz_$t.$from.log"
    # -timeout: an input taking over 10 s is a hang; -rss_limit_mb: the
    # 2 GiB the service is sized for; -max_len: tiny curves and requests.
    "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
        -max_len=4096 -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-" \
        "$work" $seeds >"$log" 2>&1
    rc=$?
    runs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+)/\1/p' "$log" | tail -n 1)
    rate=$(sed -nE 's/^stat::average_exec_per_sec: *([0-9]+)/\1/p' "$log" | tail -n 1)
    cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+ corp: [0-9]+' "$log" | tail -n 1)
    if [ "$rc" -eq 0 ]; then
        echo "fuzz $t (from $from): ${seconds} s, ${runs:-?} runs (${rate:-?}/s), $cov: no crash, leak or timeout"
    else
        status=1
        echo "fuzz $t: FAILED (exit $rc) after ${runs:-?} runs; see $log and $build/artifacts/$t-*"
        grep -E '^(==[0-9]+==ERROR|SUMMARY|.*check failed|.*Test unit written)' "$log" | head -n 5
    fi
done
exit $status
