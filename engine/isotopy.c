/* Fewer vertices by triangle moves (tk/isotopy.h). */
#include "tk/isotopy.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "tk/geometry.h"

/* An edge within ISOTOPY_MARGIN of the polygon's mean edge of a move's
 * triangle blocks it: the tests are then decided far above rounding. */
#define ISOTOPY_MARGIN 1e-9
/* An edge from a corner of the triangle meets it only at that corner
 * unless it leaves the corner in the triangle's plane, within the angle
 * there: in the plane means within COPLANAR (the sine of its angle with
 * the plane), within the angle means on the inner side of both sides up
 * to the same; a triangle whose sides' sine is below it is a line. */
#define COPLANAR 1e-9

#define NONE SIZE_MAX

/* The polygon as it loses vertices: each alive vertex's neighbours. */
typedef struct polygon {
    const tk_curve *c;
    size_t *next, *prev; /* NONE past an open component's ends */
    size_t *stretch;     /* for each vertex, the stretch whose edges start there */
    size_t *near;        /* the edges (by first vertex) near the stretch at work */
    double tol;
} polygon;

static void unit(const double *a, const double *b, double *u)
{
    tk_sub3(b, a, u);
    double n = sqrt(tk_dot3(u, u));
    for (int k = 0; k < 3; k++)
        u[k] = n > 0.0 ? u[k] / n : 0.0;
}

/* The components' colours, when c has them. */
static int copy_colour(const tk_curve *c, tk_curve *out, tk_error *err)
{
    if (!c->has_colour || !c->colour)
        return TK_OK;
    out->colour = malloc(4 * c->ncomp * sizeof *out->colour);
    if (!out->colour)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    memcpy(out->colour, c->colour, 4 * c->ncomp * sizeof *c->colour);
    out->has_colour = true;
    return TK_OK;
}

/* Whether the edge from corner s to o meets the triangle (s, x, y)
 * anywhere but at s. */
static bool corner_meets(const double *s, const double *x, const double *y, const double *o)
{
    double u1[3], u2[3], w[3], n[3];
    unit(s, x, u1);
    unit(s, y, u2);
    unit(s, o, w);
    tk_cross3(u1, u2, n);
    double sine = sqrt(tk_dot3(n, n));
    if (!(sine > COPLANAR)) /* a line: blocked along either side */
        return tk_dot3(w, u1) >= 1.0 - COPLANAR || tk_dot3(w, u2) >= 1.0 - COPLANAR;
    for (int k = 0; k < 3; k++)
        n[k] /= sine;
    if (fabs(tk_dot3(w, n)) > COPLANAR)
        return false;
    double side1[3], side2[3];
    tk_cross3(u1, w, side1);
    tk_cross3(w, u2, side2);
    return tk_dot3(side1, n) >= -COPLANAR && tk_dot3(side2, n) >= -COPLANAR;
}

/* Whether the edge from u to its successor meets the triangle of the move
 * that takes b out. */
static bool edge_blocks(const polygon *p, size_t u, size_t b)
{
    size_t a = p->prev[b], c = p->next[b], w = p->next[u];
    if (u == b || w == b)
        return false; /* the move's own edges */
    assert(!((u == a || u == c) && (w == a || w == c))); /* four vertices at least */
    const double *A = tk_curve_vertex(p->c, a), *B = tk_curve_vertex(p->c, b);
    const double *C = tk_curve_vertex(p->c, c);
    const double *U = tk_curve_vertex(p->c, u), *W = tk_curve_vertex(p->c, w);
    if (u == a || u == c)
        return corner_meets(U, u == a ? B : A, u == a ? C : B, W);
    if (w == a || w == c)
        return corner_meets(W, w == a ? B : A, w == a ? C : B, U);
    return tk_segment_meets_triangle(A, B, C, U, W, p->tol);
}

/* Clears the stretch of vertices strictly between the kept `from` and
 * `to` (numbered `id` in p->stretch) by triangle moves; false when some
 * vertex of it stays. */
