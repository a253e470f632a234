/* The flow's answer, not its path.  Different starts of the trefoil,
 * tightened to one vertex count with one step budget, end within 0.2% of
 * one another and of the best known value (the public atlas's polygon,
 * 32.743665 at 2,400 vertices; the coarser polygon's own excess is part
 * of the 0.2%): the catalogue's file, a parametric curve at two vertex
 * counts, and each disguised by tk_generate_disguise (a random rotation,
 * vertices moved along the curve, a perturbation of a few percent of the
 * edge).  And the parametric figure-eight, symmetric: the flow alone
 * stops from it at a kinked configuration 30% longer than tight, so only
 * the escapes bring it within 0.2% of the atlas's 42.09703 (400
 * vertices).  The starts are those of bench/starts, which tightens more
 * of them for longer.
 *
 * Long runs: skipped in the sanitizer build (TK_QUICK) and without the
 * catalogue. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/invariants.h"
#include "tk/thickness.h"
#include "tk/tighten.h"

typedef enum { FROM_FILE, TORUS, FIGURE_EIGHT } start_kind;

typedef struct start {
    const char *name;
    start_kind kind;
    const char *file;             /* FROM_FILE: the catalogue's */
    int p, q;                     /* TORUS */
    size_t vertices;              /* of a generated start */
    unsigned long long disguise;  /* its seed (0: none) */
    double perturbation;          /* of the edge, with a disguise */
} start;

static tk_curve *make_start(const start *s)
{
    tk_curve *c = NULL, *d = NULL;
    tk_error err;
    if (s->kind == FROM_FILE)
        c = tkt_catalogue_curve(s->file);
    else if (s->kind == TORUS)
        ck_assert_int_eq(tk_generate_torus(s->p, s->q, s->vertices, &c, &err), TK_OK);
    else
        ck_assert_int_eq(tk_generate_figure_eight(s->vertices, &c, &err), TK_OK);
    if (s->disguise == 0)
        return c;
    ck_assert_msg(tk_generate_disguise(c, s->disguise, s->perturbation, &d, &err) == TK_OK,
                  "%s: %s", s->name, err.message);
    tk_curve_free(&c);
    return d;
}

/* Tightens start s to `vertices` in `steps` steps; the result is
 * measured afresh (feasible, the type of its start) and must lie within
 * `spread` of `best`.  Returns its ropelength. */
static double tighten_start(const char *type, const start *s, size_t vertices, long steps,
                            double best, double spread)
{
    tk_curve *c = make_start(s);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.vertices = vertices;
    o.max_steps = steps;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s: %s", s->name, err.message);
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s: %s", s->name, err.message);
    const tk_curve *end = tk_run_curve(run);
    ck_assert_uint_eq(end->nvert, vertices);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(end, NULL, &m, NULL), TK_OK);
    ck_assert_msg(m.thickness >= 2 * o.radius * (1 - o.overstep_tolerance), "%s: thickness %.9f",
                  s->name, m.thickness);
    /* the type, computed here from the two curves */
    tk_invariants before = TK_INVARIANTS_INIT, after = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(c, &before, &err), TK_OK);
    ck_assert_int_eq(tk_invariants_compute(end, &after, &err), TK_OK);
    ck_assert_msg(tk_invariants_compare(&before, &after, &err) == TK_OK, "%s: %s", s->name,
                  err.message);
    tk_invariants_free(&before);
    tk_invariants_free(&after);
    size_t ne = 0;
    const tk_escape *e = tk_run_escapes(run, &ne);
    printf("%s %-9s start %5zu vertices, ropelength %.6f (%+.3f%% over %.6f) after %ld steps, "
           "%.1f s, %zu escapes, the first from %.6f\n",
           type, s->name, c->nvert, m.ropelength, 100 * (m.ropelength / best - 1), best,
           tk_run_latest(run)->step, tk_run_latest(run)->seconds, ne, ne ? e[0].from : NAN);
    ck_assert_msg(fabs(m.ropelength / best - 1) <= spread, "%s from %s: %.6f against %.6f", type,
                  s->name, m.ropelength, best);
    tk_run_free(&run);
    tk_curve_free(&c);
    return m.ropelength;
}

static bool skipped(const char *test)
{
    const char *q = getenv("TK_QUICK");
    if (q && *q && strcmp(q, "0") != 0)
        return tkt_skip(test, "a long run: the build without sanitizers runs it");
    if (!tkt_catalogue_dir())
        return tkt_skip(test, "the catalogue is absent");
    return false;
}

START_TEST(trefoils_from_five_starts_agree)
{
    if (skipped("trefoils_from_five_starts_agree"))
        return;
    static const start starts[] = {
        {"3.1", FROM_FILE, "3.1.vect", 0, 0, 0, 0, 0},
        {"3.1~", FROM_FILE, "3.1.vect", 0, 0, 0, 11, 0.05},
        {"T(2,3)", TORUS, NULL, 2, 3, 90, 0, 0},
        {"T(2,3)", TORUS, NULL, 2, 3, 300, 0, 0},
        {"T(2,3)~", TORUS, NULL, 2, 3, 120, 12, 0.01},
    };
    size_t n = sizeof starts / sizeof *starts;
    double low = INFINITY, high = -INFINITY;
    for (size_t k = 0; k < n; k++) {
        double rope = tighten_start("3_1", &starts[k], 160, 3000, 32.743665, 0.002);
        low = fmin(low, rope);
        high = fmax(high, rope);
    }
    printf("3_1: %zu starts within %.4f%% of one another\n", n, 100 * (high / low - 1));
    ck_assert(high / low - 1 <= 0.002);
}
END_TEST

/* The parametric figure-eight ((2 + cos 2t) cos 3t, (2 + cos 2t) sin 3t,
 * sin 4t) keeps its symmetry under the flow and, on its coarse level
 * alone, stops far from tight, kinked: with no loose levels and no
 * escapes the run stays there (55.1699 after 3,000 steps, 55.1073 after
 * 15,000, against 42.097: the 12,000 steps between, 150 s, are left
 * out).  The defaults (loose levels first, then escapes) must reach the
 * tight one.  (The catalogue's 4.1 and the
 * disguised copies reach it too, in bench/starts; at 10 ms a step at this
 * count they are left to it.) */
START_TEST(a_symmetric_figure_eight_reaches_the_tight_one)
{
    if (skipped("a_symmetric_figure_eight_reaches_the_tight_one"))
        return;
    static const start fig8 = {"fig8", FIGURE_EIGHT, NULL, 0, 0, 200, 0, 0};
    tk_curve *c = make_start(&fig8);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.vertices = 280;
    o.max_steps = 3000;
    o.loose = 0;
    o.escapes = 0;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s", err.message);
    double alone = tk_run_latest(run)->ropelength;
    printf("4_1 fig8 with no loose levels and no escapes: %.6f\n", alone);
    ck_assert_msg(alone > 1.1 * 42.09703, "the flow alone ended at %.6f", alone);
    tk_run_free(&run);
    tk_curve_free(&c);
    tighten_start("4_1", &fig8, 280, 15000, 42.09703, 0.002);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("starts");
    TCase *tc = tcase_create("starts");
    tcase_set_timeout(tc, 900);
    tcase_add_test(tc, trefoils_from_five_starts_agree);
    tcase_add_test(tc, a_symmetric_figure_eight_reaches_the_tight_one);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
