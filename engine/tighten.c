/* The run's life: creation, the order of a step's rooms, the history and
 * snapshots, the stop criteria.  The rooms and the state they own are
 * described in run.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "tk/record.h"
#include "tk/thickness.h"

const char *tk_stop_reason_name(tk_stop_reason r)
{
    switch (r) {
    case TK_STOP_NONE: return "running";
    case TK_STOP_STEPS: return "steps";
    case TK_STOP_TIME: return "time";
    case TK_STOP_RESIDUAL: return "residual";
    case TK_STOP_CHANGE: return "change";
    case TK_STOP_CANCELLED: return "cancelled";
    case TK_STOP_STALLED: return "stalled";
    case TK_STOP_FAILED: return "failed";
    case TK_STOP_CONVERGED: return "converged";
    case TK_STOP_WORK: return "work";
    }
    return "unknown";
}

void tk_run_free(tk_run **p)
{
    if (!p || !*p)
        return;
    tk_run *r = *p;
    tk_curve_free(&r->shared.curve);
    tk_curve_free(&r->shared.trial);
    tk_strut_finder_free(&r->shared.finder);
    tk_nnls_free(&r->shared.nnls);
    free(r->shared.pin);
    free(r->shared.pins);
    tk_active_free(r);
    tk_motion_free(r);
    tk_stepping_free(r);
    tk_recovery_free(r);
    tk_escape_free(r);
    free(r->life.history);
    free(r->life.snapshots);
    free(r->life.snapshot_steps);
    tk_type_free(r);
    free(r);
    *p = NULL;
}

static int record(tk_run *r, tk_step_report *rep, tk_error *err)
{
    tk_measure m;
    int rc = tk_thickness_measure(r->shared.curve, r->shared.finder, &m, err);
    if (rc)
        return rc;
    rep->length = m.length;
    rep->thickness = m.thickness;
    rep->minrad = m.minrad;
    rep->ropelength = m.ropelength;
    rep->vertices = r->shared.curve->nvert;
    rep->escapes = tk_escape_tries(r);
    rep->restarts = r->schedule.restarts;
    rep->seconds = tk_run_clock(r);
    rep->work = tk_run_work(r);
    /* the step sizes of the history summed: a step put back in the place
     * of the last (record_restored) has size 0 and the time of the one
     * before it */
    rep->flow_time = (r->life.nhistory > 0 ? r->life.history[r->life.nhistory - 1].flow_time
                                           : r->life.flow_from) +
                     rep->step_size;
    if (r->life.nhistory == r->life.history_capacity) {
        size_t cap = r->life.history_capacity ? 2 * r->life.history_capacity : 256;
        tk_step_report *grown = realloc(r->life.history, cap * sizeof *grown);
        if (!grown)
            return tk_error_set(err, TK_ENOMEM, "out of memory for the history");
        r->life.history = grown;
        r->life.history_capacity = cap;
    }
    r->life.history[r->life.nhistory++] = *rep;
    r->life.latest = *rep;
    if (r->opt.snapshot_every > 0 && rep->step % (long)r->opt.snapshot_every == 0) {
        size_t nv3 = 3 * r->shared.curve->nvert;
        if (r->life.nsnapshots == r->life.snapshot_capacity) {
            size_t cap = r->life.snapshot_capacity ? 2 * r->life.snapshot_capacity : 16;
            double *grown = realloc(r->life.snapshots, cap * nv3 * sizeof *grown);
            if (grown)
                r->life.snapshots = grown;
            long *steps = realloc(r->life.snapshot_steps, cap * sizeof *steps);
            if (steps)
                r->life.snapshot_steps = steps;
            if (!grown || !steps)
                return tk_error_set(err, TK_ENOMEM, "out of memory for snapshots");
            r->life.snapshot_capacity = cap;
        }
        memcpy(r->life.snapshots + r->life.nsnapshots * nv3, r->shared.curve->xyz, nv3 * sizeof(double));
        r->life.snapshot_steps[r->life.nsnapshots++] = rep->step;
    }
    return TK_OK;
}

/* The rest of a step's figures, of the run's curve and its active set
 * (found): the worst violation, the contacts and the kinks' report;
 * then recorded. */
static int figures(tk_run *r, tk_step_report *rep, tk_error *err)
{
    double t0 = tk_clock();
    int rc = tk_recovery_violation(r, r->shared.curve, &rep->violation, err);
    rep->struts = r->active.set.struts.count;
    if (!rc)
        rc = tk_active_report(r, err);
    rep->kinks = r->active.nreport;
    if (!rc)
        rc = record(r, rep, err);
    r->life.figures_seconds += tk_clock() - t0;
    return rc;
}

