/* kdtree_stream_walk.c - the ray stream's walk through the kd-tree's wide
 * nodes, KD_STREAM_LANES rays a SIMD step.
 *
 * Sources: Wald, Gribble, Boulos, Kensler, "SIMD ray stream tracing"
 * (2007): a list of active rays per node, split by one plane test per ray
 * into the near and far children's lists; Tsakok, "Faster incoherent
 * rays: multi-BVH ray stream tracing" (HPG 2009) and Barringer and
 * Akenine-Moller, "Dynamic ray stream traversal" (SIGGRAPH 2014): the
 * lists as arrays of ray indices filtered node by node, depth first, with
 * the children's lists written above the parent's on one stack-like
 * arena, and a switch to single rays where a list thins out.
 *
 * For this tree's layout (rt/accel/kdtree.h: 64-byte wide nodes of three
 * binary levels, 7 planes and 8 cells): a list entry is a ray index with
 * the ray's t interval in the cell that listed it. At a wide node every ray
 * of the list, KD_STREAM_LANES at a time in vector lanes, cuts its interval
 * by the 7 planes level by level (the near side [l, min(h, hi)], the far
 * side [max(l, lo), h], lo and hi the plane's t widened by mp |1/d|, as in
 * kdtree_trace.c's wide step; a ray parallel to the plane's axis keeps the
 * side(s) its origin is on, within mp), so each of the 8 cells gets the
 * exact interval the single-ray walk gives it. A ray joins the list of
 * every non-empty cell whose interval is non-empty and starts no later
 * than its closest hit so far. The 8 lists are then pushed, farthest first
 * in the order of the list's first ray (mixed directions cannot share one
 * order; any order is exact, only culling depends on it), so the nearest
 * is walked next. A leaf's list: each ray whose interval still starts
 * before its closest hit runs the single-ray leaf test (kdtree_trace.c's,
 * the watertight test: exact). A node reached by fewer than min_rays rays:
 * each walks on alone from it (kdtree_trace.c's walk, from that node).
 * The arena: a node's 8 lists are written above the end of its own list,
 * the nearest (walked first) highest, each with room for the whole list
 * (and one vector more: AVX-512 compresses a cell's lanes and stores the
 * whole vector); popping a list frees everything above its end.
 *
 * A leaf of triangles reached by KD_STREAM_LEAF_LANES rays or more (8-64
 * on average on the benchmark sets) is tested ray-major instead: each of
 * its triangles against the rays in lanes (leaf_lanes, tri_lanes), with
 * the watertight test's own operations per lane. A leaf holding instances
 * reached by two or more rays sends them into each instance's object as a
 * sub-stream (kdtree_stream_instances.c).
 *
 * The answers: every primitive a ray tests is tested with the single-ray
 * test's operations on (tmin, closest so far), in the leaf's order, and the cells are culled only where the
 * single-ray walk would cull them, so a ray finds the same closest t,
 * primitive and barycentrics (on an exact tie, possibly the other
 * primitive). Every width runs the same operations per lane on the same
 * lists in the same order (lanes do not interact), so the widths agree bit
 * for bit, tie-breaks included.
 *
 * Compiled once per width, from GCC/clang vector types (intrinsics only for
 * the gathers and AVX-512's compress): as
 * itself, 16 lanes for AVX-512 (F, BW, DQ, VL, by a target pragma whatever
 * the build's flags; x86 with GCC or clang only), by kdtree_stream_walk8.c
 * (8 lanes, AVX2) and kdtree_stream_walk4.c (4 lanes, the build's target).
 * kdtree_stream.c calls only the widths the CPU has.
 */
#include "kdtree_stream_internal.h"

#include <math.h>
#include <string.h>
#if defined(KD_HAVE_AVX2)
#include <immintrin.h>
#endif

