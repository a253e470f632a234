/* tightknot: the state of a run and the rooms of the flow (private to
 * engine/; the public API is tk/tighten.h).
 *
 * The files stand in one order, lowest first; each calls only files below
 * it or on its own level, and two on one level never call each other
 * (tools/engine-calls.sh checks it on the object files; make lint runs it):
 *
 *   libraries   curve, geometry, struts, thickness, rigidity, nnls,
 *               invariants, vect, generate, record, error: no run state
 *   queries.c   read-only questions every room asks, writing nothing: the
 *               clock, the history's fall, whether the polygon is the final
 *               one, its mean edge, the tolerances of the step (shrunk by
 *               the schedule's polishing level)
 *   type.c      the knot or link type: the start's, and the check that the
 *               run's curve still has it
 *   active.c    the active set: the struts and kinks that hold the motion
 *   motion.c    the resolved motion (equation 13)
 *   stepping.c  the step (section 4.5) and its retries: a step that error
 *               recovery cannot restore is undone and taken shorter
 *   recovery.c  error recovery (section 4.6), and the curve before a step,
 *               kept to undo it
 *   schedule.c  the polygon: the start, coarse to fine, re-resolution and
 *               the polishing levels; the only room that changes the
 *               vertex count
 *   escape.c    when the final polygon has converged: a deformation of the
 *               best curve so far, tightened again (the schedule restarts
 *               from it), and the best curve restored when the run stops
 *   tighten.c   the run: creation, the order of a step, its figures, the
 *               history and snapshots, the stop criteria
 *
 * Stepping and recovery stand on one level (stepping calls recovery), as
 * do schedule and escape (escape calls schedule).  What a room needs to
 * know from one above it is passed down as an argument (tk_schedule_watch
 * is told whether escapes judge their tries on the polygon), never asked
 * by calling up.
 *
 * A step (tighten.c, tk_run_step) goes through the rooms in this order,
 * each deciding one thing:
 *
 *   escape.c    before the step: the deformation asked for after an
 *               earlier step, or the best curve back
 *   schedule.c  before the step: a coarse polygon refined, or the polygon
 *               re-resolved (decided after an earlier step, carried out
 *               here, so that a step's figures and its curve always
 *               describe the same polygon)
 *   stepping.c  the step's first attempt (tk_stepping_begin): the active
 *               set (active.c), the resolved motion (motion.c), the step
 *   schedule.c  polishing: the tolerances shrink when the ropelength all
 *               but stops falling (or, on a coarse polygon, the next level
 *               is due); after the motion, before error recovery, which
 *               then works to the new tolerances
 *   stepping.c  the rest of the step (tk_stepping_finish): error recovery
 *               (recovery.c), and a shorter step when it fails
 *   tighten.c   the step's figures, the history, the stop criteria (and
 *               the schedule's other cues to move on: a stall, a spent
 *               share of the budget)
 *   escape.c    after the figures: the best final curve so far kept, and
 *               on convergence an escape asked for
 *
 * Each room owns the sub-struct named after it: only its file writes it,
 * the others read, and a room that needs another's state changed asks its
 * owner through a function (tk_recovery_keep and tk_recovery_undo,
 * tk_active_restore, tk_stepping_resume, tk_escape_start).  The shared
 * part (the curve, the trial curve, the strut finder, the solver) is made
 * by tighten.c and resized by schedule.c alone, the only room that
 * changes the vertex count; stepping.c and recovery.c move the curve's
 * coordinates (and every room refits the finder to the curve it
 * measures).
 */
#ifndef TK_ENGINE_RUN_H
#define TK_ENGINE_RUN_H

#include <math.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "tk/invariants.h"
#include "tk/nnls.h"
#include "tk/struts.h"
#include "tk/tighten.h"

/* A set of constraints: struts, and kinks with the edge whose radius
 * function each holds (equation 3 is the minimum of one function per
 * edge, so a vertex whose edges are about equally long carries two). */
