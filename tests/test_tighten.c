/* The tightening flow: feasibility after every step, exact tight values
 * (Hopf link 8 pi, chain of three 12 pi + 4), the catalogue trefoil,
 * a start with a continuum of contacts, cancellation, threads.
 *
 * The long runs are skipped in the sanitizer build (TK_QUICK set by the
 * test runner), which still runs every short test. */
#include <check.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/geometry.h"
#include "tk/invariants.h"
#include "tk/relax.h"
#include "tk/rigidity.h"
#include "tk/thickness.h"
#include "tk/record.h"
#include "tk/tighten.h"
#include "tk/vect.h"

/* why a test skips in the quick form */
#define LONG_RUN "a long run: the build without sanitizers runs it"

static bool quick(void)
{
    const char *q = getenv("TK_QUICK");
    return q && *q && strcmp(q, "0") != 0;
}

/* A curve of tests/data (the test fails when it cannot be read). */
static tk_curve *test_data(const char *name)
{
    char path[256];
    snprintf(path, sizeof path, "tests/data/%s", name);
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_msg(tk_vect_read_file(path, NULL, &c, &err) == TK_OK, "%s", err.message);
    return c;
}

/* The lowest ropelength of every step a run has recorded; *steps gets
 * their count. */
static double lowest_step(const tk_run *run, size_t *steps)
{
    const tk_step_report *h = tk_run_history(run, steps);
    double low = INFINITY;
    for (size_t i = 0; i < *steps; i++)
        low = fmin(low, h[i].ropelength);
    return low;
}

/* A run resumed on c at polishing level `level` (the test fails when it
 * cannot be). */
static tk_run *resumed_at_level(const tk_curve *c, const tk_options *o, int level)
{
    tk_error err;
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, &err), TK_OK);
    tk_resume at;
    memset(&at, 0, sizeof at);
    at.start_ropelength = m.ropelength;
    at.polish_level = level;
    tk_run *run = NULL;
    ck_assert_msg(tk_run_resume(c, o, &at, NULL, NULL, NULL, &run, &err) == TK_OK, "%s",
                  err.message);
    return run;
}

typedef struct watch {
    double tau;
    double tolerance;
    long steps;
    double worst;    /* lowest thickness / tau seen */
    long cancel_at;  /* cancel from the callback at this step (0: never) */
} watch;

static int watch_step(const tk_step_report *s, void *user)
{
    watch *w = user;
    w->steps++;
    w->worst = fmin(w->worst, s->thickness / w->tau);
    ck_assert_msg(s->thickness >= w->tau * (1 - w->tolerance),
                  "step %ld: thickness %.10f below the diameter %.10f", s->step, s->thickness,
                  w->tau);
    ck_assert(isfinite(s->ropelength) && s->ropelength > 0);
    return w->cancel_at > 0 && s->step >= w->cancel_at;
}

/* Runs `run` (made with the options o) to its stop, checking every step's
 * thickness (watch_step), and prints its figures; returns its last
 * report. */
static const tk_step_report *run_watched(tk_run *run, const tk_options *o, const char *what,
                                         tk_stop_reason *why)
{
    tk_error err;
    watch w = {2 * o->radius, o->overstep_tolerance, 0, INFINITY, 0};
    tk_run_set_progress(run, watch_step, &w);
    tk_stop_reason reason;
    int rc = tk_run_until(run, &reason, &err);
    ck_assert_msg(rc == TK_OK, "%s: %s", what, err.message);
    tk_run_set_progress(run, NULL, NULL);
    const tk_step_report *last = tk_run_latest(run);
    printf("%s: %ld steps, %.2f s, ropelength %.6f, residual %.3g, struts %zu, vertices %zu, "
           "stop %s\n",
           what, last->step, last->seconds, last->ropelength, last->residual, last->struts,
           last->vertices, tk_stop_reason_name(reason));
    if (why)
        *why = reason;
    return last;
}

/* Tightens c with the options; returns the final ropelength. */
static double tighten(const tk_curve *c, tk_options *o, const char *what, tk_stop_reason *why)
{
    tk_run *run = NULL;
    tk_error err;
    int rc = tk_run_new(c, o, &run, &err);
    ck_assert_msg(rc == TK_OK, "%s: %s", what, err.message);
    const tk_step_report *last = run_watched(run, o, what, why);
    /* the final curve measured afresh agrees with the run's figures */
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL), TK_OK);
    ck_assert(tkt_reldiff(m.ropelength, last->ropelength) < 1e-12);
    double result = last->ropelength;
    tk_run_free(&run);
    return result;
}

START_TEST(generated_hopf_link_tightens_to_8_pi)
{
    if (quick() && tkt_skip("generated_hopf_link_tightens_to_8_pi", LONG_RUN))
        return;
    /* The generated Hopf link is the tight one drawn with round polygons;
     * resampled to resolution 8 (about 200 vertices) the flow settles it
     * within 0.05% of the exact 8 pi (the polygon's own discretisation
     * error there is about 0.035%). */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(64, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 8;
    o.max_steps = 1500;
    double rope = tighten(c, &o, "generated hopf", NULL);
    ck_assert_msg(rope < 8 * M_PI * (1 + 5e-4), "ropelength %.6f vs 8 pi = %.6f", rope,
                  8 * M_PI);
    ck_assert_msg(rope > 8 * M_PI, "ropelength %.6f below 8 pi", rope);
    tk_curve_free(&c);
}
END_TEST

START_TEST(hopf_link_tightens_towards_8_pi)
{
    if (quick() && tkt_skip("hopf_link_tightens_towards_8_pi", LONG_RUN))
        return;
    /* A Hopf link whose second circle is pulled off centre and stretched,
     * so the flow has real work to do. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(48, &c, NULL), TK_OK);
    for (size_t v = c->offset[1]; v < c->offset[2]; v++) {
        c->xyz[3 * v] = 0.3 + 1.4 * c->xyz[3 * v];
        c->xyz[3 * v + 2] *= 1.2;
    }
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 400;
    double rope = tighten(c, &o, "hopf", NULL);
    /* within 0.5% of the exact 8 pi at 96 vertices (the 0.05% target needs
     * finer curves and a steadier end game; see the issue notes) */
    ck_assert_msg(rope < 8 * M_PI * 1.005, "ropelength %.6f vs 8 pi", rope);
    ck_assert_msg(rope > 8 * M_PI * 0.995, "ropelength %.6f below 8 pi", rope);
    tk_curve_free(&c);
}
END_TEST

START_TEST(generated_chain_of_three_tightens_to_12_pi_plus_4)
{
    if (quick() && tkt_skip("generated_chain_of_three_tightens_to_12_pi_plus_4", LONG_RUN))
        return;
    /* The tight chain of three: the end rings round (ropelength 4 pi
     * each), the middle one a stadium of two semicircles of diameter 2
     * joined by straight pieces of length 1 (4 pi + 4).  The end rings
     * pull kinks into themselves where they hook the middle ring before
     * they round out, so this exercises the kink constraints.  On 300
     * vertices (a coarse level of 150, a loose one of 75): at 4 a unit of the tight
     * ropelength (168) the polygon itself is 0.1% longer (a ring of n
     * sides is 2 n tan(pi / n) for a smooth 2 pi: 0.13% for n = 50). */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(3, 0, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.vertices = 300;
    o.max_steps = 3500;
    double rope = tighten(c, &o, "chain of 3", NULL);
    double tight = 12 * M_PI + 4;
    ck_assert_msg(fabs(rope - tight) < 1e-3 * tight, "ropelength %.6f vs 12 pi + 4 = %.6f",
                  rope, tight);
    tk_curve_free(&c);
}
END_TEST

/* converge stops a run once it has gone as far as its tolerances allow:
 * every escape tried, the best polished to the finest level and no longer
 * falling there.  Checked independently: the returned curve, tightened
 * again at that finest level with nothing else going on, falls by less
 * than 1e-5 (relative; 1.2e-6 when written) in 3,000 more steps, an
 * eightieth of the polygon's own error at 127 vertices (about 0.08%), and
 * it is within 0.1% of the exact 8 pi. */
START_TEST(converge_stops_where_the_flow_has_no_more_to_give)
{
    if (quick() && tkt_skip("converge_stops_where_the_flow_has_no_more_to_give", LONG_RUN))
        return;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(64, &c, NULL), TK_OK);
    for (size_t v = c->offset[1]; v < c->offset[2]; v++) {
        c->xyz[3 * v] = 0.3 + 1.4 * c->xyz[3 * v];
        c->xyz[3 * v + 2] *= 1.2;
    }
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.escapes = 2;
    o.converge = true;
    o.max_steps = 400000; /* a bound on a failure only */
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    tk_stop_reason why;
    const tk_step_report *last = run_watched(run, &o, "hopf, converge", &why);
    ck_assert_msg(why == TK_STOP_CONVERGED, "stopped: %s", tk_stop_reason_name(why));
    ck_assert_int_lt(last->step, o.max_steps);
    size_t tries = 0;
    (void)tk_run_escapes(run, &tries);
    ck_assert_uint_ge(tries, (size_t)o.escapes);
    double rope = last->ropelength;
    ck_assert_msg(rope > 8 * M_PI && rope < 8 * M_PI * (1 + 1e-3), "ropelength %.7f", rope);
    tk_curve *result = NULL;
    ck_assert_int_eq(tk_curve_copy(tk_run_curve(run), &result, &err), TK_OK);
    tk_run_free(&run);
    tk_options again = TK_OPTIONS_INIT;
    again.escapes = 0;
    again.max_steps = 3000;
    run = resumed_at_level(result, &again, 4);
    ck_assert_int_eq(tk_run_until(run, NULL, &err), TK_OK);
    size_t n = 0;
    double low = lowest_step(run, &n);
    printf("converged at %.9f; 3,000 more steps at the finest level: lowest %.9f\n", rope, low);
    ck_assert_msg(low > rope * (1 - 1e-5), "fell to %.9f from %.9f", low, rope);
    tk_run_free(&run);
    tk_curve_free(&result);
    tk_curve_free(&c);
}
END_TEST

/* The defaults that tighten (tk_options_complete, nothing given) end the
 * catalogue's figure-eight tight: within 0.2% of the atlas's 42.09703 (at
 * 400 vertices; this polygon has about 210), converged or at their 120
 * of work, which is a count of the run's operations, so the run is the
 * same on any machine at any load (README: converged at 42.1258 after
 * about a minute here). */
START_TEST(the_defaults_tighten_the_figure_eight)
{
    if (quick() && tkt_skip("the_defaults_tighten_the_figure_eight", LONG_RUN))
        return;
    if (!tkt_catalogue_dir() && tkt_skip("the_defaults_tighten_the_figure_eight", "no catalogue"))
        return;
    tk_curve *c = tkt_catalogue_curve("4.1.vect");
    tk_options o = TK_OPTIONS_INIT;
    tk_options_given none = {0};
    tk_options_complete(&o, &none);
    ck_assert(o.converge && o.autoscale && o.resolution == TK_DEFAULT_RESOLUTION);
    ck_assert(o.max_work == TK_DEFAULT_WORK && o.max_seconds == 0.0 && o.max_steps == 0);
    tk_stop_reason why;
    double rope = tighten(c, &o, "4.1, the defaults", &why);
    ck_assert_msg(why == TK_STOP_CONVERGED || why == TK_STOP_WORK, "stopped on %s",
                  tk_stop_reason_name(why));
    ck_assert_msg(rope < 42.09703 * 1.002, "ropelength %.7f", rope);
    tk_curve_free(&c);
}
END_TEST

START_TEST(re_resolution_keeps_the_resolution)
{
    /* A loose trefoil resampled at resolution 5 is too fine once it has
     * tightened: the run resamples it to 5 vertices per unit of
     * ropelength again, and stays feasible across the change (watch_step
     * checks every step). */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.re_resolve = 0.05;
    o.coarse_to_fine = false; /* the resolution stays 5 from the start */
    o.max_steps = quick() ? 150 : 400;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    size_t start = tk_run_curve(run)->nvert;
    double rope0 = tk_run_latest(run)->ropelength;
    const tk_step_report *last = run_watched(run, &o, "re-resolved trefoil", NULL);
    ck_assert(last->ropelength < rope0 * 0.95);
    ck_assert_uint_lt(last->vertices, start);
    ck_assert_uint_eq(last->vertices, tk_run_curve(run)->nvert);
    ck_assert_uint_ge(last->vertices, (size_t)ceil(5 * last->ropelength * 0.95));
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL), TK_OK);
    ck_assert(m.thickness >= 2 * o.radius * (1 - o.overstep_tolerance));
    tk_run_free(&run);
    /* the vertex count changes, so snapshots (one layout) are refused */
    o.snapshot_every = 10;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert(strstr(err.message, "re_resolve") != NULL);
    tk_curve_free(&c);
}
END_TEST

START_TEST(vertices_option_ends_at_exactly_that_count)
{
    /* The vertices option asks for a count, not a density: the run goes
     * coarse to fine as with the resolution it implies (the count over the
     * start's ropelength), each level ceil(count / 2^k), and ends on a
     * polygon of exactly that many vertices, resumed or not; with a
     * resolution too it is refused. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_figure_eight(0, &c, NULL), TK_OK);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.vertices = 4 * (size_t)ceil(2.5 * m.ropelength) + 3; /* two levels, odd */
    o.loose = 0; /* the coarse levels alone (loose levels: loose_start_escapes) */
    o.escapes = 0;
    o.max_steps = quick() ? 120 : 900;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, (o.vertices + 3) / 4);
    tk_stop_reason why;
    const tk_step_report *last = run_watched(run, &o, "figure-eight to a vertex count", &why);
    size_t nh = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    for (size_t i = 0; i < nh; i++)
        ck_assert_msg(h[i].vertices == (o.vertices + 3) / 4 || h[i].vertices == (o.vertices + 1) / 2
                      || h[i].vertices == o.vertices, "step %ld: %zu vertices", h[i].step,
                      h[i].vertices);
    ck_assert_uint_eq(last->vertices, o.vertices);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, o.vertices);
    tk_run_free(&run);
    o.resolution = 5;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "vertices and resolution"), "%s", err.message);
    tk_curve_free(&c);
}
END_TEST

/* The ropelength a run going coarse to fine (from one coarse level)
 * reckons its final polygon's vertices from: the one it had reached when
 * it first refined (the figures of the step before), or the start's if
 * that was more; 0 if it never refined. */
static double final_reference(const tk_run *run, double start)
{
    size_t nh = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    for (size_t i = 1; i < nh; i++)
        if (h[i].vertices > h[i - 1].vertices)
            return fmin(start, h[i - 1].ropelength);
    return 0.0;
}

static size_t final_count_reckoned(const tk_run *run, double resolution, double start)
{
    return (size_t)ceil(resolution * final_reference(run, start));
}

START_TEST(coarse_to_fine_ends_at_the_resolution)
{
    /* With a resolution the run starts on a polygon of half the vertices
     * (2.5 per unit ropelength for resolution 5), tightens it until the
     * ropelength all but stops falling, then doubles them: the run ends at
     * resolution 5 of the ropelength it has reached by then (the loose
     * start's is a quarter more), feasible at every step.  A stop on little
     * change waits for the final
     * polygon (the coarse one stops changing long before), and so does a
     * step budget. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, NULL), TK_OK);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.min_change = 1e-4;
    o.change_window = 50;
    o.loose = 0; /* one coarse level below the final one */
    o.max_steps = quick() ? 300 : 6000;
    o.escapes = 0; /* the schedule alone: an escape starts it again (escapes_*) */
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, (size_t)ceil(2.5 * m.ropelength));
    tk_stop_reason why;
    const tk_step_report *last = run_watched(run, &o, "coarse to fine trefoil", &why);
    /* The refinement makes the resampled polygon feasible by Newton steps,
     * not by scaling it up: its ropelength stays within 0.1% of the coarse
     * one's (a scaled-up curve loses every contact and its length). */
    size_t nh = 0, refined = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    for (size_t i = 1; i < nh; i++) {
        /* (an escape deforms and coarsens: fewer vertices) */
        if (h[i].vertices <= h[i - 1].vertices)
            continue;
        refined++;
        printf("refined from %zu to %zu vertices at step %ld: ropelength %.6f then %.6f\n",
               h[i - 1].vertices, h[i].vertices, h[i].step, h[i - 1].ropelength,
               h[i].ropelength);
        ck_assert_msg(h[i].ropelength <= 1.001 * h[i - 1].ropelength, "%.6f after %.6f",
                      h[i].ropelength, h[i - 1].ropelength);
    }
    ck_assert_uint_ge(refined, 1);
    tk_run_timing t;
    tk_run_timing_get(run, &t);
    ck_assert_int_eq(t.rescales, 0);
    size_t final = final_count_reckoned(run, 5, m.ropelength);
    printf("coarse to fine: %zu vertices on the final polygon, %zu for the start's "
           "ropelength\n",
           final, (size_t)ceil(5 * m.ropelength));
    ck_assert_uint_lt(final, (size_t)ceil(5 * m.ropelength));
    if (!quick()) {
        ck_assert_int_eq(why, TK_STOP_CHANGE);
        ck_assert_uint_eq(last->vertices, final);
        ck_assert_uint_eq(tk_run_curve(run)->nvert, last->vertices);
        /* the tight trefoil is about 32.74; a polygon of 5 vertices per
         * unit gets within a few thousandths */
        ck_assert_msg(last->ropelength < 32.80, "ropelength %.6f", last->ropelength);
    }
    tk_run_free(&run);
    /* a step budget too short for the coarse polygon to settle still ends
     * on the final one: the coarse level has half the budget */
    o.min_change = 0.0;
    o.max_steps = 40;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    last = run_watched(run, &o, "coarse to fine, 40 steps", &why);
    ck_assert_int_eq(why, TK_STOP_STEPS);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, final_count_reckoned(run, 5, m.ropelength));
    ck_assert_uint_eq(last->vertices, tk_run_curve(run)->nvert);
    tk_run_free(&run);
    /* one step is one too few: the run takes one more, on the final polygon */
    o.max_steps = 1;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    last = run_watched(run, &o, "coarse to fine, 1 step", &why);
    ck_assert_int_eq(why, TK_STOP_STEPS);
    ck_assert_int_eq(last->step, 2);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, final_count_reckoned(run, 5, m.ropelength));
    tk_run_free(&run);
    /* snapshots keep one vertex count: no coarse start then */
    o.snapshot_every = 10;
    o.max_steps = 1;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, (size_t)ceil(5 * m.ropelength));
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Two unlinked rings a hundred radii apart, each a regular 15-gon: an
 * odd regular polygon has no doubly critical pair of its own (no two
 * edges face each other), so the shortest self-distance is the gap, and
 * twice the length over it reckons a ropelength of 0.25, where each ring
 * alone is 2 pi at least (Fenchel's theorem).  The run still ends at
 * resolution 5 of the tight value (ceil(5 * 4 pi) = 63 vertices), two
 * regular polygons of about 32 vertices: 2 n tan(pi / n) each (a
 * resolution reckoned from the gap ended on two triangles, 12 sqrt(3) =
 * 20.78; catalogue 0.2.1 turned inside out on 23 vertices, 12.89). */
START_TEST(rings_far_apart_get_the_resolution_s_vertices)
{
    size_t counts[2] = {15, 15};
    bool closed[2] = {true, true};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 2, counts, closed, NULL), TK_OK);
    for (size_t comp = 0; comp < 2; comp++)
        for (size_t i = 0; i < 15; i++) {
            double *p = tk_curve_vertex(c, c->offset[comp] + i), a = 2.0 * M_PI * i / 15;
            p[0] = 100.0 * comp + cos(a);
            p[1] = comp ? 0.0 : sin(a);
            p[2] = comp ? sin(a) : 0.0;
        }
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.escapes = 0;
    o.max_steps = 1500;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    tk_stop_reason why;
    const tk_step_report *last = run_watched(run, &o, "two rings far apart", &why);
    size_t n = last->vertices, half = n / 2;
    double polygons = 2.0 * (double)half * tan(M_PI / (double)half) +
                      2.0 * (double)(n - half) * tan(M_PI / (double)(n - half));
    printf("two rings far apart: %zu vertices, ropelength %.6f (two regular polygons "
           "of %zu and %zu: %.6f)\n",
           n, last->ropelength, half, n - half, polygons);
    ck_assert_uint_ge(n, (size_t)ceil(5.0 * 4.0 * M_PI));
    ck_assert_msg(last->ropelength <= 1.001 * polygons, "%.6f against %.6f", last->ropelength,
                  polygons);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Tightens the catalogue's 3.1 at resolution 5 for `steps` steps; false
 * (the run skipped, saying why) in the quick form or without the
 * catalogue. */
