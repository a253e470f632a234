/* The schedule: the polygon a run starts from, polishing (the levels
 * the tolerances of queries.c shrink by), coarse to fine and
 * re-resolution.  The only room that changes
 * the vertex count.  See run.h for the rooms of the flow. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "tk/record.h"
#include "tk/thickness.h"

/* Each time the ropelength falls by less than POLISH_CHANGE (relative;
 * shrinking with the tolerances) over POLISH_WINDOW steps, the active
 * tolerance shrinks by POLISH_FACTOR (queries.c), at most POLISH_LEVELS
 * times. */
#define POLISH_WINDOW 200
#define POLISH_CHANGE 1e-4
#define POLISH_LEVELS 4
/* A level also ends when its curve is critical: the residual of each of
 * its last POLISH_CRITICAL_STEPS steps below POLISH_CRITICAL.  The fall
 * over a window cannot tell that before the window has passed, and a
 * start that is already tight then spends four windows at tolerances
 * that hold three times the struts of the polished curve (a tight
 * 600-vertex trefoil tightened again: 3,000 struts against 1,040, 733
 * steps a window).  A run that tightens a loose start does not meet it
 * (no step of a 2,400-vertex trefoil's 600 s run had a residual below
 * 3e-3); a curve critical at its tolerance goes no further at it. */
#define POLISH_CRITICAL 1e-3
#define POLISH_CRITICAL_STEPS 20
/* On the final polygon and the coarse levels above the coarsest, where
 * the window (below) is at least
 * POLISH_RATE_FROM times POLISH_WINDOW steps, a level also ends when the
 * fall over its last POLISH_WINDOW steps, at that rate over the whole
 * window, is below the bound.  The window is 2,933 steps at 2,400
 * vertices, and the ropelength of a curve near tight falls by less than
 * a tenth of the bound over it: the test data's tight trefoil tightened
 * again (tests/data/trefoil-2400.vect; residuals about 1e-2, so never
 * critical) fell by 8.5e-7 in its first 300 steps, and waited 2,933
 * steps of about 500 ms at a level whose 12,000 struts the third level
 * brings to 2,800 (62 ms a step).  With the rate its 240 s reached
 * 32.743705 and 32.743714 (two runs; 52 and 66 ms a step from step 600)
 * against 32.743787; catalogue 3.1 at `--vertices 2400` for 600 s
 * reached 32.7432766 against 32.7436118 (9,005 steps on the final
 * polygon against 942).  Not on the coarsest level nor the loose ones
 * below it: a loose descent crawls there past saddles more cheaply than
 * on any finer polygon, and with the rate on every coarse level the same
 * run left them at 22 s instead of 154 s, looser, and ended at 32.74377.
 * A level above the coarsest starts from a curve settled on the polygon
 * half as fine (with escapes, polished by the tries judged on the
 * coarsest) and takes up the finer polygon's share of the ropelength in
 * its first steps; after that its crawl is worth less than the next
 * polygon's steps.  Catalogue 3.1 at `--vertices 4800` (600 s of
 * processor time) stayed 114 s on its 1,200-vertex level at 0.3 s a
 * step (4,100 struts) while its ropelength fell by 1e-7 (relative) in
 * 250 steps, reached 4,800 vertices with 74 s left and ended at
 * 32.7430069; with the rate there it left that level after 65 s and the
 * 2,400-vertex one after 8, passed 32.74300 at 517 s and ended at
 * 32.7429952.  At `--vertices 2400`: 32.7431042 against 32.7431058, on
 * the final polygon from 191 s instead of 247 s.  The atlas's counts
 * (200 to 600 vertices, windows of 320 to 380 steps) and the coarse
 * levels of resolutions below 20 (windows below 400 steps) keep the
 * whole window. */
#define POLISH_RATE_FROM 2
/* The windows of steps that judge whether the ropelength has stopped
 * falling (the polish watch here, convergence for an escape) are counted
 * for a polygon whose mean edge is WINDOW_EDGE diameters (resolution 5)
 * and grow as the edges shorten: no vertex moves more than a quarter of
 * the shortest edge a step (stepping.c), so the same motion of the curve
 * takes as many more steps as the edges are shorter.  Counted in steps
 * alone, the trefoil at 4,800 vertices left its 1,200- and 2,400-vertex
 * levels after 10 and 5 s, reached 4,800 at 32.7545 and crawled there
 * (1,066 steps of 1.3 s in 1,400 s, 32.7539 at the end), while a run
 * kept at 2,400 was at 32.7434 by 600 s. */
#define WINDOW_EDGE 0.1
/* Where the active tolerance is reckoned from the edge (ACTIVE_PER_EDGE2,
 * queries.c), polishing takes it down at most POLISH_LEVELS_EDGE levels: to
 * 0.3 h^2 / 27, about 0.01 h^2, below which the pair next to a contact drops
 * out of the active set and comes back in through the step control.  The test
 * data's tight trefoil at 2,400 vertices held at a fourth level (1.7e-7 of
 * the diameter, 0.004 h^2) flipped from one step to the next between 600 and
 * 6,400 struts, the larger sets found by the step control (1.3 to 1.5 s a
 * step, the ropelength unmoved over 30 steps), where at the third it held
 * 2,800 struts at 62 ms a step (bench/steps --curve); loose trefoils
 * tightened at 2,400 vertices reached the fourth level after about 340 s and
 * stepped at 5 to 9 s there.  Coarser polygons keep the options' tolerance
 * (below 0.3 h^2: fewer than about 520 vertices of a tight trefoil, 960 of
 * 8_19) and all POLISH_LEVELS levels. */
#define POLISH_LEVELS_EDGE 3
/* A coarse level where escapes judge their tries (tk_schedule_watch's
 * judged_here) is polished as the final polygon is, but left once the
 * try has spent JUDGED_SHARE of the budget polishing it (since its first
 * stall: the descent before, from a try's loose curve, is the try's
 * own): by then its ropelength ranks the try, and a plateau's polishing
 * can crawl on for most of the budget.  Catalogue 10.34 (resolution 5,
 * 60 s of processor time) brought its explored try onto the coarsest
 * polygon at 14.6 s, was at 88.536 by 15.0 s and 88.510 by 17.5 s, and
 * polished there until 44.6 s (88.498): exploring had no time for
 * another try, and the run ended at 88.278.  Of 15 catalogue knots of 9
 * and 10 crossings, 11 now end within 0.1% of the lowest any run
 * reached, against 8, and their excess over it sums to 2.7%, against
 * 10.7% (bench/FIGURES.md; exploring for half the budget, escape.c). */
