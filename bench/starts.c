/* Starts that are not the catalogue's: for each knot or link type with a
 * best known ropelength, several starts (the catalogue file, a disguised
 * copy of it, parametric curves of the same type, disguised in turn) are
 * tightened at the same resolution for the same wall time, and each run
 * prints its final ropelength, its excess over the best known value, when
 * it came within 0.5% and 0.1% of it on its final polygon, the escapes it
 * tried and how many improved, the share of its time spent on its knot
 * type (the start's and every resampled or deformed curve's invariants),
 * and why it stopped (a run whose knot type changed fails, and says so
 * there).  Two starts of one type that end apart found different
 * critical configurations: at most one is tight.
 * Prints figures; never fails on time.
 *
 * With --atlas each start is tightened instead to the vertex count of the
 * public atlas's polygon of its type (the vertices option) for S seconds
 * (default 600), and judged against the atlas's value at that count:
 * "within.1%" and "at.atlas" (at or below it).
 *
 * With --seeds K each start runs K times, with the escapes' seeds 1 to K,
 * and a summary gives each start's lowest, median and highest final
 * ropelength and how many of its runs ended within 0.1% of the best known
 * value (at or below the atlas's with --atlas): one run says little of
 * how often the escapes find the tight basin.
 *
 *   bench/starts [CATALOGUE_DIR] [--seconds S] [--resolution R] [--jobs N]
 *                [--atlas] [--seeds K] [--escapes E] [--cpu-time] [--list]
 *                [START ...]
 */
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/tighten.h"
#include "tk/vect.h"

/* Best known ropelengths (length / tube radius) of the public atlas of
 * tight knots at its vertex counts, and exact values. */
#define ROPE_3_1 32.743665
#define ROPE_4_1 42.09703
#define ROPE_5_1 47.21489
#define ROPE_6_1 56.71771
#define ROPE_8_19 60.99699
#define ROPE_10_124 71.08937
#define ROPE_HOPF 25.132741228718345 /* 8 pi */
#define ROPE_CHAIN3 41.69911184307752 /* 12 pi + 4 */

/* The atlas's polygons: vertex count and ropelength. */
static const struct {
    const char *type;
    size_t vertices;
    double ropelength;
} atlas[] = {{"3_1", 2400, ROPE_3_1},   {"4_1", 400, ROPE_4_1},   {"5_1", 392, ROPE_5_1},
             {"6_1", 480, ROPE_6_1},    {"8_19", 489, ROPE_8_19}, {"10_124", 576, ROPE_10_124},
             {"Hopf", 202, 25.14142}};

typedef enum maker { FILE_START, TORUS, FIGURE_EIGHT, LISSAJOUS, HOPF, CHAIN } maker;

/* A start: a catalogue file or a generator, then a disguise (seed 0: none). */
typedef struct start {
    const char *name;
    const char *type;
    double best;
    maker make;
    const char *file;   /* FILE_START: the catalogue's name */
    int p, q;           /* TORUS */
    size_t vertices;    /* generators: per component (0: default) */
    unsigned long long seed;
    double perturbation;
    int freq[3];        /* LISSAJOUS */
    double phase[3];
} start;

