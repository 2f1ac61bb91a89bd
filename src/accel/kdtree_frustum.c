/* kdtree_frustum.c - rt_kdtree_intersect_frustum and
 * rt_kdtree_occluded_frustum: a tile of up to 64 coherent rays through the
 * kd-tree as one frustum, with exactly the answers of single rays.
 *
 * Sources: Reshetov, Soupikov and Hurley, "Multi-level ray tracing
 * algorithm" (SIGGRAPH 2005): a tile's rays are bounded by interval
 * arithmetic on their origins and directions, the tree is walked for the
 * bound instead of ray by ray, and the walk starts for the whole tile at
 * the deepest node it enters as one (the entry point); Wald's thesis
 * (2004), ch. 7, for the packet walk it replaces (kdtree_packet.c).
 *
 * The bound. The rays (set up in SIMD lanes by kdtree_packet_lanes.h, the
 * single-ray set-up's operations) must share the sign of each
 * direction component and have none parallel to an axis (else the tile
 * goes as 16-ray packets, which split such rays off as single rays). Per
 * axis the tile keeps [omin, omax] of the origins, [imin, imax] of 1/d
 * and the largest cell widening ma. A plane at s along that axis meets ray
 * i at t_i = (s - o_i) * inv_i, which the single walk widens to [t_i -
 * ma_i, t_i + ma_i]; fl(x * y) is monotone in each argument, so the
 * smallest t_i over the tile is at a corner of the box [s - omax, s -
 * omin] x [imin, imax] and the largest too (four products), and t_i - ma_i
 * >= tmin - max ma after rounding (fl(a - b) is monotone too). The tile's
 * interval in a cell [L, H] so contains every ray's interval in it as the
 * single walk computes them, and the cells' front-to-back order is the
 * single walk's (it depends only on the direction signs).
 *
 * The step. A wide node is one AVX2 step for the whole tile, whatever its
 * size: the 7 planes' ranges in lanes (the four corner products), then the
 * 8 cells' intervals in lanes and their order from kdtree_trace.c's tables,
 * as the single ray's step makes them; a cell is entered when L <= min(H,
 * the largest closest-hit-so-far of the tile's rays). The packet walk
 * spends a vector operation per plane and 8 rays instead. Entry point: the
 * walk goes down from the root one step a level while a single cell is
 * entered, so the first node that splits the tile is reached with no
 * stack traffic; that node is the tile's entry point (Reshetov et al.'s EP
 * search with the same bound), and a camera outside the scene's box enters
 * the tree there rather than at the root.
 *
 * Leaves. Each cell on the stack knows its parent node and depth; the
 * boxes of the nodes on the current path are kept one a depth, so an
 * entered cell's box is its parent's cut by its three planes. At a leaf
 * each ray's own interval in the cell is the slab test on that box with
 * the ray's widening: exactly the interval its single walk has there (the
 * tightest plane on each side of each axis is the box's, and t is monotone
 * in the plane's position). A ray is tested when that interval starts
 * before its closest hit so far, a vector of rays against each triangle
 * (tri_rays, the watertight test lane by lane with each ray's own shear)
 * when two or more rays of a vector share the shear's axis, else with the
 * single-ray leaf test. Each ray so meets the same leaves as its single
 * walk, in the same order, with the same closest hit so far, and gets its
 * single walk's answer to the bit, ties included (test_kdtree checks that
 * against rt_kdtree_intersect, and against brute force). Without the
 * per-ray intervals (every ray tested whose hit lies beyond the tile's L)
 * the leaf tests cost more than the step saves (callgrind,
 * ReciprocatingSaw primary: 1.23x the instructions of per-ray leaves on
 * 4x4 tiles, 2.2x on 8x8).
 * For occlusion a ray drops out at its first hit.
 *
 * Widths. The node step is one 8-lane step whatever the width (its lanes
 * are the node's cells); the rays' work (set-up, per-ray intervals, leaf
 * tests, the closest hits) is in vectors of KD_PW rays, written once
 * (kdtree_packet_lanes.h) and compiled twice: as this file, 16 lanes for
 * AVX-512 (rt_kd_frustum_walk16, four vectors for an 8x8 tile), and by
 * kdtree_frustum8.c, 8 lanes for AVX2 (rt_kd_frustum_walk8), chosen by
 * the tree's width (rt_kdtree.lanes, as the packets). Every width gives
 * each ray its single walk's bits. A tree whose rays take the portable
 * traversal, or a tile that cannot share the bound, goes through
 * rt_kdtree_intersect16 / rt_kdtree_occluded16 sixteen rays at a time.
 */
