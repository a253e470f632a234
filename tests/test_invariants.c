/* Linking numbers against exact values: the Hopf link (1), torus links
 * T(2, 2k) (k), chains (1 between neighbours, 0 otherwise), the Borromean
 * rings (0 for every pair), rings pulled apart (0); and the symmetries
 * that must hold whatever the polygon: symmetric in the two components,
 * the sign flipped by reversing one or by a mirror, unchanged by rotation,
 * scaling, resampling and small perturbations. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/generate.h"
#include "tk/invariants.h"

static long lk_of(const tk_curve *c, size_t a, size_t b)
{
    long lk = 99;
    double gauss = NAN;
    tk_error err;
    ck_assert_msg(tk_linking_number(c, a, b, &lk, &gauss, &err) == TK_OK, "%s", err.message);
    /* exact within rounding: the polygon's integral is an integer */
    ck_assert_msg(fabs(gauss - (double)lk) < 1e-9, "Gauss integral %.15g", gauss);
    return lk;
}

START_TEST(hopf_and_torus_links)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    long hopf = lk_of(c, 0, 1);
    ck_assert_int_eq(labs(hopf), 1);
    ck_assert_int_eq(lk_of(c, 1, 0), hopf);
    tk_curve_free(&c);
    for (int k = 1; k <= 4; k++) {
        ck_assert_int_eq(tk_generate_torus(2, 2 * k, 30 * k, &c, NULL), TK_OK);
        ck_assert_int_eq(c->ncomp, 2);
        ck_assert_int_eq(labs(lk_of(c, 0, 1)), k);
        tk_curve_free(&c);
    }
    /* T(3, 3): three components, each pair linked once */
    ck_assert_int_eq(tk_generate_torus(3, 3, 60, &c, NULL), TK_OK);
    ck_assert_int_eq(c->ncomp, 3);
    for (size_t a = 0; a < 3; a++)
        for (size_t b = a + 1; b < 3; b++)
            ck_assert_int_eq(labs(lk_of(c, a, b)), 1);
    tk_curve_free(&c);
}
END_TEST

START_TEST(chains_and_borromean_rings)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(5, 32, &c, NULL), TK_OK);
    for (size_t a = 0; a < 5; a++)
        for (size_t b = a + 1; b < 5; b++)
            ck_assert_int_eq(labs(lk_of(c, a, b)), b == a + 1 ? 1 : 0);
    tk_curve_free(&c);
    /* linked as a whole, yet no two of them are */
    ck_assert_int_eq(tk_generate_borromean(48, &c, NULL), TK_OK);
    for (size_t a = 0; a < 3; a++)
        for (size_t b = a + 1; b < 3; b++)
            ck_assert_int_eq(lk_of(c, a, b), 0);
    tk_curve_free(&c);
}
END_TEST

/* Reverses the order of the vertices of component comp. */
static void reverse(tk_curve *c, size_t comp)
{
    size_t n = tk_curve_comp_vertices(c, comp);
    double *x = c->xyz + 3 * c->offset[comp];
    for (size_t i = 0, j = n - 1; i < j; i++, j--)
        for (int k = 0; k < 3; k++) {
            double t = x[3 * i + k];
            x[3 * i + k] = x[3 * j + k];
            x[3 * j + k] = t;
        }
}

