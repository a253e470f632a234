/* tightknot: a film's frames at equal flow time.  The paper's films show
 * "a constant amount of simulation time" a frame; a run's steps shrink as
 * the tube closes in, so frames kept every K steps are not that.  Given
 * the flow time of each kept frame, these pick the frames of a film at
 * equal flow time, as the page's film does (web/film.js).
 */
#ifndef TK_FILM_H
#define TK_FILM_H

#include <stddef.h>

/* How many film frames a time step of `every` gives from times[0] to
 * times[n - 1] (both ends included): 0 when n is 0 or every is not
 * positive and finite. */
size_t tk_film_count(const double *times, size_t n, double every);

/* For film frame k = 0 .. count - 1, at time times[0] + k every,
 * picks[k] is the index of the frame whose time is nearest (the earlier
 * on a tie); a frame repeats where the frames are sparser than the film's
 * step.  `times` ascending, n > 0. */
void tk_film_picks(const double *times, size_t n, double every, size_t count, size_t *picks);

/* The flow time at each of n frames' steps, read off a thinned history
 * (nh entries of step hsteps[i] and flow time htimes[i], steps
 * ascending): linearly between the two entries around the step, the
 * first's or last's beyond them, as the page's film does.  nh > 0. */
void tk_film_times(const long *steps, size_t n, const long *hsteps, const double *htimes,
                   size_t nh, double *out);

#endif