static bool clear_stretch(polygon *p, size_t from, size_t to, size_t id)
{
    if (p->next[from] == to)
        return true;
    /* the stretch's bounding box: every triangle of its moves lies in it */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = from;; v = p->next[v]) {
        const double *x = tk_curve_vertex(p->c, v);
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], x[k] - p->tol);
            hi[k] = fmax(hi[k], x[k] + p->tol);
        }
        if (v == to)
            break;
    }
    /* the other edges near it: they do not change while it is cleared */
    size_t nnear = 0;
    for (size_t u = 0; u < p->c->nvert; u++) {
        size_t w = p->next[u];
        if (w == NONE || p->stretch[u] == id)
            continue;
        const double *x = tk_curve_vertex(p->c, u), *y = tk_curve_vertex(p->c, w);
        bool apart = false;
        for (int k = 0; k < 3 && !apart; k++)
            apart = fmax(x[k], y[k]) < lo[k] || fmin(x[k], y[k]) > hi[k];
        if (!apart)
            p->near[nnear++] = u;
    }
    for (bool progress = true; progress && p->next[from] != to;) {
        progress = false;
        for (size_t b = p->next[from]; b != to;) {
            size_t after = p->next[b];
            bool blocked = false;
            for (size_t k = 0; k < nnear && !blocked; k++)
                blocked = edge_blocks(p, p->near[k], b);
            for (size_t u = from; u != to && !blocked; u = p->next[u])
                blocked = edge_blocks(p, u, b);
            if (!blocked) {
                p->next[p->prev[b]] = after;
                p->prev[after] = p->prev[b];
                p->next[b] = p->prev[b] = NONE;
                progress = true;
            }
            b = after;
        }
    }
    return p->next[from] == to;
}

/* What both functions start with: no result yet, c valid, a count for
 * each of its components. */
static int begin(const tk_curve *c, tk_curve **out, size_t **counts, tk_error *err)
{
    *out = NULL;
    int rc = tk_curve_validate(c, err);
    if (rc)
        return rc;
    *counts = calloc(c->ncomp, sizeof **counts);
    return *counts ? TK_OK : tk_error_set(err, TK_ENOMEM, "out of memory");
}

/* The vertices component comp keeps, m of them, into keep (local
 * indices, rising): vertex 0 (and an open component's last), and for the
 * k-th of the others the vertex past the (k-1)-th whose arclength is
 * nearest to k / m of the component's, leaving room for those after. */
static void choose(const tk_curve *c, size_t comp, size_t m, size_t *keep)
{
    size_t n = tk_curve_comp_vertices(c, comp), j = 0;
    bool closed = c->closed[comp];
    double step = tk_curve_comp_length(c, comp) / (double)(closed ? m : m - 1);
    double s = 0.0; /* the arclength at vertex j */
    keep[0] = 0;
    for (size_t k = 1; k < m; k++) {
        if (!closed && k == m - 1) {
            keep[k] = n - 1;
            break;
        }
        double target = (double)k * step;
        s += tk_curve_edge_length(c, comp, j++);
        while (j < n - m + k) {
            double e = tk_curve_edge_length(c, comp, j);
            if (!(fabs(s + e - target) < fabs(s - target)))
                break;
            s += e;
            j++;
        }
        keep[k] = j;
    }
}

