/* denoise.c - Intel Open Image Denoise through dlopen (rt/image/denoise.h).
 *
 * The few C API entry points rt calls are declared here from OIDN's
 * documented API (Open Image Denoise API, doc/api.md of OIDN 2.x): devices
 * (oidnNewDevice, oidnSetDeviceInt / oidnGetDeviceInt "numThreads" (the
 * CPU device's worker threads), oidnCommitDevice, oidnGetDeviceError,
 * oidnReleaseDevice) and filters (oidnNewFilter "RT",
 * oidnSetSharedFilterImage with OIDN_FORMAT_FLOAT3 = 3, oidnSetFilterBool
 * "hdr" / "cleanAux", oidnSetFilterInt "quality" with OIDN_QUALITY_FAST = 4,
 * BALANCED = 5, HIGH = 6, oidnCommitFilter, oidnExecuteFilter,
 * oidnReleaseFilter). Handles are opaque pointers; OIDN_DEVICE_TYPE_CPU is 1.
 *
 * One RT filter, with rt's albedo and normal passed as clean auxiliary
 * images (cleanAux). OIDN's documentation recommends prefiltering noisy
 * auxiliary images (each denoised by its own RT filter first); rt's are not
 * noisy with a pinhole camera: no motion blur, the first non-specular hit
 * seen through perfect mirrors and glass, so what varies between a pixel's
 * samples is only which surface its edge samples land on. Measured on the
 * shared Cornell box at 16 spp (docs/hdr.md), prefiltering changed the
 * denoised image's relMSE and FLIP by under 1% and took two thirds of the
 * time (two more filters, OIDN 2.3+'s larger prefilter networks in high
 * quality). A camera with an aperture (depth of field) does make them noisy
 * where out of focus, and an open shutter (motion blur) where things move:
 * rt_denoise_input.prefilter_aux then runs OIDN's recipe, the albedo and
 * normal each through an RT filter of its own (as its `albedo` and `normal`
 * inputs) before the beauty. The default quality
 * is OIDN's "balanced" (its pre-2.3 network): 2.4x less CPU time than
 * "high" on that image for a relMSE 1.35x higher, both ~60x below the
 * noisy image's.
 *
 * Sanitizer builds refuse --denoise with a clear message: OIDN's TBB
 * dlopens a helper with RTLD_DEEPBIND, which ASan and TSan abort on.
 *
 * The library is looked up each time (dlopen counts its references, so a
 * second load is cheap) and never unloaded: OIDN's thread pool (TBB) may
 * still hold threads when the last filter is released.
 */
#include "rt/image/denoise.h"

#include <dlfcn.h>
#include <glob.h>
#include <pwd.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rt/base/clock.h"
#include "rt/base/cpu.h"
#include "rt/base/log.h"

#define OIDN_SONAME "libOpenImageDenoise.so.2"
#define OIDN_WHEEL_LIB "site-packages/pyoidn/oidn/lib/" OIDN_SONAME
#define OIDN_DEVICE_TYPE_CPU 1
#define OIDN_FORMAT_FLOAT3 3
#define OIDN_QUALITY_FAST 4
#define OIDN_QUALITY_BALANCED 5
#define OIDN_QUALITY_HIGH 6

/* The entry points, as OIDN's C API declares them (handles as void *). */
typedef struct oidn_api {
    void *(*new_device)(int type);
    void (*commit_device)(void *device);
    int (*get_device_error)(void *device, const char **message);
    void (*release_device)(void *device);
    void *(*new_filter)(void *device, const char *type);
    void (*set_shared_filter_image)(void *filter, const char *name, void *ptr, int format, size_t width, size_t height,
                                    size_t byte_offset, size_t pixel_byte_stride, size_t row_byte_stride);
    void (*set_filter_bool)(void *filter, const char *name, bool value);
    void (*set_filter_int)(void *filter, const char *name, int value);
    void (*set_device_int)(void *device, const char *name, int value);
    int (*get_device_int)(void *device, const char *name);
    void (*commit_filter)(void *filter);
    void (*execute_filter)(void *filter);
    void (*release_filter)(void *filter);
} oidn_api;

/* dlsym's object pointer into a function pointer, the way POSIX allows. */
static bool bind(void *lib, const char *name, void *fn_slot, size_t fn_size)
{
    void *p = dlsym(lib, name);
    if (!p || fn_size != sizeof p)
        return false;
    memcpy(fn_slot, &p, sizeof p);
    return true;
}
#define BIND(lib, api, field, name) bind(lib, name, &(api)->field, sizeof (api)->field)

