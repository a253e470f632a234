// The page in headless Firefox against the real daemon: the catalogue,
// a knot submitted through the form and tightened, its struts in the table,
// on the contact map and in the 3-D view, the message for a bad VECT, and
// the page without WebGL.
//
// Firefox decides whether it may use WebGL by probing the X server's GL
// driver at startup, even when headless; without a display it offers no
// WebGL at all.  So a private Xvfb is started for that probe (Mesa's
// software renderer then draws), and Firefox still runs headless.
//
// Environment: TK_DAEMON, TK_CATALOGUE, TK_WEB as in daemon.mjs, and
//   TK_FIREFOX  the browser (default /usr/bin/firefox-esr)
//   TK_XVFB     the X server for the probe (default /usr/bin/Xvfb)
// Screenshots go to test-artifacts/web/firefox-*.png.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { mkdirSync, mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import puppeteer from 'puppeteer-core';
import { ARTIFACTS, sleep, startDaemon, api as daemonApi } from './daemon.mjs';
import { canvasStatsInPage } from './canvas.mjs';
import { assertFilm } from './webm.mjs';

const FIREFOX = process.env.TK_FIREFOX || '/usr/bin/firefox-esr';
const XVFB = process.env.TK_XVFB || '/usr/bin/Xvfb';

let daemon, base, xvfb, browser, page;
const pageErrors = [];
const consoleErrors = [];
const shared = {};  // what one test leaves for the next

const api = (path, init) => daemonApi(base, path, init);

// Starts Xvfb on a display number it picks itself; resolves to ":N".
function startXvfb() {
    xvfb = spawn(XVFB, ['-displayfd', '3', '-screen', '0', '1400x900x24', '-nolisten', 'tcp'],
        { stdio: ['ignore', 'ignore', 'pipe', 'pipe'] });
    let stderr = '';
    xvfb.stderr.on('data', (d) => { stderr += d; });
    return new Promise((resolveDisplay, reject) => {
        let out = '';
        const timer = setTimeout(() => reject(new Error(`Xvfb did not start: ${stderr}`)), 15000);
        xvfb.stdio[3].on('data', (d) => {
            out += d;
            if (out.includes('\n')) { clearTimeout(timer); resolveDisplay(`:${out.trim()}`); }
        });
        xvfb.on('error', (e) => { clearTimeout(timer); reject(e); });
        xvfb.on('exit', (code) => { clearTimeout(timer); reject(new Error(`Xvfb exited (${code}): ${stderr}`)); });
    });
}

async function stopXvfb() {
    if (!xvfb || xvfb.exitCode !== null || xvfb.signalCode !== null) return;
    const gone = new Promise((r) => xvfb.on('exit', r));
    xvfb.kill('SIGTERM');
    await Promise.race([gone, sleep(5000)]);
    if (xvfb.exitCode === null && xvfb.signalCode === null) xvfb.kill('SIGKILL');
}

function watchErrors(p) {
    p.on('pageerror', (e) => pageErrors.push(String(e?.message ?? e)));
    p.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
}

// The 3-D canvas read back (see canvas.mjs).
const canvasPixels = () => page.evaluate(canvasStatsInPage);

const count = (sel) => page.$$eval(sel, (els) => els.length);
const text = (sel) => page.$eval(sel, (el) => el.textContent);

async function fill(sel, value) {
    await page.locator(sel).fill(String(value));
}

before(async () => {
    mkdirSync(ARTIFACTS, { recursive: true });
    const display = await startXvfb();
    daemon = await startDaemon();
    base = daemon.base;
    browser = await puppeteer.launch({
        browser: 'firefox',
        executablePath: FIREFOX,
        headless: true,
        env: { ...process.env, DISPLAY: display },
        defaultViewport: { width: 1366, height: 768 },
        protocolTimeout: 120000,
    });
    page = await browser.newPage();
    watchErrors(page);
    page.setDefaultTimeout(30000);
});

after(async () => {
    await browser?.close();
    await daemon?.stop();
    await stopXvfb();
});

