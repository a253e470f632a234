/* Tests for the SQLite job store (server/store.c): what is stored reads
 * back the same after closing and opening the file again, listing is
 * newest first with a filter and pages, frames come back bit for bit, and
 * the unfinished jobs are the queued and running ones, oldest first; a
 * store written before the invariants column gets it and keeps its jobs. */
#include <check.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "support.h"
#include "tk/store.h"

static char dir[64];
static char path[128];

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/tk-store-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/jobs.db", dir);
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

static tk_store *open_store(void)
{
    tk_store *s = NULL;
    tk_error err;
    ck_assert_msg(tk_store_open(path, &s, &err) == TK_OK, "%s", err.message);
    return s;
}

static int64_t add_job(tk_store *s, const char *name, tk_job_state state)
{
    tk_job j;
    memset(&j, 0, sizeof j);
    snprintf(j.name, sizeof j.name, "%s", name);
    j.state = state;
    tk_job_options o = TK_JOB_OPTIONS_INIT;
    o.run.max_steps = 77;
    o.run.resolution = 5;
    j.options = o;
    j.created = 1.7e9;
    tk_error err;
    ck_assert_msg(tk_store_insert(s, &j, "VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n", &err) ==
                      TK_OK,
                  "%s", err.message);
    ck_assert_int_gt(j.id, 0);
    j.fraction = -1.0;
    ck_assert_int_eq(tk_store_update(s, &j, &err), TK_OK);
    return j.id;
}

START_TEST(a_job_reads_back_after_reopening)
{
    tk_store *s = open_store();
    int64_t id = add_job(s, "trefoil", TK_JOB_QUEUED);
    tk_job j;
    tk_error err;
    ck_assert_int_eq(tk_store_get(s, id, &j, &err), TK_OK);
    j.state = TK_JOB_DONE;
    j.started = 1.7e9 + 1.0;
    j.finished = 1.7e9 + 2.5;
    j.has_figures = true;
    j.latest.step = 77;
    j.latest.seconds = 1.25;
    j.latest.ropelength = 32.7523560914;
    j.latest.thickness = 1.0;
    j.latest.length = 16.3761780457;
    j.latest.minrad = 0.6;
    j.latest.residual = 0.01;
    j.latest.struts = 12;
    j.latest.kinks = 1;
    j.latest.vertices = 184;
    j.components = 1;
    j.fraction = 1.0;
    snprintf(j.stop_reason, sizeof j.stop_reason, "steps");
    double xyz[2][9];
    for (int f = 0; f < 2; f++)
        for (int k = 0; k < 9; k++)
            xyz[f][k] = sin(1.0 + f * 9 + k) / 3.0; /* not short decimals */
    /* frames of two layouts: one stored before frames had their own */
    tk_store_frame frames[2] = {{10, xyz[0], 9, NULL}, {20, xyz[1], 6, (char *)"[2]"}};
    j.frames = 2;
    char *none = (char *)"not read";
    ck_assert_int_eq(tk_store_text(s, id, TK_TEXT_INVARIANTS, &none, NULL, &err), TK_OK);
    ck_assert_ptr_null(none); /* before the run starts */
    const char *type = "{\"start\":{\"determinants\":[3]},\"result\":null}";
    const char *texts[TK_TEXTS] = {NULL, "VECT curve", "{\"struts\":[]}", "[]", type,
                                   "{\"at\":{}}"};
    ck_assert_int_eq(tk_store_save(s, &j, texts, frames, 2, &err), TK_OK);
    tk_store_close(&s);

    s = open_store();
    tk_job back;
    ck_assert_int_eq(tk_store_get(s, id, &back, &err), TK_OK);
    ck_assert_str_eq(back.name, "trefoil");
    ck_assert_int_eq(back.state, TK_JOB_DONE);
    ck_assert_int_eq(back.options.run.max_steps, 77);
    ck_assert(back.options.run.resolution == 5.0);
    ck_assert(back.latest.ropelength == 32.7523560914);
    ck_assert(back.latest.length == 16.3761780457);
    ck_assert(back.started == 1.7e9 + 1.0 && back.finished == 1.7e9 + 2.5);
    ck_assert_uint_eq(back.latest.struts, 12);
    ck_assert_uint_eq(back.latest.vertices, 184);
    ck_assert(back.has_figures);
    ck_assert_str_eq(back.stop_reason, "steps");
    ck_assert_str_eq(back.error, "");
    ck_assert_uint_eq(back.frames, 2);
    char *text = NULL;
    ck_assert_int_eq(tk_store_text(s, id, TK_TEXT_CURVE, &text, NULL, &err), TK_OK);
    ck_assert_str_eq(text, "VECT curve");
    free(text);
    ck_assert_int_eq(tk_store_text(s, id, TK_TEXT_INPUT, &text, NULL, &err), TK_OK);
    ck_assert(strncmp(text, "VECT\n1 3 0", 10) == 0);
    free(text);
    ck_assert_int_eq(tk_store_text(s, id, TK_TEXT_INVARIANTS, &text, NULL, &err), TK_OK);
    ck_assert_str_eq(text, type);
    free(text);
    ck_assert_int_eq(tk_store_text(s, id, TK_TEXT_RESUME, &text, NULL, &err), TK_OK);
    ck_assert_str_eq(text, "{\"at\":{}}");
    free(text);
    tk_store_frame *back_frames = NULL;
    size_t n = 0;
    ck_assert_int_eq(tk_store_frames(s, id, 0, 5, &back_frames, &n, &err), TK_OK);
    ck_assert_uint_eq(n, 2);
    ck_assert_int_eq(back_frames[0].step, 10);
    ck_assert_uint_eq(back_frames[0].count, 9);
    ck_assert_ptr_null(back_frames[0].layout);
    ck_assert(memcmp(back_frames[0].xyz, xyz[0], sizeof xyz[0]) == 0);
    ck_assert_int_eq(back_frames[1].step, 20);
    ck_assert_uint_eq(back_frames[1].count, 6);
    ck_assert_str_eq(back_frames[1].layout, "[2]");
    ck_assert(memcmp(back_frames[1].xyz, xyz[1], 6 * sizeof(double)) == 0);
    tk_store_frames_free(back_frames, n);
    /* a page from the middle */
    ck_assert_int_eq(tk_store_frames(s, id, 1, 5, &back_frames, &n, &err), TK_OK);
    ck_assert_uint_eq(n, 1);
    ck_assert_int_eq(back_frames[0].step, 20);
    tk_store_frames_free(back_frames, n);
    tk_store_close(&s);
}
END_TEST

