/* rt/image/denoise.h - denoising with Intel Open Image Denoise (OIDN), loaded
 * at run time.
 *
 * OIDN is not a Debian package; `make denoiser` installs the `pyoidn` wheel
 * (which ships libOpenImageDenoise.so.2 and its CPU device) into
 * build/oidn-venv. rt looks for the library, in order: the file named by
 * RT_OIDN_LIBRARY; the system's libOpenImageDenoise.so.2; the wheel under
 * build/oidn-venv beside the rt binary (or one or two folders up, for the
 * test binaries) or the current directory, under $VIRTUAL_ENV, and under
 * the Python user site ($PYTHONUSERBASE or ~/.local, then
 * lib/python3.X/site-packages). Nothing but --denoise needs it.
 *
 *   char where[4096];
 *   if (rt_denoise_find(where, sizeof where, &err) != RT_OK)
 *       ... err.message is one line saying how to install it ...
 *   rt_denoise_input in = {.width = w, .height = h, .color = rgb, .albedo = albedo, .normal = normal};
 *   rt_denoise_quality_parse("high", &in.quality);   // false for a word that is not a quality
 *   in.threads = 4;                                  // OIDN's numThreads; 0: rt_cpu_count()
 *   rt_denoise_image(&in, &err);   // rgb denoised in place
 *
 * With -v it prints one line timing its steps (load, device, filter setup,
 * execute with its CPU time, release).
 */
#ifndef RT_DENOISE_H
#define RT_DENOISE_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"

/* OIDN's quality modes (its "quality" filter parameter). RT_DENOISE_DEFAULT
 * is RT_OIDN_QUALITY from the environment (fast, balanced or high), else
 * balanced: measured in docs/hdr.md against fast and high. Any other value
 * is the caller's choice and wins over RT_OIDN_QUALITY. */
typedef enum rt_denoise_quality {
    RT_DENOISE_DEFAULT = 0, /* = RT_DENOISE_BALANCED */
    RT_DENOISE_FAST,
    RT_DENOISE_BALANCED,
    RT_DENOISE_HIGH
} rt_denoise_quality;

/* What to denoise: linear HDR RGB, 3 floats a pixel, row 0 at the top. */
typedef struct rt_denoise_input {
    int width, height;
    float *color;        /* denoised in place */
    const float *albedo; /* optional (NULL): first non-specular hit's albedo, noise-free but for edges */
    const float *normal; /* optional, with albedo: its shading normal */
    rt_denoise_quality quality;
    int threads;        /* OIDN's worker threads (its numThreads); 0: rt_cpu_count(), the CPUs of the affinity mask */
    bool prefilter_aux; /* albedo and normal are noisy (depth of field, motion blur): denoise them first */
} rt_denoise_input;

/* The words of the qualities, for messages and --help. */
#define RT_DENOISE_QUALITY_NAMES "fast, balanced or high"

/* "fast", "balanced" or "high" into *out; false (and *out untouched) for
 * anything else. */
bool rt_denoise_quality_parse(const char *name, rt_denoise_quality *out);

/* The one-line hint printed when the library is missing. */
#define RT_DENOISE_INSTALL_HINT                                                                                        \
    "run 'make denoiser' in rt's source tree (the pyoidn wheel into build/oidn-venv), or 'pip install "                \
    "pyoidn==2.5.1.0' in a virtual environment or with --user, or set RT_OIDN_LIBRARY to the library"

/* Where the pyoidn wheel's library is looked for after RT_OIDN_LIBRARY and
 * the system's loader, in order, as glob(3) patterns, one a line, into out:
 * build/oidn-venv beside the rt binary (or one or two folders up), under
 * the current directory, under $VIRTUAL_ENV, then the Python user site
 * ($PYTHONUSERBASE, else ~/.local), each as
 * PREFIX/lib/python3.X/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2
 * (any python3.X). */
void rt_denoise_wheel_patterns(char *out, size_t size);

/* Finds and loads the library; `where` receives the path that loaded.
 * RT_ERR_IO with a one-line message when it cannot be found or
 * RT_OIDN_QUALITY is not a quality's name. */
rt_result rt_denoise_find(char *where, size_t size, rt_error *err);

/* Runs OIDN's "RT" filter (hdr on) on in->color in place, on OIDN's CPU
 * device; RT_ERR_IO for a bad RT_OIDN_QUALITY (before any work). Albedo
 * and normal, when given, go in as clean auxiliary images (cleanAux), as
 * rt renders them: not prefiltered (denoise.c says why) unless
 * prefilter_aux asks for it. */
rt_result rt_denoise_image(const rt_denoise_input *in, rt_error *err);

#endif
