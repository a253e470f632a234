/* tightknot service: the job store (see store.h), on SQLite or on
 * PostgreSQL.  Every operation is written once, as SQL run through two
 * primitives (query, script) that speak to either library; a statement
 * has a text of each backend's only where their dialects differ.
 *
 * Each call takes a connection of its own (kept for reuse), so requests
 * and workers never wait for each other here: SQLite's WAL lets readers
 * go on beside the one writer, PostgreSQL's row locks do the rest.  On
 * PostgreSQL the parts and frames are bytea, kept byte for byte, and the
 * document is json, kept as written. */
#define _DEFAULT_SOURCE
#include "store.h"

#include <assert.h>
#include <endian.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#include <libpq-fe.h>
#include <sqlite3.h>

#include "jsonmap.h"

#define IDLE_MAX 32 /* connections kept for reuse; more are opened while needed */
/* On a shared store the documents last read are served again for a
 * moment: a daemon that runs nothing answers a crowd of pollers of a job
 * running elsewhere from memory, not with a query each (the job's own
 * daemon writes it only every 2 s anyway).  Any write through this store
 * drops them all, so a client sees its own DELETE at once. */
#define RECENT_MAX 64   /* documents kept, one slot per id modulo this */
#define RECENT_AGE 0.5  /* seconds a kept document is served again */
#define MAX_PARAMS 10
/* the advisory lock that makes a submission's limits and insert one step
 * across daemons (any number no other program on the database uses) */
#define ADD_LOCK "7310519"

struct tk_store {
    bool pg; /* PostgreSQL: shared with other daemons */
    double lease;
    char *where;
    char label[200]; /* where, as messages name it: never a password */
    char holder[96];
    pthread_mutex_t lock; /* guards what follows; never held over a statement */
    void *idle[IDLE_MAX];
    size_t nidle;
    char write_error[TK_ERROR_MESSAGE_SIZE]; /* the last write's failure, "" once one succeeds */
    char damage[TK_ERROR_MESSAGE_SIZE];      /* the first damage a reader found */
    uint64_t writes; /* writes through this store so far */
    struct kept {
        int64_t id;
        uint64_t writes; /* the count when it was read: stale once another write came */
        double at;       /* when it was read (monotonic seconds) */
        json_t *doc;     /* never handed out: copies are */
    } recent[RECENT_MAX];
};

/* ---- the SQL: [0] SQLite's, [1] PostgreSQL's ---- */

static const char *const schema[2] = {
    "CREATE TABLE IF NOT EXISTS jobs (id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " state TEXT NOT NULL, doc TEXT NOT NULL, input TEXT NOT NULL, curve TEXT, contacts TEXT,"
    " history TEXT, resume TEXT, holder TEXT, cancel INTEGER NOT NULL DEFAULT 0,"
    " turn INTEGER NOT NULL DEFAULT 0);"
    "CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);"
    "CREATE TABLE IF NOT EXISTS frames (job INTEGER NOT NULL REFERENCES jobs (id) ON DELETE"
    " CASCADE, seq INTEGER NOT NULL, step INTEGER NOT NULL, xyz BLOB NOT NULL, layout TEXT,"
    " PRIMARY KEY (job, seq));",
    /* concurrent first starts of several daemons create the tables once */
    "BEGIN; SELECT pg_advisory_xact_lock(" ADD_LOCK ");"
    "CREATE TABLE IF NOT EXISTS jobs (id bigserial PRIMARY KEY, state text NOT NULL,"
    " doc json NOT NULL, input bytea NOT NULL, curve bytea, contacts bytea, history bytea,"
    " resume bytea, holder text, lease timestamptz, cancel boolean NOT NULL DEFAULT false);"
    "ALTER TABLE jobs ADD COLUMN IF NOT EXISTS turn bigint NOT NULL DEFAULT 0;"
    "CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);"
    "CREATE INDEX IF NOT EXISTS jobs_by_turn ON jobs (state, turn, id);"
    "CREATE TABLE IF NOT EXISTS frames (job bigint NOT NULL REFERENCES jobs (id) ON DELETE"
    " CASCADE, seq bigint NOT NULL, step bigint NOT NULL, xyz bytea NOT NULL, layout text,"
    " PRIMARY KEY (job, seq));"
    "COMMIT;"};

/* A store of the first version (SQLite) kept a job's fields in columns
 * of their own: each row becomes a document, in one transaction. */
static const char upgrade[] =
    "BEGIN; CREATE TABLE jobs_doc (id INTEGER PRIMARY KEY AUTOINCREMENT, state TEXT NOT NULL,"
    " doc TEXT NOT NULL, input TEXT NOT NULL, curve TEXT, contacts TEXT, history TEXT,"
    " resume TEXT);"
    "INSERT INTO jobs_doc SELECT id, state, json_object('name', name, 'state', state,"
    " 'options', json(options), 'progress', json_object('step', step, 'fraction', fraction),"
    " 'step', step, 'seconds', seconds, 'ropelength', ropelength, 'length', length,"
    " 'thickness', thickness, 'minrad', minrad, 'residual', residual, 'struts', struts,"
    " 'kinks', kinks, 'step_size', step_size, 'rcond', rcond, 'violation', violation,"
    " 'corrections', corrections, 'vertices', vertices, 'escapes', 0, 'components', components,"
    " 'frames', frames, 'stop_reason', nullif(stop_reason, ''), 'error', nullif(error, ''),"
    " 'invariants', json(invariants), 'created', strftime('%Y-%m-%dT%H:%M:%fZ', created,"
    " 'unixepoch'), 'started', strftime('%Y-%m-%dT%H:%M:%fZ', started, 'unixepoch'),"
    " 'finished', strftime('%Y-%m-%dT%H:%M:%fZ', finished, 'unixepoch')),"
    " input, curve, contacts, history, resume FROM jobs;"
    "DROP TABLE jobs; ALTER TABLE jobs_doc RENAME TO jobs; COMMIT;";

