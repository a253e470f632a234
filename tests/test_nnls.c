/* Sparse NNLS: the KKT conditions on random flow-like problems, agreement
 * with an independent dense solver (enumeration of passive sets with
 * Householder least squares), rank-deficient and degenerate problems, the
 * minimum-norm solve against a dense pseudo-inverse, and re-entrancy. */
#include <check.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/nnls.h"

/* ------------------------------------------------------------------ */
/* Problems. */

/* A column-major dense m x n matrix turned into a CHOLMOD sparse matrix
 * (exact zeros left out). */
static cholmod_sparse *sparse_from_dense(cholmod_common *cc, size_t m, size_t n, const double *D)
{
    size_t nnz = 0;
    for (size_t k = 0; k < m * n; k++)
        nnz += D[k] != 0.0;
    cholmod_sparse *A = cholmod_allocate_sparse(m, n, nnz, 1, 1, 0, CHOLMOD_REAL, cc);
    ck_assert_ptr_nonnull(A);
    int *Ap = A->p, *Ai = A->i;
    double *Ax = A->x;
    size_t e = 0;
    for (size_t j = 0; j < n; j++) {
        Ap[j] = (int)e;
        for (size_t i = 0; i < m; i++)
            if (D[i + j * m] != 0.0) {
                Ai[e] = (int)i;
                Ax[e++] = D[i + j * m];
            }
    }
    Ap[n] = (int)e;
    return A;
}

/* Dense copy (column-major) of a sparse matrix. */
static double *dense_from_sparse(const cholmod_sparse *A)
{
    size_t m = A->nrow, n = A->ncol;
    double *D = calloc(m * n + 1, sizeof *D);
    ck_assert_ptr_nonnull(D);
    const int *Ap = A->p, *Ai = A->i;
    const double *Ax = A->x;
    for (size_t j = 0; j < n; j++)
        for (int e = Ap[j]; e < Ap[j + 1]; e++)
            D[Ai[e] + j * m] += Ax[e];
    return D;
}

/* Like the flow's rigidity matrix: m = 3V rows, every column touches 2 to
 * 4 distinct random vertices in all three coordinates (6, 9 or 12
 * nonzeros). */
static cholmod_sparse *flow_matrix(cholmod_common *cc, tkt_rng *r, size_t V, size_t n)
{
    size_t m = 3 * V;
    cholmod_sparse *A = cholmod_allocate_sparse(m, n, 12 * n, 1, 1, 0, CHOLMOD_REAL, cc);
    ck_assert_ptr_nonnull(A);
    int *Ap = A->p, *Ai = A->i;
    double *Ax = A->x;
    size_t e = 0;
    for (size_t j = 0; j < n; j++) {
        Ap[j] = (int)e;
        size_t k = 2 + (size_t)(tkt_rng_next(r) % 3);
        if (k > V)
            k = V;
        size_t v[4];
        for (size_t a = 0; a < k; a++) {
            bool fresh;
            do {
                v[a] = (size_t)(tkt_rng_next(r) % V);
                fresh = true;
                for (size_t c = 0; c < a; c++)
                    fresh = fresh && v[c] != v[a];
            } while (!fresh);
        }
        /* sorted row indices */
        for (size_t a = 1; a < k; a++)
            for (size_t c = a; c > 0 && v[c - 1] > v[c]; c--) {
                size_t t = v[c];
                v[c] = v[c - 1];
                v[c - 1] = t;
            }
        for (size_t a = 0; a < k; a++)
            for (int c = 0; c < 3; c++) {
                Ai[e] = (int)(3 * v[a] + (size_t)c);
                Ax[e++] = tkt_rng_range(r, -1, 1);
            }
    }
    Ap[n] = (int)e;
    return A;
}

static double *random_vector(tkt_rng *r, size_t n)
{
    double *v = malloc((n + 1) * sizeof *v);
    ck_assert_ptr_nonnull(v);
    for (size_t k = 0; k < n; k++)
        v[k] = tkt_rng_range(r, -1, 1);
    return v;
}

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t k = 0; k < n; k++)
        s += a[k] * b[k];
    return s;
}

static double vnorm(const double *a, size_t n)
{
    return sqrt(dot(a, a, n));
}

/* out = A x (m) and g = A^T (A x - b) (n) from the sparse matrix. */
static void residual_gradient(const cholmod_sparse *A, const double *b, const double *x,
                              double *res, double *g)
{
    size_t m = A->nrow, n = A->ncol;
    const int *Ap = A->p, *Ai = A->i;
    const double *Ax = A->x;
    for (size_t k = 0; k < m; k++)
        res[k] = -b[k];
    for (size_t j = 0; j < n; j++)
        for (int e = Ap[j]; e < Ap[j + 1]; e++)
            res[Ai[e]] += Ax[e] * x[j];
    for (size_t j = 0; j < n; j++) {
        double s = 0.0;
        for (int e = Ap[j]; e < Ap[j + 1]; e++)
            s += Ax[e] * res[Ai[e]];
        g[j] = s;
    }
}

static double column_norm(const cholmod_sparse *A, size_t j)
{
    const int *Ap = A->p;
    const double *Ax = A->x;
    return vnorm(Ax + Ap[j], (size_t)(Ap[j + 1] - Ap[j]));
}

/* Asserts the KKT conditions of min ||Ax - b||, x >= 0 at x, with
 * tolerance rel * ||a_j|| * ||b|| on each gradient entry; returns the
 * residual norm. */
static double assert_kkt(const cholmod_sparse *A, const double *b, const double *x, double rel,
                         const char *what)
{
    size_t m = A->nrow, n = A->ncol;
    double *res = malloc((m + 1) * sizeof *res), *g = malloc((n + 1) * sizeof *g);
    ck_assert(res && g);
    residual_gradient(A, b, x, res, g);
    double bn = vnorm(b, m);
    for (size_t j = 0; j < n; j++) {
        double tol = rel * column_norm(A, j) * bn;
        ck_assert_msg(x[j] >= 0.0, "%s: x[%zu] = %g < 0", what, j, x[j]);
        ck_assert_msg(g[j] >= -tol, "%s: gradient[%zu] = %g < -%g (x = %g)", what, j, g[j], tol,
                      x[j]);
        if (x[j] > 0.0)
            ck_assert_msg(fabs(g[j]) <= tol, "%s: x[%zu] = %g > 0 but gradient %g (tol %g)",
                          what, j, x[j], g[j], tol);
    }
    /* complementarity as a whole: (A x) . (A x - b) = x . g = 0 */
    double xg = dot(x, g, n);
    ck_assert_msg(fabs(xg) <= rel * bn * bn, "%s: x.g = %g", what, xg);
    double rn = vnorm(res, m);
    free(res);
    free(g);
    return rn;
}

/* ------------------------------------------------------------------ */
/* The independent dense reference. */

/* Least squares min ||B z - b|| for the m x k column-major B by Householder
 * QR (B is destroyed).  Returns false when B is numerically rank deficient
 * (|R_jj| <= 1e-9 max |R_ii|). */
static bool dense_ls(double *B, size_t m, size_t k, const double *b, double *z)
{
    if (k > m)
        return false;
    double *c = malloc((m + 1) * sizeof *c);
    ck_assert_ptr_nonnull(c);
    memcpy(c, b, m * sizeof *c);
    double rmax = 0.0;
    bool ok = true;
    for (size_t j = 0; j < k && ok; j++) {
        double *col = B + j * m;
        double alpha = vnorm(col + j, m - j);
        if (col[j] > 0)
            alpha = -alpha;
        /* v = col[j..] - alpha e_1; H = I - 2 v v^T / v^T v */
        double v0 = col[j] - alpha;
        double vv = v0 * v0 + dot(col + j + 1, col + j + 1, m - j - 1);
        col[j] = v0;
        if (vv > 0.0) {
            for (size_t q = j + 1; q < k; q++) {
                double *cq = B + q * m;
                double s = 2.0 * dot(col + j, cq + j, m - j) / vv;
                for (size_t i = j; i < m; i++)
                    cq[i] -= s * col[i];
            }
            double s = 2.0 * dot(col + j, c + j, m - j) / vv;
            for (size_t i = j; i < m; i++)
                c[i] -= s * col[i];
        }
        col[j] = alpha;
        rmax = fmax(rmax, fabs(alpha));
    }
    for (size_t j = 0; j < k; j++)
        if (!(fabs(B[j + j * m]) > 1e-9 * rmax))
            ok = false;
    if (ok)
        for (size_t jj = k; jj-- > 0;) {
            double s = c[jj];
            for (size_t q = jj + 1; q < k; q++)
                s -= B[jj + q * m] * z[q];
            z[jj] = s / B[jj + jj * m];
        }
    free(c);
    return ok;
}

/* NNLS by enumerating every passive set S whose columns are independent:
 * the optimum A x* lies in the cone of an independent subset (Caratheodory)
 * and is the least-squares projection onto that subset's span, so the
 * least residual over feasible least-squares solutions is the optimum.
 * D is column-major m x n, n <= 12.  Returns the optimal residual norm;
 * x receives the minimiser found. */
