/* tightknot: the job queue and the worker pool (see include/tk/jobs.h). */
#define _GNU_SOURCE
#include "tk/jobs.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "jsonmap.h"
#include "tk/vect.h"

/* What a worker is doing, visible to the request handlers. */
typedef struct worker_slot {
    tk_jobs *owner;
    pthread_t thread;
    bool busy;           /* holds a job */
    bool cancel;         /* the client asked to cancel it */
    tk_run *run;         /* the engine run, once set up */
    tk_job job;          /* live record, updated every step */
} worker_slot;

struct tk_jobs {
    tk_store *store;
    tk_jobs_config cfg;
    pthread_mutex_t lock; /* guards the queue, the slots and stopping */
    pthread_cond_t wake;
    int64_t *queue;       /* ring of job ids */
    size_t queue_cap, queue_head, queue_len;
    bool stopping;
    bool joined;          /* the workers have been joined (tk_jobs_halt) */
    worker_slot *slots;
    size_t nslots;
    size_t ready;         /* workers named and scheduled (see started) */
    pthread_cond_t started;
    atomic_ullong steps_total;
};

static double now_unix(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double now_monotonic(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- queue (lock held) ---- */

static bool queue_push(tk_jobs *j, int64_t id)
{
    if (j->queue_len == j->queue_cap) {
        size_t cap = j->queue_cap ? 2 * j->queue_cap : 64;
        int64_t *grown = malloc(cap * sizeof *grown);
        if (!grown)
            return false;
        for (size_t i = 0; i < j->queue_len; i++)
            grown[i] = j->queue[(j->queue_head + i) % j->queue_cap];
        free(j->queue);
        j->queue = grown;
        j->queue_cap = cap;
        j->queue_head = 0;
    }
    j->queue[(j->queue_head + j->queue_len) % j->queue_cap] = id;
    j->queue_len++;
    return true;
}

static int64_t queue_pop(tk_jobs *j)
{
    int64_t id = j->queue[j->queue_head];
    j->queue_head = (j->queue_head + 1) % j->queue_cap;
    j->queue_len--;
    return id;
}

static bool queue_remove(tk_jobs *j, int64_t id)
{
    for (size_t i = 0; i < j->queue_len; i++) {
        size_t at = (j->queue_head + i) % j->queue_cap;
        if (j->queue[at] != id)
            continue;
        for (size_t k = i; k + 1 < j->queue_len; k++)
            j->queue[(j->queue_head + k) % j->queue_cap] =
                j->queue[(j->queue_head + k + 1) % j->queue_cap];
        j->queue_len--;
        return true;
    }
    return false;
}

static worker_slot *slot_of(tk_jobs *j, int64_t id)
{
    for (size_t i = 0; i < j->nslots; i++)
        if (j->slots[i].busy && j->slots[i].job.id == id)
            return &j->slots[i];
    return NULL;
}

/* ---- history, decimated to a bounded size ---- */

typedef struct history {
    tk_step_report *items;
    size_t count, cap;
    long stride;  /* steps between kept entries */
} history;

static void history_add(history *h, const tk_step_report *r)
{
    if (r->step % h->stride != 0)
        return;
    /* the engine reports a step again when it puts its best curve back */
    if (h->count > 0 && h->items[h->count - 1].step == r->step) {
        h->items[h->count - 1] = *r;
        return;
    }
    if (h->count == h->cap) {
        /* keep every other entry: the history stays evenly spaced */
        size_t kept = 0;
        for (size_t i = 0; i < h->count; i += 2)
            h->items[kept++] = h->items[i];
        h->count = kept;
        h->stride *= 2;
        if (r->step % h->stride != 0)
            return;
    }
    h->items[h->count++] = *r;
}

/* The history as JSON text, with `latest` appended when it is newer than
 * the last kept entry. */
static char *history_json(const history *h, const tk_step_report *latest)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < h->count; i++)
        json_array_append_new(a, tk_json_step(&h->items[i]));
    if (a && latest && (h->count == 0 || h->items[h->count - 1].step < latest->step))
        json_array_append_new(a, tk_json_step(latest));
    char *text = tk_json_dump(a, false);
    json_decref(a);
    return text;
}