int tk_isotopy_coarsen(const tk_curve *c, size_t total, tk_curve **out, bool *kept,
                       tk_error *err)
{
    *kept = false;
    size_t *counts = NULL;
    int rc = begin(c, out, &counts, err);
    if (rc)
        return rc;
    rc = tk_curve_share_total(c, total, counts, err);
    for (size_t comp = 0; !rc && comp < c->ncomp; comp++)
        if (counts[comp] > tk_curve_comp_vertices(c, comp))
            rc = tk_error_set(err, TK_EINVAL, "component %zu has %zu vertices, fewer than the "
                              "%zu its length asks of %zu", comp,
                              tk_curve_comp_vertices(c, comp), counts[comp], total);
    if (rc) {
        free(counts);
        return rc;
    }
    size_t n = c->nvert;
    polygon p = {c, malloc(n * sizeof *p.next), malloc(n * sizeof *p.prev),
                 malloc(n * sizeof *p.stretch), malloc(n * sizeof *p.near),
                 ISOTOPY_MARGIN * tk_curve_length(c) / (double)tk_curve_edge_count(c)};
    size_t *keep = malloc(n * sizeof *keep);
    if (!p.next || !p.prev || !p.stretch || !p.near || !keep)
        rc = tk_error_set(err, TK_ENOMEM, "out of memory");
    for (size_t comp = 0; !rc && comp < c->ncomp; comp++) {
        size_t m = tk_curve_comp_vertices(c, comp), base = c->offset[comp];
        for (size_t k = 0; k < m; k++) {
            bool last = k + 1 == m, first = k == 0;
            p.next[base + k] = last ? (c->closed[comp] ? base : NONE) : base + k + 1;
            p.prev[base + k] = first ? (c->closed[comp] ? base + m - 1 : NONE) : base + k - 1;
        }
    }
    /* number the stretches: the edges from each kept vertex to the next */
    size_t nkeep = 0, stretches = 0;
    for (size_t comp = 0; !rc && comp < c->ncomp; comp++) {
        size_t base = c->offset[comp], m = counts[comp];
        choose(c, comp, m, keep + nkeep);
        size_t nv = tk_curve_comp_vertices(c, comp);
        for (size_t k = 0; k < m; k++) {
            size_t end = k + 1 < m ? keep[nkeep + k + 1] : nv;
            for (size_t v = keep[nkeep + k]; v < end; v++)
                p.stretch[base + v] = stretches;
            stretches++;
        }
        for (size_t k = 0; k < m; k++)
            keep[nkeep + k] += base;
        nkeep += m;
    }
    bool clear = true;
    nkeep = 0;
    for (size_t comp = 0; !rc && clear && comp < c->ncomp; comp++) {
        size_t m = counts[comp];
        size_t last = c->closed[comp] ? m : m - 1;
        for (size_t k = 0; clear && k < last; k++) {
            size_t from = keep[nkeep + k], to = keep[nkeep + (k + 1) % m];
            clear = clear_stretch(&p, from, to, p.stretch[from]);
        }
        nkeep += m;
    }
    if (!rc && clear)
        rc = tk_curve_new(out, c->ncomp, counts, c->closed, err);
    if (!rc && clear) {
        nkeep = 0;
        for (size_t comp = 0; comp < c->ncomp; comp++) {
            double *to = (*out)->xyz + 3 * (*out)->offset[comp];
            for (size_t k = 0; k < counts[comp]; k++) {
                const double *x = tk_curve_vertex(c, keep[nkeep + k]);
                for (int d = 0; d < 3; d++)
                    to[3 * k + d] = x[d];
            }
            nkeep += counts[comp];
        }
        rc = copy_colour(c, *out, err);
        *kept = !rc;
    }
    if (rc)
        tk_curve_free(out);
    free(counts);
    free(keep);
    free(p.next);
    free(p.prev);
    free(p.stretch);
    free(p.near);
    return rc;
}

/* The pieces edge (comp, i) is cut into for about `total` in all. */
static size_t pieces(const tk_curve *c, size_t comp, size_t i, size_t total, double length)
{
    double share = round((double)total * tk_curve_edge_length(c, comp, i) / length);
    return share > 1.0 ? (size_t)share : 1;
}

int tk_isotopy_refine(const tk_curve *c, size_t total, tk_curve **out, tk_error *err)
{
    size_t *counts = NULL;
    int rc = begin(c, out, &counts, err);
    if (rc)
        return rc;
    double length = tk_curve_length(c);
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        counts[comp] = c->closed[comp] ? 0 : 1;
        for (size_t i = 0; i < tk_curve_comp_edges(c, comp); i++)
            counts[comp] += pieces(c, comp, i, total, length);
    }
    rc = tk_curve_new(out, c->ncomp, counts, c->closed, err);
    for (size_t comp = 0; !rc && comp < c->ncomp; comp++) {
        double *to = (*out)->xyz + 3 * (*out)->offset[comp];
        size_t n = tk_curve_comp_vertices(c, comp);
        for (size_t i = 0; i < tk_curve_comp_edges(c, comp); i++) {
            const double *a = tk_curve_vertex(c, c->offset[comp] + i);
            const double *b = tk_curve_vertex(c, c->offset[comp] + (i + 1) % n);
            size_t m = pieces(c, comp, i, total, length);
            for (size_t k = 0; k < m; k++, to += 3)
                for (int d = 0; d < 3; d++)
                    to[d] = a[d] + (b[d] - a[d]) * (double)k / (double)m;
        }
        if (!c->closed[comp])
            memcpy(to, tk_curve_vertex(c, c->offset[comp] + n - 1), 3 * sizeof *to);
    }
    if (!rc)
        rc = copy_colour(c, *out, err);
    if (rc)
        tk_curve_free(out);
    free(counts);
    return rc;
}
