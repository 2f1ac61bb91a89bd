/* output.c - a finished render to its file (output.h): --denoise through
 * rt/image/denoise.h (Intel Open Image Denoise's RT filter), then the
 * exposure (the scene's linear `exposure` times 2^--exposure) and tone curve
 * for 8-bit output and --half for EXR, written by rt_framebuffer_write_with. */
#include "output.h"

#include <time.h>

#include "rt/base/log.h"
#include "rt/image/denoise.h"
#include "rt/image/tonemap.h"

rt_result output_check(const args *a, rt_error *err)
{
    if (!a->denoise)
        return RT_OK;
    char where[4096];
    rt_result r = rt_denoise_find(where, sizeof where, err);
    if (r == RT_OK)
        rt_info("denoiser: %s", where);
    return r;
}

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

rt_result output_write(const args *a, const rt_settings *set, rt_framebuffer *fb, const char *path, rt_error *err)
{
    if (a->denoise) {
        double t0 = now_seconds();
        rt_denoise_input in = {.width = fb->width, .height = fb->height, .color = fb->rgb};
        rt_result r = rt_denoise_image(&in, err);
        if (r != RT_OK)
            return r;
        rt_info("denoise: %.3f s", now_seconds() - t0);
    }
    rt_image_options opt = {.exposure = set->exposure * rt_exposure_scale(a->exposure_ev), .tonemap = a->tonemap,
                            .half = a->half};
    return rt_framebuffer_write_with(fb, path, &opt, err);
}
