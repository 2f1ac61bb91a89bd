/* test_util.h - shared helpers for the cmocka tests.
 *
 * Tests include <cmocka.h> through this header. Paths: the repository root is
 * the working directory (make test runs there); shared assets are found at
 * $RT_SHARED (default ../shared). A test that cannot run calls skip() with
 * the reason printed first (test_require_shared, test_require_cornell_reference,
 * test_skip_in_sanitizer_build): cmocka lists it by name as SKIPPED, tests/run.sh
 * counts it, and CI fails on any skip outside the sanitizer builds' named
 * list (the Makefile's SANITIZER_SKIPS). Never `return` early from a test that
 * checked nothing: that counts as a pass.
 */
#ifndef RT_TEST_UTIL_H
#define RT_TEST_UTIL_H

#include <ctype.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <math.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "rt/io/image_read.h"

/* Path of a file under the shared directory, in a static buffer (one at a time). */
static inline const char *test_shared_path(const char *rel)
{
    static char buf[4096];
    const char *root = getenv("RT_SHARED");
    snprintf(buf, sizeof buf, "%s/%s", root && *root ? root : "../shared", rel);
    return buf;
}

/* The shared Mitsuba reference of the Cornell box (512x512) into *ref;
 * the calling test is skipped, saying why, when it cannot be read. */
static inline void test_require_cornell_reference(rt_framebuffer *ref)
{
    const char *path = test_shared_path("reference/cornell/reference.pfm");
    rt_error err;
    if (rt_pfm_read(path, ref, &err) != RT_OK) {
        fprintf(stderr, "skip: %s not readable (set RT_SHARED): %s\n", path, err.message);
        skip();
    }
}

/* The mean of channel c over the 8x8 block (x, y) of the 512x512 Cornell
 * reference: what pixel (x, y) of a 64x64 render of the same camera covers. */
static inline double test_cornell_block(const rt_framebuffer *ref, int x, int y, int c)
{
    double r = 0.0;
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++)
            r += ref->rgb[3 * ((size_t)(8 * y + j) * 512 + (size_t)(8 * x + i)) + (size_t)c];
    return r / 64.0;
}

/* RMSE of a 64x64 image against the Cornell reference box-averaged over
 * 8x8 blocks (test_cornell_block), and the image means of both. */
static inline double test_cornell_block_rmse(const rt_framebuffer *img, const rt_framebuffer *ref, double mine[3],
                                             double theirs[3])
{
    double se = 0.0;
    for (int c = 0; c < 3; c++)
        mine[c] = theirs[c] = 0.0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++)
            for (int c = 0; c < 3; c++) {
                double r = test_cornell_block(ref, x, y, c);
                double v = img->rgb[3 * ((size_t)y * 64 + (size_t)x) + (size_t)c];
                se += (v - r) * (v - r);
                mine[c] += v / 4096.0;
                theirs[c] += r / 4096.0;
            }
    return sqrt(se / (64.0 * 64.0 * 3.0));
}

/* A load of the file `name` that must have failed with `code` and a
 * message naming the file and containing `what`; what it got is shown when
 * it did not. */
static inline void test_expect_failure(rt_result r, const rt_error *err, rt_result code, const char *name,
                                       const char *what)
{
    if (r != code || !strstr(err->message, name) || !strstr(err->message, what))
        fprintf(stderr, "%s: got %s \"%s\", wanted %s containing \"%s\"\n", name, rt_result_name(r), err->message,
                rt_result_name(code), what);
    assert_int_equal(r, code);
    assert_non_null(strstr(err->message, name));
    assert_non_null(strstr(err->message, what));
}

/* True when the shared assets exist (without saying anything). */
static inline int test_have_shared(void)
{
    struct stat st;
    return stat(test_shared_path("assets/MANIFEST.md"), &st) == 0;
}

/* Skips the calling test, saying why, unless the shared assets are there. */
static inline void test_require_shared(void)
{
    if (!test_have_shared()) {
        fprintf(stderr, "skip: shared assets not found at %s (set RT_SHARED)\n",
                test_shared_path("assets/MANIFEST.md"));
        skip();
    }
}

/* 1 in a build with AddressSanitizer or ThreadSanitizer (the tests are built
 * with the same flags as rt and the library: make asan, make tsan). */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define TEST_SANITIZED 1
#endif
#endif
#ifndef TEST_SANITIZED
#define TEST_SANITIZED 0
#endif

/* Skips the calling test in a sanitizer build, saying why: for the few
 * tests a sanitizer runtime cannot run (each is named in the Makefile's
 * SANITIZER_SKIPS, and any other skip there fails CI). Decided by how the
 * test was built, never by what the code under test reports. */
static inline void test_skip_in_sanitizer_build(const char *why)
{
    if (TEST_SANITIZED) {
        fprintf(stderr, "skip: not in a sanitizer build: %s\n", why);
        skip();
    }
}

