/* test_farm.c - parts of a render and `rt merge` as a user runs them
 * (docs/farm.md): region parts (--part I/N, --crop) merge into exactly the
 * bytes of a single render, PNG and float; sample ranges that start on
 * block edges (multiples of 64) too; other sample ranges merge within the
 * float summation bound docs/farm.md states; --resume continues a part
 * (also one a --time-limit stopped) to exactly the single render's bytes;
 * merge refuses parts that do not make one image, naming the part, with
 * exit status 2 and nothing written. Runs ./rt (RT_BIN) in a scratch
 * directory. */
#define _XOPEN_SOURCE 700 /* posix_openpt: a terminal for the progress bar */
#include "test_util.h"
#include "test_terminal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <time.h>
#include <sys/wait.h>

#include "rt/image/framebuffer.h"
#include "rt/io/image_read.h"

static char dir[256];
static char err_text[16384];
static char scene_path[600]; /* the scene every test renders */

static const char *rt_bin(void)
{
    const char *b = getenv("RT_BIN");
    return b && *b ? b : "./rt";
}

static const char *in_dir(const char *name)
{
    static char buf[64][600]; /* the last 64 stay valid */
    static int k;
    k = (k + 1) % 64;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

/* Runs rt with the NULL-terminated args; its stderr in err_text. */
static int run(const char *const *args)
{
    const char *argv[64];
    int n = 0;
    argv[n++] = rt_bin();
    for (int i = 0; args[i] && n < 63; i++)
        argv[n++] = args[i];
    argv[n] = NULL;
    const char *errs = in_dir("stderr.txt");
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
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
        ;
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

static int setup(void **state)
{
    (void)state;
    if (!test_make_dir(dir, sizeof dir, "farm") || access(rt_bin(), X_OK) != 0)
        return -1;
    snprintf(scene_path, sizeof scene_path, "%s/scene.txt", dir);
    /* the glass Cornell box, small, path traced (passes; --integrator picks the others) */
    if (!test_copy_scene_with("scenes/glass-cornell.txt", scene_path,
                              "\nresolution 40 30\nsamples 16\nintegrator path\nseed 7\n"))
        return -1;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(dir);
    return 0;
}

/* The single render of the scene (flags added), as PNG and PFM. */
static void single(const char *png, const char *pfm, const char *extra)
{
    const char *scene = scene_path;
    RUN_OK("-q", "-t", "2", "--integrator", extra, "-o", png, scene);
    RUN_OK("-q", "-t", "2", "--integrator", extra, "-o", pfm, scene);
}

static void check_region_parts(const char *integrator, int n)
{
    single(in_dir("full.png"), in_dir("full.pfm"), integrator);
    const char *args[80] = {"merge"};
    int na = 1;
    static char names[8][600];
    for (int i = 0; i < n; i++) {
        char part[32];
        snprintf(part, sizeof part, "%d/%d", i, n);
        snprintf(names[i], sizeof names[i], "%s/p%d.%s", dir, i, i % 2 ? "pfm" : "exr"); /* both part formats */
        RUN_OK("-q", "-t", i % 2 ? "1" : "2", "--tile", i % 3 ? "7" : "32", "--integrator", integrator, "--part",
               part, "-o", names[i], in_dir("scene.txt"));
        args[na++] = names[i];
    }
    args[na++] = "-o";
    args[na++] = in_dir("merged.png");
    args[na] = NULL;
    if (run(args) != 0)
        fail_msg("merge failed: %s", err_text);
    test_assert_same_bytes(in_dir("merged.png"), in_dir("full.png"));
    args[na - 1] = in_dir("merged.pfm");
    if (run(args) != 0)
        fail_msg("merge failed: %s", err_text);
    test_assert_same_bytes(in_dir("merged.pfm"), in_dir("full.pfm"));
}

static void test_parts_1_3_7_same_bytes(void **state)
{
    (void)state;
    check_region_parts("path", 1);
    check_region_parts("path", 3);
    check_region_parts("path", 7);
    check_region_parts("direct", 3); /* tiles, not passes */
    check_region_parts("whitted", 7);
}

static void test_crop_parts_same_bytes(void **state)
{
    (void)state;
    single(in_dir("full.png"), in_dir("full.pfm"), "path");
    const char *scene = scene_path;
    /* an L of crops: left column, and the right part cut in two rows */
    RUN_OK("-q", "--crop", "0", "0", "17", "30", "-o", in_dir("c0.exr"), scene);
    RUN_OK("-q", "--crop", "17,0,40,11", "-o", in_dir("c1.pfm"), scene);
    RUN_OK("-q", "--crop", "17", "11", "40", "30", "--passes", "3", "-o", in_dir("c2.exr"), scene);
    RUN_OK("merge", in_dir("c0.exr"), in_dir("c1.pfm.json"), in_dir("c2.exr"), "-o", in_dir("m.png"));
    test_assert_same_bytes(in_dir("m.png"), in_dir("full.png"));
    RUN_OK("merge", in_dir("c2.exr"), in_dir("c0.exr"), in_dir("c1.pfm"), "-o", in_dir("m.pfm"));
    test_assert_same_bytes(in_dir("m.pfm"), in_dir("full.pfm"));
}

/* Every channel of a within the bound docs/farm.md states of b: merging
 * sample ranges sums the same n samples in another order, so each sum is
 * within 2 (n - 1) u of the other (u = 2^-24, samples >= 0), and the
 * resolve's multiply adds at most an ulp: |a - b| <= 2 n u |b|. */
static void assert_within_summation_bound(const char *a, const char *b, int n)
{
    rt_framebuffer x, y;
    rt_error err = {0};
    assert_int_equal(rt_pfm_read(a, &x, &err), RT_OK);
    assert_int_equal(rt_pfm_read(b, &y, &err), RT_OK);
    assert_int_equal(x.width, y.width);
    assert_int_equal(x.height, y.height);
    double bound = 2.0 * n * ldexp(1.0, -24);
    for (size_t i = 0; i < (size_t)x.width * (size_t)x.height * 3; i++) {
        double d = fabs((double)x.rgb[i] - (double)y.rgb[i]);
        if (d > bound * fabs((double)y.rgb[i]))
            fail_msg("value %zu: %.9g against %.9g, over the bound %.3g relative", i, x.rgb[i], y.rgb[i], bound);
    }
    rt_framebuffer_free(&x);
    rt_framebuffer_free(&y);
}

static void test_sample_ranges(void **state)
{
    (void)state;
    single(in_dir("full.png"), in_dir("full.pfm"), "path");
    const char *scene = scene_path;
    RUN_OK("-q", "--spp-range", "0:5", "-o", in_dir("a.exr"), scene);
    RUN_OK("-q", "--spp-range", "5:16", "-o", in_dir("b.exr"), scene);
    RUN_OK("merge", in_dir("b.exr"), in_dir("a.exr"), "-o", in_dir("two.pfm"));
    assert_within_summation_bound(in_dir("two.pfm"), in_dir("full.pfm"), 16);
    RUN_OK("-q", "--spp-range", "0:3", "--passes", "0", "-o", in_dir("r0.exr"), scene); /* tiles */
    RUN_OK("-q", "--spp-range", "3:9", "--passes", "2", "-o", in_dir("r1.pfm"), scene);
    RUN_OK("-q", "--spp-range", "9:16", "-o", in_dir("r2.exr"), scene);
    RUN_OK("merge", in_dir("r0.exr"), in_dir("r1.pfm"), in_dir("r2.exr"), "-o", in_dir("three.pfm"));
    assert_within_summation_bound(in_dir("three.pfm"), in_dir("full.pfm"), 16);
    /* one range of all samples is the render itself */
    RUN_OK("-q", "--spp-range", "0:16", "-o", in_dir("all.exr"), scene);
    RUN_OK("merge", in_dir("all.exr"), "-o", in_dir("one.pfm"));
    test_assert_same_bytes(in_dir("one.pfm"), in_dir("full.pfm"));
    /* regions and ranges together: part 1 of 3 in two ranges, the others whole */
    RUN_OK("-q", "--part", "0/3", "-o", in_dir("q0.exr"), scene);
    RUN_OK("-q", "--part", "1/3", "--spp-range", "0:7", "-o", in_dir("q1a.exr"), scene);
    RUN_OK("-q", "--part", "1/3", "--spp-range", "7:16", "-o", in_dir("q1b.exr"), scene);
    RUN_OK("-q", "--part", "2/3", "-o", in_dir("q2.exr"), scene);
    RUN_OK("merge", in_dir("q0.exr"), in_dir("q1a.exr"), in_dir("q1b.exr"), in_dir("q2.exr"), "-o", in_dir("mix.pfm"));
    assert_within_summation_bound(in_dir("mix.pfm"), in_dir("full.pfm"), 16);
    /* ... and --resume continues the sum exactly */
    RUN_OK("-q", "--resume", in_dir("q1a.exr"), "-o", in_dir("q1r.exr"), scene);
    RUN_OK("merge", in_dir("q0.exr"), in_dir("q1r.exr"), in_dir("q2.exr"), "-o", in_dir("mix.png"));
    test_assert_same_bytes(in_dir("mix.png"), in_dir("full.png"));
}

static void test_resume_exact(void **state)
{
    (void)state;
    single(in_dir("full.png"), in_dir("full.pfm"), "path");
    const char *scene = scene_path;
    RUN_OK("-q", "--spp-range", "0:5", "-o", in_dir("a.pfm"), scene);
    RUN_OK("-q", "--resume", in_dir("a.pfm"), "-o", in_dir("r.pfm"), scene);
    test_assert_same_bytes(in_dir("r.pfm"), in_dir("full.pfm"));
    RUN_OK("-q", "--resume", in_dir("a.pfm"), "--passes", "0", "-o", in_dir("rt.pfm"), scene); /* tiles */
    test_assert_same_bytes(in_dir("rt.pfm"), in_dir("full.pfm"));
    RUN_OK("-q", "--resume", in_dir("a.pfm.json"), "-o", in_dir("r.png"), scene);
    test_assert_same_bytes(in_dir("r.png"), in_dir("full.png"));
    /* a resumed part that is not the whole image is a part again */
    assert_int_equal(RUN("-q", "--resume", in_dir("a.pfm"), "--spp-range", "5:16", "-o", in_dir("x.pfm"), scene), 2);
    /* a part of another render is refused, naming what differs */
    assert_int_equal(RUN("-q", "--resume", in_dir("a.pfm"), "--seed", "9", "-o", in_dir("x.png"), scene), 2);
    assert_non_null(strstr(err_text, "seed 7, not 9"));
    assert_int_equal(RUN("-q", "--resume", in_dir("a.pfm"), "--set", "clamp=3", "-o", in_dir("x.png"), scene), 2);
    assert_non_null(strstr(err_text, "clamp"));
    assert_int_equal(access(in_dir("x.png"), F_OK), -1);
    /* a part of all samples has nothing left to resume */
    RUN_OK("-q", "--spp-range", "0:16", "-o", in_dir("all.exr"), scene);
    assert_int_equal(RUN("-q", "--resume", in_dir("all.exr"), "-o", in_dir("x.png"), scene), 2);
    assert_non_null(strstr(err_text, "all there are"));
}

/* A full render and three parts of it (one tiled, one resumed) merged,
 * with AOVs: the same bytes, EXR layers and PFM files alike. */
static void aov_parts_merge_exactly(const char *scene)
{
    const char *aovs = "albedo,normal,depth,position";
    RUN_OK("-q", "--aov", aovs, "-o", in_dir("af.exr"), scene);
    RUN_OK("-q", "--aov", aovs, "-o", in_dir("af.png"), scene);
    RUN_OK("-q", "--aov", aovs, "--part", "0/3", "-o", in_dir("ap0.exr"), scene);
    RUN_OK("-q", "--aov", aovs, "--part", "1/3", "--passes", "0", "-o", in_dir("ap1.exr"), scene);
    RUN_OK("-q", "--aov", aovs, "--part", "2/3", "--spp-range", "0:6", "-o", in_dir("ap2a.exr"), scene);
    RUN_OK("-q", "--aov", aovs, "--resume", in_dir("ap2a.exr"), "-o", in_dir("ap2.exr"), scene);
    RUN_OK("merge", in_dir("ap0.exr"), in_dir("ap1.exr"), in_dir("ap2.exr"), "-o", in_dir("am.exr"));
    test_assert_same_bytes(in_dir("am.exr"), in_dir("af.exr"));
    RUN_OK("merge", in_dir("ap0.exr"), in_dir("ap1.exr"), in_dir("ap2.exr"), "-o", in_dir("am.png"));
    test_assert_same_bytes(in_dir("am.png"), in_dir("af.png"));
    const char *names[4] = {"albedo", "normal", "depth", "position"};
    for (int k = 0; k < 4; k++) {
        char a[64], b[64];
        snprintf(a, sizeof a, "am.%s.pfm", names[k]);
        snprintf(b, sizeof b, "af.%s.pfm", names[k]);
        test_assert_same_bytes(in_dir(a), in_dir(b));
    }
}

/* AOVs in parts: their sums travel as EXR layers; merged and resumed they
 * are the single render's bytes, EXR layers and PFM files alike. */
static void test_aov_parts(void **state)
{
    (void)state;
    const char *scene = scene_path;
    aov_parts_merge_exactly(scene);
    /* parts with other AOVs are of another render; variance and spp are not kept */
    RUN_OK("-q", "--aov", "albedo", "--part", "2/3", "-o", in_dir("ap2x.exr"), scene);
    assert_int_equal(RUN("merge", in_dir("ap0.exr"), in_dir("ap1.exr"), in_dir("ap2x.exr"), "-o", in_dir("x.exr")), 2);
    assert_non_null(strstr(err_text, "other AOVs"));
    assert_int_equal(RUN("-q", "--aov", "variance", "--part", "0/3", "-o", in_dir("x.exr"), scene), 2);
    assert_int_equal(RUN("-q", "--aov", "albedo", "--part", "0/3", "-o", in_dir("x.pfm"), scene), 2);
    assert_int_equal(access(in_dir("x.exr"), F_OK), -1);
    assert_int_equal(access(in_dir("x.pfm"), F_OK), -1);
}

/* The same with participating media (the volumetric path tracer, whose
 * AOVs report the first collision in a medium): fog the camera sits in and
 * a ball of smoke in a null boundary, small and quick. */
static void test_aov_parts_media(void **state)
{
    (void)state;
    const char *text = "resolution 24 16\nsamples 12\nintegrator path\nseed 3\n"
                       "camera position 0 1 5 look_at 0 0.6 0 up 0 1 0 fov 45\n"
                       "medium fog homogeneous sigma_a 0.01 0.01 0.01 sigma_s 0.2 0.2 0.2 g 0.5\n"
                       "medium smoke homogeneous sigma_a 0.2 0.3 0.4 sigma_s 2 1.5 1 g 0.3\n"
                       "scene_medium fog\n"
                       "material floor color 0.6 0.6 0.6\nmaterial ball bsdf null interior smoke\n"
                       "quad -5 0 -5  0 0 10  10 0 0  floor\nsphere 0 0.6 0 0.6 ball\n"
                       "light point 1 3 2  1 1 1  20\n";
    char scene[600];
    snprintf(scene, sizeof scene, "%s", in_dir("media.txt"));
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
    aov_parts_merge_exactly(scene);
}

/* --frames A:B: one file a frame, named from the pattern (%04d or
 * Blender's ####; without -o, NAME.%04d.png); a scene without animation
 * gives the single render each frame; bad patterns are refused up front. */
static void test_frames(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "-s", "2", "-o", in_dir("one.png"), scene);
    char pattern[600];
    snprintf(pattern, sizeof pattern, "%s/f%%%%.%%04d.png", dir);
    RUN_OK("-q", "-s", "2", "--frames", "8:11", "--fps", "30", "-o", pattern, scene);
    test_assert_same_bytes(in_dir("f%.0008.png"), in_dir("one.png"));
    test_assert_same_bytes(in_dir("f%.0010.png"), in_dir("one.png"));
    assert_int_equal(access(in_dir("f%.0011.png"), F_OK), -1);
    assert_int_equal(access(in_dir("f%.0007.png"), F_OK), -1);
    snprintf(pattern, sizeof pattern, "%s/fp%%d.exr", dir);
    RUN_OK("-q", "-s", "2", "--frames", "0:2", "--part", "1/2", "-o", pattern, scene);
    assert_int_equal(access(in_dir("fp1.exr.json"), F_OK), 0);
    /* Blender's ####: the number zero-padded to as many digits */
    snprintf(pattern, sizeof pattern, "%s/h.###.png", dir);
    RUN_OK("-q", "-s", "2", "--frames", "8:10", "-o", pattern, scene);
    test_assert_same_bytes(in_dir("h.008.png"), in_dir("one.png"));
    test_assert_same_bytes(in_dir("h.009.png"), in_dir("one.png"));
    /* without -o: NAME.%04d.png in the current directory (NAME: the input's) */
    char bin[4096], cwd[4096];
    assert_non_null(realpath(rt_bin(), bin));
    assert_non_null(getcwd(cwd, sizeof cwd));
    setenv("RT_BIN", bin, 1);
    assert_int_equal(chdir(dir), 0);
    int status = RUN("-q", "-s", "2", "--frames", "3:5", "scene.txt");
    assert_int_equal(chdir(cwd), 0);
    if (status != 0)
        fail_msg("--frames without -o failed: %s", err_text);
    test_assert_same_bytes(in_dir("scene.0003.png"), in_dir("one.png"));
    test_assert_same_bytes(in_dir("scene.0004.png"), in_dir("one.png"));
    const char *bad[] = {"plain.png", "two%d%d.png", "s%s.png", "w%010d.png", "%", "two##.#.png", "long##########.png"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        assert_int_equal(RUN("-q", "--frames", "0:2", "-o", in_dir(bad[i]), scene), 2);
        assert_non_null(strstr(err_text, "%0Nd"));
    }
    assert_int_equal(RUN("-q", "--frames", "0:2", "--frame-time", "1", "-o", pattern, scene), 2);
    assert_int_equal(RUN("-q", "--frames", "2:2", "-o", pattern, scene), 2);
    assert_int_equal(RUN("-q", "--frames", "0:2", "--fps", "0", "-o", pattern, scene), 2);
}

/* --frames of an animated glTF: frame f is the model posed at f / fps, as
 * --frame-time poses it, given directly or on a scene file's model line;
 * parts of different frames are parts of different renders. */
static void test_frames_animated_gltf(void **state)
{
    (void)state;
    test_require_shared();
    char pattern[600];
    const char *truck = test_shared_path("assets/gltf/CesiumMilkTruck/glTF-Binary/CesiumMilkTruck.glb");
    static char model[4096];
    snprintf(model, sizeof model, "%s", truck);
    snprintf(pattern, sizeof pattern, "%s/truck.%%d.png", dir);
    /* the truck has no camera: a fixed one, as the sequence's automatic
     * camera frames all three frames, not frame 2 alone */
    RUN_OK("-q", "-r", "48x36", "-s", "2", "--look-from", "3,2,4", "--look-at", "0,1,0", "--frames", "0:3", "--fps",
           "4", "-o", pattern, model);
    RUN_OK("-q", "-r", "48x36", "-s", "2", "--look-from", "3,2,4", "--look-at", "0,1,0", "--frame-time", "0.5", "-o",
           in_dir("truck-t.png"), model);
    test_assert_same_bytes(in_dir("truck.2.png"), in_dir("truck-t.png"));
    size_t n0, n2;
    char *f0 = test_slurp(in_dir("truck.0.png"), &n0), *f2 = test_slurp(in_dir("truck.2.png"), &n2);
    assert_true(n0 != n2 || memcmp(f0, f2, n0) != 0); /* the truck moved */
    free(f0);
    free(f2);
    /* parts of different frames are parts of different renders */
    snprintf(pattern, sizeof pattern, "%s/tp.%%d.exr", dir);
    RUN_OK("-q", "-r", "48x36", "-s", "2", "--frames", "0:2", "--part", "0/2", "-o", pattern, model);
    RUN_OK("-q", "-r", "48x36", "-s", "2", "--frames", "1:2", "--part", "1/2", "-o", pattern, model);
    assert_int_equal(RUN("merge", in_dir("tp.0.exr"), in_dir("tp.1.exr"), "-o", in_dir("tp.png")), 2);
    assert_non_null(strstr(err_text, "not a part of the same render"));
    /* a scene file around an animated model: its model line is posed at each frame's time */
    char text[8000], fox[6200];
    const char *rel = test_shared_path("assets/gltf/Fox/glTF-Binary/Fox.glb"); /* the scene is elsewhere */
    char cwd[2048] = "";
    assert_true(rel[0] == '/' || getcwd(cwd, sizeof cwd) != NULL);
    snprintf(fox, sizeof fox, "%s%s%s", rel[0] == '/' ? "" : cwd, rel[0] == '/' ? "" : "/", rel);
    snprintf(text, sizeof text,
             "resolution 48 36\nsamples 2\ncamera position 90 60 200 look_at 0 35 0 up 0 1 0 fov 40\n"
             "light directional -0.4 -1 -0.6 1 1 1 2\nmodel \"%s\" animation Run\n",
             fox);
    FILE *f = fopen(in_dir("fox.txt"), "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    snprintf(pattern, sizeof pattern, "%s/fox.%%d.png", dir);
    RUN_OK("-q", "--frames", "0:3", "--fps", "4", "-o", pattern, in_dir("fox.txt"));
    RUN_OK("-q", "--frame-time", "0.5", "-o", in_dir("fox-t.png"), in_dir("fox.txt"));
    test_assert_same_bytes(in_dir("fox.2.png"), in_dir("fox-t.png"));
    f0 = test_slurp(in_dir("fox.0.png"), &n0), f2 = test_slurp(in_dir("fox.2.png"), &n2);
    assert_true(n0 != n2 || memcmp(f0, f2, n0) != 0); /* the fox ran */
    free(f0);
    free(f2);
    /* --animation by name: the Fox's third animation is 'Run'; an unknown
     * name is refused, naming the file's */
    static char foxglb[6200];
    snprintf(foxglb, sizeof foxglb, "%s", fox);
    RUN_OK("-q", "-r", "32x24", "-s", "1", "--frame-time", "0.3", "--animation", "2", "-o", in_dir("run2.pfm"), foxglb);
    RUN_OK("-q", "-r", "32x24", "-s", "1", "--frame-time", "0.3", "--animation", "Run", "-o", in_dir("runname.pfm"),
           foxglb);
    test_assert_same_bytes(in_dir("run2.pfm"), in_dir("runname.pfm"));
    RUN_OK("-q", "-r", "32x24", "-s", "1", "--frame-time", "0.3", "--animation", "Walk", "-o", in_dir("walk.pfm"),
           foxglb);
    f0 = test_slurp(in_dir("run2.pfm"), &n0), f2 = test_slurp(in_dir("walk.pfm"), &n2);
    assert_true(n0 != n2 || memcmp(f0, f2, n0) != 0);
    free(f0);
    free(f2);
    /* a scene's model line without its own `animation` plays the one --animation names */
    char *eol = strstr(text, " animation Run\n");
    assert_non_null(eol);
    strcpy(eol, "\n");
    f = fopen(in_dir("fox-any.txt"), "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    RUN_OK("-q", "--frame-time", "0.5", "--animation", "Run", "-o", in_dir("fox-named.png"), in_dir("fox-any.txt"));
    test_assert_same_bytes(in_dir("fox-named.png"), in_dir("fox-t.png"));
    assert_int_equal(RUN("-q", "--frame-time", "0.3", "--animation", "Trot", "-o", in_dir("trot.pfm"), foxglb), 2);
    assert_non_null(strstr(err_text, "no animation named 'Trot'"));
    assert_non_null(strstr(err_text, "'Run'"));
    snprintf(pattern, sizeof pattern, "%s/foxp.%%d.exr", dir);
    RUN_OK("-q", "--frames", "0:2", "--part", "0/2", "-o", pattern, in_dir("fox.txt"));
    RUN_OK("-q", "--frames", "1:2", "--part", "1/2", "-o", pattern, in_dir("fox.txt"));
    assert_int_equal(RUN("merge", in_dir("foxp.0.exr"), in_dir("foxp.1.exr"), "-o", in_dir("foxp.png")), 2);
    assert_non_null(strstr(err_text, "frame_time"));
}

/* The camera lines of a part's sidecar ("camera.position ... focus_distance X"). */
static void sidecar_camera(const char *json, char *out, size_t size)
{
    size_t n;
    char *t = test_slurp(json, &n);
    const char *a = strstr(t, "camera.position"), *b = a ? strstr(a, "frame_time") : NULL;
    if (!a || !b)
        fail_msg("no camera in %s", json);
    snprintf(out, size, "%.*s", (int)(b - a), a);
    free(t);
}

/* --frames with the automatic camera (the Fox has none) frames the whole
 * sequence once: every frame has the same camera, and a machine rendering
 * only its share (--only-frames) frames as the whole run did, to the same
 * bytes; --only-frames outside --frames is refused. Before, each frame was
 * framed on its own pose and the camera moved with the fox. */
static void test_frames_one_camera(void **state)
{
    (void)state;
    test_require_shared();
    static char fox[4096];
    snprintf(fox, sizeof fox, "%s", test_shared_path("assets/gltf/Fox/glTF-Binary/Fox.glb"));
    char pattern[600], parts[600];
    snprintf(pattern, sizeof pattern, "%s/seq.%%d.pfm", dir);
    snprintf(parts, sizeof parts, "%s/seq.%%d.exr", dir);
    RUN_OK("-q", "-r", "32x24", "-s", "1", "--animation", "2", "--frames", "0:12", "--fps", "8", "--part-out", parts,
           "-o", pattern, fox);
    char first[2048], other[2048], name[64];
    sidecar_camera(in_dir("seq.0.exr.json"), first, sizeof first);
    for (int f = 1; f < 12; f++) {
        snprintf(name, sizeof name, "seq.%d.exr.json", f);
        sidecar_camera(in_dir(name), other, sizeof other);
        assert_string_equal(other, first);
    }
    snprintf(pattern, sizeof pattern, "%s/share.%%d.pfm", dir);
    RUN_OK("-q", "-r", "32x24", "-s", "1", "--animation", "2", "--frames", "0:12", "--only-frames", "7:9", "--fps", "8",
           "-o", pattern, fox);
    test_assert_same_bytes(in_dir("share.7.pfm"), in_dir("seq.7.pfm"));
    test_assert_same_bytes(in_dir("share.8.pfm"), in_dir("seq.8.pfm"));
    assert_int_equal(access(in_dir("share.6.pfm"), F_OK), -1);
    assert_int_equal(access(in_dir("share.9.pfm"), F_OK), -1);
    assert_int_equal(RUN("-q", "--frames", "0:12", "--only-frames", "11:13", "-o", pattern, fox), 2);
    assert_non_null(strstr(err_text, "--only-frames"));
    assert_int_equal(RUN("-q", "--only-frames", "1:2", "-o", pattern, fox), 2);
}

/* quad.gltf in the scratch directory: a black quad 2 wide, 20 tall, two
 * triangles facing +z with its left edge at x = 0; animation 0 moves it by
 * (-4, 0, 0) at t = 0 to (4, 0, 0) at t = 1, animation 1 holds it at
 * (-6, 0, 0) over the same times. */
static void write_moving_quad(void)
{
    const float data[] = {0, -10, 0, 2, -10, 0, 2, 10, 0, 0, -10, 0, 2, 10, 0, 0, 10, 0, 0, 1, -4, 0, 0, 4, 0, 0,
                          -6, 0, 0, -6, 0, 0};
    char *enc = test_base64(data, sizeof data);
    char json[4096];
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
             "\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":8},"
             "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":104,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\","
             "\"min\":[0,-10,0],\"max\":[2,10,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":2,"
             "\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},{\"bufferView\":2,\"componentType\":5126,\"count\":2,"
             "\"type\":\"VEC3\"},{\"bufferView\":3,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
             "\"animations\":[{\"samplers\":[{\"input\":1,\"output\":2}],"
             "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]},"
             "{\"samplers\":[{\"input\":1,\"output\":3}],"
             "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]}",
             sizeof data, enc);
    free(enc);
    test_write_file(in_dir("quad.gltf"), json, strlen(json));
}

/* A scene file (name in dir) around the moving quad, with `camera_extra`
 * on its camera line, `extra` lines after it and `model_extra` on the
 * model line. */
static void write_motion_scene(const char *name, const char *camera_extra, const char *extra, const char *model_extra)
{
    char text[2048];
    /* 16 x 4 pixels over x in [-8, 8] at z = 0: tan(fov / 2) = 2 / 10 */
    snprintf(text, sizeof text,
             "resolution 16 4\nsamples 256\nintegrator direct\nbackground 1 1 1\n"
             "camera position 0 0 10 look_at 0 0 0 up 0 1 0 fov 22.6198649 %s\n%s\nmodel quad.gltf %s\n",
             camera_extra, extra, model_extra);
    test_write_file(in_dir(name), text, strlen(text));
}

/* The mean of pixel column x of a float image. */
static double column_mean(const char *path, int x)
{
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_image_read(path, &fb, &err), RT_OK);
    double sum = 0;
    int h = fb.height;
    for (int y = 0; y < h; y++)
        sum += fb.rgb[3 * ((size_t)y * (size_t)fb.width + (size_t)x)];
    rt_framebuffer_free(&fb);
    return sum / h;
}

