/* tightknot remote: submits knots to a tightknot service, follows the
 * jobs, downloads the results and keeps a summary table; also status,
 * cancel and fetch of single jobs.  Talks only the public HTTP API
 * (openapi.yaml) through libcurl.
 *
 * Resuming: DIR/jobs.tsv records every submitted file's job id as soon as
 * the server accepts it, and DIR/summary.tsv every finished file.  A second
 * run skips the files already in the summary as done and follows the jobs
 * already submitted instead of submitting them again.
 */
#include "remote.h"

#include <ctype.h>
#include <curl/curl.h>
#include <dirent.h>
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "film.h"
#include "jobopts.h"
#include "tk/vect.h"

enum { REMOTE_OK = 0, REMOTE_USAGE = 1, REMOTE_FAILED = 2, REMOTE_SERVER = 3 };

const char tk_remote_help[] =
    "usage: tightknot remote [--server URL] COMMAND ...\n"
    "\n"
    "Uses a tightknot service (tightknotd) over HTTP.\n"
    "\n"
    "Commands:\n"
    "  submit [run options] [--out DIR] [--parallel N] FILES... | DIR\n"
    "      tighten every VECT file (a directory stands for its *.vect files):\n"
    "      submits them, at most N running at once (default 4), shows their\n"
    "      progress, and downloads each result into DIR (default\n"
    "      tightknot-results): NAME.vect (the tight curve), NAME-struts.json\n"
    "      (struts and kinks) and a row of DIR/summary.tsv with name,\n"
    "      components, vertices, ropelength, thickness, residual, struts, steps,\n"
    "      seconds, reached (how many of the run's tightenings reached its\n"
    "      lowest basin), state.  Run it again to resume: files already done are not\n"
    "      submitted again and jobs already submitted are followed.\n"
    "  list [STATE]    every job the server shows you (with tokens, your own),\n"
    "                  newest first, one line each as status prints; STATE\n"
    "                  (queued, running, done, failed, cancelled) keeps those\n"
    "  status JOB...   one line per job: state, step, ropelength, residual\n"
    "  cancel JOB...   cancel queued or running jobs\n"
    "  delete JOB...   delete finished jobs (done, failed or cancelled) from\n"
    "                  the server, with their results\n"
    "  fetch [--out DIR] JOB...   download jobs' VECT and struts into DIR\n"
    "                  (NAME-JOB.vect and NAME-JOB-struts.json, as the page)\n"    "  frames [--count N | --every-time T] [--out DIR] JOB\n"
    "      a film's frames at equal flow time from the job's stored frames\n"
    "      (N of them, default 200, or one every T of flow time, each\n"
    "      frame's flow time read off the job's stored steps): DIR/NAME-JOB-\n"
    "      frame-KKKK.vect, and a line each (frame, step, flow_time, file)\n"
    "\n"
    "Run options: those of tightknot tighten, by the same names (see\n"
    "'tightknot tighten --help': --resolution R, --steps N, --time SECONDS,\n"
    "--work W, --residual X, --autoscale, --escapes N, ...), and --every K\n"
    "(keep a frame every K steps).  With neither steps nor residual a job\n"
    "gets the defaults that tighten: resolution 5, autoscale, and with no\n"
    "time or work, stop when converged or after 120 of work.\n"
    "\n"
    "Options:\n"
    "  --server URL   the service (default $TIGHTKNOT_SERVER, else\n"
    "                 http://127.0.0.1:8080)\n"
    "  --token TOKEN  sent as 'Authorization: Bearer TOKEN' to a server with\n"
    "                 --tokens (default $TIGHTKNOT_TOKEN)\n"
    "  --cacert FILE  the certificate (PEM) of the CA that signed an https\n"
    "                 server's certificate, for a private CA (the system's CAs\n"
    "                 otherwise); the server's name is always verified\n"
    "  --poll SECONDS how often to ask for progress (default 1)\n"    "  --progress     submit: a progress line (the share of the jobs' budgets\n"
    "                 spent, the time left) every 10 s on standard error when\n"
    "                 it is not a terminal (on a terminal it is always shown)\n"
    "  --json         status and list: print the jobs as JSON, one per line\n"
    "\n"
    "Exit status: 0 all done, 1 usage error, 2 some job failed or a file was\n"
    "refused, 3 the server could not be reached or answered with an error.\n"
    "\n"
    "Example (the whole catalogue on a remote server, 300 s at most each):\n"
    "  tightknot remote --server http://tk.example.org:8080 submit \\\n"
    "      --converge --time 300 --out results ../shared/catalogue\n";

/* ------------------------------------------------------------ HTTP */

typedef struct buffer {
    char *data;
    size_t len, cap;
} buffer;

typedef struct client {
    CURL *curl;
    char base[1024];
    const char *token; /* sent as a bearer token, or NULL */
    const char *cacert; /* the CA that signed an https server's certificate, or NULL */
    char error[CURL_ERROR_SIZE];
    bool tty;
    bool plain;         /* --progress: a progress line every PLAIN_EVERY s */
    double started, last_line;
} client;

#define PLAIN_EVERY 10.0

typedef struct response {
    long status;
    buffer body;
    double retry_after;
} response;

static size_t collect(char *data, size_t size, size_t n, void *user)
{
    buffer *b = user;
    size_t add = size * n;
    if (b->len + add + 1 > b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 4096;
        while (cap < b->len + add + 1)
            cap *= 2;
        char *grown = realloc(b->data, cap);
        if (!grown)
            return 0;
        b->data = grown;
        b->cap = cap;
    }
    memcpy(b->data + b->len, data, add);
    b->len += add;
    b->data[b->len] = '\0';
    return add;
}

static size_t header_line(char *data, size_t size, size_t n, void *user)
{
    response *r = user;
    size_t len = size * n;
    if (len > 12 && strncasecmp(data, "Retry-After:", 12) == 0)
        r->retry_after = strtod(data + 12, NULL);
    return len;
}

