/* Tests for the VECT reader and writer (engine/vect.c): the catalogue round
 * trip, the accepted layouts, one test per malformed case (code, line and
 * key phrase of the message), and a deterministic mutation fuzz loop. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "support.h"
#include "tk/vect.h"

#if defined(__SANITIZE_ADDRESS__)
#define TKT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TKT_ASAN 1
#endif
#endif
#ifndef TKT_ASAN
#define TKT_ASAN 0
#endif

/* ---------------------------------------------------------------- helpers */

/* Parses exactly len bytes from a heap copy with no terminating NUL, so the
 * sanitizer build catches any read past the end. */
static int parse_bytes(const char *text, size_t len, const tk_vect_limits *lim,
                       tk_curve **out, tk_error *err)
{
    char *copy = malloc(len ? len : 1);
    ck_assert_ptr_nonnull(copy);
    if (len)
        memcpy(copy, text, len);
    int rc = tk_vect_parse(copy, len, lim, out, err);
    free(copy);
    return rc;
}

static tk_curve *parse_ok(const char *text)
{
    tk_curve *c = NULL;
    tk_error err;
    int rc = parse_bytes(text, strlen(text), NULL, &c, &err);
    ck_assert_msg(rc == TK_OK, "expected success, got %s: %s", tk_status_name(rc),
                  err.message);
    ck_assert_ptr_nonnull(c);
    ck_assert_int_eq(tk_curve_validate(c, NULL), TK_OK);
    return c;
}

/* Asserts that parsing fails with `code`, that the message names `line`
 * exactly ("line 7:") and contains `phrase`. */
static void expect_fail_len(const char *text, size_t len, const tk_vect_limits *lim,
                            int code, size_t line, const char *phrase)
{
    tk_curve *c = (tk_curve *)&c; /* must be reset to NULL */
    tk_error err;
    int rc = parse_bytes(text, len, lim, &c, &err);
    ck_assert_msg(rc == code, "expected %s, got %s: %s", tk_status_name(code),
                  tk_status_name(rc), rc ? err.message : "(no message)");
    ck_assert_ptr_null(c);
    ck_assert_int_eq(err.code, code);
    char want[32];
    snprintf(want, sizeof want, "line %zu:", line);
    ck_assert_msg(strncmp(err.message, want, strlen(want)) == 0,
                  "message should start with '%s': %s", want, err.message);
    ck_assert_msg(strstr(err.message, phrase) != NULL,
                  "message should contain '%s': %s", phrase, err.message);
}

static void expect_fail(const char *text, int code, size_t line, const char *phrase)
{
    expect_fail_len(text, strlen(text), NULL, code, line, phrase);
}

static void assert_same_curve(const tk_curve *a, const tk_curve *b, const char *what)
{
    ck_assert_msg(a->ncomp == b->ncomp, "%s: components %zu vs %zu", what, a->ncomp,
                  b->ncomp);
    ck_assert_msg(a->nvert == b->nvert, "%s: vertices %zu vs %zu", what, a->nvert,
                  b->nvert);
    for (size_t i = 0; i < a->ncomp; i++) {
        ck_assert_msg(a->closed[i] == b->closed[i], "%s: closedness of %zu", what, i);
        ck_assert_msg(tk_curve_comp_vertices(a, i) == tk_curve_comp_vertices(b, i),
                      "%s: vertex count of component %zu", what, i);
    }
    ck_assert_msg(memcmp(a->xyz, b->xyz, 3 * a->nvert * sizeof *a->xyz) == 0,
                  "%s: coordinates differ", what);
    ck_assert_msg(a->has_colour == b->has_colour, "%s: has_colour", what);
    if (a->has_colour)
        ck_assert_msg(memcmp(a->colour, b->colour, 4 * a->ncomp * sizeof *a->colour) == 0,
                      "%s: colours differ", what);
}

static tk_curve *roundtrip(const tk_curve *c)
{
    char *text = NULL;
    size_t len = 0;
    tk_error err;
    int rc = tk_vect_to_string(c, &text, &len, &err);
    ck_assert_msg(rc == TK_OK, "to_string: %s", err.message);
    ck_assert_uint_eq(strlen(text), len);
    tk_curve *back = NULL;
    rc = parse_bytes(text, len, NULL, &back, &err);
    ck_assert_msg(rc == TK_OK, "reparse: %s\n%s", err.message, text);
    free(text);
    return back;
}

static bool vertex_is(const tk_curve *c, size_t v, double x, double y, double z)
{
    const double *p = tk_curve_vertex(c, v);
    return p[0] == x && p[1] == y && p[2] == z;
}

/* A long buffer: prefix, n copies of fill, suffix. */
static char *build_long(const char *prefix, char fill, size_t n, const char *suffix,
                        size_t *len)
{
    size_t lp = strlen(prefix), ls = strlen(suffix);
    char *s = malloc(lp + n + ls + 1);
    ck_assert_ptr_nonnull(s);
    memcpy(s, prefix, lp);
    memset(s + lp, fill, n);
    memcpy(s + lp + n, suffix, ls + 1);
    *len = lp + n + ls;
    return s;
}

/* Two components, open and closed, with colours: the fuzz seed. */
static const char SEED[] =
    "VECT # header\n"
    "2 7 2\n"
    "-4 3\n"
    "1 1\n"
    "0 0 0\n"
    "1 0 0\n"
    "1 1 0\n"
    "0 1 0.5\n"
    "2 2 2\n"
    "3 2.5 2\n"
    "4 3 -1e-3\n"
    "1 0 0 1\n"
    "0 0.5 1 1\n";

/* ---------------------------------------------------------------- catalogue */

