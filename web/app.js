// The page: submit a knot, watch its job, look at the result, replay it.

import { api, ApiError, auth, fetchFile, TERMINAL } from './api.js';
import { parseVect, splitFlat, torusLink, scaleToFit, writeVect } from './geometry.js';
import { drawHistory, drawContactMap, fmtForce, openPair } from './charts.js';
import { createView, forceColour, rampCss } from './view3d.js';
import { equalTimeFrames, frameFlowTimes, recordCanvas, webmType } from './film.js';

const $ = (id) => document.getElementById(id);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const POLL_MS = 300;          // live figures, ~3 times a second
const DATA_MS = 2000;         // curve, struts and history while running
const JOBS_MS = 2000;         // the job list
const FRAME_PAGE = 200;       // the API's largest page of frames
const FILM_FRAMES = 200;      // a film's frames, at equal flow time
const FILM_FPS = 25;

const state = {
    source: 'catalogue',
    catalogue: [],
    jobsOffset: 0,
    jobsLimit: 50,
    selected: null,     // job id
    watchToken: 0,
    job: null,
    contacts: null,
    curve: null,
    shown: null,        // the stored step's report the figures show
    history: [],
    live: [],           // polled figures newer than the stored history
    frames: [],         // [{ step, comps }]
    replayIndex: -1,    // -1: the stored (final) curve with its struts
    playTimer: null,
    sort: { key: 'index', dir: 1 },
    hot: -1,
    fitted: false,
};

let view = null;

// ------------------------------------------------------------------ format

const fixed = (v, d) => (v == null || !Number.isFinite(v) ? '–' : v.toFixed(d));
const prec = (v, d) => (v == null || !Number.isFinite(v) ? '–' : (+v.toPrecision(d)).toString());
const sci = (v) => (v == null || !Number.isFinite(v) ? '–' : v === 0 ? '0' : Math.abs(v) >= 0.01 && Math.abs(v) < 1000 ? v.toPrecision(3) : v.toExponential(2));

const compact = (n) => (n >= 1e6 && n % 1e5 === 0 ? `${n / 1e6}M` : n >= 1e4 && n % 100 === 0 ? `${n / 1e3}k` : `${n}`);

// A knot or link type (the API's KnotType) in a few words: a knot's
// Alexander polynomial and determinant, "1 - t + t^2 (det 3)"; a link's
// linking numbers, its components' determinants and any knotted
// component's polynomial, "lk 0-1: 1 (det 1 1; link 2)".  "?" for what is
// unknown.
function typeText(k) {
    if (!k) return '–';
    const n = k.determinants.length;
    const det = (i) => (k.determinants[i] == null ? '?' : `${k.determinants[i]}`);
    if (n === 1) return k.alexander_text[0] == null ? '?' : `${k.alexander_text[0]} (det ${det(0)})`;
    const pairs = [];
    for (let a = 0; a < n; a++)
        for (let b = a + 1; b < n; b++) pairs.push(`${a}-${b}: ${k.linking[a][b]}`);
    const knotted = k.alexander_text.map((t, i) => (t != null && t !== '1' ? `; ${i}: ${t}` : '')).join('');
    const link = k.link_determinant == null ? '?' : `${k.link_determinant}`;
    return `lk ${pairs.join(', ')} (det ${k.determinants.map((_, i) => det(i)).join(' ')}; link ${link})${knotted}`;
}

// The type figure: the result's, and the start's beside it when the run
// changed it (the job has then failed).
function showType(inv) {
    const dd = $('fig-type');
    const start = typeText(inv?.start);
    const result = typeText(inv?.result);
    const changed = inv != null && start !== result;
    dd.textContent = changed ? `${start} → ${result}` : result;
    dd.classList.toggle('changed', changed);
    dd.title = inv == null ? 'not known before the run starts'
        : changed ? `the start's type → the result's: ${start} → ${result}` : `start and result: ${result}`;
}

// The basins the run's tightenings reached (job.basins), lowest first,
// each with how often: "71.0012 ×2, 71.1281 ×1"; the note when the lowest
// was reached once.
function showBasins(b) {
    const dd = $('fig-basins');
    const list = b?.basins ?? [];
    dd.textContent = list.length
        ? list.map((x) => `${Number(x.ropelength).toFixed(4)} ×${x.times}`).join(', ') : '–';
    dd.classList.toggle('once', b?.note != null);
    dd.title = b?.note ? `the lowest ${b.note}`
        : list.length ? `the lowest reached ${b.best_reached} times` : 'not known before the run has stored its figures';
}

function fileName(job, ext) {
    const base = (job.name || 'job').replace(/[^A-Za-z0-9._-]+/g, '_');
    return `${base}-${job.id}${ext}`;
}

// ------------------------------------------------------------------ messages

