// bench/cluster.mjs: several daemons on one PostgreSQL database.
//
// Starts a PostgreSQL server of its own (tests/pg.sh; or uses $TK_PG_URL),
// then:
// 1. three daemons (one worker each) share one database; JOBS short jobs
//    are submitted to the first; once a third of them are done, the second
//    daemon is killed (kill -9) while it runs a job.  Prints how many jobs
//    ended done, how many each daemon finished, whether any job ran on two
//    daemons at once (from their logs), the lease and the time from the
//    kill until another daemon took the job up, and the wall time.
// 2. one daemon runs a long job per worker (a frame every step, so it
//    writes at every save) while a second daemon, with nothing to run,
//    answers wrk's polls of those jobs: requests/s, p50 and p99 through
//    the daemon that runs them and through the one that does not.
// Never fails on time.
//
// usage: node bench/cluster.mjs [BUILD_DIR] [CATALOGUE_DIR]
//   (environment: JOBS=30, LEASE=10 seconds, WINDOW=10 seconds of wrk,
//   CONNECTIONS=200)

import { execFile, spawnSync } from 'node:child_process';
import { chmodSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { promisify } from 'node:util';

const build = resolve(process.argv[2] ?? 'build');
process.env.TK_DAEMON = join(build, 'tightknotd');
process.env.TK_CLI = join(build, 'tightknot');
if (process.argv[3]) process.env.TK_CATALOGUE = resolve(process.argv[3]);
const JOBS = Number(process.env.JOBS ?? 30);
const LEASE = Number(process.env.LEASE ?? 10);
const WINDOW = Number(process.env.WINDOW ?? 10);
const CONNECTIONS = Number(process.env.CONNECTIONS ?? 200);

// a server of its own unless one is given; lib.mjs reads TK_PG_URL on import
let pgdir = null;
if (!process.env.TK_PG_URL) {
    pgdir = mkdtempSync(join(tmpdir(), 'tk-bench-pg-'));
    chmodSync(pgdir, 0o755);
    const r = spawnSync('tests/pg.sh', ['start', join(pgdir, 'server')], { encoding: 'utf8' });
    if (r.status !== 0) {
        console.log(`bench/cluster: no PostgreSQL server: ${r.stderr.trim()}`);
        process.exit(1);
    }
    process.env.TK_PG_URL = r.stdout.trim();
}
process.on('exit', () => {
    if (pgdir) {
        spawnSync('tests/pg.sh', ['stop', join(pgdir, 'server')]);
        rmSync(pgdir, { recursive: true, force: true });
    }
});
const { jobLines, jobRuns, pgDatabase, sleep, startDaemon, stopAll, submit, waitFinal } =
    await import('../tests/service/lib.mjs');

const args = ['--lease', String(LEASE), '--max-per-address', '1000'];

// ---- 1. three daemons, JOBS jobs, one killed
{
    const db = pgDatabase();
    const daemons = [];
    for (let k = 0; k < 3; k++) daemons.push(await startDaemon({ workers: 1, db, args }));
    const starts = ['3.1', '4.1', '5.1', '5.2'];
    const t0 = Date.now();
    const jobs = [];
    for (let i = 0; i < JOBS; i++)
        jobs.push(await submit(daemons[0], {
            catalogue: starts[i % starts.length], name: `job${i}`,
            options: { autoscale: true, resolution: 4, steps: 500 },
        }));
    const done = () => daemons.flatMap(jobLines).filter((l) => l.what.startsWith('done')).length;
    const victim = daemons[1];
    let target;
    while (!target) {
        await sleep(20);
        if (done() < JOBS / 3) continue;
        const lines = jobLines(victim);
        target = lines.find((s) => s.what.startsWith('running') &&
            !lines.some((l) => l.id === s.id && l !== s && l.ms >= s.ms));
    }
    await victim.kill();
    const killedAt = Date.now();
    const ends = [];
    for (const j of jobs) ends.push(await waitFinal(daemons[0], j.id, { timeout: 600000 }));
    const wall = (Date.now() - t0) / 1000;
    let twice = 0;
    const all = jobRuns(daemons, { 1: killedAt });
    for (const j of jobs) {
        const rs = all.filter((r) => r.id === j.id).sort((a, b) => a.from - b.from);
        for (let i = 1; i < rs.length; i++) if (rs[i].from < rs[i - 1].to) twice++;
    }
    const taken = all.find((r) => r.id === target.id && r.daemon !== 1);
    const finished = [0, 1, 2].map((k) => all.filter((r) => r.daemon === k && r.end.startsWith('done')).length);
    console.log(`three daemons, one worker each, one PostgreSQL database; ${JOBS} jobs ` +
        `(catalogue ${starts.join(', ')}; autoscale, resolution 4, 500 steps) submitted to daemon 0`);
    console.log(`  done: ${ends.filter((j) => j.state === 'done').length} of ${JOBS} in ${wall.toFixed(1)} s; ` +
        `finished by daemon 0, 1, 2: ${finished.join(', ')}; runs on two daemons at once: ${twice}`);
    console.log(`  daemon 1 killed (kill -9) while running job ${target.id}; lease ${LEASE} s; ` +
        `taken up by daemon ${taken.daemon} at step ${taken.step}, ` +
        `${((taken.from - killedAt) / 1000).toFixed(2)} s after the kill`);
    await stopAll(daemons[0], daemons[2]);
}

// ---- 2. polls through a daemon that runs nothing
{
    const db = pgDatabase();
    const runner = await startDaemon({ workers: 2, db, args });
    const ids = [];
    for (let k = 0; k < 2; k++)
        ids.push((await submit(runner, { catalogue: '10.1', options: { resolution: 5, time: 4 * WINDOW + 60, every: 1 } })).id);
    while (jobLines(runner).length < 2) await sleep(20);
    const idle = await startDaemon({ workers: 1, db, args });
    await sleep(3000); // the first stored frames
    console.log(`polling GET /v1/jobs/{id} with wrk, ${CONNECTIONS} connections, ${WINDOW} s, while ` +
        `daemon A runs two jobs (catalogue 10.1, resolution 5, a frame every step)`);
    console.log(`  ${'through'.padEnd(40)} ${'requests/s'.padStart(11)} ${'p50'.padStart(9)} ${'p99'.padStart(9)}`);
    for (const [name, d] of [['A (runs the jobs: live figures)', runner], ['B (runs nothing: from the store)', idle]]) {
        for (const paced of [false, true]) {
            const wrk = ['-t2', `-c${CONNECTIONS}`, `-d${WINDOW}s`, '--latency'];
            if (paced) wrk.push('-s', 'bench/paced.lua');
            wrk.push(`${d.base}v1/jobs/${ids[0]}`);
            if (paced) wrk.push('--', '100');
            // not execFileSync: a blocked event loop would miss the daemon
            // closing the client's idle connections meanwhile
            const { stdout: out } = await promisify(execFile)('wrk', wrk, { encoding: 'utf8' });
            const field = (re) => (re.exec(out) ?? [])[1] ?? '?';
            const label = `${name}${paced ? ', every 100 ms' : ', flat out'}`;
            console.log(`  ${label.padEnd(40)} ${field(/Requests\/sec:\s+(\S+)/).padStart(11)} ` +
                `${field(/\s50%\s+(\S+)/).padStart(9)} ${field(/\s99%\s+(\S+)/).padStart(9)}`);
        }
    }
    for (const id of ids) await runner.del(`/v1/jobs/${id}`);
    await stopAll(runner, idle);
}
