/* Escapes from critical points that are not the minimum.  See run.h for
 * the rooms of the flow.
 *
 * The flow is a gradient flow: it stops wherever the resolved gradient
 * vanishes, and a start with a symmetry keeps it, so it can settle in a
 * critical configuration far from tight (the parametric figure-eight
 * ((2 + cos 2t) cos 3t, (2 + cos 2t) sin 3t, sin 4t) at 56.10 with 12
 * kinks at the curvature bound; T(2,5) from the round torus at 48.21,
 * keeping its five-fold symmetry; the tight values are 42.10 and 47.21).
 * Once the final polygon has all but stopped tightening, the best curve
 * so far is deformed by a smooth random displacement (a few Fourier
 * modes along each component, so that strands move together rather than
 * against each other), made feasible by scaling, and tightened again
 * from the coarsest level of the schedule, where kinks are least stiff.
 * Measured on those two starts at resolution 5: the figure-eight left
 * 56.10 for 42.10, T(2,5) left 48.21 for 47.22; a deformation that keeps
 * 90% of the thickness and no coarse restart both ended back in the same
 * configuration (48.208, 55.13).  The deformation's size is the largest
 * (from one diameter down by 0.7 each time) that keeps the knot type and
 * three quarters of the thickness (a near escape) or a twentieth of it
 * (a far one); the kinds take turns (try_curve).  A far escape loosens the
 * knot many times over, and its tightening from there can find another
 * basin: catalogue 6.1 at 186 vertices settles at 57.733 (+1.8% over the
 * atlas's 6_1), as does a copy of it doubled in size and deformed down
 * to 40% of its thickness, while one deformed down to 7% reached 56.817
 * in 150 s; near escapes gained 0.01 each. */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"
#include "run.h"
#include "tk/generate.h"
#include "tk/relax.h"
#include "tk/struts.h"
#include "tk/thickness.h"

/* Converged: the ropelength fell by less than ESCAPE_CHANGE (relative)
 * over ESCAPE_WINDOW steps of the final polygon (counted for its edges,
 * tk_schedule_window). */
#define ESCAPE_WINDOW 300
#define ESCAPE_CHANGE 2e-5
/* The deformation: ESCAPE_MODES Fourier modes per component, mode k with
 * standard deviation amplitude / k per coordinate; the amplitude starts
 * at ESCAPE_AMPLITUDE diameters and shrinks by ESCAPE_SHRINK until the
 * curve keeps ESCAPE_THICKNESS of its thickness and its type, at most
 * ESCAPE_SIZES times. */
#define ESCAPE_MODES 3
#define ESCAPE_AMPLITUDE 1.0
#define ESCAPE_SHRINK 0.7
#define ESCAPE_THICKNESS 0.75
#define ESCAPE_FAR_THICKNESS 0.05
#define ESCAPE_SIZES 40
/* A run that crawls on its final polygon, its ropelength falling by less
 * than ESCAPE_CRAWL_CHANGE over ESCAPE_WINDOW steps yet never so little
 * as to count as converged, tries an escape all the same once it has
 * spent ESCAPE_CRAWL of the budget there (since the polygon was made, by
 * refinement or by the last escape): the disguised 6.1 at 480 vertices
 * fell from 57.75 to 57.46 in 600 s and never tried one.  The fall bound
 * keeps a run that is still tightening fast (a Hopf link at 35 on its way
 * to 8 pi under a small step budget) from being deformed. */
#define ESCAPE_CRAWL 0.2
#define ESCAPE_CRAWL_CHANGE 2e-4
/* The last ESCAPE_RESERVE of the budget polishes the best curve: no
 * escape starts then, and a try still behind the best when it begins is
 * given up for the best.  A try restarts from the coarsest level and
 * stops at the first plateau of the final polygon, while the plateau
 * itself still falls slowly: catalogue 8.19 at 489 vertices (600 s,
 * seed 1) reached 61.004 to 61.007 at the end of each of its near tries,
 * and its best, 61.00424, polished for 100 s when the tries were spent,
 * went on to 61.0000 after 31 s and 60.9967 after 100 s; seed 2, whose
 * last try ran to the end, ended at 61.00027 with that best at 61.00429
 * never polished.  With the reserve seed 2 gave up a far try at 61.10
 * for that best at 480 s and ended at 60.99631, below the atlas's
 * 60.99699 (seed 1 spends its tries before the reserve). */
#define ESCAPE_RESERVE 0.2

