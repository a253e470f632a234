/* Curves: construction and copying, edge and vertex numbering, lengths
 * against closed forms, rigid motions and scaling, validation errors,
 * spline resampling (against the circle it samples, and its convergence),
 * sharing vertices by length, equilateralising. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"

/* ------------------------------------------------------------ helpers */

static tk_curve *new_curve(size_t ncomp, const size_t *counts, const bool *closed)
{
    tk_curve *c = NULL;
    tk_error err;
    int rc = tk_curve_new(&c, ncomp, counts, closed, &err);
    ck_assert_msg(rc == TK_OK, "tk_curve_new: %s", err.message);
    return c;
}

static void set_vertex(tk_curve *c, size_t v, double x, double y, double z)
{
    double *p = tk_curve_vertex(c, v);
    p[0] = x;
    p[1] = y;
    p[2] = z;
}

static double dist3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The rotation by angle about the unit vector axis (Rodrigues), row major. */
static void rotation_matrix(const double axis[3], double angle, double r[9])
{
    double c = cos(angle), s = sin(angle), t = 1.0 - c;
    double x = axis[0], y = axis[1], z = axis[2];
    r[0] = t * x * x + c;     r[1] = t * x * y - s * z; r[2] = t * x * z + s * y;
    r[3] = t * x * y + s * z; r[4] = t * y * y + c;     r[5] = t * y * z - s * x;
    r[6] = t * x * z - s * y; r[7] = t * y * z + s * x; r[8] = t * z * z + c;
}

static void unit_vector(double v[3])
{
    double n = sqrt(dot3(v, v));
    for (int k = 0; k < 3; k++)
        v[k] /= n;
}

/* A closed curve through the unit circle at the given angles (radians,
 * increasing, within one turn), in the xy plane. */
static tk_curve *circle_at_angles(const double *angle, size_t n)
{
    bool closed = true;
    tk_curve *c = new_curve(1, &n, &closed);
    for (size_t k = 0; k < n; k++)
        set_vertex(c, k, cos(angle[k]), sin(angle[k]), 0.0);
    return c;
}

/* Shortest and longest edge of one component. */
static void comp_edge_range(const tk_curve *c, size_t comp, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = 0.0;
    for (size_t k = 0; k < tk_curve_comp_edges(c, comp); k++) {
        double l = tk_curve_edge_length(c, comp, k);
        *lo = fmin(*lo, l);
        *hi = fmax(*hi, l);
    }
}

/* Expects tk_curve_validate to fail with TK_EINVAL and a message holding
 * every one of the given fragments. */
static void expect_invalid(const tk_curve *c, const char *what, const char *frag1,
                           const char *frag2)
{
    tk_error err;
    tk_error_clear(&err);
    int rc = tk_curve_validate(c, &err);
    ck_assert_msg(rc == TK_EINVAL, "%s: status %d, want TK_EINVAL", what, rc);
    ck_assert_int_eq(err.code, TK_EINVAL);
    ck_assert_msg(strstr(err.message, frag1) != NULL, "%s: message '%s' lacks '%s'", what,
                  err.message, frag1);
    if (frag2)
        ck_assert_msg(strstr(err.message, frag2) != NULL, "%s: message '%s' lacks '%s'",
                      what, err.message, frag2);
}

/* ------------------------------------------------- construction, copy */

START_TEST(new_copy_free)
{
    size_t counts[3] = {4, 3, 5};
    bool closed[3] = {true, false, true};
    tk_curve *c = new_curve(3, counts, closed);
    ck_assert_uint_eq(c->ncomp, 3);
    ck_assert_uint_eq(c->nvert, 12);
    ck_assert_uint_eq(c->offset[0], 0);
    ck_assert_uint_eq(c->offset[1], 4);
    ck_assert_uint_eq(c->offset[2], 7);
    ck_assert_uint_eq(c->offset[3], 12);
    ck_assert(c->closed[0] && !c->closed[1] && c->closed[2]);
    ck_assert(!c->has_colour);
    for (size_t i = 0; i < 3 * c->nvert; i++)
        ck_assert(c->xyz[i] == 0.0);
    for (size_t i = 0; i < 3; i++)
        ck_assert_uint_eq(tk_curve_comp_vertices(c, i), counts[i]);

    tkt_rng r = {11};
    for (size_t i = 0; i < 3 * c->nvert; i++)
        c->xyz[i] = tkt_rng_range(&r, -3, 3);
    c->colour = malloc(4 * c->ncomp * sizeof *c->colour);
    ck_assert_ptr_nonnull(c->colour);
    for (size_t i = 0; i < 4 * c->ncomp; i++)
        c->colour[i] = 0.1 * (double)i;
    c->has_colour = true;

    tk_curve *d = NULL;
    tk_error err;
    ck_assert_int_eq(tk_curve_copy(c, &d, &err), TK_OK);
    ck_assert_ptr_nonnull(d);
    ck_assert_uint_eq(d->ncomp, c->ncomp);
    ck_assert_uint_eq(d->nvert, c->nvert);
    for (size_t i = 0; i <= c->ncomp; i++)
        ck_assert_uint_eq(d->offset[i], c->offset[i]);
    for (size_t i = 0; i < c->ncomp; i++)
        ck_assert(d->closed[i] == c->closed[i]);
    ck_assert(memcmp(d->xyz, c->xyz, 3 * c->nvert * sizeof *c->xyz) == 0);
    ck_assert(d->has_colour);
    ck_assert(memcmp(d->colour, c->colour, 4 * c->ncomp * sizeof *c->colour) == 0);

    /* deep: no array is shared, and changing the copy leaves the original */
    ck_assert_ptr_ne(d->xyz, c->xyz);
    ck_assert_ptr_ne(d->offset, c->offset);
    ck_assert_ptr_ne(d->closed, c->closed);
    ck_assert_ptr_ne(d->colour, c->colour);
    double keep_x = c->xyz[5], keep_col = c->colour[2];
    size_t keep_off = c->offset[1];
    d->xyz[5] += 100.0;
    d->colour[2] = 7.0;
    d->offset[1] = 2;
    d->closed[1] = true;
    tk_curve_scale(d, 3.0);
    ck_assert(c->xyz[5] == keep_x);
    ck_assert(c->colour[2] == keep_col);
    ck_assert_uint_eq(c->offset[1], keep_off);
    ck_assert(!c->closed[1]);

    tk_curve_free(&d);
    ck_assert_ptr_null(d);
    tk_curve_free(&c);
    ck_assert_ptr_null(c);
    tk_curve_free(&c); /* tolerates *p == NULL */
    tk_curve_free(NULL);

    /* no components is refused */
    ck_assert_int_eq(tk_curve_new(&c, 0, counts, closed, &err), TK_EINVAL);
    ck_assert_ptr_null(c);
    ck_assert_int_eq(err.code, TK_EINVAL);
}
END_TEST