static bool tighten_catalogue_trefoil(const char *what, bool autoscale, long steps,
                                      double *rope, tk_stop_reason *why)
{
    if (quick() || !tkt_catalogue_dir()) {
        char test[96];
        snprintf(test, sizeof test, "the catalogue's trefoil (%s)", what);
        tkt_skip(test, quick() ? LONG_RUN : "the catalogue is absent");
        return false;
    }
    tk_curve *c = tkt_catalogue_curve("3.1.vect");
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = autoscale;
    o.resolution = 5;
    o.max_steps = steps;
    o.loose = 0; /* one coarse level, as these steps were counted for */
    *rope = tighten(c, &o, what, why);
    tk_curve_free(&c);
    return true;
}

START_TEST(catalogue_trefoil_at_resolution_5)
{
    double rope;
    /* half the steps on the coarse polygon (2.5 vertices per unit
     * ropelength, whose own optimum is near 32.85), then the fine one */
    if (tighten_catalogue_trefoil("3.1", true, 700, &rope, NULL))
        ck_assert_msg(rope <= 32.80, "ropelength %.6f", rope);
}
END_TEST

START_TEST(trefoil_does_not_stall_near_its_critical_point)
{
    /* Near a constrained critical point the resolved gradient is small
     * and the equalising motion, which costs length at first order on a
     * polygon, can outweigh it: no step along their sum shortens the
     * curve.  The run must then step along the resolved gradient alone,
     * not stop as stalled (this one used to, after about 1150 steps, at
     * residual 0.012). */
    double rope;
    tk_stop_reason why;
    if (!tighten_catalogue_trefoil("3.1 to its critical point", false, 1600, &rope, &why))
        return;
    ck_assert_msg(why == TK_STOP_STEPS, "stopped: %s", tk_stop_reason_name(why));
    ck_assert_msg(rope <= 32.775, "ropelength %.6f", rope);
}
END_TEST

/* A step's merit (stepping.c): its length over the thickness its
 * violation leaves, from the step's own figures. */
typedef struct merit_watch {
    const tk_run *run;
    tk_step_report last;
    long checked;      /* steps with no correction on the polygon before them */
    long rises;        /* of those, steps whose merit rose */
    double largest;    /* the largest rise, relative */
    long length_steps; /* the run's steps judged by their length so far */
    long by_length;    /* checked steps judged by their length */
    long corrected_steps; /* the run's steps judged after their correction so far */
    long corrected;    /* such steps on the polygon before them */
} merit_watch;

static int watch_merit(const tk_step_report *s, void *user)
{
    merit_watch *w = user;
    const tk_step_report *p = &w->last;
    tk_run_timing t;
    tk_run_timing_get(w->run, &t);
    bool by_length = t.length_steps > w->length_steps;
    w->length_steps = t.length_steps;
    bool corrected = t.corrected_steps > w->corrected_steps;
    w->corrected_steps = t.corrected_steps;
    if (corrected && s->step > 1 && s->vertices == p->vertices && s->escapes == p->escapes) {
        /* corrected within the step: the merit it leaves fell all the same */
        double before = p->length / (1.0 - p->violation), after = s->length / (1.0 - s->violation);
        w->corrected++;
        ck_assert_msg(s->corrections > 0, "step %ld, judged after its correction, made none",
                      s->step);
        ck_assert_msg(after < before, "step %ld, judged after its correction, raised it by %.3g",
                      s->step, after / before - 1.0);
    }
    /* a step corrected after it, a step of size 0 (the curve corrected
     * or left), and the first on a new polygon (refined, or deformed by
     * an escape) answer for more than the step itself */
    if (s->step > 1 && s->corrections == 0 && s->step_size > 0.0 &&
        s->vertices == p->vertices && s->escapes == p->escapes) {
        double before = p->length / (1.0 - p->violation), after = s->length / (1.0 - s->violation);
        w->checked++;
        if (by_length) {
            /* no step along its motion lowered the merit (stepping.c) */
            w->by_length++;
            ck_assert_msg(s->length < p->length, "step %ld, judged by its length, lengthened it",
                          s->step);
        } else if (after > before * (1.0 + 1e-13)) {
            w->rises++;
            w->largest = fmax(w->largest, after / before - 1.0);
        }
    }
    w->last = *s;
    return 0;
}

START_TEST(a_step_lowers_the_ropelength_it_leaves)
{
    /* A step is accepted within the overstep tolerance and its violation
     * corrected after it: judged by its length alone it may gain less than
     * its violation costs, and the run then cycles between such steps and
     * their corrections (stepping.c).  Every step that needs no correction
     * must lower its length over the thickness it leaves, or, where no
     * step along its motion can (the merit rises at first order in the
     * step size), its length; and a step judged after its correction must
     * lower it with that correction. */
    if (quick() || !tkt_catalogue_dir()) {
        tkt_skip("steps lower the ropelength they leave",
                 quick() ? LONG_RUN : "the catalogue is absent");
        return;
    }
    tk_curve *c = tkt_catalogue_curve("3.1.vect");
    tk_options o = TK_OPTIONS_INIT;
    o.resolution = 5;
    o.max_steps = 2000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    merit_watch w = {.run = run, .last = *tk_run_latest(run)};
    tk_run_set_progress(run, watch_merit, &w);
    /* up to the budget's last fifth, which puts the best curve back in
     * place of a try behind it (escape.c): a new curve, whose first step
     * answers for the swap */
    while (tk_run_latest(run)->step < 4 * o.max_steps / 5 &&
           tk_run_stop_reason(run) == TK_STOP_NONE)
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    printf("steps with no correction: %ld, of which %ld judged by their length and %ld others "
           "raised the ropelength they leave (by %.3g at most); %ld judged after their "
           "correction lowered it\n",
           w.checked, w.by_length, w.rises, w.largest, w.corrected);
    ck_assert_msg(w.checked >= 1000, "only %ld steps checked", w.checked);
    ck_assert_msg(w.rises == 0, "%ld of %ld steps raised it, by %.3g at most", w.rises, w.checked,
                  w.largest);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(round_hopf_start_with_continuum_of_contacts)
{
    /* Two round circles through each other's centres: every point of one
     * is at the same distance from the other. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(48, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = quick() ? 20 : 300;
    tk_stop_reason why;
    double rope = tighten(c, &o, "round hopf", &why);
    ck_assert(why == TK_STOP_STEPS || why == TK_STOP_STALLED || why == TK_STOP_CHANGE);
    ck_assert(rope < 8 * M_PI * 1.05);
    tk_curve_free(&c);
}
END_TEST

START_TEST(recovery_restores_thousands_of_contacts_without_rescaling)
{
    /* The round Hopf link: every vertex of each ring is at distance 1 from
     * the other ring, over a thousand struts at 300 vertices a ring (a
     * vertex is near several edges; 1,292 with the active tolerance of
     * these edges, 0.3 h^2 = 1.3e-4).  Shrunk by
     * 1e-3 about the origin, every one of them is violated by 1e-3 of the
     * diameter; the run's error recovery (a start may overstep by up to
     * its overstep tolerance, here 2e-3) must restore the thickness by
     * Newton steps on the violated constraints, not by rescaling the
     * curve. */
    const size_t per_ring = 300;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_hopf(per_ring, &c, NULL), TK_OK);
    tk_curve_scale(c, 1.0 - 1e-3);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    ck_assert(m.thickness < 1.0 - 0.9e-3);
    tk_options o = TK_OPTIONS_INIT;
    o.overstep_tolerance = 2e-3;
    o.max_steps = 1;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    const tk_step_report *first = tk_run_latest(run);
    printf("recovery at %zu struts: %d corrections\n", first->struts, first->corrections);
    ck_assert_uint_ge(first->struts, 1000);
    tk_run_timing t;
    tk_run_timing_get(run, &t);
    ck_assert_int_eq(t.rescales, 0);
    /* the plain Newton steps suffice here (the bending metric's smooth
     * steps would leave some contacts short of the bound: 377 struts) */
    ck_assert_int_eq(t.bent_corrections, 0);
    const tk_curve *d = tk_run_curve(run);
    ck_assert_int_eq(tk_thickness_measure(d, NULL, &m, NULL), TK_OK);
    /* the correction tolerance: a tenth of the overstep one, at most 3e-5 */
    ck_assert_msg(m.thickness >= 1.0 - 3e-5, "thickness %.9f", m.thickness);
    double moved = 0.0;
    for (size_t i = 0; i < 3 * d->nvert; i += 3) {
        double dx = d->xyz[i] - c->xyz[i], dy = d->xyz[i + 1] - c->xyz[i + 1],
               dz = d->xyz[i + 2] - c->xyz[i + 2];
        moved = fmax(moved, sqrt(dx * dx + dy * dy + dz * dz));
    }
    /* what it costs: a rescaling to the diameter would lengthen the
     * curve by 1e-3 and lose every contact (all are 1e-3 off, beyond the
     * active tolerance, at most 3e-4); the Newton steps keep the contacts (counted
     * above, after the recovery) and deform the curve smoothly (the
     * vertices at the other ring's centre, near all of it, move most) at
     * a cost of the same order (0.14%) */
    double grew = tk_curve_length(d) / tk_curve_length(c) - 1.0;
    printf("recovery moved a vertex by at most %.3g; the length grew by %.3g\n", moved, grew);
    ck_assert_msg(grew < 2e-3, "the length grew by %.3g", grew);
    ck_assert_msg(moved < 0.1, "a vertex moved by %.3g", moved);
    /* and the run goes on from there */
    tk_stop_reason why;
    run_watched(run, &o, "recovered hopf", &why);
    ck_assert_int_eq(why, TK_STOP_STEPS);
    tk_run_timing_get(run, &t);
    ck_assert_int_eq(t.rescales, 0);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_fine_start_is_set_up_with_the_tolerance_of_its_edges)
{
    /* On a fine polygon the active tolerance is 0.3 h^2 (h the mean edge
     * in diameters), below the options' 3e-4.  A run being set up has no
     * step figures yet to reckon h from; its first active set must still
     * be taken with 0.3 h^2.  (With 3e-4 a tight trefoil resampled to
     * 2,400 vertices had 48,585 struts active at step 0, about 9,000 a
     * step later, and took 321 s to set up.)  Here: T(2,3) on 2,000
     * vertices, scaled so that its thickness is just the diameter. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 2000, &c, NULL), TK_OK);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    tk_curve_scale(c, (1.0 + 1e-9) / m.thickness);
    tk_options o = TK_OPTIONS_INIT;
    o.max_steps = 1;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    const tk_curve *d = tk_run_curve(run);
    double h = tk_curve_length(d) / (double)tk_curve_edge_count(d);
    double tolerance = 0.3 * h * h;
    ck_assert_msg(tolerance < 0.2 * o.active_tolerance, "h %g: not a fine polygon", h);
    size_t n = 0;
    const tk_strut *struts = tk_run_struts(run, &n);
    double longest = 0.0;
    for (size_t j = 0; j < n; j++)
        longest = fmax(longest, struts[j].length);
    /* the options' tolerance would have taken more pairs */
    tk_strut_finder *f = NULL;
    tk_strut_list wide = {0};
    ck_assert_int_eq(tk_strut_finder_new(d, &f, NULL), TK_OK);
    ck_assert_int_eq(tk_strut_finder_find_pairs(f, d, TK_ARC_ADMISSIBLE, 1.0,
                                                1.0 + o.active_tolerance, &wide, NULL),
                     TK_OK);
    printf("set up on %zu vertices: %zu struts, the longest 1 + %.3g (0.3 h^2 = %.3g); "
           "%zu pairs within 1 + %g\n",
           d->nvert, n, longest - 1.0, tolerance, wide.count, o.active_tolerance);
    ck_assert_uint_gt(n, 0);
    ck_assert_msg(longest <= 1.0 + tolerance * (1.0 + 1e-6), "a strut of 1 + %.3g at step 0",
                  longest - 1.0);
    ck_assert_uint_gt(wide.count, n);
    tk_strut_list_free(&wide);
    tk_strut_finder_free(&f);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_fine_tight_polygon_is_restored_in_place)
{
    /* tests/data/trefoil-2400.vect: a tight trefoil of 4,800 vertices
     * (ropelength 32.74378) resampled to 2,400.  Its struts are violated
     * by up to 4.9e-6 of the diameter all along the curve, two radii of
     * curvature by 9.4e-6 of the bound, and hundreds of others are within
     * 1% of it.  The least-norm Newton steps on the violated constraints
     * move single vertices and bend their neighbours past the bound (by
     * 13% and more, at any damping), the inequality steps crawl, and the
     * start was scaled up by 1 + 9.3e-6; steps measured by their bending
     * as well must restore it in place. */
    tk_curve *c = test_data("trefoil-2400.vect");
    tk_error err;
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    double before = tk_curve_length(c);
    tk_options o = TK_OPTIONS_INIT;
    o.coarse_to_fine = false;
    o.escapes = 0;
    o.max_steps = 1;
    tk_run *run = NULL;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    const tk_curve *d = tk_run_curve(run);
    tk_run_timing t;
    tk_run_timing_get(run, &t);
    tk_measure after;
    ck_assert_int_eq(tk_thickness_measure(d, NULL, &after, NULL), TK_OK);
    double h = tk_curve_length(d) / (double)tk_curve_edge_count(d);
    /* the correction tolerance: a tenth of the overstep one, 0.3 h^2 */
    double tolerance = 0.03 * h * h;
    printf("fine trefoil: thickness 1 - %.3g, minrad 0.5 - %.3g; restored in %d corrections, "
           "%ld rescales, thickness 1 + %.3g, length %+.3g, %zu struts\n",
           1.0 - m.thickness, 0.5 - m.minrad, tk_run_latest(run)->corrections, t.rescales,
           after.thickness - 1.0, tk_curve_length(d) / before - 1.0,
           tk_run_latest(run)->struts);
    ck_assert(d->nvert == c->nvert);
    ck_assert(m.thickness < 1.0 - 4e-6 && m.minrad < 0.5 * (1.0 - 9e-6));
    ck_assert_int_eq(t.rescales, 0);
    /* the plain and inequality steps could not, as said above */
    ck_assert_int_eq(t.bent_corrections, 1);
    ck_assert_msg(after.thickness >= 1.0 - tolerance, "thickness 1 - %.3g", 1.0 - after.thickness);
    ck_assert_msg(after.minrad >= 0.5 * (1.0 - tolerance), "minrad 0.5 - %.3g",
                  0.5 - after.minrad);
    /* in place: the length changes by less than the least rescale would
     * (1 + 9.4e-6, the worst violation) */
    ck_assert_msg(fabs(tk_curve_length(d) / before - 1.0) < 9.4e-6, "length %+.3g",
                  tk_curve_length(d) / before - 1.0);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* A step's first trials can be far longer than the step it takes: a tight
 * polygon taken up again at a deep polishing level tries twice its last
 * step, or an eighth of the largest the motion allows, and such a trial
 * crosses pairs all along the curve.  The pairs a trial crosses join the
 * active set only when they are no more than the set holds (or a quarter
 * of the vertices); a longer trial is halved first (stepping.c,
 * expand_most).  Before that rule the tight 2,400-vertex trefoil's first
 * step at level 3 carried 5,543 struts and the one after it 955; at
 * 9,600 vertices a first step carried 36,079 and took 72 s
 * (bench/FIGURES.md). */
START_TEST(an_expansion_leaves_a_long_trial_s_crossings_out)
{
    tk_curve *c = test_data("trefoil-2400.vect");
    tk_options o = TK_OPTIONS_INIT;
    o.coarse_to_fine = false;
    o.escapes = 0;
    tk_run *run = resumed_at_level(c, &o, 3);
    tk_error err;
    size_t before = tk_run_latest(run)->struts, quarter = c->nvert / 4;
    double rope = tk_run_latest(run)->ropelength;
    ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    const tk_step_report *s = tk_run_latest(run);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL), TK_OK);
    printf("tight trefoil at level 3: %zu struts at step 0, %zu carried by step 1 (step %.3g), "
           "ropelength %.9f to %.9f, thickness 1 %+.3g\n", before, s->struts, s->step_size, rope,
           s->ropelength, m.thickness - 1.0);
    /* an expansion at most doubles the set (or adds a quarter of the
     * vertices); after one, a second adds what the shorter trial still
     * crosses, here few: 952 struts became 1,608 */
    size_t most = before > quarter ? before : quarter;
    ck_assert_msg(s->struts <= before + most, "%zu struts after %zu", s->struts, before);
    ck_assert(s->step_size > 0.0);
    ck_assert(s->ropelength < rope);
    ck_assert(m.thickness >= 1.0 - o.overstep_tolerance);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* The plain problem's optimality conditions for a step's forces f, from
 * what the run reports: its struts (it must have no kinks), rebuilt as
 * the rigidity matrix A at the curve the step started from (c), and
 * v = -grad L + A f.  Into worst: the most negative a_i . v / (|a_i| |v|)
 * over the struts (a motion that shortens no contact at first order has
 * none below 0), and into term: |(A f) . v| / |v|^2 (0 at the answer). */
static void forces_resolve(const tk_curve *c, const tk_run *run, double *worst, double *term)
{
    size_t ns = 0, n3 = 3 * c->nvert;
    const tk_strut *struts = tk_run_struts(run, &ns);
    cholmod_common cc;
    cholmod_start(&cc);
    cholmod_sparse *a = NULL;
    ck_assert_int_eq(tk_rigidity_build(c, struts, ns, NULL, 0, &cc, &a, NULL), TK_OK);
    double *v = malloc(n3 * sizeof *v), *af = calloc(n3, sizeof *af);
    ck_assert(v && af);
    tk_curve_length_gradient(c, v);
    const int *ap = a->p, *ai = a->i;
    const double *ax = a->x;
    for (size_t j = 0; j < ns; j++) {
        ck_assert(struts[j].force >= 0.0);
        for (int e = ap[j]; e < ap[j + 1]; e++)
            af[ai[e]] += ax[e] * struts[j].force;
    }
    double vv = 0.0, afv = 0.0;
    for (size_t i = 0; i < n3; i++) {
        v[i] = -v[i] + af[i];
        vv += v[i] * v[i];
        afv += af[i] * v[i];
    }
    *worst = 0.0;
    for (size_t j = 0; j < ns; j++) {
        double dot = 0.0, norm = 0.0;
        for (int e = ap[j]; e < ap[j + 1]; e++) {
            dot += ax[e] * v[ai[e]];
            norm += ax[e] * ax[e];
        }
        if (norm > 0.0)
            *worst = fmin(*worst, dot / sqrt(norm * vv));
    }
    *term = fabs(afv) / vv;
    free(v);
    free(af);
    cholmod_free_sparse(&a, &cc);
    cholmod_finish(&cc);
}

