/* kdtree_packet_lanes.h - the parts of the packet walk that take rays in
 * SIMD lanes, shared by kdtree_packet.c (8- and 16-ray packets, per-ray
 * intervals) and kdtree_frustum.c (frustum packets of whole tiles): the
 * set-up of KD_PW rays (kdtree_trace.c's set-up with rays in lanes), the
 * triangle test with each lane's own ray (the watertight test's
 * operations lane by lane) and the leaf test over a packet's rays.
 *
 * Written once with GCC/clang vector types of KD_PW lanes (8 or 16) and
 * compiled per width: define KD_PW and include it between the width's
 * target pragmas (kdtree_packet.c, kdtree_frustum.c: 16 lanes for
 * AVX-512 F/BW/DQ/VL, 8 for AVX2 and FMA), after <immintrin.h> and
 * <math.h>. The only intrinsics are min, max, blend, the mask extraction
 * and the 8x8 transpose of the set-up (two of them, joined, at 16 lanes). Every lane
 * runs the same IEEE operations as the single ray's code whatever the
 * width (min and max keep SSE's operand order: a < b ? a : b), so every
 * width gives the same bits. Everything here is static inline. How the
 * packet walk uses these is described at the top of kdtree_packet.c.
 *
 * Private to src/accel/.
 */
#ifndef RT_KDTREE_PACKET_LANES_H
#define RT_KDTREE_PACKET_LANES_H

#include <immintrin.h>
#include <math.h>
#include <string.h>

#include "kdtree_internal.h"

#if KD_PW != 8 && KD_PW != 16
#error "kdtree_packet_lanes.h: KD_PW must be 8 or 16"
#endif

#if defined(__GNUC__)
#define KD_PINLINE static inline __attribute__((always_inline))
#else
#define KD_PINLINE static inline
#endif

typedef float kd_pf __attribute__((vector_size(4 * KD_PW)));
typedef int32_t kd_pi __attribute__((vector_size(4 * KD_PW)));

#define KD_PMAX (16 / KD_PW) /* vectors of a 16-ray packet: 2 at 8 lanes, 1 at 16 */

KD_PINLINE kd_pf psplat(float x)
{
    kd_pf v = {0};
    for (int i = 0; i < KD_PW; i++)
        v[i] = x;
    return v;
}

/* m ? a : b per lane (m: 0 or -1), and SSE's min and max: a < b ? a : b
 * and a > b ? a : b, b on ties and NaN (the instructions: GCC does not
 * find them in the vector-type and/or forms, which made the 8-lane packets
 * 13-22% slower than with these, docs/performance.md) */
#if KD_PW == 16
KD_PINLINE kd_pf psel(kd_pi m, kd_pf a, kd_pf b)
{
    return (kd_pf)_mm512_mask_blend_ps(_mm512_movepi32_mask((__m512i)m), (__m512)b, (__m512)a);
}
KD_PINLINE kd_pf pmin(kd_pf a, kd_pf b) { return (kd_pf)_mm512_min_ps((__m512)a, (__m512)b); }
KD_PINLINE kd_pf pmax(kd_pf a, kd_pf b) { return (kd_pf)_mm512_max_ps((__m512)a, (__m512)b); }
#else
KD_PINLINE kd_pf psel(kd_pi m, kd_pf a, kd_pf b)
{
    return (kd_pf)_mm256_blendv_ps((__m256)b, (__m256)a, (__m256)m);
}
KD_PINLINE kd_pf pmin(kd_pf a, kd_pf b) { return (kd_pf)_mm256_min_ps((__m256)a, (__m256)b); }
KD_PINLINE kd_pf pmax(kd_pf a, kd_pf b) { return (kd_pf)_mm256_max_ps((__m256)a, (__m256)b); }
#endif
KD_PINLINE kd_pf pabs(kd_pf a) { return (kd_pf)((kd_pi)a & 0x7fffffff); }
KD_PINLINE kd_pf pand(kd_pf a, kd_pi m) { return (kd_pf)((kd_pi)a & m); }

