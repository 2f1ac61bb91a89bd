/* kdtree_batch.c - closest and any hit over structure-of-arrays batches of
 * rays (rt/accel/kdtree_batch.h), for the wavefront path tracer.
 *
 * Closest hits: runs of consecutive rays in the list that share one origin
 * bit for bit and their direction signs (a pinhole camera's rays: the
 * samples of neighbouring pixels, in the order the wavefront refills them)
 * go through the 8-ray packet traversal of kdtree_packet.c
 * (rt_kdtree_intersect8; Wald, Slusallek, Benthin, Wagner 2001,
 * "Interactive Rendering with Coherent Ray Tracing"), the rest through the
 * single-ray traversal of kdtree_trace.c (rt_kdtree_intersect). Both give
 * the same answers, so results do not depend on how the rays are grouped.
 * Any hits: single rays (rt_kdtree_occluded). On a tree with instances
 * (rt/scene/instance.h) the packets enter them as sub-packets
 * (kdtree_instances.c).
 */
#include "rt/accel/kdtree_batch.h"

#include <math.h>

#include "rt/accel/kdtree_packet.h"

/* A run this long or longer goes as a packet (docs/performance.md,
 * "Wavefront path tracing", measures it). */
#define KD_BATCH_MIN_PACKET 4

static inline rt_ray ray_at(const rt_ray_batch *rb, uint32_t i)
{
    return rt_ray_make(rt_v3(rb->ox[i], rb->oy[i], rb->oz[i]), rt_v3(rb->dx[i], rb->dy[i], rb->dz[i]), rb->tmin[i],
                       rb->tmax[i]);
}

static inline unsigned dir_signs(const rt_ray_batch *rb, uint32_t i)
{
    return (unsigned)signbit(rb->dx[i]) | (unsigned)signbit(rb->dy[i]) << 1 | (unsigned)signbit(rb->dz[i]) << 2;
}

static inline bool same_origin(const rt_ray_batch *rb, uint32_t i, uint32_t l)
{
    return rb->ox[l] == rb->ox[i] && rb->oy[l] == rb->oy[i] && rb->oz[l] == rb->oz[i];
}

/* How many rays from position k of the list (at most 8) share ray k's
 * origin and direction signs. Secondary rays (a path's bounce, each from
 * its own surface point) end the run at the first comparison, before any
 * direction sign is computed. */
static inline int coherent_run(const rt_ray_batch *rb, const uint32_t *lanes, size_t k, size_t n)
{
    uint32_t i = lanes ? lanes[k] : (uint32_t)k;
    if (k + 1 >= n || !same_origin(rb, i, lanes ? lanes[k + 1] : (uint32_t)(k + 1)))
        return 1;
    unsigned sg = dir_signs(rb, i);
    int m = 1;
    for (size_t j = k + 1; j < n && m < 8; j++, m++) {
        uint32_t l = lanes ? lanes[j] : (uint32_t)j;
        if (!same_origin(rb, i, l) || dir_signs(rb, l) != sg)
            break;
    }
    return m;
}

static inline size_t put_hit(rt_hit_batch *hits, uint32_t i, bool hit, const rt_hit *h)
{
    if (!hit) {
        hits->prim[i] = RT_NONE;
        return 0;
    }
    hits->t[i] = h->t;
    hits->u[i] = h->u;
    hits->v[i] = h->v;
    hits->prim[i] = h->prim;
    if (hits->inst)
        hits->inst[i] = h->inst;
    return 1;
}

size_t rt_kdtree_intersect_batch(const rt_kdtree *tree, const rt_ray_batch *rays, const uint32_t *lanes, size_t n,
                                 rt_hit_batch *hits)
{
    size_t count = 0;
    for (size_t k = 0; k < n;) {
        int m = coherent_run(rays, lanes, k, n);
        if (m >= KD_BATCH_MIN_PACKET) {
            rt_ray r8[8];
            rt_hit h8[8];
            for (int j = 0; j < m; j++)
                r8[j] = ray_at(rays, lanes ? lanes[k + (size_t)j] : (uint32_t)(k + (size_t)j));
            unsigned mask = rt_kdtree_intersect8(tree, r8, m, h8);
            for (int j = 0; j < m; j++)
                count += put_hit(hits, lanes ? lanes[k + (size_t)j] : (uint32_t)(k + (size_t)j), mask >> j & 1u,
                                 &h8[j]);
            k += (size_t)m;
            continue;
        }
        uint32_t i = lanes ? lanes[k] : (uint32_t)k;
        rt_ray r = ray_at(rays, i);
        rt_hit h;
        count += put_hit(hits, i, rt_kdtree_intersect(tree, &r, &h), &h);
        k++;
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