test('Firefox: the page loads with the whole catalogue and WebGL 2', async () => {
    await page.goto(base + '/');
    const { body: cat } = await api('/v1/catalogue');
    assert.ok(cat.count > 0);
    await page.waitForFunction((n) => document.querySelectorAll('#catalogue-select option').length === n, {}, cat.count);
    assert.equal(await page.title(), 'tightknot');
    const version = await browser.version();
    assert.match(version, /firefox/i);
    const gl = await page.evaluate(() => Boolean(document.createElement('canvas').getContext('webgl2')));
    assert.ok(gl, `${version} offers WebGL 2`);
});

test('Firefox: a catalogue knot submitted through the form is tightened and shown', async () => {
    await page.click('#tab-catalogue');
    await fill('#catalogue-filter', '3.1');
    await page.select('#catalogue-select', '3.1');
    await fill('#opt-resolution', 5);
    await fill('#opt-steps', 200);
    await fill('#opt-every', 10);
    await fill('#opt-work', 0);
    await fill('#opt-residual', 0);
    await page.click('#submit-button');
    await page.waitForFunction(() => {
        const m = document.getElementById('submit-message');
        return !m.hidden && (m.classList.contains('error') || m.dataset.job);
    });
    assert.equal(await count('#submit-message.error'), 0, `the page reports: ${await text('#submit-message')}`);
    const id = Number(await page.$eval('#submit-message', (m) => m.dataset.job));
    shared.trefoil = id;
    await page.waitForSelector('#job-state[data-state="done"]', { timeout: 120000 });
    await page.waitForSelector('#job[data-phase="final"]');
    await sleep(300);
    await page.screenshot({ path: join(ARTIFACTS, 'firefox-done.png'), fullPage: true });

    const { body: job } = await api(`/v1/jobs/${id}`);
    const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
    assert.equal(job.state, 'done');
    assert.equal(job.name, '3.1');
    assert.equal(job.options.steps, 200);
    assert.equal(job.options.every, 10);
    assert.ok(contacts.struts.length > 0, 'a tightened trefoil has struts');
    assert.equal(await count('#strut-table tbody tr'), contacts.struts.length, 'one table row per strut');
    assert.equal(await count('#contact-map .strut-mark'), contacts.struts.length, 'one contact-map mark per strut');
    assert.equal(await count('#contact-map .kink-mark'), contacts.kinks.length, 'one mark per kink');
    assert.equal(await text('#fig-struts'), String(job.struts));
    assert.equal(await text('#fig-ropelength'), job.ropelength.toFixed(3));
    assert.equal(await text('#fig-type'), '1 - t + t^2 (det 3)', 'the trefoil\'s type');
    const d = await page.$eval('#chart path.curve', (p) => p.getAttribute('d'));
    assert.ok((d.match(/L/g) || []).length >= 2, 'the chart draws the history');

    assert.equal(await count('#view3d .view3d-message'), 0, 'no message in place of the 3-D view');
    const px = await canvasPixels();
    assert.ok(px.w > 300 && px.h > 200, `the canvas is ${px.w}x${px.h}`);
    assert.ok(px.share > 0.03, `the 3-D view is not blank (${(100 * px.share).toFixed(1)}% drawn)`);
    assert.ok(px.colours > 20, `the tube is shaded (${px.colours} colours)`);
    shared.finalPixels = px;
});

test('Firefox: hovering a strut row marks that strut on the map', async () => {
    const index = await page.$eval('#strut-table tbody tr', (r) => r.dataset.index);
    await page.hover('#strut-table tbody tr');
    await page.waitForSelector(`#contact-map .strut-mark.hot[data-index="${index}"]`);
    await page.hover('#job-name');
    await page.waitForFunction(() => !document.querySelector('#contact-map .strut-mark.hot'));
});

