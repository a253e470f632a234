/* Unit tests of the repulsive relaxation (engine/relax.c): the energy's
 * gradient against central finite differences, with and without a pull;
 * the gap against a brute force of its own; a relaxation keeps the type
 * (Alexander polynomial and linking numbers computed again), the length,
 * and every edge apart; a round circle, a critical point of E by its
 * symmetry, stays; turned inside out, a curve keeps its type and hand;
 * argument errors. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/invariants.h"
#include "tk/relax.h"
#include "tk/thickness.h"

/* A two-component link, disguised: uneven edges and no symmetry, so that
 * every term of the gradient (springs of two lengths, the pull) counts. */
static tk_curve *uneven_link(void)
{
    tk_curve *plain = NULL, *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 4, 30, &plain, NULL), TK_OK);
    ck_assert_int_eq(tk_generate_disguise(plain, 3, 0.05, &c, NULL), TK_OK);
    tk_curve_free(&plain);
    return c;
}

static void check_gradient(const tk_curve *target, double pull)
{
    tk_curve *c = uneven_link();
    double *grad = malloc(3 * c->nvert * sizeof *grad);
    tk_relax_energy(c, target, pull, grad);
    double worst = 0.0;
    for (size_t k = 0; k < 3 * c->nvert; k += 7) {
        double x = c->xyz[k], step = 1e-6;
        c->xyz[k] = x + step;
        double up = tk_relax_energy(c, target, pull, NULL);
        c->xyz[k] = x - step;
        double down = tk_relax_energy(c, target, pull, NULL);
        c->xyz[k] = x;
        double fd = (up - down) / (2.0 * step);
        worst = fmax(worst, fabs(fd - grad[k]) / fmax(1.0, fabs(fd)));
    }
    ck_assert_msg(worst < 1e-6, "gradient against finite differences: worst %g", worst);
    free(grad);
    tk_curve_free(&c);
}

START_TEST(energy_gradient_matches_finite_differences)
{
    check_gradient(NULL, 0.0);
    tk_curve *target = uneven_link();
    tk_curve_scale(target, 1.7);
    check_gradient(target, 0.8);
    tk_curve_free(&target);
}
END_TEST

/* The gap: the least distance between edges that share no vertex,
 * against the minimum over sampled points of each edge pair (an upper
 * bound that comes within the sampling's resolution). */
START_TEST(gap_against_sampled_points)
{
    tk_curve *c = uneven_link();
    double gap = tk_relax_gap(c), sampled = INFINITY;
    size_t m = tk_curve_edge_count(c);
    for (size_t i = 0; i < m; i++) {
        tk_edge a = tk_curve_edge(c, i);
        for (size_t j = i + 1; j < m; j++) {
            tk_edge b = tk_curve_edge(c, j);
            if (a.head == b.head || a.head == b.tail || a.tail == b.head || a.tail == b.tail)
                continue;
            const double *a0 = tk_curve_vertex(c, a.head), *a1 = tk_curve_vertex(c, a.tail);
            const double *b0 = tk_curve_vertex(c, b.head), *b1 = tk_curve_vertex(c, b.tail);
            for (int s = 0; s <= 40; s++) {
                double p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = a0[k] + (a1[k] - a0[k]) * s / 40.0;
                sampled = fmin(sampled, tkt_point_segment(p, b0, b1));
            }
        }
    }
    ck_assert(gap <= sampled + 1e-12);
    ck_assert_msg(sampled - gap < 0.02 * gap, "gap %g, sampled %g", gap, sampled);
    tk_curve_free(&c);
}
END_TEST