typedef struct tk_constraints {
    tk_strut_list struts;
    tk_kink *kinks;
    unsigned char *kink_edge;
    size_t nkinks, kink_capacity;
} tk_constraints;

/* A kink constraint's force from the last resolution, for the warm start. */
typedef struct tk_known_kink {
    size_t comp, vertex;
    int edge;
    double force;
} tk_known_kink;

struct tk_run {
    /* set at creation, never changed */
    tk_options opt;
    double tau;          /* the tube diameter, 2 radius */
    double min_radius;   /* lambda * radius: the bound on minrad */

    struct {
        tk_curve *curve;
        tk_curve *trial;
        tk_strut_finder *finder;
        tk_nnls *nnls;
        /* per vertex: its constraint, or NULL where it moves freely (an
         * open component's end with none stays where it is) */
        const tk_pin **pin;
        tk_pin *pins;    /* what pin points into, npins of them */
        size_t npins;
    } shared;

    struct {             /* active.c */
        tk_constraints set;        /* this step's active set, with forces */
        tk_kink *report;           /* one per vertex, forces summed */
        size_t nreport;
        tk_strut_list known_struts; /* the last resolution's, sorted, with forces */
        tk_known_kink *known_kinks;
        size_t nknown_kinks;
        double search_seconds, matrix_seconds;
    } active;

    struct {             /* motion.c */
        double *grad;    /* 3V: gradient of length */
        double *motion;  /* 3V: the motion, then the resolved motion */
        double *work;    /* 3V */
        double *x;       /* compressions, one per constraint */
        size_t x_capacity;
        double *x_last;  /* the last round's answer (momentum, motion.c) */
        size_t x_last_capacity;
        bool kept;       /* the last solve's factor is kept (tk/nnls.h) */
        double weight;   /* the proximal weight the last such solve ended
                            at (0: none) */
        double dear;     /* shrinking weights: the largest weight at which a
                            round lately needed the NNLS's fallback (0: none) */
        double nnls_seconds;
        long nnls_solves, nnls_iterations, factorisations;
    } motion;

    struct {             /* stepping.c */
        double step_size;
        int tiny_steps;
        double seconds;
        long length_steps; /* judged by their length (take_step) */
        long corrected_steps; /* judged after their correction (take_step) */
        int tiny_before; /* tiny_steps before this step's attempts */
        double *held;    /* 3V: the run's curve while a step's trial is
                            corrected */
    } stepping;

    struct {             /* recovery.c */
        tk_constraints violated;
        double *rhs;     /* one per violated constraint */
        size_t rhs_capacity;
        double *du;      /* 3V: a Newton step */
        double *before;  /* 3V: the curve before this step, to undo it */
        double *checked; /* 3V: the curve last checked, and what it gave */
        size_t checked_vertices; /* 0: none */
        double checked_worst;
        double seconds, nnls_seconds, check_seconds;
        long rescales, undone;
        long bent;       /* corrections that needed the bending metric */
        double largest_rescale; /* scale factor - 1 */
    } recovery;

    struct {             /* schedule.c */
        int polish_level;    /* times the ropelength has all but stopped falling */
        size_t polish_from;  /* history entries before the last change of
                                level or resampling */
        size_t polish_began; /* history entries before the level's first
                                stall (with polish_level > 0) */
        double resolved_at;  /* ropelength at the last re-resolution */
        double start_ropelength; /* of the input, before any resampling, by its
                                    self-distance (the vertex counts' reference) */
        double final_ropelength; /* the final polygon's reference, fixed when the
                                    run first reaches it or first escapes
                                    (0: not yet) */
        int coarse_level;    /* halvings of the vertex count still to undo */
        int coarse_levels;   /* of them at the start (with the vertices
                                option, once a loose start's ropelength
                                allows them, and at the final reference
                                once fixed) */
        bool move_on;        /* refine before the next step */
        size_t resampled_from; /* history entries before the last resampling */
        double share_from;   /* budget spent when the current schedule began
                                (an escape starts it again) */
        int restarts;        /* tk_schedule_restart's curves taken */
        int loose;           /* loose levels of the current schedule (the
                                first tightening's, or a loose try's) */
    } schedule;

