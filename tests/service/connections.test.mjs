// Connections: idle ones neither block others nor stay open past the
// timeout; beyond the connection limit new connections wait (in the
// listen queue) until one is freed.

import assert from 'node:assert/strict';
import { connect } from 'node:net';
import { describe, test } from 'node:test';

import { sleep, startDaemon } from './lib.mjs';

// Opens a TCP connection that sends nothing; resolves once connected, with
// a promise of the moment the server closes it.
function idleSocket(port) {
    return new Promise((resolve, reject) => {
        const s = connect(port, '127.0.0.1');
        const closed = new Promise((r) => s.on('close', () => r(Date.now())));
        s.on('error', () => {});
        s.once('connect', () => resolve({ socket: s, closed }));
        s.once('error', reject);
    });
}

// GET path on a new connection of its own (fetch would reuse a pooled
// one); resolves with the status line.
function rawGet(port, path) {
    return new Promise((resolve, reject) => {
        const s = connect(port, '127.0.0.1');
        let data = '';
        s.setEncoding('utf8');
        s.on('data', (chunk) => {
            data += chunk;
            if (data.includes('\r\n')) {
                resolve(data.split('\r\n')[0]);
                s.destroy();
            }
        });
        s.on('error', reject);
        s.write(`GET ${path} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n`);
    });
}

describe('idle connections', () => {
    test('100 idle connections: requests are still answered, and the idle ones are closed after --timeout', async () => {
        const d = await startDaemon({ args: ['--timeout', '2'] });
        try {
            const opened = Date.now();
            const idle = await Promise.all(Array.from({ length: 100 }, () => idleSocket(d.port)));
            const started = Date.now();
            // each request on a connection of its own: a pooled keep-alive
            // connection would itself be closed by the 2 s timeout
            assert.equal(await rawGet(d.port, '/v1/health'), 'HTTP/1.1 200 OK');
            assert.ok(Date.now() - started < 2000, 'answered while 100 connections sit idle');
            const closedAt = await Promise.race([
                Promise.all(idle.map((c) => c.closed)),
                sleep(10000).then(() => null),
            ]);
            assert.ok(closedAt, 'the server closed every idle connection within 10 s');
            const last = Math.max(...closedAt) - opened;
            assert.ok(last >= 1500, `closed after ${last} ms, not before the 2 s timeout`);
            assert.equal(await rawGet(d.port, '/v1/health'), 'HTTP/1.1 200 OK');
        } finally {
            await d.stop();
        }
    });

    test('beyond --max-connections a connection waits for a free slot; the open ones are not disturbed', async () => {
        const d = await startDaemon({ args: ['--max-connections', '20', '--timeout', '30'] });
        const idle = [];
        try {
            for (let i = 0; i < 19; i++) idle.push(await idleSocket(d.port));
            // one slot left: a request gets through
            assert.equal(await rawGet(d.port, '/v1/health'), 'HTTP/1.1 200 OK');
            for (let i = 0; i < 3; i++) idle.push(await idleSocket(d.port));
            // every slot is taken: a request is not taken up (it waits in the
            // listen queue) until connections are freed
            let answered = null;
            const waiting = rawGet(d.port, '/v1/health').then((r) => (answered = r));
            await sleep(1000);
            assert.equal(answered, null, 'no answer while every connection slot is taken');
            for (const c of idle.splice(0, 5)) c.socket.destroy();
            const r = await Promise.race([waiting, sleep(5000).then(() => null)]);
            assert.equal(r, 'HTTP/1.1 200 OK', 'answered once slots were freed');
        } finally {
            for (const c of idle) c.socket.destroy();
            await d.stop();
        }
    });
});
