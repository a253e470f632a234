/* Tests for the job store (server/store.c), each backend: a job's
 * document, parts and frames read back the same after the store is opened
 * again; listing is newest first with a filter and pages; the queue is the
 * store (claims take the oldest queued job, each exactly once, from many
 * threads; the limits hold); cancelling, deleting and queueing again
 * change only the jobs they may; a running job is written only by its
 * holder, which learns of a cancellation asked elsewhere.  SQLite: a
 * reader never waits for a writer; a store of the first version becomes
 * documents and keeps its jobs.  PostgreSQL (on the server $TK_PG_URL
 * names, tests/pg.sh; a database of its own per test): a claim whose
 * lease ran out goes to another store. */
#include <check.h>
#include <libpq-fe.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "jsonmap.h"
#include "store.h"
#include "support.h"

static char dir[64];
static char path[128];
static char where[512]; /* what tk_store_open is given: path, or a database's URI */
static bool shared;     /* the PostgreSQL backend */

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/tk-store-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/jobs.db", dir);
    snprintf(where, sizeof where, "%s", path);
    shared = false;
}

/* Runs one statement on the tests' PostgreSQL server. */
static void pg_exec(const char *sql)
{
    PGconn *c = PQconnectdb(getenv("TK_PG_URL"));
    ck_assert_msg(PQstatus(c) == CONNECTION_OK, "%s", PQerrorMessage(c));
    PGresult *r = PQexec(c, sql);
    ck_assert_msg(PQresultStatus(r) == PGRES_COMMAND_OK, "%s: %s", sql, PQerrorMessage(c));
    PQclear(r);
    PQfinish(c);
}

static char database[64];

static void pg_setup(void)
{
    static int n;
    snprintf(database, sizeof database, "tk_store_%ld_%d", (long)getpid(), ++n);
    char sql[128];
    snprintf(sql, sizeof sql, "CREATE DATABASE %s", database);
    pg_exec(sql);
    const char *url = getenv("TK_PG_URL");
    const char *slash = strrchr(url, '/');
    snprintf(where, sizeof where, "%.*s/%s", (int)(slash - url), url, database);
    shared = true;
}

static void pg_teardown(void)
{
    char sql[128];
    snprintf(sql, sizeof sql, "DROP DATABASE %s WITH (FORCE)", database);
    pg_exec(sql);
}

static void teardown(void)
{
    char p[160];
    const char *suffix[] = {"", "-wal", "-shm"};
    for (int i = 0; i < 3; i++) {
        snprintf(p, sizeof p, "%s%s", path, suffix[i]);
        unlink(p);
    }
    rmdir(dir);
}

/* The test's store, with claims that last `lease` seconds. */
static tk_store *open_leased(double lease)
{
    tk_store *s = NULL;
    tk_error err;
    ck_assert_msg(tk_store_open(where, lease, &s, &err) == TK_OK, "%s", err.message);
    ck_assert(tk_store_shared(s) == shared);
    return s;
}

static tk_store *open_store(void)
{
    return open_leased(30.0);
}

static const char input[] = "VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n";

/* Adds a queued job called name; its id. */
static int64_t add_job(tk_store *s, const char *name)
{
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    o.run.max_steps = 77;
    json_t *doc = tk_job_new(name, NULL, &o, 1, 3);
    tk_error err;
    ck_assert_msg(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 0}, &err) == TK_OK, "%s", err.message);
    int64_t id = tk_job_id(doc);
    ck_assert_int_gt(id, 0);
    json_decref(doc);
    return id;
}

static json_t *get(tk_store *s, int64_t id)
{
    json_t *doc = NULL;
    tk_error err;
    ck_assert_msg(tk_store_get(s, id, &doc, &err) == TK_OK, "%s", err.message);
    return doc;
}

static const char *state_of(tk_store *s, int64_t id)
{
    json_t *doc = get(s, id);
    const char *name = tk_job_states[tk_job_state_in(doc)];
    json_decref(doc);
    return name;
}

