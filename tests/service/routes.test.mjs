// The route table (server/routes.c) against openapi.yaml: every operation
// of the contract has its row (method, path, operationId) and no row lacks
// one; an operation open to anyone (security: []) has a row that needs no
// token.  Read from the C source's rows, so a row added, dropped or renamed
// on either side fails here.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';

import { parse as parseYaml } from 'yaml';
import { ROOT } from './lib.mjs';

const METHODS = ['get', 'put', 'post', 'delete', 'options', 'head', 'patch', 'trace'];

// "METHOD PATH" -> { operationId, token } from the contract
function operations() {
    const spec = parseYaml(readFileSync(join(ROOT, 'openapi.yaml'), 'utf8'));
    const ops = new Map();
    for (const [path, item] of Object.entries(spec.paths))
        for (const method of METHODS) {
            const op = item[method];
            if (!op) continue;
            ops.set(`${method.toUpperCase()} ${path}`,
                { operationId: op.operationId, open: Array.isArray(op.security) && op.security.length === 0 });
        }
    return ops;
}

// the same from the table's rows: {"GET", "/v1/jobs", "listJobs", handler, token, job}
function rows() {
    const source = readFileSync(join(ROOT, 'server', 'routes.c'), 'utf8');
    const table = source.match(/static const route routes\[\] = \{([\s\S]*?)\n\};/);
    assert.ok(table, 'server/routes.c has no table "static const route routes[]"');
    const found = new Map();
    const row = /\{\s*"([A-Z]+)",\s*"([^"]+)",\s*"([A-Za-z]+)",\s*\w+,\s*(true|false),\s*(true|false)\s*\}/g;
    for (const m of table[1].matchAll(row)) {
        const key = `${m[1]} ${m[2]}`;
        assert.ok(!found.has(key), `two rows for ${key}`);
        found.set(key, { operationId: m[3], token: m[4] === 'true' });
    }
    assert.ok(found.size > 0, 'no rows read from the table');
    return found;
}

test('every operation of openapi.yaml has its row in the route table, and every row an operation', () => {
    const ops = operations();
    const table = rows();
    for (const [key, op] of ops) {
        assert.ok(table.has(key), `openapi.yaml's ${key} (${op.operationId}) has no row in server/routes.c`);
        assert.equal(table.get(key).operationId, op.operationId, `${key}: the row names another operation`);
    }
    for (const [key, row] of table)
        assert.ok(ops.has(key), `server/routes.c's row ${key} (${row.operationId}) is no operation of openapi.yaml`);
});

test('an operation open to anyone (security: []) needs no token in its row', () => {
    const ops = operations();
    const open = [...ops].filter(([, op]) => op.open);
    assert.ok(open.length > 0, 'openapi.yaml has no operation with security: []');
    for (const [key] of open)
        assert.equal(rows().get(key)?.token, false, `${key} is open in openapi.yaml but its row needs a token`);
});