/* On a fine curve the flow's proximal rounds keep their factor and take
 * extrapolated centres (engine/motion.c); whatever the centres, the
 * rounds end on an answer whose term is within their share (1e-4 of
 * |v|^2), so the forces a step reports resolve its motion as the plain
 * problem's would: no constraint shortened at first order beyond the
 * proximal term's size, and the motion orthogonal to the forces' part of
 * it.  Checked from the reported contacts, with the matrix built anew,
 * on the tight 2,400-vertex trefoil at level 3.  With the rounds cut to
 * two a step, (A f) . v reached 4.0e-3 of |v|^2 here. */
START_TEST(a_fine_curve_s_forces_resolve_its_motion)
{
    tk_curve *c = test_data("trefoil-2400.vect");
    tk_options o = TK_OPTIONS_INIT;
    o.coarse_to_fine = false;
    o.escapes = 0;
    o.equalise = 0.0;
    /* no kinks: the run reports a vertex's two radius functions as one
     * kink with their forces summed, from which the matrix cannot be
     * rebuilt; the curve's radii of curvature are five times this
     * bound */
    o.lambda = 0.2;
    tk_run *run = resumed_at_level(c, &o, 3);
    tk_error err;
    int checked = 0;
    double worst = 0.0, term = 0.0;
    /* the coordinate form, where the factor is kept, from 2,000 passive
     * columns (tk/nnls.h): here 3,800 to 5,300 struts from the first
     * step */
    for (int step = 0; step < 40; step++) {
        tk_curve *before = NULL;
        ck_assert_int_eq(tk_curve_copy(tk_run_curve(run), &before, NULL), TK_OK);
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
        const tk_step_report *s = tk_run_latest(run);
        ck_assert_uint_eq(s->kinks, 0);
        /* a corrected step too reports the contacts it was resolved
         * against, at the curve it started from */
        if (s->struts > 2000) {
            double w, t;
            forces_resolve(before, run, &w, &t);
            worst = fmin(worst, w);
            term = fmax(term, t);
            checked++;
        }
        tk_curve_free(&before);
    }
    printf("tight trefoil's forces at level 3: %d steps checked, worst rate %.3g of |a||v|, "
           "|(A f) . v| / |v|^2 at most %.3g\n", checked, worst, term);
    fflush(stdout);
    ck_assert_int_ge(checked, 20);
    ck_assert_msg(worst > -1e-3, "a contact shortened at %.3g of |a| |v|", worst);
    ck_assert_msg(term < 2e-4, "(A f) . v is %.3g of |v|^2", term);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_fine_tight_curve_polishes_at_the_rate_of_its_fall)
{
    /* The tight 600-vertex trefoil resumed at polishing level 2, where its
     * residual stays above the critical bound (1e-3): the ropelength falls
     * by about 1e-10 a step, far less than the level's bound (1e-4 / 9)
     * over its window of 733 steps, and the level ends after its first
     * 200 steps at that rate instead of waiting for the whole window. */
    tk_curve *c = test_data("trefoil-600.vect");
    tk_error err;
    tk_options o = TK_OPTIONS_INIT;
    o.coarse_to_fine = false;
    o.escapes = 0;
    tk_run *run = resumed_at_level(c, &o, 2);
    double start = tk_run_latest(run)->ropelength;
    const long steps = 215;
    long above = -1; /* the last step with a residual of 1e-3 or more */
    tk_resume now;
    tk_run_resume_point(run, &now);
    while (tk_run_latest(run)->step < steps && now.polish_level == 2) {
        ck_assert_int_eq(tk_run_step(run, &err), TK_OK);
        const tk_step_report *s = tk_run_latest(run);
        if (!(s->residual < 1e-3))
            above = s->step;
        tk_run_resume_point(run, &now);
    }
    const tk_step_report *last = tk_run_latest(run);
    printf("tight trefoil at 600 vertices from polishing level 2: level %d at step %ld, "
           "a residual of 1e-3 or more last at step %ld, ropelength %.9f -> %.9f\n",
           now.polish_level, last->step, above, start, last->ropelength);
    ck_assert_int_eq(now.polish_level, 3);
    ck_assert_int_ge(last->step, 200);
    /* not critical (20 steps below 1e-3): the fall's rate ended the level */
    ck_assert_int_ge(above, last->step - 20);
    ck_assert_msg(last->ropelength < start * (1.0 + 1e-6), "%.9f -> %.9f", start,
                  last->ropelength);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Where the active tolerance is reckoned from the edge (0.3 h^2 under the
 * options' tolerance: the 600-vertex trefoil's is 2.2e-4 against 3e-4)
 * polishing stops at the third level; with a smaller options' tolerance,
 * the same curve and the same rule for a level's end, the fourth comes.
 * Resumed at the third level, the rate of the fall ends it at step 236
 * (at 216 with the smaller tolerance) when it may end. */
START_TEST(polishing_stops_at_the_third_level_where_the_edge_sets_the_tolerance)
{
    tk_curve *c = test_data("trefoil-600.vect");
    tk_error err;
    const tk_options defaults = TK_OPTIONS_INIT;
    const double tolerances[] = {defaults.active_tolerance, 1e-4};
    const int expect[] = {3, 4};
    for (int k = 0; k < 2; k++) {
        tk_options o = TK_OPTIONS_INIT;
        o.coarse_to_fine = false;
        o.escapes = 0;
        o.active_tolerance = tolerances[k];
        tk_run *run = resumed_at_level(c, &o, 3);
        double start = tk_run_latest(run)->ropelength, h = start / (2.0 * 600.0);
        tk_resume now;
        tk_run_resume_point(run, &now);
        while (tk_run_latest(run)->step < 300 && now.polish_level == 3) {
            ck_assert_int_eq(tk_run_step(run, &err), TK_OK);
            tk_run_resume_point(run, &now);
        }
        printf("tight trefoil at 600 vertices, active tolerance %g (0.3 h^2 = %.3g), from "
               "polishing level 3: level %d at step %ld\n",
               o.active_tolerance, 0.3 * h * h, now.polish_level, tk_run_latest(run)->step);
        ck_assert_int_eq(now.polish_level, expect[k]);
        ck_assert_msg(tk_run_latest(run)->ropelength < start * (1.0 + 1e-6), "%.9f -> %.9f",
                      start, tk_run_latest(run)->ropelength);
        tk_run_free(&run);
    }
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_tight_curve_tightened_again_steps_at_a_bounded_cost)
{
    /* tests/data/trefoil-600.vect: catalogue 3.1 tightened at 600
     * vertices for 150 s (32.7460111; its run ended polished, with 1,040
     * struts).  Tightened again from scratch its active tolerance is the
     * unpolished one, which holds some 3,000 dependent struts on 1,800
     * coordinates, and the proximal rounds' smallest weights needed the
     * NNLS's fallback: 2,457 pivots and 175 factorisations a warm step
     * (now 144 and 32).  The motion must still balance the gradient (the
     * KKT residual) at a bounded count of pivots, and the run polish. */
    tk_curve *c = test_data("trefoil-600.vect");
    tk_error err;
    tk_options o = TK_OPTIONS_INIT;
    o.coarse_to_fine = false;
    o.escapes = 0;
    tk_run *run = NULL;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    double start = tk_run_latest(run)->ropelength;
    /* the first step is cold: every contact is new to the NNLS */
    ck_assert_int_eq(tk_run_step(run, &err), TK_OK);
    tk_run_timing before, after;
    tk_run_timing_get(run, &before);
    const int warm = 8;
    double worst_residual = 0.0;
    for (int k = 0; k < warm; k++) {
        ck_assert_int_eq(tk_run_step(run, &err), TK_OK);
        const tk_step_report *s = tk_run_latest(run);
        ck_assert_uint_ge(s->struts, 2500);
        worst_residual = fmax(worst_residual, s->residual);
    }
    tk_run_timing_get(run, &after);
    double pivots = (double)(after.nnls_iterations - before.nnls_iterations) / warm;
    double factorisations = (double)(after.factorisations - before.factorisations) / warm;
    double end = tk_run_latest(run)->ropelength;
    printf("tight trefoil at 600 vertices again: %.1f pivots and %.1f factorisations a warm "
           "step, residual at most %.3g, ropelength %.9f -> %.9f\n",
           pivots, factorisations, worst_residual, start, end);
    ck_assert_msg(pivots < 500.0, "%.1f pivots a step", pivots);
    ck_assert_msg(worst_residual < 1e-2, "residual %.3g", worst_residual);
    /* a critical point stays one: no step undoes the tightening */
    ck_assert_msg(end < start * (1.0 + 1e-5), "%.9f -> %.9f", start, end);
    /* Critical at its tolerance, the curve polishes without waiting for
     * the window of steps over which the ropelength all but stops falling
     * (733 steps at 600 vertices): 20 steps with residuals below 1e-3
     * (here from the first), then a third of the tolerance and fewer
     * struts (1,741 against 3,001). */
    long steps = 40;
    while (tk_run_latest(run)->step < steps)
        ck_assert_int_eq(tk_run_step(run, &err), TK_OK);
    tk_resume at;
    tk_run_resume_point(run, &at);
    const tk_step_report *last = tk_run_latest(run);
    printf("  after %ld steps: polishing level %d, %zu struts, ropelength %.9f\n", last->step,
           at.polish_level, last->struts, last->ropelength);
    ck_assert_int_ge(at.polish_level, 1);
    ck_assert_uint_lt(last->struts, 2000);
    ck_assert_msg(last->ropelength < start * (1.0 + 1e-5), "%.9f -> %.9f", start,
                  last->ropelength);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* tests/data/trefoil-600.vect (a tight trefoil) started at `vertices` on
 * its final polygon, autoscaled, with no escape; *given is the file's
 * measure, *m the run's start's.  The start must be at the tube (within
 * the correction tolerance) and in place: within 0.1% of the given
 * ropelength, as a polygon resampled from a tight one is. */
static tk_run *refined_trefoil(size_t vertices, tk_measure *given, tk_measure *m)
{
    tk_curve *c = test_data("trefoil-600.vect");
    tk_error err;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, given, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.coarse_to_fine = false;
    o.escapes = 0;
    o.vertices = vertices;
    tk_run *run = NULL;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    tk_curve_free(&c);
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, m, NULL), TK_OK);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, vertices);
    ck_assert_msg(m->thickness >= 1.0 - 3e-5, "thickness %.9f", m->thickness);
    ck_assert_msg(m->minrad >= 0.5 * (1.0 - 3e-5), "minrad %.9f", m->minrad);
    ck_assert_msg(fabs(m->ropelength / given->ropelength - 1.0) < 1e-3, "%.7f from %.7f",
                  m->ropelength, given->ropelength);
    return run;
}

START_TEST(a_tight_start_refined_and_autoscaled_keeps_its_contacts)
{
    /* tests/data/trefoil-600.vect (a tight trefoil, 32.7460111) started
     * at 1,200 vertices on its final polygon, autoscaled: the spline
     * through it cuts the tube where it bends at the curvature bound.
     * Scaled to the tube by the spline's thickness it was 7% loose
     * (35.03) and kept no contact; the start must instead be the polygon
     * at the tube, resampled, its few violations put back by Newton
     * steps. */
    tk_curve *c = test_data("trefoil-600.vect");
    tk_error err;
    tk_measure spline;
    tk_curve *fine = NULL;
    ck_assert_int_eq(tk_curve_resample_total(c, 1200, &fine, &err), TK_OK);
    ck_assert_int_eq(tk_thickness_measure(fine, NULL, &spline, NULL), TK_OK);
    tk_curve_free(&fine);
    tk_curve_free(&c);
    /* (what scaling by the spline's thickness would start from) */
    double scaled = 2.0 * spline.length / spline.thickness;
    tk_measure given, m;
    tk_run *run = refined_trefoil(1200, &given, &m);
    const tk_step_report *s = tk_run_latest(run);
    printf("tight trefoil 600 -> 1200: start %.7f with %zu struts (given %.7f; the spline "
           "scaled, %.7f)\n", m.ropelength, s->struts, given.ropelength, scaled);
    ck_assert_msg(scaled > given.ropelength * 1.01, "the spline only %.7f", scaled);
    /* (155 at the start's tolerance; scaled, none) */
    ck_assert_uint_ge(s->struts, 100);
    tk_run_free(&run);
}
END_TEST

START_TEST(a_tight_start_refined_sixteen_times_over_keeps_its_place)
{
    if (quick() && tkt_skip("a_tight_start_refined_sixteen_times_over_keeps_its_place",
                            LONG_RUN))
        return;
    /* The same trefoil started at 9,600 vertices: resampled to them at
     * once, the spline's violations were so many and the Newton steps on
     * them so stiff that 400 steps did not put them back, and the start
     * was scaled up to 34.05 (4% loose).  A polygon resampled from a
     * tight one is within 0.1% of its ropelength (the 1,200-vertex start
     * above: 0.003%); so must this start be, and feasible. */
    tk_measure given, m;
    tk_run *run = refined_trefoil(9600, &given, &m);
    printf("tight trefoil 600 -> 9600: start %.7f (given %.7f)\n", m.ropelength,
           given.ropelength);
    tk_run_free(&run);
}
END_TEST

START_TEST(a_refined_tight_polygon_is_restored_without_rescaling)
{
    if (quick() && tkt_skip("a_refined_tight_polygon_is_restored_without_rescaling", LONG_RUN))
        return;
    /* The generated figure-eight at 100 vertices, tightened until its
     * kinks sit at the curvature bound, resampled to 200 as a refinement
     * does: the spline cuts the tube at the kinks and between contacts.
     * The Newton steps on the violated constraints stall there (as
     * equations they contradict each other: one's repair undoes
     * another's) and the curve used to be scaled up by 1 + 3.4e-3,
     * losing every contact; the steps of the least-distance problem with
     * inequalities must restore it in place. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_figure_eight(100, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.escapes = 0;
    o.coarse_to_fine = false;
    o.max_steps = 2500;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    const tk_step_report *last = run_watched(run, &o, "figure-eight at 100 vertices", NULL);
    ck_assert_uint_ge(last->kinks, 3);
    double coarse = last->ropelength;
    tk_curve *fine = NULL;
    ck_assert_int_eq(tk_curve_resample_total(tk_run_curve(run), 200, &fine, &err), TK_OK);
    tk_run_free(&run);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(fine, NULL, &m, NULL), TK_OK);
    printf("resampled to 200: thickness %.6f, minrad %.6f\n", m.thickness, m.minrad);
    ck_assert(m.thickness < 0.995);
    /* a start may overstep this far: its recovery is what is tested */
    tk_options p = TK_OPTIONS_INIT;
    p.overstep_tolerance = 0.09;
    p.max_steps = 1;
    ck_assert_msg(tk_run_new(fine, &p, &run, &err) == TK_OK, "%s", err.message);
    tk_run_timing t;
    tk_run_timing_get(run, &t);
    ck_assert_int_eq(t.rescales, 0);
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL), TK_OK);
    /* within the correction tolerance (3e-5) of the diameter and bound */
    ck_assert_msg(m.thickness >= 1.0 - 3e-5, "thickness %.9f", m.thickness);
    ck_assert_msg(m.minrad >= 0.5 * (1.0 - 3e-5), "minrad %.9f", m.minrad);
    /* in place: the recovery lengthens the fine polygon (the spline
     * through the coarse one is 0.17% longer than it; the flow takes that
     * off later) by far less than the scaling did (0.34%) */
    double before = 2.0 * tk_curve_length(fine);
    double rope = 2.0 * tk_curve_length(tk_run_curve(run)) / m.thickness;
    printf("restored in %d corrections: ropelength %.6f from %.6f (coarse %.6f)\n",
           tk_run_latest(run)->corrections, rope, before, coarse);
    ck_assert_msg(fabs(rope / before - 1.0) < 1e-3, "ropelength %.6f against %.6f", rope, before);
    tk_run_free(&run);
    tk_curve_free(&fine);
    tk_curve_free(&c);
}
END_TEST

START_TEST(a_loose_curve_is_kept_at_the_tube)
{
    /* A long thin ellipse, autoscaled: its thickness is the curvature at
     * the ends of its major axis, and shortening rounds those ends, so
     * the curve grows thicker than the tube as it shrinks.  With
     * autoscale a curve thicker than the start's margin is scaled down to
     * it before the next step: each step's length is then at most the
     * last one's scaled by margin * diameter / thickness (a step only
     * shortens, its recovery lengthens by far less than 1e-4).  Free
     * shortening would keep the length within a step's reach of the
     * last, far above that bound once the thickness has grown. */
    tk_curve *c = tkt_regular_polygon(80, 1.0);
    for (size_t k = 0; k < c->nvert; k++) {
        c->xyz[3 * k] *= 10.0;
        c->xyz[3 * k + 1] *= 0.8;
    }
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.escapes = 0;
    o.coarse_to_fine = false;
    o.max_steps = 300;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    double bound = o.autoscale_margin * 2.0 * o.radius, thickest = 0.0;
    int scaled = 0;
    tk_step_report last = *tk_run_latest(run);
    for (long k = 0; k < o.max_steps; k++) {
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
        const tk_step_report *s = tk_run_latest(run);
        if (last.thickness > bound * (1.0 + 1e-3)) {
            scaled++;
            double most = last.length * bound / last.thickness * (1.0 + 1e-4);
            ck_assert_msg(s->length <= most, "step %ld: length %.9g after %.9g at thickness %.6g",
                          s->step, s->length, last.length, last.thickness);
        }
        thickest = fmax(thickest, s->thickness);
        last = *s;
    }
    printf("loose ellipse: %d steps began thicker than the margin (thickest %.4f), "
           "ropelength %.4f\n", scaled, thickest, last.ropelength);
    ck_assert_int_ge(scaled, 3);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(unknot_and_unlink_are_handled)
{
    /* A single round ring (the unknot) and two separate rings: no
     * contacts at all, so the flow is pure curve shortening until the
     * curvature bound holds it. */
    tk_curve *ring = tkt_regular_polygon(40, 5.0);
    tk_options o = TK_OPTIONS_INIT;
    o.max_steps = quick() ? 30 : 400;
    tk_stop_reason why;
    double rope = tighten(ring, &o, "unknot", &why);
    ck_assert(why != TK_STOP_FAILED);
    /* it can only get shorter, and never below the round circle's 2 pi
     * (a curve of curvature <= 2/tau has length >= pi tau) */
    ck_assert(rope >= 2 * M_PI * 0.999);
    tk_curve_free(&ring);
    if (!tkt_catalogue_dir())
        return;
    tk_curve *unlink = tkt_catalogue_curve("0.2.1.vect");
    o.autoscale = true;
    rope = tighten(unlink, &o, "unlink", &why);
    ck_assert(why != TK_STOP_FAILED);
    tk_curve_free(&unlink);
}
END_TEST

START_TEST(start_thinner_than_tube_is_refused)
{
    tk_curve *c = tkt_regular_polygon(30, 0.2);
    tk_options o = TK_OPTIONS_INIT;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert(strstr(err.message, "autoscale") != NULL);
    ck_assert(run == NULL);
    o.radius = -1;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert(strstr(err.message, "radius") != NULL);
    tk_curve_free(&c);
}
END_TEST

/* A run larger than TK_RUN_MAX_VERTICES is refused before it takes the
 * memory: as a start, and as a resolution's resampling. */
START_TEST(runs_beyond_the_vertex_limit_are_refused)
{
    tk_curve *big = tkt_regular_polygon(TK_RUN_MAX_VERTICES + 1, 1e6);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(big, &o, &run, &err), TK_ELIMIT);
    ck_assert_msg(strstr(err.message, "at most") != NULL, "%s", err.message);
    ck_assert(run == NULL);
    tk_curve_free(&big);
    /* T(3,7), ropelength above 100: resolution 1e4 asks for over a million */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(3, 7, 300, &c, NULL), TK_OK);
    o.resolution = 1e4;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_ELIMIT);
    ck_assert_msg(strstr(err.message, "asks for") != NULL, "%s", err.message);
    /* just inside: a resolution that asks for fewer runs */
    o.resolution = 5;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_uint_le(tk_run_curve(run)->nvert, TK_RUN_MAX_VERTICES);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(radius_out_of_the_range_is_refused)
{
    /* A radius of 1e300 with autoscale once scaled the curve past
     * overflow, and the contact search then never ended. */
    tk_curve *c = tkt_regular_polygon(16, 10.0);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    tk_run *run = NULL;
    tk_error err;
    const double refused[] = {1e300, 1.01e30, 0.99e-30, INFINITY, NAN};
    for (size_t k = 0; k < sizeof refused / sizeof *refused; k++) {
        o.radius = refused[k];
        ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, "option 'radius': must be from 1e-30 to 1e+30"), "%s",
                      err.message);
        ck_assert(run == NULL);
    }
    /* In range, but the autoscaled curve is not: a 16-gon's thickness is
     * about a fifth of its extent, so scaling it to a radius of 1e30 puts
     * its vertices near 1e31. */
    o.radius = 1e30;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "autoscale to radius 1e+30") &&
                      strstr(err.message, "beyond the +-1e+30"),
                  "%s", err.message);
    /* Both ends of the range themselves run, and the scale does not change
     * the figures: the same steps at radius 1e-29, 1e28 and 0.5, of a
     * trefoil.  (Not of the 16-gon: its 16 vertices, all alike, are
     * within the kinks' active tolerance from the first step, and which of
     * the NNLS answers to 32 near-dependent constraints a step takes is
     * left to rounding: after 5 steps 6.37616, 6.37612 and 6.37260.) */
    double rope[3];
    const double radii[3] = {1e-29, 1e28, 0.5};
    o.max_steps = 5;
    tk_curve *knot = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 60, &knot, NULL), TK_OK);
    for (int k = 0; k < 3; k++) {
        o.radius = radii[k];
        ck_assert_msg(tk_run_new(knot, &o, &run, &err) == TK_OK, "%s", err.message);
        tk_stop_reason why;
        ck_assert_msg(tk_run_until(run, &why, &err) == TK_OK, "%s", err.message);
        rope[k] = tk_run_latest(run)->ropelength;
        tk_run_free(&run);
    }
    ck_assert_msg(tkt_reldiff(rope[0], rope[2]) < 1e-4 && tkt_reldiff(rope[1], rope[2]) < 1e-4,
                  "ropelength %.15g %.15g %.15g", rope[0], rope[1], rope[2]);
    tk_curve_free(&knot);
    tk_curve_free(&c);
}
END_TEST

