/* test_cli.c - the `rt` command as a user meets it: run as a subprocess
 * ($RT_BIN, default ./rt) with bad flags, bad scene files, bad models and
 * images made here, unwritable outputs and resource limits. Each must exit
 * with status 2, print a message naming the file (and line or byte) and
 * what is wrong, leave an existing output image byte-identical and leave no
 * temporary file behind. Then the good paths that are easy to get wrong:
 * Ctrl-C / SIGTERM (exit 130 / 143; in passes the whole image at the
 * samples reached goes to the output, tiles to NAME.partial.EXT with the
 * output left alone), --time-limit, a second Ctrl-C (exits at once, the
 * old image kept), a 1x1 image, the same bytes from 1, 64 and
 * more-threads-than-tiles renders, and --display-server against a tev
 * stand-in on loopback that decodes tev's packets.
 */
#define _XOPEN_SOURCE 700 /* posix_openpt: a terminal for the progress line */
#include "test_util.h"
#include "test_terminal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <stb/stb_image.h>

#include "rt/io/image_write.h"
#include "rt/io/image_read.h"

static char dir[256];     /* this run's scratch directory */
static char out_png[512]; /* the "earlier image" every failing run must leave alone */
static const char precious[] = "\x89PNG not really, but an earlier image the user wants to keep\n";

static const char *rt_bin(void)
{
    const char *b = getenv("RT_BIN");
    return b && *b ? b : "./rt";
}

/* rt_bin() as an absolute path, for a child that changes directory or
 * runs under another program. */
static const char *rt_bin_absolute(void)
{
    static char bin[4096], cwd[3000];
    if (rt_bin()[0] != '/' && getcwd(cwd, sizeof cwd))
        snprintf(bin, sizeof bin, "%s/%s", cwd, rt_bin());
    else
        snprintf(bin, sizeof bin, "%s", rt_bin());
    return bin;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

static const char *path_in(const char *name)
{
    static char buf[32][600]; /* the last 32 results stay valid */
    static int k;
    k = (k + 1) % 32;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void write_text(const char *name, const char *text)
{
    test_write_file(path_in(name), text, strlen(text));
}

static size_t read_all(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return (size_t)-1;
    size_t n = fread(buf, 1, cap - 1, f);
    buf[n] = 0;
    fclose(f);
    return n;
}

static void copy_file(const char *from, const char *to)
{
    static char buf[1 << 20];
    size_t n = read_all(from, buf, sizeof buf);
    assert_true(n != (size_t)-1);
    test_write_file(to, buf, n);
}

typedef struct run_result {
    int status;   /* exit status, or -1 when killed by a signal */
    int signal;   /* the signal that killed it, else 0 */
    double seconds;
    char err[16384]; /* stderr */
} run_result;

/* Runs rt with args; its stdout goes to stdout_path (NULL = /dev/null), its
 * stderr to stderr.txt in the scratch directory. */
static const char *stdin_path; /* the child's standard input when set, else /dev/null */
static const char *child_dir;  /* the child's working directory when set */

/* argv (cap entries) = program, then the NULL-terminated args, then NULL. */
static void make_argv(const char **argv, int cap, const char *program, const char *const *args)
{
    int n = 0;
    argv[n++] = program;
    for (int i = 0; args[i] && n < cap - 1; i++)
        argv[n++] = args[i];
    argv[n] = NULL;
}

static pid_t spawn_to(const char *const *args, const char *stdout_path)
{
    const char *argv[64];
    make_argv(argv, 64, rt_bin_absolute(), args);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int null = stdout_path ? open(stdout_path, O_WRONLY | O_CREAT | O_TRUNC, 0644) : open("/dev/null", O_WRONLY);
        int e = open(path_in("stderr.txt"), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (null < 0 || e < 0)
            _exit(127);
        int in = open(stdin_path ? stdin_path : "/dev/null", O_RDONLY);
        if (in < 0)
            _exit(127);
        dup2(in, 0);
        dup2(null, 1);
        dup2(e, 2);
        if (child_dir && chdir(child_dir) != 0)
            _exit(127);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    return pid;
}

static pid_t spawn(const char *const *args)
{
    return spawn_to(args, NULL);
}

static void wait_for(pid_t pid, double t0, double timeout, run_result *r)
{
    int st = 0;
    for (;;) {
        pid_t w = waitpid(pid, &st, WNOHANG);
        if (w == pid)
            break;
        assert_true(w == 0 || errno == EINTR);
        if (now_s() - t0 > timeout) {
            kill(pid, SIGKILL);
            waitpid(pid, &st, 0);
            fail_msg("%s did not finish within %.0f s", rt_bin(), timeout);
        }
        sleep_s(0.002);
    }
    r->seconds = now_s() - t0;
    r->status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r->signal = WIFSIGNALED(st) ? WTERMSIG(st) : 0;
    if (read_all(path_in("stderr.txt"), r->err, sizeof r->err) == (size_t)-1)
        r->err[0] = 0;
    if (r->status == 127)
        fail_msg("could not run %s (build it first, or set RT_BIN)", rt_bin());
}

static void run_args(run_result *r, const char *const *args)
{
    double t0 = now_s();
    wait_for(spawn(args), t0, 120.0, r);
}

/* No .rt-tmp-* file may be left in the scratch directory. */
static void assert_no_temp_files(void)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    char left[300] = "";
    while ((e = readdir(d)))
        if (strncmp(e->d_name, ".rt-tmp-", 8) == 0)
            snprintf(left, sizeof left, "%s", e->d_name);
    closedir(d); /* before failing: fail_msg does not return */
    if (left[0])
        fail_msg("temporary file %s/%s left behind", dir, left);
}

static void put_precious(const char *path)
{
    test_write_file(path, precious, sizeof precious - 1);
}

static void assert_precious(const char *path)
{
    char buf[256];
    size_t n = read_all(path, buf, sizeof buf);
    assert_int_equal(n, sizeof precious - 1);
    assert_memory_equal(buf, precious, n);
}

static void assert_contains(const char *hay, const char *needle)
{
    if (needle && !strstr(hay, needle))
        fail_msg("expected \"%s\" in rt's message:\n%s", needle, hay);
}

/* How many times needle occurs in hay. */
static int count_of(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle))
        n++;
    return n;
}

/* Runs rt with args (NULL-terminated) and expects a clean refusal: exit 2,
 * a message with both fragments, `protect` (an existing image) untouched. */
static void expect_refusal_v(const char *protect, const char *msg1, const char *msg2, const char *const *args)
{
    put_precious(protect);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, args);
    if (r->status != 2) {
        fprintf(stderr, "args:");
        for (int i = 0; args[i]; i++)
            fprintf(stderr, " %s", args[i]);
        fail_msg("\nexpected exit status 2, got %d (signal %d); stderr:\n%s", r->status, r->signal, r->err);
    }
    assert_true(strncmp(r->err, "rt: ", 4) == 0);
    assert_contains(r->err, msg1);
    assert_contains(r->err, msg2);
    assert_null(strstr(r->err, "internal error"));
    assert_precious(protect);
    assert_no_temp_files();
    free(r);
}

#define REFUSE(protect, m1, m2, ...)                                                                                   \
    do {                                                                                                               \
        const char *const args_[] = {__VA_ARGS__, NULL};                                                               \
        expect_refusal_v(protect, m1, m2, args_);                                                                      \
    } while (0)

/* --------------------------------------------------------------- setup */

static int setup(void **state)
{
    (void)state;
    if (!test_make_dir(dir, sizeof dir, "cli"))
        return -1;
    snprintf(out_png, sizeof out_png, "%s/out.png", dir);
    if (access(rt_bin(), X_OK) != 0) {
        fprintf(stderr, "test_cli: %s is not built (make rt, or set RT_BIN)\n", rt_bin());
        return -1;
    }
    return 0;
}

static void stop_xvfb(void);

static int teardown(void **state)
{
    (void)state;
    stop_xvfb();
    test_remove_dir(dir);
    return 0;
}

static void assert_same_file(const char *a, const char *b)
{
    static char x[1 << 20], y[1 << 20];
    size_t n = read_all(a, x, sizeof x), m = read_all(b, y, sizeof y);
    assert_true(n != (size_t)-1 && m != (size_t)-1);
    assert_int_equal(n, m);
    assert_memory_equal(x, y, n);
}

static void render_ok(const char *out, const char *const *extra)
{
    const char *args[32] = {"-q", "-o", out};
    int n = 3;
    for (int i = 0; extra[i]; i++)
        args[n++] = extra[i];
    args[n] = NULL;
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, args);
    if (r->status != 0)
        fail_msg("render to %s failed (%d): %s", out, r->status, r->err);
    free(r);
}

/* --------------------------------------------------------------- flags */

static void test_bad_flags(void **state)
{
    (void)state;
    const char *o = out_png;
    REFUSE(o, "-s wants samples per pixel", "'0'", "-s", "0", "-o", o);
    REFUSE(o, "-s wants", "2000000", "-s", "2000000", "-o", o);
    REFUSE(o, "-r wants", "'0x5'", "-r", "0x5", "-o", o);
    REFUSE(o, "-r wants", "40000x10", "-r", "40000x10", "-o", o);
    REFUSE(o, "-r wants", "'640'", "-r", "640", "-o", o);
    REFUSE(o, "-t wants a thread count", "'0'", "-t", "0", "-o", o);
    REFUSE(o, "-t wants", "'many'", "-t", "many", "-o", o);
    REFUSE(o, "--tile wants", "'0'", "--tile", "0", "-o", o);
    REFUSE(o, "--integrator wants", "'magic'", "--integrator", "magic", "-o", o);
    REFUSE(o, "--max-memory wants a size", "'lots'", "--max-memory", "lots", "-o", o);
    REFUSE(o, "--max-memory", "below the 64M", "--max-memory", "1M", "-o", o);
    REFUSE(o, "--max-memory wants a size", "'0x10G'", "--max-memory", "0x10G", "-o", o); /* hexadecimal, as strtod reads */
    REFUSE(o, "--max-memory wants a size", "'0'", "--max-memory", "0", "-o", o);           /* 'none' says no limit */
    REFUSE(o, "--max-memory wants a size", "'0.0000001K'", "--max-memory", "0.0000001K", "-o", o); /* rounds to 0 */
    REFUSE(o, "--max-memory wants a size", "'-1G'", "--max-memory", "-1G", "-o", o);
    REFUSE(o, "--max-memory wants a size", "'1.2.3G'", "--max-memory", "1.2.3G", "-o", o);
    REFUSE(o, "--preview wants", "'0'", "--preview", "0", "-o", o);
    REFUSE(o, "--time-limit wants seconds (more than 0, at most 1e7)", "'0'", "--time-limit", "0", "-o", o);
    REFUSE(o, "--time-limit wants", "'-1'", "--time-limit", "-1", "-o", o);
    REFUSE(o, "--time-limit wants", "'soon'", "--time-limit", "soon", "-o", o);
    REFUSE(o, "--time-limit wants", "'nan'", "--time-limit", "nan", "-o", o);
    REFUSE(o, "--time-limit wants", "'2x'", "--time-limit", "2x", "-o", o);
    REFUSE(o, "option --time-limit needs a value", NULL, "--time-limit");
    REFUSE(o, "--passes wants samples per pixel a pass from 0 (tiles)", "'-1'", "--passes", "-1", "-o", o);
    REFUSE(o, "--passes wants", "'1.5'", "--passes", "1.5", "-o", o);
    REFUSE(o, "--passes wants", "'many'", "--passes", "many", "-o", o);
    REFUSE(o, "--passes wants", "'99999999999'", "--passes", "99999999999", "-o", o);
    REFUSE(o, "--display-server wants HOST:PORT", "'tev'", "--display-server", "tev", "-o", o);
    REFUSE(o, "--display-server wants", "'127.0.0.1:99999'", "--display-server", "127.0.0.1:99999", "-o", o);
    REFUSE(o, "--display-server wants", "'[::1:14158'", "--display-server", "[::1:14158", "-o", o);
    REFUSE(o, "--display-server wants", "'::1]:14158'", "--display-server", "::1]:14158", "-o", o);
    REFUSE(o, "unknown option", "'--bogus'", "--bogus", "-o", o);
    REFUSE(o, "only one input", "b.txt", "a.txt", "b.txt", "-o", o);
    REFUSE(o, "option -o needs a value", NULL, "-o");
    REFUSE(o, "--camera 3", "0 cameras", "--camera", "3", "-o", o);
}

/* The flags as users expect them: long forms, --flag=value, a missing value
 * named, --set for any scene setting with the scene format's checks. */
static void test_flag_forms(void **state)
{
    (void)state;
    const char *o = out_png;
    REFUSE(o, "option -s needs a value", NULL, "-s", "-o", o); /* not "got '-o'" */
    REFUSE(o, "option --samples needs a value", NULL, "--samples", "--quiet", "-o", o);
    REFUSE(o, "option --set needs a value", NULL, "-o", o, "--set");
    REFUSE(o, "option --quiet takes no value", "'--quiet=yes'", "--quiet=yes", "-o", o);
    REFUSE(o, "--samples wants samples per pixel", "'0'", "--samples=0", "-o", o);
    REFUSE(o, "--resolution wants", "'0X5'", "--resolution", "0X5", "-o", o);
    REFUSE(o, "--threads wants a thread count", "'0'", "--threads=0", "-o", o);
    REFUSE(o, "-t wants", "'-1'", "-t", "-1", "-o", o); /* a negative number is a value, not a flag */
    REFUSE(o, "--output", "needs a value", "--output");
    REFUSE(o, "--set samples=0: ", "samples per pixel must be between 1 and 1048576, got '0'", "--set", "samples=0",
           "-o", o);
    REFUSE(o, "--set max_bounce=300: ", "max_bounce must be between 0 and 256", "--set=max_bounce=300", "-o", o);
    REFUSE(o, "--set exposure=0: ", "the exposure must be > 0, got '0'", "--set", "exposure=0", "-o", o);
    REFUSE(o, "--set background=1,-1,0: ", "the background colour (green) must be >= 0", "--set",
           "background=1,-1,0", "-o", o);
    REFUSE(o, "--set resolution=640: ", "expected an integer for the image height, got nothing", "--set",
           "resolution=640", "-o", o);
    REFUSE(o, "--set wants KEY=VALUE", "'samples'", "--set", "samples", "-o", o);
    REFUSE(o, "no setting is called 'sampels'", "samples, integrator", "--set", "sampels=4", "-o", o);
    /* applied after loading, so file errors come then, named by the flag */
    char env[700];
    snprintf(env, sizeof env, "environment=%s", path_in("no-such.hdr"));
    REFUSE(o, "--set environment=", "no-such.hdr", "--set", env, "-o", o);
    /* over the scene's own values, then through the same limits */
    write_text("tree2.txt", "resolution 8 8\nintegrator whitted\ndiffuse_bounces 1\n");
    REFUSE(o, "tree2.txt: ", "rays per camera sample", path_in("tree2.txt"), "--set", "diffuse_rays=1000", "--set",
           "diffuse_bounces=5", "-o", o);
}

static void test_flag_forms_same_image(void **state)
{
    (void)state;
    char ref[600];
    snprintf(ref, sizeof ref, "%s", path_in("forms-ref.pfm"));
    const char *const shorts[] = {"-r", "12x10", "-s", "2", "-t", "1", "--seed", "3", "--integrator", "whitted", NULL};
    render_ok(ref, shorts);
    const char *const longs[] = {"--resolution=12X10", "--samples", "2", "--threads=1", "--seed=3",
                                 "--integrator=whitted", "--quiet", NULL};
    const char *const sets[] = {"--set", "resolution=12,10", "--set", "samples=2", "--set=seed=3", "--set",
                                "integrator=whitted", "-t", "1", NULL};
    const char *const later[] = {"-s", "64", "--set", "samples=2", "-r", "99x99", "--set", "resolution=12x10",
                                 "--seed", "3", "--set", "integrator=path", "--integrator", "whitted", NULL};
    const char *const *variants[] = {longs, sets, later};
    for (size_t i = 0; i < sizeof variants / sizeof *variants; i++) {
        char out[600];
        snprintf(out, sizeof out, "%s/forms-%zu.pfm", dir, i);
        render_ok(out, variants[i]);
        assert_same_file(ref, out);
        unlink(out);
    }
    /* a scene file saying the same, and `--` before the input */
    write_text("forms.txt", "resolution 99 99\nsamples 64\nseed 3\nintegrator whitted\n");
    char a[600], b[600];
    snprintf(a, sizeof a, "%s", path_in("forms-a.pfm"));
    snprintf(b, sizeof b, "%s", path_in("forms-b.pfm"));
    const char *const scene_then_flags[] = {"--set", "resolution=12x10", "-s", "2", "--", path_in("forms.txt"), NULL};
    render_ok(a, scene_then_flags);
    write_text("forms2.txt", "resolution 12 10\nsamples 2\nseed 3\nintegrator whitted\n");
    const char *const scene_alone[] = {path_in("forms2.txt"), NULL};
    render_ok(b, scene_alone);
    assert_same_file(a, b);
    unlink(ref), unlink(a), unlink(b);
}

static bool same_file(const char *a, const char *b)
{
    static char x[1 << 20], y[1 << 20];
    size_t n = read_all(a, x, sizeof x), m = read_all(b, y, sizeof y);
    assert_true(n != (size_t)-1 && m != (size_t)-1);
    return n == m && memcmp(x, y, n) == 0;
}

/* --camera auto and the pose flags: the same image as a scene file saying
 * the same; bad values and a degenerate camera refused, naming the flags. */
