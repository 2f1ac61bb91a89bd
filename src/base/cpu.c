/* cpu.c - the processors this process may use (rt/base/cpu.h): the size of
 * its affinity mask (sched_getaffinity(2), CPU_COUNT), else the online
 * processors (sysconf _SC_NPROCESSORS_ONLN). A job that a scheduler pinned
 * to 4 of a node's 64 cores then starts 4 render threads, not 64. */
#define _GNU_SOURCE
#include "rt/base/cpu.h"

#include <sched.h>
#include <unistd.h>

int rt_cpu_count(void)
{
    long n = 0;
#ifdef CPU_COUNT
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0)
        n = CPU_COUNT(&set);
#endif
    if (n <= 0)
        n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (n > 1024 ? 1024 : (int)n) : 1;
}
