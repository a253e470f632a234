/* Coarsening by triangle moves (engine/isotopy.c): the vertices kept are
 * the polygon's own, in order, shared among components as the lengths
 * ask; a coarsened curve has the start's type (Alexander polynomial and
 * linking numbers computed again); a ring hugging a strand, coarsened
 * below what its strand's curvature allows, is refused where a spline
 * resampling on as few vertices unlinks it; refined, a polygon is
 * itself, cut along its edges; argument errors. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/invariants.h"
#include "tk/isotopy.h"

static int same_type(const tk_curve *a, const tk_curve *b)
{
    tk_invariants x = TK_INVARIANTS_INIT, y = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(a, &x, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(b, &y, NULL), TK_OK);
    int rc = tk_invariants_compare(&x, &y, NULL);
    tk_invariants_free(&x);
    tk_invariants_free(&y);
    return rc == TK_OK;
}

/* Every vertex of out is one of c's, in c's order within its component,
 * component 0 first, and out's counts are tk_curve_share_total's. */
static void check_subset(const tk_curve *c, const tk_curve *out, size_t total)
{
    size_t counts[8];
    ck_assert_uint_le(c->ncomp, 8);
    ck_assert_int_eq(tk_curve_share_total(c, total, counts, NULL), TK_OK);
    ck_assert_uint_eq(out->ncomp, c->ncomp);
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        ck_assert_uint_eq(tk_curve_comp_vertices(out, comp), counts[comp]);
        size_t from = c->offset[comp], end = c->offset[comp + 1];
        for (size_t k = 0; k < counts[comp]; k++) {
            const double *x = tk_curve_vertex(out, out->offset[comp] + k);
            size_t v = from;
            while (v < end && memcmp(tk_curve_vertex(c, v), x, 3 * sizeof *x) != 0)
                v++;
            ck_assert_msg(v < end, "vertex %zu of component %zu is not the start's", k, comp);
            from = v + 1;
        }
        ck_assert(memcmp(tk_curve_vertex(out, out->offset[comp]),
                         tk_curve_vertex(c, c->offset[comp]), 3 * sizeof(double)) == 0);
    }
}

/* Disguised torus knots and links (uneven edges, no symmetry) on many
 * vertices, coarsened to counts down to a few a crossing: each result is
 * the start's vertices and type; the lowest counts may be refused, the
 * higher never are. */
START_TEST(coarsening_keeps_type)
{
    const int pq[][2] = {{2, 3}, {2, 5}, {3, 4}, {2, 4}, {3, 3}};
    int refused = 0, done = 0;
    for (size_t t = 0; t < sizeof pq / sizeof pq[0]; t++) {
        tk_curve *plain = NULL, *c = NULL;
        ck_assert_int_eq(tk_generate_torus(pq[t][0], pq[t][1], 600, &plain, NULL), TK_OK);
        ck_assert_int_eq(tk_generate_disguise(plain, 5 + t, 0.05, &c, NULL), TK_OK);
        const size_t totals[] = {300, 120, 60, 36};
        for (size_t k = 0; k < sizeof totals / sizeof totals[0]; k++) {
            tk_curve *out = NULL;
            bool kept = false;
            ck_assert_int_eq(tk_isotopy_coarsen(c, totals[k], &out, &kept, NULL), TK_OK);
            if (!kept) {
                ck_assert_ptr_null(out);
                ck_assert_uint_le(totals[k], 60);
                refused++;
                continue;
            }
            check_subset(c, out, totals[k]);
            ck_assert_msg(same_type(c, out), "T(%d,%d) on %zu vertices changed its type",
                          pq[t][0], pq[t][1], totals[k]);
            done++;
            tk_curve_free(&out);
        }
        tk_curve_free(&plain);
        tk_curve_free(&c);
    }
    printf("coarsened: %d kept their type, %d refused\n", done, refused);
    ck_assert_int_ge(done, 15);
}
END_TEST

