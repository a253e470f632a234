/* tightknot: the rigidity matrix of section 3.3.
 *
 * A is 3V x E: one column per active constraint, holding the gradient of
 * that constraint with respect to the vertex coordinates (row 3v + k is
 * coordinate k of global vertex v).  Strut columns are equation (7), the
 * gradient of the edge-edge distance; kink columns are equation (6), the
 * gradient of the polygonal radius of curvature.  Struts come first, then
 * kinks, in the order given.
 */
#ifndef TK_RIGIDITY_H
#define TK_RIGIDITY_H

#include <stddef.h>

#include <cholmod.h>

#include "tk/curve.h"
#include "tk/error.h"
#include "tk/struts.h"

/* Builds A (CHOLMOD packed, sorted, real, unsymmetric) with common cc.
 * The caller frees it with cholmod_free_sparse. */
int tk_rigidity_build(const tk_curve *c, const tk_strut *struts, size_t nstruts,
                      const tk_kink *kinks, size_t nkinks, cholmod_common *cc,
                      cholmod_sparse **out, tk_error *err);

/* The same with a choice of function per kink: kink_edge[k] = 0 or 1 makes
 * kink k's column the gradient of that edge's radius function (see
 * tk_vertex_radius_gradient), so that a vertex whose two edges are equally
 * long can carry both functions as constraints; kink_edge NULL is
 * tk_rigidity_build. */
int tk_rigidity_build_branches(const tk_curve *c, const tk_strut *struts, size_t nstruts,
                               const tk_kink *kinks, const unsigned char *kink_edge,
                               size_t nkinks, cholmod_common *cc, cholmod_sparse **out,
                               tk_error *err);

/* The global vertex indices a strut's gradient touches (head and tail of
 * each edge) and the 12 gradient entries (equation 7), recomputed from the
 * curve at the strut's parameters. */
void tk_rigidity_strut_gradient(const tk_curve *c, const tk_strut *s, size_t vertices[4],
                                double grad[12]);

#endif
