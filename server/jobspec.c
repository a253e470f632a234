/* tightknot: run options by name (see include/tk/jobspec.h). */
#include "tk/jobspec.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *const tk_job_option_names[] = {"resolution", "steps", "time", "residual",
                                           "radius", "lambda", "autoscale", "every",
                                           "escapes", "seed", NULL};

/* Largest step count and interval we accept: a run of 10^9 steps is
 * already years of work, and the bound keeps every value exact in a
 * JSON double. */
#define MAX_COUNT 100000000L
/* Above this many vertices per unit ropelength the run would not fit in
 * memory for any real knot; the service also caps the vertex count. */
#define MAX_RESOLUTION 10000.0
/* The engine's bound on escape tries (tk_options.escapes). */
#define MAX_ESCAPES 1000L
/* A week: a job longer than that should be resumed as a new one. */
#define MAX_TIME 604800.0

typedef enum { KIND_REAL, KIND_COUNT, KIND_FLAG } option_kind;

static option_kind kind_of(const char *name)
{
    if (!strcmp(name, "steps") || !strcmp(name, "every") || !strcmp(name, "escapes") ||
        !strcmp(name, "seed"))
        return KIND_COUNT;
    if (!strcmp(name, "autoscale"))
        return KIND_FLAG;
    return KIND_REAL;
}

bool tk_job_option_known(const char *name)
{
    for (size_t i = 0; tk_job_option_names[i]; i++)
        if (!strcmp(tk_job_option_names[i], name))
            return true;
    return false;
}

/* Checks the domain of a real option and stores it. */
static int set_real(tk_job_options *o, const char *name, double x, tk_error *err)
{
    if (!isfinite(x))
        return tk_error_set(err, TK_EINVAL, "option '%s': must be a finite number", name);
    if (!strcmp(name, "radius") || !strcmp(name, "lambda")) {
        if (!(x > 0.0))
            return tk_error_set(err, TK_EINVAL, "option '%s': must be positive, not %g", name,
                                x);
        if (!strcmp(name, "radius") && !(x >= TK_CURVE_EDGE_MIN && x <= TK_CURVE_COORD_MAX))
            return tk_error_set(err, TK_EINVAL,
                                "option 'radius': must be between %g and %g, not %g",
                                TK_CURVE_EDGE_MIN, TK_CURVE_COORD_MAX, x);
        if (!strcmp(name, "radius"))
            o->radius = x;
        else
            o->lambda = x;
        return TK_OK;
    }
    if (x < 0.0)
        return tk_error_set(err, TK_EINVAL, "option '%s': must be zero or more, not %g", name,
                            x);
    if (!strcmp(name, "resolution")) {
        if (x > MAX_RESOLUTION)
            return tk_error_set(err, TK_EINVAL, "option 'resolution': %g is above the limit %g",
                                x, MAX_RESOLUTION);
        o->resolution = x;
    } else if (!strcmp(name, "time")) {
        if (x > MAX_TIME)
            return tk_error_set(err, TK_EINVAL,
                                "option 'time': %g seconds is above the limit %g (7 days)", x,
                                MAX_TIME);
        o->time = x;
    } else {
        o->residual = x;
    }
    return TK_OK;
}

static int set_count(tk_job_options *o, const char *name, long long n, tk_error *err)
{
    long most = !strcmp(name, "escapes") ? MAX_ESCAPES : MAX_COUNT;
    if (n < 0 || n > most)
        return tk_error_set(err, TK_EINVAL, "option '%s': must be a whole number from 0 to %ld",
                            name, most);
    if (!strcmp(name, "steps"))
        o->steps = (long)n;
    else if (!strcmp(name, "every"))
        o->every = (long)n;
    else if (!strcmp(name, "escapes"))
        o->escapes = (long)n;
    else
        o->seed = (long)n;
    return TK_OK;
}

