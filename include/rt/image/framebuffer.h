/* rt/image/framebuffer.h - the float image a render fills and every later
 * step reads: linear RGB, 3 floats a pixel, row-major, row 0 at the top.
 * Writing it to a file is rt/io/image_write.h's; reading one,
 * rt/io/image_read.h's.
 *
 *   rt_framebuffer fb;
 *   if (rt_framebuffer_init(&fb, 640, 480, &err) != RT_OK) ... RT_ERR_LIMIT or RT_ERR_NOMEM ...
 *   fb.rgb[3 * ((size_t)y * fb.width + x) + c] = value;
 *   rt_framebuffer_free(&fb);
 */
#ifndef RT_FRAMEBUFFER_H
#define RT_FRAMEBUFFER_H

#include "rt/base/error.h"

typedef struct rt_framebuffer {
    int width, height;
    float *rgb; /* 3 floats a pixel, row-major, row 0 at the top */
} rt_framebuffer;

/* Zeroed pixels; 1..65536 a side (RT_ERR_LIMIT beyond). */
rt_result rt_framebuffer_init(rt_framebuffer *fb, int width, int height, rt_error *err);
/* Frees the pixels and zeroes *fb (a second call is harmless). */
void rt_framebuffer_free(rt_framebuffer *fb);

#endif