/* One request; false (message printed) when the server cannot be reached. */
static bool request(client *c, const char *method, const char *path, const char *type,
                    const char *body, size_t len, response *r)
{
    free(r->body.data);
    memset(r, 0, sizeof *r);
    char url[2048];
    snprintf(url, sizeof url, "%s%s", c->base, path);
    CURL *h = c->curl;
    curl_easy_reset(h);
    curl_easy_setopt(h, CURLOPT_URL, url);
    curl_easy_setopt(h, CURLOPT_CUSTOMREQUEST, method);
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, collect);
    curl_easy_setopt(h, CURLOPT_WRITEDATA, &r->body);
    curl_easy_setopt(h, CURLOPT_HEADERFUNCTION, header_line);
    curl_easy_setopt(h, CURLOPT_HEADERDATA, r);
    curl_easy_setopt(h, CURLOPT_ERRORBUFFER, c->error);
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT, 10L);
    curl_easy_setopt(h, CURLOPT_TIMEOUT, 120L);
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
    if (c->cacert)
        curl_easy_setopt(h, CURLOPT_CAINFO, c->cacert);
    struct curl_slist *headers = NULL;
    if (type) {
        char line[128];
        snprintf(line, sizeof line, "Content-Type: %s", type);
        headers = curl_slist_append(headers, line);
        headers = curl_slist_append(headers, "Expect:");
        curl_easy_setopt(h, CURLOPT_POSTFIELDS, body);
        curl_easy_setopt(h, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)len);
    }
    headers = curl_slist_append(headers, "Accept: application/json, text/plain");
    if (c->token) {
        char line[1024];
        snprintf(line, sizeof line, "Authorization: Bearer %s", c->token);
        headers = curl_slist_append(headers, line);
    }
    curl_easy_setopt(h, CURLOPT_HTTPHEADER, headers);
    c->error[0] = '\0';
    CURLcode rc = curl_easy_perform(h);
    curl_slist_free_all(headers);
    if (rc != CURLE_OK) {
        /* a certificate no CA the client trusts signed: say how to trust it */
        bool certificate = rc == CURLE_PEER_FAILED_VERIFICATION || rc == CURLE_SSL_CACERT_BADFILE;
        fprintf(stderr, "%stightknot remote: cannot reach %s: %s%s\n", c->tty ? "\n" : "",
                c->base, c->error[0] ? c->error : curl_easy_strerror(rc),
                certificate ? " (a self-signed server, or one whose certificate a private CA "
                              "signed: pass --cacert FILE, that CA's certificate in PEM)"
                            : "");
        return false;
    }
    curl_easy_getinfo(h, CURLINFO_RESPONSE_CODE, &r->status);
    if (r->status == 401) {
        /* every later request would be refused the same way: stop at the
         * first, as for a server that cannot be reached */
        fprintf(stderr, "%stightknot remote: %s: %s\n", c->tty ? "\n" : "", c->base,
                c->token ? "the server refused the token (401): check --token or "
                           "$TIGHTKNOT_TOKEN"
                         : "the server needs a token (401): pass --token TOKEN or set "
                           "$TIGHTKNOT_TOKEN");
        free(r->body.data);
        r->body.data = NULL;
        return false;
    }
    if (!r->body.data)
        collect("", 1, 0, &r->body);
    return true;
}

/* What a server sends is printed to a terminal: its control characters
 * (C0, DEL and, in UTF-8, C1) become '?', so that no text of a job
 * (another client's name, say) can move the cursor, retitle the window
 * or print a line of its own. */
static void make_printable(char *s)
{
    unsigned char *p = (unsigned char *)s;
    for (size_t i = 0; p[i]; i++) {
        if (p[i] == 0xc2 && p[i + 1] >= 0x80 && p[i + 1] <= 0x9f) {
            p[i] = p[i + 1] = '?';
            i++;
        } else if (p[i] < 0x20 || p[i] == 0x7f) {
            p[i] = '?';
        }
    }
}

/* text (NULL: "") into out, printable. */
static char *printable(char *out, size_t size, const char *text)
{
    snprintf(out, size, "%s", text ? text : "");
    make_printable(out);
    return out;
}

/* The problem detail of an error response (or its start), printable. */
static void problem_text(const response *r, char *out, size_t size)
{
    json_t *doc = r->body.data ? json_loads(r->body.data, 0, NULL) : NULL;
    const char *detail = json_string_value(json_object_get(doc, "detail"));
    if (detail)
        snprintf(out, size, "%s", detail);
    else
        snprintf(out, size, "HTTP %ld: %.200s", r->status, r->body.data ? r->body.data : "");
    json_decref(doc);
    make_printable(out);
}

/* ------------------------------------------------------------ files */

/* dir/file into path; false when it does not fit. */
static bool join_path(char *path, size_t size, const char *dir, const char *file)
{
    int n = snprintf(path, size, "%s/%s", dir, file);
    return n >= 0 && (size_t)n < size;
}

static bool write_file(const char *path, const char *data, size_t len)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.part", path);
    FILE *f = fopen(tmp, "wb");
    bool ok = f && fwrite(data, 1, len, f) == len;
    if (f && fclose(f) != 0)
        ok = false;
    if (ok && rename(tmp, path) != 0)
        ok = false;
    if (!ok) {
        fprintf(stderr, "tightknot remote: cannot write %s: %s\n", path, strerror(errno));
        unlink(tmp);
    }
    return ok;
}

static char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    buffer b = {0};
    char chunk[65536];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0)
        if (collect(chunk, 1, n, &b) != n) {
            free(b.data);
            fclose(f);
            return NULL;
        }
    bool bad = ferror(f);
    fclose(f);
    if (bad) {
        free(b.data);
        return NULL;
    }
    if (!b.data)
        collect("", 1, 0, &b);
    *len = b.len;
    return b.data;
}

/* ------------------------------------------------------------ jobs */

typedef enum { ITEM_WAITING, ITEM_RUNNING, ITEM_FINISHED } item_phase;

typedef struct item {
    char *path;
    char *name;          /* file name without .vect: the job's name */
    long long job;       /* 0 until submitted */
    item_phase phase;
    char state[16];      /* the job's state when finished */
    double ropelength, thickness, residual, seconds;
    double fraction;     /* of its budget spent, as last polled (-1: unknown) */
    long long components, vertices, struts, steps, reached;
    char *row;           /* summary row, once finished */
    char message[256];
} item;

static int by_name(const void *a, const void *b)
{
    return strcmp(((const item *)a)->name, ((const item *)b)->name);
}

static char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *start = slash ? slash + 1 : path;
    size_t n = strlen(start);
    if (n > 5 && strcmp(start + n - 5, ".vect") == 0)
        n -= 5;
    return strndup(start, n);
}

