/* tightknot service: the job store, behind a narrow interface.
 *
 * A job is a row of a few fixed columns: its id, its state (the queue is
 * the store: claiming takes the oldest queued job), its document
 * (job.h) and its large parts as text, and its frames in a table of their
 * own.  This backend is one SQLite file in WAL mode, each thread on a
 * connection of its own, so a reader never waits for a writer.
 */
#ifndef TK_SERVER_STORE_H
#define TK_SERVER_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "job.h"

typedef enum tk_part {
    TK_PART_INPUT,    /* the VECT as submitted */
    TK_PART_CURVE,    /* the latest curve as VECT (NULL before the run) */
    TK_PART_CONTACTS, /* struts and kinks (tk_json_contacts) */
    TK_PART_HISTORY,  /* the decimated step figures, a JSON array */
    TK_PART_RESUME,   /* {"at", "best", "best_report"}: where the run resumes */
    TK_PARTS
} tk_part;

/* A frame: its step, the curve's coordinates and its vertices per
 * component as a JSON array (NULL: those of the job's curve). */
typedef struct tk_frame {
    long step;
    double *xyz;
    size_t count;
    char *layout;
} tk_frame;

typedef struct tk_store tk_store;

/* Opens the file, creating it and its tables when missing. */
int tk_store_open(const char *path, tk_store **out, tk_error *err);
void tk_store_close(tk_store **p);

/* Stores a new queued job (doc gets its id) with its input, unless
 * `limit` jobs are queued already, or (per_owner > 0) its owner (the
 * document's "owner") has per_owner jobs queued or running (TK_EBUSY,
 * saying which). */
int tk_store_add(tk_store *s, json_t *doc, const char *input, size_t limit, size_t per_owner,
                 tk_error *err);

/* Writes a job: its document (and state from it), the parts that are not
 * NULL, and its frames from number `first` on (later ones dropped), in
 * one transaction. */
int tk_store_put(tk_store *s, const json_t *doc, const char *const *parts,
                 const tk_frame *frames, size_t first, size_t nframes, tk_error *err);

/* The job's document (TK_ENOTFOUND when there is none). */
int tk_store_get(tk_store *s, int64_t id, json_t **doc, tk_error *err);

/* One part; *text NULL when it was never stored (free with free()). */
int tk_store_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err);

/* Documents newest first, those in `state` only (-1: all) and of
 * `owner` only (NULL: all), a page of them; *total counts all that match. */
int tk_store_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                  json_t **docs, size_t *total, tk_error *err);

/* The oldest queued job becomes running: its id; TK_ENOTFOUND when none. */
int tk_store_claim(tk_store *s, int64_t *id, tk_error *err);

/* Running jobs become queued again (at start: what a stop or a crash left). */
int tk_store_requeue(tk_store *s, tk_error *err);

/* A queued job becomes cancelled; TK_EINVAL when it is not queued. */
int tk_store_cancel(tk_store *s, int64_t id, tk_error *err);

/* Removes an ended job; TK_EINVAL when it has not ended. */
int tk_store_delete(tk_store *s, int64_t id, tk_error *err);

/* Frames [offset, offset + limit) into *out (free with tk_frames_free). */
int tk_store_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_frame **out,
                    size_t *n, tk_error *err);
void tk_frames_free(tk_frame *f, size_t n);

int tk_store_counts(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err);

/* Whether jobs can be stored (a writable file system with room, no failed
 * last write, no damage reported, the newest row reads); why not. */
bool tk_store_health(tk_store *s, char *reason, size_t size);

/* A stored text did not read back as written (SQLite checks pages, not
 * the bytes in a row): health reports it until restart. */
void tk_store_damage(tk_store *s, const char *what);

#endif
