/* tightknot: the SQLite job store (see include/tk/store.h). */
#include "tk/store.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>

#include <jansson.h>
#include <sqlite3.h>

#include "jsonmap.h"

/* Below this much free space health calls the store full: a job's save
 * (its curve and frames) needs room beyond a page or two. */
#define STORE_SPACE_MIN (64.0 * 1024.0)

struct tk_store {
    sqlite3 *db;
    pthread_mutex_t lock;
    sqlite3_stmt *get;    /* the reads of every poll, prepared once */
    /* Why the last write failed (a full disk, a read-only file), "" once
     * a write succeeds again: what health reports. */
    char write_error[TK_ERROR_MESSAGE_SIZE];
    /* Damage a reader found in the stored texts: kept until restart. */
    char damage[TK_ERROR_MESSAGE_SIZE];
};

/* Notes the outcome of a write for tk_store_health; returns status.  Lock
 * held. */
static int written(tk_store *s, int status, const tk_error *err)
{
    if (status == TK_OK)
        s->write_error[0] = '\0';
    else
        snprintf(s->write_error, sizeof s->write_error, "%s",
                 err ? err->message : sqlite3_errmsg(s->db));
    return status;
}

static const char *const state_names[TK_JOB_STATES] = {"queued", "running", "done", "failed",
                                                       "cancelled"};

const char *tk_job_state_name(tk_job_state s)
{
    return (unsigned)s < TK_JOB_STATES ? state_names[s] : "unknown";
}

bool tk_job_state_parse(const char *name, tk_job_state *out)
{
    for (int i = 0; i < TK_JOB_STATES; i++)
        if (!strcmp(name, state_names[i])) {
            *out = (tk_job_state)i;
            return true;
        }
    return false;
}

bool tk_job_state_final(tk_job_state s)
{
    return s == TK_JOB_DONE || s == TK_JOB_FAILED || s == TK_JOB_CANCELLED;
}

/* The small columns come first so that listing jobs never reads the large
 * texts stored at the end of the row. */
static const char schema[] =
    "CREATE TABLE IF NOT EXISTS jobs ("
    " id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " name TEXT NOT NULL, state TEXT NOT NULL, options TEXT NOT NULL,"
    " created REAL NOT NULL, started REAL, finished REAL,"
    " has_figures INTEGER NOT NULL DEFAULT 0,"
    " step INTEGER NOT NULL DEFAULT 0, seconds REAL, ropelength REAL, length REAL,"
    " thickness REAL, minrad REAL, residual REAL, struts INTEGER, kinks INTEGER,"
    " step_size REAL, rcond REAL, violation REAL, corrections INTEGER, vertices INTEGER,"
    " components INTEGER, fraction REAL, stop_reason TEXT, error TEXT,"
    " frames INTEGER NOT NULL DEFAULT 0,"
    " input TEXT NOT NULL, curve TEXT, contacts TEXT, history TEXT, invariants TEXT,"
    " resume TEXT);"
    "CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);"
    "CREATE TABLE IF NOT EXISTS frames ("
    " job INTEGER NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    " seq INTEGER NOT NULL, step INTEGER NOT NULL, xyz BLOB NOT NULL, layout TEXT,"
    " PRIMARY KEY (job, seq));";

#define JOB_COLUMNS                                                                        \
    "id, name, state, options, created, started, finished, has_figures, step, seconds,"   \
    " ropelength, length, thickness, minrad, residual, struts, kinks, step_size, rcond,"  \
    " violation, corrections, vertices, components, fraction, stop_reason, error, frames"

static int db_error(tk_store *s, tk_error *err, const char *what)
{
    return tk_error_set(err, TK_EIO, "job store: %s: %s", what, sqlite3_errmsg(s->db));
}

/* Columns added since the first version of the tables, each with its
 * table and declaration: a store written before gets them, so that the
 * daemon takes up the jobs an older one left. */
static const char *const added_columns[][3] = {
    {"jobs", "invariants", "TEXT"},
    {"jobs", "resume", "TEXT"},
    {"frames", "layout", "TEXT"},
};

