#include "tk/thickness.h"

#include <math.h>
#include <stdlib.h>

#include "tk/geometry.h"

int tk_thickness_measure(const tk_curve *c, tk_strut_finder *f, tk_measure *out,
                         tk_error *err)
{
    int rc = tk_curve_check_range(c, err);
    if (rc)
        return rc;
    tk_strut_finder *own = NULL;
    if (!f) {
        rc = tk_strut_finder_new(c, &own, err);
        if (rc)
            return rc;
        f = own;
    }
    double shortest = INFINITY;
    rc = tk_strut_finder_shortest(f, c, &shortest, NULL, err);
    tk_strut_finder_free(&own);
    if (rc)
        return rc;
    out->length = tk_curve_length(c);
    out->minrad = tk_curve_minrad(c, NULL);
    out->shortest = shortest;
    /* Definition 1. */
    out->thickness = fmin(2.0 * out->minrad, shortest);
    out->ropelength = out->length / (out->thickness / 2.0);
    return TK_OK;
}

int tk_thickness_contacts(const tk_curve *c, double rel_tol, tk_measure *m,
                          tk_strut_list *struts, tk_kink **kinks, size_t *nkinks,
                          tk_error *err)
{
    *kinks = NULL;
    *nkinks = 0;
    if (!(rel_tol >= 0.0))
        return tk_error_set(err, TK_EINVAL, "the tolerance must be >= 0 (got %g)", rel_tol);
    tk_strut_finder *f = NULL;
    int rc = tk_curve_check_range(c, err);
    if (!rc)
        rc = tk_strut_finder_new(c, &f, err);
    if (!rc)
        rc = tk_thickness_measure(c, f, m, err);
    if (!rc && isfinite(m->thickness)) {
        double bound = m->thickness * (1.0 + rel_tol);
        rc = tk_strut_finder_find(f, c, TK_ARC_ADMISSIBLE, m->thickness, bound, struts, err);
        if (!rc)
            rc = tk_kinks_find(c, bound, kinks, nkinks, err);
    }
    tk_strut_finder_free(&f);
    return rc;
}
