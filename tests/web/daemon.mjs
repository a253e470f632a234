// Starts the real daemon for the page's browser tests: on a free port, with
// a fresh database in a temporary directory, serving the built page.
//
// Environment (relative paths from the current directory; the defaults
// from the repository root):
//   TK_DAEMON     the daemon (default build/tightknotd)
//   TK_CATALOGUE  the catalogue directory (default ../shared/catalogue)
//   TK_WEB        the built page (default build/web, see tools/build-web.sh)
//   TK_WORKER_PRIORITY  the daemon's --worker-priority (default its own)

import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const fromEnv = (name, dflt) =>
    process.env[name] ? resolve(process.cwd(), process.env[name]) : resolve(ROOT, dflt);
export const DAEMON = fromEnv('TK_DAEMON', 'build/tightknotd');
export const CATALOGUE = fromEnv('TK_CATALOGUE', '../shared/catalogue');
export const WEB = fromEnv('TK_WEB', 'build/web');
export const ARTIFACTS = join(ROOT, 'test-artifacts', 'web');

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Resolves to { base, stop }: base is the daemon's http://host:port, and
// stop() ends it and removes its directory.  `extra`: more options.
export async function startDaemon(extra = []) {
    const tmp = mkdtempSync(join(tmpdir(), 'tk-web-'));
    const args = ['--port', '0', '--db', join(tmp, 'jobs.db'), '--catalogue', CATALOGUE, '--web', WEB, '--workers', '2',
        ...extra];
    // beside the unit tests at the lowest niceness (run-all.sh), workers
    // of the default, idle, priority would wait on them
    if (process.env.TK_WORKER_PRIORITY && !extra.includes('--worker-priority'))
        args.push('--worker-priority', process.env.TK_WORKER_PRIORITY);
    const daemon = spawn(DAEMON, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    const stop = async () => {
        if (daemon.exitCode === null && daemon.signalCode === null) {
            const gone = new Promise((r) => daemon.on('exit', r));
            daemon.kill('SIGTERM');
            await Promise.race([gone, sleep(10000)]);
            if (daemon.exitCode === null && daemon.signalCode === null) daemon.kill('SIGKILL');
        }
        rmSync(tmp, { recursive: true, force: true });
    };
    let stderr = '';
    daemon.stderr.on('data', (d) => { stderr += d; });
    try {
        const base = await new Promise((resolveUrl, reject) => {
            let out = '';
            const timer = setTimeout(() => reject(new Error(`the daemon did not start: ${stderr}`)), 15000);
            daemon.stdout.on('data', (d) => {
                out += d;
                const m = /(http:\/\/[^\s/]+)/.exec(out.split('\n')[0] || '');
                if (m && out.includes('\n')) { clearTimeout(timer); resolveUrl(m[1]); }
            });
            daemon.on('exit', (code) => { clearTimeout(timer); reject(new Error(`the daemon exited (${code}): ${stderr}`)); });
        });
        return { base, stop };
    } catch (e) {
        await stop();
        throw e;
    }
}

// fetch() against the daemon; the body parsed when it is JSON.
export async function api(base, path, init) {
    const res = await fetch(base + path, init);
    const body = (res.headers.get('content-type') || '').includes('json') ? await res.json() : await res.text();
    return { status: res.status, body };
}