#include "rt/accel/kdtree_frustum.h"

#include <math.h>
#include <string.h>

#include "rt/accel/kdtree_packet.h"
#include "kdtree_internal.h"

#ifdef KD_HAVE_AVX2
#include <immintrin.h>
#endif

#if !defined(KD_PW) && defined(KD_HAVE_AVX2) /* compiled as itself: the 16-lane walk, then the entry points */
#define KD_PW 16
#define KD_FRUSTUM_WALK rt_kd_frustum_walk16
#define KD_PBEGIN KD_AVX512_BEGIN
#define KD_PEND KD_AVX512_END
#endif

#ifdef KD_PW
KD_PBEGIN
#include "kdtree_packet_lanes.h"

#define KD_FVEC (RT_KD_FRUSTUM_MAX / KD_PW) /* vectors of KD_PW rays */

#define KD_FSTACK 192 /* as kdtree_trace.c's stack: 7 pushes a wide level */
_Static_assert(7 * ((KD_MAX_DEPTH + 2) / 3) + 1 <= KD_FSTACK, "frustum traversal stack");

/* The tile's bound, per axis (lanes 0-2; the AVX2 step permutes them by
 * the planes' axes): the ranges of the origins and of 1/d, the largest
 * widening, and -1 where the rays run towards -axis. */
typedef struct kd_frustum {
    _Alignas(32) float omin[8];
    _Alignas(32) float omax[8];
    _Alignas(32) float imin[8];
    _Alignas(32) float imax[8];
    _Alignas(32) float ma[8];
    _Alignas(32) int32_t neg[8];
} kd_frustum;

#define KD_FDEPTH 32 /* wide levels: KD_MAX_DEPTH binary levels, 3 a wide node, and the root's box */
_Static_assert((KD_MAX_DEPTH + 2) / 3 + 2 <= KD_FDEPTH, "frustum box stack");

/* The walk's stack: child references with the tile's interval in each,
 * and where the cell's box comes from (the parent's wide node, the cell's
 * number in it, and the depth of the parent's box in kd_fboxes), so a
 * cell's box is made only when the cell is entered: the parent's box cut
 * by the cell's three planes. The stack only ever holds cells of nodes on
 * the path from the root to the current node, so the boxes of those
 * nodes, one a depth, are all a cell needs. */
typedef struct kd_fstack {
    uint32_t ref[KD_FSTACK + 8], cell[KD_FSTACK + 8], parent[KD_FSTACK + 8], depth[KD_FSTACK + 8];
    float lo[KD_FSTACK + 8], hi[KD_FSTACK + 8];
    int sp;
} kd_fstack;

KD_PINLINE float kd_min(float a, float b)
{
    return b < a ? b : a;
}

KD_PINLINE float kd_max(float a, float b)
{
    return b > a ? b : a;
}

/* The smallest and largest lane (SSE's min and max order). */
KD_PINLINE float hminv(kd_pf v)
{
    float m = v[0];
    for (int i = 1; i < KD_PW; i++)
        m = v[i] < m ? v[i] : m;
    return m;
}

KD_PINLINE float hmaxv(kd_pf v)
{
    float m = v[0];
    for (int i = 1; i < KD_PW; i++)
        m = v[i] > m ? v[i] : m;
    return m;
}

/* Wide node w (number node, its box at depth d) for the tile in [L, H]
 * (rays whose closest hit so far is at most bmax): the 7 planes' t ranges
 * over the tile in lanes (four corner products each, see above), then the
 * 8 cells' intervals in lanes, as kdtree_trace.c's wide_step_avx2 makes a
 * ray's (its tables give the front-to-back order from the planes' sides);
 * the cells the tile crosses are pushed farthest first, so the nearest is
 * on top. Returns how many were pushed. */
