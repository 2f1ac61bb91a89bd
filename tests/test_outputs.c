/* test_outputs.c - what `rt` writes when some output cannot be written, and
 * what it allocates for inputs that cannot fill what they claim (issue 25,
 * classes 2 and 5), through the real ./rt (RT_BIN) in a scratch directory:
 *
 * - every file a render writes (the image, AOV files, NAME.partial.EXT, a
 *   part's sidecar, --part-out's files) is checked before rendering: one
 *   that cannot be written (a directory in its place) is exit status 2
 *   naming it, with every earlier file byte-identical;
 * - a file that turns out unwritable only at the write (a PFM part's block
 *   file, which depends on the samples reached) fails the whole write:
 *   the files written before it are not renamed over the earlier ones, and
 *   no temporary file is left;
 * - a few hundred bytes claiming 10^8 pixels (an EXR header; a part
 *   sidecar's image size) make `rt convert`, `rt compare` and `rt merge`
 *   exit 2 at once, with a peak resident size (getrusage of the child)
 *   far below what the claim would take. The bound is generous: it only
 *   has to tell "the header's claim was allocated" (>= 400 MB) from "it
 *   was not". */
#define _DEFAULT_SOURCE /* wait4 */
#include "test_util.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>

static char dir[256];
static char err_text[16384];
static long child_maxrss_kb; /* of the last run */
static char scene_path[600];  /* the scene every test renders */

static const char *rt_bin(void)
{
    const char *b = getenv("RT_BIN");
    return b && *b ? b : "./rt";
}

static const char *in_dir(const char *name)
{
    static char buf[16][600];
    static int k;
    k = (k + 1) % 16;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

/* Runs rt with the NULL-terminated args; its stderr in err_text, its peak
 * resident size in child_maxrss_kb; the exit status (-1: killed). */
static int run(const char *const *args)
{
    const char *argv[32];
    int n = 0;
    argv[n++] = rt_bin();
    for (int i = 0; args[i] && n < 31; i++)
        argv[n++] = args[i];
    argv[n] = NULL;
    const char *errs = in_dir("stderr.txt");
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int e = open(errs, O_WRONLY | O_CREAT | O_TRUNC, 0644), nul = open("/dev/null", O_RDWR);
        if (e < 0 || nul < 0)
            _exit(127);
        dup2(nul, 0);
        dup2(nul, 1);
        dup2(e, 2);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    int st = 0;
    struct rusage ru;
    while (wait4(pid, &st, 0, &ru) < 0 && errno == EINTR)
        ;
    child_maxrss_kb = ru.ru_maxrss;
    FILE *f = fopen(errs, "rb");
    size_t got = f ? fread(err_text, 1, sizeof err_text - 1, f) : 0;
    err_text[got] = 0;
    if (f)
        fclose(f);
    int status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    if (status == 127)
        fail_msg("could not run %s", rt_bin());
    return status;
}

#define RUN(...) run((const char *const[]){__VA_ARGS__, NULL})
#define RUN_OK(...)                                                                                                    \
    do {                                                                                                               \
        if (RUN(__VA_ARGS__) != 0)                                                                                     \
            fail_msg("rt failed: %s", err_text);                                                                       \
    } while (0)

static void copy(const char *from, const char *to)
{
    size_t n;
    char *t = test_slurp(from, &n);
    test_write_file(to, t, n);
    free(t);
}

/* No .rt-tmp file is left in the scratch directory. */
static void assert_no_temp_files(void)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)))
        if (strncmp(e->d_name, ".rt-tmp", 7) == 0)
            fail_msg("temporary file %s left", e->d_name);
    closedir(d);
}

static int setup(void **state)
{
    (void)state;
    if (!test_make_dir(dir, sizeof dir, "outputs") || access(rt_bin(), X_OK) != 0)
        return -1;
    snprintf(scene_path, sizeof scene_path, "%s/s.txt", dir);
    /* the glass Cornell box, tiny */
    if (!test_copy_scene_with("scenes/glass-cornell.txt", scene_path, "\nresolution 12 8\nsamples 4\nintegrator path\nseed 5\n"))
        return -1;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(dir);
    return 0;
}

