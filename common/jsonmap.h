/* tightknot: JSON forms of the engine's results, shared by the command
 * line and the service so that both write the same documents.
 *
 * Numbers that are not finite become null (JSON has no inf or nan).
 */
#ifndef TK_JSONMAP_H
#define TK_JSONMAP_H

#include <stdbool.h>
#include <stddef.h>

#include <jansson.h>

#include "tk/curve.h"
#include "tk/invariants.h"
#include "tk/record.h"
#include "tk/struts.h"
#include "tk/tighten.h"

json_t *tk_json_number(double x);
json_t *tk_json_point(const double p[3]);

/* A string from arbitrary bytes: bytes that are not ASCII show as '?' when
 * the text is not valid UTF-8. */
json_t *tk_json_text(const char *s);

/* The named fields of a record (tk/record.h) as a JSON object: whole
 * kinds as integers, BOOL as true or false, reals that are not finite as
 * null. */
json_t *tk_json_record(const tk_field *table, size_t n, const void *record);

/* Sets the fields named in the JSON object obj (null for a REAL is NaN,
 * which only a measurement takes).  TK_EINVAL when obj is not
 * an object, a name is unknown or a value is of the wrong type or out of
 * its domain; *bad (when not NULL) then points at the name (valid while
 * obj lives) and the record may have been changed by the names before. */
int tk_json_record_set(const tk_field *table, size_t n, void *record, const json_t *obj,
                       const char **bad, tk_error *err);

/* One step's figures, every field of tk_step_report. */
json_t *tk_json_step(const tk_step_report *s);

/* The run options users can give (the named fields of tk_options). */
json_t *tk_json_options(const tk_options *o);

/* The escapes a run tried (tk_run_escapes): [{"step", "from", "amplitude",
 * "reached" (null while under way), "improved"}]. */
json_t *tk_json_escapes(const tk_escape *e, size_t count);

/* How sure a run is of its result: the distinct basins (critical
 * configurations) its tightenings on the final polygon reached.  Each
 * tightening there is one sighting: the first (the best value when the
 * first try on the final polygon began) and each try's `reached`;
 * explored tries, judged on the coarsest polygon only, and tries given up
 * are none.  Sightings within TK_BASIN_SAME (relative) of each other are
 * one basin.  `final` is the run's result (a sighting too when no try was
 * made).  {"basins": [{"ropelength", "times"}] lowest first,
 * "best_reached": how many sightings the lowest basin had, "note": null,
 * or "found once: run longer or with more seeds" when that is 1}. */
#define TK_BASIN_SAME 1e-4
json_t *tk_json_basins(const tk_escape *e, size_t count, double final);

/* The contacts of curve c:
 *   {"components": [{"vertices", "closed", "length", "start"}],
 *    "struts": [{"edges": [[comp, edge], [comp, edge]], "s", "t", "p", "q",
 *                "length", "arclength": [a, b], "force"}],
 *    "kinks": [{"comp", "vertex", "minrad", "arclength", "force"}],
 *    "constraints": [{"comp", "vertex", "constraint", "arclength", "force"}]}
 * "arclength" is the position along the components laid end to end in
 * order ("start" is where each component begins), the coordinates of the
 * contact map.  Forces are included only when with_force; "constraints"
 * (the curve's pins, "constraint" as --constrain writes it) only when the
 * curve has some, their forces from pin_force (tk_run_pin_forces). */
json_t *tk_json_contacts(const tk_curve *c, const tk_strut *struts, size_t nstruts,
                         const tk_kink *kinks, size_t nkinks, bool with_force,
                         const double *pin_force);

/* The knot or link type of a curve (tk/invariants.h):
 *   {"alexander": [[1, -1, 1], ...], "alexander_text": ["1 - t + t^2", ...],
 *    "determinants": [3, ...], "link_determinant": 2,
 *    "linking": [[0, 1], [1, 0]], "complete": true}
 * One entry per component in the first three: the Alexander polynomial's
 * coefficients of 1, t, t^2, ... (Delta(1) = 1), the same as text, and
 * |Delta(-1)|; null for a component whose type is not known (open, or
 * too many crossings).  "link_determinant" is the whole link's (null when
 * not known).  "linking" is the symmetric matrix of linking
 * numbers (0 on the diagonal and for open components).  JSON null when
 * inv is NULL or has no components (not computed). */
json_t *tk_json_invariants(const tk_invariants *inv);

/* Serialises with 17 significant digits (numbers read back as the same
 * doubles); compact or indented.  NULL when out of memory. */
char *tk_json_dump(const json_t *value, bool indent);

#endif
