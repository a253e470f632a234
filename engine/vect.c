/* tightknot: Geomview VECT reading and writing.
 *
 * The reader is a small tokenizer over a (text, len) buffer plus a parser
 * that walks the fixed VECT layout.  It never trusts a count from the text:
 * the header counts are bounded by the limits and by the number of tokens
 * the remaining bytes could hold before anything is allocated from them, so
 * a short file that claims a billion vertices fails at once.  Every error
 * names the 1-based line, what was expected and what was found.
 *
 * Numbers are read and written in the "C" numeric locale whatever the
 * process locale is (uselocale is per thread), so a program that calls
 * setlocale() still reads "1.5" and writes "1.5".
 */
#ifndef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700 /* fileno, open_memstream, newlocale/uselocale */
#endif

#include "tk/vect.h"

#include <ctype.h>
#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* Longest number token we hand to strtod: %.17g needs at most 24 chars, so
 * anything longer is not a coordinate a sane writer produced. */
#define VECT_MAX_NUMBER 64

/* Files bigger than this are refused before reading them. */
#define VECT_MAX_FILE ((size_t)1 << 30)

/* How much of an offending token a message shows. */
#define VECT_SHOW_TOKEN 32

/* ---------------------------------------------------------------- tokens */

/* A constraint comment (tk/pin.h): "# Constraint k Kind numbers" defines
 * constraint k, "# Cst: k" after a vertex's coordinates puts it on the
 * vertex whose last coordinate is on that line. */
typedef struct directive {
    bool use;       /* "Cst:", else "Constraint" */
    size_t line;
    const char *text; /* after the keyword, up to the comment's end */
    size_t n;
    size_t vertex;  /* use: the global vertex, SIZE_MAX when none */
} directive;

/* At most this many constraint comments (a clasp has eight). */
#define VECT_MAX_DIRECTIVES 10000

typedef struct lexer {
    const unsigned char *s;
    size_t len;
    size_t pos;
    size_t line; /* 1-based line of s[pos] */
    directive *dirs;
    size_t ndirs, dir_capacity;
    bool dir_overflow; /* too many, or out of memory for them */
    size_t vertex, vertex_line; /* the last vertex read, and its line (0: none) */
} lexer;

static bool starts_with(const char *p, size_t n, const char *word)
{
    size_t w = strlen(word);
    return n >= w && strncasecmp(p, word, w) == 0;
}

/* The comment s[from, to) on `line`, kept if it is a constraint's. */
static void comment(lexer *lx, size_t from, size_t to, size_t line)
{
    const char *p = (const char *)lx->s + from;
    size_t n = to - from;
    while (n > 0 && (*p == ' ' || *p == '\t')) {
        p++;
        n--;
    }
    bool use = starts_with(p, n, "Cst:");
    if (!use && !(starts_with(p, n, "Constraint") && n > 10 && (p[10] == ' ' || p[10] == '\t')))
        return;
    size_t skip = use ? 4 : 10;
    if (lx->ndirs == lx->dir_capacity) {
        size_t cap = lx->dir_capacity ? 2 * lx->dir_capacity : 16;
        directive *grown = cap <= VECT_MAX_DIRECTIVES ? realloc(lx->dirs, cap * sizeof *grown)
                                                      : NULL;
        if (!grown) {
            lx->dir_overflow = true;
            return;
        }
        lx->dirs = grown;
        lx->dir_capacity = cap;
    }
    lx->dirs[lx->ndirs++] = (directive){
        .use = use,
        .line = line,
        .text = p + skip,
        .n = n - skip,
        .vertex = use && lx->vertex_line == line ? lx->vertex : SIZE_MAX,
    };
}

/* n == 0 means end of file; line is then the last line that has text. */
typedef struct token {
    const char *p;
    size_t n;
    size_t line;
} token;

static bool is_space(unsigned char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r' || ch == '\f' ||
           ch == '\v';
}

/* A lone '\r' (old Mac text) ends a line too; "\r\n" counts once. */
static void skip_space_and_comments(lexer *lx)
{
    while (lx->pos < lx->len) {
        unsigned char ch = lx->s[lx->pos];
        if (ch == '\n') {
            lx->line++;
            lx->pos++;
        } else if (ch == '\r') {
            lx->pos++;
            if (lx->pos >= lx->len || lx->s[lx->pos] != '\n')
                lx->line++;
        } else if (is_space(ch)) {
            lx->pos++;
        } else if (ch == '#') {
            /* A NUL ends a comment and starts a token, so that it is
             * refused as binary data on its line: no text file holds
             * one, and a store of C strings would cut the text there. */
            size_t from = ++lx->pos;
            while (lx->pos < lx->len && lx->s[lx->pos] != '\n' && lx->s[lx->pos] != '\r' &&
                   lx->s[lx->pos] != '\0')
                lx->pos++;
            comment(lx, from, lx->pos, lx->line);
        } else {
            break;
        }
    }
}

