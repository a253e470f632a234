/* Read-only queries on the run's state, asked by rooms on every level
 * (run.h): the clock, how far the ropelength fell, whether the polygon is
 * the final one, its mean edge and the tolerances of the step (from the
 * options, the polygon and the schedule's polishing level).  They stand
 * below all the rooms and write nothing, so a room that asks one calls
 * nothing above it; each keeps the name of the room whose state it reads
 * (tk_schedule_final), or its concern's (tk_tolerance_*). */
#include <math.h>
#include <time.h>

#include "run.h"

/* Each polishing level (schedule.c) shrinks the tolerances by this. */
#define POLISH_FACTOR (1.0 / 3.0)
/* On a fine polygon the active tolerance is at most ACTIVE_PER_EDGE2
 * times the squared mean edge (in diameters).  Next to a contact of
 * nearly parallel strands the k-th pair along them is farther by about
 * (k h)^2 times their relative curvature, so a fixed tolerance holds a
 * number of pairs per contact that grows as 1 / h: at 2,400 vertices
 * 3e-4 made 32,000 struts of the tight trefoil active (13 a vertex) and
 * a step took 9.6 s, nearly all of it the NNLS; at 3e-5, 3,500 struts
 * and 0.1 s (bench/steps).  One tolerance of the order of h^2 keeps the
 * pair next to a contact (the parallel case, tk_active_find) whatever
 * the resolution.  Measured on 3.1 at resolution 33 (1,211 vertices),
 * 150 s with four runs sharing two cores: 32.7531 with 3e-4 throughout;
 * 32.7437, 32.7454, 32.7439, 32.7438, 32.7442 and 32.7525 with factors
 * 0.1, 0.2, 0.3, 0.4, 0.65 and 1.5.  Below about 520 vertices of a tight
 * trefoil the options' tolerance is the smaller. */
#define ACTIVE_PER_EDGE2 0.3
/* A kink is active when its radius function is within the active
 * tolerance times the function's stiffness, at most KINK_TOLERANCE_MOST
 * of the bound.  Moving a vertex by d normal to its edges (e in
 * diameters) turns them by 2 d / e; the radius function rho, about
 * e / theta, changes by 2 rho^2 d / e^2, a relative 2 rho d / e^2,
 * where a strut's distance changes by at most 2 d: (rho / tau) / e^2
 * times less slack for the same motion, some 10,000 times at 2,400
 * vertices of a tight trefoil.  With the struts' tolerance, the kinks
 * just outside it, bent at that rate by every step, held the steps there
 * to a median size of 6e-6: catalogue 3.1 tightened at 2,400 vertices
 * for 1,800 s reached 32.743687 at 794 s and stayed; with a cap of 0.1
 * the median step was 4e-3, 32.7437 was passed 3 s after the final
 * polygon was reached (277 s) and the run ended at 32.743289, with 92
 * kinks active a step (median) against 45.  But like a strut, an active
 * kink is held at first order whatever its slack, and 0.1 of it held the
 * disguised figure-eight of bench/starts (resolution 5, 120 s) at 44.45
 * in two runs, where the struts' tolerance gave 42.10995.  The
 * trefoil-2400 of tests/data tightened again for 150 s: 32.743816 with
 * the struts' tolerance (median step 1.9e-5), 32.743807 with 0.01
 * (2.7e-3), 32.743804 with 0.1 (5.4e-3).  With 0.01 the figure-eight
 * crawled too, its 14 to 16 kinks held: from 55.17 (step 2,000) to 43.72
 * in 120 s (the bench: 44.474, never judged converged, no escape), where
 * with the struts' tolerance it ended at 42.10985 after 5 escapes.  So
 * the kinks' own tolerance holds only where they are stiffer than
 * KINK_STIFFNESS_FROM times a strut (edges under 0.022 diameters,
 * resolution 22 and more): not at resolution 5 (stiffness 50), and at
 * 2,400 vertices (about 10,000) as measured above. */
#define KINK_TOLERANCE_MOST 0.01
#define KINK_STIFFNESS_FROM 1000.0

