/* Per-step cost at many contacts: the trefoil tightened first (catalogue
 * 3.1 at a modest resolution), then resampled to each vertex count,
 * settled for a few steps (the spline through a tight polygon has sharper
 * turns than the polygon), scaled so that its struts are in contact and
 * stepped; prints milliseconds per step with the breakdown of
 * tk_run_timing (strut search, matrix, NNLS, checks of trial steps, step
 * control, recovery), the constraints and the NNLS work per step.  Prints
 * figures; never fails on time.
 *
 *   bench/steps [CATALOGUE_DIR] [--warm S] [--settle N] [--steps N]
 *               [--budget S] [VERTICES ...]
 *   bench/steps --curve FILE [--level L] [--steps N]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tk/curve.h"
#include "tk/thickness.h"
#include "tk/tighten.h"
#include "tk/vect.h"

static void usage(void)
{
    fprintf(stderr,
            "usage: bench/steps [CATALOGUE_DIR] [--warm S] [--settle N] [--steps N]\n"
            "                   [--budget S] [VERTICES ...]\n"
            "       bench/steps --curve FILE [--level L] [--steps N]\n"
            "Tightens catalogue 3.1 at resolution 10 for S seconds (--warm, default 60),\n"
            "then for each vertex count (default 600 1200 2400 4800): resamples it,\n"
            "settles it for N steps (--settle, default 40), scales it into contact and\n"
            "prints milliseconds per step over N steps (--steps, default 5, or as many\n"
            "as --budget seconds allow, default 300) with where the time went.\n"
            "With --curve FILE: tightens FILE's curve again (no autoscale, no escapes)\n"
            "and prints each of its first N steps (--steps), the first one cold; with\n"
            "--level L it goes on at polishing level L (as a run that polished that\n"
            "far: the tolerances a tight curve ends a run with) instead of level 0.\n");
}

static tk_run *start(const tk_curve *c, const tk_options *o)
{
    tk_run *run = NULL;
    tk_error err;
    if (tk_run_new(c, o, &run, &err) != TK_OK) {
        fprintf(stderr, "bench/steps: %s\n", err.message);
        exit(1);
    }
    return run;
}

static void row(const tk_run *run, const tk_run_timing *a, const tk_run_timing *b, double n)
{
    const tk_step_report *last = tk_run_latest(run);
    double ms = 1e3 / n;
    size_t ns = 0, forced = 0;
    const tk_strut *struts = tk_run_struts(run, &ns);
    for (size_t j = 0; j < ns; j++)
        forced += struts[j].force > 0.0;
    printf("%8zu %7zu %6zu %6zu %9.1f %13.9f | %8.1f %8.1f %8.1f %8.1f %8.1f %8.1f %8.1f | "
           "%6.1f %6.1f\n",
           last->vertices, last->struts, forced, last->kinks, ms * (b->total - a->total),
           last->ropelength, ms * (b->search - a->search), ms * (b->matrix - a->matrix),
           ms * (b->nnls - a->nnls), ms * (b->checks - a->checks),
           ms * (b->stepping - a->stepping), ms * (b->recovery - a->recovery),
           ms * (b->figures - a->figures),
           (double)(b->nnls_iterations - a->nnls_iterations) / n,
           (double)(b->factorisations - a->factorisations) / n);
    fflush(stdout);
}

static void header(void)
{
    printf("\n%8s %7s %6s %6s %9s %13s | %8s %8s %8s %8s %8s %8s %8s | %6s %6s\n",
           "vertices", "struts", "forced", "kinks", "ms/step", "ropelength", "search", "matrix",
           "nnls", "checks", "stepping", "recovery", "figures", "iter", "facts");
}

static void footer(void)
{
    printf("(forced: struts with a positive force at the last step; the columns after\n"
           " ropelength are milliseconds per step, stepping including the motion's matrix\n"
           " and NNLS solves and its searches and checks; iter and facts: NNLS pivoting\n"
           " iterations and Cholesky factorisations per step)\n");
}

/* The curve of the VECT file at path, or NULL (said on stderr, with
 * `hint` after the reason). */
static tk_curve *read_curve(const char *path, const char *hint)
{
    tk_curve *c = NULL;
    tk_error err;
    if (tk_vect_read_file(path, NULL, &c, &err) != TK_OK)
        fprintf(stderr, "bench/steps: %s%s\n", err.message, hint);
    return c;
}

/* --curve: FILE's curve tightened again, a row per step; from polishing
 * level `level` when it is not negative (resumed there). */
