/* Constraints on vertices (tk/pin.h): their text, adding and settling
 * them, their linearisation against finite differences, resampling and
 * the VECT round trip, and the flow: a rope between two parallel planes
 * whose ends slide on them tightens to the planes' distance (an exact
 * value), its pinned ends on their planes at every step and through a
 * refinement, each end's force the rope's unit tension; the catalogue's
 * clasp is refused when a constraint is not met; the paper's clasp ends
 * near the smooth value its criticality analysis gives, below the half
 * circles, its tips apart. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/curve.h"
#include "tk/generate.h"
#include "tk/pin.h"
#include "tk/struts.h"
#include "tk/tighten.h"
#include "tk/vect.h"

/* Two pins alike, field by field (their padding is not theirs). */
static bool same_pin(const tk_pin *a, const tk_pin *b)
{
    return a->comp == b->comp && a->vertex == b->vertex && a->kind == b->kind &&
           !memcmp(a->normal, b->normal, sizeof a->normal) && a->offset == b->offset &&
           !memcmp(a->point, b->point, sizeof a->point);
}

static tk_pin parsed(const char *text, bool *at_vertex)
{
    tk_pin p;
    tk_error err;
    ck_assert_msg(tk_pin_parse(text, &p, at_vertex, &err) == TK_OK, "%s: %s", text, err.message);
    return p;
}

START_TEST(text_round_trips_and_errors_name_the_constraint)
{
    const char *good[] = {"0:0=free", "1:7=fixed", "0:3=point:1,2,3", "2:0=plane:0,0,1,-10.5",
                          "0:1=line:0,0,0,1,1e-3,0"};
    for (size_t i = 0; i < sizeof good / sizeof *good; i++) {
        bool at;
        tk_pin p = parsed(good[i], &at);
        ck_assert(at == (strstr(good[i], "fixed") != NULL));
        if (at)
            continue; /* "fixed" is written as the point it takes */
        char text[256];
        tk_pin_format(&p, text, sizeof text);
        bool again;
        tk_pin q = parsed(text, &again);
        ck_assert_msg(same_pin(&p, &q), "%s -> %s", good[i], text);
    }
    const char *bad[][2] = {{"0=plane:0,0,1,1", "COMP:VERTEX="},
                            {"a:0=free", "COMP:VERTEX="},
                            {"0:0=plane:0,0,1", "plane:nx,ny,nz,d"},
                            {"0:0=plane:0,0,1,1,1", "plane:nx,ny,nz,d"},
                            {"0:0=point:1,nan,3", "point:x,y,z"},
                            {"0:0=fixed:1", "fixed"},
                            {"0:0=hinge", "the kind is"}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        tk_pin p;
        bool at;
        tk_error err;
        ck_assert_int_eq(tk_pin_parse(bad[i][0], &p, &at, &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, bad[i][1]) != NULL, "%s: %s", bad[i][0], err.message);
    }
}
END_TEST

/* An open rope from (-5, 0, 0) to (5, 3, 0), wavy in between. */
static tk_curve *wavy_rope(size_t n)
{
    tk_curve *c = NULL;
    bool open = false;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &open, NULL), TK_OK);
    for (size_t k = 0; k < n; k++) {
        double s = (double)k / (double)(n - 1), *x = tk_curve_vertex(c, k);
        x[0] = -5.0 + 10.0 * s;
        x[1] = 3.0 * s + 1.5 * sin(2.0 * M_PI * s);
        x[2] = 0.8 * sin(M_PI * s);
    }
    return c;
}

static void pin(tk_curve *c, const char *text)
{
    bool at;
    tk_pin p = parsed(text, &at);
    tk_error err;
    ck_assert_msg(tk_curve_pin_add(c, &p, at, &err) == TK_OK, "%s: %s", text, err.message);
}