/* Writes `text` to a fresh temporary file and returns its path (static buffer per call site's copy). */
static inline void test_write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    if (size)
        assert_int_equal(fwrite(data, 1, size, f), size);
    fclose(f);
}

/* A whole file's bytes, NUL-terminated (the caller frees them); fails the
 * test when it cannot be read. */
static inline char *test_slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot open %s", path);
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    assert_non_null(buf);
    for (size_t got; (got = fread(buf + n, 1, cap - n, f)) > 0;) {
        n += got;
        if (n == cap) {
            char *nb = realloc(buf, 2 * cap + 1);
            assert_non_null(nb);
            buf = nb;
            cap *= 2;
        }
    }
    fclose(f);
    buf[n] = 0;
    *size = n;
    return buf;
}

/* Files a and b hold the same bytes. */
static inline void test_assert_same_bytes(const char *a, const char *b)
{
    size_t na, nb;
    char *x = test_slurp(a, &na), *y = test_slurp(b, &nb);
    if (na != nb || memcmp(x, y, na) != 0)
        fail_msg("%s and %s differ", a, b);
    free(x);
    free(y);
}

/* A shipped scene copied to dst with lines appended (settings that make it
 * small and fast); false when either file cannot be opened. */
static inline int test_copy_scene_with(const char *src, const char *dst, const char *extra)
{
    FILE *in = fopen(src, "rb"), *f = fopen(dst, "wb");
    if (!in || !f) {
        if (in)
            fclose(in);
        if (f)
            fclose(f);
        return 0;
    }
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        fwrite(buf, 1, n, f);
    fputs(extra, f);
    fclose(in);
    return fclose(f) == 0;
}

/* The tests' one scratch-directory helper: a fresh directory
 * /tmp/rt_test_TAG_XXXXXX into dir (size >= 64), made in a group setup or
 * a test, and test_remove_dir in the teardown; false when it cannot be
 * made. */
static inline int test_make_dir(char *dir, size_t size, const char *tag)
{
    snprintf(dir, size, "/tmp/rt_test_%s_XXXXXX", tag);
    return mkdtemp(dir) != NULL;
}

/* Removes a scratch directory made by test_make_dir with everything in it
 * (subdirectories too; symbolic links are removed, not followed). */
static inline void test_remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[4200];
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) {
                int n = snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
                struct stat st;
                if (n < 0 || (size_t)n >= sizeof p)
                    continue; /* no such name in a scratch directory */
                if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
                    test_remove_dir(p);
                else
                    unlink(p);
            }
        closedir(d);
    }
    rmdir(dir);
}

/* Standard base64 (RFC 4648) of n bytes, for data: URIs in written glTF
 * files; the caller frees it. */
static inline char *test_base64(const void *data, size_t n)
{
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const uint8_t *p = data;
    char *out = malloc(4 * ((n + 2) / 3) + 1);
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t w = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        out[o++] = al[w >> 18 & 63];
        out[o++] = al[w >> 12 & 63];
        out[o++] = i + 1 < n ? al[w >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? al[w & 63] : '=';
    }
    out[o] = 0;
    return out;
}

/* A small deterministic PRNG for test data (xorshift64*). */
typedef struct test_rng { uint64_t s; } test_rng;
static inline uint64_t test_rng_next(test_rng *r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return r->s * 2685821657736338717ull;
}
static inline float test_rng_float(test_rng *r) /* [0, 1) */
{
    return (float)(test_rng_next(r) >> 40) * (1.0f / 16777216.0f);
}

/* The shared benchmark models, from bench/MANIFEST.md's table rows
 * ("| Name | `path` | ..."): up to cap of them into out; 0 when the
 * manifest is not there. */
typedef struct test_bench_model {
    char name[128];
    char glb[512];
} test_bench_model;

static inline size_t test_bench_models(test_bench_model *out, size_t cap)
{
    FILE *f = fopen(test_shared_path("bench/MANIFEST.md"), "r");
    if (!f)
        return 0;
    char line[2048];
    size_t n = 0;
    while (n < cap && fgets(line, sizeof line, f)) {
        if (strncmp(line, "| ", 2) != 0)
            continue;
        const char *p = line + 2, *q = p;
        while (isalnum((unsigned char)*q) || *q == '_')
            q++;
        if (q == p || strncmp(q, " | `", 4) != 0)
            continue;
        const char *g = q + 4, *ge = strchr(g, '`');
        if (!ge || (size_t)(q - p) >= sizeof out[n].name || (size_t)(ge - g) >= sizeof out[n].glb)
            continue;
        memcpy(out[n].name, p, (size_t)(q - p));
        out[n].name[q - p] = '\0';
        memcpy(out[n].glb, g, (size_t)(ge - g));
        out[n].glb[ge - g] = '\0';
        n++;
    }
    fclose(f);
    return n;
}

#endif
