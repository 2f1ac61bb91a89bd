/* test_shade.c - surface records: UV conventions on every primitive,
 * tangent frames (from UVs on the fly, from rt_scene_generate_tangents,
 * mirrored UVs) and normal mapping: a flat map changes nothing, bit for
 * bit; a tilted map tilts the normal by the right angle towards the right
 * world-space direction on a rotated mesh, a sphere and a quad; and the
 * Khronos NormalTangentTest / NormalTangentMirrorTest models (shared
 * assets) show every normal-mapped dome as a dome; the shading and emitter
 * records agree with the full one in every field they promise, and in
 * where secondary rays start. */
#include "test_util.h"

#include <math.h>

#include "rt/io/gltf.h"
#include "rt/image/framebuffer.h"
#include "rt/accel/kdtree.h"
#include "rt/render/render.h"
#include "rt/render/render_state.h"
#include "rt/scene/scene.h"
#include "rt/render/surface.h"
#include "rt/scene/tangents.h"
#include "rt/scene/texture.h"
#include "rt/scene/validate.h"

static bool near3(rt_vec3 a, rt_vec3 b, float eps)
{
    return fabsf(a.x - b.x) < eps && fabsf(a.y - b.y) < eps && fabsf(a.z - b.z) < eps;
}

/* A constant normal-map texture encoding the tangent-space normal n
 * (texel = (n + 1) / 2, read back with 2c - 1). */
static uint32_t normal_constant(rt_scene *s, rt_vec3 n)
{
    rt_texture t = rt_texture_constant(rt_v4(0.5f * (n.x + 1), 0.5f * (n.y + 1), 0.5f * (n.z + 1), 1));
    return rt_scene_add_texture(s, &t);
}

/* An 8-bit w x h image filled with one RGB code. */
static uint32_t image8(rt_scene *s, int w, int h, uint8_t r, uint8_t g, uint8_t b)
{
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = w;
    img.height = h;
    img.rgba8 = malloc((size_t)w * (size_t)h * 4);
    assert_non_null(img.rgba8);
    for (int i = 0; i < w * h; i++) {
        img.rgba8[4 * i] = r;
        img.rgba8[4 * i + 1] = g;
        img.rgba8[4 * i + 2] = b;
        img.rgba8[4 * i + 3] = 255;
    }
    snprintf(img.name, sizeof img.name, "mem%u_%u_%u", r, g, b);
    uint32_t i = rt_scene_add_image(s, &img);
    assert_int_not_equal(i, RT_NONE);
    rt_texture t = rt_texture_image(i);
    return rt_scene_add_texture(s, &t);
}

static uint32_t material_with_normal_map(rt_scene *s, uint32_t tex)
{
    rt_material m;
    rt_material_default(&m, "m");
    m.normal_tex.texture = tex;
    return rt_scene_add_material(s, &m);
}

/* The unit square in the xy plane as two smooth triangles, transformed by
 * `xf`: u grows along +x, v grows along -y (the image top is at +y), the
 * normal is +z. mirror_u flips u (u -> 1 - u): a mirrored UV layout. */
