/* tightknotd: the tightening service.  Parses its options, opens the job
 * store, starts the workers and the routes, and on SIGINT or SIGTERM stops
 * in order: refuse requests, store the running jobs to resume, close the
 * listener, then free the pool and close the store. */
#include <getopt.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api.h"

/* The numeric options: name, bounds, where the value goes, help. */
typedef struct setting {
    const char *name, *arg;
    unsigned long long lo, hi;
    size_t *size;
    unsigned *uint;
    const char *help;
} setting;

int main(int argc, char **argv)
{
    const char *db = "var/tightknot.db", *priority = "idle";
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    tk_api_config api = {"127.0.0.1", 8080, 16u << 20, 64u << 20, 200000, 1000, 128, 10, 2,
                         NULL, NULL};
    tk_pool_config pool_cfg = {cores > 0 ? (size_t)cores : 1, TK_PRIORITY_IDLE, 1000, 0, 2.0,
                               2000};
    const setting settings[] = {
        {"port", "P", 0, 65535, NULL, &api.port, "TCP port, 0 for any free one (default 8080)"},
        {"workers", "N", 1, 256, &pool_cfg.workers, NULL,
         "threads running the engine (default: one per core)"},
        {"queue-limit", "N", 1, 10000000, &pool_cfg.queue_limit, NULL,
         "queued jobs before submissions get 429 (default 1000)"},
        {"max-vertices", "N", 3, TK_RUN_MAX_VERTICES, &api.max_vertices, NULL,
         "largest knot accepted, after re-resolution (default 200000)"},
        {"max-body", "BYTES", 64, 1ull << 32, &api.max_body, NULL,
         "largest request body (default 16777216)"},
        {"max-body-total", "BYTES", 64, 1ull << 40, &api.max_body_total, NULL,
         "request bodies held at once over all connections;\n"
         "                       uploads beyond get 503 (default 67108864)"},
        {"max-connections", "N", 1, 100000, &api.max_connections, NULL,
         "open connections at once (default 1000)"},
        {"max-per-address", "N", 1, 100000, &api.max_per_address, NULL,
         "open connections from one client address (default 128)"},
        {"timeout", "SECONDS", 1, 3600, NULL, &api.timeout,
         "a connection silent this long is closed (default 10)"},
        {"http-threads", "N", 1, 64, &api.threads, NULL, "threads answering requests (default 2)"},
    };
    enum { NSET = sizeof settings / sizeof settings[0] };
    struct option longs[NSET + 8] = {
        {"bind", 1, NULL, 'b'}, {"db", 1, NULL, 'd'}, {"catalogue", 1, NULL, 'c'},
        {"web", 1, NULL, 'w'}, {"worker-priority", 1, NULL, 'p'}, {"help", 0, NULL, 'h'}};
    for (int i = 0; i < NSET; i++)
        longs[6 + i] = (struct option){settings[i].name, 1, NULL, 256 + i};
    for (int opt; (opt = getopt_long(argc, argv, "h", longs, NULL)) != -1;) {
        char *end = NULL;
        const setting *s = opt >= 256 ? &settings[opt - 256] : NULL;
        unsigned long long n = s && optarg[0] != '-' ? strtoull(optarg, &end, 10) : 0;
        if (s && (!end || end == optarg || *end || n < s->lo || n > s->hi)) {
            fprintf(stderr, "tightknotd: --%s: '%s' must be a whole number from %llu to %llu\n"
                    "(tightknotd --help lists the options)\n", s->name, optarg, s->lo, s->hi);
            return 1;
        }
        if (s && s->size)
            *s->size = (size_t)n;
        else if (s)
            *s->uint = (unsigned)n;
        else if (opt == 'b')
            api.bind = optarg;
        else if (opt == 'd')
            db = optarg;
        else if (opt == 'c')
            api.catalogue = optarg;
        else if (opt == 'w')
            api.web = optarg;
        else if (opt == 'p')
            priority = optarg;
        if (opt == 'h') {
            printf("usage: tightknotd [options]\n\n"
                   "The tightknot service: tightens knots and links given as Geomview VECT\n"
                   "over an HTTP/JSON API (see openapi.yaml), one job per knot, on a pool of\n"
                   "worker threads; jobs are kept in a SQLite file and survive restarts.\n\n"
                   "options:\n"
                   "  --bind ADDR          IPv4 address to listen on (default 127.0.0.1)\n"
                   "  --db FILE            job store (default var/tightknot.db; its directory\n"
                   "                       is created when missing)\n"
                   "  --catalogue DIR      offer DIR's *.vect files at /v1/catalogue\n"
                   "  --web DIR            serve the page's files from DIR at /\n"
                   "  --worker-priority P  how workers yield the CPU to requests: idle\n"
                   "                       (default: only CPU nothing else wants), low\n"
                   "                       (niceness 5) or normal (a machine shared with\n"
                   "                       other busy programs, which idle could starve)\n");
            for (int i = 0; i < NSET; i++) {
                int pad = 18 - (int)(strlen(settings[i].name) + strlen(settings[i].arg));
                printf("  --%s %s%*s%s\n", settings[i].name, settings[i].arg, pad > 0 ? pad : 1, "",
                       settings[i].help);
            }
            printf("  -h, --help           this text\n\n"
                   "On start it prints the URL it listens on.  SIGINT or SIGTERM stops it\n"
                   "within a few seconds; running jobs are stored and resume at the next\n"
                   "start, as do jobs left by a crash.\n");
            return 0;
        }
        if (opt == '?')
            return fprintf(stderr, "(tightknotd --help lists the options)\n"), 1;
    }
    if (optind < argc)
        return fprintf(stderr, "tightknotd: unexpected argument '%s'\n", argv[optind]), 1;
    static const char *const priorities[] = {"idle", "low", "normal"};
    int k = 0;
    while (k < 3 && strcmp(priority, priorities[k]))
        k++;
    if (k == 3)
        return fprintf(stderr, "tightknotd: --worker-priority: '%s' is not idle, low or "
                       "normal\n", priority), 1;
    pool_cfg.priority = (tk_priority)k;
    pool_cfg.max_vertices = api.max_vertices;

    setenv("OMP_NUM_THREADS", "1", 0); /* CHOLMOD may use OpenMP: a worker is one thread */
    /* The stop signals are taken by sigwait, so every thread blocks them;
     * a shell that starts a program in the background makes it ignore
     * SIGINT, which sigwait would then never see: defaults first. */
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_IGN);
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGINT);
    sigaddset(&stop, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop, NULL);

    char dir[PATH_MAX];
    const char *slash = strrchr(db, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - db) : 0, db);
    if (slash && slash != db)
        mkdir(dir, 0777); /* one level, as var/ is */
    tk_error err;
    tk_store *store = NULL;
    tk_pool *pool = NULL;
    tk_api *server = NULL;
    if (tk_store_open(db, &store, &err) || tk_pool_start(store, &pool_cfg, &pool, &err) ||
        tk_api_start(&api, pool, store, &server, &err)) {
        fprintf(stderr, "tightknotd: %s\n", err.message);
        tk_pool_free(&pool);
        tk_store_close(&store);
        return 2;
    }
    printf("tightknotd: listening on http://%s:%u/ (workers %zu, store %s", api.bind,
           tk_api_port(server), pool_cfg.workers, db);
    if (api.catalogue)
        printf(", catalogue %s with %zu knots", api.catalogue, tk_api_catalogue_size(server));
    printf(")\n");
    fflush(stdout);
    int sig = 0;
    sigwait(&stop, &sig);
    printf("tightknotd: %s: storing running jobs and stopping\n",
           sig == SIGINT ? "SIGINT" : "SIGTERM");
    fflush(stdout);
    /* requests get 503; the workers store their jobs and end; the HTTP
     * threads end (one in flight may still read the pool); then the rest */
    tk_api_refuse(server);
    tk_pool_halt(pool);
    tk_api_stop(&server);
    tk_pool_free(&pool);
    tk_store_close(&store);
    printf("tightknotd: stopped\n");
    return 0;
}
