/* rt/accel/intersect.h - the ray-primitive tests (rays and hits are in
 * ray.h, which this includes).
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

#include "rt/accel/ray.h"
#include "rt/base/vec.h"

/* The tests below must round the same wherever they are compiled (the
 * kd-tree's 8-wide leaf test reproduces them bit for bit): no fused
 * multiply-adds, see RT_NO_FP_CONTRACT in vec.h. */
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

#endif
