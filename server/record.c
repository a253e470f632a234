/* tightknot service: a run's record in the store (see record.h). */
#include "record.h"

#include <stdlib.h>
#include <string.h>

#include "jsonmap.h"
#include "tk/vect.h"

char *tk_record_history(const tk_run *run, const json_t *before, size_t keep)
{
    size_t n = 0, had = json_array_size(before);
    const tk_step_report *h = tk_run_history(run, &n);
    size_t total = had + n;
    keep = total < keep ? total : keep;
    json_t *a = json_array();
    for (size_t i = 0; i < keep; i++) {
        size_t at = tk_job_thin(i, total, keep);
        json_array_append_new(a, at < had ? json_incref(json_array_get(before, at))
                                          : tk_json_step(&h[at - had]));
    }
    char *text = tk_json_dump(a, false);
    json_decref(a);
    return text;
}

json_t *tk_record_history_before(const char *text, long resume)
{
    json_t *stored = text ? json_loads(text, 0, NULL) : NULL, *entry, *before = json_array();
    size_t i;
    json_array_foreach(stored, i, entry)
        if (json_integer_value(json_object_get(entry, "step")) < resume)
            json_array_append(before, entry);
    json_decref(stored);
    return before;
}

/* The run's resume point, its best curve and that curve's figures. */
static char *resume_text(const tk_run *run)
{
    tk_resume at;
    tk_run_resume_point(run, &at);
    tk_step_report report;
    const tk_curve *best = tk_run_best(run, &report);
    char *vect = NULL;
    if (best && tk_vect_to_string(best, &vect, NULL, NULL) != TK_OK)
        return NULL;
    json_t *o = json_pack("{s:o, s:o, s:o}", "at",
                          tk_json_record(tk_resume_fields, tk_resume_nfields, &at), "best",
                          vect ? json_string(vect) : json_null(), "best_report",
                          best ? tk_json_step(&report) : json_null());
    free(vect);
    char *text = tk_json_dump(o, false);
    json_decref(o);
    return text;
}

int tk_record_parts(const tk_run *run, const json_t *before, size_t keep,
                    char *parts[TK_PARTS], tk_error *err)
{
    const tk_curve *c = tk_run_curve(run);
    size_t ns = 0, nk = 0;
    const tk_strut *struts = tk_run_struts(run, &ns);
    const tk_kink *kinks = tk_run_kinks(run, &nk);
    double *pin_force = c->npins ? calloc(c->npins, sizeof *pin_force) : NULL;
    if (pin_force && tk_run_pin_forces(run, pin_force, NULL) != TK_OK) {
        free(pin_force); /* out of memory: the constraints without forces */
        pin_force = NULL;
    }
    json_t *o = tk_json_contacts(c, struts, ns, kinks, nk, true, pin_force);
    free(pin_force);
    json_object_set_new(o, "step", json_integer((json_int_t)tk_run_latest(run)->step));
    json_object_set_new(o, "thickness", tk_json_number(tk_run_latest(run)->thickness));
    parts[TK_PART_CONTACTS] = tk_json_dump(o, false);
    json_decref(o);
    int rc = tk_vect_to_string(c, &parts[TK_PART_CURVE], NULL, err);
    parts[TK_PART_HISTORY] = tk_record_history(run, before, keep);
    parts[TK_PART_RESUME] = resume_text(run);
    if (!rc && (!parts[TK_PART_CONTACTS] || !parts[TK_PART_HISTORY] || !parts[TK_PART_RESUME]))
        rc = tk_error_set(err, TK_ENOMEM, "out of memory writing a job");
    return rc;
}

int tk_record_curve(tk_store *s, int64_t id, tk_part part, size_t max_vertices, tk_curve **out,
                    tk_error *err)
{
    char *text = NULL;
    size_t len = 0;
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = max_vertices;
    int rc = tk_store_part(s, id, part, &text, &len, err);
    if (!rc && !text)
        rc = tk_error_set(err, TK_EIO, "job %lld has no stored curve", (long long)id);
    if (!rc)
        rc = tk_vect_parse(text, len, &limits, out, err);
    free(text);
    return rc;
}

int tk_record_resume(tk_store *s, const json_t *doc, const tk_options *o, size_t max_vertices,
                     const tk_invariants *input, tk_invariants *refused, tk_run **run,
                     tk_error *err)
{
    tk_curve *curve = NULL, *best = NULL;
    char *text = NULL;
    int64_t id = tk_job_id(doc);
    tk_resume at = {.step = tk_job_step(doc),
                    .seconds = json_number_value(json_object_get(doc, "seconds")),
                    .start_ropelength = json_number_value(json_object_get(doc, "ropelength"))};
    tk_step_report best_report = {0};
    int rc = tk_record_curve(s, id, TK_PART_CURVE, max_vertices, &curve, err);
    if (!rc)
        rc = tk_store_part(s, id, TK_PART_RESUME, &text, NULL, err);
    json_t *stored = text ? json_loads(text, 0, NULL) : NULL;
    const char *vect = json_string_value(json_object_get(stored, "best"));
    tk_error why = {0};
    if (!rc && text &&
        (!stored ||
         tk_json_record_set(tk_resume_fields, tk_resume_nfields, &at, json_object_get(stored, "at"),
                            NULL, &why) ||
         (vect && (tk_vect_parse(vect, strlen(vect), NULL, &best, &why) ||
                   tk_json_record_set(tk_step_fields, tk_step_nfields, &best_report,
                                      json_object_get(stored, "best_report"), NULL, &why)))))
        rc = tk_error_set(err, TK_EIO, "the stored resume point of job %lld does not read back: %.200s",
                          (long long)id, stored ? why.message : "not JSON");
    if (!rc)
        rc = tk_run_resume(curve, o, &at, best, best ? &best_report : NULL, input, run, err);
    if (rc == TK_ETYPE) /* the job's result is what was stored */
        tk_invariants_compute(curve, refused, NULL);
    json_decref(stored);
    free(text);
    tk_curve_free(&curve);
    tk_curve_free(&best);
    return rc;
}

char *tk_record_layout(const tk_curve *c)
{
    json_t *counts = json_array();
    for (size_t k = 0; k < c->ncomp; k++)
        json_array_append_new(counts, json_integer((json_int_t)tk_curve_comp_vertices(c, k)));
    char *text = tk_json_dump(counts, false);
    json_decref(counts);
    return text;
}

json_t *tk_record_components(const tk_curve *c, const json_t *counts)
{
    bool own = json_array_size(counts) == c->ncomp;
    json_t *comps = json_array();
    for (size_t k = 0; k < c->ncomp; k++)
        json_array_append_new(comps, json_pack("{s:I, s:b}", "vertices", own
                                               ? json_integer_value(json_array_get(counts, k))
                                               : (json_int_t)tk_curve_comp_vertices(c, k),
                                               "closed", c->closed[k]));
    return comps;
}
