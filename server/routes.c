/* tightknot service: the route table and the jobs' routes (see http.h
 * and openapi.yaml). */
#define _GNU_SOURCE
#include "http.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jsonmap.h"
#include "record.h"
#include "tk/vect.h"

/* Whether the client may see the job: without tokens anyone, else its
 * owner and admin names. */
static bool visible(const request *rq, const json_t *doc)
{
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    return !rq->who || rq->admin || (owner && !strcmp(owner, rq->who));
}

/* A problem for an error of the engine or the reader, with the line a
 * VECT error names ("line 3: ..."). */
static result input_problem(tk_api *a, conn *c, const tk_error *err)
{
    int line = 0;
    json_t *extra = sscanf(err->message, "line %d", &line) == 1 ? json_pack("{s:i}", "line", line)
                                                                  : NULL;
    return problem(a, c, 422, extra, NULL, "%s", err->message);
}

/* A stored text that does not read back: 500, and health says so. */
static result damaged(tk_api *a, conn *c, int64_t id, const char *what, const char *why)
{
    char message[TK_ERROR_MESSAGE_SIZE];
    snprintf(message, sizeof message, "the stored %s of job %lld does not read back: %.200s",
             what, (long long)id, why);
    tk_store_damage(a->store, message);
    return PROBLEM(a, c, 500, "%s", message);
}

/* The job's document as served: with its links. */
static json_t *with_links(json_t *doc)
{
    char self[64];
    snprintf(self, sizeof self, "/v1/jobs/%lld", (long long)tk_job_id(doc));
    json_t *links = json_pack("{s:s}", "self", self);
    const char *parts[] = {"struts", "vect", "history", "frames"};
    for (size_t i = 0; i < 4; i++)
        json_object_set_new(links, parts[i], json_sprintf("%s/%s", self, parts[i]));
    json_object_set_new(doc, "links", links);
    return doc;
}

/* The job as it stands: live from its worker while it runs here. */
static int get_job(tk_api *a, int64_t id, json_t **doc, tk_error *err)
{
    *doc = tk_pool_live(a->pool, id);
    return *doc ? TK_OK : tk_store_get(a->store, id, doc, err);
}

/* The page a listing asks for: ?offset (0 on) and ?limit (1 to most). */
static bool paging(tk_api *a, conn *c, long dflt, long most, long *offset, long *limit,
                   result *ret)
{
    return query_count(a, c, "offset", 0, 0, LONG_MAX, offset, ret) &&
           query_count(a, c, "limit", dflt, 1, most, limit, ret);
}

static result list_jobs(tk_api *a, conn *c, const call *k)
{
    const request *rq = k->rq;
    result ret = MHD_NO;
    long offset, limit;
    if (!paging(a, c, 50, 500, &offset, &limit, &ret))
        return ret;
    const char *name = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "state");
    int state = name ? tk_job_state_of(name) : -1;
    if (name && state < 0)
        return problem(a, c, 400, json_pack("{s:s}", "parameter", "state"), NULL,
                       "query parameter 'state' must be one of queued, running, done, failed, "
                       "cancelled");
    json_t *docs = NULL, *doc;
    size_t total = 0, i;
    tk_error err;
    int rc = tk_store_list(a->store, state, rq->admin ? NULL : rq->who, (size_t)offset,
                           (size_t)limit, &docs, &total, &err);
    if (rc) {
        json_decref(docs);
        return store_problem(a, c, rc, &err);
    }
    json_array_foreach(docs, i, doc) {
        json_t *live = tk_job_state_in(doc) == TK_JOB_RUNNING ? tk_pool_live(a->pool, tk_job_id(doc))
                                                               : NULL;
        json_array_set_new(docs, i, with_links(live ? live : json_incref(doc)));
    }
    return send_json(a, c, 200, json_pack("{s:o, s:I, s:I, s:I}", "jobs", docs, "total",
                                          (json_int_t)total, "offset", (json_int_t)offset,
                                          "limit", (json_int_t)limit), NULL, NULL);
}

typedef struct query_list {
    tk_query_pair pairs[64];
    size_t n;
} query_list;

/* With the lengths, so that a %00 decoded into a key or value shows. */
static result collect(void *cls, enum MHD_ValueKind kind, const char *key, size_t key_size,
                      const char *value, size_t value_size)
{
    (void)kind;
    query_list *q = cls;
    if (q->n < 64)
        q->pairs[q->n] = (tk_query_pair){key, value, strlen(key) != key_size ||
                                                         (value && strlen(value) != value_size)};
    q->n++;
    return MHD_YES;
}

