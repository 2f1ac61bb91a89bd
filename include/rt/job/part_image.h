/* rt/job/part_image.h - a part (rt/job/part.h) seen as an image: its
 * region's pixels resolved from the sums and counts (fold, then sum /
 * count) as the renderer resolves them, so `rt convert` and `rt compare`
 * show a part as the picture it holds instead of its raw sums.
 *
 *   rt_framebuffer fb;
 *   rt_part_info info;
 *   bool part;
 *   if (rt_image_or_part_read("p.exr", &fb, &info, &part, &err) != RT_OK) ...  // a part or any image
 *   if (part) ... fb is info.x1 - info.x0 by info.y1 - info.y0, samples info.s_begin:info.s_end ...
 */
#ifndef RT_JOB_PART_IMAGE_H
#define RT_JOB_PART_IMAGE_H

#include <stdbool.h>

#include "rt/base/error.h"
#include "rt/image/framebuffer.h"
#include "rt/job/part.h"

/* True when path is a part: its sidecar path.json exists, or path is the
 * sidecar (NAME.json). */
bool rt_path_is_part(const char *path);

/* The region of p resolved into fb (allocated here, the region's size):
 * 0 + the fold + each kept block in sample order (rt_sample_fold), then
 * rt_sample_resolve by the pixel's count; the pixels of a complete part
 * are the bits `rt merge` gives them. */
rt_result rt_part_image(const rt_part *p, rt_framebuffer *fb, rt_error *err);

/* Reads path into fb: a part (rt_path_is_part) read, checked and resolved
 * (*is_part true, its sidecar into *info), else any image rt_image_read
 * reads (*is_part false). info may be NULL. A broken part is refused with
 * rt_part_read's message, naming it; so is a .pfm part's counts or block
 * file (P.count.pfm, P.block.J.pfm), naming the part P. */
rt_result rt_image_or_part_read(const char *path, rt_framebuffer *fb, rt_part_info *info, bool *is_part,
                                rt_error *err);

#endif