static void *try_open(const char *path, char *where, size_t size)
{
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (lib && where)
        snprintf(where, size, "%s", path);
    return lib;
}

/* The first match of a glob pattern that loads. */
static void *try_glob(const char *pattern, char *where, size_t size)
{
    glob_t g;
    void *lib = NULL;
    if (glob(pattern, 0, NULL, &g) == 0)
        for (size_t i = 0; i < g.gl_pathc && !lib; i++)
            lib = try_open(g.gl_pathv[i], where, size);
    globfree(&g);
    return lib;
}

/* GCC's and clang's markers of a sanitizer build */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SANITIZED 1
#endif
#endif

/* Appends one pattern line to out (dropped when it does not fit). */
static void add_pattern(char *out, size_t size, const char *prefix, const char *middle, const char *wheel_at)
{
    size_t used = strlen(out);
    int n = snprintf(out + used, size - used, "%s%s%s/" OIDN_WHEEL_LIB "\n", prefix, middle, wheel_at);
    if (n < 0 || (size_t)n >= size - used)
        out[used] = 0;
}

void rt_denoise_wheel_patterns(char *out, size_t size)
{
    if (!size)
        return;
    out[0] = 0;
    static const char *const venv_lib = "/lib/python3*";
    /* build/oidn-venv beside the binary, or up to two folders above it */
    char exe[4096];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = 0;
        char *slash = strrchr(exe, '/');
        if (slash)
            *slash = 0;
        static const char *const ups[] = {"/build/oidn-venv", "/../build/oidn-venv", "/../../build/oidn-venv"};
        for (int i = 0; i < 3; i++)
            add_pattern(out, size, exe, ups[i], venv_lib);
    }
    add_pattern(out, size, "", "build/oidn-venv", venv_lib); /* under the current directory */
    const char *venv = getenv("VIRTUAL_ENV");
    if (venv && venv[0])
        add_pattern(out, size, venv, "", venv_lib);
    /* the user site, as Python finds it: PYTHONUSERBASE, else ~/.local (HOME, else the password entry) */
    const char *base = getenv("PYTHONUSERBASE");
    if (base && base[0]) {
        add_pattern(out, size, base, "", venv_lib);
        return;
    }
    const char *home = getenv("HOME");
    if (!home || !home[0]) {
        const struct passwd *pw = getpwuid(getuid());
        home = pw ? pw->pw_dir : NULL;
    }
    if (home && home[0])
        add_pattern(out, size, home, "/.local", venv_lib);
}

static void *open_library(char *where, size_t size, rt_error *err)
{
    const char *env = getenv("RT_OIDN_LIBRARY");
    if (env && env[0] && access(env, F_OK) != 0) {
        rt_fail(err, RT_ERR_IO, "--denoise: RT_OIDN_LIBRARY=%s: no such file (" RT_DENOISE_INSTALL_HINT ")", env);
        return NULL;
    }
#ifdef SANITIZED
    /* OIDN's thread pool (TBB) loads a helper with RTLD_DEEPBIND, which the
     * sanitizer runtimes abort on: say so instead */
    (void)where;
    (void)size;
    rt_fail(err, RT_ERR_IO, "--denoise is not available in a sanitizer build (Open Image Denoise's TBB loads "
            "libraries with RTLD_DEEPBIND); use the plain build");
    return NULL;
#endif

    if (env && env[0]) {
        void *lib = try_open(env, where, size);
        if (!lib)
            rt_fail(err, RT_ERR_IO, "--denoise: RT_OIDN_LIBRARY=%s does not load (%s)", env, dlerror());
        return lib;
    }
    void *lib = try_open(OIDN_SONAME, where, size);
    char patterns[8 * 4400];
    rt_denoise_wheel_patterns(patterns, sizeof patterns);
    for (char *line = patterns, *next; !lib && *line; line = next) {
        next = strchr(line, '\n');
        *next++ = 0;
        lib = try_glob(line, where, size);
    }
    if (!lib)
        rt_fail(err, RT_ERR_IO, "--denoise needs Intel Open Image Denoise (" OIDN_SONAME "), not found: "
                RT_DENOISE_INSTALL_HINT);
    return lib;
}