static bool add_item(item **items, size_t *n, size_t *cap, const char *path)
{
    if (*n == *cap) {
        *cap = *cap ? 2 * *cap : 64;
        item *grown = realloc(*items, *cap * sizeof *grown);
        if (!grown)
            return false;
        *items = grown;
    }
    item *it = &(*items)[*n];
    memset(it, 0, sizeof *it);
    it->path = strdup(path);
    it->name = base_name(path);
    it->ropelength = it->thickness = it->residual = it->seconds = NAN;
    if (!it->path || !it->name)
        return false;
    (*n)++;
    return true;
}

/* The files named on the command line, a directory standing for its
 * *.vect files; sorted by name.  False (message printed) on a bad one. */
static bool gather(int argc, char **argv, item **items, size_t *n)
{
    size_t cap = 0;
    *items = NULL;
    *n = 0;
    for (int i = 0; i < argc; i++) {
        struct stat st;
        if (stat(argv[i], &st) != 0) {
            fprintf(stderr, "tightknot remote: %s: %s\n", argv[i], strerror(errno));
            return false;
        }
        if (!S_ISDIR(st.st_mode)) {
            if (!add_item(items, n, &cap, argv[i]))
                return false;
            continue;
        }
        DIR *d = opendir(argv[i]);
        if (!d) {
            fprintf(stderr, "tightknot remote: %s: %s\n", argv[i], strerror(errno));
            return false;
        }
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            size_t len = strlen(e->d_name);
            if (len <= 5 || strcmp(e->d_name + len - 5, ".vect") || e->d_name[0] == '.')
                continue;
            char path[4096];
            snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
            if (!add_item(items, n, &cap, path)) {
                closedir(d);
                return false;
            }
        }
        closedir(d);
    }
    qsort(*items, *n, sizeof **items, by_name);
    for (size_t i = 1; i < *n; i++)
        if (!strcmp((*items)[i].name, (*items)[i - 1].name)) {
            fprintf(stderr, "tightknot remote: two files are called %s (%s and %s); their "
                            "results would overwrite each other\n",
                    (*items)[i].name, (*items)[i - 1].path, (*items)[i].path);
            return false;
        }
    return true;
}

static item *find_item(item *items, size_t n, const char *name)
{
    item key;
    key.name = (char *)name;
    return bsearch(&key, items, n, sizeof key, by_name);
}

static const char summary_header[] =
    "name\tcomponents\tvertices\tropelength\tthickness\tresidual\tstruts\tsteps\tseconds\treached\t"
    "state\n";

/* Calls take(line, item) for every line of DIR/file whose first field
 * names one of the items (a missing file has no lines). */
static void each_row(const char *out, const char *file, item *items, size_t n,
                     void (*take)(char *line, item *it))
{
    char path[4096];
    if (!join_path(path, sizeof path, out, file))
        return;
    size_t len = 0;
    char *text = read_file(path, &len);
    if (!text)
        return;
    char *save = NULL;
    for (char *line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        const char *tab = strchr(line, '\t');
        if (!tab)
            continue;
        char name[1024];
        snprintf(name, sizeof name, "%.*s", (int)(tab - line), line);
        item *it = find_item(items, n, name);
        if (it)
            take(line, it);
    }
    free(text);
}

/* A row of an earlier summary: kept when its file is done. */
static void take_summary_row(char *line, item *it)
{
    const char *state = strrchr(line, '\t');
    if (strcmp(state + 1, "done") != 0)
        return;
    size_t rowlen = strlen(line) + 2;
    it->row = malloc(rowlen);
    if (it->row)
        snprintf(it->row, rowlen, "%s\n", line);
    it->phase = ITEM_FINISHED;
    snprintf(it->state, sizeof it->state, "done");
}

/* A row of jobs.tsv (name TAB id): the job of an earlier submission. */
static void take_job_row(char *line, item *it)
{
    if (it->phase == ITEM_WAITING)
        it->job = strtoll(strchr(line, '\t') + 1, NULL, 10);
}

static bool append_job(const char *out, const item *it)
{
    char path[4096];
    if (!join_path(path, sizeof path, out, "jobs.tsv"))
        return false;
    FILE *f = fopen(path, "a");
    bool ok = f && fprintf(f, "%s\t%lld\n", it->name, it->job) > 0;
    if (f && fclose(f) != 0)
        ok = false;
    if (!ok)
        fprintf(stderr, "tightknot remote: cannot write %s: %s\n", path, strerror(errno));
    return ok;
}

/* Rewrites summary.tsv with every finished file, in name order. */
static bool save_summary(const char *out, const item *items, size_t n)
{
    buffer b = {0};
    collect((char *)summary_header, 1, strlen(summary_header), &b);
    for (size_t i = 0; i < n; i++)
        if (items[i].row)
            collect(items[i].row, 1, strlen(items[i].row), &b);
    char path[4096];
    if (!join_path(path, sizeof path, out, "summary.tsv"))
        return false;
    bool ok = b.data && write_file(path, b.data, b.len);
    free(b.data);
    return ok;
}

