/* tightknot: knot and link invariants (see include/tk/invariants.h). */
#include "tk/invariants.h"

#include <math.h>

/* The linking integral of two polygons is exact within rounding: a sum
 * further than this from an integer means the polygons (nearly) touch. */
#define LINKING_INTEGER_TOLERANCE 1e-6

static void sub3(const double *a, const double *b, double *out)
{
    for (int k = 0; k < 3; k++)
        out[k] = a[k] - b[k];
}

static void cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The unit normal of the plane through the origin spanned by u and v, or
 * zero when they are parallel. */
static void unit_normal(const double *u, const double *v, double *n)
{
    cross3(u, v, n);
    double len = sqrt(dot3(n, n));
    for (int k = 0; k < 3; k++)
        n[k] = len > 0.0 ? n[k] / len : 0.0;
}

static double clamped_asin(double x)
{
    return asin(x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x));
}

/* The signed solid angle that segment p3-p4 subtends seen along segment
 * p1-p2: the area of the quadrilateral the Gauss map sends their pairs of
 * points to.  Its four corners are the directions from p1 and p2 to p3 and
 * p4; the area is the sum of the angles between the normals of the great
 * circles through consecutive corners, the sign the orientation of the two
 * segments. */
static double segment_pair(const double *p1, const double *p2, const double *p3,
                           const double *p4)
{
    double r13[3], r14[3], r23[3], r24[3], r12[3], r34[3];
    sub3(p3, p1, r13);
    sub3(p4, p1, r14);
    sub3(p3, p2, r23);
    sub3(p4, p2, r24);
    sub3(p2, p1, r12);
    sub3(p4, p3, r34);
    double n1[3], n2[3], n3[3], n4[3];
    unit_normal(r13, r14, n1);
    unit_normal(r14, r24, n2);
    unit_normal(r24, r23, n3);
    unit_normal(r23, r13, n4);
    double omega = clamped_asin(dot3(n1, n2)) + clamped_asin(dot3(n2, n3)) +
                   clamped_asin(dot3(n3, n4)) + clamped_asin(dot3(n4, n1));
    double orient[3];
    cross3(r34, r12, orient);
    double s = dot3(orient, r13);
    return s > 0.0 ? omega : (s < 0.0 ? -omega : 0.0);
}

int tk_linking_number(const tk_curve *c, size_t a, size_t b, long *lk, double *gauss,
                      tk_error *err)
{
    if (a >= c->ncomp || b >= c->ncomp || a == b)
        return tk_error_set(err, TK_EINVAL,
                            "the linking number needs two different components (got %zu and %zu "
                            "of %zu)",
                            a, b, c->ncomp);
    if (!c->closed[a] || !c->closed[b])
        return tk_error_set(err, TK_EINVAL,
                            "the linking number needs closed components (%zu or %zu is open)", a,
                            b);
    size_t na = tk_curve_comp_vertices(c, a), nb = tk_curve_comp_vertices(c, b);
    double sum = 0.0;
    for (size_t i = 0; i < na; i++) {
        const double *p1 = tk_curve_vertex(c, tk_curve_vertex_index(c, a, i));
        const double *p2 = tk_curve_vertex(c, tk_curve_vertex_index(c, a, i + 1));
        for (size_t j = 0; j < nb; j++) {
            const double *p3 = tk_curve_vertex(c, tk_curve_vertex_index(c, b, j));
            const double *p4 = tk_curve_vertex(c, tk_curve_vertex_index(c, b, j + 1));
            sum += segment_pair(p1, p2, p3, p4);
        }
    }
    double value = sum / (4.0 * M_PI);
    if (gauss)
        *gauss = value;
    double nearest = round(value);
    if (!(fabs(value - nearest) <= LINKING_INTEGER_TOLERANCE))
        return tk_error_set(err, TK_ENUMERIC,
                            "the linking integral of components %zu and %zu is %.9g, not an "
                            "integer: they (nearly) touch",
                            a, b, value);
    *lk = (long)nearest;
    return TK_OK;
}
