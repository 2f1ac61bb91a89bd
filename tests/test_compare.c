/* test_compare.c - image comparison: the error metrics on cases worked out
 * by hand, FLIP against NVIDIA's flip-evaluator on procedural image pairs,
 * and `rt compare` (its output, thresholds and exit codes).
 *
 * The pairs are made here with integer arithmetic exactly as
 * tools/flip_reference.py makes them (each pair's hash is checked against
 * the script's), and the expected LDR-FLIP and HDR-FLIP values are what
 * flip-evaluator 1.7 printed for them; rerun the script to check them. */
#include "test_util.h"

#include <math.h>
#include <time.h>
#include <unistd.h>

#include "rt/base/file.h"
#include "rt/image/compare.h"
#include "rt/image/flip.h"
#include "rt/io/image_write.h"
#include "rt/io/image_read.h"

#include "../src/driver/commands.h"


/* |a - b| <= tol, with both values in the failure message (this cmocka has
 * no floating-point asserts). */
#define assert_near(a, b, tol) assert_near_at((double)(a), (double)(b), (double)(tol), #a, __LINE__)
static void assert_near_at(double a, double b, double tol, const char *what, int line)
{
    if (!(fabs(a - b) <= tol))
        fail_msg("line %d: %s = %.9g, expected %.9g (within %g)", line, what, a, b, tol);
}

/* ---- procedural images (tools/flip_reference.py) ----------------------------------------------- */

enum { W = 96, H = 64, ONE = 65536 };

typedef struct pcg32 { uint64_t state, inc; } pcg32;

static uint32_t pcg32_next(pcg32 *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ull + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18) ^ old) >> 27);
    uint32_t rot = (uint32_t)(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((32 - rot) & 31));
}

static pcg32 pcg32_seed(uint64_t seed, uint64_t seq)
{
    pcg32 r = {0, (seq << 1) | 1};
    pcg32_next(&r);
    r.state += seed;
    pcg32_next(&r);
    return r;
}

typedef struct qimage { int64_t q[H][W][3]; } qimage; /* values q / 65536 */

static int64_t clampi(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : v > hi ? hi : v; }

static void make_base(qimage *o)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int64_t grad[3] = {(x * 4095) / (W - 1), (y * 4095) / (H - 1), ((x + y) * 4095) / (W + H - 2)};
            int64_t c = ((x / 8 + y / 8) & 1) ? 3300 : 700;
            int64_t check[3] = {c, (c * 3) / 4, c / 2};
            for (int k = 0; k < 3; k++)
                o->q[y][x][k] = 16 * ((grad[k] + check[k]) / 2);
        }
}

static void make_noisy(const qimage *in, qimage *o)
{
    pcg32 r = pcg32_seed(42, 54);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++)
                o->q[y][x][k] = clampi(in->q[y][x][k] + (int64_t)(pcg32_next(&r) >> 19) - 4096, 0, ONE);
}

static void make_blurred(const qimage *in, qimage *o)
{
    static const int64_t w[3] = {1, 2, 1};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++) {
                int64_t s = 0;
                for (int j = 0; j < 3; j++)
                    for (int i = 0; i < 3; i++)
                        s += w[j] * w[i] * in->q[clampi(y + j - 1, 0, H - 1)][clampi(x + i - 1, 0, W - 1)][k];
                o->q[y][x][k] = s / 16;
            }
}

static void make_shifted(const qimage *in, qimage *o)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++)
                o->q[y][x][k] = in->q[y][x >= 2 ? x - 2 : 0][k];
}

static void make_colour_shifted(const qimage *in, qimage *o)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            o->q[y][x][0] = in->q[y][x][0] * 7 / 8;
            o->q[y][x][1] = in->q[y][x][1];
            o->q[y][x][2] = in->q[y][x][2] + 6000 < ONE ? in->q[y][x][2] + 6000 : ONE;
        }
}

static void make_constant(int64_t v, qimage *o)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++)
                o->q[y][x][k] = v;
}

static void to_ldr(const qimage *in, float *out)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++)
                out[(y * W + x) * 3 + k] = (float)in->q[y][x][k] / (float)ONE;
}

