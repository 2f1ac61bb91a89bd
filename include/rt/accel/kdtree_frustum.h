/* rt/accel/kdtree_frustum.h - closest hits, or occlusion, of a whole tile
 * of coherent rays (up to 64: camera rays of an 8x8 pixel tile, or shadow
 * rays from a tile's hit points to one point or small light) walked
 * through the kd-tree of kdtree.h as one frustum.
 *
 *   rt_ray rays[64];  // e.g. the primary rays of an 8x8 pixel tile
 *   rt_hit hits[64];
 *   uint64_t hit_mask = rt_kdtree_intersect_frustum(&tree, rays, 64, hits);
 *   // bit i set: hits[i] is what rt_kdtree_intersect(&tree, &rays[i], ...)
 *   // gives (the same t bits; either primitive when two tie); else
 *   // hits[i].prim == RT_NONE
 *
 *   uint64_t blocked = rt_kdtree_occluded_frustum(&tree, shadow, n);
 *   // bit i set exactly when rt_kdtree_occluded(&tree, &shadow[i])
 *
 * The tile's rays are bounded per axis by the ranges of their origins and
 * reciprocal directions; each node of the walk is decided for the whole
 * tile at once from those ranges (interval arithmetic: one step a node,
 * whatever the tile's size), and only at the leaves are the rays tested
 * one by one (in SIMD lanes: 16 with AVX-512, 8 with AVX2, the tree's
 * rt_kdtree.lanes; the same bits at every width). A tile whose rays run in different
 * directions along some axis, or with a ray parallel to an axis, goes as
 * 16-ray packets (kdtree_packet.h), which trace such rays singly. Trees
 * whose rays take the portable traversal trace tiles as packets too.
 * src/accel/kdtree_frustum.c says how and what it costs. Safe from any
 * number of threads on one tree.
 */
#ifndef RT_KDTREE_FRUSTUM_H
#define RT_KDTREE_FRUSTUM_H

#include <stdint.h>

#include "rt/accel/kdtree.h"

/* The most rays one call takes (more are ignored). */
#define RT_KD_FRUSTUM_MAX 64

/* n rays (1..64); returns the mask of rays that hit. */
uint64_t rt_kdtree_intersect_frustum(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits);
/* n rays (1..64); returns the mask of rays with any hit in (tmin, tmax). */
uint64_t rt_kdtree_occluded_frustum(const rt_kdtree *tree, const rt_ray *rays, int n);

#endif