// Shows an API problem: its title, its detail and where it points (the VECT
// line, the option or the field), and puts the cursor on a bad VECT line.
function showProblem(box, err) {
    const p = err instanceof ApiError ? err.problem : { title: 'Error', detail: String(err?.message || err) };
    box.className = 'message error';
    box.replaceChildren();
    const title = document.createElement('span');
    title.className = 'title';
    title.textContent = p.title || 'Error';
    const detail = document.createElement('span');
    detail.className = 'detail';
    detail.textContent = p.detail || '';
    box.append(title, detail);
    const where = p.line != null ? `line ${p.line}` : p.option ? `option ${p.option}` : p.field ? `field ${p.field}` : p.parameter ? `parameter ${p.parameter}` : '';
    if (where) {
        const w = document.createElement('span');
        w.className = 'where';
        w.dataset.line = p.line ?? '';
        w.textContent = `→ ${where}`;
        box.append(document.createElement('br'), w);
    }
    box.hidden = false;
    if (p.line != null && state.source === 'vect') selectLine($('vect-text'), p.line);
    if (p.option) $(`opt-${p.option}`)?.focus();
}

function showInfo(box, text) {
    box.className = 'message';
    box.textContent = text;
    box.hidden = false;
}

function selectLine(textarea, line) {
    const lines = textarea.value.split('\n');
    if (line < 1 || line > lines.length) return;
    let start = 0;
    for (let i = 0; i < line - 1; i++) start += lines[i].length + 1;
    textarea.focus();
    textarea.setSelectionRange(start, start + lines[line - 1].length);
    const lh = parseFloat(getComputedStyle(textarea).lineHeight) || 16;
    textarea.scrollTop = Math.max(0, (line - 3) * lh);
}

// ------------------------------------------------------------------ submit

function setSource(source) {
    state.source = source;
    for (const b of document.querySelectorAll('.tabs [role=tab]')) {
        b.setAttribute('aria-selected', String(b.dataset.source === source));
    }
    for (const s of ['catalogue', 'vect', 'torus']) $(`source-${s}`).hidden = s !== source;
    updateNamePlaceholder();
    if (source === 'torus') updateTorusInfo();
}

async function loadCatalogue() {
    const info = $('catalogue-info');
    try {
        const cat = await api.catalogue();
        state.catalogue = cat.knots;
        fillCatalogue();
        const sel = $('catalogue-select');
        if (!sel.value && cat.knots.some((k) => k.name === '3.1')) sel.value = '3.1';
        updateCatalogueInfo();
    } catch (e) {
        state.catalogue = [];
        info.textContent = e.status === 404 ? 'the server offers no catalogue' : `catalogue: ${e.message}`;
    }
}

function fillCatalogue() {
    const sel = $('catalogue-select');
    const keep = sel.value;
    const f = $('catalogue-filter').value.trim().toLowerCase();
    sel.replaceChildren();
    // the name typed exactly comes first, then names that begin with it,
    // then the others that hold it, each in the catalogue's order
    const rank = (name) => (name === f ? 0 : name.startsWith(f) ? 1 : 2);
    const shown = state.catalogue.filter((k) => !f || k.name.toLowerCase().includes(f))
        .map((k, i) => ({ k, i, r: rank(k.name.toLowerCase()) }))
        .sort((a, b) => a.r - b.r || a.i - b.i)
        .map((x) => x.k);
    for (const k of shown) {
        const o = document.createElement('option');
        o.value = k.name;
        o.textContent = `${k.name}  (${k.components === 1 ? 'knot' : `${k.components}-component link`}, ${k.vertices} vertices)`;
        sel.append(o);
    }
    const exact = shown.find((k) => k.name.toLowerCase() === f);
    if (exact) sel.value = exact.name;
    else if (keep && [...sel.options].some((o) => o.value === keep)) sel.value = keep;
    else if (sel.options.length === 1) sel.selectedIndex = 0;
    updateCatalogueInfo();
}

function updateCatalogueInfo() {
    const sel = $('catalogue-select');
    const shown = sel.options.length;
    const picked = sel.value ? `picked ${sel.value}; ` : '';
    $('catalogue-info').textContent = `${picked}${shown} of ${state.catalogue.length} knots shown`;
}

function torusComps() {
    const p = Math.round(Number($('torus-p').value));
    const q = Math.round(Number($('torus-q').value));
    const n = Math.round(Number($('torus-n').value));
    if (!(p >= 1 && q >= 1 && p <= 50 && q <= 50)) throw new Error('p and q must be whole numbers from 1 to 50');
    if (!(n >= 8 && n <= 5000)) throw new Error('vertices must be from 8 to 5000');
    const comps = torusLink(p, q, n);
    const radius = Number($('opt-radius').value) || 0.5;
    const lambda = Number($('opt-lambda').value) || 1;
    const fit = scaleToFit(comps, radius, lambda);
    return { p, q, n, comps, fit };
}

