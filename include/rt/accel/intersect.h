/* rt/accel/intersect.h - the ray-primitive tests (rays and hits are in
 * ray.h, which this includes).
 *
 * All tests are two-sided and return the nearest hit with t in the open
 * interval (tmin, tmax). They are `static inline` because the kd-tree's leaf
 * loops call them millions of times a second.
 *
 *   rt_ray r = rt_ray_make(origin, dir, 0.0f, INFINITY);
 *   float t, u, v;
 *   if (rt_intersect_triangle(r.org, r.dir, v0, v1, v2, r.tmin, r.tmax, &t, &u, &v)) ...
 *   rt_tri_ray tr = rt_tri_ray_make(r.org, r.dir);   // once per ray, then per triangle:
 *   if (rt_intersect_triangle_ray(&tr, v0, v1, v2, r.tmin, r.tmax, &t, &u, &v)) ...
 *   rt_quad_prep q = rt_quad_prepare(p, eu, ev);     // once per quad, then per ray:
 *   if (rt_intersect_quad_prepared(r.org, r.dir, &q, r.tmin, r.tmax, &t, &u, &v)) ...
 *
 * Triangle: watertight, Woop, Benthin and Wald (2013), "Watertight
 * Ray/Triangle Intersection", JCGT 2(1): the vertices are moved to the
 * ray's origin and sheared so that the ray is the +z axis (the shear made
 * once per ray, rt_tri_ray), then the three 2D edge functions decide
 * inside or out (recomputed in double when one rounds to zero). Each edge
 * function depends only on its two vertices, so a ray never passes between
 * two triangles that share an edge, and a hit never lies outside the
 * triangle by more than the rounding of its vertices relative to the ray
 * (Moeller-Trumbore, used before, put hits up to 1e-4 of the scene beyond
 * the tips of slivers thinner than 1:300). Two-sided; (u, v) are the
 * barycentrics of v1 and v2. Degenerate triangles (zero area, or collinear
 * vertices up to rounding) never hit, and neither does a ray within about
 * 1e-5 rad of a triangle's or quad's plane: there the determinant is
 * rounding noise and the computed hit could lie anywhere on the ray.
 * Sphere: the numerically robust quadratic of Haines et al., "Precision
 * Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7.
 * Quad (parallelogram p + s*u + t*v): plane hit, then (s, t) by projection;
 * rt_intersect_quad is rt_quad_prepare (the normal and the degeneracy
 * guard, which do not depend on the ray: the kd-tree keeps them) followed
 * by rt_intersect_quad_prepared, so both give the same bits.
 */
#ifndef RT_INTERSECT_H
#define RT_INTERSECT_H

#include "rt/accel/ray.h"
#include "rt/base/vec.h"

/* The tests below must round the same wherever they are compiled (the
 * kd-tree's 8-wide leaf test reproduces them bit for bit): no fused
 * multiply-adds, see RT_NO_FP_CONTRACT in vec.h. */

/* A ray prepared for the watertight triangle test: kz is the axis of the
 * direction's largest component, kx and ky the next two (cyclically), and
 * (sx, sy, sz) = (d[kx], d[ky], 1) / d[kz]: the shear that maps the ray to
 * the +kz axis through the origin. Made once per ray. */
typedef struct rt_tri_ray {
    rt_vec3 org, dir;
    int kx, ky, kz;
    float sx, sy, sz;
    float okx, oky, okz; /* org[kx], org[ky], org[kz] */
    float adz, ad;       /* |d[kz]|, |d.x| + |d.y| + |d.z| */
} rt_tri_ray;

static inline float rt__axis(rt_vec3 a, int k) { return k == 0 ? a.x : k == 1 ? a.y : a.z; }

/* The same, written in place (the kd-tree's ray set-up: no copy). */
static inline void rt_tri_ray_init(rt_tri_ray *rp, rt_vec3 org, rt_vec3 dir)
{
    RT_NO_FP_CONTRACT
    rt_tri_ray r;
    float ax = fabsf(dir.x), ay = fabsf(dir.y), az = fabsf(dir.z);
    r.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    r.kx = r.kz == 2 ? 0 : r.kz + 1;
    r.ky = r.kx == 2 ? 0 : r.kx + 1;
    r.org = org;
    r.dir = dir;
    r.sz = 1.0f / rt__axis(dir, r.kz);
    r.sx = rt__axis(dir, r.kx) * r.sz;
    r.sy = rt__axis(dir, r.ky) * r.sz;
    r.okx = rt__axis(org, r.kx);
    r.oky = rt__axis(org, r.ky);
    r.okz = rt__axis(org, r.kz);
    r.adz = fabsf(rt__axis(dir, r.kz));
    r.ad = ax + ay + az;
    *rp = r;
}

static inline rt_tri_ray rt_tri_ray_make(rt_vec3 org, rt_vec3 dir)
{
    rt_tri_ray r;
    rt_tri_ray_init(&r, org, dir);
    return r;
}

