// HTTPS (tightknotd --tls-cert FILE --tls-key FILE) with a certificate the
// test makes itself: a private CA signs a certificate for 127.0.0.1 and
// localhost.  Clients that trust the CA talk to the daemon (node's https,
// the remote client with --cacert); plain HTTP and clients that do not
// trust it get nothing; a key that does not fit the certificate, or one of
// the two alone, stops the daemon from starting.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFile, execFileSync, spawn } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { request as httpsRequest } from 'node:https';
import { request as httpRequest } from 'node:http';
import { join } from 'node:path';
import { CLI, DAEMON, tempDir } from './lib.mjs';

const SQUARE = 'VECT\n1 4 0\n-4\n0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n';
let dir, ca, proc, port;

const openssl = (...args) => execFileSync('openssl', args, { cwd: dir, stdio: ['ignore', 'pipe', 'pipe'] });

// Starts the daemon; resolves to its first line or its exit.
function launch(args) {
    return new Promise((res) => {
        const p = spawn(DAEMON, ['--port', '0', '--db', join(dir, 'jobs.db'), '--workers', '1', ...args],
            { stdio: ['ignore', 'pipe', 'pipe'] });
        let out = '', err = '';
        p.stdout.on('data', (x) => {
            out += x;
            if (out.includes('\n')) res({ p, out, err });
        });
        p.stderr.on('data', (x) => (err += x));
        p.on('exit', (code) => res({ code, out, err }));
    });
}

function get(requester, path, options = {}) {
    return new Promise((res) => {
        const req = requester({ host: '127.0.0.1', port, path, method: options.method ?? 'GET',
            headers: options.headers ?? {}, ca: options.ca, timeout: 5000 }, (r) => {
            let text = '';
            r.setEncoding('utf8').on('data', (c) => (text += c)).on('end', () => res({ status: r.statusCode, text }));
        });
        req.on('error', (e) => res({ error: e }));
        req.on('timeout', () => req.destroy(new Error('timeout')));
        req.end(options.body);
    });
}

const remote = (args) => new Promise((res) => execFile(CLI, ['remote', '--server', `https://127.0.0.1:${port}`, ...args],
    (err, stdout, stderr) => res({ code: err ? err.code : 0, stdout, stderr })));

before(async () => {
    dir = tempDir('tls');
    openssl('req', '-x509', '-newkey', 'rsa:2048', '-nodes', '-keyout', 'ca.key', '-out', 'ca.pem', '-days', '2',
        '-subj', '/CN=tightknot test CA');
    openssl('req', '-newkey', 'rsa:2048', '-nodes', '-keyout', 'key.pem', '-out', 'server.csr', '-subj', '/CN=localhost');
    writeFileSync(join(dir, 'ext'), 'subjectAltName=IP:127.0.0.1,DNS:localhost\n');
    openssl('x509', '-req', '-in', 'server.csr', '-CA', 'ca.pem', '-CAkey', 'ca.key', '-CAcreateserial',
        '-out', 'cert.pem', '-days', '2', '-extfile', 'ext');
    ca = readFileSync(join(dir, 'ca.pem'));
    const r = await launch(['--tls-cert', join(dir, 'cert.pem'), '--tls-key', join(dir, 'key.pem')]);
    assert.ok(r.p, `the daemon did not start: ${r.out}${r.err}`);
    proc = r.p;
    const m = /^tightknotd: \S+ listening on https:\/\/127\.0\.0\.1:(\d+)\//.exec(r.out);
    assert.ok(m, r.out);
    port = Number(m[1]);
});

after(() => proc?.kill('SIGTERM'));

test('a client that trusts the CA is answered over HTTPS', async () => {
    const r = await get(httpsRequest, '/v1/health', { ca });
    assert.equal(r.error, undefined, String(r.error));
    assert.equal(r.status, 200);
    assert.equal(JSON.parse(r.text).status, 'ok');
    const posted = await get(httpsRequest, '/v1/jobs?steps=3', { ca, method: 'POST',
        headers: { 'Content-Type': 'text/plain' }, body: SQUARE });
    assert.equal(posted.status, 202, posted.text);
});

test('plain HTTP and a client that does not trust the CA get nothing', async () => {
    const plain = await get(httpRequest, '/v1/health');
    assert.ok(plain.error || plain.status === undefined, `plain HTTP answered ${plain.status}`);
    const untrusting = await get(httpsRequest, '/v1/health');
    assert.ok(untrusting.error, 'answered without trusting the CA');
    assert.match(untrusting.error.code, /UNABLE_TO_VERIFY_LEAF_SIGNATURE|UNABLE_TO_GET_ISSUER_CERT_LOCALLY/);
});

test('the remote client verifies the server with --cacert', async () => {
    const ok = await remote(['--cacert', join(dir, 'ca.pem'), 'status', '1']);
    assert.equal(ok.code, 0, ok.stderr);
    assert.match(ok.stdout, /^1\b/m);
    const refused = await remote(['status', '1']);
    assert.equal(refused.code, 3);
    assert.match(refused.stderr, /certificate/i);
    assert.match(refused.stderr, /pass --cacert FILE/, 'the refusal says how to trust the CA');
});

test('a key that does not fit, or a certificate alone, stops the daemon from starting', async () => {
    const wrong = await launch(['--tls-cert', join(dir, 'cert.pem'), '--tls-key', join(dir, 'ca.key')]);
    assert.equal(wrong.code, 2, wrong.out);
    assert.match(wrong.err, /TLS certificate or key was refused/);
    const alone = await launch(['--tls-cert', join(dir, 'cert.pem')]);
    assert.equal(alone.code, 2);
    assert.match(alone.err, /give both, or neither/);
});