static double number_field(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

/* Reads a stored history back (after a restart), the entries before step
 * `resume` only: the stored text ends with the latest step, which the
 * resumed run reports again as its start (and which is not on the stride,
 * so it must not decide it). */
static void history_load(history *h, const char *text, long resume)
{
    json_t *a = text ? json_loads(text, 0, NULL) : NULL;
    size_t n = json_is_array(a) ? json_array_size(a) : 0;
    for (size_t i = 0; i < n && h->count < h->cap; i++) {
        const json_t *o = json_array_get(a, i);
        if (!(number_field(o, "step") < (double)resume))
            continue;
        tk_step_report r = {0};
        if (tk_json_record_set(tk_step_fields, tk_step_nfields, &r, o, NULL, NULL) != TK_OK)
            continue; /* not an entry as written */
        h->items[h->count++] = r;
    }
    if (h->count >= 2)
        h->stride = h->items[h->count - 1].step - h->items[h->count - 2].step;
    if (h->stride < 1)
        h->stride = 1;
    json_decref(a);
}

/* ---- running one job ---- */

typedef struct job_run {
    worker_slot *slot;
    tk_run *run;
    history hist;
    double last_flush;      /* monotonic seconds */
    size_t frames_stored;   /* frames of the job in the store */
    long frame_after;       /* frames are due at multiples of `every` after
                               this step (the resume step: its frame, if
                               due, was stored with it) */
    long last_step;         /* the last step reported (-1: none yet) */
    tk_store_frame *pending; /* frames taken since the last write */
    size_t pending_count, pending_cap;
    tk_invariants input_type; /* the type of the job's input (a resumed
                                 run's start is the stored curve) */
    tk_invariants refused;    /* the type of a stored curve the engine
                                 refused to resume from (another type) */
} job_run;

/* The type the job started from: its input's. */
static const tk_invariants *start_type(const job_run *jr)
{
    return jr->input_type.ncomp > 0 ? &jr->input_type : tk_run_type_start(jr->run);
}

/* {"start", "result"} as stored (TK_TEXT_INVARIANTS): the input's type
 * and the run's at its last check.  NULL when out of memory. */
static char *invariants_text(const job_run *jr)
{
    const tk_invariants *result = jr->run ? tk_run_type_latest(jr->run) : &jr->refused;
    json_t *o = json_pack("{s:o, s:o}", "start", tk_json_invariants(start_type(jr)), "result",
                          tk_json_invariants(result));
    char *text = tk_json_dump(o, false);
    json_decref(o);
    return text;
}

/* The run's resume point, best curve and its figures, as stored
 * (TK_TEXT_RESUME).  NULL when out of memory. */
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

/* The frames of the job: stored and pending. */
static size_t job_frames(const job_run *jr)
{
    return jr->frames_stored + jr->pending_count;
}

static void drop_pending(job_run *jr)
{
    for (size_t i = 0; i < jr->pending_count; i++) {
        free(jr->pending[i].xyz);
        free(jr->pending[i].layout);
    }
    jr->pending_count = 0;
}

/* The curve's vertices per component as JSON text, or NULL. */
static char *layout_text(const tk_curve *c)
{
    json_t *a = json_array();
    for (size_t k = 0; a && k < c->ncomp; k++)
        json_array_append_new(a, json_integer((json_int_t)tk_curve_comp_vertices(c, k)));
    char *text = tk_json_dump(a, false);
    json_decref(a);
    return text;
}

/* Keeps the curve as a frame when the job's step is on the `every` grid.
 * The worker takes the frames itself (the engine's snapshots stay off, so
 * that the run keeps its schedule: a frame has the vertices of its step,
 * coarse or re-resolved): they stay on the grid of the job's steps across
 * a resume, and a long run holds only the frames since the last write. */
static void take_frame(job_run *jr, long every, long step, bool again)
{
    if (every <= 0 || step % every != 0)
        return;
    if (again && step == jr->frame_after && job_frames(jr) > 0) {
        /* the step reported again (the run's best curve put back): its
         * frame is taken again in its place, stored or not (frames are
         * written by their place in the job's sequence) */
        if (jr->pending_count > 0) {
            jr->pending_count--;
            free(jr->pending[jr->pending_count].xyz);
            free(jr->pending[jr->pending_count].layout);
        } else {
            jr->frames_stored--;
        }
        jr->frame_after = step - 1;
    }
    if (step <= jr->frame_after)
        return;
    const tk_curve *c = tk_run_curve(jr->run);
    size_t per = 3 * c->nvert;
    size_t most = TK_JOB_MAX_FRAME_BYTES / (per * sizeof(double));
    if (job_frames(jr) >= (most < TK_JOB_MAX_FRAMES ? most : TK_JOB_MAX_FRAMES))
        return; /* the job's share of the store is used up */
    if (jr->pending_count == jr->pending_cap) {
        size_t cap = jr->pending_cap ? 2 * jr->pending_cap : 8;
        tk_store_frame *grown = realloc(jr->pending, cap * sizeof *grown);
        if (!grown)
            return; /* out of memory: this frame is left out */
        jr->pending = grown;
        jr->pending_cap = cap;
    }
    tk_store_frame f = {step, malloc(per * sizeof(double)), per, layout_text(c)};
    if (!f.xyz || !f.layout) {
        free(f.xyz);
        free(f.layout);
        return;
    }
    memcpy(f.xyz, c->xyz, per * sizeof(double));
    jr->pending[jr->pending_count++] = f;
    jr->frame_after = step;
}

static double job_fraction(const tk_job *job)
{
    double f = -1.0;
    tk_options run;
    tk_job_options_to_run(&job->options, &run);
    if (run.max_steps > 0)
        f = (double)job->latest.step / (double)run.max_steps;
    if (run.max_seconds > 0.0)
        f = fmax(f, job->latest.seconds / run.max_seconds);
    return f < 0.0 ? -1.0 : fmin(f, 1.0);
}

/* Writes the job's figures, curve, contacts, history, type, resume point
 * and new frames to the store, in one transaction: a restart finds them
 * consistent. */
static int flush_job(job_run *jr, const tk_job *job, tk_error *err)
{
    char *texts[TK_TEXTS] = {NULL};
    int rc = tk_vect_to_string(tk_run_curve(jr->run), &texts[TK_TEXT_CURVE], NULL, err);
    const tk_curve *c = tk_run_curve(jr->run);
    size_t ns = 0, nk = 0;
    const tk_strut *struts = tk_run_struts(jr->run, &ns);
    const tk_kink *kinks = tk_run_kinks(jr->run, &nk);
    if (!rc) {
        json_t *o = tk_json_contacts(c, struts, ns, kinks, nk, true);
        if (o) {
            json_object_set_new(o, "step", json_integer((json_int_t)job->latest.step));
            json_object_set_new(o, "thickness", tk_json_number(job->latest.thickness));
        }
        texts[TK_TEXT_CONTACTS] = tk_json_dump(o, false);
        json_decref(o);
        texts[TK_TEXT_HISTORY] = history_json(&jr->hist, &job->latest);
        texts[TK_TEXT_INVARIANTS] = invariants_text(jr);
        texts[TK_TEXT_RESUME] = resume_text(jr);
        if (!texts[TK_TEXT_CONTACTS] || !texts[TK_TEXT_HISTORY] ||
            !texts[TK_TEXT_INVARIANTS] || !texts[TK_TEXT_RESUME])
            rc = tk_error_set(err, TK_ENOMEM, "out of memory writing job %lld",
                              (long long)job->id);
    }
    if (!rc) {
        tk_job copy = *job;
        copy.frames = job_frames(jr);
        rc = tk_store_save(jr->slot->owner->store, &copy, (const char *const *)texts,
                           jr->pending, jr->pending_count, err);
        if (!rc) {
            jr->frames_stored += jr->pending_count;
            drop_pending(jr);
        }
    }
    for (int k = 0; k < TK_TEXTS; k++)
        free(texts[k]);
    return rc;
}

/* Whether the job's worker should let go of it: the service is stopping,
 * or (unless `ended`: an ended job is not cancelled any more) the job is
 * cancelled. */
static bool letting_go(job_run *jr, bool ended)
{
    tk_jobs *j = jr->slot->owner;
    pthread_mutex_lock(&j->lock);
    bool go = j->stopping || (!ended && jr->slot->cancel);
    pthread_mutex_unlock(&j->lock);
    return go;
}

/* Writes the job; while the store refuses (a full disk, a read-only
 * file) the job pauses here, showing why, and the write is retried every
 * second, until it succeeds or the worker must let go (then the store
 * keeps the job as last written, which resumes at the next start).
 * `final`: the job has ended and must not be let go of while the service
 * runs (its end would be lost). */
static int store_job(job_run *jr, tk_job *job, bool final)
{
    tk_jobs *j = jr->slot->owner;
    tk_error err;
    bool paused = false;
    int rc;
    while ((rc = flush_job(jr, job, &err)) != TK_OK) {
        if (!paused) {
            paused = true;
            pthread_mutex_lock(&j->lock);
            snprintf(jr->slot->job.error, sizeof jr->slot->job.error,
                     "paused: storing the job failed, retrying every second: %.240s",
                     err.message);
            pthread_mutex_unlock(&j->lock);
        }
        if (letting_go(jr, final))
            break;
        struct timespec second = {1, 0};
        nanosleep(&second, NULL);
    }
    if (paused) {
        pthread_mutex_lock(&j->lock);
        if (rc == TK_OK)
            jr->slot->job.error[0] = '\0';
        pthread_mutex_unlock(&j->lock);
    }
    return rc;
}

static int on_step(const tk_step_report *s, void *user)
{
    job_run *jr = user;
    worker_slot *slot = jr->slot;
    tk_jobs *j = slot->owner;
    tk_step_report r = *s;
    bool again = r.step == jr->last_step;
    jr->last_step = r.step;
    history_add(&jr->hist, &r);
    take_frame(jr, slot->job.options.every, r.step, again);
    if (s->step > 0 && !again)
        atomic_fetch_add(&j->steps_total, 1);
    pthread_mutex_lock(&j->lock);
    slot->job.latest = r;
    slot->job.has_figures = true;
    slot->job.fraction = job_fraction(&slot->job);
    slot->job.frames = job_frames(jr);
    tk_job copy = slot->job;
    bool stop = slot->cancel || j->stopping;
    pthread_mutex_unlock(&j->lock);
    double now = now_monotonic();
    if (now - jr->last_flush >= j->cfg.flush_seconds) {
        store_job(jr, &copy, false);
        jr->last_flush = now_monotonic();
        /* a paused store may have waited through a cancel or a stop */
        stop = stop || letting_go(jr, false);
    }
    return stop;
}

/* Stores the job as failed with a message, and its type when the run was
 * set up (invariants_text, or NULL). */
static void fail_job(tk_jobs *j, tk_job *job, const char *message, const char *type)
{
    job->state = TK_JOB_FAILED;
    job->finished = now_unix();
    snprintf(job->error, sizeof job->error, "%s", message);
    const char *texts[TK_TEXTS] = {NULL};
    texts[TK_TEXT_INVARIANTS] = type;
    tk_store_save(j->store, job, texts, NULL, 0, NULL);
}

/* The job's input, parsed, into *out. */
static int read_input(tk_jobs *j, const tk_job *job, tk_curve **out, tk_error *err)
{
    char *text = NULL;
    size_t len = 0;
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = j->cfg.max_vertices;
    int rc = tk_store_text(j->store, job->id, TK_TEXT_INPUT, &text, &len, err);
    if (!rc && !text)
        rc = tk_error_set(err, TK_EIO, "job %lld has no input", (long long)job->id);
    if (!rc)
        rc = tk_vect_parse(text, len, &limits, out, err);
    free(text);
    return rc;
}

/* An interrupted job's run, from its stored curve and resume point (the
 * engine goes on at its coarse level and polishing, with its escapes and
 * best curve, and checks the curve against the input's type).  A job
 * stored without a resume point (by an older daemon) goes on from its
 * curve at its step, on the final polygon. */
static int resume_run(tk_jobs *j, const tk_job *job, const tk_options *opts, job_run *jr,
                      tk_error *err)
{
    char *text = NULL, *resume = NULL;
    size_t len = 0;
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = j->cfg.max_vertices;
    tk_curve *curve = NULL, *best = NULL;
    int rc = tk_store_text(j->store, job->id, TK_TEXT_CURVE, &text, &len, err);
    if (!rc)
        rc = tk_vect_parse(text, len, &limits, &curve, err);
    if (!rc)
        rc = tk_store_text(j->store, job->id, TK_TEXT_RESUME, &resume, NULL, err);
    tk_resume at = {.step = job->latest.step, .seconds = job->latest.seconds,
                    .start_ropelength = job->latest.ropelength};
    tk_step_report best_report = {0};
    json_t *doc = !rc && resume ? json_loads(resume, 0, NULL) : NULL;
    const char *vect = json_string_value(json_object_get(doc, "best"));
    tk_error why;
    if (!rc && resume &&
        (!doc ||
         tk_json_record_set(tk_resume_fields, tk_resume_nfields, &at,
                            json_object_get(doc, "at"), NULL, &why) ||
         (vect && (tk_vect_parse(vect, strlen(vect), &limits, &best, &why) ||
                   tk_json_record_set(tk_step_fields, tk_step_nfields, &best_report,
                                      json_object_get(doc, "best_report"), NULL, &why)))))
        rc = tk_error_set(err, TK_EIO,
                          "the stored resume point of job %lld does not read back: %.200s",
                          (long long)job->id, doc ? why.message : "not JSON");
    if (!rc)
        rc = tk_run_resume(curve, opts, &at, best, best ? &best_report : NULL,
                           &jr->input_type, &jr->run, err);
    if (rc == TK_ETYPE) /* the job's result is what it was stored as */
        tk_invariants_compute(curve, &jr->refused, NULL);
    json_decref(doc);
    free(text);
    free(resume);
    tk_curve_free(&curve);
    tk_curve_free(&best);
    return rc;
}

/* Sets up the engine run for a job, with the options as the command line
 * would run them: from its input, or, when it was interrupted, from where
 * it was (resume_run).  A run knows its input's type either way. */
static int setup_run(tk_jobs *j, tk_job *job, job_run *jr, tk_error *err)
{
    tk_curve *input = NULL;
    int rc = read_input(j, job, &input, err);
    if (!rc)
        rc = tk_invariants_compute(input, &jr->input_type, err);
    tk_options opts;
    tk_job_options_to_run(&job->options, &opts);
    opts.snapshot_every = 0; /* frames are taken by the worker (take_frame) */
    bool resume = !rc && job->latest.step > 0;
    if (!rc && resume) {
        rc = resume_run(j, job, &opts, jr, err);
        char *hist = NULL;
        if (!rc && tk_store_text(j->store, job->id, TK_TEXT_HISTORY, &hist, NULL, NULL) == TK_OK)
            history_load(&jr->hist, hist, job->latest.step);
        free(hist);
        jr->frames_stored = job->frames;
        jr->frame_after = job->latest.step;
    } else if (!rc) {
        rc = tk_run_new(input, &opts, &jr->run, err);
    }
    tk_curve_free(&input);
    return rc;
}

static void run_job(worker_slot *slot)
{
    tk_jobs *j = slot->owner;
    tk_job job;
    tk_error err;
    tk_error_clear(&err);
    pthread_mutex_lock(&j->lock);
    job = slot->job;
    pthread_mutex_unlock(&j->lock);

    job_run jr = {0};
    jr.slot = slot;
    jr.hist.cap = j->cfg.history_limit > 2 ? j->cfg.history_limit : 2;
    jr.hist.items = malloc(jr.hist.cap * sizeof *jr.hist.items);
    jr.hist.stride = 1;
    jr.frame_after = -1;
    jr.last_step = -1;
    if (!jr.hist.items) {
        fail_job(j, &job, "out of memory", NULL);
        return;
    }
    int rc = setup_run(j, &job, &jr, &err);
    if (rc) {
        char *type = jr.run || jr.refused.ncomp ? invariants_text(&jr) : NULL;
        fail_job(j, &job, err.message, type);
        free(type);
        tk_run_free(&jr.run);
        tk_invariants_free(&jr.input_type);
        tk_invariants_free(&jr.refused);
        free(jr.hist.items);
        drop_pending(&jr);
        free(jr.pending);
        return;
    }
    job.state = TK_JOB_RUNNING;
    if (job.started <= 0.0)
        job.started = now_unix();
    job.components = tk_run_curve(jr.run)->ncomp;
    pthread_mutex_lock(&j->lock);
    slot->job = job;
    slot->run = jr.run;
    if (slot->cancel || j->stopping)
        tk_run_cancel(jr.run);
    pthread_mutex_unlock(&j->lock);

    /* the start's figures (step 0, or the step it resumes from), stored
     * at once: a crash from here on resumes from this curve */
    jr.last_flush = now_monotonic();
    on_step(tk_run_latest(jr.run), &jr);
    pthread_mutex_lock(&j->lock);
    job = slot->job;
    pthread_mutex_unlock(&j->lock);
    store_job(&jr, &job, false);

    tk_run_set_progress(jr.run, on_step, &jr);
    tk_stop_reason why = TK_STOP_NONE;
    rc = tk_run_until(jr.run, &why, &err);

    pthread_mutex_lock(&j->lock);
    job = slot->job;
    bool cancelled = slot->cancel;
    bool stopping = j->stopping;
    slot->run = NULL;
    pthread_mutex_unlock(&j->lock);

    snprintf(job.stop_reason, sizeof job.stop_reason, "%s", tk_stop_reason_name(why));
    if (rc) {
        job.state = TK_JOB_FAILED;
        snprintf(job.error, sizeof job.error, "%s", err.message);
    } else if (why == TK_STOP_CANCELLED && cancelled) {
        job.state = TK_JOB_CANCELLED;
    } else if (why == TK_STOP_CANCELLED && stopping) {
        /* the service is shutting down: the job resumes at the next start */
        job.state = TK_JOB_QUEUED;
        job.stop_reason[0] = '\0';
    } else {
        job.state = TK_JOB_DONE;
    }
    if (tk_job_state_final(job.state))
        job.finished = now_unix();
    /* The end is stored, waiting for the store if need be; a job the
     * store still holds as running resumes at the next start. */
    store_job(&jr, &job, true);
    tk_run_free(&jr.run);
    tk_invariants_free(&jr.input_type);
    free(jr.hist.items);
    drop_pending(&jr);
    free(jr.pending);
}

bool tk_worker_priority_parse(const char *text, tk_worker_priority *out)
{
    static const char *const names[] = {"idle", "low", "normal"};
    for (int k = 0; k < 3; k++)
        if (text && !strcmp(text, names[k])) {
            *out = (tk_worker_priority)k;
            return true;
        }
    return false;
}

/* Workers yield to the threads answering requests, so that polls are
 * answered within milliseconds however busy the engine is.  With
 * SCHED_IDLE a waking request thread preempts a worker at once; with
 * niceness alone it may wait for the worker's time slice (p99 of paced
 * polling 5-8 ms against 4-5 ms, bench/service.sh).  Per thread on Linux;
 * a failure leaves the thread as it was, which only costs latency. */
static void set_worker_priority(tk_worker_priority priority)
{
    pthread_setname_np(pthread_self(), "tk-worker");
    if (priority == TK_WORKERS_IDLE) {
        struct sched_param none = {0};
        pthread_setschedparam(pthread_self(), SCHED_IDLE, &none);
    }
    if (priority != TK_WORKERS_NORMAL)
        setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), 5);
}

