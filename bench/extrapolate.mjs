// The smooth limit of a knot's ropelength from its tight polygons.
//
// A tight polygon of N vertices is longer than the smooth tight knot by an
// excess that falls like a power of N (about N^-2 for the trefoil: the
// chords of a curve of bounded curvature).  This tightens the knot at N,
// 2N, 4N, ... vertices, each level from the last one's curve (the first
// from the file, with the escapes, to find the basin; the later ones
// refined only: no coarse levels, no escapes), fits
//
//     R(N) = c + a N^-p
//
// with the exponent p taken from the figures, not assumed, and prints the
// smooth estimate c with an error bar and the fit's residuals.  The error
// bar is the larger of two: how far c moves when each level's figure moves
// by its own floor (what its last quarter of processor time still took
// off: a level stopped before its floor is that uncertain), and, with four
// levels or more, how far c moves when one level is left out.  Each level's
// result is kept in the work directory and a run again reuses it, so a
// long run can be stopped and taken up.  Prints figures; never fails on
// time.
//
//   node bench/extrapolate.mjs [options] [KNOT]
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { basename, join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const USAGE = `usage: node bench/extrapolate.mjs [options] [KNOT]
Tightens KNOT (a catalogue name such as 3.1, or a VECT file; default 3.1)
at N, 2N, 4N, ... vertices, each level from the last one's curve, and fits
R(N) = c + a N^-p (p from the figures) for the smooth limit c.
  --catalogue DIR   where a name is looked up (default ../shared/catalogue)
  --build DIR       the programs (default build)
  --vertices N      the first level's vertices (default 1200)
  --levels K        how many levels: N ... 2^(K-1) N (default 4)
  --seconds S,...   processor seconds of each level, the last one repeated
                    (default 300,600,1200,2400: 75 minutes in all)
  --out DIR         work directory (default build/extrapolate/KNOT); a level
                    whose result is there is not run again
  --reference X     also print the estimate's distance from X (the
                    trefoil's smooth value by Przybyl and Pieranski is
                    32.742934)
  --fit N:R[:U],... fit these figures only (U: each one's uncertainty,
                    default 0), run nothing
  --json            print the fit as one JSON object
  -h, --help        this help`;

// The least-squares c and a for a fixed p (unweighted): R = c + a x,
// x = N^-p.  Returns {c, a, sse}.
function linearFit(points, p) {
    const n = points.length;
    let sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const { n: N, r } of points) {
        const x = N ** -p;
        sx += x;
        sy += r;
        sxx += x * x;
        sxy += x * r;
    }
    const det = n * sxx - sx * sx;
    const a = det !== 0 ? (n * sxy - sx * sy) / det : 0;
    const c = (sy - a * sx) / n;
    let sse = 0;
    for (const { n: N, r } of points) sse += (c + a * N ** -p - r) ** 2;
    return { c, a, sse };
}

const P_LOW = 0.25;
const P_HIGH = 8;

// Fits R(N) = c + a N^-p to at least three points {n, r}: p minimises
// the squared residuals (a scan of log p, then golden-section search
// around the best), c and a are linear in it.  Throws when the figures do
// not fall towards a limit (a <= 0: no excess that shrinks with N).
export function fitPower(points) {
    if (points.length < 3) throw new Error('a fit needs three levels or more');
    const ps = [];
    for (let k = 0; k <= 200; k++) ps.push(P_LOW * (P_HIGH / P_LOW) ** (k / 200));
    let best = 0;
    const sse = ps.map((p) => linearFit(points, p).sse);
    for (let k = 1; k < ps.length; k++) if (sse[k] < sse[best]) best = k;
    let lo = ps[Math.max(0, best - 1)], hi = ps[Math.min(ps.length - 1, best + 1)];
    const g = (Math.sqrt(5) - 1) / 2;
    let x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    let f1 = linearFit(points, x1).sse, f2 = linearFit(points, x2).sse;
    for (let it = 0; it < 200 && hi - lo > 1e-12 * hi; it++) {
        if (f1 < f2) {
            hi = x2; x2 = x1; f2 = f1;
            x1 = hi - g * (hi - lo); f1 = linearFit(points, x1).sse;
        } else {
            lo = x1; x1 = x2; f1 = f2;
            x2 = lo + g * (hi - lo); f2 = linearFit(points, x2).sse;
        }
    }
    const p = (lo + hi) / 2;
    const { c, a } = linearFit(points, p);
    if (!(a > 0) || p < P_LOW * (1 + 1e-6) || p > P_HIGH * (1 - 1e-6))
        throw new Error('the figures do not fall towards a limit like a power of N ' +
            `(the best fit has p = ${p.toPrecision(4)}, a = ${a.toPrecision(4)})`);
    const residuals = points.map(({ n: N, r }) => r - (c + a * N ** -p));
    return { c, a, p, residuals };
}