#if !defined(KD_STREAM_LANES) && defined(KD_HAVE_AVX2)
#define KD_STREAM_LANES 16
#define KD_STREAM_WALK rt_kd_stream_walk16
#define KD_STREAM_SETUP rt_kd_stream_setup16
#if defined(__clang__)
#define KD_STREAM_BEGIN _Pragma("clang attribute push (__attribute__((target(\"avx512f,avx512bw,avx512dq,avx512vl\"))), apply_to = function)")
#define KD_STREAM_END _Pragma("clang attribute pop")
#else
#define KD_STREAM_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx512f,avx512bw,avx512dq,avx512vl\")")
#define KD_STREAM_END _Pragma("GCC pop_options")
#endif
#endif

#ifdef KD_STREAM_LANES
KD_STREAM_BEGIN

#define L KD_STREAM_LANES
typedef float kd_vf __attribute__((vector_size(4 * KD_STREAM_LANES)));
typedef int32_t kd_vi __attribute__((vector_size(4 * KD_STREAM_LANES)));

#if defined(__GNUC__)
#define KD_SINLINE static inline __attribute__((always_inline))
#else
#define KD_SINLINE static inline
#endif

/* m ? a : b per lane (m: 0 or -1) */
KD_SINLINE kd_vf sel(kd_vi m, kd_vf a, kd_vf b)
{
    return (kd_vf)(((kd_vi)a & m) | ((kd_vi)b & ~m));
}
KD_SINLINE kd_vf vmin(kd_vf a, kd_vf b) { return sel(b < a, b, a); }
KD_SINLINE kd_vf vmax(kd_vf a, kd_vf b) { return sel(b > a, b, a); }
/* Lanes i of base[id[i]]: one gather instruction where the width has one
 * (the only intrinsics here), else a loop; the same values either way. */
#if KD_STREAM_LANES == 16
KD_SINLINE kd_vf gatherf(const void *base, kd_vi id) { return (kd_vf)_mm512_i32gather_ps((__m512i)id, base, 4); }
KD_SINLINE kd_vi gatheri(const void *base, kd_vi id) { return (kd_vi)_mm512_i32gather_epi32((__m512i)id, base, 4); }
#elif KD_STREAM_LANES == 8
KD_SINLINE kd_vf gatherf(const void *base, kd_vi id)
{
    return (kd_vf)_mm256_i32gather_ps((const float *)base, (__m256i)id, 4);
}
KD_SINLINE kd_vi gatheri(const void *base, kd_vi id)
{
    return (kd_vi)_mm256_i32gather_epi32((const int *)base, (__m256i)id, 4);
}
#else
KD_SINLINE kd_vf gatherf(const void *base, kd_vi id)
{
    kd_vf v = {0};
    for (int i = 0; i < L; i++)
        v[i] = ((const float *)base)[id[i]];
    return v;
}
KD_SINLINE kd_vi gatheri(const void *base, kd_vi id)
{
    kd_vi v = {0};
    for (int i = 0; i < L; i++)
        v[i] = ((const int32_t *)base)[id[i]];
    return v;
}
#endif

KD_SINLINE kd_vf splat(float x)
{
    kd_vf v = {0};
    for (int i = 0; i < L; i++)
        v[i] = x;
    return v;
}

/* One plane: the interval [l, h] cut into the below side's [bl, bh] and
 * the above side's [al, ah]; ng: the ray runs towards -axis (the above side
 * comes first). */
KD_SINLINE void cut(kd_vf l, kd_vf h, kd_vf lo, kd_vf hi, kd_vi ng, kd_vf *bl, kd_vf *bh, kd_vf *al, kd_vf *ah)
{
    kd_vf nh = vmin(h, hi), fl = vmax(l, lo);
    *bl = sel(ng, fl, l);
    *bh = sel(ng, h, nh);
    *al = sel(ng, l, fl);
    *ah = sel(ng, nh, h);
}

typedef struct kd_entry {
    uint32_t ref, count;
    size_t begin;
} kd_entry;
#define KD_STREAM_STACK (8 * ((KD_MAX_DEPTH + 2) / 3 + 2))

/* A node's 8 output lists: where each starts, how many rays it has, the
 * order they are pushed in, and what the lane steps need of the node. */
