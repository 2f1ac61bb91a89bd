/* rt/accel/kdtree_packet.h - closest hits of up to 8 coherent rays at once
 * (a 4x2 tile of primary rays, or shadow rays towards one light) through
 * the kd-tree of kdtree.h.
 *
 *   rt_ray rays[8];   // e.g. the primary rays of a 4x2 pixel tile
 *   rt_hit hits[8];
 *   unsigned hit_mask = rt_kdtree_intersect8(&tree, rays, 8, hits);
 *   // bit i set: hits[i] is what rt_kdtree_intersect(&tree, &rays[i], ...)
 *   // gives (the same t bits; either primitive when two tie); else a miss
 *
 * The rays share the walk down the tree: one step through a wide node
 * computes the 8 rays' intervals in every cell at once, a cell is
 * entered when any ray crosses it, and a leaf's triangles are tested
 * against all the rays that reach it at once. Packets whose rays run in different
 * directions along some axis (the cells' order would differ), or with a
 * ray parallel to an axis, are traced as single rays. A 4x4 tile is two
 * calls.
 */
#ifndef RT_KDTREE_PACKET_H
#define RT_KDTREE_PACKET_H

#include "rt/accel/kdtree.h"

/* n rays (1..8); returns the mask of rays that hit. */
unsigned rt_kdtree_intersect8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits);

#endif
