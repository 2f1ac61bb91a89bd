/* test_fixture.h - a scene ready to trace, as the integrator tests set it
 * up: the scene tables, their kd-tree, the render state and a trace
 * context over them; and for scenes built in code, the camera and a whole
 * render. Include after test_util.h.
 *
 *   test_fixture f;
 *   test_fixture_load(&f, "integrator path\nsphere 0 0 0 1 m\n...", RT_PREPARE_LIGHT_TABLE);
 *   rt_vec3 L = rt_radiance_path(&f.ctx, &ray, &rng);
 *   rt_vec3 L2 = test_fixture_path_radiance(&f, seed, org, dir, i);  (checked finite, >= 0)
 *   test_fixture_free(&f);
 *
 * Or in two steps, to change the scene between parsing and building:
 *
 *   test_fixture_parse(&f, text);
 *   ... add an environment map to f.s (test_fixture_add_env) ...
 *   test_fixture_build(&f, RT_PREPARE_LIGHT_TABLE);
 *
 * A scene text that does not parse fails the test with the parser's
 * message.
 */
#ifndef RT_TEST_FIXTURE_H
#define RT_TEST_FIXTURE_H

#include <string.h>

#include "rt/accel/kdtree.h"
#include "rt/io/scene_parse.h"
#include "rt/render/pathtrace.h"
#include "rt/render/render.h"
#include "rt/render/render_state.h"
#include "rt/render/surface.h"
#include "rt/scene/scene.h"
#include "rt/scene/texture.h"
#include "rt/scene/validate.h"

typedef struct test_fixture {
    rt_scene s;
    rt_settings settings; /* how to render s: its scene text's settings */
    rt_kdtree tree;
    rt_render_state rs;
    rt_trace_ctx ctx;
} test_fixture;

/* Parses `text` as a scene file into a fresh f->s. */
static inline void test_fixture_parse(test_fixture *f, const char *text)
{
    rt_error err;
    rt_scene_init(&f->s);
    rt_settings_default(&f->settings);
    if (rt_scene_parse_string(&f->s, &f->settings, text, strlen(text), "test", NULL, &err) != RT_OK)
        fail_msg("parse: %s", err.message);
}

/* The kd-tree of f->s, its render state (RT_PREPARE_* bits) and the trace
 * context. */
static inline void test_fixture_build(test_fixture *f, unsigned prepare)
{
    rt_error err;
    assert_int_equal(rt_kdtree_build(&f->tree, &f->s, NULL, &err), RT_OK);
    assert_int_equal(rt_render_state_prepare(&f->rs, &f->s, &f->settings, &f->tree, prepare, &err), RT_OK);
    rt_trace_ctx_init(&f->ctx, &f->rs);
}

static inline void test_fixture_load(test_fixture *f, const char *text, unsigned prepare)
{
    test_fixture_parse(f, text);
    test_fixture_build(f, prepare);
}

/* The path tracer's radiance along the ray from org towards dir
 * (normalised here) with the random stream of pixel i, sample 0, of
 * `seed`; asserted finite and non-negative. */
static inline rt_vec3 test_fixture_path_radiance(const test_fixture *f, uint32_t seed, rt_vec3 org, rt_vec3 dir,
                                                 uint32_t i)
{
    rt_rng rng = rt_rng_for_sample(seed, i, 0);
    rt_ray r = rt_ray_make(org, rt_normalize(dir), 0.0f, INFINITY);
    rt_vec3 L = rt_radiance_path(&f->ctx, &r, &rng);
    assert_true(rt_finite3(L) && L.x >= 0.0f && L.y >= 0.0f && L.z >= 0.0f);
    return L;
}

static inline void test_fixture_free(test_fixture *f)
{
    rt_render_state_free(&f->rs);
    rt_kdtree_free(&f->tree);
    rt_scene_free(&f->s);
}

/* The camera of a scene built in code: from `from` towards `at`, `up` up,
 * a vertical field of view of fov_deg degrees. */
static inline void test_scene_look(rt_scene *s, rt_vec3 from, rt_vec3 at, rt_vec3 up, float fov_deg)
{
    s->camera.position = from;
    s->camera.look_at = at;
    s->camera.up = up;
    s->camera.vfov_deg = fov_deg;
    s->camera_set = true;
}

/* Renders a scene built in code (validated here, with a kd-tree of its
 * own) with settings on `threads` threads in tiles of `tile` pixels (0:
 * the default) into a new *fb; no sample may be bad. */
static inline void test_render_scene(rt_scene *s, const rt_settings *settings, int threads, int tile, rt_framebuffer *fb)
{
    rt_error err = {0};
    assert_int_equal(rt_scene_validate(s, &err), RT_OK);
    rt_kdtree tree;
    assert_int_equal(rt_kdtree_build(&tree, s, NULL, &err), RT_OK);
    assert_int_equal(rt_framebuffer_init(fb, settings->width, settings->height, &err), RT_OK);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = threads;
    opt.tile_size = tile;
    rt_render_stats st;
    assert_int_equal(rt_render(s, settings, &tree, &opt, fb, &st, &err), RT_OK);
    assert_int_equal(st.bad_samples, 0);
    rt_kdtree_free(&tree);
}

/* Adds a w x h float environment image: sky radiance everywhere, `sun`
 * in a 2 x 2 texel patch around texel (si, sj). */
static inline void test_fixture_add_env(rt_scene *s, int w, int h, float sky, float sun, int si, int sj)
{
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = w;
    img.height = h;
    img.rgbaf = malloc((size_t)w * (size_t)h * 4 * sizeof(float));
    assert_non_null(img.rgbaf);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            bool in = (i == si || i == si + 1) && (j == sj || j == sj + 1);
            float *px = img.rgbaf + 4 * ((size_t)j * (size_t)w + (size_t)i);
            px[0] = px[1] = px[2] = in ? sun : sky;
            px[3] = 1.0f;
        }
    snprintf(img.name, sizeof img.name, "test-env");
    uint32_t im = rt_scene_add_image(s, &img);
    assert_true(im != RT_NONE);
    rt_texture tex = rt_texture_image(im);
    tex.wrap_t = RT_WRAP_CLAMP;
    uint32_t t = rt_scene_add_texture(s, &tex);
    assert_true(t != RT_NONE);
    s->environment.environment_texture = t;
    s->environment.environment_strength = 1.0f;
}

#endif
