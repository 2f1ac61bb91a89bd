/* kdtree_instances.c - the bottom level of an instanced kd-tree
 * (rt/accel/kdtree.h, "Instances"): one tree per scene object over its own
 * triangles in object space, and a ray's visit to an instance.
 *
 * Two-level acceleration as pbrt (TransformedPrimitive over a shared
 * aggregate, Pharr, Jakob and Humphreys, "Physically Based Rendering", 4th
 * ed., section 7.1.4) and Embree's instances do it: the top level's leaves
 * hold instances beside ordinary primitives; a ray that reaches one is
 * moved into the object's space by the inverse transform, traced in the
 * object's tree over the same (tmin, closest so far) interval, and its hit
 * is reported with the instance. The direction is transformed but not
 * renormalised, so t means the same distance along the ray in both spaces
 * and the closest hit over all instances is a plain comparison of t.
 *
 * Each object's tree is built over a view of the scene (a copy of the
 * scene record whose triangle arrays start at the object's first triangle
 * and hold only its triangles, no spheres, quads or instances), so the
 * ordinary build and traversal run unchanged; the view's triangle id plus
 * the object's first triangle is the scene's id. Objects too small for the
 * build to fork (under KD_OBJECT_ALONE triangles) are built side by side,
 * one object a thread, each on one thread; larger ones one after another,
 * each on all threads (the build forks inside). A tree is the same for any
 * thread count, so the result does not depend on the split.
 *
 * Kept trees (rt_kdtree_kept, for animation frames and motion slices): a
 * tree depends only on its triangles' corner positions, in order, and the
 * build parameters, so an object whose positions are the same bits as a
 * kept tree's (its key: 9 floats a triangle, copied when the tree was
 * built) takes that tree instead of building one; a moved instance
 * changes only the top level. Every tree of a build with a set is the
 * set's (the top-level tree borrows them).
 *
 * Packets (kdtree_packet.c, kdtree_frustum.c) walk the top level together
 * and, at an instance in a leaf, send the rays that reached it on as a
 * sub-packet (rt_kd_instance_packet): each ray moved into object space by
 * the same operations as a single ray's visit, the sub-packet through the
 * object's tree, each hit merged back as the single visit merges it; the
 * streams do the same with sub-streams (kdtree_stream_instances.c).
 */
#include "kdtree_internal.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "rt/accel/kdtree_packet.h"
#include "rt/base/alloc.h"
#include "rt/base/cpu.h"
#include "rt/scene/instance.h"

/* Objects below this many triangles are built one a thread (the build
 * forks only at KD_FORK_MIN_PRIMS, kdtree_build.c). */
#define KD_OBJECT_ALONE 4096

/* The small objects' builds: each worker takes the next one. */
typedef struct kd_object_jobs {
    rt_kdtree *trees;
    const rt_scene *views;
    const rt_kdtree_params *params; /* threads = 1 */
    size_t count;
    atomic_size_t next;
    const bool *taken; /* per object: its tree came from a kept set */
    rt_result *results; /* per object */
    rt_error *errors;   /* per object */
} kd_object_jobs;

static void *build_small_objects(void *arg)
{
    kd_object_jobs *j = arg;
    for (;;) {
        size_t o = atomic_fetch_add(&j->next, 1);
        if (o >= j->count)
            return NULL;
        if (!j->taken[o] && j->views[o].triangles.count < KD_OBJECT_ALONE)
            j->results[o] = rt_kdtree_build(&j->trees[o], &j->views[o], j->params, &j->errors[o]);
    }
}

/* One tree in a kept set: the tree, what it was built over (key: the
 * corners' positions, 9 floats a triangle, all bits set for a corner
 * whose index is out of range) and with, and whether a build has taken
 * or made it since the last trim. */
typedef struct rt_kd_kept_tree {
    rt_kdtree tree;
    float *key;
    size_t triangle_count;
    rt_kdtree_params params; /* threads and kept zeroed: they do not shape the tree */
    bool used;
} rt_kd_kept_tree;

