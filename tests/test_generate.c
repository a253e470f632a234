/* Unit tests of the example generators (engine/generate.c): counts,
 * closedness, exact geometry of the Hopf circles, separation of
 * components, linking numbers against the known values, argument errors. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/pin.h"
#include "tk/invariants.h"
#include "tk/thickness.h"

static double dist3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Every closed, valid, with the expected shape. */
static void check_shape(const tk_curve *c, size_t ncomp, size_t per_comp)
{
    tk_error err;
    ck_assert_int_eq(tk_curve_validate(c, &err), TK_OK);
    ck_assert_uint_eq(c->ncomp, ncomp);
    ck_assert_uint_eq(c->nvert, ncomp * per_comp);
    for (size_t i = 0; i < c->ncomp; i++) {
        ck_assert(c->closed[i]);
        ck_assert_uint_eq(tk_curve_comp_vertices(c, i), per_comp);
    }
}

/* Smallest distance between two vertices of different components
 * (brute force: the curves here are small). */
static double min_between_components(const tk_curve *c)
{
    double best = INFINITY;
    for (size_t a = 0; a < c->ncomp; a++)
        for (size_t b = a + 1; b < c->ncomp; b++)
            for (size_t i = c->offset[a]; i < c->offset[a + 1]; i++)
                for (size_t j = c->offset[b]; j < c->offset[b + 1]; j++)
                    best = fmin(best, dist3(tk_curve_vertex(c, i), tk_curve_vertex(c, j)));
    return best;
}

/* Smallest distance between two vertices of one component that are not
 * neighbours along it. */
static double min_non_neighbours(const tk_curve *c)
{
    double best = INFINITY;
    for (size_t k = 0; k < c->ncomp; k++) {
        size_t n = tk_curve_comp_vertices(c, k);
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 2; j < n; j++) {
                if (i == 0 && j == n - 1)
                    continue;
                best = fmin(best, dist3(tk_curve_vertex(c, c->offset[k] + i),
                                        tk_curve_vertex(c, c->offset[k] + j)));
            }
    }
    return best;
}

/* Linking number of components a and b: half the signed count of the
 * crossings between them in a projection along a direction that no edge
 * of these symmetric curves is parallel to. */
static int linking_number(const tk_curve *c, size_t a, size_t b)
{
    const double d[3] = {0.2672612419124244, 0.5345224838248488, 0.8017837257372732};
    double u[3] = {d[1], -d[0], 0.0}; /* perpendicular to d */
    double nu = sqrt(u[0] * u[0] + u[1] * u[1]);
    for (int k = 0; k < 3; k++)
        u[k] /= nu;
    double v[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2],
                   d[0] * u[1] - d[1] * u[0]};
    int twice = 0;
    size_t na = tk_curve_comp_vertices(c, a), nb = tk_curve_comp_vertices(c, b);
    for (size_t i = 0; i < na; i++) {
        const double *p0 = tk_curve_vertex(c, tk_curve_vertex_index(c, a, i));
        const double *p1 = tk_curve_vertex(c, tk_curve_vertex_index(c, a, i + 1));
        for (size_t j = 0; j < nb; j++) {
            const double *q0 = tk_curve_vertex(c, tk_curve_vertex_index(c, b, j));
            const double *q1 = tk_curve_vertex(c, tk_curve_vertex_index(c, b, j + 1));
            double P0[2], P1[2], Q0[2], Q1[2];
            P0[0] = p0[0] * u[0] + p0[1] * u[1] + p0[2] * u[2];
            P0[1] = p0[0] * v[0] + p0[1] * v[1] + p0[2] * v[2];
            P1[0] = p1[0] * u[0] + p1[1] * u[1] + p1[2] * u[2];
            P1[1] = p1[0] * v[0] + p1[1] * v[1] + p1[2] * v[2];
            Q0[0] = q0[0] * u[0] + q0[1] * u[1] + q0[2] * u[2];
            Q0[1] = q0[0] * v[0] + q0[1] * v[1] + q0[2] * v[2];
            Q1[0] = q1[0] * u[0] + q1[1] * u[1] + q1[2] * u[2];
            Q1[1] = q1[0] * v[0] + q1[1] * v[1] + q1[2] * v[2];
            double r[2] = {P1[0] - P0[0], P1[1] - P0[1]};
            double s[2] = {Q1[0] - Q0[0], Q1[1] - Q0[1]};
            double den = r[0] * s[1] - r[1] * s[0];
            if (den == 0.0)
                continue;
            double w[2] = {Q0[0] - P0[0], Q0[1] - P0[1]};
            double ts = (w[0] * s[1] - w[1] * s[0]) / den; /* along p */
            double tq = (w[0] * r[1] - w[1] * r[0]) / den; /* along q */
            if (ts < 0.0 || ts >= 1.0 || tq < 0.0 || tq >= 1.0)
                continue;
            double hp = 0.0, hq = 0.0;
            for (int k = 0; k < 3; k++) {
                hp += (p0[k] + ts * (p1[k] - p0[k])) * d[k];
                hq += (q0[k] + tq * (q1[k] - q0[k])) * d[k];
            }
            ck_assert_msg(fabs(hp - hq) > 1e-9, "components %zu and %zu meet", a, b);
            int sign = den > 0.0 ? 1 : -1;
            twice += hp > hq ? sign : -sign;
        }
    }
    ck_assert_msg(twice % 2 == 0, "odd crossing count between %zu and %zu", a, b);
    return twice / 2;
}

