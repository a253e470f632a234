// Bad requests: malformed VECT (422 naming the line), oversized bodies
// (413), bad JSON (400), bad options (422 naming the option), wrong media
// type (415), unknown paths (404), wrong methods (405 with Allow).  Every
// answer is also checked against openapi.yaml by the request helper.

import assert from 'node:assert/strict';
import { request as httpRequest } from 'node:http';
import { after, before, describe, test } from 'node:test';

import { startDaemon, submit, validateResponse, waitFinal } from './lib.mjs';

const MAX_BODY = 1000;
let d;
before(async () => {
    d = await startDaemon({ workers: 1, maxBody: MAX_BODY });
});
after(async () => d && (await d.stop()));

const TRIANGLE = 'VECT\n1 3 0\n-3\n0\n0 0 0\n4 0 0\n0 4 0\n';

// [description, body, the line the reader must blame].  The lines follow
// engine/vect.c's rules (tests/test_vect.c): the line of the offending
// token; at the end of the file, the last line holding text; a count that
// the rest of the file cannot hold, the header's count line.
const MALFORMED = [
    ['empty body', '', 1],
    ['only blank lines and a comment', '\n\n# nothing\n', 3],
    ['missing header', '1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n', 1],
    ['lower-case header after comments', '# comment\n\nvect\n1 2 0\n2\n0\n0 0 0 1 1 1\n', 3],
    ['header VECTOR', 'VECTOR\n1 2 0\n2\n0\n0 0 0 1 1 1\n', 1],
    ['header only', 'VECT\n', 1],
    ['non-integer component count', 'VECT\n1.0 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n', 2],
    ['zero components', 'VECT\n0 0 0\n', 2],
    ['negative components', 'VECT\n-1 3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n', 2],
    ['negative vertex count', 'VECT\n1 -3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n', 2],
    ['negative colour count', 'VECT\n1 3 -1\n-3\n0\n0 0 0 1 0 0 0 1 0\n', 2],
    ['huge vertex count (overflows)', 'VECT\n1 99999999999999999999999 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n', 2],
    ['too many components (over 10000)', 'VECT\n10001 30003 0\n', 2],
    ['more vertices than the server takes (200000)', 'VECT\n1 20000000 0\n-20000000\n0\n', 2],
    ['header promises more than the file holds', 'VECT\n1 300 0\n-300\n0\n0 0 0\n1 0 0\n0 1 0\n', 2],
    ['vertex counts add up to less than the header', 'VECT\n1 4 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n# pad pad pad\n', 3],
    ['vertex counts add up to more than the header', 'VECT\n2 5 0\n3\n-3\n0 0\n0 0 0 1 0 0 2 0 0 5 5 5 6 6 6\n', 4],
    ['component count of 0 vertices', 'VECT\n2 3 0\n-3 0\n0 0\n0 0 0 1 0 0 0 1 0\n', 3],
    ['closed component with 2 vertices', 'VECT\n1 2 0\n-2\n0\n0 0 0\n1 0 0\n', 3],
    ['open component with 1 vertex', 'VECT\n1 1 0\n1\n0\n0 0 0\n', 3],
    ['colour counts do not match the header', 'VECT\n1 3 1\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n1 0 0 1\n', 4],
    ['non-numeric coordinate', 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 abc 0\n0 1 0\n', 6],
    ['decimal comma', 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 1,5\n', 7],
    ['NaN coordinate', 'VECT\n1 3 0\n-3\n0\n0 0 0\nnan 0 0\n0 1 0\n', 6],
    ['infinite coordinate', 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n-Infinity 1 0\n', 7],
    ['coordinate overflowing a double', 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1e999 0\n', 7],
    ['truncated in the last vertex', 'VECT\n1 3 0\n-3\n0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0', 7],
    ['fewer vertices than declared, trailing comment', 'VECT\n1 5 0\n-5\n0\n0 0 0\n1 0 0\n0 1 0\n# a comment long enough to pass the size check\n', 8],
    ['more vertices than declared', 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n5 5 5\n', 8],
    ['duplicate consecutive vertices', 'VECT\n1 4 0\n-4\n0\n0 0 0\n1 0 0\n1 0 0\n0 1 0\n', 7],
    ['closed polygon repeating its first vertex', 'VECT\n1 4 0\n-4\n0\n1 2 3\n4 5 6\n7 8 8\n1 2 3\n', 8],
    ['CRLF lines, bad coordinate', 'VECT\r\n1 3 0\r\n-3\r\n0\r\n0 0 0\r\n1 0 0\r\n0 x 0\r\n', 7],
    ['control characters in a coordinate', 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 \x01\x02\x7f 0\n', 7],
];

// Binary garbage, only as text/plain (not a JSON string).
const BINARY = [
    ['binary garbage', Buffer.from([0x00, 0x7f, 0xfe, 0xff, 0x01, 0x02, 0x89, 0x50, 0x4e, 0x47, 0x0a, 0x1a, 0x0a, 0x00]), 1],
    ['NUL inside a coordinate', Buffer.from('VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0\x00 1 0\n', 'latin1'), 7],
    ['high bytes in a coordinate', Buffer.from('VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n\xff\xfe 1 0\n', 'latin1'), 7],
];

function assertLine(r, line, what) {
    assert.equal(r.status, 422, `${what}: ${r.text}`);
    assert.equal(r.json.line, line, `${what}: line (detail: ${r.json.detail})`);
    assert.ok(r.json.detail.startsWith(`line ${line}:`), `${what}: detail ${r.json.detail}`);
    assert.equal(r.json.option, undefined);
}

describe('malformed VECT gets 422 naming its line', () => {
    test(`${MALFORMED.length} malformed texts as text/plain`, async () => {
        assert.ok(MALFORMED.length >= 12);
        for (const [what, body, line] of MALFORMED)
            assertLine(await d.post('/v1/jobs?steps=10', body, { type: 'text/plain' }), line, what);
    });

    test('the same texts as JSON {"vect": ...}', async () => {
        for (const [what, body, line] of MALFORMED)
            assertLine(await d.post('/v1/jobs', { vect: body, options: { steps: 10 } }), line, `JSON: ${what}`);
    });

    test('binary data as text/plain', async () => {
        for (const [what, body, line] of BINARY)
            assertLine(await d.post('/v1/jobs', body, { type: 'text/plain; charset=utf-8' }), line, what);
    });

    test('nothing was stored', async () => {
        const r = await d.get('/v1/jobs');
        assert.equal(r.status, 200);
        assert.equal(r.json.total, 0);
    });

    // What only the engine can tell is found by the worker: the job fails
    // saying why (POST does bounded work only).
    test('a valid knot thinner than the tube: the job fails saying so; with autoscale it runs', async () => {
        const small = 'VECT\n1 3 0\n-3\n0\n0 0 0\n0.1 0 0\n0 0.1 0\n';
        const failed = await waitFinal(d, (await submit(d, small, { query: 'steps=5' })).id);
        assert.equal(failed.state, 'failed', JSON.stringify(failed));
        assert.match(failed.error, /autoscale/);
        const job = await waitFinal(d, (await submit(d, small, { query: 'steps=5&autoscale=true' })).id);
        assert.equal(job.state, 'done');
        assert.equal(job.progress.step, 5);
    });

    test('a resolution that asks for more vertices than the server takes: the job fails saying so', async () => {
        const job = await waitFinal(d, (await submit(d, { catalogue: '3.1', options: { resolution: 10000, steps: 5 } })).id,
            { timeout: 60000 });
        assert.equal(job.state, 'failed', JSON.stringify(job));
        assert.match(job.error, /option 'resolution': 10000 vertices per unit ropelength make \d+ vertices; the limit is 200000/);
    });
});

describe("magnitudes outside the engine's range get 422, in time bounded by the input", () => {
    // Squared distances of such curves overflow; the contact search once
    // widened its radius forever on the request thread, and two such
    // requests took the service down.
    const HUGE = 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1e200 0\n';
    const timeout = 20000;

    test('a coordinate of 1e200: 422 naming the vertex and the range', async () => {
        for (const q of ['steps=5', 'steps=5&autoscale=true', 'steps=5&resolution=2&autoscale=true']) {
            const r = await d.post(`/v1/jobs?${q}`, HUGE, { type: 'text/plain', timeout });
            assert.equal(r.status, 422, `${q}: ${r.text}`);
            assert.match(r.json.detail, /vertex 2 has coordinate y = 1e\+200, beyond the \+-1e\+30/, q);
        }
    });

    test('a radius of 1e300 with autoscale: 422 naming the option (JSON and query)', async () => {
        const r = await d.post('/v1/jobs', { vect: TRIANGLE, options: { radius: 1e300, autoscale: true } },
            { timeout });
        assert.equal(r.status, 422, r.text);
        assert.equal(r.json.option, 'radius');
        const q = await d.post('/v1/jobs?radius=1e300&autoscale=true', TRIANGLE, { type: 'text/plain', timeout });
        assert.equal(q.status, 422, q.text);
        assert.equal(q.json.option, 'radius');
    });

    test('a radius in range that autoscales the curve out of it: the job fails saying so', async () => {
        const job = await waitFinal(d, (await submit(d, { vect: TRIANGLE, options: { radius: 1e30, autoscale: true } })).id);
        assert.equal(job.state, 'failed', JSON.stringify(job));
        assert.match(job.error, /autoscale to radius 1e\+30/);
    });

    test('the service still answers', async () => {
        const h = await d.get('/v1/health', { timeout: 5000 });
        assert.equal(h.status, 200);
    });
});

// Sends a body with chunked transfer encoding (no Content-Length).
function postChunked(path, type, chunks) {
    return new Promise((resolve, reject) => {
        const req = httpRequest(new URL(path, d.base), {
            method: 'POST',
            headers: { 'content-type': type, 'transfer-encoding': 'chunked' },
        }, (res) => {
            let text = '';
            res.setEncoding('utf8');
            res.on('data', (c) => (text += c));
            res.on('end', () => {
                try {
                    const type = res.headers['content-type'];
                    const json = /json/.test(type ?? '') ? JSON.parse(text) : undefined;
                    validateResponse('POST', path, res.statusCode, type, json);
                    resolve({ status: res.statusCode, headers: res.headers, text, json });
                } catch (e) {
                    reject(e);
                }
            });
        });
        req.on('error', reject);
        for (const c of chunks) req.write(c);
        req.end();
    });
}

describe('oversized bodies get 413 (--max-body 1000)', () => {
    const big = TRIANGLE + '#' + 'x'.repeat(5000 - TRIANGLE.length - 2) + '\n';

    test('5000 bytes with Content-Length, text/plain and JSON', async () => {
        assert.equal(Buffer.byteLength(big), 5000);
        const r = await d.post('/v1/jobs?autoscale=true', big, { type: 'text/plain' });
        assert.equal(r.status, 413, r.text);
        assert.match(r.json.detail, /1000 bytes/);
        const j = await d.post('/v1/jobs', { vect: big, options: { autoscale: true } });
        assert.equal(j.status, 413, j.text);
    });

    test('5000 bytes chunked (fetch stream and node:http)', async () => {
        const enc = new TextEncoder();
        const stream = new ReadableStream({
            start(ctl) {
                for (let i = 0; i < 5; i++) ctl.enqueue(enc.encode(big.slice(i * 1000, (i + 1) * 1000)));
                ctl.close();
            },
        });
        const r = await d.post('/v1/jobs?autoscale=true', stream, { type: 'text/plain' });
        assert.equal(r.status, 413, r.text);

        const h = await postChunked('/v1/jobs?autoscale=true', 'text/plain', [big.slice(0, 2500), big.slice(2500)]);
        assert.equal(h.status, 413, h.text);
        assert.equal(h.headers['content-type'], 'application/problem+json');
        assert.equal(h.json.status, 413);
    });

    test('a body on a method that takes none is skipped, not judged: DELETE is routed (404)', async () => {
        const r = await d.req('DELETE', '/v1/jobs/999999', { body: big, type: 'text/plain' });
        assert.equal(r.status, 404, r.text);
        assert.match(r.json.detail, /no job 999999/);
    });

    test('a body at the limit is read (and judged on its content)', async () => {
        const fits = TRIANGLE + '#' + 'x'.repeat(MAX_BODY - TRIANGLE.length - 2) + '\n';
        assert.equal(Buffer.byteLength(fits), MAX_BODY);
        const ok = await postChunked('/v1/jobs?steps=3&autoscale=true', 'text/plain', [fits.slice(0, 500), fits.slice(500)]);
        assert.equal(ok.status, 202, ok.text);
        const job = await waitFinal(d, ok.json.id);
        assert.equal(job.state, 'done');
        assert.equal(job.progress.step, 3);
    });
});

describe('bad JSON, bad options, wrong media type', () => {
    test('bad JSON: 400', async () => {
        for (const body of ['{"vect": ', '{"catalogue": "3.1",}', 'not json', '{"catalogue": "3.1", "catalogue": "4.1"}']) {
            const r = await d.post('/v1/jobs', body, { type: 'application/json' });
            assert.equal(r.status, 400, `${body}: ${r.text}`);
        }
    });

    test('JSON that is not a job request: 422 naming the field', async () => {
        let r = await d.post('/v1/jobs', '[1, 2]', { type: 'application/json' });
        assert.equal(r.status, 422);
        r = await d.post('/v1/jobs', { catalogue: '3.1', colour: 'red' });
        assert.equal(r.status, 422);
        assert.equal(r.json.field, 'colour');
        r = await d.post('/v1/jobs', { vect: TRIANGLE, catalogue: '3.1' });
        assert.equal(r.status, 422);
        r = await d.post('/v1/jobs', { vect: 42 });
        assert.equal(r.status, 422);
        assert.equal(r.json.field, 'vect');
        r = await d.post('/v1/jobs', { catalogue: '3.1', name: 'n'.repeat(128) });
        assert.equal(r.status, 422, 'a name over 127 bytes (openapi.yaml: maxLength 127)');
        assert.equal(r.json.field, 'name');
        const longest = await submit(d, { catalogue: '3.1', name: 'n'.repeat(127), options: { steps: 1 } });
        assert.equal(longest.name, 'n'.repeat(127));
        r = await d.post(`/v1/jobs?autoscale=true&name=${'n'.repeat(128)}`, TRIANGLE, { type: 'text/plain' });
        assert.equal(r.status, 422);
        assert.equal(r.json.field, 'name');
        r = await d.post('/v1/jobs', { catalogue: 'no-such-knot' });
        assert.equal(r.status, 422);
        assert.equal(r.json.field, 'catalogue');
    });

    test('unknown or bad option: 422 naming the option (JSON and query)', async () => {
        const cases = [
            [{ stepz: 5 }, 'stepz'],
            [{ steps: -1 }, 'steps'],
            [{ steps: 2.5 }, 'steps'],
            [{ steps: '10' }, 'steps'],
            [{ radius: 0 }, 'radius'],
            [{ lambda: -1 }, 'lambda'],
            [{ resolution: 1e6 }, 'resolution'],
            [{ autoscale: 'yes' }, 'autoscale'],
            [{ every: 1e10 }, 'every'],
            [{ vertices: 2.5 }, 'vertices'],
            [{ vertices: 200001 }, 'vertices'], // beyond the daemon's --max-vertices
        ];
        for (const [options, option] of cases) {
            const r = await d.post('/v1/jobs', { catalogue: '3.1', options });
            assert.equal(r.status, 422, `${JSON.stringify(options)}: ${r.text}`);
            assert.equal(r.json.option, option, JSON.stringify(options));
        }
        const query = [['stepz=5', 'stepz'], ['steps=-1', 'steps'], ['steps=ten', 'steps'], ['time=abc', 'time'],
            ['radius=0', 'radius'], ['autoscale=maybe', 'autoscale'], ['residual=-1', 'residual']];
        for (const [q, option] of query) {
            const r = await d.post(`/v1/jobs?${q}`, TRIANGLE, { type: 'text/plain' });
            assert.equal(r.status, 422, `${q}: ${r.text}`);
            assert.equal(r.json.option, option, q);
        }
    });

    test('wrong media type: 415', async () => {
        for (const type of ['application/xml', 'text/html', 'application/octet-stream', 'application/jsonx']) {
            const r = await d.post('/v1/jobs', TRIANGLE, { type });
            assert.equal(r.status, 415, `${type}: ${r.text}`);
        }
        // no Content-Type at all (a Uint8Array body gets none from fetch)
        const r = await d.post('/v1/jobs', new TextEncoder().encode(TRIANGLE));
        assert.equal(r.status, 415, r.text);
    });
});

describe('unknown paths and wrong methods', () => {
    test('unknown path: 404', async () => {
        for (const path of ['/v1/nope', '/v1/jobs/999999', '/v1/jobs/abc', '/v1/jobs/0', '/v1/jobs/1/nope',
            '/v1/jobs/999999/struts', '/v1/jobs/999999/vect', '/v1/jobs/999999/history', '/v1/jobs/999999/frames',
            '/v2/jobs', '/index.html']) {
            const r = await d.get(path);
            assert.equal(r.status, 404, `${path}: ${r.text}`);
        }
        const r = await d.del('/v1/jobs/999999');
        assert.equal(r.status, 404);
    });

    test('wrong method: 405 with Allow', async () => {
        const cases = [
            ['PUT', '/v1/jobs', 'GET, POST'],
            ['DELETE', '/v1/jobs', 'GET, POST'],
            ['POST', '/v1/health', 'GET'],
            ['DELETE', '/metrics', 'GET'],
            ['POST', '/v1/catalogue', 'GET'],
            ['PUT', '/v1/catalogue/3.1', 'GET'],
            ['PATCH', '/v1/jobs/1', 'GET, DELETE'],
            ['POST', '/v1/jobs/1', 'GET, DELETE'],
            ['DELETE', '/v1/jobs/1/struts', 'GET'],
            ['POST', '/v1/jobs/1/history', 'GET'],
        ];
        for (const [method, path, allow] of cases) {
            const r = await d.req(method, path, method === 'GET' ? {} : { body: '{}', type: 'application/json' });
            assert.equal(r.status, 405, `${method} ${path}: ${r.text}`);
            assert.equal(r.headers.get('allow'), allow, `${method} ${path}`);
        }
    });

    test('bad query parameters of the lists: 400 naming them', async () => {
        for (const [q, p] of [['limit=0', 'limit'], ['limit=501', 'limit'], ['offset=-1', 'offset'],
            ['state=bogus', 'state'], ['limit=ten', 'limit']]) {
            const r = await d.get(`/v1/jobs?${q}`);
            assert.equal(r.status, 400, q);
            assert.equal(r.json.parameter, p, q);
        }
    });

    test('health and metrics', async () => {
        const h = await d.get('/v1/health');
        assert.equal(h.status, 200);
        assert.equal(h.json.status, 'ok');
        assert.equal(h.json.workers, 1);
        const m = await d.get('/metrics');
        assert.equal(m.status, 200);
        assert.match(m.text, /^tightknot_workers 1$/m);
        // this file's 4xx answers so far are counted
        const n = Number(/^tightknot_http_responses_total\{code="4xx"\} (\d+)$/m.exec(m.text)[1]);
        assert.ok(n >= MALFORMED.length * 2 + BINARY.length, `4xx count ${n}`);
    });

    test('metrics count the jobs ended and the workers\' busy time', async () => {
        const figures = async () => {
            const text = (await d.get('/metrics')).text;
            const get = (name) => Number(new RegExp(`^tightknot_${name} (\\S+)$`, 'm').exec(text)[1]);
            return { ended: get('jobs_ended_total'), busy: get('worker_busy_seconds_total') };
        };
        // the jobs of the tests before have ended (one worker: this job alone between the scrapes)
        for (let h = await d.get('/v1/health'); h.json.running || h.json.queued; h = await d.get('/v1/health'))
            await new Promise((r) => setTimeout(r, 50));
        const before = await figures();
        const t0 = performance.now();
        const job = await waitFinal(d, (await submit(d, { catalogue: '3.1', options: { resolution: 5, steps: 300 } })).id);
        assert.equal(job.state, 'done');
        // the worker counts the job just after it stores its end, so a
        // scrape right after the job reads done can come before the count
        let now = await figures();
        for (const until = performance.now() + 5000; now.ended === before.ended && performance.now() < until;
            now = await figures())
            await new Promise((r) => setTimeout(r, 20));
        const wall = (performance.now() - t0) / 1000;
        assert.equal(now.ended, before.ended + 1);
        // the one worker ran this job for at least its own seconds, and for
        // no longer than the wall time between the two scrapes
        assert.ok(now.busy - before.busy >= job.seconds, `${now.busy - before.busy} s busy, the job ${job.seconds} s`);
        assert.ok(now.busy - before.busy <= wall, `${now.busy - before.busy} s busy in ${wall} s`);
    });
});
