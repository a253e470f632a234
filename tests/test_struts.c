/* Struts: the tree against brute force (catalogue and large resampled
 * curves), the arc rule against its closed form, one strut per contact. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support.h"
#include "tk/generate.h"
#include "tk/geometry.h"
#include "tk/invariants.h"
#include "tk/struts.h"
#include "tk/thickness.h"
#include "tk/vect.h"

static void assert_same_lists(const tk_strut_list *a, const tk_strut_list *b, const char *what)
{
    ck_assert_msg(a->count == b->count, "%s: tree found %zu struts, brute force %zu", what,
                  a->count, b->count);
    for (size_t k = 0; k < a->count; k++) {
        const tk_strut *x = &a->items[k], *y = &b->items[k];
        ck_assert_msg(x->comp[0] == y->comp[0] && x->edge[0] == y->edge[0] &&
                          x->comp[1] == y->comp[1] && x->edge[1] == y->edge[1] &&
                          x->s == y->s && x->t == y->t && x->length == y->length,
                      "%s: strut %zu differs", what, k);
    }
}

/* Compares tree and brute force on one curve for both arc rules, with a
 * bound wide enough that the lists are long. */
static size_t compare_tree_and_brute(const tk_curve *c, const char *what, bool check_shortest)
{
    tk_strut_finder *f = NULL;
    tk_error err;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, &err), TK_OK);
    double shortest;
    ck_assert_int_eq(tk_strut_finder_shortest(f, c, &shortest, NULL, &err), TK_OK);
    if (check_shortest) {
        double brute = tk_struts_shortest_brute(c, NULL);
        ck_assert_msg(shortest == brute, "%s: shortest %.17g, brute force %.17g", what,
                      shortest, brute);
    }
    double tau = fmin(shortest, 2.0 * tk_curve_minrad(c, NULL));
    size_t total = 0;
    for (int rule = 0; rule < 2; rule++) {
        tk_strut_list tree = {0}, brute = {0};
        double bound = 1.25 * tau;
        ck_assert_int_eq(tk_strut_finder_find(f, c, (tk_arc_rule)rule, tau, bound, &tree, &err),
                         TK_OK);
        ck_assert_int_eq(tk_struts_find_brute(c, (tk_arc_rule)rule, tau, bound, &brute, &err),
                         TK_OK);
        assert_same_lists(&tree, &brute, what);
        for (size_t k = 0; k < tree.count; k++)
            ck_assert(tree.items[k].length <= bound);
        total += tree.count;
        tk_strut_list_free(&tree);
        tk_strut_list_free(&brute);
    }
    tk_strut_finder_free(&f);
    return total;
}

START_TEST(tree_matches_brute_force_on_catalogue)
{
    size_t n;
    char **names = tkt_catalogue_names(&n);
    if (!names) {
        tkt_skip("tree_matches_brute_force_on_catalogue", "the catalogue is absent");
        return;
    }
    size_t struts = 0;
    for (size_t i = 0; i < n; i++) {
        tk_curve *c = tkt_catalogue_curve(names[i]);
        struts += compare_tree_and_brute(c, names[i], true);
        tk_curve_free(&c);
    }
    /* the comparison is not vacuous */
    ck_assert_uint_gt(struts, 10 * n);
    tkt_free_names(names, n);
}
END_TEST

static void resampled_case(const char *name, size_t vertices)
{
    tk_curve *c = tkt_catalogue_curve(name), *big = NULL;
    tk_error err;
    ck_assert_int_eq(tk_curve_resample_total(c, vertices, &big, &err), TK_OK);
    char what[64];
    snprintf(what, sizeof what, "%s at %zu vertices", name, vertices);
    ck_assert_uint_gt(compare_tree_and_brute(big, what, true), 0);
    tk_curve_free(&c);
    tk_curve_free(&big);
}

START_TEST(tree_matches_brute_force_at_1000_vertices)
{
    if (!tkt_catalogue_dir() && tkt_skip("tree_matches_brute_force_at_1000_vertices", "the catalogue is absent"))
        return;
    resampled_case("3.1.vect", 1000);
    resampled_case("6.3.2.vect", 1500);
}
END_TEST

START_TEST(tree_matches_brute_force_at_10000_vertices)
{
    if (!tkt_catalogue_dir() && tkt_skip("tree_matches_brute_force_at_10000_vertices", "the catalogue is absent"))
        return;
    resampled_case("8.18.vect", 4000);
    resampled_case("10.1.vect", 10000);
}
END_TEST

