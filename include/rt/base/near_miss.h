/* rt/base/near_miss.h - "did you mean" hints: the candidate closest to a
 * mistyped word by edit distance (Levenshtein), for the scene parser's
 * unknown keywords and names and the command line's unknown flags.
 *
 *   rt_near_miss n = rt_near_miss_of("sampels");
 *   for (size_t i = 0; i < count; i++)
 *       rt_near_miss_consider(&n, names[i]);
 *   if (n.best) ... "unknown keyword 'sampels' (did you mean '%s'?)", n.best ...
 */
#ifndef RT_BASE_NEAR_MISS_H
#define RT_BASE_NEAR_MISS_H

/* Shown the candidates one at a time, it keeps the first of the closest
 * within edit distance 2; best is NULL when none is that close. */
typedef struct rt_near_miss {
    const char *word, *best;
    int best_d;
} rt_near_miss;

rt_near_miss rt_near_miss_of(const char *word);
void rt_near_miss_consider(rt_near_miss *n, const char *candidate);

/* The number of single-character insertions, deletions and substitutions
 * that turn a into b; words over 32 characters are 99 apart. */
int rt_edit_distance(const char *a, const char *b);

#endif
