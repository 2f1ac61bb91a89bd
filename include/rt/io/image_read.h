/* rt/io/image_read.h - reading a whole image file into a framebuffer of
 * linear RGB floats, whatever its format: PFM, and everything
 * rt_image_decode reads (image_decode.h: OpenEXR, Radiance HDR, and 8-bit
 * images, PNG, JPEG, WebP...: sRGB-decoded to linear). The format is found
 * from the file's first bytes, not its name. For `rt compare` and
 * `rt convert`; scene textures load through rt/io/image_load.h instead.
 *
 *   rt_framebuffer fb;
 *   if (rt_image_read("render.exr", &fb, &err) != RT_OK) ... err names the file ...
 *   ... fb.rgb ...
 *   rt_framebuffer_free(&fb);
 */
#ifndef RT_IMAGE_READ_H
#define RT_IMAGE_READ_H

#include "rt/base/error.h"
#include "rt/image/framebuffer.h"

/* Reads path into *fb (initialised here; free it with rt_framebuffer_free).
 * Images over 65536 a side or 2^28 pixels are refused (RT_ERR_LIMIT). */
rt_result rt_image_read(const char *path, rt_framebuffer *fb, rt_error *err);

/* Reads a PFM file (src/io/pfm.c): colour ("PF") or grey ("Pf", copied to
 * R, G and B), either byte order. The header is checked against the file's
 * size before any pixel memory is taken; every message names the file, and
 * the byte where it goes wrong. */
rt_result rt_pfm_read(const char *path, rt_framebuffer *fb, rt_error *err);

#endif
