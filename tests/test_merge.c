/* test_merge.c - the job stage's merge of parts at the library level
 * (rt/job/merge.h, rt/job/part.h) under what a hostile or careless farm
 * hands it (issue 25): parts whose layers share names but not channel
 * counts, a part image larger than its sidecar's region, the same file
 * under two names, sidecars claiming an image far larger than their
 * regions, and thousands of parts, which must cost no pairwise step (the
 * hash index's probe count is held to a linear bound; no clock). */
#include "test_util.h"

#include "rt/base/file.h"
#include "rt/base/key_index.h"
#include "rt/io/exr.h"
#include "rt/job/merge.h"
#include "rt/job/part.h"

static char dir[256];

static const char *in_dir(const char *name)
{
    static char buf[8][600];
    static int k;
    k = (k + 1) % 8;
    if (strlen(dir) + strlen(name) + 2 > sizeof buf[k])
        fail_msg("path too long: %s", name);
    memcpy(buf[k], dir, strlen(dir));
    buf[k][strlen(dir)] = '/';
    memcpy(buf[k] + strlen(dir) + 1, name, strlen(name) + 1);
    return buf[k];
}

static int setup(void **state)
{
    (void)state;
    return test_make_dir(dir, sizeof dir, "merge") ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(dir);
    return 0;
}

/* A part of a W x H render of 4 spp: region [x0, x1) x [y0, y1), every
 * sample of every pixel summing to (1, 2, 3) and counted; `layers` layers
 * named and sized as given (NULL: none). */
static void write_part(const char *path, int W, int H, int x0, int y0, int x1, int y1, int layers,
                       const char *const *names, const int *channels)
{
    rt_part_info info;
    memset(&info, 0, sizeof info);
    snprintf(info.version, sizeof info.version, "test");
    snprintf(info.scene, sizeof info.scene, "s.txt");
    info.scene_hash = 1;
    snprintf(info.settings, sizeof info.settings, "samples 4\n");
    info.width = W;
    info.height = H;
    info.x0 = x0;
    info.y0 = y0;
    info.x1 = x1;
    info.y1 = y1;
    info.spp = 4;
    info.s_begin = 0;
    info.s_end = 4;
    info.block_first = 0;
    info.block_count = 1;
    info.exposure = 1.0f;
    info.layer_count = layers;
    size_t n = (size_t)(x1 - x0) * (size_t)(y1 - y0);
    float *sum = calloc(3 * n, sizeof(float)), *block = malloc(3 * n * sizeof(float));
    uint32_t *good = malloc(n * sizeof(uint32_t));
    float *layer[RT_PART_MAX_LAYERS] = {NULL};
    assert_true(sum && block && good);
    for (size_t i = 0; i < n; i++) {
        block[3 * i] = 1.0f;
        block[3 * i + 1] = 2.0f;
        block[3 * i + 2] = 3.0f;
        good[i] = 4;
    }
    for (int k = 0; k < layers; k++) {
        snprintf(info.layer_name[k], sizeof info.layer_name[k], "%s", names[k]);
        info.layer_channels[k] = channels[k];
        layer[k] = calloc((size_t)channels[k] * n, sizeof(float));
        assert_non_null(layer[k]);
    }
    const float *blocks[1] = {block};
    rt_error err = {0};
    if (rt_part_write(path, &info, sum, blocks, good, (const float *const *)layer, NULL, &err) != RT_OK)
        fail_msg("%s", err.message);
    free(sum);
    free(block);
    free(good);
    for (int k = 0; k < layers; k++)
        free(layer[k]);
}

