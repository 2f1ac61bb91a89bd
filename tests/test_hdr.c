/* test_hdr.c - the HDR workflow: OpenEXR out and in (float exact, half to
 * half precision, layers, textures, size limits, broken files), Radiance
 * HDR and PFM files cut or lying about their size (an error naming the
 * file and the byte, never a hang or a huge allocation), the tone curves
 * at points worked out from their formulas, `rt convert` (round trips,
 * refused flag combinations, OUT over IN, exit codes), AOVs (the same bytes
 * for any threads, tiles and passes; through mirrors and glass), and
 * --denoise: the 64x64 Cornell render gets closer to the shared Mitsuba
 * reference, the noisy image is kept with --aov, the library's search
 * order, and a missing library is one clear error before any rendering. */
#include "test_util.h"

#include <glob.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rt/base/file.h"
#include "rt/image/compare.h"
#include "rt/image/denoise.h"
#include "rt/image/srgb.h"
#include "rt/image/tonemap.h"
#include "rt/io/exr.h"
#include "rt/io/image_write.h"
#include "rt/io/image_load.h"
#include "rt/io/image_read.h"
#include "rt/scene/scene.h"
#include "rt/scene/texture.h"

#include "../src/driver/commands.h"

#define assert_near(a, b, tol) assert_near_at((double)(a), (double)(b), (double)(tol), #a, __LINE__)
static void assert_near_at(double a, double b, double tol, const char *what, int line)
{
    if (!(fabs(a - b) <= tol))
        fail_msg("line %d: %s = %.9g, expected %.9g (within %g)", line, what, a, b, tol);
}

static char dir[64];

static int setup(void **state)
{
    (void)state;
    return test_make_dir(dir, sizeof dir, "hdr") ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(dir);
    return 0;
}

static const char *tmp(const char *name)
{
    static char paths[8][256];
    static int next;
    char *p = paths[next++ % 8];
    snprintf(p, 256, "%s/%.120s", dir, name);
    return p;
}

/* A w x h image with values over many magnitudes, negatives and zeros. */
static void fill(rt_framebuffer *fb, int w, int h)
{
    assert_int_equal(rt_framebuffer_init(fb, w, h, NULL), RT_OK);
    test_rng r = {12345};
    for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++) {
        float u = test_rng_float(&r);
        fb->rgb[i] = i % 17 == 0 ? 0.0f : i % 13 == 0 ? -u : u * powf(10.0f, (float)(i % 9) - 4.0f);
    }
}

static void test_exr_float_round_trip(void **state)
{
    (void)state;
    rt_framebuffer a, b;
    fill(&a, 37, 23); /* odd sizes: a last chunk of 7 lines */
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write(&a, tmp("f.exr"), 1.0f, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("f.exr"), &b, &err), RT_OK);
    assert_int_equal(b.width, 37);
    assert_int_equal(b.height, 23);
    assert_memory_equal(a.rgb, b.rgb, 37 * 23 * 3 * sizeof(float));
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
}

static void test_exr_half_round_trip(void **state)
{
    (void)state;
    rt_framebuffer a, b;
    fill(&a, 20, 18);
    rt_error err = {0};
    rt_image_options opt = {.half = true};
    assert_int_equal(rt_framebuffer_write_with(&a, tmp("h.exr"), &opt, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("h.exr"), &b, &err), RT_OK);
    for (size_t i = 0; i < 20 * 18 * 3; i++) {
        float x = a.rgb[i];
        /* half: 11 significant bits; below 2^-14 the step is 2^-24 */
        assert_near(b.rgb[i], x, fabsf(x) * (1.0f / 2048.0f) + 6e-8f);
    }
    /* half the bytes of float, or near it after ZIP */
    char *fb_bytes, *hb_bytes;
    size_t fs, hs;
    assert_int_equal(rt_framebuffer_write(&a, tmp("f2.exr"), 1.0f, &err), RT_OK);
    assert_int_equal(rt_read_file(tmp("f2.exr"), 0, &fb_bytes, &fs, &err), RT_OK);
    assert_int_equal(rt_read_file(tmp("h.exr"), 0, &hb_bytes, &hs, &err), RT_OK);
    assert_true(hs < fs);
    free(fb_bytes);
    free(hb_bytes);
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
}

static void test_exr_layers(void **state)
{
    (void)state;
    rt_framebuffer a, b;
    fill(&a, 8, 6);
    float albedo[8 * 6 * 3], depth[8 * 6];
    for (int i = 0; i < 8 * 6 * 3; i++)
        albedo[i] = 0.5f;
    for (int i = 0; i < 8 * 6; i++)
        depth[i] = (float)i;
    rt_image_layer layers[2] = {{"albedo", 3, albedo}, {"depth", 1, depth}};
    rt_image_options opt = {.layers = layers, .layer_count = 2};
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write_with(&a, tmp("l.exr"), &opt, &err), RT_OK);
    /* the beauty image reads back unchanged past the other layers */
    assert_int_equal(rt_image_read(tmp("l.exr"), &b, &err), RT_OK);
    assert_memory_equal(a.rgb, b.rgb, 8 * 6 * 3 * sizeof(float));
    /* the header lists the layers' channels, by the naming convention */
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file(tmp("l.exr"), 0, &bytes, &size, &err), RT_OK);
    static const char *names[] = {"albedo.R", "albedo.G", "albedo.B", "depth.Y", "compression", NULL};
    for (int i = 0; names[i]; i++) {
        bool found = false;
        for (size_t k = 0; k + strlen(names[i]) < size && !found; k++)
            found = memcmp(bytes + k, names[i], strlen(names[i]) + 1) == 0;
        if (!found)
            fail_msg("no channel %s in the header", names[i]);
    }
    free(bytes);
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
}

static void test_exr_texture_and_limits(void **state)
{
    (void)state;
    rt_framebuffer a;
    fill(&a, 16, 10);
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write(&a, tmp("t.exr"), 1.0f, &err), RT_OK);
    rt_scene s;
    rt_scene_init(&s);
    uint32_t img;
    assert_int_equal(rt_image_load_file(&s, tmp("t.exr"), &img, &err), RT_OK);
    const rt_image *im = &s.images[img];
    assert_int_equal(im->width, 16);
    assert_int_equal(im->height, 10);
    assert_non_null(im->rgbaf);
    for (size_t i = 0; i < 16 * 10; i++) {
        assert_memory_equal(im->rgbaf + 4 * i, a.rgb + 3 * i, 3 * sizeof(float));
        assert_true(im->rgbaf[4 * i + 3] == 1.0f);
    }
    rt_scene_free(&s);

    /* size limits are checked on the header, before the pixels */
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file(tmp("t.exr"), 0, &bytes, &size, &err), RT_OK);
    float *rgba = NULL;
    int w, h;
    assert_int_equal(rt_exr_decode(bytes, size, "t.exr", 8, 1000, &rgba, &w, &h, &err), RT_ERR_LIMIT);
    assert_int_equal(rt_exr_decode(bytes, size, "t.exr", 64, 100, &rgba, &w, &h, &err), RT_ERR_LIMIT);
    assert_non_null(strstr(err.message, "t.exr"));
    /* truncated anywhere: an error naming the file, never a crash */
    for (size_t cut = 0; cut < size; cut += 1 + cut / 8) {
        rt_result r = rt_exr_decode(bytes, cut, "cut.exr", 64, 1000, &rgba, &w, &h, &err);
        if (r == RT_OK) { /* a cut in the last chunk's padding cannot be seen */
            free(rgba);
            continue;
        }
        assert_int_equal(r, RT_ERR_INVALID);
        assert_non_null(strstr(err.message, "cut.exr"));
    }
    free(bytes);
    rt_framebuffer_free(&a);
}

