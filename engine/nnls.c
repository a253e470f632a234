/* Sparse non-negative least squares by block principal pivoting.
 *
 * The problem min ||A x - b||, x >= 0 is the linear complementarity problem
 *     y = A^T (A x - b),  x >= 0,  y >= 0,  x_i y_i = 0.
 * Block principal pivoting (Portugal, Judice and Vicente 1994; Kim and Park
 * 2011, the single right-hand-side algorithm) keeps a partition of the
 * variables into a passive set F, where x_F solves the unconstrained
 * problem min ||A_F x_F - b|| and y_F = 0, and an active set G, where
 * x_G = 0 and y_G = A_G^T (A_F x_F - b).  A variable is infeasible when
 * x_i < 0 (i in F) or y_i < 0 (i in G); every infeasible variable changes
 * side at once while their number keeps falling, a budget of
 * NNLS_FULL_EXCHANGE_BUDGET exchanges may fail to reduce it, and after that
 * only the infeasible variable of largest index changes side (Murty's rule,
 * Judice and Pires), which terminates for a positive definite A^T A.
 *
 * A^T A is only semi-definite when n > m or columns are dependent, and
 * then the pivoting can stall (seen: thousands of single pivots without
 * progress).  So the backup rule gets NNLS_BACKUP_STEPS steps, and after
 * that, or at once when a passive set had to be regularised, Lawson and
 * Hanson's active-set method takes over from the best iterate (in the
 * coordinate form an interior point first gives block pivoting a new
 * start; see interior_point); see tk_nnls_solve.  The header calls these
 * "the fallback".
 *
 * Tolerances are scale-free: with s_i = ||a_i||, x_i is infeasible when
 * s_i x_i < -tol ||b|| and y_i when y_i / s_i < -tol ||b||; both sides are
 * in units of b, so scaling a column or b changes nothing.  Zero columns
 * never enter F (any x_i is optimal for them; 0 is returned).
 *
 * The unconstrained subproblems use the normal equations of the columns
 * scaled to unit norm (variables z_i = s_i x_i), so that the normal matrix
 * M = D^-1 A_F^T A_F D^-1 has a unit diagonal: the condition estimate and
 * the regularisation below then do not depend on how the columns are
 * scaled.  With T = (A_F D^-1)^T (n_F x m, built here from A), CHOLMOD's
 * unsymmetric mode factors T T' + delta I = M + delta I directly, so M is
 * never stored.  The symbolic analysis depends only on T's pattern, which
 * is kept (a copy of it) with the factor in a small least-recently-used
 * cache: a repeat solve with the same pattern of A (the passive-set
 * sequence from x = 0 repeats from one flow step to the next) re-uses the
 * analyses.  Each solve is followed by a step of iterative refinement
 * whose residual is formed from T, not from the factor (corrected
 * semi-normal equations), which wins back most of the accuracy lost to the
 * squared condition number.
 *
 * Condition: the estimate is the ratio of the smallest to the largest pivot
 * of the factorisation, (min L_jj / max L_jj)^2 for LL' (supernodal) and
 * min d_j / max d_j for LDL' (simplicial): both estimate rcond(M) itself,
 * not rcond(L), and equal what cholmod_rcond returns in SuiteSparse 5.x.
 * It is a rough estimate (an upper bound in spirit, exact for diagonal M).
 * The scan is done here because a simplicial LDL' factorisation of a
 * singular or indefinite M "succeeds" with zero or negative pivots, which
 * CHOLMOD does not flag; such a factor reports 0.  When the estimate is
 * below rcond_floor (or CHOLMOD reports the matrix not positive definite),
 * the factorisation is repeated with delta = 1e-12, 1e-10, ..., 1e-2 added
 * to M's unit diagonal (in the unscaled variables: A_F^T A_F + delta D^2)
 * until the estimate clears the floor.  NNLS_TIKHONOV_STEPS steps of
 * iterated Tikhonov regularisation with that factor then take the bias
 * of delta out again (see normal_solve), so the residual is that of the
 * unregularised least-squares problem on F.  Once some passive set needed
 * a delta, every later one in the same solve starts from that delta
 * (which saves a failing factorisation each time, the columns being
 * dependent) and the backup rule hands over to Lawson and Hanson at once.
 * With many contacts the proximal problem is solved in the coordinate
 * form instead (see primal_pays).
 */
#include "tk/nnls.h"

#include <assert.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Enough slots for the handful of passive sets one solve visits. */
#define NNLS_SLOTS 8
#define NNLS_FULL_EXCHANGE_BUDGET 3
#define NNLS_DELTA_FIRST 1e-12
#define NNLS_DELTA_GROWTH 100.0
#define NNLS_DELTA_CAP 1e-2
#define NNLS_TIKHONOV_STEPS 3
#define NNLS_DEFAULT_TOLERANCE 1e-10
#define NNLS_DEFAULT_RCOND_FLOOR 1e-14
/* modifications of a factor before it is built afresh (see lh_sync) */
#define NNLS_LH_REFRESH 200

/* A copy of a matrix's pattern, what the caches below are kept for. */
typedef struct nnls_pattern {
    uint64_t hash;        /* pattern_hash */
    size_t nrow, ncol, nnz; /* nrow 0: none */
    int *p, *i;           /* ncol + 1 and nnz entries */
} nnls_pattern;

/* A cached symbolic analysis (and the last numeric factor) for one
 * pattern of T. */
typedef struct nnls_slot {
    cholmod_factor *L;    /* NULL when the slot is empty */
    nnls_pattern pattern; /* T's */
    double fl, lnz;       /* the analysis's flops and entries of L */
    unsigned long used;   /* least-recently-used stamp */
} nnls_slot;

/* The coordinate form's numeric factor as the last solve left it, for a
 * next solve of the same matrix (see primal_adopt). */
typedef struct nnls_kept {
    bool valid;           /* primal.L holds P_F P_F' + mu I, F = in */
    double mu;
    size_t n, nnz;
    double *values;       /* A's entries column by column (nnz) */
    bool *in;             /* n: the columns F */
    int updates;          /* modifications since it was built */
} nnls_kept;

/* The last order_columns's ordering, for the pattern of A^T it was made
 * from (see order_columns). */
typedef struct nnls_order {
    nnls_pattern pattern;
    int *order;           /* pattern.nrow: AMD's ordering of its rows */
} nnls_order;

struct tk_nnls {
    cholmod_common cc;
    nnls_slot slot[NNLS_SLOTS];
    nnls_order columns;   /* the columns' order of the last solve */
    nnls_slot primal;     /* the coordinate form's analysis (of all of P) */
    nnls_kept kept;       /* and its last factor */
    int *order;           /* the rows' ordering of the last AMD analysis */
    size_t order_m;       /* its length (0: none) */
    double order_lnz;     /* the entries of L it gave */
    unsigned long clock;
    cholmod_dense *X, *Y, *E;  /* cholmod_solve2's result and workspace */
    tk_nnls_work work;    /* done so far (tk_nnls_work_done) */
};

/* The outcome of one (possibly regularised) factorisation. */
typedef struct nnls_factor {
    cholmod_factor *L;
    double delta;         /* added to the (unit) diagonal, 0 if none */
    double rcond;         /* estimate for the first matrix factorised,
                             M + delta_min I; 0 if singular */
    int factorisations;   /* cholmod_factorize_p calls made */
    bool singular;        /* too ill-conditioned, and not regularised */
} nnls_factor;

/* ------------------------------------------------------------------ */
/* Small helpers. */

static void col_span(const cholmod_sparse *A, size_t j, size_t *lo, size_t *hi)
{
    const int *Ap = A->p;
    *lo = (size_t)Ap[j];
    *hi = A->packed ? (size_t)Ap[j + 1] : (size_t)Ap[j] + (size_t)((const int *)A->nz)[j];
}

static double col_dot(const cholmod_sparse *A, size_t j, const double *v)
{
    const int *Ai = A->i;
    const double *Ax = A->x;
    size_t lo, hi;
    col_span(A, j, &lo, &hi);
    double sum = 0.0;
    for (size_t e = lo; e < hi; e++)
        sum += Ax[e] * v[Ai[e]];
    return sum;
}

static double norm2(const double *v, size_t n)
{
    /* scaled, so that huge or tiny inputs neither overflow nor underflow */
    double scale = 0.0, ssq = 1.0;
    for (size_t k = 0; k < n; k++) {
        double a = fabs(v[k]);
        if (a == 0.0)
            continue;
        if (a > scale) {
            ssq = 1.0 + ssq * (scale / a) * (scale / a);
            scale = a;
        } else {
            ssq += (a / scale) * (a / scale);
        }
    }
    return scale * sqrt(ssq);
}

static int cholmod_failure(tk_nnls *s, const char *what, tk_error *err)
{
    int status = s->cc.status;
    if (status == CHOLMOD_OUT_OF_MEMORY)
        return tk_error_set(err, TK_ENOMEM, "out of memory in CHOLMOD (%s)", what);
    if (status == CHOLMOD_TOO_LARGE)
        return tk_error_set(err, TK_ELIMIT, "problem too large for CHOLMOD (%s)", what);
    return tk_error_set(err, TK_ENUMERIC, "CHOLMOD failed in %s (status %d)", what, status);
}

/* Checks what the solver relies on: a real, double, int-indexed,
 * unsymmetric matrix with row indices in range and finite values. */
static int check_matrix(const cholmod_sparse *A, tk_error *err)
{
    if (!A)
        return tk_error_set(err, TK_EINVAL, "nnls: no matrix");
    if (A->stype != 0 || A->xtype != CHOLMOD_REAL || A->dtype != CHOLMOD_DOUBLE ||
        A->itype != CHOLMOD_INT)
        return tk_error_set(err, TK_EINVAL,
                            "nnls: the matrix must be real, double, int-indexed and unsymmetric");
    if (A->nrow > INT_MAX || A->ncol > INT_MAX)
        return tk_error_set(err, TK_ELIMIT, "nnls: matrix %zu x %zu is too large", A->nrow,
                            A->ncol);
    if (A->ncol > 0 && (!A->p || (!A->packed && !A->nz)))
        return tk_error_set(err, TK_EINVAL, "nnls: the matrix has no column pointers");
    const int *Ai = A->i;
    const double *Ax = A->x;
    for (size_t j = 0; j < A->ncol; j++) {
        size_t lo, hi;
        col_span(A, j, &lo, &hi);
        if (hi < lo || (hi > lo && (!Ai || !Ax)))
            return tk_error_set(err, TK_EINVAL, "nnls: column %zu is malformed", j);
        for (size_t e = lo; e < hi; e++) {
            if (Ai[e] < 0 || (size_t)Ai[e] >= A->nrow)
                return tk_error_set(err, TK_EINVAL, "nnls: row index %d out of range in column %zu",
                                    Ai[e], j);
            if (!isfinite(Ax[e]))
                return tk_error_set(err, TK_EINVAL, "nnls: non-finite entry in column %zu", j);
        }
    }
    return TK_OK;
}

static int check_vector(const double *v, size_t n, const char *name, tk_error *err)
{
    if (n > 0 && !v)
        return tk_error_set(err, TK_EINVAL, "nnls: no %s vector", name);
    for (size_t k = 0; k < n; k++)
        if (!isfinite(v[k]))
            return tk_error_set(err, TK_EINVAL, "nnls: %s[%zu] is not finite", name, k);
    return TK_OK;
}

/* T = A(:, F)^T, written into T's storage (allocated with m columns and
 * nzmax >= nnz(A)); next is workspace of m ints.  Row indices come out
 * sorted because F is walked in order. */