START_TEST(test_catalogue_roundtrip)
{
    const char *dir = tkt_catalogue_dir();
    if (!dir) {
        tkt_skip("test_catalogue_roundtrip", "the catalogue is absent");
        return;
    }
    size_t count = 0;
    char **names = tkt_catalogue_names(&count);
    ck_assert_msg(count > 390, "only %zu catalogue files", count);
    for (size_t i = 0; i < count; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        tk_curve *c = NULL;
        tk_error err;
        int rc = tk_vect_read_file(path, NULL, &c, &err);
        ck_assert_msg(rc == TK_OK, "%s", err.message);
        ck_assert_uint_ge(c->ncomp, 1);
        tk_curve *back = roundtrip(c);
        assert_same_curve(c, back, names[i]);
        /* Writing the re-read curve gives the same text again. */
        char *t1 = NULL, *t2 = NULL;
        ck_assert_int_eq(tk_vect_to_string(c, &t1, NULL, NULL), TK_OK);
        ck_assert_int_eq(tk_vect_to_string(back, &t2, NULL, NULL), TK_OK);
        ck_assert_msg(strcmp(t1, t2) == 0, "%s: text not stable", names[i]);
        free(t1);
        free(t2);
        tk_curve_free(&back);
        tk_curve_free(&c);
    }
    tkt_free_names(names, count);
}
END_TEST

START_TEST(test_catalogue_known_files)
{
    if (!tkt_catalogue_dir()) {
        tkt_skip("test_catalogue_known_files", "the catalogue is absent");
        return;
    }
    tk_curve *c = tkt_catalogue_curve("3.1.vect");
    ck_assert_uint_eq(c->ncomp, 1);
    ck_assert_uint_eq(c->nvert, 47);
    ck_assert(c->closed[0]);
    ck_assert(vertex_is(c, 0, -5.00478, -2.20299, 0.670091));
    ck_assert(c->has_colour);
    ck_assert(c->colour[0] == 0 && c->colour[1] == 1 && c->colour[2] == 1 &&
              c->colour[3] == 1);
    tk_curve_free(&c);

    /* Two open arcs, comments after the counts, colours with a comment. */
    c = tkt_catalogue_curve("simple_clasp.vect");
    ck_assert_uint_eq(c->ncomp, 2);
    ck_assert_uint_eq(c->nvert, 71);
    ck_assert(!c->closed[0] && !c->closed[1]);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 0), 33);
    ck_assert(vertex_is(c, 0, -6.986076801297173, 12.30834018195552, 5.00854481029404));
    tk_curve_free(&c);

    /* One colour per vertex: the component keeps its first. */
    c = tkt_catalogue_curve("sticktrefoil.vect");
    ck_assert_uint_eq(c->nvert, 6);
    ck_assert(c->has_colour);
    ck_assert(c->colour[0] == 0.984313725490196 && c->colour[3] == 1.0);
    tk_curve_free(&c);
}
END_TEST

/* ---------------------------------------------------------------- accepted */

START_TEST(test_roundtrip_extreme_values)
{
    tkt_rng rng = {42};
    size_t counts[3] = {5, 4, 7};
    bool closed[3] = {true, false, true};
    tk_curve *c = NULL;
    ck_assert_int_eq(tk_curve_new(&c, 3, counts, closed, NULL), TK_OK);
    for (size_t v = 0; v < c->nvert; v++)
        tkt_rng_point(&rng, 10.0, tk_curve_vertex(c, v));
    double *x = c->xyz;
    x[0] = -0.0;
    x[1] = 4.9406564584124654e-324; /* smallest subnormal */
    x[2] = 1.7976931348623157e308;
    x[3] = 0.1;
    x[4] = -1e-300;
    x[5] = 1.0 / 3.0;
    x[6] = 2.2250738585072014e-308;
    x[7] = 123456789.12345678;
    x[8] = -9.999999999999999e22;
    c->colour = malloc(12 * sizeof *c->colour);
    ck_assert_ptr_nonnull(c->colour);
    for (int k = 0; k < 12; k++)
        c->colour[k] = tkt_rng_uniform(&rng);
    c->has_colour = true;
    ck_assert_int_eq(tk_curve_validate(c, NULL), TK_OK);
    tk_curve *back = roundtrip(c);
    assert_same_curve(c, back, "extreme values");
    ck_assert(signbit(back->xyz[0]));
    tk_curve_free(&back);

    c->has_colour = false;
    back = roundtrip(c);
    ck_assert(!back->has_colour);
    ck_assert_ptr_null(back->colour);
    tk_curve_free(&back);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_write_exact_text)
{
    tk_curve *c = parse_ok("VECT\n2 5 0\n-3 2\n0 0\n"
                           "0 0 0  1 0 0  0 1 0\n"
                           "0 0 1  0.5 0.25 -2\n");
    char *text = NULL;
    size_t len = 0;
    ck_assert_int_eq(tk_vect_to_string(c, &text, &len, NULL), TK_OK);
    ck_assert_str_eq(text, "VECT\n2 5 0\n-3 2\n0 0\n"
                           "0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0.25 -2\n");
    free(text);
    c->colour = malloc(8 * sizeof *c->colour);
    ck_assert_ptr_nonnull(c->colour);
    const double rgba[8] = {1, 0, 0, 1, 0, 0.5, 1, 0.75};
    memcpy(c->colour, rgba, sizeof rgba);
    c->has_colour = true;
    ck_assert_int_eq(tk_vect_to_string(c, &text, &len, NULL), TK_OK);
    ck_assert_str_eq(text, "VECT\n2 5 2\n-3 2\n1 1\n"
                           "0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0.25 -2\n"
                           "1 0 0 1\n0 0.5 1 0.75\n");
    free(text);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_comments_in_odd_places)
{
    tk_curve *c = parse_ok("# leading comment\n"
                           "\n"
                           "VECT#glued to the header\n"
                           "# between header and counts\n"
                           "1 # components\n"
                           "3 # vertices ### more hashes\n"
                           "0\n"
                           "-3#closed\n"
                           "0 # no colours\n"
                           "0 0 # half a vertex\n"
                           "0 # the rest of it\n"
                           "1#x\n0#y\n0#z\n"
                           "0 1 0 # no newline at the end");
    ck_assert_uint_eq(c->nvert, 3);
    ck_assert(c->closed[0]);
    ck_assert(vertex_is(c, 1, 1, 0, 0));
    ck_assert(vertex_is(c, 2, 0, 1, 0));
    ck_assert(!c->has_colour);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_header_trailing_spaces)
{
    tk_curve *c = parse_ok("VECT   \t # trailing comment\n1 2 0\n2\n0\n0 0 0 1 1 1\n");
    ck_assert(!c->closed[0]);
    ck_assert_uint_eq(c->nvert, 2);
    tk_curve_free(&c);
    /* Everything on one line is still the same token stream. */
    c = parse_ok("VECT 1 2 0 2 0 0 0 0 1 1 1");
    ck_assert_uint_eq(c->nvert, 2);
    tk_curve_free(&c);
    /* A UTF-8 byte order mark before the header is skipped. */
    c = parse_ok("\xEF\xBB\xBFVECT\n1 2 0\n2\n0\n0 0 0 1 1 1\n");
    ck_assert_uint_eq(c->nvert, 2);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_wrapped_coordinates)
{
    tk_curve *c = parse_ok("VECT\n1\n4\n0\n4\n0\n"
                           "0\n0\n0\n"
                           "1 0\n0 2\n0 0\n"
                           "3 3 3\n");
    ck_assert(vertex_is(c, 1, 1, 0, 0));
    ck_assert(vertex_is(c, 2, 2, 0, 0));
    ck_assert(vertex_is(c, 3, 3, 3, 3));
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_tabs_crlf_and_friends)
{
    tk_curve *c = parse_ok("VECT\r\n1\t3\t0\r\n-3\r\n0\r\n"
                           "0\t0\t0\r\n\f1\v0\t0\r\n0 1 0\r\n");
    ck_assert_uint_eq(c->nvert, 3);
    ck_assert(vertex_is(c, 1, 1, 0, 0));
    tk_curve_free(&c);
    /* Line numbers count CRLF once and a lone CR as a line end. */
    expect_fail("VECT\r\n1 3 0\r\n-3\r\n0\r\n0 0 0\r\n1 0 0\r\n0 x 0\r\n", TK_EPARSE, 7,
                "found 'x'");
    expect_fail("VECT\r1 3 0\r-3\r0\r0 0 0\r1 0 0\r0 x 0\r", TK_EPARSE, 7, "found 'x'");
}
END_TEST