/* The bytes stored for owner P's jobs, frames included (DOC and
 * B(column) the sizes in bytes). */
#define OWNER_BYTES(DOC, B, P)                                                                  \
    "SELECT coalesce(sum(" DOC " + " B("input") " + " B("curve") " + " B("contacts") " + "      \
    B("history") " + " B("resume") " + (SELECT coalesce(sum(length(xyz)), 0) FROM frames"       \
    " WHERE job = jobs.id)), 0) FROM jobs WHERE doc->>'owner' = " P
#define SQ_BYTES(c) "coalesce(length(CAST(" c " AS BLOB)), 0)"
#define PG_BYTES(c) "coalesce(octet_length(" c "), 0)"
#define SQ_OWNER_BYTES(P) OWNER_BYTES(SQ_BYTES("doc"), SQ_BYTES, P)
#define PG_OWNER_BYTES(P) OWNER_BYTES("octet_length(doc::text)", PG_BYTES, P)
/* (bigint: PostgreSQL's sum of bigints is numeric, which vquery does not read) */
static const char *const owner_bytes_sql[2] = {"SELECT CAST((" SQ_OWNER_BYTES("$1") ") AS bigint)",
                                               "SELECT CAST((" PG_OWNER_BYTES("$1") ") AS bigint)"};

/* The limits and the insert in one statement: two requests cannot both
 * take the last place ($1 doc, $2 input, $3 queue, $4 owner, $5 its
 * jobs, $6 its bytes).  The job's turn in the queue is one past the
 * latest of its owner's jobs waiting or running, or past the newest
 * running job's when it has none: each owner's k-th waiting job has the
 * k-th turn from now, so owners take turns (round robin) however many
 * jobs one of them queues.  MAX and SAME are the dialects' words. */
#define ADD(BYTES, MAX, SAME)                                                                   \
    "INSERT INTO jobs (state, doc, input, turn) SELECT 'queued', $1, $2, 1 + " MAX "((SELECT"   \
    " coalesce(max(turn), 0) FROM jobs WHERE state = 'running'), (SELECT coalesce(max(turn), 0)" \
    " FROM jobs WHERE state IN ('queued', 'running') AND doc->>'owner' " SAME " $4))"           \
    " WHERE (SELECT count(*) FROM jobs WHERE state = 'queued') < $3"                            \
    " AND ($4 IS NULL OR $5 = 0 OR (SELECT count(*) FROM jobs WHERE state IN ('queued',"         \
    " 'running') AND doc->>'owner' = $4) < $5)"                                                 \
    " AND ($4 IS NULL OR $6 = 0 OR (" BYTES ") < $6) RETURNING id"
static const char *const add_sql[2] = {ADD(SQ_OWNER_BYTES("$4"), "max", "IS"),
                                       ADD(PG_OWNER_BYTES("$4"), "greatest", "IS NOT DISTINCT FROM")};

/* A state other than running lets go of the job (on PostgreSQL, running
 * renews its lease: $10 seconds). */
#define PUT(LEASE)                                                                              \
    "UPDATE jobs SET state = $1, doc = $2, input = coalesce($3, input),"                        \
    " curve = coalesce($4, curve), contacts = coalesce($5, contacts),"                          \
    " history = coalesce($6, history), resume = coalesce($7, resume),"                          \
    " holder = CASE $1 WHEN 'running' THEN holder END" LEASE " WHERE id = $8 AND holder = $9"
static const char *const put_sql[2] = {
    PUT(""), PUT(", lease = CASE $1 WHEN 'running' THEN now() + make_interval(secs => $10) END")};