/* Motion blur (docs/gltf.md): a black quad 2 wide, as tall as the image,
 * moves at 8 units/s from x = -4 to 4 during the shutter [0, 1] before a
 * white background. Every point of the pixel column x in [0, 1] is covered
 * for 2 / 8 = 1/4 of the shutter, so the column's value is 1 - 1/4: the
 * coverage fraction equals the time overlap (16 slices put exactly 4
 * midpoints in any quarter of the shutter; measured: 0.75 to float
 * precision), and every other column its own overlap integrated over the
 * column (1 - 1/16 at x in [-4, -3], ...). Columns the quad never reaches
 * stay 1 exactly. K = 1 is the
 * pose at the shutter's midpoint; the image is the same for any thread,
 * tile, pass and part split; a pose fixed by `time` is not sliced. */
static void test_motion_blur(void **state)
{
    (void)state;
    write_moving_quad();
    write_motion_scene("blur.txt", "shutter 0 1", "motion_steps 16", "");
    RUN_OK("-q", "-o", in_dir("blur.pfm"), in_dir("blur.txt"));
    for (int x = 0; x < 16; x++) { /* every column against its time overlap, integrated over the column */
        double want = 0;
        for (int i = 0; i < 10000; i++) {
            double px = x - 8 + (i + 0.5) / 10000, t0 = (px + 2) / 8, t1 = (px + 4) / 8; /* covered in [t0, t1] */
            t0 = t0 > 0 ? t0 : 0;
            t1 = t1 < 1 ? t1 : 1;
            want += t1 > t0 ? (t1 - t0) / 10000 : 0;
        }
        double got = column_mean(in_dir("blur.pfm"), x);
        if (fabs(got - (1 - want)) > 0.01)
            fail_msg("column %d: %g, expected 1 - %g", x, got, want);
    }
    assert_true(fabs(column_mean(in_dir("blur.pfm"), 8) - 0.75) < 1e-3); /* a quarter of the shutter */
    assert_true(column_mean(in_dir("blur.pfm"), 0) == 1.0);
    assert_true(column_mean(in_dir("blur.pfm"), 15) == 1.0);
    /* any split of the work: the same bytes */
    RUN_OK("-q", "-t", "1", "--passes", "0", "--tile", "3", "-o", in_dir("blur-t1.pfm"), in_dir("blur.txt"));
    test_assert_same_bytes(in_dir("blur-t1.pfm"), in_dir("blur.pfm"));
    RUN_OK("-q", "-t", "2", "--passes", "5", "-o", in_dir("blur-p5.pfm"), in_dir("blur.txt"));
    test_assert_same_bytes(in_dir("blur-p5.pfm"), in_dir("blur.pfm"));
    RUN_OK("-q", "--part", "0/2", "-o", in_dir("bp0.exr"), in_dir("blur.txt"));
    RUN_OK("-q", "--part", "1/2", "--spp-range", "0:100", "-o", in_dir("bp1a.exr"), in_dir("blur.txt"));
    RUN_OK("-q", "--part", "1/2", "--spp-range", "100:256", "-o", in_dir("bp1b.exr"), in_dir("blur.txt"));
    RUN_OK("merge", in_dir("bp0.exr"), in_dir("bp1a.exr"), in_dir("bp1b.exr"), "-o", in_dir("bm.pfm"));
    test_assert_same_bytes(in_dir("bm.pfm"), in_dir("blur.pfm"));
    /* stopped between slices (a slice is one pass), kept as a part, resumed: the same bytes */
    RUN_OK("-q", "--time-limit", "0.000001", "--part-out", in_dir("bstop.exr"), "-o", in_dir("bstop.pfm"),
           in_dir("blur.txt"));
    RUN_OK("-q", "--resume", in_dir("bstop.exr"), "-o", in_dir("bres.pfm"), in_dir("blur.txt"));
    test_assert_same_bytes(in_dir("bres.pfm"), in_dir("blur.pfm"));
    /* a part of another shutter is of another render */
    write_motion_scene("blur2.txt", "shutter 0 0.5", "motion_steps 16", "");
    RUN_OK("-q", "--part", "1/2", "-o", in_dir("bp1x.exr"), in_dir("blur2.txt"));
    assert_int_equal(RUN("merge", in_dir("bp0.exr"), in_dir("bp1x.exr"), "-o", in_dir("x.pfm")), 2);
    /* K = 1: the pose at the shutter's midpoint, as an unblurred render at that time */
    write_motion_scene("k1.txt", "shutter 0.25 0.75", "motion_steps 1", "");
    write_motion_scene("still.txt", "", "", "");
    RUN_OK("-q", "-o", in_dir("k1.pfm"), in_dir("k1.txt"));
    RUN_OK("-q", "--frame-time", "0.5", "-o", in_dir("mid.pfm"), in_dir("still.txt"));
    test_assert_same_bytes(in_dir("k1.pfm"), in_dir("mid.pfm"));
    assert_true(column_mean(in_dir("mid.pfm"), 8) == 0.0); /* the quad over x in [0, 2] at t = 0.5 */
    RUN_OK("-q", "--frame-time", "0.25", "-o", in_dir("open.pfm"), in_dir("still.txt"));
    assert_true(column_mean(in_dir("open.pfm"), 8) == 1.0); /* and over [-2, 0] at 0.25 */
    RUN_OK("-q", "--frame-time", "0.25", "-o", in_dir("k1b.pfm"), in_dir("k1.txt")); /* the frame time shifts it */
    assert_true(column_mean(in_dir("k1b.pfm"), 10) == 0.0 && column_mean(in_dir("k1b.pfm"), 8) == 1.0); /* [2, 4] */
    /* a pose fixed by `time` does not follow the shutter: no slices, the unblurred image */
    write_motion_scene("fixed.txt", "shutter 0 1", "motion_steps 16", "time 0.5");
    write_motion_scene("fixed0.txt", "", "", "time 0.5");
    RUN_OK("-v", "-o", in_dir("fixed.pfm"), in_dir("fixed.txt"));
    assert_null(strstr(err_text, "motion: slice"));
    RUN_OK("-q", "-o", in_dir("fixed0.pfm"), in_dir("fixed0.txt"));
    test_assert_same_bytes(in_dir("fixed.pfm"), in_dir("fixed0.pfm"));
    /* a shutter that closes before it opens */
    write_motion_scene("bad.txt", "shutter 1 0", "", "");
    assert_int_equal(RUN("-q", "-o", in_dir("x.pfm"), in_dir("bad.txt")), 2);
    assert_non_null(strstr(err_text, "bad.txt:5:"));
    assert_non_null(strstr(err_text, "closes (0 s) before it opens (1 s)"));
}

