#include "tk/geometry.h"

#include <float.h>
#include <math.h>
#include <string.h>

static inline double clamp01(double x)
{
    return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

static inline void point_at(const double *a0, const double *d, double s, double *out)
{
    out[0] = a0[0] + s * d[0];
    out[1] = a0[1] + s * d[1];
    out[2] = a0[2] + s * d[2];
}

static inline double dist3(const double *a, const double *b)
{
    double d[3];
    tk_sub3(a, b, d);
    return sqrt(tk_dot3(d, d));
}

/* Parameter of the point of segment (a0, d) closest to x. */
static double project(const double *x, const double *a0, const double *d, double dd)
{
    if (dd <= 0.0)
        return 0.0;
    double r[3];
    tk_sub3(x, a0, r);
    return clamp01(tk_dot3(r, d) / dd);
}

/* Snaps s (on an edge of squared length dd, at distance dist from the
 * other edge) onto an end point within TK_SNAP_PARAMETER of it, scaled
 * down where the edge is longer than the distance (geometry.h). */
static bool snap(double *s, double dd, double dist)
{
    double limit = dd > dist * dist ? TK_SNAP_PARAMETER * dist / sqrt(dd) : TK_SNAP_PARAMETER;
    if (*s < limit) {
        *s = 0.0;
        return true;
    }
    if (*s > 1.0 - limit) {
        *s = 1.0;
        return true;
    }
    return false;
}

/* The squared distance on the square [0,1]^2 is convex, so its minimum is
 * either the interior critical point (when the segments are not parallel
 * and it lies inside) or on the square's boundary, which consists of the
 * four point-to-segment problems.  Taking the best of these candidates is
 * robust for parallel and nearly parallel segments, where solving the 2x2
 * system alone loses accuracy. */
void tk_segment_closest(const double a0[3], const double a1[3],
                        const double b0[3], const double b1[3],
                        tk_closest *out)
{
    double d1[3], d2[3], r[3];
    tk_sub3(a1, a0, d1);
    tk_sub3(b1, b0, d2);
    tk_sub3(a0, b0, r);
    double a = tk_dot3(d1, d1), e = tk_dot3(d2, d2), b = tk_dot3(d1, d2);
    double c = tk_dot3(d1, r), f = tk_dot3(d2, r);

    double best_s = 0.0, best_t = project(a0, b0, d2, e);
    double p[3], q[3];
    point_at(b0, d2, best_t, q);
    double best = dist3(a0, q);

    double cand_s[3] = {1.0, 0.0, 0.0}, cand_t[3] = {0.0, 0.0, 1.0};
    cand_t[0] = project(a1, b0, d2, e);
    cand_s[1] = project(b0, a0, d1, a);
    cand_s[2] = project(b1, a0, d1, a);
    for (int k = 0; k < 3; k++) {
        point_at(a0, d1, cand_s[k], p);
        point_at(b0, d2, cand_t[k], q);
        double dk = dist3(p, q);
        if (dk < best) {
            best = dk;
            best_s = cand_s[k];
            best_t = cand_t[k];
        }
    }

    double denom = a * e - b * b;
    if (a > 0.0 && e > 0.0 && denom <= 1e-14 * a * e) {
        /* Parallel: a whole family of minimising pairs when the segments
         * overlap.  Take the middle of the overlap, which is a local
         * minimum of the self-distance wherever any of the family is
         * (an end of the family can sit on a vertex that is not). */
        /* b0 and b1 project onto the first line at -c/a and (b-c)/a */
        double lo = fmax(0.0, fmin(-c / a, (b - c) / a));
        double hi = fmin(1.0, fmax(-c / a, (b - c) / a));
        if (lo <= hi) {
            double s = 0.5 * (lo + hi);
            point_at(a0, d1, s, p);
            double t = project(p, b0, d2, e);
            point_at(b0, d2, t, q);
            double dk = dist3(p, q);
            if (dk <= best * (1.0 + 1e-12)) {
                best = dk;
                best_s = s;
                best_t = t;
            }
        }
    } else if (a > 0.0 && e > 0.0) {
        double s = (b * f - c * e) / denom;
        double t = (a * f - b * c) / denom;
        if (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) {
            point_at(a0, d1, s, p);
            point_at(b0, d2, t, q);
            double dk = dist3(p, q);
            if (dk <= best) {
                best = dk;
                best_s = s;
                best_t = t;
            }
        }
    }

    /* Refinement: solved in the coordinates, the parameters of two long,
     * nearly parallel segments far from the origin are off by rounding
     * times |coordinates| / |edge| / sin^2 of their angle, which moves the
     * closest points by a good part of the distance (edges 8e6 long at
     * 7e6 from the origin: 0.9977 for 0.9913).  The same system solved
     * for a correction, from the difference of the points found (small
     * where the distance is), has no such loss.  Tried only where that
     * error could reach 1e-10 of the distance, and taken only when it
     * lowers the distance beyond rounding, so that a well-conditioned pair
     * (every contact of a knot at its resolution) keeps its answer bit for
     * bit, at no cost. */
    double denom2 = a * e - b * b;
    bool suspect = a > 0.0 && e > 0.0 && denom2 > 0.0 &&
                   DBL_EPSILON * (sqrt(a) + sqrt(e)) * a * e > 1e-10 * best * denom2;
    for (int pass = 0; pass < 2 && suspect; pass++) {
        double w[3];
        point_at(a0, d1, best_s, p);
        point_at(b0, d2, best_t, q);
        tk_sub3(p, q, w);
        double g1 = tk_dot3(d1, w), g2 = tk_dot3(d2, w);
        double s = clamp01(best_s + (b * g2 - e * g1) / denom2);
        double t = clamp01(best_t + (a * g2 - b * g1) / denom2);
        point_at(a0, d1, s, p);
        t = project(p, b0, d2, e);
        point_at(b0, d2, t, q);
        s = project(q, a0, d1, a);
        point_at(a0, d1, s, p);
        double dk = dist3(p, q);
        if (!(dk < best * (1.0 - 1e-12)))
            break;
        best = dk;
        best_s = s;
        best_t = t;
    }

    /* Snap parameters next to an end point onto it, then let the other
     * parameter follow, so that a contact at a shared vertex is seen the
     * same (bit for bit) from both edges at that vertex. */
    bool snapped_s = snap(&best_s, a, best), snapped_t = snap(&best_t, e, best);
    if (snapped_s && !snapped_t) {
        point_at(a0, d1, best_s, p);
        best_t = project(p, b0, d2, e);
        snap(&best_t, e, best);
    } else if (snapped_t && !snapped_s) {
        point_at(b0, d2, best_t, q);
        best_s = project(q, a0, d1, a);
        snap(&best_s, a, best);
    }
    /* End points are taken exactly, not recomputed as a0 + 1 * d. */
    if (best_s == 0.0)
        memcpy(out->p, a0, sizeof out->p);
    else if (best_s == 1.0)
        memcpy(out->p, a1, sizeof out->p);
    else
        point_at(a0, d1, best_s, out->p);
    if (best_t == 0.0)
        memcpy(out->q, b0, sizeof out->q);
    else if (best_t == 1.0)
        memcpy(out->q, b1, sizeof out->q);
    else
        point_at(b0, d2, best_t, out->q);
    out->s = best_s;
    out->t = best_t;
    out->dist = dist3(out->p, out->q);
}

/* Whether x, a point of the plane of abc (n its normal, of either length),
 * lies in the closed triangle: on the inner side of each of its edges. */
static bool in_triangle(const double *const v[3], const double n[3], const double x[3])
{
    for (int k = 0; k < 3; k++) {
        double e[3], d[3], w[3];
        tk_sub3(v[(k + 1) % 3], v[k], e);
        tk_sub3(x, v[k], d);
        tk_cross3(e, d, w);
        if (tk_dot3(w, n) < 0.0)
            return false;
    }
    return true;
}

/* The closed triangle is its three edges and the points of its plane
 * inside them: pq meets it within tol when it comes that near an edge,
 * when an end of it lies within tol of the plane over the triangle (a
 * segment in the plane across the triangle crosses an edge or has an end
 * inside), or when it crosses the plane inside. */
bool tk_segment_meets_triangle(const double a[3], const double b[3], const double c[3],
                               const double p[3], const double q[3], double tol)
{
    const double *const v[3] = {a, b, c};
    for (int k = 0; k < 3; k++) {
        tk_closest cl;
        tk_segment_closest(v[k], v[(k + 1) % 3], p, q, &cl);
        if (cl.dist <= tol)
            return true;
    }
    double e1[3], e2[3], n[3];
    tk_sub3(b, a, e1);
    tk_sub3(c, a, e2);
    tk_cross3(e1, e2, n);
    double norm = sqrt(tk_dot3(n, n));
    if (!(norm > 0.0))
        return false; /* a, b, c on a line: the edges above are all of it */
    for (int k = 0; k < 3; k++)
        n[k] /= norm;
    const double *const ends[2] = {p, q};
    double h[2];
    for (int k = 0; k < 2; k++) {
        double d[3];
        tk_sub3(ends[k], a, d);
        h[k] = tk_dot3(d, n);
        double x[3] = {ends[k][0] - h[k] * n[0], ends[k][1] - h[k] * n[1],
                       ends[k][2] - h[k] * n[2]};
        if (fabs(h[k]) <= tol && in_triangle(v, n, x))
            return true;
    }
    if (!(h[0] * h[1] < 0.0))
        return false;
    double s = h[0] / (h[0] - h[1]);
    double x[3] = {p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1]), p[2] + s * (q[2] - p[2])};
    return in_triangle(v, n, x);
}