START_TEST(copy_without_colour)
{
    tk_curve *c = tkt_regular_polygon(7, 2.0), *d = NULL;
    ck_assert_int_eq(tk_curve_copy(c, &d, NULL), TK_OK);
    ck_assert(!d->has_colour);
    ck_assert_ptr_null(d->colour);
    ck_assert(memcmp(d->xyz, c->xyz, 3 * c->nvert * sizeof *c->xyz) == 0);
    tk_curve_free(&c);
    tk_curve_free(&d);
}
END_TEST

/* ------------------------------------------------ edges and vertices */

START_TEST(edge_counts)
{
    size_t counts[4] = {5, 5, 2, 3};
    bool closed[4] = {true, false, false, true};
    tk_curve *c = new_curve(4, counts, closed);
    ck_assert_uint_eq(tk_curve_comp_edges(c, 0), 5);
    ck_assert_uint_eq(tk_curve_comp_edges(c, 1), 4);
    ck_assert_uint_eq(tk_curve_comp_edges(c, 2), 1);
    ck_assert_uint_eq(tk_curve_comp_edges(c, 3), 3);
    ck_assert_uint_eq(tk_curve_edge_count(c), 13);
    ck_assert_uint_eq(tk_curve_comp_first_edge(c, 0), 0);
    ck_assert_uint_eq(tk_curve_comp_first_edge(c, 1), 5);
    ck_assert_uint_eq(tk_curve_comp_first_edge(c, 2), 9);
    ck_assert_uint_eq(tk_curve_comp_first_edge(c, 3), 10);
    tk_curve_free(&c);
}
END_TEST

START_TEST(edge_global_local_mapping)
{
    size_t counts[4] = {5, 5, 2, 3};
    bool closed[4] = {true, false, false, true};
    tk_curve *c = new_curve(4, counts, closed);
    size_t g = 0;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = counts[comp];
        for (size_t k = 0; k < tk_curve_comp_edges(c, comp); k++, g++) {
            tk_edge e = tk_curve_edge(c, g);
            ck_assert_uint_eq(e.comp, comp);
            ck_assert_uint_eq(e.index, k);
            ck_assert_uint_eq(e.head, c->offset[comp] + k);
            size_t want_tail = c->offset[comp] + (closed[comp] ? (k + 1) % n : k + 1);
            ck_assert_uint_eq(e.tail, want_tail);
            /* and back: local to global */
            ck_assert_uint_eq(tk_curve_comp_first_edge(c, comp) + k, g);
        }
    }
    ck_assert_uint_eq(g, tk_curve_edge_count(c));
    /* spot checks: the closing edges */
    tk_edge e = tk_curve_edge(c, 4);
    ck_assert(e.comp == 0 && e.index == 4 && e.head == 4 && e.tail == 0);
    e = tk_curve_edge(c, 12);
    ck_assert(e.comp == 3 && e.index == 2 && e.head == 14 && e.tail == 12);
    /* the open components' last edges end at their last vertex */
    e = tk_curve_edge(c, 8);
    ck_assert(e.comp == 1 && e.index == 3 && e.head == 8 && e.tail == 9);
    e = tk_curve_edge(c, 9);
    ck_assert(e.comp == 2 && e.index == 0 && e.head == 10 && e.tail == 11);
    tk_curve_free(&c);
}
END_TEST

START_TEST(vertex_index_wraps)
{
    size_t counts[2] = {6, 4};
    bool closed[2] = {false, true};
    tk_curve *c = new_curve(2, counts, closed);
    /* open: no wrap */
    for (size_t k = 0; k < 6; k++)
        ck_assert_uint_eq(tk_curve_vertex_index(c, 0, k), k);
    /* closed: modulo 4, offset 6 */
    ck_assert_uint_eq(tk_curve_vertex_index(c, 1, 0), 6);
    ck_assert_uint_eq(tk_curve_vertex_index(c, 1, 3), 9);
    ck_assert_uint_eq(tk_curve_vertex_index(c, 1, 4), 6);
    ck_assert_uint_eq(tk_curve_vertex_index(c, 1, 5), 7);
    ck_assert_uint_eq(tk_curve_vertex_index(c, 1, 11), 9);
    ck_assert_uint_eq(tk_curve_vertex_index(c, 1, 4000001), 7);
    /* the vertex pointer is into the flat array */
    ck_assert_ptr_eq(tk_curve_vertex(c, 7), c->xyz + 21);
    tk_curve_free(&c);
}
END_TEST

/* ------------------------------------------------------------ lengths */

