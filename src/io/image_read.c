/* image_read.c - one reader for every image format rt writes (and 8-bit
 * ones): the first bytes decide. PFM by "PF" or "Pf" (rt_pfm_read, pfm.c; Paul Debevec's
 * format note); everything else through rt_image_decode (image_decode.c:
 * OpenEXR, Radiance HDR, WebP, PNG, JPEG, ... behind its size checks),
 * 8-bit values decoded with the sRGB transfer function (IEC 61966-2-1) so
 * that every framebuffer holds linear RGB. */
#include "rt/io/image_read.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/file.h"
#include "rt/image/srgb.h"
#include "rt/io/image_decode.h"

#define READ_MAX_DIM 65536
#define READ_MAX_PIXELS ((uint64_t)1 << 28)

rt_result rt_image_read(const char *path, rt_framebuffer *fb, rt_error *err)
{
    fb->width = fb->height = 0;
    fb->rgb = NULL;
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(path, (size_t)INT32_MAX, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    if (size >= 2 && bytes[0] == 'P' && (bytes[1] == 'F' || bytes[1] == 'f')) { /* colour or grey PFM */
        free(bytes);
        return rt_pfm_read(path, fb, err);
    }
    static const rt_image_limits lim = {READ_MAX_DIM, READ_MAX_PIXELS, READ_MAX_PIXELS};
    rt_image img;
    if (!rt_image_is_readable(bytes, size))
        r = rt_fail(err, RT_ERR_INVALID, "%s: not an image rt reads (EXR, PFM, HDR, PNG, JPEG, WebP)", path);
    else
        r = rt_image_decode(bytes, size, path, &lim, &img, err);
    free(bytes);
    if (r != RT_OK)
        return r;
    r = rt_framebuffer_init(fb, img.width, img.height, err);
    const size_t n = (size_t)img.width * (size_t)img.height;
    for (size_t i = 0; r == RT_OK && i < n; i++)
        for (int c = 0; c < 3; c++)
            fb->rgb[3 * i + (size_t)c] = img.rgbaf ? img.rgbaf[4 * i + (size_t)c]
                                                   : rt_srgb_to_linear((float)img.rgba8[4 * i + (size_t)c] / 255.0f);
    free(img.rgba8);
    free(img.rgbaf);
    return r;
}
