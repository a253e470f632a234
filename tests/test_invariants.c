/* Linking numbers against exact values: the Hopf link (1), torus links
 * T(2, 2k) (k), chains (1 between neighbours, 0 otherwise), the Borromean
 * rings (0 for every pair), rings pulled apart (0); and the symmetries
 * that must hold whatever the polygon: symmetric in the two components,
 * the sign flipped by reversing one or by a mirror, unchanged by rotation,
 * scaling, resampling and small perturbations. */
#include <check.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/generate.h"
#include "tk/invariants.h"

static long lk_of(const tk_curve *c, size_t a, size_t b)
{
    long lk = 99;
    double gauss = NAN;
    tk_error err;
    ck_assert_msg(tk_linking_number(c, a, b, &lk, &gauss, &err) == TK_OK, "%s", err.message);
    /* exact within rounding: the polygon's integral is an integer */
    ck_assert_msg(fabs(gauss - (double)lk) < 1e-9, "Gauss integral %.15g", gauss);
    return lk;
}

START_TEST(hopf_and_torus_links)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    long hopf = lk_of(c, 0, 1);
    ck_assert_int_eq(labs(hopf), 1);
    ck_assert_int_eq(lk_of(c, 1, 0), hopf);
    tk_curve_free(&c);
    for (int k = 1; k <= 4; k++) {
        ck_assert_int_eq(tk_generate_torus(2, 2 * k, 30 * k, &c, NULL), TK_OK);
        ck_assert_int_eq(c->ncomp, 2);
        ck_assert_int_eq(labs(lk_of(c, 0, 1)), k);
        tk_curve_free(&c);
    }
    /* T(3, 3): three components, each pair linked once */
    ck_assert_int_eq(tk_generate_torus(3, 3, 60, &c, NULL), TK_OK);
    ck_assert_int_eq(c->ncomp, 3);
    for (size_t a = 0; a < 3; a++)
        for (size_t b = a + 1; b < 3; b++)
            ck_assert_int_eq(labs(lk_of(c, a, b)), 1);
    tk_curve_free(&c);
}
END_TEST

START_TEST(chains_and_borromean_rings)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(5, 32, &c, NULL), TK_OK);
    for (size_t a = 0; a < 5; a++)
        for (size_t b = a + 1; b < 5; b++)
            ck_assert_int_eq(labs(lk_of(c, a, b)), b == a + 1 ? 1 : 0);
    tk_curve_free(&c);
    /* linked as a whole, yet no two of them are */
    ck_assert_int_eq(tk_generate_borromean(48, &c, NULL), TK_OK);
    for (size_t a = 0; a < 3; a++)
        for (size_t b = a + 1; b < 3; b++)
            ck_assert_int_eq(lk_of(c, a, b), 0);
    tk_curve_free(&c);
}
END_TEST

/* Reverses the order of the vertices of component comp. */
static void reverse(tk_curve *c, size_t comp)
{
    size_t n = tk_curve_comp_vertices(c, comp);
    double *x = c->xyz + 3 * c->offset[comp];
    for (size_t i = 0, j = n - 1; i < j; i++, j--)
        for (int k = 0; k < 3; k++) {
            double t = x[3 * i + k];
            x[3 * i + k] = x[3 * j + k];
            x[3 * j + k] = t;
        }
}