/* Sets the data window of an EXR file in memory (its dataWindow box2i
 * attribute) to 0,0 .. w-1,h-1. */
static void set_data_window(char *bytes, size_t size, int32_t w, int32_t h)
{
    static const char key[] = "dataWindow\0box2i\0";
    for (size_t i = 0; i + sizeof key + 20 < size; i++)
        if (memcmp(bytes + i, key, sizeof key - 1) == 0) {
            int32_t box[4] = {0, 0, w - 1, h - 1}; /* little-endian, as the test machines are */
            memcpy(bytes + i + sizeof key - 1 + 4, box, sizeof box);
            return;
        }
    fail_msg("no dataWindow attribute");
}

static int run_convert(const char *a, const char *b, const char *c, const char *d);

/* Issue 25, class 2: a few hundred bytes of EXR whose header declares 10^8
 * pixels are refused from the chunk table and the packed sizes, before
 * the pixels are allocated (the error is not out-of-memory, and rt convert
 * exits 2 under a 256 MiB data limit). */
static void test_exr_header_claims_checked(void **state)
{
    (void)state;
    rt_framebuffer a;
    assert_int_equal(rt_framebuffer_init(&a, 16, 10, NULL), RT_OK); /* black: a few hundred bytes */
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write(&a, tmp("small.exr"), 1.0f, &err), RT_OK);
    rt_framebuffer_free(&a);
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file(tmp("small.exr"), 0, &bytes, &size, &err), RT_OK);
    assert_true(size < 1000);
    float *rgba = NULL;
    int w, h;
    char want[128];
    /* 10000x10000: 625 chunks of 16 lines, an offset table larger than the file */
    set_data_window(bytes, size, 10000, 10000);
    assert_int_equal(rt_exr_decode(bytes, size, "big.exr", 32768, (uint64_t)1 << 32, &rgba, &w, &h, &err),
                     RT_ERR_INVALID);
    snprintf(want, sizeof want, "big.exr: byte %zu: EXR file ends, but its header declares 625 chunks", size);
    test_expect_failure(RT_ERR_INVALID, &err, RT_ERR_INVALID, "big.exr", want);
    assert_null(rgba);
    test_write_file(tmp("big.exr"), bytes, size);
    /* 30000x16: one chunk, whose few hundred packed bytes cannot unpack to 5.7 MB */
    set_data_window(bytes, size, 30000, 16);
    assert_int_equal(rt_exr_decode(bytes, size, "wide.exr", 32768, (uint64_t)1 << 32, &rgba, &w, &h, &err),
                     RT_ERR_INVALID);
    snprintf(want, sizeof want, "wide.exr: byte %zu: EXR file ends, but its 30000x16 data window needs 5760000", size);
    test_expect_failure(RT_ERR_INVALID, &err, RT_ERR_INVALID, "wide.exr", want);
    assert_null(rgba);
    free(bytes);
    /* rt convert under a data limit far below the 1.6 GB the header asks for */
    if (!TEST_SANITIZED) { /* a sanitizer runtime reserves more than the limit; the checks above hold there */
        fflush(NULL);
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            struct rlimit rl = {256u << 20, 256u << 20};
            if (setrlimit(RLIMIT_DATA, &rl) != 0)
                _exit(10);
            _exit(run_convert(tmp("big.exr"), tmp("big.pfm"), NULL, NULL));
        }
        int st = 0;
        assert_int_equal(waitpid(pid, &st, 0), pid);
        assert_true(WIFEXITED(st));
        assert_int_equal(WEXITSTATUS(st), 2);
        assert_int_equal(access(tmp("big.pfm"), F_OK), -1);
    }
}

/* Writes bytes[0 .. n) to the test folder's `name`; its path. */
static const char *put(const char *name, const void *bytes, size_t n)
{
    const char *path = tmp(name);
    test_write_file(path, bytes, n);
    return path;
}

/* rt_image_read must refuse bytes[0 .. n) as `name`, with a message naming
 * it and containing `what` (when given). */
static void expect_refused(const char *name, const void *bytes, size_t n, const char *what)
{
    rt_framebuffer fb;
    rt_error err = {0};
    const char *path = put(name, bytes, n);
    if (rt_image_read(path, &fb, &err) == RT_OK)
        fail_msg("%s (%zu bytes) was read", name, n);
    if (!strstr(err.message, name) || (what && !strstr(err.message, what)))
        fail_msg("%s (%zu bytes): '%s' (wanted '%s')", name, n, err.message, what ? what : "");
}

/* Radiance HDR: stb_image's reader loops for ever on a file cut inside a
 * run-length scanline (it reads zeros past the end: runs of length 0), and
 * leaves flat pixels past the end unset. Every cut is an error naming the
 * file and the byte; environment maps (the texture path) too. An alarm
 * turns a hang into a failure. */
