// What a third hostile probe found, each answered now: a database URI's
// password never leaves the daemon (health, problems, its own output), a
// store outage is a 503 with Retry-After and changes no job, a tokens
// file's '#' belongs to the token unless it starts the line and short
// tokens are refused, a job's name holds no control character and the
// client prints none it is sent, an HTTP/1.1 request names exactly one
// Host, the page cannot be framed, and the small ones: a NUL in a query
// name, a signed limit, a null option, a seed beyond 2^53.

import assert from 'node:assert/strict';
import { execFile, spawnSync } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import { createServer as createHttpServer } from 'node:http';
import { connect, createServer } from 'node:net';
import { join } from 'node:path';
import { after, before, describe, test } from 'node:test';

import { CLI, DAEMON, CATALOGUE, PG_URL, pgDatabase, raw, sleep, startDaemon, submit, tempDir, waitFinal } from './lib.mjs';


// A daemon run to its end (one that must not start): its exit status and output.
function runDaemon(args) {
    return new Promise((resolve) => {
        execFile(DAEMON, args, { timeout: 30000 }, (error, stdout, stderr) =>
            resolve({ code: error ? error.code : 0, output: stdout + stderr }));
    });
}

// ------------------------------------------------------------ F1, F11

// A TCP door to the tests' PostgreSQL (reached by its Unix socket) that can
// be shut and opened again: an outage without touching the server.
function pgDoor(socketPath) {
    const sockets = new Set();
    const server = createServer((client) => {
        const upstream = connect(socketPath);
        sockets.add(client).add(upstream);
        const drop = () => { client.destroy(); upstream.destroy(); };
        client.on('error', drop).on('close', drop);
        upstream.on('error', drop).on('close', drop);
        client.pipe(upstream).pipe(client);
    });
    return {
        server,
        open: (port = 0) => new Promise((r) => server.listen(port, '127.0.0.1', () => r(server.address().port))),
        shut: () => new Promise((r) => {
            server.close(() => r());
            for (const s of sockets) s.destroy();
            sockets.clear();
        }),
    };
}

const SECRET = 'S3cretPW-never-shown';
const pgSkip = PG_URL ? false : 'TK_PG_URL is not set: no PostgreSQL server';

describe('a PostgreSQL URI with a password, the database down', { skip: pgSkip }, () => {
    let door, port, d, uri, dbname;
    before(async () => {
        // the database the tests made, reached through the door by TCP
        const made = new URL(pgDatabase());
        dbname = made.pathname.slice(1);
        const socketDir = decodeURIComponent(made.hostname);
        door = pgDoor(join(socketDir, '.s.PGSQL.5432'));
        port = await door.open();
        uri = `postgresql://postgres:${SECRET}@127.0.0.1:${port}/${dbname}?password=${SECRET}`;
        d = await startDaemon({ db: uri, workers: 1, args: ['--lease', '3'] });
    });
    after(async () => {
        if (d) await d.stop();
        await door?.shut();
    });

    test('health, submissions and reads say 503 with Retry-After, never the password; the jobs are untouched', async () => {
        const job = await submit(d, { catalogue: '3.1', options: { steps: 3 } });
        const done = await waitFinal(d, job.id);
        assert.equal(done.state, 'done');
        await door.shut();
        const health = await d.get('/v1/health');
        assert.equal(health.status, 503, health.text);
        assert.ok(!health.text.includes(SECRET), health.text);
        const post = await d.post('/v1/jobs', { catalogue: '4.1', options: { steps: 3 } });
        assert.equal(post.status, 503, post.text);
        assert.ok(Number(post.headers.get('retry-after')) > 0, 'Retry-After');
        assert.ok(!post.text.includes(SECRET), post.text);
        for (const path of ['/v1/jobs', `/v1/jobs/${job.id}/vect`, `/v1/jobs/${job.id}/history`]) {
            const r = await d.get(path);
            assert.ok(r.status === 200 || r.status === 503, `${path}: ${r.status} ${r.text}`);
            if (r.status === 503) assert.ok(Number(r.headers.get('retry-after')) > 0, path);
            assert.ok(!r.text.includes(SECRET), r.text);
        }
        const del = await d.del(`/v1/jobs/${job.id}`);
        assert.ok(del.status === 503, `DELETE during the outage: ${del.status} ${del.text}`);
        await door.open(port);
        // a client told to retry does, and is served once the store is back
        let retried;
        for (let i = 0; i < 100; i++) {
            retried = await d.post('/v1/jobs', { catalogue: '4.1', options: { steps: 3 } });
            if (retried.status !== 503) break;
            await sleep(100);
        }
        assert.equal(retried.status, 202, retried.text);
        assert.equal((await d.get('/v1/health')).status, 200);
        const again = await d.get(`/v1/jobs/${job.id}`);
        assert.equal(again.status, 200);
        assert.equal(again.json.state, 'done');
        assert.equal(again.json.ropelength, done.ropelength);
        const list = await d.get('/v1/jobs');
        assert.deepEqual(list.json.jobs.map((j) => j.id).sort(), [job.id, retried.json.id].sort(),
            'the refused submission stored nothing');
        assert.ok(!d.output().includes(SECRET), d.output());
    });

    test('a daemon that cannot reach the database says where, without the password', async () => {
        const closed = pgDoor('/nonexistent');
        const p = await closed.open();
        await closed.shut();
        const r = await runDaemon(['--port', '0', '--db',
            `postgresql://postgres:${SECRET}@127.0.0.1:${p}/${dbname}`, '--catalogue', CATALOGUE]);
        assert.notEqual(r.code, 0);
        assert.ok(!r.output.includes(SECRET), r.output);
        assert.match(r.output, new RegExp(`127\\.0\\.0\\.1:${p}`));
    });
});

