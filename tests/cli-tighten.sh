#!/bin/sh
# Command-line tests of `tightknot tighten`: the outputs agree with each
# other (the --json figures, the output VECT measured again by `info`, the
# per-step log, the snapshots, the struts file), and bad options and input
# give the documented exit statuses with messages naming what is wrong.
#   TK_BUILD=build TK_CATALOGUE=../shared/catalogue sh tests/cli-tighten.sh
# Ends with "cli-tighten: N passed, M failed".
set -u
build=${TK_BUILD:-build}
tk=$build/tightknot
passed=0
failed=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
trap 'exit 1' INT TERM

check() { # check STATUS WHAT
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL $2"; fi
}
value() { # value NAME FILE: a number or string of a one-line JSON object (the first NAME)
    grep -o "\"$1\":\"*[^,}\"]*" "$2" | head -n 1 | sed 's/^[^:]*:"*//'
}
close() { # close A B RELTOL: |A - B| <= RELTOL * |B|
    awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; m = b < 0 ? -b : b;
        exit !(a != "" && d <= t * m) }'
}

"$tk" generate torus 2 3 --vertices 90 >"$tmp/trefoil.vect"
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 40 --json -o "$tmp/out.vect" \
    --struts "$tmp/struts.json" --log "$tmp/log.tsv" --snapshots "$tmp/snaps" --every 10 \
    >"$tmp/result.json" 2>"$tmp/err"
check $? "tighten exits 0: $(cat "$tmp/err")"
[ "$(value steps "$tmp/result.json")" = 40 ]
check $? "--json steps: $(cat "$tmp/result.json")"
[ "$(value stop_reason "$tmp/result.json")" = steps ]
check $? "stop_reason steps"
rope=$(value ropelength "$tmp/result.json")
"$tk" info "$tmp/out.vect" --json >"$tmp/info.json"
check $? "info reads the output"
close "$(value ropelength "$tmp/info.json")" "$rope" 1e-12
check $? "info on the output gives $(value ropelength "$tmp/info.json"), tighten said $rope"
close "$(value thickness "$tmp/info.json")" "$(value thickness "$tmp/result.json")" 1e-12
check $? "thickness agrees"
[ "$(value vertices "$tmp/info.json")" = "$(value vertices "$tmp/result.json")" ]
check $? "vertex count agrees"
# the log: a header, the start (step 0) and one line per step
[ "$(wc -l <"$tmp/log.tsv")" -eq 42 ]
check $? "log has $(wc -l <"$tmp/log.tsv") lines, want 42"
last=$(tail -n 1 "$tmp/log.tsv" | cut -f 1,3)
[ "$(echo "$last" | cut -f 1)" = 40 ]
check $? "the log's last step is 40: $last"
close "$(echo "$last" | cut -f 2)" "$rope" 1e-11
check $? "the log's last ropelength $(echo "$last" | cut -f 2) is the result $rope"
# ropelength only falls... or the log says why not: every thickness is at
# least the diameter minus the overstep tolerance
awk -F'\t' 'NR > 1 && $5 < 1 - 1.0001e-5 { bad = 1 } END { exit bad }' "$tmp/log.tsv"
check $? "every logged thickness is within the overstep tolerance of the diameter"
[ "$(ls "$tmp/snaps" | wc -l)" -eq 5 ]
check $? "snapshots: $(ls "$tmp/snaps" | tr '\n' ' ') (want steps 0, 10, 20, 30, 40)"
"$tk" info "$tmp/snaps/step-000040.vect" --json >"$tmp/snap.json"
close "$(value ropelength "$tmp/snap.json")" "$rope" 1e-12
check $? "the last snapshot is the final curve"
n_struts=$(value struts "$tmp/result.json")
[ "$(grep -o '"force"' "$tmp/struts.json" | wc -l)" -ge "$n_struts" ]
check $? "struts file lists forces for $n_struts struts"

