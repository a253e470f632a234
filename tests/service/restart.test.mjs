// Jobs survive the daemon: after SIGKILL the store holds every job and the
// unfinished ones run to the end at the next start; after SIGTERM (exit 0
// within 10 s) the running job resumes where it stopped.

import assert from 'node:assert/strict';
import { describe, test } from 'node:test';

import { join } from 'node:path';

import {
    CATALOGUE, generate, sleep, startDaemon, submit, tempDir, tighten, waitFinal, waitJob,
} from './lib.mjs';

// The history of a resumed job: one run of increasing steps from 0 to the
// job's step, crossing the step it was interrupted at.
async function assertResumedHistory(d, job, interrupted) {
    const h = (await d.get(`/v1/jobs/${job.id}/history`)).json;
    assert.equal(h.step, job.progress.step);
    assert.equal(h.steps[0].step, 0);
    for (let i = 1; i < h.steps.length; i++)
        assert.ok(h.steps[i].step > h.steps[i - 1].step, `history steps increase at ${i}: ${h.steps[i - 1].step}, ${h.steps[i].step}`);
    assert.equal(h.steps.at(-1).step, job.progress.step);
    assert.equal(h.steps.at(-1).ropelength, job.ropelength);
    assert.ok(h.steps.some((s) => s.step <= interrupted) && h.steps.some((s) => s.step > interrupted),
        'the history spans the interruption');
    for (let i = 1; i < h.steps.length; i++)
        assert.ok(h.steps[i].seconds >= h.steps[i - 1].seconds, `history seconds increase at ${i}`);
}

// Frames of a resumed job: the total the job reports, steps increasing, on
// the grid of options.every.
async function assertResumedFrames(d, job) {
    const frames = [];
    for (let offset = 0; ; offset += 200) {
        const r = await d.get(`/v1/jobs/${job.id}/frames?offset=${offset}&limit=200`);
        assert.equal(r.json.total, job.frames);
        frames.push(...r.json.frames);
        if (r.json.frames.length < 200) break;
    }
    assert.equal(frames.length, job.frames);
    assert.ok(frames.length >= 2);
    assert.equal(frames[0].step, 0);
    for (let i = 1; i < frames.length; i++)
        assert.ok(frames[i].step > frames[i - 1].step, `frame steps increase at ${i}: ${frames[i - 1].step}, ${frames[i].step}`);
    // a frame has the vertices of its step (fewer on a coarse level)
    for (const f of frames)
        assert.equal(f.coordinates.length, 3 * f.components.reduce((n, c) => n + c.vertices, 0));
    // on the grid of the job's steps, across the restart: every multiple of
    // options.every up to the last step, each once
    const every = job.options.every;
    const want = Array.from({ length: Math.floor(job.progress.step / every) + 1 }, (_, i) => i * every);
    assert.deepEqual(frames.map((f) => f.step), want);
}

