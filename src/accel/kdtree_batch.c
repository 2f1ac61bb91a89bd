/* kdtree_batch.c - closest and any hit over structure-of-arrays batches of
 * rays (rt/accel/kdtree_batch.h), for the wavefront path tracer.
 *
 * Today a tight loop over the single-ray traversal of kdtree_trace.c
 * (rt_kdtree_intersect / rt_kdtree_occluded), so results are those calls'
 * exactly. The batch interface is where packet traversal (8 coherent rays
 * sharing one walk of the wide nodes, Wald, Slusallek, Benthin, Wagner 2001,
 * "Interactive Rendering with Coherent Ray Tracing") or sorting rays by
 * direction octant before tracing would go; measured on the Cornell box
 * (docs/performance.md, "Wavefront path tracing"), the loop's cost is the
 * traversal itself, not the calls.
 */
#include "rt/accel/kdtree_batch.h"

static inline rt_ray ray_at(const rt_ray_batch *rb, uint32_t i)
{
    return rt_ray_make(rt_v3(rb->ox[i], rb->oy[i], rb->oz[i]), rt_v3(rb->dx[i], rb->dy[i], rb->dz[i]), rb->tmin[i],
                       rb->tmax[i]);
}

size_t rt_kdtree_intersect_batch(const rt_kdtree *tree, const rt_ray_batch *rays, const uint32_t *lanes, size_t n,
                                 rt_hit_batch *hits)
{
    size_t count = 0;
    for (size_t k = 0; k < n; k++) {
        uint32_t i = lanes ? lanes[k] : (uint32_t)k;
        rt_ray r = ray_at(rays, i);
        rt_hit h;
        if (rt_kdtree_intersect(tree, &r, &h)) {
            hits->t[i] = h.t;
            hits->u[i] = h.u;
            hits->v[i] = h.v;
            hits->prim[i] = h.prim;
            count++;
        } else {
            hits->prim[i] = RT_NONE;
        }
    }
    return count;
}

size_t rt_kdtree_occluded_batch(const rt_kdtree *tree, const rt_ray_batch *rays, const uint32_t *lanes, size_t n,
                                uint8_t *blocked)
{
    size_t count = 0;
    for (size_t k = 0; k < n; k++) {
        uint32_t i = lanes ? lanes[k] : (uint32_t)k;
        rt_ray r = ray_at(rays, i);
        blocked[i] = rt_kdtree_occluded(tree, &r) ? 1 : 0;
        count += blocked[i];
    }
    return count;
}