START_TEST(test_not_nul_terminated)
{
    /* The bytes after len are not part of the text. */
    const char text[] = "VECT\n1 3 0\n-3\n0\n0 0 0 1 0 0 0 1 05 GARBAGE";
    size_t len = strlen(text) - strlen("5 GARBAGE");
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(parse_bytes(text, len, NULL, &c, &err), TK_OK);
    ck_assert(vertex_is(c, 2, 0, 1, 0));
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_mixed_open_closed)
{
    tk_curve *c = parse_ok("VECT\n3 10 0\n-3 2 -5\n0 0 0\n"
                           "0 0 0  1 0 0  0 1 0\n"
                           "5 5 5  6 5 5\n"
                           "0 0 9  1 0 9  1 1 9  0 1 9  0.5 0.5 10\n");
    ck_assert_uint_eq(c->ncomp, 3);
    ck_assert(c->closed[0] && !c->closed[1] && c->closed[2]);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 0), 3);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 1), 2);
    ck_assert_uint_eq(tk_curve_comp_vertices(c, 2), 5);
    ck_assert_uint_eq(tk_curve_edge_count(c), 3 + 1 + 5);
    ck_assert(vertex_is(c, 4, 6, 5, 5));
    tk_curve_free(&c);
    /* An open component may end where it starts: there is no closing edge. */
    c = parse_ok("VECT\n1 3 0\n3\n0\n0 0 0 1 0 0 0 0 0\n");
    ck_assert(!c->closed[0]);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_colours_per_vertex)
{
    tk_curve *c = parse_ok("VECT\n2 6 6\n-3 3\n3 3\n"
                           "0 0 0 1 0 0 0 1 0\n"
                           "5 5 5 6 5 5 7 6 5\n"
                           "0.1 0.2 0.3 1\n0 0 0 1\n0 0 0 1\n"
                           "0.4 0.5 0.6 0.5\n1 1 1 1\n1 1 1 1\n");
    ck_assert(c->has_colour);
    const double want[8] = {0.1, 0.2, 0.3, 1, 0.4, 0.5, 0.6, 0.5};
    ck_assert(memcmp(c->colour, want, sizeof want) == 0);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_colours_one_total)
{
    /* One colour for the first component; the next inherits it (Geomview). */
    tk_curve *c = parse_ok("VECT\n2 6 1\n-3 -3\n1 0\n"
                           "0 0 0 1 0 0 0 1 0\n"
                           "5 5 5 6 5 5 5 6 5\n"
                           "0.25 0.5 0.75 1\n");
    ck_assert(c->has_colour);
    const double want[8] = {0.25, 0.5, 0.75, 1, 0.25, 0.5, 0.75, 1};
    ck_assert(memcmp(c->colour, want, sizeof want) == 0);
    tk_curve_free(&c);
    /* A colourless first component takes the first colour in the file. */
    c = parse_ok("VECT\n3 9 2\n-3 -3 -3\n0 1 1\n"
                 "0 0 0 1 0 0 0 1 0\n"
                 "5 5 5 6 5 5 5 6 5\n"
                 "9 9 9 8 9 9 9 8 9\n"
                 "1 0 0 1\n0 1 0 1\n");
    const double want3[12] = {1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1};
    ck_assert(memcmp(c->colour, want3, sizeof want3) == 0);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_colours_none)
{
    tk_curve *c = parse_ok("VECT\n2 6 0\n-3 -3\n0 0\n"
                           "0 0 0 1 0 0 0 1 0\n"
                           "5 5 5 6 5 5 5 6 5\n");
    ck_assert(!c->has_colour);
    ck_assert_ptr_null(c->colour);
    tk_curve_free(&c);
}
END_TEST

