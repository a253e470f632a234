/* tightknot: example knots and links, made by the project's own code.
 *
 * All generators produce embedded polygons, closed but for the clasp's
 * ropes, with vertices evenly spaced in parameter; `vertices` is the count per component (0 = the
 * generator's default).  These are the examples the project ships.
 */
#ifndef TK_GENERATE_H
#define TK_GENERATE_H

#include <stddef.h>

#include "tk/curve.h"
#include "tk/error.h"

/* Torus knot or link T(p, q) on the standard torus (major radius 2, minor
 * radius 1): gcd(p, q) components, p, q >= 1. */
int tk_generate_torus(int p, int q, size_t vertices, tk_curve **out,
                      tk_error *err);

/* Hopf link: two round circles of radius 1, in perpendicular planes, each
 * passing through the other's centre (the tight Hopf link when the tube
 * diameter is 1).  Each circle has a vertex at the other's centre. */
int tk_generate_hopf(size_t vertices, tk_curve **out, tk_error *err);

/* Borromean rings: three mutually perpendicular ellipses with semi-axes 2
 * and 1. */
int tk_generate_borromean(size_t vertices, tk_curve **out, tk_error *err);

/* A chain of k >= 1 round rings of radius 1, centres 1.5 apart along the x
 * axis, in alternating planes, each linked with its neighbours only. */
int tk_generate_chain(size_t k, size_t vertices, tk_curve **out,
                      tk_error *err);

/* The clasp of the paper's Table 2 (its Figure 6): two open ropes of n
 * vertices, each hooked over the other at right angles.  Rope 0 lies in
 * the plane y = 0 and hangs from the plane z = 2.5 (both its ends slide on
 * it: a plane pin n = (0, 0, 1), d = 2.5), rope 1 in the plane x = 0
 * stands on z = -2.5 (n = (0, 0, -1), d = 2.5).  Each is two straight legs 3 apart
 * joined by a half circle of radius 1.5 round the z axis, the tips 2
 * apart on it (rope 0's below), vertices at equal arclength; the ropes
 * stay more than 1.5 apart.  Tightened, the ropes' length beyond the planes, L - (sum of
 * the four ends' d), over the tube's diameter is the clasp's measure
 * (2 pi - 2 for half circles about the tips; below that tight, as the
 * tips part: Cantarella, Fu, Kusner, Sullivan and Wrinkle, 2006).  At
 * least 16 vertices a rope (TK_EINVAL), default 64. */
int tk_generate_clasp(size_t vertices, tk_curve **out, tk_error *err);

/* The figure-eight knot as the closed curve
 *     ((2 + cos 2t) cos 3t, (2 + cos 2t) sin 3t, sin 4t), t in [0, 2 pi)
 * (a start that is far from tight and, unlike the catalogue's, symmetric). */
int tk_generate_figure_eight(size_t vertices, tk_curve **out, tk_error *err);

/* The Lissajous knot (cos(nx t + px), cos(ny t + py), cos(nz t + pz)),
 * t in [0, 2 pi), freq = (nx, ny, nz) pairwise coprime and >= 1, phase =
 * (px, py, pz).  Its projection on the xy plane has 2 nx ny - nx - ny
 * crossings.  (3, 2, 5) with phases (0.7, 0.2, 0) is the knot 6_1,
 * (3, 2, 7) with (0.7, 0.7, 0) the knot 5_2 (Bogle, Hearst, Jones and
 * Stoilov, Lissajous knots, 1994; tightknot info shows the type).  At
 * least 12 vertices per turn of the fastest angle (default 60), so that
 * every edge turns that angle by less than pi / 6, and at most 10,000
 * (TK_ELIMIT); phases for which the polygon passes through itself (all 0,
 * for one) are refused (TK_EINVAL). */
int tk_generate_lissajous(const int freq[3], const double phase[3], size_t vertices,
                          tk_curve **out, tk_error *err);

/* The same knot or link, disguised: each component's vertices moved along
 * it to uneven spacing (arclength s -> s + 0.3 L sin(2 pi s / L + phase)
 * / (2 pi), spacing ratio up to 1.86), each vertex displaced by a normal
 * random vector of standard deviation `perturbation` times the mean edge
 * length per coordinate, then the whole turned by a uniformly random
 * rotation.  Everything is drawn from `seed`: the same seed gives the same
 * curve on every machine.  The knot type survives when the perturbation is
 * small against the gaps between strands (the caller's to choose; check
 * with tk/invariants.h).  Vertex counts, closedness and colours are kept;
 * open components keep their end points in place before the rotation. */
int tk_generate_disguise(const tk_curve *src, unsigned long long seed, double perturbation,
                         tk_curve **out, tk_error *err);

/* A smooth displacement of `from` into c (same counts): every vertex
 * (but an open component's ends) moved by the sum over k = 1..modes of
 * amplitude / k (a_k cos(k phi) + b_k sin(k phi)), phi = 2 pi s / L the
 * phase of its arclength s along its component of length L; component
 * j's vectors a_1, b_1, a_2, ... are coef[j * modes * 6 ...], three
 * coordinates each.  Strands near each other move together, so a few
 * modes reshape the curve without passing it through itself at once. */
void tk_generate_fourier(tk_curve *c, const tk_curve *from, const double *coef, int modes,
                         double amplitude);

/* A start of another shape with src's type: the largest smooth
 * displacement (tk_generate_fourier, TK_DEFORM_MODES modes, normal
 * coefficients drawn from `seed`) that keeps src's knot or link type, on
 * the way from src too (tk_struts_path_embedded: the invariants cannot
 * tell every link apart), and at least `keep` (in (0, 1]) of its
 * thickness.  Its amplitude starts at
 * the mean radius of src's components taken as circles (L / 2 pi) and
 * shrinks by 0.7 until both hold: far from src at once, where the
 * strands leave room.  TK_ENUMERIC when no amplitude down to 1e-6 of the
 * start does. */
#define TK_DEFORM_MODES 3
int tk_generate_deform(const tk_curve *src, unsigned long long seed, double keep,
                       tk_curve **out, tk_error *err);

#endif