static result post_job(tk_api *a, conn *c, const call *k)
{
    const request *rq = k->rq;
    query_list q = {.n = 0};
    MHD_get_connection_values_n(c, MHD_GET_ARGUMENT_KIND, collect, &q);
    if (q.n > 64)
        return PROBLEM(a, c, 400, "more than 64 query parameters");
    tk_submission sub;
    tk_problem p;
    if (tk_submission_decode(MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                         MHD_HTTP_HEADER_CONTENT_TYPE),
                             q.pairs, q.n, rq->body, rq->len, &sub, &p))
        return problem(a, c, p.status, p.member[0] ? json_pack("{s:s}", p.member, p.value) : NULL,
                       NULL, "%s", p.detail);
    char *text = NULL;
    if (sub.catalogue)
        sub.vect = text = tk_catalogue_text(a->catalogue, a->cfg.catalogue, sub.catalogue,
                                            &sub.len);
    if (sub.catalogue && !sub.vect) {
        result ret = problem(a, c, 422, json_pack("{s:s}", "field", "catalogue"), NULL, "%s%.80s%s",
                             a->cfg.catalogue ? "the catalogue has no knot '" : "this server has "
                             "no catalogue (start it with --catalogue)",
                             a->cfg.catalogue ? sub.catalogue : "", a->cfg.catalogue ? "'" : "");
        tk_submission_clear(&sub);
        return ret;
    }
    tk_vect_limits bounds = TK_VECT_LIMITS_INIT;
    bounds.max_vertices = a->cfg.max_vertices;
    tk_curve *curve = NULL;
    char *text_pinned = NULL;
    tk_error err;
    result ret;
    /* what is known without the engine: the text, its limits, the
     * magnitudes the engine measures in, the options together */
    if (tk_vect_parse(sub.vect, sub.len, &bounds, &curve, &err) ||
        tk_curve_check_range(curve, &err) || tk_options_check(&sub.options.run, &err)) {
        ret = input_problem(a, c, &err);
    } else if (sub.options.run.vertices > a->cfg.max_vertices) {
        ret = problem(a, c, 422, json_pack("{s:s}", "option", "vertices"), NULL, "option "
                      "'vertices': %zu vertices; the limit is %zu", sub.options.run.vertices,
                      a->cfg.max_vertices);
    } else if (tk_submission_pins(&sub, curve, &text_pinned, &p)) {
        ret = problem(a, c, p.status, p.member[0] ? json_pack("{s:s}", p.member, p.value) : NULL,
                      NULL, "%s", p.detail);
    } else {
        /* the reader refuses a NUL anywhere: the text is a C string */
        json_t *doc = tk_job_new(sub.name, rq->who, &sub.options, curve->ncomp, curve->nvert);
        char *input = text_pinned ? text_pinned : strndup(sub.vect, sub.len);
        text_pinned = NULL;
        int rc = doc && input ? tk_pool_submit(a->pool, doc, input, &err)
                              : tk_error_set(&err, TK_ENOMEM, "out of memory");
        const char *retry[] = {MHD_HTTP_HEADER_RETRY_AFTER, "30", NULL};
        if (rc == TK_EBUSY)
            ret = problem(a, c, atomic_load(&a->refusing) ? 503 : 429, NULL, retry, "%s",
                          err.message);
        else if (rc)
            ret = store_problem(a, c, rc, &err);
        if (!rc) {
            char location[64];
            snprintf(location, sizeof location, "/v1/jobs/%lld", (long long)tk_job_id(doc));
            const char *headers[] = {MHD_HTTP_HEADER_LOCATION, location, NULL};
            ret = send_json(a, c, 202, with_links(json_incref(doc)), NULL, headers);
        }
        json_decref(doc);
        free(input);
    }
    tk_curve_free(&curve);
    free(text);
    tk_submission_clear(&sub);
    return ret;
}

