/* kdtree_pack.c - the arrays the kd-tree's traversal reads, made from the
 * build's binary tree (kdtree_build.c): leaf blocks holding the triangles,
 * and 64-byte wide nodes of up to 7 planes in a treelet of free shape.
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
 * Wide nodes: for tracing, the binary tree is then packed into 64-byte,
 * cache-line-aligned nodes (rt_kdtree_wide: up to 7 planes, 8 cells, a
 * reference per cell to a wide node, a leaf or nothing), in depth-first
 * order. The binary node loop cost ~20 cycles a level on incoherent rays (a
 * load, then a mispredicted choice of child), and on the 1M-triangle model
 * every other level missed the cache; a wide node costs one line and one
 * SIMD step for several levels (see "Traversal" in kdtree_trace.c). Until
 * session 6 a node held the complete three levels below its top plane,
 * which filled 3.0 of its 7 planes (a kd-tree's leaves sit at every depth);
 * now it holds any treelet of up to 7 interior nodes with planes at depth
 * 0-4, chosen greedily by surface area (below), and a shape index into the
 * tree's table of shapes (kdtree.h: parent links per plane and cell, 64
 * bytes a shape, one entry per distinct shape). Nodes hold 4.1-4.2 planes
 * on average, 6.5 of 7 in the nodes rays visit (5.0-5.3 before), and rays
 * take 12-15% fewer steps (docs/performance.md, session 6).
 *
 * Measured and not kept (docs/performance.md has the numbers): treelets with
 * planes down to depth 6 (1% fewer steps, a third doubling round in every
 * step); leaves whose
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

/* Packs the binary tree (bin->nodes, bin->ids) into 64-byte nodes of up to
 * 7 planes each (rt_kdtree_wide in kdtree.h), in depth-first order, and
 * writes the leaf blocks as it meets the leaves. A node's planes are a
 * treelet of the binary tree chosen greedily by surface area, as Wald,
 * Benthin and Boulos (2008) collapse a binary BVH into a 4-wide one (Ylitie,
 * Karras and Laine 2017 choose by a SAH dynamic program instead): from the
 * top node, the interior node on the treelet's frontier whose cell has the
 * largest surface area (the likeliest to be crossed by a ray that enters
 * the node) joins, until 7 have, or none is left above depth
 * KD_TREELET_DEPTH. The cells are the treelet's external positions in
 * depth-first order, below first (so leaves are met, and their blocks
 * written, in the binary tree's depth-first order, as before); each plane's
 * and cell's parent link goes into the shape table, one entry per distinct
 * shape. */
typedef struct kd_widen {
    const rt_kdtree_node *bn;
    const uint32_t *bids;
    rt_kdtree_wide *w;
    size_t wn, wcap;
    rt_kdtree_shape *shape; /* the shape table, in order of first use */
    size_t sn, scap;
    int16_t *shape_of;  /* per shape code (treelet_code): its table index, or -1 */
    size_t planes;      /* planes filled, over all wide nodes */
    uint32_t *blk;      /* the leaf blocks */
    size_t in;          /* words of blk written */
    uint32_t *where;    /* per scene triangle: its record's offset in blk, or KD_NO_NODE */
    const float *tri9;  /* the build's triangles, 9 floats each in scene order */
    uint32_t T, other;  /* triangle count; first id of spheres and quads */
    bool oom, limit;
} kd_widen;

#define KD_NO_NODE UINT32_MAX
#define KD_TREELET 7      /* planes a wide node holds */
#define KD_TREELET_DEPTH 5 /* planes at depth 0-4: two doubling rounds reach the top (kdtree_trace.c) */
#define KD_SHAPE_CODES (1u << 16) /* treelet_code < this */

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
static bool is_inner(const rt_kdtree_node *bn, uint32_t i) { return i != KD_NO_NODE && !is_leaf(bn, i); }

/* The box of interior node i's child on side `above`. */
static rt_box child_box(const rt_kdtree_node *bn, uint32_t i, unsigned above, rt_box box)
{
    float s;
    memcpy(&s, &bn[i].a, 4);
    float *c = above ? &box.lo.x : &box.hi.x;
    c[bn[i].b & 3u] = s;
    return box;
}

static float box_area(rt_box b)
{
    float dx = b.hi.x - b.lo.x, dy = b.hi.y - b.lo.y, dz = b.hi.z - b.lo.z;
    return dx * dy + dy * dz + dz * dx;
}

/* One wide node's treelet while it is laid out. */
typedef struct kd_treelet {
    uint32_t member[KD_TREELET]; /* its interior nodes */
    int members;
    rt_kdtree_wide w;
    rt_kdtree_shape s;
    uint32_t code;              /* preorder, 1 = interior node, 0 = cell, after a leading 1 */
    int planes, cells, depth;   /* depth: the deepest plane's */
    uint32_t target[8];         /* per cell: the binary node (KD_NO_NODE: an empty leaf) */
    rt_box box[8];
} kd_treelet;

static bool in_treelet(const kd_treelet *t, uint32_t i)
{
    for (int k = 0; k < t->members; k++)
        if (t->member[k] == i)
            return true;
    return false;
}

/* Lays the treelet out depth first, below first: planes in preorder,
 * cells in order, each with its parent link (kdtree.h) as it goes. */