START_TEST(resampling_that_crosses_the_curve_is_refused)
{
    /* A regular 16-gon of radius 10 with one vertex pulled out to 28: the
     * spline through it loops past the spike through the polygon, and the
     * run once started from that curve (ropelength 1e17) or failed in
     * error recovery ("violated by 0.75 of the diameter"), a 500. */
    tk_curve *c = tkt_regular_polygon(16, 10.0);
    double *spike = tk_curve_vertex(c, 14);
    for (int k = 0; k < 3; k++)
        spike[k] *= 2.8;
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 3;
    tk_run *run = NULL;
    tk_error err;
    const double resolutions[] = {1, 2, 5};
    for (size_t k = 0; k < 3; k++) {
        o.resolution = resolutions[k];
        ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, "(nearly) cross itself"), "%s", err.message);
        ck_assert(run == NULL);
    }
    /* The polygon itself is thick enough and runs. */
    o.resolution = 0.0;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    tk_stop_reason why;
    ck_assert_int_eq(tk_run_until(run, &why, &err), TK_OK);
    ck_assert(tk_run_latest(run)->thickness >= 1.0 * (1 - o.overstep_tolerance));
    tk_run_free(&run);
    tk_curve_free(&c);
    /* Too thin to tighten in double precision, without resampling: the
     * top vertex of a 16-gon pulled down to 1e-9 above the bottom one
     * (ropelength about 3e11). */
    c = tkt_regular_polygon(16, 10.0);
    double *top = tk_curve_vertex(c, 4);
    const double *bottom = tk_curve_vertex(c, 12);
    top[0] = bottom[0];
    top[1] = bottom[1] + 1e-9;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "too thin for its length") && strstr(err.message, "1e+09"),
                  "%s", err.message);
    tk_curve_free(&c);
}
END_TEST

START_TEST(an_autoscaled_rope_shorter_than_its_diameter_is_refused)
{
    /* Four vertices of an open rope on a line but for a rounding (as
     * settling its ends on planes left them): its thickness is set by the
     * turning at a vertex, that is by rounding, about 1e16 times its
     * length.  Autoscaled, it once shrank to a length of 1.3e-16, and a
     * step of size 0 took its thickness from 1.002 to 0.405 of the
     * diameter.  (Exactly on the line, its thickness is infinite and it
     * is refused for that.) */
    size_t n = 4;
    bool closed = false;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &closed, NULL), TK_OK);
    const double along[] = {0.0, 2.0 / 4096, 1.0, 14000.0 / 4096};
    for (size_t i = 0; i < n; i++)
        tk_curve_vertex(c, i)[0] = along[i];
    tk_curve_vertex(c, 1)[1] = 1e-19;
    tk_options o = TK_OPTIONS_INIT;
    o.max_steps = 3;
    tk_run *run = NULL;
    tk_error err;
    o.autoscale = true;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "shorter than its own tube's diameter"), "%s", err.message);
    ck_assert(run == NULL);
    /* At its own scale it runs (a rope pulled straight between two planes
     * is a tight one, tests/cli-tighten.sh), its thickness held. */
    o.autoscale = false;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    tk_stop_reason why;
    ck_assert_msg(tk_run_until(run, &why, &err) == TK_OK, "%s", err.message);
    ck_assert(tk_run_latest(run)->thickness >= 1.0 * (1 - o.overstep_tolerance));
    tk_run_free(&run);
    /* Bent by a right angle at its third vertex, the same rope has its
     * thickness from that turn (a ropelength about 7): autoscaled, it runs
     * with its thickness held. */
    double *v = tk_curve_vertex(c, 3);
    v[0] = 1.0;
    v[1] = 14000.0 / 4096 - 1.0;
    o.autoscale = true;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    ck_assert_msg(tk_run_until(run, &why, &err) == TK_OK, "%s", err.message);
    ck_assert_msg(tk_run_latest(run)->ropelength >= 2.0, "%.17g", tk_run_latest(run)->ropelength);
    ck_assert(tk_run_latest(run)->thickness >= 1.0 * (1 - o.overstep_tolerance));
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

typedef struct cancel_case {
    tk_run *run;
    long steps_at_cancel;
    long steps_after;
    pthread_mutex_t lock;
    long steps;
} cancel_case;

static int count_step(const tk_step_report *s, void *user)
{
    cancel_case *cc = user;
    pthread_mutex_lock(&cc->lock);
    cc->steps = s->step;
    pthread_mutex_unlock(&cc->lock);
    return 0;
}

static void *run_thread(void *arg)
{
    cancel_case *cc = arg;
    tk_stop_reason why;
    tk_run_until(cc->run, &why, NULL);
    ck_assert(why == TK_STOP_CANCELLED);
    return NULL;
}

START_TEST(cancellation_stops_within_one_step)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 5, 200, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    cancel_case cc = {0};
    pthread_mutex_init(&cc.lock, NULL);
    ck_assert_int_eq(tk_run_new(c, &o, &cc.run, NULL), TK_OK);
    tk_run_set_progress(cc.run, count_step, &cc);
    pthread_t th;
    pthread_create(&th, NULL, run_thread, &cc);
    /* let it take a few steps, then cancel from this thread */
    for (;;) {
        pthread_mutex_lock(&cc.lock);
        long s = cc.steps;
        pthread_mutex_unlock(&cc.lock);
        if (s >= 3)
            break;
        struct timespec ts = {0, 1000000};
        nanosleep(&ts, NULL);
    }
    pthread_mutex_lock(&cc.lock);
    long at_cancel = cc.steps;
    tk_run_cancel(cc.run);
    pthread_mutex_unlock(&cc.lock);
    pthread_join(th, NULL);
    /* the step in progress when the flag was set may finish; no more */
    ck_assert_int_le(tk_run_latest(cc.run)->step, at_cancel + 1);
    ck_assert(tk_run_stop_reason(cc.run) == TK_STOP_CANCELLED);
    tk_run_free(&cc.run);
    pthread_mutex_destroy(&cc.lock);
    tk_curve_free(&c);
}
END_TEST

typedef struct parallel_case {
    const tk_curve *start;
    tk_options opt;
    double *final_xyz;
    size_t n;
    double rope;
} parallel_case;

static void *parallel_run(void *arg)
{
    parallel_case *pc = arg;
    tk_run *run = NULL;
    if (tk_run_new(pc->start, &pc->opt, &run, NULL) != TK_OK)
        return NULL;
    tk_run_until(run, NULL, NULL);
    const tk_curve *c = tk_run_curve(run);
    pc->n = 3 * c->nvert;
    pc->final_xyz = malloc(pc->n * sizeof(double));
    memcpy(pc->final_xyz, c->xyz, pc->n * sizeof(double));
    pc->rope = tk_run_latest(run)->ropelength;
    tk_run_free(&run);
    return NULL;
}

START_TEST(parallel_runs_equal_serial_runs)
{
    tk_curve *a = NULL, *b = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 90, &a, NULL), TK_OK);
    ck_assert_int_eq(tk_generate_chain(2, 40, &b, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = quick() ? 15 : 60;
    parallel_case serial[2] = {{a, o, NULL, 0, 0}, {b, o, NULL, 0, 0}};
    parallel_case threaded[2] = {{a, o, NULL, 0, 0}, {b, o, NULL, 0, 0}};
    parallel_run(&serial[0]);
    parallel_run(&serial[1]);
    pthread_t t[2];
    for (int i = 0; i < 2; i++)
        pthread_create(&t[i], NULL, parallel_run, &threaded[i]);
    for (int i = 0; i < 2; i++)
        pthread_join(t[i], NULL);
    for (int i = 0; i < 2; i++) {
        ck_assert(serial[i].final_xyz && threaded[i].final_xyz);
        ck_assert_uint_eq(serial[i].n, threaded[i].n);
        ck_assert(memcmp(serial[i].final_xyz, threaded[i].final_xyz,
                         serial[i].n * sizeof(double)) == 0);
        ck_assert(serial[i].rope == threaded[i].rope);
        free(serial[i].final_xyz);
        free(threaded[i].final_xyz);
    }
    tk_curve_free(&a);
    tk_curve_free(&b);
}
END_TEST

START_TEST(history_and_snapshots)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 100, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 25;
    o.snapshot_every = 10;
    tk_run *run = NULL;
    ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK);
    tk_stop_reason why;
    ck_assert_int_eq(tk_run_until(run, &why, NULL), TK_OK);
    ck_assert(why == TK_STOP_STEPS);
    size_t n;
    const tk_step_report *h = tk_run_history(run, &n);
    ck_assert_uint_eq(n, 26); /* the start and 25 steps */
    for (size_t k = 0; k < n; k++)
        ck_assert_int_eq(h[k].step, (long)k);
    /* the flow shortens: ropelength after 25 steps is below the start */
    ck_assert(h[n - 1].ropelength < h[0].ropelength);
    ck_assert_uint_eq(tk_run_snapshot_count(run), 3); /* steps 0, 10, 20 */
    long step;
    const double *snap = tk_run_snapshot(run, 2, &step);
    ck_assert(snap != NULL && step == 20);
    ck_assert(tk_run_snapshot(run, 3, NULL) == NULL);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

START_TEST(corrected_steps_report_their_forces)
{
    /* A step that needed error recovery still reports the struts it was
     * resolved against, with their NNLS forces: the forces balance the
     * gradient (residual < 1), so with struts active some force is
     * positive. */
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 120, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    tk_run *run = NULL;
    ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK);
    int checked = 0;
    for (int step = 0; step < (quick() ? 150 : 600) && checked < 5; step++) {
        ck_assert_int_eq(tk_run_step(run, NULL), TK_OK);
        const tk_step_report *s = tk_run_latest(run);
        size_t ns = 0;
        const tk_strut *struts = tk_run_struts(run, &ns);
        ck_assert_uint_eq(ns, s->struts);
        if (s->corrections == 0 || ns == 0 || !(s->residual < 0.99))
            continue;
        double largest = 0.0;
        for (size_t k = 0; k < ns; k++) {
            ck_assert(struts[k].force >= 0.0);
            largest = fmax(largest, struts[k].force);
        }
        ck_assert_msg(largest > 0.0, "step %ld: %zu struts after %d corrections, all forces 0",
                      s->step, ns, s->corrections);
        checked++;
    }
    ck_assert_msg(checked > 0, "no corrected step with struts to check");
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

static double clock_seconds(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double wall_seconds(void)
{
    return clock_seconds(CLOCK_MONOTONIC);
}

/* The timing figures add up: the operations and the rooms fit in the
 * total, which is the run's own share of the wall time measured outside
 * it (all of it but the loop between steps). */
START_TEST(timing_accounts_for_the_run)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(3, 48, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = quick() ? 40 : 150;
    double t0 = wall_seconds(), cpu0 = clock_seconds(CLOCK_THREAD_CPUTIME_ID);
    tk_run *run = NULL;
    ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK);
    ck_assert_int_eq(tk_run_until(run, NULL, NULL), TK_OK);
    double wall = wall_seconds() - t0, cpu = clock_seconds(CLOCK_THREAD_CPUTIME_ID) - cpu0;
    tk_run_timing t;
    tk_run_timing_get(run, &t);
    printf("timing: total %.4f of %.4f s: search %.4f, matrix %.4f, nnls %.4f (%ld solves, %ld "
           "iterations, %ld factorisations), checks %.4f, stepping %.4f, recovery %.4f\n",
           t.total, wall, t.search, t.matrix, t.nnls, t.nnls_solves, t.nnls_iterations,
           t.factorisations, t.checks, t.stepping, t.recovery);
    printf("timing: the knot type (start and result) %.4f s\n", t.invariants);
    double parts[] = {t.search, t.matrix, t.nnls, t.checks, t.stepping, t.recovery, t.invariants};
    for (size_t k = 0; k < sizeof parts / sizeof parts[0]; k++)
        ck_assert(parts[k] > 0.0 && parts[k] <= t.total);
    ck_assert(t.search + t.matrix + t.nnls + t.checks <= t.total);
    ck_assert(t.stepping + t.recovery <= t.total);
    /* the run's own clock (the wall's) misses little of its work: against
     * the processor time outside, which a busy machine's stalls between
     * the timed parts do not inflate as they do the wall time */
    ck_assert(t.total <= wall && t.total >= 0.5 * cpu);
    /* every step with constraints solves at least once */
    size_t nh = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    long constrained = 0;
    for (size_t i = 1; i < nh; i++)
        constrained += h[i].struts + h[i].kinks > 0;
    ck_assert_int_ge(t.nnls_solves, constrained / 2);
    ck_assert_int_ge(t.factorisations, 1);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Sleeps SLEEP_MS after every step: wall time the run's thread spends
 * without its processor. */
#define SLEEP_MS 3
static int sleep_step(const tk_step_report *s, void *user)
{
    (void)s;
    (*(long *)user)++;
    nanosleep(&(struct timespec){0, SLEEP_MS * 1000000L}, NULL);
    return 0;
}

/* A time budget on the run's own processor time: with cpu_time the
 * seconds the run reports and stops at leave out the wall time its thread
 * slept (a busy machine's other work), and a resumed run goes on from the
 * seconds it had spent; without it they are the wall clock's.  Measured
 * against the wall clock outside the run and the sleeps counted. */
START_TEST(cpu_time_counts_the_run_s_own_processor_time)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(3, 48, &c, NULL), TK_OK);
    const double budget = 0.3;
    for (int cpu = 0; cpu <= 1; cpu++) {
        tk_options o = TK_OPTIONS_INIT;
        o.autoscale = true;
        o.max_seconds = budget;
        o.cpu_time = cpu;
        long steps = 0;
        double t0 = wall_seconds();
        tk_run *run = NULL;
        ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK);
        tk_run_set_progress(run, sleep_step, &steps);
        tk_stop_reason why;
        ck_assert_int_eq(tk_run_until(run, &why, NULL), TK_OK);
        double wall = wall_seconds() - t0, slept = 1e-3 * SLEEP_MS * (double)steps;
        const tk_step_report *s = tk_run_latest(run);
        printf("cpu_time %d: stopped at %.3f s reported, %.3f s of wall time, %.3f s slept, "
               "%ld steps\n", cpu, s->seconds, wall, slept, steps);
        ck_assert_int_eq(why, TK_STOP_TIME);
        ck_assert(s->seconds >= budget);
        if (cpu) {
            /* the sleeps are not counted: the run took its budget besides them */
            ck_assert(wall >= budget + slept);
            ck_assert(s->seconds <= wall - slept + 0.05);
            /* resumed, it goes on from its seconds and spends the rest */
            tk_resume at;
            tk_run_resume_point(run, &at);
            ck_assert(at.seconds == s->seconds);
            tk_run *again = NULL;
            tk_options more = o;
            more.max_seconds = s->seconds + 0.1;
            ck_assert_int_eq(tk_run_resume(tk_run_curve(run), &more, &at, NULL, NULL,
                                           tk_run_type_start(run), &again, NULL),
                             TK_OK);
            ck_assert(tk_run_latest(again)->seconds >= s->seconds);
            ck_assert(tk_run_latest(again)->seconds < s->seconds + 0.05);
            ck_assert_int_eq(tk_run_until(again, &why, NULL), TK_OK);
            ck_assert_int_eq(why, TK_STOP_TIME);
            ck_assert(tk_run_latest(again)->seconds >= more.max_seconds);
            tk_run_free(&again);
        } else {
            /* the wall clock counts them: the run stopped at its first step
             * past its budget of wall time (however long a busy machine made
             * that step), or at its start where a busy machine's setting up
             * took the budget (seen beside the service's suites) */
            size_t nh = 0;
            const tk_step_report *h = tk_run_history(run, &nh);
            ck_assert(s->seconds <= wall);
            ck_assert_uint_ge(nh, 1);
            if (nh == 1) {
                ck_assert_int_eq(s->step, 0);
            } else {
                ck_assert_int_eq(h[nh - 2].step, s->step - 1);
                ck_assert(h[nh - 2].seconds < budget);
            }
        }
        tk_run_free(&run);
    }
    tk_curve_free(&c);
}
END_TEST

/* A thread that keeps the caches and the memory bus busy (the load that
 * cost a time-budgeted run a sixth of its steps beside other runs) until
 * told to stop. */
typedef struct {
    atomic_int stop;
    double sum;
} load_state;

static void *load_memory(void *arg)
{
    load_state *l = arg;
    size_t n = (size_t)1 << 22; /* 32 MB of doubles */
    double *buf = calloc(n, sizeof *buf);
    for (unsigned pass = 0; buf && !atomic_load(&l->stop); pass++)
        for (size_t i = 0; i < n; i += 8)
            buf[i] += (double)pass, l->sum += buf[i];
    free(buf);
    return NULL;
}

/* One run of `c` to a work budget; its history and curve into *h, *nh
 * and *out (the caller frees them). */
static void run_to_work(const tk_curve *c, const tk_options *o, bool sleepy,
                        tk_step_report **h, size_t *nh, tk_curve **out)
{
    tk_run *run = NULL;
    long steps = 0;
    ck_assert_int_eq(tk_run_new(c, o, &run, NULL), TK_OK);
    if (sleepy)
        tk_run_set_progress(run, sleep_step, &steps);
    tk_stop_reason why;
    ck_assert_int_eq(tk_run_until(run, &why, NULL), TK_OK);
    ck_assert_int_eq(why, TK_STOP_WORK);
    const tk_step_report *hist = tk_run_history(run, nh);
    *h = malloc(*nh * sizeof **h);
    memcpy(*h, hist, *nh * sizeof **h);
    ck_assert_int_eq(tk_curve_copy(tk_run_curve(run), out, NULL), TK_OK);
    printf("work budget %.2f: %zu steps, work %.4f in %.3f s, ropelength %.6f%s\n", o->max_work,
           *nh - 1, (*h)[*nh - 1].work, (*h)[*nh - 1].seconds, (*h)[*nh - 1].ropelength,
           sleepy ? " (sleeping 3 ms a step, memory loaded)" : "");
    tk_run_free(&run);
}

