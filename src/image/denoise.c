/* denoise.c - Intel Open Image Denoise through dlopen (rt/image/denoise.h).
 *
 * The few C API entry points rt calls are declared here from OIDN's
 * documented API (Open Image Denoise API, doc/api.md of OIDN 2.x): devices
 * (oidnNewDevice, oidnCommitDevice, oidnGetDeviceError, oidnReleaseDevice)
 * and filters (oidnNewFilter "RT", oidnSetSharedFilterImage with
 * OIDN_FORMAT_FLOAT3 = 3, oidnSetFilterBool "hdr" / "cleanAux",
 * oidnCommitFilter, oidnExecuteFilter, oidnReleaseFilter). Handles are
 * opaque pointers; OIDN_DEVICE_TYPE_CPU is 1. The "prefiltered" recipe (the
 * albedo and normal images denoised first by their own RT filters, then the
 * beauty with cleanAux) is the one OIDN's documentation gives for final
 * frames.
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
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt/base/alloc.h"

#define OIDN_SONAME "libOpenImageDenoise.so.2"
#define OIDN_WHEEL_LIB "site-packages/pyoidn/oidn/lib/" OIDN_SONAME
#define OIDN_DEVICE_TYPE_CPU 1
#define OIDN_FORMAT_FLOAT3 3

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
    char pattern[4400];
    /* build/oidn-venv beside the binary, or up to two folders above it */
    char exe[4096];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (!lib && n > 0) {
        exe[n] = 0;
        char *slash = strrchr(exe, '/');
        if (slash)
            *slash = 0;
        static const char *const ups[] = {"", "/..", "/../.."};
        for (int i = 0; i < 3 && !lib; i++) {
            snprintf(pattern, sizeof pattern, "%s%s/build/oidn-venv/lib/python3*/" OIDN_WHEEL_LIB, exe, ups[i]);
            lib = try_glob(pattern, where, size);
        }
    }
    if (!lib) {
        snprintf(pattern, sizeof pattern, "build/oidn-venv/lib/python3*/" OIDN_WHEEL_LIB);
        lib = try_glob(pattern, where, size);
    }
    const char *venv = getenv("VIRTUAL_ENV"), *home = getenv("HOME");
    if (!lib && venv && venv[0]) {
        snprintf(pattern, sizeof pattern, "%s/lib/python3*/" OIDN_WHEEL_LIB, venv);
        lib = try_glob(pattern, where, size);
    }
    if (!lib && home && home[0]) {
        snprintf(pattern, sizeof pattern, "%s/.local/lib/python3*/" OIDN_WHEEL_LIB, home);
        lib = try_glob(pattern, where, size);
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
              BIND(lib, api, commit_filter, "oidnCommitFilter") && BIND(lib, api, execute_filter, "oidnExecuteFilter") &&
              BIND(lib, api, release_filter, "oidnReleaseFilter");
    if (!ok)
        return rt_fail(err, RT_ERR_IO, "--denoise: the Open Image Denoise library lacks the OIDN 2 C API (%s)",
                       dlerror());
    return RT_OK;
}

rt_result rt_denoise_find(char *where, size_t size, rt_error *err)
{
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

/* One RT filter over `color` in place, with optional clean aux images. */
static rt_result run_filter(const oidn_api *api, void *device, float *color, const float *albedo, const float *normal,
                            bool hdr, int w, int h, rt_error *err)
{
    void *f = api->new_filter(device, "RT");
    rt_result r = device_error(api, device, "creating the RT filter", err);
    if (r != RT_OK || !f)
        return r != RT_OK ? r : rt_fail(err, RT_ERR_IO, "denoise: no RT filter");
    api->set_shared_filter_image(f, "color", color, OIDN_FORMAT_FLOAT3, (size_t)w, (size_t)h, 0, 0, 0);
    if (albedo)
        api->set_shared_filter_image(f, "albedo", (void *)albedo, OIDN_FORMAT_FLOAT3, (size_t)w, (size_t)h, 0, 0, 0);
    if (albedo && normal)
        api->set_shared_filter_image(f, "normal", (void *)normal, OIDN_FORMAT_FLOAT3, (size_t)w, (size_t)h, 0, 0, 0);
    api->set_shared_filter_image(f, "output", color, OIDN_FORMAT_FLOAT3, (size_t)w, (size_t)h, 0, 0, 0);
    api->set_filter_bool(f, "hdr", hdr);
    if (albedo)
        api->set_filter_bool(f, "cleanAux", true);
    api->commit_filter(f);
    r = device_error(api, device, "setting up the filter", err);
    if (r == RT_OK) {
        api->execute_filter(f);
        r = device_error(api, device, "filtering", err);
    }
    api->release_filter(f);
    return r;
}

rt_result rt_denoise_image(const rt_denoise_input *in, rt_error *err)
{
    oidn_api api;
    rt_result r = load(&api, NULL, 0, err);
    if (r != RT_OK)
        return r;
    const int w = in->width, h = in->height;
    const size_t n = (size_t)w * (size_t)h * 3;
    float *aux = NULL;
    if (in->albedo) { /* the prefiltered aux images: copies, denoised by their own filters */
        aux = rt_alloc(n, 2 * sizeof(float));
        if (!aux)
            return rt_fail(err, RT_ERR_NOMEM, "denoise: out of memory for the auxiliary images");
        memcpy(aux, in->albedo, n * sizeof(float));
        if (in->normal)
            memcpy(aux + n, in->normal, n * sizeof(float));
    }
    void *device = api.new_device(OIDN_DEVICE_TYPE_CPU);
    if (!device) {
        free(aux);
        return rt_fail(err, RT_ERR_IO, "denoise: Open Image Denoise has no CPU device");
    }
    api.commit_device(device);
    r = device_error(&api, device, "starting the CPU device", err);
    if (r == RT_OK && aux)
        r = run_filter(&api, device, aux, NULL, NULL, false, w, h, err);
    if (r == RT_OK && aux && in->normal)
        r = run_filter(&api, device, aux + n, NULL, NULL, false, w, h, err);
    if (r == RT_OK)
        r = run_filter(&api, device, in->color, aux, aux && in->normal ? aux + n : NULL, true, w, h, err);
    api.release_device(device);
    free(aux);
    return r;
}
