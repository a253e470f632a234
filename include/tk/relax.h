/* tightknot: relaxing a curve under a repulsive energy, to a shape of its
 * type that forgets the start's.
 *
 * The tightening flow is a gradient flow of ropelength: it ends in the
 * basin its start lies in.  A start's shape (the projection it was drawn
 * from, a crossing pushed to one side) can hold it in a basin above the
 * knot's lowest.  A repulsive energy, minimised at fixed length, spreads
 * every strand away from every other and smooths the curve out, keeping
 * the strands' arrangement (the type cannot change, below).  Relaxing
 * alone does not leave the start's basin (catalogue 10.124 relaxed
 * tightened to where the file does, 71.127); the moves below that change
 * the arrangement's shape by isotopy, turning inside out and wandering,
 * use it to even out what they make.
 *
 * The energy (of the vertices x_i, h the mean edge length):
 *     E = sum over pairs of edges of h^4 / r^4
 *       + w sum over edges e of a component of mean edge length h_c,
 *             of (|e| - h_c)^2 / h^2,
 * over pairs of edges that share no vertex, r their distance (not the
 * vertices': an edge can pass between two vertices, not through an edge
 * whose distance enters E), the first a discrete form of the energy
 * 1 / |x - y|^4 (near pairs penalise bending, far ones closeness), the
 * second springs that keep the vertices evenly spread (w = 20).  The
 * power is 4, not the Moebius energy's 2: 1 / |x - y|^2 is scale
 * invariant, a narrow passage costs it no more than a wide one of the
 * same shape, and relaxed polygons kept passages as narrow as half an
 * edge, so that a polygon on more vertices came out narrower (a turn of
 * catalogue 10.14 on 468 vertices: strands 0.52 of an edge apart,
 * ropelength 1,786; with the fourth power 0.97 of an edge, 900; the
 * turns of 14 knots of 8 to 10 crossings 0.52 to 0.96 of an edge apart,
 * now 0.97 to 0.99, and 27% to 60% shorter: bench/FIGURES.md).
 * With a target curve y of as many vertices, a pull
 *       + p sum over vertices of |x_i - y_i|^2 / h_y^2 (h_y the target's mean edge)
 * draws the curve toward y while the repulsion keeps its strands apart:
 * a deformation as large as the knot itself that is an isotopy, where a
 * displacement applied at once keeps the type only while it is smaller
 * than the gaps between strands.
 */
#ifndef TK_RELAX_H
#define TK_RELAX_H

#include <stddef.h>
#include <stdint.h>

#include "tk/curve.h"
#include "tk/error.h"

/* E above (with the pull when target is not NULL), and its gradient into
 * grad (3 per vertex) when not NULL. */
double tk_relax_energy(const tk_curve *c, const tk_curve *target, double pull, double *grad);

/* The least distance between two edges that share no vertex (+inf when
 * there are none). */
double tk_relax_gap(const tk_curve *c);

/* Relaxes a copy of c into *out (toward target with the given pull when
 * target is not NULL: as many vertices, pull >= 0) by up to `iterations`
 * steps of gradient descent on E, each rescaled about the centroid to c's length.  No
 * vertex moves by more than a quarter of the gap (tk_relax_gap) in one
 * step, so along the straight path between two steps every point of an
 * edge moves by less than half of it and no two edges that share no
 * vertex meet: the knot or link type is kept exactly.  Stops early when E
 * falls by less than 1e-9 (relative) in 50 steps.  Closed components
 * only (TK_EINVAL otherwise); *steps (when not NULL) gets the steps
 * taken. */
int tk_relax(const tk_curve *c, const tk_curve *target, double pull, int iterations,
             tk_curve **out, int *steps, tk_error *err);

/* The curve turned inside out: inverted in the unit sphere about a centre
 * (x -> (x - c) / |x - c|^2) and mirrored, scaled back to its length,
 * resampled to `vertices` and relaxed for `steps` (tk_relax).  Strands
 * near the centre go far out and far ones come in: what the curve wound
 * around it now winds around the curve (a torus knot's T(p, q) form
 * becomes its T(q, p) form), a shape of the same type far from the
 * start's that no small deformation reaches.  The centre is the curve's
 * centroid as a wire plus `offset` times its spread (the root mean
 * square distance of its points from the centroid).  Inversion and
 * mirror keep the type and its chirality on the smooth curve.  The
 * inverted polygon, on 32 x `vertices` (at least 1,000), comes down to
 * `vertices` by triangle moves (tk_isotopy_coarsen), which keep its type
 * exactly; where too few vertices would let it pass through itself their
 * count doubles (twice at most; the result can have 4 x `vertices`), and
 * the result's Alexander polynomials and linking numbers are checked
 * too.  TK_ENUMERIC when the centre lies within 1e-3 of the spread from
 * the curve, the type could not be kept, or the result's ropelength is
 * more than 20 times the curve's (a component far from the centre
 * shrinks by the square of its distance). */
int tk_relax_turn(const tk_curve *c, const double offset[3], size_t vertices, int steps,
                  tk_curve **out, tk_error *err);

/* A centre's offset for tk_relax_turn drawn from the stream *state:
 * normal coordinates of standard deviation 0.15 (of the spread): a point
 * near the centroid, where the curve winds around. */
void tk_relax_turn_offset(uint64_t *state, double offset[3]);

/* A start of another shape with c's type, guaranteed: c drawn by a pull
 * (tk_relax, `steps` steps) toward a far target (c displaced by a smooth
 * random field, three Fourier modes of amplitude its components' mean
 * radius, drawn from `seed`), then relaxed for `steps` more at the length
 * it reached.  Unlike a displacement applied at once (tk_generate_deform,
 * which checks the type with invariants that cannot tell every link of
 * unknots apart), no edge passes through another on the way: the type is
 * kept whatever the invariants can see.  Closed components only. */
int tk_relax_wander(const tk_curve *c, uint64_t seed, int steps, tk_curve **out, tk_error *err);

#endif
