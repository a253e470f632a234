/* tightknot service: what one client may take of the others (http.h):
 * its share of the upload budget, and the deadlines of head and body. */
#include "http.h"

#include <arpa/inet.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>

typedef struct watch watch;
struct limits {
    pthread_mutex_t guard; /* over held's changes, holders and watches */
    atomic_size_t held;    /* bytes of request bodies held, all connections */
    struct holder *holders; /* the clients holding bodies, and how much */
    size_t nholders;
    watch *watches;        /* every open connection with its deadline */
    pthread_t keeper;      /* cuts those past it (keep_deadlines) */
    bool keeping;
    atomic_bool stopping;
};

/* The body budget's shares.  A client is its token's name (clients
 * behind one NAT get a share each; a name on many addresses is one), else
 * its address.  It holds at most a quarter of --max-body-total, or one
 * --max-body where that is more: slow uploads of one client leave the
 * others three quarters (the probe's four 16 MB uploads took it all), yet
 * it can always send one largest body. */
typedef struct holder {
    char client[72];
    size_t bytes;
} holder;


size_t tk_limits_share(const tk_api *a)
{
    size_t quarter = a->cfg.max_body_total / 4;
    return quarter > a->cfg.max_body + 1 ? quarter : a->cfg.max_body + 1;
}

int tk_limits_reserve(tk_api *a, const request *rq, size_t more)
{
    limits *l = a->limits;
    pthread_mutex_lock(&l->guard);
    holder *h = l->holders, *end = h + l->nholders;
    while (h < end && strcmp(h->client, rq->client))
        h++;
    int refused = atomic_load(&l->held) + more > a->cfg.max_body_total ? 1
                  : (h < end ? h->bytes : 0) + more > tk_limits_share(a)     ? 2
                                                                   : 0;
    if (!refused && h == end) {
        holder *grown = realloc(l->holders, (l->nholders + 1) * sizeof *grown);
        refused = !grown;
        if (grown) {
            l->holders = grown;
            h = &grown[l->nholders++];
            *h = (holder){.bytes = 0};
            snprintf(h->client, sizeof h->client, "%s", rq->client);
        }
    }
    if (!refused) {
        h->bytes += more;
        atomic_fetch_add(&l->held, more);
    }
    pthread_mutex_unlock(&l->guard);
    return refused;
}

void tk_limits_release(tk_api *a, const request *rq, size_t bytes)
{
    if (!bytes)
        return;
    limits *l = a->limits;
    pthread_mutex_lock(&l->guard);
    size_t i = 0;
    while (i < l->nholders && strcmp(l->holders[i].client, rq->client))
        i++;
    if (i < l->nholders && !(l->holders[i].bytes -= bytes))
        l->holders[i] = l->holders[--l->nholders];
    atomic_fetch_sub(&l->held, bytes);
    pthread_mutex_unlock(&l->guard);
}

void tk_limits_client(conn *c, request *rq)
{
    const union MHD_ConnectionInfo *i = MHD_get_connection_info(c,
                                                                MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    const struct sockaddr_in *in = i ? (const void *)i->client_addr : NULL;
    char addr[INET_ADDRSTRLEN] = "?";
    if (in && in->sin_family == AF_INET)
        inet_ntop(AF_INET, &in->sin_addr, addr, sizeof addr);
    snprintf(rq->client, sizeof rq->client, "%c%s", rq->who ? 'n' : 'a', rq->who ? rq->who : addr);
}

/* Deadlines.  --timeout counts only silence: a header line every few
 * seconds kept a connection for ever, and 8 addresses x 128 held every
 * slot (the probe's F12).  libmicrohttpd 0.9.75 has only idle timeouts,
 * so we keep them: each connection is due to have its head within
 * --head-timeout of its opening or previous answer, then to keep its body
 * up to --min-body-rate (handle), and nothing while it is answered.  A
 * thread cuts those past due every 200 ms with shutdown(), which
 * libmicrohttpd reads as the client closing (it cannot answer 408 before
 * a head is whole).  A watch leaves the list before libmicrohttpd closes
 * its socket, so under the lock its descriptor is still its own. */
typedef struct watch {
    struct watch *prev, *next;
    int fd;
    atomic_llong due; /* ms of CLOCK_MONOTONIC; 0: none */
} watch;

static long long now_ms(void)
{
    return (long long)(tk_clock_seconds() * 1000.0);
}

long long tk_limits_head_due(const tk_api *a)
{
    return a->cfg.head_timeout ? now_ms() + 1000 * (long long)a->cfg.head_timeout : 0;
}

void tk_limits_due(conn *c, long long due)
{
    const union MHD_ConnectionInfo *i = MHD_get_connection_info(c,
                                                                MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    if (i && i->socket_context)
        atomic_store(&((watch *)i->socket_context)->due, due);
}

void tk_limits_notify(void *cls, conn *c, void **context, enum MHD_ConnectionNotificationCode code)
{
    tk_api *a = cls;
    limits *l = a->limits;
    watch *w = *context;
    const union MHD_ConnectionInfo *fd = MHD_get_connection_info(c,
                                                                 MHD_CONNECTION_INFO_CONNECTION_FD);
    if (code == MHD_CONNECTION_NOTIFY_STARTED && fd && (w = calloc(1, sizeof *w))) {
        w->fd = fd->connect_fd;
        *context = w;
        tk_limits_due(c, tk_limits_head_due(a));
        pthread_mutex_lock(&l->guard);
        w->next = l->watches;
        if (l->watches)
            l->watches->prev = w;
        l->watches = w;
        pthread_mutex_unlock(&l->guard);
    } else if (code == MHD_CONNECTION_NOTIFY_CLOSED && w) {
        pthread_mutex_lock(&l->guard);
        *(w->prev ? &w->prev->next : &l->watches) = w->next;
        if (w->next)
            w->next->prev = w->prev;
        pthread_mutex_unlock(&l->guard);
        free(w);
        *context = NULL;
    }
}

static void *keep_deadlines(void *cls)
{
    tk_api *a = cls;
    limits *l = a->limits;
    while (!atomic_load(&l->stopping)) {
        nanosleep(&(struct timespec){.tv_nsec = 200000000}, NULL);
        long long now = now_ms();
        pthread_mutex_lock(&l->guard);
        for (watch *w = l->watches; w; w = w->next) {
            long long due = atomic_load(&w->due);
            if (due && now > due && !shutdown(w->fd, SHUT_RDWR))
                atomic_store(&w->due, 0);
        }
        pthread_mutex_unlock(&l->guard);
    }
    return NULL;
}

int tk_limits_start(tk_api *a, tk_error *err)
{
    if (!(a->limits = calloc(1, sizeof *a->limits)))
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    pthread_mutex_init(&a->limits->guard, NULL);
    if (!(a->limits->keeping = !pthread_create(&a->limits->keeper, NULL, keep_deadlines, a)))
        return tk_error_set(err, TK_ENOMEM, "cannot start a thread");
    return TK_OK;
}

/* After the daemon stopped: its connections closed, their watches gone. */
void tk_limits_stop(tk_api *a)
{
    limits *l = a->limits;
    if (!l)
        return;
    atomic_store(&l->stopping, true);
    if (l->keeping)
        pthread_join(l->keeper, NULL);
    free(l->holders);
    pthread_mutex_destroy(&l->guard);
    free(l);
    a->limits = NULL;
}

size_t tk_limits_held(const tk_api *a)
{
    return atomic_load(&a->limits->held);
}
