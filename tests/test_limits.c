/* test_limits.c - the library's resource caps and hostile-input answers,
 * called directly: checked allocation overflows, framebuffer, tile and PNG
 * output caps, image headers that would allocate gigabytes, a PNG whose
 * zlib stream never ends, the memory budget (RLIMIT_DATA, in a child
 * process), the kd-tree's primitive cap, NaN/Inf and degenerate input in
 * every loader, and renders that must be the same image for any thread
 * count and tile size (1x1 images, more threads than tiles, cancelled
 * renders). The command-line view of the same limits is test_cli.c.
 */
#include "test_util.h"

#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stb/stb_image_write.h>

#include "rt/base/alloc.h"
#include "rt/base/log.h"
#include "rt/io/gltf.h"
#include "rt/io/image_write.h"
#include "rt/accel/kdtree.h"
#include "rt/io/image_load.h"
#include "rt/io/mesh_io.h"
#include "rt/render/limits.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/texture.h"

static void expect_message(const rt_error *err, const char *a, const char *b)
{
    if ((a && !strstr(err->message, a)) || (b && !strstr(err->message, b)))
        fail_msg("message \"%s\" lacks \"%s\" / \"%s\"", err->message, a ? a : "", b ? b : "");
}

/* ------------------------------------------------------------ allocation */

static void test_checked_allocation(void **state)
{
    (void)state;
    assert_null(rt_alloc(SIZE_MAX / 2 + 1, 2));
    assert_null(rt_alloc(SIZE_MAX, SIZE_MAX));
    assert_null(rt_realloc_array(NULL, SIZE_MAX / 4 + 1, 8));
    int *p = NULL;
    size_t cap = 0;
    assert_true(rt_grow((void **)&p, &cap, 10, sizeof *p));
    assert_true(cap >= 10);
    int *before = p;
    size_t cap_before = cap;
    assert_false(rt_grow((void **)&p, &cap, SIZE_MAX / 2, sizeof *p));
    assert_ptr_equal(p, before); /* the old block survives a failed growth */
    assert_int_equal(cap, cap_before);
    free(p);
    void *z = rt_alloc(0, 8); /* zero-size requests still give a pointer to free */
    assert_non_null(z);
    free(z);
}

/* ------------------------------------------------------- image and output */

static void test_framebuffer_and_output_caps(void **state)
{
    (void)state;
    rt_framebuffer fb;
    rt_error err = {0};
    const int bad[][2] = {{0, 5}, {5, 0}, {-3, 4}, {70000, 1}, {1, 70000}, {INT32_MIN, INT32_MIN}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        assert_int_equal(rt_framebuffer_init(&fb, bad[i][0], bad[i][1], &err), RT_ERR_LIMIT);
        assert_null(fb.rgb);
        expect_message(&err, "out of range", NULL);
    }
    assert_int_equal(rt_framebuffer_init(&fb, 1, 1, &err), RT_OK);
    rt_framebuffer_free(&fb);

    assert_int_equal(rt_output_check_size("x.png", 32768, 32768, &err), RT_ERR_LIMIT);
    expect_message(&err, "x.png: a 32768x32768 PNG", "1 GiB");
    assert_int_equal(rt_output_check_size("x.png", 16384, 16384, &err), RT_OK);
    assert_int_equal(rt_output_check_size("x.pfm", 32768, 32768, &err), RT_OK);
    assert_int_equal(rt_output_check_size("x.hdr", 32768, 32768, &err), RT_OK);
    assert_int_equal(rt_output_check_size("x.jpg", 8, 8, &err), RT_ERR_INVALID);
    assert_int_equal(rt_output_check("/no-such-dir-for-rt/x.png", &err), RT_ERR_IO);
    expect_message(&err, "/no-such-dir-for-rt/x.png: cannot write there", NULL);
}

/* --------------------------------------------------------- image headers */

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24), p[1] = (unsigned char)(v >> 16), p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* A PNG with the given header and `idat` raw bytes as its only IDAT data
 * (CRCs are zero: stb does not check them). Returns the length. */