/* The line to blame for "end of file": the one holding the last byte, not
 * the empty line after a final newline. */
static size_t eof_line(const lexer *lx)
{
    size_t line = lx->line;
    if (lx->len > 0 && line > 1) {
        unsigned char last = lx->s[lx->len - 1];
        if (last == '\n' || last == '\r')
            line--;
    }
    return line;
}

static token next_token(lexer *lx)
{
    token t = {NULL, 0, 0};
    skip_space_and_comments(lx);
    if (lx->pos >= lx->len) {
        t.line = eof_line(lx);
        return t;
    }
    size_t start = lx->pos;
    while (lx->pos < lx->len && !is_space(lx->s[lx->pos]) && lx->s[lx->pos] != '#')
        lx->pos++;
    t.p = (const char *)lx->s + start;
    t.n = lx->pos - start;
    t.line = lx->line;
    return t;
}

/* Bytes left after the last token read; what the remaining counts must fit. */
static size_t remaining_bytes(const lexer *lx)
{
    return lx->len - lx->pos;
}

/* A printable, bounded rendering of a token for messages: "end of file",
 * 'abc', binary data '\x00\x01', or '123456...' (1048576 characters). */
static void describe_token(const token *t, char *buf, size_t size)
{
    if (t->n == 0) {
        snprintf(buf, size, "end of file");
        return;
    }
    bool binary = false;
    for (size_t i = 0; i < t->n; i++) {
        unsigned char ch = (unsigned char)t->p[i];
        if (ch < 0x20 || ch == 0x7f) {
            binary = true;
            break;
        }
    }
    char shown[4 * VECT_SHOW_TOKEN + 1];
    size_t k = 0;
    size_t nshow = t->n < VECT_SHOW_TOKEN ? t->n : VECT_SHOW_TOKEN;
    for (size_t i = 0; i < nshow; i++) {
        unsigned char ch = (unsigned char)t->p[i];
        if (ch >= 0x20 && ch < 0x7f && ch != '\'' && ch != '\\') {
            shown[k++] = (char)ch;
        } else {
            snprintf(shown + k, sizeof shown - k, "\\x%02x", ch);
            k += 4;
        }
    }
    shown[k] = '\0';
    if (t->n > nshow)
        snprintf(buf, size, "%s'%s...' (%zu characters)", binary ? "binary data " : "",
                 shown, t->n);
    else
        snprintf(buf, size, "%s'%s'", binary ? "binary data " : "", shown);
}

/* ---------------------------------------------------------------- numbers */

enum { NUM_OK, NUM_BAD, NUM_RANGE, NUM_LONG, NUM_NONFINITE };

/* Decimal integer with optional sign; own scanning so that overflow is
 * caught (strtoll would need a NUL-terminated copy of any length). */
static int parse_integer(const token *t, int64_t *out)
{
    size_t i = 0;
    bool negative = false;
    if (t->n > 0 && (t->p[0] == '+' || t->p[0] == '-')) {
        negative = t->p[0] == '-';
        i = 1;
    }
    if (i >= t->n)
        return NUM_BAD;
    uint64_t v = 0;
    bool overflow = false;
    for (; i < t->n; i++) {
        unsigned char ch = (unsigned char)t->p[i];
        if (ch < '0' || ch > '9')
            return NUM_BAD;
        unsigned d = ch - '0';
        if (v > ((uint64_t)INT64_MAX - d) / 10)
            overflow = true; /* keep scanning: a non-digit later is NUM_BAD */
        else
            v = v * 10 + d;
    }
    if (overflow)
        return NUM_RANGE;
    *out = negative ? -(int64_t)v : (int64_t)v;
    return NUM_OK;
}

static int parse_real(const token *t, double *out)
{
    if (t->n > VECT_MAX_NUMBER)
        return NUM_LONG;
    char buf[VECT_MAX_NUMBER + 1];
    memcpy(buf, t->p, t->n);
    buf[t->n] = '\0';
    if (t->n == 0)
        return NUM_BAD;
    char *end = NULL;
    errno = 0;
    double v = strtod(buf, &end);
    if (end != buf + t->n)
        return NUM_BAD; /* includes an embedded NUL and trailing garbage */
    if (isnan(v) || (isinf(v) && errno != ERANGE))
        return NUM_NONFINITE;
    if (isinf(v))
        return NUM_RANGE;
    /* Underflow (ERANGE with a tiny result) is accepted: the value is the
     * nearest double, which is what the writer of such a token meant. */
    *out = v;
    return NUM_OK;
}

/* ---------------------------------------------------------------- parser */

typedef struct parser {
    lexer lx;
    tk_error *err;
} parser;

