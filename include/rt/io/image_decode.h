/* rt/io/image_decode.h - an image file's bytes into pixels, whatever the
 * format, found by content: OpenEXR (rt/io/exr.h) and Radiance HDR as
 * linear float RGBA; WebP (rt/io/webp.h), PNG, JPEG and the rest of what
 * stb_image reads as 8-bit RGBA, as stored (sRGB for colour). Behind rt's
 * own checks: a header declaring more than the limits allow is refused
 * before any pixel memory is allocated, and a PNG whose compressed stream
 * could not hold (or inflates past) its declared pixels is refused before
 * stb_image sees it.
 *
 *   rt_image_limits lim = {.max_side = 32768, .max_pixels = 1u << 28, .max_float_pixels = 1u << 26};
 *   rt_image img;
 *   if (rt_image_decode(bytes, size, "wood.png", &lim, &img, &err) != RT_OK) ... err names it ...
 *   ... img.rgba8 (or img.rgbaf), img.width, img.height; img.name is left empty ...
 *   free(img.rgba8); free(img.rgbaf);
 *
 * Textures go through rt_image_load_file / rt_image_load_memory
 * (rt/io/image_load.h: decoded once, cached by name); `rt compare` and
 * `rt convert` through rt_image_read (rt/io/image_read.h).
 */
#ifndef RT_IMAGE_DECODE_H
#define RT_IMAGE_DECODE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

typedef struct rt_image_limits {
    int max_side;              /* pixels a side */
    uint64_t max_pixels;       /* 8-bit images: 4 bytes a pixel */
    uint64_t max_float_pixels; /* EXR and HDR: 16 bytes a pixel */
} rt_image_limits;

/* True when the bytes start like an image rt_image_decode reads (EXR,
 * WebP, or a header stb_image understands); it may still fail to decode. */
bool rt_image_is_readable(const void *data, size_t size);

/* Decodes into *img (zeroed first). RT_ERR_LIMIT over the limits,
 * RT_ERR_NOMEM when the decoder runs out of memory, RT_ERR_INVALID for
 * anything that is not a readable image; the message starts "name: ". */
rt_result rt_image_decode(const void *data, size_t size, const char *name, const rt_image_limits *lim, rt_image *img,
                          rt_error *err);

#endif
