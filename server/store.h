/* tightknot service: the job store, behind a narrow interface.
 *
 * A job is a row of a few fixed columns: its id, its state (the queue is
 * the store: claiming takes the queued job of the earliest turn, see
 * tk_store_claim), its owner (indexed: a name's jobs are read without
 * the others'), its document (job.h; the state and id are the columns'),
 * its large parts, who holds it while it runs, and its frames in a table
 * of their own.  Two backends (store_db.h), one SQL (store.c):
 * - SQLite: one file in WAL mode for one daemon, each thread on a
 *   connection of its own, so a reader never waits for a writer;
 * - PostgreSQL: one database shared by any number of daemons.
 *   A claim takes the oldest job that is queued or whose holder's lease
 *   ran out, in one statement (FOR UPDATE SKIP LOCKED), so no job runs
 *   twice at once; the holder renews the lease (tk_store_renew) and a
 *   daemon that dies loses its jobs to the others when it runs out.
 * Writes to a running job (tk_store_put, tk_store_renew) succeed only for
 * its holder, so a daemon that lost a job can no longer change it.
 */
#ifndef TK_SERVER_STORE_H
#define TK_SERVER_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "job.h"

/* A job's large parts, each a column: X(ENUM, column, its parameter in
 * the write of a job (store_db.h), the column's constraint) */
#define TK_PART_COLUMNS(X)                                                                      \
    X(INPUT, input, 3, " NOT NULL") /* the VECT as submitted */                                 \
    X(CURVE, curve, 4, "")          /* the latest curve as VECT (NULL before the run) */        \
    X(CONTACTS, contacts, 5, "")    /* struts and kinks (tk_json_contacts) */                   \
    X(HISTORY, history, 6, "")      /* the decimated step figures, a JSON array */              \
    X(RESUME, resume, 7, "")        /* {at, best, best_report}: where the run resumes */
#define TK_PART_ENUM(E, col, n, what) TK_PART_##E,
typedef enum tk_part { TK_PART_COLUMNS(TK_PART_ENUM) TK_PARTS } tk_part;

/* A frame: its step, the curve's coordinates and its vertices per
 * component as a JSON array (NULL: those of the job's curve). */
typedef struct tk_frame {
    long step;
    double *xyz;
    size_t count;
    char *layout;
} tk_frame;

typedef struct tk_store tk_store;

/* Opens the store `where` names, creating its tables when missing: a
 * postgresql:// (or postgres://) URI, or else a SQLite file.  `lease`:
 * the seconds a claim lasts unrenewed (PostgreSQL only). */
int tk_store_open(const char *where, double lease, tk_store **out, tk_error *err);
void tk_store_close(tk_store **p);

/* Whether other daemons may share the store (PostgreSQL). */
bool tk_store_shared(const tk_store *s);

/* Who claims jobs through this store: "host:pid:random", unique. */
const char *tk_store_holder(const tk_store *s);

/* What submissions may not go beyond: checked with the insert, in one
 * step across daemons, so two cannot both take the last place. */
typedef struct tk_store_limits {
    size_t queued;    /* jobs queued, of all owners */
    size_t per_owner; /* jobs queued or running of the document's owner (0: any) */
    size_t bytes;     /* bytes stored for the owner's jobs, frames included (0: any) */
} tk_store_limits;

/* Stores a new queued job (doc gets its id) with its input, unless a
 * limit is reached (TK_EBUSY, saying which); the owner's limits hold for
 * a document with an "owner". */
int tk_store_add(tk_store *s, json_t *doc, const char *input, const tk_store_limits *limits,
                 tk_error *err);

/* Writes a job this store holds: its document (and state from it; a state
 * other than running lets go of it), the parts that are not NULL, and its
 * frames from number `first` on (later ones dropped), in one transaction.
 * TK_ENOTFOUND when the job is not held here (any more). */
int tk_store_put(tk_store *s, const json_t *doc, const char *const *parts,
                 const tk_frame *frames, size_t first, size_t nframes, tk_error *err);

/* tk_store_put, its frames only while the bytes stored for the
 * document's owner stay within owner_bytes (0: any), counted in the same
 * transaction with the document and parts written: when not all fit,
 * nothing is written, *fit says how many would, and TK_ELIMIT. */
int tk_store_put_within(tk_store *s, const json_t *doc, const char *const *parts,
                        const tk_frame *frames, size_t first, size_t nframes, size_t owner_bytes,
                        size_t *fit, tk_error *err);

/* The job's document (TK_ENOTFOUND when there is none; TK_EPARSE, the
 * store reported damaged, when it does not read back: damage, not an
 * outage, so a 500 and not a 503).  On a shared
 * store it may be one read up to half a second ago, unless a write went
 * through this store since. */
int tk_store_get(tk_store *s, int64_t id, json_t **doc, tk_error *err);

/* One part; *text NULL when it was never stored (free with free()). */
int tk_store_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err);

/* Documents newest first, those in `state` only (-1: all) and of
 * `owner` only (NULL: all), a page of them; *total counts all that match. */
int tk_store_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                  json_t **docs, size_t *total, tk_error *err);

/* The queued job of the earliest turn, the oldest of equal turns
 * (PostgreSQL: or a running one whose lease ran out) becomes running,
 * held here: its id; TK_ENOTFOUND when none.  A job's turn, given when it
 * is added, is one past its owner's latest waiting or running job's, or
 * past the newest running job's when the owner has none: owners take
 * turns, so one owner's many queued jobs do not keep another's waiting
 * behind all of them. */
int tk_store_claim(tk_store *s, int64_t *id, tk_error *err);

/* Keeps a running job held here (PostgreSQL: its lease starts again);
 * *cancel when a client asked to cancel it (tk_store_stop).  TK_ENOTFOUND
 * when it is no longer held here. */
int tk_store_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err);

/* At start: SQLite's running jobs (what a stop or a crash left) become
 * queued again.  PostgreSQL leaves them to their leases. */
int tk_store_requeue(tk_store *s, tk_error *err);

/* A queued job becomes cancelled; TK_EINVAL when it is not queued. */
int tk_store_cancel(tk_store *s, int64_t id, tk_error *err);

/* A running job is marked to be cancelled: its holder learns it at its
 * next renewal.  TK_EINVAL when it is not running. */
int tk_store_stop(tk_store *s, int64_t id, tk_error *err);

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