/* The triangle (a, b, c) against a prepared ray. */
static inline bool rt_intersect_triangle_ray(const rt_tri_ray *r, rt_vec3 a, rt_vec3 b, rt_vec3 c, float tmin,
                                             float tmax, float *t_out, float *u_out, float *v_out)
{
    RT_NO_FP_CONTRACT
    /* the vertices relative to the origin, as arrays (indexed by axis) */
    const float A[3] = {a.x - r->org.x, a.y - r->org.y, a.z - r->org.z},
                B[3] = {b.x - r->org.x, b.y - r->org.y, b.z - r->org.z},
                C[3] = {c.x - r->org.x, c.y - r->org.y, c.z - r->org.z};
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    float Akz = A[kz], Bkz = B[kz], Ckz = C[kz];
    float Ax = A[kx] - r->sx * Akz, Ay = A[ky] - r->sy * Akz;
    float Bx = B[kx] - r->sx * Bkz, By = B[ky] - r->sy * Bkz;
    float Cx = C[kx] - r->sx * Ckz, Cy = C[ky] - r->sy * Ckz;
    float U = Cx * By - Cy * Bx, V = Ax * Cy - Ay * Cx, W = Bx * Ay - By * Ax;
    if (U == 0.0f || V == 0.0f || W == 0.0f) { /* on an edge up to rounding: decide exactly */
        U = (float)((double)Cx * (double)By - (double)Cy * (double)Bx);
        V = (float)((double)Ax * (double)Cy - (double)Ay * (double)Cx);
        W = (float)((double)Bx * (double)Ay - (double)By * (double)Ax);
    }
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f))
        return false;
    float det = U + V + W;
    if (det == 0.0f || !isfinite(det))
        return false;
    float T = U * (r->sz * Akz) + V * (r->sz * Bkz) + W * (r->sz * Ckz);
    float inv = 1.0f / det;
    float t = T * inv;
    if (!(t > tmin && t < tmax))
        return false;
    /* A (near-)degenerate triangle, or a ray within ~1e-5 rad of its plane:
     * det is then rounding noise and t is garbage (a collinear triangle
     * would "hit" anywhere). |det d[kz]| is |(b - a) x (c - a) . d| up to
     * rounding. Checked on hits only. */
    rt_vec3 e1 = rt_sub(b, a), e2 = rt_sub(c, a);
    float a1 = fabsf(e1.x) + fabsf(e1.y) + fabsf(e1.z), a2 = fabsf(e2.x) + fabsf(e2.y) + fabsf(e2.z);
    if (!(fabsf(det) * r->adz / a1 / a2 > 0x1p-16f * r->ad))
        return false;
    *t_out = t;
    *u_out = V * inv;
    *v_out = W * inv;
    return true;
}

static inline bool rt_intersect_triangle(rt_vec3 org, rt_vec3 dir, rt_vec3 a, rt_vec3 b, rt_vec3 c, float tmin,
                                         float tmax, float *t_out, float *u_out, float *v_out)
{
    rt_tri_ray r = rt_tri_ray_make(org, dir);
    return rt_intersect_triangle_ray(&r, a, b, c, tmin, tmax, t_out, u_out, v_out);
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

/* A quad (parallelogram p + s eu + r ev, s and r in [0, 1]) prepared for
 * rt_intersect_quad_prepared: what the test computes from the quad alone,
 * made once (the kd-tree keeps one per quad). */
typedef struct rt_quad_prep {
    rt_vec3 p, eu, ev;
    rt_vec3 n;   /* eu x ev */
    float nn;    /* n . n */
    float nd;    /* |n.x| + |n.y| + |n.z| */
    bool usable; /* n . n > 0 and not degenerate by the guard below */
} rt_quad_prep;

static inline rt_quad_prep rt_quad_prepare(rt_vec3 p, rt_vec3 eu, rt_vec3 ev)
{
    RT_NO_FP_CONTRACT
    rt_quad_prep q;
    q.p = p, q.eu = eu, q.ev = ev;
    q.n = rt_cross(eu, ev);
    q.nn = rt_dot(q.n, q.n);
    q.nd = fabsf(q.n.x) + fabsf(q.n.y) + fabsf(q.n.z);
    /* edges (nearly) parallel make the numbers below rounding noise */
    q.usable = q.nn > 0.0f && q.nn / rt_dot(eu, eu) / rt_dot(ev, ev) > 0x1p-32f;
    return q;
}

/* The quad against a ray: t in (tmin, tmax), (s, r) the hit's parameters. */
static inline bool rt_intersect_quad_prepared(rt_vec3 org, rt_vec3 dir, const rt_quad_prep *q, float tmin,
                                              float tmax, float *t_out, float *s_out, float *r_out)
{
    RT_NO_FP_CONTRACT
    if (!q->usable)
        return false;
    rt_vec3 n = q->n;
    float denom = rt_dot(n, dir);
    if (denom == 0.0f)
        return false;
    float t = rt_dot(n, rt_sub(q->p, org)) / denom;
    if (!(t > tmin && t < tmax))
        return false;
    rt_vec3 w = rt_sub(rt_madd(org, dir, t), q->p);
    float s = rt_dot(n, rt_cross(w, q->ev)) / q->nn;
    if (s < 0.0f || s > 1.0f)
        return false;
    float r = rt_dot(n, rt_cross(q->eu, w)) / q->nn;
    if (r < 0.0f || r > 1.0f)
        return false;
    /* as for triangles: a grazing ray makes the numbers above rounding
     * noise; such hits do not count */
    float ad = fabsf(dir.x) + fabsf(dir.y) + fabsf(dir.z);
    if (!(fabsf(denom) / q->nd > 0x1p-16f * ad))
        return false;
    *t_out = t;
    *s_out = s;
    *r_out = r;
    return true;
}

static inline bool rt_intersect_quad(rt_vec3 org, rt_vec3 dir, rt_vec3 p, rt_vec3 eu, rt_vec3 ev, float tmin,
                                     float tmax, float *t_out, float *s_out, float *r_out)
{
    rt_quad_prep q = rt_quad_prepare(p, eu, ev);
    return rt_intersect_quad_prepared(org, dir, &q, tmin, tmax, t_out, s_out, r_out);
}

#endif
