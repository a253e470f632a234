/* tightknot service: the job store's interface (see store.h): each call
 * goes to the backend; what the backends share (the holder's name, the
 * health of writes and reads) is kept here. */
#include "store.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <unistd.h>

void tk_store_init(tk_store *s, const tk_store_ops *ops)
{
    s->ops = ops;
    pthread_mutex_init(&s->lock, NULL);
    char host[64] = "host";
    gethostname(host, sizeof host - 1);
    unsigned long long nonce = 0;
    if (getrandom(&nonce, sizeof nonce, 0) != (ssize_t)sizeof nonce)
        nonce = (unsigned long long)(uintptr_t)s ^ (unsigned long long)getpid();
    snprintf(s->holder, sizeof s->holder, "%.63s:%ld:%016llx", host, (long)getpid(), nonce);
}

int tk_store_open(const char *where, double lease, tk_store **out, tk_error *err)
{
    *out = NULL;
    if (!strncmp(where, "postgresql://", 13) || !strncmp(where, "postgres://", 11))
        return tk_store_pg_open(where, lease, out, err);
    return tk_store_sqlite_open(where, out, err);
}

void tk_store_close(tk_store **p)
{
    if (!p || !*p)
        return;
    pthread_mutex_destroy(&(*p)->lock);
    (*p)->ops->close(*p);
    *p = NULL;
}

bool tk_store_shared(const tk_store *s)
{
    return s->shared;
}

const char *tk_store_holder(const tk_store *s)
{
    return s->holder;
}

/* Notes a write's outcome for health: a failure to reach or write the
 * store (TK_EIO, TK_ENOMEM) until the next write that succeeds; answers
 * about the job (busy, not found, not queued) are neither.  Returns rc. */
static int written(tk_store *s, int rc, const tk_error *err)
{
    if (rc == TK_OK || rc == TK_EIO || rc == TK_ENOMEM) {
        pthread_mutex_lock(&s->lock);
        snprintf(s->write_error, sizeof s->write_error, "%s", rc ? err->message : "");
        pthread_mutex_unlock(&s->lock);
    }
    return rc;
}

int tk_store_add(tk_store *s, json_t *doc, const char *input, const tk_store_limits *limits,
                 tk_error *err)
{
    int rc = s->ops->add(s, doc, input, limits, err);
    if (rc != TK_EBUSY)
        return written(s, rc, err);
    /* which limit: the queue's, the owner's jobs, or the owner's bytes */
    const char *owner = json_string_value(json_object_get(doc, "owner"));
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

int tk_store_put(tk_store *s, const json_t *doc, const char *const *parts,
                 const tk_frame *frames, size_t first, size_t nframes, tk_error *err)
{
    return written(s, s->ops->put(s, doc, parts, frames, first, nframes, err), err);
}

int tk_store_get(tk_store *s, int64_t id, json_t **doc, tk_error *err)
{
    *doc = NULL;
    return s->ops->get(s, id, doc, err);
}

int tk_store_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err)
{
    *text = NULL;
    if (len)
        *len = 0;
    return s->ops->part(s, id, part, text, len, err);
}

int tk_store_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                  json_t **docs, size_t *total, tk_error *err)
{
    *docs = json_array();
    *total = 0;
    return s->ops->list(s, state, owner, offset, limit, docs, total, err);
}

int tk_store_claim(tk_store *s, int64_t *id, tk_error *err)
{
    *id = 0;
    return written(s, s->ops->claim(s, id, err), err);
}

int tk_store_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err)
{
    *cancel = false;
    return written(s, s->ops->renew(s, id, cancel, err), err);
}

int tk_store_requeue(tk_store *s, tk_error *err)
{
    return written(s, s->ops->requeue(s, err), err);
}

int tk_store_cancel(tk_store *s, int64_t id, tk_error *err)
{
    return written(s, s->ops->cancel(s, id, err), err);
}

int tk_store_stop(tk_store *s, int64_t id, tk_error *err)
{
    return written(s, s->ops->stop(s, id, err), err);
}

int tk_store_delete(tk_store *s, int64_t id, tk_error *err)
{
    return written(s, s->ops->remove(s, id, err), err);
}

int tk_store_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_frame **out,
                    size_t *n, tk_error *err)
{
    *out = calloc(limit ? limit : 1, sizeof **out);
    *n = 0;
    if (!*out)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    return s->ops->frames(s, id, offset, limit, out, n, err);
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
    return s->ops->counts(s, counts, err);
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
    if (!reason[0])
        s->ops->room(s, reason, size);
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
