/* output.c - a finished render to its files (rt/job/output.h): AOV images as EXR
 * layers or NAME.aov.pfm files, --denoise through rt/image/denoise.h (Intel
 * Open Image Denoise's RT filter, with the albedo and normal AOVs), then the
 * exposure (the scene's linear `exposure` times 2^--exposure) and tone curve
 * for 8-bit output and --half for EXR, written by rt_framebuffer_write_with. */
#include "rt/job/output.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/base/alloc.h"
#include "rt/base/clock.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/image/denoise.h"
#include "rt/image/tonemap.h"

rt_result rt_job_output_check(const rt_job_options *a, rt_error *err)
{
    if (!a->denoise)
        return RT_OK;
    char where[4096];
    rt_result r = rt_denoise_find(where, sizeof where, err);
    if (r == RT_OK)
        rt_info("denoiser: %s", where);
    return r;
}

static float **slot(rt_aov_buffers *b, int k)
{
    switch (k) {
    case RT_AOV_ALBEDO: return &b->albedo;
    case RT_AOV_NORMAL: return &b->normal;
    case RT_AOV_DEPTH: return &b->depth;
    case RT_AOV_POSITION: return &b->position;
    case RT_AOV_VARIANCE: return &b->variance;
    case RT_AOV_SPP:
    default: return &b->spp;
    }
}

static int channels_of(int k) { return k == RT_AOV_ALBEDO || k == RT_AOV_NORMAL || k == RT_AOV_POSITION ? 3 : 1; }

rt_result rt_job_aovs_init(rt_job_aovs *o, const rt_job_options *a, int width, int height, rt_error *err)
{
    memset(o, 0, sizeof *o);
    o->wanted = a->aovs;
    unsigned need = a->aovs | (a->denoise ? (1u << RT_AOV_ALBEDO) | (1u << RT_AOV_NORMAL) : 0u);
    for (int k = 0; k < RT_AOV_COUNT; k++) {
        if (!(need & (1u << k)))
            continue;
        float *p = rt_alloc((size_t)width * (size_t)height, (size_t)channels_of(k) * sizeof(float));
        if (!p) {
            rt_job_aovs_free(o);
            return rt_fail(err, RT_ERR_NOMEM, "out of memory for the %s AOV (%dx%d)", rt_aov_names[k], width, height);
        }
        *slot(&o->buf, k) = p;
    }
    return RT_OK;
}

void rt_job_aovs_free(rt_job_aovs *o)
{
    for (int k = 0; k < RT_AOV_COUNT; k++) {
        free(*slot(&o->buf, k));
        *slot(&o->buf, k) = NULL;
    }
}

rt_aov_buffers *rt_job_aovs_for_render(rt_job_aovs *o)
{
    for (int k = 0; k < RT_AOV_COUNT; k++)
        if (*slot(&o->buf, k))
            return &o->buf;
    return NULL;
}

int rt_job_aovs_layers(const rt_job_aovs *o, rt_image_layer *layers, int max)
{
    int n = 0;
    for (int k = 0; k < RT_AOV_COUNT && n < max; k++)
        if (o->wanted & (1u << k))
            layers[n++] = (rt_image_layer){rt_aov_names[k], channels_of(k), *slot((rt_aov_buffers *)&o->buf, k)};
    return n;
}

/* One image file of an AOV (1 channel: grey), into the batch. */
static rt_result write_aov_file(const float *data, int channels, int w, int h, const char *path,
                                rt_write_batch *batch, rt_error *err)
{
    rt_framebuffer fb;
    rt_result r = rt_framebuffer_init(&fb, w, h, err);
    if (r != RT_OK)
        return r;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        for (int c = 0; c < 3; c++)
            fb.rgb[3 * i + (size_t)c] = data[(size_t)channels * i + (size_t)(channels == 3 ? c : 0)];
    rt_image_options opt = {.exposure = 1.0f};
    r = rt_framebuffer_write_batched(&fb, path, &opt, batch, err);
    rt_framebuffer_free(&fb);
    return r;
}

/* Where the image `name` (an AOV, or "noisy") beside the output at path
 * goes when the output is not an EXR: NAME.albedo.pfm beside NAME.png
 * (8-bit would lose the values), else the output's own format. */
static void side_file(const char *path, rt_image_format fmt, const char *name, bool aov, char *out, size_t size)
{
    rt_path_tagged(path, name, aov && fmt == RT_FORMAT_PNG ? ".pfm" : NULL, out, size);
}

void rt_job_output_extras(const rt_job_options *a, const rt_job_aovs *aov, const char *path, char *out, size_t size)
{
    rt_image_format fmt = RT_FORMAT_PNG;
    rt_output_format(path, &fmt, NULL);
    bool noisy = a->denoise && aov->wanted;
    size_t used = 0;
    out[0] = 0;
    for (int k = -1; k < RT_AOV_COUNT; k++) {
        if (k < 0 ? !noisy : !(aov->wanted & (1u << k)))
            continue;
        const char *name = k < 0 ? "noisy" : rt_aov_names[k];
        char file[4200];
        if (fmt == RT_FORMAT_EXR)
            snprintf(file, sizeof file, "%s", name);
        else
            side_file(path, fmt, name, k >= 0, file, sizeof file);
        const char *lead = used ? ", " : fmt == RT_FORMAT_EXR ? " (layers " : " and ";
        int n = snprintf(out + used, size - used, "%s%s", lead, file);
        if (n < 0 || (size_t)n >= size - used)
            break;
        used += (size_t)n;
    }
    if (used && fmt == RT_FORMAT_EXR && used + 1 < size)
        out[used++] = ')', out[used] = 0;
}

