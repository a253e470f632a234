/* tightknot service: the PostgreSQL job store, one database for any
 * number of daemons (see store.h).
 *
 * Each call takes a connection of its own (kept for reuse), so requests
 * and workers never wait for each other here; PostgreSQL's row locks do
 * the rest.  The parts and frames are bytea, kept byte for byte; the
 * document is json, kept as written. */
#define _DEFAULT_SOURCE
#include "store.h"

#include <endian.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libpq-fe.h>

#include "jsonmap.h"

#define IDLE_MAX 32 /* connections kept for reuse; more are opened while needed */
#define MAX_PARAMS 10
/* the advisory lock that makes a submission's limits and insert one step
 * across daemons (any number no other program on the database uses) */
#define ADD_LOCK "7310519"

typedef struct pg_store {
    tk_store base;
    char *uri;
    pthread_mutex_t lock; /* guards the idle connections, never held over a statement */
    PGconn *idle[IDLE_MAX];
    size_t nidle;
} pg_store;

/* the parts' columns, in tk_part's order */
static const char *const part_columns[TK_PARTS] = {"input", "curve", "contacts", "history",
                                                   "resume"};

/* Concurrent first starts of several daemons create the tables once. */
static const char schema[] =
    "BEGIN; SELECT pg_advisory_xact_lock(" ADD_LOCK ");"
    "CREATE TABLE IF NOT EXISTS jobs (id bigserial PRIMARY KEY, state text NOT NULL,"
    " doc json NOT NULL, input bytea NOT NULL, curve bytea, contacts bytea, history bytea,"
    " resume bytea, holder text, lease timestamptz, cancel boolean NOT NULL DEFAULT false);"
    "CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);"
    "CREATE TABLE IF NOT EXISTS frames (job bigint NOT NULL REFERENCES jobs (id) ON DELETE"
    " CASCADE, seq bigint NOT NULL, step bigint NOT NULL, xyz bytea NOT NULL, layout text,"
    " PRIMARY KEY (job, seq));"
    "COMMIT;";

static void quiet(void *arg, const char *message)
{
    (void)arg; /* notices ("already exists, skipping") are not errors */
    (void)message;
}

/* The server's message, on one line. */
static int failed(PGconn *c, tk_error *err, const char *what)
{
    const char *m = PQerrorMessage(c);
    size_t n = strcspn(m, "\n");
    return tk_error_set(err, TK_EIO, "job store: %s: %.*s", what, (int)n, n ? m : "no answer");
}

static PGconn *connect_to(const char *uri, tk_error *err)
{
    /* the URI comes last: what it says wins over these defaults */
    const char *const keys[] = {"connect_timeout", "application_name", "dbname", NULL};
    const char *const values[] = {"10", "tightknotd", uri, NULL};
    PGconn *c = PQconnectdbParams(keys, values, 1);
    if (!c || PQstatus(c) != CONNECTION_OK) {
        const char *m = c ? PQerrorMessage(c) : "out of memory";
        size_t n = strcspn(m, "\n");
        tk_error_set(err, TK_EIO, "cannot reach the job store %s: %.*s", uri, (int)n, m);
        PQfinish(c);
        return NULL;
    }
    PQsetNoticeProcessor(c, quiet, NULL);
    return c;
}

static PGconn *take(tk_store *base, tk_error *err)
{
    pg_store *s = (pg_store *)base;
    pthread_mutex_lock(&s->lock);
    PGconn *c = s->nidle ? s->idle[--s->nidle] : NULL;
    pthread_mutex_unlock(&s->lock);
    return c ? c : connect_to(s->uri, err);
}

/* Back to the list, unless it broke (a lost server) or is left inside a
 * transaction. */
static void give(tk_store *base, PGconn *c)
{
    pg_store *s = (pg_store *)base;
    if (PQstatus(c) == CONNECTION_OK && PQtransactionStatus(c) != PQTRANS_IDLE)
        PQclear(PQexec(c, "ROLLBACK"));
    bool keep = PQstatus(c) == CONNECTION_OK && PQtransactionStatus(c) == PQTRANS_IDLE;
    pthread_mutex_lock(&s->lock);
    if (keep && s->nidle < IDLE_MAX) {
        s->idle[s->nidle++] = c;
        c = NULL;
    }
    pthread_mutex_unlock(&s->lock);
    PQfinish(c);
}