START_TEST(test_leading_zeros_and_signs)
{
    tk_curve *c = parse_ok("VECT\n+1 0003 00\n-03\n0\n"
                           "+0 -0 0e0  1E0 .0 0.  0x1p-1 1e-400 -0.0\n");
    ck_assert_uint_eq(c->nvert, 3);
    ck_assert(vertex_is(c, 1, 1, 0, 0));
    ck_assert(vertex_is(c, 2, 0.5, 0, 0));
    tk_curve_free(&c);
}
END_TEST

/* ---------------------------------------------------------------- malformed */

START_TEST(test_bad_header)
{
    expect_fail("VECTOR\n1 2 0\n2\n0\n0 0 0 1 1 1\n", TK_EPARSE, 1, "expected the header 'VECT'");
    expect_fail("# comment\n\nvect\n1 2 0\n2\n0\n0 0 0 1 1 1\n", TK_EPARSE, 3,
                "found 'vect'");
    expect_fail("1 2 0\n2\n0\n0 0 0 1 1 1\n", TK_EPARSE, 1, "found '1'");
    expect_fail("VECT\nBINARY\n", TK_EPARSE, 2,
                "expected the number of components (an integer), found 'BINARY'");
    expect_fail("VECT\n1.0 2 0\n2\n0\n0 0 0 1 1 1\n", TK_EPARSE, 2, "found '1.0'");
}
END_TEST

START_TEST(test_vertex_sum_mismatch)
{
    /* Enough text for 7 vertices, so that only the sum is wrong. */
    expect_fail("VECT\n2 7 0\n-3 3\n0 0\n"
                "0.0 0.0 0.0 1.0 0.0 0.0 0.0 1.0 0.0 5.0 5.0 5.0 6.0 5.0 5.0 7.0 7.0 7.0\n",
                TK_EPARSE, 3, "add up to 6, but the header (line 2) says 7 vertices");
    expect_fail("VECT\n2 5 0\n-3\n3\n0 0\n0 0 0 1 0 0 0 1 0 5 5 5 6 5 5 7 7 7\n",
                TK_EPARSE, 4, "more than the 5 vertices in the header (line 2)");
}
END_TEST

START_TEST(test_colour_sum_mismatch)
{
    expect_fail("VECT\n2 6 3\n-3 -3\n1\n1\n"
                "0 0 0 1 0 0 0 1 0 5 5 5 6 5 5 5 6 5\n1 0 0 1\n0 1 0 1\n0 0 1 1\n",
                TK_EPARSE, 5, "the colour counts add up to 2, but the header (line 2) says 3");
    expect_fail("VECT\n2 6 1\n-3 -3\n1\n1\n"
                "0 0 0 1 0 0 0 1 0 5 5 5 6 5 5 5 6 5\n1 0 0 1\n0 1 0 1\n",
                TK_EPARSE, 5, "more than the 1 colours in the header (line 2)");
}
END_TEST

START_TEST(test_colour_count_rule)
{
    expect_fail("VECT\n1 4 2\n-4\n2\n0 0 0 1 0 0 1 1 0 0 1 0\n1 0 0 1 0 1 0 1\n",
                TK_EPARSE, 4, "component 0 has 2 colours; it must have 0, 1 or 4");
    expect_fail("VECT\n1 4 0\n-4\n-1\n0 0 0 1 0 0 1 1 0 0 1 0\n", TK_EPARSE, 4,
                "colour count of component 0 is negative");
    expect_fail("VECT\n1 3 4\n-3\n1\n0 0 0 1 0 0 0 1 0\n1 0 0 1\n", TK_EPARSE, 2,
                "at most one colour per vertex");
    expect_fail("VECT\n1 3 -1\n-3\n0\n0 0 0 1 0 0 0 1 0\n", TK_EPARSE, 2,
                "number of colours must not be negative");
}
END_TEST

START_TEST(test_bad_colour_value)
{
    expect_fail("VECT\n1 3 1\n-3\n1\n0 0 0 1 0 0 0 1 0\n1 0 red 1\n", TK_EPARSE, 6,
                "expected colour value b of colour 0 of component 0 (a number), found 'red'");
    expect_fail("VECT\n1 3 1\n-3\n1\n0 0 0 1 0 0 0 1 0\n1 0 nan 1\n", TK_EPARSE, 6,
                "not a finite number");
    expect_fail("VECT\n1 3 1\n-3\n1\n0 0 0 1 0 0 0 1 0\n1 0 0\n", TK_EPARSE, 6,
                "expected colour value a of colour 0 of component 0, found end of file");
    expect_fail("VECT\n1 3 1\n-3\n1\n0 0 0 1 0 0 0 1 0\n"
                "1 0 0 0.0000000000000000000000000000000000000000000000000000000000000000001\n",
                TK_EPARSE, 6, "colour value too long (over 64 characters)");
}
END_TEST

START_TEST(test_missing_coordinate)
{
    /* Numbers longer than one character, as in real files, so that the
     * text could still hold the promised counts (else the header check
     * fires first, see test_truncated_file). */
    expect_fail("VECT\n1 3 0\n-3\n0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0\n", TK_EPARSE, 7,
                "expected coordinate z of vertex 2 of component 0, found end of file");
    /* Without a final newline the line is the same. */
    expect_fail("VECT\n1 3 0\n-3\n0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0", TK_EPARSE, 7,
                "found end of file");
    /* Trailing blank lines and comments: the line of the last text byte. */
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1\n\n# end\n", TK_EPARSE, 9,
                "found end of file");
}
END_TEST

