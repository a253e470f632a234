/* The flow's trajectory, bit for bit: runs that between them take every
 * path of the flow (coarse to fine with each of its three cues, polishing,
 * re-resolution, open components with fixed ends, kinks at a stiffness
 * above 1, steps that add constraints mid-step, error recovery, the
 * fallback without the equalising motion, a motion-free start), each
 * digested every CHECKPOINT steps: a hash of every figure of every step so
 * far (all but the wall time) and, at the end, of the curve's coordinates
 * and the forces of its struts and kinks.
 *
 * tests/data/histories.txt holds the digests of the implementation the
 * engine had when this test was written.  A change of the engine that is
 * meant to keep the flow (a reorganisation, a faster solve of the same
 * system) must leave them all equal; a change meant to alter the flow
 * writes them anew (TK_HISTORY_WRITE=tests/data/histories.txt
 * build/tests/test_history) and says so in its commit.  A mismatch names
 * the run and the first checkpoint that differs, with both ropelengths.
 *
 * The sanitizer build (TK_QUICK) runs the cheap half of the runs. */
#include <check.h>
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "tk/generate.h"
#include "tk/tighten.h"

#define CHECKPOINT 50
#define REFERENCE "tests/data/histories.txt"

typedef struct digest {
    uint64_t hash;
} digest;

/* FNV-1a, 64 bits, over the bytes of one value at a time (never over a
 * struct, whose padding is undefined). */
static void mix(digest *d, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) {
        d->hash ^= b[i];
        d->hash *= 0x100000001b3ULL;
    }
}

static void mix_double(digest *d, double x)
{
    mix(d, &x, sizeof x);
}

static void mix_size(digest *d, size_t n)
{
    uint64_t v = n;
    mix(d, &v, sizeof v);
}

static void mix_report(digest *d, const tk_step_report *s)
{
    mix_size(d, (size_t)s->step);
    mix_double(d, s->ropelength);
    mix_double(d, s->length);
    mix_double(d, s->thickness);
    mix_double(d, s->minrad);
    mix_double(d, s->residual);
    mix_size(d, s->struts);
    mix_size(d, s->kinks);
    mix_double(d, s->step_size);
    mix_double(d, s->rcond);
    mix_double(d, s->violation);
    mix_size(d, (size_t)s->corrections);
    mix_size(d, s->vertices);
    /* mixed only when there are any, so that the digests of runs without
     * escapes are those recorded before escapes existed */
    if (s->escapes)
        mix_size(d, (size_t)s->escapes);
}

static void mix_end(digest *d, const tk_run *run)
{
    const tk_curve *c = tk_run_curve(run);
    for (size_t i = 0; i < 3 * c->nvert; i++)
        mix_double(d, c->xyz[i]);
    size_t ns = 0, nk = 0;
    const tk_strut *struts = tk_run_struts(run, &ns);
    const tk_kink *kinks = tk_run_kinks(run, &nk);
    for (size_t j = 0; j < ns; j++) {
        mix_size(d, struts[j].edge[0]);
        mix_size(d, struts[j].edge[1]);
        mix_double(d, struts[j].force);
    }
    for (size_t k = 0; k < nk; k++) {
        mix_size(d, kinks[k].vertex);
        mix_double(d, kinks[k].force);
    }
    size_t ne = 0;
    const tk_escape *e = tk_run_escapes(run, &ne);
    for (size_t k = 0; k < ne; k++) {
        mix_size(d, (size_t)e[k].step);
        mix_double(d, e[k].from);
        mix_double(d, e[k].amplitude);
        mix_double(d, e[k].reached);
        mix_size(d, e[k].improved);
    }
    for (size_t k = 0; k < tk_run_snapshot_count(run); k++) {
        long step = 0;
        const double *xyz = tk_run_snapshot(run, k, &step);
        mix_size(d, (size_t)step);
        for (size_t i = 0; i < 3 * c->nvert; i++)
            mix_double(d, xyz[i]);
    }
    mix_size(d, (size_t)tk_run_stop_reason(run));
}

/* One line of the reference: a run's digest at a step. */
typedef struct checkpoint {
    char name[32];
    long step;
    uint64_t hash;
    double ropelength;
} checkpoint;

typedef struct history_case {
    const char *name;
    bool quick;          /* also in the sanitizer build */
    tk_curve *(*start)(void);
    void (*options)(tk_options *o);
} history_case;

/* (the curve is read after the call: argument order is unspecified) */
static tk_curve *generated(int rc, tk_curve **c)
{
    ck_assert_int_eq(rc, TK_OK);
    return *c;
}

