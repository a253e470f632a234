/* Tightening benchmark: catalogue knots and links at resolution 5 (kept
 * as they tighten: re-resolved whenever the ropelength fell by 5%, see
 * tk_options.re_resolve; both from a coarse start, see
 * tk_options.coarse_to_fine), each run for a fixed wall time, printing
 * vertices, steps per second, the time to reach given ropelengths, the
 * ropelength after 10 s, 60 s and the full time (of the polygon the run is
 * on then), the final residual and the peak memory; then seconds per step
 * against vertex count on the trefoil.  Prints figures; never fails on
 * time.
 *
 *   bench/tighten [CATALOGUE_DIR] [--seconds S] [--re-resolve F]
 *                 [--scaling-steps N] [KNOT ...]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "tk/curve.h"
#include "tk/thickness.h"
#include "tk/tighten.h"
#include "tk/vect.h"

static double peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

/* Ropelength thresholds whose crossing times are reported, per knot (the
 * published comparison figures), and the lowest ropelength seen at the
 * checkpoints. */
typedef struct progress {
    double thresholds[3];
    double older[3];         /* the older program's seconds; 0: a target */
    size_t nthresholds;
    double crossed[3];
    double checkpoints[3];  /* seconds */
    double at_checkpoint[3];
} progress;

static int on_step(const tk_step_report *s, void *user)
{
    progress *p = user;
    for (size_t k = 0; k < p->nthresholds; k++)
        if (p->crossed[k] < 0 && s->ropelength <= p->thresholds[k])
            p->crossed[k] = s->seconds;
    for (int k = 0; k < 3; k++)
        if (s->seconds <= p->checkpoints[k])
            p->at_checkpoint[k] = s->ropelength;
    return 0;
}

static tk_curve *load(const char *dir, const char *name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.vect", dir, name);
    tk_curve *c = NULL;
    tk_error err;
    if (tk_vect_read_file(path, NULL, &c, &err) != TK_OK) {
        fprintf(stderr, "bench: %s\n", err.message);
        return NULL;
    }
    return c;
}

static void run_knot(const char *dir, const char *name, double seconds, double re_resolve)
{
    /* The published figures of the older program on this machine from
     * the same files at the same resolution: a ropelength and the seconds
     * it took to reach it, and the targets below them. */
    static const struct {
        const char *knot;
        double ropelength[3], older_seconds[3];
    } known[] = {
        {"3.1", {33.0, 32.80, 32.7689}, {8.2, 12, 385}},
        {"2.2.1", {25.15, 25.1483, 0}, {7.5, 175, 0}},
        {"4.1", {44.73, 42.5, 0}, {354, 0, 0}},
        {"5.1", {47.234, 0, 0}, {369, 0, 0}},
        {"6.3.2", {75.03, 58.6, 0}, {340, 0, 0}},
        {"10.1", {103.04, 0, 0}, {357, 0, 0}},
    };
    progress p = {{0}, {0}, 0, {-1, -1, -1}, {10, 60, seconds}, {NAN, NAN, NAN}};
    for (size_t k = 0; k < sizeof known / sizeof known[0]; k++)
        if (strcmp(name, known[k].knot) == 0)
            for (int t = 0; t < 3 && known[k].ropelength[t] > 0; t++) {
                p.thresholds[t] = known[k].ropelength[t];
                p.older[t] = known[k].older_seconds[t];
                p.nthresholds++;
            }
    tk_curve *c = load(dir, name);
    if (!c)
        return;
    tk_options o = TK_OPTIONS_INIT;
    o.autoscale = true;
    o.resolution = 5;
    o.max_seconds = seconds;
    o.re_resolve = re_resolve;
    tk_run *run = NULL;
    tk_error err;
    if (tk_run_new(c, &o, &run, &err) != TK_OK) {
        fprintf(stderr, "bench: %s: %s\n", name, err.message);
        tk_curve_free(&c);
        return;
    }
    tk_run_set_progress(run, on_step, &p);
    tk_stop_reason why;
    int rc = tk_run_until(run, &why, &err);
    const tk_step_report *last = tk_run_latest(run);
    /* At a fixed count (no re-resolution) a run starts coarse (fewer
     * vertices, tk_options.coarse_to_fine): the thresholds count on the
     * final polygon only, reached from when it took over. */
    char fine[48] = "";
    if (!(re_resolve > 0.0)) {
        size_t nh = 0;
        const tk_step_report *h = tk_run_history(run, &nh);
        for (size_t k = 0; k < p.nthresholds; k++)
            p.crossed[k] = -1.0;
        double from = -1.0;
        for (size_t i = 0; i < nh; i++) {
            if (h[i].vertices != last->vertices)
                continue;
            if (from < 0.0)
                from = h[i].seconds;
            for (size_t k = 0; k < p.nthresholds; k++)
                if (p.crossed[k] < 0 && h[i].ropelength <= p.thresholds[k])
                    p.crossed[k] = h[i].seconds;
        }
        if (from > 0.0)
            snprintf(fine, sizeof fine, " final polygon from %.2fs;", from);
    }
    char crossed[256] = "";
    size_t used = 0;
    for (size_t k = 0; k < p.nthresholds; k++) {
        int n;
        char when[32], older[32] = "";
        if (p.crossed[k] >= 0)
            snprintf(when, sizeof when, "%.2fs", p.crossed[k]);
        else
            snprintf(when, sizeof when, "never");
        if (p.older[k] > 0)
            snprintf(older, sizeof older, "(older %gs)", p.older[k]);
        n = snprintf(crossed + used, sizeof crossed - used, "%s<=%g@%s%s", k ? " " : "",
                     p.thresholds[k], when, older);
        if (n > 0 && (size_t)n < sizeof crossed - used)
            used += (size_t)n;
    }
    /* a run that stopped before a checkpoint has no figure there */
    char at[2][16];
    for (int k = 0; k < 2; k++) {
        if (last->seconds >= p.checkpoints[k])
            snprintf(at[k], sizeof at[k], "%.5f", p.at_checkpoint[k]);
        else
            snprintf(at[k], sizeof at[k], "-");
    }
    printf("%-7s %8zu %8ld %9.1f %10s %10s %10.5f %10.3g %8.1f %s %s (%s)%s%s\n", name,
           last->vertices, last->step, (double)last->step / fmax(last->seconds, 1e-9), at[0],
           at[1], last->ropelength, last->residual, peak_mib(), fine, crossed,
           tk_stop_reason_name(why), rc ? "  FAILED: " : "", rc ? err.message : "");
    fflush(stdout);
    tk_run_free(&run);
    tk_curve_free(&c);
}