static const char *const cancel_sql[2] = {
    "UPDATE jobs SET state = 'cancelled', doc = json_set(doc, '$.stop_reason', 'cancelled',"
    " '$.finished', strftime('%Y-%m-%dT%H:%M:%fZ')) WHERE id = $1 AND state = 'queued'",
    "UPDATE jobs SET state = 'cancelled', doc = (doc::jsonb || jsonb_build_object("
    "'stop_reason', 'cancelled', 'finished', to_char(now() AT TIME ZONE 'UTC',"
    " 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"')))::json WHERE id = $1 AND state = 'queued'"};

/* SQLite: one daemon per file, so its running jobs at start are what a
 * stop or a crash left.  PostgreSQL: other daemons may be running
 * theirs; a dead daemon's are taken up when their leases run out. */
static const char *const requeue_sql[2] = {
    "UPDATE jobs SET state = 'queued', holder = NULL WHERE state = 'running'", NULL};

/* The claim takes the job of the earliest turn (ADD), the oldest of
 * equal turns.  On PostgreSQL it locks the row in the statement that
 * makes it ours, skipping rows another daemon is claiming or writing,
 * and takes a job whose lease ran out as well as a queued one. */
static const char *const claim_sql[2] = {
    "UPDATE jobs SET state = 'running', holder = $1 WHERE id = (SELECT id FROM jobs"
    " WHERE state = 'queued' ORDER BY turn, id LIMIT 1) RETURNING id",
    "UPDATE jobs SET state = 'running', holder = $1, lease = now() + make_interval(secs => $2)"
    " WHERE id = (SELECT id FROM jobs WHERE state = 'queued' OR (state = 'running' AND lease"
    " < now()) ORDER BY turn, id LIMIT 1 FOR UPDATE SKIP LOCKED) RETURNING id"};

/* SQLite: the holder is always this store while it runs, and only
 * cancellation is news. */
static const char *const renew_sql[2] = {
    "SELECT cancel FROM jobs WHERE id = $1 AND state = 'running' AND holder = $2",
    "UPDATE jobs SET lease = now() + make_interval(secs => $3) WHERE id = $1 AND state ="
    " 'running' AND holder = $2 RETURNING cancel"};

static const char *const begin_sql[2] = {"BEGIN IMMEDIATE", "BEGIN"};
static const char *const lock_sql[2] = {NULL, "SELECT pg_advisory_xact_lock(" ADD_LOCK ")"};

#define MATCHING                                                                                \
    " FROM jobs WHERE ($1 IS NULL OR state = $1) AND ($2 IS NULL OR doc->>'owner' = $2)"

/* the parts' columns, in tk_part's order */
static const char *const part_columns[TK_PARTS] = {"input", "curve", "contacts", "history",
                                                   "resume"};
_Static_assert(TK_PARTS == 5, "tk_store_put writes the parts in one statement: name them there");

/* ---- the two libraries ---- */

/* A result: n rows of ncol cells, each a NUL-terminated copy (NULL for a
 * SQL null), and the rows a change touched. */
typedef struct rows {
    size_t n, ncol, changed;
    char **cell;
    size_t *len;
} rows;

static void rows_free(rows *r)
{
    for (size_t k = 0; r->cell && k < r->n * r->ncol; k++)
        free(r->cell[k]);
    free(r->cell);
    free(r->len);
    *r = (rows){0};
}

/* Sets cell j of the last row (j 0 begins a new one) to a copy of p;
 * false when out of memory. */
static bool add_cell(rows *r, size_t j, const void *p, size_t len)
{
    if (j == 0) {
        size_t m = (r->n + 1) * r->ncol;
        char **cell = realloc(r->cell, m * sizeof *cell);
        r->cell = cell ? cell : r->cell;
        size_t *lens = cell ? realloc(r->len, m * sizeof *lens) : NULL;
        if (!lens)
            return false;
        r->len = lens;
        memset(r->cell + r->n * r->ncol, 0, r->ncol * sizeof *r->cell);
        r->n++;
    }
    size_t k = (r->n - 1) * r->ncol + j;
    r->len[k] = len;
    if (p && (r->cell[k] = malloc(len + 1)) != NULL) {
        memcpy(r->cell[k], p, len);
        r->cell[k][len] = '\0';
    }
    return !p || r->cell[k];
}

static const char *cell(const rows *r, size_t i, size_t j)
{
    return r->cell[i * r->ncol + j];
}

static int64_t int_at(const rows *r, size_t i, size_t j)
{
    return cell(r, i, j) ? strtoll(cell(r, i, j), NULL, 10) : 0;
}

/* Takes cell (i, j) out of r. */
static char *steal(rows *r, size_t i, size_t j)
{
    char *p = r->cell[i * r->ncol + j];
    r->cell[i * r->ncol + j] = NULL;
    return p;
}

static void quiet(void *arg, const char *message)
{
    (void)arg; /* notices ("already exists, skipping") are not errors */
    (void)message;
}

/* A connection to the store (flags: SQLite's for a file not there yet). */
static void *connect_to(const tk_store *s, int flags, tk_error *err)
{
    const char *m = "out of memory";
    if (s->pg) {
        /* the URI comes last: what it says wins over these defaults */
        const char *const keys[] = {"connect_timeout", "application_name", "dbname", NULL};
        const char *const values[] = {"10", "tightknotd", s->where, NULL};
        PGconn *c = PQconnectdbParams(keys, values, 1);
        if (c && PQstatus(c) == CONNECTION_OK) {
            PQsetNoticeProcessor(c, quiet, NULL);
            return c;
        }
        m = c ? PQerrorMessage(c) : m;
        tk_error_set(err, TK_EIO, "cannot reach the job store %s: %.*s", s->label,
                     (int)strcspn(m, "\n"), m);
        PQfinish(c);
        return NULL;
    }
    sqlite3 *db = NULL;
    int rc = sqlite3_open_v2(s->where, &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX | flags,
                             NULL);
    /* NORMAL keeps every committed transaction across a crash of the
     * process (kill -9), the failure the store must survive */
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(db, "PRAGMA foreign_keys=ON; PRAGMA synchronous=NORMAL;", NULL, NULL,
                          NULL);
    if (rc == SQLITE_OK) {
        sqlite3_busy_timeout(db, 10000);
        return db;
    }
    tk_error_set(err, TK_EIO, "cannot set up the job store %s: %s", s->label,
                 db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
    sqlite3_close_v2(db);
    return NULL;
}

static void disconnect(const tk_store *s, void *c)
{
    if (s->pg)
        PQfinish(c);
    else
        sqlite3_close_v2(c);
}

/* The connection's last error, on one line, as TK_EIO. */
static int failed(const tk_store *s, void *c, tk_error *err, const char *what)
{
    const char *m = s->pg ? PQerrorMessage(c) : sqlite3_errmsg(c);
    size_t n = strcspn(m, "\n");
    return tk_error_set(err, TK_EIO, "job store: %s: %.*s", what, (int)n, n ? m : "no answer");
}

/* Statements without parameters whose results are not needed (NULL:
 * none for this backend); whether they ran. */
static bool script(const tk_store *s, void *c, const char *sql)
{
    if (!sql)
        return true;
    if (!s->pg)
        return sqlite3_exec(c, sql, NULL, NULL, NULL) == SQLITE_OK;
    PGresult *r = PQexec(c, sql);
    bool ok = PQresultStatus(r) == PGRES_COMMAND_OK || PQresultStatus(r) == PGRES_TUPLES_OK;
    PQclear(r);
    return ok;
}

/* Runs a statement (NULL: none for this backend) whose parameters $1,
 * $2, ... are given by `types`: i int64, d double, t text (NULL: null),
 * j JSON text, x text kept as bytes (bytea on PostgreSQL), b bytes
 * (pointer and size_t length).  Its rows go to *out when not NULL.
 * Whether it ran (the connection's error says why not). */
static bool vquery(const tk_store *s, void *c, rows *out, const char *sql, const char *types,
                   va_list ap)
{
    rows mine = {0}, *r = out ? out : &mine;
    *r = (rows){0};
    assert(strlen(types) <= MAX_PARAMS);
    if (!sql)
        return true;
    const char *values[MAX_PARAMS];
    int lengths[MAX_PARAMS] = {0}, formats[MAX_PARAMS] = {0};
    Oid oids[MAX_PARAMS];
    char numbers[MAX_PARAMS][32];
    int64_t ints[MAX_PARAMS];
    double reals[MAX_PARAMS];
    int n = 0;
    for (; types[n] && n < MAX_PARAMS; n++) {
        char t = types[n];
        values[n] = numbers[n];
        if (t == 'i') {
            ints[n] = va_arg(ap, int64_t);
            snprintf(numbers[n], sizeof numbers[n], "%lld", (long long)ints[n]);
        } else if (t == 'd') {
            reals[n] = va_arg(ap, double);
            snprintf(numbers[n], sizeof numbers[n], "%.17g", reals[n]);
        } else {
            values[n] = va_arg(ap, const char *);
        }
        if (t == 'b')
            lengths[n] = (int)va_arg(ap, size_t);
        else if (t == 'x' && values[n])
            lengths[n] = (int)strlen(values[n]);
        formats[n] = t == 'b' || t == 'x';
        oids[n] = t == 'i' ? 20 : t == 'd' ? 701 : t == 'j' ? 114 : formats[n] ? 17 : 25;
    }
    bool ok = true;
    if (s->pg) {
        /* binary results: bytea as it is; int8 and bool made text below */
        PGresult *res = PQexecParams(c, sql, n, oids, values, lengths, formats, 1);
        ExecStatusType st = PQresultStatus(res);
        ok = st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK;
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
                ok = add_cell(r, (size_t)j, v, len);
            }
        r->changed = ok ? strtoull(PQcmdTuples(res), NULL, 10) : 0;
        PQclear(res);
    } else {
        sqlite3_stmt *st = NULL;
        ok = sqlite3_prepare_v2(c, sql, -1, &st, NULL) == SQLITE_OK;
        for (int k = 0; ok && k < n; k++) {
            char name[16];
            snprintf(name, sizeof name, "$%d", k + 1);
            int at = sqlite3_bind_parameter_index(st, name); /* 0: not used here */
            if (at && types[k] == 'i')
                sqlite3_bind_int64(st, at, ints[k]);
            else if (at && types[k] == 'd')
                sqlite3_bind_double(st, at, reals[k]);
            else if (at && types[k] == 'b')
                sqlite3_bind_blob(st, at, values[k], lengths[k], SQLITE_TRANSIENT);
            else if (at)
                sqlite3_bind_text(st, at, values[k], -1, SQLITE_TRANSIENT); /* NULL binds null */
        }
        int step = SQLITE_ERROR;
        r->ncol = ok ? (size_t)sqlite3_column_count(st) : 0;
        while (ok && (step = sqlite3_step(st)) == SQLITE_ROW)
            for (size_t j = 0; ok && j < r->ncol; j++) {
                int type = sqlite3_column_type(st, (int)j);
                const void *v = type == SQLITE_BLOB ? sqlite3_column_blob(st, (int)j)
                                                    : sqlite3_column_text(st, (int)j);
                v = type == SQLITE_NULL ? NULL : v ? v : ""; /* an empty blob reads as NULL */
                ok = add_cell(r, j, v, (size_t)sqlite3_column_bytes(st, (int)j));
            }
        ok = ok && step == SQLITE_DONE;
        r->changed = ok ? (size_t)sqlite3_changes(c) : 0;
        sqlite3_finalize(st);
    }
    if (!ok && out)
        rows_free(out);
    rows_free(&mine);
    return ok;
}

static bool query(const tk_store *s, void *c, rows *out, const char *sql, const char *types, ...)
{
    va_list ap;
    va_start(ap, types);
    bool ok = vquery(s, c, out, sql, types, ap);
    va_end(ap);
    return ok;
}

/* A connection for this call; the lock only guards the list. */
static void *take(tk_store *s, tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    void *c = s->nidle ? s->idle[--s->nidle] : NULL;
    pthread_mutex_unlock(&s->lock);
    return c ? c : connect_to(s, 0, err);
}

/* Back to the list, what did not commit rolled back, unless it broke (a
 * lost server). */
static void give(tk_store *s, void *c)
{
    bool keep = true;
    if (s->pg) {
        if (PQstatus(c) == CONNECTION_OK && PQtransactionStatus(c) != PQTRANS_IDLE)
            PQclear(PQexec(c, "ROLLBACK"));
        keep = PQstatus(c) == CONNECTION_OK && PQtransactionStatus(c) == PQTRANS_IDLE;
    } else if (!sqlite3_get_autocommit(c)) {
        sqlite3_exec(c, "ROLLBACK", NULL, NULL, NULL);
    }
    pthread_mutex_lock(&s->lock);
    if (keep && s->nidle < IDLE_MAX) {
        s->idle[s->nidle++] = c;
        c = NULL;
    }
    pthread_mutex_unlock(&s->lock);
    if (c)
        disconnect(s, c);
}

/* Notes a write's outcome for health: a failure to reach or write the
 * store (TK_EIO, TK_ENOMEM) until the next write that succeeds; answers
 * about the job (busy, not found, not queued) are neither.  Returns rc. */
static int written(tk_store *s, int rc, const tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    s->writes++;
    if (rc == TK_OK || rc == TK_EIO || rc == TK_ENOMEM)
        snprintf(s->write_error, sizeof s->write_error, "%s", rc ? err->message : "");
    pthread_mutex_unlock(&s->lock);
    return rc;
}

/* ---- opening ---- */

/* SQLite: WAL, and a store of an earlier version brought up to date. */
static bool sqlite_setup(tk_store *s, sqlite3 *db)
{
    sqlite3_stmt *old = NULL;
    bool first_version = sqlite3_prepare_v2(db, "SELECT options FROM jobs LIMIT 0", -1, &old,
                                            NULL) == SQLITE_OK;
    sqlite3_finalize(old);
    bool ok = script(s, db, "PRAGMA journal_mode=WAL;");
    if (ok && first_version) {
        /* columns that came later in the first version (an error: there) */
        script(s, db, "ALTER TABLE jobs ADD COLUMN invariants TEXT");
        script(s, db, "ALTER TABLE jobs ADD COLUMN resume TEXT");
        script(s, db, "ALTER TABLE frames ADD COLUMN layout TEXT");
        ok = script(s, db, "PRAGMA foreign_keys=OFF;") && script(s, db, upgrade) &&
             script(s, db, "PRAGMA foreign_keys=ON;");
    }
    ok = ok && script(s, db, schema[0]);
    if (ok) {
        /* a store from before holders (an error where they are there) */
        script(s, db, "ALTER TABLE jobs ADD COLUMN holder TEXT");
        script(s, db, "ALTER TABLE jobs ADD COLUMN cancel INTEGER NOT NULL DEFAULT 0");
        script(s, db, "ALTER TABLE jobs ADD COLUMN turn INTEGER NOT NULL DEFAULT 0");
        ok = script(s, db, "CREATE INDEX IF NOT EXISTS jobs_by_turn ON jobs (state, turn, id)");
    }
    return ok;
}

/* The store as messages name it.  A PostgreSQL URI may carry a user's
 * password (in its authority or its query), and messages reach clients
 * (health, problems) and logs: so only its host, port and database. */
static void label_store(tk_store *s)
{
    if (!s->pg) {
        snprintf(s->label, sizeof s->label, "%.190s", s->where);
        return;
    }
    PQconninfoOption *opts = PQconninfoParse(s->where, NULL);
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
        snprintf(s->label, sizeof s->label, "PostgreSQL database '%.60s' on %.60s%s%.8s",
                 db ? db : "(default)", host ? host : "localhost", port ? ":" : "",
                 port ? port : "");
    else
        snprintf(s->label, sizeof s->label, "PostgreSQL (its URI does not parse)");
    PQconninfoFree(opts);
}

int tk_store_open(const char *where, double lease, tk_store **out, tk_error *err)
{
    *out = NULL;
    tk_store *s = calloc(1, sizeof *s);
    if (!s || !(s->where = strdup(where))) {
        free(s);
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    }
    s->pg = !strncmp(where, "postgresql://", 13) || !strncmp(where, "postgres://", 11);
    label_store(s);
    s->lease = lease;
    pthread_mutex_init(&s->lock, NULL);
    char host[64] = "host";
    gethostname(host, sizeof host - 1);
    unsigned long long nonce = 0;
    if (getrandom(&nonce, sizeof nonce, 0) != (ssize_t)sizeof nonce)
        nonce = (unsigned long long)(uintptr_t)s ^ (unsigned long long)getpid();
    snprintf(s->holder, sizeof s->holder, "%.63s:%ld:%016llx", host, (long)getpid(), nonce);
    void *c = connect_to(s, SQLITE_OPEN_CREATE, err);
    if (c && (s->pg ? script(s, c, schema[1]) : sqlite_setup(s, c))) {
        s->idle[s->nidle++] = c;
        *out = s;
        return TK_OK;
    }
    if (c) {
        const char *m = s->pg ? PQerrorMessage(c) : sqlite3_errmsg(c);
        tk_error_set(err, TK_EIO, "cannot set up the job store %s: %.200s", s->label, m);
        give(s, c); /* rolls back a part done */
    }
    tk_store_close(&s);
    return TK_EIO;
}

void tk_store_close(tk_store **p)
{
    tk_store *s = p ? *p : NULL;
    if (!s)
        return;
    while (s->nidle)
        disconnect(s, s->idle[--s->nidle]);
    for (size_t i = 0; i < RECENT_MAX; i++)
        json_decref(s->recent[i].doc);
    pthread_mutex_destroy(&s->lock);
    free(s->where);
    free(s);
    *p = NULL;
}

bool tk_store_shared(const tk_store *s)
{
    return s->pg;
}

const char *tk_store_holder(const tk_store *s)
{
    return s->holder;
}

/* ---- the operations ---- */

/* Which limit a refused submission reached: the queue's, the owner's
 * jobs, or the owner's bytes. */
static int which_limit(tk_store *s, const char *owner, const tk_store_limits *limits,
                       tk_error *err)
{
    size_t counts[TK_JOB_STATES], mine = 0, n = 0;
    json_t *docs = NULL;
    for (int state = TK_JOB_QUEUED; owner && state <= TK_JOB_RUNNING; state++, mine += n) {
        tk_store_list(s, state, owner, 0, 0, &docs, &n, err);
        json_decref(docs);
    }
    if (tk_store_counts(s, counts, err) == TK_OK && counts[TK_JOB_QUEUED] >= limits->queued)
        return tk_error_set(err, TK_EBUSY, "the queue is full (%zu jobs waiting)", limits->queued);
    if (owner && limits->per_owner && mine >= limits->per_owner)
        return tk_error_set(err, TK_EBUSY, "'%.64s' has %zu jobs queued or running, as many as "
                            "a name may (--jobs-per-name)", owner, limits->per_owner);
    return tk_error_set(err, TK_EBUSY, "'%.64s' has stored %zu bytes or more, as many as a "
                        "name may (--bytes-per-name): delete finished jobs to make room",
                        owner ? owner : "", limits->bytes);
}

int tk_store_add(tk_store *s, json_t *doc, const char *input, const tk_store_limits *limits,
                 tk_error *err)
{
    void *c = take(s, err);
    if (!c)
        return written(s, TK_EIO, err);
    char *text = tk_json_dump(doc, false);
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    /* under one lock across daemons, the insert's counts see every
     * submission before it */
    rows r = {0};
    bool ok = text && script(s, c, begin_sql[s->pg]) && script(s, c, lock_sql[s->pg]) &&
              query(s, c, &r, add_sql[s->pg], "jxitii", text, input, (int64_t)limits->queued,
                    owner, (int64_t)limits->per_owner, (int64_t)limits->bytes);
    ok = ok && script(s, c, "COMMIT");
    int rc = !ok ? failed(s, c, err, "adding a job") : r.n == 1 ? TK_OK : TK_EBUSY;
    if (!rc)
        json_object_set_new(doc, "id", json_integer(int_at(&r, 0, 0)));
    rows_free(&r);
    free(text);
    give(s, c);
    return rc == TK_EBUSY ? which_limit(s, owner, limits, err) : written(s, rc, err);
}

int tk_store_put(tk_store *s, const json_t *doc, const char *const *parts,
                 const tk_frame *frames, size_t first, size_t nframes, tk_error *err)
{
    return tk_store_put_within(s, doc, parts, frames, first, nframes, 0, NULL, err);
}

int tk_store_put_within(tk_store *s, const json_t *doc, const char *const *parts,
                        const tk_frame *frames, size_t first, size_t nframes, size_t owner_bytes,
                        size_t *fit, tk_error *err)
{
    void *c = take(s, err);
    if (!c)
        return written(s, TK_EIO, err);
    int64_t id = tk_job_id(doc);
    char *text = tk_json_dump(doc, false);
    const char *const *p = parts ? parts : (const char *const[TK_PARTS]){NULL};
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    bool limited = owner && owner_bytes && nframes;
    rows r = {0};
    /* a limited write holds the submissions' lock (PostgreSQL; SQLite's
     * writers take turns anyway): its count of the owner's bytes stays
     * true until it commits */
    bool ok = text && script(s, c, begin_sql[s->pg]) &&
              (!limited || script(s, c, lock_sql[s->pg])) &&
              query(s, c, &r, put_sql[s->pg], "tjxxxxxitd", tk_job_states[tk_job_state_in(doc)],
                    text, p[0], p[1], p[2], p[3], p[4], id, s->holder, s->lease);
    int rc = ok && r.changed != 1
                 ? tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here", (long long)id)
                 : TK_OK;
    rows_free(&r);
    ok = ok && !rc &&
         query(s, c, NULL, "DELETE FROM frames WHERE job = $1 AND seq >= $2", "ii", id,
               (int64_t)first);
    /* the frames that fit beside all else the owner has stored, this
     * document and these parts included; the write is undone when not
     * all of them do, for the caller to write its count again */
    size_t n = 0;
    if (ok && !rc && limited && (ok = query(s, c, &r, owner_bytes_sql[s->pg], "t", owner))) {
        int64_t room = (int64_t)owner_bytes - int_at(&r, 0, 0), size;
        while (n < nframes && (size = (int64_t)(frames[n].count * sizeof(double))) <= room)
            n++, room -= size;
        rows_free(&r);
    }
    if (ok && !rc && limited && n < nframes) {
        *fit = n;
        rc = tk_error_set(err, TK_ELIMIT, "'%.64s' has stored as many bytes as a name may "
                          "(--bytes-per-name): %zu of %zu frames fit", owner, n, nframes);
    }
    for (size_t i = 0; ok && !rc && i < nframes; i++)
        ok = query(s, c, NULL, "INSERT INTO frames VALUES ($1, $2, $3, $4, $5)", "iiibt", id,
                   (int64_t)(first + i), (int64_t)frames[i].step, (const char *)frames[i].xyz,
                   frames[i].count * sizeof(double), frames[i].layout);
    ok = ok && !rc && script(s, c, "COMMIT");
    if (!ok && !rc)
        rc = failed(s, c, err, "writing a job");
    free(text);
    give(s, c); /* rolls back what did not commit */
    return written(s, rc, err);
}

/* The document of row i of (doc, id, state): the id and state are the
 * columns'.  NULL (TK_EIO in err, and the store reported damaged) when
 * it does not read back: SQLite checks its pages, not a row's bytes. */
static json_t *row_doc(tk_store *s, const rows *r, size_t i, tk_error *err)
{
    json_t *doc = cell(r, i, 0) ? json_loads(cell(r, i, 0), 0, NULL) : NULL;
    if (json_is_object(doc) && cell(r, i, 2)) {
        json_object_set_new(doc, "id", json_integer(int_at(r, i, 1)));
        json_object_set_new(doc, "state", json_string(cell(r, i, 2)));
        return doc;
    }
    json_decref(doc);
    tk_error_set(err, TK_EIO, "the stored document of job %lld does not read back",
                 (long long)int_at(r, i, 1));
    tk_store_damage(s, err->message);
    return NULL;
}

/* Runs a query (as query says) on a connection of its own; its rows in
 * *r (empty when it fails: TK_EIO, saying `what` failed). */
static int ask(tk_store *s, rows *r, const char *what, tk_error *err, const char *sql,
               const char *types, ...)
{
    *r = (rows){0};
    void *c = sql ? take(s, err) : NULL; /* no statement here: no connection either */
    if (!c)
        return sql ? TK_EIO : TK_OK;
    va_list ap;
    va_start(ap, types);
    bool ok = vquery(s, c, r, sql, types, ap);
    va_end(ap);
    int rc = ok ? TK_OK : failed(s, c, err, what);
    give(s, c);
    return rc;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Job id's document as read at `at`, when no write came since
 * (`writes`), is kept to be served for RECENT_AGE; with doc NULL, a copy
 * of the one kept, if it is still fresh, or NULL. */
static json_t *recent(tk_store *s, int64_t id, uint64_t writes, double at, const json_t *doc)
{
    json_t *copy = NULL;
    pthread_mutex_lock(&s->lock);
    struct kept *k = &s->recent[(uint64_t)id % RECENT_MAX];
    if (doc && writes == s->writes) {
        json_decref(k->doc);
        k->id = id, k->writes = writes, k->at = at, k->doc = json_deep_copy(doc);
    } else if (!doc && k->doc && k->id == id && k->writes == s->writes && at - k->at < RECENT_AGE)
        copy = json_deep_copy(k->doc);
    pthread_mutex_unlock(&s->lock);
    return copy;
}

int tk_store_get(tk_store *s, int64_t id, json_t **doc, tk_error *err)
{
    double at = now();
    uint64_t writes = 0;
    if (s->pg) {
        if ((*doc = recent(s, id, 0, at, NULL)))
            return TK_OK;
        pthread_mutex_lock(&s->lock);
        writes = s->writes;
        pthread_mutex_unlock(&s->lock);
    }
    rows r;
    int rc = ask(s, &r, "reading a job", err, "SELECT doc, id, state FROM jobs WHERE id = $1",
                 "i", id);
    if (!rc)
        rc = !r.n ? tk_error_set(err, TK_ENOTFOUND, "there is no job %lld", (long long)id)
             : (*doc = row_doc(s, &r, 0, err)) ? TK_OK
                                                : TK_EIO;
    rows_free(&r);
    if (!rc && s->pg)
        recent(s, id, writes, at, *doc);
    return rc;
}

int tk_store_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err)
{
    *text = NULL;
    if (len)
        *len = 0;
    char sql[64];
    snprintf(sql, sizeof sql, "SELECT %s FROM jobs WHERE id = $1", part_columns[part]);
    rows r;
    int rc = ask(s, &r, "reading a job", err, sql, "i", id);
    if (!rc && !r.n)
        rc = tk_error_set(err, TK_ENOTFOUND, "no such job");
    if (!rc && len)
        *len = r.len[0];
    if (!rc)
        *text = steal(&r, 0, 0);
    rows_free(&r);
    return rc;
}

int tk_store_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                  json_t **docs, size_t *total, tk_error *err)
{
    *docs = json_array();
    const char *name = state >= 0 ? tk_job_states[state] : NULL;
    rows r;
    int rc = ask(s, &r, "listing jobs", err, "SELECT count(*)" MATCHING, "tt", name, owner);
    *total = rc ? 0 : (size_t)int_at(&r, 0, 0);
    rows_free(&r);
    if (!rc)
        rc = ask(s, &r, "listing jobs", err,
                 "SELECT doc, id, state" MATCHING " ORDER BY id DESC LIMIT $3 OFFSET $4", "ttii",
                 name, owner, (int64_t)limit, (int64_t)offset);
    json_t *doc;
    for (size_t i = 0; !rc && i < r.n; i++)
        if ((doc = row_doc(s, &r, i, err)) != NULL)
            json_array_append_new(*docs, doc);
        else
            rc = TK_EIO;
    rows_free(&r);
    return rc;
}