# the text summary says what error recovery's last resorts did: this
# start (loose once autoscaled) needs neither an undone step nor a rescale
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 40 >"$tmp/summary.txt" 2>"$tmp/err"
check $? "tighten (text) exits 0: $(cat "$tmp/err")"
grep -q "^  recovery: 0 steps undone and taken shorter, 0 rescales of the whole curve$" \
    "$tmp/summary.txt"
check $? "the summary's recovery line: $(grep recovery "$tmp/summary.txt")"

# --json reports the counts the summary does, by the same names as
# TK_RECOVERY_FIELDS: 1,000 steps of this start judge some step by its
# length or after its correction
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 1000 >"$tmp/long.txt" 2>"$tmp/err"
check $? "tighten (text, 1,000 steps) exits 0: $(cat "$tmp/err")"
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 1000 --json >"$tmp/long.json" 2>"$tmp/err"
check $? "tighten --json (1,000 steps) exits 0: $(cat "$tmp/err")"
judged=$(sed -n 's/^  step control: \([0-9]*\) steps* judged by the length alone.*/\1/p' \
    "$tmp/long.txt")
given=$(value length_steps "$tmp/long.json")
[ "$given" = "${judged:-0}" ]
check $? "--json's length_steps $given is the summary's ${judged:-none}"
corrected=$(sed -n 's/^  step control: \([0-9]*\) steps* judged after their correction.*/\1/p' \
    "$tmp/long.txt")
given_corrected=$(value corrected_steps "$tmp/long.json")
[ "$given_corrected" = "${corrected:-0}" ]
check $? "--json's corrected_steps $given_corrected is the summary's ${corrected:-none}"
[ $((${judged:-0} + ${corrected:-0})) -gt 0 ]
check $? "1,000 steps judge some step by its length or after its correction"
said=$(sed -n 's/^  recovery: \([0-9]*\) steps undone and taken shorter, \([0-9]*\) rescales.*/\1 \2/p' \
    "$tmp/long.txt")
given="$(value undone_steps "$tmp/long.json") $(value rescales "$tmp/long.json")"
[ -n "$said" ] && [ "$given" = "$said" ]
check $? "--json's undone_steps and rescales ($given) are the summary's ${said:-none}"

# An escape's try still on a coarse level when the last fifth of the
# budget begins gives way to the best curve, which is on the final
# polygon: the run stays there, and the polish that follows is kept.
# (with 3,500 steps a far try is on its coarse polygon at step 2,800;
# with 3,000 the reserve finds the try before it on the final polygon)
"$tk" tighten "$tmp/trefoil.vect" --autoscale --resolution 5 --steps 3500 --json \
    --log "$tmp/reserve.tsv" >"$tmp/reserve.json" 2>"$tmp/err"
check $? "tighten --steps 3500 with escapes exits 0: $(cat "$tmp/err")"
# the put-back: restarts up by one, vertices from fewer than the final
# count to it; then the rows after it off the final count (the columns by
# the log's header)
awk -F'\t' 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    { v[NR] = $col["vertices"]; r[NR] = $col["restarts"]; p[NR] = $col["ropelength"]
      if (v[NR] > final) final = v[NR]; n = NR }
    END { for (i = 3; i <= n; i++)
              if (!at && r[i] == r[i - 1] + 1 && v[i - 1] < final && v[i] == final) at = i
          for (i = at + 1; at && i <= n; i++) off += v[i] != final
          printf "%d %d %.17g\n", at ? at - 2 : -1, off, at ? p[at] : 0 }' \
    "$tmp/reserve.tsv" >"$tmp/putback"
read -r putback off from <"$tmp/putback"
[ "$putback" -ge 2800 ]
check $? "a try on a coarse level gave way to the best at the reserve (step $putback, want >= 2800)"
[ "$off" -eq 0 ]
check $? "the best put back stays on the final polygon ($off rows left it)"
awk -v a="$(value ropelength "$tmp/reserve.json")" -v b="$from" 'BEGIN { exit !(a < b) }'
check $? "the polish of the best is kept: $(value ropelength "$tmp/reserve.json") < $from"

