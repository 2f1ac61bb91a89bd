/* kdtree_packet_lanes.h - the parts of the packet walk that take rays in
 * AVX2 lanes, shared by kdtree_packet.c (8- and 16-ray packets, per-ray
 * intervals) and kdtree_frustum.c (frustum packets of whole tiles):
 * the 8-ray set-up (kdtree_trace.c's set-up with rays in lanes), the
 * triangle test with each lane's own ray (the watertight test's
 * operations lane by lane) and the leaf test over a packet's rays.
 *
 * Private to src/accel/. Include it between KD_AVX2_BEGIN and KD_AVX2_END
 * (kdtree_internal.h), after <immintrin.h> and <math.h>: everything here
 * is static inline, compiled for AVX2 and FMA in the file that includes
 * it. How the packet walk uses these is described at the top of
 * kdtree_packet.c.
 */
#ifndef RT_KDTREE_PACKET_LANES_H
#define RT_KDTREE_PACKET_LANES_H

#include <immintrin.h>
#include <math.h>

#include "kdtree_internal.h"

/* The packet's rays for the triangle test, one ray a lane: the shear of
 * each (rt_tri_ray), when all share the axis kz. */
typedef struct kd_pray {
    __m256 ox, oy, oz, sx, sy, sz, adz, ad, tmin;
    int kx, ky, kz;
} kd_pray;

/* One triangle (tree id) against the rays of mask m, one a lane: the
 * operations of rt_intersect_triangle_ray, lane by lane (each lane its
 * ray's shear; the vertices broadcast), so each ray gets the reference's
 * bits; a lane whose edge function rounds to zero is left to the
 * reference itself (which recomputes it in double). */