START_TEST(orientation_mirror_and_motion)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 4, 64, &c, NULL), TK_OK);
    long lk = lk_of(c, 0, 1);
    reverse(c, 1);
    ck_assert_int_eq(lk_of(c, 0, 1), -lk);
    reverse(c, 1);
    /* a mirror image links the other way */
    for (size_t v = 0; v < c->nvert; v++)
        tk_curve_vertex(c, v)[2] *= -1.0;
    ck_assert_int_eq(lk_of(c, 0, 1), -lk);
    for (size_t v = 0; v < c->nvert; v++)
        tk_curve_vertex(c, v)[2] *= -1.0;
    /* rotation, scaling and a perturbation of a tenth of an edge leave it */
    tkt_rng rng = {11};
    for (int round = 0; round < 20; round++) {
        double axis[3];
        tkt_rng_point(&rng, 1.0, axis);
        double len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
        double angle = tkt_rng_range(&rng, 0, 2 * M_PI), s = sin(angle), co = cos(angle);
        double u[3] = {axis[0] / len, axis[1] / len, axis[2] / len};
        double r[9] = {co + u[0] * u[0] * (1 - co),        u[0] * u[1] * (1 - co) - u[2] * s,
                       u[0] * u[2] * (1 - co) + u[1] * s, u[1] * u[0] * (1 - co) + u[2] * s,
                       co + u[1] * u[1] * (1 - co),        u[1] * u[2] * (1 - co) - u[0] * s,
                       u[2] * u[0] * (1 - co) - u[1] * s, u[2] * u[1] * (1 - co) + u[0] * s,
                       co + u[2] * u[2] * (1 - co)};
        tk_curve *m = NULL;
        ck_assert_int_eq(tk_curve_copy(c, &m, NULL), TK_OK);
        tk_curve_rotate(m, r);
        tk_curve_scale(m, tkt_rng_range(&rng, 1e-3, 1e3));
        double shortest, longest;
        tk_curve_edge_range(m, &shortest, &longest);
        for (size_t v = 0; v < m->nvert; v++) {
            double d[3];
            tkt_rng_point(&rng, 0.1 * shortest, d);
            for (int k = 0; k < 3; k++)
                tk_curve_vertex(m, v)[k] += d[k];
        }
        ck_assert_int_eq(lk_of(m, 0, 1), lk);
        tk_curve_free(&m);
    }
    /* resampled to another vertex count */
    tk_curve *fine = NULL;
    ck_assert_int_eq(tk_curve_resample_total(c, 500, &fine, NULL), TK_OK);
    ck_assert_int_eq(lk_of(fine, 0, 1), lk);
    tk_curve_free(&fine);
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_strand_passage_is_caught)
{
    /* The second ring of a Hopf link pulled out through the first: the
     * link falls apart, and the linking number says so. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    ck_assert_int_eq(labs(lk_of(c, 0, 1)), 1);
    for (size_t i = 0; i < tk_curve_comp_vertices(c, 1); i++)
        tk_curve_vertex(c, tk_curve_vertex_index(c, 1, i))[0] += 5.0;
    ck_assert_int_eq(lk_of(c, 0, 1), 0);
    tk_curve_free(&c);
    /* the linking number of a component with itself, or with one that
     * is not there, is refused */
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    long lk;
    tk_error err;
    ck_assert_int_eq(tk_linking_number(c, 0, 0, &lk, NULL, &err), TK_EINVAL);
    ck_assert_int_eq(tk_linking_number(c, 0, 2, &lk, NULL, &err), TK_EINVAL);
    tk_curve_free(&c);
}
END_TEST

START_TEST(catalogue_links)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("catalogue_links", "the catalogue is absent");
        return;
    }
    /* Rolfsen's table: the unlinks, the Hopf link, Solomon's link T(2,4),
     * the Whitehead link, T(2,6), the Borromean rings */
    const struct {
        const char *name;
        long lk; /* |lk| of every pair */
    } known[] = {{"0.2.1.vect", 0}, {"0.3.1.vect", 0}, {"2.2.1.vect", 1}, {"4.2.1.vect", 2},
                 {"5.2.1.vect", 0}, {"6.2.1.vect", 3}, {"6.3.2.vect", 0}};
    for (size_t k = 0; k < sizeof known / sizeof *known; k++) {
        tk_curve *c = tkt_catalogue_curve(known[k].name);
        for (size_t a = 0; a < c->ncomp; a++)
            for (size_t b = a + 1; b < c->ncomp; b++)
                ck_assert_msg(labs(lk_of(c, a, b)) == known[k].lk, "%s %zu %zu", known[k].name, a,
                              b);
        tk_curve_free(&c);
    }
    /* every link of the catalogue: an integer within rounding (lk_of) */
    size_t count = 0;
    char **names = tkt_catalogue_names(&count);
    size_t links = 0;
    for (size_t i = 0; i < count; i++) {
        tk_curve *c = tkt_catalogue_curve(names[i]);
        for (size_t a = 0; a < c->ncomp; a++)
            for (size_t b = a + 1; b < c->ncomp; b++)
                if (c->closed[a] && c->closed[b])
                    lk_of(c, a, b);
        links += c->ncomp > 1;
        tk_curve_free(&c);
    }
    tkt_free_names(names, count);
    ck_assert_uint_ge(links, 100);
}
END_TEST