START_TEST(regular_polygon_lengths)
{
    const size_t ns[] = {3, 4, 5, 12, 100, 1001};
    const double radii[] = {1.0, 0.25, 3.5};
    for (size_t i = 0; i < sizeof ns / sizeof *ns; i++)
        for (size_t j = 0; j < sizeof radii / sizeof *radii; j++) {
            size_t n = ns[i];
            double R = radii[j];
            tk_curve *c = tkt_regular_polygon(n, R);
            double side = 2.0 * R * sin(M_PI / (double)n);
            double want = (double)n * side;
            ck_assert_msg(tkt_reldiff(tk_curve_length(c), want) < 1e-13,
                          "n %zu R %g: length %.17g, want %.17g", n, R, tk_curve_length(c),
                          want);
            ck_assert(tkt_reldiff(tk_curve_comp_length(c, 0), want) < 1e-13);
            /* each edge is a difference of rounded coordinates of size R:
             * its error is a few ulps of R, not of the edge */
            double tol = 8.0 * 0x1.0p-52 * R;
            for (size_t k = 0; k < n; k++)
                ck_assert_msg(fabs(tk_curve_edge_length(c, 0, k) - side) < tol,
                              "n %zu R %g edge %zu: %.17g, want %.17g", n, R, k,
                              tk_curve_edge_length(c, 0, k), side);
            double lo, hi;
            tk_curve_edge_range(c, &lo, &hi);
            ck_assert(fabs(lo - side) < tol && fabs(hi - side) < tol);
            ck_assert(lo <= hi);
            tk_curve_free(&c);
        }
}
END_TEST

START_TEST(lengths_open_and_closed)
{
    /* a unit square, closed, then the same four vertices open, then a
     * segment of length 5 */
    size_t counts[3] = {4, 4, 2};
    bool closed[3] = {true, false, false};
    tk_curve *c = new_curve(3, counts, closed);
    set_vertex(c, 0, 0, 0, 0);
    set_vertex(c, 1, 1, 0, 0);
    set_vertex(c, 2, 1, 1, 0);
    set_vertex(c, 3, 0, 1, 0);
    set_vertex(c, 4, 0, 0, 0);
    set_vertex(c, 5, 1, 0, 0);
    set_vertex(c, 6, 1, 1, 0);
    set_vertex(c, 7, 0, 1, 0);
    set_vertex(c, 8, 0, 0, 0);
    set_vertex(c, 9, 3, 4, 0);
    ck_assert(tk_curve_comp_length(c, 0) == 4.0);
    ck_assert(tk_curve_comp_length(c, 1) == 3.0);
    ck_assert(tk_curve_comp_length(c, 2) == 5.0);
    ck_assert(tk_curve_length(c) == 12.0);
    ck_assert(tk_curve_edge_length(c, 0, 3) == 1.0); /* the closing edge */
    double lo, hi;
    tk_curve_edge_range(c, &lo, &hi);
    ck_assert(lo == 1.0 && hi == 5.0);
    /* either output may be NULL */
    tk_curve_edge_range(c, NULL, &hi);
    ck_assert(hi == 5.0);
    tk_curve_edge_range(c, &lo, NULL);
    ck_assert(lo == 1.0);
    tk_curve_free(&c);
}
END_TEST

/* --------------------------------------------- motions and scaling */

START_TEST(translate_rotate_scale)
{
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_torus(2, 3, 90, &c, &err), TK_OK);
    tkt_rng r = {99};
    for (int trial = 0; trial < 20; trial++) {
        tk_curve *d = NULL;
        ck_assert_int_eq(tk_curve_copy(c, &d, &err), TK_OK);
        double len0 = tk_curve_length(d), c0[3], c1[3];
        tk_curve_centroid(d, c0);

        /* translation: centroid moves by the shift, lengths stay */
        double shift[3];
        tkt_rng_point(&r, 10.0, shift);
        tk_curve_translate(d, shift);
        tk_curve_centroid(d, c1);
        for (int k = 0; k < 3; k++)
            ck_assert_msg(fabs(c1[k] - (c0[k] + shift[k])) < 1e-13, "trial %d centroid %d",
                          trial, k);
        ck_assert(tkt_reldiff(tk_curve_length(d), len0) < 1e-13);

        /* rotation: every edge keeps its length */
        double axis[3], rot[9];
        tkt_rng_point(&r, 1.0, axis);
        unit_vector(axis);
        rotation_matrix(axis, tkt_rng_range(&r, -M_PI, M_PI), rot);
        tk_curve *before = NULL;
        ck_assert_int_eq(tk_curve_copy(d, &before, &err), TK_OK);
        tk_curve_rotate(d, rot);
        for (size_t k = 0; k < tk_curve_comp_edges(d, 0); k++)
            ck_assert_msg(tkt_reldiff(tk_curve_edge_length(d, 0, k),
                                      tk_curve_edge_length(before, 0, k)) < 1e-13,
                          "trial %d edge %zu", trial, k);
        /* the vertices did move (not the identity) */
        ck_assert(dist3(tk_curve_vertex(d, 0), tk_curve_vertex(before, 0)) > 1e-6);
        ck_assert(tkt_reldiff(tk_curve_length(d), len0) < 1e-13);
        /* the centroid rotates with the curve */
        double cr[3], cb[3];
        tk_curve_centroid(before, cb);
        tk_curve_centroid(d, cr);
        for (int k = 0; k < 3; k++) {
            double want = rot[3 * k] * cb[0] + rot[3 * k + 1] * cb[1] + rot[3 * k + 2] * cb[2];
            ck_assert(fabs(cr[k] - want) < 1e-12);
        }

        /* scaling: lengths scale by the factor */
        double f = tkt_rng_range(&r, 0.01, 100.0);
        tk_curve_scale(d, f);
        ck_assert_msg(tkt_reldiff(tk_curve_length(d), f * len0) < 1e-13,
                      "trial %d: scaled by %g: %.17g vs %.17g", trial, f, tk_curve_length(d),
                      f * len0);
        double lo0, hi0, lo1, hi1;
        tk_curve_edge_range(before, &lo0, &hi0);
        tk_curve_edge_range(d, &lo1, &hi1);
        ck_assert(tkt_reldiff(lo1, f * lo0) < 1e-13 && tkt_reldiff(hi1, f * hi0) < 1e-13);
        tk_curve_free(&before);
        tk_curve_free(&d);
    }
    tk_curve_free(&c);
}
END_TEST