static int add_columns(sqlite3 *db, char **message)
{
    for (size_t i = 0; i < sizeof added_columns / sizeof added_columns[0]; i++) {
        char sql[160];
        snprintf(sql, sizeof sql, "SELECT %s FROM %s LIMIT 0", added_columns[i][1],
                 added_columns[i][0]);
        sqlite3_stmt *st = NULL;
        bool there = sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK;
        sqlite3_finalize(st);
        if (there)
            continue;
        snprintf(sql, sizeof sql, "ALTER TABLE %s ADD COLUMN %s %s", added_columns[i][0],
                 added_columns[i][1], added_columns[i][2]);
        int rc = sqlite3_exec(db, sql, NULL, NULL, message);
        if (rc != SQLITE_OK)
            return rc;
    }
    return SQLITE_OK;
}

int tk_store_open(const char *path, tk_store **out, tk_error *err)
{
    *out = NULL;
    tk_store *s = calloc(1, sizeof *s);
    if (!s)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    pthread_mutex_init(&s->lock, NULL);
    int rc = sqlite3_open_v2(path, &s->db,
                             SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                             NULL);
    if (rc != SQLITE_OK) {
        tk_error_set(err, TK_EIO, "cannot open the job store %s: %s", path,
                     s->db ? sqlite3_errmsg(s->db) : sqlite3_errstr(rc));
        tk_store_close(&s);
        return TK_EIO;
    }
    sqlite3_busy_timeout(s->db, 5000);
    char *message = NULL;
    /* WAL: readers never wait for the workers' writes; NORMAL
     * synchronisation keeps every committed transaction across a process
     * crash (kill -9), which is the failure the store must survive. */
    rc = sqlite3_exec(s->db,
                      "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;"
                      "PRAGMA foreign_keys=ON;",
                      NULL, NULL, &message);
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(s->db, schema, NULL, NULL, &message);
    if (rc == SQLITE_OK)
        rc = add_columns(s->db, &message);
    if (rc != SQLITE_OK) {
        tk_error_set(err, TK_EIO, "cannot set up the job store %s: %s", path,
                     message ? message : sqlite3_errstr(rc));
        sqlite3_free(message);
        tk_store_close(&s);
        return TK_EIO;
    }
    *out = s;
    return TK_OK;
}

void tk_store_close(tk_store **p)
{
    if (!p || !*p)
        return;
    sqlite3_finalize((*p)->get);
    sqlite3_close_v2((*p)->db);
    pthread_mutex_destroy(&(*p)->lock);
    free(*p);
    *p = NULL;
}

static void bind_text_or_null(sqlite3_stmt *st, int col, const char *text)
{
    if (text && *text)
        sqlite3_bind_text(st, col, text, -1, SQLITE_TRANSIENT);
    else
        sqlite3_bind_null(st, col);
}

static void bind_time(sqlite3_stmt *st, int col, double t)
{
    if (t > 0.0)
        sqlite3_bind_double(st, col, t);
    else
        sqlite3_bind_null(st, col);
}

int tk_store_insert(tk_store *s, tk_job *job, const char *vect, tk_error *err)
{
    json_t *opts = tk_job_options_to_json(&job->options);
    char *opts_text = tk_json_dump(opts, false);
    json_decref(opts);
    if (!opts_text)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(s->db,
                                "INSERT INTO jobs (name, state, options, created, input)"
                                " VALUES (?, ?, ?, ?, ?)",
                                -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_text(st, 1, job->name, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 2, tk_job_state_name(job->state), -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 3, opts_text, -1, SQLITE_TRANSIENT);
        sqlite3_bind_double(st, 4, job->created);
        sqlite3_bind_text(st, 5, vect, -1, SQLITE_TRANSIENT);
        rc = sqlite3_step(st);
    }
    int status = TK_OK;
    if (rc != SQLITE_DONE)
        status = db_error(s, err, "storing a new job");
    else
        job->id = sqlite3_last_insert_rowid(s->db);
    sqlite3_finalize(st);
    written(s, status, err);
    pthread_mutex_unlock(&s->lock);
    free(opts_text);
    return status;
}

