#include "tk/error.h"

#include <stdarg.h>
#include <stdio.h>

int tk_error_set(tk_error *err, int code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        err->code = code;
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
    }
    return code;
}

void tk_error_clear(tk_error *err)
{
    if (err) {
        err->code = TK_OK;
        err->message[0] = '\0';
    }
}

const char *tk_status_name(int code)
{
    switch (code) {
    case TK_OK: return "ok";
    case TK_ENOMEM: return "out of memory";
    case TK_EINVAL: return "invalid argument";
    case TK_EPARSE: return "parse error";
    case TK_EIO: return "i/o error";
    case TK_ENUMERIC: return "numerical failure";
    case TK_ECANCELLED: return "cancelled";
    case TK_ELIMIT: return "limit exceeded";
    case TK_ENOTFOUND: return "not found";
    case TK_EBUSY: return "busy";
    case TK_ETYPE: return "knot type changed";
    default: return "unknown error";
    }
}