START_TEST(test_non_numeric_coordinate)
{
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 abc 0\n0 1 0\n", TK_EPARSE, 6,
                "expected coordinate y of vertex 1 of component 0 (a number), found 'abc'");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 1.0abc\n", TK_EPARSE, 7,
                "found '1.0abc'");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 1,5\n", TK_EPARSE, 7, "found '1,5'");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 - 0\n", TK_EPARSE, 7, "found '-'");
}
END_TEST

START_TEST(test_nan_coordinate)
{
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\nnan 0 0\n0 1 0\n", TK_EPARSE, 6,
                "found 'nan', which is not a finite number");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 -NaN(0x1)\n", TK_EPARSE, 7,
                "not a finite number");
}
END_TEST

START_TEST(test_inf_coordinate)
{
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 inf 0\n0 1 0\n", TK_EPARSE, 6,
                "found 'inf', which is not a finite number");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n-Infinity 1 0\n", TK_EPARSE, 7,
                "not a finite number");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1e999 0\n", TK_EPARSE, 7,
                "found '1e999', which overflows a double");
}
END_TEST

START_TEST(test_absurd_counts)
{
#if !TKT_ASAN
    /* A multi-gigabyte allocation would now fail and the test with it (the
     * sanitizer build has its own allocation checks and big shadow maps). */
    struct rlimit old, low;
    ck_assert_int_eq(getrlimit(RLIMIT_DATA, &old), 0);
    low = old;
    low.rlim_cur = (rlim_t)512 << 20;
    if (old.rlim_cur != RLIM_INFINITY && old.rlim_cur < low.rlim_cur)
        low.rlim_cur = old.rlim_cur;
    ck_assert_int_eq(setrlimit(RLIMIT_DATA, &low), 0);
#endif
    expect_fail("VECT\n1 2000000000 0\n-2000000000\n0\n", TK_ELIMIT, 2,
                "2000000000 vertices exceed the limit of 10000000");
    expect_fail("VECT\n2000000000 3 0\n-3\n0\n", TK_ELIMIT, 2,
                "2000000000 components exceed the limit of 10000");
    expect_fail("VECT\n1 99999999999999999999999 0\n", TK_ELIMIT, 2,
                "the number of vertices is too large");
    /* With no limits at all, the size of the text still bounds the counts. */
    tk_vect_limits huge = {SIZE_MAX, SIZE_MAX};
    const char *t = "VECT\n1 2000000000 0\n-2000000000\n0\n";
    expect_fail_len(t, strlen(t), &huge, TK_EPARSE, 2,
                    "only 15 bytes of text follow");
    t = "VECT\n1000000000000 9000000000000000000 0\n";
    expect_fail_len(t, strlen(t), &huge, TK_EPARSE, 2, "bytes of text follow");
    t = "VECT\n3 3 3\n-3 0 0\n";
    expect_fail_len(t, strlen(t), &huge, TK_EPARSE, 2, "bytes of text follow");
    /* Just under the limits is fine; one over is TK_ELIMIT. */
    tk_vect_limits small = {1, 3};
    t = "VECT\n1 3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n";
    tk_curve *c = NULL;
    ck_assert_int_eq(parse_bytes(t, strlen(t), &small, &c, NULL), TK_OK);
    tk_curve_free(&c);
    t = "VECT\n2 5 0\n-3 2\n0 0\n0 0 0 1 0 0 0 1 0 5 5 5 6 6 6\n";
    expect_fail_len(t, strlen(t), &small, TK_ELIMIT, 2, "exceed the limit of 1");
    small.max_components = 2;
    expect_fail_len(t, strlen(t), &small, TK_ELIMIT, 2, "5 vertices exceed the limit of 3");
#if !TKT_ASAN
    ck_assert_int_eq(setrlimit(RLIMIT_DATA, &old), 0);
#endif
}
END_TEST

START_TEST(test_negative_nvertices)
{
    expect_fail("VECT\n1 -3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n", TK_EPARSE, 2,
                "number of vertices must not be negative, found -3");
    expect_fail("VECT\n0 0 0\n", TK_EPARSE, 2, "number of components must be at least 1");
    expect_fail("VECT\n-1 3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n", TK_EPARSE, 2,
                "at least 1, found -1");
}
END_TEST

START_TEST(test_closed_with_two_vertices)
{
    expect_fail("VECT\n2 5 0\n3\n-2\n0 0\n0 0 0 1 0 0 2 0 0 5 5 5 6 6 6\n", TK_EPARSE, 4,
                "component 1 is closed with 2 vertices (a closed component needs at least 3)");
}
END_TEST

START_TEST(test_open_with_one_vertex)
{
    expect_fail("VECT\n1 1 0\n1\n0\n0 0 0\n", TK_EPARSE, 3,
                "component 0 is open with 1 vertex");
    expect_fail("VECT\n2 4 0\n-3 0\n0 0\n0 0 0 1 0 0 0 1 0 5 5 5\n", TK_EPARSE, 3,
                "the vertex count of component 1 is 0");
}
END_TEST

START_TEST(test_coincident_vertices)
{
    expect_fail("VECT\n1 4 0\n-4\n0\n0 0 0\n1 0 0\n1 0 0\n0 1 0\n", TK_EPARSE, 7,
                "vertex 2 of component 0 coincides with vertex 1 (line 6): zero-length edge");
    /* -0 and 0 are the same point; a vertex is blamed on the line of its x. */
    expect_fail("VECT\n2 5 0\n-3 2\n0 0\n0 0 0 1 0 0 0 1 0\n5 0\n5\n5 -0e0 5\n", TK_EPARSE,
                8, "vertex 1 of component 1 coincides with vertex 0 (line 6)");
}
END_TEST

START_TEST(test_closed_repeats_first_vertex)
{
    expect_fail("VECT\n1 4 0\n-4\n0\n1 2 3\n4 5 6\n7 8 8\n1 2 3\n", TK_EPARSE, 8,
                "vertex 3 of closed component 0 coincides with its vertex 0 (line 5)");
}
END_TEST