typedef struct kd_lists {
    unsigned cell_of_key[8];
    size_t out[8];
    uint32_t cnt[8];
    unsigned axis[7], used; /* the planes' axes, and which axes occur */
    int nonempty;           /* cells with a child */
} kd_lists;

/* The lists of list [b, b + n) at node w, from `top` up, `room` entries
 * each, in the cells' order for the list's first ray (keys as in
 * kdtree_trace.c's wide step: bit 2 = the far side of plane 0, ...): the
 * nearest cell's list highest, since it is walked (and freed) first. */
KD_SINLINE void lists_init(const kd_stream *s, const rt_kdtree_wide *w, size_t b, size_t top, size_t room,
                           kd_lists *nl)
{
    uint32_t rep = s->lid[b];
    unsigned ngb[7];
    nl->used = 0;
    for (int p = 0; p < 7; p++) {
        nl->axis[p] = (w->axes >> (2 * p)) & 3u;
        nl->used |= 1u << nl->axis[p];
        ngb[p] = s->inv[nl->axis[p]][rep] < 0.0f;
    }
    for (unsigned key = 0; key < 8; key++) {
        unsigned b0 = (key >> 2 & 1u) ^ ngb[0], p1 = 1 + b0, b1 = (key >> 1 & 1u) ^ ngb[p1], p2 = 3 + 2 * b0 + b1,
                 b2 = (key & 1u) ^ ngb[p2];
        unsigned c = 4 * b0 + 2 * b1 + b2;
        nl->cell_of_key[key] = c;
        nl->out[c] = top + (size_t)(7 - key) * room;
        nl->cnt[c] = 0;
    }
    nl->nonempty = 0;
    for (int c = 0; c < 8; c++)
        if (w->child[c] != RT_KD_EMPTY)
            nl->nonempty |= 1 << c;
}

/* One group of rays (lanes id, intervals [l, h], h already cut at the
 * closest hit) through the node's 7 planes: each cell's interval [lc, hc]. */
KD_SINLINE void cell_intervals(const kd_stream *s, const kd_lists *nl, const kd_vf *split, kd_vi id, kd_vf l, kd_vf h,
                               kd_vf *lc, kd_vf *hc)
{
    const kd_vf pinf = splat(INFINITY), ninf = splat(-INFINITY);
    kd_vf o[3], inv[3], ma[3], mp = splat(0.0f);
    kd_vi par[3];
    for (int k = 0; k < 3; k++) {
        if (!(nl->used >> k & 1u))
            continue;
        o[k] = gatherf(s->o[k], id);
        inv[k] = gatherf(s->inv[k], id);
        ma[k] = gatherf(s->ma[k], id);
        if (s->any_par)
            par[k] = gatheri(s->par[k], id);
    }
    if (s->any_par)
        mp = gatherf(s->mp, id);
    kd_vf lo[7], hi[7];
    kd_vi ng[7];
    for (int p = 0; p < 7; p++) {
        unsigned k = nl->axis[p];
        kd_vf t = (split[p] - o[k]) * inv[k];
        lo[p] = t - ma[k];
        hi[p] = t + ma[k];
        ng[p] = inv[k] < 0.0f;
        if (s->any_par) {
            kd_vf dist = o[k] - split[p];
            lo[p] = sel(par[k], sel(dist >= -mp, ninf, pinf), lo[p]);
            hi[p] = sel(par[k], sel(dist <= mp, pinf, ninf), hi[p]);
            ng[p] &= ~par[k];
        }
    }
    /* level by level: cell c = 4 b0 + 2 b1 + b2 */
    kd_vf l1[2], h1[2], l2[4], h2[4];
    cut(l, h, lo[0], hi[0], ng[0], &l1[0], &h1[0], &l1[1], &h1[1]);
    for (int b0 = 0; b0 < 2; b0++)
        cut(l1[b0], h1[b0], lo[1 + b0], hi[1 + b0], ng[1 + b0], &l2[2 * b0], &h2[2 * b0], &l2[2 * b0 + 1],
            &h2[2 * b0 + 1]);
    for (int q = 0; q < 4; q++)
        cut(l2[q], h2[q], lo[3 + q], hi[3 + q], ng[3 + q], &lc[2 * q], &hc[2 * q], &lc[2 * q + 1], &hc[2 * q + 1]);
}

