/* kdtree_trace.c - the kd-tree's traversal: the closest hit
 * (rt_kdtree_intersect) and any hit (rt_kdtree_occluded) along a ray,
 * exactly the hit brute force would find, over the arrays kdtree_pack.c
 * made (wide nodes, leaf blocks: a leaf's id list, then the triangles it
 * was the first to use; a triangle's id is its record's offset).
 *
 * Traversal: the recursive ray segment algorithm (Havran's thesis, "TA_B^rec",
 * and pbrt's KdTreeAccel) with a fixed stack, three levels per step. In a
 * wide node, each plane gives t = (split - o) / d, each cell the ray's t
 * interval through it (the parent interval cut by the near or far side of
 * its three planes), all 8 at once in AVX2 lanes; the cells' front-to-back
 * order depends only on the direction signs along the 7 planes' axes, so two
 * 128-entry tables give it. The nearest valid cell is entered, the others
 * pushed farthest first (compacted by a permute from a 256-entry table);
 * a cell is popped only if it starts before the closest hit so far. The
 * nearest cell is taken through a switch on the cell number, not by indexing
 * the node with it: when the branch is predicted (coherent rays), the next
 * node's address is known as soon as this node is loaded (indexing made
 * primary rays 35% slower). The cells and intervals are exactly the binary
 * traversal's. Every primitive test uses the ray's own (tmin, closest-so-
 * far) interval, so t is what brute force would compute.
 * Exactness against rounding: cells are widened by a tiny distance mp
 * (2^-18 of the scene's and the origin's largest coordinate, 64 times the
 * float rounding of those coordinates) on every plane, so a hit whose
 * computed t lies a few ulps outside the cell of its primitive (edges shared
 * on a split plane, grazing hits) is still found before the traversal stops.
 * Without it the lattice and chaos tests fail; with 2^-24 they pass; the
 * widening costs under 1% of the steps on the benchmark scenes. An axis
 * along which the ray moves less than mp for any finite t (direction
 * component 0, or mp / |d| overflows) is "parallel": the side of a plane is
 * then decided by the origin (both sides within mp), without the 0 * inf =
 * NaN of the slab formula; such rays (rare) run a copy of the loop with
 * that case, the others a copy without it. Empty leaves are not stored
 * (their cells' references are "empty"), so no step is spent on them.
 * Without AVX2 (or with RT_KD_SCALAR, with which the Makefile compiles this
 * file again for test_kdtree_scalar) the same step runs as plain loops.
 *
 * Leaves with 3 or more triangles are tested 8 at a time with AVX2 (when
 * compiled for it): the same IEEE operations per lane as the scalar
 * Moeller-Trumbore of intersect.h, so the same bits (tests check it).
 * Before its divide, the test rejects the lanes it surely fails from the
 * signs and bounds of u, v and t times det (see tri8): 64-65% of the
 * 8-triangle groups of primary rays and 88-95% of diffuse rays' groups end
 * there (the ones the divide would reject are 1-7%). The
 * eight triangles are loaded with one unaligned 8-float load each and an
 * 8x8 transpose, plus one gather for the ninth float: nine gathers were the
 * hottest instructions in the profile (+10-30% rays/s without them).
 *
 * Everything the two entry points use is in this file and inlined into
 * them (always_inline, flatten), intersect.h's tests included: keep new
 * traversal helpers here, not in another file, or they lose that.
 *
 * Measured and not kept (docs/performance.md has the numbers): the
 * watertight triangle test of Woop, Benthin and Wald 2013 (zero mismatches
 * against Embree on every set, but -10 to -17% rays/s on diffuse rays with
 * the per-ray shear set-up and the permuted gathers); the 8-wide test from
 * 2 or 5 triangles instead of 3; prefetching the cell on top of the stack
 * (-12% on DamagedHelmet diffuse); the leaf test out of line.
 */
#include "kdtree_internal.h"

#include <math.h>
#include <string.h>

#include "rt/accel/intersect.h"

#if defined(__AVX2__) && defined(__GNUC__) && !defined(RT_KD_SCALAR) /* RT_KD_SCALAR: the portable code, for tests */
#include <immintrin.h>
#define KD_SIMD 1
#endif

/* -------------------------------------------------------------- the ray */

/* The ray as the wide step reads it: per axis (lanes 0-2 of 8, which the
 * AVX2 step loads whole and permutes by axis; the SSE set-up repeats the
 * values in lanes 3-7, which are never selected) origin, 1/direction, cell
 * widening in t, "direction negative" and "parallel to the axis". */
typedef struct kd_ray {
    _Alignas(32) float o[8];
    _Alignas(32) float inv[8];
    _Alignas(32) float ma[8];
    _Alignas(32) int32_t neg[8]; /* -1: the above side comes first */
    _Alignas(32) int32_t par[8]; /* -1: parallel (the ray moves less than mp along the axis) */
    float mp; /* widening of every cell, in scene units */
    float tn, tf;
    bool any_par;
} kd_ray;

/* What both set-ups below share: rays that can hit nothing (an empty tree,
 * an empty interval, a non-finite or zero vector) are turned away, and the
 * cell widening mp is set. */
static inline bool ray_accept(const rt_kdtree *tree, const rt_ray *ray, kd_ray *r)
{
    if (tree->root == RT_KD_EMPTY || !(ray->tmin < ray->tmax) || rt_box_is_empty(tree->bounds))
        return false;
    if (!rt_finite3(ray->org) || !rt_finite3(ray->dir))
        return false;
    if (ray->dir.x == 0.0f && ray->dir.y == 0.0f && ray->dir.z == 0.0f)
        return false;
    float omax = fmaxf(fabsf(ray->org.x), fmaxf(fabsf(ray->org.y), fabsf(ray->org.z)));
    r->mp = (tree->scale + omax) * 0x1p-18f;
    return true;
}

/* Clips the ray to the (widened) root box; false when it misses. An axis
 * is treated as parallel when 1/d is infinite or mp/|d| overflows: then the
 * ray moves less than mp along it for any finite t, so the side of a plane
 * is decided by the origin alone (within mp: both sides). */
