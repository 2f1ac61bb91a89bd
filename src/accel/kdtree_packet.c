/* kdtree_packet.c - rt_kdtree_intersect8: up to 8 coherent rays through the
 * kd-tree at once, with exactly the answers of single rays.
 *
 * Packet traversal of kd-trees: Wald, Slusallek, Benthin and Wagner,
 * "Interactive Rendering with Coherent Ray Tracing" (Eurographics 2001),
 * and Wald's thesis (2004), ch. 7: the rays of a packet walk the tree
 * together, each with its own t interval, under an active mask; here over
 * the 64-byte wide nodes of kdtree_pack.c, with the 8 AVX2 lanes holding
 * the 8 rays (not the 8 cells, as in the single-ray step). In a wide node
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
 * their closest hit. Leaves are tested ray by ray with the single-ray leaf
 * test (kdtree_trace.c's rt_kd_leaf_hit: the 8-wide watertight test), so
 * the hits are the single rays' hits, and so brute force's (the tests
 * check it).
 *
 * Without AVX2 (and under RT_KD_SCALAR) the packet is traced as single
 * rays.
 */
#include "rt/accel/kdtree_packet.h"

#include <math.h>

#include "kdtree_internal.h"

#if defined(__AVX2__) && defined(__GNUC__) && !defined(RT_KD_SCALAR)
#include <immintrin.h>
#define KD_PACKET_SIMD 1
#endif

static unsigned single_rays(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits)
{
    unsigned mask = 0;
    for (int i = 0; i < n; i++)
        if (rt_kdtree_intersect(tree, &rays[i], &hits[i]))
            mask |= 1u << i;
    return mask;
}

#ifdef KD_PACKET_SIMD
#define KD_PSTACK 192 /* as kdtree_trace.c's stack: 7 pushes a wide level */
_Static_assert(7 * ((KD_MAX_DEPTH + 2) / 3) + 1 <= KD_PSTACK, "packet traversal stack");

typedef struct kd_pentry {
    __m256 lo, hi; /* per ray: its interval in the cell (empty: not crossing) */
    uint32_t ref;
} kd_pentry;

