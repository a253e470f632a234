// The page in a real browser (headless Chromium) against the real daemon:
// submit through the form, watch, look at the tube, the struts, the contact
// map, replay, cancel, download, and the messages for rejected input.
//
// Environment (relative paths from the current directory; the defaults
// from the repository root):
//   TK_DAEMON     the daemon (default build/tightknotd)
//   TK_CATALOGUE  the catalogue directory (default ../shared/catalogue)
//   TK_WEB        the built page (default build/web, see tools/build-web.sh)
//   TK_CHROMIUM   the browser (default /usr/bin/chromium)
// Screenshots go to test-artifacts/web/.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { ARTIFACTS, sleep, startDaemon, api as daemonApi } from './daemon.mjs';
import { canvasStatsInPage } from './canvas.mjs';
import { assertFilm } from './webm.mjs';

const CHROMIUM = process.env.TK_CHROMIUM || '/usr/bin/chromium';

let daemon, base, browser, page;
const pageErrors = [];
const consoleErrors = [];
const shared = {};  // what one test leaves for the next

const api = (path, init) => daemonApi(base, path, init);

// The 3-D canvas read back (see canvas.mjs).
const canvasPixels = () => page.evaluate(canvasStatsInPage);

// The mean absolute difference of two thumbnails, per channel value.
function difference(a, b) {
    let s = 0;
    for (let i = 0; i < a.thumb.length; i++) s += Math.abs(a.thumb[i] - b.thumb[i]);
    return s / a.thumb.length;
}

async function waitJob(id, states, ms = 120000) {
    const end = Date.now() + ms;
    for (;;) {
        const { body } = await api(`/v1/jobs/${id}`);
        if (states.includes(body.state)) return body;
        if (Date.now() > end) throw new Error(`job ${id} is still ${body.state}`);
        await sleep(200);
    }
}

// Submits the form and returns the new job's id, as the page reports it.
// The page drops the last message and job number as soon as it submits.
async function submitForm() {
    await page.click('#submit-button');
    await page.waitForFunction(() => {
        const m = document.getElementById('submit-message');
        return !m.hidden && (m.classList.contains('error') || m.dataset.job);
    });
    const id = await page.locator('#submit-message').getAttribute('data-job');
    const isError = await page.locator('#submit-message.error').count();
    assert.equal(isError, 0, `the page reports: ${await page.locator('#submit-message').innerText()}`);
    return Number(id);
}

async function setOptions(o) {
    for (const [k, v] of Object.entries(o)) await page.fill(`#opt-${k}`, String(v));
}

before(async () => {
    mkdirSync(ARTIFACTS, { recursive: true });
    daemon = await startDaemon();
    base = daemon.base;
    browser = await chromium.launch({
        executablePath: CHROMIUM,
        headless: true,
        // Root needs --no-sandbox; WebGL runs on SwiftShader without a GPU.
        args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
    });
    page = await browser.newPage({ viewport: { width: 1366, height: 768 }, acceptDownloads: true });
    page.on('pageerror', (e) => pageErrors.push(e.message));
    page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
    page.setDefaultTimeout(30000);
});

after(async () => {
    await browser?.close();
    await daemon?.stop();
});

test('the page and its libraries come from the daemon, with the catalogue', async () => {
    const requests = [];
    page.on('request', (r) => requests.push(r.url()));
    await page.goto(base + '/');
    const { body: cat } = await api('/v1/catalogue');
    await page.waitForFunction((n) => document.querySelectorAll('#catalogue-select option').length === n, cat.count);
    assert.equal(await page.title(), 'tightknot');
    assert.ok(requests.some((u) => u.endsWith('/vendor/three/build/three.module.js')), 'three.js is loaded');
    const foreign = requests.filter((u) => !u.startsWith(base));
    assert.deepEqual(foreign, [], 'no request leaves the daemon');
});

