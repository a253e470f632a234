/* tightknot: finding struts (self-contacts) with a bounding-volume tree.
 *
 * A strut is a pair of edges (e_i, e_j) at (near) minimal distance whose
 * closest points form a local minimum of the self-distance function (a
 * doubly critical pair, Definition 1): where a closest point falls on a
 * vertex, the pair counts only if that vertex is also a minimum across the
 * vertex's other edge, and the contact is reported once, by the edge that
 * starts at that vertex.
 *
 * Edge pairs are filtered by the arc between them (Theorem 3): walking
 * along the shorter arc (each arc, for closed components) the vertices
 * strictly between the two edges must be able to turn by at least pi in
 * total.  Two weightings of "able to turn" are used:
 *   - TK_ARC_ADMISSIBLE: vertex k turns at most 2 atan(l_k / tau), l_k the
 *     shorter of its edges, tau the target diameter (Theorem 3, generalised
 *     to unequal edges).  This is the flow's constraint set.
 *   - TK_ARC_FENCHEL: vertex k turns by its actual turning angle.  A doubly
 *     critical pair always has at least pi of turning on each arc (Fenchel's
 *     theorem), so this filter loses no doubly critical pair; used to
 *     measure thickness of arbitrary input.
 * Pairs on different components are always admissible.
 *
 * The tree is built over edges in curve order (each node an arc), which
 * makes refitting after a step O(V) and lets whole node pairs be skipped by
 * the arc filter.  A finder owns its tree and workspace: one per thread.
 */
#ifndef TK_STRUTS_H
#define TK_STRUTS_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/curve.h"
#include "tk/error.h"

typedef struct tk_strut {
    size_t comp[2];  /* components of the two edges */
    size_t edge[2];  /* edge indices within their components */
    double s, t;     /* parameters along the two edges, in [0, 1] */
    double p[3];     /* closest point on the first edge */
    double q[3];     /* closest point on the second edge */
    double length;   /* |p - q| */
    double force;    /* compression from the flow's NNLS (0 when unknown) */
} tk_strut;

typedef struct tk_kink {
    size_t comp;     /* component */
    size_t vertex;   /* vertex index within its component */
    double minrad;   /* polygonal radius of curvature there (equation 3) */
    double force;    /* compression from the flow's NNLS (0 when unknown) */
} tk_kink;

/* A growable list; free with tk_strut_list_free. */
typedef struct tk_strut_list {
    tk_strut *items;
    size_t count;
    size_t capacity;
} tk_strut_list;

/* qsort/bsearch order of struts by their edge pairs (component, edge of
 * the first edge, then of the second); the parameters are not compared. */
int tk_strut_compare_edges(const void *a, const void *b);

void tk_strut_list_clear(tk_strut_list *list);
void tk_strut_list_free(tk_strut_list *list);

typedef enum tk_arc_rule {
    TK_ARC_ADMISSIBLE = 0,
    TK_ARC_FENCHEL = 1
} tk_arc_rule;

typedef struct tk_strut_finder tk_strut_finder;

/* Builds a finder (and its tree) for curve c.  The finder keeps no pointer
 * to c: every call passes the curve, which must keep its vertex counts. */
int tk_strut_finder_new(const tk_curve *c, tk_strut_finder **out,
                        tk_error *err);
void tk_strut_finder_free(tk_strut_finder **p);

/* Refits the tree's boxes after the vertices moved (same counts).  O(V). */
void tk_strut_finder_refit(tk_strut_finder *f, const tk_curve *c);

/* Appends to out every strut whose length is <= bound, among edge pairs
 * passing the arc rule (tau is the diameter used by TK_ARC_ADMISSIBLE; it
 * is ignored by TK_ARC_FENCHEL).  Sorted by (comp, edge) pairs. */
int tk_strut_finder_find(tk_strut_finder *f, const tk_curve *c,
                         tk_arc_rule rule, double tau, double bound,
                         tk_strut_list *out, tk_error *err);

/* The same without the local-minimum test: every edge pair passing the arc
 * rule whose distance is <= bound, each with its own closest points, except
 * that a local minimum on a vertex is still listed once, by its owner.  So
 * the pairs next to a contact (whose closest points sit on the vertex
 * towards it) are listed too: where edges are nearly parallel they are
 * about as close, and they are the contact's next owners when it slides. */
