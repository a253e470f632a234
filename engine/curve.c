#include "tk/curve.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int tk_curve_new(tk_curve **out, size_t ncomp, const size_t *counts,
                 const bool *closed, tk_error *err)
{
    *out = NULL;
    if (ncomp == 0)
        return tk_error_set(err, TK_EINVAL, "a curve needs at least one component");
    size_t total = 0;
    for (size_t i = 0; i < ncomp; i++) {
        if (counts[i] > SIZE_MAX / 3 / sizeof(double) - total)
            return tk_error_set(err, TK_ELIMIT, "too many vertices");
        total += counts[i];
    }
    tk_curve *c = calloc(1, sizeof *c);
    if (!c)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    c->ncomp = ncomp;
    c->nvert = total;
    c->offset = malloc((ncomp + 1) * sizeof *c->offset);
    c->closed = malloc(ncomp * sizeof *c->closed);
    c->xyz = calloc(total > 0 ? 3 * total : 1, sizeof *c->xyz);
    if (!c->offset || !c->closed || !c->xyz) {
        tk_curve_free(&c);
        return tk_error_set(err, TK_ENOMEM, "out of memory for %zu vertices", total);
    }
    c->offset[0] = 0;
    for (size_t i = 0; i < ncomp; i++) {
        c->offset[i + 1] = c->offset[i] + counts[i];
        c->closed[i] = closed[i];
    }
    *out = c;
    return TK_OK;
}

void tk_curve_free(tk_curve **p)
{
    if (!p || !*p)
        return;
    tk_curve *c = *p;
    free(c->offset);
    free(c->closed);
    free(c->xyz);
    free(c->colour);
    free(c->pins);
    free(c);
    *p = NULL;
}

int tk_curve_copy(const tk_curve *src, tk_curve **out, tk_error *err)
{
    size_t *counts = malloc(src->ncomp * sizeof *counts);
    if (!counts)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    for (size_t i = 0; i < src->ncomp; i++)
        counts[i] = tk_curve_comp_vertices(src, i);
    int rc = tk_curve_new(out, src->ncomp, counts, src->closed, err);
    free(counts);
    if (rc)
        return rc;
    memcpy((*out)->xyz, src->xyz, 3 * src->nvert * sizeof *src->xyz);
    if (src->has_colour && src->colour) {
        (*out)->colour = malloc(4 * src->ncomp * sizeof *src->colour);
        if (!(*out)->colour) {
            tk_curve_free(out);
            return tk_error_set(err, TK_ENOMEM, "out of memory");
        }
        memcpy((*out)->colour, src->colour, 4 * src->ncomp * sizeof *src->colour);
        (*out)->has_colour = true;
    }
    if (src->npins) {
        (*out)->pins = malloc(src->npins * sizeof *src->pins);
        if (!(*out)->pins) {
            tk_curve_free(out);
            return tk_error_set(err, TK_ENOMEM, "out of memory");
        }
        memcpy((*out)->pins, src->pins, src->npins * sizeof *src->pins);
        (*out)->npins = src->npins;
    }
    return TK_OK;
}

/* The pins of src on `out`, resampled from it: a pinned vertex goes to the
 * vertex at its share of the component's vertices (an open component's
 * ends to its ends), and onto its constraint. */
static int carry_pins(const tk_curve *src, tk_curve *out, tk_error *err)
{
    if (!src->npins)
        return TK_OK;
    out->pins = malloc(src->npins * sizeof *src->pins);
    if (!out->pins)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    for (size_t i = 0; i < src->npins; i++) {
        tk_pin p = src->pins[i];
        size_t n = tk_curve_comp_vertices(src, p.comp), m = tk_curve_comp_vertices(out, p.comp);
        if (!src->closed[p.comp])
            p.vertex = (size_t)llround((double)p.vertex * (double)(m - 1) / (double)(n - 1));
        else
            p.vertex = (size_t)llround((double)p.vertex * (double)m / (double)n) % m;
        if (tk_curve_pin_of(out, out->offset[p.comp] + p.vertex))
            return tk_error_set(err, TK_EINVAL,
                                "resampled to %zu vertices, component %zu has two constraints "
                                "on its vertex %zu",
                                m, p.comp, p.vertex);
        out->pins[out->npins++] = p;
    }
    tk_curve_pins_snap(out);
    return TK_OK;
}