#ifdef KD_SIMD
static inline bool ray_setup(const rt_kdtree *tree, const rt_ray *ray, kd_ray *r)
{
    if (!ray_accept(tree, ray, r))
        return false;
    /* the same operations as the scalar set-up below, three axes at once
     * (lane 3 repeats x) */
    const rt_box *bb = &tree->bounds;
    __m128 o = _mm_setr_ps(ray->org.x, ray->org.y, ray->org.z, ray->org.x);
    __m128 d = _mm_setr_ps(ray->dir.x, ray->dir.y, ray->dir.z, ray->dir.x);
    __m128 lo = _mm_setr_ps(bb->lo.x, bb->lo.y, bb->lo.z, bb->lo.x), hi = _mm_setr_ps(bb->hi.x, bb->hi.y, bb->hi.z, bb->hi.x);
    __m128 mp = _mm_set1_ps(r->mp), inf = _mm_set1_ps(INFINITY);
    __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), d);
    __m128 ma = _mm_mul_ps(mp, _mm_andnot_ps(_mm_set1_ps(-0.0f), inv));
    __m128 par = _mm_cmp_ps(ma, inf, _CMP_NLT_UQ);
    __m128 out = _mm_or_ps(_mm_cmp_ps(o, _mm_sub_ps(lo, mp), _CMP_LT_OQ), _mm_cmp_ps(o, _mm_add_ps(hi, mp), _CMP_GT_OQ));
    if (_mm_movemask_ps(_mm_and_ps(par, out)))
        return false;
    __m128 t0 = _mm_mul_ps(_mm_sub_ps(lo, o), inv), t1 = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
    __m128 a = _mm_sub_ps(_mm_min_ps(t1, t0), ma), b = _mm_add_ps(_mm_max_ps(t0, t1), ma);
    a = _mm_blendv_ps(a, _mm_set1_ps(-INFINITY), par);
    b = _mm_blendv_ps(b, inf, par);
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(1, 0, 3, 2)));
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
    b = _mm_min_ps(b, _mm_shuffle_ps(b, b, _MM_SHUFFLE(1, 0, 3, 2)));
    b = _mm_min_ps(b, _mm_shuffle_ps(b, b, _MM_SHUFFLE(2, 3, 0, 1)));
    float tn = fmaxf(ray->tmin, _mm_cvtss_f32(a)), tf = fminf(ray->tmax, _mm_cvtss_f32(b));
    if (!(tn <= tf))
        return false;
    r->tn = tn;
    r->tf = tf;
    __m128 neg = _mm_andnot_ps(par, _mm_cmp_ps(inv, _mm_setzero_ps(), _CMP_NGT_UQ));
    inv = _mm_andnot_ps(par, inv);
    ma = _mm_andnot_ps(par, ma);
    _mm256_store_ps(r->o, _mm256_set_m128(o, o));
    _mm256_store_ps(r->inv, _mm256_set_m128(inv, inv));
    _mm256_store_ps(r->ma, _mm256_set_m128(ma, ma));
    _mm256_store_ps((float *)(void *)r->neg, _mm256_set_m128(neg, neg));
    _mm256_store_ps((float *)(void *)r->par, _mm256_set_m128(par, par));
    r->any_par = _mm_movemask_ps(par) != 0;
    return true;
}
#else
static inline bool ray_setup(const rt_kdtree *tree, const rt_ray *ray, kd_ray *r)
{
    if (!ray_accept(tree, ray, r))
        return false;
    const float o[3] = {ray->org.x, ray->org.y, ray->org.z}, d[3] = {ray->dir.x, ray->dir.y, ray->dir.z};
    r->any_par = false;
    float tn = ray->tmin, tf = ray->tmax;
    const float *lo = &tree->bounds.lo.x, *hi = &tree->bounds.hi.x;
    for (int k = 0; k < 3; k++) {
        float inv = 1.0f / d[k], ma = r->mp * fabsf(inv);
        r->o[k] = o[k];
        if (!(ma < INFINITY)) {
            if (o[k] < lo[k] - r->mp || o[k] > hi[k] + r->mp)
                return false;
            r->inv[k] = 0.0f, r->ma[k] = 0.0f, r->neg[k] = 0, r->par[k] = -1;
            r->any_par = true;
            continue;
        }
        r->inv[k] = inv, r->ma[k] = ma, r->neg[k] = inv > 0.0f ? 0 : -1, r->par[k] = 0;
        float t0 = (lo[k] - o[k]) * inv, t1 = (hi[k] - o[k]) * inv;
        if (t0 > t1) {
            float t = t0; t0 = t1; t1 = t;
        }
        t0 -= ma;
        t1 += ma;
        if (t0 > tn)
            tn = t0;
        if (t1 < tf)
            tf = t1;
    }
    if (!(tn <= tf))
        return false;
    r->tn = tn;
    r->tf = tf;
    return true;
}
#endif

/* --------------------------------------------------------------- leaves */

#if defined(__GNUC__)
#define KD_INLINE static inline __attribute__((always_inline))
#define KD_FLATTEN __attribute__((flatten)) /* inline the intersect.h tests into the loops */
#else
#define KD_INLINE static inline
#define KD_FLATTEN
#endif

/* Tests one primitive with the reference functions on (tmin, *best). */
KD_INLINE bool test_prim(const rt_kdtree *tree, uint32_t id, const rt_ray *ray, float *best, rt_hit *hit)
{
    float t, u, v;
    if (id < tree->other_base) {
        const float *p = tree->tri + id;
        if (!rt_intersect_triangle(ray->org, ray->dir, rt_v3(p[0], p[1], p[2]), rt_v3(p[3], p[4], p[5]),
                                   rt_v3(p[6], p[7], p[8]), ray->tmin, *best, &t, &u, &v))
            return false;
    } else if (id - tree->other_base < tree->sphere_count) {
        const rt_spheres *s = &tree->scene->spheres;
        size_t i = id - tree->other_base;
        if (!rt_intersect_sphere(ray->org, ray->dir, rt_v3(s->cx[i], s->cy[i], s->cz[i]), s->radius[i], ray->tmin,
                                 *best, &t))
            return false;
        u = v = 0.0f;
    } else {
        const rt_quads *q = &tree->scene->quads;
        size_t i = id - tree->other_base - tree->sphere_count;
        if (!rt_intersect_quad(ray->org, ray->dir, rt_v3(q->px[i], q->py[i], q->pz[i]),
                               rt_v3(q->ux[i], q->uy[i], q->uz[i]), rt_v3(q->vx[i], q->vy[i], q->vz[i]), ray->tmin,
                               *best, &t, &u, &v))
            return false;
    }
    *best = t;
    hit->t = t;
    hit->u = u;
    hit->v = v;
    hit->prim = id;
    return true;
}

#ifdef KD_SIMD
#define KD_SIMD_MIN 3 /* leaves with at least this many triangles go 8 at a time */

/* Up to 8 triangles (ids, all triangles) at once: the very operations of
 * rt_intersect_triangle, lane by lane (IEEE add, sub, mul and div round the
 * same in a vector lane as in a scalar register, and -std=c11 contracts
 * nothing into FMAs), so each lane's t, u, v are the scalar test's bits. The
 * closest valid lane wins; on a tie, the first, like the scalar loop. */
