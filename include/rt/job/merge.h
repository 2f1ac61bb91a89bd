/* rt/job/merge.h - the parts of one render (rt/job/part.h) into its image,
 * folded and resolved by the renderer's own steps (rt/render/sample_block.h),
 * so region parts give a single render's bytes (docs/farm.md).
 *
 *   rt_merge m;
 *   if (rt_merge_init(&m, nparts, &err) != RT_OK) ...
 *   for (each part) if (rt_merge_add(&m, path, &err) != RT_OK) ...    // read, same render as the first
 *   if (rt_merge_check_cover(&m, &err) != RT_OK) ...                    // before allocating the image
 *   rt_framebuffer_init(&fb, m.parts[0].info.width, m.parts[0].info.height, &err);
 *   if (rt_merge_image(&m, &fb, NULL, &err) != RT_OK) ...              // or the AOV images the parts carry
 *   rt_merge_free(&m);
 */
#ifndef RT_JOB_MERGE_H
#define RT_JOB_MERGE_H

#include "rt/base/error.h"
#include "rt/base/key_index.h"
#include "rt/image/framebuffer.h"
#include "rt/job/part.h"
#include "rt/render/aov.h"

typedef struct rt_merge {
    rt_part *parts; /* read so far, in the order given */
    int count, cap;
    int *group;     /* per part: its region's group (parts of one region are sample ranges of it) */
    int groups;
    uint64_t (*file_id)[2]; /* per part: its image's (device, inode), rt_file_id */
    rt_key_index files;     /* file id -> the first part read from that file */
    rt_key_index regions;   /* region's corners -> its group */
    uint64_t covered;       /* pixels of the distinct regions, summed */
} rt_merge;

/* Room for `capacity` parts. After a failure m is empty (rt_merge_free may still be called). */
rt_result rt_merge_init(rt_merge *m, int capacity, rt_error *err);
/* Reads the part at path (its image or sidecar) and adds it; refused, naming
 * both, when it is not a part of the same render as the first, or when it
 * is the file of a part added before (by any name: its device and inode).
 * Each add is O(1) expected: thousands of parts cost no pairwise step. */
rt_result rt_merge_add(rt_merge *m, const char *path, rt_error *err);
/* Refuses, before the caller allocates the image, parts whose regions
 * cannot tile it: fewer pixels in all than the image has and the image far
 * larger than the parts (a sidecar may claim 32768x32768 over one pixel of
 * data). Smaller gaps pass here; rt_merge_image then names the pixels. */
rt_result rt_merge_check_cover(const rt_merge *m, rt_error *err);
/* Checks that the regions tile the image once and each region's sample
 * ranges cover 0 .. spp once, folds every pixel's sums in sample order and
 * resolves them into fb (the parts' width x height) and, when aov is not
 * NULL, the AOV images its non-NULL planes ask for (the layers the parts
 * carry). The message names the part or the pixels at fault. */
rt_result rt_merge_image(const rt_merge *m, rt_framebuffer *fb, rt_aov_buffers *aov, rt_error *err);
void rt_merge_free(rt_merge *m);

#endif