# --re-resolve keeps the resolution as the knot tightens: fewer vertices
# at the end than at the start, about resolution * ropelength of them
"$tk" tighten "$tmp/trefoil.vect" --autoscale --resolution 5 --re-resolve 0.05 --steps 300 \
    --json --log "$tmp/rr.tsv" -o "$tmp/rr.vect" >"$tmp/rr.json" 2>"$tmp/err"
check $? "tighten --re-resolve exits 0: $(cat "$tmp/err")"
# the start has ceil(5 * its ropelength) vertices
first=$(awk -F'\t' 'NR == 2 { v = 5 * $3; printf "%d", (v == int(v)) ? v : int(v) + 1 }' "$tmp/rr.tsv")
last=$(value vertices "$tmp/rr.json")
rr_rope=$(value ropelength "$tmp/rr.json")
[ -n "$first" ] && [ "$last" -lt "$first" ]
check $? "re-resolution: $first vertices at the start, $last at the end"
awk -v v="$last" -v r="$rr_rope" 'BEGIN { exit !(v >= 5 * r && v <= 5 * r * 1.06 + 1) }'
check $? "re-resolution: $last vertices for ropelength $rr_rope at resolution 5"
"$tk" info "$tmp/rr.vect" --json >"$tmp/rr-info.json"
close "$(value ropelength "$tmp/rr-info.json")" "$rr_rope" 1e-12
check $? "re-resolved output measured again: $(value ropelength "$tmp/rr-info.json") vs $rr_rope"

# the knot type: the input's and the result's, both the trefoil's
"$tk" generate torus 2 3 >"$tmp/t23.vect"
"$tk" tighten "$tmp/t23.vect" --json --steps 20 >"$tmp/type.json" 2>"$tmp/err"
check $? "tighten --json --steps 20 exits 0: $(cat "$tmp/err")"
type_start=$(sed -n 's/.*"invariants":{"start":{\([^}]*\)},"result":{\([^}]*\)}}.*/\1/p' "$tmp/type.json")
type_result=$(sed -n 's/.*"invariants":{"start":{\([^}]*\)},"result":{\([^}]*\)}}.*/\2/p' "$tmp/type.json")
for part in start result; do
    eval "t=\$type_$part"
    case $t in *'"alexander":[[1,-1,1]],"alexander_text":["1 - t + t^2"],"determinants":[3],'*) true ;; *) false ;; esac
    check $? "tighten --json: the $part's type is the trefoil's: '$t'"
done
# resampled to ceil(0.1 * ropelength) = 4 vertices the trefoil is an
# unknot: the run fails, exit 2, with the engine's message as it is
"$tk" tighten "$tmp/t23.vect" --resolution 0.1 --autoscale --json >"$tmp/out" 2>"$tmp/err"
status=$?
[ "$status" -eq 2 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] &&
    grep -q "^tightknot: $tmp/t23.vect: resampling to 4 vertices (resolution 0.1): .*Alexander polynomial was 1 - t + t^2, now 1\$" "$tmp/err"
check $? "a run that changes the type: exit $status, $(cat "$tmp/err")"

# bad options: exit 1, named
for args in "--radius 0" "--lambda -1" "--steps 2.5" "--resolution -1" "--time abc" \
    "--residual nan" "--overstep 0.5" "--every 0" "--re-resolve 1" "--re-resolve 0.1 --steps 9" \
    "--escapes -1" "--escapes 1001" "--seed x" "--frobnicate 1"; do
    # shellcheck disable=SC2086
    "$tk" tighten "$tmp/trefoil.vect" $args >/dev/null 2>"$tmp/err"
    status=$?
    opt=$(echo "$args" | cut -d' ' -f1)
    [ "$status" -eq 1 ] && grep -q -- "$opt" "$tmp/err"
    check $? "tighten $args: exit $status, message $(head -n 1 "$tmp/err")"
