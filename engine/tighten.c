#include "tk/tighten.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tk/geometry.h"
#include "tk/nnls.h"
#include "tk/rigidity.h"
#include "tk/thickness.h"

/* Step sizes below this fraction of the largest allowed count as no step;
 * this many of them in a row stop the run as stalled. */
#define STALL_FRACTION 1e-12
#define STALL_STEPS 20
/* A step below this fraction of the largest allowed is tried again
 * without the equalising motion. */
#define SHORT_STEP_FRACTION 1e-6
/* Each time the ropelength falls by less than POLISH_CHANGE (relative;
 * shrinking with the tolerances) over POLISH_WINDOW steps, the active
 * tolerance shrinks by POLISH_FACTOR, at most POLISH_LEVELS times. */
#define POLISH_WINDOW 200
#define POLISH_CHANGE 1e-4
#define POLISH_FACTOR (1.0 / 3.0)
#define POLISH_LEVELS 4
/* Coarse to fine: the coarsest polygon has at least this many vertices
 * per unit ropelength, and at most this many halvings are undone. */
#define COARSEST_RESOLUTION 2.5
#define MAX_COARSE_LEVELS 3
#define MAX_HALVINGS 50
/* The largest ropelength a run starts from.  Autoscaled, such a curve's
 * coordinates reach about this many diameters, and rounding then moves
 * them by 1e-16 of that: beyond 1e9 the rounding approaches the
 * tolerances of the step control (1e-5 of the diameter) and error
 * recovery fails.  Curves that thin have (nearly) crossed themselves: a
 * spline through a polygon with a spike loops through the polygon (a
 * 16-gon with one vertex pulled out: ropelength 48, resampled 1e17). */
#define START_ROPELENGTH_MAX 1e9
#define MAX_CORRECTIONS 25
#define MAX_EXPANSIONS 8
#define HALVINGS_BEFORE_EXPANDING 3

struct tk_run {
    tk_options opt;
    double tau;          /* the tube diameter, 2 radius */
    double min_radius;   /* lambda * radius: the bound on minrad */
    tk_curve *curve;
    tk_curve *trial;
    tk_strut_finder *finder;
    tk_nnls *nnls;
    bool *fixed;         /* per vertex: end points of open components */
    double *grad;        /* 3V: gradient of length */
    double *motion;      /* 3V: the motion, then the resolved motion */
    double *work;        /* 3V */
    double *x;           /* compressions, one per constraint */
    double *rhs;         /* one per constraint */
    size_t constraint_capacity;
    tk_strut_list struts;
    /* Kink constraints: one per radius function held at a vertex (equation
     * 3 is the minimum of one function per edge, so a vertex whose edges
     * are about equally long carries two), kink_edge[k] saying which. */
    tk_kink *kinks;
    unsigned char *kink_edge;
    size_t nkinks, kink_capacity;
    tk_kink *kink_report;        /* one per vertex, forces summed */
    size_t nkink_report;
    tk_strut_list known_struts;  /* the last resolution's, sorted, with forces */
    struct known_kink *known_kinks;
    size_t nknown_kinks;
    tk_step_report latest;
    tk_step_report *history;
    size_t nhistory, history_capacity;
    double *snapshots;
    long *snapshot_steps;
    size_t nsnapshots, snapshot_capacity;
    double step_size;
    int tiny_steps;
    bool equalising;     /* this step's motion includes the equalising one */
    int polish_level;    /* times the ropelength has all but stopped falling */
    size_t polish_from;  /* history entries before the last change of level
                            or resampling */
    double resolved_at;  /* ropelength at the last re-resolution */
    double start_ropelength; /* of the input, before any resampling */
    int coarse_level;    /* halvings of the vertex count still to undo */
    int coarse_levels;   /* of them at the start */
    bool refine;         /* undo one at the start of the next step */
    size_t resampled_from; /* history entries before the last resampling */
    double started;
    tk_stop_reason stop;
    atomic_int cancel;
    tk_progress_fn progress;
    void *user;
};

/* A kink constraint's force from the last resolution, for the warm start. */
struct known_kink {
    size_t comp, vertex;
    int edge;
    double force;
};

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char *tk_stop_reason_name(tk_stop_reason r)
{
    switch (r) {
    case TK_STOP_NONE: return "running";
    case TK_STOP_STEPS: return "steps";
    case TK_STOP_TIME: return "time";
    case TK_STOP_RESIDUAL: return "residual";
    case TK_STOP_CHANGE: return "change";
    case TK_STOP_CANCELLED: return "cancelled";
    case TK_STOP_STALLED: return "stalled";
    case TK_STOP_FAILED: return "failed";
    }
    return "unknown";
}

static int check_options(const tk_options *o, tk_error *err)
{
    if (!(o->radius >= TK_CURVE_EDGE_MIN && o->radius <= TK_CURVE_COORD_MAX))
        return tk_error_set(err, TK_EINVAL, "radius must be between %g and %g (got %g)",
                            TK_CURVE_EDGE_MIN, TK_CURVE_COORD_MAX, o->radius);
    if (!(o->lambda > 0.0) || !isfinite(o->lambda))
        return tk_error_set(err, TK_EINVAL, "lambda must be a positive number (got %g)", o->lambda);
    if (!(o->resolution >= 0.0) || o->resolution > 1e4)
        return tk_error_set(err, TK_EINVAL, "resolution must be between 0 and 10000 (got %g)",
                            o->resolution);
    if (o->autoscale && !(o->autoscale_margin >= 1.0 && o->autoscale_margin < 2.0))
        return tk_error_set(err, TK_EINVAL, "autoscale margin must be in [1, 2) (got %g)",
                            o->autoscale_margin);
    if (o->max_steps < 0 || !(o->max_seconds >= 0.0) || !(o->min_residual >= 0.0) ||
        !(o->min_change >= 0.0))
        return tk_error_set(err, TK_EINVAL, "stop criteria must not be negative");
    if (!(o->active_tolerance > 0.0 && o->active_tolerance < 0.5) ||
        !(o->overstep_tolerance > 0.0 && o->overstep_tolerance < 0.1) ||
        !(o->correction_tolerance > 0.0 && o->correction_tolerance < o->overstep_tolerance))
        return tk_error_set(err, TK_EINVAL,
                            "tolerances must satisfy 0 < correction < overstep < 0.1 and "
                            "0 < active < 0.5");
    if (!(o->equalise >= 0.0) || !isfinite(o->equalise))
        return tk_error_set(err, TK_EINVAL, "equalise gain must be >= 0");
    if (!(o->re_resolve >= 0.0 && o->re_resolve < 1.0))
        return tk_error_set(err, TK_EINVAL, "re_resolve must be in [0, 1) (got %g)",
                            o->re_resolve);
    if (o->re_resolve > 0.0 && o->snapshot_every > 0)
        return tk_error_set(err, TK_EINVAL,
                            "re_resolve changes the vertex count, which snapshots keep: "
                            "use one or the other");
    return TK_OK;
}