static int again(const char *path, int level, long steps)
{
    tk_curve *c = read_curve(path, "");
    if (!c)
        return 1;
    tk_options o = TK_OPTIONS_INIT;
    o.escapes = 0;
    tk_error err;
    tk_run *run = NULL;
    if (level < 0)
        run = start(c, &o);
    else {
        tk_resume at;
        memset(&at, 0, sizeof at);
        at.polish_level = level;
        tk_measure m;
        if (tk_thickness_measure(c, NULL, &m, &err) == TK_OK)
            at.start_ropelength = m.ropelength;
        if (tk_run_resume(c, &o, &at, NULL, NULL, NULL, &run, &err) != TK_OK) {
            fprintf(stderr, "bench/steps: %s\n", err.message);
            tk_curve_free(&c);
            return 1;
        }
    }
    char from[48] = "";
    if (level >= 0)
        snprintf(from, sizeof from, " from polishing level %d", level);
    printf("%s tightened again%s: %zu vertices, ropelength %.7f; each step's row:\n", path,
           from, c->nvert, tk_run_latest(run)->ropelength);
    header();
    for (long k = 0; k < steps; k++) {
        tk_run_timing a, b;
        tk_run_timing_get(run, &a);
        if (tk_run_step(run, &err) != TK_OK) {
            fprintf(stderr, "bench/steps: %s\n", err.message);
            return 1;
        }
        tk_run_timing_get(run, &b);
        row(run, &a, &b, 1.0);
    }
    footer();
    tk_run_free(&run);
    tk_curve_free(&c);
    return 0;
}

static void run_to_stop(tk_run *run)
{
    tk_error err;
    if (tk_run_until(run, NULL, &err) != TK_OK) {
        fprintf(stderr, "bench/steps: %s\n", err.message);
        exit(1);
    }
}

int main(int argc, char **argv)
{
    const char *dir = "../shared/catalogue", *curve = NULL;
    int level = -1;
    double warm = 60.0, budget = 300.0;
    long settle = 40, steps = 5;
    size_t counts[16], ncounts = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage();
            return 0;
        } else if (strcmp(argv[i], "--warm") == 0 && i + 1 < argc) {
            warm = strtod(argv[++i], NULL);
        } else if (strcmp(argv[i], "--curve") == 0 && i + 1 < argc) {
            curve = argv[++i];
        } else if (strcmp(argv[i], "--level") == 0 && i + 1 < argc) {
            level = (int)strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--settle") == 0 && i + 1 < argc) {
            settle = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
            steps = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--budget") == 0 && i + 1 < argc) {
            budget = strtod(argv[++i], NULL);
        } else if (argv[i][0] >= '0' && argv[i][0] <= '9') {
            if (ncounts < sizeof counts / sizeof counts[0])
                counts[ncounts++] = strtoul(argv[i], NULL, 10);
        } else if (argv[i][0] != '-') {
            dir = argv[i];
        } else {
            usage();
            return 1;
        }
    }
    if (curve)
        return again(curve, level, steps);
    if (ncounts == 0) {
        size_t defaults[] = {600, 1200, 2400, 4800};
        memcpy(counts, defaults, sizeof defaults);
        ncounts = 4;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/3.1.vect", dir);
    tk_curve *loose = read_curve(path, " (the catalogue is needed)");
    if (!loose)
        return 1;
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 10;
    o.max_seconds = warm;
    tk_run *run = start(loose, &o);
    run_to_stop(run);
    tk_curve *tight = NULL;
    tk_error err;
    if (tk_curve_copy(tk_run_curve(run), &tight, &err) != TK_OK)
        return 1;
    printf("trefoil 3.1 tightened for %.0f s at resolution 10: ropelength %.6f, %zu vertices\n",
           warm, tk_run_latest(run)->ropelength, tight->nvert);
    tk_run_free(&run);

    header();
    for (size_t k = 0; k < ncounts; k++) {
        tk_curve *resampled = NULL, *settled = NULL;
        if (tk_curve_resample_total(tight, counts[k], &resampled, &err) != TK_OK) {
            fprintf(stderr, "bench/steps: %s\n", err.message);
            return 1;
        }
        tk_options s = TK_OPTIONS_INIT;
        s.autoscale = true;
        s.max_steps = settle;
        s.max_seconds = budget;
        run = start(resampled, &s);
        run_to_stop(run);
        if (tk_curve_copy(tk_run_curve(run), &settled, &err) != TK_OK) {
            fprintf(stderr, "bench/steps: %s\n", err.message);
            return 1;
        }
        tk_run_free(&run);
        /* inside the active tolerance (at least 0.3 h^2, 3e-6 at 4,800
         * vertices): every contact is a constraint from the first step */
        s.autoscale_margin = 1.0000001;
        s.max_steps = steps;
        run = start(settled, &s);
        tk_run_timing before;
        tk_run_timing_get(run, &before);
        run_to_stop(run);
        tk_run_timing t;
        tk_run_timing_get(run, &t);
        const tk_step_report *last = tk_run_latest(run);
        row(run, &before, &t, (double)(last->step > 0 ? last->step : 1));
        tk_run_free(&run);
        tk_curve_free(&resampled);
        tk_curve_free(&settled);
    }
    footer();
    tk_curve_free(&tight);
    tk_curve_free(&loose);
    return 0;
}
