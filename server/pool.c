/* tightknot service: the queue and the workers (see pool.h). */
#define _GNU_SOURCE
#include "pool.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "jsonmap.h"
#include "tk/vect.h"

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
};

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A job being run. */
typedef struct job_run {
    slot *slot;
    tk_pool *pool;
    tk_job_options opts;
    tk_run *run;
    json_t *before;          /* a resumed job's history before its resume */
    tk_frame *pending;       /* frames taken since the last write */
    size_t npending, cap;
    size_t stored;           /* frames in the store */
    long frame_after;        /* frames are due after this step (a resumed
                                run's frame of its first step is stored) */
    long last_step;          /* the last step reported, -1 before */
    double last_flush;
    bool rebase;             /* the store paused the run: it goes on in another (rebase) */
    double clock;            /* the run's seconds when the store paused it */
    tk_invariants input_type; /* the type of the job's input */
    tk_invariants refused;    /* that of a stored curve the engine refused */
} job_run;

/* ---- history ---- */

/* The history as stored: the entries before a resume and the run's own
 * (the engine keeps every step), evenly thinned to at most cfg.history,
 * the first and the latest kept. */
static char *history_text(const job_run *jr)
{
    size_t n = 0, before = json_array_size(jr->before);
    const tk_step_report *h = tk_run_history(jr->run, &n);
    size_t total = before + n, keep = total < jr->pool->cfg.history ? total : jr->pool->cfg.history;
    json_t *a = json_array();
    for (size_t i = 0; i < keep; i++) {
        size_t at = tk_job_thin(i, total, keep);
        json_array_append_new(a, at < before ? json_incref(json_array_get(jr->before, at))
                                             : tk_json_step(&h[at - before]));
    }
    char *text = tk_json_dump(a, false);
    json_decref(a);
    return text;
}

/* A resumed job's stored history, the entries before its resume step (the
 * stored text ends with that step, which the run reports again). */
static json_t *history_before(const char *text, long resume)
{
    json_t *stored = text ? json_loads(text, 0, NULL) : NULL, *entry, *before = json_array();
    size_t i;
    json_array_foreach(stored, i, entry)
        if (json_integer_value(json_object_get(entry, "step")) < resume)
            json_array_append(before, entry);
    json_decref(stored);
    return before;
}

/* ---- frames ---- */

static void drop_frame(job_run *jr)
{
    jr->npending--;
    free(jr->pending[jr->npending].xyz);
    free(jr->pending[jr->npending].layout);
}

/* Keeps the curve as a frame when its step is on the `every` grid.  The
 * worker takes frames itself rather than the engine's snapshots: they
 * keep the grid of the job's steps across a resume and have the vertices
 * of their step (coarse to fine resamples). */
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
    if (jr->npending == jr->cap) {
        size_t cap = jr->cap ? 2 * jr->cap : 8;
        tk_frame *grown = realloc(jr->pending, cap * sizeof *grown);
        if (!grown)
            return; /* out of memory: this frame is left out */
        jr->pending = grown;
        jr->cap = cap;
    }
    json_t *layout = json_array();
    for (size_t k = 0; k < c->ncomp; k++)
        json_array_append_new(layout, json_integer((json_int_t)tk_curve_comp_vertices(c, k)));
    tk_frame f = {step, malloc(per * sizeof(double)), per, tk_json_dump(layout, false)};
    json_decref(layout);
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

/* The slot's job as it stands: its document with the latest figures
 * (made here, not at every step).  Lock held. */
static json_t *current(const slot *sl)
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

/* The run's resume point, its best curve and that curve's figures. */
static char *resume_text(const job_run *jr)
{
    tk_resume at;
    tk_run_resume_point(jr->run, &at);
    tk_step_report report;
    const tk_curve *best = tk_run_best(jr->run, &report);
    char *vect = NULL;
    if (best && tk_vect_to_string(best, &vect, NULL, NULL) != TK_OK)
        return NULL;
    json_t *o = json_pack("{s:o, s:o, s:o}", "at",
                          tk_json_record(tk_resume_fields, tk_resume_nfields, &at), "best",
                          vect ? json_string(vect) : json_null(), "best_report",
                          best ? tk_json_step(&report) : json_null());
    free(vect);
    char *text = tk_json_dump(o, false);
    json_decref(o);
    return text;
}