/* The group's first m lanes join the list of every non-empty cell whose
 * interval is non-empty and starts no later than the ray's closest hit bv,
 * in lane order. */
KD_SINLINE void append_cells(kd_stream *s, kd_lists *nl, kd_vi id, size_t m, const kd_vf *lc, const kd_vf *hc,
                             kd_vf bv)
{
    uint32_t *lid = s->lid;
    float *llo = s->llo, *lhi = s->lhi;
#if KD_STREAM_LANES == 16
    /* AVX-512: each cell's rays compressed into place (a whole vector is
     * stored: the lists' room has one vector of slack) */
    __mmask16 live = (__mmask16)(m == 16 ? 0xffffu : (1u << m) - 1u);
    for (int c = 0; c < 8; c++) {
        if (!(nl->nonempty >> c & 1))
            continue;
        __mmask16 k = _mm512_movepi32_mask((__m512i)((lc[c] <= hc[c]) & (lc[c] <= bv))) & live;
        if (!k)
            continue;
        size_t pos = nl->out[c] + nl->cnt[c];
        _mm512_storeu_si512(lid + pos, _mm512_maskz_compress_epi32(k, (__m512i)id));
        _mm512_storeu_ps(llo + pos, _mm512_maskz_compress_ps(k, (__m512)lc[c]));
        _mm512_storeu_ps(lhi + pos, _mm512_maskz_compress_ps(k, (__m512)hc[c]));
        nl->cnt[c] += (uint32_t)__builtin_popcount(k);
    }
#else
    kd_vi bits = (kd_vi)splat(0.0f);
    for (int c = 0; c < 8; c++)
        if (nl->nonempty >> c & 1)
            bits |= (lc[c] <= hc[c]) & (lc[c] <= bv) & (1 << c);
    for (size_t i = 0; i < m; i++) {
        unsigned bm = (unsigned)bits[i];
        while (bm) {
            unsigned c = (unsigned)__builtin_ctz(bm);
            bm &= bm - 1u;
            size_t pos = nl->out[c] + nl->cnt[c]++;
            lid[pos] = (uint32_t)id[i];
            llo[pos] = lc[c][i];
            lhi[pos] = hc[c][i];
        }
    }
#endif
}

/* The rays of list [b, b + n) through wide node w: each joins the lists of
 * the cells it crosses, written above the list; pushes them on the stack. */
KD_SINLINE bool step(kd_stream *s, const rt_kdtree_wide *w, size_t b, size_t n, kd_entry *stack, int *sp)
{
    size_t room = n + L; /* a list's room: n, and a vector's overrun */
    if (!rt_kd_stream_reserve(s, b + n + 8 * room))
        return false;
    kd_lists nl;
    lists_init(s, w, b, b + n, room, &nl);
    kd_vf split[7];
    for (int p = 0; p < 7; p++)
        split[p] = splat(w->split[p]);
    const uint32_t *lid = s->lid;
    const float *llo = s->llo, *lhi = s->lhi;
    for (size_t j = 0; j < n; j += L) {
        size_t m = n - j < (size_t)L ? n - j : (size_t)L;
        kd_vi id;
        kd_vf l, h;
        if (m == (size_t)L) { /* vector loads (lane by lane stores, then a vector load, stall) */
            memcpy(&id, lid + b + j, sizeof id);
            memcpy(&l, llo + b + j, sizeof l);
            memcpy(&h, lhi + b + j, sizeof h);
        } else {
            for (int i = 0; i < L; i++) { /* idle lanes repeat the first ray */
                size_t e = b + j + ((size_t)i < m ? (size_t)i : 0);
                id[i] = (int32_t)lid[e];
                l[i] = llo[e];
                h[i] = lhi[e];
            }
        }
        kd_vf bv = gatherf(s->best, id), lc[8], hc[8];
        h = sel(bv < h, bv, h);
        cell_intervals(s, &nl, split, id, l, h, lc, hc);
        append_cells(s, &nl, id, m, lc, hc, bv);
    }
    for (unsigned key = 8; key-- > 0;) { /* farthest first: the nearest on top */
        unsigned c = nl.cell_of_key[key];
        if (nl.cnt[c])
            stack[(*sp)++] = (kd_entry){w->child[c], nl.cnt[c], nl.out[c]};
    }
    return true;
}


