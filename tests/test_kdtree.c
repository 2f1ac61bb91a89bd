/* test_kdtree.c - the kd-tree against brute force.
 *
 * Every scene here is checked the same way: thousands of rays are traced
 * through the tree and through a brute-force loop over every primitive with
 * the same functions of intersect.h; the closest hits must have the same t
 * bits and the same primitive (or one that ties at exactly that t), and
 * occluded() must agree with a brute-force any-hit. The scenes are random
 * soups and the layouts that break kd-trees: everything in one plane, 1000
 * copies of a triangle, huge and tiny triangles together, integer boxes whose
 * faces lie on split planes, spheres and quads, non-finite and degenerate
 * input, empty and single-primitive scenes.
 */
#include "test_util.h"

#include <pthread.h>

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_frustum.h"
#include "rt/accel/kdtree_packet.h"

/* ------------------------------------------------------------ helpers */

/* test_kdtree_scalar is this file with RT_KD_SCALAR: every tree it builds
 * takes the portable traversal (params.portable), on any CPU; test_kdtree's
 * trees take what the CPU allows (the AVX2 kernels on this machine). */
#ifdef RT_KD_SCALAR
#define TEST_PORTABLE 1
#else
#define TEST_PORTABLE 0
#endif

static uint32_t add_tri(rt_scene *s, rt_vec3 a, rt_vec3 b, rt_vec3 c)
{
    uint32_t v = rt_scene_add_vertices(s, 3);
    assert_int_not_equal(v, RT_NONE);
    s->vertices.position[v] = a;
    s->vertices.position[v + 1] = b;
    s->vertices.position[v + 2] = c;
    uint32_t t = rt_scene_add_triangle(s, v, v + 1, v + 2, 0, 0);
    assert_int_not_equal(t, RT_NONE);
    return t;
}

static void add_quad_tris(rt_scene *s, rt_vec3 p, rt_vec3 u, rt_vec3 v)
{
    add_tri(s, p, rt_add(p, u), rt_add(rt_add(p, u), v));
    add_tri(s, p, rt_add(rt_add(p, u), v), rt_add(p, v));
}

/* An axis-aligned box of 12 triangles. */
static void add_box_tris(rt_scene *s, rt_vec3 lo, rt_vec3 hi)
{
    rt_vec3 d = rt_sub(hi, lo);
    rt_vec3 ex = rt_v3(d.x, 0, 0), ey = rt_v3(0, d.y, 0), ez = rt_v3(0, 0, d.z);
    add_quad_tris(s, lo, ey, ex);
    add_quad_tris(s, rt_add(lo, ez), ex, ey);
    add_quad_tris(s, lo, ex, ez);
    add_quad_tris(s, rt_add(lo, ey), ez, ex);
    add_quad_tris(s, lo, ez, ey);
    add_quad_tris(s, rt_add(lo, ex), ey, ez);
}

static float rnd(test_rng *r, float lo, float hi) { return lo + (hi - lo) * test_rng_float(r); }
static rt_vec3 rnd3(test_rng *r, float lo, float hi) { return rt_v3(rnd(r, lo, hi), rnd(r, lo, hi), rnd(r, lo, hi)); }

static void random_soup(rt_scene *s, test_rng *r, size_t n, float size)
{
    for (size_t i = 0; i < n; i++) {
        rt_vec3 c = rnd3(r, 0.0f, 1.0f);
        float sz = size * rnd(r, 0.2f, 1.0f);
        add_tri(s, rt_add(c, rnd3(r, -sz, sz)), rt_add(c, rnd3(r, -sz, sz)), rt_add(c, rnd3(r, -sz, sz)));
    }
}

/* One primitive with the reference functions, exactly as kdtree.h promises. */
static bool ref_prim(const rt_scene *s, uint32_t id, const rt_ray *r, float tmax, rt_hit *h)
{
    size_t T = s->triangles.count, S = s->spheres.count;
    float t, u = 0.0f, v = 0.0f;
    if (id < T) {
        rt_vec3 a = rt_tri_vertex(s, id, 0), b = rt_tri_vertex(s, id, 1), c = rt_tri_vertex(s, id, 2);
        if (!rt_intersect_triangle(r->org, r->dir, a, b, c, r->tmin, tmax, &t, &u, &v))
            return false;
    } else if (id < T + S) {
        size_t i = id - T;
        const rt_spheres *sp = &s->spheres;
        if (!rt_intersect_sphere(r->org, r->dir, rt_v3(sp->cx[i], sp->cy[i], sp->cz[i]), sp->radius[i], r->tmin, tmax,
                                 &t))
            return false;
    } else {
        size_t i = id - T - S;
        const rt_quads *q = &s->quads;
        if (!rt_intersect_quad(r->org, r->dir, rt_v3(q->px[i], q->py[i], q->pz[i]), rt_v3(q->ux[i], q->uy[i], q->uz[i]),
                               rt_v3(q->vx[i], q->vy[i], q->vz[i]), r->tmin, tmax, &t, &u, &v))
            return false;
    }
    h->t = t;
    h->u = u;
    h->v = v;
    h->prim = id;
    return true;
}

static bool ref_closest(const rt_scene *s, const rt_ray *r, rt_hit *h)
{
    size_t n = rt_scene_prim_count(s);
    float tmax = r->tmax;
    bool any = false;
    h->prim = RT_NONE;
    for (size_t i = 0; i < n; i++)
        if (ref_prim(s, (uint32_t)i, r, tmax, h)) {
            tmax = h->t;
            any = true;
        }
    return any;
}

static bool ref_any(const rt_scene *s, const rt_ray *r)
{
    rt_hit h;
    size_t n = rt_scene_prim_count(s);
    for (size_t i = 0; i < n; i++)
        if (ref_prim(s, (uint32_t)i, r, r->tmax, &h))
            return true;
    return false;
}

typedef struct check_stats {
    size_t rays, hits, ties;
} check_stats;

/* The tree's answer for one ray against brute force. */
static void check_ray(const rt_scene *s, const rt_kdtree *tree, const rt_ray *r, check_stats *cs)
{
    rt_hit a, b;
    memset(&a, 0x55, sizeof a);
    bool ha = rt_kdtree_intersect(tree, r, &a);
    bool hb = ref_closest(s, r, &b);
    if (ha != hb) {
        fprintf(stderr, "mismatch: kd %d (t %.9g prim %u) brute %d (t %.9g prim %u)\n", ha, (double)a.t, a.prim, hb,
                (double)b.t, b.prim);
        fprintf(stderr, "ray org (%.9g %.9g %.9g) dir (%.9g %.9g %.9g) tmin %.9g tmax %.9g\n", (double)r->org.x,
                (double)r->org.y, (double)r->org.z, (double)r->dir.x, (double)r->dir.y, (double)r->dir.z,
                (double)r->tmin, (double)r->tmax);
    }
    assert_int_equal(ha, hb);
    cs->rays++;
    if (!ha) {
        assert_int_equal(a.prim, RT_NONE);
    } else {
        cs->hits++;
        if (a.t != b.t)
            fprintf(stderr, "t mismatch: kd %.9g (prim %u) brute %.9g (prim %u), ray org (%a %a %a) dir (%a %a %a)\n",
                    (double)a.t, a.prim, (double)b.t, b.prim, (double)r->org.x, (double)r->org.y, (double)r->org.z,
                    (double)r->dir.x, (double)r->dir.y, (double)r->dir.z);
        assert_true(a.t == b.t);
        if (a.prim == b.prim) {
            assert_true(a.u == b.u);
            assert_true(a.v == b.v);
        } else {
            /* a tie: the tree's primitive must hit at exactly this t */
            rt_hit c;
            assert_true(ref_prim(s, a.prim, r, r->tmax, &c));
            assert_true(c.t == a.t);
            assert_true(c.u == a.u && c.v == a.v);
            cs->ties++;
        }
    }
    assert_int_equal(rt_kdtree_occluded(tree, r), ref_any(s, r));
}

/* Every primitive that can be hit appears in some leaf; stats add up. */
/* Walks the wide nodes from the root: each is reached exactly once, its
 * planes are real (axis 0-2, finite) or +inf padding, and every leaf list is
 * in range and ascending. */
typedef struct walk_state {
    const rt_scene *s;
    const rt_kdtree *tree;
    uint8_t *seen, *node_seen;
    size_t n, refs, maxleaf, leaves;
    uint32_t *leaf_ids;
} walk_state;