/* The lanes of m that are set, as bits. */
KD_PINLINE unsigned pbits(kd_pi m)
{
#if KD_PW == 16
    return (unsigned)_mm512_movepi32_mask((__m512i)m);
#else
    return (unsigned)_mm256_movemask_ps((__m256)m);
#endif
}

/* Bits of a mask as lanes (-1 where set). */
KD_PINLINE kd_pi planes(unsigned bits)
{
    kd_pi b = {0}, s = {0};
    for (int i = 0; i < KD_PW; i++)
        b[i] = (int32_t)(1u << i), s[i] = (int32_t)bits;
    return (s & b) == b;
}

KD_PINLINE kd_pf pload(const float *p)
{
    kd_pf v;
    memcpy(&v, p, sizeof v);
    return v;
}

KD_PINLINE void pstore(float *p, kd_pf v)
{
    memcpy(p, &v, sizeof v);
}

/* The packet's rays for the triangle test, one ray a lane: the shear of
 * each (rt_tri_ray), when all share the axis kz. */
typedef struct kd_pray {
    kd_pf ox, oy, oz, sx, sy, sz, adz, ad, tmin;
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
    kd_pf az = psplat(v[P->kz]), bz = psplat(v[3 + P->kz]), cz = psplat(v[6 + P->kz]);
    kd_pf akz = az - P->oz, bkz = bz - P->oz, ckz = cz - P->oz;
    kd_pf Ax = (psplat(v[P->kx]) - P->ox) - P->sx * akz, Ay = (psplat(v[P->ky]) - P->oy) - P->sy * akz;
    kd_pf Bx = (psplat(v[3 + P->kx]) - P->ox) - P->sx * bkz, By = (psplat(v[3 + P->ky]) - P->oy) - P->sy * bkz;
    kd_pf Cx = (psplat(v[6 + P->kx]) - P->ox) - P->sx * ckz, Cy = (psplat(v[6 + P->ky]) - P->oy) - P->sy * ckz;
    kd_pf U = Cx * By - Cy * Bx, V = Ax * Cy - Ay * Cx, W = Bx * Ay - By * Ax;
    const kd_pf zero = psplat(0.0f);
    kd_pi neg = (U < zero) | (V < zero) | (W < zero), pos = (U > zero) | (V > zero) | (W > zero);
    unsigned live = m & ~pbits(neg & pos);
    if (!live)
        return;
    unsigned zm = live & pbits((U == zero) | (V == zero) | (W == zero));
    live &= ~zm;
    while (zm) { /* an edge function rounded to zero: the reference decides */
        int i = __builtin_ctz(zm);
        zm &= zm - 1;
        if (rt_kd_prim_hit_avx2(tree, id, &rays[i], &tr[i], &best[i], &h[i]))
            *found |= 1u << i;
    }
    if (!live)
        return;
    kd_pf det = (U + V) + W;
    kd_pf adet = pabs(det);
    kd_pi ok = ((det < zero) | (det > zero)) & (adet < psplat(INFINITY));
    kd_pf T = (U * (P->sz * akz) + V * (P->sz * bkz)) + W * (P->sz * ckz);
    kd_pf inv = psplat(1.0f) / det;
    kd_pf t = T * inv;
    ok &= (t > P->tmin) & (t < pload(best));
    live &= pbits(ok);
    if (!live)
        return;
    /* the grazing/degenerate guard, edges as the reference computes them */
    float e1x = v[3] - v[0], e1y = v[4] - v[1], e1z = v[5] - v[2], e2x = v[6] - v[0], e2y = v[7] - v[1], e2z = v[8] - v[2];
    float a1 = fabsf(e1x) + fabsf(e1y) + fabsf(e1z), a2 = fabsf(e2x) + fabsf(e2y) + fabsf(e2z);
    kd_pf lhs = ((adet * P->adz) / psplat(a1)) / psplat(a2);
    live &= pbits(lhs > psplat(0x1p-16f) * P->ad);
    if (!live)
        return;
    kd_pf ul = V * inv, vl = W * inv;
    *found |= live;
    while (live) {
        int i = __builtin_ctz(live);
        live &= live - 1;
        best[i] = t[i];
        h[i].t = t[i], h[i].u = ul[i], h[i].v = vl[i], h[i].prim = id;
    }
}

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

