/* log.c - the process's log level, warnings and verbose lines on stderr
 * (rt/base/log.h). */
#include "rt/base/log.h"

#include <stdarg.h>
#include <stdio.h>

static rt_log_level log_level = RT_LOG_NORMAL;

void rt_log_set_level(rt_log_level level) { log_level = level; }
rt_log_level rt_log_get_level(void) { return log_level; }

/* One line on stderr: the prefix, the message, a newline. */
static void vline(const char *prefix, const char *fmt, va_list ap)
{
    fputs(prefix, stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

void rt_warn(const char *fmt, ...)
{
    if (log_level < RT_LOG_NORMAL)
        return;
    va_list ap;
    va_start(ap, fmt);
    vline("rt: warning: ", fmt, ap);
    va_end(ap);
}

void rt_info(const char *fmt, ...)
{
    if (log_level < RT_LOG_VERBOSE)
        return;
    va_list ap;
    va_start(ap, fmt);
    vline("rt: ", fmt, ap);
    va_end(ap);
}
