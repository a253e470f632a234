/* Strut search.
 *
 * The tree: a binary bounding-box hierarchy over the edges in curve order.
 * Each node covers a contiguous range of global edge indices, never
 * straddling a component boundary below the nodes that split components
 * apart, so that a node is an arc of one component.  Building is O(E log E)
 * only in the box fitting (the split is the midpoint of the range), refit is
 * O(E).  Node pairs are pruned by box distance and by the arc rule.
 *
 * One contact, one strut: the closest points (p, q) of an edge pair may sit
 * on a vertex shared with a neighbouring edge.  The pair then stands for a
 * contact only if (p, q) is also the minimum over every other edge pair that
 * contains p and q (squared distance is convex on each pair of edges, so
 * that is the same as a local minimum of the self-distance: Definition 1's
 * doubly critical test), and the contact is reported by one owner pair:
 * the edge that starts at the vertex, when that pair passes the arc rule.
 */
#include "tk/struts.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "tk/geometry.h"

#define LEAF_EDGES 4
#define NO_EDGE SIZE_MAX
#define NO_COMP SIZE_MAX
/* Arcs must turn by at least pi; the margin keeps arcs that turn by exactly
 * pi (antipodal edges of a regular polygon) despite rounding in the sums. */
#define ARC_TURN_NEEDED (M_PI * (1.0 - 1e-9))
/* Distances of the same contact seen from two edge pairs agree to rounding. */
#define SAME_CONTACT_REL 1e-12
/* Widenings of the shortest-contact search by 5% before they speed up:
 * 16 reach 2.2 times the plain minimum. */
#define SLOW_WIDENINGS 16

/* An edge as the pair bound sees it (set by refit). */
typedef struct edge_frame {
    double mid[3];  /* midpoint */
    double dir[3];  /* unit direction (0 for an edge of length 0) */
    double half;    /* half its length */
    double round;   /* the rounding of a distance to it: 64 eps of its extent */
} edge_frame;

typedef struct tree_node {
    double lo[3], hi[3];
    size_t first, end;  /* global edge range [first, end) */
    size_t left, right; /* children, 0 for a leaf (the root is node 0) */
    size_t comp;        /* the component when the range lies in one */
    double extent;      /* the largest coordinate magnitude in the box */
} tree_node;

struct tk_strut_finder {
    size_t nedges;
    size_t nvert;
    size_t ncomp;
    size_t *head, *tail;      /* per edge: global vertex indices */
    size_t *comp;             /* per edge */
    size_t *local;            /* per edge: index within its component */
    size_t *prev, *next;      /* per edge: neighbouring edges or NO_EDGE */
    size_t *comp_first_edge;  /* ncomp + 1 */
    bool *comp_closed;
    double *prefix;           /* per component n+1 sums of vertex weights */
    size_t *prefix_offset;    /* ncomp: start of each component's sums */
    tree_node *nodes;
    size_t nnodes;
    edge_frame *frames;       /* per edge, of the curve last fitted */
    /* tk_strut_finder_near: the pairs for checks near a curve */
    size_t *near;             /* pairs of global edges, i < j */
    size_t nnear, near_capacity;
    double *near_of;          /* 3V: the curve */
    double *near_prefix;      /* its arc-rule sums (as prefix) */
    double near_reach;        /* 0: no pairs */
    double near_tau;
    tk_arc_rule near_rule;
};

/* The state of one query. */
typedef struct query {
    tk_strut_finder *f;
    const tk_curve *c;
    tk_arc_rule rule;
    double bound;             /* report contacts of length <= bound */
    bool shortest_mode;       /* bound shrinks to the best contact found */
    bool plain;               /* skip the local-minimum test (a lower bound) */
    tk_strut best;
    tk_strut_list *out;
    int status;
    double arc_slack;         /* the arc rule relaxed by this turn */
    bool near;                /* collect every pair into f->near */
} query;

void tk_strut_list_clear(tk_strut_list *list)
{
    list->count = 0;
}

void tk_strut_list_free(tk_strut_list *list)
{
    free(list->items);
    list->items = NULL;
    list->count = list->capacity = 0;
}

static int list_push(tk_strut_list *list, const tk_strut *s)
{
    if (list->count == list->capacity) {
        size_t cap = list->capacity ? 2 * list->capacity : 64;
        tk_strut *grown = realloc(list->items, cap * sizeof *grown);
        if (!grown)
            return TK_ENOMEM;
        list->items = grown;
        list->capacity = cap;
    }
    list->items[list->count++] = *s;
    return TK_OK;
}

void tk_strut_finder_free(tk_strut_finder **p)
{
    if (!p || !*p)
        return;
    tk_strut_finder *f = *p;
    free(f->head);
    free(f->tail);
    free(f->comp);
    free(f->local);
    free(f->prev);
    free(f->next);
    free(f->comp_first_edge);
    free(f->comp_closed);
    free(f->prefix);
    free(f->prefix_offset);
    free(f->nodes);
    free(f->frames);
    free(f->near);
    free(f->near_of);
    free(f->near_prefix);
    free(f);
    *p = NULL;
}

static size_t build_node(tk_strut_finder *f, size_t first, size_t end)
{
    size_t id = f->nnodes++;
    tree_node *n = &f->nodes[id];
    n->first = first;
    n->end = end;
    n->left = n->right = 0;
    n->comp = f->comp[first] == f->comp[end - 1] ? f->comp[first] : NO_COMP;
    if (end - first <= LEAF_EDGES && n->comp != NO_COMP)
        return id;
    size_t split = first + (end - first) / 2;
    if (n->comp == NO_COMP) {
        /* Split at the component boundary nearest the middle. */
        size_t best = NO_EDGE, best_gap = SIZE_MAX;
        for (size_t c = f->comp[first] + 1; c <= f->comp[end - 1]; c++) {
            size_t b = f->comp_first_edge[c];
            size_t gap = b > split ? b - split : split - b;
            if (b > first && b < end && gap < best_gap) {
                best = b;
                best_gap = gap;
            }
        }
        split = best;
    }
    size_t left = build_node(f, first, split);
    size_t right = build_node(f, split, end);
    f->nodes[id].left = left;
    f->nodes[id].right = right;
    return id;
}