static void test_camera_flags(void **state)
{
    (void)state;
    const char *o = out_png;
    static const char body[] = "resolution 16 12\nsamples 1\nmaterial m color 0.8 0.3 0.2\n"
                               "sphere 0 0 0 1 m\nsphere 1.5 0 -1 0.5 m\n";
    char text[1024];
    write_text("cam-none.txt", body);
    snprintf(text, sizeof text, "%scamera position 1 2 6 look_at 0.5 0 0 up 0 1 0 fov 35\n", body);
    write_text("cam-own.txt", text);
    char a[600], b[600];
    snprintf(a, sizeof a, "%s", path_in("cam-a.pfm"));
    snprintf(b, sizeof b, "%s", path_in("cam-b.pfm"));
    /* the pose on the command line = the pose in the file */
    const char *const own[] = {path_in("cam-own.txt"), NULL};
    render_ok(a, own);
    const char *const flags[] = {"--look-from", "1,2,6", "--look-at=0.5,0,0", "--up", "0,1,0", "--fov", "35",
                                 path_in("cam-none.txt"), NULL};
    render_ok(b, flags);
    assert_same_file(a, b);
    /* and over the file's own camera */
    snprintf(text, sizeof text, "%scamera position 3 3 3 look_at 0.5 0 0 fov 60\n", body);
    write_text("cam-other.txt", text);
    const char *const over[] = {"--fov", "35", "--look-from", "1,2,6", path_in("cam-other.txt"), NULL};
    render_ok(b, over);
    assert_same_file(a, b);
    /* --camera auto ignores the file's camera: the image of the file without one */
    const char *const none[] = {path_in("cam-none.txt"), NULL};
    render_ok(a, none);
    const char *const autocam[] = {"--camera", "auto", path_in("cam-own.txt"), NULL};
    render_ok(b, autocam);
    assert_same_file(a, b);
    /* a glTF's own camera, then framed automatically: a different view */
    const char *const gltf_own[] = {"-r", "16x12", "-s", "1", "assets/box.gltf", NULL};
    render_ok(a, gltf_own);
    const char *const gltf_auto[] = {"-r", "16x12", "-s", "1", "--camera=auto", "assets/box.gltf", NULL};
    render_ok(b, gltf_auto);
    assert_false(same_file(a, b));
    unlink(a), unlink(b);

    REFUSE(o, "--look-from wants three numbers X,Y,Z", "'0,1'", "--look-from", "0,1", "-o", o);
    REFUSE(o, "--look-at wants three numbers", "'0,1,x'", "--look-at", "0,1,x", "-o", o);
    REFUSE(o, "--look-at wants three numbers", "'0,1,2,3'", "--look-at", "0,1,2,3", "-o", o);
    REFUSE(o, "--up wants a direction", "'0,0,0'", "--up", "0,0,0", "-o", o);
    REFUSE(o, "--fov wants a field of view in degrees between 0 and 180", "'180'", "--fov", "180", "-o", o);
    REFUSE(o, "--fov wants", "'-5'", "--fov", "-5", "-o", o);
    REFUSE(o, "--camera wants a camera index (0, 1, ...) or 'auto'", "'front'", "--camera", "front", "-o", o);
    REFUSE(o, "--look-from 0,1,3 --look-at 0,1,3: the camera is degenerate", NULL, "-r", "8x8", "--look-from",
           "0,1,3", "--look-at", "0,1,3", "-o", o);
    REFUSE(o, "--look-at 0,5,0 --up 0,1,0: the camera is degenerate", NULL, "-r", "8x8", "--look-at", "0,5,0", "--up",
           "0,1,0", "--look-from", "0,0,0", "-o", o);
}

/* What users of pbrt-v4, Mitsuba 3 and Blender type: the aliases --spp,
 * --outfile, --nthreads and -D KEY=VALUE, values attached to short flags
 * (-s2, -r12x10, -Dseed=3), blanks in comma lists: each the same image as
 * rt's own spelling. A mistyped flag gets the nearest name. */
static void test_flag_conveniences(void **state)
{
    (void)state;
    const char *o = out_png;
    char ref[600], out[600];
    snprintf(ref, sizeof ref, "%s", path_in("conv-ref.pfm"));
    snprintf(out, sizeof out, "%s", path_in("conv.pfm"));
    const char *const own[] = {"-r", "12x10", "-s", "2", "-t", "1", "--set", "seed=3", "--look-from", "0,1,3.5",
                               "--aov", "albedo,normal", NULL};
    render_ok(ref, own);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-q", "--outfile", out, "--spp", "2", "--nthreads", "1", "-D", "seed=3", "-r",
                                      "12x10", "--look-from", "0, 1, 3.5", "--aov", "albedo, normal", NULL});
    assert_int_equal(r->status, 0);
    assert_same_file(ref, out);
    unlink(out);
    run_args(r, (const char *const[]){"-q", "-s2", "-r12x10", "-t1", "-Dseed=3", "--spp=2", "--look-from",
                                      " 0 ,1,3.5 ", "--aov=albedo , normal", "-o", out, NULL});
    assert_int_equal(r->status, 0);
    assert_same_file(ref, out);
    /* the wrote line names the AOV files, or an EXR's layers */
    run_args(r, (const char *const[]){"-r", "12x10", "-s", "1", "--aov", "albedo,normal", "-o", path_in("conv.png"),
                                      NULL});
    assert_int_equal(r->status, 0);
    char line[1400];
    snprintf(line, sizeof line, "wrote %s and %s, %s: 12x10", path_in("conv.png"), path_in("conv.albedo.pfm"),
             path_in("conv.normal.pfm"));
    assert_contains(r->err, line);
    run_args(r, (const char *const[]){"-r", "12x10", "-s", "1", "--aov", "depth,albedo", "-o", path_in("conv.exr"),
                                      NULL});
    assert_int_equal(r->status, 0);
    snprintf(line, sizeof line, "wrote %s (layers albedo, depth): 12x10", path_in("conv.exr"));
    assert_contains(r->err, line);
    free(r);
    unlink(ref), unlink(out), unlink(path_in("conv.png")), unlink(path_in("conv.exr"));
    unlink(path_in("conv.albedo.pfm")), unlink(path_in("conv.normal.pfm"));
    unlink(path_in("conv-ref.albedo.pfm")), unlink(path_in("conv-ref.normal.pfm"));

    REFUSE(o, "unknown option '--sampels' (did you mean '--samples'?)", NULL, "--sampels", "4", "-o", o);
    REFUSE(o, "unknown option '--fvo' (did you mean '--fov'?)", NULL, "--fvo=30", "-o", o);
    REFUSE(o, "unknown option '-spp' (did you mean '--spp'?)", NULL, "-spp", "4", "-o", o); /* not -s "pp" */
    REFUSE(o, "unknown option '-qv'", NULL, "-qv", "-o", o); /* no bundled short flags */
    REFUSE(o, "-s wants samples per pixel", "'0'", "-s0", "-o", o);
    REFUSE(o, "--spp wants samples per pixel", "'0'", "--spp=0", "-o", o);
    REFUSE(o, "-r wants", "'0x5'", "-r0x5", "-o", o);
    REFUSE(o, "-D samples=0: ", "samples per pixel must be between 1 and 1048576", "-Dsamples=0", "-o", o);
    REFUSE(o, "--nthreads wants a thread count", "'0'", "--nthreads", "0", "-o", o);
    REFUSE(o, "--look-from wants three numbers", "'0, , 5'", "--look-from", "0, , 5", "-o", o);
    REFUSE(o, "--aov: unknown AOV", "'nope'", "--aov", "albedo, nope", "-o", o);
}

/* Every flag `rt --help` lists is in README.md's flag table ("Using it"). */
static void test_help_flags_in_readme(void **state)
{
    (void)state;
    const char *const args[] = {"--help", NULL};
    const char *help_path = path_in("help.txt");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    double t0 = now_s();
    wait_for(spawn_to(args, help_path), t0, 60.0, r);
    assert_int_equal(r->status, 0);
    free(r);
    static char help[1 << 16], readme[1 << 17];
    assert_true(read_all(help_path, help, sizeof help) != (size_t)-1);
    assert_true(read_all("README.md", readme, sizeof readme) != (size_t)-1);
    char *table = strstr(readme, "\n## Using it\n");
    assert_non_null(table);
    char *end = strstr(table + 1, "\n## ");
    if (end)
        *end = '\0';
    int flags = 0, missing = 0;
    for (char *line = strtok(help, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, "  ", 2) != 0)
            continue;
        char *c = line;
        while (*c == ' ')
            c++;
        if (*c != '-')
            continue;
        /* "-s, --samples N     samples per pixel ...": the names end at two blanks */
        char names[128];
        char *gap = strstr(c, "  ");
        size_t n = gap ? (size_t)(gap - c) : strlen(c);
        snprintf(names, sizeof names, "%.*s", (int)n, c);
        for (char *name = names; name && *name;) {
            char *next = strstr(name, ", ");
            if (next)
                *next = '\0', next += 2;
            size_t len = strcspn(name, " =");
            char needle[64];
            snprintf(needle, sizeof needle, "`%.*s", (int)len, name);
            bool found = false;
            for (const char *p = strstr(table, needle); p && !found; p = strstr(p + 1, needle)) {
                char after = p[strlen(needle)];
                found = after == ' ' || after == '`' || after == '=';
            }
            if (!found) {
                fprintf(stderr, "README.md's flag table has no %s`\n", needle);
                missing++;
            }
            flags++;
            name = next;
        }
    }
    assert_true(flags >= 20);
    assert_int_equal(missing, 0);
    unlink(help_path);
}

/* Every line rt writes to stderr starts with "rt: ", the -v lines too. */
static void assert_lines_prefixed(const char *err)
{
    int lines = 0;
    for (const char *l = err; *l; lines++) {
        if (strncmp(l, "rt: ", 4) != 0)
            fail_msg("a line without the 'rt: ' prefix:\n%s", l);
        const char *nl = strchr(l, '\n');
        l = nl ? nl + 1 : l + strlen(l);
    }
    assert_true(lines > 0);
}

static void test_verbose_lines_prefixed(void **state)
{
    (void)state;
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *const args[] = {"-v", "-r", "8x8", "-s", "1", "-o", path_in("v.png"), NULL};
    run_args(r, args);
    assert_int_equal(r->status, 0);
    assert_contains(r->err, "rt: kd-tree: built in");
    assert_contains(r->err, "rt: render: ");
    assert_lines_prefixed(r->err);
    unlink(path_in("v.png"));
    free(r);
}

/* `rt` alone renders the built-in scene and says so first, unless -q. */
static void test_no_input_says_so(void **state)
{
    (void)state;
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *const args[] = {"-r", "8x8", "-s", "1", "-o", path_in("b.png"), NULL};
    run_args(r, args);
    assert_int_equal(r->status, 0);
    char want[800];
    snprintf(want, sizeof want,
             "rt: no input given; rendering the built-in Cornell box to %s (rt --help for usage)\n", path_in("b.png"));
    assert_true(strncmp(r->err, want, strlen(want)) == 0);
    const char *const quiet[] = {"-q", "-r", "8x8", "-s", "1", "-o", path_in("b.png"), NULL};
    run_args(r, quiet);
    assert_int_equal(r->status, 0);
    assert_string_equal(r->err, "");
    unlink(path_in("b.png"));
    free(r);
}

/* ------------------------------------------------------------ scene files */

static void test_bad_scene_files(void **state)
{
    (void)state;
    const char *o = out_png;
    /* file, its text (NULL: no such file), the message's two fragments */
    static const struct {
        const char *file, *text, *msg1, *msg2;
    } bad[] = {
        {"kw.txt", "resolution 16 16\nbogus 1 2\n", "kw.txt:2:1: ", "unknown keyword 'bogus'"},
        {"nan.txt", "resolution 16 16\ncamera position 0 1 nan look_at 0 0 0\n", "nan.txt:2:21: ", "'nan'"},
        {"inf.txt", "resolution 16 16\ncamera position 0 1 2 look_at 0 0 0 fov inf\n", "inf.txt:2:", "'inf'"},
        {"cam.txt", "resolution 16 16\ncamera position 0 0 0 look_at 0 0 0\n", "cam.txt:2:",
         "look_at point equals its position"},
        {"spp.txt", "samples 2000000\n", "spp.txt:1:9: ", "between 1 and 1048576"},
        {"res.txt", "resolution 40000 10\n", "res.txt:1:12: ", "between 1 and 32768"},
        {"depth.txt", "max_bounce 1000\n", "depth.txt:1:12: ", "max_bounce must be between 0 and 256"},
        {"tree.txt", "resolution 8 8\nintegrator whitted\ndiffuse_rays 1000\ndiffuse_bounces 5\n", "tree.txt: ",
         "rays per camera sample"},
        {"badnum.txt", "resolution 16 16x\n", "badnum.txt:1:", NULL},
        {"missing.txt", NULL, "missing.txt: cannot open", NULL},
        {"mesh.txt", "mesh missing.obj\n", "missing.obj", NULL},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        if (bad[i].text)
            write_text(bad[i].file, bad[i].text);
        REFUSE(o, bad[i].msg1, bad[i].msg2, path_in(bad[i].file), "-o", o);
    }
    /* the scene's own output line is protected the same way */
    char own[700];
    snprintf(own, sizeof own, "output \"%s\"\nbogus\n", o);
    write_text("own.txt", own);
    REFUSE(o, "own.txt:2:1: ", NULL, path_in("own.txt"));
}

/* `-` is standard input (scene text, glTF or a mesh by content); a
 * directory and an unknown extension are refused; an empty scene warns. */
static void test_inputs(void **state)
{
    (void)state;
    const char *o = out_png;
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    /* the same scene from a file and from standard input: the same image */
    write_text("in.txt", "resolution 12 10\nsamples 2\nmaterial m color 0.8 0.2 0.2\nsphere 0 0 -3 1 m\n");
    char a[600], b[600];
    snprintf(a, sizeof a, "%s", path_in("in-file.pfm"));
    snprintf(b, sizeof b, "%s", path_in("in-stdin.pfm"));
    const char *const from_file[] = {path_in("in.txt"), NULL};
    render_ok(a, from_file);
    stdin_path = path_in("in.txt");
    const char *const from_stdin[] = {"-", NULL};
    render_ok(b, from_stdin);
    assert_same_file(a, b);
    /* errors in it are named <stdin> */
    write_text("bad-in.txt", "resolution 8 8\nsphere 0 0 0 1 stel\n");
    stdin_path = path_in("bad-in.txt");
    REFUSE(o, "<stdin>:2:16: undefined material 'stel'", NULL, "-", "-o", o);
    /* a glTF and an OBJ by content */
    stdin_path = "assets/box.gltf";
    const char *const gltf[] = {"-r", "8x8", "-", NULL};
    render_ok(a, gltf);
    stdin_path = "assets/donut.obj";
    render_ok(a, gltf);
    const char *const info[] = {"--info", "-", NULL};
    run_result *ri = malloc(sizeof *ri);
    assert_non_null(ri);
    wait_for(spawn_to(info, path_in("info.txt")), now_s(), 60.0, ri);
    assert_int_equal(ri->status, 0);
    static char text[4096];
    assert_true(read_all(path_in("info.txt"), text, sizeof text) != (size_t)-1);
    assert_contains(text, "file: <stdin>\nformat: mesh\n");
    free(ri);
    stdin_path = NULL;

    REFUSE(o, "is a directory", NULL, dir, "-o", o);
    write_text("cube.stl", "solid cube\n  facet normal 0 0 1\n");
    REFUSE(o, "cube.stl: unknown input format '.stl'", ".obj, .ply, .off", path_in("cube.stl"), "-o", o);

    /* a scene with nothing in it renders the background, with a warning */
    write_text("empty.txt", "resolution 8 8\n");
    const char *const empty[] = {"-o", a, path_in("empty.txt"), NULL};
    run_args(r, empty);
    assert_int_equal(r->status, 0);
    assert_contains(r->err, "rt: warning: ");
    assert_contains(r->err, "empty.txt: nothing to render");
    unlink(a), unlink(b);
    free(r);
}

/* Runs rt with args, its stdout into buf; returns the exit status. */
static int run_stdout(const char *const *args, char *buf, size_t cap)
{
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    wait_for(spawn_to(args, path_in("stdout.txt")), now_s(), 60.0, r);
    int status = r->status;
    free(r);
    assert_true(read_all(path_in("stdout.txt"), buf, cap) != (size_t)-1);
    unlink(path_in("stdout.txt"));
    return status;
}

/* --info reports the file's own camera and settings, for every file given. */
static void test_info(void **state)
{
    (void)state;
    static char text[1 << 14];
    write_text("i1.txt", "resolution 12 10\nsamples 3\nintegrator whitted\noutput i1-out.pfm\n"
                         "camera position 0 1 5 look_at 0 1 0 fov 30\nmaterial m\nsphere 0 0 0 1 m\n");
    write_text("i2.txt", "material m\nsphere 0 0 0 1 m\n");
    const char *const args[] = {"--info", path_in("i1.txt"), path_in("i2.txt"), "assets/box.gltf", "assets/donut.obj",
                                NULL};
    assert_int_equal(run_stdout(args, text, sizeof text), 0);
    char *b2 = strstr(text, "\n\nfile: ");
    assert_non_null(b2);
    *b2 = 0;
    b2 += 2;
    assert_contains(text, "format: scene\n");
    assert_contains(text, "camera: scene file\ncamera.position: 0 1 5\ncamera.look_at: 0 1 0\ncamera.up: 0 1 0\n"
                          "camera.fov: 30\n");
    assert_contains(text, "resolution: 12x10\nsamples: 3\nintegrator: whitted\noutput: i1-out.pfm\n");
    char *b3 = strstr(b2, "\n\nfile: ");
    assert_non_null(b3);
    *b3 = 0;
    b3 += 2;
    assert_contains(b2, "i2.txt\n");
    assert_contains(b2, "camera: auto (framed to the bounds)\n");
    assert_contains(b2, "resolution: 512x512\nsamples: 1\nintegrator: direct\noutput: i2.png\n");
    char *b4 = strstr(b3, "\n\nfile: ");
    assert_non_null(b4);
    *b4 = 0;
    b4 += 2;
    assert_contains(b3, "file: assets/box.gltf\nformat: gltf\n");
    assert_contains(b3, "camera: gltf camera 0\ncamera.position: 1.20000005 1.39999998 3.20000005\n");
    assert_contains(b3, "output: box.png\n");
    assert_contains(b4, "file: assets/donut.obj\nformat: mesh\n");
    assert_contains(b4, "camera: auto");
    assert_contains(b4, "output: donut.png\n");
    /* a file that fails is reported and the rest still are, exit 2 */
    const char *const bad[] = {"--info", path_in("missing.txt"), path_in("i2.txt"), NULL};
    assert_int_equal(run_stdout(bad, text, sizeof text), 2);
    assert_contains(text, "i2.txt\n");
    /* a render still takes one input */
    REFUSE(out_png, "only one input file", "--info takes several", path_in("i1.txt"), path_in("i2.txt"), "-o",
           out_png);
}