done
# bad input: exit 2, the line named
printf 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 q 0\n' >"$tmp/bad.vect"
"$tk" tighten "$tmp/bad.vect" >/dev/null 2>"$tmp/err"
[ $? -eq 2 ] && grep -q "bad.vect:7: expected coordinate y" "$tmp/err"
check $? "a malformed file: $(cat "$tmp/err")"
# a start thinner than the tube with every option as given (--steps)
# and without --autoscale: exit 2, said why
"$tk" generate torus 2 3 --vertices 90 >"$tmp/thin.vect"
"$tk" tighten "$tmp/thin.vect" --radius 50 --steps 10 >/dev/null 2>"$tmp/err"
[ $? -eq 2 ] && grep -qi "thick\|diameter" "$tmp/err"
check $? "a start thinner than the tube: $(cat "$tmp/err")"
# the defaults that tighten: a Hopf link far thinner than the tube, no
# option but the radius, ends converged within 0.1% of the exact 8 pi
# (the polygon's own error at resolution 5 is about 0.08%), with the
# options it ran with shown
"$tk" generate chain 2 --vertices 40 >"$tmp/hopf-default.vect"
"$tk" tighten "$tmp/hopf-default.vect" --radius 50 --json >"$tmp/default.json" 2>"$tmp/err"
check $? "tighten with no options: $(cat "$tmp/err")"
node -e '
const j = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")), o = j.options;
const tight = 8 * Math.PI;
if (j.stop_reason !== "converged") throw new Error(`stopped: ${j.stop_reason}`);
if (!(j.ropelength > tight && j.ropelength < tight * 1.001)) throw new Error(`ropelength ${j.ropelength}`);
if (!(o.resolution === 5 && o.autoscale === true && o.converge === true && o.work === 120 && o.time === 0 &&
      o.steps === 0))
    throw new Error(`options ${JSON.stringify(o)}`);
' "$tmp/default.json"
check $? "no options: converged at the tight Hopf link ($(head -c 300 "$tmp/default.json"))"
# escapes: a Hopf link tightened to convergence is deformed and tightened
# again; the same seed gives the same figures, the result is no worse than
# any escape reached, and the log counts the tries
"$tk" generate chain 2 --vertices 40 >"$tmp/hopf.vect"
for k in 1 2; do
    "$tk" tighten "$tmp/hopf.vect" --autoscale --steps 1200 --escapes 2 --seed 5 --json \
        --log "$tmp/escapes$k.tsv" >"$tmp/escapes$k.json" 2>"$tmp/err"
    check $? "tighten with escapes: $(cat "$tmp/err")"
done
cmp -s "$tmp/escapes1.json" "$tmp/escapes2.json" ||
    [ "$(sed 's/"seconds":[^,]*//' "$tmp/escapes1.json")" = \
        "$(sed 's/"seconds":[^,]*//' "$tmp/escapes2.json")" ]
check $? "the same seed, the same run: $(cat "$tmp/escapes1.json") / $(cat "$tmp/escapes2.json")"
tries=$(grep -o '"improved"' "$tmp/escapes1.json" | wc -l)
[ "$tries" -ge 1 ] && [ "$(tail -n 1 "$tmp/escapes1.json" | grep -c '"escapes":\[')" -eq 1 ]
check $? "escapes listed: $(cat "$tmp/escapes1.json")"
rope=$(value ropelength "$tmp/escapes1.json")
reached=$(sed 's/.*"escapes":\[//' "$tmp/escapes1.json" | grep -o '"reached":[0-9.e+-]*' |
    cut -d: -f2)
for r in $reached; do
    awk -v a="$rope" -v b="$r" 'BEGIN { exit !(a <= b * (1 + 1e-12)) }'
    check $? "the result $rope is no worse than an escape's $r"
