/* test_kdtree_stream.c - ray streams (rt/accel/kdtree_stream.h) against the
 * single-ray walk.
 *
 * Every stream is traced at every SIMD width this CPU runs (4 lanes always,
 * 8 with AVX2, 16 with AVX-512) and through trees built for the portable
 * kernels too, for the closest and the any hit, and each ray's answer is
 * checked against rt_kdtree_intersect / rt_kdtree_occluded on the same ray:
 * the same hit or miss, the same t bits, and the same primitive and
 * barycentrics (or, on an exact tie, another primitive that the reference
 * test hits at exactly that t). The widths must agree with each other bit
 * for bit, tie-breaks included. The streams: random triangle soups with
 * rays from outside and inside the bounds, rays with tmin/tmax limits,
 * axis-parallel directions on integer boxes whose faces lie on split
 * planes, spheres and quads, degenerate rays (zero direction, empty
 * interval, infinite origin), empty streams, single rays, chunks and
 * thresholds from 1 ray up, and blocks of the shared benchmark ray sets
 * (skipped, saying why, where they are absent).
 */
#include "test_util.h"

#include <ctype.h>

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_batch.h"
#include "rt/accel/kdtree_stream.h"
#include "rt/io/load.h"
#include "rt/accel/rayset.h"
#include "rt/scene/scene.h"

/* ------------------------------------------------------------ helpers */

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

/* An axis-aligned box of 12 triangles. */
static void add_box_tris(rt_scene *s, rt_vec3 lo, rt_vec3 hi)
{
    rt_vec3 p[8];
    for (int i = 0; i < 8; i++)
        p[i] = rt_v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    static const int f[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (int i = 0; i < 6; i++) {
        add_tri(s, p[f[i][0]], p[f[i][1]], p[f[i][2]]);
        add_tri(s, p[f[i][0]], p[f[i][2]], p[f[i][3]]);
    }
}

/* The scene's primitive id with the reference functions of intersect.h. */
static bool ref_prim(const rt_scene *s, uint32_t id, const rt_ray *r, float *t_out)
{
    size_t T = s->triangles.count, S = s->spheres.count;
    float t, u, v;
    if (id < T) {
        if (!rt_intersect_triangle(r->org, r->dir, rt_tri_vertex(s, id, 0), rt_tri_vertex(s, id, 1),
                                   rt_tri_vertex(s, id, 2), r->tmin, r->tmax, &t, &u, &v))
            return false;
    } else if (id < T + S) {
        const rt_spheres *sp = &s->spheres;
        size_t i = id - T;
        if (!rt_intersect_sphere(r->org, r->dir, rt_v3(sp->cx[i], sp->cy[i], sp->cz[i]), sp->radius[i], r->tmin,
                                 r->tmax, &t))
            return false;
    } else {
        const rt_quads *q = &s->quads;
        size_t i = id - T - S;
        if (!rt_intersect_quad(r->org, r->dir, rt_v3(q->px[i], q->py[i], q->pz[i]), rt_v3(q->ux[i], q->uy[i], q->uz[i]),
                               rt_v3(q->vx[i], q->vy[i], q->vz[i]), r->tmin, r->tmax, &t, &u, &v))
            return false;
    }
    *t_out = t;
    return true;
}

/* A stream's arrays (structure of arrays) for rays[0 .. n). */
typedef struct soa {
    float *a; /* 12 floats a ray: ox oy oz dx dy dz tmin tmax t u v, and prim */
    uint32_t *prim;
    uint8_t *blocked;
    rt_ray_batch rb;
    rt_hit_batch hb;
} soa;

static void soa_make(soa *s, const rt_ray *rays, size_t n)
{
    size_t m = n ? n : 1;
    s->a = malloc(11 * m * sizeof(float));
    s->prim = malloc(m * sizeof(uint32_t));
    s->blocked = malloc(m);
    assert_non_null(s->a);
    assert_non_null(s->prim);
    assert_non_null(s->blocked);
    float *c[11];
    for (int k = 0; k < 11; k++)
        c[k] = s->a + (size_t)k * m;
    for (size_t i = 0; i < n; i++) {
        c[0][i] = rays[i].org.x, c[1][i] = rays[i].org.y, c[2][i] = rays[i].org.z;
        c[3][i] = rays[i].dir.x, c[4][i] = rays[i].dir.y, c[5][i] = rays[i].dir.z;
        c[6][i] = rays[i].tmin, c[7][i] = rays[i].tmax;
    }
    s->rb = (rt_ray_batch){c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]};
    s->hb = (rt_hit_batch){c[8], c[9], c[10], s->prim, NULL};
}