/* --info applies the flags that change the render, as the render does
 * (-r, -s, --integrator, -o, --set, --camera auto, --look-from), prints
 * the automatic camera's pose (given back as flags, the same image), and
 * lists the cameras, the animations with their frames at --fps and the
 * material variants. */
static void test_info_flags(void **state)
{
    (void)state;
    static char text[1 << 14];
    write_text("if.txt", "resolution 12 10\nsamples 3\nintegrator whitted\n"
                         "camera position 0 1 5 look_at 0 1 0 fov 30\nmaterial m\nsphere 0 0 0 1 m\n"
                         "sphere 1.5 0.2 -1 0.5 m\n");
    const char *const args[] = {"--info", path_in("if.txt"), "-r", "100x80", "-s", "7", "--integrator", "path", "-o",
                                "foo.exr", "--camera", "auto", "--look-from", "0,2,6", "--set", "exposure=2",
                                "--seed=4", NULL};
    assert_int_equal(run_stdout(args, text, sizeof text), 0);
    assert_contains(text, "camera: auto (framed to the bounds; --camera auto), then --look-from\n"
                          "camera.position: 0 2 6\n");
    assert_contains(text, "resolution: 100x80\nsamples: 7\nintegrator: path\noutput: foo.exr\n");
    assert_contains(text, "setting.exposure: 2 (--set)\nsetting.seed: 4 (--seed)\n");
    /* the automatic camera's pose, given back as flags: the same image */
    write_text("if-auto.txt", "resolution 16 12\nsamples 1\nmaterial m\nsphere 0 0 0 1 m\nsphere 1.5 0.2 -1 0.5 m\n");
    const char *const auto_args[] = {"--info", path_in("if-auto.txt"), NULL};
    assert_int_equal(run_stdout(auto_args, text, sizeof text), 0);
    assert_contains(text, "camera: auto (framed to the bounds)\n");
    char from[128], at[128], up[128], fov[64];
    const char *c = strstr(text, "camera.position: ");
    assert_non_null(c);
    float v[10];
    assert_int_equal(sscanf(c, "camera.position: %g %g %g\ncamera.look_at: %g %g %g\ncamera.up: %g %g %g\n"
                               "camera.fov: %g", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]),
                     10);
    snprintf(from, sizeof from, "%.9g,%.9g,%.9g", v[0], v[1], v[2]);
    snprintf(at, sizeof at, "%.9g,%.9g,%.9g", v[3], v[4], v[5]);
    snprintf(up, sizeof up, "%.9g,%.9g,%.9g", v[6], v[7], v[8]);
    snprintf(fov, sizeof fov, "%.9g", v[9]);
    char a[600], b[600];
    snprintf(a, sizeof a, "%s", path_in("if-a.pfm"));
    snprintf(b, sizeof b, "%s", path_in("if-b.pfm"));
    render_ok(a, (const char *const[]){path_in("if-auto.txt"), NULL});
    render_ok(b, (const char *const[]){"--look-from", from, "--look-at", at, "--up", up, "--fov", fov,
                                       path_in("if-auto.txt"), NULL});
    assert_same_file(a, b);
    unlink(a), unlink(b);
    /* a glTF's cameras and variants; -r wins over the camera's aspect ratio */
    const char *const gltf_args[] = {"--info", "assets/ext/variants.gltf", "-r", "64x64", "--variant", "blue", NULL};
    assert_int_equal(run_stdout(gltf_args, text, sizeof text), 0);
    assert_contains(text, "cameras: 1\ncamera.0: position 0 0 3.15815878 look_at 0 0 2.15815878 fov ");
    assert_contains(text, "variants: 2\nvariant.0: red\nvariant.1: blue\n");
    assert_contains(text, "camera: gltf camera 0\n");
    assert_contains(text, "resolution: 64x64\n");
    /* animations: names, lengths and frames at --fps */
    const float data[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* the triangle */
                          0, 1.5f, 0, 0.25f,         /* key times of the two animations */
                          0, 0, 0, 2, 0, 0};         /* translations */
    char *enc = test_base64(data, sizeof data);
    static char json[8192];
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
             "\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":8},"
             "{\"buffer\":0,\"byteOffset\":44,\"byteLength\":8},{\"buffer\":0,\"byteOffset\":52,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":2,"
             "\"type\":\"SCALAR\"},{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"},"
             "{\"bufferView\":3,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
             "\"animations\":[{\"name\":\"Walk\",\"samplers\":[{\"input\":1,\"output\":3}],"
             "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]},"
             "{\"samplers\":[{\"input\":2,\"output\":3}],"
             "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]}",
             sizeof data, enc);
    free(enc);
    write_text("walk.gltf", json);
    const char *const anim_args[] = {"--info", path_in("walk.gltf"), "--fps", "10", NULL};
    assert_int_equal(run_stdout(anim_args, text, sizeof text), 0);
    assert_contains(text, "animations: 2\nanimation.0: 'Walk', 1.5 s, frames 0:16 at 10 fps\n"
                          "animation.1: (unnamed), 0.25 s, frames 0:3 at 10 fps\n");
    /* a scene file's model lines count too */
    snprintf(json, sizeof json, "model %s\n", path_in("walk.gltf"));
    write_text("walk.txt", json);
    const char *const scene_args[] = {"--info", path_in("walk.txt"), NULL};
    assert_int_equal(run_stdout(scene_args, text, sizeof text), 0);
    assert_contains(text, "animations: 2\nanimation.0: 'Walk', 1.5 s, frames 0:37 at 24 fps\n");
}

/* A model given directly renders with the path tracer at 64 spp; a scene
 * file keeps its integrator line. */
static void test_model_defaults(void **state)
{
    (void)state;
    static char text[1 << 14];
    const char *const info[] = {"--info", "assets/donut.obj", "assets/box.gltf", "scenes/cornell.txt", NULL};
    assert_int_equal(run_stdout(info, text, sizeof text), 0);
    char *b2 = strstr(text, "file: assets/box.gltf");
    char *b3 = strstr(text, "file: scenes/cornell.txt");
    assert_true(b2 && b3);
    b2[-1] = b3[-1] = 0;
    assert_contains(text, "samples: 64\nintegrator: path\n");
    assert_contains(b2, "samples: 64\nintegrator: path\n");
    assert_contains(b3, "integrator: direct\n");
    char a[600], b[600];
    snprintf(a, sizeof a, "%s", path_in("md-a.pfm"));
    snprintf(b, sizeof b, "%s", path_in("md-b.pfm"));
    const char *const plain[] = {"-r", "16x12", "-s", "2", "assets/donut.obj", NULL};
    render_ok(a, plain);
    const char *const path[] = {"-r", "16x12", "-s", "2", "--integrator", "path", "assets/donut.obj", NULL};
    render_ok(b, path);
    assert_same_file(a, b);
    const char *const direct[] = {"-r", "16x12", "-s", "2", "--integrator", "direct", "assets/donut.obj", NULL};
    render_ok(b, direct);
    assert_false(same_file(a, b));
    unlink(a), unlink(b);
}

/* --------------------------------------------------------------- models */

static const char *gltf_doc(char *buf, size_t size, int count, int bad_index, const char *nodes)
{
    /* three positions (36 bytes) and three u16 indices (6 bytes + 2 padding), base64 */
    unsigned char bin[44];
    float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    memcpy(bin, pos, 36);
    uint16_t idx[4] = {0, 1, (uint16_t)(bad_index ? 7 : 2), 0};
    memcpy(bin + 36, idx, 8);
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char enc[80];
    int n = 0;
    for (int i = 0; i < 44; i += 3) {
        uint32_t v = (uint32_t)bin[i] << 16 | (uint32_t)(i + 1 < 44 ? bin[i + 1] : 0) << 8 | (i + 2 < 44 ? bin[i + 2] : 0);
        enc[n++] = b64[v >> 18 & 63];
        enc[n++] = b64[v >> 12 & 63];
        enc[n++] = i + 1 < 44 ? b64[v >> 6 & 63] : '=';
        enc[n++] = i + 2 < 44 ? b64[v & 63] : '=';
    }
    enc[n] = 0;
    snprintf(buf, size,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
             "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
             "\"nodes\":%s,\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
             enc, count, nodes);
    return buf;
}

