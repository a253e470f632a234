/* Tests for a job's options by name (server/jobspec.c): every name from
 * text and from JSON, the domains, the default step limit, and the round
 * trip through JSON. */
#include <check.h>
#include <stdbool.h>
#include <math.h>
#include <string.h>

#include "support.h"
#include "tk/jobspec.h"

/* Whether two option sets agree in every field. */
static bool same(const tk_job_options *a, const tk_job_options *b)
{
    for (size_t i = 0; i < tk_job_option_nfields; i++)
        if (tk_field_get(&tk_job_option_fields[i], a) != tk_field_get(&tk_job_option_fields[i], b))
            return false;
    return true;
}

START_TEST(every_option_is_set_from_text)
{
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_error err;
    const char *pairs[][2] = {{"resolution", "7.5"}, {"steps", "120"}, {"time", "2.5"},
                              {"residual", "1e-3"},  {"radius", "0.75"}, {"lambda", "1.5"},
                              {"autoscale", "true"}, {"every", "10"},   {"escapes", "3"},
                              {"seed", "42"},        {"coarse", "no"},  {"overstep", "2e-5"},
                              {"re_resolve", "0.1"}};
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++)
        ck_assert_msg(tk_job_option_set_text(&o, pairs[i][0], pairs[i][1], &err) == TK_OK, "%s",
                      err.message);
    const tk_options *r = &o.run;
    ck_assert(r->resolution == 7.5 && r->max_steps == 120 && r->max_seconds == 2.5);
    ck_assert(r->min_residual == 1e-3 && r->radius == 0.75 && r->lambda == 1.5 && r->autoscale);
    ck_assert(o.every == 10 && r->escapes == 3 && r->seed == 42 && !r->coarse_to_fine);
    ck_assert(r->overstep_tolerance == 2e-5 && r->re_resolve == 0.1);
    ck_assert_int_eq(tk_job_option_set_text(&o, "autoscale", "0", &err), TK_OK);
    ck_assert(!o.run.autoscale);
    /* the engine's own fields have no name */
    ck_assert_int_eq(tk_job_option_set_text(&o, "equalise", "1", &err), TK_EINVAL);
}
END_TEST

START_TEST(bad_values_name_the_option)
{
    const char *bad[][2] = {{"radius", "0"},      {"radius", "-1"},       {"lambda", "nan"},
                            {"resolution", "-2"}, {"resolution", "1e9"},  {"steps", "1.5"},
                            {"steps", "-3"},      {"steps", "99999999999"}, {"time", "x"},
                            {"residual", "inf"},  {"autoscale", "maybe"}, {"every", ""},
                            {"radius", "1 2"},     {"escapes", "1001"},  {"seed", "-1"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        tk_job_options o = TK_JOB_OPTIONS_INIT;
        tk_job_options before = o;
        tk_error err;
        ck_assert_int_eq(tk_job_option_set_text(&o, bad[i][0], bad[i][1], &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, bad[i][0]) != NULL, "'%s' does not name %s",
                      err.message, bad[i][0]);
        ck_assert(same(&o, &before));
    }
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_error err;
    ck_assert_int_eq(tk_job_option_set_text(&o, "tolerance", "1", &err), TK_EINVAL);
    ck_assert(strstr(err.message, "unknown option 'tolerance'"));
}
END_TEST

START_TEST(json_options_round_trip)
{
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    json_t *in = json_pack("{s:f, s:i, s:f, s:f, s:f, s:f, s:b, s:i, s:i, s:i, s:b, s:f, s:f}",
                           "resolution", 5.0, "steps", 300, "time", 0.0, "residual", 0.01,
                           "radius", 0.5, "lambda", 2.0, "autoscale", 1, "every", 25, "escapes",
                           0, "seed", 7, "coarse", 0, "overstep", 2e-5, "re_resolve", 0.0);
    tk_error err;
    ck_assert_int_eq(tk_job_options_from_json(&o, in, NULL, &err), TK_OK);
    json_t *out = tk_job_options_to_json(&o);
    ck_assert(json_equal(in, out));
    json_decref(in);
    json_decref(out);
    /* a whole number written as a real is a whole number */
    json_t *real_steps = json_pack("{s:f}", "steps", 40.0);
    ck_assert_int_eq(tk_job_options_from_json(&o, real_steps, NULL, &err), TK_OK);
    ck_assert_int_eq(o.run.max_steps, 40);
    json_decref(real_steps);
}
END_TEST

START_TEST(bad_json_points_at_the_option)
{
    /* 2^63 and beyond as counts: converting them to an integer type is
     * undefined (the sanitizer build traps), so the domain comes first. */
    const char *docs[] = {"{\"radius\": \"big\"}", "{\"steps\": 2.5}", "{\"autoscale\": 1}",
                          "{\"lambda\": -1}", "{\"colour\": 3}", "{\"every\": true}",
                          "{\"steps\": 9.223372036854775808e18}", "{\"every\": -9.3e18}",
                          "{\"steps\": 1e300}", "{\"radius\": 1e300}"};
    const char *names[] = {"radius", "steps", "autoscale", "lambda", "colour", "every",
                           "steps", "every", "steps", "radius"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        json_t *d = json_loads(docs[i], 0, NULL);
        tk_job_options o = TK_JOB_OPTIONS_INIT;
        const char *bad = NULL;
        tk_error err;
        ck_assert_int_eq(tk_job_options_from_json(&o, d, &bad, &err), TK_EINVAL);
        ck_assert_ptr_nonnull(bad);
        ck_assert_str_eq(bad, names[i]);
        json_decref(d);
    }
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    json_t *arr = json_array();
    tk_error err;
    ck_assert_int_eq(tk_job_options_from_json(&o, arr, NULL, &err), TK_EINVAL);
    json_decref(arr);
}
END_TEST

START_TEST(no_stop_criterion_means_the_default_steps)
{
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_options run;
    tk_job_options_to_run(&o, &run);
    ck_assert_int_eq(run.max_steps, TK_DEFAULT_STEPS);
    o.run.max_seconds = 3.0;
    tk_job_options_to_run(&o, &run);
    ck_assert_int_eq(run.max_steps, 0);
    ck_assert(run.max_seconds == 3.0);
    o.every = 7;
    o.run.radius = 2.0;
    tk_job_options_to_run(&o, &run);
    ck_assert_uint_eq(run.snapshot_every, 0); /* frames are the service's */
    ck_assert(run.radius == 2.0);
    /* the engine's own defaults stay for what a job does not set */
    tk_options defaults = TK_OPTIONS_INIT;
    ck_assert(run.overstep_tolerance == defaults.overstep_tolerance);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("jobspec");
    TCase *tc = tcase_create("options");
    tcase_add_test(tc, every_option_is_set_from_text);
    tcase_add_test(tc, bad_values_name_the_option);
    tcase_add_test(tc, json_options_round_trip);
    tcase_add_test(tc, bad_json_points_at_the_option);
    tcase_add_test(tc, no_stop_criterion_means_the_default_steps);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