int tk_strut_finder_new(const tk_curve *c, tk_strut_finder **out, tk_error *err)
{
    *out = NULL;
    tk_strut_finder *f = calloc(1, sizeof *f);
    if (!f)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    size_t ne = tk_curve_edge_count(c);
    f->nedges = ne;
    f->nvert = c->nvert;
    f->ncomp = c->ncomp;
    size_t m = ne ? ne : 1;
    f->head = malloc(m * sizeof(size_t));
    f->tail = malloc(m * sizeof(size_t));
    f->comp = malloc(m * sizeof(size_t));
    f->local = malloc(m * sizeof(size_t));
    f->prev = malloc(m * sizeof(size_t));
    f->next = malloc(m * sizeof(size_t));
    f->comp_first_edge = malloc((c->ncomp + 1) * sizeof(size_t));
    f->comp_closed = malloc(c->ncomp * sizeof(bool));
    f->prefix = malloc((c->nvert + c->ncomp) * sizeof(double));
    f->prefix_offset = malloc(c->ncomp * sizeof(size_t));
    f->nodes = malloc(2 * m * sizeof(tree_node));
    f->frames = malloc(m * sizeof(edge_frame));
    if (!f->head || !f->tail || !f->comp || !f->local || !f->prev || !f->next ||
        !f->comp_first_edge || !f->comp_closed || !f->prefix || !f->prefix_offset ||
        !f->nodes || !f->frames) {
        tk_strut_finder_free(&f);
        return tk_error_set(err, TK_ENOMEM, "out of memory for the strut tree (%zu edges)", ne);
    }
    size_t e = 0;
    for (size_t k = 0; k < c->ncomp; k++) {
        size_t n = tk_curve_comp_edges(c, k);
        f->comp_first_edge[k] = e;
        f->comp_closed[k] = c->closed[k];
        f->prefix_offset[k] = c->offset[k] + k;
        for (size_t i = 0; i < n; i++, e++) {
            f->head[e] = tk_curve_vertex_index(c, k, i);
            f->tail[e] = tk_curve_vertex_index(c, k, i + 1);
            f->comp[e] = k;
            f->local[e] = i;
            if (c->closed[k]) {
                f->prev[e] = f->comp_first_edge[k] + (i + n - 1) % n;
                f->next[e] = f->comp_first_edge[k] + (i + 1) % n;
            } else {
                f->prev[e] = i > 0 ? e - 1 : NO_EDGE;
                f->next[e] = i + 1 < n ? e + 1 : NO_EDGE;
            }
        }
    }
    f->comp_first_edge[c->ncomp] = e;
    if (ne > 0)
        build_node(f, 0, ne);
    *out = f;
    tk_strut_finder_refit(f, c);
    return TK_OK;
}

void tk_strut_finder_refit(tk_strut_finder *f, const tk_curve *c)
{
    /* Children are created after their parents, so a reverse sweep sees
     * both children of a node before the node. */
    for (size_t id = f->nnodes; id-- > 0;) {
        tree_node *n = &f->nodes[id];
        if (n->left) {
            const tree_node *l = &f->nodes[n->left], *r = &f->nodes[n->right];
            for (int k = 0; k < 3; k++) {
                n->lo[k] = fmin(l->lo[k], r->lo[k]);
                n->hi[k] = fmax(l->hi[k], r->hi[k]);
            }
            n->extent = l->extent > r->extent ? l->extent : r->extent;
            continue;
        }
        for (int k = 0; k < 3; k++) {
            n->lo[k] = INFINITY;
            n->hi[k] = -INFINITY;
        }
        for (size_t e = n->first; e < n->end; e++) {
            const double *a = c->xyz + 3 * f->head[e], *b = c->xyz + 3 * f->tail[e];
            edge_frame *fr = &f->frames[e];
            for (int k = 0; k < 3; k++) {
                n->lo[k] = fmin(n->lo[k], fmin(a[k], b[k]));
                n->hi[k] = fmax(n->hi[k], fmax(a[k], b[k]));
                fr->mid[k] = 0.5 * (a[k] + b[k]);
                fr->dir[k] = b[k] - a[k];
            }
            double len = sqrt(tk_dot3(fr->dir, fr->dir));
            for (int k = 0; k < 3; k++)
                fr->dir[k] = len > 0.0 ? fr->dir[k] / len : 0.0;
            fr->half = 0.5 * len;
            double far = 0.0;
            for (int k = 0; k < 3; k++)
                far = fmax(far, fabs(fr->mid[k]));
            fr->round = 64.0 * DBL_EPSILON * (far + fr->half);
        }
        n->extent = 0.0;
        for (int k = 0; k < 3; k++)
            n->extent = fmax(n->extent, fmax(fabs(n->lo[k]), fabs(n->hi[k])));
    }
}

/* The arc rule's weight of vertex i of component k: its turn (Fenchel), or
 * the most it can turn with 2 minrad >= tau (equation 3 solved for theta);
 * 0 at the ends of an open component. */