unsigned rt_kdtree_intersect8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits)
{
    if (n < 1)
        return 0;
    if (n > 8)
        n = 8;
    _Alignas(32) float o[3][8], inv[3][8], ma[3][8], tn[8], tf[8], best[8];
    rt_tri_ray tr[8];
    unsigned active = 0;
    int neg[3] = {-1, -1, -1};
    for (int i = 0; i < 8; i++) {
        kd_ray r;
        if (i < n) {
            hits[i].prim = RT_NONE;
            if (rt_kd_ray_prepare(tree, &rays[i], &r)) {
                if (r.any_par)
                    return single_rays(tree, rays, n, hits);
                for (int k = 0; k < 3; k++) {
                    if (neg[k] == -1)
                        neg[k] = r.neg[k] & 1;
                    else if (neg[k] != (r.neg[k] & 1))
                        return single_rays(tree, rays, n, hits); /* the cells' order differs */
                    o[k][i] = r.o[k], inv[k][i] = r.inv[k], ma[k][i] = r.ma[k];
                }
                tn[i] = r.tn, tf[i] = r.tf, best[i] = rays[i].tmax, tr[i] = r.tr;
                active |= 1u << i;
                continue;
            }
        }
        for (int k = 0; k < 3; k++) /* an idle lane: an empty interval */
            o[k][i] = 0.0f, inv[k][i] = 0.0f, ma[k][i] = 0.0f;
        tn[i] = INFINITY, tf[i] = -INFINITY, best[i] = -INFINITY;
    }
    if (!active)
        return 0;
    for (int k = 0; k < 3; k++)
        neg[k] = neg[k] == 1; /* axes no active ray has: any order */
    __m256 O[3], INV[3], MA[3];
    for (int k = 0; k < 3; k++)
        O[k] = _mm256_load_ps(o[k]), INV[k] = _mm256_load_ps(inv[k]), MA[k] = _mm256_load_ps(ma[k]);
    __m256 BEST = _mm256_load_ps(best);
    rt_hit h[8];
    unsigned found = 0;

    kd_pentry stack[KD_PSTACK];
    int sp = 0;
    uint32_t ref = tree->root;
    __m256 L = _mm256_load_ps(tn), H = _mm256_load_ps(tf);
    for (;;) {
        while (ref < RT_KD_LEAF) {
            const rt_kdtree_wide *w = &tree->wide[ref];
            __m256 lo[7], hi[7];
            int ng[7];
            for (int p = 0; p < 7; p++) {
                unsigned k = (w->axes >> (2 * p)) & 3u;
                __m256 t = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(w->split[p]), O[k]), INV[k]);
                lo[p] = _mm256_sub_ps(t, MA[k]);
                hi[p] = _mm256_add_ps(t, MA[k]);
                ng[p] = neg[k];
            }
            __m256 hcap = _mm256_min_ps(H, BEST);
            /* back to front, as kdtree_trace.c's portable step: the last
             * cell found is the nearest */
            int pushed = 0;
            for (unsigned key = 8; key-- > 0;) {
                unsigned f0 = key >> 2 & 1u, f1 = key >> 1 & 1u, f2 = key & 1u;
                unsigned b0 = f0 ^ (unsigned)ng[0], p1 = 1 + b0, b1 = f1 ^ (unsigned)ng[p1], p2 = 3 + 2 * b0 + b1,
                         b2 = f2 ^ (unsigned)ng[p2];
                uint32_t cref = w->child[4 * b0 + 2 * b1 + b2];
                if (cref == RT_KD_EMPTY)
                    continue;
                __m256 l = L, hh = hcap;
                if (f0) l = _mm256_max_ps(lo[0], l); else hh = _mm256_min_ps(hi[0], hh);
                if (f1) l = _mm256_max_ps(lo[p1], l); else hh = _mm256_min_ps(hi[p1], hh);
                if (f2) l = _mm256_max_ps(lo[p2], l); else hh = _mm256_min_ps(hi[p2], hh);
                if (!_mm256_movemask_ps(_mm256_cmp_ps(l, hh, _CMP_LE_OQ)))
                    continue;
                stack[sp].lo = l, stack[sp].hi = hh, stack[sp].ref = cref;
                sp++;
                pushed++;
            }
            if (!pushed)
                goto pop;
            sp--; /* the nearest: enter it */
            ref = stack[sp].ref, L = stack[sp].lo, H = stack[sp].hi;
        }
        {
            /* a leaf: each ray that crosses its cell */
            unsigned m = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(L, _mm256_min_ps(H, BEST), _CMP_LE_OQ)) & active;
            _mm256_store_ps(best, BEST);
            while (m) {
                int i = __builtin_ctz(m);
                m &= m - 1;
                if (rt_kd_leaf_hit(tree, ref, &rays[i], &tr[i], &best[i], &h[i]))
                    found |= 1u << i;
            }
            BEST = _mm256_load_ps(best);
        }
    pop:
        for (;;) { /* the next cell that some ray crosses before its closest hit */
            if (sp == 0)
                goto done;
            sp--;
            if (_mm256_movemask_ps(_mm256_cmp_ps(stack[sp].lo, BEST, _CMP_LE_OQ)) & active)
                break;
        }
        ref = stack[sp].ref, L = stack[sp].lo, H = stack[sp].hi;
    }
done:
    for (int i = 0; i < n; i++)
        if (found >> i & 1) {
            hits[i] = h[i];
            hits[i].prim = rt_kdtree_scene_prim(tree, h[i].prim);
        }
    return found;
}
#else
unsigned rt_kdtree_intersect8(const rt_kdtree *tree, const rt_ray *rays, int n, rt_hit *hits)
{
    return single_rays(tree, rays, n > 8 ? 8 : n, hits);
}
#endif