static const start starts[] = {
    {"3.1", "3_1", ROPE_3_1, FILE_START, "3.1", 0, 0, 0, 0, 0},
    {"3.1~", "3_1", ROPE_3_1, FILE_START, "3.1", 0, 0, 0, 11, 0.05},
    {"T(2,3)", "3_1", ROPE_3_1, TORUS, NULL, 2, 3, 120, 0, 0},
    {"T(2,3)~", "3_1", ROPE_3_1, TORUS, NULL, 2, 3, 120, 12, 0.01},
    {"4.1", "4_1", ROPE_4_1, FILE_START, "4.1", 0, 0, 0, 0, 0},
    {"4.1~", "4_1", ROPE_4_1, FILE_START, "4.1", 0, 0, 0, 13, 0.05},
    {"fig8", "4_1", ROPE_4_1, FIGURE_EIGHT, NULL, 0, 0, 200, 0, 0},
    {"fig8~", "4_1", ROPE_4_1, FIGURE_EIGHT, NULL, 0, 0, 200, 14, 0.01},
    {"5.1", "5_1", ROPE_5_1, FILE_START, "5.1", 0, 0, 0, 0, 0},
    {"T(2,5)", "5_1", ROPE_5_1, TORUS, NULL, 2, 5, 200, 0, 0},
    {"T(2,5)~", "5_1", ROPE_5_1, TORUS, NULL, 2, 5, 200, 15, 0.01},
    {"6.1", "6_1", ROPE_6_1, FILE_START, "6.1", 0, 0, 0, 0, 0},
    {"6.1~", "6_1", ROPE_6_1, FILE_START, "6.1", 0, 0, 0, 16, 0.05},
    {"L(3,2,5)", "6_1", ROPE_6_1, LISSAJOUS, NULL, 0, 0, 300, 0, 0, {3, 2, 5}, {0.7, 0.2, 0}},
    {"L(3,2,5)~", "6_1", ROPE_6_1, LISSAJOUS, NULL, 0, 0, 300, 21, 0.01, {3, 2, 5}, {0.7, 0.2, 0}},
    {"8.19", "8_19", ROPE_8_19, FILE_START, "8.19", 0, 0, 0, 0, 0},
    {"T(3,4)", "8_19", ROPE_8_19, TORUS, NULL, 3, 4, 240, 0, 0},
    {"T(3,4)~", "8_19", ROPE_8_19, TORUS, NULL, 3, 4, 240, 17, 0.01},
    {"10.124", "10_124", ROPE_10_124, FILE_START, "10.124", 0, 0, 0, 0, 0},
    {"T(3,5)", "10_124", ROPE_10_124, TORUS, NULL, 3, 5, 300, 0, 0},
    {"T(3,5)~", "10_124", ROPE_10_124, TORUS, NULL, 3, 5, 300, 18, 0.01},
    {"7.1", "7_1", NAN, FILE_START, "7.1", 0, 0, 0, 0, 0},
    {"T(2,7)", "7_1", NAN, TORUS, NULL, 2, 7, 280, 0, 0},
    {"2.2.1", "Hopf", ROPE_HOPF, FILE_START, "2.2.1", 0, 0, 0, 0, 0},
    {"hopf~", "Hopf", ROPE_HOPF, HOPF, NULL, 0, 0, 60, 19, 0.01},
    {"chain3~", "chain3", ROPE_CHAIN3, CHAIN, NULL, 0, 0, 60, 20, 0.01},
};
#define NSTARTS (sizeof starts / sizeof starts[0])

static tk_curve *make_start(const start *s, const char *dir, tk_error *err)
{
    tk_curve *c = NULL, *d = NULL;
    int rc = TK_OK;
    char path[4096];
    switch (s->make) {
    case FILE_START:
        snprintf(path, sizeof path, "%s/%s.vect", dir, s->file);
        rc = tk_vect_read_file(path, NULL, &c, err);
        break;
    case TORUS:
        rc = tk_generate_torus(s->p, s->q, s->vertices, &c, err);
        break;
    case FIGURE_EIGHT:
        rc = tk_generate_figure_eight(s->vertices, &c, err);
        break;
    case LISSAJOUS:
        rc = tk_generate_lissajous(s->freq, s->phase, s->vertices, &c, err);
        break;
    case HOPF:
        rc = tk_generate_hopf(s->vertices, &c, err);
        break;
    case CHAIN:
        rc = tk_generate_chain(3, s->vertices, &c, err);
        break;
    }
    if (rc != TK_OK || s->seed == 0)
        return rc == TK_OK ? c : NULL;
    rc = tk_generate_disguise(c, s->seed, s->perturbation, &d, err);
    tk_curve_free(&c);
    return rc == TK_OK ? d : NULL;
}

typedef struct bench {
    const char *dir;
    double seconds, resolution;
    bool atlas;
    bool cpu_time; /* the seconds are each run's processor time */
    long seeds;   /* runs of each start, seeds 1 to seeds */
    long escapes; /* the escapes option; < 0: its default */
    const start *todo[NSTARTS];
    size_t ntodo, next; /* runs: next / seeds is the start, next % seeds + 1 its seed */
    double *rope;       /* each run's final ropelength, NAN if it failed */
    bool *close;        /* each run within the summary's margin */
    pthread_mutex_t lock;
} bench;