static void check_kept(const tk_curve *before, const tk_curve *after)
{
    tk_invariants was = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(before, &was, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(after, &now, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compare(&was, &now, NULL), TK_OK);
    ck_assert(tk_relax_gap(after) > 0.0);
    tk_invariants_free(&was);
    tk_invariants_free(&now);
}

/* Relaxed, a disguised trefoil and a disguised link keep their types and
 * lengths, their energy falls, and they move: the far strands spread. */
START_TEST(relaxation_keeps_type_and_length)
{
    tk_curve *plain = NULL, *knot = NULL, *link = uneven_link();
    ck_assert_int_eq(tk_generate_torus(2, 3, 60, &plain, NULL), TK_OK);
    ck_assert_int_eq(tk_generate_disguise(plain, 5, 0.05, &knot, NULL), TK_OK);
    tk_curve *starts[2] = {knot, link};
    for (int s = 0; s < 2; s++) {
        tk_curve *out = NULL;
        int steps = 0;
        ck_assert_int_eq(tk_relax(starts[s], NULL, 0.0, 400, &out, &steps, NULL), TK_OK);
        ck_assert(steps > 100);
        ck_assert(tk_relax_energy(out, NULL, 0.0, NULL) <
                  0.9 * tk_relax_energy(starts[s], NULL, 0.0, NULL));
        ck_assert_double_eq_tol(tk_curve_length(out), tk_curve_length(starts[s]),
                                1e-12 * tk_curve_length(starts[s]));
        check_kept(starts[s], out);
        tk_curve_free(&out);
    }
    tk_curve_free(&plain);
    tk_curve_free(&knot);
    tk_curve_free(&link);
}
END_TEST

/* Pulled toward a far target that passes through itself (the trefoil's
 * vertices sent around a circle: the unknot's shape), the trefoil goes as
 * far as its strands let it and stays a trefoil. */
START_TEST(a_pull_cannot_change_the_type)
{
    tk_curve *knot = NULL, *circle = NULL, *out = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 60, &knot, NULL), TK_OK);
    ck_assert_int_eq(tk_curve_copy(knot, &circle, NULL), TK_OK);
    for (size_t v = 0; v < circle->nvert; v++) {
        double t = 2.0 * M_PI * (double)v / (double)circle->nvert, *p = tk_curve_vertex(circle, v);
        p[0] = 3.0 * cos(t);
        p[1] = 3.0 * sin(t);
        p[2] = 0.0;
    }
    int steps = 0;
    ck_assert_int_eq(tk_relax(knot, circle, 1.0, 1500, &out, &steps, NULL), TK_OK);
    ck_assert(steps > 100);
    double before = 0.0, after = 0.0;
    for (size_t v = 0; v < knot->nvert; v++)
        for (int k = 0; k < 3; k++) {
            before += pow(knot->xyz[3 * v + k] - circle->xyz[3 * v + k], 2);
            after += pow(out->xyz[3 * v + k] - circle->xyz[3 * v + k], 2);
        }
    ck_assert(after < 0.5 * before);
    check_kept(knot, out);
    tk_curve_free(&knot);
    tk_curve_free(&circle);
    tk_curve_free(&out);
}
END_TEST

/* A regular polygon is critical for E (every vertex alike): it stays. */
START_TEST(a_round_circle_stays)
{
    tk_curve *c = tkt_regular_polygon(40, 2.0), *out = NULL;
    ck_assert_int_eq(tk_relax(c, NULL, 0.0, 100, &out, NULL, NULL), TK_OK);
    double moved = 0.0;
    for (size_t k = 0; k < 3 * c->nvert; k++)
        moved = fmax(moved, fabs(out->xyz[k] - c->xyz[k]));
    ck_assert_msg(moved < 1e-9, "moved %g", moved);
    tk_curve_free(&c);
    tk_curve_free(&out);
}
END_TEST

/* The writhe by the Gauss double integral over edge midpoints (an
 * independent figure: its sign is the trefoil's handedness). */
static double writhe(const tk_curve *c)
{
    size_t m = tk_curve_edge_count(c);
    double w = 0.0;
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++) {
            if (i == j)
                continue;
            tk_edge a = tk_curve_edge(c, i), b = tk_curve_edge(c, j);
            const double *a0 = tk_curve_vertex(c, a.head), *a1 = tk_curve_vertex(c, a.tail);
            const double *b0 = tk_curve_vertex(c, b.head), *b1 = tk_curve_vertex(c, b.tail);
            double ta[3], tb[3], d[3];
            for (int k = 0; k < 3; k++) {
                ta[k] = a1[k] - a0[k];
                tb[k] = b1[k] - b0[k];
                d[k] = 0.5 * (a0[k] + a1[k]) - 0.5 * (b0[k] + b1[k]);
            }
            double cx[3] = {ta[1] * tb[2] - ta[2] * tb[1], ta[2] * tb[0] - ta[0] * tb[2],
                            ta[0] * tb[1] - ta[1] * tb[0]};
            double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            w += (cx[0] * d[0] + cx[1] * d[1] + cx[2] * d[2]) / (r * r * r);
        }
    return w / (4.0 * M_PI);
}

/* The centroid of c's vertices into centre, and their root mean square
 * distance from it (near the wire's, which tk_relax_turn uses). */
static double vertex_spread(const tk_curve *c, double centre[3])
{
    double spread = 0.0;
    centre[0] = centre[1] = centre[2] = 0.0;
    for (size_t i = 0; i < c->nvert; i++)
        for (int k = 0; k < 3; k++)
            centre[k] += c->xyz[3 * i + k] / (double)c->nvert;
    for (size_t i = 0; i < c->nvert; i++)
        for (int k = 0; k < 3; k++)
            spread += pow(c->xyz[3 * i + k] - centre[k], 2) / (double)c->nvert;
    return sqrt(spread);
}