static rt_result load(oidn_api *api, char *where, size_t size, rt_error *err)
{
    void *lib = open_library(where, size, err);
    if (!lib)
        return RT_ERR_IO;
    bool ok = BIND(lib, api, new_device, "oidnNewDevice") && BIND(lib, api, commit_device, "oidnCommitDevice") &&
              BIND(lib, api, get_device_error, "oidnGetDeviceError") &&
              BIND(lib, api, release_device, "oidnReleaseDevice") && BIND(lib, api, new_filter, "oidnNewFilter") &&
              BIND(lib, api, set_shared_filter_image, "oidnSetSharedFilterImage") &&
              BIND(lib, api, set_filter_bool, "oidnSetFilterBool") &&
              BIND(lib, api, set_filter_int, "oidnSetFilterInt") && BIND(lib, api, set_device_int, "oidnSetDeviceInt") &&
              BIND(lib, api, get_device_int, "oidnGetDeviceInt") && BIND(lib, api, commit_filter, "oidnCommitFilter") &&
              BIND(lib, api, execute_filter, "oidnExecuteFilter") &&
              BIND(lib, api, release_filter, "oidnReleaseFilter");
    if (!ok)
        return rt_fail(err, RT_ERR_IO, "--denoise: the Open Image Denoise library lacks the OIDN 2 C API (%s)",
                       dlerror());
    return RT_OK;
}

static rt_result pick_quality(const rt_denoise_input *in, rt_denoise_quality *q, rt_error *err);

rt_result rt_denoise_find(char *where, size_t size, rt_error *err)
{
    rt_denoise_input none = {0};
    rt_denoise_quality q;
    if (pick_quality(&none, &q, err) != RT_OK) /* a bad RT_OIDN_QUALITY, before rendering */
        return RT_ERR_IO;
    oidn_api api;
    return load(&api, where, size, err);
}

/* The device's pending error, if any, as an rt_error. */
static rt_result device_error(const oidn_api *api, void *device, const char *doing, rt_error *err)
{
    const char *msg = NULL;
    int code = api->get_device_error(device, &msg);
    if (code == 0)
        return RT_OK;
    return rt_fail(err, code == 4 ? RT_ERR_NOMEM : RT_ERR_IO, "denoise: %s: %s (OIDN error %d)", doing,
                   msg ? msg : "no message", code);
}

/* CPU seconds of the process, all threads (OIDN's too): the -v figures
 * beside the wall times, steadier on a busy machine. */
static double cpu_seconds(void)
{
    struct timespec t;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) != 0)
        return 0.0;
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int oidn_quality(rt_denoise_quality q)
{
    switch (q) {
    case RT_DENOISE_FAST: return OIDN_QUALITY_FAST;
    case RT_DENOISE_HIGH: return OIDN_QUALITY_HIGH;
    case RT_DENOISE_BALANCED:
    default: return OIDN_QUALITY_BALANCED;
    }
}

static const char *const quality_names[] = {"balanced", "fast", "balanced", "high"};

bool rt_denoise_quality_parse(const char *name, rt_denoise_quality *out)
{
    for (int k = RT_DENOISE_FAST; k <= RT_DENOISE_HIGH; k++)
        if (name && strcmp(name, quality_names[k]) == 0) {
            *out = (rt_denoise_quality)k;
            return true;
        }
    return false;
}

/* in->quality, else RT_OIDN_QUALITY (fast, balanced, high), else balanced. */
static rt_result pick_quality(const rt_denoise_input *in, rt_denoise_quality *q, rt_error *err)
{
    *q = in->quality >= RT_DENOISE_FAST && in->quality <= RT_DENOISE_HIGH ? in->quality : RT_DENOISE_BALANCED;
    const char *env = getenv("RT_OIDN_QUALITY");
    if (in->quality != RT_DENOISE_DEFAULT || !env || !env[0] || rt_denoise_quality_parse(env, q))
        return RT_OK;
    return rt_fail(err, RT_ERR_IO, "--denoise: RT_OIDN_QUALITY=%s is not " RT_DENOISE_QUALITY_NAMES, env);
}

/* One RT filter, in place on `image` fed as its `input` ("color", or
 * "albedo"/"normal" to prefilter those), with optional clean aux images.
 * *cpu_ms: the CPU time of its execution. */