START_TEST(a_job_reads_back_after_reopening)
{
    tk_store *s = open_store();
    int64_t id = add_job(s, "trefoil"), claimed = 0;
    json_t *doc = get(s, id);
    ck_assert_str_eq(json_string_value(json_object_get(doc, "name")), "trefoil");
    ck_assert_str_eq(json_string_value(json_object_get(doc, "state")), "queued");
    tk_step_report r = {.step = 77, .seconds = 1.25, .ropelength = 32.7523560914,
                        .thickness = 1.0, .residual = 0.1 / 3.0, .vertices = 3};
    tk_job_options o;
    tk_error err;
    ck_assert_int_eq(tk_job_options_of(doc, &o, &err), TK_OK);
    ck_assert_int_eq(o.run.max_steps, 77);
    /* only the holder writes: a job not claimed is not */
    ck_assert_int_eq(tk_store_put(s, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_claim(s, &claimed, &err), TK_OK);
    ck_assert_int_eq(claimed, id);
    tk_job_set_figures(doc, &r, &o);
    json_object_set_new(doc, "state", json_string("running"));
    const char *parts[TK_PARTS] = {NULL, "VECT curve", "{\"struts\":[]}", "[1,2]", "{}"};
    double xyz[2][6] = {{0.1, 1.0 / 3.0, -2.5, 4, 5, 6}, {1e-300, 2, 3, 4, 5, 6}};
    tk_frame frames[2] = {{10, xyz[0], 6, "[2]"}, {20, xyz[1], 6, NULL}};
    ck_assert_int_eq(tk_store_put(s, doc, parts, frames, 0, 2, 0, NULL, &err), TK_OK);
    tk_frame *f = NULL;
    size_t n = 0;
    ck_assert_int_eq(tk_store_frames(s, id, 1, 10, &f, &n, &err), TK_OK);
    ck_assert_uint_eq(n, 1);
    ck_assert_int_eq(f[0].step, 20);
    ck_assert_uint_eq(f[0].count, 6);
    ck_assert(memcmp(f[0].xyz, xyz[1], sizeof xyz[1]) == 0);
    ck_assert_ptr_null(f[0].layout);
    tk_frames_free(f, n);
    /* frames from a place on replace those after it; a state other than
     * running lets go of the job */
    frames[0].step = 15;
    json_object_set_new(doc, "state", json_string("done"));
    ck_assert_int_eq(tk_store_put(s, doc, NULL, frames, 1, 1, 0, NULL, &err), TK_OK);
    ck_assert_int_eq(tk_store_put(s, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_ENOTFOUND);
    tk_store_close(&s);

    s = open_store();
    json_t *back = get(s, id);
    ck_assert_msg(json_equal(doc, back), "%s", json_dumps(back, 0));
    for (int k = 0; k < TK_PARTS; k++) {
        char *text = NULL;
        size_t len = 0;
        ck_assert_int_eq(tk_store_part(s, id, (tk_part)k, &text, &len, &err), TK_OK);
        ck_assert_str_eq(text, k == TK_PART_INPUT ? input : parts[k]);
        ck_assert_uint_eq(len, strlen(text));
        free(text);
    }
    ck_assert_int_eq(tk_store_frames(s, id, 0, 10, &f, &n, &err), TK_OK);
    ck_assert_uint_eq(n, 2);
    ck_assert(f[0].step == 10 && f[1].step == 15 && !strcmp(f[1].layout, "[2]"));
    ck_assert(memcmp(f[0].xyz, xyz[0], sizeof xyz[0]) == 0);
    ck_assert(memcmp(f[1].xyz, xyz[0], sizeof xyz[0]) == 0);
    tk_frames_free(f, n);
    json_decref(doc);
    json_decref(back);
    tk_store_close(&s);
}
END_TEST

/* Two stores on one database (two daemons): the job one claims is written
 * and renewed by it alone; a cancellation asked through the other reaches
 * the holder at its renewal. */
START_TEST(a_running_job_is_its_holders)
{
    tk_store *a = open_store(), *b = open_store();
    ck_assert_str_ne(tk_store_holder(a), tk_store_holder(b));
    int64_t id = add_job(b, "k"), claimed = 0;
    tk_error err;
    bool cancel = true;
    ck_assert_int_eq(tk_store_claim(a, &claimed, &err), TK_OK);
    ck_assert_int_eq(claimed, id);
    json_t *doc = get(b, id);
    ck_assert_str_eq(json_string_value(json_object_get(doc, "state")), "running");
    ck_assert_int_eq(tk_store_put(b, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_renew(b, id, &cancel, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_renew(a, id, &cancel, &err), TK_OK);
    ck_assert(!cancel);
    ck_assert_int_eq(tk_store_cancel(b, id, &err), TK_EINVAL); /* not queued */
    ck_assert_int_eq(tk_store_stop(b, id, &err), TK_OK);
    ck_assert_int_eq(tk_store_renew(a, id, &cancel, &err), TK_OK);
    ck_assert(cancel);
    ck_assert_int_eq(tk_store_put(a, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_OK);
    json_object_set_new(doc, "state", json_string("cancelled"));
    ck_assert_int_eq(tk_store_put(a, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_OK);
    ck_assert_int_eq(tk_store_stop(b, id, &err), TK_EINVAL); /* ended */
    ck_assert_int_eq(tk_store_renew(a, id, &cancel, &err), TK_ENOTFOUND);
    ck_assert_str_eq(state_of(b, id), "cancelled");
    json_decref(doc);
    tk_store_close(&a);
    tk_store_close(&b);
}
END_TEST

/* PostgreSQL: a claim not renewed within its lease (its daemon died) goes
 * to the next store that claims, and the first can no longer write it. */
START_TEST(a_lapsed_claim_goes_to_another_store)
{
    tk_store *a = open_leased(0.5), *b = open_leased(0.5);
    int64_t id = add_job(a, "k"), got = 0;
    tk_error err;
    bool cancel;
    ck_assert_int_eq(tk_store_claim(a, &got, &err), TK_OK);
    ck_assert_int_eq(tk_store_claim(b, &got, &err), TK_ENOTFOUND); /* held */
    nanosleep(&(struct timespec){0, 300000000L}, NULL);
    ck_assert_int_eq(tk_store_renew(a, id, &cancel, &err), TK_OK);
    nanosleep(&(struct timespec){0, 300000000L}, NULL); /* 0.6 s after the claim, 0.3 s after the renewal: still held */
    ck_assert_int_eq(tk_store_claim(b, &got, &err), TK_ENOTFOUND);
    nanosleep(&(struct timespec){0, 400000000L}, NULL);
    ck_assert_int_eq(tk_store_claim(b, &got, &err), TK_OK);
    ck_assert_int_eq(got, id);
    json_t *doc = get(a, id);
    ck_assert_int_eq(tk_store_put(a, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_renew(a, id, &cancel, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_put(b, doc, NULL, NULL, 0, 0, 0, NULL, &err), TK_OK);
    /* a daemon's start leaves running jobs to their leases */
    ck_assert_int_eq(tk_store_requeue(a, &err), TK_OK);
    ck_assert_str_eq(state_of(a, id), "running");
    json_decref(doc);
    tk_store_close(&a);
    tk_store_close(&b);
}
END_TEST

START_TEST(missing_jobs_are_not_found)
{
    tk_store *s = open_store();
    json_t *doc = NULL;
    char *text = NULL;
    tk_error err;
    ck_assert_int_eq(tk_store_get(s, 42, &doc, &err), TK_ENOTFOUND);
    ck_assert(strstr(err.message, "42"));
    ck_assert_int_eq(tk_store_part(s, 42, TK_PART_CURVE, &text, NULL, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_cancel(s, 42, &err), TK_EINVAL);
    ck_assert_int_eq(tk_store_delete(s, 42, &err), TK_EINVAL);
    tk_store_close(&s);
}
END_TEST

START_TEST(listing_is_newest_first_filtered_and_paged)
{
    tk_store *s = open_store();
    int64_t ids[7];
    for (int i = 0; i < 7; i++)
        ids[i] = add_job(s, "k");
    tk_error err;
    ck_assert_int_eq(tk_store_cancel(s, ids[2], &err), TK_OK);
    ck_assert_int_eq(tk_store_cancel(s, ids[5], &err), TK_OK);
    json_t *docs = NULL;
    size_t total = 0;
    ck_assert_int_eq(tk_store_list(s, -1, NULL, 1, 3, &docs, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 7);
    ck_assert_uint_eq(json_array_size(docs), 3);
    for (size_t i = 0; i < 3; i++)
        ck_assert_int_eq(tk_job_id(json_array_get(docs, i)), ids[5 - i]);
    json_decref(docs);
    ck_assert_int_eq(tk_store_list(s, TK_JOB_CANCELLED, NULL, 0, 10, &docs, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 2);
    ck_assert_int_eq(tk_job_id(json_array_get(docs, 0)), ids[5]);
    ck_assert_int_eq(tk_job_id(json_array_get(docs, 1)), ids[2]);
    json_decref(docs);
    size_t counts[TK_JOB_STATES];
    ck_assert_int_eq(tk_store_counts(s, counts, &err), TK_OK);
    ck_assert(counts[TK_JOB_QUEUED] == 5 && counts[TK_JOB_CANCELLED] == 2 && counts[TK_JOB_DONE] == 0);
    tk_store_close(&s);
}
END_TEST

/* Claims from four threads at once: every claim a different job, oldest
 * first within a thread. */
enum { CLAIMERS = 4, CLAIMED = 60 };
typedef struct claimer {
    tk_store *s;
    int64_t got[CLAIMED];
    size_t n;
} claimer;

static void *claim_all(void *arg)
{
    claimer *c = arg;
    tk_error err;
    int64_t id;
    while (tk_store_claim(c->s, &id, &err) == TK_OK)
        c->got[c->n++] = id;
    return NULL;
}

START_TEST(claims_take_each_queued_job_once_oldest_first)
{
    tk_store *s = open_store();
    for (int i = 0; i < CLAIMED; i++)
        add_job(s, "k");
    claimer c[CLAIMERS];
    pthread_t t[CLAIMERS];
    for (int i = 0; i < CLAIMERS; i++) {
        c[i] = (claimer){.s = s};
        pthread_create(&t[i], NULL, claim_all, &c[i]);
    }
    int seen[CLAIMED + 1] = {0};
    size_t all = 0;
    for (int i = 0; i < CLAIMERS; i++) {
        pthread_join(t[i], NULL);
        for (size_t k = 0; k < c[i].n; k++) {
            ck_assert(c[i].got[k] >= 1 && c[i].got[k] <= CLAIMED);
            seen[c[i].got[k]]++;
            ck_assert(k == 0 || c[i].got[k] > c[i].got[k - 1]);
        }
        all += c[i].n;
    }
    ck_assert_uint_eq(all, CLAIMED);
    for (int id = 1; id <= CLAIMED; id++)
        ck_assert_int_eq(seen[id], 1);
    ck_assert_str_eq(state_of(s, 7), "running");
    /* a running job is neither cancelled nor deleted by the store; SQLite:
     * queued again (a restart) it is claimed again */
    tk_error err;
    int64_t id;
    ck_assert_int_eq(tk_store_claim(s, &id, &err), TK_ENOTFOUND);
    ck_assert_int_eq(tk_store_cancel(s, 7, &err), TK_EINVAL);
    ck_assert_int_eq(tk_store_delete(s, 7, &err), TK_EINVAL);
    if (!shared) {
        ck_assert_int_eq(tk_store_requeue(s, &err), TK_OK);
        ck_assert_int_eq(tk_store_claim(s, &id, &err), TK_OK);
        ck_assert_int_eq(id, 1);
    }
    tk_store_close(&s);
}
END_TEST

START_TEST(an_owner_limit_counts_its_queued_and_running_jobs)
{
    /* per owner, queued and running jobs count, others' and ended ones not;
     * the listing by owner sees only that owner's */
    tk_store *s = open_store();
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_error err;
    const char *owners[] = {"ann", "ann", "ann", "bo", NULL};
    const int expect[] = {TK_OK, TK_OK, TK_EBUSY, TK_OK, TK_OK};
    for (int i = 0; i < 5; i++) {
        json_t *doc = tk_job_new("k", owners[i], &o, 1, 3);
        ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 2, 0}, &err), expect[i]);
        if (expect[i])
            ck_assert_msg(strstr(err.message, "'ann' has 2 jobs queued or running"), "%s",
                          err.message);
        json_decref(doc);
    }
    int64_t id = 0;
    ck_assert_int_eq(tk_store_claim(s, &id, &err), TK_OK); /* ann's first runs: still counts */
    json_t *doc = tk_job_new("k", "ann", &o, 1, 3);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 2, 0}, &err), TK_EBUSY);
    ck_assert_int_eq(tk_store_cancel(s, 2, &err), TK_OK); /* her second ends: room */
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 2, 0}, &err), TK_OK);
    json_decref(doc);
    json_t *docs = NULL;
    size_t total = 0;
    ck_assert_int_eq(tk_store_list(s, -1, "ann", 0, 10, &docs, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 3);
    ck_assert_uint_eq(json_array_size(docs), 3);
    json_decref(docs);
    ck_assert_int_eq(tk_store_list(s, TK_JOB_QUEUED, "bo", 0, 10, &docs, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 1);
    json_decref(docs);
    tk_store_close(&s);
}
END_TEST

/* Per owner, the bytes stored for its jobs (documents, parts, frames)
 * bound its submissions, whatever their state; deleting makes room. */
START_TEST(an_owner_limit_counts_its_stored_bytes)
{
    tk_store *s = open_store();
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_error err;
    json_t *doc = tk_job_new("k", "ann", &o, 1, 3);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 1}, &err), TK_OK);
    int64_t first = tk_job_id(doc), claimed = 0;
    /* one job stored: beyond a limit of 1 byte, not beyond its own size */
    char *text = json_dumps(doc, JSON_COMPACT);
    size_t own = strlen(input) + strlen(text) - 10; /* less its id */
    free(text);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 1}, &err), TK_EBUSY);
    ck_assert_msg(strstr(err.message, "'ann' has stored 1 bytes or more"), "%s", err.message);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 4 * own}, &err),
                     TK_OK);
    json_t *bo = tk_job_new("k", "bo", &o, 1, 3);
    ck_assert_int_eq(tk_store_add(s, bo, input, &(tk_store_limits){1000, 0, 1}, &err), TK_OK);
    /* a frame of a megabyte counts */
    ck_assert_int_eq(tk_store_claim(s, &claimed, &err), TK_OK);
    ck_assert_int_eq(claimed, first);
    json_t *running = get(s, first);
    double *xyz = calloc(3 * 43691, sizeof *xyz);
    tk_frame f = {0, xyz, 3 * 43691, NULL};
    ck_assert_int_eq(tk_store_put(s, running, NULL, &f, 0, 1, 0, NULL, &err), TK_OK);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 1000000}, &err),
                     TK_EBUSY);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 1100000}, &err),
                     TK_OK);
    json_object_set_new(running, "state", json_string("done"));
    ck_assert_int_eq(tk_store_put(s, running, NULL, NULL, 1, 0, 0, NULL, &err), TK_OK); /* frame kept */
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 1000000}, &err),
                     TK_EBUSY); /* ended, but still stored */
    ck_assert_int_eq(tk_store_delete(s, first, &err), TK_OK);
    ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){1000, 0, 1000000}, &err),
                     TK_OK);
    free(xyz);
    json_decref(running);
    json_decref(doc);
    json_decref(bo);
    tk_store_close(&s);
}
END_TEST