/* Linear values: the LDR value times 2^(8x/W - 4). */
static void to_hdr(const qimage *in, float *out)
{
    to_ldr(in, out);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++)
                out[(y * W + x) * 3 + k] *= ldexpf(1.0f, (x * 8) / W - 4);
}

static uint32_t fnv1a(uint32_t h, const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &v[i], 4);
        for (int b = 0; b < 4; b++) /* little-endian bytes, whatever the host */
            h = (h ^ ((u >> (8 * b)) & 255u)) * 0x01000193u;
    }
    return h;
}

/* The values tools/flip_reference.py printed (flip-evaluator 1.7). */
typedef struct flip_case {
    const char *name;
    uint32_t ldr_hash, hdr_hash;
    float ppd;
    double ldr, hdr;
} flip_case;

static const flip_case flip_cases[] = {
    {"identical", 0xd665ec59u, 0x2163ae21u, 0.0f, 0.0000000, 0.0000000},
    {"noise", 0xb6a7405eu, 0xf0e307bau, 0.0f, 0.0845985, 0.0750022},
    {"noise_ppd30", 0xb6a7405eu, 0xf0e307bau, 30.0f, 0.1615304, 0.1414564},
    {"blur", 0x3fa03f66u, 0x5fc7b8b7u, 0.0f, 0.0847695, 0.0664266},
    {"shift", 0x32aefc86u, 0xc67f842cu, 0.0f, 0.2525053, 0.2001112},
    {"colour", 0x1b287b14u, 0x951544abu, 0.0f, 0.2946466, 0.2039342},
    {"constant", 0x6c9cbdc5u, 0x4337c5c5u, 0.0f, 0.1909993, 0.1794354},
    {"constant_same", 0xf3f71dc5u, 0xb9689dc5u, 0.0f, 0.0000000, 0.0000000},
};

/* The candidate and reference of a named pair. */
static void make_pair(const char *name, qimage *cand, qimage *ref)
{
    make_base(ref);
    if (strcmp(name, "identical") == 0)
        *cand = *ref;
    else if (strncmp(name, "noise", 5) == 0)
        make_noisy(ref, cand);
    else if (strcmp(name, "blur") == 0)
        make_blurred(ref, cand);
    else if (strcmp(name, "shift") == 0)
        make_shifted(ref, cand);
    else if (strcmp(name, "colour") == 0)
        make_colour_shifted(ref, cand);
    else if (strcmp(name, "constant") == 0) {
        make_constant(16384, cand);
        make_constant(19661, ref);
    } else if (strcmp(name, "constant_same") == 0) {
        make_constant(32768, cand);
        make_constant(32768, ref);
    } else
        fail_msg("unknown pair %s", name);
}

/* ---- FLIP against flip-evaluator ------------------------------------------------------------- */

#define FLIP_TOLERANCE 1e-3

static void test_flip_matches_flip_evaluator(void **state)
{
    (void)state;
    qimage *cq = malloc(sizeof *cq), *rq = malloc(sizeof *rq);
    float *c = malloc(sizeof(float) * W * H * 3), *r = malloc(sizeof(float) * W * H * 3);
    assert_true(cq && rq && c && r);
    double worst_ldr = 0, worst_hdr = 0;
    for (size_t i = 0; i < sizeof flip_cases / sizeof flip_cases[0]; i++) {
        const flip_case *fc = &flip_cases[i];
        make_pair(fc->name, cq, rq);
        rt_flip_options opt = {0};
        opt.ppd = fc->ppd;
        rt_error err = {0};
        double ldr = -1, hdr = -1;

        to_ldr(cq, c);
        to_ldr(rq, r);
        uint32_t h = fnv1a(fnv1a(0x811C9DC5u, c, W * H * 3), r, W * H * 3);
        if (h != fc->ldr_hash)
            fail_msg("%s: LDR images differ from tools/flip_reference.py's (hash %08x, expected %08x)", fc->name, h,
                     fc->ldr_hash);
        assert_int_equal(rt_flip_ldr(c, r, W, H, &opt, NULL, &ldr, &err), RT_OK);

        to_hdr(cq, c);
        to_hdr(rq, r);
        h = fnv1a(fnv1a(0x811C9DC5u, c, W * H * 3), r, W * H * 3);
        if (h != fc->hdr_hash)
            fail_msg("%s: HDR images differ from tools/flip_reference.py's (hash %08x, expected %08x)", fc->name, h,
                     fc->hdr_hash);
        assert_int_equal(rt_flip_hdr(c, r, W, H, &opt, NULL, &hdr, NULL, &err), RT_OK);

        printf("    %-14s LDR-FLIP %.7f (flip-evaluator %.7f, %+.1e)  HDR-FLIP %.7f (%.7f, %+.1e)\n", fc->name, ldr,
               fc->ldr, ldr - fc->ldr, hdr, fc->hdr, hdr - fc->hdr);
        worst_ldr = fmax(worst_ldr, fabs(ldr - fc->ldr));
        worst_hdr = fmax(worst_hdr, fabs(hdr - fc->hdr));
        if (fabs(ldr - fc->ldr) > FLIP_TOLERANCE || fabs(hdr - fc->hdr) > FLIP_TOLERANCE)
            fail_msg("%s: FLIP differs from flip-evaluator by more than %g", fc->name, FLIP_TOLERANCE);
    }
    printf("    largest difference: LDR %.1e, HDR %.1e\n", worst_ldr, worst_hdr);
    free(cq);
    free(rq);
    free(c);
    free(r);
}