// The fit with its error bar: points {n, r, u}, u each figure's own
// uncertainty.  floor: the half-range of c over every choice of r +- u;
// leaveOut (four points or more): the largest move of c with one point
// left out.  error = the larger; Infinity where a choice within the
// floors, or a point left out, has no fit.
export function extrapolate(points) {
    const fit = fitPower(points);
    let lo = fit.c, hi = fit.c;
    const k = points.length;
    if (points.some((q) => q.u > 0)) {
        for (let mask = 0; mask < 1 << k; mask++) {
            const moved = points.map((q, i) => ({ n: q.n, r: q.r + (mask >> i & 1 ? q.u : -q.u) }));
            try {
                const c = fitPower(moved).c;
                lo = Math.min(lo, c);
                hi = Math.max(hi, c);
            } catch {
                hi = Infinity; /* within its floor a level can undo the fit: no bound */
            }
        }
    }
    const floor = (hi - lo) / 2;
    let leaveOut = 0;
    if (k >= 4)
        for (let i = 0; i < k; i++) {
            try {
                const c = fitPower(points.filter((_, j) => j !== i)).c;
                leaveOut = Math.max(leaveOut, Math.abs(c - fit.c));
            } catch {
                leaveOut = Infinity;
            }
        }
    return { ...fit, floor, leaveOut, error: Math.max(floor, leaveOut) };
}

function parseArgs(argv) {
    const o = {
        knot: '3.1', catalogue: '../shared/catalogue', build: 'build', vertices: 1200,
        levels: 4, seconds: [300, 600, 1200, 2400], out: null, reference: null, fit: null,
        json: false,
    };
    const number = (name, v, min) => {
        const x = Number(v);
        if (!Number.isFinite(x) || x < min) throw new Error(`${name}: ${v} is not a number >= ${min}`);
        return x;
    };
    for (let i = 0; i < argv.length; i++) {
        const a = argv[i];
        const next = () => {
            if (i + 1 >= argv.length) throw new Error(`${a} needs a value`);
            return argv[++i];
        };
        if (a === '-h' || a === '--help') o.help = true;
        else if (a === '--catalogue') o.catalogue = next();
        else if (a === '--build') o.build = next();
        else if (a === '--vertices') o.vertices = Math.round(number(a, next(), 8));
        else if (a === '--levels') o.levels = Math.round(number(a, next(), 3));
        else if (a === '--seconds') o.seconds = next().split(',').map((s) => number(a, s, 0.1));
        else if (a === '--out') o.out = next();
        else if (a === '--reference') o.reference = number(a, next(), 0);
        else if (a === '--json') o.json = true;
        else if (a === '--fit')
            o.fit = next().split(',').map((t) => {
                const [n, r, u] = t.split(':');
                if (r === undefined) throw new Error(`--fit: ${t} is not N:R or N:R:U`);
                return { n: number('--fit', n, 1), r: number('--fit', r, 0), u: u === undefined ? 0 : number('--fit', u, 0) };
            });
        else if (a.startsWith('-')) throw new Error(`unknown option ${a}`);
        else o.knot = a;
    }
    return o;
}

// A level's uncertainty: what the ropelength fell by over the last
// quarter of the level's processor time (its --log).
function floorOf(logFile) {
    const lines = readFileSync(logFile, 'utf8').trim().split('\n');
    const head = lines[0].split('\t');
    const sec = head.indexOf('seconds'), rope = head.indexOf('ropelength');
    const rows = lines.slice(1).map((l) => l.split('\t')).map((f) => [Number(f[sec]), Number(f[rope])]);
    const end = rows[rows.length - 1];
    const from = rows.find(([s]) => s >= 0.75 * end[0]) ?? end;
    return Math.max(0, from[1] - end[1]);
}