// The exports, as Firefox saves them: the page hands each file to a link
// it clicks; the click is caught here and the file read back from its
// blob before the page lets it go.
test('Firefox: the view as PNG, the chart and map as SVG, the film as WebM', async () => {
    const id = shared.trefoil;
    const { body: job } = await api(`/v1/jobs/${id}`);
    await page.evaluate(() => {
        window.savedFiles = [];
        HTMLAnchorElement.prototype.click = function () {
            const name = this.download;
            fetch(this.href).then((r) => r.arrayBuffer())
                .then((b) => window.savedFiles.push({ name, bytes: Array.from(new Uint8Array(b)) }));
        };
    });
    const saved = async (n, timeout = 60000) => {
        await page.waitForFunction((k) => window.savedFiles.length >= k, { timeout }, n);
        return page.evaluate((k) => window.savedFiles[k - 1], n);
    };
    await page.click('#export-png');
    const png = await saved(1);
    assert.equal(png.name, `${job.name}-${id}-view.png`);
    assert.deepEqual(png.bytes.slice(0, 4), [0x89, 0x50, 0x4e, 0x47], 'a PNG');
    await page.click('#export-chart');
    const chart = await saved(2);
    assert.equal(chart.name, `${job.name}-${id}-ropelength.svg`);
    assert.match(Buffer.from(chart.bytes).toString('utf8'), /^<\?xml [^>]*>\n<svg [^>]*xmlns="http:\/\/www\.w3\.org\/2000\/svg"/);
    await page.click('#export-map');
    assert.equal((await saved(3)).name, `${job.name}-${id}-contacts.svg`);
    await page.waitForFunction(() => !document.getElementById('export-film').disabled, { timeout: 20000 });
    await page.click('#export-film');
    const film = await saved(4);
    assert.equal(film.name, `${job.name}-${id}-film.webm`);
    assert.deepEqual(film.bytes.slice(0, 4), [0x1a, 0x45, 0xdf, 0xa3], 'an EBML file');
    assert.ok(Buffer.from(film.bytes).includes(Buffer.from('webm')), 'of DocType webm');
    const shown = (await page.$eval('#export-film', (b) => b.dataset.steps)).split(' ').map(Number);
    assert.equal(shown.length, Math.min(200, Math.max(2, job.frames)));
    assertFilm(Uint8Array.from(film.bytes), shown.length, 25, 'Firefox film');
});

test('Firefox: a bad VECT is rejected with the problem\'s detail and line', async () => {
    const bad = 'VECT\n1 4 0\n-4\n0\n0 0 0\n4 0 0\nfoo 4 0\n0 4 0\n';
    const direct = await api('/v1/jobs', {
        method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ vect: bad }),
    });
    assert.equal(direct.status, 422);
    assert.equal(direct.body.line, 7);
    const totalBefore = (await api('/v1/jobs?limit=1')).body.total;

    await page.click('#tab-vect');
    await fill('#vect-text', bad);
    assert.equal(await page.$eval('#vect-text', (t) => t.value), bad, 'the textarea holds the pasted text');
    await page.click('#submit-button');
    await page.waitForSelector('#submit-message.error');
    const message = await text('#submit-message.error');
    assert.ok(message.includes(direct.body.detail), `the message shows the detail: ${message}`);
    assert.match(message, /line 7\b/);
    assert.equal(await page.$eval('#submit-message.error .where', (w) => w.dataset.line), '7');
    const sel = await page.$eval('#vect-text', (t) => t.value.slice(t.selectionStart, t.selectionEnd));
    assert.equal(sel, 'foo 4 0', 'the bad line is selected');
    assert.equal((await api('/v1/jobs?limit=1')).body.total, totalBefore, 'no job was stored');
    await page.screenshot({ path: join(ARTIFACTS, 'firefox-bad-vect.png') });
});

test('Firefox: without WebGL the page says so and shows the rest', async () => {
    const id = shared.trefoil;
    assert.ok(id, 'the trefoil of the earlier test');
    const plain = await browser.newPage();
    watchErrors(plain);
    try {
        // As a browser with WebGL switched off: no context of either kind.
        await plain.evaluateOnNewDocument(() => {
            const getContext = HTMLCanvasElement.prototype.getContext;
            HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
                return /^(webgl|webgl2|experimental-webgl)$/.test(kind) ? null : getContext.call(this, kind, ...rest);
            };
        });
        await plain.goto(`${base}/#job=${id}`);
        await plain.waitForSelector('#job[data-phase="final"]', { timeout: 30000 });
        const message = await plain.$eval('#view3d .view3d-message', (m) => m.textContent);
        assert.match(message, /WebGL/);
        assert.equal(await plain.$$eval('#view3d canvas', (c) => c.length), 0, 'no canvas');
        const { body: contacts } = await api(`/v1/jobs/${id}/struts`);
        assert.equal(await plain.$$eval('#strut-table tbody tr', (r) => r.length), contacts.struts.length);
        assert.equal(await plain.$$eval('#contact-map .strut-mark', (m) => m.length), contacts.struts.length);
        await plain.hover('#strut-table tbody tr');
        await plain.waitForSelector('#contact-map .strut-mark.hot');
        await plain.screenshot({ path: join(ARTIFACTS, 'firefox-no-webgl.png') });
    } finally {
        await plain.close();
    }
});

