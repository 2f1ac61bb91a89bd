/* kdtree_packet.c - rt_kdtree_intersect8/16 and rt_kdtree_occluded8/16: up
 * to 8 or 16 coherent rays through the kd-tree at once, with exactly the
 * answers of single rays.
 *
 * Packet traversal of kd-trees: Wald, Slusallek, Benthin and Wagner,
 * "Interactive Rendering with Coherent Ray Tracing" (Eurographics 2001),
 * and Wald's thesis (2004), ch. 7: the rays of a packet walk the tree
 * together, each with its own t interval, under an active mask; here over
 * the 64-byte wide nodes of kdtree_pack.c, with the SIMD lanes holding
 * the rays (not the 8 cells, as in the single-ray step). In a wide node
 * the 7 planes give each ray its t = (split - o) / d (one vector operation
 * a plane), and each cell each ray's interval: the parent interval cut by
 * the cell's three planes, widened by the ray's ma exactly as
 * kdtree_trace.c's step does, so every ray crosses the cells its single
 * traversal crosses, with the same intervals. The cells' front-to-back
 * order depends only on the direction signs along the planes' axes, which
 * the packet's rays share (else the packet is traced as single rays, as
 * when a ray is parallel to an axis); a cell is visited when some active
 * ray crosses it (nearest first, the rest pushed with their per-ray
 * intervals), and popped for the rays whose interval still starts before
 * their closest hit. A leaf that two or more rays reach is tested
 * primitive by primitive with the rays in the lanes (tri_rays: the
 * watertight test of intersect.h, each lane with its own ray's shear, the
 * vertices broadcast), when the rays share the shear's axis kz; else ray by
 * ray with the single-ray leaf test (kdtree_trace.c's rt_kd_leaf_hit).
 * Either way each ray gets the reference's bits, so its single-ray hit and
 * brute force's (test_packets checks it). An instance in a leaf takes the
 * rays in lanes that reached it as one sub-packet through its object's
 * tree (rt_kd_instance_packet, kdtree_instances.c; test_instance checks it
 * against the single walk and brute force). The 8 rays are set up together
 * too (kdtree_trace.c's ray set-up, the same operations with the rays in
 * lanes after an 8x8 transpose of the rt_ray records). callgrind,
 * DamagedHelmet's primary set in 4x2 tiles, against single rays: -11%
 * instructions with the leaves ray by ray and a set-up per ray, -26% with
 * tri_rays, -41% with the set-up in lanes.
 *
 * Widths. The walk is written once with GCC/clang vector types of KD_PW
 * lanes (kdtree_packet_lanes.h) and compiled twice: as this file, 16
 * lanes for AVX-512 (F, BW, DQ, VL, by a target pragma whatever the
 * build's flags), as rt_kd_packet_walk16, where a 4x4 tile of 16 rays is
 * one vector (Embree's rtcIntersect16 on the same CPUs); and by
 * kdtree_packet8.c, 8 lanes for AVX2 and FMA, as rt_kd_packet_walk8,
 * where 16 rays walk as two vectors in one walk (K = 2: each node step
 * and leaf list shared; callgrind, 4x4 tiles, against two 8-ray calls:
 * -5% instructions on DamagedHelmet, -1.5% on ReciprocatingSaw, -7% for
 * shadow rays). 8-ray packets take the 8-lane walk at either width. The
 * tree's width (rt_kdtree.lanes) is chosen once by its build: the widest
 * the CPU runs (__builtin_cpu_supports), or params.lanes; every width
 * gives the same bits, each ray its single walk's (test_kdtree and
 * test_bench_rays check every width the CPU runs). Any hit
 * (occluded8/16) is the same walk, a ray dropping out at its first hit.
 *
 * The set-up, the triangle test across rays and the leaf test are in
 * kdtree_packet_lanes.h, which the frustum walk (kdtree_frustum.c) shares.
 *
 * A tree whose rays take the portable traversal (no AVX2 on the CPU, or
 * params.portable: rt_kdtree.lanes 0) traces a packet as single rays.
 */
