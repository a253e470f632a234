/* tightknot: the fields of a record, by name (see include/tk/record.h). */
#include "tk/record.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define OPTION_ROW(fld, kind, dflt, lo, hi, nm, hlp)                                     \
    TK_FIELD_ROW(tk_options, fld, fld, kind, dflt, lo, hi, nm, hlp),
/* the step figures are measurements: any value, NaN included (a residual
 * before the first step) */
#define STEP_ROW(fld, kind, dflt, lo, hi, nm, hlp)                                       \
    TK_FIELD_ROW(tk_step_report, fld, fld, kind, 0, -INFINITY, INFINITY, nm, hlp),
#define RESUME_ROW(fld, kind, dflt, lo, hi, nm, hlp)                                     \
    TK_FIELD_ROW(tk_resume, fld, fld, kind, dflt, lo, hi, nm, hlp),
#define RECOVERY_ROW(fld, kind, dflt, lo, hi, nm, hlp)                                   \
    TK_FIELD_ROW(tk_run_timing, fld, fld, kind, dflt, lo, hi, nm, hlp),

const tk_field tk_option_fields[] = {TK_OPTION_FIELDS(OPTION_ROW)};
const size_t tk_option_nfields = sizeof tk_option_fields / sizeof tk_option_fields[0];
const tk_field tk_step_fields[] = {TK_STEP_FIELDS(STEP_ROW)};
const size_t tk_step_nfields = sizeof tk_step_fields / sizeof tk_step_fields[0];
const tk_field tk_resume_fields[] = {TK_RESUME_FIELDS(RESUME_ROW)};
const size_t tk_resume_nfields = sizeof tk_resume_fields / sizeof tk_resume_fields[0];
const tk_field tk_recovery_fields[] = {TK_RECOVERY_FIELDS(RECOVERY_ROW)};
const size_t tk_recovery_nfields = sizeof tk_recovery_fields / sizeof tk_recovery_fields[0];

const tk_field *tk_field_find(const tk_field *table, size_t n, const char *name)
{
    for (size_t i = 0; name && i < n; i++)
        if (table[i].name && !strcmp(table[i].name, name))
            return &table[i];
    return NULL;
}

double tk_field_get(const tk_field *f, const void *record)
{
    const char *p = (const char *)record + f->offset;
    switch (f->kind) {
    case TK_KIND_LONG: return (double)*(const long *)p;
    case TK_KIND_INT: return (double)*(const int *)p;
    case TK_KIND_SIZE: return (double)*(const size_t *)p;
    case TK_KIND_BOOL: return *(const bool *)p ? 1.0 : 0.0;
    case TK_KIND_SEED: return (double)*(const unsigned long long *)p;
    case TK_KIND_REAL:
    default: return *(const double *)p;
    }
}

static const char *label(const tk_field *f)
{
    return f->name ? f->name : f->field;
}

int tk_field_set(const tk_field *f, void *record, double x, tk_error *err)
{
    bool measured = f->min == -INFINITY && f->max == INFINITY;
    if (f->kind != TK_KIND_REAL && isfinite(x) && x != floor(x))
        return tk_error_set(err, TK_EINVAL, "option '%s': must be a whole number, not %.17g",
                            label(f), x);
    /* (NaN: a JSON null, the only way to give one) */
    if (!measured && isnan(x))
        return tk_error_set(err, TK_EINVAL, "option '%s': must be from %.16g to %.16g, not null "
                            "(no number)", label(f), f->min, f->max);
    if (!measured && !(x >= f->min && x <= f->max))
        return tk_error_set(err, TK_EINVAL, "option '%s': must be from %.16g to %.16g, not %.17g",
                            label(f), f->min, f->max, x);
    char *p = (char *)record + f->offset;
    switch (f->kind) {
    case TK_KIND_LONG: *(long *)p = (long)x; break;
    case TK_KIND_INT: *(int *)p = (int)x; break;
    case TK_KIND_SIZE: *(size_t *)p = (size_t)x; break;
    case TK_KIND_BOOL: *(bool *)p = x != 0.0; break;
    case TK_KIND_SEED: *(unsigned long long *)p = (unsigned long long)x; break;
    case TK_KIND_REAL:
    default: *(double *)p = x; break;
    }
    return TK_OK;
}

