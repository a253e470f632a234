#!/bin/sh
# Command-line tests of the tightknot program: exit codes, help texts,
# generate -> info round trips, and the catalogue's known ropelengths.
#   TK_BUILD=build TK_CATALOGUE=../shared/catalogue sh tests/cli-basic.sh
# Prints "FAIL ..." for each failure and ends with
# "cli-basic: N passed, M failed".  Plain sh, grep, sed and awk only.
set -u
build=${TK_BUILD:-build}
catalogue=${TK_CATALOGUE:-}
tk=$build/tightknot

passed=0
failed=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
trap 'exit 1' INT TERM

pass() { passed=$((passed + 1)); }
fail() {
    failed=$((failed + 1))
    echo "FAIL $*"
}
summary() {
    echo "cli-basic: $passed passed, $failed failed"
    [ "$failed" -eq 0 ]
    exit
}

# run CMD...: runs it with stdout in $tmp/out and stderr in $tmp/err,
# status in $status.
run() {
    "$@" >"$tmp/out" 2>"$tmp/err"
    status=$?
}

# expect_status WANT WHAT CMD...
expect_status() {
    want=$1
    what=$2
    shift 2
    run "$@"
    if [ "$status" -eq "$want" ]; then
        pass
    else
        fail "$what: exit status $status, want $want"
        sed -n '1,5s/^/    | /p' "$tmp/err"
    fi
}

# expect_match ERE FILE WHAT: some line of FILE matches.
expect_match() {
    if grep -Eq -- "$1" "$2"; then
        pass
    else
        fail "$3: nothing matches '$1' in: $(head -c 200 "$2")"
    fi
}

# json_value NAME FILE: the value of "NAME" on the first line of FILE (a
# one-line JSON object whose values are numbers, strings or null).
json_value() {
    sed -n '1p' "$2" | sed -n -E 's/.*"'"$1"'":("[^"]*"|[^,}]*).*/\1/p'
}

# expect_value NAME WANT FILE WHAT: exact (textual) value.
expect_value() {
    got=$(json_value "$1" "$3")
    if [ "$got" = "$2" ]; then
        pass
    else
        fail "$4: $1 is '$got', want '$2'"
    fi
}

# expect_close NAME WANT RELTOL FILE WHAT: |got - want| <= reltol * |want|.
expect_close() {
    got=$(json_value "$1" "$4")
    if [ -n "$got" ] && awk -v a="$got" -v b="$2" -v tol="$3" 'BEGIN {
            d = a - b; if (d < 0) d = -d
            m = b < 0 ? -b : b
            exit !(a == a + 0 && d <= tol * m) }'; then
        pass
    else
        fail "$5: $1 is '$got', want $2 within $3 relative"
    fi
}

if [ ! -x "$tk" ]; then
    fail "$tk is missing: build it first (make all)"
    summary
fi

# ---------------------------------------------------------------- help

expect_status 0 "tightknot --help" "$tk" --help
for word in info struts generate ropelength "Exit status"; do
    expect_match "$word" "$tmp/out" "tightknot --help mentions $word"
done
"$tk" --help >"$tmp/mainhelp"
expect_match "^  remote " "$tmp/mainhelp" "tightknot --help lists remote"
# every shape generate knows (one that it does not know is refused as
# "unknown shape") is listed by tightknot --help
for shape in torus figure-eight lissajous hopf borromean chain clasp deform relax turn wander; do
    "$tk" generate "$shape" >/dev/null 2>"$tmp/shape"
    if grep -q "unknown shape" "$tmp/shape"; then
        fail "generate $shape: $(cat "$tmp/shape")"
    else
        pass
    fi
    expect_match "$shape" "$tmp/mainhelp" "tightknot --help lists the shape $shape"
done
"$tk" generate frobnicate >/dev/null 2>"$tmp/shape"
expect_match "unknown shape" "$tmp/shape" "an unknown shape is refused as such"
expect_status 0 "tightknot -h" "$tk" -h