#define JUDGED_SHARE 0.05
/* Coarse to fine: the coarsest polygon is the halving of the final one
 * nearest this many vertices per unit ropelength on a log scale (at
 * least COARSEST_RESOLUTION / sqrt 2), and at most this many halvings are
 * undone.  Resolution 5's coarsest polygon has 2.5 a unit, and the
 * escapes judge their tries there (escape.c).  When the floor was 2.5
 * itself, a vertex count of 4 to 5 a unit (the atlas's: 10_124 at 576
 * is 8.1 a unit) stopped on a coarsest polygon of 4 to 5, where a try's
 * basins lie closer together: catalogue 10.124 at 576 vertices (600 s
 * of processor time, seed 1) ended at 71.02151, its fourteen tries
 * never below 71.0239; with the coarsest polygon on 144 vertices, 2.03 a
 * unit, it ended at 70.96826, T(3,5)'s basin (bench/FIGURES.md). */
#define COARSEST_RESOLUTION 2.5
#define MAX_COARSE_LEVELS 3
/* Loose levels (the loose option): the first tightening starts that many
 * halvings below the coarsest level, while LOOSE_RESOLUTION vertices a
 * unit of ropelength remain, and each moves on at its first stall.  A
 * step's motion is bounded by the edge (stepping.c) and costs as many
 * constraints as there are vertices, so a loose start comes down about
 * four times as fast on each halving.  At resolution 5 (60 s of
 * processor time) turned starts of 10.25, 10.67 and 10.109 were at 222,
 * 223 and 204, still on polygons of over 1,000 vertices reckoned from
 * that looseness; with two loose levels they came to 92.7, 88.9 and
 * 90.9, and catalogue 10.124 to 71.055 from 71.128.  Edges are then up
 * to 0.8 diameters long, and resampling keeps the type (none of the
 * catalogue's 398 files nor 50 tightened curves changed type resampled
 * at 0.3 a unit).  Tries are still judged on the coarsest level
 * (tk_escape_judged_here), and near ones start there (turned and far
 * ones start on the loose levels, go_loose): with the loose levels as the
 * coarsest, tries were ranked on polygons of 37 vertices for 8_19, and
 * catalogue 8.19 ended in the basin 0.06% above the one it had reached
 * (61.06702 against 61.02827, bench/starts, 60 s). */
#define LOOSE_RESOLUTION 0.6
/* A coarse polygon follows the ropelength down: each time it has fallen
 * by this fraction, the coarse level is resampled to its resolution at
 * the ropelength reached (tk_schedule_before_step).  A loose start's
 * coarse level is otherwise reckoned from its start's ropelength and as
 * much finer than it needs to be when it is tight, all level long:
 * Lissajous 6_1 L(3,2,5) (ropelength 429) had a coarse level of 1073
 * vertices at resolution 5, spent the level's 60 s of a 120 s budget
 * coming down to 89, got a final polygon of 446 vertices for that, and
 * ended at 57.25 (+0.94%). */
#define COARSE_RE_RESOLVE 0.25
/* The largest ropelength a run starts from.  Autoscaled, such a curve's
 * coordinates reach about this many diameters, and rounding then moves
 * them by 1e-16 of that: beyond 1e9 the rounding approaches the
 * tolerances of the step control (1e-5 of the diameter) and error
 * recovery fails.  Curves that thin have (nearly) crossed themselves: a
 * spline through a polygon with a spike loops through the polygon (a
 * 16-gon with one vertex pulled out: ropelength 48, resampled 1e17). */
#define START_ROPELENGTH_MAX 1e9
/* The smallest an autoscaled run starts from: a rope shorter than its
 * own diameter.  Only an open rope gets there (a closed curve's
 * ropelength is at least 2 pi), and only when it is (nearly) straight, so
 * that its thickness is set by the turning at a vertex, and there by
 * rounding when the vertices are collinear: autoscaled, such a rope
 * shrinks to the size of the rounding and the next rounding moves its
 * thickness anywhere (four collinear vertices, scaled by 1e-16 to a
 * thickness 1.002, measured 0.405 after a step of size 0).  At its own
 * scale a straight rope is a tight one (pulled straight between two
 * planes) and runs. */
#define AUTOSCALE_ROPELENGTH_MIN 2.0

size_t tk_schedule_window(const tk_run *r, size_t steps)
{
    double h = tk_mean_edge(r);
    if (!(h > 0.0) || h >= WINDOW_EDGE)
        return steps;
    return (size_t)lround((double)steps * WINDOW_EDGE / h);
}

/* The levels polishing may go down: fewer where the tolerance is reckoned
 * from the edge (POLISH_LEVELS_EDGE). */
static int polish_levels(const tk_run *r)
{
    return tk_tolerance_from_edge(r) ? POLISH_LEVELS_EDGE : POLISH_LEVELS;
}

/* The thickness of the starting curve, for set-up. */
static int measure(const tk_curve *c, tk_measure *m, tk_error *err)
{
    int rc = tk_thickness_measure(c, NULL, m, err);
    if (rc == TK_OK && !(m->thickness > 0.0 && isfinite(m->thickness)))
        rc = tk_error_set(err, TK_EINVAL,
                          "the curve has no finite thickness (%g): nothing to tighten",
                          m->thickness);
    return rc;
}

/* The ropelength a resolution reckons vertices from: twice the length
 * over the shortest self-distance, the start's ropelength but for its
 * curvature.  A noisy or unevenly spaced polygon's radius of curvature is
 * a fraction of its strands' distance (a Hopf link with each vertex moved
 * by 5% of an edge: ropelength 64.7, against 25.2 by its self-distance)
 * and its vertex count would follow that noise: a disguised Hopf link at
 * resolution 5 got 709 vertices and was still at 36.1 after 120 s, a
 * chain of three rings 1537 and 316.  Without a self-distance (one
 * open arc) the ropelength itself.
 *
 * Never below what every closed component costs: a closed curve turns
 * by 2 pi at least (Fenchel), and a tube of radius r turns by at most
 * 1/r a unit of length, so each is 2 pi radii long at least.  A ring
 * drawn as an odd polygon has no doubly critical pair of its own (no two
 * of its edges face each other), so for rings apart the shortest
 * self-distance is the gap between them: catalogue 0.2.1 (two unlinked
 * rings) turned inside out, 43.4 apart for a length of 97.7, reckoned
 * 4.51 (tight: 4 pi), and its run ended on 23 vertices at resolution 5,
 * not 64 (12.89 against the catalogue file's 12.61); 0.3.1's on 18
 * (three hexagons, 20.78 against 18.91). */