static inline void tri_rays(const rt_kdtree *tree, uint32_t id, unsigned m, const kd_pray *P, const rt_ray *rays,
                            const rt_tri_ray *tr, float *best, rt_hit *h, unsigned *found)
{
    RT_NO_FP_CONTRACT
    const float *v = tree->tri + id;
    __m256 ax = _mm256_set1_ps(v[P->kx]), ay = _mm256_set1_ps(v[P->ky]), az = _mm256_set1_ps(v[P->kz]);
    __m256 bx = _mm256_set1_ps(v[3 + P->kx]), by = _mm256_set1_ps(v[3 + P->ky]), bz = _mm256_set1_ps(v[3 + P->kz]);
    __m256 cx = _mm256_set1_ps(v[6 + P->kx]), cy = _mm256_set1_ps(v[6 + P->ky]), cz = _mm256_set1_ps(v[6 + P->kz]);
    __m256 akz = _mm256_sub_ps(az, P->oz), bkz = _mm256_sub_ps(bz, P->oz), ckz = _mm256_sub_ps(cz, P->oz);
    __m256 Ax = _mm256_sub_ps(_mm256_sub_ps(ax, P->ox), _mm256_mul_ps(P->sx, akz));
    __m256 Ay = _mm256_sub_ps(_mm256_sub_ps(ay, P->oy), _mm256_mul_ps(P->sy, akz));
    __m256 Bx = _mm256_sub_ps(_mm256_sub_ps(bx, P->ox), _mm256_mul_ps(P->sx, bkz));
    __m256 By = _mm256_sub_ps(_mm256_sub_ps(by, P->oy), _mm256_mul_ps(P->sy, bkz));
    __m256 Cx = _mm256_sub_ps(_mm256_sub_ps(cx, P->ox), _mm256_mul_ps(P->sx, ckz));
    __m256 Cy = _mm256_sub_ps(_mm256_sub_ps(cy, P->oy), _mm256_mul_ps(P->sy, ckz));
    __m256 U = _mm256_sub_ps(_mm256_mul_ps(Cx, By), _mm256_mul_ps(Cy, Bx));
    __m256 V = _mm256_sub_ps(_mm256_mul_ps(Ax, Cy), _mm256_mul_ps(Ay, Cx));
    __m256 W = _mm256_sub_ps(_mm256_mul_ps(Bx, Ay), _mm256_mul_ps(By, Ax));
    __m256 zero = _mm256_setzero_ps();
    __m256 neg = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_LT_OQ), _mm256_cmp_ps(V, zero, _CMP_LT_OQ)),
                              _mm256_cmp_ps(W, zero, _CMP_LT_OQ));
    __m256 pos = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_GT_OQ), _mm256_cmp_ps(V, zero, _CMP_GT_OQ)),
                              _mm256_cmp_ps(W, zero, _CMP_GT_OQ));
    unsigned live = m & ~(unsigned)_mm256_movemask_ps(_mm256_and_ps(neg, pos));
    if (!live)
        return;
    __m256 z = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_EQ_OQ), _mm256_cmp_ps(V, zero, _CMP_EQ_OQ)),
                            _mm256_cmp_ps(W, zero, _CMP_EQ_OQ));
    unsigned zm = live & (unsigned)_mm256_movemask_ps(z);
    live &= ~zm;
    while (zm) { /* an edge function rounded to zero: the reference decides */
        int i = __builtin_ctz(zm);
        zm &= zm - 1;
        if (rt_kd_prim_hit_avx2(tree, id, &rays[i], &tr[i], &best[i], &h[i]))
            *found |= 1u << i;
    }
    if (!live)
        return;
    __m256 det = _mm256_add_ps(_mm256_add_ps(U, V), W);
    __m256 adet = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), det);
    __m256 ok = _mm256_and_ps(_mm256_cmp_ps(det, zero, _CMP_NEQ_OQ), _mm256_cmp_ps(adet, _mm256_set1_ps(INFINITY), _CMP_LT_OQ));
    __m256 T = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(U, _mm256_mul_ps(P->sz, akz)), _mm256_mul_ps(V, _mm256_mul_ps(P->sz, bkz))),
                             _mm256_mul_ps(W, _mm256_mul_ps(P->sz, ckz)));
    __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
    __m256 t = _mm256_mul_ps(T, inv);
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, P->tmin, _CMP_GT_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, _mm256_load_ps(best), _CMP_LT_OQ));
    live &= (unsigned)_mm256_movemask_ps(ok);
    if (!live)
        return;
    /* the grazing/degenerate guard, edges as the reference computes them */
    float e1x = v[3] - v[0], e1y = v[4] - v[1], e1z = v[5] - v[2], e2x = v[6] - v[0], e2y = v[7] - v[1], e2z = v[8] - v[2];
    float a1 = fabsf(e1x) + fabsf(e1y) + fabsf(e1z), a2 = fabsf(e2x) + fabsf(e2y) + fabsf(e2z);
    __m256 lhs = _mm256_div_ps(_mm256_div_ps(_mm256_mul_ps(adet, P->adz), _mm256_set1_ps(a1)), _mm256_set1_ps(a2));
    live &= (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(lhs, _mm256_mul_ps(_mm256_set1_ps(0x1p-16f), P->ad), _CMP_GT_OQ));
    if (!live)
        return;
    _Alignas(32) float tl[8], ul[8], vl[8];
    _mm256_store_ps(tl, t);
    _mm256_store_ps(ul, _mm256_mul_ps(V, inv));
    _mm256_store_ps(vl, _mm256_mul_ps(W, inv));
    *found |= live;
    while (live) {
        int i = __builtin_ctz(live);
        live &= live - 1;
        best[i] = tl[i];
        h[i].t = tl[i], h[i].u = ul[i], h[i].v = vl[i], h[i].prim = id;
    }
}

#if defined(__GNUC__)
#define KD_PINLINE static inline __attribute__((always_inline))
#else
#define KD_PINLINE static inline
#endif

#define KD_PMAX 2 /* halves of 8 lanes: packets of 8 or 16 rays */

