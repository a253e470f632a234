/* Step control (section 4.5): how far the curve moves along the resolved
 * motion, the constraints a step runs into, the step along the resolved
 * gradient alone when the equalising motion blocks it, and the retries
 * with a shorter step when error recovery cannot restore the thickness.
 * See run.h for the rooms of the flow. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"

/* Step sizes below this fraction of the largest allowed count as no step;
 * this many of them in a row make the run stalled. */
#define STALL_FRACTION 1e-12
#define STALL_STEPS 20
/* A step below this fraction of the largest allowed is tried again
 * without the equalising motion. */
#define SHORT_STEP_FRACTION 1e-6
#define MAX_HALVINGS 50
#define MAX_EXPANSIONS 8
#define HALVINGS_BEFORE_EXPANDING 3
/* Tries at a step: the step, then up to STEP_ATTEMPTS - 1 shorter ones
 * when error recovery cannot restore the thickness (tk_stepping_finish). */
#define STEP_ATTEMPTS 4

void tk_stepping_reset(tk_run *r)
{
    r->stepping.step_size = 0.0;
    r->stepping.tiny_steps = 0;
}

void tk_stepping_resume(tk_run *r, double step_size)
{
    r->stepping.step_size = step_size;
}

int tk_stepping_fit(tk_run *r, size_t vertices, tk_error *err)
{
    free(r->stepping.held);
    r->stepping.held = calloc(3 * vertices, sizeof *r->stepping.held);
    if (!r->stepping.held)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a run of %zu vertices", vertices);
    return TK_OK;
}

void tk_stepping_free(tk_run *r)
{
    free(r->stepping.held);
}

bool tk_stepping_stalled(const tk_run *r)
{
    return r->stepping.tiny_steps >= STALL_STEPS;
}

/* The largest |motion| of a vertex. */
static double fastest(const tk_run *r)
{
    double most = 0.0;
    for (size_t v = 0; v < r->shared.curve->nvert; v++)
        most = fmax(most, tk_norm(r->motion.motion + 3 * v, 3));
    return most;
}

/* No vertex may move more than a tenth of the diameter or a quarter of
 * the shortest edge in one step, so no strand can pass through another
 * between two checks and no edge folds over: the largest step size for the
 * current motion, whose fastest vertex moves at fastest_vertex (0 when
 * nothing moves). */
static double largest_step(const tk_run *r, double fastest_vertex)
{
    if (!(fastest_vertex > 0.0))
        return 0.0;
    double shortest_edge;
    tk_curve_edge_range(r->shared.curve, &shortest_edge, NULL);
    return fmin(0.1 * r->tau, 0.25 * shortest_edge) / fastest_vertex;
}

/* What a step must lower: the length over the thickness a violation
 * leaves, 1 - worst (worst as tk_recovery_violation gives it), the
 * ropelength of the curve scaled back to its tube.  A step is accepted
 * within the overstep tolerance, and its violation, when over half of it,
 * corrected right after (down to a tenth), at a cost in length about the
 * violation's: a step judged by its length alone, along constraints that
 * curve, can lose to the correction all that it gained.  Catalogue 8.19
 * at 489 vertices after 600 s (60.99997), tightened again for 120 s
 * without escapes: judged by the length, 2,927 of its 6,328 steps raised
 * the ropelength and 2,188 needed corrections, cycling between a step and
 * its correction, and it ended at 60.99632; judged by this, 34 of 4,366
 * and 16, at 60.99535. */
static double merit(double length, double worst)
{
    return length / (1.0 - worst);
}

/* A step that shortens the curve but raises the merit at 2h, and at h by
 * more than this share of that, raises it at first order in h: no shorter
 * step lowers it (see take_step). */
#define FIRST_ORDER_SHARE 0.375