static double dense_nnls_enumerate(const double *D, size_t m, size_t n, const double *b,
                                   double *x)
{
    double best = vnorm(b, m);
    double bn = best;
    for (size_t j = 0; j < n; j++)
        x[j] = 0.0;
    double *B = malloc((m * n + 1) * sizeof *B), *z = malloc((n + 1) * sizeof *z);
    double *res = malloc((m + 1) * sizeof *res);
    size_t *cols = malloc((n + 1) * sizeof *cols);
    ck_assert(B && z && res && cols);
    for (unsigned long set = 1; set < (1UL << n); set++) {
        size_t k = 0;
        for (size_t j = 0; j < n; j++)
            if (set & (1UL << j)) {
                memcpy(B + k * m, D + j * m, m * sizeof *B);
                cols[k++] = j;
            }
        if (!dense_ls(B, m, k, b, z))
            continue;
        bool feasible = true;
        for (size_t q = 0; q < k; q++)
            feasible = feasible && z[q] * vnorm(D + cols[q] * m, m) >= -1e-12 * bn;
        if (!feasible)
            continue;
        memcpy(res, b, m * sizeof *res);
        for (size_t q = 0; q < k; q++)
            for (size_t i = 0; i < m; i++)
                res[i] -= D[i + cols[q] * m] * z[q];
        double rn = vnorm(res, m);
        if (rn < best) {
            best = rn;
            for (size_t j = 0; j < n; j++)
                x[j] = 0.0;
            for (size_t q = 0; q < k; q++)
                x[cols[q]] = fmax(0.0, z[q]);
        }
    }
    free(B);
    free(z);
    free(res);
    free(cols);
    return best;
}

/* ------------------------------------------------------------------ */
/* Running the solver. */

static int solve(tk_nnls *s, const cholmod_sparse *A, const double *b, double *x,
                 const tk_nnls_options *o, tk_nnls_report *rep)
{
    tk_error err;
    tk_error_clear(&err);
    int rc = tk_nnls_solve(s, A, b, x, o, rep, &err);
    ck_assert_msg(rc == TK_OK || rc == TK_ENUMERIC, "nnls failed: %s", err.message);
    return rc;
}

static tk_nnls *new_solver(void)
{
    tk_nnls *s = NULL;
    tk_error err;
    ck_assert_int_eq(tk_nnls_new(&s, &err), TK_OK);
    return s;
}

/* ------------------------------------------------------------------ */
/* Tests. */

/* The residual is only as exact as the KKT tolerance: with the default
 * 1e-10 an optimum residual of 0 can come back as about 1e-10 ||b||, so
 * the comparisons with enumeration (to 1e-10) ask for 1e-12. */
static const tk_nnls_options tight = {0, 1e-12, 1e-14};

START_TEST(kkt_on_random_flow_problems)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {7};
    size_t sizes[3] = {10, 100, 1000};
    /* columns per coordinate: sparse contact sets up to square */
    double ratios[4] = {0.1, 0.3, 0.6, 0.9};
    for (int si = 0; si < 3; si++)
        for (int ri = 0; ri < 4; ri++)
            for (int trial = 0; trial < (si == 2 ? 2 : 6); trial++) {
                size_t V = sizes[si], m = 3 * V;
                size_t n = (size_t)(ratios[ri] * (double)m) + 1;
                cholmod_sparse *A = flow_matrix(cc, &r, V, n);
                double *b = random_vector(&r, m);
                double *x = malloc(n * sizeof *x);
                tk_nnls_report rep;
                int rc = solve(s, A, b, x, NULL, &rep);
                char what[64];
                snprintf(what, sizeof what, "V=%zu n=%zu trial %d", V, n, trial);
                ck_assert_msg(rc == TK_OK, "%s: not converged", what);
                double rn = assert_kkt(A, b, x, 1e-9, what);
                ck_assert_msg(tkt_reldiff(rn, rep.residual) < 1e-9, "%s: residual %g vs %g",
                              what, rn, rep.residual);
                size_t passive = 0;
                for (size_t j = 0; j < n; j++)
                    passive += x[j] > 0.0;
                ck_assert_uint_eq(passive, rep.passive);
                if (rep.passive > 0)
                    ck_assert(rep.iterations >= 1 && rep.factorisations >= 1);
                ck_assert(rep.rcond > 0.0 && rep.rcond <= 1.0);
                free(b);
                free(x);
                cholmod_free_sparse(&A, cc);
            }
    tk_nnls_free(&s);
    ck_assert_ptr_null(s);
}
END_TEST

/* Small problems: the sparse solver against enumeration. */
START_TEST(matches_dense_enumeration)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {2024};
    int full_rank_compared = 0;
    for (int trial = 0; trial < 300; trial++) {
        size_t m = 2 + (size_t)(tkt_rng_next(&r) % 29); /* 2..30 */
        size_t n = 1 + (size_t)(tkt_rng_next(&r) % 10); /* 1..10 */
        cholmod_sparse *A;
        if (trial % 2 == 0) {
            /* dense random, sometimes more columns than rows */
            double *D = random_vector(&r, m * n);
            for (size_t k = 0; k < m * n; k++)
                if (tkt_rng_uniform(&r) < 0.3)
                    D[k] = 0.0;
            A = sparse_from_dense(cc, m, n, D);
            free(D);
        } else {
            size_t V = 1 + m / 3;
            if (V < 2)
                V = 2;
            A = flow_matrix(cc, &r, V, n);
            m = A->nrow;
        }
        double *D = dense_from_sparse(A);
        double *b = random_vector(&r, m);
        double *x = malloc(n * sizeof *x), *xr = malloc(n * sizeof *xr);
        tk_nnls_report rep;
        char what[64];
        snprintf(what, sizeof what, "trial %d (%zu x %zu)", trial, m, n);
        ck_assert_msg(solve(s, A, b, x, &tight, &rep) == TK_OK, "%s: not converged", what);
        double rn = assert_kkt(A, b, x, 1e-9, what);
        double ref = dense_nnls_enumerate(D, m, n, b, xr);
        double bn = vnorm(b, m);
        ck_assert_msg(fabs(rn - ref) <= 1e-10 * bn, "%s: residual %.17g, reference %.17g", what,
                      rn, ref);
        /* with independent columns the minimiser is unique */
        double *B = malloc((m * n + 1) * sizeof *B), *z = malloc(n * sizeof *z);
        memcpy(B, D, m * n * sizeof *B);
        if (dense_ls(B, m, n, b, z)) {
            full_rank_compared++;
            for (size_t j = 0; j < n; j++) {
                double sj = vnorm(D + j * m, m);
                ck_assert_msg(fabs(x[j] - xr[j]) * sj <= 1e-8 * bn, "%s: x[%zu] %.17g vs %.17g",
                              what, j, x[j], xr[j]);
            }
        }
        free(B);
        free(z);
        free(D);
        free(b);
        free(x);
        free(xr);
        cholmod_free_sparse(&A, cc);
    }
    ck_assert_int_gt(full_rank_compared, 100);
    tk_nnls_free(&s);
}
END_TEST

/* More columns than rows, small enough to enumerate: A^T A is singular,
 * block pivoting often stalls and the fallback has to finish. */
START_TEST(wide_problems_match_enumeration)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {77};
    int fallback = 0;
    for (int trial = 0; trial < 600; trial++) {
        size_t m = 2 + (size_t)(tkt_rng_next(&r) % 7);       /* 2..8 */
        size_t n = m + 1 + (size_t)(tkt_rng_next(&r) % (10 - m)); /* m+1..10 */
        double *D = random_vector(&r, m * n);
        for (size_t k = 0; k < m * n; k++)
            if (tkt_rng_uniform(&r) < 0.3)
                D[k] = 0.0;
        cholmod_sparse *A = sparse_from_dense(cc, m, n, D);
        double *b = random_vector(&r, m);
        double x[10], xr[10];
        tk_nnls_report rep;
        char what[64];
        snprintf(what, sizeof what, "wide trial %d (%zu x %zu)", trial, m, n);
        ck_assert_msg(solve(s, A, b, x, &tight, &rep) == TK_OK, "%s: not converged", what);
        fallback += rep.used_fallback;
        double rn = assert_kkt(A, b, x, 1e-9, what);
        double ref = dense_nnls_enumerate(D, m, n, b, xr);
        ck_assert_msg(fabs(rn - ref) <= 1e-10 * vnorm(b, m), "%s: residual %.17g, reference %.17g",
                      what, rn, ref);
        free(D);
        free(b);
        cholmod_free_sparse(&A, cc);
    }
    ck_assert_int_gt(fallback, 10);
    tk_nnls_free(&s);
}
END_TEST

/* Wide flow problems large enough that Lawson and Hanson modify their
 * factor hundreds of times (rows added and deleted, and rebuilt after
 * many): the answer still meets the KKT conditions. */
