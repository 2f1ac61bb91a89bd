/* rt/vec.h - small vector maths for the renderer.
 *
 * Everything here is `static inline`: these functions sit on every hot path
 * (intersection, shading, sampling), and an out-of-line vector add once cost
 * another C renderer over 40% of its render time. Types are plain structs of
 * floats passed by value; the compiler keeps them in registers.
 *
 *   rt_vec3 a = rt_v3(1, 2, 3);
 *   float   d = rt_dot(a, rt_normalize(b));
 */
#ifndef RT_VEC_H
#define RT_VEC_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#define RT_PI 3.14159265358979323846f
#define RT_INV_PI 0.31830988618379067154f

/* No fused multiply-adds in the functions marked with this: their results
 * must be the same bits wherever they are inlined (the kd-tree reproduces
 * the intersection tests lane by lane in SIMD). GCC contracts nothing under
 * -std=c11; clang contracts within expressions unless told. */
#if defined(__clang__)
#define RT_NO_FP_CONTRACT _Pragma("clang fp contract(off)")
#else
#define RT_NO_FP_CONTRACT
#endif

typedef struct rt_vec2 { float x, y; } rt_vec2;
typedef struct rt_vec3 { float x, y, z; } rt_vec3;
typedef struct rt_vec4 { float x, y, z, w; } rt_vec4;

static inline rt_vec2 rt_v2(float x, float y) { rt_vec2 r = {x, y}; return r; }
static inline rt_vec3 rt_v3(float x, float y, float z) { rt_vec3 r = {x, y, z}; return r; }
static inline rt_vec3 rt_v3s(float s) { rt_vec3 r = {s, s, s}; return r; }
static inline rt_vec4 rt_v4(float x, float y, float z, float w) { rt_vec4 r = {x, y, z, w}; return r; }

