/* Relaxing a curve under a repulsive energy (tk/relax.h). */
#include "tk/relax.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tk/geometry.h"
#include "rng.h"
#include "tk/generate.h"
#include "tk/invariants.h"
#include "tk/isotopy.h"
#include "tk/thickness.h"

/* The springs' weight against the repulsion: at 1 the repulsion pulls
 * edges out to twice the mean (catalogue 10.124 relaxed: edges 1.09 to
 * 2.04 for a mean of 1.25), at 20 to within 10% of it. */
#define RELAX_SPRING 20.0
/* Relative fall of E over RELAX_WINDOW steps below which the relaxation
 * has stopped; the step's length grows by RELAX_GROW after a step that
 * lowered E and halves after one that did not; no vertex moves by more
 * than RELAX_MOVE of the gap in one step (tk/relax.h). */
#define RELAX_WINDOW 50
#define RELAX_STOP 1e-9
#define RELAX_GROW 1.5
#define RELAX_MOVE 0.25
/* Turning inside out: the curve is first cut to about TURN_FINE vertices
 * along its edges, or 32 for each of the result's if more, and the centre must be at
 * least TURN_CLEARANCE of the curve's spread from it; the result's count
 * doubles up to TURN_DOUBLINGS - 1 times until the triangle moves down
 * to it are all clear and its type is the curve's. */
#define TURN_FINE 1000
#define TURN_CLEARANCE 1e-3
#define TURN_OFFSET 0.15
#define TURN_DOUBLINGS 3
/* A turned curve more than TURN_LOOSEST times the start's ropelength is
 * refused.  Inversion shrinks what lies far from the centre by the square
 * of its distance: a link's component far out comes back a speck on a
 * vertex or three (catalogue 0.3.1's three rings, tight at 18.91 on 95
 * vertices, turned about a point near one ring: ropelength 1.2e13, a
 * ring 1.5e-12 thick for 9.2 of length), and its try asked for 1.4e13
 * vertices.  Turns of tight curves that keep their components' sizes come
 * 1.07 to 3 times as long (10.34, 6.2.3, 9.3.12, 10.124, 0.3.1). */
#define TURN_LOOSEST 20.0
/* Wandering: the target is the curve displaced by WANDER_MODES Fourier
 * modes of amplitude its components' mean radius (L / 2 pi), the pull's
 * weight WANDER_PULL. */
#define WANDER_MODES 3
#define WANDER_PULL 1.0

/* Whether edges a and b share no vertex (the pairs E and the gap are
 * over), and then their closest points. */
static bool apart(const tk_curve *c, tk_edge a, tk_edge b, tk_closest *cl)
{
    if (a.head == b.head || a.head == b.tail || a.tail == b.head || a.tail == b.tail)
        return false;
    tk_segment_closest(tk_curve_vertex(c, a.head), tk_curve_vertex(c, a.tail),
                       tk_curve_vertex(c, b.head), tk_curve_vertex(c, b.tail), cl);
    return true;
}

/* E (and its gradient into grad, unless NULL), and the least distance
 * between edges that share no vertex into *gap, unless NULL: the pairs
 * E sums over are those the gap is over, so a step of tk_relax measures
 * both in one pass over them. */
