/* tightknotd: the tightening service.  Parses its options, opens the job
 * store, starts the workers and the routes, and on SIGINT or SIGTERM stops
 * in order: refuse requests, store the running jobs to resume, close the
 * listener, then free the pool and close the store. */
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api.h"
#include "cli.h"
#include "job.h"
#include "tk/version.h"

/* The daemon's numbers, each with its domain and default. */
typedef struct settings {
    tk_api_config api;
    tk_pool_config pool;
    double lease;
} settings;
#define ROW(path, fld, kind, dflt, lo, hi, hlp)                                                \
    TK_FIELD_ROW(settings, path, fld, kind, dflt, lo, hi, #fld, hlp)
static const tk_field fields[] = {
    ROW(api.port, port, SIZE, 8080, 0, 65535, "TCP port, 0 for any free one"),
    ROW(pool.workers, workers, SIZE, 0, 0, 256, "threads running the engine, 0 for one per core"),
    ROW(pool.queue_limit, queue_limit, SIZE, 1000, 1, 1e7,
        "queued jobs before submissions get 429"),
    ROW(pool.per_owner, jobs_per_name, SIZE, 100, 0, 1e7,
        "with --tokens: queued and running jobs a name may have before its submissions get "
        "429 (0: any number)"),
    ROW(pool.owner_bytes, bytes_per_name, SIZE, 1 << 30, 0, 0x1p50,
        "with --tokens: bytes stored for a name's jobs (inputs, curves, histories, frames) "
        "beyond which its submissions get 429 until it deletes finished jobs, and its running "
        "jobs' frames are refused (0: any number)"),
    ROW(api.max_vertices, max_vertices, SIZE, 200000, 3, TK_RUN_MAX_VERTICES,
        "largest knot accepted, after re-resolution"),
    ROW(api.max_body, max_body, SIZE, 16 << 20, 64, 0x1p32, "largest request body in bytes"),
    ROW(api.max_body_total, max_body_total, SIZE, 64 << 20, 64, 0x1p40,
        "bytes of request bodies held at once over all connections, by one client (its "
        "token's name, else its address) at most a quarter of them, or one --max-body where "
        "that is more; uploads beyond get 503"),
    ROW(api.max_connections, max_connections, SIZE, 1000, 1, 100000, "open connections at once"),
    ROW(api.max_per_address, max_per_address, SIZE, 128, 1, 100000,
        "open connections from one client address"),
    ROW(api.timeout, timeout, SIZE, 10, 1, 3600, "seconds a silent connection is kept open"),
    ROW(api.head_timeout, head_timeout, SIZE, 20, 0, 3600,
        "seconds a request's head (its line and headers) may take to arrive, from the "
        "connection's opening or its previous answer; a slower one is cut (0: any time)"),
    ROW(api.min_body_rate, min_body_rate, SIZE, 1000, 0, 1e9,
        "bytes a second a request body must keep up after its head: each byte buys 1/N s, "
        "never more than --head-timeout seconds in hand; a slower upload is cut (0: any rate)"),
    ROW(api.threads, http_threads, SIZE, 2, 1, 64, "threads answering requests"),
    ROW(lease, lease, REAL, 30, 3, 3600,
        "with a PostgreSQL --db: seconds after which the jobs of a daemon that stopped "
        "renewing them (one that died) are taken up by the others"),
};

int main(int argc, char **argv)
{
    const char *db = "var/tightknot.db", *priority = "idle", *tokens_file = NULL;
    settings set = {.api = {.bind = "127.0.0.1"}, .pool = {.flush_seconds = 2.0, .history = 2000}};
    tk_cli_defaults(fields, sizeof fields / sizeof fields[0], &set);
    bool help = false, anonymous = false, version = false;
    tk_cli cli = {.n = 0};
    tk_cli_text(&cli, "bind", 0, "ADDR", &set.api.bind, "IPv4 address to listen on (default "
                "127.0.0.1)");
    tk_cli_text(&cli, "db", 0, "STORE", &db, "job store: a SQLite file (default "
                "var/tightknot.db; its directory is created when missing), or "
                "postgresql://USER@HOST/DB, one database that any number of daemons share");
    tk_cli_text(&cli, "catalogue", 0, "DIR", &set.api.catalogue, "offer DIR's *.vect files at "
                "/v1/catalogue");
    tk_cli_text(&cli, "web", 0, "DIR", &set.api.web, "serve the page's files from DIR at /");
    tk_cli_text(&cli, "host", 0, "NAMES", &set.api.hosts, "host names (or addresses) clients "
                "reach the daemon by, comma-separated, besides the bind address and localhost "
                "(other Host headers get 421)");
    tk_cli_text(&cli, "allow-origin", 0, "ORIGINS", &set.api.allow_origins, "origins "
                "(https://example.org) whose pages may call the API, comma-separated; requests "
                "from other pages get 403");
    tk_cli_text(&cli, "worker-priority", 0, "P", &priority, "how workers yield the CPU to "
                "requests: idle (default: only CPU nothing else wants), low (niceness 5) or "
                "normal (a machine shared with other busy programs, which idle could starve)");
    tk_cli_text(&cli, "tokens", 0, "FILE", &tokens_file, "the clients: a line 'NAME TOKEN' "
                "(a token of at least 16 characters) or 'NAME sha256:HEX' each, 'admin' after "
                "it for a name that may cancel any job, '#' first on a comment line; every "
                "request but health and the page then needs 'Authorization: Bearer TOKEN', and "
                "a name sees its own jobs");
    tk_cli_text(&cli, "tls-cert", 0, "FILE", &set.api.tls_cert, "serve HTTPS with this "
                "certificate (PEM; with --tls-key)");
    tk_cli_text(&cli, "tls-key", 0, "FILE", &set.api.tls_key, "the certificate's private key "
                "(PEM)");
    tk_cli_flag(&cli, "allow-anonymous", 0, &anonymous, "listen on an address other than "
                "loopback without --tokens (anyone who reaches it may submit and cancel)");
    tk_cli_fields(&cli, fields, sizeof fields / sizeof fields[0], &set);
    tk_cli_flag(&cli, "help", 'h', &help, "this text");
    tk_cli_flag(&cli, "version", 0, &version, "print the release and stop");
    tk_error err;
    int npos = 0;
    if (tk_cli_parse(&cli, argc - 1, argv + 1, &npos, &err))
        return fprintf(stderr, "tightknotd: %s\n(tightknotd --help lists the options)\n",
                       err.message), 1;
    if (version)
        return printf("tightknotd %s\n", TK_VERSION) < 0;
    if (help) {
        printf("usage: tightknotd [options]\n\n"
               "The tightknot service: tightens knots and links given as Geomview VECT\n"
               "over an HTTP/JSON API (see openapi.yaml), one job per knot, on a pool of\n"
               "worker threads; jobs are kept in a SQLite file, or in a PostgreSQL\n"
               "database shared by several daemons, and survive restarts.\n\n"
               "options:\n");
        tk_cli_help(&cli, stdout);
        printf("\nOn start it prints the URL it listens on, then a line for each job it\n"
               "takes up or lets go.  SIGINT or SIGTERM stops it within a few seconds;\n"
               "running jobs are stored and resume at the next start (with PostgreSQL:\n"
               "on any daemon), as do jobs left by a crash (with PostgreSQL: once their\n"
               "lease runs out).\n");
        return 0;
    }
    if (npos > 0)
        return fprintf(stderr, "tightknotd: unexpected argument '%s'\n", argv[1]), 1;
    static const char *const priorities[] = {"idle", "low", "normal"};
    int k = 0;
    while (k < 3 && strcmp(priority, priorities[k]))
        k++;
    if (k == 3)
        return fprintf(stderr, "tightknotd: --worker-priority: '%s' is not idle, low or "
                       "normal\n", priority), 1;
    tk_api_config api = set.api;
    tk_pool_config pool_cfg = set.pool;
    if (!tokens_file && !anonymous && strncmp(api.bind, "127.", 4))
        return fprintf(stderr, "tightknotd: --bind %s without --tokens would let anyone who "
                       "reaches it submit and cancel jobs: give --tokens FILE, or "
                       "--allow-anonymous\n", api.bind), 1;
    if (!tokens_file)
        pool_cfg.per_owner = pool_cfg.owner_bytes = 0;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (!pool_cfg.workers)
        pool_cfg.workers = cores > 0 ? (size_t)cores : 1;
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

    bool postgres = !strncmp(db, "postgresql://", 13) || !strncmp(db, "postgres://", 11);
    char dir[PATH_MAX];
    const char *slash = strrchr(db, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - db) : 0, db);
    if (!postgres && slash && slash != db)
        mkdir(dir, 0777); /* one level, as var/ is */
    pool_cfg.log = stdout;
    tk_tokens *tokens = NULL;
    tk_store *store = NULL;
    tk_pool *pool = NULL;
    tk_api *server = NULL;
    int rc = tokens_file ? tk_tokens_load(tokens_file, &tokens, &err) : TK_OK;
    api.tokens = tokens;
    if (rc || tk_store_open(db, set.lease, &store, &err) || tk_pool_start(store, &pool_cfg, &pool, &err) ||
        tk_api_start(&api, pool, store, &server, &err)) {
        fprintf(stderr, "tightknotd: %s\n", err.message);
        tk_pool_free(&pool);
        tk_store_close(&store);
        tk_tokens_free(&tokens);
        return 2;
    }
    /* a URI may hold a password: the store's label has none */
    /* every line of the log carries its time, as the pool's job lines do */
    char now[32];
    tk_time_iso(now);
    printf("tightknotd: %s listening on %s://%s:%u/ (workers %zu, store %s", now,
           tk_api_scheme(server), api.bind, tk_api_port(server), pool_cfg.workers,
           postgres ? tk_store_label(store) : db);
    printf(" as %s", tk_store_holder(store)); /* the jobs' "daemon" */
    if (postgres)
        printf(", lease %g s", set.lease);
    if (api.catalogue)
        printf(", catalogue %s with %zu knots", api.catalogue, tk_api_catalogue_size(server));
    printf(")\n");
    fflush(stdout);
    tk_pool_go(pool);
    int sig = 0;
    sigwait(&stop, &sig);
    tk_time_iso(now);
    printf("tightknotd: %s %s: storing running jobs and stopping\n", now,
           sig == SIGINT ? "SIGINT" : "SIGTERM");
    fflush(stdout);
    /* requests get 503; the workers store their jobs and end; the HTTP
     * threads end (one in flight may still read the pool); then the rest */
    tk_api_refuse(server);
    tk_pool_halt(pool);
    tk_api_stop(&server);
    tk_pool_free(&pool);
    tk_store_close(&store);
    tk_tokens_free(&tokens);
    tk_time_iso(now);
    printf("tightknotd: %s stopped\n", now);
    return 0;
}
