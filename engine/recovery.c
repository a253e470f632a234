/* Error recovery (section 4.6): how far the curve violates its constraints,
 * Newton steps back into the feasible set, and the curve before a step, kept
 * to undo it when they fail.  It works on a constraint set of its own, so the
 * step's active set (with the forces the step reports) is left as it was.
 * See run.h for the rooms of the flow. */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "tk/geometry.h"

/* The Newton steps are damped least-squares steps (tk/nnls.h): with more
 * violated struts than coordinates (a vertex near several edges of a
 * strand it touches along its length: the round Hopf link at 300 vertices
 * a ring has 4072 for 1800 coordinates) the system is inconsistent, and
 * its minimum-norm answer so long that the step had to be cut to 3e-4 of
 * it, twelve times in a row, before a rescaling took over; damped, two
 * steps restore it. */
#define RECOVERY_DAMPING 1e-6
/* The damping adapts (Levenberg-Marquardt) between RECOVERY_DAMPING and
 * RECOVERY_DAMPING_MOST (the most tk_nnls_min_norm takes).  Where the
 * violated constraints nearly contradict each other (a strut whose repair
 * bends a vertex at the curvature bound), the least-damped step is far too
 * long: on catalogue 5.1 at resolution 5 it moved a vertex by 0.03 of the
 * diameter to undo violations of 1.7e-3, and was cut to 1/256 of itself
 * every time, the worst violation falling by 0.1% a step (1.8e-3 to
 * 1.36e-3 in 236 steps at a refinement); after a step, at a run of kinks,
 * it fell by 0.85 a step and 25 corrections were often not enough (735
 * steps undone in 60 s).  With the damping raised where steps are cut
 * short: 7.5e-4 after 12 steps at that refinement, and no step undone in
 * 60 s. */
#define RECOVERY_DAMPING_MOST 1e-2
#define RECOVERY_DAMPING_STEP 10.0
#define RECOVERY_HALVINGS_KEPT 3
/* Checks near the curve look this far at most (in diameters): a farther
 * trial is checked with the tree.  The pairs are found for NEAR_AHEAD
 * times the step's reach, so that the next steps, which start where this
 * one ended, can use them too, and found again when that is more than
 * NEAR_AHEAD times what a step needs (the list grows with the reach). */
#define NEAR_REACH_MOST 1e-3
#define NEAR_AHEAD 4.0

void tk_recovery_free(tk_run *r)
{
    tk_constraints_free(&r->recovery.violated);
    free(r->recovery.rhs);
    free(r->recovery.du);
    free(r->recovery.before);
    free(r->recovery.checked);
}

void tk_recovery_keep(tk_run *r)
{
    const tk_curve *c = r->shared.curve;
    memcpy(r->recovery.before, c->xyz, 3 * c->nvert * sizeof *c->xyz);
}

void tk_recovery_undo(tk_run *r, bool counted)
{
    tk_curve *c = r->shared.curve;
    memcpy(c->xyz, r->recovery.before, 3 * c->nvert * sizeof *c->xyz);
    if (counted)
        r->recovery.undone++;
}

int tk_recovery_fit(tk_run *r, size_t vertices, tk_error *err)
{
    free(r->recovery.du);
    free(r->recovery.before);
    free(r->recovery.checked);
    r->recovery.du = calloc(3 * vertices, sizeof *r->recovery.du);
    r->recovery.before = calloc(3 * vertices, sizeof *r->recovery.before);
    r->recovery.checked = calloc(3 * vertices, sizeof *r->recovery.checked);
    r->recovery.checked_vertices = 0;
    if (!r->recovery.du || !r->recovery.before || !r->recovery.checked)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a run of %zu vertices", vertices);
    return TK_OK;
}

/* (tau - closest admissible pair) / tau and (lambda r - minrad) /
 * (lambda r), the worse of the two. */