static void test_radiance_checked(void **state)
{
    (void)state;
    alarm(120);
    rt_framebuffer a, b;
    assert_int_equal(rt_framebuffer_init(&a, 19, 5, NULL), RT_OK);
    for (size_t i = 0; i < 19 * 5 * 3; i++)
        a.rgb[i] = (float)(i % 23) * 0.37f + 0.01f;
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write(&a, tmp("rle.hdr"), 1.0f, &err), RT_OK); /* 19 wide: run-length scanlines */
    assert_int_equal(rt_image_read(tmp("rle.hdr"), &b, &err), RT_OK);
    for (size_t i = 0; i < 19 * 5 * 3; i++) /* RGBE: 8-bit mantissas on a shared exponent */
        assert_near(b.rgb[i], a.rgb[i], 0.01 * fmax(fmax(a.rgb[i - i % 3], a.rgb[i - i % 3 + 1]), a.rgb[i - i % 3 + 2]));
    rt_framebuffer_free(&b);
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file(tmp("rle.hdr"), 0, &bytes, &size, &err), RT_OK);
    const char *res = strstr(bytes, "+X 19\n");
    assert_non_null(res);
    const size_t data_at = (size_t)(res - bytes) + 6;
    for (size_t cut = 0; cut < size; cut++)
        expect_refused("cut.hdr", bytes, cut, cut > data_at ? "Radiance HDR data ends at byte" : NULL);
    /* an environment map cut short: the scene's texture loader says so */
    put("sky.hdr", bytes, size - 7);
    rt_scene sc;
    rt_scene_init(&sc);
    uint32_t img;
    assert_int_equal(rt_image_load_file(&sc, tmp("sky.hdr"), &img, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "sky.hdr"));
    rt_scene_free(&sc);
    /* a run of length 0 */
    char *bad = malloc(size);
    assert_non_null(bad);
    memcpy(bad, bytes, size);
    assert_true(bad[data_at] == 2 && bad[data_at + 1] == 2);
    bad[data_at + 4] = 0;
    expect_refused("zero.hdr", bad, size, "run of length 0");
    /* a flat scanline after run-length ones (stb would start over at the second pixel) */
    memcpy(bad, bytes, size);
    size_t second = data_at + 4;
    for (int c = 0; c < 4; c++) /* past scanline 0's four components */
        for (int x = 0; x < 19;) {
            unsigned char count = (unsigned char)bad[second];
            x += count > 128 ? count - 128 : count;
            second += count > 128 ? 2 : 1 + count;
        }
    bad[second] = 1;
    expect_refused("mixed.hdr", bad, size, "flat after run-length");
    free(bad);
    free(bytes);
    /* flat data (under 8 pixels wide), cut */
    rt_framebuffer f4;
    assert_int_equal(rt_framebuffer_init(&f4, 4, 3, NULL), RT_OK);
    for (size_t i = 0; i < 4 * 3 * 3; i++)
        f4.rgb[i] = 0.5f;
    assert_int_equal(rt_framebuffer_write(&f4, tmp("flat.hdr"), 1.0f, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("flat.hdr"), &b, &err), RT_OK);
    assert_near(b.rgb[0], 0.5, 0);
    rt_framebuffer_free(&b);
    assert_int_equal(rt_read_file(tmp("flat.hdr"), 0, &bytes, &size, &err), RT_OK);
    expect_refused("flat-cut.hdr", bytes, size - 1, "flat pixels");
    free(bytes);
    rt_framebuffer_free(&f4);
    rt_framebuffer_free(&a);
    alarm(0);
}

/* Binary PNM: stb_image does not check that the pixels are there, so a
 * 12-byte header declaring 664x55372 read as 147 MB of uninitialised
 * pixels (found by the image_file fuzz target), and a 38-byte TGA
 * declaring 8224x8224 took 8 s and 1 GB; a whole file still reads. */
static void test_pnm_checked(void **state)
{
    (void)state;
    expect_refused("lying.pgm", "P5 664 55372 ", 13, "PNM data ends at byte 13, but its 664x55372 header needs 36767008");
    expect_refused("short16.pgm", "P5 2 1 65535 \1\2\3", 16, "needs 4 bytes of pixels from byte 13");
    /* any format: more pixels than a byte can hold (an 18-byte TGA header declaring 8224x8224) */
    expect_refused("lying.tga", "\0\0\2\0\0\0\0\0\0\0\0\0\x20\x20\x20\x20\x18\0", 18, "too few for any format");
    alarm(60); /* a header ending in a comment's '#' once looped for ever (the fuzzer's) */
    expect_refused("hash.pgm", "P53 65#", 7, NULL);
    alarm(0);
    static const char ppm[] = "P6\n# a comment\n2 1\n255\n\xff\x00\x00\x00\x00\xff";
    rt_framebuffer fb;
    rt_error err = {0};
    assert_int_equal(rt_image_read(put("ok.ppm", ppm, sizeof ppm - 1), &fb, &err), RT_OK);
    assert_int_equal(fb.width, 2);
    assert_near(fb.rgb[0], 1.0, 0);
    assert_near(fb.rgb[5], 1.0, 0);
    rt_framebuffer_free(&fb);
}

/* PFM: the header is parsed by hand and checked against the file's size
 * before any pixel memory (a 65536x65536 header on a small file is one
 * error, not 48 GiB); every message names the file and a byte; grey ("Pf")
 * and big-endian files read. */
static void test_pfm_checked(void **state)
{
    (void)state;
    rt_framebuffer a, b;
    fill(&a, 7, 3);
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write(&a, tmp("p.pfm"), 1.0f, &err), RT_OK);
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file(tmp("p.pfm"), 0, &bytes, &size, &err), RT_OK);
    const size_t data_at = size - 7 * 3 * 12;
    for (size_t cut = 0; cut < size; cut++)
        expect_refused("cut.pfm", bytes, cut, cut >= data_at ? "PFM data ends at byte" : NULL);
    free(bytes);
    static const char huge[] = "PF\n65536 65536\n-1.0\n\0\0\0\0\0\0\0\0\0\0\0\0";
    expect_refused("huge.pfm", huge, sizeof huge - 1, "needs 51539607552 bytes");
    expect_refused("wide.pfm", "PF\n65537 1\n-1.0\n", 17, "PFM width at byte 3 is over 65536");
    expect_refused("zero.pfm", "PF\n4 0\n-1.0\n", 12, "PFM height at byte 5 is 0");
    expect_refused("neg.pfm", "PF\n-4 1\n-1.0\n", 13, "expected the width");
    expect_refused("nan.pfm", "PF\n1 1\nnan\n\0\0\0\0\0\0\0\0\0\0\0\0", 23, "expected the scale");
    /* grey, little-endian: 0.5 and 1 copied to R, G and B */
    static const unsigned char grey[] = {'P', 'f', '\n', '2', ' ', '1', '\n', '-', '1', '\n', 0, 0, 0, 0x3f, 0, 0, 0x80, 0x3f};
    assert_int_equal(rt_image_read(put("g.pfm", grey, sizeof grey), &b, &err), RT_OK);
    assert_int_equal(b.width, 2);
    for (int c = 0; c < 3; c++) {
        assert_near(b.rgb[c], 0.5, 0);
        assert_near(b.rgb[3 + c], 1.0, 0);
    }
    rt_framebuffer_free(&b);
    /* colour, big-endian (a positive scale), two rows: the bottom one first */
    static const unsigned char be[] = {'P', 'F', '\n', '1', ' ', '2', '\n', '1', '.', '0', '\n',
                                       0x3f, 0x80, 0, 0, 0x40, 0, 0, 0, 0x40, 0x40, 0, 0,  /* bottom: 1 2 3 */
                                       0x3e, 0x80, 0, 0, 0, 0, 0, 0, 0xbf, 0x80, 0, 0}; /* top: 0.25 0 -1 */
    assert_int_equal(rt_image_read(put("be.pfm", be, sizeof be), &b, &err), RT_OK);
    static const float want[6] = {0.25f, 0.0f, -1.0f, 1.0f, 2.0f, 3.0f};
    assert_memory_equal(b.rgb, want, sizeof want);
    rt_framebuffer_free(&b);
    rt_framebuffer_free(&a);
}