#include "rt/accel/kdtree_packet.h"

#include <math.h>

#include "kdtree_internal.h"

#ifdef KD_HAVE_AVX2
#include <immintrin.h>
#endif

#if !defined(KD_PW) && defined(KD_HAVE_AVX2) /* compiled as itself: the 16-lane walk, then the entry points */
#define KD_PW 16
#define KD_PACKET_WALK rt_kd_packet_walk16
#define KD_PBEGIN KD_AVX512_BEGIN
#define KD_PEND KD_AVX512_END
#endif

#ifdef KD_PW
KD_PBEGIN
#include "kdtree_packet_lanes.h"

#define KD_PSTACK 192 /* as kdtree_trace.c's stack: 7 pushes a wide level */
_Static_assert(7 * ((KD_MAX_DEPTH + 2) / 3) + 1 <= KD_PSTACK, "packet traversal stack");

/* The stack of the walk: a child reference with each vector's per-ray
 * interval. */
typedef struct kd_pstack {
    uint32_t ref[KD_PSTACK];
    kd_pf lo[KD_PSTACK * KD_PMAX], hi[KD_PSTACK * KD_PMAX];
    int sp;
} kd_pstack;

/* Wide node w for the packet: each plane's t for every ray (widened by its
 * ma), then the 8 cells back to front, as kdtree_trace.c's portable step,
 * each cut from the rays' intervals [L, min(H, BEST)] by its three planes
 * and pushed with them when some ray crosses it, so the last pushed is the
 * nearest. Returns how many were pushed. */
KD_PINLINE int push_cells(const rt_kdtree_wide *w, int K, const int neg[3], kd_pf (*O)[3], kd_pf (*INV)[3],
                          kd_pf (*MA)[3], const kd_pf *L, const kd_pf *H, const kd_pf *BEST, kd_pstack *S)
{
    RT_NO_FP_CONTRACT
    kd_pf lo[7][KD_PMAX], hi[7][KD_PMAX], hcap[KD_PMAX];
    int ng[7];
    for (int p = 0; p < 7; p++) {
        unsigned a = (w->axes >> (2 * p)) & 3u;
        kd_pf s = psplat(w->split[p]);
        for (int k = 0; k < K; k++) {
            kd_pf t = (s - O[k][a]) * INV[k][a];
            lo[p][k] = t - MA[k][a];
            hi[p][k] = t + MA[k][a];
        }
        ng[p] = neg[a];
    }
    for (int k = 0; k < K; k++)
        hcap[k] = pmin(H[k], BEST[k]);
    int pushed = 0, sp = S->sp;
    for (unsigned key = 8; key-- > 0;) {
        unsigned f0 = key >> 2 & 1u, f1 = key >> 1 & 1u, f2 = key & 1u;
        unsigned b0 = f0 ^ (unsigned)ng[0], p1 = 1 + b0, b1 = f1 ^ (unsigned)ng[p1], p2 = 3 + 2 * b0 + b1,
                 b2 = f2 ^ (unsigned)ng[p2];
        uint32_t cref = w->child[4 * b0 + 2 * b1 + b2];
        if (cref == RT_KD_EMPTY)
            continue;
        unsigned cross = 0;
        for (int k = 0; k < K; k++) {
            kd_pf l = L[k], hh = hcap[k];
            if (f0) l = pmax(lo[0][k], l); else hh = pmin(hi[0][k], hh);
            if (f1) l = pmax(lo[p1][k], l); else hh = pmin(hi[p1][k], hh);
            if (f2) l = pmax(lo[p2][k], l); else hh = pmin(hi[p2][k], hh);
            cross |= pbits(l <= hh);
            S->lo[sp * K + k] = l, S->hi[sp * K + k] = hh;
        }
        if (!cross)
            continue;
        S->ref[sp++] = cref;
        pushed++;
    }
    S->sp = sp;
    return pushed;
}

