/* Tests for the JSON forms of results (server/jsonmap.c): a strut's
 * arclength coordinates, walked along the polygon, land on its points;
 * components are laid end to end; numbers keep every bit; non-finite
 * numbers become null. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/jsonmap.h"
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
    json_t *doc = tk_json_contacts(c, struts.items, struts.count, kinks, nk, true);
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
    json_t *doc = tk_json_contacts(c, NULL, 0, kinks, 2, false);
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

int main(void)
{
    Suite *s = suite_create("jsonmap");
    TCase *tc = tcase_create("jsonmap");
    tcase_add_test(tc, strut_arclengths_land_on_their_points);
    tcase_add_test(tc, kinks_sit_at_their_vertices);
    tcase_add_test(tc, numbers_keep_every_bit_and_infinities_are_null);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