START_TEST(test_truncated_file)
{
    /* Every prefix that ends before the last token starts must fail with a
     * message naming a line (TK_EPARSE), never crash or succeed. */
    size_t len = strlen(SEED);
    size_t last = len - 2; /* the final '1' before "\n" */
    ck_assert_int_eq(SEED[last], '1');
    for (size_t n = 0; n < last; n++) {
        tk_curve *c = NULL;
        tk_error err;
        int rc = parse_bytes(SEED, n, NULL, &c, &err);
        ck_assert_msg(rc == TK_EPARSE, "prefix %zu: %s", n, tk_status_name(rc));
        ck_assert_ptr_null(c);
        ck_assert_msg(strstr(err.message, "line ") == err.message, "%s", err.message);
    }
    expect_fail("VECT\n2 7 2\n-4 3\n1 1 # colours per component\n0.0 0.0 0.0\n1.0 0.0 0.0\n1.0 1.0 0.0\n"
                "0.0 1.0 0.5\n2.0 2.0",
                TK_EPARSE, 9, "expected coordinate z of vertex 0 of component 1, found end of file");
    /* Short numbers: the header check sees that the text cannot hold it. */
    expect_fail("VECT\n2 7 2\n-4 3\n1 1\n0 0 0\n1 0 0\n1 1 0\n0 1 0.5\n2 2",
                TK_EPARSE, 2, "but only 39 bytes of text follow");
    expect_fail("VECT\n2 7 2\n-4 3\n1", TK_EPARSE, 2, "bytes of text follow");
    expect_fail("VECT\n2 7 2\n-4", TK_EPARSE, 2, "bytes of text follow");
    expect_fail("VECT\n2 7", TK_EPARSE, 2, "expected the number of colours, found end of file");
    expect_fail("VECT\n", TK_EPARSE, 1, "expected the number of components, found end of file");
}
END_TEST

START_TEST(test_binary_garbage)
{
    /* A NUL inside a coordinate. */
    static const char nul[] = "VECT\n1 3 0\n-3\n0\n0 0 0\n1 0\0 0\n0 1 0\n";
    expect_fail_len(nul, sizeof nul - 1, NULL, TK_EPARSE, 6, "binary data '0\\x00'");
    static const char ctl[] = "VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n\x01\x02\x7f 1 0\n";
    expect_fail_len(ctl, sizeof ctl - 1, NULL, TK_EPARSE, 7, "binary data '\\x01\\x02\\x7f'");
    static const char high[] = "VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n\xff\xfe 1 0\n";
    expect_fail_len(high, sizeof high - 1, NULL, TK_EPARSE, 7, "found '\\xff\\xfe'");
    static const char nulhead[] = "\0VECT\n1 3 0\n";
    expect_fail_len(nulhead, sizeof nulhead - 1, NULL, TK_EPARSE, 1, "binary data");
    /* A NUL in a comment: once skipped with the comment, so that a store
     * keeping C strings cut the text there and the job failed later. */
    static const char nulcomment[] = "VECT\n1 3 0 # a \0 NUL\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n";
    expect_fail_len(nulcomment, sizeof nulcomment - 1, NULL, TK_EPARSE, 2, "binary data '\\x00'");
    static const char nultail[] = "VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n# end\0\n";
    expect_fail_len(nultail, sizeof nultail - 1, NULL, TK_EPARSE, 8, "binary data");
    static const char nulfirst[] = "# \0\nVECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n";
    expect_fail_len(nulfirst, sizeof nulfirst - 1, NULL, TK_EPARSE, 1, "binary data");

    /* Random bytes: always an error, with a line, never a crash. */
    tkt_rng rng = {7};
    for (int round = 0; round < 200; round++) {
        size_t n = 1 + (size_t)(tkt_rng_next(&rng) % 512);
        unsigned char *buf = malloc(n);
        ck_assert_ptr_nonnull(buf);
        for (size_t i = 0; i < n; i++)
            buf[i] = (unsigned char)tkt_rng_next(&rng);
        if (round % 2)
            memcpy(buf, "VECT\n", n < 5 ? n : 5); /* get past the header */
        tk_curve *c = NULL;
        tk_error err;
        int rc = parse_bytes((const char *)buf, n, NULL, &c, &err);
        ck_assert_msg(rc == TK_EPARSE || rc == TK_ELIMIT, "round %d: %s", round,
                      tk_status_name(rc));
        ck_assert_ptr_null(c);
        ck_assert_msg(strncmp(err.message, "line ", 5) == 0, "%s", err.message);
        free(buf);
    }
}
END_TEST

START_TEST(test_long_lines)
{
    size_t len;
    /* 1 MB of spaces, then valid data on the same line. */
    char *s = build_long("VECT 1 3 0 -3 0 0 0 0", ' ', (size_t)1 << 20,
                         "1 0 0 0 1 0\n", &len);
    tk_curve *c = NULL;
    tk_error err;
    ck_assert_int_eq(parse_bytes(s, len, NULL, &c, &err), TK_OK);
    ck_assert(vertex_is(c, 2, 0, 1, 0));
    tk_curve_free(&c);
    free(s);

    /* 1 MB of digits as one coordinate. */
    s = build_long("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 ", '7', (size_t)1 << 20, "\n",
                   &len);
    expect_fail_len(s, len, NULL, TK_EPARSE, 7, "coordinate too long");
    expect_fail_len(s, len, NULL, TK_EPARSE, 7, "(1048576 characters)");
    free(s);

    /* 1 MB of digits as a count overflows; 1 MB of zeros before a 3 does not. */
    s = build_long("VECT\n1 ", '9', (size_t)1 << 20, " 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n", &len);
    expect_fail_len(s, len, NULL, TK_ELIMIT, 2, "the number of vertices is too large");
    free(s);
    s = build_long("VECT\n1 ", '0', (size_t)1 << 20, "3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n", &len);
    ck_assert_int_eq(parse_bytes(s, len, NULL, &c, &err), TK_OK);
    ck_assert_uint_eq(c->nvert, 3);
    tk_curve_free(&c);
    free(s);

    /* A 1 MB comment line. */
    s = build_long("VECT\n1 3 0 #", 'x', (size_t)1 << 20, "\n-3\n0\n0 0 0 1 0 0 0 1 0 junk\n",
                   &len);
    expect_fail_len(s, len, NULL, TK_EPARSE, 5, "unexpected text after the vertices");
    free(s);
}
END_TEST