/* Runs an UPDATE or DELETE on one job (its id $1); TK_EINVAL with `why`
 * when it changes nothing. */
static int change(tk_store *s, const char *sql, int64_t id, const char *why, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "changing a job", err, sql, "i", id);
    if (!rc && !r.changed)
        rc = tk_error_set(err, TK_EINVAL, "job %lld %s", (long long)id, why);
    rows_free(&r);
    return written(s, rc, err);
}

int tk_store_cancel(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, cancel_sql[s->pg], id, "is not queued", err);
}

int tk_store_stop(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "UPDATE jobs SET cancel = true WHERE id = $1 AND state = 'running'", id,
                  "is not running", err);
}

int tk_store_delete(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "DELETE FROM jobs WHERE id = $1 AND state IN ('done', 'failed', 'cancelled')",
                  id, "has not ended", err);
}

int tk_store_requeue(tk_store *s, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "queueing unfinished jobs", err, requeue_sql[s->pg], "");
    rows_free(&r);
    return written(s, rc, err);
}

int tk_store_claim(tk_store *s, int64_t *id, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "claiming a job", err, claim_sql[s->pg], "td", s->holder, s->lease);
    *id = !rc && r.n == 1 ? int_at(&r, 0, 0) : 0;
    if (!rc && !*id)
        rc = tk_error_set(err, TK_ENOTFOUND, "no job is queued");
    rows_free(&r);
    return written(s, rc, err);
}

