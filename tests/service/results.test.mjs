// Jobs give the command line's results to the bit: a generated knot sent as
// text/plain and as JSON, and a catalogue knot; their struts, curve,
// history and frames agree with each other and with `tightknot tighten`.

import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { after, before, describe, test } from 'node:test';

import {
    CATALOGUE, generate, startDaemon, submit, tempDir, tighten, vectCoordinates, waitFinal,
} from './lib.mjs';

let d, dir;
before(async () => {
    dir = tempDir('results');
    d = await startDaemon({ workers: 2 });
});
after(async () => d && (await d.stop()));

// The job's figures against the CLI's --json summary: identical doubles.
function assertSameFigures(job, cli) {
    assert.equal(job.state, 'done', JSON.stringify(job));
    assert.equal(job.error, null);
    assert.equal(job.progress.step, cli.steps, 'steps taken');
    assert.equal(job.stop_reason, cli.stop_reason);
    for (const k of ['ropelength', 'length', 'thickness', 'minrad', 'residual'])
        assert.equal(job[k], cli[k], `${k}: job ${job[k]} vs CLI ${cli[k]}`);
    for (const k of ['struts', 'kinks', 'vertices', 'components'])
        assert.equal(job[k], cli[k], k);
}

// GET .../struts against the CLI's --struts file.
async function assertSameStruts(job, cli) {
    const r = await d.get(`/v1/jobs/${job.id}/struts`);
    assert.equal(r.status, 200);
    const s = r.json;
    assert.equal(s.id, job.id);
    assert.equal(s.step, job.progress.step);
    assert.equal(s.thickness, cli.struts.thickness);
    assert.equal(s.struts.length, cli.struts.struts.length, 'strut count');
    assert.equal(s.struts.length, job.struts, 'strut count vs the job');
    assert.ok(s.struts.length > 0, 'a tightened knot has struts');
    s.struts.forEach((st, i) => {
        const c = cli.struts.struts[i];
        assert.deepEqual(st.edges, c.edges, `strut ${i} edges`);
        assert.equal(st.length, c.length, `strut ${i} length`);
        assert.equal(st.force, c.force, `strut ${i} force`);
        assert.equal(st.s, c.s, `strut ${i} s`);
        assert.equal(st.t, c.t, `strut ${i} t`);
        assert.deepEqual(st.p, c.p, `strut ${i} p`);
        assert.deepEqual(st.q, c.q, `strut ${i} q`);
    });
    assert.deepEqual(s.kinks.map((k) => [k.comp, k.vertex, k.minrad, k.force]),
        cli.struts.kinks.map((k) => [k.comp, k.vertex, k.minrad, k.force]), 'kinks');
    // the layout: one entry per component, laid end to end
    assert.equal(s.components.length, job.components);
    assert.equal(s.components.reduce((a, c) => a + c.vertices, 0), job.vertices);
    const total = s.components.reduce((a, c) => a + c.length, 0);
    assert.ok(Math.abs(total - job.length) <= 1e-12 * job.length, `component lengths ${total} vs ${job.length}`);
}

// GET .../vect (text and JSON) against the CLI's -o output, number by number.
async function assertSameCurve(job, cli) {
    const r = await d.get(`/v1/jobs/${job.id}/vect`);
    assert.equal(r.status, 200);
    assert.match(r.headers.get('content-type'), /^text\/plain/);
    const mine = vectCoordinates(r.text);
    const theirs = vectCoordinates(cli.vect);
    assert.deepEqual(mine.counts, theirs.counts, 'component vertex counts');
    assert.equal(mine.nvert, job.vertices);
    assert.equal(mine.xyz.length, theirs.xyz.length);
    for (let i = 0; i < mine.xyz.length; i++)
        if (mine.xyz[i] !== theirs.xyz[i])
            assert.fail(`coordinate ${i}: job ${mine.xyz[i]} vs CLI ${theirs.xyz[i]}`);
    const j = await d.get(`/v1/jobs/${job.id}/vect`, { headers: { accept: 'application/json' } });
    assert.equal(j.status, 200);
    assert.equal(j.json.id, job.id);
    assert.equal(j.json.step, job.progress.step);
    assert.equal(j.json.vect, r.text);
    return mine;
}