    struct {             /* escape.c */
        uint64_t rng;        /* the deformations' random stream */
        int tries_before;    /* escapes tried before the run was resumed */
        tk_curve *best;      /* the best final polygon so far, or NULL */
        tk_step_report best_report;
        tk_constraints best_set; /* the active set of its step: found
                                    again at the curve alone it can lack a
                                    contact the step held (a kink just
                                    outside the tolerance) */
        int best_polish;     /* its polishing level */
        bool due;            /* deform before the next step */
        bool reserved;       /* the budget's reserve for the best has begun */
        bool polishing;      /* the curve is the best put back, not a try */
        double coarse;       /* where the curve under way (the first
                                tightening or a try) left its coarsest
                                polygon, NAN before that */
        size_t coarse_vertices; /* that polygon's vertices */
        double best_coarse;  /* the same for the best's tightening */
        size_t best_coarse_vertices;
        /* exploration: tries on the coarsest polygon alone, before the
           run first refines from it */
        tk_curve *explored;  /* the lowest plateau there so far, or NULL */
        tk_curve *start;     /* the start as given, for the first explored
                                try (NULL: none, or no memory for it) */
        double explored_rope, explored_thickness;
        int explore_tries;   /* logged among the tries, not counted
                                against the escapes option's */
        int explore_fails;   /* tries in a row that did not improve it */
        bool explore_over;   /* the run has left exploring (or never
                                explores: resumed, or no coarse level) */
        enum {               /* before the next step: */
            TK_EXPLORE_NONE,
            TK_EXPLORE_TRY,  /* a deformation of the lowest */
            TK_EXPLORE_BACK  /* the lowest back, on its own ropelength's
                                coarsest polygon (exploring over, or the
                                first plateau resolved) */
        } explore_pending;
        bool explore_goes_on; /* exploring over, the explored try under
                                 way goes on (lower than the lowest) */
        bool explore_resolved; /* the first plateau was put back once */
        tk_escape *log;      /* one per try */
        size_t nlog, log_capacity;
        int improved;
        int most;            /* escapes option, or 0 for a curve with an open component */
    } escape;

    tk_work_counts work; /* counted where the operations are (the flops
                            by the NNLS solver, tk_nnls_work_done) */

    struct {             /* tighten.c */
        tk_step_report latest;
        tk_step_report *history;
        size_t nhistory, history_capacity;
        double *snapshots;
        long *snapshot_steps;
        size_t nsnapshots, snapshot_capacity;
        double started;   /* tk_clock() at the start, less a resumed run's seconds */
        double cpu_spent; /* with cpu_time: the run's processor seconds before this call */
        double cpu_entered; /* the thread's processor clock where this call began */
        double work_from; /* a resumed run's work before it (tk_run_work) */
        double flow_from; /* the flow's time at the start (a resumed run's) */
        tk_stop_reason stop;
        atomic_int cancel;
        tk_progress_fn progress;
        void *user;
        double seconds;  /* spent in tk_run_new and tk_run_step */
        double figures_seconds; /* a step's figures measured and recorded */
    } life;

    struct {             /* type.c: the knot or link type */
        tk_invariants start;   /* of the input, as given */
        tk_invariants latest;  /* of the run's curve at the last check */
        long checked_step;     /* the step of the last check, -1 before */
        size_t checked_vertices;
        double seconds;
    } type;
};