KD_PINLINE int frustum_step(const rt_kdtree_wide *w, uint32_t node, int d, const kd_frustum *F, float L, float H,
                            float bmax, kd_fstack *S)
{
    const __m256i three = _mm256_set1_epi32(3), zero = _mm256_setzero_si256();
    const __m256 ninf = _mm256_set1_ps(-INFINITY), pinf = _mm256_set1_ps(INFINITY);
    __m256 split = _mm256_load_ps((const float *)(const void *)w); /* lane 7: the axes, never selected */
    __m256i axis = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)w->axes),
                                                      _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 0)),
                                    three);
    __m256 d0 = _mm256_sub_ps(split, _mm256_permutevar8x32_ps(_mm256_load_ps(F->omax), axis));
    __m256 d1 = _mm256_sub_ps(split, _mm256_permutevar8x32_ps(_mm256_load_ps(F->omin), axis));
    __m256 i0 = _mm256_permutevar8x32_ps(_mm256_load_ps(F->imin), axis);
    __m256 i1 = _mm256_permutevar8x32_ps(_mm256_load_ps(F->imax), axis);
    __m256 ma = _mm256_permutevar8x32_ps(_mm256_load_ps(F->ma), axis);
    __m256 t00 = _mm256_mul_ps(d0, i0), t01 = _mm256_mul_ps(d0, i1), t10 = _mm256_mul_ps(d1, i0),
           t11 = _mm256_mul_ps(d1, i1);
    __m256 lo = _mm256_sub_ps(_mm256_min_ps(_mm256_min_ps(t00, t01), _mm256_min_ps(t10, t11)), ma);
    __m256 hi = _mm256_add_ps(_mm256_max_ps(_mm256_max_ps(t00, t01), _mm256_max_ps(t10, t11)), ma);
    __m256i neg = _mm256_permutevar8x32_epi32(_mm256_load_si256((const __m256i *)(const void *)F->neg), axis);
    const __m256i q1 = _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2), q2 = _mm256_setr_epi32(3, 3, 4, 4, 5, 5, 6, 6);
    unsigned nb = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(neg)) & 0x7fu;
    uint64_t order = rt_kd_cell_of_key[nb];
    __m256i key = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)rt_kd_key_of_cell[nb]));
    __m256 m0 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 29)), m1 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 30)),
           m2 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 31));
    __m256 x = _mm256_max_ps(_mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, zero), m0),
                             _mm256_max_ps(_mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, q1), m1),
                                           _mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, q2), m2)));
    __m256 y = _mm256_min_ps(_mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, zero), pinf, m0),
                             _mm256_min_ps(_mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, q1), pinf, m1),
                                           _mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, q2), pinf, m2)));
    __m256 l = _mm256_max_ps(x, _mm256_set1_ps(L)), h = _mm256_min_ps(y, _mm256_set1_ps(kd_min(H, bmax)));
    __m256i ref = _mm256_load_si256((const __m256i *)(const void *)w->child);
    __m256 ok = _mm256_andnot_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(ref, _mm256_set1_epi32(-1))),
                                 _mm256_cmp_ps(l, h, _CMP_LE_OQ));
    /* key order, farthest first: lane L of cell is the cell with key 7 - L */
    __m256i cell = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)order));
    unsigned mask = (unsigned)_mm256_movemask_ps(_mm256_permutevar8x32_ps(ok, cell));
    if (!mask)
        return 0;
    __m256i idx = _mm256_permutevar8x32_epi32(
        cell, _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(const void *)&rt_kd_compress[mask])));
    int sp = S->sp;
    _mm256_storeu_si256((__m256i *)(void *)&S->ref[sp], _mm256_permutevar8x32_epi32(ref, idx));
    _mm256_storeu_si256((__m256i *)(void *)&S->cell[sp], idx);
    _mm256_storeu_si256((__m256i *)(void *)&S->parent[sp], _mm256_set1_epi32((int)node));
    _mm256_storeu_si256((__m256i *)(void *)&S->depth[sp], _mm256_set1_epi32(d));
    _mm256_storeu_ps(&S->lo[sp], _mm256_permutevar8x32_ps(l, idx));
    _mm256_storeu_ps(&S->hi[sp], _mm256_permutevar8x32_ps(h, idx));
    int n = __builtin_popcount(mask);
    S->sp = sp + n;
    return n;
}

/* The box of cell c of wide node w whose own box is pb (lo xyz, hi xyz):
 * cut by the cell's plane at each level (b = 0: below it, 1: above). */