static double energy(const tk_curve *c, const tk_curve *target, double pull, double *grad,
                     double *gap)
{
    size_t m = tk_curve_edge_count(c);
    double length = tk_curve_length(c), h = length / (double)m, h2 = h * h;
    double repulsion = 0.0, springs = 0.0, pulled = 0.0;
    if (grad)
        memset(grad, 0, 3 * c->nvert * sizeof *grad);
    for (size_t i = 0; i < m; i++) {
        tk_edge a = tk_curve_edge(c, i);
        for (size_t j = i + 1; j < m; j++) {
            tk_edge b = tk_curve_edge(c, j);
            tk_closest cl;
            if (!apart(c, a, b, &cl))
                continue;
            if (gap)
                *gap = fmin(*gap, cl.dist);
            double r2 = cl.dist * cl.dist;
            double q = h2 / r2, term = q * q;
            repulsion += term;
            if (!grad)
                continue;
            /* d(h^4 / r^4) = -4 h^4 / r^5 dr, dr by equation 7 */
            double g[12], f = -4.0 * term / cl.dist;
            tk_segment_distance_gradient(&cl, g);
            size_t at[4] = {a.head, a.tail, b.head, b.tail};
            for (int p = 0; p < 4; p++)
                for (int k = 0; k < 3; k++)
                    grad[3 * at[p] + k] += f * g[3 * p + k];
        }
    }
    /* the pull in the target's own edge length, a constant */
    double ht = target ? tk_curve_length(target) / (double)m : 1.0;
    for (size_t v = 0; target && v < c->nvert; v++) {
        double d[3];
        tk_sub3(tk_curve_vertex(c, v), tk_curve_vertex(target, v), d);
        pulled += pull * tk_dot3(d, d) / (ht * ht);
        for (int k = 0; grad && k < 3; k++)
            grad[3 * v + k] += 2.0 * pull * d[k] / (ht * ht);
    }
    /* The springs; then the terms of the gradient through h (h_c drops
     * out: a component's deviations from it sum to 0): h^4 in the
     * repulsion gives 4 E_rep dL / L, 1 / h^2 in the springs -2 E_spr
     * dL / L, dL the length's gradient (equation 14). */
    for (int pass = 0; pass < 2; pass++) {
        double scale = (4.0 * repulsion - 2.0 * springs) / length;
        for (size_t comp = 0; comp < c->ncomp; comp++) {
            size_t edges = tk_curve_comp_edges(c, comp);
            double hc = tk_curve_comp_length(c, comp) / (double)edges;
            for (size_t k = 0; k < edges; k++) {
                size_t a = tk_curve_vertex_index(c, comp, k);
                size_t b = tk_curve_vertex_index(c, comp, k + 1);
                double d[3];
                tk_sub3(tk_curve_vertex(c, b), tk_curve_vertex(c, a), d);
                double len = sqrt(tk_dot3(d, d));
                if (pass == 0) {
                    springs += RELAX_SPRING * (len - hc) * (len - hc) / h2;
                    continue;
                }
                double f = (2.0 * RELAX_SPRING * (len - hc) / h2 + scale) / len;
                for (int q = 0; q < 3; q++) {
                    grad[3 * b + q] += f * d[q];
                    grad[3 * a + q] -= f * d[q];
                }
            }
        }
        if (!grad)
            break;
    }
    return repulsion + springs + pulled;
}

double tk_relax_energy(const tk_curve *c, const tk_curve *target, double pull, double *grad)
{
    return energy(c, target, pull, grad, NULL);
}

double tk_relax_gap(const tk_curve *c)
{
    double gap = INFINITY;
    (void)energy(c, NULL, 0.0, NULL, &gap);
    return gap;
}

