/* tightknot service: the queue and the workers (see pool.h). */
#define _GNU_SOURCE
#include "worker.h"

#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

/* ---- the workers ---- */

/* Workers yield to the threads answering requests: SCHED_IDLE lets a
 * request preempt a worker at once (polling p99 4-5 ms against 5-8 ms
 * with niceness alone, bench/service.sh); a failure only costs latency. */
static void set_priority(tk_priority priority)
{
    pthread_setname_np(pthread_self(), "tk-worker");
    if (priority == TK_PRIORITY_IDLE)
        pthread_setschedparam(pthread_self(), SCHED_IDLE, &(struct sched_param){0});
    if (priority != TK_PRIORITY_NORMAL)
        setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), 5);
}

/* Waits on cv at most a second.  Lock held. */
static void wait_second(tk_pool *p, pthread_cond_t *cv)
{
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += 1;
    pthread_cond_timedwait(cv, &p->lock, &until);
}

void tk_slot_stop(slot *sl, bool cancel)
{
    if (cancel)
        sl->cancel = true;
    else
        sl->lost = true;
    if (sl->run)
        tk_run_cancel(sl->run);
}

static void *worker(void *arg)
{
    slot *sl = arg;
    tk_pool *p = sl->pool;
    set_priority(p->cfg.priority);
    pthread_mutex_lock(&p->lock);
    p->ready++;
    pthread_cond_broadcast(&p->wake);
    for (;;) {
        unsigned long seen = p->submitted;
        if (p->stopping)
            break;
        if (!p->going) {
            pthread_cond_wait(&p->wake, &p->lock);
            continue;
        }
        pthread_mutex_unlock(&p->lock);
        int64_t id = 0;
        tk_error err;
        bool claimed = tk_store_claim(p->store, &id, &err) == TK_OK;
        if (claimed)
            tk_worker_run(sl, id);
        pthread_mutex_lock(&p->lock);
        if (!claimed && !p->stopping && p->submitted == seen)
            wait_second(p, &p->wake);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

/* Renews the claims of the jobs running here every second (a lease is
 * several), and passes on a cancellation asked through another daemon or
 * a job lost to one (its lease ran out while the store was out of reach). */
static void *keeper(void *arg)
{
    tk_pool *p = arg;
    pthread_setname_np(pthread_self(), "tk-keeper");
    int64_t *ids = calloc(p->nslots, sizeof *ids);
    pthread_mutex_lock(&p->lock);
    while (ids && !p->stopping) {
        for (size_t i = 0; i < p->nslots; i++)
            ids[i] = p->slots[i].lost ? 0 : p->slots[i].id;
        pthread_mutex_unlock(&p->lock);
        for (size_t i = 0; i < p->nslots; i++) {
            bool cancel = false;
            tk_error err;
            int rc = ids[i] ? tk_store_renew(p->store, ids[i], &cancel, &err) : TK_EIO;
            if (rc != TK_ENOTFOUND && !cancel)
                continue; /* held (or the store out of reach: the next round tries again) */
            pthread_mutex_lock(&p->lock);
            if (p->slots[i].id == ids[i]) /* still the same job */
                tk_slot_stop(&p->slots[i], cancel);
            pthread_mutex_unlock(&p->lock);
        }
        pthread_mutex_lock(&p->lock);
        if (!p->stopping)
            wait_second(p, &p->tick);
    }
    pthread_mutex_unlock(&p->lock);
    free(ids);
    return NULL;
}

int tk_pool_start(tk_store *store, const tk_pool_config *cfg, tk_pool **out, tk_error *err)
{
    *out = NULL;
    tk_pool *p = calloc(1, sizeof *p);
    if (!p || !(p->slots = calloc(cfg->workers, sizeof *p->slots))
        || !(p->threads = calloc(cfg->workers, sizeof *p->threads))) {
        if (p)
            free(p->slots);
        free(p);
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    }
    p->store = store;
    p->cfg = *cfg;
    p->cfg.history = cfg->history > 2 ? cfg->history : 2; /* the first and the latest */
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    pthread_cond_init(&p->tick, NULL);
    int rc = tk_store_requeue(store, err);
    for (size_t i = 0; !rc && i < cfg->workers; i++) {
        p->slots[i].pool = p;
        if (pthread_create(&p->threads[i], NULL, worker, &p->slots[i]))
            rc = tk_error_set(err, TK_ENOMEM, "cannot start worker thread %zu", i + 1);
        else
            p->nslots++;
    }
    /* up once every worker has its name and priority */
    pthread_mutex_lock(&p->lock);
    while (p->ready < p->nslots)
        pthread_cond_wait(&p->wake, &p->lock);
    pthread_mutex_unlock(&p->lock);
    if (!rc && pthread_create(&p->keeper, NULL, keeper, p))
        rc = tk_error_set(err, TK_ENOMEM, "cannot start the thread that renews claims");
    p->keeping = !rc;
    if (rc)
        tk_pool_free(&p);
    *out = p;
    return rc;
}

void tk_pool_go(tk_pool *p)
{
    pthread_mutex_lock(&p->lock);
    p->going = true;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
}

void tk_pool_halt(tk_pool *p)
{
    pthread_mutex_lock(&p->lock);
    bool joined = p->joined;
    p->stopping = p->joined = true;
    for (size_t i = 0; i < p->nslots; i++)
        if (p->slots[i].run)
            tk_run_cancel(p->slots[i].run);
    pthread_cond_broadcast(&p->wake);
    pthread_cond_broadcast(&p->tick);
    pthread_mutex_unlock(&p->lock);
    for (size_t i = 0; !joined && i < p->nslots; i++)
        pthread_join(p->threads[i], NULL);
    if (!joined && p->keeping)
        pthread_join(p->keeper, NULL);
}

void tk_pool_free(tk_pool **pp)
{
    if (!pp || !*pp)
        return;
    tk_pool_halt(*pp);
    pthread_cond_destroy(&(*pp)->wake);
    pthread_cond_destroy(&(*pp)->tick);
    pthread_mutex_destroy(&(*pp)->lock);
    free((*pp)->slots);
    free((*pp)->threads);
    free(*pp);
    *pp = NULL;
}

int tk_pool_submit(tk_pool *p, json_t *doc, const char *input, tk_error *err)
{
    pthread_mutex_lock(&p->lock);
    bool stopping = p->stopping;
    pthread_mutex_unlock(&p->lock);
    int rc = stopping ? tk_error_set(err, TK_EBUSY, "the service is shutting down")
                      : tk_store_add(p->store, doc, input,
                                     &(tk_store_limits){p->cfg.queue_limit, p->cfg.per_owner,
                                                        p->cfg.owner_bytes},
                                     err);
    pthread_mutex_lock(&p->lock);
    p->submitted++;
    pthread_cond_signal(&p->wake);
    pthread_mutex_unlock(&p->lock);
    return rc;
}

/* The slot running job id, or NULL.  Lock held. */
static slot *running(tk_pool *p, int64_t id)
{
    for (size_t i = 0; i < p->nslots; i++)
        if (p->slots[i].id == id)
            return &p->slots[i];
    return NULL;
}

json_t *tk_pool_live(tk_pool *p, int64_t id)
{
    pthread_mutex_lock(&p->lock);
    slot *sl = running(p, id);
    json_t *doc = sl ? tk_slot_doc(sl) : NULL;
    pthread_mutex_unlock(&p->lock);
    return doc;
}

int tk_pool_cancel(tk_pool *p, int64_t id, json_t **doc, tk_error *err)
{
    *doc = NULL;
    int rc = TK_EINVAL;
    /* queued: cancelled now; running: marked (another daemon learns it at
     * its next renewal); between the two a moment ago: ask again */
    for (int tries = 0; tries < 3 && rc == TK_EINVAL; tries++) {
        rc = tk_store_cancel(p->store, id, err);
        if (rc == TK_OK)
            return tk_store_get(p->store, id, doc, err);
        if (rc == TK_EINVAL)
            rc = tk_store_stop(p->store, id, err);
    }
    if (rc == TK_EINVAL) { /* neither queued nor running: ended, or none */
        if ((rc = tk_store_get(p->store, id, doc, err)) != TK_OK)
            return rc;
        tk_job_state s = tk_job_state_in(*doc);
        json_decref(*doc);
        *doc = NULL;
        return tk_error_set(err, TK_EINVAL, "job %lld has ended (%s)", (long long)id,
                            tk_job_states[s]);
    }
    if (rc)
        return rc;
    pthread_mutex_lock(&p->lock);
    slot *sl = running(p, id);
    if (sl) { /* running here: it stops within a step */
        tk_slot_stop(sl, true);
        *doc = tk_slot_doc(sl);
    }
    pthread_mutex_unlock(&p->lock);
    return sl ? TK_OK : tk_store_get(p->store, id, doc, err);
}

void tk_pool_stats_get(tk_pool *p, tk_pool_stats *out)
{
    memset(out, 0, sizeof *out);
    pthread_mutex_lock(&p->lock);
    out->workers = p->nslots;
    out->queue_limit = p->cfg.queue_limit;
    for (size_t i = 0; i < p->nslots; i++) {
        if (!p->slots[i].id)
            continue;
        out->running++;
        const tk_step_report *r = &p->slots[i].latest;
        if (p->slots[i].run && r->step > 0 && r->seconds > 0.0)
            out->steps_per_second += (double)r->step / r->seconds;
    }
    pthread_mutex_unlock(&p->lock);
    out->steps_total = atomic_load(&p->steps_total);
    out->jobs_ended = atomic_load(&p->jobs_ended);
    out->busy_seconds = 1e-6 * (double)atomic_load(&p->busy_us);
}