static result cancel_job(tk_api *a, conn *c, const call *k)
{
    const request *rq = k->rq;
    int64_t id = k->id;
    json_t *doc = NULL;
    tk_error err;
    int rc = rq->who ? get_job(a, id, &doc, &err) : TK_OK;
    if (rc)
        return store_problem(a, c, rc, &err);
    /* another name's job is not there for this one, as for GET: neither
     * its existence nor its owner shows */
    bool refused = doc && !visible(rq, doc);
    json_decref(doc);
    if (refused)
        return PROBLEM(a, c, 404, "there is no job %lld", (long long)id);
    rc = tk_pool_cancel(a->pool, id, &doc, &err);
    if (rc == TK_EINVAL && (rc = tk_store_delete(a->store, id, &err)) == TK_OK)
        return send_buffer(a, c, 204, NULL, NULL, 0, NULL); /* ended: it goes */
    if (rc)
        return store_problem(a, c, rc, &err);
    /* a queued job is cancelled now (200), a running one within a step (202) */
    unsigned status = tk_job_state_in(doc) == TK_JOB_CANCELLED ? 200 : 202;
    return send_json(a, c, status, with_links(doc), NULL, NULL);
}

/* A stored part as JSON; NULL with *ret sent when it does not read back. */
static json_t *part_json(tk_api *a, conn *c, int64_t id, tk_part part, const char *what,
                         result *ret, bool *missing)
{
    char *text = NULL;
    size_t len = 0;
    tk_error err;
    int rc = tk_store_part(a->store, id, part, &text, &len, &err);
    json_error_t jerr;
    json_t *o = text ? json_loadb(text, len, 0, &jerr) : NULL;
    *missing = !rc && !text;
    if (rc)
        *ret = store_problem(a, c, rc, &err);
    else if (text && !o)
        *ret = damaged(a, c, id, what, jerr.text);
    free(text);
    return o;
}

static result get_struts(tk_api *a, conn *c, const call *k)
{
    const json_t *doc = k->doc;
    result ret = MHD_NO;
    bool missing;
    json_t *o = part_json(a, c, tk_job_id(doc), TK_PART_CONTACTS, "contacts", &ret, &missing);
    if (missing) /* not measured yet */
        o = json_pack("{s:i, s:n, s:[], s:[], s:[]}", "step", 0, "thickness", "components",
                      "struts", "kinks");
    if (!o)
        return ret;
    json_object_set_new(o, "id", json_integer(tk_job_id(doc)));
    return send_json(a, c, 200, o, NULL, NULL);
}

static result get_history(tk_api *a, conn *c, const call *k)
{
    const json_t *doc = k->doc;
    result ret = MHD_NO;
    bool missing;
    long limit;
    if (!query_count(a, c, "limit", 2000, 2, 2000, &limit, &ret))
        return ret;
    json_t *steps = part_json(a, c, tk_job_id(doc), TK_PART_HISTORY, "history", &ret, &missing);
    if (!steps && !missing)
        return ret;
    steps = json_is_array(steps) ? steps : json_array();
    size_t n = json_array_size(steps);
    if (n > (size_t)limit) { /* at most `limit`, evenly thinned, the last kept */
        json_t *thin = json_array();
        for (size_t i = 0; i < (size_t)limit; i++)
            json_array_append(thin, json_array_get(steps, tk_job_thin(i, n, (size_t)limit)));
        json_decref(steps);
        steps = thin;
    }
    return send_json(a, c, 200, json_pack("{s:I, s:I, s:o}", "id", tk_job_id(doc), "step",
                                          tk_store_step(a->store, doc), "steps", steps), NULL, NULL);
}

/* The job's curve (its input before the run starts), parsed to check it. */
static char *job_curve(tk_api *a, conn *c, const json_t *doc, size_t *len, tk_curve **curve,
                       result *ret)
{
    char *text = NULL;
    tk_error err;
    int rc = tk_store_part(a->store, tk_job_id(doc), TK_PART_CURVE, &text, len, &err);
    if (!rc && !text)
        rc = tk_store_part(a->store, tk_job_id(doc), TK_PART_INPUT, &text, len, &err);
    if (rc)
        *ret = store_problem(a, c, rc, &err);
    else if (tk_vect_parse(text, *len, NULL, curve, &err))
        *ret = damaged(a, c, tk_job_id(doc), "curve", err.message);
    if (!*curve) {
        free(text);
        return NULL;
    }
    return text;
}

static result get_vect(tk_api *a, conn *c, const call *k)
{
    const json_t *doc = k->doc;
    size_t len = 0;
    tk_curve *curve = NULL;
    result ret = MHD_NO;
    char *text = job_curve(a, c, doc, &len, &curve, &ret);
    tk_curve_free(&curve);
    if (!text)
        return ret;
    const char *accept = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_ACCEPT);
    if (accept && strstr(accept, "application/json") && !strstr(accept, "text/plain")) {
        json_t *o = json_pack("{s:I, s:I, s:s%}", "id", tk_job_id(doc), "step",
                              tk_store_step(a->store, doc), "vect", text, len);
        free(text);
        return send_json(a, c, 200, o, NULL, NULL);
    }
    char name[64];
    snprintf(name, sizeof name, "inline; filename=\"job-%lld.vect\"", (long long)tk_job_id(doc));
    const char *headers[] = {"Content-Disposition", name, NULL};
    return send_buffer(a, c, 200, "text/plain; charset=utf-8", text, len, headers);
}

