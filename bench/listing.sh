#!/bin/sh
# bench/listing.sh: what a tokened listing costs when the store holds many
# jobs of other names.
#
# Starts DAEMON with --tokens on a fresh SQLite store, lets 'other' submit
# one short catalogue job and 'me' two, stops it, copies other's job
# JOBS times in the file (sqlite3), starts DAEMON again on that file and
# times ROUNDS listings GET /v1/jobs as 'me' and ROUNDS submissions POST
# /v1/jobs as 'me' (curl, one after another; the one worker busy with a
# long job of other's, so they stay queued).  Prints the mean and the
# median milliseconds of each.  Never fails on time.
#
# usage: bench/listing.sh DAEMON [CATALOGUE_DIR]
#   (environment: JOBS=10000, ROUNDS=50)
set -eu
daemon=$1
catalogue=${2:-../shared/catalogue}
jobs=${JOBS:-10000}
rounds=${ROUNDS:-50}
command -v sqlite3 >/dev/null || { echo "bench/listing: sqlite3 is not installed"; exit 1; }
dir=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$dir"' EXIT
me=me-token-0123456789abcdef
other=other-token-0123456789abcdef
printf 'me %s\nother %s\n' "$me" "$other" >"$dir/tokens"

start() {
    "$daemon" --port 0 --db "$dir/jobs.db" --tokens "$dir/tokens" --catalogue "$catalogue" \
        --workers 1 --queue-limit 1000000 --jobs-per-name 0 >"$dir/log" 2>&1 &
    pid=$!
    for _ in $(seq 100); do
        url=$(sed -n 's|^tightknotd: [^ ]* listening on \(http://[^/]*/\).*|\1|p' "$dir/log")
        [ -n "$url" ] && return
        sleep 0.1
    done
    echo "bench/listing: the daemon did not start"; cat "$dir/log"; exit 1
}
stop() { kill "$pid"; wait "$pid" 2>/dev/null || true; pid=; }
post() { # token, body
    curl -s -o /dev/null -w '%{http_code}' -H "Authorization: Bearer $1" \
        -H 'Content-Type: application/json' -d "$2" "${url}v1/jobs"
}

start
post "$other" '{"catalogue": "3.1", "options": {"steps": 2}}' >/dev/null
post "$me" '{"catalogue": "3.1", "options": {"steps": 2}}' >/dev/null
post "$me" '{"catalogue": "3.1", "options": {"steps": 2}}' >/dev/null
sleep 3
stop
sqlite3 "$dir/jobs.db" "WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM n
    WHERE i < $jobs) INSERT INTO jobs (state, doc, input, curve, contacts, history, resume)
    SELECT j.state, j.doc, j.input, j.curve, j.contacts, j.history, j.resume FROM n,
    (SELECT * FROM jobs WHERE doc LIKE '%\"owner\":\"other\"%' LIMIT 1) AS j;"
echo "bench/listing: $(sqlite3 "$dir/jobs.db" 'SELECT count(*) FROM jobs') jobs stored, 2 of them me's"
start
# a long job keeps the one worker busy: the POSTs below stay queued
post "$other" '{"catalogue": "3.1", "options": {"steps": 100000000}}' >/dev/null

# times N requests made by the command given; prints mean and median ms
timed() {
    what=$1; shift
    : >"$dir/times"
    for _ in $(seq "$rounds"); do
        "$@" >>"$dir/times"
        echo >>"$dir/times"
    done
    sort -n "$dir/times" | awk -v what="$what" '{ t[NR] = $1 * 1000; s += t[NR] }
        END { printf "bench/listing: %s: mean %.2f ms, median %.2f ms over %d\n",
              what, s / NR, t[int((NR + 1) / 2)], NR }'
}
list() { curl -s -o /dev/null -w '%{time_total}' -H "Authorization: Bearer $me" "${url}v1/jobs"; }
submit() {
    curl -s -o /dev/null -w '%{time_total}' -H "Authorization: Bearer $me" \
        -H 'Content-Type: application/json' -d '{"catalogue": "3.1"}' "${url}v1/jobs"
}
timed "GET /v1/jobs as 'me'" list
timed "POST /v1/jobs as 'me'" submit
stop