static double vertex_weight(const tk_curve *c, size_t k, size_t i, tk_arc_rule rule, double tau)
{
    size_t n = tk_curve_comp_vertices(c, k), base = c->offset[k];
    if (!c->closed[k] && (i == 0 || i + 1 == n))
        return 0.0;
    const double *prev = c->xyz + 3 * (base + (i + n - 1) % n);
    const double *v = c->xyz + 3 * (base + i);
    const double *next = c->xyz + 3 * (base + (i + 1) % n);
    if (rule == TK_ARC_FENCHEL)
        return tk_vertex_turning(prev, v, next);
    double la = sqrt((v[0] - prev[0]) * (v[0] - prev[0]) + (v[1] - prev[1]) * (v[1] - prev[1]) +
                     (v[2] - prev[2]) * (v[2] - prev[2]));
    double lb = sqrt((next[0] - v[0]) * (next[0] - v[0]) + (next[1] - v[1]) * (next[1] - v[1]) +
                     (next[2] - v[2]) * (next[2] - v[2]));
    return 2.0 * atan(fmin(la, lb) / tau);
}

/* Vertex weights for the arc rule, summed per component: prefix[k] is the
 * sum of the weights of the component's vertices 0 .. k-1. */
static void fill_prefix(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule,
                        double tau)
{
    for (size_t k = 0; k < c->ncomp; k++) {
        size_t n = tk_curve_comp_vertices(c, k);
        double *p = f->prefix + f->prefix_offset[k];
        p[0] = 0.0;
        for (size_t i = 0; i < n; i++)
            p[i + 1] = p[i] + vertex_weight(c, k, i, rule, tau);
    }
}

/* Total weight of the vertices strictly between local edges i < j of a
 * component, walking forwards: vertices i+1 .. j. */
static double forward_turn(const tk_strut_finder *f, size_t comp, size_t i, size_t j)
{
    const double *p = f->prefix + f->prefix_offset[comp];
    return p[j + 1] - p[i + 1];
}

static double comp_total_turn(const tk_strut_finder *f, const tk_curve *c, size_t comp)
{
    return f->prefix[f->prefix_offset[comp] + tk_curve_comp_vertices(c, comp)];
}

static bool edges_adjacent(const tk_strut_finder *f, size_t i, size_t j)
{
    return f->next[i] == j || f->prev[i] == j;
}

/* The arc rule for global edges i != j (prefix must be filled), relaxed
 * by a turn of `slack`. */
static bool pair_allowed_by(const tk_strut_finder *f, const tk_curve *c, size_t i, size_t j,
                            double slack)
{
    if (f->comp[i] != f->comp[j])
        return true;
    if (i == j || edges_adjacent(f, i, j))
        return false;
    size_t comp = f->comp[i];
    size_t a = f->local[i], b = f->local[j];
    if (a > b) {
        size_t t = a;
        a = b;
        b = t;
    }
    double fwd = forward_turn(f, comp, a, b);
    if (fwd < ARC_TURN_NEEDED - slack)
        return false;
    if (!f->comp_closed[comp])
        return true;
    return comp_total_turn(f, c, comp) - fwd >= ARC_TURN_NEEDED - slack;
}

static bool pair_allowed(const tk_strut_finder *f, const tk_curve *c, size_t i, size_t j)
{
    return pair_allowed_by(f, c, i, j, 0.0);
}

/* Whether some pair of edges of the two nodes may pass the arc rule: an
 * upper bound of min(forward, backward) turn over the node pair. */
static bool nodes_may_pass(const tk_strut_finder *f, const tk_curve *c,
                           const tree_node *x, const tree_node *y, double slack)
{
    if (x->comp == NO_COMP || y->comp == NO_COMP || x->comp != y->comp)
        return true;
    size_t comp = x->comp, base = f->comp_first_edge[comp];
    size_t x0 = x->first - base, x1 = x->end - 1 - base;
    size_t y0 = y->first - base, y1 = y->end - 1 - base;
    size_t lo0 = x0 < y0 ? x0 : y0, hi1 = x1 > y1 ? x1 : y1;
    /* Largest forward turn: from the first edge of either node to the last. */
    double max_fwd = lo0 < hi1 ? forward_turn(f, comp, lo0, hi1) : 0.0;
    if (max_fwd < ARC_TURN_NEEDED - slack)
        return false;
    if (!f->comp_closed[comp])
        return true;
    /* Smallest forward turn between the nodes (0 when they overlap). */
    double min_fwd = 0.0;
    if (x1 < y0)
        min_fwd = forward_turn(f, comp, x1, y0);
    else if (y1 < x0)
        min_fwd = forward_turn(f, comp, y1, x0);
    return comp_total_turn(f, c, comp) - min_fwd >= ARC_TURN_NEEDED - slack;
}

static void edge_closest(const tk_strut_finder *f, const tk_curve *c, size_t i,
                         size_t j, tk_closest *out)
{
    tk_segment_closest(c->xyz + 3 * f->head[i], c->xyz + 3 * f->tail[i],
                       c->xyz + 3 * f->head[j], c->xyz + 3 * f->tail[j], out);
}

/* The edges containing a closest point at parameter s of edge e, the edge
 * that starts at the point first (the preferred owner). */
static size_t edges_at(const tk_strut_finder *f, size_t e, double s, size_t out[2])
{
    if (s == 0.0 && f->prev[e] != NO_EDGE) {
        out[0] = e;
        out[1] = f->prev[e];
        return 2;
    }
    if (s == 1.0 && f->next[e] != NO_EDGE) {
        out[0] = f->next[e];
        out[1] = e;
        return 2;
    }
    out[0] = e;
    return 1;
}

/* What edge pair (i, j) is to its closest points `cl`. */
typedef enum contact_role {
    CONTACT_OWNER,       /* a local minimum of the self-distance, reported
                            by this pair */
    CONTACT_DUPLICATE,   /* the same local minimum, reported by another pair */
    CONTACT_NOT_MINIMUM  /* an edge pair through p and q comes closer */
} contact_role;

/* Decides whether edge pair (i, j) reports contact `cl`: it must be a local
 * minimum of the self-distance (no edge pair through p and q comes closer)
 * and (i, j) must be its owner.  See the comment at the top. */
