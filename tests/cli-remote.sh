#!/bin/sh
# Tests of `tightknot remote` against a live tightknotd on loopback: a
# directory of generated knots and catalogue files is tightened with a
# small step budget; the summary has one row per file and its figures are
# the server's job records; a second run submits nothing; a refused file
# and a dead server give clear errors and non-zero exits.
#   TK_BUILD=build TK_CATALOGUE=../shared/catalogue sh tests/cli-remote.sh
# Ends with "cli-remote: N passed, M failed".
set -u
build=${TK_BUILD:-build}
catalogue=${TK_CATALOGUE:-}
tk=$build/tightknot

passed=0
failed=0
tmp=$(mktemp -d)
pid=""
cleanup() {
    [ -n "$pid" ] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

pass() { passed=$((passed + 1)); }
fail() {
    failed=$((failed + 1))
    echo "FAIL $*"
}
summary() {
    echo "cli-remote: $passed passed, $failed failed"
    [ "$failed" -eq 0 ]
    exit
}
check() { # check CONDITION-STATUS WHAT
    if [ "$1" -eq 0 ]; then pass; else fail "$2"; fi
}

# a server on a free port with a fresh store
"$build/tightknotd" --port 0 --db "$tmp/jobs.db" --workers 2 \
    ${TK_WORKER_PRIORITY:+--worker-priority "$TK_WORKER_PRIORITY"} >"$tmp/daemon.log" 2>&1 &
pid=$!
port=""
for _ in $(seq 50); do
    port=$(sed -n 's|.*http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$tmp/daemon.log")
    [ -n "$port" ] && break
    sleep 0.1
done
if [ -z "$port" ]; then
    fail "the daemon did not start: $(cat "$tmp/daemon.log")"
    summary
fi
url="http://127.0.0.1:$port"

mkdir -p "$tmp/in"
"$tk" generate torus 2 3 --vertices 60 >"$tmp/in/trefoil.vect"
"$tk" generate hopf --vertices 48 >"$tmp/in/hopf.vect"
"$tk" generate chain 3 --vertices 90 >"$tmp/in/chain3.vect"
files=3
if [ -n "$catalogue" ] && [ -f "$catalogue/3.1.vect" ]; then
    cp "$catalogue/3.1.vect" "$catalogue/2.2.1.vect" "$catalogue/0.2.1.vect" "$tmp/in/"
    files=6
fi

"$tk" remote --server "$url" submit --autoscale --steps 60 --parallel 3 --poll 0.2 \
    --out "$tmp/out" "$tmp/in" >"$tmp/stdout" 2>"$tmp/stderr"
check $? "submit exits 0: $(tail -n 3 "$tmp/stderr")"
rows=$(($(wc -l <"$tmp/out/summary.tsv") - 1))
[ "$rows" -eq "$files" ]
check $? "summary has $rows rows for $files files"
head -n 1 "$tmp/out/summary.tsv" | grep -q "^name	components	vertices	ropelength	thickness	residual	struts	steps	seconds	reached	state$"
check $? "summary header: $(head -n 1 "$tmp/out/summary.tsv")"

# every row is the server's own record of that file's job
tail -n +2 "$tmp/out/summary.tsv" >"$tmp/rows"
while IFS="	" read -r name comps verts rope thick resid struts steps secs reached state; do
    [ "$state" = done ]
    check $? "$name: state $state"
    # the unlink reaches its critical point (two round circles, residual
    # 0) within the budget and stops there; the others use all 60 steps
    if [ "$name" = 0.2.1 ]; then
        [ "$steps" -ge 1 ] && [ "$steps" -le 60 ] &&
            awk -v r="$resid" 'BEGIN {exit !(r < 1e-9)}'
        check $? "$name: $steps steps (want at most 60) and residual $resid (want < 1e-9)"
    else
        [ "$steps" = 60 ]
        check $? "$name: $steps steps, want 60"
    fi
    id=$(awk -F"	" -v n="$name" '$1 == n {print $2}' "$tmp/out/jobs.tsv" | tail -n 1)
    curl -sf "$url/v1/jobs/$id" >"$tmp/job.json"
    check $? "$name: GET /v1/jobs/$id"
    for field in ropelength thickness residual; do
        eval "mine=\$$(echo $field | sed 's/ropelength/rope/; s/thickness/thick/; s/residual/resid/')"
        theirs=$(sed -n "s/.*\"$field\":\([^,}]*\).*/\1/p" "$tmp/job.json")
        awk -v a="$mine" -v b="$theirs" 'BEGIN { exit !(a == b && a + 0 > 0) }'
        check $? "$name: $field $mine in the summary, $theirs on the server"
    done
    theirs=$(sed -n 's/.*"best_reached":\([0-9]*\).*/\1/p' "$tmp/job.json")
    [ -n "$theirs" ] && [ "$reached" = "$theirs" ]
    check $? "$name: reached $reached in the summary, best_reached $theirs on the server"
    grep -q "\"name\":\"$name\"" "$tmp/job.json"
    check $? "$name: job $id is named $name"
    [ -s "$tmp/out/$name.vect" ] && "$tk" info "$tmp/out/$name.vect" --json >"$tmp/info.json"
    check $? "$name: the downloaded VECT reads back"
    info_rope=$(sed -n 's/.*"ropelength":\([^,}]*\).*/\1/p' "$tmp/info.json")
    awk -v a="$info_rope" -v b="$rope" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1e-9 * b) }'
    check $? "$name: tightknot info on the download gives $info_rope, the job $rope"
    grep -q '"struts":\[' "$tmp/out/$name-struts.json"
    check $? "$name: struts JSON downloaded"
