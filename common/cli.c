/* tightknot: command lines from tables (see cli.h). */
#include "cli.h"

#include <assert.h>
#include <ctype.h>
#include <getopt.h>
#include <string.h>

static tk_cli_option *add(tk_cli *c, const char *name, int letter, const char *arg,
                          const char *help)
{
    assert(c->n < TK_CLI_MAX && strlen(name) < TK_CLI_NAME);
    tk_cli_option *o = &c->opt[c->n];
    snprintf(c->names[c->n], TK_CLI_NAME, "%s", name);
    *o = (tk_cli_option){.name = c->names[c->n], .letter = letter, .arg = arg, .help = help};
    c->n++;
    return o;
}

void tk_cli_text(tk_cli *c, const char *name, int letter, const char *arg, const char **out,
                 const char *help)
{
    add(c, name, letter, arg, help)->text = out;
}

void tk_cli_flag(tk_cli *c, const char *name, int letter, bool *out, const char *help)
{
    add(c, name, letter, NULL, help)->flag = out;
}

void tk_cli_texts(tk_cli *c, const char *name, const char *arg, const char **out, size_t most,
                  size_t *count, const char *help)
{
    tk_cli_option *o = add(c, name, 0, arg, help);
    o->texts = out;
    o->count = count;
    o->most = most;
    *count = 0;
}

void tk_cli_fields(tk_cli *c, const tk_field *table, size_t n, void *record)
{
    for (size_t k = 0; k < n; k++) {
        const tk_field *f = &table[k];
        for (int neg = 0; f->name && neg <= (f->kind == TK_KIND_BOOL); neg++) {
            char name[TK_CLI_NAME];
            snprintf(name, sizeof name, "%s%s", neg ? "no-" : "", f->name);
            for (char *p = name; *p; p++)
                *p = *p == '_' ? '-' : *p;
            tk_cli_option *o = add(c, name, 0, f->kind == TK_KIND_BOOL ? NULL
                                               : f->kind == TK_KIND_REAL ? "X"
                                                                         : "N", f->help);
            o->field = f;
            o->record = record;
            o->negated = neg;
        }
    }
}

void tk_cli_defaults(const tk_field *table, size_t n, void *record)
{
    for (size_t k = 0; k < n; k++) {
        int rc = tk_field_set(&table[k], record, table[k].dflt, NULL);
        assert(rc == TK_OK); /* a default lies in its domain */
        (void)rc;
    }
}

/* Sets option o from its value (NULL for one that takes none). */
static int apply(const tk_cli_option *o, const char *value, tk_error *err)
{
    if (o->flag)
        *o->flag = true;
    if (o->text)
        *o->text = value;
    if (o->texts) {
        if (*o->count == o->most)
            return tk_error_set(err, TK_EINVAL, "--%s: given more than %zu times", o->name,
                                o->most);
        o->texts[(*o->count)++] = value;
    }
    if (!o->field)
        return TK_OK;
    tk_error why;
    int rc = o->field->kind == TK_KIND_BOOL ? tk_field_set(o->field, o->record, !o->negated, &why)
                                            : tk_field_parse(o->field, o->record, value, &why);
    if (rc == TK_OK)
        return TK_OK;
    /* "option 'steps': ..." reads "--steps: ..." on a command line */
    const char *rest = strstr(why.message, "': ");
    return tk_error_set(err, rc, "--%s: %s", o->name, rest ? rest + 3 : why.message);
}