static long long det_of(const tk_curve *c, size_t comp, unsigned long long seed)
{
    long long det = -1;
    size_t m = 0;
    tk_error err;
    ck_assert_msg(tk_knot_determinant(c, comp, seed, &det, &m, &err) == TK_OK, "%s", err.message);
    return det;
}

START_TEST(torus_knot_determinants)
{
    /* |Delta(-1)| of T(2, q) is q; of T(3, 4) (8_19) 3; of T(3, 5)
     * (10_124) 1; a round polygon is the unknot */
    const struct {
        int p, q;
        long long det;
    } known[] = {{2, 3, 3}, {2, 5, 5}, {2, 7, 7}, {2, 9, 9}, {3, 4, 3}, {3, 5, 1}};
    for (size_t k = 0; k < sizeof known / sizeof *known; k++) {
        tk_curve *c = NULL;
        ck_assert_int_eq(tk_generate_torus(known[k].p, known[k].q, 120, &c, NULL), TK_OK);
        for (unsigned long long seed = 1; seed <= 12; seed++)
            ck_assert_msg(det_of(c, 0, seed) == known[k].det, "T(%d,%d) seed %llu: %lld",
                          known[k].p, known[k].q, seed, det_of(c, 0, seed));
        tk_curve_free(&c);
    }
    /* a fine polygon: edges far shorter than the picture, many to a
     * cell of the projection's grid, every crossing found once */
    tk_curve *fine = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 11, 100000, &fine, NULL), TK_OK);
    for (unsigned long long seed = 1; seed <= 3; seed++)
        ck_assert_int_eq(det_of(fine, 0, seed), 11);
    tk_curve_free(&fine);
    tk_curve *round = tkt_regular_polygon(50, 3.0);
    ck_assert_int_eq(det_of(round, 0, 7), 1);
    tk_curve_free(&round);
}
END_TEST

START_TEST(catalogue_knot_determinants)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("catalogue_knot_determinants", "the catalogue is absent");
        return;
    }
    /* Rolfsen's table */
    const struct {
        const char *name;
        long long det;
    } known[] = {{"3.1.vect", 3},  {"4.1.vect", 5},  {"5.1.vect", 5},  {"5.2.vect", 7},
                 {"6.1.vect", 9},  {"6.2.vect", 11}, {"6.3.vect", 13}, {"7.1.vect", 7},
                 {"7.7.vect", 21}, {"8.18.vect", 45}, {"8.19.vect", 3}, {"10.124.vect", 1}};
    for (size_t k = 0; k < sizeof known / sizeof *known; k++) {
        tk_curve *c = tkt_catalogue_curve(known[k].name);
        for (unsigned long long seed = 1; seed <= 4; seed++)
            ck_assert_msg(det_of(c, 0, seed) == known[k].det, "%s seed %llu: %lld", known[k].name,
                          seed, det_of(c, 0, seed));
        tk_curve_free(&c);
    }
    /* every knot of the catalogue: the same from two projections, and odd
     * (the determinant of a knot always is) */
    size_t count = 0, knots = 0;
    char **names = tkt_catalogue_names(&count);
    for (size_t i = 0; i < count; i++) {
        tk_curve *c = tkt_catalogue_curve(names[i]);
        if (c->ncomp == 1 && c->closed[0]) {
            long long a = det_of(c, 0, 1), b = det_of(c, 0, 2);
            ck_assert_msg(a == b && a % 2 == 1, "%s: %lld and %lld", names[i], a, b);
            knots++;
        }
        tk_curve_free(&c);
    }
    tkt_free_names(names, count);
    ck_assert_uint_ge(knots, 250);
}
END_TEST

