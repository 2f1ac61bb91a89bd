/* rt/base/log.h - warnings, notes and verbose figures on stderr, one level
 * for the process, and the one status line (the driver's progress bar)
 * that they never run into.
 *
 *   rt_log_set_level(RT_LOG_QUIET);        // once, by the driver, before any work
 *   rt_warn("%s:%d: unknown key '%s'", file, line, key);  // "rt: warning: ..."
 *   rt_note("display server %s: connected", addr);        // "rt: ...", unless -q
 *   rt_info("kd-tree: %zu nodes", n);      // "rt: kd-tree: ...", only with -v
 *
 *   rt_log_status("render [###   ]  50.0%%");  // "\r" + the line, erasing what a longer one left
 *   rt_log_status_keep();                  // ends it with a newline: it stays on screen
 *   rt_log_status_clear();                 // erases it (a no-op when none is shown)
 *
 * Only this module knows whether a status line is on screen: rt_warn,
 * rt_note and rt_info erase it before their line (the next status line
 * draws it again), and any other writer to the terminal (a message
 * printed with fprintf, a line on stdout) calls rt_log_status_clear()
 * first. The status functions write whatever the level; the driver draws
 * a status line only when stderr is a terminal.
 *
 * Warnings are for input that is odd but usable; anything that stops a load
 * is an rt_error (rt/base/error.h) instead.
 */
#ifndef RT_LOG_H
#define RT_LOG_H

#include "rt/base/error.h"

typedef enum rt_log_level { RT_LOG_QUIET = 0, RT_LOG_NORMAL = 1, RT_LOG_VERBOSE = 2 } rt_log_level;

/* Set once by the driver before any work starts; read-only afterwards. */
void rt_log_set_level(rt_log_level level);
rt_log_level rt_log_get_level(void);
void rt_warn(const char *fmt, ...) RT_PRINTF(1, 2);   /* "rt: warning: ..." unless quiet */
void rt_note(const char *fmt, ...) RT_PRINTF(1, 2);   /* "rt: ..." unless quiet */
void rt_info(const char *fmt, ...) RT_PRINTF(1, 2);   /* "rt: ..." only with -v */

/* The status line: drawn over the one before (carriage return, the text,
 * erase to the end of the line), kept (a newline), or erased. */
void rt_log_status(const char *fmt, ...) RT_PRINTF(1, 2);
void rt_log_status_keep(void);
void rt_log_status_clear(void);

#endif