/* Grows *v (capacity *cap) to hold n doubles, doubling from 64. */
static inline int tk_grow_doubles(double **v, size_t *cap, size_t n, tk_error *err)
{
    if (n <= *cap)
        return TK_OK;
    size_t want = *cap ? *cap : 64;
    while (want < n)
        want *= 2;
    double *grown = realloc(*v, want * sizeof *grown);
    if (!grown)
        return tk_error_set(err, TK_ENOMEM, "out of memory for %zu constraints", n);
    *v = grown;
    *cap = want;
    return TK_OK;
}

static inline double tk_norm(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
}

/* ---- queries.c: read-only, below every room ---- */

/* Monotonic wall time in seconds, for the timing figures. */
double tk_clock(void);

/* The run's own clock, whose seconds its reports give and its time
 * budget counts: the wall clock since the start, or with cpu_time the
 * processor time of the threads that ran it, summed over the calls into
 * the run (tk_run_clock_enter and _leave bracket each, on its thread; a
 * run can be driven by one thread and then another). */
double tk_run_clock(const tk_run *r);
void tk_run_clock_enter(tk_run *r);
void tk_run_clock_leave(tk_run *r);

/* The run's work so far (a resumed run's before it included), in seconds
 * of a reference processor: its operations (r->work and the NNLS
 * solver's, tk_nnls_work_done) weighed by what each cost on that
 * processor.  A function of the run's path alone, so that a budget of
 * work (max_work) gives the same run on any machine at any load. */
double tk_run_work(const tk_run *r);
/* Its counts, the NNLS solver's flops included. */
void tk_run_work_counts(const tk_run *r, tk_work_counts *out);

/* How much the ropelength fell over the last `window` entries of the
 * history, relative: the lowest over them below the lowest over the
 * window before (entries from `from` on).  Lowest, not last: before the
 * first contact the thickness is often one vertex's curvature bound,
 * which wavers from step to step, and a run still falling by 0.4% in 300
 * steps (T(3,7) at 10,000 vertices) ended its window on a spike above
 * the ropelength 300 steps before and was taken for converged.  A rise
 * is a negative fall, and the callers take it as they take a small fall:
 * no progress at this level, polish or try.  Near a critical point the
 * ropelength rises and falls by up to 1e-4 a window while the step is
 * too long for the polygon: the catalogue trefoil to its critical point
 * (tests/test_tighten.c) ends at 32.7704 after 1600 steps, and at 32.7766
 * when a rise of more than the threshold does not count as settled.
 * (A loose curve's rise, its narrowest gap opening before the strands
 * close in, is kept from being read as one: autoscale keeps such a curve
 * at the tube.)  False (and *fall untouched) while the history since
 * `from` holds no more than `window` entries. */
bool tk_history_fall(const tk_run *r, size_t from, size_t window, double *fall);

/* Whether the run is on its final polygon (no coarse level left). */
bool tk_schedule_final(const tk_run *r);

/* The mean edge of the run's polygon over the diameter (0 when unknown). */
double tk_mean_edge(const tk_run *r);

/* The tolerances of the step, as fractions of the diameter: the active
 * one (a constraint within it holds the motion), the kinks' (as strict or
 * looser where kinks are stiff), the overstep (the largest violation a
 * step may make) and the correction (what error recovery corrects down
 * to).  All shrink by tk_polish_scale's factor as the run polishes. */
double tk_tolerance_active(const tk_run *r);
double tk_tolerance_kink(const tk_run *r);
double tk_tolerance_overstep(const tk_run *r);
double tk_tolerance_correction(const tk_run *r);
/* The factor the schedule's polishing level takes the tolerances down by. */
double tk_polish_scale(const tk_run *r);
/* Whether the active tolerance is reckoned from the mean edge (on a fine
 * polygon) rather than the options'. */
bool tk_tolerance_from_edge(const tk_run *r);

/* ---- type.c: below every room ---- */

/* The start's knot or link type: `known` copied (a resumed run's), or told
 * from `start` as given. */