void tk_escape_start(tk_run *r, bool resumed, const tk_curve *start)
{
    /* An open component's hooks are not guarded by a type the invariants
     * can tell (an open rope has none): a deformation, applied at once,
     * could pull a clasp's ropes through each other and the run would go
     * on from an unhooked curve.  Such a curve tries no escape. */
    r->escape.most = r->opt.escapes;
    for (size_t comp = 0; comp < start->ncomp; comp++)
        if (!start->closed[comp])
            r->escape.most = 0;
    r->escape.rng = r->opt.seed;
    r->escape.coarse = r->escape.best_coarse = NAN;
    r->escape.explore_over = resumed; /* its exploration's best is not kept */
    if (!resumed && r->escape.most > 0 && !start->npins)
        (void)tk_curve_copy(start, &r->escape.start, NULL); /* none: a plateau's turn instead */
}

void tk_escape_free(tk_run *r)
{
    tk_curve_free(&r->escape.best);
    tk_curve_free(&r->escape.explored);
    tk_curve_free(&r->escape.start);
    tk_constraints_free(&r->escape.best_set);
    free(r->escape.log);
}

bool tk_escape_converged(const tk_run *r)
{
    double fall;
    if (!tk_schedule_final(r) ||
        !tk_history_fall(r, r->schedule.resampled_from, tk_schedule_window(r, ESCAPE_WINDOW),
                         &fall))
        return false;
    if (fall < ESCAPE_CHANGE)
        return true;
    size_t from = r->schedule.resampled_from;
    return fall < ESCAPE_CRAWL_CHANGE &&
           tk_schedule_spent(r) - tk_schedule_spent_at(r, &r->life.history[from]) >=
               ESCAPE_CRAWL;
}

/* The coarsest level, where tries are judged (judge_coarse, explore), is
 * polished before it is left, as the final polygon is (for a twentieth
 * of the budget at most: JUDGED_SHARE, schedule.c): at its first stall
 * a plateau still falls, slowly, and where it has fallen to ranks the
 * final figure better than where it stalled.  T(3,4) at 489 vertices
 * (600 s) settled on curves whose 245-vertex polygons stalled between
 * 61.100 and 61.12 and its runs ended above the atlas's 60.99699 in three
 * seeds of four (61.00998, median 61.00838); the same start tightened on
 * 245 vertices alone for 150 s (polished, with escapes) reached 61.0535
 * and 61.0815 for seeds 1 and 2, and refined from there to 489 for 450 s
 * without escapes 60.99448 and 61.02733.  Polished at its coarsest level
 * (the first tightening's too), three seeds of four ended below the atlas
 * (60.99433 for seed 1, median 60.99468); as here, seed 1 ends at
 * 60.99435.  Not the first tightening's level, before any try: the
 * disguised figure-eight of an_explored_try_leaves_a_coarse_trap, whose
 * first stall (55.30, kinks at the curvature bound) is where exploring
 * leaves for the tight knot's basin, crawled down from there under the
 * smaller tolerances for the level's whole share of 16,000 steps, to
 * 50.69 with a residual of 0.13, and explored nothing. */
bool tk_escape_judged_here(const tk_run *r)
{
    return tk_escape_tries(r) > 0 && !r->escape.polishing && r->schedule.coarse_level > 0 &&
           r->schedule.coarse_level == r->schedule.coarse_levels;
}

/* *kept becomes a copy of c, in place when it has c's shape; NULL when
 * that fails. */
static int keep(tk_curve **kept, const tk_curve *c, tk_error *err)
{
    if (*kept && (*kept)->nvert == c->nvert && (*kept)->ncomp == c->ncomp &&
        !memcmp((*kept)->offset, c->offset, c->ncomp * sizeof *c->offset)) {
        memcpy((*kept)->xyz, c->xyz, 3 * c->nvert * sizeof *c->xyz);
        return TK_OK;
    }
    tk_curve_free(kept);
    return tk_curve_copy(c, kept, err);
}

/* The run's curve, on the final polygon, as the result of the try under
 * way (or of the first tightening): logged, and kept if the best. */
static int note(tk_run *r, tk_error *err)
{
    if (!tk_schedule_final(r))
        return TK_OK;
    const tk_step_report *s = &r->life.latest;
    tk_escape *e = r->escape.nlog > 0 ? &r->escape.log[r->escape.nlog - 1] : NULL;
    if (e && !e->explored && !r->escape.polishing) {
        if (isnan(e->reached) || s->ropelength < e->reached) {
            bool was = e->improved;
            e->reached = s->ropelength;
            e->improved = e->reached < e->from;
            r->escape.improved += e->improved && !was;
        }
    }
    if (r->escape.best && !(s->ropelength < r->escape.best_report.ropelength))
        return TK_OK;
    int rc = keep(&r->escape.best, r->shared.curve, err);
    if (!rc)
        rc = tk_constraints_copy(&r->escape.best_set, &r->active.set, err);
    if (rc) {
        tk_curve_free(&r->escape.best);
        return rc;
    }
    r->escape.best_report = *s;
    r->escape.best_polish = r->schedule.polish_level;
    if (!r->escape.polishing) {
        r->escape.best_coarse = r->escape.coarse;
        r->escape.best_coarse_vertices = r->escape.coarse_vertices;
    }
    return rc;
}