/* Replaces the first `from` in the sidecar of part `path` by `to`. */
static void edit_sidecar(const char *path, const char *from, const char *to)
{
    char side[700], *text;
    size_t size;
    rt_error err;
    snprintf(side, sizeof side, "%s.json", path);
    assert_int_equal(rt_read_file(side, 0, &text, &size, &err), RT_OK);
    char *at = strstr(text, from), out[20000];
    assert_non_null(at);
    snprintf(out, sizeof out, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
    free(text);
    test_write_file(side, out, strlen(out));
}

/* Two parts with layers of the same names but other channel counts are not
 * parts of one render: the merge read the one's layer with the other's
 * stride (a heap over-read). Refused when comparing the parts, and a
 * sidecar whose layer is not the size rt writes it is refused when read. */
static void test_layer_layout_compared(void **state)
{
    (void)state;
    rt_part_info a, b;
    memset(&a, 0, sizeof a);
    a.layer_count = 2;
    snprintf(a.layer_name[0], sizeof a.layer_name[0], "albedo");
    snprintf(a.layer_name[1], sizeof a.layer_name[1], "depth");
    a.layer_channels[0] = 3;
    a.layer_channels[1] = 1;
    b = a;
    char why[1200];
    assert_null(rt_part_mismatch(&a, &b, why, sizeof why));
    b.layer_channels[1] = 3;
    const char *m = rt_part_mismatch(&a, &b, why, sizeof why);
    assert_non_null(m);
    assert_non_null(strstr(m, "layer 2 is depth of 1 channel, not depth of 3"));

    /* through files: the first part's albedo has 3 channels, the second's 1 */
    static const char *const names[1] = {"albedo"};
    static const int three[1] = {3}, one[1] = {1};
    write_part(in_dir("l0.exr"), 4, 2, 0, 0, 4, 1, 1, names, three);
    write_part(in_dir("l1.exr"), 4, 2, 0, 1, 4, 2, 1, names, one);
    rt_merge mg;
    rt_error err = {0};
    assert_int_equal(rt_merge_init(&mg, 2, &err), RT_OK);
    assert_int_equal(rt_merge_add(&mg, in_dir("l0.exr"), &err), RT_OK);
    rt_result r = rt_merge_add(&mg, in_dir("l1.exr"), &err);
    test_expect_failure(r, &err, RT_ERR_INVALID, "l1.exr.json", "\"layers\" entries must be");
    rt_merge_free(&mg);
    /* a layer rt never writes, or one twice */
    static const char *const variance[1] = {"variance"};
    write_part(in_dir("l3.exr"), 4, 2, 0, 1, 4, 2, 1, variance, three);
    write_part(in_dir("l2.exr"), 4, 2, 0, 1, 4, 2, 1, names, three);
    edit_sidecar(in_dir("l2.exr"), "[[\"albedo\", 3]]", "[[\"albedo\", 3], [\"albedo\", 3]]");
    rt_part p;
    test_expect_failure(rt_part_read(in_dir("l2.exr"), &p, &err), &err, RT_ERR_INVALID, "l2.exr.json",
                        "each at most once");
    test_expect_failure(rt_part_read(in_dir("l3.exr"), &p, &err), &err, RT_ERR_INVALID, "l3.exr.json",
                        "\"layers\" entries must be");
}

/* The EXR writer given one layer name twice: the library refuses the
 * second channel of that name while holding the context's lock, and the
 * error callback took the lock again, so the write hung for ever. Now
 * refused with a message before the library is called (an alarm turns a
 * hang into a failure). */
static void test_exr_channel_twice_refused(void **state)
{
    (void)state;
    alarm(60);
    float px[3 * 4] = {0};
    rt_exr_layer layers[2] = {{"albedo", 3, px}, {"albedo", 3, px}};
    FILE *f = fopen(in_dir("twice.exr"), "wb");
    assert_non_null(f);
    rt_error err = {0};
    rt_result r = rt_exr_write(f, "twice.exr", 2, 2, layers, 2, false, &err);
    fclose(f);
    test_expect_failure(r, &err, RT_ERR_INVALID, "twice.exr", "channel albedo.R given twice");
    /* an error inside the library while writing (a size it refuses) returns too */
    f = fopen(in_dir("zero.exr"), "wb");
    assert_non_null(f);
    r = rt_exr_write(f, "zero.exr", 0, 2, layers, 1, false, &err);
    fclose(f);
    assert_int_not_equal(r, RT_OK);
    assert_non_null(strstr(err.message, "zero.exr"));
    alarm(0);
}

/* A part image is read at the size its sidecar's region says, refused
 * before its pixels are decoded when it is another size. */
static void test_part_image_bounded_by_sidecar(void **state)
{
    (void)state;
    write_part(in_dir("b.exr"), 64, 64, 0, 0, 64, 64, 0, NULL, NULL);
    edit_sidecar(in_dir("b.exr"), "\"region\": [0, 0, 64, 64]", "\"region\": [0, 0, 2, 2]");
    rt_part p;
    rt_error err = {0};
    test_expect_failure(rt_part_read(in_dir("b.exr"), &p, &err), &err, RT_ERR_INVALID, "b.exr",
                        "the image is 64x64, not the 2x2 expected");
}

/* A sidecar's hashes are exactly 16 hex digits: strtoull took a sign,
 * blanks and "0x", so " -0x00000000001" passed for a hash. */
static void test_sidecar_hashes_strict(void **state)
{
    (void)state;
    write_part(in_dir("h.exr"), 4, 2, 0, 0, 4, 2, 0, NULL, NULL);
    edit_sidecar(in_dir("h.exr"), "\"scene_fnv1a64\": \"0000000000000001\"", "\"scene_fnv1a64\": \"-x00000000000001\"");
    rt_part p;
    rt_error err = {0};
    test_expect_failure(rt_part_read(in_dir("h.exr"), &p, &err), &err, RT_ERR_INVALID, "h.exr.json",
                        "\"scene_fnv1a64\" missing or not 16 hex digits");
    edit_sidecar(in_dir("h.exr"), "\"scene_fnv1a64\": \"-x00000000000001\"", "\"scene_fnv1a64\": \" 0x0000000000001\"");
    test_expect_failure(rt_part_read(in_dir("h.exr"), &p, &err), &err, RT_ERR_INVALID, "h.exr.json",
                        "\"scene_fnv1a64\" missing or not 16 hex digits");
    edit_sidecar(in_dir("h.exr"), "\"scene_fnv1a64\": \" 0x0000000000001\"", "\"scene_fnv1a64\": \"000000000000000F\"");
    assert_int_equal(rt_part_read(in_dir("h.exr"), &p, &err), RT_OK);
    assert_true(p.info.scene_hash == 15);
    rt_part_free(&p);
}

/* Sidecars may claim a 30000x30000 image around one pixel of data: refused
 * before the image (and an int a pixel for the gap report) is allocated. */
static void test_cover_checked_before_allocating(void **state)
{
    (void)state;
    write_part(in_dir("c.exr"), 4, 4, 0, 0, 1, 1, 0, NULL, NULL);
    edit_sidecar(in_dir("c.exr"), "\"width\": 4,\n  \"height\": 4", "\"width\": 30000,\n  \"height\": 30000");
    rt_merge mg;
    rt_error err = {0};
    assert_int_equal(rt_merge_init(&mg, 1, &err), RT_OK);
    assert_int_equal(rt_merge_add(&mg, in_dir("c.exr"), &err), RT_OK);
    assert_int_equal(rt_merge_check_cover(&mg, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "cover 1 of the 30000x30000 image's 900000000 pixels"));
    rt_framebuffer fb = {0};
    assert_int_equal(rt_merge_image(&mg, &fb, NULL, &err), RT_ERR_INVALID); /* checks it itself too */
    rt_merge_free(&mg);
}

/* The hash index: 200 000 keys in runs (as inodes come) with every key
 * then added again; each second add finds the first, and the probes stay
 * within a small constant a key (linear probing at load 1/2 averages about
 * 2.5 a miss, 1.5 a hit), where a pairwise check makes n^2/2 comparisons. */
static void test_key_index_linear(void **state)
{
    (void)state;
    enum { N = 200000 };
    rt_key_index ix;
    assert_true(rt_key_index_init(&ix, N));
    for (int i = 0; i < N; i++) {
        uint64_t key[2] = {2049, 1000000 + (uint64_t)i};
        assert_int_equal(rt_key_index_add(&ix, key, i), -1);
    }
    for (int i = 0; i < N; i++) {
        uint64_t key[2] = {2049, 1000000 + (uint64_t)i};
        if (rt_key_index_add(&ix, key, N + i) != i)
            fail_msg("key %d not found again", i);
    }
    uint64_t extra[2] = {1, 2};
    assert_int_equal(rt_key_index_add(&ix, extra, 0), -2); /* full: refused, not overrun */
    fprintf(stderr, "key index: %zu probes for %d adds\n", ix.probes, 2 * N + 1);
    assert_true(ix.probes <= (size_t)4 * (2 * N + 1));
    rt_key_index_free(&ix);
}

/* 3000 one-row parts merge into the image they tile, each pixel the
 * parts' sums resolved; the file and region indexes did a bounded number
 * of probes a part, and a part given again under another name (a hard
 * link) is found by its device and inode. */
static void test_thousands_of_parts(void **state)
{
    (void)state;
    enum { N = 3000, W = 3 };
    char name[32];
    for (int y = 0; y < N; y++) {
        snprintf(name, sizeof name, "r%d.exr", y);
        write_part(in_dir(name), W, N, 0, y, W, y + 1, 0, NULL, NULL);
    }
    rt_merge mg;
    rt_error err = {0};
    assert_int_equal(rt_merge_init(&mg, N + 1, &err), RT_OK);
    for (int y = N - 1; y >= 0; y--) { /* any order */
        snprintf(name, sizeof name, "r%d.exr", y);
        if (rt_merge_add(&mg, in_dir(name), &err) != RT_OK)
            fail_msg("%s", err.message);
    }
    assert_int_equal(mg.groups, N);
    fprintf(stderr, "%d parts: %zu file probes, %zu region probes\n", N, mg.files.probes, mg.regions.probes);
    assert_true(mg.files.probes <= 4 * N);
    assert_true(mg.regions.probes <= 4 * N);
    rt_framebuffer fb;
    assert_int_equal(rt_framebuffer_init(&fb, W, N, &err), RT_OK);
    assert_int_equal(rt_merge_check_cover(&mg, &err), RT_OK);
    if (rt_merge_image(&mg, &fb, NULL, &err) != RT_OK)
        fail_msg("%s", err.message);
    for (size_t i = 0; i < (size_t)W * N; i++)
        if (fb.rgb[3 * i] != 0.25f || fb.rgb[3 * i + 1] != 0.5f || fb.rgb[3 * i + 2] != 0.75f)
            fail_msg("pixel %zu is (%g, %g, %g), not (0.25, 0.5, 0.75)", i, fb.rgb[3 * i], fb.rgb[3 * i + 1],
                     fb.rgb[3 * i + 2]);
    rt_framebuffer_free(&fb);
    /* the part of row 1234 again, as a hard link with its own sidecar */
    assert_int_equal(link(in_dir("r1234.exr"), in_dir("again.exr")), 0);
    assert_int_equal(link(in_dir("r1234.exr.json"), in_dir("again.exr.json")), 0);
    rt_result r = rt_merge_add(&mg, in_dir("again.exr"), &err);
    test_expect_failure(r, &err, RT_ERR_INVALID, "again.exr", "is given twice (also as");
    assert_non_null(strstr(err.message, "r1234.exr"));
    rt_merge_free(&mg);
    for (int y = 0; y < N; y++) {
        snprintf(name, sizeof name, "r%d.exr", y);
        unlink(in_dir(name));
        snprintf(name, sizeof name, "r%d.exr.json", y);
        unlink(in_dir(name));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layer_layout_compared),
        cmocka_unit_test(test_exr_channel_twice_refused),
        cmocka_unit_test(test_part_image_bounded_by_sidecar),
        cmocka_unit_test(test_cover_checked_before_allocating),
        cmocka_unit_test(test_sidecar_hashes_strict),
        cmocka_unit_test(test_key_index_linear),
        cmocka_unit_test(test_thousands_of_parts),
    };
    return cmocka_run_group_tests_name("merge", tests, setup, teardown);
}
