/* tightknot service: one job's run on a worker (see pool.h and worker.h). */
#define _GNU_SOURCE
#include "worker.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "jsonmap.h"
#include "record.h"

/* A job being run. */
typedef struct job_run {
    slot *slot;
    tk_pool *pool;
    tk_job_options opts;
    tk_run *run;
    json_t *before;          /* a resumed job's history before its resume */
    tk_frame *pending;       /* frames taken since the last write */
    size_t npending;
    size_t stored;           /* frames in the store */
    long frame_after;        /* frames are due after this step */
    long last_step;          /* the last step reported, -1 before */
    double last_flush;
    bool rebase;             /* the store paused the run: it goes on in another (rebase) */
    double clock;            /* the run's seconds when the store paused it */
    tk_invariants input_type; /* the type of the job's input */
    tk_invariants refused;    /* that of a stored curve the engine refused */
} job_run;

/* ---- frames ---- */

static void drop_frame(job_run *jr)
{
    jr->npending--;
    free(jr->pending[jr->npending].xyz);
    free(jr->pending[jr->npending].layout);
}

/* Keeps the curve as a frame when its step is on the `every` grid: the
 * worker's frames, not the engine's snapshots, keep the job's grid across
 * a resume and the vertices of their step (the run resamples). */
static void take_frame(job_run *jr, long step, bool again)
{
    long every = jr->opts.every;
    if (every <= 0 || step % every != 0)
        return;
    if (again && step == jr->frame_after && jr->stored + jr->npending > 0) {
        if (jr->npending) /* the step reported again: its frame taken again */
            drop_frame(jr);
        else
            jr->stored--; /* rewritten in its place */
        jr->frame_after = step - 1;
    }
    const tk_curve *c = tk_run_curve(jr->run);
    size_t per = 3 * c->nvert, most = TK_MAX_FRAME_BYTES / (per * sizeof(double));
    if (step <= jr->frame_after || jr->stored + jr->npending >= (most < TK_MAX_FRAMES ? most
                                                                                    : TK_MAX_FRAMES))
        return;
    tk_frame *grown = realloc(jr->pending, (jr->npending + 1) * sizeof *grown);
    if (grown) /* else out of memory: this frame is left out */
        jr->pending = grown;
    tk_frame f = {step, grown ? malloc(per * sizeof(double)) : NULL, per, tk_record_layout(c)};
    if (f.xyz && f.layout) {
        memcpy(f.xyz, c->xyz, per * sizeof(double));
        jr->pending[jr->npending++] = f;
        jr->frame_after = step;
    } else {
        free(f.xyz);
        free(f.layout);
    }
}

/* ---- storing ---- */

json_t *tk_slot_doc(const slot *sl)
{
    json_t *doc = json_deep_copy(sl->doc);
    if (sl->measured) {
        tk_job_set_figures(doc, &sl->latest, sl->opts);
        json_object_set_new(doc, "frames", json_integer((json_int_t)sl->frames));
    }
    return doc;
}

/* {"start", "result"}: the input's type and the run's at its last check. */
static json_t *invariants_json(const job_run *jr)
{
    const tk_invariants *start = jr->input_type.ncomp ? &jr->input_type
                                 : jr->run            ? tk_run_type_start(jr->run)
                                                      : NULL;
    return json_pack("{s:o, s:o}", "start", tk_json_invariants(start), "result",
                     tk_json_invariants(jr->run ? tk_run_type_latest(jr->run) : &jr->refused));
}

/* The pending frames after the first `fit` are refused (beyond the
 * owner's bytes): dropped, and counted in the document. */
static void refuse(job_run *jr, size_t fit)
{
    size_t n = jr->npending - fit;
    while (jr->npending > fit)
        drop_frame(jr);
    /* the step reported again at a resume takes no stored frame's place */
    jr->frame_after = fit ? jr->pending[fit - 1].step : -1;
    pthread_mutex_lock(&jr->pool->lock);
    tk_job_add(jr->slot->doc, "frames_refused", (double)n, true);
    jr->slot->frames = jr->stored + jr->npending;
    pthread_mutex_unlock(&jr->pool->lock);
}

/* Writes the job with the parts given and the pending frames that fit
 * in its owner's bytes; the document counts those refused. */
