/* rt/accel/kdtree.h - a flattened SAH kd-tree over every primitive of a scene.
 *
 * The tree is built once from a scene (triangles, spheres and quads in the
 * scene's primitive id space, see scene.h) and then only read, from any
 * number of threads at once.
 *
 *   rt_kdtree tree;
 *   rt_error err;
 *   if (rt_kdtree_build(&tree, &scene, NULL, &err) != RT_OK) ...
 *   rt_hit hit;
 *   if (rt_kdtree_intersect(&tree, &ray, &hit)) ... hit.t, hit.prim, hit.u, hit.v
 *   bool blocked = rt_kdtree_occluded(&tree, &shadow_ray);
 *   rt_kdtree_free(&tree);
 *
 * Layout: the build makes 8-byte nodes in one array (the below child is the
 * next node) and leaf primitive lists in a second array; for tracing,
 * every three levels of that binary tree are then packed into one 64-byte,
 * cache-line-aligned rt_kdtree_wide (7 split planes, 8 cells), so a ray
 * resolves three levels with one memory access and one SIMD step instead of
 * three dependent branches. The planes and cells are exactly the binary
 * tree's. Leaves and triangles share one array of leaf blocks: a block is
 * the leaf's id list followed by the records (v0, v1, v2 and the scene id,
 * RT_KD_TRI words) of the triangles no earlier leaf used, so a leaf's list
 * and most of its triangles sit in the same or adjacent cache lines; a
 * triangle's id is the offset of its record in that array (hits report
 * scene ids). The build, this packing and the traversal are described,
 * with their sources, at the top of src/accel/kdtree_build.c,
 * kdtree_pack.c and kdtree_trace.c.
 *
 * Results are exactly those of testing every primitive with the functions
 * of intersect.h (same t bits; either id when two primitives tie). Rays with
 * a non-finite origin or direction, a zero direction, or tmin >= tmax (or
 * NaN) hit nothing. Primitives that can never be hit (non-finite
 * coordinates, a zero edge, a zero-area quad, a non-finite sphere) are left
 * out of the tree.
 *
 * Instances (rt/scene/instance.h): when the scene has some, the build
 * makes one tree per object over its own triangles (object space, the same
 * kind of tree) and the tree itself is the top level, over the world
 * geometry and the instances' world boxes (an instance is a primitive of
 * it, scene id T + S + Q + instance, after the quads). A ray reaching an
 * instance in a leaf goes into object space by the instance's inverse (t
 * is unchanged: the direction is not renormalised) and is traced in the
 * object's tree; the hit reports the object's triangle (its scene id) and
 * hit.inst = instance + 1. The packet, frustum and stream traversals
 * (kdtree_packet.h, kdtree_frustum.h, kdtree_stream.h) walk the top level
 * together and enter an instance with the rays that reached it as a
 * sub-packet or sub-stream through the object's tree, each ray with the
 * single walk's answer.
 *
 * The tree keeps a pointer to the scene (for spheres) and each quad's
 * prepared test (rt_quad_prep): the scene must outlive it and must not
 * gain or move primitives after the build.
 */
#ifndef RT_KDTREE_H
#define RT_KDTREE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "rt/base/error.h"
#include "rt/accel/intersect.h"
#include "rt/accel/ray.h"
#include "rt/scene/scene.h"

/* Build parameters; a zero field means "the default". */
typedef struct rt_kdtree_params {
    float traversal_cost; /* SAH cost of one traversal step (default 4) */
    float intersect_cost; /* SAH cost of one primitive test (default 1) */
    float empty_bonus;    /* fraction (0..1) by which a split with an empty side is cheaper (default 0.2) */
    int max_depth;        /* 0 = 8 + 1.3 log2(N) (pbrt's rule) */
    int threads;          /* build threads; 0 = one per online CPU (same tree for any count) */
    int portable;         /* 1: the portable traversal even when the CPU has AVX2 (tests; same answers) */
    int lanes;            /* SIMD width of packets and frustum tiles: 16 (AVX-512), 8 (AVX2); 0 = the widest
                           * the CPU runs, as is a width it lacks (tests, benchmarks; same answers) */
    struct rt_kdtree_kept *kept; /* objects' trees kept between builds (below); NULL: build every one */
} rt_kdtree_params;

/* The traversal kernels a tree uses, chosen once by the build from the CPU
 * (AVX2 and FMA, when compiled in: on x86 with GCC or clang, PORTABLE=1
 * builds included) and params->portable. */
typedef enum rt_kd_isa { RT_KD_ISA_PORTABLE = 0, RT_KD_ISA_AVX2 = 1 } rt_kd_isa;

typedef struct rt_kdtree_stats {
    size_t nodes, leaves, empty_leaves; /* of the binary tree */
    size_t wide_nodes;    /* 64-byte nodes of 3 levels each, which the traversal reads */
    size_t prim_refs;     /* primitive ids stored in leaves (with duplicates) */
    size_t max_leaf_prims;
    int depth;
    double build_ms;
    double serial_cpu_ms; /* CPU time the building thread spent with no other build thread running (the top-level tree) */
    size_t bytes;         /* wide nodes + leaf blocks (ids and triangles) + prepared quads (+ the objects' trees) */
} rt_kdtree_stats;

