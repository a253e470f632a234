/* The motion: minus the length gradient (equation 14), the tangential
 * motion that evens out the edges (section 4.2), and their resolution
 * against the active constraints (equation 13, Proposition 3).  See run.h
 * for the rooms of the flow. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "tk/geometry.h"
#include "tk/rigidity.h"

void tk_motion_free(tk_run *r)
{
    free(r->motion.grad);
    free(r->motion.motion);
    free(r->motion.work);
    free(r->motion.x);
    free(r->motion.x_last);
}

int tk_motion_fit(tk_run *r, size_t vertices, tk_error *err)
{
    free(r->motion.grad);
    free(r->motion.motion);
    free(r->motion.work);
    r->motion.grad = calloc(3 * vertices, sizeof *r->motion.grad);
    r->motion.motion = calloc(3 * vertices, sizeof *r->motion.motion);
    r->motion.work = calloc(3 * vertices, sizeof *r->motion.work);
    if (!r->motion.grad || !r->motion.motion || !r->motion.work)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a run of %zu vertices", vertices);
    return TK_OK;
}

/* The forces are the proximal NNLS answer centred at the last step's
 * (tk/nnls.h): unique and continuous along the flow where the plain
 * problem's are not (many dependent struts), and found in a few pivots
 * (on the trefoil at 600 vertices, 7.6 pivots against 112 a step).  Its weight,
 * against the unit diagonal of the scaled normal matrix, leaves A x off
 * the plain answer by at most sqrt(mu) / 2 of the forces' change since
 * the last step.  The resolved motion v = u + A x then descends only
 * when the proximal term, -(A x) . v, is small against |v|^2 (see
 * tk_motion_descends): near a critical point v is small, so the solve is
 * repeated centred at its own answer (the proximal point method) until
 * the term is below MOTION_PROXIMAL_SHARE of |v|^2, at most
 * MOTION_PROXIMAL_ROUNDS times (MOTION_PROXIMAL_KEPT_ROUNDS where rounds
 * are cheap, below).  The weights follow what a round costs.
 * Where every round is a factorisation (few contacts), the weight starts
 * at MOTION_PROXIMAL and shrinks by MOTION_PROXIMAL_SHRINK every round (a
 * fixed weight needs hundreds of rounds where the forces change much: the
 * unlink's first steps leave a residual of 1.6e-4 after 20; a shrinking
 * one reaches 2e-15), down to MOTION_PROXIMAL_LEAST, where the problem is
 * the plain one in all but uniqueness.  Where the solver keeps its factor
 * (tk/nnls.h: many contacts; known from the last solve) and the curve has
 * at least MOTION_KEPT_VERTICES vertices, a round at the same weight costs
 * a few solves with it, a new weight a factorisation of some 20 ms, and
 * weights of 1e-5 and less a hundred pivots and more: there the
 * weight starts at MOTION_PROXIMAL_KEPT (or the last step's, see
 * MOTION_PROXIMAL_GROW) and within a step only shrinks, by
 * MOTION_PROXIMAL_HALVE, when a round leaves more than MOTION_PROXIMAL_SLOW
 * of the last round's term.  Replayed on the NNLS problems of the first
 * steps of three trefoils tightened again (bench/steps --curve), against
 * the other rule: at 2,435 vertices, tight, 134 factorisations and 575
 * pivots in 67 solves against 374 and 2,311; at 1,200, resampled, 667 and
 * 3,544 in 49 against 2,581 and 15,536; at 4,800, resampled, 405 and 8,259
 * in 53 against 871 and 6,430 (a few first rounds pivot more).  On a
 * small curve a factorisation costs about what a round does, and at a
 * critical point, where the answer's residual tends to 0 (the unlink's
 * two round circles, 30 vertices), the term falls only as fast as the
 * residual at one weight: with 40 rounds a step the run's residual
 * stayed at 2.1e-11 there (the catalogue's 0.2.1, autoscaled), where the
 * shrinking weight reaches 1.9e-15.  The share
 * trades rounds for descent: a generated chain of three rings at 303
 * vertices is at 43.79 after 2000 steps with 1e-4, 44.22 with 1e-2 and
 * 42.30 with 1e-6, while the catalogue trefoil's final 734-vertex polygon
 * (2160 struts, where rounds at a small weight need the slow Lawson and
 * Hanson phase) takes 255 steps in 26 s with 1e-4 against 50 with 1e-6. */
