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
 *      overstep tolerance (section 4.5) and the length over the
 *      thickness it leaves is lower (the first trial that fails only the
 *      latter is judged again after its correction, on the final
 *      polygon);
 *   5. error recovery: while some constraint is violated beyond the
 *      correction tolerance, Newton steps with the damped minimum-norm
 *      solution of A^T du = -R (section 4.6), damped as much as they need;
 *      a step they cannot restore is undone and taken shorter (and not
 *      taken at all when no shorter one can be restored either), and after
 *      a step the curve is rescaled by a factor of at most 1 + 1e-6; a
 *      resampled polygon gets 400 Newton steps, and what they leave (at
 *      most half the diameter) is rescaled.
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

/* A record's fields are listed once, in an X-macro table; the struct,
 * its defaults and every mapping (tk/record.h: the command line, HTTP
 * queries, JSON, the store) are generated from it.  Each row is
 *   X(field, KIND, default, min, max, name, help)
 * KIND one of REAL (double), LONG, INT, SIZE (size_t), BOOL and SEED
 * (unsigned long long); the value must lie in [min, max]; `name` is how
 * users give it (NULL: the engine's own, set in code only); `help` says
 * what it means, as --help and the API's documentation show it. */
#define TK_CTYPE_REAL double
#define TK_CTYPE_LONG long
#define TK_CTYPE_INT int
#define TK_CTYPE_SIZE size_t
#define TK_CTYPE_BOOL bool
#define TK_CTYPE_SEED unsigned long long
#define TK_FIELD_DECLARE(field, kind, ...) TK_CTYPE_##kind field;
#define TK_FIELD_DEFAULT(field, kind, dflt, ...) .field = dflt,

/* The run options.  The stop criteria (steps, time, residual, change):
 * 0 leaves one unused, the run stops at the first met.  Tolerances are
 * relative to the diameter tau = 2 radius. */
