/* tightknot frames: a film's frames at equal flow time from a run's
 * snapshots and its log (tightknot tighten --snapshots DIR --log LOG). */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "film.h"
#include "frames.h"

enum { FRAMES_OK = 0, FRAMES_USAGE = 1, FRAMES_INPUT = 2 };

const char tk_frames_help[] =
    "usage: tightknot frames LOG DIR [--count N | --every-time T] [-o OUT]\n"
    "\n"
    "Picks a film's frames at equal flow time, as the paper's films are\n"
    "(\"each frame represents a constant amount of simulation time\"), from\n"
    "a run's snapshots and log:\n"
    "  tightknot tighten 3.1 --steps 3000 --snapshots DIR --every 10 --log LOG\n"
    "LOG gives each step's flow time (its flow_time column: the step sizes\n"
    "summed), DIR holds the snapshots (step-NNNNNN.vect).  Film frame k is\n"
    "the snapshot whose flow time is nearest the first's plus k times the\n"
    "film's time step (a snapshot repeats where they are sparser than that);\n"
    "each is copied to OUT/frame-KKKK.vect, and a line per film frame (frame,\n"
    "step, flow_time, file) goes to standard output.  For a job's frames on a\n"
    "server: tightknot remote frames JOB.\n"
    "\n"
    "Options:\n"
    "  --count N         this many film frames, the first snapshot to the last\n"
    "                    (default 200)\n"
    "  --every-time T    a film frame every T of flow time instead\n"
    "  -o, --out OUT     the directory for the frames (default frames)\n"
    "  -h, --help        show this help\n"
    "\n"
    "Exit status: 0 success, 1 usage error, 2 bad input.\n";

typedef struct frames_args {
    size_t count;
    double every_time;
} frames_args;

static const tk_field frames_fields[] = {
    TK_FIELD_ROW(frames_args, count, count, SIZE, 200, 2, 1e6, "count", ""),
    TK_FIELD_ROW(frames_args, every_time, every_time, REAL, 0, 0, 1e300, "every-time", ""),
};

typedef struct snapshot {
    long step;
    double flow_time;
    char *file;
} snapshot;

static int by_step(const void *a, const void *b)
{
    long x = ((const snapshot *)a)->step, y = ((const snapshot *)b)->step;
    return (x > y) - (x < y);
}

/* The snapshots of dir, by step: *out (n of them); FRAMES_INPUT and a
 * message when the directory cannot be read or holds none. */
static int read_snapshots(const char *dir, snapshot **out, size_t *n)
{
    *out = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "tightknot frames: %s: %s\n", dir, strerror(errno));
        return FRAMES_INPUT;
    }
    size_t cap = 0;
    struct dirent *e;
    int status = FRAMES_OK;
    while (status == FRAMES_OK && (e = readdir(d))) {
        long step;
        char tail[8];
        if (sscanf(e->d_name, "step-%ld.%7s", &step, tail) != 2 || strcmp(tail, "vect"))
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            snapshot *grown = realloc(*out, cap * sizeof *grown);
            if (!grown) {
                status = FRAMES_INPUT;
                break;
            }
            *out = grown;
        }
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        char *file = malloc(len);
        if (!file) {
            status = FRAMES_INPUT;
            break;
        }
        snprintf(file, len, "%s/%s", dir, e->d_name);
        (*out)[(*n)++] = (snapshot){step, NAN, file};
    }
    closedir(d);
    if (status != FRAMES_OK)
        fprintf(stderr, "tightknot frames: out of memory\n");
    else if (*n == 0) {
        fprintf(stderr, "tightknot frames: %s holds no snapshot (step-NNNNNN.vect)\n", dir);
        status = FRAMES_INPUT;
    } else
        qsort(*out, *n, sizeof **out, by_step);
    return status;
}

/* The flow time of each snapshot, from the log's step and flow_time
 * columns (its header names them). */