static double column_real(sqlite3_stmt *st, int col, double none)
{
    return sqlite3_column_type(st, col) == SQLITE_NULL ? none : sqlite3_column_double(st, col);
}

static void copy_column_text(sqlite3_stmt *st, int col, char *dst, size_t size)
{
    const unsigned char *t = sqlite3_column_text(st, col);
    snprintf(dst, size, "%s", t ? (const char *)t : "");
}

/* Fills a job from a row selected with JOB_COLUMNS. */
static void read_job(sqlite3_stmt *st, tk_job *j)
{
    memset(j, 0, sizeof *j);
    j->id = sqlite3_column_int64(st, 0);
    copy_column_text(st, 1, j->name, sizeof j->name);
    const unsigned char *state = sqlite3_column_text(st, 2);
    if (!state || !tk_job_state_parse((const char *)state, &j->state))
        j->state = TK_JOB_FAILED;
    tk_job_options defaults = TK_JOB_OPTIONS_INIT;
    j->options = defaults;
    const unsigned char *opts = sqlite3_column_text(st, 3);
    json_t *o = opts ? json_loads((const char *)opts, 0, NULL) : NULL;
    if (o)
        tk_job_options_from_json(&j->options, o, NULL, NULL);
    json_decref(o);
    j->created = column_real(st, 4, 0.0);
    j->started = column_real(st, 5, 0.0);
    j->finished = column_real(st, 6, 0.0);
    j->has_figures = sqlite3_column_int(st, 7) != 0;
    tk_step_report *r = &j->latest;
    r->step = (long)sqlite3_column_int64(st, 8);
    r->seconds = column_real(st, 9, 0.0);
    r->ropelength = column_real(st, 10, NAN);
    r->length = column_real(st, 11, NAN);
    r->thickness = column_real(st, 12, NAN);
    r->minrad = column_real(st, 13, NAN);
    r->residual = column_real(st, 14, NAN);
    r->struts = (size_t)sqlite3_column_int64(st, 15);
    r->kinks = (size_t)sqlite3_column_int64(st, 16);
    r->step_size = column_real(st, 17, NAN);
    r->rcond = column_real(st, 18, NAN);
    r->violation = column_real(st, 19, NAN);
    r->corrections = sqlite3_column_int(st, 20);
    r->vertices = (size_t)sqlite3_column_int64(st, 21);
    j->components = (size_t)sqlite3_column_int64(st, 22);
    j->fraction = column_real(st, 23, -1.0);
    copy_column_text(st, 24, j->stop_reason, sizeof j->stop_reason);
    copy_column_text(st, 25, j->error, sizeof j->error);
    j->frames = (size_t)sqlite3_column_int64(st, 26);
}

int tk_store_get(tk_store *s, int64_t id, tk_job *out, tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    int rc = SQLITE_OK;
    if (!s->get)
        rc = sqlite3_prepare_v3(s->db, "SELECT " JOB_COLUMNS " FROM jobs WHERE id = ?", -1,
                                SQLITE_PREPARE_PERSISTENT, &s->get, NULL);
    sqlite3_stmt *st = s->get;
    int status = TK_OK;
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, id);
        rc = sqlite3_step(st);
    }
    if (rc == SQLITE_ROW)
        read_job(st, out);
    else if (rc == SQLITE_DONE)
        status = tk_error_set(err, TK_ENOTFOUND, "there is no job %lld", (long long)id);
    else
        status = db_error(s, err, "reading a job");
    if (st)
        sqlite3_reset(st);
    pthread_mutex_unlock(&s->lock);
    return status;
}

