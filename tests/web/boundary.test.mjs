// The browser boundary in a real browser (headless Chromium) against the
// real daemon on loopback:
// - a page on another origin cannot submit a job, not even with a
//   text/plain POST, which a browser sends without asking first;
// - the same page can once the daemon allows its origin (--allow-origin),
//   and reads the answer (so the refusal above is the daemon's, not the
//   browser's);
// - a page that reaches the daemon's address under a name of its own (DNS
//   rebinding; here Chromium's host resolver rules map the name) gets 421
//   for the page and for the API, so it can read nothing.
//
// Environment: as page.test.mjs (TK_DAEMON, TK_CATALOGUE, TK_WEB,
// TK_CHROMIUM).

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { startDaemon, api } from './daemon.mjs';

const CHROMIUM = process.env.TK_CHROMIUM || '/usr/bin/chromium';
const SQUARE = 'VECT\n1 4 0\n-4\n0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n';

let other, otherBase, browser, page;

// What a page at `from` gets when it POSTs a knot to `url`: the response
// type and status it may see, or the error.
const postFrom = (url, mode) => page.evaluate(async ([u, m, body]) => {
    try {
        const r = await fetch(u, { method: 'POST', mode: m, headers: { 'Content-Type': 'text/plain' }, body });
        return { type: r.type, status: r.status, text: m === 'cors' ? await r.text() : '' };
    } catch (e) {
        return { error: String(e) };
    }
}, [url, mode, SQUARE]);

const jobCount = async (base) => (await api(base, '/v1/jobs')).body.total;

before(async () => {
    // another origin: a page of its own on another port
    other = createServer((req, res) => {
        res.writeHead(200, { 'Content-Type': 'text/html' });
        res.end('<!doctype html><title>elsewhere</title><p>another site</p>');
    });
    await new Promise((r) => other.listen(0, '127.0.0.1', r));
    otherBase = `http://127.0.0.1:${other.address().port}`;
    browser = await chromium.launch({
        executablePath: CHROMIUM,
        headless: true,
        args: ['--no-sandbox', '--host-resolver-rules=MAP rebound.test 127.0.0.1'],
    });
    page = await browser.newPage();
});

after(async () => {
    await browser?.close();
    await new Promise((r) => (other ? other.close(r) : r()));
});

test('a page on another origin cannot submit a job, even as text/plain', async () => {
    const d = await startDaemon();
    try {
        await page.goto(otherBase + '/');
        const r = await postFrom(`${d.base}/v1/jobs?steps=5`, 'no-cors');
        assert.equal(r.error, undefined, `the browser sent the request: ${JSON.stringify(r)}`);
        assert.equal(r.type, 'opaque');
        // the daemon took nothing
        assert.equal(await jobCount(d.base), 0);
        // and it said why (the same request from here, with that Origin)
        const direct = await api(d.base, '/v1/jobs?steps=5', {
            method: 'POST', headers: { 'Content-Type': 'text/plain', Origin: otherBase }, body: SQUARE });
        assert.equal(direct.status, 403);
        assert.match(direct.body.detail, /--allow-origin/);
        assert.equal(await jobCount(d.base), 0);
    } finally {
        await d.stop();
    }
});

test('an origin allowed with --allow-origin submits and reads the answer', async () => {
    const d = await startDaemon(['--allow-origin', `https://unused.example,${otherBase}`]);
    try {
        await page.goto(otherBase + '/');
        const r = await postFrom(`${d.base}/v1/jobs?steps=5`, 'cors');
        assert.equal(r.error, undefined, JSON.stringify(r));
        assert.equal(r.type, 'cors');
        assert.equal(r.status, 202, r.text);
        assert.equal(JSON.parse(r.text).state, 'queued');
        assert.equal(await jobCount(d.base), 1);
        // JSON needs a preflight: answered for this origin
        const json = await page.evaluate(async (u) => {
            const res = await fetch(u, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                body: JSON.stringify({ catalogue: '3.1', options: { steps: 5 } }) });
            return res.status;
        }, `${d.base}/v1/jobs`);
        assert.equal(json, 202);
        assert.equal(await jobCount(d.base), 2);
    } finally {
        await d.stop();
    }
});