// History: starts at step 0, increases, ends at the job's step with its figures.
async function assertHistory(job) {
    const r = await d.get(`/v1/jobs/${job.id}/history`);
    assert.equal(r.status, 200);
    const h = r.json;
    assert.equal(h.id, job.id);
    assert.equal(h.step, job.progress.step);
    assert.ok(h.steps.length >= 2);
    assert.equal(h.steps[0].step, 0);
    assert.equal(h.steps[0].residual, null, 'no residual before the first step');
    for (let i = 1; i < h.steps.length; i++)
        assert.ok(h.steps[i].step > h.steps[i - 1].step, `history steps increase at ${i}`);
    const last = h.steps.at(-1);
    assert.equal(last.step, job.progress.step, 'last history step = job step');
    for (const k of ['ropelength', 'length', 'thickness', 'minrad', 'residual', 'step_size'])
        assert.equal(last[k], job[k], `last history ${k}`);
    assert.equal(last.struts, job.struts);
    assert.equal(last.vertices, job.vertices);
    // ?limit thins evenly and keeps both ends
    const t = await d.get(`/v1/jobs/${job.id}/history?limit=3`);
    assert.equal(t.status, 200);
    assert.equal(t.json.steps.length, Math.min(3, h.steps.length));
    assert.deepEqual(t.json.steps[0], h.steps[0]);
    assert.deepEqual(t.json.steps.at(-1), last);
    const bad = await d.get(`/v1/jobs/${job.id}/history?limit=1`);
    assert.equal(bad.status, 400);
    assert.equal(bad.json.parameter, 'limit');
    return h;
}

// Frames: the engine keeps the curve at every step that is a multiple of
// `every`, step 0 included (engine/tighten.c), so a run of S steps that is
// not interrupted keeps floor(S / every) + 1 frames.
async function assertFrames(job, curve) {
    const every = job.options.every;
    const expected = every > 0 ? Math.floor(job.progress.step / every) + 1 : 0;
    assert.equal(job.frames, expected, `frames for ${job.progress.step} steps every ${every}`);
    const all = [];
    for (let offset = 0; ; offset += 2) {
        const r = await d.get(`/v1/jobs/${job.id}/frames?offset=${offset}&limit=2`);
        assert.equal(r.status, 200);
        assert.equal(r.json.total, expected);
        assert.equal(r.json.offset, offset);
        assert.equal(r.json.limit, 2);
        assert.deepEqual(r.json.components.map((c) => (c.closed ? -c.vertices : c.vertices)), curve.counts);
        all.push(...r.json.frames);
        if (r.json.frames.length < 2) break;
    }
    assert.equal(all.length, expected, 'frames over all pages');
    all.forEach((f, i) => {
        assert.equal(f.index, i);
        assert.equal(f.step, i * every, `frame ${i} step`);
        // a frame has the vertices of its step (fewer on a coarse level)
        assert.equal(f.components.length, curve.counts.length);
        assert.equal(f.coordinates.length, 3 * verticesOf(f));
        assert.ok(verticesOf(f) <= job.vertices);
    });
    if (expected > 0 && job.progress.step % every === 0) {
        assert.deepEqual(all.at(-1).coordinates, curve.xyz, 'the last frame is the final curve');
        assert.deepEqual(all.at(-1).components.map((c) => (c.closed ? -c.vertices : c.vertices)), curve.counts);
    }
    return all;
}

function verticesOf(frame) {
    return frame.components.reduce((sum, c) => sum + c.vertices, 0);
}