#define TK_OPTION_FIELDS(X)                                                                  \
    X(radius, REAL, 0.5, 1e-30, 1e30, "radius",                                              \
      "tube radius; the diameter, the thickness the run keeps, is twice it")                 \
    X(lambda, REAL, 1.0, 1e-30, 1e30, "lambda", "stiffness: minrad >= lambda x radius")      \
    X(resolution, REAL, 0.0, 0.0, 1e4, "resolution",                                         \
      "resample the start to resolution x ropelength vertices (5 quick, 10 medium, 20 "      \
      "fine), its ropelength reckoned from its self-distance (2 length / shortest "          \
      "self-distance: a noisy start's curvature does not count), and going coarse to fine "  \
      "the final polygon to resolution x the ropelength reached by then; 0 keeps the "      \
      "input's")                                                                             \
    X(vertices, SIZE, 0, 0, 1e6, "vertices",                                                 \
      "resample the start to this many vertices in all (coarse to fine as with a "          \
      "resolution), to compare with tables at a given vertex count (0: not; not with a "     \
      "resolution)")                                                                         \
    X(autoscale, BOOL, false, 0, 1, "autoscale",                                             \
      "scale the start so that its thickness is just above the diameter (needed when it "   \
      "is thinner), and a curve that grows thicker than that back down to it")              \
    X(autoscale_margin, REAL, 1.002, 1.0, 1.5, NULL, "autoscale's thickness / diameter")     \
    X(max_steps, LONG, 0, 0, 1e8, "steps", "stop after this many steps (0: no limit)")       \
    X(max_seconds, REAL, 0.0, 0.0, 604800, "time",                                           \
      "stop after this many seconds, at most a week (0: no limit)")                          \
    X(cpu_time, BOOL, false, 0, 1, "cpu_time",                                               \
      "count the seconds (--time, and those reported) in the run's own processor time, not " \
      "the wall clock's: on a busy machine a run then does the work it does on an idle one") \
    X(max_work, REAL, 0.0, 0.0, 604800, "work",                                              \
      "stop after this much work, in seconds of a reference processor (at most a week; 0: "  \
      "no limit): the work is counted from the run's own operations, so the same start, "    \
      "options and seed give the same run, step for step, on any machine at any load, "      \
      "where a budget of seconds gives another run on each")                                 \
    X(min_residual, REAL, 0.0, 0.0, 1.0, "residual",                                         \
      "stop when the residual |resolved gradient| / |gradient| falls below this (0: "        \
      "never)")                                                                              \
    X(converge, BOOL, false, 0, 1, "converge",                                               \
      "stop when the run has converged as far as its tolerances allow: on the final "        \
      "polygon, polished to its finest tolerance, every escape tried, and the ropelength "    \
      "no longer falling")                                                                   \
    X(min_change, REAL, 0.0, 0.0, 1.0, NULL,                                                 \
      "stop when the ropelength fell by less than this (relative) over change_window "       \
      "steps")                                                                               \
    X(change_window, SIZE, 20, 1, 1e8, NULL, "steps of the change criterion")               \
    X(active_tolerance, REAL, 3e-4, 1e-12, 0.4, NULL,                                        \
      "constraints this close are active (at most; a fine polygon uses 0.3 times its "       \
      "squared mean edge in diameters if smaller); a third of it each time the ropelength "  \
      "all but stops falling, four times at most (the polishing; the overstep tolerance "    \
      "then stays below it)")                                                                \
    X(overstep_tolerance, REAL, 1e-5, 1e-12, 0.09, "overstep",                               \
      "largest constraint violation a step may make, as a fraction of the diameter; "        \
      "violations are corrected down to a tenth of it")                                      \
    X(equalise, REAL, 0.5, 0.0, 1e3, NULL, "gain of the edge-equalising motion")            \
    X(snapshot_every, SIZE, 0, 0, 1e8, NULL, "keep the curve every this many steps (0: "     \
      "never)")                                                                              \
    X(re_resolve, REAL, 0.0, 0.0, 0.9, "re_resolve",                                         \
      "with a resolution: each time the ropelength has fallen by this fraction, resample "   \
      "to resolution x ropelength vertices again (0: never)")                                \
    X(coarse_to_fine, BOOL, true, 0, 1, "coarse",                                            \
      "with a resolution: start with half the vertices (a quarter, ... to the halving "     \
      "nearest 2.5 per unit ropelength, at most an eighth), fewer each time the "            \
      "ropelength falls by a quarter, and double them whenever it all but stops falling")    \
    X(loose, INT, 2, 0, 2, "loose",                                                          \
      "with a resolution: the first tightening starts this many halvings below the "        \
      "coarsest level, while 0.6 vertices a unit of ropelength remain, each left at its "    \
      "first stall (a loose start comes down about four times as fast on each); so do "      \
      "the escapes' turned and far tries (0 to 2)")                                          \
    X(escapes, INT, 8, 0, 1000, "escapes",                                                   \
      "most escapes: each time the ropelength all but stops falling on the final polygon "   \
      "(or has crawled there for a fifth of the budget) before the last fifth of the "       \
      "budget, the best curve so far is changed at random (in turn: turned inside out "      \
      "about a point near its centre, deformed and loosened many times over, deformed a "    \
      "little) and tightened again; the last fifth polishes the best curve; the "            \
      "result is the best curve found; before that, in the first half of the budget, "       \
      "as many tries again explore the coarsest polygon alone, from the lowest curve found " \
      "there, the first of them the start turned inside out (0: none)")                      \
    X(seed, SEED, 1, 0, 9007199254740991.0, "seed",                                          \
      "of the escapes' random deformations: the same seed, the same run, given a budget of " \
      "steps or work (one of seconds is shared out by the clock) (below 2^53, so that every " \
      "seed is exact as a JSON number)")

/* The snapshots (snapshot_every) keep one vertex count: they cannot be
 * combined with re_resolve, and a run with them does not go coarse to
 * fine.  The escapes (escape.c): after the final polygon has converged,
 * the best curve so far is deformed by a smooth random displacement,
 * made feasible and tightened again (coarse to fine where the run is);
 * a run returns the best curve it found. */
typedef struct tk_options {
    TK_OPTION_FIELDS(TK_FIELD_DECLARE)
} tk_options;

#define TK_OPTIONS_INIT {TK_OPTION_FIELDS(TK_FIELD_DEFAULT)}

/* The most vertices a run holds, its start's or after resampling to its
 * resolution: runs larger are refused (TK_ELIMIT).  A run's memory grows
 * with its vertices and contacts: measured peaks of 360 MB for 1,000,000
 * vertices before any contact, 145 to 244 MB for the trefoil at 2,400
 * vertices in contact over 30 minutes (bench/FIGURES.md).  A knot that large in
 * contact was not measured. */
#define TK_RUN_MAX_VERTICES 1000000

/* The defaults that tighten (tk_options_complete): a run given no stop
 * criterion but a time or work goes coarse to fine at
 * TK_DEFAULT_RESOLUTION (unless it was given a vertex count) and
 * autoscales; given neither time nor work, it stops when converged or
 * after TK_DEFAULT_WORK of work (max_work: the same run on any machine,
 * about as many seconds on the reference one). */