void tk_run_free(tk_run **p)
{
    if (!p || !*p)
        return;
    tk_run *r = *p;
    tk_curve_free(&r->curve);
    tk_curve_free(&r->trial);
    tk_strut_finder_free(&r->finder);
    tk_nnls_free(&r->nnls);
    free(r->fixed);
    free(r->grad);
    free(r->motion);
    free(r->work);
    free(r->x);
    free(r->rhs);
    tk_strut_list_free(&r->struts);
    free(r->kinks);
    free(r->kink_edge);
    free(r->kink_report);
    tk_strut_list_free(&r->known_struts);
    free(r->known_kinks);
    free(r->history);
    free(r->snapshots);
    free(r->snapshot_steps);
    free(r);
    *p = NULL;
}

/* The thickness of the starting curve, for set-up. */
static int measure(const tk_curve *c, tk_measure *m, tk_error *err)
{
    int rc = tk_thickness_measure(c, NULL, m, err);
    if (rc == TK_OK && !(m->thickness > 0.0 && isfinite(m->thickness)))
        rc = tk_error_set(err, TK_EINVAL,
                          "the curve has no finite thickness (%g): nothing to tighten",
                          m->thickness);
    return rc;
}

/* The resolution of the current coarse level (the option's at the last). */
static double resolution_now(const tk_run *r)
{
    return ldexp(r->opt.resolution, -r->coarse_level);
}

static int prepare_curve(tk_run *r, const tk_curve *start, tk_error *err)
{
    tk_measure m;
    int rc = tk_curve_copy(start, &r->curve, err);
    if (!rc)
        rc = measure(r->curve, &m, err);
    if (rc)
        return rc;
    r->start_ropelength = m.ropelength;
    if (!(m.ropelength <= START_ROPELENGTH_MAX))
        return tk_error_set(err, TK_EINVAL,
                            "the curve is too thin for its length to tighten in double "
                            "precision: ropelength %.6g, above %g (does it nearly cross itself?)",
                            m.ropelength, START_ROPELENGTH_MAX);
    if (r->opt.resolution > 0.0) {
        double want = ceil(r->opt.resolution * m.ropelength);
        if (want > 1e7)
            return tk_error_set(err, TK_ELIMIT,
                                "resolution %g at ropelength %.4g asks for %.0f vertices",
                                r->opt.resolution, m.ropelength, want);
        if (r->opt.coarse_to_fine && r->opt.snapshot_every == 0)
            while (r->coarse_level < MAX_COARSE_LEVELS &&
                   ldexp(r->opt.resolution, -(r->coarse_level + 1)) >= COARSEST_RESOLUTION)
                r->coarse_level++;
        r->coarse_levels = r->coarse_level;
        want = ceil(resolution_now(r) * m.ropelength);
        tk_curve *resampled = NULL;
        rc = tk_curve_resample_total(r->curve, (size_t)want, &resampled, err);
        if (rc)
            return rc;
        tk_curve_free(&r->curve);
        r->curve = resampled;
        rc = measure(r->curve, &m, err);
        if (rc == TK_EINVAL || (rc == TK_OK && !(m.ropelength <= START_ROPELENGTH_MAX)))
            return tk_error_set(err, TK_EINVAL,
                                "resampling to %zu vertices (resolution %g) makes the curve "
                                "(nearly) cross itself (ropelength %.6g, from %.6g): the smooth "
                                "curve through the vertices loops where they turn sharply; "
                                "tighten without a resolution first, or add vertices there",
                                r->curve->nvert, r->opt.resolution, rc ? INFINITY : m.ropelength,
                                r->start_ropelength);
        if (rc)
            return rc;
    }
    if (r->opt.autoscale) {
        double factor = r->opt.autoscale_margin * r->tau / m.thickness;
        tk_curve_scale(r->curve, factor);
        /* A radius far from the curve's own scale can carry it out of the
         * range the engine measures in. */
        tk_error why;
        if (tk_curve_check_range(r->curve, &why))
            return tk_error_set(err, TK_EINVAL,
                                "autoscale to radius %g scales the curve by %g, out of the "
                                "engine's range (%s)",
                                r->opt.radius, factor, why.message);
    } else if (m.thickness < r->tau * (1.0 - r->opt.overstep_tolerance) ||
               2.0 * m.minrad < 2.0 * r->min_radius * (1.0 - r->opt.overstep_tolerance)) {
        return tk_error_set(err, TK_EINVAL,
                            "the curve's thickness %.6g is below the tube diameter %.6g "
                            "(or its curvature too high for lambda %g): use autoscale",
                            m.thickness, r->tau, r->opt.lambda);
    }
    return TK_OK;
}

static int grow_constraints(tk_run *r, size_t n, tk_error *err)
{
    if (n <= r->constraint_capacity)
        return TK_OK;
    size_t cap = r->constraint_capacity ? r->constraint_capacity : 64;
    while (cap < n)
        cap *= 2;
    double *x = realloc(r->x, cap * sizeof *x);
    if (x)
        r->x = x;
    double *rhs = realloc(r->rhs, cap * sizeof *rhs);
    if (rhs)
        r->rhs = rhs;
    if (!x || !rhs)
        return tk_error_set(err, TK_ENOMEM, "out of memory for %zu constraints", n);
    r->constraint_capacity = cap;
    return TK_OK;
}

/* The radius function of one edge at global vertex v of c (equation 3
 * is the smaller of the two). */
static double branch_radius(const tk_curve *c, size_t v, int edge)
{
    size_t prev, next;
    double g[9];
    if (!tk_curve_vertex_neighbours(c, v, &prev, &next))
        return INFINITY;
    return tk_vertex_radius_gradient(tk_curve_vertex(c, prev), tk_curve_vertex(c, v),
                                     tk_curve_vertex(c, next), edge, g);
}

static int push_kink(tk_run *r, size_t comp, size_t vertex, int edge, double radius,
                     tk_error *err)
{
    if (r->nkinks == r->kink_capacity) {
        size_t cap = r->kink_capacity ? 2 * r->kink_capacity : 16;
        tk_kink *grown = realloc(r->kinks, cap * sizeof *grown);
        if (grown)
            r->kinks = grown;
        unsigned char *edges = realloc(r->kink_edge, cap * sizeof *edges);
        if (edges)
            r->kink_edge = edges;
        if (!grown || !edges)
            return tk_error_set(err, TK_ENOMEM, "out of memory for kinks");
        r->kink_capacity = cap;
    }
    r->kinks[r->nkinks] = (tk_kink){comp, vertex, radius, 0.0};
    r->kink_edge[r->nkinks] = (unsigned char)edge;
    r->nkinks++;
    return TK_OK;
}

static bool has_kink(const tk_run *r, size_t comp, size_t vertex, int edge)
{
    for (size_t i = 0; i < r->nkinks; i++)
        if (r->kinks[i].comp == comp && r->kinks[i].vertex == vertex && r->kink_edge[i] == edge)
            return true;
    return false;
}

