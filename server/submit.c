/* tightknot service: a submission decoded (see api.h): POST /v1/jobs's
 * body and query, without HTTP and without the engine. */
#include "api.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "tk/pin.h"
#include "tk/vect.h"

__attribute__((format(printf, 5, 6))) static int refuse(tk_problem *p, unsigned status,
                                                        const char *member, const char *value,
                                                        const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->detail, sizeof p->detail, fmt, ap);
    va_end(ap);
    p->status = status;
    snprintf(p->member, sizeof p->member, "%s", member ? member : "");
    snprintf(p->value, sizeof p->value, "%s", value ? value : "");
    return status == 400 ? TK_EPARSE : TK_EINVAL;
}

static bool media_is(const char *type, const char *media)
{
    size_t n = strlen(media);
    return type && !strncasecmp(type, media, n) && strchr("; ", type[n]);
}

/* A name is shown as a JSON string and printed on terminals: UTF-8 under
 * 128 bytes, no control character (C0, DEL, C1: escapes, bells and line
 * breaks would drive the terminal of whoever lists the jobs). */
static int set_name(tk_submission *out, const json_t *name, tk_problem *p)
{
    const unsigned char *t = (const unsigned char *)json_string_value(name);
    bool control = false;
    for (size_t i = 0; t && i < json_string_length(name); i++)
        control |= t[i] < 0x20 || t[i] == 0x7f || (t[i] == 0xc2 && t[i + 1] >= 0x80 &&
                                                   t[i + 1] <= 0x9f);
    if (!json_is_string(name) || json_string_length(name) > 127 || control)
        return refuse(p, 422, "field", "name", "'name' must be text (UTF-8, no control "
                      "character) under 128 bytes");
    out->name = json_string_value(name);
    return TK_OK;
}

static int decode_json(const char *body, size_t len, tk_submission *out, tk_problem *p)
{
    json_error_t jerr;
    json_t *doc = out->json = json_loadb(body, len, JSON_REJECT_DUPLICATES, &jerr);
    if (!doc)
        return refuse(p, 400, NULL, NULL, "the body is not valid JSON: %s (line %d, column %d)",
                      jerr.text, jerr.line, jerr.column);
    if (!json_is_object(doc))
        return refuse(p, 422, NULL, NULL, "the body must be a JSON object");
    const char *key;
    json_t *value;
    json_object_foreach(doc, key, value)
        if (strcmp(key, "vect") && strcmp(key, "catalogue") && strcmp(key, "name") &&
            strcmp(key, "options") && strcmp(key, "constraints"))
            return refuse(p, 422, "field", key, "unknown field '%.60s' (expected vect or "
                          "catalogue, name, options, constraints)", key);
    json_t *constraints = json_object_get(doc, "constraints"), *one;
    size_t k;
    if (constraints && (!json_is_array(constraints) || json_array_size(constraints) > TK_PIN_MOST))
        return refuse(p, 422, "field", "constraints", "'constraints' must be an array of at "
                      "most %d strings", TK_PIN_MOST);
    json_array_foreach(constraints, k, one)
        if (!json_is_string(one))
            return refuse(p, 422, "field", "constraints", "'constraints' must be an array of "
                          "strings (COMP:VERTEX=KIND, as tightknot tighten --constrain)");
    out->constraints = constraints;
    json_t *vect = json_object_get(doc, "vect"), *cat = json_object_get(doc, "catalogue");
    json_t *name = json_object_get(doc, "name"), *options = json_object_get(doc, "options");
    if (!vect == !cat)
        return refuse(p, 422, NULL, NULL, "give exactly one of 'vect' (the VECT text) and "
                      "'catalogue' (a knot name from GET /v1/catalogue)");
    const char *bad = vect && !json_is_string(vect)     ? "vect"
                      : cat && !json_is_string(cat)     ? "catalogue"
                      : name && !json_is_string(name)   ? "name"
                                                        : NULL;
    if (bad)
        return refuse(p, 422, "field", bad, "'%s' must be a string", bad);
    int rc = name || cat ? set_name(out, name ? name : cat, p) : TK_OK;
    tk_error err;
    if (!rc && options && tk_job_options_from_json(&out->options, options, &bad, &err))
        return refuse(p, 422, bad ? "option" : NULL, bad, "%s", err.message);
    out->vect = json_string_value(vect);
    out->len = json_string_length(vect);
    out->catalogue = json_string_value(cat);
    return rc;
}

int tk_submission_decode(const char *content_type, const tk_query_pair *query, size_t nquery,
                         const char *body, size_t len, tk_submission *out, tk_problem *p)
{
    memset(p, 0, sizeof *p);
    *out = (tk_submission){.name = "untitled", .options = TK_JOB_OPTIONS_INIT,
                           .vect = body ? body : "", .len = body ? len : 0};
    int rc = TK_OK;
    tk_error err;
    bool json = media_is(content_type, "application/json");
    if (json) {
        rc = decode_json(body ? body : "", len, out, p);
    } else if (!media_is(content_type, "text/plain")) {
        rc = refuse(p, 415, NULL, NULL, "send application/json ({\"vect\": ...} or "
                    "{\"catalogue\": ...}) or text/plain (a VECT file, options in the query); "
                    "got %.80s", content_type ? content_type : "no Content-Type");
    }
    for (size_t i = 0; !rc && !json && i < nquery; i++) { /* a text body's name and options */
        const char *key = query[i].key, *value = query[i].value ? query[i].value : "";
        if (query[i].nul) {
            rc = refuse(p, 422, "parameter", key, "query parameter '%.60s' holds a NUL byte "
                        "(%%00)", key);
            break;
        }
        json_t *name = strcmp(key, "name") ? NULL : json_string(value);
        if (name) { /* kept with the submission; a later name replaces it */
            json_decref(out->json);
            out->json = json_pack("{s:o}", "name", name);
            rc = set_name(out, json_object_get(out->json, "name"), p);
        } else if (!strcmp(key, "name")) {
            rc = refuse(p, 422, "field", "name", "'name' must be text (UTF-8, no control "
                        "character) under 128 bytes");
        } else if (tk_job_option_set_text(&out->options, key, value, &err)) {
            rc = refuse(p, 422, "option", key, "%s", err.message);
        }
    }
    if (rc)
        tk_submission_clear(out);
    return rc;
}

int tk_submission_pins(const tk_submission *s, tk_curve *c, char **input, tk_problem *p)
{
    *input = NULL;
    json_t *one;
    size_t k;
    tk_error err;
    json_array_foreach(s->constraints, k, one) {
        tk_pin pin;
        bool at_vertex;
        const char *text = json_string_value(one);
        if (tk_pin_parse(text, &pin, &at_vertex, &err) ||
            tk_curve_pin_add(c, &pin, at_vertex, &err))
            return refuse(p, err.code == TK_ENOMEM ? 503 : 422, "constraint", text, "%s",
                          err.message);
    }
    if (c->npins) {
        /* as tk_run_new will (a rounding off is closed there, farther is
         * refused), the curve left as sent */
        double shortest;
        tk_curve_edge_range(c, &shortest, NULL);
        if (tk_curve_pins_check(c, TK_PIN_SETTLE * shortest, &err))
            return refuse(p, 422, "field", "constraints", "%s", err.message);
    }
    if (json_array_size(s->constraints) && tk_vect_to_string(c, input, NULL, &err))
        return refuse(p, 503, NULL, NULL, "%s", err.message);
    return TK_OK;
}

void tk_submission_clear(tk_submission *s)
{
    json_decref(s->json);
    *s = (tk_submission){NULL};
}
