/* tightknot: Geomview VECT reading and writing.
 *
 * Format: a `VECT` header line, then `ncomponents nvertices ncolours`, one
 * vertex count per component (negative = closed), one colour count per
 * component, the vertices (x y z), the colours (r g b a).  `#` starts a
 * comment that runs to the end of the line; tokens may be separated by any
 * whitespace, so counts and coordinates may wrap across lines.
 *
 * The reader never trusts a count: every count is checked against the
 * limits and against the text that is actually there before anything is
 * allocated from it.  Errors name the 1-based line and what was expected.
 */
#ifndef TK_VECT_H
#define TK_VECT_H

#include <stddef.h>
#include <stdio.h>

#include "tk/curve.h"
#include "tk/error.h"

typedef struct tk_vect_limits {
    size_t max_components; /* default 10000 */
    size_t max_vertices;   /* total, default 10000000 */
} tk_vect_limits;

#define TK_VECT_LIMITS_INIT {10000, 10000000}

/* Parses VECT text of len bytes (need not be NUL-terminated).  limits may be
 * NULL for the defaults.  On success *out is a validated curve (see
 * tk_curve_validate); on failure *out is NULL and err says where and why
 * (TK_EPARSE, TK_ELIMIT or TK_ENOMEM). */
int tk_vect_parse(const char *text, size_t len, const tk_vect_limits *limits,
                  tk_curve **out, tk_error *err);

/* Reads and parses a file (message prefixed with the path); "-" reads
 * standard input. */
int tk_vect_read_file(const char *path, const tk_vect_limits *limits,
                      tk_curve **out, tk_error *err);

/* Writes a curve as VECT with full double precision (%.17g), so that
 * parsing the text gives back the same coordinates bit for bit.  Writes one
 * colour per component when the curve has colours. */
int tk_vect_write(const tk_curve *c, FILE *f, tk_error *err);

/* The same text in a new NUL-terminated buffer (free with free()). */
int tk_vect_to_string(const tk_curve *c, char **out, size_t *len,
                      tk_error *err);

#endif
