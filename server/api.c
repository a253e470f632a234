/* tightknot: the HTTP API (see include/tk/api.h and openapi.yaml). */
#include "tk/api.h"

#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <netinet/in.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <jansson.h>
#include <microhttpd.h>

#include "tk/jobspec.h"
#include "jsonmap.h"
#include "tk/vect.h"

#include "submission.h"

#define PAGE_LIMIT_DEFAULT 50
#define PAGE_LIMIT_MAX 500
#define FRAMES_LIMIT_DEFAULT 20
#define FRAMES_LIMIT_MAX 200
#define HISTORY_LIMIT_MAX 2000
/* A page of frames holds at most this many coordinates (about 25 MB of
 * JSON), however many vertices the job has. */
#define FRAMES_COORDINATES_MAX 1000000

enum { CLASS_2XX, CLASS_3XX, CLASS_4XX, CLASS_5XX, CLASSES };

struct tk_api {
    tk_api_config cfg;
    char *web;
    struct MHD_Daemon *daemon;
    tk_jobs *jobs;
    tk_store *store;
    atomic_bool refusing;
    atomic_size_t buffered; /* bytes of request bodies held, all connections */
    atomic_ullong requests[CLASSES];
    double started;
};

/* Per-request state: the body as it arrives. */
typedef struct request {
    char *body;
    size_t len, cap;     /* cap bytes are counted in tk_api.buffered */
    bool too_large;
    bool crowded;        /* the bodies held at once reached max_body_total */
} request;

/* Gives back what a request's body held. */
static void drop_body(tk_api *a, request *rq)
{
    atomic_fetch_sub(&a->buffered, rq->cap);
    free(rq->body);
    rq->body = NULL;
    rq->len = rq->cap = 0;
}

typedef enum MHD_Result mhd_result;