static tk_curve *torus(int p, int q, size_t vertices)
{
    tk_curve *c = NULL;
    tk_error err;
    int rc = tk_generate_torus(p, q, vertices, &c, &err);
    ck_assert_msg(rc == TK_OK, "T(%d,%d): %s", p, q, err.message);
    return c;
}

START_TEST(torus_counts)
{
    tk_curve *c = torus(2, 3, 0);
    check_shape(c, 1, tk_curve_comp_vertices(c, 0));
    ck_assert_uint_ge(c->nvert, 60);
    tk_curve_free(&c);

    c = torus(2, 3, 100);
    check_shape(c, 1, 100);
    tk_curve_free(&c);

    c = torus(2, 4, 90);
    check_shape(c, 2, 90);
    tk_curve_free(&c);

    c = torus(3, 6, 0);
    check_shape(c, 3, tk_curve_comp_vertices(c, 0));
    tk_curve_free(&c);

    c = torus(6, 4, 0);
    check_shape(c, 2, tk_curve_comp_vertices(c, 0));
    tk_curve_free(&c);

    /* T(1, q) and T(p, 1) are unknots, allowed. */
    c = torus(1, 1, 0);
    check_shape(c, 1, 60);
    tk_curve_free(&c);
    c = torus(5, 1, 0);
    check_shape(c, 1, tk_curve_comp_vertices(c, 0));
    tk_curve_free(&c);
}
END_TEST

/* Every vertex is on the torus of radii 2 and 1. */
START_TEST(torus_on_torus)
{
    const int pq[][2] = {{2, 3}, {3, 2}, {2, 4}, {3, 6}, {5, 3}, {4, 6}};
    for (size_t t = 0; t < sizeof pq / sizeof pq[0]; t++) {
        tk_curve *c = torus(pq[t][0], pq[t][1], 0);
        for (size_t v = 0; v < c->nvert; v++) {
            const double *x = tk_curve_vertex(c, v);
            double rho = hypot(x[0], x[1]) - 2.0;
            ck_assert_double_eq_tol(rho * rho + x[2] * x[2], 1.0, 1e-12);
        }
        tk_curve_free(&c);
    }
}
END_TEST

/* Components are apart, strands keep away from themselves, and the
 * components of T(g p', g q') link p' q' times. */
START_TEST(torus_embedded_and_linked)
{
    const int pq[][2] = {{2, 3}, {3, 4}, {2, 5}, {2, 4}, {3, 6}, {4, 6}, {6, 4}, {4, 4}};
    for (size_t t = 0; t < sizeof pq / sizeof pq[0]; t++) {
        int p = pq[t][0], q = pq[t][1];
        tk_curve *c = torus(p, q, 0);
        double sep = min_non_neighbours(c);
        ck_assert_msg(sep > 0.1, "T(%d,%d): non-neighbours %g apart", p, q, sep);
        if (c->ncomp > 1) {
            double apart = min_between_components(c);
            ck_assert_msg(apart > 0.1, "T(%d,%d): components %g apart", p, q, apart);
            int g = (int)c->ncomp;
            int want = (p / g) * (q / g);
            for (size_t a = 0; a < c->ncomp; a++)
                for (size_t b = a + 1; b < c->ncomp; b++)
                    ck_assert_int_eq(abs(linking_number(c, a, b)), want);
        }
        tk_curve_free(&c);
    }
}
END_TEST

