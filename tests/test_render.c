/* test_render.c - end-to-end renders checked against analytic values, the
 * thread-count independence of the image, passes giving the same bytes as
 * tiles, time limits and cancelled passes, progress reports, and image
 * output. */
#include "test_util.h"
#include "test_fixture.h"

#include <math.h>
#include <unistd.h>

#include "rt/render/camera.h"
#include "rt/io/image_write.h"
#include "rt/io/image_read.h"
#include "rt/accel/kdtree.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"
#include "rt/scene/validate.h"

static uint32_t add_lambert(rt_scene *s, const char *name, rt_vec3 albedo)
{
    rt_material m;
    rt_material_default(&m, name);
    m.color = albedo;
    return rt_scene_add_material(s, &m);
}

/* A Lambertian plane under a point light: L = albedo / pi * I * cos / r^2,
 * checked at every pixel centre (1 sample per pixel = the centre). */
static void test_lambert_plane_point_light(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    const float albedo = 0.6f, I = 10.0f;
    const rt_vec3 light = rt_v3(0.3f, 2.0f, -0.2f);
    uint32_t m = add_lambert(&s, "plane", rt_v3s(albedo));
    rt_scene_add_quad(&s, rt_v3(-10, 0, -10), rt_v3(0, 0, 20), rt_v3(20, 0, 0), m);
    rt_light l;
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_POINT;
    l.color = rt_v3s(1);
    l.intensity = I;
    l.position = light;
    l.quad = RT_NONE;
    rt_scene_add_light(&s, &l);
    set.width = 40;
    set.height = 30;
    set.samples = 1;
    test_scene_look(&s, rt_v3(0, 3, 1), rt_v3(0, 0, 0), rt_v3(0, 1, 0), 50);
    rt_framebuffer fb;
    test_render_scene(&s, &set, 2, 8, &fb);

    rt_camera_frame cf;
    rt_camera_frame_init(&cf, &s.camera, fb.width, fb.height);
    double max_rel = 0;
    for (int y = 0; y < fb.height; y++)
        for (int x = 0; x < fb.width; x++) {
            rt_ray r = rt_camera_ray(&cf, x + 0.5f, y + 0.5f, rt_v2(0.5f, 0.5f));
            double t = -(double)r.org.y / r.dir.y;
            rt_vec3 p = rt_madd(r.org, r.dir, (float)t);
            rt_vec3 d = rt_sub(light, p);
            double r2 = rt_dot(d, d), cosv = d.y / sqrt(r2);
            double expect = albedo / 3.14159265358979323846 * I * cosv / r2;
            const float *px = fb.rgb + 3 * ((size_t)y * fb.width + x);
            for (int c = 0; c < 3; c++) {
                double rel = fabs(px[c] - expect) / expect;
                if (rel > max_rel)
                    max_rel = rel;
            }
        }
    assert_true(max_rel < 1e-4);
    rt_framebuffer_free(&fb);
    rt_scene_free(&s);
}

/* A small scene with an area light, spheres, quads and triangles. */
static void build_busy_scene(rt_scene *s, rt_settings *set)
{
    rt_scene_init(s);
    rt_settings_default(set);
    uint32_t white = add_lambert(s, "white", rt_v3(0.7f, 0.7f, 0.7f));
    uint32_t red = add_lambert(s, "red", rt_v3(0.7f, 0.1f, 0.1f));
    rt_material em;
    rt_material_default(&em, "lamp");
    em.color = rt_v3s(0);
    em.emission = rt_v3(5, 5, 5);
    em.double_sided = false;
    uint32_t lamp = rt_scene_add_material(s, &em);
    rt_scene_add_quad(s, rt_v3(-2, 0, -2), rt_v3(0, 0, 4), rt_v3(4, 0, 0), white);
    rt_scene_add_sphere(s, rt_v3(0, 0.5f, 0), 0.5f, red);
    rt_scene_add_sphere(s, rt_v3(0.9f, 0.3f, 0.4f), 0.3f, white);
    uint32_t v = rt_scene_add_vertices(s, 3);
    s->vertices.position[v] = rt_v3(-1.5f, 0, -1);
    s->vertices.position[v + 1] = rt_v3(-0.5f, 0, -1.2f);
    s->vertices.position[v + 2] = rt_v3(-1, 1.2f, -1.1f);
    rt_scene_add_triangle(s, v, v + 1, v + 2, red, 0);
    rt_vec3 c = rt_v3(-0.5f, 2.5f, -0.5f), eu = rt_v3(1, 0, 0), ev = rt_v3(0, 0, 1);
    uint32_t q = rt_scene_add_quad(s, c, eu, ev, lamp); /* cross(x, z) = -y: faces down */
    rt_light l;
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_AREA;
    l.color = rt_v3s(1);
    l.intensity = 5;
    l.position = c;
    l.edge_u = eu;
    l.edge_v = ev;
    l.quad = q;
    rt_scene_add_light(s, &l);
    set->width = 37;
    set->height = 23;
    set->samples = 5;
    set->shadow_samples = 4;
    test_scene_look(s, rt_v3(0, 1.5f, 4), rt_v3(0, 0.5f, 0), rt_v3(0, 1, 0), 45);
}

