/* test_util.h - shared helpers for the cmocka tests.
 *
 * Tests include <cmocka.h> through this header. Paths: the repository root is
 * the working directory (make test runs there); shared assets are found at
 * $RT_SHARED (default ../shared), and tests that need them skip with a clear
 * message when they are absent.
 */
#ifndef RT_TEST_UTIL_H
#define RT_TEST_UTIL_H

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
 * false, with a note that the test is skipped, when it cannot be read. */
static inline bool test_read_cornell_reference(rt_framebuffer *ref)
{
    const char *path = test_shared_path("reference/cornell/reference.pfm");
    rt_error err;
    if (rt_pfm_read(path, ref, &err) != RT_OK) {
        fprintf(stderr, "note: %s not readable (set RT_SHARED); skipping\n", path);
        return false;
    }
    return true;
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

/* True when the shared assets exist; otherwise prints why the test is skipped. */
static inline int test_have_shared(void)
{
    struct stat st;
    const char *p = test_shared_path("assets/MANIFEST.md");
    if (stat(p, &st) == 0)
        return 1;
    fprintf(stderr, "note: shared assets not found at %s (set RT_SHARED); skipping\n", p);
    return 0;
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

/* A fresh scratch directory /tmp/rt_test_TAG_XXXXXX into dir (size >= 64);
 * false when it cannot be made. */
static inline int test_make_dir(char *dir, size_t size, const char *tag)
{
    snprintf(dir, size, "/tmp/rt_test_%s_XXXXXX", tag);
    return mkdtemp(dir) != NULL;
}

/* Removes a scratch directory made by test_make_dir with the files in it
 * (no subdirectories). */
static inline void test_remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[4200];
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) {
                snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
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

#endif