START_TEST(the_queue_limit_holds_and_ends_are_final)
{
    tk_store *s = open_store();
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    tk_error err;
    for (int i = 0; i < 4; i++) {
        json_t *doc = tk_job_new("k", NULL, &o, 1, 3);
        ck_assert_int_eq(tk_store_add(s, doc, input, &(tk_store_limits){3, 0, 0}, &err), i < 3 ? TK_OK : TK_EBUSY);
        json_decref(doc);
    }
    ck_assert(strstr(err.message, "queue is full"));
    ck_assert_int_eq(tk_store_cancel(s, 2, &err), TK_OK);
    json_t *doc = get(s, 2);
    ck_assert_str_eq(json_string_value(json_object_get(doc, "state")), "cancelled");
    ck_assert_str_eq(json_string_value(json_object_get(doc, "stop_reason")), "cancelled");
    ck_assert(json_is_string(json_object_get(doc, "finished")));
    json_decref(doc);
    ck_assert_int_eq(tk_store_cancel(s, 2, &err), TK_EINVAL);
    ck_assert_int_eq(tk_store_delete(s, 1, &err), TK_EINVAL); /* queued */
    ck_assert_int_eq(tk_store_delete(s, 2, &err), TK_OK);
    ck_assert_int_eq(tk_store_get(s, 2, &doc, &err), TK_ENOTFOUND);
    tk_store_close(&s);
}
END_TEST