/* ---- metrics by hand ------------------------------------------------------------------------ */

static void test_metrics_identical(void **state)
{
    (void)state;
    float img[4 * 3 * 3];
    for (int i = 0; i < 36; i++)
        img[i] = (float)i * 0.1f;
    rt_metrics m;
    rt_error err = {0};
    assert_int_equal(rt_image_metrics(img, img, 4, 3, &m, &err), RT_OK);
    assert_true(m.mse == 0 && m.rmse == 0 && m.relmse == 0 && m.mae == 0);
    for (int k = 0; k < 3; k++) {
        double s = 0;
        for (int i = 0; i < 12; i++)
            s += (double)img[3 * i + k];
        assert_near(m.mean_candidate[k], s / 12, 1e-12);
        assert_near(m.mean_reference[k], s / 12, 1e-12);
    }
}

static void test_metrics_constant_offset(void **state)
{
    (void)state;
    enum { N = 5 * 7 * 3 };
    float ref[N], cand[N];
    const float d = 0.125f; /* exact in float, so every difference is exactly d */
    for (int i = 0; i < N; i++) {
        ref[i] = 0.5f;
        cand[i] = 0.5f + d;
    }
    rt_metrics m;
    rt_error err = {0};
    assert_int_equal(rt_image_metrics(cand, ref, 5, 7, &m, &err), RT_OK);
    assert_near(m.mse, 0.125 * 0.125, 1e-15);
    assert_near(m.rmse, 0.125, 1e-15);
    assert_near(m.mae, 0.125, 1e-15);
    assert_near(m.relmse, 0.125 * 0.125 / (0.25 + 0.01), 1e-15);
    for (int k = 0; k < 3; k++) {
        assert_near(m.mean_candidate[k], 0.625, 1e-15);
        assert_near(m.mean_reference[k], 0.5, 1e-15);
    }
}

static void test_metrics_by_hand(void **state)
{
    (void)state;
    /* two pixels; differences (c - r): 1, 0, -0.5 | 0, 2, 0 */
    const float ref[6] = {0, 1, 0.5f, 2, 0, 1};
    const float cand[6] = {1, 1, 0, 2, 2, 1};
    rt_metrics m;
    rt_error err = {0};
    assert_int_equal(rt_image_metrics(cand, ref, 2, 1, &m, &err), RT_OK);
    assert_near(m.mse, (1 + 0.25 + 4) / 6.0, 1e-12);
    assert_near(m.rmse, sqrt((1 + 0.25 + 4) / 6.0), 1e-12);
    assert_near(m.mae, (1 + 0.5 + 2) / 6.0, 1e-12);
    /* relMSE = mean (c - r)^2 / (r^2 + 0.01): the reference is the denominator */
    double rel = (1 / (0 + 0.01) + 0.25 / (0.25 + 0.01) + 4 / (0 + 0.01)) / 6.0;
    assert_near(m.relmse, rel, 1e-9);
    assert_near(m.mean_candidate[0], 1.5, 1e-12);
    assert_near(m.mean_reference[2], 0.75, 1e-12);
    /* not symmetric: swapping the images changes relMSE only */
    rt_metrics s;
    assert_int_equal(rt_image_metrics(ref, cand, 2, 1, &s, &err), RT_OK);
    assert_near(s.mse, m.mse, 1e-15);
    assert_near(s.relmse, (1 / 1.01 + 0.25 / 0.01 + 4 / 4.01) / 6.0, 1e-9);
}

