/* tightknot: example knots and links (include/tk/generate.h).
 *
 * Every generator samples a parametrised curve at equal parameter steps
 * (closed but for the clasp's ropes, sampled at equal arclength).
 * Angles are evaluated by unit_circle(), which reduces k/n to the
 * first quadrant in integers, so that points at multiples of pi/2 come out
 * exact (cos(M_PI) is -1 but sin(M_PI) is 1.2e-16): the Hopf link's vertex at
 * the other circle's centre is then exactly there, and the polygons keep the
 * symmetries of their curves bit for bit.
 */
#include "tk/generate.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"
#include "tk/geometry.h"
#include "tk/invariants.h"
#include "tk/pin.h"
#include "tk/struts.h"
#include "tk/thickness.h"

/* Counts beyond which a generator refuses: the VECT reader's default
 * limits (TK_VECT_LIMITS_INIT), so that every generated curve reads back. */
#define MAX_TOTAL_VERTICES ((size_t)10000000)
#define MAX_COMPONENTS ((size_t)10000)

/* (cos, sin) of 2 pi k / n, exact at multiples of pi/2. */
static void unit_circle(size_t k, size_t n, double *c, double *s)
{
    k %= n;
    /* 4k = quadrant * n + r with 0 <= r < n: the angle is
     * quadrant * pi/2 + (pi/2) r / n.  In 64 bits 4k cannot overflow
     * (n is a vertex count <= 10^7 or a torus q < 2^31). */
    uint64_t four_k = 4 * (uint64_t)k;
    uint64_t quadrant = four_k / n;
    uint64_t r = four_k % n;
    double a = (M_PI / 2.0) * (double)r / (double)n;
    double c0 = r == 0 ? 1.0 : cos(a);
    double s0 = r == 0 ? 0.0 : sin(a);
    switch (quadrant) {
    case 0: *c = c0; *s = s0; break;
    case 1: *c = -s0; *s = c0; break;
    case 2: *c = -c0; *s = -s0; break;
    default: *c = s0; *s = -c0; break;
    }
    /* No negative zeros in the output (x + 0.0 is +0 for x = -0). */
    *c += 0.0;
    *s += 0.0;
}

/* Checks a per-component count (0 = default) against the shared rules and
 * the total against the limit; *n receives the count to use. */
static int check_counts(size_t vertices, size_t default_vertices,
                        size_t ncomp, size_t *n, tk_error *err)
{
    size_t v = vertices ? vertices : default_vertices;
    if (ncomp > MAX_COMPONENTS)
        return tk_error_set(err, TK_ELIMIT, "%zu components exceed the limit of %zu",
                            ncomp, MAX_COMPONENTS);
    if (v < 3)
        return tk_error_set(err, TK_EINVAL,
                            "a closed component needs at least 3 vertices (asked for %zu)",
                            v);
    if (v > MAX_TOTAL_VERTICES || ncomp > MAX_TOTAL_VERTICES / v)
        return tk_error_set(err, TK_ELIMIT,
                            "%zu components of %zu vertices exceed the limit of %zu vertices",
                            ncomp, v, MAX_TOTAL_VERTICES);
    *n = v;
    return TK_OK;
}

