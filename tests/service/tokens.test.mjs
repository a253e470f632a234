// Tokens (tightknotd --tokens FILE): every request but health, the page
// and a preflight needs a token of the file (401 otherwise); a job records
// the name that submitted it, a name lists, reads and cancels its own jobs
// (others' are 404 to read and to cancel, as if not there), an admin name all; a name
// has at most --jobs-per-name jobs queued or running, and stores at most
// --bytes-per-name (429).  The remote
// client sends --token or $TIGHTKNOT_TOKEN.  A daemon on an address other
// than loopback refuses to start without tokens unless --allow-anonymous.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createHash } from 'node:crypto';
import { spawn, execFile } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { CLI, DAEMON, cli, sleep, startDaemon, stopAll, tempDir } from './lib.mjs';

const SQUARE = 'VECT\n1 4 0\n-4\n0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n';
const TOKENS = { alice: 'alice-secret-00001', carol: 'carol-secret-00003', root: 'root-secret-000009' };
const sha = (t) => createHash('sha256').update(t).digest('hex');

let d, dir;
const as = (name) => ({ headers: { Authorization: `Bearer ${TOKENS[name]}` } });
let TREFOIL; // a job that runs until cancelled
const post = (name, query = 'autoscale=true&steps=100000000') =>
    d.post(`/v1/jobs?${query}`, query.includes('autoscale') ? TREFOIL : SQUARE, { type: 'text/plain', ...as(name) });

// Polls a job with a name's token until it ends.
async function finalAs(name, id) {
    for (const t0 = Date.now(); Date.now() - t0 < 60000; await sleep(50)) {
        const j = (await d.get(`/v1/jobs/${id}`, as(name))).json;
        if (['done', 'failed', 'cancelled'].includes(j.state)) return j;
    }
    assert.fail(`job ${id} did not end`);
}

before(async () => {
    dir = tempDir('tokens');
    TREFOIL = await cli(['generate', 'torus', '2', '3']);
    // alice by hash (the file holds no secret), carol as is, root admin
    writeFileSync(join(dir, 'tokens'), `# clients\nalice sha256:${sha(TOKENS.alice)}\n` +
        `carol   ${TOKENS.carol}\n  # a comment (only ever a whole line)\n\nroot ${TOKENS.root} admin\n`);
    d = await startDaemon({ workers: 1, args: ['--tokens', join(dir, 'tokens'), '--jobs-per-name', '2'] });
});

after(() => stopAll(d));

test('without a token of the file: 401 at every endpoint but health, the page and a preflight', async () => {
    const ops = [['GET', '/v1/jobs'], ['POST', '/v1/jobs'], ['GET', '/v1/jobs/1'], ['DELETE', '/v1/jobs/1'],
        ['GET', '/v1/jobs/1/struts'], ['GET', '/v1/jobs/1/vect'], ['GET', '/v1/jobs/1/history'],
        ['GET', '/v1/jobs/1/frames'], ['GET', '/v1/catalogue'], ['GET', '/v1/catalogue/3.1'], ['GET', '/metrics']];
    for (const [method, path] of ops) {
        for (const auth of [undefined, 'Bearer wrong', `Bearer ${TOKENS.alice}x`, `Basic ${TOKENS.alice}`,
            `Bearer sha256:${sha(TOKENS.alice)}`]) {
            const r = await d.req(method, path, { headers: auth ? { Authorization: auth } : {},
                body: method === 'POST' ? SQUARE : undefined, type: method === 'POST' ? 'text/plain' : undefined });
            assert.equal(r.status, 401, `${method} ${path} ${auth}: ${r.text}`);
            assert.match(r.headers.get('www-authenticate'), /^Bearer/);
        }
    }
    assert.equal((await d.get('/v1/health')).status, 200);
    assert.equal((await d.get('/v1/catalogue', as('carol'))).status, 200, 'the catalogue is every name\'s');
});

