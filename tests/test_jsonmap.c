/* Tests for the JSON forms of results (server/jsonmap.c): a strut's
 * arclength coordinates, walked along the polygon, land on its points;
 * components are laid end to end; numbers keep every bit; non-finite
 * numbers become null; the invariants of the trefoil, the figure-eight
 * and the Hopf link read back as their known polynomials, determinants
 * and linking numbers, an unknown component as nulls. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/generate.h"
#include "jsonmap.h"
#include "tk/thickness.h"

/* The point at arclength a along the curve's components laid end to end,
 * by walking the edges one by one. */
static void point_at(const tk_curve *c, double a, double out[3])
{
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t ne = tk_curve_comp_edges(c, comp);
        for (size_t k = 0; k < ne; k++) {
            tk_edge e = tk_curve_edge(c, tk_curve_comp_first_edge(c, comp) + k);
            const double *ea = tk_curve_vertex(c, e.head), *eb = tk_curve_vertex(c, e.tail);
            double len = 0.0;
            for (int d = 0; d < 3; d++)
                len += (eb[d] - ea[d]) * (eb[d] - ea[d]);
            len = sqrt(len);
            if (a <= len || (comp + 1 == c->ncomp && k + 1 == ne)) {
                double t = len > 0.0 ? a / len : 0.0;
                for (int d = 0; d < 3; d++)
                    out[d] = ea[d] + t * (eb[d] - ea[d]);
                return;
            }
            a -= len;
        }
    }
}

static void check_contacts(const char *file)
{
    if (!tkt_catalogue_dir())
        return;
    tk_curve *c = tkt_catalogue_curve(file);
    tk_measure m;
    tk_strut_list struts = {NULL, 0, 0};
    tk_kink *kinks = NULL;
    size_t nk = 0;
    tk_error err;
    ck_assert_int_eq(tk_thickness_contacts(c, 1e-3, &m, &struts, &kinks, &nk, &err), TK_OK);
    ck_assert_uint_gt(struts.count, 0);
    json_t *doc = tk_json_contacts(c, struts.items, struts.count, kinks, nk, true, NULL);
    ck_assert_ptr_nonnull(doc);
    json_t *comps = json_object_get(doc, "components");
    ck_assert_uint_eq(json_array_size(comps), c->ncomp);
    double start = 0.0;
    for (size_t k = 0; k < c->ncomp; k++) {
        json_t *o = json_array_get(comps, k);
        ck_assert(fabs(json_real_value(json_object_get(o, "start")) - start) < 1e-12 * (1 + start));
        start += tk_curve_comp_length(c, k);
    }
    json_t *list = json_object_get(doc, "struts");
    ck_assert_uint_eq(json_array_size(list), struts.count);
    for (size_t i = 0; i < struts.count; i++) {
        json_t *j = json_array_get(list, i);
        json_t *along = json_object_get(j, "arclength");
        double p[3], q[3];
        point_at(c, json_real_value(json_array_get(along, 0)), p);
        point_at(c, json_real_value(json_array_get(along, 1)), q);
        for (int d = 0; d < 3; d++) {
            ck_assert_msg(fabs(p[d] - struts.items[i].p[d]) < 1e-9, "%s strut %zu p", file, i);
            ck_assert_msg(fabs(q[d] - struts.items[i].q[d]) < 1e-9, "%s strut %zu q", file, i);
        }
        ck_assert(json_real_value(json_object_get(j, "length")) == struts.items[i].length);
        json_t *edges = json_object_get(j, "edges");
        ck_assert_int_eq(json_integer_value(json_array_get(json_array_get(edges, 1), 1)),
                         (json_int_t)struts.items[i].edge[1]);
    }
    json_decref(doc);
    tk_strut_list_free(&struts);
    free(kinks);
    tk_curve_free(&c);
}

START_TEST(strut_arclengths_land_on_their_points)
{
    check_contacts("3.1.vect");
    check_contacts("2.2.1.vect");
    check_contacts("6.3.2.vect");
}
END_TEST

START_TEST(kinks_sit_at_their_vertices)
{
    tk_curve *c = tkt_regular_polygon(12, 1.0);
    tk_kink kinks[2] = {{0, 0, 0.5, 1.5}, {0, 5, 0.5, 0.0}};
    json_t *doc = tk_json_contacts(c, NULL, 0, kinks, 2, false, NULL);
    json_t *list = json_object_get(doc, "kinks");
    double edge = 2.0 * sin(M_PI / 12.0);
    ck_assert(fabs(json_real_value(json_object_get(json_array_get(list, 0), "arclength"))) < 1e-15);
    ck_assert(fabs(json_real_value(json_object_get(json_array_get(list, 1), "arclength")) -
                   5 * edge) < 1e-12);
    ck_assert_ptr_null(json_object_get(json_array_get(list, 0), "force"));
    json_decref(doc);
    tk_curve_free(&c);
}
END_TEST

