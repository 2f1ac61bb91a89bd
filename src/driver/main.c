/* main.c - the `rt` command: parse flags, load a scene or model, build the
 * kd-tree, render on all cores (progress.c draws the progress bar and the
 * live preview), write the image.
 *
 * Exit status: 0 on success, 2 for bad input (flags, scene files, models,
 * images, an unwritable output), 130 when interrupted (the finished tiles
 * are still written). Every failure says what and where on stderr, and never
 * leaves a partial file over an existing image.
 *
 * Memory: the process runs under a budget (--max-memory, default 75% of the
 * physical memory, or of the cgroup's limit when that is lower), enforced
 * with setrlimit(RLIMIT_DATA), which Linux >= 4.7 applies to the heap and
 * every private writable mapping. An allocation past it fails, the checked
 * allocation reports "out of memory", and we say which budget was hit and
 * how to raise it, instead of swapping or meeting the OOM killer. Sanitizer
 * builds skip the limit (their shadow memory would trip it).
 */
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "rt/render/camera.h"
#include "rt/io/gltf.h"
#include "rt/io/framebuffer.h"
#include "rt/accel/kdtree.h"
#include "rt/io/mesh_io.h"
#include "rt/render/integrator.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/tangents.h"
#include "rt/scene/validate.h"

#include "progress.h"

#define RT_VERSION "0.1.0"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define RT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define RT_SANITIZED 1
#endif
#endif
#ifndef RT_SANITIZED
#define RT_SANITIZED 0
#endif

/* The kd-tree's primitive ids are 30 bits (src/kdtree.c). */
#define MAX_PRIMITIVES (((size_t)1 << 30) - 2)
/* whitted: rays a camera sample may spawn through diffuse gathering
 * (diffuse_rays ^ diffuse_bounces); more is a render that never ends. */
#define MAX_DIFFUSE_TREE ((double)(1 << 24))

static atomic_int interrupted;

static void on_signal(int sig)
{
    if (atomic_exchange(&interrupted, 1)) {
        /* second Ctrl-C: leave at once */
        signal(sig, SIG_DFL);
        raise(sig);
    }
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------ memory budget */

typedef struct memory_budget {
    unsigned long long bytes; /* 0 = none */
    bool from_flag;           /* --max-memory given */
    bool enforced;            /* setrlimit took it */
} memory_budget;

/* The cgroup v2 (or v1) memory limit of this process, 0 when none. */
static unsigned long long cgroup_memory_limit(void)
{
    static const char *const files[] = {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"};
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        FILE *f = fopen(files[i], "r");
        if (!f)
            continue;
        char buf[64] = {0};
        bool ok = fgets(buf, sizeof buf, f) != NULL;
        fclose(f);
        if (!ok || strncmp(buf, "max", 3) == 0)
            continue;
        errno = 0;
        char *end;
        unsigned long long v = strtoull(buf, &end, 10);
        if (!errno && end != buf && v > 0 && v < (1ull << 60))
            return v;
    }
    return 0;
}

/* 75% of physical memory (or of the cgroup limit, when lower). */
static unsigned long long default_memory_budget(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    unsigned long long phys = pages > 0 && page > 0 ? (unsigned long long)pages * (unsigned long long)page : 0;
    unsigned long long cg = cgroup_memory_limit();
    if (cg && (!phys || cg < phys))
        phys = cg;
    return phys / 4 * 3;
}

/* "4G", "512M", "1.5g", "300000K", "123456789" (bytes); "0", "none" or
 * "unlimited" turn the budget off (*out = 0). */
static bool parse_size(const char *s, unsigned long long *out)
{
    if (!s || !*s)
        return false;
    if (strcmp(s, "none") == 0 || strcmp(s, "unlimited") == 0) {
        *out = 0;
        return true;
    }
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || !(v >= 0.0))
        return false;
    double mul = 1.0;
    switch (*end) {
    case 'k': case 'K': mul = 1024.0; end++; break;
    case 'm': case 'M': mul = 1024.0 * 1024.0; end++; break;
    case 'g': case 'G': mul = 1024.0 * 1024.0 * 1024.0; end++; break;
    case 't': case 'T': mul = 1024.0 * 1024.0 * 1024.0 * 1024.0; end++; break;
    default: break;
    }
    if (*end == 'i' && mul > 1.0) /* KiB, MiB, ... */
        end++;
    if ((*end == 'B' || *end == 'b') && end[1] == 0)
        end++;
    if (*end)
        return false;
    double bytes = v * mul;
    if (!(bytes < 9.0e18))
        return false;
    *out = (unsigned long long)bytes;
    return true;
}