static int put(job_run *jr, char *const *parts, const json_t *end, tk_error *err)
{
    size_t fit = 0;
    int rc;
    do {
        pthread_mutex_lock(&jr->pool->lock);
        json_t *doc = tk_slot_doc(jr->slot);
        pthread_mutex_unlock(&jr->pool->lock);
        json_object_update(doc, (json_t *)end);
        rc = tk_store_put(jr->pool->store, doc, (const char *const *)parts, jr->pending,
                          jr->stored, jr->npending, jr->pool->cfg.owner_bytes, &fit, err);
        json_decref(doc);
        if (rc == TK_ELIMIT)
            refuse(jr, fit);
    } while (rc == TK_ELIMIT);
    return rc;
}

/* Writes the job's document, parts and new frames in one transaction
 * (NULL run: the document alone).  `end` (or NULL): the fields of the
 * job's end, shown only once written. */
static int flush(job_run *jr, const json_t *end, tk_error *err)
{
    char *parts[TK_PARTS] = {NULL};
    int rc = TK_OK;
    if (jr->run)
        rc = tk_record_parts(jr->run, jr->before, jr->pool->cfg.history, parts, err);
    json_t *type = jr->run || jr->refused.ncomp || jr->input_type.ncomp ? invariants_json(jr)
                                                                         : NULL;
    size_t ne = 0;
    const tk_escape *e = jr->run ? tk_run_escapes(jr->run, &ne) : NULL;
    json_t *basins = jr->run ? tk_json_basins(e, ne, tk_run_latest(jr->run)->ropelength) : NULL;
    pthread_mutex_lock(&jr->pool->lock);
    if (type)
        json_object_set_new(jr->slot->doc, "invariants", type);
    if (basins)
        json_object_set_new(jr->slot->doc, "basins", basins);
    pthread_mutex_unlock(&jr->pool->lock);
    if (!rc)
        rc = put(jr, parts, end, err);
    if (!rc) {
        jr->stored += jr->npending;
        while (jr->npending)
            drop_frame(jr);
    } else if (rc == TK_ENOTFOUND) { /* another daemon took it up: stop, unwritten */
        pthread_mutex_lock(&jr->pool->lock);
        tk_slot_stop(jr->slot, false);
        pthread_mutex_unlock(&jr->pool->lock);
    }
    for (int k = 0; k < TK_PARTS; k++)
        free(parts[k]);
    return rc;
}

/* Whether the worker should let go of its job: the pool halts, the job
 * is held elsewhere now, or (unless it has ended) it is cancelled. */
static bool letting_go(job_run *jr, bool ended)
{
    pthread_mutex_lock(&jr->pool->lock);
    bool go = jr->pool->stopping || jr->slot->lost || (!ended && jr->slot->cancel);
    pthread_mutex_unlock(&jr->pool->lock);
    return go;
}

/* Writes the job, pausing while the store refuses (pool.h); `end` as for
 * flush.  TK_OK once written; TK_ENOTFOUND when held elsewhere now; the
 * store's failure when the pool halts or the job is cancelled first.  The
 * pause counts from the first try (a lost server can take seconds to
 * refuse); a running job goes on in a run whose clock leaves it out. */
static int store_job(job_run *jr, const json_t *end)
{
    tk_error err;
    bool paused = false, ended = end != NULL;
    double t0 = tk_clock_seconds(), clock = jr->slot->latest.seconds; /* only this thread writes it */
    int rc;
    while ((rc = flush(jr, end, &err)) != TK_OK && !letting_go(jr, ended)) {
        pthread_mutex_lock(&jr->pool->lock);
        json_object_set_new(jr->slot->doc, "error",
                            json_sprintf("paused: storing the job failed, retrying every second:"
                                         " %.240s", err.message));
        pthread_mutex_unlock(&jr->pool->lock);
        paused = true;
        nanosleep(&(struct timespec){1, 0}, NULL);
    }
    pthread_mutex_lock(&jr->pool->lock);
    if (paused) {
        json_object_set_new(jr->slot->doc, "error", json_null());
        tk_job_add(jr->slot->doc, "paused_seconds", tk_clock_seconds() - t0, false);
    }
    pthread_mutex_unlock(&jr->pool->lock);
    if (paused && !ended && !jr->rebase) {
        jr->rebase = true;
        jr->clock = clock;
    }
    if (paused && !letting_go(jr, ended))
        flush(jr, end, &err); /* without the pause's message */
    return rc;
}