int tk_job_option_set_text(tk_job_options *o, const char *name, const char *text,
                           tk_error *err)
{
    if (!tk_job_option_known(name))
        return tk_error_set(err, TK_EINVAL, "unknown option '%s'", name);
    if (!text || !*text)
        return tk_error_set(err, TK_EINVAL, "option '%s': no value given", name);
    switch (kind_of(name)) {
    case KIND_FLAG:
        if (!strcmp(text, "true") || !strcmp(text, "1") || !strcmp(text, "yes")) {
            o->autoscale = true;
            return TK_OK;
        }
        if (!strcmp(text, "false") || !strcmp(text, "0") || !strcmp(text, "no")) {
            o->autoscale = false;
            return TK_OK;
        }
        return tk_error_set(err, TK_EINVAL, "option '%s': expected true or false, found '%.40s'",
                            name, text);
    case KIND_COUNT: {
        char *end = NULL;
        errno = 0;
        long long n = strtoll(text, &end, 10);
        if (errno || end == text || *end)
            return tk_error_set(err, TK_EINVAL, "option '%s': expected a whole number, found '%.40s'",
                                name, text);
        return set_count(o, name, n, err);
    }
    case KIND_REAL:
    default: {
        char *end = NULL;
        errno = 0;
        double x = strtod(text, &end);
        if (errno || end == text || *end)
            return tk_error_set(err, TK_EINVAL, "option '%s': expected a number, found '%.40s'",
                                name, text);
        return set_real(o, name, x, err);
    }
    }
}

int tk_job_options_from_json(tk_job_options *o, const json_t *obj, const char **bad,
                             tk_error *err)
{
    if (bad)
        *bad = NULL;
    if (!json_is_object(obj))
        return tk_error_set(err, TK_EINVAL, "'options' must be a JSON object");
    const char *name;
    json_t *value;
    /* json_object_foreach wants a non-const object; it does not modify it */
    json_object_foreach((json_t *)obj, name, value) {
        int rc = TK_OK;
        if (!tk_job_option_known(name)) {
            rc = tk_error_set(err, TK_EINVAL, "unknown option '%.60s'", name);
        } else if (kind_of(name) == KIND_FLAG) {
            if (json_is_boolean(value))
                o->autoscale = json_is_true(value);
            else
                rc = tk_error_set(err, TK_EINVAL, "option '%s': expected true or false", name);
        } else if (kind_of(name) == KIND_COUNT) {
            double x = json_number_value(value);
            /* The domain is checked on the double: converting one at or
             * above 2^63 to long long is undefined. */
            if (!json_is_number(value) || x != floor(x))
                rc = tk_error_set(err, TK_EINVAL, "option '%s': expected a whole number", name);
            else if (!(x >= 0.0 && x <= (double)MAX_COUNT))
                rc = set_count(o, name, -1, err);
            else
                rc = set_count(o, name, (long long)x, err);
        } else {
            if (!json_is_number(value))
                rc = tk_error_set(err, TK_EINVAL, "option '%s': expected a number", name);
            else
                rc = set_real(o, name, json_number_value(value), err);
        }
        if (rc) {
            if (bad)
                *bad = name;
            return rc;
        }
    }
    return TK_OK;
}

json_t *tk_job_options_to_json(const tk_job_options *o)
{
    return json_pack("{s:f, s:I, s:f, s:f, s:f, s:f, s:b, s:I, s:I, s:I}", "resolution",
                     o->resolution, "steps", (json_int_t)o->steps, "time", o->time, "residual",
                     o->residual, "radius", o->radius, "lambda", o->lambda, "autoscale",
                     o->autoscale, "every", (json_int_t)o->every, "escapes",
                     (json_int_t)o->escapes, "seed", (json_int_t)o->seed);
}

void tk_job_options_to_run(const tk_job_options *o, tk_options *run)
{
    tk_options defaults = TK_OPTIONS_INIT;
    *run = defaults;
    run->resolution = o->resolution;
    run->max_steps = o->steps;
    run->max_seconds = o->time;
    run->min_residual = o->residual;
    run->radius = o->radius;
    run->lambda = o->lambda;
    run->autoscale = o->autoscale;
    run->snapshot_every = (size_t)o->every;
    run->escapes = (int)o->escapes;
    run->seed = (unsigned long long)o->seed;
    if (o->steps == 0 && o->time == 0.0 && o->residual == 0.0)
        run->max_steps = TK_JOB_DEFAULT_STEPS;
}