static void format_size(unsigned long long bytes, char *buf, size_t size)
{
    if (bytes >= (1ull << 30))
        snprintf(buf, size, "%.1f GiB", (double)bytes / (double)(1ull << 30));
    else
        snprintf(buf, size, "%.0f MiB", (double)bytes / (double)(1ull << 20));
}

/* Caps the data segment (heap and private mappings) at the budget. Below
 * 64 MiB nothing works at all, so smaller budgets are refused. */
static void apply_memory_budget(memory_budget *b)
{
    b->enforced = false;
    if (!b->bytes || RT_SANITIZED)
        return;
    struct rlimit rl;
    if (getrlimit(RLIMIT_DATA, &rl) != 0)
        return;
    rlim_t want = (rlim_t)b->bytes;
    if (rl.rlim_max != RLIM_INFINITY && want > rl.rlim_max)
        want = rl.rlim_max;
    if (rl.rlim_cur != RLIM_INFINITY && rl.rlim_cur < want) /* someone set a lower limit: keep it */
        want = rl.rlim_cur;
    rl.rlim_cur = want;
    if (setrlimit(RLIMIT_DATA, &rl) == 0) {
        b->bytes = (unsigned long long)want;
        b->enforced = true;
    }
}

/* Prints an error; out-of-memory errors also say which budget ran out and
 * how to raise it. */
static void report(const rt_error *err, const memory_budget *budget)
{
    fprintf(stderr, "rt: %s\n", err->message);
    if (err->code != RT_ERR_NOMEM)
        return;
    if (budget->enforced) {
        char sz[32];
        format_size(budget->bytes, sz, sizeof sz);
        fprintf(stderr,
                "rt: the memory budget of %s (%s) ran out; raise it with --max-memory SIZE (e.g. --max-memory 16G, or "
                "'none' for no limit)\n",
                sz, budget->from_flag ? "--max-memory" : "the default, 75% of physical memory");
    } else {
        fprintf(stderr, "rt: the machine's memory ran out (no --max-memory budget was in force)\n");
    }
}

static void usage(FILE *f)
{
    char default_budget_text[32], integrators[256];
    format_size(default_memory_budget(), default_budget_text, sizeof default_budget_text);
    rt_integrator_list(integrators, sizeof integrators, ", ", " or ");
    fprintf(f,
            "usage: rt [options] [SCENE.txt | MODEL.gltf | MODEL.glb | MESH.obj | MESH.ply | MESH.off]\n"
            "\n"
            "Renders a scene to an image. With no input, renders the built-in Cornell box to out.png.\n"
            "\n"
            "options:\n"
            "  -o FILE            output image: .png (8-bit sRGB), .pfm (linear float), .hdr (Radiance)\n"
            "                     default: the scene's `output`, else INPUT-NAME.png in this directory\n"
            "  -t N               render threads (default: all %d cores)\n"
            "  -s N               samples per pixel (overrides the scene)\n"
            "  -r WxH             resolution, e.g. -r 1280x720 (overrides the scene)\n"
            "  -q                 quiet: no progress bar, no warnings\n"
            "  -v                 verbose: scene statistics, kd-tree build, render time, rays per second\n"
            "  --integrator NAME  %s (overrides the scene)\n"
            "  --camera N         use camera N of the loaded glTF models\n"
            "  --seed N           random seed (default: the scene's, else 0)\n"
            "  --tile N           tile size in pixels (default 32)\n"
            "  --preview SECONDS  live view: rewrite the output with the finished tiles every SECONDS\n"
            "  --info FILE        print what a scene or model contains (key: value lines) and exit\n"
            "  --max-memory SIZE  memory budget, e.g. 4G or 512M; 'none' for no limit\n"
            "                     (default: 75%% of physical memory, here %s)\n"
            "  -h, --help         this text\n"
            "  --version          print the version\n"
            "\n"
            "Scene format: docs/scene-format.md; limits and exit codes: docs/robustness.md.\n"
            "Exit status: 0 ok, 2 bad input (or over a limit), 130 interrupted.\n",
            rt_cpu_count(), integrators, default_budget_text);
}