int tk_recovery_violation(tk_run *r, const tk_curve *c, double *out, tk_error *err)
{
    double t0 = tk_clock(), closest;
    size_t n3 = 3 * c->nvert;
    /* the last curve checked: its answer (a function of the curve alone) */
    if (r->recovery.checked_vertices == c->nvert &&
        !memcmp(r->recovery.checked, c->xyz, n3 * sizeof *c->xyz)) {
        *out = r->recovery.checked_worst;
        r->recovery.check_seconds += tk_clock() - t0;
        return TK_OK;
    }
    int rc = TK_OK;
    r->work.checks += (double)c->nvert;
    if (!tk_strut_finder_closest_near(r->shared.finder, c, r->tau, &closest))
        rc = tk_strut_finder_closest_pair(r->shared.finder, c, TK_ARC_ADMISSIBLE, r->tau,
                                          r->tau, &closest, err);
    if (!rc) {
        double minrad = tk_curve_minrad(c, NULL);
        double v = fmax((r->tau - closest) / r->tau, (r->min_radius - minrad) / r->min_radius);
        *out = fmax(v, 0.0);
        if (r->recovery.checked) {
            memcpy(r->recovery.checked, c->xyz, n3 * sizeof *c->xyz);
            r->recovery.checked_vertices = c->nvert;
            r->recovery.checked_worst = *out;
        }
    }
    r->recovery.check_seconds += tk_clock() - t0;
    return rc;
}

int tk_recovery_near(tk_run *r, const double *motion, double h, double fastest, tk_error *err)
{
    double t0 = tk_clock();
    int rc = TK_OK;
    const tk_curve *c = r->shared.curve;
    /* (and the active set's search at the next step's start) */
    double need = fmax(h * fastest, tk_tolerance_active(r) * r->tau);
    if (h * fastest <= NEAR_REACH_MOST * r->tau &&
        !tk_strut_finder_near_covers(r->shared.finder, c, motion, h,
                                     NEAR_AHEAD * NEAR_AHEAD * need, TK_ARC_ADMISSIBLE, r->tau)) {
        tk_strut_finder_refit(r->shared.finder, c);
        double reach = fmin(NEAR_AHEAD * need, NEAR_REACH_MOST * r->tau);
        rc = tk_strut_finder_near(r->shared.finder, c, TK_ARC_ADMISSIBLE, r->tau, reach, err);
    }
    r->recovery.check_seconds += tk_clock() - t0;
    return rc;
}

/* Scaling about the centroid raises every distance and radius in
 * proportion: the factor that undoes a violation of `worst` (a fraction
 * of the bound), and RESCALE_AIM more so that rounding leaves nothing
 * violated.  (Aiming as far inside as the Newton steps do, half the
 * correction tolerance, made the factor after a step at least
 * 1 + 1.5e-6, above what a feasibility fix may be: catalogue 3.1's
 * disguised start at resolution 5 then had 1,443 steps undone in 120 s.) */
#define RESCALE_AIM 1e-9
static double rescale_factor(double worst)
{
    return (1.0 + RESCALE_AIM) / (1.0 - worst);
}

/* Scales the curve about its centroid by rescale_factor(worst); the
 * finder is then fitted to it. */
void tk_recovery_rescale(tk_run *r, double worst)
{
    tk_curve *c = r->shared.curve;
    double centre[3], back[3];
    tk_curve_centroid(c, centre);
    for (int k = 0; k < 3; k++) {
        back[k] = centre[k];
        centre[k] = -centre[k];
    }
    double factor = rescale_factor(worst);
    tk_curve_translate(c, centre);
    tk_curve_scale(c, factor);
    tk_curve_translate(c, back);
    r->recovery.rescales++;
    r->recovery.largest_rescale = fmax(r->recovery.largest_rescale, factor - 1.0);
    tk_strut_finder_refit(r->shared.finder, c);
}

/* Only the violated constraints, each aimed a little inside the feasible
 * set so rounding does not leave it just violated.  Asking the others to
 * stay put (R = 0) makes the system inconsistent wherever two constraints
 * have (nearly) the same gradient and only one is violated (the two edges
 * at a vertex contact, the two radius functions at a kink): its
 * minimum-norm answer is then long and useless.  Those that become
 * violated join next time.  Returns how many, with their deficits in
 * rhs. */
static size_t keep_violated(tk_run *r)
{
    tk_constraints *set = &r->recovery.violated;
    double *rhs = r->recovery.rhs;
    double aim = 0.5 * tk_tolerance_correction(r);
    size_t nv = 0, nb = 0;
    for (size_t j = 0; j < set->struts.count; j++) {
        double deficit = r->tau * (1.0 + aim) - set->struts.items[j].length;
        if (deficit > 0.0) {
            set->struts.items[nv] = set->struts.items[j];
            rhs[nv++] = deficit;
        }
    }
    for (size_t k = 0; k < set->nkinks; k++) {
        double deficit = r->min_radius * (1.0 + aim) - set->kinks[k].minrad;
        if (deficit > 0.0) {
            set->kinks[nb] = set->kinks[k];
            set->kink_edge[nb] = set->kink_edge[k];
            rhs[nv + nb++] = deficit;
        }
    }
    set->struts.count = nv;
    set->nkinks = nb;
    return nv + nb;
}