size_t tk_curve_comp_vertices(const tk_curve *c, size_t comp)
{
    return c->offset[comp + 1] - c->offset[comp];
}

size_t tk_curve_comp_edges(const tk_curve *c, size_t comp)
{
    size_t n = tk_curve_comp_vertices(c, comp);
    if (c->closed[comp])
        return n;
    return n > 0 ? n - 1 : 0;
}

size_t tk_curve_edge_count(const tk_curve *c)
{
    size_t e = 0;
    for (size_t i = 0; i < c->ncomp; i++)
        e += tk_curve_comp_edges(c, i);
    return e;
}

size_t tk_curve_comp_first_edge(const tk_curve *c, size_t comp)
{
    size_t e = 0;
    for (size_t i = 0; i < comp; i++)
        e += tk_curve_comp_edges(c, i);
    return e;
}

tk_edge tk_curve_edge(const tk_curve *c, size_t global_edge)
{
    tk_edge e = {0, 0, 0, 0};
    size_t first = 0;
    for (size_t i = 0; i < c->ncomp; i++) {
        size_t ne = tk_curve_comp_edges(c, i);
        if (global_edge < first + ne) {
            e.comp = i;
            e.index = global_edge - first;
            e.head = c->offset[i] + e.index;
            e.tail = tk_curve_vertex_index(c, i, e.index + 1);
            return e;
        }
        first += ne;
    }
    return e;
}

size_t tk_curve_vertex_index(const tk_curve *c, size_t comp, size_t k)
{
    size_t n = tk_curve_comp_vertices(c, comp);
    if (c->closed[comp] && n > 0)
        k %= n;
    return c->offset[comp] + k;
}

static double distance3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

double tk_curve_edge_length(const tk_curve *c, size_t comp, size_t index)
{
    size_t a = tk_curve_vertex_index(c, comp, index);
    size_t b = tk_curve_vertex_index(c, comp, index + 1);
    return distance3(c->xyz + 3 * a, c->xyz + 3 * b);
}

double tk_curve_comp_length(const tk_curve *c, size_t comp)
{
    double sum = 0.0;
    size_t ne = tk_curve_comp_edges(c, comp);
    for (size_t k = 0; k < ne; k++)
        sum += tk_curve_edge_length(c, comp, k);
    return sum;
}

double tk_curve_length(const tk_curve *c)
{
    double sum = 0.0;
    for (size_t i = 0; i < c->ncomp; i++)
        sum += tk_curve_comp_length(c, i);
    return sum;
}

void tk_curve_edge_range(const tk_curve *c, double *shortest, double *longest)
{
    double lo = INFINITY, hi = 0.0;
    for (size_t i = 0; i < c->ncomp; i++) {
        size_t ne = tk_curve_comp_edges(c, i);
        for (size_t k = 0; k < ne; k++) {
            double l = tk_curve_edge_length(c, i, k);
            lo = fmin(lo, l);
            hi = fmax(hi, l);
        }
    }
    if (shortest)
        *shortest = lo;
    if (longest)
        *longest = hi;
}

/* y = R x for a row-major R */
static void rotate3(const double r[9], double *x)
{
    double y0 = r[0] * x[0] + r[1] * x[1] + r[2] * x[2];
    double y1 = r[3] * x[0] + r[4] * x[1] + r[5] * x[2];
    double y2 = r[6] * x[0] + r[7] * x[1] + r[8] * x[2];
    x[0] = y0;
    x[1] = y1;
    x[2] = y2;
}

/* The pins move with the curve: their points, planes and lines are where
 * the curve is. */
void tk_curve_translate(tk_curve *c, const double shift[3])
{
    for (size_t v = 0; v < c->nvert; v++)
        for (int k = 0; k < 3; k++)
            c->xyz[3 * v + k] += shift[k];
    for (size_t i = 0; i < c->npins; i++) {
        tk_pin *p = &c->pins[i];
        for (int k = 0; k < 3; k++)
            p->point[k] += shift[k];
        p->offset += p->normal[0] * shift[0] + p->normal[1] * shift[1] + p->normal[2] * shift[2];
    }
}