/* A run from `start` (resampled and scaled as the options ask), or, with
 * `at`, from a resumed run's curve as it is (tk_run_resume). */
static int create(const tk_curve *start, const tk_options *opts, const tk_resume *at,
                  const tk_curve *best, const tk_step_report *best_report,
                  const tk_invariants *start_type, tk_run **out, tk_error *err)
{
    *out = NULL;
    tk_options defaults = TK_OPTIONS_INIT;
    if (!opts)
        opts = &defaults;
    int rc = tk_options_check(opts, err);
    for (size_t i = 0; !rc && at && i < tk_resume_nfields; i++) {
        tk_resume copy = *at;
        rc = tk_field_set(&tk_resume_fields[i], &copy, tk_field_get(&tk_resume_fields[i], at),
                          err);
    }
    if (!rc && at && (!best != !best_report))
        rc = tk_error_set(err, TK_EINVAL, "a best curve needs its figures, and they it");
    if (rc)
        return rc;
    tk_run *r = calloc(1, sizeof *r);
    if (!r)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    r->opt = *opts;
    r->tau = 2.0 * opts->radius;
    r->min_radius = opts->lambda * opts->radius;
    atomic_init(&r->life.cancel, 0);
    /* a resumed run's clock goes on from the time it had spent */
    r->life.started = tk_clock() - (at ? at->seconds : 0.0);
    r->life.cpu_spent = at ? at->seconds : 0.0;
    r->life.work_from = at ? at->work : 0.0;
    tk_run_clock_enter(r);
    r->life.flow_from = at ? at->flow_time : 0.0;
    tk_escape_start(r, at != NULL, start);
    rc = tk_nnls_new(&r->shared.nnls, err);
    if (!rc)
        rc = at ? tk_schedule_resume(r, start, at, err) : tk_schedule_start(r, start, err);
    if (!rc && at)
        rc = tk_escape_resume(r, at, best, best_report, err);
    /* the start as given (tk_schedule_start validated it), before
     * resampling and scaling */
    if (!rc)
        rc = tk_type_start(r, start, start_type, err);
    if (!rc && (at || r->shared.curve->nvert != start->nvert)) {
        char when[64];
        if (at)
            snprintf(when, sizeof when, "the curve resumed at step %ld", at->step);
        else if (r->opt.resolution > 0.0)
            snprintf(when, sizeof when, "resampling to %zu vertices (resolution %g)",
                     r->shared.curve->nvert, r->opt.resolution);
        else
            snprintf(when, sizeof when, "resampling to %zu vertices", r->shared.curve->nvert);
        rc = tk_type_check(r, when, err);
    }
    tk_step_report rep = {0};
    rep.step = at ? at->step : 0;
    rep.rcond = 1.0;
    rep.residual = NAN;
    if (!rc)
        rc = tk_recovery_correct(r, TK_CORRECTIONS, TK_RESCALE_START(r), &rep.corrections, err);
    if (!rc)
        rc = tk_active_find(r, r->shared.curve, &r->active.set, err);
    if (!rc)
        rc = figures(r, &rep, err);
    if (rc) {
        tk_run_free(&r);
        return rc;
    }
    tk_stepping_resume(r, at ? at->step_size : 0.0);
    r->life.seconds = tk_clock() - r->life.started;
    tk_run_clock_leave(r);
    *out = r;
    return TK_OK;
}

int tk_run_new(const tk_curve *start, const tk_options *opts, tk_run **out, tk_error *err)
{
    return create(start, opts, NULL, NULL, NULL, NULL, out, err);
}

int tk_run_resume(const tk_curve *curve, const tk_options *opts, const tk_resume *at,
                  const tk_curve *best, const tk_step_report *best_report,
                  const tk_invariants *start_type, tk_run **out, tk_error *err)
{
    return create(curve, opts, at, best, best_report, start_type, out, err);
}

void tk_run_resume_point(const tk_run *r, tk_resume *out)
{
    memset(out, 0, sizeof *out);
    out->step = r->life.latest.step;
    out->seconds = r->life.latest.seconds;
    out->work = r->life.latest.work;
    out->step_size = r->stepping.step_size;
    out->flow_time = r->life.latest.flow_time;
    tk_schedule_resume_point(r, out);
    tk_escape_resume_point(r, out);
}

void tk_run_set_progress(tk_run *r, tk_progress_fn fn, void *user)
{
    r->life.progress = fn;
    r->life.user = user;
}

void tk_run_cancel(tk_run *r)
{
    atomic_store(&r->life.cancel, 1);
}

/* The first criterion met, in the order cancellation, budget,
 * convergence (a run's stop so far stands when none is); converge's
 * stop only once the escapes ask for no more.  A stall on the
 * final polygon stops the run; on a coarse one it moves the schedule on,
 * as a spent share of the budget does. */
