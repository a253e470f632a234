#!/bin/sh
# bench/table2.sh: the paper's Table 2, the links whose tight lengths are
# known or precisely conjectured, tightened at the paper's vertex counts:
# the Gehring clasp (332), the Hopf link (216), the chain of three rings
# (384) and the Borromean rings (630).  Prints each beside the paper's
# polygon value and the smooth value, with the relative errors.  Never
# fails on the figures; prints them.
#
# Units as the paper's table: the Hopf link and the chain in length over
# the tube's radius (ropelength: 8 pi and 12 pi + 4), the Borromean rings
# in length over its diameter (29.0030, half its ropelength 58.006).  The
# clasp's row is the measure README.md ("The Gehring clasp") derives: the
# two ropes' length beyond what their four planes take, L - (d1 + d2 + d3
# + d4) over the diameter, d_i each end's plane offset after the run.
# The paper's clasp is pulled over at right angles, its ends straight up
# and down (`tightknot generate clasp`); the catalogue's simple_clasp.vect
# pulls its ends toward the faces of a regular tetrahedron, another
# clasp, and its row follows with no smooth value to compare.
#
# usage: bench/table2.sh [SECONDS] [BUILD_DIR] [CATALOGUE_DIR]
#   SECONDS of processor time a link (default 600); two run at once.
set -eu
seconds=${1:-600}
build=${2:-build}
catalogue=${3:-../shared/catalogue}
tk=$build/tightknot
[ -x "$tk" ] || { echo "bench/table2: no $tk (make first)"; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$tk" generate chain 3 --vertices 384 >"$dir/chain3.vect"
"$tk" generate clasp >"$dir/clasp.vect"

run() { # tag file vertices
    start=$(date +%s.%N)
    "$tk" tighten "$2" --autoscale --vertices "$3" --time "$seconds" --cpu-time --json \
        -o "$dir/$1.out.vect" >"$dir/$1.json" 2>"$dir/$1.err" || true
    end=$(date +%s.%N)
    echo "$start $end" >"$dir/$1.wall"
}

run clasp "$dir/clasp.vect" 332 &
run hopf "$catalogue/2.2.1.vect" 216 &
wait
run chain "$dir/chain3.vect" 384 &
run borromean "$catalogue/6.3.2.vect" 630 &
wait
run tetra "$catalogue/simple_clasp.vect" 332

# a clasp's measure from its tightened file: the ropes' length less the
# four planes' offsets (the '# Constraint k Plane nx ny nz d' lines)
planes() {
    awk '/^# Constraint [0-9]+ Plane/ { d += $NF } END { printf "%.17g", d }' "$dir/$1.out.vect"
}

node - "$dir" "$(planes clasp)" "$(planes tetra)" <<'EOF'
const [dir, clasp, tetra] = process.argv.slice(2);
const fs = require('fs');
const planes = { clasp: Number(clasp), tetra: Number(tetra) };
const rows = [
    // tag, name, paper's polygon value, smooth value, unit divisor of the ropelength
    ['clasp', 'Gehring clasp', 4.2636, 4.2629, null],
    ['hopf', 'Hopf link', 25.1406, 8 * Math.PI, 1],
    ['chain', 'chain of three', 41.7131, 12 * Math.PI + 4, 1],
    ['borromean', 'Borromean rings', 29.0096, 29.0030, 2],
    ['tetra', 'simple_clasp', NaN, NaN, null],
];
const pad = (s, n) => String(s).padEnd(n);
console.log(['link', 'vertices', 'ours', 'paper', 'smooth', 'ours.err', 'paper.err', 'stopped', 'cpu.s', 'wall.s']
    .map((h, i) => pad(h, i ? 11 : 16)).join(''));
for (const [tag, name, paper, smooth, unit] of rows) {
    let j;
    try {
        j = JSON.parse(fs.readFileSync(`${dir}/${tag}.json`, 'utf8'));
    } catch {
        console.log(`${pad(name, 16)}failed: ${fs.readFileSync(`${dir}/${tag}.err`, 'utf8').trim()}`);
        continue;
    }
    // a clasp: length over the diameter beyond its planes' reach
    const ours = unit ? j.ropelength / unit : (j.length - planes[tag]) / j.thickness;
    const [t0, t1] = fs.readFileSync(`${dir}/${tag}.wall`, 'utf8').trim().split(' ').map(Number);
    const fixed = (x, k) => (Number.isNaN(x) ? '-' : x.toFixed(k));
    const err = (x) => (Number.isNaN(smooth) ? '-' : `${(100 * (x - smooth) / smooth).toFixed(4)}%`);
    console.log([name, j.vertices, ours.toFixed(5), fixed(paper, 4), fixed(smooth, 4), err(ours),
        err(paper), j.stop_reason, j.seconds.toFixed(1), (t1 - t0).toFixed(1)]
        .map((v, i) => pad(v, i ? 11 : 16)).join(''));
}
EOF