static int fail_usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "rt: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\nrt: see 'rt --help'\n");
    return 2;
}

/* Strict integer parsing for flags: the whole string, in range. */
static bool parse_int(const char *s, long lo, long hi, long *out)
{
    if (!s || !*s)
        return false;
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

static bool parse_double(const char *s, double lo, double hi, double *out)
{
    if (!s || !*s)
        return false;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || *end || !(v >= lo && v <= hi))
        return false;
    *out = v;
    return true;
}

static bool has_ext(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) && strcasecmp(dot, ext) == 0;
}

typedef enum input_kind { INPUT_SCENE, INPUT_GLTF, INPUT_MESH } input_kind;

static input_kind input_kind_of(const char *path)
{
    if (has_ext(path, ".gltf") || has_ext(path, ".glb"))
        return INPUT_GLTF;
    if (has_ext(path, ".obj") || has_ext(path, ".ply") || has_ext(path, ".off"))
        return INPUT_MESH;
    return INPUT_SCENE;
}

/* Lighting and sampling for a bare model: a soft sky, a key light from
 * above when the model brings no lights, and enough samples for clean edges. */
static bool add_default_lighting(rt_scene *s)
{
    s->settings.samples = 16;
    s->settings.background = rt_v3(0.55f, 0.6f, 0.7f);
    if (s->light_count == 0) {
        rt_light sun;
        memset(&sun, 0, sizeof sun);
        sun.kind = RT_LIGHT_DIRECTIONAL;
        sun.color = rt_v3(1.0f, 0.96f, 0.9f);
        sun.intensity = 2.5f;
        sun.direction = rt_normalize(rt_v3(-0.4f, -1.0f, -0.6f));
        sun.quad = RT_NONE;
        if (rt_scene_add_light(s, &sun) == RT_NONE)
            return false;
    }
    return true;
}

/* What loading one input found, for --info. */
typedef struct input_info {
    input_kind kind;
    double load_ms;
    size_t meshes, primitives, nodes; /* glTF only */
} input_info;

/* Loads the input (NULL = the built-in scene). for_render adds what a bare
 * model needs to be rendered (lights, samples, its first camera) and the
 * tangents normal maps need; --info leaves the model as it is. */
static rt_result load_input(rt_scene *s, const char *path, bool for_render, input_info *info, rt_error *err)
{
    double t0 = now_ms();
    rt_result r;
    memset(info, 0, sizeof *info);
    info->kind = path ? input_kind_of(path) : INPUT_SCENE;
    if (!path) {
        r = rt_scene_parse_string(s, rt_default_scene_text, strlen(rt_default_scene_text), "<built-in scene>", NULL,
                                  err);
    } else if (info->kind == INPUT_GLTF) {
        rt_gltf_options opt;
        memset(&opt, 0, sizeof opt);
        rt_gltf_stats gs;
        memset(&gs, 0, sizeof gs);
        r = rt_gltf_load(s, path, &opt, &gs, err);
        info->meshes = gs.meshes;
        info->primitives = gs.primitives;
        info->nodes = gs.nodes;
        if (r == RT_OK && for_render) {
            if (!add_default_lighting(s))
                r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory adding the default light", path);
            if (s->camera_count) {
                s->camera = s->cameras[0];
                s->camera_set = true;
            }
        }
    } else if (info->kind == INPUT_MESH) {
        rt_material m;
        rt_material_default(&m, "default");
        uint32_t mi = rt_scene_add_material(s, &m);
        rt_mat4 id = rt_mat4_identity();
        rt_mesh_load_stats ms;
        r = mi == RT_NONE ? rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path)
                          : rt_mesh_load(s, path, &id, mi, false, &ms, err);
        info->meshes = info->primitives = r == RT_OK ? 1 : 0;
        if (r == RT_OK && for_render && !add_default_lighting(s))
            r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory adding the default light", path);
    } else {
        r = rt_scene_parse_file(s, path, err);
    }
    if (r == RT_OK && for_render) /* normal-mapped meshes without tangents get per-vertex ones */
        r = rt_scene_generate_tangents(s, err);
    info->load_ms = now_ms() - t0;
    return r;
}

