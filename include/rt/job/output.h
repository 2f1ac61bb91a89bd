/* rt/job/output.h - what a job does with a finished render: the AOV images
 * (options.aovs), the denoiser (options.denoise, fed the albedo and normal
 * AOVs), exposure and tone curve for 8-bit output, half EXR, then the
 * atomic write (rt/io/image_write.h).
 *
 *   rt_job_options o = {.aovs = 1u << RT_AOV_NORMAL};
 *   if (rt_job_output_check(&o, &err) != RT_OK) ...   // before rendering: the denoiser has its library
 *   if (rt_job_output_check_paths(&o, "out.png", &err) != RT_OK) ...   // and every file can be written
 *   rt_job_aovs aov;
 *   rt_job_aovs_init(&aov, &o, w, h, &err);           // render options .aov = rt_job_aovs_for_render(&aov)
 *   ... render into fb ...
 *   rt_job_output_write(&o, &settings, &fb, &aov, "out.exr", NULL, &err);   // or into a batch
 *   rt_job_aovs_free(&aov);
 */
#ifndef RT_JOB_OUTPUT_H
#define RT_JOB_OUTPUT_H

#include "rt/job/options.h"
#include "rt/io/image_write.h"
#include "rt/render/aov.h"
#include "rt/render/settings.h"

typedef struct rt_job_aovs {
    rt_aov_buffers buf; /* the images the render fills */
    unsigned wanted;    /* bit k: rt_aov_names[k] is written (options.aovs); denoising adds albedo and normal unwritten */
    bool noisy_aux;     /* set by the caller when the camera has an aperture or an open shutter: the
                           denoiser prefilters albedo and normal */
} rt_job_aovs;

/* Checks what the output options need before any rendering: with
 * options.denoise, that Intel Open Image Denoise loads (one line saying how
 * to install it when not). */
rt_result rt_job_output_check(const rt_job_options *a, rt_error *err);

/* Allocates the AOV images options.aovs and options.denoise need (zeroed). */
rt_result rt_job_aovs_init(rt_job_aovs *o, const rt_job_options *a, int width, int height, rt_error *err);
void rt_job_aovs_free(rt_job_aovs *o);
/* The AOVs asked for (options.aovs) as image layers (name, channels, data), at
 * most max; returns how many: what EXR output and the tev stream carry. */
int rt_job_aovs_layers(const rt_job_aovs *o, rt_image_layer *layers, int max);
/* The render's .aov: NULL when no AOV is needed. */
rt_aov_buffers *rt_job_aovs_for_render(rt_job_aovs *o);

/* Checks before rendering every file an output at path may write: the
 * image, its AOV and noisy files, and NAME.partial.EXT with its own (a
 * stopped tiled render's), each a file rt can replace (rt_output_check_file). */
rt_result rt_job_output_check_paths(const rt_job_options *a, const char *path, rt_error *err);

/* Denoises fb in place when asked (writing the noisy image beside it when
 * AOVs are asked for too), then writes it and the AOVs: layers of an .exr,
 * else files NAME.albedo.EXT beside it (NAME.EXT the output; PNG output
 * writes them as .pfm, which keeps their values). The files join batch,
 * placed by rt_write_batch_commit (rt/io/image_write.h) with the rest of
 * the render's; batch NULL places them at once, all or none. */
rt_result rt_job_output_write(const rt_job_options *a, const rt_settings *set, rt_framebuffer *fb,
                              const rt_job_aovs *aov, const char *path, rt_write_batch *batch, rt_error *err);

/* What rt_job_output_write writes besides the image at path, for the
 * "wrote" line: " and out.albedo.pfm, out.noisy.png", or for an .exr
 * " (layers noisy, albedo)"; "" when nothing (out: size bytes). */
void rt_job_output_extras(const rt_job_options *a, const rt_job_aovs *aov, const char *path, char *out, size_t size);

#endif