static void describe(char *buf, size_t size, double t)
{
    if (t < 0.0)
        snprintf(buf, size, "never");
    else
        snprintf(buf, size, "%.1fs", t);
}

/* One run of start s with the given seed; its row printed, its figures
 * kept at b->rope[slot] and b->close[slot]. */
static void run_start(bench *b, const start *s, unsigned long long seed, size_t slot)
{
    tk_error err;
    char line[512];
    tk_curve *c = make_start(s, b->dir, &err);
    if (!c) {
        snprintf(line, sizeof line, "%-9s %-7s %4llu start failed: %s\n", s->name, s->type,
                 seed, err.message);
        pthread_mutex_lock(&b->lock);
        fputs(line, stdout);
        fflush(stdout);
        pthread_mutex_unlock(&b->lock);
        return;
    }
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.seed = seed;
    if (b->escapes >= 0)
        o.escapes = (int)b->escapes;
    o.resolution = b->resolution;
    o.max_seconds = b->seconds;
    o.cpu_time = b->cpu_time;
    double best = s->best, margin[2] = {0.005, 0.001};
    for (size_t k = 0; b->atlas && k < sizeof atlas / sizeof atlas[0]; k++)
        if (!strcmp(atlas[k].type, s->type)) {
            o.resolution = 0.0;
            o.vertices = atlas[k].vertices;
            best = atlas[k].ropelength;
            margin[0] = 0.001;
            margin[1] = 0.0;
        }
    if (b->atlas && o.vertices == 0) {
        snprintf(line, sizeof line, "%-9s %-7s %4llu no atlas polygon of this type\n", s->name,
                 s->type, seed);
        pthread_mutex_lock(&b->lock);
        fputs(line, stdout);
        fflush(stdout);
        pthread_mutex_unlock(&b->lock);
        tk_curve_free(&c);
        return;
    }
    tk_run *run = NULL;
    int rc = tk_run_new(c, &o, &run, &err);
    tk_stop_reason why = TK_STOP_NONE;
    if (rc == TK_OK)
        rc = tk_run_until(run, &why, &err);
    if (!run) {
        snprintf(line, sizeof line, "%-9s %-7s %4llu refused: %s\n", s->name, s->type, seed,
                 err.message);
    } else {
        const tk_step_report *last = tk_run_latest(run);
        size_t nh = 0, ne = 0;
        const tk_step_report *h = tk_run_history(run, &nh);
        const tk_escape *e = tk_run_escapes(run, &ne);
        size_t improved = 0;
        for (size_t k = 0; k < ne; k++)
            improved += e[k].improved;
        /* the crossings count on the final polygon, whose count the
         * best known value's excess is about */
        double within[2] = {-1.0, -1.0};
        for (size_t i = 0; i < nh && isfinite(best); i++)
            for (int k = 0; k < 2; k++)
                if (within[k] < 0.0 && h[i].vertices == last->vertices &&
                    h[i].ropelength <= best * (1.0 + margin[k]))
                    within[k] = h[i].seconds;
        char excess[16] = "-", w5[16], w1[16];
        if (isfinite(best))
            snprintf(excess, sizeof excess, "%+.3f%%", 100.0 * (last->ropelength / best - 1.0));
        describe(w5, sizeof w5, within[0]);
        describe(w1, sizeof w1, within[1]);
        tk_run_timing t;
        tk_run_timing_get(run, &t);
        char rescaled[48] = "0";
        if (t.rescales > 0)
            snprintf(rescaled, sizeof rescaled, "%ld<%.1e", t.rescales, t.largest_rescale);
        snprintf(line, sizeof line,
                 "%-9s %-7s %4llu %8zu %8ld %11.5f %10s %9s %9s %5zu %5zu %6ld %11s %7.3f%%  "
                 "%s%s%s\n",
                 s->name, s->type, seed, last->vertices, last->step, last->ropelength, excess, w5,
                 w1, ne, improved, t.undone_steps, rescaled,
                 t.total > 0.0 ? 100.0 * t.invariants / t.total : 0.0, tk_stop_reason_name(why),
                 rc ? ": " : "", rc ? err.message : "");
        if (rc == TK_OK) {
            b->rope[slot] = last->ropelength;
            b->close[slot] = last->ropelength <= best * (1.0 + margin[1]);
        }
    }
    pthread_mutex_lock(&b->lock);
    fputs(line, stdout);
    fflush(stdout);
    pthread_mutex_unlock(&b->lock);
    tk_run_free(&run);
    tk_curve_free(&c);
}

