/* rt/render/sample_block.h - the sample blocks a pixel's sum is kept in
 * (docs/farm.md, "What is bit-identical"; src/render/render.c does the
 * arithmetic, rt/job/part.h stores it).
 *
 * A pixel's sum is the left fold ((b_0 + b_1) + b_2) + ... of its block
 * sums, b_j the float sum, in sample order, of the good samples among
 * samples [64 j, 64 j + 64). With at most 64 samples it is 0 + b_0 = b_0,
 * the plain sequential sum. A range of samples that starts and ends on block
 * edges can be rendered anywhere, its block sums kept apart, and folded in
 * later to the same bits as a single render. The fold's step and the
 * resolve of a pixel are the two functions below: the renderer
 * (render.c) and the merge of parts (rt/job/merge.h) both use them, so a
 * merged image is a single render's by construction.
 *
 *   rt_vec3 sum = rt_v3s(0);
 *   for (each block or part's fold, in sample order) sum = rt_sample_fold(sum, b);
 *   rt_vec3 pixel = rt_sample_resolve(sum, good);
 */
#ifndef RT_SAMPLE_BLOCK_H
#define RT_SAMPLE_BLOCK_H

#include <stdint.h>

#include "rt/base/vec.h"

#define RT_SAMPLE_BLOCK 64

/* One step of the fold: the sum so far with the next block's sum (or a
 * part's fold) taken in. */
static inline rt_vec3 rt_sample_fold(rt_vec3 sum, rt_vec3 block)
{
    return rt_add(sum, block);
}

/* The pixel value of a sum of `good` samples: sum * (1 / good); with no
 * good sample, the sum as it is (zero). */
static inline rt_vec3 rt_sample_resolve(rt_vec3 sum, uint32_t good)
{
    return good ? rt_scale(sum, 1.0f / (float)good) : sum;
}

#endif
