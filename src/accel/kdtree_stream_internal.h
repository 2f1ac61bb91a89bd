/* kdtree_stream_internal.h - what the ray stream's files share (private to
 * src/accel/; the public interface is include/rt/accel/kdtree_stream.h).
 *
 *   kdtree_stream.c        the entry points: each chunk's per-ray set-up
 *                          (kd_stream), the leaves and the ray-by-ray walk
 *                          from a node (kdtree_trace.c's), the choice of width;
 *   kdtree_stream_instances.c  an instance leaf: its rays as one sub-stream
 *                          through the object's tree;
 *   kdtree_stream_walk.c   the walk itself, written once with GCC/clang
 *                          vector types of KD_STREAM_LANES lanes and compiled
 *                          per width: as itself (16 lanes, AVX-512), by
 *                          kdtree_stream_walk8.c (8, AVX2) and
 *                          kdtree_stream_walk4.c (4, the build's target).
 */
#ifndef RT_KDTREE_STREAM_INTERNAL_H
#define RT_KDTREE_STREAM_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "kdtree_internal.h"
#include "rt/accel/kdtree_batch.h"

typedef struct kd_stream_sub kd_stream_sub; /* kdtree_stream_instances.c */

/* One chunk of rays as the walk reads it; index i is the ray's place in
 * the chunk. Per axis k: origin, 1/direction (0 on a parallel axis), the
 * cell widening in t (mp |1/d|, 0 when parallel) and -1 where the ray is
 * parallel to the axis (kdtree_trace.c's ray_setup: the same values). */
typedef struct kd_stream {
    const rt_kdtree *tree;
    bool any;      /* occlusion: a ray stops at its first hit */
    bool any_par;  /* some ray of the chunk is parallel to an axis */
    int min_rays;  /* fewer rays than this in a cell: ray by ray */
    int lanes;     /* the walk's width: 16, 8 or 4 */
    size_t chunk;  /* rays the per-ray arrays hold */
    void *block;   /* the per-ray arrays' memory */
    kd_stream_sub *sub; /* the sub-stream into instances' objects, made at the first instance leaf (NULL) */
    float *o[3], *inv[3], *ma[3];
    int32_t *par[3];
    float *mp;
    float *best;   /* closest hit so far (tmax at first); NaN once an occlusion ray is blocked */
    rt_ray *ray;
    rt_tri_ray *tr;
    rt_hit *hit;   /* hit[i].prim: a tree id, RT_NONE while none */
    /* the walk's ray lists (ray index, t interval in the cell), one arena
     * used as a stack: a node's lists lie above its parent's */
    uint32_t *lid;
    float *llo, *lhi;
    size_t cap;
} kd_stream;

/* The per-ray arrays and the root list of a chunk of up to `chunk` rays
 * for a walk of `lanes` lanes through tree (any: occlusion); false: out of
 * memory (release with rt_kd_stream_close all the same). */
bool rt_kd_stream_open(kd_stream *s, const rt_kdtree *tree, bool any, int lanes, int min_rays, size_t chunk);
void rt_kd_stream_close(kd_stream *s);
/* Rays g0 .. g0 + m of rb (m <= s->chunk) set up and walked at s->lanes:
 * s->hit[i] for i < m is ray g0 + i's answer (tree ids). false: out of
 * memory (the answers are partial). */
bool rt_kd_stream_chunk(kd_stream *s, const rt_ray_batch *rb, size_t g0, size_t m);

/* Instancing (kdtree_stream_instances.c): the rays of list [b, b + n) at
 * leaf ref, which holds an instance: each primitive of the leaf in its
 * order, an instance as one sub-stream of the rays still live (moved into
 * the object's space as rt_kd_instance_hit moves one ray, walked through
 * the object's tree, the hits merged back), the others ray by ray. false:
 * out of memory. The sub-stream's memory lives until rt_kd_stream_close. */
bool rt_kd_stream_instance_leaf(kd_stream *s, uint32_t ref, size_t b, size_t n);
void rt_kd_stream_sub_free(kd_stream_sub *sub);

/* Room for `need` list entries in the arena (pointers may move); false when
 * out of memory. */
bool rt_kd_stream_reserve(kd_stream *s, size_t need);
/* Ray i against the leaf reference ref (RT_KD_ONE or RT_KD_LEAF), on
 * (tmin, best[i]). */
void rt_kd_stream_leaf(kd_stream *s, uint32_t ref, uint32_t i);
/* Ray i alone from child reference ref over [tn, tf]. */
void rt_kd_stream_single(kd_stream *s, uint32_t ref, uint32_t i, float tn, float tf);

/* The walk of the rays listed in the arena's first `count` entries from the
 * tree's root; false when out of memory (results then partial). One per
 * width; only those the CPU runs may be called. */
bool rt_kd_stream_walk16(kd_stream *s, size_t count);
bool rt_kd_stream_walk8(kd_stream *s, size_t count);
bool rt_kd_stream_walk4(kd_stream *s, size_t count);
/* The set-up of rays g0 .. g0 + m of rb into the chunk's arrays and the
 * root list (the arena's first entries); returns how many can hit
 * something (the others: hit[i].prim RT_NONE). s->any_par is or-ed. */
size_t rt_kd_stream_setup16(kd_stream *s, const rt_ray_batch *rb, size_t g0, size_t m);
size_t rt_kd_stream_setup8(kd_stream *s, const rt_ray_batch *rb, size_t g0, size_t m);
size_t rt_kd_stream_setup4(kd_stream *s, const rt_ray_batch *rb, size_t g0, size_t m);

#endif