static double now_unix(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- responses ---- */

static mhd_result send_buffer(tk_api *a, struct MHD_Connection *c, unsigned status,
                              const char *type, char *data, size_t len,
                              const char *const *headers)
{
    struct MHD_Response *r =
        MHD_create_response_from_buffer(len, data, MHD_RESPMEM_MUST_FREE);
    if (!r) {
        free(data);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    for (size_t i = 0; headers && headers[i]; i += 2)
        MHD_add_response_header(r, headers[i], headers[i + 1]);
    mhd_result ret = MHD_queue_response(c, status, r);
    MHD_destroy_response(r);
    int cls = status >= 500 ? CLASS_5XX : status >= 400 ? CLASS_4XX : status >= 300 ? CLASS_3XX
                                                                                     : CLASS_2XX;
    atomic_fetch_add(&a->requests[cls], 1);
    return ret;
}

static mhd_result send_json_headers(tk_api *a, struct MHD_Connection *c, unsigned status,
                                    json_t *value, const char *type,
                                    const char *const *headers)
{
    char *text = tk_json_dump(value, false);
    json_decref(value);
    if (!text) {
        const char *oom = "{\"type\":\"about:blank\",\"title\":\"Internal Server Error\","
                          "\"status\":500,\"detail\":\"out of memory\"}";
        char *copy = strdup(oom);
        return copy ? send_buffer(a, c, 500, "application/problem+json", copy, strlen(copy), NULL)
                    : MHD_NO;
    }
    return send_buffer(a, c, status, type, text, strlen(text), headers);
}

static mhd_result send_json(tk_api *a, struct MHD_Connection *c, unsigned status,
                            json_t *value)
{
    return send_json_headers(a, c, status, value, "application/json", NULL);
}

static const char *status_title(unsigned status)
{
    switch (status) {
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 406: return "Not Acceptable";
    case 409: return "Conflict";
    case 413: return "Content Too Large";
    case 415: return "Unsupported Media Type";
    case 422: return "Unprocessable Content";
    case 429: return "Too Many Requests";
    case 503: return "Service Unavailable";
    default: return status >= 500 ? "Internal Server Error" : "Bad Request";
    }
}

/* An RFC 9457 problem; `extra` (taken) adds members such as "line" or
 * "option", `headers` extra response headers. */
static mhd_result send_problem_ext(tk_api *a, struct MHD_Connection *c, unsigned status,
                                   json_t *extra, const char *const *headers, const char *fmt,
                                   ...)
{
    char detail[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    json_t *p = json_pack("{s:s, s:s, s:i, s:o}", "type", "about:blank", "title",
                          status_title(status), "status", (int)status, "detail",
                          tk_json_text(detail));
    if (p && extra)
        json_object_update(p, extra);
    json_decref(extra);
    return send_json_headers(a, c, status, p, "application/problem+json", headers);
}

#define send_problem(a, c, status, ...) send_problem_ext(a, c, status, NULL, NULL, __VA_ARGS__)

/* A 422 for an engine or parser error: a VECT error names its line, be it
 * malformed (TK_EPARSE) or over a limit (TK_ELIMIT: too many components or
 * vertices, a count too large), as the reader's messages start "line N:". */
static mhd_result send_input_error(tk_api *a, struct MHD_Connection *c, const tk_error *err,
                                   const char *option)
{
    json_t *extra = json_object();
    int line = 0;
    if ((err->code == TK_EPARSE || err->code == TK_ELIMIT) &&
        sscanf(err->message, "line %d", &line) == 1 && line > 0)
        json_object_set_new(extra, "line", json_integer(line));
    if (option)
        json_object_set_new(extra, "option", json_string(option));
    else if (err->code == TK_EINVAL && strncmp(err->message, "option '", 8) == 0) {
        char name[32];
        if (sscanf(err->message, "option '%31[a-z]'", name) == 1)
            json_object_set_new(extra, "option", json_string(name));
    }
    return send_problem_ext(a, c, 422, extra, NULL, "%s", err->message);
}

/* ---- JSON of a job ---- */

static json_t *json_time(double t)
{
    if (!(t > 0.0))
        return json_null();
    time_t secs = (time_t)t;
    struct tm tm;
    gmtime_r(&secs, &tm);
    char buf[96];
    int ms = (int)((t - (double)secs) * 1000.0);
    if (ms < 0 || ms > 999)
        ms = 999;
    snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
             tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
    return json_string(buf);
}

static json_t *maybe_number(bool known, double x)
{
    return known ? tk_json_number(x) : json_null();
}

/* The job's document; `invariants` (taken) is its stored type. */
static json_t *job_json(const tk_job *j, json_t *invariants)
{
    const tk_step_report *r = &j->latest;
    bool f = j->has_figures;
    char base[64];
    snprintf(base, sizeof base, "/v1/jobs/%lld", (long long)j->id);
    json_t *links = json_object();
    const char *parts[] = {"struts", "vect", "history", "frames"};
    json_object_set_new(links, "self", json_string(base));
    for (size_t i = 0; i < 4; i++) {
        char url[96];
        snprintf(url, sizeof url, "%s/%s", base, parts[i]);
        json_object_set_new(links, parts[i], json_string(url));
    }
    json_t *o = json_object();
    json_object_set_new(o, "id", json_integer((json_int_t)j->id));
    json_object_set_new(o, "name", tk_json_text(j->name));
    json_object_set_new(o, "state", json_string(tk_job_state_name(j->state)));
    json_object_set_new(o, "options", tk_job_options_to_json(&j->options));
    json_object_set_new(o, "progress",
                        json_pack("{s:I, s:o}", "step", (json_int_t)r->step, "fraction",
                                  j->fraction >= 0.0 ? json_real(j->fraction) : json_null()));
    json_object_set_new(o, "ropelength", maybe_number(f, r->ropelength));
    json_object_set_new(o, "length", maybe_number(f, r->length));
    json_object_set_new(o, "thickness", maybe_number(f, r->thickness));
    json_object_set_new(o, "minrad", maybe_number(f, r->minrad));
    json_object_set_new(o, "residual", maybe_number(f && r->step > 0, r->residual));
    json_object_set_new(o, "struts", json_integer((json_int_t)r->struts));
    json_object_set_new(o, "kinks", json_integer((json_int_t)r->kinks));
    json_object_set_new(o, "vertices", json_integer((json_int_t)r->vertices));
    json_object_set_new(o, "components", json_integer((json_int_t)j->components));
    json_object_set_new(o, "seconds", tk_json_number(r->seconds));
    json_object_set_new(o, "step_size", maybe_number(f && r->step > 0, r->step_size));
    json_object_set_new(o, "frames", json_integer((json_int_t)j->frames));
    json_object_set_new(o, "stop_reason",
                        j->stop_reason[0] ? json_string(j->stop_reason) : json_null());
    json_object_set_new(o, "error", j->error[0] ? tk_json_text(j->error) : json_null());
    json_object_set_new(o, "invariants", invariants ? invariants : json_null());
    json_object_set_new(o, "created", json_time(j->created));
    json_object_set_new(o, "started", json_time(j->started));
    json_object_set_new(o, "finished", json_time(j->finished));
    json_object_set_new(o, "links", links);
    return o;
}

/* A stored text that does not read back as written: a 500 naming it, and
 * the store reported damaged (health says so). */
static mhd_result damaged(tk_api *a, struct MHD_Connection *c, const tk_job *job,
                          const char *what, const char *why)
{
    char message[TK_ERROR_MESSAGE_SIZE];
    snprintf(message, sizeof message, "the stored %s of job %lld does not read back: %.200s",
             what, (long long)job->id, why);
    tk_store_report_damage(a->store, message);
    return send_problem(a, c, 500, "%s", message);
}

/* The job's document with its type as the store holds it (written with
 * the figures every few seconds while the job runs, null before it
 * starts, and null when the job was deleted since it was read); false,
 * with a 500 sent, when the store fails or the stored type does not read
 * back. */
static bool job_document(tk_api *a, struct MHD_Connection *c, const tk_job *job, json_t **doc,
                         mhd_result *ret)
{
    char *text = NULL;
    size_t len = 0;
    tk_error err;
    int rc = tk_store_text(a->store, job->id, TK_TEXT_INVARIANTS, &text, &len, &err);
    if (rc && rc != TK_ENOTFOUND) {
        *ret = send_problem(a, c, 500, "%s", err.message);
        return false;
    }
    json_error_t jerr;
    json_t *type = text ? json_loadb(text, len, 0, &jerr) : json_null();
    free(text);
    if (!type) {
        *ret = damaged(a, c, job, "knot type", jerr.text);
        return false;
    }
    *doc = job_json(job, type);
    return true;
}

static mhd_result send_job(tk_api *a, struct MHD_Connection *c, unsigned status,
                           const tk_job *job, const char *const *headers)
{
    json_t *doc = NULL;
    mhd_result ret = MHD_NO;
    if (!job_document(a, c, job, &doc, &ret))
        return ret;
    return send_json_headers(a, c, status, doc, "application/json", headers);
}

/* ---- query parameters ---- */

/* Reads a whole-number query parameter within [lo, hi]; false (and a 400
 * already sent) when malformed. */
static bool query_count(tk_api *a, struct MHD_Connection *c, const char *name, long dflt,
                        long lo, long hi, long *out, mhd_result *ret)
{
    const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, name);
    *out = dflt;
    if (!v)
        return true;
    char *end = NULL;
    errno = 0;
    long n = strtol(v, &end, 10);
    if (errno || end == v || *end || n < lo || n > hi) {
        json_t *extra = json_pack("{s:s}", "parameter", name);
        *ret = send_problem_ext(a, c, 400, extra, NULL,
                                "query parameter '%s' must be a whole number from %ld to %ld",
                                name, lo, hi);
        return false;
    }
    *out = n;
    return true;
}

/* ---- handlers ---- */

static mhd_result get_health(tk_api *a, struct MHD_Connection *c)
{
    tk_jobs_stats s;
    tk_jobs_stats_get(a->jobs, &s);
    char reason[TK_ERROR_MESSAGE_SIZE + 64];
    /* A store that cannot take jobs makes the service unusable: a 503
     * problem saying why, for a load balancer or a watchdog to see. */
    if (!tk_store_health(a->store, reason, sizeof reason))
        return send_problem_ext(a, c, 503, json_pack("{s:s}", "health", "degraded"), NULL, "%s",
                                reason);
    json_t *o = json_pack("{s:s, s:I, s:I, s:I, s:I, s:f}", "status", "ok", "workers",
                          (json_int_t)s.workers, "running", (json_int_t)s.running, "queued",
                          (json_int_t)s.queued, "queue_limit", (json_int_t)s.queue_limit,
                          "uptime", now_unix() - a->started);
    return send_json(a, c, 200, o);
}

static mhd_result get_metrics(tk_api *a, struct MHD_Connection *c)
{
    tk_jobs_stats s;
    tk_jobs_stats_get(a->jobs, &s);
    size_t counts[TK_JOB_STATES];
    tk_error err;
    if (tk_store_count_states(a->store, counts, &err) != TK_OK)
        return send_problem(a, c, 500, "%s", err.message);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return send_problem(a, c, 500, "out of memory");
    fputs("# HELP tightknot_jobs Jobs in the store by state.\n# TYPE tightknot_jobs gauge\n", f);
    for (int i = 0; i < TK_JOB_STATES; i++)
        fprintf(f, "tightknot_jobs{state=\"%s\"} %zu\n", tk_job_state_name((tk_job_state)i),
                counts[i]);
    fprintf(f, "# HELP tightknot_queue_length Jobs waiting for a worker.\n"
               "# TYPE tightknot_queue_length gauge\ntightknot_queue_length %zu\n",
            s.queued);
    fprintf(f, "# HELP tightknot_queue_limit Queued jobs beyond which submissions get 429.\n"
               "# TYPE tightknot_queue_limit gauge\ntightknot_queue_limit %zu\n",
            s.queue_limit);
    fprintf(f, "# HELP tightknot_workers Worker threads.\n# TYPE tightknot_workers gauge\n"
               "tightknot_workers %zu\n",
            s.workers);
    fprintf(f, "# HELP tightknot_workers_busy Workers running a job.\n"
               "# TYPE tightknot_workers_busy gauge\ntightknot_workers_busy %zu\n",
            s.running);
    fprintf(f, "# HELP tightknot_steps_total Flow steps taken since start.\n"
               "# TYPE tightknot_steps_total counter\ntightknot_steps_total %llu\n",
            s.steps_total);
    fprintf(f, "# HELP tightknot_steps_per_second Steps per second over the running jobs.\n"
               "# TYPE tightknot_steps_per_second gauge\ntightknot_steps_per_second %.6g\n",
            s.steps_per_second);
    fprintf(f, "# HELP tightknot_http_body_bytes_held Bytes of request bodies held now, all "
               "connections (at most --max-body-total).\n"
               "# TYPE tightknot_http_body_bytes_held gauge\ntightknot_http_body_bytes_held %zu\n",
            atomic_load(&a->buffered));
    fputs("# HELP tightknot_http_responses_total HTTP responses by status class.\n"
          "# TYPE tightknot_http_responses_total counter\n",
          f);
    const char *cls[CLASSES] = {"2xx", "3xx", "4xx", "5xx"};
    for (int i = 0; i < CLASSES; i++)
        fprintf(f, "tightknot_http_responses_total{code=\"%s\"} %llu\n", cls[i],
                atomic_load(&a->requests[i]));
    if (fclose(f) != 0) {
        free(buf);
        return send_problem(a, c, 500, "out of memory");
    }
    return send_buffer(a, c, 200, "text/plain; version=0.0.4; charset=utf-8", buf, len, NULL);
}

static mhd_result get_catalogue(tk_api *a, struct MHD_Connection *c)
{
    if (!a->cfg.catalogue)
        return send_problem(a, c, 404, "this server has no catalogue (start it with --catalogue)");
    size_t n = 0;
    const tk_catalogue_entry *e = tk_catalogue_entries(a->cfg.catalogue, &n);
    json_t *list = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(list, json_pack("{s:o, s:I, s:I}", "name", tk_json_text(e[i].name),
                                              "components", (json_int_t)e[i].components,
                                              "vertices", (json_int_t)e[i].vertices));
    return send_json(a, c, 200, json_pack("{s:I, s:o}", "count", (json_int_t)n, "knots", list));
}

static mhd_result get_catalogue_entry(tk_api *a, struct MHD_Connection *c, const char *name)
{
    if (!a->cfg.catalogue)
        return send_problem(a, c, 404, "this server has no catalogue (start it with --catalogue)");
    const tk_catalogue_entry *e = tk_catalogue_find(a->cfg.catalogue, name);
    char *text = NULL;
    size_t len = 0;
    tk_error err;
    if (!e)
        return send_problem(a, c, 404, "the catalogue has no knot '%.80s'", name);
    if (tk_catalogue_read(a->cfg.catalogue, name, &text, &len, &err) != TK_OK)
        return send_problem(a, c, 500, "%s", err.message);
    json_t *o = json_pack("{s:o, s:I, s:I, s:s%}", "name", tk_json_text(e->name), "components",
                          (json_int_t)e->components, "vertices", (json_int_t)e->vertices, "vect",
                          text, len);
    free(text);
    if (!o)
        return send_problem(a, c, 500, "the catalogue file '%.80s' is not UTF-8 text", name);
    return send_json(a, c, 200, o);
}

static mhd_result list_jobs(tk_api *a, struct MHD_Connection *c)
{
    mhd_result ret = MHD_NO;
    long offset, limit;
    if (!query_count(a, c, "offset", 0, 0, LONG_MAX, &offset, &ret) ||
        !query_count(a, c, "limit", PAGE_LIMIT_DEFAULT, 1, PAGE_LIMIT_MAX, &limit, &ret))
        return ret;
    const char *state_name = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "state");
    tk_job_state state = TK_JOB_QUEUED;
    if (state_name && !tk_job_state_parse(state_name, &state))
        return send_problem_ext(a, c, 400, json_pack("{s:s}", "parameter", "state"), NULL,
                                "query parameter 'state' must be one of queued, running, done, "
                                "failed, cancelled");
    tk_job *jobs = NULL;
    size_t n = 0, total = 0;
    tk_error err;
    if (tk_store_list(a->store, state_name != NULL, state, (size_t)offset, (size_t)limit, &jobs,
                      &n, &total, &err) != TK_OK)
        return send_problem(a, c, 500, "%s", err.message);
    json_t *list = json_array();
    for (size_t i = 0; i < n; i++) {
        /* running jobs show their live figures */
        tk_job live;
        if (jobs[i].state == TK_JOB_RUNNING && tk_jobs_get(a->jobs, jobs[i].id, &live, NULL) == 0)
            jobs[i] = live;
        json_t *doc = NULL;
        if (!job_document(a, c, &jobs[i], &doc, &ret)) {
            json_decref(list);
            free(jobs);
            return ret;
        }
        json_array_append_new(list, doc);
    }
    free(jobs);
    return send_json(a, c, 200,
                     json_pack("{s:o, s:I, s:I, s:I}", "jobs", list, "total", (json_int_t)total,
                               "offset", (json_int_t)offset, "limit", (json_int_t)limit));
}

/* Looks a job up; false (with a 404 sent) when there is none. */
static bool find_job(tk_api *a, struct MHD_Connection *c, int64_t id, tk_job *job,
                     mhd_result *ret)
{
    tk_error err;
    int rc = tk_jobs_get(a->jobs, id, job, &err);
    if (rc == TK_OK)
        return true;
    *ret = send_problem(a, c, rc == TK_ENOTFOUND ? 404 : 500, "%s", err.message);
    return false;
}

static bool accepts_json(struct MHD_Connection *c)
{
    const char *accept = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_ACCEPT);
    return accept && strstr(accept, "application/json") && !strstr(accept, "text/plain");
}