static contact_role contact_role_of(const tk_strut_finder *f, const tk_curve *c, size_t i,
                                    size_t j, const tk_closest *cl)
{
    size_t pe[2], qe[2];
    size_t np = edges_at(f, i, cl->s, pe), nq = edges_at(f, j, cl->t, qe);
    if (np == 1 && nq == 1)
        return CONTACT_OWNER;
    double floor = cl->dist * (1.0 - SAME_CONTACT_REL);
    bool owner_found = false, we_own = false;
    for (size_t a = 0; a < np; a++) {
        for (size_t b = 0; b < nq; b++) {
            size_t x = pe[a], y = qe[b];
            bool ours = (x == i && y == j) || (x == j && y == i);
            if (!ours) {
                if (x == y)
                    return CONTACT_NOT_MINIMUM;
                tk_closest other;
                edge_closest(f, c, x, y, &other);
                if (other.dist < floor)
                    return CONTACT_NOT_MINIMUM;
            }
            if (!owner_found && pair_allowed(f, c, x, y)) {
                owner_found = true;
                we_own = ours;
            }
        }
    }
    return we_own ? CONTACT_OWNER : CONTACT_DUPLICATE;
}

static void strut_from(const tk_strut_finder *f, size_t i, size_t j,
                       const tk_closest *cl, tk_strut *s)
{
    s->comp[0] = f->comp[i];
    s->edge[0] = f->local[i];
    s->comp[1] = f->comp[j];
    s->edge[1] = f->local[j];
    s->s = cl->s;
    s->t = cl->t;
    memcpy(s->p, cl->p, sizeof s->p);
    memcpy(s->q, cl->q, sizeof s->q);
    s->length = cl->dist;
    s->force = 0.0;
}

/* Whether edges i and j are farther apart than sqrt(b2), by a bound
 * cheaper than their closest points.  With u the unit direction of i and
 * w the offset of j's midpoint from i's, a point of j minus a point of i
 * has a component along u of at least |w.u| - |i|/2 - |j.u|/2 and one
 * across u of at least |P w| - |P j|/2 (P the projection across u).  Two
 * strands side by side pair up, leaf by leaf, edges a few apart along
 * them, farther than any bound near the diameter; their boxes cannot
 * tell, the component along u can. */
static bool pair_beyond(const tk_strut_finder *f, size_t i, size_t j, double bound)
{
    const edge_frame *a = &f->frames[i], *b = &f->frames[j];
    double w[3];
    for (int k = 0; k < 3; k++)
        w[k] = b->mid[k] - a->mid[k];
    double ww = tk_dot3(w, w);
    double wu = tk_dot3(w, a->dir), cu = tk_dot3(b->dir, a->dir);
    /* The bound is a difference of terms as large as the edges and their
     * offset, and |P w| a square root of a difference of squares, so its
     * rounding is absolute, not relative to the bound: up to about
     * sqrt(eps) of |w| and the edges (the cancellations), and eps of the
     * coordinates (the midpoints).  A pair is pruned only when it is
     * beyond the bound by more than that; otherwise two nearly touching
     * edges far from the origin would be pruned while their closest
     * points (which tk_segment_closest gets to eps of the coordinates)
     * lie within the bound. */
    double reach = bound + 1e-7 * (sqrt(ww) + a->half + b->half) + a->round + b->round;
    double r2 = reach * reach;
    double along = fmax(fabs(wu) - a->half - b->half * fabs(cu), 0.0);
    if (along * along > r2)
        return true;
    double across = sqrt(fmax(ww - wu * wu, 0.0)) - b->half * sqrt(fmax(1.0 - cu * cu, 0.0));
    across = fmax(across, 0.0);
    return along * along + across * across > r2;
}

/* Tests global edges i < j. */
static void test_pair(query *qy, size_t i, size_t j)
{
    tk_strut_finder *f = qy->f;
    if (!pair_allowed_by(f, qy->c, i, j, qy->arc_slack))
        return;
    tk_closest cl;
    edge_closest(f, qy->c, i, j, &cl);
    if (qy->shortest_mode ? !(cl.dist < qy->bound) : !(cl.dist <= qy->bound))
        return;
    if (qy->near) {
        if (f->nnear == f->near_capacity) {
            size_t cap = f->near_capacity ? 2 * f->near_capacity : 256;
            size_t *grown = realloc(f->near, 2 * cap * sizeof *grown);
            if (!grown) {
                qy->status = TK_ENOMEM;
                return;
            }
            f->near = grown;
            f->near_capacity = cap;
        }
        f->near[2 * f->nnear] = i;
        f->near[2 * f->nnear + 1] = j;
        f->nnear++;
        return;
    }
    if (!qy->plain || qy->out) {
        /* Listing pairs without the local-minimum test still leaves out
         * the pairs that merely repeat a contact another pair reports:
         * their columns in the flow's rigidity matrix would be copies. */
        contact_role role = contact_role_of(f, qy->c, i, j, &cl);
        if (role == CONTACT_DUPLICATE || (!qy->plain && role != CONTACT_OWNER))
            return;
    }
    if (qy->shortest_mode) {
        qy->bound = cl.dist;
        strut_from(f, i, j, &cl, &qy->best);
        return;
    }
    tk_strut s;
    strut_from(f, i, j, &cl, &s);
    if (list_push(qy->out, &s) != TK_OK)
        qy->status = TK_ENOMEM;
}

static double box_gap2(const tree_node *x, const tree_node *y)
{
    double g2 = 0.0;
    for (int k = 0; k < 3; k++) {
        double g = fmax(x->lo[k] - y->hi[k], y->lo[k] - x->hi[k]);
        if (g > 0.0)
            g2 += g * g;
    }
    return g2;
}