static void *worker_main(void *arg)
{
    worker_slot *slot = arg;
    tk_jobs *j = slot->owner;
    set_worker_priority(j->cfg.priority);
    pthread_mutex_lock(&j->lock);
    j->ready++;
    pthread_cond_signal(&j->started);
    pthread_mutex_unlock(&j->lock);
    for (;;) {
        pthread_mutex_lock(&j->lock);
        while (!j->stopping && j->queue_len == 0)
            pthread_cond_wait(&j->wake, &j->lock);
        if (j->stopping) {
            pthread_mutex_unlock(&j->lock);
            break;
        }
        /* Taking the job and showing it in the slot happen under the one
         * lock that tk_jobs_cancel also holds, so a cancel either finds it
         * queued or finds it here. */
        int64_t id = queue_pop(j);
        tk_job job;
        bool take = tk_store_get(j->store, id, &job, NULL) == TK_OK &&
                    !tk_job_state_final(job.state);
        if (take) {
            slot->busy = true;
            slot->cancel = false;
            slot->run = NULL;
            slot->job = job;
        }
        pthread_mutex_unlock(&j->lock);
        if (!take)
            continue;
        run_job(slot);
        pthread_mutex_lock(&j->lock);
        slot->busy = false;
        pthread_mutex_unlock(&j->lock);
    }
    return NULL;
}