static void test_bad_models(void **state)
{
    (void)state;
    const char *o = out_png;
    static char doc[1 << 21];

    /* the good one renders, so the refusals below are about the one change */
    write_text("ok.gltf", gltf_doc(doc, sizeof doc, 3, 0, "[{\"mesh\":0}]"));
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *const good[] = {"-q", "-r", "8x8", "-o", path_in("ok.png"), path_in("ok.gltf"), NULL};
    run_args(r, good);
    if (r->status != 0)
        fail_msg("the valid glTF failed: %s", r->err);
    free(r);

    write_text("acc.gltf", gltf_doc(doc, sizeof doc, 1000, 0, "[{\"mesh\":0}]"));
    REFUSE(o, "acc.gltf: byte ", "1000 elements", path_in("acc.gltf"), "-o", o);
    write_text("idx.gltf", gltf_doc(doc, sizeof doc, 3, 1, "[{\"mesh\":0}]"));
    REFUSE(o, "idx.gltf: byte ", "is 7, past the vertex count 3", path_in("idx.gltf"), "-o", o);
    write_text("cycle.gltf", gltf_doc(doc, sizeof doc, 3, 0, "[{\"mesh\":0,\"children\":[1]},{\"children\":[0]}]"));
    REFUSE(o, "cycle.gltf: byte ", "cycle", path_in("cycle.gltf"), "-o", o);
    /* a chain of 5000 nodes, each the child of the one before */
    char *nodes = malloc(200000);
    assert_non_null(nodes);
    size_t k = 0;
    nodes[k++] = '[';
    for (int i = 0; i < 5000; i++)
        k += (size_t)snprintf(nodes + k, 200000 - k, i < 4999 ? "{\"children\":[%d]}," : "{\"mesh\":0}]", i + 1);
    write_text("deep.gltf", gltf_doc(doc, sizeof doc, 3, 0, nodes));
    free(nodes);
    REFUSE(o, "deep.gltf: byte ", "levels deep", path_in("deep.gltf"), "-o", o);
    write_text("json.gltf", "{\"asset\":{\"version\":\"2.0\"},\n \"nodes\": [ {\"mesh\": } ]}");
    REFUSE(o, "json.gltf", NULL, path_in("json.gltf"), "-o", o);
    copy_file("tests/corpus/glb/huge-length.glb", path_in("huge.glb"));
    REFUSE(o, "huge.glb: byte 8: ", "runs past the end of the file", path_in("huge.glb"), "-o", o);

    write_text("idx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    REFUSE(o, "idx.obj:4:7: ", "vertex index 9 out of range", path_in("idx.obj"), "-o", o);
    write_text("nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    REFUSE(o, "nan.obj:1:7: ", "not finite", path_in("nan.obj"), "-o", o);
    write_text("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 inf 1\nf 1//1 2//1 3//1\n");
    REFUSE(o, "inf.obj:4:", "not finite", path_in("inf.obj"), "-o", o);
    write_text("lie.ply", "ply\nformat ascii 1.0\nelement vertex 1000000\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
    REFUSE(o, "lie.ply:", "1000000 'vertex' elements", path_in("lie.ply"), "-o", o);
    test_write_file(path_in("bin.ply"),
                    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n\0\0\0\0\0\0",
                    strlen("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float "
                           "y\nproperty float z\nend_header\n") + 6);
    REFUSE(o, "bin.ply: byte ", "3 'vertex' elements", path_in("bin.ply"), "-o", o);
    write_text("t.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n");
    REFUSE(o, "t.off:4: ", "2 of 3 vertices", path_in("t.off"), "-o", o);
    write_text("idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n");
    REFUSE(o, "idx.off:", NULL, path_in("idx.off"), "-o", o);
}

/* One rule for missing textures in every format: a warning naming the
 * file and line (the map_Kd line of an MTL, the image of a glTF), and the
 * render goes on with the magenta checker. */
static void test_missing_textures(void **state)
{
    (void)state;
    static char doc[1 << 16];
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *o = path_in("miss.png");
    write_text("miss.txt", "resolution 8 8\nmaterial m texture gone.png\nsphere 0 0 0 1 m\n");
    write_text("miss.mtl", "newmtl a\nKd 1 1 1\nmap_Kd gone.png\n");
    write_text("miss.obj", "mtllib miss.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\n"
                           "f 1/1 2/2 3/3\n");
    gltf_doc(doc + 1, sizeof doc - 200, 3, 0, "[{\"mesh\":0}]");
    char *g = malloc(sizeof doc + 128);
    assert_non_null(g);
    snprintf(g, sizeof doc + 128, "{\"images\":[{\"uri\":\"gone.png\"}],\"textures\":[{\"source\":0}],%s", doc + 2);
    write_text("miss.gltf", g);
    free(g);
    static const struct { const char *input, *where; } cases[] = {
        {"miss.txt", "miss.txt:2:20: image '"},
        {"miss.obj", "miss.mtl:3: map_Kd: image '"},
        {"miss.gltf", "miss.gltf: images[0] (\"gone.png\"): image '"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        const char *const args[] = {"-r", "8x8", "-s", "1", "-o", o, path_in(cases[i].input), NULL};
        run_args(r, args);
        if (r->status != 0)
            fail_msg("%s: exit %d: %s", cases[i].input, r->status, r->err);
        assert_contains(r->err, "rt: warning: ");
        assert_contains(r->err, cases[i].where);
        assert_contains(r->err, "gone.png' not found; a magenta checker stands in");
    }
    unlink(o);
    free(r);
}

/* ---------------------------------------------------------------- images */

static void be32put(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

static void test_bad_images(void **state)
{
    (void)state;
    const char *o = out_png;
    /* a PNG header claiming 60000x60000 RGBA (14 GB decoded) on 45 bytes */
    unsigned char png[45] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
    be32put(png + 16, 60000);
    be32put(png + 20, 60000);
    png[24] = 8;
    png[25] = 6;
    memcpy(png + 33, "\0\0\0\0IEND\xae\x42\x60\x82", 12);
    test_write_file(path_in("huge.png"), png, sizeof png);
    write_text("tex.txt", "resolution 8 8\nmaterial m color 1 1 1 texture huge.png\nsphere 0 0 0 1 m\n");
    REFUSE(o, "tex.txt:2:", "huge.png: image is 60000x60000, over the limit", path_in("tex.txt"), "-o", o);
    /* a normal 256x256 header over a zlib stream that never ends */
    copy_file("tests/corpus/image/png-zlib-stream-without-end.png", path_in("bomb.png"));
    write_text("bomb.txt", "resolution 8 8\nmaterial m color 1 1 1 texture bomb.png\nsphere 0 0 0 1 m\n");
    REFUSE(o, "bomb.png: PNG pixel data does not inflate", NULL, path_in("bomb.txt"), "-o", o);
    write_text("junk.png", "this is not an image");
    write_text("env.txt", "resolution 8 8\nenvironment junk.png\n");
    REFUSE(o, "junk.png", NULL, path_in("env.txt"), "-o", o);
}

/* ---------------------------------------------------------------- output */

static void test_bad_output(void **state)
{
    (void)state;
    const char *o = out_png;
    /* checked before rendering: this render would take hours */
    REFUSE(o, "/no-such-dir-for-rt/x.png: cannot write there", NULL, "-r", "256x256", "-s", "1048576", "-o",
           "/no-such-dir-for-rt/x.png");
    REFUSE(o, "out.xyz: unknown output format", NULL, "-r", "8x8", "-o", path_in("out.xyz"));
    REFUSE(o, "out: unknown output format", NULL, "-r", "8x8", "-o", path_in("out"));
    write_text("file", "a file, not a directory");
    REFUSE(o, "file/x.png: cannot write there", NULL, "-r", "8x8", "-o", path_in("file/x.png"));
    /* a directory named like the output, refused before the scene is even
     * loaded (the scene here would fail to load) */
    const char *dpng = path_in("d.png");
    assert_int_equal(mkdir(dpng, 0755), 0);
    REFUSE(o, "d.png: is a directory", NULL, "-r", "8x8", "-o", dpng);
    REFUSE(o, "d.png: is a directory", NULL, "-o", dpng, path_in("no-such-scene.txt"));
    rmdir(dpng);
    /* a scene's own output line naming a directory: refused before rendering */
    char own[700];
    assert_int_equal(mkdir(dpng, 0755), 0);
    snprintf(own, sizeof own, "resolution 8 8\noutput \"%s\"\n", dpng);
    write_text("own-dir.txt", own);
    REFUSE(o, "d.png: is a directory", NULL, path_in("own-dir.txt"));
    /* a model's default output (NAME.png here), before the model is loaded:
     * d.gltf is not even valid */
    write_text("d.gltf", "{ not json");
    child_dir = dir;
    REFUSE(o, "d.png: is a directory", NULL, "-r", "8x8", "d.gltf");
    child_dir = NULL;
    rmdir(dpng);
    /* too big for the PNG writer: refused before rendering, not after */
    REFUSE(o, "out.png: a 32768x32768 PNG", ".pfm", "-r", "32768x32768", "-o", o);
    if (geteuid() != 0) { /* root writes anywhere */
        const char *ro = path_in("ro");
        assert_int_equal(mkdir(ro, 0755), 0);
        char prot[700];
        snprintf(prot, sizeof prot, "%s/old.png", ro);
        put_precious(prot);
        assert_int_equal(chmod(ro, 0555), 0);
        REFUSE(prot, "old.png: cannot write there", NULL, "-r", "8x8", "-o", prot);
        chmod(ro, 0755);
        unlink(prot);
        rmdir(ro);
    }
}

/* ---------------------------------------------------------------- limits */

static void test_memory_budget(void **state)
{
    (void)state;
    /* rt is built with the same flags as this test (make asan, make tsan) */
    test_skip_in_sanitizer_build("rt does not enforce --max-memory there (memory_budget.c)");
    /* -v names the budget in force */
    write_text("tiny.txt", "resolution 4 4\n");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-v", "--info", path_in("tiny.txt"), NULL});
    assert_int_equal(r->status, 0);
    assert_contains(r->err, "memory budget: ");
    assert_null(strstr(r->err, "memory budget: none"));
    free(r);
    const char *pfm = path_in("big.pfm");
    /* 20000x20000 floats are 4.5 GiB: over a 256 MiB budget at the framebuffer */
    REFUSE(pfm, "out of memory for a 20000x20000 image", "budget of 256 MiB (--max-memory) ran out", "-q", "-r",
           "20000x20000", "--max-memory", "256M", "-o", pfm);
    /* the default budget is there and named */
    REFUSE(pfm, "out of memory for a 32768x32768 image", "--max-memory SIZE", "-q", "-r", "32768x32768",
           "--max-memory", "1G", "-o", pfm);
    unlink(pfm);
}

/* ------------------------------------------------------------- rendering */

static void test_threads_same_image(void **state)
{
    (void)state;
    char one[600], many[600], lone[600], px[600], px_png[600];
    snprintf(one, sizeof one, "%s", path_in("t1.pfm"));
    snprintf(many, sizeof many, "%s", path_in("t64.pfm"));
    snprintf(lone, sizeof lone, "%s", path_in("tlone.pfm"));
    snprintf(px, sizeof px, "%s", path_in("one.pfm"));
    snprintf(px_png, sizeof px_png, "%s", path_in("one.png"));
    const char *const a1[] = {"-r", "24x20", "--tile", "4", "-s", "4", "-t", "1", NULL};
    const char *const a64[] = {"-r", "24x20", "--tile", "4", "-s", "4", "-t", "64", NULL};
    render_ok(one, a1);
    render_ok(many, a64); /* 64 threads on however few cores, 30 tiles */
    assert_same_file(one, many);
    /* one tile, eight threads: seven find nothing to do */
    const char *const alone[] = {"-r", "24x20", "--tile", "64", "-s", "4", "-t", "8", NULL};
    render_ok(lone, alone);
    assert_same_file(one, lone);
    /* a 1x1 image */
    const char *const a11[] = {"-r", "1x1", "-s", "4", "-t", "3", NULL};
    render_ok(px, a11);
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(px, &fb, &err), RT_OK);
    assert_int_equal(fb.width, 1);
    assert_int_equal(fb.height, 1);
    for (int c = 0; c < 3; c++)
        assert_true(fb.rgb[c] >= 0.0f && fb.rgb[c] < 1e6f);
    rt_framebuffer_free(&fb);
    const char *const a11p[] = {"-r", "1x1", NULL};
    render_ok(px_png, a11p);
    unlink(one), unlink(many), unlink(lone), unlink(px), unlink(px_png);
}

/* Recursion at its caps: two facing mirrors at max_bounce 256, and 600
 * index-matched glass spheres in a row (1200 crossings, past whitted's
 * guard of 1024 nested rays): no stack overflow, a finite image. */
static void test_deep_recursion(void **state)
{
    (void)state;
    write_text("mirrors.txt", "resolution 16 16\nintegrator whitted\nmax_bounce 256\n"
                              "camera position 0 0 0.5 look_at 0 0 -1 up 0 1 0 fov 10\n"
                              "material mirror color 1 1 1 reflectivity 1\n"
                              "quad -50 -50 -1  100 0 0  0 100 0 mirror\nquad -50 -50 1  0 100 0  100 0 0 mirror\n"
                              "light point 0 0 0 1 1 1 1\n");
    static char glass[64 * 1024];
    int n = snprintf(glass, sizeof glass, "resolution 8 8\nintegrator whitted\nmax_bounce 256\n"
                                          "camera position 0 0 0 look_at 0 0 -1 up 0 1 0 fov 10\n"
                                          "material glass color 1 1 1 transmission 1 ior 1.0\n"
                                          "light point 0 0 0 1 1 1 1\n");
    for (int i = 1; i <= 600; i++)
        n += snprintf(glass + n, sizeof glass - (size_t)n, "sphere 0 0 -%d 1 glass\n", 3 * i);
    write_text("glass.txt", glass);
    const char *names[2] = {"mirrors", "glass"};
    for (int k = 0; k < 2; k++) {
        char scene[600], pfm[600];
        snprintf(scene, sizeof scene, "%s/%s.txt", dir, names[k]);
        snprintf(pfm, sizeof pfm, "%s/%s.pfm", dir, names[k]);
        const char *const args[] = {"-t", "2", scene, NULL};
        render_ok(pfm, args);
        rt_framebuffer fb;
        rt_error err;
        assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
        for (size_t i = 0; i < 3 * (size_t)fb.width * (size_t)fb.height; i++)
            assert_true(fb.rgb[i] >= 0.0f && fb.rgb[i] < 1e30f);
        rt_framebuffer_free(&fb);
        unlink(pfm);
    }
}

/* A scene where every pixel is non-zero (a glowing sphere before a lit
 * background), so a finished tile or pass has no black pixel. */
static const char *slow_scene(void)
{
    write_text("slow.txt", "resolution 64 64\nbackground 0.5 0.6 0.7\n"
                           "camera position 0 0 4 look_at 0 0 0 up 0 1 0 fov 40\n"
                           "material glow color 0.5 0.5 0.5 emission 1 0.5 0.25\nsphere 0 0 0 1 glow\n");
    return path_in("slow.txt");
}

/* slow_scene with its camera line replaced by the first line of `printed`
 * (a `camera` line the window printed), as moved.txt; its path. */
static const char *slow_scene_with_camera(char *printed)
{
    static char moved[4096];
    *strchr(printed, '\n') = 0;
    snprintf(moved, sizeof moved,
             "resolution 64 64\nbackground 0.5 0.6 0.7\n%s\n"
             "material glow color 0.5 0.5 0.5 emission 1 0.5 0.25\nsphere 0 0 0 1 glow\n",
             printed);
    write_text("moved.txt", moved);
    return path_in("moved.txt");
}

/* Runs rt with args, its stderr on a new terminal (a pseudo-terminal
 * this test reads), into out (NUL-terminated); the exit status. */
static int run_on_terminal(const char *const *args, char *out, size_t cap)
{
    const char *argv[64];
    make_argv(argv, 64, rt_bin_absolute(), args);
    test_terminal_result r;
    test_terminal_run(argv, NULL, out, cap, &r);
    return r.status >= 0 ? r.status : 128 + r.signal;
}

/* The progress line as a terminal shows it: the phases before rendering
 * named (load, then the kd-tree with its primitives), then the render's
 * bar with samples per pixel in passes (tiles when tiled) and the time
 * left; the complete bar stays above the final "wrote" line, which gives
 * the wall time of the whole run and the render time (the first never
 * below the second). Not shown when stderr is not a terminal. */
static void test_progress_line_on_terminal(void **state)
{
    (void)state;
    static char out[1 << 16];
    const char *pfm = path_in("prog.pfm");
    const char *modes[2] = {"4", "0"}, *spp[2] = {"120", "400"}; /* tiles: long enough for a report before the end */
    for (int m = 0; m < 2; m++) {
        int status = run_on_terminal((const char *const[]){"-r", "48x48", "-s", spp[m], "-t", "1", "--integrator",
                                                           "path", "--passes", modes[m], "-o", pfm, slow_scene(),
                                                           NULL},
                                     out, sizeof out);
        if (status != 0)
            fail_msg("rt exited %d on a terminal:\n%s", status, out);
        assert_contains(out, "load ");
        assert_contains(out, "kd-tree (1 primitives) ...");
        assert_contains(out, "s, kd-tree ");
        assert_contains(out, "s, render [");
        assert_contains(out, m == 0 ? "/120 spp" : "/4 tiles");
        assert_contains(out, "ETA");
        /* the last bar, complete, stays on screen above the wrote line */
        const char *last = strstr(out, m == 0 ? "100.0% 120/120 spp" : "100.0% 4/4 tiles");
        if (!last)
            fail_msg("no complete bar on the terminal:\n%s", out + (strlen(out) > 600 ? strlen(out) - 600 : 0));
        const char *wrote = strstr(last, "\nrt: wrote ");
        assert_non_null(wrote);
        double wall = -1, render = -1;
        const char *semi = strstr(wrote, m == 0 ? "120 of 120 spp; " : "48x48, 400 of 400 spp; ");
        assert_non_null(semi);
        assert_int_equal(sscanf(strchr(semi, ';') + 1, " %lf s (render %lf s)", &wall, &render), 2);
        assert_true(render >= 0.0 && wall >= render);
    }
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-r", "8x8", "-s", "4", "-o", pfm, slow_scene(), NULL});
    assert_int_equal(r->status, 0);
    assert_null(strstr(r->err, "ETA"));
    assert_null(strchr(r->err, '\r'));
    assert_contains(r->err, "rt: wrote ");
    free(r);
    unlink(pfm);
}

/* Runs rt with args on a terminal (test_terminal.h) and sends `sig` once
 * its progress bar reads at least `at_least` of `unit` (" tiles", " spp");
 * rt must exit with 128 + sig. What the terminal showed goes to r->err. */
static void run_and_signal(const char *const *args, int sig, const char *unit, int at_least, run_result *r)
{
    const char *argv[64];
    make_argv(argv, 64, rt_bin_absolute(), args);
    test_terminal_signal at = {.sig = sig, .unit = unit, .at_least = at_least};
    test_terminal_result tr;
    double t0 = now_s();
    test_terminal_run(argv, &at, r->err, sizeof r->err, &tr);
    r->seconds = now_s() - t0;
    r->status = tr.status;
    r->signal = tr.signal;
    if (r->status != 128 + sig)
        fail_msg("expected exit %d after signal %d (sent at %d%s), got %d (signal %d): %s", 128 + sig, sig,
                 tr.signalled_at, unit, r->status, r->signal, r->err);
}

/* A tiled render interrupted by `sig` once its bar shows a finished tile
 * (a tile is 8192 samples a pixel: the 63 others are far from done): exit
 * 128 + sig, the output left as it was, and the finished tiles in
 * NAME.partial.pfm, each tile either finished or black, as many finished as
 * the message says, at least the one the bar showed. */
static void interrupted_tiles(int sig)
{
    const char *pfm = path_in("int.pfm"), *partial = path_in("int.partial.pfm");
    put_precious(pfm);
    unlink(partial);
    const char *const args[] = {"--tile", "8", "-s", "8192", "-t", "2", "--integrator", "direct", "-o", pfm,
                                slow_scene(), NULL};
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_and_signal(args, sig, " tiles", 1, r);
    assert_precious(pfm);
    const char *word = sig == SIGTERM ? "terminated" : "interrupted";
    char expect[700];
    snprintf(expect, sizeof expect, "rt: wrote %s: 64x64, ", partial);
    assert_contains(r->err, expect);
    snprintf(expect, sizeof expect, " of 64 tiles at 8192 spp, %s; ", word);
    assert_contains(r->err, expect);
    assert_contains(r->err, " left as it was");
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(partial, &fb, &err), RT_OK);
    assert_int_equal(fb.width, 64);
    assert_int_equal(fb.height, 64);
    int finished = 0, black = 0;
    for (int ty = 0; ty < 8; ty++)
        for (int tx = 0; tx < 8; tx++) {
            int zero = 0;
            for (int y = ty * 8; y < ty * 8 + 8; y++)
                for (int x = tx * 8; x < tx * 8 + 8; x++) {
                    const float *p = fb.rgb + 3 * ((size_t)y * 64 + (size_t)x);
                    zero += p[0] == 0.0f && p[1] == 0.0f && p[2] == 0.0f;
                }
            if (zero == 64)
                black++;
            else if (zero == 0)
                finished++;
            else
                fail_msg("tile (%d,%d) is partly black (%d of 64 pixels): a half-rendered tile was written", tx,
                         ty, zero);
        }
    int reported = -1;
    snprintf(expect, sizeof expect, "rt: wrote %s: 64x64, ", partial);
    const char *p = strstr(r->err, expect) + strlen(expect);
    assert_int_equal(sscanf(p, "%d of 64", &reported), 1);
    assert_int_equal(reported, finished);
    assert_true(finished >= 1 && black > 0);
    rt_framebuffer_free(&fb);
    assert_no_temp_files();
    unlink(pfm);
    unlink(partial);
    free(r);
}

/* A render in passes interrupted by `sig` once its bar shows the first
 * pass done: exit 128 + sig and the whole image at the samples reached
 * (whole passes of 4, at least the first) written to the output, labelled,
 * no pixel black. */
static void interrupted_passes(int sig)
{
    const char *pfm = path_in("pass.pfm");
    put_precious(pfm);
    const char *const args[] = {"-s", "100000", "-t", "2", "--integrator", "path", "-o", pfm, slow_scene(), NULL};
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_and_signal(args, sig, " spp", 4, r);
    char expect[700];
    snprintf(expect, sizeof expect, "rt: wrote %s: 64x64, ", pfm);
    const char *p = strstr(r->err, expect);
    if (!p)
        fail_msg("expected \"%s\" in rt's message:\n%s", expect, r->err);
    int spp = -1;
    char word[32] = "";
    assert_int_equal(sscanf(p + strlen(expect), "%d of 100000 spp, %31[a-z]", &spp, word), 2);
    assert_string_equal(word, sig == SIGTERM ? "terminated" : "interrupted");
    assert_true(spp >= 4 && spp < 100000 && spp % 4 == 0); /* whole passes of 4 */
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
    assert_int_equal(fb.width, 64);
    for (size_t i = 0; i < 64 * 64; i++)
        assert_true(fb.rgb[3 * i] > 0.0f && fb.rgb[3 * i + 1] > 0.0f && fb.rgb[3 * i + 2] > 0.0f);
    rt_framebuffer_free(&fb);
    assert_no_temp_files();
    unlink(pfm);
    free(r);
}

static void test_sigint_writes_finished_tiles(void **state)
{
    (void)state;
    interrupted_tiles(SIGINT);
}

static void test_sigterm_writes_finished_tiles(void **state)
{
    (void)state;
    interrupted_tiles(SIGTERM);
}

static void test_sigint_writes_passes(void **state)
{
    (void)state;
    interrupted_passes(SIGINT);
}

static void test_sigterm_writes_passes(void **state)
{
    (void)state;
    interrupted_passes(SIGTERM);
}

/* The end of the samples a part's sidecar holds ("samples": [0, END]). */
static int sidecar_samples_end(const char *json)
{
    char buf[8192];
    size_t n = read_all(json, buf, sizeof buf - 1);
    buf[n] = 0;
    const char *s = strstr(buf, "\"samples\": [");
    int a = -1, b = -1;
    if (!s || sscanf(s, "\"samples\": [%d, %d]", &a, &b) != 2)
        fail_msg("no samples in %s: %s", json, buf);
    assert_int_equal(a, 0);
    return b;
}

/* A frame of --frames stopped by SIGTERM (what a Slurm time limit or a pod
 * eviction sends) is not kept as the finished frame: exit 143, no file
 * under the frame's name, its image at the samples reached in
 * NAME.partial.pfm and its sums in NAME.part.exr; run again, the frame
 * resumes from that part (stopped again, the part holds more samples). */
static void test_sigterm_frame_kept_apart(void **state)
{
    (void)state;
    char pattern[600];
    snprintf(pattern, sizeof pattern, "%s/term.%%04d.pfm", dir);
    const char *frame = path_in("term.0005.pfm"), *partial = path_in("term.0005.partial.pfm");
    const char *sidecar = path_in("term.0005.part.exr.json");
    const char *const args[] = {"-s", "100000", "-t", "2", "--integrator", "path", "--frames", "5:6", "-o", pattern,
                                slow_scene(), NULL};
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_and_signal(args, SIGTERM, " spp", 4, r);
    assert_true(access(frame, F_OK) != 0);
    char expect[700];
    snprintf(expect, sizeof expect, "rt: wrote %s: 64x64, ", partial);
    assert_contains(r->err, expect);
    assert_contains(r->err, "spp, terminated");
    assert_contains(r->err, "term.0005.part.exr and ");
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(partial, &fb, &err), RT_OK);
    rt_framebuffer_free(&fb);
    int first = sidecar_samples_end(sidecar);
    assert_true(first >= 4 && first % 4 == 0);
    run_and_signal(args, SIGTERM, " spp", first + 4, r);
    assert_contains(r->err, "term.0005.part.exr: a stopped render of this frame; resuming it");
    assert_true(access(frame, F_OK) != 0);
    assert_true(sidecar_samples_end(sidecar) > first);
    assert_no_temp_files();
    free(r);
}

/* --time-limit already over when rendering starts (1 us: less than
 * starting a thread takes): in passes, exactly the first pass (4 spp) is
 * written to the output, labelled, exit 0, also with an integrator that
 * tiles (a time limit renders in passes); tiled (--passes 0), no tile is started (a
 * worker checks the deadline before taking one), nothing is written and
 * the output is left alone. */
static void test_time_limit(void **state)
{
    (void)state;
    const char *pfm = path_in("tl.pfm"), *partial = path_in("tl.partial.pfm");
    put_precious(pfm);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-q", "-s", "100000", "--integrator", "path", "--time-limit", "1e-6", "-o", pfm,
                                      slow_scene(), NULL});
    assert_int_equal(r->status, 0);
    char expect[700];
    snprintf(expect, sizeof expect, "rt: wrote %s: 64x64, 4 of 100000 spp, time limit; ", pfm);
    assert_contains(r->err, expect);
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
    rt_framebuffer_free(&fb);

    /* an integrator that tiles (direct) renders in passes under a time
     * limit: the whole image at the first pass, not a partial one */
    put_precious(pfm);
    run_args(r, (const char *const[]){"-q", "-s", "64", "--integrator", "direct", "--time-limit", "1e-6", "-o", pfm,
                                      slow_scene(), NULL});
    assert_int_equal(r->status, 0);
    snprintf(expect, sizeof expect, "rt: wrote %s: 64x64, 4 of 64 spp, time limit; ", pfm);
    assert_contains(r->err, expect);
    assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
    rt_framebuffer_free(&fb);
    assert_true(access(partial, F_OK) != 0);

    put_precious(pfm);
    run_args(r, (const char *const[]){"-q", "-s", "64", "--integrator", "path", "--passes", "0", "--time-limit",
                                      "1e-6", "-o", pfm, slow_scene(), NULL});
    assert_int_equal(r->status, 0);
    assert_precious(pfm);
    assert_contains(r->err, "stopped before any tile finished (time limit); nothing written");
    assert_true(access(partial, F_OK) != 0);
    assert_no_temp_files();
    unlink(pfm);
    unlink(partial);
    free(r);
}

