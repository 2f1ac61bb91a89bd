/* kdtree_internal.h - what the kd-tree's three files share (private to
 * src/accel/; the public interface is include/rt/accel/kdtree.h).
 *
 * The files, in the order a tree passes through them:
 *
 *   kdtree_build.c  rt_kdtree_build: the SAH event sweep (Wald and Havran
 *                   2006) on one or more threads, into a binary tree of
 *                   8-byte rt_kdtree_node and leaf id lists (rt_kd_binary,
 *                   which lives only during the build); then it calls
 *   kdtree_pack.c   rt_kd_pack_wide, which makes the arrays of rt_kdtree
 *                   that the traversal reads: 64-byte wide nodes of three
 *                   levels each, and leaf blocks (a leaf's id list with an
 *                   end flag, then the triangles it is the first to use);
 *   kdtree_trace.c  rt_kdtree_intersect and rt_kdtree_occluded over those
 *                   arrays (the AVX2 step and the portable one), compiled
 *                   twice: as itself (AVX2) and by kdtree.c
 *                   (no SIMD; the choice between them, once a tree);
 *   kdtree_packet.c rt_kdtree_intersect8 and rt_kdtree_occluded8: up to 8
 *                   coherent rays through the same arrays at once (one
 *                   walk for both; the leaves by kdtree_trace.c);
 *                   its lane kernels are in kdtree_packet_lanes.h;
 *   kdtree_frustum.c rt_kdtree_intersect_frustum: a tile of up to 64
 *                   rays walked as one frustum (kdtree_packet_lanes.h's
 *                   set-up and leaf test, kdtree_trace.c's step tables);
 *   kdtree_instances.c the objects' trees of an instanced tree, and a ray's
 *                   or a sub-packet's visit to an instance (the streams'
 *                   sub-streams: kdtree_stream_instances.c).
 *
 * Only the build and packing use rt_kdtree_node; the traversal reads
 * nothing but rt_kdtree and this file's KD_MAX_DEPTH and KD_IDS_PAD.
 */
#ifndef RT_KDTREE_INTERNAL_H
#define RT_KDTREE_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"

/* The build's binary node. */
typedef struct rt_kdtree_node {
    uint32_t a; /* interior: split position (float bits); leaf: first index into the id lists (or the single prim) */
    uint32_t b; /* low 2 bits: axis 0..2, or 3 = leaf (KD_LEAF_TAG). Leaf: b >> 2 = prim count (0 = empty leaf).
                 * Interior: bit 2 = below child is an empty leaf, bit 3 = above child is,
                 * b >> 4 = above-child index (the below child is the next node). */
} rt_kdtree_node;
#define KD_LEAF_TAG 3u
/* Interior nodes: b = axis | empty-child flags << 2 | above child << 4. */
#define KD_BELOW_EMPTY 4u
#define KD_ABOVE_EMPTY 8u

/* The build's depth limit; the traversal's stack is sized for it. */
#define KD_MAX_DEPTH 60

/* The tree's leaf blocks (rt_kdtree.prim_ids) are followed by this many ids
 * with RT_KD_LAST set, so the traversal can find a list's end by loading 8
 * ids at a time. */
#define KD_IDS_PAD 8

/* Sorts a leaf's ids ascending (insertion sort: leaves are short). Leaf
 * lists are kept so: triangles, the lowest ids, come first, and the
 * traversal's 8-wide leaf test takes them as one run. */
static inline void kd_sort_ids(uint32_t *p, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        uint32_t x = p[i];
        size_t j = i;
        while (j > 0 && p[j - 1] > x) {
            p[j] = p[j - 1];
            j--;
        }
        p[j] = x;
    }
}

/* The build's result: nodes in depth-first order, and the id lists their
 * leaves of two or more primitives point into (ascending ids: triangles,
 * then the scene ids of spheres and quads). */
typedef struct rt_kd_binary {
    rt_kdtree_node *nodes;
    size_t node_count;
    uint32_t *ids;
    size_t id_count;
} rt_kd_binary;

/* Packs the binary tree into tree->wide, tree->root and the leaf blocks
 * (tree->prim_ids, tree->tri: the same array), replacing tree->tri (9
 * floats a triangle in scene order, as the build made them). false: out of
 * memory, or with *limit set, more wide nodes or block words than a child
 * reference can address (tree->tri is then unchanged). */
