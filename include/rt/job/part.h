/* rt/job/part.h - a part of a render spread over machines (docs/farm.md):
 * a float image of a region's per-pixel SUMS of good samples and their
 * COUNTS, and its JSON sidecar saying what it is a part of.
 *
 * A pixel's sum is a fold over blocks of RT_SAMPLE_BLOCK samples
 * (rt/render/sample_block.h); a part keeps it as the fold of its first blocks
 * (`sum`) and the sums of its last block or blocks kept apart (`blocks`,
 * rt_part_blocks_ok says which), so a merge can fold the parts' blocks in
 * sample order to the bits of a single render.
 *
 * The image is `path` (.exr: R, G, B = the fold, block.J.R/G/B = block J's
 * sums, count.Y = the counts, 32-bit float, which holds every count up to
 * 2^24 exactly; .pfm: the fold, the counts in path.count.pfm and block J in
 * path.block.J.pfm beside it). The sidecar is `path`.json: the
 * scene's hash, the settings that affect pixels, the image size, the region,
 * the sample range, the seed, rt's version, and the FNV-1a hashes of the
 * image files, so a part whose image was replaced, truncated or corrupted is
 * refused. Both are written atomically (rt/io/image_write.h), the image
 * first.
 *
 *   rt_part_info info = {...};                     // what the part is
 *   info.block_first = (info.s_end - 1) / RT_SAMPLE_BLOCK, info.block_count = 1;   // rt_part_blocks_ok
 *   rt_part_write("p.exr", &info, fold, blocks, good, NULL, NULL, &err);   // batch NULL: written and placed now   // layers: NULL when info.layer_count is 0
 *
 *   rt_part p;
 *   if (rt_part_read("p.exr", &p, &err) != RT_OK) ... err names the file and what is wrong ...
 *   ... p.info, p.sum (3 floats a pixel of the region), p.blocks, p.good ...
 *   rt_part_free(&p);
 */
#ifndef RT_PART_H
#define RT_PART_H

#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/io/image_write.h"
#include "rt/render/sample_block.h"

#define RT_PART_FORMAT 2            /* the sidecar's "rt_part" version (1: one plain sum, before sample blocks) */
#define RT_PART_SETTINGS_MAX 8192   /* bytes of the settings text */
#define RT_PART_MAX_LAYERS 4        /* extra sums a part may carry (AOVs) */
#define RT_PART_MAX_BLOCKS 64       /* block sums a part keeps apart at most (4096 samples) */

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
    int block_first, block_count; /* the blocks kept apart (rt_part_blocks_ok) */
    int layer_count;           /* extra per-pixel sums (EXR parts only): "albedo", "depth" ... */
    char layer_name[RT_PART_MAX_LAYERS][16];
    int layer_channels[RT_PART_MAX_LAYERS]; /* 1 or 3 */
} rt_part_info;

typedef struct rt_part {
    rt_part_info info;
    float *sum;                /* 3 floats a pixel of the region, row-major: the fold before the blocks */
    float *blocks;             /* info.block_count planes of 3 floats a pixel, block after block */
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

/* Whether a part of samples [s_begin, s_end) may keep blocks [first,
 * first + count) apart: the last is the block of sample s_end - 1, and
 * either it is the only one (the part's `sum` folds the blocks before it:
 * a part from sample 0, or one merged within the summation bound of
 * docs/farm.md) or they are all of its blocks from s_begin, a block edge,
 * on, at most RT_PART_MAX_BLOCKS (its `sum` is then 0, and a merge folds
 * each block in at its place). */
bool rt_part_blocks_ok(int s_begin, int s_end, int first, int count);

/* Writes the part's image(s), then its sidecar. sum (the fold), the
 * info->block_count planes of blocks, good and the
 * info->layer_count layers (EXR layers NAME.R/G/B or NAME.Y) are the
 * region's. batch NULL: the files replace earlier ones only once all are
 * written (a failure leaves every earlier file as it was); else they join
 * the batch, renamed into place by rt_write_batch_commit with the rest of
 * a render's files. */
rt_result rt_part_write(const char *path, const rt_part_info *info, const float *sum, const float *const *blocks,
                        const uint32_t *good, const float *const *layers, rt_write_batch *batch, rt_error *err);
/* Checks before a render every file a part at path writes that can be
 * known then: the image, the sidecar, a .pfm part's counts (block files
 * are checked when the batch is committed). */
rt_result rt_part_check_paths(const char *path, rt_error *err);

/* Reads a part: `path` is its image or its sidecar (NAME.json). Checks the
 * sidecar's fields and ranges, the image hashes, the image size against the
 * region, the blocks against the samples (rt_part_blocks_ok), and that every
 * sum is finite and non-negative and every count an integer no larger than
 * the sample range. A part of another format is refused, naming it. */
rt_result rt_part_read(const char *path, rt_part *part, rt_error *err);
void rt_part_free(rt_part *part);

/* NULL when a and b are parts of the same render; else what differs, in
 * words ("other settings: 'samples 64', not 'samples 16'"), in buf. */
const char *rt_part_mismatch(const rt_part_info *a, const rt_part_info *b, char *buf, size_t size);

/* A part's AOV layers (info->layer_name: albedo, normal, position, depth)
 * to and from the render's per-pixel AOV sums, n pixels. */
struct rt_aov_sample;
void rt_part_aov_to_layers(const rt_part_info *info, const struct rt_aov_sample *sums, float *const *layers, size_t n);
void rt_part_layers_to_aov(const rt_part_info *info, const float *const *layers, struct rt_aov_sample *sums, size_t n);

#endif
