/* tightknot service: the job store, behind a narrow interface.
 *
 * A job is a row: its id, its state (the queue is the store), its owner
 * (indexed: a name's jobs are read without the others'), its document
 * (job.h; id and state are the columns'), its large parts, its holder
 * while it runs; its frames are rows of a table of their own.  Two
 * backends (store_db.h) under one SQL (store.c): SQLite, one WAL file for
 * one daemon; PostgreSQL, one database shared by any number of daemons,
 * where a claim (FOR UPDATE SKIP LOCKED) takes a queued job or one whose
 * holder's lease ran out, so a dead daemon's jobs go to the others.
 * Writes to a running job succeed only for its holder, so a daemon that
 * lost a job can no longer change it.
 */
#ifndef TK_SERVER_STORE_H
#define TK_SERVER_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "job.h"

/* A job's large parts, each a column: X(ENUM, column, its parameter in
 * SQL_PUT (store_db.h), its constraint) */
#define TK_PART_COLUMNS(X)                                                                      \
    X(INPUT, input, 3, " NOT NULL") /* the VECT as submitted */                                 \
    X(CURVE, curve, 4, "")          /* the latest curve as VECT (NULL before the run) */        \
    X(CONTACTS, contacts, 5, "")    /* struts and kinks (tk_json_contacts) */                   \
    X(HISTORY, history, 6, "")      /* the decimated step figures, a JSON array */              \
    X(RESUME, resume, 7, "")        /* {at, best, best_report}: where the run resumes */
#define TK_PART_ENUM(E, col, n, what) TK_PART_##E,
typedef enum tk_part { TK_PART_COLUMNS(TK_PART_ENUM) TK_PARTS } tk_part;

/* A frame: its step, its coordinates, and its vertices per component as
 * a JSON array (NULL: the job's curve's). */
typedef struct tk_frame {
    long step;
    double *xyz;
    size_t count;
    char *layout;
} tk_frame;

typedef struct tk_store tk_store;

/* Opens a postgresql:// (or postgres://) URI, else a SQLite file,
 * creating the tables when missing; `lease`: the seconds a claim lasts
 * unrenewed (PostgreSQL). */
int tk_store_open(const char *where, double lease, tk_store **out, tk_error *err);
void tk_store_close(tk_store **p);

/* Whether other daemons may share the store (PostgreSQL). */
bool tk_store_shared(const tk_store *s);

/* What the store is, for logs and messages: a SQLite file's path, a
 * PostgreSQL database's name, host and port (never a password). */
const char *tk_store_label(const tk_store *s);

/* Who claims jobs through this store: "host:pid:random", unique. */
const char *tk_store_holder(const tk_store *s);

/* What submissions may not go beyond, checked in the insert's statement
 * under one lock across daemons: two cannot both take the last place. */
typedef struct tk_store_limits {
    size_t queued;    /* jobs queued, of all owners */
    size_t per_owner; /* jobs queued or running of the document's owner (0: any) */
    size_t bytes;     /* bytes stored for the owner's jobs, frames included (0: any) */
} tk_store_limits;

/* Stores a new queued job (doc gets its id) with its input; TK_EBUSY
 * saying which limit it reached (an owner's only for a doc with one). */
int tk_store_add(tk_store *s, json_t *doc, const char *input, const tk_store_limits *limits,
                 tk_error *err);

/* Writes a job this store holds, in one transaction: its document (and
 * state: other than running lets go of it), the parts not NULL, and its
 * frames from number `first` on (later ones dropped).  TK_ENOTFOUND when
 * it is not held here.  With owner_bytes (0: any), when the frames do not
 * all fit in what the owner may store, nothing is written, *fit says how
 * many would, and TK_ELIMIT. */
int tk_store_put(tk_store *s, const json_t *doc, const char *const *parts,
                 const tk_frame *frames, size_t first, size_t nframes, size_t owner_bytes,
                 size_t *fit, tk_error *err);

/* The job's document; TK_ENOTFOUND, or TK_EPARSE (the store reported
 * damaged: a 500, not an outage's 503) when it does not read back.  On a
 * shared store it may be a read of up to RECENT_AGE ago, unless a write
 * went through this store since. */
int tk_store_get(tk_store *s, int64_t id, json_t **doc, tk_error *err);

/* The step of the job's parts as stored, written with its stored document
 * in one transaction (a running job's live document, doc, is ahead of
 * them); doc's own step when the store cannot say. */
json_int_t tk_store_step(tk_store *s, const json_t *doc);

/* One part; *text NULL when it was never stored (free with free()). */
int tk_store_part(tk_store *s, int64_t id, tk_part part, char **text, size_t *len, tk_error *err);

/* A page of documents newest first, of `state` (-1: all) and `owner`
 * (NULL: all); *total counts all that match. */
int tk_store_list(tk_store *s, int state, const char *owner, size_t offset, size_t limit,
                  json_t **docs, size_t *total, tk_error *err);

/* The queued job of the earliest turn, oldest first (PostgreSQL: or a
 * running one whose lease ran out), becomes running, held here: its id;
 * TK_ENOTFOUND when none.  A job's turn is one past its owner's latest
 * waiting or running job's, or past the newest running job's: owners take
 * turns, so one's many queued jobs do not keep another's behind them. */
int tk_store_claim(tk_store *s, int64_t *id, tk_error *err);

/* Keeps a running job held here (its lease starts again); *cancel when a
 * client asked to cancel it.  TK_ENOTFOUND when it is not held here. */
int tk_store_renew(tk_store *s, int64_t id, bool *cancel, tk_error *err);

/* At start, SQLite's running jobs (left by a stop or a crash) are queued
 * again; PostgreSQL leaves them to their leases. */
int tk_store_requeue(tk_store *s, tk_error *err);

/* A queued job becomes cancelled; TK_EINVAL when it is not queued. */
int tk_store_cancel(tk_store *s, int64_t id, tk_error *err);

/* Marks a running job to be cancelled, which its holder learns at its
 * next renewal; TK_EINVAL when it is not running. */
int tk_store_stop(tk_store *s, int64_t id, tk_error *err);

/* Removes an ended job; TK_EINVAL when it has not ended. */
int tk_store_delete(tk_store *s, int64_t id, tk_error *err);

/* Frames [offset, offset + limit) into *out (free with tk_frames_free). */
int tk_store_frames(tk_store *s, int64_t id, size_t offset, size_t limit, tk_frame **out,
                    size_t *n, tk_error *err);
void tk_frames_free(tk_frame *f, size_t n);

int tk_store_counts(tk_store *s, size_t counts[TK_JOB_STATES], tk_error *err);

/* Whether jobs can be stored (room on a writable file system, no failed
 * last write, no damage, the newest row reads); why not. */
bool tk_store_health(tk_store *s, char *reason, size_t size);

/* A stored text did not read back (SQLite checks pages, not a row's
 * bytes): health reports it until restart. */
void tk_store_damage(tk_store *s, const char *what);

#endif