static double reckoned_ropelength(const tk_curve *c, const tk_measure *m)
{
    double rope = isfinite(m->shortest) && m->shortest > 0.0 ? 2.0 * m->length / m->shortest
                                                              : m->ropelength;
    double least = 0.0;
    for (size_t comp = 0; comp < c->ncomp; comp++)
        least += c->closed[comp] ? 2.0 * M_PI : 0.0;
    return fmax(rope, least);
}

/* The ropelength the vertex counts of a resolution are reckoned from.  A
 * loose start is far longer than the knot it tightens to, and a count
 * reckoned from it is that much finer than the resolution asks for, all
 * run long: T(2,7) generated on a round torus (ropelength 121, the tight
 * 7_1 about 61.4) got 606 vertices at resolution 5, where catalogue 7.1
 * got 373, and was at 64.13 after 120 s, trapped in its torus symmetry,
 * with three escapes; catalogue 7.1 reached 61.44.  So the final polygon
 * is reckoned from the ropelength the run has reached when it first
 * leaves its coarse levels for it (at most the start's), and keeps that
 * count through the escapes, whose coarse levels are reckoned from it
 * too.  Until then, and for the coarse levels, the start's (or the
 * current ropelength, if lower).  With re_resolve the counts follow the
 * ropelength throughout instead. */
static double reference_ropelength(const tk_run *r)
{
    if (r->opt.re_resolve > 0.0)
        return r->life.latest.ropelength;
    if (r->schedule.final_ropelength > 0.0)
        return r->schedule.final_ropelength;
    double rope = r->life.latest.ropelength;
    return rope > 0.0 && rope < r->schedule.start_ropelength ? rope
                                                             : r->schedule.start_ropelength;
}

/* The resolution of the final polygon: the option's, or the vertices
 * asked for per unit of the ropelength the final polygon is reckoned
 * from, the start's until it is fixed (0: the input's polygon). */
static double resolution_final(const tk_run *r)
{
    if (r->opt.vertices > 0)
        return (double)r->opt.vertices / (r->schedule.final_ropelength > 0.0
                                              ? r->schedule.final_ropelength
                                              : r->schedule.start_ropelength);
    return r->opt.resolution;
}

/* The fewest vertices the run's curve can have: 3 a closed component, 2
 * an open one.  An open rope pulled straight has a ropelength near 0 (its
 * thickness grows without bound), and its resolution would ask for none. */
static size_t least_count(const tk_run *r)
{
    size_t least = 0;
    for (size_t comp = 0; comp < r->shared.curve->ncomp; comp++)
        least += r->shared.curve->closed[comp] ? 3 : 2;
    return least;
}

/* The vertices of the current coarse level at ropelength rope: with the
 * vertices option, exactly that count at the last level; never fewer
 * than least_count. */
static size_t level_count(const tk_run *r, double rope)
{
    int level = r->schedule.coarse_level;
    size_t n = r->opt.vertices > 0 ? (size_t)ceil(ldexp((double)r->opt.vertices, -level))
                                   : (size_t)ceil(ldexp(r->opt.resolution, -level) * rope);
    size_t least = least_count(r);
    return n > least ? n : least;
}

size_t tk_schedule_final_count(const tk_run *r)
{
    if (tk_schedule_final(r) || !(resolution_final(r) > 0.0))
        return r->shared.curve->nvert;
    if (r->opt.vertices > 0)
        return r->opt.vertices;
    /* (at most this until the final polygon is first reached) */
    double rope = r->schedule.final_ropelength > 0.0 && !(r->opt.re_resolve > 0.0)
                      ? r->schedule.final_ropelength
                      : r->schedule.start_ropelength;
    size_t n = (size_t)ceil(r->opt.resolution * rope), least = least_count(r);
    return n > least ? n : least;
}

/* Everything sized by the curve's vertices: the trial curve, the strut
 * tree and the rooms' vectors; the active set and the warm start are
 * dropped (their edge indices refer to the old curve). */
int tk_schedule_fit(tk_run *r, tk_error *err)
{
    const tk_curve *c = r->shared.curve;
    tk_curve_free(&r->shared.trial);
    tk_strut_finder_free(&r->shared.finder);
    int rc = tk_curve_copy(c, &r->shared.trial, err);
    if (!rc)
        rc = tk_strut_finder_new(c, &r->shared.finder, err);
    if (!rc)
        rc = tk_motion_fit(r, c->nvert, err);
    if (!rc)
        rc = tk_recovery_fit(r, c->nvert, err);
    if (!rc)
        rc = tk_stepping_fit(r, c->nvert, err);
    if (rc)
        return rc;
    /* the curve's pins, and a point where an open component's end has none */
    free(r->shared.pin);
    free(r->shared.pins);
    r->shared.npins = 0;
    r->shared.pin = calloc(c->nvert, sizeof *r->shared.pin);
    r->shared.pins = malloc((c->npins + 2 * c->ncomp) * sizeof *r->shared.pins);
    if (!r->shared.pin || !r->shared.pins)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a run of %zu vertices", c->nvert);
    for (size_t i = 0; i < c->npins; i++)
        r->shared.pins[r->shared.npins++] = c->pins[i];
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp);
        for (size_t end = 0; end < 2 && !c->closed[comp]; end++) {
            size_t k = end ? n - 1 : 0;
            if (tk_curve_pin_of(c, c->offset[comp] + k))
                continue;
            tk_pin *p = &r->shared.pins[r->shared.npins++];
            *p = (tk_pin){.comp = comp, .vertex = k, .kind = TK_PIN_POINT};
            memcpy(p->point, tk_curve_vertex(c, c->offset[comp] + k), sizeof p->point);
        }
    }
    for (size_t i = 0; i < r->shared.npins; i++) {
        const tk_pin *p = &r->shared.pins[i];
        if (p->kind != TK_PIN_FREE)
            r->shared.pin[c->offset[p->comp] + p->vertex] = p;
    }
    tk_active_reset(r);
    return TK_OK;
}

/* How many times `resolution` halves and stays at or above `floor`, at
 * most `most`. */
static int halvings(double resolution, double floor, int most)
{
    int level = 0;
    while (level < most && ldexp(resolution, -(level + 1)) >= floor)
        level++;
    return level;
}

/* The coarse levels below a final polygon of `resolution` vertices per
 * unit ropelength. */