bool rt_kd_pack_wide(rt_kdtree *tree, const rt_kd_binary *bin, bool *limit);

/* The ray as the wide step of kdtree_trace.c reads it: per axis (lanes 0-2
 * of 8, which the AVX2 step loads whole and permutes by axis; the SSE
 * set-up repeats the values in lanes 3-7, which are never selected)
 * origin, 1/direction, cell widening in t, "direction negative" and
 * "parallel to the axis". */
typedef struct kd_ray {
    _Alignas(32) float o[8];
    _Alignas(32) float inv[8];
    _Alignas(32) float ma[8];
    _Alignas(32) int32_t neg[8]; /* -1: the above side comes first */
    _Alignas(32) int32_t par[8]; /* -1: parallel (the ray moves less than mp along the axis) */
    float mp; /* widening of every cell, in scene units */
    float tn, tf;
    bool any_par;
    rt_tri_ray tr; /* the watertight triangle test's shear (intersect.h) */
} kd_ray;

/* Runtime AVX2 dispatch. On x86 with GCC or clang the AVX2 kernels (the
 * single-ray traversal of kdtree_trace.c, the packets of kdtree_packet.c)
 * are compiled for AVX2 and FMA between KD_AVX2_BEGIN and KD_AVX2_END
 * whatever the build's flags, so a PORTABLE=1 build (the x86-64 baseline)
 * has them too; kdtree.c compiles kdtree_trace.c a second
 * time without SIMD. rt_kdtree_build picks one for the tree's life
 * (rt_kdtree.isa: rt_kd_isa_best, the CPU's); rt_kdtree_intersect and
 * rt_kdtree_occluded branch on it once a ray. Only these kernels are
 * dispatched: everything else is compiled for the build's target. Both
 * give the reference's bits (-std=c11 contracts nothing into FMAs, and
 * the Makefile says -ffp-contract=off for any compiler). */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define KD_HAVE_AVX2 1
#if defined(__clang__)
#define KD_AVX2_BEGIN _Pragma("clang attribute push (__attribute__((target(\"avx2,fma\"))), apply_to = function)")
#define KD_AVX2_END _Pragma("clang attribute pop")
#else
#define KD_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma\")")
#define KD_AVX2_END _Pragma("GCC pop_options")
#endif
/* The 16-lane kernels of the packets and frustum tiles (kdtree_packet.c,
 * kdtree_frustum.c): AVX-512 F, BW, DQ and VL, with AVX2 and FMA, by a
 * target pragma in the same way. */
#if defined(__clang__)
#define KD_AVX512_BEGIN _Pragma("clang attribute push (__attribute__((target(\"avx2,fma,avx512f,avx512bw,avx512dq,avx512vl\"))), apply_to = function)")
#define KD_AVX512_END _Pragma("clang attribute pop")
#else
#define KD_AVX512_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma,avx512f,avx512bw,avx512dq,avx512vl\")")
#define KD_AVX512_END _Pragma("GCC pop_options")
#endif
#endif

#ifdef KD_HAVE_AVX2
/* kdtree_trace.c's tables for the 8-cell AVX2 step (printed by
 * tools/kd_tables.py; also read by kdtree_frustum.c's step): byte i of
 * rt_kd_compress[m] is the lane of the i-th set bit of m; for the 7 bits
 * nb of the planes crossed towards -axis, byte L of rt_kd_cell_of_key[nb]
 * is the cell with key 7 - L and byte c of rt_kd_key_of_cell[nb] the key
 * of cell c (front-to-back keys, as in kdtree_trace.c's wide_step_scalar). */
extern const uint64_t rt_kd_compress[256];
extern const uint64_t rt_kd_cell_of_key[128];
extern const uint64_t rt_kd_key_of_cell[128];
#endif

/* The traversal a tree can use on this CPU: RT_KD_ISA_AVX2 when the
 * kernels are compiled in and the CPU has AVX2 and FMA. */
rt_kd_isa rt_kd_isa_best(void);
/* The SIMD width of a tree's packets and frustum tiles (rt_kdtree.lanes):
 * want (16, 8, or 0 for the widest) where the CPU runs it, else the
 * widest it runs: 16 with AVX-512 F/BW/DQ/VL, 8 with AVX2 and FMA; 0 when
 * the tree takes the portable traversal (packets then go as single rays). */