START_TEST(wide_flow_problems_meet_kkt)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {2026};
    int fallback = 0, rebuilt = 0;
    for (int trial = 0; trial < 8; trial++) {
        size_t V = trial < 4 ? 150 : 400, m = 3 * V;
        size_t n = (size_t)((1.7 + 0.1 * (trial % 4)) * (double)m);
        cholmod_sparse *A = flow_matrix(cc, &r, V, n);
        double *b = random_vector(&r, m);
        double *x = malloc(n * sizeof *x);
        tk_nnls_report rep;
        char what[64];
        snprintf(what, sizeof what, "wide flow V=%zu n=%zu", V, n);
        ck_assert_msg(solve(s, A, b, x, NULL, &rep) == TK_OK, "%s: not converged", what);
        fallback += rep.used_fallback;
        /* the factor is modified, not built afresh, at most iterations */
        if (rep.used_fallback)
            ck_assert_msg(rep.factorisations < rep.iterations / 4,
                          "%s: %d factorisations in %d iterations", what, rep.factorisations,
                          rep.iterations);
        rebuilt += rep.used_fallback && rep.factorisations > 1;
        double rn = assert_kkt(A, b, x, 1e-9, what);
        ck_assert_msg(tkt_reldiff(rn, rep.residual) < 1e-9, "%s: residual %g vs %g", what, rn,
                      rep.residual);
        printf("%s: %d iterations, %d factorisations, %zu passive%s\n", what, rep.iterations,
               rep.factorisations, rep.passive, rep.used_fallback ? ", fallback" : "");
        free(b);
        free(x);
        cholmod_free_sparse(&A, cc);
    }
    ck_assert_int_ge(fallback, 6);
    ck_assert_int_ge(rebuilt, 1);
    tk_nnls_free(&s);
}
END_TEST

/* Builds a small rank-deficient matrix of the given kind from a random
 * flow-like one (V vertices, n0 independent columns). */
static cholmod_sparse *rank_deficient(cholmod_common *cc, tkt_rng *r, int kind, size_t V,
                                      size_t n0, size_t extra)
{
    cholmod_sparse *A0 = flow_matrix(cc, r, V, n0);
    size_t m = A0->nrow;
    double *D0 = dense_from_sparse(A0);
    cholmod_free_sparse(&A0, cc);
    size_t n = n0 + extra;
    double *D = calloc(m * n, sizeof *D);
    memcpy(D, D0, m * n0 * sizeof *D);
    for (size_t q = 0; q < extra; q++) {
        double *col = D + (n0 + q) * m;
        size_t a = (size_t)(tkt_rng_next(r) % n0), c = (size_t)(tkt_rng_next(r) % n0);
        switch (kind) {
        case 0: /* duplicates */
            memcpy(col, D0 + a * m, m * sizeof *col);
            break;
        case 1: /* sums of two others */
            for (size_t i = 0; i < m; i++)
                col[i] = D0[i + a * m] + D0[i + c * m];
            break;
        case 2: /* far more columns than rows: random sparse ones */
            for (int t = 0; t < 6; t++)
                col[tkt_rng_next(r) % m] = tkt_rng_range(r, -1, 1);
            break;
        default: /* zero columns */
            break;
        }
    }
    /* mix the extra columns in among the others */
    for (size_t q = n; q > 1; q--) {
        size_t p = (size_t)(tkt_rng_next(r) % q);
        for (size_t i = 0; i < m; i++) {
            double t = D[i + (q - 1) * m];
            D[i + (q - 1) * m] = D[i + p * m];
            D[i + p * m] = t;
        }
    }
    cholmod_sparse *A = sparse_from_dense(cc, m, n, D);
    free(D0);
    free(D);
    return A;
}

START_TEST(rank_deficient_problems)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {99};
    int regularised = 0, fallback = 0;
    for (int kind = 0; kind < 4; kind++)
        for (int trial = 0; trial < 40; trial++) {
            /* small ones against enumeration, larger ones on KKT alone */
            bool small = trial < 30;
            size_t V = small ? 3 : 60, n0 = small ? 5 : 90, extra = small ? 4 : 12;
            if (kind == 2) {
                /* 6 x 9 small; 180 x 450 large */
                V = small ? 2 : 60;
                n0 = small ? 3 : 90;
                extra = small ? 6 : 360;
            }
            cholmod_sparse *A = rank_deficient(cc, &r, kind, V, n0, extra);
            size_t m = A->nrow, n = A->ncol;
            double *b = random_vector(&r, m);
            double *x = malloc(n * sizeof *x), *xr = malloc(n * sizeof *xr);
            tk_nnls_report rep;
            char what[80];
            snprintf(what, sizeof what, "kind %d trial %d (%zu x %zu)", kind, trial, m, n);
            ck_assert_msg(solve(s, A, b, x, &tight, &rep) == TK_OK, "%s: not converged", what);
            regularised += rep.regularised;
            fallback += rep.used_fallback;
            double rn = assert_kkt(A, b, x, 1e-9, what);
            if (small && n <= 12) {
                double *D = dense_from_sparse(A);
                double ref = dense_nnls_enumerate(D, m, n, b, xr);
                ck_assert_msg(fabs(rn - ref) <= 1e-10 * vnorm(b, m),
                              "%s: residual %.17g, reference %.17g", what, rn, ref);
                free(D);
            }
            if (kind == 3) {
                /* zero columns stay at zero */
                for (size_t j = 0; j < n; j++)
                    if (column_norm(A, j) == 0.0)
                        ck_assert(x[j] == 0.0);
            }
            free(b);
            free(x);
            free(xr);
            cholmod_free_sparse(&A, cc);
        }
    /* some passive set was singular somewhere, and some problem needed
     * the fallback */
    ck_assert_int_gt(regularised, 0);
    ck_assert_int_gt(fallback, 0);
    tk_nnls_free(&s);
}
END_TEST

/* Column norms from 1e-4 to 1e4 and b of size 1e6: the tolerances are
 * relative to each column and to b, so the answer is the unscaled one,
 * rescaled. */
START_TEST(scale_invariance)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {31};
    for (int trial = 0; trial < 10; trial++) {
        cholmod_sparse *A = flow_matrix(cc, &r, 200, 400);
        size_t m = A->nrow, n = A->ncol;
        double *b = random_vector(&r, m), *x = malloc(n * sizeof *x), *xs = malloc(n * sizeof *xs);
        double *scale = malloc(n * sizeof *scale);
        tk_nnls_report rep, reps;
        ck_assert_int_eq(solve(s, A, b, x, NULL, &rep), TK_OK);
        cholmod_sparse *B = cholmod_copy_sparse(A, cc);
        const int *Bp = B->p;
        double *Bx = B->x;
        for (size_t j = 0; j < n; j++) {
            scale[j] = pow(10.0, tkt_rng_range(&r, -4, 4));
            for (int e = Bp[j]; e < Bp[j + 1]; e++)
                Bx[e] *= scale[j];
        }
        for (size_t k = 0; k < m; k++)
            b[k] *= 1e6;
        ck_assert_int_eq(solve(s, B, b, xs, NULL, &reps), TK_OK);
        assert_kkt(B, b, xs, 1e-9, "scaled");
        ck_assert_msg(tkt_reldiff(reps.residual, 1e6 * rep.residual) < 1e-9, "residual %g vs %g",
                      reps.residual, 1e6 * rep.residual);
        ck_assert_int_eq(rep.iterations, reps.iterations);
        /* the pivot-ratio estimate is of the unit-column matrix: unchanged */
        ck_assert(tkt_reldiff(rep.rcond, reps.rcond) < 1e-6);
        double xn = vnorm(x, n);
        for (size_t j = 0; j < n; j++)
            ck_assert_msg(fabs(xs[j] * scale[j] / 1e6 - x[j]) <= 1e-8 * xn, "x[%zu]", j);
        free(b);
        free(x);
        free(xs);
        free(scale);
        cholmod_free_sparse(&A, cc);
        cholmod_free_sparse(&B, cc);
    }
    tk_nnls_free(&s);
}
END_TEST

START_TEST(duplicate_pair_is_regularised)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    /* A = [a a], b = a: both columns enter F together, M is singular */
    double D[8] = {1, 2, 0, -1, 1, 2, 0, -1};
    cholmod_sparse *A = sparse_from_dense(cc, 4, 2, D);
    double b[4] = {1, 2, 0, -1}, x[2];
    tk_nnls_report rep;
    ck_assert_int_eq(solve(s, A, b, x, NULL, &rep), TK_OK);
    ck_assert(rep.regularised);
    ck_assert(rep.regularisation > 0.0 && rep.regularisation <= 1e-2);
    ck_assert(rep.rcond < 1e-14);
    ck_assert_double_eq_tol(x[0] + x[1], 1.0, 1e-9);
    ck_assert(rep.residual < 1e-9);
    assert_kkt(A, b, x, 1e-9, "duplicate pair");
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
}
END_TEST