/* At the smallest count allowed the polygon is still embedded. */
START_TEST(torus_minimum_count)
{
    tk_curve *c = NULL;
    tk_error err;
    /* T(2,3) must refuse 5 vertices (a pentagon cannot be a trefoil). */
    ck_assert_int_eq(tk_generate_torus(2, 3, 5, &c, &err), TK_EINVAL);
    ck_assert_ptr_null(c);
    size_t n = 5;
    while (tk_generate_torus(2, 3, n, &c, NULL) != TK_OK)
        n++;
    ck_assert_uint_le(n, 60);
    ck_assert_double_gt(min_non_neighbours(c), 0.1);
    tk_curve_free(&c);
    n = 3;
    while (tk_generate_torus(4, 6, n, &c, NULL) != TK_OK)
        n++;
    ck_assert_double_gt(min_between_components(c), 0.05);
    ck_assert_int_eq(abs(linking_number(c, 0, 1)), 6);
    tk_curve_free(&c);
}
END_TEST

START_TEST(hopf_geometry)
{
    const size_t counts[] = {0, 4, 8, 33, 64, 1000};
    for (size_t t = 0; t < sizeof counts / sizeof counts[0]; t++) {
        tk_curve *c = NULL;
        tk_error err;
        ck_assert_int_eq(tk_generate_hopf(counts[t], &c, &err), TK_OK);
        size_t n = tk_curve_comp_vertices(c, 0);
        if (counts[t] == 0)
            ck_assert_uint_eq(n, 64);
        else /* odd counts round up to even */
            ck_assert_uint_eq(n, counts[t] + counts[t] % 2);
        check_shape(c, 2, n);
        const double ca[3] = {0, 0, 0}, cb[3] = {1, 0, 0};
        bool a_at_b = false, b_at_a = false;
        for (size_t i = 0; i < n; i++) {
            const double *a = tk_curve_vertex(c, i);
            const double *b = tk_curve_vertex(c, n + i);
            ck_assert_double_eq_tol(dist3(a, ca), 1.0, 1e-14);
            ck_assert_double_eq_tol(dist3(b, cb), 1.0, 1e-14);
            ck_assert_double_eq(a[2], 0.0); /* A in the xy plane */
            ck_assert_double_eq(b[1], 0.0); /* B in the xz plane */
            a_at_b |= a[0] == 1.0 && a[1] == 0.0 && a[2] == 0.0;
            b_at_a |= b[0] == 0.0 && b[1] == 0.0 && b[2] == 0.0;
        }
        ck_assert_msg(a_at_b, "no vertex of A at B's centre (n = %zu)", n);
        ck_assert_msg(b_at_a, "no vertex of B at A's centre (n = %zu)", n);
        /* Inscribed regular n-gon of radius 1. */
        double want = 2.0 * (double)n * sin(M_PI / (double)n);
        ck_assert_double_eq_tol(tk_curve_comp_length(c, 0), want, 1e-12);
        ck_assert_double_eq_tol(tk_curve_comp_length(c, 1), want, 1e-12);
        ck_assert_double_gt(min_between_components(c), 0.1);
        ck_assert_int_eq(abs(linking_number(c, 0, 1)), 1);
        tk_curve_free(&c);
    }
}
END_TEST

/* Length tends to 2 pi from below, monotonically. */
START_TEST(hopf_length_converges)
{
    double prev = 0.0;
    for (size_t n = 4; n <= 4096; n *= 2) {
        tk_curve *c = NULL;
        ck_assert_int_eq(tk_generate_hopf(n, &c, NULL), TK_OK);
        double l = tk_curve_comp_length(c, 0);
        ck_assert_double_gt(l, prev);
        ck_assert_double_lt(l, 2.0 * M_PI);
        /* 2 pi - 2 n sin(pi / n) ~ pi^3 / (3 n^2) */
        ck_assert_double_lt(2.0 * M_PI - l, 4.0 * pow(M_PI, 3) / (3.0 * (double)(n * n)));
        prev = l;
        tk_curve_free(&c);
    }
    ck_assert_double_eq_tol(prev, 2.0 * M_PI, 1e-5);
}
END_TEST