/* Output name: -o, else the scene's `output`, else the input's base name
 * with .png, in the current directory. */
static void default_output(const rt_scene *s, const char *input, char *out, size_t size)
{
    if (s->settings.output[0]) {
        snprintf(out, size, "%s", s->settings.output);
        return;
    }
    if (!input) {
        snprintf(out, size, "out.png");
        return;
    }
    const char *base = strrchr(input, '/');
    base = base ? base + 1 : input;
    const char *dot = strrchr(base, '.');
    int len = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, size, "%.*s.png", len, base);
}

/* Caps on what a loaded scene may ask for, checked before any large
 * allocation of the render: the primitive count the kd-tree can index, a
 * diffuse-gather tree that would never finish, a usable camera. The image
 * size and sample count are capped where they are read (flags, parser). */
static rt_result check_limits(rt_scene *s, const char *input, bool camera_from_input, rt_error *err)
{
    const char *name = input ? input : "<built-in scene>";
    size_t prims = rt_scene_prim_count(s);
    if (prims > MAX_PRIMITIVES)
        return rt_fail(err, RT_ERR_LIMIT, "%s: %zu primitives (triangles %zu, spheres %zu, quads %zu), over the limit of %zu",
                       name, prims, s->triangles.count, s->spheres.count, s->quads.count, MAX_PRIMITIVES);
    const rt_settings *set = &s->settings;
    if (set->width < 1 || set->height < 1 || set->width > 32768 || set->height > 32768)
        return rt_fail(err, RT_ERR_LIMIT, "%s: image size %dx%d is out of range (1..32768 a side)", name, set->width,
                       set->height);
    if (set->samples > (1 << 20))
        return rt_fail(err, RT_ERR_LIMIT, "%s: %d samples per pixel, over the limit of 1048576", name, set->samples);
    if (set->integrator == RT_INTEGRATOR_WHITTED && set->diffuse_bounces > 0 && set->diffuse_rays > 1) {
        double rays = 1.0;
        for (int i = 0; i < set->diffuse_bounces && rays <= MAX_DIFFUSE_TREE; i++)
            rays *= (double)set->diffuse_rays;
        if (rays > MAX_DIFFUSE_TREE)
            return rt_fail(err, RT_ERR_LIMIT,
                           "%s: diffuse_rays %d with diffuse_bounces %d would trace over %.0f rays per camera sample "
                           "(diffuse_rays ^ diffuse_bounces); lower one of them",
                           name, set->diffuse_rays, set->diffuse_bounces, MAX_DIFFUSE_TREE);
    }
    rt_camera_frame cf;
    if (!rt_camera_frame_init(&cf, &s->camera, set->width, set->height)) {
        if (camera_from_input)
            return rt_fail(err, RT_ERR_INVALID,
                           "%s: the camera is degenerate (position equal to look_at, up parallel to the view, a field of "
                           "view outside 0..180 degrees, or a value that is not finite)",
                           name);
        rt_warn("%s: could not frame the model automatically (its bounds are empty or not finite); looking down -z",
                name);
    }
    return RT_OK;
}