#define MOTION_PROXIMAL 1e-2
#define MOTION_PROXIMAL_SHRINK 0.1
#define MOTION_KEPT_VERTICES 1000
#define MOTION_PROXIMAL_KEPT 1e-3
#define MOTION_PROXIMAL_HALVE 0.5
#define MOTION_PROXIMAL_SLOW 0.9
#define MOTION_PROXIMAL_SHARE 1e-4
#define MOTION_PROXIMAL_ROUNDS 20
#define MOTION_PROXIMAL_KEPT_ROUNDS 40
#define MOTION_PROXIMAL_LEAST 1e-12
/* Where the factor is kept, a step's first weight is the one the last
 * step's rounds ended at, times MOTION_PROXIMAL_GROW (at most
 * MOTION_PROXIMAL_KEPT): the problem changes little from one step to the
 * next, and starting each step at MOTION_PROXIMAL_KEPT again cost it the
 * same halvings as the last, a factorisation each.  On a tight trefoil
 * of 2,400 vertices tightened again (bench/steps --curve, 150 steps):
 * 1.54 factorisations a step against 1.77, median 74.8 ms against 82.0
 * (mean 96.3 against 100.2); a whole run at 2,400 vertices for 600 s
 * made 3,213 steps on its final polygon against 2,587.  Growing back
 * lets a step that needs no halving raise the weight again, towards
 * fewer pivots a round.  With the rounds accelerated (below) a small
 * weight costs few rounds, and growing by 2 a step took the weight up to
 * where every step halved it again, a factorisation each: on the tight
 * trefoil at 9,600 vertices tightened again (bench/steps --curve, 150
 * steps, two runs at once) the median step took 218 ms with growth 2
 * against 118 ms with growth 1.2, both accelerated (bench/FIGURES.md,
 * "The proximal rounds accelerated"). */
#define MOTION_PROXIMAL_GROW 1.2

/* Where the factor is kept, the rounds at one weight are the proximal
 * point method on a passive set that changes by a column or two a round
 * or not at all, and it converges linearly, by mu / (lambda + mu) a round
 * along an eigenvalue lambda of the scaled normal matrix: on the tight
 * trefoil at 9,600 vertices (14,000 struts, nearly dependent) a step's
 * term fell by a fifth a round, and a step took 7 to 40 rounds.  So the
 * next round is centred at the answer extrapolated along the last round's
 * change, x_k + beta_k (x_k - x_{k-1}), clipped at 0: the accelerated
 * proximal point method (Guler 1992, with the step rule of Beck and
 * Teboulle's FISTA, beta_k = (t_k - 1) / t_{k+1}, t_{k+1} = (1 +
 * sqrt(1 + 4 t_k^2)) / 2), whose error falls like 1/k^2 where the plain
 * method's falls like 1/k.  The extrapolation starts again from beta = 0
 * (t = 1) when the weight changes, when a round needed the fallback, and
 * when the term grew (O'Donoghue and Candes's adaptive restart, which
 * keeps the linear rate of the strongly convex case).  Every round's
 * answer is still a proximal answer, and the rounds still end on its
 * term, so the motion descends as before.  Figures in bench/FIGURES.md,
 * "The proximal rounds accelerated". */
static void momentum(tk_run *r, size_t ncon, double beta)
{
    double *x = r->motion.x, *last = r->motion.x_last;
    for (size_t i = 0; i < ncon; i++) {
        double xi = x[i];
        x[i] = fmax(0.0, xi + beta * (xi - last[i]));
        last[i] = xi;
    }
}

/* Where the factor is kept, a round's passive solves take no step of
 * refinement from this weight on (tk/nnls.h: their relative error is then
 * at most about 2e-11, under the KKT tolerance of 1e-10), which halves the
 * solves with the factor: on the tight trefoil at 9,600 vertices (bench/
 * steps --curve, 300 steps, two runs at once) the median step took
 * 122.7 ms against 142.9, and the ropelength after 300 steps was the same
 * to 1e-9.  Below MOTION_KEPT_VERTICES every solve is refined as
 * before. */
#define MOTION_UNREFINED 1e-6