int rt_kd_lanes_best(rt_kd_isa isa, int want);

#ifdef KD_HAVE_AVX2
/* The packet walk (kdtree_packet.c) per width: n rays (1..16) sharing one
 * walk, closest hits into hits or (any) occlusion, the rays that hit into
 * *mask; false, with nothing done, when they cannot share it. 16 lanes
 * (AVX-512) only where rt_kd_lanes_best gives 16. */
bool rt_kd_packet_walk16(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, unsigned *mask);
bool rt_kd_packet_walk8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, unsigned *mask);
/* The frustum walk (kdtree_frustum.c) per width: n rays (1..64), the same
 * way. */
bool rt_kd_frustum_walk16(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, uint64_t *mask);
bool rt_kd_frustum_walk8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, uint64_t *mask);
#endif

/* kdtree_trace.c's entry points, once per variant (_avx2: the AVX2 pass,
 * _portable: kdtree.c's); kdtree.h's functions call one. */
bool rt_kd_intersect_avx2(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit);
bool rt_kd_occluded_avx2(const rt_kdtree *tree, const rt_ray *ray);
bool rt_kd_intersect_portable(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit);
bool rt_kd_occluded_portable(const rt_kdtree *tree, const rt_ray *ray);

/* kdtree_trace.c's single-ray leaf test (AVX2 pass), for kdtree_packet.c
 * (whose ray set-up repeats ray_setup's operations for 8 rays in lanes):
 * the primitives of one leaf reference (RT_KD_ONE or RT_KD_LEAF) tested on
 * (ray->tmin, *best), as the single-ray traversal tests them; hit->prim is
 * the tree's primitive id. any: stop at the first hit (occlusion). */
bool rt_kd_leaf_hit_avx2(const rt_kdtree *tree, uint32_t ref, const rt_ray *ray, const rt_tri_ray *tr, float *best,
                         rt_hit *hit, bool any);
/* One primitive (a tree id, as in a leaf list) for one ray, the same way. */
bool rt_kd_prim_hit_avx2(const rt_kdtree *tree, uint32_t id, const rt_ray *ray, const rt_tri_ray *tr, float *best,
                         rt_hit *hit);


/* For the ray streams (kdtree_stream.c): kdtree_trace.c's single-ray walk
 * from a child reference over a given t interval (ray->tmax: the closest
 * hit so far; hit->prim a tree id), once per pass, and the portable pass's
 * leaf test (the AVX2 pass's is rt_kd_leaf_hit_avx2 above). */
bool rt_kd_walk_from_avx2(const rt_kdtree *tree, uint32_t ref, float tn, float tf, const rt_ray *ray, rt_hit *hit,
                          bool any);
bool rt_kd_walk_from_portable(const rt_kdtree *tree, uint32_t ref, float tn, float tf, const rt_ray *ray, rt_hit *hit,
                              bool any);
bool rt_kd_leaf_hit_portable(const rt_kdtree *tree, uint32_t ref, const rt_ray *ray, const rt_tri_ray *tr, float *best,
                             rt_hit *hit, bool any);

/* Instancing (kdtree_instances.c): the objects' trees, built before the
 * top level (tree->objects, tree->object_views; false: err says why, and
 * nothing is left allocated), and freed with it. */
rt_result rt_kd_build_objects(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err);
void rt_kd_free_objects(rt_kdtree *tree);
/* A ray against instance i on (ray->tmin, *best): into the object's space,
 * through its tree, and on a closer hit *best = hit->t = t, hit->u, v,
 * hit->prim = id (the top level's primitive id of the instance) and
 * hit->inst = the object's triangle (scene id), which the entry points
 * turn into rt_hit's prim and inst (rt_kd_finish_hit). any: only whether
 * something lies in the interval (the object's any-hit traversal; *best
 * and hit untouched). Out of line: rare beside triangles, and recursive
 * through rt_kdtree_intersect / rt_kdtree_occluded. */
bool rt_kd_instance_hit(const rt_kdtree *tree, uint32_t i, uint32_t id, const rt_ray *ray, float *best, rt_hit *hit,
                        bool any);

