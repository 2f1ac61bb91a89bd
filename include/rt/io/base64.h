/* rt/base64.h - strict base64 decoding (RFC 4648 section 4, standard
 * alphabet, '=' padding required to a multiple of 4 characters).
 *
 *   size_t cap = rt_base64_max_decoded(len), n, bad;
 *   if (rt_base64_decode(text, len, buf, &n, &bad) != RT_OK)
 *       ... character `bad` is not base64 ...
 */
#ifndef RT_BASE64_H
#define RT_BASE64_H

#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"

/* Bytes needed to decode len characters (an upper bound). */
static inline size_t rt_base64_max_decoded(size_t len) { return len / 4 * 3 + 3; }

/* Decodes src[0, len) into dst (room for rt_base64_max_decoded(len)).
 * Returns RT_OK and the decoded size, or RT_ERR_PARSE with *bad set to the
 * offset of the first offending character (len when the length is wrong). */
rt_result rt_base64_decode(const char *src, size_t len, uint8_t *dst, size_t *out_len, size_t *bad);

#endif
