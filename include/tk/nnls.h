/* tightknot: sparse non-negative least squares (equation 13).
 *
 *     minimise || A x - b ||  subject to  x >= 0
 *
 * A is m x n sparse (CHOLMOD, real, unsymmetric); in the flow m = 3V
 * coordinates, n = active constraints, b = -(motion), and x are the strut
 * and kink compressions.  Solved by block principal pivoting (Portugal,
 * Judice and Vicente; Kim and Park): each iteration solves the
 * unconstrained least-squares problem on the current passive set by sparse
 * Cholesky of the normal equations, A_F^T A_F x_F = A_F^T b, and exchanges
 * every variable that violates the KKT conditions at once; when the number
 * of violations stops falling the exchange falls back to the single-variable
 * rule (Murty's), which terminates when A^T A is positive definite.  When
 * it is not (n > m, dependent columns) and the single-variable rule stalls,
 * Lawson and Hanson's active-set method finishes from the best iterate.
 *
 * Rank-deficient or ill-conditioned A is normal in the flow (symmetric
 * starts, many contacts).  The solver estimates the reciprocal condition
 * number of each factorisation (CHOLMOD's estimate), and when a
 * factorisation fails or is too ill-conditioned it adds a small Tikhonov
 * term, reported in tk_nnls_report.  Columns are scaled to unit norm
 * inside, so delta is relative: A^T A + delta D with D = diag(A^T A).
 *
 * A tk_nnls owns its cholmod_common and workspace: one per thread.  It keeps
 * the symbolic analysis between calls and reuses it when the passive set's
 * pattern repeats.
 *
 * Where the passive columns are more than half as many as the rows, or
 * more than 2,000 (many contacts), and the problem is the proximal one
 * below with mu >= 1e-8,
 * the solver works with the m x m matrix A_F D^-2 A_F^T + mu I instead of
 * the n_F x n_F normal matrix (the coordinate form: far sparser there),
 * and block pivoting and Lawson and Hanson modify its factor with rank-one
 * updates and downdates (CHOLMOD's cholmod_updown) as columns join and
 * leave.  Its factor is kept after a solve: a next solve of the same
 * matrix (the same entries of A) with the same mu starts from it, updated
 * and downdated to its own passive set, instead of factoring afresh.  Its
 * fill-reducing ordering of the rows is kept too, and serves a next
 * matrix with other columns but as many rows while the factor stays
 * about as sparse.  In that form, when block pivoting gives up, a primal-dual
 * interior point method finds the partition near the answer (a few dozen
 * factorisations of one pattern) and block pivoting starts again from it;
 * Lawson and Hanson come only after that.
 */
#ifndef TK_NNLS_H
#define TK_NNLS_H

#include <stdbool.h>
#include <stddef.h>

#include <cholmod.h>

#include "tk/error.h"

typedef struct tk_nnls tk_nnls;

typedef struct tk_nnls_options {
    int max_iterations;     /* outer pivoting iterations, block pivoting and
                               its fallback together; default 50 + 2n */
    double kkt_tolerance;   /* relative tolerance on the KKT tests; 1e-10 */
    double rcond_floor;     /* regularise factorisations below this; 1e-14 */
    bool warm_start;        /* x holds a guess on entry: its positive entries
                               are the first passive set (in the flow, the
                               previous step's answer: pivoting then often
                               ends in one or two iterations) */
    double proximal;        /* mu > 0: solve the proximal problem instead,
                                   minimise ||A x - b||^2
                                            + mu sum_i s_i^2 (x_i - c_i)^2,
                               s_i = ||a_i||, c = max(x, 0) on entry; 0: the
                               plain problem.  See below. */
    int interior;           /* in the coordinate form, when block pivoting
                               gives up: 0 the interior point where it is
                               expected to cost less than Lawson and Hanson,
                               1 always, -1 never */
    double unrefined;       /* in the coordinate form, the proximal weight
                               from which a passive solve takes no step of
                               refinement (engine/nnls.c, primal_answer);
                               0: every solve takes one */
} tk_nnls_options;

#define TK_NNLS_OPTIONS_INIT {0, 1e-10, 1e-14, false, 0.0, 0, 0.0}

