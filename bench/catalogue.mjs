// bench/catalogue.mjs: the whole catalogue through the service, each knot
// and link from several starts, the way a user would run it: a daemon
// (its own, or one given with --server) and `tightknot remote submit`.
//
// For each knot or link of the slice it makes starts of different shapes
// with the catalogue file's type (checked with `tightknot info` before
// any is submitted): the catalogue file itself, far deformations of it
// made by isotopy (`tightknot generate wander`, one per seed), the file turned inside out
// (`tightknot generate turn`: about its centroid, then points near it,
// one per seed), and the parametric forms
// whose type is the file's (torus knots and links, chains).  They are
// tightened with the same settings; the results land in OUT/results
// (the client's summary.tsv and one VECT and contacts file a start), and
// the table of every knot done so far, over every slice run into OUT, is
// written to TABLE: its type, the ropelength of each start, the lowest,
// the spread between the starts that converged (residual below 0.05; the
// others are listed apart, as still moving), how many of the lowest start's tightenings
// reached its lowest basin (the job's basins.best_reached; 1: found once),
// the struts and kinks and seconds of the lowest, the starts whose
// result's type (measured again with `tightknot info`, the link's
// determinant too) is not the file's, which are left out of the lowest
// and the spread, the settings.  Then a summary: how many knots
// have every start within 0.1% of their lowest, the widest spreads, how
// often the catalogue's own start was the one trapped, and by how much.
//
// It resumes: run again, it submits only the starts without a result
// (the client's own resume); its daemon's store keeps the jobs of a run
// that was stopped, which the next run's daemon takes up again.  A slice
// K/N takes every N-th knot from the K-th, so the table fills over runs;
// a knot without results in OUT keeps its row of the table as it was
// (the tightened curves are not committed, the table is), so a clean
// clone goes on filling it.  Each slice run's daemon figures (jobs
// ended, the workers' busy seconds, from /metrics) are added to
// TABLE-daemon.tsv beside it.
// Prints figures; never fails on time.
//
// usage: node bench/catalogue.mjs [options] [CATALOGUE_DIR]
//   --server URL      a running daemon (default: one of its own, its store
//                     OUT/jobs.db, one worker per core)
//   --token TOKEN     for a daemon with --tokens
//   --slice K/N       the K-th of N slices (default 1/1: all)
//   --work W          work per start, in seconds of the reference processor
//                     (tightknot tighten --work; default 60): counted from
//                     the run's own operations, so a start ends where it
//                     would on an idle machine whatever else runs beside
//                     it, and run again ends there again
//   --resolution R    vertices per unit ropelength (default 5)
//   --far K           far starts per knot (generate wander), seeds 1..K (default 1)
//   --turn K          turned starts per knot, seeds 0..K-1 (default 1)
//   --parallel N      starts running at once (default: the cores)
//   --worker-priority P  its own daemon's workers: normal (default), low or
//                     idle (tightknotd --worker-priority); idle workers
//                     get only what nothing else wants, and a slice beside
//                     other busy work then crawls
//   --loose K         the run option loose (0 to 2, default 2): the first
//                     tightening and the loose tries start K halvings below
//                     the coarse level
//   --engine ID       the engine's name in the settings column (default: the
//                     last commit that changed engine/ or include/tk/)
//   --out DIR         work directory (default build/catalogue)
//   --table FILE      the table (default docs/catalogue.tsv; the daemon's figures
//                     go to FILE without .tsv, then -daemon.tsv)
//   --build DIR       the programs (default build)
//   --only NAME,...   these knots only (a check of a few)
//   --table-only      write the table and summary from OUT, submit nothing