static size_t make_png(unsigned char *out, uint32_t w, uint32_t h, int color, const unsigned char *idat, size_t n)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    size_t k = 0;
    memcpy(out, sig, 8), k = 8;
    put_be32(out + k, 13), memcpy(out + k + 4, "IHDR", 4), k += 8;
    put_be32(out + k, w), put_be32(out + k + 4, h);
    out[k + 8] = 8, out[k + 9] = (unsigned char)color, out[k + 10] = 0, out[k + 11] = 0, out[k + 12] = 0;
    k += 13, memset(out + k, 0, 4), k += 4;
    put_be32(out + k, (uint32_t)n), memcpy(out + k + 4, "IDAT", 4), k += 8;
    memcpy(out + k, idat, n), k += n, memset(out + k, 0, 4), k += 4;
    put_be32(out + k, 0), memcpy(out + k + 4, "IEND", 4), k += 8, memset(out + k, 0, 4), k += 4;
    return k;
}

static void collect(void *ctx, void *data, int size)
{
    unsigned char **p = ctx;
    memcpy(*p, data, (size_t)size);
    *p += size;
}

static void test_image_header_limits(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    uint32_t img;
    static unsigned char buf[1 << 16];
    const unsigned char tiny_idat[] = {0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01};

    /* 60000x60000 RGBA would be 14 GB: refused from the header alone */
    size_t n = make_png(buf, 60000, 60000, 6, tiny_idat, sizeof tiny_idat);
    assert_int_equal(rt_image_load_memory(&s, buf, n, "huge.png", &img, &err), RT_ERR_LIMIT);
    expect_message(&err, "huge.png: image is 60000x60000", "over the limit");
    n = make_png(buf, 40000, 2, 6, tiny_idat, sizeof tiny_idat); /* one side too long */
    assert_int_equal(rt_image_load_memory(&s, buf, n, "wide.png", &img, &err), RT_ERR_LIMIT);
    n = make_png(buf, 20000, 20000, 2, tiny_idat, sizeof tiny_idat); /* sides fine, 400M pixels not */
    assert_int_equal(rt_image_load_memory(&s, buf, n, "square.png", &img, &err), RT_ERR_LIMIT);
    /* 4096x4096 from 8 bytes of zlib: no deflate stream expands that far */
    n = make_png(buf, 4096, 4096, 6, tiny_idat, sizeof tiny_idat);
    assert_int_equal(rt_image_load_memory(&s, buf, n, "short.png", &img, &err), RT_ERR_INVALID);
    expect_message(&err, "short.png: PNG declares 4096x4096", "too few");
    /* a float image of 10000x10000 is 1.6 GB: over the float cap */
    const char hdr[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 10000 +X 10000\n";
    memset(buf, 0, 4096);
    memcpy(buf, hdr, sizeof hdr - 1);
    assert_int_equal(rt_image_load_memory(&s, buf, 4096, "big.hdr", &img, &err), RT_ERR_LIMIT);
    expect_message(&err, "big.hdr: HDR image is 10000x10000", NULL);
    /* the zlib stream that never ends (found by libFuzzer in a GLB) */
    FILE *f = fopen("tests/corpus/image/png-zlib-stream-without-end.png", "rb");
    assert_non_null(f);
    n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    assert_int_equal(rt_image_load_memory(&s, buf, n, "bomb.png", &img, &err), RT_ERR_INVALID);
    expect_message(&err, "bomb.png: PNG pixel data does not inflate to the 262400 bytes", NULL);
    assert_int_equal(rt_image_load_memory(&s, buf, 0, "empty.png", &img, &err), RT_ERR_INVALID);
    assert_int_equal(s.image_count, 0);

    /* and a real PNG (3x2 RGB, interlaced or not as stb writes it) still loads */
    unsigned char px[18];
    for (int i = 0; i < 18; i++)
        px[i] = (unsigned char)(i * 14);
    unsigned char *w = buf;
    assert_true(stbi_write_png_to_func(collect, &w, 3, 2, 3, px, 9));
    assert_int_equal(rt_image_load_memory(&s, buf, (size_t)(w - buf), "ok.png", &img, &err), RT_OK);
    assert_int_equal(s.images[img].width, 3);
    assert_int_equal(s.images[img].height, 2);
    assert_int_equal(s.images[img].rgba8[4 * 5], px[15]);
    rt_scene_free(&s);
}

/* ------------------------------------------------------------ memory cap */

static void test_memory_budget_makes_clean_errors(void **state)
{
    (void)state;
    test_skip_in_sanitizer_build("a sanitizer runtime reserves far more address space than the 256 MiB RLIMIT_DATA");
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        struct rlimit rl = {256u << 20, 256u << 20};
        if (setrlimit(RLIMIT_DATA, &rl) != 0)
            _exit(10);
        rt_framebuffer fb;
        rt_error err = {0};
        if (rt_framebuffer_init(&fb, 20000, 20000, &err) != RT_ERR_NOMEM || !strstr(err.message, "out of memory"))
            _exit(11);
        /* a mesh too big for the budget: 3 million vertices declared and present */
        rt_scene s;
        rt_scene_init(&s);
        if (rt_scene_add_vertices(&s, (size_t)400 << 20) != RT_NONE) /* 400M vertices: ~20 GB */
            _exit(12);
        rt_scene_free(&s);
        _exit(0);
    }
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
}

