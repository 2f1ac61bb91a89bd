/* test_wavefront.c - the batch traversal and the wavefront path tracer:
 *   - rt_kdtree_intersect_batch / rt_kdtree_occluded_batch against the
 *     single-ray calls, bit for bit, over triangles, spheres and quads, for
 *     random rays traced in a shuffled subset of lanes, and for fans of
 *     rays from one point (which the batch traces as packets);
 *   - the wavefront tracer against the scalar one (rt_radiance_path), sample
 *     by sample, bit for bit, for batch sizes from 1 to 4096 and work split
 *     every way, on a scene of every material kind (alpha blending and
 *     cut-outs, glass, emitters, every light kind, the emitter table; its
 *     shadow rays walk through surfaces) and on the Cornell box (batched
 *     shadow rays);
 *   - the camera stage: camera rays traced by screen tile as frustums and
 *     their first hits' shadow rays as bundles, sample by sample against
 *     rt_radiance_path on a field of triangles, tiles cut by the work's
 *     rectangle and units; a tree of one leaf keeps the batch;
 *   - rt_render with `path` (wavefront) and `path_scalar`: the same bytes for
 *     1 and 3 threads, tiles and passes, any batch and tile size;
 *   - rt_sincosf (rt/base/vec.h) within its stated error of double sin, cos;
 *   - the Cornell box of the shared Mitsuba reference, path and path_scalar
 *     the same bytes (the comparison with the reference is test_path.c's
 *     test_cornell_reference).
 */
#include "test_util.h"
#include "test_fixture.h"
#include "test_scenes.h"

#include <math.h>

#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_batch.h"
#include "rt/image/framebuffer.h"
#include "rt/io/scene_parse.h"
#include "rt/render/camera.h"
#include "rt/render/pathtrace.h"
#include "rt/render/render.h"
#include "rt/render/wavefront.h"
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
    if (rt_scene_parse_string(s, NULL, text, strlen(text), "soup", NULL, &err) != RT_OK)
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

/* Ray i of a batch, as a single ray. */
static rt_ray batch_ray(const rt_ray_batch *rb, int i)
{
    return rt_ray_make(rt_v3(rb->ox[i], rb->oy[i], rb->oz[i]), rt_v3(rb->dx[i], rb->dy[i], rb->dz[i]), rb->tmin[i],
                       rb->tmax[i]);
}

/* Entry i of a batch's closest hits is the single ray's
 * rt_kdtree_intersect: the same primitive (RT_NONE for a miss) and the
 * same bits of t, u and v. Returns whether the ray hit. */