done <"$tmp/rows"

# a second run submits nothing new
before=$(curl -sf "$url/v1/jobs?limit=1" | sed -n 's/.*"total":\([0-9]*\).*/\1/p')
"$tk" remote --server "$url" submit --autoscale --steps 60 --poll 0.2 --out "$tmp/out" \
    "$tmp/in" >/dev/null 2>"$tmp/stderr2"
check $? "second run exits 0"
after=$(curl -sf "$url/v1/jobs?limit=1" | sed -n 's/.*"total":\([0-9]*\).*/\1/p')
[ "$before" = "$after" ] && [ -n "$before" ]
check $? "second run submitted $((after - before)) jobs, want 0"
rows2=$(($(wc -l <"$tmp/out/summary.tsv") - 1))
[ "$rows2" -eq "$files" ]
check $? "summary keeps $rows2 rows"

# a refused file: its row says so, the others are still written, exit 2
printf 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 nope\n0 1 0\n' >"$tmp/in/broken.vect"
"$tk" remote --server "$url" submit --autoscale --steps 60 --poll 0.2 --out "$tmp/out" \
    "$tmp/in" >/dev/null 2>"$tmp/stderr3"
[ $? -eq 2 ]
check $? "a refused file makes the exit status 2"
grep -q "broken: refused: line 6" "$tmp/stderr3"
check $? "the refusal names the line: $(cat "$tmp/stderr3")"
grep -q "^broken	.*	refused$" "$tmp/out/summary.tsv"
check $? "the refused file has its row"
[ $(($(wc -l <"$tmp/out/summary.tsv") - 1)) -eq $((files + 1)) ]
check $? "the done rows are kept next to the refused one"

# status, fetch and cancel of single jobs
first=$(awk -F"	" '$1 == "trefoil" {print $2; exit}' "$tmp/out/jobs.tsv")
"$tk" remote --server "$url" status "$first" >"$tmp/status" 2>&1
check $? "status exits 0"
grep -q "^$first	.*	done	step 60	" "$tmp/status"
check $? "status line: $(cat "$tmp/status")"
"$tk" remote --server "$url" fetch --out "$tmp/fetched" "$first" >/dev/null 2>&1 &&
    cmp -s "$tmp/fetched/trefoil-$first.vect" "$tmp/out/trefoil.vect" &&
    cmp -s "$tmp/fetched/trefoil-$first-struts.json" "$tmp/out/trefoil-struts.json"