describe('a generated trefoil, T(2,3) with 40 vertices, 150 steps', () => {
    let knot, cli;
    before(async () => {
        knot = await generate(dir, 'torus23.vect', ['torus', '2', '3', '--vertices', '40']);
        cli = await tighten(dir, knot.path, 'torus23', ['--steps', '150']);
        assert.equal(cli.summary.steps, 150);
    });

    test('text/plain with the options in the query equals the CLI', async () => {
        const queued = await submit(d, knot.text, { query: 'steps=150&every=30&name=torus%202%203' });
        assert.equal(queued.name, 'torus 2 3');
        assert.equal(queued.options.steps, 150);
        assert.equal(queued.options.every, 30);
        assert.equal(queued.vertices, 40);
        assert.equal(queued.ropelength, null, 'no figures before it runs');
        const job = await waitFinal(d, queued.id);
        assertSameFigures(job, cli.summary);
        assert.equal(job.progress.fraction, 1);
        await assertSameStruts(job, cli);
        const curve = await assertSameCurve(job, cli);
        await assertHistory(job);
        await assertFrames(job, curve);
    });

    test('JSON {"vect": ...} equals the CLI', async () => {
        const queued = await submit(d, { vect: knot.text, name: 'json torus', options: { steps: 150 } });
        assert.equal(queued.name, 'json torus');
        const job = await waitFinal(d, queued.id);
        assertSameFigures(job, cli.summary);
        await assertSameStruts(job, cli);
        const curve = await assertSameCurve(job, cli);
        await assertHistory(job);
        await assertFrames(job, curve); // every 0: no frames
        const r = await d.get(`/v1/jobs/${job.id}/frames`);
        assert.deepEqual(r.json.frames, []);
    });
});

describe('catalogue knot 3.1, resolution 5, 300 steps', () => {
    let cli;
    before(async () => {
        // a job runs the command line's schedule: coarse to fine here
        cli = await tighten(dir, join(CATALOGUE, '3.1.vect'), 'cat31', [
            '--resolution', '5', '--steps', '300',
        ]);
    });

    test('GET /v1/catalogue lists it and /v1/catalogue/3.1 gives its file', async () => {
        const list = await d.get('/v1/catalogue');
        assert.equal(list.status, 200);
        assert.equal(list.json.count, list.json.knots.length);
        const entry = list.json.knots.find((k) => k.name === '3.1');
        assert.ok(entry, '3.1 is listed');
        const file = readFileSync(join(CATALOGUE, '3.1.vect'), 'utf8');
        const one = await d.get('/v1/catalogue/3.1');
        assert.equal(one.status, 200);
        assert.equal(one.json.vect, file);
        assert.equal(one.json.vertices, vectCoordinates(file).nvert);
        assert.equal(one.json.vertices, entry.vertices);
        const missing = await d.get('/v1/catalogue/no-such-knot');
        assert.equal(missing.status, 404);
    });

    test('{"catalogue": "3.1", "options": {...}} equals the CLI', async () => {
        const queued = await submit(d, { catalogue: '3.1', options: { resolution: 5, steps: 300, every: 50 } });
        assert.equal(queued.name, '3.1');
        const job = await waitFinal(d, queued.id);
        assertSameFigures(job, cli.summary);
        // how sure the run is: the same basins as the command line's
        assert.deepEqual(job.basins, cli.summary.basins);
        assert.ok(job.basins.basins[0].ropelength >= job.ropelength);
        assert.ok(job.started <= job.finished && job.created <= job.started);
        await assertSameStruts(job, cli);
        const curve = await assertSameCurve(job, cli);
        const h = await assertHistory(job);
        assert.ok(h.steps.at(-1).length < h.steps[0].length, 'the flow shortens the knot');
        const frames = await assertFrames(job, curve);
        // the coarse level's frames have fewer vertices than the final
        // curve, and say so
        assert.ok(frames.some((f) => verticesOf(f) < job.vertices), 'frames of the coarse level');

        // the list shows it with the same figures
        const list = await d.get('/v1/jobs?state=done&limit=500');
        assert.equal(list.status, 200);
        const listed = list.json.jobs.find((j) => j.id === job.id);
        assert.deepEqual(listed, job);
        const ids = list.json.jobs.map((j) => j.id);
        assert.deepEqual(ids, [...ids].sort((a, b) => b - a), 'newest first');
    });
});