/* Which 8x8 tiles of a 64x64 preview are finished: 1 where the tile holds
 * rendered pixels, 0 where every pixel is --preview's dim grey (0.02); a
 * tile that is partly grey fails. The count of finished tiles. */
static int preview_tiles(const rt_framebuffer *fb, int finished[64])
{
    int n = 0;
    for (int t = 0; t < 64; t++) {
        int grey = 0;
        for (int y = (t / 8) * 8; y < (t / 8) * 8 + 8; y++)
            for (int x = (t % 8) * 8; x < (t % 8) * 8 + 8; x++) {
                const float *p = fb->rgb + 3 * ((size_t)y * 64 + (size_t)x);
                grey += p[0] == 0.02f && p[1] == 0.02f && p[2] == 0.02f;
            }
        if (grey != 0 && grey != 64)
            fail_msg("preview tile %d is partly grey (%d of 64 pixels)", t, grey);
        finished[t] = grey == 0;
        n += finished[t];
    }
    return n;
}

/* --preview SECONDS rewrites the output while a tiled render runs: the
 * finished tiles as rendered, the others dim grey. The output is watched
 * until a preview shows a finished tile (tiles of 8192 samples a pixel: the
 * render is far from done), then rt is interrupted: every tile that preview
 * showed finished is, bit for bit, the tile NAME.partial.pfm keeps, and the
 * preview is left as the output, as the message says (not "left as it
 * was": --preview has written over it). */
static void test_preview(void **state)
{
    (void)state;
    const char *pfm = path_in("prev.pfm"), *partial = path_in("prev.partial.pfm");
    put_precious(pfm);
    unlink(partial);
    const char *const args[] = {"-q", "--preview", "0.1", "--tile", "8", "-s", "8192", "-t", "2", "--integrator",
                                "direct", "-o", pfm, slow_scene(), NULL};
    double t0 = now_s();
    pid_t pid = spawn(args);
    rt_framebuffer prev;
    rt_error err;
    int finished[64], shown = 0;
    while (shown == 0) {
        if (now_s() - t0 > 60.0) {
            kill(pid, SIGKILL);
            waitpid(pid, NULL, 0);
            fail_msg("no preview with a finished tile in %s within 60 s", pfm);
        }
        sleep_s(0.01);
        if (rt_pfm_read(pfm, &prev, &err) != RT_OK)
            continue; /* still the earlier file: no preview yet */
        assert_int_equal(prev.width, 64);
        shown = preview_tiles(&prev, finished);
        if (shown == 0)
            rt_framebuffer_free(&prev);
    }
    kill(pid, SIGINT);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    wait_for(pid, t0, 120.0, r);
    assert_int_equal(r->status, 130);
    /* the message says what the output holds: a preview, not the earlier file */
    char holds[700];
    snprintf(holds, sizeof holds, "; %s holds the last live preview (--preview)\n", pfm);
    assert_contains(r->err, holds);
    assert_null(strstr(r->err, "left as it was"));
    free(r);
    rt_framebuffer part, out;
    assert_int_equal(rt_pfm_read(partial, &part, &err), RT_OK);
    for (int t = 0; t < 64; t++)
        for (int y = (t / 8) * 8; finished[t] && y < (t / 8) * 8 + 8; y++) {
            size_t o = 3 * ((size_t)y * 64 + (size_t)(t % 8) * 8);
            if (memcmp(prev.rgb + o, part.rgb + o, 8 * 3 * sizeof(float)) != 0)
                fail_msg("tile %d: the preview's pixels are not the finished tile's", t);
        }
    assert_int_equal(rt_pfm_read(pfm, &out, &err), RT_OK); /* a preview, not the earlier file */
    int last[64];
    assert_true(preview_tiles(&out, last) >= shown);
    rt_framebuffer_free(&out);
    rt_framebuffer_free(&part);
    rt_framebuffer_free(&prev);
    assert_no_temp_files();
    unlink(pfm);
    unlink(partial);
}

/* The second Ctrl-C leaves at once, by the signal itself: the first is
 * sent once the progress bar shows the render running (a pixel of 2^20
 * samples, which takes seconds), the second as soon as the first has been
 * delivered. Had rt caught the second too, it would finish the pixel and
 * exit 130 instead of dying by SIGINT. How long it took is not asserted
 * (speed belongs to make bench). */
static void test_second_sigint_exits_at_once(void **state)
{
    (void)state;
    const char *png = path_in("keep.png");
    put_precious(png);
    const char *const args[] = {"-r", "2x1", "-s", "1048576", "-t", "1", "-o", png, NULL};
    const char *argv[64];
    make_argv(argv, 64, rt_bin_absolute(), args);
    test_terminal_signal at = {.sig = SIGINT, .unit = " tiles", .at_least = 0, .again = true};
    test_terminal_result tr;
    static char out[1 << 16];
    test_terminal_run(argv, &at, out, sizeof out, &tr);
    if (tr.signal != SIGINT)
        fail_msg("expected death by SIGINT, got exit %d (signal %d): %s", tr.status, tr.signal, out);
    assert_precious(png);
    assert_no_temp_files();
    unlink(png);
}

/* An image write killed at any moment (a second Ctrl-C, SIGKILL) leaves no
 * temporary file: the file being written has no name until it is complete
 * (image_write.c). A child rewrites a 100 MB PFM in a loop and is killed
 * at ten different moments; the scratch directory is checked each time. */
static void test_killed_write_leaves_no_temp(void **state)
{
    (void)state;
    const char *pfm = path_in("killed.pfm");
    for (int i = 0; i < 10; i++) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            rt_framebuffer fb;
            rt_error err;
            if (rt_framebuffer_init(&fb, 3000, 3000, &err) != RT_OK)
                _exit(3);
            for (;;)
                if (rt_framebuffer_write(&fb, pfm, 1.0f, &err) != RT_OK)
                    _exit(4);
        }
        sleep_s(0.05 + 0.037 * i);
        kill(pid, SIGKILL);
        int st = 0;
        waitpid(pid, &st, 0);
        if (!WIFSIGNALED(st))
            fail_msg("the writer exited with %d instead of being killed", WEXITSTATUS(st));
        assert_no_temp_files();
    }
    unlink(pfm);
}

/* The finished image gets its name and is renamed over the output by two
 * system calls in a row: linkat, then rename, with nothing between them
 * (a close there, where ext4 may wait on the inode's writeback, was a
 * window of milliseconds in which SIGKILL left a .rt-tmp file: the flake
 * test_killed_write_leaves_no_temp once showed). Seen with strace on a
 * real write over an existing image, for a float and an 8-bit format;
 * skipped, saying so, without strace (Debian strace) or where strace cannot
 * trace /bin/true (no ptrace here); rt failing under strace fails. */
static void test_write_renames_right_after_link(void **state)
{
    (void)state;
    if (access("/usr/bin/strace", X_OK) != 0) {
        fprintf(stderr, "skip: no /usr/bin/strace (Debian strace)\n");
        skip();
    }
    if (system("/usr/bin/strace -qq -o /dev/null /bin/true >/dev/null 2>&1") != 0) {
        fprintf(stderr, "skip: strace cannot trace /bin/true here (no ptrace)\n");
        skip();
    }
    static char log[16384];
    const char *bin = rt_bin_absolute();
    const char *outs[2] = {path_in("traced.pfm"), path_in("traced.png")};
    for (int k = 0; k < 2; k++) {
        const char *trace = path_in("strace.txt");
        put_precious(outs[k]);
        unlink(trace);
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            int null = open("/dev/null", O_RDWR);
            if (null < 0)
                _exit(127);
            dup2(null, 0);
            dup2(null, 1);
            dup2(null, 2);
            setenv("LSAN_OPTIONS", "detect_leaks=0", 1); /* LeakSanitizer's ptrace cannot attach under strace */
            execl("/usr/bin/strace", "strace", "-f", "-qq", "-o", trace, "-e",
                  "trace=linkat,close,rename,renameat,renameat2", bin, "-q", "-r", "8x8", "-s", "1", "-t", "1", "-o",
                  outs[k], (char *)NULL);
            _exit(127);
        }
        int st = 0;
        waitpid(pid, &st, 0);
        if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
            fail_msg("rt under strace writing %s: exit %d (signal %d)", outs[k], WIFEXITED(st) ? WEXITSTATUS(st) : -1,
                     WIFSIGNALED(st) ? WTERMSIG(st) : 0);
        if (read_all(trace, log, sizeof log) == (size_t)-1)
            fail_msg("strace wrote no trace to %s", trace);
        /* the line of the linkat that names the finished file, then that
         * process's next traced call */
        const char *link = strstr(log, "linkat(");
        while (link && !strstr(link, ".rt-tmp-"))
            link = strstr(link + 1, "linkat(");
        if (!link)
            fail_msg("no linkat of a .rt-tmp name in the trace of the write to %s:\n%s", outs[k], log);
        const char *line = link;
        while (line > log && line[-1] != '\n')
            line--;
        int tracee = atoi(line);
        const char *next = strchr(link, '\n');
        while (next && *++next && atoi(next) != tracee)
            next = strchr(next, '\n');
        if (!next || !*next)
            fail_msg("nothing traced after the linkat:\n%s", log);
        const char *call = strchr(next, ' ');
        while (call && *call == ' ')
            call++;
        if (!call || strncmp(call, "rename", 6) != 0 || !strstr(call, ".rt-tmp-") ||
            strchr(call, '\n') < strstr(call, ".rt-tmp-"))
            fail_msg("the next call after the linkat is not the rename of the linked file:\n%s", log);
        char buf[256];
        size_t n = read_all(outs[k], buf, sizeof buf); /* the earlier file replaced by the image */
        assert_true(n != (size_t)-1 && n > 0);
        assert_false(n == sizeof precious - 1 && memcmp(buf, precious, n) == 0);
        assert_no_temp_files();
        unlink(outs[k]);
    }
    unlink(path_in("strace.txt"));
}

/* ------------------------------------------------------------ a tev stand-in */

/* What a tev stand-in has received: the image CreateImage made, with every
 * UpdateImageV3 rectangle applied. */
#define TEV_VIEW_CHANNELS 16

typedef struct tev_view {
    int width, height;
    float *rgb;                            /* the channels R, G, B, interleaved */
    int nch;                               /* every channel: R, G, B, then the layers' */
    char ch[TEV_VIEW_CHANNELS][64];        /* their names */
    float *plane[TEV_VIEW_CHANNELS];       /* their pixels */
    int creates, updates;
    char name[256];
} tev_view;

static void tev_view_free(tev_view *v)
{
    free(v->rgb);
    for (int c = 0; c < TEV_VIEW_CHANNELS; c++)
        free(v->plane[c]);
}

/* A loopback TCP socket on a free port, bound (listening when `listening`);
 * its "127.0.0.1:PORT" for --display-server in address. */
static int tev_socket(char address[64], bool listening)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    assert_true(fd >= 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    socklen_t len = sizeof a;
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
    snprintf(address, 64, "127.0.0.1:%d", ntohs(a.sin_port));
    if (listening)
        assert_int_equal(listen(fd, 4), 0);
    return fd;
}

static int tev_accept(int listener)
{
    struct pollfd pf = {listener, POLLIN, 0};
    if (poll(&pf, 1, 60000) != 1)
        fail_msg("rt did not connect to the tev stand-in within 60 s");
    int fd = accept(listener, NULL, NULL);
    assert_true(fd >= 0);
    return fd;
}

/* Reads n bytes; false at end of stream before the first byte. */
static bool read_n(int fd, unsigned char *buf, size_t n)
{
    size_t got = 0;
    while (got < n) {
        struct pollfd pf = {fd, POLLIN, 0};
        if (poll(&pf, 1, 60000) != 1)
            fail_msg("the tev stand-in got no data for 60 s");
        ssize_t k = read(fd, buf + got, n - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            if (got == 0)
                return false;
            fail_msg("a tev packet was cut off after %zu of %zu bytes", got, n);
        }
        got += (size_t)k;
    }
    return true;
}