START_TEST(degenerate_problems)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {5};
    tk_nnls_report rep;
    tk_error err;

    /* b = 0: x = 0 */
    cholmod_sparse *A = flow_matrix(cc, &r, 20, 30);
    double b0[60] = {0}, x[60];
    for (size_t j = 0; j < 30; j++)
        x[j] = 123.0;
    ck_assert_int_eq(solve(s, A, b0, x, NULL, &rep), TK_OK);
    for (size_t j = 0; j < 30; j++)
        ck_assert(x[j] == 0.0);
    ck_assert(rep.residual == 0.0 && rep.passive == 0);

    /* every column useless: a_j . b <= 0 for all j, so x = 0 */
    double *b = random_vector(&r, 60);
    {
        int *Ap = A->p;
        double *Ax = A->x;
        const int *Ai = A->i;
        for (size_t j = 0; j < 30; j++) {
            double d = 0;
            for (int e = Ap[j]; e < Ap[j + 1]; e++)
                d += Ax[e] * b[Ai[e]];
            if (d > 0)
                for (int e = Ap[j]; e < Ap[j + 1]; e++)
                    Ax[e] = -Ax[e];
        }
    }
    ck_assert_int_eq(solve(s, A, b, x, NULL, &rep), TK_OK);
    for (size_t j = 0; j < 30; j++)
        ck_assert(x[j] == 0.0);
    ck_assert(rep.passive == 0);
    ck_assert_double_eq_tol(rep.residual, vnorm(b, 60), 1e-12);

    /* b in the cone: b = A w, w >= 0 with zeros: residual 0 */
    double w[30];
    for (size_t j = 0; j < 30; j++)
        w[j] = j % 3 == 0 ? 0.0 : tkt_rng_range(&r, 0.1, 2);
    {
        const int *Ap = A->p, *Ai = A->i;
        const double *Ax = A->x;
        memset(b, 0, 60 * sizeof *b);
        for (size_t j = 0; j < 30; j++)
            for (int e = Ap[j]; e < Ap[j + 1]; e++)
                b[Ai[e]] += Ax[e] * w[j];
    }
    ck_assert_int_eq(solve(s, A, b, x, NULL, &rep), TK_OK);
    ck_assert_msg(rep.residual <= 1e-10 * vnorm(b, 60), "residual %g", rep.residual);
    assert_kkt(A, b, x, 1e-9, "b in the cone");
    /* 30 random columns in R^60 are independent: w itself comes back */
    for (size_t j = 0; j < 30; j++)
        ck_assert_msg(fabs(x[j] - w[j]) < 1e-8, "x[%zu] = %.17g, w = %.17g", j, x[j], w[j]);
    cholmod_free_sparse(&A, cc);

    /* one column: x = max(0, a.b / a.a) */
    for (int sign = -1; sign <= 1; sign += 2) {
        double a[5] = {1, -2, 0.5, 3, 0}, bb[5] = {2, 1, -1, 4, 7};
        for (int k = 0; k < 5; k++)
            a[k] *= sign;
        A = sparse_from_dense(cc, 5, 1, a);
        double x1;
        ck_assert_int_eq(solve(s, A, bb, &x1, NULL, &rep), TK_OK);
        double expect = fmax(0.0, dot(a, bb, 5) / dot(a, a, 5));
        ck_assert_double_eq_tol(x1, expect, 1e-14);
        cholmod_free_sparse(&A, cc);
    }

    /* no columns at all */
    A = cholmod_allocate_sparse(6, 0, 0, 1, 1, 0, CHOLMOD_REAL, cc);
    ck_assert_int_eq(tk_nnls_solve(s, A, b, NULL, NULL, &rep, &err), TK_OK);
    ck_assert_double_eq_tol(rep.residual, vnorm(b, 6), 1e-15);
    ck_assert(rep.rcond == 1.0 && rep.iterations == 0);
    double du[6];
    double delta;
    ck_assert_int_eq(tk_nnls_min_norm(s, A, NULL, 0.0, NULL, du, &delta, &err), TK_OK);
    for (int k = 0; k < 6; k++)
        ck_assert(du[k] == 0.0);
    cholmod_free_sparse(&A, cc);

    /* all-zero matrix */
    double Z[12] = {0};
    A = sparse_from_dense(cc, 4, 3, Z);
    ck_assert_int_eq(solve(s, A, b, x, NULL, &rep), TK_OK);
    ck_assert(x[0] == 0.0 && x[1] == 0.0 && x[2] == 0.0);
    cholmod_free_sparse(&A, cc);
    free(b);
    tk_nnls_free(&s);
}
END_TEST

START_TEST(invalid_input_and_iteration_limit)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {11};
    tk_error err;
    cholmod_sparse *A = flow_matrix(cc, &r, 100, 200);
    double *b = random_vector(&r, 300), *x = malloc(200 * sizeof *x);

    /* a symmetric-stored matrix is refused */
    A->stype = 1;
    ck_assert_int_eq(tk_nnls_solve(s, A, b, x, NULL, NULL, &err), TK_EINVAL);
    ck_assert(err.message[0] != '\0');
    A->stype = 0;
    /* so is a non-finite right-hand side */
    double keep = b[3];
    b[3] = NAN;
    ck_assert_int_eq(tk_nnls_solve(s, A, b, x, NULL, NULL, &err), TK_EINVAL);
    b[3] = keep;
    ck_assert_int_eq(tk_nnls_solve(NULL, A, b, x, NULL, NULL, &err), TK_EINVAL);

    /* this problem needs several iterations; with one allowed the best
     * iterate comes back, still non-negative */
    tk_nnls_report rep;
    ck_assert_int_eq(solve(s, A, b, x, NULL, &rep), TK_OK);
    ck_assert_int_gt(rep.iterations, 1);
    tk_nnls_options o = TK_NNLS_OPTIONS_INIT;
    o.max_iterations = 1;
    ck_assert_int_eq(tk_nnls_solve(s, A, b, x, &o, &rep, &err), TK_ENUMERIC);
    ck_assert_int_eq(rep.iterations, 1);
    ck_assert(strstr(err.message, "iterations") != NULL);
    for (size_t j = 0; j < 200; j++)
        ck_assert(x[j] >= 0.0);
    free(b);
    free(x);
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
    tk_nnls_free(&s); /* harmless twice */
    tk_nnls_free(NULL);
}
END_TEST

START_TEST(repeat_solves_are_identical)
{
    /* the second solve re-uses cached analyses; the answer must not move */
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {3};
    cholmod_sparse *A = flow_matrix(cc, &r, 500, 900);
    double *b = random_vector(&r, 1500);
    double *x1 = malloc(900 * sizeof *x1), *x2 = malloc(900 * sizeof *x2);
    tk_nnls_report r1, r2;
    ck_assert_int_eq(solve(s, A, b, x1, NULL, &r1), TK_OK);
    ck_assert_int_eq(solve(s, A, b, x2, NULL, &r2), TK_OK);
    ck_assert(memcmp(x1, x2, 900 * sizeof *x1) == 0);
    ck_assert_int_eq(r1.iterations, r2.iterations);
    /* a fresh solver agrees too */
    tk_nnls *t = new_solver();
    ck_assert_int_eq(solve(t, A, b, x2, NULL, &r2), TK_OK);
    ck_assert(memcmp(x1, x2, 900 * sizeof *x1) == 0);
    tk_nnls_free(&t);
    free(b);
    free(x1);
    free(x2);
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
}
END_TEST

/* The columns' ordering is kept for the next solve of the same pattern
 * (nnls.c, order_columns): a solver that has solved another pattern of
 * the same size in between, one whose first column meets another vertex,
 * answers each bit for bit as a fresh solver does. */
START_TEST(the_columns_order_serves_its_pattern_only)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {11};
    size_t V = 500, n = 900;
    cholmod_sparse *A = flow_matrix(cc, &r, V, n);
    cholmod_sparse *B = cholmod_copy_sparse(A, cc);
    ck_assert_ptr_nonnull(B);
    /* B: column 0's last vertex moved to vertex V - 1 (rows stay sorted) */
    int *Bp = B->p, *Bi = B->i;
    int last = Bi[Bp[1] - 1] / 3;
    ck_assert_int_lt(last, (int)V - 1);
    for (int c = 0; c < 3; c++)
        Bi[Bp[1] - 3 + c] = 3 * ((int)V - 1) + c;
    double *b = random_vector(&r, 3 * V);
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    ck_assert(x && y);
    const cholmod_sparse *order[] = {A, B, A, B, B};
    for (int k = 0; k < 5; k++) {
        tk_nnls_report rep, fresh;
        ck_assert_int_eq(solve(s, order[k], b, x, NULL, &rep), TK_OK);
        tk_nnls *t = new_solver();
        ck_assert_int_eq(solve(t, order[k], b, y, NULL, &fresh), TK_OK);
        tk_nnls_free(&t);
        ck_assert_int_ge(rep.factorisations, 1);
        ck_assert_msg(memcmp(x, y, n * sizeof *x) == 0, "solve %d differs from a fresh one", k);
        ck_assert_int_eq(rep.iterations, fresh.iterations);
    }
    free(b);
    free(x);
    free(y);
    cholmod_free_sparse(&A, cc);
    cholmod_free_sparse(&B, cc);
    tk_nnls_free(&s);
}
END_TEST