static void add_square_mesh(rt_scene *s, const rt_mat4 *xf, uint32_t material, bool mirror_u)
{
    const rt_vec3 p[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const rt_vec2 uv[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    uint32_t v0 = rt_scene_add_vertices(s, 4);
    assert_int_not_equal(v0, RT_NONE);
    rt_mat4 nm = rt_mat4_identity();
    assert_true(rt_mat4_normal_matrix(xf, &nm));
    for (int i = 0; i < 4; i++) {
        s->vertices.position[v0 + i] = rt_mat4_point(xf, p[i]);
        s->vertices.normal[v0 + i] = rt_normalize(rt_mat4_vector(&nm, rt_v3(0, 0, 1)));
        s->vertices.uv0[v0 + i] = mirror_u ? rt_v2(1.0f - uv[i].x, uv[i].y) : uv[i];
    }
    uint8_t f = RT_TRI_SMOOTH | RT_TRI_UV;
    assert_int_not_equal(rt_scene_add_triangle(s, v0, v0 + 1, v0 + 2, material, f), RT_NONE);
    assert_int_not_equal(rt_scene_add_triangle(s, v0, v0 + 2, v0 + 3, material, f), RT_NONE);
}

/* The surface record of primitive `prim` at barycentrics/params (u, v),
 * seen along -n from outside. */
static rt_surface surface(const rt_scene *s, uint32_t prim, float u, float v, rt_vec3 p_expect, rt_vec3 view_dir)
{
    rt_render_state rs;
    rt_error err;
    rt_settings set;
    rt_settings_default(&set);
    assert_int_equal(rt_render_state_prepare(&rs, s, &set, NULL, 0, &err), RT_OK);
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &rs);
    rt_ray r = rt_ray_make(rt_sub(p_expect, view_dir), view_dir, 0.0f, INFINITY);
    rt_hit h = {1.0f, u, v, prim, 0};
    rt_surface sf;
    rt_surface_at(&ctx, &r, &h, &sf);
    rt_render_state_free(&rs);
    return sf;
}

static rt_mat4 some_rotation(void)
{
    rt_mat4 m = rt_mat4_rotate_axis(0, 37.0f);
    m = rt_mat4_mul(rt_mat4_rotate_axis(1, -71.0f), m);
    m = rt_mat4_mul(rt_mat4_rotate_axis(2, 113.0f), m);
    return rt_mat4_mul(rt_mat4_translate(rt_v3(0.4f, -2.0f, 1.5f)), m);
}

/* For each of: red tilt (towards +u) and green tilt (towards the image top),
 * check angle and direction on the rotated square. */
static void check_square_tilts(bool mirror_u, bool generate)
{
    const float a = 0.6f; /* radians */
    rt_mat4 xf = some_rotation();
    rt_vec3 wx = rt_normalize(rt_mat4_vector(&xf, rt_v3(1, 0, 0)));
    rt_vec3 wy = rt_normalize(rt_mat4_vector(&xf, rt_v3(0, 1, 0)));
    rt_vec3 wz = rt_normalize(rt_mat4_vector(&xf, rt_v3(0, 0, 1)));
    rt_vec3 towards_u = mirror_u ? rt_neg(wx) : wx; /* dP/du in world space */
    for (int green = 0; green < 2; green++) {
        rt_scene s;
        rt_scene_init(&s);
        rt_vec3 tn = green ? rt_v3(0, sinf(a), cosf(a)) : rt_v3(sinf(a), 0, cosf(a));
        uint32_t m = material_with_normal_map(&s, normal_constant(&s, tn));
        add_square_mesh(&s, &xf, m, mirror_u);
        if (generate) {
            rt_error err = {0};
            assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
            assert_true(s.triangles.flags[0] & RT_TRI_TANGENT);
            assert_true(s.triangles.flags[1] & RT_TRI_TANGENT);
            for (int i = 0; i < 4; i++) {
                rt_vec4 t = s.vertices.tangent[i];
                assert_true(near3(rt_v3(t.x, t.y, t.z), towards_u, 1e-5f));
                assert_true(t.w == (mirror_u ? -1.0f : 1.0f));
            }
        }
        /* a point inside the first triangle */
        rt_vec3 pw = rt_mat4_point(&xf, rt_v3(0.6f, 0.3f, 0));
        rt_surface sf = surface(&s, 0, 0.3f, 0.3f, pw, rt_neg(wz));
        rt_vec3 dir = green ? wy : towards_u; /* green: towards decreasing v = +y */
        rt_vec3 expect = rt_add(rt_scale(wz, cosf(a)), rt_scale(dir, sinf(a)));
        assert_true(near3(sf.n, expect, 2e-5f));
        assert_true(fabsf(acosf(rt_clampf(rt_dot(sf.n, sf.ng), -1, 1)) - a) < 1e-4f);
        assert_true(near3(sf.ng, wz, 1e-5f));
        /* the frame stays orthonormal and right-handed up to the sign */
        assert_true(fabsf(rt_dot(sf.t, sf.n)) < 1e-5f && fabsf(rt_dot(sf.b, sf.n)) < 1e-5f);
        rt_scene_free(&s);
    }
}

static void test_normal_map_rotated_mesh(void **state)
{
    (void)state;
    check_square_tilts(false, false);
    check_square_tilts(false, true);
    check_square_tilts(true, false);
    check_square_tilts(true, true);
}

static void test_normal_map_sphere_and_quad(void **state)
{
    (void)state;
    const float a = 0.4f;
    for (int green = 0; green < 2; green++) {
        rt_vec3 tn = green ? rt_v3(0, sinf(a), cosf(a)) : rt_v3(sinf(a), 0, cosf(a));
        /* sphere at the origin, seen at the point facing +z: u grows towards
         * +x, the image top is the north pole (+y) */
        rt_scene s;
        rt_scene_init(&s);
        uint32_t m = material_with_normal_map(&s, normal_constant(&s, tn));
        rt_scene_add_sphere(&s, rt_v3(0, 0, 0), 1.0f, m);
        rt_surface sf = surface(&s, 0, 0, 0, rt_v3(0, 0, 1), rt_v3(0, 0, -1));
        rt_vec3 dir = green ? rt_v3(0, 1, 0) : rt_v3(1, 0, 0);
        assert_true(near3(sf.n, rt_add(rt_scale(rt_v3(0, 0, 1), cosf(a)), rt_scale(dir, sinf(a))), 1e-5f));
        assert_true(fabsf(sf.uv0.x - 0.5f) < 1e-6f && fabsf(sf.uv0.y - 0.5f) < 1e-6f);
        rt_scene_free(&s);
        /* quad: corner p, edges eu (s) and ev (t), uv = (s, 1 - t): red tilts
         * towards eu, green towards ev (the image top is at t = 1) */
        rt_scene_init(&s);
        m = material_with_normal_map(&s, normal_constant(&s, tn));
        rt_vec3 eu = rt_v3(0, 0, -2), ev = rt_v3(0, 3, 0); /* normal cross(eu, ev) = +x */
        rt_scene_add_quad(&s, rt_v3(1, -1, 1), eu, ev, m);
        rt_vec3 p = rt_add(rt_v3(1, -1, 1), rt_add(rt_scale(eu, 0.25f), rt_scale(ev, 0.75f)));
        sf = surface(&s, 0, 0.25f, 0.75f, p, rt_v3(-1, 0, 0));
        assert_true(fabsf(sf.uv0.x - 0.25f) < 1e-6f && fabsf(sf.uv0.y - 0.25f) < 1e-6f);
        dir = green ? rt_v3(0, 1, 0) : rt_v3(0, 0, -1);
        assert_true(near3(sf.n, rt_add(rt_scale(rt_v3(1, 0, 0), cosf(a)), rt_scale(dir, sinf(a))), 1e-5f));
        /* from behind, the whole frame turns with the surface */
        rt_surface back = surface(&s, 0, 0.25f, 0.75f, p, rt_v3(1, 0, 0));
        assert_false(back.front);
        assert_true(near3(back.n, rt_neg(sf.n), 1e-6f));
        rt_scene_free(&s);
    }
}

static bool same3(rt_vec3 a, rt_vec3 b) { return memcmp(&a, &b, sizeof a) == 0; }

/* rt_surface_at_shading and rt_surface_at_emitter against rt_surface_at:
 * the fields each promises, bit for bit, on smooth normal-mapped
 * triangles (a tilted map, so n differs from ng), a sphere and a quad,
 * from the front and from behind. */
static void test_surface_record_variants(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    uint32_t m = material_with_normal_map(&s, normal_constant(&s, rt_normalize(rt_v3(0.3f, -0.2f, 1.0f))));
    rt_mat4 xf = some_rotation();
    add_square_mesh(&s, &xf, m, false);
    rt_scene_add_sphere(&s, rt_v3(5, 0, 0), 1.5f, m);
    rt_scene_add_quad(&s, rt_v3(-5, -1, 1), rt_v3(0, 0, -2), rt_v3(0, 3, 0), m);
    rt_render_state rs;
    rt_error err;
    assert_int_equal(rt_render_state_prepare(&rs, &s, &set, NULL, 0, &err), RT_OK);
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &rs);
    const rt_vec3 dirs[2] = {{0.3f, -0.4f, -0.866f}, {-0.2f, 0.5f, 0.84f}};
    for (uint32_t prim = 0; prim < 4; prim++)
        for (int d = 0; d < 2; d++) {
            rt_ray r = rt_ray_make(rt_v3(0.1f, 0.2f, 3.0f), rt_normalize(dirs[d]), 0.0f, INFINITY);
            rt_hit h = {2.5f, 0.3f, 0.45f, prim, 0};
            rt_surface a, sh, em;
            rt_surface_at(&ctx, &r, &h, &a);
            rt_surface_at_shading(&ctx, &r, &h, &sh);
            rt_surface_at_emitter(&ctx, &r, &h, &em);
            /* the normal map reads the frame: the shading record is the full one */
            assert_true(same3(sh.n, a.n) && same3(sh.t, a.t) && same3(sh.b, a.b));
            assert_true(prim >= 2 || !same3(a.n, a.ng)); /* the map tilts the triangles' normal */
            const rt_surface *v[2] = {&sh, &em};
            for (int k = 0; k < 2; k++) {
                assert_true(same3(v[k]->p, a.p) && same3(v[k]->ng, a.ng) && same3(v[k]->wo, a.wo));
                assert_true(memcmp(&v[k]->uv0, &a.uv0, sizeof a.uv0) == 0);
                assert_true(memcmp(&v[k]->uv1, &a.uv1, sizeof a.uv1) == 0);
                assert_true(v[k]->front == a.front && v[k]->material == a.material && v[k]->prim == a.prim);
            }
            /* the shading record's spawn origin, kept for ng's side, is the one computed on demand */
            assert_true(sh.p_out_set && !a.p_out_set);
            for (int side = -1; side <= 1; side += 2) {
                rt_vec3 dir = rt_normalize(rt_add(rt_scale(a.ng, (float)side), rt_v3(0.2f, 0.1f, -0.3f)));
                rt_vec3 o1 = rt_surface_spawn(&ctx, &sh, dir), o2 = rt_surface_spawn(&ctx, &a, dir);
                assert_true(same3(o1, o2));
            }
            assert_true(same3(em.n, em.ng) && same3(em.n_unmapped, em.ng));
            assert_true(rt_length2(em.t) == 0.0f && rt_length2(em.b) == 0.0f); /* -0 from behind */
            assert_true(em.vertex_color.x == 1.0f && em.vertex_color.w == 1.0f);
        }
    rt_render_state_free(&rs);
    rt_scene_free(&s);

    /* without a texture the shading record leaves the UVs out (zero), and
     * only them */
    rt_scene_init(&s);
    rt_settings_default(&set);
    rt_material plain;
    rt_material_default(&plain, "plain");
    m = rt_scene_add_material(&s, &plain);
    add_square_mesh(&s, &xf, m, false);
    rt_scene_add_sphere(&s, rt_v3(5, 0, 0), 1.5f, m);
    assert_int_equal(rt_render_state_prepare(&rs, &s, &set, NULL, 0, &err), RT_OK);
    rt_trace_ctx_init(&ctx, &rs);
    assert_int_equal(rs.material_needs[m] & RT_MATERIAL_TEXTURED, 0);
    for (uint32_t prim = 0; prim < 3; prim++) {
        rt_ray r = rt_ray_make(rt_v3(0.1f, 0.2f, 3.0f), rt_normalize(dirs[0]), 0.0f, INFINITY);
        rt_hit h = {2.5f, 0.3f, 0.45f, prim, 0};
        rt_surface a, sh;
        rt_surface_at(&ctx, &r, &h, &a);
        rt_surface_at_shading(&ctx, &r, &h, &sh);
        assert_true(a.uv0.x != 0.0f || a.uv0.y != 0.0f);
        assert_true(sh.uv0.x == 0.0f && sh.uv0.y == 0.0f && sh.uv1.x == 0.0f && sh.uv1.y == 0.0f);
        /* every other field as the full record's (no frame: the material does not read it) */
        assert_true(same3(sh.p, a.p) && same3(sh.ng, a.ng) && same3(sh.n, a.n) && same3(sh.n_unmapped, a.n_unmapped));
        assert_true(same3(sh.wo, a.wo) && sh.front == a.front && sh.material == a.material && sh.prim == a.prim);
        assert_true(memcmp(&sh.vertex_color, &a.vertex_color, sizeof a.vertex_color) == 0);
    }
    rt_render_state_free(&rs);
    rt_scene_free(&s);
}