static void test_metrics_bad_input(void **state)
{
    (void)state;
    float px[3] = {0, 0, 0};
    rt_metrics m;
    rt_error err = {0};
    assert_int_equal(rt_image_metrics(px, px, 0, 1, &m, &err), RT_ERR_INVALID);
    assert_int_equal(rt_image_metrics(px, NULL, 1, 1, &m, &err), RT_ERR_INVALID);
    /* a NaN makes the metrics NaN (so thresholds on them fail), not an error */
    float nan_px[3] = {NAN, 0, 0};
    assert_int_equal(rt_image_metrics(nan_px, px, 1, 1, &m, &err), RT_OK);
    assert_true(isnan(m.mse) && isnan(m.rmse));
}

/* ---- FLIP properties ----------------------------------------------------------------------- */

static void test_flip_identical_is_zero(void **state)
{
    (void)state;
    qimage *q = malloc(sizeof *q), *base = malloc(sizeof *base);
    float *img = malloc(sizeof(float) * W * H * 3), *map = malloc(sizeof(float) * W * H);
    assert_true(q && base && img && map);
    make_base(base);
    make_noisy(base, q);
    to_ldr(q, img);
    rt_error err = {0};
    double mean = -1;
    assert_int_equal(rt_flip_ldr(img, img, W, H, NULL, map, &mean, &err), RT_OK);
    assert_true(mean == 0.0);
    for (int i = 0; i < W * H; i++)
        assert_true(map[i] == 0.0f);
    to_hdr(q, img);
    rt_flip_exposure used;
    assert_int_equal(rt_flip_hdr(img, img, W, H, NULL, map, &mean, &used, &err), RT_OK);
    assert_true(mean == 0.0);
    assert_true(used.start < used.stop && used.count >= 2);
    free(q);
    free(base);
    free(img);
    free(map);
}