/* Whether tree id `id` (as in a leaf list, below RT_KD_PAYLOAD) is an
 * instance: ids past the spheres and quads. */
static inline bool rt_kd_is_instance(const rt_kdtree *tree, uint32_t id)
{
    return tree->instance_count > 0 && id >= tree->other_base &&
           id - tree->other_base >= tree->sphere_count + tree->quad_count;
}

/* Whether leaf reference ref (RT_KD_ONE or RT_KD_LEAF) holds an instance:
 * its single primitive, or its list's last id (lists are ascending, and
 * instances have the highest ids). */
static inline bool rt_kd_leaf_has_instance(const rt_kdtree *tree, uint32_t ref)
{
    if (tree->instance_count == 0)
        return false;
    if (ref >= RT_KD_ONE)
        return rt_kd_is_instance(tree, ref & RT_KD_PAYLOAD);
    const uint32_t *p = tree->prim_ids + (ref & RT_KD_PAYLOAD);
    while (!(*p & RT_KD_LAST))
        p++;
    return rt_kd_is_instance(tree, *p & RT_KD_PAYLOAD);
}

/* Whether the ray can meet anything inside world box b on (ray->tmin,
 * tmax): the slab test on b grown by 2^-10 of its size and of its
 * coordinates' magnitude, far more than the rounding of the transform that
 * made an instance's box from its object's or of the slab test itself, so
 * a false answer means the ray cannot reach the object's box in its space
 * and its single visit would find nothing there. The streams leave such
 * rays out of an instance's sub-stream (their set-up is most of what a
 * miss costs; the packets measured no gain from it: 3 divides a ray). */
static inline bool rt_kd_ray_may_enter(const rt_box *b, const rt_ray *ray, float tmax)
{
    const float *o = &ray->org.x, *d = &ray->dir.x, *lo = &b->lo.x, *hi = &b->hi.x;
    float t0 = ray->tmin, t1 = tmax;
    for (int k = 0; k < 3; k++) {
        float pad = 0x1p-10f * ((hi[k] - lo[k]) + (lo[k] < 0.0f ? -lo[k] : lo[k]) + (hi[k] < 0.0f ? -hi[k] : hi[k]));
        float l = lo[k] - pad, h = hi[k] + pad;
        if (d[k] == 0.0f) {
            if (o[k] < l || o[k] > h)
                return false;
            continue;
        }
        float inv = 1.0f / d[k], a = (l - o[k]) * inv, c = (h - o[k]) * inv;
        if (a > c) {
            float x = a;
            a = c;
            c = x;
        }
        if (a > t0)
            t0 = a;
        if (c < t1)
            t1 = c;
    }
    return !(t0 > t1); /* (NaN: kept) */
}

/* A packet's rays of mask m (bits of rays, best and h; at most 32 rays)
 * against the instance of tree id `id` on (rays[r].tmin, best[r]): the
 * rays moved into the object's space by the stored inverse, exactly as
 * rt_kd_instance_hit moves one (t unchanged), and traced together through
 * the object's tree as sub-packets of up to 16 (rt_kdtree_intersect16 /
 * rt_kdtree_occluded16, which give each ray its single walk's answer);
 * a closer hit is merged back as rt_kd_instance_hit writes it (best[r],
 * h[r].t, u, v, prim = id, inst = the object's triangle). Returns the
 * rays that hit (any: that are blocked; best and h untouched). */
unsigned rt_kd_instance_packet(const rt_kdtree *tree, uint32_t id, unsigned m, const rt_ray *rays, float *best,
                               rt_hit *h, bool any);

/* A closest hit's tree id to the scene's (hit->prim) and hit->inst:
 * 0 for world geometry, instance + 1 (prim then the object's triangle,
 * which rt_kd_instance_hit left in hit->inst). */
static inline void rt_kd_finish_hit(const rt_kdtree *tree, rt_hit *hit)
{
    uint32_t p = rt_kdtree_scene_prim(tree, hit->prim);
    uint32_t first_instance = (uint32_t)(tree->triangle_count + tree->sphere_count + tree->quad_count);
    if (tree->instance_count > 0 && p >= first_instance) {
        hit->prim = hit->inst;
        hit->inst = p - first_instance + 1u;
        return;
    }
    hit->prim = p;
    hit->inst = 0;
}

#endif