static int levels_below(const tk_run *r, double resolution)
{
    const tk_options *o = &r->opt;
    if (resolution > 0.0 && o->coarse_to_fine && o->snapshot_every == 0)
        return halvings(resolution, COARSEST_RESOLUTION / M_SQRT2, MAX_COARSE_LEVELS);
    return 0;
}

/* The levels a run starts with (prepare_curve); the start's ropelength
 * is known. */
static int coarse_levels(const tk_run *r)
{
    return levels_below(r, resolution_final(r));
}

/* The loose levels below the coarsest one that a schedule beginning now
 * gets, for a run that has coarse levels (the loose option, while
 * LOOSE_RESOLUTION remains). */
static int loose_levels(const tk_run *r)
{
    int levels = r->schedule.coarse_levels;
    if (levels == 0)
        return 0;
    return halvings(ldexp(resolution_final(r), -levels), LOOSE_RESOLUTION, r->opt.loose);
}

/* Fixes the ropelength the final polygon is reckoned from: when the run
 * first refines to it, or restarts for an escape without having had a
 * coarse level.  With the vertices option that also sets the coarse
 * levels of the escapes: a loose start has none (Lissajous 6_1 L(3,2,5),
 * ropelength 429, at 480 vertices is coarser than 2.5 a unit), and its
 * escapes restarted on the final polygon, where kinks are stiffest,
 * while those of catalogue 6.1 went to 240 vertices: 56.73221 (+0.026%
 * over the atlas) after 600 s against 56.71751.  The levels then are
 * those of the ropelength reached, as a resumed run reckons them. */
static void fix_final(tk_run *r, double rope)
{
    r->schedule.final_ropelength = rope;
    r->schedule.coarse_levels = coarse_levels(r);
}

/* The run's curve: a copy of the start, resampled to the resolution (of
 * the coarsest level) and autoscaled, or refused.  *correct is set where
 * the curve still needs Newton steps (below). */
static int prepare_curve(tk_run *r, const tk_curve *start, bool *correct, tk_error *err)
{
    tk_measure m;
    *correct = false;
    tk_curve **curve = &r->shared.curve;
    if (start->nvert > TK_RUN_MAX_VERTICES)
        return tk_error_set(err, TK_ELIMIT,
                            "%zu vertices: a run holds at most %d (about 2 GiB of memory); "
                            "tighten a coarser polygon (a resolution resamples it)",
                            start->nvert, TK_RUN_MAX_VERTICES);
    int rc = tk_curve_copy(start, curve, err);
    /* a start's pinned vertices a rounding away from their constraints
     * are put on them; farther, the start is refused */
    double shortest = 0.0;
    if (!rc && (*curve)->npins) {
        tk_curve_edge_range(*curve, &shortest, NULL);
        rc = tk_curve_pins_settle(*curve, TK_PIN_SETTLE * shortest, err);
    }
    if (!rc)
        rc = measure(*curve, &m, err);
    if (rc)
        return rc;
    r->schedule.start_ropelength = reckoned_ropelength(*curve, &m);
    double start_rope = m.ropelength, start_thickness = m.thickness;
    if (!(m.ropelength <= START_ROPELENGTH_MAX))
        return tk_error_set(err, TK_EINVAL,
                            "the curve is too thin for its length to tighten in double "
                            "precision: ropelength %.6g, above %g (does it nearly cross itself?)",
                            m.ropelength, START_ROPELENGTH_MAX);
    if (r->opt.autoscale && !(m.ropelength >= AUTOSCALE_ROPELENGTH_MIN))
        return tk_error_set(err, TK_EINVAL,
                            "autoscale cannot size this rope: it is shorter than its own "
                            "tube's diameter (ropelength %.6g, below %g), its thickness set "
                            "by a (nearly) straight turn; tighten it at its own scale, "
                            "without autoscale",
                            m.ropelength, AUTOSCALE_ROPELENGTH_MIN);
    if (resolution_final(r) > 0.0) {
        double want = (double)level_count(r, r->schedule.start_ropelength);
        if (want > TK_RUN_MAX_VERTICES)
            return tk_error_set(err, TK_ELIMIT,
                                "resolution %g at ropelength %.4g asks for %.0f vertices: a "
                                "run holds at most %d (about 2 GiB of memory)",
                                r->opt.resolution, r->schedule.start_ropelength, want,
                                TK_RUN_MAX_VERTICES);
        r->schedule.coarse_levels = coarse_levels(r);
        r->schedule.loose = loose_levels(r);
        r->schedule.coarse_level = r->schedule.coarse_levels + r->schedule.loose;
        /* the start, its pins settled, is kept until the first polygon
         * is chosen (below) */
        size_t count = level_count(r, r->schedule.start_ropelength);
        tk_curve *settled = *curve;
        *curve = NULL;
        size_t given = settled->nvert;
        rc = tk_curve_resample_total(settled, count, curve, err);
        bool resampled = !rc;
        if (resampled)
            rc = measure(*curve, &m, err);
        bool crosses = rc == TK_EINVAL || (rc == TK_OK && !(m.ropelength <= START_ROPELENGTH_MAX));
        if (resampled && crosses)
            rc = tk_error_set(err, TK_EINVAL,
                              "resampling to %zu vertices (resolution %g) makes the curve "
                              "(nearly) cross itself (ropelength %.6g, from %.6g): the smooth "
                              "curve through the vertices loops where they turn sharply; "
                              "tighten without a resolution first, or add vertices there",
                              count, resolution_final(r), rc ? INFINITY : m.ropelength,
                              start_rope);
        /* A start refined to more vertices than it has, whose spline is
         * thinner than its polygon, is one the spline cuts where it bends
         * at the curvature bound or between contacts: a tight curve.
         * Scaled to the tube by the spline's thickness it loses every
         * contact (catalogue 3.1 tightened at 4,800 vertices, 32.7429968,
         * resampled to 9,600 was 3.5% loose, and 1,944 s later still at
         * 32.7506); scaled by its polygon's, with no margin, the few
         * vertices that cut the tube are put back by Newton steps, as a
         * run's own refinement does (correct_resampled).  Spline
         * resampling commutes with scaling, so this is the polygon
         * scaled, then resampled.  Only for a start put on its final
         * polygon: a coarse level's flow tightens a looser start anyway,
         * at a fraction of the cost. */
        if (!rc)
            *correct = r->opt.autoscale && count > given && m.thickness < start_thickness &&
                       r->schedule.coarse_level == 0;
        /* More than twice the vertices at once, the spline's violations
         * are more and the Newton steps on them stiffer: trefoil-600
         * (32.7460111) resampled to 9,600 took 191 s of them and was then
         * scaled up, to 34.05 with no contact left.  Twice at a time
         * (refine_start; this polygon is the first), each corrected
         * before the next, it starts at 32.7472 in 20 s; to 4,800,
         * 13.5 s become 2.7 s. */
        if (!rc && *correct && count > 2 * given) {
            tk_curve_free(curve);
            rc = tk_curve_resample_total(settled, 2 * given, curve, err);
        }
        tk_curve_free(&settled);
        if (rc)
            return rc;
    }
    if (r->opt.autoscale) {
        double factor = *correct ? r->tau / start_thickness
                                 : r->opt.autoscale_margin * r->tau / m.thickness;
        tk_curve_scale(*curve, factor);
        /* A radius far from the curve's own scale can carry it out of the
         * range the engine measures in. */
        tk_error why;
        if (tk_curve_check_range(*curve, &why))
            return tk_error_set(err, TK_EINVAL,
                                "autoscale to radius %g scales the curve by %g, out of the "
                                "engine's range (%s)",
                                r->opt.radius, factor, why.message);
    } else if (m.thickness < r->tau * (1.0 - r->opt.overstep_tolerance) ||
               2.0 * m.minrad < 2.0 * r->min_radius * (1.0 - r->opt.overstep_tolerance)) {
        return tk_error_set(err, TK_EINVAL,
                            "the curve's thickness %.6g is below the tube diameter %.6g "
                            "(or its curvature too high for lambda %g): use autoscale",
                            m.thickness, r->tau, r->opt.lambda);
    }
    return TK_OK;
}