KD_INLINE bool tri8(const float *tri, const uint32_t *ids, uint32_t n, const rt_ray *ray, float *best, rt_hit *hit)
{
    RT_NO_FP_CONTRACT
    __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)n), lane);
    __m256i id = _mm256_maskload_epi32((const int *)ids, live);
    id = _mm256_and_si256(_mm256_blendv_epi8(_mm256_set1_epi32((int)ids[0]), id, live),
                          _mm256_set1_epi32((int)RT_KD_PAYLOAD)); /* the last id carries RT_KD_LAST */
    __m256i base = id; /* ids are the records' offsets */
    /* floats 0-7 of each triangle: one unaligned load per lane and an 8x8
     * transpose (cheaper than eight gathers); float 8 by one gather */
    uint32_t off[8];
    _mm256_storeu_si256((__m256i *)off, base);
    __m256 r0 = _mm256_loadu_ps(tri + off[0]), r1 = _mm256_loadu_ps(tri + off[1]), r2 = _mm256_loadu_ps(tri + off[2]),
           r3 = _mm256_loadu_ps(tri + off[3]), r4 = _mm256_loadu_ps(tri + off[4]), r5 = _mm256_loadu_ps(tri + off[5]),
           r6 = _mm256_loadu_ps(tri + off[6]), r7 = _mm256_loadu_ps(tri + off[7]);
    __m256 e2z = _mm256_i32gather_ps(tri + 8, base, 4);
    __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1), t2 = _mm256_unpacklo_ps(r2, r3),
           t3 = _mm256_unpackhi_ps(r2, r3), t4 = _mm256_unpacklo_ps(r4, r5), t5 = _mm256_unpackhi_ps(r4, r5),
           t6 = _mm256_unpacklo_ps(r6, r7), t7 = _mm256_unpackhi_ps(r6, r7);
    __m256 s0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), s1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
           s2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), s3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2)),
           s4 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(1, 0, 1, 0)), s5 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(3, 2, 3, 2)),
           s6 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(1, 0, 1, 0)), s7 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(3, 2, 3, 2));
    __m256 v0x = _mm256_permute2f128_ps(s0, s4, 0x20), v0y = _mm256_permute2f128_ps(s1, s5, 0x20),
           v0z = _mm256_permute2f128_ps(s2, s6, 0x20), e1x = _mm256_permute2f128_ps(s3, s7, 0x20),
           e1y = _mm256_permute2f128_ps(s0, s4, 0x31), e1z = _mm256_permute2f128_ps(s1, s5, 0x31),
           e2x = _mm256_permute2f128_ps(s2, s6, 0x31), e2y = _mm256_permute2f128_ps(s3, s7, 0x31);
    __m256 dx = _mm256_set1_ps(ray->dir.x), dy = _mm256_set1_ps(ray->dir.y), dz = _mm256_set1_ps(ray->dir.z);
    __m256 px = _mm256_sub_ps(_mm256_mul_ps(dy, e2z), _mm256_mul_ps(dz, e2y));
    __m256 py = _mm256_sub_ps(_mm256_mul_ps(dz, e2x), _mm256_mul_ps(dx, e2z));
    __m256 pz = _mm256_sub_ps(_mm256_mul_ps(dx, e2y), _mm256_mul_ps(dy, e2x));
    __m256 det = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(e1x, px), _mm256_mul_ps(e1y, py)), _mm256_mul_ps(e1z, pz));
    __m256 absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)), zero = _mm256_setzero_ps(),
           one = _mm256_set1_ps(1.0f);
    __m256 adet = _mm256_and_ps(det, absmask);
    __m256 ok = _mm256_and_ps(_mm256_castsi256_ps(live), _mm256_cmp_ps(adet, _mm256_set1_ps(INFINITY), _CMP_LT_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(det, zero, _CMP_NEQ_OQ));
    __m256 sx = _mm256_sub_ps(_mm256_set1_ps(ray->org.x), v0x), sy = _mm256_sub_ps(_mm256_set1_ps(ray->org.y), v0y),
           sz = _mm256_sub_ps(_mm256_set1_ps(ray->org.z), v0z);
    __m256 qx = _mm256_sub_ps(_mm256_mul_ps(sy, e1z), _mm256_mul_ps(sz, e1y));
    __m256 qy = _mm256_sub_ps(_mm256_mul_ps(sz, e1x), _mm256_mul_ps(sx, e1z));
    __m256 qz = _mm256_sub_ps(_mm256_mul_ps(sx, e1y), _mm256_mul_ps(sy, e1x));
    /* u, v, t times det: the reference's numerators, before its divide */
    __m256 un = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(sx, px), _mm256_mul_ps(sy, py)), _mm256_mul_ps(sz, pz));
    __m256 vn = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, qx), _mm256_mul_ps(dy, qy)), _mm256_mul_ps(dz, qz));
    __m256 tnum = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(e2x, qx), _mm256_mul_ps(e2y, qy)), _mm256_mul_ps(e2z, qz));
    {
        /* Early reject, no divide: lanes that the reference test below
         * surely rejects, from the numerators' signs and bounds against
         * |det| (x_s = x_n * sign(det), so x = x_s / |det| up to the two
         * roundings of x_n * (1 / det)). x_s < -2^-100 |det| makes x < 0
         * (too far from 0 to round to -0; a 1/det that overflows gives
         * -inf); u_s + v_s > (1 + 2^-20) |det| makes u + v > 1 whatever
         * the 3-4 roundings (relative 2^-24 each), as u_s, v_s are then at
         * worst tiny negatives. (min passes a NaN u_s or v_s through only
         * as "not rejected".) If every lane is rejected so, the divide and
         * the rest are skipped; otherwise the reference test decides every
         * lane. The same bounds on t (t_s beyond best or below 0) cost more
         * instructions than they saved (callgrind). */
        __m256 sgn = _mm256_andnot_ps(absmask, det);
        __m256 us = _mm256_xor_ps(un, sgn), vs = _mm256_xor_ps(vn, sgn);
        __m256 nlo = _mm256_mul_ps(adet, _mm256_set1_ps(-0x1p-100f));
        __m256 hi = _mm256_mul_ps(adet, _mm256_set1_ps(1.0f + 0x1p-20f));
        __m256 rej = _mm256_or_ps(_mm256_cmp_ps(_mm256_min_ps(us, vs), nlo, _CMP_LT_OQ),
                                  _mm256_cmp_ps(_mm256_add_ps(us, vs), hi, _CMP_GT_OQ));
        if (_mm256_testc_ps(rej, ok)) /* every ok lane rejected */
            return false;
    }
    __m256 inv = _mm256_div_ps(one, det);
    __m256 u = _mm256_mul_ps(un, inv);
    ok = _mm256_andnot_ps(_mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_LT_OQ), _mm256_cmp_ps(u, one, _CMP_GT_OQ)), ok);
    __m256 v = _mm256_mul_ps(vn, inv);
    ok = _mm256_andnot_ps(
        _mm256_or_ps(_mm256_cmp_ps(v, zero, _CMP_LT_OQ), _mm256_cmp_ps(_mm256_add_ps(u, v), one, _CMP_GT_OQ)), ok);
    __m256 t = _mm256_mul_ps(tnum, inv);
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, _mm256_set1_ps(ray->tmin), _CMP_GT_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, _mm256_set1_ps(*best), _CMP_LT_OQ));
    if (_mm256_testz_ps(ok, ok))
        return false;
    /* intersect.h's guard against determinants that are rounding noise */
    __m256 a1 = _mm256_add_ps(_mm256_add_ps(_mm256_and_ps(e1x, absmask), _mm256_and_ps(e1y, absmask)),
                              _mm256_and_ps(e1z, absmask));
    __m256 a2 = _mm256_add_ps(_mm256_add_ps(_mm256_and_ps(e2x, absmask), _mm256_and_ps(e2y, absmask)),
                              _mm256_and_ps(e2z, absmask));
    float ad = fabsf(ray->dir.x) + fabsf(ray->dir.y) + fabsf(ray->dir.z);
    __m256 lhs = _mm256_div_ps(_mm256_div_ps(adet, a1), a2);
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(lhs, _mm256_set1_ps(0x1p-16f * ad), _CMP_GT_OQ));
    int mask = _mm256_movemask_ps(ok);
    if (!mask)
        return false;
    float tl[8], ul[8], vl[8];
    _mm256_storeu_ps(tl, t);
    _mm256_storeu_ps(ul, u);
    _mm256_storeu_ps(vl, v);
    int k = __builtin_ctz((unsigned)mask);
    for (int i = k + 1; i < 8; i++)
        if ((mask >> i) & 1 && tl[i] < tl[k])
            k = i;
    *best = tl[k];
    hit->t = tl[k];
    hit->u = ul[k];
    hit->v = vl[k];
    hit->prim = ids[k] & RT_KD_PAYLOAD;
    return true;
}
#endif