static rt_result run_filter(const oidn_api *api, void *device, const char *input, float *image, const float *albedo,
                            const float *normal, rt_denoise_quality quality, size_t w, size_t h, double *cpu_ms,
                            rt_error *err)
{
    void *f = api->new_filter(device, "RT");
    rt_result r = device_error(api, device, "creating the RT filter", err);
    if (r == RT_OK && !f)
        r = rt_fail(err, RT_ERR_IO, "denoise: no RT filter");
    if (r != RT_OK)
        return r;
    const bool color = strcmp(input, "color") == 0;
    api->set_shared_filter_image(f, input, image, OIDN_FORMAT_FLOAT3, w, h, 0, 0, 0);
    if (albedo)
        api->set_shared_filter_image(f, "albedo", (void *)albedo, OIDN_FORMAT_FLOAT3, w, h, 0, 0, 0);
    if (albedo && normal)
        api->set_shared_filter_image(f, "normal", (void *)normal, OIDN_FORMAT_FLOAT3, w, h, 0, 0, 0);
    api->set_shared_filter_image(f, "output", image, OIDN_FORMAT_FLOAT3, w, h, 0, 0, 0);
    if (color)
        api->set_filter_bool(f, "hdr", true);
    api->set_filter_bool(f, "cleanAux", albedo != NULL);
    api->set_filter_int(f, "quality", oidn_quality(quality));
    api->commit_filter(f);
    r = device_error(api, device, "setting up the filter", err);
    double c0 = cpu_seconds();
    if (r == RT_OK) {
        api->execute_filter(f);
        r = device_error(api, device, "filtering", err);
    }
    *cpu_ms = 1e3 * (cpu_seconds() - c0);
    api->release_filter(f);
    return r;
}

rt_result rt_denoise_image(const rt_denoise_input *in, rt_error *err)
{
    double t0 = rt_now_seconds();
    rt_denoise_quality quality;
    rt_result r = pick_quality(in, &quality, err);
    if (r != RT_OK)
        return r;
    oidn_api api;
    r = load(&api, NULL, 0, err);
    if (r != RT_OK)
        return r;
    const size_t w = (size_t)in->width, h = (size_t)in->height, n = w * h * 3;
    const float *albedo = in->albedo, *normal = in->albedo ? in->normal : NULL;
    float *aux = NULL; /* prefiltered copies of albedo and normal */
    if (in->prefilter_aux && albedo) {
        aux = malloc((normal ? 2 : 1) * n * sizeof(float));
        if (!aux)
            return rt_fail(err, RT_ERR_NOMEM, "denoise: out of memory for the auxiliary images");
        memcpy(aux, albedo, n * sizeof(float));
        if (normal)
            memcpy(aux + n, normal, n * sizeof(float));
    }
    double t1 = rt_now_seconds();
    void *device = api.new_device(OIDN_DEVICE_TYPE_CPU);
    if (!device) {
        free(aux);
        return rt_fail(err, RT_ERR_IO, "denoise: Open Image Denoise has no CPU device");
    }
    api.set_device_int(device, "numThreads", in->threads > 0 ? in->threads : rt_cpu_count());
    api.commit_device(device);
    r = device_error(&api, device, "starting the CPU device", err);
    const int threads = r == RT_OK ? api.get_device_int(device, "numThreads") : 0; /* as OIDN took it */
    double t2 = rt_now_seconds(), cpu_ms = 0.0;
    if (r == RT_OK && aux) { /* OIDN's recipe for noisy aux: each denoised by its own filter first */
        r = run_filter(&api, device, "albedo", aux, NULL, NULL, quality, w, h, &cpu_ms, err);
        albedo = aux;
        if (r == RT_OK && normal) {
            double more = 0.0;
            r = run_filter(&api, device, "normal", aux + n, NULL, NULL, quality, w, h, &more, err);
            cpu_ms += more;
            normal = aux + n;
        }
        rt_info("denoise: albedo and normal prefiltered: %.1f ms (CPU %.1f ms)", 1e3 * (rt_now_seconds() - t2),
                cpu_ms);
    }
    double t3 = rt_now_seconds();
    if (r == RT_OK)
        r = run_filter(&api, device, "color", in->color, albedo, normal, quality, w, h, &cpu_ms, err);
    double t4 = rt_now_seconds();
    api.release_device(device);
    free(aux);
    rt_info("denoise: OIDN RT filter, %s quality, %d thread%s%s: load %.1f ms, device %.1f ms, filter %.1f ms "
            "(CPU %.1f ms), release %.1f ms", quality_names[quality], threads, threads == 1 ? "" : "s",
            albedo ? (normal ? ", albedo and normal" : ", albedo") : "",
            1e3 * (t1 - t0), 1e3 * (t2 - t1), 1e3 * (t4 - t3), cpu_ms, 1e3 * (rt_now_seconds() - t4));
    return r;
}