static void build_transpose(const cholmod_sparse *A, const int *F, size_t nf,
                            const double *inv_norm, cholmod_sparse *T, int *next)
{
    size_t m = A->nrow;
    int *Tp = T->p, *Ti = T->i;
    double *Tx = T->x;
    const int *Ai = A->i;
    const double *Ax = A->x;
    memset(Tp, 0, (m + 1) * sizeof *Tp);
    for (size_t q = 0; q < nf; q++) {
        size_t lo, hi;
        col_span(A, (size_t)F[q], &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            Tp[Ai[e] + 1]++;
    }
    for (size_t k = 0; k < m; k++)
        Tp[k + 1] += Tp[k];
    memcpy(next, Tp, m * sizeof *next);
    for (size_t q = 0; q < nf; q++) {
        size_t lo, hi;
        col_span(A, (size_t)F[q], &lo, &hi);
        for (size_t e = lo; e < hi; e++) {
            int dst = next[Ai[e]]++;
            Ti[dst] = (int)q;
            Tx[dst] = Ax[e] * inv_norm[F[q]];
        }
    }
    T->nrow = nf;
    T->sorted = 1;
    T->packed = 1;
}

/* w = T' z (m entries). */
static void t_transpose_times(const cholmod_sparse *T, const double *z, double *w)
{
    const int *Tp = T->p, *Ti = T->i;
    const double *Tx = T->x;
    for (size_t k = 0; k < T->ncol; k++) {
        double sum = 0.0;
        for (int e = Tp[k]; e < Tp[k + 1]; e++)
            sum += Tx[e] * z[Ti[e]];
        w[k] = sum;
    }
}

/* out = T w (nrow entries). */
static void t_times(const cholmod_sparse *T, const double *w, double *out)
{
    const int *Tp = T->p, *Ti = T->i;
    const double *Tx = T->x;
    memset(out, 0, T->nrow * sizeof *out);
    for (size_t k = 0; k < T->ncol; k++) {
        double wk = w[k];
        if (wk == 0.0)
            continue;
        for (int e = Tp[k]; e < Tp[k + 1]; e++)
            out[Ti[e]] += Tx[e] * wk;
    }
}

/* ------------------------------------------------------------------ */
/* The factor cache. */

static uint64_t pattern_hash(const cholmod_sparse *T)
{
    /* FNV-1a over the dimensions and the pattern */
    uint64_t h = 1469598103934665603ULL;
    const int *Tp = T->p, *Ti = T->i;
    size_t nnz = (size_t)Tp[T->ncol];
    uint64_t dims[2] = {T->nrow, T->ncol};
    for (int k = 0; k < 2; k++) {
        h ^= dims[k];
        h *= 1099511628211ULL;
    }
    for (size_t k = 0; k <= T->ncol; k++) {
        h ^= (uint32_t)Tp[k];
        h *= 1099511628211ULL;
    }
    for (size_t k = 0; k < nnz; k++) {
        h ^= (uint32_t)Ti[k];
        h *= 1099511628211ULL;
    }
    return h;
}

static void pattern_clear(nnls_pattern *pat)
{
    free(pat->p);
    free(pat->i);
    memset(pat, 0, sizeof *pat);
}

/* Whether pat is T's pattern (hash h). */
static bool pattern_is(const nnls_pattern *pat, const cholmod_sparse *T, uint64_t h)
{
    const int *Tp = T->p, *Ti = T->i;
    size_t nnz = (size_t)Tp[T->ncol];
    return pat->nrow > 0 && pat->hash == h && pat->nrow == T->nrow && pat->ncol == T->ncol &&
           pat->nnz == nnz && memcmp(pat->p, Tp, (T->ncol + 1) * sizeof *Tp) == 0 &&
           memcmp(pat->i, Ti, nnz * sizeof *Ti) == 0;
}

/* pat becomes a copy of T's pattern (hash h); false, and pat empty, when
 * out of memory. */
static bool pattern_keep(nnls_pattern *pat, const cholmod_sparse *T, uint64_t h)
{
    const int *Tp = T->p, *Ti = T->i;
    size_t nnz = (size_t)Tp[T->ncol];
    pattern_clear(pat);
    pat->p = malloc((T->ncol + 1) * sizeof *pat->p);
    pat->i = malloc((nnz ? nnz : 1) * sizeof *pat->i);
    if (!pat->p || !pat->i) {
        pattern_clear(pat);
        return false;
    }
    memcpy(pat->p, Tp, (T->ncol + 1) * sizeof *Tp);
    memcpy(pat->i, Ti, nnz * sizeof *Ti);
    pat->hash = h;
    pat->nrow = T->nrow;
    pat->ncol = T->ncol;
    pat->nnz = nnz;
    return true;
}

static void slot_clear(tk_nnls *s, nnls_slot *slot)
{
    if (slot->L)
        cholmod_free_factor(&slot->L, &s->cc);
    pattern_clear(&slot->pattern);
    memset(slot, 0, sizeof *slot);
}

/* Whether slot holds the analysis of T's pattern (hash h). */
static bool slot_holds(const nnls_slot *slot, const cholmod_sparse *T, uint64_t h)
{
    return slot->L && pattern_is(&slot->pattern, T, h);
}

static nnls_slot *slot_find(tk_nnls *s, const cholmod_sparse *T, uint64_t h)
{
    for (int k = 0; k < NNLS_SLOTS; k++)
        if (slot_holds(&s->slot[k], T, h))
            return &s->slot[k];
    return NULL;
}

/* Analyses T into `slot`, with the fill-reducing ordering `order` of T's
 * rows (NULL: AMD's own for this T). */
static int slot_analyse(tk_nnls *s, nnls_slot *slot, const cholmod_sparse *T, const int *order,
                        uint64_t h, tk_error *err)
{
    slot_clear(s, slot);
    if (!pattern_keep(&slot->pattern, T, h))
        return tk_error_set(err, TK_ENOMEM, "out of memory for the factor cache");
    /* cholmod_analyze takes a non-const matrix but does not change it */
    if (order) {
        s->cc.method[0].ordering = CHOLMOD_GIVEN;
        slot->L = cholmod_analyze_p((cholmod_sparse *)T, (int *)order, NULL, 0, &s->cc);
        s->cc.method[0].ordering = CHOLMOD_AMD;
    } else {
        slot->L = cholmod_analyze((cholmod_sparse *)T, &s->cc);
    }
    if (!slot->L || s->cc.status < CHOLMOD_OK) {
        int rc = cholmod_failure(s, "analyze", err);
        slot_clear(s, slot);
        return rc;
    }
    slot->fl = s->cc.fl;
    slot->lnz = s->cc.lnz;
    return TK_OK;
}

/* slot_analyse into the least recently used of the slots. */
static int slot_fill(tk_nnls *s, const cholmod_sparse *T, const int *order, uint64_t h,
                     nnls_slot **out, tk_error *err)
{
    nnls_slot *slot = &s->slot[0];
    for (int k = 1; k < NNLS_SLOTS && slot->L; k++)
        if (!s->slot[k].L || s->slot[k].used < slot->used)
            slot = &s->slot[k];
    *out = slot;
    return slot_analyse(s, slot, T, order, h, err);
}

/* The pivot-ratio estimate of rcond(M) described at the top; 0 when a
 * pivot is zero, negative or not finite. */
static double factor_rcond(const cholmod_factor *L)
{
    const double *Lx = L->x;
    double lo = INFINITY, hi = 0.0;
    if (L->n == 0)
        return 1.0;
    if (L->is_super) {
        const int *super = L->super, *pi = L->pi, *px = L->px;
        for (size_t sn = 0; sn < L->nsuper; sn++) {
            int k1 = super[sn], k2 = super[sn + 1];
            size_t nsrow = (size_t)(pi[sn + 1] - pi[sn]);
            for (int j = k1; j < k2; j++) {
                size_t jj = (size_t)(j - k1);
                double d = Lx[(size_t)px[sn] + jj + jj * nsrow];
                if (!(d > 0.0) || !isfinite(d))
                    return 0.0;
                lo = fmin(lo, d);
                hi = fmax(hi, d);
            }
        }
    } else {
        const int *Lp = L->p;
        for (size_t j = 0; j < L->n; j++) {
            double d = Lx[Lp[j]];
            if (!(d > 0.0) || !isfinite(d))
                return 0.0;
            lo = fmin(lo, d);
            hi = fmax(hi, d);
        }
    }
    double r = lo / hi;
    return L->is_ll ? r * r : r;
}

/* The floating-point operations of a numeric factorisation, about: the
 * squares of the factor's column counts (a supernode's columns each with
 * its rows) summed. */
static double factor_flops(const cholmod_factor *L)
{
    double fl = 0.0;
    if (L->is_super) {
        const int *super = L->super, *pi = L->pi;
        for (size_t sn = 0; sn < L->nsuper; sn++) {
            double rows = (double)(pi[sn + 1] - pi[sn]);
            fl += (double)(super[sn + 1] - super[sn]) * rows * rows;
        }
    } else if (L->nz) {
        const int *nz = L->nz;
        for (size_t j = 0; j < L->n; j++)
            fl += (double)nz[j] * (double)nz[j];
    }
    return fl;
}

/* One numeric factorisation of T T' + delta I (of T's columns fset only,
 * when given); *rcond gets the estimate (0 when CHOLMOD found the matrix
 * not positive definite). */
static int factor_once(tk_nnls *s, const cholmod_sparse *T, const int *fset, size_t fsize,
                       cholmod_factor *L, double delta, double *rcond, tk_error *err)
{
    double b[2] = {delta, 0.0};
    cholmod_factorize_p((cholmod_sparse *)T, b, (int *)fset, fsize, L, &s->cc);
    if (s->cc.status < CHOLMOD_OK)
        return cholmod_failure(s, "factorize", err);
    s->work.factor_flops += factor_flops(L);
    *rcond = s->cc.status == CHOLMOD_NOT_POSDEF ? 0.0 : factor_rcond(L);
    return TK_OK;
}

/* Factors T T' (= the scaled A_F^T A_F, unit diagonal) in the row order
 * `order` (NULL: AMD's), or with fset the same of T's columns fset only
 * (the analysis, cached, is of all of T, whose pattern holds every
 * subset's), with
 * delta I added when needed: first with delta_min (0: none), then, when
 * may_regularise, with delta growing by NNLS_DELTA_GROWTH from
 * NNLS_DELTA_FIRST up to NNLS_DELTA_CAP until the estimate clears the
 * floor.  Without may_regularise a singular matrix sets f->singular and
 * is not an error. */
static int factor_normal(tk_nnls *s, const cholmod_sparse *T, const int *order,
                         const int *fset, size_t fsize, double delta_min, bool may_regularise,
                         double rcond_floor, nnls_factor *f, tk_error *err)
{
    uint64_t h = pattern_hash(T);
    nnls_slot *slot = slot_find(s, T, h);
    int rc = TK_OK;
    if (!slot && (rc = slot_fill(s, T, order, h, &slot, err)) != TK_OK)
        return rc;
    slot->used = ++s->clock;
    f->L = slot->L;
    f->singular = false;
    double delta = delta_min;
    for (;;) {
        double est = 0.0;
        if ((rc = factor_once(s, T, fset, fsize, slot->L, delta, &est, err)) != TK_OK)
            return rc;
        f->factorisations++;
        if (delta == delta_min)
            f->rcond = est;
        if (est > 0.0 && est >= rcond_floor) {
            f->delta = delta;
            return TK_OK;
        }
        if (!may_regularise) {
            f->singular = true;
            return TK_OK;
        }
        delta = delta == 0.0 ? NNLS_DELTA_FIRST : delta * NNLS_DELTA_GROWTH;
        if (delta > NNLS_DELTA_CAP * 1.000001)
            break;
    }
    return tk_error_set(err, TK_ENUMERIC,
                        "nnls: the normal equations (%zu columns) stay singular with a "
                        "regularisation of %g times their diagonal",
                        T->nrow, NNLS_DELTA_CAP);
}

/* Solves with the factor for rhs (n entries); *out points into s->X. */
static int factor_solve(tk_nnls *s, cholmod_factor *L, double *rhs, size_t n,
                        const double **out, tk_error *err)
{
    cholmod_dense B;
    memset(&B, 0, sizeof B);
    B.nrow = n;
    B.ncol = 1;
    B.nzmax = n;
    B.d = n;
    B.x = rhs;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, L, &B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cc) ||
        s->cc.status < CHOLMOD_OK)
        return cholmod_failure(s, "solve", err);
    *out = s->X->x;
    return TK_OK;
}

/* z = (T T' + delta I)^{-1} c, solved with the factor (of T T' +
 * f->delta I) and `refine` steps of refinement whose residual
 * c - T (T' z) - delta z comes from T itself.  With delta = 0 < f->delta
 * the steps are iterated Tikhonov regularisation, which converge to the
 * minimum-norm solution of T T' z = c when c is in the range of T (each
 * step shrinks the error along an eigenvalue lambda by
 * f->delta / (lambda + f->delta)), and so take the bias of the
 * regularisation out of T' z.  w (m entries) and res (nrow entries) are
 * workspace. */
