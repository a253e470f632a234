#!/bin/sh
# Runs every test and closes with one line: "tests: N passed, M failed,
# K skipped" (suites that report skips say so; a skip is never a pass).
# Each test program's or suite's line ends with its seconds.
#   run-all.sh [--unit-only] BUILD_DIR SANITIZER_BUILD_DIR CATALOGUE_DIR
# Unit tests (Check, one process per test) run from both build directories;
# the command-line, service and page tests run against BUILD_DIR's programs.
set -u
unit_only=0
if [ "${1:-}" = "--unit-only" ]; then unit_only=1; shift; fi
build=$1
asan=${2:-}
tsan=build/tsan
TK_CATALOGUE=$3
export TK_CATALOGUE
if [ ! -d "$TK_CATALOGUE" ]; then
    echo "note: catalogue $TK_CATALOGUE is absent; tests that need it are skipped"
fi

passed=0
failed=0
skipped=0
log=$(mktemp)
lanes=$(mktemp -d)
# A PostgreSQL server of the tests' own (tests/pg.sh, in a directory the
# postgres user can reach): the store's tests on PostgreSQL, the service's
# suite on it, and several daemons sharing one database.
pgdir=$(mktemp -d /tmp/tk-pg-XXXXXX)
chmod 755 "$pgdir"
trap 'rm -rf "$log" "$lanes"; ./tests/pg.sh stop "$pgdir/server" 2>/dev/null; rm -rf "$pgdir"' EXIT
TK_PG_URL=$(./tests/pg.sh start "$pgdir/server" 2>"$log")
case $? in
0) echo "postgresql: a server of the tests' own at $TK_PG_URL" ;;
3) TK_PG_URL=""; skipped=$((skipped + 1)); echo "SKIP postgresql: $(cat "$log")" ;;
*) TK_PG_URL=""; failed=$((failed + 1)); echo "FAIL postgresql: the tests' server did not start"; cat "$log" ;;
esac
export TK_PG_URL

# One unit test program, $1, its output to $2: its line (and any failure
# or skip), then "counts: PASSED FAILED SKIPPED".  Check's summary line:
# "100%: Checks: 7, Failures: 0, Errors: 0".
# A program named PROGRAM@TAG runs only its test cases tagged TAG, and
# PROGRAM@-TAG all the others (Check's CK_INCLUDE_TAGS, CK_EXCLUDE_TAGS):
# one long program in two processes, one a lane.
run_unit() {
    quick=1
    case "$1" in "$build"/tests/*) quick=0 ;; esac
    program=${1%@*} tags=""
    case "$1" in
    *@-*) tags="CK_EXCLUDE_TAGS=${1##*@-}" ;;
    *@*) tags="CK_INCLUDE_TAGS=${1##*@}" ;;
    esac
    t0=$(date +%s)
    # shellcheck disable=SC2086
    env TK_QUICK=$quick $tags "$program" >"$2" 2>&1
    line=$(grep -E '^[0-9]+%: Checks: ' "$2" | tail -n 1)
    if [ -z "$line" ]; then
        echo "FAIL $1: no summary (crashed?)"
        tail -n 20 "$2"
        echo "counts: 0 1 0"
        return
    fi
    checks=$(echo "$line" | sed -E 's/.*Checks: ([0-9]+).*/\1/')
    bad=$(echo "$line" | sed -E 's/.*Failures: ([0-9]+), Errors: ([0-9]+).*/\1 \2/' | awk '{print $1 + $2}')
    # a test that skipped says so (tkt_skip); Check counted it as passed
    skips=$(grep -c '^SKIP ' "$2")
    echo "$1: $line, $skips skipped ($(($(date +%s) - t0)) s)"
    grep -E '^SKIP ' "$2"
    [ "$bad" -eq 0 ] || grep -E ':[EF]:' "$2"
    echo "counts: $((checks - bad - skips)) $bad $skips"
}

