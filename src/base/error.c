/* error.c - the result enum, located error messages, warnings and checked
 * allocation. */
#include "rt/base/error.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rt_log_level log_level = RT_LOG_NORMAL;

void rt_log_set_level(rt_log_level level) { log_level = level; }
rt_log_level rt_log_get_level(void) { return log_level; }

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

void rt_warn(const char *fmt, ...)
{
    if (log_level < RT_LOG_NORMAL)
        return;
    va_list ap;
    va_start(ap, fmt);
    fputs("rt: warning: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void rt_info(const char *fmt, ...)
{
    if (log_level < RT_LOG_VERBOSE)
        return;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void *rt_alloc(size_t count, size_t size)
{
    if (count == 0 || size == 0)
        return calloc(1, 1);
    if (count > SIZE_MAX / size)
        return NULL;
    return calloc(count, size);
}

void *rt_realloc_array(void *p, size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size)
        return NULL;
    size_t bytes = count * size;
    return realloc(p, bytes ? bytes : 1);
}

int rt_grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap : 16;
    while (c < need) {
        if (c > SIZE_MAX / 2)
            return 0;
        c *= 2;
    }
    void *q = rt_realloc_array(*p, c, size);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

void rt_check_failed(const char *file, int line, const char *expr)
{
    fprintf(stderr, "rt: internal error: %s:%d: check failed: %s\n", file, line, expr);
    abort();
}