/* ------------------------------------------------------------- the tree */

static void test_kdtree_primitive_cap(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    s.triangles.count = (size_t)1 << 30; /* the count alone must be refused (no arrays behind it) */
    rt_kdtree tree;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_ERR_LIMIT);
    expect_message(&err, "1073741824 primitives", "at most");
    s.triangles.count = 0;
    rt_scene_free(&s);
}

/* What rt_render_check_limits refuses before a render (the driver calls
 * it; test_cli.c checks the command line's messages): the primitive
 * count, a settings value out of its table's range, a whitted gather tree
 * over RT_MAX_DIFFUSE_TREE rays, a degenerate camera the input gave (an
 * automatic one only warns). */
static void test_render_limits(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    s.camera.position = rt_v3(0, 0, 5);
    s.camera.look_at = rt_v3(0, 0, 0);
    rt_error err = {0};
    assert_int_equal(rt_render_check_limits(&s, &set, "ok.txt", true, &err), RT_OK);
    s.triangles.count = (size_t)1 << 30; /* the count alone (no arrays behind it) */
    assert_int_equal(rt_render_check_limits(&s, &set, "big.glb", true, &err), RT_ERR_LIMIT);
    expect_message(&err, "big.glb: 1073741824 primitives", "over the limit");
    s.triangles.count = 0;
    set.samples = -3;
    assert_int_equal(rt_render_check_limits(&s, &set, "bad.txt", true, &err), RT_ERR_LIMIT);
    expect_message(&err, "bad.txt: ", "samples");
    rt_settings_default(&set);
    set.integrator = RT_INTEGRATOR_WHITTED;
    set.diffuse_bounces = 3;
    set.diffuse_rays = 256; /* 256^3 = 2^24: just allowed */
    assert_int_equal(rt_render_check_limits(&s, &set, "tree.txt", true, &err), RT_OK);
    set.diffuse_rays = 257;
    assert_int_equal(rt_render_check_limits(&s, &set, "tree.txt", true, &err), RT_ERR_LIMIT);
    expect_message(&err, "tree.txt: diffuse_rays 257 with diffuse_bounces 3", "rays per camera sample");
    rt_settings_default(&set);
    s.camera.look_at = s.camera.position;
    assert_int_equal(rt_render_check_limits(&s, &set, "cam.txt", true, &err), RT_ERR_INVALID);
    expect_message(&err, "cam.txt: the camera is degenerate", NULL);
    rt_log_level was = rt_log_get_level();
    rt_log_set_level(RT_LOG_QUIET); /* the automatic camera's warning */
    assert_int_equal(rt_render_check_limits(&s, &set, "auto.glb", false, &err), RT_OK);
    rt_log_set_level(was);
    rt_scene_free(&s);
}

/* ----------------------------------------------------------- bad numbers */

static rt_result parse(const char *text, rt_error *err)
{
    rt_scene s;
    rt_scene_init(&s);
    rt_result r = rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", ".", err);
    rt_scene_free(&s);
    return r;
}

static void test_scene_numbers_and_caps(void **state)
{
    (void)state;
    rt_error err = {0};
    static const char *const bad[] = {
        "camera position 0 0 nan look_at 0 0 0\n",
        "camera position 0 0 5 look_at 0 inf 0\n",
        "camera position 0 0 5 look_at 0 0 0 fov 1e999\n",
        "camera position 0 0 5 look_at 0 0 0 up 0 0 0\n",
        "camera position 0 0 0 look_at 0 0 0\n",
        "material m\nsphere 0 nan 0 1 m\n",
        "material m\nsphere 0 0 0 inf m\n",
        "material m\ntriangle 0 0 0 1 0 0 2 0 0 m\n",
        "material m\nquad 0 0 0 0 0 0 1 0 0 m\n",
        "material m color nan 0 0\n",
        "samples 0\n",
        "samples 1048577\n",
        "resolution 32769 1\n",
        "resolution 0 10\n",
        "max_bounce 257\n",
        "max_bounce -1\n",
        "background 1 1 -1\n",
        "exposure nan\n",
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        rt_result r = parse(bad[i], &err);
        if (r == RT_OK)
            fail_msg("accepted: %s", bad[i]);
        if (strncmp(err.message, "t.txt:", 6) != 0)
            fail_msg("message without its place for %s: %s", bad[i], err.message);
    }
    assert_int_equal(parse("samples 1048576\nresolution 32768 1\nmax_bounce 256\n", &err), RT_OK);
}