/* per lane: (k == 0 ? a : k == 1 ? b : c) */
KD_SINLINE kd_vf pick3(kd_vi k, kd_vf a, kd_vf b, kd_vf c)
{
    return sel(k == 0, a, sel(k == 1, b, c));
}

/* The rays of a leaf test as lanes: index, origin, the watertight test's
 * shear and axes (rt_tri_ray), tmin. */
typedef struct kd_lane_rays {
    kd_vi id, kx, ky, kz;
    kd_vf o[3], sx, sy, sz, adz, ad, tmin;
} kd_lane_rays;

/* Triangle tid against the lanes `live` of lr (rt_intersect_triangle_ray
 * lane by lane, see leaf_lanes): where it hits before *best, the hit
 * replaces the lane's (best, hu, hv, prim) and sets found; an occlusion
 * ray leaves `live` at its first hit. */
KD_SINLINE void tri_lanes(const kd_stream *s, uint32_t tid, const kd_lane_rays *lr, kd_vi *live, kd_vf *best,
                          kd_vf *hu, kd_vf *hv, kd_vi *prim, kd_vi *found)
{
    RT_NO_FP_CONTRACT
    const float *v = s->tree->tri + tid;
    const kd_vi kx = lr->kx, ky = lr->ky, kz = lr->kz;
    const kd_vf sx = lr->sx, sy = lr->sy, sz = lr->sz, adz = lr->adz, ad = lr->ad, tmin = lr->tmin;
    const kd_vf *o = lr->o;
    kd_vf A[3], B[3], C[3];
    for (int k = 0; k < 3; k++) {
        A[k] = splat(v[k]) - o[k];
        B[k] = splat(v[3 + k]) - o[k];
        C[k] = splat(v[6 + k]) - o[k];
    }
    kd_vf Akz = pick3(kz, A[0], A[1], A[2]), Bkz = pick3(kz, B[0], B[1], B[2]), Ckz = pick3(kz, C[0], C[1], C[2]);
    kd_vf Ax = pick3(kx, A[0], A[1], A[2]) - sx * Akz, Ay = pick3(ky, A[0], A[1], A[2]) - sy * Akz;
    kd_vf Bx = pick3(kx, B[0], B[1], B[2]) - sx * Bkz, By = pick3(ky, B[0], B[1], B[2]) - sy * Bkz;
    kd_vf Cx = pick3(kx, C[0], C[1], C[2]) - sx * Ckz, Cy = pick3(ky, C[0], C[1], C[2]) - sy * Ckz;
    kd_vf U = Cx * By - Cy * Bx, V = Ax * Cy - Ay * Cx, W = Bx * Ay - By * Ax;
    const kd_vf zero = splat(0.0f);
    kd_vi edge = *live & ((U == zero) | (V == zero) | (W == zero));
    kd_vi ok = *live & ~edge & ~(((U < zero) | (V < zero) | (W < zero)) & ((U > zero) | (V > zero) | (W > zero)));
    int any = 0;
    for (int i = 0; i < L; i++)
        any |= ok[i] | edge[i];
    if (any) {
        kd_vf det = U + V + W;
        kd_vf adet = (kd_vf)((kd_vi)det & 0x7fffffff);
        ok &= (det != zero) & (adet < splat(INFINITY));
        kd_vf T = U * (sz * Akz) + V * (sz * Bkz) + W * (sz * Ckz);
        kd_vf inv = splat(1.0f) / det;
        kd_vf t = T * inv;
        ok &= (t > tmin) & (t < *best);
        float e1[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]}, e2[3] = {v[6] - v[0], v[7] - v[1], v[8] - v[2]};
        float a1 = fabsf(e1[0]) + fabsf(e1[1]) + fabsf(e1[2]), a2 = fabsf(e2[0]) + fabsf(e2[1]) + fabsf(e2[2]);
        ok &= adet * adz / a1 / a2 > 0x1p-16f * ad;
        *best = sel(ok, t, *best);
        *hu = sel(ok, V * inv, *hu);
        *hv = sel(ok, W * inv, *hv);
        *prim = (*prim & ~ok) | ((int32_t)tid & ok);
        *found |= ok;
        for (int i = 0; i < L; i++) { /* an edge function of zero: the reference decides */
            if (!edge[i])
                continue;
            uint32_t r = (uint32_t)lr->id[i];
            float tt, uu, vv;
            if (rt_intersect_triangle_ray(&s->tr[r], rt_v3(v[0], v[1], v[2]), rt_v3(v[3], v[4], v[5]),
                                          rt_v3(v[6], v[7], v[8]), tmin[i], (*best)[i], &tt, &uu, &vv)) {
                (*best)[i] = tt, (*hu)[i] = uu, (*hv)[i] = vv, (*prim)[i] = (int32_t)tid, (*found)[i] = -1;
            }
        }
        if (s->any)
            *live &= ~*found;
    }
}