done
col=$(head -n 1 "$tmp/escapes1.tsv" | tr '\t' '\n' | grep -nx escapes | cut -d: -f1)
[ -n "$col" ] && [ "$(tail -n 1 "$tmp/escapes1.tsv" | cut -f"$col")" -eq "$tries" ]
check $? "the log's escapes column: $(tail -n 1 "$tmp/escapes1.tsv")"

# Two outputs naming one file, or --log or --struts naming the input, are
# refused before any work (exit 1), the input untouched; -o IN tightens
# the file in place.
cp "$tmp/trefoil.vect" "$tmp/in.vect"
sum=$(cksum <"$tmp/in.vect")
for args in "-o $tmp/in.vect --log $tmp/in.vect" "--log $tmp/in.vect" \
    "--struts $tmp/../$(basename "$tmp")/in.vect" "-o $tmp/same --struts $tmp/same" \
    "-o $tmp/same2 --log $tmp/./same2"; do
    cp "$tmp/trefoil.vect" "$tmp/in.vect"
    # shellcheck disable=SC2086
    "$tk" tighten "$tmp/in.vect" --autoscale --steps 3 $args >"$tmp/out" 2>"$tmp/err"
    st=$?
    [ "$st" -eq 1 ] && grep -q -e "one file" -e "names the input" "$tmp/err" &&
        [ "$(cksum <"$tmp/in.vect")" = "$sum" ] && [ ! -e "$tmp/same" ] && [ ! -e "$tmp/same2" ]
    check $? "tighten IN $args: exit $st, $(cat "$tmp/err")"
done
cp "$tmp/trefoil.vect" "$tmp/in.vect"
"$tk" tighten "$tmp/in.vect" --autoscale --steps 3 -o "$tmp/in.vect" --log "$tmp/in.tsv" \
    >/dev/null 2>"$tmp/err" && "$tk" info "$tmp/in.vect" >/dev/null
check $? "tighten IN -o IN: in place: $(cat "$tmp/err")"

# "-" as -o or --struts: the file on standard output, byte for byte what
# a named file gets, and the report (text or --json) on standard error
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 40 -o "$tmp/named.vect" \
    --struts "$tmp/named.json" >/dev/null 2>&1
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 40 -o - >"$tmp/piped.vect" \
    2>"$tmp/report.txt"
check $? "tighten -o - exits 0: $(head -c 200 "$tmp/report.txt")"
cmp -s "$tmp/named.vect" "$tmp/piped.vect"
check $? "-o - writes the VECT a named file gets"
grep -q "40 steps" "$tmp/report.txt"
check $? "-o -: the report goes to standard error: $(head -c 200 "$tmp/report.txt")"
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 40 --struts - --json \
    >"$tmp/piped.json" 2>"$tmp/report.json"
cmp -s "$tmp/named.json" "$tmp/piped.json"
check $? "--struts - writes the struts file a named file gets"
[ "$(value steps "$tmp/report.json")" = 40 ]
check $? "--struts - --json: the JSON report goes to standard error"
"$tk" tighten "$tmp/trefoil.vect" -o - --struts - >/dev/null 2>"$tmp/err"
[ $? -eq 1 ] && grep -q "name one file" "$tmp/err"
check $? "-o - and --struts - together: usage error: $(cat "$tmp/err")"
"$tk" tighten "$tmp/trefoil.vect" --log - >/dev/null 2>"$tmp/err"
[ $? -eq 1 ] && grep -q "name a file" "$tmp/err"
check $? "--log -: usage error: $(cat "$tmp/err")"


# --progress when standard error is not a terminal: plain lines with the
# share of the budget and the time left; no nan at the start
"$tk" tighten "$tmp/trefoil.vect" --autoscale --steps 300 --progress >/dev/null 2>"$tmp/progress"
check $? "tighten --progress: $(head -c 200 "$tmp/progress")"
grep -q "^tightknot: step       0 .*residual - .*  0% of the budget" "$tmp/progress" &&
    grep -q "of the budget, [0-9]* s left" "$tmp/progress" && ! grep -qi nan "$tmp/progress"
