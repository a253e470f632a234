#!/bin/sh
# bench/service.sh: how the service answers while every worker is busy.
#
# Starts tightknotd on a free loopback port with a fresh store, submits one
# long catalogue job per worker, and then alternates windows of WINDOW
# seconds: engine alone, engine while wrk polls GET /v1/jobs/{id} with 50
# connections, engine alone, with 200 connections, engine alone.  Prints
# wrk's requests/s and p50/p99 latency and the engine's steps/s in each
# window (from /metrics), so the cost of the load on the engine shows next
# to the unloaded windows around it; then the same with paced polling (200
# clients at 1 and at 10 polls a second each, bench/poll.mjs).  Never fails
# on time.
#
# usage: bench/service.sh [BUILD_DIR] [CATALOGUE_DIR]   (WINDOW=10 by default)
set -eu
build=${1:-build}
catalogue=${2:-../shared/catalogue}
window=${WINDOW:-10}
knot=${KNOT:-10.1}
command -v wrk >/dev/null || { echo "bench/service: wrk is not installed (make deps)"; exit 1; }
dir=$(mktemp -d)
: >"$dir/log"
"$build/tightknotd" --port 0 --db "$dir/bench.db" --catalogue "$catalogue" >"$dir/log" 2>&1 &
pid=$!
# the traps are set once the daemon runs, so that it never sees them
stop_daemon() {
    kill "$pid" 2>/dev/null || return 0
    for _ in $(seq 100); do
        kill -0 "$pid" 2>/dev/null || return 0
        sleep 0.1
    done
    echo "bench/service: the daemon did not stop within 10 s of SIGTERM; killing it"
    kill -9 "$pid" 2>/dev/null
}
trap 'stop_daemon; rm -rf "$dir"' EXIT
trap 'exit 1' INT TERM
port=""
for _ in $(seq 50); do
    port=$(sed -n 's|.*http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$dir/log" || true)
    [ -n "$port" ] && break
    sleep 0.1
done
[ -n "$port" ] || { echo "bench/service: the daemon did not start:"; cat "$dir/log"; exit 1; }
url="http://127.0.0.1:$port"
workers=$(curl -sf "$url/v1/health" | sed 's/.*"workers":\([0-9]*\).*/\1/')
long=$((8 * window + 60))
ids=""
for _ in $(seq "$workers"); do
    id=$(curl -sf -X POST -H 'Content-Type: application/json' \
        -d "{\"catalogue\": \"$knot\", \"options\": {\"resolution\": 5, \"time\": $long}}" \
        "$url/v1/jobs" | sed 's/^{"id":\([0-9]*\),.*/\1/')
    ids="$ids $id"
done
first=$(echo "$ids" | awk '{print $1}')
sleep 2
steps() { curl -sf "$url/metrics" | awk '/^tightknot_steps_total/ {print $2}'; }
now() { date +%s.%N; }
rate() { echo "$1 $2 $3 $4" | awk '{printf "%.1f", ($2 - $1) / ($4 - $3)}'; }

echo "tightknotd: $workers workers busy on catalogue $knot (resolution 5); windows of $window s"
printf '%-22s %12s %10s %10s %14s\n' "load" "requests/s" "p50" "p99" "engine steps/s"
quiet() {
    s0=$(steps); t0=$(now); sleep "$window"; s1=$(steps); t1=$(now)
    printf '%-22s %12s %10s %10s %14s\n' "none" "-" "-" "-" "$(rate "$s0" "$s1" "$t0" "$t1")"
}
loaded() {
    s0=$(steps); t0=$(now)
    wrk -t2 -c"$1" -d"${window}s" --latency "$url/v1/jobs/$first" >"$dir/wrk" 2>&1 || true
    s1=$(steps); t1=$(now)
    rps=$(awk '/^Requests\/sec/ {print $2}' "$dir/wrk")
    p50=$(awk '$1 == "50%" {print $2}' "$dir/wrk")
    p99=$(awk '$1 == "99%" {print $2}' "$dir/wrk")
    printf '%-22s %12s %10s %10s %14s\n' "GET job, $1 conns" "$rps" "$p50" "$p99" \
        "$(rate "$s0" "$s1" "$t0" "$t1")"
}
# Paced polling (bench/poll.mjs): CLIENTS clients, each one GET every
# PERIOD ms whatever the answers take, as watching pages and scripts do.
paced() {
    s0=$(steps); t0=$(now)
    out=$(node bench/poll.mjs "$url/v1/jobs/$first" "$1" "$2" "$window")
    s1=$(steps); t1=$(now)
    set -- "$1" "$2" $out
    printf '%-22s %12s %10s %10s %14s\n' "$1 x $((1000 / $2))/s paced" "$3" "$4" "$5" \
        "$(rate "$s0" "$s1" "$t0" "$t1")"
    [ "$7" = 0 ] || echo "  ($7 requests failed)"
}
quiet
loaded 50
quiet
loaded 200
quiet
if command -v node >/dev/null; then
    paced 200 1000
    quiet
    paced 200 100
    quiet
fi
peak=$(awk '/VmHWM/ {print $2, $3}' "/proc/$pid/status")
echo "daemon peak memory: $peak"
for id in $ids; do curl -sf -X DELETE "$url/v1/jobs/$id" >/dev/null || true; done
