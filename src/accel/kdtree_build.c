/* kdtree.c - SAH kd-tree: O(N log N) build with perfect splits, and
 * front-to-back traversal that returns bit-exact closest hits.
 *
 * Build: Wald and Havran, "On building fast kd-Trees for Ray Tracing, and on
 * doing that in O(N log N)", IEEE Symposium on Interactive Ray Tracing 2006
 * (section 4: event sorting). Each node holds, per axis, a list of events
 * sorted once at the root by (position, type), type END < PLANAR < START:
 * a primitive whose (clipped) bounds on axis k are [a, b] has START at a and
 * END at b, or one PLANAR event when a == b. One linear sweep per axis gives
 * for every candidate plane p the counts N_L (left of p), N_P (in p) and
 * N_R (right of p), and the plane cost
 *
 *   C(p) = lambda(p) * (K_T + K_I * (P_L * N_L' + P_R * N_R'))
 *   P_L  = SA(V_L) / SA(V),  P_R = SA(V_R) / SA(V)   (surface area heuristic,
 *          MacDonald and Booth 1990: probability that a ray through V
 *          crosses the child)
 *
 * with the planar primitives put on the cheaper side (N_L' = N_L + N_P or
 * N_R' = N_R + N_P), and lambda(p) = 1 - empty_bonus when one side is empty
 * (the empty-space bonus), else 1. Only planes strictly inside V count
 * (so no zero-volume cells are cut off again and again). The node becomes a
 * leaf when the best C(p) is not below the leaf cost K_I * N, or at the depth
 * limit (default 8 + 1.3 log2 N, as pbrt). Defaults: K_T = 4, K_I = 1,
 * empty_bonus = 0.2 (the paper's lambda = 0.8). Measured on the shared
 * benchmark rays (DamagedHelmet, ReciprocatingSaw, MetalRoughSpheres), the
 * paper's K_T = 15, K_I = 20 traced no faster but made 7 nodes and 5
 * references per triangle (115 bytes/triangle); K_T / K_I from 2 to 5 all
 * trace at the same speed within noise, and 4 gives 50-56 bytes a triangle
 * (tree + triangles) and the faster build.
 * Splitting classifies each primitive as left, right or both in one pass over
 * the chosen axis' events; the event lists of left-only and right-only
 * primitives are filtered into the children keeping their order, and only the
 * straddling primitives get new events: each is clipped against the child
 * box (Sutherland-Hodgman in double precision, bounds rounded outwards:
 * "perfect splits", Havran's thesis 2000, section 4.5), the few new events
 * sorted and merged in. Hence O(N log N) overall. The root lists are sorted
 * by an LSD radix sort on 64-bit event keys (position bits, type, primitive).
 * With more than one build thread (params->threads; default one per online
 * CPU) the top levels fork: a below child's subtree is built by a new
 * thread into its own arrays while the above child is built here, down to
 * about 4 concurrent subtrees per thread, and the pieces are spliced into
 * depth-first order afterwards: the tree is bit-identical for any thread
 * count.
 *
 * Layout: the build makes 8-byte nodes in depth-first order (below child =
 * next node, above child index in the node; see kdtree.h) and leaf id lists
 * in a second array. Triangles are stored as v0, e1 = v1 - v0, e2 = v2 - v0
 * (computed exactly as the reference tests do, so t is bit-identical to
 * testing the scene's triangle directly) plus their scene id, 10 floats.
 * After the build the triangles are renumbered in the order the
 * depth-first leaves first use them and stored in that order, so a leaf's
 * triangles mostly share cache lines: on the 1M-triangle model +15-30%
 * rays/s (profile: ~40% of the time was the first triangle gather waiting
 * on memory); the scene id in the same record spares the hit a last cache
 * miss into a separate map. Arrays over 2 MB go on transparent huge pages
 * (madvise): +5-15% there, the TLB no longer misses on every node.
 *
 * Wide nodes: for tracing, the binary tree is then packed three levels at a
 * time into 64-byte, cache-line-aligned nodes (rt_kdtree_wide: 7 planes, 8
 * cells, a reference per cell to a wide node, a leaf or nothing; missing
 * planes below a leaf are +inf), in depth-first order. Leaf lists end with
 * a flag on the last id. The binary node loop cost ~20 cycles a level on
 * incoherent rays (a load, then a mispredicted choice of child), and on the
 * 1M-triangle model every other level missed the cache; a wide node costs
 * one line for three levels and one SIMD step (see "Traversal").
 *
 * Leaves with 3 or more triangles are tested 8 at a time with AVX2 (when
 * compiled for it): the same IEEE operations per lane as the scalar
 * Moeller-Trumbore of intersect.h, so the same bits (tests check it). The
 * eight triangles are loaded with one unaligned 8-float load each and an
 * 8x8 transpose, plus one gather for the ninth float: nine gathers were the
 * hottest instructions in the profile (+10-30% rays/s without them).
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
 * Without AVX2 (or with RT_KD_SCALAR, which the tests build too) the same
 * step runs as plain loops.
 *
 * Measured and not kept (docs/performance.md has the numbers): leaves whose
 * triangles got consecutive numbers stored as a range without an id list
 * (too few such leaves: 54.2 -> 54.0 bytes/triangle, no speed change); the
 * watertight triangle test of Woop, Benthin and Wald 2013 (zero mismatches
 * against Embree on every set, but -10 to -17% rays/s on diffuse rays with
 * the per-ray shear set-up and the permuted gathers); K_T 1.5-6, empty bonus
 * 0.2-0.8 and depth limits up to 50 (no gain on both ray kinds); the 8-wide
 * test from 2 or 5 triangles instead of 3; huge pages for the build's event
 * arrays (no faster). With the wide nodes: a SAH leaf cost in steps of 8
 * primitives (the 8-wide test) with K_T 2-8; packing subtrees of at most 8
 * primitives into one leaf (-0.4 bytes/triangle, a little slower
 * everywhere); prefetching the cell on top of the stack (-12% on
 * DamagedHelmet diffuse); the leaf test out of line.
 */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* madvise */
#endif
#include "rt/accel/kdtree.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

/* The arrays the traversal reads, when large, go on 2 MB pages where the
 * system allows (Linux transparent huge pages in "madvise" mode): rays
 * through a million-triangle scene touch tens of MB at random, and with
 * 4 KB pages most of those cache misses also miss the TLB. Smaller arrays
 * are cache-line aligned. Free with free(). */
#define KD_HUGE ((size_t)2 << 20)
static void *alloc_hot(size_t size)
{
    void *p = NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (size >= KD_HUGE) {
        size_t rounded = (size + KD_HUGE - 1) & ~(KD_HUGE - 1);
        if (posix_memalign(&p, KD_HUGE, rounded) != 0)
            return NULL;
        (void)madvise(p, rounded, MADV_HUGEPAGE); /* advice only: failure leaves 4 KB pages */
        return p;
    }
#endif
    /* cache-line aligned: a wide node must sit in one line */
    return posix_memalign(&p, 64, size ? size : 64) == 0 ? p : NULL;
}

/* ------------------------------------------------------------- events */

