/* test_texture.c - texture lookups against values worked out by hand:
 * wrap modes at and beyond the edges, nearest texel selection, bilinear
 * weights, sRGB decoding, float images, procedural textures, UV
 * transforms, and the loader: PNG, JPEG and HDR files decode to what was
 * written, the same file is loaded once for every material that uses it,
 * and bad files fail cleanly. */
#include "test_util.h"

#include <math.h>
#include <unistd.h>

#include "rt/io/image_write.h"
#include "rt/image/srgb.h"
#include "rt/io/image_load.h"
#include "rt/scene/scene.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/texture.h"

#include <stb/stb_image_write.h> /* the implementation is in -lstb */

/* A w x h RGBA8 image whose texel (x, y) has R = 10 + 40 x, G = 10 + 60 y,
 * B = 7, A = 200, as a texture with the given sampling. */
static uint32_t grid_texture(rt_scene *s, int w, int h, rt_wrap ws, rt_wrap wt, rt_filter f)
{
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = w;
    img.height = h;
    img.rgba8 = malloc((size_t)w * (size_t)h * 4);
    assert_non_null(img.rgba8);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint8_t *p = img.rgba8 + 4 * (y * w + x);
            p[0] = (uint8_t)(10 + 40 * x);
            p[1] = (uint8_t)(10 + 60 * y);
            p[2] = 7;
            p[3] = 200;
        }
    snprintf(img.name, sizeof img.name, "grid%dx%d", w, h);
    uint32_t i = rt_scene_add_image(s, &img);
    assert_int_not_equal(i, RT_NONE);
    rt_texture t = rt_texture_image(i);
    t.wrap_s = ws;
    t.wrap_t = wt;
    t.filter = f;
    return rt_scene_add_texture(s, &t);
}

/* Which texel (x, y) a nearest lookup returned. */
static void texel_of(rt_vec4 c, int *x, int *y)
{
    *x = (int)lroundf((c.x * 255.0f - 10.0f) / 40.0f);
    *y = (int)lroundf((c.y * 255.0f - 10.0f) / 60.0f);
}

static void test_wrap_modes_nearest(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    /* 4 wide, 2 high: u in texels is 4u, v is 2v */
    uint32_t rep = grid_texture(&s, 4, 2, RT_WRAP_REPEAT, RT_WRAP_REPEAT, RT_FILTER_NEAREST);
    uint32_t cla = grid_texture(&s, 4, 2, RT_WRAP_CLAMP, RT_WRAP_CLAMP, RT_FILTER_NEAREST);
    uint32_t mir = grid_texture(&s, 4, 2, RT_WRAP_MIRROR, RT_WRAP_MIRROR, RT_FILTER_NEAREST);
    uint32_t mixed = grid_texture(&s, 4, 2, RT_WRAP_CLAMP, RT_WRAP_REPEAT, RT_FILTER_NEAREST);
    static const struct { float u; int rep, cla, mir; } cu[] = {
        {0.0f, 0, 0, 0},     {0.1f, 0, 0, 0},    {0.99f, 3, 3, 3},  {1.0f, 0, 3, 3},   /* the right edge */
        {1.1f, 0, 3, 3},     {1.3f, 1, 3, 2},    {1.9f, 3, 3, 0},   {2.1f, 0, 3, 0},   /* beyond it */
        {-0.01f, 3, 0, 0},   {-0.3f, 2, 0, 1},   {-1.1f, 3, 0, 3},  {-2.1f, 3, 0, 0},  /* before the left */
        {5.6f, 2, 3, 1},     {-4.9f, 0, 0, 3},
    };
    for (size_t i = 0; i < sizeof cu / sizeof *cu; i++) {
        int x, y;
        texel_of(rt_texture_sample(&s, rep, rt_v2(cu[i].u, 0.25f), false), &x, &y);
        assert_int_equal(x, cu[i].rep);
        assert_int_equal(y, 0);
        texel_of(rt_texture_sample(&s, cla, rt_v2(cu[i].u, 0.25f), false), &x, &y);
        assert_int_equal(x, cu[i].cla);
        texel_of(rt_texture_sample(&s, mir, rt_v2(cu[i].u, 0.25f), false), &x, &y);
        assert_int_equal(x, cu[i].mir);
    }
    /* v: 2 texels; repeat 1.6 -> row 1, clamp -> row 1, mirror 1.6 -> 3.2 -> row 0 */
    int x, y;
    texel_of(rt_texture_sample(&s, rep, rt_v2(0.1f, 1.6f), false), &x, &y);
    assert_int_equal(y, 1);
    texel_of(rt_texture_sample(&s, cla, rt_v2(0.1f, -7.0f), false), &x, &y);
    assert_int_equal(y, 0);
    texel_of(rt_texture_sample(&s, mir, rt_v2(0.1f, 1.6f), false), &x, &y);
    assert_int_equal(y, 0);
    /* wrap_s and wrap_t are independent */
    texel_of(rt_texture_sample(&s, mixed, rt_v2(1.3f, 1.6f), false), &x, &y);
    assert_int_equal(x, 3);
    assert_int_equal(y, 1);
    /* huge and non-finite coordinates stay inside the image */
    texel_of(rt_texture_sample(&s, rep, rt_v2(1e30f, NAN), false), &x, &y);
    assert_true(x >= 0 && x < 4 && y >= 0 && y < 2);
    /* alpha is read as stored */
    assert_true(fabsf(rt_texture_sample(&s, rep, rt_v2(0.1f, 0.1f), true).w - 200.0f / 255.0f) < 1e-6f);
    rt_scene_free(&s);
}