/* The files beside an image at path that are not its layers: each AOV
 * asked for (NAME.albedo.EXT; .pfm beside a .png), and the noisy image
 * when denoising with AOVs; none beside an .exr. Returns how many. */
static int side_files(const rt_job_options *a, const char *path, char (*out)[4200], int max)
{
    rt_image_format fmt = RT_FORMAT_PNG;
    int n = 0;
    if (rt_output_format(path, &fmt, NULL) != RT_OK || fmt == RT_FORMAT_EXR)
        return 0;
    for (int k = 0; k < RT_AOV_COUNT && n < max; k++)
        if (a->aovs & (1u << k))
            side_file(path, fmt, rt_aov_names[k], true, out[n++], sizeof out[0]);
    if (a->denoise && a->aovs && n < max)
        side_file(path, fmt, "noisy", false, out[n++], sizeof out[0]);
    return n;
}

rt_result rt_job_output_check_paths(const rt_job_options *a, const char *path, rt_error *err)
{
    char partial[4200], side[RT_AOV_COUNT + 1][4200];
    rt_result r = rt_output_check(path, err);
    if (r != RT_OK)
        return r;
    if (!rt_path_tagged(path, "partial", NULL, partial, sizeof partial))
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    const char *images[2] = {path, partial}; /* a stopped tiled render writes NAME.partial.EXT instead */
    for (int i = 0; i < 2 && r == RT_OK; i++) {
        if (i > 0)
            r = rt_output_check_file(partial, err);
        int n = side_files(a, images[i], side, RT_AOV_COUNT + 1);
        for (int k = 0; k < n && r == RT_OK; k++)
            r = rt_output_check_file(side[k], err);
    }
    return r;
}

rt_result rt_job_output_write(const rt_job_options *a, const rt_settings *set, rt_framebuffer *fb,
                              const rt_job_aovs *aov, const char *path, rt_write_batch *batch, rt_error *err)
{
    if (!batch) { /* the files of this output alone, placed together */
        rt_write_batch own;
        rt_write_batch_init(&own, NULL);
        rt_result r = rt_job_output_write(a, set, fb, aov, path, &own, err);
        if (r != RT_OK) {
            rt_write_batch_discard(&own);
            return r;
        }
        return rt_write_batch_commit(&own, err);
    }
    rt_image_options opt = {.exposure = set->exposure * rt_exposure_scale(a->exposure_ev), .tonemap = a->tonemap,
                            .half = a->half};
    rt_image_format fmt = RT_FORMAT_PNG;
    rt_output_format(path, &fmt, err);
    rt_image_layer layers[RT_AOV_COUNT + 1];
    int nl = 0;
    float *noisy = NULL;
    rt_result r = RT_OK;
    if (a->denoise) {
        if (aov->wanted) { /* the noisy image is kept beside the denoised one */
            size_t n = (size_t)fb->width * (size_t)fb->height * 3;
            noisy = rt_alloc(n, sizeof(float));
            if (!noisy)
                return rt_fail(err, RT_ERR_NOMEM, "out of memory for the noisy image");
            memcpy(noisy, fb->rgb, n * sizeof(float));
        }
        double t0 = rt_now_seconds();
        rt_denoise_input in = {.width = fb->width, .height = fb->height, .color = fb->rgb,
                               .albedo = aov->buf.albedo, .normal = aov->buf.normal,
                               .prefilter_aux = aov->noisy_aux, .quality = a->denoise_quality,
                               .threads = a->threads};
        r = rt_denoise_image(&in, err);
        if (r != RT_OK)
            goto done;
        rt_info("denoise: %.3f s (albedo and normal as clean auxiliary images)", rt_now_seconds() - t0);
    }
    if (fmt == RT_FORMAT_EXR) {
        if (noisy)
            layers[nl++] = (rt_image_layer){"noisy", 3, noisy};
        nl += rt_job_aovs_layers(aov, layers + nl, RT_AOV_COUNT);
        opt.layers = layers;
        opt.layer_count = nl;
    } else {
        char p[4200];
        for (int k = 0; k < RT_AOV_COUNT && r == RT_OK; k++)
            if (aov->wanted & (1u << k)) {
                side_file(path, fmt, rt_aov_names[k], true, p, sizeof p);
                r = write_aov_file(*slot((rt_aov_buffers *)&aov->buf, k), channels_of(k), fb->width, fb->height, p,
                                   batch, err);
            }
        if (r == RT_OK && noisy) {
            rt_framebuffer nf = {fb->width, fb->height, noisy};
            side_file(path, fmt, "noisy", false, p, sizeof p);
            r = rt_framebuffer_write_batched(&nf, p, &opt, batch, err);
        }
        if (r != RT_OK)
            goto done;
    }
    r = rt_framebuffer_write_batched(fb, path, &opt, batch, err);
done:
    free(noisy);
    return r;
}