START_TEST(tree_matches_brute_force_on_generated)
{
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_torus(3, 5, 1200, &c, &err), TK_OK);
    ck_assert_uint_gt(compare_tree_and_brute(c, "T(3,5)", true), 0);
    tk_curve_free(&c);
    ck_assert_int_eq(tk_generate_chain(4, 300, &c, &err), TK_OK);
    ck_assert_uint_gt(compare_tree_and_brute(c, "chain of 4", true), 0);
    tk_curve_free(&c);
}
END_TEST

/* Two strands side by side, as in a tight knot: a stadium (straight sides
 * 10 long at distance 1, caps of radius 1/2) of 2,000 vertices evenly
 * spaced, moved by up to 1e-4 so that its contacts differ.  Most edge
 * pairs the tree's leaves meet are a few edges apart along the sides and
 * just farther than a bound near 1: the tree's cheap pair bound
 * (struts.c, pair_beyond) must drop those and no other.  Struts and the
 * closest pair against brute force at bounds 1e-6 to 1e-2 above the
 * shortest.  (`noise` scales the displacements: at 1 the polygon turns by
 * up to about 0.03 at each vertex of the sides, beyond the 0.023 that the
 * curvature bound of a tube of diameter 1 allows its edges.) */
static tk_curve *stadium(size_t n, double noise)
{
    size_t counts[1] = {n};
    bool closed[1] = {true};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 1, counts, closed, NULL), TK_OK);
    double side = 10.0, cap = M_PI * 0.5, total = 2.0 * (side + cap);
    for (size_t k = 0; k < n; k++) {
        double s = total * (double)k / (double)n, *p = c->xyz + 3 * k;
        if (s < side) {
            p[0] = s, p[1] = 0.0;
        } else if (s < side + cap) {
            double a = (s - side) / 0.5;
            p[0] = side + 0.5 * sin(a), p[1] = 0.5 - 0.5 * cos(a);
        } else if (s < 2.0 * side + cap) {
            p[0] = side - (s - side - cap), p[1] = 1.0;
        } else {
            double a = (s - 2.0 * side - cap) / 0.5;
            p[0] = -0.5 * sin(a), p[1] = 0.5 + 0.5 * cos(a);
        }
        p[1] += noise * 5e-5 * cos(1.7 * (double)k);
        p[2] = noise * 1e-4 * sin(2.39996 * (double)k);
    }
    return c;
}

START_TEST(tree_matches_brute_force_on_strands_side_by_side)
{
    size_t n = 2000;
    tk_curve *c = stadium(n, 1.0);
    tk_strut_finder *f = NULL;
    tk_error err;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, &err), TK_OK);
    double shortest = tk_struts_shortest_brute(c, NULL);
    double slack[4] = {1e-6, 3e-5, 1e-4, 1e-2};
    size_t last = 0;
    for (int k = 0; k < 4; k++) {
        tk_strut_list tree = {0}, brute = {0};
        double bound = shortest * (1.0 + slack[k]);
        ck_assert_int_eq(tk_strut_finder_find(f, c, TK_ARC_ADMISSIBLE, 1.0, bound, &tree, &err),
                         TK_OK);
        ck_assert_int_eq(tk_struts_find_brute(c, TK_ARC_ADMISSIBLE, 1.0, bound, &brute, &err),
                         TK_OK);
        assert_same_lists(&tree, &brute, "stadium");
        printf("stadium of %zu vertices: %zu struts within %g of the shortest\n", n, tree.count,
               slack[k]);
        ck_assert_uint_ge(tree.count, last > 0 ? last : 1);
        last = tree.count;
        tk_strut_list_free(&tree);
        tk_strut_list_free(&brute);
    }
    double closest = 0.0;
    ck_assert_int_eq(tk_strut_finder_closest_pair(f, c, TK_ARC_ADMISSIBLE, 1.0, 2.0, &closest,
                                                  &err),
                     TK_OK);
    printf("stadium: closest pair %.17g, shortest strut by brute force %.17g\n", closest,
           shortest);
    ck_assert(closest == shortest);
    tk_strut_finder_free(&f);
    tk_curve_free(&c);
}
END_TEST

/* Smooth displacements of every vertex of c by up to `reach` (a few waves
 * along the curve, as a step's motion), into t: trial k of 40. */
static void displace(const tk_curve *c, tk_curve *t, double reach, int trial)
{
    size_t n = c->nvert;
    double phase = 0.7 * trial, waves = 1 + trial % 5, size = reach * (0.2 + 0.02 * trial);
    for (size_t v = 0; v < n; v++) {
        double a = 2.0 * M_PI * waves * (double)v / (double)n;
        double d[3] = {cos(a + phase), sin(2.0 * a - phase), cos(3.0 * a + 2.0 * phase)};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; k++)
            t->xyz[3 * v + k] = c->xyz[3 * v + k] + size * d[k] / fmax(len, 1.0);
    }
}