/* The one packet walk of every entry point: K vectors of KD_PW rays in
 * lanes (K = 1, or 2 for 16 rays at 8 lanes, a constant at each call; n
 * rays with KD_PW (K - 1) < n <= KD_PW K); any = occlusion: a ray is done
 * at its first hit (its lane leaves the active mask and its
 * closest-so-far becomes -inf, so no cell is entered or popped for it),
 * and hits is not written. *mask gets the rays that hit. Returns false,
 * with nothing done, when the rays cannot share the walk (their direction
 * signs differ along an axis, or one is parallel to an axis): the caller
 * traces smaller packets or single rays. */
KD_PINLINE bool packet_walk(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, int K,
                            unsigned *mask)
{
    *mask = 0;
    if (!any)
        for (int i = 0; i < n; i++)
            hits[i].prim = RT_NONE;
    if (tree->root == RT_KD_EMPTY || rt_box_is_empty(tree->bounds))
        return true;
    kd_pf O[KD_PMAX][3], INV[KD_PMAX][3], MA[KD_PMAX][3], TN[KD_PMAX], TF[KD_PMAX], TMAX[KD_PMAX];
    unsigned active = 0, parm = 0, negbits[3] = {0, 0, 0};
    for (int k = 0; k < K; k++)
        active |= setup_half(tree, rays, n, k, O[k], INV[k], MA[k], &TN[k], &TF[k], &TMAX[k], &parm, negbits);
    if (!active)
        return true;
    if (parm & active)
        return false; /* a ray parallel to an axis */
    int neg[3];
    for (int a = 0; a < 3; a++) {
        unsigned nm = negbits[a] & active;
        if (nm && nm != active)
            return false; /* the cells' order differs */
        neg[a] = nm != 0;
    }
    _Alignas(64) float best[16];
    rt_tri_ray tr[16];
    for (int i = 0; i < n; i++)
        if (active >> i & 1)
            tr[i] = rt_tri_ray_make(rays[i].org, rays[i].dir);
    kd_pray P[KD_PMAX];
    bool across[KD_PMAX];
    kd_pf BEST[KD_PMAX];
    for (int k = 0; k < K; k++)
        across[k] = prepare_half(rays, tr, active, k, O[k], INV[k], MA[k], &TN[k], &TF[k], TMAX[k], &BEST[k], best,
                                 &P[k]);
    rt_hit h[16];
    unsigned found = 0;

    kd_pstack S;
    S.sp = 0;
    uint32_t ref = tree->root;
    kd_pf L[KD_PMAX], H[KD_PMAX];
    for (int k = 0; k < K; k++)
        L[k] = TN[k], H[k] = TF[k];
    for (;;) {
        while (ref < RT_KD_LEAF) {
            if (!push_cells(&tree->wide[ref], K, neg, O, INV, MA, L, H, BEST, &S))
                goto pop;
            S.sp--; /* the nearest: enter it */
            ref = S.ref[S.sp];
            for (int k = 0; k < K; k++)
                L[k] = S.lo[S.sp * K + k], H[k] = S.hi[S.sp * K + k];
        }
        found = leaf_rays(tree, ref, K, any, active, across, P, L, H, BEST, rays, tr, best, h, found);
        unsigned done = found & active;
        if (any && done) {
            active &= ~done;
            if (!active)
                goto done;
            for (; done; done &= done - 1)
                best[__builtin_ctz(done)] = -INFINITY;
        }
        for (int k = 0; k < K; k++)
            BEST[k] = pload(best + KD_PW * k);
    pop:
        for (;;) { /* the next cell that some ray crosses before its closest hit */
            if (S.sp == 0)
                goto done;
            S.sp--;
            unsigned c = 0;
            for (int k = 0; k < K; k++)
                c |= pbits(S.lo[S.sp * K + k] <= BEST[k]) << (KD_PW * k);
            if (c & active)
                break;
        }
        ref = S.ref[S.sp];
        for (int k = 0; k < K; k++)
            L[k] = S.lo[S.sp * K + k], H[k] = S.hi[S.sp * K + k];
    }
done:
    *mask = found;
    if (!any)
        for (int i = 0; i < n; i++)
            if (found >> i & 1) {
                hits[i] = h[i];
                rt_kd_finish_hit(tree, &hits[i]);
            }
    return true;
}