START_TEST(numbers_keep_every_bit_and_infinities_are_null)
{
    double x = 0.1 + 0.2, tiny = 4.9406564584124654e-324;
    json_t *a = json_pack("[o, o, o, o]", tk_json_number(x), tk_json_number(tiny),
                          tk_json_number(INFINITY), tk_json_number(NAN));
    char *text = tk_json_dump(a, false);
    json_t *back = json_loads(text, 0, NULL);
    ck_assert(json_real_value(json_array_get(back, 0)) == x);
    ck_assert(json_real_value(json_array_get(back, 1)) == tiny);
    ck_assert(json_is_null(json_array_get(back, 2)) && json_is_null(json_array_get(back, 3)));
    free(text);
    json_decref(a);
    json_decref(back);
    json_t *s = tk_json_text("caf\xe9");
    ck_assert_str_eq(json_string_value(s), "caf?");
    json_decref(s);
}
END_TEST

/* The invariants of a generated curve as JSON text, parsed back: what a
 * client sees. */
static json_t *invariants_read_back(tk_curve *c)
{
    tk_invariants inv = TK_INVARIANTS_INIT;
    tk_error err;
    ck_assert_int_eq(tk_invariants_compute(c, &inv, &err), TK_OK);
    json_t *doc = tk_json_invariants(&inv);
    char *text = tk_json_dump(doc, false);
    ck_assert_ptr_nonnull(text);
    json_t *back = json_loads(text, 0, NULL);
    ck_assert_ptr_nonnull(back);
    free(text);
    json_decref(doc);
    tk_invariants_free(&inv);
    tk_curve_free(&c);
    return back;
}

static void assert_integers(const json_t *a, const long long *want, size_t n)
{
    ck_assert_msg(json_is_array(a) && json_array_size(a) == n, "an array of %zu", n);
    for (size_t i = 0; i < n; i++) {
        ck_assert(json_is_integer(json_array_get(a, i)));
        ck_assert_int_eq(json_integer_value(json_array_get(a, i)), want[i]);
    }
}

START_TEST(invariants_of_known_knots_and_links)
{
    tk_error err;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, &err), TK_OK);
    json_t *j = invariants_read_back(c);
    static const long long trefoil[] = {1, -1, 1}, three[] = {3}, zero[] = {0};
    ck_assert_uint_eq(json_array_size(json_object_get(j, "alexander")), 1);
    assert_integers(json_array_get(json_object_get(j, "alexander"), 0), trefoil, 3);
    ck_assert_str_eq(json_string_value(json_array_get(json_object_get(j, "alexander_text"), 0)),
                     "1 - t + t^2");
    assert_integers(json_object_get(j, "determinants"), three, 1);
    ck_assert_uint_eq(json_array_size(json_object_get(j, "linking")), 1);
    assert_integers(json_array_get(json_object_get(j, "linking"), 0), zero, 1);
    ck_assert(json_is_true(json_object_get(j, "complete")));
    json_decref(j);

    tk_curve *plain = NULL;
    ck_assert_int_eq(tk_generate_figure_eight(0, &plain, &err), TK_OK);
    ck_assert_int_eq(tk_generate_disguise(plain, 3, 0.05, &c, &err), TK_OK);
    tk_curve_free(&plain);
    j = invariants_read_back(c);
    static const long long fig8[] = {-1, 3, -1}, five[] = {5};
    assert_integers(json_array_get(json_object_get(j, "alexander"), 0), fig8, 3);
    ck_assert_str_eq(json_string_value(json_array_get(json_object_get(j, "alexander_text"), 0)),
                     "-1 + 3t - t^2");
    assert_integers(json_object_get(j, "determinants"), five, 1);
    json_decref(j);

    ck_assert_int_eq(tk_generate_hopf(0, &c, &err), TK_OK);
    j = invariants_read_back(c);
    static const long long unknot[] = {1}, ones[] = {1, 1};
    json_t *lk = json_object_get(j, "linking");
    ck_assert_uint_eq(json_array_size(lk), 2);
    long long off = json_integer_value(json_array_get(json_array_get(lk, 0), 1));
    ck_assert(off == 1 || off == -1);
    const long long row0[] = {0, off}, row1[] = {off, 0};
    assert_integers(json_array_get(lk, 0), row0, 2);
    assert_integers(json_array_get(lk, 1), row1, 2);
    for (size_t k = 0; k < 2; k++) {
        assert_integers(json_array_get(json_object_get(j, "alexander"), k), unknot, 1);
        ck_assert_str_eq(json_string_value(json_array_get(json_object_get(j, "alexander_text"), k)),
                         "1");
    }
    assert_integers(json_object_get(j, "determinants"), ones, 2);
    json_decref(j);
}
END_TEST

