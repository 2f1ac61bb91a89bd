/* rt/render/sample_block.h - the sample blocks a pixel's sum is kept in
 * (docs/farm.md, "What is bit-identical"; src/render/render.c does the
 * arithmetic, rt/io/part.h stores it).
 *
 * A pixel's sum is the left fold ((b_0 + b_1) + b_2) + ... of its block
 * sums, b_j the float sum, in sample order, of the good samples among
 * samples [64 j, 64 j + 64). With at most 64 samples it is 0 + b_0 = b_0,
 * the plain sequential sum. A range of samples that starts and ends on block
 * edges can be rendered anywhere, its block sums kept apart, and folded in
 * later to the same bits as a single render. A header of its own (only
 * this constant) because parts (rt/io) store what the renderer keeps.
 */
#ifndef RT_SAMPLE_BLOCK_H
#define RT_SAMPLE_BLOCK_H

#define RT_SAMPLE_BLOCK 64

#endif
