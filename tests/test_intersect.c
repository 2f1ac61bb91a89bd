/* test_intersect.c - the ray-primitive tests of intersect.h against
 * hand-computed cases: exact t (the inputs are chosen so that every step of
 * the watertight triangle test, the sphere quadratic and the quad projection is exact in
 * float), misses, edges and tangents, rays from inside and from the
 * surface, tmin/tmax clipping, non-unit directions, degenerate shapes; and
 * rt_offset_ray_origin at three scene scales.
 */
#include "test_util.h"

#include "rt/accel/intersect.h"

static bool tri(rt_vec3 o, rt_vec3 d, rt_vec3 a, rt_vec3 b, rt_vec3 c, float tmin, float tmax, float *t, float *u,
                float *v)
{
    return rt_intersect_triangle(o, d, a, b, c, tmin, tmax, t, u, v);
}

static const rt_vec3 A = {0, 0, 0}, B = {1, 0, 0}, C = {0, 1, 0};

/* ------------------------------------------------------------ triangle */

static void test_triangle_hit(void **state)
{
    (void)state;
    float t, u, v;
    assert_true(tri(rt_v3(0.25f, 0.25f, -1), rt_v3(0, 0, 1), A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(t == 1.0f && u == 0.25f && v == 0.25f);
    /* two-sided: from the other side */
    assert_true(tri(rt_v3(0.25f, 0.5f, 3), rt_v3(0, 0, -1), A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(t == 3.0f && u == 0.25f && v == 0.5f);
    /* non-unit direction: t is in units of |dir| */
    assert_true(tri(rt_v3(0.25f, 0.25f, -1), rt_v3(0, 0, 4), A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(t == 0.25f && u == 0.25f && v == 0.25f);
    /* oblique: from (0,0,-2) towards (0.5, 0.25, 0), t = 1 at the target */
    assert_true(tri(rt_v3(0, 0, -2), rt_v3(0.5f, 0.25f, 2), A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(t == 1.0f && u == 0.5f && v == 0.25f);
    /* a triangle off the origin, t = 5 */
    rt_vec3 a = rt_v3(10, 20, 30), b = rt_v3(12, 20, 30), c = rt_v3(10, 24, 30);
    assert_true(tri(rt_v3(11, 21, 25), rt_v3(0, 0, 1), a, b, c, 0, INFINITY, &t, &u, &v));
    assert_true(t == 5.0f && u == 0.5f && v == 0.25f);
}

static void test_triangle_miss_and_edges(void **state)
{
    (void)state;
    float t = -1, u, v;
    rt_vec3 d = rt_v3(0, 0, 1);
    assert_false(tri(rt_v3(2, 2, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_false(tri(rt_v3(-0.25f, 0.5f, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_false(tri(rt_v3(0.75f, 0.5f, -1), d, A, B, C, 0, INFINITY, &t, &u, &v)); /* u + v > 1 */
    assert_true(t == -1.0f); /* outputs untouched on a miss */
    /* behind the origin */
    assert_false(tri(rt_v3(0.25f, 0.25f, 1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    /* the edges and corners are inside (closed triangle) */
    assert_true(tri(rt_v3(0.5f, 0, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(t == 1.0f && u == 0.5f && v == 0.0f);
    assert_true(tri(rt_v3(0, 0.5f, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(u == 0.0f && v == 0.5f);
    assert_true(tri(rt_v3(0.5f, 0.5f, -1), d, A, B, C, 0, INFINITY, &t, &u, &v)); /* hypotenuse */
    assert_true(u + v == 1.0f);
    assert_true(tri(rt_v3(0, 0, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(u == 0.0f && v == 0.0f);
    assert_true(tri(rt_v3(1, 0, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_true(u == 1.0f && v == 0.0f);
    /* just outside an edge */
    assert_false(tri(rt_v3(0.5f, -1e-6f, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_false(tri(rt_v3(-1e-6f, 0.5f, -1), d, A, B, C, 0, INFINITY, &t, &u, &v));
    /* grazing: rays in the triangle's plane, along and across an edge, never hit */
    assert_false(tri(rt_v3(-1, 0, 0), rt_v3(1, 0, 0), A, B, C, 0, INFINITY, &t, &u, &v));
    assert_false(tri(rt_v3(0.25f, -1, 0), rt_v3(0, 1, 0), A, B, C, 0, INFINITY, &t, &u, &v));
    assert_false(tri(rt_v3(0.25f, 0.25f, 0), rt_v3(1, 1, 0), A, B, C, -INFINITY, INFINITY, &t, &u, &v));
    /* zero direction */
    assert_false(tri(rt_v3(0.25f, 0.25f, -1), rt_v3(0, 0, 0), A, B, C, 0, INFINITY, &t, &u, &v));
}

static void test_triangle_interval(void **state)
{
    (void)state;
    float t, u, v;
    rt_vec3 o = rt_v3(0.25f, 0.25f, -1), d = rt_v3(0, 0, 1);
    /* (tmin, tmax) is open at both ends */
    assert_false(tri(o, d, A, B, C, 0, 1.0f, &t, &u, &v));
    assert_true(tri(o, d, A, B, C, 0, nextafterf(1.0f, 2.0f), &t, &u, &v));
    assert_false(tri(o, d, A, B, C, 1.0f, INFINITY, &t, &u, &v));
    assert_true(tri(o, d, A, B, C, nextafterf(1.0f, 0.0f), INFINITY, &t, &u, &v));
    assert_false(tri(o, d, A, B, C, 0, 0.5f, &t, &u, &v));
    /* a ray starting on the triangle: t = 0 is not in (0, inf), nor in (1e-4, inf) */
    assert_false(tri(rt_v3(0.25f, 0.25f, 0), d, A, B, C, 0, INFINITY, &t, &u, &v));
    assert_false(tri(rt_v3(0.25f, 0.25f, 0), d, A, B, C, 1e-4f, INFINITY, &t, &u, &v));
    /* but a negative tmin finds it */
    assert_true(tri(rt_v3(0.25f, 0.25f, 0), d, A, B, C, -1.0f, INFINITY, &t, &u, &v));
    assert_true(t == 0.0f);
    /* NaN bounds: nothing */
    assert_false(tri(o, d, A, B, C, NAN, INFINITY, &t, &u, &v));
    assert_false(tri(o, d, A, B, C, 0, NAN, &t, &u, &v));
}

static void test_triangle_degenerate(void **state)
{
    (void)state;
    float t, u, v;
    test_rng r = {42};
    /* zero-area triangles: a point, a zero edge, collinear vertices (whose
     * determinant is rounding noise, not zero), non-finite vertices */
    rt_vec3 degen[][3] = {
        {{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}},
        {{0, 0, 0}, {0, 0, 0}, {1, 1, 0}},
        {{0, 0, 0}, {0.5f, 0.5f, 0.5f}, {1, 1, 1}},
        {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}},
        {{0.1f, 0.2f, 0.3f}, {0.4f, 0.5f, 0.6f}, {0.7f, 0.8f, 0.9f}},
        {{-1, 3, 7}, {0.3f, 3.3f, 6.9f}, {2.9f, 3.9f, 6.7f}}, /* (1.3, 0.3, -0.1) * 1 and * 3, rounded */
        {{NAN, 0, 0}, {1, 0, 0}, {0, 1, 0}},
        {{INFINITY, 0, 0}, {1, 0, 0}, {0, 1, 0}},
    };
    for (size_t k = 0; k < sizeof degen / sizeof degen[0]; k++)
        for (int i = 0; i < 20000; i++) {
            rt_vec3 o = rt_v3(test_rng_float(&r) * 4 - 2, test_rng_float(&r) * 4 - 2, test_rng_float(&r) * 4 - 2);
            rt_vec3 target = rt_lerp3(degen[k][0], degen[k][2], test_rng_float(&r));
            rt_vec3 d = i % 2 ? rt_sub(target, o)
                              : rt_v3(test_rng_float(&r) - 0.5f, test_rng_float(&r) - 0.5f, test_rng_float(&r) - 0.5f);
            if (tri(o, d, degen[k][0], degen[k][1], degen[k][2], -INFINITY, INFINITY, &t, &u, &v))
                fail_msg("degenerate triangle %zu hit at t %g", k, (double)t);
        }
}

static void test_triangle_sliver_tips(void **state)
{
    (void)state;
    /* Slivers 1:300 to 1:30000 at scales 1e-3 to 1e3, rays from 2 scene
     * units away aimed at points just beyond a tip along the sliver's axis
     * (outside the triangle), and at points on it. A hit must lie in the
     * triangle's bounding box widened by 2^-20 of the scene (the kd-tree
     * widens its cells by 2^-18, and a hit outside every cell holding the
     * triangle is one brute force finds and the tree cannot). Moeller-
     * Trumbore failed this: its u and v numerators are triple products with
     * s = org - v0, whose rounding (about 2^-24 |s| each, independent for u
     * and v) opens the tip of a sliver of angle a by that over a, up to
     * 1e-4 of the scene beyond the vertex at 1:300. */
    static const float ratios[] = {300.0f, 3000.0f, 30000.0f};
    static const float scales[] = {1e-3f, 1.0f, 1e3f};
    test_rng r = {77};
    for (int si = 0; si < 3; si++)
        for (int ri = 0; ri < 3; ri++) {
            float k = scales[si];
            int hits = 0;
            for (int i = 0; i < 4000; i++) {
                rt_vec3 a = rt_scale(rt_v3(test_rng_float(&r), test_rng_float(&r), test_rng_float(&r)), k);
                rt_vec3 axis = rt_normalize(rt_v3(test_rng_float(&r) - 0.5f, test_rng_float(&r) - 0.5f,
                                                  test_rng_float(&r) - 0.5f));
                rt_vec3 side = rt_normalize(rt_cross(axis, rt_v3(0.3f, 0.5f, 0.8f)));
                rt_vec3 mid = rt_add(a, rt_scale(axis, 0.3f * k));
                rt_vec3 b = rt_add(mid, rt_scale(side, 0.3f * k / ratios[ri]));
                rt_vec3 c = rt_sub(mid, rt_scale(side, 0.3f * k / ratios[ri]));
                /* beyond the tip a (outside), or inside along the axis */
                float along = i % 4 == 0 ? 0.5f : -(1e-6f + 1e-4f * test_rng_float(&r));
                rt_vec3 q = rt_add(a, rt_scale(axis, along * 0.3f * k));
                rt_vec3 o = rt_add(q, rt_scale(rt_v3(test_rng_float(&r) * 2 - 1, test_rng_float(&r) * 2 - 1,
                                                     test_rng_float(&r) * 2 - 1), 2.0f * k));
                rt_vec3 d = rt_sub(q, o);
                float t, u, v;
                if (!tri(o, d, a, b, c, 0.0f, INFINITY, &t, &u, &v))
                    continue;
                hits++;
                rt_vec3 p = rt_add(o, rt_scale(d, t));
                float tol = 0x1p-20f * 2.0f * k;
                rt_box bb = rt_box_point(rt_box_point(rt_box_point(rt_box_empty(), a), b), c);
                if (p.x < bb.lo.x - tol || p.y < bb.lo.y - tol || p.z < bb.lo.z - tol || p.x > bb.hi.x + tol ||
                    p.y > bb.hi.y + tol || p.z > bb.hi.z + tol)
                    fail_msg("1:%g sliver at scale %g: hit %g of the scene outside its box (along %g)",
                             (double)ratios[ri], (double)k,
                             (double)(fmaxf(rt_max3(rt_sub(bb.lo, p)), rt_max3(rt_sub(p, bb.hi))) / k),
                             (double)along);
            }
            assert_true(hits >= 100); /* rays aimed inside hit (thinner slivers are more often "grazing": no hit) */
        }
}

/* -------------------------------------------------------------- sphere */

static void test_sphere(void **state)
{
    (void)state;
    float t = -1;
    rt_vec3 c = rt_v3(0, 0, 0);
    /* from outside: near root */
    assert_true(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    assert_true(t == 4.0f);
    /* non-unit direction */
    assert_true(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 2), c, 1.0f, 0, INFINITY, &t));
    assert_true(t == 2.0f);
    /* off-centre sphere, radius 2, along -x: t = 10 - 3 - 2 = 5 */
    assert_true(rt_intersect_sphere(rt_v3(10, 1, 1), rt_v3(-1, 0, 0), rt_v3(3, 1, 1), 2.0f, 0, INFINITY, &t));
    assert_true(t == 5.0f);
    /* from inside: the far root */
    assert_true(rt_intersect_sphere(c, rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    assert_true(t == 1.0f);
    assert_true(rt_intersect_sphere(rt_v3(0, 0, 0.5f), rt_v3(0, 0, -1), c, 1.0f, 0, INFINITY, &t));
    assert_true(t == 1.5f);
    /* tmax clipping: the near root excluded, then the far one */
    assert_false(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 1), c, 1.0f, 0, 4.0f, &t));
    assert_true(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 1), c, 1.0f, 4.0f, INFINITY, &t));
    assert_true(t == 6.0f);
    assert_false(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 1), c, 1.0f, 6.0f, INFINITY, &t));
    /* miss, and behind the origin */
    assert_false(rt_intersect_sphere(rt_v3(0, 2, -5), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    assert_false(rt_intersect_sphere(rt_v3(0, 0, 5), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    /* tangent: discriminant exactly 0, one (double) root */
    assert_true(rt_intersect_sphere(rt_v3(1, 0, -5), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    assert_true(t == 5.0f);
    assert_false(rt_intersect_sphere(rt_v3(1.0001f, 0, -5), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    /* starting on the surface, going in: t = 0 is excluded, the far side is found */
    assert_true(rt_intersect_sphere(rt_v3(0, 0, -1), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    assert_true(t == 2.0f);
    assert_true(rt_intersect_sphere(rt_v3(0, 0, -1), rt_v3(0, 0, 1), c, 1.0f, 1e-4f, INFINITY, &t));
    assert_true(t == 2.0f);
    /* starting on the surface, going out: nothing */
    assert_false(rt_intersect_sphere(rt_v3(0, 0, -1), rt_v3(0, 0, -1), c, 1.0f, 0, INFINITY, &t));
    /* far away: the robust form keeps t accurate (the naive one loses digits) */
    assert_true(rt_intersect_sphere(rt_v3(0, 0, -1e4f), rt_v3(0, 0, 1), c, 1.0f, 0, INFINITY, &t));
    assert_true(fabsf(t - 9999.0f) <= 1e-3f);
    /* a small sphere far from the origin of the ray, oblique */
    rt_vec3 sc = rt_v3(100, 200, 300), o = rt_v3(0, 0, 0);
    rt_vec3 d = rt_normalize(sc);
    assert_true(rt_intersect_sphere(o, d, sc, 0.01f, 0, INFINITY, &t));
    assert_true(fabsf(t - (rt_length(sc) - 0.01f)) <= 1e-3f);
    /* zero direction, NaN radius */
    assert_false(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 0), c, 1.0f, 0, INFINITY, &t));
    assert_false(rt_intersect_sphere(rt_v3(0, 0, -5), rt_v3(0, 0, 1), c, NAN, 0, INFINITY, &t));
}

/* ---------------------------------------------------------------- quad */

static void test_quad(void **state)
{
    (void)state;
    float t = -1, s, r;
    rt_vec3 p = rt_v3(0, 0, 0), u = rt_v3(2, 0, 0), v = rt_v3(0, 1, 0);
    assert_true(rt_intersect_quad(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 1), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_true(t == 1.0f && s == 0.25f && r == 0.5f);
    /* from behind, non-unit direction */
    assert_true(rt_intersect_quad(rt_v3(1, 0.25f, 4), rt_v3(0, 0, -2), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_true(t == 2.0f && s == 0.5f && r == 0.25f);
    /* edges and corners count */
    assert_true(rt_intersect_quad(rt_v3(2, 0.5f, -1), rt_v3(0, 0, 1), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_true(s == 1.0f && r == 0.5f);
    assert_true(rt_intersect_quad(rt_v3(2, 1, -1), rt_v3(0, 0, 1), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_true(s == 1.0f && r == 1.0f);
    /* outside in s, in t, behind, parallel */
    assert_false(rt_intersect_quad(rt_v3(2.5f, 0.5f, -1), rt_v3(0, 0, 1), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_false(rt_intersect_quad(rt_v3(0.5f, 1.5f, -1), rt_v3(0, 0, 1), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_false(rt_intersect_quad(rt_v3(0.5f, 0.5f, 1), rt_v3(0, 0, 1), p, u, v, 0, INFINITY, &t, &s, &r));
    assert_false(rt_intersect_quad(rt_v3(-1, 0.5f, 0), rt_v3(1, 0, 0), p, u, v, 0, INFINITY, &t, &s, &r));
    /* interval */
    assert_false(rt_intersect_quad(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 1), p, u, v, 0, 1.0f, &t, &s, &r));
    assert_false(rt_intersect_quad(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 1), p, u, v, 1.0f, INFINITY, &t, &s, &r));
    /* a skewed parallelogram: p + 0.5 u + 0.5 v */
    rt_vec3 p2 = rt_v3(1, 1, 1), u2 = rt_v3(2, 0, 0), v2 = rt_v3(1, 2, 0);
    rt_vec3 target = rt_add(p2, rt_add(rt_scale(u2, 0.5f), rt_scale(v2, 0.5f)));
    assert_true(rt_intersect_quad(rt_add(target, rt_v3(0, 0, -3)), rt_v3(0, 0, 1), p2, u2, v2, 0, INFINITY, &t, &s,
                                  &r));
    assert_true(t == 3.0f && s == 0.5f && r == 0.5f);
    /* degenerate: parallel edges, a zero edge */
    assert_false(rt_intersect_quad(rt_v3(0.5f, 0, -1), rt_v3(0, 0, 1), p, u, rt_v3(4, 0, 0), 0, INFINITY, &t, &s, &r));
    assert_false(rt_intersect_quad(rt_v3(0.5f, 0, -1), rt_v3(0, 0, 1), p, u, rt_v3(0, 0, 0), 0, INFINITY, &t, &s, &r));
    assert_false(rt_intersect_quad(rt_v3(0.5f, 0.5f, -1), rt_v3(0.1f, 0.2f, 1), p, rt_v3(1, 1, 1), rt_v3(3, 3, 3), 0,
                                   INFINITY, &t, &s, &r));
}

/* ----------------------------------------------------- offset origins */

static void test_offset_ray_origin(void **state)
{
    (void)state;
    static const float scales[] = {1e-3f, 1.0f, 1e3f};
    test_rng rng = {7};
    for (int si = 0; si < 3; si++) {
        float scale = scales[si];
        for (int i = 0; i < 3000; i++) {
            /* points across the scene, some near the origin, some on an axis plane */
            float m = i % 3 == 0 ? 0.01f : 1.0f;
            rt_vec3 p = rt_scale(rt_v3(test_rng_float(&rng) * 2 - 1, test_rng_float(&rng) * 2 - 1,
                                       test_rng_float(&rng) * 2 - 1),
                                 scale * m);
            if (i % 7 == 0)
                p.y = 0.0f;
            rt_vec3 n = rt_normalize(
                rt_v3(test_rng_float(&rng) * 2 - 1, test_rng_float(&rng) * 2 - 1, test_rng_float(&rng) * 2 - 1));
            if (i % 11 == 0)
                n = rt_v3(0, i % 2 ? 1.0f : -1.0f, 0);
            rt_vec3 q = rt_offset_ray_origin(p, n, scale);
            rt_vec3 dq = rt_sub(q, p);
            float dist = rt_length(dq), ref = fmaxf(scale, rt_max3(rt_v3(fabsf(p.x), fabsf(p.y), fabsf(p.z))));
            /* on the side of n, moved a little but not too little */
            assert_true(rt_dot(dq, n) > 0.0f);
            assert_true(dist <= 1e-4f * ref);
            assert_true(dist >= 1e-7f * scale);
        }
        /* what it is for: a ray leaving a triangle from the offset origin, to
         * the normal's side, never hits that triangle again */
        rt_vec3 a = rt_scale(rt_v3(-1, -0.8f, 0.3f), scale), b = rt_scale(rt_v3(1.2f, -0.5f, -0.2f), scale),
                c = rt_scale(rt_v3(0.1f, 1.1f, 0.4f), scale);
        rt_vec3 e1 = rt_sub(b, a), e2 = rt_sub(c, a), n = rt_normalize(rt_cross(e1, e2));
        for (int i = 0; i < 3000; i++) {
            float bu = test_rng_float(&rng), bv = test_rng_float(&rng) * (1.0f - bu);
            rt_vec3 hit = rt_add(a, rt_add(rt_scale(e1, bu), rt_scale(e2, bv)));
            rt_vec3 side = i % 2 ? n : rt_neg(n);
            rt_vec3 o = rt_offset_ray_origin(hit, side, scale);
            rt_vec3 d = rt_v3(test_rng_float(&rng) * 2 - 1, test_rng_float(&rng) * 2 - 1, test_rng_float(&rng) * 2 - 1);
            if (rt_dot(d, side) < 0.0f)
                d = rt_sub(d, rt_scale(side, 2.0f * rt_dot(d, side)));
            float t, u, v;
            if (rt_intersect_triangle(o, d, a, b, c, 0.0f, INFINITY, &t, &u, &v))
                fail_msg("scale %g: self-intersection at t %g", (double)scale, (double)t);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_hit),      cmocka_unit_test(test_triangle_miss_and_edges),
        cmocka_unit_test(test_triangle_interval), cmocka_unit_test(test_triangle_degenerate),
        cmocka_unit_test(test_sphere),            cmocka_unit_test(test_quad),
        cmocka_unit_test(test_offset_ray_origin), cmocka_unit_test(test_triangle_sliver_tips),
    };
    return cmocka_run_group_tests_name("intersect", tests, NULL, NULL);
}