int tk_strut_finder_find_pairs(tk_strut_finder *f, const tk_curve *c,
                               tk_arc_rule rule, double tau, double bound,
                               tk_strut_list *out, tk_error *err);

/* The shortest doubly critical self-distance of the curve (Definition 1),
 * by branch and bound on the tree; +INFINITY when there is none (e.g. a
 * single open edge).  If where is non-NULL it receives that strut. */
int tk_strut_finder_shortest(tk_strut_finder *f, const tk_curve *c,
                             double *shortest, tk_strut *where,
                             tk_error *err);

/* The smallest distance among edge pairs passing the arc rule, with no
 * local-minimum test, when it is below `below`; otherwise `below`.  The
 * flow's step control: by Theorem 3 a curve whose radii of curvature keep
 * the bound has thickness >= tau exactly when this is >= tau. */
int tk_strut_finder_closest_pair(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule,
                                 double tau, double below, double *dist, tk_error *err);

/* For checks of curves near c, each vertex within `reach` of c's (the
 * trial points of a step): an edge pair's distance there differs from
 * c's by at most 2 reach, so only the pairs closer than tau + 2 reach at
 * c (and allowed by the arc rule, which changes with the curve) can be
 * below tau.  Finds them once (the finder fitted to c).  Replaces the
 * last such list.  While they hold every pair a query needs (its curve
 * near enough c), tk_strut_finder_find and _find_pairs look at them
 * instead of the tree, to the same answer. */
int tk_strut_finder_near(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule, double tau,
                         double reach, tk_error *err);
/* Whether the last list of tk_strut_finder_near (with this rule and tau,
 * and a reach of at most `most`) covers every curve c + s h motion,
 * 0 <= s <= 1 (motion 3V). */
bool tk_strut_finder_near_covers(const tk_strut_finder *f, const tk_curve *c, const double *motion,
                                 double h, double most, tk_arc_rule rule, double tau);
/* tk_strut_finder_closest_pair(f, t, rule, tau, below, dist) with the
 * rule and tau of the last tk_strut_finder_near, from its pairs alone:
 * the same answer, for below <= tau.  False (and *dist untouched) when t
 * is not near enough its curve to tell; the finder need not be fitted
 * to t. */
bool tk_strut_finder_closest_near(tk_strut_finder *f, const tk_curve *t, double below,
                                  double *dist);

/* tk_strut_finder_shortest(f, t) from the pairs of the last
 * tk_strut_finder_near (TK_ARC_ADMISSIBLE; the Fenchel rule's pairs of
 * a curve whose turns keep the curvature bound, or nearly, are among
 * them): the same answer.  False (*shortest untouched) when t is not
 * near enough that curve, or bends too far beyond the bound, to tell;
 * tk_strut_finder_shortest tries this first.  The finder need not be
 * fitted to t. */
bool tk_strut_finder_shortest_near(tk_strut_finder *f, const tk_curve *t, double *shortest,
                                   tk_strut *where);

/* The same answers by checking every pair of edges: O(V^2), for tests and
 * for comparison in benchmarks. */
int tk_struts_find_brute(const tk_curve *c, tk_arc_rule rule, double tau,
                         double bound, tk_strut_list *out, tk_error *err);
double tk_struts_shortest_brute(const tk_curve *c, tk_strut *where);

/* Whether the global edges i and j pass the arc rule (exposed for tests). */
bool tk_struts_pair_allowed(const tk_curve *c, tk_arc_rule rule, double tau,
                            size_t i, size_t j);

/* Whether the straight path from a to b (the same components and vertex
 * counts; every vertex moving at constant speed from its place on a to
 * its place on b) is an isotopy: no two edges that are not neighbours
 * meet on the way, so no strand passes through another and the knot or
 * link type is kept, whatever invariants can tell.  *embedded false also
 * when two such edges come within 1e-6 of a's mean edge on the way (a
 * meeting cannot be told from that by rounding), or when proving it
 * takes more than 2,000 pieces of the path.  TK_ENOMEM only. */
int tk_struts_path_embedded(const tk_curve *a, const tk_curve *b, bool *embedded,
                            tk_error *err);

/* Every vertex whose 2 * minrad is <= bound (kinks), appended to *out
 * (a malloc'd array the caller frees), *count set. */
int tk_kinks_find(const tk_curve *c, double bound, tk_kink **out,
                  size_t *count, tk_error *err);

#endif
