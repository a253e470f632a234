/* tightknot service: the HTTP layer (see api.h and http.h): requests
 * read within their limits, answered through the route table; answers and
 * problems; TLS; the daemon started and stopped. */
#define _GNU_SOURCE
#include "http.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "jsonmap.h"

/* ---- answers ---- */

/* Sends len bytes (taken) with a type and headers (name, value, ..., NULL). */
result send_buffer(tk_api *a, conn *c, unsigned status, const char *type, char *buf,
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
    const char *origin = tk_allowed_origin(a, c); /* CORS: that page may read it */
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

result send_json(tk_api *a, conn *c, unsigned status, json_t *o, const char *type,
                        const char *const *headers)
{
    char *text = o ? tk_json_dump(o, false) : NULL;
    json_decref(o);
    if (!text)
        return send_buffer(a, c, 500, "text/plain", strdup("out of memory"), 13, NULL);
    return send_buffer(a, c, status, type ? type : "application/json", text, strlen(text), headers);
}

result problem(tk_api *a, conn *c, unsigned status, json_t *extra, const char *const *headers,
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

/* A store that cannot be reached or written (TK_EIO: a database down or
 * restarting, a full disk) is an outage, not a fault of the request or of
 * ours: 503 and when to try again; the store changed nothing. */
result store_problem(tk_api *a, conn *c, int rc, const tk_error *err)
{
    static const char *const retry[] = {"Retry-After", "5", NULL};
    if (rc == TK_EIO)
        return problem(a, c, 503, NULL, retry, "%s", err->message);
    return PROBLEM(a, c, rc == TK_ENOTFOUND ? 404 : 500, "%s", err->message);
}

bool query_count(tk_api *a, conn *c, const char *name, long dflt, long lo, long hi,
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

char *slurp(const char *path, size_t *len)
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

/* ---- requests ---- */

static void drop_body(tk_api *a, request *rq)
{
    tk_limits_release(a, rq, rq->cap);
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
        tk_limits_due(c, rq->due = tk_limits_head_due(a)); /* the head is whole: the body's grace */
        char why[600];
        unsigned refused = tk_boundary(a, c, version, why, sizeof why);
        if (refused) /* answered before any body is read */
            return problem(a, c, refused, NULL, NULL, "%s", why);
        if (a->cfg.tokens && tk_route_needs_token(method, url) &&
            !(rq->who = tk_tokens_check(a->cfg.tokens,
                                        MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                                    MHD_HTTP_HEADER_AUTHORIZATION),
                                        &rq->admin))) {
            const char *headers[] = {MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"tightknot\"",
                                     NULL};
            return problem(a, c, 401, NULL, headers, "this server needs a token: send "
                           "'Authorization: Bearer TOKEN' (one of its --tokens file)");
        }
        tk_limits_client(c, rq);
        const char *length = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                         MHD_HTTP_HEADER_CONTENT_LENGTH);
        rq->too_large = post && length && strtoull(length, NULL, 10) > a->cfg.max_body;
        if (!rq->too_large && !atomic_load(&a->refusing))
            return MHD_YES;
    } else if (*size > 0) {
        /* each byte buys 1/rate s, never more than --head-timeout in hand:
         * a body keeps the rate over every such span (an average since
         * the start would let a fast start buy hours of trickle) */
        long long most = tk_limits_head_due(a);
        rq->due = a->cfg.min_body_rate ? rq->due + (long long)(*size * 1000 / a->cfg.min_body_rate)
                                       : 0;
        tk_limits_due(c, rq->due = rq->due < most ? rq->due : most);
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
            rq->crowded = tk_limits_reserve(a, rq, more);
            char *grown = rq->crowded ? NULL : realloc(rq->body, cap);
            if (!grown) {
                if (!rq->crowded) { /* out of memory: as if the budget were */
                    tk_limits_release(a, rq, more);
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
    tk_limits_due(c, 0); /* answered at the client's pace (--timeout) */
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
                           "they end", rq->who ? "this name" : "this address", tk_limits_share(a));
        return problem(a, c, 503, NULL, headers, "too many uploads at once (%zu bytes held): "
                       "try again shortly", a->cfg.max_body_total);
    }
    return tk_route(a, c, &(call){.rq = rq, .url = url, .method = method});
}

static void request_done(void *cls, conn *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)toe;
    tk_limits_due(c, tk_limits_head_due(cls)); /* the next request's head, on a kept connection */
    if (*con_cls) {
        drop_body(cls, *con_cls);
        free(*con_cls);
        *con_cls = NULL;
    }
}

/* ---- start and stop ---- */

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
    int rc = tk_limits_start(a, err);
    if (rc)
        goto done;
    if (cfg->web && !(a->web = realpath(cfg->web, NULL))) {
        rc = tk_error_set(err, TK_EIO, "--web: cannot use %s: %s", cfg->web, strerror(errno));
        goto done;
    }
    if (cfg->catalogue)
        a->catalogue = tk_catalogue_load(cfg->catalogue);
    /* all interfaces: loopback's names, and those given */
    bool any = !strcmp(cfg->bind, "0.0.0.0");
    if (asprintf(&a->hosts, "%s,localhost%s%s", any ? "127.0.0.1" : cfg->bind,
                 cfg->hosts ? "," : "", cfg->hosts ? cfg->hosts : "") < 0) {
        a->hosts = NULL;
        rc = tk_error_set(err, TK_ENOMEM, "out of memory");
        goto done;
    }
    size_t len = 0;
    if (!cfg->tls_cert != !cfg->tls_key ||
        (cfg->tls_cert && (!(a->tls_cert = slurp(cfg->tls_cert, &len)) ||
                           !(a->tls_key = slurp(cfg->tls_key, &len))))) {
        rc = tk_error_set(err, TK_EIO, "--tls-cert and --tls-key: %s",
                          cfg->tls_cert && cfg->tls_key ? "cannot read both files"
                                                        : "give both, or neither");
        goto done;
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
        MHD_OPTION_NOTIFY_CONNECTION, tk_limits_notify, a, MHD_OPTION_END);
    if (!a->daemon)
        rc = tk_error_set(err, TK_EIO, "cannot listen on %s:%zu: %s", cfg->bind, cfg->port,
                          errno ? strerror(errno)
                                : a->tls_cert ? "the TLS certificate or key was refused"
                                              : "unknown error");
done:
    if (rc)
        tk_api_stop(&a);
    *out = a;
    return rc;
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
    return tk_catalogue_size(a->catalogue);
}

void tk_api_refuse(tk_api *a)
{
    atomic_store(&a->refusing, true);
}

void tk_api_stop(tk_api **p)
{
    if (!p || !*p)
        return;
    if ((*p)->daemon) /* closes the connections: their watches go */
        MHD_stop_daemon((*p)->daemon);
    tk_limits_stop(*p);
    tk_catalogue_free(&(*p)->catalogue);
    free((*p)->hosts);
    free((*p)->tls_cert);
    free((*p)->tls_key);
    free((*p)->web);
    free(*p);
    *p = NULL;
}