static inline rt_vec3 rt_add(rt_vec3 a, rt_vec3 b) { return rt_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline rt_vec3 rt_sub(rt_vec3 a, rt_vec3 b) { return rt_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline rt_vec3 rt_mul(rt_vec3 a, rt_vec3 b) { return rt_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline rt_vec3 rt_div(rt_vec3 a, rt_vec3 b) { return rt_v3(a.x / b.x, a.y / b.y, a.z / b.z); }
static inline rt_vec3 rt_scale(rt_vec3 a, float s) { return rt_v3(a.x * s, a.y * s, a.z * s); }
static inline rt_vec3 rt_neg(rt_vec3 a) { return rt_v3(-a.x, -a.y, -a.z); }
/* a + b * s, the ray-point form */
static inline rt_vec3 rt_madd(rt_vec3 a, rt_vec3 b, float s)
{
    RT_NO_FP_CONTRACT
    return rt_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}

static inline float rt_dot(rt_vec3 a, rt_vec3 b)
{
    RT_NO_FP_CONTRACT
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline rt_vec3 rt_cross(rt_vec3 a, rt_vec3 b)
{
    RT_NO_FP_CONTRACT
    return rt_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float rt_length2(rt_vec3 a) { return rt_dot(a, a); }
static inline float rt_length(rt_vec3 a) { return sqrtf(rt_dot(a, a)); }
/* Normalises a; a zero vector stays zero instead of becoming NaN. */
static inline rt_vec3 rt_normalize(rt_vec3 a)
{
    float l2 = rt_dot(a, a);
    return l2 > 0.0f ? rt_scale(a, 1.0f / sqrtf(l2)) : a;
}
/* fmaxf / fminf inline: GCC calls libm for them (without -ffinite-math-only),
 * a call per use on the hot path. The same results as glibc's x86-64 ones,
 * bit for bit: a NaN operand loses to a number, and of two equal operands
 * (+0 and -0) the second is returned, as its maxss / minss do. */
static inline float rt_fmaxf(float a, float b) { return (a > b || b != b) ? a : b; }
static inline float rt_fminf(float a, float b) { return (a < b || b != b) ? a : b; }
/* sin and cos of x together, inline (libm's sincosf is a call on the hot
 * path): x = q pi/2 + r with |r| <= pi/4 (Cody-Waite reduction, pi/2 in
 * three parts as Cephes' sinf splits pi/4, the first two exact in float
 * products for |q| < 2^13), Taylor polynomials to r^9 and r^10 (their
 * truncation error is below 2e-9 there), then the quadrant. Max absolute
 * error 1e-7 against double precision over |x| <= 8 pi (measured 8.3e-8; libm: 6e-8;
 * tests/test_wavefront.c measures it). Plain float arithmetic, no FMA: the
 * same bits on every x86-64 build. */
static inline void rt_sincosf(float x, float *s, float *c)
{
    int q = (int)(x * 0.636619772f + (x >= 0.0f ? 0.5f : -0.5f));
    float k = (float)q;
    float r = ((x - k * 1.5703125f) - k * 4.837512969970703125e-4f) - k * 7.54978995489188216e-8f;
    float r2 = r * r;
    float sp = r + r * r2 * (-1.0f / 6.0f + r2 * (1.0f / 120.0f + r2 * (-1.0f / 5040.0f + r2 * (1.0f / 362880.0f))));
    float cp = 1.0f + r2 * (-0.5f + r2 * (1.0f / 24.0f + r2 * (-1.0f / 720.0f + r2 * (1.0f / 40320.0f +
                                                                                     r2 * (-1.0f / 3628800.0f)))));
    switch (q & 3) {
    case 0: *s = sp; *c = cp; break;
    case 1: *s = cp; *c = -sp; break;
    case 2: *s = -sp; *c = -cp; break;
    default: *s = -cp; *c = sp; break;
    }
}
static inline rt_vec3 rt_vmin(rt_vec3 a, rt_vec3 b) { return rt_v3(rt_fminf(a.x, b.x), rt_fminf(a.y, b.y), rt_fminf(a.z, b.z)); }
static inline rt_vec3 rt_vmax(rt_vec3 a, rt_vec3 b) { return rt_v3(rt_fmaxf(a.x, b.x), rt_fmaxf(a.y, b.y), rt_fmaxf(a.z, b.z)); }
static inline rt_vec3 rt_lerp3(rt_vec3 a, rt_vec3 b, float t) { return rt_madd(rt_scale(a, 1.0f - t), b, t); }
static inline float rt_axis(rt_vec3 a, int axis) { return axis == 0 ? a.x : (axis == 1 ? a.y : a.z); }
static inline float rt_max3(rt_vec3 a) { return rt_fmaxf(a.x, rt_fmaxf(a.y, a.z)); }
static inline float rt_luminance(rt_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline bool rt_finite3(rt_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline float rt_clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }

/* Reflect d about the normal n (both pointing away from the surface for n). */
static inline rt_vec3 rt_reflect(rt_vec3 d, rt_vec3 n) { return rt_sub(d, rt_scale(n, 2.0f * rt_dot(d, n))); }

/* An orthonormal basis around unit n (Duff et al. 2017, "Building an
 * Orthonormal Basis, Revisited", JCGT 6(1)). */
static inline void rt_onb(rt_vec3 n, rt_vec3 *t, rt_vec3 *b)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float bb = n.x * n.y * a;
    *t = rt_v3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    *b = rt_v3(bb, sign + n.y * n.y * a, -n.y);
}

/* Axis-aligned box. An empty box has lo = +inf, hi = -inf. */
typedef struct rt_box { rt_vec3 lo, hi; } rt_box;

static inline rt_box rt_box_empty(void)
{
    rt_box b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    return b;
}
static inline rt_box rt_box_point(rt_box b, rt_vec3 p) { b.lo = rt_vmin(b.lo, p); b.hi = rt_vmax(b.hi, p); return b; }
static inline rt_box rt_box_union(rt_box a, rt_box b) { a.lo = rt_vmin(a.lo, b.lo); a.hi = rt_vmax(a.hi, b.hi); return a; }
static inline bool rt_box_is_empty(rt_box b) { return !(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z); }
static inline float rt_box_area(rt_box b)
{
    rt_vec3 d = rt_sub(b.hi, b.lo);
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}
static inline float rt_box_diagonal(rt_box b) { return rt_box_is_empty(b) ? 0.0f : rt_length(rt_sub(b.hi, b.lo)); }

/* 4x4 row-major affine/projective matrix: m[row][col], points are columns. */
typedef struct rt_mat4 { float m[4][4]; } rt_mat4;

static inline rt_mat4 rt_mat4_identity(void)
{
    rt_mat4 r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    return r;
}
static inline rt_mat4 rt_mat4_mul(rt_mat4 a, rt_mat4 b)
{
    rt_mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j] + a.m[i][3] * b.m[3][j];
    return r;
}
static inline rt_vec3 rt_mat4_point(const rt_mat4 *a, rt_vec3 p)
{
    return rt_v3(a->m[0][0] * p.x + a->m[0][1] * p.y + a->m[0][2] * p.z + a->m[0][3],
                 a->m[1][0] * p.x + a->m[1][1] * p.y + a->m[1][2] * p.z + a->m[1][3],
                 a->m[2][0] * p.x + a->m[2][1] * p.y + a->m[2][2] * p.z + a->m[2][3]);
}
static inline rt_vec3 rt_mat4_vector(const rt_mat4 *a, rt_vec3 v)
{
    return rt_v3(a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
                 a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
                 a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z);
}
/* Determinant of the upper 3x3 (negative: the transform mirrors). */
static inline float rt_mat4_det3(const rt_mat4 *a)
{
    const float(*m)[4] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
/* The matrix that transforms normals: inverse transpose of the upper 3x3,
 * scaled by the determinant's sign only (normals are renormalised anyway).
 * Returns false for a singular matrix. */
static inline bool rt_mat4_normal_matrix(const rt_mat4 *a, rt_mat4 *out)
{
    const float(*m)[4] = a->m;
    rt_mat4 r = rt_mat4_identity();
    /* cofactor matrix = det * inverse transpose */
    r.m[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    r.m[0][1] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    r.m[0][2] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    r.m[1][0] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
    r.m[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
    r.m[1][2] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
    r.m[2][0] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
    r.m[2][1] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
    r.m[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    float det = rt_mat4_det3(a);
    if (!(fabsf(det) > 0.0f) || !isfinite(det))
        return false;
    float s = det < 0.0f ? -1.0f : 1.0f;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r.m[i][j] *= s;
    *out = r;
    return true;
}
/* Translation, rotation (axis-angle about x, y, z in degrees, applied x then y then z) and scale. */
static inline rt_mat4 rt_mat4_translate(rt_vec3 t)
{
    rt_mat4 r = rt_mat4_identity();
    r.m[0][3] = t.x; r.m[1][3] = t.y; r.m[2][3] = t.z;
    return r;
}
static inline rt_mat4 rt_mat4_scale(rt_vec3 s)
{
    rt_mat4 r = rt_mat4_identity();
    r.m[0][0] = s.x; r.m[1][1] = s.y; r.m[2][2] = s.z;
    return r;
}
static inline rt_mat4 rt_mat4_rotate_axis(int axis, float degrees)
{
    float a = degrees * (RT_PI / 180.0f), c = cosf(a), s = sinf(a);
    rt_mat4 r = rt_mat4_identity();
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    r.m[i][i] = c; r.m[i][j] = -s;
    r.m[j][i] = s; r.m[j][j] = c;
    return r;
}
/* Unit quaternion (x, y, z, w) to rotation matrix. */
static inline rt_mat4 rt_mat4_quat(rt_vec4 q)
{
    float x = q.x, y = q.y, z = q.z, w = q.w;
    rt_mat4 r = rt_mat4_identity();
    r.m[0][0] = 1 - 2 * (y * y + z * z); r.m[0][1] = 2 * (x * y - z * w);     r.m[0][2] = 2 * (x * z + y * w);
    r.m[1][0] = 2 * (x * y + z * w);     r.m[1][1] = 1 - 2 * (x * x + z * z); r.m[1][2] = 2 * (y * z - x * w);
    r.m[2][0] = 2 * (x * z - y * w);     r.m[2][1] = 2 * (y * z + x * w);     r.m[2][2] = 1 - 2 * (x * x + y * y);
    return r;
}

#endif
