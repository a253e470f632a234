/* tightknot service: the SQLite job store, one file for one daemon (see
 * store.h). */
#include "store.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>

#include <sqlite3.h>

#include "jsonmap.h"

#define IDLE_MAX 32 /* connections kept for reuse; more are opened while needed */

typedef struct sqlite_store {
    tk_store base;
    char *path;
    pthread_mutex_t lock; /* guards the idle connections, never held over a statement */
    sqlite3 *idle[IDLE_MAX];
    size_t nidle;
} sqlite_store;

/* the parts' columns, in tk_part's order */
static const char *const part_columns[TK_PARTS] = {"input", "curve", "contacts", "history",
                                                   "resume"};
_Static_assert(TK_PARTS == 5, "tk_store_put writes the parts in one statement: name them there");

static const char schema[] =
    "CREATE TABLE IF NOT EXISTS jobs (id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " state TEXT NOT NULL, doc TEXT NOT NULL, input TEXT NOT NULL, curve TEXT, contacts TEXT,"
    " history TEXT, resume TEXT, holder TEXT, cancel INTEGER NOT NULL DEFAULT 0);"
    "CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);"
    "CREATE TABLE IF NOT EXISTS frames (job INTEGER NOT NULL REFERENCES jobs (id) ON DELETE"
    " CASCADE, seq INTEGER NOT NULL, step INTEGER NOT NULL, xyz BLOB NOT NULL, layout TEXT,"
    " PRIMARY KEY (job, seq));";

/* A store of the first version kept a job's fields in columns of their
 * own: each row becomes a document, in one transaction. */
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

static int failed(sqlite3 *db, tk_error *err, const char *what)
{
    return tk_error_set(err, TK_EIO, "job store: %s: %s", what, sqlite3_errmsg(db));
}

static sqlite3 *connect(const char *path, int flags, tk_error *err)
{
    sqlite3 *db = NULL;
    int rc = sqlite3_open_v2(path, &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX | flags, NULL);
    /* NORMAL keeps every committed transaction across a crash of the
     * process (kill -9), the failure the store must survive */
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(db, "PRAGMA foreign_keys=ON; PRAGMA synchronous=NORMAL;", NULL, NULL,
                          NULL);
    if (rc != SQLITE_OK) {
        tk_error_set(err, TK_EIO, "cannot set up the job store %s: %s", path,
                     db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
        sqlite3_close_v2(db);
        return NULL;
    }
    sqlite3_busy_timeout(db, 10000);
    return db;
}

/* A connection for this call; the lock only guards the list. */
static sqlite3 *take(tk_store *base, tk_error *err)
{
    sqlite_store *s = (sqlite_store *)base;
    pthread_mutex_lock(&s->lock);
    sqlite3 *db = s->nidle ? s->idle[--s->nidle] : NULL;
    pthread_mutex_unlock(&s->lock);
    return db ? db : connect(s->path, 0, err);
}

static void give(tk_store *base, sqlite3 *db)
{
    sqlite_store *s = (sqlite_store *)base;
    pthread_mutex_lock(&s->lock);
    if (s->nidle < IDLE_MAX)
        s->idle[s->nidle++] = db;
    else
        sqlite3_close_v2(db);
    pthread_mutex_unlock(&s->lock);
}

/* A statement with its parameters bound by `types`: i int64, t text (NULL
 * binds null), b blob (pointer and int length). NULL when it fails. */
static sqlite3_stmt *prepare(sqlite3 *db, const char *sql, const char *types, ...)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK)
        return NULL;
    va_list ap;
    va_start(ap, types);
    for (int i = 0; types[i]; i++) {
        if (types[i] == 'i') {
            sqlite3_bind_int64(st, i + 1, va_arg(ap, int64_t));
        } else if (types[i] == 't') {
            const char *t = va_arg(ap, const char *);
            sqlite3_bind_text(st, i + 1, t, -1, SQLITE_TRANSIENT); /* NULL binds null */
        } else {
            const void *p = va_arg(ap, const void *);
            sqlite3_bind_blob(st, i + 1, p, va_arg(ap, int), SQLITE_TRANSIENT);
        }
    }
    va_end(ap);
    return st;
}

/* Steps a statement that returns no row, and finalises it. */
static bool done(sqlite3_stmt *st)
{
    bool ok = st && sqlite3_step(st) == SQLITE_DONE;
    sqlite3_finalize(st);
    return ok;
}

