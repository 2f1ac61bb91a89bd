/* mesh_text.h - what the text mesh readers (OBJ and MTL, ascii PLY, OFF)
 * share: locale-free number parsing on byte ranges, blanks and tokens, and
 * warning once per keyword. Private to src/io; below the readers, above
 * nothing but the error record.
 *
 *   const char *q = rt_mesh_skip_space(p, eol), *te = rt_mesh_token_end(q, eol);
 *   float f;
 *   bool nonfinite;
 *   if (rt_mesh_parse_float(q, te, &f, &nonfinite) != te) ... // not a number, or not finite
 */
#ifndef RT_MESH_TEXT_H
#define RT_MESH_TEXT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Number parsing on [p, end) without locale or allocation. Both return the
 * position after the number, or NULL when no number starts at p. Floats are
 * correctly rounded (a fast exact path, else strtof on a bounded copy).
 * *nonfinite is set when the text is a number but not a finite float
 * ("nan", "inf", 1e39); then the return value is still NULL. */
const char *rt_mesh_parse_float(const char *p, const char *end, float *out, bool *nonfinite);
const char *rt_mesh_parse_int(const char *p, const char *end, int64_t *out);

/* Warn once per keyword per file: a small set of keywords already warned about. */
typedef struct rt_warn_once {
    char seen[32][24];
    int count;
} rt_warn_once;
/* True the first time `key` (len bytes) is seen; false after (and when full). */
bool rt_warn_once_first(rt_warn_once *w, const char *key, size_t len);

static inline bool rt_mesh_is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
/* The first non-space character at or after p (end when none). */
static inline const char *rt_mesh_skip_space(const char *p, const char *end)
{
    while (p < end && rt_mesh_is_space(*p))
        p++;
    return p;
}
/* The end of the token starting at p. */
static inline const char *rt_mesh_token_end(const char *p, const char *end)
{
    while (p < end && !rt_mesh_is_space(*p))
        p++;
    return p;
}

#endif