int tk_relax(const tk_curve *c, const tk_curve *target, double pull, int iterations,
             tk_curve **out, int *steps, tk_error *err)
{
    *out = NULL;
    if (steps)
        *steps = 0;
    int rc = tk_curve_validate(c, err);
    for (size_t comp = 0; !rc && comp < c->ncomp; comp++)
        if (!c->closed[comp])
            rc = tk_error_set(err, TK_EINVAL, "component %zu is open: only closed curves relax",
                              comp);
    if (!rc && target && (target->nvert != c->nvert || !(pull >= 0.0)))
        rc = tk_error_set(err, TK_EINVAL, "the target must have the curve's %zu vertices "
                          "and the pull be at least 0", c->nvert);
    if (rc)
        return rc;
    tk_curve *x = NULL, *trial = NULL;
    double *grad = malloc(3 * c->nvert * sizeof *grad);
    double *trial_grad = malloc(3 * c->nvert * sizeof *trial_grad);
    rc = grad && trial_grad ? tk_curve_copy(c, &x, err)
                            : tk_error_set(err, TK_ENOMEM, "out of memory");
    if (!rc)
        rc = tk_curve_copy(c, &trial, err);
    if (rc) {
        free(grad);
        free(trial_grad);
        tk_curve_free(&x);
        return rc;
    }
    double length = tk_curve_length(c), centre[3];
    tk_curve_centroid(c, centre);
    double gap = INFINITY;
    double e = energy(x, target, pull, grad, &gap), window = e;
    double alpha = INFINITY; /* the next step's largest move */
    int taken = 0;
    for (int it = 0; it < iterations; it++) {
        double largest = 0.0;
        for (size_t v = 0; v < c->nvert; v++)
            largest = fmax(largest, sqrt(tk_dot3(grad + 3 * v, grad + 3 * v)));
        double move = fmin(alpha, RELAX_MOVE * gap);
        if (!(largest > 0.0) || !(move > 1e-12 * length))
            break;
        for (size_t k = 0; k < 3 * c->nvert; k++)
            trial->xyz[k] = x->xyz[k] - move / largest * grad[k];
        /* back to the start's length about its centroid: a similarity,
         * which moves no edge through another (not under a pull, whose
         * target sets the size; E without it does not change with size) */
        if (!target) {
            double now[3];
            tk_curve_centroid(trial, now);
            double shift[3] = {-now[0], -now[1], -now[2]};
            tk_curve_translate(trial, shift);
            tk_curve_scale(trial, length / tk_curve_length(trial));
            tk_curve_translate(trial, centre);
        }
        /* the trial's gradient and gap come with its energy, in the same
         * pass over the pairs: taken, it needs no second pass (the pairs
         * are most of a step's cost; a turn of catalogue 10.136 took 0.89 s
         * against 1.29 s with the second pass) */
        double trial_gap = INFINITY;
        double trial_e = energy(trial, target, pull, trial_grad, &trial_gap);
        if (!(trial_e < e)) {
            alpha = move / 2.0;
            continue;
        }
        tk_curve *swap = x;
        x = trial;
        trial = swap;
        double *swap_grad = grad;
        grad = trial_grad;
        trial_grad = swap_grad;
        gap = trial_gap;
        e = trial_e;
        alpha = move * RELAX_GROW;
        if (++taken % RELAX_WINDOW == 0) {
            if (window - e < RELAX_STOP * window)
                break;
            window = e;
        }
    }
    free(grad);
    free(trial_grad);
    tk_curve_free(&trial);
    if (steps)
        *steps = taken;
    *out = x;
    return TK_OK;
}

/* The centroid of the curve as a wire of uniform density (each edge's
 * midpoint weighted by its length): a property of the curve, not of where
 * its vertices happen to lie. */
static void wire_centroid(const tk_curve *c, double centre[3])
{
    double total = 0.0;
    centre[0] = centre[1] = centre[2] = 0.0;
    for (size_t i = 0; i < tk_curve_edge_count(c); i++) {
        tk_edge e = tk_curve_edge(c, i);
        const double *a = tk_curve_vertex(c, e.head), *b = tk_curve_vertex(c, e.tail);
        double d[3];
        tk_sub3(b, a, d);
        double len = sqrt(tk_dot3(d, d));
        for (int k = 0; k < 3; k++)
            centre[k] += len * 0.5 * (a[k] + b[k]);
        total += len;
    }
    for (int k = 0; k < 3; k++)
        centre[k] /= total;
}

