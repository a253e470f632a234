/* tightknotd: the tightening service.  Parses its options, opens the job
 * store, starts the worker pool and the HTTP API, and waits for SIGINT or
 * SIGTERM to shut down in order: refuse new requests, stop the running
 * jobs (stored to resume), close the listener and the store. */
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tk/api.h"
#include "tk/catalogue.h"
#include "tk/jobs.h"
#include "tk/store.h"

static const char usage[] =
    "usage: tightknotd [options]\n"
    "\n"
    "The tightknot service: tightens knots and links given as Geomview VECT\n"
    "over an HTTP/JSON API (see openapi.yaml), one job per knot, on a pool of\n"
    "worker threads; jobs are kept in a SQLite file and survive restarts.\n"
    "\n"
    "options:\n"
    "  --bind ADDR          IPv4 address to listen on (default 127.0.0.1)\n"
    "  --port P             TCP port, 0 for any free one (default 8080)\n"
    "  --db FILE            job store (default var/tightknot.db; its directory\n"
    "                       is created when missing)\n"
    "  --workers N          threads running the engine (default: one per core)\n"
    "  --worker-priority P  how the workers yield the CPU to answering requests:\n"
    "                       idle (default: they use only CPU nothing else\n"
    "                       wants, and requests preempt them at once), low\n"
    "                       (niceness 5) or normal (for a machine shared with\n"
    "                       other busy programs, where idle could starve them)\n"
    "  --queue-limit N      queued jobs before submissions get 429 (default 1000)\n"
    "  --max-vertices N     largest knot accepted, after re-resolution\n"
    "                       (default 200000)\n"
    "  --max-body BYTES     largest request body (default 16777216)\n"
    "  --max-body-total BYTES  request bodies held at once, over all\n"
    "                       connections; uploads beyond get 503 (default 67108864)\n"
    "  --max-connections N  open connections at once (default 1000)\n"
    "  --max-per-address N  open connections from one client address\n"
    "                       (default 128): one client cannot hold them all\n"
    "  --timeout SECONDS    a connection that sends nothing for this long is\n"
    "                       closed (default 10)\n"
    "  --http-threads N     threads answering requests (default 2)\n"
    "  --catalogue DIR      offer DIR's *.vect files at /v1/catalogue\n"
    "  --web DIR            serve the page's files from DIR at /\n"
    "  -h, --help           this text\n"
    "\n"
    "On start it prints the URL it listens on.  SIGINT or SIGTERM stops it\n"
    "within a few seconds; running jobs are stored and resume at the next\n"
    "start, as do jobs left by a crash.\n";

static int bad_usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "tightknotd: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(tightknotd --help lists the options)\n");
    return 1;
}

static bool parse_size(const char *text, unsigned long long lo, unsigned long long hi,
                       unsigned long long *out)
{
    char *end = NULL;
    errno = 0;
    if (!text || *text == '-')
        return false;
    unsigned long long n = strtoull(text, &end, 10);
    if (errno || end == text || *end || n < lo || n > hi)
        return false;
    *out = n;
    return true;
}

/* Creates the directory part of path (one level, as var/ is). */
static void make_parent(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash || slash == path)
        return;
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    mkdir(dir, 0777);
}

