/* rt/io/meshopt.h - EXT_meshopt_compression's buffer views, decoded with
 * Debian's libmeshoptimizer (its C API, meshoptimizer.h).
 *
 * A compressed view names a range of a source buffer, the element count
 * and size, a mode and a filter; decoding fills count * stride bytes. The
 * input is untrusted: rt_meshopt_check says whether the declared shape is
 * one the extension allows before anything is allocated, and decoding
 * reports a malformed stream instead of reading past it.
 *
 *   const char *why = rt_meshopt_check(mode, filter, count, stride);
 *   if (!why) why = rt_meshopt_decode(dst, count, stride, src, src_size, mode, filter);
 *   if (why) ... error naming the view: why ...
 */
#ifndef RT_MESHOPT_H
#define RT_MESHOPT_H

#include <stddef.h>
#include <stdint.h>

typedef enum rt_meshopt_mode { RT_MESHOPT_ATTRIBUTES, RT_MESHOPT_TRIANGLES, RT_MESHOPT_INDICES } rt_meshopt_mode;
typedef enum rt_meshopt_filter {
    RT_MESHOPT_FILTER_NONE,
    RT_MESHOPT_FILTER_OCTAHEDRAL,
    RT_MESHOPT_FILTER_QUATERNION,
    RT_MESHOPT_FILTER_EXPONENTIAL
} rt_meshopt_filter;

/* The spelling of the extension's "mode" / "filter" strings; -1 if unknown. */
int rt_meshopt_mode_from_name(const char *name);
int rt_meshopt_filter_from_name(const char *name);

/* NULL if the extension allows this shape, else why not (a static string). */
const char *rt_meshopt_check(rt_meshopt_mode mode, rt_meshopt_filter filter, size_t count, size_t stride);

/* Decodes src into dst (count * stride bytes). NULL on success, else why. */
const char *rt_meshopt_decode(void *dst, size_t count, size_t stride, const uint8_t *src, size_t src_size,
                              rt_meshopt_mode mode, rt_meshopt_filter filter);

#endif
