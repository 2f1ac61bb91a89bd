/* kdtree_pack.c - the arrays the kd-tree's traversal reads, made from the
 * build's binary tree (kdtree_build.c): leaf blocks holding the triangles,
 * and 64-byte wide nodes of three levels each.
 *
 * Triangles: each is stored as its vertices v0, v1, v2 (the scene's, so
 * the watertight test gives the bits of testing the scene's triangle
 * directly, and a vertex shared by two triangles is the same number in
 * both: no cracks) plus its scene id, 10 words
 * (RT_KD_TRI). Leaf blocks: one array of 32-bit words holds, leaf after
 * leaf in depth-first order, a leaf's id list (ending with a flag on the
 * last id) followed by the records of the triangles that no earlier leaf
 * used; a triangle's id is its record's offset in that array, a one-
 * primitive leaf's reference is the id itself. So the list and the
 * triangles met first in a leaf share cache lines (or the adjacent line),
 * and the triangles a leaf shares with the leaf before it, which a ray
 * often has just tested, are the only ones elsewhere. Every triangle is
 * stored once (a perfect-split kd-tree puts one in 1.8-2.9 leaves, and a
 * copy per leaf would take 75-115 bytes a triangle where the bound is 64).
 * Before, the triangles were one array in first-use order and the lists
 * another: leaf -> list -> triangles was two dependent cache misses on the
 * 1M-triangle model. Session 1's ordering by first use (one or two cache
 * lines per leaf instead of one per triangle: +15-30% rays/s on the
 * 1M-triangle model) is kept by the same placement; the scene id in the
 * record spares the hit a last cache miss into a separate map. Arrays over
 * 2 MB go on transparent huge pages (madvise): +5-15% there, the TLB no
 * longer misses on every node.
 *
 * Wide nodes: for tracing, the binary tree is then packed three levels at a
 * time into 64-byte, cache-line-aligned nodes (rt_kdtree_wide: 7 planes, 8
 * cells, a reference per cell to a wide node, a leaf or nothing; missing
 * planes below a leaf are +inf), in depth-first order. The binary node loop
 * cost ~20 cycles a level on incoherent rays (a load, then a mispredicted
 * choice of child), and on the 1M-triangle model every other level missed
 * the cache; a wide node costs one line for three levels and one SIMD step
 * (see "Traversal" in kdtree_trace.c).
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

/* ------------------------------------------------------- wide nodes */

/* Packs the binary tree (bin->nodes, bin->ids) into 64-byte nodes of three
 * levels each (rt_kdtree_wide in kdtree.h), in depth-first order, and
 * writes the leaf blocks as it meets the leaves. Cell by cell: follow
 * the cell's three below/above choices down from the top node; a leaf met
 * above the third level takes the cell whose remaining choices are all
 * "below" (the missing planes are +inf, so that cell is the leaf's whole
 * box) and the other cells under it stay empty. */
typedef struct kd_widen {
    const rt_kdtree_node *bn;
    const uint32_t *bids;
    rt_kdtree_wide *w;
    size_t wn, wcap;
    uint32_t *blk;      /* the leaf blocks */
    size_t in;          /* words of blk written */
    uint32_t *where;    /* per scene triangle: its record's offset in blk, or KD_NO_NODE */
    const float *tri9;  /* the build's triangles, 9 floats each in scene order */
    uint32_t T, other;  /* triangle count; first id of spheres and quads */
    bool oom, limit;
} kd_widen;

#define KD_NO_NODE UINT32_MAX

/* The block id of primitive p (a scene id): a triangle's record, stored
 * here when no earlier leaf stored it, or a sphere's or quad's id. */
static uint32_t block_id(kd_widen *x, uint32_t p)
{
    if (p >= x->T)
        return x->other + (p - x->T);
    if (x->where[p] == KD_NO_NODE) {
        uint32_t *r = x->blk + x->in;
        memcpy(r, x->tri9 + 9 * (size_t)p, 9 * sizeof *r);
        r[9] = p;
        x->where[p] = (uint32_t)x->in;
        x->in += RT_KD_TRI;
    }
    return x->where[p];
}

/* A leaf's reference: one primitive, or a block (the id list, then the
 * records of the triangles first used here). */
static uint32_t widen_leaf(kd_widen *x, const rt_kdtree_node *nd)
{
    uint32_t n = nd->b >> 2;
    if (n == 0)
        return RT_KD_EMPTY;
    if (n == 1)
        return RT_KD_ONE | block_id(x, nd->a);
    uint32_t off = (uint32_t)x->in;
    uint32_t *list = x->blk + off;
    x->in += n;
    for (uint32_t j = 0; j < n; j++)
        list[j] = block_id(x, x->bids[nd->a + j]);
    kd_sort_ids(list, n); /* triangles, the lower ids, first */
    list[n - 1] |= RT_KD_LAST;
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
    x.tri9 = tree->tri;
    x.T = (uint32_t)tree->triangle_count;
    /* the blocks' size: every multi-primitive leaf's list, and one record
     * per triangle that some leaf holds */
    x.where = malloc((x.T ? x.T : 1) * sizeof *x.where);
    if (!x.where)
        return false;
    memset(x.where, 0xff, (x.T ? x.T : 1) * sizeof *x.where);
    size_t words = 0;
    for (size_t i = 0; i < bin->node_count; i++) {
        const rt_kdtree_node *nd = &bin->nodes[i];
        if ((nd->b & 3u) != KD_LEAF_TAG || nd->b == KD_LEAF_TAG)
            continue;
        uint32_t n = nd->b >> 2;
        const uint32_t *p = n == 1 ? &nd->a : bin->ids + nd->a;
        if (n > 1)
            words += n;
        for (uint32_t j = 0; j < n; j++)
            if (p[j] < x.T && x.where[p[j]] == KD_NO_NODE) {
                x.where[p[j]] = 0;
                words += RT_KD_TRI;
            }
    }
    memset(x.where, 0xff, (x.T ? x.T : 1) * sizeof *x.where);
    size_t others = tree->sphere_count + tree->quad_count + tree->instance_count;
    if (words + others > RT_KD_PAYLOAD) {
        free(x.where);
        *limit = true;
        return false;
    }
    x.other = (uint32_t)words;
    /* + KD_IDS_PAD: a leaf's length is found by loading 8 ids at a time */
    x.blk = alloc_hot((words + KD_IDS_PAD) * sizeof *x.blk);
    if (!x.blk) {
        free(x.where);
        return false;
    }
    tree->root = bin->node_count ? widen_rec(&x, 0) : RT_KD_EMPTY;
    free(x.where);
    for (size_t i = 0; i < KD_IDS_PAD; i++)
        x.blk[words + i] = RT_KD_LAST;
    rt_kdtree_wide *w = NULL;
    if (!x.oom && !x.limit && (w = alloc_hot(x.wn * sizeof *w)) != NULL && x.wn)
        memcpy(w, x.w, x.wn * sizeof *w);
    free(x.w);
    if (!w) {
        free(x.blk);
        *limit = x.limit;
        return false;
    }
    tree->wide = w;
    tree->wide_count = x.wn;
    free(tree->tri);
    tree->prim_ids = x.blk;
    tree->tri = (float *)(void *)x.blk;
    tree->prim_id_count = words;
    tree->other_base = x.other;
    return true;
}