#define TK_DEFAULT_RESOLUTION 5.0
#define TK_DEFAULT_WORK 120.0

/* Why a run stopped. */
typedef enum tk_stop_reason {
    TK_STOP_NONE = 0,      /* still running */
    TK_STOP_STEPS,
    TK_STOP_TIME,
    TK_STOP_RESIDUAL,
    TK_STOP_CHANGE,
    TK_STOP_CANCELLED,
    TK_STOP_STALLED,       /* the step size fell to nothing */
    TK_STOP_FAILED,        /* numerical failure: see the error message */
    TK_STOP_CONVERGED,     /* as far as its tolerances allow (converge) */
    TK_STOP_WORK           /* the work budget (max_work) */
} tk_stop_reason;

const char *tk_stop_reason_name(tk_stop_reason r);

/* The figures of one step (also the run's history); rows as for the
 * options, without domains. */
#define TK_STEP_FIELDS(X)                                                                    \
    X(step, LONG, 0, 0, 0, "step", "1 for the first step; 0 for the start")                 \
    X(seconds, REAL, 0, 0, 0, "seconds", "wall time since the run started")                 \
    X(ropelength, REAL, 0, 0, 0, "ropelength", "2 length / thickness (Definition 1)")       \
    X(length, REAL, 0, 0, 0, "length", "of the curve")                                      \
    X(thickness, REAL, 0, 0, 0, "thickness", "the tube diameter (Definition 1)")            \
    X(minrad, REAL, 0, 0, 0, "minrad", "smallest radius of curvature (equation 3)")         \
    X(residual, REAL, 0, 0, 0, "residual", "|-grad L + A x| / |grad L|")                    \
    X(struts, SIZE, 0, 0, 0, "struts", "active struts")                                     \
    X(kinks, SIZE, 0, 0, 0, "kinks", "active kinks")                                        \
    X(step_size, REAL, 0, 0, 0, "step_size", "h of the step taken")                         \
    X(flow_time, REAL, 0, 0, 0, "flow_time",                                                \
      "the flow's time: the step sizes h summed since the start (a film's frames at equal "  \
      "flow time show the flow at a constant rate, as the paper's)")                          \
    X(rcond, REAL, 0, 0, 0, "rcond",                                                        \
      "condition estimate of the NNLS's proximal normal matrix (1 without constraints)")    \
    X(violation, REAL, 0, 0, 0, "violation",                                                \
      "worst constraint violation after the step / tau")                                     \
    X(corrections, INT, 0, 0, 0, "corrections", "Newton iterations after the step")         \
    X(vertices, SIZE, 0, 0, 0, "vertices", "of the curve")                                  \
    X(escapes, INT, 0, 0, 0, "escapes", "escapes tried so far (tk_run_escapes)")            \
    X(restarts, INT, 0, 0, 0, "restarts",                                                   \
      "times the curve was replaced by another: an escape's deformation of the best, or "   \
      "the best put back (the figures jump where it changes)")                              \
    X(work, REAL, 0, 0, 0, "work",                                                          \
      "work done since the run started, in seconds of a reference processor (tk_run_work; " \
      "last, so that the columns before it keep their places)")

typedef struct tk_step_report {
    TK_STEP_FIELDS(TK_FIELD_DECLARE)
} tk_step_report;

typedef struct tk_run tk_run;

/* Called after every step with that step's figures; a non-zero return
 * cancels the run. */
typedef int (*tk_progress_fn)(const tk_step_report *step, void *user);

/* Creates a run from a copy of `start`, applying re-resolution and
 * autoscale.  Fails with TK_EINVAL when the start is not a valid curve, or
 * is thinner than the tube and autoscale is off; TK_ELIMIT when the
 * resolution asks for more vertices than a run may have; TK_ETYPE when
 * the resampled polygon is not of the start's type (a resolution too
 * coarse to carry the knot: the message names the vertex count);
 * TK_ENUMERIC or TK_ENOMEM when measuring the start fails. */
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
/* The vertices of the run's final polygon, now or once coarse to fine
 * has reached it (re-resolution changes it later). */
