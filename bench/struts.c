/* Strut search benchmark: catalogue knots resampled to 10^3 .. 10^6
 * vertices; for each, the time to build the tree, to refit it, to find the
 * shortest doubly critical distance (thickness) and to list every strut
 * within 1e-4 of the thickness (Theorem 3's admissible pairs), with the
 * brute-force time where it is feasible.  Prints figures; never fails on
 * time.
 *
 *   bench/struts [CATALOGUE_DIR] [--max V] [KNOT.vect ...]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "tk/curve.h"
#include "tk/struts.h"
#include "tk/thickness.h"
#include "tk/vect.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

/* Runs fn repeatedly for at least 0.3 s (or 3 times) and returns the best
 * time of one run. */
typedef struct search_args {
    tk_strut_finder *f;
    const tk_curve *c;
    double tau;
    size_t found;
    double shortest;
} search_args;

static void run_find(search_args *a)
{
    tk_strut_list list = {0};
    tk_strut_finder_find(a->f, a->c, TK_ARC_ADMISSIBLE, a->tau, a->tau * (1 + 1e-4), &list,
                         NULL);
    a->found = list.count;
    tk_strut_list_free(&list);
}

static void run_shortest(search_args *a)
{
    tk_strut_finder_shortest(a->f, a->c, &a->shortest, NULL, NULL);
}

static void run_refit(search_args *a)
{
    tk_strut_finder_refit(a->f, a->c);
}

static double best_time(void (*fn)(search_args *), search_args *a)
{
    double best = INFINITY, spent = 0.0;
    for (int rep = 0; rep < 50 && (rep < 3 || spent < 0.3); rep++) {
        double t0 = now();
        fn(a);
        double dt = now() - t0;
        best = fmin(best, dt);
        spent += dt;
    }
    return best;
}

static void bench_one(const char *dir, const char *name, size_t vertices, size_t brute_max)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    tk_curve *src = NULL, *c = NULL;
    tk_error err;
    if (tk_vect_read_file(path, NULL, &src, &err) != TK_OK) {
        fprintf(stderr, "bench: %s\n", err.message);
        return;
    }
    if (tk_curve_resample_total(src, vertices, &c, &err) != TK_OK) {
        fprintf(stderr, "bench: resampling %s: %s\n", name, err.message);
        tk_curve_free(&src);
        return;
    }
    double t0 = now();
    tk_strut_finder *f = NULL;
    if (tk_strut_finder_new(c, &f, &err) != TK_OK) {
        fprintf(stderr, "bench: %s\n", err.message);
        tk_curve_free(&src);
        tk_curve_free(&c);
        return;
    }
    double build = now() - t0;
    tk_measure m;
    tk_thickness_measure(c, f, &m, NULL);
    search_args a = {f, c, m.thickness, 0, 0.0};
    double refit = best_time(run_refit, &a);
    double shortest = best_time(run_shortest, &a);
    double find = best_time(run_find, &a);
    size_t edges = tk_curve_edge_count(c);
    char brute_text[32] = "-";
    if (c->nvert <= brute_max) {
        tk_strut_list list = {0};
        double b0 = now();
        tk_struts_find_brute(c, TK_ARC_ADMISSIBLE, m.thickness, m.thickness * (1 + 1e-4), &list,
                             NULL);
        snprintf(brute_text, sizeof brute_text, "%.4f", now() - b0);
        tk_strut_list_free(&list);
    }
    printf("%-12s %9zu %10.5f %10.6f %11.5f %11.5f %9.1f %9s %7zu %10.5f %8.1f\n", name,
           c->nvert, build, refit, shortest, find, 1e9 * find / (double)edges, brute_text,
           a.found, m.ropelength, peak_mib());
    fflush(stdout);
    tk_strut_finder_free(&f);
    tk_curve_free(&src);
    tk_curve_free(&c);
}

int main(int argc, char **argv)
{
    const char *dir = "../shared/catalogue";
    size_t max_vertices = 1000000, brute_max = 20000;
    const char *knots[16];
    size_t nknots = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            printf("usage: struts [CATALOGUE_DIR] [--max V] [--brute-max V] [KNOT.vect ...]\n"
                   "Times the strut tree on catalogue knots resampled to 10^3 .. V vertices.\n");
            return 0;
        } else if (strcmp(argv[i], "--max") == 0 && i + 1 < argc) {
            max_vertices = strtoull(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--brute-max") == 0 && i + 1 < argc) {
            brute_max = strtoull(argv[++i], NULL, 10);
        } else if (strstr(argv[i], ".vect") && nknots < 16) {
            knots[nknots++] = argv[i];
        } else {
            dir = argv[i];
        }
    }
    if (nknots == 0) {
        knots[nknots++] = "3.1.vect";
        knots[nknots++] = "10.1.vect";
        knots[nknots++] = "6.3.2.vect";
    }
    printf("strut search: tree build, refit, shortest doubly critical distance, all struts\n"
           "within thickness * (1 + 1e-4); seconds (best of repeats); ns/edge for the search;\n"
           "brute force O(V^2) where V <= %zu; peak RSS so far\n\n", brute_max);
    printf("%-12s %9s %10s %10s %11s %11s %9s %9s %7s %10s %8s\n", "knot", "vertices",
           "build_s", "refit_s", "shortest_s", "struts_s", "ns/edge", "brute_s", "struts",
           "ropelength", "peak_MiB");
    for (size_t k = 0; k < nknots; k++)
        for (size_t v = 1000; v <= max_vertices; v *= 10)
            bench_one(dir, knots[k], v, brute_max);
    return 0;
}