START_TEST(scale_exact_powers_of_two)
{
    tk_curve *c = tkt_regular_polygon(17, 1.0);
    double len = tk_curve_length(c);
    tk_curve_scale(c, 4.0);
    ck_assert(tk_curve_length(c) == 4.0 * len); /* exact: a power of two */
    tk_curve_scale(c, 0.125);
    ck_assert(tk_curve_length(c) == 0.5 * len);
    tk_curve_free(&c);
}
END_TEST

/* ----------------------------------------------------------- validate */

START_TEST(validate_accepts_good_curves)
{
    tk_curve *c = tkt_regular_polygon(3, 1.0);
    tk_error err;
    ck_assert_int_eq(tk_curve_validate(c, &err), TK_OK);
    tk_curve_free(&c);
    size_t n = 2;
    bool closed = false;
    c = new_curve(1, &n, &closed);
    set_vertex(c, 1, 0, 0, 1e-9);
    ck_assert_int_eq(tk_curve_validate(c, &err), TK_OK);
    tk_curve_free(&c);
}
END_TEST

START_TEST(validate_failures)
{
    /* component 0 is a fine triangle; component 1 carries each offence */
    tk_curve *c;
    {
        size_t counts[2] = {3, 2};
        bool closed[2] = {true, true};
        c = new_curve(2, counts, closed);
        set_vertex(c, 0, 1, 0, 0);
        set_vertex(c, 1, 0, 1, 0);
        set_vertex(c, 2, 0, 0, 1);
        set_vertex(c, 3, 5, 0, 0);
        set_vertex(c, 4, 6, 0, 0);
        expect_invalid(c, "closed with 2 vertices", "component 1", "2 vertices");
        tk_curve_free(&c);
    }
    {
        size_t counts[2] = {3, 1};
        bool closed[2] = {true, false};
        c = new_curve(2, counts, closed);
        set_vertex(c, 0, 1, 0, 0);
        set_vertex(c, 1, 0, 1, 0);
        set_vertex(c, 2, 0, 0, 1);
        set_vertex(c, 3, 5, 0, 0);
        expect_invalid(c, "open with 1 vertex", "component 1", "open");
        tk_curve_free(&c);
    }
    size_t counts[2] = {3, 5};
    bool closed[2] = {true, true};
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    for (int b = 0; b < 3; b++)
        for (int axis = 0; axis < 3; axis++) {
            c = new_curve(2, counts, closed);
            for (size_t v = 0; v < c->nvert; v++)
                set_vertex(c, v, (double)v, (double)(v * v), 0.5 * (double)v);
            tk_curve_vertex(c, 3 + 2)[axis] = bad[b];
            char what[64];
            snprintf(what, sizeof what, "non-finite %d on axis %d", b, axis);
            expect_invalid(c, what, "component 1", "vertex 2");
            tk_curve_free(&c);
        }
    /* a repeated vertex: zero-length edge 2 -> 3 of component 1 */
    c = new_curve(2, counts, closed);
    for (size_t v = 0; v < c->nvert; v++)
        set_vertex(c, v, (double)v, (double)(v * v), 0.5 * (double)v);
    memcpy(tk_curve_vertex(c, 3 + 3), tk_curve_vertex(c, 3 + 2), 3 * sizeof(double));
    expect_invalid(c, "zero-length edge", "component 1", "2 and 3");
    tk_curve_free(&c);
    /* the closing edge: last vertex equal to the first */
    c = new_curve(2, counts, closed);
    for (size_t v = 0; v < c->nvert; v++)
        set_vertex(c, v, (double)v, (double)(v * v), 0.5 * (double)v);
    memcpy(tk_curve_vertex(c, 3 + 4), tk_curve_vertex(c, 3 + 0), 3 * sizeof(double));
    expect_invalid(c, "zero-length closing edge", "component 1", "4 and 0");
    tk_curve_free(&c);
    /* an open component's last edge */
    {
        size_t oc[2] = {3, 4};
        bool ocl[2] = {true, false};
        c = new_curve(2, oc, ocl);
        for (size_t v = 0; v < c->nvert; v++)
            set_vertex(c, v, (double)v, (double)(v * v), 0.0);
        memcpy(tk_curve_vertex(c, 6), tk_curve_vertex(c, 5), 3 * sizeof(double));
        expect_invalid(c, "zero-length open edge", "component 1", "2 and 3");
        tk_curve_free(&c);
    }
}
END_TEST

/* ----------------------------------------------------------- resample */

