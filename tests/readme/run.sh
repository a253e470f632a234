#!/bin/sh
# README's "Scaling out" worked example, its very lines (between the
# scaling-out markers), run as written but for the first line's cluster
# name and ports (free ones of its own), in a temporary directory where
# build/ and ../shared/catalogue are links to the ones under test and
# HOME (for ~/.pgpass) is its own.  Then: the Hopf link it submits is done
# and tight, the job is in that cluster's database, the daemon's output
# never shows the password, the service wants the token and serves the
# page over HTTPS.  The cluster is dropped afterwards.  Needs root and
# Debian's postgresql-common (pg_createcluster), else it is skipped.
# The last line is "readme: N passed, M failed, K skipped".
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 1
build=$(cd "${TK_BUILD:-build}" && pwd)
catalogue=$(cd "${TK_CATALOGUE:-../shared/catalogue}" 2>/dev/null && pwd)
passed=0
failed=0
check() { # check STATUS WHAT
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL $2"; fi
}
skip() {
    echo "SKIP README's scaling out: $*"
    echo "readme: 0 passed, 0 failed, 1 skipped"
    exit 0
}
[ "$(id -u)" -eq 0 ] || skip "it makes a PostgreSQL cluster: root only"
command -v pg_createcluster >/dev/null || skip "no pg_createcluster (Debian's postgresql-common)"
[ -n "$catalogue" ] || skip "no catalogue at ${TK_CATALOGUE:-../shared/catalogue}"
for f in tightknotd tightknot web/index.html; do
    [ -e "$build/$f" ] || { echo "FAIL no $build/$f (run make)"; echo "readme: 0 passed, 1 failed"; exit 1; }
done

tmp=$(mktemp -d /tmp/tk-readme-XXXXXX)
chmod 755 "$tmp"
mkdir "$tmp/work" "$tmp/home" "$tmp/shared"
ln -s "$build" "$tmp/work/build"
ln -s "$catalogue" "$tmp/shared/catalogue"
free_port() {
    node -e 'const s = require("net").createServer().listen(0, "127.0.0.1", () => { console.log(s.address().port); s.close(); });'
}
pgport=$(free_port)
port=$(free_port)
cluster=tkreadme$$
ver=$(ls /usr/lib/postgresql | sort -n | tail -n 1)
cleanup() {
    [ -f "$tmp/work/pid" ] && kill "$(cat "$tmp/work/pid")" 2>/dev/null
    pkill -f "$tmp/work/build/tightknotd" 2>/dev/null
    pg_dropcluster --stop "$ver" "$cluster" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT

# the block, its fences off, the first line's names and ports ours; the
# daemon's pid kept for the cleanup
sed -n '/^<!-- scaling-out:begin -->$/,/^<!-- scaling-out:end -->$/p' README.md |
    sed '1,2d;$d' | sed '$d' >"$tmp/readme.sh"
first='DB=localhost TK=localhost PGPORT=5433 PORT=8443 CLUSTER=tightknot'
grep -qx "$first" "$tmp/readme.sh"
check $? "README's block starts with the line of names and ports: $(head -n 3 "$tmp/readme.sh")"
sed -i "s/^$first\$/DB=localhost TK=localhost PGPORT=$pgport PORT=$port CLUSTER=$cluster/" \
    "$tmp/readme.sh"
sed -i 's/^until grep -q "listening on" tightknotd.log; do sleep 1; done$/echo $! > pid; &/' \
    "$tmp/readme.sh"
lines=$(grep -c . "$tmp/readme.sh")
(cd "$tmp/work" && HOME="$tmp/home" timeout 600 sh -e ../readme.sh) >"$tmp/out" 2>&1
check $? "README's $lines lines run: $(tail -n 20 "$tmp/out")"

# the Hopf link, done and tight (8 pi exactly; the polygon within 0.1%)
row=$(awk -F'\t' 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    $c["name"] == "2.2.1" { print $c["state"], $c["ropelength"] }' "$tmp/work/results/summary.tsv" 2>/dev/null)
echo "$row" | awk '{ pi8 = 8 * atan2(0, -1); exit !($1 == "done" && $2 > pi8 && $2 < pi8 * 1.001) }'
check $? "the Hopf link is done within 0.1% of 8 pi: ${row:-no row}"
[ -s "$tmp/work/results/2.2.1.vect" ]
check $? "its tight curve is downloaded"
jobs=$(runuser -u postgres -- psql -qtA -p "$pgport" -d tightknot -c "SELECT count(*) FROM jobs" 2>&1)
[ "$jobs" = 1 ]
check $? "the job is stored in the cluster's database: $jobs"
password=$(sed -n 's/^localhost:[0-9]*:tightknot:tightknot://p' "$tmp/home/.pgpass")
[ ${#password} -ge 32 ] && ! grep -q "$password" "$tmp/work/tightknotd.log" "$tmp/out"
check $? "a strong password (${#password} characters), never in the daemon's output"
grep -q "store PostgreSQL database 'tightknot' on localhost:$pgport" "$tmp/work/tightknotd.log"
check $? "the daemon names its store by host, port and database: $(head -n 2 "$tmp/work/tightknotd.log")"
code=$(curl -s -o /dev/null -w '%{http_code}' --cacert "$tmp/work/cert.pem" "https://localhost:$port/v1/jobs")
[ "$code" = 401 ]
check $? "without the token: 401 ($code)"
token=$(cut -d' ' -f2 "$tmp/work/tokens.txt")
[ ${#token} -ge 64 ] &&
    curl -sf --cacert "$tmp/work/cert.pem" -H "Authorization: Bearer $token" \
        "https://localhost:$port/v1/jobs" | grep -q '"total":1'
check $? "with the token: the job listed"
curl -sf --cacert "$tmp/work/cert.pem" "https://localhost:$port/" | grep -q "<title>tightknot</title>" &&
    curl -sf --cacert "$tmp/work/cert.pem" -H "Authorization: Bearer $token" \
        "https://localhost:$port/v1/catalogue" | grep -q '"2.2.1"'
check $? "the page and the catalogue over HTTPS"

echo "readme: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