static bool assert_batch_hit_is_single(const rt_kdtree *tree, const rt_ray_batch *rb, const rt_hit_batch *hb, int i)
{
    rt_ray ray = batch_ray(rb, i);
    rt_hit h;
    if (!rt_kdtree_intersect(tree, &ray, &h)) {
        assert_int_equal(hb->prim[i], RT_NONE);
        return false;
    }
    assert_int_equal(hb->prim[i], h.prim);
    assert_memory_equal(&hb->t[i], &h.t, sizeof h.t);
    assert_memory_equal(&hb->u[i], &h.u, sizeof h.u);
    assert_memory_equal(&hb->v[i], &h.v, sizeof h.v);
    return true;
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
    rt_hit_batch hb = {t, u, v, prim, NULL};
    size_t hits = rt_kdtree_intersect_batch(&tree, &rb, lanes, n, &hb);
    size_t blocks = rt_kdtree_occluded_batch(&tree, &rb, lanes, n, blocked);
    size_t want_hits = 0, want_blocks = 0;
    for (int i = 0; i < N; i++) {
        if (i % 2) { /* not in the batch: untouched */
            assert_int_equal(prim[i], 0xdeadbeefu);
            assert_int_equal(blocked[i], 7);
            continue;
        }
        want_hits += assert_batch_hit_is_single(&tree, &rb, &hb, i);
        rt_ray ray = batch_ray(&rb, i);
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

/* Camera-like rays: runs of 1 to 12 rays from one eye point in a narrow
 * fan (the wavefront's camera rays, which the batch traces as 8-ray
 * packets), some fans straddling an axis (mixed direction signs), through
 * the soup: every answer bit for bit a single ray's. */
static void test_batch_packets_match_single_rays(void **state)
{
    (void)state;
    rt_scene s;
    soup_scene(&s);
    rt_kdtree tree;
    rt_error err;
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    enum { N = 4096 };
    static float ox[N], oy[N], oz[N], dx[N], dy[N], dz[N], tmin[N], tmax[N], t[N], u[N], v[N];
    static uint32_t prim[N];
    test_rng r = {777};
    int i = 0, runs = 0;
    while (i < N) {
        int len = 1 + (int)(test_rng_next(&r) % 12);
        rt_vec3 eye = rt_v3(rnd(&r, -1.0f, 2.0f), rnd(&r, -1.0f, 2.0f), -1.5f);
        rt_vec3 at = rt_v3(rnd(&r, 0.2f, 0.8f), rnd(&r, 0.2f, 0.8f), 0.5f);
        float spread = runs % 5 == 0 ? 0.3f : 0.01f; /* wide fans cross axes */
        for (int k = 0; k < len && i < N; k++, i++) {
            rt_vec3 d = rt_sub(rt_add(at, rt_v3(rnd(&r, -spread, spread), rnd(&r, -spread, spread), 0.0f)), eye);
            ox[i] = eye.x, oy[i] = eye.y, oz[i] = eye.z;
            dx[i] = d.x, dy[i] = d.y, dz[i] = d.z;
            tmin[i] = 0.0f;
            tmax[i] = k == 3 ? 1.0f : INFINITY;
        }
        runs++;
    }
    rt_ray_batch rb = {ox, oy, oz, dx, dy, dz, tmin, tmax};
    rt_hit_batch hb = {t, u, v, prim, NULL};
    size_t hits = rt_kdtree_intersect_batch(&tree, &rb, NULL, N, &hb);
    size_t want = 0;
    for (int k = 0; k < N; k++)
        want += assert_batch_hit_is_single(&tree, &rb, &hb, k);
    assert_int_equal(hits, want);
    fprintf(stderr, "%d fans, %zu of %d rays hit\n", runs, hits, N);
    assert_true(hits > N / 10 && hits < N);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

/* ------------------------------------------------------------ wavefront */

static const char *every_material =
    "integrator path\nresolution 24 16\nsamples 6\nbackground 0.2 0.3 0.4\n" TEST_EVERY_MATERIAL_SCENE;

typedef test_fixture fixture; /* test_fixture.h */

static void load_text(fixture *f, const char *text) { test_fixture_load(f, text, RT_PREPARE_LIGHT_TABLE); }

static void load_cornell(fixture *f, int res)
{
    FILE *fp = fopen("scenes/cornell-reference.txt", "rb");
    assert_non_null(fp);
    static char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = 0;
    load_text(f, text);
    f->settings.width = f->settings.height = res;
}

static void unload(fixture *f) { test_fixture_free(f); }

/* Every sample of the rectangle of columns [x0, x1), rows [y0, y1) of the
 * image through the wavefront with the given batch size and pixels per
 * work unit, against rt_radiance_path; what the wavefront traced as tiles
 * and bundles. */
static rt_wavefront_stats check_rect(fixture *f, size_t batch, uint32_t per_unit, int x0, int x1, int y0, int y1,
                                     uint32_t spp)
{
    int W = f->settings.width, H = f->settings.height, RW = x1 - x0;
    rt_camera_frame cf;
    rt_camera_frame_init(&cf, &f->s.camera, W, H);
    rt_wavefront *wf = rt_wavefront_new(batch, &f->rs);
    assert_non_null(wf);
    uint32_t npx = (uint32_t)(RW * (y1 - y0));
    float *out = malloc(3 * sizeof(float) * npx * spp);
    assert_non_null(out);
    uint64_t rays_wave = 0, rays_scalar = 0;
    rt_trace_ctx ctx = f->ctx;
    ctx.ray_count = &rays_wave;
    for (uint32_t p = 0; p < npx; p += per_unit) {
        /* samples split in two halves of the range, the second first */
        uint32_t half = spp / 2;
        uint32_t count = npx - p < per_unit ? npx - p : per_unit;
        rt_wavefront_work hi = {&cf, W, f->settings.seed, spp, x0, x1, y0, p, count, half, spp};
        rt_wavefront_work lo = {&cf, W, f->settings.seed, spp, x0, x1, y0, p, count, 0, half};
        static float tmp[3 * 4096];
        assert_true(count * spp <= 4096);
        rt_wavefront_radiance(wf, &ctx, &hi, tmp);
        for (uint32_t i = 0; i < count; i++)
            memcpy(out + 3 * ((size_t)(p + i) * spp + half), tmp + 3 * (size_t)i * (spp - half),
                   3 * sizeof(float) * (spp - half));
        if (half > 0) {
            rt_wavefront_radiance(wf, &ctx, &lo, tmp);
            for (uint32_t i = 0; i < count; i++)
                memcpy(out + 3 * ((size_t)(p + i) * spp), tmp + 3 * (size_t)i * half, 3 * sizeof(float) * half);
        }
    }
    rt_trace_ctx sctx = f->ctx;
    sctx.ray_count = &rays_scalar;
    double sum = 0.0;
    for (uint32_t p = 0; p < npx; p++) {
        int x = x0 + (int)(p % (uint32_t)RW), y = y0 + (int)(p / (uint32_t)RW);
        for (uint32_t s = 0; s < spp; s++) {
            rt_rng rng;
            rt_ray r = rt_camera_pixel_sample(&cf, W, f->settings.seed, spp, x, y, s, &rng);
            rt_vec3 L = rt_radiance_path(&sctx, &r, &rng);
            const float *o = out + 3 * ((size_t)p * spp + s);
            if (memcmp(o, &L.x, sizeof(float)) || memcmp(o + 1, &L.y, sizeof(float)) ||
                memcmp(o + 2, &L.z, sizeof(float)))
                fail_msg("batch %zu, pixel (%d, %d) sample %u: wavefront (%.9g %.9g %.9g), scalar (%.9g %.9g %.9g)",
                         batch, x, y, s, o[0], o[1], o[2], L.x, L.y, L.z);
            sum += L.x + L.y + L.z;
        }
    }
    assert_true(sum > 0.0);
    assert_true(rays_wave == rays_scalar); /* the same rays, counted the same */
    free(out);
    rt_wavefront_stats st = rt_wavefront_stats_of(wf);
    rt_wavefront_free(wf);
    return st;
}

/* Every sample of rows [y0, y1) of the image, as check_rect. */
static void check_against_scalar(fixture *f, size_t batch, uint32_t per_unit, int y0, int y1, uint32_t spp)
{
    check_rect(f, batch, per_unit, 0, f->settings.width, y0, y1, spp);
}

static void test_wavefront_equals_scalar(void **state)
{
    (void)state;
    fixture f;
    load_text(&f, every_material);
    assert_true(f.rs.shadows_need_shading);
    const size_t batches[] = {1, 7, 256, 4096};
    for (int smp = RT_SAMPLER_INDEPENDENT; smp <= RT_SAMPLER_SOBOL; smp++) { /* each sampler (rt/render/sampler.h) */
        f.settings.sampler = smp;
        for (size_t b = 0; b < 4; b++)
            if (smp == RT_SAMPLER_INDEPENDENT || b % 2 == 1)
                check_against_scalar(&f, batches[b], b == 1 ? 5 : 48, 0, 16, 6);
    }
    unload(&f);
    /* 300 lights: the batch shrinks to keep its light samples bounded */
    static char many[300 * 64 + 512];
    int n = snprintf(many, sizeof many, "integrator path\nresolution 16 8\nsamples 2\n"
                                        "camera position 0 1 5 look_at 0 0 0 fov 50\n"
                                        "material m color 0.7 0.7 0.7\nquad -5 0 5  10 0 0  0 0 -10  m\n"
                                        "sphere 0 0.5 0 0.5 m\n");
    for (int l = 0; l < 300; l++)
        n += snprintf(many + n, sizeof many - (size_t)n, "light point %d 2 %d  1 1 1  0.1\n", l % 20 - 10,
                      l / 20 - 7);
    load_text(&f, many);
    assert_int_equal(f.s.light_count, 300);
    check_against_scalar(&f, 4096, 128, 0, 8, 2);
    unload(&f);
    load_cornell(&f, 32);
    assert_false(f.rs.shadows_need_shading);
    check_against_scalar(&f, 64, 13, 8, 24, 8);
    check_against_scalar(&f, 1024, 512, 0, 32, 4);
    unload(&f);
    /* an environment image sampled beside a directional and an area
     * light, over Lambert, rough metal, the rough glTF BRDF and smooth and
     * rough plastic (their light samples taken in lanes) */
    test_fixture_parse(&f, "integrator path\nresolution 24 16\nsamples 4\n"
                           "camera position 0 1.5 5 look_at 0 0.5 0 fov 50\n"
                           "material m color 0.7 0.7 0.7\nmaterial g color 0.8 0.5 0.3 metallic 0.3 roughness 0.5\n"
                           "material cu bsdf conductor metal Cu ggx_alpha_uv 0.3 0.2\n"
                           "material sp bsdf plastic color 0.7 0.1 0.05 ior 1.5\n"
                           "material rp bsdf plastic color 0.1 0.2 0.6 ior 1.5 ggx_alpha 0.2\n"
                           "quad -5 0 5  10 0 0  0 0 -10  m\nsphere -1 0.5 0 0.5 g\nsphere 1 0.5 0 0.5 cu\n"
                           "sphere -0.6 0.4 1.2 0.4 sp\nsphere 0.6 0.4 1.2 0.4 rp\n"
                           "light directional -1 -1 -0.5  1 1 1  1\nlight area -1 3 -1  2 0 0  0 0 2  2 2 2  1\n");
    test_fixture_add_env(&f.s, 32, 16, 0.5f, 20.0f, 20, 3);
    test_fixture_build(&f, RT_PREPARE_LIGHT_TABLE);
    assert_true(rt_path_samples_env(&f.ctx));
    assert_false(f.rs.shadows_need_shading);
    check_against_scalar(&f, 256, 48, 0, 16, 4);
    unload(&f);
}

/* A bumpy field of 1152 triangles under a point, a spot, an area and a
 * directional light: a tree with inner nodes, so the wavefront traces its
 * camera rays as tiles and its first hits' shadow rays as bundles. */
static void load_field(fixture *f, bool instanced)
{
    static char text[1152 * 96 + 1024];
    int n = snprintf(text, sizeof text,
                     "integrator path\nresolution 37 29\nsamples 4\nbackground 0.1 0.1 0.2\n"
                     "camera position 0 6 9 look_at 0 0 0 fov 50\n"
                     "material m color 0.7 0.6 0.5\n"
                     "light point 2 4 1  1 0.9 0.8  30\n"
                     "light spot -3 5 2  0.5 -1 -0.3  1 1 1  60  15 25\n"
                     "light area -0.5 3 -0.5  1 0 0  0 0 1  1 0.9 0.8  10\n"
                     "light directional -0.5 -1 -0.3  0.6 0.7 1  0.5\n"
                     "sphere 1 1 0 0.8 m\n%s", instanced ? "object terrain\n" : "");
    const int G = 24;
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            float x0 = -6.0f + 12.0f * (float)i / G, x1 = -6.0f + 12.0f * (float)(i + 1) / G;
            float z0 = -6.0f + 12.0f * (float)j / G, z1 = -6.0f + 12.0f * (float)(j + 1) / G;
            float h00 = 0.3f * sinf(x0) * cosf(z0), h10 = 0.3f * sinf(x1) * cosf(z0);
            float h01 = 0.3f * sinf(x0) * cosf(z1), h11 = 0.3f * sinf(x1) * cosf(z1);
            n += snprintf(text + n, sizeof text - (size_t)n,
                          "triangle %g %g %g  %g %g %g  %g %g %g m\ntriangle %g %g %g  %g %g %g  %g %g %g m\n", x0,
                          h00, z0, x1, h10, z0, x1, h11, z1, x0, h00, z0, x1, h11, z1, x0, h01, z1);
        }
    if (instanced) /* the terrain twice: a top level over two instances of one object */
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "end\ninstance terrain\ninstance terrain translate 0.5 -0.4 -3 rotate 0 20 0 scale 0.9\n");
    assert_true(n < (int)sizeof text);
    load_text(f, text);
}

/* The tile checks on the field, flat or as two instances of one object. */
static void check_tiles_on_field(bool instanced)
{
    fixture f;
    load_field(&f, instanced);
    assert_false(f.rs.shadows_need_shading);
    assert_int_equal(f.tree.instance_count, instanced ? 2 : 0);
    struct { size_t batch; uint32_t per_unit; int x0, x1, y0, y1; uint32_t spp; } runs[] = {
        {1024, 200, 0, 37, 0, 29, 16}, /* whole rows; tiles of 2x2 pixels, the last column 1 wide */
        {1024, 77, 5, 30, 3, 26, 8},   /* a rectangle inside, units starting mid-row; 4x2 pixels */
        {100, 45, 9, 28, 1, 20, 1},    /* one sample: 8x8 pixels of one sample index */
        {4096, 500, 0, 37, 2, 29, 3},  /* 4x4 pixels of 3 samples */
    };
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        rt_wavefront_stats st = check_rect(&f, runs[k].batch, runs[k].per_unit, runs[k].x0, runs[k].x1, runs[k].y0,
                                           runs[k].y1, runs[k].spp);
        uint64_t camera = (uint64_t)(runs[k].x1 - runs[k].x0) * (uint64_t)(runs[k].y1 - runs[k].y0) * runs[k].spp;
        if (f.tree.isa != RT_KD_ISA_AVX2) { /* (the frustum would trace them as packets) */
            assert_true(st.tiles == 0 && st.bundles == 0);
            continue;
        }
        assert_true(st.tile_rays * 2 > camera && st.tile_rays <= camera);
        assert_true(st.bundle_rays > camera); /* most first hits see several lights */
    }
    unload(&f);
}

