/* kdtree_pack.c - the arrays the kd-tree's traversal reads, made from the
 * build's binary tree (kdtree_build.c): the triangles copied in leaf order,
 * and 64-byte wide nodes of three levels each.
 *
 * Triangles: each is stored as v0, e1 = v1 - v0, e2 = v2 - v0 (as the build
 * computed them, exactly as the reference tests do, so t is bit-identical
 * to testing the scene's triangle directly) plus its scene id, 10 floats
 * (RT_KD_TRI). After the build the triangles are renumbered in the order
 * the depth-first leaves first use them and stored in that order, so a
 * leaf's triangles mostly share cache lines: on the 1M-triangle model
 * +15-30% rays/s (profile: ~40% of the time was the first triangle gather
 * waiting on memory); the scene id in the same record spares the hit a last
 * cache miss into a separate map. Arrays over 2 MB go on transparent huge
 * pages (madvise): +5-15% there, the TLB no longer misses on every node.
 *
 * Wide nodes: for tracing, the binary tree is then packed three levels at a
 * time into 64-byte, cache-line-aligned nodes (rt_kdtree_wide: 7 planes, 8
 * cells, a reference per cell to a wide node, a leaf or nothing; missing
 * planes below a leaf are +inf), in depth-first order. Leaf lists end with
 * a flag on the last id. The binary node loop cost ~20 cycles a level on
 * incoherent rays (a load, then a mispredicted choice of child), and on the
 * 1M-triangle model every other level missed the cache; a wide node costs
 * one line for three levels and one SIMD step (see "Traversal" in
 * kdtree_trace.c).
 *
 * Measured and not kept (docs/performance.md has the numbers): leaves whose
 * triangles got consecutive numbers stored as a range without an id list
 * (too few such leaves: 54.2 -> 54.0 bytes/triangle, no speed change);
 * packing subtrees of at most 8 primitives into one leaf (-0.4
 * bytes/triangle, a little slower everywhere).
 */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* madvise */
#endif
#include "kdtree_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#include "rt/base/alloc.h"
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

/* ------------------------------------------- triangles in leaf order */

/* Renumbers the triangles in the order the depth-first node array first
 * references them and stores their data in that order, so the triangles of
 * a leaf mostly sit next to each other in memory (one or two cache lines
 * per leaf instead of one per triangle); each record ends with the
 * triangle's scene id. Leaf lists stay ascending. */
bool rt_kd_order_triangles(rt_kdtree *tree, rt_kd_binary *bin)
{
    size_t T = tree->triangle_count;
    if (T == 0)
        return true;
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
    for (size_t i = 0; i < bin->node_count; i++) {
        rt_kdtree_node *nd = &bin->nodes[i];
        if ((nd->b & 3u) != KD_LEAF_TAG || nd->b == KD_LEAF_TAG)
            continue;
        uint32_t n = nd->b >> 2;
        uint32_t *p = n == 1 ? &nd->a : bin->ids + nd->a;
        for (uint32_t j = 0; j < n && p[j] < T; j++) {
            if (newid[p[j]] == UINT32_MAX) {
                old[next] = p[j];
                newid[p[j]] = next++;
            }
            p[j] = newid[p[j]];
        }
        kd_sort_ids(p, n); /* ascending again (spheres and quads keep their ids, above every triangle's) */
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

/* Packs the binary tree (bin->nodes, bin->ids) into 64-byte nodes of three
 * levels each (rt_kdtree_wide in kdtree.h), in depth-first order, and
 * copies the leaf lists with RT_KD_LAST set on each list's last id. Cell by cell: follow
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

static bool is_leaf(const rt_kdtree_node *bn, uint32_t i) { return (bn[i].b & 3u) == KD_LEAF_TAG; }

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

bool rt_kd_pack_wide(rt_kdtree *tree, const rt_kd_binary *bin, bool *limit)
{
    kd_widen x;
    memset(&x, 0, sizeof x);
    x.bn = bin->nodes;
    x.bids = bin->ids;
    /* + KD_IDS_PAD: a leaf's length is found by loading 8 ids at a time */
    x.ids = alloc_hot((bin->id_count + KD_IDS_PAD) * sizeof *x.ids);
    if (!x.ids)
        return false;
    tree->root = bin->node_count ? widen_rec(&x, 0) : RT_KD_EMPTY;
    for (size_t i = 0; i < KD_IDS_PAD; i++)
        x.ids[x.in + i] = RT_KD_LAST;
    rt_kdtree_wide *w = NULL;
    if (!x.oom && !x.limit && (w = alloc_hot(x.wn * sizeof *w)) != NULL && x.wn)
        memcpy(w, x.w, x.wn * sizeof *w);
    free(x.w);
    if (!w) {
        free(x.ids);
        *limit = x.limit;
        return false;
    }
    tree->wide = w;
    tree->wide_count = x.wn;
    tree->prim_ids = x.ids;
    tree->prim_id_count = x.in;
    return true;
}