/* The parameters that shape a tree. */
static rt_kdtree_params shaping(const rt_kdtree_params *p)
{
    rt_kdtree_params s = p ? *p : (rt_kdtree_params){0};
    s.threads = 0;
    s.kept = NULL;
    return s;
}

static bool same_shaping(const rt_kdtree_params *a, const rt_kdtree_params *b)
{
    return a->traversal_cost == b->traversal_cost && a->intersect_cost == b->intersect_cost &&
           a->empty_bonus == b->empty_bonus && a->max_depth == b->max_depth && a->portable == b->portable;
}

/* Corner k of triangle t of a view, as the key stores it. */
static void key_corner(const rt_scene *v, size_t t, int k, float out[3])
{
    uint32_t ix = v->triangles.index[3 * t + (size_t)k];
    if (ix < v->vertices.count) {
        rt_vec3 p = v->vertices.position[ix];
        out[0] = p.x, out[1] = p.y, out[2] = p.z;
    } else {
        memset(out, 0xff, 3 * sizeof *out);
    }
}

/* Whether view v's triangles are key's, bit for bit. */
static bool same_key(const rt_scene *v, const float *key)
{
    for (size_t t = 0; t < v->triangles.count; t++)
        for (int k = 0; k < 3; k++) {
            float c[3];
            key_corner(v, t, k, c);
            if (memcmp(c, key + 9 * t + 3 * (size_t)k, sizeof c) != 0)
                return false;
        }
    return true;
}

/* The kept tree object view v can take (first trying item `hint`, where
 * the same object sat last time), or NULL. */
static rt_kd_kept_tree *find_kept(rt_kdtree_kept *kept, const rt_scene *v, const rt_kdtree_params *shape,
                                  size_t hint)
{
    for (size_t i = 0; i < kept->count; i++) {
        rt_kd_kept_tree *k = &kept->items[(hint + i) % kept->count];
        if (k->triangle_count == v->triangles.count && same_shaping(&k->params, shape) && same_key(v, k->key))
            return k;
    }
    return NULL;
}

/* Moves a freshly built tree of view v into the set; false when out of
 * memory (the tree is then still the caller's). */
static bool keep_tree(rt_kdtree_kept *kept, rt_kdtree *tree, const rt_scene *v, const rt_kdtree_params *shape)
{
    size_t n = v->triangles.count;
    float *key = rt_alloc(n ? 9 * n : 1, sizeof *key);
    if (!key || !rt_grow((void **)&kept->items, &kept->cap, kept->count + 1, sizeof *kept->items)) {
        free(key);
        return false;
    }
    for (size_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++)
            key_corner(v, t, k, key + 9 * t + 3 * (size_t)k);
    rt_kd_kept_tree *k = &kept->items[kept->count++];
    k->tree = *tree;
    k->tree.scene = NULL; /* the view it was built over dies with its top-level tree */
    k->key = key;
    k->triangle_count = n;
    k->params = *shape;
    k->used = true;
    kept->built++;
    return true;
}

void rt_kdtree_kept_init(rt_kdtree_kept *kept) { memset(kept, 0, sizeof *kept); }

void rt_kdtree_kept_trim(rt_kdtree_kept *kept)
{
    size_t w = 0;
    for (size_t i = 0; i < kept->count; i++) {
        rt_kd_kept_tree *k = &kept->items[i];
        if (!k->used) {
            rt_kdtree_free(&k->tree);
            free(k->key);
            continue;
        }
        k->used = false;
        kept->items[w++] = *k;
    }
    kept->count = w;
}

void rt_kdtree_kept_free(rt_kdtree_kept *kept)
{
    for (size_t i = 0; i < kept->count; i++) {
        rt_kdtree_free(&kept->items[i].tree);
        free(kept->items[i].key);
    }
    free(kept->items);
    memset(kept, 0, sizeof *kept);
}