/* The tolerances of this step: the options' while the ropelength falls,
 * each a third smaller every time it all but stops (polishing).  A
 * constraint within the active tolerance holds the motion as if it were
 * in contact: with a slack of up to 3e-4 of the diameter such constraints
 * kept runs settling about 1e-4 (relative) above their critical points
 * (3.1 at resolution 5: 32.7719 at 3e-4, 32.7694 at 1e-4, 32.7689 at
 * 1e-5), while a tolerance that small from the start makes the loose
 * phase slower (contacts are met mid-step and found by the step control
 * instead).  The overstep tolerance stays below the active one (a step's
 * violations must be seen as active next time), the correction tolerance
 * a tenth of that.  Shrinking them costs step length (steps along curved
 * constraints grow as the square root of the overstep tolerance), so each
 * level waits until the ropelength falls by less than the offset the
 * current one leaves (about a third of its active tolerance, relative):
 * a run that merely crawls (past a saddle) keeps its step sizes. */
static double polish_scale(const tk_run *r)
{
    return pow(POLISH_FACTOR, r->polish_level);
}

static double active_tolerance(const tk_run *r)
{
    return r->opt.active_tolerance * polish_scale(r);
}

static double overstep_tolerance(const tk_run *r)
{
    return fmin(r->opt.overstep_tolerance, active_tolerance(r));
}

static double correction_tolerance(const tk_run *r)
{
    return fmin(r->opt.correction_tolerance, 0.1 * overstep_tolerance(r));
}

/* Active constraints of the run's curve (the finder must be fitted to it).
 * Struts are every admissible edge pair within the active tolerance, not
 * only the doubly critical ones (tk_strut_finder_find_pairs).  Equation
 * (4) asks d(e_i, e_j) >= tau of every admissible pair; where a contact
 * lies on nearly parallel edges the pair next to it, whose closest point
 * is the vertex towards the contact, is about as close, and a motion that
 * keeps the contact's own pair to first order can bring that one closer
 * at first order: the contact slides onto it (section 2.3's parallel
 * case, which the paper left out as rare; in tight knots it is common).
 * Without it the step control held such runs to steps of 1e-4.
 * At a kink each edge's radius function within the active tolerance is a
 * constraint of its own.  Holding only the smaller one (equation 3's min)
 * is not enough: the equalising motion keeps the two edges equally long,
 * the resolved motion then keeps the one function to first order while
 * the other falls at first order, and the step control must shrink the
 * step in proportion to the tolerance. */
static int find_active(tk_run *r, const tk_curve *c, tk_error *err)
{
    tk_strut_list_clear(&r->struts);
    r->nkinks = 0;
    double slack = 1.0 + active_tolerance(r);
    int rc = tk_strut_finder_find_pairs(r->finder, c, TK_ARC_ADMISSIBLE, r->tau,
                                        r->tau * slack, &r->struts, err);
    tk_kink *found = NULL;
    size_t nfound = 0;
    if (!rc)
        rc = tk_kinks_find(c, 2.0 * r->min_radius * slack, &found, &nfound, err);
    for (size_t k = 0; !rc && k < nfound; k++) {
        size_t v = tk_curve_vertex_index(c, found[k].comp, found[k].vertex);
        for (int edge = 0; edge < 2 && !rc; edge++) {
            double radius = branch_radius(c, v, edge);
            if (radius <= r->min_radius * slack)
                rc = push_kink(r, found[k].comp, found[k].vertex, edge, radius, err);
        }
    }
    free(found);
    if (!rc)
        rc = grow_constraints(r, r->struts.count + r->nkinks, err);
    return rc;
}

static int compare_kink_vertices(const void *pa, const void *pb)
{
    const tk_kink *a = pa, *b = pb;
    if (a->comp != b->comp)
        return a->comp < b->comp ? -1 : 1;
    return a->vertex < b->vertex ? -1 : (a->vertex > b->vertex ? 1 : 0);
}

/* The kinks as reported: one per vertex, with its radius (equation 3) and
 * the sum of its constraints' forces. */
static int report_kinks(tk_run *r, tk_error *err)
{
    free(r->kink_report);
    r->kink_report = NULL;
    r->nkink_report = 0;
    if (!r->nkinks)
        return TK_OK;
    tk_kink *out = malloc(r->nkinks * sizeof *out);
    if (!out)
        return tk_error_set(err, TK_ENOMEM, "out of memory for kinks");
    memcpy(out, r->kinks, r->nkinks * sizeof *out);
    qsort(out, r->nkinks, sizeof *out, compare_kink_vertices);
    size_t n = 0;
    for (size_t k = 0; k < r->nkinks; k++) {
        if (n > 0 && compare_kink_vertices(&out[n - 1], &out[k]) == 0) {
            out[n - 1].force += out[k].force;
            continue;
        }
        out[n] = out[k];
        size_t v = tk_curve_vertex_index(r->curve, out[n].comp, out[n].vertex);
        out[n].minrad = fmin(branch_radius(r->curve, v, 0), branch_radius(r->curve, v, 1));
        n++;
    }
    r->kink_report = out;
    r->nkink_report = n;
    return TK_OK;
}

/* The rigidity matrix of the active constraints, with the rows of fixed
 * vertices zeroed: those coordinates are not variables. */
static int build_matrix(tk_run *r, const tk_curve *c, cholmod_sparse **a, tk_error *err)
{
    int rc = tk_rigidity_build_branches(c, r->struts.items, r->struts.count, r->kinks,
                                        r->kink_edge, r->nkinks, tk_nnls_common(r->nnls), a,
                                        err);
    if (rc)
        return rc;
    const int *colp = (*a)->p, *row = (*a)->i;
    double *val = (*a)->x;
    for (int k = 0; k < colp[(*a)->ncol]; k++)
        if (r->fixed[row[k] / 3])
            val[k] = 0.0;
    return TK_OK;
}

static void free_matrix(tk_run *r, cholmod_sparse **a)
{
    if (*a)
        cholmod_free_sparse(a, tk_nnls_common(r->nnls));
}

/* out = A x (3V entries). */
static void multiply(const cholmod_sparse *a, const double *x, double *out, size_t rows)
{
    memset(out, 0, rows * sizeof *out);
    const int *colp = a->p, *row = a->i;
    const double *val = a->x;
    for (size_t j = 0; j < a->ncol; j++)
        for (int k = colp[j]; k < colp[j + 1]; k++)
            out[row[k]] += val[k] * x[j];
}

static double norm(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
}

/* Section 4.2: a velocity along each vertex's tangent proportional to how
 * far the vertex is from its share of the component's length, so that the
 * edges even out.  Scaled to the mean size of the length gradient so the
 * two motions keep their proportion as the curve tightens. */
