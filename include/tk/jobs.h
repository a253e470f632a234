/* tightknot: the job queue and the worker pool of the service.
 *
 * Submitting stores a job and puts its id on a FIFO queue; a fixed pool of
 * worker threads takes ids off the queue and runs the engine.  While a job
 * runs, its figures live in the worker's slot (read by tk_jobs_get on every
 * poll) and are written to the store every few seconds and at the end,
 * with the curve, so that a restart takes the job up where it was.
 *
 * When the store cannot be written (a full disk), a running job pauses:
 * its worker retries the write every second and goes on once it
 * succeeds; the job reads `running` with its error saying why it waits.
 * A job is never failed for the store's sake, and a stop while paused
 * leaves it as last stored, to resume at the next start.
 *
 * Request handlers only call these functions; none of them runs the
 * engine's flow.
 */
#ifndef TK_JOBS_H
#define TK_JOBS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tk/curve.h"
#include "tk/error.h"
#include "tk/store.h"

/* How the worker threads yield the CPU to the threads answering requests
 * (Linux scheduling; elsewhere they run as any thread). */
typedef enum tk_worker_priority {
    TK_WORKERS_IDLE = 0,   /* SCHED_IDLE: they run only on CPU nothing else
                              wants, and a request preempts them at once */
    TK_WORKERS_LOW,        /* niceness 5: a smaller share next to busy threads */
    TK_WORKERS_NORMAL      /* like every other thread */
} tk_worker_priority;

/* "idle", "low" or "normal"; false for anything else. */
bool tk_worker_priority_parse(const char *text, tk_worker_priority *out);

typedef struct tk_jobs_config {
    size_t workers;        /* threads running the engine (>= 1) */
    tk_worker_priority priority;
    size_t queue_limit;    /* queued jobs beyond this are refused (TK_EBUSY) */
    size_t max_vertices;   /* a run's vertex count limit, after re-resolution */
    double flush_seconds;  /* how often a running job is written to the store */
    size_t history_limit;  /* history entries kept per job (decimated beyond) */
} tk_jobs_config;

#define TK_JOBS_CONFIG_INIT {2, TK_WORKERS_IDLE, 1000, 1000000, 2.0, 2000}

/* What a job may keep of its frames: at most this many, and at most this
 * many bytes of them (a frame of V vertices is 24 V bytes); frames due
 * beyond either are not kept.  Bounds the store's growth per job. */
#define TK_JOB_MAX_FRAMES 1000
#define TK_JOB_MAX_FRAME_BYTES (256u << 20)

typedef struct tk_jobs tk_jobs;

/* Starts the workers; jobs the store holds as queued or running (left by
 * a restart or a crash) are queued again first, oldest first. */
int tk_jobs_start(tk_store *store, const tk_jobs_config *cfg, tk_jobs **out, tk_error *err);

/* Stops taking jobs, stops the running ones within a step and stores them
 * as queued (with their curve) so that the next start resumes them, then
 * joins the workers. */
void tk_jobs_stop(tk_jobs **p);

/* The first half of tk_jobs_stop: the workers stopped and joined, the
 * jobs stored, but the pool still there, so that request threads still
 * running can call it (submissions get TK_EBUSY); free it with
 * tk_jobs_stop once no request thread can.  Only one thread may halt. */
void tk_jobs_halt(tk_jobs *j);

/* The job record of a submission, once a run is seen to start from curve
 * with the options: the vertex limit, re-resolution within it, and the
 * run's own set-up (resampling, autoscale, thickness), without taking a
 * step.  Fails with TK_EINVAL, TK_ELIMIT or TK_ENUMERIC and the reason.
 * The record is queued with the default step limit when no stop
 * criterion is set; it has no id until stored. */
int tk_job_prepare(const char *name, const tk_job_options *opts, const tk_curve *curve,
                   size_t max_vertices, tk_job *job, tk_error *err);

/* Validates and queues a job: `curve` is the parsed `vect` text.  The
 * options are checked by setting up a run (re-resolution, autoscale,
 * thickness) without taking a step.  Fails with TK_EINVAL (bad options or
 * a start the run refuses), TK_ELIMIT (too many vertices) or TK_EBUSY
 * (queue full).  On success *job is the stored job. */
int tk_jobs_submit(tk_jobs *j, const char *name, const tk_job_options *opts,
                   const tk_curve *curve, const char *vect, tk_job *job, tk_error *err);

/* The job as it is now (live figures while it runs); TK_ENOTFOUND. */
int tk_jobs_get(tk_jobs *j, int64_t id, tk_job *out, tk_error *err);

/* Cancels a queued job at once, or asks a running one to stop (it does
 * within a step).  TK_EINVAL when the job has already finished (the
 * caller may then delete it from the store: no worker touches it again). */
int tk_jobs_cancel(tk_jobs *j, int64_t id, tk_job *out, tk_error *err);

typedef struct tk_jobs_stats {
    size_t queued;          /* waiting in the queue */
    size_t running;         /* being run by workers */
    size_t workers;
    size_t queue_limit;
    unsigned long long steps_total; /* steps taken since start */
    double steps_per_second;        /* over the running jobs */
} tk_jobs_stats;

void tk_jobs_stats_get(tk_jobs *j, tk_jobs_stats *out);

#endif