/* UV conventions: sphere longitude/latitude, quad (s, 1 - t), triangles
 * from their vertices. */
static void test_uv_conventions(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    rt_material m;
    rt_material_default(&m, "m");
    uint32_t mi = rt_scene_add_material(&s, &m);
    rt_scene_add_sphere(&s, rt_v3(0, 0, 0), 2.0f, mi);
    rt_surface sf = surface(&s, 0, 0, 0, rt_v3(0, 2, 0), rt_v3(0, -1, 0)); /* north pole */
    assert_true(fabsf(sf.uv0.y) < 1e-6f);
    sf = surface(&s, 0, 0, 0, rt_v3(0, -2, 0), rt_v3(0, 1, 0)); /* south pole */
    assert_true(fabsf(sf.uv0.y - 1.0f) < 1e-6f);
    sf = surface(&s, 0, 0, 0, rt_v3(2, 0, 0), rt_v3(-1, 0, 0)); /* +x: u = 0.5 + 1/4 */
    assert_true(fabsf(sf.uv0.x - 0.75f) < 1e-6f && fabsf(sf.uv0.y - 0.5f) < 1e-6f);
    sf = surface(&s, 0, 0, 0, rt_v3(0, 0, 2), rt_v3(0, 0, -1)); /* +z: u = 0.5 */
    assert_true(fabsf(sf.uv0.x - 0.5f) < 1e-6f);
    rt_scene_free(&s);

    /* an image's top-left texel shows at the quad's corner p + ev */
    rt_scene_init(&s);
    rt_settings_default(&set);
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = img.height = 2;
    img.rgba8 = calloc(16, 1);
    assert_non_null(img.rgba8);
    img.rgba8[0] = 255; /* texel (0, 0): red */
    img.rgba8[3] = img.rgba8[7] = img.rgba8[11] = img.rgba8[15] = 255;
    snprintf(img.name, sizeof img.name, "corner");
    rt_texture t = rt_texture_image(rt_scene_add_image(&s, &img));
    t.filter = RT_FILTER_NEAREST;
    m.base_color_tex.texture = rt_scene_add_texture(&s, &t);
    m.color = rt_v3s(1);
    mi = rt_scene_add_material(&s, &m);
    rt_scene_add_quad(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0), mi);
    rt_render_state rs;
    rt_error err;
    assert_int_equal(rt_render_state_prepare(&rs, &s, &set, NULL, 0, &err), RT_OK);
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &rs);
    sf = surface(&s, 0, 0.1f, 0.9f, rt_v3(0.1f, 0.9f, 0), rt_v3(0, 0, -1));
    assert_true(rt_surface_base_color(&ctx, &sf).x == 1.0f);
    sf = surface(&s, 0, 0.1f, 0.1f, rt_v3(0.1f, 0.1f, 0), rt_v3(0, 0, -1));
    assert_true(rt_surface_base_color(&ctx, &sf).x == 0.0f);
    rt_render_state_free(&rs);
    rt_scene_free(&s);
}