/* Eight rt_ray records (8 floats each) in, one vector a field out, the
 * rays in lanes: ox oy oz dx dy dz tmin tmax (an 8x8 transpose). */
KD_PINLINE void transpose8(__m256 R[8])
{
    __m256 t0 = _mm256_unpacklo_ps(R[0], R[1]), t1 = _mm256_unpackhi_ps(R[0], R[1]),
           t2 = _mm256_unpacklo_ps(R[2], R[3]), t3 = _mm256_unpackhi_ps(R[2], R[3]),
           t4 = _mm256_unpacklo_ps(R[4], R[5]), t5 = _mm256_unpackhi_ps(R[4], R[5]),
           t6 = _mm256_unpacklo_ps(R[6], R[7]), t7 = _mm256_unpackhi_ps(R[6], R[7]);
    __m256 s0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), s1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
           s2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), s3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2)),
           s4 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(1, 0, 1, 0)), s5 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(3, 2, 3, 2)),
           s6 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(1, 0, 1, 0)), s7 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(3, 2, 3, 2));
    R[0] = _mm256_permute2f128_ps(s0, s4, 0x20), R[1] = _mm256_permute2f128_ps(s1, s5, 0x20);
    R[2] = _mm256_permute2f128_ps(s2, s6, 0x20), R[3] = _mm256_permute2f128_ps(s3, s7, 0x20);
    R[4] = _mm256_permute2f128_ps(s0, s4, 0x31), R[5] = _mm256_permute2f128_ps(s1, s5, 0x31);
    R[6] = _mm256_permute2f128_ps(s2, s6, 0x31), R[7] = _mm256_permute2f128_ps(s3, s7, 0x31);
}

/* kdtree_trace.c's ray set-up (ray_accept and the AVX2 ray_setup), the
 * same operations with the rays of half k in lanes (lanes past n repeat the
 * half's first ray, idle): origin O, reciprocal direction INV, the offset
 * MA per axis, and the interval [*TN, *TF] within the tree's bounds.
 * Returns the half's accepted rays as bits of the packet; adds the rays
 * parallel to an axis to *parm and the negative directions to negbits. */