/* A step along curved constraints violates them at second order in the
 * step size h while it shortens the curve at first order, so its merit
 * rises for all but small steps (the Maratos effect of exact penalty
 * functions), though the correction after it costs far less length than
 * the merit reckons (1 - worst spread over the whole length, where the
 * Newton steps move the few violated contacts alone).  So the first trial
 * that shortens the curve within the overstep tolerance but raises the
 * merit is corrected (at most CORRECTED_NEWTON Newton steps, no
 * rescaling) and judged by the merit it leaves then: a second-order
 * correction.  Lissajous 6_1 L(3,2,5) at 480 vertices, tightened for 600 s
 * and polished again from there (56.71794, no escapes, 150 s): 56.71746
 * judged before the correction, 56.71706 after; 100 steps of its polish
 * at the fourth level (bench/steps --curve) left it at 56.717831, where
 * it began, with steps of 1.3e-3, and now take it to 56.717777, with
 * steps of 4e-3 to 3e-2 (30.8 ms a step against 40.6). */
#define CORRECTED_NEWTON 3
/* Not where the resolved motion is below this fraction of the length
 * gradient (the step's residual): the curve is critical but for
 * rounding, and its steps are of rounding's direction.  The catalogue's
 * unlink 0.2.1 (two round circles, residual 2e-15 from step 32) took
 * steps of 1e9 there, each corrected and judged some 1e-8 lower, and
 * never stalled. */
#define CORRECTED_CRITICAL 1e-9

/* Whether a trial that shortens the curve but raises the merit, leaving
 * the violation `worst`, is worth judging after its correction: it must
 * violate something the correction would mend, the curve must not be
 * critical (CORRECTED_CRITICAL), and the polygon must be the final one.
 * A coarser polygon's looser tolerances let the halved trials go about as
 * far, at a fraction of a Newton step each, and its plateaus are for
 * finding a basin rather than polishing: the catalogue's 5.1 at
 * resolution 5 (120 s) took 2.5 ms a step on its first coarse polygon
 * (135 vertices) and 2,303 steps to its plateau with corrected trials
 * there, 1.9 ms and 2,369 steps without; it came within 0.5% of the
 * atlas's 5_1 after 11.9 s against 8.1 s, and both ended at 47.2418.
 * L(3,2,5) at 480 vertices, 600 s, ends at 56.71727 with corrected
 * trials on its final polygon alone (56.71706 on every polygon; the
 * atlas's 6_1, 56.71771). */
static bool correction_pays(const tk_run *r, const tk_step_report *rep, double worst)
{
    return worst > tk_tolerance_correction(r) && rep->residual > CORRECTED_CRITICAL &&
           tk_schedule_final(r);
}

/* The run's curve becomes the trial (r->shared.trial, the curve plus h
 * times the motion), corrected; *taken when that lowers the merit below
 * merit_before (the step is then rep's), else the run's curve is put back.
 * The finder is left fitted to the run's curve. */
static int judge_corrected(tk_run *r, tk_step_report *rep, double h, double merit_before,
                           bool *taken, tk_error *err)
{
    tk_curve *c = r->shared.curve;
    size_t n3 = 3 * c->nvert;
    double *held = r->stepping.held;
    memcpy(held, c->xyz, n3 * sizeof *c->xyz);
    memcpy(c->xyz, r->shared.trial->xyz, n3 * sizeof *c->xyz);
    int iterations = 0;
    /* what the Newton steps leave, the merit counts (no rescaling: the
     * call then fails with TK_ENUMERIC, the curve as they left it) */
    int rc = tk_recovery_correct(r, CORRECTED_NEWTON, 0.0, &iterations, err);
    double worst = 0.0;
    if (rc == TK_OK || rc == TK_ENUMERIC)
        rc = tk_recovery_violation(r, c, &worst, err);
    if (rc)
        return rc;
    *taken = worst <= tk_tolerance_overstep(r) && merit(tk_curve_length(c), worst) < merit_before;
    if (*taken) {
        r->stepping.step_size = h;
        r->stepping.corrected_steps++;
        rep->step_size = h;
        rep->corrections += iterations;
        return TK_OK;
    }
    memcpy(c->xyz, held, n3 * sizeof *c->xyz);
    tk_strut_finder_refit(r->shared.finder, c);
    return TK_OK;
}

