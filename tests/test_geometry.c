/* Geometry: edge distances against dense sampling, gradients (equations 6,
 * 7 and 14) against central finite differences, exact minrad values. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/geometry.h"

/* Largest component difference over largest component magnitude. */
static double vec_reldiff(const double *a, const double *b, size_t n)
{
    double diff = 0.0, mag = 0.0;
    for (size_t i = 0; i < n; i++) {
        diff = fmax(diff, fabs(a[i] - b[i]));
        mag = fmax(mag, fmax(fabs(a[i]), fabs(b[i])));
    }
    return mag > 0.0 ? diff / mag : diff;
}

static double seg_dist(const double *x)
{
    tk_closest c;
    tk_segment_closest(x, x + 3, x + 6, x + 9, &c);
    return c.dist;
}

/* An independent estimate of the segment distance: the distance from p(s)
 * to the second segment is convex in s, so a scan followed by ternary
 * search finds its minimum. */
static double sampled_dist(const double *x)
{
    double best = INFINITY, bs = 0;
    const int n = 400;
    double p[3];
    for (int i = 0; i <= n; i++) {
        double s = (double)i / n;
        for (int k = 0; k < 3; k++)
            p[k] = x[k] + s * (x[3 + k] - x[k]);
        double d = tkt_point_segment(p, x + 6, x + 9);
        if (d < best) {
            best = d;
            bs = s;
        }
    }
    double lo = fmax(0, bs - 1.0 / n), hi = fmin(1, bs + 1.0 / n);
    for (int it = 0; it < 200; it++) {
        double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3, p2[3];
        for (int k = 0; k < 3; k++) {
            p[k] = x[k] + m1 * (x[3 + k] - x[k]);
            p2[k] = x[k] + m2 * (x[3 + k] - x[k]);
        }
        if (tkt_point_segment(p, x + 6, x + 9) < tkt_point_segment(p2, x + 6, x + 9))
            hi = m2;
        else
            lo = m1;
    }
    for (int k = 0; k < 3; k++)
        p[k] = x[k] + lo * (x[3 + k] - x[k]);
    return fmin(best, tkt_point_segment(p, x + 6, x + 9));
}

/* Random segment pairs of several kinds, including nearly degenerate ones. */
static void random_segments(tkt_rng *r, int kind, double x[12])
{
    for (int k = 0; k < 12; k++)
        x[k] = tkt_rng_range(r, -1, 1);
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = x[3 + k] - x[k];
    double tilt = 0.0;
    switch (kind) {
    case 0: /* general position */
        return;
    case 1: tilt = 1e-3; break;   /* nearly parallel */
    case 2: tilt = 1e-5; break;   /* more nearly parallel */
    case 3: tilt = 0.0; break;    /* exactly parallel */
    case 4: /* closest point near an end of the second segment */
        for (int k = 0; k < 3; k++)
            x[9 + k] = x[6 + k] + 1e-4 * (x[9 + k] - x[6 + k]);
        return;
    default:
        return;
    }
    /* second segment = first shifted, direction tilted slightly */
    double shift[3], wob[3];
    tkt_rng_point(r, 0.5, shift);
    tkt_rng_point(r, 1.0, wob);
    double len = tkt_rng_range(r, 0.3, 1.5), off = tkt_rng_range(r, -0.8, 0.8);
    for (int k = 0; k < 3; k++) {
        x[6 + k] = x[k] + shift[k] + off * d[k];
        x[9 + k] = x[6 + k] + len * d[k] + tilt * wob[k];
    }
}