/* A ring of radius r threaded on a circle of radius 1 (a Hopf link): on
 * m vertices the circle's chords leave it 1 - cos(pi / m) inward, which
 * for m = 10 is 0.049, far beyond r = 0.01: no polygon of the circle's
 * own 10 vertices, none of them in the ring, passes through it.  The
 * coarsening refuses; a spline resampling on as many vertices takes the
 * circle out of the ring and the link comes apart (linking number 0). */
static tk_curve *threaded_ring(size_t n, size_t ring, double r)
{
    size_t counts[2] = {n, ring};
    bool closed[2] = {true, true};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    for (size_t k = 0; k < n; k++) {
        double a = 2.0 * M_PI * ((double)k + 0.5) / (double)n;
        double *x = tk_curve_vertex(c, k);
        x[0] = cos(a);
        x[1] = sin(a);
        x[2] = 0.0;
    }
    /* the ring about the circle's point at angle pi / 10, halfway between
     * two of the vertices a coarsening to 10 keeps, across the circle */
    double t = M_PI / 10.0;
    for (size_t k = 0; k < ring; k++) {
        double a = 2.0 * M_PI * (double)k / (double)ring;
        double *x = tk_curve_vertex(c, n + k);
        x[0] = (1.0 + r * cos(a)) * cos(t);
        x[1] = (1.0 + r * cos(a)) * sin(t);
        x[2] = r * sin(a);
    }
    return c;
}

START_TEST(a_threaded_ring_is_not_passed_through)
{
    tk_curve *c = threaded_ring(2000, 12, 0.01), *out = NULL, *spline = NULL;
    bool kept = true;
    /* the ring is 0.0377 of the 6.34 long: on 13 vertices it keeps 3 */
    ck_assert_int_eq(tk_isotopy_coarsen(c, 13, &out, &kept, NULL), TK_OK);
    ck_assert(!kept);
    ck_assert_ptr_null(out);
    ck_assert_int_eq(tk_curve_resample_total(c, 13, &spline, NULL), TK_OK);
    ck_assert(!same_type(c, spline));
    /* with vertices enough the circle stays in the ring */
    ck_assert_int_eq(tk_isotopy_coarsen(c, 400, &out, &kept, NULL), TK_OK);
    ck_assert(kept);
    check_subset(c, out, 400);
    ck_assert(same_type(c, out));
    tk_curve_free(&out);
    tk_curve_free(&spline);
    tk_curve_free(&c);
}
END_TEST

/* Open components keep both ends; a colour is carried, pins are not. */
START_TEST(open_ends_and_colour)
{
    size_t counts[2] = {50, 40};
    bool closed[2] = {false, true};
    tk_curve *c = NULL, *out = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    for (size_t k = 0; k < 50; k++) {
        double *x = tk_curve_vertex(c, k);
        x[0] = (double)k;
        x[1] = sin(0.3 * (double)k);
        x[2] = 5.0;
    }
    for (size_t k = 0; k < 40; k++) {
        double *x = tk_curve_vertex(c, 50 + k), a = 2.0 * M_PI * (double)k / 40.0;
        x[0] = 20.0 * cos(a);
        x[1] = 20.0 * sin(a);
        x[2] = 0.0;
    }
    c->colour = calloc(8, sizeof *c->colour);
    c->colour[0] = 0.5;
    c->has_colour = true;
    bool kept = false;
    ck_assert_int_eq(tk_isotopy_coarsen(c, 30, &out, &kept, NULL), TK_OK);
    ck_assert(kept);
    check_subset(c, out, 30);
    size_t last = out->offset[1] - 1;
    ck_assert(memcmp(tk_curve_vertex(out, last), tk_curve_vertex(c, 49), 3 * sizeof(double)) == 0);
    ck_assert(out->has_colour && out->colour[0] == 0.5);
    ck_assert_uint_eq(out->npins, 0);
    tk_curve_free(&out);
    tk_curve_free(&c);
}
END_TEST