START_TEST(a_crossing_change_is_caught)
{
    /* The trefoil (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t) seen from
     * above has three crossings; lowering the over strand of one of them
     * below the other gives the unknot. */
    size_t n = 300;
    bool closed = true;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &closed, NULL), TK_OK);
    for (size_t i = 0; i < n; i++) {
        double t = 2.0 * M_PI * (double)i / (double)n;
        double *x = tk_curve_vertex(c, i);
        x[0] = sin(t) + 2.0 * sin(2.0 * t);
        x[1] = cos(t) - 2.0 * cos(2.0 * t);
        x[2] = -sin(3.0 * t);
    }
    ck_assert_int_eq(det_of(c, 0, 3), 3);
    /* the first crossing of the picture in the xy plane, by brute force */
    size_t over = n, under = n;
    for (size_t i = 0; i < n && over == n; i++)
        for (size_t j = i + 2; j < n && over == n; j++) {
            if (i == 0 && j == n - 1)
                continue;
            const double *a = tk_curve_vertex(c, i), *b = tk_curve_vertex(c, (i + 1) % n);
            const double *q = tk_curve_vertex(c, j), *d = tk_curve_vertex(c, (j + 1) % n);
            double rx = b[0] - a[0], ry = b[1] - a[1], sx = d[0] - q[0], sy = d[1] - q[1];
            double den = rx * sy - ry * sx;
            if (den == 0.0)
                continue;
            double s = ((q[0] - a[0]) * sy - (q[1] - a[1]) * sx) / den;
            double t = ((q[0] - a[0]) * ry - (q[1] - a[1]) * rx) / den;
            if (s > 0 && s < 1 && t > 0 && t < 1) {
                bool i_over = a[2] + s * (b[2] - a[2]) > q[2] + t * (d[2] - q[2]);
                over = i_over ? i : j;
                under = i_over ? j : i;
            }
        }
    ck_assert_uint_lt(over, n);
    /* push the over strand, a few edges either side, under the other */
    double floor = tk_curve_vertex(c, under)[2] - 1.0;
    for (long d = -4; d <= 5; d++) {
        double *x = tk_curve_vertex(c, (size_t)(((long)over + d + (long)n) % (long)n));
        x[2] = fmin(x[2], floor);
    }
    for (unsigned long long seed = 1; seed <= 6; seed++)
        ck_assert_int_eq(det_of(c, 0, seed), 1);
    tk_curve_free(&c);
}
END_TEST

/* The Alexander polynomial of T(p, q), (t^pq - 1)(t - 1) / ((t^p - 1)
 * (t^q - 1)), by exact long division: an independent reference. */
static int torus_alexander(int p, int q, long long *coeff)
{
    long long num[64] = {0}, den[64] = {0};
    /* (t^pq - 1)(t - 1) */
    num[p * q + 1] += 1;
    num[p * q] -= 1;
    num[1] -= 1;
    num[0] += 1;
    /* (t^p - 1)(t^q - 1) */
    den[p + q] += 1;
    den[p] -= 1;
    den[q] -= 1;
    den[0] += 1;
    int dn = p * q + 1, dd = p + q, dq = dn - dd;
    for (int i = dq; i >= 0; i--) {
        coeff[i] = num[i + dd]; /* den is monic */
        for (int j = 0; j <= dd; j++)
            num[i + j] -= coeff[i] * den[j];
    }
    for (int i = 0; i <= dn; i++)
        ck_assert_int_eq(num[i], 0); /* it divides */
    return dq;
}

static void assert_alexander(const tk_curve *c, size_t comp, const long long *want, int degree,
                             const char *what)
{
    long long got[TK_ALEXANDER_MAX_DEGREE + 1];
    int deg = -1;
    tk_error err;
    for (unsigned long long seed = 1; seed <= 3; seed++) {
        ck_assert_msg(tk_knot_alexander(c, comp, seed, got, &deg, NULL, &err) == TK_OK, "%s: %s",
                      what, err.message);
        ck_assert_msg(deg == degree, "%s seed %llu: degree %d, not %d", what, seed, deg, degree);
        for (int i = 0; i <= degree; i++)
            ck_assert_msg(got[i] == want[i], "%s seed %llu: coefficient %d is %lld, not %lld",
                          what, seed, i, got[i], want[i]);
    }
}