static tk_curve *trefoil(void)
{
    tk_curve *c = NULL;
    return generated(tk_generate_torus(2, 3, 120, &c, NULL), &c);
}

static tk_curve *chain(void)
{
    tk_curve *c = NULL;
    return generated(tk_generate_chain(3, 48, &c, NULL), &c);
}

static tk_curve *hopf(void)
{
    tk_curve *c = NULL;
    return generated(tk_generate_chain(2, 40, &c, NULL), &c);
}

static tk_curve *borromean(void)
{
    tk_curve *c = NULL;
    return generated(tk_generate_borromean(48, &c, NULL), &c);
}

static tk_curve *tight_hopf(void)
{
    tk_curve *c = NULL;
    return generated(tk_generate_hopf(32, &c, NULL), &c);
}

/* An open arc: 70 consecutive vertices of an 80-vertex trefoil, ends
 * fixed. */
static tk_curve *open_arc(void)
{
    tk_curve *t = trefoil(), *c = NULL;
    size_t n = 70;
    bool closed = false;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &closed, NULL), TK_OK);
    for (size_t i = 0; i < n; i++)
        memcpy(c->xyz + 3 * i, t->xyz + 3 * (i * 120 / 80), 3 * sizeof *c->xyz);
    tk_curve_free(&t);
    return c;
}

/* The flow itself is pinned without escapes (they start only once it
 * has converged); one case below has them. */
static void autoscaled(tk_options *o)
{
    o->autoscale = true;
    o->escapes = 0;
}

/* Coarse to fine with two coarse levels, moved on by the budget and by
 * the ropelength all but stopping. */
static void coarse_to_fine(tk_options *o)
{
    o->autoscale = true;
    o->resolution = 6;
    o->max_steps = 500;
}

static void re_resolving(tk_options *o)
{
    o->autoscale = true;
    o->resolution = 4;
    o->coarse_to_fine = false;
    o->re_resolve = 0.05;
    o->max_steps = 400;
}

static void stiff_without_equalising(tk_options *o)
{
    o->autoscale = true;
    o->lambda = 1.5;
    o->equalise = 0.0;
    o->max_steps = 300;
}

static void long_polish(tk_options *o)
{
    o->autoscale = true;
    o->max_steps = 1200;
}

/* Coarse to fine moved on by polishing alone, then a stop on the change. */
static void coarse_to_fine_to_convergence(tk_options *o)
{
    o->autoscale = true;
    o->resolution = 5.2;
    o->min_change = 2e-6;
    o->max_steps = 3000;
}

static void until_residual(tk_options *o)
{
    o->autoscale = true;
    o->min_residual = 0.02;
    o->max_steps = 400;
}

static void with_snapshots(tk_options *o)
{
    o->autoscale = true;
    o->max_steps = 300;
    o->snapshot_every = 40;
}

/* Escapes from the polished Hopf link: deformed, tightened again coarse
 * to fine, the best kept and restored at the stop. */
static void escaping(tk_options *o)
{
    o->autoscale = true;
    o->resolution = 3;
    o->escapes = 2;
    o->seed = 7;
    o->max_steps = 1500;
}

static void short_budget(tk_options *o)
{
    o->autoscale = true;
    o->max_steps = 150;
}

static const history_case cases[] = {
    {"trefoil-coarse-to-fine", false, trefoil, coarse_to_fine},
    {"hopf-re-resolve", true, hopf, re_resolving},
    {"chain-stiff-no-equalise", true, chain, stiff_without_equalising},
    {"hopf-polish", false, hopf, long_polish},
    {"open-arc-snapshots", true, open_arc, with_snapshots},
    {"hopf-coarse-to-fine-converged", false, hopf, coarse_to_fine_to_convergence},
    {"tight-hopf-residual", true, tight_hopf, until_residual},
    {"borromean", true, borromean, short_budget},
    {"hopf-escapes", false, hopf, escaping},
};
#define NCASES (sizeof cases / sizeof cases[0])

static bool quick(void)
{
    const char *q = getenv("TK_QUICK");
    return q && *q && strcmp(q, "0") != 0;
}

/* Runs case k to its stop; appends its checkpoints to out (room for
 * `room`), returns how many. */
