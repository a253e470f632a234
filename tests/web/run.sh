#!/bin/sh
# Runs the page's browser tests: builds the page into $TK_WEB (default
# build/web), then tests/web/page.test.mjs in headless Chromium and
# tests/web/firefox.test.mjs in headless Firefox, each against the real
# daemon.  The last line is "web: N passed, M failed", for both files; a
# Firefox file that cannot run (no firefox-esr, no Xvfb) counts as one
# failure, and the Chromium tests still run.
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

files="tests/web/page.test.mjs tests/web/boundary.test.mjs"
skipped=0
skip_firefox() {
    echo "FAIL tests/web/firefox.test.mjs not run: $*" >&2
    skipped=1
}
if [ ! -x "${TK_FIREFOX:-/usr/bin/firefox-esr}" ]; then
    skip_firefox "firefox-esr not installed at ${TK_FIREFOX:-/usr/bin/firefox-esr} (run tools/install-deps.sh as root)"
elif [ ! -x "${TK_XVFB:-/usr/bin/Xvfb}" ]; then
    skip_firefox "xvfb not installed: no ${TK_XVFB:-/usr/bin/Xvfb} (run tools/install-deps.sh as root)"
elif [ ! -d node_modules/puppeteer-core ]; then
    skip_firefox "node_modules/puppeteer-core is missing (run npm install)"
else
    files="$files tests/web/firefox.test.mjs"
fi

tap=$(mktemp)
trap 'rm -f "$tap"' EXIT INT TERM
# shellcheck disable=SC2086
TK_WEB=$web node --test --test-concurrency=1 \
    --test-reporter=spec --test-reporter-destination=stdout \
    --test-reporter=tap --test-reporter-destination="$tap" \
    $files
status=$?
pass=$(sed -n 's/^# pass \([0-9]*\)$/\1/p' "$tap" | tail -1)
failed=$(sed -n 's/^# fail \([0-9]*\)$/\1/p' "$tap" | tail -1)
pass=${pass:-0}
failed=${failed:-0}
# a crash before any test reports still counts as a failure
if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then failed=1; fi
failed=$((failed + skipped))
echo "web: $pass passed, $failed failed"
[ "$status" -eq 0 ] && [ "$failed" -eq 0 ]
