/* Fuzz target: the run options by name (server/job.c), the way the
 * HTTP query, the command line and a JSON body give them.
 *
 * The first byte picks the form: even, the rest is "name=value" pairs
 * separated by '&' (a query string, as the command line's --name value
 * pairs also reach tk_job_option_set_text); odd, the rest is a JSON
 * document for tk_job_options_from_json.  Whatever is accepted must lie
 * in the documented domains, survive the round trip through JSON
 * unchanged, and start a run on a small curve or be refused by the
 * engine with a clean error. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "tk/generate.h"
#include "job.h"
#include "tk/tighten.h"

static int from_text(tk_job_options *o, const char *text, size_t len)
{
    char *copy = malloc(len + 1);
    CHECK(copy);
    memcpy(copy, text, len);
    copy[len] = '\0';
    int rc = TK_OK;
    char *save = NULL;
    for (char *pair = strtok_r(copy, "&", &save); pair && rc == TK_OK;
         pair = strtok_r(NULL, "&", &save)) {
        char *eq = strchr(pair, '=');
        const char *value = "";
        if (eq) {
            *eq = '\0';
            value = eq + 1;
        }
        tk_error err;
        rc = tk_job_option_set_text(o, pair, value, &err);
        if (rc)
            CHECK(rc == TK_EINVAL && strstr(err.message, "option") != NULL);
    }
    free(copy);
    return rc;
}

static int from_json(tk_job_options *o, const char *text, size_t len)
{
    json_t *doc = json_loadb(text, len, JSON_REJECT_DUPLICATES | JSON_DECODE_ANY, NULL);
    if (!doc)
        return TK_EPARSE;
    const char *bad = NULL;
    tk_error err;
    int rc = tk_job_options_from_json(o, doc, &bad, &err);
    if (rc)
        CHECK(rc == TK_EINVAL && (!json_is_object(doc) || bad != NULL));
    json_decref(doc);
    return rc;
}

/* Every field within its table's domain, checked independently of the
 * code that set it. */
static void check_domains(const tk_job_options *o)
{
    for (size_t i = 0; i < tk_job_option_nfields; i++) {
        const tk_field *f = &tk_job_option_fields[i];
        double x = tk_field_get(f, o);
        CHECK(x >= f->min && x <= f->max);
        CHECK(f->kind == TK_KIND_REAL || x == floor(x));
    }
    CHECK(o->run.radius >= 1e-30 && o->run.radius <= 1e30);
    CHECK(o->run.lambda > 0.0 && isfinite(o->run.lambda));
}

static void check_round_trip(const tk_job_options *o)
{
    /* through the job's document, as the store keeps it */
    json_t *doc = tk_job_new("fuzz", NULL, o, 1, 3);
    CHECK(doc);
    tk_job_options back, complete = *o;
    tk_job_options_complete(&complete);
    tk_error err;
    CHECK(tk_job_options_of(doc, &back, &err) == TK_OK);
    CHECK(fuzz_options_equal(&back, &complete));
    json_decref(doc);
}

/* A run on a 24-vertex trefoil with the options, for a few steps at most:
 * started, or refused with a clean error. */
static void check_run(const tk_job_options *o)
{
    /* thousands of vertices: too slow for a fuzz input (a step is not cut
     * short by the time budget: 771,084 vertices took 8.9 s for two steps
     * and a 1 s budget at -O2, past the fuzzer's 10 s under ASan) */
    if (o->run.resolution > 20.0 || o->run.vertices > 20000)
        return;
    tk_curve *c = NULL;
    CHECK(tk_generate_torus(2, 3, 24, &c, NULL) == TK_OK);
    tk_job_options job = *o;
    tk_job_options_complete(&job);
    tk_options run = job.run;
    run.max_steps = 2;
    run.max_seconds = 1.0;
    tk_run *r = NULL;
    tk_error err;
    int rc = tk_run_new(c, &run, &r, &err);
    if (rc == TK_OK) {
        tk_stop_reason why;
        rc = tk_run_until(r, &why, &err);
        CHECK(rc == TK_OK || rc == TK_ENUMERIC || rc == TK_ETYPE);
        tk_run_free(&r);
    } else {
        /* tk_run_new's contract; TK_ETYPE: a resolution too coarse for
         * the trefoil (below 6 vertices) */
        CHECK(rc == TK_EINVAL || rc == TK_ELIMIT || rc == TK_ENUMERIC || rc == TK_ETYPE ||
              rc == TK_ENOMEM);
        CHECK(err.message[0] != '\0');
    }
    tk_curve_free(&c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 4096)
        return 0;
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    const char *text = (const char *)data + 1;
    int rc = data[0] % 2 ? from_json(&o, text, size - 1) : from_text(&o, text, size - 1);
    if (rc != TK_OK)
        return 0;
    check_domains(&o);
    check_round_trip(&o);
    check_run(&o);
    return 0;
}
