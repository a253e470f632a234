/* tightknot: a directory of VECT files offered by name ("3.1" for
 * 3.1.vect), read once at start-up so that listing it costs nothing. */
#ifndef TK_CATALOGUE_H
#define TK_CATALOGUE_H

#include <stddef.h>

#include "tk/error.h"

typedef struct tk_catalogue_entry {
    char *name;        /* file name without .vect */
    size_t components;
    size_t vertices;
    size_t bytes;
} tk_catalogue_entry;

typedef struct tk_catalogue tk_catalogue;

/* Reads every *.vect in dir (files that do not parse are left out and
 * counted in *skipped when it is not NULL). */
int tk_catalogue_open(const char *dir, tk_catalogue **out, size_t *skipped, tk_error *err);
void tk_catalogue_free(tk_catalogue **p);

/* Entries sorted by name. */
const tk_catalogue_entry *tk_catalogue_entries(const tk_catalogue *c, size_t *count);

/* The entry called name, or NULL. */
const tk_catalogue_entry *tk_catalogue_find(const tk_catalogue *c, const char *name);

/* The file's text (NUL-terminated; free with free()). */
int tk_catalogue_read(const tk_catalogue *c, const char *name, char **text, size_t *len,
                      tk_error *err);

#endif