/* Rays rk[0 .. nk) as one vector a field (lanes past nk repeat rk[0]):
 * one 8x8 transpose at 8 lanes, two joined at 16. */
KD_PINLINE void load_rays(const rt_ray *rk, int nk, kd_pf R[8])
{
    __m256 A[8];
    for (int i = 0; i < 8; i++)
        A[i] = _mm256_loadu_ps((const float *)(const void *)&rk[i < nk ? i : 0]);
    transpose8(A);
#if KD_PW == 16
    __m256 B[8];
    for (int i = 0; i < 8; i++)
        B[i] = _mm256_loadu_ps((const float *)(const void *)&rk[8 + i < nk ? 8 + i : 0]);
    transpose8(B);
    for (int f = 0; f < 8; f++)
        R[f] = (kd_pf)_mm512_insertf32x8(_mm512_castps256_ps512(A[f]), B[f], 1);
#else
    for (int f = 0; f < 8; f++)
        R[f] = (kd_pf)A[f];
#endif
}

/* kdtree_trace.c's ray set-up (ray_accept and the AVX2 ray_setup), the
 * same operations with the rays of vector k in lanes (lanes past n repeat
 * the vector's first ray, idle): origin O, reciprocal direction INV, the
 * offset MA per axis, and the interval [*TN, *TF] within the tree's
 * bounds. Returns the vector's accepted rays as bits of the packet; adds
 * the rays parallel to an axis to *parm and the negative directions to
 * negbits. */
KD_PINLINE unsigned setup_half(const rt_kdtree *tree, const rt_ray *rays, int n, int k, kd_pf O[3], kd_pf INV[3],
                               kd_pf MA[3], kd_pf *TN, kd_pf *TF, kd_pf *TMAX, unsigned *parm, unsigned negbits[3])
{
    RT_NO_FP_CONTRACT
    const kd_pf inf = psplat(INFINITY), ninf = psplat(-INFINITY), zero = psplat(0.0f);
    const rt_ray *rk = rays + KD_PW * k;
    int nk = n - KD_PW * k < KD_PW ? n - KD_PW * k : KD_PW;
    kd_pf R[8];
    load_rays(rk, nk, R);
    kd_pi ok = R[6] < R[7];
    ok &= ~((R[3] == zero) & (R[4] == zero) & (R[5] == zero));
    for (int a = 0; a < 6; a++)
        ok &= pabs(R[a]) < inf;
    kd_pf om = pmax(pmax(pabs(R[0]), pabs(R[1])), pabs(R[2]));
    kd_pf mp = (psplat(tree->scale) + om) * psplat(0x1p-18f);
    const float *blo = &tree->bounds.lo.x, *bhi = &tree->bounds.hi.x;
    kd_pf A = ninf, B = inf;
    kd_pi par = {0};
    for (int a = 0; a < 3; a++) {
        kd_pf lo = psplat(blo[a]), hi = psplat(bhi[a]);
        O[a] = R[a];
        INV[a] = psplat(1.0f) / R[3 + a];
        MA[a] = mp * pabs(INV[a]);
        kd_pi pk = ~(MA[a] < inf);
        kd_pi out = (O[a] < lo - mp) | (O[a] > hi + mp);
        ok &= ~(pk & out);
        kd_pf t0 = (lo - O[a]) * INV[a], t1 = (hi - O[a]) * INV[a];
        kd_pf ta = pmin(t1, t0) - MA[a], tb = pmax(t0, t1) + MA[a];
        A = pmax(A, psel(pk, ninf, ta));
        B = pmin(B, psel(pk, inf, tb));
        par |= pk;
        negbits[a] |= pbits(~(INV[a] > zero)) << (KD_PW * k);
    }
    *TN = pmax(R[6], A), *TF = pmin(R[7], B), *TMAX = R[7];
    ok &= *TN <= *TF;
    *parm |= pbits(par) << (KD_PW * k);
    return (pbits(ok) & (unsigned)((1ull << nk) - 1u)) << (KD_PW * k);
}

