/* test_wavefront.c - the batch traversal and the wavefront path tracer:
 *   - rt_kdtree_intersect_batch / rt_kdtree_occluded_batch against the
 *     single-ray calls, bit for bit, over triangles, spheres and quads, for
 *     random rays traced in a shuffled subset of lanes;
 */
#include "test_util.h"

#include <math.h>

#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_batch.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/scene.h"

static float rnd(test_rng *r, float lo, float hi) { return lo + (hi - lo) * test_rng_float(r); }

/* a random soup of triangles with spheres and quads among them */
static void soup_scene(rt_scene *s)
{
    rt_error err;
    const char *text = "material m color 0.5 0.5 0.5\n"
                       "sphere 0.2 0.3 0.4 0.15 m\nsphere 0.7 0.6 0.5 0.1 m\nsphere 0.5 0.5 0.5 0.3 m\n"
                       "quad 0 0 0  1 0 0  0 1 0  m\nquad 0.1 0.9 0.1  0.8 0 0  0 0 0.8  m\n";
    rt_scene_init(s);
    if (rt_scene_parse_string(s, text, strlen(text), "soup", NULL, &err) != RT_OK)
        fail_msg("parse: %s", err.message);
    test_rng r = {0x9e3779b97f4a7c15ull};
    for (int i = 0; i < 400; i++) {
        uint32_t v = rt_scene_add_vertices(s, 3);
        assert_int_not_equal(v, RT_NONE);
        rt_vec3 c = rt_v3(rnd(&r, 0, 1), rnd(&r, 0, 1), rnd(&r, 0, 1));
        for (int k = 0; k < 3; k++)
            s->vertices.position[v + (uint32_t)k] =
                rt_add(c, rt_v3(rnd(&r, -0.08f, 0.08f), rnd(&r, -0.08f, 0.08f), rnd(&r, -0.08f, 0.08f)));
        assert_int_not_equal(rt_scene_add_triangle(s, v, v + 1, v + 2, 0, 0), RT_NONE);
    }
}

static void test_batch_traversal_matches_single_rays(void **state)
{
    (void)state;
    rt_scene s;
    soup_scene(&s);
    rt_kdtree tree;
    rt_error err;
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    enum { N = 4096 };
    static float ox[N], oy[N], oz[N], dx[N], dy[N], dz[N], tmin[N], tmax[N], t[N], u[N], v[N];
    static uint32_t prim[N], lanes[N];
    static uint8_t blocked[N];
    test_rng r = {12345};
    for (int i = 0; i < N; i++) {
        ox[i] = rnd(&r, -0.5f, 1.5f), oy[i] = rnd(&r, -0.5f, 1.5f), oz[i] = rnd(&r, -0.5f, 1.5f);
        dx[i] = rnd(&r, -1, 1), dy[i] = rnd(&r, -1, 1), dz[i] = rnd(&r, -1, 1);
        tmin[i] = i % 7 == 0 ? 0.3f : 0.0f;
        tmax[i] = i % 3 == 0 ? rnd(&r, 0.1f, 2.0f) : INFINITY;
        if (i % 101 == 0)
            dx[i] = dy[i] = dz[i] = 0.0f; /* degenerate: hits nothing */
        lanes[i] = (uint32_t)i;
    }
    /* a shuffled subset: every other lane, in random order */
    size_t n = N / 2;
    for (size_t i = 0; i < n; i++)
        lanes[i] = 2u * (uint32_t)i;
    for (size_t i = n - 1; i > 0; i--) {
        size_t j = (size_t)(test_rng_next(&r) % (i + 1));
        uint32_t tmp = lanes[i];
        lanes[i] = lanes[j];
        lanes[j] = tmp;
    }
    for (int i = 0; i < N; i++)
        prim[i] = 0xdeadbeefu, blocked[i] = 7;
    rt_ray_batch rb = {ox, oy, oz, dx, dy, dz, tmin, tmax};
    rt_hit_batch hb = {t, u, v, prim};
    size_t hits = rt_kdtree_intersect_batch(&tree, &rb, lanes, n, &hb);
    size_t blocks = rt_kdtree_occluded_batch(&tree, &rb, lanes, n, blocked);
    size_t want_hits = 0, want_blocks = 0;
    for (int i = 0; i < N; i++) {
        if (i % 2) { /* not in the batch: untouched */
            assert_int_equal(prim[i], 0xdeadbeefu);
            assert_int_equal(blocked[i], 7);
            continue;
        }
        rt_ray ray = rt_ray_make(rt_v3(ox[i], oy[i], oz[i]), rt_v3(dx[i], dy[i], dz[i]), tmin[i], tmax[i]);
        rt_hit h;
        if (rt_kdtree_intersect(&tree, &ray, &h)) {
            want_hits++;
            assert_int_equal(prim[i], h.prim);
            assert_memory_equal(&t[i], &h.t, sizeof h.t);
            assert_memory_equal(&u[i], &h.u, sizeof h.u);
            assert_memory_equal(&v[i], &h.v, sizeof h.v);
        } else {
            assert_int_equal(prim[i], RT_NONE);
        }
        bool occ = rt_kdtree_occluded(&tree, &ray);
        want_blocks += occ;
        assert_int_equal(blocked[i], occ ? 1 : 0);
    }
    assert_int_equal(hits, want_hits);
    assert_int_equal(blocks, want_blocks);
    fprintf(stderr, "%zu of %zu rays hit, %zu blocked\n", hits, n, blocks);
    assert_true(hits > n / 10 && hits < n); /* the rays test something */
    /* lanes NULL: entries 0 .. 63 */
    for (int i = 0; i < 64; i++)
        prim[i] = 0xdeadbeefu;
    rt_kdtree_intersect_batch(&tree, &rb, NULL, 64, &hb);
    for (int i = 0; i < 64; i++)
        assert_int_not_equal(prim[i], 0xdeadbeefu);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_batch_traversal_matches_single_rays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