/* A budget of work names one run: the same start and options tighten
 * step for step alike, bit for bit, whether the run has the machine to
 * itself or sleeps after every step while another thread loads the
 * memory (a time budget, wall or processor, ends elsewhere under such
 * load).  The work counts up with every step, and the run stops at the
 * first step that reaches the budget; a resumed run goes on from the work
 * it had done. */
START_TEST(a_work_budget_gives_the_same_run_at_any_load)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 120, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5.0;
    o.max_work = 1.5;
    tk_step_report *ha = NULL, *hb = NULL;
    size_t na = 0, nb = 0;
    tk_curve *a = NULL, *b = NULL;
    run_to_work(c, &o, false, &ha, &na, &a);
    load_state load = {.sum = 0.0};
    atomic_init(&load.stop, 0);
    pthread_t loader;
    ck_assert_int_eq(pthread_create(&loader, NULL, load_memory, &load), 0);
    run_to_work(c, &o, true, &hb, &nb, &b);
    atomic_store(&load.stop, 1);
    pthread_join(loader, NULL);
    /* through the coarse levels, whose shares the budget sets */
    ck_assert_uint_ge(na, 100);
    ck_assert_uint_lt(ha[0].vertices, ha[na - 1].vertices);
    ck_assert_uint_eq(na, nb);
    for (size_t k = 0; k < na; k++) {
        ck_assert_msg(ha[k].ropelength == hb[k].ropelength && ha[k].work == hb[k].work &&
                          ha[k].vertices == hb[k].vertices,
                      "step %ld: ropelength %.17g against %.17g, work %.17g against %.17g",
                      ha[k].step, ha[k].ropelength, hb[k].ropelength, ha[k].work, hb[k].work);
        if (k > 0)
            ck_assert(ha[k].work >= ha[k - 1].work);
    }
    ck_assert_uint_eq(a->nvert, b->nvert);
    ck_assert(!memcmp(a->xyz, b->xyz, 3 * a->nvert * sizeof *a->xyz));
    /* the first step at the budget stops it */
    ck_assert(ha[na - 1].work >= o.max_work);
    ck_assert(ha[na - 2].work < o.max_work);
    /* a resumed run counts on from the work done */
    tk_run *run = NULL;
    ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK);
    for (int k = 0; k < 50; k++)
        ck_assert_int_eq(tk_run_step(run, NULL), TK_OK);
    tk_resume at;
    tk_run_resume_point(run, &at);
    ck_assert(at.work == tk_run_latest(run)->work && at.work > 0.0);
    tk_run *again = NULL;
    ck_assert_int_eq(tk_run_resume(tk_run_curve(run), &o, &at, NULL, NULL,
                                   tk_run_type_start(run), &again, NULL),
                     TK_OK);
    ck_assert(tk_run_latest(again)->work >= at.work);
    ck_assert_int_eq(tk_run_step(again, NULL), TK_OK);
    ck_assert(tk_run_latest(again)->work > at.work);
    tk_run_free(&again);
    tk_run_free(&run);
    free(ha);
    free(hb);
    tk_curve_free(&a);
    tk_curve_free(&b);
    tk_curve_free(&c);
}
END_TEST

/* The type is checked where the flow's constraints do not hold it: a
 * trefoil resampled to 4 vertices is an unknot, and the run is refused
 * with the reason; a run that keeps its type reports it, start and
 * result. */
START_TEST(the_knot_type_is_checked)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 120, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 0.1;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_ETYPE);
    ck_assert_ptr_null(run);
    ck_assert_msg(strstr(err.message, "resampling to 4 vertices") != NULL &&
                      strstr(err.message, "Alexander polynomial was 1 - t + t^2, now 1") != NULL,
                  "%s", err.message);
    tk_curve_free(&c);

    ck_assert_int_eq(tk_generate_chain(3, 40, &c, NULL), TK_OK);
    o.resolution = 0.0;
    o.max_steps = 30;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    const tk_invariants *start = tk_run_type_start(run);
    ck_assert_ptr_eq(tk_run_type_latest(run), start); /* nothing checked yet */
    ck_assert_int_eq(tk_run_until(run, NULL, &err), TK_OK);
    const tk_invariants *result = tk_run_type_latest(run);
    ck_assert_ptr_ne(result, start);
    ck_assert(result->complete && start->complete);
    ck_assert_int_eq(tk_invariants_compare(start, result, &err), TK_OK);
    /* neighbours link once, the ends not at all */
    ck_assert_int_eq(labs(result->linking[0 * 3 + 1]), 1);
    ck_assert_int_eq(labs(result->linking[1 * 3 + 2]), 1);
    ck_assert_int_eq(result->linking[0 * 3 + 2], 0);
    for (size_t k = 0; k < 3; k++)
        ck_assert_int_eq(result->knot[k].determinant, 1);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Escapes: a converged Hopf link deformed and tightened again; the run
 * returns the best curve it found (no tighter curve in its log), feasible,
 * at its own vertex count, with its type; the same seed gives the same
 * run bit for bit, in any thread. */
static tk_run *escaping_run(unsigned long long seed)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(2, 40, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.escapes = 2;
    o.seed = seed;
    o.max_steps = 3000; /* its escapes start after steps 627 and 1315 */
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s", err.message);
    tk_curve_free(&c);
    return run;
}

START_TEST(escapes_keep_the_best_and_repeat)
{
    tk_run *a = escaping_run(7), *b = escaping_run(7), *other = escaping_run(8);
    size_t ne = 0;
    const tk_escape *e = tk_run_escapes(a, &ne);
    ck_assert_uint_ge(ne, 1);
    const tk_step_report *end = tk_run_latest(a);
    ck_assert_int_eq(end->escapes, (int)ne);
    for (size_t k = 0; k < ne; k++) {
        printf("escape %zu after step %ld: from %.6f, amplitude %.4f, reached %.6f\n", k,
               e[k].step, e[k].from, e[k].amplitude, e[k].reached);
        ck_assert(e[k].turned ? e[k].amplitude == 0.0
                              : e[k].amplitude > 0.0 && e[k].amplitude <= 1.0);
        ck_assert(end->ropelength <= e[k].from * (1.0 + 1e-12));
        if (!isnan(e[k].reached))
            ck_assert(end->ropelength <= e[k].reached * (1.0 + 1e-12));
        ck_assert_int_eq(e[k].improved, e[k].reached < e[k].from);
    }
    /* the curve returned is the lowest of every step's (the run has one
     * polygon), not only of those where a try was judged */
    size_t nh = 0;
    double low = lowest_step(a, &nh);
    printf("returned %.9f, lowest of %zu steps %.9f\n", end->ropelength, nh, low);
    ck_assert_msg(end->ropelength <= low * (1.0 + 1e-12), "%.12f above %.12f",
                  end->ropelength, low);
    /* measured independently: feasible, at the start's vertex count */
    const tk_curve *c = tk_run_curve(a);
    ck_assert_uint_eq(c->nvert, 80);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    ck_assert(m.thickness >= 1.0 - 1e-5);
    ck_assert(fabs(m.ropelength - end->ropelength) <= 1e-9 * end->ropelength);
    tk_error err;
    ck_assert_int_eq(tk_invariants_compare(tk_run_type_start(a), tk_run_type_latest(a), &err),
                     TK_OK);
    /* the same seed, the same run; another seed, another */
    const tk_curve *cb = tk_run_curve(b), *co = tk_run_curve(other);
    ck_assert_uint_eq(cb->nvert, c->nvert);
    ck_assert(memcmp(c->xyz, cb->xyz, 3 * c->nvert * sizeof *c->xyz) == 0);
    /* (its escapes deform differently: the first turns about the
     * centroid whatever the seed, the second deforms at random; the curve
     * returned is the same when neither improved on the first tightening) */
    size_t no = 0;
    const tk_escape *eo = tk_run_escapes(other, &no);
    ck_assert_uint_ge(ne, 2);
    ck_assert_uint_ge(no, 2);
    ck_assert(e[0].turned && eo[0].turned && !e[1].turned && !eo[1].turned);
    ck_assert(!isnan(e[1].reached) && !isnan(eo[1].reached));
    ck_assert(eo[1].reached != e[1].reached || eo[1].amplitude != e[1].amplitude ||
              co->nvert != c->nvert ||
              memcmp(c->xyz, co->xyz, 3 * c->nvert * sizeof *c->xyz) != 0);
    tk_run_free(&a);
    tk_run_free(&b);
    tk_run_free(&other);
}
END_TEST

/* A run stopped after `steps` and resumed from its resume point, curve,
 * best curve and start type, as a process that ended would; returns the
 * resumed run (the first is freed) and its resume point in *at. */
static tk_run *interrupted(tk_run *first, long steps, tk_resume *at)
{
    tk_error err;
    while (tk_run_latest(first)->step < steps)
        ck_assert_msg(tk_run_step(first, &err) == TK_OK, "%s", err.message);
    tk_run_resume_point(first, at);
    /* the point is a record within its domains */
    for (size_t i = 0; i < tk_resume_nfields; i++) {
        tk_resume copy = *at;
        ck_assert_int_eq(tk_field_set(&tk_resume_fields[i], &copy,
                                      tk_field_get(&tk_resume_fields[i], at), NULL),
                         TK_OK);
    }
    tk_step_report best_report;
    const tk_curve *best = tk_run_best(first, &best_report);
    tk_run *second = NULL;
    ck_assert_msg(tk_run_resume(tk_run_curve(first), tk_run_options(first), at, best,
                                best ? &best_report : NULL, tk_run_type_start(first), &second,
                                &err) == TK_OK,
                  "%s", err.message);
    tk_run_free(&first);
    return second;
}

/* Resumed mid-schedule, a coarse to fine run goes on at its level and
 * within its budget: it ends on the final polygon at the step budget,
 * its steps numbered on from where it stopped, as the run that went
 * through ends. */
START_TEST(a_resumed_run_goes_on_where_it_was)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.max_steps = 400;
    o.loose = 0; /* its levels counted below */
    tk_run *through = NULL, *first = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &through, &err), TK_OK);
    ck_assert_int_eq(tk_run_until(through, NULL, &err), TK_OK);
    ck_assert_int_eq(tk_run_new(c, &o, &first, &err), TK_OK);
    size_t coarse = tk_run_curve(first)->nvert;
    tk_resume at;
    tk_run *second = interrupted(first, 60, &at);
    ck_assert_int_eq(at.step, 60);
    ck_assert_int_eq(at.coarse_level, 1);
    ck_assert(at.step_size > 0.0 && at.start_ropelength > 0.0);
    const tk_step_report *start = tk_run_latest(second);
    ck_assert_int_eq(start->step, 60);
    ck_assert(start->seconds >= at.seconds);
    /* the flow's time is the step sizes summed, and goes on from there */
    size_t n = 0;
    const tk_step_report *h = tk_run_history(through, &n);
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        sum += h[k].step_size;
        ck_assert_msg(fabs(h[k].flow_time - sum) <= 1e-12 * sum, "step %ld: %.17g against %.17g",
                      h[k].step, h[k].flow_time, sum);
    }
    ck_assert(sum > 0.0);
    ck_assert(at.flow_time > 0.0 && start->flow_time == at.flow_time);
    ck_assert_uint_eq(tk_run_curve(second)->nvert, coarse);
    ck_assert_int_eq(tk_run_until(second, NULL, &err), TK_OK);
    const tk_step_report *end = tk_run_latest(second), *want = tk_run_latest(through);
    printf("resumed at step 60: %.9f at step %ld, %zu vertices; straight through %.9f, %zu\n",
           end->ropelength, end->step, end->vertices, want->ropelength, want->vertices);
    ck_assert_int_eq(end->step, 400);
    ck_assert_uint_eq(end->vertices, want->vertices);
    ck_assert(end->vertices > coarse);
    ck_assert(fabs(end->ropelength - want->ropelength) < 2e-3 * want->ropelength);
    tk_run_free(&second);
    tk_run_free(&through);
    /* a curve of another type than the start's is refused */
    tk_curve *unknot = NULL;
    ck_assert_int_eq(tk_generate_torus(1, 1, 60, &unknot, NULL), TK_OK);
    tk_curve_scale(unknot, 10.0);
    tk_invariants trefoil = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(c, &trefoil, NULL), TK_OK);
    at.coarse_level = 0;
    ck_assert_int_eq(tk_run_resume(unknot, &o, &at, NULL, NULL, &trefoil, &second, &err),
                     TK_ETYPE);
    /* and a level the options do not have */
    at.coarse_level = 3;
    ck_assert_int_eq(tk_run_resume(c, &o, &at, NULL, NULL, NULL, &second, &err), TK_EINVAL);
    tk_invariants_free(&trefoil);
    tk_curve_free(&unknot);
    tk_curve_free(&c);
}
END_TEST

/* With the vertices option a start too loose for a coarse level gets one
 * once its ropelength allows it (schedule.c, coarsen_late): half the
 * vertices at the first step whose ropelength before it is at most
 * vertices / (2 x 2.5 / sqrt 2), not before, with the loose levels below it; a
 * run resumed on that level goes on there, and ends on the final
 * polygon. */
START_TEST(a_loose_start_gets_its_coarse_level_late)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 0, &c, NULL), TK_OK);
    /* without loose levels, and with the default's (one: 128 vertices a
     * round torus of ropelength 38.3 are 3.3 a unit, 1.7 a halving
     * further, too few for a coarse level; once the ropelength is down to
     * 36.2, 1.77 at the coarse level and 0.88 a halving further) */
    for (int loose = 0; loose <= 1; loose++) {
        tk_options o = TK_OPTIONS_INIT;
        o.autoscale = true;
        o.vertices = 128;
        o.max_steps = 600;
        o.escapes = 0;
        if (!loose)
            o.loose = 0;
        tk_run *run = NULL;
        tk_error err;
        ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
        const double allows = 128.0 / (2.0 * 2.5 / sqrt(2.0));
        ck_assert_uint_eq(tk_run_curve(run)->nvert, 128);
        ck_assert(tk_run_latest(run)->ropelength > allows);
        double rope = 0.0;
        while (tk_run_curve(run)->nvert == 128 && tk_run_latest(run)->step < 300) {
            rope = tk_run_latest(run)->ropelength;
            ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
            if (tk_run_curve(run)->nvert == 128)
                ck_assert_msg(rope > allows, "step %ld: ropelength %.6g allows 64 vertices",
                              tk_run_latest(run)->step, rope);
        }
        long at_step = tk_run_latest(run)->step;
        size_t count = (size_t)ceil(ldexp(128.0, -(1 + loose)));
        printf("coarse level from step %ld, at ropelength %.6g, on %zu vertices\n", at_step, rope,
               tk_run_curve(run)->nvert);
        ck_assert_uint_eq(tk_run_curve(run)->nvert, count);
        ck_assert(rope <= allows);
        /* resumed there, it keeps its levels, late and loose, and ends on
         * the final polygon through each */
        tk_resume at;
        run = interrupted(run, at_step + 5, &at);
        ck_assert_int_eq(at.coarse_level, 1 + loose);
        ck_assert_int_eq(at.coarse_levels, 1);
        ck_assert_int_eq(at.loose, loose);
        ck_assert_uint_eq(tk_run_curve(run)->nvert, count);
        size_t nh = 0, rises = 0;
        ck_assert_int_eq(tk_run_until(run, NULL, &err), TK_OK);
        const tk_step_report *h = tk_run_history(run, &nh);
        for (size_t i = 1; i < nh; i++)
            rises += h[i].vertices > h[i - 1].vertices;
        ck_assert_uint_eq(rises, (size_t)(1 + loose));
        ck_assert_int_eq(tk_run_latest(run)->step, 600);
        ck_assert_uint_eq(tk_run_latest(run)->vertices, 128);
        tk_run_free(&run);
    }
    tk_curve_free(&c);
}
END_TEST

/* A loose start at a resolution: its final polygon has resolution x the
 * ropelength reached when the run first refined (not the start's), and
 * keeps that count through the escapes, whose coarse polygons are
 * reckoned from the same ropelength; a run resumed during an escape
 * keeps it too.  With the loose option the first tightening starts that
 * many halvings below the coarse level (0.625 and 1.25 a unit for 2) and
 * passes through them, and so do the turned and far tries, explored or
 * on the final polygon; every try is judged on the coarse level, and
 * near ones start there.
 * T(2,5) on the round torus at resolution 5: its start is half as long
 * again as the tight knot. */