describe('kill -9 and restart on the same store', () => {
    test('all jobs listed; the interrupted one continues, the queued ones give the CLI results', async (t) => {
        const dir = tempDir('kill');
        const knot = await generate(dir, 'torus23.vect', ['torus', '2', '3', '--vertices', '40']);
        const cli = tighten(dir, knot.path, 'torus23', ['--steps', '150']);
        // the vertices of resolution 10, the final level of the long job's
        // coarse to fine schedule
        const finest = tighten(dir, join(CATALOGUE, '3.1.vect'), 'finest', ['--resolution', '10', '--no-coarse', '--steps', '1']);

        const d1 = await startDaemon({ workers: 1, dir });
        t.after(() => d1.proc.kill('SIGKILL')); // when the test fails before the kill
        // a 6-second job, then two short ones waiting behind it (no loose
        // levels: their small polygons step so fast that its 6 s go past
        // the 2,000 steps the history keeps whole, and the step before
        // its last refinement, checked below, can be thinned out)
        const a = await submit(d1, { catalogue: '3.1', name: 'long', options: { resolution: 10, time: 6, every: 100, autoscale: false, loose: 0 } });
        const b = await submit(d1, knot.text, { query: 'steps=150&name=b' });
        const c = await submit(d1, { vect: knot.text, name: 'c', options: { steps: 150 } });
        await waitJob(d1, a.id, (j) => j.state === 'running' && j.progress.step > 0);
        // the store is written every 2 s; its history is served from the
        // store, so a stored step past the start shows there (a worker
        // starved by a loaded machine, as under the thread sanitizer beside
        // the page's suite, may write later than 2 s)
        await sleep(3000);
        for (let t0 = Date.now(); Date.now() - t0 < 30000; await sleep(200)) {
            const h = (await d1.get(`/v1/jobs/${a.id}/history`)).json.steps;
            if (h.length && h[h.length - 1].step > 0) break;
        }
        const live = (await d1.get(`/v1/jobs/${a.id}`)).json;
        assert.equal(live.state, 'running');
        assert.equal((await d1.get(`/v1/jobs/${b.id}`)).json.state, 'queued');
        await d1.kill();

        const d2 = await startDaemon({ workers: 1, dir, db: d1.db });
        try {
            const list = await d2.get('/v1/jobs');
            assert.equal(list.json.total, 3);
            assert.deepEqual(list.json.jobs.map((j) => j.id), [c.id, b.id, a.id]);
            assert.deepEqual(list.json.jobs.map((j) => j.name), ['c', 'b', 'long']);
            const stored = list.json.jobs[2];
            assert.ok(['queued', 'running'].includes(stored.state), stored.state);
            assert.ok(stored.progress.step > 0, 'the store holds the running job\'s progress');
            assert.ok(stored.progress.step <= live.progress.step);

            const done = await waitFinal(d2, a.id, { timeout: 20000 });
            t.diagnostic(`killed at step ${live.progress.step} (stored ${stored.progress.step}), ` +
                `finished at step ${done.progress.step} after ${done.seconds.toFixed(2)} s`);
            assert.equal(done.state, 'done', JSON.stringify(done));
            assert.equal(done.stop_reason, 'time');
            // it goes on from the stored step (the live one was up to 2 s of
            // steps further; how far past it the rest of the time budget
            // takes the run depends on the CPU the worker gets)
            assert.ok(done.progress.step > stored.progress.step, 'it continued past its stored step');
            assert.ok(done.seconds >= 6 - 0.05 && done.seconds < 9, `seconds ${done.seconds}`);
            assert.equal(done.progress.fraction, 1);
            assert.ok(done.started < done.finished);
            await assertResumedHistory(d2, done, stored.progress.step);
            await assertResumedFrames(d2, done);
            // the schedule went on where it was: the job ends on its final
            // polygon, reckoned from the ropelength of the step before it
            // first got there, or from the start's where that was higher
            // (a worker starved by a loaded machine leaves its coarse
            // levels on their share of the time, before their plateau:
            // 3.1 at step 251, ropelength 37.30, start 36.19)
            const h = (await d2.get(`/v1/jobs/${a.id}/history`)).json.steps;
            const most = Math.max(...h.map((s) => s.vertices));
            const up = h.findIndex((s, i) => i > 0 && s.vertices === most && h[i - 1].vertices < most);
            assert.ok(up > 0, 'the job refined');
            assert.equal(h[up].step, h[up - 1].step + 1, 'the history holds the step before the refinement');
            const start = (await finest).summary.vertices;
            assert.equal(done.vertices, Math.min(Math.ceil(10 * h[up - 1].ropelength), start),
                `the final level: refined at step ${h[up].step} from ropelength ` +
                `${h[up - 1].ropelength} (${h[up - 1].vertices} vertices); the start's count ${start}`);

            // the two that never started run from their input, as the CLI does
            const want = (await cli).summary;
            for (const id of [b.id, c.id]) {
                const job = await waitFinal(d2, id);
                assert.equal(job.state, 'done');
                assert.equal(job.progress.step, 150);
                for (const k of ['ropelength', 'length', 'thickness', 'minrad', 'residual', 'struts', 'vertices'])
                    assert.equal(job[k], want[k], `job ${id} ${k}`);
            }
        } finally {
            await d2.stop();
        }
    });
});

describe('SIGTERM with a running job, and restart', () => {
    test('exits 0 within 10 s; the job resumes and ends at its step budget', async (t) => {
        const dir = tempDir('term');
        const STEPS = 1600;
        const d1 = await startDaemon({ workers: 1, dir });
        t.after(() => d1.proc.kill('SIGKILL')); // when the test fails before the stop
        const a = await submit(d1, { catalogue: '3.1', options: { resolution: 10, steps: STEPS, coarse: false } });
        // stop it well into the run, where struts are active (3.1 at
        // resolution 10 on the fine polygon alone takes about 1 s for its
        // first 1100 steps, 2 s for 1600)
        await waitJob(d1, a.id, (j) => j.state === 'running' && j.progress.step >= 1000, { every: 10 });
        const seconds = await d1.stop();
        t.diagnostic(`SIGTERM to exit: ${seconds.toFixed(2)} s`);
        assert.match(d1.output(), /SIGTERM: storing running jobs and stopping/);
        assert.match(d1.output(), /tightknotd: \S+ stopped$/m);

        const d2 = await startDaemon({ workers: 1, dir, db: d1.db });
        try {
            const stored = (await d2.get(`/v1/jobs/${a.id}`)).json;
            assert.ok(['queued', 'running'].includes(stored.state), stored.state);
            assert.ok(stored.progress.step > 0 && stored.progress.step < STEPS,
                `stored at step ${stored.progress.step}`);
            assert.equal(stored.finished, null);
            const done = await waitFinal(d2, a.id);
            t.diagnostic(`stopped at step ${stored.progress.step}, finished at ${done.progress.step}`);
            assert.equal(done.state, 'done', JSON.stringify(done));
            assert.equal(done.stop_reason, 'steps');
            assert.equal(done.progress.step, STEPS, 'the resumed run ends at the step budget');
            assert.equal(done.progress.fraction, 1);
            await assertResumedHistory(d2, done, stored.progress.step);
            const s = (await d2.get(`/v1/jobs/${a.id}/struts`)).json;
            assert.equal(s.step, STEPS);
            assert.equal(s.struts.length, done.struts);
        } finally {
            await d2.stop();
        }
    });
});

