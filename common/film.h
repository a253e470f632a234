/* tightknot: a film's frames at equal flow time.  The paper's films show
 * "a constant amount of simulation time" a frame; a run's steps shrink as
 * the tube closes in, so frames kept every K steps are not that.  Given
 * the flow time of each kept frame, these pick the frames of a film at
 * equal flow time, as the page's film does (web/film.js).
 */
#ifndef TK_FILM_H
#define TK_FILM_H

#include <stddef.h>

/* The film's frames from n frames of ascending flow times (n > 0):
 * `count` of them at equal steps from the first frame's time to the
 * last's, or, with every > 0, one every `every` of flow time (the count
 * following from the span).  For film frame k, at times[0] + k step, the
 * index of the frame whose time is nearest (the earlier on a tie); a frame
 * repeats where the frames are sparser than the film's step.  Returns the
 * indices (malloc'd, *out their count), NULL when there would be more than
 * TK_FILM_MOST or memory ran out. */
#define TK_FILM_MOST 10000000
size_t *tk_film_picks(const double *times, size_t n, size_t count, double every, size_t *out);

/* The flow time at each of n frames' steps, read off a thinned history
 * (nh entries of step hsteps[i] and flow time htimes[i], steps
 * ascending): linearly between the two entries around the step, the
 * first's or last's beyond them, as the page's film does.  nh > 0. */
void tk_film_times(const long *steps, size_t n, const long *hsteps, const double *htimes,
                   size_t nh, double *out);

#endif