/* g = A^T du - r (n entries). */
static void transpose_residual(const cholmod_sparse *A, const double *du, const double *r,
                               double *g)
{
    const int *Ap = A->p, *Ai = A->i;
    const double *Ax = A->x;
    for (size_t j = 0; j < A->ncol; j++) {
        g[j] = -r[j];
        for (int e = Ap[j]; e < Ap[j + 1]; e++)
            g[j] += Ax[e] * du[Ai[e]];
    }
}

/* Checks min_norm on A (m x n, n <= m small enough for dense QR when
 * dense is true). */
static void check_min_norm(tk_nnls *s, const cholmod_sparse *A, tkt_rng *r, bool dense,
                           const char *what)
{
    size_t m = A->nrow, n = A->ncol;
    double *rr = random_vector(r, n), *du = malloc(m * sizeof *du);
    double *g = malloc((n + 1) * sizeof *g);
    double delta = -1;
    tk_error err;
    ck_assert_msg(tk_nnls_min_norm(s, A, rr, 0.0, NULL, du, &delta, &err) == TK_OK, "%s: %s", what,
                  err.message);
    ck_assert(delta == 0.0);
    /* A^T du = r */
    transpose_residual(A, du, rr, g);
    ck_assert_msg(vnorm(g, n) <= 1e-10 * vnorm(rr, n), "%s: ||A^T du - r|| = %g", what,
                  vnorm(g, n));
    if (dense) {
        /* Independent checks by Householder QR: du is in range(A) (least
         * squares of du on A leaves nothing), and du = A y with
         * R^T R y = r (A = QR), the pseudo-inverse solution (A^T)^+ r. */
        double *D = dense_from_sparse(A);
        double *B = malloc(m * n * sizeof *B), *y = malloc(n * sizeof *y);
        memcpy(B, D, m * n * sizeof *B);
        ck_assert(dense_ls(B, m, n, du, y)); /* y = argmin ||A y - du|| */
        double *p = calloc(m, sizeof *p);
        for (size_t j = 0; j < n; j++)
            for (size_t i = 0; i < m; i++)
                p[i] += D[i + j * m] * y[j];
        for (size_t i = 0; i < m; i++)
            p[i] -= du[i];
        ck_assert_msg(vnorm(p, m) <= 1e-10 * vnorm(du, m), "%s: du not in range(A): %g", what,
                      vnorm(p, m));
        /* the pseudo-inverse solution from R: R^T R y = r, du = A y */
        memcpy(B, D, m * n * sizeof *B);
        double *zz = malloc(n * sizeof *zz);
        ck_assert(dense_ls(B, m, n, du, zz)); /* B now holds R on top */
        double *t = malloc(n * sizeof *t);
        for (size_t j = 0; j < n; j++) { /* R^T t = r */
            double sum = rr[j];
            for (size_t q = 0; q < j; q++)
                sum -= B[q + j * m] * t[q];
            t[j] = sum / B[j + j * m];
        }
        for (size_t jj = n; jj-- > 0;) { /* R y = t */
            double sum = t[jj];
            for (size_t q = jj + 1; q < n; q++)
                sum -= B[jj + q * m] * y[q];
            y[jj] = sum / B[jj + jj * m];
        }
        memset(p, 0, m * sizeof *p);
        for (size_t j = 0; j < n; j++)
            for (size_t i = 0; i < m; i++)
                p[i] += D[i + j * m] * y[j];
        for (size_t i = 0; i < m; i++)
            ck_assert_msg(fabs(p[i] - du[i]) <= 1e-10 * vnorm(p, m), "%s: du[%zu] %.17g vs %.17g",
                          what, i, du[i], p[i]);
        free(D);
        free(B);
        free(y);
        free(p);
        free(zz);
        free(t);
    }
    free(rr);
    free(du);
    free(g);
}

START_TEST(min_norm_solutions)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {17};
    for (int trial = 0; trial < 40; trial++) {
        size_t V = 4 + (size_t)(tkt_rng_next(&r) % 7), n = 1 + (size_t)(tkt_rng_next(&r) % V);
        cholmod_sparse *A = flow_matrix(cc, &r, V, n);
        char what[64];
        snprintf(what, sizeof what, "min_norm trial %d", trial);
        check_min_norm(s, A, &r, true, what);
        cholmod_free_sparse(&A, cc);
    }
    size_t big[2] = {100, 1000};
    for (int k = 0; k < 2; k++) {
        cholmod_sparse *A = flow_matrix(cc, &r, big[k], big[k]);
        check_min_norm(s, A, &r, false, "min_norm large");
        cholmod_free_sparse(&A, cc);
    }
    /* dependent columns: the system is regularised and still answers */
    double D[12] = {1, 0, 1, 0, 1, 0, 1, 0, 2, 0, 2, 0};
    cholmod_sparse *A = sparse_from_dense(cc, 4, 3, D);
    double rr[3] = {1, 1, 2}, du[4], delta = 0;
    tk_error err;
    ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, 0.0, NULL, du, &delta, &err), TK_OK);
    ck_assert(delta > 0.0);
    /* consistent right-hand side: A^T du = r still holds closely */
    ck_assert_double_eq_tol(du[0] + du[2], 1.0, 1e-6);
    ck_assert_double_eq_tol(du[1], 0.0, 1e-12);
    ck_assert_double_eq_tol(du[0], du[2], 1e-6);
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
}
END_TEST

START_TEST(damped_min_norm_steps)
{
    /* More columns than rows (n > m: inconsistent, as recovery's violated
     * struts outnumber the coordinates), many more (the primal form is
     * then the smaller one) and fewer: with damping delta the answer
     * satisfies the damped least-squares optimality condition
     * A D^-1 (A^T du - r) + delta du = 0, D = diag(A^T A), checked here
     * from A itself (to 1e-6: the damped system's condition is up to
     * 1 / delta). */
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {29};
    const double deltas[3] = {1e-8, 1e-6, 1e-3};
    for (int trial = 0; trial < 45; trial++) {
        size_t V = 3 + (size_t)(tkt_rng_next(&r) % 6), m = 3 * V;
        size_t shape = (size_t)trial / 3 % 3, extra = tkt_rng_next(&r) % 20;
        size_t n = shape == 0 ? m + 1 + extra : shape == 1 ? 4 * m + extra : 1 + extra % (m / 2);
        cholmod_sparse *A = flow_matrix(cc, &r, V, n);
        double *rr = random_vector(&r, n), *du = malloc(m * sizeof *du);
        double *g = malloc(n * sizeof *g), *kkt = malloc(m * sizeof *kkt);
        double delta = deltas[trial % 3], used = -1;
        tk_error err;
        ck_assert_msg(tk_nnls_min_norm(s, A, rr, delta, NULL, du, &used, &err) == TK_OK, "%s",
                      err.message);
        ck_assert(used >= delta);
        const int *Ap = A->p, *Ai = A->i;
        const double *Ax = A->x;
        transpose_residual(A, du, rr, g);
        for (size_t i = 0; i < m; i++)
            kkt[i] = used * du[i];
        for (size_t j = 0; j < n; j++) {
            double d = column_norm(A, j);
            for (int e = Ap[j]; e < Ap[j + 1]; e++)
                kkt[Ai[e]] += Ax[e] * g[j] / (d * d);
        }
        double scale = used * vnorm(du, m) + 1e-300;
        ck_assert_msg(vnorm(kkt, m) <= 1e-6 * fmax(scale, vnorm(rr, n)),
                      "trial %d (delta %g): optimality %g against %g", trial, used,
                      vnorm(kkt, m), scale);
        /* du = 0 leaves all of r: the step does better */
        ck_assert(vnorm(g, n) < vnorm(rr, n));
        free(rr);
        free(du);
        free(g);
        free(kkt);
        cholmod_free_sparse(&A, cc);
    }
    /* a negative or huge damping is refused */
    cholmod_sparse *A = flow_matrix(cc, &r, 4, 4);
    double rr[4] = {1, 2, 3, 4}, du[12];
    tk_error err;
    ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, -1e-6, NULL, du, NULL, &err), TK_EINVAL);
    ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, 1.0, NULL, du, NULL, &err), TK_EINVAL);
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
}
END_TEST

/* M = I + w S' S, S the second differences along the coordinates taken
 * three apart (one axis of a closed chain of vertices): the shape of
 * error recovery's metric. */
static cholmod_sparse *bending_metric(cholmod_common *cc, size_t V, double w)
{
    size_t m = 3 * V;
    double *D = calloc(m * m, sizeof *D);
    for (size_t v = 0; v < V; v++)
        for (size_t x = 0; x < 3; x++) {
            size_t at[3] = {3 * ((v + V - 1) % V) + x, 3 * v + x, 3 * ((v + 1) % V) + x};
            double row[3] = {1.0, -2.0, 1.0};
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    D[at[a] + m * at[b]] += w * row[a] * row[b];
        }
    for (size_t i = 0; i < m; i++)
        D[i + m * i] += 1.0;
    cholmod_sparse *M = sparse_from_dense(cc, m, m, D);
    free(D);
    return M;
}