function runLevel(o, dir, level, start, count, seconds) {
    const name = join(dir, `level-${count}`);
    if (existsSync(`${name}.json`)) {
        const done = JSON.parse(readFileSync(`${name}.json`, 'utf8'));
        if (done.vertices === count && done.options?.time === seconds) return done;
    }
    const args = ['tighten', start, '--vertices', String(count), '--autoscale', '--time', String(seconds),
        '--cpu-time', '--json', '-o', `${name}.vect`, '--log', `${name}.tsv`];
    if (level > 0) args.push('--no-coarse', '--escapes', '0');
    process.stderr.write(`bench/extrapolate: level ${level + 1}, ${count} vertices, ${seconds} s from ${start}\n`);
    const run = spawnSync(join(o.build, 'tightknot'), args, { encoding: 'utf8', maxBuffer: 1 << 28 });
    if (run.status !== 0) throw new Error(`tightknot ${args.join(' ')} failed: ${run.stderr.trim()}`);
    writeFileSync(`${name}.json`, run.stdout);
    return JSON.parse(run.stdout);
}

function report(o, fit, points) {
    if (o.json) {
        console.log(JSON.stringify({ levels: points, ...fit, reference: o.reference }));
        return;
    }
    console.log('vertices      ropelength     its floor     residual of the fit');
    points.forEach((q, i) =>
        console.log(`${String(q.n).padStart(8)}  ${q.r.toFixed(9).padStart(14)}  ${q.u.toExponential(2).padStart(10)}  ${fit.residuals[i].toExponential(2).padStart(10)}`));
    console.log(`fit: R(N) = c + a N^-p, p = ${fit.p.toFixed(4)}, a = ${fit.a.toPrecision(6)}`);
    console.log(`smooth estimate c = ${fit.c.toFixed(7)} +- ${fit.error.toExponential(2)} ` +
        `(the levels' floors: ${fit.floor.toExponential(2)}; one level left out: ` +
        `${points.length >= 4 ? fit.leaveOut.toExponential(2) : 'needs four levels'})`);
    if (o.reference !== null) {
        const d = fit.c - o.reference;
        console.log(`against ${o.reference}: ${d >= 0 ? '+' : ''}${d.toExponential(2)} ` +
            `(${(d / o.reference).toExponential(2)} relative), ` +
            `${Math.abs(d) <= fit.error ? 'inside' : 'outside'} the error bar`);
    }
}

function main() {
    let o;
    try {
        o = parseArgs(process.argv.slice(2));
    } catch (e) {
        console.error(`bench/extrapolate: ${e.message}\n${USAGE}`);
        process.exit(2);
    }
    if (o.help) {
        console.log(USAGE);
        return;
    }
    try {
        if (o.fit) {
            report(o, extrapolate(o.fit), o.fit);
            return;
        }
        const file = o.knot.endsWith('.vect') ? o.knot : join(o.catalogue, `${o.knot}.vect`);
        if (!existsSync(file)) throw new Error(`no file ${file}`);
        const dir = resolve(o.out ?? join('build', 'extrapolate', basename(file, '.vect')));
        mkdirSync(dir, { recursive: true });
        const points = [];
        let start = file;
        for (let level = 0; level < o.levels; level++) {
            const count = o.vertices * 2 ** level;
            const seconds = o.seconds[Math.min(level, o.seconds.length - 1)];
            const done = runLevel(o, dir, level, start, count, seconds);
            const name = join(dir, `level-${count}`);
            points.push({ n: done.vertices, r: done.ropelength, u: floorOf(`${name}.tsv`), seconds: done.seconds });
            start = `${name}.vect`;
        }
        report(o, extrapolate(points), points);
    } catch (e) {
        console.error(`bench/extrapolate: ${e.message}`);
        process.exit(1);
    }
}

if (process.argv[1] && import.meta.url === pathToFileURL(resolve(process.argv[1])).href) main();