// The form as it loads: a catalogue link with no option touched ends
// tight, converged before its cap, within 0.1% of the exact 8 pi.
test('the form\'s defaults tighten: the Hopf link ends converged at 8 pi', async () => {
    await page.click('#tab-catalogue');
    await page.fill('#catalogue-filter', '2.2.1');
    assert.equal(await page.inputValue('#catalogue-select'), '2.2.1');
    const id = await submitForm();
    const job = await waitJob(id, ['done', 'failed', 'cancelled']);
    assert.equal(job.state, 'done', JSON.stringify(job));
    assert.equal(job.stop_reason, 'converged');
    const o = job.options;
    assert.ok(o.resolution === 5 && o.autoscale === true && o.converge === true && o.work === 120 && o.time === 0 &&
        o.steps === 0,
        JSON.stringify(o));
    assert.ok(job.ropelength > 8 * Math.PI && job.ropelength < 8 * Math.PI * 1.001, `ropelength ${job.ropelength}`);
    await page.fill('#catalogue-filter', '');
});

test('a catalogue knot submitted through the form is tightened and shown', async () => {
    await page.click('#tab-catalogue');
    // a name typed exactly comes first and is picked (0.3.1 comes before
    // 3.1 in the catalogue), then the names that begin with it
    await page.fill('#catalogue-filter', '3.1');
    const options = await page.locator('#catalogue-select option').evaluateAll((os) => os.map((o) => o.value));
    assert.ok(options.length > 1, `3.1 is held by other names too: ${options.join(' ')}`);
    assert.equal(options[0], '3.1');
    const begins = options.filter((n) => n.startsWith('3.1')).length;
    assert.ok(options.slice(0, begins).every((n) => n.startsWith('3.1')), options.join(' '));
    assert.equal(await page.inputValue('#catalogue-select'), '3.1');
    await page.selectOption('#catalogue-select', '3.1');
    await setOptions({ resolution: 5, steps: 300, every: 10, work: 0, residual: 0 });
    const id = await submitForm();
    shared.trefoil = id;
    await page.waitForSelector('#job-state[data-state="done"]', { timeout: 120000 });
    await page.waitForSelector('#job[data-phase="final"]');
    await page.waitForTimeout(300);
    await page.screenshot({ path: join(ARTIFACTS, 'done.png'), fullPage: true });

    const { body: job } = await api(`/v1/jobs/${id}`);
    const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
    assert.equal(job.state, 'done');
    assert.equal(job.options.steps, 300);
    assert.equal(job.options.every, 10);
    assert.ok(contacts.struts.length > 0, 'a tightened trefoil has struts');
    assert.equal(await page.locator('#strut-table tbody tr').count(), contacts.struts.length, 'one table row per strut');
    assert.equal(await page.locator('#contact-map .strut-mark').count(), contacts.struts.length, 'one contact-map mark per strut');
    assert.equal(await page.locator('#contact-map .kink-mark').count(), contacts.kinks.length, 'one mark per kink');
    assert.equal(await page.locator('#kink-table tbody tr').count(), contacts.kinks.length);
    // the components' boundaries: none for a knot
    assert.equal(await page.locator('#contact-map .boundary').count(), 0);

    assert.equal(await page.locator('#fig-struts').innerText(), String(job.struts));
    assert.equal(await page.locator('#fig-ropelength').innerText(), job.ropelength.toFixed(3));
    assert.equal(await page.locator('#fig-step').innerText(), String(job.progress.step));
    assert.equal(await page.locator('#fig-step-label').innerText(), 'step of 300');
    // the type: the trefoil's, kept by the run
    assert.deepEqual(job.invariants.result.alexander, [[1, -1, 1]]);
    assert.equal(await page.locator('#fig-type').innerText(), '1 - t + t^2 (det 3)');
    // the basins the run reached, as the job says, lowest first
    assert.equal(await page.locator('#fig-basins').innerText(),
        job.basins.basins.map((b) => `${b.ropelength.toFixed(4)} ×${b.times}`).join(', '));
    const d = await page.locator('#chart path.curve').getAttribute('d');
    assert.ok((d.match(/L/g) || []).length >= 2, 'the chart draws the history');

    const row = page.locator(`#jobs-table tbody tr[data-id="${id}"]`);
    await row.waitFor();
    assert.match(await row.innerText(), /done/);
    assert.match(await row.innerText(), new RegExp(job.ropelength.toFixed(3).replace('.', '\\.')));

    const px = await canvasPixels();
    assert.ok(px.w > 300 && px.h > 200, `the canvas is ${px.w}x${px.h}`);
    assert.ok(px.share > 0.03, `the 3-D view is not blank (${(100 * px.share).toFixed(1)}% drawn)`);
    assert.ok(px.colours > 20, `the tube is shaded (${px.colours} colours)`);
    shared.finalPixels = px;
});

