/* What the fuzz targets share: a check that aborts (a crash is what a
 * fuzzer reports), and the comparison of run options field by field. */
#ifndef TK_FUZZ_H
#define TK_FUZZ_H

#include <stdio.h>
#include <stdlib.h>

#include "job.h"

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
    for (size_t i = 0; i < tk_job_option_nfields; i++) {
        double x = tk_field_get(&tk_job_option_fields[i], a);
        double y = tk_field_get(&tk_job_option_fields[i], b);
        if (!(x == y || (x != x && y != y)))
            return 0;
    }
    return 1;
}

#endif