/* A render refuses, before rendering, an output set with any file it
 * cannot write; the earlier files stay as they were. */
static void test_every_output_checked_before_rendering(void **state)
{
    (void)state;
    const char *scene = scene_path;
    /* a part whose sidecar path is a directory: the earlier part kept whole */
    RUN_OK("-q", "--part", "0/2", "-o", in_dir("p.exr"), scene);
    copy(in_dir("p.exr"), in_dir("p-was.exr"));
    copy(in_dir("p.exr.json"), in_dir("p-was.exr.json"));
    assert_int_equal(rename(in_dir("p.exr.json"), in_dir("side-was.json")), 0);
    assert_int_equal(mkdir(in_dir("p.exr.json"), 0755), 0);
    assert_int_equal(RUN("-q", "--part", "1/2", "-o", in_dir("p.exr"), scene), 2);
    assert_non_null(strstr(err_text, "p.exr.json: is a directory"));
    test_assert_same_bytes(in_dir("p.exr"), in_dir("p-was.exr"));
    rmdir(in_dir("p.exr.json"));
    /* --part-out's sidecar likewise, the main output too */
    RUN_OK("-q", "-o", in_dir("img.png"), scene);
    copy(in_dir("img.png"), in_dir("img-was.png"));
    assert_int_equal(mkdir(in_dir("po.exr.json"), 0755), 0);
    assert_int_equal(RUN("-q", "--part-out", in_dir("po.exr"), "-o", in_dir("img.png"), scene), 2);
    assert_non_null(strstr(err_text, "po.exr.json: is a directory"));
    test_assert_same_bytes(in_dir("img.png"), in_dir("img-was.png"));
    /* an AOV file, and the partial image a stopped tiled render would write */
    assert_int_equal(mkdir(in_dir("img.depth.pfm"), 0755), 0);
    assert_int_equal(RUN("-q", "--aov", "albedo,depth", "-o", in_dir("img.png"), scene), 2);
    assert_non_null(strstr(err_text, "img.depth.pfm: is a directory"));
    test_assert_same_bytes(in_dir("img.png"), in_dir("img-was.png"));
    assert_int_equal(access(in_dir("img.albedo.pfm"), F_OK), -1); /* not written either */
    assert_int_equal(mkdir(in_dir("img.partial.png"), 0755), 0);
    assert_int_equal(RUN("-q", "-o", in_dir("img.png"), scene), 2);
    if (!strstr(err_text, "img.partial.png: is a directory"))
        fail_msg("%s", err_text);
    test_assert_same_bytes(in_dir("img.png"), in_dir("img-was.png"));
    assert_no_temp_files();
}

/* A PFM part's block file depends on the samples reached, so it is checked
 * at the write: a directory there fails the write after the counts and
 * before the image, and neither replaces the earlier part's. */
static void test_failed_write_replaces_nothing(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "--part", "0/2", "-o", in_dir("q.pfm"), scene);
    copy(in_dir("q.pfm"), in_dir("q-was.pfm"));
    copy(in_dir("q.count.pfm"), in_dir("q-was.count.pfm"));
    copy(in_dir("q.pfm.json"), in_dir("q-was.pfm.json"));
    assert_int_equal(rename(in_dir("q.block.0.pfm"), in_dir("q-was.block.0.pfm")), 0);
    assert_int_equal(mkdir(in_dir("q.block.0.pfm"), 0755), 0);
    assert_int_equal(RUN("-q", "--part", "1/2", "-o", in_dir("q.pfm"), scene), 2);
    assert_non_null(strstr(err_text, "q.block.0.pfm: is a directory"));
    test_assert_same_bytes(in_dir("q.pfm"), in_dir("q-was.pfm"));
    test_assert_same_bytes(in_dir("q.count.pfm"), in_dir("q-was.count.pfm")); /* written before the block: not placed */
    test_assert_same_bytes(in_dir("q.pfm.json"), in_dir("q-was.pfm.json"));
    assert_no_temp_files();
}

