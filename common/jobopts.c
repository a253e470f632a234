/* tightknot: a job's options (see jobopts.h). */
#include "jobopts.h"

#include "jsonmap.h"

#define JOB_ROW(fld, kind, dflt, lo, hi, nm, hlp)                                        \
    TK_FIELD_ROW(tk_job_options, run.fld, fld, kind, dflt, lo, hi, nm, hlp),

const tk_field tk_job_option_fields[] = {
    TK_OPTION_FIELDS(JOB_ROW)
    {"every", "every", TK_KIND_LONG, offsetof(tk_job_options, every), 0, 0, 1e8,
     "keep a frame every this many steps (0: none)"},
};
const size_t tk_job_option_nfields = sizeof tk_job_option_fields / sizeof tk_job_option_fields[0];

int tk_job_option_set_text(tk_job_options *o, const char *name, const char *text, tk_error *err)
{
    const tk_field *f = tk_field_find(tk_job_option_fields, tk_job_option_nfields, name);
    if (!f)
        return tk_error_set(err, TK_EINVAL, "unknown option '%.60s'", name);
    int rc = tk_field_parse(f, o, text, err);
    if (!rc)
        (void)tk_options_given_mark(&o->given, name); /* false for every */
    return rc;
}

int tk_job_options_from_json(tk_job_options *o, const json_t *obj, const char **bad,
                             tk_error *err)
{
    if (bad)
        *bad = NULL;
    if (!json_is_object(obj))
        return tk_error_set(err, TK_EINVAL, "'options' must be a JSON object");
    int rc = tk_json_record_set(tk_job_option_fields, tk_job_option_nfields, o, obj, bad, err);
    const char *name;
    json_t *value;
    if (!rc)
        json_object_foreach((json_t *)obj, name, value)
            (void)tk_options_given_mark(&o->given, name); /* false for every */
    return rc;
}

void tk_job_options_complete(tk_job_options *o)
{
    tk_options_complete(&o->run, &o->given);
}