static const tk_store_ops sqlite_ops;

int tk_store_sqlite_open(const char *path, tk_store **out, tk_error *err)
{
    *out = NULL;
    sqlite3 *db = connect(path, SQLITE_OPEN_CREATE, err);
    if (!db)
        return TK_EIO;
    sqlite3_stmt *old = prepare(db, "SELECT options FROM jobs LIMIT 0", "");
    bool first_version = old != NULL;
    sqlite3_finalize(old);
    char *message = NULL;
    int rc = sqlite3_exec(db, "PRAGMA journal_mode=WAL;", NULL, NULL, &message);
    if (rc == SQLITE_OK && first_version) {
        /* columns that came later in the first version (an error: there) */
        sqlite3_exec(db, "ALTER TABLE jobs ADD COLUMN invariants TEXT", NULL, NULL, NULL);
        sqlite3_exec(db, "ALTER TABLE jobs ADD COLUMN resume TEXT", NULL, NULL, NULL);
        sqlite3_exec(db, "ALTER TABLE frames ADD COLUMN layout TEXT", NULL, NULL, NULL);
        rc = sqlite3_exec(db, "PRAGMA foreign_keys=OFF;", NULL, NULL, &message) ||
             sqlite3_exec(db, upgrade, NULL, NULL, &message) ||
             sqlite3_exec(db, "PRAGMA foreign_keys=ON;", NULL, NULL, &message);
    }
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(db, schema, NULL, NULL, &message);
    if (rc == SQLITE_OK) {
        /* a store from before holders (an error where they are there) */
        sqlite3_exec(db, "ALTER TABLE jobs ADD COLUMN holder TEXT", NULL, NULL, NULL);
        sqlite3_exec(db, "ALTER TABLE jobs ADD COLUMN cancel INTEGER NOT NULL DEFAULT 0", NULL,
                     NULL, NULL);
    }
    sqlite_store *s = rc == SQLITE_OK ? calloc(1, sizeof *s) : NULL;
    if (s && (s->path = strdup(path)) != NULL) {
        tk_store_init(&s->base, &sqlite_ops);
        pthread_mutex_init(&s->lock, NULL);
        s->idle[s->nidle++] = db;
        *out = &s->base;
        return TK_OK;
    }
    tk_error_set(err, rc ? TK_EIO : TK_ENOMEM, "cannot set up the job store %s: %s", path,
                 rc ? (message ? message : sqlite3_errstr(rc)) : "out of memory");
    sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
    sqlite3_free(message);
    sqlite3_close_v2(db);
    free(s);
    return rc ? TK_EIO : TK_ENOMEM;
}

static void sq_close(tk_store *base)
{
    sqlite_store *s = (sqlite_store *)base;
    while (s->nidle)
        sqlite3_close_v2(s->idle[--s->nidle]);
    pthread_mutex_destroy(&s->lock);
    free(s->path);
    free(s);
}

static int sq_add(tk_store *s, json_t *doc, const char *input, const tk_store_limits *limits,
                  tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    char *text = tk_json_dump(doc, false);
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    /* the limits and the insert in one statement: two requests cannot both
     * take the last place */
#define BYTES(c) "coalesce(length(CAST(" c " AS BLOB)), 0)"
    sqlite3_stmt *st = prepare(db,
                               "INSERT INTO jobs (state, doc, input) SELECT 'queued', ?1, ?2"
                               " WHERE (SELECT count(*) FROM jobs WHERE state = 'queued') < ?3"
                               " AND (?4 IS NULL OR ?5 = 0 OR (SELECT count(*) FROM jobs WHERE"
                               " state IN ('queued', 'running') AND json_extract(doc, '$.owner')"
                               " = ?4) < ?5)"
                               " AND (?4 IS NULL OR ?6 = 0 OR (SELECT coalesce(sum(" BYTES("doc")
                               " + " BYTES("input") " + " BYTES("curve") " + " BYTES("contacts")
                               " + " BYTES("history") " + " BYTES("resume") " + (SELECT"
                               " coalesce(sum(length(xyz)), 0) FROM frames WHERE job = jobs.id)),"
                               " 0) FROM jobs WHERE json_extract(doc, '$.owner') = ?4) < ?6)",
                               "ttitii", text, input, (int64_t)limits->queued, owner,
                               (int64_t)limits->per_owner, (int64_t)limits->bytes);
#undef BYTES
    int rc = text && done(st) ? TK_OK : failed(db, err, "adding a job");
    free(text);
    if (!rc && sqlite3_changes(db) == 0)
        rc = TK_EBUSY;
    if (!rc)
        json_object_set_new(doc, "id", json_integer(sqlite3_last_insert_rowid(db)));
    give(s, db);
    return rc;
}