static mhd_result get_job_vect(tk_api *a, struct MHD_Connection *c, const tk_job *job)
{
    char *text = NULL;
    size_t len = 0;
    tk_error err;
    int rc = tk_store_text(a->store, job->id, TK_TEXT_CURVE, &text, &len, &err);
    if (!rc && !text) /* not started yet: the input is the current curve */
        rc = tk_store_text(a->store, job->id, TK_TEXT_INPUT, &text, &len, &err);
    if (rc)
        return send_problem(a, c, 500, "%s", err.message);
    /* Every stored curve parsed when it was written: one that does not now
     * was damaged in the store, and is not served as if it were a knot. */
    tk_curve *check = NULL;
    if (text && tk_vect_parse(text, len, NULL, &check, &err) != TK_OK) {
        free(text);
        return damaged(a, c, job, "curve", err.message);
    }
    tk_curve_free(&check);
    if (accepts_json(c)) {
        json_t *o = json_pack("{s:I, s:I, s:s%}", "id", (json_int_t)job->id, "step",
                              (json_int_t)job->latest.step, "vect", text ? text : "", len);
        free(text);
        return send_json(a, c, 200, o);
    }
    char name[TK_JOB_NAME_SIZE + 64];
    snprintf(name, sizeof name, "inline; filename=\"job-%lld.vect\"", (long long)job->id);
    const char *headers[] = {"Content-Disposition", name, NULL};
    return send_buffer(a, c, 200, "text/plain; charset=utf-8", text, len, headers);
}