START_TEST(resample_circle_from_12_gon)
{
    /* a unit 12-gon in a tilted plane about an off-origin centre */
    tk_curve *c = tkt_regular_polygon(12, 1.0);
    double axis[3] = {1.0, 2.0, -0.5}, rot[9], shift[3] = {0.3, -1.7, 2.2};
    unit_vector(axis);
    rotation_matrix(axis, 0.9, rot);
    tk_curve_rotate(c, rot);
    tk_curve_translate(c, shift);
    double normal[3] = {rot[2], rot[5], rot[8]}; /* the image of z */

    size_t count = 400;
    tk_curve *d = NULL;
    tk_error err;
    ck_assert_int_eq(tk_curve_resample(c, &count, &d, &err), TK_OK);
    ck_assert_uint_eq(d->ncomp, 1);
    ck_assert_uint_eq(d->nvert, 400);
    ck_assert(d->closed[0]);
    double worst_radial = 0.0, worst_plane = 0.0;
    for (size_t v = 0; v < d->nvert; v++) {
        double rel[3];
        for (int k = 0; k < 3; k++)
            rel[k] = tk_curve_vertex(d, v)[k] - shift[k];
        double h = dot3(rel, normal);
        double rho = sqrt(fmax(0.0, dot3(rel, rel) - h * h));
        worst_plane = fmax(worst_plane, fabs(h));
        worst_radial = fmax(worst_radial, hypot(rho - 1.0, h));
    }
    ck_assert_msg(worst_radial < 2e-3, "farthest from the unit circle: %.3g", worst_radial);
    ck_assert_msg(worst_plane < 1e-12, "farthest from the plane: %.3g", worst_plane);
    double lo, hi;
    tk_curve_edge_range(d, &lo, &hi);
    ck_assert_msg(hi / lo < 1.01, "edges from %.9g to %.9g (ratio %.6f)", lo, hi, hi / lo);
    /* and it goes round once: its length is close to 2 pi */
    ck_assert_msg(fabs(tk_curve_length(d) - 2.0 * M_PI) < 0.01, "length %.9g",
                  tk_curve_length(d));
    ck_assert_int_eq(tk_curve_validate(d, &err), TK_OK);
    tk_curve_free(&c);
    tk_curve_free(&d);
}
END_TEST

static void own_count_keeps_length(tk_curve *c, const char *what)
{
    size_t *counts = malloc(c->ncomp * sizeof *counts);
    ck_assert_ptr_nonnull(counts);
    for (size_t i = 0; i < c->ncomp; i++)
        counts[i] = tk_curve_comp_vertices(c, i);
    tk_curve *d = NULL;
    tk_error err;
    ck_assert_msg(tk_curve_resample(c, counts, &d, &err) == TK_OK, "%s: %s", what,
                  err.message);
    for (size_t i = 0; i < c->ncomp; i++) {
        ck_assert_uint_eq(tk_curve_comp_vertices(d, i), counts[i]);
        ck_assert(d->closed[i] == c->closed[i]);
    }
    double a = tk_curve_length(c), b = tk_curve_length(d);
    ck_assert_msg(tkt_reldiff(a, b) < 0.01, "%s: length %.9g became %.9g", what, a, b);
    free(counts);
    tk_curve_free(&d);
}

START_TEST(resample_to_own_count_keeps_length)
{
    tk_curve *c = tkt_regular_polygon(30, 2.0);
    own_count_keeps_length(c, "30-gon");
    tk_curve_free(&c);
    tk_error err;
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, &err), TK_OK);
    own_count_keeps_length(c, "T(2,3)");
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_borromean(0, &c, &err), TK_OK);
    own_count_keeps_length(c, "Borromean rings");
    tk_curve_free(&c);
    if (!tkt_catalogue_dir()) {
        printf("note: the catalogue is absent; resampling 3.1.vect to its own count not checked\n");
        return;
    }
    c = tkt_catalogue_curve("3.1.vect");
    own_count_keeps_length(c, "3.1.vect");
    tk_curve_free(&c);
}
END_TEST

START_TEST(resample_open_keeps_end_points)
{
    /* an open helix arc with uneven spacing, and a closed triangle before
     * it so that the open component does not start at offset 0 */
    size_t counts[2] = {3, 23};
    bool closed[2] = {true, false};
    tk_curve *c = new_curve(2, counts, closed);
    set_vertex(c, 0, 10, 0, 0);
    set_vertex(c, 1, 11, 0, 0);
    set_vertex(c, 2, 10, 1, 0);
    tkt_rng r = {5};
    double t = 0.1;
    for (size_t k = 0; k < 23; k++) {
        t += tkt_rng_range(&r, 0.1, 0.4);
        set_vertex(c, 3 + k, 1.3 * cos(t) + 0.1, 0.7 * sin(t) - 0.3, 0.37 * t + 0.1);
    }
    const size_t asks[] = {2, 3, 7, 23, 50, 501};
    for (size_t a = 0; a < sizeof asks / sizeof *asks; a++) {
        size_t want[2] = {5, asks[a]};
        tk_curve *d = NULL;
        tk_error err;
        ck_assert_int_eq(tk_curve_resample(c, want, &d, &err), TK_OK);
        ck_assert_uint_eq(tk_curve_comp_vertices(d, 0), 5);
        ck_assert_uint_eq(tk_curve_comp_vertices(d, 1), asks[a]);
        ck_assert(d->closed[0] && !d->closed[1]);
        const double *first = tk_curve_vertex(c, 3), *last = tk_curve_vertex(c, 25);
        const double *dfirst = tk_curve_vertex(d, d->offset[1]);
        const double *dlast = tk_curve_vertex(d, d->offset[2] - 1);
        for (int k = 0; k < 3; k++) {
            ck_assert_msg(dfirst[k] == first[k], "%zu vertices: first end %d moved: %.17g -> %.17g",
                          asks[a], k, first[k], dfirst[k]);
            ck_assert_msg(dlast[k] == last[k], "%zu vertices: last end %d moved: %.17g -> %.17g",
                          asks[a], k, last[k], dlast[k]);
        }
        tk_curve_free(&d);
    }
    tk_curve_free(&c);

    /* random open polylines, random counts: the ends are copied, not
     * re-evaluated (re-evaluation can be an ulp off) */
    for (int trial = 0; trial < 200; trial++) {
        size_t n = 3 + (size_t)(tkt_rng_next(&r) % 20), m = 2 + (size_t)(tkt_rng_next(&r) % 100);
        bool open = false;
        tk_curve *e = new_curve(1, &n, &open), *d = NULL;
        for (size_t i = 0; i < 3 * n; i++)
            e->xyz[i] = tkt_rng_range(&r, -2, 2);
        tk_error err;
        ck_assert_int_eq(tk_curve_resample(e, &m, &d, &err), TK_OK);
        ck_assert_uint_eq(d->nvert, m);
        for (int k = 0; k < 3; k++) {
            ck_assert_msg(d->xyz[k] == e->xyz[k], "trial %d (%zu -> %zu): first end %d: %.17g -> %.17g",
                          trial, n, m, k, e->xyz[k], d->xyz[k]);
            ck_assert_msg(d->xyz[3 * (m - 1) + k] == e->xyz[3 * (n - 1) + k],
                          "trial %d (%zu -> %zu): last end %d: %.17g -> %.17g", trial, n, m, k,
                          e->xyz[3 * (n - 1) + k], d->xyz[3 * (m - 1) + k]);
        }
        tk_curve_free(&d);
        tk_curve_free(&e);
    }
}
END_TEST

