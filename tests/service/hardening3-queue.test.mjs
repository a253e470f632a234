// Hardening, round three (issue 55), the queue and the store's bounds:
// F2  a job paused by a failing store keeps its time budget for work: the
//     pause is not spent, and the job says how long it was paused;
// F3  --bytes-per-name bounds the frames a name stores, not only its
//     submissions: frames beyond it are refused and the job counts them;
// F6  the queue is fair between names: one name's many queued jobs do
//     not keep another's waiting behind all of them.
// F2 needs mount (root) for a small tmpfs, as store.test.mjs does.  F3 and
// F6 run on either store (TK_STORE=postgresql: on the tests' server).

import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { closeSync, mkdirSync, openSync, rmSync, statfsSync, writeFileSync, writeSync } from 'node:fs';
import { join } from 'node:path';
import { describe, test } from 'node:test';

import { ON_PG, sleep, startDaemon, submit, tempDir, waitFinal, waitJob } from './lib.mjs';

const TOKENS = { alice: 'alice-token-0000001', bob: 'bob-token-00000002' };
const as = (name) => ({ headers: { Authorization: `Bearer ${TOKENS[name]}` } });
function tokensFile() {
    const path = join(tempDir('h3-tokens'), 'tokens');
    writeFileSync(path, Object.entries(TOKENS).map(([n, t]) => `${n} ${t}\n`).join(''));
    return path;
}
async function submitAs(d, name, body) {
    const r = await d.post('/v1/jobs', body, as(name));
    assert.equal(r.status, 202, r.text);
    return r.json;
}
async function finalAs(d, name, id, timeout = 120000) {
    for (const t0 = Date.now(); Date.now() - t0 < timeout; await sleep(50)) {
        const j = (await d.get(`/v1/jobs/${id}`, as(name))).json;
        if (['done', 'failed', 'cancelled'].includes(j.state)) return j;
    }
    assert.fail(`job ${id} did not end in ${timeout} ms`);
}

// ---------------------------------------------------------------- F2

function canMount(dir) {
    try {
        mkdirSync(dir, { recursive: true });
        execFileSync('mount', ['-t', 'tmpfs', '-o', 'size=16m', 'tmpfs', dir], { stdio: 'pipe' });
        return true;
    } catch (e) {
        return false;
    }
}
// Fills the file system of dir: the free space as it is, and then in
// small pieces until a write fails, since the daemon's store may take
// some of it between the count and the write (a write of the whole count
// then failed with ENOSPC).
function fill(dir) {
    const s = statfsSync(dir);
    const fd = openSync(join(dir, 'filler'), 'w');
    try {
        for (let size = Math.max(0, s.bavail * s.bsize - 65536); size >= 512; ) {
            try {
                writeSync(fd, Buffer.alloc(size));
            } catch (e) {
                if (e.code !== 'ENOSPC') throw e;
                size = Math.floor(size / 2);
            }
        }
    } finally {
        closeSync(fd);
    }
}
const storeDir = join(tempDir('h3-full'), 'store');
const mounted = canMount(storeDir);

describe('F2: a pause of the store does not spend the time budget', { skip: mounted ? false : 'cannot mount a tmpfs here (needs root)' }, () => {
    test('time 6 s, paused 6 s after about 1.5 s: 6 s of work, paused_seconds about 6', async (t) => {
        const d = await startDaemon({ workers: 1, db: join(storeDir, 'jobs.db') });
        try {
            const T = 6, PAUSE = 6;
            const job = await submit(d, { catalogue: '3.1', options: { time: T, every: 1 } });
            await waitJob(d, job.id, (j) => j.state === 'running' && j.seconds > 1.5, { what: 'running 1.5 s' });
            fill(storeDir);
            const paused = await waitJob(d, job.id, (j) => j.error && /^paused/.test(j.error),
                { timeout: 30000, every: 20, what: 'paused' });
            const pausedAt = Date.now();
            await sleep(PAUSE * 1000);
            rmSync(join(storeDir, 'filler'));
            const freedAfter = (Date.now() - pausedAt) / 1000;
            const done = await waitFinal(d, job.id);
            const wall = (Date.parse(done.finished) - Date.parse(done.started)) / 1000;
            t.diagnostic(`paused at step ${paused.progress.step} (${paused.seconds} s of work) for ${freedAfter.toFixed(1)} s; ` +
                `ended ${done.state}/${done.stop_reason} at step ${done.progress.step}, seconds ${done.seconds}, ` +
                `paused_seconds ${done.paused_seconds}, wall ${wall.toFixed(1)} s`);
            assert.equal(done.state, 'done', JSON.stringify(done));
            assert.equal(done.stop_reason, 'time');
            // the run had its whole budget for work: started to finished is
            // the budget and the pause
            assert.ok(wall >= T + freedAfter - 1, `wall ${wall} s: the pause of ${freedAfter} s ate the budget of ${T} s`);
            assert.ok(done.seconds >= T && done.seconds < T + 1.5, `work ${done.seconds} s`);
            assert.equal(typeof done.paused_seconds, 'number', 'paused_seconds in the job');
            assert.ok(done.paused_seconds >= freedAfter - 0.5 && done.paused_seconds <= freedAfter + 2.5,
                `paused_seconds ${done.paused_seconds} against a pause of ${freedAfter} s`);
            assert.equal(done.error, null);
        } finally {
            await d.stop();
            execFileSync('umount', ['-l', storeDir]);
        }
    });
});

