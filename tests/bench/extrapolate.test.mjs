// bench/extrapolate.mjs: the fit against figures made from a known limit,
// and a short run of the whole bench on catalogue 3.1.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { extrapolate, fitPower } from '../../bench/extrapolate.mjs';

const root = resolve(import.meta.dirname, '../..');
const build = resolve(process.env.TK_BUILD ?? join(root, 'build'));
const catalogue = resolve(process.env.TK_CATALOGUE ?? join(root, '../shared/catalogue'));

const made = (c, a, p, ns) => ns.map((n) => ({ n, r: c + a * n ** -p, u: 0 }));

test('the limit and exponent of exact figures come back', () => {
    for (const [c, a, p] of [[32.742934, 60, 2], [5, 10, 1.5], [42.09, 3e6, 3.1]]) {
        const fit = fitPower(made(c, a, p, [1200, 2400, 4800, 9600]));
        assert.ok(Math.abs(fit.c - c) <= 1e-9 * c, `c ${fit.c} against ${c}`);
        assert.ok(Math.abs(fit.p - p) <= 1e-4 * p, `p ${fit.p} against ${p}`);
        assert.ok(Math.abs(fit.a - a) <= 1e-3 * a, `a ${fit.a} against ${a}`);
        for (const e of fit.residuals) assert.ok(Math.abs(e) <= 1e-10 * c);
    }
});

test('three levels fit exactly, four leave residuals', () => {
    const three = made(1, 1, 2, [100, 200, 400]);
    three[1].r += 1e-6;
    const fit3 = fitPower(three);
    for (const e of fit3.residuals) assert.ok(Math.abs(e) <= 1e-12, `residual ${e}`);
    const four = made(1, 1, 2, [100, 200, 400, 800]);
    four[1].r += 1e-6;
    const fit4 = fitPower(four);
    assert.ok(Math.max(...fit4.residuals.map(Math.abs)) > 1e-8);
});

test('the error bar holds the limit of figures moved within their floors', () => {
    // a deterministic stream: figures moved by up to their floor each
    let seed = 12345;
    const next = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648) * 2 - 1;
    const c = 32.742934;
    for (let k = 0; k < 20; k++) {
        const pts = made(c, 60, 2, [1200, 2400, 4800, 9600]).map((q, i) => {
            const u = 1e-6 / 2 ** i;
            return { n: q.n, r: q.r + u * next(), u };
        });
        const fit = extrapolate(pts);
        assert.ok(Math.abs(fit.c - c) <= fit.error, `case ${k}: ${fit.c} +- ${fit.error} misses ${c}`);
        assert.ok(fit.error >= fit.floor && fit.error >= fit.leaveOut);
    }
});

test('figures that do not fall towards a limit are refused', () => {
    assert.throws(() => fitPower([{ n: 300, r: 32.8 }, { n: 600, r: 32.81 }, { n: 1200, r: 32.747 }]),
        /do not fall towards a limit/);
    assert.throws(() => fitPower(made(1, -1, 2, [100, 200, 400])), /do not fall towards a limit/);
    assert.throws(() => fitPower(made(1, 1, 2, [100, 200])), /three levels/);
});

const haveRun = existsSync(join(build, 'tightknot')) && existsSync(join(catalogue, '3.1.vect'));
test('a short run of the bench: levels of 2^k N vertices, the type kept, its fit its own',
    { skip: haveRun ? false : `needs ${build}/tightknot and ${catalogue}/3.1.vect` }, () => {
        const out = mkdtempSync(join(tmpdir(), 'tk-extrapolate-'));
        try {
            const args = [join(root, 'bench/extrapolate.mjs'), '--build', build, '--catalogue', catalogue,
                '--vertices', '60', '--levels', '3', '--seconds', '2', '--out', out, '--json', '3.1'];
            const run = spawnSync(process.execPath, args, { encoding: 'utf8' });
            assert.equal(run.status, 0, run.stderr);
            const fit = JSON.parse(run.stdout);
            assert.deepEqual(fit.levels.map((q) => q.n), [60, 120, 240]);
            fit.levels.forEach((q, i) => {
                const level = JSON.parse(readFileSync(join(out, `level-${q.n}.json`), 'utf8'));
                assert.deepEqual(level.invariants.result.alexander, level.invariants.start.alexander);
                assert.equal(level.ropelength, q.r);
                const vect = readFileSync(join(out, `level-${q.n}.vect`), 'utf8').split('\n');
                assert.match(vect[1], new RegExp(`^1 ${q.n} 0`));
                // the residuals are the figures less the fitted curve
                const again = q.r - (fit.c + fit.a * q.n ** -fit.p);
                assert.ok(Math.abs(again - fit.residuals[i]) <= 1e-12 * q.r);
            });
            // run again: the levels are taken up, not run again, and the fit is the same
            const again = spawnSync(process.execPath, args, { encoding: 'utf8' });
            assert.equal(again.status, 0, again.stderr);
            assert.doesNotMatch(again.stderr, /level \d/);
            assert.equal(JSON.parse(again.stdout).c, fit.c);
        } finally {
            rmSync(out, { recursive: true, force: true });
        }
    });