static bool node_pair_pruned(const query *qy, const tree_node *x, const tree_node *y)
{
    double g2 = box_gap2(x, y);
    /* The gap is exact to rounding, but an edge pair's distance from
     * tk_segment_closest is exact only to eps of the coordinates, so a
     * pair just beyond the bound may measure within it: pruned only
     * beyond that rounding. */
    double reach = qy->bound + 64.0 * DBL_EPSILON * (x->extent > y->extent ? x->extent : y->extent);
    double b2 = reach * reach;
    if (qy->shortest_mode ? g2 >= b2 : g2 > b2)
        return true;
    return !nodes_may_pass(qy->f, qy->c, x, y, qy->arc_slack);
}

static void visit(query *qy, size_t xi, size_t yi)
{
    if (qy->status != TK_OK)
        return;
    const tree_node *x = &qy->f->nodes[xi], *y = &qy->f->nodes[yi];
    if (node_pair_pruned(qy, x, y))
        return;
    if (!x->left && !y->left) {
        /* (the frames are the fitted curve's, as the boxes) */
        for (size_t i = x->first; i < x->end; i++)
            for (size_t j = (xi == yi ? i + 1 : y->first); j < y->end; j++)
                if (!pair_beyond(qy->f, i, j, qy->bound))
                    test_pair(qy, i < j ? i : j, i < j ? j : i);
        return;
    }
    size_t pairs[3][2];
    size_t np = 0;
    if (xi == yi) {
        pairs[0][0] = x->left, pairs[0][1] = x->left;
        pairs[1][0] = x->left, pairs[1][1] = x->right;
        pairs[2][0] = x->right, pairs[2][1] = x->right;
        np = 3;
    } else if (!y->left || (x->left && x->end - x->first >= y->end - y->first)) {
        pairs[0][0] = x->left, pairs[0][1] = yi;
        pairs[1][0] = x->right, pairs[1][1] = yi;
        np = 2;
    } else {
        pairs[0][0] = xi, pairs[0][1] = y->left;
        pairs[1][0] = xi, pairs[1][1] = y->right;
        np = 2;
    }
    if (qy->shortest_mode) {
        /* Nearest pairs first, so the bound shrinks early. */
        double gap[3];
        for (size_t k = 0; k < np; k++)
            gap[k] = box_gap2(&qy->f->nodes[pairs[k][0]], &qy->f->nodes[pairs[k][1]]);
        for (size_t a = 1; a < np; a++)
            for (size_t b = a; b > 0 && gap[b] < gap[b - 1]; b--) {
                double g = gap[b];
                gap[b] = gap[b - 1];
                gap[b - 1] = g;
                size_t p0 = pairs[b][0], p1 = pairs[b][1];
                pairs[b][0] = pairs[b - 1][0];
                pairs[b][1] = pairs[b - 1][1];
                pairs[b - 1][0] = p0;
                pairs[b - 1][1] = p1;
            }
    }
    for (size_t k = 0; k < np; k++)
        visit(qy, pairs[k][0], pairs[k][1]);
}

/* An edge pair yields at most one strut, so this order is total on a
 * strut list. */
int tk_strut_compare_edges(const void *pa, const void *pb)
{
    const tk_strut *a = pa, *b = pb;
    for (int k = 0; k < 2; k++) {
        if (a->comp[k] != b->comp[k])
            return a->comp[k] < b->comp[k] ? -1 : 1;
        if (a->edge[k] != b->edge[k])
            return a->edge[k] < b->edge[k] ? -1 : 1;
    }
    return 0;
}

static int check_counts(const tk_strut_finder *f, const tk_curve *c, tk_error *err)
{
    if (c->nvert != f->nvert || c->ncomp != f->ncomp || tk_curve_edge_count(c) != f->nedges)
        return tk_error_set(err, TK_EINVAL, "the curve does not match the strut finder");
    return TK_OK;
}

/* Checks a query's arguments and fills the arc rule's sums. */
static int begin_query(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule, double tau,
                       tk_error *err)
{
    int rc = check_counts(f, c, err);
    if (rc)
        return rc;
    if (rule == TK_ARC_ADMISSIBLE && !(tau > 0.0))
        return tk_error_set(err, TK_EINVAL, "the diameter must be positive (got %g)", tau);
    fill_prefix(f, c, rule, tau);
    return TK_OK;
}

static bool find_near(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule, double tau,
                      double bound, bool plain, tk_strut_list *out, int *status);

static int find_pairs(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule, double tau,
                      double bound, bool plain, tk_strut_list *out, tk_error *err)
{
    int rc = begin_query(f, c, rule, tau, err);
    if (rc)
        return rc;
    size_t start = out->count;
    int status = TK_OK;
    if (!find_near(f, c, rule, tau, bound, plain, out, &status)) {
        query qy = {f, c, rule, bound, false, plain, {{0}}, out, TK_OK};
        if (f->nedges > 1 && bound >= 0.0)
            visit(&qy, 0, 0);
        status = qy.status;
    }
    if (status != TK_OK)
        return tk_error_set(err, status, "out of memory listing struts");
    if (out->count > start)
        qsort(out->items + start, out->count - start, sizeof *out->items,
              tk_strut_compare_edges);
    return TK_OK;
}

int tk_strut_finder_find(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule,
                         double tau, double bound, tk_strut_list *out, tk_error *err)
{
    return find_pairs(f, c, rule, tau, bound, false, out, err);
}

int tk_strut_finder_find_pairs(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule,
                               double tau, double bound, tk_strut_list *out, tk_error *err)
{
    return find_pairs(f, c, rule, tau, bound, true, out, err);
}