static int on_step(const tk_step_report *r, void *user)
{
    job_run *jr = user;
    tk_pool *p = jr->pool;
    bool again = r->step == jr->last_step;
    jr->last_step = r->step;
    take_frame(jr, r->step, again);
    if (r->step > 0 && !again)
        atomic_fetch_add(&p->steps_total, 1);
    pthread_mutex_lock(&p->lock);
    jr->slot->latest = *r;
    jr->slot->measured = true;
    jr->slot->frames = jr->stored + jr->npending;
    bool go = p->stopping || jr->slot->cancel || jr->slot->lost;
    pthread_mutex_unlock(&p->lock);
    if (!go && tk_clock_seconds() - jr->last_flush >= p->cfg.flush_seconds) {
        store_job(jr, NULL);
        jr->last_flush = tk_clock_seconds();
        go = letting_go(jr, false) || jr->rebase; /* a paused store may have waited through either */
    }
    return go;
}

/* The engine's clock includes a pause of the store; a job's time budget
 * is for work.  So after a pause the run goes on in a new one resumed from
 * it, as after a restart: the same curve, schedule, escapes and best
 * curve; the history before the resume kept here. */
static int rebase(job_run *jr, tk_error *err)
{
    tk_resume at;
    tk_step_report report;
    tk_run_resume_point(jr->run, &at);
    /* its clock when the pause began: the stop that ended it may have
     * measured the curve (the escapes' best put back) since */
    at.seconds = fmin(at.seconds, jr->clock);
    const tk_curve *best = tk_run_best(jr->run, &report);
    char *text = tk_record_history(jr->run, jr->before, jr->pool->cfg.history);
    json_t *before = text ? tk_record_history_before(text, at.step) : NULL;
    free(text);
    tk_run *run = NULL;
    int rc = !before ? tk_error_set(err, TK_ENOMEM, "out of memory")
                     : tk_run_resume(tk_run_curve(jr->run), tk_run_options(jr->run), &at, best,
                                     best ? &report : NULL, &jr->input_type, &run, err);
    jr->rebase = false;
    if (rc) {
        json_decref(before);
        return rc;
    }
    json_decref(jr->before);
    jr->before = before;
    tk_run_set_progress(run, on_step, jr);
    pthread_mutex_lock(&jr->pool->lock);
    tk_run *old = jr->run;
    jr->run = jr->slot->run = run;
    if (jr->slot->cancel || jr->slot->lost || jr->pool->stopping)
        tk_run_cancel(run);
    pthread_mutex_unlock(&jr->pool->lock);
    tk_run_free(&old);
    return TK_OK;
}

/* A line of the pool's log: the time, the job, what happened. */
static void say(tk_pool *p, int64_t id, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void say(tk_pool *p, int64_t id, const char *fmt, ...)
{
    if (!p->cfg.log)
        return;
    char line[256], now[32];
    tk_time_iso(now);
    size_t n = (size_t)snprintf(line, sizeof line, "%s job %lld: ", now, (long long)id);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line + n, sizeof line - n, fmt, ap);
    va_end(ap);
    fprintf(p->cfg.log, "tightknotd: %s\n", line); /* one call: lines never interleave */
    fflush(p->cfg.log);
}

/* ---- setting a run up ---- */

/* The job's run as the command line would make it, from its input or
 * from where it was interrupted. */
static int setup(job_run *jr, const json_t *doc, tk_error *err)
{
    tk_curve *input = NULL;
    tk_options o = jr->opts.run;
    o.snapshot_every = 0; /* frames are the worker's (take_frame) */
    int rc = tk_record_curve(jr->pool->store, jr->slot->id, TK_PART_INPUT,
                             jr->pool->cfg.max_vertices, &input, err);
    if (!rc)
        rc = tk_invariants_compute(input, &jr->input_type, err);
    long step = tk_job_step(doc);
    if (!rc && step > 0) {
        rc = tk_record_resume(jr->pool->store, doc, &o, jr->pool->cfg.max_vertices,
                              &jr->input_type, &jr->refused, &jr->run, err);
        char *hist = NULL;
        if (!rc && !tk_store_part(jr->pool->store, jr->slot->id, TK_PART_HISTORY, &hist, NULL,
                                  NULL))
            jr->before = tk_record_history_before(hist, step);
        free(hist);
        jr->stored = (size_t)json_integer_value(json_object_get(doc, "frames"));
        jr->frame_after = step;
    } else if (!rc) {
        rc = tk_run_new(input, &o, &jr->run, err);
    }
    /* the polygon a resolution asks for, known once the start is measured */
    size_t wanted = rc ? 0 : tk_run_final_vertices(jr->run);
    if (wanted > jr->pool->cfg.max_vertices)
        rc = tk_error_set(err, TK_ELIMIT, "option 'resolution': %g vertices per unit "
                          "ropelength make %zu vertices; the limit is %zu",
                          o.resolution, wanted, jr->pool->cfg.max_vertices);
    tk_curve_free(&input);
    return rc;
}