static void loose_start_escapes(int loose, long steps)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 5, 200, &c, NULL), TK_OK);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.loose = loose;
    o.escapes = 2;
    /* the second escape (after the explored ones) starts before the last
     * fifth: at step 14,006 of 20,000 with loose 0, the tries polished on
     * their coarse polygons, at 17,857 of 24,000 with loose 2 (its loose
     * tries start on their own curves' counts, a_loose_try_starts_on_its_
     * own_count, and take more steps than on the replaced curve's) */
    o.max_steps = steps;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    /* the first tightening starts on the loosest level */
    size_t coarse = tk_run_curve(run)->nvert;
    ck_assert_uint_eq(coarse, (size_t)ceil(ldexp(2.5, -loose) * m.ropelength));
    size_t ne = 0, explored = 0;
    const tk_escape *e = tk_run_escapes(run, &ne);
    while (ne - explored < 2 && tk_run_latest(run)->step < o.max_steps) {
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
        e = tk_run_escapes(run, &ne);
        explored = ne > 0 && e[ne - 1].explored ? ne : explored;
    }
    ck_assert_uint_eq(ne - explored, 2);
    /* (the run's own: the first refinement may be a loose level's) */
    tk_resume place;
    tk_run_resume_point(run, &place);
    double reference = place.final_ropelength;
    if (!loose)
        ck_assert_double_eq(reference, final_reference(run, m.ropelength));
    size_t final = (size_t)ceil(5 * reference), again = (size_t)ceil(2.5 * reference);
    size_t nh = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    size_t restarts = 0, refinements = 0, plateau = 0, loose_levels = 0, loose_tries = 0;
    size_t fine_loose = 0;
    double lowest = INFINITY;
    for (size_t i = 1; i < nh; i++) {
        int k = h[i].escapes - 1;
        /* the kinds take turns: turned, far, near; the first two are
         * loose tries, on the loose levels where the run has them, their
         * count reckoned from at least the reference, explored or on the
         * final polygon */
        int kind = k < 0 ? -1 : (k - (e[k].explored ? 0 : (int)explored)) % 3;
        bool loosened = loose && kind >= 0 && kind != 2;
        if (h[i].escapes > h[i - 1].escapes && e[k].explored) {
            /* explored: the lowest curve's polygon, the first plateau's
             * (turned: the coarse polygon of the lowest ropelength) */
            plateau = plateau ? plateau : h[i - 1].vertices;
            lowest = fmin(lowest, k == 0 ? h[i - 1].ropelength : e[k - 1].coarse);
            ck_assert_int_eq(e[k].turned, kind == 0);
            if (loosened)
                ck_assert_uint_ge(h[i].vertices, (size_t)ceil(ldexp(2.5, -loose) * lowest));
            else
                ck_assert_uint_eq(h[i].vertices,
                                  kind == 0 ? (size_t)ceil(2.5 * lowest) : plateau);
            loose_tries += loosened;
            ck_assert_uint_eq(refinements, 0);
        } else if (h[i].escapes > h[i - 1].escapes) {
            /* an escape: back to the coarse level of the same reference,
             * or a loose level of at least that reference */
            ck_assert_int_eq(e[k].turned, kind == 0);
            if (loosened) {
                /* on a loose level of its own curve: at most half the
                 * coarse level's 2.5 a unit of its own ropelength (a far
                 * try, several times the reference, can have more
                 * vertices than the reference's coarse polygon) */
                ck_assert_uint_ge(h[i].vertices, (size_t)ceil(ldexp(2.5, -loose) * reference));
                ck_assert_uint_le(h[i].vertices, (size_t)ceil(ldexp(2.5, 1 - loose) * h[i].ropelength));
            } else {
                ck_assert_uint_eq(h[i].vertices, again);
            }
            loose_tries += loosened;
            fine_loose += loosened;
            restarts++;
        } else if (h[i].restarts > h[i - 1].restarts && k >= 0 && e[k].explored) {
            /* exploring over: the lowest curve on its own ropelength's coarse polygon */
            lowest = fmin(lowest, e[k].coarse);
            ck_assert_uint_eq(h[i].vertices, (size_t)ceil(2.5 * lowest));
        } else if (k >= 0 && h[i].restarts == h[i - 1].restarts &&
                   h[i].vertices != h[i - 1].vertices && h[i].vertices != final) {
            /* a try's loose levels, refined or following the ropelength
             * down: only with the loose option */
            ck_assert_int_gt(loose, 0);
        } else if (h[i].vertices != h[i - 1].vertices && h[i].vertices != final) {
            /* the first tightening's levels, loose and coarse: following
             * the ropelength down or refined, at 2.5 a unit of the
             * ropelength before or a loose level's fewer (0.625, 1.25),
             * never after an escape */
            bool level = false;
            for (double a = ldexp(2.5, -loose); a <= 2.5; a *= 2)
                level = level || h[i].vertices == (size_t)ceil(a * h[i - 1].ropelength);
            ck_assert_msg(level, "%zu vertices at ropelength %.4f", h[i].vertices,
                          h[i - 1].ropelength);
            ck_assert_uint_eq(refinements, 0);
            ck_assert_int_eq(h[i].escapes, 0);
            loose_levels += h[i].vertices > h[i - 1].vertices;
        } else if (h[i].vertices > h[i - 1].vertices) {
            /* to the final polygon: a try from the coarse one, where it
             * is judged (an explored one that goes on, from its own) */
            if (k >= 0 && !e[k].explored && h[i].restarts == h[i - 1].restarts)
                ck_assert_uint_eq(h[i - 1].vertices, again);
            refinements++;
        }
    }
    printf("loose T(2,5), loose %d: start ropelength %.2f, %zu vertices for it; final polygon %zu, "
           "coarse %zu after %zu escapes (the second at step %ld), %zu refinements\n",
           loose, m.ropelength, (size_t)ceil(5 * m.ropelength), final, again, restarts,
           tk_run_latest(run)->step, refinements);
    ck_assert_uint_lt(final, (size_t)ceil(5 * m.ropelength) * 3 / 4);
    ck_assert_uint_eq(restarts, 2);
    ck_assert_uint_eq(loose_levels, (size_t)loose); /* refined from each to the next */
    printf("explored tries: %zu; the lowest explored ropelength %.6f; %zu loose tries\n",
           explored, lowest, loose_tries);
    ck_assert(loose ? loose_tries > 0 : loose_tries == 0);
    /* the two tries on the final polygon, turned and far, on the loose levels */
    ck_assert_uint_eq(fine_loose, loose ? 2 : 0);
    /* resumed during the second escape, it ends on the same polygon */
    tk_resume at;
    tk_run *second = interrupted(run, tk_run_latest(run)->step + 5, &at);
    ck_assert(at.final_ropelength == reference);
    ck_assert_int_eq(tk_run_until(second, NULL, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(second)->nvert, final);
    tk_run_free(&second);
    tk_curve_free(&c);
}

START_TEST(a_loose_start_keeps_its_final_count_through_escapes)
{
    if (quick() && tkt_skip("a_loose_start_keeps_its_final_count_through_escapes", LONG_RUN))
        return;
    loose_start_escapes(0, 20000);
}
END_TEST

START_TEST(loose_levels_come_first_for_every_loose_try)
{
    if (quick() && tkt_skip("loose_levels_come_first_for_every_loose_try", LONG_RUN))
        return;
    loose_start_escapes(2, 24000);
}
END_TEST

/* With the vertices option a loose start can be too long for a coarse
 * level (fewer than 2.5 / sqrt 2 vertices per unit of its ropelength at
 * half the count), yet its escapes restart on a coarse polygon as those of a
 * tighter start do: it gets its level late (a_loose_start_gets_its_
 * coarse_level_late), its first refinement fixes the final polygon's
 * reference at the ropelength reached, and the coarse levels are that
 * ropelength's; resumed during an escape, the run reckons them the same.
 * T(2,3) from the round torus (ropelength 38.3 by its self-distance, the
 * tight trefoil 32.7) at 3.4 vertices per unit of the start's. */
START_TEST(a_loose_start_at_a_vertex_count_escapes_coarse)
{
    if (quick() && tkt_skip("a_loose_start_at_a_vertex_count_escapes_coarse", LONG_RUN))
        return;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 200, &c, NULL), TK_OK);
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(c, NULL, &m, NULL), TK_OK);
    double reckoned = 2.0 * m.length / m.shortest;
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.vertices = (size_t)floor(3.4 * reckoned);
    o.escapes = 2;
    o.loose = 0; /* its tries on the coarse level (loose ones: loose_start_escapes) */
    /* two escapes after the first refinement come within it (their
     * coarse polygons polished); the resumed run takes the rest */
    o.max_steps = 8000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, o.vertices); /* no coarse level */
    /* on to two escapes after the first refinement (the tries before it
     * explore the late level) */
    int refined_at = -1;
    bool was_coarse = false;
    while ((refined_at < 0 || tk_run_latest(run)->escapes < refined_at + 2) &&
           tk_run_latest(run)->step < o.max_steps) {
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
        was_coarse = was_coarse || tk_run_curve(run)->nvert < o.vertices;
        if (refined_at < 0 && was_coarse && tk_run_curve(run)->nvert == o.vertices)
            refined_at = tk_run_latest(run)->escapes;
    }
    ck_assert_int_ge(refined_at, 0);
    ck_assert_int_eq(tk_run_latest(run)->escapes, refined_at + 2);
    size_t nh = 0, coarse = (o.vertices + 1) / 2;
    const tk_step_report *h = tk_run_history(run, &nh);
    double reference = 0.0;
    for (size_t i = 1; i < nh; i++) {
        if (h[i].escapes > h[i - 1].escapes) {
            /* (before the first refinement, a try that explores the level) */
            ck_assert_uint_eq(h[i].vertices, coarse);
        } else if (h[i].vertices != h[i - 1].vertices) {
            /* the late level before the first refinement, or a refinement */
            bool late = h[i].vertices == coarse && h[i].escapes == 0 && !(reference > 0.0);
            ck_assert_msg(late || h[i].vertices == o.vertices, "step %ld: %zu vertices",
                          h[i].step, h[i].vertices);
            if (h[i].vertices == o.vertices && !(reference > 0.0))
                reference = h[i - 1].ropelength;
        }
    }
    printf("T(2,3) at %zu vertices (start ropelength %.2f): escapes on %zu, the final "
           "reference %.4f, %d tries before it\n",
           o.vertices, reckoned, coarse, reference, refined_at);
    ck_assert(reference > 0.0);
    /* 2.5 / sqrt 2 a unit at half the count */
    ck_assert_double_le(reference, reckoned * 3.4 / (2.0 * 2.5 / sqrt(2.0)));
    tk_resume at;
    tk_run *second = interrupted(run, tk_run_latest(run)->step + 5, &at);
    ck_assert(at.final_ropelength == reference);
    ck_assert_int_eq(at.coarse_level, 1);
    ck_assert_int_eq(tk_run_until(second, NULL, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(second)->nvert, o.vertices);
    tk_run_free(&second);
    tk_curve_free(&c);
}
END_TEST

/* A loose start's coarse polygon follows the ropelength down: each time
 * the ropelength has fallen by a quarter since the level's count was
 * reckoned, and the count would fall by a quarter, it is resampled to 2.5
 * vertices per unit of the ropelength reached (resolution 5), before the
 * next step, feasible.  Lissajous 6_1 L(3,2,5): start ropelength 429, so
 * 1073 coarse vertices, where the tight knot (56.7) needs 142. */
START_TEST(a_loose_coarse_level_follows_the_ropelength)
{
    const int freq[3] = {3, 2, 5};
    const double phase[3] = {0.7, 0.2, 0.0};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_lissajous(freq, phase, 300, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.escapes = 0;
    o.max_steps = 100000; /* (the coarse level's share: half of it) */
    o.loose = 0;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_uint_gt(tk_run_curve(run)->nvert, 1000);
    while (tk_run_latest(run)->step < 2600)
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    size_t nh = 0, resampled = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    /* the ropelength the count was last reckoned from: at first the
     * start's (as autoscaled, step 0) */
    ck_assert_int_eq(h[0].step, 0);
    double reckoned = h[0].ropelength;
    for (size_t i = 1; i < nh; i++) {
        ck_assert_msg(h[i].thickness >= 1.0 - o.overstep_tolerance, "step %ld: thickness %.9f",
                      h[i].step, h[i].thickness);
        ck_assert_uint_le(h[i].vertices, h[i - 1].vertices);
        double rope = h[i - 1].ropelength, want = ceil(2.5 * rope);
        bool due = rope < 0.75 * reckoned && want < 0.75 * (double)h[i - 1].vertices;
        if (h[i].vertices == h[i - 1].vertices) {
            ck_assert_msg(!due, "step %ld: ropelength %.3f, reckoned from %.3f, %zu vertices",
                          h[i].step, rope, reckoned, h[i].vertices);
            continue;
        }
        printf("L(3,2,5) coarse: %zu -> %zu vertices at step %ld, ropelength %.3f\n",
               h[i - 1].vertices, h[i].vertices, h[i].step, rope);
        ck_assert_msg(due, "step %ld: not due", h[i].step);
        ck_assert_uint_eq(h[i].vertices, (size_t)want);
        reckoned = rope;
        resampled++;
    }
    ck_assert_uint_ge(resampled, 2);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* A run of c at resolution 5 with two loose levels for `steps` steps;
 * *type gets c's invariants, for loose_run_end. */
static tk_run *loose_run(const tk_curve *c, long steps, tk_invariants *type)
{
    ck_assert_int_eq(tk_invariants_compute(c, type, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.loose = 2;
    o.max_steps = steps;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    return run;
}

/* The run's curve is of the start's type (by the invariants computed
 * here); frees the run and the type. */
static void loose_run_end(tk_run **run, tk_invariants *type)
{
    tk_invariants result = TK_INVARIANTS_INIT;
    ck_assert_int_eq(tk_invariants_compute(tk_run_curve(*run), &result, NULL), TK_OK);
    ck_assert_int_eq(tk_invariants_compare(type, &result, NULL), TK_OK);
    tk_invariants_free(&result);
    tk_invariants_free(type);
    tk_run_free(run);
}

/* A loose polygon follows the ropelength down only where the fewer
 * vertices keep the type (tk_schedule_before_step): a far start of
 * catalogue 9.45 (wandered as `tightknot generate wander 9.45.vect 1`
 * makes it), at resolution 5 with two loose levels, started its first
 * explored try at step 3,968, the plateau turned, of ropelength 261 on a
 * loose level of 196 vertices.  That step's check once read the
 * ropelength of the last report, the curve the try replaced (74.93),
 * which calls for 47 vertices; the try's curve resampled to 47 is another
 * knot, and the run failed there (the type check after the resampling)
 * before the guard.  The try's level follows its own ropelength down (a
 * try's first step is not judged now; a_loose_try_starts_on_its_own_count):
 * it has fewer vertices than it started with by step 12,000 (judged from
 * the replaced curve's ropelength, the level stayed at 196 for 6,500
 * steps).  The first explored try is now the start turned (escape.c,
 * turned_start): 234.81 on 170 vertices, replacing 74.93, down to 127 by
 * step 4,636; with the relaxation's fourth power (tk/relax.h), whose
 * turns are less narrow, 140.72 on 85, replacing 75.00, down to 63 by
 * step 5,502: still nearly twice as loose as the curve it replaced,
 * whose count (47) the old check would have given it.
 * Every step is taken, each polygon of the start's type (the run checks
 * every resampling), and the curve at the end is of the start's type by
 * the invariants computed here. */
START_TEST(a_loose_level_keeps_its_polygon_where_fewer_vertices_lose_the_type)
{
    const char *name = "a_loose_level_keeps_its_polygon_where_fewer_vertices_lose_the_type";
    if ((quick() && tkt_skip(name, LONG_RUN)) ||
        (!tkt_catalogue_dir() && tkt_skip(name, "no catalogue")))
        return;
    tk_curve *file = tkt_catalogue_curve("9.45.vect"), *c = NULL;
    ck_assert_ptr_nonnull(file);
    ck_assert_int_eq(tk_relax_wander(file, 1, 2000, &c, NULL), TK_OK);
    tk_invariants type = TK_INVARIANTS_INIT;
    tk_run *run = loose_run(c, 30000, &type);
    tk_error err;
    size_t first = 0, least = SIZE_MAX;
    double replaced = NAN, from = NAN;
    while (tk_run_latest(run)->step < 12000 && !(least < first)) {
        double before = tk_run_latest(run)->ropelength;
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "step %ld: %s", tk_run_latest(run)->step,
                      err.message);
        const tk_step_report *s = tk_run_latest(run);
        if (s->restarts != 1)
            continue;
        /* the first try, on its first polygon and those it came down to */
        if (!first) {
            first = s->vertices;
            replaced = before;
            from = s->ropelength;
        }
        least = s->vertices < least ? s->vertices : least;
    }
    printf("9.45 wandered: its first try from %.2f (replacing %.2f) on %zu vertices, down to %zu "
           "by step %ld at %.4f\n", from, replaced, first, least, tk_run_latest(run)->step,
           tk_run_latest(run)->ropelength);
    fflush(stdout);
    ck_assert_uint_gt(first, 0);
    /* a try far looser than the curve it replaced, which came down */
    ck_assert_double_gt(from, 1.5 * replaced);
    ck_assert_uint_lt(least, first);
    loose_run_end(&run, &type);
    tk_curve_free(&c);
    tk_curve_free(&file);
}
END_TEST

/* A loose try starts on the polygon its own curve calls for, not the one
 * the curve it replaced would (tk_schedule_before_step): catalogue 2.2.1
 * (the Hopf link) at resolution 5 with two loose levels tries a far
 * escape at step 2,462 (its second try), a curve of ropelength about 147
 * replacing one of 25.22.  At the loose level's 0.625 vertices a unit (5 halved for the
 * coarsest level and twice more for the loose ones) the replaced curve's
 * ropelength calls for ceil(0.625 * 25.22) = 16 vertices, and the try's
 * own for 92; before, the try's first step resampled it to those 16, a
 * tenth of a vertex per unit of its length (its first step measured 141
 * on them, 226.6 on its own 92).  Every try that starts more
 * than 4/3 looser than the curve it replaces (where that resampling was
 * due) has more than the replaced curve's count on its first step, more
 * than twice that count where it starts more than twice as loose (the
 * first try, the start turned inside out, now comes at step 959 at 34.95
 * on 21 vertices, replacing 25.22), and the run ends of the start's
 * type. */
START_TEST(a_loose_try_starts_on_its_own_count)
{
    const char *name = "a_loose_try_starts_on_its_own_count";
    if ((quick() && tkt_skip(name, LONG_RUN)) ||
        (!tkt_catalogue_dir() && tkt_skip(name, "no catalogue")))
        return;
    tk_curve *c = tkt_catalogue_curve("2.2.1.vect");
    ck_assert_ptr_nonnull(c);
    tk_invariants type = TK_INVARIANTS_INIT;
    tk_run *run = loose_run(c, 6000, &type);
    tk_error err;
    long restarts = 0;
    int far = 0;
    while (tk_run_latest(run)->step < 6000) {
        tk_step_report before = *tk_run_latest(run);
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "step %ld: %s", before.step, err.message);
        const tk_step_report *s = tk_run_latest(run);
        if ((long)s->restarts == restarts)
            continue;
        restarts = (long)s->restarts;
        size_t replaced = (size_t)ceil(0.625 * before.ropelength);
        printf("Hopf try %ld at step %ld: %zu vertices at %.3f, replacing %.3f (%zu vertices at "
               "the loose level)\n", restarts, s->step, s->vertices, s->ropelength,
               before.ropelength, replaced);
        if (!(s->ropelength > before.ropelength * 4.0 / 3.0))
            continue;
        ck_assert_uint_gt(s->vertices, replaced);
        if (!(s->ropelength > before.ropelength * 2.0))
            continue;
        far++;
        ck_assert_uint_gt(s->vertices, 2 * replaced);
    }
    ck_assert_int_ge(far, 1);
    loose_run_end(&run, &type);
    tk_curve_free(&c);
}
END_TEST

/* The fall of tk_history_fall (run.h), recomputed: the least ropelength
 * of the last `window` reports up to (not including) report `n` against
 * the least of the `window` before them (fewer when the level is
 * younger), relative; NAN before `from` + `window` reports. */
static double fall_over(const tk_step_report *h, size_t from, size_t n, size_t window)
{
    if (n <= from + window)
        return NAN;
    size_t split = n - window, first = split > from + window ? split - window : from;
    double before = INFINITY, recent = INFINITY;
    for (size_t k = first; k < split; k++)
        before = fmin(before, h[k].ropelength);
    for (size_t k = split; k < n; k++)
        recent = fmin(recent, h[k].ropelength);
    return (before - recent) / recent;
}

/* The window of the watch judging report i's step: 200 steps for a mean
 * edge (report i - 1's ropelength over report i's edges) of a tenth of
 * the diameter or more, as many more as it is shorter. */
static size_t window_at(const tk_step_report *h, size_t i)
{
    double edge = h[i - 1].ropelength / (2.0 * (double)h[i].vertices);
    return edge >= 0.1 ? 200 : (size_t)lround(200.0 * 0.1 / edge);
}

/* The coarse level of report `from`'s polygon, checked against the rule
 * (a_fine_coarse_level_waits_as_many_more_steps, below): the step of
 * report i was judged after its motion, on the reports before it (the
 * mean edge: report i - 1's ropelength over report i's edges), and the
 * level moves on at its first stall (or 20 steps in a row with a
 * residual below 1e-3), or, polished, each such stall (its bound a third
 * smaller at each level) takes it a level down, and the stall of the fourth
 * level moves it on (a coarse polygon keeps all four: 0.3 h^2 is above
 * the options' 3e-4).  A level that begins at step i's watch starts its
 * window at report i; a move-on shows as report i + 1's count or
 * restarts.  Polished, it also moves on `cap` steps (0: none) after its
 * first stall.  A level above the coarsest (`above`) whose window is 400
 * steps or more also stalls when its fall over the last 200 steps, at
 * that rate over the whole window, is below the bound.  The report where
 * it moved on, or 0 if it did not; *by_rate tells whether that rate was
 * what moved it (the fall over the whole window was not yet below). */
static size_t coarse_level_checked(const tk_step_report *h, size_t nh, size_t from, bool polished,
                                   bool above, double cap, size_t *first_stall, bool *by_rate)
{
    *by_rate = false;
    int level = 0;
    *first_stall = 0;
    for (size_t i = from + 1; i + 1 < nh; i++) {
        size_t window = window_at(h, i);
        bool critical = i >= from + 20; /* (the watch's rule on every level) */
        for (size_t k = i >= 20 ? i - 20 : 0; k < i && critical; k++)
            critical = h[k].residual < 1e-3;
        double bound = 1e-4 * pow(1.0 / 3.0, level);
        bool slow = fall_over(h, from, i, window) < bound;
        bool rate = above && window >= 400 &&
                    fall_over(h, from, i, 200) * (double)window / 200.0 < bound;
        bool stall = slow || rate || critical;
        bool moved = h[i + 1].vertices != h[i].vertices || h[i + 1].restarts != h[i].restarts;
        /* (a level where tries are judged is also left `cap` steps after
         * its first stall: the watch at report i's step sees report i - 1,
         * and counts from the report of the step that stalled) */
        bool capped = cap > 0.0 && *first_stall > 0 &&
                      (double)(h[i - 1].step - h[*first_stall].step) >= cap;
        ck_assert_msg(moved == ((stall && level == (polished ? 4 : 0)) || capped),
                      "step %ld at level %d (since report %zu): %s, %s", h[i].step, level, from,
                      stall ? "stalled" : capped ? "capped" : "going on",
                      moved ? "moved on" : "stayed");
        if (moved) {
            *by_rate = rate && !slow && !critical;
            return i;
        }
        if (stall) {
            *first_stall = *first_stall ? *first_stall : i;
            level++;
            from = i;
        }
    }
    return 0;
}

/* The trefoil from the round torus (200 vertices) set up to be tightened
 * at `vertices`, coarse to fine from `coarsest` (600 / 38.3 is 15.7 a
 * unit, whose third halving, 1.96, is the one nearest 2.5: 75), with a
 * budget of `steps` (1,000,000: too large for any level's share to end
 * it). */
static tk_run *torus_trefoil_at(size_t vertices, size_t coarsest, int escapes, long steps,
                                tk_curve **c, tk_options *o)
{
    ck_assert_int_eq(tk_generate_torus(2, 3, 200, c, NULL), TK_OK);
    *o = (tk_options)TK_OPTIONS_INIT;
    o->autoscale = true;
    o->vertices = vertices;
    o->escapes = escapes;
    o->loose = 0; /* the coarse levels alone */
    o->max_steps = steps;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(*c, o, &run, &err), TK_OK);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, coarsest);
    return run;
}