static int sq_put(tk_store *s, const json_t *doc, const char *const *parts,
                  const tk_frame *frames, size_t first, size_t nframes, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    int64_t id = tk_job_id(doc);
    char *text = tk_json_dump(doc, false);
    bool ok = text && sqlite3_exec(db, "BEGIN IMMEDIATE", NULL, NULL, NULL) == SQLITE_OK;
    const char *const *p = parts ? parts : (const char *const[TK_PARTS]){NULL};
    ok = ok && done(prepare(db,
                            "UPDATE jobs SET state = ?1, doc = ?2, input = coalesce(?3, input),"
                            " curve = coalesce(?4, curve), contacts = coalesce(?5, contacts),"
                            " history = coalesce(?6, history), resume = coalesce(?7, resume),"
                            " holder = CASE ?1 WHEN 'running' THEN holder END"
                            " WHERE id = ?8 AND holder = ?9",
                            "tttttttit", tk_job_states[tk_job_state_in(doc)], text, p[0], p[1],
                            p[2], p[3], p[4], id, s->holder));
    int rc = ok && sqlite3_changes(db) != 1
                 ? tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here", (long long)id)
                 : TK_OK;
    ok = ok && !rc && done(prepare(db, "DELETE FROM frames WHERE job = ? AND seq >= ?", "ii", id,
                                   (int64_t)first));
    for (size_t i = 0; ok && i < nframes; i++)
        ok = done(prepare(db, "INSERT INTO frames VALUES (?, ?, ?, ?, ?)", "iiibt", id,
                          (int64_t)(first + i), (int64_t)frames[i].step, frames[i].xyz,
                          (int)(frames[i].count * sizeof(double)), frames[i].layout));
    ok = ok && sqlite3_exec(db, "COMMIT", NULL, NULL, NULL) == SQLITE_OK;
    if (!ok && !rc)
        rc = failed(db, err, "writing a job");
    if (!ok)
        sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
    free(text);
    give(s, db);
    return rc;
}

/* Runs a query for one text column; *text NULL for a SQL null. */
static int one_text(tk_store *s, sqlite3_stmt *st, sqlite3 *db, char **text, size_t *len,
                    tk_error *err)
{
    *text = NULL;
    int step = st ? sqlite3_step(st) : SQLITE_ERROR;
    int rc = step == SQLITE_ROW ? TK_OK
             : step == SQLITE_DONE ? tk_error_set(err, TK_ENOTFOUND, "no such job")
                                   : failed(db, err, "reading a job");
    const char *t = rc ? NULL : (const char *)sqlite3_column_text(st, 0);
    size_t n = t ? (size_t)sqlite3_column_bytes(st, 0) : 0;
    if (t && (*text = malloc(n + 1)) != NULL)
        memcpy(*text, t, n + 1);
    if (t && !*text)
        rc = tk_error_set(err, TK_ENOMEM, "out of memory");
    if (len)
        *len = n;
    sqlite3_finalize(st);
    give(s, db);
    return rc;
}

/* The document of a row (doc, id, state): the id and state are the
 * columns'.  NULL (TK_EIO in err, and the store reported damaged) when
 * it does not read back: SQLite checks its pages, not a row's bytes. */
static json_t *row_doc(tk_store *s, sqlite3_stmt *st, tk_error *err)
{
    json_t *doc = json_loads((const char *)sqlite3_column_text(st, 0), 0, NULL);
    if (json_is_object(doc)) {
        json_object_set_new(doc, "id", json_integer(sqlite3_column_int64(st, 1)));
        json_object_set_new(doc, "state", json_string((const char *)sqlite3_column_text(st, 2)));
        return doc;
    }
    json_decref(doc);
    tk_error_set(err, TK_EIO, "the stored document of job %lld does not read back",
                 (long long)sqlite3_column_int64(st, 1));
    tk_store_damage(s, err->message);
    return NULL;
}

