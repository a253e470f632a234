#!/bin/sh
# The benches' own logic that can be checked against known answers
# (bench/extrapolate.mjs's fit, and a short run of it); the last line is
# "bench: N passed, M failed, K skipped".
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 1
TK_SUMMARY_NAME=bench node --test --test-reporter="$root/tests/service/summary-reporter.mjs" \
    tests/bench/*.test.mjs