enum { EV_END = 0, EV_PLANAR = 1, EV_START = 2 };
enum { SIDE_BOTH = 0, SIDE_LEFT = 1, SIDE_RIGHT = 2 };
#define PRIM_BITS 30
#define PRIM_MASK ((1u << PRIM_BITS) - 1u)
#define KD_STACK 64
#define KD_MAX_DEPTH 60
_Static_assert(KD_MAX_DEPTH < KD_STACK, "one stack entry per level at most");
#define LEAF_TAG 3u
/* Interior nodes: b = axis | empty-child flags << 2 | above child << 4. */
#define KD_BELOW_EMPTY 4u
#define KD_ABOVE_EMPTY 8u
#define KD_INDEX_BITS 28
#define KD_MAX_NODES ((size_t)1 << (KD_INDEX_BITS - 1)) /* per builder; stitching adds them up */
#define KD_MAX_IDS ((size_t)UINT32_MAX)
/* Below this many primitives the build stays on one thread. 4096: with the
 * second core free, DamagedHelmet (15k triangles) builds in 21-24 ms with 2
 * threads against 30-36 ms with 1 (20000 before, measured under load). */
#define KD_FORK_MIN_PRIMS 4096

/* Event = ordered position bits << 32 | type << 30 | primitive: sorting the
 * integers sorts by (position, type). */
static inline uint32_t f2o(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}
static inline float o2f(uint32_t o)
{
    uint32_t u = (o & 0x80000000u) ? (o & 0x7fffffffu) : ~o;
    float f;
    memcpy(&f, &u, 4);
    return f;
}
static inline uint64_t ev_make(float pos, unsigned type, uint32_t prim)
{
    pos += 0.0f; /* -0 -> +0: one plane, one key */
    return ((uint64_t)f2o(pos) << 32) | ((uint64_t)type << PRIM_BITS) | prim;
}
static inline uint32_t ev_key(uint64_t e) { return (uint32_t)(e >> 32); }
static inline unsigned ev_type(uint64_t e) { return (unsigned)(e >> PRIM_BITS) & 3u; }
static inline uint32_t ev_prim(uint64_t e) { return (uint32_t)e & PRIM_MASK; }

/* Sorts events by (position, type); tmp has room for n. */
static void ev_sort(uint64_t *a, size_t n, uint64_t *tmp)
{
    if (n < 64) {
        for (size_t i = 1; i < n; i++) {
            uint64_t x = a[i];
            size_t j = i;
            while (j > 0 && (a[j - 1] >> PRIM_BITS) > (x >> PRIM_BITS)) {
                a[j] = a[j - 1];
                j--;
            }
            a[j] = x;
        }
        return;
    }
    static const int shift[3] = {30, 41, 52}, bits[3] = {11, 11, 12};
    uint64_t *src = a, *dst = tmp;
    size_t count[4096];
    for (int pass = 0; pass < 3; pass++) {
        size_t radix = (size_t)1 << bits[pass], mask = radix - 1;
        memset(count, 0, radix * sizeof count[0]);
        for (size_t i = 0; i < n; i++)
            count[(src[i] >> shift[pass]) & mask]++;
        if (count[(src[0] >> shift[pass]) & mask] == n)
            continue; /* every key shares this digit */
        size_t sum = 0;
        for (size_t r = 0; r < radix; r++) {
            size_t c = count[r];
            count[r] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            dst[count[(src[i] >> shift[pass]) & mask]++] = src[i];
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    if (src != a)
        memcpy(a, src, n * sizeof *a);
}

/* ------------------------------------------------------------ clipping */

/* The float next to finite-or-infinite f towards -inf / +inf (nextafterf
 * without the library call). */
static inline float float_down(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    if (f == 0.0f)
        u = 0x80000001u; /* -smallest subnormal */
    else
        u = f > 0.0f ? u - 1 : u + 1;
    memcpy(&f, &u, 4);
    return f;
}
static inline float float_up(float f) { return -float_down(-f); }

/* x rounded to a float below / above it (outwards, for conservative bounds). */
static inline float round_down(double x)
{
    float f = (float)x;
    return (double)f > x ? float_down(f) : f;
}
static inline float round_up(double x)
{
    float f = (float)x;
    return (double)f < x ? float_up(f) : f;
}

#define POLY_MAX 40

/* Sutherland-Hodgman: keeps the part of polygon `in` with sign * (x_k - c) >= 0. */
static int clip_plane(double (*in)[3], int n, double (*out)[3], int k, double c, double sign)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = in[i], *b = in[i + 1 == n ? 0 : i + 1];
        double da = sign * (a[k] - c), db = sign * (b[k] - c);
        if (da >= 0.0) {
            if (m >= POLY_MAX)
                return -1;
            memcpy(out[m++], a, sizeof(double[3]));
        }
        if ((da >= 0.0) != (db >= 0.0)) {
            if (m >= POLY_MAX)
                return -1;
            double t = da / (da - db);
            for (int j = 0; j < 3; j++)
                out[m][j] = a[j] + (b[j] - a[j]) * t;
            out[m][k] = c;
            m++;
        }
    }
    return m;
}

/* ------------------------------------------------------------- build */

/* Parallel build: near the root (depth < fork_depth) the below child's
 * subtree is handed to a new thread, building into its own arrays, while
 * this thread builds the above child; the parent keeps a placeholder node
 * that is replaced by the subtree when everything is stitched together in
 * depth-first order. So the tree is identical for any number of threads. */
typedef struct kd_fork kd_fork;

typedef struct kd_build {
    const rt_scene *s;
    uint32_t T, S, Q;
    double kt, ki, lambda;
    int max_depth;
    uint8_t *side;   /* per primitive, during one split */
    uint32_t *strad; /* straddling primitives of the current split */
    size_t strad_cap;
    rt_kdtree_node *nodes;
    size_t node_count, node_cap;
    uint32_t *ids;
    size_t id_count, id_cap;
    rt_kdtree_stats st;
    bool oom, limit; /* limit: the tree outgrew the node format (reported as RT_ERR_LIMIT) */
    int fork_depth;       /* fork below children above this depth */
    size_t fork_min;      /* ... of at least this many primitives */
    size_t nprims_total;  /* length of a side array */
    kd_fork **forks;      /* subtrees built by other threads (stable addresses) */
    size_t fork_count, fork_cap;
} kd_build;

struct kd_fork {
    kd_build out; /* the subtree's nodes, ids, stats and its own forks */
    rt_box V;
    uint64_t *ev;
    size_t cnt[3], nprims;
    int depth;
};

#define TASK_MARK (LEAF_TAG | (0x3fffffffu << 2)) /* placeholder leaf: a = fork index */

static inline float *box_lo(rt_box *b) { return &b->lo.x; }
static inline float *box_hi(rt_box *b) { return &b->hi.x; }

/* Bounds of the part of primitive `prim` inside `box` (tight for triangles
 * and quads, box-intersected for spheres); false when nothing is inside. */