/* Turned inside out, a trefoil stays a trefoil of the same hand (its
 * writhe keeps its sign: the mirror undoes the inversion's), a link keeps
 * its linking number.  A centre on the curve is refused, not followed
 * (its image would be at infinity). */
START_TEST(turning_keeps_type_and_hand)
{
    tk_curve *knot = NULL, *link = NULL, *out = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 120, &knot, NULL), TK_OK);
    double zero[3] = {0.0, 0.0, 0.0};
    ck_assert_int_eq(tk_relax_turn(knot, zero, 90, 500, &out, NULL), TK_OK);
    ck_assert_uint_eq(out->nvert, 90);
    check_kept(knot, out);
    double before = writhe(knot), after = writhe(out);
    printf("writhe %.4f turned %.4f\n", before, after);
    ck_assert(fabs(before) > 2.0 && before * after > 0.0);
    tk_curve_free(&out);
    ck_assert_int_eq(tk_generate_torus(2, 4, 60, &link, NULL), TK_OK);
    uint64_t state = 3;
    double offset[3];
    tk_relax_turn_offset(&state, offset);
    ck_assert_int_eq(tk_relax_turn(link, offset, 80, 300, &out, NULL), TK_OK);
    check_kept(link, out);
    tk_curve_free(&out);
    /* centres along the ray from the centroid through a vertex: each
     * turns the curve keeping its type or is refused, and those within
     * 1e-3 of the spread from the curve are refused as too near (the
     * spread and centroid here are the vertices', near the wire's) */
    tk_curve_free(&knot);
    ck_assert_int_eq(tk_generate_torus(2, 5, 200, &knot, NULL), TK_OK);
    const double *v = tk_curve_vertex(knot, 0);
    double centre[3], spread = vertex_spread(knot, centre);
    int near = 0, turned = 0;
    for (int step = -20; step <= 20; step++) {
        double onto[3];
        for (int k = 0; k < 3; k++)
            onto[k] = (1.0 + 0.0025 * step) * (v[k] - centre[k]) / spread;
        tk_error err;
        int rc = tk_relax_turn(knot, onto, 80, 5, &out, &err);
        if (rc == TK_OK) {
            check_kept(knot, out);
            turned++;
        } else {
            ck_assert_int_eq(rc, TK_ENUMERIC);
            ck_assert_ptr_null(out);
            near += strstr(err.message, "too near") != NULL;
        }
        tk_curve_free(&out);
    }
    printf("centres along the ray: %d turned, %d too near\n", turned, near);
    ck_assert_int_gt(near, 0);
    ck_assert_int_gt(turned, 0);
    tk_curve_free(&knot);
    tk_curve_free(&link);
}
END_TEST

/* A turn leaves no narrow passage: with the repulsion's fourth power
 * (tk/relax.h) the relaxed polygon keeps every two edges that share no
 * vertex at least 0.9 of its mean edge apart.  Catalogue 10.158 turned
 * about its centroid on its own 108 vertices, 3,000 steps (what
 * `tightknot generate turn 10.158.vect 0` does): 0.978 of an edge; with
 * the square, 0.754. */
START_TEST(a_turn_leaves_no_narrow_passage)
{
    const char *name = "a_turn_leaves_no_narrow_passage";
    if (!tkt_catalogue_dir() && tkt_skip(name, "no catalogue"))
        return;
    tk_curve *knot = tkt_catalogue_curve("10.158.vect"), *out = NULL;
    double zero[3] = {0.0, 0.0, 0.0};
    ck_assert_int_eq(tk_relax_turn(knot, zero, knot->nvert, 3000, &out, NULL), TK_OK);
    check_kept(knot, out);
    double edge = tk_curve_length(out) / (double)tk_curve_edge_count(out);
    double gap = tk_relax_gap(out);
    printf("10.158 turned: closest edges %.4f of the mean edge\n", gap / edge);
    ck_assert_double_ge(gap, 0.9 * edge);
    tk_curve_free(&out);
    tk_curve_free(&knot);
}
END_TEST

/* Three round rings in a row, unlinked, the last far out: turned about
 * the first one's centre, the far ring comes back a speck (inversion
 * shrinks by the square of the distance), and the turn is refused for it
 * (the curve's ropelength would be 1e8 times its own); turned
 * about the centroid every ring keeps a size, and the result is taken
 * with a ropelength within 20 times the rings'. */