/* Equation (7): by Clarke's theorem for min-functions, the derivative of
 * the distance is that of |p(s0) - q(t0)| at the fixed minimising
 * parameters. */
void tk_segment_distance_gradient(const tk_closest *c, double grad[12])
{
    double u[3];
    tk_sub3(c->p, c->q, u);
    double n = sqrt(tk_dot3(u, u));
    if (!(n > 0.0)) {
        memset(grad, 0, 12 * sizeof *grad);
        return;
    }
    for (int k = 0; k < 3; k++) {
        u[k] /= n;
        grad[k] = (1.0 - c->s) * u[k];
        grad[3 + k] = c->s * u[k];
        grad[6 + k] = -(1.0 - c->t) * u[k];
        grad[9 + k] = -c->t * u[k];
    }
}

double tk_vertex_turning(const double prev[3], const double v[3],
                         const double next[3])
{
    double a[3], b[3], x[3];
    tk_sub3(v, prev, a);
    tk_sub3(next, v, b);
    tk_cross3(a, b, x);
    return atan2(sqrt(tk_dot3(x, x)), tk_dot3(a, b));
}

/* Equation (3) written without angles: with a, b the incoming and outgoing
 * edge vectors, tan(theta/2) = |a x b| / (|a||b| + a.b), so
 *     minrad = min(|a|, |b|) * (|a||b| + a.b) / (2 |a x b|),
 * which stays accurate for small and for nearly reversing turns. */
