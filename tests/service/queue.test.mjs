// The queue and the workers: cancelling queued and running jobs, a full
// queue (429), and many clients polling while the workers are busy.

import assert from 'node:assert/strict';
import { describe, test } from 'node:test';

import { sleep, startDaemon, submit, waitFinal, waitJob } from './lib.mjs';

// A job that runs far longer than any test: 3.1 at resolution 10 (367
// vertices) for a million steps.
const LONG = { catalogue: '3.1', options: { resolution: 10, steps: 1000000 } };
const SHORT = { catalogue: '3.1', options: { resolution: 5, steps: 20 } };

const running = (d, id) =>
    waitJob(d, id, (j) => j.state === 'running' && j.progress.step > 0, { what: 'running with a step taken' });

describe('cancelling (--workers 1)', () => {
    test('DELETE a queued job: 200 cancelled; a running one: 202, then cancelled; a finished one: 204, deleted', async (t) => {
        const d = await startDaemon({ workers: 1 });
        try {
            const a = await submit(d, LONG);
            await running(d, a.id);
            const b = await submit(d, LONG);
            assert.equal((await d.get(`/v1/jobs/${b.id}`)).json.state, 'queued');
            // before it starts, its curve is its input and it has no contacts
            const input = (await d.get('/v1/catalogue/3.1')).json.vect;
            assert.equal((await d.get(`/v1/jobs/${b.id}/vect`)).text, input);
            const none = (await d.get(`/v1/jobs/${b.id}/struts`)).json;
            assert.deepEqual([none.step, none.thickness, none.struts, none.kinks], [0, null, [], []]);
            assert.deepEqual((await d.get(`/v1/jobs/${b.id}/history`)).json.steps, []);
            assert.equal((await d.get(`/v1/jobs/${b.id}/frames`)).json.total, 0);

            // queued: cancelled at once
            const rb = await d.del(`/v1/jobs/${b.id}`);
            assert.equal(rb.status, 200, rb.text);
            assert.equal(rb.json.state, 'cancelled');
            assert.equal(rb.json.stop_reason, 'cancelled');
            assert.notEqual(rb.json.finished, null);
            assert.equal(rb.json.progress.step, 0);
            assert.equal((await d.get(`/v1/jobs/${b.id}`)).json.state, 'cancelled');
            assert.equal((await d.get('/v1/health')).json.queued, 0);

            // running: asked to stop, stops within a couple of seconds
            const ra = await d.del(`/v1/jobs/${a.id}`);
            assert.equal(ra.status, 202, ra.text);
            assert.equal(ra.json.state, 'running');
            const t0 = Date.now();
            const job = await waitJob(d, a.id, (j) => j.state !== 'running', { timeout: 5000, every: 20 });
            const ms = Date.now() - t0;
            t.diagnostic(`running job cancelled ${ms} ms after DELETE, at step ${job.progress.step}`);
            assert.equal(job.state, 'cancelled');
            assert.ok(ms < 2500, `cancelled after ${ms} ms`);
            assert.equal(job.stop_reason, 'cancelled');
            assert.notEqual(job.finished, null);
            assert.ok(job.progress.step > 0 && job.progress.step < LONG.options.steps);
            assert.ok(job.ropelength > 0);

            // it keeps its last curve and figures, all of the same step
            const h = await d.get(`/v1/jobs/${a.id}/history`);
            assert.equal(h.json.steps.at(-1).step, job.progress.step);
            assert.equal(h.json.steps.at(-1).ropelength, job.ropelength);
            const s = await d.get(`/v1/jobs/${a.id}/struts`);
            assert.equal(s.json.step, job.progress.step);
            assert.equal(s.json.struts.length, job.struts);
            const v = await d.get(`/v1/jobs/${a.id}/vect`, { headers: { accept: 'application/json' } });
            assert.equal(v.json.step, job.progress.step);

            const list = await d.get('/v1/jobs?state=cancelled');
            assert.deepEqual(list.json.jobs.map((j) => j.id), [b.id, a.id]);
            assert.equal(list.json.total, 2);

            // the worker is free again
            const c = await waitFinal(d, (await submit(d, SHORT)).id);
            assert.equal(c.state, 'done');
            assert.equal(c.progress.step, 20);

            // DELETE of a finished job removes it, with its texts and frames
            for (const id of [a.id, b.id, c.id]) {
                const gone = await d.del(`/v1/jobs/${id}`);
                assert.equal(gone.status, 204, gone.text);
                assert.equal(gone.text, '');
                for (const part of ['', '/vect', '/struts', '/history', '/frames'])
                    assert.equal((await d.get(`/v1/jobs/${id}${part}`)).status, 404, `${id}${part}`);
                assert.equal((await d.del(`/v1/jobs/${id}`)).status, 404);
            }
            assert.equal((await d.get('/v1/jobs')).json.total, 0);
        } finally {
            await d.stop();
        }
    });
});