static void add_equalising_motion(tk_run *r, const tk_curve *c, double *u)
{
    size_t nv = c->nvert;
    double mean_grad = 0.0;
    for (size_t v = 0; v < nv; v++)
        mean_grad += norm(r->grad + 3 * v, 3);
    mean_grad /= (double)(nv ? nv : 1);
    if (!(r->opt.equalise > 0.0) || !(mean_grad > 0.0))
        return;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp), ne = tk_curve_comp_edges(c, comp);
        double total = tk_curve_comp_length(c, comp), mean_edge = total / (double)ne;
        double *offset = r->work; /* n entries suffice: 3V >= n */
        double arc = 0.0, shift = 0.0;
        for (size_t k = 0; k < n; k++) {
            offset[k] = total * (double)k / (double)ne - arc;
            shift += offset[k];
            if (k < ne)
                arc += tk_curve_edge_length(c, comp, k);
        }
        /* A closed component's vertices may all slide together: only their
         * spacing matters. */
        shift = c->closed[comp] ? shift / (double)n : 0.0;
        for (size_t k = 0; k < n; k++) {
            size_t v = c->offset[comp] + k;
            if (r->fixed[v] || (!c->closed[comp] && (k == 0 || k + 1 == n)))
                continue;
            size_t before = c->closed[comp] ? (k + n - 1) % n : k - 1;
            const double *prev = tk_curve_vertex(c, c->offset[comp] + before);
            const double *next = tk_curve_vertex(c, tk_curve_vertex_index(c, comp, k + 1));
            double t[3] = {next[0] - prev[0], next[1] - prev[1], next[2] - prev[2]};
            double tn = norm(t, 3);
            if (!(tn > 0.0))
                continue;
            double speed = r->opt.equalise * mean_grad * (offset[k] - shift) / mean_edge;
            for (int j = 0; j < 3; j++)
                u[3 * v + j] += speed * t[j] / tn;
        }
    }
}

/* Worst violation of the constraints by curve c, as a fraction of the
 * bound: (tau - closest admissible pair) / tau and
 * (lambda r - minrad) / (lambda r).  0 when all hold.  The finder must be
 * fitted to c. */
static int violation(tk_run *r, const tk_curve *c, double *out, tk_error *err)
{
    double closest;
    int rc = tk_strut_finder_closest_pair(r->finder, c, TK_ARC_ADMISSIBLE, r->tau, r->tau,
                                          &closest, err);
    if (rc)
        return rc;
    double minrad = tk_curve_minrad(c, NULL);
    double v = fmax((r->tau - closest) / r->tau, (r->min_radius - minrad) / r->min_radius);
    *out = fmax(v, 0.0);
    return TK_OK;
}

/* Scales the run's curve about its centroid, which raises every distance
 * and radius in proportion, just enough to undo a violation of `worst`
 * (a fraction of the bound), and fits the finder to it. */
static void scale_to_feasible(tk_run *r, double worst)
{
    double centre[3], back[3];
    tk_curve_centroid(r->curve, centre);
    for (int k = 0; k < 3; k++) {
        back[k] = centre[k];
        centre[k] = -centre[k];
    }
    tk_curve_translate(r->curve, centre);
    tk_curve_scale(r->curve, (1.0 + 0.5 * correction_tolerance(r)) / (1.0 - worst));
    tk_curve_translate(r->curve, back);
    tk_strut_finder_refit(r->finder, r->curve);
}

/* Section 4.6: Newton steps du solving A_V^T du = -R with minimum norm,
 * R the violations of the violated constraints V among the active ones,
 * until every violation is below the correction tolerance.  Each step is damped until the worst violation falls (near-
 * dependent constraints can make the regularised solution long); rescaling
 * about the centroid is the last resort, for small leftovers only.  On
 * return the finder is fitted to the curve. */
static int correct_violations(tk_run *r, int *iterations, tk_error *err)
{
    tk_curve *c = r->curve, *t = r->trial;
    size_t n3 = 3 * c->nvert;
    int rc = TK_OK;
    *iterations = 0;
    tk_strut_finder_refit(r->finder, c);
    double worst;
    rc = violation(r, c, &worst, err);
    for (int it = 0; !rc && worst > correction_tolerance(r) && it < MAX_CORRECTIONS; it++) {
        rc = find_active(r, c, err);
        if (rc)
            return rc;
        size_t ns = r->struts.count, ncon = ns + r->nkinks;
        if (ncon == 0)
            break;
        /* Only the violated constraints, each aimed a little inside the
         * feasible set so rounding does not leave it just violated.  Asking
         * the others to stay put (R = 0) makes the system inconsistent
         * wherever two constraints have (nearly) the same gradient and only
         * one is violated (the two edges at a vertex contact, the two
         * radius functions at a kink): its minimum-norm answer is then
         * long and useless.  Those that become violated join next time. */
        double aim = 0.5 * correction_tolerance(r);
        size_t nv = 0, nb = 0;
        for (size_t j = 0; j < ns; j++) {
            double deficit = r->tau * (1.0 + aim) - r->struts.items[j].length;
            if (deficit > 0.0) {
                r->struts.items[nv] = r->struts.items[j];
                r->rhs[nv++] = deficit;
            }
        }
        for (size_t k = 0; k < r->nkinks; k++) {
            double deficit = r->min_radius * (1.0 + aim) - r->kinks[k].minrad;
            if (deficit > 0.0) {
                r->kinks[nb] = r->kinks[k];
                r->kink_edge[nb] = r->kink_edge[k];
                r->rhs[nv + nb++] = deficit;
            }
        }
        r->struts.count = nv;
        r->nkinks = nb;
        if (nv + nb == 0)
            break;
        cholmod_sparse *a = NULL;
        rc = build_matrix(r, c, &a, err);
        if (rc)
            return rc;
        double delta = 0.0;
        rc = tk_nnls_min_norm(r->nnls, a, r->rhs, r->motion, &delta, err);
        free_matrix(r, &a);
        if (rc)
            return rc;
        /* Never move a vertex by more than a tenth of the diameter. */
        double longest = 0.0;
        for (size_t v = 0; v < c->nvert; v++)
            longest = fmax(longest, norm(r->motion + 3 * v, 3));
        double alpha = longest > 0.1 * r->tau ? 0.1 * r->tau / longest : 1.0;
        bool improved = false;
        for (int halving = 0; halving < 12 && !improved; halving++, alpha *= 0.5) {
            for (size_t i = 0; i < n3; i++)
                t->xyz[i] = c->xyz[i] + alpha * r->motion[i];
            tk_strut_finder_refit(r->finder, t);
            double trial_worst;
            rc = violation(r, t, &trial_worst, err);
            if (rc)
                return rc;
            if (trial_worst < worst) {
                memcpy(c->xyz, t->xyz, n3 * sizeof *c->xyz);
                worst = trial_worst;
                improved = true;
            }
        }
        tk_strut_finder_refit(r->finder, c);
        (*iterations)++;
        if (!improved)
            break;
    }
    if (rc || worst <= correction_tolerance(r))
        return rc;
    if (worst > 10.0 * r->opt.overstep_tolerance)
        return tk_error_set(err, TK_ENUMERIC,
                            "could not restore the thickness: constraints violated by %.3g of "
                            "the diameter after %d corrections",
                            worst, *iterations);
    scale_to_feasible(r, worst);
    return TK_OK;
}

/* Error recovery (correct_violations) cuts the active sets down to the
 * violated constraints.  The step's own set, with the forces its NNLS
 * gave, is what the step reports, so it is kept aside and put back rather
 * than searched for again: the next step searches anyway. */
