/* Thickness and ropelength (Definition 1): exact values, invariance under
 * rigid motions and scaling, and the published values of two catalogue
 * curves. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/generate.h"
#include "tk/geometry.h"
#include "tk/struts.h"
#include "tk/thickness.h"

START_TEST(regular_polygon_exact)
{
    /* Even regular n-gon of circumradius R: 2 minrad = 2 R cos(pi/n) (eq. 3)
     * and the opposite edges' midpoints are 2 R cos(pi/n) apart. */
    for (size_t n = 4; n <= 400; n += 6) {
        double radius = 1.7;
        tk_curve *c = tkt_regular_polygon(n, radius);
        tk_measure m;
        ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
        double expect = 2.0 * radius * cos(M_PI / (double)n);
        double tol = 1e-14 + 4e-16 * (double)(n * n);
        ck_assert_msg(tkt_reldiff(m.thickness, expect) < tol, "n=%zu thickness %.17g", n,
                      m.thickness);
        ck_assert_msg(tkt_reldiff(m.shortest, expect) < 1e-13, "n=%zu shortest %.17g", n,
                      m.shortest);
        double length = (double)n * 2.0 * radius * sin(M_PI / (double)n);
        ck_assert(tkt_reldiff(m.length, length) < 1e-13);
        ck_assert(tkt_reldiff(m.ropelength, 2.0 * length / expect) < tol);
        tk_curve_free(&c);
    }
}
END_TEST

static double point_to_component(const tk_curve *c, size_t comp, const double *x)
{
    double best = INFINITY;
    size_t ne = tk_curve_comp_edges(c, comp);
    for (size_t k = 0; k < ne; k++)
        best = fmin(best, tkt_point_segment(x, tk_curve_vertex(c, tk_curve_vertex_index(c, comp, k)),
                                        tk_curve_vertex(c, tk_curve_vertex_index(c, comp, k + 1))));
    return best;
}

/* Independent estimate of the distance between components 0 and 1: along
 * each edge of component 1 the distance to component 0 is a minimum of
 * convex functions; scan it finely and refine the best sample by ternary
 * search on its bracket. */
static double sampled_component_distance(const tk_curve *c)
{
    double best = INFINITY;
    size_t ne = tk_curve_comp_edges(c, 1);
    for (size_t k = 0; k < ne; k++) {
        const double *a = tk_curve_vertex(c, tk_curve_vertex_index(c, 1, k));
        const double *b = tk_curve_vertex(c, tk_curve_vertex_index(c, 1, k + 1));
        const int n = 200;
        double x[3], bs = 0, edge_best = INFINITY;
        for (int i = 0; i <= n; i++) {
            double s = (double)i / n;
            for (int j = 0; j < 3; j++)
                x[j] = a[j] + s * (b[j] - a[j]);
            double d = point_to_component(c, 0, x);
            if (d < edge_best) {
                edge_best = d;
                bs = s;
            }
        }
        double lo = fmax(0, bs - 1.0 / n), hi = fmin(1, bs + 1.0 / n);
        for (int it = 0; it < 100; it++) {
            double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3, y[3];
            for (int j = 0; j < 3; j++) {
                x[j] = a[j] + m1 * (b[j] - a[j]);
                y[j] = a[j] + m2 * (b[j] - a[j]);
            }
            if (point_to_component(c, 0, x) < point_to_component(c, 0, y))
                hi = m2;
            else
                lo = m1;
        }
        for (int j = 0; j < 3; j++)
            x[j] = a[j] + lo * (b[j] - a[j]);
        best = fmin(best, fmin(edge_best, point_to_component(c, 0, x)));
    }
    return best;
}