// ------------------------------------------------------------ F4

describe('a tokens file', () => {
    test("a '#' inside a token is the token's; a comment is a whole line", async () => {
        const dir = tempDir('tokens3');
        const file = join(dir, 'tokens');
        writeFileSync(file, '  # the clients\nalice Zx#9f8e7d6c5b4a3928\n');
        const d = await startDaemon({ workers: 1, args: ['--tokens', file] });
        try {
            const as = (t) => ({ headers: { Authorization: `Bearer ${t}` } });
            assert.equal((await d.get('/v1/jobs', as('Zx#9f8e7d6c5b4a3928'))).status, 200);
            assert.equal((await d.get('/v1/jobs', as('Zx'))).status, 401);
        } finally {
            await d.stop();
        }
    });

    test('a token under 16 characters is refused at start, naming its line', async () => {
        const dir = tempDir('tokens3');
        const file = join(dir, 'tokens');
        writeFileSync(file, '# the clients\nalice a-long-enough-token-1\nbob y\n');
        const r = await runDaemon(['--port', '0', '--db', join(dir, 'j.db'), '--tokens', file]);
        assert.notEqual(r.code, 0);
        assert.match(r.output, new RegExp(`${file}:3: .*16`));
    });
});

// ------------------------------------------------------------ F8, F9, minor