/* --animation N picks the glTF animation --frame-time plays: at t = 0.5
 * animation 0 has the quad over x in [0, 2] (pixel column 8 black, column
 * 2 white), animation 1 holds it over [-6, -4] (column 2 black, column 8
 * white); animation 0 is the default; one the file does not have is
 * refused, naming the count. */
static void test_animation_index(void **state)
{
    (void)state;
    write_moving_quad();
    write_motion_scene("still.txt", "", "", "");
    RUN_OK("-q", "--frame-time", "0.5", "-o", in_dir("anim-default.pfm"), in_dir("still.txt"));
    RUN_OK("-q", "--frame-time", "0.5", "--animation", "0", "-o", in_dir("anim0.pfm"), in_dir("still.txt"));
    RUN_OK("-q", "--frame-time", "0.5", "--animation", "1", "-o", in_dir("anim1.pfm"), in_dir("still.txt"));
    test_assert_same_bytes(in_dir("anim-default.pfm"), in_dir("anim0.pfm"));
    assert_true(column_mean(in_dir("anim0.pfm"), 8) == 0.0 && column_mean(in_dir("anim0.pfm"), 2) == 1.0);
    assert_true(column_mean(in_dir("anim1.pfm"), 2) == 0.0 && column_mean(in_dir("anim1.pfm"), 8) == 1.0);
    assert_int_equal(RUN("-q", "--frame-time", "0.5", "--animation", "2", "-o", in_dir("anim2.pfm"),
                         in_dir("still.txt")),
                     2);
    assert_non_null(strstr(err_text, "quad.gltf: animation 2 requested, the file has 2 (0 to 1)"));
    assert_int_equal(access(in_dir("anim2.pfm"), F_OK), -1);
}