int tk_strut_finder_shortest(tk_strut_finder *f, const tk_curve *c, double *shortest,
                             tk_strut *where, tk_error *err)
{
    int rc = begin_query(f, c, TK_ARC_FENCHEL, 0.0, err);
    if (rc)
        return rc;
    query qy = {f, c, TK_ARC_FENCHEL, INFINITY, true, false, {{0}}, NULL, TK_OK};
    *shortest = INFINITY;
    if (f->nedges < 2 || tk_strut_finder_shortest_near(f, c, shortest, where))
        return TK_OK;
    /* Branch and bound needs a good bound early: with none, every node pair
     * closer than the first contact found is opened, and on a finely
     * sampled curve that is most of them (pairs near a contact are close
     * but not local minima, so they never tighten the bound).  First the
     * plain minimum over the same pairs, without the local-minimum test:
     * every pair tightens it, so it comes fast, and it is a lower bound of
     * the answer (usually equal to it).  Then search for local minima in a
     * radius just above it, widening until one turns up.  The answer does
     * not depend on the widening (any local minimum below the radius is
     * found, so the smallest found is the smallest there is); only the
     * cost does.  Slowly at first, where the answer nearly always is; then
     * the factor squares each round, so that the rounds stay few (about
     * 20 + log2 log2 of the range) whatever the ratio of the curve's size
     * to its closest approach (a self-intersecting curve has lower = 0).
     * The last round has no bound: it ends the loop even where the
     * diagonal is not finite. */
    qy.plain = true;
    visit(&qy, 0, 0);
    double lower = qy.bound;
    qy.plain = false;
    const tree_node *root = &f->nodes[0];
    double diagonal = 0.0;
    for (int k = 0; k < 3; k++)
        diagonal += (root->hi[k] - root->lo[k]) * (root->hi[k] - root->lo[k]);
    diagonal = sqrt(diagonal);
    double radius = isfinite(lower) ? lower * (1.0 + 1e-9) + 1e-300 : INFINITY;
    double growth = 1.05;
    for (int round = 1;; round++) {
        bool last = !(radius < 2.0 * diagonal) || !isfinite(radius);
        qy.bound = last ? INFINITY : radius;
        visit(&qy, 0, 0);
        if (qy.bound < radius || last)
            break;
        radius *= growth;
        if (round >= SLOW_WIDENINGS)
            growth = growth < 2.0 ? 2.0 : growth * growth;
    }
    *shortest = qy.bound;
    if (where)
        *where = qy.best;
    return TK_OK;
}

int tk_strut_finder_closest_pair(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule,
                                 double tau, double below, double *dist, tk_error *err)
{
    int rc = begin_query(f, c, rule, tau, err);
    if (rc)
        return rc;
    query qy = {f, c, rule, below, true, true, {{0}}, NULL, TK_OK};
    if (f->nedges > 1)
        visit(&qy, 0, 0);
    *dist = qy.bound;
    return TK_OK;
}

/* The arc rule's sums change with the curve (they add up turns bounded
 * by the edge lengths): the pairs are found with the rule relaxed by
 * NEAR_ARC_SLACK, and a curve whose turns between two vertices may differ
 * from c's by more than half of it is checked by the tree instead. */
#define NEAR_ARC_SLACK 0.05

int tk_strut_finder_near(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule, double tau,
                         double reach, tk_error *err)
{
    f->near_reach = 0.0;
    f->nnear = 0;
    int rc = begin_query(f, c, rule, tau, err);
    if (rc)
        return rc;
    size_t nsums = c->nvert + c->ncomp;
    if (!f->near_of)
        f->near_of = malloc(3 * c->nvert * sizeof *f->near_of);
    if (!f->near_prefix)
        f->near_prefix = malloc(nsums * sizeof *f->near_prefix);
    if (!f->near_of || !f->near_prefix)
        return tk_error_set(err, TK_ENOMEM, "out of memory for near pairs");
    /* (the margin is far above the rounding of a distance) */
    double bound = (tau + 2.0 * reach) * (1.0 + 1e-9);
    query qy = {f, c, rule, bound, false, true, {{0}}, NULL, TK_OK, NEAR_ARC_SLACK, true};
    if (f->nedges > 1)
        visit(&qy, 0, 0);
    if (qy.status != TK_OK) {
        f->nnear = 0;
        return tk_error_set(err, qy.status, "out of memory for near pairs");
    }
    memcpy(f->near_of, c->xyz, 3 * c->nvert * sizeof *c->xyz);
    memcpy(f->near_prefix, f->prefix, nsums * sizeof *f->prefix);
    f->near_reach = reach;
    f->near_tau = tau;
    f->near_rule = rule;
    return TK_OK;
}

bool tk_strut_finder_near_covers(const tk_strut_finder *f, const tk_curve *c, const double *motion,
                                 double h, double most, tk_arc_rule rule, double tau)
{
    if (!(f->near_reach > 0.0) || f->near_reach > most || f->near_rule != rule ||
        f->near_tau != tau || c->nvert != f->nvert)
        return false;
    for (size_t v = 0; v < c->nvert; v++) {
        const double *p = c->xyz + 3 * v, *q = f->near_of + 3 * v, *m = motion + 3 * v;
        double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
        if (sqrt(tk_dot3(d, d)) + h * sqrt(tk_dot3(m, m)) > f->near_reach)
            return false;
    }
    return true;
}

/* The farthest a vertex of t is from the near pairs' curve, or INFINITY
 * when they cannot serve t: no pairs, other counts, or its arc rule's
 * turns changed enough to admit a pair they left out.  The arc rule's
 * sums must be t's (fill_prefix). */
