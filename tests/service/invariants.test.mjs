// The knot or link type of a job: its start's and its result's, equal to
// what `tightknot tighten --json` says of the same run; a start that
// resampling would make another knot is refused with the engine's reason;
// a job resumed from a stored curve of another type than its input fails
// saying which polynomial changed; a stored type that does not read back
// is a 500 naming it.

import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { after, before, describe, test } from 'node:test';

import {
    cli, generate, startDaemon, submit, tempDir, tighten, waitFinal, waitJob,
} from './lib.mjs';

const TREFOIL = {
    alexander: [[1, -1, 1]],
    alexander_text: ['1 - t + t^2'],
    determinants: [3],
    link_determinant: 3,
    linking: [[0]],
    complete: true,
};

describe('a job\'s invariants', () => {
    let d, dir;
    before(async () => {
        dir = tempDir('invariants');
        d = await startDaemon({ workers: 2 });
    });
    after(async () => d && (await d.stop()));

    test('a trefoil and a Hopf link: start and result as the CLI gives them', async () => {
        const trefoil = await generate(dir, 'torus23.vect', ['torus', '2', '3', '--vertices', '40']);
        const hopf = await generate(dir, 'hopf.vect', ['hopf']);
        for (const [knot, tag] of [[trefoil, 'torus23'], [hopf, 'hopf']]) {
            const mine = await tighten(dir, knot.path, tag, ['--steps', '60', '--autoscale']);
            const queued = await submit(d, { vect: knot.text, name: tag, options: { steps: 60, autoscale: true } });
            assert.equal(queued.invariants, null, 'no type before the run starts');
            const job = await waitFinal(d, queued.id);
            assert.equal(job.state, 'done', JSON.stringify(job));
            assert.equal(job.progress.step, mine.summary.steps);
            assert.deepEqual(job.invariants, mine.summary.invariants, `${tag}: job vs CLI`);
            assert.deepEqual(job.invariants.result, job.invariants.start, `${tag}: the type kept`);
            const listed = (await d.get('/v1/jobs?limit=500')).json.jobs.find((j) => j.id === job.id);
            assert.deepEqual(listed.invariants, job.invariants, `${tag}: the list shows it too`);
        }
        const t = (await d.get('/v1/jobs?limit=500')).json.jobs.find((j) => j.name === 'torus23');
        assert.deepEqual(t.invariants.start, TREFOIL);
        assert.deepEqual(t.invariants.result, TREFOIL);
        const h = (await d.get('/v1/jobs?limit=500')).json.jobs.find((j) => j.name === 'hopf');
        const lk = h.invariants.result.linking;
        assert.ok(Math.abs(lk[0][1]) === 1 && lk[1][0] === lk[0][1] && lk[0][0] === 0 && lk[1][1] === 0,
            `the Hopf link's linking matrix: ${JSON.stringify(lk)}`);
        assert.deepEqual(h.invariants.result.determinants, [1, 1]);
        assert.equal(h.invariants.result.link_determinant, 2, 'the Hopf link\'s own determinant');
    });

    test('resampling at resolution 0.1 would unknot the trefoil: the job fails with the engine\'s reason', async () => {
        const text = await cli(['generate', 'torus', '2', '3']);
        const job = await waitFinal(d, (await submit(d, { vect: text, options: { resolution: 0.1, autoscale: true } })).id);
        assert.equal(job.state, 'failed', JSON.stringify(job));
        assert.match(job.error, /^resampling to 4 vertices \(resolution 0\.1\): .*its Alexander polynomial was 1 - t \+ t\^2, now 1$/);
        // the CLI says the same
        const path = (await generate(dir, 'coarse.vect', ['torus', '2', '3'])).path;
        let failed = null;
        try {
            await cli(['tighten', path, '--resolution', '0.1', '--autoscale']);
        } catch (e) {
            failed = e;
        }
        assert.ok(failed, 'the CLI fails too');
        assert.equal(failed.code, 2);
        assert.ok(failed.stderr.includes(job.error), `CLI: ${failed.stderr}`);
    });

    test('a stored document that does not read back: 500 naming it, health degraded', async () => {
        const own = await startDaemon({ workers: 1 });
        try {
            const job = await waitFinal(own, (await submit(own, { catalogue: '3.1', options: { steps: 3 } })).id);
            assert.equal(job.invariants.start.determinants.length, 1);
            // the document (with the job's type) cut short
            execFileSync('sqlite3', [own.db, `UPDATE jobs SET doc = substr(doc, 1, 40) WHERE id = ${job.id};`]);
            const r = await own.get(`/v1/jobs/${job.id}`);
            assert.equal(r.status, 500);
            assert.match(r.json.detail, new RegExp(`the stored document of job ${job.id} does not read back`));
            const h = await own.get('/v1/health');
            assert.equal(h.status, 503);
            assert.match(h.json.detail, /damaged: the stored document/);
        } finally {
            await own.stop();
        }
    });
});

describe('a job resumed from a curve of another type', () => {
    test('fails, its reason saying which polynomial changed', async (t) => {
        const dir = tempDir('retype');
        const trefoil = await cli(['generate', 'torus', '2', '3', '--vertices', '40']);
        // one ring of radius 1: an unknot, thicker than the tube
        const unknot = await cli(['generate', 'chain', '1']);
        const d1 = await startDaemon({ workers: 1, dir });
        t.after(() => d1.proc.kill('SIGKILL'));
        const queued = await submit(d1, { vect: trefoil, name: 'retyped', options: { time: 60 } });
        // running, and stored with its type (the type is read from the store)
        const live = await waitJob(d1, queued.id, (j) => j.state === 'running' && j.progress.step > 0 &&
            j.invariants !== null, { what: 'running and stored' });
        assert.deepEqual(live.invariants.start, TREFOIL);
        await d1.stop(); // stored as queued, with its curve, to resume
        const stored = execFileSync('sqlite3', [d1.db, `SELECT state, json_extract(doc, '$.progress.step') > 0 FROM jobs WHERE id = ${queued.id};`],
            { encoding: 'utf8' }).trim();
        assert.equal(stored, 'queued|1');
        // a curve of another type where the job resumes
        execFileSync('sqlite3', [d1.db, `UPDATE jobs SET curve = '${unknot}' WHERE id = ${queued.id};`]);

        const d2 = await startDaemon({ workers: 1, dir, db: d1.db });
        try {
            const job = await waitFinal(d2, queued.id);
            assert.equal(job.state, 'failed', JSON.stringify(job));
            assert.match(job.error, /^the curve resumed at step \d+: .*its Alexander polynomial was 1 - t \+ t\^2, now 1$/);
            assert.deepEqual(job.invariants.start, TREFOIL, 'the start is the input\'s type');
            assert.deepEqual(job.invariants.result.alexander, [[1]], 'the result is the unknot');
            assert.ok(job.finished !== null);
        } finally {
            await d2.stop();
        }
    });
});