static void test_bilinear_weights(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    uint32_t cla = grid_texture(&s, 4, 2, RT_WRAP_CLAMP, RT_WRAP_CLAMP, RT_FILTER_BILINEAR);
    uint32_t rep = grid_texture(&s, 4, 2, RT_WRAP_REPEAT, RT_WRAP_REPEAT, RT_FILTER_BILINEAR);
    /* texel centres at u = (i + 0.5) / 4, v = (j + 0.5) / 2: exact texels */
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 4; i++) {
            rt_vec4 c = rt_texture_sample(&s, cla, rt_v2((i + 0.5f) / 4, (j + 0.5f) / 2), false);
            assert_true(fabsf(c.x * 255.0f - (10 + 40 * i)) < 1e-3f);
            assert_true(fabsf(c.y * 255.0f - (10 + 60 * j)) < 1e-3f);
        }
    /* between centres: a fraction fx of the way from texel 1 to 2 in x, fy
     * from row 0 to 1: R = 50 + 40 fx, G = 10 + 60 fy (linear in each) */
    const float fx = 0.3f, fy = 0.8f;
    rt_vec4 c = rt_texture_sample(&s, cla, rt_v2((1.5f + fx) / 4, (0.5f + fy) / 2), false);
    assert_true(fabsf(c.x * 255.0f - (50.0f + 40.0f * fx)) < 1e-3f);
    assert_true(fabsf(c.y * 255.0f - (10.0f + 60.0f * fy)) < 1e-3f);
    /* the four weights at a general point: compare with the formula on raw texels */
    rt_vec2 uv = rt_v2(0.41f, 0.63f);
    float x = uv.x * 4 - 0.5f, y = uv.y * 2 - 0.5f; /* 1.14, 0.76 */
    float ax = x - floorf(x), ay = y - floorf(y);
    float r00 = 10 + 40 * 1, r10 = 10 + 40 * 2; /* R depends on x only */
    float expect_r = (1 - ax) * r00 + ax * r10;
    float expect_g = (1 - ay) * 10 + ay * 70;
    c = rt_texture_sample(&s, cla, uv, false);
    assert_true(fabsf(c.x * 255.0f - expect_r) < 1e-3f && fabsf(c.y * 255.0f - expect_g) < 1e-3f);
    /* at the corner uv (0, 0): clamp gives texel (0, 0); repeat blends it
     * half and half with the far column and row */
    c = rt_texture_sample(&s, cla, rt_v2(0, 0), false);
    assert_true(fabsf(c.x * 255.0f - 10.0f) < 1e-3f && fabsf(c.y * 255.0f - 10.0f) < 1e-3f);
    c = rt_texture_sample(&s, rep, rt_v2(0, 0), false);
    assert_true(fabsf(c.x * 255.0f - 0.5f * (10 + 130)) < 1e-3f);
    assert_true(fabsf(c.y * 255.0f - 0.5f * (10 + 70)) < 1e-3f);
    rt_scene_free(&s);
}