static double near_moved(const tk_strut_finder *f, const tk_curve *t)
{
    if (!(f->near_reach > 0.0) || check_counts(f, t, NULL) != TK_OK)
        return INFINITY;
    double moved2 = 0.0;
    for (size_t v = 0; v < t->nvert; v++) {
        const double *p = t->xyz + 3 * v, *q = f->near_of + 3 * v;
        double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
        moved2 = fmax(moved2, tk_dot3(d, d));
    }
    /* a forward turn (and the rest of a closed component's) changed by at
     * most twice the range of the sums' change */
    for (size_t k = 0; k < t->ncomp; k++) {
        const double *now = f->prefix + f->prefix_offset[k];
        const double *then = f->near_prefix + f->prefix_offset[k];
        double lo = 0.0, hi = 0.0;
        for (size_t i = 0; i <= tk_curve_comp_vertices(t, k); i++) {
            lo = fmin(lo, now[i] - then[i]);
            hi = fmax(hi, now[i] - then[i]);
        }
        if (2.0 * (hi - lo) > 0.5 * NEAR_ARC_SLACK)
            return INFINITY;
    }
    return sqrt(moved2);
}

/* Whether the last near pairs hold every pair of t (the finder's rule
 * and tau) closer than `bound`: a distance changes by at most twice the
 * farthest a vertex moved.  The arc rule's sums must be t's. */
static bool near_holds(const tk_strut_finder *f, const tk_curve *t, double bound)
{
    return near_moved(f, t) <= 0.5 * (f->near_tau + 2.0 * f->near_reach - bound);
}

bool tk_strut_finder_closest_near(tk_strut_finder *f, const tk_curve *t, double below,
                                  double *dist)
{
    if (!(below <= f->near_tau) || !(f->near_reach > 0.0) || check_counts(f, t, NULL) != TK_OK)
        return false;
    fill_prefix(f, t, f->near_rule, f->near_tau);
    if (!near_holds(f, t, below))
        return false;
    /* as tk_strut_finder_closest_pair: the least distance below `below`
     * among the pairs the arc rule allows at t */
    double least = below;
    for (size_t k = 0; k < f->nnear; k++) {
        size_t i = f->near[2 * k], j = f->near[2 * k + 1];
        if (!pair_allowed(f, t, i, j))
            continue;
        tk_closest cl;
        edge_closest(f, t, i, j, &cl);
        if (cl.dist < least)
            least = cl.dist;
    }
    *dist = least;
    return true;
}

/* The Fenchel rule's sums of t in place of the admissible rule's (which
 * the prefix holds), and how far t's turns exceed the admissible weights,
 * summed over the vertices: 0 when 2 minrad >= tau everywhere. */
static double fenchel_over_admissible(tk_strut_finder *f, const tk_curve *t)
{
    double excess = 0.0;
    for (size_t k = 0; k < t->ncomp; k++) {
        double *p = f->prefix + f->prefix_offset[k], admissible_before = p[0];
        for (size_t i = 0; i < tk_curve_comp_vertices(t, k); i++) {
            double admissible = p[i + 1] - admissible_before;
            double turn = vertex_weight(t, k, i, TK_ARC_FENCHEL, 0.0);
            admissible_before = p[i + 1];
            excess += fmax(turn - admissible, 0.0);
            p[i + 1] = p[i] + turn;
        }
    }
    return excess;
}

/* Why the admissible near pairs serve the Fenchel rule: a pair the
 * Fenchel rule allows at t turns by at least pi between its edges, so
 * the admissible weights there add up to at least pi minus t's excess;
 * near_moved bounds their change since the list was made by half of
 * NEAR_ARC_SLACK, and an excess of a quarter more leaves the pair within
 * the slack the list was made with.  Its distance at t below `bound` was
 * below tau + 2 reach there. */
bool tk_strut_finder_shortest_near(tk_strut_finder *f, const tk_curve *t, double *shortest,
                                   tk_strut *where)
{
    if (!(f->near_reach > 0.0) || f->near_rule != TK_ARC_ADMISSIBLE ||
        check_counts(f, t, NULL) != TK_OK)
        return false;
    fill_prefix(f, t, TK_ARC_ADMISSIBLE, f->near_tau);
    /* (the margin is far above the rounding of a distance) */
    double bound = (f->near_tau + 2.0 * (f->near_reach - near_moved(f, t))) * (1.0 - 1e-9);
    if (!(bound > 0.0) || !(fenchel_over_admissible(f, t) <= 0.25 * NEAR_ARC_SLACK))
        return false;
    /* as the tree's search in shortest mode, over the near pairs */
    query qy = {f, t, TK_ARC_FENCHEL, bound, true, false, {{0}}, NULL, TK_OK};
    for (size_t k = 0; k < f->nnear; k++)
        test_pair(&qy, f->near[2 * k], f->near[2 * k + 1]);
    if (!(qy.bound < bound))
        return false;
    *shortest = qy.bound;
    if (where)
        *where = qy.best;
    return true;
}

/* find_pairs from the near pairs (the arc rule's sums c's, as
 * begin_query left them), when they hold every pair it needs:
 * each goes through test_pair as the tree's would, and the tree prunes
 * only pairs farther than the bound, so the list is the same.  False
 * (nothing appended) when they do not. */
static bool find_near(tk_strut_finder *f, const tk_curve *c, tk_arc_rule rule, double tau,
                      double bound, bool plain, tk_strut_list *out, int *status)
{
    if (f->near_rule != rule || f->near_tau != tau || !near_holds(f, c, bound))
        return false;
    query qy = {f, c, rule, bound, false, plain, {{0}}, out, TK_OK};
    for (size_t k = 0; k < f->nnear && qy.status == TK_OK; k++)
        test_pair(&qy, f->near[2 * k], f->near[2 * k + 1]);
    *status = qy.status;
    return true;
}

