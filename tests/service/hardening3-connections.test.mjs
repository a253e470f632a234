// What the third hostile probe found in the connection layer (issue 55),
// each answered now:
// F5  one client holding slow uploads took all of --max-body-total and
//     every other client got 503: now a client (its token's name, else its
//     address) holds at most its share, and the others still upload;
// F12 eight addresses trickling request heads held every connection slot
//     for as long as they trickled (--timeout counts only silence): now a
//     head must arrive whole within --head-timeout and a body at
//     --min-body-rate, so a trickle is cut and the others are served.

import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { request as httpRequest } from 'node:http';
import { connect } from 'node:net';
import { join } from 'node:path';
import { after, before, describe, test } from 'node:test';

import { sleep, startDaemon, tempDir } from './lib.mjs';

// Opens a connection from `localAddress` and sends `head` (no end); the
// socket keeps what it is answered in s.answer and when it was closed in
// s.closedAt (ms since the epoch).
function openRaw(port, head, localAddress = '127.0.0.1') {
    return new Promise((resolve, reject) => {
        const s = connect({ port, host: '127.0.0.1', localAddress });
        s.setEncoding('latin1');
        s.answer = '';
        s.on('data', (d) => (s.answer += d));
        s.on('error', () => {});
        s.on('close', () => {
            s.gone = true;
            s.closedAt = Date.now();
        });
        s.once('error', reject);
        s.on('connect', () => {
            s.openedAt = Date.now();
            if (head) s.write(head);
            resolve(s);
        });
    });
}

const statusOf = (s) => Number(/^HTTP\/1\.1 (\d{3})/.exec(s.answer)?.[1] ?? 0);

// A request from localAddress on a connection of its own; {status, text, ms}.
function requestFrom(port, localAddress, { method = 'GET', path = '/v1/health', body, headers = {},
    timeout = 10000 } = {}) {
    return new Promise((resolve, reject) => {
        const t0 = performance.now();
        const req = httpRequest({ host: '127.0.0.1', port, path, method, localAddress, agent: false,
            headers: body ? { 'content-type': 'application/json', ...headers } : headers }, (res) => {
            let text = '';
            res.setEncoding('utf8');
            res.on('data', (d) => (text += d));
            res.on('end', () => resolve({ status: res.statusCode, text, ms: performance.now() - t0 }));
        });
        req.on('error', reject);
        req.setTimeout(timeout, () => req.destroy(new Error(`no answer in ${timeout} ms`)));
        req.end(body);
    });
}

// Resolves when the socket is closed, or with null after ms.
const closedWithin = (s, ms) => Promise.race([
    new Promise((r) => (s.gone ? r(s.closedAt) : s.on('close', () => r(s.closedAt)))),
    sleep(ms).then(() => null),
]);

const SMALL = JSON.stringify({ catalogue: '3.1', options: { steps: 2 } });
const MiB = 1 << 20;

// Four uploads of 1,000,000 bytes from one client, 900,000 sent each: as
// the probe's four 16 MB uploads were to the default budget.
async function hog(port, localAddress, headers = '') {
    const head = `POST /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n${headers}Content-Type: text/plain\r\n` +
        'Content-Length: 1000000\r\n\r\n';
    const held = [];
    for (let i = 0; i < 4; i++) {
        const s = await openRaw(port, head, localAddress);
        s.write(Buffer.alloc(900000, 0x23)); // '#': one long comment
        held.push(s);
        await sleep(150);
    }
    await sleep(300);
    return held;
}

async function bytesHeld(port) {
    const m = await requestFrom(port, '127.0.0.1', { path: '/metrics' });
    return Number(/^tightknot_http_body_bytes_held (\d+)$/m.exec(m.text)[1]);
}

describe('F5: a client holds a share of --max-body-total, not all of it', () => {
    let d;
    before(async () => {
        d = await startDaemon({ workers: 1, maxBody: MiB, args: ['--max-body-total', String(4 * MiB)] });
    });
    after(async () => d && (await d.stop()));

    test('one address holding four slow uploads: another address still submits (202)', async (t) => {
        const held = await hog(d.port, '127.0.0.2');
        try {
            const bytes = await bytesHeld(d.port);
            const other = await requestFrom(d.port, '127.0.0.3', { method: 'POST', path: '/v1/jobs', body: SMALL });
            t.diagnostic(`one address holds ${bytes} of ${4 * MiB} bytes; another address's POST: ${other.status}`);
            assert.equal(other.status, 202, other.text);
            assert.ok(bytes <= MiB + 1, `one client holds ${bytes} bytes, more than its share`);
            // the hog's own uploads beyond its share are refused once they end
            for (const s of held) s.write(Buffer.alloc(100000, 0x23));
            await sleep(1000);
            const statuses = held.map(statusOf);
            t.diagnostic(`the hog's four uploads: ${statuses.join(', ')}`);
            assert.ok(statuses.filter((x) => x === 503).length >= 3, `statuses ${statuses}`);
            assert.ok(statuses.every((x) => x === 503 || x === 422), `statuses ${statuses}`);
            const refused = held.find((s) => statusOf(s) === 503).answer;
            assert.match(refused, /Retry-After: \d+/i);
            assert.match(refused, /too many uploads at once/);
        } finally {
            for (const s of held) s.destroy();
        }
    });
});