import { execFileSync, spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readdirSync, readFileSync, statSync, writeFileSync } from 'node:fs';
import { cpus } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const argv = process.argv.slice(2);
const opt = {
    server: null, token: process.env.TIGHTKNOT_TOKEN ?? null, slice: '1/1', work: 60,
    resolution: 5, far: 1, turn: 1, parallel: cpus().length, out: 'build/catalogue',
    table: 'docs/catalogue.tsv', build: 'build', only: null, tableOnly: false, loose: 2, engine: null,
    workerPriority: 'normal',
    catalogue: '../shared/catalogue',
};
for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
        if (i + 1 >= argv.length) usage(`${a} needs a value`);
        return argv[++i];
    };
    if (a === '--server') opt.server = value();
    else if (a === '--token') opt.token = value();
    else if (a === '--slice') opt.slice = value();
    else if (a === '--work') opt.work = Number(value());
    else if (a === '--resolution') opt.resolution = Number(value());
    else if (a === '--far') opt.far = Number(value());
    else if (a === '--turn') opt.turn = Number(value());
    else if (a === '--parallel') opt.parallel = Number(value());
    else if (a === '--worker-priority') opt.workerPriority = value();
    else if (a === '--loose') opt.loose = Number(value());
    else if (a === '--engine') opt.engine = value();
    else if (a === '--out') opt.out = value();
    else if (a === '--table') opt.table = value();
    else if (a === '--build') opt.build = value();
    else if (a === '--only') opt.only = value().split(',');
    else if (a === '--table-only') opt.tableOnly = true;
    else if (a === '-h' || a === '--help') usage(null);
    else if (a.startsWith('-')) usage(`unknown option ${a}`);
    else opt.catalogue = a;
}
const slice = /^(\d+)\/(\d+)$/.exec(opt.slice);
if (!slice || +slice[1] < 1 || +slice[1] > +slice[2]) usage(`--slice ${opt.slice}: expected K/N, 1 <= K <= N`);
for (const k of ['work', 'resolution', 'parallel'])
    if (!(opt[k] > 0)) usage(`--${k} must be positive`);
if (!(Number.isInteger(opt.far) && opt.far >= 0)) usage('--far must be a whole number >= 0');
if (!(Number.isInteger(opt.turn) && opt.turn >= 0)) usage('--turn must be a whole number >= 0');
if (!(Number.isInteger(opt.loose) && opt.loose >= 0 && opt.loose <= 2)) usage('--loose must be 0, 1 or 2');
if (!['normal', 'low', 'idle'].includes(opt.workerPriority)) usage('--worker-priority must be normal, low or idle');
// the settings a slice ran with, kept beside its results: the table's
// rows carry their own slice's
const settingsText = (loose, engine) => `resolution ${opt.resolution}, ${opt.work} s of work `
    + `a start, autoscale, default escapes${loose ? `, loose ${loose}` : ''}${engine ? `, engine ${engine}` : ''}`;
if (opt.engine === null) {
    const git = spawnSync('git', ['log', '-1', '--format=%h', '--', 'engine', 'include/tk'],
        { encoding: 'utf8', cwd: resolve(dirname(fileURLToPath(import.meta.url)), '..') });
    opt.engine = git.status === 0 ? git.stdout.trim() : '';
}
const SETTINGS = settingsText(opt.loose, opt.engine);

function usage(why) {
    const text = readFileSync(new URL(import.meta.url), 'utf8').split('\n');
    const from = text.findIndex((l) => l.startsWith('// usage:'));
    const help = text.slice(from, text.findIndex((l, k) => k > from && !l.startsWith('//')))
        .map((l) => l.replace(/^\/\/ ?/, '')).join('\n');
    if (why) console.error(`bench/catalogue: ${why}`);
    (why ? console.error : console.log)(help);
    process.exit(why ? 1 : 0);
}

const CLI = resolve(opt.build, 'tightknot');
const DAEMON = resolve(opt.build, 'tightknotd');
for (const p of [CLI, DAEMON])
    if (!existsSync(p)) usage(`${p} is missing: build it with make`);
const out = resolve(opt.out);
const startsDir = join(out, 'starts');
// one results directory per slice (the client's summary holds the files
// of its own run only); the table reads them all
const resultsRoot = join(out, 'results');
const resultsDir = join(resultsRoot, opt.only ? `only-${opt.only.join('_')}`
    : `slice-${slice[1]}-of-${slice[2]}`);
// the daemon's figures of each slice run, committed beside the table (the
// results directories are not)
const DAEMON_LOG = opt.table.replace(/(\.tsv)?$/, '-daemon.tsv');
mkdirSync(startsDir, { recursive: true });
mkdirSync(resultsDir, { recursive: true });