KD_PINLINE void cell_box(const rt_kdtree_wide *w, unsigned c, const float pb[6], float b[6])
{
    memcpy(b, pb, 6 * sizeof *b);
    unsigned b0 = c >> 2 & 1u, b1 = c >> 1 & 1u, b2 = c & 1u;
    unsigned pl[3] = {0, 1 + b0, 3 + 2 * b0 + b1}, side[3] = {b0, b1, b2};
    for (int q = 0; q < 3; q++) {
        unsigned a = (w->axes >> (2 * pl[q])) & 3u;
        float sv = w->split[pl[q]];
        if (side[q])
            b[a] = kd_max(b[a], sv);
        else
            b[3 + a] = kd_min(b[3 + a], sv);
    }
}

/* The rays' state, in vectors of KD_PW rays (vector g: rays KD_PW g ..). */
typedef struct kd_ftile {
    kd_pf O[KD_FVEC][3], INV[KD_FVEC][3], MA[KD_FVEC][3];
    kd_pf TN[KD_FVEC], TF[KD_FVEC], TMAX[KD_FVEC], BEST[KD_FVEC];
    kd_pray P[KD_FVEC];
    bool across[KD_FVEC];
    _Alignas(64) float best[RT_KD_FRUSTUM_MAX];
    rt_tri_ray tr[RT_KD_FRUSTUM_MAX];
    rt_hit h[RT_KD_FRUSTUM_MAX];
} kd_ftile;

/* Sets up the tile's rays and its bound F, and *L0, *H0 (the tile's
 * interval in the tree's box). Returns false when the rays cannot share
 * the bound (a ray parallel to an axis, or direction signs that differ);
 * else *active gets the rays that can hit something (0: none). */
KD_PINLINE bool frustum_setup(const rt_kdtree *tree, const rt_ray *rays, int n, kd_ftile *T, kd_frustum *F,
                              uint64_t *active, float *L0, float *H0)
{
    uint64_t act = 0;
    unsigned negany[3] = {0, 0, 0}, posany[3] = {0, 0, 0};
    int vecs = (n + KD_PW - 1) / KD_PW;
    for (int g = 0; g < vecs; g++) {
        unsigned parm = 0, negbits[3] = {0, 0, 0};
        unsigned ag = setup_half(tree, rays + KD_PW * g, n - KD_PW * g, 0, T->O[g], T->INV[g], T->MA[g], &T->TN[g],
                                 &T->TF[g], &T->TMAX[g], &parm, negbits);
        if (parm & ag)
            return false;
        for (int a = 0; a < 3; a++) {
            negany[a] |= negbits[a] & ag;
            posany[a] |= ~negbits[a] & ag;
        }
        act |= (uint64_t)ag << (KD_PW * g);
    }
    *active = act;
    if (!act)
        return true;
    memset(F, 0, sizeof *F);
    for (int a = 0; a < 3; a++) {
        if (negany[a] && posany[a])
            return false;
        F->neg[a] = negany[a] ? -1 : 0;
    }
    for (int i = 0; i < n; i++)
        if (act >> i & 1)
            T->tr[i] = rt_tri_ray_make(rays[i].org, rays[i].dir);
    const kd_pf inf = psplat(INFINITY), ninf = psplat(-INFINITY);
    kd_pf omin[3], omax[3], imin[3], imax[3], ma[3], tn = inf, tf = ninf;
    for (int a = 0; a < 3; a++)
        omin[a] = imin[a] = inf, omax[a] = imax[a] = ma[a] = ninf;
    const unsigned lanes = (1u << (KD_PW - 1)) * 2u - 1u;
    for (int g = 0; g < vecs; g++) {
        unsigned ag = (unsigned)(act >> (KD_PW * g)) & lanes;
        /* the lanes' values before prepare_half zeroes the idle ones */
        kd_pi m = planes(ag);
        for (int a = 0; a < 3; a++) {
            omin[a] = pmin(omin[a], psel(m, T->O[g][a], inf));
            omax[a] = pmax(omax[a], psel(m, T->O[g][a], ninf));
            imin[a] = pmin(imin[a], psel(m, T->INV[g][a], inf));
            imax[a] = pmax(imax[a], psel(m, T->INV[g][a], ninf));
            ma[a] = pmax(ma[a], psel(m, T->MA[g][a], ninf));
        }
        tn = pmin(tn, psel(m, T->TN[g], inf));
        tf = pmax(tf, psel(m, T->TF[g], ninf));
        T->across[g] = prepare_half(rays + KD_PW * g, T->tr + KD_PW * g, ag, 0, T->O[g], T->INV[g], T->MA[g],
                                    &T->TN[g], &T->TF[g], T->TMAX[g], &T->BEST[g], T->best + KD_PW * g, &T->P[g]);
    }
    for (int a = 0; a < 3; a++) {
        F->omin[a] = hminv(omin[a]), F->omax[a] = hmaxv(omax[a]);
        F->imin[a] = hminv(imin[a]), F->imax[a] = hmaxv(imax[a]);
        F->ma[a] = hmaxv(ma[a]);
    }
    *L0 = hminv(tn);
    *H0 = hmaxv(tf);
    return true;
}