test('hovering a strut row highlights that strut in 3-D and on the map', async () => {
    const beforePx = await canvasPixels();
    const row = page.locator('#strut-table tbody tr').first();
    const index = await row.getAttribute('data-index');
    await row.hover();
    await page.waitForTimeout(200);
    const hoverPx = await canvasPixels();
    assert.ok(difference(beforePx, hoverPx) > 0.05, 'the highlight changes the picture');
    assert.equal(await page.locator(`#contact-map .strut-mark.hot[data-index="${index}"]`).count(), 1);
    await page.mouse.move(5, 5);
    await page.hover('#job-name');
    await page.waitForTimeout(200);
    assert.equal(await page.locator('#contact-map .strut-mark.hot').count(), 0);
});

test('the strut table sorts by a column when its header is clicked', async () => {
    const id = shared.trefoil;
    const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
    const forces = contacts.struts.map((s) => s.force);
    const column = async () => (await page.locator('#strut-table tbody tr td:nth-child(7)').allInnerTexts()).map(Number);
    await page.click('#strut-table th[data-key="force"]');
    assert.equal(await page.locator('#strut-table th[data-key="force"]').getAttribute('aria-sort'), 'ascending');
    const up = await column();
    assert.deepEqual(up, [...up].sort((a, b) => a - b));
    assert.equal(up.length, forces.length);
    await page.click('#strut-table th[data-key="force"]');
    assert.equal(await page.locator('#strut-table th[data-key="force"]').getAttribute('aria-sort'), 'descending');
    const down = await column();
    assert.deepEqual(down, [...down].sort((a, b) => b - a));
    assert.ok(Math.abs(down[0] - Math.max(...forces)) <= 1e-3 * Math.max(...forces), 'the largest force comes first');
    await page.click('#strut-table th[data-key="index"]');
});

test('replay draws the run\'s frames', async () => {
    const id = shared.trefoil;
    const { body: frames } = await api(`/v1/jobs/${id}/frames?limit=1`);
    assert.ok(frames.total >= 2, 'the run kept frames');
    const slider = page.locator('#replay-slider');
    await page.waitForFunction(() => !document.getElementById('replay-slider').disabled);
    assert.equal(Number(await slider.getAttribute('max')), frames.total - 1);

    const finalPx = await canvasPixels();
    await slider.focus();
    await page.keyboard.press('Home');
    await page.waitForFunction(() => /step 0\b/.test(document.getElementById('replay-label').textContent));
    await page.evaluate(() => window.scrollTo(0, 0));
    const firstPx = await canvasPixels();
    assert.ok(difference(finalPx, firstPx) > 0.5, 'the first frame differs from the final curve');
    assert.ok(firstPx.share > 0.03, 'the first frame is drawn');

    await page.click('#replay-play');
    await page.waitForFunction(() => {
        const m = /step (\d+)/.exec(document.getElementById('replay-label').textContent);
        return m && Number(m[1]) >= 60;
    });
    await page.screenshot({ path: join(ARTIFACTS, 'replay.png') });
    const playingPx = await canvasPixels();
    assert.ok(difference(firstPx, playingPx) > 0.5, 'playing moves on from the first frame');
    await page.waitForFunction(() => document.getElementById('replay-play').textContent.includes('Play'), null, { timeout: 30000 });
    assert.equal(Number(await slider.inputValue()), frames.total - 1, 'the replay ends at the last frame');

    await page.click('#replay-final');
    await page.waitForFunction(() => document.getElementById('view3d-label').textContent.startsWith('stored curve'));
});