static mhd_result get_job_text_json(tk_api *a, struct MHD_Connection *c, const tk_job *job,
                                    tk_job_text which)
{
    char *text = NULL;
    size_t len = 0;
    tk_error err;
    if (tk_store_text(a->store, job->id, which, &text, &len, &err) != TK_OK)
        return send_problem(a, c, 500, "%s", err.message);
    json_error_t jerr;
    json_t *doc = text ? json_loadb(text, len, 0, &jerr) : NULL;
    bool broken = text && !doc;
    free(text);
    if (broken)
        return damaged(a, c, job, which == TK_TEXT_CONTACTS ? "contacts" : "history", jerr.text);
    if (which == TK_TEXT_CONTACTS) {
        if (!doc) /* not measured yet */
            doc = json_pack("{s:I, s:n, s:[], s:[], s:[]}", "step", (json_int_t)0, "thickness",
                            "components", "struts", "kinks");
        json_object_set_new(doc, "id", json_integer((json_int_t)job->id));
        return send_json(a, c, 200, doc);
    }
    /* history: at most `limit` entries, evenly thinned, the last kept */
    mhd_result ret = MHD_NO;
    long limit;
    if (!query_count(a, c, "limit", HISTORY_LIMIT_MAX, 2, HISTORY_LIMIT_MAX, &limit, &ret)) {
        json_decref(doc);
        return ret;
    }
    json_t *steps = json_is_array(doc) ? doc : json_array();
    if (steps != doc)
        json_decref(doc);
    size_t n = json_array_size(steps);
    if (n > (size_t)limit) {
        json_t *thin = json_array();
        for (size_t i = 0; i < (size_t)limit; i++) {
            size_t at = (size_t)((double)i * (double)(n - 1) / (double)(limit - 1) + 0.5);
            json_array_append(thin, json_array_get(steps, at));
        }
        json_decref(steps);
        steps = thin;
    }
    return send_json(a, c, 200,
                     json_pack("{s:I, s:I, s:o}", "id", (json_int_t)job->id, "step",
                               (json_int_t)job->latest.step, "steps", steps));
}