int main(int argc, char **argv)
{
    const char *db = "var/tightknot.db";
    const char *catalogue_dir = NULL;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    tk_api_config api = {"127.0.0.1", 8080, 16u << 20, 200000, 64u << 20, 1000, 128, 10, 2,
                         NULL, NULL};
    tk_jobs_config jobs_cfg = TK_JOBS_CONFIG_INIT;
    jobs_cfg.workers = cores > 0 ? (size_t)cores : 1;
    jobs_cfg.max_vertices = api.max_vertices;

    for (int i = 1; i < argc; i++) {
        const char *opt = argv[i];
        if (!strcmp(opt, "-h") || !strcmp(opt, "--help")) {
            fputs(usage, stdout);
            return 0;
        }
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        unsigned long long n = 0;
        if (!value)
            return bad_usage("%s needs a value", opt);
        i++;
        if (!strcmp(opt, "--bind"))
            api.bind = value;
        else if (!strcmp(opt, "--db"))
            db = value;
        else if (!strcmp(opt, "--catalogue"))
            catalogue_dir = value;
        else if (!strcmp(opt, "--web"))
            api.web = value;
        else if (!strcmp(opt, "--port")) {
            if (!parse_size(value, 0, 65535, &n))
                return bad_usage("--port: '%s' is not a port number (0 to 65535)", value);
            api.port = (unsigned)n;
        } else if (!strcmp(opt, "--workers")) {
            if (!parse_size(value, 1, 256, &n))
                return bad_usage("--workers: '%s' must be from 1 to 256", value);
            jobs_cfg.workers = (size_t)n;
        } else if (!strcmp(opt, "--worker-priority")) {
            if (!tk_worker_priority_parse(value, &jobs_cfg.priority))
                return bad_usage("--worker-priority: '%s' is not idle, low or normal", value);
        } else if (!strcmp(opt, "--queue-limit")) {
            if (!parse_size(value, 1, 10000000, &n))
                return bad_usage("--queue-limit: '%s' must be from 1 to 10000000", value);
            jobs_cfg.queue_limit = (size_t)n;
        } else if (!strcmp(opt, "--max-vertices")) {
            if (!parse_size(value, 3, 100000000, &n))
                return bad_usage("--max-vertices: '%s' must be from 3 to 100000000", value);
            api.max_vertices = jobs_cfg.max_vertices = (size_t)n;
        } else if (!strcmp(opt, "--max-body")) {
            if (!parse_size(value, 64, 1ull << 32, &n))
                return bad_usage("--max-body: '%s' must be from 64 to 4294967296", value);
            api.max_body = (size_t)n;
        } else if (!strcmp(opt, "--max-body-total")) {
            if (!parse_size(value, 64, 1ull << 40, &n))
                return bad_usage("--max-body-total: '%s' must be from 64 to 1099511627776", value);
            api.max_body_total = (size_t)n;
        } else if (!strcmp(opt, "--max-per-address")) {
            if (!parse_size(value, 1, 100000, &n))
                return bad_usage("--max-per-address: '%s' must be from 1 to 100000", value);
            api.max_per_address = (size_t)n;
        } else if (!strcmp(opt, "--max-connections")) {
            if (!parse_size(value, 1, 100000, &n))
                return bad_usage("--max-connections: '%s' must be from 1 to 100000", value);
            api.max_connections = (size_t)n;
        } else if (!strcmp(opt, "--timeout")) {
            if (!parse_size(value, 1, 3600, &n))
                return bad_usage("--timeout: '%s' must be from 1 to 3600 seconds", value);
            api.timeout = (unsigned)n;
        } else if (!strcmp(opt, "--http-threads")) {
            if (!parse_size(value, 1, 64, &n))
                return bad_usage("--http-threads: '%s' must be from 1 to 64", value);
            api.threads = (size_t)n;
        } else {
            return bad_usage("unknown option '%s'", opt);
        }
    }

    /* CHOLMOD may use OpenMP; each worker is one thread of work. */
    setenv("OMP_NUM_THREADS", "1", 0);
    /* The signals are taken by sigwait below, never by a handler, so every
     * thread started from here on blocks them. */
    sigset_t stop_signals;
    /* A shell that starts a program in the background makes it ignore
     * SIGINT, and an ignored signal never reaches sigwait: take both back
     * to their defaults first. */
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop_signals, NULL);
    signal(SIGPIPE, SIG_IGN);

    tk_error err;
    tk_catalogue *catalogue = NULL;
    if (catalogue_dir) {
        size_t skipped = 0;
        if (tk_catalogue_open(catalogue_dir, &catalogue, &skipped, &err) != TK_OK) {
            fprintf(stderr, "tightknotd: %s\n", err.message);
            return 2;
        }
        if (skipped)
            fprintf(stderr, "tightknotd: catalogue %s: %zu files do not parse and are left out\n",
                    catalogue_dir, skipped);
        api.catalogue = catalogue;
    }
    make_parent(db);
    tk_store *store = NULL;
    if (tk_store_open(db, &store, &err) != TK_OK) {
        fprintf(stderr, "tightknotd: %s\n", err.message);
        tk_catalogue_free(&catalogue);
        return 2;
    }
    tk_jobs *jobs = NULL;
    if (tk_jobs_start(store, &jobs_cfg, &jobs, &err) != TK_OK) {
        fprintf(stderr, "tightknotd: %s\n", err.message);
        tk_store_close(&store);
        tk_catalogue_free(&catalogue);
        return 2;
    }
    tk_api *server = NULL;
    if (tk_api_start(&api, jobs, store, &server, &err) != TK_OK) {
        fprintf(stderr, "tightknotd: %s\n", err.message);
        tk_jobs_stop(&jobs);
        tk_store_close(&store);
        tk_catalogue_free(&catalogue);
        return 2;
    }
    size_t entries = 0;
    if (catalogue)
        tk_catalogue_entries(catalogue, &entries);
    printf("tightknotd: listening on http://%s:%u/ (workers %zu, store %s", api.bind,
           tk_api_port(server), jobs_cfg.workers, db);
    if (catalogue)
        printf(", catalogue %s with %zu knots", catalogue_dir, entries);
    printf(")\n");
    fflush(stdout);

    int sig = 0;
    sigwait(&stop_signals, &sig);
    printf("tightknotd: %s: storing running jobs and stopping\n",
           sig == SIGINT ? "SIGINT" : "SIGTERM");
    fflush(stdout);
    /* In order: requests get 503; the workers store their jobs and end;
     * the HTTP threads end (a request still in flight may read the pool);
     * only then is the pool freed. */
    tk_api_refuse(server);
    tk_jobs_halt(jobs);
    tk_api_stop(&server);
    tk_jobs_stop(&jobs);
    tk_store_close(&store);
    tk_catalogue_free(&catalogue);
    printf("tightknotd: stopped\n");
    return 0;
}
