/* tightknot service: a job is one JSON document, what GET /v1/jobs/{id}
 * serves (openapi.yaml, Job) less its links: what was asked (name,
 * options) and by whom (owner: its token's name, or null), where it
 * stands (state, progress, timestamps, stop reason, error, frames, knot
 * type), its latest figures (the step report's fields, tk/tighten.h), and
 * what the store did to it (frames_refused, paused_seconds).  The store
 * keeps it, the pool updates it, the routes serve it: no field is listed
 * twice.
 */
#ifndef TK_SERVER_JOB_H
#define TK_SERVER_JOB_H

#include <stdbool.h>

#include <jansson.h>

#include "jobopts.h"

typedef enum tk_job_state {
    TK_JOB_QUEUED, TK_JOB_RUNNING, TK_JOB_DONE, TK_JOB_FAILED, TK_JOB_CANCELLED, TK_JOB_STATES
} tk_job_state;
#define TK_JOB_FINAL(s) ((s) >= TK_JOB_DONE)
extern const char *const tk_job_states[TK_JOB_STATES];

/* The state called name, or -1. */
int tk_job_state_of(const char *name);

/* The options of a stored document; TK_EIO when they do not read back. */
int tk_job_options_of(const json_t *doc, tk_job_options *o, tk_error *err);

/* A queued job's document, figures unknown (null), options complete. */
json_t *tk_job_new(const char *name, const char *owner, const tk_job_options *o,
                   size_t components, size_t vertices);

/* Sets the figures of step r and the progress through the budget of o. */
void tk_job_set_figures(json_t *doc, const tk_step_report *r, const tk_job_options *o);

/* Adds amount to the count (whole) or number doc[key] (0 when absent). */
void tk_job_add(json_t *doc, const char *key, double amount, bool whole);

/* Sets doc[key] to the time now (tk_time_iso). */
void tk_job_stamp(json_t *doc, const char *key);

/* The time now, ISO 8601, UTC, milliseconds: "2024-05-06T07:08:09.123Z". */
void tk_time_iso(char out[32]);

/* Seconds on the monotonic clock: for spans and deadlines. */
double tk_clock_seconds(void);

/* The index of the i-th of `keep` entries taken evenly from n, the first
 * and the last among them: how a history is thinned. */
size_t tk_job_thin(size_t i, size_t n, size_t keep);

/* The job's state, step and id as the document says. */
tk_job_state tk_job_state_in(const json_t *doc);
long tk_job_step(const json_t *doc);
json_int_t tk_job_id(const json_t *doc);

#endif
