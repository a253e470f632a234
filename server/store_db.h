/* tightknot service: the store's two backends (store_sqlite.c,
 * store_pg.c) behind the table store.c speaks through: a backend runs a
 * statement with its parameters and hands back its rows as text. */
#ifndef TK_SERVER_STORE_DB_H
#define TK_SERVER_STORE_DB_H

#include <stdbool.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <jansson.h>
#include <pthread.h>

#include "tk/error.h"

#define MAX_PARAMS 10

/* A result: n rows of ncol cells, each a NUL-terminated copy (NULL for a
 * SQL null) with its length, and the rows a change touched. */
typedef struct rows {
    size_t n, ncol, changed;
    struct cell {
        char *p;
        size_t len;
    } *cell;
} rows;

void rows_free(rows *r);
/* Sets cell j of the last row (j 0 begins a new one) to a copy of p;
 * false when out of memory. */
bool rows_add(rows *r, size_t j, const void *p, size_t len);
const char *rows_cell(const rows *r, size_t i, size_t j);
int64_t rows_int(const rows *r, size_t i, size_t j); /* 0 for a null */
char *rows_steal(rows *r, size_t i, size_t j);       /* the cell, taken out of r */

/* A statement's parameters $1.. by type: i int64, d double, t text (NULL:
 * null), j JSON text, x text kept as bytes (bytea on PostgreSQL), b bytes
 * (value and length). */
typedef struct params {
    int n;
    char type[MAX_PARAMS];
    const char *value[MAX_PARAMS];
    int length[MAX_PARAMS];
    int64_t ints[MAX_PARAMS];
    double reals[MAX_PARAMS];
    char number[MAX_PARAMS][32];
} params;

typedef struct backend {
    /* A connection (create: the file may be made), or NULL with TK_EIO
     * naming `label`. */
    void *(*connect)(const char *where, const char *label, bool create, tk_error *err);
    void (*disconnect)(void *c);
    const char *(*error)(void *c);
    /* Statements without parameters or results; whether they ran. */
    bool (*script)(void *c, const char *sql);
    /* One statement; its rows into *r.  Whether it ran. */
    bool (*run)(void *c, rows *r, const char *sql, const params *p);
    /* Rolls back what did not commit; whether c may be used again. */
    bool (*release)(void *c);
    /* Creates the tables or brings an earlier version's up to date. */
    bool (*setup)(void *c);
    /* `where` as messages name it (never a password). */
    void (*label)(const char *where, char *out, size_t size);
    /* Why the file system cannot take a write, into reason (NULL: no file). */
    void (*room)(const char *where, char *reason, size_t size);
    /* The statements where the dialects differ (NULL: none), and those
     * built from the shared text below with the dialect's words. */
    const char *claim, *renew, *requeue, *begin, *lock, *add, *put, *owner_bytes;
} backend;

/* Runs statements without parameters or results (NULL: none). */
bool db_script(const backend *db, void *c, const char *sql);
/* Runs a statement (NULL: none) with parameters $1, $2, ... by `types`
 * (params; b takes a pointer and a size_t length), its rows to *out
 * unless NULL.  Whether it ran (the connection's error says why not). */
bool db_query(const backend *db, void *c, rows *out, const char *sql, const char *types, ...);
bool db_vquery(const backend *db, void *c, rows *out, const char *sql, const char *types,
               va_list ap);

const backend *tk_store_sqlite(void);
const backend *tk_store_pg(void);

#define IDLE_MAX 32 /* connections kept for reuse; more are opened while needed */
/* On a shared store the documents last read are served again for a
 * moment: pollers of a job running elsewhere (written every 2 s anyway)
 * cost no query each.  Any write through this store drops them all, so a
 * client sees its own DELETE at once. */
#define RECENT_MAX 64   /* documents kept, one slot per id modulo this */
#define RECENT_AGE 0.5  /* seconds a kept document is served again */

struct tk_store {
    const backend *db;
    bool pg; /* PostgreSQL: shared with other daemons */
    double lease;
    char *where;
    char label[200]; /* where, as messages name it: never a password */
    char holder[96];
    pthread_mutex_t lock; /* guards what follows; never held over a statement */
    void *idle[IDLE_MAX];
    size_t nidle;
    char write_error[TK_ERROR_MESSAGE_SIZE]; /* the last write's failure, "" once one succeeds */
    char damage[TK_ERROR_MESSAGE_SIZE];      /* the first damage a reader found */
    uint64_t writes; /* writes through this store so far */
    struct kept {
        int64_t id;
        uint64_t writes; /* the count when it was read: stale once another write came */
        double at;       /* when it was read (monotonic seconds) */
        json_t *doc;     /* never handed out: copies are */
    } recent[RECENT_MAX];
};

/* The connection's last error, on one line, as TK_EIO saying `what` failed. */
int store_failed(const struct tk_store *s, void *c, tk_error *err, const char *what);
/* A connection for this call (kept, or a new one), and back: what did not
 * commit rolled back, kept unless it broke (a lost server). */
void *store_take(struct tk_store *s, tk_error *err);
void store_give(struct tk_store *s, void *c);
/* Notes a write's outcome for health: TK_EIO or TK_ENOMEM until a write
 * succeeds (busy, not found, not queued are answers, not failures).
 * Returns rc. */
int store_written(struct tk_store *s, int rc, const tk_error *err);

/* The advisory lock that makes a submission's limits and insert one step
 * across daemons (any number no other program on the database uses). */
#define ADD_LOCK "7310519"

/* The shared SQL, with the dialect's words: B(column) a column's bytes
 * (DOC_BYTES the document's), LEASE what writing a running job sets
 * besides.  SQL_OWNER_BYTES: owner P's stored bytes, frames included.
 * SQL_ADD: the limits and the insert in one statement ($1 doc, $2 input,
 * $3 queue, $4 owner, $5 its jobs, $6 its bytes), the turn as store.h
 * says; owner '' is the column's null. */
#define SQL_PART_BYTES(E, col, n, sql) " + " B(#col)
#define SQL_OWNER_BYTES(P)                                                                      \
    "SELECT CAST(coalesce(sum(" DOC_BYTES TK_PART_COLUMNS(SQL_PART_BYTES) " + (SELECT"           \
    " coalesce(sum(length(xyz)), 0) FROM frames WHERE job = jobs.id)), 0) AS bigint) FROM jobs" \
    " WHERE owner = " P
#define SQL_ADD                                                                                 \
    "INSERT INTO jobs (state, doc, input, owner, turn) SELECT 'queued', $1, $2, coalesce($4,"   \
    " ''), 1 + (SELECT coalesce(max(turn), 0) FROM jobs WHERE state = 'running' OR (owner ="     \
    " coalesce($4, '') AND state = 'queued')) WHERE (SELECT count(*) FROM jobs WHERE state ="    \
    " 'queued') < $3 AND ($4 IS NULL OR $5 = 0 OR (SELECT count(*) FROM jobs WHERE owner = $4"   \
    " AND state IN ('queued', 'running')) < $5)"                                                \
    " AND ($4 IS NULL OR $6 = 0 OR (" SQL_OWNER_BYTES("$4") ") < $6) RETURNING id"
/* A state other than running lets go of the job. */
#define SQL_PART_SET(E, col, n, sql) ", " #col " = coalesce($" #n ", " #col ")"
#define SQL_PUT                                                                                 \
    "UPDATE jobs SET state = $1, doc = $2" TK_PART_COLUMNS(SQL_PART_SET)                        \
    ", holder = CASE $1 WHEN 'running' THEN holder END" LEASE " WHERE id = $8 AND holder = $9"

#endif