/* The length of a leaf list: up to its id with RT_KD_LAST (the lists are
 * followed by KD_IDS_PAD such ids, so 8 can always be loaded). */
KD_INLINE uint32_t leaf_length(const uint32_t *p)
{
    uint32_t n = 0;
#ifdef KD_SIMD
    for (;; n += 8) {
        unsigned m = (unsigned)_mm256_movemask_ps(_mm256_loadu_ps((const float *)(const void *)(p + n)));
        if (m)
            return n + (uint32_t)__builtin_ctz(m) + 1;
    }
#else
    while (!(p[n] & RT_KD_LAST))
        n++;
    return n + 1;
#endif
}

/* All primitives of a multi-primitive leaf (ids ascending: triangles first). */
KD_INLINE bool test_leaf(const rt_kdtree *tree, const uint32_t *p, uint32_t n, const rt_ray *ray, float *best,
                         rt_hit *hit, bool any)
{
    bool found = false;
    uint32_t i = 0;
#ifdef KD_SIMD
    if (n >= KD_SIMD_MIN) {
        uint32_t T = tree->other_base;
        while (i < n && (p[i] & RT_KD_PAYLOAD) < T) {
            uint32_t m = n - i < 8 ? n - i : 8;
            while ((p[i + m - 1] & RT_KD_PAYLOAD) >= T)
                m--;
            if (tri8(tree->tri, p + i, m, ray, best, hit)) {
                found = true;
                if (any)
                    return true;
            }
            i += m;
        }
    }
#endif
    for (; i < n; i++)
        if (test_prim(tree, p[i] & RT_KD_PAYLOAD, ray, best, hit)) {
            found = true;
            if (any)
                return true;
        }
    return found;
}

/* ------------------------------------------------------ the wide step */

/* One step through a wide node w for the ray's interval [tn, tf]: which of
 * the 8 cells the ray crosses (non-empty t interval, non-empty child), in
 * front-to-back order. The nearest is returned in *near_cell with its
 * interval, the others are pushed farthest first (so the next nearest ends
 * on top of the stack); returns how many were pushed, or -1 when the ray
 * crosses no non-empty cell.
 *
 * Order: a cell's key k = k0 k1 k2 (bit 2 = level 0) says on which side of
 * its plane at each level it lies, 0 = the side the ray enters first (the
 * below side unless the ray runs towards -axis: neg). Cell c = 4 b0 + 2 b1
 * + b2 with b = k ^ neg at each level, its planes 0, 1 + b0, 3 + 2 b0 + b1;
 * ascending keys are front to back. The cell's t interval is [tn, tf] cut
 * by [lo, inf) for each plane it lies beyond and (-inf, hi] for each it lies
 * before, lo/hi = t(plane) -/+ ma: the binary traversal's intervals, so the
 * same leaves in the same order. */
#define KD_WSTACK 192 /* 7 net pushes per wide level, KD_MAX_DEPTH / 3 levels, + 8 for the full-width store */
_Static_assert(7 * ((KD_MAX_DEPTH + 2) / 3) + 8 <= KD_WSTACK, "wide traversal stack");

