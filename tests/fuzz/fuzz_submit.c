/* Fuzz target: a job submission, from the request's media type, query and
 * body up to the stored job.
 *
 * The first byte picks the Content-Type (JSON, text/plain, text/plain
 * with a charset, something else, none).  For text/plain the bytes up to
 * the first newline are the query ("name=value" pairs separated by '&'),
 * the rest the body.  The submission is decoded (server/api.c), its VECT
 * parsed, and the job stored in a real SQLite store and read back: the
 * stored document must be the one submitted (name, options) and the
 * stored input the submitted text byte for byte.  Refusals must carry a 4xx status and a detail;
 * nothing may crash.  The job is deleted again so that the store stays
 * small over millions of runs. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fuzz.h"
#include "api.h"
#include "tk/vect.h"

#define FUZZ_MAX_VERTICES 2000
#define MAX_PAIRS 32

/* One store for the whole fuzzing process, in a directory of its own,
 * removed at exit. */
static tk_store *fuzz_store;
static char dir[] = "/tmp/tk-fuzz-submit-XXXXXX";

static void remove_store(void)
{
    tk_store_close(&fuzz_store);
    const char *const files[] = {"jobs.db", "jobs.db-wal", "jobs.db-shm"};
    for (size_t i = 0; i < 3; i++) {
        char path[sizeof dir + 16];
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        unlink(path);
    }
    rmdir(dir);
}

static tk_store *the_store(void)
{
    if (!fuzz_store) {
        CHECK(mkdtemp(dir) != NULL);
        char path[sizeof dir + 16];
        snprintf(path, sizeof path, "%s/jobs.db", dir);
        tk_error err;
        CHECK(tk_store_open(path, 30.0, &fuzz_store, &err) == TK_OK);
        atexit(remove_store);
    }
    return fuzz_store;
}

static void store_and_read_back(const tk_submission *sub, const tk_curve *curve,
                                const char *vect, size_t vlen)
{
    tk_store *store = the_store();
    json_t *doc = tk_job_new(sub->name, NULL, &sub->options, curve->ncomp, curve->nvert);
    char *input = strndup(vect, vlen);
    CHECK(doc && input);
    tk_error err;
    CHECK(tk_store_add(store, doc, input, &(tk_store_limits){1000000, 0, 0}, &err) == TK_OK);
    int64_t id = tk_job_id(doc);
    json_t *back = NULL;
    CHECK(tk_store_get(store, id, &back, &err) == TK_OK);
    CHECK(json_equal(doc, back));
    CHECK(strcmp(json_string_value(json_object_get(back, "name")), sub->name) == 0);
    CHECK(tk_job_state_in(back) == TK_JOB_QUEUED);
    tk_job_options options, complete = sub->options;
    tk_job_options_complete(&complete);
    CHECK(tk_job_options_of(back, &options, &err) == TK_OK);
    CHECK(fuzz_options_equal(&options, &complete));
    char *text = NULL;
    size_t len = 0;
    CHECK(tk_store_part(store, id, TK_PART_INPUT, &text, &len, &err) == TK_OK);
    CHECK(text && len == vlen && memcmp(text, vect, len) == 0);
    free(text);
    CHECK(tk_store_cancel(store, id, &err) == TK_OK);
    CHECK(tk_store_delete(store, id, &err) == TK_OK);
    json_decref(back);
    CHECK(tk_store_get(store, id, &back, &err) == TK_ENOTFOUND);
    json_decref(doc);
    free(input);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 8192)
        return 0;
    static const char *const types[] = {"application/json", "text/plain",
                                        "text/plain; charset=utf-8", "application/xml", NULL};
    const char *type = types[data[0] % 5];
    const char *rest = (const char *)data + 1;
    size_t n = size - 1;
    /* the query: the first line, split at '&' and '=' (as a server would
     * hand it over, NUL-terminated pieces) */
    char *query = NULL;
    tk_query_pair pairs[MAX_PAIRS];
    size_t npairs = 0;
    const char *body = rest;
    size_t len = n;
    const char *newline = memchr(rest, '\n', n);
    if (type && strncmp(type, "text/", 5) == 0 && newline) {
        size_t qlen = (size_t)(newline - rest);
        query = malloc(qlen + 1);
        CHECK(query);
        memcpy(query, rest, qlen);
        query[qlen] = '\0';
        char *save = NULL;
        for (char *pair = strtok_r(query, "&", &save); pair && npairs < MAX_PAIRS;
             pair = strtok_r(NULL, "&", &save)) {
            char *eq = strchr(pair, '=');
            if (eq)
                *eq++ = '\0';
            pairs[npairs++] = (tk_query_pair){pair, eq};
        }
        body = newline + 1;
        len = n - qlen - 1;
    }
    tk_submission sub;
    tk_problem problem;
    int rc = tk_submission_decode(type, pairs, npairs, body, len, &sub, &problem);
    if (rc != TK_OK || sub.catalogue) {
        CHECK(rc == TK_OK || (problem.status >= 400 && problem.status < 500));
        CHECK(rc == TK_OK || problem.detail[0] != '\0');
        CHECK(rc == TK_OK || sub.vect == NULL);
        tk_submission_clear(&sub);
        free(query);
        return 0;
    }
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = FUZZ_MAX_VERTICES;
    tk_curve *curve = NULL;
    tk_error err;
    rc = tk_vect_parse(sub.vect, sub.len, &limits, &curve, &err);
    if (rc == TK_OK) {
        /* what the store keeps is a C string: the reader let no NUL in */
        CHECK(memchr(sub.vect, '\0', sub.len) == NULL);
        /* the constraints given: refused with a 4xx naming one, or the
         * input to store is the curve written with every constraint, which
         * reads back as the curve with them */
        char *pinned = NULL;
        size_t had = curve->npins;
        if (tk_submission_pins(&sub, curve, &pinned, &problem) != TK_OK) {
            CHECK(problem.status >= 400 && problem.status < 600 && problem.detail[0] != '\0');
        } else if (pinned) {
            CHECK(curve->npins == had + json_array_size(sub.constraints));
            tk_curve *back = NULL;
            CHECK(tk_vect_parse(pinned, strlen(pinned), NULL, &back, &err) == TK_OK);
            CHECK(back->npins == curve->npins && back->nvert == curve->nvert);
            CHECK(!memcmp(back->xyz, curve->xyz, 3 * curve->nvert * sizeof *curve->xyz));
            tk_curve_free(&back);
            store_and_read_back(&sub, curve, pinned, strlen(pinned));
        } else {
            CHECK(json_array_size(sub.constraints) == 0);
            store_and_read_back(&sub, curve, sub.vect, sub.len);
        }
        free(pinned);
    } else {
        CHECK(rc == TK_EPARSE || rc == TK_ELIMIT);
        CHECK(strncmp(err.message, "line ", 5) == 0);
    }
    tk_curve_free(&curve);
    tk_submission_clear(&sub);
    free(query);
    return 0;
}