static uint64_t le(const unsigned char *p, int bytes)
{
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

/* A packet's reader: every field must lie inside the packet. */
typedef struct field_reader {
    const unsigned char *p;
    size_t at, size;
} field_reader;

static uint64_t field(field_reader *r, int bytes)
{
    if (r->at + (size_t)bytes > r->size)
        fail_msg("tev packet field past its end (%zu + %d > %zu)", r->at, bytes, r->size);
    uint64_t v = le(r->p + r->at, bytes);
    r->at += (size_t)bytes;
    return v;
}

static const char *field_string(field_reader *r)
{
    const char *s = (const char *)r->p + r->at;
    size_t n = strnlen(s, r->size - r->at);
    if (r->at + n >= r->size)
        fail_msg("tev packet string without its NUL");
    r->at += n + 1;
    return s;
}

/* Decodes one packet into v; false at the end of the stream. */
static bool tev_read_packet(int fd, tev_view *v)
{
    unsigned char head[4];
    if (!read_n(fd, head, 4))
        return false;
    size_t size = (size_t)le(head, 4);
    assert_true(size >= 5 && size < ((size_t)64 << 20));
    unsigned char *p = malloc(size);
    assert_non_null(p);
    memcpy(p, head, 4);
    if (!read_n(fd, p + 4, size - 4))
        fail_msg("tev packet of %zu bytes cut off after its length", size);
    field_reader r = {p, 4, size};
    int type = (int)field(&r, 1);
    if (type == 4) { /* CreateImage */
        assert_int_equal(field(&r, 1), 0); /* grabFocus */
        snprintf(v->name, sizeof v->name, "%s", field_string(&r));
        v->width = (int)(int32_t)field(&r, 4);
        v->height = (int)(int32_t)field(&r, 4);
        v->nch = (int)field(&r, 4);
        assert_true(v->nch >= 3 && v->nch <= TEV_VIEW_CHANNELS);
        for (int c = 0; c < v->nch; c++)
            snprintf(v->ch[c], sizeof v->ch[c], "%s", field_string(&r));
        assert_string_equal(v->ch[0], "R");
        assert_string_equal(v->ch[1], "G");
        assert_string_equal(v->ch[2], "B");
        assert_true(v->width > 0 && v->height > 0);
        assert_int_equal(r.at, size); /* nothing after the names */
        free(v->rgb);
        v->rgb = calloc((size_t)v->width * (size_t)v->height * 3, sizeof(float));
        assert_non_null(v->rgb);
        for (int c = 0; c < TEV_VIEW_CHANNELS; c++) {
            free(v->plane[c]);
            v->plane[c] = c < v->nch ? calloc((size_t)v->width * (size_t)v->height, sizeof(float)) : NULL;
        }
        v->creates++;
    } else if (type == 6) { /* UpdateImageV3 */
        assert_true(v->creates > 0);
        field(&r, 1);
        assert_string_equal(field_string(&r), v->name);
        int n = (int)field(&r, 4);
        assert_true(n >= 1 && n <= v->nch);
        int chan[TEV_VIEW_CHANNELS]; /* the image's channel of each listed name */
        for (int c = 0; c < n; c++) {
            const char *name = field_string(&r);
            chan[c] = -1;
            for (int k = 0; k < v->nch; k++)
                if (strcmp(v->ch[k], name) == 0)
                    chan[c] = k;
            if (chan[c] < 0)
                fail_msg("tev update names channel '%s', which CreateImage did not", name);
        }
        int x = (int)(int32_t)field(&r, 4), y = (int)(int32_t)field(&r, 4);
        int w = (int)(int32_t)field(&r, 4), h = (int)(int32_t)field(&r, 4);
        assert_true(x >= 0 && y >= 0 && w > 0 && h > 0 && x + w <= v->width && y + h <= v->height);
        int64_t off[TEV_VIEW_CHANNELS], stride[TEV_VIEW_CHANNELS];
        for (int c = 0; c < n; c++)
            off[c] = (int64_t)field(&r, 8);
        for (int c = 0; c < n; c++)
            stride[c] = (int64_t)field(&r, 8);
        size_t npx = (size_t)w * (size_t)h, nfloats = 0;
        for (int c = 0; c < n; c++) {
            assert_true(off[c] >= 0 && stride[c] >= 0);
            size_t need = (size_t)off[c] + (npx - 1) * (size_t)stride[c] + 1;
            nfloats = need > nfloats ? need : nfloats;
        }
        assert_int_equal(size - r.at, nfloats * 4); /* exactly the floats, nothing after */
        const unsigned char *data = p + r.at;
        for (int c = 0; c < n; c++) {
            int ch = chan[c];
            for (size_t i = 0; i < npx; i++) {
                union { uint32_t u; float f; } f;
                f.u = (uint32_t)le(data + 4 * ((size_t)off[c] + i * (size_t)stride[c]), 4);
                size_t px = (size_t)(y + (int)(i / (size_t)w)) * (size_t)v->width + (size_t)(x + (int)(i % (size_t)w));
                v->plane[ch][px] = f.f;
                if (ch < 3)
                    v->rgb[3 * px + (size_t)ch] = f.f;
            }
        }
        v->updates++;
    } else {
        fail_msg("the tev stand-in got packet type %d", type);
    }
    free(p);
    return true;
}

/* What tev shows equals the image rt wrote, bit for bit. */
static void assert_tev_shows(const tev_view *v, const char *pfm, const char *name)
{
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
    assert_string_equal(v->name, name);
    assert_int_equal(v->width, fb.width);
    assert_int_equal(v->height, fb.height);
    assert_memory_equal(v->rgb, fb.rgb, (size_t)fb.width * (size_t)fb.height * 3 * sizeof(float));
    rt_framebuffer_free(&fb);
}

/* tev's layer `layer` equals the AOV file rt wrote (a PFM; one-channel
 * AOVs are written grey, so LAYER.Y is compared with its R). */
static void assert_tev_layer(const tev_view *v, const char *layer, int channels, const char *pfm)
{
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
    assert_int_equal(v->width, fb.width);
    assert_int_equal(v->height, fb.height);
    static const char *const rgb[3] = {"R", "G", "B"};
    for (int c = 0; c < channels; c++) {
        char name[64];
        snprintf(name, sizeof name, "%s.%s", layer, channels == 1 ? "Y" : rgb[c]);
        int k = -1;
        for (int i = 0; i < v->nch; i++)
            if (strcmp(v->ch[i], name) == 0)
                k = i;
        if (k < 0)
            fail_msg("tev has no channel %s", name);
        for (size_t px = 0; px < (size_t)fb.width * (size_t)fb.height; px++)
            if (memcmp(&v->plane[k][px], &fb.rgb[3 * px + (size_t)c], sizeof(float)) != 0)
                fail_msg("tev's %s at pixel %zu is %.9g, the written %s has %.9g", name, px, v->plane[k][px], pfm,
                         fb.rgb[3 * px + (size_t)c]);
    }
    rt_framebuffer_free(&fb);
}

/* Runs rt with args, which point it at the tev stand-in `listener`, reads
 * everything rt sends into *v until rt closes the connection, closes the
 * listener; rt must exit 0. */
static void run_showing_tev(const char *const *args, int listener, tev_view *v)
{
    double t0 = now_s();
    pid_t pid = spawn(args);
    int fd = tev_accept(listener);
    memset(v, 0, sizeof *v);
    while (tev_read_packet(fd, v))
        ;
    close(fd);
    close(listener);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    wait_for(pid, t0, 120.0, r);
    assert_int_equal(r->status, 0);
    free(r);
}

/* --display-server with a tev stand-in listening: tiled and in passes, the
 * image tev ends up showing is the written one, bit for bit. */
static void test_display_server(void **state)
{
    (void)state;
    const char *modes[2] = {"0", "2"};
    for (int m = 0; m < 2; m++) {
        char address[64];
        int listener = tev_socket(address, true);
        const char *pfm = path_in("tev.pfm");
        const char *const args[] = {"-q", "-r", "40x24", "-s", "6", "--tile", "8", "--integrator", "path", "--passes",
                                    modes[m], "--display-server", address, "-o", pfm, slow_scene(), NULL};
        tev_view v;
        run_showing_tev(args, listener, &v);
        assert_int_equal(v.creates, 1);
        assert_true(v.updates >= 1);
        assert_tev_shows(&v, pfm, "tev.pfm");
        tev_view_free(&v);
        unlink(pfm);
    }
}

/* --aov with --display-server: the AOVs go along as extra layers, named
 * as in rt's EXR output (albedo.R ... depth.Y), updated with the image;
 * what tev ends up with equals the written AOV files bit for bit, tiled
 * and in passes. */
static void test_display_server_aovs(void **state)
{
    (void)state;
    const char *modes[2] = {"0", "2"};
    static const char *const want[] = {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.R", "normal.G",
                                       "normal.B", "depth.Y", "spp.Y"};
    for (int m = 0; m < 2; m++) {
        char address[64];
        int listener = tev_socket(address, true);
        const char *pfm = path_in("tevaov.pfm");
        const char *const args[] = {"-q", "-r", "40x24", "-s", "6", "--tile", "8", "--integrator", "path",
                                    "--passes", modes[m], "--aov", "albedo,normal,depth,spp", "--display-server",
                                    address, "-o", pfm, slow_scene(), NULL};
        tev_view v;
        run_showing_tev(args, listener, &v);
        assert_int_equal(v.creates, 1);
        assert_true(v.updates >= 1);
        assert_int_equal(v.nch, (int)(sizeof want / sizeof want[0]));
        for (int c = 0; c < v.nch; c++)
            assert_string_equal(v.ch[c], want[c]);
        assert_tev_shows(&v, pfm, "tevaov.pfm");
        assert_tev_layer(&v, "albedo", 3, path_in("tevaov.albedo.pfm"));
        assert_tev_layer(&v, "normal", 3, path_in("tevaov.normal.pfm"));
        assert_tev_layer(&v, "depth", 1, path_in("tevaov.depth.pfm"));
        assert_tev_layer(&v, "spp", 1, path_in("tevaov.spp.pfm"));
        tev_view_free(&v);
        unlink(pfm);
        unlink(path_in("tevaov.albedo.pfm"));
        unlink(path_in("tevaov.normal.pfm"));
        unlink(path_in("tevaov.depth.pfm"));
        unlink(path_in("tevaov.spp.pfm"));
    }
}

/* tev not there (a wrong port): rt says so once, without -v, naming the
 * address and that it renders on and keeps trying (it tries at the start
 * and again for the final image: one warning all the same); nothing with
 * -q; the image is written. */
static void test_display_server_absent(void **state)
{
    (void)state;
    char address[64];
    int bound = tev_socket(address, false); /* bound, not listening: connections are refused */
    const char *pfm = path_in("absent.pfm");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-q", "-r", "16x16", "-s", "2", "--display-server", address, "-o", pfm, NULL});
    assert_int_equal(r->status, 0);
    assert_string_equal(r->err, "");
    run_args(r, (const char *const[]){"-r", "16x16", "-s", "2", "--display-server", address, "-o", pfm, NULL});
    close(bound);
    assert_int_equal(r->status, 0);
    char want[160];
    snprintf(want, sizeof want, "rt: warning: --display-server %s: nothing listens there (", address);
    assert_contains(r->err, want);
    assert_contains(r->err, "); rendering on, and trying again every 2 s");
    assert_int_equal(count_of(r->err, "--display-server"), 1);
    assert_lines_prefixed(r->err);
    rt_framebuffer fb;
    rt_error err;
    assert_int_equal(rt_pfm_read(pfm, &fb, &err), RT_OK);
    rt_framebuffer_free(&fb);
    run_args(r, (const char *const[]){"--display-server", "nohost", "-o", pfm, NULL});
    assert_int_equal(r->status, 2);
    assert_contains(r->err, "--display-server wants HOST:PORT");
    unlink(pfm);
    free(r);
}

/* tev closed and opened again: rt connects again by itself and sends the
 * image anew; after Ctrl-C the second connection shows the written image. */
static void test_display_server_reconnects(void **state)
{
    (void)state;
    char address[64];
    int listener = tev_socket(address, true);
    const char *pfm = path_in("again.pfm");
    const char *const args[] = {"-q", "-s", "100000", "-t", "2", "--integrator", "path", "--display-server", address,
                                "-o", pfm, slow_scene(), NULL};
    double t0 = now_s();
    pid_t pid = spawn(args);
    int fd = tev_accept(listener);
    tev_view v;
    memset(&v, 0, sizeof v);
    while (v.updates == 0)
        assert_true(tev_read_packet(fd, &v));
    close(fd); /* tev goes away */
    fd = tev_accept(listener);
    tev_view w;
    memset(&w, 0, sizeof w);
    while (w.updates == 0)
        assert_true(tev_read_packet(fd, &w));
    kill(pid, SIGINT);
    while (tev_read_packet(fd, &w))
        ;
    close(fd);
    close(listener);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    wait_for(pid, t0, 120.0, r);
    assert_int_equal(r->status, 130);
    assert_int_equal(w.creates, 1);
    assert_tev_shows(&w, pfm, "again.pfm");
    tev_view_free(&v);
    tev_view_free(&w);
    free(r);
    unlink(pfm);
}

/* ------------------------------------------------------------ --window under Xvfb */

/* Starts Xvfb on a display number it picks itself (-displayfd); returns
 * its pid and the number, or -1 when there is no Xvfb. The pid is kept in
 * running_xvfb until stop_xvfb, so teardown (or the next start) stops an
 * Xvfb that a failing test left running; a test binary killed outright
 * takes its Xvfb along (PR_SET_PDEATHSIG). */
static pid_t running_xvfb = -1;

static void stop_xvfb(void)
{
    if (running_xvfb > 0) {
        kill(running_xvfb, SIGTERM);
        waitpid(running_xvfb, NULL, 0);
    }
    running_xvfb = -1;
}

static pid_t start_xvfb(int *display)
{
    stop_xvfb(); /* one an earlier test left running when it failed: its pid is about to be forgotten */
    if (access("/usr/bin/Xvfb", X_OK) != 0)
        fail_msg("no /usr/bin/Xvfb (require_window_tools first)");
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    pid_t parent = getpid();
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        /* ended with the test binary even when that is killed before its teardown */
        if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || getppid() != parent)
            _exit(127);
        close(fds[0]);
        char fd[16];
        snprintf(fd, sizeof fd, "%d", fds[1]);
        int null = open("/dev/null", O_WRONLY);
        dup2(null, 1);
        dup2(null, 2);
        execl("/usr/bin/Xvfb", "Xvfb", "-displayfd", fd, "-screen", "0", "320x240x24", "-nolisten", "tcp", (char *)NULL);
        _exit(127);
    }
    close(fds[1]);
    char buf[32] = {0};
    size_t n = 0;
    struct pollfd pf = {fds[0], POLLIN, 0};
    while (n < sizeof buf - 1 && poll(&pf, 1, 30000) == 1) {
        ssize_t k = read(fds[0], buf + n, sizeof buf - 1 - n);
        if (k <= 0)
            break;
        n += (size_t)k;
        if (memchr(buf, '\n', n))
            break;
    }
    close(fds[0]);
    if (sscanf(buf, "%d", display) != 1) {
        kill(pid, SIGTERM);
        waitpid(pid, NULL, 0);
        fail_msg("Xvfb did not report its display");
    }
    running_xvfb = pid;
    return pid;
}

/* Saves DISPLAY into saved and unsets it, so that a --window test sees no
 * display but the Xvfb it starts. */
static void save_display(char saved[256])
{
    const char *display = getenv("DISPLAY");
    saved[0] = '\0';
    if (display)
        snprintf(saved, 256, "%s", display);
    unsetenv("DISPLAY");
}

/* Puts back the DISPLAY save_display saved (unset if there was none). */
static void restore_display(const char saved[256])
{
    if (saved[0])
        setenv("DISPLAY", saved, 1);
    else
        unsetenv("DISPLAY");
}

/* Skips the calling test, saying why, unless what a --window test needs
 * is installed: SDL2's development files (pkg-config finds sdl2: then the
 * Makefile built rt's window against them), Xvfb, and xdotool when asked.
 * Decided from the system, never from what rt says about itself. */
static void require_window_tools(bool xdotool)
{
    if (system("pkg-config --exists sdl2") != 0) {
        fprintf(stderr, "skip: no SDL2 (pkg-config sdl2; Debian libsdl2-dev): rt is built without --window\n");
        skip();
    }
    if (access("/usr/bin/Xvfb", X_OK) != 0) {
        fprintf(stderr, "skip: no /usr/bin/Xvfb (Debian xvfb)\n");
        skip();
    }
    if (xdotool && access("/usr/bin/xdotool", X_OK) != 0) {
        fprintf(stderr, "skip: no /usr/bin/xdotool (Debian xdotool)\n");
        skip();
    }
}

/* For a --window test, DISPLAY saved, the tools there
 * (require_window_tools): rt, built with SDL2, refuses --window without a
 * display; then starts Xvfb and returns its display number. */
static int window_xvfb(run_result *r, const char *png)
{
    run_args(r, (const char *const[]){"-q", "-r", "8x8", "-s", "1", "--window", "-o", png, NULL});
    assert_int_equal(r->status, 2);
    assert_contains(r->err, "rt: --window: cannot open a window: ");
    assert_null(strstr(r->err, "built without SDL2"));
    int dpy = -1;
    start_xvfb(&dpy);
    return dpy;
}

/* --window under Xvfb: the window shows the rendered image, the PNG's very
 * bytes (read back from the window through RT_WINDOW_SCREENSHOT). Without
 * a display --window is refused with a clear message and exit 2. */
static void test_window(void **state)
{
    (void)state;
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("win.png"), *shot = path_in("win.ppm");
    char saved[256];
    save_display(saved);
    put_precious(png);
    run_args(r, (const char *const[]){"-q", "-r", "8x8", "-s", "1", "--window", "-o", png, NULL});
    assert_int_equal(r->status, 2);
    assert_contains(r->err, "rt: --window: cannot open a window: ");
    assert_precious(png);
    bool without_sdl2 = strstr(r->err, "built without SDL2") != NULL;
    free(r);
    require_window_tools(false);
    assert_false(without_sdl2); /* SDL2 is there: rt was built with it */
    r = malloc(sizeof *r);
    assert_non_null(r);
    int dpy = -1;
    start_xvfb(&dpy);
    char dname[32];
    snprintf(dname, sizeof dname, ":%d", dpy);
    setenv("DISPLAY", dname, 1);
    setenv("RT_WINDOW_SCREENSHOT", shot, 1);
    /* under AddressSanitizer: SDL's libraries (D-Bus, and X11 modules it
     * dlopens and unloads, so their frames cannot even be named for a
     * suppression) keep memory to the end, so this one run is not checked
     * for leaks; every other run of rt in the suite is (no effect without
     * LeakSanitizer) */
    setenv("LSAN_OPTIONS", "detect_leaks=0", 1);
    run_args(r, (const char *const[]){"-q", "-r", "40x24", "-s", "8", "--integrator", "path", "--passes", "2", "--window",
                                      "-o", png, slow_scene(), NULL});
    unsetenv("RT_WINDOW_SCREENSHOT");
    unsetenv("LSAN_OPTIONS");
    restore_display(saved);
    stop_xvfb();
    if (r->status != 0) {
        static char msg[sizeof r->err];
        snprintf(msg, sizeof msg, "%s", r->err);
        int status = r->status;
        free(r);
        fail_msg("rt --window under Xvfb failed (%d): %s", status, msg);
    }
    int w = 0, h = 0, n = 0;
    unsigned char *img = stbi_load(png, &w, &h, &n, 3);
    assert_non_null(img);
    static char ppm[64 * 1024];
    size_t len = read_all(shot, ppm, sizeof ppm);
    assert_true(len != (size_t)-1);
    int sw = 0, sh = 0, maxv = 0, off = 0;
    assert_int_equal(sscanf(ppm, "P6 %d %d %d%n", &sw, &sh, &maxv, &off), 3);
    assert_int_equal(sw, w);
    assert_int_equal(sh, h);
    assert_int_equal(maxv, 255);
    assert_int_equal(len, (size_t)off + 1 + 3 * (size_t)w * (size_t)h);
    assert_memory_equal(ppm + off + 1, img, 3 * (size_t)w * (size_t)h);
    stbi_image_free(img);
    unlink(png);
    unlink(shot);
    free(r);
}

/* Runs rt under the Xvfb display dpy with RT_WINDOW_SCRIPT=script, its
 * stdout to `out`; LeakSanitizer off as in test_window. */
static void run_window_script(run_result *r, int dpy, const char *script, const char *out, const char *const *args)
{
    char dname[32];
    snprintf(dname, sizeof dname, ":%d", dpy);
    setenv("DISPLAY", dname, 1);
    setenv("RT_WINDOW_SCRIPT", script, 1);
    setenv("LSAN_OPTIONS", "detect_leaks=0", 1);
    double t0 = now_s();
    wait_for(spawn_to(args, out), t0, 120.0, r);
    unsetenv("RT_WINDOW_SCRIPT");
    unsetenv("LSAN_OPTIONS");
    unsetenv("DISPLAY");
}

/* The window's camera under Xvfb, driven through SDL's own event queue
 * (RT_WINDOW_SCRIPT): a drag after the render finished moves the camera
 * and renders again from sample 0 (a new image, written again); P prints
 * a `camera` line which, pasted into the scene and rendered without a
 * window, gives the window's final image byte for byte; ] three times
 * and F12 write NAME.1.EXT, the image an --exposure 1 render writes;
 * closing the window mid-render writes the image at the samples reached,
 * labelled "window closed", exit 0. */
