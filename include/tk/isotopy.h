/* tightknot: fewer vertices by moves that keep the type.
 *
 * A triangle move takes a vertex b out of a polygon: its two edges a b and
 * b c become the one edge a c, and on the way they sweep the triangle abc.
 * When no other edge of the polygon meets that triangle no strand passes
 * through another, and the knot or link type is kept: exactly, whatever
 * the invariants can tell.  A polygon resampled on fewer vertices
 * through a spline (tk_curve_resample) has no such guarantee where its
 * features are smaller than its new edges, and the invariants cannot
 * catch every change: catalogue 9.2.3 (two unknots, linking number -1)
 * turned inside out and resampled on 101 vertices that way became the
 * Hopf link, whose components and linking number are the same (only the
 * link's determinant, 30 against 2, tells them apart), and tightened to
 * 8 pi.
 */
#ifndef TK_ISOTOPY_H
#define TK_ISOTOPY_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/curve.h"
#include "tk/error.h"

/* c on `total` vertices of its own, shared among its components in
 * proportion to their lengths (tk_curve_share_total), each component
 * keeping its vertex 0 (an open one both ends) and those nearest to equal
 * arclength along it; the others are taken out by triangle moves, each
 * checked against every edge the polygon has at that moment (an edge
 * within 1e-9 of c's mean edge counts as meeting it).
 * Between two kept vertices, a vertex whose move is blocked is tried again
 * after the others of the stretch.  *kept is false and *out NULL when
 * some stretch cannot be cleared that way (strands too close for so few
 * vertices).  The result carries no pins (they name vertices that may be
 * gone).  TK_EINVAL when c is invalid or a component would need more
 * vertices than it has; TK_ENOMEM. */
int tk_isotopy_coarsen(const tk_curve *c, size_t total, tk_curve **out, bool *kept,
                       tk_error *err);

/* c on about `total` vertices along its own edges: each edge cut into
 * pieces of equal length, as many as its share of the total length asks
 * (at least one).  The polygon is c's, so its type is, exactly; a spline
 * through c's vertices (tk_curve_resample) is not.  The result carries
 * no pins.  TK_EINVAL when c is invalid; TK_ENOMEM. */
int tk_isotopy_refine(const tk_curve *c, size_t total, tk_curve **out, tk_error *err);

#endif