static mhd_result get_job_frames(tk_api *a, struct MHD_Connection *c, const tk_job *job)
{
    mhd_result ret = MHD_NO;
    long offset, limit;
    if (!query_count(a, c, "offset", 0, 0, LONG_MAX, &offset, &ret) ||
        !query_count(a, c, "limit", FRAMES_LIMIT_DEFAULT, 1, FRAMES_LIMIT_MAX, &limit, &ret))
        return ret;
    size_t per_frame = 3 * job->latest.vertices;
    if (per_frame > 0 && (size_t)limit * per_frame > FRAMES_COORDINATES_MAX)
        limit = (long)(FRAMES_COORDINATES_MAX / per_frame > 0 ? FRAMES_COORDINATES_MAX / per_frame
                                                               : 1);
    tk_store_frame *stored = NULL;
    size_t n = 0;
    tk_error err;
    if (tk_store_frames(a->store, job->id, (size_t)offset, (size_t)limit, &stored, &n, &err) !=
        TK_OK)
        return send_problem(a, c, 500, "%s", err.message);
    /* the component layout, from the stored curve: a frame has its own
     * vertex counts when the run resampled (coarse to fine,
     * re-resolution), the curve's closed components always */
    json_t *comps = json_array();
    char *text = NULL;
    size_t len = 0;
    tk_curve *curve = NULL;
    if (tk_store_text(a->store, job->id, TK_TEXT_CURVE, &text, &len, NULL) == TK_OK && text &&
        tk_vect_parse(text, len, NULL, &curve, NULL) == TK_OK)
        for (size_t k = 0; k < curve->ncomp; k++)
            json_array_append_new(comps, json_pack("{s:I, s:b}", "vertices",
                                                   (json_int_t)tk_curve_comp_vertices(curve, k),
                                                   "closed", curve->closed[k]));
    free(text);
    json_t *frames = json_array();
    for (size_t i = 0; i < n; i++) {
        json_t *coords = json_array();
        for (size_t k = 0; k < stored[i].count; k++)
            json_array_append_new(coords, tk_json_number(stored[i].xyz[k]));
        json_t *counts = stored[i].layout ? json_loads(stored[i].layout, 0, NULL) : NULL;
        json_t *layout = json_array();
        for (size_t k = 0; k < json_array_size(counts) && curve && k < curve->ncomp; k++)
            json_array_append_new(layout,
                                  json_pack("{s:O, s:b}", "vertices", json_array_get(counts, k),
                                            "closed", curve->closed[k]));
        json_decref(counts);
        json_t *f = json_pack("{s:I, s:I, s:o}", "index", (json_int_t)((size_t)offset + i),
                              "step", (json_int_t)stored[i].step, "coordinates", coords);
        if (!json_array_size(layout)) { /* a frame stored before frames had their own */
            json_decref(layout);
            layout = json_copy(comps);
        }
        json_object_set_new(f, "components", layout);
        json_array_append_new(frames, f);
    }
    tk_curve_free(&curve);
    tk_store_frames_free(stored, n);
    return send_json(a, c, 200,
                     json_pack("{s:I, s:I, s:I, s:I, s:o, s:o}", "id", (json_int_t)job->id,
                               "total", (json_int_t)job->frames, "offset", (json_int_t)offset,
                               "limit", (json_int_t)limit, "components", comps, "frames",
                               frames));
}

