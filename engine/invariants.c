/* tightknot: knot and link invariants (see include/tk/invariants.h). */
#include "tk/invariants.h"

#include <math.h>
#include <stdlib.h>

#include "tk/geometry.h"

/* The linking integral of two polygons is exact within rounding: a sum
 * further than this from an integer means the polygons (nearly) touch. */
#define LINKING_INTEGER_TOLERANCE 1e-6

/* The unit normal of the plane through the origin spanned by u and v, or
 * zero when they are parallel. */
static void unit_normal(const double *u, const double *v, double *n)
{
    tk_cross3(u, v, n);
    double len = sqrt(tk_dot3(n, n));
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
    tk_sub3(p3, p1, r13);
    tk_sub3(p4, p1, r14);
    tk_sub3(p3, p2, r23);
    tk_sub3(p4, p2, r24);
    tk_sub3(p2, p1, r12);
    tk_sub3(p4, p3, r34);
    double n1[3], n2[3], n3[3], n4[3];
    unit_normal(r13, r14, n1);
    unit_normal(r14, r24, n2);
    unit_normal(r24, r23, n3);
    unit_normal(r23, r13, n4);
    double omega = clamped_asin(tk_dot3(n1, n2)) + clamped_asin(tk_dot3(n2, n3)) +
                   clamped_asin(tk_dot3(n3, n4)) + clamped_asin(tk_dot3(n4, n1));
    double orient[3];
    tk_cross3(r34, r12, orient);
    double s = tk_dot3(orient, r13);
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

/* ---- the knot determinant ---- */

/* Projections tried before giving up on finding a generic one. */
#define PROJECTION_TRIES 8
/* A crossing this close (in edge parameter) to a vertex, or edges this
 * close to parallel, make the projection not generic: another is tried. */
#define GENERIC_MARGIN 1e-9
/* The determinant is computed modulo these primes (2^61 - 1 and
 * 2^59 - 55): two residues that agree on a value below 2^60 in magnitude
 * are that value. */
#define PRIME_A 2305843009213693951ULL
#define PRIME_B 576460752303423433ULL

typedef struct crossing {
    double under; /* position along the knot (edge index + parameter) */
    double over;
} crossing;

/* splitmix64: a direction from a seed, without shared state. */
static unsigned long long mix(unsigned long long *s)
{
    unsigned long long z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* An orthonormal frame (e1, e2 spanning the picture, e3 the height) from
 * a direction uniform on the sphere. */
static void frame(unsigned long long *s, double e1[3], double e2[3], double e3[3])
{
    double u = (double)(mix(s) >> 11) / 9007199254740992.0;
    double v = (double)(mix(s) >> 11) / 9007199254740992.0;
    double z = 2.0 * u - 1.0, r = sqrt(fmax(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * v;
    e3[0] = r * cos(phi);
    e3[1] = r * sin(phi);
    e3[2] = z;
    double a[3] = {fabs(e3[0]) < 0.9 ? 1.0 : 0.0, fabs(e3[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    unit_normal(e3, a, e1);
    tk_cross3(e3, e1, e2);
}

/* The crossings of the knot seen along e3: for each pair of non-adjacent
 * edges whose pictures cross, where along the knot the under and the over
 * strand pass.  Returns TK_OK, TK_ENUMERIC for a projection that is not
 * generic, or TK_ENOMEM. */
static int find_crossings(const tk_curve *c, size_t comp, const double e1[3], const double e2[3],
                          const double e3[3], crossing **out, size_t *count, tk_error *err)
{
    size_t n = tk_curve_comp_vertices(c, comp);
    double *p = malloc(3 * n * sizeof *p);
    crossing *list = NULL;
    size_t m = 0, cap = 0;
    if (!p)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a projection");
    for (size_t i = 0; i < n; i++) {
        const double *x = tk_curve_vertex(c, tk_curve_vertex_index(c, comp, i));
        p[3 * i] = tk_dot3(x, e1);
        p[3 * i + 1] = tk_dot3(x, e2);
        p[3 * i + 2] = tk_dot3(x, e3);
    }
    int rc = TK_OK;
    for (size_t i = 0; i < n && !rc; i++) {
        const double *a = p + 3 * i, *b = p + 3 * ((i + 1) % n);
        for (size_t j = i + 2; j < n && !rc; j++) {
            if (i == 0 && j == n - 1)
                continue; /* neighbours across the closing vertex */
            const double *q = p + 3 * j, *d = p + 3 * ((j + 1) % n);
            double rx = b[0] - a[0], ry = b[1] - a[1], sx = d[0] - q[0], sy = d[1] - q[1];
            double den = rx * sy - ry * sx;
            double qx = q[0] - a[0], qy = q[1] - a[1];
            double scale = sqrt((rx * rx + ry * ry) * (sx * sx + sy * sy));
            if (fabs(den) <= GENERIC_MARGIN * scale) {
                /* parallel pictures: generic only if they are apart */
                if (fabs(qx * ry - qy * rx) <= GENERIC_MARGIN * (rx * rx + ry * ry))
                    rc = TK_ENUMERIC; /* and on one line: they may overlap */
                continue;
            }
            double s = (qx * sy - qy * sx) / den, t = (qx * ry - qy * rx) / den;
            if (s < -GENERIC_MARGIN || s > 1.0 + GENERIC_MARGIN || t < -GENERIC_MARGIN ||
                t > 1.0 + GENERIC_MARGIN)
                continue;
            if (s < GENERIC_MARGIN || s > 1.0 - GENERIC_MARGIN || t < GENERIC_MARGIN ||
                t > 1.0 - GENERIC_MARGIN) {
                rc = TK_ENUMERIC; /* through a vertex's picture */
                continue;
            }
            double zi = a[2] + s * (b[2] - a[2]), zj = q[2] + t * (d[2] - q[2]);
            if (fabs(zi - zj) <= GENERIC_MARGIN * (fabs(zi) + fabs(zj))) {
                rc = TK_ENUMERIC; /* the strands meet: no over or under */
                continue;
            }
            if (m == cap) {
                size_t grown_cap = cap ? 2 * cap : 64;
                crossing *grown = realloc(list, grown_cap * sizeof *grown);
                if (!grown) {
                    rc = tk_error_set(err, TK_ENOMEM, "out of memory for crossings");
                    break;
                }
                list = grown;
                cap = grown_cap;
            }
            double pi = (double)i + s, pj = (double)j + t;
            list[m].over = zi > zj ? pi : pj;
            list[m].under = zi > zj ? pj : pi;
            m++;
        }
    }
    free(p);
    if (rc) {
        free(list);
        return rc;
    }
    *out = list;
    *count = m;
    return TK_OK;
}

static int by_under(const void *pa, const void *pb)
{
    double a = ((const crossing *)pa)->under, b = ((const crossing *)pb)->under;
    return a < b ? -1 : (a > b ? 1 : 0);
}

/* The arc a position lies on: arc k runs from undercrossing k to k+1
 * (cyclically), so it is the last undercrossing at or before the
 * position, and the last arc before the first. */
static size_t arc_of(const crossing *x, size_t m, double position)
{
    size_t lo = 0, hi = m; /* first index whose under > position */
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (x[mid].under <= position)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo == 0 ? m - 1 : lo - 1;
}

static unsigned long long mulmod(unsigned long long a, unsigned long long b,
                                 unsigned long long p)
{
    return (unsigned long long)((unsigned __int128)a * b % p);
}

static unsigned long long powmod(unsigned long long a, unsigned long long e,
                                 unsigned long long p)
{
    unsigned long long r = 1;
    for (; e; e >>= 1, a = mulmod(a, a, p))
        if (e & 1)
            r = mulmod(r, a, p);
    return r;
}

/* The determinant of the k x k matrix a (entries small integers, row
 * major, overwritten) modulo the prime p, by elimination. */
static unsigned long long det_mod(long long *entries, size_t k, unsigned long long p,
                                  unsigned long long *a)
{
    for (size_t i = 0; i < k * k; i++) {
        long long v = entries[i] % (long long)p;
        a[i] = (unsigned long long)(v < 0 ? v + (long long)p : v);
    }
    unsigned long long det = 1;
    for (size_t col = 0; col < k; col++) {
        size_t pivot = col;
        while (pivot < k && a[pivot * k + col] == 0)
            pivot++;
        if (pivot == k)
            return 0;
        if (pivot != col) {
            for (size_t j = 0; j < k; j++) {
                unsigned long long t = a[col * k + j];
                a[col * k + j] = a[pivot * k + j];
                a[pivot * k + j] = t;
            }
            det = det ? p - det : 0; /* a row swap negates */
        }
        unsigned long long d = a[col * k + col];
        det = mulmod(det, d, p);
        unsigned long long inv = powmod(d, p - 2, p);
        for (size_t r = col + 1; r < k; r++) {
            unsigned long long f = mulmod(a[r * k + col], inv, p);
            if (!f)
                continue;
            for (size_t j = col; j < k; j++)
                a[r * k + j] = (a[r * k + j] + p - mulmod(f, a[col * k + j], p)) % p;
        }
    }
    return det;
}

/* The residue r modulo p read as an integer of magnitude below p / 2. */
static long long symmetric(unsigned long long r, unsigned long long p)
{
    return r > p / 2 ? -(long long)(p - r) : (long long)r;
}

int tk_knot_determinant(const tk_curve *c, size_t comp, unsigned long long seed, long long *det,
                        size_t *crossings, tk_error *err)
{
    if (comp >= c->ncomp || !c->closed[comp])
        return tk_error_set(err, TK_EINVAL, "the determinant needs a closed component (%zu)",
                            comp);
    crossing *x = NULL;
    size_t m = 0;
    int rc = TK_ENUMERIC;
    unsigned long long state = seed;
    for (int attempt = 0; attempt < PROJECTION_TRIES && rc == TK_ENUMERIC; attempt++) {
        double e1[3], e2[3], e3[3];
        frame(&state, e1, e2, e3);
        rc = find_crossings(c, comp, e1, e2, e3, &x, &m, err);
    }
    if (rc == TK_ENUMERIC)
        return tk_error_set(err, TK_ENUMERIC,
                            "no generic projection of component %zu in %d tries: strands (nearly) "
                            "meet",
                            comp, PROJECTION_TRIES);
    if (rc)
        return rc;
    if (crossings)
        *crossings = m;
    if (m < 2) {
        /* no crossing, or one (a kink): a diagram of the unknot */
        free(x);
        *det = 1;
        return TK_OK;
    }
    qsort(x, m, sizeof *x, by_under);
    size_t k = m - 1; /* the minor without the last row and column */
    long long *entries = calloc(m * m, sizeof *entries);
    unsigned long long *work = malloc(k * k * sizeof *work);
    if (!entries || !work) {
        free(x);
        free(entries);
        free(work);
        return tk_error_set(err, TK_ENOMEM, "out of memory for %zu crossings", m);
    }
    /* Crossing i (sorted by its undercrossing) ends arc i - 1 and starts
     * arc i; its over-arc is where the over strand lies.  Fox colouring at
     * t = -1: 2 over - in - out. */
    for (size_t i = 0; i < m; i++) {
        size_t over = arc_of(x, m, x[i].over);
        size_t in = (i + m - 1) % m, outgoing = i;
        entries[i * m + over] += 2;
        entries[i * m + in] -= 1;
        entries[i * m + outgoing] -= 1;
    }
    long long *minor = calloc(k * k, sizeof *minor);
    if (!minor) {
        free(x);
        free(entries);
        free(work);
        return tk_error_set(err, TK_ENOMEM, "out of memory for %zu crossings", m);
    }
    for (size_t r = 0; r < k; r++)
        for (size_t col = 0; col < k; col++)
            minor[r * k + col] = entries[r * m + col];
    long long va = symmetric(det_mod(minor, k, PRIME_A, work), PRIME_A);
    long long vb = symmetric(det_mod(minor, k, PRIME_B, work), PRIME_B);
    free(x);
    free(entries);
    free(work);
    free(minor);
    if (va != vb)
        return tk_error_set(err, TK_ENUMERIC,
                            "the determinant of component %zu exceeds 2^59 (%zu crossings)", comp,
                            m);
    *det = va < 0 ? -va : va;
    return TK_OK;
}
