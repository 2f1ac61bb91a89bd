/* rt/accel/kdtree_stream.h - closest and any hit for a stream of many rays
 * (hundreds to hundreds of thousands) walked through the kd-tree together.
 *
 *   rt_ray_batch rb = {.ox = ox, .oy = oy, .oz = oz, .dx = dx, .dy = dy, .dz = dz,
 *                      .tmin = tmin, .tmax = tmax};          // rt/accel/kdtree_batch.h
 *   rt_hit_batch hb = {.t = t, .u = u, .v = v, .prim = prim};
 *   size_t hits = rt_kdtree_intersect_stream(&tree, &rb, n, &hb, NULL);
 *   // for i < n: prim[i] is the scene's primitive (RT_NONE on a miss), t[i], u[i], v[i]
 *   size_t blocked = rt_kdtree_occluded_stream(&tree, &rb, n, occ, NULL);   // occ[i] = 0 or 1
 *
 * Rays i < n of the arrays are traced; results go to entry i. Every result
 * is what rt_kdtree_intersect / rt_kdtree_occluded return for the same ray
 * (same t bits, primitive and barycentrics; where two primitives tie at
 * exactly the same t, either), whatever the stream's size, order and the
 * SIMD width that walked it. The stream is walked in chunks of rays at a
 * time (params->chunk); a chunk's rays are split at every wide node of the
 * tree into the cells they cross, each cell's rays walk on together, and
 * where fewer than params->min_rays remain, each walks on alone from that
 * node (src/accel/kdtree_stream.c says how). Safe from any number of
 * threads at once on one tree (each call uses its own memory; when that
 * memory cannot be had the rays are traced one by one, with the same
 * results).
 */
#ifndef RT_KDTREE_STREAM_H
#define RT_KDTREE_STREAM_H

#include <stddef.h>
#include <stdint.h>

#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_batch.h"

/* How a stream is walked; zero fields take the defaults, NULL all of them. */
typedef struct rt_kd_stream_params {
    int lanes;    /* SIMD width of the walk: 16 (AVX-512), 8 (AVX2), 4 (portable); 0 = the widest the CPU
                   * and the tree allow (rt_kd_stream_lanes_best). A width the CPU lacks falls back to 0. */
    int min_rays; /* a cell reached by fewer rays than this is walked ray by ray (default RT_KD_STREAM_MIN_RAYS) */
    int chunk;    /* rays walked together (default RT_KD_STREAM_CHUNK) */
} rt_kd_stream_params;
#define RT_KD_STREAM_MIN_RAYS 2
#define RT_KD_STREAM_CHUNK 4096

/* The widest walk this CPU can run on this tree: 16 with AVX-512 (F, BW,
 * DQ, VL), 8 with AVX2, else 4; 4 for trees built with params.portable. */
int rt_kd_stream_lanes_best(const rt_kdtree *tree);
/* Whether this CPU can run the walk of that width (4, 8 or 16). */
int rt_kd_stream_lanes_supported(int lanes);

/* Closest hits of rays 0 .. n; returns how many hit. */
size_t rt_kdtree_intersect_stream(const rt_kdtree *tree, const rt_ray_batch *rays, size_t n, rt_hit_batch *hits,
                                  const rt_kd_stream_params *params);
/* Any hit of rays 0 .. n: blocked[i] = 1 when something lies in (tmin, tmax),
 * else 0; returns how many are blocked. */
size_t rt_kdtree_occluded_stream(const rt_kdtree *tree, const rt_ray_batch *rays, size_t n, uint8_t *blocked,
                                 const rt_kd_stream_params *params);

#endif