/* Noted at every step, not only where a try has converged: a try (or the
 * best put back to be polished) that went below the best and then rose
 * a little before it was judged used to be put back to the old best and
 * replay the same steps.  Catalogue 8.19 at 489 vertices (600 s) made
 * the same 482 steps from 60.996670 three times over, each reaching
 * 60.996636 and rising to 60.996693 by the window's end. */
void tk_escape_after_step(tk_run *r)
{
    if (r->escape.most > 0)
        (void)note(r, NULL); /* out of memory for the copy: no best, the run's curve ends it */
}

int tk_escape_tries(const tk_run *r)
{
    return r->escape.tries_before + (int)r->escape.nlog;
}

static bool tries_left(const tk_run *r)
{
    return tk_escape_tries(r) - r->escape.explore_tries < r->escape.most &&
           tk_schedule_spent(r) < 1.0 - ESCAPE_RESERVE;
}

bool tk_escape_ask(tk_run *r)
{
    if (r->escape.most <= 0 || r->escape.due)
        return r->escape.due;
    if (note(r, NULL) != TK_OK)
        return false; /* out of memory for the copy: no escape */
    /* the best put back goes on from where its polishing has come: put
     * back again it would replay the same steps */
    bool behind = !r->escape.polishing &&
                  r->escape.best_report.ropelength < r->life.latest.ropelength;
    r->escape.due = tries_left(r) || behind;
    return r->escape.due;
}

void tk_escape_reserve(tk_run *r)
{
    if (r->escape.reserved || r->escape.due || tk_escape_tries(r) == 0 ||
        tk_schedule_spent(r) < 1.0 - ESCAPE_RESERVE)
        return;
    r->escape.reserved = true;
    if (note(r, NULL) != TK_OK)
        return; /* out of memory for the copy: the try goes on */
    /* a try on a coarser polygon is behind by its nature: its ropelength
     * does not compare with the final polygon's */
    r->escape.due = r->escape.best && !r->escape.polishing &&
                    (!tk_schedule_final(r) ||
                     r->escape.best_report.ropelength < r->life.latest.ropelength);
}

/* A deformation is applied at once: every vertex moves along a straight
 * line from the best curve to the deformed one.  Its type is checked at
 * the end, but the invariants cannot tell every link apart.  With each
 * component's Alexander polynomial and the linking numbers alone the
 * Borromean rings had the invariants of three unlinked rings (the link's
 * determinant, 16 against 0, now tells these two apart), and catalogue
 * 6.3.2 tightened at 630 vertices for 600 s (bench/table2.sh) ended at
 * 39.6, three rings pulled apart by a deformation, where the Borromean
 * rings' tight value is 58.006.  So the path itself must be an isotopy (tk_struts_path_embedded),
 * or a smaller deformation is tried. */

/* The largest deformation of `best` (of the given thickness) that keeps
 * its type, on the way too, and ESCAPE_THICKNESS of its
 * thickness (ESCAPE_FAR_THICKNESS when far), into *out: ESCAPE_MODES
 * modes of normal coefficients (tk_generate_fourier). */
static int deformed(tk_run *r, const tk_curve *best, double thickness, bool far, tk_curve **out,
                    double *amplitude, tk_error *err)
{
    size_t ncoef = best->ncomp * ESCAPE_MODES * 6;
    double *coef = malloc(ncoef * sizeof *coef);
    int rc = coef ? tk_curve_copy(best, out, err)
                  : tk_error_set(err, TK_ENOMEM, "out of memory for a deformation");
    for (size_t i = 0; !rc && i < ncoef; i++)
        coef[i] = tk_rng_normal(&r->escape.rng);
    double a = ESCAPE_AMPLITUDE * r->tau;
    double keep = far ? ESCAPE_FAR_THICKNESS : ESCAPE_THICKNESS;
    bool found = false;
    for (int size = 0; !rc && !found && size < ESCAPE_SIZES; size++, a *= ESCAPE_SHRINK) {
        r->work.deforms += (double)best->nvert;
        tk_generate_fourier(*out, best, coef, ESCAPE_MODES, a);
        tk_curve_pins_snap(*out); /* a pinned vertex stays on its constraint */
        tk_measure m;
        tk_error why;
        if (tk_thickness_measure(*out, NULL, &m, &why) != TK_OK ||
            !(m.thickness >= keep * thickness))
            continue;
        rc = tk_type_kept(r, *out, &found, err);
        if (!rc && found) {
            bool embedded;
            rc = tk_struts_path_embedded(best, *out, &embedded, err);
            found = !rc && embedded;
        }
        *amplitude = a / r->tau;
    }
    free(coef);
    if (!rc && !found) {
        /* nothing that small changes it: tighten the best again as it is */
        memcpy((*out)->xyz, best->xyz, 3 * best->nvert * sizeof *best->xyz);
        *amplitude = 0.0;
    }
    if (rc)
        tk_curve_free(out);
    return rc;
}

