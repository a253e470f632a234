/* The weights of a budget of work, fitted again on this machine: each
 * knot is tightened for S seconds of its own processor time (resolution
 * 5, or KNOT@V: V vertices in all), and each stretch of 200 steps gives
 * a row, the operations it counted (tk_run_timing's work) and the
 * processor seconds it took.  The weights that make the counts best add
 * up to the seconds (least squares, none negative: the engine's own NNLS
 * solver) are printed beside those engine/queries.c uses (from the
 * reports' work), and for each run and each of its vertex counts, the
 * seconds against the work the engine counted and against the fit's.
 * On the machine the engine's weights were fitted on, both ratios are
 * near 1; on another, the engine's ratio says how much faster or slower
 * it is.  Prints figures; never fails on time.
 *
 *   bench/workfit [CATALOGUE_DIR] [--seconds S] [KNOT[@V] ...]
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tk/nnls.h"
#include "tk/tighten.h"
#include "tk/vect.h"

#define STRETCH 200
#define NCOUNTS 8
#define MOST_ROWS 100000

static const char *count_names[NCOUNTS] = {"checks", "columns", "pivots", "factors",
                                           "newton", "turns",   "deforms", "flops"};

static void counts_of(const tk_work_counts *w, double *out)
{
    const double in[NCOUNTS] = {w->checks, w->columns, w->pivots, w->factors,
                                w->newton, w->turns,   w->deforms, w->flops};
    memcpy(out, in, sizeof in);
}

typedef struct {
    double counts[NCOUNTS];
    double seconds, work;
    int run;
    size_t vertices;
} row;

static const char *default_knots[] = {"2.2.1", "3.1",  "4.1",    "6.3.2",  "7.4",
                                      "8.2.4", "9.23", "10.124", "3.1@2400", "5.1@1200"};

static void usage(void)
{
    fprintf(stderr, "usage: bench/workfit [CATALOGUE_DIR] [--seconds S] [KNOT[@V] ...]\n"
                    "Tightens each knot (default 2.2.1 3.1 4.1 6.3.2 7.4 8.2.4 9.23 10.124\n"
                    "at resolution 5, 3.1@2400 and 5.1@1200 at 2,400 and 1,200 vertices) for S\n"
                    "seconds of processor time (default 30), fits the weights of the work's\n"
                    "counts to the seconds of each 200 steps and prints them, and each run's\n"
                    "seconds against the work the engine counted and the fit's.\n");
}

/* Rows of one run of `knot` into rows[*n ..]. */
static int tighten(const char *dir, const char *knot, int index, double seconds, row *rows,
                   size_t *n)
{
    char name[256], path[1024];
    snprintf(name, sizeof name, "%s", knot);
    char *at = strchr(name, '@');
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.cpu_time = true;
    o.max_seconds = seconds;
    o.resolution = 5.0;
    if (at) {
        *at = '\0';
        o.resolution = 0.0;
        o.vertices = (size_t)strtoul(at + 1, NULL, 10);
    }
    snprintf(path, sizeof path, "%s/%s.vect", dir, name);
    tk_curve *c = NULL;
    tk_run *run = NULL;
    tk_error err;
    if (tk_vect_read_file(path, NULL, &c, &err) != TK_OK ||
        tk_run_new(c, &o, &run, &err) != TK_OK) {
        fprintf(stderr, "bench/workfit: %s\n", err.message);
        tk_curve_free(&c);
        return 1;
    }
    tk_run_timing t;
    tk_run_timing_get(run, &t);
    double before[NCOUNTS], after[NCOUNTS];
    counts_of(&t.work, before);
    tk_step_report last = *tk_run_latest(run);
    long taken = 0; /* steps in the stretch under way */
    int rc = TK_OK;
    while (rc == TK_OK && tk_run_stop_reason(run) == TK_STOP_NONE && *n < MOST_ROWS) {
        rc = tk_run_step(run, &err);
        const tk_step_report *s = tk_run_latest(run);
        bool stopped = rc != TK_OK || tk_run_stop_reason(run) != TK_STOP_NONE;
        /* a stretch ends every STRETCH steps and where the polygon changes */
        if (++taken < STRETCH && !stopped && s->vertices == last.vertices)
            continue;
        taken = 0;
        tk_run_timing_get(run, &t);
        counts_of(&t.work, after);
        row *r = &rows[(*n)++];
        for (int k = 0; k < NCOUNTS; k++)
            r->counts[k] = after[k] - before[k];
        r->seconds = s->seconds - last.seconds;
        r->work = s->work - last.work;
        r->run = index;
        r->vertices = last.vertices;
        memcpy(before, after, sizeof before);
        last = *s;
    }
    if (rc != TK_OK)
        fprintf(stderr, "bench/workfit: %s: %s\n", knot, err.message);
    printf("%-10s %8ld steps, ropelength %.6f\n", knot, tk_run_latest(run)->step,
           tk_run_latest(run)->ropelength);
    fflush(stdout);
    tk_run_free(&run);
    tk_curve_free(&c);
    return rc != TK_OK;
}