int tk_type_start(tk_run *r, const tk_curve *start, const tk_invariants *known, tk_error *err);
/* The run's curve still has the start's knot or link type; else TK_ETYPE
 * with a message that begins with `when` ("resampling to 400 vertices"). */
int tk_type_check(tk_run *r, const char *when, tk_error *err);
/* Whether `c` (a curve the run may take: a deformation, a resampled try)
 * has the start's type, into *kept; TK_ENOMEM only. */
int tk_type_kept(tk_run *r, const tk_curve *c, bool *kept, tk_error *err);
void tk_type_free(tk_run *r);

/* ---- active.c ---- */

/* The active constraints of curve c into *set (the finder must be fitted
 * to c). */
int tk_active_find(tk_run *r, const tk_curve *c, tk_constraints *set, tk_error *err);
/* Adds to the active set the constraints a step to `trial` broke that were
 * not active (the finder fitted to `trial`); *added counts them.  When the
 * struts among them are more than `most`, none is added (*added 0). */
int tk_active_expand(tk_run *r, const tk_curve *trial, size_t most, size_t *added,
                     tk_error *err);
/* The rigidity matrix of a set at c, the rows of pinned vertices projected
 * onto the directions their constraints allow (tk_pin_project). */
int tk_active_matrix(tk_run *r, const tk_curve *c, const tk_constraints *set,
                     cholmod_sparse **a, tk_error *err);
/* The forces x (struts, then kinks) onto the active set, kept for the next
 * step's warm start. */
int tk_active_set_forces(tk_run *r, const double *x, tk_error *err);
/* The warm start: the last forces of the active set's constraints into x. */
void tk_active_guess_forces(const tk_run *r, double *x);
/* The kinks as reported (one per vertex, forces summed). */
int tk_active_report(tk_run *r, tk_error *err);
/* The active set becomes a copy of `set` (the best curve's, put back). */
int tk_active_restore(tk_run *r, const tk_constraints *set, tk_error *err);
/* A new polygon: no active set, no warm start. */
void tk_active_reset(tk_run *r);
void tk_active_free(tk_run *r);
void tk_constraints_free(tk_constraints *set);
int tk_constraints_copy(tk_constraints *dst, const tk_constraints *src, tk_error *err);
double tk_branch_radius(const tk_curve *c, size_t v, int edge);

/* ---- motion.c ---- */

/* Resolves the motion against the active set (equation 13). */
int tk_motion_resolve(tk_run *r, tk_step_report *rep, bool equalise, tk_error *err);
/* Whether the motion shortens the curve at first order. */
bool tk_motion_descends(const tk_run *r);
int tk_motion_fit(tk_run *r, size_t vertices, tk_error *err);
void tk_motion_free(tk_run *r);

/* ---- stepping.c ---- */

/* A step's first attempt: the curve kept to undo it (tk_recovery_keep),
 * the active set found, the motion resolved and the step taken (section
 * 4.5).  The step's figures go into *rep. */
int tk_stepping_begin(tk_run *r, tk_step_report *rep, tk_error *err);
/* The rest of the step after tk_stepping_begin (whose status is rc): its
 * violations corrected (error recovery, when over half the overstep
 * tolerance); when Newton steps cannot restore the thickness, the step
 * undone and taken again a quarter as long, up to STEP_ATTEMPTS in all,
 * and failing that no step, the curve corrected as a start's is.  The
 * finder is left fitted to the run's curve. */
int tk_stepping_finish(tk_run *r, tk_step_report *rep, int rc, tk_error *err);
/* The step size has been nothing for too many steps. */
bool tk_stepping_stalled(const tk_run *r);
void tk_stepping_reset(tk_run *r);
/* A run's first step size: a resumed run's last, or 0 (the first step
 * then tries an eighth of the largest). */
void tk_stepping_resume(tk_run *r, double step_size);
int tk_stepping_fit(tk_run *r, size_t vertices, tk_error *err);
void tk_stepping_free(tk_run *r);