test('the final VECT and the struts JSON download', async () => {
    const id = shared.trefoil;
    const [vect] = await Promise.all([page.waitForEvent('download'), page.click('#job-download-vect')]);
    const text = readFileSync(await vect.path(), 'utf8');
    assert.match(text, /^VECT/);
    assert.equal(text, (await api(`/v1/jobs/${id}/vect`)).body);
    assert.match(vect.suggestedFilename(), /\.vect$/);
    const [json] = await Promise.all([page.waitForEvent('download'), page.click('#job-download-struts')]);
    const got = JSON.parse(readFileSync(await json.path(), 'utf8'));
    assert.deepEqual(got, (await api(`/v1/jobs/${id}/struts`)).body);
});

test('the 3-D view exports as PNG, the chart and the contact map as SVG files of their own', async () => {
    const id = shared.trefoil;
    const { body: job } = await api(`/v1/jobs/${id}`);
    const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
    const [png] = await Promise.all([page.waitForEvent('download'), page.click('#export-png')]);
    const bytes = readFileSync(await png.path());
    assert.deepEqual([...bytes.subarray(0, 8)], [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a], 'a PNG');
    const canvas = await page.evaluate(() => { const c = document.querySelector('#view3d canvas'); return [c.width, c.height]; });
    assert.deepEqual([bytes.readUInt32BE(16), bytes.readUInt32BE(20)], canvas, 'the canvas, pixel for pixel in size');
    assert.equal(png.suggestedFilename(), `${job.name}-${id}-view.png`);
    for (const [button, name, check] of [
        ['#export-chart', 'ropelength.svg', (doc) => assert.equal(doc.match(/class="curve"/g)?.length, 1)],
        ['#export-map', 'contacts.svg', (doc) => assert.equal(doc.match(/class="strut-mark/g)?.length, contacts.struts.length)],
    ]) {
        const [svg] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
        const text = readFileSync(await svg.path(), 'utf8');
        assert.equal(svg.suggestedFilename(), `${job.name}-${id}-${name}`);
        assert.match(text, /^<\?xml [^>]*>\n<svg [^>]*xmlns="http:\/\/www\.w3\.org\/2000\/svg"/);
        check(text);
        // it stands alone: parsed by the browser as an image, drawn with
        // its own styles (no stylesheet)
        const drawn = await page.evaluate(async (t) => {
            const img = new Image();
            img.src = URL.createObjectURL(new Blob([t], { type: 'image/svg+xml' }));
            await img.decode();
            return [img.naturalWidth, img.naturalHeight];
        }, text);
        assert.ok(drawn[0] > 0 && drawn[1] > 0, `drawn ${drawn}`);
        assert.doesNotMatch(text, /var\(--/, 'no stylesheet variable left unresolved');
    }
});

// The film: WebM from the 3-D view, its frames at equal flow time.  The
// flow time is checked against its definition (the step sizes summed,
// from the job's every stored step: 300 steps, none thinned), and every
// film frame against all the run's frames (brute force): none is nearer
// its time on the equal grid than the one shown.
test('the film is a WebM of the run at equal flow time', async () => {
    const id = shared.trefoil;
    const { body: job } = await api(`/v1/jobs/${id}`);
    const { body: hist } = await api(`/v1/jobs/${id}/history?limit=2000`);
    assert.equal(hist.steps.length, job.progress.step + 1, 'every step stored');
    let sum = 0;
    for (const s of hist.steps) {
        sum += s.step_size ?? 0;
        assert.ok(Math.abs(s.flow_time - sum) <= 1e-12 * Math.max(1, sum), `step ${s.step}: flow_time ${s.flow_time}, sum of h ${sum}`);
    }
    const flow = new Map(hist.steps.map((s) => [s.step, s.flow_time]));
    await page.waitForFunction(() => !document.getElementById('export-film').disabled, null, { timeout: 20000 });
    const [film] = await Promise.all([page.waitForEvent('download', { timeout: 60000 }), page.click('#export-film')]);
    assert.equal(film.suggestedFilename(), `${job.name}-${id}-film.webm`);
    const bytes = readFileSync(await film.path());
    assert.deepEqual([...bytes.subarray(0, 4)], [0x1a, 0x45, 0xdf, 0xa3], 'an EBML file');
    assert.ok(bytes.includes(Buffer.from('webm')), 'of DocType webm');
    assert.ok(bytes.length > 2000, `${bytes.length} bytes`);
    const shown = (await page.getAttribute('#export-film', 'data-steps')).split(' ').map(Number);
    assertFilm(bytes, shown.length, 25, 'film');
    const { body: fr } = await api(`/v1/jobs/${id}/frames?limit=200`);
    const frameTimes = fr.frames.map((f) => flow.get(f.step));
    assert.equal(shown.length, Math.min(200, Math.max(2, fr.frames.length)));
    const t0 = frameTimes[0], t1 = frameTimes[frameTimes.length - 1];
    shown.forEach((step, k) => {
        const t = t0 + (t1 - t0) * k / (shown.length - 1);
        const best = Math.min(...frameTimes.map((x) => Math.abs(x - t)));
        assert.ok(Math.abs(flow.get(step) - t) <= best + 1e-12, `film frame ${k}: step ${step} at ${flow.get(step)}, time ${t}`);
    });
    assert.ok(new Set(shown).size > 2, `more than the first and last frame: ${shown}`);
});

test('a bad VECT is rejected with the problem\'s detail and line', async () => {
    const bad = 'VECT\n1 4 0\n-4\n0\n0 0 0\n4 0 0\nfoo 4 0\n0 4 0\n';
    const direct = await api('/v1/jobs', {
        method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ vect: bad }),
    });
    assert.equal(direct.status, 422);
    assert.equal(direct.body.line, 7);
    const totalBefore = (await api('/v1/jobs?limit=1')).body.total;

    await page.click('#tab-vect');
    await page.fill('#vect-text', bad);
    await page.click('#submit-button');
    const box = page.locator('#submit-message.error');
    await box.waitFor();
    const text = await box.innerText();
    assert.ok(text.includes(direct.body.detail), `the message shows the detail: ${text}`);
    assert.match(text, /line 7\b/);
    assert.equal(await box.locator('.where').getAttribute('data-line'), '7');
    // the cursor is put on the bad line
    const sel = await page.$eval('#vect-text', (t) => t.value.slice(t.selectionStart, t.selectionEnd));
    assert.equal(sel, 'foo 4 0');
    assert.equal((await api('/v1/jobs?limit=1')).body.total, totalBefore, 'no job was stored');
    await page.screenshot({ path: join(ARTIFACTS, 'bad-vect.png') });

    // an option the server refuses is named too
    await page.fill('#vect-text', 'VECT\n1 3 0\n-3\n0\n0 0 0\n4 0 0\n0 4 0\n');
    await page.fill('#opt-resolution', '-1');
    await page.click('#submit-button');
    await page.waitForFunction(() => /option resolution/.test(document.getElementById('submit-message').textContent));
    await page.fill('#opt-resolution', '5');
});

test('an uploaded VECT file is submitted, and its kinks are shown', async () => {
    await page.click('#tab-vect');
    await page.fill('#vect-text', '');
    // a triangle tightens into three kinks
    const triangle = 'VECT\n1 3 0\n-3\n0\n0 0 0\n4 0 0\n0 4 0\n';
    await page.setInputFiles('#vect-file', { name: 'triangle.vect', mimeType: 'text/plain', buffer: Buffer.from(triangle) });
    await page.waitForFunction(() => document.getElementById('vect-text').value.startsWith('VECT'));
    assert.equal(await page.getAttribute('#opt-name', 'placeholder'), 'triangle');
    await setOptions({ resolution: 0, steps: 100, every: 0 });
    const id = await submitForm();
    const job = await waitJob(id, ['done', 'failed']);
    assert.equal(job.name, 'triangle', 'the job is named after the file');
    assert.equal(job.state, 'done');
    await page.waitForSelector('#job[data-phase="final"]');
    assert.match(await page.locator('#replay-label').innerText(), /no frames/);
    const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
    assert.ok(contacts.kinks.length > 0);
    assert.equal(await page.locator('#contact-map .kink-mark').count(), contacts.kinks.length);
    assert.equal(await page.locator('#kink-table tbody tr').count(), contacts.kinks.length);
});

test('a torus link generated in the page is thick enough and has its components', async () => {
    await page.click('#tab-torus');
    await page.fill('#torus-p', '2');
    await page.fill('#torus-q', '4');
    await page.fill('#torus-n', '60');
    await page.waitForFunction(() => /2-component link/.test(document.getElementById('torus-info').textContent));
    await setOptions({ resolution: 0, steps: 30, every: 10 });
    const id = await submitForm();
    const job = await waitJob(id, ['done', 'failed']);
    assert.equal(job.state, 'done', job.error || '');
    assert.equal(job.components, 2);
    assert.equal(job.vertices, 120);
    assert.equal(job.name, 'T(2,4)');
    await page.waitForSelector('#job[data-phase="final"]');
    // T(2,4): two unknots with linking number 2 (its sign by orientation)
    // and the link's determinant 4
    const lk = job.invariants.result.linking[0][1];
    assert.equal(Math.abs(lk), 2);
    assert.equal(await page.locator('#fig-type').innerText(), `lk 0-1: ${lk} (det 1 1; link 4)`);
    const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
    assert.equal(await page.locator('#contact-map .boundary').count(), 2, 'one boundary line each way');
    assert.equal(await page.locator('#contact-map .strut-mark').count(), contacts.struts.length);
    const px = await canvasPixels();
    assert.ok(px.share > 0.03);
    await page.screenshot({ path: join(ARTIFACTS, 'torus-link.png'), fullPage: true });
});

test('a running job shows live figures and can be cancelled', async () => {
    await page.click('#tab-catalogue');
    await page.fill('#catalogue-filter', '');
    await page.selectOption('#catalogue-select', '8.19');
    await setOptions({ resolution: 10, steps: 1000000, work: 120, every: 50 });
    const id = await submitForm();
    await page.waitForSelector('#job-state[data-state="running"]', { timeout: 60000 });
    const stepOf = async () => Number(await page.locator('#fig-step').innerText());
    await page.waitForFunction(() => Number(document.getElementById('fig-step').textContent) > 0);
    const s1 = await stepOf();
    await page.waitForFunction((s) => Number(document.getElementById('fig-step').textContent) > s, s1);
    // the chart follows the polled figures between stored histories
    await page.waitForFunction(() => (document.querySelector('#chart path.curve')?.getAttribute('d').match(/L/g) || []).length >= 2);
    await page.screenshot({ path: join(ARTIFACTS, 'running.png') });
    // one step on the page: the figures, the 3-D view and the strut table
    // name the same stored step, at every look while the job runs
    const steps = () => page.evaluate(() => [
        document.getElementById('fig-step').textContent,
        /step (\d+)/.exec(document.getElementById('view3d-label').textContent)?.[1],
        /at step (\d+)/.exec(document.getElementById('struts-caption').textContent)?.[1],
    ].map(Number));
    // (once a step past the start is stored: before, only the input is)
    await page.waitForFunction(() => /at step [1-9]/.test(document.getElementById('struts-caption').textContent));
    const seen = new Set();
    for (let k = 0; k < 12; k++) {
        const [fig, view3d, table] = await steps();
        assert.ok(fig === view3d && view3d === table, `figures at step ${fig}, 3-D view ${view3d}, struts ${table}`);
        seen.add(fig);
        await sleep(500);
    }
    assert.ok(seen.size >= 2, `the shown step moves on while the job runs: ${[...seen]}`);
    await page.click('#job-cancel');
    await page.waitForSelector('#job-state[data-state="cancelled"]', { timeout: 30000 });
    const job = await waitJob(id, ['cancelled']);
    assert.equal(job.stop_reason, 'cancelled');
    assert.ok(await page.locator('#job-cancel').isDisabled());
    await page.waitForSelector('#job[data-phase="final"]');
});

test('selecting a job in the list shows it', async () => {
    const row = page.locator(`#jobs-table tbody tr[data-id="${shared.trefoil}"]`);
    await row.click();
    await page.waitForSelector('#job[data-phase="final"]');
    assert.equal(await page.locator('#job-id').innerText(), `#${shared.trefoil}`);
    assert.equal(await row.getAttribute('aria-selected'), 'true');
    const { body: contacts } = await api(`/v1/jobs/${shared.trefoil}/struts`);
    assert.equal(await page.locator('#strut-table tbody tr').count(), contacts.struts.length);
    assert.match(page.url(), new RegExp(`#job=${shared.trefoil}$`));
});

test('the chart breaks its line where the run took another curve', async () => {
    // the page's own drawing code, on figures whose `restarts` changes twice
    // (an escape's looser curve at step 3, the best put back at step 6)
    const drawn = await page.evaluate(async () => {
        const { drawHistory } = await import('/charts.js');
        const svg = document.createElementNS('http://www.w3.org/2000/svg', 'svg');
        const rope = [40, 35, 33, 60, 45, 38, 33, 32.9];
        const restarts = [0, 0, 0, 1, 1, 1, 2, 2];
        drawHistory(svg, rope.map((r, i) => ({ step: i, ropelength: r, restarts: restarts[i] })));
        const d = svg.querySelector('path.curve').getAttribute('d');
        return {
            moves: (d.match(/M/g) || []).length,
            lines: (d.match(/L/g) || []).length,
            ticks: [...svg.querySelectorAll('line.restart')].map((l) => l.querySelector('title').textContent),
        };
    });
    assert.equal(drawn.moves, 3, 'three pieces of line');
    assert.equal(drawn.lines, 5, 'joined within each piece');
    assert.deepEqual(drawn.ticks.map((t) => t.split(':')[0]), ['step 3', 'step 6']);
});

test('a clasp shows its constrained ends and planes, and its contact map along each rope', async () => {
    const { status, body: queued } = await api('/v1/jobs', {
        method: 'POST', headers: { 'content-type': 'application/json' },
        body: JSON.stringify({ catalogue: 'simple_clasp', options: { autoscale: true, steps: 600 } }),
    });
    assert.equal(status, 202, JSON.stringify(queued));
    await waitJob(queued.id, ['done']);
    await page.goto(`${base}/#job=${queued.id}`);
    await page.waitForSelector('#job[data-phase="final"]');
    const { body: contacts } = await api(`/v1/jobs/${queued.id}/struts`);
    assert.equal(contacts.constraints.length, 4);
    assert.match(await page.locator('#view3d-label').innerText(), /4 constrained vertices/);
    assert.match(await page.locator('#map-caption').innerText(), /along one rope.*Figure 6/);
    // one mark per strut, at its arclength along component 0 (x) and 1 (y):
    // the same affine map for every mark, increasing along both
    const marks = await page.locator('#contact-map .strut-mark').evaluateAll((ms) =>
        ms.map((m) => [Number(m.getAttribute('data-index')), Number(m.getAttribute('cx')), Number(m.getAttribute('cy'))]));
    assert.equal(marks.length, contacts.struts.length);
    assert.ok(marks.length >= 2, 'a hooked clasp has struts');
    const [c0, c1] = contacts.components;
    const along = contacts.struts.map((s) => {
        const first = s.edges[0][0] === 0 ? 0 : 1;
        return [s.arclength[first] - c0.start, s.arclength[1 - first] - c1.start];
    });
    const [i, j] = [0, 1].map((k) => marks[k][0]);
    const kx = (marks[1][1] - marks[0][1]) / (along[j][0] - along[i][0]);
    for (const [n, cx, cy] of marks) {
        assert.ok(Math.abs(cx - (marks[0][1] + kx * (along[n][0] - along[i][0]))) < 0.5, `strut ${n}: x`);
        assert.ok(Math.abs(cy - (marks[0][2] - kx * (along[n][1] - along[i][1]))) < 0.5, `strut ${n}: y at the same scale`);
    }
    assert.ok(kx > 0);
    await page.screenshot({ path: join(ARTIFACTS, 'clasp.png') });
});

test('no script errors', () => {
    assert.deepEqual(pageErrors, []);
    assert.deepEqual(consoleErrors.filter((e) => !/status of 4\d\d/.test(e)), []);
});