static void treelet_layout(const rt_kdtree_node *bn, kd_treelet *t, uint32_t i, rt_box box, int depth, uint32_t link)
{
    if (i != KD_NO_NODE && in_treelet(t, i)) {
        int p = t->planes++;
        memcpy(&t->w.split[p], &bn[i].a, 4);
        t->w.axes |= (bn[i].b & 3u) << (2 * p);
        t->s.plane[p] = link;
        if (depth > t->depth)
            t->depth = depth;
        t->code = t->code << 1 | 1u;
        for (unsigned side = 0; side < 2; side++)
            treelet_layout(bn, t, binary_child(bn, i, side), child_box(bn, i, side, box), depth + 1,
                           (uint32_t)p | side << 3 | (uint32_t)(6 - depth) << 8);
        return;
    }
    int c = t->cells++;
    t->code <<= 1;
    t->s.cell[c] = link;
    t->target[c] = i;
    t->box[c] = box;
}

/* The shape's index in the table, added when new; -1: out of memory. */
static int shape_index(kd_widen *x, const kd_treelet *t)
{
    int16_t *slot = &x->shape_of[t->code];
    if (*slot >= 0)
        return *slot;
    if (!rt_grow((void **)&x->shape, &x->scap, x->sn + 1, sizeof *x->shape))
        return -1;
    x->shape[x->sn] = t->s;
    *slot = (int16_t)x->sn;
    return (int)x->sn++;
}

static uint32_t widen_rec(kd_widen *x, uint32_t top, rt_box box)
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
    kd_treelet t;
    memset(&t, 0, sizeof t);
    /* the treelet: greedy by surface area over the frontier (the interior
     * children of its members; ties: a fixed order) */
    uint32_t front[KD_TREELET + 1];
    rt_box fbox[KD_TREELET + 1];
    int fdepth[KD_TREELET + 1], nf = 0, md = 0;
    uint32_t m = top;
    rt_box mb = box;
    for (;;) {
        t.member[t.members++] = m;
        for (unsigned side = 0; side < 2; side++) {
            uint32_t ch = binary_child(bn, m, side);
            if (is_inner(bn, ch)) {
                front[nf] = ch;
                fbox[nf] = child_box(bn, m, side, mb);
                fdepth[nf] = md + 1;
                nf++;
            }
        }
        if (t.members == KD_TREELET)
            break;
        int best = -1;
        float ba = 0.0f;
        for (int k = 0; k < nf; k++) {
            float ak = box_area(fbox[k]);
            if (fdepth[k] < KD_TREELET_DEPTH && (best < 0 || ak > ba))
                best = k, ba = ak;
        }
        if (best < 0)
            break;
        m = front[best];
        mb = fbox[best];
        md = fdepth[best];
        front[best] = front[nf - 1];
        fbox[best] = fbox[nf - 1];
        fdepth[best] = fdepth[nf - 1];
        nf--;
    }
    for (int p = 0; p < KD_TREELET; p++)
        t.w.split[p] = INFINITY; /* unused planes: +inf on x, never read */
    t.code = 1;
    for (int p = 0; p < 8; p++)
        t.s.plane[p] = t.s.cell[p] = RT_KD_NO_LINK; /* what the shape does not have */
    treelet_layout(bn, &t, top, box, 0, RT_KD_NO_LINK);
    x->planes += (size_t)t.planes;
    int si = shape_index(x, &t);
    if (si < 0) {
        x->oom = true;
        return RT_KD_EMPTY;
    }
    t.w.axes |= (uint32_t)si << RT_KD_SHAPE_SHIFT;
    for (int c = 0; c < 8; c++) {
        t.w.child[c] = c < t.cells ? widen_rec(x, t.target[c], t.box[c]) : RT_KD_EMPTY;
        if (x->oom || x->limit)
            return RT_KD_EMPTY;
    }
    x->w[me] = t.w; /* x->w may have moved */
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
    size_t others = tree->sphere_count + tree->quad_count;
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
    x.shape_of = malloc(KD_SHAPE_CODES * sizeof *x.shape_of);
    if (!x.shape_of) {
        free(x.where);
        free(x.blk);
        return false;
    }
    memset(x.shape_of, 0xff, KD_SHAPE_CODES * sizeof *x.shape_of);
    tree->root = bin->node_count ? widen_rec(&x, 0, tree->bounds) : RT_KD_EMPTY;
    free(x.where);
    free(x.shape_of);
    for (size_t i = 0; i < KD_IDS_PAD; i++)
        x.blk[words + i] = RT_KD_LAST;
    rt_kdtree_wide *w = NULL;
    rt_kdtree_shape *sh = NULL;
    if (!x.oom && !x.limit && (w = alloc_hot(x.wn * sizeof *w)) != NULL && x.wn)
        memcpy(w, x.w, x.wn * sizeof *w);
    if (w && (sh = alloc_hot(x.sn * sizeof *sh)) != NULL && x.sn)
        memcpy(sh, x.shape, x.sn * sizeof *sh);
    free(x.w);
    free(x.shape);
    if (!w || !sh) {
        free(w);
        free(x.blk);
        *limit = x.limit;
        return false;
    }
    tree->wide = w;
    tree->wide_count = x.wn;
    tree->shapes = sh;
    tree->shape_count = x.sn;
    free(tree->tri);
    tree->prim_ids = x.blk;
    tree->tri = (float *)(void *)x.blk;
    tree->prim_id_count = words;
    tree->other_base = x.other;
    return true;
}