void tk_curve_rotate(tk_curve *c, const double r[9])
{
    for (size_t v = 0; v < c->nvert; v++)
        rotate3(r, c->xyz + 3 * v);
    for (size_t i = 0; i < c->npins; i++) {
        rotate3(r, c->pins[i].point);
        rotate3(r, c->pins[i].normal);
    }
}

void tk_curve_scale(tk_curve *c, double factor)
{
    for (size_t i = 0; i < 3 * c->nvert; i++)
        c->xyz[i] *= factor;
    for (size_t i = 0; i < c->npins; i++) {
        tk_pin *p = &c->pins[i];
        for (int k = 0; k < 3; k++)
            p->point[k] *= factor;
        p->offset *= factor;
    }
}

void tk_curve_centroid(const tk_curve *c, double centre[3])
{
    double s[3] = {0, 0, 0};
    for (size_t v = 0; v < c->nvert; v++)
        for (int k = 0; k < 3; k++)
            s[k] += c->xyz[3 * v + k];
    for (int k = 0; k < 3; k++)
        centre[k] = c->nvert ? s[k] / (double)c->nvert : 0.0;
}

/* tk_curve_validate, and with `range` also the engine's magnitudes, in
 * one pass: measuring runs this on every step of a flow. */
static int check_curve(const tk_curve *c, bool range, tk_error *err)
{
    if (c->ncomp == 0)
        return tk_error_set(err, TK_EINVAL, "the curve has no components");
    for (size_t i = 0; i < c->ncomp; i++) {
        size_t n = tk_curve_comp_vertices(c, i);
        if (c->closed[i] && n < 3)
            return tk_error_set(err, TK_EINVAL,
                                "component %zu is closed with %zu vertices (needs at least 3)",
                                i, n);
        if (!c->closed[i] && n < 2)
            return tk_error_set(err, TK_EINVAL,
                                "component %zu is open with %zu vertex (needs at least 2)",
                                i, n);
        for (size_t k = 0; k < n; k++) {
            const double *x = c->xyz + 3 * (c->offset[i] + k);
            for (int a = 0; a < 3; a++) {
                if (!isfinite(x[a]))
                    return tk_error_set(err, TK_EINVAL,
                                        "component %zu vertex %zu has a non-finite coordinate",
                                        i, k);
                if (range && !(fabs(x[a]) <= TK_CURVE_COORD_MAX))
                    return tk_error_set(err, TK_EINVAL,
                                        "component %zu vertex %zu has coordinate %c = %g, "
                                        "beyond the +-%g the engine measures in: scale the "
                                        "curve down",
                                        i, k, "xyz"[a], x[a], TK_CURVE_COORD_MAX);
            }
        }
        size_t ne = tk_curve_comp_edges(c, i);
        for (size_t k = 0; k < ne; k++) {
            double l = tk_curve_edge_length(c, i, k);
            if (!(l > 0.0))
                return tk_error_set(err, TK_EINVAL,
                                    "component %zu: vertices %zu and %zu coincide (zero-length edge)",
                                    i, k, (k + 1) % n);
            if (range && !(l >= TK_CURVE_EDGE_MIN))
                return tk_error_set(err, TK_EINVAL,
                                    "component %zu: the edge from vertex %zu to %zu is %g "
                                    "long, shorter than the %g the engine measures: scale "
                                    "the curve up or drop the vertex",
                                    i, k, (k + 1) % n, l, TK_CURVE_EDGE_MIN);
        }
    }
    return TK_OK;
}

int tk_curve_validate(const tk_curve *c, tk_error *err)
{
    return check_curve(c, false, err);
}

int tk_curve_check_range(const tk_curve *c, tk_error *err)
{
    return check_curve(c, true, err);
}

/* Solves the tridiagonal system with sub-diagonal a, diagonal b,
 * super-diagonal c (a[0], c[n-1] unused) for three right-hand sides stored
 * as rhs[3*i + k], in place.  The spline matrices are strictly diagonally
 * dominant, so no pivoting is needed.  work has n entries. */
