/* memory_budget.h - the `rt` process's memory budget (driver-private).
 *
 * rt runs under a budget: --max-memory, else 75% of the physical memory (or
 * of the cgroup's limit when that is lower). An allocation past it fails, and
 * the driver says which budget ran out and how to raise it, instead of
 * swapping or meeting the OOM killer.
 *
 *   memory_budget b = {memory_budget_default(), false, false};
 *   if (!memory_budget_parse("4G", &b.bytes)) ... refuse the flag ...
 *   memory_budget_apply(&b);          // once, before loading; logs the budget with -v
 *   ... b.enforced says whether it took ...
 *   memory_budget_report(&err, &b);   // "rt: MESSAGE", and for out of memory which budget ran out
 */
#ifndef RT_DRIVER_MEMORY_BUDGET_H
#define RT_DRIVER_MEMORY_BUDGET_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"

typedef struct memory_budget {
    unsigned long long bytes; /* 0 = none */
    bool from_flag;           /* --max-memory given */
    bool enforced;            /* setrlimit took it */
} memory_budget;

/* 75% of physical memory (or of the cgroup limit, when lower). */
unsigned long long memory_budget_default(void);
/* "4G", "512M", "1.5g", "300000K", "123456789" (bytes); "0", "none" or
 * "unlimited" turn the budget off (*out = 0). */
bool memory_budget_parse(const char *s, unsigned long long *out);
/* "4.0 GiB", "512 MiB" */
void memory_budget_format(unsigned long long bytes, char *buf, size_t size);
/* Caps the data segment at b->bytes (not in sanitizer builds) and says so with -v. */
void memory_budget_apply(memory_budget *b);
/* Prints an error on stderr; out-of-memory errors also say which budget
 * ran out and how to raise it. */
void memory_budget_report(const rt_error *err, const memory_budget *b);

#endif