START_TEST(missing_jobs_are_not_found)
{
    tk_store *s = open_store();
    tk_job j;
    tk_error err;
    ck_assert_int_eq(tk_store_get(s, 42, &j, &err), TK_ENOTFOUND);
    ck_assert(strstr(err.message, "42"));
    char *text = NULL;
    ck_assert_int_eq(tk_store_text(s, 42, TK_TEXT_INPUT, &text, NULL, &err), TK_ENOTFOUND);
    memset(&j, 0, sizeof j);
    j.id = 42;
    ck_assert_int_eq(tk_store_update(s, &j, &err), TK_ENOTFOUND);
    tk_store_close(&s);
}
END_TEST

START_TEST(listing_is_newest_first_filtered_and_paged)
{
    tk_store *s = open_store();
    int64_t ids[7];
    tk_job_state states[7] = {TK_JOB_DONE,    TK_JOB_QUEUED, TK_JOB_DONE,  TK_JOB_RUNNING,
                              TK_JOB_FAILED,  TK_JOB_DONE,   TK_JOB_QUEUED};
    for (int i = 0; i < 7; i++) {
        char name[16];
        snprintf(name, sizeof name, "k%d", i);
        ids[i] = add_job(s, name, states[i]);
    }
    tk_job *jobs = NULL;
    size_t n = 0, total = 0;
    tk_error err;
    ck_assert_int_eq(tk_store_list(s, false, 0, 0, 3, &jobs, &n, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 7);
    ck_assert_uint_eq(n, 3);
    ck_assert(jobs[0].id == ids[6] && jobs[1].id == ids[5] && jobs[2].id == ids[4]);
    free(jobs);
    ck_assert_int_eq(tk_store_list(s, true, TK_JOB_DONE, 1, 10, &jobs, &n, &total, &err), TK_OK);
    ck_assert_uint_eq(total, 3);
    ck_assert_uint_eq(n, 2);
    ck_assert(jobs[0].id == ids[2] && jobs[1].id == ids[0]);
    free(jobs);
    int64_t *open = NULL;
    ck_assert_int_eq(tk_store_unfinished(s, &open, &n, &err), TK_OK);
    ck_assert_uint_eq(n, 3);
    ck_assert(open[0] == ids[1] && open[1] == ids[3] && open[2] == ids[6]);
    free(open);
    size_t counts[TK_JOB_STATES];
    ck_assert_int_eq(tk_store_count_states(s, counts, &err), TK_OK);
    ck_assert_uint_eq(counts[TK_JOB_DONE], 3);
    ck_assert_uint_eq(counts[TK_JOB_QUEUED], 2);
    ck_assert_uint_eq(counts[TK_JOB_RUNNING], 1);
    ck_assert_uint_eq(counts[TK_JOB_FAILED], 1);
    ck_assert_uint_eq(counts[TK_JOB_CANCELLED], 0);
    tk_store_close(&s);
}
END_TEST

START_TEST(state_names_round_trip)
{
    for (int i = 0; i < TK_JOB_STATES; i++) {
        tk_job_state back;
        ck_assert(tk_job_state_parse(tk_job_state_name((tk_job_state)i), &back));
        ck_assert_int_eq(back, i);
    }
    tk_job_state x;
    ck_assert(!tk_job_state_parse("finished", &x));
    ck_assert(tk_job_state_final(TK_JOB_CANCELLED) && !tk_job_state_final(TK_JOB_RUNNING));
}
END_TEST

START_TEST(an_unwritable_path_is_an_error)
{
    tk_store *s = NULL;
    tk_error err;
    ck_assert_int_eq(tk_store_open("/nonexistent-dir/x/jobs.db", &s, &err), TK_EIO);
    ck_assert_ptr_null(s);
    ck_assert(strstr(err.message, "/nonexistent-dir/x/jobs.db"));
}
END_TEST

/* The tables as the first version of the store made them, with one
 * finished job and its frame: opened by this one, the job reads back,
 * has no type or resume point stored, and takes one; its frame has no
 * layout of its own (it has the job's curve's). */
START_TEST(an_older_store_gets_the_invariants_column)
{
    sqlite3 *db = NULL;
    ck_assert_int_eq(sqlite3_open(path, &db), SQLITE_OK);
    const char *old =
        "CREATE TABLE jobs ("
        " id INTEGER PRIMARY KEY AUTOINCREMENT,"
        " name TEXT NOT NULL, state TEXT NOT NULL, options TEXT NOT NULL,"
        " created REAL NOT NULL, started REAL, finished REAL,"
        " has_figures INTEGER NOT NULL DEFAULT 0,"
        " step INTEGER NOT NULL DEFAULT 0, seconds REAL, ropelength REAL, length REAL,"
        " thickness REAL, minrad REAL, residual REAL, struts INTEGER, kinks INTEGER,"
        " step_size REAL, rcond REAL, violation REAL, corrections INTEGER, vertices INTEGER,"
        " components INTEGER, fraction REAL, stop_reason TEXT, error TEXT,"
        " frames INTEGER NOT NULL DEFAULT 0,"
        " input TEXT NOT NULL, curve TEXT, contacts TEXT, history TEXT);"
        "INSERT INTO jobs (name, state, options, created, step, ropelength, input, curve)"
        " VALUES ('old', 'done', '{\"steps\": 5}', 1.7e9, 5, 33.5, 'VECT in', 'VECT out');"
        "CREATE TABLE frames ("
        " job INTEGER NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
        " seq INTEGER NOT NULL, step INTEGER NOT NULL, xyz BLOB NOT NULL,"
        " PRIMARY KEY (job, seq));"
        "INSERT INTO frames VALUES (1, 0, 0,"
        " x'000000000000F03F000000000000F03F000000000000F03F');";
    char *message = NULL;
    ck_assert_msg(sqlite3_exec(db, old, NULL, NULL, &message) == SQLITE_OK, "%s", message);
    sqlite3_close(db);

    tk_store *s = open_store();
    tk_job j;
    tk_error err;
    ck_assert_int_eq(tk_store_get(s, 1, &j, &err), TK_OK);
    ck_assert_str_eq(j.name, "old");
    ck_assert_int_eq(j.state, TK_JOB_DONE);
    ck_assert_int_eq(j.latest.step, 5);
    ck_assert(j.latest.ropelength == 33.5);
    char *text = (char *)"not read";
    ck_assert_int_eq(tk_store_text(s, 1, TK_TEXT_INVARIANTS, &text, NULL, &err), TK_OK);
    ck_assert_ptr_null(text);
    ck_assert_int_eq(tk_store_text(s, 1, TK_TEXT_RESUME, &text, NULL, &err), TK_OK);
    ck_assert_ptr_null(text);
    tk_store_frame *frames = NULL;
    size_t n = 0;
    ck_assert_int_eq(tk_store_frames(s, 1, 0, 10, &frames, &n, &err), TK_OK);
    ck_assert_uint_eq(n, 1);
    ck_assert_uint_eq(frames[0].count, 3);
    ck_assert(frames[0].xyz[0] == 1.0 && frames[0].xyz[2] == 1.0);
    ck_assert_ptr_null(frames[0].layout);
    tk_store_frames_free(frames, n);
    const char *texts[TK_TEXTS] = {NULL};
    texts[TK_TEXT_INVARIANTS] = "{\"start\":null}";
    ck_assert_int_eq(tk_store_save(s, &j, texts, NULL, 0, &err), TK_OK);
    tk_store_close(&s);
    /* opening it again adds nothing more */
    s = open_store();
    ck_assert_int_eq(tk_store_text(s, 1, TK_TEXT_INVARIANTS, &text, NULL, &err), TK_OK);
    ck_assert_str_eq(text, "{\"start\":null}");
    free(text);
    ck_assert_int_eq(tk_store_text(s, 1, TK_TEXT_CURVE, &text, NULL, &err), TK_OK);
    ck_assert_str_eq(text, "VECT out");
    free(text);
    tk_store_close(&s);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("store");
    TCase *tc = tcase_create("store");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, a_job_reads_back_after_reopening);
    tcase_add_test(tc, missing_jobs_are_not_found);
    tcase_add_test(tc, listing_is_newest_first_filtered_and_paged);
    tcase_add_test(tc, state_names_round_trip);
    tcase_add_test(tc, an_unwritable_path_is_an_error);
    tcase_add_test(tc, an_older_store_gets_the_invariants_column);
    suite_add_tcase(s, tc);
    return tkt_run_suite(s);
}
