/* The active set: which struts and kinks hold the motion, the rigidity
 * matrix of a set, and the forces kept from one step for the next (the
 * warm start).  See run.h for the rooms of the flow. */
#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "tk/geometry.h"
#include "tk/rigidity.h"

void tk_constraints_free(tk_constraints *set)
{
    tk_strut_list_free(&set->struts);
    free(set->kinks);
    free(set->kink_edge);
    *set = (tk_constraints){0};
}

/* *dst becomes a copy of src (its old contents freed). */
int tk_constraints_copy(tk_constraints *dst, const tk_constraints *src, tk_error *err)
{
    tk_constraints_free(dst);
    size_t ns = src->struts.count, nk = src->nkinks;
    dst->struts.items = malloc((ns ? ns : 1) * sizeof *dst->struts.items);
    dst->kinks = malloc((nk ? nk : 1) * sizeof *dst->kinks);
    dst->kink_edge = malloc(nk ? nk : 1);
    if (!dst->struts.items || !dst->kinks || !dst->kink_edge) {
        tk_constraints_free(dst);
        return tk_error_set(err, TK_ENOMEM, "out of memory copying an active set");
    }
    if (ns)
        memcpy(dst->struts.items, src->struts.items, ns * sizeof *dst->struts.items);
    if (nk) {
        memcpy(dst->kinks, src->kinks, nk * sizeof *dst->kinks);
        memcpy(dst->kink_edge, src->kink_edge, nk);
    }
    dst->struts.capacity = ns ? ns : 1;
    dst->struts.count = ns;
    dst->nkinks = nk;
    dst->kink_capacity = nk ? nk : 1;
    return TK_OK;
}

int tk_active_restore(tk_run *r, const tk_constraints *set, tk_error *err)
{
    return tk_constraints_copy(&r->active.set, set, err);
}

void tk_active_free(tk_run *r)
{
    tk_constraints_free(&r->active.set);
    free(r->active.report);
    tk_strut_list_free(&r->active.known_struts);
    free(r->active.known_kinks);
}

void tk_active_reset(tk_run *r)
{
    tk_strut_list_clear(&r->active.known_struts);
    r->active.nknown_kinks = 0;
    tk_strut_list_clear(&r->active.set.struts);
    r->active.set.nkinks = 0;
}

/* The radius function of one edge at global vertex v of c (equation 3
 * is the smaller of the two). */
double tk_branch_radius(const tk_curve *c, size_t v, int edge)
{
    size_t prev, next;
    double g[9];
    if (!tk_curve_vertex_neighbours(c, v, &prev, &next))
        return INFINITY;
    return tk_vertex_radius_gradient(tk_curve_vertex(c, prev), tk_curve_vertex(c, v),
                                     tk_curve_vertex(c, next), edge, g);
}

static int push_kink(tk_constraints *set, size_t comp, size_t vertex, int edge, double radius,
                     tk_error *err)
{
    if (set->nkinks == set->kink_capacity) {
        size_t cap = set->kink_capacity ? 2 * set->kink_capacity : 16;
        tk_kink *grown = realloc(set->kinks, cap * sizeof *grown);
        if (grown)
            set->kinks = grown;
        unsigned char *edges = realloc(set->kink_edge, cap * sizeof *edges);
        if (edges)
            set->kink_edge = edges;
        if (!grown || !edges)
            return tk_error_set(err, TK_ENOMEM, "out of memory for kinks");
        set->kink_capacity = cap;
    }
    set->kinks[set->nkinks] = (tk_kink){comp, vertex, radius, 0.0};
    set->kink_edge[set->nkinks] = (unsigned char)edge;
    set->nkinks++;
    return TK_OK;
}

static bool has_kink(const tk_constraints *set, size_t comp, size_t vertex, int edge)
{
    for (size_t i = 0; i < set->nkinks; i++)
        if (set->kinks[i].comp == comp && set->kinks[i].vertex == vertex &&
            set->kink_edge[i] == edge)
            return true;
    return false;
}