/* The largest closest-hit-so-far of the tile's rays (-inf for rays that
 * are done or idle). */
KD_PINLINE float best_max(const kd_ftile *T, int vecs)
{
    kd_pf m = T->BEST[0];
    for (int g = 1; g < vecs; g++)
        m = pmax(m, T->BEST[g]);
    return hmaxv(m);
}

/* Each ray's own interval in the cell of box b (lo xyz, hi xyz) into *L
 * and *H for vector g: the slab test with the cell's widening, so exactly
 * the interval the single walk gives the ray in that cell (the tightest
 * plane on each side of each axis is the box's, and t is monotone in the
 * plane's position), cut by the ray's [tn, tf]; idle lanes get an empty
 * one. */
KD_PINLINE void ray_intervals(const kd_ftile *T, const kd_frustum *F, int g, const float b[6], kd_pf *L, kd_pf *H)
{
    RT_NO_FP_CONTRACT
    kd_pf l = T->TN[g], h = T->TF[g];
    for (int a = 0; a < 3; a++) {
        kd_pf in = psplat(b[F->neg[a] ? 3 + a : a]), out = psplat(b[F->neg[a] ? a : 3 + a]);
        l = pmax(l, (in - T->O[g][a]) * T->INV[g][a] - T->MA[g][a]);
        h = pmin(h, (out - T->O[g][a]) * T->INV[g][a] + T->MA[g][a]);
    }
    *L = l, *H = h;
}

/* The one walk of both entry points (any: occlusion, hits not written).
 * Returns false, with nothing done, when the tile cannot share the bound. */
KD_PINLINE bool frustum_walk(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any,
                             uint64_t *mask)
{
    *mask = 0;
    if (!any)
        for (int i = 0; i < n; i++)
            hits[i].prim = RT_NONE;
    if (tree->root == RT_KD_EMPTY || rt_box_is_empty(tree->bounds))
        return true;
    kd_ftile T;
    kd_frustum F;
    uint64_t active;
    float L, H;
    if (!frustum_setup(tree, rays, n, &T, &F, &active, &L, &H))
        return false;
    if (!active)
        return true;
    const unsigned lanes = (1u << (KD_PW - 1)) * 2u - 1u;
    int vecs = (n + KD_PW - 1) / KD_PW;
    float bmax = best_max(&T, vecs);
    uint64_t found = 0;
    kd_fstack S;
    S.sp = 0;
    uint32_t ref = tree->root;
    float boxes[KD_FDEPTH][6];
    boxes[0][0] = tree->bounds.lo.x, boxes[0][1] = tree->bounds.lo.y, boxes[0][2] = tree->bounds.lo.z;
    boxes[0][3] = tree->bounds.hi.x, boxes[0][4] = tree->bounds.hi.y, boxes[0][5] = tree->bounds.hi.z;
    int d = 0; /* the current cell's box is boxes[d] (when it is a node: once it is stepped) */
    for (;;) {
        while (ref < RT_KD_LEAF) {
            if (!frustum_step(&tree->wide[ref], ref, d, &F, L, H, bmax, &S))
                goto pop;
            S.sp--; /* the nearest: enter it */
            ref = S.ref[S.sp], L = S.lo[S.sp], H = S.hi[S.sp];
            d = (int)S.depth[S.sp] + 1;
            cell_box(&tree->wide[S.parent[S.sp]], S.cell[S.sp], boxes[d - 1], boxes[d]);
        }
        for (int g = 0; g < vecs; g++) {
            unsigned ag = (unsigned)(active >> (KD_PW * g)) & lanes;
            if (!ag)
                continue;
            kd_pf Lv, Hv;
            ray_intervals(&T, &F, g, boxes[d], &Lv, &Hv);
            unsigned fg = (unsigned)(found >> (KD_PW * g)) & lanes;
            fg = leaf_rays(tree, ref, 1, any, ag, &T.across[g], &T.P[g], &Lv, &Hv, &T.BEST[g], rays + KD_PW * g,
                           T.tr + KD_PW * g, T.best + KD_PW * g, T.h + KD_PW * g, fg);
            found |= (uint64_t)fg << (KD_PW * g);
        }
        if (any) {
            uint64_t done = found & active;
            if (done) {
                active &= ~done;
                if (!active)
                    goto done;
                for (; done; done &= done - 1)
                    T.best[__builtin_ctzll(done)] = -INFINITY;
            }
        }
        for (int g = 0; g < vecs; g++)
            T.BEST[g] = pload(T.best + KD_PW * g);
        bmax = best_max(&T, vecs);
    pop:
        for (;;) { /* the next cell that starts before some ray's closest hit */
            if (S.sp == 0)
                goto done;
            S.sp--;
            if (S.lo[S.sp] <= bmax)
                break;
        }
        ref = S.ref[S.sp], L = S.lo[S.sp], H = S.hi[S.sp];
        d = (int)S.depth[S.sp] + 1;
        cell_box(&tree->wide[S.parent[S.sp]], S.cell[S.sp], boxes[d - 1], boxes[d]);
    }
done:
    *mask = found;
    if (!any)
        for (int i = 0; i < n; i++)
            if (found >> i & 1) {
                hits[i] = T.h[i];
                rt_kd_finish_hit(tree, &hits[i]);
            }
    return true;
}