// The name the job gets when the field is left empty.
function updateNamePlaceholder() {
    const field = $('opt-name');
    if (state.source === 'catalogue') field.placeholder = $('catalogue-select').value || "the knot's name";
    else if (state.source === 'torus') field.placeholder = `T(${$('torus-p').value},${$('torus-q').value})`;
    else field.placeholder = uploadedName() || 'untitled';
}

// The uploaded file's name, while the text area still holds that file.
function uploadedName() {
    const f = state.vectFile;
    return f && f.text === $('vect-text').value ? f.name : '';
}

function updateTorusInfo() {
    const info = $('torus-info');
    try {
        const { p, q, comps, fit } = torusComps();
        const kind = comps.length > 1 ? `a ${comps.length}-component link` : p === 1 || q === 1 ? 'an unknot' : 'a knot';
        info.textContent = `T(${p},${q}) is ${kind}; scaled ×${fit.scale.toFixed(2)} to thickness ≈ ${fit.thickness.toFixed(3)} (tube diameter ${2 * (Number($('opt-radius').value) || 0.5)})`;
    } catch (e) {
        info.textContent = e.message;
    }
}

function readOptions() {
    const opts = {};
    const num = (id, key) => {
        const raw = $(id).value.trim();
        if (raw === '') return;
        const v = Number(raw);
        // Bad values go to the server as they are, so the message about
        // them is the service's own.
        opts[key] = Number.isFinite(v) ? v : raw;
    };
    num('opt-resolution', 'resolution');
    num('opt-steps', 'steps');
    num('opt-work', 'work');
    num('opt-residual', 'residual');
    num('opt-every', 'every');
    num('opt-radius', 'radius');
    num('opt-lambda', 'lambda');
    opts.autoscale = $('opt-autoscale').checked;
    opts.converge = $('opt-converge').checked;
    return opts;
}

async function submit(ev) {
    ev.preventDefault();
    const box = $('submit-message');
    const button = $('submit-button');
    const body = { options: readOptions() };
    const name = $('opt-name').value.trim();
    try {
        if (state.source === 'catalogue') {
            const k = $('catalogue-select').value;
            if (!k) throw new Error('pick a knot from the catalogue');
            body.catalogue = k;
        } else if (state.source === 'vect') {
            const text = $('vect-text').value;
            if (!text.trim()) throw new Error('paste a VECT file or choose one');
            body.vect = text;
            if (uploadedName()) body.name = uploadedName();
        } else {
            const { p, q, n, comps } = torusComps();
            body.vect = writeVect(comps, `torus ${p} ${q}, ${n} vertices per component`);
            body.name = `T(${p},${q})`;
        }
    } catch (e) {
        showProblem(box, e);
        return;
    }
    if (name) body.name = name;
    button.disabled = true;
    showInfo(box, 'submitting…');
    delete box.dataset.job;
    try {
        const job = await api.submit(body);
        showInfo(box, `submitted job #${job.id} (${job.name})`);
        box.dataset.job = job.id;
        state.jobsOffset = 0;
        refreshJobs();
        selectJob(job.id);
    } catch (e) {
        showProblem(box, e);
    } finally {
        button.disabled = false;
    }
}

// ------------------------------------------------------------------ jobs list

async function refreshJobs() {
    try {
        const list = await api.jobs({ offset: state.jobsOffset, limit: state.jobsLimit });
        renderJobs(list);
    } catch (e) {
        $('jobs-total').textContent = `(${e.message})`;
    }
}

function renderJobs(list) {
    const tbody = $('jobs-table').tBodies[0];
    // Rows are rebuilt only when something shown changed, so that a click
    // never lands on a row being replaced.
    const key = JSON.stringify([state.selected, list.total, list.offset,
        list.jobs.map((j) => [j.id, j.name, j.state, j.ropelength])]);
    if (key === state.jobsKey) return;
    state.jobsKey = key;
    tbody.replaceChildren();
    for (const j of list.jobs) {
        const tr = document.createElement('tr');
        tr.dataset.id = j.id;
        tr.setAttribute('aria-selected', String(j.id === state.selected));
        tr.tabIndex = 0;
        const cells = [
            j.id,
            j.name,
            null,
            fixed(j.ropelength, 3),
        ];
        cells.forEach((c, i) => {
            const td = document.createElement('td');
            if (i === 2) {
                const s = document.createElement('span');
                s.className = 'state';
                s.dataset.state = j.state;
                s.textContent = j.state;
                td.append(s);
            } else {
                td.textContent = c;
            }
            if (i === 1) { td.className = 'name'; td.title = j.name; }
            if (i === 3) td.className = 'num';
            tr.append(td);
        });
        tr.addEventListener('click', () => selectJob(j.id));
        tr.addEventListener('keydown', (e) => { if (e.key === 'Enter') selectJob(j.id); });
        tbody.append(tr);
    }
    $('jobs-total').textContent = `(${list.total})`;
    const from = list.total ? list.offset + 1 : 0, to = list.offset + list.jobs.length;
    $('jobs-range').textContent = `${from}–${to} of ${list.total}`;
    $('jobs-newer').disabled = list.offset <= 0;
    $('jobs-older').disabled = to >= list.total;
}

