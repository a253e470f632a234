#!/bin/sh
# Runs the page's browser tests: builds the page into $TK_WEB (default
# build/web), then tests/web/page.test.mjs against the real daemon in
# headless Chromium.  The last line is "web: N passed, M failed".
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 1
web=${TK_WEB:-build/web}
daemon=${TK_DAEMON:-build/tightknotd}

fail() {
    echo "web: $*" >&2
    echo "web: 0 passed, 1 failed"
    exit 1
}
[ -x "$daemon" ] || fail "no daemon at $daemon (run make first)"
[ -x "${TK_CHROMIUM:-/usr/bin/chromium}" ] || fail "no Chromium at ${TK_CHROMIUM:-/usr/bin/chromium} (run tools/install-deps.sh as root)"
[ -d node_modules/playwright-core ] || fail "node_modules/playwright-core is missing (run npm install)"
sh tools/build-web.sh "$web" || fail "tools/build-web.sh failed"

tap=$(mktemp)
trap 'rm -f "$tap"' EXIT INT TERM
TK_WEB=$web node --test --test-concurrency=1 \
    --test-reporter=spec --test-reporter-destination=stdout \
    --test-reporter=tap --test-reporter-destination="$tap" \
    tests/web/page.test.mjs
status=$?
pass=$(sed -n 's/^# pass \([0-9]*\)$/\1/p' "$tap" | tail -1)
failed=$(sed -n 's/^# fail \([0-9]*\)$/\1/p' "$tap" | tail -1)
pass=${pass:-0}
failed=${failed:-0}
# a crash before any test reports still counts as a failure
if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then failed=1; fi
echo "web: $pass passed, $failed failed"
[ "$status" -eq 0 ] && [ "$failed" -eq 0 ]