// ---- the knots and their types

const natural = (a, b) => a.localeCompare(b, 'en', { numeric: true });
const knots = readdirSync(opt.catalogue)
    .filter((f) => /^\d+(\.\d+){1,2}\.vect$/.test(f))
    .map((f) => f.slice(0, -5))
    .sort(natural);
const mine = knots.filter((n, k) => k % +slice[2] === +slice[1] - 1 && (!opt.only || opt.only.includes(n)));

const info = (file) => JSON.parse(execFileSync(CLI, ['info', '--json', file], { encoding: 'utf8' }));
// The type as compared: Alexander polynomials, determinants, linking
// numbers up to sign (a mirror or a reversed component has the same
// ropelength) and the link's determinant (which alone tells 6.2.2 from
// T(2,6), and 6.2.3 from T(2,4)).
const typeKey = (inv) => JSON.stringify([inv.alexander, inv.determinants,
    inv.linking.map((row) => row.map(Math.abs)), inv.link_determinant ?? null]);
const typeText = (inv) => `det ${inv.determinants.join(',')}; ${inv.alexander_text.join(', ')}` +
    (inv.linking.length > 1 ? `; lk ${inv.linking.map((r) => r.join(' ')).join(' / ')}` +
        `; link det ${inv.link_determinant ?? '?'}` : '');

// The catalogue file's type, kept in STARTS/NAME.type.json; measured again
// when the kept one predates the link determinant.
function fileType(name) {
    const typeFile = join(startsDir, `${name}.type.json`);
    if (existsSync(typeFile)) {
        const kept = JSON.parse(readFileSync(typeFile, 'utf8'));
        if ('link_determinant' in kept) return kept;
    }
    const want = info(join(opt.catalogue, `${name}.vect`)).invariants;
    writeFileSync(typeFile, JSON.stringify(want));
    return want;
}

// The parametric forms worth trying for a name K.N or K.C.N (crossings K,
// C components): whichever of them has the file's type is a start.
function parametric(name) {
    const [k, c] = name.split('.').map(Number);
    const comps = name.split('.').length === 3 ? c : 1;
    const tries = [];
    if (comps === 1 && k % 2 === 1) tries.push(['torus', '2', String(k)]);
    if (comps === 2 && k % 2 === 0) tries.push(['torus', '2', String(k)]);
    if (k === 8 && comps === 1) tries.push(['torus', '3', '4']);
    if (k === 10 && comps === 1) tries.push(['torus', '3', '5']);
    if (k === 6 && comps === 3) tries.push(['torus', '3', '3']);
    if (k === 8 && comps === 4) tries.push(['torus', '4', '4']);
    if (comps > 1 && k === 2 * (comps - 1)) tries.push(['chain', String(comps)]);
    return tries;
}

// Makes the starts of one knot (those not made yet); returns their files.
function makeStarts(name) {
    const file = join(opt.catalogue, `${name}.vect`);
    const want = fileType(name);
    const files = [];
    // a start made before is checked again: the type compared has grown
    const put = (tag, text, why) => {
        const path = join(startsDir, `${name}@${tag}.vect`);
        const made = existsSync(path);
        if (!made) writeFileSync(path + '.part', text);
        const got = info(made ? path : path + '.part').invariants;
        if (typeKey(got) !== typeKey(want)) {
            console.log(`  ${name}: the ${why} is of another type (${typeText(got)}), not a start`);
            execFileSync('rm', ['-f', path, path + '.part']);
            return;
        }
        if (!made) execFileSync('mv', [path + '.part', path]);
        files.push(path);
    };
    put('cat', readFileSync(file, 'utf8'), 'catalogue file');
    // far starts by isotopy (generate wander): a displacement applied at
    // once (generate deform) made 8.2.3's far start another link with the
    // same invariants, which ended 35% below the file's
    for (let s = 1; s <= opt.far; s++) {
        const r = spawnSync(CLI, ['generate', 'wander', file, String(s)], { encoding: 'utf8' });
        if (r.status === 0) put(`wander${s}`, r.stdout, `wandered start ${s}`);
        else console.log(`  ${name}: no wandered start ${s}: ${r.stderr.trim()}`);
    }
    for (let s = 0; s < opt.turn; s++) {
        const r = spawnSync(CLI, ['generate', 'turn', file, String(s)], { encoding: 'utf8' });
        if (r.status === 0) put(`turn${s}`, r.stdout, `turned start ${s}`);
        else console.log(`  ${name}: no turned start ${s}: ${r.stderr.trim()}`);
    }
    for (const p of parametric(name)) {
        const r = spawnSync(CLI, ['generate', ...p], { encoding: 'utf8' });
        if (r.status === 0) {
            const got = spawnSync(CLI, ['info', '--json', '-'], { input: r.stdout, encoding: 'utf8' });
            if (got.status === 0 && typeKey(JSON.parse(got.stdout).invariants) === typeKey(want))
                put(p.join(''), r.stdout, p.join(' '));
        }
    }
    return files;
}