async function cancelJob() {
    const id = state.selected;
    if (!id) return;
    $('job-cancel').disabled = true;
    try {
        const job = await api.cancel(id);
        if (id === state.selected) showJob(job);
        refreshJobs();
    } catch (e) {
        showProblem($('job-error'), e);
    }
}

// ------------------------------------------------------------------ one job

function selectJob(id) {
    id = Number(id);
    if (!view) {
        view = createView($('view3d'));
        view.setOpacity(Number($('tube-opacity').value));
    }
    stopPlay();
    state.selected = id;
    state.watchToken++;
    state.job = null;
    state.contacts = null;
    state.curve = null;
    state.shown = null;
    state.history = [];
    state.live = [];
    state.frames = [];
    state.replayIndex = -1;
    state.hot = -1;
    state.fitted = false;
    if (location.hash !== `#job=${id}`) history.replaceState(null, '', `#job=${id}`);
    $('empty').hidden = true;
    $('job').hidden = false;
    $('job').dataset.phase = 'loading';
    $('job-error').hidden = true;
    $('job-name').textContent = '…';
    $('job-id').textContent = `#${id}`;
    for (const r of $('jobs-table').tBodies[0].rows) r.setAttribute('aria-selected', String(Number(r.dataset.id) === id));
    view.clear();
    renderStruts();
    drawHistory($('chart'), []);
    resetReplay('no frames yet');
    watch(id, state.watchToken);
}

async function watch(id, token) {
    const live = () => token === state.watchToken;
    let lastStep = -1, lastData = 0;
    for (;;) {
        let job;
        try {
            job = await api.job(id);
        } catch (e) {
            if (!live()) return;
            showProblem($('job-error'), e);
            if (e.status === 404) return;
            await sleep(1000);
            continue;
        }
        if (!live()) return;
        showJob(job);
        const terminal = TERMINAL.has(job.state);
        const now = performance.now();
        if (terminal || lastData === 0 || (job.progress.step !== lastStep && now - lastData > DATA_MS)) {
            lastStep = job.progress.step;
            lastData = now;
            try {
                await loadData(job, live);
            } catch (e) {
                if (live()) showProblem($('job-error'), e);
            }
            if (!live()) return;
        }
        if (terminal) {
            $('job').dataset.phase = 'frames';
            try {
                await loadFrames(job, live);
            } catch (e) {
                if (live()) showProblem($('job-error'), e);
            }
            if (live()) $('job').dataset.phase = 'final';
            refreshJobs();
            return;
        }
        $('job').dataset.phase = 'watching';
        await sleep(POLL_MS);
        if (!live()) return;
    }
}

function showJob(job) {
    state.job = job;
    $('job-name').textContent = job.name;
    $('job-id').textContent = `#${job.id}`;
    const st = $('job-state');
    st.textContent = job.state;
    st.dataset.state = job.state;
    $('job-reason').textContent = job.stop_reason ? `stopped: ${job.stop_reason}` : '';
    if (job.error) {
        const box = $('job-error');
        box.className = 'message error';
        box.textContent = job.error;
        box.hidden = false;
    }
    $('job-cancel').disabled = TERMINAL.has(job.state);
    // fetched with the token and saved from a blob (downloadFile)
    const links = [['job-download-vect', `/v1/jobs/${job.id}/vect`, fileName(job, '.vect')],
        ['job-download-struts', `/v1/jobs/${job.id}/struts`, fileName(job, '-struts.json')]];
    for (const [id, href, name] of links) {
        const b = $(id);
        b.dataset.href = href;
        b.dataset.name = name;
        b.disabled = job.state === 'queued';
    }
    const steps = job.options.steps;
    $('fig-step-label').textContent = steps ? `step of ${compact(steps)}` : 'step';
    // The history is stored every few seconds; the polled figures fill the
    // chart in between.
    const lastStored = state.history.length ? state.history[state.history.length - 1].step : -1;
    if (Number.isFinite(job.ropelength) && job.progress.step > lastStored) {
        const live = state.live;
        if (!live.length || live[live.length - 1].step < job.progress.step) {
            live.push({ step: job.progress.step, ropelength: job.ropelength });
            drawChart();
        }
    }
    // until a step's curve and struts are shown, the polled figures
    if (!state.shown) showFigures({ ...job, step: job.progress.step });
    showType(job.invariants);
    showBasins(job.basins);
    const frac = job.progress.fraction ?? (job.state === 'done' ? 1 : 0);
    $('job-progress').style.width = `${(100 * frac).toFixed(1)}%`;
}