/* The samples [0, k] a sidecar says its part holds. */
static int sidecar_end(const char *json)
{
    size_t n;
    char *t = test_slurp(json, &n);
    const char *s = strstr(t, "\"samples\": [");
    assert_non_null(s);
    int a = -1, b = -1;
    assert_int_equal(sscanf(s, "\"samples\": [%d, %d]", &a, &b), 2);
    free(t);
    return b;
}

/* A time limit that is over before the first pass ends (1 us: less than
 * starting a thread takes) stops a render in passes after exactly its
 * first pass (the limit is checked between passes) and a tiled one before
 * its first tile (a worker checks it before taking one): where it stops is
 * known, so the test asserts that branch. */
#define TIME_UP "0.000001"

/* A render stopped by a time limit after its first pass leaves a part of
 * it; resumed, or merged with the rest of the samples, it is the straight
 * render of all of them. */
static void test_time_limit_then_resume(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "-s", "64", "-o", in_dir("full64.pfm"), scene);
    RUN_OK("-q", "-s", "64", "--passes", "1", "--time-limit", TIME_UP, "--part-out", in_dir("stop.exr"), "-o",
           in_dir("stopped.pfm"), scene);
    assert_int_equal(sidecar_end(in_dir("stop.exr.json")), 1);
    RUN_OK("-q", "-s", "64", "--resume", in_dir("stop.exr"), "-o", in_dir("resumed.pfm"), scene);
    test_assert_same_bytes(in_dir("resumed.pfm"), in_dir("full64.pfm"));
    RUN_OK("-q", "-s", "64", "--spp-range", "1:64", "-o", in_dir("rest.exr"), scene);
    RUN_OK("merge", in_dir("stop.exr"), in_dir("rest.exr"), "-o", in_dir("merged64.pfm"));
    assert_within_summation_bound(in_dir("merged64.pfm"), in_dir("full64.pfm"), 64);
    /* a part render stopped the same way writes the part of the passes it finished */
    RUN_OK("-q", "-s", "64", "--passes", "1", "--time-limit", TIME_UP, "--part", "0/1", "-o", in_dir("p.exr"), scene);
    assert_int_equal(sidecar_end(in_dir("p.exr.json")), 1);
    RUN_OK("-q", "-s", "64", "--resume", in_dir("p.exr"), "-o", in_dir("p-resumed.pfm"), scene);
    test_assert_same_bytes(in_dir("p-resumed.pfm"), in_dir("full64.pfm"));
}