int tk_field_parse(const tk_field *f, void *record, const char *text, tk_error *err)
{
    if (!text || !*text)
        return tk_error_set(err, TK_EINVAL, "option '%s': no value given", label(f));
    if (f->kind == TK_KIND_BOOL) {
        static const char *const yes[] = {"true", "yes", "1"}, *const no[] = {"false", "no", "0"};
        for (int k = 0; k < 3; k++)
            if (!strcmp(text, yes[k]) || !strcmp(text, no[k]))
                return tk_field_set(f, record, !strcmp(text, yes[k]), err);
        return tk_error_set(err, TK_EINVAL, "option '%s': expected true or false, found '%.40s'",
                            label(f), text);
    }
    /* decimal only: strtod would also read hexadecimal, inf and nan */
    char *end = NULL;
    errno = 0;
    double x = strtod(text, &end);
    if (strspn(text, "0123456789+-.eE") != strlen(text) || end == text || *end ||
        errno == ERANGE)
        return tk_error_set(err, TK_EINVAL, "option '%s': expected a number, found '%.40s'",
                            label(f), text);
    return tk_field_set(f, record, x, err);
}

int tk_options_check(const tk_options *o, tk_error *err)
{
    for (size_t i = 0; i < tk_option_nfields; i++) {
        tk_options copy = *o;
        int rc = tk_field_set(&tk_option_fields[i], &copy, tk_field_get(&tk_option_fields[i], o),
                              err);
        if (rc)
            return rc;
    }
    if (o->vertices > 0 && o->resolution > 0.0)
        return tk_error_set(err, TK_EINVAL,
                            "vertices and resolution both set the vertex count: give one");
    if (o->re_resolve > 0.0 && o->snapshot_every > 0)
        return tk_error_set(err, TK_EINVAL,
                            "re_resolve changes the vertex count, which snapshots keep: "
                            "use one or the other");
    return TK_OK;
}

double tk_options_spent(const tk_options *o, const tk_step_report *s)
{
    double spent = -1.0;
    if (o->max_steps > 0)
        spent = (double)s->step / (double)o->max_steps;
    if (o->max_seconds > 0.0)
        spent = fmax(spent, s->seconds / o->max_seconds);
    if (o->max_work > 0.0)
        spent = fmax(spent, s->work / o->max_work);
    return spent;
}

/* Where each run option's mark lies in tk_options_given, by its name
 * (NULL: the engine's own, not given by users). */
#define GIVEN_ROW(fld, kind, dflt, lo, hi, nm, hlp) {nm, offsetof(tk_options_given, fld)},
static const struct {
    const char *name;
    size_t offset;
} given_rows[] = {TK_OPTION_FIELDS(GIVEN_ROW)};

bool tk_options_given_mark(tk_options_given *g, const char *name)
{
    for (size_t i = 0; i < sizeof given_rows / sizeof given_rows[0]; i++)
        if (given_rows[i].name && !strcmp(given_rows[i].name, name)) {
            *(bool *)((char *)g + given_rows[i].offset) = true;
            return true;
        }
    return false;
}

void tk_options_complete(tk_options *o, const tk_options_given *given)
{
    if (o->max_steps > 0 || o->min_residual > 0.0 || o->min_change > 0.0)
        return;
    if (!given->resolution && !given->vertices)
        o->resolution = TK_DEFAULT_RESOLUTION;
    if (!given->autoscale)
        o->autoscale = true;
    if (!given->converge)
        o->converge = !((given->max_seconds && o->max_seconds > 0.0) ||
                        (given->max_work && o->max_work > 0.0));
    if (!given->max_seconds && !given->max_work)
        o->max_work = TK_DEFAULT_WORK;
}