static void *worker(void *arg)
{
    bench *b = arg;
    for (;;) {
        pthread_mutex_lock(&b->lock);
        size_t runs = b->ntodo * (size_t)b->seeds;
        size_t k = b->next < runs ? b->next++ : SIZE_MAX;
        pthread_mutex_unlock(&b->lock);
        if (k == SIZE_MAX)
            return NULL;
        run_start(b, b->todo[k / (size_t)b->seeds], (unsigned long long)(k % (size_t)b->seeds) + 1,
                  k);
    }
}

static int by_value(const void *x, const void *y)
{
    double a = *(const double *)x, c = *(const double *)y;
    return (a > c) - (a < c);
}

/* Each start's runs over the seeds: lowest, median and highest final
 * ropelength (runs that failed left out) and how many ended close. */
static void summary(const bench *b)
{
    size_t seeds = (size_t)b->seeds;
    double *sorted = malloc(seeds * sizeof *sorted);
    if (!sorted)
        return;
    printf("\n%-9s %-7s %5s %11s %11s %11s  %s\n", "start", "type", "runs", "lowest", "median",
           "highest", b->atlas ? "at.atlas" : "within.1%");
    for (size_t s = 0; s < b->ntodo; s++) {
        size_t n = 0, close = 0;
        for (size_t k = s * seeds; k < (s + 1) * seeds; k++) {
            if (!isnan(b->rope[k]))
                sorted[n++] = b->rope[k];
            close += b->close[k];
        }
        if (n == 0) {
            printf("%-9s %-7s %5zu %11s %11s %11s  -\n", b->todo[s]->name, b->todo[s]->type, n,
                   "-", "-", "-");
            continue;
        }
        qsort(sorted, n, sizeof *sorted, by_value);
        double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
        char count[32] = "-";
        if (isfinite(b->todo[s]->best))
            snprintf(count, sizeof count, "%zu of %zu", close, n);
        printf("%-9s %-7s %5zu %11.5f %11.5f %11.5f  %s\n", b->todo[s]->name, b->todo[s]->type,
               n, sorted[0], median, sorted[n - 1], count);
    }
    free(sorted);
}

/* *out = text as a whole number within [least, most]; false if it is not. */
static bool count_arg(const char *text, long least, long most, long *out)
{
    char *end;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || v < least || v > most)
        return false;
    *out = v;
    return true;
}