int tk_relax_turn(const tk_curve *c, const double offset[3], size_t vertices, int steps,
                  tk_curve **out, tk_error *err)
{
    *out = NULL;
    int rc = tk_curve_validate(c, err);
    if (rc)
        return rc;
    /* edges short against the centre's distance: the image of a straight
     * edge is an arc, and the polygon through the images' vertices must
     * stay of the type (checked below) */
    size_t fine = TURN_FINE > 32 * vertices ? TURN_FINE : 32 * vertices;
    tk_curve *x = NULL, *coarse = NULL;
    tk_invariants type = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
    rc = tk_isotopy_refine(c, fine, &x, err);
    double centre[3], spread = 0.0, length = tk_curve_length(c);
    if (!rc) {
        wire_centroid(x, centre);
        for (size_t v = 0; v < x->nvert; v++) {
            double d[3];
            tk_sub3(tk_curve_vertex(x, v), centre, d);
            spread += tk_dot3(d, d) / (double)x->nvert;
        }
        spread = sqrt(spread);
        for (int k = 0; k < 3; k++)
            centre[k] += offset[k] * spread;
        double clearance = INFINITY;
        for (size_t i = 0; i < tk_curve_edge_count(x); i++) {
            tk_edge e = tk_curve_edge(x, i);
            tk_closest cl;
            tk_segment_closest(tk_curve_vertex(x, e.head), tk_curve_vertex(x, e.tail), centre,
                               centre, &cl);
            clearance = fmin(clearance, cl.dist);
        }
        if (!(clearance > TURN_CLEARANCE * spread))
            rc = tk_error_set(err, TK_ENUMERIC, "the centre is %g from the curve: too near to "
                              "turn it about", clearance);
    }
    /* x -> (x - c) / |x - c|^2 and a mirror: inversion in a sphere is a
     * homeomorphism of the 3-sphere that reverses orientation, the
     * mirror puts it back, so the type (and its chirality) is kept */
    for (size_t v = 0; !rc && v < x->nvert; v++) {
        double *p = tk_curve_vertex(x, v), d[3];
        tk_sub3(p, centre, d);
        double r2 = tk_dot3(d, d);
        p[0] = -d[0] / r2;
        p[1] = d[1] / r2;
        p[2] = d[2] / r2;
    }
    if (!rc) {
        tk_curve_scale(x, length / tk_curve_length(x));
        rc = tk_invariants_compute(c, &type, err);
    }
    /* the inverted curve is uneven (what was near the centre is now far
     * out and long): on too few vertices its polygon would pass through
     * itself, and the invariants cannot see every such change (9.2.3,
     * tk/isotopy.h), so it loses its vertices by triangle moves, and
     * their count doubles until every move is clear; the invariants are
     * checked too, for the fine polygon's chords standing for arcs */
    bool kept = false;
    for (int tries = 0; !rc && !kept && tries < TURN_DOUBLINGS; tries++, vertices *= 2) {
        tk_curve_free(&coarse);
        tk_invariants_free(&now);
        rc = tk_isotopy_coarsen(x, vertices, &coarse, &kept, err);
        if (!rc && kept)
            rc = tk_invariants_compute(coarse, &now, err);
        kept = !rc && kept && tk_invariants_compare(&type, &now, NULL) == TK_OK;
    }
    if (!rc && kept)
        rc = tk_relax(coarse, NULL, 0.0, steps, out, NULL, err);
    if (!rc && !kept)
        rc = tk_error_set(err, TK_ENUMERIC, "turned inside out, the curve could not keep "
                          "its type on up to %zu vertices", vertices / 2);
    tk_measure before, after;
    if (!rc)
        rc = tk_thickness_measure(c, NULL, &before, err);
    if (!rc)
        rc = tk_thickness_measure(*out, NULL, &after, err);
    if (!rc && !(after.ropelength <= TURN_LOOSEST * before.ropelength))
        rc = tk_error_set(err, TK_ENUMERIC, "turned inside out, the curve's ropelength is "
                          "%.3g, %.3g times its own: a strand far from the centre shrank to "
                          "a speck", after.ropelength, after.ropelength / before.ropelength);
    if (rc)
        tk_curve_free(out);
    tk_invariants_free(&type);
    tk_invariants_free(&now);
    tk_curve_free(&x);
    tk_curve_free(&coarse);
    return rc;
}

void tk_relax_turn_offset(uint64_t *state, double offset[3])
{
    for (int k = 0; k < 3; k++)
        offset[k] = TURN_OFFSET * tk_rng_normal(state);
}

int tk_relax_wander(const tk_curve *c, uint64_t seed, int steps, tk_curve **out, tk_error *err)
{
    *out = NULL;
    tk_curve *target = NULL, *pulled = NULL;
    size_t ncoef = c->ncomp * WANDER_MODES * 6;
    double *coef = malloc(ncoef * sizeof *coef);
    int rc = coef ? tk_curve_copy(c, &target, err) : tk_error_set(err, TK_ENOMEM, "out of memory");
    double radius = 0.0;
    for (size_t comp = 0; !rc && comp < c->ncomp; comp++)
        radius += tk_curve_comp_length(c, comp) / (2.0 * M_PI) / (double)c->ncomp;
    for (size_t i = 0; !rc && i < ncoef; i++)
        coef[i] = tk_rng_normal(&seed);
    if (!rc)
        tk_generate_fourier(target, c, coef, WANDER_MODES, radius);
    /* toward the target as far as the strands let it, then relaxed at the
     * length reached: both steps move no edge through another */
    if (!rc)
        rc = tk_relax(c, target, WANDER_PULL, steps, &pulled, NULL, err);
    if (!rc)
        rc = tk_relax(pulled, NULL, 0.0, steps, out, NULL, err);
    free(coef);
    tk_curve_free(&target);
    tk_curve_free(&pulled);
    return rc;
}