static int read_log(const char *path, snapshot *s, size_t n)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "tightknot frames: %s: %s\n", path, strerror(errno));
        return FRAMES_INPUT;
    }
    char line[8192];
    int col_step = -1, col_flow = -1, status = FRAMES_OK;
    if (fgets(line, sizeof line, f)) {
        int k = 0;
        for (char *tok = strtok(line, "\t\n"); tok; tok = strtok(NULL, "\t\n"), k++) {
            if (!strcmp(tok, "step"))
                col_step = k;
            else if (!strcmp(tok, "flow_time"))
                col_flow = k;
        }
    }
    if (col_step < 0 || col_flow < 0) {
        fprintf(stderr, "tightknot frames: %s:1: no step and flow_time columns (a log of "
                        "'tightknot tighten --log')\n", path);
        fclose(f);
        return FRAMES_INPUT;
    }
    for (long lineno = 2; fgets(line, sizeof line, f); lineno++) {
        double step = NAN, flow = NAN;
        int k = 0;
        for (char *tok = strtok(line, "\t\n"); tok; tok = strtok(NULL, "\t\n"), k++) {
            if (k == col_step)
                step = strtod(tok, NULL);
            else if (k == col_flow)
                flow = strtod(tok, NULL);
        }
        if (!isfinite(step) || !isfinite(flow)) {
            fprintf(stderr, "tightknot frames: %s:%ld: no step or flow_time\n", path, lineno);
            status = FRAMES_INPUT;
            break;
        }
        /* a step reported again (a best put back) keeps its first time */
        snapshot key = {(long)step, 0, NULL};
        snapshot *hit = bsearch(&key, s, n, sizeof *s, by_step);
        if (hit && isnan(hit->flow_time))
            hit->flow_time = flow;
    }
    fclose(f);
    for (size_t i = 0; status == FRAMES_OK && i < n; i++)
        if (isnan(s[i].flow_time)) {
            fprintf(stderr, "tightknot frames: %s has no step %ld (the snapshot %s)\n", path,
                    s[i].step, s[i].file);
            status = FRAMES_INPUT;
        }
    for (size_t i = 1; status == FRAMES_OK && i < n; i++)
        if (s[i].flow_time < s[i - 1].flow_time) {
            fprintf(stderr, "tightknot frames: %s: the flow time falls from step %ld to %ld\n",
                    path, s[i - 1].step, s[i].step);
            status = FRAMES_INPUT;
        }
    return status;
}

static int copy_file(const char *from, const char *to)
{
    FILE *in = fopen(from, "rb"), *out = in ? fopen(to, "wb") : NULL;
    char buf[65536];
    size_t got;
    int ok = in && out;
    while (ok && (got = fread(buf, 1, sizeof buf, in)) > 0)
        ok = fwrite(buf, 1, got, out) == got;
    ok = ok && !ferror(in);
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        ok = 0;
    if (!ok)
        fprintf(stderr, "tightknot frames: copying %s to %s: %s\n", from, to, strerror(errno));
    return ok ? FRAMES_OK : FRAMES_INPUT;
}

int tk_frames_main(int argc, char **argv)
{
    frames_args a;
    tk_cli_defaults(frames_fields, 2, &a);
    bool help = false;
    const char *out = "frames";
    tk_cli cli = {.n = 0};
    tk_cli_flag(&cli, "help", 'h', &help, NULL);
    tk_cli_text(&cli, "out", 'o', "OUT", &out, NULL);
    tk_cli_fields(&cli, frames_fields, 2, &a);
    tk_error err;
    int npos = 0;
    if (tk_cli_parse(&cli, argc, argv, &npos, &err)) {
        fprintf(stderr, "tightknot frames: %s\nTry 'tightknot frames --help'.\n", err.message);
        return FRAMES_USAGE;
    }
    if (help) {
        fputs(tk_frames_help, stdout);
        return FRAMES_OK;
    }
    if (npos != 2) {
        fprintf(stderr, "tightknot frames: give LOG and DIR\nTry 'tightknot frames --help'.\n");
        return FRAMES_USAGE;
    }
    snapshot *s = NULL;
    size_t n = 0;
    int status = read_snapshots(argv[1], &s, &n);
    if (status == FRAMES_OK)
        status = read_log(argv[0], s, n);
    if (status == FRAMES_OK && mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "tightknot frames: cannot make %s: %s\n", out, strerror(errno));
        status = FRAMES_INPUT;
    }
    double *times = status == FRAMES_OK ? malloc(n * sizeof *times) : NULL;
    size_t count = 0, *picks = NULL;
    if (times) {
        for (size_t i = 0; i < n; i++)
            times[i] = s[i].flow_time;
        picks = tk_film_picks(times, n, a.count, a.every_time, &count);
    }
    if (status == FRAMES_OK && !picks) {
        fprintf(stderr, "tightknot frames: %zu frames: too many\n", count);
        status = FRAMES_INPUT;
    }
    if (status == FRAMES_OK)
        printf("frame\tstep\tflow_time\tfile\n");
    for (size_t k = 0; status == FRAMES_OK && k < count; k++) {
        char to[4200];
        snprintf(to, sizeof to, "%s/frame-%04zu.vect", out, k + 1);
        const snapshot *p = &s[picks[k]];
        status = copy_file(p->file, to);
        if (status == FRAMES_OK)
            printf("%zu\t%ld\t%.17g\t%s\n", k + 1, p->step, p->flow_time, to);
    }
    free(picks);
    free(times);
    for (size_t i = 0; i < n; i++)
        free(s[i].file);
    free(s);
    return status;
}