static int sq_get(tk_store *s, int64_t id, json_t **doc, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    sqlite3_stmt *st = prepare(db, "SELECT doc, id, state FROM jobs WHERE id = ?", "i", (int64_t)id);
    int step = st ? sqlite3_step(st) : SQLITE_ERROR;
    int rc = step == SQLITE_DONE  ? tk_error_set(err, TK_ENOTFOUND, "there is no job %lld", (long long)id)
             : step != SQLITE_ROW ? failed(db, err, "reading a job")
             : !(*doc = row_doc(s, st, err)) ? TK_EIO
                                              : TK_OK;
    sqlite3_finalize(st);
    give(s, db);
    return rc;
}

static int sq_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    char sql[64];
    snprintf(sql, sizeof sql, "SELECT %s FROM jobs WHERE id = ?", part_columns[part]);
    return one_text(s, prepare(db, sql, "i", (int64_t)id), db, text, len, err);
}

static int sq_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                   json_t **docs, size_t *total, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    const char *name = state >= 0 ? tk_job_states[state] : NULL;
#define MATCHING " FROM jobs WHERE (?1 IS NULL OR state = ?1) AND (?2 IS NULL OR" \
                 " json_extract(doc, '$.owner') = ?2)"
    sqlite3_stmt *st = prepare(db, "SELECT count(*)" MATCHING, "tt", name, owner);
    bool ok = st && sqlite3_step(st) == SQLITE_ROW;
    *total = ok ? (size_t)sqlite3_column_int64(st, 0) : 0;
    sqlite3_finalize(st);
    st = ok ? prepare(db, "SELECT doc, id, state" MATCHING " ORDER BY id DESC LIMIT ?3 OFFSET ?4",
                      "ttii", name, owner, (int64_t)limit, (int64_t)offset)
            : NULL;
    int step = SQLITE_ERROR;
    json_t *doc = NULL;
    while (st && (step = sqlite3_step(st)) == SQLITE_ROW && (doc = row_doc(s, st, err)) != NULL)
        json_array_append_new(*docs, doc);
    int rc = step == SQLITE_DONE ? TK_OK
             : step == SQLITE_ROW ? TK_EIO
                                  : failed(db, err, "listing jobs");
    sqlite3_finalize(st);
    give(s, db);
    return rc;
}

/* Runs an UPDATE or DELETE on one job (its id ?1); TK_EINVAL with `why`
 * when it changes nothing. */
static int change(tk_store *s, const char *sql, int64_t id, const char *why, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    int rc = done(prepare(db, sql, "i", id)) ? TK_OK : failed(db, err, "changing a job");
    if (!rc && sqlite3_changes(db) == 0)
        rc = tk_error_set(err, TK_EINVAL, "job %lld %s", (long long)id, why);
    give(s, db);
    return rc;
}

static int sq_cancel(tk_store *s, int64_t id, tk_error *err)
{
    return change(s,
                  "UPDATE jobs SET state = 'cancelled', doc = json_set(doc, '$.stop_reason',"
                  " 'cancelled', '$.finished', strftime('%Y-%m-%dT%H:%M:%fZ')) WHERE id = ? AND"
                  " state = 'queued'",
                  id, "is not queued", err);
}

static int sq_stop(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "UPDATE jobs SET cancel = 1 WHERE id = ? AND state = 'running'", id,
                  "is not running", err);
}

static int sq_remove(tk_store *s, int64_t id, tk_error *err)
{
    return change(s,
                  "DELETE FROM jobs WHERE id = ? AND state IN ('done', 'failed', 'cancelled')",
                  id, "has not ended", err);
}

static int sq_requeue(tk_store *s, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    int rc = done(prepare(db, "UPDATE jobs SET state = 'queued', holder = NULL WHERE state = 'running'", ""))
                 ? TK_OK
                 : failed(db, err, "queueing unfinished jobs");
    give(s, db);
    return rc;
}