// The figures box: one step's report (a history entry, or the job's own
// figures before any step is stored).
function showFigures(r) {
    $('fig-step').textContent = `${r.step}`;
    $('fig-ropelength').textContent = fixed(r.ropelength, 3);
    $('fig-thickness').textContent = prec(r.thickness, 6);
    $('fig-minrad').textContent = prec(r.minrad, 5);
    $('fig-residual').textContent = sci(r.residual);
    $('fig-struts').textContent = r.struts;
    $('fig-kinks').textContent = r.kinks;
    $('fig-vertices').textContent = r.vertices;
    $('fig-seconds').textContent = r.seconds == null ? '–' : `${r.seconds.toFixed(1)} s`;
}

// One step on the page: the figures, the 3-D view and the strut table
// are of the same stored step.  A running job's worker may store a newer
// step between the three requests, so they are asked again (a few times
// at most) until the curve, the struts and the history's last entry agree.
async function loadData(job, live) {
    let doc, contacts, hist, same = false;
    for (let tries = 0; tries < 4 && !same; tries++) {
        [doc, contacts, hist] = await Promise.all([
            api.vect(job.id), api.struts(job.id), api.history(job.id, 1000),
        ]);
        if (!live()) return;
        const last = hist.steps[hist.steps.length - 1];
        same = doc.step === contacts.step && last?.step === doc.step;
    }
    if (!live()) return;
    state.curve = { comps: parseVect(doc.vect), step: doc.step };
    state.contacts = contacts;
    state.history = hist.steps;
    if (same) {
        state.shown = hist.steps[hist.steps.length - 1];
        showFigures(state.shown);
    }
    const lastStored = hist.steps.length ? hist.steps[hist.steps.length - 1].step : -1;
    state.live = state.live.filter((s) => s.step > lastStored);
    drawChart();
    renderStruts();
    if (state.replayIndex < 0) showFinal();
}

function drawChart() {
    const mark = state.replayIndex >= 0 ? state.frames[state.replayIndex]?.step : null;
    drawHistory($('chart'), state.history.concat(state.live), mark);
}

// The stored curve with its struts.
function showFinal() {
    if (!state.curve || !state.job) return;
    state.replayIndex = -1;
    view.setCurve(state.curve.comps, state.job.options.radius);
    view.setStruts(state.contacts?.struts || []);
    view.setConstraints(state.contacts?.constraints || [], state.curve.comps);
    view.setShowStruts($('show-struts').checked);
    // Fit once per job, and with "follow" each time the curve moves on.
    if (state.fitted === false || ($('follow').checked && state.fitted !== state.curve.step)) {
        view.fit();
        state.fitted = state.curve.step;
    }
    const n = state.contacts?.struts.length ?? 0;
    const pins = state.contacts?.constraints?.length ?? 0;
    $('view3d-label').textContent = `stored curve, step ${state.curve.step} · ${n} strut${n === 1 ? '' : 's'}` +
        (pins ? ` · ${pins} constrained vert${pins === 1 ? 'ex' : 'ices'} (dark balls; planes in violet)` : '');
    $('replay-final').disabled = true;
    drawChart();
    if (state.frames.length) {
        $('replay-slider').value = state.frames.length - 1;
        $('replay-label').textContent = `${state.frames.length} frames`;
    }
}

// ------------------------------------------------------------------ struts

function strutRows() {
    const struts = state.contacts?.struts || [];
    const rows = struts.map((s, i) => {
        const [a0, b0] = s.arclength;
        return {
            index: i, s,
            comps: [s.edges[0][0], s.edges[1][0]],
            edges: [s.edges[0][1], s.edges[1][1]],
            a: a0, b: b0, length: s.length, force: Number.isFinite(s.force) ? s.force : -Infinity,
        };
    });
    const { key, dir } = state.sort;
    rows.sort((x, y) => {
        const u = x[key], v = y[key];
        const c = Array.isArray(u) ? (u[0] - v[0]) || (u[1] - v[1]) : u - v;
        return dir * c || x.index - y.index;
    });
    return rows;
}

function strutColour(s, fmax) {
    const f = Number.isFinite(s.force) ? s.force : 0;
    return `#${forceColour(fmax > 0 ? f / fmax : 0).getHexString()}`;
}

