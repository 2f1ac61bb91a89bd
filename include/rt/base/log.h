/* rt/base/log.h - warnings and verbose figures on stderr, one level for the
 * process.
 *
 *   rt_log_set_level(RT_LOG_QUIET);        // once, by the driver, before any work
 *   rt_warn("%s:%d: unknown key '%s'", file, line, key);  // "rt: warning: ..."
 *   rt_info("kd-tree: %zu nodes", n);      // "rt: kd-tree: ...", only with -v
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
void rt_info(const char *fmt, ...) RT_PRINTF(1, 2);   /* "rt: ..." only with -v */

#endif