describe('frames across a restart', () => {
    test('every 1: one frame per step up to the 1000 kept, none repeated, after SIGTERM and resume', async (t) => {
        const dir = tempDir('frames');
        const knot = await generate(dir, 'torus23.vect', ['torus', '2', '3', '--vertices', '40']);
        const d1 = await startDaemon({ workers: 1, dir });
        t.after(() => d1.proc.kill('SIGKILL'));
        const a = await submit(d1, knot.text, { query: 'time=2&every=1' });
        await waitJob(d1, a.id, (j) => j.state === 'running' && j.progress.step >= 20, { every: 5 });
        await d1.stop();
        const d2 = await startDaemon({ workers: 1, dir, db: d1.db });
        try {
            const stored = (await d2.get(`/v1/jobs/${a.id}`)).json;
            assert.equal(stored.finished, null, 'stopped before it finished');
            const done = await waitFinal(d2, a.id);
            t.diagnostic(`stopped at step ${stored.progress.step}, finished at ${done.progress.step} (${done.stop_reason})`);
            assert.equal(done.state, 'done');
            assert.ok(done.progress.step > stored.progress.step);
            // a job keeps at most 1000 frames (openapi.yaml)
            const kept = Math.min(done.progress.step + 1, 1000);
            assert.equal(done.frames, kept, 'frames of steps 0 to N, at most 1000');
            const steps = [];
            for (let offset = 0; ; offset += 200) {
                const r = (await d2.get(`/v1/jobs/${a.id}/frames?offset=${offset}&limit=200`)).json;
                assert.equal(r.total, done.frames);
                steps.push(...r.frames.map((f) => f.step));
                if (r.frames.length < 200) break;
            }
            assert.deepEqual(steps, Array.from({ length: kept }, (_, i) => i));
        } finally {
            await d2.stop();
        }
    });
});

describe('SIGTERM while 100 clients poll', () => {
    // The stop order (refuse requests, store the running jobs, stop the
    // listener, then free the pool and close the store) under load: the
    // sanitizer builds run this too, and the daemon's exit status carries
    // what they find.
    test('exits 0 within 10 s; every answer was whole; the jobs resume', async (t) => {
        const d1 = await startDaemon({ workers: 2 });
        t.after(() => d1.proc.kill('SIGKILL'));
        const jobs = [];
        for (const knot of ['3.1', '4.1'])
            jobs.push(await submit(d1, { catalogue: knot, options: { resolution: 10, time: 60, every: 5 } }));
        for (const job of jobs)
            await waitJob(d1, job.id, (j) => j.state === 'running' && j.progress.step > 0);
        const paths = [`/v1/jobs/${jobs[0].id}`, `/v1/jobs/${jobs[1].id}/frames?limit=2`, '/v1/jobs',
            `/v1/jobs/${jobs[0].id}/struts`, `/v1/jobs/${jobs[1].id}/history`, '/v1/health'];
        let polling = true;
        const seen = {};
        const pollers = Array.from({ length: 100 }, async (_, i) => {
            const path = paths[i % paths.length];
            while (polling) {
                let r;
                try {
                    r = await d1.get(path, { timeout: 10000 });
                } catch (e) {
                    if (e.code === 'ERR_ASSERTION') throw e;
                    await sleep(5); // refused: the daemon has stopped listening
                    continue;
                }
                seen[r.status] = (seen[r.status] ?? 0) + 1;
                assert.ok(r.status === 200 || r.status === 503, `${path}: ${r.status} ${r.text.slice(0, 200)}`);
            }
        });
        await sleep(1500);
        const seconds = await d1.stop();
        polling = false;
        await Promise.all(pollers);
        t.diagnostic(`SIGTERM to exit under 100 pollers: ${seconds.toFixed(2)} s; answers ${JSON.stringify(seen)}`);
        assert.ok((seen[200] ?? 0) >= 100, `answers: ${JSON.stringify(seen)}`);

        const d2 = await startDaemon({ workers: 2, dir: d1.dir, db: d1.db });
        try {
            for (const job of jobs) {
                const stored = (await d2.get(`/v1/jobs/${job.id}`)).json;
                assert.ok(stored.progress.step > 0, `job ${job.id} stored at step ${stored.progress.step}`);
                const running = await waitJob(d2, job.id, (j) => j.state === 'running' && j.progress.step > stored.progress.step);
                assert.equal(running.finished, null);
            }
        } finally {
            await d2.stop();
        }
    });
});