/* The kinds of tries, in turn: the best turned inside out
 * (tk_relax_turn), a far deformation, a near one.  Deformations, near or
 * far, stay in the strands' arrangement: catalogue 10.124 at resolution 5
 * (120 s) settled at 71.128 and its 13 tries in 600 s all came back
 * within 0.01%, as did starts deformed far from it (71.127) and relaxed
 * (71.127), while a T(3,5) start ends at 71.002.  Turned about its
 * centroid and relaxed, the same curve tightened on 178 vertices to
 * 71.147, where T(3,5)'s does (71.151) and the file's stops at 71.315:
 * 10.124 is T(3,5), and what the file's curve winds around, turned, it
 * winds around the other way.  About points near the centroid, 2 turns of
 * 7 reached that basin, 3 a basin between (71.20), none of 10 pulled far
 * off by tk_relax's isotopy.  The turn comes first: a knot of 9 or 10
 * crossings gets two or three tries in 60 s, and with the near one first
 * the catalogue's 9.38, 10.110 and 10.148 tried only near ones and ended
 * at 82.88, 96.13 and 83.59 (resolution 5, loose 2), their first turned
 * try at 81.83, 90.04 and 79.37.  A turned or far try starts on the
 * loose levels (the loose option) as a loose start does, and is judged
 * on the coarsest level as every try is: catalogue 10.70 (near tries
 * first) ended at 91.64, still falling, with its turned try started on
 * the coarsest level, and at 89.25 with it started on the loose levels.
 * For a while tries on the final polygon started on the coarsest level
 * all the same: their loose levels had followed the ropelength of the
 * best curve, not their own (schedule.c, restart), and took the rest of
 * the budget (catalogue 10.124, resolution 5, 120 s: 71.0571).  On the
 * coarsest level a turned curve, autoscaled about three times as long
 * as the best, comes down slowly: catalogue 10.34's turned try on the
 * final polygon spent 22 s of a 60 s run there and was given up at 96.1.
 * Since each try follows its own ropelength, 10.124 reaches T(3,5)'s
 * basin with its turned try on the final polygon on the loose levels
 * (71.0037; 71.0007 on the coarsest), and of 15 catalogue knots of 9
 * and 10 crossings (60 s) 13 end within 5e-5 of where they did with
 * those tries on the coarsest level; 10.34 and 10.154 end lower (88.278
 * and 82.654 against 88.844 and 82.921), through their explored try, the
 * turn being cheaper (bench/FIGURES.md). */
enum { TRY_TURNED, TRY_FAR, TRY_NEAR, TRY_KINDS };

/* The turned curve is relaxed on TURN_RESOLUTION vertices a unit of
 * ropelength, for TURN_STEPS steps (about 2 s for 10.124's 107). */
#define TURN_RESOLUTION 1.5
#define TURN_STEPS 3000

/* c turned inside out about its centroid plus `offset` (of its spread),
 * on TURN_RESOLUTION vertices a unit of `rope` (8 a component at least),
 * into *out; TK_ENUMERIC when the turn is refused (a centre too near the
 * curve, or too few vertices to turn it). */
static int turn(tk_run *r, const tk_curve *c, const double offset[3], double rope,
                tk_curve **out, tk_error *err)
{
    size_t count = (size_t)(TURN_RESOLUTION * rope);
    if (count < 8 * c->ncomp)
        count = 8 * c->ncomp;
    r->work.turns += (double)count * (double)count;
    tk_error why;
    int rc = tk_relax_turn(c, offset, count, TURN_STEPS, out, &why);
    if (rc == TK_ENOMEM)
        return tk_error_set(err, rc, "%s", why.message);
    return rc ? TK_ENUMERIC : TK_OK;
}