int tk_jobs_start(tk_store *store, const tk_jobs_config *cfg, tk_jobs **out, tk_error *err)
{
    *out = NULL;
    if (cfg->workers < 1)
        return tk_error_set(err, TK_EINVAL, "at least one worker is needed");
    tk_jobs *j = calloc(1, sizeof *j);
    if (!j)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    j->store = store;
    j->cfg = *cfg;
    pthread_mutex_init(&j->lock, NULL);
    pthread_cond_init(&j->wake, NULL);
    pthread_cond_init(&j->started, NULL);
    atomic_init(&j->steps_total, 0);
    int64_t *ids = NULL;
    size_t n = 0;
    int rc = tk_store_unfinished(store, &ids, &n, err);
    for (size_t i = 0; !rc && i < n; i++)
        if (!queue_push(j, ids[i]))
            rc = tk_error_set(err, TK_ENOMEM, "out of memory");
    free(ids);
    j->slots = rc ? NULL : calloc(cfg->workers, sizeof *j->slots);
    if (!rc && !j->slots)
        rc = tk_error_set(err, TK_ENOMEM, "out of memory");
    for (size_t i = 0; !rc && i < cfg->workers; i++) {
        j->slots[i].owner = j;
        if (pthread_create(&j->slots[i].thread, NULL, worker_main, &j->slots[i]) != 0)
            rc = tk_error_set(err, TK_ENOMEM, "cannot start worker thread %zu", i + 1);
        else
            j->nslots++;
    }
    /* The pool is up when every worker has its name and priority, so that
     * whoever sees the service answer sees its threads as they stay. */
    pthread_mutex_lock(&j->lock);
    while (j->ready < j->nslots)
        pthread_cond_wait(&j->started, &j->lock);
    pthread_mutex_unlock(&j->lock);
    if (rc) {
        tk_jobs_stop(&j);
        return rc;
    }
    *out = j;
    return TK_OK;
}