static mhd_result cancel_job(tk_api *a, struct MHD_Connection *c, int64_t id)
{
    tk_job job;
    tk_error err;
    int rc = tk_jobs_cancel(a->jobs, id, &job, &err);
    if (rc == TK_EINVAL) {
        /* finished: no worker touches it again, so it can go */
        rc = tk_store_delete(a->store, id, &err);
        if (rc == TK_OK) {
            struct MHD_Response *r = MHD_create_response_from_buffer(0, NULL,
                                                                     MHD_RESPMEM_PERSISTENT);
            if (!r)
                return MHD_NO;
            mhd_result ret = MHD_queue_response(c, 204, r);
            MHD_destroy_response(r);
            atomic_fetch_add(&a->requests[CLASS_2XX], 1);
            return ret;
        }
    }
    if (rc == TK_ENOTFOUND)
        return send_problem(a, c, 404, "%s", err.message);
    if (rc)
        return send_problem(a, c, 500, "%s", err.message);
    /* a queued job is cancelled now (200); a running one stops within a
     * step (202) */
    return send_job(a, c, job.state == TK_JOB_CANCELLED ? 200 : 202, &job, NULL);
}

/* ---- submitting ---- */

/* The query's parameters, in order, for tk_submission_decode. */
typedef struct query_list {
    tk_query_pair *pairs;
    size_t n, cap;
    bool failed;
} query_list;

static mhd_result collect_query(void *cls, enum MHD_ValueKind kind, const char *key,
                                const char *value)
{
    (void)kind;
    query_list *q = cls;
    if (q->n == q->cap) {
        size_t cap = q->cap ? 2 * q->cap : 16;
        tk_query_pair *grown = realloc(q->pairs, cap * sizeof *grown);
        if (!grown) {
            q->failed = true;
            return MHD_NO;
        }
        q->pairs = grown;
        q->cap = cap;
    }
    q->pairs[q->n++] = (tk_query_pair){key, value};
    return MHD_YES;
}

static mhd_result submit(tk_api *a, struct MHD_Connection *c, const char *name,
                         const tk_job_options *opts, const char *vect, size_t len)
{
    tk_error err;
    tk_vect_limits limits = TK_VECT_LIMITS_INIT;
    limits.max_vertices = a->cfg.max_vertices;
    tk_curve *curve = NULL;
    if (tk_vect_parse(vect, len, &limits, &curve, &err) != TK_OK)
        return send_input_error(a, c, &err, NULL);
    /* the reader refuses a NUL anywhere, so the text is a C string */
    tk_job job;
    int rc = tk_jobs_submit(a->jobs, name, opts, curve, vect, &job, &err);
    tk_curve_free(&curve);
    if (rc == TK_EBUSY) {
        const char *headers[] = {MHD_HTTP_HEADER_RETRY_AFTER, "30", NULL};
        return send_problem_ext(a, c, atomic_load(&a->refusing) ? 503 : 429, NULL, headers, "%s",
                                err.message);
    }
    /* The submission starts a run to see that one can start: when the
     * engine cannot make the start feasible (TK_ENUMERIC), or its
     * resampling would change the knot type (TK_ETYPE: too few vertices
     * per unit ropelength), that is this input's doing, not a fault of
     * the service. */
    if (rc == TK_EINVAL || rc == TK_ELIMIT || rc == TK_EPARSE || rc == TK_ENUMERIC ||
        rc == TK_ETYPE)
        return send_input_error(a, c, &err, NULL);
    if (rc)
        return send_problem(a, c, 500, "%s", err.message);
    char location[64];
    snprintf(location, sizeof location, "/v1/jobs/%lld", (long long)job.id);
    const char *headers[] = {MHD_HTTP_HEADER_LOCATION, location, NULL};
    return send_job(a, c, 202, &job, headers);
}

static mhd_result post_job(tk_api *a, struct MHD_Connection *c, const request *rq)
{
    const char *type =
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
    query_list q = {0};
    MHD_get_connection_values(c, MHD_GET_ARGUMENT_KIND, collect_query, &q);
    if (q.failed) {
        free(q.pairs);
        return send_problem(a, c, 500, "out of memory reading the query");
    }
    tk_submission sub;
    tk_submission_problem p;
    int rc = tk_submission_decode(type, q.pairs, q.n, rq->body, rq->len, a->cfg.catalogue,
                                  &sub, &p);
    free(q.pairs);
    if (rc) {
        if (p.status == 0)
            return send_problem(a, c, 500, "%s", p.detail);
        json_t *extra = p.member[0] ? json_pack("{s:s}", p.member, p.value) : NULL;
        return send_problem_ext(a, c, p.status, extra, NULL, "%s", p.detail);
    }
    mhd_result ret = submit(a, c, sub.name, &sub.options, sub.vect, sub.len);
    tk_submission_clear(&sub);
    return ret;
}

/* ---- the page's files ---- */

static const char *content_type_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    if (!dot)
        return "application/octet-stream";
    if (!strcmp(dot, ".html"))
        return "text/html; charset=utf-8";
    if (!strcmp(dot, ".js") || !strcmp(dot, ".mjs"))
        return "text/javascript; charset=utf-8";
    if (!strcmp(dot, ".css"))
        return "text/css; charset=utf-8";
    if (!strcmp(dot, ".svg"))
        return "image/svg+xml";
    if (!strcmp(dot, ".png"))
        return "image/png";
    if (!strcmp(dot, ".json"))
        return "application/json";
    if (!strcmp(dot, ".vect") || !strcmp(dot, ".txt"))
        return "text/plain; charset=utf-8";
    return "application/octet-stream";
}