static void check_stop(tk_run *r)
{
    const tk_options *o = &r->opt;
    const tk_step_report *s = &r->life.latest;
    tk_stop_reason stop = r->life.stop;
    double fall;
    if (atomic_load(&r->life.cancel))
        stop = TK_STOP_CANCELLED;
    else if (o->max_steps > 0 && s->step >= o->max_steps)
        stop = TK_STOP_STEPS;
    else if (o->max_seconds > 0.0 && s->seconds >= o->max_seconds)
        stop = TK_STOP_TIME;
    else if (o->max_work > 0.0 && s->work >= o->max_work)
        stop = TK_STOP_WORK;
    else if (!tk_schedule_final(r))
        ; /* convergence is judged on the final polygon only */
    else if (o->min_residual > 0.0 && s->residual < o->min_residual)
        stop = TK_STOP_RESIDUAL;
    else if (o->min_change > 0.0 &&
             tk_history_fall(r, r->schedule.resampled_from, o->change_window, &fall) &&
             fall < o->min_change)
        stop = TK_STOP_CHANGE; /* within one polygon: a resampled one starts a little longer */
    if (stop == TK_STOP_NONE && tk_stepping_stalled(r) && !tk_schedule_move_on(r))
        stop = TK_STOP_STALLED;
    /* converged on the final polygon: an escape, while tries and budget
     * remain, rather than a stop */
    bool converged = stop == TK_STOP_RESIDUAL || stop == TK_STOP_CHANGE ||
                     stop == TK_STOP_STALLED ||
                     (stop == TK_STOP_NONE && tk_escape_converged(r));
    if (converged && tk_escape_ask(r))
        stop = TK_STOP_NONE;
    else if (converged && stop == TK_STOP_NONE && o->converge && tk_schedule_settled(r))
        stop = TK_STOP_CONVERGED; /* no try left, nor a best to put back */
    else if (stop == TK_STOP_NONE)
        tk_escape_reserve(r);
    if (tk_schedule_share_spent(r)) {
        tk_schedule_move_on(r);
        /* a stop on the budget has spent >= 1, above every share */
        if (stop == TK_STOP_STEPS || stop == TK_STOP_TIME || stop == TK_STOP_WORK)
            stop = TK_STOP_NONE;
    }
    r->life.stop = stop;
}

/* The figures of the best curve an escape found, put back when the run
 * stopped on another: its active set and forces replace the last step's
 * entry of the history (same step number, step size 0), so the budget
 * holds. */
static int record_restored(tk_run *r, tk_error *err)
{
    tk_step_report rep = {0};
    rep.step = r->life.latest.step;
    r->life.nhistory--;
    if (r->life.nsnapshots > 0 && r->life.snapshot_steps[r->life.nsnapshots - 1] == rep.step)
        r->life.nsnapshots--;
    tk_curve *c = r->shared.curve;
    tk_strut_finder_refit(r->shared.finder, c);
    int rc = tk_active_restore(r, &r->escape.best_set, err);
    if (!rc)
        rc = tk_motion_resolve(r, &rep, false, err);
    if (!rc)
        rc = figures(r, &rep, err);
    if (!rc && r->life.progress)
        (void)r->life.progress(&r->life.latest, r->life.user); /* stopping anyway */
    return rc;
}

/* A run that stops (for any reason but a failure) returns the best curve
 * it found, its type checked against the start's. */
static int check_result(tk_run *r, tk_error *err)
{
    if (r->life.stop == TK_STOP_NONE || r->life.stop == TK_STOP_FAILED)
        return TK_OK;
    /* checked already, unless the run went on since */
    if (r->type.checked_step == r->life.latest.step &&
        r->type.checked_vertices == r->shared.curve->nvert)
        return TK_OK;
    bool restored = false;
    int rc = tk_escape_finish(r, &restored, err);
    if (!rc && restored)
        rc = record_restored(r, err);
    if (!rc)
        rc = tk_type_check(r, "tightening changed the knot or link type", err);
    if (rc)
        r->life.stop = TK_STOP_FAILED;
    return rc;
}

static int step(tk_run *r, tk_error *err);

int tk_run_step(tk_run *r, tk_error *err)
{
    double t0 = tk_clock();
    tk_run_clock_enter(r);
    int rc = step(r, err);
    tk_run_clock_leave(r);
    r->life.seconds += tk_clock() - t0;
    return rc;
}

