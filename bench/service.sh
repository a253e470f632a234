#!/bin/sh
# bench/service.sh: how the service answers while every worker is busy.
#
# Starts tightknotd on a free loopback port with a fresh store, times the
# submission of a 200,000-vertex VECT (POST does bounded work: the text,
# its limits, the options), submits one long catalogue job per worker (a
# frame every step, so the workers write frames at every save), and then
# alternates windows of WINDOW
# seconds: engine alone, engine while wrk polls GET /v1/jobs/{id}, engine
# alone, ...  wrk runs twice per connection count: flat out (each
# connection asks again as soon as it has its answer: saturation) and
# paced (bench/paced.lua: each connection waits 100 ms, or 1 s, between
# polls, as a watching page or script does).  Prints wrk's requests/s and p50/p99
# latency and, for the engine, its steps/s (from /metrics) and the CPU its
# worker threads got (cores, from /proc: the steps' cost drifts as the knot
# tightens, the CPU share does not), with the share of the mean of the
# unloaded windows on either side.  Never fails on time.
#
# usage: bench/service.sh [BUILD_DIR] [CATALOGUE_DIR]
#   (environment: WINDOW=10 seconds, KNOT=10.1, PRIORITY=idle, the
#   daemon's --worker-priority)
set -eu
build=${1:-build}
catalogue=${2:-../shared/catalogue}
window=${WINDOW:-10}
knot=${KNOT:-10.1}
priority=${PRIORITY:-idle}
command -v wrk >/dev/null || { echo "bench/service: wrk is not installed (make deps)"; exit 1; }
dir=$(mktemp -d)
: >"$dir/log"
"$build/tightknotd" --port 0 --db "$dir/bench.db" --catalogue "$catalogue" \
    --worker-priority "$priority" --max-per-address 1000 >"$dir/log" 2>&1 &
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
long=$((12 * window + 60))
ids=""
for _ in $(seq "$workers"); do
    id=$(curl -sf -X POST -H 'Content-Type: application/json' \
        -d "{\"catalogue\": \"$knot\", \"options\": {\"resolution\": 5, \"time\": $long, \"every\": 1}}" \
        "$url/v1/jobs" | sed -n 's/.*"id":\([0-9]*\).*/\1/p')
    ids="$ids $id"
done
first=$(echo "$ids" | awk '{print $1}')
# a large submission, timed by curl; cancelled before a worker is free for it
"$build/tightknot" generate torus 2 3 --vertices 200000 >"$dir/large.vect"
large=$(curl -sf -o "$dir/large.json" -w '%{time_total} %{http_code} %{size_upload}' -X POST \
    -H 'Content-Type: text/plain' --data-binary @"$dir/large.vect" "$url/v1/jobs?steps=1")
large_id=$(sed -n 's/.*"id":\([0-9]*\).*/\1/p' "$dir/large.json")
curl -sf -X DELETE "$url/v1/jobs/$large_id" >/dev/null || true
echo "$large" | awk '{printf "POST /v1/jobs with 200000 vertices (%.1f MB): %s in %.3f s\n", $3 / 1e6, $2, $1}'
sleep 2
steps() { curl -sf "$url/metrics" | awk '/^tightknot_steps_total/ {print $2}'; }
# CPU ticks of the worker threads (named tk-worker) and of the daemon's
# other threads (answering requests): utime + stime, fields 14 and 15 of
# /proc/PID/task/TID/stat, counted here after the ") " that ends the name.
ticks() {
    for stat in /proc/"$pid"/task/*/stat; do
        cat "$stat" 2>/dev/null || true
    done | awk '{ rest = substr($0, index($0, ") ") + 2); split(rest, f, " ")
                  if (index($0, "(tk-worker)")) engine += f[12] + f[13]
                  else http += f[12] + f[13] }
                END {print engine + 0, http + 0}'
}
hz=$(getconf CLK_TCK)
now() { date +%s.%N; }
rate() { echo "$1 $2 $3 $4" | awk '{printf "%.1f", ($2 - $1) / ($4 - $3)}'; }

echo "tightknotd: $workers workers ($priority priority) busy on catalogue $knot" \
    "(resolution 5); windows of $window s"
printf '%-24s %11s %9s %9s %9s %18s %10s\n' "load" "requests/s" "p50" "p99" "steps/s" \
    "engine cores" "http cores"
last_cores=""
pending=""
# A loaded window's engine share is printed against the mean of the
# unloaded windows before and after it, so it waits for the next one.
window_figures() {
    s0=$(steps); k0=$(ticks); t0=$(now)
    "$@"
    s1=$(steps); k1=$(ticks); t1=$(now)
    step_rate=$(rate "$s0" "$s1" "$t0" "$t1")
    cores=$(echo "$k0 $k1 $t0 $t1 $hz" | awk '{printf "%.3f", ($3 - $1) / $7 / ($6 - $5)}')
    http_cores=$(echo "$k0 $k1 $t0 $t1 $hz" | awk '{printf "%.3f", ($4 - $2) / $7 / ($6 - $5)}')
}
quiet() {
    window_figures sleep "$window"
    if [ -n "$pending" ]; then
        share=$(echo "$pending_cores $last_cores $cores" |
            awk '{printf "%.1f%%", 100 * $1 / (($2 + $3) / 2)}')
        # shellcheck disable=SC2086 # the loaded window's figures, one word each
        printf '%-24s %11s %9s %9s %9s %18s %10s\n' $pending "$pending_cores ($share)" \
            "$pending_http"
        pending=""
    fi
    printf '%-24s %11s %9s %9s %9s %18s %10s\n' "none" "-" "-" "-" "$step_rate" "$cores" \
        "$http_cores"
    last_cores=$cores
}
loaded() {
    conns=$1
    period=$2
    if [ "$period" = 0 ]; then
        label="wrk-$conns-flat-out"
        window_figures wrk -t2 -c"$conns" -d"${window}s" --latency "$url/v1/jobs/$first" \
            >"$dir/wrk" 2>&1 || true
    else
        label="wrk-$conns-every-${period}ms"
        window_figures wrk -t2 -c"$conns" -d"${window}s" --latency -s bench/paced.lua \
            "$url/v1/jobs/$first" -- "$period" >"$dir/wrk" 2>&1 || true
    fi
    rps=$(awk '/^Requests\/sec/ {print $2}' "$dir/wrk")
    p50=$(awk '$1 == "50%" {print $2}' "$dir/wrk")
    p99=$(awk '$1 == "99%" {print $2}' "$dir/wrk")
    pending="$label $rps $p50 $p99 $step_rate"
    pending_cores=$cores
    pending_http=$http_cores
}
quiet
for load in "50 0" "200 0" "50 100" "200 100" "200 1000"; do
    # shellcheck disable=SC2086 # two words: connections and period
    loaded $load
    quiet
done
peak=$(awk '/VmHWM/ {print $2, $3}' "/proc/$pid/status")
echo "daemon peak memory: $peak"
for id in $ids; do curl -sf -X DELETE "$url/v1/jobs/$id" >/dev/null || true; done