static void soa_free(soa *s)
{
    free(s->a);
    free(s->prim);
    free(s->blocked);
}

static int lanes_list(int *out)
{
    static const int all[3] = {4, 8, 16};
    int n = 0;
    for (int i = 0; i < 3; i++)
        if (rt_kd_stream_lanes_supported(all[i]))
            out[n++] = all[i];
    return n;
}

typedef struct stream_stats {
    size_t rays, hits, blocked, ties;
} stream_stats;

/* rays[0 .. n) as one stream at every width (with params p, lanes set
 * here; NULL: defaults), each answer the single ray's; the widths' answers
 * identical. */
static void check_stream(const rt_scene *scene, const rt_kdtree *tree, const rt_ray *rays, size_t n,
                         const rt_kd_stream_params *p, stream_stats *st)
{
    int lanes[3], nl = lanes_list(lanes);
    soa s, first;
    soa_make(&first, rays, n);
    for (int w = 0; w < nl; w++) {
        soa_make(&s, rays, n);
        rt_kd_stream_params q = p ? *p : (rt_kd_stream_params){0, 0, 0};
        q.lanes = lanes[w];
        size_t hits = rt_kdtree_intersect_stream(tree, &s.rb, n, &s.hb, &q);
        size_t blocked = rt_kdtree_occluded_stream(tree, &s.rb, n, s.blocked, &q);
        size_t h2 = 0, b2 = 0;
        for (size_t i = 0; i < n; i++) {
            rt_hit h;
            bool hit = rt_kdtree_intersect(tree, &rays[i], &h);
            bool occ = rt_kdtree_occluded(tree, &rays[i]);
            h2 += hit;
            b2 += occ;
            if ((s.prim[i] != RT_NONE) != hit || s.blocked[i] != occ)
                fail_msg("lanes %d ray %zu (o %g %g %g d %g %g %g t %g..%g): stream hit %d blocked %d, single %d %d",
                         lanes[w], i, (double)rays[i].org.x, (double)rays[i].org.y, (double)rays[i].org.z,
                         (double)rays[i].dir.x, (double)rays[i].dir.y, (double)rays[i].dir.z, (double)rays[i].tmin,
                         (double)rays[i].tmax, s.prim[i] != RT_NONE, s.blocked[i], hit, occ);
            if (!hit)
                continue;
            float t = s.hb.t[i];
            if (memcmp(&t, &h.t, sizeof t) != 0)
                fail_msg("lanes %d ray %zu: stream t %.9g, single t %.9g", lanes[w], i, (double)t, (double)h.t);
            if (s.prim[i] != h.prim) { /* an exact tie: the other primitive hits at the same t */
                float t2;
                assert_true(ref_prim(scene, s.prim[i], &rays[i], &t2));
                assert_true(t2 == t);
                if (w == 0 && st)
                    st->ties++;
            } else {
                assert_true(memcmp(&s.hb.u[i], &h.u, sizeof h.u) == 0);
                assert_true(memcmp(&s.hb.v[i], &h.v, sizeof h.v) == 0);
            }
        }
        assert_int_equal(hits, h2);
        assert_int_equal(blocked, b2);
        if (w == 0) {
            memcpy(first.a + 8 * (n ? n : 1), s.a + 8 * (n ? n : 1), 3 * (n ? n : 1) * sizeof(float));
            memcpy(first.prim, s.prim, n * sizeof(uint32_t));
            memcpy(first.blocked, s.blocked, n);
            if (st) {
                st->rays += n;
                st->hits += hits;
                st->blocked += blocked;
            }
        } else { /* every width: the same bits as the first, ties included */
            for (size_t i = 0; i < n; i++) {
                assert_int_equal(s.prim[i], first.prim[i]);
                assert_int_equal(s.blocked[i], first.blocked[i]);
                if (s.prim[i] != RT_NONE) {
                    assert_true(memcmp(&s.hb.t[i], &first.hb.t[i], sizeof(float)) == 0);
                    assert_true(memcmp(&s.hb.u[i], &first.hb.u[i], sizeof(float)) == 0);
                    assert_true(memcmp(&s.hb.v[i], &first.hb.v[i], sizeof(float)) == 0);
                }
            }
        }
        soa_free(&s);
    }
    soa_free(&first);
}