#ifndef KD_SIMD /* the portable step (the AVX2 one below does the same, 8 cells at once) */
KD_INLINE int wide_step_scalar(const rt_kdtree_wide *w, const kd_ray *r, bool par, float tn, float tf, uint32_t *sref,
                               float *slo, float *shi, unsigned *near_cell, float *near_tn, float *near_tf)
{
    float lo[7], hi[7];
    int neg[7];
    for (int p = 0; p < 7; p++) {
        unsigned k = (w->axes >> (2 * p)) & 3u;
        if (par && r->par[k]) {
            float dist = r->o[k] - w->split[p];
            lo[p] = dist >= -r->mp ? -INFINITY : INFINITY;
            hi[p] = dist <= r->mp ? INFINITY : -INFINITY;
            neg[p] = 0;
        } else {
            float t = (w->split[p] - r->o[k]) * r->inv[k];
            lo[p] = t - r->ma[k];
            hi[p] = t + r->ma[k];
            neg[p] = r->neg[k];
        }
    }
    /* back to front: the entries come out farthest first, and the last one
     * (the nearest) is returned instead of pushed */
    int n = 0;
    for (unsigned key = 8; key-- > 0;) {
        unsigned f0 = key >> 2 & 1u, f1 = key >> 1 & 1u, f2 = key & 1u;
        unsigned b0 = f0 ^ (unsigned)(neg[0] & 1), p1 = 1 + b0, b1 = f1 ^ (unsigned)(neg[p1] & 1),
                 p2 = 3 + 2 * b0 + b1, b2 = f2 ^ (unsigned)(neg[p2] & 1);
        float l = tn, h = tf;
        if (f0) l = lo[0] > l ? lo[0] : l; else h = hi[0] < h ? hi[0] : h;
        if (f1) l = lo[p1] > l ? lo[p1] : l; else h = hi[p1] < h ? hi[p1] : h;
        if (f2) l = lo[p2] > l ? lo[p2] : l; else h = hi[p2] < h ? hi[p2] : h;
        unsigned cell = 4 * b0 + 2 * b1 + b2;
        uint32_t ref = w->child[cell];
        if (ref == RT_KD_EMPTY || !(l <= h))
            continue;
        sref[n] = ref, slo[n] = l, shi[n] = h;
        n++;
        *near_cell = cell, *near_tn = l, *near_tf = h;
    }
    return n - 1; /* -1: none */
}
#endif

#ifdef KD_SIMD
/* Byte i of entry m: the lane of the i-th set bit of m (compaction by a
 * permute, as AVX2 has no compress instruction). This table and the two
 * below are printed by tools/kd_tables.py. */
static const uint64_t kd_compress[256] = {
    0x0000000000000000ull, 0x0000000000000000ull, 0x0000000000000001ull, 0x0000000000000100ull,
    0x0000000000000002ull, 0x0000000000000200ull, 0x0000000000000201ull, 0x0000000000020100ull,
    0x0000000000000003ull, 0x0000000000000300ull, 0x0000000000000301ull, 0x0000000000030100ull,
    0x0000000000000302ull, 0x0000000000030200ull, 0x0000000000030201ull, 0x0000000003020100ull,
    0x0000000000000004ull, 0x0000000000000400ull, 0x0000000000000401ull, 0x0000000000040100ull,
    0x0000000000000402ull, 0x0000000000040200ull, 0x0000000000040201ull, 0x0000000004020100ull,
    0x0000000000000403ull, 0x0000000000040300ull, 0x0000000000040301ull, 0x0000000004030100ull,
    0x0000000000040302ull, 0x0000000004030200ull, 0x0000000004030201ull, 0x0000000403020100ull,
    0x0000000000000005ull, 0x0000000000000500ull, 0x0000000000000501ull, 0x0000000000050100ull,
    0x0000000000000502ull, 0x0000000000050200ull, 0x0000000000050201ull, 0x0000000005020100ull,
    0x0000000000000503ull, 0x0000000000050300ull, 0x0000000000050301ull, 0x0000000005030100ull,
    0x0000000000050302ull, 0x0000000005030200ull, 0x0000000005030201ull, 0x0000000503020100ull,
    0x0000000000000504ull, 0x0000000000050400ull, 0x0000000000050401ull, 0x0000000005040100ull,
    0x0000000000050402ull, 0x0000000005040200ull, 0x0000000005040201ull, 0x0000000504020100ull,
    0x0000000000050403ull, 0x0000000005040300ull, 0x0000000005040301ull, 0x0000000504030100ull,
    0x0000000005040302ull, 0x0000000504030200ull, 0x0000000504030201ull, 0x0000050403020100ull,
    0x0000000000000006ull, 0x0000000000000600ull, 0x0000000000000601ull, 0x0000000000060100ull,
    0x0000000000000602ull, 0x0000000000060200ull, 0x0000000000060201ull, 0x0000000006020100ull,
    0x0000000000000603ull, 0x0000000000060300ull, 0x0000000000060301ull, 0x0000000006030100ull,
    0x0000000000060302ull, 0x0000000006030200ull, 0x0000000006030201ull, 0x0000000603020100ull,
    0x0000000000000604ull, 0x0000000000060400ull, 0x0000000000060401ull, 0x0000000006040100ull,
    0x0000000000060402ull, 0x0000000006040200ull, 0x0000000006040201ull, 0x0000000604020100ull,
    0x0000000000060403ull, 0x0000000006040300ull, 0x0000000006040301ull, 0x0000000604030100ull,
    0x0000000006040302ull, 0x0000000604030200ull, 0x0000000604030201ull, 0x0000060403020100ull,
    0x0000000000000605ull, 0x0000000000060500ull, 0x0000000000060501ull, 0x0000000006050100ull,
    0x0000000000060502ull, 0x0000000006050200ull, 0x0000000006050201ull, 0x0000000605020100ull,
    0x0000000000060503ull, 0x0000000006050300ull, 0x0000000006050301ull, 0x0000000605030100ull,
    0x0000000006050302ull, 0x0000000605030200ull, 0x0000000605030201ull, 0x0000060503020100ull,
    0x0000000000060504ull, 0x0000000006050400ull, 0x0000000006050401ull, 0x0000000605040100ull,
    0x0000000006050402ull, 0x0000000605040200ull, 0x0000000605040201ull, 0x0000060504020100ull,
    0x0000000006050403ull, 0x0000000605040300ull, 0x0000000605040301ull, 0x0000060504030100ull,
    0x0000000605040302ull, 0x0000060504030200ull, 0x0000060504030201ull, 0x0006050403020100ull,
    0x0000000000000007ull, 0x0000000000000700ull, 0x0000000000000701ull, 0x0000000000070100ull,
    0x0000000000000702ull, 0x0000000000070200ull, 0x0000000000070201ull, 0x0000000007020100ull,
    0x0000000000000703ull, 0x0000000000070300ull, 0x0000000000070301ull, 0x0000000007030100ull,
    0x0000000000070302ull, 0x0000000007030200ull, 0x0000000007030201ull, 0x0000000703020100ull,
    0x0000000000000704ull, 0x0000000000070400ull, 0x0000000000070401ull, 0x0000000007040100ull,
    0x0000000000070402ull, 0x0000000007040200ull, 0x0000000007040201ull, 0x0000000704020100ull,
    0x0000000000070403ull, 0x0000000007040300ull, 0x0000000007040301ull, 0x0000000704030100ull,
    0x0000000007040302ull, 0x0000000704030200ull, 0x0000000704030201ull, 0x0000070403020100ull,
    0x0000000000000705ull, 0x0000000000070500ull, 0x0000000000070501ull, 0x0000000007050100ull,
    0x0000000000070502ull, 0x0000000007050200ull, 0x0000000007050201ull, 0x0000000705020100ull,
    0x0000000000070503ull, 0x0000000007050300ull, 0x0000000007050301ull, 0x0000000705030100ull,
    0x0000000007050302ull, 0x0000000705030200ull, 0x0000000705030201ull, 0x0000070503020100ull,
    0x0000000000070504ull, 0x0000000007050400ull, 0x0000000007050401ull, 0x0000000705040100ull,
    0x0000000007050402ull, 0x0000000705040200ull, 0x0000000705040201ull, 0x0000070504020100ull,
    0x0000000007050403ull, 0x0000000705040300ull, 0x0000000705040301ull, 0x0000070504030100ull,
    0x0000000705040302ull, 0x0000070504030200ull, 0x0000070504030201ull, 0x0007050403020100ull,
    0x0000000000000706ull, 0x0000000000070600ull, 0x0000000000070601ull, 0x0000000007060100ull,
    0x0000000000070602ull, 0x0000000007060200ull, 0x0000000007060201ull, 0x0000000706020100ull,
    0x0000000000070603ull, 0x0000000007060300ull, 0x0000000007060301ull, 0x0000000706030100ull,
    0x0000000007060302ull, 0x0000000706030200ull, 0x0000000706030201ull, 0x0000070603020100ull,
    0x0000000000070604ull, 0x0000000007060400ull, 0x0000000007060401ull, 0x0000000706040100ull,
    0x0000000007060402ull, 0x0000000706040200ull, 0x0000000706040201ull, 0x0000070604020100ull,
    0x0000000007060403ull, 0x0000000706040300ull, 0x0000000706040301ull, 0x0000070604030100ull,
    0x0000000706040302ull, 0x0000070604030200ull, 0x0000070604030201ull, 0x0007060403020100ull,
    0x0000000000070605ull, 0x0000000007060500ull, 0x0000000007060501ull, 0x0000000706050100ull,
    0x0000000007060502ull, 0x0000000706050200ull, 0x0000000706050201ull, 0x0000070605020100ull,
    0x0000000007060503ull, 0x0000000706050300ull, 0x0000000706050301ull, 0x0000070605030100ull,
    0x0000000706050302ull, 0x0000070605030200ull, 0x0000070605030201ull, 0x0007060503020100ull,
    0x0000000007060504ull, 0x0000000706050400ull, 0x0000000706050401ull, 0x0000070605040100ull,
    0x0000000706050402ull, 0x0000070605040200ull, 0x0000070605040201ull, 0x0007060504020100ull,
    0x0000000706050403ull, 0x0000070605040300ull, 0x0000070605040301ull, 0x0007060504030100ull,
    0x0000070605040302ull, 0x0007060504030200ull, 0x0007060504030201ull, 0x0706050403020100ull,
};

