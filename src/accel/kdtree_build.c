/* kdtree_build.c - the SAH kd-tree's build: O(N log N) with perfect splits,
 * on one or more threads, into a binary tree that kdtree_pack.c then packs
 * for the traversal (kdtree_trace.c). rt_kdtree_build and rt_kdtree_free.
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
 * depth-first order afterwards. Above that, where fewer subtrees than
 * threads are being built (the root on 2 threads; the root and its
 * children on 4), a node of 16k or more primitives shares its own work:
 * the primitives' bounds and events and the root's radix sort in parts of
 * the arrays, the sweeps in parts of each event list (cut where the key
 * changes) started from the counts of the parts before, the sides in two
 * passes (STARTs and PLANARs, then ENDs) and the children's lists by
 * counts, then offsets. Each step gives what the one-thread step gives and
 * the best plane is the first cheapest in the same order, so the tree is
 * bit-identical for any thread count. What stays on one thread is the
 * splice and the packing (kdtree_pack.c): 5-8% of the 1M-triangle model's
 * CPU time (rt_kdtree_stats.serial_cpu_ms; docs/performance.md, "Build
 * time").
 *
 * Output (kdtree_internal.h): 8-byte nodes in depth-first order (below
 * child = next node, above child index in the node) and leaf id lists in a
 * second array, ascending, triangles first. The triangles' records for the
 * traversal (the scene's v0, v1, v2, which the watertight test of
 * intersect.h reads as they are, so t is bit-identical to testing the
 * scene's triangle directly) are made here with the primitives' bounds;
 * kdtree_pack.c puts them into the leaf blocks and packs the nodes.
 *
 * Measured and not kept (docs/performance.md has the numbers): K_T 1.5-6,
 * empty bonus 0.2-0.8 and depth limits up to 50 (no gain on both ray
 * kinds); huge pages for the build's event arrays (no faster); with the
 * wide nodes, a SAH leaf cost in steps of 8 primitives (the 8-wide leaf
 * test) with K_T 2-8.
 */
#include "kdtree_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "rt/base/clock.h"
#include "rt/base/cpu.h"
#include "rt/base/log.h"
#include "rt/base/alloc.h"
#include "rt/scene/instance.h"

/* ------------------------------------------------------------- events */

enum { EV_END = 0, EV_PLANAR = 1, EV_START = 2 };
enum { SIDE_BOTH = 0, SIDE_LEFT = 1, SIDE_RIGHT = 2 };
#define PRIM_BITS 30
#define PRIM_MASK ((1u << PRIM_BITS) - 1u)
#define KD_INDEX_BITS 28 /* of the above-child index in a binary node */
#define KD_MAX_NODES ((size_t)1 << (KD_INDEX_BITS - 1)) /* per builder; stitching adds them up */
#define KD_MAX_IDS ((size_t)UINT32_MAX)
/* Below this many primitives the build stays on one thread. 4096: with the
 * second core free, DamagedHelmet (15k triangles) builds in 21-24 ms with 2
 * threads against 30-36 ms with 1 (20000 before, measured under load). */
#define KD_FORK_MIN_PRIMS 4096
/* A node of at least this many primitives near the root, where fewer
 * subtrees than threads are being built, shares its own work (the plane
 * sweeps, the sides, the children's lists) among the threads left over;
 * so do the root's bounds and event sort. */
#define KD_PART_MIN_PRIMS 16384
#define KD_MAX_THREADS 64

/* ----------------------------------------------------- fork-join parts */

/* CPU time of the calling thread, ms. */
static double thread_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* Runs fn on the n records at args (`size` bytes each), n - 1 of them on
 * new threads and the first on this one, and waits for all; a record whose
 * thread cannot start runs here afterwards. The records never depend on
 * which thread ran them, so neither does the tree. */
static void run_parts(void *(*fn)(void *), void *args, size_t size, int n)
{
    pthread_t th[KD_MAX_THREADS];
    bool started[KD_MAX_THREADS];
    char *a = args;
    for (int i = 1; i < n; i++)
        started[i] = pthread_create(&th[i], NULL, fn, a + (size_t)i * size) == 0;
    fn(a);
    for (int i = 1; i < n; i++) {
        if (started[i])
            pthread_join(th[i], NULL);
        else
            fn(a + (size_t)i * size);
    }
}

/* Start of part i of n of a range of m items. */
static inline size_t part_start(size_t m, int i, int n) { return m * (size_t)i / (size_t)n; }

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

/* Insertion sort by (position, type), stable. */
static void ev_insertion_sort(uint64_t *a, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        uint64_t x = a[i];
        size_t j = i;
        while (j > 0 && (a[j - 1] >> PRIM_BITS) > (x >> PRIM_BITS)) {
            a[j] = a[j - 1];
            j--;
        }
        a[j] = x;
    }
}

/* Bottom-up merge sort by (position, type), stable (runs of 16 by
 * insertion); tmp has room for n. For the short lists of a split's
 * straddlers, where the radix sort's 8,192 counters (zeroed and summed each
 * pass) cost more than the events: the same order, as both are stable. */