START_TEST(unknown_components_are_null)
{
    /* a record as the engine leaves it for an open component next to a
     * trefoil: the open one unknown, the record incomplete */
    tk_knot_type knots[2] = {{false, 0, {0}, 0}, {true, 2, {1, -1, 1}, 3}};
    long linking[4] = {0, 0, 0, 0};
    tk_invariants inv = {2, knots, linking, false};
    json_t *j = tk_json_invariants(&inv);
    ck_assert(json_is_null(json_array_get(json_object_get(j, "alexander"), 0)));
    ck_assert(json_is_null(json_array_get(json_object_get(j, "alexander_text"), 0)));
    ck_assert(json_is_null(json_array_get(json_object_get(j, "determinants"), 0)));
    ck_assert_int_eq(json_integer_value(json_array_get(json_object_get(j, "determinants"), 1)), 3);
    ck_assert(json_is_false(json_object_get(j, "complete")));
    ck_assert_uint_eq(json_array_size(json_array_get(json_object_get(j, "linking"), 1)), 2);
    json_decref(j);
    /* nothing computed: null, not an empty record */
    tk_invariants none = TK_INVARIANTS_INIT;
    j = tk_json_invariants(&none);
    ck_assert(json_is_null(j));
    json_decref(j);
    j = tk_json_invariants(NULL);
    ck_assert(json_is_null(j));
    json_decref(j);
}
END_TEST

/* The basins a run reached, counted by hand: the first tightening on the
 * final polygon (the first counted try's `from`), then each try's end;
 * explored tries and tries given up are no sighting; values within
 * TK_BASIN_SAME are one basin. */
START_TEST(basins_count_the_sightings)
{
    const double n = NAN;
    /* step, from, amplitude, coarse, reached, improved, explored */
    tk_escape e[] = {{10, 72.0, 1.0, 90.0, n, false, true},        /* explored: none */
                     {20, 71.128, 1.0, n, 71.1281, false, false},  /* 71.128 twice */
                     {30, 71.128, 0.7, n, 71.001, true, false},    /* a lower basin */
                     {40, 71.001, 0.5, n, n, false, false},        /* given up: none */
                     {50, 71.001, 0.3, n, 71.0015, false, false}}; /* 71.001 again */
    json_t *b = tk_json_basins(e, 5, 71.0008);
    json_t *list = json_object_get(b, "basins");
    ck_assert_uint_eq(json_array_size(list), 2);
    ck_assert(json_real_value(json_object_get(json_array_get(list, 0), "ropelength")) == 71.001);
    ck_assert_int_eq(json_integer_value(json_object_get(json_array_get(list, 0), "times")), 2);
    ck_assert(json_real_value(json_object_get(json_array_get(list, 1), "ropelength")) == 71.128);
    ck_assert_int_eq(json_integer_value(json_object_get(json_array_get(list, 1), "times")), 2);
    ck_assert_int_eq(json_integer_value(json_object_get(b, "best_reached")), 2);
    ck_assert(json_is_null(json_object_get(b, "note")));
    json_decref(b);
    /* the lowest once: flagged */
    b = tk_json_basins(e, 3, 71.0008);
    ck_assert_int_eq(json_integer_value(json_object_get(b, "best_reached")), 1);
    ck_assert_str_eq(json_string_value(json_object_get(b, "note")),
                     "found once: run longer or with more seeds");
    json_decref(b);
    /* no try on the final polygon: the result alone, once */
    b = tk_json_basins(e, 1, 42.1);
    list = json_object_get(b, "basins");
    ck_assert_uint_eq(json_array_size(list), 1);
    ck_assert(json_real_value(json_object_get(json_array_get(list, 0), "ropelength")) == 42.1);
    ck_assert_int_eq(json_integer_value(json_object_get(b, "best_reached")), 1);
    json_decref(b);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("jsonmap");
    TCase *tc = tcase_create("jsonmap");
    tcase_add_test(tc, strut_arclengths_land_on_their_points);
    tcase_add_test(tc, kinks_sit_at_their_vertices);
    tcase_add_test(tc, numbers_keep_every_bit_and_infinities_are_null);
    tcase_add_test(tc, invariants_of_known_knots_and_links);
    tcase_add_test(tc, unknown_components_are_null);
    tcase_add_test(tc, basins_count_the_sightings);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
