/* tightknot service: the job store (see store.h).  Every operation is
 * written once, as SQL either backend runs (store_db.h); only the claim,
 * the renewal, the requeue and the locking have a text per dialect.  Each
 * call takes a connection of its own (kept for reuse), so requests and
 * workers never wait for each other here. */
#include "store.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jsonmap.h"
#include "store_db.h"

#define MATCHING                                                                                \
    " FROM jobs WHERE ($1 IS NULL OR state = $1) AND ($2 IS NULL OR owner = $2)"

#define PART_NAME(E, col, n, sql) #col,
static const char *const part_columns[TK_PARTS] = {TK_PART_COLUMNS(PART_NAME)};
_Static_assert(TK_PARTS == 5, "tk_store_put passes the parts as $3..$7: name them there");

/* The document as stored: its id and state are the columns'. */
static char *doc_text(const json_t *doc)
{
    json_t *copy = json_copy((json_t *)doc);
    json_object_del(copy, "id");
    json_object_del(copy, "state");
    char *text = copy ? tk_json_dump(copy, false) : NULL;
    json_decref(copy);
    return text;
}

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
    void *c = store_take(s, err);
    if (!c)
        return store_written(s, TK_EIO, err);
    char *text = doc_text(doc);
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    /* under one lock across daemons: the counts see every submission before */
    rows r = {0};
    bool ok = text && db_script(s->db, c, s->db->begin) && db_script(s->db, c, s->db->lock) &&
              db_query(s->db, c, &r, s->db->add, "jxitii", text, input, (int64_t)limits->queued,
                    owner, (int64_t)limits->per_owner, (int64_t)limits->bytes);
    ok = ok && db_script(s->db, c, "COMMIT");
    int rc = !ok ? store_failed(s, c, err, "adding a job") : r.n == 1 ? TK_OK : TK_EBUSY;
    if (!rc)
        json_object_set_new(doc, "id", json_integer(rows_int(&r, 0, 0)));
    rows_free(&r);
    free(text);
    store_give(s, c);
    return rc == TK_EBUSY ? which_limit(s, owner, limits, err) : store_written(s, rc, err);
}

int tk_store_put(tk_store *s, const json_t *doc, const char *const *parts,
                 const tk_frame *frames, size_t first, size_t nframes, size_t owner_bytes,
                 size_t *fit, tk_error *err)
{
    void *c = store_take(s, err);
    if (!c)
        return store_written(s, TK_EIO, err);
    int64_t id = tk_job_id(doc);
    char *text = doc_text(doc);
    const char *const *p = parts ? parts : (const char *const[TK_PARTS]){NULL};
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    bool limited = owner && owner_bytes && nframes;
    rows r = {0};
    /* a limited write holds the submissions' lock: its count of the
     * owner's bytes stays true until it commits */
    bool ok = text && db_script(s->db, c, s->db->begin) &&
              (!limited || db_script(s->db, c, s->db->lock)) &&
              db_query(s->db, c, &r, s->db->put, "tjxxxxxitd", tk_job_states[tk_job_state_in(doc)],
                    text, p[0], p[1], p[2], p[3], p[4], id, s->holder, s->lease);
    int rc = ok && r.changed != 1
                 ? tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here", (long long)id)
                 : TK_OK;
    rows_free(&r);
    ok = ok && !rc &&
         db_query(s->db, c, NULL, "DELETE FROM frames WHERE job = $1 AND seq >= $2", "ii", id,
               (int64_t)first);
    /* the frames that fit beside all else the owner stored, this write's
     * included; when not all do, it is undone for the caller to retry */
    size_t n = 0;
    if (ok && !rc && limited && (ok = db_query(s->db, c, &r, s->db->owner_bytes, "t", owner))) {
        int64_t room = (int64_t)owner_bytes - rows_int(&r, 0, 0), size;
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
        ok = db_query(s->db, c, NULL, "INSERT INTO frames VALUES ($1, $2, $3, $4, $5)", "iiibt", id,
                   (int64_t)(first + i), (int64_t)frames[i].step, (const char *)frames[i].xyz,
                   frames[i].count * sizeof(double), frames[i].layout);
    ok = ok && !rc && db_script(s->db, c, "COMMIT");
    if (!ok && !rc)
        rc = store_failed(s, c, err, "writing a job");
    free(text);
    store_give(s, c); /* rolls back what did not commit */
    return store_written(s, rc, err);
}

/* The document of row i of (doc, id, state); NULL (TK_EPARSE, the store
 * reported damaged) when it does not read back. */
static json_t *row_doc(tk_store *s, const rows *r, size_t i, tk_error *err)
{
    json_t *doc = rows_cell(r, i, 0) ? json_loads(rows_cell(r, i, 0), 0, NULL) : NULL;
    if (json_is_object(doc) && rows_cell(r, i, 2)) {
        json_object_set_new(doc, "id", json_integer(rows_int(r, i, 1)));
        json_object_set_new(doc, "state", json_string(rows_cell(r, i, 2)));
        return doc;
    }
    json_decref(doc);
    tk_error_set(err, TK_EPARSE, "the stored document of job %lld does not read back",
                 (long long)rows_int(r, i, 1));
    tk_store_damage(s, err->message);
    return NULL;
}

/* Runs a query (db_query) on a connection of its own; its rows in *r
 * (empty when it fails: TK_EIO, saying `what` failed). */
static int ask(tk_store *s, rows *r, const char *what, tk_error *err, const char *sql,
               const char *types, ...)
{
    *r = (rows){0};
    void *c = sql ? store_take(s, err) : NULL; /* no statement here: no connection either */
    if (!c)
        return sql ? TK_EIO : TK_OK;
    va_list ap;
    va_start(ap, types);
    bool ok = db_vquery(s->db, c, r, sql, types, ap);
    va_end(ap);
    int rc = ok ? TK_OK : store_failed(s, c, err, what);
    store_give(s, c);
    return rc;
}

/* Keeps doc, job id's as read at `at`, when no write came since `writes`;
 * with doc NULL, a copy of the one kept while fresh (RECENT_AGE), or NULL. */
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
    double at = tk_clock_seconds();
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
                                                : TK_EPARSE;
    rows_free(&r);
    if (!rc && s->pg)
        recent(s, id, writes, at, *doc);
    return rc;
}