/* A leaf of triangles only (ref RT_KD_LEAF, ids below other_base) against
 * the rays of list [b, b + n), ray-major: each triangle against
 * KD_STREAM_LANES rays at once, in the leaf's order, with the watertight
 * test of intersect.h (rt_intersect_triangle_ray) lane by lane: each lane
 * its ray's shear and axis order, the same IEEE operations (the vertices
 * less the origin on all three axes, then picked by the lane's axes), and
 * the reference itself, in scalar code, for a lane whose edge function
 * rounds to zero (it recomputes those in double). A lane keeps a hit only
 * when its t is below the closest so far: the first of equal t, as the
 * single-ray leaf test. Rays whose interval starts after their closest hit
 * are left out first. */
KD_SINLINE void leaf_lanes(kd_stream *s, const uint32_t *ids, size_t b, size_t n)
{
    uint32_t keep[64];
    const size_t trs = sizeof(rt_tri_ray) / sizeof(float), rs = sizeof(rt_ray) / sizeof(float);
    for (size_t j0 = 0; j0 < n;) {
        size_t m = 0; /* up to L rays that may still hit here */
        for (; j0 < n && m < (size_t)L; j0++) {
            uint32_t i = s->lid[b + j0];
            if (s->llo[b + j0] <= s->best[i])
                keep[m++] = i;
        }
        if (m == 0)
            break;
        kd_vi id, idt, idr;
        for (int i = 0; i < L; i++)
            id[i] = (int32_t)keep[(size_t)i < m ? (size_t)i : 0];
        idt = id * (int32_t)trs;
        idr = id * (int32_t)rs;
        const rt_tri_ray *t0 = s->tr;
        kd_lane_rays lr;
        lr.id = id;
        for (int k = 0; k < 3; k++)
            lr.o[k] = gatherf(s->o[k], id);
        lr.sx = gatherf(&t0->sx, idt), lr.sy = gatherf(&t0->sy, idt), lr.sz = gatherf(&t0->sz, idt);
        lr.adz = gatherf(&t0->adz, idt), lr.ad = gatherf(&t0->ad, idt);
        lr.kx = gatheri(&t0->kx, idt), lr.ky = gatheri(&t0->ky, idt), lr.kz = gatheri(&t0->kz, idt);
        lr.tmin = gatherf(&s->ray->tmin, idr);
        kd_vf best = gatherf(s->best, id);
        kd_vi live = (kd_vi)splat(0.0f), found = live, prim = live;
        for (int i = 0; i < L; i++)
            live[i] = (size_t)i < m ? -1 : 0;
        kd_vf hu = splat(0.0f), hv = hu;
        for (const uint32_t *p = ids;; p++) {
            tri_lanes(s, *p & RT_KD_PAYLOAD, &lr, &live, &best, &hu, &hv, &prim, &found);
            if (*p & RT_KD_LAST)
                break;
        }
        for (size_t i = 0; i < m; i++) {
            if (!found[i])
                continue;
            rt_hit h = {best[i], hu[i], hv[i], (uint32_t)prim[i], 0};
            uint32_t r = (uint32_t)id[i];
            if (s->any) {
                s->best[r] = NAN;
                s->hit[r].prim = 0;
            } else {
                s->best[r] = h.t;
                s->hit[r] = h;
            }
        }
    }
}

