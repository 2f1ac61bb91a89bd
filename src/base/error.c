/* error.c - the result enum, located error messages and the invariant
 * check's report (rt/base/error.h). */
#include "rt/base/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

rt_result rt_fail(rt_error *err, rt_result code, const char *fmt, ...)
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

const char *rt_result_name(rt_result code)
{
    switch (code) {
    case RT_OK: return "ok";
    case RT_ERR_IO: return "i/o error";
    case RT_ERR_PARSE: return "parse error";
    case RT_ERR_INVALID: return "invalid input";
    case RT_ERR_UNSUPPORTED: return "unsupported";
    case RT_ERR_NOMEM: return "out of memory";
    case RT_ERR_LIMIT: return "over a limit";
    case RT_ERR_INTERRUPTED: return "interrupted";
    }
    return "unknown error";
}

void rt_check_failed(const char *file, int line, const char *expr)
{
    fprintf(stderr, "rt: internal error: %s:%d: check failed: %s\n", file, line, expr);
    abort();
}