START_TEST(segment_distance_matches_sampling)
{
    tkt_rng r = {42};
    for (int trial = 0; trial < 400; trial++) {
        double x[12];
        random_segments(&r, trial % 5, x);
        double d = seg_dist(x), ref = sampled_dist(x);
        /* the sampled minimum is an upper bound within grid resolution */
        ck_assert_msg(d <= ref + 1e-12, "trial %d: %.17g > sampled %.17g", trial, d, ref);
        ck_assert_msg(ref - d < 1e-12, "trial %d: %.17g vs sampled %.17g", trial, d, ref);
        /* the reported points are on the segments and at the distance */
        tk_closest c;
        tk_segment_closest(x, x + 3, x + 6, x + 9, &c);
        ck_assert(c.s >= 0 && c.s <= 1 && c.t >= 0 && c.t <= 1);
        double pq = 0;
        for (int k = 0; k < 3; k++) {
            double p = x[k] + c.s * (x[3 + k] - x[k]);
            double q = x[6 + k] + c.t * (x[9 + k] - x[6 + k]);
            ck_assert(fabs(p - c.p[k]) < 1e-14 && fabs(q - c.q[k]) < 1e-14);
            pq += (c.p[k] - c.q[k]) * (c.p[k] - c.q[k]);
        }
        ck_assert(fabs(sqrt(pq) - c.dist) < 1e-15);
    }
}
END_TEST

START_TEST(segment_distance_exact_cases)
{
    /* crossing perpendicular segments 2 apart */
    double a0[3] = {-1, 0, 0}, a1[3] = {1, 0, 0}, b0[3] = {0, -1, 2}, b1[3] = {0, 1, 2};
    tk_closest c;
    tk_segment_closest(a0, a1, b0, b1, &c);
    ck_assert_double_eq_tol(c.dist, 2.0, 1e-15);
    ck_assert_double_eq_tol(c.s, 0.5, 1e-15);
    ck_assert_double_eq_tol(c.t, 0.5, 1e-15);
    /* parallel overlapping segments: distance is the offset */
    double p0[3] = {0, 0, 0}, p1[3] = {2, 0, 0}, q0[3] = {1, 0.5, 0}, q1[3] = {3, 0.5, 0};
    tk_segment_closest(p0, p1, q0, q1, &c);
    ck_assert_double_eq_tol(c.dist, 0.5, 1e-15);
    /* collinear disjoint: gap between the ends */
    double r0[3] = {4, 0, 0}, r1[3] = {5, 0, 0};
    tk_segment_closest(p0, p1, r0, r1, &c);
    ck_assert_double_eq_tol(c.dist, 2.0, 1e-15);
    ck_assert(c.s == 1.0 && c.t == 0.0);
    /* a degenerate segment is a point */
    tk_segment_closest(b0, b0, a0, a1, &c);
    ck_assert_double_eq_tol(c.dist, sqrt(5.0), 1e-15);
}
END_TEST

/* A closest point 5e-8 of its parameter from the end of an edge 6e7 long
 * is 3 units from that end: snapping it there (the snap once took any
 * parameter within 1e-7) measured a pair 0.002 apart as 3 apart, and the
 * flow passed a strand through another (a fuzzed curve, in
 * tests/fuzz/corpus/flow).  Exact: the short edge is the segment of the z
 * axis in [-1, 1], the long one the line y = 0.002, z = 0 from x = -3. */
START_TEST(long_edge_keeps_its_closest_point)
{
    double a0[3] = {0, 0, -1}, a1[3] = {0, 0, 1};
    double b0[3] = {-3, 0.002, 0}, b1[3] = {6e7 - 3, 0.002, 0};
    tk_closest c;
    tk_segment_closest(a0, a1, b0, b1, &c);
    ck_assert_double_eq_tol(c.dist, 0.002, 1e-12);
    ck_assert_double_eq_tol(c.t, 3.0 / 6e7, 1e-15);
    ck_assert_double_eq_tol(c.s, 0.5, 1e-12);
    tk_segment_closest(b0, b1, a0, a1, &c);
    ck_assert_double_eq_tol(c.dist, 0.002, 1e-12);
    /* an edge shorter than the distance still snaps within 1e-7 */
    double e0[3] = {-1e-8, 1, 0}, e1[3] = {1 - 1e-8, 1, 0};
    tk_segment_closest(a0, a1, e0, e1, &c);
    ck_assert(c.t == 0.0 && c.q[0] == e0[0]);
}
END_TEST