/* ---- recovery.c ---- */

/* Worst violation of the constraints by c as a fraction of the bound (0
 * when all hold); the finder must be fitted to c.  The curve a step
 * accepts is the last trial it checked, and the step's figures check it
 * again: a curve equal to the last one checked is not searched twice. */
int tk_recovery_violation(tk_run *r, const tk_curve *c, double *out, tk_error *err);
/* Prepares the checks of the curves c + s h motion, 0 <= s <= 1 (a
 * step's trial points; fastest the largest |motion| of a vertex): they
 * look at the edge pairs near them alone (tk_strut_finder_near), with the
 * same answers, and so do the corrections after it and the next active
 * set's search while they stay near.
 * The pairs are found again only when the last ones do not cover those
 * curves (the finder is then fitted to the run's curve). */
int tk_recovery_near(tk_run *r, const double *motion, double h, double fastest, tk_error *err);
/* Corrects the run's curve until no constraint is violated beyond the
 * correction tolerance (section 4.6), with at most `most` Newton steps
 * (TK_CORRECTIONS after a step); the finder is then fitted to it.  What
 * the Newton steps leave is removed by rescaling the curve about its
 * centroid when the factor that takes is at most 1 + rescale_up_to;
 * otherwise the call fails with TK_ENUMERIC, the curve as the Newton steps
 * left it. */
#define TK_CORRECTIONS 25
int tk_recovery_correct(tk_run *r, int most, double rescale_up_to, int *iterations,
                        tk_error *err);
/* Rescaling the whole curve throws away its contacts (and at a violation
 * of a few percent, the work of minutes): after a step it is only a
 * feasibility fix, by a factor of at most 1 + 1e-6; a step that needs
 * more is undone and taken again shorter, and one that cannot be taken
 * shorter either moves nothing.  A start may need more (its own slack). */
#define TK_RESCALE_FEASIBILITY 1e-6
#define TK_RESCALE_START(r) (10.0 * (r)->opt.overstep_tolerance)
/* Scales the curve about its centroid to undo a violation `worst`. */
void tk_recovery_rescale(tk_run *r, double worst);
/* Keeps the run's curve as it is before a step, to undo the step. */
void tk_recovery_keep(tk_run *r);
/* The run's curve back to the one kept; `counted` among the undone steps
 * (tk_run_timing) when it is a step given up for a shorter one. */
void tk_recovery_undo(tk_run *r, bool counted);
int tk_recovery_fit(tk_run *r, size_t vertices, tk_error *err);
void tk_recovery_free(tk_run *r);

/* ---- schedule.c ---- */

/* The run's curve from `start`: resampled (to the coarsest level's count)
 * and autoscaled as the options ask, and everything sized by it. */
int tk_schedule_start(tk_run *r, const tk_curve *start, tk_error *err);
/* A resumed run's schedule: its curve as it is, at the level, polishing
 * and share of `at` (tk_schedule_resume_point's). */
int tk_schedule_resume(tk_run *r, const tk_curve *curve, const tk_resume *at, tk_error *err);
void tk_schedule_resume_point(const tk_run *r, tk_resume *out);
/* Resizes the shared part and the rooms' vectors to the run's curve. */
int tk_schedule_fit(tk_run *r, tk_error *err);
/* The run's curve replaced by `curve` (taken over): with `coarse` the
 * schedule starts again from its coarsest level (the curve resampled to
 * it), or with `loose` too from the loose levels below it where the run
 * has them and the resampled curve keeps its type; else `curve` is on the
 * final polygon (the escapes' best): it keeps its vertices, the schedule
 * is at the final level and the polishing level is `polish`; made
 * feasible by scaling, type-checked. */
int tk_schedule_restart(tk_run *r, tk_curve *curve, bool coarse, bool loose, int polish,
                        tk_error *err);
