/* near_miss.c - "did you mean" hints (rt/base/near_miss.h): the
 * Levenshtein edit distance by the textbook dynamic programme over a
 * (n+1) x (m+1) table, on words of at most 32 characters. */
#include "rt/base/near_miss.h"

#include <stddef.h>
#include <string.h>

int rt_edit_distance(const char *a, const char *b)
{
    size_t n = strlen(a), m = strlen(b);
    if (n > 32 || m > 32)
        return 99;
    int d[33][33];
    for (size_t i = 0; i <= n; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= m; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= n; i++)
        for (size_t j = 1; j <= m; j++) {
            int c = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            int del = d[i - 1][j] + 1, ins = d[i][j - 1] + 1;
            d[i][j] = c < del ? (c < ins ? c : ins) : (del < ins ? del : ins);
        }
    return d[n][m];
}

rt_near_miss rt_near_miss_of(const char *word) { return (rt_near_miss){word, NULL, 3}; }

void rt_near_miss_consider(rt_near_miss *n, const char *candidate)
{
    int d = rt_edit_distance(n->word, candidate);
    if (d < n->best_d)
        n->best_d = d, n->best = candidate;
}