START_TEST(torus_knot_alexander_polynomials)
{
    const int pq[][2] = {{2, 3}, {2, 5}, {2, 7}, {3, 4}, {3, 5}, {2, 9}, {3, 7}};
    for (size_t k = 0; k < sizeof pq / sizeof *pq; k++) {
        long long want[64];
        int degree = torus_alexander(pq[k][0], pq[k][1], want);
        tk_curve *c = NULL;
        ck_assert_int_eq(tk_generate_torus(pq[k][0], pq[k][1], 0, &c, NULL), TK_OK);
        char what[64];
        snprintf(what, sizeof what, "T(%d,%d)", pq[k][0], pq[k][1]);
        assert_alexander(c, 0, want, degree, what);
        /* the same knot from another start */
        tk_curve *d = NULL;
        ck_assert_int_eq(tk_generate_disguise(c, 40 + k, 0.05, &d, NULL), TK_OK);
        assert_alexander(d, 0, want, degree, what);
        tk_curve_free(&d);
        tk_curve_free(&c);
    }
    /* the figure-eight: -1 + 3t - t^2, also mirrored */
    const long long eight[] = {-1, 3, -1};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_figure_eight(48, &c, NULL), TK_OK);
    assert_alexander(c, 0, eight, 2, "figure-eight at 48 vertices");
    for (size_t v = 0; v < c->nvert; v++)
        tk_curve_vertex(c, v)[2] *= -1.0;
    assert_alexander(c, 0, eight, 2, "mirrored figure-eight");
    tk_curve_free(&c);
    /* Lissajous knots: 6_1 (2 - 5t + 2t^2, at two counts and disguised)
     * and 5_2 (2 - 3t + 2t^2) */
    const int f325[3] = {3, 2, 5}, f327[3] = {3, 2, 7};
    const double p6[3] = {0.7, 0.2, 0.0}, p5[3] = {0.7, 0.7, 0.0};
    const long long six[] = {-2, 5, -2}, five[] = {2, -3, 2};
    ck_assert_int_eq(tk_generate_lissajous(f325, p6, 0, &c, NULL), TK_OK);
    assert_alexander(c, 0, six, 2, "Lissajous (3, 2, 5)");
    tk_curve *d = NULL;
    ck_assert_int_eq(tk_generate_disguise(c, 47, 0.05, &d, NULL), TK_OK);
    assert_alexander(d, 0, six, 2, "Lissajous (3, 2, 5) disguised");
    tk_curve_free(&d);
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_lissajous(f325, p6, 60, &c, NULL), TK_OK);
    assert_alexander(c, 0, six, 2, "Lissajous (3, 2, 5) at 60 vertices");
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_lissajous(f327, p5, 0, &c, NULL), TK_OK);
    assert_alexander(c, 0, five, 2, "Lissajous (3, 2, 7)");
    tk_curve_free(&c);
    tk_curve *round = tkt_regular_polygon(40, 2.0);
    const long long one[] = {1};
    assert_alexander(round, 0, one, 0, "a round polygon");
    tk_curve_free(&round);
}
END_TEST