static int correct(tk_run *r, int *iterations, tk_error *err)
{
    size_t ns = r->struts.count, nk = r->nkinks;
    tk_strut *struts = ns ? malloc(ns * sizeof *struts) : NULL;
    tk_kink *kinks = nk ? malloc(nk * sizeof *kinks) : NULL;
    unsigned char *edges = nk ? malloc(nk * sizeof *edges) : NULL;
    if ((ns && !struts) || (nk && (!kinks || !edges))) {
        free(struts);
        free(kinks);
        free(edges);
        return tk_error_set(err, TK_ENOMEM, "out of memory for error recovery");
    }
    if (ns)
        memcpy(struts, r->struts.items, ns * sizeof *struts);
    if (nk) {
        memcpy(kinks, r->kinks, nk * sizeof *kinks);
        memcpy(edges, r->kink_edge, nk * sizeof *edges);
    }
    int rc = correct_violations(r, iterations, err);
    /* the lists only ever grow, so the saved sets fit where they were */
    if (ns)
        memcpy(r->struts.items, struts, ns * sizeof *struts);
    r->struts.count = ns;
    if (nk) {
        memcpy(r->kinks, kinks, nk * sizeof *kinks);
        memcpy(r->kink_edge, edges, nk * sizeof *edges);
    }
    r->nkinks = nk;
    free(struts);
    free(kinks);
    free(edges);
    return rc;
}

static int record(tk_run *r, tk_step_report *rep, tk_error *err)
{
    tk_measure m;
    int rc = tk_thickness_measure(r->curve, r->finder, &m, err);
    if (rc)
        return rc;
    rep->length = m.length;
    rep->thickness = m.thickness;
    rep->minrad = m.minrad;
    rep->ropelength = m.ropelength;
    rep->vertices = r->curve->nvert;
    rep->seconds = now_seconds() - r->started;
    if (r->nhistory == r->history_capacity) {
        size_t cap = r->history_capacity ? 2 * r->history_capacity : 256;
        tk_step_report *grown = realloc(r->history, cap * sizeof *grown);
        if (!grown)
            return tk_error_set(err, TK_ENOMEM, "out of memory for the history");
        r->history = grown;
        r->history_capacity = cap;
    }
    r->history[r->nhistory++] = *rep;
    r->latest = *rep;
    if (r->opt.snapshot_every > 0 && rep->step % (long)r->opt.snapshot_every == 0) {
        size_t nv3 = 3 * r->curve->nvert;
        if (r->nsnapshots == r->snapshot_capacity) {
            size_t cap = r->snapshot_capacity ? 2 * r->snapshot_capacity : 16;
            double *grown = realloc(r->snapshots, cap * nv3 * sizeof *grown);
            if (grown)
                r->snapshots = grown;
            long *steps = realloc(r->snapshot_steps, cap * sizeof *steps);
            if (steps)
                r->snapshot_steps = steps;
            if (!grown || !steps)
                return tk_error_set(err, TK_ENOMEM, "out of memory for snapshots");
            r->snapshot_capacity = cap;
        }
        memcpy(r->snapshots + r->nsnapshots * nv3, r->curve->xyz, nv3 * sizeof(double));
        r->snapshot_steps[r->nsnapshots++] = rep->step;
    }
    return TK_OK;
}

/* Everything sized by the curve's vertices: the trial curve, the strut
 * tree and the work vectors; the warm start is dropped (its edge indices
 * refer to the old curve). */
static int fit_to_curve(tk_run *r, tk_error *err)
{
    tk_curve_free(&r->trial);
    tk_strut_finder_free(&r->finder);
    int rc = tk_curve_copy(r->curve, &r->trial, err);
    if (!rc)
        rc = tk_strut_finder_new(r->curve, &r->finder, err);
    if (rc)
        return rc;
    size_t nv = r->curve->nvert;
    free(r->fixed);
    free(r->grad);
    free(r->motion);
    free(r->work);
    r->fixed = calloc(nv, sizeof *r->fixed);
    r->grad = calloc(3 * nv, sizeof *r->grad);
    r->motion = calloc(3 * nv, sizeof *r->motion);
    r->work = calloc(3 * nv, sizeof *r->work);
    if (!r->fixed || !r->grad || !r->motion || !r->work)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a run of %zu vertices", nv);
    for (size_t comp = 0; comp < r->curve->ncomp; comp++)
        if (!r->curve->closed[comp]) {
            r->fixed[r->curve->offset[comp]] = true;
            r->fixed[r->curve->offset[comp + 1] - 1] = true;
        }
    tk_strut_list_clear(&r->known_struts);
    r->nknown_kinks = 0;
    tk_strut_list_clear(&r->struts);
    r->nkinks = 0;
    return TK_OK;
}

/* Resamples the run's curve to `count` vertices along its spline and
 * scales it about its centroid just enough to be feasible again. */
static int resample_to(tk_run *r, size_t count, tk_error *err)
{
    tk_curve *resampled = NULL;
    int rc = tk_curve_resample_total(r->curve, count, &resampled, err);
    if (rc)
        return rc;
    tk_curve_free(&r->curve);
    r->curve = resampled;
    r->resolved_at = r->latest.ropelength;
    /* a new polygon, further from its critical point: polishing starts
     * again from its own history */
    r->polish_level = 0;
    r->polish_from = r->nhistory;
    r->resampled_from = r->nhistory;
    rc = fit_to_curve(r, err);
    double worst = 0.0;
    if (!rc)
        rc = violation(r, r->curve, &worst, err);
    if (rc)
        return rc;
    if (worst > 0.0)
        scale_to_feasible(r, worst);
    r->step_size = 0.0;
    r->tiny_steps = 0;
    return TK_OK;
}

/* Coarse to fine: a coarse polygon has fewer, longer edges, so each step
 * is cheaper and the kink constraints far less stiff (their relative
 * curvature grows like 1 / (theta l)^2); it gets to the neighbourhood of
 * the tight shape many times faster, past saddles the fine polygon crawls
 * by (6.3.2 at resolution 2.5: below 58.6 after 34 s; at 5, 67.7 after
 * 300 s).  Once it has all but stopped tightening, the vertices are
 * doubled and the finer polygon starts from there. */
static int refine(tk_run *r, tk_error *err)
{
    r->refine = false;
    r->coarse_level--;
    double rope = r->opt.re_resolve > 0.0 ? r->latest.ropelength : r->start_ropelength;
    return resample_to(r, (size_t)ceil(resolution_now(r) * rope), err);
}

/* Re-resolution during the run: the start was resampled to `resolution`
 * vertices per unit of ropelength, and as the knot tightens that count
 * grows finer than asked for.  Finer than needed costs twice: every step
 * solves for more constraints, and the step the flow can take (explicit
 * Euler on the length gradient, whose stiffness grows as the edges
 * shorten, and the overstep control at kinks) shrinks with the edges.
 * When the ropelength has fallen by the re_resolve fraction since the
 * last resampling and the count is that much too fine, the curve is
 * resampled along its spline to ceil(resolution * ropelength) vertices
 * and scaled about its centroid just enough to be feasible again (costing
 * as much length, relatively, as the resampling cost thickness). */