static bool prim_clip_bounds(const kd_build *c, uint32_t prim, rt_box box, rt_box *out)
{
    const rt_scene *s = c->s;
    double poly[2][POLY_MAX][3];
    double lo[3], hi[3];
    int n = 0;
    const float *bl = &box.lo.x, *bh = &box.hi.x;
    if (prim < c->T) {
        for (int v = 0; v < 3; v++) {
            rt_vec3 p = rt_tri_vertex(s, prim, v);
            poly[0][v][0] = p.x, poly[0][v][1] = p.y, poly[0][v][2] = p.z;
        }
        n = 3;
    } else if (prim < c->T + c->S) {
        uint32_t i = prim - c->T;
        const rt_spheres *sp = &s->spheres;
        double cc[3] = {sp->cx[i], sp->cy[i], sp->cz[i]}, r = fabs((double)sp->radius[i]);
        for (int k = 0; k < 3; k++) {
            lo[k] = cc[k] - r;
            hi[k] = cc[k] + r;
        }
    } else {
        uint32_t i = prim - c->T - c->S;
        const rt_quads *q = &s->quads;
        double p[3] = {q->px[i], q->py[i], q->pz[i]}, u[3] = {q->ux[i], q->uy[i], q->uz[i]},
               v[3] = {q->vx[i], q->vy[i], q->vz[i]};
        for (int k = 0; k < 3; k++) {
            poly[0][0][k] = p[k];
            poly[0][1][k] = p[k] + u[k];
            poly[0][2][k] = p[k] + u[k] + v[k];
            poly[0][3][k] = p[k] + v[k];
        }
        n = 4;
    }
    if (n > 0) {
        int cur = 0;
        for (int k = 0; k < 3 && n > 0; k++) {
            n = clip_plane(poly[cur], n, poly[cur ^ 1], k, bl[k], 1.0);
            cur ^= 1;
            if (n > 0) {
                n = clip_plane(poly[cur], n, poly[cur ^ 1], k, bh[k], -1.0);
                cur ^= 1;
            }
        }
        if (n < 0) { /* cannot happen for a convex polygon; stay conservative */
            for (int k = 0; k < 3; k++)
                lo[k] = -INFINITY, hi[k] = INFINITY;
        } else if (n == 0) {
            return false;
        } else {
            for (int k = 0; k < 3; k++)
                lo[k] = hi[k] = poly[cur][0][k];
            for (int j = 1; j < n; j++)
                for (int k = 0; k < 3; k++) {
                    double x = poly[cur][j][k];
                    lo[k] = x < lo[k] ? x : lo[k];
                    hi[k] = x > hi[k] ? x : hi[k];
                }
        }
    }
    float *ol = &out->lo.x, *oh = &out->hi.x;
    for (int k = 0; k < 3; k++) {
        float l = round_down(lo[k]), h = round_up(hi[k]);
        ol[k] = l > bl[k] ? l : bl[k];
        oh[k] = h < bh[k] ? h : bh[k];
        if (!(ol[k] <= oh[k]))
            return false;
    }
    return true;
}

/* Appends the events of one box to the three per-axis lists. */
static inline void emit_events(rt_box b, uint32_t prim, uint64_t *list[3], size_t n[3])
{
    const float *lo = &b.lo.x, *hi = &b.hi.x;
    for (int k = 0; k < 3; k++) {
        if (lo[k] == hi[k]) {
            list[k][n[k]++] = ev_make(lo[k], EV_PLANAR, prim);
        } else {
            list[k][n[k]++] = ev_make(lo[k], EV_START, prim);
            list[k][n[k]++] = ev_make(hi[k], EV_END, prim);
        }
    }
}

static uint32_t push_node(kd_build *c)
{
    if (c->node_count >= KD_MAX_NODES) { /* 28 bits of child index */
        c->oom = c->limit = true;
        return 0;
    }
    if (!rt_grow((void **)&c->nodes, &c->node_cap, c->node_count + 1, sizeof *c->nodes)) {
        c->oom = true;
        return 0;
    }
    c->nodes[c->node_count].a = 0;
    c->nodes[c->node_count].b = LEAF_TAG;
    return (uint32_t)c->node_count++;
}

static void make_leaf(kd_build *c, uint32_t node, const uint64_t *ev0, size_t n0, size_t nprims, int depth)
{
    rt_kdtree_node *nd = &c->nodes[node];
    c->st.leaves++;
    if (depth > c->st.depth)
        c->st.depth = depth;
    if (nprims > c->st.max_leaf_prims)
        c->st.max_leaf_prims = nprims;
    c->st.prim_refs += nprims;
    if (nprims == 0) {
        c->st.empty_leaves++;
        nd->a = 0;
        nd->b = LEAF_TAG;
        return;
    }
    if (nprims == 1) {
        for (size_t i = 0; i < n0; i++)
            if (ev_type(ev0[i]) != EV_END) {
                nd->a = ev_prim(ev0[i]);
                break;
            }
        nd->b = LEAF_TAG | (1u << 2);
        return;
    }
    if (c->id_count + nprims > KD_MAX_IDS) {
        c->oom = c->limit = true;
        return;
    }
    if (!rt_grow((void **)&c->ids, &c->id_cap, c->id_count + nprims, sizeof *c->ids)) {
        c->oom = true;
        return;
    }
    nd = &c->nodes[node];
    uint32_t *dst = c->ids + c->id_count;
    size_t m = 0;
    for (size_t i = 0; i < n0 && m < nprims; i++)
        if (ev_type(ev0[i]) != EV_END) {
            uint32_t p = ev_prim(ev0[i]);
            size_t j = m++; /* insertion sort: ascending ids, triangles first */
            while (j > 0 && dst[j - 1] > p) {
                dst[j] = dst[j - 1];
                j--;
            }
            dst[j] = p;
        }
    nd->a = (uint32_t)c->id_count;
    nd->b = LEAF_TAG | ((uint32_t)m << 2);
    c->id_count += m;
}

/* Merges sorted `add` (na) into the sorted prefix dst[0..nd) of dst, which
 * has room for nd + na, from the back. */
static void merge_back(uint64_t *dst, size_t nd, const uint64_t *add, size_t na)
{
    size_t i = nd, j = na, k = nd + na;
    while (j > 0) {
        if (i > 0 && (dst[i - 1] >> PRIM_BITS) > (add[j - 1] >> PRIM_BITS))
            dst[--k] = dst[--i];
        else
            dst[--k] = add[--j];
    }
}

/* Best SAH plane of a node (section 4.2 of Wald and Havran): one sweep per
 * axis over its sorted events. Returns the cost, INFINITY when no plane. */
