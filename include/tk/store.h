/* tightknot: the job store, one SQLite file in WAL mode.
 *
 * A job row holds what a client can ask for after a restart: the request
 * (name, options, input VECT), the state and timestamps, the latest
 * figures, the latest curve (so an unfinished job resumes from it), the
 * final contacts, the decimated history and the knot or link type as
 * JSON, and the snapshots (frames) in their own table.
 *
 * One store is shared by every thread of the daemon: each call takes the
 * store's lock for the duration of one statement or transaction.
 */
#ifndef TK_STORE_H
#define TK_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tk/error.h"
#include "tk/jobspec.h"
#include "tk/tighten.h"

typedef enum tk_job_state {
    TK_JOB_QUEUED = 0,
    TK_JOB_RUNNING,
    TK_JOB_DONE,
    TK_JOB_FAILED,
    TK_JOB_CANCELLED,
    TK_JOB_STATES
} tk_job_state;

const char *tk_job_state_name(tk_job_state s);
/* Returns false for a name that is no state. */
bool tk_job_state_parse(const char *name, tk_job_state *out);
bool tk_job_state_final(tk_job_state s);

#define TK_JOB_NAME_SIZE 128
#define TK_JOB_ERROR_SIZE 320

typedef struct tk_job {
    int64_t id;
    char name[TK_JOB_NAME_SIZE];
    tk_job_state state;
    tk_job_options options;
    double created, started, finished; /* Unix seconds; 0 when not yet */
    tk_step_report latest;             /* figures of the latest step stored */
    bool has_figures;                  /* false until the run has measured */
    size_t components;
    double fraction;                   /* progress in [0, 1]; < 0 unknown */
    char stop_reason[16];              /* engine's stop reason; "" while going */
    char error[TK_JOB_ERROR_SIZE];     /* why it failed; "" otherwise */
    size_t frames;                     /* snapshots stored */
} tk_job;

/* The large texts of a job. */
typedef enum tk_job_text {
    TK_TEXT_INPUT = 0, /* the VECT as submitted */
    TK_TEXT_CURVE,     /* the latest curve as VECT (NULL before the run starts) */
    TK_TEXT_CONTACTS,  /* struts and kinks JSON (tk_json_contacts) */
    TK_TEXT_HISTORY,   /* decimated per-step figures, a JSON array */
    TK_TEXT_INVARIANTS, /* {"start", "result"}: the knot or link type of the
                          input and of the run's curve at its last check
                          (tk_json_invariants each); NULL until the run
                          has started */
    TK_TEXT_RESUME,     /* {"at": the run's resume point (tk/tighten.h's
                           TK_RESUME_FIELDS), "best": its best curve as
                           VECT or null, "best_report": that curve's step
                           figures or null}; NULL until the run has
                           started */
    TK_TEXTS
} tk_job_text;

typedef struct tk_store tk_store;

/* Opens (creating when missing) the database file and its tables; a
 * store written before a column was added gets it (NULL in its rows). */
int tk_store_open(const char *path, tk_store **out, tk_error *err);
void tk_store_close(tk_store **p);

/* Inserts a new job (state, name, options, created from *job) with its
 * input VECT; sets job->id. */
int tk_store_insert(tk_store *s, tk_job *job, const char *vect, tk_error *err);

/* Reads a job; TK_ENOTFOUND when there is none with that id. */
int tk_store_get(tk_store *s, int64_t id, tk_job *out, tk_error *err);

/* Jobs newest first, optionally only those in `state` (filter false:
 * all), from `offset`, at most `limit`; *total counts all matching. */
int tk_store_list(tk_store *s, bool filter, tk_job_state state, size_t offset, size_t limit,
                  tk_job **out, size_t *count, size_t *total, tk_error *err);

/* Stores the state, timestamps, figures, stop reason and error of job. */
int tk_store_update(tk_store *s, const tk_job *job, tk_error *err);

/* A frame of a job: its step, the curve's coordinates and, as JSON, its
 * vertices per component (frames differ in them when the run resampled;
 * NULL: those of the job's stored curve, as frames stored before). */
typedef struct tk_store_frame {
    long step;
    double *xyz;
    size_t count;  /* doubles */
    char *layout;  /* JSON array of vertex counts, or NULL */
} tk_store_frame;

/* Stores the job (as tk_store_update) and, in the same transaction, the
 * texts that are not NULL (texts[k] for tk_job_text k; texts may be
 * NULL) and the frames, which are the last nframes of job->frames. */
int tk_store_save(tk_store *s, const tk_job *job, const char *const *texts,
                  const tk_store_frame *frames, size_t nframes, tk_error *err);

/* Reads one text; *out is NULL when it was never stored (free with free()). */
int tk_store_text(tk_store *s, int64_t id, tk_job_text which, char **out, size_t *len,
                  tk_error *err);

/* Frames [offset, offset + limit) of a job into *out (*n of them; free
 * with tk_store_frames_free). */
int tk_store_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_store_frame **out,
                    size_t *n, tk_error *err);
void tk_store_frames_free(tk_store_frame *frames, size_t n);

/* Ids of queued and running jobs, oldest first (to take up after a
 * restart). */
int tk_store_unfinished(tk_store *s, int64_t **ids, size_t *n, tk_error *err);

/* Removes a job with its texts and frames; TK_ENOTFOUND when there is
 * none.  The caller sees that it is not running. */
int tk_store_delete(tk_store *s, int64_t id, tk_error *err);

/* Whether the store can take jobs: not found damaged, writable, its last
 * write succeeded, and its newest job reads back.  When not, reason says
 * why (for GET /v1/health). */
bool tk_store_health(tk_store *s, char *reason, size_t size);

/* Records that a stored text did not read back as what was written (a
 * VECT that does not parse, JSON that is not JSON): SQLite cannot see
 * bytes overwritten inside a row, its readers can.  Health reports the
 * first such damage until the daemon restarts. */
void tk_store_report_damage(tk_store *s, const char *what);

/* Number of jobs in each state. */
int tk_store_count_states(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err);

#endif