static bool has_strut(const tk_strut_list *list, const tk_strut *s)
{
    for (size_t j = 0; j < list->count; j++) {
        const tk_strut *o = &list->items[j];
        if (o->comp[0] == s->comp[0] && o->edge[0] == s->edge[0] && o->comp[1] == s->comp[1] &&
            o->edge[1] == s->edge[1])
            return true;
    }
    return false;
}

/* Struts are every admissible edge pair within the active tolerance, not
 * only the doubly critical ones (tk_strut_finder_find_pairs).  Equation
 * (4) asks d(e_i, e_j) >= tau of every admissible pair; where a contact
 * lies on nearly parallel edges the pair next to it, whose closest point
 * is the vertex towards the contact, is about as close, and a motion that
 * keeps the contact's own pair to first order can bring that one closer
 * at first order: the contact slides onto it (section 2.3's parallel
 * case, which the paper left out as rare; in tight knots it is common).
 * Without it the step control held such runs to steps of 1e-4.
 * At a kink each edge's radius function within the active tolerance is a
 * constraint of its own.  Holding only the smaller one (equation 3's min)
 * is not enough: the equalising motion keeps the two edges equally long,
 * the resolved motion then keeps the one function to first order while
 * the other falls at first order, and the step control must shrink the
 * step in proportion to the tolerance.  Kinks have a tolerance of their
 * own (tk_tolerance_kink): their functions are stiffer. */
int tk_active_find(tk_run *r, const tk_curve *c, tk_constraints *set, tk_error *err)
{
    double t0 = tk_clock();
    tk_strut_list_clear(&set->struts);
    set->nkinks = 0;
    double slack = 1.0 + tk_tolerance_active(r);
    int rc = tk_strut_finder_find_pairs(r->shared.finder, c, TK_ARC_ADMISSIBLE, r->tau,
                                        r->tau * slack, &set->struts, err);
    tk_kink *found = NULL;
    size_t nfound = 0;
    double bent = 1.0 + tk_tolerance_kink(r);
    if (!rc)
        rc = tk_kinks_find(c, 2.0 * r->min_radius * bent, &found, &nfound, err);
    for (size_t k = 0; !rc && k < nfound; k++) {
        size_t v = tk_curve_vertex_index(c, found[k].comp, found[k].vertex);
        for (int edge = 0; edge < 2 && !rc; edge++) {
            double radius = tk_branch_radius(c, v, edge);
            if (radius <= r->min_radius * bent)
                rc = push_kink(set, found[k].comp, found[k].vertex, edge, radius, err);
        }
    }
    free(found);
    r->active.search_seconds += tk_clock() - t0;
    return rc;
}

/* The contacts that become active mid-step (section 4.5): found again with
 * the tree at the trial point, and added with their values at the current
 * curve so the next resolution keeps them to first order. */