// ---- the daemon and the client

async function ownDaemon() {
    const proc = spawn(DAEMON, ['--port', '0', '--db', join(out, 'jobs.db'),
        '--workers', String(opt.parallel), '--worker-priority', opt.workerPriority, '--max-per-address', '1000'],
    { stdio: ['ignore', 'pipe', 'inherit'] });
    const port = await new Promise((res, rej) => {
        let text = '';
        proc.stdout.setEncoding('utf8').on('data', (d) => {
            text += d;
            const m = /listening on http:\/\/127\.0\.0\.1:(\d+)\//.exec(text);
            if (m) res(Number(m[1]));
        });
        proc.on('exit', (code) => rej(new Error(`tightknotd exited (${code}) before listening: ${text}`)));
    });
    return { url: `http://127.0.0.1:${port}`, proc };
}

async function submitAll(server, files) {
    const kept = join(resultsDir, 'settings.txt');
    if (existsSync(kept) && readFileSync(kept, 'utf8').trim() !== SETTINGS)
        usage(`${resultsDir} holds results made with other settings (${readFileSync(kept, 'utf8').trim()})`);
    writeFileSync(kept, `${SETTINGS}\n`);
    // autoscale: a deformed start is thinner than the tube (ropelength
    // does not depend on the scale)
    const args = ['remote', '--server', server, 'submit', '--resolution', String(opt.resolution),
        '--work', String(opt.work), '--autoscale', '--parallel', String(opt.parallel),
        '--loose', String(opt.loose), '--out', resultsDir, ...files];
    if (opt.token) args.splice(3, 0, '--token', opt.token);
    const child = spawn(CLI, args, { stdio: 'inherit' });
    return new Promise((res) => child.on('exit', (code) => res(code)));
}

// ---- the table

// Every results directory's rows; a start run again in a later
// directory (a summary written later) replaces its earlier row.
function readSummary() {
    const rows = new Map();
    const paths = readdirSync(resultsRoot).map((dir) => join(resultsRoot, dir, 'summary.tsv'))
        .filter(existsSync).sort((a, b) => statSync(a).mtimeMs - statSync(b).mtimeMs);
    for (const path of paths) readRows(path, dirname(path), rows);
    return rows;
}

// The client's summary.tsv: name, components, vertices, ropelength,
// thickness, residual, struts, steps, seconds, [reached,] state (a row
// the client kept from before it wrote `reached` has none).
function readRows(path, dir, rows) {
    for (const line of readFileSync(path, 'utf8').split('\n')) {
        const f = line.split('\t');
        if (f.length < 10 || f[0] === 'name') continue;
        const [name, components, vertices, ropelength, , residual, struts, steps, seconds] = f;
        rows.set(name, { name, components: +components, vertices: +vertices, ropelength: +ropelength,
            residual: +residual, struts: +struts, steps: +steps, seconds: +seconds,
            reached: f.length > 10 ? f[9] : '', state: f.at(-1), dir });
    }
}

