/* tightknot: constraints on vertices.
 *
 * A vertex can be held at a point, on a plane or on a line: the ends of
 * the open ropes of a clasp slide on planes (the paper's Table 2, the
 * Gehring clasp).  The pins are part of the curve (tk_curve.pins): copies
 * and resamplings carry them, the VECT format writes them as comments
 * ("# Constraint k Plane a b c d" in the header, "# Cst: k" after a
 * vertex), and the flow moves a pinned vertex only along its constraint:
 * its rows of the gradient and of the rigidity matrix are projected onto
 * the directions the constraint allows, which is the same as solving for
 * the constraint's own multiplier with the struts' (the projected least
 * squares problem min |P (A x + u)| has the same x), and the pinned
 * vertices are put back on their constraints after anything that moves
 * the whole curve (a rescaling, a resampling, an escape's deformation).
 */
#ifndef TK_PIN_H
#define TK_PIN_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/error.h"

/* A constraint on one vertex (the user's "constraint"; "pin" here, as
 * the flow's own constraints are the struts and kinks): the vertex stays
 * at a point, on a plane n . x = d, or on a line p + s t.  An open
 * component's end with no pin stays where it is (a point); FREE lets it
 * move as any vertex does. */
typedef enum tk_pin_kind { TK_PIN_FREE, TK_PIN_POINT, TK_PIN_PLANE, TK_PIN_LINE } tk_pin_kind;

typedef struct tk_pin {
    size_t comp, vertex; /* vertex within its component */
    tk_pin_kind kind;
    double normal[3];    /* PLANE: unit normal n; LINE: unit direction t */
    double offset;       /* PLANE: d */
    double point[3];     /* POINT: the point; LINE: a point of the line */
} tk_pin;

struct tk_curve;

/* The most constraints a command line or a job gives (a clasp has four). */
#define TK_PIN_MOST 1000

/* How far a pinned vertex may lie from its constraint and be put on it
 * (tk_curve_pins_settle), relative to the curve's shortest edge: the
 * catalogue's clasp writes its planes' normals to six digits, and its end
 * points lie up to 7.8e-6 off them, its shortest edge 0.49 long. */
#define TK_PIN_SETTLE 1e-3

/* Adds a pin to the curve (tk_curve.pins stay in the order of their
 * vertices): its vertex must exist and carry no pin yet, an
 * end of an open component or any vertex; a normal or direction must be
 * finite and not zero (it is made a unit vector, d with it); a POINT given
 * with `at_vertex` is pinned where the vertex is.  TK_EINVAL naming the
 * constraint otherwise. */
int tk_curve_pin_add(struct tk_curve *c, const tk_pin *pin, bool at_vertex, tk_error *err);

/* The pin of global vertex v, or NULL. */
const tk_pin *tk_curve_pin_of(const struct tk_curve *c, size_t v);

/* The distance of the pinned vertex from its constraint (0 for FREE). */
double tk_pin_distance(const struct tk_curve *c, const tk_pin *pin);

/* Puts every pinned vertex on its constraint (the nearest point of it). */
void tk_curve_pins_snap(struct tk_curve *c);

/* A start's pins: every pinned vertex within `tolerance` of its constraint
 * is put on it; TK_EINVAL naming the first farther one and by how much. */
int tk_curve_pins_settle(struct tk_curve *c, double tolerance, tk_error *err);
/* The same check, the curve left as it is. */
int tk_curve_pins_check(const struct tk_curve *c, double tolerance, tk_error *err);

/* Projects a motion v of the pinned vertex onto the directions its pin
 * allows: nothing for a POINT, the plane's for a PLANE, the line's for a
 * LINE, all for FREE. */
void tk_pin_project(const tk_pin *pin, double v[3]);

/* A pin as text, "COMP:VERTEX=KIND[:NUMBERS]" (the command line's
 * --constrain, the job's constraints): free, fixed (where the vertex is),
 * point:x,y,z, plane:nx,ny,nz,d (n . x = d), line:px,py,pz,tx,ty,tz.
 * tk_pin_parse sets *at_vertex for "fixed"; TK_EINVAL saying what is
 * wrong.  tk_pin_format writes the numbers with %.17g (as tk_snprintf). */
int tk_pin_parse(const char *text, tk_pin *out, bool *at_vertex, tk_error *err);
int tk_pin_format(const tk_pin *pin, char *buf, size_t size);

/* The kind's name: "free", "point", "plane", "line". */
const char *tk_pin_kind_name(tk_pin_kind kind);

/* A pin's numbers, the one layout its text and the VECT comment share:
 * none (FREE), x y z (POINT), nx ny nz d (PLANE), px py pz tx ty tz
 * (LINE).  tk_pin_count says how many, tk_pin_numbers writes them into v
 * (6 at most), tk_pin_set_numbers sets the pin's from v. */
int tk_pin_count(tk_pin_kind kind);
void tk_pin_numbers(const tk_pin *pin, double v[6]);
void tk_pin_set_numbers(tk_pin *pin, const double *v);

/* The kind named `name` (any case), its first n bytes; -1 when none. */
int tk_pin_kind_of(const char *name, size_t n);

#endif