START_TEST(resample_link_counts)
{
    tk_curve *c = NULL, *d = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_chain(3, 24, &c, &err), TK_OK);
    ck_assert_uint_eq(c->ncomp, 3);
    size_t counts[3] = {40, 77, 3};
    ck_assert_int_eq(tk_curve_resample(c, counts, &d, &err), TK_OK);
    ck_assert_uint_eq(d->ncomp, 3);
    ck_assert_uint_eq(d->nvert, 120);
    for (size_t i = 0; i < 3; i++) {
        ck_assert_uint_eq(tk_curve_comp_vertices(d, i), counts[i]);
        ck_assert(d->closed[i]);
    }
    /* each ring stays where it was: centroid of ring i near (1.5 i, 0, 0) */
    for (size_t i = 0; i < 2; i++) {
        double s[3] = {0, 0, 0};
        for (size_t v = d->offset[i]; v < d->offset[i + 1]; v++)
            for (int k = 0; k < 3; k++)
                s[k] += tk_curve_vertex(d, v)[k] / (double)counts[i];
        ck_assert_msg(fabs(s[0] - 1.5 * (double)i) < 1e-2 && fabs(s[1]) < 1e-2 &&
                          fabs(s[2]) < 1e-2,
                      "ring %zu centred at (%g %g %g)", i, s[0], s[1], s[2]);
    }
    ck_assert_int_eq(tk_curve_validate(d, &err), TK_OK);
    tk_curve_free(&d);
    tk_curve_free(&c);
}
END_TEST

