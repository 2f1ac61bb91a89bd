/* rt/base/error.h - one result enum and one error record for every fallible call.
 *
 * A function that can fail on input returns rt_result and, on failure, fills
 * an rt_error whose message already names the place ("file:line:col: ..." or
 * "file: byte 1234: ...") and what is wrong. Nothing in rt asserts on input.
 *
 *   rt_error err = {0};
 *   if (rt_scene_load(&scene, path, &err) != RT_OK) {
 *       fprintf(stderr, "rt: %s\n", err.message);
 *       return 2;
 *   }
 *
 * Warnings go through rt/base/log.h, allocation through rt/base/alloc.h.
 */
#ifndef RT_ERROR_H
#define RT_ERROR_H

#include <stddef.h>

typedef enum rt_result {
    RT_OK = 0,
    RT_ERR_IO,          /* a file could not be opened, read or written */
    RT_ERR_PARSE,       /* text or JSON that does not parse */
    RT_ERR_INVALID,     /* parses, but breaks the format's rules */
    RT_ERR_UNSUPPORTED, /* valid, but rt does not do it (a required extension) */
    RT_ERR_NOMEM,       /* an allocation failed */
    RT_ERR_LIMIT,       /* over a resource cap (image size, memory, counts) */
    RT_ERR_INTERRUPTED, /* stopped by a signal */
} rt_result;

typedef struct rt_error {
    rt_result code;
    char message[1024];
} rt_error;

#if defined(__GNUC__)
#define RT_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define RT_PRINTF(a, b)
#endif

/* Fills err (when not NULL) and returns code, so callers can write
 * `return rt_fail(err, RT_ERR_PARSE, "%s:%d:%d: expected a number", ...);` */
rt_result rt_fail(rt_error *err, rt_result code, const char *fmt, ...) RT_PRINTF(3, 4);

/* Short name of a result ("parse error", "out of memory", ...). */
const char *rt_result_name(rt_result code);

/* Invariant checks on the renderer's own state (never on input). RT_DCHECK
 * costs nothing unless built with -DRT_DEBUG. */
void rt_check_failed(const char *file, int line, const char *expr);
#define RT_CHECK(x) ((x) ? (void)0 : rt_check_failed(__FILE__, __LINE__, #x))
#ifdef RT_DEBUG
#define RT_DCHECK(x) RT_CHECK(x)
#else
#define RT_DCHECK(x) ((void)0)
#endif

#endif
