/* tightknot: the tightening flow (sections 3 and 4 of the paper).
 *
 * A run owns a copy of the curve and everything a step needs (strut tree,
 * NNLS solver with its CHOLMOD common, work vectors), so runs in different
 * threads share nothing.  Each step:
 *   1. active constraints: struts within tau (1 + active_tolerance) among
 *      Theorem 3's admissible pairs, and kinks (vertices whose minrad is
 *      within the same tolerance of lambda * radius; equation 3 is the
 *      smaller of one function per edge, and each of the two within the
 *      tolerance is a constraint);
 *   2. the motion u = -grad(length) (equation 14) plus a tangential motion
 *      that evens out the edges (section 4.2);
 *   3. the rigidity matrix A (equations 6, 7) and the NNLS problem
 *      min ||A x + u||, x >= 0 (equation 13); the resolved motion is
 *      u + A x (Proposition 3), x the compressions;
 *   4. the step: halving from twice the last step size until the error it
 *      introduces into every constraint (contacts that become active
 *      mid-step included, found again with the tree) is within the
 *      overstep tolerance (section 4.5);
 *   5. error recovery: while some constraint is violated beyond the
 *      correction tolerance, Newton steps with the minimum-norm solution of
 *      A^T du = -R (section 4.6); rescaling only if that fails.
 * The flow keeps the tube embedded, so it cannot change the knot or link
 * type; resampling and recovery move the curve in ways its constraints
 * do not cover, so the type (tk/invariants.h) of the start is compared
 * with the run's curve after every resampling and whenever the run stops,
 * and a difference fails the run (TK_ETYPE).
 * With a resolution the run goes coarse to fine (coarse_to_fine): fewer
 * vertices first, doubled whenever the ropelength all but stops falling.
 * Open components keep their end points fixed.
 *
 * Thread safety: a run is used by one thread at a time, except
 * tk_run_cancel, which any thread may call at any time.
 */
#ifndef TK_TIGHTEN_H
#define TK_TIGHTEN_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/curve.h"
#include "tk/error.h"
#include "tk/invariants.h"
#include "tk/struts.h"

typedef struct tk_options {
    double radius;               /* tube radius in [1e-30, 1e30] (the range of
                                  * tk_curve_check_range); the diameter tau is 2 radius */
    double lambda;               /* stiffness: minrad >= lambda * radius */
    double resolution;           /* re-resolve to ceil(resolution * ropelength)
                                    vertices at the start; 0 keeps the input */
    bool autoscale;              /* scale so thickness = autoscale_margin * tau */
    double autoscale_margin;
    /* Stop criteria; 0 leaves one unused.  The run stops at the first met. */
    long max_steps;
    double max_seconds;
    double min_residual;         /* stop when residual < this */
    double min_change;           /* stop when ropelength fell by less than
                                    this (relative) over change_window steps */
    size_t change_window;
    /* Tolerances, relative to the diameter tau. */
    double active_tolerance;     /* constraints this close are active; a third
                                    of it each time the ropelength all but
                                    stops falling, four times at most (the
                                    polishing; the overstep and correction
                                    tolerances then stay below it) */
    double overstep_tolerance;   /* largest violation a step may introduce */
    double correction_tolerance; /* violations above this are corrected */
    double equalise;             /* gain of the edge-equalising motion */
    size_t snapshot_every;       /* keep the curve every K steps (0: never) */
    double re_resolve;           /* with resolution > 0: whenever the ropelength
                                    has fallen by this fraction since the last
                                    resampling and the vertex count is that
                                    much finer than resolution * ropelength,
                                    resample to that count (and scale up just
                                    enough to stay feasible); 0: never.  The
                                    vertex count then changes during the run,
                                    so it cannot be combined with snapshots. */
    bool coarse_to_fine;         /* with resolution > 0 and no snapshots: start
                                    with half the vertices (a quarter, ...,
                                    while that leaves 2.5 per unit
                                    ropelength) and double them each time the
                                    ropelength all but stops falling, up to
                                    the resolution's count */
    /* Escapes from critical points that are not the minimum (escape.c):
     * each time the ropelength all but stops falling on the final polygon
     * (or a convergence criterion is met) while tries and budget remain,
     * the best curve so far is deformed at random, made feasible and
     * tightened again (coarse to fine where the run is); the run returns
     * the best curve found.  0 turns them off. */
    int escapes;                 /* most tries */
    unsigned long long seed;     /* of the random deformations: the same
                                    seed, the same run */
} tk_options;

#define TK_OPTIONS_INIT                                                                  \
    {                                                                                    \
        0.5, 1.0, 0.0, false, 1.002, 0, 0.0, 0.0, 0.0, 20, 3e-4, 1e-5, 1e-6, 0.5, 0, 0.0, \
            true, 8, 1                                                                   \
    }