/* Seconds per step on the trefoil resampled to growing vertex counts
 * (the first steps, where contacts are few). */
static void scaling(const char *dir, long steps)
{
    tk_curve *c = load(dir, "3.1");
    if (!c)
        return;
    printf("\nseconds per step, trefoil, first %ld steps:\n%8s %12s %8s\n", steps, "vertices",
           "ms/step", "struts");
    for (size_t v = 184; v <= 12000; v *= 2) {
        tk_curve *big = NULL;
        tk_error err;
        if (tk_curve_resample_total(c, v, &big, &err) != TK_OK)
            break;
        tk_options o = TK_OPTIONS_INIT;
        o.autoscale = true;
        o.max_steps = steps;
        tk_run *run = NULL;
        if (tk_run_new(big, &o, &run, &err) == TK_OK) {
            tk_run_until(run, NULL, &err);
            const tk_step_report *last = tk_run_latest(run);
            printf("%8zu %12.3f %8zu\n", v, 1e3 * last->seconds / (double)last->step,
                   last->struts);
            fflush(stdout);
        }
        tk_run_free(&run);
        tk_curve_free(&big);
    }
    tk_curve_free(&c);
}

int main(int argc, char **argv)
{
    const char *dir = "../shared/catalogue";
    double seconds = 300.0, re_resolve = 0.05;
    long scaling_steps = 20;
    const char *knots[16];
    size_t nknots = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            printf("usage: tighten [CATALOGUE_DIR] [--seconds S] [--re-resolve F]\n"
                   "               [--scaling-steps N] [KNOT ...]\n"
                   "Tightens catalogue knots at resolution 5 for S seconds each (default 300),\n"
                   "re-resolving whenever the ropelength fell by the fraction F (default\n"
                   "0.05; 0: never), and prints figures; then seconds per step against\n"
                   "vertex count.\n");
            return 0;
        } else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
            seconds = strtod(argv[++i], NULL);
        } else if (strcmp(argv[i], "--re-resolve") == 0 && i + 1 < argc) {
            re_resolve = strtod(argv[++i], NULL);
        } else if (strcmp(argv[i], "--scaling-steps") == 0 && i + 1 < argc) {
            scaling_steps = strtol(argv[++i], NULL, 10);
        } else if (strchr(argv[i], '/') || strcmp(argv[i], ".") == 0) {
            dir = argv[i];
        } else if (nknots < 16) {
            knots[nknots++] = argv[i];
        }
    }
    if (nknots == 0) {
        const char *all[] = {"3.1", "4.1", "5.1", "2.2.1", "6.3.2", "10.1"};
        for (size_t k = 0; k < 6; k++)
            knots[nknots++] = all[k];
    }
    printf("tightening at resolution 5 (re-resolved every %.0f%% of ropelength), %.0f s each; "
           "ropelength after 10 s, 60 s and at the end\n\n", 100.0 * re_resolve, seconds);
    printf("%-7s %8s %8s %9s %10s %10s %10s %10s %8s  %s\n", "knot", "vertices", "steps",
           "steps/s", "rope@10s", "rope@60s", "rope@end", "residual", "peak_MiB",
           "thresholds");
    for (size_t k = 0; k < nknots; k++)
        run_knot(dir, knots[k], seconds, re_resolve);
    if (scaling_steps > 0)
        scaling(dir, scaling_steps);
    return 0;
}