/* Runs a statement with its parameters given by `types`: i int64, d
 * double, t text (NULL: null), b bytes (pointer and size_t length; NULL:
 * null).  `binary`: the result's columns in binary form.  NULL when it
 * fails (the connection's message says why). */
static PGresult *run(PGconn *c, const char *sql, bool binary, const char *types, ...)
{
    const char *values[MAX_PARAMS];
    int lengths[MAX_PARAMS], formats[MAX_PARAMS];
    char numbers[MAX_PARAMS][32];
    int n = 0;
    va_list ap;
    va_start(ap, types);
    for (; types[n] && n < MAX_PARAMS; n++) {
        lengths[n] = formats[n] = 0;
        if (types[n] == 'i') {
            snprintf(numbers[n], sizeof numbers[n], "%lld", (long long)va_arg(ap, int64_t));
            values[n] = numbers[n];
        } else if (types[n] == 'd') {
            snprintf(numbers[n], sizeof numbers[n], "%.17g", va_arg(ap, double));
            values[n] = numbers[n];
        } else if (types[n] == 't') {
            values[n] = va_arg(ap, const char *);
        } else {
            values[n] = va_arg(ap, const char *);
            lengths[n] = (int)va_arg(ap, size_t);
            formats[n] = 1;
        }
    }
    va_end(ap);
    PGresult *r = PQexecParams(c, sql, n, NULL, values, lengths, formats, binary);
    ExecStatusType st = PQresultStatus(r);
    if (st != PGRES_COMMAND_OK && st != PGRES_TUPLES_OK) {
        PQclear(r);
        return NULL;
    }
    return r;
}

/* Statements without parameters whose results are not needed; whether
 * they ran. */
static bool exec(PGconn *c, const char *sql)
{
    PGresult *r = PQexec(c, sql);
    bool ok = PQresultStatus(r) == PGRES_COMMAND_OK || PQresultStatus(r) == PGRES_TUPLES_OK;
    PQclear(r);
    return ok;
}

static const tk_store_ops pg_ops;

int tk_store_pg_open(const char *uri, double lease, tk_store **out, tk_error *err)
{
    *out = NULL;
    PGconn *c = connect_to(uri, err);
    if (!c)
        return TK_EIO;
    if (!exec(c, schema)) {
        tk_error_set(err, TK_EIO, "cannot set up the job store %s: %.200s", uri,
                     PQerrorMessage(c));
        PQfinish(c);
        return TK_EIO;
    }
    pg_store *s = calloc(1, sizeof *s);
    if (!s || !(s->uri = strdup(uri))) {
        free(s);
        PQfinish(c);
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    }
    tk_store_init(&s->base, &pg_ops);
    s->base.shared = true;
    s->base.lease = lease;
    pthread_mutex_init(&s->lock, NULL);
    s->idle[s->nidle++] = c;
    *out = &s->base;
    return TK_OK;
}

static void pg_close(tk_store *base)
{
    pg_store *s = (pg_store *)base;
    while (s->nidle)
        PQfinish(s->idle[--s->nidle]);
    pthread_mutex_destroy(&s->lock);
    free(s->uri);
    free(s);
}

static int64_t int_at(const PGresult *r, int row, int col)
{
    return strtoll(PQgetvalue(r, row, col), NULL, 10);
}

