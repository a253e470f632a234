/* tightknot service: the HTTP layer (http.c) as the routes and the
 * modules beside them see it: the daemon's state, a request, answers. */
#ifndef TK_SERVER_HTTP_H
#define TK_SERVER_HTTP_H

#include <stdatomic.h>

#include <microhttpd.h>

#include "api.h"

typedef enum MHD_Result result;
typedef struct MHD_Connection conn;
typedef struct catalogue catalogue;
typedef struct limits limits;

struct tk_api {
    tk_api_config cfg;
    char *tls_cert, *tls_key; /* PEM, or NULL: plain HTTP */
    char *hosts; /* the hosts served, comma-separated (the browser boundary) */
    char *web;   /* the page's directory, resolved */
    catalogue *catalogue;
    limits *limits; /* the upload budget's shares and the deadlines (limits.c) */
    struct MHD_Daemon *daemon;
    tk_pool *pool;
    tk_store *store;
    atomic_bool refusing;
    atomic_ullong responses[4]; /* by class: 2xx .. 5xx */
    time_t started;
};

/* A request's body as it arrives, and who sends it. */
typedef struct request {
    char *body;
    size_t len, cap;  /* cap bytes are held in the upload budget (limits.c) */
    bool too_large;
    int crowded;      /* 0, or the budget that refused the body: 1 all clients', 2 its client's */
    char client[72];  /* 'n' and the token's name, else 'a' and the address */
    long long due;    /* when its body must be whole (ms, monotonic) */
    const char *who;  /* the token's name (with --tokens), else NULL */
    bool admin;
} request;

/* A route handler's request, URL, path parameter ({id} as id, {name} as
 * arg) and, for a job's GET, the job. */
typedef struct call {
    const request *rq;
    const char *url, *method, *arg;
    int64_t id;
    const json_t *doc;
} call;
typedef result handler(tk_api *a, conn *c, const call *k);

/* The answer to a request whose head passed the boundary and the token
 * check; whether (method, url) needs a token. */
result tk_route(tk_api *a, conn *c, const call *k);
bool tk_route_needs_token(const char *method, const char *url);

/* Answers: send_buffer takes buf and adds headers (name, value, ...,
 * NULL); problem sends an RFC 9457 problem, `extra` (taken, or NULL)
 * adding members such as "line". */
result send_buffer(tk_api *a, conn *c, unsigned status, const char *type, char *buf, size_t len,
                   const char *const *headers);
result send_json(tk_api *a, conn *c, unsigned status, json_t *o, const char *type,
                 const char *const *headers);
__attribute__((format(printf, 6, 7))) result problem(tk_api *a, conn *c, unsigned status,
                                                     json_t *extra, const char *const *headers,
                                                     const char *fmt, ...);
#define PROBLEM(a, c, status, ...) problem(a, c, status, NULL, NULL, __VA_ARGS__)
/* TK_EIO is an outage: 503 and when to try again; not found 404; else 500. */
result store_problem(tk_api *a, conn *c, int rc, const tk_error *err);
/* A whole-number query parameter in [lo, hi] (dflt when absent); false
 * when malformed, *ret the 400 sent. */
bool query_count(tk_api *a, conn *c, const char *name, long dflt, long lo, long hi, long *out,
                 result *ret);
/* A file's whole text (NUL-terminated), or NULL. */
char *slurp(const char *path, size_t *len);

/* The browser boundary (boundary.c): 0 when the request may pass, else
 * the status (400, 421, 403) and why; the allowed other origin it comes
 * from, or NULL. */
unsigned tk_boundary(const tk_api *a, conn *c, const char *version, char *why, size_t size);
const char *tk_allowed_origin(const tk_api *a, conn *c);

/* Handlers of the page's files (static.c), the catalogue, health and
 * metrics. */
handler tk_get_static, tk_get_catalogue, tk_list_catalogue, tk_get_health, tk_get_metrics;
/* Reads the catalogue's *.vect files once; NULL when there are none. */
catalogue *tk_catalogue_load(const char *dir);
void tk_catalogue_free(catalogue **p);
size_t tk_catalogue_size(const catalogue *cat);
/* Entry name's VECT text (free with free()), or NULL when there is none. */
char *tk_catalogue_text(const catalogue *cat, const char *dir, const char *name, size_t *len);

/* The upload budget and the deadlines (limits.c). */
int tk_limits_start(tk_api *a, tk_error *err);
void tk_limits_stop(tk_api *a);
size_t tk_limits_held(const tk_api *a); /* bytes of bodies held now */
/* Names rq's client, once its token is checked. */
void tk_limits_client(conn *c, request *rq);
/* Takes `more` bytes of the budget for rq's client: 0, or the budget that
 * refuses them. */
int tk_limits_reserve(tk_api *a, const request *rq, size_t more);
void tk_limits_release(tk_api *a, const request *rq, size_t bytes);
size_t tk_limits_share(const tk_api *a); /* what one client may hold */
/* The connection's deadline (ms, monotonic; 0: none); --head-timeout on. */
void tk_limits_due(conn *c, long long due);
long long tk_limits_head_due(const tk_api *a);
/* Watches a connection while it is open. */
void tk_limits_notify(void *cls, conn *c, void **context, enum MHD_ConnectionNotificationCode code);

#endif