size_t tk_run_final_vertices(const tk_run *r);
/* The latest figures (step 0 before the first step). */
const tk_step_report *tk_run_latest(const tk_run *r);
const tk_step_report *tk_run_history(const tk_run *r, size_t *count);
/* Active struts and kinks of the last step, with their NNLS forces. */
const tk_strut *tk_run_struts(const tk_run *r, size_t *count);
const tk_kink *tk_run_kinks(const tk_run *r, size_t *count);
/* The force of each constraint on a vertex of the run's curve
 * (tk_run_curve(r)->pins, in their order) at the last step, into
 * force[0 .. npins): the part of the motion at the vertex its constraint
 * takes up, as a strut's force is its constraint's multiplier. */
int tk_run_pin_forces(const tk_run *r, double *force, tk_error *err);
tk_stop_reason tk_run_stop_reason(const tk_run *r);

/* One escape: where it started, the best ropelength then, where its
 * coarsest polygon ended, and what its tightening reached on the final
 * polygon (NAN while under way, or when the run stopped or gave it up
 * first: a try whose coarsest polygon ended above the best's is given up
 * there, and the last fifth of the budget polishes the best curve, and
 * what that reaches is no try's).  An explored try, made before the run
 * first left its coarsest polygon, deforms the lowest curve found there
 * and is judged there alone: `from` and `improved` compare its coarsest
 * polygon's end with that curve's, and it never reaches the final one. */
typedef struct tk_escape {
    long step;          /* the step after which the deformation was made */
    double from;        /* the best ropelength when it started */
    double amplitude;   /* of the deformation, in tube diameters */
    double coarse;      /* its coarsest polygon's last ropelength (NAN:
                           none, or not left yet) */
    double reached;
    bool improved;      /* reached < from (explored: coarse < from) */
    bool explored;      /* on the coarsest polygon only */
    bool turned;        /* the curve turned inside out (tk/relax.h), not
                           deformed: amplitude 0 */
} tk_escape;

const tk_escape *tk_run_escapes(const tk_run *r, size_t *count);

/* The knot or link type of the start as given, and of the run's curve at
 * the last check (after every resampling and at every stop; the start's
 * before any).  A run whose type changed has failed (TK_ETYPE). */
const tk_invariants *tk_run_type_start(const tk_run *r);
const tk_invariants *tk_run_type_latest(const tk_run *r);

/* Error recovery's last resorts and the step control's fallback, counted
 * over a run (fields of tk_run_timing; `tighten --json` reports them as
 * "recovery").  Rows as for the options. */
#define TK_RECOVERY_FIELDS(X)                                                                \
    X(undone_steps, LONG, 0, 0, 9e15, "undone_steps",                                        \
      "steps undone and taken again shorter because Newton steps could not restore the "     \
      "thickness (section 4.6)")                                                             \
    X(rescales, LONG, 0, 0, 9e15, "rescales",                                                \
      "rescalings of the whole curve about its centroid, autoscale not counted")             \
    X(largest_rescale, REAL, 0, 0, 1e300, "largest_rescale",                                 \
      "the largest of their factors, minus 1")                                               \
    X(bent_corrections, LONG, 0, 0, 9e15, "bent_corrections",                                \
      "corrections whose Newton and inequality steps could not restore the thickness and "   \
      "went on to steps weighed by their bending (section 4.6 on fine polygons)")            \
    X(length_steps, LONG, 0, 0, 9e15, "length_steps",                                        \
      "steps judged by their length alone: the length over the thickness their violation "   \
      "leaves rose at first order in the step size (section 4.5; the NNLS answer is not "    \
      "exact enough for the stiff kinks of a fine polygon)")                                 \
    X(corrected_steps, LONG, 0, 0, 9e15, "corrected_steps",                                  \
      "steps judged after their correction: along curved constraints the length over the "   \
      "thickness their violation leaves rose, and fell once the violation was corrected "    \
      "(section 4.6)")

/* A run's work (the step report's), counted in operations whose number
 * depends on the run's path alone, not on the machine or its load: each
 * a sum over the operations of their sizes, weighed into seconds of a
 * reference processor by what each cost it (engine/queries.c). */
typedef struct tk_work_counts {
    double checks;    /* vertices of each curve checked for its violation */
    double columns;   /* rigidity matrix columns built */
    double pivots;    /* motion NNLS iterations x (3 vertices + constraints) */
    double factors;   /* motion NNLS factorisations x (3 vertices + constraints) */
    double newton;    /* recovery solves x (3 vertices + constraints) */
    double turns;     /* vertices squared of each turn's relaxation */
    double deforms;   /* vertices of each deformation tried */
    double flops;     /* NNLS factorisations' floating-point operations */
} tk_work_counts;

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
    double figures;      /* each step's figures: its worst violation, kinks,
                            thickness and ropelength (included in total) */
    long nnls_solves, nnls_iterations, factorisations;
    double invariants;   /* the knot type computed and compared (included
                            in total) */
    tk_work_counts work; /* the operations counted, as the step's work
                            weighs them (a resumed run's since its resume) */
    TK_RECOVERY_FIELDS(TK_FIELD_DECLARE)
} tk_run_timing;