/* The most struts an expansion may add: a trial that crosses more pairs
 * than the set holds (or than a quarter of the vertices, while the set is
 * small) went too far to learn the contacts from, and a shorter one
 * follows.  On the trefoil at 9,600 vertices a trial at about 100 times the
 * usual step crossed 17,321 pairs besides the 5,543 in the set, and the
 * step's resolution carried them all: 18.8 s for a step where the steps
 * around it took 0.1 to 0.3 s (bench/FIGURES.md).  Only from
 * EXPAND_BOUNDED_VERTICES on (the 4,000 coordinates below which the
 * NNLS's coordinate form changes nothing either, engine/nnls.c): there
 * the bound changed where the escapes' tries went, and T(3,4) at
 * resolution 5 (306 vertices, 60 s) ended in the basin 0.05% above
 * 8_19's with 5 of 6 seeds, against 1 of 6 without it. */
#define EXPAND_BOUNDED_VERTICES 1334

static size_t expand_most(const tk_run *r)
{
    if (r->shared.curve->nvert < EXPAND_BOUNDED_VERTICES)
        return SIZE_MAX;
    const tk_constraints *set = &r->active.set;
    size_t held = set->struts.count + set->nkinks, quarter = r->shared.curve->nvert / 4;
    return held > quarter ? held : quarter;
}

/* The largest step, halving from twice the last one, whose end point
 * violates no constraint by more than the overstep tolerance and has a
 * lower merit (the first trial with a higher one judged after its
 * correction too, judge_corrected); failing that, where the merit rises
 * at first order in the step size, the step before the one that showed
 * it, if it shortens the curve.
 * rep->step_size is the step taken (0 if none was acceptable), *allowed
 * the largest step the motion allowed; a resolution after new constraints
 * keeps the motion's `equalising`. */