static int maybe_re_resolve(tk_run *r, tk_error *err)
{
    const tk_options *o = &r->opt;
    double rope = r->latest.ropelength;
    if (r->refine && r->coarse_level > 0)
        return refine(r, err);
    if (!(o->re_resolve > 0.0) || !(o->resolution > 0.0) || !isfinite(rope))
        return TK_OK;
    if (!isfinite(r->resolved_at)) {
        r->resolved_at = rope;
        return TK_OK;
    }
    double want = ceil(resolution_now(r) * rope);
    if (!(rope < r->resolved_at * (1.0 - o->re_resolve)) ||
        !(want < (double)r->curve->nvert * (1.0 - o->re_resolve)))
        return TK_OK;
    return resample_to(r, (size_t)want, err);
}

int tk_run_new(const tk_curve *start, const tk_options *opts, tk_run **out, tk_error *err)
{
    *out = NULL;
    tk_options defaults = TK_OPTIONS_INIT;
    if (!opts)
        opts = &defaults;
    int rc = check_options(opts, err);
    if (rc)
        return rc;
    tk_run *r = calloc(1, sizeof *r);
    if (!r)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    r->opt = *opts;
    r->tau = 2.0 * opts->radius;
    r->min_radius = opts->lambda * opts->radius;
    atomic_init(&r->cancel, 0);
    r->started = now_seconds();
    rc = prepare_curve(r, start, err);
    if (!rc)
        rc = tk_nnls_new(&r->nnls, err);
    if (!rc)
        rc = fit_to_curve(r, err);
    if (rc) {
        tk_run_free(&r);
        return rc;
    }
    r->resolved_at = INFINITY;
    int corrections = 0;
    rc = correct(r, &corrections, err);
    if (!rc)
        rc = find_active(r, r->curve, err);
    tk_step_report rep = {0};
    rep.rcond = 1.0;
    rep.residual = NAN;
    rep.corrections = corrections;
    rep.struts = r->struts.count;
    if (!rc)
        rc = report_kinks(r, err);
    rep.kinks = r->nkink_report;
    if (!rc)
        rc = violation(r, r->curve, &rep.violation, err);
    if (!rc)
        rc = record(r, &rep, err);
    if (rc) {
        tk_run_free(&r);
        return rc;
    }
    *out = r;
    return TK_OK;
}

void tk_run_set_progress(tk_run *r, tk_progress_fn fn, void *user)
{
    r->progress = fn;
    r->user = user;
}

void tk_run_cancel(tk_run *r)
{
    atomic_store(&r->cancel, 1);
}

static int compare_known_kinks(const void *pa, const void *pb)
{
    const struct known_kink *a = pa, *b = pb;
    if (a->comp != b->comp)
        return a->comp < b->comp ? -1 : 1;
    if (a->vertex != b->vertex)
        return a->vertex < b->vertex ? -1 : 1;
    return a->edge < b->edge ? -1 : (a->edge > b->edge ? 1 : 0);
}

/* The forces of the last resolution as the NNLS's starting guess: contacts
 * change little from one step to the next, so the passive set does too. */
static void guess_forces(const tk_run *r)
{
    size_t ns = r->struts.count;
    for (size_t j = 0; j < ns; j++) {
        const tk_strut *hit =
            r->known_struts.count
                ? bsearch(&r->struts.items[j], r->known_struts.items, r->known_struts.count,
                          sizeof *hit, tk_strut_compare_edges)
                : NULL;
        r->x[j] = hit ? hit->force : 0.0;
    }
    for (size_t k = 0; k < r->nkinks; k++) {
        struct known_kink key = {r->kinks[k].comp, r->kinks[k].vertex, r->kink_edge[k], 0.0};
        const struct known_kink *hit =
            r->nknown_kinks ? bsearch(&key, r->known_kinks, r->nknown_kinks, sizeof *hit,
                                      compare_known_kinks)
                            : NULL;
        r->x[ns + k] = hit ? hit->force : 0.0;
    }
}

static int remember_forces(tk_run *r, tk_error *err)
{
    tk_strut_list *known = &r->known_struts;
    tk_strut_list_clear(known);
    if (known->capacity < r->struts.count) {
        tk_strut *grown = realloc(known->items, r->struts.count * sizeof *grown);
        if (!grown)
            return tk_error_set(err, TK_ENOMEM, "out of memory for struts");
        known->items = grown;
        known->capacity = r->struts.count;
    }
    known->count = r->struts.count;
    if (known->count) {
        memcpy(known->items, r->struts.items, known->count * sizeof *known->items);
        qsort(known->items, known->count, sizeof *known->items, tk_strut_compare_edges);
    }
    free(r->known_kinks);
    r->known_kinks = NULL;
    r->nknown_kinks = 0;
    if (r->nkinks) {
        r->known_kinks = malloc(r->nkinks * sizeof *r->known_kinks);
        if (!r->known_kinks)
            return tk_error_set(err, TK_ENOMEM, "out of memory for kinks");
        for (size_t k = 0; k < r->nkinks; k++)
            r->known_kinks[k] = (struct known_kink){r->kinks[k].comp, r->kinks[k].vertex,
                                                    r->kink_edge[k], r->kinks[k].force};
        r->nknown_kinks = r->nkinks;
        qsort(r->known_kinks, r->nknown_kinks, sizeof *r->known_kinks, compare_known_kinks);
    }
    return TK_OK;
}

/* Resolves the motion against the active constraints (equation 13):
 * motion = u + A x with x >= 0 minimising |A x + u|; with `equalise`, u
 * includes the edge-equalising motion. */
static int resolve_motion(tk_run *r, tk_step_report *rep, bool equalise, tk_error *err)
{
    tk_curve *c = r->curve;
    size_t n3 = 3 * c->nvert;
    tk_curve_length_gradient(c, r->grad);
    for (size_t v = 0; v < c->nvert; v++)
        if (r->fixed[v])
            r->grad[3 * v] = r->grad[3 * v + 1] = r->grad[3 * v + 2] = 0.0;
    for (size_t i = 0; i < n3; i++)
        r->motion[i] = -r->grad[i];
    if (equalise)
        add_equalising_motion(r, c, r->motion);
    size_t ns = r->struts.count, ncon = ns + r->nkinks;
    double grad_norm = norm(r->grad, n3);
    rep->rcond = 1.0;
    if (ncon == 0) {
        rep->residual = grad_norm > 0.0 ? 1.0 : 0.0;
        return TK_OK;
    }
    cholmod_sparse *a = NULL;
    int rc = build_matrix(r, c, &a, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n3; i++)
        r->work[i] = -r->motion[i];
    tk_nnls_report nr;
    tk_nnls_options nopt = TK_NNLS_OPTIONS_INIT;
    nopt.warm_start = true;
    guess_forces(r);
    rc = tk_nnls_solve(r->nnls, a, r->work, r->x, &nopt, &nr, err);
    if (rc) {
        free_matrix(r, &a);
        return rc;
    }
    rep->rcond = nr.rcond;
    multiply(a, r->x, r->work, n3);
    free_matrix(r, &a);
    for (size_t i = 0; i < n3; i++)
        r->motion[i] += r->work[i];
    /* The residual of the length gradient alone, with the same forces. */
    double s = 0.0;
    for (size_t i = 0; i < n3; i++) {
        double d = -r->grad[i] + r->work[i];
        s += d * d;
    }
    rep->residual = grad_norm > 0.0 ? sqrt(s) / grad_norm : 0.0;
    for (size_t j = 0; j < ns; j++)
        r->struts.items[j].force = r->x[j];
    for (size_t k = 0; k < r->nkinks; k++)
        r->kinks[k].force = r->x[ns + k];
    return remember_forces(r, err);
}

