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

#include "rt/image/compare.h"
#include "rt/image/flip.h"


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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flip_matches_flip_evaluator),
    };
    return cmocka_run_group_tests_name("compare", tests, NULL, NULL);
}
