/* tightknot service: the job document (see job.h). */
#include "job.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "jsonmap.h"

const char *const tk_job_states[TK_JOB_STATES] = {"queued", "running", "done", "failed",
                                                  "cancelled"};

int tk_job_state_of(const char *name)
{
    for (int s = 0; name && s < TK_JOB_STATES; s++)
        if (!strcmp(name, tk_job_states[s]))
            return s;
    return -1;
}

int tk_job_options_of(const json_t *doc, tk_job_options *o, tk_error *err)
{
    *o = (tk_job_options)TK_JOB_OPTIONS_INIT;
    tk_error why;
    if (tk_job_options_from_json(o, json_object_get(doc, "options"), NULL, &why))
        return tk_error_set(err, TK_EIO, "the stored options of job %lld do not read back: %s",
                            (long long)tk_job_id(doc), why.message);
    return TK_OK;
}

json_t *tk_job_new(const char *name, const char *owner, const tk_job_options *o,
                   size_t components, size_t vertices)
{
    tk_job_options run = *o;
    tk_job_options_complete(&run);
    json_t *doc = json_pack("{s:o, s:s, s:o, s:{s:i, s:n}, s:I, s:i, s:i, s:f, s:n, s:n, s:n, "
                            "s:n, s:n}", "name", tk_json_text(name), "state", "queued", "options",
                            tk_json_record(tk_job_option_fields, tk_job_option_nfields, &run),
                            "progress", "step", 0, "fraction", "components",
                            (json_int_t)components, "frames", 0, "frames_refused", 0,
                            "paused_seconds", 0.0, "stop_reason", "error", "invariants",
                            "started", "finished");
    /* figures: measurements unknown until the run has measured */
    for (size_t i = 0; doc && i < tk_step_nfields; i++)
        json_object_set_new(doc, tk_step_fields[i].name,
                            tk_step_fields[i].kind == TK_KIND_REAL ? json_null() : json_integer(0));
    json_object_set_new(doc, "vertices", json_integer((json_int_t)vertices));
    json_object_set_new(doc, "owner", owner ? json_string(owner) : json_null());
    json_object_set_new(doc, "daemon", json_null());
    tk_job_stamp(doc, "created");
    return doc;
}

void tk_job_set_figures(json_t *doc, const tk_step_report *r, const tk_job_options *o)
{
    json_t *figures = tk_json_step(r);
    json_object_update(doc, figures);
    json_decref(figures);
    if (r->step == 0) { /* the start has no step to measure */
        json_object_set_new(doc, "residual", json_null());
        json_object_set_new(doc, "step_size", json_null());
    }
    double f = tk_options_spent(&o->run, r);
    json_object_set_new(doc, "progress",
                        json_pack("{s:I, s:o}", "step", (json_int_t)r->step, "fraction",
                                  f < 0.0 ? json_null() : json_real(fmin(f, 1.0))));
}

void tk_job_add(json_t *doc, const char *key, double amount, bool whole)
{
    /* 0 when absent: a job stored before the key was */
    double sum = json_number_value(json_object_get(doc, key)) + amount;
    json_object_set_new(doc, key, whole ? json_integer((json_int_t)sum) : json_real(sum));
}

void tk_job_stamp(json_t *doc, const char *key)
{
    char now[32];
    tk_time_iso(now);
    json_object_set_new(doc, key, json_string(now));
}

void tk_time_iso(char out[32])
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    struct tm tm;
    gmtime_r(&ts.tv_sec, &tm);
    size_t n = strftime(out, 32, "%Y-%m-%dT%H:%M:%S", &tm);
    snprintf(out + n, 32 - n, ".%03ldZ", ts.tv_nsec / 1000000);
}

double tk_clock_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

size_t tk_job_thin(size_t i, size_t n, size_t keep)
{
    return keep < 2 ? n - 1 : (size_t)((double)i * (double)(n - 1) / (double)(keep - 1) + 0.5);
}

tk_job_state tk_job_state_in(const json_t *doc)
{
    int s = tk_job_state_of(json_string_value(json_object_get(doc, "state")));
    return s < 0 ? TK_JOB_FAILED : (tk_job_state)s;
}

long tk_job_step(const json_t *doc)
{
    return (long)json_integer_value(json_object_get(json_object_get(doc, "progress"), "step"));
}

json_int_t tk_job_id(const json_t *doc)
{
    return json_integer_value(json_object_get(doc, "id"));
}