static int sq_claim(tk_store *s, int64_t *id, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    sqlite3_stmt *st = prepare(db,
                               "UPDATE jobs SET state = 'running', holder = ? WHERE id = (SELECT"
                               " min(id) FROM jobs WHERE state = 'queued') RETURNING id",
                               "t", s->holder);
    int step = st ? sqlite3_step(st) : SQLITE_ERROR;
    *id = step == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
    if (step == SQLITE_ROW)
        step = sqlite3_step(st);
    sqlite3_finalize(st);
    int rc = step != SQLITE_DONE ? failed(db, err, "claiming a job")
             : *id              ? TK_OK
                                : tk_error_set(err, TK_ENOTFOUND, "no job is queued");
    give(s, db);
    return rc;
}

/* One daemon per file: the holder is always this store while it runs,
 * and only cancellation is news. */
static int sq_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    sqlite3_stmt *st = prepare(db, "SELECT cancel FROM jobs WHERE id = ? AND state = 'running'"
                               " AND holder = ?", "it", id, s->holder);
    int step = st ? sqlite3_step(st) : SQLITE_ERROR;
    *cancel = step == SQLITE_ROW && sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    int rc = step == SQLITE_ROW    ? TK_OK
             : step == SQLITE_DONE ? tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here",
                                                  (long long)id)
                                   : failed(db, err, "renewing a job");
    give(s, db);
    return rc;
}

static int sq_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_frame **out,
                     size_t *n, tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    sqlite3_stmt *st = prepare(db,
                               "SELECT step, xyz, layout FROM frames WHERE job = ? AND seq >= ?"
                               " ORDER BY seq LIMIT ?",
                               "iii", (int64_t)id, (int64_t)offset, (int64_t)limit);
    int step = SQLITE_ERROR;
    while (st && (step = sqlite3_step(st)) == SQLITE_ROW && *n < limit) {
        tk_frame *f = &(*out)[(*n)++];
        size_t bytes = (size_t)sqlite3_column_bytes(st, 1);
        const char *layout = (const char *)sqlite3_column_text(st, 2);
        f->step = (long)sqlite3_column_int64(st, 0);
        f->count = bytes / sizeof(double);
        f->xyz = malloc(bytes + 1);
        f->layout = layout ? strdup(layout) : NULL;
        if (f->xyz)
            memcpy(f->xyz, sqlite3_column_blob(st, 1), f->count * sizeof(double));
        else
            step = SQLITE_NOMEM;
    }
    sqlite3_finalize(st);
    int rc = step == SQLITE_DONE ? TK_OK : failed(db, err, "reading frames");
    give(s, db);
    return rc;
}

static int sq_counts(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err)
{
    sqlite3 *db = take(s, err);
    if (!db)
        return TK_EIO;
    sqlite3_stmt *st = prepare(db, "SELECT state, count(*) FROM jobs GROUP BY state", "");
    int step = SQLITE_ERROR, k;
    while (st && (step = sqlite3_step(st)) == SQLITE_ROW)
        if ((k = tk_job_state_of((const char *)sqlite3_column_text(st, 0))) >= 0)
            counts[k] = (size_t)sqlite3_column_int64(st, 1);
    sqlite3_finalize(st);
    int rc = step == SQLITE_DONE ? TK_OK : failed(db, err, "counting jobs");
    give(s, db);
    return rc;
}

/* Room for a write on the file's file system. */
static void sq_room(tk_store *base, char *reason, size_t size)
{
    sqlite_store *s = (sqlite_store *)base;
    char dir[4096];
    const char *slash = strrchr(s->path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - s->path) + 1 : 1, slash ? s->path : ".");
    struct statvfs fs;
    if (statvfs(dir, &fs) != 0)
        return;
    double room = (double)fs.f_bavail * (double)fs.f_frsize;
    if (fs.f_flag & ST_RDONLY)
        snprintf(reason, size, "the job store's file system is read-only: jobs cannot be stored");
    else if (room < 64.0 * 1024.0) /* a save (curve, frames) needs more than a page or two */
        snprintf(reason, size, "the job store's file system is full (%.0f KiB free): jobs cannot "
                 "be stored", room / 1024.0);
}

static const tk_store_ops sqlite_ops = {
    .add = sq_add, .put = sq_put, .get = sq_get, .part = sq_part, .list = sq_list,
    .claim = sq_claim, .renew = sq_renew, .requeue = sq_requeue, .cancel = sq_cancel,
    .stop = sq_stop, .remove = sq_remove, .frames = sq_frames, .counts = sq_counts,
    .room = sq_room, .close = sq_close,
};