double tk_clock(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double thread_clock(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double tk_run_clock(const tk_run *r)
{
    if (!r->opt.cpu_time)
        return tk_clock() - r->life.started;
    return r->life.cpu_spent + (thread_clock() - r->life.cpu_entered);
}

/* What each counted operation cost the reference processor, in seconds a
 * unit (tk_work_counts): a least-squares fit of the processor
 * time of 200-step stretches of ten runs (catalogue 2.2.1, 3.1, 4.1,
 * 6.3.2, 7.4, 8.2.4, 9.23 and 10.124 at resolution 5, 30 s each; 3.1 at
 * 2,400 and 5.1 at 1,200 vertices, 60 s each) on the machine of
 * bench/FIGURES.md ("A budget of work").  Each run's work came within 6%
 * below to 22% above its seconds there, each of its levels within 27%
 * below to 47% above.  The counts that got no weight in that fit (the
 * contacts searched, the steps' vertices, the solves with a factor) are
 * not counted: what they cost grew with the columns. */
#define WORK_CHECK 1.63e-8      /* a vertex of a curve checked */
#define WORK_COLUMN 2.84e-6     /* a column of a rigidity matrix */
#define WORK_PIVOT 1.05e-7      /* an NNLS iteration, a unit of its size */
#define WORK_FACTOR 7.24e-8     /* an NNLS factorisation, a unit of its size */
#define WORK_NEWTON 8.98e-7     /* a recovery solve, a unit of its size */
#define WORK_TURN 9.71e-5       /* a turn, a squared vertex */
#define WORK_DEFORM 1.36e-6     /* a deformation, a vertex */
#define WORK_FLOP 4.49e-10      /* a factorisation's floating-point operation */

void tk_run_work_counts(const tk_run *r, tk_work_counts *out)
{
    *out = r->work;
    if (r->shared.nnls)
        out->flops = tk_nnls_work_done(r->shared.nnls).factor_flops;
}

double tk_run_work(const tk_run *r)
{
    tk_work_counts w;
    tk_run_work_counts(r, &w);
    return r->life.work_from + WORK_CHECK * w.checks + WORK_COLUMN * w.columns +
           WORK_PIVOT * w.pivots + WORK_FACTOR * w.factors + WORK_NEWTON * w.newton +
           WORK_TURN * w.turns + WORK_DEFORM * w.deforms + WORK_FLOP * w.flops;
}

void tk_run_clock_enter(tk_run *r)
{
    r->life.cpu_entered = thread_clock();
}

void tk_run_clock_leave(tk_run *r)
{
    r->life.cpu_spent += thread_clock() - r->life.cpu_entered;
}

bool tk_history_fall(const tk_run *r, size_t from, size_t window, double *fall)
{
    size_t n = r->life.nhistory;
    if (window == 0 || n <= from + window)
        return false;
    const tk_step_report *h = r->life.history;
    size_t split = n - window, first = split > from + window ? split - window : from;
    double before = INFINITY, recent = INFINITY;
    for (size_t k = first; k < split; k++)
        before = fmin(before, h[k].ropelength);
    for (size_t k = split; k < n; k++)
        recent = fmin(recent, h[k].ropelength);
    *fall = (before - recent) / recent;
    return true;
}

bool tk_schedule_final(const tk_run *r)
{
    return r->schedule.coarse_level == 0;
}

/* The tolerances of this step: the options' while the ropelength falls,
 * each a third smaller every time it all but stops (polishing).  A
 * constraint within the active tolerance holds the motion as if it were
 * in contact: with a slack of up to 3e-4 of the diameter such constraints
 * kept runs settling about 1e-4 (relative) above their critical points
 * (3.1 at resolution 5: 32.7719 at 3e-4, 32.7694 at 1e-4, 32.7689 at
 * 1e-5), while a tolerance that small from the start makes the loose
 * phase slower (contacts are met mid-step and found by the step control
 * instead).  The overstep tolerance stays below the active one (a step's
 * violations must be seen as active next time), the correction tolerance
 * a tenth of that.  Shrinking them costs step length (steps along curved
 * constraints grow as the square root of the overstep tolerance), so each
 * level waits until the ropelength falls by less than the offset the
 * current one leaves (about a third of its active tolerance, relative):
 * a run that merely crawls (past a saddle) keeps its step sizes. */
double tk_polish_scale(const tk_run *r)
{
    return pow(POLISH_FACTOR, r->schedule.polish_level);
}

/* The mean edge of the run's polygon over the diameter (0 when unknown):
 * half the ropelength of the last step's figures per edge, or, while a run
 * is set up and has none yet, its curve's length over the diameter per edge.
 * Without that fallback a new or resumed run on a fine polygon corrected
 * its start and found its first active set with the options' tolerance
 * instead of 0.3 h^2: a tight trefoil on 2,400 vertices had 48,585 struts
 * active at step 0 (about 9,000 a step later) and took 321 s to set up. */
double tk_mean_edge(const tk_run *r)
{
    size_t edges = tk_curve_edge_count(r->shared.curve);
    double rope = r->life.latest.ropelength;
    if (!(rope > 0.0 && isfinite(rope)))
        rope = 2.0 * tk_curve_length(r->shared.curve) / r->tau;
    return edges > 0 && rope > 0.0 && isfinite(rope) ? rope / (2.0 * (double)edges) : 0.0;
}

bool tk_tolerance_from_edge(const tk_run *r)
{
    double h = tk_mean_edge(r);
    return h > 0.0 && ACTIVE_PER_EDGE2 * h * h < r->opt.active_tolerance;
}

double tk_tolerance_active(const tk_run *r)
{
    double active = r->opt.active_tolerance, h = tk_mean_edge(r);
    if (h > 0.0)
        active = fmin(active, ACTIVE_PER_EDGE2 * h * h);
    return active * tk_polish_scale(r);
}

double tk_tolerance_kink(const tk_run *r)
{
    double active = tk_tolerance_active(r), h = tk_mean_edge(r);
    if (!(h > 0.0))
        return active;
    double stiffness = r->min_radius / r->tau / (h * h);
    if (stiffness < KINK_STIFFNESS_FROM)
        return active;
    return fmax(active, fmin(KINK_TOLERANCE_MOST, active * stiffness));
}

double tk_tolerance_overstep(const tk_run *r)
{
    return fmin(r->opt.overstep_tolerance, tk_tolerance_active(r));
}

double tk_tolerance_correction(const tk_run *r)
{
    return 0.1 * tk_tolerance_overstep(r);
}
