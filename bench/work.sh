#!/bin/sh
# bench/work.sh: how a budget of work (tightknot tighten --work) compares
# with the processor time it takes on this machine.  The work is counted
# from a run's operations and weighed by what each cost the reference
# processor (engine/queries.c), so on that machine W of work should take
# about W seconds; on a faster or slower one, proportionally less or more.
# Each knot is tightened to W of work with its processor time counted
# (--cpu-time), one at a time, and a line printed: the knot, the work, the
# processor seconds, their ratio, steps, ropelength.  Then the same
# knot's first run is run again beside a second copy of itself (two at
# once) and the ropelengths and steps compared: a budget of work gives
# the same run whatever else the machine does.  Prints figures; never
# fails on them.
#
# usage: bench/work.sh [WORK] [BUILD_DIR] [CATALOGUE_DIR] [KNOT ...]
#   WORK per run (default 20); knots by catalogue name (default 3.1 5.2
#   7.4 8.14 9.23 10.133 2.2.1 6.3.2)
set -eu
work=${1:-20}
build=${2:-build}
catalogue=${3:-../shared/catalogue}
[ $# -gt 3 ] && shift 3 || set -- 3.1 5.2 7.4 8.14 9.23 10.133 2.2.1 6.3.2
tk=$build/tightknot
[ -x "$tk" ] || { echo "bench/work: no $tk (make first)"; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

field() { # file key
    grep -o "\"$2\":[-0-9.eE+]*" "$1" | head -1 | cut -d: -f2
}
run() { # knot tag
    "$tk" tighten "$catalogue/$1.vect" --work "$work" --cpu-time --json \
        -o "$dir/$2.vect" >"$dir/$2.json" 2>"$dir/$2.err" || true
}

printf '%-8s %8s %10s %7s %8s %12s   %s\n' knot work cpu.s ratio steps ropelength \
    "again, two at once"
for k in "$@"; do
    run "$k" "$k.alone"
    run "$k" "$k.a" & run "$k" "$k.b" & wait
    j=$dir/$k.alone.json
    w=$(field "$j" work); s=$(field "$j" seconds); n=$(field "$j" steps); r=$(field "$j" ropelength)
    same="differ"
    if cmp -s "$dir/$k.alone.vect" "$dir/$k.a.vect" && cmp -s "$dir/$k.alone.vect" "$dir/$k.b.vect"; then
        same="the same curve, bit for bit"
    fi
    awk -v k="$k" -v w="$w" -v s="$s" -v n="$n" -v r="$r" -v same="$same" \
        -v sa="$(field "$dir/$k.a.json" seconds)" -v sb="$(field "$dir/$k.b.json" seconds)" \
        'BEGIN { printf "%-8s %8.2f %10.2f %7.3f %8d %12.6f   %s (%.1f and %.1f s)\n",
                 k, w, s, s / w, n, r, same, sa, sb }'
done