START_TEST(adding_checks_the_vertex_and_the_numbers)
{
    tk_curve *c = wavy_rope(20);
    const char *bad[][2] = {{"1:0=free", "no component 1"},
                            {"0:20=free", "no vertex 20"},
                            {"0:3=plane:0,0,0,1", "normal is zero"},
                            {"0:3=line:0,0,0,0,0,0", "direction is zero"},
                            {"0:3=plane:1e300,1e300,1e300,1", "not finite"}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        bool at;
        tk_pin p = parsed(bad[i][0], &at);
        tk_error err;
        ck_assert_int_eq(tk_curve_pin_add(c, &p, at, &err), TK_EINVAL);
        ck_assert_msg(strstr(err.message, bad[i][1]) != NULL, "%s: %s", bad[i][0], err.message);
    }
    pin(c, "0:0=plane:2,0,0,-10"); /* made a unit normal: x = -5 */
    ck_assert_double_eq_tol(c->pins[0].normal[0], 1.0, 1e-15);
    ck_assert_double_eq_tol(c->pins[0].offset, -5.0, 1e-15);
    ck_assert_double_eq_tol(tk_pin_distance(c, &c->pins[0]), 0.0, 1e-15);
    bool at;
    tk_pin again = parsed("0:0=free", &at);
    tk_error err;
    ck_assert_int_eq(tk_curve_pin_add(c, &again, at, &err), TK_EINVAL);
    ck_assert(strstr(err.message, "has a constraint already"));
    /* fixed: where the vertex is */
    pin(c, "0:7=fixed");
    ck_assert(!memcmp(c->pins[1].point, tk_curve_vertex(c, 7), 3 * sizeof(double)));
    /* settling: a rounding away is closed, farther is refused naming it */
    pin(c, "0:19=plane:1,0,0,5.000001");
    ck_assert_int_eq(tk_curve_pins_check(c, 1e-5, NULL), TK_OK);
    ck_assert_double_eq(tk_curve_vertex(c, 19)[0], 5.0); /* checked, left as it is */
    ck_assert_int_eq(tk_curve_pins_check(c, 1e-7, NULL), TK_EINVAL);
    ck_assert_int_eq(tk_curve_pins_settle(c, 1e-5, NULL), TK_OK);
    ck_assert_double_eq_tol(tk_curve_vertex(c, 19)[0], 5.000001, 1e-15);
    pin(c, "0:10=line:0,0,5,0,0,1");
    ck_assert_int_eq(tk_curve_pins_settle(c, 1e-5, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "constraint 0:10=line") != NULL, "%s", err.message);
    tk_curve_free(&c);
}
END_TEST

/* The flow moves a pinned vertex by P v (tk_pin_project): along P v the
 * constraint's function g (n.x - d; the distance to the line or the
 * point) stays 0 to second order in the step, against finite
 * differences, while the part (I - P) v it takes away moves g at first
 * order by its own length. */
START_TEST(the_projection_is_the_constraint_s_tangent_space)
{
    tkt_rng rng = {7};
    const char *kinds[] = {"0:5=plane:0.3,-0.4,0.8,0.2", "0:5=line:0.1,0.2,0.3,1,2,-1",
                           "0:5=point:0.5,0.5,0.5"};
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++) {
        tk_curve *c = wavy_rope(12);
        pin(c, kinds[i]);
        tk_curve_pins_snap(c);
        const tk_pin *p = &c->pins[0];
        double *x = tk_curve_vertex(c, 5), x0[3];
        memcpy(x0, x, sizeof x0);
        for (int trial = 0; trial < 20; trial++) {
            double v[3], pv[3];
            tkt_rng_point(&rng, 1.0, v);
            memcpy(pv, v, sizeof v);
            tk_pin_project(p, pv);
            double rejected = sqrt((v[0] - pv[0]) * (v[0] - pv[0]) +
                                   (v[1] - pv[1]) * (v[1] - pv[1]) +
                                   (v[2] - pv[2]) * (v[2] - pv[2]));
            for (double h = 1e-2; h >= 1e-4; h /= 10) {
                for (int k = 0; k < 3; k++)
                    x[k] = x0[k] + h * pv[k];
                double along = tk_pin_distance(c, p);
                for (int k = 0; k < 3; k++)
                    x[k] = x0[k] + h * v[k];
                double whole = tk_pin_distance(c, p);
                memcpy(x, x0, sizeof x0);
                ck_assert_msg(along <= 1e-12 + 2.0 * h * h, "%s: %g along P v at h %g",
                              kinds[i], along, h);
                ck_assert_msg(fabs(whole - h * rejected) <= 1e-12 + 2.0 * h * h,
                              "%s: moved %g, (I - P) v gives %g at h %g", kinds[i], whole,
                              h * rejected, h);
            }
        }
        tk_curve_free(&c);
    }
}
END_TEST

