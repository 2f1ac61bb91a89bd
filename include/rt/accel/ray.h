/* rt/accel/ray.h - rays, hits, and where a secondary ray starts.
 *
 * A ray is an origin, a direction (not necessarily unit length) and the open
 * interval (tmin, tmax) of t it covers; a hit is what the intersection tests
 * (intersect.h) and the kd-tree (kdtree.h) report. Every stage passes these.
 *
 *   rt_ray r = rt_ray_make(origin, dir, 0.0f, INFINITY);
 *   rt_hit hit;
 *   if (rt_kdtree_intersect(&tree, &r, &hit)) ... hit.t, hit.prim, hit.u, hit.v
 *   rt_vec3 o = rt_offset_ray_origin(p, n, scene_scale); // a secondary ray leaving p
 */
#ifndef RT_RAY_H
#define RT_RAY_H

#include <stdint.h>

#include "rt/base/vec.h"

typedef struct rt_ray {
    rt_vec3 org, dir; /* dir need not be unit length; t is in units of |dir| */
    float tmin, tmax;
} rt_ray;

typedef struct rt_hit {
    float t;
    float u, v;    /* triangle barycentrics of v1, v2; quad (s, t); sphere unused */
    uint32_t prim; /* primitive id (see scene.h), RT_NONE for a miss; on an instance its object's triangle */
    uint32_t inst; /* 0: prim is world geometry; n > 0: prim was hit through instance n - 1
                    * (rt/scene/instance.h), so a zeroed hit is never an instance's */
} rt_hit;

static inline rt_ray rt_ray_make(rt_vec3 org, rt_vec3 dir, float tmin, float tmax)
{
    rt_ray r = {org, dir, tmin, tmax};
    return r;
}

/* Robust origin for a secondary ray leaving a surface at p with geometric
 * normal n (unit, pointing to the side the ray leaves on): Waechter and
 * Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray
 * Tracing Gems ch. 6. Away from the origin p moves a fixed number of float
 * ulps along n, so the step grows with |p|; near the origin, where ulps
 * vanish, it moves a fixed distance. `scale` is the scene's size (largest
 * absolute coordinate; 1 for the paper's constants): both the "near the
 * origin" region and the fixed step scale with it, because the error of a
 * computed hit point is relative to the coordinates of the geometry hit, not
 * to p. So a 6 cm model and a 400 m one both render without acne or leaks. */
static inline float rt__nudge_float(float x, int ulps)
{
    union { float f; int32_t i; } u;
    u.f = x;
    u.i += x < 0.0f ? -ulps : ulps;
    return u.f;
}
static inline rt_vec3 rt_offset_ray_origin(rt_vec3 p, rt_vec3 n, float scale)
{
    const float origin = scale * (1.0f / 32.0f), float_scale = scale * (1.0f / 65536.0f), int_scale = 256.0f;
    rt_vec3 q;
    q.x = fabsf(p.x) < origin ? p.x + float_scale * n.x : rt__nudge_float(p.x, (int)(int_scale * n.x));
    q.y = fabsf(p.y) < origin ? p.y + float_scale * n.y : rt__nudge_float(p.y, (int)(int_scale * n.y));
    q.z = fabsf(p.z) < origin ? p.z + float_scale * n.z : rt__nudge_float(p.z, (int)(int_scale * n.z));
    return q;
}

#endif
