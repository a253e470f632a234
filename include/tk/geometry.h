/* tightknot: the local geometry of a polygon and its gradients.
 *
 * Distances between edges with their closest points (robust for parallel
 * and nearly parallel edges), the polygonal radius of curvature at a vertex
 * (equation 3) and the gradients of both (equations 6 and 7), and the
 * gradient of length (equation 14).  Pure functions of their arguments.
 */
#ifndef TK_GEOMETRY_H
#define TK_GEOMETRY_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/curve.h"

/* Vectors of R^3 as three doubles: the products the geometry and the
 * invariants are written in. */
static inline double tk_dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void tk_sub3(const double *a, const double *b, double *out)
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

static inline void tk_cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Closest points of two segments p(s) = a0 + s (a1 - a0) and
 * q(t) = b0 + t (b1 - b0), s, t in [0, 1]. */
typedef struct tk_closest {
    double dist;  /* |p - q| */
    double s, t;  /* parameters of the closest points */
    double p[3];  /* closest point on the first segment */
    double q[3];  /* closest point on the second segment */
} tk_closest;

/* Parameters closer than this to 0 or 1 are snapped to the end point, so
 * that the two edges sharing a vertex see a contact at that vertex
 * identically (same closest points, same distance, bit for bit); on an
 * edge longer than the distance, closer than this times the distance
 * over the edge's length, so that a snap never moves a closest point by
 * more than 1e-7 of the distance (on an edge 6e7 long, 1e-7 of its
 * parameter is 6 units: a pair 0.002 apart measured 1.002, and the flow
 * passed one strand through the other). */
#define TK_SNAP_PARAMETER 1e-7

/* Closest points of two segments.  Where the minimum is not unique
 * (parallel segments) one minimising pair is chosen deterministically.
 * Degenerate (zero-length) segments are handled as points. */
void tk_segment_closest(const double a0[3], const double a1[3],
                        const double b0[3], const double b1[3],
                        tk_closest *out);

/* Whether the segment pq comes within tol of the closed triangle abc
 * (meets it when tol is 0): through its interior, touching an edge, or
 * lying in its plane across it.  A degenerate triangle (a, b, c on a
 * line) is the segments between them.  What a triangle move sweeps: the
 * polygon a b c becomes a c through the triangle, and an edge that meets
 * it is one a strand would pass through. */
bool tk_segment_meets_triangle(const double a[3], const double b[3], const double c[3],
                               const double p[3], const double q[3], double tol);

/* Gradient of the edge-edge distance (equation 7) with respect to the four
 * end points (a0, a1, b0, b1), as 12 numbers, given their closest points.
 * Zero when the distance is zero. */
void tk_segment_distance_gradient(const tk_closest *c, double grad[12]);

/* The polygonal radius of curvature at vertex v between edges
 * (prev -> v) and (v -> next), equation (3):
 *     min(|v - prev|, |next - v|) / (2 tan(theta / 2)),
 * theta the turning angle.  +INFINITY for a straight vertex, 0 for a full
 * reversal. */
double tk_vertex_minrad(const double prev[3], const double v[3],
                        const double next[3]);

/* The same and its gradient with respect to (prev, v, next) as 9 numbers
 * (equation 6, or its twin when the incoming edge is the shorter one).
 * Returns the radius; at a straight vertex returns +INFINITY and a zero
 * gradient. */
double tk_vertex_minrad_gradient(const double prev[3], const double v[3],
                                 const double next[3], double grad[9]);

/* Equation (3) is the minimum of two smooth functions, one per edge:
 *     |e| / (2 tan(theta / 2)),  e = v - prev (edge 0) or next - v (edge 1).
 * Returns the chosen one's value and its gradient with respect to
 * (prev, v, next) (equation 6 for edge 1); +INFINITY and a zero gradient
 * at a straight vertex. */
double tk_vertex_radius_gradient(const double prev[3], const double v[3],
                                 const double next[3], int edge, double grad[9]);

/* Turning angle at v in [0, pi]. */
double tk_vertex_turning(const double prev[3], const double v[3],
                         const double next[3]);

/* Whether global vertex v of the curve has two edges (interior vertex of an
 * open component, or any vertex of a closed one), and its neighbours. */
int tk_curve_vertex_neighbours(const tk_curve *c, size_t v, size_t *prev,
                               size_t *next);

/* Minimum of tk_vertex_minrad over every vertex with two edges, and where it
 * is (vertex index, or (size_t)-1 when there is none: +INFINITY). */
double tk_curve_minrad(const tk_curve *c, size_t *where);

/* Gradient of the curve's length (equation 14), 3 * nvert numbers. */
void tk_curve_length_gradient(const tk_curve *c, double *grad);

#endif