/* The step recovery.du from the run's curve, halved until the worst
 * violation falls, at most 12 times.  *improved whether it fell (the
 * run's curve then moved, *worst its new violation), *halvings how many
 * times the step was cut.  The finder is left fitted to the run's curve. */
static int line_search(tk_run *r, double *worst, int *halvings, bool *improved, tk_error *err)
{
    tk_curve *c = r->shared.curve, *t = r->shared.trial;
    const double *du = r->recovery.du;
    size_t n3 = 3 * c->nvert;
    int rc = TK_OK;
    *improved = false;
    /* Never move a vertex by more than a tenth of the diameter. */
    double longest = 0.0;
    for (size_t v = 0; v < c->nvert; v++)
        longest = fmax(longest, tk_norm(du + 3 * v, 3));
    double alpha = longest > 0.1 * r->tau ? 0.1 * r->tau / longest : 1.0;
    for (*halvings = 0; *halvings < 12 && !rc; ++*halvings, alpha *= 0.5) {
        for (size_t i = 0; i < n3; i++)
            t->xyz[i] = c->xyz[i] + alpha * du[i];
        tk_strut_finder_refit(r->shared.finder, t);
        double trial_worst;
        rc = tk_recovery_violation(r, t, &trial_worst, err);
        if (!rc && trial_worst < *worst) {
            memcpy(c->xyz, t->xyz, n3 * sizeof *c->xyz);
            *worst = trial_worst;
            *improved = true;
            break;
        }
    }
    tk_strut_finder_refit(r->shared.finder, c);
    return rc;
}

/* The Newton steps' metric.  On a fine polygon a vertex's radius of
 * curvature is stiff to any motion that is not smooth: moving it by d
 * across edges of length e that turn by theta changes the radius by about
 * 2 d / (e theta) of itself.  The minimum-norm step on the violated
 * constraints is rough at the scale of an edge (it moves only the
 * vertices of violated struts), and on a tight trefoil of 4,800 vertices
 * resampled to 2,400 (struts violated by up to 4.9e-6, two radii by
 * 9.4e-6) every such step broke the curvature bound at some vertex by 13%
 * to 97%, however damped, until the curve had to be rescaled.  So the
 * damping measures a step by its bending as well as its length:
 *     du' M du = |du|^2 + l^4 |du''|^2,
 * du'' the second differences along each component over its mean edge
 * squared.  A motion a sin(s / l) changes a strut by up to a, a/tau of
 * its bound, and a radius by about a r^2 / l^2, a r_min / l^2 of its
 * bound: l^2 = tau r_min makes the two alike, so that a step which mends
 * the struts bends the curve by as little.  On that curve, after the
 * plain Newton and inequality steps, two such steps restore it (3.7 s
 * in all, the length up 2.6e-6; it used to be scaled up by 1 + 9.3e-6).
 * Alone, without the inequality steps before them, they restore it in
 * two (0.5 s). */