# a knot by its catalogue name, when no file has that name: from
# $TIGHTKNOT_CATALOGUE (a copy here), with or without .vect; the same
# figures as the file's; -o never overwrites the catalogue's file a bare
# name found (an explicit path may be tightened in place)
mkdir -p "$tmp/cat"
"$tk" generate torus 2 5 >"$tmp/cat/5.1.vect"
"$tk" info "$tmp/cat/5.1.vect" | tail -n 1 | awk '{$1 = ""; print}' >"$tmp/byfile"
for arg in 5.1 5.1.vect; do
    (cd "$tmp" && TIGHTKNOT_CATALOGUE="$tmp/cat" "$OLDPWD/$tk" info "$arg") >"$tmp/byname" 2>&1
    if [ "$(tail -n 1 "$tmp/byname" | awk '{$1 = ""; print}')" = "$(cat "$tmp/byfile")" ]; then
        pass
    else
        fail "info $arg by catalogue name: $(cat "$tmp/byname")"
    fi
done
cp "$tmp/cat/5.1.vect" "$tmp/kept.vect"
TIGHTKNOT_CATALOGUE="$tmp/cat" "$tk" tighten 5.1 --steps 3 -o "$tmp/cat/5.1.vect" \
    >/dev/null 2>"$tmp/err"
status=$?
if [ "$status" -eq 1 ] && grep -q "names the input" "$tmp/err" &&
    cmp -s "$tmp/cat/5.1.vect" "$tmp/kept.vect"; then
    pass
else
    fail "tighten NAME -o the catalogue's file: status $status, $(cat "$tmp/err")"
fi
(cd "$tmp" && TIGHTKNOT_CATALOGUE="$tmp/cat" "$OLDPWD/$tk" info 9.99) >/dev/null 2>"$tmp/err"
expect_match "9.99: cannot open" "$tmp/err" "a name in no catalogue is named as given"
expect_status 1 "tightknot without a command" "$tk"
expect_status 1 "unknown command" "$tk" frobnicate
expect_match "frobnicate" "$tmp/err" "unknown command names it"

for cmd in info struts generate; do
    for flag in --help -h; do
        expect_status 0 "$cmd $flag" "$tk" "$cmd" "$flag"
        expect_match "^usage: tightknot $cmd" "$tmp/out" "$cmd $flag has a usage line"
        expect_match "Example" "$tmp/out" "$cmd $flag has an example"
    done
done
for cmd in info struts; do
    "$tk" "$cmd" --help >"$tmp/help"
    for word in --json --tolerance "2 \\* length / thickness" "thickness" "diameter"; do
        expect_match "$word" "$tmp/help" "$cmd --help mentions $word"
    done
done
"$tk" generate --help >"$tmp/help"
for word in --vertices "torus P Q" hopf borromean "chain K"; do
    expect_match "$word" "$tmp/help" "generate --help mentions $word"
done
expect_status 0 "help info" "$tk" help info
expect_match "^usage: tightknot info" "$tmp/out" "help info shows info's help"

# --version: both programs print the release of include/tk/version.h
release=$(sed -n -E 's/^#define TK_VERSION "([^"]*)"$/\1/p' include/tk/version.h)
for prog in tightknot tightknotd; do
    expect_status 0 "$prog --version" "$build/$prog" --version
    if [ -n "$release" ] && [ "$(cat "$tmp/out")" = "$prog $release" ]; then
        pass
    else
        fail "$prog --version printed '$(cat "$tmp/out")', want '$prog $release'"
    fi
done

# ---------------------------------------------------------- usage errors

