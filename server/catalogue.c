/* tightknot service: the bundled catalogue, the *.vect files of a
 * directory offered by name (see http.h). */
#define _GNU_SOURCE
#include "http.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tk/vect.h"

typedef struct entry {
    char *name; /* the file's name without .vect */
    size_t components, vertices;
} entry;

struct catalogue {
    entry *entries; /* sorted by name */
    size_t n;
};

static int by_name(const void *x, const void *y)
{
    return strcmp(((const entry *)x)->name, ((const entry *)y)->name);
}

/* The entry called name, or NULL. */
static const entry *find(const catalogue *cat, const char *name)
{
    entry key = {.name = (char *)name};
    return cat ? bsearch(&key, cat->entries, cat->n, sizeof key, by_name) : NULL;
}

static char *read_text(const char *dir, const char *name, size_t *len)
{
    char *path = NULL;
    char *text = asprintf(&path, "%s/%s.vect", dir, name) < 0 ? NULL : slurp(path, len);
    free(path);
    return text;
}

/* A file that does not parse is left out. */
catalogue *tk_catalogue_load(const char *dir)
{
    catalogue *cat = calloc(1, sizeof *cat);
    DIR *d = cat ? opendir(dir) : NULL;
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        size_t n = strlen(e->d_name), len = 0;
        if (n < 6 || strcmp(e->d_name + n - 5, ".vect") || e->d_name[0] == '.')
            continue;
        char *name = strndup(e->d_name, n - 5);
        char *text = name ? read_text(dir, name, &len) : NULL;
        tk_curve *curve = NULL;
        entry *grown = text && !tk_vect_parse(text, len, NULL, &curve, NULL)
                           ? realloc(cat->entries, (cat->n + 1) * sizeof *grown)
                           : NULL;
        if (grown) {
            cat->entries = grown;
            cat->entries[cat->n++] = (entry){name, curve->ncomp, curve->nvert};
        } else {
            free(name);
        }
        tk_curve_free(&curve);
        free(text);
    }
    if (d)
        closedir(d);
    if (cat && cat->entries)
        qsort(cat->entries, cat->n, sizeof *cat->entries, by_name);
    if (cat && !cat->n)
        tk_catalogue_free(&cat);
    return cat;
}

void tk_catalogue_free(catalogue **p)
{
    if (!p || !*p)
        return;
    for (size_t i = 0; i < (*p)->n; i++)
        free((*p)->entries[i].name);
    free((*p)->entries);
    free(*p);
    *p = NULL;
}

size_t tk_catalogue_size(const catalogue *cat)
{
    return cat ? cat->n : 0;
}

char *tk_catalogue_text(const catalogue *cat, const char *dir, const char *name, size_t *len)
{
    return find(cat, name) ? read_text(dir, name, len) : NULL;
}

result tk_list_catalogue(tk_api *a, conn *c, const call *k)
{
    (void)k;
    if (!a->cfg.catalogue)
        return PROBLEM(a, c, 404, "this server has no catalogue (start it with --catalogue)");
    json_t *list = json_array();
    for (size_t i = 0; i < tk_catalogue_size(a->catalogue); i++) {
        const entry *e = &a->catalogue->entries[i];
        json_array_append_new(list, json_pack("{s:s, s:I, s:I}", "name", e->name, "components",
                                              (json_int_t)e->components, "vertices",
                                              (json_int_t)e->vertices));
    }
    return send_json(a, c, 200, json_pack("{s:I, s:o}", "count",
                                          (json_int_t)tk_catalogue_size(a->catalogue), "knots",
                                          list), NULL, NULL);
}

result tk_get_catalogue(tk_api *a, conn *c, const call *k)
{
    if (!a->cfg.catalogue)
        return PROBLEM(a, c, 404, "this server has no catalogue (start it with --catalogue)");
    const entry *e = find(a->catalogue, k->arg);
    if (!e)
        return PROBLEM(a, c, 404, "the catalogue has no knot '%.80s'", k->arg);
    size_t len = 0;
    char *text = read_text(a->cfg.catalogue, e->name, &len);
    json_t *o = text ? json_pack("{s:s, s:I, s:I, s:s%}", "name", e->name, "components",
                                 (json_int_t)e->components, "vertices", (json_int_t)e->vertices,
                                 "vect", text, len) : NULL;
    free(text);
    if (!o)
        return PROBLEM(a, c, 500, "the catalogue file '%.80s' cannot be read as text", k->arg);
    return send_json(a, c, 200, o, NULL, NULL);
}