static void test_srgb(void **state)
{
    (void)state;
    /* the transfer function itself (IEC 61966-2-1) */
    assert_true(fabsf(rt_srgb_to_linear(0.5f) - 0.21404114f) < 1e-6f);
    assert_true(fabsf(rt_srgb_to_linear(0.04f) - 0.04f / 12.92f) < 1e-7f);
    assert_true(rt_srgb_to_linear(0.0f) == 0.0f && fabsf(rt_srgb_to_linear(1.0f) - 1.0f) < 1e-6f);
    for (int i = 0; i <= 100; i++) {
        float c = i / 100.0f;
        assert_true(fabsf(rt_linear_to_srgb(rt_srgb_to_linear(c)) - c) < 1e-5f);
    }
    /* a texel of code 128 as colour: ((128/255 + 0.055) / 1.055)^2.4 = 0.2158605 */
    rt_scene s;
    rt_scene_init(&s);
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = img.height = 1;
    img.rgba8 = malloc(4);
    assert_non_null(img.rgba8);
    img.rgba8[0] = 128;
    img.rgba8[1] = 10;
    img.rgba8[2] = 255;
    img.rgba8[3] = 128;
    snprintf(img.name, sizeof img.name, "one");
    rt_texture t = rt_texture_image(rt_scene_add_image(&s, &img));
    uint32_t ti = rt_scene_add_texture(&s, &t);
    rt_vec4 c = rt_texture_sample(&s, ti, rt_v2(0.3f, 0.7f), true);
    assert_true(fabsf(c.x - 0.2158605f) < 1e-6f);
    assert_true(fabsf(c.y - (10.0f / 255.0f) / 12.92f) < 1e-7f); /* the linear toe */
    assert_true(fabsf(c.z - 1.0f) < 1e-6f);
    assert_true(fabsf(c.w - 128.0f / 255.0f) < 1e-6f); /* alpha is never decoded */
    /* as data (normal maps): the code / 255 */
    c = rt_texture_sample(&s, ti, rt_v2(0.3f, 0.7f), false);
    assert_true(fabsf(c.x - 128.0f / 255.0f) < 1e-6f);
    rt_scene_free(&s);
}

static void test_float_and_procedural(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = 2;
    img.height = 1;
    img.rgbaf = malloc(8 * sizeof(float));
    assert_non_null(img.rgbaf);
    const float px[8] = {4.5f, 0.25f, 0, 1, 0.5f, 2, 0, 1};
    memcpy(img.rgbaf, px, sizeof px);
    snprintf(img.name, sizeof img.name, "hdr");
    rt_texture t = rt_texture_image(rt_scene_add_image(&s, &img));
    t.filter = RT_FILTER_NEAREST;
    uint32_t ti = rt_scene_add_texture(&s, &t);
    /* float texels are linear already: the sRGB flag does not touch them */
    rt_vec4 c = rt_texture_sample(&s, ti, rt_v2(0.2f, 0.5f), true);
    assert_true(c.x == 4.5f && c.y == 0.25f);
    c = rt_texture_sample(&s, ti, rt_v2(0.7f, 0.5f), true);
    assert_true(c.x == 0.5f && c.y == 2.0f);

    rt_texture ck = rt_texture_checker(rt_v4(1, 0, 0, 1), rt_v4(0, 0, 1, 1), 2.0f);
    uint32_t ci = rt_scene_add_texture(&s, &ck);
    assert_true(rt_texture_sample(&s, ci, rt_v2(0.1f, 0.1f), true).x == 1.0f);  /* square (0, 0) */
    assert_true(rt_texture_sample(&s, ci, rt_v2(0.6f, 0.1f), true).z == 1.0f);  /* (1, 0) */
    assert_true(rt_texture_sample(&s, ci, rt_v2(0.6f, 0.6f), true).x == 1.0f);  /* (1, 1) */
    assert_true(rt_texture_sample(&s, ci, rt_v2(-0.1f, 0.1f), true).z == 1.0f); /* (-1, 0) */
    rt_texture k = rt_texture_constant(rt_v4(0.2f, 0.4f, 0.6f, 0.8f));
    uint32_t ki = rt_scene_add_texture(&s, &k);
    c = rt_texture_sample(&s, ki, rt_v2(123.0f, -9.0f), true);
    assert_true(c.x == 0.2f && c.y == 0.4f && c.z == 0.6f && c.w == 0.8f); /* constants are linear */
    /* no texture and a bad index: white, not a crash */
    c = rt_texture_sample(&s, RT_NONE, rt_v2(0, 0), true);
    assert_true(c.x == 1.0f && c.w == 1.0f);
    c = rt_texture_sample(&s, 999, rt_v2(0, 0), true);
    assert_true(c.x == 1.0f);
    /* a slot's transform: uv' = (2u + 0.5, 3v - 1) */
    rt_texture_slot slot;
    rt_texture_slot_none(&slot);
    slot.uv_transform[0] = 2;
    slot.uv_transform[2] = 0.5f;
    slot.uv_transform[4] = 3;
    slot.uv_transform[5] = -1;
    rt_vec2 uv = rt_texture_slot_uv(&slot, rt_v2(0.25f, 0.5f));
    assert_true(uv.x == 1.0f && uv.y == 0.5f);
    rt_scene_free(&s);
}