double tk_vertex_minrad(const double prev[3], const double v[3],
                        const double next[3])
{
    double a[3], b[3], x[3];
    tk_sub3(v, prev, a);
    tk_sub3(next, v, b);
    tk_cross3(a, b, x);
    double la = sqrt(tk_dot3(a, a)), lb = sqrt(tk_dot3(b, b)), ab = tk_dot3(a, b);
    double sin_term = sqrt(tk_dot3(x, x));
    if (!(sin_term > 0.0))
        return ab >= 0.0 ? INFINITY : 0.0;
    /* For turns past a right angle |a||b| + a.b cancels; the identity
     * (|a||b| + a.b)(|a||b| - a.b) = |a x b|^2 avoids it. */
    double h = ab >= 0.0 ? (la * lb + ab) / sin_term : sin_term / (la * lb - ab);
    return 0.5 * fmin(la, lb) * h;
}

/* The gradient of one of the two functions whose minimum is equation (3)
 * (the paper writes the outgoing edge's as (6)): differentiate
 * h = (|a||b| + a.b) / |a x b| = cot(theta/2) with respect to the edge
 * vectors a and b by the quotient rule, then radius = L h / 2 with L the
 * chosen edge's length, and map edge vectors back to vertices
 * (a = v - prev, b = next - v). */