static int pg_add(tk_store *s, json_t *doc, const char *input, const tk_store_limits *limits,
                  tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    char *text = tk_json_dump(doc, false);
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    /* Under one lock across daemons, the insert's counts see every
     * submission before it: two cannot both take the last place. */
    PGresult *r = NULL;
    bool ok = text && exec(c, "BEGIN") &&
              exec(c, "SELECT pg_advisory_xact_lock(" ADD_LOCK ")") &&
              (r = run(c,
                       "INSERT INTO jobs (state, doc, input) SELECT 'queued', $1::json, $2::bytea"
                       " WHERE (SELECT count(*) FROM jobs WHERE state = 'queued') < $3::bigint"
                       " AND ($4::text IS NULL OR $5::bigint = 0 OR (SELECT count(*) FROM jobs"
                       " WHERE state IN ('queued', 'running') AND doc->>'owner' = $4::text)"
                       " < $5::bigint)"
                       " AND ($4::text IS NULL OR $6::bigint = 0 OR (SELECT coalesce(sum("
                       "octet_length(doc::text) + octet_length(input)"
                       " + coalesce(octet_length(curve), 0) + coalesce(octet_length(contacts), 0)"
                       " + coalesce(octet_length(history), 0) + coalesce(octet_length(resume), 0)"
                       " + (SELECT coalesce(sum(octet_length(xyz)), 0) FROM frames WHERE job ="
                       " jobs.id)), 0) FROM jobs WHERE doc->>'owner' = $4::text) < $6::bigint)"
                       " RETURNING id",
                       false, "tbitii", text, input, strlen(input), (int64_t)limits->queued,
                       owner, (int64_t)limits->per_owner, (int64_t)limits->bytes)) != NULL;
    int rc = !ok              ? failed(c, err, "adding a job")
             : PQntuples(r) == 1 ? TK_OK
                                 : TK_EBUSY;
    if (!rc)
        json_object_set_new(doc, "id", json_integer(int_at(r, 0, 0)));
    PQclear(r);
    if (ok && !exec(c, "COMMIT") && !rc)
        rc = failed(c, err, "adding a job");
    free(text);
    give(s, c);
    return rc;
}

static int pg_put(tk_store *s, const json_t *doc, const char *const *parts,
                  const tk_frame *frames, size_t first, size_t nframes, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    int64_t id = tk_job_id(doc);
    char *text = tk_json_dump(doc, false);
    const char *const *p = parts ? parts : (const char *const[TK_PARTS]){NULL};
#define PART(k) p[k], p[k] ? strlen(p[k]) : 0
    bool ok = text && exec(c, "BEGIN");
    /* a state other than running lets go of the job; running renews its lease */
    PGresult *r = ok ? run(c,
                           "UPDATE jobs SET state = $1::text, doc = $2::json,"
                           " input = coalesce($3::bytea, input), curve = coalesce($4::bytea, curve),"
                           " contacts = coalesce($5::bytea, contacts),"
                           " history = coalesce($6::bytea, history),"
                           " resume = coalesce($7::bytea, resume),"
                           " holder = CASE WHEN $1::text = 'running' THEN holder END,"
                           " lease = CASE WHEN $1::text = 'running' THEN now() +"
                           " make_interval(secs => $10::float8) END"
                           " WHERE id = $8::bigint AND holder = $9::text",
                           false, "ttbbbbbitd", tk_job_states[tk_job_state_in(doc)], text,
                           PART(0), PART(1), PART(2), PART(3), PART(4), id, s->holder, s->lease)
                     : NULL;
#undef PART
    ok = r != NULL;
    int rc = ok && strcmp(PQcmdTuples(r), "1")
                 ? tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here", (long long)id)
                 : TK_OK;
    PQclear(r);
    if (ok && !rc) {
        r = run(c, "DELETE FROM frames WHERE job = $1::bigint AND seq >= $2::bigint", false, "ii",
                id, (int64_t)first);
        ok = r != NULL;
        PQclear(r);
    }
    for (size_t i = 0; ok && i < nframes; i++) {
        r = run(c, "INSERT INTO frames VALUES ($1::bigint, $2::bigint, $3::bigint, $4::bytea,"
                " $5::text)", false, "iiibt", id, (int64_t)(first + i), (int64_t)frames[i].step,
                (const char *)frames[i].xyz, frames[i].count * sizeof(double), frames[i].layout);
        ok = r != NULL;
        PQclear(r);
    }
    ok = ok && exec(c, "COMMIT");
    if (!ok && !rc)
        rc = failed(c, err, "writing a job");
    free(text);
    give(s, c); /* rolls back what did not commit */
    return rc;
}

/* The document of row i of (doc, id, state): the id and state are the
 * columns'. */
static json_t *row_doc(tk_store *s, const PGresult *r, int i, tk_error *err)
{
    json_t *doc = json_loads(PQgetvalue(r, i, 0), 0, NULL);
    if (json_is_object(doc)) {
        json_object_set_new(doc, "id", json_integer(int_at(r, i, 1)));
        json_object_set_new(doc, "state", json_string(PQgetvalue(r, i, 2)));
        return doc;
    }
    json_decref(doc);
    tk_error_set(err, TK_EIO, "the stored document of job %lld does not read back",
                 (long long)int_at(r, i, 1));
    tk_store_damage(s, err->message);
    return NULL;
}

