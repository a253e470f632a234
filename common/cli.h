/* tightknot: command lines from tables, for the three programs
 * (tightknot, tightknot remote, tightknotd).
 *
 * A program lists its options once: numbers and switches as fields of a
 * record (tk/record.h: name, kind, domain, default, help), texts and flags
 * by hand.  The same list makes getopt_long's table, checks each value
 * against its field's domain, and writes the options part of --help, so a
 * help line can never disagree with what the parser takes.
 */
#ifndef TK_CLI_H
#define TK_CLI_H

#include <stdbool.h>
#include <stdio.h>

#include "tk/error.h"
#include "tk/record.h"

#define TK_CLI_MAX 96  /* options of one command line */
#define TK_CLI_NAME 40 /* longest option name */

typedef struct tk_cli_option {
    const char *name;      /* --name ('_' of a field's name written '-') */
    int letter;            /* -x as well, or 0 */
    const char *arg;       /* the value's name in --help; NULL: takes none */
    const char *help;
    const char **text;     /* a text option's value (pointing into argv) */
    const char **texts;    /* a repeated text option's values, *count of at most most */
    size_t *count, most;
    bool *flag;            /* a flag, set when given */
    const tk_field *field; /* a field of `record`, set with its domain */
    void *record;
    bool negated;          /* the --no-NAME of a BOOL field */
    bool given;            /* set by tk_cli_parse when it was on the line */
} tk_cli_option;

typedef struct tk_cli {
    tk_cli_option opt[TK_CLI_MAX];
    char names[TK_CLI_MAX][TK_CLI_NAME];
    size_t n;
} tk_cli;

/* Options: a text (--name ARG), a flag (--name), and every named field of
 * a table (--name X; a BOOL as --name and --no-name). */
void tk_cli_text(tk_cli *c, const char *name, int letter, const char *arg, const char **out,
                 const char *help);
void tk_cli_flag(tk_cli *c, const char *name, int letter, bool *out, const char *help);
/* A text option that may be given again and again: its values in order
 * at out[0 .. *count), at most `most` of them. */
void tk_cli_texts(tk_cli *c, const char *name, const char *arg, const char **out, size_t most,
                  size_t *count, const char *help);
void tk_cli_fields(tk_cli *c, const tk_field *table, size_t n, void *record);

/* Sets every field of a table to its default. */
void tk_cli_defaults(const tk_field *table, size_t n, void *record);

/* Parses argv[0..argc) (the arguments after the program's or the
 * command's name).  Options may come before and after the other
 * arguments; "--" ends them, and a negative number is an argument.  The
 * other arguments are gathered in order at the front of argv, *npos of
 * them.  TK_EINVAL with a message naming the option when one is unknown,
 * lacks its value or has a value outside its domain. */
int tk_cli_parse(tk_cli *c, int argc, char **argv, int *npos, tk_error *err);

/* Whether an option of the field `name` of `record` was on the line (its
 * --no- form too). */
bool tk_cli_given(const tk_cli *c, const void *record, const char *name);

/* The options with their help, one per line, the help wrapped at 78
 * columns; a field's help ends with its default. */
void tk_cli_help(const tk_cli *c, FILE *out);

#endif