static double number_or_nan(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static void format_number(char *out, size_t size, double x)
{
    if (isfinite(x))
        snprintf(out, size, "%.17g", x);
    else
        snprintf(out, size, "-");
}

/* Downloads a finished job's curve and struts; false on failure. */
static bool download(client *c, long long job, const char *out, const char *name)
{
    char path[4200], api[128];
    response r = {0};
    snprintf(api, sizeof api, "/v1/jobs/%lld/vect", job);
    curl_easy_reset(c->curl);
    bool ok = request(c, "GET", api, NULL, NULL, 0, &r) && r.status == 200;
    /* the API answers JSON when asked for it first; here the text */
    if (ok) {
        json_t *doc = json_loadb(r.body.data, r.body.len, 0, NULL);
        const char *vect = json_string_value(json_object_get(doc, "vect"));
        snprintf(path, sizeof path, "%s/%s.vect", out, name);
        ok = vect ? write_file(path, vect, strlen(vect)) : write_file(path, r.body.data, r.body.len);
        json_decref(doc);
    }
    snprintf(api, sizeof api, "/v1/jobs/%lld/struts", job);
    if (ok)
        ok = request(c, "GET", api, NULL, NULL, 0, &r) && r.status == 200;
    if (ok) {
        snprintf(path, sizeof path, "%s/%s-struts.json", out, name);
        ok = write_file(path, r.body.data, r.body.len);
    }
    free(r.body.data);
    return ok;
}

/* Fills a finished item from its job record. */
static void finish_item(item *it, const json_t *job)
{
    it->phase = ITEM_FINISHED;
    const char *state = json_string_value(json_object_get(job, "state"));
    snprintf(it->state, sizeof it->state, "%s", state ? state : "failed");
    make_printable(it->state);
    it->ropelength = number_or_nan(job, "ropelength");
    it->thickness = number_or_nan(job, "thickness");
    it->residual = number_or_nan(job, "residual");
    it->seconds = number_or_nan(job, "seconds");
    it->components = (long long)json_integer_value(json_object_get(job, "components"));
    it->vertices = (long long)json_integer_value(json_object_get(job, "vertices"));
    it->struts = (long long)json_integer_value(json_object_get(job, "struts"));
    it->steps = (long long)json_integer_value(
        json_object_get(json_object_get(job, "progress"), "step"));
    /* how many of the run's tightenings reached its lowest basin */
    it->reached = (long long)json_integer_value(
        json_object_get(json_object_get(job, "basins"), "best_reached"));
    const char *error = json_string_value(json_object_get(job, "error"));
    if (error)
        printable(it->message, sizeof it->message, error);
}

static void make_row(item *it)
{
    char rope[32], thick[32], resid[32], secs[32];
    format_number(rope, sizeof rope, it->ropelength);
    format_number(thick, sizeof thick, it->thickness);
    format_number(resid, sizeof resid, it->residual);
    format_number(secs, sizeof secs, it->seconds);
    size_t n = strlen(it->name) + 256;
    free(it->row);
    it->row = malloc(n);
    if (it->row)
        snprintf(it->row, n, "%s\t%lld\t%lld\t%s\t%s\t%s\t%lld\t%lld\t%s\t%lld\t%s\n",
                 it->name, it->components, it->vertices, rope, thick, resid, it->struts,
                 it->steps, secs, it->reached, it->state);
}

/* Submits one file; returns REMOTE_OK, REMOTE_FAILED (the server refused the file:
 * the item is finished as failed), REMOTE_SERVER, or -1 for a full queue. */
static int submit_one(client *c, item *it, const char *query, double *retry)
{
    size_t len = 0;
    char *text = read_file(it->path, &len);
    if (!text) {
        it->phase = ITEM_FINISHED;
        snprintf(it->state, sizeof it->state, "failed");
        snprintf(it->message, sizeof it->message, "cannot read %s: %s", it->path,
                 strerror(errno));
        return REMOTE_FAILED;
    }
    char *escaped = curl_easy_escape(c->curl, it->name, 0);
    char path[4096];
    snprintf(path, sizeof path, "/v1/jobs?name=%s%s", escaped ? escaped : "job", query);
    curl_free(escaped);
    response r = {0};
    bool reached = request(c, "POST", path, "text/plain", text, len, &r);
    free(text);
    int status = REMOTE_OK;
    if (!reached) {
        status = REMOTE_SERVER;
    } else if (r.status == 202) {
        json_t *job = json_loadb(r.body.data, r.body.len, 0, NULL);
        it->job = (long long)json_integer_value(json_object_get(job, "id"));
        it->phase = ITEM_RUNNING;
        json_decref(job);
        if (it->job <= 0) {
            fprintf(stderr, "tightknot remote: the server's answer has no job id\n");
            status = REMOTE_SERVER;
        }
    } else if (r.status == 429 || r.status == 503) {
        *retry = r.retry_after > 0 ? r.retry_after : 5.0;
        status = -1;
    } else if (r.status >= 400 && r.status < 500) {
        it->phase = ITEM_FINISHED;
        snprintf(it->state, sizeof it->state, "refused");
        problem_text(&r, it->message, sizeof it->message);
        status = REMOTE_FAILED;
    } else {
        char detail[256];
        problem_text(&r, detail, sizeof detail);
        fprintf(stderr, "tightknot remote: submitting %s: %s\n", it->name, detail);
        status = REMOTE_SERVER;
    }
    free(r.body.data);
    return status;
}

/* The query string of the run options given on the command line. */
typedef struct run_args {
    char query[1024];
    const char *out;
    size_t parallel;
    double poll;
    size_t count;        /* frames: film frames */
    double every_time;   /* frames: or one every this much flow time */
} run_args;

static const tk_field run_arg_fields[] = {
    TK_FIELD_ROW(run_args, parallel, parallel, SIZE, 4, 1, 1000, "parallel", ""),
    TK_FIELD_ROW(run_args, poll, poll, REAL, 1, 1e-3, 3600, "poll", ""),
    TK_FIELD_ROW(run_args, count, count, SIZE, 200, 2, 1e6, "count", ""),
    TK_FIELD_ROW(run_args, every_time, every_time, REAL, 0, 0, 1e300, "every-time", ""),
};
#define RUN_ARG_NFIELDS (sizeof run_arg_fields / sizeof run_arg_fields[0])

static double now_seconds(void);

/* The batch's progress: the files finished, and the share of their
 * budgets the running ones have spent, with the time left at the pace so
 * far ("37%, about 4 min left"; unknown while no job has a budget). */
static void progress_line(client *c, const item *items, size_t n, const char *last)
{
    double now = now_seconds();
    if (!c->tty && !(c->plain && now - c->last_line >= PLAIN_EVERY))
        return;
    c->last_line = now;
    size_t done = 0, running = 0, failed = 0;
    double share = 0.0;
    bool known = true;
    for (size_t i = 0; i < n; i++) {
        if (items[i].phase == ITEM_RUNNING) {
            running++;
            known = known && items[i].fraction >= 0.0;
            share += fmax(items[i].fraction, 0.0);
        } else if (items[i].phase == ITEM_FINISHED) {
            done++;
            share += 1.0;
            if (strcmp(items[i].state, "done"))
                failed++;
        }
    }
    double p = n ? share / (double)n : 1.0;
    char left[64] = "";
    if (known && p > 0.0 && p < 1.0) {
        double t = (now - c->started) * (1.0 - p) / p;
        if (t < 120.0)
            snprintf(left, sizeof left, ", about %.0f s left", t);
        else
            snprintf(left, sizeof left, ", about %.0f min left", t / 60.0);
    }
    if (!c->tty) {
        fprintf(stderr, "tightknot remote: %3.0f%%%s: %zu/%zu finished, %zu running, %zu failed\n",
                100.0 * p, left, done, n, running, failed);
        return;
    }
    int width = 30;
    int filled = (int)((double)width * p);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < filled ? '=' : ' ';
    bar[width] = '\0';
    fprintf(stderr, "\r[%s] %3.0f%%%s  %zu/%zu finished, %zu running, %zu failed  %-30.30s", bar,
            100.0 * p, left, done, n, running, failed, last ? last : "");
    fflush(stderr);
}

static void report_item(client *c, const item *it)
{
    if (c->tty)
        fputc('\n', stderr);
    if (!strcmp(it->state, "done"))
        fprintf(stderr, "%s: done, ropelength %.6f, %lld steps, %.1f s\n", it->name,
                it->ropelength, it->steps, it->seconds);
    else
        fprintf(stderr, "%s: %s%s%s\n", it->name, it->state, it->message[0] ? ": " : "",
                it->message);
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void pause_for(double seconds)
{
    struct timespec ts = {(time_t)seconds, (long)((seconds - floor(seconds)) * 1e9)};
    nanosleep(&ts, NULL);
}

static int cmd_submit(client *c, const run_args *a, int argc, char **argv)
{
    item *items = NULL;
    size_t n = 0;
    if (argc == 0) {
        fprintf(stderr, "tightknot remote submit: no FILES given\nTry 'tightknot remote --help'.\n");
        return REMOTE_USAGE;
    }
    if (!gather(argc, argv, &items, &n))
        return REMOTE_USAGE;
    if (n == 0) {
        fprintf(stderr, "tightknot remote submit: no .vect files found\n");
        free(items);
        return REMOTE_USAGE;
    }
    if (mkdir(a->out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "tightknot remote: cannot make %s: %s\n", a->out, strerror(errno));
        return REMOTE_FAILED;
    }
    each_row(a->out, "summary.tsv", items, n, take_summary_row);
    each_row(a->out, "jobs.tsv", items, n, take_job_row);
    /* jobs submitted by an earlier run are followed, not submitted again */
    size_t running = 0;
    for (size_t i = 0; i < n; i++)
        if (items[i].phase == ITEM_WAITING && items[i].job > 0) {
            items[i].phase = ITEM_RUNNING;
            running++;
        }
    int status = REMOTE_OK;
    size_t next = 0;
    double wait_until = 0.0;
    bool unreachable = false;
    for (;;) {
        /* submit while there is room */
        while (!unreachable && running < (size_t)a->parallel && now_seconds() >= wait_until) {
            while (next < n && items[next].phase != ITEM_WAITING)
                next++;
            if (next == n)
                break;
            item *it = &items[next];
            double retry = 0.0;
            int rc = submit_one(c, it, a->query, &retry);
            if (rc == -1) {
                wait_until = now_seconds() + retry;
                break;
            }
            if (rc == REMOTE_SERVER) {
                unreachable = true;
                break;
            }
            if (rc == REMOTE_FAILED) {
                report_item(c, it);
                status = REMOTE_FAILED;
                make_row(it);
                save_summary(a->out, items, n);
                continue;
            }
            if (!append_job(a->out, it))
                status = REMOTE_FAILED;
            running++;
        }
        if (unreachable || (running == 0 && next >= n))
            break;
        /* follow the running jobs */
        const char *last = NULL;
        for (size_t i = 0; i < n && !unreachable; i++) {
            item *it = &items[i];
            if (it->phase != ITEM_RUNNING)
                continue;
            char path[64];
            snprintf(path, sizeof path, "/v1/jobs/%lld", it->job);
            response r = {0};
            if (!request(c, "GET", path, NULL, NULL, 0, &r)) {
                unreachable = true;
                free(r.body.data);
                break;
            }
            json_t *job = r.status == 200 ? json_loadb(r.body.data, r.body.len, 0, NULL) : NULL;
            const char *state = json_string_value(json_object_get(job, "state"));
            if (r.status == 404) {
                /* the server lost it (a new store): submit it again */
                it->phase = ITEM_WAITING;
                it->job = 0;
                running--;
                if (next > i)
                    next = i;
            } else if (!state) {
                char detail[256];
                problem_text(&r, detail, sizeof detail);
                fprintf(stderr, "tightknot remote: job %lld: %s\n", it->job, detail);
                unreachable = true;
            } else if (!strcmp(state, "done") || !strcmp(state, "failed") ||
                       !strcmp(state, "cancelled")) {
                finish_item(it, job);
                running--;
                if (!strcmp(state, "done") && !download(c, it->job, a->out, it->name)) {
                    snprintf(it->state, sizeof it->state, "failed");
                    snprintf(it->message, sizeof it->message, "downloading the result failed");
                }
                if (strcmp(it->state, "done"))
                    status = REMOTE_FAILED;
                make_row(it);
                if (!save_summary(a->out, items, n))
                    status = REMOTE_FAILED;
                report_item(c, it);
            } else {
                last = it->name;
                json_t *f = json_object_get(json_object_get(job, "progress"), "fraction");
                it->fraction = json_is_number(f) ? json_number_value(f) : -1.0;
            }
            json_decref(job);
            free(r.body.data);
        }
        progress_line(c, items, n, last);
        if (unreachable)
            break;
        if (running > 0 || wait_until > now_seconds())
            pause_for(a->poll);
    }
    if (c->tty)
        fputc('\n', stderr);
    size_t done = 0, finished = 0;
    for (size_t i = 0; i < n; i++)
        if (items[i].phase == ITEM_FINISHED) {
            finished++;
            done += !strcmp(items[i].state, "done");
        }
    save_summary(a->out, items, n);
    fprintf(stderr, "%zu of %zu files done, %zu failed; summary in %s/summary.tsv\n", done, n,
            finished - done, a->out);
    if (unreachable) {
        fprintf(stderr, "tightknot remote: stopped; run the same command again to resume\n");
        status = REMOTE_SERVER;
    }
    for (size_t i = 0; i < n; i++) {
        free(items[i].path);
        free(items[i].name);
        free(items[i].row);
    }
    free(items);
    return status;
}

static bool parse_job_id(const char *text, long long *id)
{
    char *end = NULL;
    errno = 0;
    *id = strtoll(text, &end, 10);
    if (errno || end == text || *end || *id <= 0) {
        fprintf(stderr, "tightknot remote: '%s' is not a job id (a positive whole number)\n",
                text);
        return false;
    }
    return true;
}

/* One line for a job, as status prints it: id, name, state (or `label`),
 * step, ropelength, residual, and the error of a failed one; every text
 * from the server made printable. */
static void print_job(long long id, json_t *job, const char *label)
{
    char name[512], state[64], error[1024], rope[32], resid[32];
    printable(name, sizeof name, json_string_value(json_object_get(job, "name")));
    printable(state, sizeof state, json_string_value(json_object_get(job, "state")));
    printable(error, sizeof error, json_string_value(json_object_get(job, "error")));
    format_number(rope, sizeof rope, number_or_nan(job, "ropelength"));
    format_number(resid, sizeof resid, number_or_nan(job, "residual"));
    printf("%lld\t%s\t%s\tstep %lld\tropelength %s\tresidual %s%s%s\n", id, name,
           label ? label : state[0] ? state : "?",
           (long long)json_integer_value(json_object_get(json_object_get(job, "progress"), "step")),
           rope, resid, error[0] ? "\terror " : "", error);
}

/* list [STATE]: every job the server shows this client (with tokens, its
 * own), newest first, fetched LIST_PAGE at a time; one line each as
 * status prints, or with --json each job's object on a line. */
#define LIST_PAGE 500

static int cmd_list(client *c, bool json, int argc, char **argv)
{
    if (argc > 1) {
        fprintf(stderr, "tightknot remote list: at most one STATE (queued, running, done, failed "
                        "or cancelled)\nTry 'tightknot remote --help'.\n");
        return REMOTE_USAGE;
    }
    char *state = argc ? curl_easy_escape(c->curl, argv[0], 0) : NULL;
    int status = REMOTE_OK;
    for (long long offset = 0;;) {
        char path[256];
        snprintf(path, sizeof path, "/v1/jobs?limit=%d&offset=%lld%s%s", LIST_PAGE, offset,
                 state ? "&state=" : "", state ? state : "");
        response r = {0};
        if (!request(c, "GET", path, NULL, NULL, 0, &r)) {
            status = REMOTE_SERVER;
            break;
        }
        if (r.status >= 400) {
            char detail[256];
            problem_text(&r, detail, sizeof detail);
            fprintf(stderr, "tightknot remote list: %s\n", detail);
            status = r.status == 400 ? REMOTE_USAGE : REMOTE_SERVER;
            free(r.body.data);
            break;
        }
        json_t *page = json_loadb(r.body.data, r.body.len, 0, NULL);
        free(r.body.data);
        if (!page) {
            fprintf(stderr, "tightknot remote list: the server's answer is not JSON\n");
            status = REMOTE_SERVER;
            break;
        }
        json_t *jobs = json_object_get(page, "jobs"), *job;
        size_t k;
        json_array_foreach(jobs, k, job) {
            if (json) {
                char *text = json_dumps(job, JSON_COMPACT | JSON_PRESERVE_ORDER |
                                                 JSON_REAL_PRECISION(17));
                if (text)
                    printf("%s\n", text);
                free(text);
            } else {
                print_job((long long)json_integer_value(json_object_get(job, "id")), job, NULL);
            }
        }
        size_t n = json_array_size(jobs);
        long long total = (long long)json_integer_value(json_object_get(page, "total"));
        json_decref(page);
        offset += (long long)n;
        if (n == 0 || offset >= total)
            break;
    }
    curl_free(state);
    return status;
}

/* A job's files are named NAME-JOB..., as the page names them: its name
 * with what a file name cannot hold as '_'. */
static void file_base(char *out, size_t size, const json_t *job, long long id)
{
    char name[256];
    printable(name, sizeof name, json_string_value(json_object_get(job, "name")));
    for (char *p = name; *p; p++)
        if (!(isalnum((unsigned char)*p) || *p == '.' || *p == '_' || *p == '-'))
            *p = '_';
    snprintf(out, size, "%s-%lld", name, id);
}

/* GET path as JSON into *out (NULL on failure, said on stderr). */
static int get_json(client *c, const char *path, json_t **out)
{
    response r = {0};
    *out = NULL;
    if (!request(c, "GET", path, NULL, NULL, 0, &r))
        return REMOTE_SERVER;
    int status = REMOTE_OK;
    if (r.status != 200) {
        char detail[256];
        problem_text(&r, detail, sizeof detail);
        fprintf(stderr, "tightknot remote: %s: %s\n", path, detail);
        status = r.status == 404 ? REMOTE_FAILED : REMOTE_SERVER;
    } else if (!(*out = json_loadb(r.body.data, r.body.len, 0, NULL))) {
        fprintf(stderr, "tightknot remote: %s: the answer is not JSON\n", path);
        status = REMOTE_SERVER;
    }
    free(r.body.data);
    return status;
}

/* A frame of the API (its components and flat coordinates) as VECT. */
static bool write_frame(const char *path, const json_t *frame)
{
    json_t *comps = json_object_get(frame, "components"), *xyz = json_object_get(frame, "coordinates");
    size_t n = json_array_size(comps), total = 0;
    size_t *counts = calloc(n ? n : 1, sizeof *counts);
    bool *closed = calloc(n ? n : 1, sizeof *closed);
    bool ok = counts && closed && n > 0;
    for (size_t i = 0; ok && i < n; i++) {
        json_t *one = json_array_get(comps, i);
        counts[i] = (size_t)json_integer_value(json_object_get(one, "vertices"));
        closed[i] = json_is_true(json_object_get(one, "closed"));
        total += counts[i];
    }
    tk_curve *curve = NULL;
    tk_error err;
    ok = ok && json_array_size(xyz) == 3 * total && tk_curve_new(&curve, n, counts, closed, &err) == TK_OK;
    for (size_t i = 0; ok && i < 3 * total; i++)
        curve->xyz[i] = json_number_value(json_array_get(xyz, i));
    FILE *f = ok ? fopen(path, "w") : NULL;
    ok = f && tk_vect_write(curve, f, &err) == TK_OK;
    if (f && fclose(f) != 0)
        ok = false;
    tk_curve_free(&curve);
    free(counts);
    free(closed);
    return ok;
}

/* tightknot remote frames JOB: the job's frames for a film at equal flow
 * time (common/film.h), each frame's time read off its stored steps. */
static int cmd_frames(client *c, const run_args *a, int argc, char **argv)
{
    long long id;
    if (argc != 1) {
        fprintf(stderr, "tightknot remote frames: one JOB\nTry 'tightknot remote --help'.\n");
        return REMOTE_USAGE;
    }
    if (!parse_job_id(argv[0], &id))
        return REMOTE_USAGE;
    char path[128], name[256];
    json_t *job = NULL, *hist = NULL, *frames = json_array();
    snprintf(path, sizeof path, "/v1/jobs/%lld", id);
    int status = frames ? get_json(c, path, &job) : REMOTE_FAILED;
    snprintf(path, sizeof path, "/v1/jobs/%lld/history?limit=2000", id);
    if (status == REMOTE_OK)
        status = get_json(c, path, &hist);
    for (size_t offset = 0; status == REMOTE_OK;) {
        json_t *page = NULL;
        snprintf(path, sizeof path, "/v1/jobs/%lld/frames?offset=%zu&limit=200", id, offset);
        status = get_json(c, path, &page);
        json_t *got = json_object_get(page, "frames");
        size_t k;
        json_t *one;
        json_array_foreach(got, k, one)
            json_array_append(frames, one);
        offset += json_array_size(got);
        bool more = json_array_size(got) > 0 &&
                    offset < (size_t)json_integer_value(json_object_get(page, "total"));
        json_decref(page);
        if (!more)
            break;
    }
    size_t n = json_array_size(frames), nh = 0;
    json_t *steps = json_object_get(hist, "steps");
    long *fsteps = calloc(n + 1, sizeof *fsteps), *hsteps = calloc(json_array_size(steps) + 1, sizeof *hsteps);
    double *times = calloc(n + 1, sizeof *times), *htimes = calloc(json_array_size(steps) + 1, sizeof *htimes);
    if (status == REMOTE_OK && !(fsteps && hsteps && times && htimes))
        status = REMOTE_FAILED;
    for (size_t i = 0; status == REMOTE_OK && i < json_array_size(steps); i++) {
        json_t *t = json_object_get(json_array_get(steps, i), "flow_time");
        if (json_is_number(t)) {
            hsteps[nh] = (long)json_integer_value(json_object_get(json_array_get(steps, i), "step"));
            htimes[nh++] = json_number_value(t);
        }
    }
    if (status == REMOTE_OK && (n == 0 || nh == 0)) {
        fprintf(stderr, "tightknot remote frames: job %lld has %s\n", id,
                n == 0 ? "no frames (it was submitted with every 0)"
                       : "no flow time in its steps (stored by an older daemon)");
        status = REMOTE_FAILED;
    }
    size_t count = 0, *picks = NULL;
    if (status == REMOTE_OK) {
        for (size_t i = 0; i < n; i++)
            fsteps[i] = (long)json_integer_value(json_object_get(json_array_get(frames, i), "step"));
        tk_film_times(fsteps, n, hsteps, htimes, nh, times);
        if (!(picks = tk_film_picks(times, n, a->count, a->every_time, &count))) {
            fprintf(stderr, "tightknot remote frames: %zu frames: too many\n", count);
            status = REMOTE_FAILED;
        }
    }
    if (status == REMOTE_OK && mkdir(a->out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "tightknot remote: cannot make %s: %s\n", a->out, strerror(errno));
        status = REMOTE_FAILED;
    }
    file_base(name, sizeof name, job, id);
    if (status == REMOTE_OK)
        printf("frame\tstep\tflow_time\tfile\n");
    for (size_t k = 0; status == REMOTE_OK && k < count; k++) {
        char file[4400];
        snprintf(file, sizeof file, "%s/%s-frame-%04zu.vect", a->out, name, k + 1);
        if (!write_frame(file, json_array_get(frames, picks[k]))) {
            fprintf(stderr, "tightknot remote: cannot write %s\n", file);
            status = REMOTE_FAILED;
        } else
            printf("%zu\t%ld\t%.17g\t%s\n", k + 1, fsteps[picks[k]], times[picks[k]], file);
    }
    free(picks);
    free(fsteps);
    free(hsteps);
    free(times);
    free(htimes);
    json_decref(job);
    json_decref(hist);
    json_decref(frames);
    return status;
}

static int cmd_jobs(client *c, const char *what, const run_args *a, bool json, int argc,
                    char **argv)
{
    if (argc == 0) {
        fprintf(stderr, "tightknot remote %s: no JOB given\nTry 'tightknot remote --help'.\n",
                what);
        return REMOTE_USAGE;
    }
    int status = REMOTE_OK;
    if (!strcmp(what, "fetch") && mkdir(a->out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "tightknot remote: cannot make %s: %s\n", a->out, strerror(errno));
        return REMOTE_FAILED;
    }
    for (int i = 0; i < argc; i++) {
        long long id;
        if (!parse_job_id(argv[i], &id))
            return REMOTE_USAGE;
        char path[64];
        snprintf(path, sizeof path, "/v1/jobs/%lld", id);
        response r = {0};
        bool cancel = !strcmp(what, "cancel");
        bool remove = !strcmp(what, "delete");
        if (!request(c, "GET", path, NULL, NULL, 0, &r))
            return REMOTE_SERVER;
        /* DELETE cancels a job that goes on and deletes one that has
         * ended: each command does only what its name says. */
        if ((cancel || remove) && r.status == 200) {
            json_t *now = json_loadb(r.body.data, r.body.len, 0, NULL);
            const char *state = json_string_value(json_object_get(now, "state"));
            bool ended = state && strcmp(state, "queued") && strcmp(state, "running");
            bool refuse = ended != remove;
            if (refuse) {
                fprintf(stderr, "tightknot remote: job %lld is %s: %s\n", id,
                        state ? state : "?",
                        remove ? "cancel it first" : "it has already finished (delete removes it)");
                status = REMOTE_FAILED;
            }
            json_decref(now);
            free(r.body.data);
            memset(&r, 0, sizeof r);
            if (refuse)
                continue;
            if (!request(c, "DELETE", path, NULL, NULL, 0, &r))
                return REMOTE_SERVER;
            if (remove && r.status == 204) {
                printf("%lld\tdeleted\n", id);
                free(r.body.data);
                continue;
            }
        }
        if (r.status >= 400) {
            char detail[256];
            problem_text(&r, detail, sizeof detail);
            fprintf(stderr, "tightknot remote: job %lld: %s\n", id, detail);
            status = r.status == 404 || r.status == 409 ? REMOTE_FAILED : REMOTE_SERVER;
            free(r.body.data);
            continue;
        }
        json_t *job = json_loadb(r.body.data, r.body.len, 0, NULL);
        char name[512];
        printable(name, sizeof name, json_string_value(json_object_get(job, "name")));
        if (json && !cancel) {
            printf("%s\n", r.body.data);
        } else if (!strcmp(what, "fetch")) {
            char file[300];
            file_base(file, sizeof file, job, id);
            if (!download(c, id, a->out, file))
                status = REMOTE_FAILED;
            else
                printf("job %lld (%s): %s/%s.vect, %s/%s-struts.json\n", id, name,
                       a->out, file, a->out, file);
        } else {
            print_job(id, job, cancel ? (r.status == 202 ? "cancelling" : "cancelled") : NULL);
        }
        json_decref(job);
        free(r.body.data);
    }
    return status;
}

int tk_remote_main(int argc, char **argv)
{
    const char *server = getenv("TIGHTKNOT_SERVER"), *token = getenv("TIGHTKNOT_TOKEN");
    if (!server || !*server)
        server = "http://127.0.0.1:8080";
    run_args a = {.out = "tightknot-results"};
    tk_cli_defaults(run_arg_fields, RUN_ARG_NFIELDS, &a);
    bool json = false, help = false, progress = false;
    tk_job_options job = TK_JOB_OPTIONS_INIT;
    tk_cli cli = {.n = 0};
    tk_cli_flag(&cli, "help", 'h', &help, NULL);
    tk_cli_flag(&cli, "json", 0, &json, NULL);
    tk_cli_flag(&cli, "progress", 0, &progress, NULL);
    tk_cli_text(&cli, "server", 0, "URL", &server, NULL);
    tk_cli_text(&cli, "token", 0, "TOKEN", &token, NULL);
    const char *cacert = NULL;
    tk_cli_text(&cli, "cacert", 0, "FILE", &cacert, NULL);
    tk_cli_text(&cli, "out", 0, "DIR", &a.out, NULL);
    tk_cli_fields(&cli, run_arg_fields, RUN_ARG_NFIELDS, &a);
    tk_cli_fields(&cli, tk_job_option_fields, tk_job_option_nfields, &job);
    tk_error err;
    int npos = 0;
    if (tk_cli_parse(&cli, argc, argv, &npos, &err)) {
        fprintf(stderr, "tightknot remote: %s\nTry 'tightknot remote --help'.\n", err.message);
        return REMOTE_USAGE;
    }
    if (help) {
        fputs(tk_remote_help, stdout);
        return REMOTE_OK;
    }
    if (npos == 0) {
        fprintf(stderr, "tightknot remote: no COMMAND given (submit, list, status, cancel, delete, "
                        "fetch or frames)\nTry 'tightknot remote --help'.\n");
        return REMOTE_USAGE;
    }
    const char *command = argv[0];
    char **rest = argv + 1;
    int nrest = npos - 1, status = REMOTE_OK;
    /* the options as a query string, only those given or that differ from
     * the defaults, so the server's defaults stay the server's */
    tk_job_options defaults = TK_JOB_OPTIONS_INIT;
    size_t q = 0;
    for (size_t k = 0; k < tk_job_option_nfields; k++) {
        const tk_field *f = &tk_job_option_fields[k];
        double x = tk_field_get(f, &job);
        if (f->name && (x != tk_field_get(f, &defaults) || tk_cli_given(&cli, &job, f->name)) &&
            q < sizeof a.query)
            q += (size_t)(f->kind == TK_KIND_BOOL
                              ? snprintf(a.query + q, sizeof a.query - q, "&%s=%s", f->name,
                                         x != 0.0 ? "true" : "false")
                              : snprintf(a.query + q, sizeof a.query - q, "&%s=%.17g",
                                         f->name, x));
    }

    client c;
    memset(&c, 0, sizeof c);
    size_t blen = strlen(server);
    while (blen > 0 && server[blen - 1] == '/')
        blen--;
    if (strncmp(server, "http://", 7) && strncmp(server, "https://", 8)) {
        fprintf(stderr, "tightknot remote: --server: '%s' is not an http:// or https:// URL\n",
                server);
        return REMOTE_USAGE;
    }
    snprintf(c.base, sizeof c.base, "%.*s", (int)blen, server);
    c.token = token && *token ? token : NULL;
    c.cacert = cacert;
    if (c.token && strcspn(c.token, "\r\n") != strlen(c.token)) {
        fprintf(stderr, "tightknot remote: --token: a token is one line\n");
        return REMOTE_USAGE;
    }
    c.tty = isatty(STDERR_FILENO) != 0;
    c.plain = progress && !c.tty;
    c.started = now_seconds();
    c.last_line = -INFINITY;
    if (curl_global_init(CURL_GLOBAL_DEFAULT) != CURLE_OK || !(c.curl = curl_easy_init())) {
        fprintf(stderr, "tightknot remote: cannot start libcurl\n");
        return REMOTE_FAILED;
    }
    if (!strcmp(command, "submit"))
        status = cmd_submit(&c, &a, nrest, rest);
    else if (!strcmp(command, "list"))
        status = cmd_list(&c, json, nrest, rest);
    else if (!strcmp(command, "status") || !strcmp(command, "cancel") ||
             !strcmp(command, "delete") || !strcmp(command, "fetch"))
        status = cmd_jobs(&c, command, &a, json, nrest, rest);
    else if (!strcmp(command, "frames"))
        status = cmd_frames(&c, &a, nrest, rest);
    else {
        fprintf(stderr, "tightknot remote: unknown command '%s' (submit, list, status, "
                        "cancel, delete, fetch or frames)\nTry 'tightknot remote --help'.\n",
                command);
        status = REMOTE_USAGE;
    }
    curl_easy_cleanup(c.curl);
    curl_global_cleanup();
    return status;
}