test('a name sees, reads and cancels its own jobs; an admin all', async () => {
    const a = await post('alice');
    assert.equal(a.status, 202, a.text);
    assert.equal(a.json.owner, 'alice');
    const c = await post('carol', 'steps=3');
    assert.equal(c.status, 202, c.text);
    assert.equal(c.json.owner, 'carol');
    const list = async (name) => (await d.get('/v1/jobs', as(name))).json.jobs.map((j) => j.id).sort();
    assert.deepEqual(await list('alice'), [a.json.id]);
    assert.deepEqual(await list('carol'), [c.json.id]);
    assert.deepEqual(await list('root'), [a.json.id, c.json.id].sort());
    for (const part of ['', '/struts', '/vect', '/history', '/frames']) {
        assert.equal((await d.get(`/v1/jobs/${a.json.id}${part}`, as('carol'))).status, 404, part);
        assert.equal((await d.get(`/v1/jobs/${a.json.id}${part}`, as('alice'))).status, 200, part);
        assert.equal((await d.get(`/v1/jobs/${a.json.id}${part}`, as('root'))).status, 200, part);
    }
    // another name's job is not there to cancel either: the same 404 as
    // for a job that never was, neither its owner nor its existence shown
    const refused = await d.del(`/v1/jobs/${a.json.id}`, as('carol'));
    assert.equal(refused.status, 404, refused.text);
    assert.doesNotMatch(refused.text, /alice/);
    const never = await d.del('/v1/jobs/999999', as('carol'));
    assert.equal(never.status, 404, never.text);
    assert.equal(refused.json.detail.replace(String(a.json.id), 'N'),
        never.json.detail.replace('999999', 'N'));
    assert.notEqual((await d.get(`/v1/jobs/${a.json.id}`, as('alice'))).json.state, 'cancelled');
    const cancelled = await d.del(`/v1/jobs/${a.json.id}`, as('root'));
    assert.ok([200, 202].includes(cancelled.status), cancelled.text);
    assert.equal((await finalAs('alice', a.json.id)).state, 'cancelled');
});

test('a name has at most --jobs-per-name jobs queued or running; others still submit', async () => {
    // alice's first job is cancelled (or stopping): two more fit, a third does not
    const ids = [];
    for (let i = 0; i < 2; i++) {
        const r = await post('alice');
        assert.equal(r.status, 202, r.text);
        ids.push(r.json.id);
    }
    const over = await post('alice');
    assert.equal(over.status, 429, over.text);
    assert.ok(Number(over.headers.get('retry-after')) > 0);
    assert.match(over.json.detail, /^'alice' has 2 jobs queued or running/);
    assert.equal((await post('carol', 'steps=3')).status, 202);
    for (const id of ids) {
        const r = await d.del(`/v1/jobs/${id}`, as('alice'));
        assert.ok([200, 202].includes(r.status), `${id}: ${r.status} ${r.text}`);
        await finalAs('alice', id);
    }
    assert.equal((await post('alice', 'steps=3')).status, 202, 'room again once cancelled');
});

test('a name stores at most --bytes-per-name: 429 until it deletes finished jobs', async () => {
    const small = await startDaemon({ workers: 1, args: ['--tokens', join(dir, 'tokens'), '--bytes-per-name', '1'] });
    try {
        const as2 = (name) => ({ type: 'text/plain', ...as(name) });
        const first = await small.post('/v1/jobs?steps=3', SQUARE, as2('alice'));
        assert.equal(first.status, 202, first.text);
        const over = await small.post('/v1/jobs?steps=3', SQUARE, as2('alice'));
        assert.equal(over.status, 429, over.text);
        assert.match(over.json.detail, /^'alice' has stored 1 bytes or more.*delete finished jobs/);
        assert.equal((await small.post('/v1/jobs?steps=3', SQUARE, as2('carol'))).status, 202);
        for (const t0 = Date.now(); (await small.get(`/v1/jobs/${first.json.id}`, as('alice'))).json.state !== 'done'; await sleep(50))
            assert.ok(Date.now() - t0 < 30000, 'the first job did not end');
        assert.equal((await small.post('/v1/jobs?steps=3', SQUARE, as2('alice'))).status, 429, 'ended, still stored');
        assert.equal((await small.del(`/v1/jobs/${first.json.id}`, as('alice'))).status, 204);
        assert.equal((await small.post('/v1/jobs?steps=3', SQUARE, as2('alice'))).status, 202, 'room once deleted');
    } finally {
        await small.stop();
    }
});