# Runs $2 (run_idle or run_suite) on each of the list $1 in two lanes, one
# a core: each lane takes the next not yet taken (mkdir is the lock), so
# a list ordered longest first has its lanes end together.  Each one's
# output goes to a file of its own in the lanes' directory $3;
# lanes_report prints them in the list's order and adds their counts to
# the totals.
lanes_run() {
    lanedir=$lanes/$3
    mkdir "$lanedir"
    for _ in 1 2; do
        (
            i=0
            for t in $1; do
                i=$((i + 1))
                mkdir "$lanedir/taken.$i" 2>/dev/null || continue
                $2 "$t" "$lanedir/log.$i" >"$lanedir/out.$i"
            done
        ) &
    done
    wait
}

lanes_report() {
    i=0
    for t in $1; do
        i=$((i + 1))
        out="$lanes/$2/out.$i"
        counts=$(grep '^counts: ' "$out" 2>/dev/null | tail -n 1)
        if [ -z "$counts" ]; then
            failed=$((failed + 1)); echo "FAIL $t: no totals"; continue
        fi
        grep -v '^counts: ' "$out"
        passed=$((passed + $(echo "$counts" | cut -d ' ' -f 2)))
        failed=$((failed + $(echo "$counts" | cut -d ' ' -f 3)))
        skipped=$((skipped + $(echo "$counts" | cut -d ' ' -f 4)))
    done
}

# The sanitizer build runs every test, but the long tightening runs in
# their short form (TK_QUICK): they are the same code paths, ten times
# slower under the sanitizers.
# The unit test programs of both builds run in two lanes (none of them
# times itself, and their PostgreSQL databases are named by process), the
# longest first.
units=""
for dir in "$build" $asan; do
    [ -d "$dir/tests" ] || continue
    for t in "$dir"/tests/test_*; do
        case "$t" in *.o|*.d) continue ;; esac
        [ -x "$t" ] && units="$units $t"
    done
done
# test_tighten's three longest tests (tagged "long") run apart from
# the rest: the program alone is 540 s on an idle core
long='/test_(starts|tighten|struts|nnls|history)(@.*)?$'
units=$(printf '%s\n' $units | sed -E 's#^(.*/test_tighten)$#\1@long\n\1@-long#')
units="$(for name in tighten@long starts tighten@-long struts nnls history; do
    echo "$units" | grep -E "/test_$name\$"; done)
$(echo "$units" | grep -vE "$long")"

# The command-line tests (tests/cli-*.sh) and the suites in directories
# (tests/*/run.sh: the service's API, the page in a browser, the fuzz
# corpora replayed in both builds) all end with
# "NAME: N passed, M failed".
# The service's suite runs a second time against the address sanitizer
# build's daemon and command line, and a third against the thread
# sanitizer's.
#
# They run in two lanes too, the longest first, each suite in its own
# temporary directories, on its own free ports and (on PostgreSQL) in
# databases named by process, so two never share anything.
run_suite() {
    t=$1
    log=$2
    dir=$build
    store=sqlite
    # every file but those of the PostgreSQL pass alone
    only=$(ls tests/service/*.test.mjs | grep -v -e cluster | tr '\n' ' ')
    case "$t" in
    pg:*)
        t=${t#pg:}; store=postgresql
        only=$(ls tests/service/*.test.mjs | grep -e cluster -e queue -e restart -e results \
            -e tokens -e workers | tr '\n' ' ')
        ;;
    asan:*)
        # all but chaos: its kill -9 paths (the store reopened, the
        # jobs requeued and resumed) run here in restart.test.mjs,
        # and chaos repeats them ten times
        dir=$asan; t=${t#asan:}
        only=$(ls tests/service/*.test.mjs | grep -v -e chaos -e cluster | tr '\n' ' ')
        ;;
    tsan:*)
        dir=$tsan; t=${t#tsan:}
        only=$(ls tests/service/*.test.mjs | grep -v -e chaos -e store -e cluster | tr '\n' ' ')
        ;;
    esac
    if [ ! -f "$t" ]; then echo "counts: 0 0 0"; return; fi
    t0=$(date +%s)
    TK_BUILD=$dir TK_ASAN_BUILD=$asan TK_DAEMON=$dir/tightknotd TK_CLI=$dir/tightknot \
        TK_WEB=$dir/web TK_SERVICE_TESTS=$only TK_STORE=$store sh "$t" >"$log" 2>&1
    line=$(grep -E '^[a-z-]+: [0-9]+ passed, [0-9]+ failed' "$log" | tail -n 1)
    if [ -z "$line" ]; then
        echo "FAIL $t: no summary"; tail -n 20 "$log"
        echo "counts: 0 1 0"
        return
    fi
    p=$(echo "$line" | sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\1/')
    f=$(echo "$line" | sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\2/')
    k=$(echo "$line" | sed -nE 's/.* ([0-9]+) skipped.*/\1/p')
    echo "$t ($dir, $store): $line ($(($(date +%s) - t0)) s)"
    grep -E '^SKIP ' "$log"
    [ "$f" -eq 0 ] || grep -E '^FAIL|^not ok|^# fail|Error' "$log" | head -n 40
    # a ThreadSanitizer report: where the two accesses were
    [ "$f" -eq 0 ] || grep -E '^  (Write|Read|Previous|Atomic|Location|Thread T)|^    #[0-9] ' "$log" |
        head -n 60
    echo "counts: $p $f ${k:-0}"
}

# A unit test program, or a suite given as suite:PATH (the fuzz corpora's
# replays, as CPU-bound as a unit test), with its output to $2.
run_idle() {
    case "$1" in
    suite:*) run_suite "${1#suite:}" "$2" ;;
    *) run_unit "$1" "$2" ;;
    esac
}

