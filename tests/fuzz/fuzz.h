/* What the fuzz targets share: a check that aborts (a crash is what a
 * fuzzer reports), and the comparison of run options field by field. */
#ifndef TK_FUZZ_H
#define TK_FUZZ_H

#include <stdio.h>
#include <stdlib.h>

#include "tk/jobspec.h"

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (!(cond)) {                                                                   \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);    \
            abort();                                                                     \
        }                                                                                \
    } while (0)

/* Whether two option sets are the same, field by field (the struct has
 * padding, so not memcmp). */
static inline int fuzz_options_equal(const tk_job_options *a, const tk_job_options *b)
{
    return a->resolution == b->resolution && a->steps == b->steps && a->time == b->time &&
           a->residual == b->residual && a->radius == b->radius && a->lambda == b->lambda &&
           a->autoscale == b->autoscale && a->every == b->every;
}

#endif
