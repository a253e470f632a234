/* Tests for the job document (server/job.c): its options by name from
 * text and from JSON, their domains, the defaults that tighten, the round
 * trip through the document, and the document's figures against the
 * step report they come from. */
#include <check.h>
#include <stdbool.h>
#include <math.h>
#include <string.h>

#include "support.h"
#include "job.h"
#include "jsonmap.h"

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
    json_t *in = json_pack("{s:f, s:i, s:i, s:f, s:f, s:f, s:f, s:b, s:i, s:i, s:i, s:b, s:f, s:f, "
                           "s:b, s:b, s:f, s:i}",
                           "resolution", 5.0, "vertices", 0, "steps", 300, "time", 0.0, "residual", 0.01,
                           "radius", 0.5, "lambda", 2.0, "autoscale", 1, "every", 25, "escapes",
                           0, "seed", 7, "coarse", 0, "overstep", 2e-5, "re_resolve", 0.0,
                           "converge", 1, "cpu_time", 1, "work", 1.5, "loose", 2);
    tk_error err;
    ck_assert_int_eq(tk_job_options_from_json(&o, in, NULL, &err), TK_OK);
    json_t *doc = tk_job_new("knot", NULL, &o, 1, 3);
    ck_assert(json_equal(in, json_object_get(doc, "options")));
    tk_job_options back;
    ck_assert_int_eq(tk_job_options_of(doc, &back, &err), TK_OK);
    ck_assert(same(&o, &back));
    json_decref(in);
    json_decref(doc);
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

/* No stop criterion: the defaults that tighten, shown in the job; a time
 * given is run out (no converge), with the rest of them; steps (or a
 * residual, a change) leave the options as given. */
START_TEST(no_stop_criterion_means_the_defaults_that_tighten)
{
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_job_options_complete(&o);
    ck_assert_int_eq(o.run.max_steps, 0);
    ck_assert(o.run.max_work == TK_DEFAULT_WORK && o.run.max_seconds == 0.0 && o.run.converge &&
              o.run.autoscale);
    ck_assert(o.run.resolution == TK_DEFAULT_RESOLUTION && o.run.vertices == 0);
    tk_error err;
    o = (tk_job_options)TK_JOB_OPTIONS_INIT;
    ck_assert_int_eq(tk_job_option_set_text(&o, "time", "3", &err), TK_OK);
    ck_assert_int_eq(tk_job_option_set_text(&o, "radius", "2", &err), TK_OK);
    ck_assert_int_eq(tk_job_option_set_text(&o, "vertices", "300", &err), TK_OK);
    tk_job_options_complete(&o);
    ck_assert_int_eq(o.run.max_steps, 0);
    ck_assert(o.run.max_seconds == 3.0 && o.run.radius == 2.0 && !o.run.converge);
    ck_assert(o.run.max_work == 0.0); /* a time given: no cap of work */
    ck_assert(o.run.autoscale);
    ck_assert(o.run.vertices == 300 && o.run.resolution == 0.0); /* a count given: kept */
    /* what is given keeps its value, the default too: no autoscale, the
     * input's vertices, no converge (a cap of 120 of work still) */
    o = (tk_job_options)TK_JOB_OPTIONS_INIT;
    json_t *given = json_pack("{s:b, s:f, s:b}", "autoscale", 0, "resolution", 0.0, "converge", 0);
    ck_assert_int_eq(tk_job_options_from_json(&o, given, NULL, &err), TK_OK);
    json_decref(given);
    tk_job_options_complete(&o);
    ck_assert(!o.run.autoscale && o.run.resolution == 0.0 && !o.run.converge);
    ck_assert(o.run.max_work == TK_DEFAULT_WORK && o.run.max_seconds == 0.0);
    /* a time or work of 0 given (no limit): converged, with no cap */
    const char *budgets[] = {"time", "work"};
    for (int k = 0; k < 2; k++) {
        o = (tk_job_options)TK_JOB_OPTIONS_INIT;
        ck_assert_int_eq(tk_job_option_set_text(&o, budgets[k], "0", &err), TK_OK);
        tk_job_options_complete(&o);
        ck_assert(o.run.max_seconds == 0.0 && o.run.max_work == 0.0 && o.run.converge);
    }
    /* work given is run out, with no cap of time */
    o = (tk_job_options)TK_JOB_OPTIONS_INIT;
    ck_assert_int_eq(tk_job_option_set_text(&o, "work", "30", &err), TK_OK);
    tk_job_options_complete(&o);
    ck_assert(o.run.max_work == 30.0 && o.run.max_seconds == 0.0 && !o.run.converge);
    /* the engine's own defaults stay for what a job does not set */
    tk_options defaults = TK_OPTIONS_INIT;
    ck_assert(o.run.overstep_tolerance == defaults.overstep_tolerance);
    o = (tk_job_options)TK_JOB_OPTIONS_INIT;
    o.run.max_steps = 50;
    tk_job_options_complete(&o);
    ck_assert(o.run.max_steps == 50 && !o.run.converge && !o.run.autoscale);
    ck_assert(o.run.max_seconds == 0.0 && o.run.resolution == 0.0);
    /* a new job shows the options it runs with */
    tk_job_options none = TK_JOB_OPTIONS_INIT;
    json_t *doc = tk_job_new("knot", NULL, &none, 1, 3);
    json_t *opts = json_object_get(doc, "options");
    ck_assert(json_real_value(json_object_get(opts, "work")) == TK_DEFAULT_WORK);
    ck_assert(json_real_value(json_object_get(opts, "time")) == 0.0);
    ck_assert(json_is_true(json_object_get(opts, "converge")));
    json_decref(doc);
}
END_TEST