static void test_window_camera(void **state)
{
    (void)state;
    require_window_tools(false);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("cam.png"), *out = path_in("cam.out");
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    const char *scene = slow_scene();
    /* 1. a drag, then P, then Esc */
    run_window_script(r, dpy, "wait done; drag left 20 12 30 14; wait done; key P; key Escape", out,
                      (const char *const[]){"-v", "-r", "40x24", "-s", "8", "--integrator", "path", "--passes", "2",
                                            "--window", "-o", png, scene, NULL});
    static char printed[2048];
    read_all(out, printed, sizeof printed);
    int status1 = r->status;
    bool restarted = strstr(r->err, "the camera moved; rendering again from sample 0") != NULL;
    int wrote1 = count_of(r->err, "rt: wrote ");

    /* 2. exposure keys and a snapshot */
    const char *png2 = path_in("cam2.png"), *shot = path_in("cam2.1.png");
    unlink(shot);
    run_window_script(r, dpy, "wait done; key ]; key ]; key ]; key F12; key Escape", NULL,
                      (const char *const[]){"-q", "-r", "40x24", "-s", "8", "--integrator", "path", "--window", "-o",
                                            png2, scene, NULL});
    int status2 = r->status;
    bool snap2 = strstr(r->err, "cam2.1.png: 40x24, 8 of 8 spp (window snapshot)") != NULL;

    /* 3. closed mid-render */
    const char *png3 = path_in("cam3.png");
    run_window_script(r, dpy, "wait pass; drag right 10 10 15 12; wait pass; key Escape", NULL,
                      (const char *const[]){"-r", "40x24", "-s", "100000", "--integrator", "path", "--passes", "2",
                                            "--window", "-o", png3, scene, NULL});
    stop_xvfb();
    restore_display(saved);
    assert_int_equal(status1, 0);
    assert_true(restarted);
    assert_int_equal(wrote1, 2); /* the first camera's image, then the moved one's */
    assert_int_equal(strncmp(printed, "camera position ", 16), 0);
    assert_null(strstr(printed, "camera position 0 0 4 look_at 0 0 0 "));
    assert_int_equal(status2, 0);
    assert_true(snap2);
    if (r->status != 0)
        fail_msg("closing the window mid-render: exit %d: %s", r->status, r->err);
    assert_contains(r->err, "of 100000 spp, window closed");
    assert_contains(r->err, "rt: wrote ");

    /* the drag changed the image: the first camera's render differs */
    const char *orig = path_in("cam-orig.png"), *again = path_in("cam-again.png");
    render_ok(orig, (const char *const[]){"-r", "40x24", "-s", "8", "--integrator", "path", scene, NULL});
    assert_false(same_file(orig, png));
    /* the printed line, pasted into the scene, renders the window's image */
    render_ok(again, (const char *const[]){"-r", "40x24", "-s", "8", "--integrator", "path",
                                           slow_scene_with_camera(printed), NULL});
    assert_same_file(again, png);
    /* ] ] ] = +1 stop: the snapshot is what --exposure 1 writes */
    render_ok(again, (const char *const[]){"-r", "40x24", "-s", "8", "--integrator", "path", "--exposure", "1", scene,
                                           NULL});
    assert_same_file(again, shot);
    assert_no_temp_files();
    unlink(png);
    unlink(png2);
    unlink(png3);
    unlink(shot);
    unlink(orig);
    unlink(again);
    unlink(out);
    free(r);
}

typedef struct printed_camera {
    double p[3], at[3], up[3], fov;
} printed_camera;

/* The `camera` lines in text, in order; returns how many (at most max). */
static int printed_cameras(const char *text, printed_camera *c, int max)
{
    int n = 0;
    for (const char *l = strstr(text, "camera position "); l && n < max; l = strstr(l + 1, "\ncamera position ")) {
        if (*l == '\n')
            l++;
        printed_camera *k = &c[n];
        if (sscanf(l, "camera position %lf %lf %lf look_at %lf %lf %lf up %lf %lf %lf fov %lf", &k->p[0], &k->p[1],
                   &k->p[2], &k->at[0], &k->at[1], &k->at[2], &k->up[0], &k->up[1], &k->up[2], &k->fov) != 10)
            fail_msg("cannot read the printed camera line: %.200s", l);
        n++;
    }
    return n;
}

static double cam_dist(const printed_camera *c)
{
    double d = 0.0;
    for (int i = 0; i < 3; i++)
        d += (c->at[i] - c->p[i]) * (c->at[i] - c->p[i]);
    return sqrt(d);
}

/* |unit view direction of a - that of b| */
static double cam_turn(const printed_camera *a, const printed_camera *b)
{
    double da = cam_dist(a), db = cam_dist(b), t = 0.0;
    for (int i = 0; i < 3; i++) {
        double d = (a->at[i] - a->p[i]) / da - (b->at[i] - b->p[i]) / db;
        t += d * d;
    }
    return sqrt(t);
}

static double cam_moved(const printed_camera *a, const printed_camera *b)
{
    double t = 0.0;
    for (int i = 0; i < 3; i++)
        t += (a->at[i] - b->at[i]) * (a->at[i] - b->at[i]);
    return sqrt(t);
}

/* Each input reaches the camera as documented (scripted SDL events, P
 * after each): a right drag pans (direction and distance kept, look_at
 * moved), two wheel notches dolly to 0.85^2 of the distance (look_at
 * kept), W walks 2% of the scene's bounding-box diagonal forward, R goes
 * back to the first camera, whose finished render is then the image a
 * render without a window writes. */
static void test_window_inputs(void **state)
{
    (void)state;
    require_window_tools(false);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("in.png"), *out = path_in("in.out");
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    const char *scene = slow_scene(); /* a sphere of radius 1 at the origin: diagonal 2 sqrt(3) */
    run_window_script(r, dpy,
                      "wait done; key P; drag right 20 12 25 12; key P; wheel 2; key P; key W; key P; key R; key P; "
                      "wait done; key Escape",
                      out,
                      (const char *const[]){"-q", "-r", "40x24", "-s", "4", "--integrator", "path", "--window", "-o",
                                            png, scene, NULL});
    stop_xvfb();
    restore_display(saved);
    if (r->status != 0)
        fail_msg("rt --window failed (%d): %s", r->status, r->err);
    static char text[8192];
    read_all(out, text, sizeof text);
    printed_camera c[5];
    assert_int_equal(printed_cameras(text, c, 5), 5);
    assert_true(strstr(text, "camera position 0 0 4 look_at 0 0 0 up 0 1 0 fov 40\n") == text);
    /* pan */
    assert_true(cam_turn(&c[1], &c[0]) < 1e-6);
    assert_true(fabs(cam_dist(&c[1]) - cam_dist(&c[0])) < 1e-5);
    assert_true(cam_moved(&c[1], &c[0]) > 0.01);
    /* dolly */
    assert_true(cam_moved(&c[2], &c[1]) == 0.0);
    assert_true(fabs(cam_dist(&c[2]) - 0.85 * 0.85 * cam_dist(&c[1])) < 1e-5);
    /* walk */
    assert_true(cam_turn(&c[3], &c[2]) < 1e-6);
    assert_true(fabs(cam_moved(&c[3], &c[2]) - 0.02 * 2.0 * sqrt(3.0)) < 1e-5);
    assert_true(fabs(cam_dist(&c[3]) - cam_dist(&c[2])) < 1e-5);
    /* home */
    assert_memory_equal(&c[4], &c[0], sizeof c[0]);
    const char *plain = path_in("in-plain.png");
    render_ok(plain, (const char *const[]){"-r", "40x24", "-s", "4", "--integrator", "path", scene, NULL});
    assert_same_file(plain, png);
    unlink(plain);
    unlink(png);
    unlink(out);
    free(r);
}

/* Runs xdotool with args on display dpy; its stdout into `out` (cap
 * bytes, may be NULL); returns its exit status. */
static int xdo(int dpy, char *out, size_t cap, const char *const *args)
{
    const char *xout = path_in("xdo.out");
    const char *argv[32];
    make_argv(argv, 32, "xdotool", args);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        char dname[32];
        snprintf(dname, sizeof dname, ":%d", dpy);
        setenv("DISPLAY", dname, 1);
        int o = open(xout, O_WRONLY | O_CREAT | O_TRUNC, 0644), null = open("/dev/null", O_RDWR);
        if (o < 0 || null < 0)
            _exit(127);
        dup2(null, 0);
        dup2(o, 1);
        dup2(null, 2);
        execv("/usr/bin/xdotool", (char *const *)argv);
        _exit(127);
    }
    int st = 0;
    double t0 = now_s();
    while (waitpid(pid, &st, WNOHANG) == 0) {
        if (now_s() - t0 > 30.0) {
            kill(pid, SIGKILL);
            waitpid(pid, &st, 0);
            return -1;
        }
        sleep_s(0.01);
    }
    if (out && read_all(xout, out, cap) == (size_t)-1)
        out[0] = 0;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Waits until file `path` holds `needle` `times` times, or 60 s. */
static bool wait_for_text(const char *path, const char *needle, int times)
{
    static char buf[16384];
    for (double t0 = now_s(); now_s() - t0 < 60.0; sleep_s(0.02))
        if (read_all(path, buf, sizeof buf) != (size_t)-1 && count_of(buf, needle) >= times)
            return true;
    return false;
}

/* The same through real X input: xdotool (Debian xdotool; tools/install-deps.sh
 * installs it when it can) moves Xvfb's pointer with XTEST, drags over the
 * window, presses P and Esc; the steps wait on what rt says (its "wrote"
 * lines, the printed camera). The drag renders again at a new camera, and
 * the printed line pasted into the scene renders the window's final image.
 * Skipped without SDL2, Xvfb or xdotool. */
static void test_window_camera_xdotool(void **state)
{
    (void)state;
    require_window_tools(true);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("xdo.png"), *out = path_in("xdo.txt"), *err = path_in("stderr.txt");
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    const char *scene = slow_scene();
    char dname[32];
    snprintf(dname, sizeof dname, ":%d", dpy);
    setenv("DISPLAY", dname, 1);
    setenv("LSAN_OPTIONS", "detect_leaks=0", 1);
    double t0 = now_s();
    pid_t pid = spawn_to((const char *const[]){"-v", "-r", "40x24", "-s", "8", "--integrator", "path", "--passes", "2",
                                               "--window", "-o", png, scene, NULL},
                         out);
    unsetenv("LSAN_OPTIONS");
    restore_display(saved);
    static char wid[64], printed[2048];
    bool ok = xdo(dpy, wid, sizeof wid, (const char *const[]){"search", "--sync", "--name", "^rt: ", NULL}) == 0;
    if (ok)
        *strchr(wid, '\n') = 0;
    bool first = ok && wait_for_text(err, "rt: wrote ", 1);
    /* a drag of 10 pixels right, 2 down with the left button */
    bool dragged = first && xdo(dpy, NULL, 0,
                                (const char *const[]){"mousemove", "--window", wid, "20", "12", "mousedown", "1",
                                                      "mousemove", "--window", wid, "30", "14", "mouseup", "1",
                                                      NULL}) == 0;
    bool again = dragged && wait_for_text(err, "the camera moved; rendering again from sample 0", 1) &&
                 wait_for_text(err, "rt: wrote ", 2);
    bool keyed = again && xdo(dpy, NULL, 0, (const char *const[]){"windowfocus", "--sync", wid, "key", "p", NULL}) == 0;
    bool printed_ok = keyed && wait_for_text(out, "camera position ", 1);
    xdo(dpy, NULL, 0, (const char *const[]){"key", "Escape", NULL});
    wait_for(pid, t0, 120.0, r);
    stop_xvfb();
    assert_true(ok);
    assert_true(first);
    assert_true(dragged);
    if (!again)
        fail_msg("the drag did not render again:\n%s", r->err);
    assert_true(printed_ok);
    assert_int_equal(r->status, 0);
    read_all(out, printed, sizeof printed);
    assert_null(strstr(printed, "camera position 0 0 4 look_at 0 0 0 "));
    const char *again_png = path_in("xdo-again.png");
    render_ok(again_png, (const char *const[]){"-r", "40x24", "-s", "8", "--integrator", "path",
                                               slow_scene_with_camera(printed), NULL});
    assert_same_file(again_png, png);
    unlink(png);
    unlink(again_png);
    unlink(out);
    free(r);
}

/* ------------------------------------------------------------ the terminal: lines kept apart */

/* Runs rt with args under the Xvfb display dpy (-1: none) and
 * RT_WINDOW_SCRIPT=script (NULL: none), its stderr, and its stdout too
 * when stdout_too, on a terminal (test_terminal.h); what the terminal got
 * into raw, the lines it shows into screen; the exit status. */
static int run_terminal_window(int dpy, const char *script, bool stdout_too, const char *const *args, char *raw,
                               size_t raw_cap, char *screen, size_t screen_cap)
{
    char dname[32];
    snprintf(dname, sizeof dname, ":%d", dpy);
    if (dpy >= 0)
        setenv("DISPLAY", dname, 1);
    if (script)
        setenv("RT_WINDOW_SCRIPT", script, 1);
    setenv("LSAN_OPTIONS", "detect_leaks=0", 1); /* SDL's libraries, as in test_window */
    const char *argv[64];
    make_argv(argv, 64, rt_bin_absolute(), args);
    test_terminal_result tr;
    test_terminal_run_io(argv, NULL, stdout_too, raw, raw_cap, &tr);
    unsetenv("RT_WINDOW_SCRIPT");
    unsetenv("LSAN_OPTIONS");
    if (dpy >= 0)
        unsetenv("DISPLAY");
    test_terminal_screen(raw, screen, screen_cap);
    return tr.status >= 0 ? tr.status : 128 + tr.signal;
}

/* Every line the terminal shows is one thing: a line of rt's ("rt: "), a
 * line P printed ("camera position ", "# "), or the progress line; no
 * line holds a second one after the progress bar or a phase. */
static void assert_lines_apart(const char *screen)
{
    for (const char *l = screen; *l;) {
        const char *nl = strchr(l, '\n');
        size_t n = nl ? (size_t)(nl - l) : strlen(l);
        char line[4096];
        snprintf(line, sizeof line, "%.*s", (int)(n < sizeof line ? n : sizeof line - 1), l);
        bool own = strncmp(line, "rt: ", 4) == 0 || strncmp(line, "camera position ", 16) == 0 ||
                   strncmp(line, "# ", 2) == 0;
        if (!own && !strstr(line, "render [") && !strstr(line, " ..."))
            fail_msg("a line the terminal shows is none of rt's:\n%s\nin:\n%s", line, screen);
        if (strstr(line + 1, "rt: ") || strstr(line + 1, "camera position"))
            fail_msg("two things on one line of the terminal:\n%s\nin:\n%s", line, screen);
        l = nl ? nl + 1 : l + n;
    }
}

/* Lines written while the progress line is up start on a line of their
 * own: -v lines while a phase ("load ...", "kd-tree ...") is shown, and
 * the camera line P prints on stdout while the bar is up. */
static void test_terminal_lines_apart(void **state)
{
    (void)state;
    static char raw[1 << 17], screen[1 << 17];
    const char *png = path_in("apart.png");
    int status = run_terminal_window(-1, NULL, true,
                                     (const char *const[]){"-v", "-r", "24x24", "-s", "8", "-o", png, slow_scene(),
                                                           NULL},
                                     raw, sizeof raw, screen, sizeof screen);
    if (status != 0)
        fail_msg("rt -v on a terminal exited %d:\n%s", status, screen);
    assert_contains(screen, "\nrt: scene: ");
    assert_contains(screen, "\nrt: kd-tree: built in ");
    assert_lines_apart(screen);

    require_window_tools(false);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    free(r);
    /* P while the bar of a long render is up, then Esc */
    status = run_terminal_window(dpy, "wait pass; key P; wait pass; key Escape", true,
                                 (const char *const[]){"-r", "40x24", "-s", "100000", "--integrator", "path",
                                                       "--passes", "2", "--window", "-o", png, slow_scene(), NULL},
                                 raw, sizeof raw, screen, sizeof screen);
    stop_xvfb();
    restore_display(saved);
    if (status != 0)
        fail_msg("rt --window on a terminal exited %d:\n%s", status, screen);
    assert_contains(screen, "camera position 0 0 4 look_at 0 0 0 up 0 1 0 fov 40\n# as flags: ");
    assert_contains(screen, "of 100000 spp, window closed");
    assert_lines_apart(screen);
    unlink(png);
}

/* After a move of the window's camera the progress line gives the phases
 * before rendering the times they took, not the time the window stood
 * idle: every "load N.NNs, kd-tree N.NNs, window N.NNs" before "render ["
 * on the terminal reads the same, with the window idle 1.5 s between the
 * first render and the move. */
static void test_progress_line_after_a_move(void **state)
{
    (void)state;
    require_window_tools(false);
    static char raw[1 << 17], screen[1 << 17];
    const char *png = path_in("idle.png");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    free(r);
    int status = run_terminal_window(dpy, "wait done; sleep 1500; drag left 20 12 30 14; wait done; key Escape", false,
                                     (const char *const[]){"-r", "40x24", "-s", "8", "--integrator", "path",
                                                           "--passes", "2", "--window", "-o", png, slow_scene(), NULL},
                                     raw, sizeof raw, screen, sizeof screen);
    stop_xvfb();
    restore_display(saved);
    if (status != 0)
        fail_msg("rt --window on a terminal exited %d:\n%s", status, screen);
    assert_int_equal(count_of(screen, "rt: wrote "), 2); /* the first camera's image, then the moved one's */
    int bars = 0;
    char first[256] = "";
    for (const char *k = strstr(raw, "s, render ["); k; k = strstr(k + 1, "s, render [")) {
        const char *start = k;
        while (start > raw && start[-1] != '\r' && start[-1] != '\n')
            start--;
        char phases[256]; /* "load 0.00s, kd-tree 0.00s, window 0.07s" */
        snprintf(phases, sizeof phases, "%.*s", (int)(k + 1 - start), start);
        if (!first[0])
            snprintf(first, sizeof first, "%s", phases);
        if (strcmp(phases, first) != 0)
            fail_msg("the phases took \"%s\" at first, \"%s\" on a later progress line:\n%s", first, phases, screen);
        bars++;
    }
    assert_true(bars >= 2);
    unlink(png);
}