START_TEST(damped_steps_in_a_metric)
{
    /* The damped step in a metric M satisfies its own optimality condition
     * A D^-1 (A^T du - r) + delta M du = 0, checked from A and M; with
     * M = I it is the plain damped step; and it bends less than the plain
     * one (du' S'S du, the quantity the metric weighs). */
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {31};
    const double deltas[3] = {1e-6, 1e-4, 1e-2};
    for (int trial = 0; trial < 30; trial++) {
        size_t V = 5 + (size_t)(tkt_rng_next(&r) % 6), m = 3 * V;
        size_t n = trial % 2 ? m + 1 + tkt_rng_next(&r) % 20 : 1 + tkt_rng_next(&r) % (m / 2);
        double delta = deltas[trial % 3], w = 100.0;
        cholmod_sparse *A = flow_matrix(cc, &r, V, n), *M = bending_metric(cc, V, w);
        cholmod_sparse *eye = cholmod_speye(m, m, CHOLMOD_REAL, cc);
        double *rr = random_vector(&r, n), *du = malloc(m * sizeof *du);
        double *plain = malloc(m * sizeof *plain), *same = malloc(m * sizeof *same);
        double *g = malloc(n * sizeof *g), *kkt = malloc(m * sizeof *kkt);
        double used = -1.0;
        tk_error err;
        ck_assert_msg(tk_nnls_min_norm(s, A, rr, delta, M, du, &used, &err) == TK_OK, "%s",
                      err.message);
        ck_assert_double_eq(used, delta);
        ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, delta, eye, same, NULL, &err), TK_OK);
        ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, delta, NULL, plain, NULL, &err), TK_OK);
        const int *Ap = A->p, *Ai = A->i, *Mp = M->p, *Mi = M->i;
        const double *Ax = A->x, *Mx = M->x;
        transpose_residual(A, du, rr, g);
        memset(kkt, 0, m * sizeof *kkt);
        double bend = 0.0, plain_bend = 0.0;
        for (size_t j = 0; j < m; j++)
            for (int e = Mp[j]; e < Mp[j + 1]; e++) {
                kkt[Mi[e]] += delta * Mx[e] * du[j];
                double sts = (Mx[e] - ((size_t)Mi[e] == j)) / w;
                bend += du[Mi[e]] * sts * du[j];
                plain_bend += plain[Mi[e]] * sts * plain[j];
            }
        for (size_t j = 0; j < n; j++) {
            double d = column_norm(A, j);
            for (int e = Ap[j]; e < Ap[j + 1]; e++)
                kkt[Ai[e]] += Ax[e] * g[j] / (d * d);
        }
        double scale = delta * vnorm(du, m) + 1e-300;
        ck_assert_msg(vnorm(kkt, m) <= 1e-6 * fmax(scale, vnorm(rr, n)),
                      "trial %d (delta %g): optimality %g against %g", trial, delta,
                      vnorm(kkt, m), scale);
        double gap = 0.0;
        for (size_t i = 0; i < m; i++)
            gap = fmax(gap, fabs(same[i] - plain[i]));
        ck_assert_msg(gap <= 1e-8 * vnorm(plain, m), "trial %d: identity metric off by %g",
                      trial, gap);
        ck_assert_msg(bend <= plain_bend * (1.0 + 1e-9), "trial %d: bends %g, plain %g", trial,
                      bend, plain_bend);
        free(rr);
        free(du);
        free(plain);
        free(same);
        free(g);
        free(kkt);
        cholmod_free_sparse(&A, cc);
        cholmod_free_sparse(&M, cc);
        cholmod_free_sparse(&eye, cc);
    }
    /* a metric needs a damping, and the step's order */
    cholmod_sparse *A = flow_matrix(cc, &r, 5, 4), *M = bending_metric(cc, 5, 1.0),
                   *small = bending_metric(cc, 4, 1.0);
    double rr[4] = {1, 2, 3, 4}, du[15];
    tk_error err;
    ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, 0.0, M, du, NULL, &err), TK_EINVAL);
    ck_assert_int_eq(tk_nnls_min_norm(s, A, rr, 1e-4, small, du, NULL, &err), TK_EINVAL);
    cholmod_free_sparse(&A, cc);
    cholmod_free_sparse(&M, cc);
    cholmod_free_sparse(&small, cc);
    tk_nnls_free(&s);
}
END_TEST

/* Re-entrancy: two solvers in two threads. */
typedef struct job {
    unsigned long long seed;
    size_t V, n;
    double *x;       /* answers */
    double *du;
    int rc;
} job;

static void *run_job(void *arg)
{
    job *jb = arg;
    tk_nnls *s = NULL;
    tk_error err;
    jb->rc = tk_nnls_new(&s, &err);
    if (jb->rc != TK_OK)
        return NULL;
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {jb->seed};
    for (int round = 0; round < 4 && jb->rc == TK_OK; round++) {
        cholmod_sparse *A = flow_matrix(cc, &r, jb->V, jb->n);
        double *b = random_vector(&r, 3 * jb->V), *rr = random_vector(&r, jb->n);
        jb->rc = tk_nnls_solve(s, A, b, jb->x + round * jb->n, NULL, NULL, &err);
        if (jb->rc == TK_OK)
            jb->rc = tk_nnls_min_norm(s, A, rr, 0.0, NULL, jb->du + round * 3 * jb->V, NULL, &err);
        free(b);
        free(rr);
        cholmod_free_sparse(&A, cc);
    }
    tk_nnls_free(&s);
    return NULL;
}

START_TEST(two_threads_match_series)
{
    job series[2] = {{101, 400, 700, NULL, NULL, 0}, {202, 300, 250, NULL, NULL, 0}};
    job parallel[2];
    for (int k = 0; k < 2; k++) {
        series[k].x = calloc(4 * series[k].n, sizeof(double));
        series[k].du = calloc(12 * series[k].V, sizeof(double));
        parallel[k] = series[k];
        parallel[k].x = calloc(4 * series[k].n, sizeof(double));
        parallel[k].du = calloc(12 * series[k].V, sizeof(double));
        run_job(&series[k]);
        ck_assert_int_eq(series[k].rc, TK_OK);
    }
    pthread_t th[2];
    for (int k = 0; k < 2; k++)
        ck_assert_int_eq(pthread_create(&th[k], NULL, run_job, &parallel[k]), 0);
    for (int k = 0; k < 2; k++)
        ck_assert_int_eq(pthread_join(th[k], NULL), 0);
    for (int k = 0; k < 2; k++) {
        ck_assert_int_eq(parallel[k].rc, TK_OK);
        ck_assert(memcmp(series[k].x, parallel[k].x, 4 * series[k].n * sizeof(double)) == 0);
        ck_assert(memcmp(series[k].du, parallel[k].du, 12 * series[k].V * sizeof(double)) == 0);
        free(series[k].x);
        free(series[k].du);
        free(parallel[k].x);
        free(parallel[k].du);
    }
}
END_TEST

/* Asserts the KKT conditions of the proximal problem
 *     min ||A x - b||^2 + mu sum_j s_j^2 (x_j - c_j)^2,  x >= 0
 * at x (its half gradient A^T (A x - b) + mu s_j^2 (x_j - c_j) is >= 0,
 * and 0 where x_j > 0), tolerance as assert_kkt's. */
static void assert_proximal_kkt(const cholmod_sparse *A, const double *b, const double *c,
                                double mu, const double *x, double rel, const char *what)
{
    size_t m = A->nrow, n = A->ncol;
    double *res = malloc((m + 1) * sizeof *res), *g = malloc((n + 1) * sizeof *g);
    ck_assert(res && g);
    residual_gradient(A, b, x, res, g);
    double bn = vnorm(b, m);
    for (size_t j = 0; j < n; j++) {
        double sj = column_norm(A, j), tol = rel * sj * bn;
        g[j] += mu * sj * sj * (x[j] - c[j]);
        ck_assert_msg(x[j] >= 0.0, "%s: x[%zu] = %g < 0", what, j, x[j]);
        ck_assert_msg(g[j] >= -tol, "%s: gradient[%zu] = %g < -%g", what, j, g[j], tol);
        if (x[j] > 0.0)
            ck_assert_msg(fabs(g[j]) <= tol, "%s: x[%zu] = %g > 0 but gradient %g", what, j,
                          x[j], g[j]);
    }
    free(res);
    free(g);
}

/* The proximal problem on rank-deficient and wide problems, where the
 * plain one needs regularisation and the fallback: its KKT conditions
 * hold without regularisation, from a random centre; and the proximal point
 * method (each answer the next centre) ends at the plain problem's
 * residual, as found by the plain solver. */