static void walk_ref(walk_state *w, uint32_t ref)
{
    const rt_kdtree *tree = w->tree;
    if (ref == RT_KD_EMPTY)
        return;
    if (ref < RT_KD_LEAF) {
        assert_true(ref < tree->wide_count);
        assert_false(w->node_seen[ref]);
        w->node_seen[ref] = 1;
        const rt_kdtree_wide *nd = &tree->wide[ref];
        for (int p = 0; p < 7; p++) {
            unsigned axis = (nd->axes >> (2 * p)) & 3u;
            assert_true(axis < 3);
            assert_true(isfinite(nd->split[p]) || (nd->split[p] == INFINITY && axis == 0));
        }
        assert_int_equal(nd->axes >> 14, 0);
        for (int c = 0; c < 8; c++)
            walk_ref(w, nd->child[c]);
        return;
    }
    const uint32_t *ids;
    size_t c;
    uint32_t one = ref & RT_KD_PAYLOAD;
    if (ref >= RT_KD_ONE) {
        c = 1;
        ids = &one;
    } else {
        assert_true(one < tree->prim_id_count);
        c = 1;
        while (!(tree->prim_ids[one + c - 1] & RT_KD_LAST))
            c++;
        assert_true(c > 1 && one + c <= tree->prim_id_count);
        w->leaf_ids = realloc(w->leaf_ids, c * sizeof *w->leaf_ids);
        assert_non_null(w->leaf_ids);
        for (size_t j = 0; j < c; j++)
            w->leaf_ids[j] = tree->prim_ids[one + j] & RT_KD_PAYLOAD;
        ids = w->leaf_ids;
    }
    w->leaves++;
    w->refs += c;
    if (c > w->maxleaf)
        w->maxleaf = c;
    for (size_t j = 0; j < c; j++) {
        if (j > 0) /* ascending: triangles first, as the leaf loop expects */
            assert_true(ids[j - 1] < ids[j]);
        /* a triangle is its record's offset in the leaf blocks, the record
         * carries the scene's id; spheres and quads come above other_base */
        if (ids[j] < tree->other_base) {
            assert_true(ids[j] + RT_KD_TRI <= tree->prim_id_count);
            if (ref < RT_KD_ONE) /* not inside the leaf's own id list */
                assert_true(ids[j] >= one + c || ids[j] + RT_KD_TRI <= one);
        }
        size_t id = rt_kdtree_scene_prim(tree, ids[j]);
        assert_true(id < w->n);
        assert_true(ids[j] >= tree->other_base || id < w->s->triangles.count);
        w->seen[id] = 1;
    }
}

static void check_tree(const rt_scene *s, const rt_kdtree *tree)
{
    const rt_kdtree_stats *st = &tree->stats;
    size_t n = rt_scene_prim_count(s);
    assert_true(st->nodes > 0);
    assert_true(st->leaves > 0 && st->leaves <= st->nodes);
    assert_int_equal(st->nodes, 2 * st->leaves - 1);
    assert_true(st->empty_leaves <= st->leaves);
    assert_true(st->depth <= tree->max_depth);
    assert_int_equal(st->wide_nodes, tree->wide_count);
    assert_true(tree->wide_count <= st->nodes);
    assert_true(st->bytes >= tree->wide_count * 64);
    assert_int_equal((uintptr_t)tree->wide % 64, 0);
    walk_state w = {s, tree, calloc(n ? n : 1, 1), calloc(tree->wide_count + 1, 1), n, 0, 0, 0, NULL};
    assert_non_null(w.seen);
    assert_non_null(w.node_seen);
    walk_ref(&w, tree->root);
    for (size_t i = 0; i < tree->wide_count; i++)
        assert_true(w.node_seen[i]);
    free(w.node_seen);
    free(w.leaf_ids);
    uint8_t *seen = w.seen;
    size_t refs = w.refs, maxleaf = w.maxleaf, leaves = w.leaves + st->empty_leaves;
    assert_int_equal(leaves, st->leaves);
    assert_int_equal(refs, st->prim_refs);
    assert_int_equal(maxleaf, st->max_leaf_prims);
    /* a primitive left out of the tree must be one that never hits: its box is empty or non-finite */
    for (size_t i = 0; i < n; i++) {
        if (seen[i])
            continue;
        rt_box b = rt_scene_prim_bounds(s, (uint32_t)i);
        bool finite = rt_finite3(b.lo) && rt_finite3(b.hi);
        if (finite && i < s->triangles.count) {
            rt_vec3 a = rt_tri_vertex(s, i, 0);
            rt_vec3 e1 = rt_sub(rt_tri_vertex(s, i, 1), a), e2 = rt_sub(rt_tri_vertex(s, i, 2), a);
            finite = rt_finite3(e1) && rt_finite3(e2) && rt_length2(e1) > 0.0f && rt_length2(e2) > 0.0f;
        } else if (finite && i >= s->triangles.count + s->spheres.count) {
            size_t q = i - s->triangles.count - s->spheres.count;
            rt_vec3 nq = rt_cross(rt_v3(s->quads.ux[q], s->quads.uy[q], s->quads.uz[q]),
                                 rt_v3(s->quads.vx[q], s->quads.vy[q], s->quads.vz[q]));
            finite = rt_dot(nq, nq) > 0.0f;
        }
        if (finite)
            fprintf(stderr, "primitive %zu is in no leaf\n", i);
        assert_false(finite);
    }
    free(seen);
}

/* A random ray: origin in [lo, hi]^3, direction random with some zero and
 * axis-aligned components, and a mix of tmin/tmax. */
static rt_ray random_ray(test_rng *r, float lo, float hi)
{
    rt_vec3 o = rnd3(r, lo, hi);
    rt_vec3 d = rnd3(r, -1.0f, 1.0f);
    uint64_t k = test_rng_next(r);
    switch (k % 8) {
    case 0: d.x = 0.0f; break;
    case 1: d.y = 0.0f, d.z = 0.0f; break;
    case 2: d = rt_scale(d, 1000.0f); break;
    case 3: d = rt_scale(d, 0.001f); break;
    default: break;
    }
    if ((k >> 8) % 4 == 0) /* aim at the middle of the scene */
        d = rt_sub(rt_v3s(0.5f * (lo + hi)), o);
    float tmin = (k >> 12) % 3 == 0 ? 0.0f : rnd(r, 0.0f, 0.01f);
    float tmax = (k >> 16) % 3 == 0 ? rnd(r, 0.1f, 2.0f) : INFINITY;
    if ((k >> 20) % 7 == 0)
        d = rt_neg(d);
    return rt_ray_make(o, d, tmin, tmax);
}

static void report(const char *name, const check_stats *cs)
{
    if (getenv("RT_TEST_VERBOSE"))
        fprintf(stderr, "%s: %zu rays, %zu hits, %zu ties\n", name, cs->rays, cs->hits, cs->ties);
}

static void check_random_rays(const rt_scene *s, const rt_kdtree *tree, uint64_t seed, size_t n, float lo, float hi,
                              check_stats *cs)
{
    test_rng r = {seed};
    for (size_t i = 0; i < n; i++) {
        rt_ray ray = random_ray(&r, lo, hi);
        check_ray(s, tree, &ray, cs);
    }
}

static void build_ok(rt_kdtree *tree, const rt_scene *s)
{
    rt_error err = {0};
    rt_kdtree_params p = {0};
    p.portable = TEST_PORTABLE;
    rt_result res = rt_kdtree_build(tree, s, &p, &err);
#ifdef RT_KD_SCALAR
    assert_int_equal(tree->isa, RT_KD_ISA_PORTABLE);
#elif defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) /* any build: the AVX2 kernels */
        assert_int_equal(tree->isa, RT_KD_ISA_AVX2);
#endif
    if (res != RT_OK)
        fprintf(stderr, "build failed: %s\n", err.message);
    assert_int_equal(res, RT_OK);
    check_tree(s, tree);
}

/* A tree whose packets and frustum tiles run at `lanes` SIMD lanes (16:
 * AVX-512, 8: AVX2 or, in the portable build of this file, single rays):
 * false, with nothing left built, where this CPU does not run that width,
 * so each width is tested on every machine that can run it. */
