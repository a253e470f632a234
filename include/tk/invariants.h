/* tightknot: invariants of the knot or link type of a polygon, to check
 * that tightening never changes it.
 *
 * The linking number of two disjoint closed polygons is the Gauss
 * integral, which for polygons is a sum over pairs of edges of the signed
 * solid angle each pair's quadrilateral subtends, over 4 pi: exact up to
 * rounding, so the sum lands within rounding of an integer.
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

#endif
