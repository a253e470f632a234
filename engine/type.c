/* The knot or link type of a run: the start's, told once, and the checks
 * that the run's curve still has it (after each resampling and escape
 * deformation, schedule.c, and when the run stops, tighten.c).  Below the
 * rooms (run.h), so that the schedule, which makes new polygons, checks
 * them without calling up to the run. */
#include "run.h"

int tk_type_start(tk_run *r, const tk_curve *start, const tk_invariants *known, tk_error *err)
{
    r->type.checked_step = -1;
    if (known)
        return tk_invariants_copy(known, &r->type.start, err);
    double t0 = tk_clock();
    tk_error why;
    int rc = tk_invariants_compute(start, &r->type.start, &why);
    r->type.seconds += tk_clock() - t0;
    if (rc)
        tk_error_set(err, rc, "the knot or link type of the start cannot be told: %s",
                     why.message);
    return rc;
}

int tk_type_check(tk_run *r, const char *when, tk_error *err)
{
    const tk_curve *c = r->shared.curve;
    double t0 = tk_clock();
    tk_error why;
    int rc = tk_invariants_compute(c, &r->type.latest, &why);
    if (!rc)
        rc = tk_invariants_compare(&r->type.start, &r->type.latest, &why);
    r->type.seconds += tk_clock() - t0;
    r->type.checked_step = r->life.latest.step;
    r->type.checked_vertices = c->nvert;
    if (rc)
        return tk_error_set(err, rc == TK_ETYPE ? TK_ETYPE : rc, "%s: %s", when, why.message);
    return TK_OK;
}

int tk_type_kept(tk_run *r, const tk_curve *c, bool *kept, tk_error *err)
{
    tk_invariants type = TK_INVARIANTS_INIT;
    tk_error why;
    double t0 = tk_clock();
    int rc = tk_invariants_compute(c, &type, &why);
    *kept = rc == TK_OK && tk_invariants_compare(&r->type.start, &type, NULL) == TK_OK;
    r->type.seconds += tk_clock() - t0;
    tk_invariants_free(&type);
    return rc == TK_ENOMEM ? tk_error_set(err, rc, "%s", why.message) : TK_OK;
}

void tk_type_free(tk_run *r)
{
    tk_invariants_free(&r->type.start);
    tk_invariants_free(&r->type.latest);
}
