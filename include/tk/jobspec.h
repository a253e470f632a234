/* tightknot: the options of a tightening job, by name.
 *
 * A job's options are the run options (tk/tighten.h's table, by the names
 * the command line uses) and the service's own `every` (frames).  They
 * reach a job from an HTTP query (?resolution=5) and from a JSON object
 * ({"resolution": 5}); this module maps both through the one table, so
 * every way in says the same thing about a bad value.
 */
#ifndef TK_JOBSPEC_H
#define TK_JOBSPEC_H

#include <stdbool.h>
#include <stddef.h>

#include <jansson.h>

#include "tk/error.h"
#include "tk/record.h"
#include "tk/tighten.h"

typedef struct tk_job_options {
    tk_options run; /* the run options */
    long every;     /* keep a frame every this many steps (0: none) */
} tk_job_options;

#define TK_JOB_OPTIONS_INIT {TK_OPTIONS_INIT, 0}

/* The job options' fields: the named run options, then every. */
extern const tk_field tk_job_option_fields[];
extern const size_t tk_job_option_nfields;

/* Sets the option `name` from its text form ("5", "1e-3", "true").
 * Fails with TK_EINVAL and a message naming the option when the name is
 * unknown or the value is malformed or out of its domain. */
int tk_job_option_set_text(tk_job_options *o, const char *name, const char *text,
                           tk_error *err);

/* Sets every option present in the JSON object; on failure *bad (when not
 * NULL) points at the offending option's name (valid while obj lives). */
int tk_job_options_from_json(tk_job_options *o, const json_t *obj, const char **bad,
                             tk_error *err);

/* A JSON object with every option. */
json_t *tk_job_options_to_json(const tk_job_options *o);

/* The engine's options for the job: its run options, with
 * TK_DEFAULT_STEPS when no stop criterion is set (as the command line
 * does). */
void tk_job_options_to_run(const tk_job_options *o, tk_options *run);

#endif