/* Whether leaf list p holds triangles only (ids ascending: its last id is
 * below other_base). */
KD_SINLINE bool tri_leaf(const rt_kdtree *tree, const uint32_t *p)
{
    while (!(*p & RT_KD_LAST))
        p++;
    return (*p & RT_KD_PAYLOAD) < tree->other_base;
}
#define KD_STREAM_LEAF_LANES 4 /* rays a leaf list needs for the ray-major test */
#define KD_STREAM_INSTANCE_RAYS 2 /* rays a leaf list needs to enter its instances as a sub-stream */

bool KD_STREAM_WALK(kd_stream *s, size_t count)
{
    const rt_kdtree *tree = s->tree;
    if (count == 0 || tree->root == RT_KD_EMPTY)
        return true;
    kd_entry stack[KD_STREAM_STACK];
    int sp = 0;
    stack[sp++] = (kd_entry){tree->root, (uint32_t)count, 0};
    while (sp > 0) {
        kd_entry e = stack[--sp];
        if (e.ref >= RT_KD_LEAF && e.ref < RT_KD_ONE && e.count >= KD_STREAM_LEAF_LANES &&
            tri_leaf(tree, tree->prim_ids + (e.ref & RT_KD_PAYLOAD))) {
            leaf_lanes(s, tree->prim_ids + (e.ref & RT_KD_PAYLOAD), e.begin, e.count);
        } else if (e.ref >= RT_KD_LEAF && e.count >= KD_STREAM_INSTANCE_RAYS && rt_kd_leaf_has_instance(tree, e.ref)) {
            if (!rt_kd_stream_instance_leaf(s, e.ref, e.begin, e.count))
                return false;
        } else if (e.ref >= RT_KD_LEAF) {
            for (size_t k = e.begin; k < e.begin + e.count; k++) {
                uint32_t i = s->lid[k];
                if (s->llo[k] <= s->best[i])
                    rt_kd_stream_leaf(s, e.ref, i);
            }
        } else if (e.count < (uint32_t)s->min_rays || sp + 8 > KD_STREAM_STACK) { /* (the stack: never, by depth) */
            for (size_t k = e.begin; k < e.begin + e.count; k++) {
                uint32_t i = s->lid[k];
                float b = s->best[i], l = s->llo[k], h = s->lhi[k];
                if (l <= b)
                    rt_kd_stream_single(s, e.ref, i, l, h < b ? h : b);
            }
        } else if (!step(s, &tree->wide[e.ref], e.begin, e.count, stack, &sp)) {
            return false;
        }
    }
    return true;
}

/* The chunk's rays g0 .. g0 + m of the arrays, set up KD_STREAM_LANES at a
 * time: kdtree_trace.c's ray_setup (its acceptance tests, cell widening
 * mp, 1/d, parallel axes, the t interval in the tree's widened box: the
 * same IEEE operations lane by lane), the per-ray arrays at index i - g0
 * and the root list of the accepted rays; returns its length. */