json_int_t tk_store_step(tk_store *s, const json_t *doc)
{
    json_t *stored = NULL;
    json_int_t step = (json_int_t)tk_job_step(
        tk_store_get(s, tk_job_id(doc), &stored, NULL) == TK_OK ? stored : doc);
    json_decref(stored);
    return step;
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
        *len = r.cell[0].len;
    if (!rc)
        *text = rows_steal(&r, 0, 0);
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
    *total = rc ? 0 : (size_t)rows_int(&r, 0, 0);
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
            rc = TK_EPARSE;
    rows_free(&r);
    return rc;
}

/* An UPDATE or DELETE of job $1 ($2, $3 texts or NULL); TK_EINVAL with
 * `why` when it changes nothing. */
static int change(tk_store *s, const char *sql, int64_t id, const char *two, const char *three,
                  const char *why, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "changing a job", err, sql, "ijt", id, two, three);
    if (!rc && !r.changed)
        rc = tk_error_set(err, TK_EINVAL, "job %lld %s", (long long)id, why);
    rows_free(&r);
    return store_written(s, rc, err);
}

/* Written back only while the document is the one read: a claim since
 * makes it TK_EINVAL, and the caller asks again. */
int tk_store_cancel(tk_store *s, int64_t id, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "changing a job", err, "SELECT doc FROM jobs WHERE id = $1 AND state ="
                 " 'queued'", "i", id);
    json_t *doc = !rc && r.n ? json_loads(rows_cell(&r, 0, 0), 0, NULL) : NULL;
    json_object_set_new(doc, "stop_reason", json_string("cancelled"));
    tk_job_stamp(doc, "finished");
    char *text = doc ? tk_json_dump(doc, false) : NULL;
    if (!rc && text)
        rc = change(s, "UPDATE jobs SET state = 'cancelled', doc = $2 WHERE id = $1 AND state ="
                    " 'queued' AND CAST(doc AS TEXT) = $3", id, text, rows_cell(&r, 0, 0),
                    "is not queued", err);
    else if (!rc)
        rc = store_written(s, tk_error_set(err, TK_EINVAL, "job %lld is not queued", (long long)id), err);
    free(text);
    json_decref(doc);
    rows_free(&r);
    return rc;
}

int tk_store_stop(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "UPDATE jobs SET cancel = true WHERE id = $1 AND state = 'running'", id,
                  NULL, NULL, "is not running", err);
}

int tk_store_delete(tk_store *s, int64_t id, tk_error *err)
{
    return change(s, "DELETE FROM jobs WHERE id = $1 AND state IN ('done', 'failed', 'cancelled')",
                  id, NULL, NULL, "has not ended", err);
}

int tk_store_requeue(tk_store *s, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "queueing unfinished jobs", err, s->db->requeue, "");
    rows_free(&r);
    return store_written(s, rc, err);
}

int tk_store_claim(tk_store *s, int64_t *id, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "claiming a job", err, s->db->claim, "td", s->holder, s->lease);
    *id = !rc && r.n == 1 ? rows_int(&r, 0, 0) : 0;
    if (!rc && !*id)
        rc = tk_error_set(err, TK_ENOTFOUND, "no job is queued");
    rows_free(&r);
    return store_written(s, rc, err);
}

int tk_store_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err)
{
    rows r;
    int rc = ask(s, &r, "renewing a job", err, s->db->renew, "itd", id, s->holder, s->lease);
    if (!rc && !r.n)
        rc = tk_error_set(err, TK_ENOTFOUND, "job %lld is not held here", (long long)id);
    *cancel = !rc && rows_int(&r, 0, 0) != 0;
    rows_free(&r);
    return store_written(s, rc, err);
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
        f->step = (long)rows_int(&r, i, 0);
        f->count = r.cell[i * r.ncol + 1].len / sizeof(double);
        f->xyz = (double *)(void *)rows_steal(&r, i, 1);
        f->layout = rows_steal(&r, i, 2);
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
        if ((k = (size_t)tk_job_state_of(rows_cell(&r, i, 0))) < TK_JOB_STATES)
            counts[k] = (size_t)rows_int(&r, i, 1);
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

bool tk_store_health(tk_store *s, char *reason, size_t size)
{
    reason[0] = '\0';
    pthread_mutex_lock(&s->lock);
    if (s->damage[0])
        snprintf(reason, size, "the job store is damaged: %s", s->damage);
    pthread_mutex_unlock(&s->lock);
    if (!reason[0] && s->db->room) /* PostgreSQL's full disk shows as a failed write */
        s->db->room(s->where, reason, size);
    pthread_mutex_lock(&s->lock);
    if (!reason[0] && s->write_error[0])
        snprintf(reason, size, "the last write to the job store failed: %s", s->write_error);
    pthread_mutex_unlock(&s->lock);
    if (reason[0])
        return false;
    /* a read of the newest row: damage shows here before a client finds it */
    tk_error err;
    json_t *docs = NULL;
    size_t total = 0;
    int rc = tk_store_list(s, -1, NULL, 0, 1, &docs, &total, &err);
    json_decref(docs);
    if (rc)
        snprintf(reason, size, "the job store cannot be read: %s", err.message);
    return rc == TK_OK;
}