static int fail(parser *ps, int code, size_t line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Every parse error goes through here so that each starts "line N: ". */
static int fail(parser *ps, int code, size_t line, const char *fmt, ...)
{
    char body[TK_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(body, sizeof body, fmt, ap);
    va_end(ap);
    return tk_error_set(ps->err, code, "line %zu: %s", line, body);
}

/* Reads an integer; `what` describes it for messages ("the number of
 * components"). *line receives the token's line. */
static int expect_integer(parser *ps, const char *what, int64_t *out, size_t *line)
{
    token t = next_token(&ps->lx);
    *line = t.line;
    char found[4 * VECT_SHOW_TOKEN + 64];
    describe_token(&t, found, sizeof found);
    if (t.n == 0)
        return fail(ps, TK_EPARSE, t.line, "expected %s, found %s", what, found);
    switch (parse_integer(&t, out)) {
    case NUM_OK:
        return TK_OK;
    case NUM_RANGE:
        return fail(ps, TK_ELIMIT, t.line, "%s is too large: %s", what, found);
    default:
        return fail(ps, TK_EPARSE, t.line, "expected %s (an integer), found %s", what,
                    found);
    }
}

static int expect_real(parser *ps, const char *what, double *out, size_t *line)
{
    token t = next_token(&ps->lx);
    *line = t.line;
    char found[4 * VECT_SHOW_TOKEN + 64];
    describe_token(&t, found, sizeof found);
    if (t.n == 0)
        return fail(ps, TK_EPARSE, t.line, "expected %s, found %s", what, found);
    switch (parse_real(&t, out)) {
    case NUM_OK:
        return TK_OK;
    case NUM_LONG:
        return fail(ps, TK_EPARSE, t.line,
                    "expected %s, found %s: %s too long (over %d characters)", what,
                    found, strncmp(what, "colour", 6) == 0 ? "colour value" : "coordinate",
                    VECT_MAX_NUMBER);
    case NUM_NONFINITE:
        return fail(ps, TK_EPARSE, t.line,
                    "expected %s, found %s, which is not a finite number", what, found);
    case NUM_RANGE:
        return fail(ps, TK_EPARSE, t.line,
                    "expected %s, found %s, which overflows a double", what, found);
    default:
        return fail(ps, TK_EPARSE, t.line, "expected %s (a number), found %s", what,
                    found);
    }
}

/* Whether T = 2*ncomp + 3*nvert + 4*ncol more tokens could fit in `bytes`:
 * each token needs a byte and a separator before it.  Division instead of
 * multiplication so that huge limits cannot overflow the sum. */
static bool tokens_fit(size_t bytes, uint64_t ncomp, uint64_t nvert, uint64_t ncol)
{
    uint64_t budget = (uint64_t)bytes / 2;
    if (ncomp > budget / 2)
        return false;
    budget -= 2 * ncomp;
    if (nvert > budget / 3)
        return false;
    budget -= 3 * nvert;
    return ncol <= budget / 4;
}

static double distance3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

static const char AXIS[3] = {'x', 'y', 'z'};
static const char CHANNEL[4] = {'r', 'g', 'b', 'a'};

/* Parses the whole text into *out.  Counts are checked in text order so
 * that the first error reported is the first one a reader meets. */

/* Reads up to `most` numbers of a comment's text into v; how many. */
static int comment_numbers(const char *p, size_t n, double *v, int most, bool *bad)
{
    char buf[VECT_MAX_NUMBER + 1];
    int count = 0;
    size_t i = 0;
    *bad = false;
    while (i < n) {
        while (i < n && (p[i] == ' ' || p[i] == '\t'))
            i++;
        size_t start = i;
        while (i < n && p[i] != ' ' && p[i] != '\t')
            i++;
        if (i == start)
            break;
        char *end;
        if (count == most || i - start > VECT_MAX_NUMBER) {
            *bad = true;
            return count;
        }
        memcpy(buf, p + start, i - start);
        buf[i - start] = '\0';
        errno = 0;
        v[count] = strtod(buf, &end);
        if (*end != '\0' || errno == ERANGE || !isfinite(v[count])) {
            *bad = true;
            return count;
        }
        count++;
    }
    return count;
}

/* A constraint number: a whole number from 1, and where it ends. */
static long constraint_number(const char *p, size_t n, size_t *used)
{
    size_t i = 0;
    while (i < n && (p[i] == ' ' || p[i] == '\t'))
        i++;
    long k = 0;
    size_t start = i;
    while (i < n && p[i] >= '0' && p[i] <= '9' && k < 100000000)
        k = 10 * k + (p[i++] - '0');
    *used = i;
    return i > start && (i == n || p[i] == ' ' || p[i] == '\t') ? k : -1;
}

typedef struct definition {
    long k;
    const directive *d;
} definition;

static int by_number(const void *a, const void *b)
{
    long x = ((const definition *)a)->k, y = ((const definition *)b)->k;
    return (x > y) - (x < y);
}

/* Constraint k's definition made a pin of global vertex v. */
static int pin_of(parser *ps, tk_curve *c, const definition *def, size_t v, size_t use_line,
                  tk_pin *pin)
{
    size_t at;
    constraint_number(def->d->text, def->d->n, &at);
    const char *p = def->d->text + at;
    size_t n = def->d->n - at;
    while (n > 0 && (*p == ' ' || *p == '\t')) {
        p++;
        n--;
    }
    /* (the comment runs to its line's end, not to a NUL) */
    size_t len = 0;
    while (len < n && p[len] != ' ' && p[len] != '\t')
        len++;
    int kind = tk_pin_kind_of(p, len);
    if (kind < 0)
        return fail(ps, TK_EPARSE, def->d->line,
                    "constraint %ld: the kind is Plane a b c d, Point x y z, Line px py pz "
                    "tx ty tz or Free", def->k);
    double x[6];
    bool bad;
    int count = comment_numbers(p + len, n - len, x, 6, &bad);
    if (bad || count != tk_pin_count((tk_pin_kind)kind))
        return fail(ps, TK_EPARSE, def->d->line, "constraint %ld: %s takes %d numbers", def->k,
                    tk_pin_kind_name((tk_pin_kind)kind), tk_pin_count((tk_pin_kind)kind));
    /* the component holding v: the last whose offset is at most v */
    size_t lo = 0, hi = c->ncomp - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (c->offset[mid] <= v)
            lo = mid;
        else
            hi = mid - 1;
    }
    *pin = (tk_pin){.comp = lo, .vertex = v - c->offset[lo], .kind = (tk_pin_kind)kind};
    tk_pin_set_numbers(pin, x);
    tk_error why;
    int rc = tk_curve_pin_add(c, pin, false, &why);
    return rc ? fail(ps, rc == TK_ENOMEM ? TK_ENOMEM : TK_EPARSE, use_line, "%s", why.message)
              : TK_OK;
}

/* The constraint comments (see `directive`) made pins of the curve. */
static int apply_constraints(parser *ps, tk_curve *c)
{
    lexer *lx = &ps->lx;
    if (lx->dir_overflow)
        return fail(ps, TK_ELIMIT, lx->line, "more than %d constraint comments",
                    VECT_MAX_DIRECTIVES);
    if (lx->ndirs == 0)
        return TK_OK;
    definition *defs = malloc(lx->ndirs * sizeof *defs);
    if (!defs)
        return tk_error_set(ps->err, TK_ENOMEM, "out of memory for the constraints");
    size_t ndefs = 0;
    int rc = TK_OK;
    for (size_t u = 0; u < lx->ndirs && !rc; u++) {
        const directive *d = &lx->dirs[u];
        size_t used;
        long k = constraint_number(d->text, d->n, &used);
        if (k < 1)
            rc = fail(ps, TK_EPARSE, d->line,
                      d->use ? "'# Cst: K' names its constraint by a number from 1"
                             : "'# Constraint K KIND ...' numbers its constraint from 1");
        else if (d->use && d->vertex == SIZE_MAX)
            rc = fail(ps, TK_EPARSE, d->line,
                      "'# Cst: %ld' must follow the coordinates of the vertex it constrains, "
                      "on their line", k);
        else if (!d->use)
            defs[ndefs++] = (definition){k, d};
    }
    if (!rc)
        qsort(defs, ndefs, sizeof *defs, by_number);
    for (size_t i = 1; i < ndefs && !rc; i++)
        if (defs[i].k == defs[i - 1].k) {
            const directive *a = defs[i].d->line < defs[i - 1].d->line ? defs[i].d : defs[i - 1].d;
            const directive *b = a == defs[i].d ? defs[i - 1].d : defs[i].d;
            rc = fail(ps, TK_EPARSE, b->line, "constraint %ld is defined twice (first on line %zu)",
                      defs[i].k, a->line);
        }
    for (size_t u = 0; u < lx->ndirs && !rc; u++) {
        const directive *d = &lx->dirs[u];
        if (!d->use)
            continue;
        size_t used;
        definition key = {constraint_number(d->text, d->n, &used), NULL};
        const definition *def = bsearch(&key, defs, ndefs, sizeof *defs, by_number);
        tk_pin pin;
        if (!def)
            rc = fail(ps, TK_EPARSE, d->line,
                      "constraint %ld is not defined ('# Constraint %ld KIND ...' in the "
                      "header)", key.k, key.k);
        else
            rc = pin_of(ps, c, def, d->vertex, d->line, &pin);
    }
    free(defs);
    return rc;
}

static int parse_vect(parser *ps, const tk_vect_limits *lim, tk_curve **out)
{
    int rc = TK_OK;
    size_t *counts = NULL;
    size_t *ncolour = NULL;
    bool *closed = NULL;
    tk_curve *c = NULL;
    char what[96];
    size_t line = 1;

    token head = next_token(&ps->lx);
    if (head.n != 4 || memcmp(head.p, "VECT", 4) != 0) {
        char found[4 * VECT_SHOW_TOKEN + 64];
        describe_token(&head, found, sizeof found);
        rc = fail(ps, TK_EPARSE, head.line, "expected the header 'VECT', found %s", found);
        goto done;
    }

    int64_t ncomp, nvert, ncol;
    size_t ncomp_line, nvert_line, ncol_line;
    if ((rc = expect_integer(ps, "the number of components", &ncomp, &ncomp_line)))
        goto done;
    if (ncomp < 1) {
        rc = fail(ps, TK_EPARSE, ncomp_line,
                  "the number of components must be at least 1, found %" PRId64, ncomp);
        goto done;
    }
    if ((uint64_t)ncomp > lim->max_components) {
        rc = fail(ps, TK_ELIMIT, ncomp_line,
                  "%" PRId64 " components exceed the limit of %zu", ncomp,
                  lim->max_components);
        goto done;
    }
    if ((rc = expect_integer(ps, "the number of vertices", &nvert, &nvert_line)))
        goto done;
    if (nvert < 0) {
        rc = fail(ps, TK_EPARSE, nvert_line,
                  "the number of vertices must not be negative, found %" PRId64, nvert);
        goto done;
    }
    if ((uint64_t)nvert > lim->max_vertices) {
        rc = fail(ps, TK_ELIMIT, nvert_line,
                  "%" PRId64 " vertices exceed the limit of %zu", nvert, lim->max_vertices);
        goto done;
    }
    if ((rc = expect_integer(ps, "the number of colours", &ncol, &ncol_line)))
        goto done;
    if (ncol < 0) {
        rc = fail(ps, TK_EPARSE, ncol_line,
                  "the number of colours must not be negative, found %" PRId64, ncol);
        goto done;
    }
    /* At most one colour per vertex (Geomview), so this also bounds ncol. */
    if (ncol > nvert) {
        rc = fail(ps, TK_EPARSE, ncol_line,
                  "%" PRId64 " colours for %" PRId64 " vertices: there can be at most "
                  "one colour per vertex", ncol, nvert);
        goto done;
    }
    if (!tokens_fit(remaining_bytes(&ps->lx), (uint64_t)ncomp, (uint64_t)nvert,
                    (uint64_t)ncol)) {
        rc = fail(ps, TK_EPARSE, ncol_line,
                  "the header promises %" PRId64 " components, %" PRId64
                  " vertices and %" PRId64 " colours, but only %zu bytes of text "
                  "follow (the file is truncated or the counts are wrong)",
                  ncomp, nvert, ncol, remaining_bytes(&ps->lx));
        goto done;
    }

    size_t nc = (size_t)ncomp;
    counts = malloc(nc * sizeof *counts);
    ncolour = malloc(nc * sizeof *ncolour);
    closed = malloc(nc * sizeof *closed);
    if (!counts || !ncolour || !closed) {
        rc = tk_error_set(ps->err, TK_ENOMEM, "out of memory for %zu components", nc);
        goto done;
    }

    uint64_t sum = 0;
    for (size_t i = 0; i < nc; i++) {
        int64_t v;
        snprintf(what, sizeof what, "the vertex count of component %zu", i);
        if ((rc = expect_integer(ps, what, &v, &line)))
            goto done;
        if (v == 0) {
            rc = fail(ps, TK_EPARSE, line,
                      "the vertex count of component %zu is 0 (negative = closed, "
                      "positive = open)", i);
            goto done;
        }
        uint64_t n = v < 0 ? (uint64_t)(-v) : (uint64_t)v;
        closed[i] = v < 0;
        if (closed[i] && n < 3) {
            rc = fail(ps, TK_EPARSE, line,
                      "component %zu is closed with %" PRIu64
                      " vertices (a closed component needs at least 3)", i, n);
            goto done;
        }
        if (!closed[i] && n < 2) {
            rc = fail(ps, TK_EPARSE, line,
                      "component %zu is open with 1 vertex (an open component needs "
                      "at least 2)", i);
            goto done;
        }
        /* n and sum are both <= nvert here, so the sum cannot overflow. */
        if (n > (uint64_t)nvert - sum) {
            rc = fail(ps, TK_EPARSE, line,
                      "the vertex counts up to component %zu add up to %" PRIu64
                      ", more than the %" PRId64 " vertices in the header (line %zu)",
                      i, sum + n, nvert, nvert_line);
            goto done;
        }
        sum += n;
        counts[i] = (size_t)n;
    }
    if (sum != (uint64_t)nvert) {
        rc = fail(ps, TK_EPARSE, line,
                  "the vertex counts add up to %" PRIu64 ", but the header (line %zu) "
                  "says %" PRId64 " vertices", sum, nvert_line, nvert);
        goto done;
    }

    sum = 0;
    for (size_t i = 0; i < nc; i++) {
        int64_t v;
        snprintf(what, sizeof what, "the colour count of component %zu", i);
        if ((rc = expect_integer(ps, what, &v, &line)))
            goto done;
        if (v < 0) {
            rc = fail(ps, TK_EPARSE, line,
                      "the colour count of component %zu is negative (%" PRId64 ")", i, v);
            goto done;
        }
        if (v != 0 && v != 1 && (uint64_t)v != counts[i]) {
            rc = fail(ps, TK_EPARSE, line,
                      "component %zu has %" PRId64 " colours; it must have 0, 1 or %zu "
                      "(one per vertex)", i, v, counts[i]);
            goto done;
        }
        if ((uint64_t)v > (uint64_t)ncol - sum) {
            rc = fail(ps, TK_EPARSE, line,
                      "the colour counts up to component %zu add up to %" PRIu64
                      ", more than the %" PRId64 " colours in the header (line %zu)",
                      i, sum + (uint64_t)v, ncol, ncol_line);
            goto done;
        }
        sum += (uint64_t)v;
        ncolour[i] = (size_t)v;
    }
    if (sum != (uint64_t)ncol) {
        rc = fail(ps, TK_EPARSE, line,
                  "the colour counts add up to %" PRIu64 ", but the header (line %zu) "
                  "says %" PRId64 " colours", sum, ncol_line, ncol);
        goto done;
    }

    if ((rc = tk_curve_new(&c, nc, counts, closed, ps->err)))
        goto done;

    for (size_t i = 0; i < nc; i++) {
        size_t first_line = 0;
        size_t prev_line = 0;
        for (size_t k = 0; k < counts[i]; k++) {
            double *x = c->xyz + 3 * (c->offset[i] + k);
            size_t vline = 0;
            for (int a = 0; a < 3; a++) {
                snprintf(what, sizeof what, "coordinate %c of vertex %zu of component %zu",
                         AXIS[a], k, i);
                if ((rc = expect_real(ps, what, &x[a], &line)))
                    goto done;
                if (a == 0)
                    vline = line;
            }
            ps->lx.vertex = c->offset[i] + k;
            ps->lx.vertex_line = line;
            /* Same test as tk_curve_validate, so that it never fails later. */
            if (k > 0 && !(distance3(x - 3, x) > 0.0)) {
                rc = fail(ps, TK_EPARSE, vline,
                          "vertex %zu of component %zu coincides with vertex %zu "
                          "(line %zu): zero-length edge", k, i, k - 1, prev_line);
                goto done;
            }
            if (k == 0)
                first_line = vline;
            /* A closed polygon that repeats its first vertex at the end is
             * the usual mistake; blame the repeat, where it must be fixed. */
            if (closed[i] && k + 1 == counts[i] &&
                !(distance3(x, c->xyz + 3 * c->offset[i]) > 0.0)) {
                rc = fail(ps, TK_EPARSE, vline,
                          "vertex %zu of closed component %zu coincides with its "
                          "vertex 0 (line %zu): zero-length closing edge; do not "
                          "repeat the first vertex at the end", k, i, first_line);
                goto done;
            }
            prev_line = vline;
        }
    }

    if (ncol > 0) {
        c->colour = malloc(4 * nc * sizeof *c->colour);
        if (!c->colour) {
            rc = tk_error_set(ps->err, TK_ENOMEM, "out of memory for colours");
            goto done;
        }
        c->has_colour = true;
        size_t first_coloured = nc;
        for (size_t i = 0; i < nc; i++) {
            for (size_t j = 0; j < ncolour[i]; j++) {
                double rgba[4];
                for (int a = 0; a < 4; a++) {
                    snprintf(what, sizeof what, "colour value %c of colour %zu of "
                             "component %zu", CHANNEL[a], j, i);
                    if ((rc = expect_real(ps, what, &rgba[a], &line)))
                        goto done;
                }
                if (j == 0)
                    memcpy(c->colour + 4 * i, rgba, sizeof rgba);
            }
            if (ncolour[i] > 0 && first_coloured == nc)
                first_coloured = i;
            /* Geomview: a component without colours takes the previous one's. */
            if (ncolour[i] == 0 && first_coloured < nc)
                memcpy(c->colour + 4 * i, c->colour + 4 * (i - 1), 4 * sizeof *c->colour);
        }
        /* Components before the first coloured one have no previous colour;
         * they take the first colour in the file so that every component
         * has one. */
        for (size_t i = 0; i < first_coloured && first_coloured < nc; i++)
            memcpy(c->colour + 4 * i, c->colour + 4 * first_coloured,
                   4 * sizeof *c->colour);
    }

    token extra = next_token(&ps->lx);
    if (extra.n != 0) {
        char found[4 * VECT_SHOW_TOKEN + 64];
        describe_token(&extra, found, sizeof found);
        rc = fail(ps, TK_EPARSE, extra.line, "unexpected text after the %s: %s",
                  ncol > 0 ? "colours" : "vertices (the file has no colours)", found);
        goto done;
    }

    tk_error verr;
    if (tk_curve_validate(c, &verr) != TK_OK) {
        rc = fail(ps, TK_EPARSE, eof_line(&ps->lx), "%s", verr.message);
        goto done;
    }
    if ((rc = apply_constraints(ps, c)))
        goto done;
    *out = c;
    c = NULL;

done:
    tk_curve_free(&c);
    free(counts);
    free(ncolour);
    free(closed);
    return rc;
}

/* Numbers are always in the "C" locale; see the top of the file.  If the
 * locale object cannot be made, the thread's locale is used as it is. */
typedef struct c_numeric {
    locale_t c;
    locale_t saved;
} c_numeric;

static void c_numeric_enter(c_numeric *n)
{
    n->c = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    n->saved = (locale_t)0;
    if (n->c != (locale_t)0)
        n->saved = uselocale(n->c);
}

static void c_numeric_leave(c_numeric *n)
{
    if (n->c != (locale_t)0) {
        uselocale(n->saved);
        freelocale(n->c);
    }
}

int tk_vect_parse(const char *text, size_t len, const tk_vect_limits *limits,
                  tk_curve **out, tk_error *err)
{
    static const tk_vect_limits defaults = TK_VECT_LIMITS_INIT;
    if (!out)
        return tk_error_set(err, TK_EINVAL, "tk_vect_parse: out is NULL");
    *out = NULL;
    if (!text && len > 0)
        return tk_error_set(err, TK_EINVAL, "tk_vect_parse: text is NULL");
    tk_error_clear(err);
    parser ps = {{(const unsigned char *)text, text ? len : 0, 0, 1}, err};
    /* Windows editors like to start UTF-8 text with a byte order mark. */
    if (ps.lx.len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        ps.lx.pos = 3;
    c_numeric loc;
    c_numeric_enter(&loc);
    int rc = parse_vect(&ps, limits ? limits : &defaults, out);
    c_numeric_leave(&loc);
    free(ps.lx.dirs);
    return rc;
}

/* ---------------------------------------------------------------- files */

/* Reads a whole file, refusing more than VECT_MAX_FILE bytes.  Reads in
 * chunks rather than trusting st_size so that pipes and files that grow
 * while being read are handled too. */
static int read_whole(const char *path, char **data, size_t *size, tk_error *err)
{
    int rc = TK_OK;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    *data = NULL;
    *size = 0;
    /* "-" is standard input as it is: opening /dev/stdin fails where it is
     * a socket (a pipe from node's child_process is one) */
    bool std_in = strcmp(path, "-") == 0;
    FILE *f = std_in ? stdin : fopen(path, "rb");
    if (!f) {
        rc = tk_error_set(err, TK_EIO, "%s: cannot open: %s", path, strerror(errno));
        goto done;
    }
    struct stat st;
    if (fstat(fileno(f), &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            rc = tk_error_set(err, TK_EIO, "%s: is a directory", path);
            goto done;
        }
        if (S_ISREG(st.st_mode) && (uintmax_t)st.st_size > VECT_MAX_FILE) {
            rc = tk_error_set(err, TK_ELIMIT, "%s: %jd bytes is over the limit of %zu",
                              path, (intmax_t)st.st_size, VECT_MAX_FILE);
            goto done;
        }
        if (S_ISREG(st.st_mode) && st.st_size > 0)
            cap = (size_t)st.st_size + 1; /* +1 so that EOF shows without a regrow */
    }
    if (cap < 4096)
        cap = 4096;
    buf = malloc(cap);
    if (!buf) {
        rc = tk_error_set(err, TK_ENOMEM, "%s: out of memory reading the file", path);
        goto done;
    }
    for (;;) {
        if (n == cap) {
            if (cap > VECT_MAX_FILE)
                break; /* reported below */
            size_t grow = cap > VECT_MAX_FILE / 2 ? VECT_MAX_FILE + 1 : 2 * cap;
            char *grown = realloc(buf, grow);
            if (!grown) {
                rc = tk_error_set(err, TK_ENOMEM, "%s: out of memory reading the file",
                                  path);
                goto done;
            }
            buf = grown;
            cap = grow;
        }
        size_t want = cap - n;
        size_t got = fread(buf + n, 1, want, f);
        n += got;
        if (got < want) {
            if (ferror(f)) {
                rc = tk_error_set(err, TK_EIO, "%s: read error: %s", path, strerror(errno));
                goto done;
            }
            break; /* end of file */
        }
    }
    if (n > VECT_MAX_FILE) {
        rc = tk_error_set(err, TK_ELIMIT, "%s: over the limit of %zu bytes", path,
                          VECT_MAX_FILE);
        goto done;
    }
    *data = buf;
    *size = n;
    buf = NULL;

done:
    free(buf);
    if (f && !std_in)
        fclose(f);
    return rc;
}

int tk_vect_read_file(const char *path, const tk_vect_limits *limits,
                      tk_curve **out, tk_error *err)
{
    if (!out)
        return tk_error_set(err, TK_EINVAL, "tk_vect_read_file: out is NULL");
    *out = NULL;
    if (!path)
        return tk_error_set(err, TK_EINVAL, "tk_vect_read_file: path is NULL");
    char *text = NULL;
    size_t len = 0;
    int rc = read_whole(path, &text, &len, err);
    if (rc)
        return rc;
    tk_error perr;
    tk_error_clear(&perr);
    rc = tk_vect_parse(text, len, limits, out, &perr);
    free(text);
    if (rc) {
        /* "line 7: ..." becomes "PATH:7: ...", the compiler convention. */
        const char *m = perr.message;
        size_t digits = 0;
        if (strncmp(m, "line ", 5) == 0)
            while (m[5 + digits] >= '0' && m[5 + digits] <= '9')
                digits++;
        if (digits > 0 && m[5 + digits] == ':')
            tk_error_set(err, rc, "%s:%s", path, m + 5);
        else
            tk_error_set(err, rc, "%s: %s", path, m);
    }
    return rc;
}

/* ---------------------------------------------------------------- writing */

/* The writer refuses curves the reader would refuse (tk_curve_validate),
 * so that whatever it writes can be read back. */
static int write_vect(const tk_curve *c, FILE *f, tk_error *err)
{
    tk_error verr;
    int rc = tk_curve_validate(c, &verr);
    if (rc)
        return tk_error_set(err, rc, "cannot write VECT: %s", verr.message);
    bool colour = c->has_colour && c->colour;
    if (colour)
        for (size_t i = 0; i < 4 * c->ncomp; i++)
            if (!isfinite(c->colour[i]))
                return tk_error_set(err, TK_EINVAL,
                                    "cannot write VECT: component %zu has a non-finite "
                                    "colour value", i / 4);

    if (fprintf(f, "VECT\n%zu %zu %zu\n", c->ncomp, c->nvert, colour ? c->ncomp : 0) < 0)
        goto io;
    for (size_t i = 0; i < c->ncomp; i++)
        if (fprintf(f, "%s%s%zu", i ? " " : "", c->closed[i] ? "-" : "",
                    tk_curve_comp_vertices(c, i)) < 0)
            goto io;
    if (fputc('\n', f) == EOF)
        goto io;
    for (size_t i = 0; i < c->ncomp; i++)
        if (fprintf(f, "%s%d", i ? " " : "", colour ? 1 : 0) < 0)
            goto io;
    if (fputc('\n', f) == EOF)
        goto io;
    /* the pins as constraint comments, numbered in their order */
    for (size_t i = 0; i < c->npins; i++) {
        const tk_pin *p = &c->pins[i];
        double v[6];
        int count = tk_pin_count(p->kind);
        tk_pin_numbers(p, v);
        /* the kind capitalised, as the catalogue's clasp writes it */
        const char *name = tk_pin_kind_name(p->kind);
        if (fprintf(f, "# Constraint %zu %c%s", i + 1, toupper((unsigned char)name[0]), name + 1) < 0)
            goto io;
        for (int k = 0; k < count; k++)
            if (fprintf(f, " %.17g", v[k]) < 0)
                goto io;
        if (fputc('\n', f) == EOF)
            goto io;
    }
    for (size_t v = 0; v < c->nvert; v++) {
        const double *x = c->xyz + 3 * v;
        if (fprintf(f, "%.17g %.17g %.17g", x[0], x[1], x[2]) < 0)
            goto io;
        for (size_t i = 0; i < c->npins; i++)
            if (c->offset[c->pins[i].comp] + c->pins[i].vertex == v &&
                fprintf(f, " # Cst: %zu", i + 1) < 0)
                goto io;
        if (fputc('\n', f) == EOF)
            goto io;
    }
    if (colour)
        for (size_t i = 0; i < c->ncomp; i++) {
            const double *k = c->colour + 4 * i;
            if (fprintf(f, "%.17g %.17g %.17g %.17g\n", k[0], k[1], k[2], k[3]) < 0)
                goto io;
        }
    if (fflush(f) != 0 || ferror(f))
        goto io;
    return TK_OK;

io:
    return tk_error_set(err, TK_EIO, "writing VECT failed: %s", strerror(errno));
}

int tk_vect_write(const tk_curve *c, FILE *f, tk_error *err)
{
    if (!c || !f)
        return tk_error_set(err, TK_EINVAL, "tk_vect_write: %s is NULL",
                            !c ? "the curve" : "the file");
    c_numeric loc;
    c_numeric_enter(&loc);
    int rc = write_vect(c, f, err);
    c_numeric_leave(&loc);
    return rc;
}

int tk_vect_to_string(const tk_curve *c, char **out, size_t *len, tk_error *err)
{
    if (!out)
        return tk_error_set(err, TK_EINVAL, "tk_vect_to_string: out is NULL");
    *out = NULL;
    if (len)
        *len = 0;
    char *buf = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f)
        return tk_error_set(err, TK_ENOMEM, "out of memory for the VECT text");
    int rc = tk_vect_write(c, f, err);
    if (fclose(f) != 0 && rc == TK_OK)
        rc = tk_error_set(err, TK_ENOMEM, "out of memory for the VECT text");
    if (rc) {
        free(buf);
        return rc;
    }
    *out = buf;
    if (len)
        *len = size;
    return TK_OK;
}