int tk_struts_find_brute(const tk_curve *c, tk_arc_rule rule, double tau, double bound,
                         tk_strut_list *out, tk_error *err)
{
    if (rule == TK_ARC_ADMISSIBLE && !(tau > 0.0))
        return tk_error_set(err, TK_EINVAL, "the diameter must be positive (got %g)", tau);
    tk_strut_finder *f = NULL;
    int rc = tk_strut_finder_new(c, &f, err);
    if (rc)
        return rc;
    fill_prefix(f, c, rule, tau);
    size_t start = out->count;
    query qy = {f, c, rule, bound, false, false, {{0}}, out, TK_OK};
    for (size_t i = 0; i < f->nedges && qy.status == TK_OK; i++)
        for (size_t j = i + 1; j < f->nedges; j++)
            test_pair(&qy, i, j);
    tk_strut_finder_free(&f);
    if (qy.status != TK_OK)
        return tk_error_set(err, qy.status, "out of memory listing struts");
    if (out->count > start)
        qsort(out->items + start, out->count - start, sizeof *out->items,
              tk_strut_compare_edges);
    return TK_OK;
}

double tk_struts_shortest_brute(const tk_curve *c, tk_strut *where)
{
    tk_strut_finder *f = NULL;
    if (tk_strut_finder_new(c, &f, NULL) != TK_OK)
        return NAN;
    fill_prefix(f, c, TK_ARC_FENCHEL, 0.0);
    query qy = {f, c, TK_ARC_FENCHEL, INFINITY, true, false, {{0}}, NULL, TK_OK};
    for (size_t i = 0; i < f->nedges; i++)
        for (size_t j = i + 1; j < f->nedges; j++)
            test_pair(&qy, i, j);
    tk_strut_finder_free(&f);
    if (where)
        *where = qy.best;
    return qy.bound;
}

bool tk_struts_pair_allowed(const tk_curve *c, tk_arc_rule rule, double tau, size_t i,
                            size_t j)
{
    tk_strut_finder *f = NULL;
    if (tk_strut_finder_new(c, &f, NULL) != TK_OK)
        return false;
    fill_prefix(f, c, rule, tau);
    bool ok = pair_allowed(f, c, i, j);
    tk_strut_finder_free(&f);
    return ok;
}

int tk_kinks_find(const tk_curve *c, double bound, tk_kink **out, size_t *count,
                  tk_error *err)
{
    *out = NULL;
    *count = 0;
    size_t cap = 0;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp), base = c->offset[comp];
        size_t first = c->closed[comp] ? 0 : 1;
        size_t last = c->closed[comp] ? n : (n >= 1 ? n - 1 : 0);
        for (size_t k = first; k < last; k++) {
            double r = tk_vertex_minrad(c->xyz + 3 * (base + (k + n - 1) % n),
                                        c->xyz + 3 * (base + k),
                                        c->xyz + 3 * (base + (k + 1) % n));
            if (!(2.0 * r <= bound))
                continue;
            if (*count == cap) {
                cap = cap ? 2 * cap : 16;
                tk_kink *grown = realloc(*out, cap * sizeof *grown);
                if (!grown) {
                    free(*out);
                    *out = NULL;
                    *count = 0;
                    return tk_error_set(err, TK_ENOMEM, "out of memory listing kinks");
                }
                *out = grown;
            }
            (*out)[(*count)++] = (tk_kink){comp, k, r, 0.0};
        }
    }
    return TK_OK;
}

/* The path is cut into pieces none of which moves a vertex by more than
 * PATH_SHARE of the closest distance between two edges that are not
 * neighbours at its start: a point of an edge moves no more than its
 * vertices, so no such distance falls to 0 within the piece.
 * Where two edges pass through each other the pieces shorten
 * geometrically toward the moment they meet, and once their distance is
 * down to the rounding of the vertices' places (1e-16 of them) a piece
 * steps over it: an escape's far deformation of catalogue 10.140's
 * turned start (tests/data/path-through-*.vect) went through edges 31
 * and 102 that way in its 53rd piece, was taken for an isotopy, and the run
 * tightened 8_20 (whose Alexander polynomial 10_140 shares) to 63.14.
 * So a distance below PATH_FLOOR of the mean edge proves nothing: two
 * edges that close count as meeting. */
#define PATH_SHARE 0.45
#define PATH_PIECES 2000
#define PATH_FLOOR 1e-6

int tk_struts_path_embedded(const tk_curve *a, const tk_curve *b, bool *embedded, tk_error *err)
{
    *embedded = false;
    tk_curve *x = NULL;
    tk_strut_finder *f = NULL;
    int rc = tk_curve_copy(a, &x, err);
    if (!rc)
        rc = tk_strut_finder_new(a, &f, err);
    double most = 0.0, shortest = 0.0;
    for (size_t v = 0; !rc && v < a->nvert; v++) {
        const double *p = tk_curve_vertex(a, v), *q = tk_curve_vertex(b, v);
        double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        most = fmax(most, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    if (!rc)
        tk_curve_edge_range(a, &shortest, NULL);
    /* the arc rule with a vanishing diameter: every vertex may turn by all
     * but nothing of pi, so every pair of edges but neighbours is looked at */
    double tiny = 1e-9 * shortest;
    size_t edges = tk_curve_edge_count(a);
    double meeting = edges ? PATH_FLOOR * tk_curve_length(a) / (double)edges : 0.0;
    double s = 0.0;
    for (int piece = 0; !rc && piece < PATH_PIECES; piece++) {
        double dist;
        rc = tk_strut_finder_closest_pair(f, x, TK_ARC_ADMISSIBLE, tiny, INFINITY, &dist, err);
        if (rc || !(dist > meeting))
            break;
        if (!(most > 0.0) || s + PATH_SHARE * dist / most >= 1.0) {
            *embedded = true;
            break;
        }
        s += PATH_SHARE * dist / most;
        for (size_t i = 0; i < 3 * a->nvert; i++)
            x->xyz[i] = a->xyz[i] + s * (b->xyz[i] - a->xyz[i]);
        tk_strut_finder_refit(f, x);
    }
    tk_strut_finder_free(&f);
    tk_curve_free(&x);
    return rc;
}