static mhd_result get_static(tk_api *a, struct MHD_Connection *c, const char *url)
{
    if (!a->web)
        return send_problem(a, c, 404, "no page here: this server was started without --web");
    const char *rel = strcmp(url, "/") == 0 ? "/index.html" : url;
    /* Plain names below the root only: the path must start with its own
     * separator (the root is joined to it as a directory, so ".bak/x" never
     * reaches a neighbour "web.bak"), with no parent steps and no hidden
     * files. */
    if (rel[0] != '/' || strstr(rel, "/.") || strstr(rel, "..") || strchr(rel, '\\') ||
        strlen(rel) > 512)
        return send_problem(a, c, 404, "no such file");
    char path[1200];
    snprintf(path, sizeof path, "%s%s", a->web, rel);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd);
        return send_problem(a, c, 404, "no such file: %.200s", url);
    }
    struct MHD_Response *r = MHD_create_response_from_fd((uint64_t)st.st_size, fd);
    if (!r) {
        close(fd);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, content_type_of(path));
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
    mhd_result ret = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r);
    atomic_fetch_add(&a->requests[CLASS_2XX], 1);
    return ret;
}

/* ---- routing ---- */

static mhd_result method_not_allowed(tk_api *a, struct MHD_Connection *c, const char *allow,
                                     const char *method)
{
    const char *headers[] = {MHD_HTTP_HEADER_ALLOW, allow, NULL};
    return send_problem_ext(a, c, 405, NULL, headers, "%s is not allowed here; use %s", method,
                            allow);
}

/* Parses "/v1/jobs/{id}[/part]"; false when the id is not a number. */
static bool parse_job_path(const char *rest, int64_t *id, const char **part)
{
    char *end = NULL;
    if (!isdigit((unsigned char)rest[0]))
        return false;
    errno = 0;
    long long n = strtoll(rest, &end, 10);
    if (errno || n <= 0)
        return false;
    *id = n;
    if (*end == '\0') {
        *part = "";
        return true;
    }
    if (*end != '/')
        return false;
    *part = end + 1;
    return true;
}

static mhd_result route(tk_api *a, struct MHD_Connection *c, const char *url,
                        const char *method, const request *rq)
{
    bool get = !strcmp(method, "GET") || !strcmp(method, "HEAD");
    if (!strcmp(url, "/v1/health"))
        return get ? get_health(a, c) : method_not_allowed(a, c, "GET", method);
    if (!strcmp(url, "/metrics"))
        return get ? get_metrics(a, c) : method_not_allowed(a, c, "GET", method);
    if (!strcmp(url, "/v1/catalogue"))
        return get ? get_catalogue(a, c) : method_not_allowed(a, c, "GET", method);
    if (!strncmp(url, "/v1/catalogue/", 14))
        return get ? get_catalogue_entry(a, c, url + 14) : method_not_allowed(a, c, "GET", method);
    if (!strcmp(url, "/v1/jobs")) {
        if (get)
            return list_jobs(a, c);
        if (!strcmp(method, "POST"))
            return post_job(a, c, rq);
        return method_not_allowed(a, c, "GET, POST", method);
    }
    if (!strncmp(url, "/v1/jobs/", 9)) {
        int64_t id = 0;
        const char *part = NULL;
        if (!parse_job_path(url + 9, &id, &part))
            return send_problem(a, c, 404, "no such resource: %.200s (job ids are positive "
                                           "whole numbers)",
                                url);
        bool known = !*part || !strcmp(part, "struts") || !strcmp(part, "vect") ||
                     !strcmp(part, "history") || !strcmp(part, "frames");
        if (!known)
            return send_problem(a, c, 404, "no such resource: %.200s", url);
        if (!*part && !strcmp(method, "DELETE"))
            return cancel_job(a, c, id);
        if (!get)
            return method_not_allowed(a, c, *part ? "GET" : "GET, DELETE", method);
        tk_job job;
        mhd_result ret = MHD_NO;
        if (!find_job(a, c, id, &job, &ret))
            return ret;
        if (!*part)
            return send_job(a, c, 200, &job, NULL);
        if (!strcmp(part, "struts"))
            return get_job_text_json(a, c, &job, TK_TEXT_CONTACTS);
        if (!strcmp(part, "history"))
            return get_job_text_json(a, c, &job, TK_TEXT_HISTORY);
        if (!strcmp(part, "vect"))
            return get_job_vect(a, c, &job);
        return get_job_frames(a, c, &job);
    }
    if (!strncmp(url, "/v1/", 4) || !strcmp(url, "/v1"))
        return send_problem(a, c, 404, "no such resource: %.200s", url);
    return get ? get_static(a, c, url) : method_not_allowed(a, c, "GET", method);
}

