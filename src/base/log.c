/* log.c - the process's log level, warnings, notes and verbose lines on
 * stderr, and the status line they erase before writing (rt/base/log.h).
 * Whether a status line is on screen is the terminal's own state, so it is
 * the process's: one flag, atomic because a warning may come from another
 * thread than the one drawing the progress bar. */
#include "rt/base/log.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>

static rt_log_level log_level = RT_LOG_NORMAL;
static atomic_bool status_shown; /* a status line is on the terminal, not ended by a newline */

void rt_log_set_level(rt_log_level level) { log_level = level; }
rt_log_level rt_log_get_level(void) { return log_level; }

void rt_log_status_clear(void)
{
    if (atomic_exchange(&status_shown, false)) {
        fputs("\r\033[K", stderr);
        fflush(stderr);
    }
}

void rt_log_status_keep(void)
{
    if (atomic_exchange(&status_shown, false)) {
        fputc('\n', stderr);
        fflush(stderr);
    }
}

void rt_log_status(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputc('\r', stderr);
    vfprintf(stderr, fmt, ap);
    fputs("\033[K", stderr); /* erase what a longer line left */
    fflush(stderr);
    va_end(ap);
    atomic_store(&status_shown, true);
}

/* One line on stderr, on a line of its own: the prefix, the message, a newline. */
static void vline(const char *prefix, const char *fmt, va_list ap)
{
    rt_log_status_clear();
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

void rt_note(const char *fmt, ...)
{
    if (log_level < RT_LOG_NORMAL)
        return;
    va_list ap;
    va_start(ap, fmt);
    vline("rt: ", fmt, ap);
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