check $? "fetch downloads the same VECT and struts, named NAME-JOB as the page names them"
"$tk" remote --server "$url" cancel "$first" >/dev/null 2>"$tmp/cancel"
[ $? -eq 2 ] && grep -q "already finished" "$tmp/cancel"
check $? "cancelling a finished job: $(cat "$tmp/cancel")"
"$tk" remote --server "$url" status "$first" >/dev/null 2>&1
check $? "cancel left the finished job as it was"
"$tk" remote --server "$url" delete "$first" >"$tmp/delete" 2>&1
check $? "delete of a finished job exits 0: $(cat "$tmp/delete")"
grep -q "^$first	deleted$" "$tmp/delete"
check $? "delete says so: $(cat "$tmp/delete")"
"$tk" remote --server "$url" status "$first" >/dev/null 2>"$tmp/gone"
[ $? -eq 2 ] && grep -q "no job $first" "$tmp/gone"
check $? "a deleted job is gone: $(cat "$tmp/gone")"
"$tk" remote --server "$url" status 999999 >/dev/null 2>"$tmp/missing"
[ $? -eq 2 ] && grep -q "no job 999999" "$tmp/missing"
check $? "status of a missing job: $(cat "$tmp/missing")"

# list: every job the server holds, newest first, as status prints them;
# a state keeps those in it; --json the job objects; a bad state is named
"$tk" remote --server "$url" list >"$tmp/list" 2>&1
check $? "list exits 0: $(head -c 200 "$tmp/list")"
ids=$(awk -F"	" '$2 != "" {print $2}' "$tmp/out/jobs.tsv" | grep -v "^$first$" |
    sort -n | tr '\n' ' ')
[ "$(cut -f 1 "$tmp/list" | sort -n | tr '\n' ' ')" = "$ids" ]
check $? "list names the jobs submitted and not deleted ($ids): $(cut -f 1 "$tmp/list" | tr '\n' ' ')"
[ "$(cut -f 1 "$tmp/list" | tr '\n' ' ')" = "$(cut -f 1 "$tmp/list" | sort -rn | tr '\n' ' ')" ]
check $? "list is newest first"
for id in $ids; do
    "$tk" remote --server "$url" status "$id" 2>/dev/null