/* The view of object o: the scene with only its triangles. */
static void object_view(rt_scene *v, const rt_scene *scene, const rt_object *ob)
{
    *v = *scene;
    v->triangles.index = scene->triangles.index + 3 * ob->first_triangle;
    v->triangles.material = scene->triangles.material + ob->first_triangle;
    v->triangles.flags = scene->triangles.flags + ob->first_triangle;
    v->triangles.count = v->triangles.cap = ob->triangle_count;
    memset(&v->spheres, 0, sizeof v->spheres);
    memset(&v->quads, 0, sizeof v->quads);
    v->objects = NULL;
    v->object_count = v->object_cap = 0;
    v->instances = NULL;
    v->instance_count = v->instance_cap = 0;
}

/* The objects whose trees the kept set has: taken into the tree
 * (taken[o]), the set's counts updated. */
static void take_kept(rt_kdtree *tree, rt_kdtree_kept *kept, const rt_kdtree_params *shape, bool *taken)
{
    for (size_t o = 0; o < tree->object_count; o++) {
        rt_kd_kept_tree *k = kept ? find_kept(kept, &tree->object_views[o], shape, o) : NULL;
        taken[o] = k != NULL;
        if (k) {
            tree->objects[o] = k->tree;
            tree->objects[o].scene = &tree->object_views[o];
            k->used = true;
            kept->taken++;
        }
    }
}

/* The trees not taken: the small ones side by side, one a thread, then
 * the large ones one after another on all threads; per object results. */
static void build_missing(rt_kdtree *tree, const rt_kdtree_params *params, const bool *taken, rt_result *results,
                          rt_error *errors)
{
    size_t n = tree->object_count;
    int threads = params && params->threads > 0 ? params->threads : rt_cpu_count();
    if (threads < 1)
        threads = 1;
    if (threads > 64)
        threads = 64;
    rt_kdtree_params one = params ? *params : (rt_kdtree_params){0};
    one.threads = 1;
    one.kept = NULL;
    rt_kdtree_params all = params ? *params : (rt_kdtree_params){0};
    all.kept = NULL;
    kd_object_jobs jobs = {tree->objects, tree->object_views, &one, n, 0, taken, results, errors};
    pthread_t th[64];
    int started = 0;
    for (int t = 1; t < threads && (size_t)t < n; t++) /* this thread is the first worker */
        if (pthread_create(&th[started], NULL, build_small_objects, &jobs) == 0)
            started++;
    build_small_objects(&jobs);
    for (int t = 0; t < started; t++)
        pthread_join(th[t], NULL);
    for (size_t o = 0; o < n; o++) /* the large ones, each forking on all threads */
        if (!taken[o] && tree->object_views[o].triangles.count >= KD_OBJECT_ALONE)
            results[o] = rt_kdtree_build(&tree->objects[o], &tree->object_views[o], &all, &errors[o]);
}

rt_result rt_kd_build_objects(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err)
{
    size_t n = scene->object_count;
    tree->objects = rt_alloc(n, sizeof *tree->objects);
    tree->object_views = rt_alloc(n, sizeof *tree->object_views);
    rt_result *results = rt_alloc(n, sizeof *results);
    rt_error *errors = rt_alloc(n, sizeof *errors);
    bool *taken = rt_alloc(n, sizeof *taken);
    if (!tree->objects || !tree->object_views || !results || !errors || !taken) {
        free(results);
        free(errors);
        free(taken);
        rt_kd_free_objects(tree);
        return rt_fail(err, RT_ERR_NOMEM, "kdtree: out of memory for the trees of %zu instanced objects", n);
    }
    memset(tree->objects, 0, n * sizeof *tree->objects);
    for (size_t o = 0; o < n; o++) {
        object_view(&tree->object_views[o], scene, &scene->objects[o]);
        results[o] = RT_OK;
    }
    tree->object_count = n; /* every tree zeroed or built: rt_kd_free_objects frees either */
    rt_kdtree_kept *kept = params ? params->kept : NULL;
    rt_kdtree_params shape = shaping(params);
    take_kept(tree, kept, &shape, taken);
    build_missing(tree, params, taken, results, errors);
    rt_result r = RT_OK;
    for (size_t o = 0; o < n && r == RT_OK; o++)
        if (results[o] != RT_OK) {
            r = results[o];
            if (err)
                *err = errors[o];
        }
    for (size_t o = 0; o < n && r == RT_OK && kept; o++) /* what was built goes into the set */
        if (!taken[o]) {
            if (!keep_tree(kept, &tree->objects[o], &tree->object_views[o], &shape)) {
                r = rt_fail(err, RT_ERR_NOMEM, "kdtree: out of memory keeping the trees of %zu instanced objects", n);
                break;
            }
            taken[o] = true; /* the set's now */
        }
    free(results);
    free(errors);
    if (r != RT_OK) { /* the trees the set does not hold are this build's to free */
        for (size_t o = 0; o < n; o++)
            if (!taken[o])
                rt_kdtree_free(&tree->objects[o]);
    }
    tree->objects_kept = r != RT_OK || kept != NULL;
    free(taken);
    if (r != RT_OK)
        rt_kd_free_objects(tree);
    return r;
}