static void build_ok(rt_kdtree *tree, const rt_scene *s, int portable)
{
    rt_kdtree_params p;
    memset(&p, 0, sizeof p);
    p.portable = portable;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(tree, s, &p, &err), RT_OK);
}

/* n rays: origins in [lo, hi]^3, directions random (some with a zero
 * component), every fourth with a limited interval. */
static rt_ray *random_rays(test_rng *r, size_t n, float lo, float hi)
{
    rt_ray *rays = malloc((n ? n : 1) * sizeof *rays);
    assert_non_null(rays);
    for (size_t i = 0; i < n; i++) {
        rt_vec3 o = rnd3(r, lo, hi), d = rnd3(r, -1.0f, 1.0f);
        if (i % 7 == 3)
            d.x = 0.0f;
        if (i % 11 == 5)
            d.y = d.z = 0.0f;
        if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f)
            d.x = 1.0f;
        float tmin = 0.0f, tmax = INFINITY;
        if (i % 4 == 1) {
            tmin = rnd(r, 0.0f, 0.5f);
            tmax = tmin + rnd(r, 0.0f, 1.0f);
        }
        rays[i] = rt_ray_make(o, d, tmin, tmax);
    }
    return rays;
}

static void report(const char *name, const stream_stats *st)
{
    fprintf(stderr, "%s: %zu rays, %zu hits, %zu blocked, %zu ties\n", name, st->rays, st->hits, st->blocked, st->ties);
}

/* -------------------------------------------------------------- tests */

static void test_widths(void **state)
{
    (void)state;
    int lanes[3];
    int n = lanes_list(lanes);
    assert_true(n >= 1 && lanes[0] == 4);
    fprintf(stderr, "stream widths this CPU runs:");
    for (int i = 0; i < n; i++)
        fprintf(stderr, " %d", lanes[i]);
    fprintf(stderr, "\n");
    assert_false(rt_kd_stream_lanes_supported(5));
}