/* The rooms in their order (run.h). */
static int step(tk_run *r, tk_error *err)
{
    if (r->life.stop == TK_STOP_FAILED)
        return tk_error_set(err, TK_EINVAL, "the run has failed; it cannot step");
    if (atomic_load(&r->life.cancel)) {
        r->life.stop = TK_STOP_CANCELLED;
        return TK_OK;
    }
    tk_step_report rep = {0};
    rep.step = r->life.latest.step + 1;
    int rc = tk_escape_before_step(r, err);
    if (!rc)
        rc = tk_schedule_before_step(r, err);
    if (rc) {
        r->life.stop = TK_STOP_FAILED;
        return rc;
    }
    /* The schedule's polish watch runs after the motion, before error
     * recovery (which then works to the new tolerances), and on the first
     * attempt alone: between the halves of the step. */
    rc = tk_stepping_begin(r, &rep, err);
    tk_schedule_watch(r, tk_escape_judged_here(r));
    rc = tk_stepping_finish(r, &rep, rc, err);
    /* a pinned vertex moves along its constraint only, but each step
     * rounds: put back on it, it does not drift over many steps */
    if (!rc && r->shared.curve->npins)
        tk_curve_pins_snap(r->shared.curve);
    if (!rc)
        rc = figures(r, &rep, err);
    if (rc) {
        r->life.stop = TK_STOP_FAILED;
        return rc;
    }
    tk_escape_after_step(r);
    if (r->life.progress && r->life.progress(&r->life.latest, r->life.user) != 0)
        tk_run_cancel(r);
    r->life.stop = TK_STOP_NONE;
    check_stop(r);
    return check_result(r, err);
}

int tk_run_until(tk_run *r, tk_stop_reason *reason, tk_error *err)
{
    int rc = TK_OK;
    if (r->life.stop != TK_STOP_FAILED)
        r->life.stop = TK_STOP_NONE;
    check_stop(r);
    double t0 = tk_clock();
    tk_run_clock_enter(r);
    rc = check_result(r, err);
    tk_run_clock_leave(r);
    r->life.seconds += tk_clock() - t0;
    while (!rc && r->life.stop == TK_STOP_NONE) {
        rc = tk_run_step(r, err);
        if (rc)
            break;
    }
    if (reason)
        *reason = r->life.stop;
    return rc;
}

const tk_options *tk_run_options(const tk_run *r)
{
    return &r->opt;
}

const tk_curve *tk_run_curve(const tk_run *r)
{
    return r->shared.curve;
}

size_t tk_run_final_vertices(const tk_run *r)
{
    return tk_schedule_final_count(r);
}

const tk_step_report *tk_run_latest(const tk_run *r)
{
    return &r->life.latest;
}

const tk_step_report *tk_run_history(const tk_run *r, size_t *count)
{
    *count = r->life.nhistory;
    return r->life.history;
}

const tk_strut *tk_run_struts(const tk_run *r, size_t *count)
{
    *count = r->active.set.struts.count;
    return r->active.set.struts.items;
}

const tk_kink *tk_run_kinks(const tk_run *r, size_t *count)
{
    *count = r->active.nreport;
    return r->active.report;
}

void tk_run_timing_get(const tk_run *r, tk_run_timing *out)
{
    *out = (tk_run_timing){
        .search = r->active.search_seconds,
        .matrix = r->active.matrix_seconds,
        .nnls = r->motion.nnls_seconds + r->recovery.nnls_seconds,
        .checks = r->recovery.check_seconds,
        .total = r->life.seconds,
        .stepping = r->stepping.seconds,
        .recovery = r->recovery.seconds,
        .figures = r->life.figures_seconds,
        .nnls_solves = r->motion.nnls_solves,
        .nnls_iterations = r->motion.nnls_iterations,
        .factorisations = r->motion.factorisations,
        .invariants = r->type.seconds,
        .undone_steps = r->recovery.undone,
        .rescales = r->recovery.rescales,
        .bent_corrections = r->recovery.bent,
        .length_steps = r->stepping.length_steps,
        .corrected_steps = r->stepping.corrected_steps,
        .largest_rescale = r->recovery.largest_rescale,
    };
    tk_run_work_counts(r, &out->work);
}

const tk_invariants *tk_run_type_start(const tk_run *r)
{
    return &r->type.start;
}

const tk_invariants *tk_run_type_latest(const tk_run *r)
{
    return r->type.checked_step >= 0 ? &r->type.latest : &r->type.start;
}

tk_stop_reason tk_run_stop_reason(const tk_run *r)
{
    return r->life.stop;
}

size_t tk_run_snapshot_count(const tk_run *r)
{
    return r->life.nsnapshots;
}

const double *tk_run_snapshot(const tk_run *r, size_t k, long *step)
{
    if (k >= r->life.nsnapshots)
        return NULL;
    if (step)
        *step = r->life.snapshot_steps[k];
    return r->life.snapshots + k * 3 * r->shared.curve->nvert;
}