void tk_run_timing_get(const tk_run *r, tk_run_timing *out);

/* Going on after the process ended.  A run's place in its schedule is a
 * record (rows as for the options; a resumed run's budgets count from
 * its first start, so the step and time it reached are part of it):
 * with the run's curve, its best curve and the type of its start, that
 * is what tk_run_resume needs to go on where it was: at the same coarse
 * level and polishing, with the escapes it has left and the same random
 * stream.  What it does not keep is the history before it (the windows
 * that judge convergence begin again) and the warm start of the forces. */
#define TK_RESUME_FIELDS(X)                                                                  \
    X(step, LONG, 0, 0, 9e15, "step", "steps taken")                                        \
    X(seconds, REAL, 0, 0, 1e12, "seconds", "wall time spent")                              \
    X(work, REAL, 0, 0, 1e12, "work", "work done (tk_run_work)")                             \
    X(start_ropelength, REAL, 0, 0, 1e300, "start_ropelength",                              \
      "the ropelength of the input, before any resampling")                                  \
    X(coarse_level, INT, 0, 0, 64, "coarse_level", "halvings of the vertex count still to "  \
      "undo")                                                                                \
    X(coarse_levels, INT, 0, 0, 64, "coarse_levels", "coarse levels below the final "         \
      "polygon, late ones included (0: as the options reckon them)")                         \
    X(loose, INT, 0, 0, 2, "loose", "loose levels of the current schedule")                  \
    X(polish_level, INT, 0, 0, 1000, "polish_level", "times the ropelength has all but "     \
      "stopped falling on this polygon")                                                     \
    X(share_from, REAL, 0, 0, 1e9, "share_from",                                             \
      "the part of the budget spent when the current schedule began")                        \
    X(resolved_at, REAL, 0, 0, 1e300, "resolved_at",                                        \
      "ropelength at the last re-resolution (0: none yet)")                                  \
    X(final_ropelength, REAL, 0, 0, 1e300, "final_ropelength",                              \
      "the ropelength the final polygon's vertices are reckoned from (0: not yet fixed)")    \
    X(step_size, REAL, 0, 0, 1e300, "step_size", "the last step's size")                     \
    X(flow_time, REAL, 0, 0, 1e300, "flow_time", "the flow's time so far")                   \
    X(escapes, INT, 0, 0, 1000, "escapes", "escapes tried")                                 \
    X(draws, LONG, 0, 0, 9e15, "draws", "numbers drawn from the escapes' random stream")    \
    X(best_polish, INT, 0, 0, 1000, "best_polish", "the polishing level of the best curve")  \
    X(restarts, INT, 0, 0, 1e6, "restarts", "times the curve was replaced by another")

typedef struct tk_resume {
    TK_RESUME_FIELDS(TK_FIELD_DECLARE)
} tk_resume;

/* The run's place, for tk_run_resume. */
void tk_run_resume_point(const tk_run *r, tk_resume *out);

/* The best curve on the final polygon so far (kept by the escapes at
 * every step) and its figures into *report; NULL when there is none
 * (escapes off, or no step on the final polygon yet). */
const tk_curve *tk_run_best(const tk_run *r, tk_step_report *report);

/* A run that goes on from `curve` (the run's curve when `at` was taken),
 * with the options it started with: the first history entry is that
 * curve's figures at step at->step; steps and time count on from `at`.
 * `best` and `best_report` (both or neither) are tk_run_best's;
 * `start_type` the type of the first start (NULL: the curve's own, which
 * then cannot catch a change before the resume).  TK_EINVAL when `at` is
 * out of its domain or does not fit the options. */
int tk_run_resume(const tk_curve *curve, const tk_options *opts, const tk_resume *at,
                  const tk_curve *best, const tk_step_report *best_report,
                  const tk_invariants *start_type, tk_run **out, tk_error *err);

/* Snapshots: the vertex coordinates (3 * vertices doubles, same component
 * layout as tk_run_curve) every snapshot_every steps. */
size_t tk_run_snapshot_count(const tk_run *r);
const double *tk_run_snapshot(const tk_run *r, size_t k, long *step);

#endif