START_TEST(hopf_component_distance)
{
    /* Two unit circles, each through the other's centre, each with a vertex
     * there.  The vertex at A's centre is exactly the apothem cos(pi/n)
     * from A's edges; the polygons' chords come closer elsewhere. */
    for (size_t n = 8; n <= 128; n *= 2) {
        tk_curve *c = NULL;
        ck_assert_int_eq(tk_generate_hopf(n, &c, NULL), TK_OK);
        tk_strut_list list = {0};
        double apothem = cos(M_PI / (double)n);
        ck_assert_int_eq(tk_struts_find_brute(c, TK_ARC_FENCHEL, 0.0, 1.0, &list, NULL), TK_OK);
        double closest = INFINITY;
        bool centre_strut = false;
        for (size_t k = 0; k < list.count; k++) {
            const tk_strut *s = &list.items[k];
            if (s->comp[0] == s->comp[1])
                continue;
            closest = fmin(closest, s->length);
            /* B's vertex n/2 sits at A's centre */
            if (s->comp[1] == 1 && s->edge[1] == n / 2 && s->t == 0.0)
                centre_strut = centre_strut || tkt_reldiff(s->length, apothem) < 1e-14;
        }
        ck_assert_msg(centre_strut, "n=%zu: no strut from the centre vertex", n);
        double sampled = sampled_component_distance(c);
        ck_assert_msg(closest <= sampled + 1e-14 && sampled - closest < 1e-10,
                      "n=%zu: %.17g vs sampled %.17g", n, closest, sampled);
        tk_measure m;
        ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
        ck_assert(tkt_reldiff(m.thickness, fmin(closest, 2 * m.minrad)) < 1e-15);
        tk_strut_list_free(&list);
        tk_curve_free(&c);
    }
}
END_TEST

static void rotation(double angle, const double axis_in[3], double r[9])
{
    double n = sqrt(axis_in[0] * axis_in[0] + axis_in[1] * axis_in[1] + axis_in[2] * axis_in[2]);
    double x = axis_in[0] / n, y = axis_in[1] / n, z = axis_in[2] / n;
    double c = cos(angle), s = sin(angle), t = 1 - c;
    double m[9] = {t * x * x + c,     t * x * y - s * z, t * x * z + s * y,
                   t * x * y + s * z, t * y * y + c,     t * y * z - s * x,
                   t * x * z - s * y, t * y * z + s * x, t * z * z + c};
    for (int i = 0; i < 9; i++)
        r[i] = m[i];
}

START_TEST(ropelength_invariant_under_rigid_motions_and_scaling)
{
    const char *names[] = {"3.1.vect", "5.2.vect", "6.3.2.vect", "3_1_328.vect",
                           "10_154_test.vect", "simple_clasp.vect"};
    if (!tkt_catalogue_dir()) {
        tkt_skip("invariance on catalogue files", "the catalogue is absent");
        return;
    }
    tkt_rng rng = {2024};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        tk_curve *c = tkt_catalogue_curve(names[i]);
        tk_measure base;
        ck_assert_int_eq(tk_thickness_measure(c, NULL, &base, NULL), TK_OK);
        for (int trial = 0; trial < 5; trial++) {
            tk_curve *moved = NULL;
            ck_assert_int_eq(tk_curve_copy(c, &moved, NULL), TK_OK);
            double axis[3], shift[3], r[9];
            tkt_rng_point(&rng, 1.0, axis);
            tkt_rng_point(&rng, 50.0, shift);
            rotation(tkt_rng_range(&rng, 0, 2 * M_PI), axis, r);
            double factor = exp(tkt_rng_range(&rng, -3, 3));
            tk_curve_rotate(moved, r);
            tk_curve_translate(moved, shift);
            tk_curve_scale(moved, factor);
            tk_measure m;
            ck_assert_int_eq(tk_thickness_measure(moved, NULL, &m, NULL), TK_OK);
            ck_assert_msg(tkt_reldiff(m.ropelength, base.ropelength) < 1e-12,
                          "%s trial %d: %.17g vs %.17g", names[i], trial, m.ropelength,
                          base.ropelength);
            ck_assert(tkt_reldiff(m.thickness, factor * base.thickness) < 1e-12);
            tk_curve_free(&moved);
        }
        tk_curve_free(&c);
    }
}
END_TEST

START_TEST(published_values)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("published_values", "the catalogue is absent");
        return;
    }
    struct {
        const char *name;
        double ropelength;
    } known[] = {{"3_1_328.vect", 32.752356}, {"10_154_test.vect", 82.3858}};
    for (size_t i = 0; i < 2; i++) {
        tk_curve *c = tkt_catalogue_curve(known[i].name);
        tk_measure m;
        ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
        ck_assert_msg(tkt_reldiff(m.ropelength, known[i].ropelength) < 1e-6, "%s: %.10f",
                      known[i].name, m.ropelength);
        tk_curve_free(&c);
    }
}
END_TEST