/* The integrators that tile (whitted, direct) render in passes when the
 * render keeps a part, so a stop keeps one there too; --passes 0 (tiles,
 * asked for) says it keeps none. */
static void test_time_limit_tiling_integrator(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "-s", "64", "--integrator", "whitted", "-o", in_dir("wfull.pfm"), scene);
    RUN_OK("-q", "-s", "64", "--integrator", "whitted", "--time-limit", TIME_UP, "--part-out", in_dir("wstop.exr"),
           "-o", in_dir("wstopped.pfm"), scene);
    assert_int_equal(sidecar_end(in_dir("wstop.exr.json")), 4); /* the first whole pass of 4 */
    RUN_OK("-q", "-s", "64", "--integrator", "whitted", "--resume", in_dir("wstop.exr"), "-o", in_dir("wresumed.pfm"),
           scene);
    test_assert_same_bytes(in_dir("wresumed.pfm"), in_dir("wfull.pfm"));
    RUN_OK("-q", "-s", "64", "--integrator", "direct", "--time-limit", TIME_UP, "--crop", "0", "0", "40", "15", "-o",
           in_dir("dstop.exr"), scene);
    assert_int_equal(sidecar_end(in_dir("dstop.exr.json")), 4);
    /* tiles, asked for: no tile is started, and rt says it keeps no part */
    RUN_OK("-s", "64", "--integrator", "whitted", "--passes", "0", "--time-limit", TIME_UP, "--part-out",
           in_dir("tstop.exr"), "-o", in_dir("tstopped.pfm"), scene);
    assert_int_equal(access(in_dir("tstop.exr.json"), F_OK), -1);
    assert_non_null(strstr(err_text, "keeps no part"));
}

/* A frame stopped early (here by a time limit after its first pass; a
 * signal takes the same path) is not the finished frame: its image goes to
 * NAME.partial.EXT and its sums to NAME.part.exr, the frame's name stays
 * free; the next run of the frame resumes the part to exactly the bytes of
 * a render never stopped, and removes what the stop left. An integrator
 * that tiles (direct) stops and resumes alike (a frame renders in passes). */
static void test_frames_stopped_then_resumed(void **state)
{
    (void)state;
    const char *scene = scene_path;
    const char *integrators[] = {"path", "direct"};
    for (int k = 0; k < 2; k++) {
        char pattern[600], name[64];
        snprintf(pattern, sizeof pattern, "%s/straight-%s.%%04d.pfm", dir, integrators[k]);
        RUN_OK("-q", "-s", "64", "--integrator", integrators[k], "--frames", "5:7", "-o", pattern, scene);
        snprintf(pattern, sizeof pattern, "%s/stop-%s.%%04d.pfm", dir, integrators[k]);
        RUN_OK("-q", "-s", "64", "--integrator", integrators[k], "--frames", "5:7", "--time-limit", TIME_UP, "-o",
               pattern, scene);
        for (int f = 5; f < 7; f++) {
            snprintf(name, sizeof name, "stop-%s.%04d", integrators[k], f);
            char image[700], partial[700], sidecar[700];
            snprintf(image, sizeof image, "%s.pfm", in_dir(name));
            snprintf(partial, sizeof partial, "%s.partial.pfm", in_dir(name));
            snprintf(sidecar, sizeof sidecar, "%s.part.exr.json", in_dir(name));
            assert_int_equal(access(image, F_OK), -1); /* not under the finished frame's name */
            assert_int_equal(access(partial, F_OK), 0);
            assert_int_equal(sidecar_end(sidecar), 4); /* the first pass of 4 (also direct's, which tiles unstopped) */
        }
        RUN_OK("-q", "-s", "64", "--integrator", integrators[k], "--frames", "5:7", "-o", pattern, scene);
        for (int f = 5; f < 7; f++) {
            char a[700], b[700];
            snprintf(a, sizeof a, "%s/stop-%s.%04d.pfm", dir, integrators[k], f);
            snprintf(b, sizeof b, "%s/straight-%s.%04d.pfm", dir, integrators[k], f);
            test_assert_same_bytes(a, b);
            snprintf(a, sizeof a, "%s/stop-%s.%04d.part.exr.json", dir, integrators[k], f);
            assert_int_equal(access(a, F_OK), -1); /* the stop's leftovers removed */
            snprintf(a, sizeof a, "%s/stop-%s.%04d.part.exr", dir, integrators[k], f);
            assert_int_equal(access(a, F_OK), -1);
            snprintf(a, sizeof a, "%s/stop-%s.%04d.partial.pfm", dir, integrators[k], f);
            assert_int_equal(access(a, F_OK), -1);
        }
    }
    /* with what a part cannot keep (the spp AOV) a stopped frame is still
     * kept apart, without a part, and renders again from the start */
    char aovs[600];
    snprintf(aovs, sizeof aovs, "%s/aov.%%04d.pfm", dir);
    RUN_OK("-q", "-s", "64", "--aov", "spp", "--frames", "2:3", "--time-limit", TIME_UP, "-o", aovs, scene);
    assert_int_equal(access(in_dir("aov.0002.pfm"), F_OK), -1);
    assert_int_equal(access(in_dir("aov.0002.partial.pfm"), F_OK), 0);
    assert_int_equal(access(in_dir("aov.0002.part.exr.json"), F_OK), -1);
    RUN_OK("-q", "-s", "64", "--aov", "spp", "--frames", "2:3", "-o", aovs, scene);
    RUN_OK("-q", "-s", "64", "-o", in_dir("aov-straight.pfm"), scene);
    test_assert_same_bytes(in_dir("aov.0002.pfm"), in_dir("aov-straight.pfm"));
    assert_int_equal(access(in_dir("aov.0002.partial.pfm"), F_OK), -1);
    /* a stopped frame's part of other settings is not resumed over: refused, naming it */
    char pattern[600];
    snprintf(pattern, sizeof pattern, "%s/other.%%04d.pfm", dir);
    RUN_OK("-q", "-s", "64", "--frames", "1:2", "--time-limit", TIME_UP, "-o", pattern, scene);
    assert_int_equal(RUN("-q", "-s", "32", "--frames", "1:2", "-o", pattern, scene), 2);
    assert_non_null(strstr(err_text, "other.0001.part.exr"));
    assert_non_null(strstr(err_text, "to render the frame over")); /* and says what to do */
    assert_int_equal(access(in_dir("other.0001.pfm"), F_OK), -1);
    assert_int_equal(RUN("-q", "--frames", "1:2", "--resume", in_dir("other.0001.part.exr"), "-o", pattern, scene), 2);
}

