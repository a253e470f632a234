/* tightknot service: what a run leaves in the store and reads back: its
 * parts (store.h) and its frames' layout. */
#ifndef TK_SERVER_RECORD_H
#define TK_SERVER_RECORD_H

#include "store.h"
#include "tk/tighten.h"

/* The run's parts as stored (not its input): its curve, contacts, resume
 * point, and history (`before` a resume and the run's own, thinned to
 * `keep`).  Free each with free(). */
int tk_record_parts(const tk_run *run, const json_t *before, size_t keep,
                    char *parts[TK_PARTS], tk_error *err);

/* The history as stored (tk_record_parts). */
char *tk_record_history(const tk_run *run, const json_t *before, size_t keep);

/* A stored history's entries before the resume step (which the run
 * reports again). */
json_t *tk_record_history_before(const char *text, long resume);

/* A stored curve (TK_PART_INPUT or TK_PART_CURVE) within max_vertices. */
int tk_record_curve(tk_store *s, int64_t id, tk_part part, size_t max_vertices, tk_curve **out,
                    tk_error *err);

/* A run from the job's stored curve and resume point (without one: from
 * its curve at its step).  TK_ETYPE: the curve's type, into *refused, is
 * not the input's. */
int tk_record_resume(tk_store *s, const json_t *doc, const tk_options *o, size_t max_vertices,
                     const tk_invariants *input, tk_invariants *refused, tk_run **run,
                     tk_error *err);

/* A frame's layout as stored: its vertices per component, a JSON array. */
char *tk_record_layout(const tk_curve *c);

/* A frame's components as served ([{vertices, closed}]): the layout's
 * counts (unless NULL or of another length: the curve's), the curve's
 * closedness. */
json_t *tk_record_components(const tk_curve *c, const json_t *counts);

#endif