static void test_tonemap_curves(void **state)
{
    (void)state;
    assert_near(rt_exposure_scale(0), 1, 0);
    assert_near(rt_exposure_scale(1), 2, 0);
    assert_near(rt_exposure_scale(-2), 0.25, 0);
    rt_tonemap tm;
    assert_true(rt_tonemap_parse("agx", &tm) && tm == RT_TONEMAP_AGX);
    assert_false(rt_tonemap_parse("reinhard", &tm));
    float o[3];
    /* filmic: Hable's curve divided by its value at W = 11.2, on 2x: 1 at x = 5.6 */
    rt_tonemap_rgb(RT_TONEMAP_FILMIC, (float[3]){5.6f, 0.0f, 100.0f}, o);
    assert_near(o[0], 1.0, 1e-5);
    assert_near(o[1], 0.0, 1e-6); /* f(0) = DE/DF - E/F = 0 */
    assert_near(o[2], 1.0, 0);    /* clipped past white */
    /* aces (Narkowicz): at x = 1, 0.6(2.51*0.6 + 0.03) / (0.6(2.43*0.6 + 0.59) + 0.14) */
    rt_tonemap_rgb(RT_TONEMAP_ACES, (float[3]){1.0f, 0.0f, 1e6f}, o);
    double x = 0.6;
    assert_near(o[0], x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 1e-6);
    assert_near(o[1], 0.0, 1e-7);
    assert_near(o[2], 1.0, 0);
    /* agx: grey stays grey (to the published matrices' rounding), black maps near 0 and the curve rises */
    float prev = -1.0f;
    for (float v = 0.0f; v < 100.0f; v = v * 2.0f + 0.001f) {
        rt_tonemap_rgb(RT_TONEMAP_AGX, (float[3]){v, v, v}, o);
        assert_near(o[0], o[1], 1e-3);
        assert_near(o[1], o[2], 1e-3);
        assert_true(o[0] >= prev - 1e-6f);
        prev = o[0];
    }
    rt_tonemap_rgb(RT_TONEMAP_AGX, (float[3]){0, 0, 0}, o);
    assert_true(o[0] < 1e-3f);
    rt_tonemap_rgb(RT_TONEMAP_AGX, (float[3]){0.18f, 0.18f, 0.18f}, o);
    assert_true(o[0] > 0.1f && o[0] < 0.3f); /* mid grey stays mid */
    /* clamp is exactly the plain sRGB encode rt always wrote, NaN and negatives to 0 */
    float rgb[6] = {0.5f, 2.0f, -1.0f, NAN, 0.0031308f, 0.2f};
    unsigned char b[6];
    rt_tonemap_to_srgb8(RT_TONEMAP_CLAMP, 1.5f, rgb, 2, b);
    for (int i = 0; i < 6; i++)
        assert_int_equal(b[i], (unsigned char)(rt_linear_to_srgb(rgb[i] * 1.5f) * 255.0f + 0.5f));
    rt_tonemap_to_srgb8(RT_TONEMAP_AGX, 1.0f, rgb, 2, b);
    assert_true(b[0] > 0 && b[1] < 255);
}

static int run_convert(const char *a, const char *b, const char *c, const char *d)
{
    char *argv[8] = {"convert"};
    int argc = 1;
    const char *in[4] = {a, b, c, d};
    for (int i = 0; i < 4 && in[i]; i++)
        argv[argc++] = (char *)in[i];
    FILE *out = tmpfile(), *errs = tmpfile();
    int status = rt_cmd_convert_to(argc, argv, out, errs);
    fclose(out);
    fclose(errs);
    return status;
}

static void test_convert(void **state)
{
    (void)state;
    rt_framebuffer a, b;
    fill(&a, 12, 9);
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_write(&a, tmp("c.pfm"), 1.0f, &err), RT_OK);
    /* PFM -> EXR -> PFM keeps every bit */
    assert_int_equal(run_convert(tmp("c.pfm"), tmp("c.exr"), NULL, NULL), 0);
    assert_int_equal(run_convert(tmp("c.exr"), tmp("c2.pfm"), NULL, NULL), 0);
    assert_int_equal(rt_image_read(tmp("c2.pfm"), &b, &err), RT_OK);
    assert_memory_equal(a.rgb, b.rgb, 12 * 9 * 3 * sizeof(float));
    rt_framebuffer_free(&b);
    /* to PNG with exposure and a curve: the tone-mapped values, read back through sRGB */
    assert_int_equal(run_convert(tmp("c.exr"), tmp("c.png"), "--tonemap", "aces"), 0);
    assert_int_equal(rt_image_read(tmp("c.png"), &b, &err), RT_OK);
    unsigned char want[12 * 9 * 3];
    rt_tonemap_to_srgb8(RT_TONEMAP_ACES, 1.0f, a.rgb, 12 * 9, want);
    for (size_t i = 0; i < 12 * 9 * 3; i++)
        assert_near(b.rgb[i], rt_srgb_to_linear(want[i] / 255.0f), 1e-6);
    rt_framebuffer_free(&b);
    /* refused: curves on float output, --half on PFM, unknown flags and curves, missing files */
    assert_int_equal(run_convert(tmp("c.exr"), tmp("x.pfm"), "--tonemap", "agx"), 2);
    assert_int_equal(run_convert(tmp("c.exr"), tmp("x.exr"), "--exposure", "1"), 2);
    assert_int_equal(run_convert(tmp("c.exr"), tmp("x.pfm"), "--half", NULL), 2);
    assert_int_equal(run_convert(tmp("c.exr"), tmp("x.png"), "--tonemap", "reinhard"), 2);
    assert_int_equal(run_convert(tmp("c.exr"), tmp("x.png"), "--bogus", NULL), 2);
    assert_int_equal(run_convert(tmp("missing.exr"), tmp("x.png"), NULL, NULL), 2);
    assert_int_equal(run_convert(tmp("c.exr"), NULL, NULL, NULL), 2);
    assert_int_equal(access(tmp("x.pfm"), F_OK), -1);
    /* OUT the same file as IN (by any name) is refused: the input stays */
    char *before, *after;
    size_t nb, na;
    assert_int_equal(rt_read_file(tmp("c.exr"), 0, &before, &nb, &err), RT_OK);
    char again[300];
    snprintf(again, sizeof again, "%s/./c.exr", dir);
    assert_int_equal(run_convert(tmp("c.exr"), again, "--half", NULL), 2);
    assert_int_equal(rt_read_file(tmp("c.exr"), 0, &after, &na, &err), RT_OK);
    assert_true(na == nb && memcmp(before, after, nb) == 0);
    free(before);
    free(after);
    /* a broken input leaves an existing output as it was */
    test_write_file(tmp("bad.exr"), "\x76\x2f\x31\x01garbage", 11);
    assert_int_equal(run_convert(tmp("bad.exr"), tmp("c2.pfm"), NULL, NULL), 2);
    assert_int_equal(rt_image_read(tmp("c2.pfm"), &b, &err), RT_OK);
    assert_memory_equal(a.rgb, b.rgb, 12 * 9 * 3 * sizeof(float));
    rt_framebuffer_free(&b);
    rt_framebuffer_free(&a);
}