/* Renders the same scene (mesh, sphere, quad; whitted; point light) with
 * the given normal map on every material, RT_NONE for none. */
static void render_all(int map_kind, rt_framebuffer *fb)
{
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    set.integrator = RT_INTEGRATOR_WHITTED;
    set.width = 24;
    set.height = 16;
    set.samples = 2;
    set.max_bounce = 2;
    s.environment.background = rt_v3(0.3f, 0.4f, 0.5f);
    uint32_t tex = RT_NONE;
    if (map_kind == 1)
        tex = normal_constant(&s, rt_v3(0, 0, 1));
    else if (map_kind == 2)
        tex = image8(&s, 3, 3, 128, 128, 255);
    rt_material m;
    rt_material_default(&m, "shiny");
    m.normal_tex.texture = tex;
    m.specular = 0.5f;
    m.reflectivity = 0.3f;
    uint32_t mi = rt_scene_add_material(&s, &m);
    rt_mat4 xf = some_rotation();
    xf = rt_mat4_mul(rt_mat4_translate(rt_v3(-0.4f, 2.0f, -1.5f)), xf);
    add_square_mesh(&s, &xf, mi, false);
    rt_scene_add_sphere(&s, rt_v3(1.2f, 0.3f, 0), 0.6f, mi);
    rt_scene_add_quad(&s, rt_v3(-3, -1, -3), rt_v3(0, 0, 6), rt_v3(6, 0, 0), mi);
    rt_light l;
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_POINT;
    l.color = rt_v3s(1);
    l.intensity = 20;
    l.position = rt_v3(1, 4, 3);
    l.quad = RT_NONE;
    rt_scene_add_light(&s, &l);
    s.camera.position = rt_v3(0, 1, 5);
    s.camera.look_at = rt_v3(0, 0, 0);
    s.camera.up = rt_v3(0, 1, 0);
    s.camera.vfov_deg = 50;
    s.camera_set = true;
    rt_error err = {0};
    assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_kdtree tree;
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    assert_int_equal(rt_framebuffer_init(fb, set.width, set.height, &err), RT_OK);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    rt_render_stats st;
    assert_int_equal(rt_render(&s, &set, &tree, &opt, fb, &st, &err), RT_OK);
    assert_int_equal(st.bad_samples, 0);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_flat_normal_map_is_exact(void **state)
{
    (void)state;
    rt_framebuffer plain, flat_const, flat_png;
    render_all(0, &plain);
    render_all(1, &flat_const);
    render_all(2, &flat_png);
    size_t n = (size_t)plain.width * (size_t)plain.height * 3;
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += plain.rgb[i];
    assert_true(sum > 0.1 * (double)n); /* something was lit */
    assert_memory_equal(plain.rgb, flat_const.rgb, n * sizeof(float));
    assert_memory_equal(plain.rgb, flat_png.rgb, n * sizeof(float));
    rt_framebuffer_free(&plain);
    rt_framebuffer_free(&flat_const);
    rt_framebuffer_free(&flat_png);
}

/* 8-bit normal maps: 255 -> +1, 0 -> -1, 128 -> 0 exactly. */
static void test_normal_map_8bit_extremes(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    uint32_t m = material_with_normal_map(&s, image8(&s, 2, 2, 255, 128, 128));
    rt_scene_add_quad(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0), m);
    /* tangent-space (1, 0, 0): the normal lies along +u (x) */
    rt_surface sf = surface(&s, 0, 0.5f, 0.5f, rt_v3(0.5f, 0.5f, 0), rt_v3(0, 0, -1));
    assert_true(near3(sf.n, rt_v3(1, 0, 0), 1e-6f));
    rt_scene_free(&s);
    rt_scene_init(&s);
    m = material_with_normal_map(&s, image8(&s, 2, 2, 128, 0, 128));
    rt_scene_add_quad(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0), m);
    sf = surface(&s, 0, 0.5f, 0.5f, rt_v3(0.5f, 0.5f, 0), rt_v3(0, 0, -1));
    assert_true(near3(sf.n, rt_v3(0, -1, 0), 1e-6f)); /* green 0: towards the image bottom */
    rt_scene_free(&s);
}