static void solve_tridiagonal(size_t n, const double *a, const double *b,
                              const double *c, double *rhs, double *work)
{
    double beta = b[0];
    work[0] = 0.0;
    for (int k = 0; k < 3; k++)
        rhs[k] /= beta;
    for (size_t i = 1; i < n; i++) {
        work[i] = c[i - 1] / beta;
        beta = b[i] - a[i] * work[i];
        for (int k = 0; k < 3; k++)
            rhs[3 * i + k] = (rhs[3 * i + k] - a[i] * rhs[3 * (i - 1) + k]) / beta;
    }
    for (size_t i = n - 1; i-- > 0;)
        for (int k = 0; k < 3; k++)
            rhs[3 * i + k] -= work[i + 1] * rhs[3 * (i + 1) + k];
}

/* A cubic spline through the points y[0..n-1] (closed: periodic, the
 * interval after y[n-1] returning to y[0]), parametrised by chord length. */
typedef struct spline {
    size_t n, intervals;
    const double *y;
    double *u;  /* knots, intervals + 1 */
    double *m;  /* second derivatives, 3 per knot (n of them) */
} spline;

static int spline_fit(spline *sp, const double *y, size_t n, bool closed)
{
    size_t ni = closed ? n : n - 1;
    sp->n = n;
    sp->intervals = ni;
    sp->y = y;
    sp->u = malloc((ni + 1) * sizeof *sp->u);
    sp->m = calloc(3 * n, sizeof *sp->m);
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    double *c = malloc(n * sizeof *c), *work = malloc(n * sizeof *work);
    double *z = calloc(3 * n, sizeof *z);
    int rc = TK_OK;
    if (!sp->u || !sp->m || !a || !b || !c || !work || !z) {
        rc = TK_ENOMEM;
        goto done;
    }
    sp->u[0] = 0.0;
    for (size_t i = 0; i < ni; i++)
        sp->u[i + 1] = sp->u[i] + distance3(y + 3 * i, y + 3 * ((i + 1) % n));
    /* Continuity of the first derivative at knot i:
     *   h[i-1] M[i-1] + 2 (h[i-1] + h[i]) M[i] + h[i] M[i+1]
     *     = 6 ((y[i+1] - y[i]) / h[i] - (y[i] - y[i-1]) / h[i-1]). */
    if (closed) {
        /* Periodic: a cyclic system, solved with Sherman-Morrison on top of
         * the plain tridiagonal solve. */
        for (size_t i = 0; i < n; i++) {
            size_t ip = (i + n - 1) % n, in = (i + 1) % n;
            double h0 = sp->u[ip + 1] - sp->u[ip], h1 = sp->u[i + 1] - sp->u[i];
            a[i] = h0;
            b[i] = 2.0 * (h0 + h1);
            c[i] = h1;
            for (int k = 0; k < 3; k++)
                sp->m[3 * i + k] = 6.0 * ((y[3 * in + k] - y[3 * i + k]) / h1 -
                                          (y[3 * i + k] - y[3 * ip + k]) / h0);
        }
        double corner_lo = a[0], corner_hi = c[n - 1], gamma = -b[0];
        double b0 = b[0], bn = b[n - 1];
        b[0] = b0 - gamma;
        b[n - 1] = bn - corner_lo * corner_hi / gamma;
        z[0] = gamma;
        z[3 * (n - 1)] = corner_hi;
        /* z holds the correction vector in its first coordinate slot. */
        double *zz = calloc(3 * n, sizeof *zz);
        if (!zz) {
            rc = TK_ENOMEM;
            goto done;
        }
        for (size_t i = 0; i < n; i++)
            zz[3 * i] = zz[3 * i + 1] = zz[3 * i + 2] = z[3 * i];
        solve_tridiagonal(n, a, b, c, sp->m, work);
        solve_tridiagonal(n, a, b, c, zz, work);
        for (int k = 0; k < 3; k++) {
            double vx = sp->m[k] + corner_lo / gamma * sp->m[3 * (n - 1) + k];
            double vz = zz[k] + corner_lo / gamma * zz[3 * (n - 1) + k];
            double factor = vx / (1.0 + vz);
            for (size_t i = 0; i < n; i++)
                sp->m[3 * i + k] -= factor * zz[3 * i + k];
        }
        free(zz);
    } else if (n > 2) {
        /* Natural: M[0] = M[n-1] = 0, the interior knots solved. */
        size_t ninner = n - 2;
        for (size_t j = 0; j < ninner; j++) {
            size_t i = j + 1;
            double h0 = sp->u[i] - sp->u[i - 1], h1 = sp->u[i + 1] - sp->u[i];
            a[j] = h0;
            b[j] = 2.0 * (h0 + h1);
            c[j] = h1;
            for (int k = 0; k < 3; k++)
                z[3 * j + k] = 6.0 * ((y[3 * (i + 1) + k] - y[3 * i + k]) / h1 -
                                      (y[3 * i + k] - y[3 * (i - 1) + k]) / h0);
        }
        solve_tridiagonal(ninner, a, b, c, z, work);
        memcpy(sp->m + 3, z, 3 * ninner * sizeof *z);
    }
done:
    free(a);
    free(b);
    free(c);
    free(work);
    free(z);
    return rc;
}

