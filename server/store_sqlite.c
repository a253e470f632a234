/* tightknot service: the store's SQLite backend (see store_db.h): one
 * file in WAL mode for one daemon, each thread on a connection of its
 * own, so a reader never waits for the writer. */
#include "store_db.h"

#include <stdio.h>
#include <string.h>
#include <sys/statvfs.h>

#include <sqlite3.h>

#include "store.h"

#define SQ_PART(E, col, n, sql) ", " #col " TEXT" sql
static const char schema[] =
    "CREATE TABLE IF NOT EXISTS jobs (id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " state TEXT NOT NULL, doc TEXT NOT NULL" TK_PART_COLUMNS(SQ_PART)
    ", holder TEXT, cancel INTEGER NOT NULL DEFAULT 0, turn INTEGER NOT NULL DEFAULT 0);"
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

static void *sq_connect(const char *where, const char *label, bool create, tk_error *err)
{
    sqlite3 *db = NULL;
    int rc = sqlite3_open_v2(where, &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX |
                                             (create ? SQLITE_OPEN_CREATE : 0), NULL);
    /* NORMAL keeps every committed transaction across a crash of the
     * process (kill -9), the failure the store must survive */
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(db, "PRAGMA foreign_keys=ON; PRAGMA synchronous=NORMAL;", NULL, NULL,
                          NULL);
    if (rc == SQLITE_OK) {
        sqlite3_busy_timeout(db, 10000);
        return db;
    }
    tk_error_set(err, TK_EIO, "cannot set up the job store %s: %s", label,
                 db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
    sqlite3_close_v2(db);
    return NULL;
}

static void sq_disconnect(void *c)
{
    sqlite3_close_v2(c);
}

static const char *sq_error(void *c)
{
    return sqlite3_errmsg(c);
}

static bool sq_script(void *c, const char *sql)
{
    return sqlite3_exec(c, sql, NULL, NULL, NULL) == SQLITE_OK;
}

static bool sq_run(void *c, rows *r, const char *sql, const params *p)
{
    sqlite3_stmt *st = NULL;
    bool ok = sqlite3_prepare_v2(c, sql, -1, &st, NULL) == SQLITE_OK;
    for (int k = 0; ok && k < p->n; k++) {
        char name[16];
        snprintf(name, sizeof name, "$%d", k + 1);
        int at = sqlite3_bind_parameter_index(st, name); /* 0: not used here */
        char t = p->type[k];
        if (at && t == 'i')
            sqlite3_bind_int64(st, at, p->ints[k]);
        else if (at && t == 'd')
            sqlite3_bind_double(st, at, p->reals[k]);
        else if (at && t == 'b')
            sqlite3_bind_blob(st, at, p->value[k], p->length[k], SQLITE_TRANSIENT);
        else if (at)
            sqlite3_bind_text(st, at, p->value[k], -1, SQLITE_TRANSIENT); /* NULL binds null */
    }
    int step = SQLITE_ERROR;
    r->ncol = ok ? (size_t)sqlite3_column_count(st) : 0;
    while (ok && (step = sqlite3_step(st)) == SQLITE_ROW)
        for (size_t j = 0; ok && j < r->ncol; j++) {
            int type = sqlite3_column_type(st, (int)j);
            const void *v = type == SQLITE_BLOB ? sqlite3_column_blob(st, (int)j)
                                                : sqlite3_column_text(st, (int)j);
            v = type == SQLITE_NULL ? NULL : v ? v : ""; /* an empty blob reads as NULL */
            ok = rows_add(r, j, v, (size_t)sqlite3_column_bytes(st, (int)j));
        }
    ok = ok && step == SQLITE_DONE;
    r->changed = ok ? (size_t)sqlite3_changes(c) : 0;
    sqlite3_finalize(st);
    return ok;
}

static bool sq_release(void *c)
{
    if (!sqlite3_get_autocommit(c))
        sqlite3_exec(c, "ROLLBACK", NULL, NULL, NULL);
    return true;
}

/* WAL, and a store of an earlier version brought up to date: columns
 * that came later are added (an error where they are there already). */
static bool sq_setup(void *db)
{
    sqlite3_stmt *old = NULL;
    bool first_version = sqlite3_prepare_v2(db, "SELECT options FROM jobs LIMIT 0", -1, &old,
                                            NULL) == SQLITE_OK;
    sqlite3_finalize(old);
    bool ok = sq_script(db, "PRAGMA journal_mode=WAL;");
    if (ok && first_version) {
        sq_script(db, "ALTER TABLE jobs ADD COLUMN invariants TEXT");
        sq_script(db, "ALTER TABLE jobs ADD COLUMN resume TEXT");
        sq_script(db, "ALTER TABLE frames ADD COLUMN layout TEXT");
        ok = sq_script(db, "PRAGMA foreign_keys=OFF;") && sq_script(db, upgrade) &&
             sq_script(db, "PRAGMA foreign_keys=ON;");
    }
    ok = ok && sq_script(db, schema);
    if (ok) {
        sq_script(db, "ALTER TABLE jobs ADD COLUMN holder TEXT");
        sq_script(db, "ALTER TABLE jobs ADD COLUMN cancel INTEGER NOT NULL DEFAULT 0");
        sq_script(db, "ALTER TABLE jobs ADD COLUMN turn INTEGER NOT NULL DEFAULT 0");
        /* the owner, until now only in the document, read from there once */
        if (sq_script(db, "ALTER TABLE jobs ADD COLUMN owner TEXT NOT NULL DEFAULT ''"))
            ok = sq_script(db, "UPDATE jobs SET owner = coalesce(doc->>'owner', '')");
        ok = ok && sq_script(db, "CREATE INDEX IF NOT EXISTS jobs_by_turn ON jobs (state, turn,"
                                 " id); CREATE INDEX IF NOT EXISTS jobs_by_owner ON jobs (owner,"
                                 " state, id);");
    }
    return ok;
}

static void sq_label(const char *where, char *out, size_t size)
{
    snprintf(out, size, "%.190s", where);
}

/* Room for a write on the file's file system. */
static void sq_room(const char *where, char *reason, size_t size)
{
    char dir[4096];
    const char *slash = strrchr(where, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - where) + 1 : 1, slash ? where : ".");
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

#define B(c) "coalesce(length(CAST(" c " AS BLOB)), 0)"
#define DOC_BYTES B("doc")
#define LEASE ""
const backend *tk_store_sqlite(void)
{
    /* one daemon per file: its running jobs at start are what a stop or a
     * crash left, the holder is always this store while a job runs, and
     * only cancellation is news; writers take turns anyway */
    static const backend b = {
        sq_connect, sq_disconnect, sq_error, sq_script, sq_run, sq_release, sq_setup, sq_label,
        sq_room,
        .claim = "UPDATE jobs SET state = 'running', holder = $1 WHERE id = (SELECT id FROM jobs"
                 " WHERE state = 'queued' ORDER BY turn, id LIMIT 1) RETURNING id",
        .renew = "SELECT cancel FROM jobs WHERE id = $1 AND state = 'running' AND holder = $2",
        .requeue = "UPDATE jobs SET state = 'queued', holder = NULL WHERE state = 'running'",
        .begin = "BEGIN IMMEDIATE", .lock = NULL, .add = SQL_ADD, .put = SQL_PUT,
        .owner_bytes = SQL_OWNER_BYTES("$1")};
    return &b;
}