static result get_frames(tk_api *a, conn *c, const call *k)
{
    const json_t *doc = k->doc;
    result ret = MHD_NO;
    long offset, limit;
    if (!paging(a, c, 20, 200, &offset, &limit, &ret))
        return ret;
    /* a page holds at most 10^6 coordinates, however large the knot */
    long per = 3 * (long)json_integer_value(json_object_get(doc, "vertices"));
    if (per > 0 && limit * per > 1000000)
        limit = 1000000 / per > 0 ? 1000000 / per : 1;
    size_t len = 0, n = 0;
    tk_curve *curve = NULL;
    char *text = job_curve(a, c, doc, &len, &curve, &ret);
    if (!text)
        return ret;
    free(text);
    tk_frame *stored = NULL;
    tk_error err;
    int64_t id = tk_job_id(doc);
    if (tk_store_frames(a->store, id, (size_t)offset, (size_t)limit, &stored, &n, &err)) {
        tk_frames_free(stored, n);
        tk_curve_free(&curve);
        return store_problem(a, c, TK_EIO, &err);
    }
    /* a frame's components: its own vertex counts (the run resampled), the
     * curve's closedness */
    json_t *comps = tk_record_components(curve, NULL), *frames = json_array();
    for (size_t i = 0; i < n; i++) {
        json_t *coords = json_array();
        for (size_t j = 0; j < stored[i].count; j++)
            json_array_append_new(coords, tk_json_number(stored[i].xyz[j]));
        json_t *counts = stored[i].layout ? json_loads(stored[i].layout, 0, NULL) : NULL;
        json_t *layout = tk_record_components(curve, counts);
        json_decref(counts);
        json_array_append_new(frames, json_pack("{s:I, s:I, s:o, s:o}", "index", (json_int_t)
                                                offset + (json_int_t)i, "step",
                                                (json_int_t)stored[i].step, "coordinates",
                                                coords, "components", layout));
    }
    tk_curve_free(&curve);
    tk_frames_free(stored, n);
    return send_json(a, c, 200,
                     json_pack("{s:I, s:O, s:I, s:I, s:o, s:o}", "id", id, "total",
                               json_object_get(doc, "frames"), "offset", (json_int_t)offset,
                               "limit", (json_int_t)limit, "components", comps, "frames", frames),
                     NULL, NULL);
}

static result get_one(tk_api *a, conn *c, const call *k)
{
    return send_json(a, c, 200, with_links(json_incref((json_t *)k->doc)), NULL, NULL);
}

/* A CORS preflight, for a page of an origin allowed with --allow-origin. */
static result preflight(tk_api *a, conn *c, const call *k)
{
    (void)k;
    const char *headers[] = {"Access-Control-Allow-Methods", "GET, POST, DELETE",
                             "Access-Control-Allow-Headers", "Content-Type, Authorization",
                             "Access-Control-Max-Age", "600", NULL};
    return send_buffer(a, c, 204, NULL, NULL, 0, headers);
}

/* ---- the route table ---- */

/* One row per operation of openapi.yaml (tests/service/routes.test.mjs
 * holds the two to each other): method, path, operationId, whether it
 * needs a token (with --tokens: all but the page, health and a preflight,
 * which browsers send without credentials), and whether it reads the job
 * first (another name's job is not there).  "/" is the page and every
 * file beside it: any path outside /v1 and /metrics. */
typedef struct route {
    const char *method, *path, *operation;
    handler *fn;
    bool token, job;
} route;