void tk_jobs_halt(tk_jobs *j)
{
    pthread_mutex_lock(&j->lock);
    bool joined = j->joined;
    j->stopping = true;
    j->joined = true;
    for (size_t i = 0; i < j->nslots; i++)
        if (j->slots[i].run)
            tk_run_cancel(j->slots[i].run);
    pthread_cond_broadcast(&j->wake);
    pthread_mutex_unlock(&j->lock);
    if (!joined)
        for (size_t i = 0; i < j->nslots; i++)
            pthread_join(j->slots[i].thread, NULL);
}

void tk_jobs_stop(tk_jobs **p)
{
    if (!p || !*p)
        return;
    tk_jobs *j = *p;
    tk_jobs_halt(j);
    pthread_cond_destroy(&j->wake);
    pthread_cond_destroy(&j->started);
    pthread_mutex_destroy(&j->lock);
    free(j->slots);
    free(j->queue);
    free(j);
    *p = NULL;
}

int tk_job_prepare(const char *name, const tk_job_options *opts, const tk_curve *curve,
                   size_t max_vertices, tk_job *job, tk_error *err)
{
    tk_options run_opts;
    tk_job_options_to_run(opts, &run_opts);
    /* A run refuses what it cannot start from; finding out here gives the
     * client a 422 now instead of a failed job later.  Re-resolution is
     * bounded first, as it decides the memory the check itself takes. */
    if (curve->nvert > max_vertices)
        return tk_error_set(err, TK_ELIMIT, "the curve has %zu vertices; the limit is %zu",
                            curve->nvert, max_vertices);
    tk_run *probe = NULL;
    if (run_opts.resolution > 0.0) {
        tk_options measure = run_opts;
        measure.resolution = 0.0;
        measure.autoscale = true;
        int rc = tk_run_new(curve, &measure, &probe, err);
        if (rc)
            return rc;
        double wanted = ceil(run_opts.resolution * tk_run_latest(probe)->ropelength);
        tk_run_free(&probe);
        if (!(wanted <= (double)max_vertices))
            return tk_error_set(err, TK_ELIMIT,
                                "option 'resolution': %g vertices per unit ropelength make %.0f "
                                "vertices; the limit is %zu",
                                run_opts.resolution, wanted, max_vertices);
    }
    int rc = tk_run_new(curve, &run_opts, &probe, err);
    tk_run_free(&probe);
    if (rc)
        return rc;
    memset(job, 0, sizeof *job);
    snprintf(job->name, sizeof job->name, "%s", name);
    job->state = TK_JOB_QUEUED;
    job->options = *opts;
    /* the job shows the step budget it runs with */
    job->options.run.max_steps = run_opts.max_steps;
    job->created = now_unix();
    job->fraction = -1.0;
    job->components = curve->ncomp;
    job->latest.vertices = curve->nvert;
    return TK_OK;
}