/* Where the weight shrinks, its last rounds are the dear ones: near a
 * critical point with many dependent contacts the problem at 1e-8 and
 * less is all but the plain one, and block pivoting gives way to the
 * fallback (tk/nnls.h), a thousand pivots and more a round.  There, where
 * the resolved motion is below MOTION_CRITICAL of the unresolved one
 * (|v| < MOTION_CRITICAL |u|: the curve is critical to within that), a
 * round that needed the fallback ends the rounds when its motion
 * descends at half the rate of the exact one or better (term below
 * MOTION_PROXIMAL_ENOUGH of |v|^2: the slope along v is -|v|^2 + term),
 * and so does a round whose next weight would be at or below the
 * largest that needed it lately (run.h: motion.dear, which fades by
 * MOTION_DEAR_FADE a solve, so a deeper round is tried again some 20
 * solves later).  A tight trefoil of 600 vertices tightened again
 * (bench/steps --curve t600.vect --steps 150; its active set at the
 * unpolished tolerance, 3,000 struts) took 4,485 ms a step (mean;
 * median 4,076) and 146 factorisations, and now 659 ms (431) and 73;
 * `tighten` on it for 150 s made 27 steps and ended at 32.7460107, and
 * now 175 steps and 32.745988.  Without the bound on |v| the steps took
 * 187 ms, but the early rounds also acted in the flow far from critical
 * points, where the motion's lost precision cost progress: catalogue 3.1
 * at 2,400 vertices (600 s) left its 600-vertex level after 27 s at
 * 32.7528 instead of 49 s at 32.7516, and did not reach 32.7437 in 600 s
 * (204 s).  No step of that run reported a residual below 3e-3; with the
 * bound its 4,318 steps in 600 s, and every trajectory of
 * tests/data/histories.txt, are as they were. */
#define MOTION_PROXIMAL_ENOUGH 0.5
#define MOTION_DEAR_FADE 0.9
#define MOTION_CRITICAL 1e-3

/* out = A x (3V entries). */
static void multiply(const cholmod_sparse *a, const double *x, double *out, size_t rows)
{
    memset(out, 0, rows * sizeof *out);
    const int *colp = a->p, *row = a->i;
    const double *val = a->x;
    for (size_t j = 0; j < a->ncol; j++)
        for (int k = colp[j]; k < colp[j + 1]; k++)
            out[row[k]] += val[k] * x[j];
}

/* Section 4.2: a velocity along each vertex's tangent proportional to how
 * far the vertex is from its share of the component's length, so that the
 * edges even out.  Scaled to the mean size of the length gradient so the
 * two motions keep their proportion as the curve tightens. */
static void add_equalising_motion(tk_run *r, const tk_curve *c, double *u)
{
    size_t nv = c->nvert;
    const double *grad = r->motion.grad;
    double mean_grad = 0.0;
    for (size_t v = 0; v < nv; v++)
        mean_grad += tk_norm(grad + 3 * v, 3);
    mean_grad /= (double)(nv ? nv : 1);
    if (!(r->opt.equalise > 0.0) || !(mean_grad > 0.0))
        return;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp), ne = tk_curve_comp_edges(c, comp);
        double total = tk_curve_comp_length(c, comp), mean_edge = total / (double)ne;
        double *offset = r->motion.work; /* n entries suffice: 3V >= n */
        double arc = 0.0, shift = 0.0;
        for (size_t k = 0; k < n; k++) {
            offset[k] = total * (double)k / (double)ne - arc;
            shift += offset[k];
            if (k < ne)
                arc += tk_curve_edge_length(c, comp, k);
        }
        /* A closed component's vertices may all slide together: only their
         * spacing matters. */
        shift = c->closed[comp] ? shift / (double)n : 0.0;
        for (size_t k = 0; k < n; k++) {
            size_t v = c->offset[comp] + k;
            if (r->shared.pin[v] || (!c->closed[comp] && (k == 0 || k + 1 == n)))
                continue;
            size_t before = c->closed[comp] ? (k + n - 1) % n : k - 1;
            const double *prev = tk_curve_vertex(c, c->offset[comp] + before);
            const double *next = tk_curve_vertex(c, tk_curve_vertex_index(c, comp, k + 1));
            double t[3] = {next[0] - prev[0], next[1] - prev[1], next[2] - prev[2]};
            double tn = tk_norm(t, 3);
            if (!(tn > 0.0))
                continue;
            double speed = r->opt.equalise * mean_grad * (offset[k] - shift) / mean_edge;
            for (int j = 0; j < 3; j++)
                u[3 * v + j] += speed * t[j] / tn;
        }
    }
}