START_TEST(doubly_critical_matters)
{
    /* On 10_154_test: the minimum over Theorem 3's admissible pairs (tau =
     * the thickness) equals the shortest doubly critical self-distance
     * (the equality case of (5)), while the plain minimum over all
     * non-adjacent edge pairs, without the local-minimum test, is far
     * smaller and would make the ropelength absurd. */
    if (!tkt_catalogue_dir()) {
        tkt_skip("doubly critical pairs", "the catalogue is absent");
        return;
    }
    tk_curve *c = tkt_catalogue_curve("10_154_test.vect");
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    size_t ne = tk_curve_edge_count(c);
    /* Theorem 3's rule written out for this one closed component: vertex
     * k can turn at most 2 atan(l_k / tau), l_k its shorter edge. */
    double *turn = calloc(ne + 1, sizeof *turn);
    for (size_t k = 0; k < ne; k++) {
        double l = fmin(tk_curve_edge_length(c, 0, (k + ne - 1) % ne),
                        tk_curve_edge_length(c, 0, k));
        turn[k + 1] = turn[k] + 2 * atan(l / m.thickness);
    }
    double admissible = INFINITY, plain = INFINITY;
    for (size_t i = 0; i < ne; i++)
        for (size_t j = i + 2; j < ne; j++) {
            if (i == 0 && j == ne - 1)
                continue;
            tk_edge a = tk_curve_edge(c, i), b = tk_curve_edge(c, j);
            tk_closest cl;
            tk_segment_closest(tk_curve_vertex(c, a.head), tk_curve_vertex(c, a.tail),
                               tk_curve_vertex(c, b.head), tk_curve_vertex(c, b.tail), &cl);
            plain = fmin(plain, cl.dist);
            double fwd = turn[j + 1] - turn[i + 1], bwd = turn[ne] - fwd;
            if (fmin(fwd, bwd) >= M_PI)
                admissible = fmin(admissible, cl.dist);
        }
    free(turn);
    ck_assert_msg(tkt_reldiff(admissible, m.shortest) < 1e-14, "%.17g vs %.17g", admissible,
                  m.shortest);
    ck_assert(m.length / (plain / 2) > 1000.0);
    ck_assert(tkt_reldiff(m.ropelength, 82.3858) < 1e-6);
    tk_curve_free(&c);
}
END_TEST

START_TEST(contacts_of_tight_trefoil)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("contacts_of_tight_trefoil", "the catalogue is absent");
        return;
    }
    tk_curve *c = tkt_catalogue_curve("3_1_328.vect");
    tk_measure m;
    tk_strut_list struts = {0};
    tk_kink *kinks = NULL;
    size_t nk = 0;
    ck_assert_int_eq(tk_thickness_contacts(c, 1e-4, &m, &struts, &kinks, &nk, NULL), TK_OK);
    /* every listed strut is within the tolerance and no shorter than the
     * thickness; kinks likewise */
    ck_assert_uint_gt(struts.count, 0);
    for (size_t k = 0; k < struts.count; k++) {
        ck_assert(struts.items[k].length >= m.thickness * (1 - 1e-15));
        ck_assert(struts.items[k].length <= m.thickness * (1 + 1e-4));
    }
    for (size_t k = 0; k < nk; k++)
        ck_assert(2 * kinks[k].minrad <= m.thickness * (1 + 1e-4));
    free(kinks);
    tk_strut_list_free(&struts);
    tk_curve_free(&c);
}
END_TEST

/* A triangle (0,0,0), (1,0,0), (0,y,0). */
static tk_curve *right_triangle(double y)
{
    size_t n = 3;
    bool closed = true;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &closed, NULL), TK_OK);
    c->xyz[3] = 1.0;
    c->xyz[7] = y;
    return c;
}

START_TEST(extreme_magnitudes_are_refused_in_bounded_time)
{
    /* Once squared distances overflow, no distance means anything; these
     * once made the shortest-contact search widen its radius forever. */
    const double ys[] = {1e200, 1e308, -1.7976931348623157e308, 1e31};
    for (size_t k = 0; k < sizeof ys / sizeof *ys; k++) {
        tk_curve *c = right_triangle(ys[k]);
        ck_assert_int_eq(tk_curve_validate(c, NULL), TK_OK); /* a valid VECT */
        tk_measure m;
        tk_error err;
        ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, "vertex 2 has coordinate y") &&
                          strstr(err.message, "1e+30"),
                      "%s", err.message);
        tk_curve_free(&c);
    }
    /* Edges below the range, at a small overall scale. */
    tk_curve *c = tkt_regular_polygon(12, 1e-31);
    tk_measure m;
    tk_error err;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "shorter than the 1e-30"), "%s", err.message);
    tk_curve_free(&c);
}
END_TEST

