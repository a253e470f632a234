/* tightknot: a job's options, as the service takes them and the remote
 * client sends them: the engine's run options (their table, tk/tighten.h,
 * by the names the command line uses) and the service's own `every` (a
 * frame every this many steps).  One table for both ends.
 */
#ifndef TK_JOBOPTS_H
#define TK_JOBOPTS_H

#include <jansson.h>

#include "tk/record.h"

typedef struct tk_job_options {
    tk_options run;
    long every;
    tk_options_given given; /* the run options set by name (the defaults fill the rest) */
} tk_job_options;
#define TK_JOB_OPTIONS_INIT {TK_OPTIONS_INIT, 0, {0}}
extern const tk_field tk_job_option_fields[];
extern const size_t tk_job_option_nfields;

/* Sets the option `name` from text ("5", "1e-3", "true") and marks it
 * given: TK_EINVAL with a message naming it when it is unknown, malformed
 * or out of domain. */
int tk_job_option_set_text(tk_job_options *o, const char *name, const char *text, tk_error *err);

/* Sets the options present in a JSON object and marks them given; on
 * failure *bad (when not NULL) is the offending name (valid while obj
 * lives) or NULL. */
int tk_job_options_from_json(tk_job_options *o, const json_t *obj, const char **bad,
                             tk_error *err);

/* The options a job runs with: the defaults that tighten
 * (tk_options_complete), as the command line's. */
void tk_job_options_complete(tk_job_options *o);

#endif