size_t KD_STREAM_SETUP(kd_stream *s, const rt_ray_batch *rb, size_t g0, size_t m)
{
    const rt_kdtree *tree = s->tree;
    for (size_t i = 0; i < m; i++)
        s->hit[i].prim = RT_NONE;
    if (tree->root == RT_KD_EMPTY || rt_box_is_empty(tree->bounds))
        return 0;
    const float *blo = &tree->bounds.lo.x, *bhi = &tree->bounds.hi.x;
    const float *src[8] = {rb->ox, rb->oy, rb->oz, rb->dx, rb->dy, rb->dz, rb->tmin, rb->tmax};
    const kd_vi absmask = (kd_vi)splat(0.0f) | 0x7fffffff;
    const kd_vf pinf = splat(INFINITY), zero = splat(0.0f);
    size_t count = 0;
    for (size_t j = 0; j < m; j += L) {
        size_t n = m - j < (size_t)L ? m - j : (size_t)L;
        kd_vf v[8];
        for (int c = 0; c < 8; c++) {
            if (n == (size_t)L)
                memcpy(&v[c], src[c] + g0 + j, sizeof v[c]);
            else
                for (int i = 0; i < L; i++)
                    v[c][i] = src[c][g0 + j + ((size_t)i < n ? (size_t)i : 0)];
        }
        kd_vf *o = v, *d = v + 3, tn = v[6], tf = v[7];
        kd_vi ok = tn < tf;
        kd_vf ao[3];
        for (int k = 0; k < 3; k++) {
            ao[k] = (kd_vf)((kd_vi)o[k] & absmask);
            ok &= (ao[k] < pinf) & ((kd_vf)((kd_vi)d[k] & absmask) < pinf);
        }
        ok &= ~((d[0] == zero) & (d[1] == zero) & (d[2] == zero));
        kd_vf omax = vmax(ao[0], vmax(ao[1], ao[2]));
        kd_vf mp = (splat(tree->scale) + omax) * 0x1p-18f;
        kd_vf inv[3], ma[3];
        kd_vi par[3], anypar = ok & 0;
        for (int k = 0; k < 3; k++) {
            kd_vf iv = splat(1.0f) / d[k];
            kd_vf mk = mp * (kd_vf)((kd_vi)iv & absmask);
            kd_vi pk = ~(mk < pinf);
            ok &= ~(pk & ((o[k] < splat(blo[k]) - mp) | (o[k] > splat(bhi[k]) + mp)));
            kd_vf t0 = (splat(blo[k]) - o[k]) * iv, t1 = (splat(bhi[k]) - o[k]) * iv;
            kd_vi sw = t0 > t1;
            kd_vf a = sel(sw, t1, t0) - mk, b = sel(sw, t0, t1) + mk;
            tn = sel(~pk & (a > tn), a, tn);
            tf = sel(~pk & (b < tf), b, tf);
            inv[k] = sel(pk, zero, iv);
            ma[k] = sel(pk, zero, mk);
            par[k] = pk;
            anypar |= pk;
        }
        ok &= tn <= tf;
        /* whole vectors where the group is full (pointers in locals: the
         * stores could alias s's fields otherwise) */
        kd_vf *fv[11] = {&o[0], &o[1], &o[2], &inv[0], &inv[1], &inv[2], &ma[0], &ma[1], &ma[2], &mp, &v[7]};
        float *fd[11] = {s->o[0], s->o[1], s->o[2], s->inv[0], s->inv[1], s->inv[2], s->ma[0], s->ma[1], s->ma[2],
                         s->mp, s->best};
        for (int c = 0; c < 11; c++)
            memcpy(fd[c] + j, fv[c], n * sizeof(float));
        for (int k = 0; k < 3; k++)
            memcpy(s->par[k] + j, &par[k], n * sizeof(int32_t));
        int any = 0;
        rt_ray *rays = s->ray;
        rt_tri_ray *trs = s->tr;
        uint32_t *lid = s->lid;
        float *llo = s->llo, *lhi = s->lhi;
        for (size_t i = 0; i < n; i++) {
            if (!ok[i])
                continue;
            size_t r = j + i;
            rt_ray ray = {{o[0][i], o[1][i], o[2][i]}, {d[0][i], d[1][i], d[2][i]}, v[6][i], v[7][i]};
            rays[r] = ray;
            rt_tri_ray_init(&trs[r], ray.org, ray.dir);
            any |= anypar[i];
            lid[count] = (uint32_t)r;
            llo[count] = tn[i];
            lhi[count] = tf[i];
            count++;
        }
        s->any_par |= any != 0;
    }
    return count;
}

#undef L
KD_STREAM_END
#else
typedef int kd_stream_walk_no_avx512; /* (ISO C wants something in a file) */
#endif
