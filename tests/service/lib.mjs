// Shared helpers of the service tests: start and stop the real daemon, run
// the CLI, make requests whose JSON answers are all checked against the
// schemas of openapi.yaml, poll jobs, read VECT numbers.
//
// Environment:
//   TK_DAEMON     the daemon (default build/tightknotd)
//   TK_CLI        the command-line program (default build/tightknot)
//   TK_CATALOGUE  the catalogue directory (default ../shared/catalogue)
//   TK_PG_URL     a PostgreSQL server of the tests' own (tests/pg.sh), for
//                 the tests that need one
//   TK_STORE      "postgresql": every fresh daemon's store is a database of
//                 its own on that server (default: a SQLite file)
//   TK_WORKER_PRIORITY  every daemon's --worker-priority, unless a test
//                 gives its own (default: the daemon's, idle)
// Relative paths in the environment are taken from the current directory,
// the defaults from the repository root.

import { connect } from 'node:net';
import assert from 'node:assert/strict';
import { spawn, execFile, execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';

import Ajv2020 from 'ajv/dist/2020.js';
import addFormats from 'ajv-formats';
import { parse as parseYaml } from 'yaml';

const execFileP = promisify(execFile);

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const fromEnv = (name, dflt) =>
    process.env[name] ? resolve(process.cwd(), process.env[name]) : resolve(ROOT, dflt);
export const DAEMON = fromEnv('TK_DAEMON', 'build/tightknotd');
export const CLI = fromEnv('TK_CLI', 'build/tightknot');
export const CATALOGUE = fromEnv('TK_CATALOGUE', '../shared/catalogue');

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// ---------------------------------------------------------------- PostgreSQL

export const PG_URL = process.env.TK_PG_URL ?? '';
export const ON_PG = PG_URL !== '' && process.env.TK_STORE === 'postgresql';
// the lease of a daemon on PostgreSQL in these tests: a killed daemon's
// jobs are taken up this many seconds after its last renewal
export const PG_LEASE = 3;

// A new, empty database on the tests' server; its URI.
let databases = 0;
export function pgDatabase() {
    assert.ok(PG_URL, 'TK_PG_URL is not set (tests/pg.sh starts a server)');
    const name = `tk_${process.pid}_${++databases}`;
    execFileSync('psql', [PG_URL, '-qc', `CREATE DATABASE ${name}`]);
    return PG_URL.slice(0, PG_URL.lastIndexOf('/') + 1) + name;
}

// ---------------------------------------------------------------- temp dirs

const tempDirs = [];
export function tempDir(tag = 'tk') {
    const d = mkdtempSync(join(tmpdir(), `tk-service-${tag}-`));
    tempDirs.push(d);
    return d;
}
process.on('exit', () => {
    if (process.env.TK_KEEP_TMP) return;
    for (const d of tempDirs) rmSync(d, { recursive: true, force: true });
});

// ---------------------------------------------------------------- the contract

const spec = parseYaml(readFileSync(join(ROOT, 'openapi.yaml'), 'utf8'));
const SPEC_ID = 'https://tightknot.invalid/openapi.yaml';
const ajv = new Ajv2020({ allErrors: true, strict: true, allowUnionTypes: true });
addFormats(ajv);
// the root of the added document holds the components; it is never
// validated against itself
ajv.addKeyword('components');
ajv.addSchema({ $id: SPEC_ID, components: { schemas: spec.components.schemas } });

// '#/components/...' in an inline schema points into the spec
function rebase(schema) {
    if (Array.isArray(schema)) return schema.map(rebase);
    if (schema && typeof schema === 'object') {
        const out = {};
        for (const [k, v] of Object.entries(schema))
            out[k] = k === '$ref' && typeof v === 'string' && v.startsWith('#/') ? SPEC_ID + v : rebase(v);
        return out;
    }
    return schema;
}

function deref(obj) {
    while (obj && obj.$ref) {
        const parts = obj.$ref.replace(/^#\//, '').split('/');
        obj = parts.reduce((o, p) => o?.[p.replace(/~1/g, '/').replace(/~0/g, '~')], spec);
    }
    return obj;
}

// The spec's path template matching a concrete path, e.g. /v1/jobs/{id}.
function pathTemplate(path) {
    for (const template of Object.keys(spec.paths)) {
        const re = new RegExp('^' + template.replace(/\{[^}]+\}/g, '[^/]+') + '$');
        if (re.test(path)) return template;
    }
    return null;
}

const validators = new Map();
function validatorFor(key, schema) {
    let v = validators.get(key);
    if (!v) {
        v = ajv.compile(rebase(schema));
        validators.set(key, v);
    }
    return v;
}

// Checks a response against the contract: the status must be documented
// for the path and method (404/405 of unknown paths or methods are checked
// as problems), the media type must be one the spec lists, and a JSON body
// must match the schema.  Returns nothing; throws an AssertionError.
export function validateResponse(method, url, status, contentType, body) {
    const path = new URL(url, 'http://x').pathname;
    const media = (contentType || '').split(';')[0].trim().toLowerCase();
    const what = `${method} ${path} -> ${status} ${media}`;
    const template = pathTemplate(path);
    const op = template && spec.paths[template][method.toLowerCase()];
    let content;
    if (!op) {
        assert.ok(status === 404 || status === 405, `${what}: not in openapi.yaml`);
        content = { 'application/problem+json': { schema: { $ref: '#/components/schemas/Problem' } } };
    } else {
        const response = deref(op.responses[String(status)] ?? op.responses[`${String(status)[0]}XX`] ??
            op.responses.default);
        assert.ok(response, `${what}: status ${status} is not documented in openapi.yaml`);
        content = response.content ?? {};
    }
    if (status >= 400)
        assert.equal(media, 'application/problem+json', `${what}: errors must be problem+json`);
    if (status === 204) {
        // No Content: a documented 204 has no content, and the answer none
        assert.equal(Object.keys(content).length, 0, `${what}: a 204 documented with content`);
        assert.equal(media, '', `${what}: a 204 with a media type`);
        return;
    }
    const entry = content[media];
    assert.ok(entry, `${what}: media type not documented (documented: ${Object.keys(content)})`);
    if (!media.includes('json')) return;
    const validate = validatorFor(`${template} ${method} ${status} ${media}`, entry.schema);
    if (!validate(body))
        assert.fail(`${what}: body does not match openapi.yaml: ` +
            ajv.errorsText(validate.errors, { separator: '; ' }) +
            `\nbody: ${JSON.stringify(body).slice(0, 800)}`);
    if (status >= 400) assert.equal(body.status, status, `${what}: problem status member`);
}

// ---------------------------------------------------------------- requests

// One request; every answer is validated.  Options: body (string, Buffer,
// object = JSON, ReadableStream), type (Content-Type), headers, raw (skip
// JSON parsing).  Returns {status, headers, text, json, ms}.
export async function request(base, method, path, opts = {}) {
    const headers = { ...(opts.headers ?? {}) };
    let body = opts.body;
    if (body !== undefined && body !== null && typeof body === 'object' && !(body instanceof Uint8Array) &&
        !(body instanceof ReadableStream)) {
        body = JSON.stringify(body);
        headers['content-type'] ??= 'application/json';
    }
    if (opts.type) headers['content-type'] = opts.type;
    const init = { method, headers, body };
    // a hang fails the test instead of stalling the suite
    if (opts.timeout) init.signal = AbortSignal.timeout(opts.timeout);
    if (body instanceof ReadableStream) init.duplex = 'half';
    const t0 = performance.now();
    const res = await fetch(new URL(path, base), init);
    const text = await res.text();
    const ms = performance.now() - t0;
    const type = res.headers.get('content-type') ?? '';
    let json;
    if (/json/.test(type)) {
        try {
            json = JSON.parse(text);
        } catch (e) {
            assert.fail(`${method} ${path}: ${res.status} ${type} is not JSON: ${text.slice(0, 200)}`);
        }
    }
    validateResponse(method, path, res.status, type, json);
    return { status: res.status, headers: res.headers, text, json, ms };
}

// Numbers as the daemon wrote them: JSON.parse keeps every double exactly
// (both sides print 17 significant digits), so === compares bits.

// Sends `head` (a request line and headers, CRLF included) as raw bytes, so
// that paths reach the daemon exactly as written; resolves to the status,
// the headers as one string, the body, and the whole answer (text).
export function raw(port, head) {
    return new Promise((resolve, reject) => {
        const s = connect(port, '127.0.0.1');
        let data = '';
        s.setEncoding('latin1');
        s.setTimeout(10000, () => {
            s.destroy();
            reject(new Error(`no answer in 10 s to ${JSON.stringify(head.slice(0, 80))}`));
        });
        s.on('data', (d) => (data += d));
        s.on('error', reject);
        s.on('end', () => {
            const m = /^HTTP\/1\.[01] (\d{3})/.exec(data);
            const split = data.indexOf('\r\n\r\n');
            resolve({
                status: m ? Number(m[1]) : 0,
                headers: split >= 0 ? data.slice(0, split) : data,
                body: split >= 0 ? data.slice(split + 4) : '',
                text: data,
            });
        });
        s.write(head);
    });
}

// ---------------------------------------------------------------- the daemon

// Daemons still running when the test process exits (a test failed before
// stopping its daemon) are killed, never left behind.
const live = new Set();
process.on('exit', () => {
    for (const p of live) p.kill('SIGKILL');
});

// Starts the daemon on a free port with a fresh store (or `db`).  Returns
// {base, port, db, dir, proc, output(), stop(), kill()}.
export async function startDaemon(o = {}) {
    const dir = o.dir ?? tempDir('daemon');
    const db = o.db ?? (ON_PG ? pgDatabase() : join(dir, 'jobs.db'));
    const args = ['--port', '0', '--db', db, '--catalogue', CATALOGUE];
    if (db.startsWith('postgresql://') && !(o.args ?? []).includes('--lease'))
        args.push('--lease', String(PG_LEASE));
    if (o.workers) args.push('--workers', String(o.workers));
    if (o.queueLimit) args.push('--queue-limit', String(o.queueLimit));
    if (o.maxBody) args.push('--max-body', String(o.maxBody));
    // run-all.sh runs the unit tests beside the suites at the lowest
    // niceness, and the daemon's idle workers would wait on them:
    // TK_WORKER_PRIORITY (normal there) unless the test sets its own or
    // wants the default (priority: null)
    const priority = o.priority === undefined ? process.env.TK_WORKER_PRIORITY : o.priority;
    if (priority && !(o.args ?? []).includes('--worker-priority')) args.push('--worker-priority', priority);
    args.push(...(o.args ?? []));
    const proc = spawn(DAEMON, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    live.add(proc);
    proc.on('exit', () => live.delete(proc));
    let out = '', err = '';
    proc.stdout.setEncoding('utf8').on('data', (d) => (out += d));
    proc.stderr.setEncoding('utf8').on('data', (d) => (err += d));
    const exited = new Promise((r) => proc.on('exit', (code, signal) => r({ code, signal })));
    const port = await new Promise((res, rej) => {
        const timer = setTimeout(() => rej(new Error(`daemon did not start in 10 s: ${out}${err}`)), 10000);
        const check = () => {
            const first = out.split('\n')[0];
            const m = /^tightknotd: \S+ listening on http:\/\/127\.0\.0\.1:(\d+)\/ /.exec(first);
            if (m && out.includes('\n')) {
                clearTimeout(timer);
                res(Number(m[1]));
            } else if (out.includes('\n')) {
                clearTimeout(timer);
                rej(new Error(`unexpected first line: ${first}`));
            }
        };
        proc.stdout.on('data', check);
        exited.then(({ code, signal }) => {
            clearTimeout(timer);
            rej(new Error(`daemon exited (${code ?? signal}) before listening: ${out}${err}`));
        });
    });
    assert.ok(port > 0 && port < 65536);
    const d = {
        base: `http://127.0.0.1:${port}/`,
        port,
        db,
        dir,
        proc,
        exited,
        output: () => out + err,
        get: (path, opts) => request(d.base, 'GET', path, opts),
        post: (path, body, opts = {}) => request(d.base, 'POST', path, { ...opts, body }),
        del: (path, opts) => request(d.base, 'DELETE', path, opts),
        req: (method, path, opts) => request(d.base, method, path, opts),
        // SIGTERM; the daemon must exit 0 within 10 s.  Returns the seconds taken.
        async stop() {
            if (proc.exitCode !== null || proc.signalCode !== null) return 0;
            const t0 = performance.now();
            proc.kill('SIGTERM');
            let timer;
            const r = await Promise.race([exited, new Promise((res) => (timer = setTimeout(res, 10000, null)))]);
            clearTimeout(timer);
            if (!r) {
                proc.kill('SIGKILL');
                assert.fail(`daemon did not exit within 10 s of SIGTERM:\n${out}${err}`);
            }
            assert.equal(r.code, 0, `daemon exit status after SIGTERM (signal ${r.signal}):\n${out}${err}`);
            return (performance.now() - t0) / 1000;
        },
        async kill() {
            proc.kill('SIGKILL');
            const r = await exited;
            assert.equal(r.signal, 'SIGKILL');
        },
    };
    return d;
}

// The daemon's job lines: [{ms, id, what}] ("running from step S", "done
// at step S", "taken up elsewhere: let go at step S", ...).
export function jobLines(d) {
    const out = [];
    for (const line of d.output().split('\n')) {
        const m = /^tightknotd: (\S+Z) job (\d+): (.*)$/.exec(line);
        if (m) out.push({ ms: Date.parse(m[1]), id: Number(m[2]), what: m[3] });
    }
    return out;
}

// Each daemon's runs of each job: [{daemon, id, from, to, step}], `to` the
// time of its end line, or `killedAt` for a run that was under way.
export function jobRuns(daemons, killedAt) {
    const all = [];
    daemons.forEach((d, k) => {
        const open = new Map();
        for (const l of jobLines(d)) {
            const m = /^running from step (\d+)$/.exec(l.what);
            if (m) {
                assert.ok(!open.has(l.id), `daemon ${k} took up job ${l.id} while running it`);
                open.set(l.id, { daemon: k, id: l.id, from: l.ms, step: Number(m[1]) });
            } else {
                const r = open.get(l.id);
                assert.ok(r, `daemon ${k} ended job ${l.id} it was not running: ${l.what}`);
                all.push({ ...r, to: l.ms, end: l.what });
                open.delete(l.id);
            }
        }
        for (const r of open.values()) {
            assert.ok(killedAt[k] !== undefined, `daemon ${k} left job ${r.id} running`);
            all.push({ ...r, to: killedAt[k], end: 'killed' });
        }
    });
    return all;
}

// Stops every daemon given, ignoring those already gone (for after()).
export async function stopAll(...daemons) {
    for (const d of daemons) if (d) await d.stop();
}

// ---------------------------------------------------------------- jobs

// Submits and asserts 202; returns the job.
export async function submit(d, body, opts = {}) {
    const r = opts.query !== undefined || typeof body === 'string'
        ? await d.post(`/v1/jobs${opts.query ? '?' + opts.query : ''}`, body, { type: 'text/plain' })
        : await d.post('/v1/jobs', body);
    assert.equal(r.status, 202, `submit: ${r.text}`);
    assert.equal(r.headers.get('location'), `/v1/jobs/${r.json.id}`);
    assert.equal(r.json.state, 'queued');
    return r.json;
}

// Polls GET /v1/jobs/{id} until pred(job) holds; returns the job.  The
// wait is long: under the thread sanitizer, beside the browser's suite on
// two cores, a job's steps run several times slower than alone (3.1 at
// resolution 10: 300 steps in 11 s), and a wait is not a test of speed.
export async function waitJob(d, id, pred, { timeout = 120000, every = 50, what = 'condition' } = {}) {
    const t0 = Date.now();
    let job;
    for (;;) {
        const r = await d.get(`/v1/jobs/${id}`);
        assert.equal(r.status, 200);
        job = r.json;
        if (pred(job)) return job;
        if (Date.now() - t0 > timeout)
            assert.fail(`job ${id}: ${what} not reached in ${timeout} ms; last: ${JSON.stringify(job)}`);
        await sleep(every);
    }
}

export const FINAL = new Set(['done', 'failed', 'cancelled']);
export const waitFinal = (d, id, o = {}) => waitJob(d, id, (j) => FINAL.has(j.state), { what: 'a final state', ...o });

// ---------------------------------------------------------------- the CLI

export async function cli(args, opts = {}) {
    const { stdout } = await execFileP(CLI, args, { maxBuffer: 64 << 20, ...opts });
    return stdout;
}

// Writes `tightknot generate ...` into dir; returns {path, text}.
export async function generate(dir, name, args) {
    const text = await cli(['generate', ...args]);
    const path = join(dir, name);
    writeFileSync(path, text);
    return { path, text };
}

// Runs `tightknot tighten` with the given options into dir; returns
// {summary (the --json object), vect (text of -o), struts (the --struts object)}.
export async function tighten(dir, input, tag, options) {
    const out = join(dir, `${tag}.out.vect`);
    const struts = join(dir, `${tag}.struts.json`);
    const stdout = await cli(['tighten', input, ...options, '--json', '-o', out, '--struts', struts]);
    return {
        summary: JSON.parse(stdout),
        vect: readFileSync(out, 'utf8'),
        struts: JSON.parse(readFileSync(struts, 'utf8')),
    };
}

// ---------------------------------------------------------------- VECT

// The numbers of a VECT text after the header word, comments dropped.
export function vectNumbers(text) {
    const tokens = text.replace(/#[^\n]*/g, '').split(/\s+/).filter(Boolean);
    assert.equal(tokens[0], 'VECT');
    return tokens.slice(1).map(Number);
}

// {ncomp, nvert, counts, xyz} of a VECT text without colours.
export function vectCoordinates(text) {
    const n = vectNumbers(text);
    const [ncomp, nvert, ncol] = n;
    const counts = n.slice(3, 3 + ncomp);
    const xyz = n.slice(3 + 2 * ncomp, 3 + 2 * ncomp + 3 * nvert);
    assert.equal(xyz.length, 3 * nvert);
    return { ncomp, nvert, ncol, counts, xyz };
}
