/* Fuzz target: the VECT reader, then the measure of what it accepts.
 *
 * Any bytes: the reader either refuses them with a message that names a
 * line, or returns a valid curve.  A curve in the engine's range is then
 * measured (thickness, struts, kinks), and checked against independent
 * truth: Definition 1's thickness is min(2 minrad, shortest), the tree's
 * shortest contact equals the brute-force one on small curves, every
 * strut reported lies within the bound, and writing the curve out and
 * reading it back gives the same coordinates and constraints bit for bit.  Any failed
 * check aborts (a crash to the fuzzer). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "tk/struts.h"
#include "tk/thickness.h"
#include "tk/vect.h"

/* Large enough for real structure, small enough for many runs a second
 * with the O(V^2) brute-force check. */
#define FUZZ_MAX_VERTICES 256
#define BRUTE_MAX_VERTICES 64

static void check_round_trip(const tk_curve *c)
{
    char *text = NULL;
    size_t len = 0;
    CHECK(tk_vect_to_string(c, &text, &len, NULL) == TK_OK);
    tk_curve *back = NULL;
    tk_error err;
    CHECK(tk_vect_parse(text, len, NULL, &back, &err) == TK_OK);
    CHECK(back->ncomp == c->ncomp && back->nvert == c->nvert);
    CHECK(memcmp(back->xyz, c->xyz, 3 * c->nvert * sizeof *c->xyz) == 0);
    /* the constraints too, each the same (the writer numbers them anew) */
    CHECK(back->npins == c->npins);
    for (size_t i = 0; i < c->npins; i++) {
        const tk_pin *a = &c->pins[i], *b = &back->pins[i];
        CHECK(a->comp == b->comp && a->vertex == b->vertex && a->kind == b->kind &&
              !memcmp(a->normal, b->normal, sizeof a->normal) && a->offset == b->offset &&
              !memcmp(a->point, b->point, sizeof a->point));
    }
    tk_curve_free(&back);
    free(text);
}

static void check_measure(const tk_curve *c)
{
    tk_measure m;
    tk_error err;
    int rc = tk_thickness_measure(c, NULL, &m, &err);
    if (rc != TK_OK) {
        /* only the range is refused on a valid curve */
        CHECK(rc == TK_EINVAL && tk_curve_check_range(c, NULL) != TK_OK);
        return;
    }
    CHECK(tk_curve_check_range(c, NULL) == TK_OK);
    CHECK(m.length > 0.0 && isfinite(m.length));
    CHECK(m.minrad >= 0.0 && m.shortest >= 0.0);
    CHECK(m.thickness == fmin(2.0 * m.minrad, m.shortest));
    if (c->nvert <= BRUTE_MAX_VERTICES) {
        double brute = tk_struts_shortest_brute(c, NULL);
        CHECK(brute == m.shortest ||
              fabs(brute - m.shortest) <= 1e-12 * fmax(fabs(brute), fabs(m.shortest)));
    }
    if (!(m.thickness > 0.0) || !isfinite(m.thickness))
        return;
    tk_strut_list struts = {0};
    tk_kink *kinks = NULL;
    size_t nkinks = 0;
    tk_measure again;
    rc = tk_thickness_contacts(c, 1e-3, &again, &struts, &kinks, &nkinks, &err);
    CHECK(rc == TK_OK || rc == TK_ENOMEM);
    if (rc == TK_OK) {
        CHECK(again.thickness == m.thickness);
        double bound = m.thickness * (1.0 + 1e-3);
        for (size_t k = 0; k < struts.count; k++)
            CHECK(struts.items[k].length <= bound * (1.0 + 1e-12));
        for (size_t k = 0; k < nkinks; k++)
            CHECK(2.0 * kinks[k].minrad <= bound * (1.0 + 1e-12));
        if (c->nvert <= BRUTE_MAX_VERTICES) {
            tk_strut_list brute = {0};
            CHECK(tk_struts_find_brute(c, TK_ARC_ADMISSIBLE, m.thickness, bound, &brute,
                                       NULL) == TK_OK);
            CHECK(brute.count == struts.count);
            for (size_t k = 0; k < brute.count; k++)
                CHECK(tk_strut_compare_edges(&brute.items[k], &struts.items[k]) == 0 &&
                      brute.items[k].length == struts.items[k].length);
            tk_strut_list_free(&brute);
        }
    }
    tk_strut_list_free(&struts);
    free(kinks);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    tk_vect_limits limits = {64, FUZZ_MAX_VERTICES};
    tk_curve *c = NULL;
    tk_error err;
    int rc = tk_vect_parse((const char *)data, size, &limits, &c, &err);
    if (rc != TK_OK) {
        CHECK(c == NULL);
        CHECK(rc == TK_EPARSE || rc == TK_ELIMIT);
        CHECK(strncmp(err.message, "line ", 5) == 0);
        return 0;
    }
    CHECK(tk_curve_validate(c, NULL) == TK_OK);
    check_round_trip(c);
    check_measure(c);
    tk_curve_free(&c);
    return 0;
}
