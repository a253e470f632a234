/* tightknot service: who is asking (see auth.h). */
#define _GNU_SOURCE
#include "auth.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <gnutls/crypto.h>
#include <gnutls/gnutls.h>

typedef struct entry {
    char name[64];
    unsigned char hash[32];
    bool admin;
} entry;

struct tk_tokens {
    entry *e;
    size_t n;
};

int tk_tokens_load(const char *path, tk_tokens **out, tk_error *err)
{
    *out = NULL;
    FILE *f = fopen(path, "r");
    if (!f)
        return tk_error_set(err, TK_EIO, "--tokens: cannot read %s", path);
    tk_tokens *t = calloc(1, sizeof *t);
    char *line = NULL;
    size_t cap = 0;
    int rc = t ? TK_OK : tk_error_set(err, TK_ENOMEM, "out of memory");
    for (long no = 1; !rc && getline(&line, &cap, f) >= 0; no++) {
        /* a comment is a whole line: a '#' inside a token is the token's */
        line[strcspn(line, "\r\n")] = '\0';
        char name[64], token[512], mark[16], extra;
        int k = line[strspn(line, " \t")] == '#'
                    ? 0
                    : sscanf(line, "%63s %511s %15s %c", name, token, mark, &extra);
        if (k <= 0)
            continue; /* blank or a comment */
        entry e = {.admin = k >= 3 && !strcmp(mark, "admin")};
        snprintf(e.name, sizeof e.name, "%s", name);
        bool hashed = !strncasecmp(token, "sha256:", 7);
        size_t hash_size = sizeof e.hash;
        entry *grown = NULL;
        if (k < 2 || k > 3 || (k == 3 && !e.admin) || strlen(name) > 62 || strlen(token) > 510 ||
            (hashed && (strlen(token + 7) != 64 ||
                        gnutls_hex2bin(token + 7, 64, e.hash, &hash_size) || hash_size != 32)))
            rc = tk_error_set(err, TK_EPARSE, "%s:%ld: expected 'NAME TOKEN' or 'NAME "
                              "sha256:HEX' (64 hex digits; a name of at most 62 bytes, a token of at most 510), "
                              "then optionally 'admin'", path, no);
        else if (!hashed && strlen(token) < TK_TOKEN_MIN)
            rc = tk_error_set(err, TK_EPARSE, "%s:%ld: the token has %zu character%s; a token "
                              "needs at least %d, or a client could guess it", path, no,
                              strlen(token), strlen(token) == 1 ? "" : "s", TK_TOKEN_MIN);
        else if (!hashed && gnutls_hash_fast(GNUTLS_DIG_SHA256, token, strlen(token), e.hash))
            rc = tk_error_set(err, TK_EIO, "--tokens: cannot hash a token");
        else if (!(grown = realloc(t->e, (t->n + 1) * sizeof *grown)))
            rc = tk_error_set(err, TK_ENOMEM, "out of memory");
        else
            (t->e = grown)[t->n++] = e;
    }
    free(line);
    fclose(f);
    if (!rc && t->n == 0)
        rc = tk_error_set(err, TK_EPARSE, "%s: no tokens", path);
    if (rc)
        tk_tokens_free(&t);
    *out = t;
    return rc;
}

void tk_tokens_free(tk_tokens **t)
{
    if (!t || !*t)
        return;
    free((*t)->e);
    free(*t);
    *t = NULL;
}

const char *tk_tokens_check(const tk_tokens *t, const char *authorization, bool *admin)
{
    unsigned char hash[32];
    *admin = false;
    if (!authorization || strncasecmp(authorization, "Bearer ", 7) ||
        gnutls_hash_fast(GNUTLS_DIG_SHA256, authorization + 7, strlen(authorization + 7), hash))
        return NULL;
    const char *name = NULL;
    for (size_t i = 0; i < t->n; i++) {
        unsigned char differ = 0; /* every byte compared: no timing to learn from */
        for (int k = 0; k < 32; k++)
            differ |= (unsigned char)(hash[k] ^ t->e[i].hash[k]);
        if (!differ && !name) {
            name = t->e[i].name;
            *admin = t->e[i].admin;
        }
    }
    return name;
}
