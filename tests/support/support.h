/* Shared helpers for the unit tests: the catalogue, a deterministic random
 * number generator, small curve builders. */
#ifndef TK_TEST_SUPPORT_H
#define TK_TEST_SUPPORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tk/curve.h"

/* The catalogue directory ($TK_CATALOGUE, else ../shared/catalogue), or
 * NULL when it is absent (tests then skip with a message). */
const char *tkt_catalogue_dir(void);

/* Sorted names (e.g. "3.1.vect") of every .vect file in the catalogue;
 * *count set.  Free with tkt_free_names.  NULL and 0 when absent. */
char **tkt_catalogue_names(size_t *count);
void tkt_free_names(char **names, size_t count);

/* Reads catalogue file `name` ("3.1.vect"); aborts the test on failure. */
tk_curve *tkt_catalogue_curve(const char *name);

/* splitmix64: deterministic, seedable, no hidden state. */
typedef struct tkt_rng { uint64_t state; } tkt_rng;
uint64_t tkt_rng_next(tkt_rng *r);
double tkt_rng_uniform(tkt_rng *r);              /* [0, 1) */
double tkt_rng_range(tkt_rng *r, double lo, double hi);
void tkt_rng_point(tkt_rng *r, double scale, double out[3]);

/* A regular closed n-gon of circumradius radius in the xy plane. */
tk_curve *tkt_regular_polygon(size_t n, double radius);

/* Relative difference |a - b| / max(|a|, |b|, tiny). */
double tkt_reldiff(double a, double b);

/* Distance from point x to the segment (b0, b1), by projection: an
 * independent reference for the engine's edge distances. */
double tkt_point_segment(const double *x, const double *b0, const double *b1);

/* Says on standard output that the test calling it skips its checks, as
 * "SKIP test: why" at the start of a line, and returns true: the test
 * then returns.  Check counts such a test as passed; the test runner
 * counts it as skipped instead (one line, one test: call it once, at
 * the test's top level). */
bool tkt_skip(const char *test, const char *why);

/* Runs a suite with Check's normal output (its summary line is what the
 * test runner counts); returns the process exit status. */
struct Suite;
int tkt_run_suite(struct Suite *s);

#endif