static int resolve(tk_run *r, tk_step_report *rep, tk_error *err)
{
    return resolve_motion(r, rep, r->equalising, err);
}

/* Whether the motion shortens the curve at first order.  The resolved
 * motion of the length gradient alone always does, unless it is 0: by the
 * NNLS optimality conditions (A x) . motion = 0, so grad . motion =
 * -|motion|^2.  With the equalising motion added it may not (see
 * tk_run_step), and then no short step can pass the length test. */
static bool descends(const tk_run *r)
{
    double slope = 0.0;
    for (size_t i = 0; i < 3 * r->curve->nvert; i++)
        slope += r->grad[i] * r->motion[i];
    return slope < 0.0;
}

static bool has_strut(const tk_strut_list *list, const tk_strut *s)
{
    for (size_t j = 0; j < list->count; j++) {
        const tk_strut *o = &list->items[j];
        if (o->comp[0] == s->comp[0] && o->edge[0] == s->edge[0] && o->comp[1] == s->comp[1] &&
            o->edge[1] == s->edge[1])
            return true;
    }
    return false;
}

/* A step tried to `trial` broke constraints that were not active: add them
 * (with their values at the current curve) so the next resolution keeps
 * them to first order.  These are the contacts that become active mid-step
 * (section 4.5): found again with the tree at the trial point.  The finder
 * must be fitted to `trial`.  *added counts the new constraints. */
static int expand_active(tk_run *r, const tk_curve *trial, size_t *added, tk_error *err)
{
    const tk_curve *c = r->curve;
    *added = 0;
    double floor = 1.0 - overstep_tolerance(r);
    tk_strut_list broken = {0};
    int rc = tk_strut_finder_find(r->finder, trial, TK_ARC_ADMISSIBLE, r->tau, r->tau * floor,
                                  &broken, err);
    for (size_t j = 0; !rc && j < broken.count; j++) {
        tk_strut s = broken.items[j];
        if (has_strut(&r->struts, &s))
            continue;
        tk_closest cl;
        tk_segment_closest(tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[0], s.edge[0])),
                           tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[0], s.edge[0] + 1)),
                           tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[1], s.edge[1])),
                           tk_curve_vertex(c, tk_curve_vertex_index(c, s.comp[1], s.edge[1] + 1)),
                           &cl);
        s.s = cl.s;
        s.t = cl.t;
        memcpy(s.p, cl.p, sizeof s.p);
        memcpy(s.q, cl.q, sizeof s.q);
        s.length = cl.dist;
        s.force = 0.0;
        if (r->struts.count == r->struts.capacity) {
            size_t cap = r->struts.capacity ? 2 * r->struts.capacity : 64;
            tk_strut *grown = realloc(r->struts.items, cap * sizeof *grown);
            if (!grown) {
                rc = tk_error_set(err, TK_ENOMEM, "out of memory for struts");
                break;
            }
            r->struts.items = grown;
            r->struts.capacity = cap;
        }
        r->struts.items[r->struts.count++] = s;
        (*added)++;
    }
    tk_strut_list_free(&broken);
    tk_kink *bent = NULL;
    size_t nbent = 0;
    if (!rc)
        rc = tk_kinks_find(trial, 2.0 * r->min_radius * floor, &bent, &nbent, err);
    for (size_t k = 0; !rc && k < nbent; k++) {
        size_t v = tk_curve_vertex_index(c, bent[k].comp, bent[k].vertex);
        for (int edge = 0; edge < 2 && !rc; edge++) {
            if (branch_radius(trial, v, edge) > r->min_radius * floor ||
                has_kink(r, bent[k].comp, bent[k].vertex, edge))
                continue;
            rc = push_kink(r, bent[k].comp, bent[k].vertex, edge, branch_radius(c, v, edge), err);
            if (!rc)
                (*added)++;
        }
    }
    free(bent);
    if (!rc)
        rc = grow_constraints(r, r->struts.count + r->nkinks, err);
    return rc;
}

/* No vertex may move more than a tenth of the diameter or a quarter of
 * the shortest edge in one step, so no strand can pass through another
 * between two checks and no edge folds over: the largest step size for the
 * current motion (0 when nothing moves). */
static double largest_step(const tk_run *r)
{
    const tk_curve *c = r->curve;
    double fastest = 0.0;
    for (size_t v = 0; v < c->nvert; v++)
        fastest = fmax(fastest, norm(r->motion + 3 * v, 3));
    if (!(fastest > 0.0))
        return 0.0;
    double shortest_edge;
    tk_curve_edge_range(c, &shortest_edge, NULL);
    return fmin(0.1 * r->tau, 0.25 * shortest_edge) / fastest;
}

/* Section 4.5: the largest step, halving from twice the last one, whose
 * end point violates no constraint by more than the overstep tolerance.
 * rep->step_size is the step taken (0 if none was acceptable), *allowed
 * the largest step the motion allowed. */
static int take_step(tk_run *r, tk_step_report *rep, double *allowed, tk_error *err)
{
    tk_curve *c = r->curve, *t = r->trial;
    size_t n3 = 3 * c->nvert;
    double largest = largest_step(r);
    *allowed = largest;
    if (!(largest > 0.0) || !descends(r)) {
        rep->step_size = 0.0;
        r->step_size = 0.0;
        return TK_OK;
    }
    double h = r->step_size > 0.0 ? fmin(2.0 * r->step_size, largest) : largest / 8.0;
    double length_before = tk_curve_length(c);
    int expansions = 0;
    for (int halving = 0; halving < MAX_HALVINGS; halving++, h *= 0.5) {
        for (size_t i = 0; i < n3; i++)
            t->xyz[i] = c->xyz[i] + h * r->motion[i];
        tk_strut_finder_refit(r->finder, t);
        double worst;
        int rc = violation(r, t, &worst, err);
        if (rc)
            return rc;
        if (worst > overstep_tolerance(r) && expansions < MAX_EXPANSIONS &&
            halving >= HALVINGS_BEFORE_EXPANDING) {
            /* Constraints the step keeps running into: make them active,
             * resolve again and retry the same step size.  Not at the first
             * failure: a shorter step is cheaper than a new resolution, and
             * usually enough. */
            size_t added = 0;
            rc = expand_active(r, t, &added, err);
            if (rc)
                return rc;
            if (added > 0) {
                expansions++;
                tk_strut_finder_refit(r->finder, c);
                rc = resolve(r, rep, err);
                if (rc)
                    return rc;
                largest = largest_step(r);
                *allowed = largest;
                if (!descends(r))
                    break;
                h = 2.0 * fmin(h, largest); /* undo this iteration's halving */
                continue;
            }
        }
        /* The resolved motion shortens the curve to first order; a step
         * that makes it longer went too far along a curved constraint. */
        if (worst <= overstep_tolerance(r) && tk_curve_length(t) < length_before) {
            memcpy(c->xyz, t->xyz, n3 * sizeof *c->xyz);
            r->step_size = h;
            rep->step_size = h;
            return TK_OK;
        }
    }
    tk_strut_finder_refit(r->finder, c);
    rep->step_size = 0.0;
    r->step_size = 0.0;
    return TK_OK;
}

