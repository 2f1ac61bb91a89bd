/* framebuffer.c - the in-memory float image every stage hands on
 * (rt/image/framebuffer.h): linear RGB, 3 floats a pixel, row 0 at the top,
 * taken in one checked allocation. */
#include "rt/image/framebuffer.h"

#include <stdlib.h>

#include "rt/base/alloc.h"

rt_result rt_framebuffer_init(rt_framebuffer *fb, int width, int height, rt_error *err)
{
    fb->width = fb->height = 0;
    fb->rgb = NULL;
    if (width <= 0 || height <= 0 || width > 65536 || height > 65536)
        return rt_fail(err, RT_ERR_LIMIT, "image size %dx%d is out of range (1..65536 a side)", width, height);
    fb->rgb = rt_alloc((size_t)width * (size_t)height, 3 * sizeof(float));
    if (!fb->rgb)
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for a %dx%d image", width, height);
    fb->width = width;
    fb->height = height;
    return RT_OK;
}

void rt_framebuffer_free(rt_framebuffer *fb)
{
    free(fb->rgb);
    fb->rgb = NULL;
    fb->width = fb->height = 0;
}