static bool build_at(rt_kdtree *tree, const rt_scene *s, int lanes)
{
    rt_error err = {0};
    rt_kdtree_params p = {0};
    p.portable = TEST_PORTABLE;
    p.lanes = lanes;
    rt_result res = rt_kdtree_build(tree, s, &p, &err);
    if (res != RT_OK)
        fprintf(stderr, "build failed: %s\n", err.message);
    assert_int_equal(res, RT_OK);
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RT_KD_SCALAR)
    if (lanes == 16 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
        assert_int_equal(tree->lanes, 16);
    if (lanes == 8 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        assert_int_equal(tree->lanes, 8);
#endif
    if (tree->lanes == lanes || (lanes == 8 && tree->lanes == 0))
        return true;
    fprintf(stderr, "[          ] %d-lane packets: not on this CPU\n", lanes);
    rt_kdtree_free(tree);
    return false;
}

/* -------------------------------------------------------------- tests */

static void test_empty_scene(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    rt_kdtree tree;
    build_ok(&tree, &s);
    rt_hit h;
    h.prim = 7;
    rt_ray r = rt_ray_make(rt_v3(0, 0, -1), rt_v3(0, 0, 1), 0.0f, INFINITY);
    assert_false(rt_kdtree_intersect(&tree, &r, &h));
    assert_int_equal(h.prim, RT_NONE);
    assert_false(rt_kdtree_occluded(&tree, &r));
    assert_int_equal(tree.stats.prim_refs, 0);
    rt_kdtree_free(&tree);
    rt_kdtree_free(&tree); /* twice is harmless */
    rt_scene_free(&s);
}

static void test_single_triangle(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    add_tri(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0));
    rt_kdtree tree;
    build_ok(&tree, &s);
    assert_int_equal(tree.stats.nodes, 1);
    assert_int_equal(tree.stats.prim_refs, 1);
    rt_hit h;
    rt_ray r = rt_ray_make(rt_v3(0.25f, 0.25f, -2), rt_v3(0, 0, 1), 0.0f, INFINITY);
    assert_true(rt_kdtree_intersect(&tree, &r, &h));
    assert_true(h.t == 2.0f);
    assert_int_equal(h.prim, 0);
    assert_true(h.u == 0.25f && h.v == 0.25f);
    r.tmax = 2.0f; /* open interval: t = tmax is a miss */
    assert_false(rt_kdtree_intersect(&tree, &r, &h));
    assert_false(rt_kdtree_occluded(&tree, &r));
    /* the flat root box (z extent 0) with rays in its plane and parallel to it */
    r = rt_ray_make(rt_v3(-1, 0.25f, 0), rt_v3(1, 0, 0), 0.0f, INFINITY);
    assert_false(rt_kdtree_intersect(&tree, &r, &h));
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 11, 2000, -0.5f, 1.5f, &cs);
    report(__func__, &cs);
    assert_true(cs.hits > 50);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_random_soups(void **state)
{
    (void)state;
    static const size_t sizes[] = {300, 1000, 3000};
    static const float tri_size[] = {0.25f, 0.12f, 0.07f};
    for (int i = 0; i < 3; i++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {1234u + (uint64_t)i};
        random_soup(&s, &r, sizes[i], tri_size[i]);
        rt_kdtree tree;
        build_ok(&tree, &s);
        assert_true(tree.stats.leaves > 10);
        assert_true(tree.stats.depth > 3);
        check_stats cs = {0, 0, 0};
        check_random_rays(&s, &tree, 99 + (uint64_t)i, 3000, -0.2f, 1.2f, &cs);
        report(__func__, &cs);
        assert_true(cs.hits > 500);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

static void test_params(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {77};
    random_soup(&s, &r, 1000, 0.05f);
    rt_kdtree_params p[3] = {
        {.traversal_cost = 1.0f, .intersect_cost = 80.0f, .empty_bonus = 0.5f,
         .max_depth = 0, .threads = 0, .portable = TEST_PORTABLE}, /* pbrt's costs: deep trees */
        {.traversal_cost = 1.0f, .intersect_cost = 1.0f, .empty_bonus = 0.0f,
         .max_depth = 0, .threads = 0, .portable = TEST_PORTABLE},
        {.traversal_cost = 10.0f, .intersect_cost = 1.0f, .empty_bonus = 0.0f,
         .max_depth = 3, .threads = 0, .portable = TEST_PORTABLE}, /* shallow */
    };
    for (int i = 0; i < 3; i++) {
        rt_kdtree tree;
        rt_error err = {0};
        assert_int_equal(rt_kdtree_build(&tree, &s, &p[i], &err), RT_OK);
        check_tree(&s, &tree);
        if (i == 2)
            assert_true(tree.stats.depth <= 3);
        check_stats cs = {0, 0, 0};
        check_random_rays(&s, &tree, 5 + (uint64_t)i, 1000, -0.2f, 1.2f, &cs);
        rt_kdtree_free(&tree);
    }
    rt_scene_free(&s);
}

static void test_deepest_tree(void **state)
{
    (void)state;
    /* Triangles ever closer to the origin (distances and sizes halving), with
     * a cost model that splits whenever it can: a tree down to the deepest
     * level the format allows (60, so 20 levels of wide nodes), traced by
     * rays through the cluster. Each wide level can push 7 cells, so this
     * is where the traversal stack is fullest (ASan checks its bound). */
    rt_scene s;
    rt_scene_init(&s);
    for (int k = 0; k < 90; k++)
        for (int axis = 0; axis < 3; axis++) {
            float d = ldexpf(1.0f, -k), e = 0.25f * d;
            rt_vec3 c = rt_v3(axis == 0 ? d : 0.1f * d, axis == 1 ? d : 0.1f * d, axis == 2 ? d : 0.1f * d);
            add_tri(&s, c, rt_add(c, rt_v3(e, 0, 0)), rt_add(c, rt_v3(0, e, e)));
        }
    rt_kdtree_params p = {.traversal_cost = 1.0f, .intersect_cost = 80.0f, .empty_bonus = 0.5f,
         .max_depth = 60, .threads = 1, .portable = TEST_PORTABLE};
    rt_kdtree tree;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(&tree, &s, &p, &err), RT_OK);
    check_tree(&s, &tree);
    assert_true(tree.stats.depth >= 40);
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 91, 3000, -0.05f, 0.05f, &cs);
    check_random_rays(&s, &tree, 92, 1000, -1.0f, 1.0f, &cs);
    report(__func__, &cs);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_one_plane(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {5};
    for (int i = 0; i < 1500; i++) {
        rt_vec3 c = rt_v3(rnd(&r, 0, 1), rnd(&r, 0, 1), 0.5f);
        rt_vec3 a = rt_add(c, rt_v3(rnd(&r, -0.05f, 0.05f), rnd(&r, -0.05f, 0.05f), 0.0f));
        rt_vec3 b = rt_add(c, rt_v3(rnd(&r, -0.05f, 0.05f), rnd(&r, -0.05f, 0.05f), 0.0f));
        rt_vec3 d = rt_add(c, rt_v3(rnd(&r, -0.05f, 0.05f), rnd(&r, -0.05f, 0.05f), 0.0f));
        add_tri(&s, a, b, d);
    }
    rt_kdtree tree;
    build_ok(&tree, &s);
    assert_true(tree.stats.leaves > 10);
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 3, 2000, -0.2f, 1.2f, &cs);
    /* rays in the plane (parallel to it: never hit, must not crash) and through it */
    for (int i = 0; i < 1000; i++) {
        rt_ray ray = rt_ray_make(rt_v3(rnd(&r, -0.5f, 1.5f), rnd(&r, -0.5f, 1.5f), 0.5f),
                                 rt_v3(rnd(&r, -1, 1), rnd(&r, -1, 1), 0.0f), 0.0f, INFINITY);
        check_ray(&s, &tree, &ray, &cs);
        ray = rt_ray_make(rt_v3(rnd(&r, 0, 1), rnd(&r, 0, 1), i % 2 ? 2.0f : -1.0f), rt_v3(0, 0, i % 2 ? -1.0f : 1.0f),
                          0.0f, INFINITY);
        check_ray(&s, &tree, &ray, &cs);
    }
    report(__func__, &cs);
    assert_true(cs.hits > 500);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_identical_triangles(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    for (int i = 0; i < 1000; i++)
        add_tri(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0.5f), rt_v3(0, 1, 0.25f));
    test_rng r = {8};
    random_soup(&s, &r, 100, 0.1f);
    rt_kdtree tree;
    build_ok(&tree, &s);
    /* termination: the copies cannot be separated, so no deep tree of them */
    assert_true(tree.stats.max_leaf_prims >= 1000);
    assert_true(tree.stats.prim_refs < 20000);
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 4, 1000, -0.2f, 1.2f, &cs);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_huge_and_tiny(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {9};
    random_soup(&s, &r, 1000, 1e-4f);
    add_tri(&s, rt_v3(-100, -100, 0.3f), rt_v3(100, -100, 0.6f), rt_v3(0, 100, 0.5f));
    add_tri(&s, rt_v3(-50, 0.5f, -50), rt_v3(50, 0.4f, -50), rt_v3(0, 0.6f, 60));
    for (int i = 0; i < 200; i++) {
        rt_vec3 c = rnd3(&r, 0, 1);
        add_tri(&s, c, rt_add(c, rt_v3(1e-6f, 0, 0)), rt_add(c, rt_v3(0, 1e-6f, 1e-7f)));
    }
    rt_kdtree tree;
    build_ok(&tree, &s);
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 6, 3000, -0.2f, 1.2f, &cs);
    /* rays aimed at tiny triangles */
    for (size_t i = 0; i < 1000; i++) {
        uint32_t t = (uint32_t)(i % s.triangles.count);
        rt_vec3 a = rt_tri_vertex(&s, t, 0), b = rt_tri_vertex(&s, t, 1), c = rt_tri_vertex(&s, t, 2);
        rt_vec3 target = rt_scale(rt_add(rt_add(a, b), c), 1.0f / 3.0f);
        rt_vec3 o = rnd3(&r, -1, 2);
        rt_ray ray = rt_ray_make(o, rt_sub(target, o), 0.0f, INFINITY);
        check_ray(&s, &tree, &ray, &cs);
    }
    report(__func__, &cs);
    assert_true(cs.hits > 1000);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_integer_boxes(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    /* a 4x4x4 lattice of unit cubes with gaps, and touching cubes sharing faces */
    for (int x = 0; x < 4; x++)
        for (int y = 0; y < 4; y++)
            for (int z = 0; z < 4; z++)
                if ((x + y + z) % 2 == 0)
                    add_box_tris(&s, rt_v3((float)(2 * x), (float)(2 * y), (float)(2 * z)),
                                 rt_v3((float)(2 * x + 1), (float)(2 * y + 1), (float)(2 * z + 1)));
    for (int x = 0; x < 4; x++)
        add_box_tris(&s, rt_v3((float)x, 9, 0), rt_v3((float)(x + 1), 10, 1));
    rt_kdtree tree;
    build_ok(&tree, &s);
    check_stats cs = {0, 0, 0};
    test_rng r = {10};
    /* axis-aligned and diagonal rays from integer and half-integer points:
     * they run along faces and edges and hit exactly on split planes */
    static const rt_vec3 dirs[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1},
                                   {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}, {-1, 1, -1}, {2, 1, 0}};
    for (int i = 0; i < 6000; i++) {
        float h = (i % 3 == 0) ? 0.5f : 0.0f;
        rt_vec3 o = rt_v3((float)(test_rng_next(&r) % 12) - 2.0f + h, (float)(test_rng_next(&r) % 13) - 2.0f,
                          (float)(test_rng_next(&r) % 12) - 2.0f + (i % 5 == 0 ? 0.5f : 0.0f));
        rt_vec3 d = dirs[test_rng_next(&r) % (sizeof dirs / sizeof dirs[0])];
        if (i % 2)
            d = rt_neg(d);
        rt_ray ray = rt_ray_make(o, d, i % 4 == 0 ? 0.0f : 1e-3f, INFINITY);
        check_ray(&s, &tree, &ray, &cs);
    }
    check_random_rays(&s, &tree, 12, 2000, -2.0f, 10.0f, &cs);
    report(__func__, &cs);
    assert_true(cs.hits > 1500);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_spheres_and_quads(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {13};
    random_soup(&s, &r, 500, 0.05f);
    for (int i = 0; i < 100; i++)
        rt_scene_add_sphere(&s, rnd3(&r, 0, 1), rnd(&r, 0.001f, 0.08f), 0);
    rt_scene_add_sphere(&s, rt_v3(0.5f, 0.5f, 0.5f), 0.0f, 0); /* zero radius */
    rt_scene_add_sphere(&s, rt_v3(0.5f, 0.5f, 0.5f), 2.0f, 0);  /* encloses everything: hit from inside */
    for (int i = 0; i < 100; i++)
        rt_scene_add_quad(&s, rnd3(&r, 0, 1), rnd3(&r, -0.1f, 0.1f), rnd3(&r, -0.1f, 0.1f), 0);
    rt_scene_add_quad(&s, rt_v3(0, 0, 0.5f), rt_v3(1, 0, 0), rt_v3(0, 1, 0), 0); /* axis-aligned */
    rt_scene_add_quad(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0), rt_v3(2, 0, 0), 0);    /* degenerate: never hits */
    rt_kdtree tree;
    build_ok(&tree, &s);
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 14, 3000, -0.2f, 1.2f, &cs);
    check_random_rays(&s, &tree, 15, 500, -3.0f, 4.0f, &cs);
    report(__func__, &cs);
    assert_true(cs.hits > 2000);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_bad_input(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {16};
    random_soup(&s, &r, 300, 0.1f);
    float nan = NAN, inf = INFINITY;
    add_tri(&s, rt_v3(nan, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0));
    add_tri(&s, rt_v3(0, 0, 0), rt_v3(inf, 0, 0), rt_v3(0, 1, 0));
    add_tri(&s, rt_v3(0, 0, 0), rt_v3(-inf, 0, 0), rt_v3(0, inf, 0));
    add_tri(&s, rt_v3(0.5f, 0.5f, 0.5f), rt_v3(0.5f, 0.5f, 0.5f), rt_v3(0.5f, 0.5f, 0.5f)); /* a point */
    add_tri(&s, rt_v3(0, 0, 0), rt_v3(0.5f, 0.5f, 0.5f), rt_v3(1, 1, 1));                   /* collinear */
    add_tri(&s, rt_v3(0.1f, 0.2f, 0.3f), rt_v3(0.7f, 0.2f, 0.3f), rt_v3(0.1f, 0.2f, 0.3f)); /* zero edge */
    add_tri(&s, rt_v3(-3e38f, 0, 0), rt_v3(3e38f, 0, 0), rt_v3(0, 1, 0));                   /* edge overflows */
    rt_scene_add_sphere(&s, rt_v3(nan, 0, 0), 1.0f, 0);
    rt_scene_add_sphere(&s, rt_v3(0, 0, 0), inf, 0);
    rt_scene_add_quad(&s, rt_v3(0, 0, inf), rt_v3(1, 0, 0), rt_v3(0, 1, 0), 0);
    rt_kdtree tree;
    build_ok(&tree, &s);
    assert_true(rt_finite3(tree.bounds.lo) && rt_finite3(tree.bounds.hi));
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &tree, 17, 2000, -0.2f, 1.2f, &cs);
    /* bad rays hit nothing and do not crash */
    rt_hit h;
    rt_ray bad[] = {
        rt_ray_make(rt_v3(nan, 0.5f, -1), rt_v3(0, 0, 1), 0, inf),
        rt_ray_make(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, nan), 0, inf),
        rt_ray_make(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 0), 0, inf),
        rt_ray_make(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 1), nan, inf),
        rt_ray_make(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 1), 0, nan),
        rt_ray_make(rt_v3(0.5f, 0.5f, -1), rt_v3(0, 0, 1), 5, 1),
        rt_ray_make(rt_v3(inf, 0.5f, -1), rt_v3(0, 0, 1), 0, inf),
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_false(rt_kdtree_intersect(&tree, &bad[i], &h));
        assert_int_equal(h.prim, RT_NONE);
        assert_false(rt_kdtree_occluded(&tree, &bad[i]));
    }
    rt_kdtree_free(&tree);
    rt_scene_free(&s);

    /* nothing valid at all */
    rt_scene_init(&s);
    add_tri(&s, rt_v3(nan, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0));
    build_ok(&tree, &s);
    rt_ray ray = rt_ray_make(rt_v3(0.2f, 0.2f, -1), rt_v3(0, 0, 1), 0, inf);
    assert_false(rt_kdtree_intersect(&tree, &ray, &h));
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_inside_and_far(void **state)
{
    (void)state;
    /* rays starting inside the root box, and scenes far from the origin */
    static const float offsets[] = {0.0f, 1000.0f, -1e5f};
    for (int i = 0; i < 3; i++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {18 + (uint64_t)i};
        random_soup(&s, &r, 800, 0.15f);
        rt_vec3 off = rt_v3s(offsets[i]);
        for (size_t v = 0; v < s.vertices.count; v++)
            s.vertices.position[v] = rt_add(s.vertices.position[v], off);
        rt_kdtree tree;
        build_ok(&tree, &s);
        check_stats cs = {0, 0, 0};
        check_random_rays(&s, &tree, 19, 1500, offsets[i] + 0.2f, offsets[i] + 0.8f, &cs);
        check_random_rays(&s, &tree, 20, 500, offsets[i] - 3.0f, offsets[i] + 4.0f, &cs);
        report(__func__, &cs);
        assert_true(cs.hits > 700);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

typedef struct trace_job {
    const rt_kdtree *tree;
    const rt_ray *rays;
    size_t n;
    rt_hit *out;
    bool *occ;
} trace_job;

static void *trace_thread(void *arg)
{
    trace_job *j = arg;
    for (size_t i = 0; i < j->n; i++) {
        rt_kdtree_intersect(j->tree, &j->rays[i], &j->out[i]);
        j->occ[i] = rt_kdtree_occluded(j->tree, &j->rays[i]);
    }
    return NULL;
}

static void test_extreme_scales(void **state)
{
    (void)state;
    /* the same soup at 1e-9 and 1e12 scene units: epsilons are relative
     * (Moeller-Trumbore multiplies three lengths: scale^3 must stay a float) */
    static const float scales[] = {1e-9f, 1e12f};
    for (int i = 0; i < 2; i++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {26};
        random_soup(&s, &r, 600, 0.15f);
        for (size_t v = 0; v < s.vertices.count; v++)
            s.vertices.position[v] = rt_scale(s.vertices.position[v], scales[i]);
        rt_kdtree tree;
        build_ok(&tree, &s);
        check_stats cs = {0, 0, 0};
        test_rng rr = {27};
        for (int k = 0; k < 1500; k++) {
            rt_ray ray = random_ray(&rr, -0.2f, 1.2f);
            ray.org = rt_scale(ray.org, scales[i]);
            ray.tmin = 0.0f;
            ray.tmax *= scales[i]; /* same direction: t scales with the scene */
            check_ray(&s, &tree, &ray, &cs);
        }
        report(__func__, &cs);
        assert_true(cs.hits > 300);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

static float chaos_coord(test_rng *r)
{
    static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 2.0f, 1e-30f, -1e-30f, 1e30f, -1e30f, 1e-3f, 3.0f};
    uint64_t k = test_rng_next(r) % 100;
    if (k < 50)
        return rnd(r, -2.0f, 2.0f);
    if (k < 75)
        return (float)(int)(test_rng_next(r) % 5) - 2.0f; /* integer lattice: shared planes and edges */
    if (k < 98)
        return special[test_rng_next(r) % (sizeof special / sizeof special[0])];
    return k == 98 ? NAN : INFINITY;
}

static void test_chaos(void **state)
{
    (void)state;
    /* triangles, spheres and quads with coordinates from a mix of lattice
     * points, tiny and huge values and the odd NaN/inf: the build must not
     * fail or crash, and every answer must still be brute force's */
    for (int round = 0; round < 6; round++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {100 + (uint64_t)round};
        for (int i = 0; i < 300; i++) {
            rt_vec3 v[3];
            for (int j = 0; j < 3; j++)
                v[j] = rt_v3(chaos_coord(&r), chaos_coord(&r), chaos_coord(&r));
            add_tri(&s, v[0], v[1], v[2]);
        }
        for (int i = 0; i < 20; i++)
            rt_scene_add_sphere(&s, rt_v3(chaos_coord(&r), chaos_coord(&r), chaos_coord(&r)),
                                fabsf(chaos_coord(&r)) * 0.3f, 0);
        for (int i = 0; i < 20; i++)
            rt_scene_add_quad(&s, rt_v3(chaos_coord(&r), chaos_coord(&r), chaos_coord(&r)),
                              rt_v3(chaos_coord(&r), chaos_coord(&r), chaos_coord(&r)),
                              rt_v3(chaos_coord(&r), chaos_coord(&r), chaos_coord(&r)), 0);
        rt_kdtree tree;
        build_ok(&tree, &s);
        check_stats cs = {0, 0, 0};
        for (int k = 0; k < 800; k++) {
            rt_ray ray = random_ray(&r, -2.5f, 2.5f);
            if (k % 4 == 0) /* from lattice points along lattice directions */
                ray = rt_ray_make(rt_v3((float)(int)(test_rng_next(&r) % 5) - 2.0f, (float)(int)(test_rng_next(&r) % 5) - 2.0f,
                                        -3.0f),
                                  rt_v3((float)(int)(test_rng_next(&r) % 3) - 1.0f, (float)(int)(test_rng_next(&r) % 3) - 1.0f,
                                        1.0f),
                                  0.0f, INFINITY);
            check_ray(&s, &tree, &ray, &cs);
        }
        report(__func__, &cs);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

static void test_edge_rays(void **state)
{
    (void)state;
    /* fans of triangles around shared vertices, with slivers (leaves of 8
     * or more triangles: the 8-wide test) and rays aimed at their vertices,
     * edges and inner points, moved by an ulp either way, at scales 1e-6
     * to 1e6: the 8-wide test's early reject (signs and bounds of u, v
     * times det before the divide) must never drop a lane that the
     * reference test keeps */
    static const float scales[] = {1e-6f, 1.0f, 1e6f};
    static const float uv[][2] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}, {0.5f, 0.5f},
                                  {0.0f, 0.5f}, {0.5f, 0.0f}, {0.25f, 0.25f}};
    for (int si = 0; si < 3; si++) {
        float k = scales[si];
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {300 + (uint64_t)si};
        for (int f = 0; f < 4; f++) {
            rt_vec3 c = rt_scale(rnd3(&r, 0.0f, 1.0f), k);
            enum { FAN = 12 };
            for (int i = 0; i < FAN; i++) {
                float a0 = 6.2831853f * (float)i / FAN, a1 = 6.2831853f * (float)(i + 1) / FAN;
                rt_vec3 p0 = rt_add(c, rt_scale(rt_v3(cosf(a0), sinf(a0), rnd(&r, -0.05f, 0.05f)), 0.3f * k));
                rt_vec3 p1 = rt_add(c, rt_scale(rt_v3(cosf(a1), sinf(a1), rnd(&r, -0.05f, 0.05f)), 0.3f * k));
                add_tri(&s, c, p0, p1);
                /* a sliver along the spoke (1:30, 1:300 or 1:3000): det
                 * small for most rays. With Moeller-Trumbore (before
                 * session 4) slivers of 1:300 and thinner got hits up to
                 * 1e-4 of the scene outside the triangle's box, which no
                 * cell holds, and the tree differed from brute force; the
                 * watertight test has no such hits */
                float thin = i % 3 == 0 ? 1e-2f : i % 3 == 1 ? 1e-3f : 1e-4f;
                add_tri(&s, c, p0, rt_add(rt_scale(rt_add(c, p0), 0.5f), rt_scale(rnd3(&r, -1.0f, 1.0f), thin * k)));
            }
        }
        rt_kdtree tree;
        build_ok(&tree, &s);
        check_stats cs = {0, 0, 0};
        for (size_t t = 0; t < s.triangles.count; t++) {
            rt_vec3 a = rt_tri_vertex(&s, t, 0), e1 = rt_sub(rt_tri_vertex(&s, t, 1), a),
                    e2 = rt_sub(rt_tri_vertex(&s, t, 2), a);
            for (size_t j = 0; j < sizeof uv / sizeof uv[0]; j++) {
                rt_vec3 p = rt_add(a, rt_add(rt_scale(e1, uv[j][0]), rt_scale(e2, uv[j][1])));
                for (int w = 0; w < 3; w++) {
                    rt_vec3 q = p;
                    if (w > 0) { /* an ulp off, each coordinate either way */
                        float *c3[3] = {&q.x, &q.y, &q.z};
                        for (int m = 0; m < 3; m++)
                            *c3[m] = nextafterf(*c3[m], (test_rng_next(&r) & 1) ? INFINITY : -INFINITY);
                    }
                    rt_vec3 o = rt_add(q, rt_scale(rnd3(&r, -1.0f, 1.0f), 2.0f * k));
                    rt_ray ray = rt_ray_make(o, rt_sub(q, o), 0.0f, INFINITY);
                    check_ray(&s, &tree, &ray, &cs);
                }
            }
        }
        report(__func__, &cs);
        assert_true(cs.hits > cs.rays / 2);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

/* The answers for a tile of n rays (mask: the rays that hit, h their hits)
 * against brute force: the same hit or miss, the same t bits, the same
 * primitive or one that ties at exactly that t. */
static void check_tile_hits(const rt_scene *s, const rt_ray *rays, int n, uint64_t mask, const rt_hit *h,
                            const char *what, check_stats *cs)
{
    assert_true(n == 64 || mask >> n == 0);
    for (int i = 0; i < n; i++) {
        rt_hit b;
        bool ha = mask >> i & 1, hb = ref_closest(s, &rays[i], &b);
        if (ha != hb || (ha && h[i].t != b.t))
            fprintf(stderr, "%s ray %d of %d: kd %d (t %.9g prim %u) brute %d (t %.9g prim %u)\n", what, i, n, ha,
                    (double)h[i].t, h[i].prim, hb, (double)b.t, b.prim);
        assert_int_equal(ha, hb);
        cs->rays++;
        if (!ha) {
            assert_int_equal(h[i].prim, RT_NONE);
            continue;
        }
        cs->hits++;
        assert_true(h[i].t == b.t);
        if (h[i].prim == b.prim) {
            assert_true(h[i].u == b.u && h[i].v == b.v);
        } else {
            rt_hit c;
            assert_true(ref_prim(s, h[i].prim, &rays[i], rays[i].tmax, &c));
            assert_true(c.t == h[i].t && c.u == h[i].u && c.v == h[i].v);
            cs->ties++;
        }
    }
}

/* The packets' and the frustum's hits are the single walk's to the bit,
 * ties included, at every width: each ray meets the same leaves in the
 * same order with the same closest hit so far (kdtree_packet.c,
 * kdtree_frustum.c), so the renderer can take either. */
static void check_as_single(const rt_kdtree *tree, const rt_ray *rays, int n, uint64_t mask, const rt_hit *h)
{
    for (int i = 0; i < n; i++) {
        rt_hit b;
        bool hb = rt_kdtree_intersect(tree, &rays[i], &b);
        assert_int_equal(hb, (int)(mask >> i & 1));
        if (hb && (b.prim != h[i].prim || b.t != h[i].t || b.u != h[i].u || b.v != h[i].v))
            fprintf(stderr, "tile ray %d of %d: prim %u t %a, single prim %u t %a\n", i, n, h[i].prim,
                    (double)h[i].t, b.prim, (double)b.t);
        assert_true(!hb || (b.prim == h[i].prim && b.t == h[i].t && b.u == h[i].u && b.v == h[i].v));
    }
}

/* One packet of n rays through rt_kdtree_intersect8 (n <= 8) or
 * rt_kdtree_intersect16 against brute force. */
static void check_packet(const rt_scene *s, const rt_kdtree *tree, const rt_ray *rays, int n, check_stats *cs)
{
    rt_hit h[16];
    memset(h, 0x55, sizeof h);
    unsigned mask = n > 8 ? rt_kdtree_intersect16(tree, rays, n, h) : rt_kdtree_intersect8(tree, rays, n, h);
    check_tile_hits(s, rays, n, mask, h, "packet", cs);
    check_as_single(tree, rays, n, mask, h);
}

/* A tile of n rays (up to 64) through rt_kdtree_intersect_frustum against
 * brute force. */
static void check_frustum(const rt_scene *s, const rt_kdtree *tree, const rt_ray *rays, int n, check_stats *cs)
{
    rt_hit h[RT_KD_FRUSTUM_MAX];
    memset(h, 0x55, sizeof h);
    uint64_t mask = rt_kdtree_intersect_frustum(tree, rays, n, h);
    check_tile_hits(s, rays, n, mask, h, "frustum", cs);
    check_as_single(tree, rays, n, mask, h);
}

/* The two scenes of the packet tests: 0, a random soup; 1, integer boxes
 * whose faces lie on split planes. */
static void packet_scene(rt_scene *s, test_rng *r, int which)
{
    if (which == 0) {
        random_soup(s, r, 3000, 0.05f);
    } else {
        for (int i = 0; i < 40; i++) {
            rt_vec3 lo = rt_v3((float)(int)(test_rng_next(r) % 8), (float)(int)(test_rng_next(r) % 8),
                               (float)(int)(test_rng_next(r) % 8));
            add_box_tris(s, lo, rt_add(lo, rt_v3(1.0f + (float)(int)(test_rng_next(r) % 2), 1.0f, 1.0f)));
        }
    }
}

/* A random pinhole camera into a scene of size span, as the packet tests
 * aim their 4x4 tiles of rays: the eye, the forward, right and up axes. */
typedef struct tile_camera {
    rt_vec3 eye, fw, rx, uy;
} tile_camera;

static tile_camera random_tile_camera(test_rng *r, float span)
{
    tile_camera c;
    c.eye = rt_add(rnd3(r, -0.5f * span, 1.5f * span), rt_v3(0, 0, -span));
    rt_vec3 at = rnd3(r, 0.3f * span, 0.7f * span);
    c.fw = rt_normalize(rt_sub(at, c.eye));
    c.rx = rt_normalize(rt_cross(c.fw, rt_v3(0.3f, 1.0f, 0.1f)));
    c.uy = rt_cross(c.rx, c.fw);
    return c;
}

/* The direction of ray i (row-major, 4 a row) of the tile whose first ray
 * is at (x0, y0) on the image plane, its rays pix apart. */
static rt_vec3 tile_dir(const tile_camera *c, float x0, float y0, float pix, int i)
{
    return rt_add(c->fw, rt_add(rt_scale(c->rx, x0 + pix * (float)(i % 4)), rt_scale(c->uy, y0 + pix * (float)(i / 4))));
}

static void packets_at(int lanes)
{
    /* rt_kdtree_intersect8 gives each ray its single-ray (so brute-force)
     * hit: coherent 4x2 tiles of pinhole cameras (the packet path),
     * packets of random rays (mixed direction signs: single rays), rays
     * parallel to an axis, rays that can hit nothing, and n from 1 to 8;
     * a random soup, and integer boxes whose faces lie on split planes */
    for (int sc = 0; sc < 2; sc++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {700 + (uint64_t)sc};
        packet_scene(&s, &r, sc);
        rt_kdtree tree;
        if (!build_at(&tree, &s, lanes)) {
            rt_scene_free(&s);
            return;
        }
        check_stats cs = {0, 0, 0};
        float span = sc == 0 ? 1.0f : 9.0f;
        for (int cam = 0; cam < 40; cam++) {
            tile_camera tc = random_tile_camera(&r, span);
            float pix = cam % 2 ? 1e-3f : 2e-2f; /* tight tiles, and wider ones that straddle edges */
            for (int tile = 0; tile < 30; tile++) {
                float x0 = rnd(&r, -0.5f, 0.5f), y0 = rnd(&r, -0.5f, 0.5f);
                rt_ray rays[16];
                for (int i = 0; i < 16; i++) {
                    rays[i] = rt_ray_make(tc.eye, tile_dir(&tc, x0, y0, pix, i), 0.0f, INFINITY);
                }
                int n = 8;
                switch (tile % 10) {
                case 1: n = 1 + (int)(test_rng_next(&r) % 15); break;
                case 2: rays[3 + 8 * (tile / 10 & 1)].dir.x = 0.0f; break;               /* parallel to an axis */
                case 3: rays[5].tmin = rays[5].tmax = 1.0f; break;  /* an empty interval */
                case 4: rays[0].org.y = NAN; break;                  /* hits nothing */
                case 5: for (int i = 0; i < 16; i++) rays[i] = random_ray(&r, -0.2f * span, 1.2f * span); break;
                case 6: rays[2].tmax = rnd(&r, 0.5f, 2.0f) * span; rays[6].tmin = 0.5f * span; break;
                case 7: rays[7 + 8 * (tile / 10 & 1)].dir = rt_neg(rays[7 + 8 * (tile / 10 & 1)].dir); break; /* one ray the other way */
                default: break;
                }
                check_packet(&s, &tree, rays, n < 8 ? n : 8, &cs); /* 4x2 */
                check_packet(&s, &tree, rays, n == 8 ? 16 : n, &cs); /* 4x4 (n > 8: 16 lanes) */
                check_frustum(&s, &tree, rays, n == 8 ? 16 : n, &cs); /* the 4x4 tile as a frustum */
            }
        }
        report(__func__, &cs);
        assert_true(cs.hits > cs.rays / 10);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

static void test_packets(void **state)
{
    (void)state;
    packets_at(16); /* AVX-512 */
    packets_at(8);  /* AVX2 */
}

/* One packet of n shadow rays through rt_kdtree_occluded8 (n <= 8) or
 * rt_kdtree_occluded16: each ray's bit is the single-ray
 * rt_kdtree_occluded and brute force's any-hit. */
static void check_packet_occluded(const rt_scene *s, const rt_kdtree *tree, const rt_ray *rays, int n, check_stats *cs)
{
    unsigned mask = n > 8 ? rt_kdtree_occluded16(tree, rays, n) : rt_kdtree_occluded8(tree, rays, n);
    assert_true(mask >> n == 0);
    uint64_t fmask = rt_kdtree_occluded_frustum(tree, rays, n); /* the same rays as one frustum */
    assert_true(fmask == mask);
    for (int i = 0; i < n; i++) {
        bool pa = mask >> i & 1, sa = rt_kdtree_occluded(tree, &rays[i]), ba = ref_any(s, &rays[i]);
        if (pa != ba || sa != ba)
            fprintf(stderr, "shadow ray %d of %d: packet %d single %d brute %d (tmin %.9g tmax %.9g)\n", i, n, pa, sa,
                    ba, (double)rays[i].tmin, (double)rays[i].tmax);
        assert_int_equal(pa, ba);
        assert_int_equal(sa, ba);
        cs->rays++;
        cs->hits += pa;
    }
}

static void packets_occluded_at(int lanes)
{
    /* rt_kdtree_occluded8 against single rays and brute force: shadow rays
     * from the hit points of coherent 4x2 tiles to one point light (the
     * packet path when the points lie on one side of the light), from
     * scattered points to one light (mixed signs: single rays), random
     * rays with random intervals, rays whose segment ends exactly on a
     * triangle (tmax = the t of that hit: not occluded by it; one ulp
     * more: occluded), the odd rays of test_packets, and n from 1 to 8 */
    for (int sc = 0; sc < 2; sc++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {900 + (uint64_t)sc};
        packet_scene(&s, &r, sc);
        rt_kdtree tree;
        if (!build_at(&tree, &s, lanes)) {
            rt_scene_free(&s);
            return;
        }
        check_stats cs = {0, 0, 0};
        size_t ends = 0;
        float span = sc == 0 ? 1.0f : 9.0f;
        for (int cam = 0; cam < 40; cam++) {
            tile_camera tc = random_tile_camera(&r, span);
            rt_vec3 light = rnd3(&r, -0.5f * span, 1.5f * span);
            float pix = cam % 2 ? 1e-3f : 2e-2f;
            for (int tile = 0; tile < 30; tile++) {
                float x0 = rnd(&r, -0.5f, 0.5f), y0 = rnd(&r, -0.5f, 0.5f);
                rt_ray rays[16];
                int n = 8, expect[16]; /* known answers: 0, 1 (-1: not known) */
                for (int i = 0; i < 16; i++)
                    expect[i] = -1;
                for (int i = 0; i < 16; i++) { /* a tile's hit points (or points along its rays) to the light */
                    rt_vec3 d = tile_dir(&tc, x0, y0, pix, i);
                    rt_ray pr = rt_ray_make(tc.eye, d, 0.0f, INFINITY);
                    rt_hit h;
                    float t = rt_kdtree_intersect(&tree, &pr, &h) ? h.t : span;
                    rt_vec3 p = rt_add(tc.eye, rt_scale(d, t));
                    rays[i] = rt_ray_make(p, rt_sub(light, p), 1e-4f, 1.0f);
                }
                switch (tile % 10) {
                case 1: n = 1 + (int)(test_rng_next(&r) % 15); break;
                case 2: rays[3 + 8 * (tile / 10 & 1)].dir.x = 0.0f; break;               /* parallel to an axis */
                case 3: rays[5].tmin = rays[5].tmax = 0.5f; break;  /* an empty interval */
                case 4: rays[0].org.y = NAN; break;                  /* hits nothing */
                case 5: /* random rays, random intervals */
                    for (int i = 0; i < 16; i++) {
                        rays[i] = random_ray(&r, -0.2f * span, 1.2f * span);
                        rays[i].tmin = rnd(&r, 0.0f, 0.5f) * span;
                        rays[i].tmax = rays[i].tmin + rnd(&r, 0.0f, 2.0f) * span;
                    }
                    break;
                case 6: /* scattered points to the light: mixed signs */
                    for (int i = 0; i < 16; i++) {
                        rt_vec3 p = rnd3(&r, -0.2f * span, 1.2f * span);
                        rays[i] = rt_ray_make(p, rt_sub(light, p), 0.0f, 1.0f);
                    }
                    break;
                case 7: case 8: { /* segments that end exactly on their first hit: from near the light to
                                   * points of one triangle, or from those points back towards the light */
                    uint32_t tri = (uint32_t)(test_rng_next(&r) % s.triangles.count);
                    rt_vec3 a = rt_tri_vertex(&s, tri, 0), b = rt_tri_vertex(&s, tri, 1), c = rt_tri_vertex(&s, tri, 2);
                    rt_vec3 o = rt_add(light, rnd3(&r, -0.01f * span, 0.01f * span));
                    for (int i = 0; i < 16; i++) {
                        float u = rnd(&r, 0.05f, 0.45f), v = rnd(&r, 0.05f, 0.45f);
                        rt_vec3 q = rt_add(a, rt_add(rt_scale(rt_sub(b, a), u), rt_scale(rt_sub(c, a), v)));
                        rays[i] = tile % 10 == 7 ? rt_ray_make(o, rt_sub(q, o), 0.0f, INFINITY)
                                                 : rt_ray_make(q, rt_sub(o, q), 1e-4f, INFINITY);
                        rt_hit hb;
                        expect[i] = -1;
                        if (!ref_closest(&s, &rays[i], &hb)) {
                            rays[i].tmax = 1.0f;
                            continue;
                        }
                        /* open at tmax: the hit at exactly tmax does not count, one ulp later it does */
                        rays[i].tmax = i % 2 ? hb.t : nextafterf(hb.t, INFINITY);
                        expect[i] = i % 2 == 0;
                        ends++;
                    }
                    break;
                }
                default: break;
                }
                check_packet_occluded(&s, &tree, rays, n < 8 ? n : 8, &cs);
                check_packet_occluded(&s, &tree, rays, n == 8 ? 16 : n, &cs);
                for (int i = 0; i < 16; i++)
                    if (expect[i] >= 0)
                        assert_int_equal(rt_kdtree_occluded(&tree, &rays[i]), expect[i]);
            }
        }
        report(__func__, &cs);
        assert_true(cs.hits > cs.rays / 10 && cs.hits < cs.rays - cs.rays / 10);
        assert_true(ends > 100);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

static void test_packets_occluded(void **state)
{
    (void)state;
    packets_occluded_at(16); /* AVX-512 */
    packets_occluded_at(8);  /* AVX2 */
}

static void frustum_at(int lanes)
{
    /* rt_kdtree_intersect_frustum and rt_kdtree_occluded_frustum on 8x8
     * tiles (64 rays, four groups of 16) against brute force: pinhole
     * cameras outside the scene and inside it, tight tiles and wide ones,
     * the odd rays of test_packets (a ray parallel to an axis, one the
     * other way: the tile goes as packets), n from 1 to 64; then shadow
     * rays from the tile's hit points to a point light, and segments cut
     * at their hit (tmax = t: not occluded; one ulp more: occluded) */
    for (int sc = 0; sc < 2; sc++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {1300 + (uint64_t)sc};
        packet_scene(&s, &r, sc);
        rt_kdtree tree;
        if (!build_at(&tree, &s, lanes)) {
            rt_scene_free(&s);
            return;
        }
        check_stats cs = {0, 0, 0}, cso = {0, 0, 0};
        float span = sc == 0 ? 1.0f : 9.0f;
        for (int cam = 0; cam < 24; cam++) {
            tile_camera tc = random_tile_camera(&r, span);
            if (cam % 3 == 2) /* inside the scene's box */
                tc.eye = rnd3(&r, 0.2f * span, 0.8f * span);
            float pix = cam % 2 ? 1e-3f : 1e-2f;
            for (int tile = 0; tile < 10; tile++) {
                float x0 = rnd(&r, -0.5f, 0.5f), y0 = rnd(&r, -0.5f, 0.5f);
                rt_ray rays[64];
                for (int i = 0; i < 64; i++) {
                    rt_vec3 d = rt_add(tc.fw, rt_add(rt_scale(tc.rx, x0 + pix * (float)(i % 8)),
                                                     rt_scale(tc.uy, y0 + pix * (float)(i / 8))));
                    rays[i] = rt_ray_make(tc.eye, d, 0.0f, INFINITY);
                }
                int n = 64;
                switch (tile) {
                case 1: n = 1 + (int)(test_rng_next(&r) % 63); break;
                case 2: rays[37].dir.x = 0.0f; break;                 /* parallel to an axis */
                case 3: rays[5].tmin = rays[5].tmax = 1.0f; break;    /* an empty interval */
                case 4: rays[40].org.y = NAN; break;                  /* hits nothing */
                case 5: rays[50] = rt_ray_make(tc.eye, rt_neg(rays[50].dir), 0.0f, INFINITY); break;
                case 6: rays[2].tmax = rnd(&r, 0.5f, 2.0f) * span; rays[60].tmin = 0.5f * span; break;
                default: break;
                }
                rt_hit h[64];
                memset(h, 0x55, sizeof h);
                uint64_t m = rt_kdtree_intersect_frustum(&tree, rays, n, h);
                check_tile_hits(&s, rays, n, m, h, "frustum 8x8", &cs);
                check_as_single(&tree, rays, n, m, h);
                /* shadow rays: the hit points (or points along the rays) to a light */
                rt_vec3 light = rnd3(&r, -0.5f * span, 1.5f * span);
                rt_ray sr[64];
                for (int i = 0; i < n; i++) {
                    float t = (m >> i & 1) ? h[i].t : span;
                    rt_vec3 p = rt_add(rays[i].org, rt_scale(rays[i].dir, t));
                    sr[i] = rt_ray_make(p, rt_sub(light, p), 1e-4f, 1.0f);
                    if (tile == 7 && !(rt_finite3(p))) /* a ray that hit nothing: a finite point */
                        sr[i] = rt_ray_make(tc.eye, rt_sub(light, tc.eye), 1e-4f, 1.0f);
                }
                if (tile == 8) /* the camera rays cut at their hit */
                    for (int i = 0; i < n; i++) {
                        sr[i] = rays[i];
                        if (m >> i & 1)
                            sr[i].tmax = i % 2 ? h[i].t : nextafterf(h[i].t, INFINITY);
                    }
                uint64_t o = rt_kdtree_occluded_frustum(&tree, sr, n);
                assert_true(n == 64 || o >> n == 0);
                for (int i = 0; i < n; i++) {
                    bool fa = o >> i & 1, ba = ref_any(&s, &sr[i]);
                    if (fa != ba)
                        fprintf(stderr, "frustum shadow ray %d of %d: %d, brute %d\n", i, n, fa, ba);
                    assert_int_equal(fa, ba);
                    if (tile == 8 && (m >> i & 1))
                        assert_int_equal(fa, i % 2 == 0);
                    cso.rays++;
                    cso.hits += fa;
                }
            }
        }
        report(__func__, &cs);
        report(__func__, &cso);
        assert_true(cs.hits > cs.rays / 10);
        assert_true(cso.hits > cso.rays / 20 && cso.hits < cso.rays - cso.rays / 20);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
}

static void test_frustum(void **state)
{
    (void)state;
    frustum_at(16); /* AVX-512 */
    frustum_at(8);  /* AVX2 */
}

static void test_threads_safe_reads(void **state)
{
    (void)state;
    /* four threads query one tree at once (ThreadSanitizer watches) and get
     * what one thread gets */
    {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {25};
        random_soup(&s, &r, 2000, 0.1f);
        rt_kdtree tree;
        build_ok(&tree, &s);
        enum { NR = 2000, NT = 4 };
        rt_ray *rays = malloc(NR * sizeof *rays);
        rt_hit *ref = malloc(NR * sizeof *ref), *out = malloc(NT * NR * sizeof *out);
        bool *occ_ref = malloc(NR), *occ = malloc(NT * NR);
        assert_true(rays && ref && out && occ_ref && occ);
        for (size_t i = 0; i < NR; i++) {
            rays[i] = random_ray(&r, -0.2f, 1.2f);
            if (!rt_kdtree_intersect(&tree, &rays[i], &ref[i]))
                ref[i].t = INFINITY;
            occ_ref[i] = rt_kdtree_occluded(&tree, &rays[i]);
        }
        pthread_t th[NT];
        trace_job jobs[NT];
        for (int k = 0; k < NT; k++) {
            jobs[k] = (trace_job){&tree, rays, NR, out + (size_t)k * NR, occ + (size_t)k * NR};
            assert_int_equal(pthread_create(&th[k], NULL, trace_thread, &jobs[k]), 0);
        }
        for (int k = 0; k < NT; k++)
            pthread_join(th[k], NULL);
        for (int k = 0; k < NT; k++)
            for (size_t i = 0; i < NR; i++) {
                const rt_hit *h = &out[(size_t)k * NR + i];
                assert_int_equal(h->prim, ref[i].prim);
                if (h->prim != RT_NONE)
                    assert_true(h->t == ref[i].t && h->u == ref[i].u && h->v == ref[i].v);
                assert_int_equal(occ[(size_t)k * NR + i], occ_ref[i]);
            }
        free(rays);
        free(ref);
        free(out);
        free(occ_ref);
        free(occ);
        rt_kdtree_free(&tree);
        rt_scene_free(&s);
    }
    /* two trees over one scene are independent; a tree is only read by queries */
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {21};
    random_soup(&s, &r, 500, 0.05f);
    rt_kdtree a, b;
    build_ok(&a, &s);
    build_ok(&b, &s);
    assert_int_equal(a.stats.nodes, b.stats.nodes);
    assert_int_equal(a.wide_count, b.wide_count);
    assert_memory_equal(a.wide, b.wide, a.wide_count * sizeof *a.wide);
    rt_kdtree_free(&a);
    check_stats cs = {0, 0, 0};
    check_random_rays(&s, &b, 22, 500, -0.2f, 1.2f, &cs);
    rt_kdtree_free(&b);
    rt_scene_free(&s);
}

/* The packed tree of a build with `threads` build threads equals tree a,
 * array for array and byte for byte. */
static void assert_same_tree_with_threads(const rt_scene *s, const rt_kdtree *a, int threads)
{
    rt_kdtree_params p = {0};
    p.threads = threads;
    p.portable = TEST_PORTABLE;
    rt_kdtree b;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(&b, s, &p, &err), RT_OK);
    assert_int_equal(a->stats.nodes, b.stats.nodes);
    assert_int_equal(a->wide_count, b.wide_count);
    assert_int_equal(a->root, b.root);
    assert_int_equal(a->prim_id_count, b.prim_id_count);
    assert_int_equal(a->other_base, b.other_base);
    assert_memory_equal(&a->bounds, &b.bounds, sizeof a->bounds);
    assert_memory_equal(a->wide, b.wide, a->wide_count * sizeof *a->wide);
    assert_memory_equal(a->prim_ids, b.prim_ids, a->prim_id_count * sizeof *a->prim_ids);
    assert_int_equal(a->stats.leaves, b.stats.leaves);
    assert_int_equal(a->stats.empty_leaves, b.stats.empty_leaves);
    assert_int_equal(a->stats.prim_refs, b.stats.prim_refs);
    assert_int_equal(a->stats.depth, b.stats.depth);
    rt_kdtree_free(&b);
}

static void test_parallel_build_identical(void **state)
{
    (void)state;
    /* subtrees built as parallel tasks, and the large nodes near the root
     * cut into parts on several threads (sweeps, sides, the children's
     * lists, the root's bounds and sort) must give exactly the serial tree:
     * a random soup (straddlers everywhere), and triangles whose vertices
     * lie on 25 planes an axis (long runs of equal event keys that the parts must
     * not cut, planar triangles on the split planes) */
    for (int scene = 0; scene < 2; scene++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {23};
        if (scene == 0) {
            random_soup(&s, &r, 70000, 0.03f);
        } else {
            /* small triangles on an integer grid: every key is shared by
             * thousands of events */
            for (int i = 0; i < 40000; i++) {
                rt_vec3 o = rt_v3((float)(test_rng_next(&r) % 24), (float)(test_rng_next(&r) % 24),
                                  (float)(test_rng_next(&r) % 24)), v[3];
                for (int j = 0; j < 3; j++)
                    v[j] = rt_add(o, rt_v3((float)(test_rng_next(&r) % 2), (float)(test_rng_next(&r) % 2),
                                           (float)(test_rng_next(&r) % 2)));
                add_tri(&s, v[0], v[1], v[2]);
            }
        }
        rt_kdtree_params p1 = {0};
        p1.threads = 1;
        p1.portable = TEST_PORTABLE;
        rt_kdtree a;
        rt_error err = {0};
        assert_int_equal(rt_kdtree_build(&a, &s, &p1, &err), RT_OK);
        check_tree(&s, &a);
        for (int t = 2; t <= 4; t++)
            assert_same_tree_with_threads(&s, &a, t);
        check_stats cs = {0, 0, 0};
        check_random_rays(&s, &a, 24, 300, -0.2f, 1.2f, &cs);
        report(__func__, &cs);
        rt_kdtree_free(&a);
        rt_scene_free(&s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_empty_scene),
        cmocka_unit_test(test_single_triangle),
        cmocka_unit_test(test_random_soups),
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_deepest_tree),
        cmocka_unit_test(test_one_plane),
        cmocka_unit_test(test_identical_triangles),
        cmocka_unit_test(test_huge_and_tiny),
        cmocka_unit_test(test_integer_boxes),
        cmocka_unit_test(test_spheres_and_quads),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_inside_and_far),
        cmocka_unit_test(test_extreme_scales),
        cmocka_unit_test(test_chaos),
        cmocka_unit_test(test_edge_rays),
        cmocka_unit_test(test_packets),
        cmocka_unit_test(test_packets_occluded),
        cmocka_unit_test(test_frustum),
        cmocka_unit_test(test_threads_safe_reads),
        cmocka_unit_test(test_parallel_build_identical),
    };
    return cmocka_run_group_tests_name("kdtree", tests, NULL, NULL);
}