static int normal_solve(tk_nnls *s, const cholmod_sparse *T, const nnls_factor *f,
                        const double *c, double *z, double *w, double *res, int refine,
                        double delta, tk_error *err)
{
    size_t nf = T->nrow;
    const double *sol;
    memcpy(res, c, nf * sizeof *res);
    int rc = factor_solve(s, f->L, res, nf, &sol, err);
    if (rc != TK_OK)
        return rc;
    memcpy(z, sol, nf * sizeof *z);
    for (int step = 0; step < refine; step++) {
        t_transpose_times(T, z, w);
        t_times(T, w, res);
        for (size_t q = 0; q < nf; q++)
            res[q] = c[q] - res[q] - delta * z[q];
        if ((rc = factor_solve(s, f->L, res, nf, &sol, err)) != TK_OK)
            return rc;
        for (size_t q = 0; q < nf; q++)
            z[q] += sol[q];
    }
    return TK_OK;
}

/* ------------------------------------------------------------------ */
/* The public interface. */

int tk_nnls_new(tk_nnls **out, tk_error *err)
{
    if (!out)
        return tk_error_set(err, TK_EINVAL, "nnls: no output pointer");
    *out = NULL;
    tk_nnls *s = calloc(1, sizeof *s);
    if (!s)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    if (!cholmod_start(&s->cc)) {
        free(s);
        return tk_error_set(err, TK_ENOMEM, "CHOLMOD could not start");
    }
    /* the library never prints; failures come back through status */
    s->cc.print = 0;
    s->cc.error_handler = NULL;
    /* The flow's normal matrices are small and very sparse: the simplicial
     * factorisation is as fast, and it keeps CHOLMOD's BLAS and OpenMP
     * threads out of runs that already have a thread each.  One ordering
     * (AMD) instead of trying several. */
    s->cc.supernodal = CHOLMOD_SIMPLICIAL;
    s->cc.nmethods = 1;
    s->cc.method[0].ordering = CHOLMOD_AMD;
    s->cc.postorder = 0;
    *out = s;
    return TK_OK;
}

void tk_nnls_free(tk_nnls **p)
{
    if (!p || !*p)
        return;
    tk_nnls *s = *p;
    for (int k = 0; k < NNLS_SLOTS; k++)
        slot_clear(s, &s->slot[k]);
    slot_clear(s, &s->primal);
    free(s->kept.values);
    free(s->kept.in);
    free(s->order);
    pattern_clear(&s->columns.pattern);
    free(s->columns.order);
    cholmod_free_dense(&s->X, &s->cc);
    cholmod_free_dense(&s->Y, &s->cc);
    cholmod_free_dense(&s->E, &s->cc);
    cholmod_finish(&s->cc);
    free(s);
    *p = NULL;
}

cholmod_common *tk_nnls_common(tk_nnls *s)
{
    return s ? &s->cc : NULL;
}

tk_nnls_work tk_nnls_work_done(const tk_nnls *s)
{
    return s->work;
}

static size_t matrix_nnz(const cholmod_sparse *A)
{
    size_t nnz = 0;
    for (size_t j = 0; j < A->ncol; j++) {
        size_t lo, hi;
        col_span(A, j, &lo, &hi);
        nnz += hi - lo;
    }
    return nnz;
}

/* The state of one tk_nnls_solve call. */
typedef struct nnls_work {
    tk_nnls *s;
    const cholmod_sparse *A;
    const double *b;
    size_t m, n;
    double tolb;          /* tolerance times ||b|| */
    double rcond_floor;
    int max_iter;
    double mu;            /* the proximal weight (0: the plain problem) */
    bool refined;         /* passive solves in the coordinate form take
                             their step of refinement (opts->unrefined) */
    double *centre;       /* n: the proximal centre c (when mu > 0) */
    double *colnorm;      /* s_i = ||a_i|| */
    double *inv_norm;     /* 1 / s_i, 0 for zero columns */
    double *y;            /* A^T (A x - b) */
    double *r;            /* A x - b (m) */
    double *c, *zq, *res; /* per passive variable: rhs, solution, workspace */
    double *trial;        /* n: Lawson-Hanson's unconstrained solution */
    double *best;         /* n: the iterate with fewest violations */
    int *F;               /* passive indices, increasing */
    int *order;           /* n: all columns in one fill-reducing order */
    bool ordered;         /* order is made (order_columns) */
    int *place;           /* n: column i's row in T (when passive) */
    int *suborder;        /* n: the passive set in that order, as T's rows */
    int *next;            /* m: workspace of build_transpose */
    bool *passive;
    bool *blocked;        /* Lawson-Hanson: columns not to add again yet */
    cholmod_sparse *T;    /* A_F^T, scaled */
    double delta_mode;    /* regularisation every later solve gets */
    size_t best_count;    /* block pivoting's fewest violations (of best) */
    tk_nnls_report rep;
    /* Lawson and Hanson's factor (see lh_sync), once they take over */
    cholmod_factor *lhL;  /* n x n; position p is column order[p] */
    cholmod_sparse *Tall; /* A^T, scaled, all columns */
    cholmod_sparse *R;    /* n x 1: a column of the normal matrix */
    int *pos;             /* n: column i's position */
    bool *in_factor;      /* n: columns whose rows the factor holds */
    double *acc;          /* n: a column of the normal matrix, scattered */
    int *touched;         /* n: acc's nonzero entries */
    double *zpos;         /* n: the passive solution, by position */
    double *rhs;          /* n: T b + mu z_c, by position */
    int lh_updates;       /* rows added or deleted since the factor was built */
    /* the coordinate form (see primal_pays), once used */
    cholmod_sparse *P;    /* m x n: A with its columns scaled */
    double *ym, *ry;      /* m: y, and workspace */
    double *ptb;          /* n: P' b */
    bool lh_primal;       /* Lawson and Hanson use pL, not lhL */
    cholmod_factor *pL;   /* the factor of P_F P_F' + mu I (s->primal's) */
    bool pl_current;      /* pL holds that matrix for F = in_factor */
} nnls_work;

static void work_free(nnls_work *w)
{
    if (w->T)
        cholmod_free_sparse(&w->T, &w->s->cc);
    free(w->colnorm);
    free(w->inv_norm);
    free(w->y);
    free(w->r);
    free(w->c);
    free(w->zq);
    free(w->res);
    free(w->trial);
    free(w->best);
    free(w->F);
    free(w->order);
    free(w->place);
    free(w->suborder);
    free(w->next);
    free(w->passive);
    free(w->blocked);
    free(w->centre);
    if (w->lhL)
        cholmod_free_factor(&w->lhL, &w->s->cc);
    if (w->Tall)
        cholmod_free_sparse(&w->Tall, &w->s->cc);
    if (w->R)
        cholmod_free_sparse(&w->R, &w->s->cc);
    free(w->pos);
    free(w->in_factor);
    free(w->acc);
    free(w->touched);
    free(w->zpos);
    free(w->rhs);
    if (w->P)
        cholmod_free_sparse(&w->P, &w->s->cc);
    free(w->ym);
    free(w->ry);
    free(w->ptb);
}

/* One fill-reducing order (AMD on A^T A) of all the columns.  A solve
 * visits several passive sets, each a different normal matrix; ordering
 * each afresh was a third of the flow's time.  The order of the whole
 * matrix restricted to a passive set serves as that set's order. */
/* T = A^T with every column scaled (place is left listing them all). */
static void transpose_all(nnls_work *w, cholmod_sparse *T)
{
    for (size_t i = 0; i < w->n; i++)
        w->place[i] = (int)i;
    build_transpose(w->A, w->place, w->n, w->inv_norm, T, w->next);
}

/* Keeps `order` as the ordering of T's pattern (hash h); out of memory,
 * nothing is kept and the next solve orders afresh. */
static void order_keep(nnls_order *o, const cholmod_sparse *T, uint64_t h, const int *order)
{
    int *kept = realloc(o->order, T->nrow * sizeof *kept);
    if (kept)
        o->order = kept;
    if (!kept || !pattern_keep(&o->pattern, T, h)) {
        pattern_clear(&o->pattern);
        return;
    }
    memcpy(o->order, order, T->nrow * sizeof *order);
}

/* Made when the n_F x n_F form is first needed: where the coordinate
 * form serves the whole solve, ordering A^T A was a tenth of its time.
 * AMD's ordering depends on the pattern alone, and a flow step solves
 * with the same matrix in each of its proximal rounds (motion.c), as do
 * steps between which the struts stay: the ordering of the last pattern
 * is kept and given again for the same pattern, the same ordering AMD
 * would make.  Catalogue 10.106's first 20 s (resolution 5) spent 19%
 * of their time in AMD. */
static int order_columns(nnls_work *w, tk_error *err)
{
    if (w->ordered)
        return TK_OK;
    transpose_all(w, w->T);
    nnls_order *o = &w->s->columns;
    uint64_t h = pattern_hash(w->T);
    if (pattern_is(&o->pattern, w->T, h)) {
        memcpy(w->order, o->order, w->n * sizeof *w->order);
    } else {
        if (!cholmod_amd(w->T, NULL, 0, w->order, &w->s->cc) || w->s->cc.status < CHOLMOD_OK)
            return cholmod_failure(w->s, "amd", err);
        order_keep(o, w->T, h, w->order);
    }
    w->ordered = true;
    return TK_OK;
}

static int work_alloc(nnls_work *w, tk_error *err)
{
    size_t n = w->n, m = w->m ? w->m : 1;
    w->colnorm = malloc(n * sizeof *w->colnorm);
    w->inv_norm = malloc(n * sizeof *w->inv_norm);
    w->y = malloc(n * sizeof *w->y);
    w->r = malloc(m * sizeof *w->r);
    w->c = malloc(n * sizeof *w->c);
    w->zq = malloc(n * sizeof *w->zq);
    w->res = malloc(n * sizeof *w->res);
    w->trial = malloc(n * sizeof *w->trial);
    w->best = calloc(n, sizeof *w->best);
    w->F = malloc(n * sizeof *w->F);
    w->order = malloc(n * sizeof *w->order);
    w->place = malloc(n * sizeof *w->place);
    w->suborder = malloc(n * sizeof *w->suborder);
    w->next = malloc(m * sizeof *w->next);
    w->passive = calloc(n, sizeof *w->passive);
    w->blocked = calloc(n, sizeof *w->blocked);
    if (!w->colnorm || !w->inv_norm || !w->y || !w->r || !w->c || !w->zq || !w->res ||
        !w->trial || !w->best || !w->F || !w->order || !w->place || !w->suborder ||
        !w->next || !w->passive || !w->blocked)
        return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu columns)", w->n);
    w->T = cholmod_allocate_sparse(w->n, w->m, matrix_nnz(w->A), 1, 1, 0, CHOLMOD_REAL,
                                   &w->s->cc);
    if (!w->T)
        return cholmod_failure(w->s, "allocate", err);
    const double *Ax = w->A->x;
    for (size_t i = 0; i < n; i++) {
        size_t lo, hi;
        col_span(w->A, i, &lo, &hi);
        w->colnorm[i] = hi > lo ? norm2(Ax + lo, hi - lo) : 0.0;
        w->inv_norm[i] = w->colnorm[i] > 0.0 ? 1.0 / w->colnorm[i] : 0.0;
    }
    return TK_OK;
}

/* The coordinate form.  Where the passive columns are more than half as
 * many as the coordinates, the m x m matrix P_F P_F' (P = A D^-1, the
 * columns scaled) is smaller and much sparser to factor than the
 * n_F x n_F normal matrix: on the first NNLS of a tight 1,200-vertex
 * trefoil (3,600 coordinates, 6,003 struts) L has 184 thousand entries
 * against 1.6 million and a factorisation takes 0.02 s against 0.3 s; at
 * 2,000 passive columns the two cost the same.  The proximal normal
 * equations (P_F' P_F + mu I) z = P_F' b + mu z_c have the answer
 * z = z_c + P_F' y with (P_F P_F' + mu I) y = b - P_F z_c (multiply out),
 * with no division by mu.  But y holds the least-squares residual over
 * mu, and its rounding reaches z as about eps / mu: on that problem the
 * normal equations' relative residual was 2e-11 at mu = 1e-6, 2e-9 at
 * 1e-8 and 1e-5 at 1e-12, where the n_F x n_F form keeps 1e-14 to 1e-12.
 * A step of refinement in z's own space (primal_answer) brings it to
 * 5e-15 at 1e-6 and 4e-14 at 1e-8, but only to 2e-11 at 1e-10 (the other
 * form: 4e-13).  So the form serves the proximal problem with mu of at
 * least NNLS_PRIMAL_LEAST only; the flow's rounds (engine/motion.c) go
 * from 1e-2 down to 1e-12 and seldom need the last ones. */