START_TEST(proximal_problems)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {4242};
    int plain_fallback = 0;
    for (int kind = 0; kind < 3; kind++)
        for (int trial = 0; trial < 8; trial++) {
            size_t V = 60, n0 = 90, extra = kind == 2 ? 360 : 40;
            cholmod_sparse *A = rank_deficient(cc, &r, kind, V, n0, extra);
            size_t m = A->nrow, n = A->ncol;
            double *b = random_vector(&r, m);
            double *c = malloc(n * sizeof *c), *x = malloc(n * sizeof *x);
            double *plain = malloc(n * sizeof *plain);
            for (size_t j = 0; j < n; j++) {
                double v = tkt_rng_range(&r, -1, 1);
                c[j] = v > 0.0 ? v : 0.0;
            }
            char what[80];
            snprintf(what, sizeof what, "kind %d trial %d (%zu x %zu)", kind, trial, m, n);
            tk_nnls_report rep;
            ck_assert_int_eq(solve(s, A, b, plain, &tight, &rep), TK_OK);
            plain_fallback += rep.used_fallback;
            double best = rep.residual;
            tk_nnls_options o = tight;
            o.proximal = 1e-2;
            memcpy(x, c, n * sizeof *x);
            ck_assert_msg(solve(s, A, b, x, &o, &rep) == TK_OK, "%s: not converged", what);
            ck_assert_msg(!rep.regularised, "%s: regularised", what);
            assert_proximal_kkt(A, b, c, o.proximal, x, 1e-9, what);
            ck_assert(rep.residual >= best * (1.0 - 1e-12));
            /* the proximal point method: the residual falls to the plain
             * problem's (within 1e-10 ||b||: it may be 0) */
            double bn = vnorm(b, m), previous = rep.residual;
            int it = 0;
            for (; it < 2000 && rep.residual > best + 1e-10 * bn; it++) {
                ck_assert_int_eq(solve(s, A, b, x, &o, &rep), TK_OK);
                ck_assert_msg(rep.residual <= previous + 1e-12 * bn, "%s: rose from %.17g to %.17g",
                              what, previous, rep.residual);
                previous = rep.residual;
            }
            ck_assert_msg(rep.residual <= best + 1e-10 * bn, "%s: %.17g, plain %.17g", what,
                          rep.residual, best);
            free(b);
            free(c);
            free(x);
            free(plain);
            cholmod_free_sparse(&A, cc);
        }
    /* the same problems needed the fallback when plain */
    ck_assert_int_gt(plain_fallback, 0);
    tk_nnls_options bad = tight;
    bad.proximal = -1.0;
    double A1[3] = {1, 0, 0}, b1[3] = {1, 1, 1}, x1[1] = {0};
    cholmod_sparse *A = sparse_from_dense(cc, 3, 1, A1);
    tk_error err;
    ck_assert_int_eq(tk_nnls_solve(s, A, b1, x1, &bad, NULL, &err), TK_EINVAL);
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
}
END_TEST

/* Rounds of the proximal point method (tk/nnls.h) whose weight shrinks
 * tenfold a round from 1e-2 to 1e-8, each centred at the last answer, on wide
 * flow problems whose passive sets hold more than half as many columns as
 * there are coordinates (so the solver's coordinate form, m x m, serves
 * them), with the fallback at the small weights: every answer meets its
 * proximal problem's KKT conditions, and the residual never rises from
 * one round to the next by more than rounding.  Each sequence runs twice,
 * its fallback Lawson and Hanson's and then the interior point's: the
 * proximal problem's answer is unique, so the two agree. */
#define ROUNDS 7

START_TEST(proximal_rounds_on_wide_problems)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {777};
    int fallback = 0, wide = 0, interior = 0;
    for (int trial = 0; trial < 5; trial++) {
        size_t V = trial < 3 ? 100 : 160;
        cholmod_sparse *A = flow_matrix(cc, &r, V, 6 * V);
        size_t m = A->nrow, n = A->ncol;
        double *b = random_vector(&r, m);
        double *c = calloc(n, sizeof *c), *x = calloc(n, sizeof *x);
        double *lh = calloc(ROUNDS * n, sizeof *lh);
        ck_assert(c && x && lh);
        for (int way = -1; way <= 1; way += 2) {
            tk_nnls_options o = tight;
            o.warm_start = true;
            o.interior = way;
            memset(x, 0, n * sizeof *x);
            double previous = INFINITY, mu = 1e-2;
            for (int round = 0; round < ROUNDS; round++, mu *= 0.1) {
                char what[100];
                snprintf(what, sizeof what, "trial %d (%zu x %zu) mu %g %s", trial, m, n, mu,
                         way < 0 ? "Lawson-Hanson" : "interior point");
                memcpy(c, x, n * sizeof *c);
                o.proximal = mu;
                tk_nnls_report rep;
                ck_assert_msg(solve(s, A, b, x, &o, &rep) == TK_OK, "%s: not converged", what);
                assert_proximal_kkt(A, b, c, mu, x, 1e-9, what);
                ck_assert_msg(rep.residual <= previous * (1.0 + 1e-9),
                              "%s: residual rose from %.17g to %.17g", what, previous,
                              rep.residual);
                previous = rep.residual;
                fallback += rep.used_fallback;
                wide += 2 * rep.passive > m;
                if (way < 0) {
                    ck_assert_int_eq(rep.interior_steps, 0);
                    memcpy(lh + round * n, x, n * sizeof *x);
                    continue;
                }
                interior += rep.interior_steps > 0;
                double diff = 0.0, size = 0.0;
                for (size_t j = 0; j < n; j++) {
                    double sj = column_norm(A, j);
                    diff = fmax(diff, sj * fabs(x[j] - lh[round * n + j]));
                    size = fmax(size, sj * fabs(x[j]));
                }
                ck_assert_msg(diff <= 1e-9 * size, "%s: %g from Lawson and Hanson's (of %g)",
                              what, diff, size);
            }
        }
        free(b);
        free(c);
        free(x);
        free(lh);
        cholmod_free_sparse(&A, cc);
    }
    ck_assert_int_gt(fallback, 0);
    ck_assert_int_gt(wide, 0);
    ck_assert_int_gt(interior, 0);
    tk_nnls_free(&s);
}
END_TEST


/* The coordinate form (m x m) serves a passive set of more than 2,000
 * columns even when they are fewer than half the coordinates: there the
 * n_F x n_F factor fills far more (tk/nnls.h).  A flow problem on 1,600
 * vertices (4,800 coordinates) whose proximal answer is a chosen x0 > 0
 * on 2,200 of its 2,600 columns (b = A x0, centred at x0): the answer
 * comes back, its KKT conditions hold, and the coordinate form's factor
 * is kept; on 1,500 columns the other form serves (no factor kept). */
START_TEST(many_passive_columns_use_the_coordinate_form)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {2026};
    const size_t V = 1600, n = 2600, supports[] = {2200, 1500};
    cholmod_sparse *A = flow_matrix(cc, &r, V, n);
    size_t m = A->nrow;
    for (int k = 0; k < 2; k++) {
        double *x0 = calloc(n, sizeof *x0), *x = calloc(n, sizeof *x), *b = calloc(m, sizeof *b);
        ck_assert(x0 && x && b);
        for (size_t j = 0; j < supports[k]; j++)
            x0[j] = tkt_rng_range(&r, 0.5, 1.5) / column_norm(A, j);
        const int *Ap = A->p, *Ai = A->i;
        const double *Ax = A->x;
        for (size_t j = 0; j < n; j++)
            for (int e = Ap[j]; e < Ap[j + 1]; e++)
                b[Ai[e]] += Ax[e] * x0[j];
        tk_nnls_options o = tight;
        o.warm_start = true;
        o.proximal = 1e-2;
        memcpy(x, x0, n * sizeof *x);
        char what[80];
        snprintf(what, sizeof what, "%zu of %zu columns on %zu coordinates", supports[k], n, m);
        tk_nnls_report rep;
        ck_assert_msg(solve(s, A, b, x, &o, &rep) == TK_OK, "%s: not converged", what);
        assert_proximal_kkt(A, b, x0, o.proximal, x, 1e-9, what);
        ck_assert_uint_eq(rep.passive, supports[k]);
        ck_assert_msg(2 * rep.passive < m, "%s: more than half the coordinates", what);
        double gap = 0.0;
        for (size_t j = 0; j < n; j++)
            gap = fmax(gap, column_norm(A, j) * fabs(x[j] - x0[j]));
        ck_assert_msg(gap <= 1e-9, "%s: %g from the chosen answer", what, gap);
        printf("%s: %s form\n", what, rep.kept ? "coordinate" : "normal");
        ck_assert_int_eq(rep.kept, supports[k] > 2000);
        free(x0);
        free(x);
        free(b);
    }
    cholmod_free_sparse(&A, cc);
    tk_nnls_free(&s);
}
END_TEST

/* The scaled largest difference of two answers, against the first's size. */
static double answer_gap(const cholmod_sparse *A, const double *x, const double *y)
{
    double diff = 0.0, size = 0.0;
    for (size_t j = 0; j < A->ncol; j++) {
        double sj = column_norm(A, j);
        diff = fmax(diff, sj * fabs(x[j] - y[j]));
        size = fmax(size, sj * fabs(x[j]));
    }
    return size > 0.0 ? diff / size : diff;
}