KD_PINLINE unsigned setup_half(const rt_kdtree *tree, const rt_ray *rays, int n, int k, __m256 O[3], __m256 INV[3],
                               __m256 MA[3], __m256 *TN, __m256 *TF, __m256 *TMAX, unsigned *parm,
                               unsigned negbits[3])
{
    const __m256 inf = _mm256_set1_ps(INFINITY), sign = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps();
    const rt_ray *rk = rays + 8 * k;
    int nk = n - 8 * k < 8 ? n - 8 * k : 8;
    __m256 R[8];
    for (int i = 0; i < 8; i++)
        R[i] = _mm256_loadu_ps((const float *)(const void *)&rk[i < nk ? i : 0]);
    transpose8(R);
    __m256 ok = _mm256_cmp_ps(R[6], R[7], _CMP_LT_OQ);
    __m256 dz = _mm256_and_ps(_mm256_cmp_ps(R[3], zero, _CMP_EQ_OQ),
                              _mm256_and_ps(_mm256_cmp_ps(R[4], zero, _CMP_EQ_OQ), _mm256_cmp_ps(R[5], zero, _CMP_EQ_OQ)));
    ok = _mm256_andnot_ps(dz, ok);
    for (int a = 0; a < 6; a++)
        ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_andnot_ps(sign, R[a]), inf, _CMP_LT_OQ));
    __m256 om = _mm256_max_ps(_mm256_max_ps(_mm256_andnot_ps(sign, R[0]), _mm256_andnot_ps(sign, R[1])),
                              _mm256_andnot_ps(sign, R[2]));
    __m256 mp = _mm256_mul_ps(_mm256_add_ps(_mm256_set1_ps(tree->scale), om), _mm256_set1_ps(0x1p-18f));
    const float *blo = &tree->bounds.lo.x, *bhi = &tree->bounds.hi.x;
    __m256 A = _mm256_set1_ps(-INFINITY), B = inf, par = zero;
    for (int a = 0; a < 3; a++) {
        __m256 lo = _mm256_set1_ps(blo[a]), hi = _mm256_set1_ps(bhi[a]);
        O[a] = R[a];
        INV[a] = _mm256_div_ps(_mm256_set1_ps(1.0f), R[3 + a]);
        MA[a] = _mm256_mul_ps(mp, _mm256_andnot_ps(sign, INV[a]));
        __m256 pk = _mm256_cmp_ps(MA[a], inf, _CMP_NLT_UQ);
        __m256 out = _mm256_or_ps(_mm256_cmp_ps(O[a], _mm256_sub_ps(lo, mp), _CMP_LT_OQ),
                                  _mm256_cmp_ps(O[a], _mm256_add_ps(hi, mp), _CMP_GT_OQ));
        ok = _mm256_andnot_ps(_mm256_and_ps(pk, out), ok);
        __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(lo, O[a]), INV[a]), t1 = _mm256_mul_ps(_mm256_sub_ps(hi, O[a]), INV[a]);
        __m256 ta = _mm256_sub_ps(_mm256_min_ps(t1, t0), MA[a]), tb = _mm256_add_ps(_mm256_max_ps(t0, t1), MA[a]);
        A = _mm256_max_ps(A, _mm256_blendv_ps(ta, _mm256_set1_ps(-INFINITY), pk));
        B = _mm256_min_ps(B, _mm256_blendv_ps(tb, inf, pk));
        par = _mm256_or_ps(par, pk);
        negbits[a] |= (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(INV[a], zero, _CMP_NGT_UQ)) << (8 * k);
    }
    *TN = _mm256_max_ps(R[6], A), *TF = _mm256_min_ps(R[7], B), *TMAX = R[7];
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(*TN, *TF, _CMP_LE_OQ));
    *parm |= (unsigned)_mm256_movemask_ps(par) << (8 * k);
    return ((unsigned)_mm256_movemask_ps(ok) & ((1u << nk) - 1u)) << (8 * k);
}

/* Half k once the packet is accepted: its idle lanes get an empty interval
 * and no hit to improve (*BEST, and best in memory), and its rays' shears
 * go into *P for the triangle test across rays. Returns whether that test
 * applies: some ray is active and all share the shear's axis kz. */
KD_PINLINE bool prepare_half(const rt_ray *rays, const rt_tri_ray *tr, unsigned active, int k, __m256 O[3],
                             __m256 INV[3], __m256 MA[3], __m256 *TN, __m256 *TF, __m256 TMAX, __m256 *BEST,
                             float *best, kd_pray *P)
{
    const __m256 inf = _mm256_set1_ps(INFINITY);
    unsigned ak = active >> (8 * k) & 0xffu;
    __m256 idle = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32((int)ak), _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128)),
        _mm256_setzero_si256()));
    for (int a = 0; a < 3; a++) {
        O[a] = _mm256_andnot_ps(idle, O[a]);
        INV[a] = _mm256_andnot_ps(idle, INV[a]);
        MA[a] = _mm256_andnot_ps(idle, MA[a]);
    }
    *TN = _mm256_blendv_ps(*TN, inf, idle);
    *TF = _mm256_blendv_ps(*TF, _mm256_set1_ps(-INFINITY), idle);
    *BEST = _mm256_blendv_ps(TMAX, _mm256_set1_ps(-INFINITY), idle);
    _mm256_store_ps(best + 8 * k, *BEST);
    if (!ak)
        return false;
    bool across = true;
    _Alignas(32) float q[9][8];
    int first = 8 * k + __builtin_ctz(ak);
    P->kx = tr[first].kx, P->ky = tr[first].ky, P->kz = tr[first].kz;
    for (int j = 0; j < 8; j++) {
        int i = ak >> j & 1 ? 8 * k + j : first;
        const rt_tri_ray *t = &tr[i];
        if (t->kz != P->kz)
            across = false;
        q[0][j] = t->okx, q[1][j] = t->oky, q[2][j] = t->okz, q[3][j] = t->sx, q[4][j] = t->sy, q[5][j] = t->sz;
        q[6][j] = t->adz, q[7][j] = t->ad, q[8][j] = rays[i].tmin;
    }
    P->ox = _mm256_load_ps(q[0]), P->oy = _mm256_load_ps(q[1]), P->oz = _mm256_load_ps(q[2]);
    P->sx = _mm256_load_ps(q[3]), P->sy = _mm256_load_ps(q[4]), P->sz = _mm256_load_ps(q[5]);
    P->adz = _mm256_load_ps(q[6]), P->ad = _mm256_load_ps(q[7]), P->tmin = _mm256_load_ps(q[8]);
    return across;
}

