/* tightknot: the catalogue directory (see include/tk/catalogue.h). */
#include "tk/catalogue.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "tk/vect.h"

struct tk_catalogue {
    char *dir;
    tk_catalogue_entry *entries;
    size_t count;
};

static int by_name(const void *a, const void *b)
{
    return strcmp(((const tk_catalogue_entry *)a)->name, ((const tk_catalogue_entry *)b)->name);
}

static char *join(const char *dir, const char *file)
{
    size_t n = strlen(dir) + strlen(file) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s/%s", dir, file);
    return p;
}

static int read_whole(const char *path, char **text, size_t *len, tk_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return tk_error_set(err, TK_EIO, "cannot open %s: %s", path, strerror(errno));
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int rc = TK_OK;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 16384;
            char *grown = realloc(buf, cap);
            if (!grown) {
                rc = tk_error_set(err, TK_ENOMEM, "out of memory reading %s", path);
                break;
            }
            buf = grown;
        }
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0) {
            if (ferror(f))
                rc = tk_error_set(err, TK_EIO, "reading %s failed", path);
            break;
        }
    }
    fclose(f);
    if (rc) {
        free(buf);
        return rc;
    }
    buf[n] = '\0';
    *text = buf;
    if (len)
        *len = n;
    return TK_OK;
}

int tk_catalogue_open(const char *dir, tk_catalogue **out, size_t *skipped, tk_error *err)
{
    *out = NULL;
    if (skipped)
        *skipped = 0;
    DIR *d = opendir(dir);
    if (!d)
        return tk_error_set(err, TK_EIO, "cannot read the catalogue %s: %s", dir,
                            strerror(errno));
    tk_catalogue *c = calloc(1, sizeof *c);
    int rc = c && (c->dir = strdup(dir)) ? TK_OK : tk_error_set(err, TK_ENOMEM, "out of memory");
    size_t cap = 0;
    struct dirent *e;
    while (!rc && (e = readdir(d)) != NULL) {
        size_t n = strlen(e->d_name);
        if (n <= 5 || strcmp(e->d_name + n - 5, ".vect") != 0 || e->d_name[0] == '.')
            continue;
        char *path = join(dir, e->d_name);
        char *text = NULL;
        size_t len = 0;
        tk_curve *curve = NULL;
        if (!path || read_whole(path, &text, &len, NULL) != TK_OK ||
            tk_vect_parse(text, len, NULL, &curve, NULL) != TK_OK) {
            if (skipped)
                (*skipped)++;
            free(path);
            free(text);
            continue;
        }
        if (c->count == cap) {
            cap = cap ? 2 * cap : 256;
            tk_catalogue_entry *grown = realloc(c->entries, cap * sizeof *grown);
            if (!grown)
                rc = tk_error_set(err, TK_ENOMEM, "out of memory");
            else
                c->entries = grown;
        }
        if (!rc) {
            tk_catalogue_entry *entry = &c->entries[c->count];
            entry->name = strndup(e->d_name, n - 5);
            entry->components = curve->ncomp;
            entry->vertices = curve->nvert;
            entry->bytes = len;
            if (entry->name)
                c->count++;
            else
                rc = tk_error_set(err, TK_ENOMEM, "out of memory");
        }
        tk_curve_free(&curve);
        free(path);
        free(text);
    }
    closedir(d);
    if (rc) {
        tk_catalogue_free(&c);
        return rc;
    }
    qsort(c->entries, c->count, sizeof *c->entries, by_name);
    *out = c;
    return TK_OK;
}

void tk_catalogue_free(tk_catalogue **p)
{
    if (!p || !*p)
        return;
    for (size_t i = 0; i < (*p)->count; i++)
        free((*p)->entries[i].name);
    free((*p)->entries);
    free((*p)->dir);
    free(*p);
    *p = NULL;
}

const tk_catalogue_entry *tk_catalogue_entries(const tk_catalogue *c, size_t *count)
{
    *count = c->count;
    return c->entries;
}

const tk_catalogue_entry *tk_catalogue_find(const tk_catalogue *c, const char *name)
{
    tk_catalogue_entry key = {(char *)name, 0, 0, 0};
    return bsearch(&key, c->entries, c->count, sizeof key, by_name);
}

int tk_catalogue_read(const tk_catalogue *c, const char *name, char **text, size_t *len,
                      tk_error *err)
{
    /* only names listed at start-up: a name never becomes a path of its own */
    const tk_catalogue_entry *e = tk_catalogue_find(c, name);
    if (!e)
        return tk_error_set(err, TK_ENOTFOUND, "the catalogue has no knot '%.80s'", name);
    size_t n = strlen(e->name) + 6;
    char *file = malloc(n);
    if (!file)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    snprintf(file, n, "%s.vect", e->name);
    char *path = join(c->dir, file);
    free(file);
    if (!path)
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    int rc = read_whole(path, text, len, err);
    free(path);
    return rc;
}