/* Checks near a curve (tk_strut_finder_near) give the tree's closest
 * pair, struts and pairs near contacts exactly, on the stadium above: its caps are half circles of
 * diameter 1, so pairs across them sit at the arc rule's edge (a turn of
 * pi) at distance about 1, and moving the curve changes which of them the
 * rule allows.  Smooth displacements of every vertex by up to the reach,
 * at bounds below and above the closest pair; a curve farther than the
 * reach, or one whose edges all change length (rough noise), is
 * declined. */
START_TEST(near_checks_equal_the_tree)
{
    size_t n = 2000;
    tk_curve *c = stadium(n, 1.0), *t = NULL;
    tk_error err;
    ck_assert_int_eq(tk_curve_copy(c, &t, &err), TK_OK);
    tk_strut_finder *f = NULL, *plain = NULL;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, &err), TK_OK);
    ck_assert_int_eq(tk_strut_finder_new(c, &plain, &err), TK_OK);
    size_t listed = 0;
    double reach = 2e-3;
    ck_assert_int_eq(tk_strut_finder_near(f, c, TK_ARC_ADMISSIBLE, 1.0, reach, &err), TK_OK);
    int compared = 0, below = 0;
    for (int trial = 0; trial < 40; trial++) {
        displace(c, t, reach, trial);
        tk_strut_finder_refit(f, t);
        tk_strut_finder_refit(plain, t);
        /* the struts and the pairs near contacts, from the near pairs
         * (f) and from the tree alone (plain) */
        for (int pairs = 0; pairs < 2; pairs++) {
            tk_strut_list a = {0}, b = {0};
            int (*find)(tk_strut_finder *, const tk_curve *, tk_arc_rule, double, double,
                        tk_strut_list *, tk_error *) =
                pairs ? tk_strut_finder_find_pairs : tk_strut_finder_find;
            ck_assert_int_eq(find(f, t, TK_ARC_ADMISSIBLE, 1.0, 1.0 + 1e-4, &a, &err), TK_OK);
            ck_assert_int_eq(find(plain, t, TK_ARC_ADMISSIBLE, 1.0, 1.0 + 1e-4, &b, &err), TK_OK);
            assert_same_lists(&a, &b, "near pairs");
            listed += a.count;
            tk_strut_list_free(&a);
            tk_strut_list_free(&b);
        }
        for (int b = 0; b < 2; b++) {
            double limit = b ? 1.0 : 0.995;
            double tree = 0.0, near = -1.0;
            ck_assert_int_eq(tk_strut_finder_closest_pair(f, t, TK_ARC_ADMISSIBLE, 1.0, limit,
                                                          &tree, &err),
                             TK_OK);
            if (!tk_strut_finder_closest_near(f, t, limit, &near))
                continue;
            ck_assert_msg(near == tree, "trial %d: near %.17g, tree %.17g", trial, near, tree);
            compared++;
            below += tree < limit;
        }
    }
    printf("near checks: %d of 80 compared, %d of them below the bound; %zu struts and "
           "pairs listed\n",
           compared, below, listed);
    ck_assert_uint_gt(listed, 1000);
    ck_assert_int_ge(compared, 60);
    ck_assert_int_ge(below, 20);
    /* too far: one vertex beyond the reach */
    memcpy(t->xyz, c->xyz, 3 * n * sizeof *t->xyz);
    t->xyz[3 * 500 + 2] += 1.01 * reach;
    double near = -1.0;
    ck_assert(!tk_strut_finder_closest_near(f, t, 1.0, &near));
    /* rough: every edge a little longer or shorter */
    for (size_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++)
            t->xyz[3 * v + k] = c->xyz[3 * v + k] + 0.5 * reach * ((v + k) % 2 ? 1.0 : -1.0);
    ck_assert(!tk_strut_finder_closest_near(f, t, 1.0, &near));
    ck_assert(near == -1.0);
    tk_strut_finder_free(&f);
    tk_strut_finder_free(&plain);
    tk_curve_free(&t);
    tk_curve_free(&c);
}
END_TEST

/* The shortest doubly critical distance (Definition 1, the Fenchel arc
 * rule) from the near pairs (made with the admissible rule, which allows
 * every pair the Fenchel rule does on a curve that keeps the curvature
 * bound) equals the tree's, on the stadium with a hundredth of its noise,
 * whose vertices keep the bound, moved as in the test above; the noisy
 * stadium, which bends beyond the bound at every vertex, and a curve bent
 * far beyond it at one vertex are declined, as are curves farther than
 * the reach. */
