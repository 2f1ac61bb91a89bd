/* rt/base/clock.h - the one clock rt times itself with: monotonic seconds.
 *
 *   double t0 = rt_now_seconds();
 *   ...
 *   rt_info("built in %.1f ms", 1e3 * (rt_now_seconds() - t0));
 *
 * CLOCK_MONOTONIC (POSIX): never jumps with the wall clock, so durations,
 * deadlines (--time-limit) and ETAs stay right when the system time is set.
 */
#ifndef RT_CLOCK_H
#define RT_CLOCK_H

#include <time.h>

static inline double rt_now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
