/* rt/io/webp.h - WebP images (EXT_texture_webp, or a .webp texture file),
 * decoded with Debian's libwebp.
 *
 * The size in the header is checked against the caller's limits before any
 * pixel memory is allocated.
 *
 *   if (rt_webp_is(bytes, size)) {
 *       uint8_t *rgba; int w, h;
 *       if (rt_webp_decode(bytes, size, "tex.webp", 32768, 1u << 28, &rgba, &w, &h, &err) != RT_OK) ...
 *       ... w * h * 4 bytes, row 0 at the top; free(rgba) ...
 *   }
 */
#ifndef RT_WEBP_H
#define RT_WEBP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"

/* True if the bytes start like a WebP file ("RIFF" size "WEBP"). */
bool rt_webp_is(const void *data, size_t size);

rt_result rt_webp_decode(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                         uint8_t **rgba, int *width, int *height, rt_error *err);

#endif