START_TEST(resampling_and_rigid_motions_carry_the_pins)
{
    tk_curve *c = wavy_rope(30), *r = NULL;
    pin(c, "0:0=plane:1,0,0,-5");
    pin(c, "0:15=line:0,1.5,0,0,0,1");
    pin(c, "0:29=plane:1,0,0,5");
    tk_curve_pins_settle(c, 1.0, NULL);
    size_t count = 61;
    ck_assert_int_eq(tk_curve_resample(c, &count, &r, NULL), TK_OK);
    ck_assert_uint_eq(r->npins, 3);
    ck_assert_uint_eq(r->pins[0].vertex, 0);
    ck_assert_uint_eq(r->pins[1].vertex, 31); /* 15 of 29 vertices on, of 60: 31.03 */
    ck_assert_uint_eq(r->pins[2].vertex, 60);
    for (size_t i = 0; i < r->npins; i++)
        ck_assert_double_eq_tol(tk_pin_distance(r, &r->pins[i]), 0.0, 1e-12);
    /* moved as a whole, the constraints move with the curve */
    double shift[3] = {1, -2, 3}, turn[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
    tk_curve_translate(r, shift);
    tk_curve_rotate(r, turn);
    tk_curve_scale(r, 2.5);
    for (size_t i = 0; i < r->npins; i++)
        ck_assert_double_eq_tol(tk_pin_distance(r, &r->pins[i]), 0.0, 1e-12);
    tk_curve_free(&r);
    tk_curve_free(&c);
}
END_TEST

START_TEST(vect_keeps_the_constraints)
{
    tk_curve *c = wavy_rope(9), *back = NULL;
    pin(c, "0:0=plane:0.6,0.8,0,-3");
    pin(c, "0:4=point:0,1.5,0.8");
    pin(c, "0:8=line:5,3,0,0,0,1");
    tk_curve_pins_settle(c, 10.0, NULL);
    char *text = NULL;
    ck_assert_int_eq(tk_vect_to_string(c, &text, NULL, NULL), TK_OK);
    ck_assert_msg(strstr(text, "# Constraint 1 Plane 0.59999999999999998 0.80000000000000004 0 -3") &&
                      strstr(text, "# Cst: 2"),
                  "%s", text);
    tk_error err;
    ck_assert_msg(tk_vect_parse(text, strlen(text), NULL, &back, &err) == TK_OK, "%s",
                  err.message);
    ck_assert_uint_eq(back->npins, 3);
    for (size_t i = 0; i < 3; i++)
        ck_assert_msg(same_pin(&c->pins[i], &back->pins[i]), "pin %zu", i);
    free(text);
    tk_curve_free(&back);
    /* errors name the line */
    const char *bad[][2] = {
        {"VECT\n1 2 0\n2\n0\n# Constraint 1 Plane 0 0 1\n0 0 0 # Cst: 1\n1 0 0\n",
         "line 5: constraint 1: plane takes 4 numbers"},
        {"VECT\n1 2 0\n2\n0\n0 0 0 # Cst: 2\n1 0 0\n", "line 5: constraint 2 is not defined"},
        {"VECT\n1 2 0\n2\n0\n# Cst: 1\n# Constraint 1 Free\n0 0 0\n1 0 0\n",
         "line 5: '# Cst: 1' must follow the coordinates"},
        {"VECT\n1 2 0\n2\n0\n# Constraint 1 Free\n# Constraint 1 Free\n0 0 0 # Cst: 1\n1 0 0\n",
         "line 6: constraint 1 is defined twice (first on line 5)"},
        {"VECT\n1 2 0\n2\n0\n# Constraint 1 Wall 1\n0 0 0 # Cst: 1\n1 0 0\n",
         "line 5: constraint 1: the kind is"},
        {"VECT\n1 2 0\n2\n0\n# Constraint 1 Plane 0 0 0 1\n0 0 0 # Cst: 1\n1 0 0\n",
         "line 6: constraint 0:0: the plane normal is zero"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        tk_curve *d = NULL;
        ck_assert_int_eq(tk_vect_parse(bad[i][0], strlen(bad[i][0]), NULL, &d, &err), TK_EPARSE);
        ck_assert_msg(strstr(err.message, bad[i][1]) != NULL, "%zu: %s", i, err.message);
    }
    tk_curve_free(&c);
}
END_TEST

typedef struct watch {
    double worst;     /* the farthest a pinned vertex was from its constraint */
    size_t counts[8]; /* the vertex counts seen, in order */
    size_t ncounts;
    tk_run *run;
} watch;

static int watch_pins(const tk_step_report *s, void *user)
{
    watch *w = user;
    const tk_curve *c = tk_run_curve(w->run);
    for (size_t i = 0; i < c->npins; i++)
        w->worst = fmax(w->worst, tk_pin_distance(c, &c->pins[i]));
    if ((w->ncounts == 0 || w->counts[w->ncounts - 1] != s->vertices) && w->ncounts < 8)
        w->counts[w->ncounts++] = s->vertices;
    return 0;
}

/* Two parallel planes x = -5 and x = 5, the rope's ends sliding on them:
 * the shortest rope between them is a segment at right angles to both,
 * 10 long (10.44 with its ends held where they start).  Coarse to fine,
 * every step keeps the ends on their planes within 1e-9 of the diameter,
 * and the end's force is the rope's tension, |grad length| at an end, 1. */
START_TEST(a_rope_between_planes_tightens_to_their_distance)
{
    tk_curve *c = wavy_rope(40);
    pin(c, "0:0=plane:1,0,0,-5");
    pin(c, "0:39=plane:1,0,0,5");
    tk_options o = TK_OPTIONS_INIT;
    o.vertices = 80; /* 20, 40 and 80 (a resolution follows the ropelength, near 0 here) */
    o.max_steps = 1500;
    o.escapes = 0;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    watch w = {0.0, {0}, 0, run};
    tk_run_set_progress(run, watch_pins, &w);
    ck_assert_int_eq(tk_run_until(run, NULL, &err), TK_OK);
    const tk_curve *fin = tk_run_curve(run);
    double length = tk_run_latest(run)->length;
    printf("rope between planes: length %.12f after %ld steps, on %zu vertices (levels:",
           length, tk_run_latest(run)->step, fin->nvert);
    for (size_t i = 0; i < w.ncounts; i++)
        printf(" %zu", w.counts[i]);
    printf("), ends at most %.3g off their planes\n", w.worst);
    ck_assert_uint_ge(w.ncounts, 2); /* refined at least once */
    ck_assert(w.worst <= 1e-9 * 2.0 * o.radius);
    ck_assert_double_eq_tol(length, 10.0, 1e-6);
    ck_assert_uint_eq(fin->npins, 2);
    double force[2];
    ck_assert_int_eq(tk_run_pin_forces(run, force, NULL), TK_OK);
    for (int i = 0; i < 2; i++)
        ck_assert_double_eq_tol(force[i], 1.0, 1e-6);
    tk_run_free(&run);
    /* held at their starting points instead, the ends keep the rope at
     * the chord between them */
    tk_curve_free(&c);
    c = wavy_rope(40);
    o.vertices = 0;
    ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK);
    ck_assert_int_eq(tk_run_until(run, NULL, NULL), TK_OK);
    ck_assert_double_eq_tol(tk_run_latest(run)->length, sqrt(109.0), 1e-4);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* The catalogue's clasp: its four planes come from the file; moved off
 * one of them by more than a rounding, the start is refused, naming the
 * constraint. */
START_TEST(a_clasp_off_its_plane_is_refused)
{
    tk_curve *c = tkt_catalogue_curve("simple_clasp.vect"); /* (fails the test when absent) */
    ck_assert_uint_eq(c->npins, 4);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 5;
    tk_run *run = NULL;
    ck_assert_int_eq(tk_run_new(c, &o, &run, NULL), TK_OK); /* 7.8e-6 off: settled */
    tk_run_free(&run);
    tk_curve_vertex(c, c->offset[1])[2] += 0.01;
    tk_error err;
    ck_assert_int_eq(tk_run_new(c, &o, &run, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "constraint 1:0=plane") != NULL, "%s", err.message);
    tk_curve_free(&c);
}
END_TEST

/* The clasp's ends slide on their planes through 2,000 steps of the flow
 * with its struts, coarse to fine: never more than 1e-9 of the diameter
 * off them, and the ropes shorter. */
START_TEST(the_clasp_s_ends_stay_on_their_planes)
{
    tk_curve *c = tkt_catalogue_curve("simple_clasp.vect"); /* (fails the test when absent) */
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5.0;
    o.max_steps = 2000;
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    watch w = {0.0, {0}, 0, run};
    tk_run_set_progress(run, watch_pins, &w);
    double start = tk_run_latest(run)->ropelength;
    ck_assert_int_eq(tk_run_until(run, NULL, &err), TK_OK);
    const tk_step_report *s = tk_run_latest(run);
    printf("clasp: %.6f to %.6f in %ld steps, levels", start, s->ropelength, s->step);
    for (size_t i = 0; i < w.ncounts; i++)
        printf(" %zu", w.counts[i]);
    printf(", ends at most %.3g off their planes, %zu struts\n", w.worst, s->struts);
    ck_assert_uint_ge(w.ncounts, 2);
    ck_assert(w.worst <= 1e-9 * 2.0 * o.radius);
    ck_assert(s->ropelength < start - 0.1);
    ck_assert_uint_gt(s->struts, 0);
    /* struts only between the ropes, as the paper's Figure 6 */
    size_t ns = 0;
    const tk_strut *st = tk_run_struts(run, &ns);
    for (size_t i = 0; i < ns; i++)
        ck_assert_uint_ne(st[i].comp[0], st[i].comp[1]);
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

/* The paper's clasp (tk_generate_clasp: ends pulled straight up and
 * down, Table 2's Gehring clasp).  Tightened, its measure, the ropes'
 * length beyond their planes' offsets over the diameter, is below the
 * 2 pi - 2 of two half circles about the tips and near the smooth
 * 4.2629 of Cantarella, Fu, Kusner, Sullivan and Wrinkle (2006), and
 * its tips are more than a diameter apart: the gap their criticality
 * analysis found.  Each leg leaves its plane at a right angle. */
START_TEST(the_paper_s_clasp_tightens_below_its_half_circles)
{
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(tk_generate_clasp(40, &c, &err), TK_OK);
    ck_assert_uint_eq(c->npins, 4);
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 3000;
    tk_run *run = NULL;
    ck_assert_msg(tk_run_new(c, &o, &run, &err) == TK_OK, "%s", err.message);
    ck_assert_int_eq(tk_run_until(run, NULL, &err), TK_OK);
    const tk_curve *fin = tk_run_curve(run);
    const tk_step_report *s = tk_run_latest(run);
    double offsets = 0.0;
    for (size_t i = 0; i < fin->npins; i++)
        offsets += fin->pins[i].offset;
    double measure = (s->length - offsets) / s->thickness;
    /* the tips: the lowest vertex of rope 0, the highest of rope 1 */
    const double *tip[2] = {NULL, NULL};
    for (size_t comp = 0; comp < 2; comp++)
        for (size_t v = fin->offset[comp]; v < fin->offset[comp + 1]; v++) {
            const double *p = tk_curve_vertex(fin, v);
            if (!tip[comp] || (comp ? p[2] > tip[comp][2] : p[2] < tip[comp][2]))
                tip[comp] = p;
        }
    double gap = sqrt(pow(tip[0][0] - tip[1][0], 2) + pow(tip[0][1] - tip[1][1], 2) +
                      pow(tip[0][2] - tip[1][2], 2)) / s->thickness;
    printf("paper's clasp: measure %.6f on %zu vertices after %ld steps (half circles "
           "%.6f, smooth 4.2629), tips %.4f diameters apart\n",
           measure, fin->nvert, s->step, 2.0 * M_PI - 2.0, gap);
    ck_assert_double_lt(measure, 2.0 * M_PI - 2.0);
    ck_assert_double_eq_tol(measure, 4.2629, 0.005 * 4.2629);
    ck_assert_double_gt(gap, 1.01);
    /* a leg meets its plane at a right angle: the end's edge along the
     * plane's normal */
    for (size_t i = 0; i < fin->npins; i++) {
        const tk_pin *p = &fin->pins[i];
        size_t v = fin->offset[p->comp] + p->vertex;
        size_t w = p->vertex == 0 ? v + 1 : v - 1;
        const double *a = tk_curve_vertex(fin, v), *b = tk_curve_vertex(fin, w);
        double e[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
        double along = (e[0] * p->normal[0] + e[1] * p->normal[1] + e[2] * p->normal[2]) /
                       sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        ck_assert_double_gt(along, 1.0 - 1e-6);
    }
    tk_run_free(&run);
    tk_curve_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("pin");
    TCase *tc = tcase_create("pin");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, text_round_trips_and_errors_name_the_constraint);
    tcase_add_test(tc, adding_checks_the_vertex_and_the_numbers);
    tcase_add_test(tc, the_projection_is_the_constraint_s_tangent_space);
    tcase_add_test(tc, resampling_and_rigid_motions_carry_the_pins);
    tcase_add_test(tc, vect_keeps_the_constraints);
    tcase_add_test(tc, a_rope_between_planes_tightens_to_their_distance);
    tcase_add_test(tc, a_clasp_off_its_plane_is_refused);
    tcase_add_test(tc, the_clasp_s_ends_stay_on_their_planes);
    tcase_add_test(tc, the_paper_s_clasp_tightens_below_its_half_circles);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