static void test_empty_streams(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {7};
    random_soup(&s, &r, 200, 0.1f);
    rt_kdtree tree;
    build_ok(&tree, &s, 0);
    check_stream(&s, &tree, NULL, 0, NULL, NULL);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
    /* an empty scene: every ray misses */
    rt_scene_init(&s);
    build_ok(&tree, &s, 0);
    rt_ray *rays = random_rays(&r, 100, -1.0f, 2.0f);
    stream_stats st = {0, 0, 0, 0};
    check_stream(&s, &tree, rays, 100, NULL, &st);
    assert_int_equal(st.hits, 0);
    free(rays);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_single_rays(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {11};
    random_soup(&s, &r, 1000, 0.1f);
    rt_kdtree tree;
    build_ok(&tree, &s, 0);
    rt_ray *rays = random_rays(&r, 300, -0.2f, 1.2f);
    stream_stats st = {0, 0, 0, 0};
    for (size_t i = 0; i < 300; i++)
        check_stream(&s, &tree, &rays[i], 1, NULL, &st);
    report(__func__, &st);
    assert_true(st.hits > 30);
    free(rays);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_random_scenes(void **state)
{
    (void)state;
    static const size_t sizes[] = {300, 3000, 20000};
    static const float tri_size[] = {0.25f, 0.07f, 0.02f};
    for (int k = 0; k < 3; k++) {
        rt_scene s;
        rt_scene_init(&s);
        test_rng r = {100u + (uint64_t)k};
        random_soup(&s, &r, sizes[k], tri_size[k]);
        for (int portable = 0; portable < 2; portable++) {
            rt_kdtree tree;
            build_ok(&tree, &s, portable);
            stream_stats st = {0, 0, 0, 0};
            /* from outside the bounds and from inside them */
            rt_ray *out = random_rays(&r, 3000, -1.0f, 2.0f), *in = random_rays(&r, 3000, 0.1f, 0.9f);
            check_stream(&s, &tree, out, 3000, NULL, &st);
            check_stream(&s, &tree, in, 3000, NULL, &st);
            /* thresholds and chunks from one ray up */
            static const rt_kd_stream_params ps[] = {{0, 1, 0}, {0, 3, 0}, {0, 64, 0}, {0, 1 << 30, 0},
                                                     {0, 1, 1}, {0, 2, 7}, {0, 4, 1000}};
            for (size_t i = 0; i < sizeof ps / sizeof ps[0]; i++)
                check_stream(&s, &tree, in, 1500, &ps[i], &st);
            report(__func__, &st);
            assert_true(st.hits > 1000);
            free(out);
            free(in);
            rt_kdtree_free(&tree);
        }
        rt_scene_free(&s);
    }
}

static void test_axis_parallel(void **state)
{
    (void)state;
    /* integer boxes: faces on the split planes; rays along the axes and in
     * the planes of faces */
    rt_scene s;
    rt_scene_init(&s);
    for (int x = 0; x < 6; x++)
        for (int y = 0; y < 6; y++)
            for (int z = 0; z < 3; z++)
                if ((x + y + z) % 2 == 0)
                    add_box_tris(&s, rt_v3((float)x, (float)y, (float)z), rt_v3((float)x + 1, (float)y + 1, (float)z + 1));
    rt_kdtree tree;
    build_ok(&tree, &s, 0);
    test_rng r = {5};
    size_t n = 4000;
    rt_ray *rays = malloc(n * sizeof *rays);
    assert_non_null(rays);
    for (size_t i = 0; i < n; i++) {
        rt_vec3 o = rt_v3((float)(int)rnd(&r, -1.0f, 7.0f), (float)(int)rnd(&r, -1.0f, 7.0f),
                          (float)(int)rnd(&r, -1.0f, 4.0f));
        if (i % 2) /* half of them off the lattice */
            o = rt_add(o, rnd3(&r, 0.0f, 1.0f));
        rt_vec3 d = rt_v3(0, 0, 0);
        int axis = (int)(i % 3);
        float sgn = (i / 3) % 2 ? -1.0f : 1.0f;
        if (axis == 0) d.x = sgn;
        else if (axis == 1) d.y = sgn;
        else d.z = sgn;
        if (i % 5 == 0) /* two components */
            d = rt_v3(d.x ? d.x : 0.5f, d.y, d.z ? d.z : 0.0f);
        rays[i] = rt_ray_make(o, d, 0.0f, i % 3 == 1 ? 2.5f : INFINITY);
    }
    stream_stats st = {0, 0, 0, 0};
    check_stream(&s, &tree, rays, n, NULL, &st);
    static const rt_kd_stream_params p1 = {0, 1, 0};
    check_stream(&s, &tree, rays, n, &p1, &st);
    report(__func__, &st);
    assert_true(st.hits > 500);
    free(rays);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_spheres_and_quads(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {21};
    random_soup(&s, &r, 500, 0.08f);
    for (int i = 0; i < 40; i++)
        assert_int_not_equal(rt_scene_add_sphere(&s, rnd3(&r, 0.0f, 1.0f), rnd(&r, 0.01f, 0.1f), 0), RT_NONE);
    for (int i = 0; i < 40; i++)
        assert_int_not_equal(rt_scene_add_quad(&s, rnd3(&r, 0.0f, 1.0f), rnd3(&r, -0.1f, 0.1f), rnd3(&r, -0.1f, 0.1f), 0),
                             RT_NONE);
    rt_kdtree tree;
    build_ok(&tree, &s, 0);
    rt_ray *rays = random_rays(&r, 4000, -0.5f, 1.5f);
    stream_stats st = {0, 0, 0, 0};
    check_stream(&s, &tree, rays, 4000, NULL, &st);
    report(__func__, &st);
    assert_true(st.hits > 200);
    free(rays);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_degenerate_rays(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    test_rng r = {33};
    random_soup(&s, &r, 1000, 0.1f);
    rt_kdtree tree;
    build_ok(&tree, &s, 0);
    rt_ray *rays = random_rays(&r, 512, -0.2f, 1.2f);
    for (size_t i = 0; i < 512; i += 4) {
        switch (i / 4 % 8) {
        case 0: rays[i].dir = rt_v3(0, 0, 0); break;                 /* no direction */
        case 1: rays[i].tmax = rays[i].tmin; break;                   /* empty interval */
        case 2: rays[i].tmin = 1.0f, rays[i].tmax = 0.5f; break;      /* reversed */
        case 3: rays[i].org.x = INFINITY; break;                      /* infinite origin */
        case 4: rays[i].dir = rt_v3(1e-30f, 0, 0); break;             /* 1/d overflows: parallel */
        case 5: rays[i].dir = rt_v3(1e30f, -1e30f, 1e-30f); break;    /* huge and tiny */
        case 6: rays[i].tmin = -INFINITY; break;                      /* from behind the origin */
        default: rays[i].org = rt_v3(1e30f, 0.5f, 0.5f), rays[i].dir = rt_v3(-1, 0, 0); break;
        }
    }
    stream_stats st = {0, 0, 0, 0};
    check_stream(&s, &tree, rays, 512, NULL, &st);
    report(__func__, &st);
    free(rays);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

/* ------------------------------------------------ the shared ray sets */

/* Blocks of 2048 consecutive rays (a stream as a renderer makes them),
 * spread over each primary and diffuse set of every model. */
static void test_shared_sets(void **state)
{
    (void)state;
    test_bench_model models[16];
    size_t nm = test_bench_models(models, 16);
    if (nm == 0) {
        fprintf(stderr, "skip: no models in %s (set RT_SHARED)\n", test_shared_path("bench/MANIFEST.md"));
        skip();
    }
    for (size_t m = 0; m < nm; m++) {
        rt_scene scene;
        rt_scene_init(&scene);
        rt_error err = {0};
        char glb[4096];
        snprintf(glb, sizeof glb, "%s", test_shared_path(models[m].glb));
        if (rt_load(&scene, NULL, glb, NULL, NULL, &err) != RT_OK) {
            fprintf(stderr, "skip: %s: %s\n", glb, err.message);
            skip();
        }
        rt_kdtree tree;
        build_ok(&tree, &scene, 0);
        static const char *kinds[2] = {"primary", "diffuse"};
        for (int k = 0; k < 2; k++) {
            char rel[512], rays[4096];
            snprintf(rel, sizeof rel, "bench/%.127s/%.127s.%s.rays", models[m].name, models[m].name, kinds[k]);
            snprintf(rays, sizeof rays, "%s", test_shared_path(rel));
            rt_rayset rs;
            if (rt_rayset_load(&rs, rays, NULL, &err) != RT_OK) {
                fprintf(stderr, "skip: %s\n", err.message);
                skip();
            }
            stream_stats st = {0, 0, 0, 0};
            size_t block = 2048, blocks = 4;
            for (size_t b = 0; b < blocks && rs.count >= block; b++) {
                size_t start = (rs.count - block) / (blocks - 1) * b;
                check_stream(&scene, &tree, rs.rays + start, block, NULL, &st);
            }
            fprintf(stderr, "%s %s: ", models[m].name, kinds[k]);
            report(__func__, &st);
            assert_true(st.rays > 0);
            rt_rayset_free(&rs);
        }
        rt_kdtree_free(&tree);
        rt_scene_free(&scene);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_widths),
        cmocka_unit_test(test_empty_streams),
        cmocka_unit_test(test_single_rays),
        cmocka_unit_test(test_random_scenes),
        cmocka_unit_test(test_axis_parallel),
        cmocka_unit_test(test_spheres_and_quads),
        cmocka_unit_test(test_degenerate_rays),
        cmocka_unit_test(test_shared_sets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