/* Generated tangents: a mirrored seam votes by area; triangles that have
 * tangents keep them; a second call changes nothing; no normal map, no work. */
static void test_generate_tangents(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    rt_material plain;
    rt_material_default(&plain, "plain");
    uint32_t mp = rt_scene_add_material(&s, &plain);
    rt_mat4 id = rt_mat4_identity();
    add_square_mesh(&s, &id, mp, false);
    assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
    for (size_t i = 0; i < s.triangles.count; i++) /* nothing normal-mapped: nothing made */
        assert_false(s.triangles.flags[i] & RT_TRI_TANGENT);
    rt_scene_free(&s);

    /* two squares sharing an edge at x = 1: the left one (area 1) mapped
     * normally, the right one (area 3, 3 wide) mirrored in u */
    rt_scene_init(&s);
    uint32_t m = material_with_normal_map(&s, normal_constant(&s, rt_v3(0, 0, 1)));
    uint32_t v0 = rt_scene_add_vertices(&s, 6);
    const rt_vec3 p[6] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {4, 0, 0}, {4, 1, 0}};
    const rt_vec2 uv[6] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}, {0, 1}, {0, 0}};
    for (int i = 0; i < 6; i++) {
        s.vertices.position[v0 + i] = p[i];
        s.vertices.normal[v0 + i] = rt_v3(0, 0, 1);
        s.vertices.uv0[v0 + i] = uv[i];
    }
    uint8_t f = RT_TRI_SMOOTH | RT_TRI_UV;
    rt_scene_add_triangle(&s, v0, v0 + 1, v0 + 2, m, f);
    rt_scene_add_triangle(&s, v0, v0 + 2, v0 + 3, m, f);
    rt_scene_add_triangle(&s, v0 + 1, v0 + 4, v0 + 5, m, f); /* mirrored: u decreases along +x */
    rt_scene_add_triangle(&s, v0 + 1, v0 + 5, v0 + 2, m, f);
    assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
    rt_vec4 *t = s.vertices.tangent;
    assert_non_null(t);
    /* left-only vertices: +x, w = +1; right-only: -x, w = -1 */
    assert_true(near3(rt_v3(t[v0].x, t[v0].y, t[v0].z), rt_v3(1, 0, 0), 1e-6f) && t[v0].w == 1.0f);
    assert_true(near3(rt_v3(t[v0 + 4].x, t[v0 + 4].y, t[v0 + 4].z), rt_v3(-1, 0, 0), 1e-6f) && t[v0 + 4].w == -1.0f);
    /* seam vertices: the mirrored side has more area and wins, with its own tangent */
    assert_true(t[v0 + 1].w == -1.0f && t[v0 + 2].w == -1.0f);
    assert_true(near3(rt_v3(t[v0 + 1].x, t[v0 + 1].y, t[v0 + 1].z), rt_v3(-1, 0, 0), 1e-6f));
    for (size_t i = 0; i < s.triangles.count; i++)
        assert_true(s.triangles.flags[i] & RT_TRI_TANGENT);
    /* a second call finds nothing to do */
    rt_vec4 before[6];
    memcpy(before, t + v0, sizeof before);
    assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
    assert_memory_equal(before, s.vertices.tangent + v0, sizeof before);
    rt_scene_free(&s);

    /* supplied tangents are kept */
    rt_scene_init(&s);
    m = material_with_normal_map(&s, normal_constant(&s, rt_v3(0, 0, 1)));
    add_square_mesh(&s, &id, m, false);
    assert_true(rt_scene_enable_attr(&s, RT_ATTR_TANGENT));
    for (int i = 0; i < 4; i++)
        s.vertices.tangent[i] = rt_v4(0, 1, 0, -1);
    s.triangles.flags[0] |= RT_TRI_TANGENT;
    assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
    /* vertices 0, 1, 2 belong to the triangle with tangents: kept; vertex 3
     * only to the other one: generated (+x, right-handed) */
    for (int i = 0; i < 3; i++)
        assert_true(s.vertices.tangent[i].y == 1.0f && s.vertices.tangent[i].w == -1.0f);
    assert_true(near3(rt_v3(s.vertices.tangent[3].x, s.vertices.tangent[3].y, s.vertices.tangent[3].z),
                      rt_v3(1, 0, 0), 1e-6f) && s.vertices.tangent[3].w == 1.0f);
    assert_true(s.triangles.flags[1] & RT_TRI_TANGENT);
    rt_scene_free(&s);
}