/* Why a run stopped. */
typedef enum tk_stop_reason {
    TK_STOP_NONE = 0,      /* still running */
    TK_STOP_STEPS,
    TK_STOP_TIME,
    TK_STOP_RESIDUAL,
    TK_STOP_CHANGE,
    TK_STOP_CANCELLED,
    TK_STOP_STALLED,       /* the step size fell to nothing */
    TK_STOP_FAILED         /* numerical failure: see the error message */
} tk_stop_reason;

const char *tk_stop_reason_name(tk_stop_reason r);

/* The figures of one step (also the run's history). */
typedef struct tk_step_report {
    long step;               /* 1 for the first step; 0 for the start */
    double seconds;          /* wall time since the run started */
    double ropelength;       /* 2 length / thickness (Definition 1) */
    double length;
    double thickness;        /* Definition 1 */
    double minrad;
    double residual;         /* |-grad L + A x| / |grad L| */
    size_t struts;           /* active struts */
    size_t kinks;            /* active kinks */
    double step_size;        /* h of the step taken */
    double rcond;            /* NNLS condition estimate (1 without constraints) */
    double violation;        /* worst constraint violation after the step / tau */
    int corrections;         /* Newton iterations after the step */
    size_t vertices;
    int escapes;             /* escapes tried so far (tk_run_escapes) */
} tk_step_report;

typedef struct tk_run tk_run;

/* Called after every step with that step's figures; a non-zero return
 * cancels the run. */
typedef int (*tk_progress_fn)(const tk_step_report *step, void *user);

/* Creates a run from a copy of `start`, applying re-resolution and
 * autoscale.  Fails (TK_EINVAL) when the start is not a valid curve, or is
 * thinner than the tube and autoscale is off. */
int tk_run_new(const tk_curve *start, const tk_options *opts, tk_run **out, tk_error *err);
void tk_run_free(tk_run **p);

void tk_run_set_progress(tk_run *r, tk_progress_fn fn, void *user);

/* One step.  Returns TK_OK, or an error (the run is then stopped with
 * TK_STOP_FAILED and the curve is the last good one). */
int tk_run_step(tk_run *r, tk_error *err);

/* Steps until a stop criterion is met; *reason says which. */
int tk_run_until(tk_run *r, tk_stop_reason *reason, tk_error *err);

/* Asks the run to stop; it does within one step.  Thread-safe. */
void tk_run_cancel(tk_run *r);

const tk_options *tk_run_options(const tk_run *r);
const tk_curve *tk_run_curve(const tk_run *r);
/* The latest figures (step 0 before the first step). */
const tk_step_report *tk_run_latest(const tk_run *r);
const tk_step_report *tk_run_history(const tk_run *r, size_t *count);
/* Active struts and kinks of the last step, with their NNLS forces. */
const tk_strut *tk_run_struts(const tk_run *r, size_t *count);
const tk_kink *tk_run_kinks(const tk_run *r, size_t *count);
tk_stop_reason tk_run_stop_reason(const tk_run *r);

/* One escape: where it started, the best ropelength then, and what its
 * tightening reached on the final polygon (NAN while under way or when
 * the run stopped first). */
typedef struct tk_escape {
    long step;          /* the step after which the deformation was made */
    double from;        /* the best ropelength when it started */
    double amplitude;   /* of the deformation, in tube diameters */
    double reached;
    bool improved;      /* reached < from */
} tk_escape;

const tk_escape *tk_run_escapes(const tk_run *r, size_t *count);

/* The knot or link type of the start as given, and of the run's curve at
 * the last check (after every resampling and at every stop; the start's
 * before any).  A run whose type changed has failed (TK_ETYPE). */
const tk_invariants *tk_run_type_start(const tk_run *r);
const tk_invariants *tk_run_type_latest(const tk_run *r);

/* Where a run's wall time went, in seconds.  The first four are the
 * operations every step repeats, wherever in the flow they happen;
 * `total` is all of tk_run_new and tk_run_step (the rest of it is the
 * motion, measuring and recording the figures, and the schedule's
 * resampling); the two rooms' totals include the operations they called.
 * So search + matrix + nnls + checks <= total and stepping + recovery <=
 * total. */
typedef struct tk_run_timing {
    double search;       /* active sets: struts and kinks found with the tree */
    double matrix;       /* rigidity matrices built (equations 6, 7) */
    double nnls;         /* NNLS solves (equation 13) and minimum-norm solves */
    double checks;       /* the worst violation of a curve (trial steps,
                            recovery, each step's figures) */
    double total;        /* tk_run_new and tk_run_step, all of them */
    double stepping;     /* step control (section 4.5), everything it called */
    double recovery;     /* error recovery (section 4.6), everything it called */
    long nnls_solves, nnls_iterations, factorisations;
    double invariants;   /* the knot type computed and compared (included
                            in total) */
} tk_run_timing;

void tk_run_timing_get(const tk_run *r, tk_run_timing *out);

/* Snapshots: the vertex coordinates (3 * vertices doubles, same component
 * layout as tk_run_curve) every snapshot_every steps. */
size_t tk_run_snapshot_count(const tk_run *r);
const double *tk_run_snapshot(const tk_run *r, size_t k, long *step);

#endif