check $? "--progress lines: $(head -c 400 "$tmp/progress")"

# the flow time: every logged step's is the step sizes summed
"$tk" tighten "$tmp/hopf.vect" --autoscale --steps 400 --escapes 0 --log "$tmp/film.tsv" \
    --snapshots "$tmp/snaps" --every 10 >/dev/null 2>"$tmp/err"
check $? "tighten with snapshots: $(cat "$tmp/err")"
awk -F'\t' 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    { sum += $col["step_size"]; d = $col["flow_time"] - sum; if (d < 0) d = -d
      if (d > 1e-12 * (sum > 1 ? sum : 1)) { print "step " $1 ": " $col["flow_time"] " against " sum; bad = 1 } }
    END { exit bad || NR < 400 }' "$tmp/film.tsv"
check $? "flow_time is the step sizes summed"
# frames at equal flow time, checked against every snapshot (brute force):
# no snapshot is nearer a film frame's time than the one picked
"$tk" frames "$tmp/film.tsv" "$tmp/snaps" --count 25 -o "$tmp/film" >"$tmp/frames.tsv" 2>"$tmp/err"
check $? "frames: $(cat "$tmp/err")"
[ "$(ls "$tmp/film" | wc -l)" -eq 25 ] && [ "$(tail -n +2 "$tmp/frames.tsv" | wc -l)" -eq 25 ]
check $? "frames --count 25 writes 25 frames: $(ls "$tmp/film" | head -3)"
awk -F'\t' 'FNR == 1 { f++; if (f == 1) for (i = 1; i <= NF; i++) col[$i] = i; next }
    f == 1 { if ($1 % 10 == 0 && !($1 in t)) { t[$1] = $col["flow_time"]; n++ } next }
    { pick[$1] = $2; m = $1 }
    END { lo = t[0]; hi = 0; for (s in t) if (t[s] > hi) hi = t[s]
          for (k = 1; k <= m; k++) { want = lo + (hi - lo) * (k - 1) / (m - 1)
              d = t[pick[k]] - want; if (d < 0) d = -d
              for (s in t) { e = t[s] - want; if (e < 0) e = -e; if (e < d - 1e-12) { print "frame " k ": step " pick[k] ", step " s " is nearer"; bad = 1 } } }
          exit bad || m != 25 }' "$tmp/film.tsv" "$tmp/frames.tsv"
check $? "each film frame is the snapshot nearest its time"
cmp -s "$tmp/film/frame-0001.vect" "$tmp/snaps/step-000000.vect" &&
    cmp -s "$tmp/film/frame-0025.vect" "$tmp/snaps/step-000400.vect"
check $? "the film runs from the first snapshot to the last"
span=$(tail -n 1 "$tmp/frames.tsv" | cut -f3) # the first frame's time is 0
"$tk" frames "$tmp/film.tsv" "$tmp/snaps" --every-time "$span" -o "$tmp/film2" >/dev/null 2>"$tmp/err"
[ $? -eq 0 ] && [ "$(ls "$tmp/film2" | wc -l)" -eq 2 ]
check $? "frames --every-time the whole span: the first and the last ($(ls "$tmp/film2" | tr '\n' ' ') $(cat "$tmp/err"))"
printf 'step\tropelength\n0\t1\n' >"$tmp/nolog.tsv"
"$tk" frames "$tmp/nolog.tsv" "$tmp/snaps" >/dev/null 2>"$tmp/err"
[ $? -eq 2 ] && grep -q "nolog.tsv:1: no step and flow_time columns" "$tmp/err"
check $? "frames with a log lacking flow_time: exit 2, the line named: $(cat "$tmp/err")"
"$tk" frames "$tmp/film.tsv" >/dev/null 2>"$tmp/err"
[ $? -eq 1 ]
check $? "frames without DIR: usage error: $(cat "$tmp/err")"

