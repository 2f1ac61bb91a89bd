/* rt/intersect.h - rays, hits, and the ray-primitive tests.
 *
 * All tests are two-sided and return the nearest hit with t in the open
 * interval (tmin, tmax). They are `static inline` because the kd-tree's leaf
 * loops call them millions of times a second.
 *
 *   rt_ray r = rt_ray_make(origin, dir, 0.0f, INFINITY);
 *   float t, u, v;
 *   if (rt_intersect_triangle(r.org, r.dir, v0, e1, e2, r.tmin, r.tmax, &t, &u, &v)) ...
 *
 * Triangle: Moeller and Trumbore (1997), "Fast, Minimum Storage Ray/Triangle
 * Intersection", with precomputed edges e1 = v1 - v0, e2 = v2 - v0; (u, v)
 * are the barycentrics of v1 and v2. Degenerate triangles (zero area, or
 * collinear edges up to rounding) never hit, and neither does a ray within
 * about 1e-5 rad of a triangle's or quad's plane: there the determinant is
 * rounding noise and the computed hit could lie anywhere on the ray.
 * Sphere: the numerically robust quadratic of Haines et al., "Precision
 * Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7.
 * Quad (parallelogram p + s*u + t*v): plane hit, then (s, t) by projection.
 */
#ifndef RT_INTERSECT_H
#define RT_INTERSECT_H

#include "rt/base/vec.h"

typedef struct rt_ray {
    rt_vec3 org, dir; /* dir need not be unit length; t is in units of |dir| */
    float tmin, tmax;
} rt_ray;

typedef struct rt_hit {
    float t;
    float u, v;    /* triangle barycentrics of v1, v2; quad (s, t); sphere unused */
    uint32_t prim; /* primitive id (see scene.h), RT_NONE for a miss */
} rt_hit;

/* The tests below must round the same wherever they are compiled (the
 * kd-tree's 8-wide leaf test reproduces them bit for bit): no fused
 * multiply-adds, see RT_NO_FP_CONTRACT in vec.h. */
static inline rt_ray rt_ray_make(rt_vec3 org, rt_vec3 dir, float tmin, float tmax)
{
    rt_ray r = {org, dir, tmin, tmax};
    return r;
}

static inline bool rt_intersect_triangle(rt_vec3 org, rt_vec3 dir, rt_vec3 v0, rt_vec3 e1, rt_vec3 e2, float tmin,
                                         float tmax, float *t_out, float *u_out, float *v_out)
{
    RT_NO_FP_CONTRACT
    rt_vec3 p = rt_cross(dir, e2);
    float det = rt_dot(e1, p);
    if (det == 0.0f || !isfinite(det))
        return false;
    float inv = 1.0f / det;
    rt_vec3 s = rt_sub(org, v0);
    float u = rt_dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f)
        return false;
    rt_vec3 q = rt_cross(s, e1);
    float v = rt_dot(dir, q) * inv;
    if (v < 0.0f || u + v > 1.0f)
        return false;
    float t = rt_dot(e2, q) * inv;
    if (!(t > tmin && t < tmax))
        return false;
    /* A (near-)degenerate triangle, or a ray within ~1e-5 rad of its plane:
     * det is then rounding noise and u, v, t are garbage (a collinear
     * triangle with non-zero edges would "hit" anywhere). Checked on hits
     * only, so it costs nothing in the common miss path. */
    float a1 = fabsf(e1.x) + fabsf(e1.y) + fabsf(e1.z), a2 = fabsf(e2.x) + fabsf(e2.y) + fabsf(e2.z);
    float ad = fabsf(dir.x) + fabsf(dir.y) + fabsf(dir.z);
    if (!(fabsf(det) / a1 / a2 > 0x1p-16f * ad))
        return false;
    *t_out = t;
    *u_out = u;
    *v_out = v;
    return true;
}

static inline bool rt_intersect_sphere(rt_vec3 org, rt_vec3 dir, rt_vec3 center, float radius, float tmin, float tmax,
                                       float *t_out)
{
    RT_NO_FP_CONTRACT
    rt_vec3 f = rt_sub(org, center);
    float a = rt_dot(dir, dir);
    if (!(a > 0.0f))
        return false;
    float bp = -rt_dot(f, dir);                 /* half of -b */
    rt_vec3 l = rt_madd(f, dir, bp / a);        /* centre to the ray's closest point */
    float disc = a * (radius * radius - rt_dot(l, l));
    if (disc < 0.0f)
        return false;
    float c = rt_dot(f, f) - radius * radius;
    float q = bp + copysignf(sqrtf(disc), bp);
    float t0, t1;
    if (q == 0.0f) {
        t0 = t1 = 0.0f; /* ray starts at the centre of a zero sphere, or tangent at the origin */
    } else {
        t0 = c / q;
        t1 = q / a;
    }
    if (t0 > t1) {
        float tmp = t0; t0 = t1; t1 = tmp;
    }
    if (t0 > tmin && t0 < tmax) { *t_out = t0; return true; }
    if (t1 > tmin && t1 < tmax) { *t_out = t1; return true; }
    return false;
}

static inline bool rt_intersect_quad(rt_vec3 org, rt_vec3 dir, rt_vec3 p, rt_vec3 eu, rt_vec3 ev, float tmin,
                                     float tmax, float *t_out, float *s_out, float *r_out)
{
    RT_NO_FP_CONTRACT
    rt_vec3 n = rt_cross(eu, ev);
    float nn = rt_dot(n, n);
    float denom = rt_dot(n, dir);
    if (denom == 0.0f || !(nn > 0.0f))
        return false;
    float t = rt_dot(n, rt_sub(p, org)) / denom;
    if (!(t > tmin && t < tmax))
        return false;
    rt_vec3 w = rt_sub(rt_madd(org, dir, t), p);
    float s = rt_dot(n, rt_cross(w, ev)) / nn;
    if (s < 0.0f || s > 1.0f)
        return false;
    float r = rt_dot(n, rt_cross(eu, w)) / nn;
    if (r < 0.0f || r > 1.0f)
        return false;
    /* as for triangles: edges (nearly) parallel, or a grazing ray, make the
     * numbers above rounding noise; such hits do not count */
    float nd = fabsf(n.x) + fabsf(n.y) + fabsf(n.z), ad = fabsf(dir.x) + fabsf(dir.y) + fabsf(dir.z);
    if (!(nn / rt_dot(eu, eu) / rt_dot(ev, ev) > 0x1p-32f) || !(fabsf(denom) / nd > 0x1p-16f * ad))
        return false;
    *t_out = t;
    *s_out = s;
    *r_out = r;
    return true;
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