/* Two edges about 8e6 long, 7e6 from the origin, nearly antiparallel
 * (a fuzzed 4-gon autoscaled to thickness 1): solved in the coordinates
 * their closest points were off by 0.006 of a distance of 0.99, and the
 * flow took a step to thickness 0.9977 believing it 1.0037 (in
 * tests/fuzz/corpus/flow).  The exact distance, from rational arithmetic
 * on these doubles, is 0.99127762490016... */
START_TEST(long_nearly_parallel_edges_far_out)
{
    double v0[3] = {7469035.3920376794, -1.0499231529779648e-09, 4386.1325066092895};
    double v1[3] = {7859949.4515956417, -5.2182183685806819e-09, 5482.6656329957195};
    double v2[3] = {8772.2650178385611, -548.2665635470978, -548.26656328644629};
    double v3[3] = {-1644.799600351035, -548.26656307676842, -548.26656327631451};
    tk_closest c;
    tk_segment_closest(v1, v2, v3, v0, &c);
    ck_assert_double_eq_tol(c.dist, 0.9912776249001626, 1e-9);
    ck_assert_double_eq_tol(c.s, 0.991898195306496, 1e-9);
    ck_assert_double_eq_tol(c.t, 0.009908839195989845, 1e-9);
    tk_segment_closest(v3, v0, v1, v2, &c);
    ck_assert_double_eq_tol(c.dist, 0.9912776249001626, 1e-9);
}
END_TEST

/* Segment against triangle, against a brute force: the least distance
 * between N points along the segment and the triangle's points of a
 * barycentric grid of step 1/N, which is within the grid's spacing
 * (h = (|pq| + the triangle's longest side) / N) of the true distance.
 * A segment said to meet the triangle must come within h of it on the
 * grid; one said to miss it must not come within h of it (the true
 * distance is then above 0).  Cases: random segments and triangles, and
 * segments through a random point of the triangle's plane (inside or out)
 * and segments in the plane, where the hard cases lie. */
static double brute_triangle(const double *a, const double *b, const double *c,
                             const double *p, const double *q, int n)
{
    double best = INFINITY;
    for (int i = 0; i <= n; i++) {
        double x[3];
        for (int k = 0; k < 3; k++)
            x[k] = p[k] + (q[k] - p[k]) * i / n;
        for (int u = 0; u <= n; u++)
            for (int v = 0; u + v <= n; v++) {
                double d = 0.0;
                for (int k = 0; k < 3; k++) {
                    double y = a[k] + (b[k] - a[k]) * u / n + (c[k] - a[k]) * v / n;
                    d += (x[k] - y) * (x[k] - y);
                }
                best = fmin(best, d);
            }
    }
    return sqrt(best);
}

