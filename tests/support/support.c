#include "support.h"

#include <check.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "tk/vect.h"

const char *tkt_catalogue_dir(void)
{
    const char *dir = getenv("TK_CATALOGUE");
    if (!dir || !*dir)
        dir = "../shared/catalogue";
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return NULL;
    return dir;
}

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

char **tkt_catalogue_names(size_t *count)
{
    *count = 0;
    const char *dir = tkt_catalogue_dir();
    if (!dir)
        return NULL;
    DIR *d = opendir(dir);
    if (!d)
        return NULL;
    size_t cap = 512, n = 0;
    char **names = malloc(cap * sizeof *names);
    struct dirent *ent;
    while (names && (ent = readdir(d)) != NULL) {
        size_t len = strlen(ent->d_name);
        if (len < 6 || strcmp(ent->d_name + len - 5, ".vect") != 0)
            continue;
        if (n == cap) {
            cap *= 2;
            char **grown = realloc(names, cap * sizeof *names);
            if (!grown)
                break;
            names = grown;
        }
        names[n++] = strdup(ent->d_name);
    }
    closedir(d);
    if (names)
        qsort(names, n, sizeof *names, compare_names);
    *count = n;
    return names;
}

void tkt_free_names(char **names, size_t count)
{
    for (size_t i = 0; i < count; i++)
        free(names[i]);
    free(names);
}

tk_curve *tkt_catalogue_curve(const char *name)
{
    const char *dir = tkt_catalogue_dir();
    ck_assert_msg(dir != NULL, "catalogue absent");
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    tk_curve *c = NULL;
    tk_error err;
    int rc = tk_vect_read_file(path, NULL, &c, &err);
    ck_assert_msg(rc == TK_OK, "reading %s: %s", path, err.message);
    return c;
}

uint64_t tkt_rng_next(tkt_rng *r)
{
    uint64_t z = (r->state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double tkt_rng_uniform(tkt_rng *r)
{
    return (double)(tkt_rng_next(r) >> 11) * 0x1.0p-53;
}

double tkt_rng_range(tkt_rng *r, double lo, double hi)
{
    return lo + (hi - lo) * tkt_rng_uniform(r);
}

void tkt_rng_point(tkt_rng *r, double scale, double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = tkt_rng_range(r, -scale, scale);
}

tk_curve *tkt_regular_polygon(size_t n, double radius)
{
    tk_curve *c = NULL;
    bool closed = true;
    ck_assert_int_eq(tk_curve_new(&c, 1, &n, &closed, NULL), TK_OK);
    for (size_t k = 0; k < n; k++) {
        double a = 2.0 * M_PI * (double)k / (double)n;
        c->xyz[3 * k] = radius * cos(a);
        c->xyz[3 * k + 1] = radius * sin(a);
        c->xyz[3 * k + 2] = 0.0;
    }
    return c;
}

double tkt_reldiff(double a, double b)
{
    double m = fmax(fmax(fabs(a), fabs(b)), 1e-300);
    return fabs(a - b) / m;
}

double tkt_point_segment(const double *x, const double *b0, const double *b1)
{
    double d[3], r[3], dd = 0, rd = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = b1[k] - b0[k];
        r[k] = x[k] - b0[k];
        dd += d[k] * d[k];
        rd += r[k] * d[k];
    }
    double t = dd > 0 ? fmin(1, fmax(0, rd / dd)) : 0;
    double s2 = 0;
    for (int k = 0; k < 3; k++)
        s2 += (r[k] - t * d[k]) * (r[k] - t * d[k]);
    return sqrt(s2);
}

bool tkt_skip(const char *test, const char *why)
{
    printf("SKIP %s: %s\n", test, why);
    fflush(stdout);
    return true;
}

int tkt_run_suite(Suite *s)
{
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
