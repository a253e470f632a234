/* tightknot: error values.
 *
 * Every engine function that can fail returns an int status (TK_OK == 0)
 * and, when given a non-NULL tk_error, fills it with a message the caller
 * can show as it is.  The engine never prints and never exits.
 */
#ifndef TK_ERROR_H
#define TK_ERROR_H

#include <stddef.h>

enum tk_status {
    TK_OK = 0,
    TK_ENOMEM = 1,   /* an allocation failed */
    TK_EINVAL = 2,   /* an argument is out of its domain */
    TK_EPARSE = 3,   /* input text is malformed (message names the line) */
    TK_EIO = 4,      /* reading or writing a file failed */
    TK_ENUMERIC = 5, /* numerical trouble the engine could not recover from */
    TK_ECANCELLED = 6,
    TK_ELIMIT = 7,   /* input exceeds a configured limit */
    TK_ENOTFOUND = 8,/* no such item (a job id, a catalogue name) */
    TK_EBUSY = 9,    /* a queue or pool is full; try again later */
    TK_ETYPE = 10    /* the knot or link type changed (a strand passed
                        through another) */
};

#define TK_ERROR_MESSAGE_SIZE 320

typedef struct tk_error {
    int code;
    char message[TK_ERROR_MESSAGE_SIZE];
} tk_error;

/* Fills err (if non-NULL) with code and a printf-style message; returns code
 * so that callers can write `return tk_error_set(err, TK_EINVAL, "...")`. */
int tk_error_set(tk_error *err, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Clears err to TK_OK and an empty message. */
void tk_error_clear(tk_error *err);

/* A short constant name for a status code ("parse error", ...). */
const char *tk_status_name(int code);

#endif
