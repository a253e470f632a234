/* Fuzz target: a few steps of the flow on tiny fuzzed curves.
 *
 * The bytes are a curve: the first picks one or two components, and
 * whether they are closed or open ropes whose ends slide on planes (a
 * constraint on each end vertex, its normal from three more numbers); the
 * next one per component its vertex count (4 to 19), then each
 * coordinate is a signed 16-bit integer / 4096 (a box of side 16).  A
 * valid curve is autoscaled and tightened for a few steps; after every
 * step the thickness must hold the diameter within the overstep
 * tolerance (the flow's promise, section 4.5), every constrained vertex
 * must lie on its plane within 1e-9 of the diameter, and the figures must
 * be finite.  An error must be a clean one with a message, and it leaves
 * the last good curve, which must hold the diameter too. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "tk/thickness.h"
#include "tk/tighten.h"

typedef struct reader {
    const uint8_t *p;
    size_t n, at;
} reader;

static unsigned next_byte(reader *r)
{
    return r->at < r->n ? r->p[r->at++] : 0u;
}

static double next_coordinate(reader *r)
{
    unsigned hi = next_byte(r), lo = next_byte(r);
    int16_t v = (int16_t)(uint16_t)((hi << 8) | lo);
    return (double)v / 4096.0;
}

static double magnitude(const double *x)
{
    return fabs(x[0]) + fabs(x[1]) + fabs(x[2]);
}

typedef struct watched {
    const tk_options *o;
    const tk_run *run;
} watched;

static int check_step(const tk_step_report *s, void *user)
{
    const watched *w = user;
    const tk_options *o = w->o;
    double tau = 2.0 * o->radius;
    const tk_curve *c = tk_run_curve(w->run);
    /* (and a rounding of the coordinates' size: a tiny curve autoscaled to
     * a diameter 1 has coordinates of millions) */
    for (size_t i = 0; i < c->npins; i++)
        if (!(tk_pin_distance(c, &c->pins[i]) <=
              1e-9 * tau + 8 * DBL_EPSILON * (fabs(c->pins[i].offset) +
                                              magnitude(tk_curve_vertex(c, c->offset[c->pins[i].comp] +
                                                                               c->pins[i].vertex))))) {
            char text[256];
            tk_pin_format(&c->pins[i], text, sizeof text);
            fprintf(stderr, "step %ld: constraint %s: its vertex %.17g off it\n", s->step, text,
                    tk_pin_distance(c, &c->pins[i]));
            abort();
        }
    if (!(s->thickness >= tau * (1.0 - o->overstep_tolerance))) {
        fprintf(stderr, "step %ld: thickness %.17g below the diameter %.17g\n", s->step,
                s->thickness, tau);
        abort();
    }
    CHECK(isfinite(s->ropelength) && s->ropelength > 0.0);
    CHECK(isfinite(s->length) && s->length > 0.0);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader rd = {data, size, 0};
    unsigned first = next_byte(&rd);
    size_t ncomp = 1 + first % 2;
    bool open = (first / 2) % 2;
    size_t counts[2];
    bool closed[2] = {!open, !open};
    for (size_t k = 0; k < ncomp; k++)
        counts[k] = 4 + next_byte(&rd) % 16;
    tk_curve *c = NULL;
    CHECK(tk_curve_new(&c, ncomp, counts, closed, NULL) == TK_OK);
    for (size_t i = 0; i < 3 * c->nvert; i++)
        c->xyz[i] = next_coordinate(&rd);
    /* each end of an open rope on a plane through it (a zero normal is
     * refused, as it must be) */
    for (size_t k = 0; open && k < ncomp; k++)
        for (int end = 0; end < 2; end++) {
            tk_pin pin = {.comp = k, .vertex = end ? counts[k] - 1 : 0, .kind = TK_PIN_PLANE};
            for (int a = 0; a < 3; a++)
                pin.normal[a] = next_coordinate(&rd);
            const double *x = tk_curve_vertex(c, c->offset[k] + pin.vertex);
            pin.offset = pin.normal[0] * x[0] + pin.normal[1] * x[1] + pin.normal[2] * x[2];
            tk_error why;
            int prc = tk_curve_pin_add(c, &pin, false, &why);
            CHECK(prc == TK_OK || (prc == TK_EINVAL && why.message[0] != '\0'));
        }
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.max_steps = 6;
    o.max_seconds = 2.0;
    tk_run *run = NULL;
    tk_error err;
    int rc = tk_run_new(c, &o, &run, &err);
    if (rc != TK_OK) {
        CHECK(rc == TK_EINVAL || rc == TK_ENUMERIC || rc == TK_ELIMIT);
        CHECK(err.message[0] != '\0');
        tk_curve_free(&c);
        return 0;
    }
    watched w = {&o, run};
    check_step(tk_run_latest(run), &w);
    tk_run_set_progress(run, check_step, &w);
    tk_stop_reason why;
    rc = tk_run_until(run, &why, &err);
    if (rc != TK_OK) {
        CHECK(rc == TK_ENUMERIC && why == TK_STOP_FAILED && err.message[0] != '\0');
        tk_measure m;
        CHECK(tk_thickness_measure(tk_run_curve(run), NULL, &m, NULL) == TK_OK);
        CHECK(m.thickness >= 2.0 * o.radius * (1.0 - o.overstep_tolerance));
    }
    tk_run_free(&run);
    tk_curve_free(&c);
    return 0;
}
