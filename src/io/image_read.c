/* image_read.c - one reader for every image format rt writes (and 8-bit
 * ones): the first bytes decide. OpenEXR by its magic number 76 2f 31 01
 * (exr.c), PFM by "PF" (rt_pfm_read; Paul Debevec's format note), Radiance
 * HDR and 8-bit images through stb_image behind the size checks of
 * stbi_info, 8-bit values decoded with the sRGB transfer function
 * (IEC 61966-2-1) so that every framebuffer holds linear RGB. */
#include "rt/io/image_read.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>

#include "rt/base/file.h"
#include "rt/io/exr.h"
#include "rt/scene/texture.h"

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
    if (size >= 2 && bytes[0] == 'P' && bytes[1] == 'F') {
        free(bytes);
        return rt_pfm_read(path, fb, err);
    }
    if (rt_exr_is(bytes, size)) {
        float *rgba;
        int w, h;
        r = rt_exr_decode(bytes, size, path, READ_MAX_DIM, READ_MAX_PIXELS, &rgba, &w, &h, err);
        free(bytes);
        if (r != RT_OK)
            return r;
        r = rt_framebuffer_init(fb, w, h, err);
        if (r == RT_OK)
            for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
                memcpy(fb->rgb + 3 * i, rgba + 4 * i, 3 * sizeof(float));
        free(rgba);
        return r;
    }
    int w = 0, h = 0, comp = 0;
    const stbi_uc *b = (const stbi_uc *)bytes;
    if (!stbi_info_from_memory(b, (int)size, &w, &h, &comp)) {
        free(bytes);
        return rt_fail(err, RT_ERR_INVALID, "%s: not an image rt reads (EXR, PFM, HDR, PNG, JPEG)", path);
    }
    if (w <= 0 || h <= 0 || w > READ_MAX_DIM || h > READ_MAX_DIM || (uint64_t)w * (uint64_t)h > READ_MAX_PIXELS) {
        free(bytes);
        return rt_fail(err, RT_ERR_LIMIT, "%s: image is %dx%d, over the limit of %d a side and %llu pixels", path, w,
                       h, READ_MAX_DIM, (unsigned long long)READ_MAX_PIXELS);
    }
    int lw = 0, lh = 0, lc = 0;
    if (stbi_is_hdr_from_memory(b, (int)size)) {
        float *px = stbi_loadf_from_memory(b, (int)size, &lw, &lh, &lc, 3);
        free(bytes);
        if (!px || lw != w || lh != h) {
            stbi_image_free(px);
            return rt_fail(err, RT_ERR_INVALID, "%s: cannot decode the HDR image (%s)", path, stbi_failure_reason());
        }
        r = rt_framebuffer_init(fb, w, h, err);
        if (r == RT_OK)
            memcpy(fb->rgb, px, (size_t)w * (size_t)h * 3 * sizeof(float));
        stbi_image_free(px);
        return r;
    }
    stbi_uc *px = stbi_load_from_memory(b, (int)size, &lw, &lh, &lc, 3);
    free(bytes);
    if (!px || lw != w || lh != h) {
        stbi_image_free(px);
        return rt_fail(err, RT_ERR_INVALID, "%s: cannot decode the image (%s)", path, stbi_failure_reason());
    }
    r = rt_framebuffer_init(fb, w, h, err);
    if (r == RT_OK)
        for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++)
            fb->rgb[i] = rt_srgb_to_linear((float)px[i] / 255.0f);
    stbi_image_free(px);
    return r;
}
