/* tightknot: the run options of a tightening job, by name.
 *
 * The same ten options reach a run from the command line (--resolution
 * 5), from an HTTP query (?resolution=5) and from a JSON object
 * ({"resolution": 5}); this module is the one place that knows their names,
 * their domains and their defaults, so every way in says the same thing
 * about a bad value.
 */
#ifndef TK_JOBSPEC_H
#define TK_JOBSPEC_H

#include <stdbool.h>
#include <stddef.h>

#include <jansson.h>

#include "tk/error.h"
#include "tk/tighten.h"

typedef struct tk_job_options {
    double resolution; /* vertices per unit ropelength at the start; 0 keeps the input */
    long steps;        /* stop after this many steps (0: no step limit) */
    double time;       /* stop after this many seconds (0: no time limit) */
    double residual;   /* stop when the residual falls below this (0: never) */
    double radius;     /* tube radius */
    double lambda;     /* stiffness: minrad >= lambda * radius */
    bool autoscale;    /* scale the start so no contact is active */
    long every;        /* keep a snapshot every this many steps (0: none) */
    long escapes;      /* most escape tries (tk_options.escapes) */
    long seed;         /* of the escapes' deformations */
} tk_job_options;

#define TK_JOB_OPTIONS_INIT {0.0, 0, 0.0, 0.0, 0.5, 1.0, false, 0, 8, 1}

/* With no stop criterion given, a run stops after this many steps. */
#define TK_JOB_DEFAULT_STEPS 1000

/* The option names, NULL-terminated, in the order the API lists them. */
extern const char *const tk_job_option_names[];

/* True when name is one of the option names. */
bool tk_job_option_known(const char *name);

/* Sets the option `name` from its text form ("5", "1e-3", "true").
 * Fails with TK_EINVAL and a message naming the option when the name is
 * unknown or the value is malformed or out of its domain. */
int tk_job_option_set_text(tk_job_options *o, const char *name, const char *text,
                           tk_error *err);

/* Sets every option present in the JSON object; on failure *bad (when not
 * NULL) points at the offending option's name (valid while obj lives). */
int tk_job_options_from_json(tk_job_options *o, const json_t *obj, const char **bad,
                             tk_error *err);

/* A JSON object with all ten options. */
json_t *tk_job_options_to_json(const tk_job_options *o);

/* The engine's options for the job, with the default step limit applied
 * when no stop criterion is set. */
void tk_job_options_to_run(const tk_job_options *o, tk_options *run);

#endif
