/* memory_budget.c - the process's memory budget (memory_budget.h).
 *
 * Enforced with setrlimit(RLIMIT_DATA), which Linux >= 4.7 applies to the
 * heap and every private writable mapping. An allocation past it fails, the
 * checked allocation reports "out of memory", and the driver says which
 * budget was hit. Sanitizer builds skip the limit (their shadow memory would
 * trip it).
 */
#include "memory_budget.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "rt/base/error.h"
#include "rt/base/log.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define RT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define RT_SANITIZED 1
#endif
#endif
#ifndef RT_SANITIZED
#define RT_SANITIZED 0
#endif

/* The cgroup v2 (or v1) memory limit of this process, 0 when none. */
static unsigned long long cgroup_memory_limit(void)
{
    static const char *const files[] = {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"};
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        FILE *f = fopen(files[i], "r");
        if (!f)
            continue;
        char buf[64] = {0};
        bool ok = fgets(buf, sizeof buf, f) != NULL;
        fclose(f);
        if (!ok || strncmp(buf, "max", 3) == 0)
            continue;
        errno = 0;
        char *end;
        unsigned long long v = strtoull(buf, &end, 10);
        if (!errno && end != buf && v > 0 && v < (1ull << 60))
            return v;
    }
    return 0;
}

unsigned long long memory_budget_default(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    unsigned long long phys = pages > 0 && page > 0 ? (unsigned long long)pages * (unsigned long long)page : 0;
    unsigned long long cg = cgroup_memory_limit();
    if (cg && (!phys || cg < phys))
        phys = cg;
    return phys / 4 * 3;
}

bool memory_budget_parse(const char *s, unsigned long long *out)
{
    if (!s || !*s)
        return false;
    if (strcmp(s, "none") == 0 || strcmp(s, "unlimited") == 0) {
        *out = 0;
        return true;
    }
    /* a plain decimal number, as every numeric flag takes (no sign, no
     * hexadecimal, no inf or nan: strtod alone would take them), then a unit */
    size_t digits = 0, dots = 0, n = 0;
    for (; (s[n] >= '0' && s[n] <= '9') || s[n] == '.'; n++)
        s[n] == '.' ? dots++ : digits++;
    if (digits == 0 || dots > 1)
        return false;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end != s + n || !(v >= 0.0))
        return false;
    double mul = 1.0;
    switch (*end) {
    case 'k': case 'K': mul = 1024.0; end++; break;
    case 'm': case 'M': mul = 1024.0 * 1024.0; end++; break;
    case 'g': case 'G': mul = 1024.0 * 1024.0 * 1024.0; end++; break;
    case 't': case 'T': mul = 1024.0 * 1024.0 * 1024.0 * 1024.0; end++; break;
    default: break;
    }
    if (*end == 'i' && mul > 1.0) /* KiB, MiB, ... */
        end++;
    if ((*end == 'B' || *end == 'b') && end[1] == 0)
        end++;
    if (*end)
        return false;
    double bytes = v * mul;
    if (!(bytes < 9.0e18) || !(bytes >= 1.0)) /* 0 bytes would read as 'none': that is said as 'none' */
        return false;
    *out = (unsigned long long)bytes;
    return true;
}

void memory_budget_format(unsigned long long bytes, char *buf, size_t size)
{
    if (bytes >= (1ull << 30))
        snprintf(buf, size, "%.1f GiB", (double)bytes / (double)(1ull << 30));
    else
        snprintf(buf, size, "%.0f MiB", (double)bytes / (double)(1ull << 20));
}

/* Below 64 MiB nothing works at all; the flag parser refuses smaller budgets. */
void memory_budget_apply(memory_budget *b)
{
    b->enforced = false;
    struct rlimit rl;
    if (b->bytes && !RT_SANITIZED && getrlimit(RLIMIT_DATA, &rl) == 0) {
        rlim_t want = (rlim_t)b->bytes;
        if (rl.rlim_max != RLIM_INFINITY && want > rl.rlim_max)
            want = rl.rlim_max;
        if (rl.rlim_cur != RLIM_INFINITY && rl.rlim_cur < want) /* someone set a lower limit: keep it */
            want = rl.rlim_cur;
        rl.rlim_cur = want;
        if (setrlimit(RLIMIT_DATA, &rl) == 0) {
            b->bytes = (unsigned long long)want;
            b->enforced = true;
        }
    }
    if (b->enforced) {
        char sz[32];
        memory_budget_format(b->bytes, sz, sizeof sz);
        rt_info("memory budget: %s%s", sz, b->from_flag ? " (--max-memory)" : " (75% of physical memory)");
    } else {
        rt_info("memory budget: none%s", RT_SANITIZED && b->bytes ? " (not enforced in sanitizer builds)" : "");
    }
}

void memory_budget_report(const rt_error *err, const memory_budget *b)
{
    fprintf(stderr, "rt: %s\n", err->message);
    if (err->code != RT_ERR_NOMEM)
        return;
    if (b->enforced) {
        char sz[32];
        memory_budget_format(b->bytes, sz, sizeof sz);
        fprintf(stderr,
                "rt: the memory budget of %s (%s) ran out; raise it with --max-memory SIZE (e.g. --max-memory 16G, or "
                "'none' for no limit)\n",
                sz, b->from_flag ? "--max-memory" : "the default, 75% of physical memory");
    } else {
        fprintf(stderr, "rt: the machine's memory ran out (no --max-memory budget was in force)\n");
    }
}