START_TEST(shortest_near_equals_the_tree)
{
    size_t n = 2000;
    double reach = 2e-3;
    tk_curve *c = stadium(n, 0.01), *t = NULL, *noisy = stadium(n, 1.0);
    tk_error err;
    ck_assert_int_eq(tk_curve_copy(c, &t, &err), TK_OK);
    tk_strut_finder *f = NULL, *plain = NULL;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, &err), TK_OK);
    ck_assert_int_eq(tk_strut_finder_new(c, &plain, &err), TK_OK);
    ck_assert_int_eq(tk_strut_finder_near(f, c, TK_ARC_ADMISSIBLE, 1.0, reach, &err), TK_OK);
    int compared = 0;
    double least = INFINITY, most = 0.0;
    for (int trial = 0; trial < 40; trial++) {
        displace(c, t, reach, trial);
        tk_strut_finder_refit(plain, t);
        double tree = 0.0, near = -1.0;
        ck_assert_int_eq(tk_strut_finder_shortest(plain, t, &tree, NULL, &err), TK_OK);
        if (!tk_strut_finder_shortest_near(f, t, &near, NULL))
            continue;
        ck_assert_msg(near == tree, "trial %d: near %.17g, tree %.17g", trial, near, tree);
        least = fmin(least, tree);
        most = fmax(most, tree);
        compared++;
    }
    printf("shortest doubly critical distance near a curve: %d of 40 compared, %.9f to "
           "%.9f\n",
           compared, least, most);
    ck_assert_int_ge(compared, 25);
    double shortest = -1.0;
    /* the same stadium with its full noise, made into the near curve */
    ck_assert_int_eq(tk_strut_finder_near(plain, noisy, TK_ARC_ADMISSIBLE, 1.0, reach, &err),
                     TK_OK);
    ck_assert(!tk_strut_finder_shortest_near(plain, noisy, &shortest, NULL));
    /* a kink: one vertex of a straight side moved across it by half the
     * reach, a turn of about 0.17 where the bound allows 0.023 */
    memcpy(t->xyz, c->xyz, 3 * n * sizeof *t->xyz);
    t->xyz[3 * 300 + 2] += 0.5 * reach;
    ck_assert(!tk_strut_finder_shortest_near(f, t, &shortest, NULL));
    /* too far: one vertex beyond the reach */
    t->xyz[3 * 300 + 2] = c->xyz[3 * 300 + 2];
    t->xyz[3 * 500 + 2] += 1.01 * reach;
    ck_assert(!tk_strut_finder_shortest_near(f, t, &shortest, NULL));
    ck_assert(shortest == -1.0);
    tk_strut_finder_free(&f);
    tk_strut_finder_free(&plain);
    tk_curve_free(&t);
    tk_curve_free(&noisy);
    tk_curve_free(&c);
}
END_TEST

START_TEST(admissible_pairs_of_equilateral_polygon)
{
    /* Theorem 3: on an equilateral polygon with edge l, pairs with fewer
     * than pi / (2 atan(l / tau)) vertices between them (on the shorter
     * arc) are excluded. */
    size_t n = 40;
    tk_curve *c = tkt_regular_polygon(n, 3.0);
    double l = tk_curve_edge_length(c, 0, 0);
    double taus[3] = {0.5, 1.0, 2.0};
    for (int k = 0; k < 3; k++) {
        double need = M_PI / (2.0 * atan(l / taus[k]));
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n; j++) {
                size_t fwd = j - i, bwd = n - fwd; /* vertices strictly between */
                bool expect = (double)(fwd < bwd ? fwd : bwd) >= need && fwd > 1 && bwd > 1;
                ck_assert_msg(tk_struts_pair_allowed(c, TK_ARC_ADMISSIBLE, taus[k], i, j) == expect,
                              "tau %g edges %zu %zu", taus[k], i, j);
            }
    }
    tk_curve_free(&c);
}
END_TEST

static tk_curve *two_open(const double *a, size_t na, const double *b, size_t nb)
{
    size_t counts[2] = {na, nb};
    bool closed[2] = {false, false};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    for (size_t i = 0; i < 3 * na; i++)
        c->xyz[i] = a[i];
    for (size_t i = 0; i < 3 * nb; i++)
        c->xyz[3 * na + i] = b[i];
    return c;
}