describe('names, hosts and small inputs', () => {
    let d;
    before(async () => {
        d = await startDaemon({ workers: 1 });
    });
    after(async () => {
        await d.stop();
    });

    test('a name with a control character is refused (422), in JSON and in the query', async () => {
        for (const name of ['\u001b]0;PWNED\u0007', 'two\r\nlines', 'bell\u0007', 'del\u007f', 'csi\u009b2J']) {
            const r = await d.post('/v1/jobs', { catalogue: '3.1', name, options: { steps: 1 } });
            assert.equal(r.status, 422, `${JSON.stringify(name)}: ${r.text}`);
            assert.equal(r.json.field, 'name');
        }
        const q = await d.post('/v1/jobs?name=a%1bb', 'VECT\n1 4 0\n-4\n0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n',
            { type: 'text/plain' });
        assert.equal(q.status, 422, q.text);
        // Unicode beyond the controls is a name like any other
        const ok = await d.post('/v1/jobs', { catalogue: '3.1', name: 'nœud — 三葉', options: { steps: 1 } });
        assert.equal(ok.status, 202, ok.text);
        assert.equal(ok.json.name, 'nœud — 三葉');
    });

    test('a NUL in a query parameter is refused, not cut there', async () => {
        const square = 'VECT\n1 4 0\n-4\n0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n';
        for (const query of ['name=a%00b', 'steps=5%00x', 'st%00eps=5']) {
            const r = await d.post(`/v1/jobs?${query}`, square, { type: 'text/plain' });
            assert.equal(r.status, 422, `${query}: ${r.text}`);
            assert.match(r.json.detail, /NUL/);
        }
    });

    test('a limit with a sign or blanks is a 400', async () => {
        for (const v of ['+5', '%205', '-0', '5%20'])
            assert.equal((await d.get(`/v1/jobs?limit=${v}`)).status, 400, v);
        assert.equal((await d.get('/v1/jobs?limit=5')).status, 200);
    });

    test('a null option says null; a seed beyond 2^53 is refused, not rounded', async () => {
        const n = await d.post('/v1/jobs', { catalogue: '3.1', options: { time: null } });
        assert.equal(n.status, 422, n.text);
        assert.match(n.json.detail, /not null/);
        assert.doesNotMatch(n.json.detail, /nan/i);
        const big = await d.post('/v1/jobs', '{"catalogue": "3.1", "options": {"seed": 9007199254740993}}',
            { type: 'application/json' });
        assert.equal(big.status, 422, big.text);
        assert.equal(big.json.option, 'seed');
        const top = await d.post('/v1/jobs', '{"catalogue": "3.1", "options": {"seed": 9007199254740991, "steps": 1}}',
            { type: 'application/json' });
        assert.equal(top.status, 202, top.text);
        assert.equal(top.json.options.seed, 9007199254740991);
    });

    test('an HTTP/1.1 request without a Host, or with two, is a 400; HTTP/1.0 needs none', async () => {
        const none = await raw(d.port, 'GET /v1/health HTTP/1.1\r\nConnection: close\r\n\r\n');
        assert.equal(none.status, 400, none.text);
        assert.match(none.text, /application\/problem\+json/);
        const two = await raw(d.port, `GET /v1/health HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
            `Host: evil.example\r\nConnection: close\r\n\r\n`);
        assert.equal(two.status, 400, two.text);
        const old = await raw(d.port, 'GET /v1/health HTTP/1.0\r\n\r\n');
        assert.equal(old.status, 200, old.text);
        const one = await raw(d.port, `GET /v1/health HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
            'Connection: close\r\n\r\n');
        assert.equal(one.status, 200, one.text);
    });

    test("an Origin is the daemon's own only with its scheme too", async () => {
        const body = { catalogue: '3.1', options: { steps: 1 } };
        const other = await d.post('/v1/jobs', body, { headers: { Origin: `https://127.0.0.1:${d.port}` } });
        assert.equal(other.status, 403, other.text);
        const own = await d.post('/v1/jobs', body, { headers: { Origin: `http://127.0.0.1:${d.port}` } });
        assert.equal(own.status, 202, own.text);
    });

    test('no answer may be framed by another site or sniffed as another type', async () => {
        for (const path of ['/', '/v1/health', '/v1/jobs', '/v1/nothing']) {
            const r = await d.get(path);
            assert.match(r.headers.get('content-security-policy') ?? '', /frame-ancestors 'none'/, path);
            assert.equal(r.headers.get('x-content-type-options'), 'nosniff', path);
        }
    });
});

describe('the client prints what a server sends without its control characters', () => {
    let server, port;
    const NAME = '\u001b]0;PWNED\u0007\u001b[2J\u001b[31mred\r\nfake line\u009b';
    before(async () => {
        // a server (not ours) that sends a job whose texts hold escapes
        server = createHttpServer((req, res) => {
            const job = { id: 1, name: NAME, state: 'failed\u001b[1A', error: 'bad\u001b[2Kthing',
                progress: { step: 3 }, ropelength: 40, residual: 0.5 };
            res.writeHead(200, { 'Content-Type': 'application/json' });
            res.end(JSON.stringify(job));
        });
        port = await new Promise((r) => server.listen(0, '127.0.0.1', () => r(server.address().port)));
    });
    after(() => server.close());

    test('remote status: no ESC, BEL, CR, DEL or C1 in its line', async () => {
        const out = await new Promise((resolve) => execFile(CLI,
            ['remote', '--server', `http://127.0.0.1:${port}`, 'status', '1'],
            (error, stdout, stderr) => resolve(stdout + stderr)));
        assert.match(out, /PWNED/);
        assert.doesNotMatch(out, /[\u0000-\u0008\u000b-\u001f\u007f\u0080-\u009f]/);
        assert.equal(out.trim().split('\n').length, 1, out);
    });
});

test("the command line reads '-' from standard input that is a socket (node's pipes are)", () => {
    const knot = spawnSync(CLI, ['generate', 'torus', '2', '3'], { encoding: 'utf8' });
    assert.equal(knot.status, 0);
    const r = spawnSync(CLI, ['info', '--json', '-'], { input: knot.stdout, encoding: 'utf8' });
    assert.equal(r.status, 0, r.stderr);
    assert.deepEqual(JSON.parse(r.stdout).invariants.determinants, [3]);
    const bad = spawnSync(CLI, ['info', '-'], { input: 'VECT\n1 2\n', encoding: 'utf8' });
    assert.equal(bad.status, 2);
    assert.match(bad.stderr, /^tightknot: -:2: /);
});