static void test_flip_map_and_options(void **state)
{
    (void)state;
    qimage *cq = malloc(sizeof *cq), *rq = malloc(sizeof *rq);
    float *c = malloc(sizeof(float) * W * H * 3), *r = malloc(sizeof(float) * W * H * 3);
    float *map = malloc(sizeof(float) * W * H);
    assert_true(cq && rq && c && r && map);
    make_pair("blur", cq, rq);
    to_ldr(cq, c);
    to_ldr(rq, r);
    rt_error err = {0};
    double mean = -1, again = -1;
    assert_int_equal(rt_flip_ldr(c, r, W, H, NULL, map, &mean, &err), RT_OK);
    double s = 0;
    for (int i = 0; i < W * H; i++) {
        assert_true(map[i] >= 0.0f && map[i] <= 1.0f);
        s += map[i];
    }
    assert_near(s / (W * H), mean, 1e-12);
    /* the zero options are FLIP's defaults */
    rt_flip_options opt = {0};
    opt.ppd = RT_FLIP_DEFAULT_PPD;
    assert_int_equal(rt_flip_ldr(c, r, W, H, &opt, NULL, &again, &err), RT_OK);
    assert_true(again == mean);

    /* HDR-FLIP: the automatic exposures given back as fixed ones give the same result */
    to_hdr(cq, c);
    to_hdr(rq, r);
    rt_flip_exposure used;
    assert_int_equal(rt_flip_hdr(c, r, W, H, NULL, NULL, &mean, &used, &err), RT_OK);
    opt.fixed_exposure = true;
    opt.start_exposure = used.start;
    opt.stop_exposure = used.stop;
    opt.exposures = used.count;
    assert_int_equal(rt_flip_hdr(c, r, W, H, &opt, map, &again, NULL, &err), RT_OK);
    assert_true(again == mean);
    /* other tone mappers run and give other, plausible values */
    opt.fixed_exposure = false;
    opt.exposures = 0;
    for (int tm = RT_FLIP_TONEMAP_HABLE; tm <= RT_FLIP_TONEMAP_REINHARD; tm++) {
        opt.tonemapper = (rt_flip_tonemapper)tm;
        assert_int_equal(rt_flip_hdr(c, r, W, H, &opt, NULL, &again, NULL, &err), RT_OK);
        assert_true(again > 0.0 && again < 1.0);
    }

    /* bad input: a size, a ppd, an exposure range, a non-finite value */
    assert_int_equal(rt_flip_ldr(c, r, 0, H, NULL, NULL, &mean, &err), RT_ERR_INVALID);
    opt = (rt_flip_options){0};
    opt.ppd = -1;
    assert_int_equal(rt_flip_ldr(c, r, W, H, &opt, NULL, &mean, &err), RT_ERR_INVALID);
    opt = (rt_flip_options){0};
    opt.fixed_exposure = true;
    opt.start_exposure = 2;
    opt.stop_exposure = 1;
    assert_int_equal(rt_flip_hdr(c, r, W, H, &opt, NULL, &mean, NULL, &err), RT_ERR_INVALID);
    c[3 * (W * 5 + 7) + 1] = NAN;
    assert_int_equal(rt_flip_hdr(c, r, W, H, NULL, NULL, &mean, NULL, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "candidate image's pixel (7, 5)"));
    free(cq);
    free(rq);
    free(c);
    free(r);
    free(map);
}

static void test_flip_black_reference(void **state)
{
    (void)state;
    /* all-black reference (the reference implementation divides by zero
     * here): exposure 0, and a black candidate scores 0 */
    enum { N = 16 * 16 };
    static float black[N * 3], grey[N * 3];
    for (int i = 0; i < N * 3; i++)
        grey[i] = 0.5f;
    rt_error err = {0};
    double mean = -1;
    rt_flip_exposure used;
    assert_int_equal(rt_flip_hdr(black, black, 16, 16, NULL, NULL, &mean, &used, &err), RT_OK);
    assert_true(mean == 0.0 && used.start == 0.0f && used.stop == 0.0f);
    assert_int_equal(rt_flip_hdr(grey, black, 16, 16, NULL, NULL, &mean, &used, &err), RT_OK);
    assert_true(mean > 0.1 && mean <= 1.0);
}

static void test_srgb_encode_and_magma(void **state)
{
    (void)state;
    const float lin[9] = {-1.0f, 0.0f, 0.001f, 0.0031308f, 0.18f, 0.5f, 1.0f, 2.0f, 0.25f};
    float s[9];
    rt_flip_srgb_encode(lin, s, 3);
    assert_true(s[0] == 0.0f && s[1] == 0.0f);
    assert_near(s[2], 0.01292f, 1e-7f);
    assert_near(s[3], 0.0404500f, 1e-6f);
    assert_near(s[4], 0.4613561f, 1e-6f);
    assert_near(s[5], 0.7353570f, 1e-6f);
    assert_near(s[6], 1.0f, 1e-6f);
    assert_near(s[7], 1.0f, 1e-6f);
    rt_flip_srgb_encode(lin, s, 3); /* in place gives the same */
    float t[9];
    memcpy(t, lin, sizeof t);
    rt_flip_srgb_encode(t, t, 3);
    assert_memory_equal(s, t, sizeof s);

    float lo[3], hi[3], mid[3], nan_c[3];
    rt_flip_magma(0.0f, lo);
    rt_flip_magma(1.0f, hi);
    rt_flip_magma(0.5f, mid);
    rt_flip_magma(NAN, nan_c);
    assert_near(lo[0], 0.001462f, 1e-6f);   /* magma's first entry */
    assert_near(hi[1], 0.991438f, 1e-6f);   /* and last */
    assert_near(mid[0], 0.716387f + (127.5f - 128.0f) / 16.0f * (0.716387f - 0.613617f), 1e-5f);
    assert_memory_equal(nan_c, lo, sizeof lo);
}