START_TEST(contact_at_shared_vertex_is_one_strut)
{
    /* A V whose tip touches a straight line: both edges of the V have
     * their closest point at the tip; one contact, one strut. */
    double v[9] = {-1, 1, 0, 0, 0, 0, 1, 1, 0};
    double line[9] = {-2, -1, 0, 0.5, -1, 0, 2, -1, 0};
    tk_curve *c = two_open(v, 3, line, 3);
    tk_strut_list list = {0};
    tk_strut_finder *f = NULL;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, NULL), TK_OK);
    ck_assert_int_eq(tk_strut_finder_find(f, c, TK_ARC_ADMISSIBLE, 1.0, 1.5, &list, NULL), TK_OK);
    ck_assert_uint_eq(list.count, 1);
    ck_assert_double_eq_tol(list.items[0].length, 1.0, 1e-15);
    /* owned by the edge starting at the tip */
    ck_assert_uint_eq(list.items[0].edge[0], 1);
    ck_assert(list.items[0].s == 0.0);
    tk_strut_list_free(&list);
    tk_strut_finder_free(&f);
    tk_curve_free(&c);
}
END_TEST

START_TEST(vertex_that_is_not_a_local_minimum_is_no_strut)
{
    /* The middle vertex is at distance 1 from the line but its left edge
     * comes closer (its free end is at distance 0.5): only that end is a
     * local minimum of the self-distance. */
    double v[9] = {-1, -0.5, 0, 0, 0, 0, 1, 1, 0};
    double line[6] = {-3, -1, 0, 3, -1, 0};
    tk_curve *c = two_open(v, 3, line, 2);
    tk_strut_list list = {0};
    ck_assert_int_eq(tk_struts_find_brute(c, TK_ARC_FENCHEL, 0.0, 3.0, &list, NULL), TK_OK);
    ck_assert_uint_eq(list.count, 1);
    ck_assert_double_eq_tol(list.items[0].length, 0.5, 1e-15);
    ck_assert(list.items[0].edge[0] == 0 && list.items[0].s == 0.0);
    tk_strut_list_free(&list);
    tk_curve_free(&c);
}
END_TEST

/* Two V's whose tips nearly touch (1e-10 to 3e-14 apart), one V with an
 * edge a million units long.  The pair bound for that edge and the
 * other tip's works with terms as large as the edge, so its rounding is
 * absolute (about sqrt(eps) of the edge), not relative to the bound: it
 * once pruned the touching pair, and the tree found no strut where brute
 * force found the one at the tips (a fuzzed 24-vertex curve, in
 * tests/fuzz/corpus/vect).  Exact answer: a's points lie at or below the
 * tip's height and b's at or above the other's, so the one strut is tip
 * to tip, owned by the edges that start at the tips. */
START_TEST(nearly_touching_tips_far_from_the_origin)
{
    double gaps[3] = {1e-10, 1e-12, 3e-14};
    for (int g = 0; g < 3; g++) {
        double d = gaps[g];
        double o[3] = {2.3444232432646719, -1.3535533905932735, 0.70710678118654746};
        double a[9] = {o[0] - 1.1196783718730827, o[1] + 1.6464466094067262, o[2] - 0.3,
                       o[0], o[1], o[2],
                       o[0] + 0.8660254037844386, o[1] + 1.5, o[2] - 0.7071067811865475};
        double b[9] = {o[0] - 1.3, o[1] - 1.2, o[2] + d + 0.25,
                       o[0], o[1], o[2] + d,
                       o[0] + 1.1e6, o[1] - 1.4e6, o[2] + d + 0.6e6};
        tk_curve *c = two_open(a, 3, b, 3);
        double tip = fabs(c->xyz[3 * 4 + 2] - c->xyz[3 * 1 + 2]);
        tk_strut_finder *f = NULL;
        ck_assert_int_eq(tk_strut_finder_new(c, &f, NULL), TK_OK);
        tk_strut_list tree = {0}, brute = {0};
        for (int rule = 0; rule < 2; rule++) {
            double bound = tip * (1.0 + 1e-3);
            ck_assert_int_eq(tk_strut_finder_find(f, c, (tk_arc_rule)rule, tip, bound, &tree,
                                                  NULL), TK_OK);
            ck_assert_int_eq(tk_struts_find_brute(c, (tk_arc_rule)rule, tip, bound, &brute,
                                                  NULL), TK_OK);
            assert_same_lists(&tree, &brute, "tips");
            ck_assert_uint_eq(tree.count, 1);
            ck_assert(tree.items[0].edge[0] == 1 && tree.items[0].edge[1] == 1);
            ck_assert(tree.items[0].s == 0.0 && tree.items[0].t == 0.0);
            ck_assert(tree.items[0].length == tip);
            double shortest = 0.0;
            ck_assert_int_eq(tk_strut_finder_shortest(f, c, &shortest, NULL, NULL), TK_OK);
            ck_assert(shortest == tip && shortest == tk_struts_shortest_brute(c, NULL));
            tk_strut_list_clear(&tree);
            tk_strut_list_clear(&brute);
        }
        tk_strut_list_free(&tree);
        tk_strut_list_free(&brute);
        tk_strut_finder_free(&f);
        tk_curve_free(&c);
    }
}
END_TEST