/* Newton steps on a resampled curve's violated constraints (resample_to) */
static int correct_resampled(tk_run *r, tk_error *err);

/* The rest of a start's refinement (prepare_curve): to the final polygon
 * twice the vertices at a time, each polygon corrected before the next. */
static int refine_start(tk_run *r, tk_error *err)
{
    size_t count = level_count(r, r->schedule.start_ropelength);
    int rc = correct_resampled(r, err);
    while (!rc && r->shared.curve->nvert < count) {
        size_t next = 2 * r->shared.curve->nvert;
        tk_curve *resampled = NULL;
        rc = tk_curve_resample_total(r->shared.curve, next < count ? next : count, &resampled,
                                     err);
        if (rc)
            break;
        tk_curve_free(&r->shared.curve);
        r->shared.curve = resampled;
        rc = tk_schedule_fit(r, err);
        if (!rc)
            rc = correct_resampled(r, err);
    }
    return rc;
}

int tk_schedule_start(tk_run *r, const tk_curve *start, tk_error *err)
{
    r->schedule.resolved_at = INFINITY;
    bool correct = false;
    int rc = prepare_curve(r, start, &correct, err);
    if (!rc)
        rc = tk_schedule_fit(r, err);
    if (!rc && correct)
        rc = refine_start(r, err);
    return rc;
}

int tk_schedule_resume(tk_run *r, const tk_curve *curve, const tk_resume *at, tk_error *err)
{
    r->schedule.start_ropelength = at->start_ropelength;
    r->schedule.final_ropelength = at->final_ropelength;
    r->schedule.coarse_levels = coarse_levels(r);
    /* late levels (coarsen_late) are reckoned from a ropelength the place
     * does not keep, so it keeps their count (a place from before it did
     * not: the level it is at is the most it can have had) */
    if (r->opt.vertices > 0 && !(at->final_ropelength > 0.0)) {
        int late = at->coarse_levels > 0 ? at->coarse_levels : at->coarse_level - at->loose;
        if (late > r->schedule.coarse_levels && late <= MAX_COARSE_LEVELS)
            r->schedule.coarse_levels = late;
    }
    r->schedule.restarts = at->restarts;
    r->schedule.loose = at->loose;
    if (at->loose > loose_levels(r) ||
        at->coarse_level > r->schedule.coarse_levels + r->schedule.loose)
        return tk_error_set(err, TK_EINVAL,
                            "the run resumes at coarse level %d with %d loose levels, but its "
                            "options have %d and %d",
                            at->coarse_level, at->loose,
                            r->schedule.coarse_levels + loose_levels(r), loose_levels(r));
    r->schedule.coarse_level = at->coarse_level;
    r->schedule.polish_level = at->polish_level;
    r->schedule.polish_began = r->life.nhistory; /* (a resumed level's polishing counts again) */
    r->schedule.share_from = at->share_from;
    r->schedule.resolved_at = at->resolved_at > 0.0 ? at->resolved_at : INFINITY;
    tk_measure m;
    int rc = tk_curve_copy(curve, &r->shared.curve, err);
    if (!rc)
        rc = measure(curve, &m, err);
    if (!rc && m.thickness < r->tau * (1.0 - r->opt.overstep_tolerance))
        rc = tk_error_set(err, TK_EINVAL,
                          "the curve to resume is thinner (%.6g) than the tube diameter %.6g",
                          m.thickness, r->tau);
    return rc ? rc : tk_schedule_fit(r, err);
}

void tk_schedule_resume_point(const tk_run *r, tk_resume *out)
{
    out->start_ropelength = r->schedule.start_ropelength;
    out->coarse_level = r->schedule.coarse_level;
    out->coarse_levels = r->schedule.coarse_levels;
    out->loose = r->schedule.loose;
    out->polish_level = r->schedule.polish_level;
    out->share_from = r->schedule.share_from;
    out->restarts = r->schedule.restarts;
    out->resolved_at = isfinite(r->schedule.resolved_at) ? r->schedule.resolved_at : 0.0;
    out->final_ropelength = r->schedule.final_ropelength;
}

/* Resamples the run's curve to `count` vertices along its spline and
 * makes it feasible again by Newton steps on the constraints it violates
 * (a tight curve's spline cuts the tube a little where it bends at the
 * curvature bound and between contacts).  Scaling it about its centroid
 * instead would throw away every contact: a tight 1217-vertex trefoil
 * (32.76) resampled to 2435 was scaled up by 1.357 and its run ended at
 * 38.63.
 * The scaling stays the last resort, for what Newton steps leave (up to
 * RESAMPLED_RESCALE_UP_TO; more means strands all but meet).
 * Where the spline breaks the curvature bound, a Newton step on the
 * violated vertices pushes their neighbours over it, so the worst
 * violation falls only by a constant factor a step: catalogue 3.1 at 600
 * vertices (32.7616) resampled to 1200 broke it at 36 vertices by up to
 * 7.5%, and 25 steps later 4.7e-4 was left (0.88 a step), removed by
 * scaling up by that.  Refinement happens a few times a run, so it may
 * take RESAMPLED_CORRECTIONS steps. */