/* Q closes the window, as --help says (Esc too); C sinks along up and E
 * rises, by the walking step (2% of the bounds' diagonal). */
static void test_window_keys(void **state)
{
    (void)state;
    require_window_tools(false);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("keys.png"), *out = path_in("keys.out");
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    /* q after the render: closed, nothing rendered again (the Escape after
     * a second render would close a window that q had not) */
    run_window_script(r, dpy, "wait done; key q; wait done; key Escape", NULL,
                      (const char *const[]){"-r", "40x24", "-s", "4", "--integrator", "path", "--window", "-o", png,
                                            slow_scene(), NULL});
    int status1 = r->status, wrote1 = count_of(r->err, "rt: wrote ");
    static char err1[sizeof r->err];
    snprintf(err1, sizeof err1, "%s", r->err);
    run_window_script(r, dpy, "wait done; key P; key C; key P; key E; key P; key Q; wait done; key Escape", out,
                      (const char *const[]){"-q", "-r", "40x24", "-s", "4", "--integrator", "path", "--window", "-o",
                                            png, slow_scene(), NULL});
    stop_xvfb();
    restore_display(saved);
    if (status1 != 0 || wrote1 != 1)
        fail_msg("q should close the window after the first render (exit %d, %d wrote lines):\n%s", status1, wrote1,
                 err1);
    if (r->status != 0)
        fail_msg("rt --window failed (%d): %s", r->status, r->err);
    static char text[8192];
    read_all(out, text, sizeof text);
    printed_camera c[3];
    assert_int_equal(printed_cameras(text, c, 3), 3);
    double step = 0.02 * 2.0 * sqrt(3.0); /* a sphere of radius 1: diagonal 2 sqrt(3) */
    assert_true(fabs(c[1].p[1] - (c[0].p[1] - step)) < 1e-5 && fabs(c[1].at[1] - (c[0].at[1] - step)) < 1e-5);
    assert_true(fabs(c[1].p[0] - c[0].p[0]) < 1e-6 && fabs(c[1].p[2] - c[0].p[2]) < 1e-6);
    assert_true(fabs(c[2].p[1] - c[0].p[1]) < 1e-5);
    unlink(png);
    unlink(out);
    free(r);
}

/* Pixels of an 8-bit image that differ from its top-left pixel (the
 * background) by more than 8 in a channel. */
static int model_pixels(const char *png)
{
    int w = 0, h = 0, n = 0, count = 0;
    unsigned char *img = stbi_load(png, &w, &h, &n, 3);
    assert_non_null(img);
    for (int i = 0; i < w * h; i++)
        for (int c = 0; c < 3; c++)
            if (abs((int)img[3 * i + c] - (int)img[c]) > 8) {
                count++;
                break;
            }
    stbi_image_free(img);
    return count;
}

/* A glTF camera's look_at is a point 1 unit ahead, which means nothing:
 * orbiting about it swung the model out of the window. The window orbits
 * about the model's depth instead (the first surface at the image's
 * centre): after a drag of 45 degrees the box of assets/box.gltf
 * (3.7 units away) is still in view, as large as before (within 25%),
 * and the printed camera looks at a point of the box, at the first
 * camera's distance. */
static void test_window_orbits_a_gltf_camera(void **state)
{
    (void)state;
    require_window_tools(false);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("orbit.png"), *first = path_in("orbit-first.png"), *out = path_in("orbit.out");
    char saved[256];
    save_display(saved);
    int dpy = window_xvfb(r, png);
    run_window_script(r, dpy, "wait done; key P; drag left 32 32 48 32; wait done; key P; key Escape", out,
                      (const char *const[]){"-q", "-r", "64x64", "-s", "1", "--window", "-o", png, "assets/box.gltf",
                                            NULL});
    stop_xvfb();
    restore_display(saved);
    if (r->status != 0)
        fail_msg("rt --window failed (%d): %s", r->status, r->err);
    static char text[8192];
    read_all(out, text, sizeof text);
    printed_camera c[2];
    assert_int_equal(printed_cameras(text, c, 2), 2);
    assert_true(fabs(cam_dist(&c[0]) - 1.0) < 1e-5); /* the glTF camera as loaded */
    /* a unit box turned about y: its points lie within sqrt(3)/2 of the origin */
    if (sqrt(c[1].at[0] * c[1].at[0] + c[1].at[1] * c[1].at[1] + c[1].at[2] * c[1].at[2]) > 0.87)
        fail_msg("the orbit's pivot %g %g %g is not on the box", c[1].at[0], c[1].at[1], c[1].at[2]);
    double d0 = sqrt(c[0].p[0] * c[0].p[0] + c[0].p[1] * c[0].p[1] + c[0].p[2] * c[0].p[2]);
    assert_true(cam_dist(&c[1]) > 0.5 * d0 && cam_dist(&c[1]) < d0);
    assert_true(cam_turn(&c[1], &c[0]) > 0.5); /* it did turn */
    render_ok(first, (const char *const[]){"-r", "64x64", "-s", "1", "assets/box.gltf", NULL});
    int before = model_pixels(first), after = model_pixels(png);
    if (!(before > 100 && after > 0.75 * before && after < 1.25 * before))
        fail_msg("the box covers %d pixels before the orbit, %d after", before, after);
    unlink(png);
    unlink(first);
    unlink(out);
    free(r);
}

/* SDL's own messages go through rt's log: with no display to be had (a
 * DISPLAY nobody serves, XDG_RUNTIME_DIR unset, so that SDL tries Wayland
 * too and libwayland complains on stderr) every line is rt's, and the
 * reason names the display; with -v SDL's lines come as "rt: SDL: ...". */
static void test_window_sdl_messages(void **state)
{
    (void)state;
    require_window_tools(false);
    char saved[256];
    save_display(saved);
    char xdg[512] = "";
    if (getenv("XDG_RUNTIME_DIR"))
        snprintf(xdg, sizeof xdg, "%s", getenv("XDG_RUNTIME_DIR"));
    unsetenv("XDG_RUNTIME_DIR");
    unsetenv("WAYLAND_DISPLAY");
    unsetenv("SDL_VIDEODRIVER");
    int free_dpy = 7000;
    char sock[64];
    for (;; free_dpy++) { /* a display number nothing serves */
        snprintf(sock, sizeof sock, "/tmp/.X11-unix/X%d", free_dpy);
        if (access(sock, F_OK) != 0)
            break;
    }
    char dname[32];
    snprintf(dname, sizeof dname, ":%d", free_dpy);
    setenv("DISPLAY", dname, 1);
    setenv("LSAN_OPTIONS", "detect_leaks=0", 1);
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    const char *png = path_in("sdl.png");
    put_precious(png);
    run_args(r, (const char *const[]){"-r", "8x8", "-s", "1", "--window", "-o", png, NULL});
    int status = r->status;
    static char err[sizeof r->err];
    snprintf(err, sizeof err, "%s", r->err);
    run_args(r, (const char *const[]){"-v", "-r", "8x8", "-s", "1", "--window", "-o", png, NULL});
    unsetenv("LSAN_OPTIONS");
    if (xdg[0])
        setenv("XDG_RUNTIME_DIR", xdg, 1);
    restore_display(saved);
    assert_int_equal(status, 2);
    assert_lines_prefixed(err);
    assert_contains(err, "rt: --window: cannot open a window: ");
    char want[64];
    snprintf(want, sizeof want, "DISPLAY=%s", dname);
    assert_contains(err, want);
    assert_int_equal(r->status, 2);
    assert_lines_prefixed(r->err);
    assert_precious(png);
    unlink(png);
    free(r);
}

/* `rt compare` is reached from the command line: an image against itself
 * (every metric 0, exit 0), against a different one with a threshold that
 * fails (exit 1), and against a missing file (exit 2, the file named). */
static void test_compare_command(void **state)
{
    (void)state;
    const char *a = path_in("cmp-a.pfm"), *b = path_in("cmp-b.pfm"), *out = path_in("cmp-out.txt");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-q", "-r", "16x16", "-s", "1", "-o", a, NULL});
    assert_int_equal(r->status, 0);
    run_args(r, (const char *const[]){"-q", "-r", "16x16", "-s", "4", "-o", b, NULL});
    assert_int_equal(r->status, 0);
    double t0 = now_s();
    wait_for(spawn_to((const char *const[]){"compare", a, a, NULL}, out), t0, 120.0, r);
    assert_int_equal(r->status, 0);
    static char text[8192];
    assert_true(read_all(out, text, sizeof text) != (size_t)-1);
    assert_contains(text, "RMSE: 0\n");
    assert_contains(text, "LDR-FLIP: 0.000000\n");
    run_args(r, (const char *const[]){"compare", a, b, "--max-rmse", "0", NULL});
    assert_int_equal(r->status, 1);
    run_args(r, (const char *const[]){"compare", a, path_in("no-such.pfm"), NULL});
    assert_int_equal(r->status, 2);
    assert_contains(r->err, "no-such.pfm");
    free(r);
}

/* rt convert and rt compare given a part (sums and counts, docs/farm.md):
 * its region's picture, sum / count, the bits of the render's own pixels;
 * a .pfm part's counts file and a broken part refused by name. */
static void test_convert_compare_parts(void **state)
{
    (void)state;
    const char *full = path_in("pc-full.pfm"), *crop = path_in("pc-crop.exr"), *whole = path_in("pc-whole.pfm");
    const char *out = path_in("pc-out.pfm");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-q", "-r", "16x12", "-s", "4", "-o", full, NULL});
    assert_int_equal(r->status, 0);
    run_args(r, (const char *const[]){"-q", "-r", "16x12", "-s", "4", "--crop", "4", "2", "12", "10", "-o", crop,
                                      NULL});
    assert_int_equal(r->status, 0);
    run_args(r, (const char *const[]){"-q", "-r", "16x12", "-s", "4", "--part", "0/1", "-o", whole, NULL});
    assert_int_equal(r->status, 0);
    /* a lone crop: its 8x8 pixels, each the render's */
    run_args(r, (const char *const[]){"convert", crop, out, NULL});
    assert_int_equal(r->status, 0);
    assert_contains(r->err, "is a part: pixels [4, 12) x [2, 10) of 16x12, samples 0:4 of 4");
    rt_framebuffer a, b;
    rt_error err = {0};
    assert_int_equal(rt_image_read(full, &a, &err), RT_OK);
    assert_int_equal(rt_image_read(out, &b, &err), RT_OK);
    assert_int_equal(b.width, 8);
    assert_int_equal(b.height, 8);
    for (int y = 0; y < 8; y++)
        assert_memory_equal(b.rgb + 3 * (size_t)y * 8, a.rgb + 3 * ((size_t)(y + 2) * 16 + 4), 8 * 3 * sizeof(float));
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
    /* a part of the whole image, by its image or its sidecar: the render's bytes */
    run_args(r, (const char *const[]){"convert", whole, out, NULL});
    assert_int_equal(r->status, 0);
    assert_same_file(full, out);
    char sidecar[700];
    snprintf(sidecar, sizeof sidecar, "%s.json", whole);
    run_args(r, (const char *const[]){"compare", sidecar, full, "--max-rmse", "0", "--max-flip", "0", NULL});
    assert_int_equal(r->status, 0);
    assert_contains(r->err, "pc-whole.pfm.json is a part");
    run_args(r, (const char *const[]){"compare", full, crop, NULL}); /* the crop is 8x8: sizes differ */
    assert_int_equal(r->status, 2);
    assert_contains(r->err, "is 16x12 but the reference");
    /* not the part's companion files, nor a part whose sidecar lies */
    REFUSE(out_png, "pc-whole.count.pfm holds the sample counts of the part", "pc-whole.pfm", "convert",
           path_in("pc-whole.count.pfm"), out_png);
    static char text[1 << 14];
    size_t n = read_all(sidecar, text, sizeof text);
    assert_true(n != (size_t)-1);
    char *hash = strstr(text, "\"image_fnv1a64\": \"");
    assert_non_null(hash);
    hash[18] = hash[18] == '0' ? '1' : '0'; /* another image's hash */
    test_write_file(sidecar, text, n);
    REFUSE(out_png, "pc-whole.pfm", NULL, "convert", whole, out_png);
    REFUSE(out_png, "pc-whole.pfm", NULL, "compare", whole, full);
    free(r);
    unlink(full), unlink(crop), unlink(out), unlink(whole), unlink(sidecar);
    unlink(path_in("pc-whole.count.pfm")), unlink(path_in("pc-whole.block.0.pfm"));
    snprintf(sidecar, sizeof sidecar, "%s.json", crop);
    unlink(sidecar);
}

/* --crop with -o NAME.png: the cropped image (pbrt's --pixelbounds), each
 * pixel the full render's; --part-out keeps the part beside it; -o .exr
 * is a part as before. */
static void test_crop_image(void **state)
{
    (void)state;
    const char *full = path_in("ci-full.png"), *crop = path_in("ci-crop.png"), *part = path_in("ci-part.exr");
    run_result *r = malloc(sizeof *r);
    assert_non_null(r);
    run_args(r, (const char *const[]){"-q", "-r", "16x12", "-s", "2", "-o", full, NULL});
    assert_int_equal(r->status, 0);
    run_args(r, (const char *const[]){"-r", "16x12", "-s", "2", "--crop", "4", "2", "12", "10", "-o", crop,
                                      "--part-out", part, NULL});
    assert_int_equal(r->status, 0);
    assert_contains(r->err, ": 8x8, 2 of 2 spp");
    int fw, fh, cw, ch, n;
    unsigned char *f = stbi_load(full, &fw, &fh, &n, 3), *c = stbi_load(crop, &cw, &ch, &n, 3);
    assert_non_null(f);
    assert_non_null(c);
    assert_int_equal(cw, 8);
    assert_int_equal(ch, 8);
    for (int y = 0; y < 8; y++)
        assert_memory_equal(c + (size_t)y * 8 * 3, f + ((size_t)(y + 2) * 16 + 4) * 3, 8 * 3);
    stbi_image_free(f);
    stbi_image_free(c);
    char sidecar[700];
    snprintf(sidecar, sizeof sidecar, "%s.json", part);
    assert_int_equal(access(sidecar, F_OK), 0); /* the part too */
    unlink(part), unlink(sidecar), unlink(crop);
    run_args(r, (const char *const[]){"-q", "-r", "16x12", "-s", "2", "--crop", "4", "2", "12", "10", "-o", part,
                                      NULL});
    assert_int_equal(r->status, 0);
    assert_int_equal(access(sidecar, F_OK), 0); /* .exr: a part, as before */
    REFUSE(out_png, "--crop 4 2 40 10: the image is only 16x12", NULL, "-r", "16x12", "--crop", "4", "2", "40", "10",
           "-o", out_png);
    free(r);
    unlink(full), unlink(part), unlink(sidecar);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_flags),
        cmocka_unit_test(test_flag_forms),
        cmocka_unit_test(test_flag_forms_same_image),
        cmocka_unit_test(test_camera_flags),
        cmocka_unit_test(test_flag_conveniences),
        cmocka_unit_test(test_help_flags_in_readme),
        cmocka_unit_test(test_verbose_lines_prefixed),
        cmocka_unit_test(test_no_input_says_so),
        cmocka_unit_test(test_bad_scene_files),
        cmocka_unit_test(test_inputs),
        cmocka_unit_test(test_info),
        cmocka_unit_test(test_info_flags),
        cmocka_unit_test(test_model_defaults),
        cmocka_unit_test(test_bad_models),
        cmocka_unit_test(test_missing_textures),
        cmocka_unit_test(test_bad_images),
        cmocka_unit_test(test_bad_output),
        cmocka_unit_test(test_memory_budget),
        cmocka_unit_test(test_threads_same_image),
        cmocka_unit_test(test_deep_recursion),
        cmocka_unit_test(test_sigint_writes_finished_tiles),
        cmocka_unit_test(test_sigterm_writes_finished_tiles),
        cmocka_unit_test(test_sigint_writes_passes),
        cmocka_unit_test(test_sigterm_writes_passes),
        cmocka_unit_test(test_time_limit),
        cmocka_unit_test(test_sigterm_frame_kept_apart),
        cmocka_unit_test(test_preview),
        cmocka_unit_test(test_progress_line_on_terminal),
        cmocka_unit_test(test_second_sigint_exits_at_once),
        cmocka_unit_test(test_killed_write_leaves_no_temp),
        cmocka_unit_test(test_write_renames_right_after_link),
        cmocka_unit_test(test_display_server),
        cmocka_unit_test(test_display_server_aovs),
        cmocka_unit_test(test_display_server_absent),
        cmocka_unit_test(test_display_server_reconnects),
        cmocka_unit_test(test_window),
        cmocka_unit_test(test_window_camera),
        cmocka_unit_test(test_window_camera_xdotool),
        cmocka_unit_test(test_window_inputs),
        cmocka_unit_test(test_window_keys),
        cmocka_unit_test(test_window_orbits_a_gltf_camera),
        cmocka_unit_test(test_window_sdl_messages),
        cmocka_unit_test(test_terminal_lines_apart),
        cmocka_unit_test(test_progress_line_after_a_move),
        cmocka_unit_test(test_compare_command),
        cmocka_unit_test(test_convert_compare_parts),
        cmocka_unit_test(test_crop_image),
    };
    return cmocka_run_group_tests_name("cli", tests, setup, teardown);
}