START_TEST(catalogue_alexander_polynomials)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("catalogue_alexander_polynomials", "the catalogue is absent");
        return;
    }
    /* Rolfsen's table, normalised to Delta(1) = 1 */
    const struct {
        const char *name;
        int degree;
        long long coeff[5];
    } known[] = {{"5.2.vect", 2, {2, -3, 2}},
                 {"6.1.vect", 2, {-2, 5, -2}},
                 {"6.2.vect", 4, {-1, 3, -3, 3, -1}},
                 {"6.3.vect", 4, {1, -3, 5, -3, 1}},
                 {"7.2.vect", 2, {3, -5, 3}}};
    for (size_t k = 0; k < sizeof known / sizeof *known; k++) {
        tk_curve *c = tkt_catalogue_curve(known[k].name);
        assert_alexander(c, 0, known[k].coeff, known[k].degree, known[k].name);
        tk_curve_free(&c);
    }
    /* Every closed component of the catalogue: |Delta(-1)| is the
     * determinant found from the colouring matrix (another matrix, another
     * arithmetic). */
    size_t count = 0, components = 0;
    char **names = tkt_catalogue_names(&count);
    for (size_t i = 0; i < count; i++) {
        tk_curve *c = tkt_catalogue_curve(names[i]);
        tk_invariants inv = TK_INVARIANTS_INIT;
        tk_error err;
        ck_assert_msg(tk_invariants_compute(c, &inv, &err) == TK_OK, "%s: %s", names[i],
                      err.message);
        ck_assert_msg(inv.complete, "%s", names[i]);
        for (size_t a = 0; a < c->ncomp; a++) {
            if (!c->closed[a])
                continue;
            ck_assert_msg(inv.knot[a].determinant == det_of(c, a, 5), "%s component %zu",
                          names[i], a);
            components++;
        }
        tk_invariants_free(&inv);
        tk_curve_free(&c);
    }
    tkt_free_names(names, count);
    ck_assert_uint_ge(components, 398);
}
END_TEST

START_TEST(the_type_record)
{
    tk_curve *c = NULL;
    tk_invariants was = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
    tk_error err;
    /* the Borromean rings: unknotted, unlinked pairwise */
    ck_assert_int_eq(tk_generate_borromean(60, &c, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(c, &was, &err), TK_OK);
    ck_assert_uint_eq(was.ncomp, 3);
    for (size_t a = 0; a < 3; a++) {
        ck_assert(was.knot[a].known);
        ck_assert_int_eq(was.knot[a].degree, 0);
        ck_assert_int_eq(was.knot[a].determinant, 1);
        for (size_t b = 0; b < 3; b++)
            ck_assert_int_eq(was.linking[a * 3 + b], 0);
    }
    tk_curve_free(&c);
    /* the Hopf link, disguised: the same type */
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(c, &was, &err), TK_OK);
    ck_assert_int_eq(labs(was.linking[1]), 1);
    ck_assert_int_eq(was.linking[1], was.linking[2]);
    tk_curve *d = NULL;
    ck_assert_int_eq(tk_generate_disguise(c, 3, 0.05, &d, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(d, &now, &err), TK_OK);
    ck_assert_int_eq(tk_invariants_compare(&was, &now, &err), TK_OK);
    /* one ring reversed: the linking number changes sign, and is caught */
    size_t n = tk_curve_comp_vertices(d, 1);
    double *x = d->xyz + 3 * d->offset[1];
    for (size_t i = 0, j = n - 1; i < j; i++, j--)
        for (int k = 0; k < 3; k++) {
            double t = x[3 * i + k];
            x[3 * i + k] = x[3 * j + k];
            x[3 * j + k] = t;
        }
    ck_assert_int_eq(tk_invariants_compute(d, &now, &err), TK_OK);
    ck_assert_int_eq(tk_invariants_compare(&was, &now, &err), TK_ETYPE);
    ck_assert_msg(strstr(err.message, "linking number of components 0 and 1 was") != NULL, "%s",
                  err.message);
    tk_curve_free(&d);
    tk_curve_free(&c);
    /* the trefoil against the unknot */
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(c, &was, &err), TK_OK);
    tk_curve *round = tkt_regular_polygon(40, 2.0);
    ck_assert_int_eq(tk_invariants_compute(round, &now, &err), TK_OK);
    ck_assert_int_eq(tk_invariants_compare(&was, &now, &err), TK_ETYPE);
    ck_assert_str_eq(err.message, "the knot type of component 0 changed: its Alexander "
                                  "polynomial was 1 - t + t^2, now 1");
    tk_curve_free(&round);
    tk_curve_free(&c);
    tk_invariants_free(&was);
    tk_invariants_free(&now);
}
END_TEST

/* The determinant of a whole link (tk_link_determinant) against Rolfsen's
 * table and exact values: T(2, n) has n, a chain of k rings (a connected
 * sum of k - 1 Hopf links) 2^(k - 1), the Borromean rings 16, a split
 * link 0; the same from every projection (seed), mirrored and moved; a
 * knot's is its own determinant. */