done >"$tmp/statuses"
[ "$(sort "$tmp/list")" = "$(sort "$tmp/statuses")" ]
check $? "list's lines are status's lines"
"$tk" remote --server "$url" list done >"$tmp/done" 2>&1
[ "$(wc -l <"$tmp/done")" -eq "$(grep -c "	done	" "$tmp/list")" ]
check $? "list done keeps the done jobs: $(wc -l <"$tmp/done")"
"$tk" remote --server "$url" --json list >"$tmp/list.json" 2>&1
[ "$(grep -c '^{"' "$tmp/list.json")" -eq "$(wc -l <"$tmp/list")" ]
check $? "list --json: one object a job"
"$tk" remote --server "$url" list finished >/dev/null 2>"$tmp/badstate"
[ $? -eq 1 ] && grep -q "state" "$tmp/badstate"
check $? "list with a bad state: usage error from the server's message: $(cat "$tmp/badstate")"

# a film's frames of a job at equal flow time: each the stored frame
# nearest its time on the equal grid, all frames tried (brute force), the
# flow times from the job's every stored step (200 steps, none thinned),
# the files the frames' own coordinates
"$tk" remote --server "$url" submit --autoscale --steps 200 --every 10 --poll 0.2 \
    --out "$tmp/fout" "$tmp/in/trefoil.vect" >/dev/null 2>"$tmp/err"
check $? "a job with frames: $(tail -n 2 "$tmp/err")"
fjob=$(awk -F"	" '$1 == "trefoil" {print $2; exit}' "$tmp/fout/jobs.tsv")
"$tk" remote --server "$url" frames --count 15 --out "$tmp/frames" "$fjob" >"$tmp/frames.tsv" 2>"$tmp/err"
check $? "remote frames exits 0: $(cat "$tmp/err")"
[ "$(ls "$tmp/frames" | grep -c "^trefoil-$fjob-frame-00[0-9][0-9]\.vect$")" -eq 15 ]
check $? "remote frames writes NAME-JOB-frame-KKKK.vect, 15 of them: $(ls "$tmp/frames" | head -n 2)"
"$tk" info "$tmp/frames/trefoil-$fjob-frame-0015.vect" >/dev/null
check $? "a frame is a VECT file"
node -e '
const [url, job, table, dir] = process.argv.slice(1);
const fs = require("fs");
(async () => {
    const hist = await (await fetch(`${url}/v1/jobs/${job}/history?limit=2000`)).json();
    const fr = await (await fetch(`${url}/v1/jobs/${job}/frames?limit=200`)).json();
    const flow = new Map(hist.steps.map((s) => [s.step, s.flow_time]));
    const times = fr.frames.map((f) => flow.get(f.step));
    const rows = fs.readFileSync(table, "utf8").trim().split("\n").slice(1).map((l) => l.split("\t"));
    if (rows.length !== 15) throw new Error(`${rows.length} rows`);
    const t0 = times[0], t1 = times[times.length - 1];
    rows.forEach(([k, step, t, file], i) => {
        const want = t0 + (t1 - t0) * i / 14;
        const best = Math.min(...times.map((x) => Math.abs(x - want)));
        if (Math.abs(flow.get(Number(step)) - want) > best + 1e-12) throw new Error(`frame ${k}: step ${step}`);
        if (Math.abs(Number(t) - flow.get(Number(step))) > 1e-12 * Math.max(1, t1)) throw new Error(`frame ${k}: time ${t}`);
        const f = fr.frames.find((x) => x.step === Number(step));
        const nums = fs.readFileSync(file, "utf8").replace(/#.*$/gm, "").trim().split(/\s+/).slice(1).map(Number);
        const got = nums.slice(-f.coordinates.length);
        if (got.some((x, j) => Math.abs(x - f.coordinates[j]) > 1e-12 * Math.max(1, Math.abs(x))))
            throw new Error(`frame ${k}: coordinates differ from the stored frame`);
    });
})().catch((e) => { console.error(e.message); process.exit(1); });
' "$url" "$fjob" "$tmp/frames.tsv" "$tmp/frames" 2>"$tmp/err"
check $? "each film frame is the stored frame nearest its flow time: $(cat "$tmp/err")"
"$tk" remote --server "$url" frames 999999 >/dev/null 2>"$tmp/err"
[ $? -eq 2 ]
check $? "frames of a missing job: exit 2 ($(cat "$tmp/err"))"

# a dead server: a clear message and exit 3
kill "$pid" && wait "$pid" 2>/dev/null
pid=""
"$tk" remote --server "$url" submit --steps 5 --out "$tmp/out2" "$tmp/in/hopf.vect" \
    >/dev/null 2>"$tmp/dead"
[ $? -eq 3 ]
check $? "a dead server makes the exit status 3"
grep -q "cannot reach $url" "$tmp/dead"
check $? "a dead server is named: $(cat "$tmp/dead")"
"$tk" remote --server "ftp://x" status 1 >/dev/null 2>&1
[ $? -eq 1 ]
check $? "a non-http URL is a usage error"
"$tk" remote submit --steps -1 x >/dev/null 2>"$tmp/usage"
[ $? -eq 1 ] && grep -q -- "--steps: must be from 0" "$tmp/usage"
check $? "a bad run option is a usage error naming it: $(cat "$tmp/usage")"

summary
