/* Tests for the records' fields by name (engine/record.c) and their JSON
 * (common/jsonmap.c): the tables against the structs they describe, the
 * domains, text and JSON round trips. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "jsonmap.h"
#include "support.h"
#include "tk/record.h"

/* Whether two option records agree in every field (memcmp would compare
 * the padding too). */
static bool same_options(const tk_options *a, const tk_options *b)
{
    for (size_t i = 0; i < tk_option_nfields; i++)
        if (tk_field_get(&tk_option_fields[i], a) != tk_field_get(&tk_option_fields[i], b))
            return false;
    return true;
}

/* Every field's place is its own and inside the struct, and the
 * defaults of TK_OPTIONS_INIT are the table's and lie in their domains. */
START_TEST(tables_describe_their_structs)
{
    tk_options d = TK_OPTIONS_INIT;
    ck_assert_int_eq(tk_options_check(&d, NULL), TK_OK);
    for (size_t i = 0; i < tk_option_nfields; i++) {
        const tk_field *f = &tk_option_fields[i];
        ck_assert_msg(tk_field_get(f, &d) == f->dflt, "%s", f->field);
        ck_assert(f->offset < sizeof d && f->min <= f->max);
        for (size_t j = 0; j < i; j++)
            ck_assert(tk_option_fields[j].offset != f->offset);
    }
    /* a step report set field by field reads back field by field */
    tk_step_report s;
    memset(&s, 0, sizeof s);
    for (size_t i = 0; i < tk_step_nfields; i++) {
        tk_field f = tk_step_fields[i];
        f.min = 0.0;
        f.max = 1e9;
        ck_assert_int_eq(tk_field_set(&f, &s, (double)(i + 1), NULL), TK_OK);
    }
    for (size_t i = 0; i < tk_step_nfields; i++)
        ck_assert(tk_field_get(&tk_step_fields[i], &s) == (double)(i + 1));
    ck_assert_int_eq(s.step, 1);
    ck_assert_int_eq(s.restarts, (int)tk_step_nfields - 1);
    ck_assert(s.work == (double)tk_step_nfields); /* the last field */
    /* the recovery counts are fields of the run's timing, each its own */
    tk_run_timing t;
    memset(&t, 0, sizeof t);
    for (size_t i = 0; i < tk_recovery_nfields; i++) {
        const tk_field *f = &tk_recovery_fields[i];
        ck_assert(f->offset < sizeof t && f->name);
        ck_assert_int_eq(tk_field_set(f, &t, (double)(i + 1), NULL), TK_OK);
    }
    ck_assert_int_eq(t.undone_steps, 1);
    ck_assert_int_eq(t.rescales, 2);
    ck_assert(t.largest_rescale == 3.0);
    ck_assert_int_eq(t.bent_corrections, 4);
    ck_assert_int_eq(t.length_steps, 5);
    ck_assert_int_eq(t.corrected_steps, 6);
    ck_assert(t.search == 0.0 && t.total == 0.0 && t.factorisations == 0);
}
END_TEST

/* Out of its domain, not whole, not finite or malformed: refused with the
 * option's name, the record unchanged. */