int tk_active_expand(tk_run *r, const tk_curve *trial, size_t most, size_t *added,
                     tk_error *err)
{
    const tk_curve *c = r->shared.curve;
    tk_constraints *set = &r->active.set;
    double t0 = tk_clock();
    *added = 0;
    double floor = 1.0 - tk_tolerance_overstep(r);
    tk_strut_list broken = {0};
    int rc = tk_strut_finder_find(r->shared.finder, trial, TK_ARC_ADMISSIBLE, r->tau,
                                  r->tau * floor, &broken, err);
    /* the pairs not in the set, kept at the front (the finder's pairs are
     * distinct, so none of them is checked against another) */
    size_t fresh = 0;
    for (size_t j = 0; !rc && j < broken.count; j++)
        if (!has_strut(&set->struts, &broken.items[j]))
            broken.items[fresh++] = broken.items[j];
    if (fresh > most) {
        tk_strut_list_free(&broken);
        r->active.search_seconds += tk_clock() - t0;
        return rc;
    }
    for (size_t j = 0; !rc && j < fresh; j++) {
        tk_strut s = broken.items[j];
        tk_closest cl;
        tk_segment_closest(tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[0], s.edge[0])),
                           tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[0], s.edge[0] + 1)),
                           tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[1], s.edge[1])),
                           tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[1], s.edge[1] + 1)),
                           &cl);
        s.s = cl.s;
        s.t = cl.t;
        memcpy(s.p, cl.p, sizeof s.p);
        memcpy(s.q, cl.q, sizeof s.q);
        s.length = cl.dist;
        s.force = 0.0;
        if (set->struts.count == set->struts.capacity) {
            size_t cap = set->struts.capacity ? 2 * set->struts.capacity : 64;
            tk_strut *grown = realloc(set->struts.items, cap * sizeof *grown);
            if (!grown) {
                rc = tk_error_set(err, TK_ENOMEM, "out of memory for struts");
                break;
            }
            set->struts.items = grown;
            set->struts.capacity = cap;
        }
        set->struts.items[set->struts.count++] = s;
        (*added)++;
    }
    tk_strut_list_free(&broken);
    tk_kink *bent = NULL;
    size_t nbent = 0;
    if (!rc)
        rc = tk_kinks_find(trial, 2.0 * r->min_radius * floor, &bent, &nbent, err);
    for (size_t k = 0; !rc && k < nbent; k++) {
        size_t v = tk_curve_vertex_index(c, bent[k].comp, bent[k].vertex);
        for (int edge = 0; edge < 2 && !rc; edge++) {
            if (tk_branch_radius(trial, v, edge) > r->min_radius * floor ||
                has_kink(set, bent[k].comp, bent[k].vertex, edge))
                continue;
            rc = push_kink(set, bent[k].comp, bent[k].vertex, edge, tk_branch_radius(c, v, edge),
                           err);
            if (!rc)
                (*added)++;
        }
    }
    free(bent);
    r->active.search_seconds += tk_clock() - t0;
    return rc;
}

/* The rows of pinned vertices are projected onto the directions their
 * constraints allow (zeroed for a point): the other directions are not
 * variables.  Projecting the columns and the gradient (motion.c) solves
 * min |P (A x + u)|, the problem with the constraints' own multipliers
 * eliminated. */
int tk_active_matrix(tk_run *r, const tk_curve *c, const tk_constraints *set,
                     cholmod_sparse **a, tk_error *err)
{
    double t0 = tk_clock();
    int rc = tk_rigidity_build_branches(c, set->struts.items, set->struts.count, set->kinks,
                                        set->kink_edge, set->nkinks,
                                        tk_nnls_common(r->shared.nnls), a, err);
    if (!rc) {
        /* a column's rows come sorted, three for each of its vertices
         * (tk_rigidity_build_branches) */
        const int *colp = (*a)->p, *row = (*a)->i;
        double *val = (*a)->x;
        for (int k = 0; k + 2 < colp[(*a)->ncol]; k++) {
            const tk_pin *pin = r->shared.pin[row[k] / 3];
            if (!pin)
                continue;
            assert(row[k] % 3 == 0 && row[k + 2] == row[k] + 2);
            tk_pin_project(pin, val + k);
            k += 2;
        }
    }
    r->work.columns += (double)(set->struts.count + set->nkinks);
    r->active.matrix_seconds += tk_clock() - t0;
    return rc;
}

static int compare_known_kinks(const void *pa, const void *pb)
{
    const tk_known_kink *a = pa, *b = pb;
    if (a->comp != b->comp)
        return a->comp < b->comp ? -1 : 1;
    if (a->vertex != b->vertex)
        return a->vertex < b->vertex ? -1 : 1;
    return a->edge < b->edge ? -1 : (a->edge > b->edge ? 1 : 0);
}

/* Contacts change little from one step to the next, so the passive set of
 * the NNLS does too. */
void tk_active_guess_forces(const tk_run *r, double *x)
{
    const tk_constraints *set = &r->active.set;
    const tk_strut_list *known = &r->active.known_struts;
    size_t ns = set->struts.count;
    for (size_t j = 0; j < ns; j++) {
        const tk_strut *hit = known->count ? bsearch(&set->struts.items[j], known->items,
                                                     known->count, sizeof *hit,
                                                     tk_strut_compare_edges)
                                           : NULL;
        x[j] = hit ? hit->force : 0.0;
    }
    for (size_t k = 0; k < set->nkinks; k++) {
        tk_known_kink key = {set->kinks[k].comp, set->kinks[k].vertex, set->kink_edge[k], 0.0};
        const tk_known_kink *hit =
            r->active.nknown_kinks ? bsearch(&key, r->active.known_kinks,
                                             r->active.nknown_kinks, sizeof *hit,
                                             compare_known_kinks)
                                   : NULL;
        x[ns + k] = hit ? hit->force : 0.0;
    }
}

