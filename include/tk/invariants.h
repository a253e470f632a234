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
 * 1 for the unknot, 3 for the trefoil, 5 for the figure-eight.  The same
 * matrix of a diagram of all the components is the link's: 2 for the
 * Hopf link, 4 for the (2, 4) torus link, 6 for T(2, 6), 12 for
 * Rolfsen's 6^2_3, 8 for the Whitehead link, 16 for the Borromean rings,
 * 0 for a split link.  Two links whose components and linking numbers agree
 * (6^2_3 and the (2, 4) torus link: unknots, linking number 2) can still
 * differ there.
 */
#ifndef TK_INVARIANTS_H
#define TK_INVARIANTS_H

#include <stdbool.h>
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
/* Projections with more crossings than this are refused (TK_ELIMIT):
 * the invariants cost up to O(crossings^3) (the determinant) and
 * O(crossings^4) (the Alexander polynomial; the matrices are sparse, so
 * far less: 0.17 s for the 261 crossings of the catalogue's random
 * 600-gon blob.vect).  The simplest of three generic projections is used;
 * a tight knot of up to 13 crossings shows a few dozen. */
#define TK_INVARIANT_MAX_CROSSINGS 400
/* Highest degree of an Alexander polynomial kept (twice the genus: 12 for
 * T(3, 7)). */
#define TK_ALEXANDER_MAX_DEGREE 40

int tk_knot_determinant(const tk_curve *c, size_t comp, unsigned long long seed, long long *det,
                        size_t *crossings, tk_error *err);

/* The determinant of the whole link c (every component closed): |det|
 * of the colouring matrix of a diagram of all its components less a row
 * and a column, from a projection drawn from `seed` as for
 * tk_knot_determinant; for one component, that knot's determinant.  0
 * when the diagram shows a split link.  Fails as tk_knot_determinant
 * does. */
int tk_link_determinant(const tk_curve *c, unsigned long long seed, long long *det,
                        size_t *crossings, tk_error *err);

/* The Alexander polynomial of closed component comp seen as a knot:
 * coeff[0..*degree] are its coefficients of 1, t, ..., t^degree,
 * normalised so that coeff[0] != 0 and Delta(1) = 1 (the trefoil's is
 * 1 - t + t^2, the figure-eight's -1 + 3t - t^2, the unknot's 1).  From
 * the Alexander matrix of a projection (seeded as for the determinant)
 * evaluated at crossings-many points modulo 2^61 - 1 and interpolated;
 * the result is checked to be symmetric with Delta(1) = +-1.  Fails as
 * tk_knot_determinant does, and with TK_ELIMIT beyond
 * TK_ALEXANDER_MAX_DEGREE. */
int tk_knot_alexander(const tk_curve *c, size_t comp, unsigned long long seed,
                      long long coeff[TK_ALEXANDER_MAX_DEGREE + 1], int *degree,
                      size_t *crossings, tk_error *err);

/* ---- the knot or link type of a curve, as a record ---- */

typedef struct tk_knot_type {
    bool known;        /* false for an open component, or one whose simplest
                          projection has too many crossings (TK_ELIMIT) */
    int degree;        /* of the Alexander polynomial */
    long long alexander[TK_ALEXANDER_MAX_DEGREE + 1];
    long long determinant; /* |Delta(-1)| */
} tk_knot_type;

typedef struct tk_invariants {
    size_t ncomp;
    tk_knot_type *knot;  /* per component */
    long *linking;       /* ncomp x ncomp, row major, symmetric; 0 on the
                            diagonal and for open components */
    bool link_known;     /* false when a component is open or the diagram
                            of all of them has too many crossings */
    long long link_determinant; /* tk_link_determinant */
    bool complete;       /* every closed component's knot type is known,
                            and the link's determinant */
} tk_invariants;

#define TK_INVARIANTS_INIT {0, NULL, NULL, false, 0, false}

/* The invariants of c into *out (freed first).  Fails with TK_ENUMERIC
 * when strands (nearly) meet, TK_ENOMEM; a component with too many
 * crossings is left unknown (out->complete false), not an error. */
int tk_invariants_compute(const tk_curve *c, tk_invariants *out, tk_error *err);
void tk_invariants_free(tk_invariants *inv);
int tk_invariants_copy(const tk_invariants *src, tk_invariants *out, tk_error *err);

/* TK_OK when `now` has the type `was` had (what either leaves unknown is
 * not compared), else TK_ETYPE with a message naming the first
 * difference ("component 0: the Alexander polynomial was 1 - t + t^2, now
 * 1"): the components' knot types, the linking numbers, then the link's
 * determinant. */
int tk_invariants_compare(const tk_invariants *was, const tk_invariants *now, tk_error *err);

/* The polynomial as text, "1 - t + t^2", into buf (always terminated). */
void tk_alexander_format(const tk_knot_type *k, char *buf, size_t size);

#endif