/* Runs the rt binary (RT_BIN, default ./rt) through the shell; its status. */
static int run_rt(const char *env, const char *args, const char *stderr_to)
{
    const char *bin = getenv("RT_BIN") ? getenv("RT_BIN") : "./rt";
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s %s %s 2>%s", env ? env : "", bin, args, stderr_to ? stderr_to : "/dev/null");
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Skips the calling test, saying why, where --denoise cannot run: in a
 * sanitizer build (denoise.c refuses there), or with no Open Image Denoise
 * where `make denoiser` puts it (build/oidn-venv) and no RT_OIDN_LIBRARY.
 * Where it is installed, rt must find it: that is not a reason to skip. */
static void require_denoiser(void)
{
    test_skip_in_sanitizer_build("denoise.c refuses --denoise (OIDN's TBB dlopens with RTLD_DEEPBIND)");
    const char *env = getenv("RT_OIDN_LIBRARY");
    glob_t g;
    bool installed = env && *env;
    if (!installed && glob("build/oidn-venv/lib/python3*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2", 0,
                           NULL, &g) == 0) {
        installed = true;
        globfree(&g);
    }
    if (!installed) {
        fprintf(stderr, "skip: no Open Image Denoise in build/oidn-venv (make denoiser) and no RT_OIDN_LIBRARY\n");
        skip();
    }
    char where[4096];
    rt_error err = {0};
    if (rt_denoise_find(where, sizeof where, &err) != RT_OK)
        fail_msg("Open Image Denoise is installed, but rt does not find it: %s", err.message);
}

/* The 512x512 reference box-averaged to 64x64 (test_path.c's comparison);
 * skips the calling test without it. */
static void reference_64(rt_framebuffer *out)
{
    rt_framebuffer ref;
    rt_error err;
    test_require_cornell_reference(&ref);
    assert_int_equal(ref.width, 512);
    assert_int_equal(rt_framebuffer_init(out, 64, 64, &err), RT_OK);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++)
            for (int c = 0; c < 3; c++)
                out->rgb[3 * ((size_t)y * 64 + (size_t)x) + (size_t)c] = (float)test_cornell_block(&ref, x, y, c);
    rt_framebuffer_free(&ref);
}