#define RESAMPLED_RESCALE_UP_TO 0.5
#define RESAMPLED_CORRECTIONS 400
static int correct_resampled(tk_run *r, tk_error *err)
{
    double worst = 0.0;
    int rc = tk_recovery_violation(r, r->shared.curve, &worst, err);
    if (rc || !(worst > tk_tolerance_correction(r)))
        return rc;
    int iterations = 0;
    tk_error why;
    rc = tk_recovery_correct(r, RESAMPLED_CORRECTIONS, RESAMPLED_RESCALE_UP_TO, &iterations, &why);
    if (rc)
        return tk_error_set(err, rc, "resampling to %zu vertices: %s", r->shared.curve->nvert,
                            why.message);
    return TK_OK;
}

static int resample_to(tk_run *r, size_t count, tk_error *err)
{
    tk_curve *resampled = NULL;
    int rc = tk_curve_resample_total(r->shared.curve, count, &resampled, err);
    if (rc)
        return rc;
    tk_curve_free(&r->shared.curve);
    r->shared.curve = resampled;
    r->schedule.resolved_at = r->life.latest.ropelength;
    /* a new polygon, further from its critical point: polishing starts
     * again from its own history */
    r->schedule.polish_level = 0;
    r->schedule.polish_from = r->schedule.polish_began = r->life.nhistory;
    r->schedule.resampled_from = r->life.nhistory;
    rc = tk_schedule_fit(r, err);
    if (!rc)
        rc = correct_resampled(r, err);
    if (rc)
        return rc;
    tk_stepping_reset(r);
    char when[64];
    snprintf(when, sizeof when, "resampling to %zu vertices", r->shared.curve->nvert);
    return tk_type_check(r, when, err);
}

/* Coarse to fine: a coarse polygon has fewer, longer edges, so each step
 * is cheaper and the kink constraints far less stiff (their relative
 * curvature grows like 1 / (theta l)^2); it gets to the neighbourhood of
 * the tight shape many times faster, past saddles the fine polygon crawls
 * by (6.3.2 at resolution 2.5: below 58.6 after 34 s; at 5, 67.7 after
 * 300 s).  Once it has all but stopped tightening (tk_schedule_watch),
 * stalled, or spent its share of the budget (both judged with the stop
 * criteria, tighten.c), the vertices are doubled and the finer polygon
 * starts from there. */
bool tk_schedule_move_on(tk_run *r)
{
    if (r->schedule.coarse_level == 0)
        return false;
    r->schedule.move_on = true;
    return true;
}

static int refine(tk_run *r, tk_error *err)
{
    r->schedule.move_on = false;
    r->schedule.coarse_level--;
    double rope = reference_ropelength(r);
    /* a loose level's count, as a loose try's start (go_loose), from the
     * curve's own ropelength where that is the larger */
    if (r->schedule.coarse_level > r->schedule.coarse_levels && r->life.latest.ropelength > rope)
        rope = r->life.latest.ropelength;
    if (r->schedule.coarse_level == 0 && !(r->schedule.final_ropelength > 0.0))
        fix_final(r, rope);
    return resample_to(r, level_count(r, rope), err);
}

/* A run with a budget of steps or time spends its last share of it on the
 * final polygon even when a coarse one is still tightening: each level's
 * share is an equal part of the budget.  A budget too small for that (a
 * step or two) is overrun by one step per level, so the run still ends on
 * the polygon of its resolution. */
double tk_schedule_spent(const tk_run *r)
{
    return tk_schedule_spent_at(r, &r->life.latest);
}

double tk_schedule_spent_at(const tk_run *r, const tk_step_report *s)
{
    return fmax(0.0, tk_options_spent(&r->opt, s));
}

bool tk_schedule_share_spent(const tk_run *r)
{
    if (r->schedule.coarse_level == 0)
        return false;
    /* the shares of what was left when this schedule began */
    double from = r->schedule.share_from;
    double spent = from < 1.0 ? (tk_schedule_spent(r) - from) / (1.0 - from) : 1.0;
    int levels = r->schedule.coarse_levels + r->schedule.loose;
    return spent >= (double)(levels - r->schedule.coarse_level + 1) / (double)(levels + 1);
}

/* The run goes on from `curve` (taken), on the level set, resampled to
 * `count` vertices: the start of a schedule, made feasible as a start is. */
static int restart(tk_run *r, tk_curve *curve, size_t count, int polish, tk_error *err)
{
    tk_curve_free(&r->shared.curve);
    r->shared.curve = curve;
    r->schedule.restarts++;
    r->schedule.share_from = tk_schedule_spent(r);
    r->schedule.move_on = false;
    tk_measure m;
    int rc = measure(curve, &m, err);
    if (rc)
        return rc;
    /* a deformed curve is thinner: scaled to the tube, as at the start */
    if (m.thickness < r->tau * (1.0 - tk_tolerance_overstep(r)))
        tk_curve_scale(curve, r->opt.autoscale_margin * r->tau / m.thickness);
    /* resample_to checks the type of what it makes */
    bool resampled = count != curve->nvert;
    rc = resampled ? resample_to(r, count, err) : tk_schedule_fit(r, err);
    if (rc)
        return rc;
    r->schedule.polish_level = polish;
    r->schedule.polish_from = r->schedule.polish_began = r->life.nhistory;
    r->schedule.resampled_from = r->life.nhistory;
    /* the coarse polygon follows this curve's ropelength down from its
     * own (tk_schedule_before_step), not from the curve it replaces: a
     * turned try of catalogue 10.34 (resolution 5), autoscaled far
     * looser than the best curve it came from (89.14), stayed on its
     * 164-vertex loose level for 10 s, still at 101.7, as its ropelength
     * had to fall below three quarters of 89.14 first */
    r->schedule.resolved_at = m.ropelength;
    tk_stepping_reset(r);
    return resampled ? TK_OK : tk_type_check(r, "an escape's deformation", err);
}

/* Whether `curve` resampled to `count` vertices would keep the run's
 * type (*kept), without changing anything. */
static int resampled_keeps(tk_run *r, const tk_curve *curve, size_t count, bool *kept,
                           tk_error *err)
{
    tk_curve *resampled = NULL;
    *kept = false;
    int rc = tk_curve_resample_total(curve, count, &resampled, err);
    if (!rc)
        rc = tk_type_kept(r, resampled, kept, err);
    tk_curve_free(&resampled);
    return rc;
}