static double find_plane(const kd_build *c, rt_box V, uint64_t *const list[3], const size_t cnt[3], size_t nprims,
                         int *best_k, uint32_t *best_key, int *best_side)
{
    const float *vlo = &V.lo.x, *vhi = &V.hi.x;
    double ext[3] = {(double)vhi[0] - vlo[0], (double)vhi[1] - vlo[1], (double)vhi[2] - vlo[2]};
    double area = 2.0 * (ext[0] * ext[1] + ext[1] * ext[2] + ext[2] * ext[0]);
    double best = INFINITY;
    if (!(area > 0.0) || !isfinite(area))
        return best;
    /* cost = kt + ki * (PL * nl + PR * nr) = kt + (2 ki / area) * ((ab + dl (a+b)) nl + (ab + dr (a+b)) nr) */
    double scale = 2.0 * c->ki / area, kt = c->kt, lambda = c->lambda;
    for (int k = 0; k < 3; k++) {
        if (!(vlo[k] < vhi[k]))
            continue;
        double a = ext[(k + 1) % 3], b = ext[(k + 2) % 3], ab = a * b, apb = a + b;
        uint32_t lo_key = f2o(vlo[k] + 0.0f), hi_key = f2o(vhi[k] + 0.0f);
        const uint64_t *E = list[k];
        size_t n = cnt[k], nl = 0, nr = nprims;
        double lo = vlo[k], hi = vhi[k];
        for (size_t i = 0; i < n;) {
            uint64_t e = E[i];
            uint32_t key = ev_key(e);
            size_t pe, pp, ps;
            if (i + 1 == n || ev_key(E[i + 1]) != key) { /* the usual lone event */
                unsigned t = ev_type(e);
                pe = t == EV_END, pp = t == EV_PLANAR, ps = t == EV_START;
                i++;
            } else {
                pe = pp = ps = 0;
                while (i < n && ev_key(E[i]) == key && ev_type(E[i]) == EV_END)
                    pe++, i++;
                while (i < n && ev_key(E[i]) == key && ev_type(E[i]) == EV_PLANAR)
                    pp++, i++;
                while (i < n && ev_key(E[i]) == key && ev_type(E[i]) == EV_START)
                    ps++, i++;
            }
            nr -= pp + pe;
            if (key > lo_key && key < hi_key) {
                double p = (double)o2f(key);
                double wl = ab + (p - lo) * apb, wr = ab + (hi - p) * apb;
                size_t nl1 = nl + pp; /* planar ones left */
                double c1 = kt + scale * (wl * (double)(int64_t)nl1 + wr * (double)(int64_t)nr);
                if (nl1 == 0 || nr == 0)
                    c1 *= lambda;
                if (c1 < best) {
                    best = c1, *best_k = k, *best_key = key, *best_side = SIDE_LEFT;
                }
                if (pp > 0) { /* planar ones right */
                    size_t nr2 = nr + pp;
                    double c2 = kt + scale * (wl * (double)(int64_t)nl + wr * (double)(int64_t)nr2);
                    if (nl == 0 || nr2 == 0)
                        c2 *= lambda;
                    if (c2 < best) {
                        best = c2, *best_k = k, *best_key = key, *best_side = SIDE_RIGHT;
                    }
                }
            }
            nl += ps + pp;
        }
    }
    return best;
}

static void build_rec(kd_build *c, rt_box V, uint64_t *ev, size_t cnt[3], size_t nprims, int depth);

static void *fork_worker(void *arg);
static void free_forks(kd_build *c);

/* Builds the subtree of box V from its event lists (one block `ev`, lists of
 * cnt[0], cnt[1], cnt[2] events, owned and freed here) over nprims prims. */
static void build_rec(kd_build *c, rt_box V, uint64_t *ev, size_t cnt[3], size_t nprims, int depth)
{
    uint32_t node = push_node(c);
    if (c->oom) {
        free(ev);
        return;
    }
    uint64_t *list[3] = {ev, ev + cnt[0], ev + cnt[0] + cnt[1]};
    int k = -1, best_side = SIDE_LEFT;
    uint32_t best_key = 0;
    double best = INFINITY;
    if (nprims > 1 && depth < c->max_depth)
        best = find_plane(c, V, list, cnt, nprims, &k, &best_key, &best_side);
    if (k < 0 || !(best < c->ki * (double)nprims)) {
        make_leaf(c, node, list[0], cnt[0], nprims, depth);
        free(ev);
        return;
    }

    /* classify in one pass over axis k (events of a primitive come in the
     * order START, END): left, right, or both (a straddler) */
    uint8_t *side = c->side;
    const uint64_t *E = list[k];
    size_t n = cnt[k], ns = 0;
    if (!rt_grow((void **)&c->strad, &c->strad_cap, nprims, sizeof *c->strad)) {
        c->oom = true;
        free(ev);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        uint64_t e = E[i];
        uint32_t key = ev_key(e), p = ev_prim(e);
        unsigned t = ev_type(e);
        if (t == EV_START) {
            side[p] = key >= best_key ? SIDE_RIGHT : SIDE_BOTH;
        } else if (t == EV_END) {
            if (key <= best_key)
                side[p] = SIDE_LEFT;
            else if (side[p] == SIDE_BOTH)
                c->strad[ns++] = p;
        } else {
            side[p] = key < best_key || (key == best_key && best_side == SIDE_LEFT) ? SIDE_LEFT : SIDE_RIGHT;
        }
    }

    float split = o2f(best_key);
    rt_box VL = V, VR = V;
    box_hi(&VL)[k] = split;
    box_lo(&VR)[k] = split;

    /* new events of the straddling primitives, clipped to each child */
    uint64_t *nbuf = NULL;
    uint64_t *nl_list[3] = {NULL, NULL, NULL}, *nr_list[3] = {NULL, NULL, NULL};
    size_t nl_cnt[3] = {0, 0, 0}, nr_cnt[3] = {0, 0, 0};
    size_t npl = 0, npr = 0; /* straddlers kept on each side */
    if (ns > 0) {
        nbuf = malloc(ns * 14 * sizeof *nbuf); /* 6 lists of 2 ns + sort scratch 2 ns */
        if (!nbuf) {
            c->oom = true;
            free(ev);
            return;
        }
        for (int d = 0; d < 3; d++) {
            nl_list[d] = nbuf + (size_t)d * 2 * ns;
            nr_list[d] = nbuf + (size_t)(3 + d) * 2 * ns;
        }
        for (size_t i = 0; i < ns; i++) {
            uint32_t p = c->strad[i];
            rt_box b;
            if (prim_clip_bounds(c, p, VL, &b)) {
                emit_events(b, p, nl_list, nl_cnt);
                npl++;
            }
            if (prim_clip_bounds(c, p, VR, &b)) {
                emit_events(b, p, nr_list, nr_cnt);
                npr++;
            }
        }
        uint64_t *scratch = nbuf + 12 * ns;
        for (int d = 0; d < 3; d++) {
            ev_sort(nl_list[d], nl_cnt[d], scratch);
            ev_sort(nr_list[d], nr_cnt[d], scratch);
        }
    }

    /* filter the parent lists into the children's blocks, merging the new
     * events in; sized for the worst case, shrunk afterwards */
    size_t total = cnt[0] + cnt[1] + cnt[2];
    size_t lcap = total + nl_cnt[0] + nl_cnt[1] + nl_cnt[2], rcap = total + nr_cnt[0] + nr_cnt[1] + nr_cnt[2];
    uint64_t *lev = malloc((lcap ? lcap : 1) * sizeof *lev);
    uint64_t *rev = malloc((rcap ? rcap : 1) * sizeof *rev);
    if (!lev || !rev) {
        free(lev);
        free(rev);
        free(nbuf);
        free(ev);
        c->oom = true;
        return;
    }
    size_t lc[3], rc[3], lo = 0, ro = 0;
    size_t left_prims = npl, right_prims = npr;
    for (int d = 0; d < 3; d++) {
        uint64_t *lp = lev + lo, *rp = rev + ro;
        const uint64_t *src = list[d];
        size_t a = 0, b = 0, m = cnt[d];
        for (size_t i = 0; i < m; i++) {
            uint64_t e = src[i];
            uint8_t sd = side[ev_prim(e)];
            lp[a] = e; /* branch-free: write both, advance one */
            rp[b] = e;
            a += sd == SIDE_LEFT;
            b += sd == SIDE_RIGHT;
        }
        if (d == k) {
            for (size_t i = 0; i < a; i++)
                left_prims += ev_type(lp[i]) != EV_END;
            for (size_t i = 0; i < b; i++)
                right_prims += ev_type(rp[i]) != EV_END;
        }
        if (ns > 0) {
            merge_back(lp, a, nl_list[d], nl_cnt[d]);
            merge_back(rp, b, nr_list[d], nr_cnt[d]);
        }
        lc[d] = a + nl_cnt[d];
        rc[d] = b + nr_cnt[d];
        lo += lc[d];
        ro += rc[d];
    }
    free(nbuf);
    free(ev);
    /* give back what the worst case did not need (shrinking cannot fail for good) */
    uint64_t *t;
    if (lo < lcap && (t = realloc(lev, (lo ? lo : 1) * sizeof *lev)) != NULL)
        lev = t;
    if (ro < rcap && (t = realloc(rev, (ro ? ro : 1) * sizeof *rev)) != NULL)
        rev = t;

    kd_fork *f = NULL;
    if (depth < c->fork_depth && left_prims >= c->fork_min &&
        rt_grow((void **)&c->forks, &c->fork_cap, c->fork_count + 1, sizeof *c->forks) &&
        (f = calloc(1, sizeof *f)) != NULL) {
        uint32_t ph = push_node(c);
        if (c->oom) {
            free(f);
            free(lev);
            free(rev);
            return;
        }
        c->nodes[ph].a = (uint32_t)c->fork_count;
        c->nodes[ph].b = TASK_MARK;
        c->forks[c->fork_count++] = f;
        kd_build *o = &f->out;
        o->s = c->s;
        o->T = c->T, o->S = c->S, o->Q = c->Q;
        o->kt = c->kt, o->ki = c->ki, o->lambda = c->lambda;
        o->max_depth = c->max_depth;
        o->fork_depth = c->fork_depth, o->fork_min = c->fork_min, o->nprims_total = c->nprims_total;
        f->V = VL;
        f->ev = lev;
        memcpy(f->cnt, lc, sizeof f->cnt);
        f->nprims = left_prims;
        f->depth = depth + 1;
        pthread_t th;
        bool started = pthread_create(&th, NULL, fork_worker, f) == 0;
        if (!started)
            fork_worker(f);
        uint32_t above = (uint32_t)c->node_count;
        build_rec(c, VR, rev, rc, right_prims, depth + 1);
        if (started)
            pthread_join(th, NULL);
        if (f->out.oom) {
            c->oom = true;
            c->limit |= f->out.limit;
        }
        if (c->oom)
            return;
        uint32_t bits;
        memcpy(&bits, &split, 4);
        c->nodes[node].a = bits;
        bool below_empty = f->out.node_count == 1 && f->out.nodes[0].b == LEAF_TAG;
        uint32_t flags = (below_empty ? KD_BELOW_EMPTY : 0u) | (c->nodes[above].b == LEAF_TAG ? KD_ABOVE_EMPTY : 0u);
        c->nodes[node].b = (uint32_t)k | flags | (above << 4);
        return;
    }
    build_rec(c, VL, lev, lc, left_prims, depth + 1);
    if (c->oom) {
        free(rev);
        return;
    }
    uint32_t above = (uint32_t)c->node_count;
    build_rec(c, VR, rev, rc, right_prims, depth + 1);
    if (c->oom)
        return;
    uint32_t bits;
    memcpy(&bits, &split, 4);
    c->nodes[node].a = bits;
    /* flag children that are empty leaves: traversal skips them unread */
    uint32_t flags = (c->nodes[node + 1].b == LEAF_TAG ? KD_BELOW_EMPTY : 0u) |
                     (c->nodes[above].b == LEAF_TAG ? KD_ABOVE_EMPTY : 0u);
    c->nodes[node].b = (uint32_t)k | flags | (above << 4);
}