void tk_worker_run(slot *sl, int64_t id)
{
    tk_pool *p = sl->pool;
    tk_error err;
    json_t *doc = NULL;
    if (tk_store_get(p->store, id, &doc, &err))
        return; /* unreadable: it stays as stored, and health says why */
    job_run jr = {.slot = sl, .pool = p, .frame_after = -1, .last_step = -1};
    double busy_from = tk_clock_seconds();
    pthread_mutex_lock(&p->lock);
    *sl = (slot){.pool = p, .id = id, .doc = doc, .opts = &jr.opts};
    pthread_mutex_unlock(&p->lock);
    int rc = tk_job_options_of(doc, &jr.opts, &err);
    if (!rc)
        rc = setup(&jr, doc, &err);
    tk_stop_reason why = TK_STOP_NONE;
    if (!rc) {
        pthread_mutex_lock(&p->lock);
        json_object_set_new(doc, "state", json_string("running"));
        /* which daemon runs it (kept when it ends: which ran it) */
        json_object_set_new(doc, "daemon", json_string(tk_store_holder(p->store)));
        if (json_is_null(json_object_get(doc, "started")))
            tk_job_stamp(doc, "started");
        json_object_set_new(doc, "components", json_integer((json_int_t)tk_run_curve(jr.run)->ncomp));
        sl->run = jr.run;
        if (sl->cancel || p->stopping)
            tk_run_cancel(jr.run);
        pthread_mutex_unlock(&p->lock);
        say(p, id, "running from step %ld", tk_job_step(doc));
        /* the start stored at once: a crash from here resumes from it */
        jr.last_flush = tk_clock_seconds();
        on_step(tk_run_latest(jr.run), &jr);
        store_job(&jr, NULL);
        tk_run_set_progress(jr.run, on_step, &jr);
        do { /* in a new run after each pause of the store (rebase) */
            rc = jr.rebase ? rebase(&jr, &err) : TK_OK;
            if (!rc)
                rc = tk_run_until(jr.run, &why, &err);
        } while (!rc && jr.rebase && !letting_go(&jr, false));
    }
    pthread_mutex_lock(&p->lock);
    sl->run = NULL;
    bool lost = sl->lost;
    tk_job_state state = rc                         ? TK_JOB_FAILED
                         : why != TK_STOP_CANCELLED ? TK_JOB_DONE
                         : sl->cancel               ? TK_JOB_CANCELLED
                                                    : TK_JOB_QUEUED; /* resumes at the next start */
    pthread_mutex_unlock(&p->lock);
    json_t *end = json_pack("{s:s, s:o}", "state", tk_job_states[state], "stop_reason",
                            state == TK_JOB_QUEUED || why == TK_STOP_NONE
                                ? json_null() : json_string(tk_stop_reason_name(why)));
    if (rc)
        json_object_set_new(end, "error", json_string(err.message));
    if (TK_JOB_FINAL(state))
        tk_job_stamp(end, "finished");
    int stored = lost ? TK_ENOTFOUND : store_job(&jr, end);
    pthread_mutex_lock(&p->lock);
    sl->id = 0;
    sl->doc = NULL;
    pthread_mutex_unlock(&p->lock);
    atomic_fetch_add(&p->busy_us, (unsigned long long)(1e6 * (tk_clock_seconds() - busy_from)));
    atomic_fetch_add(&p->jobs_ended, TK_JOB_FINAL(state) && stored == TK_OK);
    say(p, id, "%s at step %ld", stored == TK_OK          ? tk_job_states[state]
                                 : stored == TK_ENOTFOUND ? "taken up elsewhere: let go"
                                                          : "let go unstored (the store fails)",
        jr.last_step);
    json_decref(end);
    json_decref(doc);
    tk_run_free(&jr.run);
    tk_invariants_free(&jr.input_type);
    tk_invariants_free(&jr.refused);
    while (jr.npending)
        drop_frame(&jr);
    free(jr.pending);
    json_decref(jr.before);
}