int tk_store_list(tk_store *s, bool filter, tk_job_state state, size_t offset, size_t limit,
                  tk_job **out, size_t *count, size_t *total, tk_error *err)
{
    *out = NULL;
    *count = 0;
    *total = 0;
    tk_job *jobs = limit ? calloc(limit, sizeof *jobs) : NULL;
    if (limit && !jobs)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int status = TK_OK;
    int rc = sqlite3_prepare_v2(s->db,
                                filter ? "SELECT count(*) FROM jobs WHERE state = ?"
                                       : "SELECT count(*) FROM jobs",
                                -1, &st, NULL);
    if (rc == SQLITE_OK) {
        if (filter)
            sqlite3_bind_text(st, 1, tk_job_state_name(state), -1, SQLITE_STATIC);
        rc = sqlite3_step(st);
    }
    if (rc == SQLITE_ROW)
        *total = (size_t)sqlite3_column_int64(st, 0);
    else
        status = db_error(s, err, "counting jobs");
    sqlite3_finalize(st);
    st = NULL;
    if (!status && limit) {
        rc = sqlite3_prepare_v2(s->db,
                                filter ? "SELECT " JOB_COLUMNS " FROM jobs WHERE state = ?3"
                                         " ORDER BY id DESC LIMIT ?1 OFFSET ?2"
                                       : "SELECT " JOB_COLUMNS " FROM jobs"
                                         " ORDER BY id DESC LIMIT ?1 OFFSET ?2",
                                -1, &st, NULL);
        if (rc == SQLITE_OK) {
            sqlite3_bind_int64(st, 1, (sqlite3_int64)limit);
            sqlite3_bind_int64(st, 2, (sqlite3_int64)offset);
            if (filter)
                sqlite3_bind_text(st, 3, tk_job_state_name(state), -1, SQLITE_STATIC);
            while ((rc = sqlite3_step(st)) == SQLITE_ROW && *count < limit)
                read_job(st, &jobs[(*count)++]);
        }
        if (rc != SQLITE_DONE && rc != SQLITE_ROW)
            status = db_error(s, err, "listing jobs");
        sqlite3_finalize(st);
    }
    pthread_mutex_unlock(&s->lock);
    if (status) {
        free(jobs);
        *count = 0;
        return status;
    }
    *out = jobs;
    return TK_OK;
}

static void bind_real_or_null(sqlite3_stmt *st, int col, double x)
{
    if (isfinite(x))
        sqlite3_bind_double(st, col, x);
    else
        sqlite3_bind_null(st, col);
}

/* The UPDATE of tk_store_update, with the lock held. */
static int update_locked(tk_store *s, const tk_job *j, tk_error *err)
{
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(
        s->db,
        "UPDATE jobs SET state = ?2, started = ?3, finished = ?4, has_figures = ?5, step = ?6,"
        " seconds = ?7, ropelength = ?8, length = ?9, thickness = ?10, minrad = ?11,"
        " residual = ?12, struts = ?13, kinks = ?14, step_size = ?15, rcond = ?16,"
        " violation = ?17, corrections = ?18, vertices = ?19, components = ?20,"
        " fraction = ?21, stop_reason = ?22, error = ?23, frames = ?24 WHERE id = ?1",
        -1, &st, NULL);
    if (rc == SQLITE_OK) {
        const tk_step_report *r = &j->latest;
        sqlite3_bind_int64(st, 1, j->id);
        sqlite3_bind_text(st, 2, tk_job_state_name(j->state), -1, SQLITE_STATIC);
        bind_time(st, 3, j->started);
        bind_time(st, 4, j->finished);
        sqlite3_bind_int(st, 5, j->has_figures);
        sqlite3_bind_int64(st, 6, r->step);
        bind_real_or_null(st, 7, r->seconds);
        bind_real_or_null(st, 8, r->ropelength);
        bind_real_or_null(st, 9, r->length);
        bind_real_or_null(st, 10, r->thickness);
        bind_real_or_null(st, 11, r->minrad);
        bind_real_or_null(st, 12, r->residual);
        sqlite3_bind_int64(st, 13, (sqlite3_int64)r->struts);
        sqlite3_bind_int64(st, 14, (sqlite3_int64)r->kinks);
        bind_real_or_null(st, 15, r->step_size);
        bind_real_or_null(st, 16, r->rcond);
        bind_real_or_null(st, 17, r->violation);
        sqlite3_bind_int(st, 18, r->corrections);
        sqlite3_bind_int64(st, 19, (sqlite3_int64)r->vertices);
        sqlite3_bind_int64(st, 20, (sqlite3_int64)j->components);
        bind_real_or_null(st, 21, j->fraction >= 0.0 ? j->fraction : NAN);
        bind_text_or_null(st, 22, j->stop_reason);
        bind_text_or_null(st, 23, j->error);
        sqlite3_bind_int64(st, 24, (sqlite3_int64)j->frames);
        rc = sqlite3_step(st);
    }
    int status = TK_OK;
    if (rc != SQLITE_DONE)
        status = db_error(s, err, "updating a job");
    else if (sqlite3_changes(s->db) == 0)
        status = tk_error_set(err, TK_ENOTFOUND, "there is no job %lld", (long long)j->id);
    sqlite3_finalize(st);
    return status;
}