/* The front-to-back order of a node's cells depends only on which of its 7
 * planes the ray crosses towards -axis (7 bits nb): byte L of
 * kd_cell_of_key[nb] is the cell with key 7 - L, byte c of
 * kd_key_of_cell[nb] the key of cell c (keys as in wide_step_scalar). */
static const uint64_t kd_cell_of_key[128] = {
    0x0001020304050607ull, 0x0405060700010203ull, 0x0203000104050607ull, 0x0405060702030001ull,
    0x0001020306070405ull, 0x0607040500010203ull, 0x0203000106070405ull, 0x0607040502030001ull,
    0x0100020304050607ull, 0x0405060701000203ull, 0x0203010004050607ull, 0x0405060702030100ull,
    0x0100020306070405ull, 0x0607040501000203ull, 0x0203010006070405ull, 0x0607040502030100ull,
    0x0001030204050607ull, 0x0405060700010302ull, 0x0302000104050607ull, 0x0405060703020001ull,
    0x0001030206070405ull, 0x0607040500010302ull, 0x0302000106070405ull, 0x0607040503020001ull,
    0x0100030204050607ull, 0x0405060701000302ull, 0x0302010004050607ull, 0x0405060703020100ull,
    0x0100030206070405ull, 0x0607040501000302ull, 0x0302010006070405ull, 0x0607040503020100ull,
    0x0001020305040607ull, 0x0504060700010203ull, 0x0203000105040607ull, 0x0504060702030001ull,
    0x0001020306070504ull, 0x0607050400010203ull, 0x0203000106070504ull, 0x0607050402030001ull,
    0x0100020305040607ull, 0x0504060701000203ull, 0x0203010005040607ull, 0x0504060702030100ull,
    0x0100020306070504ull, 0x0607050401000203ull, 0x0203010006070504ull, 0x0607050402030100ull,
    0x0001030205040607ull, 0x0504060700010302ull, 0x0302000105040607ull, 0x0504060703020001ull,
    0x0001030206070504ull, 0x0607050400010302ull, 0x0302000106070504ull, 0x0607050403020001ull,
    0x0100030205040607ull, 0x0504060701000302ull, 0x0302010005040607ull, 0x0504060703020100ull,
    0x0100030206070504ull, 0x0607050401000302ull, 0x0302010006070504ull, 0x0607050403020100ull,
    0x0001020304050706ull, 0x0405070600010203ull, 0x0203000104050706ull, 0x0405070602030001ull,
    0x0001020307060405ull, 0x0706040500010203ull, 0x0203000107060405ull, 0x0706040502030001ull,
    0x0100020304050706ull, 0x0405070601000203ull, 0x0203010004050706ull, 0x0405070602030100ull,
    0x0100020307060405ull, 0x0706040501000203ull, 0x0203010007060405ull, 0x0706040502030100ull,
    0x0001030204050706ull, 0x0405070600010302ull, 0x0302000104050706ull, 0x0405070603020001ull,
    0x0001030207060405ull, 0x0706040500010302ull, 0x0302000107060405ull, 0x0706040503020001ull,
    0x0100030204050706ull, 0x0405070601000302ull, 0x0302010004050706ull, 0x0405070603020100ull,
    0x0100030207060405ull, 0x0706040501000302ull, 0x0302010007060405ull, 0x0706040503020100ull,
    0x0001020305040706ull, 0x0504070600010203ull, 0x0203000105040706ull, 0x0504070602030001ull,
    0x0001020307060504ull, 0x0706050400010203ull, 0x0203000107060504ull, 0x0706050402030001ull,
    0x0100020305040706ull, 0x0504070601000203ull, 0x0203010005040706ull, 0x0504070602030100ull,
    0x0100020307060504ull, 0x0706050401000203ull, 0x0203010007060504ull, 0x0706050402030100ull,
    0x0001030205040706ull, 0x0504070600010302ull, 0x0302000105040706ull, 0x0504070603020001ull,
    0x0001030207060504ull, 0x0706050400010302ull, 0x0302000107060504ull, 0x0706050403020001ull,
    0x0100030205040706ull, 0x0504070601000302ull, 0x0302010005040706ull, 0x0504070603020100ull,
    0x0100030207060504ull, 0x0706050401000302ull, 0x0302010007060504ull, 0x0706050403020100ull,
};
static const uint64_t kd_key_of_cell[128] = {
    0x0706050403020100ull, 0x0302010007060504ull, 0x0706050401000302ull, 0x0302010005040706ull,
    0x0504070603020100ull, 0x0100030207060504ull, 0x0504070601000302ull, 0x0100030205040706ull,
    0x0706050403020001ull, 0x0302010007060405ull, 0x0706050401000203ull, 0x0302010005040607ull,
    0x0504070603020001ull, 0x0100030207060405ull, 0x0504070601000203ull, 0x0100030205040607ull,
    0x0706050402030100ull, 0x0302010006070504ull, 0x0706050400010302ull, 0x0302010004050706ull,
    0x0504070602030100ull, 0x0100030206070504ull, 0x0504070600010302ull, 0x0100030204050706ull,
    0x0706050402030001ull, 0x0302010006070405ull, 0x0706050400010203ull, 0x0302010004050607ull,
    0x0504070602030001ull, 0x0100030206070405ull, 0x0504070600010203ull, 0x0100030204050607ull,
    0x0706040503020100ull, 0x0302000107060504ull, 0x0706040501000302ull, 0x0302000105040706ull,
    0x0504060703020100ull, 0x0100020307060504ull, 0x0504060701000302ull, 0x0100020305040706ull,
    0x0706040503020001ull, 0x0302000107060405ull, 0x0706040501000203ull, 0x0302000105040607ull,
    0x0504060703020001ull, 0x0100020307060405ull, 0x0504060701000203ull, 0x0100020305040607ull,
    0x0706040502030100ull, 0x0302000106070504ull, 0x0706040500010302ull, 0x0302000104050706ull,
    0x0504060702030100ull, 0x0100020306070504ull, 0x0504060700010302ull, 0x0100020304050706ull,
    0x0706040502030001ull, 0x0302000106070405ull, 0x0706040500010203ull, 0x0302000104050607ull,
    0x0504060702030001ull, 0x0100020306070405ull, 0x0504060700010203ull, 0x0100020304050607ull,
    0x0607050403020100ull, 0x0203010007060504ull, 0x0607050401000302ull, 0x0203010005040706ull,
    0x0405070603020100ull, 0x0001030207060504ull, 0x0405070601000302ull, 0x0001030205040706ull,
    0x0607050403020001ull, 0x0203010007060405ull, 0x0607050401000203ull, 0x0203010005040607ull,
    0x0405070603020001ull, 0x0001030207060405ull, 0x0405070601000203ull, 0x0001030205040607ull,
    0x0607050402030100ull, 0x0203010006070504ull, 0x0607050400010302ull, 0x0203010004050706ull,
    0x0405070602030100ull, 0x0001030206070504ull, 0x0405070600010302ull, 0x0001030204050706ull,
    0x0607050402030001ull, 0x0203010006070405ull, 0x0607050400010203ull, 0x0203010004050607ull,
    0x0405070602030001ull, 0x0001030206070405ull, 0x0405070600010203ull, 0x0001030204050607ull,
    0x0607040503020100ull, 0x0203000107060504ull, 0x0607040501000302ull, 0x0203000105040706ull,
    0x0405060703020100ull, 0x0001020307060504ull, 0x0405060701000302ull, 0x0001020305040706ull,
    0x0607040503020001ull, 0x0203000107060405ull, 0x0607040501000203ull, 0x0203000105040607ull,
    0x0405060703020001ull, 0x0001020307060405ull, 0x0405060701000203ull, 0x0001020305040607ull,
    0x0607040502030100ull, 0x0203000106070504ull, 0x0607040500010302ull, 0x0203000104050706ull,
    0x0405060702030100ull, 0x0001020306070504ull, 0x0405060700010302ull, 0x0001020304050706ull,
    0x0607040502030001ull, 0x0203000106070405ull, 0x0607040500010203ull, 0x0203000104050607ull,
    0x0405060702030001ull, 0x0001020306070405ull, 0x0405060700010203ull, 0x0001020304050607ull,
};