static mhd_result handle(void *cls, struct MHD_Connection *c, const char *url,
                         const char *method, const char *version, const char *upload_data,
                         size_t *upload_data_size, void **con_cls)
{
    (void)version;
    tk_api *a = cls;
    request *rq = *con_cls;
    /* only POST reads its body; any other method's body is skipped */
    bool wants_body = !strcmp(method, "POST");
    if (!rq) {
        rq = calloc(1, sizeof *rq);
        if (!rq)
            return MHD_NO;
        *con_cls = rq;
        /* refuse a declared oversized body before reading it */
        const char *length =
            MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
        if (wants_body && length && strtoull(length, NULL, 10) > a->cfg.max_body)
            rq->too_large = true;
        if (rq->too_large || atomic_load(&a->refusing))
            goto answer;
        return MHD_YES;
    }
    if (*upload_data_size > 0) {
        if (!wants_body) {
            *upload_data_size = 0;
            return MHD_YES;
        }
        if (!rq->too_large && rq->len + *upload_data_size > a->cfg.max_body) {
            rq->too_large = true;
            drop_body(a, rq);
        }
        if (!rq->too_large && !rq->crowded) {
            if (rq->len + *upload_data_size + 1 > rq->cap) {
                size_t cap = rq->cap ? rq->cap : 65536;
                while (cap < rq->len + *upload_data_size + 1)
                    cap *= 2;
                /* Every body is bounded by max_body, and all of them at
                 * once by max_body_total: held uploads cannot take the
                 * daemon's memory, whatever their number. */
                size_t more = cap - rq->cap;
                if (atomic_fetch_add(&a->buffered, more) + more > a->cfg.max_body_total) {
                    atomic_fetch_sub(&a->buffered, more);
                    rq->crowded = true;
                    drop_body(a, rq);
                    *upload_data_size = 0;
                    return MHD_YES;
                }
                char *grown = realloc(rq->body, cap);
                if (!grown) {
                    atomic_fetch_sub(&a->buffered, more);
                    return MHD_NO;
                }
                rq->body = grown;
                rq->cap = cap;
            }
            memcpy(rq->body + rq->len, upload_data, *upload_data_size);
            rq->len += *upload_data_size;
            rq->body[rq->len] = '\0';
        }
        *upload_data_size = 0;
        return MHD_YES;
    }
answer:
    if (atomic_load(&a->refusing)) {
        const char *headers[] = {MHD_HTTP_HEADER_RETRY_AFTER, "10", NULL};
        return send_problem_ext(a, c, 503, NULL, headers, "the service is shutting down");
    }
    if (rq->too_large)
        return send_problem(a, c, 413, "the request body is larger than the limit of %zu bytes",
                            a->cfg.max_body);
    if (rq->crowded) {
        const char *headers[] = {MHD_HTTP_HEADER_RETRY_AFTER, "5", NULL};
        return send_problem_ext(a, c, 503, NULL, headers,
                                "too many uploads at once (%zu bytes held): try again shortly",
                                a->cfg.max_body_total);
    }
    return route(a, c, url, method, rq);
}

static void request_done(void *cls, struct MHD_Connection *c, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    (void)c;
    (void)toe;
    request *rq = *con_cls;
    if (rq) {
        drop_body(cls, rq);
        free(rq);
        *con_cls = NULL;
    }
}

int tk_api_start(const tk_api_config *cfg, tk_jobs *jobs, tk_store *store, tk_api **out,
                 tk_error *err)
{
    *out = NULL;
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)cfg->port);
    if (inet_pton(AF_INET, cfg->bind, &addr.sin_addr) != 1)
        return tk_error_set(err, TK_EINVAL, "--bind: '%s' is not an IPv4 address", cfg->bind);
    tk_api *a = calloc(1, sizeof *a);
    if (!a)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    a->cfg = *cfg;
    a->jobs = jobs;
    a->store = store;
    a->started = now_unix();
    atomic_init(&a->refusing, false);
    atomic_init(&a->buffered, 0);
    for (int i = 0; i < CLASSES; i++)
        atomic_init(&a->requests[i], 0);
    if (cfg->web) {
        a->web = realpath(cfg->web, NULL);
        if (!a->web) {
            free(a);
            return tk_error_set(err, TK_EIO, "--web: cannot use %s: %s", cfg->web,
                                strerror(errno));
        }
    }
    unsigned threads = cfg->threads ? (unsigned)cfg->threads : 2;
    a->daemon = MHD_start_daemon(
        MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL, 0, NULL, NULL, handle, a,
        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr, MHD_OPTION_THREAD_POOL_SIZE, threads,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)cfg->max_connections,
        MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)cfg->max_per_address,
        MHD_OPTION_CONNECTION_TIMEOUT, cfg->timeout, MHD_OPTION_NOTIFY_COMPLETED, request_done,
        a, MHD_OPTION_LISTEN_BACKLOG_SIZE, 1024, MHD_OPTION_END);
    if (!a->daemon) {
        int e = errno;
        free(a->web);
        free(a);
        return tk_error_set(err, TK_EIO, "cannot listen on %s:%u: %s", cfg->bind, cfg->port,
                            e ? strerror(e) : "unknown error");
    }
    *out = a;
    return TK_OK;
}

unsigned tk_api_port(const tk_api *a)
{
    const union MHD_DaemonInfo *info =
        MHD_get_daemon_info(a->daemon, MHD_DAEMON_INFO_BIND_PORT);
    return info ? info->port : a->cfg.port;
}

void tk_api_refuse(tk_api *a)
{
    atomic_store(&a->refusing, true);
}

void tk_api_stop(tk_api **p)
{
    if (!p || !*p)
        return;
    MHD_stop_daemon((*p)->daemon);
    free((*p)->web);
    free(*p);
    *p = NULL;
}