static int take_step(tk_run *r, tk_step_report *rep, bool equalising, double *allowed,
                     tk_error *err)
{
    tk_curve *c = r->shared.curve, *t = r->shared.trial;
    tk_strut_finder *finder = r->shared.finder;
    const double *motion = r->motion.motion;
    size_t n3 = 3 * c->nvert;
    double fast = fastest(r), largest = largest_step(r, fast);
    *allowed = largest;
    if (!(largest > 0.0) || !tk_motion_descends(r)) {
        rep->step_size = 0.0;
        r->stepping.step_size = 0.0;
        return TK_OK;
    }
    double h = r->stepping.step_size > 0.0 ? fmin(2.0 * r->stepping.step_size, largest)
                                           : largest / 8.0;
    /* every trial of this motion moves a vertex by at most h |motion| */
    int rc0 = tk_recovery_near(r, motion, h * (1.0 + 1e-9), fast, err);
    if (rc0)
        return rc0;
    double worst_before;
    if ((rc0 = tk_recovery_violation(r, c, &worst_before, err)) != TK_OK)
        return rc0;
    double length_before = tk_curve_length(c), merit_before = merit(length_before, worst_before);
    /* the last step size tried that shortened the curve within the
     * tolerance but raised the merit, and by how much */
    double last_h = 0.0, last_rise = 0.0;
    int expansions = 0;
    bool corrected = false, corrected_ok = false;
    for (int halving = 0; halving < MAX_HALVINGS; halving++, h *= 0.5) {
        for (size_t i = 0; i < n3; i++)
            t->xyz[i] = c->xyz[i] + h * motion[i];
        tk_strut_finder_refit(finder, t);
        double worst;
        int rc = tk_recovery_violation(r, t, &worst, err);
        if (rc)
            return rc;
        if (worst > tk_tolerance_overstep(r) && expansions < MAX_EXPANSIONS &&
            halving >= HALVINGS_BEFORE_EXPANDING) {
            /* Constraints the step keeps running into: make them active,
             * resolve again and retry the same step size.  Not at the first
             * failure: a shorter step is cheaper than a new resolution, and
             * usually enough. */
            size_t added = 0;
            rc = tk_active_expand(r, t, expand_most(r), &added, err);
            if (rc)
                return rc;
            if (added > 0) {
                expansions++;
                tk_strut_finder_refit(finder, c);
                rc = tk_motion_resolve(r, rep, equalising, err);
                if (rc)
                    return rc;
                fast = fastest(r);
                largest = largest_step(r, fast);
                *allowed = largest;
                if (!tk_motion_descends(r))
                    break;
                h = 2.0 * fmin(h, largest); /* undo this iteration's halving */
                last_h = last_rise = 0.0; /* (of the old motion) */
                rc = tk_recovery_near(r, motion, h * (1.0 + 1e-9), fast, err);
                if (rc)
                    return rc;
                continue;
            }
        }
        /* The resolved motion shortens the curve to first order; a step
         * that makes it longer went too far along a curved constraint,
         * and one whose violation costs more than it shortens gains
         * nothing (see merit). */
        if (worst > tk_tolerance_overstep(r))
            continue;
        double length = tk_curve_length(t), rise = merit(length, worst) - merit_before;
        if (rise < 0.0) {
            memcpy(c->xyz, t->xyz, n3 * sizeof *c->xyz);
            r->stepping.step_size = h;
            rep->step_size = h;
            return TK_OK;
        }
        if (!(length < length_before)) {
            last_h = last_rise = 0.0;
            continue;
        }
        if (!corrected && correction_pays(r, rep, worst)) {
            corrected = true;
            rc = judge_corrected(r, rep, h, merit_before, &corrected_ok, err);
            if (rc || corrected_ok)
                return rc;
        }
        /* The merit's rise is c h + b h^2: halving h takes it to between a
         * quarter and a half of itself, nearer a half the more the first order
         * term weighs.  The resolved motion keeps every active constraint to
         * first order only as far as the NNLS answer is exact: where the factor
         * is kept (motion.c) its rates are off by some 1e-5 relative, and a
         * kink's radius function, which moves some (rho / tau) / e^2 times as
         * fast as a strut's distance for edges e (schedule.c), then falls at a
         * relative rate that the shortening, |v|^2 / L, cannot pay.  The tight
         * trefoil at 2,400 vertices (bench/steps --curve): a kink at 1.6e-3 h
         * against 3.2e-6 h; judged by the merit alone it stayed at 32.743394
         * through 145 steps of 3.7 s, each halving down to a few 1e-8 and
         * resolving after every new constraint.  There the step is judged by
         * its length, as in the paper, and the correction after it pays for the
         * violation; where the rise is of second order (a step too long along a
         * curved constraint), halving on finds one that lowers the merit. */
        if (last_h > 0.0 && rise > FIRST_ORDER_SHARE * last_rise) {
            for (size_t i = 0; i < n3; i++)
                c->xyz[i] += last_h * motion[i];
            r->stepping.step_size = last_h;
            r->stepping.length_steps++;
            rep->step_size = last_h;
            tk_strut_finder_refit(finder, c);
            return TK_OK;
        }
        last_h = h;
        last_rise = rise;
    }
    tk_strut_finder_refit(finder, c);
    rep->step_size = 0.0;
    r->stepping.step_size = 0.0;
    return TK_OK;
}