/* Vector k once the packet is accepted: its idle lanes get an empty
 * interval and no hit to improve (*BEST, and best in memory), and its
 * rays' shears go into *P for the triangle test across rays. Returns
 * whether that test applies: some ray is active and all share the shear's
 * axis kz. */
KD_PINLINE bool prepare_half(const rt_ray *rays, const rt_tri_ray *tr, unsigned active, int k, kd_pf O[3],
                             kd_pf INV[3], kd_pf MA[3], kd_pf *TN, kd_pf *TF, kd_pf TMAX, kd_pf *BEST, float *best,
                             kd_pray *P)
{
    const kd_pf inf = psplat(INFINITY), ninf = psplat(-INFINITY);
    unsigned ak = active >> (KD_PW * k) & ((1u << (KD_PW - 1)) * 2u - 1u);
    kd_pi idle = ~planes(ak);
    for (int a = 0; a < 3; a++) {
        O[a] = pand(O[a], ~idle);
        INV[a] = pand(INV[a], ~idle);
        MA[a] = pand(MA[a], ~idle);
    }
    *TN = psel(idle, inf, *TN);
    *TF = psel(idle, ninf, *TF);
    *BEST = psel(idle, ninf, TMAX);
    pstore(best + KD_PW * k, *BEST);
    if (!ak)
        return false;
    bool across = true;
    _Alignas(64) float q[9][KD_PW];
    int first = KD_PW * k + __builtin_ctz(ak);
    P->kx = tr[first].kx, P->ky = tr[first].ky, P->kz = tr[first].kz;
    for (int j = 0; j < KD_PW; j++) {
        int i = ak >> j & 1 ? KD_PW * k + j : first;
        const rt_tri_ray *t = &tr[i];
        if (t->kz != P->kz)
            across = false;
        q[0][j] = t->okx, q[1][j] = t->oky, q[2][j] = t->okz, q[3][j] = t->sx, q[4][j] = t->sy, q[5][j] = t->sz;
        q[6][j] = t->adz, q[7][j] = t->ad, q[8][j] = rays[i].tmin;
    }
    P->ox = pload(q[0]), P->oy = pload(q[1]), P->oz = pload(q[2]);
    P->sx = pload(q[3]), P->sy = pload(q[4]), P->sz = pload(q[5]);
    P->adz = pload(q[6]), P->ad = pload(q[7]), P->tmin = pload(q[8]);
    return across;
}

/* Leaf ref for each active ray whose interval [L, min(H, BEST)] crosses
 * its cell: the vectors with two or more such rays sharing kz (across)
 * primitive by primitive with the rays in lanes (vec), an instance as one
 * sub-packet of those rays (rt_kd_instance_packet), the other rays one by
 * one; with any, a ray that hits is done. Returns found with the rays
 * that hit added. */
KD_PINLINE unsigned leaf_rays(const rt_kdtree *tree, uint32_t ref, int K, bool any, unsigned active,
                              const bool *across, const kd_pray *P, const kd_pf *L, const kd_pf *H, const kd_pf *BEST,
                              const rt_ray *rays, const rt_tri_ray *tr, float *best, rt_hit *h, unsigned found)
{
    const unsigned lanes = (1u << (KD_PW - 1)) * 2u - 1u;
    unsigned m = 0, vec = 0;
    for (int k = 0; k < K; k++) {
        unsigned mk = pbits(L[k] <= pmin(H[k], BEST[k])) & (active >> (KD_PW * k) & lanes);
        if (across[k] && mk & (mk - 1))
            vec |= mk << (KD_PW * k);
        m |= mk << (KD_PW * k);
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
                unsigned vk = vec >> (KD_PW * k) & lanes, fk = 0;
                if (vk) {
                    tri_rays(tree, id, vk, &P[k], rays + KD_PW * k, tr + KD_PW * k, best + KD_PW * k,
                             h + KD_PW * k, &fk);
                    found |= fk << (KD_PW * k);
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