START_TEST(orientation_mirror_and_motion)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 4, 64, &c, NULL), TK_OK);
    long lk = lk_of(c, 0, 1);
    reverse(c, 1);
    ck_assert_int_eq(lk_of(c, 0, 1), -lk);
    reverse(c, 1);
    /* a mirror image links the other way */
    for (size_t v = 0; v < c->nvert; v++)
        tk_curve_vertex(c, v)[2] *= -1.0;
    ck_assert_int_eq(lk_of(c, 0, 1), -lk);
    for (size_t v = 0; v < c->nvert; v++)
        tk_curve_vertex(c, v)[2] *= -1.0;
    /* rotation, scaling and a perturbation of a tenth of an edge leave it */
    tkt_rng rng = {11};
    for (int round = 0; round < 20; round++) {
        double axis[3];
        tkt_rng_point(&rng, 1.0, axis);
        double len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
        double angle = tkt_rng_range(&rng, 0, 2 * M_PI), s = sin(angle), co = cos(angle);
        double u[3] = {axis[0] / len, axis[1] / len, axis[2] / len};
        double r[9] = {co + u[0] * u[0] * (1 - co),        u[0] * u[1] * (1 - co) - u[2] * s,
                       u[0] * u[2] * (1 - co) + u[1] * s, u[1] * u[0] * (1 - co) + u[2] * s,
                       co + u[1] * u[1] * (1 - co),        u[1] * u[2] * (1 - co) - u[0] * s,
                       u[2] * u[0] * (1 - co) - u[1] * s, u[2] * u[1] * (1 - co) + u[0] * s,
                       co + u[2] * u[2] * (1 - co)};
        tk_curve *m = NULL;
        ck_assert_int_eq(tk_curve_copy(c, &m, NULL), TK_OK);
        tk_curve_rotate(m, r);
        tk_curve_scale(m, tkt_rng_range(&rng, 1e-3, 1e3));
        double shortest, longest;
        tk_curve_edge_range(m, &shortest, &longest);
        for (size_t v = 0; v < m->nvert; v++) {
            double d[3];
            tkt_rng_point(&rng, 0.1 * shortest, d);
            for (int k = 0; k < 3; k++)
                tk_curve_vertex(m, v)[k] += d[k];
        }
        ck_assert_int_eq(lk_of(m, 0, 1), lk);
        tk_curve_free(&m);
    }
    /* resampled to another vertex count */
    tk_curve *fine = NULL;
    ck_assert_int_eq(tk_curve_resample_total(c, 500, &fine, NULL), TK_OK);
    ck_assert_int_eq(lk_of(fine, 0, 1), lk);
    tk_curve_free(&fine);
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_strand_passage_is_caught)
{
    /* The second ring of a Hopf link pulled out through the first: the
     * link falls apart, and the linking number says so. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    ck_assert_int_eq(labs(lk_of(c, 0, 1)), 1);
    for (size_t i = 0; i < tk_curve_comp_vertices(c, 1); i++)
        tk_curve_vertex(c, tk_curve_vertex_index(c, 1, i))[0] += 5.0;
    ck_assert_int_eq(lk_of(c, 0, 1), 0);
    tk_curve_free(&c);
    /* the linking number of a component with itself, or with one that
     * is not there, is refused */
    ck_assert_int_eq(tk_generate_hopf(40, &c, NULL), TK_OK);
    long lk;
    tk_error err;
    ck_assert_int_eq(tk_linking_number(c, 0, 0, &lk, NULL, &err), TK_EINVAL);
    ck_assert_int_eq(tk_linking_number(c, 0, 2, &lk, NULL, &err), TK_EINVAL);
    tk_curve_free(&c);
}
END_TEST

START_TEST(catalogue_links)
{
    if (!tkt_catalogue_dir()) {
        printf("catalogue absent: catalogue linking numbers skipped\n");
        return;
    }
    /* Rolfsen's table: the unlinks, the Hopf link, Solomon's link T(2,4),
     * the Whitehead link, T(2,6), the Borromean rings */
    const struct {
        const char *name;
        long lk; /* |lk| of every pair */
    } known[] = {{"0.2.1.vect", 0}, {"0.3.1.vect", 0}, {"2.2.1.vect", 1}, {"4.2.1.vect", 2},
                 {"5.2.1.vect", 0}, {"6.2.1.vect", 3}, {"6.3.2.vect", 0}};
    for (size_t k = 0; k < sizeof known / sizeof *known; k++) {
        tk_curve *c = tkt_catalogue_curve(known[k].name);
        for (size_t a = 0; a < c->ncomp; a++)
            for (size_t b = a + 1; b < c->ncomp; b++)
                ck_assert_msg(labs(lk_of(c, a, b)) == known[k].lk, "%s %zu %zu", known[k].name, a,
                              b);
        tk_curve_free(&c);
    }
    /* every link of the catalogue: an integer within rounding (lk_of) */
    size_t count = 0;
    char **names = tkt_catalogue_names(&count);
    size_t links = 0;
    for (size_t i = 0; i < count; i++) {
        tk_curve *c = tkt_catalogue_curve(names[i]);
        for (size_t a = 0; a < c->ncomp; a++)
            for (size_t b = a + 1; b < c->ncomp; b++)
                if (c->closed[a] && c->closed[b])
                    lk_of(c, a, b);
        links += c->ncomp > 1;
        tk_curve_free(&c);
    }
    tkt_free_names(names, count);
    ck_assert_uint_ge(links, 100);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("invariants");
    TCase *tc = tcase_create("linking");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, hopf_and_torus_links);
    tcase_add_test(tc, chains_and_borromean_rings);
    tcase_add_test(tc, orientation_mirror_and_motion);
    tcase_add_test(tc, a_strand_passage_is_caught);
    tcase_add_test(tc, catalogue_links);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
