/* rt/io/exr.h - OpenEXR images in and out, through the OpenEXR Core C API
 * (Debian libopenexr-dev, linked with -lOpenEXRCore).
 *
 * Writing: one scanline part, ZIP compression (16 lines a chunk), 32-bit
 * float or, with half = true, 16-bit half channels. The beauty image is the
 * channels R, G, B; each extra layer NAME adds NAME.R, NAME.G, NAME.B (three
 * components) or NAME.Y (one), the multi-layer naming every EXR viewer reads.
 * The bytes go to an open FILE (image_write.c hands it the temporary file
 * that is renamed into place once complete).
 *
 *   rt_exr_layer layers[2] = {{NULL, 3, fb.rgb}, {"albedo", 3, albedo}};
 *   rt_exr_write(f, "out.exr", w, h, layers, 2, false, &err);
 *
 * Reading: single-part scanline or tiled files (level 0 of tiled ones), any
 * compression the library knows, channel types half, float or uint. R, G, B
 * (and A) are taken; a file with Y alone is grey; other channels are skipped.
 * Sizes are checked against the caller's limits before any pixel memory is
 * allocated, so a hostile header cannot ask for gigabytes.
 *
 *   float *rgba; int w, h;
 *   if (rt_exr_decode(bytes, size, "sky.exr", 32768, 1u << 26, &rgba, &w, &h, &err) != RT_OK) ...
 *   ... rgba: w * h * 4 floats, row 0 at the top, alpha 1 where the file has none ...
 *   free(rgba);
 *
 * Named channels (all required), for files with layers of their own:
 *
 *   const char *names[4] = {"R", "G", "B", "count.Y"};
 *   rt_exr_decode_channels(bytes, size, "part.exr", 32768, 1u << 28, names, 4, &px, &w, &h, &err);
 */
#ifndef RT_EXR_H
#define RT_EXR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "rt/base/error.h"

/* One layer of an EXR file to write. */
typedef struct rt_exr_layer {
    const char *name;  /* NULL: the beauty image (R, G, B); else NAME.R/G/B or NAME.Y */
    int channels;      /* 1 or 3 */
    const float *data; /* width * height * channels floats, interleaved, row 0 at the top */
} rt_exr_layer;

/* True when the bytes start with the OpenEXR magic number. */
bool rt_exr_is(const void *data, size_t size);

/* Writes the layers as one EXR image to f (at its current position 0).
 * `path` names the file in messages. */
rt_result rt_exr_write(FILE *f, const char *path, int width, int height, const rt_exr_layer *layers, int layer_count,
                       bool half, rt_error *err);

/* Decodes an EXR held in memory into RGBA floats (malloc'ed; the caller frees).
 * Refuses images over max_dim a side or max_pixels in all (RT_ERR_LIMIT). */
rt_result rt_exr_decode(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                        float **rgba, int *width, int *height, rt_error *err);

/* Decodes the named channels (all of them must be there, float or half) of
 * an EXR held in memory: count floats a pixel, channels[k] at component k
 * (malloc'ed; the caller frees). For files rt wrote itself with extra
 * layers (a part's "count.Y", docs/farm.md). */
rt_result rt_exr_decode_channels(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                                 const char *const *channels, int count, float **pixels, int *width, int *height,
                                 rt_error *err);
/* The same, for a file whose size is known beforehand (a part's region,
 * from its sidecar): a data window other than width x height is refused,
 * naming both sizes, before any pixel memory is allocated. */
rt_result rt_exr_decode_channels_sized(const void *data, size_t size, const char *name, int width, int height,
                                       const char *const *channels, int count, float **pixels, rt_error *err);

#endif