/* A coarse level moves on when its ropelength fell by less than 1e-4 over
 * 200 steps counted for a mean edge of a tenth of the diameter: on a
 * polygon with shorter edges, as many more steps as they are shorter
 * (each step moves a vertex at most a quarter of the shortest edge).  A
 * trefoil at 600 vertices from the round torus (start ropelength 38.3,
 * tight 32.7: a mean edge of 0.055 diameters on the 300-vertex level)
 * goes through coarse levels of 75, 150 and 300 vertices; with a step budget
 * too large for any level's share to end it, each level ends exactly
 * where the rule first holds. */
START_TEST(a_fine_coarse_level_waits_as_many_more_steps)
{
    if (quick() && tkt_skip("a_fine_coarse_level_waits_as_many_more_steps", LONG_RUN))
        return;
    tk_curve *c = NULL;
    tk_options o;
    tk_run *run = torus_trefoil_at(600, 75, 0, 1000000, &c, &o);
    tk_error err;
    while (tk_run_curve(run)->nvert < o.vertices && tk_run_latest(run)->step < 20000)
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, o.vertices);
    size_t nh = 0, from = 0, levels = 0, stall = 0, i;
    bool by_rate = false;
    const tk_step_report *h = tk_run_history(run, &nh);
    double most = 1.0;
    /* every level, the final one too (which does not move on) */
    while ((i = coarse_level_checked(h, nh, from, false, levels > 0, 0.0, &stall, &by_rate)) > 0) {
        size_t window = window_at(h, i);
        printf("T(2,3) at 600: the %zu-vertex level moved on at step %ld after %zu steps "
               "(window %zu), ropelength %.5f\n",
               h[i].vertices, h[i].step, i + 1 - from, window, h[i].ropelength);
        ck_assert_uint_eq(h[i + 1].vertices, 2 * h[i].vertices);
        most = fmax(most, (double)window / 200.0);
        from = i + 1;
        levels++;
    }
    ck_assert_uint_eq(levels, 3);
    ck_assert_double_ge(most, 1.5); /* the rule in steps alone would differ */
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Above the coarsest level, a level whose window is 400 steps or more
 * (a mean edge of a twentieth of the diameter or less) also moves on when
 * its fall over the last 200 steps, at that rate over the whole window,
 * is below the bound, as the final polygon's polishing does
 * (POLISH_RATE_FROM, schedule.c).  The trefoil from the round torus at
 * 1,600 vertices goes through coarse levels of 200, 400 and 800 vertices
 * (41.8 a unit, three halvings at most), the last two with windows of
 * about 480 and 960 steps; each level ends exactly where the rules first
 * hold, and at least one where the rate alone holds. */
START_TEST(a_coarse_level_above_the_coarsest_moves_on_at_the_final_rate)
{
    if (quick() && tkt_skip("a_coarse_level_above_the_coarsest_moves_on_at_the_final_rate",
                            LONG_RUN))
        return;
    tk_curve *c = NULL;
    tk_options o;
    tk_run *run = torus_trefoil_at(1600, 200, 0, 1000000, &c, &o);
    tk_error err;
    while (tk_run_curve(run)->nvert < o.vertices && tk_run_latest(run)->step < 40000)
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    ck_assert_uint_eq(tk_run_curve(run)->nvert, o.vertices);
    size_t nh = 0, from = 0, levels = 0, rated = 0, stall = 0, i;
    bool by_rate = false;
    const tk_step_report *h = tk_run_history(run, &nh);
    while ((i = coarse_level_checked(h, nh, from, false, levels > 0, 0.0, &stall, &by_rate)) > 0) {
        printf("T(2,3) at 1600: the %zu-vertex level moved on at step %ld after %zu steps "
               "(window %zu)%s, ropelength %.6f\n",
               h[i].vertices, h[i].step, i + 1 - from, window_at(h, i),
               by_rate ? " at the final rate" : "", h[i].ropelength);
        ck_assert_uint_eq(h[i + 1].vertices, 2 * h[i].vertices);
        rated += by_rate;
        from = i + 1;
        levels++;
    }
    ck_assert_uint_eq(levels, 3);
    ck_assert_uint_ge(rated, 1);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* With escapes, the coarsest level is where the tries are judged
 * (escape.c), so a try's is polished before it is left, or until the try
 * has spent a twentieth of the budget polishing it (JUDGED_SHARE,
 * schedule.c); the first tightening's moves on at its first stall, as
 * without escapes, to the first explored try.  The same trefoil as
 * above, with a budget of `steps`; returns the steps the try spent on
 * the level from its first stall. */
static long polished_try(long steps)
{
    tk_curve *c = NULL;
    tk_options o;
    tk_run *run = torus_trefoil_at(600, 75, 1, steps, &c, &o);
    tk_error err;
    size_t nh = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    /* until the explored try has left its coarse polygon */
    while (h[nh - 1].vertices == 75 && h[nh - 1].restarts <= h[0].restarts + 1 &&
           h[nh - 1].step < 20000) {
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
        h = tk_run_history(run, &nh);
    }
    size_t stall = 0;
    bool by_rate = false;
    size_t first = coarse_level_checked(h, nh, 0, false, false, 0.0, &stall, &by_rate);
    ck_assert_uint_gt(first, 0);
    size_t ne = 0;
    const tk_escape *e = tk_run_escapes(run, &ne);
    ck_assert(ne == 1 && e[0].explored && h[first + 1].escapes == 1);
    size_t tried = coarse_level_checked(h, nh, first + 1, true, false, 0.05 * (double)steps,
                                        &stall, &by_rate);
    ck_assert_uint_gt(tried, 0);
    ck_assert(e[0].coarse == h[tried].ropelength);
    long spent = h[tried].step - h[stall].step;
    printf("T(2,3) at 600, escapes, %ld steps: the first tightening left its 75-vertex level "
           "at step %ld (%.5f); the explored try's level first stalled at step %ld (%.5f) and "
           "moved on at step %ld (%.5f), %ld steps after that stall\n",
           steps, h[first].step, h[first].ropelength, h[stall].step, h[stall].ropelength,
           h[tried].step, h[tried].ropelength, spent);
    tk_run_free(&run);
    tk_curve_free(&c);
    return spent;
}

START_TEST(the_coarsest_level_of_a_try_is_polished_first)
{
    if (quick() && tkt_skip("the_coarsest_level_of_a_try_is_polished_first", LONG_RUN))
        return;
    /* (a budget too large for the twentieth to end it) */
    long spent = polished_try(1000000);
    ck_assert_int_lt(spent, 50000);
}
END_TEST

/* The same with a budget whose twentieth ends the try's polishing first:
 * the level is left then, polished or not (coarse_level_checked). */
START_TEST(a_try_leaves_its_coarsest_level_after_a_twentieth_of_the_budget)
{
    if (quick() &&
        tkt_skip("a_try_leaves_its_coarsest_level_after_a_twentieth_of_the_budget", LONG_RUN))
        return;
    long whole = polished_try(1000000);
    /* a twentieth of the budget is half the polishing (and not a whole
     * number of steps: the engine reckons it as a difference of fractions
     * of the budget, which a tie would leave to rounding) */
    long steps = 10 * whole + 1;
    long spent = polished_try(steps);
    ck_assert_int_lt(spent, whole);
    ck_assert_int_ge(spent, steps / 20);
}
END_TEST

/* Resumed during an escape, a run keeps its best curve, its tries and
 * its random stream: it ends no worse than the best it had. */
START_TEST(a_resumed_run_keeps_its_escapes)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(2, 40, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.escapes = 2;
    o.seed = 7;
    o.max_steps = 1500;
    tk_run *first = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &first, &err), TK_OK);
    while (tk_run_latest(first)->escapes == 0 && tk_run_latest(first)->step < 1500)
        ck_assert_int_eq(tk_run_step(first, &err), TK_OK);
    ck_assert_int_eq(tk_run_latest(first)->escapes, 1);
    tk_step_report best;
    ck_assert_ptr_nonnull(tk_run_best(first, &best));
    tk_resume at;
    tk_run *second = interrupted(first, tk_run_latest(first)->step + 5, &at);
    ck_assert_int_eq(at.escapes, 1);
    ck_assert_int_eq(at.restarts, 1); /* the escape's curve */
    ck_assert(at.draws > 0);
    tk_step_report kept;
    ck_assert_ptr_nonnull(tk_run_best(second, &kept));
    ck_assert(kept.ropelength == best.ropelength);
    ck_assert_int_eq(tk_run_latest(second)->escapes, 1);
    ck_assert_int_eq(tk_run_latest(second)->restarts, 1);
    /* the random stream's place reads back as it was set */
    tk_resume again;
    tk_run_resume_point(second, &again);
    ck_assert_int_eq(again.draws, at.draws);
    ck_assert_int_eq(again.restarts, 1);
    ck_assert_int_eq(tk_run_until(second, NULL, &err), TK_OK);
    const tk_step_report *end = tk_run_latest(second);
    printf("resumed during an escape: best %.9f, ended %.9f after %d escapes\n",
           best.ropelength, end->ropelength, end->escapes);
    ck_assert(end->ropelength <= best.ropelength * (1.0 + 1e-12));
    ck_assert_int_le(end->escapes, 2);
    ck_assert_int_eq(end->step, 1500);
    tk_run_free(&second);
    tk_curve_free(&c);
}
END_TEST

/* The ropelength of each step, by step number (entry 0 the start's). */
typedef struct ropelengths {
    double at[4001];
} ropelengths;

static int keep_ropelength(const tk_step_report *s, void *user)
{
    ropelengths *h = user;
    if (s->step >= 0 && s->step <= 4000)
        h->at[s->step] = s->ropelength;
    return 0;
}

static double lowest(const ropelengths *h, long from, long to)
{
    double low = INFINITY;
    for (long k = from; k <= to; k++)
        low = fmin(low, h->at[k]);
    return low;
}

/* A final polygon whose ropelength still falls, by more than counts as
 * converged (2e-5 over 300 steps) but by less than 2e-4, tries an escape
 * once it has spent a fifth of the budget on that polygon (escape.c's
 * crawl rule): T(2,5) from the round torus at 100 vertices (one polygon,
 * made at the start) with 3,000 steps, at step 600.  The falls are
 * reckoned here from the steps' own reports. */
START_TEST(a_crawling_run_escapes_after_a_fifth_of_its_budget)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 5, 100, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.escapes = 1;
    o.max_steps = 3000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ropelengths *h = calloc(1, sizeof *h);
    ck_assert_ptr_nonnull(h);
    h->at[0] = tk_run_latest(run)->ropelength;
    tk_run_set_progress(run, keep_ropelength, h);
    while (tk_run_latest(run)->escapes == 0 && tk_run_latest(run)->step < o.max_steps)
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    size_t ne = 0;
    const tk_escape *e = tk_run_escapes(run, &ne);
    ck_assert_uint_eq(ne, 1);
    ck_assert_int_eq(e[0].step, o.max_steps / 5);
    long at = e[0].step;
    double fall = (lowest(h, at - 599, at - 300) - lowest(h, at - 299, at)) /
                  lowest(h, at - 599, at - 300);
    printf("crawl: escape after step %ld of %ld, the ropelength fell by %.3g over the "
           "300 steps before\n",
           at, o.max_steps, fall);
    ck_assert(fall > 2e-5 && fall < 2e-4);
    /* from where it stood: the first escape's best curve is the one that
     * converged (or crawled) */
    ck_assert(e[0].from == h->at[at]);
    free(h);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* The last fifth of the budget polishes the best curve (escape.c's
 * reserve): no escape starts in it, and a try still behind the best when
 * it begins is given up for the best, on the final polygon.  The Hopf
 * link of escaping_run (two rings of 40 vertices) with the default
 * escapes and seed, 2,000 steps: at step 1,600 its second try (loosened
 * many times over) is still far from tight.  The best is reckoned here
 * from the steps' own reports. */
START_TEST(the_last_fifth_of_the_budget_polishes_the_best)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_chain(2, 40, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 2000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s", err.message);
    size_t nh = 0, ne = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    const tk_escape *e = tk_run_escapes(run, &ne);
    ck_assert_uint_ge(ne, 1);
    ck_assert_int_lt((int)ne, o.escapes); /* tries were left: the reserve stopped them */
    for (size_t k = 0; k < ne; k++)
        ck_assert_int_lt(5 * e[k].step, 4 * o.max_steps);
    /* the first step in the reserve, the best before it */
    size_t at = 0;
    while (at < nh && 5 * h[at].step < 4 * o.max_steps)
        at++;
    ck_assert_uint_lt(at + 1, nh);
    ck_assert_int_eq(h[at + 1].step, h[at].step + 1);
    size_t final = tk_run_curve(run)->nvert;
    double best = INFINITY;
    for (size_t i = 0; i <= at; i++)
        if (h[i].vertices == final)
            best = fmin(best, h[i].ropelength);
    printf("reserve: at step %ld the try %d stood at %.6f on %zu vertices; the best %.9f, "
           "the next step %.9f, the end %.9f\n",
           h[at].step, h[at].escapes, h[at].ropelength, h[at].vertices, best,
           h[at + 1].ropelength, tk_run_latest(run)->ropelength);
    ck_assert(h[at].vertices != final || h[at].ropelength > best * (1.0 + 1e-3));
    ck_assert_uint_eq(h[at + 1].vertices, final);
    ck_assert(fabs(h[at + 1].ropelength - best) <= 1e-5 * best);
    ck_assert(tk_run_latest(run)->ropelength <= h[at + 1].ropelength);
    /* what the polish reached is not the given-up try's */
    ck_assert(isnan(e[ne - 1].reached) || e[ne - 1].reached > best * (1.0 + 1e-3));
    ck_assert(!e[ne - 1].improved);
    /* the steps say where the curve was replaced: at each escape (a
     * looser curve) and where the best was put back, and nowhere else
     * does the ropelength rise by more than a step's correction */
    ck_assert_int_eq(h[0].restarts, 0);
    int put_back = 0;
    for (size_t i = 1; i < nh; i++) {
        int more = h[i].restarts - h[i - 1].restarts;
        bool escaped = h[i].escapes > h[i - 1].escapes;
        bool replaced = escaped || i == at + 1;
        /* (the run's end may put the best back once more, as its last record) */
        ck_assert_msg(more == replaced || (more == 1 && i + 1 == nh),
                      "step %ld: restarts %d -> %d, escapes %d -> %d", h[i].step,
                      h[i - 1].restarts, h[i].restarts, h[i - 1].escapes, h[i].escapes);
        if (escaped)
            ck_assert(h[i].ropelength > 1.01 * h[i - 1].ropelength);
        else if (more == 0 && h[i].vertices == h[i - 1].vertices)
            /* (a curve thicker than the tube, up to autoscale's margin,
             * may thin to it as it shortens: 2 length / thickness rises
             * by as much) */
            ck_assert_msg(h[i].ropelength <= (1.0 + 1e-3) * h[i - 1].ropelength *
                                                 fmax(1.0, h[i - 1].thickness / (2.0 * o.radius)),
                          "step %ld: %.9f -> %.9f", h[i].step, h[i - 1].ropelength,
                          h[i].ropelength);
        put_back += more == 1 && !escaped;
    }
    ck_assert_int_ge(put_back, 1);
    ck_assert_int_eq(tk_run_latest(run)->restarts, (int)ne + put_back);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Once the tries are spent the best curve is put back and polished, and
 * not put back again until the run ends: judged again each window, a
 * polish that stood a little above the best (a step's rise) was put back
 * to it and replayed the same steps (T(2,3) at 60 vertices, one escape:
 * put back 24 times in 12,000 steps).  Every step's curve counts for the
 * best, so none is lost by going on. */
START_TEST(a_best_put_back_is_polished_not_replayed)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 60, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.escapes = 1;
    o.max_steps = 6000; /* the escape after step 911, the best put back at 2,052 */
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s", err.message);
    size_t nh = 0, ne = 0;
    double low = lowest_step(run, &nh);
    (void)tk_run_escapes(run, &ne);
    const tk_step_report *end = tk_run_latest(run);
    printf("T(2,3), 60 vertices, %ld steps: %zu escape, %d restarts; ends at %.9f, the lowest "
           "step %.9f\n", end->step, ne, end->restarts, end->ropelength, low);
    ck_assert_uint_eq(ne, 1);
    /* the escape, the best put back, and at most once more at the end */
    ck_assert_int_le(end->restarts, (int)ne + 2);
    ck_assert_msg(end->ropelength <= low * (1.0 + 1e-12), "%.12f above %.12f",
                  end->ropelength, low);
    /* measured independently: the curve returned is the one reported */
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL), TK_OK);
    ck_assert(fabs(m.ropelength - end->ropelength) <= 1e-9 * end->ropelength);
    ck_assert(m.thickness >= 1.0 - 1e-5);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Every figure a run reports, in order. */
typedef struct reports {
    tk_step_report *items;
    size_t count, capacity;
} reports;

static int keep_report(const tk_step_report *s, void *user)
{
    reports *all = user;
    if (all->count == all->capacity) {
        all->capacity = all->capacity ? 2 * all->capacity : 256;
        all->items = realloc(all->items, all->capacity * sizeof *all->items);
        ck_assert_ptr_nonnull(all->items);
    }
    all->items[all->count++] = *s;
    return 0;
}

/* A run that stops before it has tried an escape returns its best curve
 * too, not the one its budget ended on: near its critical point the
 * ropelength goes up and down by about the overstep tolerance.  T(2,3) at
 * 60 vertices on one polygon stands at 32.98667689 at step 446, above
 * its 32.98666843 of two steps before (its first escape comes after
 * step 480). */
