/* tightknot: knot and link invariants (see include/tk/invariants.h). */
#include "tk/invariants.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"
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
/* Generic projections compared for the fewest crossings. */
#define DIAGRAMS_COMPARED 3
/* The determinant is computed modulo these primes (2^61 - 1 and
 * 2^59 - 55): two residues that agree on a value below 2^60 in magnitude
 * are that value. */
#define PRIME_A 2305843009213693951ULL
#define PRIME_B 576460752303423433ULL

typedef struct crossing {
    double under; /* position along the knot (edge index + parameter) */
    double over;
    int sign;     /* +1 when the under strand passes from right to left
                     of the over strand, looking down the projection */
} crossing;

/* An orthonormal frame (e1, e2 spanning the picture, e3 the height) from
 * a direction uniform on the sphere. */
static void frame(uint64_t *s, double e1[3], double e2[3], double e3[3])
{
    tk_rng_direction(s, e3);
    double a[3] = {fabs(e3[0]) < 0.9 ? 1.0 : 0.0, fabs(e3[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    unit_normal(e3, a, e1);
    tk_cross3(e3, e1, e2);
}

/* Whether the pictures of edges i and j (i < j, not neighbours) of the
 * projected polygons p (x, y and height of each vertex; edge i runs from
 * vertex i to vertex next[i]) cross, appended
 * to *list if they do; TK_ENUMERIC when the projection is not generic
 * there. */
static int test_pair(const double *p, const size_t *next, size_t i, size_t j, crossing **list,
                     size_t *m, size_t *cap, tk_error *err)
{
    const double *a = p + 3 * i, *b = p + 3 * next[i];
    const double *q = p + 3 * j, *d = p + 3 * next[j];
    double rx = b[0] - a[0], ry = b[1] - a[1], sx = d[0] - q[0], sy = d[1] - q[1];
    double den = rx * sy - ry * sx;
    double qx = q[0] - a[0], qy = q[1] - a[1];
    double scale = sqrt((rx * rx + ry * ry) * (sx * sx + sy * sy));
    if (fabs(den) <= GENERIC_MARGIN * scale) {
        /* parallel pictures: generic only if they are apart */
        if (fabs(qx * ry - qy * rx) <= GENERIC_MARGIN * (rx * rx + ry * ry))
            return TK_ENUMERIC; /* and on one line: they may overlap */
        return TK_OK;
    }
    double s = (qx * sy - qy * sx) / den, t = (qx * ry - qy * rx) / den;
    if (s < -GENERIC_MARGIN || s > 1.0 + GENERIC_MARGIN || t < -GENERIC_MARGIN ||
        t > 1.0 + GENERIC_MARGIN)
        return TK_OK;
    if (s < GENERIC_MARGIN || s > 1.0 - GENERIC_MARGIN || t < GENERIC_MARGIN ||
        t > 1.0 - GENERIC_MARGIN)
        return TK_ENUMERIC; /* through a vertex's picture */
    double zi = a[2] + s * (b[2] - a[2]), zj = q[2] + t * (d[2] - q[2]);
    if (fabs(zi - zj) <= GENERIC_MARGIN * (fabs(zi) + fabs(zj)))
        return TK_ENUMERIC; /* the strands meet: no over or under */
    if (*m == *cap) {
        size_t grown_cap = *cap ? 2 * *cap : 64;
        crossing *grown = realloc(*list, grown_cap * sizeof *grown);
        if (!grown)
            return tk_error_set(err, TK_ENOMEM, "out of memory for crossings");
        *list = grown;
        *cap = grown_cap;
    }
    double pi = (double)i + s, pj = (double)j + t;
    crossing *x = &(*list)[(*m)++];
    x->over = zi > zj ? pi : pj;
    x->under = zi > zj ? pj : pi;
    /* (over direction x under direction) . e3; den = r x s */
    x->sign = (zi > zj) == (den > 0.0) ? 1 : -1;
    return TK_OK;
}

/* A uniform grid over the projection's bounding box, each cell listing
 * the edges whose (slightly widened) boxes meet it: only edges sharing a
 * cell can cross, so finding the crossings costs about the number of
 * edges, not its square (100,000 vertices: seconds a projection
 * otherwise).  Cells are about two mean edges wide, at most about 4n of
 * them. */
typedef struct grid {
    double x0, y0, cell;
    size_t nx, ny;
    size_t *start;   /* ncells + 1 */
    size_t *edge;    /* the edges of cell k: edge[start[k] .. start[k + 1]) */
    double *box;     /* 4 per edge: x min, y min, x max, y max */
} grid;

static size_t grid_index(double v, double v0, double cell, size_t count)
{
    double k = floor((v - v0) / cell);
    return k < 0.0 ? 0 : k >= (double)count ? count - 1 : (size_t)k;
}

static void grid_free(grid *g)
{
    free(g->start);
    free(g->edge);
    free(g->box);
}

static int grid_build(const double *p, const size_t *next, size_t n, grid *g, tk_error *err)
{
    *g = (grid){0};
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, length = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *a = p + 3 * i, *b = p + 3 * next[i];
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], a[k]);
            hi[k] = fmax(hi[k], a[k]);
        }
        length += hypot(b[0] - a[0], b[1] - a[1]);
    }
    double w = hi[0] - lo[0], h = hi[1] - lo[1];
    double widen = GENERIC_MARGIN * (w + h) + 1e-300;
    g->cell = fmax(2.0 * length / (double)n, sqrt(w * h / (4.0 * (double)n)));
    if (!(g->cell > 0.0))
        g->cell = fmax(w + h, 1.0);
    g->x0 = lo[0];
    g->y0 = lo[1];
    g->nx = (size_t)fmin(floor(w / g->cell) + 1.0, 4.0 * (double)n + 1.0);
    g->ny = (size_t)fmin(floor(h / g->cell) + 1.0, 4.0 * (double)n + 1.0);
    size_t ncells = g->nx * g->ny;
    g->start = calloc(ncells + 1, sizeof *g->start);
    g->box = malloc(4 * n * sizeof *g->box);
    if (!g->start || !g->box)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a projection's grid");
    for (size_t i = 0; i < n; i++) {
        const double *a = p + 3 * i, *b = p + 3 * next[i];
        double *bx = g->box + 4 * i;
        bx[0] = fmin(a[0], b[0]) - widen;
        bx[1] = fmin(a[1], b[1]) - widen;
        bx[2] = fmax(a[0], b[0]) + widen;
        bx[3] = fmax(a[1], b[1]) + widen;
    }
    /* count, then place (counting sort by cell) */
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < n; i++) {
            const double *bx = g->box + 4 * i;
            size_t i0 = grid_index(bx[0], g->x0, g->cell, g->nx);
            size_t i1 = grid_index(bx[2], g->x0, g->cell, g->nx);
            size_t j0 = grid_index(bx[1], g->y0, g->cell, g->ny);
            size_t j1 = grid_index(bx[3], g->y0, g->cell, g->ny);
            for (size_t jy = j0; jy <= j1; jy++)
                for (size_t ix = i0; ix <= i1; ix++) {
                    size_t k = jy * g->nx + ix;
                    if (pass == 0)
                        g->start[k + 1]++;
                    else
                        g->edge[g->start[k]++] = i;
                }
        }
        if (pass == 0) {
            for (size_t k = 0; k < ncells; k++)
                g->start[k + 1] += g->start[k];
            g->edge = malloc((g->start[ncells] ? g->start[ncells] : 1) * sizeof *g->edge);
            if (!g->edge)
                return tk_error_set(err, TK_ENOMEM, "out of memory for a projection's grid");
        }
    }
    /* placing moved each start to the next cell's: shift back */
    for (size_t k = ncells; k > 0; k--)
        g->start[k] = g->start[k - 1];
    g->start[0] = 0;
    return TK_OK;
}