static void test_same_image_any_thread_count(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    rt_framebuffer a, b, c;
    test_render_scene(&s, &set, 1, 32, &a);
    test_render_scene(&s, &set, 2, 32, &b);
    test_render_scene(&s, &set, 7, 5, &c); /* more threads than useful, odd tiles */
    size_t n = (size_t)a.width * a.height * 3 * sizeof(float);
    assert_memory_equal(a.rgb, b.rgb, n);
    assert_memory_equal(a.rgb, c.rgb, n);
    /* and the image is not trivially black */
    double sum = 0;
    for (size_t i = 0; i < (size_t)a.width * a.height * 3; i++)
        sum += a.rgb[i];
    assert_true(sum > 1.0);
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
    rt_framebuffer_free(&c);
    rt_scene_free(&s);
}

/* What a progress callback sees: reports in order, the last one final with
 * every tile done, tiles that cover the image exactly once, and finished
 * tiles whose pixels are already the final ones (what --preview shows). */
typedef struct progress_log {
    int calls, finals, last_done;
    bool final_was_last;
    int *covered;   /* per pixel: how many tiles of the final report cover it */
    float *seen;    /* pixels copied from finished tiles during the reports */
} progress_log;

static void log_progress(const rt_render_progress *p, void *user)
{
    progress_log *log = user;
    log->calls++;
    assert_true(p->tiles_done >= log->last_done && p->tiles_done <= p->tiles_total);
    log->last_done = p->tiles_done;
    log->final_was_last = p->final;
    if (p->final) {
        log->finals++;
        assert_int_equal(p->tiles_done, p->tiles_total);
    }
    for (int i = 0; i < p->tiles_total; i++) {
        rt_tile t = rt_render_progress_tile(p, i);
        assert_true(t.x0 >= 0 && t.x0 < t.x1 && t.x1 <= p->fb->width);
        assert_true(t.y0 >= 0 && t.y0 < t.y1 && t.y1 <= p->fb->height);
        if (p->final)
            assert_true(t.finished);
        if (!t.finished)
            continue;
        for (int y = t.y0; y < t.y1; y++)
            for (int x = t.x0; x < t.x1; x++) {
                size_t k = (size_t)y * (size_t)p->fb->width + (size_t)x;
                if (p->final)
                    log->covered[k]++;
                memcpy(log->seen + 3 * k, p->fb->rgb + 3 * k, 3 * sizeof(float));
            }
    }
}