/* A loose try (turned inside out, or deformed far) restarts on the loose
 * levels, as a loose start does, if its resampled curve keeps the type;
 * else on the coarsest level (*count, already that level's).  The count
 * is reckoned from the try's own ropelength where that is the larger: a
 * turned trefoil (ropelength 32.8 before) resampled to 21 vertices at
 * 0.625 a unit of 32.8 lost its type. */
static int go_loose(tk_run *r, const tk_curve *curve, double rope, size_t *count, tk_error *err)
{
    int loose = loose_levels(r);
    if (loose == 0)
        return TK_OK;
    tk_measure m;
    int rc = measure(curve, &m, err);
    if (rc)
        return rc;
    r->schedule.coarse_level = r->schedule.coarse_levels + loose;
    size_t want = level_count(r, fmax(rope, reckoned_ropelength(curve, &m)));
    bool kept = false;
    rc = resampled_keeps(r, curve, want, &kept, err);
    if (!rc && kept) {
        r->schedule.loose = loose;
        *count = want;
    } else {
        r->schedule.coarse_level = r->schedule.coarse_levels;
    }
    return rc;
}

int tk_schedule_restart(tk_run *r, tk_curve *curve, bool coarse, bool loose, int polish,
                        tk_error *err)
{
    size_t count = curve->nvert;
    if (coarse && !(r->schedule.final_ropelength > 0.0))
        fix_final(r, reference_ropelength(r));
    r->schedule.loose = 0;
    if (coarse && r->schedule.coarse_levels > 0) {
        r->schedule.coarse_level = r->schedule.coarse_levels;
        count = level_count(r, reference_ropelength(r));
        int rc = loose ? go_loose(r, curve, reference_ropelength(r), &count, err) : TK_OK;
        if (rc) {
            tk_curve_free(&curve);
            return rc;
        }
    }
    /* The best curve put back is on the final polygon, whatever level the
     * try it replaces had reached: left at the try's, catalogue 3.1 at
     * 2,400 vertices (600 s), whose try was on its 600-vertex level when
     * the reserve began, polished the best from 32.7433009 to 32.743291
     * without noting it (the escapes note the final polygon only), then
     * took the stall for a coarse level's and went on to 1,200 vertices,
     * and ended with the best unpolished. */
    if (!coarse)
        r->schedule.coarse_level = 0;
    return restart(r, curve, count, coarse ? 0 : polish, err);
}

size_t tk_schedule_coarsest_count(tk_run *r, double rope)
{
    int level = r->schedule.coarse_level;
    r->schedule.coarse_level = r->schedule.coarse_levels;
    size_t count = level_count(r, rope);
    r->schedule.coarse_level = level;
    return count;
}

int tk_schedule_explore(tk_run *r, tk_curve *curve, double rope, bool loose, tk_error *err)
{
    r->schedule.loose = 0;
    r->schedule.coarse_level = r->schedule.coarse_levels;
    size_t count = rope > 0.0 ? level_count(r, rope) : curve->nvert;
    int rc = loose ? go_loose(r, curve, rope, &count, err) : TK_OK;
    if (rc) {
        tk_curve_free(&curve);
        return rc;
    }
    return restart(r, curve, count, 0, err);
}

/* A loose curve is kept at the tube.  Shortening a curve that touches
 * nothing can open its narrowest gap before the strands close in again,
 * so its thickness grows past the tube's and its ropelength, the measure
 * the schedule and the escapes judge by, rises while it shrinks: T(3,4)
 * after an escape's far deformation (autoscaled to 613) went from 1.03 to
 * 1.37 diameters in 8 steps, its ropelength down to 448 and then up
 * again, so its coarse polygon looked done and the finer one took 24,000
 * steps (70 s) to come down to 61.3.  With autoscale, a curve thicker
 * than the start's margin is scaled down to it, as the start was: the
 * ropelength stays, the length falls as much as the thickness allows, and
 * the flow works on contacts at once.  (The figures of the step before
 * are those of the curve before; scaling changes no ropelength.) */
static void keep_at_tube(tk_run *r)
{
    const tk_step_report *s = &r->life.latest;
    if (!r->opt.autoscale || s->vertices != r->shared.curve->nvert ||
        !(s->thickness > r->opt.autoscale_margin * r->tau))
        return;
    /* the first step after a restart reports the figures of the curve it
     * was given: catalogue 10.124 turned inside out reported 1.045 where
     * its curve was at 0.999999, was scaled 4% below the tube, and its
     * run failed; the thinner of the two is the one to scale by */
    double thickness = s->thickness;
    tk_measure now;
    if (measure(r->shared.curve, &now, NULL) == TK_OK && now.thickness < thickness)
        thickness = now.thickness;
    if (thickness > r->opt.autoscale_margin * r->tau)
        tk_curve_scale(r->shared.curve, r->opt.autoscale_margin * r->tau / thickness);
}

/* With the vertices option a start too loose for a coarse level (fewer
 * than 2 x COARSEST_RESOLUTION / sqrt 2 vertices per unit of its
 * ropelength)
 * starts on the final polygon, and gets the coarse levels its ropelength
 * allows once it has fallen that far, before the final polygon is first
 * reached.  Without them Lissajous 6_1 L(3,2,5) (ropelength 429) at 480
 * vertices spent the first 120 s of its 600 coming down to 57.10 on 480
 * vertices, and its explored tries (escape.c) began after that; with them
 * it was on 240 vertices after 3.7 s, at 57.15 after 25 s, and its tries
 * had explored that level and reached 56.80 by 57 s.  The loose levels
 * come with them, as at a start: the parametric figure-eight at 280
 * vertices (15,000 steps) otherwise stopped in its kinked trap on 140
 * (55.29), and its turned tries, which keep its symmetry, left it only
 * for 54.51; with them it came to 42.1085 before any try. */
static int coarsen_late(tk_run *r, double rope, tk_error *err)
{
    const tk_options *o = &r->opt;
    if (!(o->vertices > 0) || r->schedule.final_ropelength > 0.0 ||
        r->schedule.coarse_levels > 0 || r->schedule.restarts > 0 || !(rope > 0.0) ||
        !isfinite(rope))
        return TK_OK;
    int levels = levels_below(r, (double)o->vertices / rope);
    if (levels == 0)
        return TK_OK;
    r->schedule.coarse_levels = levels;
    r->schedule.loose = loose_levels(r);
    r->schedule.coarse_level = levels + r->schedule.loose;
    r->schedule.share_from = tk_schedule_spent(r);
    return resample_to(r, level_count(r, rope), err);
}