/* The store no longer has the slot's job held here: its lease ran out
 * and another daemon took it up, so this run stops without writing. */
static void lose(tk_pool *p, slot *sl)
{
    pthread_mutex_lock(&p->lock);
    sl->lost = true;
    if (sl->run)
        tk_run_cancel(sl->run);
    pthread_mutex_unlock(&p->lock);
}

/* The pending frames after the first `fit` are refused (beyond the bytes
 * the job's owner may store): dropped, and counted in the document. */
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

/* Writes the job as it stands with the parts given, its pending frames
 * while they fit in its owner's bytes: those that do not are refused,
 * and the document saying so written in their place. */
static int put(job_run *jr, char *const *parts, const json_t *end, tk_error *err)
{
    size_t fit = 0;
    int rc;
    do {
        pthread_mutex_lock(&jr->pool->lock);
        json_t *doc = current(jr->slot);
        pthread_mutex_unlock(&jr->pool->lock);
        json_object_update(doc, (json_t *)end);
        rc = tk_store_put_within(jr->pool->store, doc, (const char *const *)parts, jr->pending,
                                 jr->stored, jr->npending, jr->pool->cfg.owner_bytes, &fit, err);
        json_decref(doc);
        if (rc == TK_ELIMIT)
            refuse(jr, fit);
    } while (rc == TK_ELIMIT);
    return rc;
}

/* Writes the job's document, curve, contacts, history, resume point and
 * new frames in one transaction (NULL run: the document alone).  `end`
 * (or NULL) holds the fields of the job's end: they are written, and
 * shown once written, so no one reads an end the store does not have. */
