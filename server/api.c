/* tightknot service: the HTTP routes (see api.h and openapi.yaml). */
#define _GNU_SOURCE
#include "api.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <limits.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <microhttpd.h>

#include "jsonmap.h"
#include "tk/vect.h"

typedef enum MHD_Result result;
typedef struct MHD_Connection conn;

typedef struct entry {
    char *name; /* the file's name without .vect */
    size_t components, vertices;
} entry;

struct tk_api {
    tk_api_config cfg;
    char *tls_cert, *tls_key; /* PEM, or NULL: plain HTTP */
    char *hosts; /* the hosts served, comma-separated (the browser boundary) */
    char *web;
    entry *entries; /* the catalogue, sorted by name */
    size_t nentries;
    struct MHD_Daemon *daemon;
    tk_pool *pool;
    tk_store *store;
    atomic_bool refusing;
    atomic_size_t held;           /* bytes of request bodies held, all connections */
    pthread_mutex_t guard;        /* over held's changes, holders and watches */
    struct holder *holders;       /* the clients holding bodies, and how much */
    size_t nholders;
    struct watch *watches;        /* every open connection with its deadline */
    pthread_t keeper;             /* cuts those past it (keep_deadlines) */
    bool keeping;
    atomic_bool stopping;
    atomic_ullong responses[4];   /* by class: 2xx .. 5xx */
    time_t started;
};

/* ---- the browser boundary ---- */

/* Whether the comma-separated list holds item (len bytes), ignoring case. */
static bool listed(const char *list, const char *item, size_t len)
{
    for (const char *p = list; p && *p; p += strcspn(p, ",") + (p[strcspn(p, ",")] == ',')) {
        size_t n = strcspn(p, ",");
        if (n == len && !strncasecmp(p, item, len))
            return true;
    }
    return false;
}

/* An allowed other origin the request comes from, or NULL. */
static const char *allowed_origin(const tk_api *a, conn *c)
{
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    return origin && listed(a->cfg.allow_origins, origin, strlen(origin)) ? origin : NULL;
}

/* MHD_get_connection_values's iterator: counts the Host headers. */
static result count_host(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind, (void)value;
    if (!strcasecmp(key, MHD_HTTP_HEADER_HOST))
        (*(int *)cls)++;
    return MHD_YES;
}

/* A page in a browser can send requests to any address, loopback too:
 * with a name of its own that resolves here (DNS rebinding) it can even
 * read the answers.  So the Host a request names must be one this daemon
 * serves, and a request a page sends (it carries an Origin) must come from
 * the daemon's own origin (the page it serves) or one allowed with
 * --allow-origin, scheme and all.  An HTTP/1.1 request names exactly one
 * Host (RFC 9112, 3.2): with none or two, which one a proxy in front and
 * this daemon each read is not the same.  0 when the request may pass,
 * else the status to refuse it with (400, 421 or 403), with why. */
static unsigned boundary(const tk_api *a, conn *c, const char *version, char *why, size_t size)
{
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST);
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    int hosts = 0;
    MHD_get_connection_values(c, MHD_HEADER_KIND, count_host, &hosts);
    if (hosts > 1 || (hosts == 0 && strcmp(version, MHD_HTTP_VERSION_1_0))) {
        snprintf(why, size, "an HTTP/1.1 request names exactly one Host (this one names %d)",
                 hosts);
        return 400;
    }
    if (host) { /* the name without its port; [v6] whole */
        size_t n = host[0] == '[' ? strcspn(host, "]") + 1 : strcspn(host, ":");
        if (!listed(a->hosts, host, n)) {
            snprintf(why, size, "this server does not serve the host '%.*s' (it serves %s; "
                     "name more with --host)", (int)(n < 200 ? n : 200), host, a->hosts);
            return 421;
        }
    }
    /* the daemon's own origin: its scheme, then the Host */
    const char *scheme = a->tls_cert ? "https://" : "http://";
    size_t sn = strlen(scheme);
    if (!origin || (host && !strncasecmp(origin, scheme, sn) && !strcasecmp(origin + sn, host)) ||
        allowed_origin(a, c))
        return 0;
    snprintf(why, size, "requests from pages at '%.200s' are not allowed here (the daemon's "
             "own page is; allow others with --allow-origin)", origin);
    return 403;
}

/* A request's body as it arrives; cap bytes are counted in tk_api.held. */
typedef struct request {
    char *body;
    size_t len, cap;
    bool too_large;
    int crowded; /* 0, or the budget that refused the body: 1 all clients', 2 its client's */
    char client[72]; /* 'n' and the token's name, else 'a' and the address */
    long long due;   /* when its body must be whole (watch.due) */
    const char *who; /* the token's name (with --tokens), else NULL */
    bool admin;
} request;

/* With tokens every request names its client, but a read of health or of
 * the page's files, and a preflight (browsers send no credentials). */
static bool needs_token(const char *url, const char *method)
{
    if (!strcmp(method, "OPTIONS"))
        return false;
    bool api = !strncmp(url, "/v1/", 4) || !strcmp(url, "/v1") || !strcmp(url, "/metrics");
    bool read = !strcmp(method, "GET") || !strcmp(method, "HEAD");
    return !read || (api && strcmp(url, "/v1/health"));
}

/* Whether the client may see the job: without tokens anyone, else its
 * owner and admin names. */
static bool visible(const request *rq, const json_t *doc)
{
    const char *owner = json_string_value(json_object_get(doc, "owner"));
    return !rq->who || rq->admin || (owner && !strcmp(owner, rq->who));
}