/* Leaf ref for each active ray whose interval [L, min(H, BEST)] crosses
 * its cell: the halves with two or more such rays sharing kz (across)
 * primitive by primitive with the rays in lanes (vec), an instance as one
 * sub-packet of those rays (rt_kd_instance_packet), the other rays one by
 * one; with any, a ray that hits is done. Returns found with the rays
 * that hit added. */
KD_PINLINE unsigned leaf_rays(const rt_kdtree *tree, uint32_t ref, int K, bool any, unsigned active,
                              const bool *across, const kd_pray *P, const __m256 *L, const __m256 *H,
                              const __m256 *BEST, const rt_ray *rays, const rt_tri_ray *tr, float *best, rt_hit *h,
                              unsigned found)
{
    unsigned m = 0, vec = 0;
    for (int k = 0; k < K; k++) {
        unsigned mk = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(L[k], _mm256_min_ps(H[k], BEST[k]), _CMP_LE_OQ)) &
                      (active >> (8 * k) & 0xffu);
        if (across[k] && mk & (mk - 1))
            vec |= mk << (8 * k);
        m |= mk << (8 * k);
    }
    for (unsigned s = m & ~vec; s; s &= s - 1) {
        int i = __builtin_ctz(s);
        if (rt_kd_leaf_hit_avx2(tree, ref, &rays[i], &tr[i], &best[i], &h[i], any))
            found |= 1u << i;
    }
    if (!vec)
        return found;
    uint32_t one = ref & RT_KD_PAYLOAD;
    const uint32_t *p = ref >= RT_KD_ONE ? &one : tree->prim_ids + (ref & RT_KD_PAYLOAD);
    for (;; p++) {
        uint32_t id = *p & RT_KD_PAYLOAD;
        if (id < tree->other_base) {
            for (int k = 0; k < K; k++) {
                unsigned vk = vec >> (8 * k) & 0xffu, fk = 0;
                if (vk) {
                    tri_rays(tree, id, vk, &P[k], rays + 8 * k, tr + 8 * k, best + 8 * k, h + 8 * k, &fk);
                    found |= fk << (8 * k);
                }
            }
        } else if (rt_kd_is_instance(tree, id)) { /* a sub-packet through the object's tree */
            found |= rt_kd_instance_packet(tree, id, vec, rays, best, h, any);
        } else {
            for (unsigned s = vec; s; s &= s - 1) {
                int i = __builtin_ctz(s);
                if (rt_kd_prim_hit_avx2(tree, id, &rays[i], &tr[i], &best[i], &h[i]))
                    found |= 1u << i;
            }
        }
        if (any && !(vec &= ~found)) /* occlusion: the rays that hit are done */
            break;
        if (ref >= RT_KD_ONE || (*p & RT_KD_LAST))
            break;
    }
    return found;
}


#endif
