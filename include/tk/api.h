/* tightknot: the HTTP API of the service (openapi.yaml is its contract).
 *
 * libmicrohttpd answers on its own threads; handlers validate, store,
 * enqueue and answer through the job queue (tk/jobs.h) and the store,
 * never running the engine's flow themselves.
 */
#ifndef TK_API_H
#define TK_API_H

#include <stdbool.h>
#include <stddef.h>

#include "tk/catalogue.h"
#include "tk/error.h"
#include "tk/jobs.h"
#include "tk/store.h"

typedef struct tk_api_config {
    const char *bind;          /* IPv4 address to listen on */
    unsigned port;             /* 0: any free port (see tk_api_port) */
    size_t max_body;           /* request bodies beyond this get 413 */
    size_t max_vertices;       /* VECT inputs beyond this get 422 */
    size_t max_body_total;     /* bodies held at once, all connections:
                                  uploads beyond it get 503 */
    size_t max_connections;    /* open connections at once */
    size_t max_per_address;    /* open connections from one client address */
    unsigned timeout;          /* seconds an idle connection is kept */
    size_t threads;            /* threads answering requests */
    const char *web;           /* directory of the page's files, or NULL */
    const tk_catalogue *catalogue; /* or NULL */
} tk_api_config;

typedef struct tk_api tk_api;

int tk_api_start(const tk_api_config *cfg, tk_jobs *jobs, tk_store *store, tk_api **out,
                 tk_error *err);

/* The port it listens on. */
unsigned tk_api_port(const tk_api *a);

/* From now on every request gets 503 (the service is shutting down). */
void tk_api_refuse(tk_api *a);

void tk_api_stop(tk_api **p);

#endif