/* ---- answers ---- */

/* Sends len bytes (taken) with a type and headers (name, value, ..., NULL). */
static result send_buffer(tk_api *a, conn *c, unsigned status, const char *type, char *buf,
                          size_t len, const char *const *headers)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, buf, MHD_RESPMEM_MUST_FREE);
    if (!r) {
        free(buf);
        return MHD_NO;
    }
    if (type)
        MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    for (size_t i = 0; headers && headers[i]; i += 2)
        MHD_add_response_header(r, headers[i], headers[i + 1]);
    /* no page of another site may frame ours (clickjacking), and no
     * answer is read as another type than it says */
    MHD_add_response_header(r, "Content-Security-Policy", "frame-ancestors 'none'");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    const char *origin = allowed_origin(a, c); /* CORS: that page may read it */
    if (origin) {
        MHD_add_response_header(r, "Access-Control-Allow-Origin", origin);
        MHD_add_response_header(r, MHD_HTTP_HEADER_VARY, "Origin");
    }
    result ret = MHD_queue_response(c, status, r);
    MHD_destroy_response(r);
    if (status >= 200 && status < 600)
        atomic_fetch_add(&a->responses[status / 100 - 2], 1);
    return ret;
}

static result send_json(tk_api *a, conn *c, unsigned status, json_t *o, const char *type,
                        const char *const *headers)
{
    char *text = o ? tk_json_dump(o, false) : NULL;
    json_decref(o);
    if (!text)
        return send_buffer(a, c, 500, "text/plain", strdup("out of memory"), 13, NULL);
    return send_buffer(a, c, status, type ? type : "application/json", text, strlen(text), headers);
}

/* An RFC 9457 problem; `extra` (taken, or NULL) adds members such as
 * "line" or "option". */
__attribute__((format(printf, 6, 7))) static result
problem(tk_api *a, conn *c, unsigned status, json_t *extra, const char *const *headers,
        const char *fmt, ...)
{
    char detail[1024];
    const char *title = MHD_get_reason_phrase_for(status);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    json_t *o = json_pack("{s:s, s:s, s:i, s:o}", "type", "about:blank", "title",
                          title[0] ? title : "Error", "status",
                          (int)status, "detail", tk_json_text(detail));
    json_object_update(o, extra);
    json_decref(extra);
    return send_json(a, c, status, o, "application/problem+json", headers);
}
#define PROBLEM(a, c, status, ...) problem(a, c, status, NULL, NULL, __VA_ARGS__)

/* A problem for an error of the engine or the reader: a VECT error names
 * its line ("line 3: ..."). */
static result input_problem(tk_api *a, conn *c, const tk_error *err)
{
    int line = 0;
    json_t *extra = sscanf(err->message, "line %d", &line) == 1 ? json_pack("{s:i}", "line", line)
                                                                  : NULL;
    return problem(a, c, 422, extra, NULL, "%s", err->message);
}

/* A stored text that does not read back as written: 500, and health says
 * the store is damaged. */
static result damaged(tk_api *a, conn *c, int64_t id, const char *what, const char *why)
{
    char message[TK_ERROR_MESSAGE_SIZE];
    snprintf(message, sizeof message, "the stored %s of job %lld does not read back: %.200s",
             what, (long long)id, why);
    tk_store_damage(a->store, message);
    return PROBLEM(a, c, 500, "%s", message);
}

/* A store that cannot be reached or written (TK_EIO: a database down or
 * restarting, a full disk) is an outage, not a fault of the request or of
 * ours: 503 and when to try again; the store changed nothing. */
static result store_problem(tk_api *a, conn *c, int rc, const tk_error *err)
{
    static const char *const retry[] = {"Retry-After", "5", NULL};
    if (rc == TK_EIO)
        return problem(a, c, 503, NULL, retry, "%s", err->message);
    return PROBLEM(a, c, rc == TK_ENOTFOUND ? 404 : 500, "%s", err->message);
}

/* Reads a whole-number query parameter in [lo, hi] (dflt when absent);
 * false when it is malformed (then *ret is the 400 sent). */
static bool query_count(tk_api *a, conn *c, const char *name, long dflt, long lo, long hi,
                        long *out, result *ret)
{
    const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, name);
    char *end = NULL;
    errno = 0;
    *out = v ? strtol(v, &end, 10) : dflt;
    /* digits only: strtol would take blanks and a sign first */
    if (!v || (v[0] >= '0' && v[0] <= '9' && !errno && !*end && *out >= lo && *out <= hi))
        return true;
    *ret = problem(a, c, 400, json_pack("{s:s}", "parameter", name), NULL,
                   "query parameter '%s' must be a whole number from %ld to %ld", name, lo, hi);
    return false;
}

/* ---- jobs ---- */

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