static int pg_get(tk_store *s, int64_t id, json_t **doc, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    PGresult *r = run(c, "SELECT doc, id, state FROM jobs WHERE id = $1::bigint", false, "i", id);
    int rc = !r                 ? failed(c, err, "reading a job")
             : !PQntuples(r)    ? tk_error_set(err, TK_ENOTFOUND, "there is no job %lld",
                                               (long long)id)
             : !(*doc = row_doc(s, r, 0, err)) ? TK_EIO
                                               : TK_OK;
    PQclear(r);
    give(s, c);
    return rc;
}

static int pg_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    char sql[64];
    snprintf(sql, sizeof sql, "SELECT %s FROM jobs WHERE id = $1::bigint", part_columns[part]);
    PGresult *r = run(c, sql, true, "i", id);
    int rc = !r              ? failed(c, err, "reading a job")
             : !PQntuples(r) ? tk_error_set(err, TK_ENOTFOUND, "no such job")
                             : TK_OK;
    if (!rc && !PQgetisnull(r, 0, 0)) {
        size_t n = (size_t)PQgetlength(r, 0, 0);
        if ((*text = malloc(n + 1)) == NULL) {
            rc = tk_error_set(err, TK_ENOMEM, "out of memory");
        } else {
            memcpy(*text, PQgetvalue(r, 0, 0), n);
            (*text)[n] = '\0';
            if (len)
                *len = n;
        }
    }
    PQclear(r);
    give(s, c);
    return rc;
}

static int pg_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                   json_t **docs, size_t *total, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    const char *name = state >= 0 ? tk_job_states[state] : NULL;
#define MATCHING " FROM jobs WHERE ($1::text IS NULL OR state = $1::text) AND ($2::text IS NULL" \
                 " OR doc->>'owner' = $2::text)"
    PGresult *r = run(c, "SELECT count(*)" MATCHING, false, "tt", name, owner);
    *total = r ? (size_t)int_at(r, 0, 0) : 0;
    PQclear(r);
    r = r ? run(c, "SELECT doc, id, state" MATCHING " ORDER BY id DESC LIMIT $3 OFFSET $4", false,
                "ttii", name, owner, (int64_t)limit, (int64_t)offset)
          : NULL;
#undef MATCHING
    int rc = r ? TK_OK : failed(c, err, "listing jobs");
    json_t *doc;
    for (int i = 0; !rc && i < PQntuples(r); i++)
        if ((doc = row_doc(s, r, i, err)) != NULL)
            json_array_append_new(*docs, doc);
        else
            rc = TK_EIO;
    PQclear(r);
    give(s, c);
    return rc;
}

/* Runs an UPDATE or DELETE on one job (its id $1); TK_EINVAL with `why`
 * when it changes nothing. */
static int change(tk_store *s, const char *sql, int64_t id, const char *why, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    PGresult *r = run(c, sql, false, "i", id);
    int rc = !r                          ? failed(c, err, "changing a job")
             : !strcmp(PQcmdTuples(r), "0") ? tk_error_set(err, TK_EINVAL, "job %lld %s",
                                                           (long long)id, why)
                                            : TK_OK;
    PQclear(r);
    give(s, c);
    return rc;
}

static int pg_cancel(tk_store *s, int64_t id, tk_error *err)
{
    return change(s,
                  "UPDATE jobs SET state = 'cancelled', doc = (doc::jsonb || jsonb_build_object("
                  "'stop_reason', 'cancelled', 'finished', to_char(now() AT TIME ZONE 'UTC',"
                  " 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"')))::json"
                  " WHERE id = $1::bigint AND state = 'queued'",
                  id, "is not queued", err);
}

static int pg_stop(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "UPDATE jobs SET cancel = true WHERE id = $1::bigint AND state = 'running'",
                  id, "is not running", err);
}

static int pg_remove(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "DELETE FROM jobs WHERE id = $1::bigint AND state IN ('done', 'failed',"
                  " 'cancelled')", id, "has not ended", err);
}

/* Other daemons may be running their jobs: a dead daemon's are taken up
 * when their leases run out (pg_claim). */
