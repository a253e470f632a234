/* NNLS benchmark: flow-like rigidity matrices with 10^2 .. 10^4 columns.
 * V vertices on a closed polygon; 70% of the columns are struts between
 * edges (i, i+1) and (j, j+1) with j about half-way round (12 nonzeros:
 * weights (1-s, s, -(1-t), -t) times a unit vector), 30% are kinks at
 * distinct vertices (9 nonzeros summing to zero per coordinate), so every
 * column is orthogonal to the rigid translations, as in the flow.  Prints
 * the time of a first solve (cold factor cache), of a repeat solve (warm
 * cache) and of the minimum-norm solve; never fails on time.
 *
 *   bench/nnls [MAX_COLUMNS [VERTICES_PER_COLUMN]]
 *
 * VERTICES_PER_COLUMN (default 0.5) below 1/3 gives more columns than
 * rows, the rank-deficient case of a knot with many contacts.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "tk/nnls.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* splitmix64 */
static double uniform(unsigned long long *state)
{
    unsigned long long z = (*state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

static void unit_vector(unsigned long long *st, double u[3])
{
    double len;
    do {
        for (int k = 0; k < 3; k++)
            u[k] = 2.0 * uniform(st) - 1.0;
        len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    } while (len < 0.1 || len > 1.0);
    for (int k = 0; k < 3; k++)
        u[k] /= len;
}

static cholmod_sparse *flow_problem(cholmod_common *cc, size_t n, double per_column,
                                    unsigned long long *st)
{
    size_t V = (size_t)(per_column * (double)n);
    if (V < 8)
        V = 8;
    size_t m = 3 * V;
    size_t kinks = (3 * n) / 10, struts = n - kinks;
    cholmod_triplet *T = cholmod_allocate_triplet(m, n, 12 * n, 0, CHOLMOD_REAL, cc);
    if (!T)
        return NULL;
    int *Ti = T->i, *Tj = T->j;
    double *Tx = T->x;
    size_t e = 0;
    for (size_t c = 0; c < struts; c++) {
        size_t i = (size_t)(uniform(st) * (double)V);
        size_t j = (i + V / 2 + (size_t)(uniform(st) * 7.0) + V - 3) % V;
        if (j == i || (j + 1) % V == i || (i + 1) % V == j)
            j = (j + 3) % V;
        double s = uniform(st), t = uniform(st), u[3];
        unit_vector(st, u);
        size_t vert[4] = {i, (i + 1) % V, j, (j + 1) % V};
        double w[4] = {1.0 - s, s, -(1.0 - t), -t};
        for (int a = 0; a < 4; a++)
            for (int k = 0; k < 3; k++) {
                Ti[e] = (int)(3 * vert[a] + (size_t)k);
                Tj[e] = (int)c;
                Tx[e++] = w[a] * u[k];
            }
    }
    /* kinks at every (V / kinks)-th vertex */
    for (size_t q = 0; q < kinks; q++) {
        size_t v = kinks <= V ? (q * V) / kinks : q % V;
        double g0[3], g2[3];
        unit_vector(st, g0);
        unit_vector(st, g2);
        size_t vert[3] = {(v + V - 1) % V, v, (v + 1) % V};
        for (int k = 0; k < 3; k++) {
            double vals[3] = {g0[k], -g0[k] - g2[k], g2[k]};
            for (int a = 0; a < 3; a++) {
                Ti[e] = (int)(3 * vert[a] + (size_t)k);
                Tj[e] = (int)(struts + q);
                Tx[e++] = vals[a];
            }
        }
    }
    T->nnz = e;
    cholmod_sparse *A = cholmod_triplet_to_sparse(T, e, cc);
    cholmod_free_triplet(&T, cc);
    return A;
}

int main(int argc, char **argv)
{
    size_t max_n = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 10000;
    double per_column = argc > 2 ? strtod(argv[2], NULL) : 0.5;
    if (!(per_column > 0.0 && per_column < 100.0))
        per_column = 0.5;
    tk_nnls *s = NULL;
    tk_error err;
    if (tk_nnls_new(&s, &err) != TK_OK) {
        fprintf(stderr, "bench/nnls: %s\n", err.message);
        return 1;
    }
    cholmod_common *cc = tk_nnls_common(s);
    unsigned long long st = 1;
    printf("%8s %8s %6s %6s %8s %5s %10s %10s %10s %10s\n", "columns", "rows", "iter", "fact",
           "passive", "reg", "rcond", "cold ms", "warm ms", "minnorm ms");
    for (size_t n = 100; n <= max_n; n *= 10) {
        for (int rep = 0; rep < 3; rep++) {
            cholmod_sparse *A = flow_problem(cc, n, per_column, &st);
            if (!A) {
                fprintf(stderr, "bench/nnls: out of memory\n");
                break;
            }
            size_t m = A->nrow;
            double *b = malloc(m * sizeof *b), *x = malloc(n * sizeof *x);
            double *r = malloc(n * sizeof *r), *du = malloc(m * sizeof *du);
            if (!b || !x || !r || !du) {
                fprintf(stderr, "bench/nnls: out of memory\n");
                return 1;
            }
            for (size_t k = 0; k < m; k++)
                b[k] = 2.0 * uniform(&st) - 1.0;
            for (size_t k = 0; k < n; k++)
                r[k] = 2.0 * uniform(&st) - 1.0;
            tk_nnls_report report;
            tk_nnls *fresh = NULL;
            tk_nnls_new(&fresh, &err);
            double t0 = now();
            int rc = tk_nnls_solve(fresh, A, b, x, NULL, &report, &err);
            double cold = now() - t0;
            tk_nnls_free(&fresh);
            t0 = now();
            rc |= tk_nnls_solve(s, A, b, x, NULL, &report, &err);
            rc |= tk_nnls_solve(s, A, b, x, NULL, &report, &err);
            double t1 = now();
            double warm = (t1 - t0) / 2.0;
            double delta;
            rc |= tk_nnls_min_norm(s, A, r, 0.0, NULL, du, &delta, &err);
            double mn = now() - t1;
            if (rc != TK_OK)
                printf("  (status %d: %s)\n", rc, err.message);
            printf("%8zu %8zu %6d %6d %8zu %5s %10.2g %10.2f %10.2f %10.2f\n", n, m,
                   report.iterations, report.factorisations, report.passive,
                   report.regularised ? "yes" : "no", report.rcond, 1e3 * cold, 1e3 * warm,
                   1e3 * mn);
            free(b);
            free(x);
            free(r);
            free(du);
            cholmod_free_sparse(&A, cc);
        }
    }
    tk_nnls_free(&s);
    return 0;
}
