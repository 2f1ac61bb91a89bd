/* webp.c - WebP images (rt/io/webp.h) through libwebp's simple decoding API
 * (WebPGetInfo, WebPDecodeRGBAInto; Google's "WebP API Documentation").
 * The container is RIFF: "RIFF", a little-endian size, "WEBP". */
#include "rt/io/webp.h"

#include <stdlib.h>
#include <string.h>

#include <webp/decode.h>

bool rt_webp_is(const void *data, size_t size)
{
    const uint8_t *p = data;
    return size >= 12 && memcmp(p, "RIFF", 4) == 0 && memcmp(p + 8, "WEBP", 4) == 0;
}

rt_result rt_webp_decode(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                         uint8_t **rgba, int *width, int *height, rt_error *err)
{
    int w = 0, h = 0;
    *rgba = NULL;
    if (!WebPGetInfo(data, size, &w, &h))
        return rt_fail(err, RT_ERR_INVALID, "%s: not a readable WebP image", name);
    if (w <= 0 || h <= 0 || w > max_dim || h > max_dim || (uint64_t)w * (uint64_t)h > max_pixels)
        return rt_fail(err, RT_ERR_LIMIT, "%s: image is %dx%d, over the limit of %dx%d and %llu pixels", name, w, h,
                       max_dim, max_dim, (unsigned long long)max_pixels);
    size_t bytes = (size_t)w * (size_t)h * 4;
    uint8_t *px = malloc(bytes);
    if (!px)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for a %dx%d image", name, w, h);
    if (!WebPDecodeRGBAInto(data, size, px, bytes, w * 4)) {
        free(px);
        return rt_fail(err, RT_ERR_INVALID, "%s: cannot decode the WebP image", name);
    }
    *rgba = px;
    *width = w;
    *height = h;
    return RT_OK;
}
