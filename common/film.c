/* tightknot: a film's frames at equal flow time (see film.h). */
#include "film.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>

size_t *tk_film_picks(const double *times, size_t n, size_t count, double every, size_t *out)
{
    assert(n > 0);
    double span = times[n - 1] - times[0];
    if (every > 0.0 && isfinite(every)) {
        double c = floor(span / every) + 1.0;
        count = c <= TK_FILM_MOST ? (size_t)c : TK_FILM_MOST + 1;
    } else
        every = count > 1 ? span / (double)(count - 1) : 0.0;
    *out = count;
    size_t *picks = count <= TK_FILM_MOST ? malloc((count ? count : 1) * sizeof *picks) : NULL;
    size_t j = 0;
    for (size_t k = 0; picks && k < count; k++) {
        double t = times[0] + every * (double)k;
        while (j + 1 < n && times[j + 1] <= t)
            j++;
        picks[k] = j + 1 < n && times[j + 1] - t < t - times[j] ? j + 1 : j;
    }
    return picks;
}

void tk_film_times(const long *steps, size_t n, const long *hsteps, const double *htimes,
                   size_t nh, double *out)
{
    assert(nh > 0);
    for (size_t i = 0; i < n; i++) {
        long step = steps[i];
        if (step <= hsteps[0]) {
            out[i] = htimes[0];
            continue;
        }
        if (step >= hsteps[nh - 1]) {
            out[i] = htimes[nh - 1];
            continue;
        }
        size_t lo = 0, hi = nh - 1; /* hsteps[lo] < step < hsteps[hi] */
        while (hi - lo > 1) {
            size_t mid = lo + (hi - lo) / 2;
            if (hsteps[mid] <= step)
                lo = mid;
            else
                hi = mid;
        }
        out[i] = htimes[lo] + (htimes[hi] - htimes[lo]) * (double)(step - hsteps[lo]) /
                                  (double)(hsteps[hi] - hsteps[lo]);
    }
}
