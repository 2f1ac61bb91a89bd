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
 * the object's first triangle is the scene's id.
 */
#include "kdtree_internal.h"

#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/scene/instance.h"

rt_result rt_kd_build_objects(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err)
{
    size_t n = scene->object_count;
    tree->objects = rt_alloc(n, sizeof *tree->objects);
    tree->object_views = rt_alloc(n, sizeof *tree->object_views);
    if (!tree->objects || !tree->object_views) {
        rt_kd_free_objects(tree);
        return rt_fail(err, RT_ERR_NOMEM, "kdtree: out of memory for the trees of %zu instanced objects", n);
    }
    memset(tree->objects, 0, n * sizeof *tree->objects);
    for (size_t o = 0; o < n; o++) {
        const rt_object *ob = &scene->objects[o];
        rt_scene *v = &tree->object_views[o];
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
        rt_result r = rt_kdtree_build(&tree->objects[o], v, params, err);
        if (r != RT_OK) {
            tree->object_count = o;
            rt_kd_free_objects(tree);
            return r;
        }
        tree->object_count = o + 1;
    }
    return RT_OK;
}

void rt_kd_free_objects(rt_kdtree *tree)
{
    for (size_t o = 0; o < tree->object_count; o++)
        rt_kdtree_free(&tree->objects[o]);
    free(tree->objects);
    free(tree->object_views);
    tree->objects = NULL;
    tree->object_views = NULL;
    tree->object_count = 0;
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