static result list_jobs(tk_api *a, conn *c, const request *rq)
{
    result ret = MHD_NO;
    long offset, limit;
    if (!query_count(a, c, "offset", 0, 0, LONG_MAX, &offset, &ret) ||
        !query_count(a, c, "limit", 50, 1, 500, &limit, &ret))
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


/* The catalogue entry called name, or NULL. */
static const entry *find_entry(const tk_api *a, const char *name)
{
    for (size_t i = 0; i < a->nentries; i++)
        if (!strcmp(a->entries[i].name, name))
            return &a->entries[i];
    return NULL;
}

/* A file's whole text (NUL-terminated), or NULL. */
static char *slurp(const char *path, size_t *len)
{
    char *text = NULL;
    FILE *f = path ? fopen(path, "rb") : NULL;
    if (f) {
        FILE *out = open_memstream(&text, len);
        char buf[65536];
        size_t n;
        while (out && (n = fread(buf, 1, sizeof buf, f)) > 0)
            fwrite(buf, 1, n, out);
        if (out)
            fclose(out);
        fclose(f);
    }
    return text;
}

static char *read_file(const char *dir, const char *name, const char *suffix, size_t *len)
{
    char *path = NULL;
    char *text = asprintf(&path, "%s/%s%s", dir, name, suffix) < 0 ? NULL : slurp(path, len);
    free(path);
    return text;
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

static result post_job(tk_api *a, conn *c, const request *rq)
{
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
    if (sub.catalogue && a->entries && find_entry(a, sub.catalogue))
        sub.vect = text = read_file(a->cfg.catalogue, sub.catalogue, ".vect", &sub.len);
    if (sub.catalogue && !sub.vect) {
        result ret = problem(a, c, 422, json_pack("{s:s}", "field", "catalogue"), NULL, "%s%.80s%s",
                             a->cfg.catalogue ? "the catalogue has no knot '" : "this server has "
                             "no catalogue (start it with --catalogue)",
                             a->cfg.catalogue ? sub.catalogue : "", a->cfg.catalogue ? "'" : "");
        tk_submission_clear(&sub);
        return ret;
    }
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = a->cfg.max_vertices;
    tk_curve *curve = NULL;
    tk_error err;
    result ret;
    /* what is known without the engine: the text, its limits, the
     * magnitudes the engine measures in, the options together */
    if (tk_vect_parse(sub.vect, sub.len, &limits, &curve, &err) ||
        tk_curve_check_range(curve, &err)) {
        ret = input_problem(a, c, &err);
    } else if (tk_options_check(&sub.options.run, &err)) {
        ret = input_problem(a, c, &err);
    } else if (sub.options.run.vertices > a->cfg.max_vertices) {
        ret = problem(a, c, 422, json_pack("{s:s}", "option", "vertices"), NULL, "option "
                      "'vertices': %zu vertices; the limit is %zu", sub.options.run.vertices,
                      a->cfg.max_vertices);
    } else {
        /* the reader refuses a NUL anywhere: the text is a C string */
        json_t *doc = tk_job_new(sub.name, rq->who, &sub.options, curve->ncomp, curve->nvert);
        char *input = strndup(sub.vect, sub.len);
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

static result cancel_job(tk_api *a, conn *c, int64_t id, const request *rq)
{
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

static result get_struts(tk_api *a, conn *c, const json_t *doc)
{
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

static result get_history(tk_api *a, conn *c, const json_t *doc)
{
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
                                          (json_int_t)tk_job_step(doc), "steps", steps), NULL, NULL);
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

static result get_vect(tk_api *a, conn *c, const json_t *doc)
{
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
                              (json_int_t)tk_job_step(doc), "vect", text, len);
        free(text);
        return send_json(a, c, 200, o, NULL, NULL);
    }
    char name[64];
    snprintf(name, sizeof name, "inline; filename=\"job-%lld.vect\"", (long long)tk_job_id(doc));
    const char *headers[] = {"Content-Disposition", name, NULL};
    return send_buffer(a, c, 200, "text/plain; charset=utf-8", text, len, headers);
}

static result get_frames(tk_api *a, conn *c, const json_t *doc)
{
    result ret = MHD_NO;
    long offset, limit;
    if (!query_count(a, c, "offset", 0, 0, LONG_MAX, &offset, &ret) ||
        !query_count(a, c, "limit", 20, 1, 200, &limit, &ret))
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
    json_t *comps = json_array(), *frames = json_array();
    for (size_t k = 0; k < curve->ncomp; k++)
        json_array_append_new(comps, json_pack("{s:I, s:b}", "vertices", (json_int_t)
                                               tk_curve_comp_vertices(curve, k), "closed",
                                               curve->closed[k]));
    for (size_t i = 0; i < n; i++) {
        json_t *coords = json_array();
        for (size_t k = 0; k < stored[i].count; k++)
            json_array_append_new(coords, tk_json_number(stored[i].xyz[k]));
        json_t *counts = stored[i].layout ? json_loads(stored[i].layout, 0, NULL) : NULL;
        bool own = json_array_size(counts) == curve->ncomp; /* else stored before frames had it */
        json_t *layout = own ? json_array() : json_copy(comps);
        for (size_t k = 0; own && k < curve->ncomp; k++)
            json_array_append_new(layout, json_pack("{s:O, s:b}", "vertices",
                                                    json_array_get(counts, k), "closed",
                                                    curve->closed[k]));
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

/* ---- the service ---- */

static result get_health(tk_api *a, conn *c)
{
    tk_pool_stats s;
    tk_pool_stats_get(a->pool, &s);
    size_t counts[TK_JOB_STATES];
    char reason[TK_ERROR_MESSAGE_SIZE + 64];
    tk_error err;
    /* a store that cannot take jobs: 503 saying why, for a watchdog */
    if (!tk_store_health(a->store, reason, sizeof reason) ||
        (tk_store_counts(a->store, counts, &err) &&
         snprintf(reason, sizeof reason, "%s", err.message)))
        return problem(a, c, 503, json_pack("{s:s}", "health", "degraded"), NULL, "%s", reason);
    return send_json(a, c, 200, json_pack("{s:s, s:I, s:I, s:I, s:I, s:I}", "status", "ok",
                                          "workers", (json_int_t)s.workers, "running",
                                          (json_int_t)s.running, "queued",
                                          (json_int_t)counts[TK_JOB_QUEUED], "queue_limit",
                                          (json_int_t)s.queue_limit, "uptime",
                                          (json_int_t)(time(NULL) - a->started)), NULL, NULL);
}

static result get_metrics(tk_api *a, conn *c)
{
    tk_pool_stats s;
    tk_pool_stats_get(a->pool, &s);
    size_t counts[TK_JOB_STATES];
    tk_error err;
    int rc = tk_store_counts(a->store, counts, &err);
    if (rc)
        return store_problem(a, c, rc, &err);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return MHD_NO;
    fputs("# HELP tightknot_jobs Jobs in the store by state.\n# TYPE tightknot_jobs gauge\n", f);
    for (int i = 0; i < TK_JOB_STATES; i++)
        fprintf(f, "tightknot_jobs{state=\"%s\"} %zu\n", tk_job_states[i], counts[i]);
    const struct { const char *name, *type, *help; double value; } gauges[] = {
        {"queue_length", "gauge", "Jobs waiting for a worker.", (double)counts[TK_JOB_QUEUED]},
        {"queue_limit", "gauge", "Queued jobs beyond which submissions get 429.",
         (double)s.queue_limit},
        {"workers", "gauge", "Worker threads.", (double)s.workers},
        {"workers_busy", "gauge", "Workers running a job.", (double)s.running},
        {"steps_total", "counter", "Flow steps taken since start.", (double)s.steps_total},
        {"steps_per_second", "gauge", "Steps per second over the running jobs.",
         s.steps_per_second},
        {"http_body_bytes_held", "gauge",
         "Bytes of request bodies held now, all connections (at most --max-body-total).",
         (double)atomic_load(&a->held)}};
    for (size_t i = 0; i < sizeof gauges / sizeof gauges[0]; i++)
        fprintf(f, "# HELP tightknot_%s %s\n# TYPE tightknot_%s %s\ntightknot_%s %.17g\n",
                gauges[i].name, gauges[i].help, gauges[i].name, gauges[i].type, gauges[i].name,
                gauges[i].value);
    fputs("# HELP tightknot_http_responses_total HTTP responses by status class.\n"
          "# TYPE tightknot_http_responses_total counter\n", f);
    for (int i = 0; i < 4; i++)
        fprintf(f, "tightknot_http_responses_total{code=\"%dxx\"} %llu\n", i + 2,
                atomic_load(&a->responses[i]));
    fclose(f);
    return send_buffer(a, c, 200, "text/plain; version=0.0.4; charset=utf-8", buf, len, NULL);
}

static result get_catalogue(tk_api *a, conn *c, const char *name)
{
    if (!a->cfg.catalogue)
        return PROBLEM(a, c, 404, "this server has no catalogue (start it with --catalogue)");
    const entry *e = name ? find_entry(a, name) : NULL;
    if (name && !e)
        return PROBLEM(a, c, 404, "the catalogue has no knot '%.80s'", name);
    json_t *list = json_array();
    for (size_t i = 0; !name && i < a->nentries; i++)
        json_array_append_new(list, json_pack("{s:s, s:I, s:I}", "name", a->entries[i].name,
                                              "components", (json_int_t)a->entries[i].components,
                                              "vertices", (json_int_t)a->entries[i].vertices));
    if (!name)
        return send_json(a, c, 200, json_pack("{s:I, s:o}", "count", (json_int_t)a->nentries,
                                              "knots", list), NULL, NULL);
    json_decref(list);
    size_t len = 0;
    char *text = read_file(a->cfg.catalogue, name, ".vect", &len);
    json_t *o = text ? json_pack("{s:s, s:I, s:I, s:s%}", "name", e->name, "components",
                                 (json_int_t)e->components, "vertices", (json_int_t)e->vertices,
                                 "vect", text, len) : NULL;
    free(text);
    if (!o)
        return PROBLEM(a, c, 500, "the catalogue file '%.80s' cannot be read as text", name);
    return send_json(a, c, 200, o, NULL, NULL);
}

static result get_static(tk_api *a, conn *c, const char *url)
{
    static const char *const types[][2] = {
        {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
        {".mjs", "text/javascript; charset=utf-8"}, {".css", "text/css; charset=utf-8"},
        {".svg", "image/svg+xml"}, {".png", "image/png"}, {".json", "application/json"},
        {".vect", "text/plain; charset=utf-8"}, {".txt", "text/plain; charset=utf-8"}};
    if (!a->web)
        return PROBLEM(a, c, 404, "no page here: this server was started without --web");
    const char *rel = strcmp(url, "/") ? url : "/index.html";
    /* plain names below the root: no parent steps, no hidden files (the
     * root is joined as a directory, so no neighbour "web.bak" either) */
    if (rel[0] != '/' || strstr(rel, "/.") || strstr(rel, "..") || strchr(rel, '\\') ||
        strlen(rel) > 512)
        return PROBLEM(a, c, 404, "no such file");
    char path[1200];
    snprintf(path, sizeof path, "%s%s", a->web, rel);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd);
        return PROBLEM(a, c, 404, "no such file: %.200s", url);
    }
    struct MHD_Response *r = MHD_create_response_from_fd((uint64_t)st.st_size, fd);
    const char *dot = strrchr(path, '.'), *type = "application/octet-stream";
    for (size_t i = 0; dot && i < sizeof types / sizeof types[0]; i++)
        type = strcmp(dot, types[i][0]) ? type : types[i][1];
    if (!r) {
        close(fd);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
    result ret = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r);
    atomic_fetch_add(&a->responses[0], 1);
    return ret;
}

/* ---- routing ---- */

static result route(tk_api *a, conn *c, const char *url, const char *method, const request *rq)
{
    bool get = !strcmp(method, "GET") || !strcmp(method, "HEAD");
    const char *allow = "GET";
    if (!strcmp(method, "OPTIONS") && allowed_origin(a, c)) { /* a CORS preflight */
        const char *headers[] = {"Access-Control-Allow-Methods", "GET, POST, DELETE",
                                 "Access-Control-Allow-Headers", "Content-Type, Authorization",
                                 "Access-Control-Max-Age", "600", NULL};
        return send_buffer(a, c, 204, NULL, NULL, 0, headers);
    }
    if (!strcmp(url, "/v1/jobs") && !strcmp(method, "POST"))
        return post_job(a, c, rq);
    if (!strcmp(url, "/v1/jobs")) {
        allow = "GET, POST";
        if (get)
            return list_jobs(a, c, rq);
    } else if (!strncmp(url, "/v1/jobs/", 9)) {
        char *end = NULL;
        errno = 0;
        long long id = url[9] >= '0' && url[9] <= '9' ? strtoll(url + 9, &end, 10) : 0;
        const char *part = end && *end == '/' ? end + 1 : "";
        if (errno || id <= 0 || (*end && *end != '/'))
            return PROBLEM(a, c, 404, "no such resource: %.200s (job ids are positive whole "
                           "numbers)", url);
        static const char *const parts[] = {"", "struts", "vect", "history", "frames"};
        int k = 0;
        while (k < 5 && strcmp(part, parts[k]))
            k++;
        if (k == 5)
            return PROBLEM(a, c, 404, "no such resource: %.200s", url);
        if (k == 0 && !strcmp(method, "DELETE"))
            return cancel_job(a, c, id, rq);
        allow = k ? "GET" : "GET, DELETE";
        json_t *doc = NULL;
        tk_error err;
        int rc = get ? get_job(a, id, &doc, &err) : TK_OK;
        if (!rc && get && !visible(rq, doc)) { /* another name's: not there for this one */
            json_decref(doc);
            rc = tk_error_set(&err, TK_ENOTFOUND, "there is no job %lld", id);
        }
        if (rc)
            return store_problem(a, c, rc, &err);
        if (get) {
            result ret = k == 0 ? send_json(a, c, 200, with_links(json_incref(doc)), NULL, NULL)
                         : k == 1 ? get_struts(a, c, doc)
                         : k == 2 ? get_vect(a, c, doc)
                         : k == 3 ? get_history(a, c, doc)
                                  : get_frames(a, c, doc);
            json_decref(doc);
            return ret;
        }
    } else if (!strcmp(url, "/v1/health") && get) {
        return get_health(a, c);
    } else if (!strcmp(url, "/metrics") && get) {
        return get_metrics(a, c);
    } else if (!strcmp(url, "/v1/catalogue") && get) {
        return get_catalogue(a, c, NULL);
    } else if (!strncmp(url, "/v1/catalogue/", 14) && get) {
        return get_catalogue(a, c, url + 14);
    } else if (!strncmp(url, "/v1/", 4) || !strcmp(url, "/v1")) {
        if (strcmp(url, "/v1/health") && strcmp(url, "/v1/catalogue") &&
            strncmp(url, "/v1/catalogue/", 14))
            return PROBLEM(a, c, 404, "no such resource: %.200s", url);
    } else if (get) {
        return get_static(a, c, url);
    }
    const char *headers[] = {MHD_HTTP_HEADER_ALLOW, allow, NULL};
    return problem(a, c, 405, NULL, headers, "%s is not allowed here; use %s", method, allow);
}

/* ---- one client against the others ---- */

/* The body budget's shares.  A client is the name of the token its
 * request carries (clients behind one address, a NAT, get a share each; a
 * name on many addresses is still one), else its address.  It holds at
 * most a quarter of --max-body-total, or one body of --max-body where that
 * is more: one client holding slow uploads leaves the others three
 * quarters (the probe's four 16 MB uploads took it all), yet can always
 * send one largest body. */
typedef struct holder {
    char client[72];
    size_t bytes;
} holder;

static size_t share(const tk_api *a)
{
    size_t quarter = a->cfg.max_body_total / 4;
    return quarter > a->cfg.max_body + 1 ? quarter : a->cfg.max_body + 1;
}

/* Takes `more` bytes of the budget for rq's client: 0, or the budget that
 * refuses them (request.crowded). */
static int reserve(tk_api *a, const request *rq, size_t more)
{
    pthread_mutex_lock(&a->guard);
    holder *h = a->holders, *end = h + a->nholders;
    while (h < end && strcmp(h->client, rq->client))
        h++;
    int refused = atomic_load(&a->held) + more > a->cfg.max_body_total ? 1
                  : (h < end ? h->bytes : 0) + more > share(a)     ? 2
                                                                   : 0;
    if (!refused && h == end) {
        holder *grown = realloc(a->holders, (a->nholders + 1) * sizeof *grown);
        refused = !grown;
        if (grown) {
            a->holders = grown;
            h = &grown[a->nholders++];
            *h = (holder){.bytes = 0};
            snprintf(h->client, sizeof h->client, "%s", rq->client);
        }
    }
    if (!refused) {
        h->bytes += more;
        atomic_fetch_add(&a->held, more);
    }
    pthread_mutex_unlock(&a->guard);
    return refused;
}

static void release(tk_api *a, const request *rq, size_t bytes)
{
    if (!bytes)
        return;
    pthread_mutex_lock(&a->guard);
    size_t i = 0;
    while (i < a->nholders && strcmp(a->holders[i].client, rq->client))
        i++;
    if (i < a->nholders && !(a->holders[i].bytes -= bytes))
        a->holders[i] = a->holders[--a->nholders];
    atomic_fetch_sub(&a->held, bytes);
    pthread_mutex_unlock(&a->guard);
}

/* rq's client (reserve), once its token is checked. */
static void name_client(conn *c, request *rq)
{
    const union MHD_ConnectionInfo *i = MHD_get_connection_info(c,
                                                                MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    const struct sockaddr_in *in = i ? (const void *)i->client_addr : NULL;
    char addr[INET_ADDRSTRLEN] = "?";
    if (in && in->sin_family == AF_INET)
        inet_ntop(AF_INET, &in->sin_addr, addr, sizeof addr);
    snprintf(rq->client, sizeof rq->client, "%c%s", rq->who ? 'n' : 'a', rq->who ? rq->who : addr);
}

/* Deadlines.  --timeout counts only silence: a client sending a header
 * line every few seconds kept its connection for ever, and 8 addresses x
 * 128 of them held every slot (the probe's F12).  libmicrohttpd 0.9.75
 * has only idle timeouts, and calls us once a head is whole, so we keep
 * them: each connection, watched from its start (NOTIFY_CONNECTION), is
 * due to have its head within --head-timeout of its opening or of its
 * previous answer, then to keep its body up to --min-body-rate (handle),
 * and is due nothing while it is answered.  A thread looks
 * every 200 ms and cuts those past due with shutdown(): libmicrohttpd's
 * thread then reads the end of input and closes the connection as one
 * the client closed (it has no way for us to answer 408 before a head is
 * whole).  A watch leaves the list before libmicrohttpd closes its
 * socket, so under the lock its descriptor is still its own. */
typedef struct watch {
    struct watch *prev, *next;
    int fd;
    atomic_llong due; /* ms of CLOCK_MONOTONIC; 0: none */
} watch;

static long long now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (long long)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* --head-timeout from now (0: none). */
static long long head_due(const tk_api *a)
{
    return a->cfg.head_timeout ? now_ms() + 1000 * (long long)a->cfg.head_timeout : 0;
}

static void set_due(conn *c, long long due)
{
    const union MHD_ConnectionInfo *i = MHD_get_connection_info(c,
                                                                MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    if (i && i->socket_context)
        atomic_store(&((watch *)i->socket_context)->due, due);
}

static void notify(void *cls, conn *c, void **context, enum MHD_ConnectionNotificationCode code)
{
    tk_api *a = cls;
    watch *w = *context;
    const union MHD_ConnectionInfo *fd = MHD_get_connection_info(c,
                                                                 MHD_CONNECTION_INFO_CONNECTION_FD);
    if (code == MHD_CONNECTION_NOTIFY_STARTED && fd && (w = calloc(1, sizeof *w))) {
        w->fd = fd->connect_fd;
        *context = w;
        set_due(c, head_due(a));
        pthread_mutex_lock(&a->guard);
        w->next = a->watches;
        if (a->watches)
            a->watches->prev = w;
        a->watches = w;
        pthread_mutex_unlock(&a->guard);
    } else if (code == MHD_CONNECTION_NOTIFY_CLOSED && w) {
        pthread_mutex_lock(&a->guard);
        *(w->prev ? &w->prev->next : &a->watches) = w->next;
        if (w->next)
            w->next->prev = w->prev;
        pthread_mutex_unlock(&a->guard);
        free(w);
        *context = NULL;
    }
}

static void *keep_deadlines(void *cls)
{
    tk_api *a = cls;
    while (!atomic_load(&a->stopping)) {
        nanosleep(&(struct timespec){.tv_nsec = 200000000}, NULL);
        long long now = now_ms();
        pthread_mutex_lock(&a->guard);
        for (watch *w = a->watches; w; w = w->next) {
            long long due = atomic_load(&w->due);
            if (due && now > due && !shutdown(w->fd, SHUT_RDWR))
                atomic_store(&w->due, 0);
        }
        pthread_mutex_unlock(&a->guard);
    }
    return NULL;
}

static void drop_body(tk_api *a, request *rq)
{
    release(a, rq, rq->cap);
    free(rq->body);
    rq->body = NULL;
    rq->len = rq->cap = 0;
}

/* Reads a POST's body within max_body, all bodies at once within
 * max_body_total (held uploads cannot take the daemon's memory); skips
 * any other method's body; then answers. */
static result handle(void *cls, conn *c, const char *url, const char *method,
                     const char *version, const char *data, size_t *size, void **con_cls)
{
    tk_api *a = cls;
    request *rq = *con_cls;
    bool post = !strcmp(method, "POST");
    if (!rq) {
        if (!(*con_cls = rq = calloc(1, sizeof *rq)))
            return MHD_NO;
        set_due(c, rq->due = head_due(a)); /* the head is whole: the body's grace */
        char why[600];
        unsigned refused = boundary(a, c, version, why, sizeof why);
        if (refused) /* answered before any body is read */
            return problem(a, c, refused, NULL, NULL, "%s", why);
        if (a->cfg.tokens && needs_token(url, method) &&
            !(rq->who = tk_tokens_check(a->cfg.tokens,
                                        MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                                    MHD_HTTP_HEADER_AUTHORIZATION),
                                        &rq->admin))) {
            const char *headers[] = {MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"tightknot\"",
                                     NULL};
            return problem(a, c, 401, NULL, headers, "this server needs a token: send "
                           "'Authorization: Bearer TOKEN' (one of its --tokens file)");
        }
        name_client(c, rq);
        const char *length = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                         MHD_HTTP_HEADER_CONTENT_LENGTH);
        rq->too_large = post && length && strtoull(length, NULL, 10) > a->cfg.max_body;
        if (!rq->too_large && !atomic_load(&a->refusing))
            return MHD_YES;
    } else if (*size > 0) {
        /* each byte buys 1/rate s, never more than --head-timeout in hand:
         * a body keeps the rate over every such span (an average since
         * the start would let a fast start buy hours of trickle) */
        long long most = head_due(a);
        rq->due = a->cfg.min_body_rate ? rq->due + (long long)(*size * 1000 / a->cfg.min_body_rate)
                                       : 0;
        set_due(c, rq->due = rq->due < most ? rq->due : most);
        if (post && !rq->too_large && rq->len + *size > a->cfg.max_body) {
            rq->too_large = true;
            drop_body(a, rq);
        }
        if (post && !rq->too_large && !rq->crowded && rq->len + *size + 1 > rq->cap) {
            size_t cap = rq->cap ? rq->cap : 65536;
            while (cap < rq->len + *size + 1)
                cap *= 2;
            cap = cap > a->cfg.max_body + 1 ? a->cfg.max_body + 1 : cap; /* never needs more */
            size_t more = cap - rq->cap;
            rq->crowded = reserve(a, rq, more);
            char *grown = rq->crowded ? NULL : realloc(rq->body, cap);
            if (!grown) {
                if (!rq->crowded) { /* out of memory: as if the budget were */
                    release(a, rq, more);
                    rq->crowded = 1;
                }
                drop_body(a, rq);
            } else {
                rq->body = grown;
                rq->cap = cap;
            }
        }
        if (post && !rq->too_large && !rq->crowded) {
            memcpy(rq->body + rq->len, data, *size);
            rq->len += *size;
            rq->body[rq->len] = '\0';
        }
        *size = 0;
        return MHD_YES;
    }
    set_due(c, 0); /* answered at the client's pace (--timeout) */
    if (atomic_load(&a->refusing)) {
        const char *headers[] = {MHD_HTTP_HEADER_RETRY_AFTER, "10", NULL};
        return problem(a, c, 503, NULL, headers, "the service is shutting down");
    }
    if (rq->too_large)
        return PROBLEM(a, c, 413, "the request body is larger than the limit of %zu bytes",
                       a->cfg.max_body);
    if (rq->crowded) {
        const char *headers[] = {MHD_HTTP_HEADER_RETRY_AFTER, "5", NULL};
        if (rq->crowded == 2)
            return problem(a, c, 503, NULL, headers, "too many uploads at once from one client "
                           "(%s): its others hold the %zu bytes one client may; try again when "
                           "they end", rq->who ? "this name" : "this address", share(a));
        return problem(a, c, 503, NULL, headers, "too many uploads at once (%zu bytes held): "
                       "try again shortly", a->cfg.max_body_total);
    }
    return route(a, c, url, method, rq);
}

static void request_done(void *cls, conn *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)toe;
    set_due(c, head_due(cls)); /* the next request's head, on a kept connection */
    if (*con_cls) {
        drop_body(cls, *con_cls);
        free(*con_cls);
        *con_cls = NULL;
    }
}

/* ---- submissions ---- */

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
            strcmp(key, "options"))
            return refuse(p, 422, "field", key, "unknown field '%.60s' (expected vect or "
                          "catalogue, name, options)", key);
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

void tk_submission_clear(tk_submission *s)
{
    json_decref(s->json);
    *s = (tk_submission){NULL};
}

/* ---- start and stop ---- */

static int by_name(const void *x, const void *y)
{
    return strcmp(((const entry *)x)->name, ((const entry *)y)->name);
}

/* Reads the catalogue's *.vect files once (a file that does not parse is
 * left out). */
static void load_catalogue(tk_api *a)
{
    DIR *d = opendir(a->cfg.catalogue);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        size_t n = strlen(e->d_name), len = 0;
        if (n < 6 || strcmp(e->d_name + n - 5, ".vect") || e->d_name[0] == '.')
            continue;
        char *name = strndup(e->d_name, n - 5);
        char *text = name ? read_file(a->cfg.catalogue, name, ".vect", &len) : NULL;
        tk_curve *curve = NULL;
        entry *grown = text && !tk_vect_parse(text, len, NULL, &curve, NULL)
                           ? realloc(a->entries, (a->nentries + 1) * sizeof *grown)
                           : NULL;
        if (grown) {
            a->entries = grown;
            a->entries[a->nentries++] = (entry){name, curve->ncomp, curve->nvert};
        } else {
            free(name);
        }
        tk_curve_free(&curve);
        free(text);
    }
    if (d)
        closedir(d);
    if (a->entries)
        qsort(a->entries, a->nentries, sizeof *a->entries, by_name);
}

int tk_api_start(const tk_api_config *cfg, tk_pool *pool, tk_store *store, tk_api **out,
                 tk_error *err)
{
    *out = NULL;
    struct sockaddr_in addr = {.sin_family = AF_INET, .sin_port = htons((uint16_t)cfg->port)};
    if (inet_pton(AF_INET, cfg->bind, &addr.sin_addr) != 1)
        return tk_error_set(err, TK_EINVAL, "--bind: '%s' is not an IPv4 address", cfg->bind);
    DIR *probe = cfg->catalogue ? opendir(cfg->catalogue) : NULL;
    if (cfg->catalogue && !probe)
        return tk_error_set(err, TK_EIO, "--catalogue: cannot read %s: %s", cfg->catalogue,
                            strerror(errno));
    if (probe)
        closedir(probe);
    tk_api *a = calloc(1, sizeof *a);
    if (!a)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    *a = (tk_api){.cfg = *cfg, .pool = pool, .store = store, .started = time(NULL)};
    pthread_mutex_init(&a->guard, NULL);
    if (cfg->web && !(a->web = realpath(cfg->web, NULL))) {
        tk_error_set(err, TK_EIO, "--web: cannot use %s: %s", cfg->web, strerror(errno));
        tk_api_stop(&a);
        return TK_EIO;
    }
    if (cfg->catalogue)
        load_catalogue(a);
    /* all interfaces: loopback's names, and those given */
    bool any = !strcmp(cfg->bind, "0.0.0.0");
    if (asprintf(&a->hosts, "%s,localhost%s%s", any ? "127.0.0.1" : cfg->bind,
                 cfg->hosts ? "," : "", cfg->hosts ? cfg->hosts : "") < 0) {
        a->hosts = NULL;
        tk_api_stop(&a);
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    }
    size_t len = 0;
    if (!cfg->tls_cert != !cfg->tls_key ||
        (cfg->tls_cert && (!(a->tls_cert = slurp(cfg->tls_cert, &len)) ||
                           !(a->tls_key = slurp(cfg->tls_key, &len))))) {
        tk_error_set(err, TK_EIO, "--tls-cert and --tls-key: %s", cfg->tls_cert && cfg->tls_key
                     ? "cannot read both files" : "give both, or neither");
        tk_api_stop(&a);
        return TK_EIO;
    }
    struct MHD_OptionItem tls[] = {{MHD_OPTION_HTTPS_MEM_CERT, 0, a->tls_cert},
                                   {MHD_OPTION_HTTPS_MEM_KEY, 0, a->tls_key},
                                   {MHD_OPTION_END, 0, NULL}};
    errno = 0;
    a->daemon = MHD_start_daemon(
        MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | (a->tls_cert ? MHD_USE_TLS : 0), 0,
        NULL, NULL, handle, a, MHD_OPTION_ARRAY, a->tls_cert ? tls : tls + 2,
        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr, MHD_OPTION_THREAD_POOL_SIZE,
        (unsigned)(cfg->threads ? cfg->threads : 2), MHD_OPTION_CONNECTION_LIMIT,
        (unsigned)cfg->max_connections, MHD_OPTION_PER_IP_CONNECTION_LIMIT,
        (unsigned)cfg->max_per_address, MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)cfg->timeout,
        MHD_OPTION_NOTIFY_COMPLETED, request_done, a, MHD_OPTION_LISTEN_BACKLOG_SIZE, 1024,
        MHD_OPTION_NOTIFY_CONNECTION, notify, a, MHD_OPTION_END);
    if (a->daemon && !(a->keeping = !pthread_create(&a->keeper, NULL, keep_deadlines, a))) {
        tk_api_stop(&a);
        return tk_error_set(err, TK_ENOMEM, "cannot start a thread");
    }
    if (!a->daemon) {
        tk_error_set(err, TK_EIO, "cannot listen on %s:%zu: %s", cfg->bind, cfg->port,
                     errno ? strerror(errno)
                           : a->tls_cert ? "the TLS certificate or key was refused"
                                         : "unknown error");
        tk_api_stop(&a);
        return TK_EIO;
    }
    *out = a;
    return TK_OK;
}

unsigned tk_api_port(const tk_api *a)
{
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(a->daemon,
                                                           MHD_DAEMON_INFO_BIND_PORT);
    return info ? info->port : (unsigned)a->cfg.port;
}

const char *tk_api_scheme(const tk_api *a)
{
    return a->tls_cert ? "https" : "http";
}

size_t tk_api_catalogue_size(const tk_api *a)
{
    return a->nentries;
}

void tk_api_refuse(tk_api *a)
{
    atomic_store(&a->refusing, true);
}

void tk_api_stop(tk_api **p)
{
    if (!p || !*p)
        return;
    atomic_store(&(*p)->stopping, true);
    if ((*p)->keeping)
        pthread_join((*p)->keeper, NULL);
    if ((*p)->daemon) /* closes the connections: their watches go */
        MHD_stop_daemon((*p)->daemon);
    free((*p)->holders);
    pthread_mutex_destroy(&(*p)->guard);
    for (size_t i = 0; i < (*p)->nentries; i++)
        free((*p)->entries[i].name);
    free((*p)->entries);
    free((*p)->hosts);
    free((*p)->tls_cert);
    free((*p)->tls_key);
    free((*p)->web);
    free(*p);
    *p = NULL;
}