describe('F5: with --tokens the share is the name\'s', () => {
    let d;
    const ALICE = 'alice-token-0123456789', BOB = 'bob-token-0123456789ab';
    before(async () => {
        const dir = tempDir('tokens');
        writeFileSync(join(dir, 'tokens'), `alice ${ALICE}\nbob ${BOB}\n`);
        d = await startDaemon({ workers: 1, maxBody: MiB,
            args: ['--max-body-total', String(4 * MiB), '--tokens', join(dir, 'tokens')] });
    });
    after(async () => d && (await d.stop()));

    test('alice holds her share: bob from her address submits, alice from another address is refused', async (t) => {
        const held = await hog(d.port, '127.0.0.2', `Authorization: Bearer ${ALICE}\r\n`);
        try {
            const bob = await requestFrom(d.port, '127.0.0.2', { method: 'POST', path: '/v1/jobs', body: SMALL,
                headers: { authorization: `Bearer ${BOB}` } });
            const alice = await requestFrom(d.port, '127.0.0.4', { method: 'POST', path: '/v1/jobs', body: SMALL,
                headers: { authorization: `Bearer ${ALICE}` } });
            t.diagnostic(`bob from alice's address: ${bob.status}; alice from another address: ${alice.status}`);
            assert.equal(bob.status, 202, bob.text);
            assert.equal(alice.status, 503, alice.text);
            assert.match(alice.text, /too many uploads at once/);
        } finally {
            for (const s of held) s.destroy();
        }
    });
});

describe('F12: a request\'s head and body have deadlines', () => {
    let d;
    before(async () => {
        // 32 slots (16 per HTTP thread), 4 per address; a head in 2 s, a
        // body at 1000 bytes/s after that grace
        d = await startDaemon({ workers: 1, args: ['--max-connections', '32', '--max-per-address', '4',
            '--timeout', '10', '--head-timeout', '2', '--min-body-rate', '1000'] });
    });
    after(async () => d && (await d.stop()));

    test('8 addresses trickling heads on every slot: a 9th address is answered within 3.5 s', async (t) => {
        const slow = [];
        for (let a = 2; a <= 9; a++)
            for (let i = 0; i < 4; i++)
                slow.push(await openRaw(d.port, 'GET /v1/health HTTP/1.1\r\nHost: 127.0.0.1\r\n', `127.0.0.${a}`));
        const drip = setInterval(() => {
            for (const s of slow) if (!s.gone) s.write('X-a: b\r\n');
        }, 300);
        try {
            await sleep(200);
            let r;
            try {
                r = await requestFrom(d.port, '127.0.0.10', { timeout: 8000 });
            } catch (e) {
                assert.fail(`the 9th address: ${e.message} while ${slow.filter((s) => !s.gone).length} heads trickle`);
            }
            t.diagnostic(`the 9th address: ${r.status} after ${r.ms.toFixed(0)} ms; ` +
                `${slow.filter((s) => s.gone).length} of 32 trickling heads cut`);
            assert.equal(r.status, 200);
            assert.ok(r.ms < 3500, `answered after ${r.ms} ms`);
        } finally {
            clearInterval(drip);
            for (const s of slow) s.destroy();
        }
    });

    test('a head trickled a line every 300 ms is cut at --head-timeout (2 s, +-0.5 s); others are served meanwhile', async (t) => {
        await sleep(300);
        const s = await openRaw(d.port, 'GET /v1/health HTTP/1.1\r\nHost: 127.0.0.1\r\n', '127.0.0.11');
        const drip = setInterval(() => !s.gone && s.write('X-a: b\r\n'), 300);
        try {
            const h = await requestFrom(d.port, '127.0.0.12');
            assert.equal(h.status, 200);
            assert.ok(h.ms < 500, `health took ${h.ms} ms`);
            const at = await closedWithin(s, 6000);
            assert.ok(at, 'the trickled head was still open after 6 s');
            const lived = at - s.openedAt;
            t.diagnostic(`trickled head cut after ${lived} ms; health meanwhile in ${h.ms.toFixed(1)} ms`);
            assert.ok(lived >= 1500 && lived <= 2500, `cut after ${lived} ms`);
        } finally {
            clearInterval(drip);
            s.destroy();
        }
    });

    test('a body trickled below --min-body-rate is cut; a slow upload above it is read and answered', async (t) => {
        const head = (n) => `POST /v1/jobs?steps=2&autoscale=true HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: text/plain\r\n` +
            `Content-Length: ${n}\r\nConnection: close\r\n\r\n`;
        // 100,000 bytes at once, then 10 every 300 ms: the fast start buys
        // at most --head-timeout in hand (not 100 s), so it is cut near 2 s
        const trickle = await openRaw(d.port, head(200000) + '#'.repeat(100000), '127.0.0.13');
        // 600 bytes every 300 ms (2000 bytes/s) for 3 s: never behind
        const body = 'VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n#'.padEnd(6000, 'x') + '\n';
        const steady = await openRaw(d.port, head(body.length), '127.0.0.14');
        let sent = 0;
        const drip = setInterval(() => {
            if (!trickle.gone) trickle.write('##########');
            if (sent < body.length) steady.write(body.slice(sent, (sent += 600)));
        }, 300);
        try {
            const at = await closedWithin(trickle, 8000);
            assert.ok(at, 'the trickled body was still open after 8 s');
            const lived = at - trickle.openedAt;
            await closedWithin(steady, 3000);
            t.diagnostic(`trickled body cut after ${lived} ms; the steady upload answered ${statusOf(steady)}`);
            assert.ok(lived >= 1800 && lived <= 3000, `cut after ${lived} ms`);
            assert.equal(statusOf(steady), 202, steady.answer.slice(0, 300));
        } finally {
            clearInterval(drip);
            trickle.destroy();
            steady.destroy();
        }
    });
});