START_TEST(resample_too_few_vertices)
{
    tk_curve *c = NULL, *d = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_chain(3, 24, &c, &err), TK_OK);
    size_t counts[3] = {40, 2, 40};
    tk_error_clear(&err);
    ck_assert_int_eq(tk_curve_resample(c, counts, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    ck_assert_msg(strstr(err.message, "component 1") != NULL, "message '%s'", err.message);
    tk_curve_free(&c);

    size_t n = 6;
    bool closed = false;
    c = new_curve(1, &n, &closed);
    for (size_t v = 0; v < n; v++)
        set_vertex(c, v, (double)v, 0.1 * (double)(v * v), 0.0);
    size_t one = 1;
    ck_assert_int_eq(tk_curve_resample(c, &one, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    size_t zero = 0;
    ck_assert_int_eq(tk_curve_resample(c, &zero, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    tk_curve_free(&c);
}
END_TEST

START_TEST(resample_rejects_invalid_input)
{
    tk_curve *c = tkt_regular_polygon(10, 1.0), *d = NULL;
    tk_curve_vertex(c, 4)[1] = NAN;
    size_t count = 50;
    tk_error err;
    ck_assert_int_eq(tk_curve_resample(c, &count, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    ck_assert_int_eq(tk_curve_resample_total(c, 50, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    tk_curve_free(&c);
}
END_TEST

START_TEST(resample_converges)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("resample_converges", "the catalogue is absent");
        return;
    }
    tk_curve *c = tkt_catalogue_curve("3.1.vect");
    ck_assert_uint_eq(c->ncomp, 1);
    size_t n1 = 1000, n2 = 2000;
    tk_curve *a = NULL, *b = NULL;
    tk_error err;
    ck_assert_int_eq(tk_curve_resample(c, &n1, &a, &err), TK_OK);
    ck_assert_int_eq(tk_curve_resample(c, &n2, &b, &err), TK_OK);
    ck_assert_uint_eq(a->nvert, 1000);
    ck_assert_uint_eq(b->nvert, 2000);
    double la = tk_curve_length(a), lb = tk_curve_length(b);
    ck_assert_msg(tkt_reldiff(la, lb) < 1e-4, "1000 vertices: %.12g, 2000: %.12g (rel %.3g)",
                  la, lb, tkt_reldiff(la, lb));
    /* inscribed polygons of a smooth curve grow towards its length */
    ck_assert_msg(la <= lb, "length fell from %.12g to %.12g", la, lb);
    tk_curve_free(&a);
    tk_curve_free(&b);
    tk_curve_free(&c);
}
END_TEST

/* ---------------------------------------------------- resample_total */

static tk_curve *two_rings(double r0, double r1, size_t n0, size_t n1)
{
    size_t counts[2] = {n0, n1};
    bool closed[2] = {true, true};
    tk_curve *c = new_curve(2, counts, closed);
    for (size_t k = 0; k < n0; k++) {
        double a = 2.0 * M_PI * (double)k / (double)n0;
        set_vertex(c, k, r0 * cos(a), r0 * sin(a), 0.0);
    }
    for (size_t k = 0; k < n1; k++) {
        double a = 2.0 * M_PI * (double)k / (double)n1;
        set_vertex(c, n0 + k, 10.0 + r1 * cos(a), 0.0, r1 * sin(a));
    }
    return c;
}

START_TEST(resample_total_by_length)
{
    /* radii 1 and 2, same vertex count: lengths exactly 1 : 2 */
    tk_curve *c = two_rings(1.0, 2.0, 40, 40), *d = NULL;
    tk_error err;
    ck_assert_int_eq(tk_curve_resample_total(c, 300, &d, &err), TK_OK);
    ck_assert_uint_eq(d->ncomp, 2);
    ck_assert_uint_eq(tk_curve_comp_vertices(d, 0), 100);
    ck_assert_uint_eq(tk_curve_comp_vertices(d, 1), 200);
    ck_assert_uint_eq(d->nvert, 300);
    tk_curve_free(&d);

    /* sums are exact, and each count within one of its share */
    const size_t totals[] = {6, 7, 10, 31, 97, 301, 1000, 4097};
    tk_curve_free(&c);
    c = two_rings(1.0, 2.7, 13, 40);
    double l0 = tk_curve_comp_length(c, 0), l = tk_curve_length(c);
    for (size_t i = 0; i < sizeof totals / sizeof *totals; i++) {
        ck_assert_int_eq(tk_curve_resample_total(c, totals[i], &d, &err), TK_OK);
        size_t n0 = tk_curve_comp_vertices(d, 0), n1 = tk_curve_comp_vertices(d, 1);
        ck_assert_msg(n0 + n1 == totals[i], "total %zu: %zu + %zu", totals[i], n0, n1);
        ck_assert(n0 >= 3 && n1 >= 3);
        double share = (double)totals[i] * l0 / l;
        if (share >= 3.0 && (double)totals[i] - share >= 3.0)
            ck_assert_msg(fabs((double)n0 - share) < 1.0, "total %zu: %zu for share %.3f",
                          totals[i], n0, share);
        tk_curve_free(&d);
    }
    tk_curve_free(&c);
}
END_TEST

START_TEST(resample_total_minimums)
{
    /* a tiny ring beside a huge one: the tiny one still gets 3, an open
     * arc still gets 2 */
    size_t counts[3] = {8, 8, 5};
    bool closed[3] = {true, true, false};
    tk_curve *c = new_curve(3, counts, closed), *d = NULL;
    for (size_t k = 0; k < 8; k++) {
        double a = 2.0 * M_PI * (double)k / 8.0;
        set_vertex(c, k, 1e-3 * cos(a), 1e-3 * sin(a), 0.0);
        set_vertex(c, 8 + k, 100.0 * cos(a), 100.0 * sin(a), 5.0);
    }
    for (size_t k = 0; k < 5; k++)
        set_vertex(c, 16 + k, 0.001 * (double)k, 50.0, 0.0);
    tk_error err;
    const size_t totals[] = {8, 9, 20, 100, 1000};
    for (size_t i = 0; i < sizeof totals / sizeof *totals; i++) {
        ck_assert_int_eq(tk_curve_resample_total(c, totals[i], &d, &err), TK_OK);
        size_t n0 = tk_curve_comp_vertices(d, 0), n1 = tk_curve_comp_vertices(d, 1),
               n2 = tk_curve_comp_vertices(d, 2);
        ck_assert_msg(n0 >= 3 && n1 >= 3 && n2 >= 2, "total %zu: %zu %zu %zu", totals[i], n0,
                      n1, n2);
        ck_assert_uint_eq(n0 + n1 + n2, totals[i]);
        ck_assert(d->closed[0] && d->closed[1] && !d->closed[2]);
        tk_curve_free(&d);
    }
    /* the least possible total is exactly the sum of the minimums */
    ck_assert_int_eq(tk_curve_resample_total(c, 8, &d, &err), TK_OK);
    ck_assert_uint_eq(tk_curve_comp_vertices(d, 0), 3);
    ck_assert_uint_eq(tk_curve_comp_vertices(d, 1), 3);
    ck_assert_uint_eq(tk_curve_comp_vertices(d, 2), 2);
    tk_curve_free(&d);
    /* one fewer is an error */
    tk_error_clear(&err);
    ck_assert_int_eq(tk_curve_resample_total(c, 7, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    ck_assert(err.message[0] != '\0');
    ck_assert_int_eq(tk_curve_resample_total(c, 0, &d, &err), TK_EINVAL);
    ck_assert_ptr_null(d);
    tk_curve_free(&c);
}
END_TEST

/* ---------------------------------------------------- equilateralize */

START_TEST(equilateralize_uneven_circle)
{
    /* 200 vertices on the unit circle, steps alternating 1 : 4 and jittered */
    size_t n = 200;
    double *angle = malloc(n * sizeof *angle), *step = malloc(n * sizeof *step);
    ck_assert(angle && step);
    tkt_rng r = {3};
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        step[k] = (k % 2 ? 4.0 : 1.0) * tkt_rng_range(&r, 0.8, 1.2);
        sum += step[k];
    }
    angle[0] = 0.0;
    for (size_t k = 1; k < n; k++)
        angle[k] = angle[k - 1] + 2.0 * M_PI * step[k - 1] / sum;
    tk_curve *c = circle_at_angles(angle, n);
    double lo, hi;
    tk_curve_edge_range(c, &lo, &hi);
    ck_assert_msg(hi / lo > 3.0, "the start is not uneven: %.3f", hi / lo);
    double len0 = tk_curve_length(c);
    double v0[3];
    memcpy(v0, tk_curve_vertex(c, 0), sizeof v0);

    tk_error err;
    ck_assert_int_eq(tk_curve_equilateralize(c, &err), TK_OK);
    ck_assert_uint_eq(c->nvert, n);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 0), n);
    tk_curve_edge_range(c, &lo, &hi);
    ck_assert_msg(hi / lo < 1.05, "edges from %.9g to %.9g (ratio %.5f)", lo, hi, hi / lo);
    /* vertices move along the polygon: still on or inside the circle,
     * the length cannot grow */
    for (size_t v = 0; v < n; v++) {
        const double *p = tk_curve_vertex(c, v);
        ck_assert(hypot(p[0], p[1]) <= 1.0 + 1e-15 && p[2] == 0.0);
    }
    ck_assert(tk_curve_length(c) <= len0 * (1.0 + 1e-15));
    /* the fixed start */
    ck_assert(memcmp(v0, tk_curve_vertex(c, 0), sizeof v0) == 0);
    tk_curve_free(&c);
    free(angle);
    free(step);
}
END_TEST

START_TEST(equilateralize_open_and_link)
{
    /* an open arc of a circle with very unequal steps, then a closed ring */
    size_t counts[2] = {120, 60};
    bool closed[2] = {false, true};
    tk_curve *c = new_curve(2, counts, closed);
    tkt_rng r = {17};
    double t = 0.0;
    for (size_t k = 0; k < 120; k++) {
        set_vertex(c, k, 3.0 * cos(t), 3.0 * sin(t), 0.2 * t);
        t += (k % 3 == 0 ? 5.0 : 1.0) * tkt_rng_range(&r, 0.005, 0.015);
    }
    for (size_t k = 0; k < 60; k++) {
        double a = 2.0 * M_PI * pow((double)k / 60.0, 1.5);
        set_vertex(c, 120 + k, 10.0 + cos(a), sin(a), 0.0);
    }
    double first[3], last[3];
    memcpy(first, tk_curve_vertex(c, 0), sizeof first);
    memcpy(last, tk_curve_vertex(c, 119), sizeof last);
    double lo, hi;
    comp_edge_range(c, 0, &lo, &hi);
    ck_assert(hi / lo > 3.0);
    tk_error err;
    ck_assert_int_eq(tk_curve_equilateralize(c, &err), TK_OK);
    ck_assert_uint_eq(c->ncomp, 2);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 0), 120);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 1), 60);
    ck_assert(!c->closed[0] && c->closed[1]);
    ck_assert(memcmp(first, tk_curve_vertex(c, 0), sizeof first) == 0);
    ck_assert(memcmp(last, tk_curve_vertex(c, 119), sizeof last) == 0);
    comp_edge_range(c, 0, &lo, &hi);
    ck_assert_msg(hi / lo < 1.05, "open arc: edges from %.9g to %.9g", lo, hi);
    comp_edge_range(c, 1, &lo, &hi);
    ck_assert_msg(hi / lo < 1.05, "ring: edges from %.9g to %.9g", lo, hi);
    ck_assert_int_eq(tk_curve_validate(c, &err), TK_OK);
    tk_curve_free(&c);
}
END_TEST

START_TEST(equilateralize_equilateral_is_fixed)
{
    /* a regular polygon is already equilateral: it stays put */
    tk_curve *c = tkt_regular_polygon(24, 1.5), *d = NULL;
    ck_assert_int_eq(tk_curve_copy(c, &d, NULL), TK_OK);
    ck_assert_int_eq(tk_curve_equilateralize(d, NULL), TK_OK);
    for (size_t v = 0; v < c->nvert; v++)
        ck_assert_msg(dist3(tk_curve_vertex(c, v), tk_curve_vertex(d, v)) < 1e-13, "vertex %zu",
                      v);
    tk_curve_free(&c);
    tk_curve_free(&d);
}
END_TEST

START_TEST(equilateralize_rejects_invalid)
{
    tk_curve *c = tkt_regular_polygon(6, 1.0);
    memcpy(tk_curve_vertex(c, 3), tk_curve_vertex(c, 2), 3 * sizeof(double));
    tk_error err;
    ck_assert_int_eq(tk_curve_equilateralize(c, &err), TK_EINVAL);
    ck_assert(strstr(err.message, "component 0") != NULL);
    tk_curve_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("curve");
    TCase *tc = tcase_create("curve");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, new_copy_free);
    tcase_add_test(tc, copy_without_colour);
    tcase_add_test(tc, edge_counts);
    tcase_add_test(tc, edge_global_local_mapping);
    tcase_add_test(tc, vertex_index_wraps);
    tcase_add_test(tc, regular_polygon_lengths);
    tcase_add_test(tc, lengths_open_and_closed);
    tcase_add_test(tc, translate_rotate_scale);
    tcase_add_test(tc, scale_exact_powers_of_two);
    tcase_add_test(tc, validate_accepts_good_curves);
    tcase_add_test(tc, validate_failures);
    tcase_add_test(tc, resample_circle_from_12_gon);
    tcase_add_test(tc, resample_to_own_count_keeps_length);
    tcase_add_test(tc, resample_open_keeps_end_points);
    tcase_add_test(tc, resample_link_counts);
    tcase_add_test(tc, resample_too_few_vertices);
    tcase_add_test(tc, resample_converges);
    tcase_add_test(tc, resample_total_by_length);
    tcase_add_test(tc, resample_total_minimums);
    tcase_add_test(tc, equilateralize_uneven_circle);
    tcase_add_test(tc, equilateralize_open_and_link);
    tcase_add_test(tc, equilateralize_equilateral_is_fixed);
    tcase_add_test(tc, equilateralize_rejects_invalid);
    suite_add_tcase(s, tc);
    /* apart, with a short timeout: a NaN must be refused, not loop */
    TCase *bad = tcase_create("invalid input");
    tcase_set_timeout(bad, 10);
    tcase_add_test(bad, resample_rejects_invalid_input);
    suite_add_tcase(s, bad);
    return tkt_run_suite(s);
}
