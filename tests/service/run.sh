#!/bin/sh
# The service's integration tests: lint openapi.yaml, then run
# tests/service/*.test.mjs (node:test) against the real daemon and CLI.
#   TK_DAEMON=build/tightknotd TK_CLI=build/tightknot \
#   TK_CATALOGUE=../shared/catalogue sh tests/service/run.sh
# Installs the node modules first when node_modules is missing or older
# than package-lock.json.  Ends with "service: N passed, M failed, K
# skipped" (the lint counts as one test); the exit status is non-zero on
# any failure.
set -u

# paths from the environment are relative to the caller's directory
absolute() {
    case $1 in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac
}
root=$(cd "$(dirname "$0")/../.." && pwd)
TK_DAEMON=$(absolute "${TK_DAEMON:-$root/build/tightknotd}")
TK_CLI=$(absolute "${TK_CLI:-$root/build/tightknot}")
TK_CATALOGUE=$(absolute "${TK_CATALOGUE:-$root/../shared/catalogue}")
export TK_DAEMON TK_CLI TK_CATALOGUE
# the linter neither phones home nor looks for updates
REDOCLY_TELEMETRY=off
REDOCLY_SUPPRESS_UPDATE_NOTICE=true
export REDOCLY_TELEMETRY REDOCLY_SUPPRESS_UPDATE_NOTICE
cd "$root" || exit 1

fail_setup() {
    echo "FAIL $1"
    echo "service: 0 passed, 1 failed"
    exit 1
}

for f in "$TK_DAEMON" "$TK_CLI"; do
    [ -x "$f" ] || fail_setup "$f is missing: build it with make"
done
[ -d "$TK_CATALOGUE" ] || fail_setup "the catalogue $TK_CATALOGUE is missing (set TK_CATALOGUE)"
command -v node >/dev/null 2>&1 || fail_setup "node is not installed (the tests need node 20 or later)"

# npm writes node_modules/.package-lock.json on every install
stamp=node_modules/.package-lock.json
if [ ! -f "$stamp" ] || [ package-lock.json -nt "$stamp" ]; then
    echo "service: installing node modules (npm ci)"
    npm ci --no-audit --no-fund || fail_setup "npm ci failed"
    touch "$stamp"
fi

start=$(date +%s)
lint_passed=0
lint_failed=0
echo "service: npx redocly lint openapi.yaml"
if npx --no-install redocly lint openapi.yaml; then
    lint_passed=1
else
    lint_failed=1
    echo "FAIL redocly lint openapi.yaml"
fi

summary=$(mktemp)
races=$(mktemp -d)
trap 'rm -rf "$summary" "$races"' EXIT
# Under ThreadSanitizer (a daemon built with SANITIZE=thread) every report
# is written to $races and counted as a failure below.
TSAN_OPTIONS="log_path=$races/tsan ${TSAN_OPTIONS:-}"
export TSAN_OPTIONS
# TK_SERVICE_TESTS: the test files to run (default: all of them)
# shellcheck disable=SC2086
node --test \
    --test-reporter=spec --test-reporter-destination=stdout \
    --test-reporter=./tests/service/summary-reporter.mjs --test-reporter-destination="$summary" \
    ${TK_SERVICE_TESTS:-tests/service/*.test.mjs}
status=$?

line=$(grep -E '^service: [0-9]+ passed, [0-9]+ failed, [0-9]+ skipped$' "$summary" | tail -n 1)
skipped=0
if [ -z "$line" ]; then
    passed=0
    failed=1
    echo "FAIL node --test gave no summary (exit status $status)"
else
    passed=$(echo "$line" | sed -E 's/^service: ([0-9]+) passed.*/\1/')
    failed=$(echo "$line" | sed -E 's/.* ([0-9]+) failed, .*/\1/')
    skipped=$(echo "$line" | sed -E 's/.* ([0-9]+) skipped$/\1/')
    grep -E '^(FAIL|SKIP) ' "$summary"
fi
if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then
    failed=1
    echo "FAIL node --test exited with status $status"
fi
passed=$((passed + lint_passed))
failed=$((failed + lint_failed))
for report in "$races"/tsan*; do
    [ -f "$report" ] || continue
    failed=$((failed + 1))
    echo "FAIL ThreadSanitizer: $(grep -m 1 '^WARNING' "$report")"
    sed -n '1,60p' "$report"
done
echo "service: took $(( $(date +%s) - start )) s"
echo "service: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