START_TEST(segment_meets_triangle_against_sampling)
{
    tkt_rng rng = {12345};
    const int n = 60;
    int met = 0, missed = 0, unclear = 0;
    for (int t = 0; t < 600; t++) {
        double a[3], b[3], c[3], p[3], q[3];
        tkt_rng_point(&rng, 1.0, a);
        tkt_rng_point(&rng, 1.0, b);
        tkt_rng_point(&rng, 1.0, c);
        int kind = t % 3;
        if (kind == 0) {
            tkt_rng_point(&rng, 1.0, p);
            tkt_rng_point(&rng, 1.0, q);
        } else {
            /* through x = a + s (b - a) + u (c - a), s and u in -0.5 .. 1.5 */
            double s = tkt_rng_range(&rng, -0.5, 1.5), u = tkt_rng_range(&rng, -0.5, 1.5);
            double x[3], dir[3];
            for (int k = 0; k < 3; k++)
                x[k] = a[k] + s * (b[k] - a[k]) + u * (c[k] - a[k]);
            tkt_rng_point(&rng, 1.0, dir);
            if (kind == 2) { /* in the plane: dir along the triangle's sides */
                double s2 = tkt_rng_range(&rng, -1.0, 1.0), u2 = tkt_rng_range(&rng, -1.0, 1.0);
                for (int k = 0; k < 3; k++)
                    dir[k] = s2 * (b[k] - a[k]) + u2 * (c[k] - a[k]);
            }
            double back = tkt_rng_range(&rng, 0.0, 1.0);
            for (int k = 0; k < 3; k++) {
                p[k] = x[k] - back * dir[k];
                q[k] = x[k] + (1.0 - back) * dir[k];
            }
        }
        double side = fmax(fmax(sqrt(pow(b[0] - a[0], 2) + pow(b[1] - a[1], 2) + pow(b[2] - a[2], 2)),
                                sqrt(pow(c[0] - b[0], 2) + pow(c[1] - b[1], 2) + pow(c[2] - b[2], 2))),
                           sqrt(pow(a[0] - c[0], 2) + pow(a[1] - c[1], 2) + pow(a[2] - c[2], 2)));
        double len = sqrt(pow(q[0] - p[0], 2) + pow(q[1] - p[1], 2) + pow(q[2] - p[2], 2));
        double h = (len + side) / n, brute = brute_triangle(a, b, c, p, q, n);
        bool meets = tk_segment_meets_triangle(a, b, c, p, q, 0.0);
        if (meets)
            ck_assert_msg(brute <= h, "case %d: said to meet, but %g apart on the grid (h %g)",
                          t, brute, h);
        else
            ck_assert_msg(brute > 0.0, "case %d: said to miss, but met on the grid", t);
        if (brute > h)
            ck_assert_msg(!meets, "case %d: %g apart, said to meet", t, brute);
        met += meets;
        missed += !meets && brute > h;
        unclear += !meets && brute <= h;
    }
    printf("segment and triangle: %d met, %d missed, %d missed within the grid's spacing\n",
           met, missed, unclear);
    ck_assert_int_gt(met, 50);
    ck_assert_int_gt(missed, 200);
    /* a tolerance widens it: a segment parallel to the plane at height d */
    double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
    double p[3] = {0.2, 0.2, 1e-3}, q[3] = {0.3, 0.1, 1e-3};
    ck_assert(!tk_segment_meets_triangle(a, b, c, p, q, 0.5e-3));
    ck_assert(tk_segment_meets_triangle(a, b, c, p, q, 2e-3));
    /* a line of a triangle is its sides */
    double d[3] = {2, 0, 0}, r[3] = {1.5, -1, 0}, s[3] = {1.5, 1, 0.5};
    ck_assert(tk_segment_meets_triangle(a, b, d, r, s, 0.0) == false);
    double s2[3] = {1.5, 1, 0};
    ck_assert(tk_segment_meets_triangle(a, b, d, r, s2, 0.0));
}
END_TEST