int tk_jobs_submit(tk_jobs *j, const char *name, const tk_job_options *opts,
                   const tk_curve *curve, const char *vect, tk_job *job, tk_error *err)
{
    int rc = tk_job_prepare(name, opts, curve, j->cfg.max_vertices, job, err);
    if (rc)
        return rc;
    pthread_mutex_lock(&j->lock);
    if (j->stopping) {
        pthread_mutex_unlock(&j->lock);
        return tk_error_set(err, TK_EBUSY, "the service is shutting down");
    }
    if (j->queue_len >= j->cfg.queue_limit) {
        pthread_mutex_unlock(&j->lock);
        return tk_error_set(err, TK_EBUSY, "the queue is full (%zu jobs waiting)",
                            j->cfg.queue_limit);
    }
    rc = tk_store_insert(j->store, job, vect, err);
    if (!rc)
        rc = tk_store_update(j->store, job, err);
    if (!rc && !queue_push(j, job->id))
        rc = tk_error_set(err, TK_ENOMEM, "out of memory");
    if (!rc)
        pthread_cond_signal(&j->wake);
    pthread_mutex_unlock(&j->lock);
    return rc;
}

int tk_jobs_get(tk_jobs *j, int64_t id, tk_job *out, tk_error *err)
{
    pthread_mutex_lock(&j->lock);
    worker_slot *slot = slot_of(j, id);
    if (slot)
        *out = slot->job;
    pthread_mutex_unlock(&j->lock);
    return slot ? TK_OK : tk_store_get(j->store, id, out, err);
}

