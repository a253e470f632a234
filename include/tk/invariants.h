/* tightknot: invariants of the knot or link type of a polygon, to check
 * that tightening never changes it.
 *
 * The linking number of two disjoint closed polygons is the Gauss
 * integral, which for polygons is a sum over pairs of edges of the signed
 * solid angle each pair's quadrilateral subtends, over 4 pi: exact up to
 * rounding, so the sum lands within rounding of an integer.
 *
 * The determinant of a knot, |Alexander polynomial at -1|, comes from a
 * projection: the crossings of the polygon seen along a direction, the
 * arcs between its undercrossings, and the colouring matrix (each crossing
 * 2 x its over-arc - its two under-arcs); any minor of one order less has
 * the determinant as its absolute value, whatever the projection.  It is
 * 1 for the unknot, 3 for the trefoil, 5 for the figure-eight.
 */
#ifndef TK_INVARIANTS_H
#define TK_INVARIANTS_H

#include <stddef.h>

#include "tk/curve.h"
#include "tk/error.h"

/* The Gauss linking integral of closed components a and b (a != b) of c,
 * as a real number (*gauss, within rounding of an integer for disjoint
 * polygons) and rounded (*lk).  Fails with TK_EINVAL when either component
 * is open or a == b, and with TK_ENUMERIC when the sum is not within 1e-6
 * of an integer (the components (nearly) touch).  O(n_a n_b). */
int tk_linking_number(const tk_curve *c, size_t a, size_t b, long *lk, double *gauss,
                      tk_error *err);

/* The determinant |Delta(-1)| of closed component comp of c seen as a
 * knot, from a projection along a direction drawn from `seed` (any seed
 * gives the same answer; another is tried when a projection is not
 * generic).  *crossings (may be NULL) receives the projection's crossing
 * count.  Fails with TK_EINVAL for an open component, TK_ENUMERIC when no
 * generic projection is found or the determinant exceeds 2^60, TK_ENOMEM.
 * O(n^2) for the crossings, O(m^3) in the m crossings. */
int tk_knot_determinant(const tk_curve *c, size_t comp, unsigned long long seed, long long *det,
                        size_t *crossings, tk_error *err);

#endif