START_TEST(bad_values_name_the_field)
{
    const char *bad[][2] = {{"radius", "0"},       {"radius", "-1"},      {"lambda", "nan"},
                            {"resolution", "-2"},  {"resolution", "1e9"}, {"steps", "1.5"},
                            {"steps", "-3"},       {"steps", "1e12"},     {"time", "x"},
                            {"residual", "inf"},   {"autoscale", "maybe"}, {"escapes", "1001"},
                            {"seed", "-1"},        {"overstep", "0.5"},   {"radius", "1 2"},
                            {"re_resolve", "1"},   {"coarse", ""},        {"steps", "0x10"},
                            /* not exact as a JSON number (nor as a double) */
                            {"seed", "9007199254740992"}, {"seed", "9007199254740993"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        tk_options o = TK_OPTIONS_INIT, before = o;
        const tk_field *f = tk_field_find(tk_option_fields, tk_option_nfields, bad[i][0]);
        ck_assert_msg(f != NULL, "%s", bad[i][0]);
        tk_error err;
        ck_assert_int_eq(tk_field_parse(f, &o, bad[i][1], &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, bad[i][0]) != NULL, "%s", err.message);
        ck_assert(same_options(&o, &before));
    }
    /* the engine refuses what the table refuses */
    tk_options o = TK_OPTIONS_INIT;
    o.active_tolerance = 0.0;
    ck_assert_int_eq(tk_options_check(&o, NULL), TK_EINVAL);
    ck_assert_ptr_null(tk_field_find(tk_option_fields, tk_option_nfields, "active_tolerance"));
}
END_TEST

/* Each named option's every kind of value from text, then through JSON
 * and back, exactly. */
START_TEST(options_round_trip_through_text_and_json)
{
    tk_options o = TK_OPTIONS_INIT;
    const char *set[][2] = {{"radius", "0.75"}, {"lambda", "1.5"},  {"resolution", "7.5"},
                            {"autoscale", "yes"}, {"steps", "120"},  {"time", "2.5"},
                            {"residual", "1e-3"}, {"overstep", "2e-5"}, {"re_resolve", "0.05"},
                            {"coarse", "false"}, {"escapes", "3"},   {"seed", "9007199254740991"}};
    for (size_t i = 0; i < sizeof set / sizeof set[0]; i++) {
        tk_error err;
        const tk_field *f = tk_field_find(tk_option_fields, tk_option_nfields, set[i][0]);
        ck_assert_msg(f && tk_field_parse(f, &o, set[i][1], &err) == TK_OK, "%s", set[i][0]);
    }
    ck_assert(o.radius == 0.75 && o.lambda == 1.5 && o.resolution == 7.5 && o.autoscale);
    ck_assert(o.max_steps == 120 && o.max_seconds == 2.5 && o.min_residual == 1e-3);
    ck_assert(o.overstep_tolerance == 2e-5 && o.re_resolve == 0.05 && !o.coarse_to_fine);
    ck_assert(o.escapes == 3 && o.seed == 9007199254740991ULL);
    json_t *j = tk_json_options(&o);
    /* only the named fields, each once */
    size_t named = 0;
    for (size_t i = 0; i < tk_option_nfields; i++)
        named += tk_option_fields[i].name != NULL;
    ck_assert_uint_eq(json_object_size(j), named);
    ck_assert(json_is_false(json_object_get(j, "coarse")));
    ck_assert(json_is_integer(json_object_get(j, "steps")));
    char *text = tk_json_dump(j, false);
    json_t *back = json_loads(text, 0, NULL);
    tk_options again = TK_OPTIONS_INIT;
    ck_assert_int_eq(tk_json_record_set(tk_option_fields, tk_option_nfields, &again, back, NULL,
                                        NULL),
                     TK_OK);
    ck_assert(same_options(&again, &o));
    free(text);
    json_decref(j);
    json_decref(back);
}
END_TEST

START_TEST(bad_json_points_at_the_option)
{
    const char *docs[] = {"{\"steps\": 1.5}", "{\"autoscale\": 1}", "{\"radius\": \"1\"}",
                          "{\"nonsense\": 1}", "{\"steps\": 9.3e18}", "{\"coarse\": null}"};
    const char *names[] = {"steps", "autoscale", "radius", "nonsense", "steps", "coarse"};
    for (size_t i = 0; i < sizeof docs / sizeof docs[0]; i++) {
        json_t *j = json_loads(docs[i], 0, NULL);
        tk_options o = TK_OPTIONS_INIT;
        const char *bad = NULL;
        tk_error err;
        ck_assert_int_eq(tk_json_record_set(tk_option_fields, tk_option_nfields, &o, j, &bad,
                                            &err),
                         TK_EINVAL);
        ck_assert_str_eq(bad, names[i]);
        ck_assert_msg(strstr(err.message, names[i]) != NULL, "%s", err.message);
        json_decref(j);
    }
    /* a null says so, not "nan"; a seed beyond 2^53 is refused, not rounded */
    const char *nulls[][2] = {{"{\"time\": null}", "not null"},
                              {"{\"seed\": 9007199254740993}", "9007199254740991"}};
    for (size_t i = 0; i < 2; i++) {
        json_t *j = json_loads(nulls[i][0], 0, NULL);
        tk_options o = TK_OPTIONS_INIT;
        tk_error err;
        ck_assert_int_eq(tk_json_record_set(tk_option_fields, tk_option_nfields, &o, j, NULL,
                                            &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, nulls[i][1]) && !strstr(err.message, "nan"), "%s",
                      err.message);
        json_decref(j);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("record");
    TCase *tc = tcase_create("fields");
    tcase_add_test(tc, tables_describe_their_structs);
    tcase_add_test(tc, bad_values_name_the_field);
    tcase_add_test(tc, options_round_trip_through_text_and_json);
    tcase_add_test(tc, bad_json_points_at_the_option);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
