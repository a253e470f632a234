/* tightknot: measuring a polygon (Definition 1).
 *
 *   thickness  = min( 2 * minrad, shortest doubly critical self-distance )
 *   ropelength = length / (thickness / 2)
 *
 * thickness is the tube diameter; ropelength is length over tube radius, the
 * convention of the published tables (tight trefoil ~32.74, tight Hopf link
 * 8 pi).
 */
#ifndef TK_THICKNESS_H
#define TK_THICKNESS_H

#include <stddef.h>

#include "tk/curve.h"
#include "tk/error.h"
#include "tk/struts.h"

typedef struct tk_measure {
    double length;
    double minrad;        /* smallest polygonal radius of curvature */
    double shortest;      /* shortest doubly critical self-distance */
    double thickness;     /* min(2 minrad, shortest) */
    double ropelength;    /* length / (thickness / 2) */
} tk_measure;

/* Measures a validated curve.  Uses the strut tree; f may be NULL (a
 * temporary finder is built) or a finder built for c. */
int tk_thickness_measure(const tk_curve *c, tk_strut_finder *f,
                         tk_measure *out, tk_error *err);

/* Measures and lists the contacts: struts within thickness * (1 + rel_tol)
 * (Theorem 3's admissible pairs for tau = thickness) and kinks with
 * 2 * minrad within the same bound.  The caller frees kinks (free()) and
 * the strut list. */
int tk_thickness_contacts(const tk_curve *c, double rel_tol, tk_measure *m,
                          tk_strut_list *struts, tk_kink **kinks,
                          size_t *nkinks, tk_error *err);

#endif
