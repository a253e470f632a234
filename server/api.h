/* tightknot service: the HTTP API (openapi.yaml is its contract).
 * Requests never run the engine: POST checks what it can without it (the
 * body, the VECT and its limits, the options' domains) and queues the job.
 */
#ifndef TK_SERVER_API_H
#define TK_SERVER_API_H

#include "auth.h"
#include "pool.h"

typedef struct tk_api_config {
    const char *bind;       /* IPv4 address */
    size_t port;            /* 0: any free one (tk_api_port) */
    size_t max_body;        /* larger bodies get 413 */
    size_t max_body_total;  /* bodies held at once over all connections, one client a
                               quarter or one max_body: 503 beyond */
    size_t max_vertices;    /* larger VECT inputs get 422 */
    size_t max_connections, max_per_address;
    size_t timeout;         /* seconds an idle connection is kept */
    size_t head_timeout;    /* seconds a request's head may take (0: any) */
    size_t min_body_rate;   /* bytes a second a body averages after head_timeout (0: any) */
    size_t threads;         /* threads answering requests */
    const char *web;        /* the page's files, or NULL */
    const char *catalogue;  /* a directory of *.vect offered by name, or NULL */
    const char *hosts;      /* names served besides the bind address and localhost
                               (comma-separated), or NULL */
    const char *allow_origins; /* other origins whose pages may call (comma-separated) */
    const tk_tokens *tokens; /* the clients and their tokens, or NULL: open to anyone */
    const char *tls_cert, *tls_key; /* PEM files: HTTPS; NULL: plain HTTP */
} tk_api_config;

typedef struct tk_api tk_api;

int tk_api_start(const tk_api_config *cfg, tk_pool *pool, tk_store *store, tk_api **out,
                 tk_error *err);
unsigned tk_api_port(const tk_api *a);
const char *tk_api_scheme(const tk_api *a); /* "http" or "https" */
size_t tk_api_catalogue_size(const tk_api *a);
void tk_api_refuse(tk_api *a); /* from now on every request gets 503 */
void tk_api_stop(tk_api **p);

/* A POST /v1/jobs decoded, without HTTP or the engine: name, options,
 * and the VECT text (unparsed, in the body or `json`) or a catalogue
 * entry's name. */
typedef struct tk_query_pair {
    const char *key, *value; /* value NULL: no '=' */
    bool nul;                /* either held a NUL byte (decoded %00) */
} tk_query_pair;

typedef struct tk_submission {
    const char *name, *vect, *catalogue;
    size_t len;
    tk_job_options options;
    json_t *json; /* the body when it was JSON */
    json_t *constraints; /* its "constraints" (strings, as --constrain), or NULL */
} tk_submission;

/* Why a submission is refused (400, 415 or 422), and the member naming
 * the culprit ("field", "option", "parameter"; "": none) with its value. */
typedef struct tk_problem {
    unsigned status;
    char detail[512], member[16], value[64];
} tk_problem;

int tk_submission_decode(const char *content_type, const tk_query_pair *query, size_t nquery,
                         const char *body, size_t len, tk_submission *out, tk_problem *p);
void tk_submission_clear(tk_submission *s);

/* The submission's constraints on vertices added to its parsed curve c,
 * and every constraint of c (its VECT's too) checked against the start
 * as a run checks it (tk_curve_pins_check): 422 naming the constraint
 * otherwise.  *input is then the text to store: NULL when the VECT as
 * sent holds every constraint, else c written out with them (free()). */
int tk_submission_pins(const tk_submission *s, tk_curve *c, char **input, tk_problem *p);

#endif
