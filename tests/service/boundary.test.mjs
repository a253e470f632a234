// The browser boundary: every endpoint answers a Host the daemon does not
// serve with 421 and a page of a foreign origin with 403, before reading a
// body; the daemon's own origin, the names given with --host and the
// origins given with --allow-origin pass, the latter with CORS headers and
// a preflight.  (tests/web/boundary.test.mjs does the same from a real
// browser.)

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { request as httpRequest } from 'node:http';
import { startDaemon, stopAll, submit, validateResponse, waitFinal } from './lib.mjs';

const SQUARE = 'VECT\n1 4 0\n-4\n0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n';
const ALLOWED = 'https://lab.example.org';

let d, job;

// One request with any headers (fetch will not forge Host); the answer is
// checked against openapi.yaml.
function raw(method, path, headers = {}, body) {
    return new Promise((resolve, reject) => {
        let answered = false;
        const req = httpRequest({ host: '127.0.0.1', port: d.port, method, path, headers }, (res) => {
            answered = true;
            let text = '';
            res.setEncoding('utf8').on('data', (c) => (text += c)).on('end', () => {
                const type = res.headers['content-type'] ?? '';
                const json = /json/.test(type) ? JSON.parse(text) : undefined;
                validateResponse(method, path, res.statusCode, type, json);
                resolve({ status: res.statusCode, headers: res.headers, json, text });
            });
        });
        // an answer before the body is read may close the connection under
        // the body still being written (EPIPE): the answer is what counts
        req.on('error', (e) => { if (!answered) reject(e); });
        if (body && headers.Expect === '100-continue') {
            req.on('continue', () => req.end(body)); /* only when the daemon asks for it */
            req.flushHeaders();
        } else {
            if (body) req.write(body);
            req.end();
        }
    });
}

// Every operation of openapi.yaml, on an existing job.
const operations = () => [
    ['GET', '/'], ['GET', '/v1/jobs'], ['POST', '/v1/jobs?steps=5'], [`GET`, `/v1/jobs/${job}`],
    ['DELETE', `/v1/jobs/${job}`], ['GET', `/v1/jobs/${job}/struts`], ['GET', `/v1/jobs/${job}/vect`],
    ['GET', `/v1/jobs/${job}/history`], ['GET', `/v1/jobs/${job}/frames`], ['GET', '/v1/catalogue'],
    ['GET', '/v1/catalogue/3.1'], ['GET', '/v1/health'], ['GET', '/metrics'],
];

before(async () => {
    d = await startDaemon({ workers: 1, args: ['--host', 'tk.lab.example,10.1.2.3', '--allow-origin', ALLOWED] });
    job = (await submit(d, SQUARE, { query: 'steps=3' })).id;
    await waitFinal(d, job);
});

after(() => stopAll(d));

test('a Host the daemon does not serve gets 421 at every endpoint', async () => {
    for (const [method, path] of operations()) {
        for (const host of ['rebound.example', `rebound.example:${d.port}`, '127.0.0.2', '[::2]:80']) {
            const r = await raw(method, path, { Host: host, 'Content-Type': 'text/plain' },
                method === 'POST' ? SQUARE : undefined);
            assert.equal(r.status, 421, `${method} ${path} Host ${host}: ${r.text}`);
            assert.match(r.json.detail, /does not serve the host/);
        }
    }
    const list = await d.get('/v1/jobs');
    assert.equal(list.json.total, 1, 'no job was added');
});

test('the bind address, localhost and the --host names are served, with or without a port', async () => {
    for (const host of ['127.0.0.1', `127.0.0.1:${d.port}`, 'localhost', `LocalHost:${d.port}`,
        'tk.lab.example', `tk.lab.example:${d.port}`, '10.1.2.3:8080']) {
        const r = await raw('GET', '/v1/health', { Host: host });
        assert.equal(r.status, 200, `Host ${host}: ${r.text}`);
    }
});

test('a page of a foreign origin gets 403 at every endpoint, a big body unread', async () => {
    for (const [method, path] of operations()) {
        for (const origin of ['http://evil.example', 'null', `http://127.0.0.1:${d.port + 1}`,
            `http://localhost.evil.example:${d.port}`]) {
            const r = await raw(method, path, { Origin: origin, 'Content-Type': 'text/plain' },
                method === 'POST' ? SQUARE : undefined);
            assert.equal(r.status, 403, `${method} ${path} Origin ${origin}: ${r.text}`);
            assert.equal(r.headers['access-control-allow-origin'], undefined);
        }
    }
    const big = 'VECT\n' + ' '.repeat(8 << 20);
    const t0 = performance.now();
    const r = await raw('POST', '/v1/jobs', { Origin: 'http://evil.example', 'Content-Type': 'text/plain',
        'Content-Length': String(big.length), Expect: '100-continue' }, big);
    assert.equal(r.status, 403);
    assert.ok(performance.now() - t0 < 5000);
    assert.equal((await d.get(`/v1/jobs/${job}`)).json.state, 'done', 'DELETE was refused');
    assert.equal((await d.get('/v1/jobs')).json.total, 1, 'no job was added');
});

test('the daemon\'s own origin passes (the page it serves), without CORS headers', async () => {
    for (const origin of [`http://127.0.0.1:${d.port}`, `http://localhost:${d.port}`]) {
        const host = new URL(origin).host;
        const r = await raw('POST', '/v1/jobs?steps=3', { Origin: origin, Host: host, 'Content-Type': 'text/plain' },
            SQUARE);
        assert.equal(r.status, 202, `${origin}: ${r.text}`);
        assert.equal(r.headers['access-control-allow-origin'], undefined);
        await waitFinal(d, r.json.id);
    }
});

test('an origin allowed with --allow-origin passes with CORS headers and a preflight', async () => {
    const r = await raw('POST', '/v1/jobs?steps=3', { Origin: ALLOWED, 'Content-Type': 'text/plain' }, SQUARE);
    assert.equal(r.status, 202, r.text);
    assert.equal(r.headers['access-control-allow-origin'], ALLOWED);
    assert.equal(r.headers.vary, 'Origin');
    const g = await raw('GET', `/v1/jobs/${r.json.id}`, { Origin: ALLOWED });
    assert.equal(g.headers['access-control-allow-origin'], ALLOWED);
    for (const path of ['/v1/jobs', `/v1/jobs/${job}`]) {
        const p = await raw('OPTIONS', path, { Origin: ALLOWED, 'Access-Control-Request-Method': 'DELETE',
            'Access-Control-Request-Headers': 'content-type' });
        assert.equal(p.status, 204, p.text);
        assert.equal(p.headers['access-control-allow-origin'], ALLOWED);
        assert.match(p.headers['access-control-allow-methods'], /DELETE/);
        assert.match(p.headers['access-control-allow-headers'], /Content-Type/);
        // a preflight from elsewhere, or none at all
        assert.equal((await raw('OPTIONS', path, { Origin: 'http://evil.example' })).status, 403);
        assert.equal((await raw('OPTIONS', path)).status, 405);
    }
    await waitFinal(d, r.json.id);
});
