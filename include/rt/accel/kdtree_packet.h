/* rt/accel/kdtree_packet.h - closest hits, or occlusion, of up to 8
 * coherent rays at once (a 4x2 tile of primary rays, or shadow rays from
 * many points towards one light) through the kd-tree of kdtree.h.
 *
 *   rt_ray rays[8];   // e.g. the primary rays of a 4x2 pixel tile
 *   rt_hit hits[8];
 *   unsigned hit_mask = rt_kdtree_intersect8(&tree, rays, 8, hits);
 *   // bit i set: hits[i] is what rt_kdtree_intersect(&tree, &rays[i], ...)
 *   // gives (the same t bits; either primitive when two tie); else a miss
 *
 *   rt_ray shadow[8]; // from 8 shading points to one light, each with its
 *                     // own tmin and tmax (the segment to the light)
 *   unsigned blocked = rt_kdtree_occluded8(&tree, shadow, 8);
 *   // bit i set exactly when rt_kdtree_occluded(&tree, &shadow[i])
 *
 * The rays share the walk down the tree: one step through a wide node
 * computes the 8 rays' intervals in every cell at once, a cell is
 * entered when any ray crosses it, and a leaf's triangles are tested
 * against all the rays that reach it at once; for occlusion a ray drops
 * out of the packet at its first hit. Packets whose rays run in different
 * directions along some axis (the cells' order would differ), or with a
 * ray parallel to an axis, are traced as single rays. A 4x4 tile is one
 * call of rt_kdtree_intersect16 (one 16-lane vector with AVX-512, two
 * 8-lane halves sharing the walk with AVX2: rt_kdtree.lanes, chosen by the
 * build). Packets go through the SIMD kernels when the tree's rays do
 * (rt_kdtree.isa), else as single rays; every width gives the same bits.
 */
#ifndef RT_KDTREE_PACKET_H
#define RT_KDTREE_PACKET_H

#include "rt/accel/kdtree.h"

/* n rays (1..8; more are ignored); returns the mask of rays that hit. */
unsigned rt_kdtree_intersect8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits);
/* n rays (1..8); returns the mask of rays with any hit in (tmin, tmax). */
unsigned rt_kdtree_occluded8(const rt_kdtree *tree, const rt_ray *rays, int n);
/* The same for n = 1..16 rays (a 4x4 tile) in one walk (16 lanes, or two
 * 8-lane halves sharing each node step and leaf); rays that cannot share
 * it go as two packets of 8. */
unsigned rt_kdtree_intersect16(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits);
unsigned rt_kdtree_occluded16(const rt_kdtree *tree, const rt_ray *rays, int n);

#endif