static int metric_build(const tk_run *r, cholmod_common *cc, cholmod_sparse **out,
                        tk_error *err)
{
    const tk_curve *c = r->shared.curve;
    size_t m = 3 * c->nvert;
    double l2 = r->tau * r->min_radius;
    *out = NULL;
    /* nine entries a vertex: its three rows of three */
    cholmod_triplet *t = cholmod_allocate_triplet(m, m, 3 * m, 0, CHOLMOD_REAL, cc);
    if (!t)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a recovery step");
    int *ti = t->i, *tj = t->j;
    double *tx = t->x;
    size_t rows = 0;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t ne = tk_curve_comp_edges(c, comp);
        double edge = ne ? tk_curve_comp_length(c, comp) / (double)ne : 0.0;
        if (!(edge > 0.0))
            continue;
        /* row (as t's column) v of the second difference, in units of
         * l^2: (x_prev - 2 x_v + x_next) l^2 / e^2; a pinned vertex moves
         * along its constraint alone, so its column is left out (its
         * rows of the step are then the projected rigidity matrix's) */
        double w = l2 / (edge * edge);
        size_t first = c->offset[comp], count = tk_curve_comp_vertices(c, comp);
        for (size_t v = first; v < first + count; v++) {
            size_t at[3], prev, next;
            if (!tk_curve_vertex_neighbours(c, v, &prev, &next))
                continue;
            at[0] = prev;
            at[1] = v;
            at[2] = next;
            for (int x = 0; x < 3; x++, rows++)
                for (int k = 0; k < 3; k++) {
                    if (r->shared.pin[at[k]])
                        continue;
                    ti[t->nnz] = (int)(3 * at[k] + (size_t)x);
                    tj[t->nnz] = (int)rows;
                    tx[t->nnz++] = k == 1 ? -2.0 * w : w;
                }
        }
    }
    assert(t->nnz <= t->nzmax && rows <= m);
    t->ncol = rows;
    int rc = TK_OK;
    double one[2] = {1.0, 0.0};
    cholmod_sparse *st = cholmod_triplet_to_sparse(t, t->nnz, cc);
    cholmod_sparse *sst = st ? cholmod_aat(st, NULL, 0, 1, cc) : NULL;
    cholmod_sparse *eye = sst ? cholmod_speye(m, m, CHOLMOD_REAL, cc) : NULL;
    if (!eye || !(*out = cholmod_add(sst, eye, one, one, 1, 1, cc)))
        rc = tk_error_set(err, TK_ENOMEM, "out of memory for a recovery step");
    cholmod_free_sparse(&eye, cc);
    cholmod_free_sparse(&sst, cc);
    cholmod_free_sparse(&st, cc);
    cholmod_free_triplet(&t, cc);
    return rc;
}

/* One Newton step with the given damping in the metric (metric_build) on
 * the violated constraints (the columns of a, their deficits in
 * recovery.rhs), through line_search. */
static int damped_step(tk_run *r, const cholmod_sparse *a, const cholmod_sparse *metric,
                       double damping, double *worst, int *halvings, bool *improved,
                       tk_error *err)
{
    double delta = 0.0;
    double t0 = tk_clock();
    *improved = false;
    r->work.newton += (double)(a->nrow + a->ncol);
    int rc = tk_nnls_min_norm(r->shared.nnls, a, r->recovery.rhs, damping, metric,
                              r->recovery.du, &delta, err);
    r->recovery.nnls_seconds += tk_clock() - t0;
    return rc ? rc : line_search(r, worst, halvings, improved, err);
}

/* Where the violated constraints contradict each other as equations (at
 * catalogue 5.1's refinement to 270 vertices one's linearised change had
 * the wrong sign, down to -6.8 times its deficit, whatever the damping),
 * the least-distance problem with inequalities still has an answer:
 * scaling the curve up lengthens every strut and radius, so
 *     minimise |du|  subject to  A^T du >= d
 * over all the active constraints (d_j the deficit, negative for one with
 * slack to give) is feasible, and over-satisfying a constraint is allowed
 * where the equations had to split the difference.  Its dual is the
 * non-negative quadratic problem
 *     minimise 1/2 y^T (A^T A + delta D) y - d^T y,  y >= 0,  du = A y
 * (D = diag(A^T A), delta D damping it as the Newton steps are), which is
 * the NNLS problem min |B y - b| with B = [A; sqrt(delta D)] and
 * b = [0; d / sqrt(delta D)]: B^T B is that matrix and B^T b = d.  At its
 * answer A^T du >= d - delta D y, equal where y_j > 0. */
#define INEQUALITY_DAMPING 1e-4
/* At most this many inequality steps, or a tenth of the Newton steps
 * allowed where that is more: a refinement (400) may need more than a
 * step's correction.  Generated T(2,5) at resolution 5, refined from 121
 * to 242 vertices after an escape: 11 Newton steps left 7.8e-4, ten
 * inequality steps 1.03e-4 (the curve was rescaled by that), the 11th
 * and 12th 2.5e-6 and 0. */
#define INEQUALITY_STEPS 10
/* They stop when one lowers the worst violation by less than this
 * fraction of it.  Where the worst is a curvature bound that any motion of
 * the thousands of struts' vertices bends further (a tight trefoil of
 * 4,800 vertices resampled to 2,400: two kinks 9.4e-6 over, the whole
 * curve's struts up to 4.9e-6), each step lowered it by 0.1% in 3 to 5 s
 * (9.37e-6 to 9.30e-6 in ten steps, 36 s); the steps that follow
 * (metric_build) restore it. */