int tk_store_update(tk_store *s, const tk_job *job, tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    int status = written(s, update_locked(s, job, err), err);
    pthread_mutex_unlock(&s->lock);
    return status;
}

static const char *text_column(tk_job_text which)
{
    switch (which) {
    case TK_TEXT_INPUT: return "input";
    case TK_TEXT_CURVE: return "curve";
    case TK_TEXT_CONTACTS: return "contacts";
    case TK_TEXT_HISTORY: return "history";
    case TK_TEXT_INVARIANTS: return "invariants";
    case TK_TEXT_RESUME: return "resume";
    default: return NULL;
    }
}

static int set_text_locked(tk_store *s, int64_t id, tk_job_text which, const char *text,
                           tk_error *err)
{
    char sql[96];
    snprintf(sql, sizeof sql, "UPDATE jobs SET %s = ? WHERE id = ?", text_column(which));
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(s->db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_text(st, 1, text, -1, SQLITE_STATIC);
        sqlite3_bind_int64(st, 2, id);
        rc = sqlite3_step(st);
    }
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? TK_OK : db_error(s, err, "storing a job's text");
}

static int add_frame_locked(tk_store *s, int64_t id, size_t seq, const tk_store_frame *f,
                            tk_error *err)
{
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(s->db,
                                "INSERT OR REPLACE INTO frames (job, seq, step, xyz, layout)"
                                " VALUES (?, ?, ?, ?, ?)",
                                -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)seq);
        sqlite3_bind_int64(st, 3, f->step);
        sqlite3_bind_blob64(st, 4, f->xyz, f->count * sizeof(double), SQLITE_STATIC);
        bind_text_or_null(st, 5, f->layout);
        rc = sqlite3_step(st);
    }
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? TK_OK : db_error(s, err, "storing a frame");
}

int tk_store_save(tk_store *s, const tk_job *job, const char *const *texts,
                  const tk_store_frame *frames, size_t nframes, tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    int status = TK_OK;
    if (sqlite3_exec(s->db, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK) {
        status = written(s, db_error(s, err, "starting a transaction"), err);
        pthread_mutex_unlock(&s->lock);
        return status;
    }
    status = update_locked(s, job, err);
    for (int k = 0; !status && texts && k < TK_TEXTS; k++)
        if (texts[k])
            status = set_text_locked(s, job->id, (tk_job_text)k, texts[k], err);
    /* the frames are the last nframes of job->frames */
    for (size_t i = 0; !status && i < nframes; i++)
        status = add_frame_locked(s, job->id, job->frames - nframes + i, &frames[i], err);
    if (!status && sqlite3_exec(s->db, "COMMIT", NULL, NULL, NULL) != SQLITE_OK)
        status = db_error(s, err, "committing");
    if (status)
        sqlite3_exec(s->db, "ROLLBACK", NULL, NULL, NULL);
    written(s, status, err);
    pthread_mutex_unlock(&s->lock);
    return status;
}

int tk_store_delete(tk_store *s, int64_t id, tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(s->db, "DELETE FROM jobs WHERE id = ?", -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, id);
        rc = sqlite3_step(st);
    }
    sqlite3_finalize(st);
    int status = rc == SQLITE_DONE ? TK_OK : db_error(s, err, "deleting a job");
    if (!status && sqlite3_changes(s->db) == 0)
        status = tk_error_set(err, TK_ENOTFOUND, "no job %lld", (long long)id);
    else
        written(s, status, err);
    pthread_mutex_unlock(&s->lock);
    return status;
}