static rt_result load_mesh_text(const char *name, const char *text, rt_scene *s, rt_error *err)
{
    char path[256];
    snprintf(path, sizeof path, "/tmp/rt-test-limits-%d-%s", (int)getpid(), name);
    test_write_file(path, text, strlen(text));
    rt_material m;
    rt_material_default(&m, "m");
    uint32_t mi = rt_scene_add_material(s, &m);
    rt_mat4 id = rt_mat4_identity();
    rt_mesh_load_stats st;
    rt_mesh_options opt = {.transform = &id, .material = mi};
    rt_result r = rt_mesh_load(s, path, &opt, &st, err);
    unlink(path);
    return r;
}

static void test_mesh_numbers(void **state)
{
    (void)state;
    /* a face element without properties holds no bytes: its count (4e9,
     * which no file size bounds) must not be reserved (found by libFuzzer) */
    rt_scene z;
    rt_scene_init(&z);
    rt_error zerr = {0};
    assert_int_equal(load_mesh_text("zero.ply",
                                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 4000000000\nelement junk 4000000000\nend_header\n"
                                    "0 0 0\n1 0 0\n0 1 0\n",
                                    &z, &zerr),
                     RT_OK);
    assert_int_equal(z.triangles.count, 0);
    rt_scene_free(&z);

    static const char *const bad[][2] = {
        {"a.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
        {"b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 inf\nf 1/1 2/1 3/1\n"},
        {"c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"},
        {"d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n"},
        {"e.off", "OFF\n3 1 0\n0 0 nan\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"},
        {"g.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n"},
        {"h.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "end_header\n0 0 0\n1 inf 0\n0 1 0\n"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        rt_scene s;
        rt_scene_init(&s);
        rt_error err = {0};
        if (load_mesh_text(bad[i][0], bad[i][1], &s, &err) == RT_OK)
            fail_msg("%s accepted", bad[i][0]);
        if (!strstr(err.message, bad[i][0]))
            fail_msg("%s: message does not name the file: %s", bad[i][0], err.message);
        rt_scene_free(&s);
    }
}

/* ------------------------------------------------------------ rendering */

static void render_scene(rt_scene *s, const rt_settings *set, int threads, int tile, atomic_int *cancel, rt_framebuffer *fb,
                         rt_render_stats *st, rt_result expect)
{
    rt_kdtree tree;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(&tree, s, NULL, &err), RT_OK);
    assert_int_equal(rt_framebuffer_init(fb, set->width, set->height, &err), RT_OK);
    rt_render_options o;
    memset(&o, 0, sizeof o);
    o.threads = threads;
    o.tile_size = tile;
    o.cancel = cancel;
    assert_int_equal(rt_render(s, set, &tree, &o, fb, st, &err), expect);
    rt_kdtree_free(&tree);
}

static void builtin(rt_scene *s, rt_settings *set, int w, int h, int spp)
{
    rt_scene_init(s);
    rt_settings_default(set);
    rt_error err = {0};
    assert_int_equal(rt_scene_parse_string(s, set, rt_default_scene_text, strlen(rt_default_scene_text), "<built-in>", NULL,
                                           &err),
                     RT_OK);
    set->width = w;
    set->height = h;
    set->samples = spp;
}

static void test_same_image_any_threads_and_tiles(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    builtin(&s, &set, 21, 13, 2);
    rt_framebuffer ref, fb;
    rt_render_stats st;
    render_scene(&s, &set, 1, 4, NULL, &ref, &st, RT_OK);
    assert_int_equal(st.tiles_total, 6 * 4);
    assert_int_equal(st.bad_samples, 0);
    const int cases[][2] = {{2, 4}, {3, 1}, {64, 4}, {64, 5}, {8, 100} /* one tile, eight threads */, {1, 21}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        render_scene(&s, &set, cases[i][0], cases[i][1], NULL, &fb, &st, RT_OK);
        if (memcmp(ref.rgb, fb.rgb, sizeof(float) * 3 * 21 * 13) != 0)
            fail_msg("%d threads, %d-pixel tiles: a different image", cases[i][0], cases[i][1]);
        rt_framebuffer_free(&fb);
    }
    rt_framebuffer_free(&ref);
    rt_scene_free(&s);

    /* 1x1 */
    builtin(&s, &set, 1, 1, 4);
    render_scene(&s, &set, 4, 0, NULL, &fb, &st, RT_OK);
    assert_int_equal(st.tiles_total, 1);
    assert_true(isfinite(fb.rgb[0]) && fb.rgb[0] > 0.0f);
    rt_framebuffer_free(&fb);
    rt_scene_free(&s);
}

static void test_cancelled_render(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    builtin(&s, &set, 40, 30, 1);
    atomic_int cancel;
    atomic_init(&cancel, 1);
    rt_framebuffer fb;
    rt_render_stats st;
    render_scene(&s, &set, 4, 8, &cancel, &fb, &st, RT_ERR_INTERRUPTED);
    assert_true(st.interrupted);
    assert_int_equal(st.tiles_done, 0);
    assert_int_equal(st.tiles_total, 5 * 4);
    for (size_t i = 0; i < 3u * 40u * 30u; i++)
        assert_true(fb.rgb[i] == 0.0f);
    rt_framebuffer_free(&fb);
    rt_scene_free(&s);
}

static void test_tile_count_cap(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    builtin(&s, &set, 32768, 32768, 1);
    rt_kdtree tree;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    float dummy[3] = {0};
    rt_framebuffer fb = {32768, 32768, dummy}; /* refused before any pixel is touched */
    rt_render_options o;
    memset(&o, 0, sizeof o);
    o.tile_size = 1;
    rt_render_stats st;
    assert_int_equal(rt_render(&s, &set, &tree, &o, &fb, &st, &err), RT_ERR_LIMIT);
    expect_message(&err, "1073741824 tiles", "larger tiles");
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

/* Degenerate and far-out geometry: every sample finite, none dropped. */
static void test_degenerate_geometry_renders_clean(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    builtin(&s, &set, 16, 16, 4);
    /* a zero-area triangle, a needle, and a triangle at 1e30 */
    uint32_t v = rt_scene_add_vertices(&s, 9);
    assert_int_not_equal(v, RT_NONE);
    const float p[9][3] = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {-1, 0.5f, 0}, {1, 0.5f, 0}, {1, 0.5f + 1e-30f, 0},
                           {1e30f, 1e30f, 1e30f}, {-1e30f, 1e30f, 1e30f}, {0, -1e30f, 1e30f}};
    for (int i = 0; i < 9; i++)
        s.vertices.position[v + (uint32_t)i] = rt_v3(p[i][0], p[i][1], p[i][2]);
    for (int t = 0; t < 3; t++)
        assert_int_not_equal(rt_scene_add_triangle(&s, v + 3u * (uint32_t)t, v + 3u * (uint32_t)t + 1,
                                                   v + 3u * (uint32_t)t + 2, 0, RT_TRI_SMOOTH),
                             RT_NONE);
    const rt_integrator kinds[] = {RT_INTEGRATOR_DIRECT, RT_INTEGRATOR_WHITTED, RT_INTEGRATOR_PATH};
    for (size_t k = 0; k < 3; k++) {
        set.integrator = kinds[k];
        rt_framebuffer fb;
        rt_render_stats st;
        render_scene(&s, &set, 2, 8, NULL, &fb, &st, RT_OK);
        assert_int_equal(st.bad_samples, 0);
        for (size_t i = 0; i < 3u * 16u * 16u; i++)
            assert_true(isfinite(fb.rgb[i]) && fb.rgb[i] >= 0.0f);
        rt_framebuffer_free(&fb);
    }
    rt_scene_free(&s);
}

int main(void)
{
    rt_log_set_level(RT_LOG_QUIET);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_checked_allocation),
        cmocka_unit_test(test_framebuffer_and_output_caps),
        cmocka_unit_test(test_image_header_limits),
        cmocka_unit_test(test_memory_budget_makes_clean_errors),
        cmocka_unit_test(test_kdtree_primitive_cap),
        cmocka_unit_test(test_render_limits),
        cmocka_unit_test(test_scene_numbers_and_caps),
        cmocka_unit_test(test_mesh_numbers),
        cmocka_unit_test(test_same_image_any_threads_and_tiles),
        cmocka_unit_test(test_cancelled_render),
        cmocka_unit_test(test_tile_count_cap),
        cmocka_unit_test(test_degenerate_geometry_renders_clean),
    };
    return cmocka_run_group_tests_name("limits", tests, NULL, NULL);
}