#define INEQUALITY_CRAWL 0.01

/* One such step over the active set at the run's curve, through
 * line_search (*improved and *worst as it reports them). */
static int inequality_step(tk_run *r, double *worst, bool *improved, tk_error *err)
{
    tk_curve *c = r->shared.curve;
    tk_constraints *set = &r->recovery.violated;
    *improved = false;
    int rc = tk_active_find(r, c, set, err);
    size_t n = set->struts.count + set->nkinks, m = 3 * c->nvert;
    if (!rc)
        rc = tk_grow_doubles(&r->recovery.rhs, &r->recovery.rhs_capacity, n, err);
    if (rc || n == 0)
        return rc;
    double aim = 0.5 * tk_tolerance_correction(r);
    for (size_t j = 0; j < set->struts.count; j++)
        r->recovery.rhs[j] = r->tau * (1.0 + aim) - set->struts.items[j].length;
    for (size_t k = 0; k < set->nkinks; k++)
        r->recovery.rhs[set->struts.count + k] = r->min_radius * (1.0 + aim) - set->kinks[k].minrad;
    cholmod_common *cc = tk_nnls_common(r->shared.nnls);
    cholmod_sparse *a = NULL, *b = NULL;
    double *rhs = calloc(m + n, sizeof *rhs), *y = calloc(n, sizeof *y);
    rc = rhs && y ? tk_active_matrix(r, c, set, &a, err)
                  : tk_error_set(err, TK_ENOMEM, "out of memory for a recovery step");
    if (!rc && !(b = cholmod_allocate_sparse(m + n, n, a->nzmax + n, 1, 1, 0, CHOLMOD_REAL, cc)))
        rc = tk_error_set(err, TK_ENOMEM, "out of memory for a recovery step");
    if (!rc) {
        const int *ap = a->p, *ai = a->i;
        const double *ax = a->x;
        int *bp = b->p, *bi = b->i;
        double *bx = b->x;
        size_t z = 0;
        for (size_t j = 0; j < n; j++) {
            bp[j] = (int)z;
            double d = 0.0;
            for (int e = ap[j]; e < ap[j + 1]; e++, z++) {
                bi[z] = ai[e];
                bx[z] = ax[e];
                d += ax[e] * ax[e];
            }
            double root = sqrt(INEQUALITY_DAMPING * d);
            bi[z] = (int)(m + j);
            bx[z++] = root;
            /* a column that is all zero (pinned vertices) cannot move: its
             * term is left out */
            rhs[m + j] = root > 0.0 ? r->recovery.rhs[j] / root : 0.0;
        }
        bp[n] = (int)z;
        double t0 = tk_clock();
        r->work.newton += (double)(m + n);
        rc = tk_nnls_solve(r->shared.nnls, b, rhs, y, NULL, NULL, err);
        r->recovery.nnls_seconds += tk_clock() - t0;
        if (rc == TK_ENUMERIC) /* y is the best found: the line search judges it */
            rc = TK_OK;
    }
    if (!rc) {
        double *du = r->recovery.du;
        memset(du, 0, m * sizeof *du);
        const int *ap = a->p, *ai = a->i;
        const double *ax = a->x;
        for (size_t j = 0; j < n; j++)
            for (int e = ap[j]; e < ap[j + 1]; e++)
                du[ai[e]] += ax[e] * y[j];
        int halvings;
        rc = line_search(r, worst, &halvings, improved, err);
    }
    cholmod_free_sparse(&a, cc);
    cholmod_free_sparse(&b, cc);
    free(rhs);
    free(y);
    return rc;
}

/* Newton steps du solving A_V^T du = -R with minimum norm (damped) in
 * the metric (NULL: |du|), R the violations of the violated constraints V
 * among the active ones, until every violation is below the correction
 * tolerance or `most` steps have been taken (counted in *iterations).
 * Each step is damped until the worst violation falls (near-dependent
 * constraints can make the regularised solution long); they end where no
 * damping gives a step that lowers it. */