void tk_store_report_damage(tk_store *s, const char *what)
{
    pthread_mutex_lock(&s->lock);
    if (!s->damage[0])
        snprintf(s->damage, sizeof s->damage, "%s", what);
    pthread_mutex_unlock(&s->lock);
}

bool tk_store_health(tk_store *s, char *reason, size_t size)
{
    pthread_mutex_lock(&s->lock);
    bool ok = true;
    /* The file system first: a full or read-only one fails the next
     * write, and health should say so before a job finds out. */
    if (s->damage[0]) {
        snprintf(reason, size, "the job store is damaged: %s", s->damage);
        pthread_mutex_unlock(&s->lock);
        return false;
    }
    const char *file = sqlite3_db_filename(s->db, "main");
    char dir[4096];
    const char *slash = file ? strrchr(file, '/') : NULL;
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - file) + 1 : 1, slash ? file : ".");
    struct statvfs fs;
    bool known = file && *file && statvfs(dir, &fs) == 0;
    if (known && (fs.f_flag & ST_RDONLY)) {
        ok = false;
        snprintf(reason, size, "the job store's file system is read-only: jobs cannot be stored");
    } else if (known && (double)fs.f_bavail * (double)fs.f_frsize < STORE_SPACE_MIN) {
        ok = false;
        snprintf(reason, size,
                 "the job store's file system is full (%.0f KiB free): jobs cannot be stored",
                 (double)fs.f_bavail * (double)fs.f_frsize / 1024.0);
    } else if (sqlite3_db_readonly(s->db, "main") == 1) {
        ok = false;
        snprintf(reason, size, "the job store is read-only: jobs cannot be stored");
    } else if (s->write_error[0]) {
        ok = false;
        snprintf(reason, size, "the last write to the job store failed: %s", s->write_error);
    } else {
        /* A read that walks to the newest row: a damaged file shows here
         * as "malformed" before a client's read finds it. */
        sqlite3_stmt *st = NULL;
        int rc = sqlite3_prepare_v2(s->db,
                                    "SELECT id, length(input), state FROM jobs"
                                    " ORDER BY id DESC LIMIT 1",
                                    -1, &st, NULL);
        while (rc == SQLITE_OK || rc == SQLITE_ROW)
            rc = sqlite3_step(st);
        if (rc != SQLITE_DONE) {
            ok = false;
            snprintf(reason, size, "the job store cannot be read: %s", sqlite3_errmsg(s->db));
        }
        sqlite3_finalize(st);
    }
    if (ok && size)
        reason[0] = '\0';
    pthread_mutex_unlock(&s->lock);
    return ok;
}

int tk_store_text(tk_store *s, int64_t id, tk_job_text which, char **out, size_t *len,
                  tk_error *err)
{
    *out = NULL;
    if (len)
        *len = 0;
    char sql[96];
    snprintf(sql, sizeof sql, "SELECT %s FROM jobs WHERE id = ?", text_column(which));
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int status = TK_OK;
    int rc = sqlite3_prepare_v2(s->db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, id);
        rc = sqlite3_step(st);
    }
    if (rc == SQLITE_ROW) {
        const unsigned char *t = sqlite3_column_text(st, 0);
        if (t) {
            size_t n = (size_t)sqlite3_column_bytes(st, 0);
            *out = malloc(n + 1);
            if (!*out) {
                status = tk_error_set(err, TK_ENOMEM, "out of memory");
            } else {
                memcpy(*out, t, n + 1);
                if (len)
                    *len = n;
            }
        }
    } else if (rc == SQLITE_DONE) {
        status = tk_error_set(err, TK_ENOTFOUND, "there is no job %lld", (long long)id);
    } else {
        status = db_error(s, err, "reading a job's text");
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->lock);
    return status;
}