/* Ctrl-C in passes, sent once the progress bar shows the first of 64
 * one-sample passes done: exit 130, the part holds the whole passes done
 * (at least that one, a pass cut short is not in it), and resumed it is
 * the straight render. */
static void test_interrupt_then_resume(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "-s", "64", "-o", in_dir("full64i.pfm"), scene);
    const char *argv[] = {rt_bin(), "-s", "64", "--passes", "1", "-t", "2", "--part-out", in_dir("int.exr"), "-o",
                          in_dir("int.pfm"), scene, NULL};
    static char out[1 << 16];
    test_terminal_signal at = {.sig = SIGINT, .unit = " spp", .at_least = 1};
    test_terminal_result r;
    test_terminal_run(argv, &at, out, sizeof out, &r);
    if (r.status != 130)
        fail_msg("expected exit 130 after SIGINT at %d/64 spp, got %d (signal %d):\n%s", r.signalled_at, r.status,
                 r.signal, out);
    int k = sidecar_end(in_dir("int.exr.json"));
    assert_true(k >= r.signalled_at && k < 64);
    RUN_OK("-q", "-s", "64", "--resume", in_dir("int.exr"), "-o", in_dir("int-resumed.pfm"), scene);
    test_assert_same_bytes(in_dir("int-resumed.pfm"), in_dir("full64i.pfm"));
}

static const char precious[] = "an earlier image the user keeps\n";

/* merge with args must exit 2 naming `names` and leave the output alone. */
static void refuse(const char *names, const char *const *args)
{
    test_write_file(in_dir("keep.png"), precious, sizeof precious - 1);
    int st = run(args);
    if (st != 2)
        fail_msg("expected exit 2, got %d: %s", st, err_text);
    if (strncmp(err_text, "rt: merge: ", 11) != 0 || (names && !strstr(err_text, names)))
        fail_msg("expected a message naming '%s', got: %s", names, err_text);
    size_t n;
    char *t = test_slurp(in_dir("keep.png"), &n);
    assert_int_equal(n, sizeof precious - 1);
    assert_memory_equal(t, precious, n);
    free(t);
}

#define REFUSE(names, ...) refuse(names, (const char *const[]){"merge", __VA_ARGS__, "-o", in_dir("keep.png"), NULL})

static void copy(const char *from, const char *to, size_t cut)
{
    size_t n;
    char *t = test_slurp(from, &n);
    test_write_file(to, t, cut && cut < n ? cut : n);
    free(t);
}

static void test_merge_refusals(void **state)
{
    (void)state;
    const char *scene = scene_path;
    for (int i = 0; i < 3; i++) {
        char part[32], name[32];
        snprintf(part, sizeof part, "%d/3", i);
        snprintf(name, sizeof name, "g%d.exr", i);
        RUN_OK("-q", "--part", part, "-o", in_dir(name), scene);
    }
    /* a missing region, a part twice, overlapping regions */
    REFUSE("a part is missing: no part covers the region [0, 40) x [", in_dir("g0.exr"), in_dir("g2.exr"));
    REFUSE("given twice", in_dir("g0.exr"), in_dir("g1.exr"), in_dir("g1.exr"), in_dir("g2.exr"));
    char other_name[700]; /* the same file by another name */
    snprintf(other_name, sizeof other_name, "%s/./g1.exr", dir);
    REFUSE("given twice (also as", in_dir("g0.exr"), in_dir("g1.exr"), other_name, in_dir("g2.exr"));
    RUN_OK("-q", "--crop", "0", "0", "40", "20", "-o", in_dir("top.exr"), scene);
    REFUSE("overlaps", in_dir("g0.exr"), in_dir("g1.exr"), in_dir("g2.exr"), in_dir("top.exr"));
    /* sample ranges: overlapping, missing */
    RUN_OK("-q", "--spp-range", "0:9", "-o", in_dir("s0.exr"), scene);
    RUN_OK("-q", "--spp-range", "8:16", "-o", in_dir("s1.exr"), scene);
    RUN_OK("-q", "--spp-range", "10:16", "-o", in_dir("s2.exr"), scene);
    REFUSE("s1.exr", in_dir("s0.exr"), in_dir("s1.exr"));
    REFUSE("in no part", in_dir("s0.exr"), in_dir("s2.exr"));
    REFUSE("in no part", in_dir("s2.exr"));
    /* another render: seed, samples, resolution, settings, scene file */
    RUN_OK("-q", "--part", "1/3", "--seed", "8", "-o", in_dir("seed.exr"), scene);
    REFUSE("seed.exr", in_dir("g0.exr"), in_dir("seed.exr"), in_dir("g2.exr"));
    RUN_OK("-q", "--part", "1/3", "--set", "clamp=5", "-o", in_dir("clamp.exr"), scene);
    REFUSE("clamp", in_dir("g0.exr"), in_dir("clamp.exr"), in_dir("g2.exr"));
    RUN_OK("-q", "--part", "1/3", "-r", "40x31", "-o", in_dir("size.exr"), scene);
    REFUSE("size.exr", in_dir("g0.exr"), in_dir("size.exr"), in_dir("g2.exr"));
    copy(scene, in_dir("scene2.txt"), 0);
    FILE *f = fopen(in_dir("scene2.txt"), "a");
    assert_non_null(f);
    fputs("# another file\n", f);
    fclose(f);
    RUN_OK("-q", "--part", "1/3", "-o", in_dir("other.exr"), in_dir("scene2.txt"));
    REFUSE("another scene", in_dir("g0.exr"), in_dir("other.exr"), in_dir("g2.exr"));
    /* damaged files: a truncated image, an image from another part, a broken
     * or edited sidecar, no sidecar, not a part at all */
    copy(in_dir("g1.exr"), in_dir("t.exr"), 300);
    copy(in_dir("g1.exr.json"), in_dir("t.exr.json"), 0);
    REFUSE("t.exr", in_dir("g0.exr"), in_dir("t.exr"), in_dir("g2.exr"));
    copy(in_dir("g0.exr"), in_dir("w.exr"), 0);
    copy(in_dir("g1.exr.json"), in_dir("w.exr.json"), 0);
    REFUSE("w.exr", in_dir("g0.exr"), in_dir("w.exr"), in_dir("g2.exr"));
    copy(in_dir("g1.exr"), in_dir("j.exr"), 0);
    copy(in_dir("g1.exr.json"), in_dir("j.exr.json"), 200);
    REFUSE("j.exr.json", in_dir("g0.exr"), in_dir("j.exr"), in_dir("g2.exr"));
    size_t n;
    char *t = test_slurp(in_dir("g1.exr.json"), &n);
    char *s = strstr(t, "samples 16");
    assert_non_null(s);
    s[8] = '5'; /* "samples 56" */
    test_write_file(in_dir("e.exr.json"), t, n);
    free(t);
    copy(in_dir("g1.exr"), in_dir("e.exr"), 0);
    REFUSE("e.exr.json", in_dir("g0.exr"), in_dir("e.exr"), in_dir("g2.exr"));
    copy(in_dir("g1.exr"), in_dir("n.exr"), 0);
    REFUSE("n.exr.json", in_dir("g0.exr"), in_dir("n.exr"), in_dir("g2.exr"));
    /* sidecars with a key twice or absurd numbers, and one whose region is
     * not the image's size (the image's hash still matches), each named */
    static const char *const edits[][3] = {
        {"\"seed\": 7", "\"seed\": 7, \"seed\": 8", "key \"seed\" given twice"},
        {"\"width\": 40", "\"width\": -40", "\"width\" and \"height\""},
        {"\"height\": 30", "\"height\": 1e30", "\"width\" and \"height\""},
        {"\"spp\": 16", "\"spp\": 1e30", "\"spp\" must be"},
        {"\"samples\": [0, 16]", "\"samples\": [-16, 16]", "\"samples\" must be"},
        {"\"region\": [0, ", "\"region\": [-1, ", "\"region\" must be"},
        {", 40, ", ", 41, ", "\"region\" must be"},
        {", 40, ", ", 39, ", "the image is 40x"},
        {"\"seed\": 7", "\"seed\": 1e300", "\"seed\" must be"},
    };
    for (size_t e = 0; e < sizeof edits / sizeof edits[0]; e++) {
        t = test_slurp(in_dir("g1.exr.json"), &n);
        char *at = strstr(t, edits[e][0]), edited[16384];
        assert_non_null(at);
        snprintf(edited, sizeof edited, "%.*s%s%s", (int)(at - t), t, edits[e][1], at + strlen(edits[e][0]));
        free(t);
        test_write_file(in_dir("ed.exr.json"), edited, strlen(edited));
        copy(in_dir("g1.exr"), in_dir("ed.exr"), 0);
        REFUSE(edits[e][2], in_dir("g0.exr"), in_dir("ed.exr"), in_dir("g2.exr"));
        assert_non_null(strstr(err_text, "ed.exr"));
    }
    /* PFM parts: a truncated image, a truncated or missing counts file */
    RUN_OK("-q", "--part", "1/3", "-o", in_dir("q.pfm"), scene);
    static const char *const pfm_cut[][2] = {{"q.pfm", "tq.pfm"}, {"q.count.pfm", "tq.count.pfm"}};
    for (int c = 0; c < 2; c++) {
        copy(in_dir("q.pfm"), in_dir("tq.pfm"), 0);
        copy(in_dir("q.count.pfm"), in_dir("tq.count.pfm"), 0);
        copy(in_dir("q.pfm.json"), in_dir("tq.pfm.json"), 0);
        copy(in_dir(pfm_cut[c][0]), in_dir(pfm_cut[c][1]), 500);
        REFUSE(pfm_cut[c][1], in_dir("g0.exr"), in_dir("tq.pfm"), in_dir("g2.exr"));
    }
    unlink(in_dir("tq.count.pfm"));
    REFUSE("tq.count.pfm", in_dir("g0.exr"), in_dir("tq.pfm"), in_dir("g2.exr"));
    REFUSE("not a part", in_dir("g0.exr"), scene);
    /* the output over a part's own image or sidecar */
    assert_int_equal(RUN("merge", in_dir("g0.exr"), in_dir("g1.exr"), in_dir("g2.exr"), "-o", in_dir("g1.exr")), 2);
    assert_non_null(strstr(err_text, "part's own files"));
    RUN_OK("merge", in_dir("g0.exr"), in_dir("g1.exr"), in_dir("g2.exr"), "-o", in_dir("ok.exr"));
    /* flags */
    REFUSE(NULL, in_dir("g0.exr"), "--bogus");
    REFUSE("needs at least one PART", "--half");
    assert_int_equal(RUN("merge", in_dir("g0.exr"), in_dir("g1.exr"), in_dir("g2.exr")), 2); /* no -o */
    assert_non_null(strstr(err_text, "-o OUT"));
    /* a part must be a float image */
    assert_int_equal(RUN("-q", "--part", "0/3", "-o", in_dir("keep.png"), scene), 2);
    assert_non_null(strstr(err_text, ".exr or .pfm"));
    size_t m;
    char *k = test_slurp(in_dir("keep.png"), &m);
    assert_memory_equal(k, precious, sizeof precious - 1);
    free(k);
    /* bad part flags */
    assert_int_equal(RUN("-q", "--spp-range", "0:17", "-o", in_dir("x.exr"), scene), 2);
    assert_int_equal(RUN("-q", "--crop", "0", "0", "41", "30", "-o", in_dir("x.exr"), scene), 2);
    assert_int_equal(RUN("-q", "--part", "0/31", "-o", in_dir("x.exr"), scene), 2);
    assert_int_equal(RUN("-q", "--part", "0/3", "--crop", "0,0,1,1", "-o", in_dir("x.exr"), scene), 2);
    assert_int_equal(access(in_dir("x.exr"), F_OK), -1);
}