/* Try number `index` (explored, or on the final polygon) from `best` (of
 * the given thickness and ropelength) into *out; *turned says whether it
 * was turned, *loose whether it starts on the loose levels (a turned or
 * far one).  The first turn is about the centroid itself, the later
 * ones about points drawn near it (the stream draws the same either way):
 * catalogue 10.124 turned about its centroid tightened to 71.0024 and
 * 71.0012 in 60 s (resolution 5, two runs of bench/catalogue); runs
 * whose turns were all about points drawn near it
 * ended at 71.054 and 71.058 (seeds 1 and 2, 120 s), and with the first
 * about the centroid at 71.00266 and 71.00279 (each through a turned try
 * on the final polygon, from 71.058). */
static int try_curve(tk_run *r, const tk_curve *best, double thickness, double rope, int index,
                     tk_curve **out, double *amplitude, bool *turned, bool *loose, tk_error *err)
{
    int kind = index % TRY_KINDS;
    *turned = false;
    /* turned inside out, a pinned vertex would leave its constraint far
     * behind: a far deformation instead */
    if (kind == TRY_TURNED && best->npins)
        kind = TRY_FAR;
    *loose = kind != TRY_NEAR;
    if (kind != TRY_TURNED)
        return deformed(r, best, thickness, kind == TRY_FAR, out, amplitude, err);
    double offset[3];
    tk_relax_turn_offset(&r->escape.rng, offset);
    if (index == TRY_TURNED) /* the first turn of the kind of tries: about the centroid */
        offset[0] = offset[1] = offset[2] = 0.0;
    *amplitude = 0.0;
    int rc = turn(r, best, offset, rope, out, err);
    /* refused: a far deformation instead */
    *turned = rc == TK_OK;
    return rc == TK_ENUMERIC ? deformed(r, best, thickness, true, out, amplitude, err) : rc;
}

/* Exploration: before the run first refines its coarsest polygon, tries
 * start from the lowest curve found there and are judged there alone,
 * where a step costs a fraction of the final polygon's and kinks are
 * least stiff.  A plateau of the coarse polygon that is not the tight
 * knot's is otherwise refined, and the final polygon can take a long
 * time to leave it, too steadily for a crawl: the figure-eight disguised
 * by bench/starts (resolution 5) stopped at 55.30 on 142 vertices with
 * kinks at the curvature bound (residual 0.02); on the final 277 it fell
 * about 0.05 every 300 steps and was at 44.95 after 120 s, with no
 * escape.  Its first explored try left that plateau at 42.18 on the
 * coarse polygon, and the run ended at 42.1238 (+0.063% over the atlas's
 * 4_1); with a budget of 16,000 steps, 42.1243 against 44.597.
 * Exploring ends after EXPLORE_FAILS tries in a row that gain less than
 * EXPLORE_GAIN (a plateau's own spread: tries that end in the same basin
 * differ by about 2e-5), after EXPLORE_SHARE of the budget, or after as
 * many tries as the escapes option allows (they are not counted against
 * it); the lowest curve is then put back on its own ropelength's coarse
 * polygon, which the later tries will use too.  A try under way when the
 * share ends goes on instead if it is lower already.  A coarse level can
 * end while the ropelength still rises (catalogue 3.1 unscaled at step
 * 201, residual 0.69): exploring starts only from a first plateau whose
 * residual is below EXPLORE_CRITICAL.  The first plateau's polygon is
 * reckoned from a looser curve and can be finer than its own ropelength's
 * coarsest level: catalogue 8.19 at resolution 5 stopped at 61.13 on 203
 * vertices, where 153 are its own, and its tries there (a far one took
 * 10 s) explored for the whole first quarter of a 120 s run.  More than
 * EXPLORE_RESOLVE finer, it is put back on its own polygon first and its
 * plateau there found again: the tries and the lowest then compare on one
 * polygon, and 8.19's three tries ended exploring at 17.7 s.  Half the
 * budget and five tries, not a quarter and three, since a try's
 * coarsest level is left after a twentieth of the budget's polishing
 * (schedule.c, JUDGED_SHARE) and a try costs about 10 s in 60 at 10
 * crossings: of 15 catalogue knots of 9 and 10 crossings (resolution 5,
 * 60 s), the excess over the lowest any run reached summed to 2.9% with
 * both, 4.6% with the coarsest level left early alone (counted then from
 * the level's start), 10.7% with neither; 10.104 ended at 89.238 against
 * 90.598, 10.76 at 88.832 against 89.390, 10.34 at 87.655 against
 * 86.902. */