static int flush(job_run *jr, const json_t *end, tk_error *err)
{
    char *parts[TK_PARTS] = {NULL};
    int rc = TK_OK;
    if (jr->run) {
        const tk_curve *c = tk_run_curve(jr->run);
        size_t ns = 0, nk = 0;
        const tk_strut *struts = tk_run_struts(jr->run, &ns);
        const tk_kink *kinks = tk_run_kinks(jr->run, &nk);
        json_t *o = tk_json_contacts(c, struts, ns, kinks, nk, true);
        json_object_set_new(o, "step", json_integer((json_int_t)tk_run_latest(jr->run)->step));
        json_object_set_new(o, "thickness", tk_json_number(tk_run_latest(jr->run)->thickness));
        parts[TK_PART_CONTACTS] = tk_json_dump(o, false);
        json_decref(o);
        rc = tk_vect_to_string(c, &parts[TK_PART_CURVE], NULL, err);
        parts[TK_PART_HISTORY] = history_text(jr);
        parts[TK_PART_RESUME] = resume_text(jr);
        if (!rc && (!parts[TK_PART_CONTACTS] || !parts[TK_PART_HISTORY] || !parts[TK_PART_RESUME]))
            rc = tk_error_set(err, TK_ENOMEM, "out of memory writing a job");
    }
    json_t *type = jr->run || jr->refused.ncomp || jr->input_type.ncomp ? invariants_json(jr)
                                                                         : NULL;
    pthread_mutex_lock(&jr->pool->lock);
    if (type)
        json_object_set_new(jr->slot->doc, "invariants", type);
    pthread_mutex_unlock(&jr->pool->lock);
    if (!rc)
        rc = put(jr, parts, end, err);
    if (!rc) {
        jr->stored += jr->npending;
        while (jr->npending)
            drop_frame(jr);
    } else if (rc == TK_ENOTFOUND) {
        lose(jr->pool, jr->slot);
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

/* Writes the job, pausing while the store refuses (see pool.h); `end` as
 * for flush (NULL while it runs).  TK_OK once written; TK_ENOTFOUND when
 * it is held elsewhere now; the store's failure when the pool halts or
 * the job is cancelled before a write succeeds.  The pause, from the
 * first try (a lost server can take seconds to refuse), is added to the
 * job's paused_seconds, and a running job goes on in a run whose clock
 * leaves it out (rebase). */
static int store_job(job_run *jr, const json_t *end)
{
    tk_error err;
    bool paused = false, ended = end != NULL;
    double t0 = seconds_now(), clock = jr->slot->latest.seconds; /* only this thread writes it */
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
        tk_job_add(jr->slot->doc, "paused_seconds", seconds_now() - t0, false);
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
    if (!go && seconds_now() - jr->last_flush >= p->cfg.flush_seconds) {
        store_job(jr, NULL);
        jr->last_flush = seconds_now();
        go = letting_go(jr, false) || jr->rebase; /* a paused store may have waited through either */
    }
    return go;
}

/* The engine's clock runs from a run's start, a pause of the store
 * included; a job's time budget is for work.  So after a pause the run
 * goes on in a new one resumed from it (tk_run_resume, as after a
 * restart, its clock at its latest step's): the same curve, schedule,
 * escapes and best curve; the history before the resume kept here. */
static int rebase(job_run *jr, tk_error *err)
{
    tk_resume at;
    tk_step_report report;
    tk_run_resume_point(jr->run, &at);
    /* its clock when the pause began: the stop that ended it (which puts
     * back the escapes' best curve, as a stop before a restart does) may
     * have measured the curve again since */
    at.seconds = fmin(at.seconds, jr->clock);
    const tk_curve *best = tk_run_best(jr->run, &report);
    char *text = history_text(jr);
    json_t *before = text ? history_before(text, at.step) : NULL;
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

/* A line of the pool's log: the time (UTC, milliseconds), the job, what
 * happened. */
static void say(tk_pool *p, int64_t id, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void say(tk_pool *p, int64_t id, const char *fmt, ...)
{
    if (!p->cfg.log)
        return;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    struct tm tm;
    gmtime_r(&ts.tv_sec, &tm);
    char line[256];
    size_t n = strftime(line, sizeof line, "%Y-%m-%dT%H:%M:%S", &tm);
    n += (size_t)snprintf(line + n, sizeof line - n, ".%03ldZ job %lld: ", ts.tv_nsec / 1000000,
                          (long long)id);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line + n, sizeof line - n, fmt, ap);
    va_end(ap);
    fprintf(p->cfg.log, "tightknotd: %s\n", line); /* one call: lines never interleave */
    fflush(p->cfg.log);
}

/* ---- setting a run up ---- */

static int read_curve(job_run *jr, tk_part part, tk_curve **out, tk_error *err)
{
    char *text = NULL;
    size_t len = 0;
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = jr->pool->cfg.max_vertices;
    int rc = tk_store_part(jr->pool->store, jr->slot->id, part, &text, &len, err);
    if (!rc && !text)
        rc = tk_error_set(err, TK_EIO, "job %lld has no stored curve", (long long)jr->slot->id);
    if (!rc)
        rc = tk_vect_parse(text, len, &limits, out, err);
    free(text);
    return rc;
}

/* A run from the job's stored curve and resume point (tk_run_resume); a
 * job stored without one goes on from its curve at its step. */
static int resume(job_run *jr, const tk_options *o, const json_t *doc, tk_error *err)
{
    tk_curve *curve = NULL, *best = NULL;
    char *text = NULL;
    tk_resume at = {.step = tk_job_step(doc),
                    .seconds = json_number_value(json_object_get(doc, "seconds")),
                    .start_ropelength = json_number_value(json_object_get(doc, "ropelength"))};
    tk_step_report best_report = {0};
    int rc = read_curve(jr, TK_PART_CURVE, &curve, err);
    if (!rc)
        rc = tk_store_part(jr->pool->store, jr->slot->id, TK_PART_RESUME, &text, NULL, err);
    json_t *stored = text ? json_loads(text, 0, NULL) : NULL;
    const char *vect = json_string_value(json_object_get(stored, "best"));
    tk_error why = {0};
    if (!rc && text &&
        (!stored ||
         tk_json_record_set(tk_resume_fields, tk_resume_nfields, &at, json_object_get(stored, "at"),
                            NULL, &why) ||
         (vect && (tk_vect_parse(vect, strlen(vect), NULL, &best, &why) ||
                   tk_json_record_set(tk_step_fields, tk_step_nfields, &best_report,
                                      json_object_get(stored, "best_report"), NULL, &why)))))
        rc = tk_error_set(err, TK_EIO, "the stored resume point of job %lld does not read back: %.200s",
                          (long long)jr->slot->id, stored ? why.message : "not JSON");
    if (!rc)
        rc = tk_run_resume(curve, o, &at, best, best ? &best_report : NULL, &jr->input_type,
                           &jr->run, err);
    if (rc == TK_ETYPE) /* the job's result is what was stored */
        tk_invariants_compute(curve, &jr->refused, NULL);
    json_decref(stored);
    free(text);
    tk_curve_free(&curve);
    tk_curve_free(&best);
    return rc;
}

/* The engine's run for the job, as the command line would make it: from
 * its input, or from where it was when it was interrupted. */
static int setup(job_run *jr, const json_t *doc, tk_error *err)
{
    tk_curve *input = NULL;
    tk_options o = jr->opts.run;
    o.snapshot_every = 0; /* frames are the worker's (take_frame) */
    int rc = read_curve(jr, TK_PART_INPUT, &input, err);
    if (!rc)
        rc = tk_invariants_compute(input, &jr->input_type, err);
    long step = tk_job_step(doc);
    if (!rc && step > 0) {
        rc = resume(jr, &o, doc, err);
        char *hist = NULL;
        if (!rc && !tk_store_part(jr->pool->store, jr->slot->id, TK_PART_HISTORY, &hist, NULL,
                                  NULL))
            jr->before = history_before(hist, step);
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

static void run_job(slot *sl, int64_t id)
{
    tk_pool *p = sl->pool;
    tk_error err;
    json_t *doc = NULL;
    if (tk_store_get(p->store, id, &doc, &err))
        return; /* unreadable: it stays as stored, and health says why */
    job_run jr = {.slot = sl, .pool = p, .frame_after = -1, .last_step = -1};
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
        if (json_is_null(json_object_get(doc, "started")))
            tk_job_stamp(doc, "started");
        json_object_set_new(doc, "components", json_integer((json_int_t)tk_run_curve(jr.run)->ncomp));
        sl->run = jr.run;
        if (sl->cancel || p->stopping)
            tk_run_cancel(jr.run);
        pthread_mutex_unlock(&p->lock);
        say(p, id, "running from step %ld", tk_job_step(doc));
        /* the start stored at once: a crash from here resumes from it */
        jr.last_flush = seconds_now();
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

/* ---- the workers ---- */

/* Workers yield to the threads answering requests: with SCHED_IDLE a
 * waking request preempts a worker at once (polling p99 4-5 ms against
 * 5-8 ms with niceness alone, bench/service.sh).  Linux, per thread; a
 * failure only costs latency. */
static void set_priority(tk_priority priority)
{
    pthread_setname_np(pthread_self(), "tk-worker");
    if (priority == TK_PRIORITY_IDLE)
        pthread_setschedparam(pthread_self(), SCHED_IDLE, &(struct sched_param){0});
    if (priority != TK_PRIORITY_NORMAL)
        setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), 5);
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
            run_job(sl, id);
        pthread_mutex_lock(&p->lock);
        if (!claimed && !p->stopping && p->submitted == seen) {
            struct timespec until;
            clock_gettime(CLOCK_REALTIME, &until);
            until.tv_sec += 1;
            pthread_cond_timedwait(&p->wake, &p->lock, &until);
        }
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

/* Renews the claims of the jobs running here every second (a lease is
 * several seconds), and passes on what the store says: a cancellation
 * asked through another daemon, or a job lost to one (its lease ran out
 * while this daemon could not reach the store). */
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
            slot *sl = &p->slots[i];
            if (sl->id == ids[i]) { /* still the same job */
                if (cancel)
                    sl->cancel = true;
                else
                    sl->lost = true;
                if (sl->run)
                    tk_run_cancel(sl->run);
            }
            pthread_mutex_unlock(&p->lock);
        }
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_sec += 1;
        pthread_mutex_lock(&p->lock);
        if (!p->stopping)
            pthread_cond_timedwait(&p->tick, &p->lock, &until);
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
    json_t *doc = sl ? current(sl) : NULL;
    pthread_mutex_unlock(&p->lock);
    return doc;
}

int tk_pool_cancel(tk_pool *p, int64_t id, json_t **doc, tk_error *err)
{
    *doc = NULL;
    int rc = TK_EINVAL;
    /* queued: cancelled now; running: marked, here or on another daemon
     * (which learns it at its next renewal); between the two (claimed or
     * queued again a moment ago), ask again */
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
        sl->cancel = true;
        if (sl->run)
            tk_run_cancel(sl->run);
        *doc = current(sl);
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
}