/* --info: one `key: value` line per figure, for people and scripts. */
static int print_info(const char *path, const memory_budget *budget)
{
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    input_info info;
    rt_result r = load_input(&s, path, false, &info, &err);
    if (r != RT_OK) {
        report(&err, budget);
        rt_scene_free(&s);
        return 2;
    }
    rt_box b = rt_scene_bounds(&s);
    printf("file: %s\n", path);
    printf("format: %s\n", info.kind == INPUT_GLTF ? "gltf" : info.kind == INPUT_MESH ? "mesh" : "scene");
    printf("triangles: %zu\n", s.triangles.count);
    printf("vertices: %zu\n", s.vertices.count);
    printf("spheres: %zu\n", s.spheres.count);
    printf("quads: %zu\n", s.quads.count);
    if (rt_box_is_empty(b))
        printf("bounds: none\n");
    else
        printf("bounds: %.9g %.9g %.9g %.9g %.9g %.9g\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    if (info.kind != INPUT_SCENE) {
        printf("meshes: %zu\n", info.meshes);
        printf("primitives: %zu\n", info.primitives);
    }
    if (info.kind == INPUT_GLTF)
        printf("nodes: %zu\n", info.nodes);
    printf("materials: %zu\n", s.material_count);
    printf("textures: %zu\n", s.texture_count);
    printf("images: %zu\n", s.image_count);
    for (size_t i = 0; i < s.image_count; i++)
        printf("image.%zu: %dx%d %s\n", i, s.images[i].width, s.images[i].height, s.images[i].name);
    printf("cameras: %zu\n", s.camera_count);
    printf("lights: %zu\n", s.light_count);
    printf("load_ms: %.3f\n", info.load_ms);
    rt_scene_free(&s);
    return 0;
}

int main(int argc, char **argv)
{
    const char *input = NULL, *output = NULL, *integrator = NULL, *preview = NULL, *info_path = NULL;
    memory_budget budget = {default_memory_budget(), false, false};
    long threads = 0, samples = 0, width = 0, height = 0, camera = -1, seed = -1, tile = 0;
    double preview_seconds = 0.0;
    rt_log_level level = RT_LOG_NORMAL;

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *next = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED_ARG()                                                                                                     \
    do {                                                                                                               \
        if (!next)                                                                                                     \
            return fail_usage("option %s needs a value", a);                                                         \
        i++;                                                                                                           \
    } while (0)
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--version") == 0) {
            printf("rt %s\n", RT_VERSION);
            return 0;
        } else if (strcmp(a, "-o") == 0) {
            NEED_ARG();
            output = next;
        } else if (strcmp(a, "-t") == 0) {
            NEED_ARG();
            if (!parse_int(next, 1, 1024, &threads))
                return fail_usage("-t wants a thread count from 1 to 1024, got '%s'", next);
        } else if (strcmp(a, "-s") == 0) {
            NEED_ARG();
            if (!parse_int(next, 1, 1 << 20, &samples))
                return fail_usage("-s wants samples per pixel from 1 to 1048576, got '%s'", next);
        } else if (strcmp(a, "-r") == 0) {
            NEED_ARG();
            char *x = strchr(next, 'x');
            char wbuf[32];
            if (!x || (size_t)(x - next) >= sizeof wbuf)
                return fail_usage("-r wants WIDTHxHEIGHT, e.g. 640x480, got '%s'", next);
            memcpy(wbuf, next, (size_t)(x - next));
            wbuf[x - next] = 0;
            if (!parse_int(wbuf, 1, 32768, &width) || !parse_int(x + 1, 1, 32768, &height))
                return fail_usage("-r wants WIDTHxHEIGHT with sides from 1 to 32768, got '%s'", next);
        } else if (strcmp(a, "-q") == 0) {
            level = RT_LOG_QUIET;
        } else if (strcmp(a, "-v") == 0) {
            level = RT_LOG_VERBOSE;
        } else if (strcmp(a, "--integrator") == 0) {
            NEED_ARG();
            rt_integrator id;
            if (!rt_integrator_by_name(next, &id)) {
                char names[256], msg[512];
                rt_integrator_list(names, sizeof names, ", ", " or ");
                snprintf(msg, sizeof msg, "--integrator wants %s, got '%s'", names, next);
                return fail_usage("%s", msg);
            }
            integrator = next;
        } else if (strcmp(a, "--camera") == 0) {
            NEED_ARG();
            if (!parse_int(next, 0, INT_MAX, &camera))
                return fail_usage("--camera wants a camera index (0, 1, ...), got '%s'", next);
        } else if (strcmp(a, "--seed") == 0) {
            NEED_ARG();
            if (!parse_int(next, 0, UINT32_MAX > LONG_MAX ? LONG_MAX : (long)UINT32_MAX, &seed))
                return fail_usage("--seed wants a non-negative integer, got '%s'", next);
        } else if (strcmp(a, "--tile") == 0) {
            NEED_ARG();
            if (!parse_int(next, 1, 4096, &tile))
                return fail_usage("--tile wants a tile size from 1 to 4096, got '%s'", next);
        } else if (strcmp(a, "--preview") == 0) {
            NEED_ARG();
            if (!parse_double(next, 0.1, 3600.0, &preview_seconds))
                return fail_usage("--preview wants seconds between updates (0.1 to 3600), got '%s'", next);
            preview = "";
        } else if (strcmp(a, "--info") == 0) {
            NEED_ARG();
            info_path = next;
        } else if (strcmp(a, "--max-memory") == 0) {
            NEED_ARG();
            if (!parse_size(next, &budget.bytes))
                return fail_usage("--max-memory wants a size such as 4G, 512M or 'none', got '%s'", next);
            if (budget.bytes && budget.bytes < (64ull << 20))
                return fail_usage("--max-memory: '%s' is below the 64M rt needs to start", next);
            budget.from_flag = true;
        } else if (a[0] == '-' && a[1] != 0) {
            return fail_usage("unknown option '%s'", a);
        } else {
            if (input)
                return fail_usage("only one input file, please (got a second: '%s')", a);
            input = a;
        }