test('the remote client sends --token or $TIGHTKNOT_TOKEN', async () => {
    const r = await post('carol', 'steps=3');
    const run = (args, env = {}) => new Promise((res) => execFile(CLI, ['remote', '--server', d.base, ...args],
        { env: { ...process.env, TIGHTKNOT_TOKEN: '', ...env } }, (err, stdout, stderr) =>
        res({ code: err ? err.code : 0, stdout, stderr })));
    const bare = await run(['status', String(r.json.id)]);
    assert.notEqual(bare.code, 0);
    assert.match(bare.stderr, /401|token/i);
    const flag = await run(['--token', TOKENS.carol, 'status', String(r.json.id)]);
    assert.equal(flag.code, 0, flag.stderr);
    assert.match(flag.stdout, new RegExp(`^${r.json.id}\\b`, 'm'));
    const env = await run(['status', String(r.json.id)], { TIGHTKNOT_TOKEN: TOKENS.carol });
    assert.equal(env.code, 0, env.stderr);
    const other = await run(['--token', TOKENS.alice, 'status', String(r.json.id)]);
    assert.notEqual(other.code, 0, 'alice cannot read carol\'s job');
});

test('remote submit without a token, or with a wrong one, stops at the first 401 and says how to pass one', async () => {
    const dir = tempDir();
    const files = ['a', 'b', 'c'].map((n) => {
        const f = join(dir, `${n}.vect`);
        writeFileSync(f, SQUARE);
        return f;
    });
    const run = (args) => new Promise((res) => execFile(CLI, ['remote', '--server', d.base, ...args],
        { env: { ...process.env, TIGHTKNOT_TOKEN: '' } }, (err, stdout, stderr) =>
        res({ code: err ? err.code : 0, stdout, stderr })));
    const listed = async () => (await fetch(`${d.base}/v1/jobs?limit=500`, as('root')).then((x) => x.json())).total;
    const before = await listed();
    const bare = await run(['submit', '--steps', '3', '--out', join(dir, 'out'), ...files]);
    assert.equal(bare.code, 3, bare.stderr);
    assert.match(bare.stderr, /needs a token \(401\): pass --token TOKEN or set \$TIGHTKNOT_TOKEN/);
    assert.equal((bare.stderr.match(/\(401\)/g) || []).length, 1, `one refusal, not one per file: ${bare.stderr}`);
    assert.doesNotMatch(bare.stderr, /refused:/, 'no file is marked refused');
    const wrong = await run(['--token', 'not-a-token-of-the-file', 'submit', '--steps', '3',
        '--out', join(dir, 'out2'), ...files]);
    assert.equal(wrong.code, 3, wrong.stderr);
    assert.match(wrong.stderr, /refused the token \(401\)/);
    assert.equal(await listed(), before, 'no job was stored');
});

// Runs the daemon with args until it prints its first line or exits.
function launch(args) {
    return new Promise((res) => {
        const p = spawn(DAEMON, args, { stdio: ['ignore', 'pipe', 'pipe'] });
        let out = '', err = '';
        p.stdout.on('data', (x) => { out += x; if (out.includes('\n')) { p.kill('SIGTERM'); } });
        p.stderr.on('data', (x) => (err += x));
        p.on('exit', (code) => res({ code, out, err }));
    });
}

test('another address than loopback needs tokens or --allow-anonymous; a bad tokens file is named', async () => {
    const db = join(dir, 'other.db');
    const open = await launch(['--bind', '0.0.0.0', '--port', '0', '--db', db]);
    assert.equal(open.code, 1);
    assert.match(open.err, /--tokens FILE, or --allow-anonymous/);
    const anon = await launch(['--bind', '0.0.0.0', '--port', '0', '--db', db, '--allow-anonymous']);
    assert.match(anon.out, /^tightknotd: \S+ listening on http:\/\/0\.0\.0\.0:\d+\//);
    const tok = await launch(['--bind', '0.0.0.0', '--port', '0', '--db', db, '--tokens', join(dir, 'tokens')]);
    assert.match(tok.out, /^tightknotd: \S+ listening on/);
    writeFileSync(join(dir, 'bad'), 'alice ok-and-long-enough\nbob sha256:12345\n');
    const bad = await launch(['--port', '0', '--db', db, '--tokens', join(dir, 'bad')]);
    assert.equal(bad.code, 2);
    assert.match(bad.err, /bad:2: expected/);
});