START_TEST(distance_gradient_matches_finite_differences)
{
    tkt_rng r = {7};
    int checked = 0;
    for (int trial = 0; trial < 2000; trial++) {
        double x[12];
        random_segments(&r, trial % 5, x);
        tk_closest c;
        tk_segment_closest(x, x + 3, x + 6, x + 9, &c);
        /* Equation (7) holds where the minimum is unique; exactly parallel
         * pairs have a family of minima (and no derivative), and the
         * distance is not differentiable where the closest point sits on an
         * end point with a nearly flat side. */
        if (trial % 5 == 3 || c.dist < 1e-3)
            continue;
        double g[12], fd[12];
        tk_segment_distance_gradient(&c, g);
        const double h = 1e-6;
        for (int k = 0; k < 12; k++) {
            double y[12];
            memcpy(y, x, sizeof y);
            y[k] = x[k] + h;
            double up = seg_dist(y);
            y[k] = x[k] - h;
            double down = seg_dist(y);
            fd[k] = (up - down) / (2 * h);
        }
        /* Skip configurations where a kink of the min-function lies within
         * the difference stencil: one-sided differences disagree there. */
        bool kink = false;
        for (int k = 0; k < 12 && !kink; k++) {
            double y[12];
            memcpy(y, x, sizeof y);
            y[k] = x[k] + h;
            double up = seg_dist(y);
            double fwd = (up - c.dist) / h;
            y[k] = x[k] - h;
            double back = (c.dist - seg_dist(y)) / h;
            kink = fabs(fwd - back) > 1e-4 * (1 + fabs(fwd));
        }
        if (kink)
            continue;
        checked++;
        ck_assert_msg(vec_reldiff(g, fd, 12) < 1e-6, "trial %d (kind %d): rel diff %g", trial,
                      trial % 5, vec_reldiff(g, fd, 12));
    }
    ck_assert_int_gt(checked, 1000);
}
END_TEST

static double minrad_at(const double *x)
{
    return tk_vertex_minrad(x, x + 3, x + 6);
}

START_TEST(minrad_gradient_matches_finite_differences)
{
    tkt_rng r = {99};
    int checked = 0;
    for (int trial = 0; trial < 3000; trial++) {
        double x[9];
        for (int k = 0; k < 9; k++)
            x[k] = tkt_rng_range(&r, -1, 1);
        int kind = trial % 4;
        if (kind == 1 || kind == 2) {
            /* nearly straight (1) or nearly reversing (2) vertex */
            double dir[3], wob[3];
            for (int k = 0; k < 3; k++)
                dir[k] = x[3 + k] - x[k];
            tkt_rng_point(&r, 1.0, wob);
            double amount = kind == 1 ? 1e-2 : 1e-2;
            double sign = kind == 1 ? 1.0 : -1.0;
            double len = tkt_rng_range(&r, 0.2, 2.0);
            for (int k = 0; k < 3; k++)
                x[6 + k] = x[3 + k] + sign * len * dir[k] + amount * wob[k];
        } else if (kind == 3) {
            /* very unequal edges */
            for (int k = 0; k < 3; k++)
                x[k] = x[3 + k] + 1e-3 * (x[k] - x[3 + k]);
        }
        double g[9], fd[9];
        double value = tk_vertex_minrad_gradient(x, x + 3, x + 6, g);
        ck_assert(fabs(value - minrad_at(x)) <= 1e-15 * fmax(1.0, value));
        /* minrad switches branch where the two edges are equally long: no
         * derivative there, and FD straddling it is meaningless */
        double la = 0, lb = 0;
        for (int k = 0; k < 3; k++) {
            la += (x[3 + k] - x[k]) * (x[3 + k] - x[k]);
            lb += (x[6 + k] - x[3 + k]) * (x[6 + k] - x[3 + k]);
        }
        if (fabs(sqrt(la) - sqrt(lb)) < 1e-3)
            continue;
        /* the step must be small against the features of the function:
         * the shorter edge, and the distance from straight or reversed */
        double turn = tk_vertex_turning(x, x + 3, x + 6);
        double scale = fmin(sqrt(la), sqrt(lb)) * fmin(1.0, fmin(turn, M_PI - turn));
        const double h = 1e-4 * scale;
        for (int k = 0; k < 9; k++) {
            double y[9];
            memcpy(y, x, sizeof y);
            y[k] = x[k] + h;
            double up = minrad_at(y);
            y[k] = x[k] - h;
            double down = minrad_at(y);
            fd[k] = (up - down) / (2 * h);
        }
        checked++;
        ck_assert_msg(vec_reldiff(g, fd, 9) < 1e-6, "trial %d (kind %d): rel diff %g", trial,
                      kind, vec_reldiff(g, fd, 9));
    }
    ck_assert_int_gt(checked, 2500);
}
END_TEST