"$tk" generate hopf >"$tmp/hopf.vect"
expect_status 1 "unknown option" "$tk" info --frobnicate "$tmp/hopf.vect"
expect_match "--frobnicate" "$tmp/err" "unknown option is named"
expect_status 1 "info without files" "$tk" info
expect_status 1 "--tolerance without its value" "$tk" info "$tmp/hopf.vect" --tolerance
expect_match "--tolerance" "$tmp/err" "missing value names the option"
expect_status 1 "--tolerance not a number" "$tk" info --tolerance 1e-4x "$tmp/hopf.vect"
expect_match "--tolerance" "$tmp/err" "bad number names the option"
expect_status 1 "--tolerance negative" "$tk" info --tolerance=-1 "$tmp/hopf.vect"
expect_status 1 "--json takes no value" "$tk" info --json=yes "$tmp/hopf.vect"
expect_status 1 "generate's option on info" "$tk" info --vertices 10 "$tmp/hopf.vect"
expect_status 1 "struts with two files" "$tk" struts "$tmp/hopf.vect" "$tmp/hopf.vect"
expect_status 1 "generate without a shape" "$tk" generate
expect_status 1 "generate unknown shape" "$tk" generate cube
expect_status 1 "torus with a bad number" "$tk" generate torus 2 x3
expect_match "x3" "$tmp/err" "bad torus argument is named"
expect_status 1 "torus with one number" "$tk" generate torus 2
expect_status 1 "torus T(0, 3)" "$tk" generate torus 0 3
expect_status 1 "torus T(-2, 3)" "$tk" generate torus -2 3
expect_status 1 "--vertices not an integer" "$tk" generate hopf --vertices 1.5
expect_match "--vertices" "$tmp/err" "bad --vertices names the option"
expect_status 1 "--vertices 2" "$tk" generate hopf --vertices 2
expect_status 1 "--vertices over the limit" "$tk" generate borromean --vertices 99999999999
expect_status 1 "chain 0" "$tk" generate chain 0
expect_status 1 "hopf with an argument" "$tk" generate hopf 3
# deform: a start of the file's type, another with another seed
"$tk" generate torus 2 5 >"$tmp/t25.vect"
expect_status 0 "deform a file" "$tk" generate deform "$tmp/t25.vect" 4
cp "$tmp/out" "$tmp/d4.vect"
"$tk" info "$tmp/t25.vect" | tail -n 1 | sed 's/.* det /det /' >"$tmp/type-a"
"$tk" info "$tmp/d4.vect" | tail -n 1 | sed 's/.* det /det /' >"$tmp/type-b"
if cmp -s "$tmp/type-a" "$tmp/type-b" && ! cmp -s "$tmp/t25.vect" "$tmp/d4.vect"; then pass; else
    fail "deform keeps the type: $(cat "$tmp/type-a") / $(cat "$tmp/type-b")"; fi
expect_status 1 "deform without a file" "$tk" generate deform
expect_status 1 "deform with a bad seed" "$tk" generate deform "$tmp/t25.vect" x
printf 'VECT\n1 2\n' >"$tmp/bad.vect"
expect_status 2 "deform of a bad file" "$tk" generate deform "$tmp/bad.vect"
expect_match "bad.vect:2:" "$tmp/err" "deform of a bad file names the line"

# ----------------------------------------------------------- bad input

expect_status 2 "missing file" "$tk" info "$tmp/no-such.vect"
expect_match "no-such\\.vect" "$tmp/err" "missing file is named"

# A malformed coordinate on line 7.
printf 'VECT\n1 4 0\n-4\n0\n0 0 0\n1 0 0\n1 1 oops\n0 1 0\n' >"$tmp/bad.vect"
expect_status 2 "malformed VECT" "$tk" info "$tmp/bad.vect"
expect_match "^tightknot: .*bad\\.vect:7: " "$tmp/err" "parse error says FILE:LINE"
lines=$(wc -l <"$tmp/err")
if [ "$lines" -eq 1 ]; then pass; else fail "parse error: $lines lines on stderr, want 1"; fi
expect_status 2 "struts on malformed VECT" "$tk" struts "$tmp/bad.vect"

# Coordinates whose squares overflow once made the contact search widen
# forever; now a clear refusal naming the vertex (timeout: a hang fails).
printf 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1e200 0\n' >"$tmp/huge.vect"
expect_status 2 "info on a coordinate of 1e200" timeout 20 "$tk" info "$tmp/huge.vect"
expect_match "vertex 2 has coordinate y = 1e\\+200, beyond the \\+-1e\\+30" "$tmp/err" \
    "coordinate beyond the range is named"
expect_status 2 "struts on a coordinate of 1e200" timeout 20 "$tk" struts "$tmp/huge.vect"

# Every file is processed; one failure makes the status 2.
expect_status 2 "info with a bad file among good ones" \
    "$tk" info --json "$tmp/hopf.vect" "$tmp/bad.vect" "$tmp/hopf.vect"
lines=$(wc -l <"$tmp/out")
if [ "$lines" -eq 2 ]; then pass; else fail "info kept going: $lines result lines, want 2"; fi