#define NNLS_PRIMAL_LEAST 1e-8
/* The crossover is not a fixed share of the coordinates either: the n_F x n_F
 * factor fills faster than the m x m one as both grow.  On a
 * 4,800-vertex trefoil near tight (14,400 coordinates; bench/steps
 * --curve FILE --level 3, 30 steps) 6,300 passive columns, under half
 * the coordinates, gave an L of 885 thousand entries and 2.45e8 flops a
 * factorisation, and steps of 1.7 s (mean; median 1.4 s, 13
 * factorisations a step); in the coordinate form from 2,000 passive
 * columns on, 0.21 s (median 0.12 s, 5 factorisations), the ropelengths
 * the same to the printed digits.  So the coordinate form also serves
 * any passive set of more than NNLS_PRIMAL_COLUMNS columns, the count at
 * which the two cost the same at 1,200 vertices.  Below 4,000
 * coordinates (1,333 vertices) that changes nothing. */
#define NNLS_PRIMAL_COLUMNS 2000

static bool primal_pays(const nnls_work *w, size_t nf)
{
    return w->mu >= NNLS_PRIMAL_LEAST && (2 * nf > w->m || nf > NNLS_PRIMAL_COLUMNS);
}

static int primal_alloc(nnls_work *w, tk_error *err)
{
    if (w->P)
        return TK_OK;
    w->P = cholmod_copy_sparse((cholmod_sparse *)w->A, &w->s->cc);
    w->ym = malloc(w->m * sizeof *w->ym);
    w->ry = malloc(w->m * sizeof *w->ry);
    w->ptb = malloc(w->n * sizeof *w->ptb);
    if (!w->P || !w->ym || !w->ry || !w->ptb)
        return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu coordinates)", w->m);
    double *Px = w->P->x;
    for (size_t i = 0; i < w->n; i++) {
        size_t lo, hi;
        col_span(w->P, i, &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            Px[e] *= w->inv_norm[i];
        w->ptb[i] = col_dot(w->P, i, w->b);
    }
    return TK_OK;
}

/* x on the passive set (out, n entries, 0 off it) from L, the factor of
 * P_F P_F' + mu I: z = z_c + P_F' y, then a step of refinement in z's own
 * space, whose residual h = P_F' b + mu z_c - (P_F' P_F + mu I) z comes
 * from P and whose correction (P_F' P_F + mu I)^-1 h is
 * (h - P_F' (P_F P_F' + mu I)^-1 P_F h) / mu: it loses about eps / mu of
 * itself, not of z, so one step suffices (figures above).  The step is a
 * second solve with the factor, and where the factor is kept solves are
 * much of a flow step's time (bench/FIGURES.md, "Passive solves without
 * refinement"): from mu >= opts->unrefined (when set) it is left out,
 * which the caller may ask where eps / mu is well below the KKT tolerance
 * (2e-11 of relative residual at 1e-6, above, against 1e-10). */
static int primal_answer(nnls_work *w, cholmod_factor *L, double *out, tk_error *err)
{
    size_t m = w->m, n = w->n;
    const int *Pi = w->P->i;
    const double *Px = w->P->x;
    double *v = w->ry, *y = w->ym, *h = w->res;
    memcpy(v, w->b, m * sizeof *v);
    for (size_t i = 0; i < n; i++) {
        double zc = w->colnorm[i] * w->centre[i];
        if (!w->passive[i] || zc == 0.0)
            continue;
        size_t lo, hi;
        col_span(w->P, i, &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            v[Pi[e]] -= Px[e] * zc;
    }
    const double *sol;
    int rc = factor_solve(w->s, L, v, m, &sol, err);
    if (rc != TK_OK)
        return rc;
    memcpy(y, sol, m * sizeof *y);
    memset(v, 0, m * sizeof *v);
    for (size_t i = 0; i < n; i++) {
        out[i] = w->passive[i] ? w->colnorm[i] * w->centre[i] + col_dot(w->P, i, y) : 0.0;
        if (!w->refined)
            continue;
        size_t lo, hi;
        col_span(w->P, i, &lo, &hi);
        for (size_t e = lo; e < hi && out[i] != 0.0; e++)
            v[Pi[e]] += Px[e] * out[i];
    }
    if (!w->refined) {
        for (size_t i = 0; i < n; i++)
            out[i] *= w->inv_norm[i];
        return TK_OK;
    }
    for (size_t i = 0; i < n; i++)
        h[i] = w->passive[i] ? w->ptb[i] - col_dot(w->P, i, v) +
                                   w->mu * (w->colnorm[i] * w->centre[i] - out[i])
                             : 0.0;
    memset(v, 0, m * sizeof *v);
    for (size_t i = 0; i < n; i++) {
        size_t lo, hi;
        col_span(w->P, i, &lo, &hi);
        for (size_t e = lo; e < hi && h[i] != 0.0; e++)
            v[Pi[e]] += Px[e] * h[i];
    }
    if ((rc = factor_solve(w->s, L, v, m, &sol, err)) != TK_OK)
        return rc;
    for (size_t i = 0; i < n; i++)
        out[i] = w->passive[i] ? (out[i] + (h[i] - col_dot(w->P, i, sol)) / w->mu) *
                                     w->inv_norm[i]
                               : 0.0;
    return TK_OK;
}

/* The coordinate form keeps one factor of P_F P_F' + mu I through a solve,
 * for block pivoting and Lawson and Hanson alike: a column joining the
 * passive set is a rank-one update, one leaving a downdate
 * (cholmod_updown, on a simplicial factor analysed for all the columns,
 * so no change needs a new pattern), with the same refreshes as lh_sync.
 * Between two passive sets of block pivoting on a flow step's warm start
 * few columns change, and a factorisation of the whole (2,435 vertices,
 * 11,722 struts: 386,058 entries in L) cost 20 ms.  The matrix is
 * positive definite whatever F is (mu > 0), so a column never counts as
 * dependent; a factor whose pivots say otherwise after modifications is
 * built afresh. */
static int primal_modify(nnls_work *w, bool update, tk_error *err)
{
    size_t k = 0;
    for (size_t i = 0; i < w->n; i++)
        if (w->passive[i] != w->in_factor[i] && w->passive[i] == update)
            w->F[k++] = (int)i;
    if (k == 0)
        return TK_OK;
    /* the columns joining or leaving, in the rows' fill-reducing order,
     * which is the factor's */
    cholmod_sparse *C =
        cholmod_submatrix(w->P, w->pL->Perm, (long)w->m, w->F, k, 1, 1, &w->s->cc);
    bool ok = C && cholmod_updown(update, C, w->pL, &w->s->cc) && w->s->cc.status >= CHOLMOD_OK;
    cholmod_free_sparse(&C, &w->s->cc);
    if (!ok)
        return cholmod_failure(w->s, "updown", err);
    for (size_t q = 0; q < k; q++)
        w->in_factor[w->F[q]] = update;
    w->lh_updates += (int)k;
    return TK_OK;
}

/* From one flow step to the next the struts change a little and the rows
 * (coordinates) not at all, and most of an analysis of P P' is AMD's
 * ordering: on the tight 2,435-vertex trefoil 14 ms, against 2.3 ms for
 * the rest with the last step's ordering given, whose factor then had
 * 0.4% more entries than AMD's own.  So the last AMD ordering serves while
 * the factor it gives has at most NNLS_ORDER_SLACK times the entries of
 * the one it was made for. */
#define NNLS_ORDER_SLACK 1.1

static int primal_analyse(tk_nnls *s, const cholmod_sparse *P, uint64_t h, tk_error *err)
{
    nnls_slot *slot = &s->primal;
    if (s->order_m == P->nrow) {
        int rc = slot_analyse(s, slot, P, s->order, h, err);
        if (rc != TK_OK || slot->lnz <= NNLS_ORDER_SLACK * s->order_lnz)
            return rc;
    }
    int rc = slot_analyse(s, slot, P, NULL, h, err);
    if (rc != TK_OK)
        return rc;
    if (s->order_m != P->nrow) {
        free(s->order);
        s->order_m = 0;
        if (!(s->order = malloc((P->nrow ? P->nrow : 1) * sizeof *s->order)))
            return tk_error_set(err, TK_ENOMEM, "out of memory for an ordering");
    }
    memcpy(s->order, slot->L->Perm, P->nrow * sizeof *s->order);
    s->order_m = P->nrow;
    s->order_lnz = slot->lnz;
    return TK_OK;
}

/* w->pL: the analysis of all of P, which holds every passive set's
 * pattern (P's pattern is often the last solve's, and then kept);
 * *held (may be NULL) says whether it was. */
static int primal_analysis(nnls_work *w, bool *held, tk_error *err)
{
    if (held)
        *held = w->pL != NULL;
    if (w->pL)
        return TK_OK;
    uint64_t h = pattern_hash(w->P);
    bool was = slot_holds(&w->s->primal, w->P, h);
    if (!was) {
        w->s->kept.valid = false;
        int rc = primal_analyse(w->s, w->P, h, err);
        if (rc != TK_OK)
            return rc;
    }
    if (held)
        *held = was;
    w->pL = w->s->primal.L;
    return TK_OK;
}

/* Whether A's entries are those the kept factor was made from. */
static bool kept_matches(const nnls_work *w)
{
    const nnls_kept *k = &w->s->kept;
    if (!k->valid || k->mu != w->mu || k->n != w->n)
        return false;
    const double *Ax = w->A->x;
    size_t at = 0;
    for (size_t j = 0; j < w->n; j++) {
        size_t lo, hi;
        col_span(w->A, j, &lo, &hi);
        if (at + (hi - lo) > k->nnz ||
            memcmp(k->values + at, Ax + lo, (hi - lo) * sizeof *Ax) != 0)
            return false;
        at += hi - lo;
    }
    return at == k->nnz;
}

/* The rounds of the flow's proximal point method (engine/motion.c) solve
 * the same matrix with the same weight from one centre to the next, and
 * their passive sets differ in a few columns: the factor the last solve
 * left, updated and downdated to the new set, saves a factorisation a
 * round (on the tight 2,435-vertex trefoil 20 ms against about 1 ms).
 * The analysis must be the one the factor was made with (the pattern's
 * slot never re-analysed since), and A's entries and mu the same. */
static void primal_adopt(nnls_work *w)
{
    nnls_kept *k = &w->s->kept;
    if (kept_matches(w)) {
        memcpy(w->in_factor, k->in, w->n * sizeof *w->in_factor);
        w->lh_updates = k->updates;
        w->pl_current = true;
    }
    /* whatever happens to the factor now is this solve's */
    k->valid = false;
}

/* At the end of a solve: keeps what the factor holds for the next. */
static int primal_keep(nnls_work *w, tk_error *err)
{
    nnls_kept *k = &w->s->kept;
    if (!w->pl_current)
        return TK_OK;
    size_t nnz = matrix_nnz(w->A);
    if (k->nnz < nnz || k->n < w->n) {
        free(k->values);
        free(k->in);
        k->values = malloc((nnz ? nnz : 1) * sizeof *k->values);
        k->in = malloc(w->n * sizeof *k->in);
        k->nnz = k->n = 0;
        if (!k->values || !k->in)
            return tk_error_set(err, TK_ENOMEM, "out of memory for the kept factor");
    }
    const double *Ax = w->A->x;
    size_t at = 0;
    for (size_t j = 0; j < w->n; j++) {
        size_t lo, hi;
        col_span(w->A, j, &lo, &hi);
        memcpy(k->values + at, Ax + lo, (hi - lo) * sizeof *Ax);
        at += hi - lo;
    }
    memcpy(k->in, w->in_factor, w->n * sizeof *k->in);
    k->nnz = nnz;
    k->n = w->n;
    k->mu = w->mu;
    k->updates = w->lh_updates;
    k->valid = true;
    return TK_OK;
}

/* Whether factor L (NULL: none yet) is to be built afresh for the passive
 * set rather than modified: after NNLS_LH_REFRESH modifications, or when
 * more columns change than a rebuild costs. */
static bool factor_stale(const nnls_work *w, const cholmod_factor *L)
{
    size_t changes = 0, nf = 0;
    for (size_t i = 0; i < w->n; i++) {
        changes += w->in_factor[i] != w->passive[i];
        nf += w->passive[i];
    }
    return !L || w->lh_updates + (int)changes > NNLS_LH_REFRESH || changes > nf / 2 + 8;
}

static int primal_sync(nnls_work *w, bool *singular, tk_error *err)
{
    size_t n = w->n;
    int rc;
    if (!w->pL) {
        bool held;
        if ((rc = primal_analysis(w, &held, err)) != TK_OK)
            return rc;
        if (held)
            primal_adopt(w);
    }
    bool afresh = !w->pl_current || factor_stale(w, w->pL);
    double rcond = 0.0;
    w->pl_current = false;
    if (!afresh) {
        /* updates first: the matrix only grows until the downdates */
        if ((rc = primal_modify(w, true, err)) != TK_OK ||
            (rc = primal_modify(w, false, err)) != TK_OK)
            return rc;
        rcond = factor_rcond(w->pL);
        afresh = rcond < w->rcond_floor;
    }
    if (afresh) {
        w->s->kept.valid = false;
        size_t nf = 0;
        for (size_t i = 0; i < n; i++)
            if ((w->in_factor[i] = w->passive[i]))
                w->F[nf++] = (int)i;
        if ((rc = factor_once(w->s, w->P, w->F, nf, w->pL, w->mu, &rcond, err)) != TK_OK)
            return rc;
        w->rep.factorisations++;
        w->lh_updates = 0;
    }
    w->rep.rcond = fmin(w->rep.rcond, rcond);
    *singular = rcond < w->rcond_floor;
    if (*singular)
        w->lh_updates = NNLS_LH_REFRESH + 1;
    else
        w->pl_current = true;
    return TK_OK;
}

/* passive_solve in the coordinate form; *done false when its factor was
 * too ill-conditioned (the other form then takes over). */
static int primal_solve(nnls_work *w, double *out, bool *done, tk_error *err)
{
    *done = false;
    int rc = primal_alloc(w, err);
    if (rc != TK_OK)
        return rc;
    if (!w->in_factor && !(w->in_factor = calloc(w->n, sizeof *w->in_factor)))
        return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu columns)", w->n);
    bool singular;
    if ((rc = primal_sync(w, &singular, err)) != TK_OK || singular)
        return rc;
    if ((rc = primal_answer(w, w->pL, out, err)) != TK_OK)
        return rc;
    *done = true;
    return TK_OK;
}