/* The clasp: two open ropes of n vertices, their ends on the planes
 * z = 2.5 and z = -2.5, each rope in its own plane, more than 1.5 apart,
 * its length that of two legs of 2.5 - 0.5 and a half circle of radius
 * 1.5 a rope, less what the chords cut. */
START_TEST(clasp_ropes)
{
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_clasp(0, &c, &err), TK_OK);
    ck_assert_int_eq(tk_curve_validate(c, &err), TK_OK);
    ck_assert_uint_eq(c->ncomp, 2);
    for (size_t k = 0; k < 2; k++) {
        ck_assert(!c->closed[k]);
        ck_assert_uint_eq(tk_curve_comp_vertices(c, k), 64);
        for (size_t v = c->offset[k]; v < c->offset[k + 1]; v++)
            ck_assert_double_eq(tk_curve_vertex(c, v)[k ? 0 : 1], 0.0);
    }
    ck_assert_uint_eq(c->npins, 4);
    for (size_t i = 0; i < 4; i++) {
        ck_assert_int_eq(c->pins[i].kind, TK_PIN_PLANE);
        ck_assert_double_eq(tk_pin_distance(c, &c->pins[i]), 0.0);
        ck_assert_double_eq(c->pins[i].normal[2], c->pins[i].comp ? -1.0 : 1.0);
    }
    ck_assert_double_gt(min_between_components(c), 1.5);
    /* the polygon's length: the legs' 14 and the chords of the half circles */
    double length = 0.0;
    for (size_t k = 0; k < 2; k++)
        for (size_t v = c->offset[k] + 1; v < c->offset[k + 1]; v++)
            length += dist3(tk_curve_vertex(c, v - 1), tk_curve_vertex(c, v));
    ck_assert_double_lt(length, 2.0 * (4.0 + 1.5 * M_PI));
    ck_assert_double_gt(length, 2.0 * (4.0 + 1.5 * M_PI) - 0.01);
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_clasp(15, &c, &err), TK_EINVAL);
    ck_assert_ptr_null(c);
    ck_assert_int_eq(tk_generate_clasp(6000000, &c, &err), TK_ELIMIT);
}
END_TEST

START_TEST(borromean_rings)
{
    const size_t counts[] = {0, 3, 4, 7, 96};
    for (size_t t = 0; t < sizeof counts / sizeof counts[0]; t++) {
        tk_curve *c = NULL;
        tk_error err;
        ck_assert_int_eq(tk_generate_borromean(counts[t], &c, &err), TK_OK);
        check_shape(c, 3, counts[t] ? counts[t] : 96);
        /* The smooth ellipses stay sqrt(2/3) apart. */
        ck_assert_double_gt(min_between_components(c), 0.1);
        for (size_t a = 0; a < 3; a++)
            for (size_t b = a + 1; b < 3; b++)
                ck_assert_int_eq(linking_number(c, a, b), 0);
        tk_curve_free(&c);
    }
    /* The first ring is the ellipse (2 cos t, sin t, 0). */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_borromean(8, &c, NULL), TK_OK);
    const double *v = tk_curve_vertex(c, 0);
    ck_assert_double_eq(v[0], 2.0);
    ck_assert_double_eq(v[1], 0.0);
    v = tk_curve_vertex(c, 2);
    ck_assert_double_eq(v[0], 0.0);
    ck_assert_double_eq(v[1], 1.0);
    tk_curve_free(&c);
}
END_TEST

START_TEST(chain_rings)
{
    for (size_t k = 1; k <= 5; k++) {
        tk_curve *c = NULL;
        tk_error err;
        ck_assert_int_eq(tk_generate_chain(k, 0, &c, &err), TK_OK);
        check_shape(c, k, 64);
        for (size_t r = 0; r < k; r++) {
            const double centre[3] = {1.5 * (double)r, 0.0, 0.0};
            for (size_t i = c->offset[r]; i < c->offset[r + 1]; i++) {
                const double *x = tk_curve_vertex(c, i);
                ck_assert_double_eq_tol(dist3(x, centre), 1.0, 1e-14);
                ck_assert_double_eq(x[r % 2 == 0 ? 2 : 1], 0.0);
            }
        }
        if (k > 1)
            ck_assert_double_gt(min_between_components(c), 0.1);
        for (size_t a = 0; a < k; a++)
            for (size_t b = a + 1; b < k; b++)
                ck_assert_int_eq(abs(linking_number(c, a, b)), b == a + 1 ? 1 : 0);
        tk_curve_free(&c);
    }
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(3, 4, &c, NULL), TK_OK);
    check_shape(c, 3, 4);
    ck_assert_int_eq(abs(linking_number(c, 0, 1)), 1);
    tk_curve_free(&c);
}
END_TEST