#define EXPLORE_SHARE 0.5
#define EXPLORE_FAILS 5
#define EXPLORE_GAIN 1e-4
#define EXPLORE_CRITICAL 0.1
#define EXPLORE_RESOLVE 0.05

static bool explore_more(const tk_run *r)
{
    return r->escape.explore_tries < r->escape.most && r->escape.explore_fails < EXPLORE_FAILS &&
           tk_schedule_spent(r) < EXPLORE_SHARE;
}

/* The curve under way has left its coarsest polygon while the run
 * explores: kept if the lowest there, then the next explored try is
 * asked for or, exploring over, the lowest is put back to go on from
 * there.  False when the run goes on with this curve (it is the lowest
 * and exploring is over), as it would without exploring. */
static bool explore(tk_run *r)
{
    const tk_step_report *s = &r->life.latest;
    tk_escape *e = r->escape.nlog > 0 ? &r->escape.log[r->escape.nlog - 1] : NULL;
    if (!e && !(s->residual < EXPLORE_CRITICAL)) {
        r->escape.explore_over = true; /* no plateau: the run goes on as without exploring */
        return false;
    }
    /* the first plateau's polygon is reckoned from a looser curve */
    bool resolve = !e && !r->escape.explore_resolved &&
                   (double)tk_schedule_coarsest_count(r, s->ropelength) <
                       (1.0 - EXPLORE_RESOLVE) * (double)s->vertices;
    if (e && e->explored) {
        e->coarse = s->ropelength;
        e->improved = s->ropelength < e->from;
        r->escape.improved += e->improved;
    }
    /* a gain within a plateau's own spread is no other basin */
    bool lower = !r->escape.explored || s->ropelength < r->escape.explored_rope;
    bool gain = !r->escape.explored ||
                s->ropelength < r->escape.explored_rope * (1.0 - EXPLORE_GAIN);
    r->escape.explore_fails = gain ? 0 : r->escape.explore_fails + 1;
    if (lower) {
        if (keep(&r->escape.explored, r->shared.curve, NULL) != TK_OK) {
            r->escape.explore_over = true; /* out of memory for the copy: this curve goes on */
            return false;
        }
        r->escape.explored_rope = s->ropelength;
        r->escape.explored_thickness = s->thickness;
    }
    r->escape.explore_pending = TK_EXPLORE_TRY;
    if (resolve) {
        r->escape.explore_resolved = true;
        r->escape.explore_pending = TK_EXPLORE_BACK;
    } else if (!explore_more(r)) {
        r->escape.explore_over = true;
        r->escape.explore_pending = TK_EXPLORE_BACK;
        if (!(s->ropelength > r->escape.explored_rope))
            r->escape.explore_pending = TK_EXPLORE_NONE;
    }
    return r->escape.explore_pending != TK_EXPLORE_NONE;
}

/* A new entry at the end of the escapes' log, or NULL (*err set). */
static tk_escape *log_entry(tk_run *r, tk_error *err)
{
    if (r->escape.nlog == r->escape.log_capacity) {
        size_t cap = r->escape.log_capacity ? 2 * r->escape.log_capacity : 8;
        tk_escape *grown = realloc(r->escape.log, cap * sizeof *grown);
        if (!grown) {
            tk_error_set(err, TK_ENOMEM, "out of memory for the escapes");
            return NULL;
        }
        r->escape.log = grown;
        r->escape.log_capacity = cap;
    }
    return &r->escape.log[r->escape.nlog++];
}

/* The first explored try is the run's start turned inside out about its
 * centroid (tk_relax_turn), not the plateau: which basin a run ends in
 * is mostly its start's shape's, and the turn of a loose start is a shape
 * of the same type that the tightened curve's turn does not reach.  The
 * table's turned start is the same turn (`generate turn`, on the file's
 * vertices), and turned again it is near the file's shape: the two
 * starts each try the other's shape.  Fourteen knots of 9 and 10
 * crossings whose starts disagreed in the table, the file's start and
 * the turned one each (resolution 5, 60 s): within 0.1% of the lowest
 * 18 runs of 28 against 14 with the plateau's turn first, both starts of
 * a knot in 6 knots against 3, their excess over it summed 4.5% against
 * 16.2%; 10.146 and 10.23 went below the table's lowest (79.780 against
 * 79.831, 88.150 against 88.484), 10.63's file the other way (0.50%
 * above; bench/FIGURES.md).  On TURN_RESOLUTION vertices a unit of the
 * plateau's ropelength, as a turn of the plateau; *out is the turned
 * curve, TK_ENUMERIC when there is none to make (no start kept, or the
 * turn refused), and a plateau's try is made instead. */
