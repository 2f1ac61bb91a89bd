/* output.h - what rt does with a finished render (driver-private): the AOV
 * images (--aov), the denoiser (--denoise, fed the albedo and normal AOVs),
 * exposure and tone curve for 8-bit output, half EXR, then the atomic write
 * (rt/io/image_write.h).
 *
 *   if (output_check(&a, &err) != RT_OK) ...     // before rendering: --denoise has its library
 *   output_aovs aov;
 *   output_aovs_init(&aov, &a, w, h, &err);      // render options .aov = aov.wanted ? &aov.buf : NULL
 *   ... render into fb ...
 *   output_write(&a, &scene.settings, &fb, &aov, "out.exr", &err);
 *   output_aovs_free(&aov);
 */
#ifndef RT_DRIVER_OUTPUT_H
#define RT_DRIVER_OUTPUT_H

#include "args.h"
#include "rt/io/image_write.h"
#include "rt/render/aov.h"

typedef struct output_aovs {
    rt_aov_buffers buf; /* the images the render fills */
    unsigned wanted;    /* bit k: aov_names[k] is written (--aov); --denoise adds albedo and normal unwritten */
    bool noisy_aux;     /* set by the caller when the camera has an aperture or an open shutter: --denoise prefilters albedo and normal */
} output_aovs;

/* Checks what the output options need before any rendering: with --denoise,
 * that Intel Open Image Denoise loads (one line saying how to install it
 * when not). */
rt_result output_check(const args *a, rt_error *err);

/* Allocates the AOV images --aov and --denoise need (zeroed). */
rt_result output_aovs_init(output_aovs *o, const args *a, int width, int height, rt_error *err);
void output_aovs_free(output_aovs *o);
/* The AOVs asked for (--aov) as image layers (name, channels, data), at
 * most max; returns how many: what EXR output and the tev stream carry. */
int output_aovs_layers(const output_aovs *o, rt_image_layer *layers, int max);
/* The render's .aov: NULL when no AOV is needed. */
rt_aov_buffers *output_aovs_for_render(output_aovs *o);

/* Denoises fb in place when asked (writing the noisy image beside it when
 * AOVs are asked for too), then writes it and the AOVs: layers of an .exr,
 * else files NAME.albedo.EXT beside it (NAME.EXT the output; PNG output
 * writes them as .pfm, which keeps their values). The image's own write
 * keeps *temp up to date for the signal handler (temp may be NULL). */
rt_result output_write(const args *a, const rt_settings *set, rt_framebuffer *fb, const output_aovs *aov,
                       const char *path, rt_write_temp *temp, rt_error *err);

#endif
