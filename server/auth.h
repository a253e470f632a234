/* tightknot service: who is asking.  A tokens file names the clients:
 *
 *   # name  token                                           [admin]
 *   alice   sha256:2bb80d537b1da3e38bd30361aa855686bde0eacd7162fef6a25fe97bf527a25b
 *   bob     s3cret-bob-token                                 admin
 *
 * A token as it is (at least TK_TOKEN_MIN characters) or as "sha256:" and
 * its SHA-256 in hex, so the file need hold no secret; only hashes are
 * kept.  A '#' first on a line makes a comment, elsewhere it is the
 * token's.  A request sends "Authorization: Bearer TOKEN".
 */
#ifndef TK_SERVER_AUTH_H
#define TK_SERVER_AUTH_H

#include <stdbool.h>

#include "tk/error.h"

/* Shorter tokens are refused when the file is read. */
#define TK_TOKEN_MIN 16

typedef struct tk_tokens tk_tokens;

/* Reads the file; TK_EPARSE naming the line of a malformed one. */
int tk_tokens_load(const char *path, tk_tokens **out, tk_error *err);
void tk_tokens_free(tk_tokens **t);

/* The name whose token an Authorization header's value ("Bearer TOKEN")
 * carries, *admin whether it is marked admin; NULL when none does. */
const char *tk_tokens_check(const tk_tokens *t, const char *authorization, bool *admin);

#endif