/* The width's kernel (kdtree_internal.h): the walk with its constants. */
bool KD_PACKET_WALK(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, unsigned *mask)
{
#if KD_PW == 8
    if (n > KD_PW)
        return any ? packet_walk(tree, rays, n, NULL, true, 2, mask) : packet_walk(tree, rays, n, hits, false, 2, mask);
#endif
    return any ? packet_walk(tree, rays, n, NULL, true, 1, mask) : packet_walk(tree, rays, n, hits, false, 1, mask);
}
KD_PEND
#endif /* KD_PW */

#ifndef KD_PACKET_WALK_ONLY
/* The packet as single rays: closest hits into hits, or (any) occlusion. */
static unsigned single_rays(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any)
{
    unsigned mask = 0;
    for (int i = 0; i < n; i++)
        if (any ? rt_kdtree_occluded(tree, &rays[i]) : rt_kdtree_intersect(tree, &rays[i], &hits[i]))
            mask |= 1u << i;
    return mask;
}

#ifdef KD_HAVE_AVX2
#define KD_PACKETS(tree) ((tree)->isa == RT_KD_ISA_AVX2)
/* The packet kernel of the tree's width: 16 lanes for packets of more
 * than 8 rays when the tree has them, else 8. */
static bool packet_kernel(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits, bool any, unsigned *mask)
{
    if (tree->lanes == 16 && n > 8)
        return rt_kd_packet_walk16(tree, rays, n, hits, any, mask);
    return rt_kd_packet_walk8(tree, rays, n, hits, any, mask);
}
#else
#define KD_PACKETS(tree) false
#define packet_kernel(tree, rays, n, hits, any, mask) ((void)(mask), false)
#endif

/* The entry points, compiled for the build's target: the kernels when the
 * tree's rays take the AVX2 traversal and the rays can share the walk. */
unsigned rt_kdtree_intersect8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits)
{
    unsigned mask;
    if (n < 1)
        return 0;
    n = n > 8 ? 8 : n;
    if (KD_PACKETS(tree) && packet_kernel(tree, rays, n, hits, false, &mask))
        return mask;
    return single_rays(tree, rays, n, hits, false);
}

unsigned rt_kdtree_occluded8(const rt_kdtree *tree, const rt_ray *rays, int n)
{
    unsigned mask;
    if (n < 1)
        return 0;
    n = n > 8 ? 8 : n;
    if (KD_PACKETS(tree) && packet_kernel(tree, rays, n, NULL, true, &mask))
        return mask;
    return single_rays(tree, rays, n, NULL, true);
}

/* 16 rays: one walk when they share it, else as two packets of 8 (each of
 * which may go as single rays) */
unsigned rt_kdtree_intersect16(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits)
{
    unsigned mask;
    if (n <= 8)
        return rt_kdtree_intersect8(tree, rays, n, hits);
    n = n > 16 ? 16 : n;
    if (KD_PACKETS(tree) && packet_kernel(tree, rays, n, hits, false, &mask))
        return mask;
    return rt_kdtree_intersect8(tree, rays, 8, hits) | rt_kdtree_intersect8(tree, rays + 8, n - 8, hits + 8) << 8;
}

unsigned rt_kdtree_occluded16(const rt_kdtree *tree, const rt_ray *rays, int n)
{
    unsigned mask;
    if (n <= 8)
        return rt_kdtree_occluded8(tree, rays, n);
    n = n > 16 ? 16 : n;
    if (KD_PACKETS(tree) && packet_kernel(tree, rays, n, NULL, true, &mask))
        return mask;
    return rt_kdtree_occluded8(tree, rays, 8) | rt_kdtree_occluded8(tree, rays + 8, n - 8) << 8;
}
#endif /* KD_PACKET_WALK_ONLY */
