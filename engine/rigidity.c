#include "tk/rigidity.h"

#include <math.h>
#include <string.h>

#include "tk/geometry.h"

void tk_rigidity_strut_gradient(const tk_curve *c, const tk_strut *s, size_t vertices[4],
                                double grad[12])
{
    vertices[0] = tk_curve_vertex_index(c, s->comp[0], s->edge[0]);
    vertices[1] = tk_curve_vertex_index(c, s->comp[0], s->edge[0] + 1);
    vertices[2] = tk_curve_vertex_index(c, s->comp[1], s->edge[1]);
    vertices[3] = tk_curve_vertex_index(c, s->comp[1], s->edge[1] + 1);
    /* Equation (7) at the strut's own parameters: p and q are taken from the
     * current vertices so the column matches the curve A is built for. */
    tk_closest cl;
    cl.s = s->s;
    cl.t = s->t;
    for (int k = 0; k < 3; k++) {
        const double *a0 = tk_curve_vertex(c, vertices[0]), *a1 = tk_curve_vertex(c, vertices[1]);
        const double *b0 = tk_curve_vertex(c, vertices[2]), *b1 = tk_curve_vertex(c, vertices[3]);
        cl.p[k] = a0[k] + s->s * (a1[k] - a0[k]);
        cl.q[k] = b0[k] + s->t * (b1[k] - b0[k]);
    }
    double d2 = 0.0;
    for (int k = 0; k < 3; k++)
        d2 += (cl.p[k] - cl.q[k]) * (cl.p[k] - cl.q[k]);
    cl.dist = sqrt(d2);
    tk_segment_distance_gradient(&cl, grad);
}

/* One column's entries before sorting: up to four vertices x 3. */
typedef struct column {
    size_t n;
    size_t row[12];
    double value[12];
} column;

static void column_add(column *col, size_t vertex, const double *g3)
{
    /* Merge repeated vertices so the column has no duplicate rows. */
    for (size_t i = 0; i < col->n; i += 3)
        if (col->row[i] == 3 * vertex) {
            for (int k = 0; k < 3; k++)
                col->value[i + k] += g3[k];
            return;
        }
    for (int k = 0; k < 3; k++) {
        col->row[col->n] = 3 * vertex + (size_t)k;
        col->value[col->n] = g3[k];
        col->n++;
    }
}

static void column_sort(column *col)
{
    for (size_t a = 1; a < col->n; a++)
        for (size_t b = a; b > 0 && col->row[b] < col->row[b - 1]; b--) {
            size_t r = col->row[b];
            col->row[b] = col->row[b - 1];
            col->row[b - 1] = r;
            double v = col->value[b];
            col->value[b] = col->value[b - 1];
            col->value[b - 1] = v;
        }
}

int tk_rigidity_build(const tk_curve *c, const tk_strut *struts, size_t nstruts,
                      const tk_kink *kinks, size_t nkinks, cholmod_common *cc,
                      cholmod_sparse **out, tk_error *err)
{
    return tk_rigidity_build_branches(c, struts, nstruts, kinks, NULL, nkinks, cc, out, err);
}

int tk_rigidity_build_branches(const tk_curve *c, const tk_strut *struts, size_t nstruts,
                               const tk_kink *kinks, const unsigned char *kink_edge,
                               size_t nkinks, cholmod_common *cc, cholmod_sparse **out,
                               tk_error *err)
{
    *out = NULL;
    size_t ncol = nstruts + nkinks;
    cholmod_sparse *a = cholmod_allocate_sparse(3 * c->nvert, ncol, 12 * ncol + 1, 1, 1, 0,
                                                CHOLMOD_REAL, cc);
    if (!a)
        return tk_error_set(err, TK_ENOMEM, "out of memory for the rigidity matrix (%zu columns)",
                            ncol);
    int *colp = a->p, *rowi = a->i;
    double *val = a->x;
    size_t nz = 0;
    for (size_t j = 0; j < ncol; j++) {
        column col = {0};
        if (j < nstruts) {
            size_t v[4];
            double g[12];
            tk_rigidity_strut_gradient(c, &struts[j], v, g);
            for (int k = 0; k < 4; k++)
                column_add(&col, v[k], g + 3 * k);
        } else {
            const tk_kink *kk = &kinks[j - nstruts];
            size_t v = tk_curve_vertex_index(c, kk->comp, kk->vertex), prev, next;
            tk_curve_vertex_neighbours(c, v, &prev, &next);
            double g[9];
            /* Equation (6): the gradient of the radius at the vertex, of
             * the shorter edge's function or of the one asked for. */
            if (kink_edge)
                tk_vertex_radius_gradient(tk_curve_vertex(c, prev), tk_curve_vertex(c, v),
                                          tk_curve_vertex(c, next), kink_edge[j - nstruts], g);
            else
                tk_vertex_minrad_gradient(tk_curve_vertex(c, prev), tk_curve_vertex(c, v),
                                          tk_curve_vertex(c, next), g);
            column_add(&col, prev, g);
            column_add(&col, v, g + 3);
            column_add(&col, next, g + 6);
        }
        column_sort(&col);
        colp[j] = (int)nz;
        for (size_t i = 0; i < col.n; i++) {
            rowi[nz] = (int)col.row[i];
            val[nz] = col.value[i];
            nz++;
        }
    }
    colp[ncol] = (int)nz;
    *out = a;
    return TK_OK;
}