/* A curve of ncomp closed components of n vertices each. */
static int new_closed(size_t ncomp, size_t n, tk_curve **out, tk_error *err)
{
    size_t *counts = malloc(ncomp * sizeof *counts);
    bool *closed = malloc(ncomp * sizeof *closed);
    int rc;
    if (!counts || !closed) {
        rc = tk_error_set(err, TK_ENOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < ncomp; i++) {
        counts[i] = n;
        closed[i] = true;
    }
    rc = tk_curve_new(out, ncomp, counts, closed, err);
done:
    free(counts);
    free(closed);
    return rc;
}

static size_t gcd_size(size_t a, size_t b)
{
    while (b) {
        size_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/* T(p, q): with g = gcd(p, q), p' = p/g, q' = q/g, one strand is
 *     alpha = p' t, beta = q' t, t in [0, 2 pi),
 * on the torus ((2 + cos beta) cos alpha, (2 + cos beta) sin alpha,
 * sin beta).  The strand is the level set q' alpha - p' beta = 0 (mod 2 pi)
 * of the torus; strand k is the level 2 pi k / g, obtained by turning
 * strand 0 by 2 pi k / q about the z axis (q' * 2 pi k / q = 2 pi k / g).
 * (Turning by 2 pi k / p instead would give the level 2 pi k q' / (g p'),
 * which coincides with strand 0 for T(2, 4).)  The g levels are evenly
 * spaced, so the strands are disjoint, and the torus map is injective
 * (major radius 2 > minor radius 1), so each strand is embedded.
 *
 * Sampling needs two things.  Every step must advance both angles by less
 * than pi, or the polygon loses its winding (T(2,3) sampled at 3 vertices
 * is a flat triangle): n >= 2 max(p', q') + 1.  And the chords must stay
 * close to the curve compared with the gap between neighbouring strands:
 * in the flat (alpha, beta) square the strands are parallel lines 2 pi /
 * (g S) apart, S = |(p', q')|, a step is 2 pi S / n long and its chord
 * sags by about step^2 / 8 (the tube has radius 1); sag < gap / 2 gives
 * n > sqrt(pi g S^3 / 2).  We ask for n >= 2 sqrt(g S^3), which a brute
 * force check of every edge pair found embedded, with strands at least
 * 0.37 of that gap apart, for all p, q <= 60 (with sqrt(g S^3) alone
 * T(20, 7) intersects itself). */
static size_t torus_min_vertices(size_t g, size_t pp, size_t qq)
{
    size_t wind = pp > qq ? pp : qq;
    double s2 = (double)pp * (double)pp + (double)qq * (double)qq;
    double need = ceil(2.0 * sqrt((double)g * s2 * sqrt(s2)));
    double lo = 2.0 * (double)wind + 1.0;
    if (need < lo)
        need = lo;
    /* Beyond the limit the caller refuses anyway; keep the value finite. */
    if (need > (double)MAX_TOTAL_VERTICES)
        return MAX_TOTAL_VERTICES + 1;
    return (size_t)need;
}

int tk_generate_torus(int p, int q, size_t vertices, tk_curve **out,
                      tk_error *err)
{
    *out = NULL;
    if (p < 1 || q < 1)
        return tk_error_set(err, TK_EINVAL,
                            "torus T(%d, %d): p and q must be at least 1", p, q);
    size_t g = gcd_size((size_t)p, (size_t)q);
    size_t pp = (size_t)p / g, qq = (size_t)q / g;
    size_t wind = pp > qq ? pp : qq;
    size_t least = torus_min_vertices(g, pp, qq);
    /* About 40 vertices per turn of the faster angle (edges of about a
     * quarter of the tube radius on this torus), never below 60, and with
     * room to spare over the minimum. */
    size_t dflt = wind > MAX_TOTAL_VERTICES / 40 ? MAX_TOTAL_VERTICES + 1 : 40 * wind;
    if (dflt < 60)
        dflt = 60;
    if (least <= MAX_TOTAL_VERTICES && dflt < 2 * least)
        dflt = 2 * least;
    size_t n;
    int rc = check_counts(vertices, dflt, g, &n, err);
    if (rc)
        return rc;
    if (least > MAX_TOTAL_VERTICES)
        return tk_error_set(err, TK_ELIMIT,
                            "torus T(%d, %d) needs more vertices than the limit of %zu",
                            p, q, MAX_TOTAL_VERTICES);
    if (n < least)
        return tk_error_set(err, TK_EINVAL,
                            "torus T(%d, %d) needs at least %zu vertices per component to be embedded (asked for %zu)",
                            p, q, least, n);
    rc = new_closed(g, n, out, err);
    if (rc)
        return rc;
    tk_curve *c = *out;
    for (size_t k = 0; k < g; k++) {
        double ck, sk;
        unit_circle(k, (size_t)q, &ck, &sk);
        for (size_t i = 0; i < n; i++) {
            double ca, sa, cb, sb;
            /* p' i and q' i modulo n, in 64 bits (n <= 10^7, p', q' < 2^31). */
            unit_circle((size_t)((uint64_t)pp * i % n), n, &ca, &sa);
            unit_circle((size_t)((uint64_t)qq * i % n), n, &cb, &sb);
            double r = 2.0 + cb;
            double x = r * ca, y = r * sa;
            double *v = tk_curve_vertex(c, c->offset[k] + i);
            v[0] = ck * x - sk * y + 0.0;
            v[1] = sk * x + ck * y + 0.0;
            v[2] = sb;
        }
    }
    return TK_OK;
}

/* Circle A: radius 1 about the origin in the xy plane, vertex 0 at (1,0,0).
 * Circle B: radius 1 about (1,0,0) in the xz plane, vertex 0 at (2,0,0) and
 * vertex n/2 at the origin, which needs n even; both get the same (even)
 * count so that the link keeps its symmetry swapping the circles. */
int tk_generate_hopf(size_t vertices, tk_curve **out, tk_error *err)
{
    *out = NULL;
    size_t n;
    int rc = check_counts(vertices, 64, 2, &n, err);
    if (rc)
        return rc;
    n += n % 2;
    rc = new_closed(2, n, out, err);
    if (rc)
        return rc;
    tk_curve *c = *out;
    for (size_t i = 0; i < n; i++) {
        double co, si;
        unit_circle(i, n, &co, &si);
        double *a = tk_curve_vertex(c, i);
        a[0] = co;
        a[1] = si;
        a[2] = 0.0;
        double *b = tk_curve_vertex(c, n + i);
        b[0] = 1.0 + co;
        b[1] = 0.0;
        b[2] = si;
    }
    return TK_OK;
}

/* The ellipses x^2/4 + y^2 = 1 (z = 0), y^2/4 + z^2 = 1 (x = 0) and
 * z^2/4 + x^2 = 1 (y = 0), each turned a third of the way round the
 * diagonal from the previous one.  Each pair is unlinked: the second meets
 * the plane of the first at (0, +-2, 0), both outside the first; the
 * three together are the Borromean rings.  Distinct components stay at
 * least sqrt(2/3) apart. */
int tk_generate_borromean(size_t vertices, tk_curve **out, tk_error *err)
{
    *out = NULL;
    size_t n;
    int rc = check_counts(vertices, 96, 3, &n, err);
    if (rc)
        return rc;
    rc = new_closed(3, n, out, err);
    if (rc)
        return rc;
    tk_curve *c = *out;
    for (size_t i = 0; i < n; i++) {
        double co, si;
        unit_circle(i, n, &co, &si);
        double *e0 = tk_curve_vertex(c, i);
        double *e1 = tk_curve_vertex(c, n + i);
        double *e2 = tk_curve_vertex(c, 2 * n + i);
        e0[0] = 2.0 * co; e0[1] = si;       e0[2] = 0.0;
        e1[0] = 0.0;      e1[1] = 2.0 * co; e1[2] = si;
        e2[0] = si;       e2[1] = 0.0;      e2[2] = 2.0 * co;
    }
    return TK_OK;
}

/* Ring i: radius 1 about (1.5 i, 0, 0), in the xy plane for even i and the
 * xz plane for odd i.  Ring i + 1 crosses the plane of ring i at distance
 * 0.5 (inside) and 2.5 (outside) from its centre, so neighbours link once;
 * rings two apart share a plane with centres 3 apart and do not touch. */
int tk_generate_chain(size_t k, size_t vertices, tk_curve **out,
                      tk_error *err)
{
    *out = NULL;
    if (k < 1)
        return tk_error_set(err, TK_EINVAL, "a chain needs at least 1 ring");
    size_t n;
    int rc = check_counts(vertices, 64, k, &n, err);
    if (rc)
        return rc;
    /* Triangles do not link: ring i + 1's edge through the plane of ring i
     * would pass through ring i's vertex at (1.5 i + 1, 0, 0). */
    if (n < 4)
        return tk_error_set(err, TK_EINVAL,
                            "a chain needs at least 4 vertices per ring (asked for %zu)", n);
    rc = new_closed(k, n, out, err);
    if (rc)
        return rc;
    tk_curve *c = *out;
    for (size_t r = 0; r < k; r++) {
        double centre = 1.5 * (double)r;
        for (size_t i = 0; i < n; i++) {
            double co, si;
            unit_circle(i, n, &co, &si);
            double *v = tk_curve_vertex(c, c->offset[r] + i);
            v[0] = centre + co;
            v[1] = r % 2 == 0 ? si : 0.0;
            v[2] = r % 2 == 0 ? 0.0 : si;
        }
    }
    return TK_OK;
}

/* Rope 0 of the clasp at arclength s: down the leg x = -CLASP_R from the
 * plane z = CLASP_H, round the half circle about (0, 0, CLASP_C) in the
 * plane y = 0, up the leg x = CLASP_R.  Rope 1 is its image under
 * (x, 0, z) -> (0, x, -z).  The planes are as near as leaves the legs
 * straight: the measure does not depend on where they are, and vertices
 * on a leg do nothing for it.  At 332 vertices (600 s of processor time)
 * planes at 4 gave 4.26460, at 2.5 4.26353. */
#define CLASP_H 2.5
#define CLASP_R 1.5
#define CLASP_C 0.5

static void clasp_point(double s, double p[3])
{
    double leg = CLASP_H - CLASP_C, arc = M_PI * CLASP_R;
    if (s < leg) {
        p[0] = -CLASP_R;
        p[2] = CLASP_H - s;
    } else if (s < leg + arc) {
        double phi = -M_PI / 2.0 + (s - leg) / CLASP_R;
        p[0] = CLASP_R * sin(phi);
        p[2] = CLASP_C - CLASP_R * cos(phi);
    } else {
        p[0] = CLASP_R;
        p[2] = CLASP_C + (s - leg - arc);
    }
    p[1] = 0.0;
}

int tk_generate_clasp(size_t vertices, tk_curve **out, tk_error *err)
{
    *out = NULL;
    size_t n = vertices ? vertices : 64;
    /* fewer and the half circle's chords cut in toward the other rope */
    if (n < 16)
        return tk_error_set(err, TK_EINVAL,
                            "a clasp needs at least 16 vertices a rope (asked for %zu)", n);
    if (n > MAX_TOTAL_VERTICES / 2)
        return tk_error_set(err, TK_ELIMIT,
                            "2 ropes of %zu vertices exceed the limit of %zu vertices", n,
                            MAX_TOTAL_VERTICES);
    size_t counts[2] = {n, n};
    bool closed[2] = {false, false};
    int rc = tk_curve_new(out, 2, counts, closed, err);
    if (rc)
        return rc;
    tk_curve *c = *out;
    double length = 2.0 * (CLASP_H - CLASP_C) + M_PI * CLASP_R;
    for (size_t i = 0; i < n; i++) {
        /* the last vertex exactly at the end of the second leg */
        double s = i + 1 == n ? length : length * (double)i / (double)(n - 1), p[3];
        clasp_point(s, p);
        double *a = tk_curve_vertex(c, i), *b = tk_curve_vertex(c, n + i);
        memcpy(a, p, sizeof p);
        b[0] = 0.0;
        b[1] = p[0];
        b[2] = -p[2];
    }
    for (size_t comp = 0; comp < 2 && !rc; comp++)
        for (size_t end = 0; end < 2 && !rc; end++) {
            tk_pin pin = {.comp = comp, .vertex = end ? n - 1 : 0, .kind = TK_PIN_PLANE,
                          .normal = {0.0, 0.0, comp ? -1.0 : 1.0}, .offset = CLASP_H};
            rc = tk_curve_pin_add(c, &pin, false, err);
        }
    if (rc)
        tk_curve_free(out);
    return rc;
}

int tk_generate_figure_eight(size_t vertices, tk_curve **out, tk_error *err)
{
    *out = NULL;
    size_t n;
    int rc = check_counts(vertices, 200, 1, &n, err);
    if (rc)
        return rc;
    /* Four turns of the fastest angle (4t): below 2 * 4 + 1 vertices a
     * step passes pi and the polygon loses the curve's winding; at 48
     * vertices a brute force check finds it embedded with room. */
    if (n < 48)
        return tk_error_set(err, TK_EINVAL,
                            "the figure-eight needs at least 48 vertices to be embedded "
                            "(asked for %zu)", n);
    rc = new_closed(1, n, out, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n; i++) {
        double c2, s2, c3, s3, c4, s4;
        unit_circle(2 * i % n, n, &c2, &s2);
        unit_circle(3 * i % n, n, &c3, &s3);
        unit_circle(4 * i % n, n, &c4, &s4);
        double *v = tk_curve_vertex(*out, i);
        v[0] = (2.0 + c2) * c3;
        v[1] = (2.0 + c2) * s3;
        v[2] = s4;
    }
    return TK_OK;
}

/* Whether closed component 0 of c keeps its edges apart: no two edges
 * that share no vertex come closer than `gap` (every pair, brute force). */
static bool edges_apart(const tk_curve *c, double gap)
{
    size_t n = c->nvert;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 2; j < n; j++) {
            if (i == 0 && j == n - 1)
                continue;
            tk_closest cl;
            tk_segment_closest(tk_curve_vertex(c, i), tk_curve_vertex(c, i + 1),
                               tk_curve_vertex(c, j), tk_curve_vertex(c, (j + 1) % n), &cl);
            if (!(cl.dist > gap))
                return false;
        }
    return true;
}

/* edges_apart compares every pair of edges: about 2 s at 10,000 vertices. */
#define LISSAJOUS_MAX_VERTICES 10000

int tk_generate_lissajous(const int freq[3], const double phase[3], size_t vertices,
                          tk_curve **out, tk_error *err)
{
    *out = NULL;
    int fastest = 0;
    for (int k = 0; k < 3; k++) {
        if (freq[k] < 1 || freq[k] > 1000)
            return tk_error_set(err, TK_EINVAL,
                                "a Lissajous frequency must be 1 to 1000 (got %d)", freq[k]);
        if (!isfinite(phase[k]))
            return tk_error_set(err, TK_EINVAL, "a Lissajous phase must be finite");
        if (gcd_size((size_t)freq[k], (size_t)freq[(k + 1) % 3]) != 1)
            return tk_error_set(err, TK_EINVAL,
                                "the Lissajous frequencies %d and %d are not coprime: the "
                                "curve would run over itself",
                                freq[k], freq[(k + 1) % 3]);
        if (freq[k] > fastest)
            fastest = freq[k];
    }
    size_t n;
    int rc = check_counts(vertices, 60 * (size_t)fastest, 1, &n, err);
    if (rc)
        return rc;
    if (n > LISSAJOUS_MAX_VERTICES)
        return tk_error_set(err, TK_ELIMIT,
                            "a Lissajous knot has at most %zu vertices (asked for %zu): "
                            "tighten --vertices resamples it",
                            (size_t)LISSAJOUS_MAX_VERTICES, n);
    if (n < 12 * (size_t)fastest)
        return tk_error_set(err, TK_EINVAL,
                            "this Lissajous knot needs at least %zu vertices (12 a turn of its "
                            "fastest angle; asked for %zu)",
                            12 * (size_t)fastest, n);
    if ((rc = new_closed(1, n, out, err)) != TK_OK)
        return rc;
    for (size_t i = 0; i < n; i++) {
        double *v = tk_curve_vertex(*out, i);
        for (int k = 0; k < 3; k++) {
            double co, si;
            unit_circle((size_t)freq[k] * i % n, n, &co, &si);
            /* cos(a + p) = cos a cos p - sin a sin p */
            v[k] = co * cos(phase[k]) - si * sin(phase[k]) + 0.0;
        }
    }
    /* the curve lies in [-1, 1]^3: a gap below 1e-9 is a crossing */
    if (!edges_apart(*out, 1e-9)) {
        tk_curve_free(out);
        return tk_error_set(err, TK_EINVAL,
                            "the Lissajous curve with phases (%g, %g, %g) passes through itself",
                            phase[0], phase[1], phase[2]);
    }
    return TK_OK;
}

/* Where arclength s lies on component comp of c (s in [0, its length)). */
static void point_at(const tk_curve *c, size_t comp, double s, double p[3])
{
    size_t edges = tk_curve_comp_edges(c, comp);
    for (size_t e = 0; e < edges; e++) {
        double len = tk_curve_edge_length(c, comp, e);
        if (s <= len || e + 1 == edges) {
            const double *a = tk_curve_vertex(c, tk_curve_vertex_index(c, comp, e));
            const double *b = tk_curve_vertex(c, tk_curve_vertex_index(c, comp, e + 1));
            double t = len > 0.0 ? fmin(1.0, fmax(0.0, s / len)) : 0.0;
            for (int d = 0; d < 3; d++)
                p[d] = a[d] + t * (b[d] - a[d]);
            return;
        }
        s -= len;
    }
}

int tk_generate_disguise(const tk_curve *src, unsigned long long seed, double perturbation,
                         tk_curve **out, tk_error *err)
{
    *out = NULL;
    if (!(perturbation >= 0.0 && perturbation <= 1.0))
        return tk_error_set(err, TK_EINVAL, "the perturbation must be in [0, 1] (got %g)",
                            perturbation);
    int rc = tk_curve_validate(src, err);
    if (!rc)
        rc = tk_curve_copy(src, out, err);
    if (rc)
        return rc;
    tk_curve *c = *out;
    uint64_t state = seed;
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        size_t n = tk_curve_comp_vertices(c, comp);
        size_t edges = tk_curve_comp_edges(c, comp);
        double length = tk_curve_comp_length(src, comp);
        double mean_edge = length / (double)edges;
        double phase = 2.0 * M_PI * tk_rng_uniform(&state);
        /* s(u) = L (u + 0.3 (sin(2 pi u + phase) - sin(phase)) / (2 pi))
         * is increasing (its slope is L (1 + 0.3 cos) > 0) from s(0) = 0 to
         * s(1) = L, so an open component keeps its ends. */
        for (size_t k = 0; k < n; k++) {
            double u = (double)k / (double)edges;
            double s = length * (u + 0.3 * (sin(2.0 * M_PI * u + phase) - sin(phase)) /
                                         (2.0 * M_PI));
            if (!c->closed[comp] && k + 1 == n)
                s = length;
            point_at(src, comp, s, tk_curve_vertex(c, c->offset[comp] + k));
        }
        for (size_t k = 0; k < n; k++) {
            if (!c->closed[comp] && (k == 0 || k + 1 == n))
                continue;
            double *v = tk_curve_vertex(c, c->offset[comp] + k);
            for (int d = 0; d < 3; d++)
                v[d] += perturbation * mean_edge * tk_rng_normal(&state);
        }
    }
    /* A uniformly random rotation: a unit quaternion with normal
     * coordinates. */
    double q[4], norm = 0.0;
    for (int d = 0; d < 4; d++) {
        q[d] = tk_rng_normal(&state);
        norm += q[d] * q[d];
    }
    norm = sqrt(norm);
    for (int d = 0; d < 4; d++)
        q[d] /= norm;
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double rot[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                     2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    tk_curve_rotate(c, rot);
    return tk_curve_validate(c, err);
}

void tk_generate_fourier(tk_curve *c, const tk_curve *from, const double *coef, int modes,
                         double amplitude)
{
    memcpy(c->xyz, from->xyz, 3 * from->nvert * sizeof *c->xyz);
    for (size_t comp = 0; comp < c->ncomp; comp++) {
        const double *a = coef + comp * (size_t)modes * 6;
        size_t n = tk_curve_comp_vertices(c, comp);
        double length = tk_curve_comp_length(from, comp), s = 0.0;
        for (size_t i = 0; i < n; i++) {
            double phase = 2.0 * M_PI * s / length;
            double *v = tk_curve_vertex(c, c->offset[comp] + i);
            bool end = !c->closed[comp] && (i == 0 || i + 1 == n);
            for (int k = 1; k <= modes && !end; k++)
                for (int d = 0; d < 3; d++)
                    v[d] += amplitude / k *
                            (a[(k - 1) * 6 + d] * cos(k * phase) +
                             a[(k - 1) * 6 + 3 + d] * sin(k * phase));
            if (i + 1 < n)
                s += tk_curve_edge_length(from, comp, i);
        }
    }
}

int tk_generate_deform(const tk_curve *src, unsigned long long seed, double keep,
                       tk_curve **out, tk_error *err)
{
    *out = NULL;
    if (!(keep > 0.0 && keep <= 1.0))
        return tk_error_set(err, TK_EINVAL, "the thickness kept must be in (0, 1] (got %g)", keep);
    tk_measure m;
    tk_invariants type = TK_INVARIANTS_INIT, now = TK_INVARIANTS_INIT;
    size_t ncoef = src->ncomp * TK_DEFORM_MODES * 6;
    double *coef = malloc(ncoef * sizeof *coef);
    int rc = coef ? tk_curve_validate(src, err) : tk_error_set(err, TK_ENOMEM, "out of memory");
    if (!rc)
        rc = tk_thickness_measure(src, NULL, &m, err);
    if (!rc)
        rc = tk_invariants_compute(src, &type, err);
    if (!rc)
        rc = tk_curve_copy(src, out, err);
    uint64_t state = seed;
    double radius = 0.0;
    for (size_t i = 0; !rc && i < ncoef; i++)
        coef[i] = tk_rng_normal(&state);
    for (size_t comp = 0; !rc && comp < src->ncomp; comp++)
        radius += tk_curve_comp_length(src, comp) / (2.0 * M_PI) / (double)src->ncomp;
    bool found = false;
    for (double a = radius; !rc && !found && a >= 1e-6 * radius; a *= 0.7) {
        tk_generate_fourier(*out, src, coef, TK_DEFORM_MODES, a);
        tk_measure d;
        tk_error why;
        found = tk_thickness_measure(*out, NULL, &d, &why) == TK_OK &&
                d.thickness >= keep * m.thickness &&
                tk_invariants_compute(*out, &now, &why) == TK_OK &&
                tk_invariants_compare(&type, &now, &why) == TK_OK;
        tk_invariants_free(&now);
        /* and on the way: the invariants cannot tell every link apart */
        if (found)
            rc = tk_struts_path_embedded(src, *out, &found, err);
    }
    if (!rc && !found)
        rc = tk_error_set(err, TK_ENUMERIC, "no deformation of seed %llu keeps the type and "
                          "%g of the thickness", seed, keep);
    free(coef);
    tk_invariants_free(&type);
    if (rc)
        tk_curve_free(out);
    return rc;
}
