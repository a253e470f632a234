/* tightknot: JSON forms of the engine's results (see common/jsonmap.h). */
#include "jsonmap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

json_t *tk_json_number(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

json_t *tk_json_point(const double p[3])
{
    json_t *a = json_array();
    for (int k = 0; a && k < 3; k++)
        json_array_append_new(a, tk_json_number(p[k]));
    return a;
}

json_t *tk_json_text(const char *s)
{
    json_t *j = json_string(s);
    if (j)
        return j;
    char *copy = strdup(s);
    if (!copy)
        return NULL;
    for (char *p = copy; *p; p++)
        if ((unsigned char)*p >= 0x80)
            *p = '?';
    j = json_string(copy);
    free(copy);
    return j;
}

json_t *tk_json_record(const tk_field *table, size_t n, const void *record)
{
    json_t *o = json_object();
    for (size_t i = 0; o && i < n; i++) {
        const tk_field *f = &table[i];
        double x = tk_field_get(f, record);
        if (f->name)
            json_object_set_new(o, f->name,
                                f->kind == TK_KIND_REAL   ? tk_json_number(x)
                                : f->kind == TK_KIND_BOOL ? json_boolean(x != 0.0)
                                                          : json_integer((json_int_t)x));
    }
    return o;
}

int tk_json_record_set(const tk_field *table, size_t n, void *record, const json_t *obj,
                       const char **bad, tk_error *err)
{
    if (bad)
        *bad = NULL;
    if (!json_is_object(obj))
        return tk_error_set(err, TK_EINVAL, "expected a JSON object");
    const char *name;
    json_t *value;
    /* json_object_foreach wants a non-const object; it does not modify it */
    json_object_foreach((json_t *)obj, name, value) {
        const tk_field *f = tk_field_find(table, n, name);
        int rc = TK_OK;
        if (!f)
            rc = tk_error_set(err, TK_EINVAL, "unknown option '%.60s'", name);
        else if (f->kind == TK_KIND_BOOL ? !json_is_boolean(value)
                                         : !json_is_number(value) &&
                                               !(f->kind == TK_KIND_REAL && json_is_null(value)))
            rc = tk_error_set(err, TK_EINVAL, "option '%s': expected %s", name,
                              f->kind == TK_KIND_BOOL ? "true or false" : "a number");
        else
            rc = tk_field_set(f, record,
                              json_is_boolean(value) ? json_is_true(value)
                              : json_is_null(value)  ? NAN
                                                     : json_number_value(value),
                              err);
        if (rc) {
            if (bad)
                *bad = name;
            return rc;
        }
    }
    return TK_OK;
}

json_t *tk_json_step(const tk_step_report *s)
{
    return tk_json_record(tk_step_fields, tk_step_nfields, s);
}

json_t *tk_json_options(const tk_options *o)
{
    return tk_json_record(tk_option_fields, tk_option_nfields, o);
}

json_t *tk_json_escapes(const tk_escape *e, size_t count)
{
    json_t *list = json_array();
    for (size_t k = 0; list && k < count; k++)
        json_array_append_new(
            list, json_pack("{s:I, s:o, s:o, s:o, s:o, s:b, s:b, s:b}", "step", (json_int_t)e[k].step,
                            "from", tk_json_number(e[k].from), "amplitude",
                            tk_json_number(e[k].amplitude), "coarse",
                            tk_json_number(e[k].coarse), "reached",
                            tk_json_number(e[k].reached), "improved", e[k].improved,
                            "explored", e[k].explored, "turned", e[k].turned));
    return list;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Why TK_BASIN_SAME is 1e-4: re-posed copies of one start, and escapes
 * back into the basin they left, end within 2e-5 of each other at
 * resolution 5, while the distinct basins seen on the catalogue are
 * 1.6e-3 and more apart. */
json_t *tk_json_basins(const tk_escape *e, size_t count, double final)
{
    double *seen = malloc((count + 1) * sizeof *seen);
    if (!seen)
        return NULL;
    size_t n = 0;
    for (size_t k = 0; k < count; k++) {
        if (e[k].explored)
            continue;
        if (n == 0 && isfinite(e[k].from))
            seen[n++] = e[k].from;
        if (isfinite(e[k].reached))
            seen[n++] = e[k].reached;
    }
    if (n == 0 && isfinite(final))
        seen[n++] = final;
    qsort(seen, n, sizeof *seen, by_value);
    json_t *basins = json_array();
    size_t best = 0;
    for (size_t k = 0; k < n;) {
        size_t j = k + 1;
        while (j < n && seen[j] - seen[k] <= TK_BASIN_SAME * seen[k])
            j++;
        json_array_append_new(basins, json_pack("{s:o, s:I}", "ropelength",
                                                tk_json_number(seen[k]), "times",
                                                (json_int_t)(j - k)));
        if (k == 0)
            best = j - k;
        k = j;
    }
    free(seen);
    return json_pack("{s:o, s:I, s:o}", "basins", basins, "best_reached", (json_int_t)best,
                     "note", best == 1 ? json_string("found once: run longer or with more seeds")
                                       : json_null());
}

/* Arclength at the start of every edge, components laid end to end:
 * start[e] for global edge e, plus each component's start in comp_start. */
static double *edge_starts(const tk_curve *c, double *comp_start)
{
    size_t ne = tk_curve_edge_count(c);
    double *start = malloc((ne + 1) * sizeof *start);
    if (!start)
        return NULL;
    double s = 0.0;
    size_t e = 0;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        comp_start[comp] = s;
        size_t n = tk_curve_comp_edges(c, comp);
        for (size_t k = 0; k < n; k++, e++) {
            start[e] = s;
            s += tk_curve_edge_length(c, comp, k);
        }
    }
    start[e] = s;
    return start;
}

/* A vertex's place along the components laid end to end: it starts edge
 * `vertex` of its component; the last vertex of an open one ends the
 * component. */
static double vertex_along(const tk_curve *c, const double *start, const double *comp_start,
                           size_t comp, size_t vertex)
{
    return vertex < tk_curve_comp_edges(c, comp)
               ? start[tk_curve_comp_first_edge(c, comp) + vertex]
               : comp_start[comp] + tk_curve_comp_length(c, comp);
}

json_t *tk_json_contacts(const tk_curve *c, const tk_strut *struts, size_t nstruts,
                         const tk_kink *kinks, size_t nkinks, bool with_force,
                         const double *pin_force)
{
    double *comp_start = malloc((c->ncomp + 1) * sizeof *comp_start);
    double *start = comp_start ? edge_starts(c, comp_start) : NULL;
    json_t *o = json_object();
    json_t *comps = json_array();
    json_t *list = json_array();
    json_t *klist = json_array();
    if (!start || !o || !comps || !list || !klist) {
        free(comp_start);
        free(start);
        json_decref(o);
        json_decref(comps);
        json_decref(list);
        json_decref(klist);
        return NULL;
    }
    for (size_t comp = 0; comp < c->ncomp; comp++)
        json_array_append_new(comps,
                              json_pack("{s:I, s:b, s:o, s:o}", "vertices",
                                        (json_int_t)tk_curve_comp_vertices(c, comp), "closed",
                                        c->closed[comp], "length",
                                        tk_json_number(tk_curve_comp_length(c, comp)), "start",
                                        tk_json_number(comp_start[comp])));
    for (size_t i = 0; i < nstruts; i++) {
        const tk_strut *st = &struts[i];
        double along[2];
        double param[2] = {st->s, st->t};
        for (int k = 0; k < 2; k++) {
            size_t e = tk_curve_comp_first_edge(c, st->comp[k]) + st->edge[k];
            along[k] = start[e] + param[k] * (start[e + 1] - start[e]);
        }
        json_t *j = json_object();
        json_object_set_new(j, "edges",
                            json_pack("[[II][II]]", (json_int_t)st->comp[0],
                                      (json_int_t)st->edge[0], (json_int_t)st->comp[1],
                                      (json_int_t)st->edge[1]));
        json_object_set_new(j, "s", tk_json_number(st->s));
        json_object_set_new(j, "t", tk_json_number(st->t));
        json_object_set_new(j, "p", tk_json_point(st->p));
        json_object_set_new(j, "q", tk_json_point(st->q));
        json_object_set_new(j, "length", tk_json_number(st->length));
        json_object_set_new(j, "arclength",
                            json_pack("[o, o]", tk_json_number(along[0]),
                                      tk_json_number(along[1])));
        if (with_force)
            json_object_set_new(j, "force", tk_json_number(st->force));
        json_array_append_new(list, j);
    }
    for (size_t i = 0; i < nkinks; i++) {
        const tk_kink *k = &kinks[i];
        json_t *j = json_object();
        json_object_set_new(j, "comp", json_integer((json_int_t)k->comp));
        json_object_set_new(j, "vertex", json_integer((json_int_t)k->vertex));
        json_object_set_new(j, "minrad", tk_json_number(k->minrad));
        json_object_set_new(j, "arclength", tk_json_number(vertex_along(c, start, comp_start,
                                                                         k->comp, k->vertex)));
        if (with_force)
            json_object_set_new(j, "force", tk_json_number(k->force));
        json_array_append_new(klist, j);
    }
    json_object_set_new(o, "components", comps);
    json_object_set_new(o, "struts", list);
    json_object_set_new(o, "kinks", klist);
    if (c->npins) {
        json_t *plist = json_array();
        for (size_t i = 0; i < c->npins; i++) {
            const tk_pin *p = &c->pins[i];
            char text[512];
            tk_pin_format(p, text, sizeof text);
            json_t *j = json_pack("{s:I, s:I, s:s, s:o}", "comp", (json_int_t)p->comp, "vertex",
                                  (json_int_t)p->vertex, "constraint", text, "arclength",
                                  tk_json_number(vertex_along(c, start, comp_start, p->comp,
                                                              p->vertex)));
            if (with_force && pin_force)
                json_object_set_new(j, "force", tk_json_number(pin_force[i]));
            json_array_append_new(plist, j);
        }
        json_object_set_new(o, "constraints", plist);
    }
    free(start);
    free(comp_start);
    return o;
}

json_t *tk_json_invariants(const tk_invariants *inv)
{
    if (!inv || inv->ncomp == 0)
        return json_null();
    size_t n = inv->ncomp;
    json_t *alexander = json_array(), *text = json_array(), *det = json_array(),
           *linking = json_array();
    for (size_t a = 0; a < n; a++) {
        const tk_knot_type *k = &inv->knot[a];
        json_t *coeff = json_null(), *poly = json_null();
        if (k->known) {
            coeff = json_array();
            for (int i = 0; i <= k->degree; i++)
                json_array_append_new(coeff, json_integer((json_int_t)k->alexander[i]));
            /* up to 41 terms of "- C t^40" */
            char buf[1024];
            tk_alexander_format(k, buf, sizeof buf);
            poly = json_string(buf);
        }
        json_array_append_new(alexander, coeff);
        json_array_append_new(text, poly);
        json_array_append_new(det, k->known ? json_integer((json_int_t)k->determinant)
                                            : json_null());
        json_t *row = json_array();
        for (size_t b = 0; b < n; b++)
            json_array_append_new(row, json_integer((json_int_t)inv->linking[a * n + b]));
        json_array_append_new(linking, row);
    }
    json_t *link = inv->link_known ? json_integer((json_int_t)inv->link_determinant)
                                   : json_null();
    return json_pack("{s:o, s:o, s:o, s:o, s:o, s:b}", "alexander", alexander, "alexander_text",
                     text, "determinants", det, "link_determinant", link, "linking", linking,
                     "complete", inv->complete);
}

char *tk_json_dump(const json_t *value, bool indent)
{
    size_t flags = JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17) |
                   (indent ? JSON_INDENT(1) : JSON_COMPACT);
    return value ? json_dumps(value, flags) : NULL;
}
