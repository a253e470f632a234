// The job store on a file system that fills up (a small tmpfs of the
// test's own): health says so (503, degraded, the reason), a running job
// pauses instead of failing and goes on when space returns, and a stop
// while paused leaves it to resume.  A read-only one refuses the start.
// The frames a job keeps and its budgets are bounded.  Needs mount (root); skipped, and reported as
// skipped, where the test cannot mount.

import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { mkdirSync, readFileSync, rmSync, statfsSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { after, before, describe, test } from 'node:test';

import { DAEMON, sleep, startDaemon, submit, tempDir, waitFinal, waitJob } from './lib.mjs';

const mounts = [];
function mountTmpfs(dir, size) {
    mkdirSync(dir, { recursive: true });
    execFileSync('mount', ['-t', 'tmpfs', '-o', `size=${size}`, 'tmpfs', dir], { stdio: 'pipe' });
    mounts.push(dir);
}
function canMount() {
    try {
        const dir = join(tempDir('probe'), 'm');
        mountTmpfs(dir, '64k');
        execFileSync('umount', [dir]);
        mounts.pop();
        return true;
    } catch (e) {
        return false;
    }
}
const skip = canMount() ? false : 'cannot mount a tmpfs here (needs root and CAP_SYS_ADMIN)';

// Fills the file system of `dir` with a file, leaving about `leave` bytes.
function fill(dir, leave) {
    const s = statfsSync(dir);
    const free = s.bavail * s.bsize;
    const n = Math.max(0, free - leave);
    writeFileSync(join(dir, 'filler'), Buffer.alloc(n));
    return n;
}

// The catalogue's trefoil (47 vertices) for 20 s, a frame every step: its
// saves write the new frames, the curve and the history, tens of KiB.
const JOB = { catalogue: '3.1', options: { time: 20, every: 1 } };

describe('a full file system under the store', { skip }, () => {
    let d, dir;
    before(async () => {
        dir = join(tempDir('full'), 'store');
        mountTmpfs(dir, '16m');
        d = await startDaemon({ workers: 1, db: join(dir, 'jobs.db') });
    });
    after(async () => {
        if (d) await d.stop();
        for (const m of mounts.splice(0)) execFileSync('umount', ['-l', m]);
    });

    test('health ok; full: 503 degraded naming it, the job pauses with the reason; freed: it goes on to done', async () => {
        const h0 = await d.get('/v1/health');
        assert.equal(h0.status, 200, h0.text);
        const job = await submit(d, JOB);
        await waitJob(d, job.id, (j) => j.state === 'running' && j.progress.step > 20, { what: 'running' });
        fill(dir, 8 * 1024);
        const paused = await waitJob(d, job.id, (j) => j.error && /^paused: storing the job failed/.test(j.error),
            { timeout: 30000, what: 'paused' });
        assert.equal(paused.state, 'running');
        assert.match(paused.error, /full|disk/i);
        const h1 = await d.get('/v1/health');
        assert.equal(h1.status, 503, h1.text);
        assert.equal(h1.json.health, 'degraded');
        assert.match(h1.json.detail, /full/);
        // paused: the step stands still
        const at = (await d.get(`/v1/jobs/${job.id}`)).json.progress.step;
        await sleep(1500);
        assert.equal((await d.get(`/v1/jobs/${job.id}`)).json.progress.step, at, 'a paused job takes no steps');
        // reads still answer while writes fail
        assert.equal((await d.get(`/v1/jobs/${job.id}/history`)).status, 200);

        rmSync(join(dir, 'filler'));
        const done = await waitFinal(d, job.id);
        assert.equal(done.state, 'done', JSON.stringify(done));
        assert.equal(done.error, null);
        assert.equal(done.stop_reason, 'time');
        assert.ok(done.progress.step > at, `steps after the pause: ${at} -> ${done.progress.step}`);
        assert.equal((await d.get('/v1/health')).status, 200);
        // every frame the job reports can be read
        const f = await d.get(`/v1/jobs/${job.id}/frames?offset=${done.frames - 1}&limit=1`);
        assert.equal(f.json.total, done.frames);
        assert.equal(f.json.frames.length, 1);
    });

    test('stopped while paused: exits 0, and the job resumes at the next start', async () => {
        const job = await submit(d, JOB);
        await waitJob(d, job.id, (j) => j.state === 'running' && j.progress.step > 20, { what: 'running' });
        fill(dir, 8 * 1024);
        await waitJob(d, job.id, (j) => j.error && /^paused/.test(j.error), { timeout: 30000, what: 'paused' });
        await d.stop();
        rmSync(join(dir, 'filler'));
        d = await startDaemon({ workers: 1, db: join(dir, 'jobs.db') });
        const done = await waitFinal(d, job.id);
        assert.equal(done.state, 'done', JSON.stringify(done));
        assert.equal(done.stop_reason, 'time');
    });
});

describe('a read-only file system under the store', { skip }, () => {
    // A file system cannot turn read-only under an open, written file (the
    // remount is refused as busy), so this is the start on one.
    test('the daemon refuses to start on it: exit 2 naming the store', async () => {
        const dir = join(tempDir('ro'), 'store');
        mountTmpfs(dir, '8m');
        try {
            const d = await startDaemon({ workers: 1, db: join(dir, 'jobs.db') });
            await waitFinal(d, (await submit(d, { catalogue: '3.1', options: { steps: 5 } })).id);
            await d.stop();
            execFileSync('mount', ['-o', 'remount,ro', dir]);
            const r = spawnSync(DAEMON, ['--port', '0', '--db', join(dir, 'jobs.db')], { encoding: 'utf8', timeout: 10000 });
            assert.equal(r.status, 2, r.stdout + r.stderr);
            assert.match(r.stderr, /cannot set up the job store .*jobs\.db/);
        } finally {
            for (const m of mounts.splice(0)) execFileSync('umount', ['-l', m]);
        }
    });
});

describe('a damaged store', () => {
    test('at start: exit 2 naming the store, the file left as it was', async () => {
        const dir = tempDir('corrupt');
        const db = join(dir, 'jobs.db');
        const d = await startDaemon({ workers: 1, db });
        await waitFinal(d, (await submit(d, { catalogue: '3.1', options: { steps: 5 } })).id);
        await d.stop();
        // the header page overwritten: no longer an SQLite file
        const bytes = readFileSync(db);
        const damaged = Buffer.from(bytes);
        damaged.fill(0x5a, 0, Math.min(4096, damaged.length));
        writeFileSync(db, damaged);
        const r = spawnSync(DAEMON, ['--port', '0', '--db', db], { encoding: 'utf8', timeout: 10000 });
        assert.equal(r.status, 2, r.stdout + r.stderr);
        assert.match(r.stderr, /job store .*jobs\.db.*(not a database|malformed)/);
        assert.ok(readFileSync(db).equals(damaged), 'the damaged file is kept for whoever repairs it');
    });
});

describe('texts damaged in the store while the daemon runs', () => {
    // SQLite checks its pages, not the bytes inside a row: random bytes
    // written over a stored curve read back as they are.  The daemon reads
    // each stored text back as what it wrote (a VECT, JSON) before serving
    // it, and says so when it does not.
    test('a curve of random bytes and broken contacts: 500 naming them, health 503 degraded', async () => {
        const d = await startDaemon({ workers: 1 });
        try {
            const job = await waitFinal(d, (await submit(d, { catalogue: '3.1', options: { steps: 5 } })).id);
            const other = await waitFinal(d, (await submit(d, { catalogue: '4.1', options: { steps: 5 } })).id);
            assert.equal((await d.get(`/v1/jobs/${job.id}/vect`)).status, 200);
            assert.equal((await d.get('/v1/health')).status, 200);
            execFileSync('sqlite3', [d.db, `UPDATE jobs SET curve = CAST(randomblob(3000) AS TEXT) WHERE id = ${job.id};` +
                `UPDATE jobs SET contacts = '{"struts": [' || 'x' WHERE id = ${job.id};`]);
            const v = await d.get(`/v1/jobs/${job.id}/vect`);
            assert.equal(v.status, 500, v.text.slice(0, 200));
            assert.match(v.json.detail, new RegExp(`the stored curve of job ${job.id} does not read back`));
            const st = await d.get(`/v1/jobs/${job.id}/struts`);
            assert.equal(st.status, 500);
            assert.match(st.json.detail, /stored contacts/);
            const h = await d.get('/v1/health');
            assert.equal(h.status, 503);
            assert.equal(h.json.health, 'degraded');
            assert.match(h.json.detail, /damaged: the stored curve/);
            // the undamaged job still reads
            assert.equal((await d.get(`/v1/jobs/${other.id}/vect`)).status, 200);
        } finally {
            await d.stop();
        }
    });
});

describe('bounds on what a job keeps', () => {
    let d;
    before(async () => {
        d = await startDaemon({ workers: 1 });
    });
    after(async () => d && (await d.stop()));

    test('a frame every step keeps at most 1000 frames', async () => {
        const job = await waitFinal(d, (await submit(d, { catalogue: '3.1', options: { steps: 1200, every: 1 } })).id,
            { timeout: 60000 });
        assert.equal(job.state, 'done');
        assert.equal(job.progress.step, 1200);
        assert.equal(job.frames, 1000);
        const last = (await d.get(`/v1/jobs/${job.id}/frames?offset=999&limit=5`)).json;
        assert.equal(last.total, 1000);
        assert.equal(last.frames.length, 1);
    });

    test('steps over 1e8 and time over a week: 422 naming the option', async () => {
        for (const [options, option] of [[{ steps: 1e8 + 1 }, 'steps'], [{ time: 604801 }, 'time'],
            [{ every: 1e8 + 1 }, 'every'], [{ steps: 1e9 }, 'steps'], [{ time: 1e300 }, 'time']]) {
            const r = await d.post('/v1/jobs', { catalogue: '3.1', options });
            assert.equal(r.status, 422, `${JSON.stringify(options)}: ${r.text}`);
            assert.equal(r.json.option, option);
        }
    });
});
