/* log.c - the process's log level, warnings and verbose lines on stderr
 * (rt/base/log.h). */
#include "rt/base/log.h"

#include <stdarg.h>
#include <stdio.h>

static rt_log_level log_level = RT_LOG_NORMAL;

void rt_log_set_level(rt_log_level level) { log_level = level; }
rt_log_level rt_log_get_level(void) { return log_level; }

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
    fputs("rt: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}