START_TEST(refit_follows_moved_vertices)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(3, 100, &c, NULL), TK_OK);
    tk_strut_finder *f = NULL;
    ck_assert_int_eq(tk_strut_finder_new(c, &f, NULL), TK_OK);
    /* move the middle ring: the tree must see it after a refit */
    double shift[3] = {0.3, 0.1, -0.2};
    for (size_t v = c->offset[1]; v < c->offset[2]; v++)
        for (int k = 0; k < 3; k++)
            c->xyz[3 * v + k] += shift[k];
    tk_strut_finder_refit(f, c);
    double tree, brute = tk_struts_shortest_brute(c, NULL);
    ck_assert_int_eq(tk_strut_finder_shortest(f, c, &tree, NULL, NULL), TK_OK);
    ck_assert(tree == brute);
    tk_strut_finder_free(&f);
    tk_curve_free(&c);
}
END_TEST

START_TEST(kinks_of_a_polygon)
{
    /* a square of side 2: minrad = 1 at every corner (tan 45 deg = 1) */
    size_t n = 4;
    bool closed = true;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &closed, NULL), TK_OK);
    double sq[12] = {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0};
    for (int i = 0; i < 12; i++)
        c->xyz[i] = sq[i];
    tk_kink *k = NULL;
    size_t nk = 0;
    ck_assert_int_eq(tk_kinks_find(c, 2.0 + 1e-12, &k, &nk, NULL), TK_OK);
    ck_assert_uint_eq(nk, 4);
    for (size_t i = 0; i < nk; i++)
        ck_assert_double_eq_tol(k[i].minrad, 1.0, 1e-15);
    free(k);
    ck_assert_int_eq(tk_kinks_find(c, 2.0 - 1e-9, &k, &nk, NULL), TK_OK);
    ck_assert_uint_eq(nk, 0);
    free(k);
    tk_curve_free(&c);
}
END_TEST

/* The smallest distance between two edges that are not neighbours, by
 * brute force over every pair. */
static double closest_apart(const tk_curve *c)
{
    size_t ne = tk_curve_edge_count(c);
    double best = INFINITY;
    for (size_t i = 0; i < ne; i++)
        for (size_t j = i + 1; j < ne; j++) {
            tk_edge a = tk_curve_edge(c, i), b = tk_curve_edge(c, j);
            if (a.head == b.head || a.head == b.tail || a.tail == b.head || a.tail == b.tail)
                continue;
            tk_closest cl;
            tk_segment_closest(tk_curve_vertex(c, a.head), tk_curve_vertex(c, a.tail),
                               tk_curve_vertex(c, b.head), tk_curve_vertex(c, b.tail), &cl);
            best = fmin(best, cl.dist);
        }
    return best;
}

/* A straight path between two curves is an isotopy when no two edges
 * meet on it: one ring pulled out of the Borromean rings through another
 * is not (the components and the linking numbers are the same at both
 * ends; only the link's determinant, 16 against 0, tells them apart),
 * nor is a ring moved through another; small smooth deformations
 * of a trefoil that it passes keep every pair of edges apart at every
 * one of 400 points of the path, by brute force. */