/* The same as wide_step_scalar, eight cells at once. Lanes are cells here
 * (lane c = cell c, whose planes 0, 1 + c/4 and 3 + c/2 are the same for
 * every node), so the caller can read the nearest cell's interval from a
 * fixed lane once it has branched on the cell: only that branch waits for
 * the choice of the nearest cell, the data does not. The pushes go in key
 * order (see wide_step_scalar) through the key -> cell permutation. */
typedef struct kd_step {
    __m256 l, h;   /* per cell: its t interval */
    unsigned cell; /* the nearest valid cell */
} kd_step;

KD_INLINE int wide_step_avx2(const rt_kdtree_wide *w, const kd_ray *r, bool par, float tn, float tf, uint32_t *sref,
                             float *slo, float *shi, kd_step *out)
{
    const __m256i three = _mm256_set1_epi32(3), zero = _mm256_setzero_si256();
    const __m256 ninf = _mm256_set1_ps(-INFINITY), pinf = _mm256_set1_ps(INFINITY);
    __m256 split = _mm256_load_ps((const float *)(const void *)w); /* lane 7: the axes, unused */
    __m256i axis = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)w->axes),
                                                      _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 0)),
                                    three);
    __m256 o = _mm256_permutevar8x32_ps(_mm256_load_ps(r->o), axis);
    __m256 inv = _mm256_permutevar8x32_ps(_mm256_load_ps(r->inv), axis);
    __m256 ma = _mm256_permutevar8x32_ps(_mm256_load_ps(r->ma), axis);
    __m256i neg = _mm256_permutevar8x32_epi32(_mm256_load_si256((const __m256i *)(const void *)r->neg), axis);
    __m256 t = _mm256_mul_ps(_mm256_sub_ps(split, o), inv);
    __m256 lo = _mm256_sub_ps(t, ma), hi = _mm256_add_ps(t, ma);
    if (par) {
        __m256 pm = _mm256_castsi256_ps(
            _mm256_permutevar8x32_epi32(_mm256_load_si256((const __m256i *)(const void *)r->par), axis));
        __m256 dist = _mm256_sub_ps(o, split), mp = _mm256_set1_ps(r->mp);
        __m256 plo = _mm256_blendv_ps(pinf, ninf, _mm256_cmp_ps(dist, _mm256_sub_ps(_mm256_setzero_ps(), mp), _CMP_GE_OQ));
        __m256 phi = _mm256_blendv_ps(ninf, pinf, _mm256_cmp_ps(dist, mp, _CMP_LE_OQ));
        lo = _mm256_blendv_ps(lo, plo, pm);
        hi = _mm256_blendv_ps(hi, phi, pm);
        neg = _mm256_andnot_si256(_mm256_castps_si256(pm), neg);
    }
    /* cell order: the planes of cell c (0, 1 + c/4, 3 + c/2), and the key
     * bits that say on which side of each the cell is for this ray */
    const __m256i q1 = _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2), q2 = _mm256_setr_epi32(3, 3, 4, 4, 5, 5, 6, 6);
    unsigned nb = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(neg)) & 0x7fu;
    uint64_t order = kd_cell_of_key[nb];
    __m256i key = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)kd_key_of_cell[nb]));
    /* blendv reads the sign bit: key bit 2, 1, 0 = far side at level 0, 1, 2 */
    __m256 m0 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 29)), m1 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 30)),
           m2 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 31));
    __m256 x = _mm256_max_ps(_mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, zero), m0),
                             _mm256_max_ps(_mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, q1), m1),
                                           _mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, q2), m2)));
    __m256 y = _mm256_min_ps(_mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, zero), pinf, m0),
                             _mm256_min_ps(_mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, q1), pinf, m1),
                                           _mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, q2), pinf, m2)));
    __m256 l = _mm256_max_ps(x, _mm256_set1_ps(tn)), h = _mm256_min_ps(y, _mm256_set1_ps(tf));
    __m256i ref = _mm256_load_si256((const __m256i *)(const void *)w->child);
    __m256 ok = _mm256_andnot_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(ref, _mm256_set1_epi32(-1))),
                                 _mm256_cmp_ps(l, h, _CMP_LE_OQ));
    /* key order, farthest first: the nearest valid cell is the top bit */
    __m256i cell = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)order));
    unsigned mask = (unsigned)_mm256_movemask_ps(_mm256_permutevar8x32_ps(ok, cell));
    if (!mask)
        return -1;
    unsigned lane = 31u - (unsigned)__builtin_clz(mask), rest = mask ^ (1u << lane);
    out->l = l, out->h = h, out->cell = (unsigned)(order >> (8 * lane)) & 7u;
    __m256i idx = _mm256_permutevar8x32_epi32(
        cell, _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(const void *)&kd_compress[rest])));
    _mm256_storeu_si256((__m256i *)(void *)sref, _mm256_permutevar8x32_epi32(ref, idx));
    _mm256_storeu_ps(slo, _mm256_permutevar8x32_ps(l, idx));
    _mm256_storeu_ps(shi, _mm256_permutevar8x32_ps(h, idx));
    return __builtin_popcount(rest);
}