# The unit tests and the fuzz corpora's replays (after the long units) run
# at the lowest niceness, beside the suites below: a suite mostly waits on
# its daemon's jobs (the service's took 321 s for about 63 s of processor
# time), so the units take what the suites leave, and the suites, their
# daemons' workers at normal priority (TK_WORKER_PRIORITY), run about as
# on an idle machine.  Check's timeouts are of the wall clock: three
# times theirs, for a unit test that waits on a busy suite.
if [ "$unit_only" -eq 0 ] && [ -f tests/fuzz/run.sh ]; then
    units="$(echo "$units" | grep -E "$long")
suite:tests/fuzz/run.sh
$(echo "$units" | grep -vE "$long")"
fi
CK_TIMEOUT_MULTIPLIER=3
export CK_TIMEOUT_MULTIPLIER
(
    renice -n 19 -p "$(exec sh -c 'echo $PPID')" >/dev/null
    lanes_run "$units" run_idle units
) &
idle=$!

if [ "$unit_only" -eq 0 ]; then
    # the longest first: the service's suite, in each build and store
    suites="tests/service/run.sh"
    [ -n "$asan" ] && [ -x "$asan/tightknotd" ] && suites="$suites asan:tests/service/run.sh"
    suites="$suites tests/web/run.sh"
    # against the thread sanitizer's daemon, every file but the two
    # slowest (kill -9 ten times, a file system filling up: no thread
    # interplay the others lack)
    [ -x "$tsan/tightknotd" ] && suites="$suites tsan:tests/service/run.sh"
    # the service's suite once more with every daemon's store on
    # PostgreSQL: the files whose jobs are stored, restarted and shared
    # (the others poke the SQLite file or never store a job)
    [ -n "$TK_PG_URL" ] && suites="$suites pg:tests/service/run.sh"
    # the fuzz targets' replays run with the units, above
    for t in tests/cli-*.sh tests/*/run.sh; do
        case " $suites " in *" $t "*) ;; *) [ "$t" = tests/fuzz/run.sh ] || suites="$suites $t" ;; esac
    done
    TK_WORKER_PRIORITY=normal
    export TK_WORKER_PRIORITY
    lanes_run "$suites" run_suite suites
fi
wait "$idle"
lanes_report "$units" units
[ "$unit_only" -eq 0 ] && lanes_report "$suites" suites

echo "tests: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