function kinksOf(start, dir) {
    try {
        // NAME-struts.json (NAME.struts.json from older clients)
        const file = [`${start}-struts.json`, `${start}.struts.json`].map((f) => join(dir, f)).find(existsSync);
        const doc = JSON.parse(readFileSync(file ?? join(dir, `${start}-struts.json`), 'utf8'));
        return doc.kinks?.length ?? '';
    } catch {
        return '';
    }
}

const CONVERGED = 0.05;
const COLUMNS = ['name', 'components', 'type', 'vertices', 'starts', 'lowest', 'lowest.start',
    'spread.%', 'cat.above.%', 'lowest.reached', 'struts', 'kinks', 'seconds', 'failed', 'type.changed',
    'unconverged', 'settings'];

// One knot's row of the table from its results here: the row's fields by
// COLUMNS' names, or null when no result of the file's type is done.
// Failed starts' states go to `failed` (the table keeps their count).
function rowOf(knot, starts, failedStates) {
    starts.sort((a, b) => natural(a.tag, b.tag));
    const done = starts.filter((s) => s.state === 'done' && Number.isFinite(s.ropelength));
    const failed = starts.filter((s) => s.state !== 'done');
    for (const s of failed) failedStates.push(`${knot}@${s.tag}: ${s.state}`);
    let type = '', want = null;
    try {
        want = fileType(knot);
        type = typeText(want);
    } catch { /* not in this catalogue */ }
    // the type at the end, measured again on each result's curve: a
    // result of another type (or a start of one, made before the type
    // compared held the link's determinant) is another link's figure,
    // left out of the lowest and the spread
    const changed = want ? done.filter((s) => {
        try {
            return typeKey(info(join(s.dir, `${knot}@${s.tag}.vect`)).invariants) !== typeKey(want);
        } catch {
            return true;
        }
    }).map((s) => s.tag) : [];
    const ok = done.filter((s) => !changed.includes(s.tag));
    if (!ok.length) return null;
    // A start still moving when its time ran out (residual at least
    // CONVERGED: a loose start whose polygon was reckoned from its own
    // length, say) has not reached a basin to compare: the spread and
    // the catalogue's excess are over the converged starts, and the
    // others are listed apart.
    const converged = ok.filter((s) => s.residual < CONVERGED);
    const judged = converged.length ? converged : ok;
    const best = judged.reduce((a, b) => (b.ropelength < a.ropelength ? b : a));
    const worst = judged.reduce((a, b) => (b.ropelength > a.ropelength ? b : a));
    const cat = converged.find((s) => s.tag === 'cat');
    // (slices run before settings.txt was kept: these options without loose)
    let settings;
    try {
        settings = readFileSync(join(best.dir, 'settings.txt'), 'utf8').trim();
    } catch {
        settings = settingsText(0);
    }
    return {
        name: knot, components: best.components, type, vertices: best.vertices,
        starts: ok.map((s) => `${s.tag}=${s.ropelength.toFixed(6)}`).join(' '),
        lowest: best.ropelength.toFixed(6), 'lowest.start': best.tag,
        'spread.%': (100 * (worst.ropelength - best.ropelength) / best.ropelength).toFixed(4),
        'cat.above.%': cat ? (100 * (cat.ropelength - best.ropelength) / best.ropelength).toFixed(4) : '',
        'lowest.reached': best.reached, struts: best.struts, kinks: kinksOf(`${knot}@${best.tag}`, best.dir),
        seconds: ok.reduce((t, s) => t + s.seconds, 0).toFixed(0), failed: failed.length,
        'type.changed': want ? changed.join(' ') || 'none' : '',
        unconverged: ok.filter((s) => !(s.residual < CONVERGED)).map((s) => s.tag).join(' '),
        settings,
    };
}

// The table as committed: its rows by name.  A knot with no result here
// keeps its row, so that a clean clone (without the curves of the runs
// before) fills the table on, slice by slice.
function tableRows() {
    const rows = new Map();
    if (!existsSync(opt.table)) return rows;
    const [head, ...body] = readFileSync(opt.table, 'utf8').trim().split('\n');
    const names = head.split('\t');
    for (const line of body) {
        const f = line.split('\t');
        rows.set(f[0], Object.fromEntries(names.map((n, k) => [n, f[k] ?? ''])));
    }
    return rows;
}

