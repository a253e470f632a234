/* tightknot service: the store's PostgreSQL backend (see store_db.h): one
 * database shared by any number of daemons.  The parts and frames are
 * bytea, kept byte for byte, and the document is json, kept as written. */
#define _DEFAULT_SOURCE
#include "store_db.h"

#include <endian.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libpq-fe.h>

#include "store.h"

/* concurrent first starts of several daemons create the tables once; the
 * owner, until now only in the document, is read from there once */
#define PG_PART(E, col, n, sql) ", " #col " bytea" sql
static const char schema[] =
    "BEGIN; SELECT pg_advisory_xact_lock(" ADD_LOCK ");"
    "CREATE TABLE IF NOT EXISTS jobs (id bigserial PRIMARY KEY, state text NOT NULL,"
    " doc json NOT NULL" TK_PART_COLUMNS(PG_PART) ", holder text, lease timestamptz,"
    " cancel boolean NOT NULL DEFAULT false);"
    "ALTER TABLE jobs ADD COLUMN IF NOT EXISTS turn bigint NOT NULL DEFAULT 0;"
    "DO $$ BEGIN IF NOT EXISTS (SELECT 1 FROM information_schema.columns WHERE table_schema ="
    " current_schema() AND table_name = 'jobs' AND column_name = 'owner') THEN"
    " ALTER TABLE jobs ADD COLUMN owner text NOT NULL DEFAULT '';"
    " UPDATE jobs SET owner = coalesce(doc->>'owner', ''); END IF; END $$;"
    "CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);"
    "CREATE INDEX IF NOT EXISTS jobs_by_turn ON jobs (state, turn, id);"
    "CREATE INDEX IF NOT EXISTS jobs_by_owner ON jobs (owner, state, id);"
    "CREATE TABLE IF NOT EXISTS frames (job bigint NOT NULL REFERENCES jobs (id) ON DELETE"
    " CASCADE, seq bigint NOT NULL, step bigint NOT NULL, xyz bytea NOT NULL, layout text,"
    " PRIMARY KEY (job, seq));"
    "COMMIT;";

static void quiet(void *arg, const char *message)
{
    (void)arg; /* notices ("already exists, skipping") are not errors */
    (void)message;
}

static void *pg_connect(const char *where, const char *label, bool create, tk_error *err)
{
    (void)create;
    /* the URI comes last: what it says wins over these defaults */
    const char *const keys[] = {"connect_timeout", "application_name", "dbname", NULL};
    const char *const values[] = {"10", "tightknotd", where, NULL};
    PGconn *c = PQconnectdbParams(keys, values, 1);
    if (c && PQstatus(c) == CONNECTION_OK) {
        PQsetNoticeProcessor(c, quiet, NULL);
        return c;
    }
    const char *m = c ? PQerrorMessage(c) : "out of memory";
    tk_error_set(err, TK_EIO, "cannot reach the job store %s: %.*s", label,
                 (int)strcspn(m, "\n"), m);
    PQfinish(c);
    return NULL;
}

static void pg_disconnect(void *c)
{
    PQfinish(c);
}

static const char *pg_error(void *c)
{
    return PQerrorMessage(c);
}

static bool pg_script(void *c, const char *sql)
{
    PGresult *r = PQexec(c, sql);
    bool ok = PQresultStatus(r) == PGRES_COMMAND_OK || PQresultStatus(r) == PGRES_TUPLES_OK;
    PQclear(r);
    return ok;
}