/* --part I/N: the bands tile the image whatever N, and are the same on every run. */
static void test_part_bands(void **state)
{
    (void)state;
    const char *scene = scene_path;
    for (int n = 1; n <= 30; n += 29) {
        int next = 0;
        for (int i = 0; i < n; i++) {
            char part[32];
            snprintf(part, sizeof part, "%d/%d", i, n);
            RUN_OK("-q", "-s", "1", "--part", part, "-o", in_dir("band.exr"), scene);
            size_t sz;
            char *t = test_slurp(in_dir("band.exr.json"), &sz);
            int reg[4];
            const char *s = strstr(t, "\"region\": [");
            assert_non_null(s);
            assert_int_equal(sscanf(s, "\"region\": [%d, %d, %d, %d]", &reg[0], &reg[1], &reg[2], &reg[3]), 4);
            free(t);
            assert_int_equal(reg[0], 0);
            assert_int_equal(reg[2], 40);
            assert_int_equal(reg[1], next);
            assert_true(reg[3] > reg[1]);
            next = reg[3];
        }
        assert_int_equal(next, 30);
    }
}


/* The sidecar's "blocks": [first, count]. */
static void sidecar_blocks(const char *json, int *first, int *count)
{
    size_t n;
    char *t = test_slurp(json, &n);
    const char *s = strstr(t, "\"blocks\": [");
    assert_non_null(s);
    assert_int_equal(sscanf(s, "\"blocks\": [%d, %d]", first, count), 2);
    free(t);
}

/* Merges the NULL-terminated parts into out; asserts it worked. */
static void merge_to(const char *out, const char *const *parts)
{
    const char *args[32] = {"merge"};
    int na = 1;
    for (int i = 0; parts[i]; i++)
        args[na++] = parts[i];
    args[na++] = "-o";
    args[na++] = out;
    args[na] = NULL;
    if (run(args) != 0)
        fail_msg("merge failed: %s", err_text);
}

#define MERGE(out, ...) merge_to(out, (const char *const[]){__VA_ARGS__, NULL})

/* Sample ranges whose edges are multiples of 64 (the sample blocks of
 * rt/render/sample_block.h) merge into exactly the single render's bytes:
 * 2 and 3 ranges, EXR and PFM parts, tiles and passes, 1 and 2 threads,
 * alone and with region parts; the integrator one path at a time (direct)
 * and as a wavefront (path). Before sums were kept in blocks these
 * differed in the last bits (a float sum cannot be regrouped). */