/* The crossings of closed components lo .. hi - 1 of c seen along e3:
 * for each pair of edges, not neighbours, whose pictures cross, where
 * the under and the over strand pass.  A position is the index of its
 * edge among the components' edges taken in order, plus the parameter
 * along it, so the positions of component lo + k run from
 * first[k] to first[k + 1] (first, hi - lo + 1 entries, may be NULL).
 * Returns TK_OK, TK_ENUMERIC for a projection that is not generic, or
 * TK_ENOMEM. */
static int find_crossings(const tk_curve *c, size_t lo, size_t hi, const double e1[3],
                          const double e2[3], const double e3[3], size_t *first, crossing **out,
                          size_t *count, tk_error *err)
{
    size_t n = 0;
    for (size_t k = lo; k < hi; k++)
        n += tk_curve_comp_vertices(c, k);
    double *p = malloc(3 * n * sizeof *p);
    size_t *next = malloc(n * sizeof *next);
    crossing *list = NULL;
    size_t m = 0, cap = 0;
    if (!p || !next) {
        free(p);
        free(next);
        return tk_error_set(err, TK_ENOMEM, "out of memory for a projection");
    }
    size_t at = 0;
    for (size_t k = lo; k < hi; k++) {
        size_t nk = tk_curve_comp_vertices(c, k);
        if (first)
            first[k - lo] = at;
        for (size_t i = 0; i < nk; i++) {
            const double *x = tk_curve_vertex(c, tk_curve_vertex_index(c, k, i));
            p[3 * (at + i)] = tk_dot3(x, e1);
            p[3 * (at + i) + 1] = tk_dot3(x, e2);
            p[3 * (at + i) + 2] = tk_dot3(x, e3);
            next[at + i] = i + 1 < nk ? at + i + 1 : at;
        }
        at += nk;
    }
    if (first)
        first[hi - lo] = n;
    grid g;
    int rc = grid_build(p, next, n, &g, err);
    for (size_t k = 0; !rc && k < g.nx * g.ny; k++)
        for (size_t u = g.start[k]; !rc && u < g.start[k + 1]; u++)
            for (size_t v = u + 1; !rc && v < g.start[k + 1]; v++) {
                size_t i = g.edge[u], j = g.edge[v];
                if (i > j) {
                    size_t t = i;
                    i = j;
                    j = t;
                }
                if (next[i] == j || next[j] == i)
                    continue; /* neighbours */
                const double *bi = g.box + 4 * i, *bj = g.box + 4 * j;
                double lx = fmax(bi[0], bj[0]), ly = fmax(bi[1], bj[1]);
                if (lx > fmin(bi[2], bj[2]) || ly > fmin(bi[3], bj[3]))
                    continue; /* boxes apart */
                /* a pair sharing several cells is tested in one: where
                 * its boxes' overlap begins */
                if (grid_index(ly, g.y0, g.cell, g.ny) * g.nx +
                        grid_index(lx, g.x0, g.cell, g.nx) !=
                    k)
                    continue;
                rc = test_pair(p, next, i, j, &list, &m, &cap, err);
            }
    grid_free(&g);
    free(p);
    free(next);
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

/* The arc a position lies on, among the arcs of one component whose
 * undercrossings are x[lo .. hi) (sorted, hi > lo): arc k runs from
 * undercrossing k to the next (cyclically), so it is the last
 * undercrossing at or before the position, and the last arc before the
 * first. */
static size_t arc_in(const crossing *x, size_t lo, size_t hi, double position)
{
    size_t start = lo, end = hi; /* first index whose under > position */
    while (start < end) {
        size_t mid = start + (end - start) / 2;
        if (x[mid].under <= position)
            start = mid + 1;
        else
            end = mid;
    }
    return start == lo ? hi - 1 : start - 1;
}

static size_t arc_of(const crossing *x, size_t m, double position)
{
    return arc_in(x, 0, m, position);
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

/* A diagram of closed components lo .. hi - 1: the crossings of the
 * fewest-crossing projection among the first DIAGRAMS_COMPARED generic
 * ones (drawn from seed), sorted by their undercrossings' positions
 * (find_crossings: component lo + k's run from first[k] to first[k + 1];
 * first may be NULL).  The invariants' cost grows with the crossings,
 * not the vertices.  `what` names the components in messages. */
static int diagram(const tk_curve *c, size_t lo, size_t hi, unsigned long long seed,
                   size_t *first, const char *what, crossing **out, size_t *count, tk_error *err)
{
    *out = NULL;
    *count = 0;
    for (size_t k = lo; k < hi; k++)
        if (k >= c->ncomp || !c->closed[k])
            return tk_error_set(err, TK_EINVAL,
                                "a knot or link invariant needs closed components (%zu is not)",
                                k);
    uint64_t state = seed;
    int generic = 0;
    for (int attempt = 0; attempt < PROJECTION_TRIES && generic < DIAGRAMS_COMPARED; attempt++) {
        double e1[3], e2[3], e3[3];
        frame(&state, e1, e2, e3);
        crossing *x = NULL;
        size_t m = 0;
        int rc = find_crossings(c, lo, hi, e1, e2, e3, first, &x, &m, err);
        if (rc == TK_ENUMERIC)
            continue;
        if (rc) {
            free(*out);
            *out = NULL;
            return rc;
        }
        if (generic++ == 0 || m < *count) {
            free(*out);
            *out = x;
            *count = m;
        } else {
            free(x);
        }
    }
    if (!generic)
        return tk_error_set(err, TK_ENUMERIC,
                            "no generic projection of %s in %d tries: strands (nearly) meet", what,
                            PROJECTION_TRIES);
    if (*count > TK_INVARIANT_MAX_CROSSINGS) {
        free(*out);
        *out = NULL;
        return tk_error_set(err, TK_ELIMIT,
                            "%s has %zu crossings in its simplest projection found, more than "
                            "the %d its invariants are computed for",
                            what, *count, TK_INVARIANT_MAX_CROSSINGS);
    }
    if (*count > 1)
        qsort(*out, *count, sizeof **out, by_under);
    return TK_OK;
}

/* The diagram of component comp alone (diagram), its crossing count
 * into *crossings (may be NULL), its name for messages into what. */
#define KNOT_NAME 48
static int knot_diagram(const tk_curve *c, size_t comp, unsigned long long seed,
                        char what[KNOT_NAME], crossing **x, size_t *m, size_t *crossings,
                        tk_error *err)
{
    snprintf(what, KNOT_NAME, "component %zu", comp);
    int rc = diagram(c, comp, comp + 1, seed, NULL, what, x, m, err);
    if (!rc && crossings)
        *crossings = *m;
    return rc;
}

/* |det| of the colouring matrix of a diagram less its last row and
 * column: the determinant of the knot or link it shows.  x holds its m
 * crossings sorted by undercrossing; the undercrossings of component k
 * are x[block[k] .. block[k + 1]), its positions run from first[k] to
 * first[k + 1], k < ncomp.  Every component must have an undercrossing.
 * Crossing i ends arc "in" (the one before it on its component) and
 * starts arc i; its over-arc is where the over strand lies.  Fox
 * colouring at t = -1: 2 over - in - out. */
static int colouring_determinant(const crossing *x, size_t m, const size_t *first,
                                 const size_t *block, size_t ncomp, const char *what,
                                 long long *det, tk_error *err)
{
    assert(m >= 2);
    size_t k = m - 1; /* the minor without the last row and column */
    long long *entries = calloc(m * m, sizeof *entries);
    long long *minor = calloc(k * k, sizeof *minor);
    unsigned long long *work = malloc(k * k * sizeof *work);
    if (!entries || !minor || !work) {
        free(entries);
        free(minor);
        free(work);
        return tk_error_set(err, TK_ENOMEM, "out of memory for %zu crossings", m);
    }
    size_t own = 0; /* the component of crossing i's undercrossing */
    for (size_t i = 0; i < m; i++) {
        while (i >= block[own + 1])
            own++;
        assert(block[own] < block[own + 1]);
        size_t top = 0; /* the component of its over strand */
        while (top + 1 < ncomp && x[i].over >= (double)first[top + 1])
            top++;
        size_t over = arc_in(x, block[top], block[top + 1], x[i].over);
        size_t in = i == block[own] ? block[own + 1] - 1 : i - 1, outgoing = i;
        entries[i * m + over] += 2;
        entries[i * m + in] -= 1;
        entries[i * m + outgoing] -= 1;
    }
    for (size_t r = 0; r < k; r++)
        for (size_t col = 0; col < k; col++)
            minor[r * k + col] = entries[r * m + col];
    long long va = symmetric(det_mod(minor, k, PRIME_A, work), PRIME_A);
    long long vb = symmetric(det_mod(minor, k, PRIME_B, work), PRIME_B);
    free(entries);
    free(work);
    free(minor);
    if (va != vb)
        return tk_error_set(err, TK_ENUMERIC, "the determinant of %s exceeds 2^59 (%zu crossings)",
                            what, m);
    *det = va < 0 ? -va : va;
    return TK_OK;
}

int tk_knot_determinant(const tk_curve *c, size_t comp, unsigned long long seed, long long *det,
                        size_t *crossings, tk_error *err)
{
    char what[KNOT_NAME];
    crossing *x = NULL;
    size_t m = 0;
    int rc = knot_diagram(c, comp, seed, what, &x, &m, crossings, err);
    if (rc)
        return rc;
    if (m < 2) {
        /* no crossing, or one (a kink): a diagram of the unknot */
        free(x);
        *det = 1;
        return TK_OK;
    }
    size_t first[2] = {0, tk_curve_comp_vertices(c, comp)}, block[2] = {0, m};
    rc = colouring_determinant(x, m, first, block, 1, what, det, err);
    free(x);
    return rc;
}

int tk_link_determinant(const tk_curve *c, unsigned long long seed, long long *det,
                        size_t *crossings, tk_error *err)
{
    size_t n = c->ncomp;
    if (n == 0)
        return tk_error_set(err, TK_EINVAL, "the link determinant needs a component");
    size_t *first = malloc((n + 1) * sizeof *first), *block = malloc((n + 1) * sizeof *block);
    crossing *x = NULL;
    size_t m = 0;
    int rc = first && block ? TK_OK : tk_error_set(err, TK_ENOMEM, "out of memory for a link");
    if (!rc)
        rc = diagram(c, 0, n, seed, first, "the link", &x, &m, err);
    if (!rc && crossings)
        *crossings = m;
    /* a component with no undercrossing lies above the rest and can be
     * lifted off them: the link is split, and its determinant 0 (so is a
     * diagram without crossings of two components or more) */
    bool split = false;
    for (size_t k = 0, i = 0; !rc && k <= n; k++) {
        while (i < m && k < n && x[i].under < (double)first[k])
            i++;
        block[k] = k == n ? m : i;
        if (k > 0 && block[k] == block[k - 1])
            split = true;
    }
    if (!rc) {
        if (n == 1 && m < 2)
            *det = 1; /* an unknot's diagram */
        else if (split)
            *det = 0;
        else
            rc = colouring_determinant(x, m, first, block, n, "the link", det, err);
    }
    free(first);
    free(block);
    free(x);
    return rc;
}

/* ---- the Alexander polynomial ---- */

/* Arithmetic modulo the Mersenne prime 2^61 - 1 (PRIME_A), reduced
 * without division. */
static uint64_t mul61(uint64_t a, uint64_t b)
{
    unsigned __int128 z = (unsigned __int128)a * b;
    uint64_t r = (uint64_t)(z & PRIME_A) + (uint64_t)(z >> 61);
    while (r >= PRIME_A)
        r -= PRIME_A;
    return r;
}

static uint64_t inv61(uint64_t a)
{
    uint64_t r = 1;
    for (uint64_t e = PRIME_A - 2; e; e >>= 1, a = mul61(a, a))
        if (e & 1)
            r = mul61(r, a);
    return r;
}

static uint64_t mod61(long long v)
{
    long long r = v % (long long)PRIME_A;
    return (uint64_t)(r < 0 ? r + (long long)PRIME_A : r);
}

/* The determinant of the k x k matrix a (residues, row major,
 * overwritten) modulo 2^61 - 1. */
static uint64_t det61(uint64_t *a, size_t k)
{
    uint64_t det = 1;
    for (size_t col = 0; col < k; col++) {
        size_t pivot = col;
        while (pivot < k && a[pivot * k + col] == 0)
            pivot++;
        if (pivot == k)
            return 0;
        if (pivot != col) {
            for (size_t j = col; j < k; j++) {
                uint64_t t = a[col * k + j];
                a[col * k + j] = a[pivot * k + j];
                a[pivot * k + j] = t;
            }
            det = det ? PRIME_A - det : 0;
        }
        det = mul61(det, a[col * k + col]);
        uint64_t inv = inv61(a[col * k + col]);
        for (size_t r = col + 1; r < k; r++) {
            uint64_t f = mul61(a[r * k + col], inv);
            if (!f)
                continue;
            for (size_t j = col; j < k; j++) {
                uint64_t sub = mul61(f, a[col * k + j]);
                a[r * k + j] = a[r * k + j] >= sub ? a[r * k + j] - sub
                                                    : a[r * k + j] + PRIME_A - sub;
            }
        }
    }
    return det;
}

/* The polynomial of degree < m through (t_j, v_j), t_j = j + 2, modulo
 * 2^61 - 1, as coefficients of 1, t, ... (Newton's divided differences,
 * then expanded): O(m^2). */
static void interpolate61(uint64_t *v, size_t m, uint64_t *coeff)
{
    for (size_t level = 1; level < m; level++)
        for (size_t j = m - 1; j >= level; j--) {
            uint64_t num = v[j] >= v[j - 1] ? v[j] - v[j - 1] : v[j] + PRIME_A - v[j - 1];
            v[j] = mul61(num, inv61((uint64_t)level)); /* t_j - t_{j-level} = level */
        }
    /* Horner on the Newton form: p = v0 + (t - t0)(v1 + (t - t1)(...)) */
    for (size_t i = 0; i < m; i++)
        coeff[i] = 0;
    for (size_t j = m; j-- > 0;) {
        /* coeff <- coeff * (t - t_j) + v_j */
        uint64_t tj = (uint64_t)j + 2;
        for (size_t i = m - 1; i > 0; i--) {
            uint64_t sub = mul61(coeff[i], tj);
            uint64_t x = coeff[i - 1];
            coeff[i] = x >= sub ? x - sub : x + PRIME_A - sub;
        }
        uint64_t sub = mul61(coeff[0], tj);
        coeff[0] = v[j] >= sub ? v[j] - sub : v[j] + PRIME_A - sub;
    }
}

int tk_knot_alexander(const tk_curve *c, size_t comp, unsigned long long seed,
                      long long coeff[TK_ALEXANDER_MAX_DEGREE + 1], int *degree,
                      size_t *crossings, tk_error *err)
{
    char what[KNOT_NAME];
    crossing *x = NULL;
    size_t m = 0;
    int rc = knot_diagram(c, comp, seed, what, &x, &m, crossings, err);
    if (rc)
        return rc;
    if (m < 2) {
        free(x);
        coeff[0] = 1;
        *degree = 0;
        return TK_OK;
    }
    /* Row i of the Alexander matrix (Fox calculus on the Wirtinger
     * relation at crossing i, abelianised): (1 - t) in the over-arc's
     * column; t and -1 in the columns of the arcs ending and starting
     * there, in that order for a positive crossing and swapped for a
     * negative one.  Any minor of order m - 1 is +-t^s Delta(t). */
    size_t k = m - 1;
    size_t *over = malloc(m * sizeof *over);
    uint64_t *a = malloc(k * k * sizeof *a);
    uint64_t *v = malloc(m * sizeof *v);
    uint64_t *p = malloc(m * sizeof *p);
    if (!over || !a || !v || !p) {
        rc = tk_error_set(err, TK_ENOMEM, "out of memory for %zu crossings", m);
        goto done;
    }
    for (size_t i = 0; i < m; i++)
        over[i] = arc_of(x, m, x[i].over);
    for (size_t j = 0; j < m; j++) {
        long long t = (long long)j + 2;
        for (size_t i = 0; i < k * k; i++)
            a[i] = 0;
        for (size_t i = 0; i < k; i++) {
            size_t in = (i + m - 1) % m, out = i;
            long long entry[3] = {1 - t, x[i].sign > 0 ? t : -1, x[i].sign > 0 ? -1 : t};
            size_t column[3] = {over[i], in, out};
            for (int e = 0; e < 3; e++)
                if (column[e] < k)
                    a[i * k + column[e]] = (a[i * k + column[e]] + mod61(entry[e])) % PRIME_A;
        }
        v[j] = det61(a, k);
    }
    interpolate61(v, m, p);
    /* +-t^s Delta: strip the power of t, read the coefficients as small
     * integers, then the sign that makes Delta(1) = 1. */
    size_t low = 0, high = m - 1;
    while (low < m && p[low] == 0)
        low++;
    if (low == m) {
        rc = tk_error_set(err, TK_ENUMERIC,
                          "component %zu: the Alexander matrix of a %zu-crossing projection is "
                          "singular, which no knot diagram's is",
                          comp, m);
        goto done;
    }
    while (p[high] == 0)
        high--;
    if (high - low > TK_ALEXANDER_MAX_DEGREE) {
        rc = tk_error_set(err, TK_ELIMIT,
                          "component %zu: the Alexander polynomial has degree %zu, more than "
                          "%d",
                          comp, high - low, TK_ALEXANDER_MAX_DEGREE);
        goto done;
    }
    *degree = (int)(high - low);
    long long at_one = 0;
    for (size_t i = low; i <= high; i++) {
        coeff[i - low] = symmetric(p[i], PRIME_A);
        at_one += coeff[i - low];
    }
    for (int i = 0; i <= *degree; i++) {
        if (at_one < 0)
            coeff[i] = -coeff[i];
        /* a knot's polynomial is symmetric and Delta(1) = +-1: anything
         * else is a coefficient beyond 2^60 or a broken diagram */
        if (coeff[i] != (at_one < 0 ? -1 : 1) * symmetric(p[high - (size_t)i], PRIME_A) ||
            (at_one != 1 && at_one != -1)) {
            rc = tk_error_set(err, TK_ENUMERIC,
                              "component %zu: the Alexander polynomial from a %zu-crossing "
                              "projection is not a knot's (Delta(1) = %lld)",
                              comp, m, at_one);
            goto done;
        }
    }
done:
    free(x);
    free(over);
    free(a);
    free(v);
    free(p);
    return rc;
}

/* ---- the type of a curve ---- */

/* The seed of the projections: any gives the same invariants. */
#define INVARIANT_SEED 1

void tk_invariants_free(tk_invariants *inv)
{
    free(inv->knot);
    free(inv->linking);
    *inv = (tk_invariants)TK_INVARIANTS_INIT;
}

int tk_invariants_compute(const tk_curve *c, tk_invariants *out, tk_error *err)
{
    tk_invariants_free(out);
    size_t n = c->ncomp;
    out->knot = calloc(n, sizeof *out->knot);
    out->linking = calloc(n * n, sizeof *out->linking);
    if (!out->knot || !out->linking) {
        tk_invariants_free(out);
        return tk_error_set(err, TK_ENOMEM, "out of memory for the invariants");
    }
    out->ncomp = n;
    out->complete = true;
    int rc = TK_OK;
    for (size_t a = 0; a < n && !rc; a++) {
        tk_knot_type *k = &out->knot[a];
        if (!c->closed[a])
            continue;
        rc = tk_knot_alexander(c, a, INVARIANT_SEED, k->alexander, &k->degree, NULL, err);
        if (rc == TK_ELIMIT) {
            out->complete = false;
            rc = TK_OK;
            continue;
        }
        if (rc)
            break;
        k->known = true;
        long long at_minus_one = 0;
        for (int i = 0; i <= k->degree; i++)
            at_minus_one += (i % 2 ? -1 : 1) * k->alexander[i];
        k->determinant = at_minus_one < 0 ? -at_minus_one : at_minus_one;
    }
    for (size_t a = 0; a < n && !rc; a++)
        for (size_t b = a + 1; b < n && !rc && c->closed[a]; b++) {
            if (!c->closed[b])
                continue;
            long lk = 0;
            rc = tk_linking_number(c, a, b, &lk, NULL, err);
            out->linking[a * n + b] = out->linking[b * n + a] = lk;
        }
    /* the link's own determinant tells apart links whose components and
     * linking numbers agree; a knot's is its component's */
    bool all_closed = true;
    for (size_t a = 0; a < n; a++)
        all_closed = all_closed && c->closed[a];
    if (!rc && n == 1) {
        out->link_known = out->knot[0].known;
        out->link_determinant = out->knot[0].determinant;
    } else if (!rc && n > 1 && all_closed) {
        rc = tk_link_determinant(c, INVARIANT_SEED, &out->link_determinant, NULL, err);
        out->link_known = rc == TK_OK;
        if (rc == TK_ELIMIT) {
            out->complete = false;
            rc = TK_OK;
        }
    }
    if (rc)
        tk_invariants_free(out);
    return rc;
}

int tk_invariants_copy(const tk_invariants *src, tk_invariants *out, tk_error *err)
{
    tk_invariants_free(out);
    size_t n = src->ncomp;
    if (!n)
        return TK_OK;
    out->knot = malloc(n * sizeof *out->knot);
    out->linking = malloc(n * n * sizeof *out->linking);
    if (!out->knot || !out->linking) {
        tk_invariants_free(out);
        return tk_error_set(err, TK_ENOMEM, "out of memory for the invariants");
    }
    memcpy(out->knot, src->knot, n * sizeof *out->knot);
    memcpy(out->linking, src->linking, n * n * sizeof *out->linking);
    out->ncomp = n;
    out->link_known = src->link_known;
    out->link_determinant = src->link_determinant;
    out->complete = src->complete;
    return TK_OK;
}

void tk_alexander_format(const tk_knot_type *k, char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i <= k->degree && used < size; i++) {
        long long c = k->alexander[i];
        if (c == 0)
            continue;
        long long mag = c < 0 ? -c : c;
        const char *sign = used == 0 ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + ");
        char coefficient[32] = "";
        if (mag != 1 || i == 0)
            snprintf(coefficient, sizeof coefficient, "%lld", mag);
        char power[32] = "";
        if (i == 1)
            snprintf(power, sizeof power, "t");
        else if (i > 1)
            snprintf(power, sizeof power, "t^%d", i);
        int w = snprintf(buf + used, size - used, "%s%s%s", sign, coefficient, power);
        used += w > 0 ? (size_t)w : 0;
    }
}

int tk_invariants_compare(const tk_invariants *was, const tk_invariants *now, tk_error *err)
{
    if (was->ncomp != now->ncomp)
        return tk_error_set(err, TK_ETYPE, "the curve had %zu components, now %zu", was->ncomp,
                            now->ncomp);
    size_t n = was->ncomp;
    for (size_t a = 0; a < n; a++) {
        const tk_knot_type *x = &was->knot[a], *y = &now->knot[a];
        if (!x->known || !y->known)
            continue;
        bool same = x->degree == y->degree;
        for (int i = 0; same && i <= x->degree; i++)
            same = x->alexander[i] == y->alexander[i];
        if (!same) {
            char before[160], after[160];
            tk_alexander_format(x, before, sizeof before);
            tk_alexander_format(y, after, sizeof after);
            return tk_error_set(err, TK_ETYPE,
                                "the knot type of component %zu changed: its Alexander polynomial "
                                "was %s, now %s",
                                a, before, after);
        }
    }
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n; b++)
            if (was->linking[a * n + b] != now->linking[a * n + b])
                return tk_error_set(err, TK_ETYPE,
                                    "the link type changed: the linking number of components "
                                    "%zu and %zu was %ld, now %ld",
                                    a, b, was->linking[a * n + b], now->linking[a * n + b]);
    if (was->link_known && now->link_known && was->link_determinant != now->link_determinant)
        return tk_error_set(err, TK_ETYPE,
                            "the link type changed: its determinant was %lld, now %lld",
                            was->link_determinant, now->link_determinant);
    return TK_OK;
}