int tk_store_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "renewing a job", err, renew_sql[s->pg], "itd", id, s->holder, s->lease);
    if (!rc && !r.n)
        rc = tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here", (long long)id);
    *cancel = !rc && int_at(&r, 0, 0) != 0;
    rows_free(&r);
    return written(s, rc, err);
}

int tk_store_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_frame **out,
                    size_t *n, tk_error *err)
{
    *n = 0;
    if (!(*out = calloc(limit ? limit : 1, sizeof **out)))
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    rows r;
    int rc = ask(s, &r, "reading frames", err,
                 "SELECT step, xyz, layout FROM frames WHERE job = $1 AND seq >= $2 ORDER BY seq"
                 " LIMIT $3", "iii", id, (int64_t)offset, (int64_t)limit);
    for (size_t i = 0; !rc && i < r.n && *n < limit; i++) {
        tk_frame *f = &(*out)[(*n)++];
        f->step = (long)int_at(&r, i, 0);
        f->count = r.len[i * r.ncol + 1] / sizeof(double);
        f->xyz = (double *)(void *)steal(&r, i, 1);
        f->layout = steal(&r, i, 2);
    }
    rows_free(&r);
    return rc;
}

void tk_frames_free(tk_frame *f, size_t n)
{
    for (size_t i = 0; f && i < n; i++) {
        free(f[i].xyz);
        free(f[i].layout);
    }
    free(f);
}