START_TEST(invalid_arguments)
{
    tk_curve *c = NULL;
    tk_error err;
    tk_error_clear(&err);
    ck_assert_int_eq(tk_generate_torus(0, 3, 0, &c, &err), TK_EINVAL);
    ck_assert_ptr_null(c);
    ck_assert_int_eq(err.code, TK_EINVAL);
    ck_assert(err.message[0] != '\0');
    ck_assert_int_eq(tk_generate_torus(2, -1, 0, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_torus(2, 3, 2, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_torus(2, 3, 10000001, &c, &err), TK_ELIMIT);
    /* A million components of the default count pass the limit. */
    ck_assert_int_eq(tk_generate_torus(1000000, 1000000, 0, &c, &err), TK_ELIMIT);
    ck_assert_int_eq(tk_generate_torus(2147483647, 2, 0, &c, &err), TK_ELIMIT);
    ck_assert_ptr_null(c);

    ck_assert_int_eq(tk_generate_hopf(1, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_hopf(2, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_hopf(6000000, &c, &err), TK_ELIMIT);
    ck_assert_int_eq(tk_generate_hopf((size_t)-1, &c, &err), TK_ELIMIT);
    ck_assert_int_eq(tk_generate_borromean(2, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_borromean(4000000, &c, &err), TK_ELIMIT);
    ck_assert_int_eq(tk_generate_chain(0, 0, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_chain(2, 2, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_chain(2, 3, &c, &err), TK_EINVAL); /* triangles do not link */
    ck_assert_int_eq(tk_generate_chain(1000000, 0, &c, &err), TK_ELIMIT);
    /* More components than the VECT reader takes by default. */
    ck_assert_int_eq(tk_generate_chain(10001, 4, &c, &err), TK_ELIMIT);
    ck_assert_int_eq(tk_generate_torus(10001, 10001, 3, &c, &err), TK_ELIMIT);
    ck_assert_int_eq(err.code, TK_ELIMIT);
    ck_assert_ptr_null(c);
    /* A NULL error is allowed. */
    ck_assert_int_eq(tk_generate_chain(0, 0, &c, NULL), TK_EINVAL);
}
END_TEST

/* The Lissajous knot: each vertex on the curve at its parameter (against
 * cos from libm), the default count 60 a turn of the fastest angle, and
 * the curves it must refuse: frequencies not coprime, too few vertices,
 * phases that make it retrace itself (all 0: K(-t) = K(t)) or are not
 * finite. */
START_TEST(lissajous_curve)
{
    const int freq[3] = {3, 2, 5};
    const double phase[3] = {0.7, 0.2, 0.0};
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_lissajous(freq, phase, 0, &c, &err), TK_OK);
    ck_assert_uint_eq(c->nvert, 300);
    ck_assert_uint_eq(c->ncomp, 1);
    ck_assert(c->closed[0]);
    for (size_t i = 0; i < c->nvert; i++) {
        double t = 2.0 * M_PI * (double)i / 300.0;
        for (int k = 0; k < 3; k++)
            ck_assert_msg(fabs(tk_curve_vertex(c, i)[k] - cos(freq[k] * t + phase[k])) < 1e-14,
                          "vertex %zu coordinate %d", i, k);
    }
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_lissajous(freq, phase, 60, &c, &err), TK_OK);
    ck_assert_uint_eq(c->nvert, 60);
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_lissajous(freq, phase, 59, &c, &err), TK_EINVAL);
    ck_assert_int_eq(tk_generate_lissajous(freq, phase, 10001, &c, &err), TK_ELIMIT);
    ck_assert_ptr_null(c);
    const int shared[3] = {3, 2, 6}, zero[3] = {0, 2, 5};
    ck_assert_int_eq(tk_generate_lissajous(shared, phase, 0, &c, &err), TK_EINVAL);
    ck_assert_ptr_nonnull(strstr(err.message, "coprime"));
    ck_assert_int_eq(tk_generate_lissajous(zero, phase, 0, &c, &err), TK_EINVAL);
    const double still[3] = {0.0, 0.0, 0.0}, bad[3] = {0.7, NAN, 0.0};
    ck_assert_int_eq(tk_generate_lissajous(freq, still, 0, &c, &err), TK_EINVAL);
    ck_assert_ptr_nonnull(strstr(err.message, "passes through itself"));
    ck_assert_int_eq(tk_generate_lissajous(freq, bad, 0, &c, &err), TK_EINVAL);
    ck_assert_ptr_null(c);
}
END_TEST

/* A far deformation: the type kept (the Alexander polynomial and linking
 * numbers computed again here), at least the kept share of the thickness,
 * measured again; the same seed the same curve, another seed another;
 * the displacement is the sum of its modes (checked at one vertex by
 * hand). */
START_TEST(deform_keeps_type_and_thickness)
{
    tk_curve *c = NULL, *d = NULL, *again = NULL, *other = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 5, 120, &c, NULL), TK_OK);
    tk_measure m, md;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    ck_assert_int_eq(tk_generate_deform(c, 7, 0.05, &d, NULL), TK_OK);
    ck_assert_int_eq(tk_thickness_measure(d, NULL, &md, NULL), TK_OK);
    ck_assert(md.thickness >= 0.05 * m.thickness);
    tk_invariants was = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(c, &was, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(d, &now, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compare(&was, &now, NULL), TK_OK);
    double moved = 0.0;
    for (size_t k = 0; k < 3 * c->nvert; k++)
        moved = fmax(moved, fabs(d->xyz[k] - c->xyz[k]));
    ck_assert(moved > 0.0);
    ck_assert_int_eq(tk_generate_deform(c, 7, 0.05, &again, NULL), TK_OK);
    ck_assert_mem_eq(again->xyz, d->xyz, 3 * d->nvert * sizeof *d->xyz);
    ck_assert_int_eq(tk_generate_deform(c, 8, 0.05, &other, NULL), TK_OK);
    ck_assert(memcmp(other->xyz, d->xyz, 3 * d->nvert * sizeof *d->xyz) != 0);
    /* one mode by hand: a_1 = (1, 0, 0), the rest 0, amplitude 0.5; vertex
     * i sits at the phase of its arclength */
    double coef[6 * 3] = {1.0};
    tk_generate_fourier(other, c, coef, 3, 0.5);
    size_t n = c->nvert, i = n / 3;
    double before = 0.0, total = 0.0;
    for (size_t k = 0; k < n; k++) {
        const double *p = c->xyz + 3 * k, *q = c->xyz + 3 * ((k + 1) % n);
        double e = sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                        (q[2] - p[2]) * (q[2] - p[2]));
        before += k < i ? e : 0.0;
        total += e;
    }
    double phase = 2.0 * M_PI * before / total;
    ck_assert_double_eq_tol(other->xyz[3 * i] - c->xyz[3 * i], 0.5 * cos(phase), 1e-12);
    ck_assert(other->xyz[3 * i + 1] == c->xyz[3 * i + 1]);
    tk_error err;
    tk_curve_free(&again);
    ck_assert_int_eq(tk_generate_deform(c, 7, 0.0, &again, &err), TK_EINVAL);
    ck_assert_ptr_null(again);
    tk_invariants_free(&was);
    tk_invariants_free(&now);
    tk_curve_free(&c);
    tk_curve_free(&d);
    tk_curve_free(&other);
}
END_TEST

static Suite *generate_suite(void)
{
    Suite *s = suite_create("generate");
    TCase *tc = tcase_create("generate");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, torus_counts);
    tcase_add_test(tc, torus_on_torus);
    tcase_add_test(tc, torus_embedded_and_linked);
    tcase_add_test(tc, torus_minimum_count);
    tcase_add_test(tc, hopf_geometry);
    tcase_add_test(tc, hopf_length_converges);
    tcase_add_test(tc, borromean_rings);
    tcase_add_test(tc, clasp_ropes);
    tcase_add_test(tc, chain_rings);
    tcase_add_test(tc, invalid_arguments);
    tcase_add_test(tc, lissajous_curve);
    tcase_add_test(tc, deform_keeps_type_and_thickness);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(generate_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