/* ---------------------------------------------------- parallel build */

static void *fork_worker(void *arg)
{
    kd_fork *f = arg;
    kd_build *c = &f->out;
    c->side = malloc(c->nprims_total ? c->nprims_total : 1);
    if (!c->side) {
        c->oom = true;
        free(f->ev);
    } else {
        build_rec(c, f->V, f->ev, f->cnt, f->nprims, f->depth);
    }
    f->ev = NULL;
    free(c->side);
    free(c->strad);
    c->side = NULL;
    c->strad = NULL;
    c->strad_cap = 0;
    return NULL;
}

static void free_forks(kd_build *c)
{
    for (size_t i = 0; i < c->fork_count; i++) {
        kd_fork *f = c->forks[i];
        free_forks(&f->out);
        free(f->ev);
        free(f->out.nodes);
        free(f->out.ids);
        free(f);
    }
    free(c->forks);
    c->forks = NULL;
    c->fork_count = c->fork_cap = 0;
}

/* Sizes and stats of a builder with all its forks. */
static void sum_forks(const kd_build *c, size_t *nodes, size_t *ids, rt_kdtree_stats *st, bool top)
{
    *nodes += c->node_count - c->fork_count;
    *ids += c->id_count;
    if (!top) {
        st->leaves += c->st.leaves;
        st->empty_leaves += c->st.empty_leaves;
        st->prim_refs += c->st.prim_refs;
        if (c->st.max_leaf_prims > st->max_leaf_prims)
            st->max_leaf_prims = c->st.max_leaf_prims;
        if (c->st.depth > st->depth)
            st->depth = c->st.depth;
    }
    for (size_t i = 0; i < c->fork_count; i++)
        sum_forks(&c->forks[i]->out, nodes, ids, st, false);
}

/* Copies the subtree at node i of builder b into (nodes, ids) in
 * depth-first order, splicing forked subtrees in place of their
 * placeholders. Returns the index in b after the subtree. */
