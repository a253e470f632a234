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

void tk_curve_translate(tk_curve *c, const double shift[3])
{
    for (size_t v = 0; v < c->nvert; v++)
        for (int k = 0; k < 3; k++)
            c->xyz[3 * v + k] += shift[k];
}

void tk_curve_rotate(tk_curve *c, const double r[9])
{
    for (size_t v = 0; v < c->nvert; v++) {
        double *x = c->xyz + 3 * v;
        double y0 = r[0] * x[0] + r[1] * x[1] + r[2] * x[2];
        double y1 = r[3] * x[0] + r[4] * x[1] + r[5] * x[2];
        double y2 = r[6] * x[0] + r[7] * x[1] + r[8] * x[2];
        x[0] = y0;
        x[1] = y1;
        x[2] = y2;
    }
}

void tk_curve_scale(tk_curve *c, double factor)
{
    for (size_t i = 0; i < 3 * c->nvert; i++)
        c->xyz[i] *= factor;
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

int tk_curve_validate(const tk_curve *c, tk_error *err)
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
            if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
                return tk_error_set(err, TK_EINVAL,
                                    "component %zu vertex %zu has a non-finite coordinate",
                                    i, k);
        }
        size_t ne = tk_curve_comp_edges(c, i);
        for (size_t k = 0; k < ne; k++)
            if (!(tk_curve_edge_length(c, i, k) > 0.0))
                return tk_error_set(err, TK_EINVAL,
                                    "component %zu: vertices %zu and %zu coincide (zero-length edge)",
                                    i, k, (k + 1) % n);
    }
    return TK_OK;
}