/* The camera stage traces the camera rays a refill starts by screen tile
 * (rt_kdtree_intersect_frustum), and the shadow rays of their first hits
 * light by light as bundles (rt_kdtree_occluded_frustum): on rectangles
 * whose sides are no multiple of a tile, work units that start mid-row and
 * mid-tile and sample ranges split in two, every sample is still
 * rt_radiance_path's (single rays), and most camera rays went as tiles. A
 * tree of one leaf keeps the batch. */
static void test_camera_tiles_equal_single_rays(void **state)
{
    (void)state;
    check_tiles_on_field(false);
    check_tiles_on_field(true); /* frustums enter instances */
    fixture f;
    load_text(&f, "integrator path\nresolution 16 16\nsamples 4\ncamera position 0 1 5 look_at 0 0 0 fov 50\n"
                  "material m color 0.7 0.7 0.7\nquad -5 0 5  10 0 0  0 0 -10  m\nsphere 0 0.5 0 0.5 m\n"
                  "light point 1 3 1  1 1 1  20\n");
    assert_int_equal(f.tree.wide_count, 0); /* one leaf */
    rt_wavefront_stats st = check_rect(&f, 256, 64, 0, 16, 0, 16, 4);
    assert_true(st.tiles == 0 && st.bundles == 0);
    unload(&f);
}

