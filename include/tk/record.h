/* tightknot: the fields of a record, by name.
 *
 * The run options, the step report, a run's resume point and its
 * recovery counts are each written down once, as an
 * X-macro table (tk/tighten.h).  This module turns a table into field
 * descriptors (name, kind, place in the struct, domain, help), so that
 * every mapping of a record (the command line's options and --help, HTTP
 * queries, JSON, the store, a TSV log) is a loop over its fields rather
 * than a list copied by hand.  Values pass as doubles: every kind's
 * domain lies within the integers a double holds exactly (2^53).
 */
#ifndef TK_RECORD_H
#define TK_RECORD_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/error.h"
#include "tk/tighten.h"

typedef enum tk_field_kind {
    TK_KIND_REAL,
    TK_KIND_LONG,
    TK_KIND_INT,
    TK_KIND_SIZE,
    TK_KIND_BOOL,
    TK_KIND_SEED
} tk_field_kind;

typedef struct tk_field {
    const char *field; /* the struct member */
    const char *name;  /* as users give it; NULL: set in code only */
    tk_field_kind kind;
    size_t offset;
    double dflt, min, max;
    const char *help;
} tk_field;

/* A row of a table for the struct `type` from an X-macro row (tk/tighten.h),
 * the member `fld` reached by `path` (fld, or outer.fld). */
#define TK_FIELD_ROW(type, path, fld, kind, dflt, lo, hi, nm, hlp)                         \
    {#fld, nm, TK_KIND_##kind, offsetof(type, path), (double)(dflt), lo, hi, hlp}

/* The tables, in their order in tk/tighten.h. */
extern const tk_field tk_option_fields[];
extern const size_t tk_option_nfields;
extern const tk_field tk_step_fields[];
extern const size_t tk_step_nfields;
extern const tk_field tk_resume_fields[];
extern const size_t tk_resume_nfields;
/* the recovery fields of tk_run_timing (TK_RECOVERY_FIELDS) */
extern const tk_field tk_recovery_fields[];
extern const size_t tk_recovery_nfields;

/* The field called `name` (its user name), or NULL. */
const tk_field *tk_field_find(const tk_field *table, size_t n, const char *name);

/* The field's value in the record. */
double tk_field_get(const tk_field *f, const void *record);

/* Sets the field to x: TK_EINVAL, with a message naming the field and its
 * domain, when x is not whole for a whole kind, or outside [min, max] (not
 * finite included; the record is then unchanged).  A field whose domain
 * is (-inf, inf) is a measurement and takes any value, NaN too. */
int tk_field_set(const tk_field *f, void *record, double x, tk_error *err);

/* Sets the field from text: a number ("5", "1e-3"), or for a BOOL true,
 * false, yes, no, 1 or 0.  Errors as tk_field_set, and for malformed
 * text. */
int tk_field_parse(const tk_field *f, void *record, const char *text, tk_error *err);

/* Every option within its domain, and the options consistent with each
 * other (re_resolve and snapshots exclude each other). */
int tk_options_check(const tk_options *o, tk_error *err);

/* The share of its budget (steps, time, work: the largest share) a run has
 * spent at the step report s, not capped at 1; -1 when it has no budget. */
double tk_options_spent(const tk_options *o, const tk_step_report *s);

/* Which run options a user gave (on the command line, in a job's JSON or
 * query), whatever their values: the defaults below fill the others. */
#define TK_FIELD_GIVEN(field, ...) bool field;
typedef struct tk_options_given {
    TK_OPTION_FIELDS(TK_FIELD_GIVEN)
} tk_options_given;

/* Marks the run option that users name `name` as given; false when no run
 * option has that name. */
bool tk_options_given_mark(tk_options_given *g, const char *name);

/* The defaults that tighten, as the command line and the service apply
 * them to what a user gave.  A run with none of steps, residual and change
 * set (the stops that end the flow at a chosen point, to compare runs) is
 * meant to end tight; of the options the user did not give, it goes coarse
 * to fine at TK_DEFAULT_RESOLUTION (unless a resolution or a vertex count
 * was given), autoscales (a start thinner than the tube can run no other
 * way), is capped at TK_DEFAULT_WORK of work unless it was given a time
 * or work (0: no cap), and stops when converged unless a time or work
 * was given (a budget given is run out, as before these defaults).
 * Options given keep their values; any other run is left as given. */
void tk_options_complete(tk_options *o, const tk_options_given *given);

#endif