/* motion = u + A x with x >= 0 minimising |A x + u|, u = -grad(length)
 * (and, with `equalise`, the edge-equalising motion); the forces go to the
 * active set. */
int tk_motion_resolve(tk_run *r, tk_step_report *rep, bool equalise, tk_error *err)
{
    const tk_curve *c = r->shared.curve;
    size_t n3 = 3 * c->nvert;
    double *grad = r->motion.grad, *motion = r->motion.motion, *work = r->motion.work;
    tk_curve_length_gradient(c, grad);
    for (size_t v = 0; v < c->nvert; v++)
        if (r->shared.pin[v])
            tk_pin_project(r->shared.pin[v], grad + 3 * v);
    for (size_t i = 0; i < n3; i++)
        motion[i] = -grad[i];
    if (equalise)
        add_equalising_motion(r, c, motion);
    const tk_constraints *set = &r->active.set;
    size_t ncon = set->struts.count + set->nkinks;
    double grad_norm = tk_norm(grad, n3);
    rep->rcond = 1.0;
    if (ncon == 0) {
        rep->residual = grad_norm > 0.0 ? 1.0 : 0.0;
        return TK_OK;
    }
    int rc = tk_grow_doubles(&r->motion.x, &r->motion.x_capacity, ncon, err);
    if (!rc)
        rc = tk_grow_doubles(&r->motion.x_last, &r->motion.x_last_capacity, ncon, err);
    if (rc)
        return rc;
    cholmod_sparse *a = NULL;
    rc = tk_active_matrix(r, c, set, &a, err);
    if (rc)
        return rc;
    double target2 = 0.0; /* |b|^2, b = -u */
    for (size_t i = 0; i < n3; i++) {
        work[i] = -motion[i];
        target2 += work[i] * work[i];
    }
    tk_nnls_report nr;
    tk_nnls_options nopt = TK_NNLS_OPTIONS_INIT;
    nopt.warm_start = true;
    tk_active_guess_forces(r, r->motion.x);
    double t0 = tk_clock(), last = INFINITY;
    bool large = c->nvert >= MOTION_KEPT_VERTICES, cheap = large && r->motion.kept;
    nopt.proximal = !cheap ? MOTION_PROXIMAL
                   : r->motion.weight > 0.0
                       ? fmin(MOTION_PROXIMAL_GROW * r->motion.weight, MOTION_PROXIMAL_KEPT)
                       : MOTION_PROXIMAL_KEPT;
    int most = cheap ? MOTION_PROXIMAL_KEPT_ROUNDS : MOTION_PROXIMAL_ROUNDS;
    nopt.unrefined = cheap ? MOTION_UNREFINED : 0.0;
    double used = nopt.proximal, dear = 0.0, t = 1.0;
    bool recorded = false; /* x_last holds the round before's answer */
    for (int round = 0; !rc && round < most; round++) {
        used = nopt.proximal;
        rc = tk_nnls_solve(r->shared.nnls, a, work, r->motion.x, &nopt, &nr, err);
        r->motion.nnls_iterations += nr.iterations;
        r->motion.factorisations += nr.factorisations;
        r->work.pivots += (double)nr.iterations * (double)(n3 + ncon);
        r->work.factors += (double)nr.factorisations * (double)(n3 + ncon);
        r->motion.kept = !rc && nr.kept;
        double term = fabs(nr.proximal_term), res2 = nr.residual * nr.residual;
        bool shrinking = !large || !nr.kept;
        if (!rc && shrinking && nr.used_fallback)
            dear = fmax(dear, used);
        if (rc || !(term > MOTION_PROXIMAL_SHARE * res2))
            break;
        if (shrinking && term < MOTION_PROXIMAL_ENOUGH * res2 &&
            res2 < MOTION_CRITICAL * MOTION_CRITICAL * target2 &&
            (nr.used_fallback || MOTION_PROXIMAL_SHRINK * used <= r->motion.dear))
            break;
        if (shrinking)
            nopt.proximal *= MOTION_PROXIMAL_SHRINK;
        else if (term > MOTION_PROXIMAL_SLOW * last)
            nopt.proximal *= MOTION_PROXIMAL_HALVE;
        nopt.proximal = fmax(nopt.proximal, MOTION_PROXIMAL_LEAST);
        /* (never after the last round: x leaves the loop as an answer) */
        recorded = recorded && !shrinking;
        if (!shrinking && round + 1 < most) {
            double beta = 0.0;
            if (nopt.proximal != used || nr.used_fallback || term > last || !recorded) {
                t = 1.0;
            } else {
                double next = 0.5 * (1.0 + sqrt(1.0 + 4.0 * t * t));
                beta = (t - 1.0) / next;
                t = next;
            }
            momentum(r, ncon, beta);
            recorded = true;
        }
        last = term;
    }
    r->motion.weight = cheap && !rc ? used : 0.0;
    r->motion.dear = fmax(dear, MOTION_DEAR_FADE * r->motion.dear);
    r->motion.nnls_seconds += tk_clock() - t0;
    r->motion.nnls_solves++;
    if (!rc) {
        rep->rcond = nr.rcond;
        multiply(a, r->motion.x, work, n3);
    }
    cholmod_free_sparse(&a, tk_nnls_common(r->shared.nnls));
    if (rc)
        return rc;
    for (size_t i = 0; i < n3; i++)
        motion[i] += work[i];
    /* The residual of the length gradient alone, with the same forces. */
    double s = 0.0;
    for (size_t i = 0; i < n3; i++) {
        double d = -grad[i] + work[i];
        s += d * d;
    }
    rep->residual = grad_norm > 0.0 ? sqrt(s) / grad_norm : 0.0;
    return tk_active_set_forces(r, r->motion.x, err);
}

