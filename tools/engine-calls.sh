#!/bin/sh
# Prints the engine's cross-file calls, from the object files' symbols, and
# checks them against the rooms' order (engine/run.h): a file may call the
# files below it and those on its own level, never one above it, and two
# files on one level may not call each other (that is a circle too).
#
#   tools/engine-calls.sh [BUILD]     (default build; reads BUILD/engine/*.o)
#
# Each line: a file's level, its name, and the engine files whose
# functions it calls.  Exit status 1 when a call runs up (each is named on
# standard error), 2 when the objects are missing or a file has no level
# here (a new file must be given one).

build=${1:-build}
dir=$build/engine

# The levels, lowest first.  The libraries (the curve, its geometry and
# struts, the solvers, the invariants, the records, the file formats) hold
# no run state and serve every room, so they all stand below the rooms;
# among themselves only two that call each other are refused.  The
# constraints on vertices (pin.c) are part of the curve's value, below
# it: the curve carries them through its copies, resamplings and motions.
# queries.c (read-only questions on the run's state) and type.c (the knot
# type's checks) serve every room from just above the libraries.
levels='
0 pin error
1 curve geometry struts nnls rigidity invariants record vect generate thickness relax isotopy
2 queries type
3 active
4 motion
5 stepping recovery
6 schedule escape
7 tighten
'

set -- "$dir"/*.o
if [ ! -f "$1" ]; then
    echo "engine-calls: no objects in $dir (build them first)" >&2
    exit 2
fi

# "file symbol-line" for every symbol of every object
symbols=$(for o in "$@"; do
    f=${o##*/}
    f=${f%.o}
    out=$(nm "$o") || exit 2
    printf '%s\n' "$out" | sed "s/^/$f /"
done) || exit 2

printf '%s\n' "$symbols" | awk -v levels="$levels" '
BEGIN {
    n = split(levels, row, "\n")
    for (i = 1; i <= n; i++) {
        k = split(row[i], w, " ")
        for (j = 2; j <= k; j++)
            level[w[j]] = w[1] + 0
    }
}
# "file addr T sym" defines a function; "file U sym" uses one.
NF == 4 && ($3 == "T" || $3 == "W") { owner[$4] = $1; files[$1] = 1; next }
NF == 3 && $2 == "U" { used[$1, $3] = 1; files[$1] = 1; next }
NF >= 3 { files[$1] = 1 }
END {
    status = 0
    for (f in files)
        if (!(f in level)) {
            printf "engine-calls: %s.c has no level (tools/engine-calls.sh)\n", f > "/dev/stderr"
            status = 2
        }
    if (status)
        exit status
    for (key in used) {
        split(key, p, SUBSEP)
        if ((p[2] in owner) && owner[p[2]] != p[1])
            calls[p[1], owner[p[2]]] = 1
    }
    # The files by level, then by name, for a stable listing.
    nf = 0
    for (f in files)
        order[++nf] = f
    for (i = 2; i <= nf; i++)
        for (j = i; j > 1; j--) {
            a = order[j - 1]; b = order[j]
            if (level[a] < level[b] || (level[a] == level[b] && a <= b))
                break
            order[j - 1] = b; order[j] = a
        }
    for (i = 1; i <= nf; i++) {
        f = order[i]
        line = ""
        for (j = 1; j <= nf; j++) {
            g = order[j]
            if ((f, g) in calls) {
                line = line " " g
                if (level[g] > level[f]) {
                    bad = bad sprintf("engine-calls: %s (level %d) calls %s (level %d), above it\n",
                                      f, level[f], g, level[g])
                    status = 1
                } else if (level[g] == level[f] && (g, f) in calls && f < g) {
                    bad = bad sprintf("engine-calls: %s and %s (level %d) call each other\n",
                                      f, g, level[f])
                    status = 1
                }
            }
        }
        printf "%d %-10s ->%s\n", level[f], f, line
    }
    if (status)
        printf "%s", bad > "/dev/stderr"
    else
        print "engine-calls: no file calls one above it"
    exit status
}'