// A tokened daemon, as in boundary.test.mjs for Chromium: "token needed"
// told from "wrong token", sign in, both files downloaded with the token
// (read back from the blob the page saves), sign out.
test('Firefox: with --tokens: token needed, wrong token, sign in, downloads, sign out', async () => {
    const dir = mkdtempSync(join(tmpdir(), 'tk-ff-tokens-'));
    writeFileSync(join(dir, 'tokens'), 'ann ann-token-00000001\n');
    const d = await startDaemon(['--tokens', join(dir, 'tokens')]);
    const p = await browser.newPage();
    watchErrors(p);
    const auth = { Authorization: 'Bearer ann-token-00000001' };
    try {
        const square = 'VECT\n1 4 0\n-4\n0\n0 0 0\n4 0 0\n4 4 0\n0 4 0\n';
        const job = await daemonApi(d.base, '/v1/jobs?steps=3', { method: 'POST',
            headers: { 'Content-Type': 'text/plain', ...auth }, body: square });
        assert.equal(job.status, 202);
        const state = () => p.$eval('#signin-state', (e) => e.dataset.state);
        await p.goto(`${d.base}/`);
        await p.waitForFunction(() => document.getElementById('signin-state').dataset.state === 'token-needed');
        await p.locator('#signin-token').fill('not-the-token-0000');
        await p.click('#signin-button');
        await p.waitForFunction(() => document.getElementById('signin-state').dataset.state === 'wrong-token');
        await p.locator('#signin-token').fill('ann-token-00000001');
        await p.click('#signin-button');
        await p.waitForFunction(() => document.querySelectorAll('#catalogue-select option').length > 0, { timeout: 20000 });
        assert.equal(await state(), 'signed-in');
        await p.goto(`${d.base}/#job=${job.body.id}`);
        await p.waitForFunction(() => !document.getElementById('job-download-vect').disabled, { timeout: 20000 });
        await p.evaluate(() => {
            window.savedFiles = [];
            HTMLAnchorElement.prototype.click = function () {
                const name = this.download;
                fetch(this.href).then((r) => r.text()).then((t) => window.savedFiles.push({ name, text: t }));
            };
        });
        await p.click('#job-download-vect');
        await p.click('#job-download-struts');
        await p.waitForFunction(() => window.savedFiles.length >= 2, { timeout: 20000 });
        const saved = await p.evaluate(() => window.savedFiles);
        const vect = saved.find((f) => f.name.endsWith('.vect')), struts = saved.find((f) => f.name.endsWith('-struts.json'));
        assert.equal(vect?.text, (await daemonApi(d.base, `/v1/jobs/${job.body.id}/vect`, { headers: auth })).body);
        assert.deepEqual(JSON.parse(struts?.text ?? 'null'),
            (await daemonApi(d.base, `/v1/jobs/${job.body.id}/struts`, { headers: auth })).body);
        await p.click('#signout-button');
        assert.equal(await p.evaluate(() => sessionStorage.getItem('tightknot.token')), null);
        await p.waitForFunction(() => document.getElementById('signin-state').dataset.state === 'token-needed', { timeout: 20000 });
    } finally {
        await p.close();
        await d.stop();
    }
});

test('Firefox: no script errors', () => {
    assert.deepEqual(pageErrors, []);
    assert.deepEqual(consoleErrors.filter((e) => !/status of 4\d\d/.test(e)), []);
});