function writeTable() {
    const byKnot = new Map();
    for (const r of readSummary().values()) {
        const at = r.name.lastIndexOf('@');
        if (at < 0) continue;
        const knot = r.name.slice(0, at);
        if (!byKnot.has(knot)) byKnot.set(knot, []);
        byKnot.get(knot).push({ ...r, tag: r.name.slice(at + 1) });
    }
    const rows = tableRows();
    const failedStates = [];
    for (const [knot, starts] of byKnot) {
        const row = rowOf(knot, starts, failedStates);
        if (row) rows.set(knot, row);
    }
    const ordered = [...rows.keys()].sort(natural).map((k) => rows.get(k));
    mkdirSync(resolve(opt.table, '..'), { recursive: true });
    writeFileSync(opt.table, [COLUMNS, ...ordered.map((r) => COLUMNS.map((c) => r[c]))]
        .map((f) => f.join('\t')).join('\n') + '\n');

    // the summary, from the table's rows alone (those kept and those made here)
    const summary = { compared: 0, agree: 0, spreads: [], catTrapped: [], changed: [], unconverged: [],
        failed: 0, bySettings: new Map() };
    for (const r of ordered) {
        const values = r.starts.split(' ').map((t) => t.split('='));
        const moving = r.unconverged ? r.unconverged.split(' ') : [];
        const judged = values.filter(([tag]) => !moving.includes(tag));
        const pick = judged.length ? judged : values;
        const worst = pick.reduce((a, b) => (+b[1] > +a[1] ? b : a));
        const spread = +r['spread.%'], catAbove = r['cat.above.%'] === '' ? NaN : +r['cat.above.%'];
        const compared = judged.length > 1;
        for (const tag of moving) summary.unconverged.push(`${r.name}@${tag}`);
        if (r['type.changed'] && r['type.changed'] !== 'none')
            for (const tag of r['type.changed'].split(' ')) summary.changed.push(`${r.name}@${tag}`);
        summary.failed += +r.failed || 0;
        if (!summary.bySettings.has(r.settings)) summary.bySettings.set(r.settings, { knots: 0, compared: 0, agree: 0, catTrapped: 0 });
        const group = summary.bySettings.get(r.settings);
        group.knots++;
        group.compared += compared;
        group.agree += compared && spread <= 0.1;
        group.catTrapped += catAbove > 0.1;
        summary.compared += compared;
        summary.agree += compared && spread <= 0.1;
        summary.spreads.push([spread, r.name, r['lowest.start'], +r.lowest, worst[0], +worst[1]]);
        if (catAbove > 0.1) summary.catTrapped.push([catAbove, r.name]);
    }
    const n = ordered.length;
    const pct = (k) => (n ? (100 * k / n).toFixed(1) : '-');
    console.log(`table: ${opt.table}, ${n} of ${knots.length} knots and links (${[...summary.bySettings.keys()].join('; ')})`);
    console.log(`  with two converged starts or more: ${summary.compared}; every converged start within ` +
        `0.1% of the lowest: ${summary.agree} (${summary.compared ? (100 * summary.agree / summary.compared).toFixed(1) : '-'}%)`);
    console.log(`  starts still moving when their time ran out (residual >= ${CONVERGED}): ` +
        `${summary.unconverged.length}` + (summary.unconverged.length ? `: ${summary.unconverged.join(', ')}` : ''));
    console.log(`  the catalogue's start more than 0.1% above the lowest: ${summary.catTrapped.length} ` +
        `(${pct(summary.catTrapped.length)}%)` + (summary.catTrapped.length
        ? `, by ${Math.min(...summary.catTrapped.map((t) => t[0])).toFixed(2)}% to ` +
          `${Math.max(...summary.catTrapped.map((t) => t[0])).toFixed(2)}%` : ''));
    for (const [settings, g] of summary.bySettings)
        console.log(`  ${settings}: ${g.knots} knots, ${g.agree} of ${g.compared} with two converged starts ` +
            `or more within 0.1%; the catalogue's start more than 0.1% above the lowest in ${g.catTrapped}`);
    // the daemon's figures of every slice run (DAEMON_LOG: slice, wall
    // seconds, jobs ended, workers' busy seconds, workers, from its /metrics)
    if (existsSync(DAEMON_LOG)) {
        const runs = readFileSync(DAEMON_LOG, 'utf8').trim().split('\n').slice(1)
            .map((l) => l.split('\t').slice(1).map(Number));
        const [wall, ended, busy, slots] = runs.reduce((t, r) => [t[0] + r[0], t[1] + r[1], t[2] + r[2], t[3] + r[0] * r[3]], [0, 0, 0, 0]);
        if (runs.length)
            console.log(`  the daemon, over ${runs.length} slice runs in ${DAEMON_LOG}: ${ended} jobs in ${(wall / 3600).toFixed(2)} h ` +
                `(${(ended / (wall / 3600)).toFixed(1)} jobs an hour), workers busy ${(100 * busy / slots).toFixed(1)}% of the time`);
    }
    const widest = summary.spreads.sort((a, b) => b[0] - a[0]).slice(0, 10).filter((s) => s[0] > 0.1);
    for (const [spread, knot, lo, lov, hi, hiv] of widest)
        console.log(`  ${knot}: ${spread.toFixed(3)}% apart (${lo} ${lov.toFixed(4)}, ${hi} ${hiv.toFixed(4)})`);
    console.log(`  failed starts: ${summary.failed}` + (failedStates.length ? ` (of the results here: ${failedStates.join('; ')})` : ''));
    console.log(`  type at the end: ${summary.changed.length ? `another's (left out of the lowest) in ${summary.changed.join(', ')}`
        : 'the file\'s in every result'}`);
}

// ---- the run

if (!opt.tableOnly) {
    console.log(`bench/catalogue: slice ${opt.slice}, ${mine.length} of ${knots.length} knots and links; ` +
        `starts in ${startsDir}`);
    const files = [];
    for (const name of mine) files.push(...makeStarts(name));
    console.log(`bench/catalogue: ${files.length} starts; resolution ${opt.resolution}, ${opt.work} s of work each, ` +
        `${opt.parallel} at once`);
    let daemon = null;
    const server = opt.server ?? (daemon = await ownDaemon()).url;
    const metric = async (name) => {
        const text = await fetch(`${server}/metrics`).then((r) => r.text()).catch(() => '');
        const m = new RegExp(`^tightknot_${name} (\\S+)$`, 'm').exec(text);
        return m ? Number(m[1]) : NaN;
    };
    const before = { ended: await metric('jobs_ended_total'), busy: await metric('worker_busy_seconds_total') };
    const t0 = Date.now();
    const code = await submitAll(server, files);
    const wall = (Date.now() - t0) / 1000, workers = await metric('workers');
    const ended = await metric('jobs_ended_total') - before.ended;
    const busy = await metric('worker_busy_seconds_total') - before.busy;
    if (Number.isFinite(ended) && Number.isFinite(busy)) {
        if (!existsSync(DAEMON_LOG)) writeFileSync(DAEMON_LOG, 'run\twall.s\tjobs.ended\tbusy.s\tworkers\n');
        writeFileSync(DAEMON_LOG, `${basename(resultsDir)}\t${wall.toFixed(0)}\t${ended}\t${busy.toFixed(0)}\t${workers}\n`, { flag: 'a' });
        console.log(`bench/catalogue: ${ended} jobs ended in ${wall.toFixed(0)} s (${(ended / (wall / 3600)).toFixed(1)} an hour), ` +
            `the ${workers} workers busy ${(100 * busy / (workers * wall)).toFixed(1)}% of the time (/metrics)`);
    }
    console.log(`bench/catalogue: the client ended (exit ${code}) after ${((Date.now() - t0) / 1000).toFixed(0)} s`);
    if (daemon) {
        const metrics = await fetch(`${server}/metrics`).then((r) => r.text()).catch(() => '');
        for (const line of metrics.split('\n'))
            if (/^tightknot_(jobs|workers|worker)/.test(line)) console.log(`  ${line}`);
        daemon.proc.kill('SIGTERM');
        await new Promise((r) => daemon.proc.on('exit', r));
    }
}
writeTable();