static int turned_start(tk_run *r, tk_curve **out, tk_error *err)
{
    static const double centroid[3] = {0.0, 0.0, 0.0};
    return r->escape.start ? turn(r, r->escape.start, centroid, r->escape.explored_rope, out, err)
                           : TK_ENUMERIC;
}

/* Before a step asked for by explore(): the next explored try, or the
 * lowest curve back. */
static int explore_next(tk_run *r, tk_error *err)
{
    tk_curve *curve = NULL;
    int rc;
    assert(r->escape.explored);
    if (r->escape.explore_pending == TK_EXPLORE_BACK) {
        /* (resolved, the first plateau is found again on that polygon) */
        rc = tk_curve_copy(r->escape.explored, &curve, err);
        tk_curve_free(&r->escape.explored);
        return rc ? rc : tk_schedule_explore(r, curve, r->escape.explored_rope, false, err);
    }
    double amplitude = 0.0;
    bool turned = false;
    bool loose = false;
    rc = r->escape.explore_tries == 0 ? turned_start(r, &curve, err) : TK_ENUMERIC;
    if (rc == TK_OK)
        turned = loose = true;
    else if (rc == TK_ENUMERIC)
        rc = try_curve(r, r->escape.explored, r->escape.explored_thickness,
                       r->escape.explored_rope, r->escape.explore_tries, &curve, &amplitude,
                       &turned, &loose, err);
    tk_escape *e = rc ? NULL : log_entry(r, err);
    if (!e) {
        tk_curve_free(&curve);
        return rc ? rc : TK_ENOMEM;
    }
    *e = (tk_escape){
        .step = r->life.latest.step,
        .from = r->escape.explored_rope,
        .amplitude = amplitude,
        .coarse = NAN,
        .reached = NAN,
        .improved = false,
        .explored = true,
        .turned = turned,
    };
    r->escape.explore_tries++;
    /* a turned curve comes on its own vertices: onto the coarsest polygon */
    return tk_schedule_explore(r, curve, e->turned ? r->escape.explored_rope : 0.0, loose, err);
}

/* A try is judged where it leaves its coarsest polygon, against where the
 * best's tightening left a polygon of as many vertices: the coarse
 * plateau costs a fraction of the final one and ranks the tries as the
 * final polygon does.  At 489 vertices (600 s, seed 1; each try's
 * coarsest polygon has 245), catalogue 8.19's and T(3,4)'s tries ranked
 * the same on both polygons in all 16 comparisons with the best, and the
 * tries that failed had spent 184 s and 45 s on their final polygons.
 * Given up at once, they leave that time to polish the best: 8.19 ended
 * at 60.99446 (60.99462 and 60.99555 before), T(3,4) at 61.0145
 * (61.01725 and 61.01793).  A best with no such figure (a run whose
 * first tightening started on its final polygon) judges no try on its
 * coarse polygon. */
static void judge_coarse(tk_run *r)
{
    if (!r->schedule.move_on || r->schedule.coarse_level != r->schedule.coarse_levels ||
        r->escape.polishing || !isnan(r->escape.coarse))
        return;
    const tk_step_report *s = &r->life.latest;
    r->escape.coarse = s->ropelength;
    r->escape.coarse_vertices = s->vertices;
    if (!r->escape.explore_over && explore(r)) {
        r->escape.coarse = NAN; /* this curve is replaced before it is refined */
        return;
    }
    tk_escape *e = r->escape.nlog > 0 ? &r->escape.log[r->escape.nlog - 1] : NULL;
    if (e && r->escape.explore_goes_on) {
        r->escape.explore_goes_on = false;
        e->coarse = s->ropelength;
        e->improved = s->ropelength < e->from;
        r->escape.improved += e->improved;
    }
    if (!e || e->explored)
        return; /* the first tightening (explored or not), or a resumed run's curve */
    e->coarse = s->ropelength;
    if (r->escape.best_coarse_vertices == s->vertices &&
        !(s->ropelength <= r->escape.best_coarse))
        r->escape.due = true; /* given up: its reached stays NAN */
}