test('a job says which daemon runs it: none while queued, the one that ran it after', async () => {
    const m = /listening on \S+ \(workers \d+, store [^)]*? as (\S+?)[,)]/.exec(d.output());
    assert.ok(m, `the daemon names itself: ${d.output().split('\n')[0]}`);
    assert.match(m[1], /^[^:]+:\d+:[0-9a-f]{16}$/);
    const r = await d.post('/v1/jobs', { catalogue: '3.1', options: { steps: 5 } });
    assert.equal(r.status, 202, r.text);
    assert.ok('daemon' in r.json, 'the field is there from the start');
    assert.ok(r.json.daemon === null || r.json.daemon === m[1], r.json.daemon);
    const job = await waitFinal(d, r.json.id);
    assert.equal(job.state, 'done');
    assert.equal(job.daemon, m[1]);
});

describe('the catalogue clasp: its four planes, one constraint more, 400 steps', () => {
    let cli;
    const extra = '0:3=fixed';
    before(async () => {
        cli = await tighten(dir, join(CATALOGUE, 'simple_clasp.vect'), 'clasp', [
            '--autoscale', '--steps', '400', '--constrain', extra,
        ]);
    });

    test('{"catalogue", "constraints": [...]} equals the CLI, constraints and their forces too', async () => {
        const queued = await submit(d, {
            catalogue: 'simple_clasp', constraints: [extra], options: { autoscale: true, steps: 400 },
        });
        const job = await waitFinal(d, queued.id);
        assertSameFigures(job, cli.summary);
        await assertSameStruts(job, cli);
        await assertSameCurve(job, cli);
        const s = (await d.get(`/v1/jobs/${job.id}/struts`)).json;
        assert.equal(s.constraints.length, 5, 'the file\'s four and the one given');
        assert.deepEqual(s.constraints, cli.struts.constraints);
        assert.ok(s.constraints.some((p) => p.constraint.startsWith('0:3=point:')), 'fixed: a point');
        // the planes' ends: the rope's unit tension
        for (const p of s.constraints.filter((q) => q.constraint.includes('=plane:')))
            assert.ok(Math.abs(p.force - 1) < 0.05, `${p.constraint}: force ${p.force}`);
        // the curve keeps them, as the file wrote them
        const text = (await d.get(`/v1/jobs/${job.id}/vect`)).text;
        assert.equal((text.match(/^# Constraint \d+ /gm) ?? []).length, 5);
        assert.equal((text.match(/# Cst: \d+$/gm) ?? []).length, 5);
    });

    test('a constraint that cannot hold is a 422 naming it, and no job', async () => {
        const before = (await d.get('/v1/jobs?limit=500')).json.jobs.length;
        const cases = [
            [['2:0=free'], 'constraint', /no component 2/],
            [['0:99=free'], 'constraint', /component 0 has no vertex 99/],
            [['0:5=plane:0,0,0,1'], 'constraint', /plane normal is zero/],
            [['0:0=free'], 'constraint', /has a constraint already/],
            [['0:5=plane:0,0,1,100'], 'field', /constraint 0:5=plane.*from it/],
            [['0:5=wall'], 'constraint', /the kind is/],
            [[5], 'field', /array of strings/],
        ];
        for (const [constraints, member, detail] of cases) {
            const r = await d.post('/v1/jobs', { catalogue: 'simple_clasp', constraints, options: { steps: 5 } });
            assert.equal(r.status, 422, JSON.stringify(constraints));
            assert.match(r.headers.get('content-type'), /^application\/problem\+json/);
            assert.ok(member in r.json, `${JSON.stringify(constraints)}: ${JSON.stringify(r.json)}`);
            assert.match(r.json.detail, detail);
        }
        assert.equal((await d.get('/v1/jobs?limit=500')).json.jobs.length, before);
    });
});