/* The nearest cell's child and interval: a branch per cell (see above). */
#define KD_NEAR(c)                                                                 \
    case c:                                                                        \
        ref = w->child[c];                                                         \
        tn = _mm_cvtss_f32(_mm_permute_ps(_mm256_extractf128_ps(st.l, (c) / 4), (c) % 4)); \
        tf = _mm_cvtss_f32(_mm_permute_ps(_mm256_extractf128_ps(st.h, (c) / 4), (c) % 4)); \
        break;
#endif

/* The shared traversal; any = stop at the first hit (occlusion). A stack
 * entry is a child reference with its t interval; the nearest is on top. */
KD_INLINE bool traverse_ray(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit, bool any, bool par, const kd_ray *r)
{
    const rt_kdtree_wide *wide = tree->wide;
    const uint32_t *ids = tree->prim_ids;
    uint32_t sref[KD_WSTACK];
    float slo[KD_WSTACK], shi[KD_WSTACK];
    int sp = 0;
    uint32_t ref = tree->root;
    float tn = r->tn, tf = r->tf, best = ray->tmax;
    bool found = false;
    for (;;) {
        while (ref < RT_KD_LEAF) {
            const rt_kdtree_wide *w = &wide[ref];
#ifdef KD_SIMD
            kd_step st;
            int n = wide_step_avx2(w, r, par, tn, tf < best ? tf : best, sref + sp, slo + sp, shi + sp, &st);
            if (n < 0)
                goto pop;
            sp += n;
            /* a branch per cell rather than w->child[cell]: when the branch
             * is predicted (coherent rays), the next node's address is
             * known as soon as this node is loaded */
            switch (st.cell) {
                KD_NEAR(0) KD_NEAR(1) KD_NEAR(2) KD_NEAR(3) KD_NEAR(4) KD_NEAR(5) KD_NEAR(6)
            default:
                KD_NEAR(7)
            }
#else
            unsigned cell = 0; /* set whenever the step returns >= 0 */
            int n = wide_step_scalar(w, r, par, tn, tf < best ? tf : best, sref + sp, slo + sp, shi + sp, &cell, &tn,
                                     &tf);
            if (n < 0)
                goto pop;
            sp += n;
            ref = w->child[cell];
#endif
        }
        if (ref >= RT_KD_ONE) {
            if (test_prim(tree, ref & RT_KD_PAYLOAD, ray, &best, hit)) {
                found = true;
                if (any)
                    return true;
            }
        } else {
            const uint32_t *p = ids + (ref & RT_KD_PAYLOAD);
            if (test_leaf(tree, p, leaf_length(p), ray, &best, hit, any)) {
                found = true;
                if (any)
                    return true;
            }
        }
    pop:
        for (;;) { /* next cell that starts before the closest hit */
            if (sp == 0)
                return found;
            sp--;
            if (slo[sp] <= best)
                break;
        }
        ref = sref[sp];
        tn = slo[sp];
        tf = shi[sp];
    }
}

/* Two copies of the loop: rays parallel to some axis (rare: a zero direction
 * component) need a case in every step that the others skip. */
KD_INLINE bool traverse(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit, bool any)
{
    kd_ray r;
    if (!ray_setup(tree, ray, &r))
        return false;
    if (!r.any_par)
        return traverse_ray(tree, ray, hit, any, false, &r);
    return traverse_ray(tree, ray, hit, any, true, &r);
}

KD_FLATTEN bool rt_kdtree_intersect(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit)
{
    hit->prim = RT_NONE;
    if (traverse(tree, ray, hit, false)) {
        hit->prim = rt_kdtree_scene_prim(tree, hit->prim);
        return true;
    }
    hit->prim = RT_NONE;
    return false;
}

KD_FLATTEN bool rt_kdtree_occluded(const rt_kdtree *tree, const rt_ray *ray)
{
    rt_hit h;
    return traverse(tree, ray, &h, true);
}