/* Re-resolution during the run: the start was resampled to `resolution`
 * vertices per unit of ropelength, and as the knot tightens that count
 * grows finer than asked for.  Finer than needed costs twice: every step
 * solves for more constraints, and the step the flow can take (explicit
 * Euler on the length gradient, whose stiffness grows as the edges
 * shorten, and the overstep control at kinks) shrinks with the edges.
 * When the ropelength has fallen by the re_resolve fraction since the
 * last resampling and the count is that much too fine, the curve is
 * resampled along its spline to ceil(resolution * ropelength) vertices
 * and scaled about its centroid just enough to be feasible again (costing
 * as much length, relatively, as the resampling cost thickness). */
int tk_schedule_before_step(tk_run *r, tk_error *err)
{
    const tk_options *o = &r->opt;
    double rope = r->life.latest.ropelength;
    keep_at_tube(r);
    if (r->schedule.move_on)
        return refine(r, err);
    int rc = coarsen_late(r, rope, err);
    if (rc)
        return rc;
    double fraction = o->re_resolve > 0.0 || tk_schedule_final(r) ? o->re_resolve
                                                                   : COARSE_RE_RESOLVE;
    if (!(fraction > 0.0) || !(o->resolution > 0.0) || !isfinite(rope))
        return TK_OK;
    if (!isfinite(r->schedule.resolved_at)) {
        r->schedule.resolved_at = rope;
        return TK_OK;
    }
    /* Right after a restart the last report is still the replaced
     * curve's, and so is `rope`: a polygon with no report of its own is
     * not judged here (after a refinement the two agree anyway, as
     * resample_to stores that ropelength).  So a loose try stays on the
     * count go_loose reckoned from its own
     * looser curve and follows its own ropelength down from there
     * (restart() stored it as resolved_at).  Until this was so, the
     * check brought each loose try at its first step to the count of the
     * curve it replaced (10.34's turned try "to 56 vertices in 2 s" in
     * 1e7a2b5's figures: 0.625 a unit of the 89.14 it replaced), as
     * coarse a polygon as the tightened curve's for a curve loosened many
     * times over.  Measured at resolution 5, 60 s (bench/FIGURES.md,
     * "A loose try on its own count"): of the catalogue files of 38
     * knots, 7 ended lower, by 0.06% to 4.2%, 2 higher, by 0.08% and
     * 1.3%; of the 54 starts of two table slices, 3 lower (0.21% to 2.5%),
     * 4 higher (0.11% to 4.6%): a reshuffle; the catalogue's 10.124 in
     * 120 s reaches T(3,5)'s basin (71.0022; 71.0547 before). */
    if (r->life.nhistory == r->schedule.resampled_from)
        return TK_OK;
    double want = (double)level_count(r, rope);
    if (!(rope < r->schedule.resolved_at * (1.0 - fraction)) ||
        !(want < (double)r->shared.curve->nvert * (1.0 - fraction)))
        return TK_OK;
    /* so few vertices can lose the type (a wandered start of catalogue
     * 9.45, on a loose try's level at 47 vertices, failed its job that
     * way): where they would, the polygon stays, until the ropelength
     * has fallen by as much again. */
    bool kept = false;
    rc = resampled_keeps(r, r->shared.curve, (size_t)want, &kept, err);
    if (rc || !kept) {
        r->schedule.resolved_at = rope;
        return rc;
    }
    return resample_to(r, (size_t)want, err);
}

/* Whether the last POLISH_CRITICAL_STEPS steps since `from` (history
 * entries) all had a residual below POLISH_CRITICAL. */
static bool critical_since(const tk_run *r, size_t from)
{
    size_t n = r->life.nhistory;
    if (n < from + POLISH_CRITICAL_STEPS)
        return false;
    for (size_t k = n - POLISH_CRITICAL_STEPS; k < n; k++)
        if (!(r->life.history[k].residual < POLISH_CRITICAL))
            return false;
    return true;
}

/* Whether the ropelength has stopped falling at the current level: by
 * less than the bound over the window, or at a rate that makes less over
 * it (POLISH_RATE_FROM). */
static bool stalled(const tk_run *r)
{
    size_t from = r->schedule.polish_from, window = tk_schedule_window(r, POLISH_WINDOW);
    double fall, bound = POLISH_CHANGE * tk_polish_scale(r);
    if (tk_history_fall(r, from, window, &fall) && fall < bound)
        return true;
    bool above_coarsest =
        tk_schedule_final(r) || r->schedule.coarse_level < r->schedule.coarse_levels;
    return above_coarsest && window >= POLISH_RATE_FROM * POLISH_WINDOW &&
           tk_history_fall(r, from, POLISH_WINDOW, &fall) &&
           fall * (double)window / POLISH_WINDOW < bound;
}

bool tk_schedule_settled(const tk_run *r)
{
    return tk_schedule_final(r) && r->schedule.polish_level >= polish_levels(r) &&
           (stalled(r) || critical_since(r, r->schedule.polish_from));
}

/* Judged on the history before this step's figures, after its motion and
 * before its error recovery (which then works to the new tolerances).  A
 * coarse level moves on at its first stall, unless escapes judge their
 * tries there: then it is polished first, as the final polygon is, and
 * moves on when its last level stalls or JUDGED_SHARE of the budget has
 * gone on polishing it. */
void tk_schedule_watch(tk_run *r, bool judged_here)
{
    bool coarse = r->schedule.coarse_level > 0;
    if (coarse && judged_here && r->schedule.polish_level > 0 &&
        r->life.nhistory > r->schedule.polish_began &&
        tk_schedule_spent(r) -
                tk_schedule_spent_at(r, &r->life.history[r->schedule.polish_began]) >=
            JUDGED_SHARE) {
        tk_schedule_move_on(r);
        return;
    }
    bool deeper = (!coarse || judged_here) &&
                  r->schedule.polish_level < polish_levels(r);
    if (!(deeper || coarse) || !(stalled(r) || critical_since(r, r->schedule.polish_from)))
        return;
    if (!deeper) {
        tk_schedule_move_on(r);
        return;
    }
    if (r->schedule.polish_level == 0)
        r->schedule.polish_began = r->life.nhistory;
    r->schedule.polish_level++;
    r->schedule.polish_from = r->life.nhistory;
}
