/* Tests for a film's frames at equal flow time (common/film.c), against
 * brute force: every film frame is a frame nearest its time on the equal
 * grid, the grid runs from the first frame to the last, and the flow time
 * read off a thinned history is exact at its entries and linear between
 * them. */
#include <check.h>
#include <math.h>
#include <stdlib.h>

#include "film.h"
#include "support.h"

/* splitmix64: the tests' own numbers, the same every run */
static double uniform(unsigned long long *state)
{
    unsigned long long z = (*state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1p-53;
}

START_TEST(each_film_frame_is_a_nearest_frame)
{
    unsigned long long rng = 42;
    for (int trial = 0; trial < 200; trial++) {
        size_t n = 1 + (size_t)(uniform(&rng) * 60);
        double times[64], t = 0.0;
        for (size_t i = 0; i < n; i++) {
            /* shrinking steps, some repeated times (a step put back) */
            t += uniform(&rng) < 0.1 ? 0.0 : uniform(&rng) / (1.0 + (double)i);
            times[i] = t;
        }
        size_t want = 2 + (size_t)(uniform(&rng) * 80), count = 0;
        size_t *picks = tk_film_picks(times, n, want, 0.0, &count);
        ck_assert_ptr_nonnull(picks);
        ck_assert_uint_eq(count, want);
        double span = times[n - 1] - times[0];
        for (size_t k = 0; k < count; k++) {
            double at = times[0] + span * (double)k / (double)(count - 1);
            double best = INFINITY;
            for (size_t i = 0; i < n; i++)
                best = fmin(best, fabs(times[i] - at));
            ck_assert_uint_lt(picks[k], n);
            ck_assert_msg(fabs(times[picks[k]] - at) <= best + 1e-15,
                          "trial %d, frame %zu: %.17g from %.17g, the nearest %.17g", trial, k,
                          times[picks[k]], at, best);
            if (k > 0)
                ck_assert_uint_ge(picks[k], picks[k - 1]);
        }
        ck_assert(times[picks[0]] == times[0] && times[picks[count - 1]] == times[n - 1]);
        free(picks);
    }
}
END_TEST

START_TEST(every_time_sets_the_count)
{
    double times[] = {0.0, 0.5, 1.0, 2.5, 4.0};
    size_t count = 0;
    size_t *picks = tk_film_picks(times, 5, 99, 1.0, &count);
    ck_assert_uint_eq(count, 5); /* 0, 1, 2, 3, 4 */
    size_t want[] = {0, 2, 3, 3, 4}; /* the times 0, 1, 2.5, 2.5, 4 nearest 0, 1, 2, 3, 4 */
    for (size_t k = 0; k < count; k++)
        ck_assert_msg(picks[k] == want[k], "frame %zu: %zu", k, picks[k]);
    free(picks);
    /* more than the most a film takes: refused */
    ck_assert_ptr_null(tk_film_picks(times, 5, 2, 1e-9, &count));
}
END_TEST

START_TEST(flow_times_read_off_a_thinned_history)
{
    long hsteps[] = {0, 10, 30, 100};
    double htimes[] = {0.0, 1.0, 1.5, 3.0};
    long steps[] = {0, 5, 10, 20, 30, 65, 100, 150};
    double out[8];
    tk_film_times(steps, 8, hsteps, htimes, 4, out);
    double want[] = {0.0, 0.5, 1.0, 1.25, 1.5, 2.25, 3.0, 3.0};
    for (size_t i = 0; i < 8; i++)
        ck_assert_msg(fabs(out[i] - want[i]) < 1e-15, "step %ld: %.17g", steps[i], out[i]);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("film");
    TCase *tc = tcase_create("picks");
    tcase_add_test(tc, each_film_frame_is_a_nearest_frame);
    tcase_add_test(tc, every_time_sets_the_count);
    tcase_add_test(tc, flow_times_read_off_a_thinned_history);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