int tk_store_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_store_frame **out,
                    size_t *n, tk_error *err)
{
    *n = 0;
    *out = limit ? calloc(limit, sizeof **out) : NULL;
    if (limit && !*out)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int status = TK_OK;
    int rc = sqlite3_prepare_v2(s->db,
                                "SELECT step, xyz, layout FROM frames WHERE job = ? AND seq >= ?"
                                " ORDER BY seq LIMIT ?",
                                -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)offset);
        sqlite3_bind_int64(st, 3, (sqlite3_int64)limit);
        while (!status && *n < limit && (rc = sqlite3_step(st)) == SQLITE_ROW) {
            tk_store_frame *f = &(*out)[*n];
            size_t bytes = (size_t)sqlite3_column_bytes(st, 1);
            const unsigned char *layout = sqlite3_column_text(st, 2);
            f->step = (long)sqlite3_column_int64(st, 0);
            f->count = bytes / sizeof(double);
            f->xyz = malloc(bytes ? bytes : 1);
            f->layout = layout ? strdup((const char *)layout) : NULL;
            (*n)++;
            if (!f->xyz || (layout && !f->layout))
                status = tk_error_set(err, TK_ENOMEM, "out of memory for frames");
            else if (bytes)
                memcpy(f->xyz, sqlite3_column_blob(st, 1), bytes);
        }
        if (!status && rc != SQLITE_DONE && rc != SQLITE_ROW)
            status = db_error(s, err, "reading frames");
    } else {
        status = db_error(s, err, "reading frames");
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->lock);
    if (status) {
        tk_store_frames_free(*out, *n);
        *out = NULL;
        *n = 0;
    }
    return status;
}

void tk_store_frames_free(tk_store_frame *frames, size_t n)
{
    for (size_t i = 0; frames && i < n; i++) {
        free(frames[i].xyz);
        free(frames[i].layout);
    }
    free(frames);
}

int tk_store_unfinished(tk_store *s, int64_t **ids, size_t *n, tk_error *err)
{
    *ids = NULL;
    *n = 0;
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int status = TK_OK;
    size_t cap = 0;
    int rc = sqlite3_prepare_v2(s->db,
                                "SELECT id FROM jobs WHERE state IN ('queued', 'running')"
                                " ORDER BY id",
                                -1, &st, NULL);
    while (rc == SQLITE_OK || rc == SQLITE_ROW) {
        rc = sqlite3_step(st);
        if (rc != SQLITE_ROW)
            break;
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            int64_t *grown = realloc(*ids, cap * sizeof **ids);
            if (!grown) {
                status = tk_error_set(err, TK_ENOMEM, "out of memory");
                break;
            }
            *ids = grown;
        }
        (*ids)[(*n)++] = sqlite3_column_int64(st, 0);
    }
    if (!status && rc != SQLITE_DONE)
        status = db_error(s, err, "listing unfinished jobs");
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->lock);
    if (status) {
        free(*ids);
        *ids = NULL;
        *n = 0;
    }
    return status;
}

int tk_store_count_states(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err)
{
    for (int i = 0; i < TK_JOB_STATES; i++)
        counts[i] = 0;
    pthread_mutex_lock(&s->lock);
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(s->db, "SELECT state, count(*) FROM jobs GROUP BY state", -1,
                                &st, NULL);
    while (rc == SQLITE_OK || rc == SQLITE_ROW) {
        rc = sqlite3_step(st);
        if (rc != SQLITE_ROW)
            break;
        tk_job_state state;
        const unsigned char *name = sqlite3_column_text(st, 0);
        if (name && tk_job_state_parse((const char *)name, &state))
            counts[state] = (size_t)sqlite3_column_int64(st, 1);
    }
    int status = rc == SQLITE_DONE ? TK_OK : db_error(s, err, "counting jobs");
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->lock);
    return status;
}
