/* rt/accel/kdtree_batch.h - closest and any hit for a batch of rays held
 * as structure-of-arrays (the wavefront path tracer's layout).
 *
 *   rt_ray_batch rb = {.ox = ox, .oy = oy, .oz = oz, .dx = dx, .dy = dy, .dz = dz,
 *                      .tmin = tmin, .tmax = tmax};
 *   rt_hit_batch hb = {.t = t, .u = u, .v = v, .prim = prim};
 *   size_t hits = rt_kdtree_intersect_batch(&tree, &rb, lanes, n, &hb);
 *   // for k < n: ray lanes[k] (lanes NULL: ray k) hit prim[lanes[k]] (RT_NONE on a miss)
 *   rt_kdtree_occluded_batch(&tree, &rb, lanes, n, blocked);   // blocked[lane] = 0 or 1
 *
 * `lanes` lists which entries of the arrays to trace (the live paths of a
 * batch, in any order); results go to the same entry. Every result is
 * bit-for-bit what rt_kdtree_intersect / rt_kdtree_occluded (rt/accel/kdtree.h)
 * return for the same ray, whatever the batch's size and order. Runs of
 * consecutive rays in the list that share one origin (a pinhole camera's
 * rays, listed pixel by pixel) are traced 8 at a time as packets
 * (rt/accel/kdtree_packet.h): list coherent rays next to each other.
 * On a tree with instances the packets enter them as sub-packets (the same
 * answers), and hits->inst should be given (rt_hit.inst: which instance,
 * + 1).
 */
#ifndef RT_KDTREE_BATCH_H
#define RT_KDTREE_BATCH_H

#include <stddef.h>
#include <stdint.h>

#include "rt/accel/kdtree.h"

/* Rays: origin, direction (need not be unit) and the interval (tmin, tmax). */
typedef struct rt_ray_batch {
    const float *ox, *oy, *oz;
    const float *dx, *dy, *dz;
    const float *tmin, *tmax;
} rt_ray_batch;

/* Closest hits: t, barycentrics (rt_hit's u, v) and the scene's primitive
 * id, RT_NONE for a miss (t, u, v then untouched). */
typedef struct rt_hit_batch {
    float *t, *u, *v;
    uint32_t *prim;
    uint32_t *inst; /* rt_hit's inst, written on a hit; NULL: not wanted (a tree without instances) */
} rt_hit_batch;

/* Closest hit of rays lanes[0 .. n) (NULL: 0 .. n); returns how many hit. */
size_t rt_kdtree_intersect_batch(const rt_kdtree *tree, const rt_ray_batch *rays, const uint32_t *lanes, size_t n,
                                 rt_hit_batch *hits);
/* Any hit of rays lanes[0 .. n): blocked[lane] = 1 when something lies in
 * (tmin, tmax), else 0; returns how many are blocked. */
size_t rt_kdtree_occluded_batch(const rt_kdtree *tree, const rt_ray_batch *rays, const uint32_t *lanes, size_t n,
                                uint8_t *blocked);

#endif