/* The same on the coarsest level before the final polygon is fixed (the
 * escapes' exploration): `curve` resampled to that level's vertices at
 * ropelength `rope`, or kept as it is with 0; with `loose`, on the loose
 * levels as tk_schedule_restart puts it. */
int tk_schedule_explore(tk_run *r, tk_curve *curve, double rope, bool loose, tk_error *err);
/* The vertices of the coarsest level at ropelength `rope`. */
size_t tk_schedule_coarsest_count(tk_run *r, double rope);
/* The fraction of the step or time budget spent (0 without one). */
double tk_schedule_spent(const tk_run *r);
/* The same at the step of report s. */
double tk_schedule_spent_at(const tk_run *r, const tk_step_report *s);
/* Before a step: refines or re-resolves if due. */
int tk_schedule_before_step(tk_run *r, tk_error *err);
/* After a step's motion: polishing (or, on a coarse polygon, moving on).
 * `judged_here`: tk_escape_judged_here's answer, passed down by the run
 * (a coarse level where tries are judged is polished as the final one). */
void tk_schedule_watch(tk_run *r, bool judged_here);
/* Refine before the next step; false on the final polygon. */
bool tk_schedule_move_on(tk_run *r);
/* On a coarse polygon, whether its share of the step or time budget is
 * spent. */
bool tk_schedule_share_spent(const tk_run *r);
size_t tk_schedule_final_count(const tk_run *r);
/* Whether the run has gone as far as its tolerances allow: on the final
 * polygon, at its last polishing level, and stopped falling there. */
bool tk_schedule_settled(const tk_run *r);
/* A window of `steps` steps at resolution 5, counted for the run's
 * polygon: as many more steps as its mean edge is shorter. */
size_t tk_schedule_window(const tk_run *r, size_t steps);

/* ---- escape.c ---- */

/* A new run's escapes: the random stream at the seed, nothing explored
 * or noted yet (a resumed run explores no more), none at all for a start
 * with an open component. */
void tk_escape_start(tk_run *r, bool resumed, const tk_curve *start);
/* Whether the final polygon has converged: its ropelength fell by less
 * than a set fraction over a window of steps, or by less than a larger
 * one for a set share of the budget (a crawl). */
bool tk_escape_converged(const tk_run *r);
/* Whether the run's polygon is where its tries are judged (the coarsest
 * level of a try, explored or not, or of a curve put back after one; not
 * the best's polishing): polished there before it is left, as a final
 * polygon is. */
bool tk_escape_judged_here(const tk_run *r);
/* After each step's figures, with escapes: the curve on the final polygon
 * is kept if it is the best so far, and the try under way's lowest noted. */
void tk_escape_after_step(tk_run *r);
/* Asks for an escape before the next step when tries and budget remain
 * (the attempt that converged is noted); false when none is left. */
bool tk_escape_ask(tk_run *r);
/* Once the budget's reserve for polishing the best curve begins: asks
 * for the best back (escape.due) when the try under way is behind it. */
void tk_escape_reserve(tk_run *r);
/* Before a step: the deformation (or, with no tries left, the best curve
 * back) when asked for. */
int tk_escape_before_step(tk_run *r, tk_error *err);
/* The run has stopped: the best curve found becomes its result
 * (*restored when that is not the curve it stopped on). */
int tk_escape_finish(tk_run *r, bool *restored, tk_error *err);
/* Escapes tried, before a resume and since. */
int tk_escape_tries(const tk_run *r);
/* The escapes' part of the run's resume point. */
void tk_escape_resume_point(const tk_run *r, tk_resume *out);
/* A resumed run's escapes: tries before, the random stream's position
 * and the best curve (copied). */
int tk_escape_resume(tk_run *r, const tk_resume *at, const tk_curve *best,
                     const tk_step_report *best_report, tk_error *err);
void tk_escape_free(tk_run *r);

/* (tighten.c, above every room, declares nothing here: its functions are
 * tk/tighten.h's.) */

#endif