/* Files: written with rt's own writers (PNG is 8-bit sRGB, HDR is RGBE),
 * read back through stb_image, once per path. */
static void test_loader_and_cache(void **state)
{
    (void)state;
    char dir[64];
    assert_true(test_make_dir(dir, sizeof dir, "texture"));
    char png[512], hdr[512], bad[512], scene[512];
    snprintf(png, sizeof png, "%s/tex.png", dir);
    snprintf(hdr, sizeof hdr, "%s/env.hdr", dir);
    snprintf(bad, sizeof bad, "%s/bad.png", dir);
    snprintf(scene, sizeof scene, "%s/scene.txt", dir);
    rt_error err = {0};
    rt_framebuffer fb;
    assert_int_equal(rt_framebuffer_init(&fb, 3, 2, &err), RT_OK);
    const float lin[6][3] = {{0.2158605f, 0, 1}, {1, 1, 1}, {0, 0, 0}, {0.5f, 0.25f, 0.125f}, {0.05f, 0.9f, 0.3f}, {0, 1, 0}};
    for (int i = 0; i < 6; i++)
        for (int k = 0; k < 3; k++)
            fb.rgb[3 * i + k] = lin[i][k];
    assert_int_equal(rt_framebuffer_write(&fb, png, 1.0f, &err), RT_OK);
    for (int i = 0; i < 6; i++)
        fb.rgb[3 * i] *= 37.0f; /* HDR keeps values above 1 */
    assert_int_equal(rt_framebuffer_write(&fb, hdr, 1.0f, &err), RT_OK);
    rt_framebuffer_free(&fb);

    rt_scene s;
    rt_scene_init(&s);
    uint32_t a = RT_NONE, b = RT_NONE, h = RT_NONE;
    assert_int_equal(rt_image_load_file(&s, png, &a, &err), RT_OK);
    assert_int_equal(rt_image_load_file(&s, png, &b, &err), RT_OK);
    assert_int_equal(a, b); /* cached by path */
    assert_int_equal(s.image_count, 1);
    assert_int_equal(s.images[a].width, 3);
    assert_int_equal(s.images[a].height, 2);
    assert_non_null(s.images[a].rgba8);
    rt_texture t = rt_texture_image(a);
    t.filter = RT_FILTER_NEAREST;
    uint32_t ti = rt_scene_add_texture(&s, &t);
    /* row 0 is the top: pixel (0, 0) at uv (1/6, 1/4); sRGB round trip within 8-bit steps */
    for (int i = 0; i < 6; i++) {
        rt_vec2 uv = rt_v2(((i % 3) + 0.5f) / 3.0f, ((i / 3) + 0.5f) / 2.0f);
        rt_vec4 c = rt_texture_sample(&s, ti, uv, true);
        for (int k = 0; k < 3; k++) {
            float got = k == 0 ? c.x : (k == 1 ? c.y : c.z);
            float tol = 0.5f / 255.0f * 2.5f * fmaxf(0.05f, powf(lin[i][k], 1.0f / 1.7f)) + 1e-4f;
            assert_true(fabsf(got - lin[i][k]) < tol);
        }
    }
    /* code 128 was written for 0.2158605 (= sRGB 128 exactly) */
    assert_int_equal(s.images[a].rgba8[0], 128);
    assert_int_equal(rt_image_load_file(&s, hdr, &h, &err), RT_OK);
    assert_int_not_equal(h, a);
    assert_non_null(s.images[h].rgbaf);
    assert_true(fabsf(s.images[h].rgbaf[0] - 37.0f * 0.2158605f) < 0.01f * 37.0f * 0.2158605f);
    assert_true(fabsf(s.images[h].rgbaf[4 * 3] - 37.0f * 0.5f) < 0.01f * 37.0f * 0.5f);
    /* JPEG (written by stb_image_write, quality 95): four flat quadrants
     * come back within a few codes of what was written */
    char jpg[512];
    snprintf(jpg, sizeof jpg, "%s/quad.jpg", dir);
    static const uint8_t quad_rgb[4][3] = {{200, 40, 30}, {30, 180, 60}, {20, 40, 220}, {128, 128, 128}};
    uint8_t pix[32 * 32 * 3];
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++)
            memcpy(pix + 3 * (y * 32 + x), quad_rgb[(y / 16) * 2 + x / 16], 3);
    assert_true(stbi_write_jpg(jpg, 32, 32, 3, pix, 95) != 0);
    uint32_t j = RT_NONE;
    assert_int_equal(rt_image_load_file(&s, jpg, &j, &err), RT_OK);
    assert_non_null(s.images[j].rgba8);
    rt_texture tj = rt_texture_image(j);
    uint32_t tji = rt_scene_add_texture(&s, &tj);
    for (int q = 0; q < 4; q++) {
        rt_vec2 uv = rt_v2((q % 2) * 0.5f + 0.25f, (q / 2) * 0.5f + 0.25f);
        rt_vec4 c = rt_texture_sample(&s, tji, uv, false);
        assert_true(fabsf(c.x * 255.0f - quad_rgb[q][0]) < 6.0f);
        assert_true(fabsf(c.y * 255.0f - quad_rgb[q][1]) < 6.0f);
        assert_true(fabsf(c.z * 255.0f - quad_rgb[q][2]) < 6.0f);
    }
    unlink(jpg);
    /* failures: a missing file and garbage name the file and leave the scene as it was */
    test_write_file(bad, "not an image at all", 19);
    size_t before = s.image_count;
    uint32_t x = RT_NONE;
    assert_int_not_equal(rt_image_load_file(&s, bad, &x, &err), RT_OK);
    assert_non_null(strstr(err.message, "bad.png"));
    assert_int_not_equal(rt_image_load_file(&s, "/nonexistent/dir/none.png", &x, &err), RT_OK);
    assert_non_null(strstr(err.message, "none.png"));
    assert_int_equal(s.image_count, before);
    rt_scene_free(&s);

    /* one file used by several materials and a named texture is decoded once */
    const char *text = "texture wood image tex.png filter nearest\n"
                       "material a texture tex.png\n"
                       "material b texture wood\n"
                       "material c texture tex.png normal_map tex.png\n";
    test_write_file(scene, text, strlen(text));
    rt_scene_init(&s);
    assert_int_equal(rt_scene_parse_file(&s, NULL, scene, &err), RT_OK);
    assert_int_equal(s.image_count, 1);
    assert_true(s.material_count >= 3);
    rt_scene_free(&s);

    test_remove_dir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wrap_modes_nearest),
        cmocka_unit_test(test_bilinear_weights),
        cmocka_unit_test(test_srgb),
        cmocka_unit_test(test_float_and_procedural),
        cmocka_unit_test(test_loader_and_cache),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