/* Sets an EXR's data and display windows to w x h (its chunk table stays). */
static void set_windows(char *bytes, size_t size, int w, int h)
{
    static const char *const names[2] = {"dataWindow", "displayWindow"};
    for (int k = 0; k < 2; k++) {
        char *at = NULL;
        for (size_t i = 0; i + strlen(names[k]) + 1 < size && !at; i++)
            if (memcmp(bytes + i, names[k], strlen(names[k]) + 1) == 0)
                at = bytes + i;
        assert_non_null(at);
        at += strlen(names[k]) + 1 + strlen("box2i") + 1 + 4;
        int32_t box[4] = {0, 0, w - 1, h - 1};
        for (int c = 0; c < 4; c++)
            for (int b = 0; b < 4; b++)
                at[4 * c + b] = (char)((uint32_t)box[c] >> (8 * b));
    }
}

#define SMALL_PEAK_KB (200L * 1024) /* 10^8 pixels of the smallest buffer rt would make are >= 400 MB */

static void expect_refused_small(const char *what)
{
    if (child_maxrss_kb > SMALL_PEAK_KB)
        fail_msg("%s: peak resident size %ld KB, over %ld KB", what, child_maxrss_kb, SMALL_PEAK_KB);
}

/* Tiny files claiming 10^8 pixels: exit 2 at once, nothing like the claim
 * allocated. */
static void test_tiny_files_claiming_huge_images(void **state)
{
    (void)state;
    if (TEST_SANITIZED) /* the sanitizer runtime's own shadow memory is resident; the library tests hold there */
        test_skip_in_sanitizer_build("a sanitizer's shadow memory makes peak RSS meaningless");
    const char *scene = scene_path;
    RUN_OK("-q", "-o", in_dir("small.exr"), scene);
    size_t n;
    char *bytes = test_slurp(in_dir("small.exr"), &n);
    assert_true(n < 4096);
    set_windows(bytes, n, 10000, 10000);
    test_write_file(in_dir("huge.exr"), bytes, n);
    free(bytes);
    assert_int_equal(RUN("convert", in_dir("huge.exr"), in_dir("out.pfm")), 2);
    assert_non_null(strstr(err_text, "huge.exr"));
    expect_refused_small("rt convert");
    assert_int_equal(RUN("compare", in_dir("huge.exr"), in_dir("small.exr")), 2);
    assert_non_null(strstr(err_text, "huge.exr"));
    expect_refused_small("rt compare");
    /* a part of one pixel whose sidecar says the image is 10000x10000 */
    RUN_OK("-q", "--crop", "0", "0", "1", "1", "-o", in_dir("px.exr"), scene);
    char *side = test_slurp(in_dir("px.exr.json"), &n), edited[20000];
    char *w = strstr(side, "\"width\": 12,\n  \"height\": 8");
    assert_non_null(w);
    snprintf(edited, sizeof edited, "%.*s\"width\": 10000,\n  \"height\": 10000%s", (int)(w - side), side,
             w + strlen("\"width\": 12,\n  \"height\": 8"));
    free(side);
    test_write_file(in_dir("px.exr.json"), edited, strlen(edited));
    test_write_file(in_dir("keep.png"), "kept", 4);
    assert_int_equal(RUN("merge", in_dir("px.exr"), "-o", in_dir("keep.png")), 2);
    assert_non_null(strstr(err_text, "cover 1 of the 10000x10000 image"));
    expect_refused_small("rt merge");
    char *k = test_slurp(in_dir("keep.png"), &n);
    assert_int_equal(n, 4);
    free(k);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_output_checked_before_rendering),
        cmocka_unit_test(test_failed_write_replaces_nothing),
        cmocka_unit_test(test_tiny_files_claiming_huge_images),
    };
    return cmocka_run_group_tests_name("outputs", tests, setup, teardown);
}