int tk_escape_before_step(tk_run *r, tk_error *err)
{
    if (r->escape.most > 0)
        judge_coarse(r);
    if (!r->escape.explore_over && r->escape.explore_tries > 0 &&
        r->escape.explore_pending == TK_EXPLORE_NONE && !(tk_schedule_spent(r) < EXPLORE_SHARE)) {
        /* the exploring share spent with a try under way: the lowest goes
         * on, or the try if it is lower already (and judged where it
         * leaves its coarsest polygon, as the lowest) */
        r->escape.explore_over = true;
        r->escape.explore_goes_on = r->life.latest.ropelength < r->escape.explored_rope;
        r->escape.explore_pending = r->escape.explore_goes_on ? TK_EXPLORE_NONE : TK_EXPLORE_BACK;
    }
    if (r->escape.explore_pending != TK_EXPLORE_NONE) {
        int rc = explore_next(r, err);
        r->escape.explore_pending = TK_EXPLORE_NONE;
        return rc;
    }
    if (!r->escape.due)
        return TK_OK;
    r->escape.due = false;
    if (!r->escape.best)
        return TK_OK;
    tk_curve *curve = NULL;
    if (!tries_left(r)) {
        /* the tries are spent, or the reserve has begun, and the last
         * is behind: polish the best (what it reaches is not the try's) */
        r->escape.polishing = true;
        int rc = tk_curve_copy(r->escape.best, &curve, err);
        return rc ? rc : tk_schedule_restart(r, curve, false, false, r->escape.best_polish, err);
    }
    double amplitude = 0.0;
    int fine = tk_escape_tries(r) - r->escape.explore_tries;
    bool turned = false, loose = false;
    int rc = try_curve(r, r->escape.best, r->escape.best_report.thickness,
                       r->escape.best_report.ropelength, fine, &curve, &amplitude, &turned, &loose,
                       err);
    tk_escape *e = rc ? NULL : log_entry(r, err);
    if (!e) {
        tk_curve_free(&curve);
        return rc ? rc : TK_ENOMEM;
    }
    r->escape.polishing = false;
    r->escape.coarse = NAN;
    *e = (tk_escape){
        .step = r->life.latest.step,
        .from = r->escape.best_report.ropelength,
        .amplitude = amplitude,
        .coarse = NAN,
        .reached = NAN,
        .improved = false,
        .turned = turned,
    };
    return tk_schedule_restart(r, curve, true, loose, 0, err);
}

int tk_escape_finish(tk_run *r, bool *restored, tk_error *err)
{
    *restored = false;
    /* Kept whether or not the run tried an escape: on a fine polygon the
     * last steps' ropelength goes up and down by about the overstep
     * tolerance (steps judged by their length, and their violations,
     * section 4.5), and a run stops wherever its budget ends.  A generated
     * T(2,3) tightened at 2,400 vertices for 600 s, which never converged
     * and so tried none, stopped at 32.7431151 where it had been at
     * 32.7431102.  A resumed run's best is kept all the same. */
    if (r->escape.most <= 0 && !r->escape.best)
        return TK_OK;
    int rc = note(r, err);
    if (rc || !r->escape.best)
        return rc;
    if (tk_schedule_final(r) &&
        !(r->escape.best_report.ropelength < r->life.latest.ropelength))
        return TK_OK;
    tk_curve *curve = NULL;
    rc = tk_curve_copy(r->escape.best, &curve, err);
    if (!rc)
        rc = tk_schedule_restart(r, curve, false, false, r->escape.best_polish, err);
    *restored = rc == TK_OK;
    return rc;
}

/* splitmix64 adds its odd gamma to the state at every draw, so the
 * stream's position is (state - seed) / gamma modulo 2^64, gamma's
 * inverse found by Newton's iteration (each doubles the bits right). */
#define GAMMA 0x9e3779b97f4a7c15ULL

static uint64_t draws(const tk_run *r)
{
    uint64_t inv = GAMMA;
    for (int k = 0; k < 6; k++)
        inv *= 2 - GAMMA * inv;
    assert(inv * GAMMA == 1);
    return (r->escape.rng - (uint64_t)r->opt.seed) * inv;
}

void tk_escape_resume_point(const tk_run *r, tk_resume *out)
{
    out->escapes = tk_escape_tries(r);
    out->draws = (long)draws(r);
    out->best_polish = r->escape.best_polish;
}

const tk_curve *tk_run_best(const tk_run *r, tk_step_report *report)
{
    if (r->escape.best && report)
        *report = r->escape.best_report;
    return r->escape.best;
}

int tk_escape_resume(tk_run *r, const tk_resume *at, const tk_curve *best,
                     const tk_step_report *best_report, tk_error *err)
{
    r->escape.tries_before = at->escapes;
    r->escape.rng = (uint64_t)r->opt.seed + (uint64_t)at->draws * GAMMA;
    if (!best)
        return TK_OK;
    r->escape.best_report = *best_report;
    r->escape.best_polish = at->best_polish;
    return tk_curve_copy(best, &r->escape.best, err);
}

const tk_escape *tk_run_escapes(const tk_run *r, size_t *count)
{
    *count = r->escape.nlog;
    return r->escape.log;
}
