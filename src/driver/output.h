/* output.h - what rt does with a finished render (driver-private): the
 * denoiser (--denoise), exposure and tone curve for 8-bit output, half EXR,
 * then the atomic write (rt/io/framebuffer.h).
 *
 *   if (output_check(&a, &err) != RT_OK) ...     // before rendering: --denoise has its library
 *   ... render into fb ...
 *   output_write(&a, &scene.settings, &fb, "out.exr", &err);
 */
#ifndef RT_DRIVER_OUTPUT_H
#define RT_DRIVER_OUTPUT_H

#include "args.h"
#include "rt/io/framebuffer.h"

/* Checks what the output options need before any rendering: with --denoise,
 * that Intel Open Image Denoise loads (one line saying how to install it
 * when not). */
rt_result output_check(const args *a, rt_error *err);

/* Denoises fb in place when asked, then writes it to path. */
rt_result output_write(const args *a, const rt_settings *set, rt_framebuffer *fb, const char *path, rt_error *err);

#endif