static size_t stitch(const kd_build *b, size_t i, rt_kdtree_node *nodes, size_t *nn, uint32_t *ids, size_t *ni)
{
    rt_kdtree_node nd = b->nodes[i];
    if (nd.b == TASK_MARK) {
        stitch(&b->forks[nd.a]->out, 0, nodes, nn, ids, ni);
        return i + 1;
    }
    if ((nd.b & 3u) == LEAF_TAG) {
        if ((nd.b >> 2) > 1) {
            memcpy(ids + *ni, b->ids + nd.a, (nd.b >> 2) * sizeof *ids);
            nd.a = (uint32_t)*ni;
            *ni += nd.b >> 2;
        }
        nodes[(*nn)++] = nd;
        return i + 1;
    }
    size_t me = (*nn)++;
    stitch(b, i + 1, nodes, nn, ids, ni);
    uint32_t above = (uint32_t)*nn;
    size_t next = stitch(b, nd.b >> 4, nodes, nn, ids, ni);
    nodes[me].a = nd.a;
    nodes[me].b = (nd.b & 15u) | (above << 4);
    return next;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static bool finite_box(rt_box b) { return rt_finite3(b.lo) && rt_finite3(b.hi); }

typedef struct kd_sort_job {
    uint64_t *list[2];
    size_t cnt[2];
    uint64_t *tmp;
} kd_sort_job;

static void *sort_worker(void *arg)
{
    kd_sort_job *j = arg;
    ev_sort(j->list[0], j->cnt[0], j->tmp);
    ev_sort(j->list[1], j->cnt[1], j->tmp);
    return NULL;
}

/* Renumbers the triangles in the order the depth-first node array first
 * references them and stores their data in that order, so the triangles of
 * a leaf mostly sit next to each other in memory (one or two cache lines
 * per leaf instead of one per triangle); each record ends with the
 * triangle's scene id. Leaf lists stay ascending. */
static bool leaf_order(rt_kdtree *tree, kd_build *c, size_t T)
{
    uint32_t *newid = malloc(T * sizeof *newid);
    uint32_t *old = malloc(T * sizeof *old);
    float *tri = alloc_hot(T * RT_KD_TRI * sizeof *tri);
    if (!newid || !old || !tri) {
        free(newid);
        free(old);
        free(tri);
        return false;
    }
    memset(newid, 0xff, T * sizeof *newid);
    uint32_t next = 0;
    for (size_t i = 0; i < c->node_count; i++) {
        rt_kdtree_node *nd = &c->nodes[i];
        if ((nd->b & 3u) != LEAF_TAG || nd->b == LEAF_TAG)
            continue;
        uint32_t n = nd->b >> 2;
        uint32_t *p = n == 1 ? &nd->a : c->ids + nd->a;
        for (uint32_t j = 0; j < n && p[j] < T; j++) {
            if (newid[p[j]] == UINT32_MAX) {
                old[next] = p[j];
                newid[p[j]] = next++;
            }
            p[j] = newid[p[j]];
        }
        for (uint32_t j = 1; j < n && p[j] < T; j++) { /* ascending again (first-seen ones already are) */
            uint32_t x = p[j], k = j;
            while (k > 0 && p[k - 1] > x) {
                p[k] = p[k - 1];
                k--;
            }
            p[k] = x;
        }
    }
    for (size_t i = 0; i < T; i++) /* triangles in no leaf (never hit) go last */
        if (newid[i] == UINT32_MAX) {
            old[next] = (uint32_t)i;
            newid[i] = next++;
        }
    for (size_t i = 0; i < T; i++) { /* 9 floats, then the scene id (the hit's, in the same cache line) */
        memcpy(tri + RT_KD_TRI * i, tree->tri + 9 * (size_t)old[i], 9 * sizeof *tri);
        memcpy(tri + RT_KD_TRI * i + 9, &old[i], sizeof old[i]);
    }
    free(newid);
    free(old);
    free(tree->tri);
    tree->tri = tri;
    return true;
}

/* ------------------------------------------------------- wide nodes */

/* Packs the binary tree (c->nodes, c->ids) into 64-byte nodes of three
 * levels each (rt_kdtree_wide in kdtree.h), in depth-first order, and
 * rewrites the leaf lists with their counts in front. Cell by cell: follow
 * the cell's three below/above choices down from the top node; a leaf met
 * above the third level takes the cell whose remaining choices are all
 * "below" (the missing planes are +inf, so that cell is the leaf's whole
 * box) and the other cells under it stay empty. */
typedef struct kd_widen {
    const rt_kdtree_node *bn;
    const uint32_t *bids;
    rt_kdtree_wide *w;
    size_t wn, wcap;
    uint32_t *ids;
    size_t in;
    bool oom, limit;
} kd_widen;

#define KD_NO_NODE UINT32_MAX
#define KD_IDS_PAD 8

static uint32_t widen_leaf(kd_widen *x, const rt_kdtree_node *nd)
{
    uint32_t n = nd->b >> 2;
    if (n == 0)
        return RT_KD_EMPTY;
    if (n == 1)
        return RT_KD_ONE | nd->a;
    if (x->in > RT_KD_PAYLOAD) {
        x->limit = true;
        return RT_KD_EMPTY;
    }
    uint32_t off = (uint32_t)x->in;
    memcpy(x->ids + x->in, x->bids + nd->a, n * sizeof *x->ids);
    x->in += n;
    x->ids[x->in - 1] |= RT_KD_LAST;
    return RT_KD_LEAF | off;
}

/* The binary child of interior node i on side `above`, or KD_NO_NODE for an
 * empty leaf. */
static uint32_t binary_child(const rt_kdtree_node *bn, uint32_t i, unsigned above)
{
    uint32_t b = bn[i].b;
    if (b & (above ? KD_ABOVE_EMPTY : KD_BELOW_EMPTY))
        return KD_NO_NODE;
    return above ? b >> 4 : i + 1;
}

static bool is_leaf(const rt_kdtree_node *bn, uint32_t i) { return (bn[i].b & 3u) == LEAF_TAG; }

static uint32_t widen_rec(kd_widen *x, uint32_t top)
{
    const rt_kdtree_node *bn = x->bn;
    if (top == KD_NO_NODE)
        return RT_KD_EMPTY;
    if (is_leaf(bn, top))
        return widen_leaf(x, &bn[top]);
    if (x->wn >= (size_t)RT_KD_LEAF) {
        x->limit = true;
        return RT_KD_EMPTY;
    }
    if (!rt_grow((void **)&x->w, &x->wcap, x->wn + 1, sizeof *x->w)) {
        x->oom = true;
        return RT_KD_EMPTY;
    }
    size_t me = x->wn++;
    rt_kdtree_wide w;
    memset(&w, 0, sizeof w);
    uint32_t plane[7];
    plane[0] = top;
    for (int p = 0; p < 3; p++) {
        uint32_t i = plane[p];
        bool inner = i != KD_NO_NODE && !is_leaf(bn, i);
        plane[2 * p + 1] = inner ? binary_child(bn, i, 0) : KD_NO_NODE;
        plane[2 * p + 2] = inner ? binary_child(bn, i, 1) : KD_NO_NODE;
    }
    for (int p = 0; p < 7; p++) {
        uint32_t i = plane[p];
        if (i != KD_NO_NODE && !is_leaf(bn, i)) {
            memcpy(&w.split[p], &bn[i].a, 4);
            w.axes |= (bn[i].b & 3u) << (2 * p);
        } else {
            w.split[p] = INFINITY; /* axis 0: the whole cell is below */
        }
    }
    for (unsigned cell = 0; cell < 8; cell++) {
        uint32_t i = top;
        bool leaf_above = false; /* i is a leaf (or empty) met above level 3 */
        bool gone = false;       /* the cell is beside such a leaf */
        for (int level = 0; level < 3 && !gone; level++) {
            unsigned bit = (cell >> (2 - level)) & 1u;
            if (leaf_above) {
                gone = bit != 0;
                continue;
            }
            i = binary_child(bn, i, bit);
            if (i == KD_NO_NODE) {
                leaf_above = true;
                gone = true; /* an empty leaf: every cell under it is empty */
            } else if (is_leaf(bn, i)) {
                leaf_above = level < 2;
            }
        }
        w.child[cell] = gone ? RT_KD_EMPTY : widen_rec(x, i);
        if (x->oom || x->limit)
            return RT_KD_EMPTY;
    }
    x->w[me] = w; /* x->w may have moved */
    return (uint32_t)me;
}

static bool widen(rt_kdtree *tree, kd_build *c)
{
    kd_widen x;
    memset(&x, 0, sizeof x);
    x.bn = c->nodes;
    x.bids = c->ids;
    /* + KD_IDS_PAD: a leaf's length is found by loading 8 ids at a time */
    x.ids = alloc_hot((c->id_count + KD_IDS_PAD) * sizeof *x.ids);
    if (!x.ids)
        return false;
    tree->root = c->node_count ? widen_rec(&x, 0) : RT_KD_EMPTY;
    for (size_t i = 0; i < KD_IDS_PAD; i++)
        x.ids[x.in + i] = RT_KD_LAST;
    rt_kdtree_wide *w = NULL;
    if (!x.oom && !x.limit && (w = alloc_hot(x.wn * sizeof *w)) != NULL && x.wn)
        memcpy(w, x.w, x.wn * sizeof *w);
    free(x.w);
    if (!w) {
        free(x.ids);
        c->limit = x.limit;
        return false;
    }
    tree->wide = w;
    tree->wide_count = x.wn;
    tree->prim_ids = x.ids;
    tree->prim_id_count = x.in;
    return true;
}

rt_result rt_kdtree_build(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err)
{
    double t0 = now_ms();
    memset(tree, 0, sizeof *tree);
    tree->scene = scene;
    tree->bounds = rt_box_empty();
    size_t T = scene->triangles.count, S = scene->spheres.count, Q = scene->quads.count, N = T + S + Q;
    if (N >= (size_t)PRIM_MASK)
        return rt_fail(err, RT_ERR_LIMIT, "kdtree: %zu primitives, at most %u supported", N, PRIM_MASK - 1u);
    tree->triangle_count = T;
    tree->simd_ok = T < (size_t)INT32_MAX / RT_KD_TRI;
    tree->sphere_count = S;
    tree->quad_count = Q;

    kd_build c;
    memset(&c, 0, sizeof c);
    c.s = scene;
    c.T = (uint32_t)T;
    c.S = (uint32_t)S;
    c.Q = (uint32_t)Q;
    c.kt = params && params->traversal_cost > 0.0f ? params->traversal_cost : 4.0;
    c.ki = params && params->intersect_cost > 0.0f ? params->intersect_cost : 1.0;
    double eb = params && params->empty_bonus > 0.0f ? params->empty_bonus : 0.2;
    if (eb > 1.0)
        eb = 1.0;
    c.lambda = 1.0 - eb;
    int threads = params && params->threads > 0 ? params->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (threads < 1)
        threads = 1;
    if (threads > 64)
        threads = 64;

    uint64_t *ev = NULL, *tmp = NULL;
    if (T > 0) {
        tree->tri = malloc(T * 9 * sizeof *tree->tri);
        if (!tree->tri)
            goto oom;
    }
    ev = malloc((N ? 6 * N : 1) * sizeof *ev);
    c.side = malloc(N ? N : 1);
    if (!ev || !c.side)
        goto oom;

    /* valid primitives and their bounds: first a count, then the events */
    size_t nvalid = 0;
    rt_box *pb = malloc((N ? N : 1) * sizeof *pb);
    if (!pb)
        goto oom;
    size_t nverts = scene->vertices.count;
    for (size_t i = 0; i < N; i++) {
        rt_box b = rt_box_empty();
        bool ok = true;
        if (i < T) {
            const uint32_t *ix = scene->triangles.index + 3 * i;
            float *dst = tree->tri + 9 * i;
            memset(dst, 0, 9 * sizeof *dst);
            if (ix[0] >= nverts || ix[1] >= nverts || ix[2] >= nverts) {
                ok = false;
            } else {
                rt_vec3 a = scene->vertices.position[ix[0]], bb = scene->vertices.position[ix[1]],
                        cc = scene->vertices.position[ix[2]];
                rt_vec3 e1 = rt_sub(bb, a), e2 = rt_sub(cc, a);
                ok = rt_finite3(a) && rt_finite3(bb) && rt_finite3(cc) && rt_finite3(e1) && rt_finite3(e2) &&
                     (e1.x != 0.0f || e1.y != 0.0f || e1.z != 0.0f) && (e2.x != 0.0f || e2.y != 0.0f || e2.z != 0.0f);
                if (ok) {
                    dst[0] = a.x, dst[1] = a.y, dst[2] = a.z;
                    dst[3] = e1.x, dst[4] = e1.y, dst[5] = e1.z;
                    dst[6] = e2.x, dst[7] = e2.y, dst[8] = e2.z;
                    b = rt_box_point(rt_box_point(rt_box_point(b, a), bb), cc);
                }
            }
        } else if (i < T + S) {
            size_t j = i - T;
            const rt_spheres *sp = &scene->spheres;
            ok = isfinite(sp->cx[j]) && isfinite(sp->cy[j]) && isfinite(sp->cz[j]) && isfinite(sp->radius[j]);
            if (ok) {
                double r = fabs((double)sp->radius[j]);
                b.lo = rt_v3(round_down(sp->cx[j] - r), round_down(sp->cy[j] - r), round_down(sp->cz[j] - r));
                b.hi = rt_v3(round_up(sp->cx[j] + r), round_up(sp->cy[j] + r), round_up(sp->cz[j] + r));
            }
        } else {
            size_t j = i - T - S;
            const rt_quads *q = &scene->quads;
            rt_vec3 p = rt_v3(q->px[j], q->py[j], q->pz[j]), u = rt_v3(q->ux[j], q->uy[j], q->uz[j]),
                    v = rt_v3(q->vx[j], q->vy[j], q->vz[j]);
            rt_vec3 nrm = rt_cross(u, v);
            ok = rt_finite3(p) && rt_finite3(u) && rt_finite3(v) && rt_dot(nrm, nrm) > 0.0f;
            if (ok) {
                double lo[3], hi[3];
                const float *pp = &p.x, *uu = &u.x, *vv = &v.x;
                for (int k = 0; k < 3; k++) {
                    double c0 = pp[k], c1 = c0 + uu[k], c2 = c0 + vv[k], c3 = c1 + vv[k];
                    lo[k] = fmin(fmin(c0, c1), fmin(c2, c3));
                    hi[k] = fmax(fmax(c0, c1), fmax(c2, c3));
                }
                b.lo = rt_v3(round_down(lo[0]), round_down(lo[1]), round_down(lo[2]));
                b.hi = rt_v3(round_up(hi[0]), round_up(hi[1]), round_up(hi[2]));
            }
        }
        if (ok && !finite_box(b))
            ok = false;
        pb[i] = b;
        if (ok) {
            nvalid++;
            tree->bounds = rt_box_union(tree->bounds, b);
        } else {
            pb[i] = rt_box_empty();
        }
    }
    if (nvalid < N)
        rt_info("kdtree: %zu of %zu primitives can never be hit (non-finite or degenerate) and are left out", N - nvalid,
                N);

    size_t cnt[3] = {0, 0, 0};
    uint64_t *list[3] = {ev, ev + 2 * nvalid, ev + 4 * nvalid};
    for (size_t i = 0; i < N; i++)
        if (!rt_box_is_empty(pb[i]))
            emit_events(pb[i], (uint32_t)i, list, cnt);
    free(pb);
    tmp = malloc((nvalid ? 2 * nvalid : 1) * sizeof *tmp);
    if (!tmp)
        goto oom;
    {
        /* the three axes sort independently: y and z on a helper thread */
        kd_sort_job job = {{list[1], list[2]}, {cnt[1], cnt[2]}, NULL};
        pthread_t th;
        bool started = false;
        if (threads > 1 && nvalid >= KD_FORK_MIN_PRIMS && (job.tmp = malloc(2 * nvalid * sizeof *job.tmp)) != NULL)
            started = pthread_create(&th, NULL, sort_worker, &job) == 0;
        ev_sort(list[0], cnt[0], tmp);
        if (started) {
            pthread_join(th, NULL);
        } else {
            ev_sort(list[1], cnt[1], tmp);
            ev_sort(list[2], cnt[2], tmp);
        }
        free(job.tmp);
    }
    free(tmp);
    tmp = NULL;
    /* compact the three lists into one block */
    memmove(ev + cnt[0], list[1], cnt[1] * sizeof *ev);
    memmove(ev + cnt[0] + cnt[1], list[2], cnt[2] * sizeof *ev);

    if (nvalid > 0) {
        const float *lo = &tree->bounds.lo.x, *hi = &tree->bounds.hi.x;
        for (int k = 0; k < 3; k++)
            tree->scale = fmaxf(tree->scale, fmaxf(fabsf(lo[k]), fabsf(hi[k])));
    }
    int md = params && params->max_depth > 0 ? params->max_depth
                                             : (int)(8.0 + 1.3 * log2((double)(nvalid > 1 ? nvalid : 1)) + 0.5);
    if (md > KD_MAX_DEPTH)
        md = KD_MAX_DEPTH;
    c.max_depth = md;
    tree->max_depth = md;

    if (threads > 1 && nvalid >= KD_FORK_MIN_PRIMS) {
        /* 4 subtrees per thread: the OS evens out uneven halves */
        int f = 2;
        while ((1 << (f - 2)) < threads && f < 8)
            f++;
        c.fork_depth = f;
        c.fork_min = 4096;
        c.nprims_total = N;
    }
    build_rec(&c, tree->bounds, ev, cnt, nvalid, 0);
    ev = NULL;
    if (c.oom)
        goto oom;
    if (c.fork_count > 0) {
        size_t nn = 0, ni = 0;
        sum_forks(&c, &nn, &ni, &c.st, true);
        if (nn >= ((size_t)1 << KD_INDEX_BITS) || ni > KD_MAX_IDS) {
            c.limit = true;
            goto oom;
        }
        rt_kdtree_node *nodes = malloc(nn * sizeof *nodes);
        uint32_t *ids = malloc((ni ? ni : 1) * sizeof *ids);
        if (!nodes || !ids) {
            free(nodes);
            free(ids);
            goto oom;
        }
        size_t on = 0, oi = 0;
        stitch(&c, 0, nodes, &on, ids, &oi);
        free_forks(&c);
        free(c.nodes);
        free(c.ids);
        c.nodes = nodes;
        c.ids = ids;
        c.node_count = on;
        c.id_count = oi;
    }
    free(c.side);
    free(c.strad);
    c.side = NULL;
    c.strad = NULL;
    if (T > 0 && !leaf_order(tree, &c, T))
        goto oom;
    if (!widen(tree, &c))
        goto oom;
    c.st.nodes = c.node_count;
    c.st.wide_nodes = tree->wide_count;
    c.st.bytes = tree->wide_count * sizeof *tree->wide + tree->prim_id_count * sizeof *tree->prim_ids +
                 T * RT_KD_TRI * sizeof(float);
    free(c.nodes);
    free(c.ids);
    c.st.build_ms = now_ms() - t0;
    tree->stats = c.st;
    return RT_OK;

oom:
    free_forks(&c);
    free(ev);
    free(tmp);
    free(c.side);
    free(c.strad);
    free(c.nodes);
    free(c.ids);
    free(tree->tri);
    memset(tree, 0, sizeof *tree);
    if (c.limit)
        return rt_fail(err, RT_ERR_LIMIT, "kdtree: %zu primitives make more nodes or references than the node format holds",
                       N);
    return rt_fail(err, RT_ERR_NOMEM, "kdtree: out of memory building the tree over %zu primitives", N);
}

void rt_kdtree_free(rt_kdtree *tree)
{
    if (!tree)
        return;
    free(tree->wide);
    free(tree->prim_ids);
    free(tree->tri);
    memset(tree, 0, sizeof *tree);
}

/* ---------------------------------------------------------- traversal */

#if defined(__AVX2__) && defined(__GNUC__) && !defined(RT_KD_SCALAR) /* RT_KD_SCALAR: the portable code, for tests */
#include <immintrin.h>
#define KD_SIMD 1
#endif

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

/* Clips the ray to the (widened) root box; false when it misses. An axis
 * is treated as parallel when 1/d is infinite or mp/|d| overflows: then the
 * ray moves less than mp along it for any finite t, so the side of a plane
 * is decided by the origin alone (within mp: both sides). */
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

#if defined(__GNUC__)
#define KD_INLINE static inline __attribute__((always_inline))
#define KD_FLATTEN __attribute__((flatten)) /* inline the intersect.h tests into the loops */
#define KD_PREFETCH(p) __builtin_prefetch(p)
#else
#define KD_INLINE static inline
#define KD_FLATTEN
#define KD_PREFETCH(p) ((void)(p))
#endif

/* Tests one primitive with the reference functions on (tmin, *best). */
KD_INLINE bool test_prim(const rt_kdtree *tree, uint32_t id, const rt_ray *ray, float *best, rt_hit *hit)
{
    float t, u, v;
    if (id < tree->triangle_count) {
        const float *p = tree->tri + RT_KD_TRI * (size_t)id;
        if (!rt_intersect_triangle(ray->org, ray->dir, rt_v3(p[0], p[1], p[2]), rt_v3(p[3], p[4], p[5]),
                                   rt_v3(p[6], p[7], p[8]), ray->tmin, *best, &t, &u, &v))
            return false;
    } else if (id < tree->triangle_count + tree->sphere_count) {
        const rt_spheres *s = &tree->scene->spheres;
        size_t i = id - tree->triangle_count;
        if (!rt_intersect_sphere(ray->org, ray->dir, rt_v3(s->cx[i], s->cy[i], s->cz[i]), s->radius[i], ray->tmin,
                                 *best, &t))
            return false;
        u = v = 0.0f;
    } else {
        const rt_quads *q = &tree->scene->quads;
        size_t i = id - tree->triangle_count - tree->sphere_count;
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
    __m256i base = _mm256_mullo_epi32(id, _mm256_set1_epi32(RT_KD_TRI));
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
    __m256 inv = _mm256_div_ps(one, det);
    __m256 sx = _mm256_sub_ps(_mm256_set1_ps(ray->org.x), v0x), sy = _mm256_sub_ps(_mm256_set1_ps(ray->org.y), v0y),
           sz = _mm256_sub_ps(_mm256_set1_ps(ray->org.z), v0z);
    __m256 u = _mm256_mul_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(sx, px), _mm256_mul_ps(sy, py)), _mm256_mul_ps(sz, pz)), inv);
    ok = _mm256_andnot_ps(_mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_LT_OQ), _mm256_cmp_ps(u, one, _CMP_GT_OQ)), ok);
    __m256 qx = _mm256_sub_ps(_mm256_mul_ps(sy, e1z), _mm256_mul_ps(sz, e1y));
    __m256 qy = _mm256_sub_ps(_mm256_mul_ps(sz, e1x), _mm256_mul_ps(sx, e1z));
    __m256 qz = _mm256_sub_ps(_mm256_mul_ps(sx, e1y), _mm256_mul_ps(sy, e1x));
    __m256 v = _mm256_mul_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, qx), _mm256_mul_ps(dy, qy)), _mm256_mul_ps(dz, qz)), inv);
    ok = _mm256_andnot_ps(
        _mm256_or_ps(_mm256_cmp_ps(v, zero, _CMP_LT_OQ), _mm256_cmp_ps(_mm256_add_ps(u, v), one, _CMP_GT_OQ)), ok);
    __m256 t = _mm256_mul_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(e2x, qx), _mm256_mul_ps(e2y, qy)), _mm256_mul_ps(e2z, qz)), inv);
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
    if (n >= KD_SIMD_MIN && tree->simd_ok) {
        uint32_t T = (uint32_t)tree->triangle_count;
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
        if (hit->prim < tree->triangle_count)
            hit->prim = rt_kdtree_scene_triangle(tree, hit->prim);
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