describe('a full queue (--workers 1 --queue-limit 2)', () => {
    test('submissions beyond the limit get 429 with Retry-After; room again after a cancel', async () => {
        const d = await startDaemon({ workers: 1, queueLimit: 2 });
        try {
            const first = await submit(d, LONG);
            await running(d, first.id);
            const accepted = [];
            let refused;
            for (let i = 0; i < 10 && !refused; i++) {
                const r = await d.post('/v1/jobs', LONG);
                if (r.status === 202) accepted.push(r.json.id);
                else refused = r;
            }
            assert.ok(refused, 'a submission was refused');
            assert.equal(accepted.length, 2, 'two jobs wait, the third is refused');
            assert.equal(refused.status, 429, refused.text);
            assert.equal(refused.headers.get('content-type'), 'application/problem+json');
            const retry = refused.headers.get('retry-after');
            assert.match(retry ?? '', /^[1-9][0-9]*$/, `Retry-After: ${retry}`);
            assert.equal(refused.json.status, 429);
            assert.match(refused.json.detail, /queue is full/);

            // a text/plain submission is refused the same way
            const vect = (await d.get('/v1/catalogue/3.1')).json.vect;
            const plain = await d.post('/v1/jobs?resolution=5&steps=10', vect, { type: 'text/plain' });
            assert.equal(plain.status, 429);

            const h = await d.get('/v1/health');
            assert.deepEqual([h.json.running, h.json.queued, h.json.queue_limit, h.json.workers], [1, 2, 2, 1]);
            const m = await d.get('/metrics');
            assert.match(m.text, /^tightknot_queue_length 2$/m);
            assert.match(m.text, /^tightknot_workers_busy 1$/m);
            assert.match(m.text, /^tightknot_jobs\{state="queued"\} 2$/m);
            assert.match(m.text, /^tightknot_jobs\{state="running"\} 1$/m);
            const list = await d.get('/v1/jobs');
            assert.equal(list.json.total, 3, 'refused jobs are not stored');

            // cancelling a waiting job makes room for one more
            assert.equal((await d.del(`/v1/jobs/${accepted[0]}`)).status, 200);
            const again = await d.post('/v1/jobs', LONG);
            assert.equal(again.status, 202, again.text);
            assert.equal((await d.post('/v1/jobs', LONG)).status, 429);
        } finally {
            await d.stop(); // with a running job and a full queue: exit 0 within 10 s
        }
    });
});

describe('many clients polling while the workers are busy', () => {
    test('100 concurrent GET /v1/jobs/{id} all answer 200', async (t) => {
        const d = await startDaemon({ workers: 2 });
        try {
            const jobs = [await submit(d, LONG), await submit(d, LONG)];
            for (const j of jobs) await running(d, j.id);
            await sleep(300); // the engine at full speed on both workers
            const t0 = performance.now();
            const answers = await Promise.all(Array.from({ length: 100 }, (_, i) =>
                d.get(`/v1/jobs/${jobs[i % 2].id}`)));
            const wall = performance.now() - t0;
            const slowest = Math.max(...answers.map((r) => r.ms));
            t.diagnostic(`100 concurrent polls: slowest ${slowest.toFixed(1)} ms, all in ${wall.toFixed(1)} ms`);
            for (const [i, r] of answers.entries()) {
                assert.equal(r.status, 200);
                assert.equal(r.json.id, jobs[i % 2].id);
                assert.equal(r.json.state, 'running');
                assert.ok(r.json.progress.step > 0);
            }
            assert.ok(slowest < 10000, `slowest poll ${slowest} ms`);
            const h = await d.get('/v1/health');
            assert.equal(h.json.running, 2);
            // the jobs kept running during the burst
            const later = await Promise.all(jobs.map((j) => d.get(`/v1/jobs/${j.id}`)));
            later.forEach((r, i) => assert.ok(r.json.progress.step >= Math.max(
                ...answers.filter((_, k) => k % 2 === i).map((a) => a.json.progress.step))));
        } finally {
            await d.stop();
        }
    });
});