void rt_kd_free_objects(rt_kdtree *tree)
{
    for (size_t o = 0; o < tree->object_count && !tree->objects_kept; o++)
        rt_kdtree_free(&tree->objects[o]);
    free(tree->objects);
    free(tree->object_views);
    tree->objects = NULL;
    tree->object_views = NULL;
    tree->object_count = 0;
    tree->objects_kept = false;
}

bool rt_kd_instance_hit(const rt_kdtree *tree, uint32_t i, uint32_t id, const rt_ray *ray, float *best, rt_hit *hit,
                        bool any)
{
    const rt_instance *in = &tree->scene->instances[i];
    const rt_mat4 *m = &in->to_object;
    rt_ray r = rt_ray_make(rt_mat4_point(m, ray->org), rt_mat4_vector(m, ray->dir), ray->tmin, *best);
    if (any)
        return rt_kdtree_occluded(&tree->objects[in->object], &r);
    rt_hit h;
    if (!rt_kdtree_intersect(&tree->objects[in->object], &r, &h) || !(h.t < *best))
        return false;
    *best = h.t;
    hit->t = h.t;
    hit->u = h.u;
    hit->v = h.v;
    hit->prim = id;
    hit->inst = h.prim + (uint32_t)tree->scene->objects[in->object].first_triangle;
    return true;
}

unsigned rt_kd_instance_packet(const rt_kdtree *tree, uint32_t id, unsigned m, const rt_ray *rays, float *best,
                               rt_hit *h, bool any)
{
    uint32_t first_instance = (uint32_t)(tree->other_base + tree->sphere_count + tree->quad_count);
    const rt_instance *in = &tree->scene->instances[id - first_instance];
    const rt_kdtree *ob = &tree->objects[in->object];
    uint32_t first_triangle = (uint32_t)tree->scene->objects[in->object].first_triangle;
    const rt_mat4 *x = &in->to_object;
    unsigned found = 0;
    for (int r0 = 0; r0 < 32 && m >> r0; ) {
        rt_ray sub[16];
        rt_hit sh[16];
        int lane[16], n = 0;
        for (int r = r0; r < 32 && n < 16; r = ++r0) {
            if (!(m >> r & 1u))
                continue;
            lane[n] = r;
            sub[n++] = rt_ray_make(rt_mat4_point(x, rays[r].org), rt_mat4_vector(x, rays[r].dir), rays[r].tmin,
                                   best[r]);
        }
        if (n == 0)
            break;
        unsigned got = any ? rt_kdtree_occluded16(ob, sub, n) : rt_kdtree_intersect16(ob, sub, n, sh);
        for (int j = 0; j < n; j++) {
            int r = lane[j];
            if (!(got >> j & 1u))
                continue;
            if (any) {
                found |= 1u << r;
                continue;
            }
            if (!(sh[j].t < best[r]))
                continue;
            best[r] = sh[j].t;
            h[r].t = sh[j].t;
            h[r].u = sh[j].u;
            h[r].v = sh[j].v;
            h[r].prim = id;
            h[r].inst = sh[j].prim + first_triangle;
            found |= 1u << r;
        }
    }
    return found;
}