// ---------------------------------------------------------------- F3

// Bytes of a name's stored frames, and of the rest of its jobs, counted as
// the submission check counts them.
function storedBytes(d, owner) {
    const q = ON_PG
        ? `SELECT (SELECT coalesce(sum(octet_length(xyz)), 0) FROM frames f JOIN jobs j ON j.id = f.job WHERE j.doc->>'owner' = '${owner}'),` +
          ` (SELECT coalesce(sum(octet_length(doc::text) + octet_length(input) + coalesce(octet_length(curve), 0) +` +
          ` coalesce(octet_length(contacts), 0) + coalesce(octet_length(history), 0) + coalesce(octet_length(resume), 0)), 0)` +
          ` FROM jobs WHERE doc->>'owner' = '${owner}')`
        : `SELECT (SELECT coalesce(sum(length(xyz)), 0) FROM frames f JOIN jobs j ON j.id = f.job WHERE j.doc->>'owner' = '${owner}'),` +
          ` (SELECT coalesce(sum(length(CAST(doc AS BLOB)) + length(CAST(input AS BLOB)) + coalesce(length(CAST(curve AS BLOB)), 0) +` +
          ` coalesce(length(CAST(contacts AS BLOB)), 0) + coalesce(length(CAST(history AS BLOB)), 0) + coalesce(length(CAST(resume AS BLOB)), 0)), 0)` +
          ` FROM jobs WHERE doc->>'owner' = '${owner}')`;
    const out = ON_PG ? execFileSync('psql', [d.db, '-Atc', q], { encoding: 'utf8' })
        : execFileSync('sqlite3', [d.db, q], { encoding: 'utf8' });
    const [frames, rest] = out.trim().split('|').map(Number);
    return { frames, rest };
}

describe('F3: --bytes-per-name bounds the frames stored', () => {
    test('3 jobs of 300 steps, a frame each step, 200 kB: frames stop at the limit, the jobs count those refused', async (t) => {
        const LIMIT = 200000;
        const d = await startDaemon({ workers: 1, args: ['--tokens', tokensFile(), '--bytes-per-name', String(LIMIT)] });
        try {
            const ids = [];
            for (let i = 0; i < 3; i++)
                ids.push((await submitAs(d, 'alice', { catalogue: '3.1', options: { steps: 300, every: 1 } })).id);
            const jobs = [];
            for (const id of ids) jobs.push(await finalAs(d, 'alice', id));
            const b = storedBytes(d, 'alice');
            t.diagnostic(`frames stored ${jobs.map((j) => j.frames).join(', ')}, refused ${jobs.map((j) => j.frames_refused).join(', ')}; ` +
                `bytes: frames ${b.frames}, the rest ${b.rest} (limit ${LIMIT})`);
            for (const j of jobs) assert.equal(j.state, 'done', JSON.stringify(j));
            // the frames a name stores stay within its limit (a frame is
            // stored only while the name's bytes, with it, do; a job's
            // result, its document, curve and history, is always kept, so
            // the rest may go beyond: README, --bytes-per-name)
            assert.ok(b.frames <= LIMIT, `frames stored: ${b.frames} bytes against a limit of ${LIMIT}`);
            assert.ok(b.frames >= LIMIT / 4, `the limit is used: ${b.frames} bytes of frames`);
            // each job says how many of its frames were refused
            for (const j of jobs) {
                assert.equal(typeof j.frames_refused, 'number', 'frames_refused in the job');
                assert.equal(j.frames + j.frames_refused, j.progress.step + 1, `job ${j.id}: every frame stored or counted`);
                const f = await d.get(`/v1/jobs/${j.id}/frames?offset=0&limit=1`, as('alice'));
                assert.equal(f.json.total, j.frames);
            }
            assert.ok(jobs.reduce((n, j) => n + j.frames_refused, 0) > 0);
        } finally {
            await d.stop();
        }
    });
});

// ---------------------------------------------------------------- F6

describe('F6: the queue is fair between names', () => {
    test('alice queues 6 jobs, bob 1 after them (--workers 1): bob starts before alice\'s 3rd', async (t) => {
        const d = await startDaemon({ workers: 1, args: ['--tokens', tokensFile()] });
        try {
            const JOB = { catalogue: '3.1', options: { time: 0.5 } };
            const mine = [];
            for (let i = 0; i < 6; i++) mine.push((await submitAs(d, 'alice', JOB)).id);
            const theirs = (await submitAs(d, 'bob', JOB)).id;
            const bob = await finalAs(d, 'bob', theirs);
            const alice = [];
            for (const id of mine) alice.push(await finalAs(d, 'alice', id));
            const order = [...alice.map((j) => ({ who: `alice#${alice.indexOf(j) + 1}`, at: Date.parse(j.started) })),
                { who: 'bob', at: Date.parse(bob.started) }].sort((a, b) => a.at - b.at).map((x) => x.who);
            t.diagnostic(`start order: ${order.join(' ')}`);
            const before = alice.filter((j) => Date.parse(j.started) < Date.parse(bob.started)).length;
            assert.ok(before <= 2, `bob's job started after ${before} of alice's 6 (order ${order.join(' ')})`);
            // alice's own jobs keep their order
            for (let i = 1; i < alice.length; i++)
                assert.ok(Date.parse(alice[i].started) >= Date.parse(alice[i - 1].started));
        } finally {
            await d.stop();
        }
    });
});
