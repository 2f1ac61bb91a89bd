/* rt/io/part.h - a part of a render spread over machines (docs/farm.md):
 * a float image of a region's per-pixel SUMS of good samples and their
 * COUNTS, and its JSON sidecar saying what it is a part of.
 *
 * The image is `path` (.exr: R, G, B = the sums, count.Y = the counts, 32-bit
 * float, which holds every count up to 2^24 exactly; .pfm: the sums, and the
 * counts in path.count.pfm beside it). The sidecar is `path`.json: the
 * scene's hash, the settings that affect pixels, the image size, the region,
 * the sample range, the seed, rt's version, and the FNV-1a hashes of the
 * image files, so a part whose image was replaced, truncated or corrupted is
 * refused. Both are written atomically (rt/io/framebuffer.h), the image
 * first.
 *
 *   rt_part_info info = {...};                     // what the part is
 *   rt_part_write("p.exr", &info, sum, good, NULL, NULL, &err);   // layers: NULL when info.layer_count is 0
 *
 *   rt_part p;
 *   if (rt_part_read("p.exr", &p, &err) != RT_OK) ... err names the file and what is wrong ...
 *   ... p.info, p.sum (3 floats a pixel of the region), p.good ...
 *   rt_part_free(&p);
 */
#ifndef RT_PART_H
#define RT_PART_H

#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/io/framebuffer.h"

#define RT_PART_FORMAT 1            /* the sidecar's "rt_part" version */
#define RT_PART_SETTINGS_MAX 8192   /* bytes of the settings text */
#define RT_PART_MAX_LAYERS 4        /* extra sums a part may carry (AOVs) */

typedef struct rt_part_info {
    char version[32];          /* rt's version that rendered it */
    char scene[1024];          /* the input as named on the command line (messages only) */
    uint64_t scene_hash;       /* FNV-1a 64 of the input's bytes */
    char settings[RT_PART_SETTINGS_MAX]; /* what affects pixels: "key value" lines */
    int width, height;         /* the whole image */
    int x0, y0, x1, y1;        /* the region: [x0, x1) x [y0, y1) */
    int spp;                   /* the whole render's samples per pixel */
    int s_begin, s_end;        /* the samples summed: [s_begin, s_end) */
    uint32_t seed;
    float exposure;            /* the scene's exposure, for 8-bit output of a merge */
    int layer_count;           /* extra per-pixel sums (EXR parts only): "albedo", "depth" ... */
    char layer_name[RT_PART_MAX_LAYERS][16];
    int layer_channels[RT_PART_MAX_LAYERS]; /* 1 or 3 */
} rt_part_info;

typedef struct rt_part {
    rt_part_info info;
    float *sum;                /* 3 floats a pixel of the region, row-major */
    uint32_t *good;            /* 1 a pixel */
    float *layer[RT_PART_MAX_LAYERS]; /* info.layer_channels[k] floats a pixel */
    char path[4096];           /* the image's path (messages) */
} rt_part;

/* FNV-1a, 64 bits, continued from h (start from RT_FNV1A64_INIT). */
#define RT_FNV1A64_INIT 0xcbf29ce484222325ull
uint64_t rt_fnv1a64(const void *data, size_t size, uint64_t h);

/* True when path names a part's image format (.exr or .pfm). */
bool rt_part_path_ok(const char *path);
/* The sidecar's path for a part image: path + ".json". false when it does not fit. */
bool rt_part_sidecar_path(const char *path, char *out, size_t size);

/* Writes the part's image(s), then its sidecar. sum, good and the
 * info->layer_count layers (EXR layers NAME.R/G/B or NAME.Y) are the
 * region's. temp (may be NULL) tracks the temporary file for a signal
 * handler. */
rt_result rt_part_write(const char *path, const rt_part_info *info, const float *sum, const uint32_t *good,
                        const float *const *layers, rt_write_temp *temp, rt_error *err);

/* Reads a part: `path` is its image or its sidecar (NAME.json). Checks the
 * sidecar's fields and ranges, the image hashes, the image size against the
 * region, and that every sum is finite and non-negative and every count an
 * integer no larger than the sample range. */
rt_result rt_part_read(const char *path, rt_part *part, rt_error *err);
void rt_part_free(rt_part *part);

#endif