START_TEST(a_run_that_tried_no_escape_returns_its_best)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 60, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.coarse_to_fine = false;
    o.max_steps = 446;
    tk_run *run = NULL;
    tk_error err;
    reports all = {0};
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    tk_run_set_progress(run, keep_report, &all);
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s", err.message);
    size_t ne = 0;
    (void)tk_run_escapes(run, &ne);
    ck_assert_uint_eq(ne, 0);
    ck_assert_uint_ge(all.count, 2);
    /* the step the budget ended on, then the best put back in its place */
    const tk_step_report *stopped = &all.items[all.count - 2], *end = tk_run_latest(run);
    double low = INFINITY;
    for (size_t k = 0; k + 1 < all.count; k++)
        low = fmin(low, all.items[k].ropelength);
    printf("T(2,3), 60 vertices, one polygon, %ld steps: stopped at %.9f, the lowest step "
           "%.9f, returned %.9f\n", stopped->step, stopped->ropelength, low, end->ropelength);
    ck_assert_int_eq(stopped->step, (long)o.max_steps);
    ck_assert_msg(stopped->ropelength > low * (1.0 + 1e-8), "%.12f is the lowest", low);
    ck_assert_int_eq(end->step, stopped->step);
    ck_assert_msg(end->ropelength == low, "%.12f, not the lowest %.12f", end->ropelength, low);
    /* measured independently: the curve returned is the one reported */
    tk_measure m;
    ck_assert_int_eq(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL), TK_OK);
    ck_assert(fabs(m.ropelength - low) <= 1e-9 * low);
    free(all.items);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* A try is judged where it leaves its coarsest polygon, against where the
 * best's own tightening left it (escape.c, judge_coarse): behind, it is
 * given up there, takes no step on the final polygon, and the next try
 * starts at once; not behind, it goes on to the final polygon.  T(2,3)
 * from the round torus at 200 vertices: every tightening's coarsest
 * polygon has 100.  The lineage is rebuilt from the history and the
 * escapes' log alone: the first tightening's last step before its first
 * refinement (the lowest explored curve's, put back), then the coarse
 * figure of each try that improved; explored tries reach nothing.  (A run
 * whose first tightening starts on the final polygon, as at 130 vertices,
 * where the torus is too long for a coarse level, has no lineage until a
 * try improves, and refines every try until then.) */
START_TEST(a_try_behind_on_its_coarsest_polygon_is_given_up_there)
{
    if (quick() && tkt_skip("a_try_behind_on_its_coarsest_polygon_is_given_up_there", LONG_RUN))
        return;
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_torus(2, 3, 120, &c, NULL), TK_OK);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.vertices = 200;
    o.escapes = 8;
    o.seed = 3;
    o.loose = 0; /* every try on the coarsest polygon */
    /* polished on its coarse polygon, every try ends in the lineage's
     * basin, its figure within 3e-5 of the lineage's; since the tries
     * turn the curve inside out in turn, the lowest explored curve (seed
     * 3's turned one) is lower than every later try's in seeds 1 to 16,
     * so that the branch that refines a try is not always taken here */
    o.max_steps = 30000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_OK);
    /* up to the budget's last fifth: the reserve polishes the best and
     * begins no try (the_last_fifth_of_the_budget_polishes_the_best) */
    while (tk_run_latest(run)->step < o.max_steps / 5 * 4)
        ck_assert_msg(tk_run_step(run, &err) == TK_OK, "%s", err.message);
    size_t nh = 0, ne = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    const tk_escape *e = tk_run_escapes(run, &ne);
    ck_assert_uint_eq(h[0].vertices, 100); /* the first tightening starts coarse */
    double lineage = NAN;
    for (size_t i = 1; i < nh && isnan(lineage); i++)
        if (h[i].vertices > h[i - 1].vertices) {
            ck_assert_uint_eq(h[i - 1].vertices, 100);
            lineage = h[i - 1].ropelength;
        }
    ck_assert(!isnan(lineage));
    size_t given_up = 0, refined = 0;
    for (size_t k = 0; k < ne; k++) {
        /* the try's steps: escapes counts the tries begun, and a restart
         * that begins none (the best, or the lowest explored, put back)
         * ends it */
        size_t first = nh, last = 0, on_final = 0;
        for (size_t i = 0; i < nh; i++)
            if (h[i].escapes == (int)k + 1 && (first == nh || h[i].restarts == h[first].restarts)) {
                first = i < first ? i : first;
                last = i;
                on_final += h[i].vertices == o.vertices;
            }
        ck_assert_uint_lt(first, nh);
        if (e[k].explored) {
            /* judged among the explored (an_explored_try_...), never as a
             * try on the final polygon */
            ck_assert(isnan(e[k].reached));
            continue;
        }
        bool ended = k + 1 < ne; /* the last can be cut short by the budget or the reserve */
        printf("try %zu: steps %ld-%ld, from %.6f, coarse %.6f against %.6f, %zu steps on the "
               "final polygon, reached %.6f\n", k + 1, h[first].step, h[last].step, e[k].from,
               e[k].coarse, lineage, on_final, e[k].reached);
        if (isnan(e[k].coarse)) {
            ck_assert(!ended);
            continue;
        }
        ck_assert_uint_eq(h[first].vertices, 100);
        if (e[k].coarse > lineage) {
            /* given up on its coarse polygon, at its last step there */
            ck_assert_uint_eq(on_final, 0);
            ck_assert(isnan(e[k].reached));
            if (ended) {
                ck_assert(e[k].coarse == h[last].ropelength);
                given_up++;
            }
        } else if (ended) {
            ck_assert_uint_gt(on_final, 0);
            ck_assert(!isnan(e[k].reached));
            refined++;
        }
        if (e[k].improved)
            lineage = e[k].coarse;
    }
    printf("T(2,3) at 200 vertices, %zu tries: %zu given up on the coarse polygon, %zu refined; "
           "ends at %.6f\n", ne, given_up, refined, tk_run_latest(run)->ropelength);
    ck_assert_uint_gt(given_up, 0);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* Exploration (escape.c): before the first refinement, tries deform the
 * lowest curve found on the coarsest polygon and are judged there.  The
 * figure-eight, disguised (seed 14, perturbation 0.01), at resolution 5:
 * its coarse levels stop at 55.30 with kinks at the curvature bound,
 * and its final polygon, refined from there, took 60,000 steps to come
 * down.  With a budget of 32,000 steps an explored try leaves it for the
 * tight knot's basin (the plateau turned inside out, when it was the
 * first, at 42.18) and the run ends within 0.2% of the best known 4_1
 * (42.09703, 400 vertices).  Without loose levels: with them (the default) the first
 * tightening passes the trap by, down to 42.13 on 212 vertices before
 * any try. */
/* The run of the test below: the disguised figure-eight into *d, at
 * resolution 5 without loose levels, for 32,000 steps. */
static tk_run *trap_run(tk_curve **d)
{
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_generate_figure_eight(200, &c, NULL), TK_OK);
    ck_assert_int_eq(tk_generate_disguise(c, 14, 0.01, d, NULL), TK_OK);
    tk_curve_free(&c);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.loose = 0; /* the trap is the coarse level's: loose levels pass it by */
    o.max_steps = 32000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(*d, &o, &run, &err) == TK_OK, "%s", err.message);
    return run;
}

START_TEST(an_explored_try_leaves_a_coarse_trap)
{
    if (quick() && tkt_skip("an_explored_try_leaves_a_coarse_trap", LONG_RUN))
        return;
    tk_curve *d = NULL;
    tk_run *run = trap_run(&d);
    tk_error err;
    ck_assert_msg(tk_run_until(run, NULL, &err) == TK_OK, "%s", err.message);
    size_t nh = 0, ne = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    const tk_escape *e = tk_run_escapes(run, &ne);
    ck_assert_uint_gt(ne, 0);
    ck_assert(e[0].explored);
    /* the first tightening's plateau: its last step before the first try */
    size_t at = 1;
    while (at < nh && h[at].escapes == 0)
        at++;
    ck_assert_uint_lt(at, nh);
    double plateau = h[at - 1].ropelength;
    ck_assert_int_eq(h[at - 1].step, e[0].step);
    ck_assert(e[0].from == plateau);
    /* an explored try: on the plateau's polygon (turned, on the coarsest
     * polygon of the plateau's ropelength), judged where it leaves it */
    ck_assert_uint_eq(h[at].vertices,
                      e[0].turned ? (size_t)ceil(2.5 * plateau) : h[at - 1].vertices);
    size_t left = at + 1; /* (a loose try's polygon follows its ropelength down first) */
    while (left < nh && h[left].vertices <= h[left - 1].vertices &&
           h[left].restarts == h[at].restarts)
        left++;
    ck_assert_uint_lt(left, nh);
    ck_assert(e[0].coarse == h[left - 1].ropelength);
    ck_assert(isnan(e[0].reached));
    /* an explored try leaves the trap */
    size_t k = 0;
    while (k < ne && e[k].explored && !(e[k].coarse < 0.9 * plateau && e[k].improved))
        k++;
    for (size_t i = 0; i < ne; i++)
        printf("try %zu: %s%s, from %.5f, coarse %.5f\n", i + 1,
               e[i].explored ? "explored" : "on the final polygon",
               e[i].turned ? ", turned" : "", e[i].from, e[i].coarse);
    ck_assert_msg(k < ne && e[k].explored, "no explored try left the plateau at %.5f", plateau);
    const tk_step_report *end = tk_run_latest(run);
    double excess = end->ropelength / 42.09703 - 1.0;
    printf("disguised figure-eight at resolution 5: plateau %.5f, explored try %zu left it at "
           "%.5f; ends at %.6f (%+.3f%%, %zu vertices), %zu tries\n", plateau, k + 1,
           e[k].coarse, end->ropelength, 100.0 * excess, end->vertices, ne);
    ck_assert_msg(fabs(excess) < 2e-3, "%.6f", end->ropelength);
    tk_run_free(&run);
    tk_curve_free(&d);
}
END_TEST

/* The largest distance between like vertices of a and b (as many
 * vertices) with each centred on its centroid and scaled to unit length,
 * in mean edges: how far apart two polygons are as shapes, whatever
 * their scale. */
static double shape_gap(const tk_curve *a, const tk_curve *b)
{
    ck_assert_uint_eq(a->nvert, b->nvert);
    const tk_curve *ab[2] = {a, b};
    double centre[2][3] = {{0}}, scale[2];
    for (int k = 0; k < 2; k++) {
        for (size_t v = 0; v < a->nvert; v++)
            for (int j = 0; j < 3; j++)
                centre[k][j] += ab[k]->xyz[3 * v + j] / (double)a->nvert;
        scale[k] = 1.0 / tk_curve_length(ab[k]);
    }
    double gap = 0.0;
    for (size_t v = 0; v < a->nvert; v++) {
        double d2 = 0.0;
        for (int j = 0; j < 3; j++) {
            double x = (a->xyz[3 * v + j] - centre[0][j]) * scale[0];
            double y = (b->xyz[3 * v + j] - centre[1][j]) * scale[1];
            d2 += (x - y) * (x - y);
        }
        gap = fmax(gap, sqrt(d2));
    }
    return gap * (double)a->nvert;
}

/* The first explored try is the start turned inside out (escape.c,
 * turned_start), not the plateau: the figure-eight's disguise of the test
 * above (loose levels off, so that the try comes onto the coarsest
 * polygon at once).  After the try's first step the curve is, as a
 * shape, within a quarter of an edge of the start turned about its
 * centroid on 1.5 vertices a unit of the plateau's ropelength and
 * resampled to that polygon, made here apart (a step moves no vertex by
 * more than that); the plateau turned so is ten times as far from it, so
 * the test tells the two apart (0.02 and 1.22 edges: a disguised
 * figure-eight and its plateau are alike as shapes, a catalogue file and
 * its tightened curve less so). */
START_TEST(the_first_explored_try_turns_the_start)
{
    tk_curve *d = NULL;
    tk_run *run = trap_run(&d);
    tk_error err;
    size_t ne = 0, nh = 0;
    tk_curve *plateau = NULL;
    while (tk_run_escapes(run, &ne), ne == 0) {
        tk_curve_free(&plateau);
        ck_assert_int_eq(tk_curve_copy(tk_run_curve(run), &plateau, NULL), TK_OK);
        int rc = tk_run_step(run, &err);
        ck_assert_msg(rc == TK_OK, "%s", err.message);
        ck_assert_int_lt(tk_run_latest(run)->step, tk_run_options(run)->max_steps);
    }
    const tk_escape *e = tk_run_escapes(run, &ne);
    ck_assert(e[0].explored && e[0].turned);
    const tk_step_report *h = tk_run_history(run, &nh);
    ck_assert_int_eq(h[nh - 1].escapes, 1);
    ck_assert(e[0].from == h[nh - 2].ropelength);
    const tk_curve *now = tk_run_curve(run);
    size_t count = (size_t)(1.5 * e[0].from);
    double offset[3] = {0.0, 0.0, 0.0}, gap[2];
    const tk_curve *from[2] = {d, plateau};
    for (int k = 0; k < 2; k++) {
        tk_curve *t = NULL, *u = NULL;
        ck_assert_int_eq(tk_relax_turn(from[k], offset, count, 3000, &t, &err), TK_OK);
        ck_assert_int_eq(tk_curve_resample_total(t, now->nvert, &u, &err), TK_OK);
        gap[k] = shape_gap(now, u);
        tk_curve_free(&t);
        tk_curve_free(&u);
    }
    printf("the first explored try after its first step, %zu vertices: %.3f edges from the start "
           "turned, %.3f from the plateau (%.4f) turned\n", now->nvert, gap[0], gap[1],
           e[0].from);
    ck_assert_msg(gap[0] < 0.25, "%.3f edges from the start turned", gap[0]);
    ck_assert_msg(gap[1] > 0.5 && gap[1] > 10.0 * gap[0], "the plateau's turn is %.3f edges from it",
                  gap[1]);
    tk_curve_free(&plateau);
    tk_run_free(&run);
    tk_curve_free(&d);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("tighten");
    TCase *tc = tcase_create("tighten");
    tcase_set_timeout(tc, 900);
    tcase_add_test(tc, start_thinner_than_tube_is_refused);
    tcase_add_test(tc, runs_beyond_the_vertex_limit_are_refused);
    tcase_add_test(tc, corrected_steps_report_their_forces);
    tcase_add_test(tc, history_and_snapshots);
    tcase_add_test(tc, timing_accounts_for_the_run);
    tcase_add_test(tc, cpu_time_counts_the_run_s_own_processor_time);
    tcase_add_test(tc, a_work_budget_gives_the_same_run_at_any_load);
    tcase_add_test(tc, the_knot_type_is_checked);
    tcase_add_test(tc, escapes_keep_the_best_and_repeat);
    tcase_add_test(tc, a_resumed_run_goes_on_where_it_was);
    tcase_add_test(tc, a_loose_start_gets_its_coarse_level_late);
    tcase_add_test(tc, a_resumed_run_keeps_its_escapes);
    tcase_add_test(tc, a_crawling_run_escapes_after_a_fifth_of_its_budget);
    tcase_add_test(tc, the_last_fifth_of_the_budget_polishes_the_best);
    tcase_add_test(tc, a_best_put_back_is_polished_not_replayed);
    tcase_add_test(tc, a_run_that_tried_no_escape_returns_its_best);
    tcase_add_test(tc, the_first_explored_try_turns_the_start);
    tcase_add_test(tc, converge_stops_where_the_flow_has_no_more_to_give);
    tcase_add_test(tc, the_defaults_tighten_the_figure_eight);
    tcase_add_test(tc, re_resolution_keeps_the_resolution);
    tcase_add_test(tc, coarse_to_fine_ends_at_the_resolution);
    tcase_add_test(tc, rings_far_apart_get_the_resolution_s_vertices);
    tcase_add_test(tc, vertices_option_ends_at_exactly_that_count);
    tcase_add_test(tc, cancellation_stops_within_one_step);
    tcase_add_test(tc, parallel_runs_equal_serial_runs);
    tcase_add_test(tc, a_step_lowers_the_ropelength_it_leaves);
    tcase_add_test(tc, round_hopf_start_with_continuum_of_contacts);
    tcase_add_test(tc, recovery_restores_thousands_of_contacts_without_rescaling);
    tcase_add_test(tc, a_fine_start_is_set_up_with_the_tolerance_of_its_edges);
    tcase_add_test(tc, a_fine_tight_polygon_is_restored_in_place);
    tcase_add_test(tc, an_expansion_leaves_a_long_trial_s_crossings_out);
    tcase_add_test(tc, a_fine_curve_s_forces_resolve_its_motion);
    tcase_add_test(tc, a_tight_start_refined_and_autoscaled_keeps_its_contacts);
    tcase_add_test(tc, a_tight_start_refined_sixteen_times_over_keeps_its_place);
    tcase_add_test(tc, a_tight_curve_tightened_again_steps_at_a_bounded_cost);
    tcase_add_test(tc, a_fine_tight_curve_polishes_at_the_rate_of_its_fall);
    tcase_add_test(tc, polishing_stops_at_the_third_level_where_the_edge_sets_the_tolerance);
    tcase_add_test(tc, a_refined_tight_polygon_is_restored_without_rescaling);
    tcase_add_test(tc, a_loose_curve_is_kept_at_the_tube);
    tcase_add_test(tc, a_loose_start_keeps_its_final_count_through_escapes);
    tcase_add_test(tc, a_loose_coarse_level_follows_the_ropelength);
    tcase_add_test(tc, a_loose_level_keeps_its_polygon_where_fewer_vertices_lose_the_type);
    tcase_add_test(tc, a_loose_try_starts_on_its_own_count);
    tcase_add_test(tc, a_loose_start_at_a_vertex_count_escapes_coarse);
    tcase_add_test(tc, a_fine_coarse_level_waits_as_many_more_steps);
    tcase_add_test(tc, a_coarse_level_above_the_coarsest_moves_on_at_the_final_rate);
    tcase_add_test(tc, the_coarsest_level_of_a_try_is_polished_first);
    tcase_add_test(tc, a_try_leaves_its_coarsest_level_after_a_twentieth_of_the_budget);
    tcase_add_test(tc, unknot_and_unlink_are_handled);
    tcase_add_test(tc, hopf_link_tightens_towards_8_pi);
    tcase_add_test(tc, generated_hopf_link_tightens_to_8_pi);
    tcase_add_test(tc, catalogue_trefoil_at_resolution_5);
    tcase_add_test(tc, trefoil_does_not_stall_near_its_critical_point);
    tcase_add_test(tc, generated_chain_of_three_tightens_to_12_pi_plus_4);
    suite_add_tcase(s, tc);
    /* The three longest (about 300 s of the program's 540 on one idle
     * core), tagged so that tests/run-all.sh runs them in a process of
     * their own beside the rest (CK_INCLUDE_TAGS / CK_EXCLUDE_TAGS). */
    TCase *long_runs = tcase_create("long");
    tcase_set_tags(long_runs, "long");
    tcase_set_timeout(long_runs, 900);
    tcase_add_test(long_runs, an_explored_try_leaves_a_coarse_trap);
    tcase_add_test(long_runs, loose_levels_come_first_for_every_loose_try);
    tcase_add_test(long_runs, a_try_behind_on_its_coarsest_polygon_is_given_up_there);
    suite_add_tcase(s, long_runs);
    /* A hang here is the failure: a short timeout. */
    TCase *range = tcase_create("range");
    tcase_set_timeout(range, 30);
    tcase_add_test(range, radius_out_of_the_range_is_refused);
    tcase_add_test(range, resampling_that_crosses_the_curve_is_refused);
    tcase_add_test(range, an_autoscaled_rope_shorter_than_its_diameter_is_refused);
    suite_add_tcase(s, range);
    return tkt_run_suite(s);
}