START_TEST(test_empty_input)
{
    expect_fail_len("", 0, NULL, TK_EPARSE, 1, "expected the header 'VECT', found end of file");
    tk_curve *c = (tk_curve *)&c;
    tk_error err;
    ck_assert_int_eq(tk_vect_parse(NULL, 0, NULL, &c, &err), TK_EPARSE);
    ck_assert_ptr_null(c);
    expect_fail(" \n\t\n", TK_EPARSE, 2, "found end of file");
}
END_TEST

START_TEST(test_only_comments)
{
    expect_fail("# one\n# two\n# three\n", TK_EPARSE, 3,
                "expected the header 'VECT', found end of file");
    expect_fail("VECT # just the header\n# and comments\n", TK_EPARSE, 2,
                "expected the number of components, found end of file");
}
END_TEST

START_TEST(test_extra_text)
{
    expect_fail("VECT\n1 3 1\n-3\n1\n0 0 0 1 0 0 0 1 0\n1 0 0 1\n0.5\n", TK_EPARSE, 7,
                "unexpected text after the colours: '0.5'");
    expect_fail("VECT\n1 3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n\n# fine\nVECT\n", TK_EPARSE, 8,
                "unexpected text after the vertices");
    /* Trailing comments and blank lines are not text. */
    tk_curve *c = parse_ok("VECT\n1 3 0\n-3\n0\n0 0 0 1 0 0 0 1 0\n\n# fine\n\n");
    tk_curve_free(&c);
}
END_TEST

/* ---------------------------------------------------------------- fuzz */

START_TEST(test_mutation_fuzz)
{
    static const char interesting[] = "0123456789-+.eE#\n \t\r\0xnI";
    size_t seed_len = strlen(SEED);
    {
        tk_curve *c = parse_ok(SEED);
        ck_assert_uint_eq(c->nvert, 7);
        tk_curve_free(&c);
    }
    tkt_rng rng = {20240601};
    int ok = 0;
    char *buf = malloc(2 * seed_len + 16);
    ck_assert_ptr_nonnull(buf);
    for (int iter = 0; iter < 2000; iter++) {
        memcpy(buf, SEED, seed_len);
        size_t n = seed_len;
        int nmut = 1 + (int)(tkt_rng_next(&rng) % 4);
        for (int m = 0; m < nmut && n > 0; m++) {
            size_t at = (size_t)(tkt_rng_next(&rng) % n);
            char ch = (tkt_rng_next(&rng) % 2)
                          ? interesting[tkt_rng_next(&rng) % (sizeof interesting - 1)]
                          : (char)tkt_rng_next(&rng);
            switch (tkt_rng_next(&rng) % 5) {
            case 0: /* replace */
            case 1:
                buf[at] = ch;
                break;
            case 2: /* delete */
                memmove(buf + at, buf + at + 1, n - at - 1);
                n--;
                break;
            case 3: /* insert */
                if (n < 2 * seed_len) {
                    memmove(buf + at + 1, buf + at, n - at);
                    buf[at] = ch;
                    n++;
                }
                break;
            default: /* truncate */
                n = at;
                break;
            }
        }
        tk_curve *c = NULL;
        tk_error err;
        int rc = parse_bytes(buf, n, NULL, &c, &err);
        if (rc == TK_OK) {
            ok++;
            ck_assert_ptr_nonnull(c);
            ck_assert_int_eq(tk_curve_validate(c, NULL), TK_OK);
            tk_curve *back = roundtrip(c);
            assert_same_curve(c, back, "fuzz");
            tk_curve_free(&back);
            tk_curve_free(&c);
        } else {
            ck_assert_msg(rc == TK_EPARSE || rc == TK_ELIMIT, "iteration %d: %s", iter,
                          tk_status_name(rc));
            ck_assert_ptr_null(c);
            ck_assert_msg(err.message[0] != '\0', "iteration %d: empty message", iter);
            ck_assert_msg(strstr(err.message, "line") != NULL, "iteration %d: %s", iter,
                          err.message);
        }
    }
    free(buf);
    /* Some mutations (a digit for a digit) keep the text valid. */
    ck_assert_int_gt(ok, 0);
}
END_TEST

/* ---------------------------------------------------------------- files */

START_TEST(test_read_missing_file)
{
    const char *path = "/nonexistent/dir/knot.vect";
    tk_curve *c = (tk_curve *)&c;
    tk_error err;
    int rc = tk_vect_read_file(path, NULL, &c, &err);
    ck_assert_int_eq(rc, TK_EIO);
    ck_assert_ptr_null(c);
    ck_assert_msg(strstr(err.message, path) != NULL, "%s", err.message);
    ck_assert_msg(strstr(err.message, "cannot open") != NULL, "%s", err.message);

    rc = tk_vect_read_file("/", NULL, &c, &err);
    ck_assert_int_eq(rc, TK_EIO);
    ck_assert_msg(strstr(err.message, "directory") != NULL, "%s", err.message);
}
END_TEST