static bool pg_run(void *c, rows *r, const char *sql, const params *p)
{
    int formats[MAX_PARAMS];
    Oid oids[MAX_PARAMS];
    for (int k = 0; k < p->n; k++) {
        char t = p->type[k];
        formats[k] = t == 'b' || t == 'x';
        oids[k] = t == 'i' ? 20 : t == 'd' ? 701 : t == 'j' ? 114 : formats[k] ? 17 : 25;
    }
    /* binary results: bytea as it is; int8 and bool made text below */
    PGresult *res = PQexecParams(c, sql, p->n, oids, p->value, p->length, formats, 1);
    ExecStatusType st = PQresultStatus(res);
    bool ok = st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK;
    r->ncol = ok ? (size_t)PQnfields(res) : 0;
    for (int i = 0; ok && i < PQntuples(res); i++)
        for (int j = 0; ok && j < (int)r->ncol; j++) {
            const char *v = PQgetisnull(res, i, j) ? NULL : PQgetvalue(res, i, j);
            size_t len = (size_t)PQgetlength(res, i, j);
            char text[32];
            uint64_t be;
            if (v && PQftype(res, j) == 20) { /* int8, big-endian */
                memcpy(&be, v, sizeof be);
                len = (size_t)snprintf(text, sizeof text, "%lld", (long long)be64toh(be));
                v = text;
            } else if (v && PQftype(res, j) == 16) { /* bool */
                v = v[0] ? "1" : "0";
            }
            ok = rows_add(r, (size_t)j, v, len);
        }
    r->changed = ok ? strtoull(PQcmdTuples(res), NULL, 10) : 0;
    PQclear(res);
    return ok;
}

/* A connection that broke (a lost server) is not used again. */
static bool pg_release(void *c)
{
    if (PQstatus(c) == CONNECTION_OK && PQtransactionStatus(c) != PQTRANS_IDLE)
        PQclear(PQexec(c, "ROLLBACK"));
    return PQstatus(c) == CONNECTION_OK && PQtransactionStatus(c) == PQTRANS_IDLE;
}

static bool pg_setup(void *c)
{
    return pg_script(c, schema);
}

/* A URI may carry a user's password (in its authority or its query), and
 * messages reach clients (health, problems) and logs: so only its host,
 * port and database. */
static void pg_label(const char *where, char *out, size_t size)
{
    PQconninfoOption *opts = PQconninfoParse(where, NULL);
    const char *host = NULL, *port = NULL, *db = NULL;
    for (PQconninfoOption *o = opts; o && o->keyword; o++) {
        const char **slot = !strcmp(o->keyword, "host")     ? &host
                            : !strcmp(o->keyword, "port")   ? &port
                            : !strcmp(o->keyword, "dbname") ? &db
                                                            : NULL;
        if (slot && o->val && o->val[0])
            *slot = o->val;
    }
    if (opts)
        snprintf(out, size, "PostgreSQL database '%.60s' on %.60s%s%.8s", db ? db : "(default)",
                 host ? host : "localhost", port ? ":" : "", port ? port : "");
    else
        snprintf(out, size, "PostgreSQL (its URI does not parse)");
    PQconninfoFree(opts);
}

#define B(c) "coalesce(octet_length(" c "), 0)"
#define DOC_BYTES "octet_length(doc::text)"
/* running renews the lease ($10 seconds) */
#define LEASE ", lease = CASE $1 WHEN 'running' THEN now() + make_interval(secs => $10) END"
const backend *tk_store_pg(void)
{
    /* A claim locks the row in the statement that makes it ours, skipping
     * rows another daemon is claiming or writing, and takes a job whose
     * lease ran out as well as a queued one; other daemons may be running
     * theirs at start (a dead daemon's are taken up when their leases run
     * out); the lock makes a submission's limits and insert one step
     * across daemons. */
    static const backend b = {
        pg_connect, pg_disconnect, pg_error, pg_script, pg_run, pg_release, pg_setup, pg_label,
        NULL,
        .claim = "UPDATE jobs SET state = 'running', holder = $1, lease = now() + make_interval("
                 "secs => $2) WHERE id = (SELECT id FROM jobs WHERE state = 'queued' OR (state ="
                 " 'running' AND lease < now()) ORDER BY turn, id LIMIT 1 FOR UPDATE SKIP LOCKED)"
                 " RETURNING id",
        .renew = "UPDATE jobs SET lease = now() + make_interval(secs => $3) WHERE id = $1 AND"
                 " state = 'running' AND holder = $2 RETURNING cancel",
        .requeue = NULL, .begin = "BEGIN", .lock = "SELECT pg_advisory_xact_lock(" ADD_LOCK ")",
        .add = SQL_ADD, .put = SQL_PUT, .owner_bytes = SQL_OWNER_BYTES("$1")};
    return &b;
}