int tk_store_counts(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err)
{
    memset(counts, 0, TK_JOB_STATES * sizeof *counts);
    rows r;
    int rc = ask(s, &r, "counting jobs", err, "SELECT state, count(*) FROM jobs GROUP BY state",
                 "");
    for (size_t i = 0, k; !rc && i < r.n; i++)
        if ((k = (size_t)tk_job_state_of(cell(&r, i, 0))) < TK_JOB_STATES)
            counts[k] = (size_t)int_at(&r, i, 1);
    rows_free(&r);
    return rc;
}

void tk_store_damage(tk_store *s, const char *what)
{
    pthread_mutex_lock(&s->lock);
    if (!s->damage[0])
        snprintf(s->damage, sizeof s->damage, "%s", what);
    pthread_mutex_unlock(&s->lock);
}

/* Room for a write on a SQLite file's file system (a PostgreSQL server
 * keeps its own disks: a full one shows as a failed write). */
static void room(const tk_store *s, char *reason, size_t size)
{
    if (s->pg)
        return;
    char dir[4096];
    const char *slash = strrchr(s->where, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - s->where) + 1 : 1,
             slash ? s->where : ".");
    struct statvfs fs;
    if (statvfs(dir, &fs) != 0)
        return;
    double free_bytes = (double)fs.f_bavail * (double)fs.f_frsize;
    if (fs.f_flag & ST_RDONLY)
        snprintf(reason, size, "the job store's file system is read-only: jobs cannot be stored");
    else if (free_bytes < 64.0 * 1024.0) /* a save (curve, frames) needs more than a page or two */
        snprintf(reason, size, "the job store's file system is full (%.0f KiB free): jobs cannot "
                 "be stored", free_bytes / 1024.0);
}

bool tk_store_health(tk_store *s, char *reason, size_t size)
{
    reason[0] = '\0';
    pthread_mutex_lock(&s->lock);
    if (s->damage[0])
        snprintf(reason, size, "the job store is damaged: %s", s->damage);
    pthread_mutex_unlock(&s->lock);
    if (!reason[0])
        room(s, reason, size);
    pthread_mutex_lock(&s->lock);
    if (!reason[0] && s->write_error[0])
        snprintf(reason, size, "the last write to the job store failed: %s", s->write_error);
    pthread_mutex_unlock(&s->lock);
    if (reason[0])
        return false;
    /* a read that walks to the newest row: a damaged file shows here as
     * "malformed" before a client's read finds it */
    tk_error err;
    json_t *docs = NULL;
    size_t total = 0;
    int rc = tk_store_list(s, -1, NULL, 0, 1, &docs, &total, &err);
    json_decref(docs);
    if (rc)
        snprintf(reason, size, "the job store cannot be read: %s", err.message);
    return rc == TK_OK;
}