START_TEST(turning_refuses_a_ring_shrunk_to_a_speck)
{
    size_t counts[3] = {24, 24, 24};
    bool closed[3] = {true, true, true};
    double at[3] = {0.0, 4.0, 40.0};
    tk_curve *rings = NULL, *out = NULL;
    ck_assert_int_eq(tk_curve_new(&rings, 3, counts, closed, NULL), TK_OK);
    for (size_t comp = 0; comp < 3; comp++)
        for (size_t i = 0; i < 24; i++) {
            double *p = tk_curve_vertex(rings, rings->offset[comp] + i), a = 2.0 * M_PI * i / 24;
            p[0] = at[comp] + cos(a);
            p[1] = sin(a);
            p[2] = 0.0;
        }
    double centroid[3], spread = vertex_spread(rings, centroid);
    tk_measure m, turned;
    ck_assert_int_eq(tk_thickness_measure(rings, NULL, &m, NULL), TK_OK);
    double first[3] = {-centroid[0] / spread, -centroid[1] / spread, -centroid[2] / spread};
    tk_error err;
    ck_assert_int_eq(tk_relax_turn(rings, first, 36, 50, &out, &err), TK_ENUMERIC);
    ck_assert_ptr_null(out);
    printf("turned about the first ring: %s\n", err.message);
    ck_assert_ptr_nonnull(strstr(err.message, "speck"));
    double zero[3] = {0.0, 0.0, 0.0};
    ck_assert_int_eq(tk_relax_turn(rings, zero, 36, 50, &out, NULL), TK_OK);
    check_kept(rings, out);
    ck_assert_int_eq(tk_thickness_measure(out, NULL, &turned, NULL), TK_OK);
    printf("turned about the centroid: ropelength %.4g from %.4g\n", turned.ropelength,
           m.ropelength);
    ck_assert(turned.ropelength <= 20.0 * m.ropelength);
    tk_curve_free(&out);
    tk_curve_free(&rings);
}
END_TEST

/* Wandering: the type kept, the shape far from the start (some vertex
 * moved by more than the curve's radius), the same seed the same curve. */
START_TEST(wandering_goes_far_and_keeps_the_type)
{
    tk_curve *link = uneven_link(), *out = NULL, *again = NULL;
    ck_assert_int_eq(tk_relax_wander(link, 7, 400, &out, NULL), TK_OK);
    check_kept(link, out);
    double radius = tk_curve_length(link) / (2.0 * M_PI * (double)link->ncomp), moved = 0.0;
    for (size_t v = 0; v < link->nvert; v++) {
        double d = 0.0;
        for (int k = 0; k < 3; k++)
            d += pow(out->xyz[3 * v + k] - link->xyz[3 * v + k], 2);
        moved = fmax(moved, sqrt(d));
    }
    printf("wandered: the farthest vertex moved %.3g, the radius %.3g\n", moved, radius);
    ck_assert(moved > radius);
    ck_assert_int_eq(tk_relax_wander(link, 7, 400, &again, NULL), TK_OK);
    ck_assert_mem_eq(again->xyz, out->xyz, 3 * out->nvert * sizeof *out->xyz);
    tk_curve_free(&link);
    tk_curve_free(&out);
    tk_curve_free(&again);
}
END_TEST

START_TEST(invalid_arguments)
{
    tk_curve *c = tkt_regular_polygon(12, 1.0), *other = tkt_regular_polygon(13, 1.0);
    tk_curve *out = NULL;
    tk_error err;
    ck_assert_int_eq(tk_relax(c, other, 1.0, 10, &out, NULL, &err), TK_EINVAL);
    ck_assert_ptr_nonnull(strstr(err.message, "12 vertices"));
    ck_assert_int_eq(tk_relax(c, c, -1.0, 10, &out, NULL, &err), TK_EINVAL);
    c->closed[0] = false;
    ck_assert_int_eq(tk_relax(c, NULL, 0.0, 10, &out, NULL, &err), TK_EINVAL);
    ck_assert_ptr_nonnull(strstr(err.message, "open"));
    ck_assert_ptr_null(out);
    tk_curve_free(&c);
    tk_curve_free(&other);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("relax");
    TCase *tc = tcase_create("relax");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, energy_gradient_matches_finite_differences);
    tcase_add_test(tc, gap_against_sampled_points);
    tcase_add_test(tc, relaxation_keeps_type_and_length);
    tcase_add_test(tc, a_pull_cannot_change_the_type);
    tcase_add_test(tc, a_round_circle_stays);
    tcase_add_test(tc, turning_keeps_type_and_hand);
    tcase_add_test(tc, a_turn_leaves_no_narrow_passage);
    tcase_add_test(tc, turning_refuses_a_ring_shrunk_to_a_speck);
    tcase_add_test(tc, wandering_goes_far_and_keeps_the_type);
    tcase_add_test(tc, invalid_arguments);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