static void test_progress_reports(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    set.samples = 16;
    rt_error err = {0};
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_kdtree tree;
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    rt_framebuffer fb;
    assert_int_equal(rt_framebuffer_init(&fb, set.width, set.height, &err), RT_OK);
    size_t npx = (size_t)fb.width * (size_t)fb.height;
    progress_log log;
    memset(&log, 0, sizeof log);
    log.covered = calloc(npx, sizeof *log.covered);
    log.seen = calloc(3 * npx, sizeof *log.seen);
    assert_true(log.covered && log.seen);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = 2;
    opt.tile_size = 7; /* edge tiles are cut short */
    opt.pass_samples = -1; /* tiles: passes are checked in test_pass_progress */
    opt.progress = log_progress;
    opt.progress_user = &log;
    rt_render_stats st;
    assert_int_equal(rt_render(&s, &set, &tree, &opt, &fb, &st, &err), RT_OK);
    assert_true(log.calls >= 1);
    assert_int_equal(log.finals, 1);
    assert_true(log.final_was_last);
    for (size_t k = 0; k < npx; k++)
        assert_int_equal(log.covered[k], 1);
    assert_memory_equal(log.seen, fb.rgb, 3 * npx * sizeof(float));
    free(log.covered);
    free(log.seen);
    rt_framebuffer_free(&fb);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

/* Renders with explicit options; returns rt_render's result. */
static rt_result render_with(rt_scene *s, rt_settings *set, const rt_render_options *opt, rt_framebuffer *fb, rt_render_stats *st)
{
    rt_error err = {0};
    assert_int_equal(rt_scene_validate(s, &err), RT_OK);
    rt_kdtree tree;
    assert_int_equal(rt_kdtree_build(&tree, s, NULL, &err), RT_OK);
    assert_int_equal(rt_framebuffer_init(fb, set->width, set->height, &err), RT_OK);
    rt_result r = rt_render(s, set, &tree, opt, fb, st, &err);
    rt_kdtree_free(&tree);
    return r;
}

/* The reference the pass tests compare with: the scene tiled, one thread,
 * 32-pixel tiles (opt is left holding those options). */
static void render_tiled_reference(rt_scene *s, rt_settings *set, rt_render_options *opt, rt_framebuffer *ref, rt_render_stats *st)
{
    memset(opt, 0, sizeof *opt);
    opt->threads = 1;
    opt->tile_size = 32;
    opt->pass_samples = -1;
    assert_int_equal(render_with(s, set, opt, ref, st), RT_OK);
}

/* Renders s with opt, asserts it completed with `samples` per pixel and
 * gave ref's bytes; *st keeps its statistics. */
static void assert_renders_like(rt_scene *s, rt_settings *set, const rt_render_options *opt, const rt_framebuffer *ref, int samples,
                                rt_render_stats *st)
{
    rt_framebuffer fb;
    assert_int_equal(render_with(s, set, opt, &fb, st), RT_OK);
    assert_int_equal(st->samples_done, samples);
    assert_false(st->partial || st->interrupted || st->time_limited);
    assert_memory_equal(ref->rgb, fb.rgb, (size_t)ref->width * ref->height * 3 * sizeof(float));
    rt_framebuffer_free(&fb);
}

/* Passes of any size give the bytes of the tiled render, for 1, 2 and 3
 * threads and several tile sizes, with every integrator of the table
 * (path_scalar, the one-path-at-a-time path tracer, too); the path
 * tracers' default is passes. 13 samples: passes of 1, 2, 4, 5 and 13 split
 * it evenly and unevenly, and 32 is larger than the count. */
static void test_passes_same_bytes_as_tiles(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    set.samples = 13;
    set.clamp = 3.0f; /* the clamp's arithmetic too */
    const rt_integrator integrators[] = {RT_INTEGRATOR_PATH, RT_INTEGRATOR_PATH_SCALAR, RT_INTEGRATOR_DIRECT,
                                         RT_INTEGRATOR_WHITTED};
    const int pass_sizes[] = {1, 2, 4, 5, 13, 32, 0};
    for (size_t k = 0; k < sizeof integrators / sizeof *integrators; k++) {
        set.integrator = integrators[k];
        rt_render_options opt;
        rt_framebuffer ref;
        rt_render_stats st;
        render_tiled_reference(&s, &set, &opt, &ref, &st);
        assert_false(st.passes);
        assert_int_equal(st.samples_done, 13);
        double sum = 0;
        for (size_t i = 0; i < (size_t)ref.width * ref.height * 3; i++)
            sum += ref.rgb[i];
        assert_true(sum > 1.0);
        for (int threads = 1; threads <= 3; threads++)
            for (size_t p = 0; p < sizeof pass_sizes / sizeof *pass_sizes; p++) {
                opt.threads = threads;
                opt.tile_size = threads == 3 ? 5 : 16 * threads;
                opt.pass_samples = pass_sizes[p];
                assert_renders_like(&s, &set, &opt, &ref, 13, &st);
                bool passes = pass_sizes[p] > 0 || integrators[k] == RT_INTEGRATOR_PATH ||
                              integrators[k] == RT_INTEGRATOR_PATH_SCALAR;
                assert_int_equal(st.passes, passes);
                if (passes && pass_sizes[p] > 0)
                    assert_int_equal(st.passes_done, (13 + pass_sizes[p] - 1) / pass_sizes[p]);
            }
        rt_framebuffer_free(&ref);
    }
    rt_scene_free(&s);
}

/* Above 64 samples a pixel's sum folds its blocks of 64 (render.h): passes
 * of sizes that cross block edges anywhere, threads and tiles still give
 * the tiled render's bytes, for the wavefront (path), one path at a time
 * (path_scalar) and the tiled direct integrator. */
static void test_passes_same_bytes_above_a_block(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    set.samples = 130;
    const rt_integrator integrators[] = {RT_INTEGRATOR_PATH, RT_INTEGRATOR_PATH_SCALAR, RT_INTEGRATOR_DIRECT};
    const int pass_sizes[] = {1, 7, 64, 100, 130};
    for (size_t k = 0; k < sizeof integrators / sizeof *integrators; k++) {
        set.integrator = integrators[k];
        rt_render_options opt;
        rt_framebuffer ref;
        rt_render_stats st;
        render_tiled_reference(&s, &set, &opt, &ref, &st);
        for (size_t p = 0; p < sizeof pass_sizes / sizeof *pass_sizes; p++) {
            opt.threads = 1 + (int)(p % 2);
            opt.tile_size = p % 2 ? 5 : 16;
            opt.pass_samples = pass_sizes[p];
            assert_renders_like(&s, &set, &opt, &ref, 130, &st);
            assert_true(st.passes);
        }
        rt_framebuffer_free(&ref);
    }
    rt_scene_free(&s);
}

/* A time limit already over when the render starts: passes stop after the
 * first pass with the whole image at its samples (the pass that crosses the
 * budget is finished), tiles take no tile; both report it and return OK.
 * With every integrator of the table, in passes and in tiles. */
static void test_time_limit(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    set.samples = 64;
    const rt_integrator integrators[] = {RT_INTEGRATOR_PATH, RT_INTEGRATOR_PATH_SCALAR, RT_INTEGRATOR_DIRECT,
                                         RT_INTEGRATOR_WHITTED};
    for (size_t k = 0; k < sizeof integrators / sizeof *integrators; k++) {
        set.integrator = integrators[k];
        rt_render_options opt;
        memset(&opt, 0, sizeof opt);
        opt.threads = 2;
        opt.pass_samples = 3;
        opt.time_limit = 1e-9;
        rt_framebuffer fb;
        rt_render_stats st;
        assert_int_equal(render_with(&s, &set, &opt, &fb, &st), RT_OK);
        assert_true(st.passes && st.time_limited && !st.interrupted && !st.partial);
        assert_int_equal(st.samples_done, 3);
        assert_int_equal(st.passes_done, 1);
        assert_int_equal(st.camera_rays, 3 * (uint64_t)fb.width * (uint64_t)fb.height); /* every pixel, 3 samples */
        rt_framebuffer_free(&fb);

        opt.pass_samples = -1; /* tiles */
        assert_int_equal(render_with(&s, &set, &opt, &fb, &st), RT_OK);
        assert_true(!st.passes && st.time_limited && !st.interrupted && st.partial);
        assert_true(st.tiles_done < st.tiles_total);
        assert_int_equal(st.samples_done, 0);
        rt_framebuffer_free(&fb);
    }
    rt_scene_free(&s);
}

/* Cancelled after the first pass (from the progress report that says it is
 * done): RT_ERR_INTERRUPTED, fb is the whole image at that pass's samples,
 * the same bytes a time-limited render stopping there gives; every tile
 * reads as finished once a pass is done. */
typedef struct cancel_after_pass {
    atomic_int cancel;
    int reports, last_samples;
} cancel_after_pass;

static void cancel_on_pass(const rt_render_progress *p, void *user)
{
    cancel_after_pass *c = user;
    c->reports++;
    assert_true(p->passes);
    assert_int_equal(p->samples_total, 40);
    assert_true(p->samples_done >= c->last_samples);
    c->last_samples = p->samples_done;
    for (int i = 0; i < p->tiles_total; i++)
        assert_int_equal(rt_render_progress_tile(p, i).finished, p->samples_done > 0);
    if (p->samples_done > 0)
        atomic_store(&c->cancel, 1);
}

static void test_pass_progress_and_cancel(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    set.samples = 40;
    set.integrator = RT_INTEGRATOR_PATH;
    cancel_after_pass c;
    memset(&c, 0, sizeof c);
    atomic_init(&c.cancel, 0);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = 3;
    opt.tile_size = 8;
    opt.pass_samples = 6;
    opt.cancel = &c.cancel;
    opt.progress = cancel_on_pass;
    opt.progress_user = &c;
    rt_framebuffer a, b;
    rt_render_stats st;
    assert_int_equal(render_with(&s, &set, &opt, &a, &st), RT_ERR_INTERRUPTED);
    assert_true(st.interrupted && !st.partial && !st.time_limited);
    assert_int_equal(st.samples_done, 6);
    assert_int_equal(c.last_samples, 6);
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    opt.pass_samples = 6;
    opt.time_limit = 1e-9;
    assert_int_equal(render_with(&s, &set, &opt, &b, &st), RT_OK);
    assert_int_equal(st.samples_done, 6);
    assert_memory_equal(a.rgb, b.rgb, (size_t)a.width * a.height * 3 * sizeof(float));
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
    rt_scene_free(&s);
}

/* The area light's visible quad shows its radiance from below and nothing from above. */
static void test_area_light_visible_one_sided(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    build_busy_scene(&s, &set);
    set.width = 1;
    set.height = 1;
    set.samples = 1;
    test_scene_look(&s, rt_v3(0, 1.0f, 0.0f), rt_v3(0, 3, 0.0f), rt_v3(0, 0, 1), 1);
    rt_framebuffer fb;
    test_render_scene(&s, &set, 1, 32, &fb);
    assert_float_equal(fb.rgb[0], 5.0f, 1e-5);
    rt_framebuffer_free(&fb);
    s.camera.position = rt_v3(0, 4.0f, 0.0f);
    s.camera.look_at = rt_v3(0, 0, 0.0f);
    test_render_scene(&s, &set, 1, 32, &fb);
    assert_float_equal(fb.rgb[0], 0.0f, 1e-6); /* back of the emitter, lit from nowhere */
    rt_framebuffer_free(&fb);
    rt_scene_free(&s);
}

static void test_pfm_roundtrip_and_atomic_write(void **state)
{
    (void)state;
    rt_error err = {0};
    rt_framebuffer fb, back;
    assert_int_equal(rt_framebuffer_init(&fb, 5, 3, &err), RT_OK);
    for (int i = 0; i < 45; i++)
        fb.rgb[i] = (float)i * 0.25f - 1.0f;
    char dir[64];
    assert_true(test_make_dir(dir, sizeof dir, "render"));
    char path[256];
    snprintf(path, sizeof path, "%s/a.pfm", dir);
    assert_int_equal(rt_framebuffer_write(&fb, path, 1.0f, &err), RT_OK);
    assert_int_equal(rt_pfm_read(path, &back, &err), RT_OK);
    assert_int_equal(back.width, 5);
    assert_int_equal(back.height, 3);
    assert_memory_equal(fb.rgb, back.rgb, 45 * sizeof(float));
    rt_framebuffer_free(&back);
    /* PNG and HDR write too */
    snprintf(path, sizeof path, "%s/a.png", dir);
    assert_int_equal(rt_framebuffer_write(&fb, path, 1.0f, &err), RT_OK);
    snprintf(path, sizeof path, "%s/a.hdr", dir);
    assert_int_equal(rt_framebuffer_write(&fb, path, 1.0f, &err), RT_OK);
    /* unknown format and unwritable directory are refused up front */
    snprintf(path, sizeof path, "%s/a.jpg", dir);
    assert_int_equal(rt_output_check(path, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "unknown output format"));
    assert_int_equal(rt_output_check("/nonexistent-dir/x.png", &err), RT_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent-dir/x.png"));
    rt_framebuffer_free(&fb);
    test_remove_dir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lambert_plane_point_light),
        cmocka_unit_test(test_same_image_any_thread_count),
        cmocka_unit_test(test_progress_reports),
        cmocka_unit_test(test_passes_same_bytes_as_tiles),
        cmocka_unit_test(test_passes_same_bytes_above_a_block),
        cmocka_unit_test(test_time_limit),
        cmocka_unit_test(test_pass_progress_and_cancel),
        cmocka_unit_test(test_area_light_visible_one_sided),
        cmocka_unit_test(test_pfm_roundtrip_and_atomic_write),
    };
    return cmocka_run_group_tests_name("render", tests, NULL, NULL);
}
