/* tightknot service: the job queue and the worker pool.
 *
 * The contract:
 * - Ordering.  The store is the queue: a free worker claims the queued
 *   job of the earliest turn (tk_store_claim): owners take turns, round
 *   robin, and an owner's own jobs start in the order they came.
 *   tk_pool_submit stores a job and wakes a worker; idle workers look
 *   again every second.
 * - Running.  A worker runs the engine with the job's options exactly as
 *   `tightknot tighten` would, keeps the job's document current at every
 *   step (tk_pool_live) and writes it with its curve, contacts, history,
 *   resume point and new frames every flush_seconds and at the end, in
 *   one transaction.  Frames beyond the owner's owner_bytes are refused
 *   and counted (frames_refused).  A start the engine refuses fails the job.
 * - Cancellation.  A queued job is cancelled in the store at once; a
 *   running one stops within a step and is stored `cancelled`: at once
 *   here, else when its daemon next renews its claim.
 * - Claims.  A thread renews the claims of the jobs running here every
 *   second: it learns of cancellations asked through other daemons, and
 *   of jobs lost to them (a lease ran out), which stop without a write.
 * - Shutdown.  tk_pool_halt stops the running jobs within a step, stores
 *   them `queued` with their resume point, and joins the workers; the pool
 *   stays readable until tk_pool_free.
 * - Resume.  tk_pool_start queues again what SQLite holds as running (a
 *   stop or a crash; PostgreSQL leaves it to the leases); such a job goes
 *   on from its stored resume point, numbering its steps on.
 * - Store failures.  When a write fails (a full disk) the job pauses, its
 *   document's error saying why, and the write is retried every second
 *   until it succeeds or the pool halts.  The pause is counted in
 *   paused_seconds, not spent of the time budget: the run goes on in a
 *   new one resumed from it, its clock where the pause began.
 * - Locks.  One mutex guards the workers' slots; no store call and no
 *   engine step is made while it is held, so a request never waits for a
 *   worker longer than a copy of a document.
 */
#ifndef TK_SERVER_POOL_H
#define TK_SERVER_POOL_H

#include <stdio.h>

#include "store.h"

typedef enum tk_priority { TK_PRIORITY_IDLE, TK_PRIORITY_LOW, TK_PRIORITY_NORMAL } tk_priority;

typedef struct tk_pool_config {
    size_t workers;
    tk_priority priority; /* idle: workers use only CPU nothing else wants */
    size_t queue_limit;   /* queued jobs beyond which submissions are refused */
    size_t per_owner;     /* queued and running jobs a token's name may have (0: any) */
    size_t owner_bytes;   /* bytes a token's name may have stored to submit, and with its
                             frames (0: any) */
    size_t max_vertices;  /* a run's vertex limit, after re-resolution */
    double flush_seconds; /* how often a running job is written */
    size_t history;       /* history entries kept per job (thinned beyond) */
    FILE *log;            /* a line per job taken up and let go (NULL: none) */
} tk_pool_config;

/* What a job may keep of its frames: this many, this many bytes (a
 * frame of V vertices is 24 V). */
#define TK_MAX_FRAMES 1000
#define TK_MAX_FRAME_BYTES (256u << 20)

typedef struct tk_pool tk_pool;

/* Starts the workers; they take up jobs after tk_pool_go (so the daemon
 * says where it listens before the log's first job line). */
int tk_pool_start(tk_store *store, const tk_pool_config *cfg, tk_pool **out, tk_error *err);
void tk_pool_go(tk_pool *p);
void tk_pool_halt(tk_pool *p);
void tk_pool_free(tk_pool **p);

/* Queues a job: doc (tk_job_new) gets its id.  TK_EBUSY when the queue is
 * full or the pool halted. */
int tk_pool_submit(tk_pool *p, json_t *doc, const char *input, tk_error *err);

/* A job running here: a copy of its document now; NULL otherwise. */
json_t *tk_pool_live(tk_pool *p, int64_t id);

/* Cancels a queued or running job, *doc its document after (`running`
 * until it stops).  TK_EINVAL when it has ended, TK_ENOTFOUND: none. */
int tk_pool_cancel(tk_pool *p, int64_t id, json_t **doc, tk_error *err);

typedef struct tk_pool_stats {
    size_t workers, running, queue_limit;
    unsigned long long steps_total; /* steps taken since start */
    unsigned long long jobs_ended;  /* jobs run here to an end since start */
    double busy_seconds;            /* the workers' time running jobs since start */
    double steps_per_second;        /* over the running jobs */
} tk_pool_stats;
void tk_pool_stats_get(tk_pool *p, tk_pool_stats *out);

#endif