static void render_with(fixture *f, rt_integrator in, int threads, int tile, int passes, int batch, rt_framebuffer *fb)
{
    rt_error err;
    f->settings.integrator = in;
    assert_int_equal(rt_framebuffer_init(fb, f->settings.width, f->settings.height, &err), RT_OK);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = threads;
    opt.tile_size = tile;
    opt.pass_samples = passes;
    opt.batch_size = batch;
    rt_render_stats st;
    assert_int_equal(rt_render(&f->s, &f->settings, &f->tree, &opt, fb, &st, &err), RT_OK);
    assert_int_equal(st.bad_samples, 0);
}

static void test_render_bytes_any_split(void **state)
{
    (void)state;
    fixture f;
    load_text(&f, every_material);
    for (int smp = RT_SAMPLER_INDEPENDENT; smp <= RT_SAMPLER_SOBOL; smp++) { /* each sampler */
        f.settings.sampler = smp;
        rt_framebuffer ref;
        render_with(&f, RT_INTEGRATOR_PATH_SCALAR, 1, 8, -1, 0, &ref);
        size_t n = (size_t)ref.width * (size_t)ref.height * 3 * sizeof(float);
        struct { int threads, tile, passes, batch; } runs[] = {
            {1, 8, -1, 0}, {3, 8, -1, 0}, {3, 5, 2, 3}, {2, 64, 1, 4096}, {1, 16, 4, 100}, {3, 7, -1, 1},
        };
        for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
            rt_framebuffer fb;
            render_with(&f, RT_INTEGRATOR_PATH, runs[k].threads, runs[k].tile, runs[k].passes, runs[k].batch, &fb);
            if (memcmp(fb.rgb, ref.rgb, n) != 0)
                fail_msg("sampler %d, run %zu (threads %d, tile %d, passes %d, batch %d) differs from path_scalar",
                         smp, k, runs[k].threads, runs[k].tile, runs[k].passes, runs[k].batch);
            rt_framebuffer_free(&fb);
        }
        rt_framebuffer_free(&ref);
    }
    unload(&f);
}