static int newton_steps(tk_run *r, int most, const cholmod_sparse *metric, double *worst,
                        int *iterations, tk_error *err)
{
    tk_curve *c = r->shared.curve;
    tk_constraints *set = &r->recovery.violated;
    double damping = RECOVERY_DAMPING;
    int rc = TK_OK;
    for (int it = 0; !rc && *worst > tk_tolerance_correction(r) && it < most; it++) {
        rc = tk_active_find(r, c, set, err);
        if (!rc)
            rc = tk_grow_doubles(&r->recovery.rhs, &r->recovery.rhs_capacity,
                                 set->struts.count + set->nkinks, err);
        if (rc || set->struts.count + set->nkinks == 0 || keep_violated(r) == 0)
            break;
        cholmod_sparse *a = NULL;
        if ((rc = tk_active_matrix(r, c, set, &a, err)) != TK_OK)
            break;
        bool improved = false;
        int halvings = 0;
        for (;;) {
            rc = damped_step(r, a, metric, damping, worst, &halvings, &improved, err);
            if (rc || improved || !(damping < RECOVERY_DAMPING_MOST))
                break;
            /* no cut of the step helps: solved again, damped more */
            damping = fmin(damping * RECOVERY_DAMPING_STEP * RECOVERY_DAMPING_STEP,
                           RECOVERY_DAMPING_MOST);
        }
        cholmod_free_sparse(&a, tk_nnls_common(r->shared.nnls));
        if (rc)
            break;
        (*iterations)++;
        if (!improved)
            break;
        /* Levenberg-Marquardt: a step taken whole lowers the damping, one
         * cut short raises it */
        if (halvings == 0)
            damping = fmax(damping / RECOVERY_DAMPING_STEP, RECOVERY_DAMPING);
        else if (halvings >= RECOVERY_HALVINGS_KEPT)
            damping = fmin(damping * RECOVERY_DAMPING_STEP, RECOVERY_DAMPING_MOST);
    }
    return rc;
}

/* Newton steps (newton_steps) until every violation is below the
 * correction tolerance.  Where they can no longer lower the worst,
 * inequality steps (inequality_step) take over (see INEQUALITY_STEPS),
 * and where those crawl, Newton steps measured by their bending too
 * (metric_build).  Rescaling about the centroid is the last resort, for
 * leftovers up to rescale_up_to only.  The stages go in that order
 * because each leaves the trajectories the earlier ones serve as they
 * were: the figure-eight refinement of tests/test_tighten, which the
 * inequality steps restore with its length up 0.018%, came out 0.1%
 * shorter where the bending metric's steps came before them (they spread
 * each repair over some l / e edges). */
static int correct(tk_run *r, int most, double rescale_up_to, int *iterations, tk_error *err);

int tk_recovery_correct(tk_run *r, int most, double rescale_up_to, int *iterations,
                        tk_error *err)
{
    double t0 = tk_clock();
    int rc = correct(r, most, rescale_up_to, iterations, err);
    r->recovery.seconds += tk_clock() - t0;
    return rc;
}

static int correct(tk_run *r, int most, double rescale_up_to, int *iterations, tk_error *err)
{
    *iterations = 0;
    tk_strut_finder_refit(r->shared.finder, r->shared.curve);
    double worst;
    int rc = tk_recovery_violation(r, r->shared.curve, &worst, err);
    if (!rc)
        rc = newton_steps(r, most, NULL, &worst, iterations, err);
    int inequality_most = most / 10 > INEQUALITY_STEPS ? most / 10 : INEQUALITY_STEPS;
    for (int it = 0; !rc && worst > tk_tolerance_correction(r) && it < inequality_most; it++) {
        bool improved = false;
        double was = worst;
        rc = inequality_step(r, &worst, &improved, err);
        (*iterations)++;
        if (!improved || worst > (1.0 - INEQUALITY_CRAWL) * was)
            break;
    }
    if (!rc && worst > tk_tolerance_correction(r) && *iterations < most) {
        r->recovery.bent++;
        cholmod_sparse *metric = NULL;
        rc = metric_build(r, tk_nnls_common(r->shared.nnls), &metric, err);
        if (!rc)
            rc = newton_steps(r, most - *iterations, metric, &worst, iterations, err);
        cholmod_free_sparse(&metric, tk_nnls_common(r->shared.nnls));
    }
    if (rc || worst <= tk_tolerance_correction(r))
        return rc;
    if (!(rescale_factor(worst) - 1.0 <= rescale_up_to))
        return tk_error_set(err, TK_ENUMERIC,
                            "could not restore the thickness: constraints violated by %.3g of "
                            "the diameter after %d corrections",
                            worst, *iterations);
    tk_recovery_rescale(r, worst);
    return TK_OK;
}