START_TEST(test_read_file_messages)
{
    char path[] = "/tmp/tk_test_vect_XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "wb");
    ck_assert_ptr_nonnull(f);
    fputs("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 one 0\n", f);
    ck_assert_int_eq(fclose(f), 0);

    tk_curve *c = NULL;
    tk_error err;
    int rc = tk_vect_read_file(path, NULL, &c, &err);
    char want[64];
    snprintf(want, sizeof want, "%s:7: expected coordinate y", path);
    ck_assert_int_eq(rc, TK_EPARSE);
    ck_assert_msg(strncmp(err.message, want, strlen(want)) == 0, "%s", err.message);

    tk_vect_limits small = {1, 2};
    rc = tk_vect_read_file(path, &small, &c, &err);
    ck_assert_int_eq(rc, TK_ELIMIT);
    snprintf(want, sizeof want, "%s:2: ", path);
    ck_assert_msg(strncmp(err.message, want, strlen(want)) == 0, "%s", err.message);

    /* A good file, and err may be NULL. */
    f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    fputs("VECT\n1 3 0\n-3\n0\n0 0 0\n1 0 0\n0 1 0\n", f);
    ck_assert_int_eq(fclose(f), 0);
    ck_assert_int_eq(tk_vect_read_file(path, NULL, &c, NULL), TK_OK);
    ck_assert_uint_eq(c->nvert, 3);
    tk_curve_free(&c);

    /* Over 1 GiB is refused from its size, before reading (a sparse file,
     * so the test costs no disk). */
    if (truncate(path, ((off_t)1 << 30) + 1) == 0) {
        rc = tk_vect_read_file(path, NULL, &c, &err);
        ck_assert_int_eq(rc, TK_ELIMIT);
        ck_assert_ptr_null(c);
        ck_assert_msg(strstr(err.message, path) != NULL, "%s", err.message);
        ck_assert_msg(strstr(err.message, "over the limit") != NULL, "%s", err.message);
    } else {
        printf("note: cannot make a sparse file; size-limit check skipped\n");
    }
    unlink(path);
}
END_TEST

START_TEST(test_write_errors)
{
    tk_curve *c = tkt_regular_polygon(5, 1.0);
    tk_error err;
    FILE *full = fopen("/dev/full", "w");
    if (full) {
        int rc = tk_vect_write(c, full, &err);
        ck_assert_int_eq(rc, TK_EIO);
        ck_assert_msg(strstr(err.message, "writing VECT failed") != NULL, "%s",
                      err.message);
        fclose(full);
    } else {
        printf("note: /dev/full absent; write-error check skipped\n");
    }
    /* The writer refuses what the reader would refuse. */
    c->xyz[4] = NAN;
    char *text = (char *)&text;
    ck_assert_int_eq(tk_vect_to_string(c, &text, NULL, &err), TK_EINVAL);
    ck_assert_ptr_null(text);
    ck_assert_msg(strstr(err.message, "cannot write VECT: component 0 vertex 1") != NULL,
                  "%s", err.message);
    c->xyz[4] = 0.5;
    c->colour = calloc(4, sizeof *c->colour);
    ck_assert_ptr_nonnull(c->colour);
    c->has_colour = true;
    c->colour[2] = INFINITY;
    ck_assert_int_eq(tk_vect_to_string(c, &text, NULL, &err), TK_EINVAL);
    ck_assert_msg(strstr(err.message, "colour") != NULL, "%s", err.message);
    tk_curve_free(&c);
}
END_TEST

/* ---------------------------------------------------------------- main */

static Suite *vect_suite(void)
{
    Suite *s = suite_create("vect");

    TCase *tc = tcase_create("catalogue");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_catalogue_roundtrip);
    tcase_add_test(tc, test_catalogue_known_files);
    suite_add_tcase(s, tc);

    tc = tcase_create("accepted");
    tcase_add_test(tc, test_roundtrip_extreme_values);
    tcase_add_test(tc, test_write_exact_text);
    tcase_add_test(tc, test_comments_in_odd_places);
    tcase_add_test(tc, test_header_trailing_spaces);
    tcase_add_test(tc, test_wrapped_coordinates);
    tcase_add_test(tc, test_tabs_crlf_and_friends);
    tcase_add_test(tc, test_not_nul_terminated);
    tcase_add_test(tc, test_mixed_open_closed);
    tcase_add_test(tc, test_colours_per_vertex);
    tcase_add_test(tc, test_colours_one_total);
    tcase_add_test(tc, test_colours_none);
    tcase_add_test(tc, test_leading_zeros_and_signs);
    suite_add_tcase(s, tc);

    tc = tcase_create("malformed");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_bad_header);
    tcase_add_test(tc, test_vertex_sum_mismatch);
    tcase_add_test(tc, test_colour_sum_mismatch);
    tcase_add_test(tc, test_colour_count_rule);
    tcase_add_test(tc, test_bad_colour_value);
    tcase_add_test(tc, test_missing_coordinate);
    tcase_add_test(tc, test_non_numeric_coordinate);
    tcase_add_test(tc, test_nan_coordinate);
    tcase_add_test(tc, test_inf_coordinate);
    tcase_add_test(tc, test_absurd_counts);
    tcase_add_test(tc, test_negative_nvertices);
    tcase_add_test(tc, test_closed_with_two_vertices);
    tcase_add_test(tc, test_open_with_one_vertex);
    tcase_add_test(tc, test_coincident_vertices);
    tcase_add_test(tc, test_closed_repeats_first_vertex);
    tcase_add_test(tc, test_truncated_file);
    tcase_add_test(tc, test_binary_garbage);
    tcase_add_test(tc, test_long_lines);
    tcase_add_test(tc, test_empty_input);
    tcase_add_test(tc, test_only_comments);
    tcase_add_test(tc, test_extra_text);
    suite_add_tcase(s, tc);

    tc = tcase_create("fuzz");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_mutation_fuzz);
    suite_add_tcase(s, tc);

    tc = tcase_create("files");
    tcase_add_test(tc, test_read_missing_file);
    tcase_add_test(tc, test_read_file_messages);
    tcase_add_test(tc, test_write_errors);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(vect_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