function renderStruts() {
    const contacts = state.contacts;
    const struts = contacts?.struts || [];
    const fmax = Math.max(0, ...struts.map((s) => (Number.isFinite(s.force) ? s.force : 0)));
    const tbody = $('strut-table').tBodies[0];
    tbody.replaceChildren();
    const frag = document.createDocumentFragment();
    for (const r of strutRows()) {
        const tr = document.createElement('tr');
        tr.dataset.index = r.index;
        const sw = `<span class="swatch" style="background:${strutColour(r.s, fmax)}"></span>`;
        tr.innerHTML = `<td class="num">${r.index}</td><td>${r.comps[0]} – ${r.comps[1]}</td><td>${r.edges[0]} – ${r.edges[1]}</td>` +
            `<td class="num">${r.a.toFixed(4)}</td><td class="num">${r.b.toFixed(4)}</td>` +
            `<td class="num">${r.length.toFixed(6)}</td><td class="num">${sw}${fmtForce(r.s.force)}</td>`;
        frag.append(tr);
    }
    tbody.append(frag);
    for (const th of $('strut-table').tHead.rows[0].cells) {
        th.setAttribute('aria-sort', th.dataset.key === state.sort.key ? (state.sort.dir > 0 ? 'ascending' : 'descending') : 'none');
    }
    const step = contacts ? ` at step ${contacts.step}` : '';
    $('struts-caption').textContent = contacts ? `(${struts.length}${step}; hover a row to find it in 3-D, click a header to sort)` : '';

    const kinks = contacts?.kinks || [];
    const kb = $('kink-table').tBodies[0];
    kb.replaceChildren();
    for (const k of kinks) {
        const tr = document.createElement('tr');
        tr.innerHTML = `<td class="num">${k.comp}</td><td class="num">${k.vertex}</td><td class="num">${k.arclength.toFixed(4)}</td>` +
            `<td class="num">${k.minrad.toFixed(5)}</td><td class="num">${fmtForce(k.force)}</td>`;
        kb.append(tr);
    }
    $('kinks-caption').textContent = contacts ? `(${kinks.length})` : '';

    state.marks = drawContactMap($('contact-map'), contacts, {
        colour: (s) => strutColour(s, fmax),
        onHover: (i) => setHot(i),
    });
    $('map-caption').textContent = openPair(contacts)
        ? '(each axis the arclength along one rope, as the paper\'s Figure 6)'
        : '(arclength of the two ends; kinks on the diagonal)';
    $('strut-legend').innerHTML = struts.length
        ? `force 0 <span class="ramp" style="background:${rampCss}"></span> ${fmtForce(fmax)}` : '';
    state.hot = -1;
}

// Highlights one strut everywhere: its table row, its mark, its rod in 3-D.
function setHot(i) {
    if (state.hot === i) return;
    const old = state.hot;
    state.hot = i;
    if (old >= 0) {
        $('strut-table').querySelector(`tr[data-index="${old}"]`)?.classList.remove('hot');
        state.marks?.[old]?.classList.remove('hot');
    }
    if (i >= 0) {
        $('strut-table').querySelector(`tr[data-index="${i}"]`)?.classList.add('hot');
        const m = state.marks?.[i];
        if (m) { m.classList.add('hot'); m.parentNode.append(m); }
        if (state.replayIndex < 0) view.highlight(i);
    } else {
        view.clearHighlight();
    }
}

// ------------------------------------------------------------------ replay

function resetReplay(label) {
    $('replay-play').disabled = true;
    $('export-film').disabled = true;
    $('replay-slider').disabled = true;
    $('replay-slider').max = 0;
    $('replay-slider').value = 0;
    $('replay-final').disabled = true;
    $('replay-label').textContent = label;
}

async function loadFrames(job, live) {
    state.frames = [];
    if (!job.frames) {
        resetReplay(job.options.every ? 'no frames stored' : 'no frames (every = 0)');
        return;
    }
    resetReplay('loading frames…');
    let offset = 0, total = Infinity;
    while (offset < total) {
        const page = await api.frames(job.id, offset, FRAME_PAGE);
        if (!live()) return;
        total = page.total;
        // a frame has its own vertex counts (coarse to fine, re-resolution)
        for (const f of page.frames) state.frames.push({ step: f.step, comps: splitFlat(f.coordinates, f.components || page.components) });
        if (!page.frames.length) break;
        offset += page.frames.length;
        $('replay-label').textContent = `loading frames ${offset} / ${total}`;
    }
    const n = state.frames.length;
    if (!n) { resetReplay('no frames stored'); return; }
    $('replay-slider').max = n - 1;
    $('replay-slider').value = n - 1;
    $('replay-slider').disabled = false;
    $('replay-play').disabled = false;
    $('export-film').disabled = !webmType();
    $('replay-label').textContent = `${n} frames`;
}

function showFrame(i) {
    const f = state.frames[i];
    if (!f || !state.job) return;
    state.replayIndex = i;
    view.setCurve(f.comps, state.job.options.radius);
    // The struts belong to the stored curve, not to earlier frames.
    view.setStruts([]);
    if ($('follow').checked) view.fit();
    $('replay-slider').value = i;
    $('replay-label').textContent = `frame ${i + 1} / ${state.frames.length} · step ${f.step}`;
    $('view3d-label').textContent = `replay: step ${f.step}`;
    $('replay-final').disabled = false;
    drawChart();
}

function play() {
    if (state.playTimer) { stopPlay(); return; }
    const n = state.frames.length;
    if (!n) return;
    let i = state.replayIndex < 0 || state.replayIndex >= n - 1 ? 0 : state.replayIndex;
    showFrame(i);
    $('replay-play').textContent = '❚❚ Pause';
    const fps = Number($('replay-speed').value) || 20;
    state.playTimer = setInterval(() => {
        i++;
        if (i >= n) { stopPlay(); return; }
        showFrame(i);
    }, 1000 / fps);
}