/* Three levels of the binary tree: planes in breadth-first order (0 the top
 * node, 1 and 2 its below and above children, 3-6 theirs: plane p's children
 * are 2p+1 and 2p+2), cells c = 4 b0 + 2 b1 + b2 with b = 0 for the below
 * side at each level. A plane that does not exist (a leaf above level 3)
 * is +inf on x, which keeps the whole cell below it. A child reference is
 * another wide node (< RT_KD_LEAF), RT_KD_EMPTY, RT_KD_ONE | primitive id, or
 * RT_KD_LEAF | offset into prim_ids of a list of primitive ids (ascending,
 * the last with RT_KD_LAST set). A primitive id below other_base is the
 * offset of a triangle's record in the same array, an id above it a sphere
 * or quad (scene id = id - other_base + triangle_count). */
typedef struct rt_kdtree_wide {
    float split[7];
    uint32_t axes;      /* axis of plane p in bits 2p, 2p+1 */
    uint32_t child[8];
} rt_kdtree_wide;
#define RT_KD_EMPTY 0xffffffffu
#define RT_KD_LEAF 0x80000000u
#define RT_KD_ONE 0xc0000000u
#define RT_KD_PAYLOAD 0x3fffffffu
#define RT_KD_LAST 0x80000000u
#define RT_KD_TRI 10

typedef struct rt_kdtree {
    rt_kdtree_wide *wide; /* 64-byte aligned */
    size_t wide_count;
    uint32_t root;        /* a child reference: the whole tree */
    /* the leaf blocks: tri and prim_ids are the same array (64-byte aligned,
     * prim_id_count words, then KD_IDS_PAD words of padding), read as floats
     * for triangle records (RT_KD_TRI words each: v0.xyz, v1.xyz, v2.xyz,
     * then the bits of the scene's triangle id) and as ids for leaf lists */
    uint32_t *prim_ids;
    size_t prim_id_count;
    float *tri;
    uint32_t other_base;  /* primitive ids >= this are spheres and quads */
    size_t triangle_count, sphere_count, quad_count; /* at build time */
    rt_quad_prep *quads;  /* per scene quad: its test's ray-independent part (quad_count) */
    float scale; /* largest absolute coordinate of bounds (traversal epsilon) */
    const rt_scene *scene;
    rt_kd_isa isa;        /* the traversal kernels this tree uses */
    int lanes;            /* its packets' and frustum tiles' SIMD width: 16, 8, 0 (single rays) */
    rt_box bounds;
    int max_depth;
    rt_kdtree_stats stats;
    /* instancing: one tree per scene object (object_count, each over a
     * view of the scene holding only that object's triangles), and the
     * instances' count; primitive ids past the quads are instances */
    struct rt_kdtree *objects;
    struct rt_scene *object_views;
    size_t object_count, instance_count;
    bool objects_kept;    /* the objects' trees belong to params->kept, not to this tree */
} rt_kdtree;

/* Objects' trees kept from one build for the next (animation frames,
 * motion slices): node animation moves instances, not the objects, so a
 * build given the same set (rt_kdtree_params.kept) takes every object's
 * tree from it whose triangles are the same, bit for bit (the positions
 * of their corners, in order, and the build parameters), and builds
 * only the others and the top level; what it builds goes into the set.
 * The trees of a tree built so belong to the set: the set must outlive
 * it. A taken tree is the one a fresh build makes (a tree depends only on
 * those positions and parameters), so hits do not change.
 *
 *   rt_kdtree_kept kept;
 *   rt_kdtree_kept_init(&kept);
 *   rt_kdtree_params par = {0};
 *   par.kept = &kept;
 *   for each frame: load the scene posed; rt_kdtree_build(&tree, &scene, &par, &err);
 *                   render; rt_kdtree_free(&tree); rt_kdtree_kept_trim(&kept);
 *   rt_kdtree_kept_free(&kept);
 *
 * built and taken count the objects' trees built into the set and taken
 * from it, over its life (what rt -v says, and what tests check). */
typedef struct rt_kdtree_kept {
    struct rt_kd_kept_tree *items; /* kdtree_instances.c */
    size_t count, cap;
    size_t built, taken;
} rt_kdtree_kept;
void rt_kdtree_kept_init(rt_kdtree_kept *kept);
/* Frees the trees no build took or made since the last trim: call it only
 * when no tree built with the set is alive. */
void rt_kdtree_kept_trim(rt_kdtree_kept *kept);
void rt_kdtree_kept_free(rt_kdtree_kept *kept);

rt_result rt_kdtree_build(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err);
void rt_kdtree_free(rt_kdtree *tree);

/* The scene's id of primitive id n (a triangle's record offset, or a
 * sphere or quad above other_base). */
static inline uint32_t rt_kdtree_scene_prim(const rt_kdtree *tree, uint32_t n)
{
    uint32_t id;
    if (n >= tree->other_base)
        return n - tree->other_base + (uint32_t)tree->triangle_count;
    memcpy(&id, tree->tri + (size_t)n + 9, sizeof id);
    return id;
}

/* Closest hit with t in (ray->tmin, ray->tmax). */
bool rt_kdtree_intersect(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit);
/* Any hit with t in (ray->tmin, ray->tmax): for shadow rays. */
bool rt_kdtree_occluded(const rt_kdtree *tree, const rt_ray *ray);

#endif