static long long link_det_of(const tk_curve *c, unsigned long long seed)
{
    long long det = -1;
    size_t m = 0;
    tk_error err;
    ck_assert_msg(tk_link_determinant(c, seed, &det, &m, &err) == TK_OK, "%s", err.message);
    return det;
}

START_TEST(link_determinants)
{
    tk_curve *c = NULL;
    for (int n = 2; n <= 8; n++) {
        ck_assert_int_eq(tk_generate_torus(2, n, 24 * n, &c, NULL), TK_OK);
        for (unsigned long long seed = 1; seed <= 3; seed++)
            ck_assert_int_eq(link_det_of(c, seed), n);
        if (c->ncomp == 1) {
            long long det = 0;
            tk_error err;
            ck_assert_int_eq(tk_knot_determinant(c, 0, 7, &det, NULL, &err), TK_OK);
            ck_assert_int_eq(link_det_of(c, 7), det);
        }
        tk_curve_free(&c);
    }
    for (size_t k = 2; k <= 5; k++) {
        ck_assert_int_eq(tk_generate_chain(k, 32, &c, NULL), TK_OK);
        ck_assert_int_eq(link_det_of(c, 1), 1LL << (k - 1));
        tk_curve_free(&c);
    }
    ck_assert_int_eq(tk_generate_borromean(60, &c, NULL), TK_OK);
    ck_assert_int_eq(link_det_of(c, 1), 16);
    /* one ring moved far off along z: a split link, whatever is above */
    size_t n = tk_curve_comp_vertices(c, 2);
    for (size_t i = 0; i < n; i++)
        c->xyz[3 * (c->offset[2] + i) + 2] += 10.0;
    for (unsigned long long seed = 1; seed <= 3; seed++)
        ck_assert_int_eq(link_det_of(c, seed), 0);
    tk_curve_free(&c);
    /* the Hopf link mirrored, rotated and disguised */
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    for (size_t i = 0; i < c->nvert; i++)
        c->xyz[3 * i] = -c->xyz[3 * i];
    tk_curve *d = NULL;
    ck_assert_int_eq(tk_generate_disguise(c, 5, 0.05, &d, NULL), TK_OK);
    ck_assert_int_eq(link_det_of(d, 2), 2);
    tk_curve_free(&d);
    tk_curve_free(&c);
    if (!tkt_catalogue_dir()) {
        tkt_skip("link_determinants (the catalogue's)", "the catalogue is absent");
        return;
    }
    const struct {
        const char *name;
        long long det;
    } known[] = {{"0.2.1.vect", 0}, {"0.3.1.vect", 0}, {"2.2.1.vect", 2}, {"4.2.1.vect", 4},
                 {"5.2.1.vect", 8}, {"6.2.1.vect", 6}, {"6.2.2.vect", 10}, {"6.2.3.vect", 12},
                 {"6.3.2.vect", 16}};
    for (size_t k = 0; k < sizeof known / sizeof *known; k++) {
        c = tkt_catalogue_curve(known[k].name);
        for (unsigned long long seed = 1; seed <= 3; seed++)
            ck_assert_msg(link_det_of(c, seed) == known[k].det, "%s seed %llu: %lld", known[k].name,
                          seed, link_det_of(c, seed));
        tk_curve_free(&c);
    }
    /* every closed link of the catalogue: one value from three projections */
    size_t count = 0, links = 0;
    char **names = tkt_catalogue_names(&count);
    for (size_t i = 0; i < count; i++) {
        c = tkt_catalogue_curve(names[i]);
        bool closed = c->ncomp > 1;
        for (size_t a = 0; a < c->ncomp; a++)
            closed = closed && c->closed[a];
        if (closed) {
            long long first = link_det_of(c, 1);
            ck_assert_msg(link_det_of(c, 2) == first && link_det_of(c, 3) == first, "%s",
                          names[i]);
            links++;
        }
        tk_curve_free(&c);
    }
    tkt_free_names(names, count);
    ck_assert_uint_ge(links, 100);
}
END_TEST

