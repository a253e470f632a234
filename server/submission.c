/* tightknot: decoding a job submission (see submission.h). */
#include "submission.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <jansson.h>

static int refuse(tk_submission_problem *p, unsigned status, const char *member,
                  const char *value, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Fills the problem; returns the error code of its kind. */
static int refuse(tk_submission_problem *p, unsigned status, const char *member,
                  const char *value, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->detail, sizeof p->detail, fmt, ap);
    va_end(ap);
    p->status = status;
    p->code = status == 400 ? TK_EPARSE : TK_EINVAL;
    snprintf(p->member, sizeof p->member, "%s", member ? member : "");
    snprintf(p->value, sizeof p->value, "%s", value ? value : "");
    return p->code;
}

static bool media_is(const char *content_type, const char *media)
{
    if (!content_type)
        return false;
    size_t n = strlen(media);
    return strncasecmp(content_type, media, n) == 0 &&
           (content_type[n] == '\0' || content_type[n] == ';' || content_type[n] == ' ');
}

/* A name is stored and shown as a JSON string: valid UTF-8, no NUL, and
 * short enough for the job record. */
static bool valid_name(const char *name, size_t len)
{
    json_t *probe = json_stringn(name, len);
    json_decref(probe);
    return probe && len < TK_JOB_NAME_SIZE && memchr(name, '\0', len) == NULL;
}

static int set_name(tk_submission *out, const char *name, size_t len, tk_submission_problem *p)
{
    if (!valid_name(name, len))
        return refuse(p, 422, "field", "name",
                      "'name' must be text (UTF-8, no NUL) under %d bytes", TK_JOB_NAME_SIZE);
    memcpy(out->name, name, len);
    out->name[len] = '\0';
    return TK_OK;
}

static int take_text(tk_submission *out, const char *text, size_t len, tk_submission_problem *p)
{
    out->vect = malloc(len + 1);
    if (!out->vect) {
        p->status = 0;
        p->code = TK_ENOMEM;
        snprintf(p->detail, sizeof p->detail, "out of memory for a body of %zu bytes", len);
        return TK_ENOMEM;
    }
    memcpy(out->vect, text, len);
    out->vect[len] = '\0';
    out->len = len;
    return TK_OK;
}

static int decode_json(const char *body, size_t len, const tk_catalogue *catalogue,
                       tk_submission *out, tk_submission_problem *p)
{
    json_error_t jerr;
    json_t *doc = json_loadb(body, len, JSON_REJECT_DUPLICATES, &jerr);
    if (!doc)
        return refuse(p, 400, NULL, NULL, "the body is not valid JSON: %s (line %d, column %d)",
                      jerr.text, jerr.line, jerr.column);
    int rc = TK_OK;
    const char *key;
    json_t *value;
    if (!json_is_object(doc)) {
        rc = refuse(p, 422, NULL, NULL, "the body must be a JSON object");
        goto done;
    }
    json_object_foreach(doc, key, value) {
        if (strcmp(key, "vect") && strcmp(key, "catalogue") && strcmp(key, "name") &&
            strcmp(key, "options")) {
            rc = refuse(p, 422, "field", key,
                        "unknown field '%.60s' (expected vect or catalogue, name, options)", key);
            goto done;
        }
    }
    json_t *vect = json_object_get(doc, "vect");
    json_t *cat = json_object_get(doc, "catalogue");
    json_t *name = json_object_get(doc, "name");
    json_t *options = json_object_get(doc, "options");
    if ((vect != NULL) == (cat != NULL)) {
        rc = refuse(p, 422, NULL, NULL,
                    "give exactly one of 'vect' (the VECT text) and 'catalogue' (a knot name "
                    "from GET /v1/catalogue)");
        goto done;
    }
    const char *bad_field = vect && !json_is_string(vect)  ? "vect"
                            : cat && !json_is_string(cat) ? "catalogue"
                            : name && !json_is_string(name) ? "name"
                                                            : NULL;
    if (bad_field) {
        rc = refuse(p, 422, "field", bad_field, "'%s' must be a string", bad_field);
        goto done;
    }
    if (name)
        rc = set_name(out, json_string_value(name), json_string_length(name), p);
    else if (cat)
        rc = set_name(out, json_string_value(cat), json_string_length(cat), p);
    else
        rc = set_name(out, "untitled", 8, p);
    if (rc)
        goto done;
    tk_error err;
    const char *bad = NULL;
    if (options && tk_job_options_from_json(&out->options, options, &bad, &err) != TK_OK) {
        rc = refuse(p, 422, bad ? "option" : NULL, bad, "%s", err.message);
        goto done;
    }
    if (vect) {
        rc = take_text(out, json_string_value(vect), json_string_length(vect), p);
    } else if (!catalogue) {
        rc = refuse(p, 422, "field", "catalogue",
                    "this server has no catalogue (start it with --catalogue)");
    } else {
        char *text = NULL;
        size_t n = 0;
        int found = tk_catalogue_read(catalogue, json_string_value(cat), &text, &n, &err);
        if (found == TK_ENOTFOUND) {
            rc = refuse(p, 422, "field", "catalogue", "%s", err.message);
        } else if (found) {
            p->status = 0;
            p->code = rc = found;
            snprintf(p->detail, sizeof p->detail, "%s", err.message);
        } else {
            out->vect = text;
            out->len = n;
        }
    }
done:
    json_decref(doc);
    return rc;
}

static int decode_text(const tk_query_pair *query, size_t nquery, const char *body, size_t len,
                       tk_submission *out, tk_submission_problem *p)
{
    int rc = set_name(out, "untitled", 8, p);
    for (size_t i = 0; !rc && i < nquery; i++) {
        const char *key = query[i].key, *value = query[i].value ? query[i].value : "";
        if (!strcmp(key, "name")) {
            rc = set_name(out, value, strlen(value), p);
            continue;
        }
        /* an unknown query parameter is an unknown option, named as in JSON */
        tk_error err;
        if (tk_job_option_set_text(&out->options, key, value, &err) != TK_OK)
            rc = refuse(p, 422, "option", key, "%s", err.message);
    }
    return rc ? rc : take_text(out, body, len, p);
}

int tk_submission_decode(const char *content_type, const tk_query_pair *query, size_t nquery,
                         const char *body, size_t len, const tk_catalogue *catalogue,
                         tk_submission *out, tk_submission_problem *problem)
{
    memset(out, 0, sizeof *out);
    memset(problem, 0, sizeof *problem);
    tk_job_options defaults = TK_JOB_OPTIONS_INIT;
    out->options = defaults;
    if (!body)
        body = "";
    int rc;
    if (media_is(content_type, "application/json"))
        rc = decode_json(body, len, catalogue, out, problem);
    else if (media_is(content_type, "text/plain"))
        rc = decode_text(query, nquery, body, len, out, problem);
    else
        rc = refuse(problem, 415, NULL, NULL,
                    "send application/json ({\"vect\": ...} or {\"catalogue\": ...}) or "
                    "text/plain (a VECT file, options in the query); got %.80s",
                    content_type ? content_type : "no Content-Type");
    if (rc)
        tk_submission_clear(out);
    return rc;
}

void tk_submission_clear(tk_submission *s)
{
    free(s->vect);
    s->vect = NULL;
    s->len = 0;
}