/* scenes/cornell-reference.txt at 64x64 and 32 spp: `path` (the
 * wavefront) and `path_scalar` give the same bytes. How close both come to
 * the Mitsuba reference is test_path.c's test_cornell_reference, the one
 * Cornell-reference test. */
static void test_cornell_wavefront_equals_scalar(void **state)
{
    (void)state;
    fixture f;
    load_cornell(&f, 64);
    f.settings.samples = 32;
    rt_framebuffer img, scalar;
    render_with(&f, RT_INTEGRATOR_PATH, 2, 32, 0, 0, &img);
    render_with(&f, RT_INTEGRATOR_PATH_SCALAR, 2, 32, 0, 0, &scalar);
    assert_memory_equal(img.rgb, scalar.rgb, 64 * 64 * 3 * sizeof(float));
    rt_framebuffer_free(&scalar);
    rt_framebuffer_free(&img);
    unload(&f);
}

/* rt_sincosf: max absolute error 1e-7 against double precision over
 * |x| <= 8 pi (dense grid plus the quadrant boundaries), sin^2 + cos^2 = 1
 * to 5e-7. */
static void test_sincos_error(void **state)
{
    (void)state;
    double worst = 0.0, worst_norm = 0.0;
    const double lim = 8.0 * 3.14159265358979;
    for (int i = -2000000; i <= 2000000; i++) {
        float x = (float)(lim * i / 2000000.0);
        float s, c;
        rt_sincosf(x, &s, &c);
        double es = fabs((double)s - sin((double)x)), ec = fabs((double)c - cos((double)x));
        worst = es > worst ? es : worst;
        worst = ec > worst ? ec : worst;
        double nrm = fabs((double)s * s + (double)c * c - 1.0);
        worst_norm = nrm > worst_norm ? nrm : worst_norm;
    }
    for (int k = -16; k <= 16; k++) { /* around each multiple of pi/4 */
        float x0 = (float)(k * 3.14159265358979 / 4.0);
        float x = nextafterf(x0, -INFINITY);
        for (int j = 0; j < 3; j++, x = nextafterf(x, INFINITY)) {
            float s, c;
            rt_sincosf(x, &s, &c);
            double es = fabs((double)s - sin((double)x)), ec = fabs((double)c - cos((double)x));
            worst = es > worst ? es : worst;
            worst = ec > worst ? ec : worst;
        }
    }
    fprintf(stderr, "rt_sincosf: max abs error %.3g, |sin^2 + cos^2 - 1| <= %.3g\n", worst, worst_norm);
    assert_true(worst <= 1e-7);
    assert_true(worst_norm <= 5e-7);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_batch_traversal_matches_single_rays),
        cmocka_unit_test(test_batch_packets_match_single_rays),
        cmocka_unit_test(test_wavefront_equals_scalar),
        cmocka_unit_test(test_camera_tiles_equal_single_rays),
        cmocka_unit_test(test_render_bytes_any_split),
        cmocka_unit_test(test_cornell_wavefront_equals_scalar),
        cmocka_unit_test(test_sincos_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