int tk_active_set_forces(tk_run *r, const double *x, tk_error *err)
{
    tk_constraints *set = &r->active.set;
    size_t ns = set->struts.count;
    for (size_t j = 0; j < ns; j++)
        set->struts.items[j].force = x[j];
    for (size_t k = 0; k < set->nkinks; k++)
        set->kinks[k].force = x[ns + k];
    tk_strut_list *known = &r->active.known_struts;
    tk_strut_list_clear(known);
    if (known->capacity < ns) {
        tk_strut *grown = realloc(known->items, ns * sizeof *grown);
        if (!grown)
            return tk_error_set(err, TK_ENOMEM, "out of memory for struts");
        known->items = grown;
        known->capacity = ns;
    }
    known->count = ns;
    if (ns) {
        memcpy(known->items, set->struts.items, ns * sizeof *known->items);
        qsort(known->items, ns, sizeof *known->items, tk_strut_compare_edges);
    }
    free(r->active.known_kinks);
    r->active.known_kinks = NULL;
    r->active.nknown_kinks = 0;
    if (set->nkinks) {
        tk_known_kink *kk = malloc(set->nkinks * sizeof *kk);
        if (!kk)
            return tk_error_set(err, TK_ENOMEM, "out of memory for kinks");
        for (size_t k = 0; k < set->nkinks; k++)
            kk[k] = (tk_known_kink){set->kinks[k].comp, set->kinks[k].vertex, set->kink_edge[k],
                                    set->kinks[k].force};
        qsort(kk, set->nkinks, sizeof *kk, compare_known_kinks);
        r->active.known_kinks = kk;
        r->active.nknown_kinks = set->nkinks;
    }
    return TK_OK;
}

static int compare_kink_vertices(const void *pa, const void *pb)
{
    const tk_kink *a = pa, *b = pb;
    if (a->comp != b->comp)
        return a->comp < b->comp ? -1 : 1;
    return a->vertex < b->vertex ? -1 : (a->vertex > b->vertex ? 1 : 0);
}

/* One per vertex at the curvature bound, with its radius (equation 3)
 * and the sum of its constraints' forces: the kinks that hold the motion
 * or are within the struts' active tolerance (on fine polygons the
 * kinks' own is wider, tk_tolerance_kink, and holds vertices up to 1%
 * from the bound). */
int tk_active_report(tk_run *r, tk_error *err)
{
    const tk_constraints *set = &r->active.set;
    free(r->active.report);
    r->active.report = NULL;
    r->active.nreport = 0;
    if (!set->nkinks)
        return TK_OK;
    tk_kink *out = malloc(set->nkinks * sizeof *out);
    if (!out)
        return tk_error_set(err, TK_ENOMEM, "out of memory for kinks");
    memcpy(out, set->kinks, set->nkinks * sizeof *out);
    qsort(out, set->nkinks, sizeof *out, compare_kink_vertices);
    size_t n = 0;
    const tk_curve *c = r->shared.curve;
    double near = r->min_radius * (1.0 + tk_tolerance_active(r));
    for (size_t k = 0; k < set->nkinks; k++) {
        if (n > 0 && compare_kink_vertices(&out[n - 1], &out[k]) == 0) {
            out[n - 1].force += out[k].force;
            continue;
        }
        out[n] = out[k];
        size_t v = tk_curve_vertex_index(c, out[n].comp, out[n].vertex);
        out[n].minrad = fmin(tk_branch_radius(c, v, 0), tk_branch_radius(c, v, 1));
        /* (a vertex's other edge, next in order, is then looked at alone) */
        if (out[n].force > 0.0 || out[n].minrad <= near)
            n++;
    }
    r->active.report = out;
    r->active.nreport = n;
    return TK_OK;
}