START_TEST(a_straight_path_is_an_isotopy_when_no_edges_meet)
{
    tk_curve *a = NULL, *b = NULL;
    bool ok;
    ck_assert_int_eq(tk_generate_borromean(96, &a, NULL), TK_OK);
    ck_assert_int_eq(tk_curve_copy(a, &b, NULL), TK_OK);
    for (size_t v = b->offset[0]; v < b->offset[1]; v++)
        tk_curve_vertex(b, v)[0] += 6.0; /* ring 0 pulled 6 along x */
    tk_invariants ta = TK_INVARIANTS_INIT, tb = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(a, &ta, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(b, &tb, NULL), TK_OK);
    for (size_t x = 0; x < 3; x++) {
        ck_assert_int_eq(ta.knot[x].determinant, tb.knot[x].determinant);
        for (size_t y = 0; y < 3; y++)
            ck_assert_int_eq(ta.linking[3 * x + y], tb.linking[3 * x + y]);
    }
    ck_assert_int_eq(ta.link_determinant, 16);
    ck_assert_int_eq(tb.link_determinant, 0);
    ck_assert_int_eq(tk_invariants_compare(&ta, &tb, NULL), TK_ETYPE);
    tk_invariants_free(&ta);
    tk_invariants_free(&tb);
    ck_assert_int_eq(tk_struts_path_embedded(a, b, &ok, NULL), TK_OK);
    ck_assert(!ok);
    /* a small move is one */
    for (size_t v = b->offset[0]; v < b->offset[1]; v++)
        tk_curve_vertex(b, v)[0] = tk_curve_vertex(a, v)[0] + 0.05;
    ck_assert_int_eq(tk_struts_path_embedded(a, b, &ok, NULL), TK_OK);
    ck_assert(ok);
    tk_curve_free(&a);
    tk_curve_free(&b);
    /* two rings side by side, one moved through the other's strand */
    size_t n[2] = {40, 40};
    bool closed[2] = {true, true};
    ck_assert_int_eq(tk_curve_new(&a, 2, n, closed, NULL), TK_OK);
    for (size_t k = 0; k < 40; k++) {
        double t = 2.0 * M_PI * (double)k / 40.0;
        double *p = tk_curve_vertex(a, k), *q = tk_curve_vertex(a, 40 + k);
        p[0] = cos(t), p[1] = sin(t), p[2] = 0.0;
        q[0] = 3.0 + cos(t), q[1] = 0.0, q[2] = sin(t);
    }
    ck_assert_int_eq(tk_curve_copy(a, &b, NULL), TK_OK);
    for (size_t k = 0; k < 40; k++)
        tk_curve_vertex(b, 40 + k)[0] -= 2.0; /* its centre to (1, 0, 0): linked */
    ck_assert_int_eq(tk_struts_path_embedded(a, b, &ok, NULL), TK_OK);
    ck_assert(!ok);
    tk_curve_free(&a);
    tk_curve_free(&b);
    /* smooth deformations of a trefoil, against brute force along the path */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 60, &c, NULL), TK_OK);
    int passed = 0;
    for (unsigned seed = 1; seed <= 12; seed++) {
        double coef[TK_DEFORM_MODES * 6];
        tkt_rng rng = {seed};
        for (size_t i = 0; i < sizeof coef / sizeof *coef; i++)
            coef[i] = tkt_rng_range(&rng, -1.0, 1.0);
        ck_assert_int_eq(tk_curve_copy(c, &b, NULL), TK_OK);
        tk_generate_fourier(b, c, coef, TK_DEFORM_MODES, 0.3 * (double)seed);
        ck_assert_int_eq(tk_struts_path_embedded(c, b, &ok, NULL), TK_OK);
        if (ok) {
            passed++;
            tk_curve *x = NULL;
            ck_assert_int_eq(tk_curve_copy(c, &x, NULL), TK_OK);
            for (int k = 0; k <= 400; k++) {
                double s = k / 400.0;
                for (size_t i = 0; i < 3 * c->nvert; i++)
                    x->xyz[i] = c->xyz[i] + s * (b->xyz[i] - c->xyz[i]);
                ck_assert_msg(closest_apart(x) > 0.0, "seed %u: edges meet at %g", seed, s);
            }
            tk_curve_free(&x);
        }
        tk_curve_free(&b);
    }
    ck_assert_int_gt(passed, 0);
    tk_curve_free(&c);
}
END_TEST

/* The place of edge e of the straight path from a to b at s into p, q. */
static void edge_on_path(const tk_curve *a, const tk_curve *b, size_t e, double s, double p[3],
                         double q[3])
{
    tk_edge ed = tk_curve_edge(a, e);
    for (int k = 0; k < 3; k++) {
        p[k] = a->xyz[3 * ed.head + k] + s * (b->xyz[3 * ed.head + k] - a->xyz[3 * ed.head + k]);
        q[k] = a->xyz[3 * ed.tail + k] + s * (b->xyz[3 * ed.tail + k] - a->xyz[3 * ed.tail + k]);
    }
}

/* The volume spanned by edges i and j at s: it changes sign where the
 * lines through them meet. */
static double path_volume(const tk_curve *a, const tk_curve *b, size_t i, size_t j, double s)
{
    double p0[3], p1[3], q0[3], q1[3], d1[3], d2[3], n[3], w[3];
    edge_on_path(a, b, i, s, p0, p1);
    edge_on_path(a, b, j, s, q0, q1);
    tk_sub3(p1, p0, d1);
    tk_sub3(q1, q0, d2);
    tk_sub3(q0, p0, w);
    tk_cross3(d1, d2, n);
    return tk_dot3(n, w);
}

