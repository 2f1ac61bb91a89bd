/* rt/io/image_write.h - writing a framebuffer (rt/image/framebuffer.h) to
 * a file: PNG (8-bit sRGB), PFM (linear float), Radiance HDR and OpenEXR
 * (float or half, with extra layers such as AOVs), chosen by the file
 * extension. The float formats (PFM, HDR,
 * EXR) always hold linear radiance as rendered: exposure and the tone curve
 * apply to PNG alone.
 *
 * Writes are atomic: the image goes to a temporary file in the same
 * directory, which is renamed over the target only once complete, so a
 * failed or killed render never leaves a truncated file or clobbers an
 * earlier image. On Linux that file has no name until it is complete
 * (O_TMPFILE), so a process killed mid-write leaves no temporary file.
 *
 *   rt_framebuffer fb;
 *   rt_framebuffer_init(&fb, 640, 480, &err);
 *   ... fill fb.rgb (linear RGB floats, row 0 at the top) ...
 *   rt_output_check("out.png", &err);                // before rendering
 *   rt_framebuffer_write(&fb, "out.png", 1.0f, &err);
 *
 *   rt_image_options opt = {.exposure = 2.0f, .tonemap = RT_TONEMAP_AGX};
 *   rt_framebuffer_write_with(&fb, "out.png", &opt, &err);   // or .half, .layers for EXR
 */
#ifndef RT_IMAGE_WRITE_H
#define RT_IMAGE_WRITE_H

#include <signal.h>
#include <stdbool.h>

#include "rt/base/error.h"
#include "rt/image/framebuffer.h"
#include "rt/image/tonemap.h"

typedef enum rt_image_format { RT_FORMAT_PNG = 0, RT_FORMAT_PFM, RT_FORMAT_HDR, RT_FORMAT_EXR } rt_image_format;

#define RT_MAX_IMAGE_LAYERS 72 /* a part: its counts, up to 64 sample blocks, its AOVs (rt/job/part.h) */

/* An extra image beside the beauty one (an AOV): EXR writes it as a layer. */
typedef struct rt_image_layer {
    const char *name;  /* "albedo": channels albedo.R, .G, .B (or albedo.Y for one channel) */
    int channels;      /* 1 or 3 */
    const float *data; /* width * height * channels floats, row 0 at the top */
} rt_image_layer;

/* How to write; the zero value is rt_framebuffer_write's defaults with exposure 1. */
typedef struct rt_image_options {
    float exposure;       /* linear scale before the tone curve, PNG only (<= 0: 1) */
    rt_tonemap tonemap;   /* PNG only; RT_TONEMAP_CLAMP (0) clamps to [0, 1] */
    bool half;            /* EXR: 16-bit half channels instead of 32-bit float */
    const rt_image_layer *layers; /* EXR: extra layers (at most RT_MAX_IMAGE_LAYERS) */
    int layer_count;
} rt_image_options;

/* The format for a path's extension (.png, .pfm, .hdr, .exr; case-insensitive). */
rt_result rt_output_format(const char *path, rt_image_format *format, rt_error *err);
/* Checks before a render that the format is known, that the path is not a
 * directory or anything else but a regular file, and that its directory is
 * writable (by creating and removing the temporary file the write would
 * use). Cheap: the driver calls it before loading the scene. */
rt_result rt_output_check(const char *path, rt_error *err);
/* Checks that the format can hold a width x height image (PNG output is
 * capped at 1 GiB of pixel data; RT_ERR_LIMIT beyond). */
rt_result rt_output_check_size(const char *path, int width, int height, rt_error *err);
/* Writes atomically. exposure scales the values for PNG only. */
rt_result rt_framebuffer_write(const rt_framebuffer *fb, const char *path, float exposure, rt_error *err);
/* Writes atomically with the options (tone curve, half floats, EXR layers). */
rt_result rt_framebuffer_write_with(const rt_framebuffer *fb, const char *path, const rt_image_options *opt,
                                    rt_error *err);

/* A write's temporary file, for a signal handler that ends the process:
 * while `active` is non-zero, `path` may name the temporary file of a
 * write under way, and the handler may unlink(path) (async-signal-safe;
 * a name not yet or no longer there is harmless). */
typedef struct rt_write_temp {
    char path[4300]; /* as long as any temporary name image_write.c makes */
    volatile sig_atomic_t active;
} rt_write_temp;
/* rt_framebuffer_write_with that keeps *temp up to date (temp may be NULL). */
rt_result rt_framebuffer_write_tracked(const rt_framebuffer *fb, const char *path, const rt_image_options *opt,
                                       rt_write_temp *temp, rt_error *err);

/* Writes bytes to path the same atomic way (a part's sidecar, docs/farm.md). */
rt_result rt_file_write_atomic(const char *path, const void *bytes, size_t size, rt_write_temp *temp, rt_error *err);

/* Checks before a render that path (any file: a sidecar, an AOV image) can
 * be written as the image is: not a directory or other non-file, in a
 * directory where a temporary file can be made. rt_output_check is the
 * format check and this. */
rt_result rt_output_check_file(const char *path, rt_error *err);

/* Several files written together (an image, its AOV files, a part's
 * sidecar): each goes to its own temporary file, and none replaces
 * anything until rt_write_batch_commit, which first checks every target
 * again and then renames them in the order written; a failure anywhere
 * before that leaves every earlier file as it was, and the temporary
 * files are removed (unnamed on Linux while pending, so a killed process
 * leaves none).
 *
 *   rt_write_batch b;
 *   rt_write_batch_init(&b, temp);                       // temp: as for rt_framebuffer_write_tracked, or NULL
 *   r = rt_framebuffer_write_batched(&fb, "out.png", &opt, &b, &err);
 *   if (r == RT_OK) r = rt_file_write_batched("out.png.json", text, len, &b, &err);
 *   r = r == RT_OK ? rt_write_batch_commit(&b, &err) : (rt_write_batch_discard(&b), r);
 */
struct rt_write_pending;
typedef struct rt_write_batch {
    struct rt_write_pending *items;
    size_t count, cap;
    rt_write_temp *track;
} rt_write_batch;
void rt_write_batch_init(rt_write_batch *b, rt_write_temp *track);
rt_result rt_framebuffer_write_batched(const rt_framebuffer *fb, const char *path, const rt_image_options *opt,
                                       rt_write_batch *batch, rt_error *err);
rt_result rt_file_write_batched(const char *path, const void *bytes, size_t size, rt_write_batch *batch,
                                rt_error *err);
/* The bytes written for path in this batch, not yet committed (malloc'ed,
 * NUL after the last; the caller frees): a part hashes its images so. */
rt_result rt_write_batch_read(const rt_write_batch *b, const char *path, char **bytes, size_t *size, rt_error *err);
/* Renames every file of the batch into place (after checking every target);
 * on failure removes those not yet placed. The batch is empty afterwards. */
rt_result rt_write_batch_commit(rt_write_batch *b, rt_error *err);
/* Removes every pending file; nothing is replaced. */
void rt_write_batch_discard(rt_write_batch *b);

#endif