/* The unconstrained least-squares solution on the passive set into out
 * (n entries, 0 off the set).  may_regularise: see factor_normal; when a
 * singular set may not be regularised, *singular is set and out is left
 * alone. */
static int passive_solve(nnls_work *w, bool may_regularise, bool *singular, double *out,
                         tk_error *err)
{
    size_t nf = 0;
    for (size_t i = 0; i < w->n; i++)
        if (w->passive[i])
            w->F[nf++] = (int)i;
    *singular = false;
    if (nf == 0) {
        memset(out, 0, w->n * sizeof *out);
        return TK_OK;
    }
    if (primal_pays(w, nf)) {
        bool done;
        int rc = primal_solve(w, out, &done, err);
        if (rc != TK_OK || done)
            return rc;
        /* primal_sync used F for its lists */
        nf = 0;
        for (size_t i = 0; i < w->n; i++)
            if (w->passive[i])
                w->F[nf++] = (int)i;
    }
    int rc = order_columns(w, err);
    if (rc != TK_OK)
        return rc;
    /* in the scaled variables zq_q = s_i x_i the normal matrix has a unit
     * diagonal */
    build_transpose(w->A, w->F, nf, w->inv_norm, w->T, w->next);
    for (size_t q = 0; q < nf; q++)
        w->place[w->F[q]] = (int)q;
    size_t k = 0;
    for (size_t j = 0; j < w->n; j++)
        if (w->passive[w->order[j]])
            w->suborder[k++] = w->place[w->order[j]];
    nnls_factor f = {NULL, 0.0, 1.0, 0, false};
    double delta_min = w->mu > 0.0 ? w->mu : may_regularise ? w->delta_mode : 0.0;
    rc = factor_normal(w->s, w->T, w->suborder, NULL, 0, delta_min,
                       may_regularise || w->mu > 0.0, w->rcond_floor, &f, err);
    w->rep.factorisations += f.factorisations;
    w->rep.rcond = fmin(w->rep.rcond, f.rcond);
    if (rc != TK_OK)
        return rc;
    if (f.singular) {
        *singular = true;
        return TK_OK;
    }
    if (f.delta > w->mu) {
        w->delta_mode = f.delta;
        w->rep.regularised = true;
        w->rep.regularisation = fmax(w->rep.regularisation, f.delta);
    }
    t_times(w->T, w->b, w->c);
    /* The proximal problem's normal equations are
     * (T T' + mu I) z = T b + mu z_c, z_c the centre scaled. */
    for (size_t q = 0; q < nf && w->mu > 0.0; q++)
        w->c[q] += w->mu * w->colnorm[w->F[q]] * w->centre[w->F[q]];
    /* When regularised, c = T b is in the range of T, so iterated Tikhonov
     * steps recover the least-squares solution (of minimum norm, up to
     * rounding along the null space, which does not change A x): the
     * residual is then that of the unregularised problem, not one
     * inflated by delta. */
    rc = normal_solve(w->s, w->T, &f, w->c, w->zq, w->r, w->res,
                      f.delta > w->mu ? NNLS_TIKHONOV_STEPS : 1, w->mu, err);
    if (rc != TK_OK)
        return rc;
    memset(out, 0, w->n * sizeof *out);
    for (size_t q = 0; q < nf; q++)
        out[w->F[q]] = w->zq[q] * w->inv_norm[w->F[q]];
    return TK_OK;
}

/* Lawson and Hanson change the passive set a column or two at a time, and
 * refactorising for each (as passive_solve does) was 70% of a flow step
 * at 1,200 vertices and 2,750 struts.  Instead they keep one LDL' factor
 * of the whole n x n matrix that is the scaled normal matrix M + mu I on
 * the passive set and the identity elsewhere, in the positions of the
 * fill-reducing order of all the columns, and modify it: a column that
 * joins adds its row and column (cholmod_rowadd), one that leaves deletes
 * them (cholmod_rowdel), each costing about one row of the factor.
 * Modifications accumulate rounding, so the factor is built afresh after
 * NNLS_LH_REFRESH of them (or when more change at once than a rebuild
 * costs), every solve takes a step of refinement with M itself, and the
 * passive columns count as dependent when the pivots' ratio falls below
 * the floor, as for a factorisation. */

static int lh_alloc(nnls_work *w, tk_error *err)
{
    size_t n = w->n;
    if (!w->in_factor)
        w->in_factor = calloc(n, sizeof *w->in_factor);
    if (!w->in_factor)
        return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu columns)", n);
    if (w->lh_primal)
        return primal_alloc(w, err);
    /* in_factor now speaks of lhL */
    w->pl_current = false;
    int rc = order_columns(w, err);
    if (rc != TK_OK)
        return rc;
    w->pos = malloc(n * sizeof *w->pos);
    w->acc = calloc(n, sizeof *w->acc);
    w->touched = malloc(n * sizeof *w->touched);
    w->zpos = malloc(n * sizeof *w->zpos);
    w->rhs = malloc(n * sizeof *w->rhs);
    if (!w->pos || !w->acc || !w->touched || !w->zpos || !w->rhs)
        return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu columns)", n);
    for (size_t p = 0; p < n; p++)
        w->pos[w->order[p]] = (int)p;
    w->Tall = cholmod_allocate_sparse(n, w->m, matrix_nnz(w->A), 1, 1, 0, CHOLMOD_REAL,
                                      &w->s->cc);
    w->R = cholmod_allocate_sparse(n, 1, n, 0, 1, 0, CHOLMOD_REAL, &w->s->cc);
    if (!w->Tall || !w->R)
        return cholmod_failure(w->s, "allocate", err);
    transpose_all(w, w->Tall);
    /* the right-hand side T b + mu z_c, by position: fixed for the solve */
    for (size_t i = 0; i < n; i++) {
        double v = col_dot(w->A, i, w->b) * w->inv_norm[i];
        if (w->mu > 0.0)
            v += w->mu * w->colnorm[i] * w->centre[i];
        w->rhs[w->pos[i]] = v;
    }
    return TK_OK;
}

/* Column i of the matrix the factor holds (M + mu I on the columns in the
 * factor and i itself), by position, into w->R. */
static void lh_column(nnls_work *w, size_t i)
{
    const int *Ai = w->A->i, *Tp = w->Tall->p, *Ti = w->Tall->i;
    const double *Ax = w->A->x, *Tx = w->Tall->x;
    size_t lo, hi, nt = 0;
    col_span(w->A, i, &lo, &hi);
    for (size_t e = lo; e < hi; e++) {
        double v = Ax[e] * w->inv_norm[i];
        for (int f = Tp[Ai[e]]; f < Tp[Ai[e] + 1]; f++) {
            size_t j = (size_t)Ti[f];
            if (j == i || !w->in_factor[j])
                continue;
            if (w->acc[j] == 0.0)
                w->touched[nt++] = (int)j;
            w->acc[j] += Tx[f] * v;
            if (w->acc[j] == 0.0) /* cancelled: keep it listed once */
                w->acc[j] = 0x1p-1074;
        }
    }
    int *Ri = w->R->i, *Rp = w->R->p;
    double *Rx = w->R->x;
    for (size_t q = 0; q < nt; q++) {
        Ri[q] = w->pos[w->touched[q]];
        Rx[q] = w->acc[w->touched[q]];
        w->acc[w->touched[q]] = 0.0;
    }
    Ri[nt] = w->pos[i];
    Rx[nt] = 1.0 + w->mu;
    Rp[0] = 0;
    Rp[1] = (int)nt + 1;
}

/* Brings the factor to the passive set; *singular when its pivots say the
 * passive columns are dependent (see factor_rcond). */
static int lh_sync(nnls_work *w, bool *singular, tk_error *err)
{
    size_t n = w->n, nf = 0;
    bool afresh = factor_stale(w, w->lhL);
    if (afresh) {
        /* afresh: from the identity, adding the rows in order costs one
         * factorisation (each row's trailing matrix is still the identity) */
        if (w->lhL)
            cholmod_free_factor(&w->lhL, &w->s->cc);
        w->lhL = cholmod_allocate_factor(n, &w->s->cc);
        if (!w->lhL)
            return cholmod_failure(w->s, "allocate", err);
        memset(w->in_factor, 0, n * sizeof *w->in_factor);
        w->lh_updates = 0;
        w->rep.factorisations++;
    }
    for (size_t p = 0; p < n; p++) {
        size_t i = (size_t)w->order[p];
        if (w->in_factor[i] && !w->passive[i]) {
            if (!cholmod_rowdel(p, NULL, w->lhL, &w->s->cc) || w->s->cc.status < CHOLMOD_OK)
                return cholmod_failure(w->s, "rowdel", err);
            w->in_factor[i] = false;
            w->lh_updates++;
        }
    }
    for (size_t p = 0; p < n; p++) {
        size_t i = (size_t)w->order[p];
        if (w->passive[i] && !w->in_factor[i]) {
            lh_column(w, i);
            if (!cholmod_rowadd(p, w->R, w->lhL, &w->s->cc) || w->s->cc.status < CHOLMOD_OK)
                return cholmod_failure(w->s, "rowadd", err);
            w->in_factor[i] = true;
            w->lh_updates += !afresh;
        }
    }
    /* simplicial LDL': D's entries lead the columns */
    const int *Lp = w->lhL->p;
    const double *Lx = w->lhL->x;
    double lo = INFINITY, hi = 0.0;
    for (size_t p = 0; p < n; p++)
        if (w->passive[w->order[p]]) {
            double d = Lx[Lp[p]];
            nf++;
            lo = isfinite(d) ? fmin(lo, d) : -INFINITY;
            hi = fmax(hi, d);
        }
    double rcond = nf == 0 ? 1.0 : hi > 0.0 && lo > 0.0 ? lo / hi : 0.0;
    w->rep.rcond = fmin(w->rep.rcond, rcond);
    *singular = rcond < w->rcond_floor;
    /* a dependent column's tiny pivot spoils the rows after it, and
     * deleting it again would divide by that pivot: built afresh next */
    if (*singular)
        w->lh_updates = NNLS_LH_REFRESH + 1;
    return TK_OK;
}

