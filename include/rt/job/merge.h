/* rt/job/merge.h - the parts of one render (rt/job/part.h) into its image,
 * folded and resolved by the renderer's own steps (rt/render/sample_block.h),
 * so region parts give a single render's bytes (docs/farm.md).
 *
 *   rt_merge m;
 *   if (rt_merge_init(&m, nparts, &err) != RT_OK) ...
 *   for (each part) if (rt_merge_add(&m, path, &err) != RT_OK) ...    // read, same render as the first
 *   rt_framebuffer_init(&fb, m.parts[0].info.width, m.parts[0].info.height, &err);
 *   if (rt_merge_image(&m, &fb, NULL, &err) != RT_OK) ...              // or the AOV images the parts carry
 *   rt_merge_free(&m);
 */
#ifndef RT_JOB_MERGE_H
#define RT_JOB_MERGE_H

#include "rt/base/error.h"
#include "rt/image/framebuffer.h"
#include "rt/job/part.h"
#include "rt/render/aov.h"

typedef struct rt_merge {
    rt_part *parts; /* read so far, in the order given */
    int count, cap;
    int *group;     /* per part: its region's group (parts of one region are sample ranges of it) */
    int groups;
} rt_merge;

/* Room for `capacity` parts. After a failure m is empty (rt_merge_free may still be called). */
rt_result rt_merge_init(rt_merge *m, int capacity, rt_error *err);
/* Reads the part at path (its image or sidecar) and adds it; refused, naming
 * both, when it is not a part of the same render as the first. */
rt_result rt_merge_add(rt_merge *m, const char *path, rt_error *err);
/* Checks that the regions tile the image once and each region's sample
 * ranges cover 0 .. spp once, folds every pixel's sums in sample order and
 * resolves them into fb (the parts' width x height) and, when aov is not
 * NULL, the AOV images its non-NULL planes ask for (the layers the parts
 * carry). The message names the part or the pixels at fault. */
rt_result rt_merge_image(const rt_merge *m, rt_framebuffer *fb, rt_aov_buffers *aov, rt_error *err);
void rt_merge_free(rt_merge *m);

#endif