static int pg_requeue(tk_store *s, tk_error *err)
{
    (void)s;
    (void)err;
    return TK_OK;
}

static int pg_claim(tk_store *s, int64_t *id, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    /* the lock is taken in the same statement that makes the job ours;
     * rows another daemon is claiming or writing are skipped */
    PGresult *r = run(c,
                      "UPDATE jobs SET state = 'running', holder = $1::text,"
                      " lease = now() + make_interval(secs => $2::float8)"
                      " WHERE id = (SELECT id FROM jobs WHERE state = 'queued' OR (state ="
                      " 'running' AND lease < now()) ORDER BY id LIMIT 1 FOR UPDATE SKIP LOCKED)"
                      " RETURNING id",
                      false, "td", s->holder, s->lease);
    *id = r && PQntuples(r) == 1 ? int_at(r, 0, 0) : 0;
    int rc = !r    ? failed(c, err, "claiming a job")
             : *id ? TK_OK
                   : tk_error_set(err, TK_ENOTFOUND, "no job is queued");
    PQclear(r);
    give(s, c);
    return rc;
}

static int pg_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    PGresult *r = run(c,
                      "UPDATE jobs SET lease = now() + make_interval(secs => $3::float8)"
                      " WHERE id = $1::bigint AND state = 'running' AND holder = $2::text"
                      " RETURNING cancel",
                      false, "itd", id, s->holder, s->lease);
    int rc = !r              ? failed(c, err, "renewing a job")
             : !PQntuples(r) ? tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here",
                                            (long long)id)
                             : TK_OK;
    *cancel = !rc && PQgetvalue(r, 0, 0)[0] == 't';
    PQclear(r);
    give(s, c);
    return rc;
}

static int pg_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_frame **out,
                     size_t *n, tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    PGresult *r = run(c,
                      "SELECT step, xyz, layout FROM frames WHERE job = $1::bigint AND seq >="
                      " $2::bigint ORDER BY seq LIMIT $3",
                      true, "iii", id, (int64_t)offset, (int64_t)limit);
    int rc = r ? TK_OK : failed(c, err, "reading frames");
    for (int i = 0; !rc && i < PQntuples(r) && *n < limit; i++) {
        tk_frame *f = &(*out)[(*n)++];
        uint64_t step;
        memcpy(&step, PQgetvalue(r, i, 0), sizeof step); /* int8, big-endian */
        f->step = (long)(int64_t)be64toh(step);
        size_t bytes = (size_t)PQgetlength(r, i, 1);
        f->count = bytes / sizeof(double);
        f->xyz = malloc(bytes + 1);
        f->layout = PQgetisnull(r, i, 2) ? NULL
                                         : strndup(PQgetvalue(r, i, 2), (size_t)PQgetlength(r, i, 2));
        if (f->xyz)
            memcpy(f->xyz, PQgetvalue(r, i, 1), f->count * sizeof(double));
        else
            rc = tk_error_set(err, TK_ENOMEM, "out of memory");
    }
    PQclear(r);
    give(s, c);
    return rc;
}

static int pg_counts(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err)
{
    PGconn *c = take(s, err);
    if (!c)
        return TK_EIO;
    PGresult *r = run(c, "SELECT state, count(*) FROM jobs GROUP BY state", false, "");
    int rc = r ? TK_OK : failed(c, err, "counting jobs"), k;
    for (int i = 0; !rc && i < PQntuples(r); i++)
        if ((k = tk_job_state_of(PQgetvalue(r, i, 0))) >= 0)
            counts[k] = (size_t)int_at(r, i, 1);
    PQclear(r);
    give(s, c);
    return rc;
}

/* The server keeps its own disks: a full one shows as a failed write. */
static void pg_room(tk_store *s, char *reason, size_t size)
{
    (void)s;
    (void)reason;
    (void)size;
}

static const tk_store_ops pg_ops = {
    .add = pg_add, .put = pg_put, .get = pg_get, .part = pg_part, .list = pg_list,
    .claim = pg_claim, .renew = pg_renew, .requeue = pg_requeue, .cancel = pg_cancel,
    .stop = pg_stop, .remove = pg_remove, .frames = pg_frames, .counts = pg_counts,
    .room = pg_room, .close = pg_close,
};