static void spline_free(spline *sp)
{
    free(sp->u);
    free(sp->m);
    sp->u = sp->m = NULL;
}

/* Evaluates the spline at parameter x in [0, u[intervals]]. */
static void spline_eval(const spline *sp, double x, double out[3])
{
    size_t lo = 0, hi = sp->intervals;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (sp->u[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    size_t i = lo, j = (lo + 1) % sp->n;
    double h = sp->u[i + 1] - sp->u[i];
    double s = x - sp->u[i], r = h - s;
    for (int k = 0; k < 3; k++) {
        double mi = sp->m[3 * i + k], mj = sp->m[3 * j + k];
        out[k] = mi * r * r * r / (6.0 * h) + mj * s * s * s / (6.0 * h) +
                 (sp->y[3 * i + k] / h - mi * h / 6.0) * r +
                 (sp->y[3 * j + k] / h - mj * h / 6.0) * s;
    }
}

/* Places count points at equal arclength along the spline, measured on a
 * dense sampling of it (fine enough that the spacing is equal to well
 * under a percent). */
static int spline_resample(const spline *sp, bool closed, size_t count, double *out)
{
    size_t dense = 32 * sp->intervals;
    if (dense < 8 * count)
        dense = 8 * count;
    double total_u = sp->u[sp->intervals];
    double *arc = malloc((dense + 1) * sizeof *arc);
    if (!arc)
        return TK_ENOMEM;
    double prev[3], cur[3];
    spline_eval(sp, 0.0, prev);
    arc[0] = 0.0;
    for (size_t k = 1; k <= dense; k++) {
        spline_eval(sp, total_u * (double)k / (double)dense, cur);
        arc[k] = arc[k - 1] + distance3(prev, cur);
        memcpy(prev, cur, sizeof prev);
    }
    size_t spans = closed ? count : count - 1;
    size_t seg = 0;
    for (size_t v = 0; v < count; v++) {
        double target = arc[dense] * (double)v / (double)spans;
        while (seg + 1 < dense && arc[seg + 1] < target)
            seg++;
        double len = arc[seg + 1] - arc[seg];
        double frac = len > 0.0 ? (target - arc[seg]) / len : 0.0;
        double x = total_u * ((double)seg + frac) / (double)dense;
        if (!closed && v == count - 1)
            x = total_u;
        if (!closed && (v == 0 || v == count - 1))
            memcpy(out + 3 * v, sp->y + 3 * (v == 0 ? 0 : sp->n - 1), 3 * sizeof *out);
        else
            spline_eval(sp, x, out + 3 * v);
    }
    free(arc);
    return TK_OK;
}

int tk_curve_resample(const tk_curve *src, const size_t *counts, tk_curve **out,
                      tk_error *err)
{
    *out = NULL;
    int rc = tk_curve_validate(src, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < src->ncomp; i++)
        if (counts[i] < (src->closed[i] ? 3u : 2u))
            return tk_error_set(err, TK_EINVAL,
                                "component %zu cannot have %zu vertices", i, counts[i]);
    rc = tk_curve_new(out, src->ncomp, counts, src->closed, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < src->ncomp && rc == TK_OK; i++) {
        spline sp = {0};
        size_t n = tk_curve_comp_vertices(src, i);
        rc = spline_fit(&sp, src->xyz + 3 * src->offset[i], n, src->closed[i]);
        if (rc == TK_OK)
            rc = spline_resample(&sp, src->closed[i], counts[i],
                                 (*out)->xyz + 3 * (*out)->offset[i]);
        spline_free(&sp);
    }
    if (rc == TK_OK)
        rc = carry_pins(src, *out, err);
    else
        tk_error_set(err, rc, "out of memory resampling");
    if (rc == TK_OK)
        rc = tk_curve_validate(*out, err);
    if (rc)
        tk_curve_free(out);
    return rc;
}

int tk_curve_share_total(const tk_curve *src, size_t total, size_t *counts, tk_error *err)
{
    size_t minimum = 0;
    for (size_t i = 0; i < src->ncomp; i++)
        minimum += src->closed[i] ? 3 : 2;
    if (total < minimum)
        return tk_error_set(err, TK_EINVAL, "%zu vertices are too few for %zu components",
                            total, src->ncomp);
    double *share = calloc(src->ncomp, sizeof *share);
    if (!share)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    double length = tk_curve_length(src);
    size_t given = 0;
    for (size_t i = 0; i < src->ncomp; i++) {
        share[i] = (double)total * tk_curve_comp_length(src, i) / length;
        size_t least = src->closed[i] ? 3 : 2;
        counts[i] = (size_t)floor(share[i]);
        if (counts[i] < least)
            counts[i] = least;
        given += counts[i];
    }
    /* Largest remainders get the vertices left over; components above their
     * share give back when the minimums overshot. */
    while (given < total) {
        size_t best = 0;
        double gap = -INFINITY;
        for (size_t i = 0; i < src->ncomp; i++)
            if (share[i] - (double)counts[i] > gap) {
                gap = share[i] - (double)counts[i];
                best = i;
            }
        counts[best]++;
        given++;
    }
    while (given > total) {
        size_t best = 0;
        double excess = -INFINITY;
        for (size_t i = 0; i < src->ncomp; i++)
            if (counts[i] > (src->closed[i] ? 3u : 2u) &&
                (double)counts[i] - share[i] > excess) {
                excess = (double)counts[i] - share[i];
                best = i;
            }
        counts[best]--;
        given--;
    }
    free(share);
    return TK_OK;
}

int tk_curve_resample_total(const tk_curve *src, size_t total, tk_curve **out,
                            tk_error *err)
{
    *out = NULL;
    int rc = tk_curve_validate(src, err);
    if (rc)
        return rc;
    size_t *counts = calloc(src->ncomp, sizeof *counts);
    if (!counts)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    rc = tk_curve_share_total(src, total, counts, err);
    if (!rc)
        rc = tk_curve_resample(src, counts, out, err);
    free(counts);
    return rc;
}

int tk_curve_equilateralize(tk_curve *c, tk_error *err)
{
    int rc = tk_curve_validate(c, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < c->ncomp; i++) {
        size_t n = tk_curve_comp_vertices(c, i), ne = tk_curve_comp_edges(c, i);
        double *x = c->xyz + 3 * c->offset[i];
        double *old = malloc(3 * n * sizeof *old);
        double *arc = malloc((ne + 1) * sizeof *arc);
        if (!old || !arc) {
            free(old);
            free(arc);
            return tk_error_set(err, TK_ENOMEM, "out of memory");
        }
        memcpy(old, x, 3 * n * sizeof *old);
        arc[0] = 0.0;
        for (size_t k = 0; k < ne; k++)
            arc[k + 1] = arc[k] + distance3(old + 3 * k, old + 3 * ((k + 1) % n));
        size_t seg = 0;
        for (size_t v = 1; v < n; v++) {
            if (!c->closed[i] && v == n - 1)
                break;
            double target = arc[ne] * (double)v / (double)ne;
            while (seg + 1 < ne && arc[seg + 1] < target)
                seg++;
            double frac = (target - arc[seg]) / (arc[seg + 1] - arc[seg]);
            const double *a = old + 3 * seg, *b = old + 3 * ((seg + 1) % n);
            for (int k = 0; k < 3; k++)
                x[3 * v + k] = a[k] + frac * (b[k] - a[k]);
        }
        free(old);
        free(arc);
    }
    tk_curve_pins_snap(c);
    return TK_OK;
}