if [ -w /dev/full ]; then
    expect_status 2 "generate into a full disk" sh -c "'$tk' generate hopf >/dev/full"
fi

# ---------------------------------------------------------- round trips

expect_status 0 "info --json on hopf" "$tk" info --json "$tmp/hopf.vect"
for name in file components vertices length thickness minrad ropelength struts kinks invariants; do
    expect_match "\"$name\":" "$tmp/out" "info --json has $name"
done
expect_value components 2 "$tmp/out" "hopf"
expect_value vertices 128 "$tmp/out" "hopf"
expect_value file "\"$tmp/hopf.vect\"" "$tmp/out" "hopf"
# Two polygons inscribed in unit circles: length 2 * 2n sin(pi/n).
expect_close length 12.561324627819012 1e-12 "$tmp/out" "hopf"
expect_status 0 "info (text) on hopf" "$tk" info "$tmp/hopf.vect"
expect_match "^file +comps +vertices" "$tmp/out" "info prints a header"
expect_match "hopf\\.vect +2 +128 " "$tmp/out" "info prints the counts"

# The tight Hopf link has ropelength 8 pi (length / tube radius).
"$tk" generate hopf --vertices 1000 >"$tmp/hopf1000.vect"
expect_status 0 "info on a fine hopf" "$tk" info --json "$tmp/hopf1000.vect"
expect_close ropelength 25.132741228718345 1e-4 "$tmp/out" "fine hopf"
expect_close thickness 1 1e-4 "$tmp/out" "fine hopf"

expect_status 0 "generate hopf, odd count" "$tk" generate hopf --vertices=33
"$tk" info --json - <"$tmp/out" >"$tmp/info"
expect_value vertices 68 "$tmp/info" "hopf --vertices 33 (rounded up to even)"

expect_status 0 "generate torus 2 3" "$tk" generate torus 2 3
cp "$tmp/out" "$tmp/trefoil.vect"
expect_match "^VECT" "$tmp/trefoil.vect" "torus output is VECT"
expect_status 0 "torus 2 3 parses" "$tk" info --json "$tmp/trefoil.vect"
expect_value components 1 "$tmp/out" "torus 2 3"

"$tk" generate torus 2 4 --vertices 90 >"$tmp/t24.vect"
expect_status 0 "torus 2 4 parses" "$tk" info --json "$tmp/t24.vect"
expect_value components 2 "$tmp/out" "torus 2 4"
expect_value vertices 180 "$tmp/out" "torus 2 4"

"$tk" generate chain 3 >"$tmp/chain.vect"
expect_status 0 "chain 3 parses" "$tk" info --json "$tmp/chain.vect"
expect_value components 3 "$tmp/out" "chain 3"
expect_value vertices 192 "$tmp/out" "chain 3"

"$tk" generate borromean >"$tmp/borromean.vect"
expect_status 0 "borromean parses" "$tk" info --json "$tmp/borromean.vect"
expect_value components 3 "$tmp/out" "borromean"

# The knot or link type: the trefoil's Alexander polynomial 1 - t + t^2
# and determinant 3; the figure-eight's -1 + 3t - t^2 from a disguised
# start; the Hopf link's linking number +-1, the same both ways.
expect_status 0 "info --json on the trefoil" "$tk" info --json "$tmp/trefoil.vect"
expect_match '"invariants":\{"alexander":\[\[1,-1,1\]\],"alexander_text":\["1 - t \+ t\^2"\],"determinants":\[3\],"link_determinant":3,"linking":\[\[0\]\],"complete":true\}' \
    "$tmp/out" "info --json: the trefoil's type"
expect_status 0 "info (text) on the trefoil" "$tk" info "$tmp/trefoil.vect"
expect_match 'trefoil\.vect +1 +[0-9]+ .* det 3, 1 - t \+ t\^2$' "$tmp/out" "info: the trefoil's type column"
"$tk" generate figure-eight --disguise 3 >"$tmp/fig8.vect"
expect_status 0 "info on a disguised figure-eight" "$tk" info --json "$tmp/fig8.vect"
expect_match '"alexander":\[\[-1,3,-1\]\],"alexander_text":\["-1 \+ 3t - t\^2"\],"determinants":\[5\]' \
    "$tmp/out" "info --json: the figure-eight's type"