static void test_aligned_ranges_same_bytes(void **state)
{
    (void)state;
    const char *scene = scene_path;
    /* 192 spp: 0:64 + 64:192 */
    RUN_OK("-q", "-r", "16x12", "-s", "192", "-o", in_dir("s192.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "-o", in_dir("s192.png"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "-t", "2", "--spp-range", "0:64", "-o", in_dir("a0.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "-t", "1", "--passes", "0", "--spp-range", "64:192", "-o",
           in_dir("a1.pfm"), scene);
    int first = -1, count = -1;
    sidecar_blocks(in_dir("a1.pfm.json"), &first, &count);
    assert_int_equal(first, 1); /* blocks 1 and 2 kept apart */
    assert_int_equal(count, 2);
    assert_int_equal(access(in_dir("a1.block.2.pfm"), F_OK), 0);
    MERGE(in_dir("m2.pfm"), in_dir("a1.pfm"), in_dir("a0.exr"));
    test_assert_same_bytes(in_dir("m2.pfm"), in_dir("s192.pfm"));
    MERGE(in_dir("m2.png"), in_dir("a0.exr"), in_dir("a1.pfm"));
    test_assert_same_bytes(in_dir("m2.png"), in_dir("s192.png"));
    /* 320 spp: 0:128 + 128:192 + 192:320 */
    RUN_OK("-q", "-r", "16x12", "-s", "320", "-o", in_dir("s320.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "320", "-o", in_dir("s320.png"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "320", "-t", "1", "--passes", "0", "--tile", "5", "--spp-range", "0:128", "-o",
           in_dir("b0.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "320", "-t", "2", "--passes", "7", "--spp-range", "128:192", "-o",
           in_dir("b1.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "320", "-t", "2", "--spp-range", "192:320", "-o", in_dir("b2.exr"), scene);
    MERGE(in_dir("m3.pfm"), in_dir("b2.exr"), in_dir("b0.exr"), in_dir("b1.pfm"));
    test_assert_same_bytes(in_dir("m3.pfm"), in_dir("s320.pfm"));
    MERGE(in_dir("m3.png"), in_dir("b0.exr"), in_dir("b1.pfm"), in_dir("b2.exr"));
    test_assert_same_bytes(in_dir("m3.png"), in_dir("s320.png"));
    /* regions and ranges together: part 0 whole, part 1 in 2 ranges, part 2 in 3 */
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--part", "0/3", "-o", in_dir("q0.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--part", "1/3", "--spp-range", "0:64", "-o", in_dir("q1a.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--part", "1/3", "--spp-range", "64:192", "--passes", "0", "-o",
           in_dir("q1b.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--part", "2/3", "--spp-range", "0:128", "-t", "1", "-o",
           in_dir("q2a.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--part", "2/3", "--spp-range", "128:192", "-o", in_dir("q2b.exr"),
           scene);
    MERGE(in_dir("mq.pfm"), in_dir("q2b.exr"), in_dir("q1b.exr"), in_dir("q0.exr"), in_dir("q1a.pfm"),
          in_dir("q2a.exr"));
    test_assert_same_bytes(in_dir("mq.pfm"), in_dir("s192.pfm"));
    MERGE(in_dir("mq.png"), in_dir("q0.exr"), in_dir("q1a.pfm"), in_dir("q1b.exr"), in_dir("q2a.exr"),
          in_dir("q2b.exr"));
    test_assert_same_bytes(in_dir("mq.png"), in_dir("s192.png"));
    /* one path at a time (direct: tiles) */
    RUN_OK("-q", "-r", "16x12", "-s", "130", "--integrator", "direct", "-o", in_dir("d.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "130", "--integrator", "direct", "--spp-range", "0:64", "-t", "1", "-o",
           in_dir("d0.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "130", "--integrator", "direct", "--spp-range", "64:128", "--passes", "3", "-o",
           in_dir("d1.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "130", "--integrator", "direct", "--spp-range", "128:130", "-o",
           in_dir("d2.pfm"), scene);
    MERGE(in_dir("md.pfm"), in_dir("d0.exr"), in_dir("d1.exr"), in_dir("d2.pfm"));
    test_assert_same_bytes(in_dir("md.pfm"), in_dir("d.pfm"));
    /* a range off the block edges still merges, within the bound */
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--spp-range", "0:100", "-o", in_dir("u0.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "192", "--spp-range", "100:192", "-o", in_dir("u1.exr"), scene);
    MERGE(in_dir("mu.pfm"), in_dir("u0.exr"), in_dir("u1.exr"));
    assert_within_summation_bound(in_dir("mu.pfm"), in_dir("s192.pfm"), 192);
    /* a PFM part's block file damaged: refused, naming it, nothing written */
    copy(in_dir("a1.block.2.pfm"), in_dir("a1.block.2.pfm"), 100);
    assert_int_equal(RUN("merge", in_dir("a0.exr"), in_dir("a1.pfm"), "-o", in_dir("bad.pfm")), 2);
    assert_non_null(strstr(err_text, "a1.block.2.pfm: the image's bytes do not match"));
    assert_int_equal(access(in_dir("bad.pfm"), F_OK), -1);
}

/* --resume stopped inside a block (70 of 200 samples) is exact; so is a
 * part from a block edge resumed and merged after the range before it. */
static void test_resume_inside_a_block(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "-r", "16x12", "-s", "200", "-o", in_dir("s200.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--spp-range", "0:70", "-o", in_dir("r70.exr"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--resume", in_dir("r70.exr"), "-o", in_dir("r.pfm"), scene);
    test_assert_same_bytes(in_dir("r.pfm"), in_dir("s200.pfm"));
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--resume", in_dir("r70.exr"), "--passes", "0", "-o", in_dir("rt.pfm"),
           scene);
    test_assert_same_bytes(in_dir("rt.pfm"), in_dir("s200.pfm"));
    /* samples 64:100, resumed to 64:200, after 0:64 */
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--spp-range", "64:100", "-o", in_dir("k.pfm"), scene);
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--resume", in_dir("k.pfm"), "-o", in_dir("k2.exr"), scene);
    int first = -1, count = -1;
    sidecar_blocks(in_dir("k2.exr.json"), &first, &count);
    assert_int_equal(first, 1);
    assert_int_equal(count, 3);
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--spp-range", "0:64", "-o", in_dir("k0.exr"), scene);
    MERGE(in_dir("mk.pfm"), in_dir("k0.exr"), in_dir("k2.exr"));
    test_assert_same_bytes(in_dir("mk.pfm"), in_dir("s200.pfm"));
    /* ... also when a time limit stopped it (after its first pass) */
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--spp-range", "64:200", "--passes", "1", "--time-limit", TIME_UP, "-o",
           in_dir("kt.exr"), scene);
    assert_int_equal(sidecar_end(in_dir("kt.exr.json")), 65);
    RUN_OK("-q", "-r", "16x12", "-s", "200", "--resume", in_dir("kt.exr"), "-o", in_dir("kt.exr"), scene);
    MERGE(in_dir("mkt.pfm"), in_dir("kt.exr"), in_dir("k0.exr"));
    test_assert_same_bytes(in_dir("mkt.pfm"), in_dir("s200.pfm"));
}

/* A range from a block edge longer than the 64 blocks a part keeps apart
 * says so and merges within the bound. */
static void test_too_many_blocks(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "-r", "3x2", "-s", "4224", "-o", in_dir("big.pfm"), scene); /* 66 blocks */
    RUN_OK("-q", "-r", "3x2", "-s", "4224", "--spp-range", "0:64", "-o", in_dir("big0.exr"), scene);
    assert_int_equal(RUN("-r", "3x2", "-s", "4224", "--spp-range", "64:4224", "-o", in_dir("big1.exr"), scene), 0);
    assert_non_null(strstr(err_text, "keeps at most 64 apart"));
    int first = -1, count = -1;
    sidecar_blocks(in_dir("big1.exr.json"), &first, &count);
    assert_int_equal(first, 65); /* only the last block apart, after the part's own fold */
    assert_int_equal(count, 1);
    MERGE(in_dir("bigm.pfm"), in_dir("big0.exr"), in_dir("big1.exr"));
    assert_within_summation_bound(in_dir("bigm.pfm"), in_dir("big.pfm"), 4224);
}

/* A part written by an rt before sample blocks (format 1) is refused by
 * merge and --resume, naming the file and the format. */
static void test_old_format_refused(void **state)
{
    (void)state;
    const char *scene = scene_path;
    RUN_OK("-q", "--spp-range", "0:8", "-o", in_dir("old.exr"), scene);
    size_t n;
    char *t = test_slurp(in_dir("old.exr.json"), &n);
    char *s = strstr(t, "\"rt_part\": 2");
    assert_non_null(s);
    s[11] = '1';
    test_write_file(in_dir("old.exr.json"), t, n);
    free(t);
    test_write_file(in_dir("keep.png"), precious, sizeof precious - 1);
    assert_int_equal(RUN("merge", in_dir("old.exr"), "-o", in_dir("keep.png")), 2);
    assert_non_null(strstr(err_text, "old.exr.json: part format 1, this rt reads format 2"));
    assert_int_equal(RUN("-q", "--resume", in_dir("old.exr"), "-o", in_dir("keep.png"), scene), 2);
    assert_non_null(strstr(err_text, "old.exr.json: part format 1"));
    size_t m;
    char *k = test_slurp(in_dir("keep.png"), &m);
    assert_int_equal(m, sizeof precious - 1);
    assert_memory_equal(k, precious, m);
    free(k);
}

/* --part I/N balances cost, not area, and the cost is the one part_split.c
 * defines: 1 a ray, 4 more for a ray that finds a surface. The upper half of
 * this view is a lit wall (a camera ray that hits, 1 + 4, and its shadow
 * ray, 1: 6 a pixel), the lower half empty (a camera ray that escapes: 1),
 * so a column costs 32 x 6 + 32 = 224 and the cuts go where the running cost
 * reaches 56, 112 and 168: after rows 9, 18 and 27 (equal area: 16 rows
 * each; rays alone: 12, 24, 40). */
static void test_part_bands_cost(void **state)
{
    (void)state;
    static const char wall[] = "resolution 64 64\nsamples 4\nintegrator direct\n"
                               "camera position 0 0 10 look_at 0 0 0 up 0 1 0 fov 40\n"
                               "material white color 0.8 0.8 0.8\nquad -100 0 0  200 0 0  0 100 0  white\n"
                               "light directional 0 0 -1  1 1 1  1\n";
    test_write_file(in_dir("wall.txt"), wall, sizeof wall - 1);
    static const int cuts[5] = {0, 10, 19, 28, 64};
    for (int i = 0; i < 4; i++) {
        char part[16];
        snprintf(part, sizeof part, "%d/4", i);
        RUN_OK("-q", "--part", part, "-o", in_dir("wb.exr"), in_dir("wall.txt"));
        size_t sz;
        char *t = test_slurp(in_dir("wb.exr.json"), &sz);
        const char *s = strstr(t, "\"region\": [");
        int reg[4];
        assert_non_null(s);
        assert_int_equal(sscanf(s, "\"region\": [%d, %d, %d, %d]", &reg[0], &reg[1], &reg[2], &reg[3]), 4);
        free(t);
        assert_int_equal(reg[1], cuts[i]);
        assert_int_equal(reg[3], cuts[i + 1]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parts_1_3_7_same_bytes),
        cmocka_unit_test(test_crop_parts_same_bytes),
        cmocka_unit_test(test_sample_ranges),
        cmocka_unit_test(test_resume_exact),
        cmocka_unit_test(test_time_limit_then_resume),
        cmocka_unit_test(test_time_limit_tiling_integrator),
        cmocka_unit_test(test_interrupt_then_resume),
        cmocka_unit_test(test_merge_refusals),
        cmocka_unit_test(test_aov_parts),
        cmocka_unit_test(test_aov_parts_media),
        cmocka_unit_test(test_frames),
        cmocka_unit_test(test_frames_animated_gltf),
        cmocka_unit_test(test_frames_one_camera),
        cmocka_unit_test(test_frames_stopped_then_resumed),
        cmocka_unit_test(test_animation_index),
        cmocka_unit_test(test_motion_blur),
        cmocka_unit_test(test_part_bands),
        cmocka_unit_test(test_aligned_ranges_same_bytes),
        cmocka_unit_test(test_resume_inside_a_block),
        cmocka_unit_test(test_too_many_blocks),
        cmocka_unit_test(test_old_format_refused),
        cmocka_unit_test(test_part_bands_cost),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