/* The resolved motion of the length gradient alone always shortens the
 * curve at first order, unless it is 0: by the NNLS optimality conditions
 * (A x) . motion = 0, so grad . motion = -|motion|^2.  With the equalising
 * motion added it may not (see stepping.c), and then no short step can
 * pass the length test. */
bool tk_motion_descends(const tk_run *r)
{
    double slope = 0.0;
    for (size_t i = 0; i < 3 * r->shared.curve->nvert; i++)
        slope += r->motion.grad[i] * r->motion.motion[i];
    return slope < 0.0;
}

/* The pins' forces: at a pinned vertex the unprojected motion -grad + A x
 * (the struts' and kinks' gradients as they are, their forces x from the
 * last solve) has a part the pin's constraint takes up, (I - P) of it;
 * that part's length is the constraint's force, as a strut's force is the
 * multiplier of its constraint.  On a tight curve the motion's projected
 * part vanishes, and the pin's force balances the rest. */
int tk_run_pin_forces(const tk_run *r, double *force, tk_error *err)
{
    const tk_curve *c = r->shared.curve;
    const tk_constraints *set = &r->active.set;
    size_t n3 = 3 * c->nvert, ncon = set->struts.count + set->nkinks;
    double *w = malloc(n3 * sizeof *w), *ax = malloc(n3 * sizeof *ax);
    double *x = malloc((ncon ? ncon : 1) * sizeof *x);
    cholmod_common *cc = tk_nnls_common(r->shared.nnls);
    cholmod_sparse *a = NULL;
    int rc = w && ax && x ? TK_OK : tk_error_set(err, TK_ENOMEM, "out of memory for the forces");
    if (!rc && ncon)
        rc = tk_rigidity_build_branches(c, set->struts.items, set->struts.count, set->kinks,
                                        set->kink_edge, set->nkinks, cc, &a, err);
    if (!rc) {
        tk_curve_length_gradient(c, w);
        for (size_t i = 0; i < n3; i++)
            w[i] = -w[i];
        for (size_t j = 0; j < set->struts.count; j++)
            x[j] = set->struts.items[j].force;
        for (size_t k = 0; k < set->nkinks; k++)
            x[set->struts.count + k] = set->kinks[k].force;
        if (a) {
            multiply(a, x, ax, n3);
            for (size_t i = 0; i < n3; i++)
                w[i] += ax[i];
        }
        for (size_t i = 0; i < c->npins; i++) {
            const tk_pin *p = &c->pins[i];
            const double *wv = w + 3 * (c->offset[p->comp] + p->vertex);
            double kept[3] = {wv[0], wv[1], wv[2]};
            tk_pin_project(p, kept);
            double d[3] = {wv[0] - kept[0], wv[1] - kept[1], wv[2] - kept[2]};
            force[i] = tk_norm(d, 3);
        }
    }
    cholmod_free_sparse(&a, cc);
    free(w);
    free(ax);
    free(x);
    return rc;
}