int tk_jobs_cancel(tk_jobs *j, int64_t id, tk_job *out, tk_error *err)
{
    pthread_mutex_lock(&j->lock);
    worker_slot *slot = slot_of(j, id);
    if (slot) {
        slot->cancel = true;
        if (slot->run)
            tk_run_cancel(slot->run);
        *out = slot->job;
        pthread_mutex_unlock(&j->lock);
        return TK_OK;
    }
    /* Not running: read and change it while holding the lock, so that no
     * worker takes it up in between. */
    int rc = tk_store_get(j->store, id, out, err);
    if (!rc && tk_job_state_final(out->state))
        rc = tk_error_set(err, TK_EINVAL, "job %lld has already finished (%s)", (long long)id,
                          tk_job_state_name(out->state));
    if (!rc) {
        queue_remove(j, id);
        out->state = TK_JOB_CANCELLED;
        out->finished = now_unix();
        snprintf(out->stop_reason, sizeof out->stop_reason, "cancelled");
        rc = tk_store_update(j->store, out, err);
    }
    pthread_mutex_unlock(&j->lock);
    return rc;
}

void tk_jobs_stats_get(tk_jobs *j, tk_jobs_stats *out)
{
    memset(out, 0, sizeof *out);
    pthread_mutex_lock(&j->lock);
    out->queued = j->queue_len;
    out->workers = j->nslots;
    out->queue_limit = j->cfg.queue_limit;
    for (size_t i = 0; i < j->nslots; i++) {
        const worker_slot *s = &j->slots[i];
        if (!s->busy)
            continue;
        out->running++;
        if (s->run && s->job.latest.seconds > 0.0 && s->job.latest.step > 0)
            out->steps_per_second += (double)s->job.latest.step / s->job.latest.seconds;
    }
    pthread_mutex_unlock(&j->lock);
    out->steps_total = atomic_load(&j->steps_total);
}