int main(int argc, char **argv)
{
    bench b = {.dir = "../shared/catalogue", .seconds = 120.0, .resolution = 5.0, .seeds = 1,
               .escapes = -1};
    bool seconds_given = false;
    long jobs = 2;
    pthread_mutex_init(&b.lock, NULL);
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            printf("usage: starts [CATALOGUE_DIR] [--seconds S] [--resolution R] [--jobs N]\n"
                   "              [--atlas] [--seeds K] [--escapes E] [--cpu-time] [--list]\n"
                   "              [START ...]\n"
                   "Tightens each start (default: all; --list names them) at resolution R\n"
                   "(default 5) for S seconds (default 120), N at a time (default 2), and\n"
                   "prints its final ropelength, its excess over the best known value and\n"
                   "when it came within 0.5%% and 0.1%% of it on its final polygon, with\n"
                   "the steps error recovery undid and its rescales of the whole curve\n"
                   "(count<largest factor - 1).\n"
                   "--atlas: each at the atlas's vertex count of its type instead, for S\n"
                   "seconds (default 600), against the atlas's value.\n"
                   "--seeds K: each start K times, with the escapes' seeds 1 to K (default\n"
                   "1), then each start's lowest, median and highest ropelength and how\n"
                   "many runs ended within 0.1%% of the best known value (with --atlas: at\n"
                   "or below the atlas's).\n"
                   "--escapes E: the tighten option (default: tighten's).\n"
                   "--cpu-time: S seconds of each run's processor time, not the wall\n"
                   "clock's (the tighten option), so that runs beside other work do what\n"
                   "they do alone.\n");
            return 0;
        } else if (strcmp(argv[i], "--atlas") == 0) {
            b.atlas = true;
        } else if (strcmp(argv[i], "--cpu-time") == 0) {
            b.cpu_time = true;
        } else if (strcmp(argv[i], "--list") == 0) {
            for (size_t k = 0; k < NSTARTS; k++)
                printf("%-9s %-7s %s\n", starts[k].name, starts[k].type,
                       starts[k].make == FILE_START ? "catalogue" : "generated");
            return 0;
        } else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
            b.seconds = strtod(argv[++i], NULL);
            seconds_given = true;
        } else if (strcmp(argv[i], "--resolution") == 0 && i + 1 < argc) {
            b.resolution = strtod(argv[++i], NULL);
        } else if (strcmp(argv[i], "--jobs") == 0 && i + 1 < argc) {
            jobs = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--seeds") == 0 && i + 1 < argc) {
            if (!count_arg(argv[++i], 1, 1000, &b.seeds)) {
                fprintf(stderr, "starts: --seeds takes 1 to 1000\n");
                return 2;
            }
        } else if (strcmp(argv[i], "--escapes") == 0 && i + 1 < argc) {
            if (!count_arg(argv[++i], 0, 1000, &b.escapes)) {
                fprintf(stderr, "starts: --escapes takes 0 to 1000\n");
                return 2;
            }
        } else if (strchr(argv[i], '/') || strcmp(argv[i], ".") == 0) {
            b.dir = argv[i];
        } else {
            size_t k = 0;
            while (k < NSTARTS && strcmp(starts[k].name, argv[i]) != 0)
                k++;
            if (k == NSTARTS) {
                fprintf(stderr, "starts: no start '%s' (--list names them)\n", argv[i]);
                return 2;
            }
            b.todo[b.ntodo++] = &starts[k];
        }
    }
    if (b.ntodo == 0)
        for (size_t k = 0; k < NSTARTS; k++)
            b.todo[b.ntodo++] = &starts[k];
    if (jobs < 1 || jobs > 64)
        jobs = 1;
    if (b.atlas && !seconds_given)
        b.seconds = 600.0;
    if (b.atlas)
        printf("starts at the atlas's vertex counts, %.0f s each, %ld at a time; excess over "
               "the atlas's value at that count; within: first time on the final polygon\n\n",
               b.seconds, jobs);
    else
        printf("starts at resolution %g, %.0f s each, %ld at a time; excess over the best known "
               "value; within: first time on the final polygon\n\n",
               b.resolution, b.seconds, jobs);
    printf("%-9s %-7s %4s %8s %8s %11s %10s %9s %9s %5s %5s %6s %11s %8s  %s\n", "start",
           "type", "seed", "vertices", "steps", "ropelength", "excess",
           b.atlas ? "within.1%" : "within.5%", b.atlas ? "at.atlas" : "within.1%", "esc", "impr",
           "undone", "rescaled", "inv.time", "stop");
    fflush(stdout);
    size_t runs = b.ntodo * (size_t)b.seeds;
    b.rope = malloc(runs * sizeof *b.rope);
    b.close = calloc(runs, sizeof *b.close);
    if (!b.rope || !b.close) {
        fprintf(stderr, "starts: out of memory\n");
        return 1;
    }
    for (size_t k = 0; k < runs; k++)
        b.rope[k] = NAN;
    pthread_t th[64];
    for (long k = 0; k < jobs; k++)
        pthread_create(&th[k], NULL, worker, &b);
    for (long k = 0; k < jobs; k++)
        pthread_join(th[k], NULL);
    if (b.seeds > 1)
        summary(&b);
    free(b.rope);
    free(b.close);
    pthread_mutex_destroy(&b.lock);
    return 0;
}
