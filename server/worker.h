/* tightknot service: the pool's slots, as its threads (pool.c) and the
 * run of one job (worker.c) share them.  The contract is pool.h's. */
#ifndef TK_SERVER_WORKER_H
#define TK_SERVER_WORKER_H

#include <pthread.h>
#include <stdatomic.h>

#include "pool.h"

typedef struct slot {
    tk_pool *pool;
    int64_t id;   /* the job it runs; 0: none */
    bool cancel;  /* its client asked to cancel it */
    bool lost;    /* the store no longer has it held here (another daemon took it) */
    tk_run *run;  /* once set up */
    json_t *doc;  /* the job's document, less the figures below */
    const tk_job_options *opts;
    tk_step_report latest; /* the latest step's figures (once measured) */
    bool measured;
    size_t frames;         /* frames taken, stored or not */
} slot;

struct tk_pool {
    tk_store *store;
    tk_pool_config cfg;
    pthread_mutex_t lock; /* guards the slots, stopping, submitted and ready */
    pthread_cond_t wake;
    pthread_t keeper;     /* renews the running jobs' claims (keeper) */
    pthread_cond_t tick;  /* wakes the keeper when the pool halts */
    bool keeping;
    bool going;           /* workers claim jobs (tk_pool_go) */
    bool stopping, joined;
    unsigned long submitted;
    slot *slots;
    pthread_t *threads;   /* threads[i] runs slots[i]; only tk_pool_start writes them */
    size_t nslots, ready;
    atomic_ullong steps_total;
    atomic_ullong busy_us;    /* microseconds the workers have run jobs */
    atomic_ullong jobs_ended; /* jobs run here to done, failed or cancelled */
};

/* The slot's job as it stands: its document with the latest figures
 * (made here, not at every step).  Lock held. */
json_t *tk_slot_doc(const slot *sl);

/* Stops the slot's run within a step: its client cancelled it, or else it
 * is lost to another daemon.  Lock held. */
void tk_slot_stop(slot *sl, bool cancel);

/* Runs the job claimed as id in sl to its end, a halt, a cancellation or
 * its loss to another daemon, and stores it (pool.h). */
void tk_worker_run(slot *sl, int64_t id);

#endif