START_TEST(shortest_contact_search_ends_on_any_finite_curve)
{
    /* The search itself, below the range check, must end whatever the
     * magnitudes: with the box's diagonal infinite, or 600 orders of
     * magnitude between the closest approach and the curve's size. */
    const double ys[] = {1e200, 1e308, 1e-300};
    for (size_t k = 0; k < sizeof ys / sizeof *ys; k++) {
        tk_curve *c = right_triangle(ys[k]);
        tk_strut_finder *f = NULL;
        ck_assert_int_eq(tk_strut_finder_new(c, &f, NULL), TK_OK);
        double shortest = 0.0;
        ck_assert_int_eq(tk_strut_finder_shortest(f, c, &shortest, NULL, NULL), TK_OK);
        /* A triangle's edges all share vertices: no admissible pair. */
        ck_assert(isinf(shortest));
        tk_strut_finder_free(&f);
        tk_curve_free(&c);
    }
    /* Two far components, one 300 orders of magnitude smaller than the
     * gap between them (squares still finite): their distance. */
    size_t counts[2] = {4, 4};
    bool closed[2] = {true, true};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    const double sq[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int v = 0; v < 4; v++) {
        c->xyz[3 * v] = 1e-150 * sq[v][0];
        c->xyz[3 * v + 1] = 1e-150 * sq[v][1];
        c->xyz[12 + 3 * v] = 1e150 * (2.0 + sq[v][0]);
        c->xyz[12 + 3 * v + 1] = 1e150 * sq[v][1];
    }
    tk_strut_finder *f = NULL;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, NULL), TK_OK);
    double shortest = 0.0;
    ck_assert_int_eq(tk_strut_finder_shortest(f, c, &shortest, NULL, NULL), TK_OK);
    ck_assert_msg(tkt_reldiff(shortest, 2e150) < 1e-12, "shortest %g", shortest);
    tk_strut_finder_free(&f);
    tk_curve_free(&c);
}
END_TEST

START_TEST(measured_exactly_at_the_ends_of_the_range)
{
    /* Even regular n-gon (see regular_polygon_exact) at the largest and
     * smallest scales the range admits. */
    const double scales[] = {0.9e30, 3e-29, 1.0};
    for (size_t k = 0; k < sizeof scales / sizeof *scales; k++) {
        size_t n = 16;
        tk_curve *c = tkt_regular_polygon(n, scales[k]);
        tk_measure m;
        tk_error err;
        ck_assert_msg(tk_thickness_measure(c, NULL, &m, &err) == TK_OK, "%s", err.message);
        double expect = 2.0 * scales[k] * cos(M_PI / (double)n);
        ck_assert_msg(tkt_reldiff(m.thickness, expect) < 1e-13, "scale %g: thickness %.17g",
                      scales[k], m.thickness);
        double length = (double)n * 2.0 * scales[k] * sin(M_PI / (double)n);
        ck_assert(tkt_reldiff(m.ropelength, 2.0 * length / expect) < 1e-13);
        tk_curve_free(&c);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("thickness");
    TCase *tc = tcase_create("thickness");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, regular_polygon_exact);
    tcase_add_test(tc, hopf_component_distance);
    tcase_add_test(tc, ropelength_invariant_under_rigid_motions_and_scaling);
    tcase_add_test(tc, published_values);
    tcase_add_test(tc, doubly_critical_matters);
    tcase_add_test(tc, contacts_of_tight_trefoil);
    suite_add_tcase(s, tc);
    /* A hang here is the failure: a short timeout. */
    TCase *range = tcase_create("range");
    tcase_set_timeout(range, 20);
    tcase_add_test(range, extreme_magnitudes_are_refused_in_bounded_time);
    tcase_add_test(range, shortest_contact_search_ends_on_any_finite_curve);
    tcase_add_test(range, measured_exactly_at_the_ends_of_the_range);
    suite_add_tcase(s, range);
    return tkt_run_suite(s);
}