/* passive_solve's answer (not regularised) from the modified factor. */
static int lh_solve(nnls_work *w, bool *singular, double *out, tk_error *err)
{
    size_t n = w->n;
    if (w->lh_primal) {
        int rc = primal_sync(w, singular, err);
        return rc != TK_OK || *singular ? rc : primal_answer(w, w->pL, out, err);
    }
    int rc = lh_sync(w, singular, err);
    if (rc != TK_OK || *singular)
        return rc;
    if (w->lhL->xtype == CHOLMOD_PATTERN) {
        /* no passive column yet: the factor is still symbolic */
        memset(out, 0, n * sizeof *out);
        return TK_OK;
    }
    /* the right-hand side on the passive set, zero off it */
    double *c = w->c, *z = w->zpos, *res = w->res;
    for (size_t p = 0; p < n; p++)
        c[p] = w->passive[w->order[p]] ? w->rhs[p] : 0.0;
    const double *sol;
    memcpy(res, c, n * sizeof *res);
    if ((rc = factor_solve(w->s, w->lhL, res, n, &sol, err)) != TK_OK)
        return rc;
    memcpy(z, sol, n * sizeof *z);
    /* one step of refinement, its residual c - (M + mu I) z from A */
    const int *Ai = w->A->i;
    const double *Ax = w->A->x;
    memset(w->r, 0, w->m * sizeof *w->r);
    for (size_t p = 0; p < n; p++) {
        size_t i = (size_t)w->order[p], lo, hi;
        if (!w->passive[i])
            continue;
        col_span(w->A, i, &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            w->r[Ai[e]] += Ax[e] * w->inv_norm[i] * z[p];
    }
    for (size_t p = 0; p < n; p++) {
        size_t i = (size_t)w->order[p];
        res[p] = w->passive[i]
                     ? c[p] - col_dot(w->A, i, w->r) * w->inv_norm[i] - w->mu * z[p]
                     : 0.0;
    }
    if ((rc = factor_solve(w->s, w->lhL, res, n, &sol, err)) != TK_OK)
        return rc;
    for (size_t i = 0; i < n; i++) {
        size_t p = (size_t)w->pos[i];
        out[i] = w->passive[i] ? (z[p] + sol[p]) * w->inv_norm[i] : 0.0;
    }
    return TK_OK;
}

/* r = A x - b and y = A^T r + mu D^2 (x - c), the objective's half
 * gradient (for every column, or only the active ones with y = 0 on the
 * passive set, as block pivoting defines it). */
static void gradient(nnls_work *w, const double *x, bool active_only)
{
    const int *Ai = w->A->i;
    const double *Ax = w->A->x;
    for (size_t k = 0; k < w->m; k++)
        w->r[k] = -w->b[k];
    for (size_t i = 0; i < w->n; i++) {
        if (x[i] == 0.0)
            continue;
        size_t lo, hi;
        col_span(w->A, i, &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            w->r[Ai[e]] += Ax[e] * x[i];
    }
    for (size_t i = 0; i < w->n; i++) {
        if (active_only && w->passive[i]) {
            w->y[i] = 0.0;
            continue;
        }
        w->y[i] = col_dot(w->A, i, w->r);
        if (w->mu > 0.0)
            w->y[i] += w->mu * w->colnorm[i] * w->colnorm[i] * (x[i] - w->centre[i]);
    }
}

/* Whether variable i is infeasible, in the scale-free sense above. */
static bool infeasible(const nnls_work *w, const double *x, size_t i)
{
    double si = w->colnorm[i];
    if (si == 0.0)
        return false;
    return w->passive[i] ? si * x[i] < -w->tolb : w->y[i] / si < -w->tolb;
}

/* Block principal pivoting from x = 0, or from the least-squares solution
 * on the passive set `guess` (NULL for none).  *converged tells whether it
 * finished.  It gives up (to Lawson and Hanson) when the backup rule has
 * run NNLS_BACKUP_STEPS times without finishing, or at once when the
 * backup rule is needed after a passive set needed regularising: with a
 * singular A^T A the problem is only positive semi-definite, and single
 * pivots were seen to wander for thousands of steps. */
#define NNLS_BACKUP_STEPS 10

static int block_pivoting(nnls_work *w, double *x, const bool *guess, bool *converged,
                          tk_error *err)
{
    size_t n = w->n;
    size_t bar = SIZE_MAX;          /* Kim and Park's beta */
    int budget = NNLS_FULL_EXCHANGE_BUDGET;
    int backup_steps = 0;
    bool singular;
    int rc;
    *converged = false;
    w->best_count = SIZE_MAX;
    memset(x, 0, n * sizeof *x);
    memset(w->passive, 0, n * sizeof *w->passive);
    if (guess) {
        for (size_t i = 0; i < n; i++)
            w->passive[i] = guess[i] && w->colnorm[i] > 0.0;
        if ((rc = passive_solve(w, true, &singular, x, err)) != TK_OK)
            return rc;
        if (singular) {
            memset(x, 0, n * sizeof *x);
            memset(w->passive, 0, n * sizeof *w->passive);
        }
    }
    gradient(w, x, true);
    for (;;) {
        size_t ninf = 0, last = 0;
        for (size_t i = 0; i < n; i++)
            if (infeasible(w, x, i)) {
                ninf++;
                last = i;
            }
        if (ninf < w->best_count) {
            w->best_count = ninf;
            memcpy(w->best, x, n * sizeof *x);
        }
        if (ninf == 0) {
            *converged = true;
            return TK_OK;
        }
        if (w->rep.iterations >= w->max_iter)
            return TK_OK;
        bool backup = false;
        if (ninf < bar) {
            bar = ninf;
            budget = NNLS_FULL_EXCHANGE_BUDGET;
        } else if (budget > 0) {
            budget--;
        } else {
            backup = true;
        }
        if (backup) {
            if (w->delta_mode > 0.0 || backup_steps >= NNLS_BACKUP_STEPS)
                return TK_OK;
            /* only the infeasible variable of largest index changes side */
            backup_steps++;
            w->rep.used_fallback = true;
            w->passive[last] = !w->passive[last];
        } else {
            for (size_t i = 0; i < n; i++)
                if (infeasible(w, x, i))
                    w->passive[i] = !w->passive[i];
        }
        w->rep.iterations++;
        if ((rc = passive_solve(w, true, &singular, x, err)) != TK_OK)
            return rc;
        gradient(w, x, true);
    }
}

/* Lawson and Hanson's inner loop: moves x towards the least-squares
 * solution on the passive set, dropping the variables that reach zero,
 * until that solution is positive.  t is the column just added (SIZE_MAX
 * for none): when it leaves again without any step taken, the loop stops
 * with *progress false.  *singular: the passive columns are dependent to
 * working precision (x is then unchanged by the last attempt). */
static int lh_inner(nnls_work *w, double *x, size_t t, bool *progress, bool *singular,
                    tk_error *err)
{
    size_t n = w->n;
    *progress = false;
    for (;;) {
        int rc = lh_solve(w, singular, w->trial, err);
        if (rc != TK_OK || *singular)
            return rc;
        /* the longest step from x towards trial that stays feasible */
        double alpha = 1.0;
        size_t hit = SIZE_MAX;
        for (size_t i = 0; i < n; i++)
            if (w->passive[i] && w->trial[i] <= 0.0) {
                /* x_i = trial_i = 0 (a column just added) blocks any step */
                double d = x[i] - w->trial[i];
                double a = d > 0.0 ? x[i] / d : 0.0;
                if (a < alpha) {
                    alpha = a;
                    hit = i;
                }
            }
        if (hit == SIZE_MAX) {
            memcpy(x, w->trial, n * sizeof *x);
            *progress = true;
            return TK_OK;
        }
        if (alpha > 0.0)
            *progress = true;
        for (size_t i = 0; i < n; i++)
            if (w->passive[i]) {
                x[i] += alpha * (w->trial[i] - x[i]);
                if (i == hit || x[i] <= 0.0) {
                    x[i] = 0.0;
                    w->passive[i] = false;
                }
            }
        if (t != SIZE_MAX && !w->passive[t] && !*progress)
            return TK_OK;
    }
}

/* Lawson and Hanson's active-set method: columns join the passive set one
 * at a time (the most violating first) and leave it when a step towards
 * the unconstrained solution would make them negative, so every iterate
 * is feasible, the objective falls and the passive columns stay
 * independent (a column whose addition makes the normal equations
 * singular is blocked until the next step makes progress).  Slower than
 * block pivoting, but it needs no regularisation and does not cycle on
 * rank-deficient or degenerate problems.  It starts from x (feasible,
 * e.g. block pivoting's best iterate clamped at 0) when the support of x
 * has independent columns, otherwise from 0. */
static int lawson_hanson(nnls_work *w, double *x, bool *converged, tk_error *err)
{
    size_t n = w->n;
    bool progress, singular;
    *converged = false;
    memset(w->blocked, 0, n * sizeof *w->blocked);
    w->lh_primal = primal_pays(w, n);
    int rc = lh_alloc(w, err);
    if (rc != TK_OK)
        return rc;
    for (size_t i = 0; i < n; i++) {
        if (!(x[i] > 0.0) || w->colnorm[i] == 0.0)
            x[i] = 0.0;
        w->passive[i] = x[i] > 0.0;
    }
    rc = lh_inner(w, x, SIZE_MAX, &progress, &singular, err);
    if (rc != TK_OK)
        return rc;
    if (singular) {
        memset(x, 0, n * sizeof *x);
        memset(w->passive, 0, n * sizeof *w->passive);
    }
    gradient(w, x, false);
    for (;;) {
        size_t t = SIZE_MAX;
        double most = -w->tolb;
        for (size_t i = 0; i < n; i++) {
            if (w->passive[i] || w->blocked[i] || w->colnorm[i] == 0.0)
                continue;
            double v = w->y[i] / w->colnorm[i];
            if (v < most) {
                most = v;
                t = i;
            }
        }
        if (t == SIZE_MAX) {
            *converged = true;
            return TK_OK;
        }
        if (w->rep.iterations >= w->max_iter)
            return TK_OK;
        w->rep.iterations++;
        w->passive[t] = true;
        if ((rc = lh_inner(w, x, t, &progress, &singular, err)) != TK_OK)
            return rc;
        if (singular) {
            /* t depends on the passive columns to working precision */
            w->passive[t] = false;
            progress = false;
        }
        if (progress)
            memset(w->blocked, 0, n * sizeof *w->blocked);
        else
            w->blocked[t] = true;
        gradient(w, x, false);
    }
}

/* ------------------------------------------------------------------ */
/* An interior point for the coordinate form.
 *
 * Where block pivoting gives up on a problem in the coordinate form (a
 * cold start at thousands of struts: every contact new, no forces to start
 * from), Lawson and Hanson, one column at a time, took most of the 3,807
 * pivoting iterations of the first flow step of a tight 2,435-vertex
 * trefoil tightened again (bench/steps --curve).  A primal-dual interior
 * point method (Mehrotra's predictor-corrector, Nocedal and Wright,
 * Numerical Optimization, 2nd ed., section 16.6) needs a few dozen steps
 * (about 20 there) whatever the partition, each one factorisation of the
 * same pattern: in the
 * scaled variables z the problem is
 *     min 1/2 |P z - b|^2 + mu/2 |z - z_c|^2,  z >= 0,
 * its KKT conditions g(z) = P'(P z - b) + mu (z - z_c) = s, z, s >= 0,
 * z_i s_i = 0, and a Newton step solves (P'P + Lambda) dz = q with
 * Lambda = mu I + Z^-1 S diagonal, by Woodbury through the m x m matrix
 * K = I + P Lambda^-1 P' (the analysis of P P' already made).  Its answer
 * is only near the solution; its partition (z_i > s_i passive) then
 * starts block pivoting again, which ends the solve exactly, as a warm
 * start does. */
#define NNLS_IPM_ITERATIONS 60
#define NNLS_IPM_GAP 1e-14      /* stop at mean z_i s_i below this times the first */
#define NNLS_IPM_FRACTION 0.99  /* of the step to the boundary */

typedef struct nnls_ipm {
    cholmod_sparse *T;          /* P Lambda^-1/2 */
    double *lam, *z, *s, *g, *dz, *ds, *q, *h; /* n */
    double *vm, *rm;            /* m */
} nnls_ipm;

/* out = (P'P + Lambda)^-1 q by Woodbury, K factored in w->pL:
 * Lambda^-1 q - Lambda^-1 P' K^-1 P Lambda^-1 q. */
static int ipm_apply(nnls_work *w, nnls_ipm *ip, const double *q, double *out, tk_error *err)
{
    const int *Pi = w->P->i;
    const double *Px = w->P->x;
    memset(ip->vm, 0, w->m * sizeof *ip->vm);
    for (size_t i = 0; i < w->n; i++) {
        out[i] = q[i] / ip->lam[i];
        size_t lo, hi;
        col_span(w->P, i, &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            ip->vm[Pi[e]] += Px[e] * out[i];
    }
    const double *sol;
    int rc = factor_solve(w->s, w->pL, ip->vm, w->m, &sol, err);
    for (size_t i = 0; rc == TK_OK && i < w->n; i++)
        out[i] -= col_dot(w->P, i, sol) / ip->lam[i];
    return rc;
}

/* ipm_apply with a step of refinement whose residual q - (P'P + Lambda)
 * out comes from P (into h). */
static int ipm_solve(nnls_work *w, nnls_ipm *ip, const double *q, double *out, tk_error *err)
{
    const int *Pi = w->P->i;
    const double *Px = w->P->x;
    int rc = ipm_apply(w, ip, q, out, err);
    if (rc != TK_OK)
        return rc;
    memset(ip->rm, 0, w->m * sizeof *ip->rm);
    for (size_t i = 0; i < w->n; i++) {
        size_t lo, hi;
        col_span(w->P, i, &lo, &hi);
        for (size_t e = lo; e < hi; e++)
            ip->rm[Pi[e]] += Px[e] * out[i];
    }
    for (size_t i = 0; i < w->n; i++)
        ip->h[i] = q[i] - col_dot(w->P, i, ip->rm) - ip->lam[i] * out[i];
    /* q is spent (it may be ip->q itself): the correction goes there */
    if ((rc = ipm_apply(w, ip, ip->h, ip->q, err)) != TK_OK)
        return rc;
    for (size_t i = 0; i < w->n; i++)
        out[i] += ip->q[i];
    return TK_OK;
}

/* The largest alpha keeping v + alpha dv >= 0 (infinite when no entry falls). */
static double ipm_reach(const double *v, const double *dv, size_t n)
{
    double alpha = INFINITY;
    for (size_t i = 0; i < n; i++)
        if (dv[i] < 0.0)
            alpha = fmin(alpha, -v[i] / dv[i]);
    return alpha;
}

static void ipm_free(nnls_work *w, nnls_ipm *ip)
{
    if (ip->T)
        cholmod_free_sparse(&ip->T, &w->s->cc);
    double **v[] = {&ip->lam, &ip->z, &ip->s, &ip->g, &ip->dz, &ip->ds, &ip->q, &ip->h,
                    &ip->vm, &ip->rm};
    for (size_t k = 0; k < sizeof v / sizeof *v; k++)
        free(*v[k]);
}

/* The interior point above; guess (n) gets its partition.  Its steps and
 * factorisations count in the report.  The coordinate form's factor is
 * left holding K: the next primal_sync builds it afresh. */
static int interior_point(nnls_work *w, bool *guess, tk_error *err)
{
    size_t m = w->m, n = w->n;
    assert(w->mu > 0.0);
    int rc = primal_alloc(w, err);
    if (rc == TK_OK)
        rc = primal_analysis(w, NULL, err);
    if (rc != TK_OK)
        return rc;
    w->pl_current = w->s->kept.valid = false;
    nnls_ipm ip = {0};
    double **nv[] = {&ip.lam, &ip.z, &ip.s, &ip.g, &ip.dz, &ip.ds, &ip.q, &ip.h};
    bool ok = (ip.T = cholmod_copy_sparse(w->P, &w->s->cc)) != NULL;
    for (size_t k = 0; k < sizeof nv / sizeof *nv; k++)
        ok = (*nv[k] = malloc(n * sizeof **nv[k])) && ok;
    ok = (ip.vm = malloc(m * sizeof *ip.vm)) && (ip.rm = malloc(m * sizeof *ip.rm)) && ok;
    if (!ok) {
        ipm_free(w, &ip);
        return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu columns)", n);
    }
    const int *Pi = w->P->i;
    const double *Px = w->P->x;
    double *Tx = ip.T->x;
    /* start on the central path's scale: z = s = the largest |P' b| */
    double zeta = 0.0;
    for (size_t i = 0; i < n; i++)
        zeta = fmax(zeta, fabs(w->ptb[i]));
    for (size_t i = 0; i < n; i++)
        ip.z[i] = ip.s[i] = zeta > 0.0 ? zeta : 1.0;
    double gap0 = 0.0;
    w->lh_updates = NNLS_LH_REFRESH + 1;
    for (int it = 0; it < NNLS_IPM_ITERATIONS; it++) {
        /* g holds the dual residual g(z) - s; the mean complementarity */
        memcpy(ip.rm, w->b, m * sizeof *ip.rm);
        for (size_t i = 0; i < m; i++)
            ip.rm[i] = -ip.rm[i];
        for (size_t i = 0; i < n; i++) {
            size_t lo, hi;
            col_span(w->P, i, &lo, &hi);
            for (size_t e = lo; e < hi; e++)
                ip.rm[Pi[e]] += Px[e] * ip.z[i];
        }
        double gap = 0.0;
        for (size_t i = 0; i < n; i++) {
            ip.g[i] = col_dot(w->P, i, ip.rm) +
                      w->mu * (ip.z[i] - w->colnorm[i] * w->centre[i]) - ip.s[i];
            gap += ip.z[i] * ip.s[i];
        }
        gap /= (double)n;
        if (it == 0)
            gap0 = gap;
        else if (gap <= NNLS_IPM_GAP * gap0 || !isfinite(gap))
            break;
        /* K = I + P Lambda^-1 P' */
        for (size_t i = 0; i < n; i++) {
            ip.lam[i] = w->mu + ip.s[i] / ip.z[i];
            double sc = 1.0 / sqrt(ip.lam[i]);
            size_t lo, hi;
            col_span(w->P, i, &lo, &hi);
            for (size_t e = lo; e < hi; e++)
                Tx[e] = Px[e] * sc;
        }
        double one[2] = {1.0, 0.0};
        cholmod_factorize_p(ip.T, one, NULL, 0, w->pL, &w->s->cc);
        if (w->s->cc.status < CHOLMOD_OK) {
            rc = cholmod_failure(w->s, "factorize", err);
            break;
        }
        w->s->work.factor_flops += factor_flops(w->pL);
        w->rep.factorisations++;
        w->rep.iterations++;
        w->rep.interior_steps++;
        /* the predictor (affine scaling) step: sigma = 0 */
        for (size_t i = 0; i < n; i++)
            ip.q[i] = -ip.g[i] - ip.s[i];
        if ((rc = ipm_solve(w, &ip, ip.q, ip.dz, err)) != TK_OK)
            break;
        for (size_t i = 0; i < n; i++)
            ip.ds[i] = -ip.s[i] - ip.s[i] / ip.z[i] * ip.dz[i];
        double alpha = fmin(1.0, fmin(ipm_reach(ip.z, ip.dz, n), ipm_reach(ip.s, ip.ds, n)));
        double affine = 0.0;
        for (size_t i = 0; i < n; i++)
            affine += (ip.z[i] + alpha * ip.dz[i]) * (ip.s[i] + alpha * ip.ds[i]);
        affine /= (double)n;
        double sigma = pow(affine / gap, 3.0);
        /* the corrector: centring sigma gap and the predictor's second
         * order term; q = -g + Z^-1 r_c, r_c = sigma gap - z s - dz ds */
        for (size_t i = 0; i < n; i++) {
            double rcomp = sigma * gap - ip.z[i] * ip.s[i] - ip.dz[i] * ip.ds[i];
            ip.ds[i] = rcomp; /* ds below from it */
            ip.q[i] = -ip.g[i] + rcomp / ip.z[i];
        }
        if ((rc = ipm_solve(w, &ip, ip.q, ip.dz, err)) != TK_OK)
            break;
        for (size_t i = 0; i < n; i++)
            ip.ds[i] = (ip.ds[i] - ip.s[i] * ip.dz[i]) / ip.z[i];
        alpha = fmin(1.0, NNLS_IPM_FRACTION *
                              fmin(ipm_reach(ip.z, ip.dz, n), ipm_reach(ip.s, ip.ds, n)));
        for (size_t i = 0; i < n; i++) {
            ip.z[i] += alpha * ip.dz[i];
            ip.s[i] += alpha * ip.ds[i];
        }
    }
    for (size_t i = 0; i < n; i++)
        guess[i] = ip.z[i] > ip.s[i] && w->colnorm[i] > 0.0;
    ipm_free(w, &ip);
    return rc;
}

/* Whether the interior point should come before Lawson and Hanson.  They
 * take about one iteration per violation of block pivoting's best iterate
 * (seen: 100 for 103, 1517 for 1739, 488 for 462), each a few solves with
 * the factor and a gradient; the interior point two dozen factorisations
 * and block pivoting's new start.  So the choice goes by the violations
 * against the ratio of a factorisation's flops to the factor's entries:
 * on the tight 2,435-vertex trefoil (ratio 80) the two broke even between
 * 135 and 460 violations. */
#define NNLS_IPM_PAYS 3.0

static int interior_pays(nnls_work *w, bool *pays, tk_error *err)
{
    *pays = false;
    int rc = primal_alloc(w, err);
    if (rc == TK_OK)
        rc = primal_analysis(w, NULL, err);
    if (rc == TK_OK)
        *pays = (double)w->best_count >
                NNLS_IPM_PAYS * w->s->primal.fl / fmax(w->s->primal.lnz, 1.0);
    return rc;
}

int tk_nnls_solve(tk_nnls *s, const cholmod_sparse *A, const double *b, double *x,
                  const tk_nnls_options *opts, tk_nnls_report *report, tk_error *err)
{
    tk_nnls_options o = TK_NNLS_OPTIONS_INIT;
    nnls_work w;
    memset(&w, 0, sizeof w);
    w.rep = (tk_nnls_report){0, 0, false, false, 0.0, 1.0, 0.0, 0.0, 0, false, 0};
    int rc = TK_OK;

    if (!s)
        return tk_error_set(err, TK_EINVAL, "nnls: no solver");
    if ((rc = check_matrix(A, err)) != TK_OK)
        return rc;
    size_t m = A->nrow, n = A->ncol;
    if ((rc = check_vector(b, m, "b", err)) != TK_OK)
        return rc;
    if (n > 0 && !x)
        return tk_error_set(err, TK_EINVAL, "nnls: no x vector");
    if (opts)
        o = *opts;
    w.s = s;
    w.A = A;
    w.b = b;
    w.m = m;
    w.n = n;
    w.max_iter = o.max_iterations > 0 ? o.max_iterations
                 : (n > (size_t)(INT_MAX / 4) ? INT_MAX : 50 + 2 * (int)n);
    w.rcond_floor = o.rcond_floor >= 0.0 ? o.rcond_floor : NNLS_DEFAULT_RCOND_FLOOR;
    double tol = o.kkt_tolerance > 0.0 ? o.kkt_tolerance : NNLS_DEFAULT_TOLERANCE;

    if (!(o.proximal >= 0.0) || !isfinite(o.proximal))
        return tk_error_set(err, TK_EINVAL, "nnls: the proximal weight %g is not >= 0",
                            o.proximal);
    w.mu = o.proximal;
    if (!(o.unrefined >= 0.0))
        return tk_error_set(err, TK_EINVAL, "nnls: the weight without refinement %g is not >= 0",
                            o.unrefined);
    w.refined = !(o.unrefined > 0.0 && w.mu >= o.unrefined);
    bool *guess = NULL;
    if ((o.warm_start || w.mu > 0.0) && n > 0) {
        guess = malloc(n * sizeof *guess);
        w.centre = calloc(n, sizeof *w.centre);
        if (!guess || !w.centre) {
            free(guess);
            free(w.centre);
            return tk_error_set(err, TK_ENOMEM, "out of memory for nnls (%zu columns)", n);
        }
        for (size_t i = 0; i < n; i++) {
            guess[i] = x[i] > 0.0;
            w.centre[i] = w.mu > 0.0 && x[i] > 0.0 ? x[i] : 0.0;
        }
    }
    for (size_t i = 0; i < n; i++)
        x[i] = 0.0;
    double bnorm = norm2(b, m);
    w.rep.residual = bnorm;
    w.tolb = tol * bnorm;
    /* x = 0 is optimal for b = 0, and nothing is to be solved for n = 0 */
    if (n == 0 || bnorm == 0.0)
        goto done;
    if ((rc = work_alloc(&w, err)) != TK_OK)
        goto done;

    /* Two phases share the iteration cap.  Block pivoting solves the
     * usual problem in a few iterations.  When it stalls (n > m, or a
     * rank-deficient or degenerate problem), Lawson and Hanson's method
     * takes its best iterate (clamped, so feasible) to the answer one
     * variable at a time: from there it needs about as many steps as that
     * iterate had violations, where from 0 it needs one per passive
     * variable.  (Going on with block pivoting on a regularised, positive
     * definite problem was tried and stalled the same way.) */
    bool converged = false, lh = false;
    rc = block_pivoting(&w, x, guess, &converged, err);
    bool ipm = false;
    if (rc == TK_OK && !converged && w.rep.iterations < w.max_iter && primal_pays(&w, n) &&
        o.interior >= 0) {
        ipm = o.interior > 0;
        if (!ipm)
            rc = interior_pays(&w, &ipm, err);
    }
    if (rc == TK_OK && ipm) {
        /* guess is there: mu > 0 */
        w.rep.used_fallback = true;
        rc = interior_point(&w, guess, err);
        if (rc == TK_OK)
            rc = block_pivoting(&w, x, guess, &converged, err);
    }
    if (rc == TK_OK && !converged && w.rep.iterations < w.max_iter) {
        w.rep.used_fallback = true;
        lh = true;
        memcpy(x, w.best, n * sizeof *x);
        rc = lawson_hanson(&w, x, &converged, err);
    }
    if (rc == TK_OK && !converged)
        rc = tk_error_set(err, TK_ENUMERIC, "nnls: no solution after %d pivoting iterations",
                          w.rep.iterations);
    if (rc == TK_OK && (rc = primal_keep(&w, err)) == TK_OK)
        w.rep.kept = w.pl_current;
    /* Lawson-Hanson's iterates are feasible and improve; otherwise keep
     * block pivoting's best */
    if (rc != TK_OK && !lh)
        memcpy(x, w.best, n * sizeof *x);
    /* within tolerance is feasible: the answer is exactly non-negative */
    for (size_t i = 0; i < n; i++)
        if (!(x[i] > 0.0))
            x[i] = 0.0;
    gradient(&w, x, true);
    w.rep.residual = norm2(w.r, m);
    for (size_t i = 0; i < n; i++) {
        w.rep.passive += x[i] > 0.0;
        if (w.mu > 0.0)
            w.rep.proximal_term +=
                w.mu * w.colnorm[i] * w.colnorm[i] * x[i] * (x[i] - w.centre[i]);
    }

done:
    if (report)
        *report = w.rep;
    work_free(&w);
    free(guess);
    return rc;
}

/* The columns F (nf of them) of A, each divided by its norm: P (m x nf),
 * with P P' = A D^-1 A' over F. */
static void build_scaled(const cholmod_sparse *A, const int *F, size_t nf,
                         const double *inv_norm, cholmod_sparse *P)
{
    int *Pp = P->p, *Pi = P->i;
    double *Px = P->x;
    const int *Ai = A->i;
    const double *Ax = A->x;
    size_t e = 0;
    for (size_t q = 0; q < nf; q++) {
        size_t lo, hi;
        col_span(A, (size_t)F[q], &lo, &hi);
        Pp[q] = (int)e;
        for (size_t k = lo; k < hi; k++, e++) {
            Pi[e] = Ai[k];
            Px[e] = Ax[k] * inv_norm[F[q]];
        }
    }
    Pp[nf] = (int)e;
    P->ncol = nf;
    P->sorted = A->sorted;
    P->packed = 1;
}

/* Whether the damped step is cheaper in its primal form, (P P' + delta I)
 * du = P c with P P' of order m, than in its dual one, (P' P + delta I) z
 * = c of order nf: by the entries of the two normal matrices, the sum of
 * squared row counts of P against that of its squared column counts.  A
 * vertex touching a whole strand (the round Hopf link: every vertex near
 * the other ring's centre is equidistant from all of it) puts a dense
 * block of its struts into the dual matrix, and only one dense row into
 * the primal one. */
static bool primal_is_smaller(const cholmod_sparse *A, const int *F, size_t nf, int *rowcount)
{
    const int *Ai = A->i;
    double dual = 0.0, primal = 0.0;
    memset(rowcount, 0, A->nrow * sizeof *rowcount);
    for (size_t q = 0; q < nf; q++) {
        size_t lo, hi;
        col_span(A, (size_t)F[q], &lo, &hi);
        primal += (double)(hi - lo) * (double)(hi - lo);
        for (size_t e = lo; e < hi; e++)
            rowcount[Ai[e]]++;
    }
    for (size_t k = 0; k < A->nrow; k++)
        dual += (double)rowcount[k] * (double)rowcount[k];
    return primal < dual;
}

/* The damped step in the metric M: (P P' + delta M) du = P c, P (m x nf)
 * the scaled columns and c their targets, solved with a factorisation of
 * the sum (formed: M is not a multiple of I, so CHOLMOD's beta cannot
 * add it) and two steps of refinement whose residual comes from P and M
 * themselves.  w holds nf entries and res m. */
static int metric_solve(tk_nnls *s, const cholmod_sparse *P, const cholmod_sparse *M,
                        double delta, const double *c, double *du, double *w, double *res,
                        tk_error *err)
{
    size_t m = P->nrow;
    int rc = TK_OK;
    double one[2] = {1.0, 0.0}, weight[2] = {delta, 0.0};
    cholmod_sparse *ppt = cholmod_aat((cholmod_sparse *)P, NULL, 0, 1, &s->cc);
    cholmod_sparse *sum =
        ppt ? cholmod_add(ppt, (cholmod_sparse *)M, one, weight, 1, 1, &s->cc) : NULL;
    cholmod_sparse *upper = sum ? cholmod_copy(sum, 1, 1, &s->cc) : NULL;
    cholmod_factor *L = upper ? cholmod_analyze(upper, &s->cc) : NULL;
    if (!L || !cholmod_factorize(upper, L, &s->cc) || s->cc.status < CHOLMOD_OK) {
        rc = cholmod_failure(s, "factorize", err);
        goto done;
    }
    s->work.factor_flops += factor_flops(L);
    if (s->cc.status == CHOLMOD_NOT_POSDEF || !(factor_rcond(L) > 0.0)) {
        rc = tk_error_set(err, TK_ENUMERIC, "nnls: the damped step's matrix (order %zu) is "
                          "not positive definite", m);
        goto done;
    }
    cholmod_dense X;
    memset(&X, 0, sizeof X);
    X.nrow = X.nzmax = X.d = m;
    X.ncol = 1;
    X.x = du;
    X.xtype = CHOLMOD_REAL;
    X.dtype = CHOLMOD_DOUBLE;
    /* each pass solves for the residual res = P (c - P' du) - delta M du
     * (at du = 0: P c) and adds the answer to du */
    double minus_delta[2] = {-delta, 0.0};
    cholmod_dense R = X;
    R.x = res;
    const double *sol;
    memset(du, 0, m * sizeof *du);
    for (int pass = 0; pass < 3 && rc == TK_OK; pass++) {
        t_transpose_times(P, du, w);
        for (size_t k = 0; k < P->ncol; k++)
            w[k] = c[k] - w[k];
        t_times(P, w, res);
        cholmod_sdmult((cholmod_sparse *)M, 0, minus_delta, one, &X, &R, &s->cc);
        if ((rc = factor_solve(s, L, res, m, &sol, err)) == TK_OK)
            for (size_t i = 0; i < m; i++)
                du[i] += sol[i];
    }
done:
    cholmod_free_factor(&L, &s->cc);
    cholmod_free_sparse(&upper, &s->cc);
    cholmod_free_sparse(&sum, &s->cc);
    cholmod_free_sparse(&ppt, &s->cc);
    return rc;
}

int tk_nnls_min_norm(tk_nnls *s, const cholmod_sparse *A, const double *r, double delta_min,
                     const cholmod_sparse *metric, double *du, double *delta_used,
                     tk_error *err)
{
    int rc = TK_OK;
    int *F = NULL, *next = NULL;
    double *c = NULL, *z = NULL, *res = NULL, *inv_norm = NULL;
    cholmod_sparse *T = NULL;

    if (delta_used)
        *delta_used = 0.0;
    if (!s)
        return tk_error_set(err, TK_EINVAL, "nnls: no solver");
    if ((rc = check_matrix(A, err)) != TK_OK)
        return rc;
    size_t m = A->nrow, n = A->ncol;
    if ((rc = check_vector(r, n, "r", err)) != TK_OK)
        return rc;
    if (m > 0 && !du)
        return tk_error_set(err, TK_EINVAL, "nnls: no du vector");
    if (!(delta_min >= 0.0 && delta_min <= NNLS_DELTA_CAP))
        return tk_error_set(err, TK_EINVAL, "nnls: damping %g outside [0, %g]", delta_min,
                            NNLS_DELTA_CAP);
    if (metric && !(delta_min > 0.0 && metric->nrow == m && metric->ncol == m &&
                    metric->stype == 0 && metric->xtype == CHOLMOD_REAL))
        return tk_error_set(err, TK_EINVAL,
                            "nnls: a metric needs a positive damping and a real %zu x %zu "
                            "matrix with both triangles stored",
                            m, m);
    for (size_t k = 0; k < m; k++)
        du[k] = 0.0;
    if (n == 0 || m == 0)
        return TK_OK;

    F = malloc(n * sizeof *F);
    next = malloc(m * sizeof *next);
    c = malloc(n * sizeof *c);
    z = malloc((n > m ? n : m) * sizeof *z);
    res = malloc((n > m ? n : m) * sizeof *res);
    inv_norm = malloc(n * sizeof *inv_norm);
    if (!F || !next || !c || !z || !res || !inv_norm) {
        rc = tk_error_set(err, TK_ENOMEM, "out of memory for min-norm (%zu columns)", n);
        goto done;
    }
    /* zero columns add nothing to A y; leaving them out keeps A^T A from
     * being singular for no reason (their rows of A^T du = r cannot hold
     * unless r is 0 there) */
    size_t nf = 0;
    const double *Ax = A->x;
    for (size_t i = 0; i < n; i++) {
        size_t lo, hi;
        col_span(A, i, &lo, &hi);
        double si = hi > lo ? norm2(Ax + lo, hi - lo) : 0.0;
        inv_norm[i] = si > 0.0 ? 1.0 / si : 0.0;
        if (si > 0.0) {
            /* scaled: A D^-1 y' = du with (D^-1 A^T A D^-1) y' = D^-1 r */
            c[nf] = r[i] * inv_norm[i];
            F[nf++] = (int)i;
        }
    }
    if (nf == 0)
        goto done;
    /* delta = 0 needs the dual form: P P' is singular below full rank; a
     * metric the primal one (the dual would need its inverse) */
    bool primal = metric || (delta_min > 0.0 && primal_is_smaller(A, F, nf, next));
    T = primal ? cholmod_allocate_sparse(m, n, matrix_nnz(A), 1, 1, 0, CHOLMOD_REAL, &s->cc)
               : cholmod_allocate_sparse(n, m, matrix_nnz(A), 1, 1, 0, CHOLMOD_REAL, &s->cc);
    if (!T) {
        rc = cholmod_failure(s, "allocate", err);
        goto done;
    }
    if (primal)
        build_scaled(A, F, nf, inv_norm, T);
    else
        build_transpose(A, F, nf, inv_norm, T, next);
    if (metric) {
        if ((rc = metric_solve(s, T, metric, delta_min, c, du, z, res, err)) == TK_OK &&
            delta_used)
            *delta_used = delta_min;
        goto done;
    }
    nnls_factor f = {NULL, 0.0, 1.0, 0, false};
    if ((rc = factor_normal(s, T, NULL, NULL, 0, delta_min, true, NNLS_DEFAULT_RCOND_FLOOR, &f,
                            err)) != TK_OK)
        goto done;
    /* r need not be in the range of A^T (dependent constraints with
     * different targets), so the refinement stays on the regularised
     * system: iterated Tikhonov would blow its null-space part up by
     * 1 / delta a step */
    if (primal) {
        /* du = (P P' + delta I)^-1 P c: the same step, by P (P' P +
         * delta I)^-1 = (P P' + delta I)^-1 P */
        t_times(T, c, z);
        if ((rc = normal_solve(s, T, &f, z, du, c, res, 2, f.delta, err)) != TK_OK)
            goto done;
    } else {
        if ((rc = normal_solve(s, T, &f, c, z, du, res, f.delta > 0.0 ? 2 : 1, f.delta, err)) !=
            TK_OK)
            goto done;
        t_transpose_times(T, z, du);
    }
    if (delta_used)
        *delta_used = f.delta;

done:
    if (rc != TK_OK)
        for (size_t k = 0; k < m; k++)
            du[k] = 0.0;
    cholmod_free_sparse(&T, &s->cc);
    free(F);
    free(next);
    free(c);
    free(z);
    free(res);
    free(inv_norm);
    return rc;
}