/* Catalogue 6.2.3 and the (2, 4) torus link have two unknotted
 * components and linking number 2, as 6.2.2 and T(2, 6) have with
 * linking number 3: only the link's determinant (12 against 4, 10
 * against 6) tells them apart, and the type check must. */
START_TEST(links_that_only_the_link_determinant_tells_apart)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("links_that_only_the_link_determinant_tells_apart", "the catalogue is absent");
        return;
    }
    const char *pairs[][2] = {{"6.2.3.vect", "4.2.1.vect"}, {"6.2.2.vect", "6.2.1.vect"}};
    for (size_t k = 0; k < 2; k++) {
        tk_curve *a = tkt_catalogue_curve(pairs[k][0]), *b = tkt_catalogue_curve(pairs[k][1]);
        tk_invariants was = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
        tk_error err;
        ck_assert_int_eq(tk_invariants_compute(a, &was, &err), TK_OK);
        ck_assert_int_eq(tk_invariants_compute(b, &now, &err), TK_OK);
        ck_assert(was.link_known && now.link_known);
        ck_assert_int_eq(labs(was.linking[1]), labs(now.linking[1]));
        ck_assert_int_eq(tk_invariants_compare(&was, &now, &err), TK_ETYPE);
        ck_assert_msg(strstr(err.message, "the link type changed: its determinant was") != NULL,
                      "%s", err.message);
        tk_invariants_free(&was);
        tk_invariants_free(&now);
        tk_curve_free(&a);
        tk_curve_free(&b);
    }
    /* 6.2.3 resampled to 12 and 13 vertices: the coarse polygon's chords
     * cut through a strand, and it is the (2, 4) torus link, with the
     * same components and linking number (a loose level of a run did
     * this, and ended at T(2,4)'s ropelength) */
    tk_curve *c = tkt_catalogue_curve("6.2.3.vect");
    tk_invariants was = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
    tk_error err;
    ck_assert_int_eq(tk_invariants_compute(c, &was, &err), TK_OK);
    ck_assert_int_eq(was.link_determinant, 12);
    for (size_t n = 12; n <= 13; n++) {
        tk_curve *coarse = NULL;
        ck_assert_int_eq(tk_curve_resample_total(c, n, &coarse, &err), TK_OK);
        ck_assert_int_eq(tk_invariants_compute(coarse, &now, &err), TK_OK);
        ck_assert_int_eq(now.linking[1], was.linking[1]);
        ck_assert_int_eq(now.knot[0].determinant, 1);
        ck_assert_int_eq(now.knot[1].determinant, 1);
        ck_assert_int_eq(now.link_determinant, 4);
        ck_assert_int_eq(tk_invariants_compare(&was, &now, &err), TK_ETYPE);
        ck_assert_str_eq(err.message, "the link type changed: its determinant was 12, now 4");
        tk_curve_free(&coarse);
    }
    tk_invariants_free(&was);
    tk_invariants_free(&now);
    tk_curve_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("invariants");
    TCase *tc = tcase_create("linking");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, hopf_and_torus_links);
    tcase_add_test(tc, chains_and_borromean_rings);
    tcase_add_test(tc, orientation_mirror_and_motion);
    tcase_add_test(tc, a_strand_passage_is_caught);
    tcase_add_test(tc, catalogue_links);
    suite_add_tcase(s, tc);
    TCase *knots = tcase_create("determinant");
    tcase_set_timeout(knots, 60);
    tcase_add_test(knots, torus_knot_determinants);
    tcase_add_test(knots, catalogue_knot_determinants);
    tcase_add_test(knots, a_crossing_change_is_caught);
    tcase_add_test(knots, torus_knot_alexander_polynomials);
    tcase_add_test(knots, catalogue_alexander_polynomials);
    tcase_add_test(knots, the_type_record);
    tcase_add_test(knots, link_determinants);
    tcase_add_test(knots, links_that_only_the_link_determinant_tells_apart);
    suite_add_tcase(s, knots);
    return tkt_run_suite(s);
}