/* A 512x512 LDR-FLIP (a checkerboard ramp and a noisy copy: the image
 * size where FLIP's filters and tiling are exercised in full) gives
 * flip-evaluator's value, 0.4297478 (tools/flip_reference.py --big prints
 * it); its time is printed (about 0.1 s; speed is measured by benchmarks,
 * never asserted in tests). */
static void test_flip_512_time(void **state)
{
    (void)state;
    enum { S = 512 };
    float *c = malloc(sizeof(float) * S * S * 3), *r = malloc(sizeof(float) * S * S * 3);
    assert_true(c && r);
    pcg32 rng = pcg32_seed(7, 1);
    for (int y = 0; y < S; y++)
        for (int x = 0; x < S; x++)
            for (int k = 0; k < 3; k++) {
                float v = (float)(((x / 16 + y / 16) & 1) * 128 + x / 4) / 256.0f;
                r[(y * S + x) * 3 + k] = v;
                c[(y * S + x) * 3 + k] = fminf(1.0f, v + (float)(pcg32_next(&rng) >> 24) / 1024.0f);
            }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    double mean;
    rt_error err = {0};
    assert_int_equal(rt_flip_ldr(c, r, S, S, NULL, NULL, &mean, &err), RT_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double sec = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("    512x512 LDR-FLIP: %.3f s (mean %.4f)\n", sec, mean);
    assert_near(mean, 0.4297478, FLIP_TOLERANCE);
    free(c);
    free(r);
}

/* ---- rt compare ---------------------------------------------------------------------------- */

typedef struct cmd_result {
    int status;
    char out[4096], errs[4096];
} cmd_result;

static void slurp(FILE *f, char *buf, size_t size)
{
    rewind(f);
    size_t n = fread(buf, 1, size - 1, f);
    buf[n] = '\0';
    fclose(f);
}

/* Runs rt compare with a NULL-terminated argument list (after "compare"). */
static cmd_result run_compare(const char *first, ...)
{
    char *argv[32];
    int argc = 0;
    argv[argc++] = (char *)"compare";
    va_list ap;
    va_start(ap, first);
    for (const char *a = first; a && argc < 31; a = va_arg(ap, const char *))
        argv[argc++] = (char *)a;
    va_end(ap);
    argv[argc] = NULL;
    cmd_result r;
    FILE *out = tmpfile(), *errs = tmpfile();
    assert_true(out && errs);
    r.status = rt_cmd_compare_to(argc, argv, out, errs);
    slurp(out, r.out, sizeof r.out);
    slurp(errs, r.errs, sizeof r.errs);
    return r;
}

/* The number after "key: " in text, NAN when absent. */
static double value_of(const char *text, const char *key)
{
    char pattern[64];
    snprintf(pattern, sizeof pattern, "%s: ", key);
    const char *p = strstr(text, pattern);
    return p ? strtod(p + strlen(pattern), NULL) : NAN;
}

static void write_pfm(const char *path, const float *rgb, int w, int h)
{
    rt_framebuffer fb;
    rt_error err = {0};
    assert_int_equal(rt_framebuffer_init(&fb, w, h, &err), RT_OK);
    memcpy(fb.rgb, rgb, sizeof(float) * 3 * (size_t)w * (size_t)h);
    if (rt_framebuffer_write(&fb, path, 1.0f, &err) != RT_OK)
        fail_msg("%s", err.message);
    rt_framebuffer_free(&fb);
}

static void test_rt_compare(void **state)
{
    (void)state;
    char dir[64];
    assert_true(test_make_dir(dir, sizeof dir, "compare"));
    char cand[256], ref[256], small[256], nan_img[256], map[256], hdr_map[256], missing[256];
    snprintf(cand, sizeof cand, "%s/cand.pfm", dir);
    snprintf(ref, sizeof ref, "%s/ref.pfm", dir);
    snprintf(small, sizeof small, "%s/small.pfm", dir);
    snprintf(nan_img, sizeof nan_img, "%s/nan.pfm", dir);
    snprintf(map, sizeof map, "%s/map.png", dir);
    snprintf(hdr_map, sizeof hdr_map, "%s/hdr-map.pfm", dir);
    snprintf(missing, sizeof missing, "%s/missing.pfm", dir);

    /* the HDR "noise" pair: rt compare's HDR-FLIP is flip-evaluator's value for it */
    qimage *cq = malloc(sizeof *cq), *rq = malloc(sizeof *rq);
    float *c = malloc(sizeof(float) * W * H * 3), *r = malloc(sizeof(float) * W * H * 3);
    assert_true(cq && rq && c && r);
    make_pair("noise", cq, rq);
    to_hdr(cq, c);
    to_hdr(rq, r);
    write_pfm(cand, c, W, H);
    write_pfm(ref, r, W, H);
    write_pfm(small, r, W / 2, H);
    c[3 * (W * 3 + 2)] = INFINITY;
    write_pfm(nan_img, c, W, H);
    rt_metrics m;
    rt_error err = {0};
    to_hdr(cq, c);
    assert_int_equal(rt_image_metrics(c, r, W, H, &m, &err), RT_OK);

    cmd_result res = run_compare(cand, ref, "--error-map", map, "--hdr-error-map", hdr_map, NULL);
    if (res.status != 0)
        fail_msg("rt compare: %d: %s", res.status, res.errs);
    const char *keys[] = {"MSE", "RMSE", "relMSE", "MAE", "mean (candidate)", "mean (reference)", "LDR-FLIP",
                          "HDR-FLIP"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (isnan(value_of(res.out, keys[i])))
            fail_msg("no '%s: ' line in:\n%s", keys[i], res.out);
    assert_near(value_of(res.out, "RMSE"), m.rmse, 1e-5 * m.rmse);
    assert_near(value_of(res.out, "relMSE"), m.relmse, 1e-5 * m.relmse);
    assert_near(value_of(res.out, "mean (reference)"), m.mean_reference[0], 1e-5);
    assert_near(value_of(res.out, "HDR-FLIP"), flip_cases[1].hdr, FLIP_TOLERANCE);
    double ldr = value_of(res.out, "LDR-FLIP"), rmse = value_of(res.out, "RMSE");
    assert_true(ldr > 0 && ldr < 1);
    struct stat st;
    assert_int_equal(stat(map, &st), 0);
    assert_true(st.st_size > 100);
    rt_framebuffer fb;
    assert_int_equal(rt_pfm_read(hdr_map, &fb, &err), RT_OK);
    double s = 0;
    for (int i = 0; i < W * H; i++)
        s += fb.rgb[3 * i];
    assert_near(s / (W * H), flip_cases[1].hdr, FLIP_TOLERANCE);
    rt_framebuffer_free(&fb);

    /* thresholds: met (0), missed (1, saying which) */
    char hi[32], lo[32];
    snprintf(hi, sizeof hi, "%g", rmse * 1.01);
    snprintf(lo, sizeof lo, "%g", ldr * 0.99);
    res = run_compare(cand, ref, "--max-rmse", hi, "--max-flip", "0.9", "--max-hdr-flip", "0.9", NULL);
    assert_int_equal(res.status, 0);
    res = run_compare(cand, ref, "--max-rmse", hi, "--max-flip", lo, NULL);
    assert_int_equal(res.status, 1);
    assert_non_null(strstr(res.errs, "--max-flip"));
    assert_null(strstr(res.errs, "--max-rmse"));
    res = run_compare(ref, ref, "--max-rmse", "0", "--max-flip", "0", "--max-hdr-flip", "0", NULL);
    assert_int_equal(res.status, 0);
    assert_true(value_of(res.out, "MSE") == 0 && value_of(res.out, "HDR-FLIP") == 0);
    res = run_compare(cand, ref, "--ppd", "30", NULL);
    assert_int_equal(res.status, 0);
    assert_near(value_of(res.out, "HDR-FLIP"), flip_cases[2].hdr, FLIP_TOLERANCE);

    /* bad input: exit 2 with a message naming the file */
    res = run_compare(cand, missing, NULL);
    assert_int_equal(res.status, 2);
    assert_non_null(strstr(res.errs, missing));
    res = run_compare(small, ref, NULL);
    assert_int_equal(res.status, 2);
    assert_non_null(strstr(res.errs, small));
    assert_non_null(strstr(res.errs, "48x64"));
    res = run_compare(nan_img, ref, NULL);
    assert_int_equal(res.status, 2);
    assert_non_null(strstr(res.errs, nan_img));
    assert_non_null(strstr(res.errs, "(2, 3)"));
    res = run_compare(cand, "tests/test_compare.c", NULL);
    assert_int_equal(res.status, 2);
    assert_non_null(strstr(res.errs, "test_compare.c"));
    assert_non_null(strstr(res.errs, "PFM"));
    /* flags */
    res = run_compare(cand, NULL);
    assert_int_equal(res.status, 2);
    res = run_compare(cand, ref, "--max-rmse", "x", NULL);
    assert_int_equal(res.status, 2);
    /* the one number syntax of every flag: no hexadecimal, blanks or signs of infinity */
    static const char *const not_numbers[] = {"0x1p-3", " 0.5", "0.5 ", "inf", "1e999", "+0x10", ".", "1e"};
    for (size_t i = 0; i < sizeof not_numbers / sizeof not_numbers[0]; i++) {
        res = run_compare(cand, ref, "--max-rmse", not_numbers[i], NULL);
        if (res.status != 2)
            fail_msg("--max-rmse '%s' was taken (status %d)", not_numbers[i], res.status);
        res = run_compare(cand, ref, "--ppd", not_numbers[i], NULL);
        assert_int_equal(res.status, 2);
    }
    res = run_compare(cand, ref, "--max-rmse", "1e3", "--ppd", "3.0e1", NULL);
    assert_int_equal(res.status, 0);
    res = run_compare(cand, ref, "--ppd", "0", NULL);
    assert_int_equal(res.status, 2);
    res = run_compare(cand, ref, "--max-flip", NULL);
    assert_int_equal(res.status, 2);
    res = run_compare(cand, ref, "--frobnicate", NULL);
    assert_int_equal(res.status, 2);
    res = run_compare(cand, ref, "--error-map", "/nonexistent-dir/map.png", NULL);
    assert_int_equal(res.status, 2);
    assert_non_null(strstr(res.errs, "/nonexistent-dir/map.png"));
    res = run_compare("--help", NULL);
    assert_int_equal(res.status, 0);
    assert_non_null(strstr(res.out, "usage: rt compare"));

    /* an error map over an image being compared (by another name too) is
     * refused before any work: the image stays as it was */
    char *before, *after;
    size_t nb, na;
    assert_int_equal(rt_read_file(cand, 0, &before, &nb, &err), RT_OK);
    char cand_again[300];
    snprintf(cand_again, sizeof cand_again, "%s/./cand.pfm", dir);
    res = run_compare(cand, ref, "--error-map", cand_again, NULL);
    assert_int_equal(res.status, 2);
    assert_non_null(strstr(res.errs, "is the image"));
    res = run_compare(cand, ref, "--hdr-error-map", ref, NULL);
    assert_int_equal(res.status, 2);
    res = run_compare(cand, ref, "--error-map", map, "--hdr-error-map", map, NULL);
    assert_int_equal(res.status, 2);
    assert_int_equal(rt_read_file(cand, 0, &after, &na, &err), RT_OK);
    assert_true(na == nb && memcmp(before, after, nb) == 0);
    free(before);
    free(after);

    test_remove_dir(dir);
    free(cq);
    free(rq);
    free(c);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_metrics_identical),
        cmocka_unit_test(test_metrics_constant_offset),
        cmocka_unit_test(test_metrics_by_hand),
        cmocka_unit_test(test_metrics_bad_input),
        cmocka_unit_test(test_flip_matches_flip_evaluator),
        cmocka_unit_test(test_flip_identical_is_zero),
        cmocka_unit_test(test_flip_map_and_options),
        cmocka_unit_test(test_flip_black_reference),
        cmocka_unit_test(test_srgb_encode_and_magma),
        cmocka_unit_test(test_flip_512_time),
        cmocka_unit_test(test_rt_compare),
    };
    return cmocka_run_group_tests_name("compare", tests, NULL, NULL);
}
