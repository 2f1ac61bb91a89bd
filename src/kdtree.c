/* kdtree.c - PLACEHOLDER: brute force over all primitives until the SAH
 * kd-tree lands. Same interface, so the renderer can be written against it. */
#include "rt/kdtree.h"

#include <stdlib.h>
#include <string.h>

rt_result rt_kdtree_build(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err)
{
    (void)params; (void)err;
    memset(tree, 0, sizeof *tree);
    tree->scene = scene;
    tree->triangle_count = scene->triangles.count;
    tree->sphere_count = scene->spheres.count;
    tree->quad_count = scene->quads.count;
    tree->bounds = rt_scene_bounds(scene);
    return RT_OK;
}

void rt_kdtree_free(rt_kdtree *tree) { memset(tree, 0, sizeof *tree); }

static bool prim_hit(const rt_kdtree *tree, uint32_t id, const rt_ray *r, float tmax, rt_hit *h)
{
    const rt_scene *s = tree->scene;
    uint32_t i;
    float t, u = 0, v = 0;
    switch (rt_prim_kind_of(s, id, &i)) {
    case RT_PRIM_TRIANGLE: {
        rt_vec3 a = rt_tri_vertex(s, i, 0), b = rt_tri_vertex(s, i, 1), c = rt_tri_vertex(s, i, 2);
        if (!rt_intersect_triangle(r->org, r->dir, a, rt_sub(b, a), rt_sub(c, a), r->tmin, tmax, &t, &u, &v))
            return false;
        break;
    }
    case RT_PRIM_SPHERE:
        if (!rt_intersect_sphere(r->org, r->dir, rt_v3(s->spheres.cx[i], s->spheres.cy[i], s->spheres.cz[i]),
                                 s->spheres.radius[i], r->tmin, tmax, &t))
            return false;
        break;
    default: {
        const rt_quads *q = &s->quads;
        if (!rt_intersect_quad(r->org, r->dir, rt_v3(q->px[i], q->py[i], q->pz[i]), rt_v3(q->ux[i], q->uy[i], q->uz[i]),
                               rt_v3(q->vx[i], q->vy[i], q->vz[i]), r->tmin, tmax, &t, &u, &v))
            return false;
    }
    }
    h->t = t; h->u = u; h->v = v; h->prim = id;
    return true;
}

bool rt_kdtree_intersect(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit)
{
    size_t n = tree->triangle_count + tree->sphere_count + tree->quad_count;
    float tmax = ray->tmax;
    bool any = false;
    for (size_t i = 0; i < n; i++)
        if (prim_hit(tree, (uint32_t)i, ray, tmax, hit)) {
            tmax = hit->t;
            any = true;
        }
    if (!any)
        hit->prim = RT_NONE;
    return any;
}

bool rt_kdtree_occluded(const rt_kdtree *tree, const rt_ray *ray)
{
    rt_hit h;
    size_t n = tree->triangle_count + tree->sphere_count + tree->quad_count;
    for (size_t i = 0; i < n; i++)
        if (prim_hit(tree, (uint32_t)i, ray, ray->tmax, &h))
            return true;
    return false;
}
