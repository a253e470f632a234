/* tightknot: polygonal knots and links.
 *
 * A curve is a list of components; each component is a closed polygon or an
 * open polyline.  All vertices live in one flat array (x0 y0 z0 x1 y1 z1 ...),
 * component c owning vertices offset[c] .. offset[c+1]-1, so that the
 * geometry and the flow work on one R^{3V} vector as the paper does.
 *
 * Edges: edge k of component c runs from its vertex k to vertex k+1 (the
 * last edge of a closed component wraps to its vertex 0).  A closed
 * component with n vertices has n edges, an open one n-1.  Edges are also
 * numbered globally in component order (tk_curve_edge_count, tk_curve_edge).
 *
 * A tk_curve is a plain value: functions that change it say so; nothing is
 * shared between two curves.
 */
#ifndef TK_CURVE_H
#define TK_CURVE_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/error.h"
#include "tk/pin.h"

typedef struct tk_curve {
    size_t ncomp;     /* number of components (>= 1 for a real curve) */
    size_t nvert;     /* total number of vertices */
    size_t *offset;   /* ncomp + 1 entries; offset[ncomp] == nvert */
    bool *closed;     /* per component */
    double *xyz;      /* 3 * nvert coordinates */
    bool has_colour;  /* true when colour holds one RGBA per component */
    double *colour;   /* 4 * ncomp, or NULL */
    tk_pin *pins;     /* npins constraints on vertices, at most one a vertex */
    size_t npins;
} tk_curve;

/* One edge of a curve, resolved to its vertices. */
typedef struct tk_edge {
    size_t comp;  /* component */
    size_t index; /* edge index within its component */
    size_t head;  /* global index of its first vertex */
    size_t tail;  /* global index of its second vertex */
} tk_edge;

/* Allocates a curve with ncomp components of the given vertex counts and
 * closedness, coordinates zeroed.  counts/closed have ncomp entries. */
int tk_curve_new(tk_curve **out, size_t ncomp, const size_t *counts,
                 const bool *closed, tk_error *err);

/* Frees a curve and clears the pointer; tolerates NULL and *p == NULL. */
void tk_curve_free(tk_curve **p);

/* A deep copy. */
int tk_curve_copy(const tk_curve *src, tk_curve **out, tk_error *err);

/* Number of vertices of component c. */
size_t tk_curve_comp_vertices(const tk_curve *c, size_t comp);

/* Number of edges of component c (n if closed, n-1 if open). */
size_t tk_curve_comp_edges(const tk_curve *c, size_t comp);

/* Total number of edges. */
size_t tk_curve_edge_count(const tk_curve *c);

/* Global index of the first edge of component comp. */
size_t tk_curve_comp_first_edge(const tk_curve *c, size_t comp);

/* Resolves a global edge index (0 .. edge_count-1). */
tk_edge tk_curve_edge(const tk_curve *c, size_t global_edge);

/* Global vertex index of vertex k of component comp, with k taken modulo the
 * component's vertex count for closed components. */
size_t tk_curve_vertex_index(const tk_curve *c, size_t comp, size_t k);

/* Pointer to the 3 coordinates of global vertex v. */
static inline double *tk_curve_vertex(const tk_curve *c, size_t v)
{
    return c->xyz + 3 * v;
}

/* Length of edge (comp, index); of component comp; of the whole curve. */
double tk_curve_edge_length(const tk_curve *c, size_t comp, size_t index);
double tk_curve_comp_length(const tk_curve *c, size_t comp);
double tk_curve_length(const tk_curve *c);

/* Shortest and longest edge of the whole curve. */
void tk_curve_edge_range(const tk_curve *c, double *shortest, double *longest);

/* Rigid motions and scaling, applied in place, to the pins too (their
 * points, planes and lines move with the curve). rotation is a row-major
 * 3x3 matrix (assumed orthogonal; not checked). */
void tk_curve_translate(tk_curve *c, const double shift[3]);
void tk_curve_rotate(tk_curve *c, const double rotation[9]);
void tk_curve_scale(tk_curve *c, double factor);

/* Centre of mass of the vertices. */
void tk_curve_centroid(const tk_curve *c, double centre[3]);

/* Checks the invariants every engine function relies on: finite
 * coordinates, closed components of >= 3 vertices, open of >= 2, no
 * zero-length edge.  Fails with TK_EINVAL naming the first offence. */
int tk_curve_validate(const tk_curve *c, tk_error *err);

/* The magnitudes the engine measures and tightens in.  Squared distances
 * and the gradients of minrad (powers of 1/|e| up to the second) must stay
 * far from overflow and underflow for every finite input, so coordinates
 * are bounded in magnitude and edges from below.  Any ordinary unit (a
 * nanometre tube in metres, a light-year tube in metres) fits. */
#define TK_CURVE_COORD_MAX 1e30
#define TK_CURVE_EDGE_MIN 1e-30

/* tk_curve_validate, and every coordinate within +-TK_CURVE_COORD_MAX and
 * every edge at least TK_CURVE_EDGE_MIN long: what measuring a curve needs.
 * A VECT file may hold any finite double (it round-trips exactly); this is
 * the engine's domain, not the format's.  Fails with TK_EINVAL naming the
 * first offence and the bound. */
int tk_curve_check_range(const tk_curve *c, tk_error *err);

/* A new curve whose component c has counts[c] vertices placed at equal
 * arclength along a C^2 cubic spline through the old vertices (periodic for
 * closed components, natural for open ones, parametrised by chord length).
 * Open components keep both end points.  Used for re-resolution. */
int tk_curve_resample(const tk_curve *src, const size_t *counts,
                      tk_curve **out, tk_error *err);

/* `total` vertices shared among src's components in proportion to their
 * lengths, into counts[ncomp] (each closed component gets at least 3,
 * each open at least 2: TK_EINVAL when total is below that). */
int tk_curve_share_total(const tk_curve *src, size_t total, size_t *counts, tk_error *err);

/* As tk_curve_resample, with `total` vertices shared among components in
 * proportion to their lengths (each closed component gets at least 3, each
 * open at least 2). */
int tk_curve_resample_total(const tk_curve *src, size_t total, tk_curve **out,
                            tk_error *err);

/* Moves vertices along the polygon itself (no smoothing) to equal arclength
 * spacing on each component (open components keep their end points), so
 * the edges come out equal up to the corners they cut.  In place; vertex
 * counts unchanged. */
int tk_curve_equilateralize(tk_curve *c, tk_error *err);

#endif
