// Worker threads: named tk-worker, one per --workers, and scheduled as
// --worker-priority says (read back from /proc, Linux).

import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { readdirSync, readFileSync } from 'node:fs';
import { describe, test } from 'node:test';

import { DAEMON, startDaemon, tempDir } from './lib.mjs';

const SCHED_OTHER = 0;
const SCHED_IDLE = 5;

// The daemon's threads: name, scheduling policy and niceness of each.
function threads(pid) {
    return readdirSync(`/proc/${pid}/task`).map((tid) => {
        const stat = readFileSync(`/proc/${pid}/task/${tid}/stat`, 'utf8');
        const name = stat.slice(stat.indexOf('(') + 1, stat.lastIndexOf(')'));
        // fields from the third on, after the name's closing parenthesis
        const fields = stat.slice(stat.lastIndexOf(')') + 2).trim().split(/\s+/);
        return { name, nice: Number(fields[19 - 3]), policy: Number(fields[41 - 3]) };
    });
}

const workers = (pid) => threads(pid).filter((t) => t.name === 'tk-worker');

describe('worker threads', { skip: process.platform !== 'linux' && 'needs /proc' }, () => {
    test('by default 3 workers run under SCHED_IDLE, and no other thread does', async () => {
        const d = await startDaemon({ workers: 3, priority: null });
        try {
            const all = threads(d.proc.pid);
            const pool = all.filter((t) => t.name === 'tk-worker');
            assert.equal(pool.length, 3);
            for (const t of pool) assert.equal(t.policy, SCHED_IDLE);
            for (const t of all.filter((t) => t.name !== 'tk-worker')) {
                assert.equal(t.policy, SCHED_OTHER, `thread ${t.name}`);
                assert.equal(t.nice, 0, `thread ${t.name}`);
            }
        } finally {
            await d.stop();
        }
    });

    for (const [priority, nice] of [['low', 5], ['normal', 0]]) {
        test(`--worker-priority ${priority}: SCHED_OTHER at niceness ${nice}`, async () => {
            const d = await startDaemon({ workers: 2, args: ['--worker-priority', priority] });
            try {
                const pool = workers(d.proc.pid);
                assert.equal(pool.length, 2);
                for (const t of pool) assert.deepEqual([t.policy, t.nice], [SCHED_OTHER, nice]);
            } finally {
                await d.stop();
            }
        });
    }

    test('an unknown --worker-priority is refused with exit 1 and says which values exist', async () => {
        const dir = tempDir('priority');
        const proc = spawn(DAEMON, ['--port', '0', '--db', `${dir}/jobs.db`, '--worker-priority', 'fast'],
            { stdio: ['ignore', 'pipe', 'pipe'] });
        let err = '';
        proc.stderr.setEncoding('utf8').on('data', (s) => (err += s));
        const code = await new Promise((r) => proc.on('exit', r));
        assert.equal(code, 1);
        assert.match(err, /--worker-priority: 'fast' is not idle, low or normal/);
    });
});