double tk_vertex_radius_gradient(const double prev[3], const double v[3],
                                 const double next[3], int edge, double grad[9])
{
    double a[3], b[3], x[3];
    tk_sub3(v, prev, a);
    tk_sub3(next, v, b);
    tk_cross3(a, b, x);
    double la = sqrt(tk_dot3(a, a)), lb = sqrt(tk_dot3(b, b));
    double ab = tk_dot3(a, b);
    double den = sqrt(tk_dot3(x, x));
    memset(grad, 0, 9 * sizeof *grad);
    if (!(den > 0.0))
        return ab >= 0.0 ? INFINITY : 0.0;
    /* h = cot(theta/2) as num/den: num = |a||b| + a.b, den = |a x b| for
     * turns up to a right angle; num = |a x b|, den = |a||b| - a.b past it
     * (the same value without cancellation). */
    bool sharp = ab < 0.0;
    double cross_len = den;
    double num = sharp ? cross_len : la * lb + ab;
    if (sharp)
        den = la * lb - ab;
    double h = num / den;
    bool along_a = edge == 0;
    double len = along_a ? la : lb;

    double ga[3], gb[3];
    for (int k = 0; k < 3; k++) {
        /* derivatives of |a||b| + a.b, of |a||b| - a.b and of |a x b| */
        double dsum_a = a[k] / la * lb + b[k], dsum_b = b[k] / lb * la + a[k];
        double ddiff_a = a[k] / la * lb - b[k], ddiff_b = b[k] / lb * la - a[k];
        double dcross_a = (a[k] * lb * lb - ab * b[k]) / cross_len;
        double dcross_b = (b[k] * la * la - ab * a[k]) / cross_len;
        double dnum_a = sharp ? dcross_a : dsum_a, dnum_b = sharp ? dcross_b : dsum_b;
        double dden_a = sharp ? ddiff_a : dcross_a, dden_b = sharp ? ddiff_b : dcross_b;
        double dh_a = (dnum_a * den - num * dden_a) / (den * den);
        double dh_b = (dnum_b * den - num * dden_b) / (den * den);
        ga[k] = 0.5 * len * dh_a + (along_a ? 0.5 * h * a[k] / la : 0.0);
        gb[k] = 0.5 * len * dh_b + (along_a ? 0.0 : 0.5 * h * b[k] / lb);
    }
    for (int k = 0; k < 3; k++) {
        grad[k] = -ga[k];
        grad[3 + k] = ga[k] - gb[k];
        grad[6 + k] = gb[k];
    }
    return 0.5 * len * h;
}

/* Equation (3) takes the shorter edge's function; its gradient is that
 * function's (where the edges are equally long there is none: the flow
 * then uses both functions as constraints). */
double tk_vertex_minrad_gradient(const double prev[3], const double v[3],
                                 const double next[3], double grad[9])
{
    double la2 = 0.0, lb2 = 0.0;
    for (int k = 0; k < 3; k++) {
        la2 += (v[k] - prev[k]) * (v[k] - prev[k]);
        lb2 += (next[k] - v[k]) * (next[k] - v[k]);
    }
    return tk_vertex_radius_gradient(prev, v, next, sqrt(la2) <= sqrt(lb2) ? 0 : 1, grad);
}

int tk_curve_vertex_neighbours(const tk_curve *c, size_t v, size_t *prev,
                               size_t *next)
{
    size_t lo = 0, hi = c->ncomp;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (c->offset[mid] <= v)
            lo = mid;
        else
            hi = mid;
    }
    size_t n = tk_curve_comp_vertices(c, lo);
    size_t k = v - c->offset[lo];
    if (!c->closed[lo] && (k == 0 || k + 1 >= n))
        return 0;
    if (prev)
        *prev = c->offset[lo] + (k + n - 1) % n;
    if (next)
        *next = c->offset[lo] + (k + 1) % n;
    return 1;
}

double tk_curve_minrad(const tk_curve *c, size_t *where)
{
    double best = INFINITY;
    size_t best_v = (size_t)-1;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp), base = c->offset[comp];
        size_t first = c->closed[comp] ? 0 : 1;
        size_t last = c->closed[comp] ? n : (n >= 1 ? n - 1 : 0);
        for (size_t k = first; k < last; k++) {
            size_t pv = base + (k + n - 1) % n, nv = base + (k + 1) % n;
            double r = tk_vertex_minrad(c->xyz + 3 * pv, c->xyz + 3 * (base + k),
                                        c->xyz + 3 * nv);
            if (r < best) {
                best = r;
                best_v = base + k;
            }
        }
    }
    if (where)
        *where = best_v;
    return best;
}

/* Equation (14): each edge pulls its two end points towards each other
 * with unit force. */
void tk_curve_length_gradient(const tk_curve *c, double *grad)
{
    memset(grad, 0, 3 * c->nvert * sizeof *grad);
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t ne = tk_curve_comp_edges(c, comp);
        for (size_t k = 0; k < ne; k++) {
            size_t h = tk_curve_vertex_index(c, comp, k);
            size_t t = tk_curve_vertex_index(c, comp, k + 1);
            double u[3];
            tk_sub3(c->xyz + 3 * t, c->xyz + 3 * h, u);
            double n = sqrt(tk_dot3(u, u));
            if (!(n > 0.0))
                continue;
            for (int j = 0; j < 3; j++) {
                grad[3 * h + j] -= u[j] / n;
                grad[3 * t + j] += u[j] / n;
            }
        }
    }
}