function stopPlay() {
    if (state.playTimer) clearInterval(state.playTimer);
    state.playTimer = null;
    $('replay-play').textContent = '▶ Play';
}

// ------------------------------------------------------------------ health

async function refreshHealth() {
    const h = $('health');
    try {
        const s = await api.health();
        h.classList.remove('down');
        h.textContent = `${s.status} · ${s.workers} workers · ${s.running} running · ${s.queued} queued`;
    } catch (e) {
        h.classList.add('down');
        h.textContent = e.status === 503 ? 'the service is stopping' : 'the service is not reachable';
    }
}

// ------------------------------------------------------------------ sign-in

// The sign-in box: what the last answer said of the token (none needed so
// far, signed in, token needed, wrong token), sign in and sign out.
const SIGNIN_TEXT = {
    none: '',
    'signed-in': 'signed in',
    'signed-out': 'signed out',
    'token-needed': 'this server needs a token: sign in',
    'wrong-token': 'wrong token: the server refused it',
};

function showSignIn(what) {
    const st = $('signin-state');
    // a 401 of a request sent before signing in says nothing of the new token
    if (what === 'token-needed' && auth.token()) return;
    st.dataset.state = what;
    st.textContent = SIGNIN_TEXT[what] ?? what;
    const signedIn = Boolean(auth.token());
    $('signout-button').hidden = !signedIn;
    if (what === 'token-needed' || what === 'wrong-token') $('signin-token').focus();
}

function signIn(e) {
    e.preventDefault();
    const token = $('signin-token').value.trim();
    if (!token) return;
    $('signin-token').value = '';
    auth.signIn(token);
    loadCatalogue();
    refreshJobs();
    if (state.selected) selectJob(state.selected);
}

async function downloadFile(e) {
    const b = e.currentTarget;
    if (!b.dataset.href) return;
    try {
        saveBlob(await fetchFile(b.dataset.href), b.dataset.name);
    } catch (err) {
        showProblem($('job-error'), err);
    }
}

// ------------------------------------------------------------------ exports

function saveBlob(blob, name) {
    const url = URL.createObjectURL(blob);
    const a = document.createElement('a');
    a.href = url;
    a.download = name;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 10000);
}

// The page styles its SVG figures from style.css; a file on its own needs
// the styles that apply written on each element.
const SVG_STYLES = ['fill', 'fill-opacity', 'stroke', 'stroke-opacity', 'stroke-width',
    'stroke-dasharray', 'opacity', 'font-family', 'font-size', 'font-weight', 'text-anchor',
    'dominant-baseline'];

function standaloneSvg(svg) {
    const copy = svg.cloneNode(true);
    const from = [svg, ...svg.querySelectorAll('*')], to = [copy, ...copy.querySelectorAll('*')];
    for (let i = 0; i < from.length; i++) {
        const cs = getComputedStyle(from[i]);
        to[i].setAttribute('style', SVG_STYLES.map((k) => `${k}: ${cs.getPropertyValue(k)}`).join('; '));
        // presentation attributes naming the page's variables: the style
        // written above holds their values
        for (const k of SVG_STYLES) if (to[i].getAttribute(k)?.includes('var(')) to[i].removeAttribute(k);
    }
    const box = svg.viewBox.baseVal;
    copy.setAttribute('xmlns', 'http://www.w3.org/2000/svg');
    copy.setAttribute('width', String(box.width));
    copy.setAttribute('height', String(box.height));
    return new Blob(['<?xml version="1.0" encoding="UTF-8"?>\n', new XMLSerializer().serializeToString(copy)],
        { type: 'image/svg+xml' });
}

function exportName(what) {
    return state.job ? fileName(state.job, `-${what}`) : `tightknot-${what}`;
}

async function exportPng() {
    if (!view || view.unavailable) return;
    const blob = await view.png();
    if (blob) saveBlob(blob, exportName('view.png'));
}

// The run's film: FILM_FRAMES frames at equal flow time (film.js), each
// frame's flow time read off the job's stored steps, recorded from the
// 3-D view as WebM.  The steps shown are left on the button
// (data-steps) with their flow times (data-times).
async function exportFilm() {
    const button = $('export-film');
    const job = state.job;
    if (!view || view.unavailable || !job || !state.frames.length || button.disabled) return;
    stopPlay();
    button.disabled = true;
    const label = button.textContent;
    try {
        const hist = await api.history(job.id, 2000);
        const times = frameFlowTimes(state.frames.map((f) => f.step), hist.steps);
        if (!times) throw new Error('this job\'s steps carry no flow time (stored by an older daemon)');
        const count = Math.min(FILM_FRAMES, Math.max(2, state.frames.length));
        const picks = equalTimeFrames(times, count);
        button.textContent = 'recording…';
        const blob = await recordCanvas(view.renderer.domElement, picks.length, FILM_FPS, (k) => {
            showFrame(picks[k]);
            view.renderNow();
        });
        button.dataset.steps = picks.map((i) => state.frames[i].step).join(' ');
        button.dataset.times = picks.map((i) => times[i]).join(' ');
        saveBlob(blob, exportName('film.webm'));
    } catch (err) {
        showProblem($('job-error'), err);
    } finally {
        button.textContent = label;
        button.disabled = !state.frames.length || !webmType();
    }
}