static void check_stop(tk_run *r)
{
    const tk_options *o = &r->opt;
    const tk_step_report *s = &r->latest;
    if (atomic_load(&r->cancel))
        r->stop = TK_STOP_CANCELLED;
    else if (o->max_steps > 0 && s->step >= o->max_steps)
        r->stop = TK_STOP_STEPS;
    else if (o->max_seconds > 0.0 && s->seconds >= o->max_seconds)
        r->stop = TK_STOP_TIME;
    else if (r->coarse_level > 0)
        ; /* convergence is judged on the final polygon only */
    else if (o->min_residual > 0.0 && s->residual < o->min_residual)
        r->stop = TK_STOP_RESIDUAL;
    else if (o->min_change > 0.0 && o->change_window > 0 &&
             r->nhistory > r->resampled_from + o->change_window) {
        /* within one polygon: a resampled one starts a little longer */
        double before = r->history[r->nhistory - 1 - o->change_window].ropelength;
        if ((before - s->ropelength) / s->ropelength < o->min_change)
            r->stop = TK_STOP_CHANGE;
    }
    if (r->stop == TK_STOP_NONE && r->tiny_steps >= STALL_STEPS) {
        if (r->coarse_level > 0)
            r->refine = true;
        else
            r->stop = TK_STOP_STALLED;
    }
    /* A run with a budget of steps or time spends its last share of it on
     * the final polygon even when a coarse one is still tightening: each
     * level's share is an equal part of the budget.  A budget too small
     * for that (a step or two) is overrun by one step per level, so the
     * run still ends on the polygon of its resolution. */
    if (r->coarse_level > 0) {
        double spent = 0.0;
        if (o->max_steps > 0)
            spent = fmax(spent, (double)s->step / (double)o->max_steps);
        if (o->max_seconds > 0.0)
            spent = fmax(spent, s->seconds / o->max_seconds);
        if (spent >= (double)(r->coarse_levels - r->coarse_level + 1) /
                         (double)(r->coarse_levels + 1)) {
            r->refine = true;
            /* a stop on the budget has spent >= 1, above every share */
            if (r->stop == TK_STOP_STEPS || r->stop == TK_STOP_TIME)
                r->stop = TK_STOP_NONE;
        }
    }
}

int tk_run_step(tk_run *r, tk_error *err)
{
    if (r->stop == TK_STOP_FAILED)
        return tk_error_set(err, TK_EINVAL, "the run has failed; it cannot step");
    if (atomic_load(&r->cancel)) {
        r->stop = TK_STOP_CANCELLED;
        return TK_OK;
    }
    tk_step_report rep = {0};
    rep.step = r->latest.step + 1;
    int rc = maybe_re_resolve(r, err);
    if (rc) {
        r->stop = TK_STOP_FAILED;
        return rc;
    }
    tk_strut_finder_refit(r->finder, r->curve);
    rc = find_active(r, r->curve, err);
    r->equalising = r->opt.equalise > 0.0;
    if (!rc)
        rc = resolve(r, &rep, err);
    double allowed = 0.0;
    if (!rc)
        rc = take_step(r, &rep, &allowed, err);
    /* The equalising motion is tangential, but on a polygon it costs
     * length at first order.  Near a constrained critical point the
     * resolved gradient is small and that cost can outweigh it, or the
     * length rises at second order faster than the motion lowers it at
     * first: the step search then finds nothing (or next to nothing) and
     * the run would stall short of the critical point.  The step goes
     * along the resolved gradient alone instead. */
    if (!rc && r->equalising && !(rep.step_size >= SHORT_STEP_FRACTION * allowed)) {
        r->equalising = false;
        r->step_size = 0.0;
        rc = resolve(r, &rep, err);
        if (!rc)
            rc = take_step(r, &rep, &allowed, err);
    }
    r->tiny_steps = rep.step_size < STALL_FRACTION * allowed ? r->tiny_steps + 1 : 0;
    if (r->nhistory > r->polish_from + POLISH_WINDOW && r->polish_level < POLISH_LEVELS) {
        double before = r->history[r->nhistory - 1 - POLISH_WINDOW].ropelength;
        double now = r->history[r->nhistory - 1].ropelength;
        if (before - now < POLISH_CHANGE * polish_scale(r) * now) {
            if (r->coarse_level > 0) {
                r->refine = true;
            } else {
                r->polish_level++;
                r->polish_from = r->nhistory;
            }
        }
    }
    double worst = 0.0;
    if (!rc)
        rc = violation(r, r->curve, &worst, err);
    if (!rc && worst > 0.5 * overstep_tolerance(r))
        rc = correct(r, &rep.corrections, err);
    if (!rc)
        rc = violation(r, r->curve, &rep.violation, err);
    rep.struts = r->struts.count;
    if (!rc)
        rc = report_kinks(r, err);
    rep.kinks = r->nkink_report;
    if (!rc)
        rc = record(r, &rep, err);
    if (rc) {
        r->stop = TK_STOP_FAILED;
        return rc;
    }
    if (r->progress && r->progress(&r->latest, r->user) != 0)
        tk_run_cancel(r);
    r->stop = TK_STOP_NONE;
    check_stop(r);
    return TK_OK;
}

int tk_run_until(tk_run *r, tk_stop_reason *reason, tk_error *err)
{
    int rc = TK_OK;
    if (r->stop != TK_STOP_FAILED)
        r->stop = TK_STOP_NONE;
    check_stop(r);
    while (r->stop == TK_STOP_NONE) {
        rc = tk_run_step(r, err);
        if (rc)
            break;
    }
    if (reason)
        *reason = r->stop;
    return rc;
}

const tk_options *tk_run_options(const tk_run *r)
{
    return &r->opt;
}

const tk_curve *tk_run_curve(const tk_run *r)
{
    return r->curve;
}

const tk_step_report *tk_run_latest(const tk_run *r)
{
    return &r->latest;
}

const tk_step_report *tk_run_history(const tk_run *r, size_t *count)
{
    *count = r->nhistory;
    return r->history;
}

const tk_strut *tk_run_struts(const tk_run *r, size_t *count)
{
    *count = r->struts.count;
    return r->struts.items;
}

const tk_kink *tk_run_kinks(const tk_run *r, size_t *count)
{
    *count = r->nkink_report;
    return r->kink_report;
}

tk_stop_reason tk_run_stop_reason(const tk_run *r)
{
    return r->stop;
}

size_t tk_run_snapshot_count(const tk_run *r)
{
    return r->nsnapshots;
}

const double *tk_run_snapshot(const tk_run *r, size_t k, long *step)
{
    if (k >= r->nsnapshots)
        return NULL;
    if (step)
        *step = r->snapshot_steps[k];
    return r->snapshots + k * 3 * r->curve->nvert;
}