/* The document's figures are the step report's, field by field; unknown
 * until the run has measured; the progress is the spent share of the
 * larger budget. */
START_TEST(the_document_carries_the_step_figures)
{
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    o.run.max_steps = 200;
    o.run.max_seconds = 10.0;
    json_t *doc = tk_job_new("knot", NULL, &o, 2, 96);
    ck_assert_str_eq(json_string_value(json_object_get(doc, "state")), "queued");
    ck_assert_int_eq(json_integer_value(json_object_get(doc, "vertices")), 96);
    ck_assert_int_eq(json_integer_value(json_object_get(doc, "components")), 2);
    for (size_t i = 0; i < tk_step_nfields; i++) {
        const json_t *v = json_object_get(doc, tk_step_fields[i].name);
        ck_assert_msg(v != NULL, "%s missing", tk_step_fields[i].name);
        if (tk_step_fields[i].kind == TK_KIND_REAL)
            ck_assert_msg(json_is_null(v), "%s known before the run", tk_step_fields[i].name);
    }
    ck_assert(json_is_null(json_object_get(json_object_get(doc, "progress"), "fraction")));
    tk_step_report r = {.step = 50, .seconds = 4.0, .ropelength = 33.5, .length = 16.75,
                        .thickness = 1.0, .minrad = 0.7, .residual = 0.02, .struts = 12,
                        .kinks = 3, .step_size = 1e-3, .rcond = 0.25, .violation = 1e-7,
                        .corrections = 2, .vertices = 96, .escapes = 1};
    tk_job_set_figures(doc, &r, &o);
    for (size_t i = 0; i < tk_step_nfields; i++)
        ck_assert_msg(json_number_value(json_object_get(doc, tk_step_fields[i].name)) ==
                          tk_field_get(&tk_step_fields[i], &r),
                      "%s", tk_step_fields[i].name);
    const json_t *progress = json_object_get(doc, "progress");
    ck_assert_int_eq(json_integer_value(json_object_get(progress, "step")), 50);
    ck_assert_double_eq_tol(json_real_value(json_object_get(progress, "fraction")), 0.4, 1e-15);
    ck_assert_int_eq(tk_job_step(doc), 50);
    /* the start (step 0) has no step to measure */
    r.step = 0;
    tk_job_set_figures(doc, &r, &o);
    ck_assert(json_is_null(json_object_get(doc, "residual")));
    ck_assert(json_is_null(json_object_get(doc, "step_size")));
    json_decref(doc);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("job");
    TCase *tc = tcase_create("options");
    tcase_add_test(tc, every_option_is_set_from_text);
    tcase_add_test(tc, bad_values_name_the_option);
    tcase_add_test(tc, json_options_round_trip);
    tcase_add_test(tc, bad_json_points_at_the_option);
    tcase_add_test(tc, no_stop_criterion_means_the_defaults_that_tighten);
    tcase_add_test(tc, the_document_carries_the_step_figures);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