/* Refined, a polygon is itself: its vertices in order, each new one on
 * the edge it cuts (within rounding), about the count asked, the pieces
 * of an edge equal; an open component keeps its last vertex. */
START_TEST(refining_keeps_the_polygon)
{
    tk_curve *plain = NULL, *c = NULL, *out = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 4, 40, &plain, NULL), TK_OK);
    ck_assert_int_eq(tk_generate_disguise(plain, 3, 0.05, &c, NULL), TK_OK);
    c->closed[1] = false;
    ck_assert_int_eq(tk_isotopy_refine(c, 1000, &out, NULL), TK_OK);
    printf("refined: %zu vertices for 1000 asked\n", out->nvert);
    ck_assert(out->nvert >= 950 && out->nvert <= 1050);
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp), at = out->offset[comp];
        size_t edges = tk_curve_comp_edges(c, comp);
        for (size_t i = 0; i < edges; i++) {
            const double *a = tk_curve_vertex(c, c->offset[comp] + i);
            const double *b = tk_curve_vertex(c, c->offset[comp] + (i + 1) % n);
            ck_assert(memcmp(tk_curve_vertex(out, at), a, 3 * sizeof *a) == 0);
            size_t end = at + 1;
            while (end < out->offset[comp + 1] && memcmp(tk_curve_vertex(out, end), b, 3 * sizeof *b) != 0) {
                ck_assert(tkt_point_segment(tk_curve_vertex(out, end), a, b) <
                          1e-12 * tk_curve_length(c));
                end++;
            }
            size_t pieces = end - at;
            if (end == out->offset[comp + 1]) /* the closing edge: back to vertex 0 */
                ck_assert(i == edges - 1 && c->closed[comp]);
            double piece = tk_curve_edge_length(c, comp, i) / (double)pieces;
            for (size_t k = at; k < end; k++) {
                const double *x = tk_curve_vertex(out, k);
                const double *y = k + 1 < out->offset[comp + 1] ? tk_curve_vertex(out, k + 1)
                                                                : tk_curve_vertex(out, out->offset[comp]);
                double d = sqrt(pow(y[0] - x[0], 2) + pow(y[1] - x[1], 2) + pow(y[2] - x[2], 2));
                ck_assert(fabs(d - piece) < 1e-9 * piece);
            }
            at = end;
        }
        if (!c->closed[comp])
            ck_assert(memcmp(tk_curve_vertex(out, out->offset[comp + 1] - 1),
                             tk_curve_vertex(c, c->offset[comp + 1] - 1), 3 * sizeof(double)) == 0);
    }
    tk_curve_free(&out);
    tk_curve_free(&plain);
    tk_curve_free(&c);
}
END_TEST

START_TEST(invalid_arguments)
{
    tk_curve *c = tkt_regular_polygon(12, 1.0), *out = NULL;
    bool kept = true;
    tk_error err;
    ck_assert_int_eq(tk_isotopy_coarsen(c, 2, &out, &kept, &err), TK_EINVAL);
    ck_assert(!kept);
    ck_assert_int_eq(tk_isotopy_coarsen(c, 13, &out, &kept, &err), TK_EINVAL);
    ck_assert_ptr_nonnull(strstr(err.message, "12 vertices"));
    ck_assert_ptr_null(out);
    /* as many as it has: the curve itself */
    ck_assert_int_eq(tk_isotopy_coarsen(c, 12, &out, &kept, &err), TK_OK);
    ck_assert(kept);
    ck_assert_mem_eq(out->xyz, c->xyz, 36 * sizeof *c->xyz);
    tk_curve_free(&out);
    tk_curve_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("isotopy");
    TCase *tc = tcase_create("isotopy");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, coarsening_keeps_type);
    tcase_add_test(tc, a_threaded_ring_is_not_passed_through);
    tcase_add_test(tc, open_ends_and_colour);
    tcase_add_test(tc, refining_keeps_the_polygon);
    tcase_add_test(tc, invalid_arguments);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