int tk_cli_parse(tk_cli *c, int argc, char **argv, int *npos, tk_error *err)
{
    struct option longs[TK_CLI_MAX + 1];
    char shorts[2 * TK_CLI_MAX + 3] = "+:";
    for (size_t k = 0; k < c->n; k++) {
        const tk_cli_option *o = &c->opt[k];
        longs[k] = (struct option){o->name, o->arg ? required_argument : no_argument, NULL,
                                   256 + (int)k};
        if (o->letter) {
            size_t len = strlen(shorts);
            shorts[len] = (char)o->letter;
            shorts[len + 1] = o->arg ? ':' : '\0';
            shorts[len + 2] = '\0';
        }
    }
    longs[c->n] = (struct option){0};
    /* getopt_long reads from argv[1]; "+" keeps it from permuting, so the
     * other arguments are gathered here and options may follow them */
    char **args = argv - 1;
    int nargs = argc + 1;
    *npos = 0;
    optind = 0; /* glibc: start afresh */
    opterr = 0;
    for (;;) {
        int before = optind > 0 ? optind : 1;
        if (before >= nargs)
            return TK_OK;
        const char *next = args[before];
        if (next[0] == '-' && (isdigit((unsigned char)next[1]) || next[1] == '.')) {
            argv[(*npos)++] = args[before]; /* a negative number */
            optind = before + 1;
            continue;
        }
        int code = getopt_long(nargs, args, shorts, longs, NULL);
        if (code == -1 && optind == before + 1 && !strcmp(args[before], "--")) {
            while (optind < nargs)
                argv[(*npos)++] = args[optind++];
            return TK_OK;
        }
        if (code == -1) {
            argv[(*npos)++] = args[optind++];
            continue;
        }
        if (code == '?')
            return tk_error_set(err, TK_EINVAL, "unknown option '%s'", args[optind - 1]);
        if (code == ':')
            return tk_error_set(err, TK_EINVAL, "option %s needs a value", args[optind - 1]);
        size_t k = code >= 256 ? (size_t)code - 256 : 0;
        while (code < 256 && k < c->n && c->opt[k].letter != code)
            k++;
        assert(k < c->n); /* getopt returns only the letters it was given */
        if (apply(&c->opt[k], optarg, err))
            return TK_EINVAL;
        c->opt[k].given = true;
    }
}

bool tk_cli_given(const tk_cli *c, const void *record, const char *name)
{
    for (size_t k = 0; k < c->n; k++)
        if (c->opt[k].given && c->opt[k].record == record && c->opt[k].field &&
            c->opt[k].field->name && !strcmp(c->opt[k].field->name, name))
            return true;
    return false;
}

void tk_cli_help(const tk_cli *c, FILE *out)
{
    for (size_t k = 0; k < c->n; k++) {
        const tk_cli_option *o = &c->opt[k];
        if (o->negated)
            continue; /* shown with its positive form */
        char flag[2 * TK_CLI_NAME + 16], text[1024];
        int at = snprintf(flag, sizeof flag, "%c%c%s--%s", o->letter ? '-' : ' ',
                          o->letter ? o->letter : ' ', o->letter ? ", " : "", o->name);
        if (o->field && o->field->kind == TK_KIND_BOOL)
            snprintf(flag + at, sizeof flag - (size_t)at, ", --no-%s", o->name);
        else if (o->arg)
            snprintf(flag + at, sizeof flag - (size_t)at, " %s", o->arg);
        const char *start = o->letter ? flag : flag + 2;
        if (!o->field)
            snprintf(text, sizeof text, "%s", o->help);
        else if (o->field->kind == TK_KIND_BOOL)
            snprintf(text, sizeof text, "%s (default %s)", o->help, o->field->dflt ? "on" : "off");
        else
            snprintf(text, sizeof text, "%s (default %.15g)", o->help, o->field->dflt);
        /* the flag in 22 columns (alone on its line when longer), the help
         * from column 25, wrapped at 78 */
        int width = (int)strlen(start);
        fprintf(out, "  %s%*s", start, width <= 20 ? 22 - width : 0, "");
        if (width > 20)
            fprintf(out, "\n%24s", "");
        for (const char *p = text; *p;) {
            size_t len = strlen(p), cut = len;
            if (len > 54) {
                for (cut = 54; cut > 0 && p[cut] != ' '; cut--)
                    ;
                cut = cut ? cut : 54;
            }
            fprintf(out, "%.*s\n", (int)cut, p);
            for (p += cut; *p == ' ';)
                p++;
            if (*p)
                fprintf(out, "%24s", "");
        }
    }
}