/* The width's kernel (kdtree_internal.h). */
bool KD_FRUSTUM_WALK(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, uint64_t *mask)
{
    return any ? frustum_walk(tree, rays, n, NULL, true, mask) : frustum_walk(tree, rays, n, hits, false, mask);
}
KD_PEND
#endif /* KD_PW */

#ifndef KD_FRUSTUM_WALK_ONLY
/* The tile as 16-ray packets. */
static uint64_t as_packets(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any)
{
    uint64_t mask = 0;
    for (int g = 0; 16 * g < n; g++) {
        int m = n - 16 * g < 16 ? n - 16 * g : 16;
        unsigned b = any ? rt_kdtree_occluded16(tree, rays + 16 * g, m)
                         : rt_kdtree_intersect16(tree, rays + 16 * g, m, hits + 16 * g);
        mask |= (uint64_t)b << (16 * g);
    }
    return mask;
}

#ifdef KD_HAVE_AVX2
#define KD_FRUSTUM(tree) ((tree)->isa == RT_KD_ISA_AVX2)
/* The frustum kernel of the tree's width. */
static bool frustum_kernel(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, uint64_t *mask)
{
    if (tree->lanes == 16)
        return rt_kd_frustum_walk16(tree, rays, n, hits, any, mask);
    return rt_kd_frustum_walk8(tree, rays, n, hits, any, mask);
}
#else
#define KD_FRUSTUM(tree) false
#define frustum_kernel(tree, rays, n, hits, any, mask) ((void)(mask), false)
#endif

uint64_t rt_kdtree_intersect_frustum(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits)
{
    uint64_t mask;
    if (n < 1)
        return 0;
    n = n > RT_KD_FRUSTUM_MAX ? RT_KD_FRUSTUM_MAX : n;
    if (KD_FRUSTUM(tree) && frustum_kernel(tree, rays, n, hits, false, &mask))
        return mask;
    return as_packets(tree, rays, n, hits, false);
}

uint64_t rt_kdtree_occluded_frustum(const rt_kdtree *tree, const rt_ray *rays, int n)
{
    uint64_t mask;
    if (n < 1)
        return 0;
    n = n > RT_KD_FRUSTUM_MAX ? RT_KD_FRUSTUM_MAX : n;
    if (KD_FRUSTUM(tree) && frustum_kernel(tree, rays, n, NULL, true, &mask))
        return mask;
    return as_packets(tree, rays, n, NULL, true);
}
#endif /* KD_FRUSTUM_WALK_ONLY */