/* Resolves the motion and takes the step (section 4.5). */
static int step(tk_run *r, tk_step_report *rep, tk_error *err)
{
    double t0 = tk_clock();
    bool equalising = r->opt.equalise > 0.0;
    int rc = tk_motion_resolve(r, rep, equalising, err);
    double allowed = 0.0;
    if (!rc)
        rc = take_step(r, rep, equalising, &allowed, err);
    /* The equalising motion is tangential, but on a polygon it costs
     * length at first order.  Near a constrained critical point the
     * resolved gradient is small and that cost can outweigh it, or the
     * length rises at second order faster than the motion lowers it at
     * first: the step search then finds nothing (or next to nothing) and
     * the run would stall short of the critical point.  The step goes
     * along the resolved gradient alone instead. */
    if (!rc && equalising && !(rep->step_size >= SHORT_STEP_FRACTION * allowed)) {
        r->stepping.step_size = 0.0;
        rc = tk_motion_resolve(r, rep, false, err);
        if (!rc)
            rc = take_step(r, rep, false, &allowed, err);
    }
    r->stepping.tiny_steps =
        rep->step_size < STALL_FRACTION * allowed ? r->stepping.tiny_steps + 1 : 0;
    r->stepping.seconds += tk_clock() - t0;
    return rc;
}

/* One attempt at the step: the active set of the run's curve, then the
 * step along its resolved motion. */
static int attempt_step(tk_run *r, tk_step_report *rep, tk_error *err)
{
    tk_curve *c = r->shared.curve;
    tk_strut_finder_refit(r->shared.finder, c);
    int rc = tk_active_find(r, c, &r->active.set, err);
    if (!rc)
        rc = step(r, rep, err);
    return rc;
}

int tk_stepping_begin(tk_run *r, tk_step_report *rep, tk_error *err)
{
    tk_recovery_keep(r);
    r->stepping.tiny_before = r->stepping.tiny_steps;
    return attempt_step(r, rep, err);
}

int tk_stepping_finish(tk_run *r, tk_step_report *rep, int rc, tk_error *err)
{
    tk_curve *c = r->shared.curve;
    for (int attempt = 0;; attempt++) {
        if (attempt > 0)
            rc = attempt_step(r, rep, err);
        double worst = 0.0;
        if (!rc)
            rc = tk_recovery_violation(r, c, &worst, err);
        if (!rc && worst > 0.5 * tk_tolerance_overstep(r)) {
            int corrections = 0;
            rc = tk_recovery_correct(r, TK_CORRECTIONS, TK_RESCALE_FEASIBILITY, &corrections,
                                     err);
            rep->corrections += corrections;
        }
        if (rc != TK_ENUMERIC || !(rep->step_size > 0.0))
            break;
        /* Newton steps could not restore the thickness: undo the step,
         * take one a quarter as long (section 4.5's control doubles the
         * last step size first, so it starts at half) */
        tk_recovery_undo(r, true);
        r->stepping.step_size = 0.25 * rep->step_size;
        rep->corrections = 0;
        if (attempt == STEP_ATTEMPTS - 1) {
            /* No shorter step could be restored either: this step moves
             * nothing, the next one starts shorter still, and a run of
             * such steps is a stall (counted from before the attempts,
             * each of which counted its own step).  The curve as it was
             * is within the overstep tolerance; when its own violation is
             * what every step pushes past the point where recovery starts,
             * and the Newton steps cannot lower it, each step fails the
             * same way: the trefoil at 4,800 vertices, a kink at 1.745e-6
             * below the bound (half its overstep tolerance, 3.49e-6), went
             * 350 s without a step.  So it is corrected, and what the
             * Newton steps leave rescaled (ropelength does not change
             * with scale) as at a start; failing that, left as it was. */
            r->stepping.tiny_steps = r->stepping.tiny_before + 1;
            rep->step_size = 0.0;
            int corrections = 0;
            rc = tk_recovery_correct(r, TK_CORRECTIONS, TK_RESCALE_START(r), &corrections, err);
            if (rc == TK_ENUMERIC)
                tk_recovery_undo(r, false);
            else
                rep->corrections = corrections;
            tk_strut_finder_refit(r->shared.finder, c);
            rc = rc == TK_ENUMERIC ? TK_OK : rc;
            break;
        }
    }
    return rc;
}
