/* tightknot: a film's frames at equal flow time (see film.h). */
#include "film.h"

#include <assert.h>
#include <math.h>

size_t tk_film_count(const double *times, size_t n, double every)
{
    if (n == 0 || !(every > 0.0) || !isfinite(every))
        return 0;
    double span = times[n - 1] - times[0];
    return (size_t)floor(span / every) + 1;
}

void tk_film_picks(const double *times, size_t n, double every, size_t count, size_t *picks)
{
    assert(n > 0);
    size_t j = 0;
    for (size_t k = 0; k < count; k++) {
        double t = times[0] + every * (double)k;
        while (j + 1 < n && times[j + 1] <= t)
            j++;
        picks[k] = j + 1 < n && times[j + 1] - t < t - times[j] ? j + 1 : j;
    }
}
