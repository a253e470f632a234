// Several daemons on one PostgreSQL database share one queue: jobs
// submitted to one daemon run on all of them, none twice at once; when a
// daemon is killed (kill -9) its running job is taken up by another once
// its lease runs out, and every job ends with the command line's figures;
// any daemon answers for and cancels any job.  Needs TK_PG_URL (tests/pg.sh).

import assert from 'node:assert/strict';
import { describe, test } from 'node:test';

import { join } from 'node:path';

import {
    CATALOGUE, PG_LEASE, PG_URL, jobLines, jobRuns, pgDatabase, sleep, startDaemon, stopAll,
    submit, tempDir, tighten, waitFinal, waitJob,
} from './lib.mjs';

const skip = PG_URL ? false : 'TK_PG_URL is not set: no PostgreSQL server to share';

describe('three daemons on one PostgreSQL database', { skip }, () => {
    test('12 jobs spread over all three; kill -9 of one mid-run: every job done as the command line computes it, none run twice at once', async (t) => {
        const dir = tempDir('cluster');
        const db = pgDatabase();
        // four starts, three jobs each: 3 to 6 s of steps alone, so a job
        // whose stored progress is seen has time left to be killed in
        const starts = ['3.1', '4.1', '5.1', '5.2'];
        const STEPS = 2000;
        const options = ['--autoscale', '--resolution', '4', '--steps', String(STEPS)];
        const cli = await Promise.all(starts.map((k) => tighten(dir, join(CATALOGUE, `${k}.vect`), k, options)));

        const daemons = [];
        t.after(() => daemons.forEach((d) => d.proc.kill('SIGKILL')));
        for (let k = 0; k < 3; k++) daemons.push(await startDaemon({ workers: 1, db }));
        const jobs = [];
        for (let i = 0; i < 12; i++)
            jobs.push(await submit(daemons[0], {
                catalogue: starts[i % 4], name: `job${i}`,
                options: { autoscale: true, resolution: 4, steps: STEPS },
            }));

        // kill daemon 1 while it runs a job that it has stored beyond its
        // start (the store is written every 2 s) and not ended; a job
        // stored past three quarters of its steps may end before the kill
        // lands, so it is not chosen
        const victim = daemons[1];
        let target;
        for (const t0 = Date.now(); !target; await sleep(20)) {
            assert.ok(Date.now() - t0 < 60000, `daemon 1 stored no job's progress in 60 s:\n${victim.output()}`);
            const lines = jobLines(victim);
            const open = lines.filter((s) => s.what.startsWith('running') &&
                !lines.some((l) => l.id === s.id && l !== s && l.ms >= s.ms));
            for (const s of open) {
                const stored = (await daemons[0].get(`/v1/jobs/${s.id}`)).json;
                if (stored.state === 'running' && stored.progress.step > 0 &&
                    stored.progress.step <= 0.75 * STEPS) target = s;
            }
        }
        await victim.kill();
        const killedAt = Date.now();
        // the job daemon 1 held at the kill, from its own log: the one
        // chosen, unless that ended in the moment between
        const killed = jobRuns([victim], { 0: killedAt }).find((r) => r.end === 'killed');
        assert.ok(killed, `daemon 1 ran no job when it was killed:\n${victim.output()}`);
        if (killed.id !== target.id)
            t.diagnostic(`job ${target.id} ended before the kill; daemon 1 held job ${killed.id}`);
        target = killed;
        const stored = (await daemons[0].get(`/v1/jobs/${target.id}`)).json;
        t.diagnostic(`killed daemon 1 while it ran job ${target.id}, stored at step ${stored.progress.step}`);

        // every job ends done, read through a daemon that was not submitted to
        const reader = daemons[2];
        const done = [];
        for (const j of jobs) done.push(await waitFinal(reader, j.id, { timeout: 120000 }));

        const all = jobRuns(daemons, { 1: killedAt });
        // none ran twice at once: a job's runs follow each other
        for (const j of jobs) {
            const rs = all.filter((r) => r.id === j.id).sort((a, b) => a.from - b.from);
            assert.ok(rs.length >= 1, `job ${j.id} never ran`);
            for (let i = 1; i < rs.length; i++)
                assert.ok(rs[i].from >= rs[i - 1].to,
                    `job ${j.id} ran on daemons ${rs[i - 1].daemon} and ${rs[i].daemon} at once`);
            assert.equal(rs.at(-1).end, `done at step ${STEPS}`, `job ${j.id}'s last run: ${JSON.stringify(rs)}`);
        }
        // spread: each daemon ran jobs
        for (let k = 0; k < 3; k++)
            assert.ok(all.some((r) => r.daemon === k), `daemon ${k} ran no job`);
        // the killed daemon's job: taken up elsewhere, but not before its
        // lease ran out (renewed every second, so at most 1 s before the kill)
        const taken = all.find((r) => r.id === target.id && r.daemon !== 1 && r.from >= killedAt - 1000);
        assert.ok(taken, `job ${target.id} was not taken up after the kill: ${JSON.stringify(all)}`);
        const takeover = (taken.from - killedAt) / 1000;
        t.diagnostic(`job ${target.id} taken up by daemon ${taken.daemon} at step ${taken.step}, ` +
            `${takeover.toFixed(2)} s after the kill (lease ${PG_LEASE} s)`);
        assert.ok(takeover >= PG_LEASE - 1.2, `taken up ${takeover} s after the kill, within the lease`);
        assert.equal(taken.step, stored.progress.step, 'taken up where it was stored');
        t.diagnostic(`runs per daemon: ${[0, 1, 2].map((k) => all.filter((r) => r.daemon === k).length).join(', ')}`);

        // the command line's figures: bit for bit for a job that ran through;
        // a resumed run goes on from its stored curve (not the solver's
        // warm state), so it ends at the same step and polygon, of the
        // start's type.  Its flow is another path from there: at step 2000
        // the curve is still falling (about 0.1% a hundred steps for 4.1),
        // and a resumed 4.1 has ended 0.54% below the command line's.  So
        // its ropelength is held on one side (the resume lost no more
        // than 0.2% of the tightening) and its thickness holds the diameter
        for (let i = 0; i < 12; i++) {
            const job = done[i], want = cli[i % 4].summary;
            assert.equal(job.state, 'done', JSON.stringify(job));
            assert.equal(job.stop_reason, 'steps');
            assert.equal(job.progress.step, STEPS);
            assert.equal(job.vertices, want.vertices);
            const resumed = all.filter((r) => r.id === job.id).length > 1;
            assert.deepEqual(job.invariants.result, job.invariants.start, `job ${job.id}'s type`);
            if (resumed) {
                t.diagnostic(`resumed job ${job.id} (${starts[i % 4]}): ${job.ropelength} against ` +
                    `the command line's ${want.ropelength}`);
                assert.ok(job.ropelength < (1 + 2e-3) * want.ropelength,
                    `resumed job ${job.id}: ${job.ropelength} against ${want.ropelength}`);
                assert.ok(job.thickness >= 1 - 1e-5, `resumed job ${job.id}: thickness ${job.thickness}`);
            } else
                assert.equal(job.ropelength, want.ropelength, `job ${job.id} (${starts[i % 4]})`);
        }
        await stopAll(daemons[0], daemons[2]);
    });

    test('any daemon reads and cancels a job running on another', async (t) => {
        const db = pgDatabase();
        const daemons = [];
        t.after(() => daemons.forEach((d) => d.proc.kill('SIGKILL')));
        for (let k = 0; k < 2; k++) daemons.push(await startDaemon({ workers: 1, db }));
        const job = await submit(daemons[0], { catalogue: '3.1', options: { resolution: 10, time: 60 } });
        let runner;
        for (const t0 = Date.now(); runner === undefined; await sleep(20)) {
            assert.ok(Date.now() - t0 < 20000, 'the job did not start');
            runner = daemons.findIndex((d) => jobLines(d).some((l) => l.id === job.id));
            if (runner < 0) runner = undefined;
        }
        const other = daemons[1 - runner];
        // figures through the other daemon: from the store, written every 2 s
        const seen = await waitJob(other, job.id, (j) => j.state === 'running' && j.progress.step > 0);
        assert.ok(seen.ropelength > 0);
        const t0 = Date.now();
        const r = await other.del(`/v1/jobs/${job.id}`);
        assert.equal(r.status, 202, r.text);
        assert.equal(r.json.state, 'running');
        const end = await waitFinal(other, job.id, { timeout: 15000 });
        t.diagnostic(`cancelled through the other daemon: stored ${((Date.now() - t0) / 1000).toFixed(2)} s after DELETE`);
        assert.equal(end.state, 'cancelled');
        assert.equal(end.stop_reason, 'cancelled');
        assert.match(daemons[runner].output(), new RegExp(`job ${job.id}: cancelled at step \\d+`));
        await stopAll(...daemons);
    });

    test('a daemon shows its own change of a job at once, and another daemon\'s within seconds', async (t) => {
        const db = pgDatabase();
        const daemons = [];
        t.after(() => daemons.forEach((d) => d.proc.kill('SIGKILL')));
        for (let k = 0; k < 2; k++) daemons.push(await startDaemon({ workers: 1, db }));
        // two jobs keep both workers busy, so the next two stay queued
        const jobs = [];
        for (let i = 0; i < 4; i++)
            jobs.push(await submit(daemons[0], { catalogue: '3.1', options: { resolution: 10, time: 60 } }));
        for (const j of jobs.slice(0, 2))
            await waitJob(daemons[0], j.id, (x) => x.state === 'running');
        const [a, b] = [jobs[2].id, jobs[3].id];
        // read, changed through the same daemon, read again: the change at once
        for (let i = 0; i < 3; i++) assert.equal((await daemons[1].get(`/v1/jobs/${a}`)).json.state, 'queued');
        const r = await daemons[1].del(`/v1/jobs/${a}`);
        assert.equal(r.status, 200, r.text);
        assert.equal(r.json.state, 'cancelled');
        assert.equal((await daemons[1].get(`/v1/jobs/${a}`)).json.state, 'cancelled');
        // read through one daemon, changed through the other
        for (let i = 0; i < 3; i++) assert.equal((await daemons[1].get(`/v1/jobs/${b}`)).json.state, 'queued');
        assert.equal((await daemons[0].del(`/v1/jobs/${b}`)).status, 200);
        const t0 = Date.now();
        await waitJob(daemons[1], b, (x) => x.state === 'cancelled', { timeout: 3000, every: 10 });
        t.diagnostic(`another daemon's cancel seen after ${Date.now() - t0} ms`);
        for (const j of jobs.slice(0, 2)) await daemons[1].del(`/v1/jobs/${j.id}`);
        for (const j of jobs.slice(0, 2)) await waitFinal(daemons[1], j.id);
        await stopAll(...daemons);
    });
});