static const route routes[] = {
    {"GET", "/", "getPage", tk_get_static, false, false},
    {"OPTIONS", "/v1/jobs", "preflightJobs", preflight, false, false},
    {"GET", "/v1/jobs", "listJobs", list_jobs, true, false},
    {"POST", "/v1/jobs", "createJob", post_job, true, false},
    {"OPTIONS", "/v1/jobs/{id}", "preflightJob", preflight, false, false},
    {"GET", "/v1/jobs/{id}", "getJob", get_one, true, true},
    {"DELETE", "/v1/jobs/{id}", "cancelJob", cancel_job, true, false},
    {"GET", "/v1/jobs/{id}/struts", "getJobStruts", get_struts, true, true},
    {"GET", "/v1/jobs/{id}/vect", "getJobVect", get_vect, true, true},
    {"GET", "/v1/jobs/{id}/history", "getJobHistory", get_history, true, true},
    {"GET", "/v1/jobs/{id}/frames", "getJobFrames", get_frames, true, true},
    {"GET", "/v1/catalogue", "listCatalogue", tk_list_catalogue, true, false},
    {"GET", "/v1/catalogue/{name}", "getCatalogueKnot", tk_get_catalogue, true, false},
    {"GET", "/v1/health", "getHealth", tk_get_health, false, false},
    {"GET", "/metrics", "getMetrics", tk_get_metrics, true, false},
};
#define NROUTES (sizeof routes / sizeof routes[0])

static bool api_path(const char *url)
{
    return !strncmp(url, "/v1/", 4) || !strcmp(url, "/v1") || !strcmp(url, "/metrics");
}

/* Whether url is the row's path: {id} one segment, {name} all the rest;
 * *arg the parameter's first byte. */
static bool matches(const route *r, const char *url, const char **arg)
{
    if (!strcmp(r->path, "/"))
        return !api_path(url);
    const char *p = r->path, *u = url;
    while (*p && *p != '{' && *p == *u)
        p++, u++;
    if (*p != '{')
        return !*p && !*u;
    *arg = u;
    u += strncmp(p, "{id}", 4) ? strlen(u) : strcspn(u, "/");
    return !strcmp(p + strcspn(p, "}") + 1, u);
}

/* The row of (method, url), HEAD as GET; NULL when none. */
static const route *find(const char *method, const char *url, const char **arg)
{
    bool get = !strcmp(method, "GET") || !strcmp(method, "HEAD");
    for (size_t i = 0; i < NROUTES; i++)
        if ((get ? !strcmp(routes[i].method, "GET") : !strcmp(routes[i].method, method)) &&
            matches(&routes[i], url, arg))
            return &routes[i];
    return NULL;
}

bool tk_route_needs_token(const char *method, const char *url)
{
    const char *arg;
    const route *r = find(method, url, &arg);
    return r ? r->token : strcmp(method, "OPTIONS") != 0;
}

result tk_route(tk_api *a, conn *c, const call *k)
{
    const char *url = k->url, *arg = NULL;
    call at = *k;
    /* a preflight is answered wherever an allowed page may call */
    if (!strcmp(k->method, "OPTIONS") && tk_allowed_origin(a, c))
        return preflight(a, c, k);
    if (!strncmp(url, "/v1/jobs/", 9)) {
        char *end = NULL;
        errno = 0;
        at.id = url[9] >= '0' && url[9] <= '9' ? strtoll(url + 9, &end, 10) : 0;
        if (errno || at.id <= 0 || (*end && *end != '/'))
            return PROBLEM(a, c, 404, "no such resource: %.200s (job ids are positive whole "
                           "numbers)", url);
    }
    const route *r = strcmp(k->method, "OPTIONS") ? find(k->method, url, &arg) : NULL;
    if (r) {
        json_t *doc = NULL;
        tk_error err;
        int rc = r->job ? get_job(a, at.id, &doc, &err) : TK_OK;
        if (!rc && r->job && !visible(k->rq, doc)) { /* another name's: not there for this one */
            json_decref(doc);
            rc = tk_error_set(&err, TK_ENOTFOUND, "there is no job %lld", (long long)at.id);
        }
        if (rc)
            return store_problem(a, c, rc, &err);
        at.doc = doc;
        at.arg = arg;
        result ret = r->fn(a, c, &at);
        json_decref(doc);
        return ret;
    }
    /* the path's other methods, or none: 405 or 404 */
    char allow[64] = "";
    for (size_t i = 0; i < NROUTES; i++)
        if (strcmp(routes[i].method, "OPTIONS") && matches(&routes[i], url, &arg))
            snprintf(allow + strlen(allow), sizeof allow - strlen(allow), "%s%s",
                     allow[0] ? ", " : "", routes[i].method);
    if (!allow[0])
        return PROBLEM(a, c, 404, "no such resource: %.200s", url);
    const char *headers[] = {MHD_HTTP_HEADER_ALLOW, allow, NULL};
    return problem(a, c, 405, NULL, headers, "%s is not allowed here; use %s", k->method, allow);
}