/* An exclusive write transaction left open on another connection: the
 * store's readers go on (WAL: with a rollback journal they would wait out
 * the busy timeout and fail). */
START_TEST(readers_do_not_wait_for_a_writer)
{
    tk_store *s = open_store();
    int64_t id = add_job(s, "k");
    sqlite3 *db = NULL;
    ck_assert_int_eq(sqlite3_open(path, &db), SQLITE_OK);
    ck_assert_int_eq(sqlite3_exec(db, "BEGIN EXCLUSIVE; UPDATE jobs SET curve = 'x';", NULL,
                                  NULL, NULL), SQLITE_OK);
    json_t *docs = NULL;
    size_t total = 0;
    tk_error err;
    char *text = NULL;
    ck_assert_int_eq(tk_store_list(s, -1, NULL, 0, 10, &docs, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 1);
    ck_assert_int_eq(tk_store_part(s, id, TK_PART_CURVE, &text, NULL, &err), TK_OK);
    ck_assert_ptr_null(text); /* not yet committed */
    ck_assert_str_eq(state_of(s, id), "queued");
    json_decref(docs);
    sqlite3_exec(db, "COMMIT", NULL, NULL, NULL);
    sqlite3_close(db);
    tk_store_close(&s);
}
END_TEST

START_TEST(an_unwritable_path_is_an_error)
{
    tk_store *s = NULL;
    tk_error err;
    ck_assert_int_eq(tk_store_open("/nonexistent/dir/jobs.db", 30.0, &s, &err), TK_EIO);
    ck_assert_ptr_null(s);
    ck_assert(strstr(err.message, "/nonexistent/dir/jobs.db"));
}
END_TEST

/* A store of the first version (a column per field, before the type and
 * resume columns) opens as documents with its jobs, parts and frames. */
START_TEST(a_first_version_store_becomes_documents)
{
    sqlite3 *db = NULL;
    ck_assert_int_eq(sqlite3_open(path, &db), SQLITE_OK);
    const char *old =
        "CREATE TABLE jobs (id INTEGER PRIMARY KEY AUTOINCREMENT,"
        " name TEXT NOT NULL, state TEXT NOT NULL, options TEXT NOT NULL,"
        " created REAL NOT NULL, started REAL, finished REAL,"
        " has_figures INTEGER NOT NULL DEFAULT 0,"
        " step INTEGER NOT NULL DEFAULT 0, seconds REAL, ropelength REAL, length REAL,"
        " thickness REAL, minrad REAL, residual REAL, struts INTEGER, kinks INTEGER,"
        " step_size REAL, rcond REAL, violation REAL, corrections INTEGER, vertices INTEGER,"
        " components INTEGER, fraction REAL, stop_reason TEXT, error TEXT,"
        " frames INTEGER NOT NULL DEFAULT 0,"
        " input TEXT NOT NULL, curve TEXT, contacts TEXT, history TEXT);"
        "INSERT INTO jobs (name, state, options, created, finished, step, ropelength, vertices,"
        " components, stop_reason, frames, input, curve) VALUES ('old', 'done',"
        " '{\"steps\": 5, \"radius\": 0.5}', 1700000000.25, 1700000002.5, 5, 33.5, 47, 1,"
        " 'steps', 1, 'VECT in', 'VECT out');"
        "INSERT INTO jobs (name, state, options, created, input) VALUES ('waiting', 'queued',"
        " '{}', 1700000003, 'VECT 2');"
        "CREATE TABLE frames (job INTEGER NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
        " seq INTEGER NOT NULL, step INTEGER NOT NULL, xyz BLOB NOT NULL,"
        " PRIMARY KEY (job, seq));"
        "INSERT INTO frames VALUES (1, 0, 0,"
        " x'000000000000F03F000000000000F03F000000000000F03F');";
    char *message = NULL;
    ck_assert_msg(sqlite3_exec(db, old, NULL, NULL, &message) == SQLITE_OK, "%s", message);
    sqlite3_close(db);

    for (int twice = 0; twice < 2; twice++) {
        tk_store *s = open_store();
        json_t *doc = get(s, 1);
        ck_assert_str_eq(json_string_value(json_object_get(doc, "name")), "old");
        ck_assert_str_eq(json_string_value(json_object_get(doc, "state")), "done");
        ck_assert_int_eq(tk_job_step(doc), 5);
        ck_assert(json_number_value(json_object_get(doc, "ropelength")) == 33.5);
        ck_assert_str_eq(json_string_value(json_object_get(doc, "created")),
                         "2023-11-14T22:13:20.250Z");
        ck_assert_str_eq(json_string_value(json_object_get(doc, "finished")),
                         "2023-11-14T22:13:22.500Z");
        ck_assert(json_is_null(json_object_get(doc, "started")));
        tk_job_options o;
        tk_error err;
        ck_assert_int_eq(tk_job_options_of(doc, &o, &err), TK_OK);
        ck_assert_int_eq(o.run.max_steps, 5);
        json_decref(doc);
        char *text = NULL;
        ck_assert_int_eq(tk_store_part(s, 1, TK_PART_CURVE, &text, NULL, &err), TK_OK);
        ck_assert_str_eq(text, "VECT out");
        free(text);
        ck_assert_int_eq(tk_store_part(s, 1, TK_PART_RESUME, &text, NULL, &err), TK_OK);
        ck_assert_ptr_null(text);
        tk_frame *f = NULL;
        size_t n = 0;
        ck_assert_int_eq(tk_store_frames(s, 1, 0, 10, &f, &n, &err), TK_OK);
        ck_assert_uint_eq(n, 1);
        ck_assert(f[0].count == 3 && f[0].xyz[0] == 1.0 && f[0].xyz[2] == 1.0);
        tk_frames_free(f, n);
        int64_t id;
        ck_assert_int_eq(tk_store_claim(s, &id, &err), TK_OK);
        ck_assert_int_eq(id, twice ? 3 : 2); /* the old queued job, then the new one */
        ck_assert_int_eq(add_job(s, "new"), 3 + twice);
        tk_store_close(&s);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("store");
    TCase *tc = tcase_create("sqlite");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, a_job_reads_back_after_reopening);
    tcase_add_test(tc, a_running_job_is_its_holders);
    tcase_add_test(tc, missing_jobs_are_not_found);
    tcase_add_test(tc, listing_is_newest_first_filtered_and_paged);
    tcase_add_test(tc, claims_take_each_queued_job_once_oldest_first);
    tcase_add_test(tc, the_queue_limit_holds_and_ends_are_final);
    tcase_add_test(tc, an_owner_limit_counts_its_queued_and_running_jobs);
    tcase_add_test(tc, an_owner_limit_counts_its_stored_bytes);
    tcase_add_test(tc, readers_do_not_wait_for_a_writer);
    tcase_add_test(tc, an_unwritable_path_is_an_error);
    tcase_add_test(tc, a_first_version_store_becomes_documents);
    suite_add_tcase(s, tc);
    /* the same on PostgreSQL, where the tests have a server */
    if (getenv("TK_PG_URL") && *getenv("TK_PG_URL")) {
        TCase *pg = tcase_create("postgresql");
        tcase_add_checked_fixture(pg, pg_setup, pg_teardown);
        tcase_add_test(pg, a_job_reads_back_after_reopening);
        tcase_add_test(pg, a_running_job_is_its_holders);
        tcase_add_test(pg, missing_jobs_are_not_found);
        tcase_add_test(pg, listing_is_newest_first_filtered_and_paged);
        tcase_add_test(pg, claims_take_each_queued_job_once_oldest_first);
        tcase_add_test(pg, the_queue_limit_holds_and_ends_are_final);
        tcase_add_test(pg, an_owner_limit_counts_its_queued_and_running_jobs);
        tcase_add_test(pg, an_owner_limit_counts_its_stored_bytes);
        tcase_add_test(pg, a_lapsed_claim_goes_to_another_store);
        suite_add_tcase(s, pg);
    } else {
        printf("SKIP store: the PostgreSQL cases (TK_PG_URL is not set)\n");
    }
    return tkt_run_suite(s);
}
