/* tightknot: what a POST /v1/jobs asks for, decoded without HTTP and
 * without the engine.
 *
 * The body is JSON ({"vect": ...} or {"catalogue": ...}, with an optional
 * name and options) or a raw VECT as text/plain with the name and the
 * options in the query.  Decoding checks the media type, the JSON, the
 * fields, the name and the options, and fetches a catalogue entry's text;
 * it does not read the VECT (the caller parses it, so that its errors name
 * their line).  Re-entrant; nothing shared.
 */
#ifndef TK_SUBMISSION_H
#define TK_SUBMISSION_H

#include <stddef.h>

#include "tk/catalogue.h"
#include "tk/jobspec.h"
#include "tk/store.h"

/* A query parameter as received (value NULL when it had no '='). */
typedef struct tk_query_pair {
    const char *key;
    const char *value;
} tk_query_pair;

typedef struct tk_submission {
    char name[TK_JOB_NAME_SIZE];
    tk_job_options options;
    char *vect;      /* the VECT text, owned (free with tk_submission_clear) */
    size_t len;      /* its length in bytes (it may hold anything) */
} tk_submission;

/* Why a submission is refused: the HTTP status (400 bad JSON, 415 wrong
 * media type, 422 a field, name or option out of its domain), the detail,
 * and the member that names the culprit ("field", "option" or
 * "parameter"; "" when none) with its value.  status 0 with code set is a
 * fault of ours (out of memory, a catalogue file unreadable). */
typedef struct tk_submission_problem {
    unsigned status;
    int code;
    char detail[512];
    char member[16];
    char value[64];
} tk_submission_problem;

/* Decodes a submission.  content_type may be NULL (no header); query has
 * nquery pairs; body has len bytes (not NUL-terminated); catalogue may be
 * NULL (then {"catalogue": ...} is refused).  Returns TK_OK with *out
 * filled, or an error code with *problem filled and *out empty. */
int tk_submission_decode(const char *content_type, const tk_query_pair *query, size_t nquery,
                         const char *body, size_t len, const tk_catalogue *catalogue,
                         tk_submission *out, tk_submission_problem *problem);

void tk_submission_clear(tk_submission *s);

#endif