static size_t run_case(const history_case *hc, checkpoint *out, size_t room)
{
    tk_options o = TK_OPTIONS_INIT;
    autoscaled(&o);
    hc->options(&o);
    tk_curve *start = hc->start();
    tk_run *run = NULL;
    tk_error err;
    ck_assert_msg(tk_run_new(start, &o, &run, &err) == TK_OK, "%s: %s", hc->name, err.message);
    tk_stop_reason why;
    ck_assert_msg(tk_run_until(run, &why, &err) == TK_OK, "%s: %s", hc->name, err.message);
    size_t nh = 0, n = 0;
    const tk_step_report *h = tk_run_history(run, &nh);
    printf("%s: %zu steps in %.1f s, ropelength %.6f, %zu vertices, stop %s\n", hc->name,
           nh - 1, h[nh - 1].seconds, h[nh - 1].ropelength, h[nh - 1].vertices,
           tk_stop_reason_name(why));
    digest d = {0xcbf29ce484222325ULL};
    for (size_t i = 0; i < nh; i++) {
        mix_report(&d, &h[i]);
        bool last = i + 1 == nh;
        if (h[i].step % CHECKPOINT != 0 && !last)
            continue;
        if (last)
            mix_end(&d, run);
        ck_assert(n < room);
        snprintf(out[n].name, sizeof out[n].name, "%s", hc->name);
        out[n].step = h[i].step;
        out[n].hash = d.hash;
        out[n].ropelength = h[i].ropelength;
        n++;
    }
    tk_run_free(&run);
    tk_curve_free(&start);
    return n;
}

static size_t read_reference(checkpoint *ref, size_t room)
{
    FILE *f = fopen(REFERENCE, "r");
    ck_assert_msg(f != NULL, "cannot open %s (run from the source tree)", REFERENCE);
    size_t n = 0;
    char line[256];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n')
            continue;
        ck_assert(n < room);
        checkpoint *c = &ref[n];
        ck_assert_msg(sscanf(line, "%31s %ld %" SCNx64 " %lg", c->name, &c->step, &c->hash,
                             &c->ropelength) == 4,
                      "%s: bad line: %s", REFERENCE, line);
        n++;
    }
    fclose(f);
    return n;
}

#define ROOM 4096

START_TEST(trajectories_are_unchanged)
{
    static checkpoint got[ROOM], ref[ROOM];
    const char *write = getenv("TK_HISTORY_WRITE");
    size_t ngot = 0, runs = 0;
    for (size_t k = 0; k < NCASES; k++)
        if (write || !quick() || cases[k].quick) {
            ngot += run_case(&cases[k], got + ngot, ROOM - ngot);
            runs++;
        }
    if (write && *write) {
        FILE *f = fopen(write, "w");
        ck_assert_msg(f != NULL, "cannot write %s", write);
        fprintf(f, "# run, step, FNV-1a digest of the history to that step (and at the last\n"
                   "# step of the final curve and forces), ropelength: see tests/test_history.c\n");
        for (size_t i = 0; i < ngot; i++)
            fprintf(f, "%s %ld %016" PRIx64 " %.17g\n", got[i].name, got[i].step, got[i].hash,
                    got[i].ropelength);
        ck_assert_int_eq(fclose(f), 0);
        printf("wrote %zu checkpoints to %s\n", ngot, write);
        return;
    }
    size_t nref = read_reference(ref, ROOM);
    size_t compared = 0;
    for (size_t i = 0; i < ngot; i++) {
        const checkpoint *want = NULL;
        for (size_t j = 0; j < nref && !want; j++)
            if (strcmp(ref[j].name, got[i].name) == 0 && ref[j].step == got[i].step)
                want = &ref[j];
        ck_assert_msg(want != NULL, "%s: no reference checkpoint at step %ld (the run stopped "
                      "at another step)", got[i].name, got[i].step);
        ck_assert_msg(want->hash == got[i].hash,
                      "%s: the trajectory differs by step %ld: ropelength %.17g, reference "
                      "%.17g",
                      got[i].name, got[i].step, got[i].ropelength, want->ropelength);
        compared++;
    }
    /* every reference checkpoint of the runs made was reached */
    for (size_t j = 0; j < nref; j++) {
        bool made = false, found = false;
        for (size_t k = 0; k < NCASES; k++)
            if (strcmp(cases[k].name, ref[j].name) == 0)
                made = !quick() || cases[k].quick;
        for (size_t i = 0; i < ngot && !found; i++)
            found = strcmp(ref[j].name, got[i].name) == 0 && ref[j].step == got[i].step;
        ck_assert_msg(!made || found, "%s: the run ended before step %ld", ref[j].name,
                      ref[j].step);
    }
    printf("%zu checkpoints of %zu runs equal the reference\n", compared, runs);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("history");
    TCase *tc = tcase_create("history");
    tcase_set_timeout(tc, 900);
    tcase_add_test(tc, trajectories_are_unchanged);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