# Lissajous knots: (3, 2, 5) is 6_1 (2 - 5t + 2t^2, determinant 9), with
# (3, 2, 7) and phases 0.7 0.7 0 the knot 5_2 (determinant 7); frequencies
# that are not coprime and phases that retrace the curve are usage errors.
"$tk" generate lissajous 3 2 5 --vertices 120 >"$tmp/l325.vect"
expect_status 0 "info on Lissajous (3, 2, 5)" "$tk" info --json "$tmp/l325.vect"
expect_match '"alexander":\[\[-2,5,-2\]\],"alexander_text":\["-2 \+ 5t - 2t\^2"\],"determinants":\[9\]' \
    "$tmp/out" "info --json: Lissajous (3, 2, 5) is 6_1"
expect_value vertices 120 "$tmp/out" "Lissajous --vertices"
"$tk" generate lissajous 3 2 7 0.7 0.7 0 >"$tmp/l327.vect"
expect_status 0 "info on Lissajous (3, 2, 7)" "$tk" info --json "$tmp/l327.vect"
expect_match '"determinants":\[7\]' "$tmp/out" "info --json: Lissajous (3, 2, 7) is 5_2"
expect_status 1 "Lissajous frequencies not coprime" "$tk" generate lissajous 3 2 6
expect_match 'not coprime' "$tmp/err" "Lissajous: the frequencies named"
expect_status 1 "Lissajous retracing itself" "$tk" generate lissajous 3 2 5 0 0 0
expect_match 'passes through itself' "$tmp/err" "Lissajous: the phases named"
expect_status 0 "info --json on hopf" "$tk" info --json "$tmp/hopf.vect"
expect_match '"determinants":\[1,1\],"link_determinant":2,"linking":(\[\[0,1\],\[1,0\]\]|\[\[0,-1\],\[-1,0\]\]),"complete":true' \
    "$tmp/out" "info --json: the Hopf link's linking number and determinant"
expect_status 0 "info (text) on hopf" "$tk" info "$tmp/hopf.vect"
expect_match ' det 1 1, lk 0-1: -?1, link det 2$' "$tmp/out" "info: the Hopf link's type column"

# Standard input as "-", through a pipe.
"$tk" generate chain 4 | "$tk" info --json - >"$tmp/out" 2>"$tmp/err"
expect_value components 4 "$tmp/out" "chain 4 through a pipe"
expect_value file '"-"' "$tmp/out" "standard input is called -"

# struts --json lists as many struts as info counts.
expect_status 0 "struts --json" "$tk" struts --json "$tmp/hopf.vect"
for name in file thickness struts kinks edges '"s"' '"t"' '"p"' '"q"' length; do
    expect_match "$name" "$tmp/out" "struts --json has $name"
done
nstruts=$(grep -o '"edges"' "$tmp/out" | wc -l)
"$tk" info --json "$tmp/hopf.vect" >"$tmp/info"
expect_value struts "$nstruts" "$tmp/info" "struts --json agrees with info"
expect_status 0 "struts (text)" "$tk" struts "$tmp/hopf.vect"
expect_match "^thickness " "$tmp/out" "struts prints the thickness"

# ------------------------------------------------------------ catalogue

if [ -n "$catalogue" ] && [ -d "$catalogue" ]; then
    expect_status 0 "info on 3_1_328" "$tk" info --json "$catalogue/3_1_328.vect"
    expect_close ropelength 32.752356 1e-6 "$tmp/out" "3_1_328.vect"
    expect_status 0 "info on 10_154_test" "$tk" info --json "$catalogue/10_154_test.vect"
    expect_close ropelength 82.3858 1e-5 "$tmp/out" "10_154_test.vect"
    expect_status 0 "info on several catalogue files" \
        "$tk" info "$catalogue/3.1.vect" "$catalogue/2.2.1.vect" "$catalogue/6.3.2.vect"
    lines=$(wc -l <"$tmp/out")
    if [ "$lines" -eq 4 ]; then pass; else fail "info on 3 files: $lines lines, want 4"; fi
else
    echo "note: catalogue '${catalogue}' absent: its checks are skipped"
fi

summary