static void test_denoise_cornell(void **state)
{
    (void)state;
    require_denoiser();
    rt_error err = {0};
    rt_framebuffer ref;
    reference_64(&ref);
    char args[512];
    snprintf(args, sizeof args, "-q -r 64x64 -s 16 -o %s scenes/cornell-reference.txt", tmp("noisy.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    snprintf(args, sizeof args, "-q -r 64x64 -s 16 --denoise -o %s scenes/cornell-reference.txt", tmp("den.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    rt_framebuffer noisy, den;
    assert_int_equal(rt_image_read(tmp("noisy.pfm"), &noisy, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("den.pfm"), &den, &err), RT_OK);
    rt_metrics mn, md;
    assert_int_equal(rt_image_metrics(noisy.rgb, ref.rgb, 64, 64, &mn, &err), RT_OK);
    assert_int_equal(rt_image_metrics(den.rgb, ref.rgb, 64, 64, &md, &err), RT_OK);
    fprintf(stderr, "cornell 64x64 @ 16 spp against the reference: RMSE noisy %.5f, denoised %.5f; relMSE %.5f, %.5f\n",
            mn.rmse, md.rmse, mn.relmse, md.relmse);
    /* relMSE (the error relative to the radiance, the measure for HDR
     * images) drops many times; so does the RMSE over the lit box, without
     * the light itself (reference over 1), whose radiance of ~17 a denoiser
     * shifts by a few percent, which alone outweighs the whole box in RMSE */
    assert_true(md.relmse < 0.25 * mn.relmse);
    double sn = 0.0, sd = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < 64 * 64; i++) {
        const float *r = ref.rgb + 3 * i;
        if (r[0] > 1.0f || r[1] > 1.0f || r[2] > 1.0f)
            continue;
        for (int c = 0; c < 3; c++) {
            double en = noisy.rgb[3 * i + (size_t)c] - r[c], ed = den.rgb[3 * i + (size_t)c] - r[c];
            sn += en * en;
            sd += ed * ed;
        }
        count++;
    }
    fprintf(stderr, "  without the light (%zu pixels): RMSE noisy %.5f, denoised %.5f\n", count,
            sqrt(sn / (3.0 * (double)count)), sqrt(sd / (3.0 * (double)count)));
    assert_true(count > 3800);
    assert_true(sd < 0.5 * sn);
    /* and the image means stay: the denoiser removes noise, not light */
    for (int c = 0; c < 3; c++)
        assert_near(md.mean_candidate[c] / md.mean_reference[c], 1.0, 0.04);
    rt_framebuffer_free(&noisy);
    rt_framebuffer_free(&den);
    rt_framebuffer_free(&ref);
}

static bool same_file(const char *a, const char *b)
{
    char *x, *y;
    size_t nx, ny;
    rt_error err;
    if (rt_read_file(a, 0, &x, &nx, &err) != RT_OK || rt_read_file(b, 0, &y, &ny, &err) != RT_OK)
        fail_msg("%s", err.message);
    bool same = nx == ny && memcmp(x, y, nx) == 0;
    free(x);
    free(y);
    return same;
}

/* The float outputs hold the radiance as rendered whatever the exposure
 * (--exposure in stops and the scene's exposure factor), all three alike:
 * PFM byte for byte, EXR value for value, Radiance HDR to its 8-bit
 * mantissas; only the 8-bit PNG is scaled. */
static void test_float_outputs_ignore_exposure(void **state)
{
    (void)state;
    const char *common = "-q -r 24x16 -s 2 --integrator path";
    char args[512];
    snprintf(args, sizeof args, "%s -o %s", common, tmp("lin.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    static const char *const ext[4] = {"pfm", "exr", "hdr", "png"};
    for (int k = 0; k < 4; k++) {
        snprintf(args, sizeof args, "%s --exposure 2 --set exposure=1.5 -o %s/exp.%s", common, dir, ext[k]);
        assert_int_equal(run_rt(NULL, args, NULL), 0);
    }
    snprintf(args, sizeof args, "%s -o %s", common, tmp("lin.png"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    assert_true(same_file(tmp("lin.pfm"), tmp("exp.pfm")));
    /* said, not silently ignored (rt convert and rt merge refuse them) */
    snprintf(args, sizeof args, "-r 8x8 -s 1 --tonemap agx --half -o %s", tmp("said.pfm"));
    assert_int_equal(run_rt(NULL, args, tmp("said.txt")), 0);
    char *said;
    size_t said_size;
    rt_error said_err;
    assert_int_equal(rt_read_file(tmp("said.txt"), 0, &said, &said_size, &said_err), RT_OK);
    if (!strstr(said, "said.pfm holds the linear radiance: --exposure and --tonemap shape 8-bit output") ||
        !strstr(said, "said.pfm: --half is for .exr output; ignored"))
        fail_msg("rt said: %s", said);
    free(said);
    rt_framebuffer lin, e;
    rt_error err;
    assert_int_equal(rt_image_read(tmp("lin.pfm"), &lin, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("exp.exr"), &e, &err), RT_OK);
    assert_memory_equal(lin.rgb, e.rgb, (size_t)24 * 16 * 3 * sizeof(float));
    rt_framebuffer_free(&e);
    assert_int_equal(rt_image_read(tmp("exp.hdr"), &e, &err), RT_OK);
    for (size_t i = 0; i < (size_t)24 * 16 * 3; i++) {
        const float *px = lin.rgb + (i - i % 3);
        assert_near(e.rgb[i], lin.rgb[i], fmax(fmax(px[0], px[1]), px[2]) / 128.0 + 1e-30);
    }
    rt_framebuffer_free(&e);
    /* the PNG is 6x brighter (1.5 x 2^2) before the curve: brighter on average */
    rt_framebuffer p1, p6;
    assert_int_equal(rt_image_read(tmp("lin.png"), &p1, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("exp.png"), &p6, &err), RT_OK);
    double s1 = 0.0, s6 = 0.0;
    for (size_t i = 0; i < (size_t)24 * 16 * 3; i++) {
        s1 += p1.rgb[i];
        s6 += p6.rgb[i];
    }
    assert_true(s6 > 2.0 * s1);
    rt_framebuffer_free(&p1);
    rt_framebuffer_free(&p6);
    rt_framebuffer_free(&lin);
}

/* AOVs: the beauty image is the same with them as without; every AOV is
 * bit-identical for 1 and 3 threads and other tile sizes; the values are
 * the scene's, worked out here from it: the Cornell box's white floor has
 * albedo 0.73 + 0.04 and normal +y; its position is where the ray through
 * the pixel's centre from scenes/cornell.txt's camera (position 0 1 3.94,
 * looking down -z, vertical fov 39.3) meets the plane y = 0 (the mean of
 * the pixel's samples, within its footprint), its depth the distance from
 * the camera to there; the variance of the pixel's mean is the samples'
 * variance over their count, so 4x the samples give a quarter of it. */
static void test_aovs(void **state)
{
    (void)state;
    char args[512];
    const char *common = "-q -r 48x40 -s 4 --integrator path scenes/cornell.txt";
    snprintf(args, sizeof args, "%s -o %s", common, tmp("plain.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    snprintf(args, sizeof args, "%s -t 1 --aov albedo,normal,depth,position,variance,spp -o %s", common, tmp("a1.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    snprintf(args, sizeof args, "%s -t 3 --tile 7 --aov albedo,normal,depth,position,variance,spp -o %s", common,
             tmp("a3.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    /* tile by tile, and in passes of 3 samples: the same bytes again */
    snprintf(args, sizeof args, "%s -t 2 --passes 0 --tile 5 --aov albedo,normal,depth,position,variance,spp -o %s",
             common, tmp("at.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    snprintf(args, sizeof args, "%s -t 2 --passes 3 --aov albedo,normal,depth,position,variance,spp -o %s", common,
             tmp("ap.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    assert_true(same_file(tmp("plain.pfm"), tmp("a1.pfm")));
    static const char *const names[] = {"albedo", "normal", "depth", "position", "variance", "spp"};
    static const char *const others[] = {"a3", "at", "ap"};
    for (int k = 0; k < 6; k++)
        for (int o = 0; o < 3; o++) {
            char p1[128], p3[128];
            snprintf(p1, sizeof p1, "a1.%s.pfm", names[k]);
            snprintf(p3, sizeof p3, "%s.%s.pfm", others[o], names[k]);
            if (!same_file(tmp(p1), tmp(p3)))
                fail_msg("the %s AOV differs between 1 thread and %s", names[k], p3);
        }
    rt_framebuffer alb, nrm, spp;
    rt_error err;
    assert_int_equal(rt_image_read(tmp("a1.albedo.pfm"), &alb, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("a1.normal.pfm"), &nrm, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("a1.spp.pfm"), &spp, &err), RT_OK);
    size_t px = 3 * ((size_t)38 * 48 + 24); /* bottom row, middle: the floor */
    assert_near(alb.rgb[px], 0.73 + 0.04, 1e-4); /* diffuse 0.73 + the dielectric's specular f0 0.04 */
    assert_near(nrm.rgb[px + 1], 1.0, 1e-3);
    assert_near(spp.rgb[px], 4.0, 0);
    rt_framebuffer pos, dep;
    assert_int_equal(rt_image_read(tmp("a1.position.pfm"), &pos, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("a1.depth.pfm"), &dep, &err), RT_OK);
    double t = tan(0.5 * 39.3 * 3.14159265358979 / 180.0);
    double dx = ((24 + 0.5) / 48 * 2 - 1) * t * 48.0 / 40.0, dy = (1 - (38 + 0.5) / 40 * 2) * t; /* dz = -1 */
    double hit = 1.0 / -dy;                                                                      /* y: 1 -> 0 */
    double want[3] = {dx * hit, 0.0, 3.94 - hit};
    double dist = sqrt((want[0]) * (want[0]) + 1.0 + (3.94 - want[2]) * (3.94 - want[2]));
    fprintf(stderr, "floor pixel: position (%.4f %.4f %.4f), the ray through its centre meets y = 0 at (%.4f 0 %.4f); "
                    "depth %.4f, distance %.4f\n",
            pos.rgb[px], pos.rgb[px + 1], pos.rgb[px + 2], want[0], want[2], dep.rgb[px], dist);
    assert_near(pos.rgb[px + 1], 0.0, 1e-5);
    assert_near(pos.rgb[px], want[0], 0.01);
    assert_near(pos.rgb[px + 2], want[2], 0.03); /* a pixel spans about 0.16 in z there */
    double seen = sqrt((double)pos.rgb[px] * pos.rgb[px] + 1.0 + (3.94 - pos.rgb[px + 2]) * (3.94 - pos.rgb[px + 2]));
    assert_near(dep.rgb[px], seen, 1e-3 * seen); /* depth: the distance to the mean position, to first order */
    assert_near(dep.rgb[px], dist, 0.03);
    rt_framebuffer_free(&pos);
    rt_framebuffer_free(&dep);
    rt_framebuffer_free(&alb);
    rt_framebuffer_free(&nrm);
    rt_framebuffer_free(&spp);
    /* variance over the floor's bottom-middle block at 16 and 64 samples */
    double var[2];
    for (int k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "-q -r 48x40 -s %d --integrator path --aov variance -o %s scenes/cornell.txt",
                 k ? 64 : 16, tmp("v.pfm"));
        assert_int_equal(run_rt(NULL, args, NULL), 0);
        rt_framebuffer v;
        assert_int_equal(rt_image_read(tmp("v.variance.pfm"), &v, &err), RT_OK);
        var[k] = 0.0;
        for (int y = 33; y < 38; y++) /* the floor (row 38 is its front edge) */
            for (int x = 18; x < 30; x++) {
                float a = v.rgb[3 * ((size_t)y * 48 + (size_t)x)];
                assert_true(a > 0.0f); /* a lit diffuse floor under the path tracer is noisy */
                var[k] += a / (5.0 * 12.0);
            }
        rt_framebuffer_free(&v);
    }
    fprintf(stderr, "floor variance of the mean: %.4g at 16 spp, %.4g at 64 (ratio %.2f, 4 expected)\n", var[0],
            var[1], var[0] / var[1]);
    assert_true(var[0] / var[1] > 3.0 && var[0] / var[1] < 5.3);
    /* EXR: one file with the layers */
    snprintf(args, sizeof args, "%s --aov albedo,depth -o %s", common, tmp("a.exr"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    assert_int_equal(access(tmp("a.albedo.pfm"), F_OK), -1);
    snprintf(args, sizeof args, "%s --aov albedo,bogus -o %s", common, tmp("b.exr"));
    assert_int_equal(run_rt(NULL, args, NULL), 2);
}

/* AOVs through perfect mirrors and glass, as OIDN wants them: a camera
 * facing a smooth silver mirror (bsdf conductor, then a glTF metal of
 * roughness 0) sees the red wall behind it: the wall's albedo and normal
 * (facing the ray, -z), while depth and position stay the mirror's; through
 * a slab of smooth glass, the green wall behind it. */
static void test_aovs_through_mirror_and_glass(void **state)
{
    (void)state;
    static const char *const scenes[3] = {
        "material m bsdf conductor metal Ag ggx_alpha 0\n"
        "quad -5 -5 0  10 0 0  0 10 0  m\n"
        "quad -5 -5 4  0 10 0  10 0 0  red\n",
        "material m color 1 1 1 metallic 1 roughness 0\n"
        "quad -5 -5 0  10 0 0  0 10 0  m\n"
        "quad -5 -5 4  0 10 0  10 0 0  red\n",
        "material glass bsdf dielectric ior 1.5\n"
        "quad -5 -5 0.1  10 0 0  0 10 0  glass\n"
        "quad -5 -5 -0.1  0 10 0  10 0 0  glass\n"
        "quad -5 -5 -2  10 0 0  0 10 0  green\n",
    };
    static const float albedo[3][3] = {{0.65f, 0.05f, 0.05f}, {0.65f, 0.05f, 0.05f}, {0.12f, 0.45f, 0.15f}};
    static const float normal_z[3] = {-1.0f, -1.0f, 1.0f}, depth[3] = {2.0f, 2.0f, 1.9f};
    for (int k = 0; k < 3; k++) {
        char text[1024], name[32], args[600], scene[256], out[256];
        snprintf(text, sizeof text,
                 "resolution 8 8\nsamples 2\nintegrator path\n"
                 "camera position 0 0 2 look_at 0 0 0 up 0 1 0 fov 10\n"
                 "material red color 0.65 0.05 0.05 bsdf lambert\n"
                 "material green color 0.12 0.45 0.15 bsdf lambert\n"
                 "light point 0 0 1 1 1 1 10\n%s",
                 scenes[k]);
        snprintf(name, sizeof name, "specular%d.txt", k);
        snprintf(scene, sizeof scene, "%s", put(name, text, strlen(text)));
        snprintf(name, sizeof name, "specular%d.pfm", k);
        snprintf(out, sizeof out, "%s", tmp(name));
        snprintf(args, sizeof args, "-q --aov albedo,normal,depth -o %s %s", out, scene);
        assert_int_equal(run_rt(NULL, args, NULL), 0);
        rt_framebuffer a, n, d;
        rt_error err;
        snprintf(name, sizeof name, "specular%d.albedo.pfm", k);
        assert_int_equal(rt_image_read(tmp(name), &a, &err), RT_OK);
        snprintf(name, sizeof name, "specular%d.normal.pfm", k);
        assert_int_equal(rt_image_read(tmp(name), &n, &err), RT_OK);
        snprintf(name, sizeof name, "specular%d.depth.pfm", k);
        assert_int_equal(rt_image_read(tmp(name), &d, &err), RT_OK);
        for (size_t i = 0; i < 64; i++) {
            for (int c = 0; c < 3; c++)
                assert_near(a.rgb[3 * i + (size_t)c], albedo[k][c], 1e-6);
            assert_near(n.rgb[3 * i + 2], normal_z[k], 1e-5);
            assert_near(d.rgb[3 * i], depth[k], 0.02); /* the first hit (a view 10 degrees wide: 1.0076x at the corners) */
        }
        rt_framebuffer_free(&a);
        rt_framebuffer_free(&n);
        rt_framebuffer_free(&d);
    }
}

static void test_denoise_missing_library(void **state)
{
    (void)state;
    char args[512];
    snprintf(args, sizeof args, "--denoise -o %s", tmp("never.png"));
    assert_int_equal(run_rt("RT_OIDN_LIBRARY=/nonexistent/libOpenImageDenoise.so.2", args, tmp("msg.txt")), 2);
    assert_int_equal(access(tmp("never.png"), F_OK), -1);
    char *msg;
    size_t size;
    rt_error err;
    assert_int_equal(rt_read_file(tmp("msg.txt"), 0, &msg, &size, &err), RT_OK);
    /* one line, naming what is missing */
    assert_non_null(strstr(msg, "/nonexistent/libOpenImageDenoise.so.2"));
    assert_non_null(strchr(msg, '\n'));
    assert_null(strchr(msg, '\n') + 1 < msg + size ? strchr(strchr(msg, '\n') + 1, '\n') : NULL);
    free(msg);
}

/* Where the wheel is looked for, in order: build/oidn-venv near the binary
 * and under the current directory, $VIRTUAL_ENV, then the Python user site:
 * $PYTHONUSERBASE when set (where 'pip install --user' puts it then), else
 * ~/.local. */
static void test_denoise_search_order(void **state)
{
    (void)state;
    const char *keep[3] = {getenv("VIRTUAL_ENV"), getenv("PYTHONUSERBASE"), getenv("HOME")};
    char saved[3][1024];
    for (int i = 0; i < 3; i++)
        snprintf(saved[i], sizeof saved[i], "%s", keep[i] ? keep[i] : "");
    setenv("VIRTUAL_ENV", "/venv", 1);
    setenv("PYTHONUSERBASE", "/userbase", 1);
    setenv("HOME", "/home/someone", 1);
    char list[16384];
    rt_denoise_wheel_patterns(list, sizeof list);
    const char *wheel = "/lib/python3*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2\n";
    char venv[256], user[256];
    snprintf(venv, sizeof venv, "/venv%s", wheel);
    snprintf(user, sizeof user, "/userbase%s", wheel);
    const char *cwd = strstr(list, "\nbuild/oidn-venv/lib/python3*/"), *v = strstr(list, venv), *u = strstr(list, user);
    if (!cwd || !v || !u || !(cwd < v && v < u) || strstr(list, "/home/someone"))
        fail_msg("search order:\n%s", list);
    unsetenv("PYTHONUSERBASE");
    rt_denoise_wheel_patterns(list, sizeof list);
    if (!strstr(list, "/home/someone/.local/lib/python3*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2\n"))
        fail_msg("without PYTHONUSERBASE:\n%s", list);
    static const char *const names[3] = {"VIRTUAL_ENV", "PYTHONUSERBASE", "HOME"};
    for (int i = 0; i < 3; i++) {
        if (keep[i])
            setenv(names[i], saved[i], 1);
        else
            unsetenv(names[i]);
    }
}

/* --denoise with --aov keeps the noisy image beside the denoised one: the
 * same bytes as a render without --denoise, as NAME.noisy.pfm or as the
 * EXR's noisy layer. */
static void test_denoise_keeps_noisy(void **state)
{
    (void)state;
    require_denoiser();
    rt_error err = {0};
    const char *common = "-q -r 20x16 -s 2 --integrator path";
    char args[512];
    snprintf(args, sizeof args, "%s -o %s", common, tmp("raw.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    snprintf(args, sizeof args, "%s --denoise --aov albedo -o %s", common, tmp("den.pfm"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    assert_true(same_file(tmp("raw.pfm"), tmp("den.noisy.pfm")));
    assert_false(same_file(tmp("raw.pfm"), tmp("den.pfm")));
    assert_int_equal(access(tmp("den.albedo.pfm"), F_OK), 0);
    snprintf(args, sizeof args, "%s --denoise --aov normal -o %s", common, tmp("den.exr"));
    assert_int_equal(run_rt(NULL, args, NULL), 0);
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file(tmp("den.exr"), 0, &bytes, &size, &err), RT_OK);
    static const char *const noisy[3] = {"noisy.R", "noisy.G", "noisy.B"};
    float *px = NULL;
    int w, h;
    assert_int_equal(rt_exr_decode_channels(bytes, size, "den.exr", 64, 4096, noisy, 3, &px, &w, &h, &err), RT_OK);
    rt_framebuffer raw;
    assert_int_equal(rt_image_read(tmp("raw.pfm"), &raw, &err), RT_OK);
    assert_memory_equal(px, raw.rgb, (size_t)20 * 16 * 3 * sizeof(float));
    rt_framebuffer_free(&raw);
    free(px);
    free(bytes);
}

/* --denoise-quality and -t reach OIDN: its filter runs in the quality
 * asked for (the flag over RT_OIDN_QUALITY) on the device's numThreads as
 * OIDN reports it back (the -v line); bad words are refused before any
 * work. */
static void test_denoise_quality_and_threads(void **state)
{
    (void)state;
    rt_denoise_quality q = RT_DENOISE_DEFAULT;
    assert_true(rt_denoise_quality_parse("fast", &q) && q == RT_DENOISE_FAST);
    assert_true(rt_denoise_quality_parse("balanced", &q) && q == RT_DENOISE_BALANCED);
    assert_true(rt_denoise_quality_parse("high", &q) && q == RT_DENOISE_HIGH);
    assert_false(rt_denoise_quality_parse("High", &q) || rt_denoise_quality_parse("", &q));
    assert_int_equal(q, RT_DENOISE_HIGH);
    char args[512];
    snprintf(args, sizeof args, "--denoise --denoise-quality ultra -o %s", tmp("never.png"));
    assert_int_equal(run_rt(NULL, args, NULL), 2);
    snprintf(args, sizeof args, "--denoise-quality high -o %s", tmp("never.png")); /* without --denoise */
    assert_int_equal(run_rt(NULL, args, NULL), 2);
    assert_int_equal(access(tmp("never.png"), F_OK), -1);

    require_denoiser();
    rt_error err = {0};
    const char *common = "-v -r 24x24 -s 2 --integrator path --denoise";
    snprintf(args, sizeof args, "%s -t 1 --denoise-quality fast -o %s", common, tmp("fast.pfm"));
    assert_int_equal(run_rt("RT_OIDN_QUALITY=high", args, tmp("fast.txt")), 0);
    snprintf(args, sizeof args, "%s -t 2 -o %s", common, tmp("high.pfm"));
    assert_int_equal(run_rt("RT_OIDN_QUALITY=high", args, tmp("high.txt")), 0);
    char *msg;
    size_t size;
    assert_int_equal(rt_read_file(tmp("fast.txt"), 0, &msg, &size, &err), RT_OK);
    if (!strstr(msg, "OIDN RT filter, fast quality, 1 thread,"))
        fail_msg("-t 1 --denoise-quality fast: %s", msg);
    free(msg);
    assert_int_equal(rt_read_file(tmp("high.txt"), 0, &msg, &size, &err), RT_OK);
    if (!strstr(msg, "OIDN RT filter, high quality, 2 threads,"))
        fail_msg("-t 2 with RT_OIDN_QUALITY=high: %s", msg);
    free(msg);
    /* the same render, two networks: two images */
    rt_framebuffer fast, high;
    assert_int_equal(rt_image_read(tmp("fast.pfm"), &fast, &err), RT_OK);
    assert_int_equal(rt_image_read(tmp("high.pfm"), &high, &err), RT_OK);
    assert_true(memcmp(fast.rgb, high.rgb, (size_t)24 * 24 * 3 * sizeof(float)) != 0);
    rt_framebuffer_free(&fast);
    rt_framebuffer_free(&high);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exr_float_round_trip), cmocka_unit_test(test_exr_half_round_trip),
        cmocka_unit_test(test_exr_layers),           cmocka_unit_test(test_exr_texture_and_limits),
        cmocka_unit_test(test_exr_header_claims_checked),
        cmocka_unit_test(test_radiance_checked),     cmocka_unit_test(test_pfm_checked),
        cmocka_unit_test(test_pnm_checked),
        cmocka_unit_test(test_float_outputs_ignore_exposure),
        cmocka_unit_test(test_tonemap_curves),       cmocka_unit_test(test_convert),
        cmocka_unit_test(test_denoise_cornell),      cmocka_unit_test(test_denoise_missing_library),
        cmocka_unit_test(test_aovs),                 cmocka_unit_test(test_aovs_through_mirror_and_glass),
        cmocka_unit_test(test_denoise_quality_and_threads), cmocka_unit_test(test_denoise_search_order),
        cmocka_unit_test(test_denoise_keeps_noisy),
    };
    return cmocka_run_group_tests_name("hdr", tests, setup, teardown);
}