/* A solve with x as the centre on a fresh solver (nothing kept): into y. */
static tk_nnls_report fresh_solve(const cholmod_sparse *A, const double *b, const double *x,
                                  double *y, const tk_nnls_options *o)
{
    tk_nnls *t = new_solver();
    tk_nnls_report rep;
    memcpy(y, x, A->ncol * sizeof *y);
    ck_assert_int_eq(solve(t, A, b, y, o, &rep), TK_OK);
    tk_nnls_free(&t);
    return rep;
}

/* The coordinate form's factor kept from one solve to the next (tk/nnls.h):
 * rounds of the proximal point method at one weight on a wide flow
 * problem start from the last round's factor, with no factorisation of
 * their own where the passive set changed little, and their answers are
 * a fresh solver's.  A matrix with one entry changed, or another weight,
 * is factored afresh; a matrix with a column fewer (another pattern, the
 * same rows: the kept ordering) is solved as a fresh solver does. */
START_TEST(kept_factor_serves_the_same_matrix_only)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {2027};
    size_t V = 120;
    cholmod_sparse *A = flow_matrix(cc, &r, V, 6 * V);
    size_t m = A->nrow, n = A->ncol;
    double *b = random_vector(&r, m);
    double *x = calloc(n, sizeof *x), *y = calloc(n, sizeof *y), *c = calloc(n, sizeof *c);
    ck_assert(x && y && c);
    tk_nnls_options o = tight;
    o.warm_start = true;
    o.proximal = 1e-3;
    int reused = 0;
    for (int round = 0; round < 8; round++) {
        memcpy(c, x, n * sizeof *c);
        tk_nnls_report rep, fresh = fresh_solve(A, b, c, y, &o);
        ck_assert_int_eq(solve(s, A, b, x, &o, &rep), TK_OK);
        ck_assert_msg(2 * rep.passive > m, "round %d: %zu passive of %zu rows", round,
                      rep.passive, m);
        ck_assert_int_ge(fresh.factorisations, 1);
        reused += round > 0 && rep.factorisations == 0;
        double gap = answer_gap(A, y, x);
        ck_assert_msg(gap <= 1e-9, "round %d: %g from a fresh solver's", round, gap);
        assert_proximal_kkt(A, b, c, o.proximal, x, 1e-9, "kept factor");
    }
    ck_assert_int_gt(reused, 0);

    /* one entry changed: the same pattern, another matrix */
    double *Ax = A->x;
    Ax[7] *= 1.001;
    tk_nnls_report rep;
    fresh_solve(A, b, x, y, &o);
    ck_assert_int_eq(solve(s, A, b, x, &o, &rep), TK_OK);
    ck_assert_int_ge(rep.factorisations, 1);
    ck_assert_msg(answer_gap(A, y, x) <= 1e-9, "changed entry: %g", answer_gap(A, y, x));

    /* another weight */
    tk_nnls_options o2 = o;
    o2.proximal = 2e-3;
    fresh_solve(A, b, x, y, &o2);
    ck_assert_int_eq(solve(s, A, b, x, &o2, &rep), TK_OK);
    ck_assert_int_ge(rep.factorisations, 1);
    ck_assert_msg(answer_gap(A, y, x) <= 1e-9, "other weight: %g", answer_gap(A, y, x));

    /* a column fewer */
    int *keep = malloc(n * sizeof *keep);
    ck_assert_ptr_nonnull(keep);
    for (size_t j = 0; j + 1 < n; j++)
        keep[j] = (int)(j < 11 ? j : j + 1);
    cholmod_sparse *B = cholmod_submatrix(A, NULL, -1, keep, (long)(n - 1), 1, 1, cc);
    ck_assert_ptr_nonnull(B);
    for (size_t j = 11; j + 1 < n; j++)
        x[j] = x[j + 1];
    fresh_solve(B, b, x, y, &o);
    ck_assert_int_eq(solve(s, B, b, x, &o, &rep), TK_OK);
    ck_assert_int_ge(rep.factorisations, 1);
    ck_assert_msg(answer_gap(B, y, x) <= 1e-9, "a column fewer: %g", answer_gap(B, y, x));

    free(keep);
    free(b);
    free(x);
    free(y);
    free(c);
    cholmod_free_sparse(&A, cc);
    cholmod_free_sparse(&B, cc);
    tk_nnls_free(&s);
}
END_TEST

/* Passive solves without refinement (opts->unrefined, tk/nnls.h): rounds
 * of the proximal point method from 1e-2 down to 1e-8 tenfold, each
 * centred at its last answer, on wide flow problems in the coordinate
 * form, once with every solve refined and once with none from 1e-6 on.
 * Every answer meets its proximal problem's KKT conditions; in the
 * rounds left unrefined the two runs' answers differ (the option acts)
 * by no more than 1e-9 of their size: about eps / mu, 1.5e-10 at most at
 * 1e-6 here.  (The refined rounds after them start from centres that
 * differ by as much, and at 1e-8 that reached 2.9e-9.) */
START_TEST(unrefined_solves_meet_kkt)
{
    tk_nnls *s = new_solver();
    cholmod_common *cc = tk_nnls_common(s);
    tkt_rng r = {4242};
    int differ = 0, wide = 0;
    for (int trial = 0; trial < 4; trial++) {
        size_t V = 120;
        cholmod_sparse *A = flow_matrix(cc, &r, V, 6 * V);
        size_t m = A->nrow, n = A->ncol;
        double *b = random_vector(&r, m);
        double *xs[2], *c = calloc(n, sizeof *c);
        ck_assert(c);
        for (int way = 0; way < 2; way++) {
            xs[way] = calloc(ROUNDS * n, sizeof *xs[way]);
            ck_assert(xs[way]);
            tk_nnls_options o = tight;
            o.warm_start = true;
            o.unrefined = way ? 1e-6 : 0.0;
            double mu = 1e-2;
            for (int round = 0; round < ROUNDS; round++, mu *= 0.1) {
                char what[100];
                snprintf(what, sizeof what, "trial %d (%zu x %zu) mu %g, %s", trial, m, n, mu,
                         way ? "unrefined from 1e-6" : "refined");
                double *x = xs[way] + round * n;
                if (round > 0)
                    memcpy(x, x - n, n * sizeof *x);
                memcpy(c, x, n * sizeof *c);
                o.proximal = mu;
                tk_nnls_report rep;
                ck_assert_msg(solve(s, A, b, x, &o, &rep) == TK_OK, "%s: not converged", what);
                assert_proximal_kkt(A, b, c, mu, x, 1e-9, what);
                wide += way == 0 && rep.kept;
            }
        }
        for (int round = 0; round < ROUNDS; round++) {
            double gap = answer_gap(A, xs[0] + round * n, xs[1] + round * n);
            /* 1e-2, 1e-3, ...: the first five rounds are at 1e-6 or more,
             * where the unrefined solve loses about eps / mu */
            if (round >= 5)
                continue;
            ck_assert_msg(gap <= 1e-9, "trial %d round %d: the unrefined answer %g from the "
                          "refined one", trial, round, gap);
            differ += gap > 0.0;
        }
        free(b);
        free(c);
        free(xs[0]);
        free(xs[1]);
        cholmod_free_sparse(&A, cc);
    }
    printf("unrefined solves: %d of 20 rounds at 1e-6 or more differ from the refined ones "
           "(within 1e-9), %d solves kept the coordinate form's factor\n", differ, wide);
    ck_assert_int_gt(differ, 0);
    ck_assert_int_gt(wide, 0);
    tk_nnls_free(&s);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("nnls");
    TCase *tc = tcase_create("nnls");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, kkt_on_random_flow_problems);
    tcase_add_test(tc, matches_dense_enumeration);
    tcase_add_test(tc, wide_problems_match_enumeration);
    tcase_add_test(tc, wide_flow_problems_meet_kkt);
    tcase_add_test(tc, rank_deficient_problems);
    tcase_add_test(tc, scale_invariance);
    tcase_add_test(tc, duplicate_pair_is_regularised);
    tcase_add_test(tc, degenerate_problems);
    tcase_add_test(tc, invalid_input_and_iteration_limit);
    tcase_add_test(tc, repeat_solves_are_identical);
    tcase_add_test(tc, the_columns_order_serves_its_pattern_only);
    tcase_add_test(tc, min_norm_solutions);
    tcase_add_test(tc, damped_min_norm_steps);
    tcase_add_test(tc, damped_steps_in_a_metric);
    tcase_add_test(tc, two_threads_match_series);
    tcase_add_test(tc, proximal_problems);
    tcase_add_test(tc, proximal_rounds_on_wide_problems);
    tcase_add_test(tc, many_passive_columns_use_the_coordinate_form);
    tcase_add_test(tc, kept_factor_serves_the_same_matrix_only);
    tcase_add_test(tc, unrefined_solves_meet_kkt);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