typedef struct tk_nnls_report {
    int iterations;         /* pivoting iterations (and interior point
                               steps) */
    int factorisations;     /* Cholesky factorisations done */
    bool used_fallback;     /* the single-variable exchange rule (or the
                               Lawson-Hanson fallback) was needed */
    bool regularised;       /* a Tikhonov term was added */
    double regularisation;  /* the largest delta used, relative to the
                               diagonal (0 if none) */
    double rcond;           /* smallest reciprocal condition estimate seen
                               (of A_F^T A_F with unit-norm columns: the
                               pivot ratio of its Cholesky factor, as
                               cholmod_rcond; 0 for a singular one; 1 when
                               no column is passive; of A_F^T A_F + mu I for
                               the proximal problem, or in the coordinate
                               form of A_F A_F^T + mu I, scaled likewise) */
    double residual;        /* || A x - b || at the answer */
    double proximal_term;   /* mu sum_i s_i^2 x_i (x_i - c_i) = -(A x) . (A x - b)
                               at the proximal answer (0 at the plain one):
                               how far it leaves the residual from orthogonal
                               to A x */
    size_t passive;         /* number of x_i > 0 */
    bool kept;              /* the coordinate form's factor is kept: a next
                               solve of the same matrix and weight starts
                               from it (see above) */
    int interior_steps;     /* of the interior point (coordinate form), 0
                               when block pivoting needed none */
} tk_nnls_report;

/* A solver with its own CHOLMOD common.  Never prints. */
int tk_nnls_new(tk_nnls **out, tk_error *err);
void tk_nnls_free(tk_nnls **p);

/* The solver's cholmod_common, for allocating matrices passed to it. */
cholmod_common *tk_nnls_common(tk_nnls *s);

/* The work a solver has done, summed over its calls: counts of the
 * operations that depend on the problems alone, not on the machine (the
 * pivoting iterations and factorisations are in the reports). */
typedef struct tk_nnls_work {
    double factor_flops;     /* numeric factorisations: the squares of the
                                factor's column counts summed */
} tk_nnls_work;

tk_nnls_work tk_nnls_work_done(const tk_nnls *s);

/* Solves the NNLS problem.  A is m x n (A->stype == 0, packed, real); b has
 * m entries; x receives n entries.  opts may be NULL for the defaults;
 * report may be NULL.  Returns TK_OK, or TK_ENUMERIC when no answer
 * satisfying x >= 0 could be produced (x then holds the best found). */
int tk_nnls_solve(tk_nnls *s, const cholmod_sparse *A, const double *b, double *x,
                  const tk_nnls_options *opts, tk_nnls_report *report, tk_error *err);

/* The proximal problem (opts->proximal = mu > 0) is strictly convex: its
 * answer is unique and moves continuously with A, b and the centre c, and
 * its normal matrix M + mu I is positive definite, of condition at most
 * about (1 + mu) / mu, so for a moderate mu (1e-2) block pivoting from c's
 * support finishes in a few pivots; as mu shrinks towards 0 it becomes the
 * plain problem again, fallback included.  Repeated with the answer as the
 * next centre it is the proximal point method, whose iterates converge to
 * the plain problem's answer nearest the first centre: along an eigenvalue
 * lambda of the scaled A^T A the distance shrinks by mu / (lambda + mu) a
 * time, so A x is off by at most sqrt(mu) / 2 times |c - x*| (scaled)
 * after one.  The flow solves a few a step, the first centred at the last
 * step's forces (engine/motion.c): where constraints are many and
 * dependent (thousands of struts on nearly parallel strands), the plain
 * problem's answer is not unique and block pivoting stalls on it.  The
 * report's residual is ||A x - b||. */

/* The minimum-norm solution du (m entries) of the underdetermined system
 * A^T du = r (r has n entries), du = A y with (A^T A + delta D) y = r,
 * D = diag(A^T A), delta = delta_min unless the factorisation needs more
 * (*delta_used gives it).  With delta > 0, du is the damped least-squares
 * (Levenberg-Marquardt) step: it minimises
 * |A^T du - r|^2_{D^-1} + delta |du|^2, so A D^-1 (A^T du - r) + delta du
 * = 0.  Where A^T du = r is inconsistent or nearly so (more constraints
 * than coordinates, many dependent), the minimum-norm answer is long and
 * rounding-dominated and this one is not.  Zero columns of A are left out
 * (their rows of A^T du = r cannot hold unless r is 0 there).  delta_used
 * may be NULL.  Used for error recovery (section 4.6).
 * With a metric M (m x m, symmetric positive definite, both triangles
 * stored; NULL: the identity), the damping term is delta du' M du
 * instead, du = (A D^-1 A^T + delta M)^-1 A D^-1 r, solved in that form
 * (it needs delta_min > 0, which is then used as it is). */
int tk_nnls_min_norm(tk_nnls *s, const cholmod_sparse *A, const double *r, double delta_min,
                     const cholmod_sparse *metric, double *du, double *delta_used,
                     tk_error *err);

#endif
