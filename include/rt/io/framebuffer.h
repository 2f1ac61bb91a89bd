/* rt/io/framebuffer.h - the framebuffer and writing it out: PNG (8-bit sRGB), PFM
 * (linear float) and Radiance HDR, chosen by the file extension.
 *
 * Writes are atomic: the image goes to a temporary file in the same
 * directory, which is renamed over the target only once complete, so a
 * failed or killed render never leaves a truncated file or clobbers an
 * earlier image.
 *
 *   rt_framebuffer fb;
 *   rt_framebuffer_init(&fb, 640, 480, &err);
 *   ... fill fb.rgb (linear RGB floats, row 0 at the top) ...
 *   rt_output_check("out.png", &err);                // before rendering
 *   rt_framebuffer_write(&fb, "out.png", 1.0f, &err);
 */
#ifndef RT_FRAMEBUFFER_H
#define RT_FRAMEBUFFER_H

#include <signal.h>

#include "rt/base/error.h"

typedef struct rt_framebuffer {
    int width, height;
    float *rgb; /* 3 floats a pixel, row-major, row 0 at the top */
} rt_framebuffer;

typedef enum rt_image_format { RT_FORMAT_PNG = 0, RT_FORMAT_PFM, RT_FORMAT_HDR } rt_image_format;

rt_result rt_framebuffer_init(rt_framebuffer *fb, int width, int height, rt_error *err);
void rt_framebuffer_free(rt_framebuffer *fb);

/* The format for a path's extension (.png, .pfm, .hdr; case-insensitive). */
rt_result rt_output_format(const char *path, rt_image_format *format, rt_error *err);
/* Checks before a render that the format is known and the directory is
 * writable (by creating and removing a temporary file there). */
rt_result rt_output_check(const char *path, rt_error *err);
/* Checks that the format can hold a width x height image (PNG output is
 * capped at 1 GiB of pixel data; RT_ERR_LIMIT beyond). */
rt_result rt_output_check_size(const char *path, int width, int height, rt_error *err);
/* Writes atomically. exposure scales the values for PNG only. */
rt_result rt_framebuffer_write(const rt_framebuffer *fb, const char *path, float exposure, rt_error *err);

/* A write's temporary file, for a signal handler that ends the process:
 * while `active` is non-zero, `path` may name the temporary file of a
 * write under way, and the handler may unlink(path) (async-signal-safe;
 * a name not yet or no longer there is harmless). */
typedef struct rt_write_temp {
    char path[4200];
    volatile sig_atomic_t active;
} rt_write_temp;
/* rt_framebuffer_write that keeps *temp up to date (temp may be NULL). */
rt_result rt_framebuffer_write_tracked(const rt_framebuffer *fb, const char *path, float exposure, rt_write_temp *temp,
                                       rt_error *err);

/* Reads a PFM (for tests and comparisons against references). */
rt_result rt_pfm_read(const char *path, rt_framebuffer *fb, rt_error *err);

#endif