/* A path on which two edges pass through each other is no isotopy, even
 * where the pieces close in on the moment they meet down to the rounding
 * of the vertices: an escape's far deformation of a 10_140 (188
 * vertices; tests/data/path-through-a.vect to -b.vect) was taken for one,
 * and its end is 8_20.  The truth by brute force: for every pair of edges
 * that share no vertex, the moments (to 1e-12, by bisection on the sign
 * of the volume they span, over 2,000 pieces of the path) where the lines
 * through them meet, and whether the edges themselves meet there. */
START_TEST(a_path_through_which_two_edges_pass_is_no_isotopy)
{
    tk_curve *a = NULL, *b = NULL;
    tk_error err;
    ck_assert_msg(tk_vect_read_file("tests/data/path-through-a.vect", NULL, &a, &err) == TK_OK,
                  "%s", err.message);
    ck_assert_msg(tk_vect_read_file("tests/data/path-through-b.vect", NULL, &b, &err) == TK_OK,
                  "%s", err.message);
    ck_assert_uint_eq(a->nvert, b->nvert);
    size_t n = tk_curve_edge_count(a), meetings = 0;
    double mean = tk_curve_length(a) / (double)n;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 2; j < n; j++) {
            if (i == 0 && j == n - 1)
                continue; /* neighbours across vertex 0 */
            for (int k = 0; k < 2000; k++) {
                double lo = k / 2000.0, hi = (k + 1) / 2000.0;
                double vlo = path_volume(a, b, i, j, lo), vhi = path_volume(a, b, i, j, hi);
                if ((vlo < 0.0) == (vhi < 0.0))
                    continue;
                while (hi - lo > 1e-12) {
                    double mid = 0.5 * (lo + hi), v = path_volume(a, b, i, j, mid);
                    if ((v < 0.0) == (vlo < 0.0))
                        lo = mid;
                    else
                        hi = mid;
                }
                double p0[3], p1[3], q0[3], q1[3];
                edge_on_path(a, b, i, lo, p0, p1);
                edge_on_path(a, b, j, lo, q0, q1);
                tk_closest cl;
                tk_segment_closest(p0, p1, q0, q1, &cl);
                if (cl.dist < 1e-9 * mean)
                    meetings++;
            }
        }
    ck_assert_uint_gt(meetings, 0);
    bool ok = true;
    ck_assert_int_eq(tk_struts_path_embedded(a, b, &ok, NULL), TK_OK);
    ck_assert_msg(!ok, "%zu meetings of two edges on the way, and the path was taken for an "
                  "isotopy", meetings);
    /* the first part of the path, before the edges meet, is one */
    tk_curve *half = NULL;
    ck_assert_int_eq(tk_curve_copy(a, &half, NULL), TK_OK);
    for (size_t v = 0; v < 3 * a->nvert; v++)
        half->xyz[v] = a->xyz[v] + 0.5 * (b->xyz[v] - a->xyz[v]);
    ck_assert_int_eq(tk_struts_path_embedded(a, half, &ok, NULL), TK_OK);
    ck_assert(ok);
    tk_curve_free(&half);
    tk_curve_free(&a);
    tk_curve_free(&b);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("struts");
    TCase *tc = tcase_create("struts");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, tree_matches_brute_force_on_catalogue);
    tcase_add_test(tc, tree_matches_brute_force_at_1000_vertices);
    tcase_add_test(tc, tree_matches_brute_force_at_10000_vertices);
    tcase_add_test(tc, tree_matches_brute_force_on_generated);
    tcase_add_test(tc, tree_matches_brute_force_on_strands_side_by_side);
    tcase_add_test(tc, near_checks_equal_the_tree);
    tcase_add_test(tc, shortest_near_equals_the_tree);
    tcase_add_test(tc, admissible_pairs_of_equilateral_polygon);
    tcase_add_test(tc, contact_at_shared_vertex_is_one_strut);
    tcase_add_test(tc, vertex_that_is_not_a_local_minimum_is_no_strut);
    tcase_add_test(tc, nearly_touching_tips_far_from_the_origin);
    tcase_add_test(tc, refit_follows_moved_vertices);
    tcase_add_test(tc, kinks_of_a_polygon);
    tcase_add_test(tc, a_straight_path_is_an_isotopy_when_no_edges_meet);
    tcase_add_test(tc, a_path_through_which_two_edges_pass_is_no_isotopy);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