/* Khronos' NormalTangentTest (no tangents: rt generates them) and
 * NormalTangentMirrorTest (supplied tangents, mirrored U and V layouts):
 * plates facing +z, each with a hemispherical dome, either real geometry or
 * a normal map. Seen along -z on a grid, the shading normal's xy part d is
 * non-zero on each dome; each dome is a connected region of |d| > 0.05, and
 * on a dome d points away from its centre: sum d.x (x - cx) > 0 and
 * sum d.y (y - cy) > 0. A flipped green channel or an ignored handedness
 * turns one of them negative. */
static void check_domes(const char *rel, size_t expect_domes)
{
    const char *path = test_shared_path(rel);
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    rt_error err = {0};
    rt_gltf_stats gs;
    if (rt_gltf_load(&s, path, NULL, &gs, &err) != RT_OK)
        fail_msg("%s: %s", path, err.message);
    assert_int_equal(rt_scene_generate_tangents(&s, &err), RT_OK);
    rt_kdtree tree;
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    rt_render_state rs;
    assert_int_equal(rt_render_state_prepare(&rs, &s, &set, &tree, 0, &err), RT_OK);
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &rs);
    rt_box b = rt_scene_bounds(&s);
    enum { W = 640, H = 512 };
    float *dx = calloc((size_t)W * H, sizeof *dx), *dy = calloc((size_t)W * H, sizeof *dy);
    int *label = calloc((size_t)W * H, sizeof *label), *stack = malloc((size_t)W * H * sizeof *stack);
    assert_true(dx && dy && label && stack);
    float sx = (b.hi.x - b.lo.x) / W, sy = (b.hi.y - b.lo.y) / H;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            rt_vec3 o = rt_v3(b.lo.x + (i + 0.5f) * sx, b.hi.y - (j + 0.5f) * sy, b.hi.z + 1.0f);
            rt_ray r = rt_ray_make(o, rt_v3(0, 0, -1), 0.0f, INFINITY);
            rt_hit h;
            if (!rt_trace(&ctx, &r, &h))
                continue;
            rt_surface sf;
            rt_surface_at(&ctx, &r, &h, &sf);
            if (!sf.front)
                continue;
            dx[j * W + i] = sf.n.x;
            dy[j * W + i] = sf.n.y;
        }
    size_t domes = 0;
    int next = 0;
    for (int start = 0; start < W * H; start++) {
        if (label[start] || dx[start] * dx[start] + dy[start] * dy[start] < 0.05f * 0.05f)
            continue;
        /* flood fill one region (4-connected) */
        int n = 0, top = 0;
        label[start] = ++next;
        stack[top++] = start;
        double cx = 0, cy = 0;
        int *members = malloc((size_t)W * H * sizeof *members);
        assert_non_null(members);
        while (top) {
            int p = stack[--top], x = p % W, y = p / W;
            members[n++] = p;
            cx += x;
            cy += y;
            const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
            for (int k = 0; k < 4; k++) {
                int qx = x + nb[k][0], qy = y + nb[k][1];
                if (qx < 0 || qy < 0 || qx >= W || qy >= H)
                    continue;
                int q = qy * W + qx;
                if (!label[q] && dx[q] * dx[q] + dy[q] * dy[q] >= 0.05f * 0.05f) {
                    label[q] = next;
                    stack[top++] = q;
                }
            }
        }
        if (n >= 300) { /* a dome, not a label's edge or a corner arrow */
            cx /= n;
            cy /= n;
            double ax = 0, ay = 0;
            for (int k = 0; k < n; k++) {
                int x = members[k] % W, y = members[k] / W;
                ax += dx[members[k]] * (x - cx);
                ay += dy[members[k]] * (cy - y); /* image rows grow downwards, world y upwards */
            }
            if (!(ax > 0 && ay > 0))
                fprintf(stderr, "%s: region at pixel (%.0f, %.0f), %d px: x %.1f y %.1f\n", rel, cx, cy, n, ax, ay);
            assert_true(ax > 0 && ay > 0);
            domes++;
        }
        free(members);
    }
    assert_true(domes >= expect_domes);
    free(dx);
    free(dy);
    free(label);
    free(stack);
    rt_render_state_free(&rs);
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

static void test_khronos_normal_tangent_models(void **state)
{
    (void)state;
    test_require_shared();
    /* 3 blocks x 5 rows x (geometry, normal map) */
    check_domes("assets/gltf/NormalTangentTest/glTF-Binary/NormalTangentTest.glb", 30);
    /* 2 blocks x 5 rows x (geometry, normal map, V mirror, U mirror) */
    check_domes("assets/gltf/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb", 40);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normal_map_rotated_mesh),
        cmocka_unit_test(test_normal_map_sphere_and_quad),
        cmocka_unit_test(test_uv_conventions),
        cmocka_unit_test(test_surface_record_variants),
        cmocka_unit_test(test_flat_normal_map_is_exact),
        cmocka_unit_test(test_normal_map_8bit_extremes),
        cmocka_unit_test(test_generate_tangents),
        cmocka_unit_test(test_khronos_normal_tangent_models),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