static void ev_merge_sort(uint64_t *a, size_t n, uint64_t *tmp)
{
    for (size_t i = 0; i < n; i += 16)
        ev_insertion_sort(a + i, n - i < 16 ? n - i : 16);
    uint64_t *src = a, *dst = tmp;
    for (size_t w = 16; w < n; w *= 2) {
        for (size_t i = 0; i < n; i += 2 * w) {
            size_t m = i + w < n ? i + w : n, e = i + 2 * w < n ? i + 2 * w : n, p = i, q = m, k = i;
            while (p < m && q < e)
                dst[k++] = (src[q] >> PRIM_BITS) < (src[p] >> PRIM_BITS) ? src[q++] : src[p++];
            while (p < m)
                dst[k++] = src[p++];
            while (q < e)
                dst[k++] = src[q++];
        }
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    if (src != a)
        memcpy(a, src, n * sizeof *a);
}

/* Sorts events by (position, type), stable; tmp has room for n. */
static void ev_sort(uint64_t *a, size_t n, uint64_t *tmp)
{
    if (n < 64) {
        ev_insertion_sort(a, n);
        return;
    }
    if (n < 512) {
        ev_merge_sort(a, n, tmp);
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

/* Whether the whole polygon keeps sign * (x_k - c) >= 0: then clip_plane
 * would return it unchanged, and is skipped (most planes of a box cut a
 * straddling triangle nowhere). */
static bool all_inside(double (*in)[3], int n, int k, double c, double sign)
{
    for (int i = 0; i < n; i++)
        if (!(sign * (in[i][k] - c) >= 0.0))
            return false;
    return true;
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
    uint32_t T, S, Q, I; /* I: instances, primitives T + S + Q + i (rt/scene/instance.h) */
    bool skip_objects;   /* the scene has objects: their triangles (object space) stay out */
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
    int threads;          /* of the whole build: a node at depth d shares its work among threads >> d */
    bool track;           /* the caller's builder: times its parallel sections */
    int par_nest;
    double par_t0, par_cpu_ms; /* CPU time this thread spent while other build threads ran */
} kd_build;

/* Brackets a stretch during which other build threads run (nested ones
 * count once): what the calling thread spends outside them is the build's
 * serial part, which a second thread cannot shorten. */
static void par_begin(kd_build *c)
{
    if (c->track && c->par_nest++ == 0)
        c->par_t0 = thread_cpu_ms();
}
static void par_end(kd_build *c)
{
    if (c->track && --c->par_nest == 0)
        c->par_cpu_ms += thread_cpu_ms() - c->par_t0;
}

/* run_parts, inside par_begin / par_end when on more than one thread. */
static void run_parts_of(kd_build *c, void *(*fn)(void *), void *args, size_t size, int n)
{
    if (n < 2) {
        fn(args);
        return;
    }
    par_begin(c);
    run_parts(fn, args, size, n);
    par_end(c);
}

/* One part of a pass of ev_sort_parts: counts its events' digits, or
 * scatters them to the offsets in count. */
typedef struct kd_sort_part {
    const uint64_t *src;
    uint64_t *dst;
    size_t from, to, mask;
    size_t *count; /* mask + 1 entries */
    int shift;
    bool scatter;
} kd_sort_part;

static void *sort_part(void *arg)
{
    kd_sort_part *w = arg;
    const uint64_t *src = w->src;
    size_t *count = w->count, mask = w->mask;
    int shift = w->shift;
    if (!w->scatter) {
        memset(count, 0, (mask + 1) * sizeof *count);
        for (size_t i = w->from; i < w->to; i++)
            count[(src[i] >> shift) & mask]++;
    } else {
        for (size_t i = w->from; i < w->to; i++)
            w->dst[count[(src[i] >> shift) & mask]++] = src[i];
    }
    return NULL;
}

/* ev_sort on nt threads: the same three stable passes, each part of the
 * list counting its digits, then scattering them after those of the parts
 * before it; so the same order as ev_sort. tmp has room for n. */
static void ev_sort_parts(kd_build *c, uint64_t *a, size_t n, uint64_t *tmp, int nt)
{
    size_t *counts = nt > 1 && n >= 2 * KD_PART_MIN_PRIMS ? malloc((size_t)nt * 4096 * sizeof *counts) : NULL;
    if (!counts) {
        ev_sort(a, n, tmp);
        return;
    }
    static const int shift[3] = {30, 41, 52}, bits[3] = {11, 11, 12};
    kd_sort_part part[KD_MAX_THREADS];
    uint64_t *src = a, *dst = tmp;
    for (int pass = 0; pass < 3; pass++) {
        size_t radix = (size_t)1 << bits[pass], first = (src[0] >> shift[pass]) & (radix - 1), same = 0;
        for (int i = 0; i < nt; i++)
            part[i] = (kd_sort_part){src, dst, part_start(n, i, nt), part_start(n, i + 1, nt), radix - 1,
                                     counts + (size_t)i * 4096, shift[pass], false};
        run_parts_of(c, sort_part, part, sizeof *part, nt);
        for (int i = 0; i < nt; i++)
            same += part[i].count[first];
        if (same == n)
            continue; /* every key shares this digit */
        size_t sum = 0;
        for (size_t r = 0; r < radix; r++)
            for (int i = 0; i < nt; i++) {
                size_t m = part[i].count[r];
                part[i].count[r] = sum;
                sum += m;
            }
        for (int i = 0; i < nt; i++)
            part[i].scatter = true;
        run_parts_of(c, sort_part, part, sizeof *part, nt);
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    if (src != a)
        memcpy(a, src, n * sizeof *a);
    free(counts);
}

struct kd_fork {
    kd_build out; /* the subtree's nodes, ids, stats and its own forks */
    rt_box V;
    uint64_t *ev;
    size_t cnt[3], nprims;
    int depth;
};

#define TASK_MARK (KD_LEAF_TAG | (0x3fffffffu << 2)) /* placeholder leaf: a = fork index */

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
    } else if (prim >= c->T + c->S + c->Q) { /* an instance: its world box */
        const rt_box *ib = &s->instances[prim - c->T - c->S - c->Q].bounds;
        for (int k = 0; k < 3; k++) {
            lo[k] = (&ib->lo.x)[k];
            hi[k] = (&ib->hi.x)[k];
        }
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
            if (!all_inside(poly[cur], n, k, bl[k], 1.0)) {
                n = clip_plane(poly[cur], n, poly[cur ^ 1], k, bl[k], 1.0);
                cur ^= 1;
            }
            if (n > 0 && !all_inside(poly[cur], n, k, bh[k], -1.0)) {
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
    c->nodes[c->node_count].b = KD_LEAF_TAG;
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
        nd->b = KD_LEAF_TAG;
        return;
    }
    if (nprims == 1) {
        for (size_t i = 0; i < n0; i++)
            if (ev_type(ev0[i]) != EV_END) {
                nd->a = ev_prim(ev0[i]);
                break;
            }
        nd->b = KD_LEAF_TAG | (1u << 2);
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
        if (ev_type(ev0[i]) != EV_END)
            dst[m++] = ev_prim(ev0[i]);
    kd_sort_ids(dst, m);
    nd->a = (uint32_t)c->id_count;
    nd->b = KD_LEAF_TAG | ((uint32_t)m << 2);
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

/* The cost C(p) of a plane with nl primitives on its left and nr on its
 * right (wl, wr: the children's surface areas, scaled as in find_plane),
 * with the empty-space bonus when a side is empty. */
static inline double plane_cost(double kt, double scale, double lambda, double wl, double wr, size_t nl, size_t nr)
{
    double c = kt + scale * (wl * (double)(int64_t)nl + wr * (double)(int64_t)nr);
    return nl == 0 || nr == 0 ? c * lambda : c;
}

/* A node's best plane so far: its cost, axis, position key and the side
 * its planar primitives go to. */
typedef struct kd_plane {
    double cost;
    int k, side;
    uint32_t key;
} kd_plane;

/* What the plane cost needs of a node on one axis (find_plane). */
typedef struct kd_axis {
    double kt, scale, lambda, ab, apb, lo, hi;
    uint32_t lo_key, hi_key;
    bool ok; /* the node has extent on this axis */
} kd_axis;

/* The sweep's constants on each axis of V; false when V has no area (no
 * plane then). cost = kt + ki * (PL * nl + PR * nr)
 *                   = kt + (2 ki / area) * ((ab + dl (a+b)) nl + (ab + dr (a+b)) nr) */
static bool node_axes(const kd_build *c, rt_box V, kd_axis ax[3])
{
    const float *vlo = &V.lo.x, *vhi = &V.hi.x;
    double ext[3] = {(double)vhi[0] - vlo[0], (double)vhi[1] - vlo[1], (double)vhi[2] - vlo[2]};
    double area = 2.0 * (ext[0] * ext[1] + ext[1] * ext[2] + ext[2] * ext[0]);
    if (!(area > 0.0) || !isfinite(area))
        return false;
    for (int k = 0; k < 3; k++) {
        double a = ext[(k + 1) % 3], b = ext[(k + 2) % 3];
        ax[k] = (kd_axis){c->kt, 2.0 * c->ki / area, c->lambda, a * b, a + b, vlo[k], vhi[k],
                          f2o(vlo[k] + 0.0f), f2o(vhi[k] + 0.0f), vlo[k] < vhi[k]};
    }
    return true;
}

/* Sweeps events E[from..to) of axis k (a range that starts and ends where
 * the key changes), with nl primitives left of the first event and nr not
 * ended before it, and keeps in *best the first plane cheaper than it. */
static void sweep(const kd_axis *ax, int k, const uint64_t *E, size_t from, size_t to, size_t nl, size_t nr,
                  kd_plane *best)
{
    double kt = ax->kt, scale = ax->scale, lambda = ax->lambda, ab = ax->ab, apb = ax->apb, lo = ax->lo,
           hi = ax->hi;
    uint32_t lo_key = ax->lo_key, hi_key = ax->hi_key;
    kd_plane b = *best;
    for (size_t i = from; i < to;) {
        uint64_t e = E[i];
        uint32_t key = ev_key(e);
        size_t pe, pp, ps;
        if (i + 1 == to || ev_key(E[i + 1]) != key) { /* the usual lone event */
            unsigned t = ev_type(e);
            pe = t == EV_END, pp = t == EV_PLANAR, ps = t == EV_START;
            i++;
        } else {
            pe = pp = ps = 0;
            while (i < to && ev_key(E[i]) == key && ev_type(E[i]) == EV_END)
                pe++, i++;
            while (i < to && ev_key(E[i]) == key && ev_type(E[i]) == EV_PLANAR)
                pp++, i++;
            while (i < to && ev_key(E[i]) == key && ev_type(E[i]) == EV_START)
                ps++, i++;
        }
        nr -= pp + pe;
        if (key > lo_key && key < hi_key) {
            double p = (double)o2f(key);
            double wl = ab + (p - lo) * apb, wr = ab + (hi - p) * apb;
            double c1 = plane_cost(kt, scale, lambda, wl, wr, nl + pp, nr); /* planar ones left */
            if (c1 < b.cost)
                b = (kd_plane){c1, k, SIDE_LEFT, key};
            if (pp > 0) { /* planar ones right */
                double c2 = plane_cost(kt, scale, lambda, wl, wr, nl, nr + pp);
                if (c2 < b.cost)
                    b = (kd_plane){c2, k, SIDE_RIGHT, key};
            }
        }
        nl += ps + pp;
    }
    *best = b;
}

/* Best SAH plane of a node (section 4.2 of Wald and Havran): one sweep per
 * axis over its sorted events, into *best (cost INFINITY when no plane). */
static void find_plane(const kd_build *c, rt_box V, uint64_t *const list[3], const size_t cnt[3], size_t nprims,
                       kd_plane *best)
{
    kd_axis ax[3];
    if (!node_axes(c, V, ax))
        return;
    for (int k = 0; k < 3; k++)
        if (ax[k].ok)
            sweep(&ax[k], k, list[k], 0, cnt[k], 0, nprims, best);
}

/* Fills in interior node `node` once both children are built: split
 * position, axis, above child, and flags for children that are empty leaves
 * (the traversal skips them unread). */
static void set_interior(kd_build *c, uint32_t node, int k, float split, bool below_empty, uint32_t above)
{
    uint32_t bits;
    memcpy(&bits, &split, 4);
    c->nodes[node].a = bits;
    uint32_t flags = (below_empty ? KD_BELOW_EMPTY : 0u) | (c->nodes[above].b == KD_LEAF_TAG ? KD_ABOVE_EMPTY : 0u);
    c->nodes[node].b = (uint32_t)k | flags | (above << 4);
}

static void build_rec(kd_build *c, rt_box V, uint64_t *ev, size_t cnt[3], size_t nprims, int depth);

static void *fork_worker(void *arg);
static void free_forks(kd_build *c);

/* Sides of the primitives of a split at best_key on the axis whose events
 * are E[0..n) (a primitive's events come in the order START, END): left,
 * right, or both; the straddlers go to c->strad. Returns their count. */
static size_t classify(kd_build *c, const uint64_t *E, size_t n, uint32_t best_key, int best_side)
{
    uint8_t *side = c->side;
    size_t ns = 0;
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
    return ns;
}

/* The new events of a split's straddling primitives, clipped to each child
 * and sorted per axis, in one block (buf) that owns the six lists. */
typedef struct kd_straddlers {
    uint64_t *buf;
    uint64_t *l[3], *r[3];
    size_t lcnt[3], rcnt[3];
    size_t npl, npr; /* straddlers kept on each side */
} kd_straddlers;

/* Fills *x for the ns straddlers in c->strad; false when out of memory. */
static bool clip_straddlers(const kd_build *c, size_t ns, rt_box VL, rt_box VR, kd_straddlers *x)
{
    memset(x, 0, sizeof *x);
    if (ns == 0)
        return true;
    x->buf = malloc(ns * 14 * sizeof *x->buf); /* 6 lists of 2 ns + sort scratch 2 ns */
    if (!x->buf)
        return false;
    for (int d = 0; d < 3; d++) {
        x->l[d] = x->buf + (size_t)d * 2 * ns;
        x->r[d] = x->buf + (size_t)(3 + d) * 2 * ns;
    }
    for (size_t i = 0; i < ns; i++) {
        uint32_t p = c->strad[i];
        rt_box b;
        if (prim_clip_bounds(c, p, VL, &b)) {
            emit_events(b, p, x->l, x->lcnt);
            x->npl++;
        }
        if (prim_clip_bounds(c, p, VR, &b)) {
            emit_events(b, p, x->r, x->rcnt);
            x->npr++;
        }
    }
    uint64_t *scratch = x->buf + 12 * ns;
    for (int d = 0; d < 3; d++) {
        ev_sort(x->l[d], x->lcnt[d], scratch);
        ev_sort(x->r[d], x->rcnt[d], scratch);
    }
    return true;
}

/* A split's two children: each one block of event lists (cnt[3] long) and
 * its primitive count. */
typedef struct kd_children {
    uint64_t *lev, *rev;
    size_t lc[3], rc[3];
    size_t left_prims, right_prims;
} kd_children;

/* Gives back what the worst case of the children's lists did not need
 * (shrinking cannot fail for good) and hands them to ch. */
static void children_shrink(kd_children *ch, uint64_t *lev, size_t lo, size_t lcap, uint64_t *rev, size_t ro,
                            size_t rcap)
{
    uint64_t *t;
    if (lo < lcap && (t = realloc(lev, (lo ? lo : 1) * sizeof *lev)) != NULL)
        lev = t;
    if (ro < rcap && (t = realloc(rev, (ro ? ro : 1) * sizeof *rev)) != NULL)
        rev = t;
    ch->lev = lev;
    ch->rev = rev;
}

/* Filters the parent's lists into the children's blocks by c->side, merging
 * the straddlers' new events in; sized for the worst case, shrunk
 * afterwards. k: the split axis, whose events count the primitives. False
 * when out of memory (nothing allocated then). */
static bool split_events(const kd_build *c, uint64_t *const list[3], const size_t cnt[3], int k, size_t ns,
                         const kd_straddlers *x, kd_children *ch)
{
    const uint8_t *side = c->side;
    size_t total = cnt[0] + cnt[1] + cnt[2];
    size_t lcap = total + x->lcnt[0] + x->lcnt[1] + x->lcnt[2], rcap = total + x->rcnt[0] + x->rcnt[1] + x->rcnt[2];
    uint64_t *lev = malloc((lcap ? lcap : 1) * sizeof *lev);
    uint64_t *rev = malloc((rcap ? rcap : 1) * sizeof *rev);
    if (!lev || !rev) {
        free(lev);
        free(rev);
        return false;
    }
    size_t lo = 0, ro = 0;
    ch->left_prims = x->npl;
    ch->right_prims = x->npr;
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
                ch->left_prims += ev_type(lp[i]) != EV_END;
            for (size_t i = 0; i < b; i++)
                ch->right_prims += ev_type(rp[i]) != EV_END;
        }
        if (ns > 0) {
            merge_back(lp, a, x->l[d], x->lcnt[d]);
            merge_back(rp, b, x->r[d], x->rcnt[d]);
        }
        ch->lc[d] = a + x->lcnt[d];
        ch->rc[d] = b + x->rcnt[d];
        lo += ch->lc[d];
        ro += ch->rc[d];
    }
    children_shrink(ch, lev, lo, lcap, rev, ro, rcap);
    return true;
}

/* Builds the below child (VL) on a thread of its own as fork f, into its
 * own arrays behind a placeholder node, while this thread builds the above
 * child (VR); then makes `node` their parent. */
static void build_forked(kd_build *c, kd_fork *f, uint32_t node, int k, float split, rt_box VL, rt_box VR,
                         kd_children *ch, int depth)
{
    uint32_t ph = push_node(c);
    if (c->oom) {
        free(f);
        free(ch->lev);
        free(ch->rev);
        return;
    }
    c->nodes[ph].a = (uint32_t)c->fork_count;
    c->nodes[ph].b = TASK_MARK;
    c->forks[c->fork_count++] = f;
    kd_build *o = &f->out;
    o->s = c->s;
    o->T = c->T, o->S = c->S, o->Q = c->Q, o->I = c->I, o->skip_objects = c->skip_objects;
    o->kt = c->kt, o->ki = c->ki, o->lambda = c->lambda;
    o->max_depth = c->max_depth;
    o->fork_depth = c->fork_depth, o->fork_min = c->fork_min, o->nprims_total = c->nprims_total;
    o->threads = c->threads;
    f->V = VL;
    f->ev = ch->lev;
    memcpy(f->cnt, ch->lc, sizeof f->cnt);
    f->nprims = ch->left_prims;
    f->depth = depth + 1;
    pthread_t th;
    par_begin(c);
    bool started = pthread_create(&th, NULL, fork_worker, f) == 0;
    if (!started)
        fork_worker(f);
    uint32_t above = (uint32_t)c->node_count;
    build_rec(c, VR, ch->rev, ch->rc, ch->right_prims, depth + 1);
    if (started)
        pthread_join(th, NULL);
    par_end(c);
    if (f->out.oom) {
        c->oom = true;
        c->limit |= f->out.limit;
    }
    if (c->oom)
        return;
    bool below_empty = f->out.node_count == 1 && f->out.nodes[0].b == KD_LEAF_TAG;
    set_interior(c, node, k, split, below_empty, above);
}

/* ------------------------------------------- a large node on many threads */

/* Near the root, where fewer subtrees than threads are being built, a
 * large node cuts each axis' event list into parts (at key changes, so a
 * sweep's group of equal keys stays in one part) and runs each step on
 * them side by side: counts, then the sweeps from the counts of the parts
 * before; the primitives' sides (STARTs and PLANARs, then ENDs); the
 * children's lists (counts, then copies to the offsets they give, then the
 * straddlers merged in). Every step gives what the one-thread step gives,
 * and the best plane is the first cheapest in the same order: the same
 * tree. */
enum { STEP_COUNT, STEP_SWEEP, STEP_STARTS, STEP_ENDS, STEP_SPLIT_COUNT, STEP_SPLIT, STEP_MERGE };

typedef struct kd_node_work {
    kd_build *c;
    uint64_t *const *list;
    kd_axis ax[3];
    kd_plane plane;
    const kd_straddlers *x;
    uint64_t *lbase[3], *rbase[3]; /* the children's lists per axis */
    size_t la[3], rb[3];           /* ... before the straddlers' events */
    int parts;
} kd_node_work;

typedef struct kd_node_part {
    kd_node_work *w;
    int index, step;
    size_t from[3], to[3];
    size_t nl[3], nr[3]; /* STEP_COUNT: non-END, non-START events; then the sweep's counts before the part */
    kd_plane best[3];
    size_t ns; /* straddlers, at c->strad + from[k] */
    size_t nleft[3], nright[3], lprims, rprims;
    uint64_t *lout[3], *rout[3];
} kd_node_part;

static void part_count(kd_node_part *p)
{
    for (int k = 0; k < 3; k++) {
        const uint64_t *E = p->w->list[k];
        size_t nl = 0, nr = 0;
        if (p->w->ax[k].ok)
            for (size_t i = p->from[k]; i < p->to[k]; i++) {
                unsigned t = ev_type(E[i]);
                nl += t != EV_END;
                nr += t != EV_START;
            }
        p->nl[k] = nl;
        p->nr[k] = nr;
    }
}

static void part_sweep(kd_node_part *p)
{
    for (int k = 0; k < 3; k++) {
        p->best[k] = (kd_plane){INFINITY, -1, SIDE_LEFT, 0};
        if (p->w->ax[k].ok)
            sweep(&p->w->ax[k], k, p->w->list[k], p->from[k], p->to[k], p->nl[k], p->nr[k], &p->best[k]);
    }
}

/* classify's START and PLANAR events (ends: its END events, after all
 * parts' starts). */
static void part_sides(kd_node_part *p, bool ends)
{
    kd_plane pl = p->w->plane;
    uint8_t *side = p->w->c->side;
    const uint64_t *E = p->w->list[pl.k];
    uint32_t *strad = p->w->c->strad + p->from[pl.k];
    size_t ns = 0;
    for (size_t i = p->from[pl.k]; i < p->to[pl.k]; i++) {
        uint64_t e = E[i];
        uint32_t key = ev_key(e), q = ev_prim(e);
        unsigned t = ev_type(e);
        if (ends && t == EV_END) {
            if (key <= pl.key)
                side[q] = SIDE_LEFT;
            else if (side[q] == SIDE_BOTH)
                strad[ns++] = q;
        } else if (!ends && t == EV_START) {
            side[q] = key >= pl.key ? SIDE_RIGHT : SIDE_BOTH;
        } else if (!ends && t == EV_PLANAR) {
            side[q] = key < pl.key || (key == pl.key && pl.side == SIDE_LEFT) ? SIDE_LEFT : SIDE_RIGHT;
        }
    }
    p->ns = ns;
}

static void part_split_count(kd_node_part *p)
{
    const uint8_t *side = p->w->c->side;
    int k = p->w->plane.k;
    for (int d = 0; d < 3; d++) {
        const uint64_t *E = p->w->list[d];
        size_t a = 0, b = 0;
        for (size_t i = p->from[d]; i < p->to[d]; i++) {
            uint8_t sd = side[ev_prim(E[i])];
            a += sd == SIDE_LEFT;
            b += sd == SIDE_RIGHT;
        }
        p->nleft[d] = a;
        p->nright[d] = b;
    }
    const uint64_t *E = p->w->list[k];
    p->lprims = p->rprims = 0;
    for (size_t i = p->from[k]; i < p->to[k]; i++) {
        uint8_t sd = side[ev_prim(E[i])];
        bool counts = ev_type(E[i]) != EV_END;
        p->lprims += counts && sd == SIDE_LEFT;
        p->rprims += counts && sd == SIDE_RIGHT;
    }
}

/* split_events' copy, each event to its side's list or to a sink (a
 * write past the part's end would land in the next part's). */
static void part_split(kd_node_part *p)
{
    const uint8_t *side = p->w->c->side;
    for (int d = 0; d < 3; d++) {
        const uint64_t *E = p->w->list[d];
        uint64_t *lp = p->lout[d], *rp = p->rout[d], sink;
        size_t a = 0, b = 0;
        for (size_t i = p->from[d]; i < p->to[d]; i++) {
            uint64_t e = E[i];
            uint8_t sd = side[ev_prim(e)];
            *(sd == SIDE_LEFT ? lp + a : &sink) = e;
            *(sd == SIDE_RIGHT ? rp + b : &sink) = e;
            a += sd == SIDE_LEFT;
            b += sd == SIDE_RIGHT;
        }
    }
}

/* The straddlers' events merged into the six lists, list j of 6 in part j
 * mod parts. */
static void part_merge(kd_node_part *p)
{
    kd_node_work *w = p->w;
    for (int j = p->index; j < 6; j += w->parts) {
        int d = j / 2;
        if (j & 1)
            merge_back(w->rbase[d], w->rb[d], w->x->r[d], w->x->rcnt[d]);
        else
            merge_back(w->lbase[d], w->la[d], w->x->l[d], w->x->lcnt[d]);
    }
}

static void *node_part(void *arg)
{
    kd_node_part *p = arg;
    switch (p->step) {
    case STEP_COUNT: part_count(p); break;
    case STEP_SWEEP: part_sweep(p); break;
    case STEP_STARTS: part_sides(p, false); break;
    case STEP_ENDS: part_sides(p, true); break;
    case STEP_SPLIT_COUNT: part_split_count(p); break;
    case STEP_SPLIT: part_split(p); break;
    default: part_merge(p); break;
    }
    return NULL;
}

static void run_step(kd_node_part *part, int step)
{
    int n = part[0].w->parts;
    for (int i = 0; i < n; i++)
        part[i].step = step;
    run_parts_of(part[0].w->c, node_part, part, sizeof *part, n);
}

/* The parts of a node's lists: each axis' cut at key changes. */
static void node_parts_cut(kd_node_part *part, int n, uint64_t *const list[3], const size_t cnt[3])
{
    for (int k = 0; k < 3; k++) {
        size_t prev = 0;
        for (int i = 0; i < n; i++) {
            size_t b = i + 1 == n ? cnt[k] : part_start(cnt[k], i + 1, n);
            if (b < prev)
                b = prev;
            while (b > 0 && b < cnt[k] && ev_key(list[k][b]) == ev_key(list[k][b - 1]))
                b++;
            part[i].from[k] = prev;
            part[i].to[k] = b;
            prev = b;
        }
    }
}

/* find_plane on the parts. */
static void find_plane_parts(kd_node_work *w, kd_node_part *part, rt_box V, size_t nprims, kd_plane *best)
{
    if (!node_axes(w->c, V, w->ax))
        return;
    run_step(part, STEP_COUNT);
    for (int k = 0; k < 3; k++) {
        size_t nl = 0, nr = nprims;
        for (int i = 0; i < w->parts; i++) {
            size_t dl = part[i].nl[k], dr = part[i].nr[k];
            part[i].nl[k] = nl;
            part[i].nr[k] = nr;
            nl += dl;
            nr -= dr;
        }
    }
    run_step(part, STEP_SWEEP);
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < w->parts; i++)
            if (part[i].best[k].cost < best->cost)
                *best = part[i].best[k];
}

/* classify on the parts (c->strad has room for the axis' events). */
static size_t classify_parts(kd_node_work *w, kd_node_part *part)
{
    run_step(part, STEP_STARTS);
    run_step(part, STEP_ENDS);
    size_t ns = 0;
    uint32_t *strad = w->c->strad;
    for (int i = 0; i < w->parts; i++) {
        memmove(strad + ns, strad + part[i].from[w->plane.k], part[i].ns * sizeof *strad);
        ns += part[i].ns;
    }
    return ns;
}

/* split_events on the parts. */
static bool split_events_parts(kd_node_work *w, kd_node_part *part, const size_t cnt[3], size_t ns,
                               const kd_straddlers *x, kd_children *ch)
{
    run_step(part, STEP_SPLIT_COUNT);
    size_t total = cnt[0] + cnt[1] + cnt[2];
    size_t lcap = total + x->lcnt[0] + x->lcnt[1] + x->lcnt[2], rcap = total + x->rcnt[0] + x->rcnt[1] + x->rcnt[2];
    uint64_t *lev = malloc((lcap ? lcap : 1) * sizeof *lev);
    uint64_t *rev = malloc((rcap ? rcap : 1) * sizeof *rev);
    if (!lev || !rev) {
        free(lev);
        free(rev);
        return false;
    }
    size_t lo = 0, ro = 0;
    ch->left_prims = x->npl;
    ch->right_prims = x->npr;
    for (int d = 0; d < 3; d++) {
        size_t a = 0, b = 0;
        w->lbase[d] = lev + lo;
        w->rbase[d] = rev + ro;
        for (int i = 0; i < w->parts; i++) {
            part[i].lout[d] = lev + lo + a;
            part[i].rout[d] = rev + ro + b;
            a += part[i].nleft[d];
            b += part[i].nright[d];
        }
        w->la[d] = a;
        w->rb[d] = b;
        ch->lc[d] = a + x->lcnt[d];
        ch->rc[d] = b + x->rcnt[d];
        lo += ch->lc[d];
        ro += ch->rc[d];
    }
    for (int i = 0; i < w->parts; i++) {
        ch->left_prims += part[i].lprims;
        ch->right_prims += part[i].rprims;
    }
    run_step(part, STEP_SPLIT);
    if (ns > 0) {
        w->x = x;
        run_step(part, STEP_MERGE);
    }
    children_shrink(ch, lev, lo, lcap, rev, ro, rcap);
    return true;
}

/* The parts of a node of nprims primitives at `depth`, when it is large
 * and threads are left over (NULL: the node runs on this thread). */
static kd_node_part *node_parts(kd_build *c, kd_node_work *w, uint64_t *const list[3], const size_t cnt[3],
                                size_t nprims, int depth)
{
    int n = depth < 8 ? c->threads >> depth : 1;
    if (n < 2 || nprims < KD_PART_MIN_PRIMS || depth >= c->max_depth)
        return NULL;
    kd_node_part *part = calloc((size_t)n, sizeof *part);
    if (!part)
        return NULL;
    *w = (kd_node_work){.c = c, .list = list, .parts = n};
    for (int i = 0; i < n; i++) {
        part[i].w = w;
        part[i].index = i;
    }
    node_parts_cut(part, n, list, cnt);
    return part;
}

/* Builds the subtree of box V from its event lists (one block `ev`, lists of
 * cnt[0], cnt[1], cnt[2] events, owned and freed here) over nprims prims:
 * the best plane (find_plane) or a leaf, the primitives' sides, the
 * straddlers clipped to each child, the children's lists, then the
 * children, the below one on a thread of its own near the root. */
static void build_rec(kd_build *c, rt_box V, uint64_t *ev, size_t cnt[3], size_t nprims, int depth)
{
    uint32_t node = push_node(c);
    if (c->oom) {
        free(ev);
        return;
    }
    uint64_t *list[3] = {ev, ev + cnt[0], ev + cnt[0] + cnt[1]};
    kd_node_work work;
    kd_node_part *parts = node_parts(c, &work, list, cnt, nprims, depth);
    kd_plane pl = {INFINITY, -1, SIDE_LEFT, 0};
    if (nprims > 1 && depth < c->max_depth) {
        if (parts)
            find_plane_parts(&work, parts, V, nprims, &pl);
        else
            find_plane(c, V, list, cnt, nprims, &pl);
    }
    int k = pl.k;
    if (k < 0 || !(pl.cost < c->ki * (double)nprims)) {
        make_leaf(c, node, list[0], cnt[0], nprims, depth);
        free(parts);
        free(ev);
        return;
    }
    if (!rt_grow((void **)&c->strad, &c->strad_cap, parts ? cnt[k] : nprims, sizeof *c->strad)) {
        c->oom = true;
        free(parts);
        free(ev);
        return;
    }
    work.plane = pl;
    size_t ns = parts ? classify_parts(&work, parts) : classify(c, list[k], cnt[k], pl.key, pl.side);

    float split = o2f(pl.key);
    rt_box VL = V, VR = V;
    box_hi(&VL)[k] = split;
    box_lo(&VR)[k] = split;

    kd_straddlers x;
    if (!clip_straddlers(c, ns, VL, VR, &x)) {
        c->oom = true;
        free(parts);
        free(ev);
        return;
    }
    kd_children ch;
    bool ok = parts ? split_events_parts(&work, parts, cnt, ns, &x, &ch) : split_events(c, list, cnt, k, ns, &x, &ch);
    free(parts);
    free(x.buf);
    free(ev);
    if (!ok) {
        c->oom = true;
        return;
    }

    kd_fork *f = NULL;
    if (depth < c->fork_depth && ch.left_prims >= c->fork_min &&
        rt_grow((void **)&c->forks, &c->fork_cap, c->fork_count + 1, sizeof *c->forks) &&
        (f = calloc(1, sizeof *f)) != NULL) {
        build_forked(c, f, node, k, split, VL, VR, &ch, depth);
        return;
    }
    build_rec(c, VL, ch.lev, ch.lc, ch.left_prims, depth + 1);
    if (c->oom) {
        free(ch.rev);
        return;
    }
    uint32_t above = (uint32_t)c->node_count;
    build_rec(c, VR, ch.rev, ch.rc, ch.right_prims, depth + 1);
    if (c->oom)
        return;
    set_interior(c, node, k, split, c->nodes[node + 1].b == KD_LEAF_TAG, above);
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
    if ((nd.b & 3u) == KD_LEAF_TAG) {
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

static bool finite_box(rt_box b) { return rt_finite3(b.lo) && rt_finite3(b.hi); }

/* ------------------------------------------------------- the whole build */

/* Bounds of every primitive (and the triangles' records), the root's three
 * sorted event lists, the recursive build (forked near the root), the forks
 * stitched into one depth-first array, then kdtree_pack.c. */
/* The cost model and the other parameters of a build (params may be NULL;
 * 0 fields take the defaults); returns the threads to build with. */
static int init_build(kd_build *c, const rt_scene *scene, const rt_kdtree_params *params)
{
    memset(c, 0, sizeof *c);
    c->s = scene;
    c->T = (uint32_t)scene->triangles.count;
    c->S = (uint32_t)scene->spheres.count;
    c->Q = (uint32_t)scene->quads.count;
    c->skip_objects = scene->object_count > 0;
    c->I = c->skip_objects ? (uint32_t)scene->instance_count : 0;
    c->kt = params && params->traversal_cost > 0.0f ? params->traversal_cost : 4.0;
    c->ki = params && params->intersect_cost > 0.0f ? params->intersect_cost : 1.0;
    double eb = params && params->empty_bonus > 0.0f ? params->empty_bonus : 0.2;
    if (eb > 1.0)
        eb = 1.0;
    c->lambda = 1.0 - eb;
    int threads = params && params->threads > 0 ? params->threads : rt_cpu_count();
    if (threads < 1)
        threads = 1;
    if (threads > 64)
        threads = 64;
    return threads;
}

/* Primitive i's box as the splits will clip it, and whether it can be hit
 * at all (finite, not degenerate); a triangle's vertices are copied to
 * tree->tri (zeros for one that cannot be hit). Spheres and quads are
 * bounded by clipping against all of space; a triangle's box is its
 * vertices' (the same numbers, without the clipping passes that a million
 * triangles would pay for nothing). */
static bool prim_bounds(const kd_build *c, rt_kdtree *tree, size_t i, rt_box *out)
{
    const rt_box everywhere = {{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};
    const rt_scene *scene = c->s;
    size_t T = c->T, S = c->S, nverts = scene->vertices.count;
    rt_box b = rt_box_empty();
    bool ok = true;
    if (i < T) {
        const uint32_t *ix = scene->triangles.index + 3 * i;
        float *dst = tree->tri + 9 * i;
        memset(dst, 0, 9 * sizeof *dst);
        if (ix[0] >= nverts || ix[1] >= nverts || ix[2] >= nverts ||
            (c->skip_objects && (scene->triangles.flags[i] & RT_TRI_OBJECT))) {
            ok = false; /* (an object's triangle: its instances place it) */
        } else {
            rt_vec3 a = scene->vertices.position[ix[0]], bb = scene->vertices.position[ix[1]],
                    cc = scene->vertices.position[ix[2]];
            rt_vec3 e1 = rt_sub(bb, a), e2 = rt_sub(cc, a);
            ok = rt_finite3(a) && rt_finite3(bb) && rt_finite3(cc) && rt_finite3(e1) && rt_finite3(e2) &&
                 (e1.x != 0.0f || e1.y != 0.0f || e1.z != 0.0f) && (e2.x != 0.0f || e2.y != 0.0f || e2.z != 0.0f);
            if (ok) {
                dst[0] = a.x, dst[1] = a.y, dst[2] = a.z;
                dst[3] = bb.x, dst[4] = bb.y, dst[5] = bb.z;
                dst[6] = cc.x, dst[7] = cc.y, dst[8] = cc.z;
                b = rt_box_point(rt_box_point(rt_box_point(b, a), bb), cc);
            }
        }
    } else if (i >= T + S + c->Q) {
        const rt_box *ib = &scene->instances[i - T - S - c->Q].bounds;
        ok = rt_finite3(ib->lo) && rt_finite3(ib->hi) && prim_clip_bounds(c, (uint32_t)i, everywhere, &b);
    } else if (i < T + S) {
        size_t j = i - T;
        const rt_spheres *sp = &scene->spheres;
        ok = isfinite(sp->cx[j]) && isfinite(sp->cy[j]) && isfinite(sp->cz[j]) && isfinite(sp->radius[j]) &&
             prim_clip_bounds(c, (uint32_t)i, everywhere, &b);
    } else {
        size_t j = i - T - S;
        const rt_quads *q = &scene->quads;
        rt_vec3 p = rt_v3(q->px[j], q->py[j], q->pz[j]), u = rt_v3(q->ux[j], q->uy[j], q->uz[j]),
                v = rt_v3(q->vx[j], q->vy[j], q->vz[j]);
        rt_vec3 nrm = rt_cross(u, v);
        ok = rt_finite3(p) && rt_finite3(u) && rt_finite3(v) && rt_dot(nrm, nrm) > 0.0f &&
             prim_clip_bounds(c, (uint32_t)i, everywhere, &b);
    }
    if (ok && !finite_box(b))
        ok = false;
    *out = b;
    return ok;
}

/* One part of the primitives: their boxes (pass 1), then their events
 * (pass 2, into list at the offsets the parts before it leave). */
typedef struct kd_bound_part {
    const kd_build *c;
    rt_kdtree *tree;
    rt_box *pb;
    size_t from, to;
    size_t nvalid, placed, cnt[3]; /* pass 1: hittable primitives, objects' triangles, events per axis */
    rt_box bounds;
    uint64_t *list[3]; /* pass 2 */
    bool emit;
} kd_bound_part;

static void *bound_part(void *arg)
{
    kd_bound_part *w = arg;
    if (w->emit) {
        size_t n[3] = {0, 0, 0};
        for (size_t i = w->from; i < w->to; i++)
            if (!rt_box_is_empty(w->pb[i]))
                emit_events(w->pb[i], (uint32_t)i, w->list, n);
        return NULL;
    }
    const kd_build *c = w->c;
    w->bounds = rt_box_empty();
    for (size_t i = w->from; i < w->to; i++) {
        if (c->skip_objects && i < c->T && (c->s->triangles.flags[i] & RT_TRI_OBJECT))
            w->placed++;
        rt_box b;
        if (!prim_bounds(c, w->tree, i, &b)) {
            w->pb[i] = rt_box_empty();
            continue;
        }
        w->pb[i] = b;
        w->nvalid++;
        w->bounds = rt_box_union(w->bounds, b);
        for (int k = 0; k < 3; k++)
            w->cnt[k] += (&b.lo.x)[k] == (&b.hi.x)[k] ? 1 : 2;
    }
    return NULL;
}

/* Every primitive's box (pb: empty for one that can never be hit), the
 * tree's bounds and the root's unsorted event lists, in primitive order, in
 * ev (room for 6 N): list k at ev + 2 k nvalid, cnt[k] long; on nt threads.
 * Returns how many primitives can be hit. */
static size_t bound_prims(kd_build *c, rt_kdtree *tree, rt_box *pb, size_t N, int nt, uint64_t *ev,
                          uint64_t *list[3], size_t cnt[3])
{
    kd_bound_part part[KD_MAX_THREADS];
    if (nt < 1 || N < KD_PART_MIN_PRIMS)
        nt = 1;
    for (int i = 0; i < nt; i++)
        part[i] = (kd_bound_part){.c = c, .tree = tree, .pb = pb, .from = part_start(N, i, nt),
                                  .to = part_start(N, i + 1, nt)};
    run_parts_of(c, bound_part, part, sizeof *part, nt);
    size_t nvalid = 0, placed = 0;
    for (int i = 0; i < nt; i++) {
        nvalid += part[i].nvalid;
        placed += part[i].placed;
        if (part[i].nvalid > 0)
            tree->bounds = rt_box_union(tree->bounds, part[i].bounds);
    }
    if (nvalid + placed < N)
        rt_info("kdtree: %zu of %zu primitives can never be hit (non-finite or degenerate) and are left out",
                N - nvalid - placed, N - placed);
    for (int k = 0; k < 3; k++) {
        list[k] = ev + 2 * (size_t)k * nvalid;
        cnt[k] = 0;
    }
    for (int i = 0; i < nt; i++)
        for (int k = 0; k < 3; k++) {
            part[i].list[k] = list[k] + cnt[k];
            cnt[k] += part[i].cnt[k];
            part[i].emit = true;
        }
    run_parts_of(c, bound_part, part, sizeof *part, nt);
    return nvalid;
}

/* Sorts the three event lists (each on nt threads when long) and compacts
 * them into one block at list[0]; false when out of memory. */
static bool sort_events(kd_build *c, uint64_t *list[3], const size_t cnt[3], size_t nvalid, int nt)
{
    uint64_t *ev = list[0];
    uint64_t *tmp = malloc((nvalid ? 2 * nvalid : 1) * sizeof *tmp);
    if (!tmp)
        return false;
    for (int k = 0; k < 3; k++)
        ev_sort_parts(c, list[k], cnt[k], tmp, nt);
    free(tmp);
    /* compact the three lists into one block */
    memmove(ev + cnt[0], list[1], cnt[1] * sizeof *ev);
    memmove(ev + cnt[0] + cnt[1], list[2], cnt[2] * sizeof *ev);
    return true;
}

/* The forked subtrees in place of their placeholders, depth first, in one
 * array of nodes and one of ids; false when out of memory or over the node
 * format (then c->limit). */
static bool stitch_forks(kd_build *c)
{
    size_t nn = 0, ni = 0;
    sum_forks(c, &nn, &ni, &c->st, true);
    if (nn >= ((size_t)1 << KD_INDEX_BITS) || ni > KD_MAX_IDS) {
        c->limit = true;
        return false;
    }
    rt_kdtree_node *nodes = malloc(nn * sizeof *nodes);
    uint32_t *ids = malloc((ni ? ni : 1) * sizeof *ids);
    if (!nodes || !ids) {
        free(nodes);
        free(ids);
        return false;
    }
    size_t on = 0, oi = 0;
    stitch(c, 0, nodes, &on, ids, &oi);
    free_forks(c);
    free(c->nodes);
    free(c->ids);
    c->nodes = nodes;
    c->ids = ids;
    c->node_count = on;
    c->id_count = oi;
    return true;
}

/* The quads' tests without their ray-independent part (cross product,
 * lengths, the degeneracy guard): the same bits. False when out of memory
 * (the packed tree is freed then). */
static bool prepare_quads(rt_kdtree *tree, const rt_scene *scene, size_t Q)
{
    tree->quads = malloc(Q * sizeof *tree->quads);
    if (!tree->quads) {
        free(tree->wide);
        free(tree->prim_ids);
        tree->wide = NULL;
        tree->prim_ids = NULL;
        tree->tri = NULL;
        return false;
    }
    const rt_quads *q = &scene->quads;
    for (size_t i = 0; i < Q; i++)
        tree->quads[i] = rt_quad_prepare(rt_v3(q->px[i], q->py[i], q->pz[i]), rt_v3(q->ux[i], q->uy[i], q->uz[i]),
                                         rt_v3(q->vx[i], q->vy[i], q->vz[i]));
    return true;
}

rt_result rt_kdtree_build(rt_kdtree *tree, const rt_scene *scene, const rt_kdtree_params *params, rt_error *err)
{
    double t0 = 1e3 * rt_now_seconds();
    memset(tree, 0, sizeof *tree);
    tree->scene = scene;
    tree->isa = params && params->portable ? RT_KD_ISA_PORTABLE : rt_kd_isa_best(); /* once a tree */
    tree->lanes = rt_kd_lanes_best(tree->isa, params ? params->lanes : 0);
    tree->bounds = rt_box_empty();
    size_t T = scene->triangles.count, S = scene->spheres.count, Q = scene->quads.count;
    size_t I = scene->object_count > 0 ? scene->instance_count : 0, N = T + S + Q + I;
    if (N >= (size_t)PRIM_MASK)
        return rt_fail(err, RT_ERR_LIMIT, "kdtree: %zu primitives, at most %u supported", N, PRIM_MASK - 1u);
    tree->triangle_count = T;
    tree->sphere_count = S;
    tree->quad_count = Q;
    tree->instance_count = I;
    if (scene->object_count > 0) {
        rt_result r = rt_kd_build_objects(tree, scene, params, err);
        if (r != RT_OK)
            return r;
    }

    kd_build c;
    int threads = init_build(&c, scene, params);
    c.threads = threads;
    c.track = true;
    double cpu0 = thread_cpu_ms();
    uint64_t *ev = NULL;
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
    rt_box *pb = malloc((N ? N : 1) * sizeof *pb);
    if (!pb)
        goto oom;
    size_t cnt[3];
    uint64_t *list[3];
    size_t nvalid = bound_prims(&c, tree, pb, N, threads, ev, list, cnt);
    free(pb);
    if (!sort_events(&c, list, cnt, nvalid, threads))
        goto oom;

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
    if (c.fork_count > 0 && !stitch_forks(&c))
        goto oom;
    free(c.side);
    free(c.strad);
    c.side = NULL;
    c.strad = NULL;
    rt_kd_binary bin = {c.nodes, c.node_count, c.ids, c.id_count};
    if (!rt_kd_pack_wide(tree, &bin, &c.limit))
        goto oom;
    if (Q > 0 && !prepare_quads(tree, scene, Q))
        goto oom;
    c.st.nodes = c.node_count;
    c.st.wide_nodes = tree->wide_count;
    c.st.bytes = tree->wide_count * sizeof *tree->wide + tree->prim_id_count * sizeof *tree->prim_ids +
                 Q * sizeof *tree->quads;
    for (size_t o = 0; o < tree->object_count; o++)
        c.st.bytes += tree->objects[o].stats.bytes;
    free(c.nodes);
    free(c.ids);
    c.st.build_ms = 1e3 * rt_now_seconds() - t0;
    c.st.serial_cpu_ms = thread_cpu_ms() - cpu0 - c.par_cpu_ms;
    tree->stats = c.st;
    return RT_OK;

oom:
    free_forks(&c);
    free(ev);
    free(c.side);
    free(c.strad);
    free(c.nodes);
    free(c.ids);
    free(tree->tri);
    rt_kd_free_objects(tree);
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
    free(tree->prim_ids); /* tree->tri is the same array */
    free(tree->quads);
    rt_kd_free_objects(tree);
    memset(tree, 0, sizeof *tree);
}