START_TEST(minrad_exact_values)
{
    /* regular n-gon of circumradius R: minrad = R cos(pi/n) (equation 3) */
    for (size_t n = 3; n <= 1000; n = n * 3 / 2 + 1) {
        tk_curve *c = tkt_regular_polygon(n, 2.5);
        size_t where;
        double m = tk_curve_minrad(c, &where);
        /* rounding in the vertices is amplified by about n^2 (short edges,
         * small turning angles) */
        double tol = 1e-14 + 4e-16 * (double)(n * n);
        ck_assert_msg(tkt_reldiff(m, 2.5 * cos(M_PI / (double)n)) < tol, "n=%zu: %.17g", n, m);
        ck_assert(where < n);
        tk_curve_free(&c);
    }
    /* a right angle with edges 1 and 3: min(1,3) / (2 tan(pi/4)) = 1/2 */
    double a[3] = {0, 0, 0}, v[3] = {1, 0, 0}, b[3] = {1, 3, 0};
    ck_assert_double_eq_tol(tk_vertex_minrad(a, v, b), 0.5, 1e-15);
    ck_assert_double_eq_tol(tk_vertex_turning(a, v, b), M_PI / 2, 1e-15);
    /* straight and reversing vertices */
    double s[3] = {2, 0, 0};
    ck_assert(isinf(tk_vertex_minrad(a, v, s)));
    ck_assert(tk_vertex_minrad(a, v, a) == 0.0);
}
END_TEST

START_TEST(length_gradient_matches_finite_differences)
{
    tkt_rng r = {5};
    size_t counts[2] = {7, 5};
    bool closed[2] = {true, false};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    for (int trial = 0; trial < 50; trial++) {
        for (size_t i = 0; i < 3 * c->nvert; i++)
            c->xyz[i] = tkt_rng_range(&r, -2, 2);
        double g[36], fd[36];
        tk_curve_length_gradient(c, g);
        const double h = 1e-6;
        for (size_t i = 0; i < 3 * c->nvert; i++) {
            double keep = c->xyz[i];
            c->xyz[i] = keep + h;
            double up = tk_curve_length(c);
            c->xyz[i] = keep - h;
            double down = tk_curve_length(c);
            c->xyz[i] = keep;
            fd[i] = (up - down) / (2 * h);
        }
        ck_assert_msg(vec_reldiff(g, fd, 3 * c->nvert) < 1e-6, "trial %d", trial);
    }
    tk_curve_free(&c);
}
END_TEST

START_TEST(vertex_neighbours)
{
    size_t counts[2] = {4, 3};
    bool closed[2] = {true, false};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    size_t p, n;
    ck_assert(tk_curve_vertex_neighbours(c, 0, &p, &n) && p == 3 && n == 1);
    ck_assert(tk_curve_vertex_neighbours(c, 3, &p, &n) && p == 2 && n == 0);
    ck_assert(!tk_curve_vertex_neighbours(c, 4, &p, &n));
    ck_assert(tk_curve_vertex_neighbours(c, 5, &p, &n) && p == 4 && n == 6);
    ck_assert(!tk_curve_vertex_neighbours(c, 6, &p, &n));
    tk_curve_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("geometry");
    TCase *tc = tcase_create("geometry");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, segment_distance_matches_sampling);
    tcase_add_test(tc, segment_distance_exact_cases);
    tcase_add_test(tc, long_edge_keeps_its_closest_point);
    tcase_add_test(tc, long_nearly_parallel_edges_far_out);
    tcase_add_test(tc, segment_meets_triangle_against_sampling);
    tcase_add_test(tc, distance_gradient_matches_finite_differences);
    tcase_add_test(tc, minrad_gradient_matches_finite_differences);
    tcase_add_test(tc, minrad_exact_values);
    tcase_add_test(tc, length_gradient_matches_finite_differences);
    tcase_add_test(tc, vertex_neighbours);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