// ------------------------------------------------------------------ wiring

function wire() {
    for (const b of document.querySelectorAll('.tabs [role=tab]')) {
        b.addEventListener('click', () => setSource(b.dataset.source));
    }
    $('catalogue-filter').addEventListener('input', fillCatalogue);
    $('catalogue-select').addEventListener('change', () => { updateCatalogueInfo(); updateNamePlaceholder(); });
    $('catalogue-select').addEventListener('dblclick', () => $('submit-form').requestSubmit());
    $('vect-file').addEventListener('change', async () => {
        const file = $('vect-file').files[0];
        if (!file) return;
        const text = await file.text();
        state.vectFile = { name: file.name.replace(/\.vect$/i, ''), text };
        $('vect-text').value = text;
        updateNamePlaceholder();
    });
    $('vect-text').addEventListener('input', updateNamePlaceholder);
    // Dropping a file on the text area reads it rather than inserting a path.
    $('vect-text').addEventListener('dragover', (e) => e.preventDefault());
    $('vect-text').addEventListener('drop', async (e) => {
        const file = e.dataTransfer?.files?.[0];
        if (!file) return;
        e.preventDefault();
        $('vect-text').value = await file.text();
    });
    for (const id of ['torus-p', 'torus-q', 'torus-n', 'opt-radius', 'opt-lambda']) {
        $(id).addEventListener('input', () => { if (state.source === 'torus') { updateTorusInfo(); updateNamePlaceholder(); } });
    }
    $('submit-form').addEventListener('submit', submit);

    $('jobs-newer').addEventListener('click', () => { state.jobsOffset = Math.max(0, state.jobsOffset - state.jobsLimit); refreshJobs(); });
    $('jobs-older').addEventListener('click', () => { state.jobsOffset += state.jobsLimit; refreshJobs(); });
    $('job-cancel').addEventListener('click', cancelJob);
    $('job-download-vect').addEventListener('click', downloadFile);
    $('job-download-struts').addEventListener('click', downloadFile);
    $('signin').addEventListener('submit', signIn);
    $('signout-button').addEventListener('click', () => { auth.signOut(); refreshJobs(); });
    auth.onChange(showSignIn);

    $('strut-table').tHead.addEventListener('click', (e) => {
        const th = e.target.closest('th[data-key]');
        if (!th) return;
        const key = th.dataset.key;
        state.sort = { key, dir: state.sort.key === key ? -state.sort.dir : 1 };
        renderStruts();
    });
    const tbody = $('strut-table').tBodies[0];
    tbody.addEventListener('mouseover', (e) => {
        const tr = e.target.closest('tr[data-index]');
        if (tr) setHot(Number(tr.dataset.index));
    });
    tbody.addEventListener('mouseleave', () => setHot(-1));

    $('replay-play').addEventListener('click', play);
    $('replay-slider').addEventListener('input', () => { stopPlay(); showFrame(Number($('replay-slider').value)); });
    $('replay-final').addEventListener('click', () => { stopPlay(); showFinal(); });
    $('replay-speed').addEventListener('change', () => { if (state.playTimer) { stopPlay(); play(); } });
    $('show-struts').addEventListener('change', () => view?.setShowStruts($('show-struts').checked));
    $('tube-opacity').addEventListener('input', () => view?.setOpacity(Number($('tube-opacity').value)));
    $('fit-view').addEventListener('click', () => view?.fit());
    $('export-png').addEventListener('click', exportPng);
    $('export-film').addEventListener('click', exportFilm);
    $('export-chart').addEventListener('click', () => saveBlob(standaloneSvg($('chart')), exportName('ropelength.svg')));
    $('export-map').addEventListener('click', () => saveBlob(standaloneSvg($('contact-map')), exportName('contacts.svg')));

    window.addEventListener('hashchange', () => {
        const m = /^#job=(\d+)$/.exec(location.hash);
        if (m && Number(m[1]) !== state.selected) selectJob(Number(m[1]));
    });
}

function start() {
    wire();
    showSignIn(auth.token() ? 'signed-in' : 'none');
    setSource('catalogue');
    loadCatalogue();
    refreshJobs();
    refreshHealth();
    setInterval(refreshJobs, JOBS_MS);
    setInterval(refreshHealth, 5000);
    const m = /^#job=(\d+)$/.exec(location.hash);
    if (m) selectJob(Number(m[1]));
    // Read back by the tests and handy from the console.
    window.tightknot = { state, get view() { return view; } };
}

start();