test('a name that is not the daemon\'s (DNS rebinding) gets 421, the page and the API', async () => {
    const d = await startDaemon();
    try {
        const port = new URL(d.base).port;
        const res = await page.goto(`http://rebound.test:${port}/`);
        assert.equal(res.status(), 421);
        const seen = await page.evaluate(async () => {
            const r = await fetch('/v1/jobs');
            return { status: r.status, body: await r.text() };
        });
        assert.equal(seen.status, 421);
        assert.match(seen.body, /does not serve the host 'rebound\.test'/);
        // its own name serves the page
        const own = await page.goto(`${d.base}/`);
        assert.equal(own.status(), 200);
    } finally {
        await d.stop();
    }
});

test('with --tokens: the page says a token is needed, tells a wrong one apart, signs in and out, and downloads with it', async () => {
    const dir = mkdtempSync(join(tmpdir(), 'tk-web-tokens-'));
    writeFileSync(join(dir, 'tokens'), 'ann ann-token-00000001\n');
    const d = await startDaemon(['--tokens', join(dir, 'tokens')]);
    const context = await browser.newContext({ acceptDownloads: true });
    const p = await context.newPage();
    try {
        const job = await api(d.base, '/v1/jobs?steps=3', { method: 'POST',
            headers: { 'Content-Type': 'text/plain', Authorization: 'Bearer ann-token-00000001' }, body: SQUARE });
        assert.equal(job.status, 202);
        const dialogs = [];
        p.on('dialog', async (dialog) => { dialogs.push(dialog.message()); await dialog.dismiss(); });
        await p.goto(`${d.base}/`);
        const state = () => p.locator('#signin-state').getAttribute('data-state');
        await p.waitForFunction(() => document.getElementById('signin-state').dataset.state === 'token-needed');
        assert.match(await p.locator('#signin-state').innerText(), /needs a token/);
        // a wrong token is told apart from none
        await p.fill('#signin-token', 'not-the-token-0000');
        await p.click('#signin-button');
        await p.waitForFunction(() => document.getElementById('signin-state').dataset.state === 'wrong-token');
        assert.match(await p.locator('#signin-state').innerText(), /wrong token/);
        // the right one: the catalogue and the job list load, and the
        // field keeps nothing shown
        await p.fill('#signin-token', 'ann-token-00000001');
        await p.click('#signin-button');
        await p.waitForFunction(() => document.querySelectorAll('#catalogue-select option').length > 0,
            null, { timeout: 20000 });
        assert.equal(await state(), 'signed-in');
        assert.equal(await p.inputValue('#signin-token'), '');
        assert.equal(await p.evaluate(() => sessionStorage.getItem('tightknot.token')), 'ann-token-00000001');
        await p.waitForFunction((id) => document.querySelector(`#jobs-table tr[data-id="${id}"]`) !== null,
            job.body.id, { timeout: 20000 });
        // the job's files download with the token (a bare link would get 401)
        await p.goto(`${d.base}/#job=${job.body.id}`);
        await p.waitForFunction(() => !document.getElementById('job-download-vect').disabled, null, { timeout: 20000 });
        const [vect] = await Promise.all([p.waitForEvent('download'), p.click('#job-download-vect')]);
        const text = readFileSync(await vect.path(), 'utf8');
        const direct = await api(d.base, `/v1/jobs/${job.body.id}/vect`, { headers: { Authorization: 'Bearer ann-token-00000001' } });
        assert.equal(text, direct.body);
        assert.match(vect.suggestedFilename(), new RegExp(`-${job.body.id}\\.vect$`));
        // kept for the session; nothing ever prompts
        await p.reload();
        await p.waitForFunction(() => document.querySelectorAll('#catalogue-select option').length > 0);
        assert.equal(await state(), 'signed-in');
        // signed out: the token is gone and the next answer says one is needed
        await p.click('#signout-button');
        assert.equal(await p.evaluate(() => sessionStorage.getItem('tightknot.token')), null);
        await p.waitForFunction(() => document.getElementById('signin-state').dataset.state === 'token-needed',
            null, { timeout: 20000 });
        assert.deepEqual(dialogs, [], 'no dialog');
    } finally {
        await context.close();
        await d.stop();
    }
});