/* The weights w >= 0 that minimise |A w - seconds| over the rows, the
 * columns scaled to unit norm for the solve. */
static int fit(const row *rows, size_t n, double *w)
{
    tk_nnls *s = NULL;
    tk_error err;
    if (tk_nnls_new(&s, &err) != TK_OK)
        return 1;
    cholmod_common *cc = tk_nnls_common(s);
    cholmod_sparse *a = cholmod_allocate_sparse(n, NCOUNTS, n * NCOUNTS, 1, 1, 0, CHOLMOD_REAL, cc);
    double *b = malloc(n * sizeof *b), scale[NCOUNTS];
    int rc = !a || !b;
    for (int k = 0; !rc && k < NCOUNTS; k++) {
        double sum = 0.0;
        for (size_t i = 0; i < n; i++)
            sum += rows[i].counts[k] * rows[i].counts[k];
        scale[k] = sum > 0.0 ? 1.0 / sqrt(sum) : 0.0;
        ((int *)a->p)[k] = (int)(k * n);
        for (size_t i = 0; i < n; i++) {
            ((int *)a->i)[k * n + i] = (int)i;
            ((double *)a->x)[k * n + i] = rows[i].counts[k] * scale[k];
        }
    }
    if (!rc) {
        ((int *)a->p)[NCOUNTS] = (int)(NCOUNTS * n);
        for (size_t i = 0; i < n; i++)
            b[i] = rows[i].seconds;
        memset(w, 0, NCOUNTS * sizeof *w);
        rc = tk_nnls_solve(s, a, b, w, NULL, NULL, &err) != TK_OK;
        if (rc)
            fprintf(stderr, "bench/workfit: the fit: %s\n", err.message);
        for (int k = 0; k < NCOUNTS; k++)
            w[k] *= scale[k];
    }
    free(b);
    cholmod_free_sparse(&a, cc);
    tk_nnls_free(&s);
    return rc;
}

int main(int argc, char **argv)
{
    const char *dir = "../shared/catalogue";
    double seconds = 30.0;
    const char *knots[64];
    int nknots = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
            seconds = strtod(argv[++i], NULL);
        else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            usage();
            return 0;
        } else if (argv[i][0] == '-') {
            usage();
            return 2;
        } else if (strchr(argv[i], '/'))
            dir = argv[i];
        else if (nknots < 64)
            knots[nknots++] = argv[i];
    }
    if (!(seconds > 0.0)) {
        usage();
        return 2;
    }
    if (nknots == 0)
        for (size_t k = 0; k < sizeof default_knots / sizeof *default_knots; k++)
            knots[nknots++] = default_knots[k];
    row *rows = malloc(MOST_ROWS * sizeof *rows);
    if (!rows)
        return 1;
    size_t n = 0;
    printf("bench/workfit: %d runs of %g s of processor time each\n", nknots, seconds);
    for (int k = 0; k < nknots; k++)
        if (tighten(dir, knots[k], k, seconds, rows, &n))
            return 1;
    double w[NCOUNTS];
    if (fit(rows, n, w))
        return 1;
    printf("\n%-8s %14s   (seconds a unit, fitted on %zu stretches)\n", "count", "fitted", n);
    for (int k = 0; k < NCOUNTS; k++)
        printf("%-8s %14.4g\n", count_names[k], w[k]);
    printf("\n%-10s %9s %9s %8s %9s %8s   per vertex count: seconds / the engine's work\n",
           "run", "seconds", "work", "ratio", "fitted", "ratio");
    for (int k = 0; k < nknots; k++) {
        double sec = 0.0, work = 0.0, model = 0.0;
        char levels[1024] = "";
        size_t len = 0;
        for (size_t i = 0; i < n; i++) {
            if (rows[i].run != k)
                continue;
            sec += rows[i].seconds;
            work += rows[i].work;
            for (int j = 0; j < NCOUNTS; j++)
                model += w[j] * rows[i].counts[j];
        }
        /* each vertex count's seconds against its work, where it took a
         * second or more (in the order the run first reached them) */
        for (size_t i = 0; i < n; i++) {
            if (rows[i].run != k)
                continue;
            bool seen = false;
            for (size_t j = 0; j < i && !seen; j++)
                seen = rows[j].run == k && rows[j].vertices == rows[i].vertices;
            double ls = 0.0, lw = 0.0;
            for (size_t j = i; !seen && j < n; j++)
                if (rows[j].run == k && rows[j].vertices == rows[i].vertices)
                    ls += rows[j].seconds, lw += rows[j].work;
            if (!seen && ls >= 1.0 && len < sizeof levels)
                len += (size_t)snprintf(levels + len, sizeof levels - len, " %zu:%.2f",
                                        rows[i].vertices, lw > 0.0 ? ls / lw : NAN);
        }
        printf("%-10s %9.2f %9.2f %8.3f %9.2f %8.3f  %s\n", knots[k], sec, work,
               work > 0.0 ? sec / work : NAN, model, model > 0.0 ? sec / model : NAN, levels);
    }
    free(rows);
    return 0;
}