# Constraints on vertices: a rope between the planes x = -5 and x = 5 given
# on the command line tightens to their distance (exact: 10), its output
# keeps them for the next run, the struts file gives each end the rope's
# unit tension; a constraint that cannot hold is refused, naming it.
awk 'BEGIN { n = 40; print "VECT"; print "1 " n " 0"; print n; print 0
    for (k = 0; k < n; k++) { s = k / (n - 1)
        printf "%.17g %.17g %.17g\n", -5 + 10 * s, 3 * s + 1.5 * sin(6.283185307179586 * s), 0.8 * sin(3.141592653589793 * s) } }' \
    >"$tmp/rope.vect"
"$tk" tighten "$tmp/rope.vect" --vertices 80 --steps 1500 --escapes 0 --constrain 0:0=plane:1,0,0,-5 \
    --constrain 0:39=plane:2,0,0,10 --json -o "$tmp/rope-out.vect" --struts "$tmp/rope-struts.json" \
    >"$tmp/rope.json" 2>"$tmp/err"
check $? "tighten --constrain: $(cat "$tmp/err")"
close "$(value length "$tmp/rope.json")" 10 1e-6
check $? "the rope between the planes is their distance: $(value length "$tmp/rope.json")"
[ "$(grep -c '^# Constraint [12] Plane' "$tmp/rope-out.vect")" -eq 2 ] &&
    [ "$(grep -c '# Cst: [12]$' "$tmp/rope-out.vect")" -eq 2 ]
check $? "the output keeps its constraints: $(grep '#' "$tmp/rope-out.vect" | tr '\n' ' ')"
"$tk" info --json "$tmp/rope-out.vect" >"$tmp/rope-info.json" 2>"$tmp/err" &&
    node -e 'const i = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
        process.exit(JSON.stringify(i.constraints) === JSON.stringify(["0:0=plane:1,0,0,-5", "0:79=plane:1,0,0,5"]) ? 0 : 1)' \
        "$tmp/rope-info.json" &&
    "$tk" info "$tmp/rope-out.vect" | grep -q ", 2 constrained vertices$"
check $? "info lists them: $(cat "$tmp/rope-info.json" "$tmp/err")"
node -e 'const s = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
    process.exit(s.constraints.length === 2 && s.constraints.every((c) => Math.abs(c.force - 1) < 1e-6) &&
        s.constraints[1].constraint === "0:79=plane:1,0,0,5" ? 0 : 1)' "$tmp/rope-struts.json"
check $? "the ends' forces are the unit tension: $(cat "$tmp/rope-struts.json" | tr -d '\n' | cut -c1-300)"
"$tk" tighten "$tmp/rope-out.vect" --steps 10 --escapes 0 --json >"$tmp/again.json" 2>"$tmp/err"
close "$(value length "$tmp/again.json")" 10 1e-6
check $? "tightened again from its output, the rope stays at 10: $(value length "$tmp/again.json") $(cat "$tmp/err")"
"$tk" tighten "$tmp/rope.vect" --steps 10 --constrain 0:5=plane:0,0,1,7 >/dev/null 2>"$tmp/err"
[ $? -eq 2 ] && grep -q "constraint 0:5=plane:0,0,1,7: its vertex is" "$tmp/err"
check $? "a start off its constraint: exit 2, the constraint named: $(cat "$tmp/err")"
"$tk" tighten "$tmp/rope.vect" --steps 10 --constrain 0:40=free >/dev/null 2>"$tmp/err"
[ $? -eq 1 ] && grep -q "component 0 has no vertex 40" "$tmp/err"
check $? "a constraint on a vertex that does not exist: usage error: $(cat "$tmp/err")"

echo "cli-tighten: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