#undef NEED_ARG
    }
    rt_log_set_level(level);
    apply_memory_budget(&budget);
    if (budget.enforced) {
        char sz[32];
        format_size(budget.bytes, sz, sizeof sz);
        rt_info("memory budget: %s%s", sz, budget.from_flag ? " (--max-memory)" : " (75% of physical memory)");
    } else {
        rt_info("memory budget: none%s", RT_SANITIZED && budget.bytes ? " (not enforced in sanitizer builds)" : "");
    }
    if (info_path)
        return print_info(info_path, &budget);

    rt_scene scene;
    rt_scene_init(&scene);
    rt_error err = {0};
    input_info info;
    if (load_input(&scene, input, true, &info, &err) != RT_OK) {
        report(&err, &budget);
        rt_scene_free(&scene);
        return 2;
    }
    if (rt_scene_validate(&scene, &err) != RT_OK) { /* from here on the tables are trusted */
        rt_error named;
        rt_fail(&named, err.code, "%s: %s", input ? input : "<built-in scene>", err.message);
        report(&named, &budget);
        rt_scene_free(&scene);
        return 2;
    }
    rt_settings *set = &scene.settings;
    if (samples) set->samples = (int)samples;
    if (width) set->width = (int)width, set->height = (int)height;
    if (seed >= 0) set->seed = (uint32_t)seed;
    if (integrator)
        rt_integrator_by_name(integrator, &set->integrator);
    if (camera >= 0) {
        if ((size_t)camera >= scene.camera_count) {
            fprintf(stderr, "rt: --camera %ld: the loaded models have %zu camera%s\n", camera, scene.camera_count,
                    scene.camera_count == 1 ? "" : "s");
            rt_scene_free(&scene);
            return 2;
        }
        scene.camera = scene.cameras[camera];
        scene.camera_set = true;
    }
    /* a glTF camera made for another aspect ratio: keep the height, fit the width */
    if (!width && input && info.kind == INPUT_GLTF && scene.camera.aspect_ratio > 0.0f) {
        double w = (double)set->height * scene.camera.aspect_ratio + 0.5;
        set->width = w < 1.0 ? 1 : (w > 32768.0 ? 32768 : (int)w);
    }
    bool camera_from_input = scene.camera_set;
    if (!scene.camera_set)
        rt_scene_frame_camera(&scene);
    if (check_limits(&scene, input, camera_from_input, &err) != RT_OK) {
        report(&err, &budget);
        rt_scene_free(&scene);
        return 2;
    }

    char outbuf[1024];
    if (!output) {
        default_output(&scene, input, outbuf, sizeof outbuf);
        output = outbuf;
    }
    if (rt_output_check(output, &err) != RT_OK || rt_output_check_size(output, set->width, set->height, &err) != RT_OK) {
        report(&err, &budget);
        rt_scene_free(&scene);
        return 2;
    }

    rt_info("scene: %s (loaded in %.1f ms)", input ? input : "<built-in>", info.load_ms);
    rt_info("  triangles %zu, spheres %zu, quads %zu, vertices %zu", scene.triangles.count, scene.spheres.count,
            scene.quads.count, scene.vertices.count);
    rt_info("  materials %zu, textures %zu, images %zu, lights %zu", scene.material_count, scene.texture_count,
            scene.image_count, scene.light_count);
    rt_info("  %dx%d, %d samples per pixel, integrator %s", set->width, set->height, set->samples,
            rt_integrator_name(set->integrator));

    rt_kdtree tree;
    if (rt_kdtree_build(&tree, &scene, NULL, &err) != RT_OK) {
        report(&err, &budget);
        rt_scene_free(&scene);
        return 2;
    }
    rt_info("kd-tree: built in %.1f ms: %zu nodes, %zu leaves (%zu empty), %zu references, depth %d; "
            "%zu 64-byte nodes of 3 levels, %.1f MiB",
            tree.stats.build_ms, tree.stats.nodes, tree.stats.leaves, tree.stats.empty_leaves, tree.stats.prim_refs,
            tree.stats.depth, tree.stats.wide_nodes, (double)tree.stats.bytes / (1024.0 * 1024.0));

    rt_framebuffer fb;
    if (rt_framebuffer_init(&fb, set->width, set->height, &err) != RT_OK) {
        report(&err, &budget);
        rt_kdtree_free(&tree);
        rt_scene_free(&scene);
        return 2;
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    progress_view view;
    progress_view_init(&view, level >= RT_LOG_NORMAL && isatty(2), preview ? output : NULL, preview_seconds,
                       set->exposure);
    rt_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.threads = (int)threads;
    ro.tile_size = (int)tile;
    ro.cancel = &interrupted;
    ro.progress = view.bar || view.preview_path ? progress_report : NULL;
    ro.progress_user = &view;
    rt_render_stats rs;
    rt_result r = rt_render(&scene, &tree, &ro, &fb, &rs, &err);
    int status = 0;
    if (r == RT_ERR_INTERRUPTED) {
        fprintf(stderr, "rt: %s; writing the finished tiles to %s\n", err.message, output);
        status = 130;
    } else if (r != RT_OK) {
        report(&err, &budget);
        status = 2;
    }
    if (status != 2) {
        if (rt_framebuffer_write(&fb, output, set->exposure, &err) != RT_OK) {
            report(&err, &budget);
            status = 2;
        } else if (level >= RT_LOG_NORMAL) {
            fprintf(stderr, "rt: wrote %s (%dx%d, %d spp, %.2f s)\n", output, fb.width, fb.height, set->samples,
                    rs.seconds);
        }
    }
    rt_info("render: %.3f s on %d threads, %llu camera rays, %llu rays, %.2f Mrays/s", rs.seconds, rs.threads,
            (unsigned long long)rs.camera_rays, (unsigned long long)rs.rays,
            rs.seconds > 0 ? 1e-6 * (double)rs.rays / rs.seconds : 0.0);
    if (rs.bad_samples)
        rt_warn("%llu NaN/Inf samples were dropped", (unsigned long long)rs.bad_samples);
    rt_framebuffer_free(&fb);
    rt_kdtree_free(&tree);
    rt_scene_free(&scene);
    return status;
}
