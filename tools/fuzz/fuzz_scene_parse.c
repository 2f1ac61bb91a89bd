/* fuzz_scene_parse.c - fuzz target for the scene text parser (src/scene_parse.c).
 *
 * Two ways to build it (from the repository root):
 *
 *   libFuzzer (clang): compile this file with -DRT_LIBFUZZER and
 *   -fsanitize=fuzzer,address,undefined together with every module in src/
 *   except main.c (-std=c11 -Iinclude -D_POSIX_C_SOURCE=200809L, link -lstb
 *   -lm -lpthread), then run it on the shipped scenes with the dictionary:
 *       ./fuzz_scene_parse -dict=tools/fuzz/scene.dict corpus/ scenes/
 *
 *   stand-alone (gcc or clang, with ASan/UBSan): a built-in grammar and
 *   mutation fuzzer, deterministic for a given seed; with file arguments it
 *   replays them instead (crash reproduction). After `make asan` has built
 *   build-asan/librt.a with the sanitizers:
 *       gcc -std=c11 -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=all
 *           -Iinclude -D_POSIX_C_SOURCE=200809L tools/fuzz/fuzz_scene_parse.c
 *           build-asan/librt.a -lstb -lm -lpthread -o fuzz
 *       ./fuzz -n 1000000 -seed 7
 *       ./fuzz crash-1234.txt
 *
 * Every input must either parse or fail with a message that starts with
 * "NAME:LINE:COL: " (LINE, COL >= 1); the scene is always freed, so leaks show
 * up under LeakSanitizer. Relative paths resolve against scenes/, so the
 * dictionary's ../assets/ files exercise the image, mesh and glTF loaders.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/scene_parse.h"

static void check_one(const uint8_t *data, size_t size)
{
    rt_scene s;
    rt_error err;
    memset(&err, 0, sizeof err);
    rt_scene_init(&s);
    rt_result r = rt_scene_parse_string(&s, (const char *)data, size, "fuzz.txt", "scenes", &err);
    if (r != RT_OK) {
        int line = 0, col = 0;
        if (sscanf(err.message, "fuzz.txt:%d:%d: ", &line, &col) != 2 || line < 1 || col < 1) {
            fprintf(stderr, "message without a location: %s\n", err.message);
            abort();
        }
    }
    rt_scene_free(&s);
}

#ifdef RT_LIBFUZZER
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int quiet;
    if (!quiet) {
        rt_log_set_level(RT_LOG_QUIET);
        quiet = 1;
    }
    if (size <= (1u << 20))
        check_one(data, size);
    return 0;
}
#else

static uint64_t rng = 88172645463325252ull;
static uint64_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

/* Keywords first (statement starters), then words that appear in arguments. */
static const char *const words[] = {
    "resolution", "samples", "integrator", "max_bounce", "diffuse_bounces", "diffuse_rays", "shadow_samples",
    "seed", "background", "ambient_light", "exposure", "clamp", "ray_offset", "environment", "output", "camera",
    "texture", "material", "sphere", "quad", "triangle", "mesh", "model", "light",
#define N_KEYWORDS 24
    "position", "look_at", "up", "fov", "aperture", "focus", "gltf", "image", "checker", "constant", "wrap",
    "filter", "repeat", "clamp", "mirror", "nearest", "bilinear", "scale", "color", "alpha", "texture",
    "normal_map", "uv_scale", "uv_offset", "double_sided", "true", "false", "alpha_mode", "mask",
    "attenuation_distance", "inf", "point", "directional", "spot", "area", "range", "translate", "rotate",
    "material_override", "strength", "m", "t", "n", "../assets/uvgrid.png", "../assets/torus.obj",
    "../assets/box.gltf", "../assets/bumps.png", "nosuch.png", "x.obj", "x.gltf", "0", "1", "-1", "0.5", "1e3",
    "1e40", "nan", "9999999999", "4294967296", "32769", "\\", "#", "\"", "\"a b\"", "\"\"", "__x", "direct",
    "whitted", "path", "emission", "ior", "metallic", "\xff", "\xc3\xa9",
};
#define N_WORDS (sizeof words / sizeof *words)

static size_t generate(char *buf, size_t cap)
{
    size_t len = 0;
    if (next() % 3 == 0) { /* mutate the default scene */
        len = strlen(rt_default_scene_text);
        if (len > cap - 64)
            len = cap - 64;
        memcpy(buf, rt_default_scene_text, len);
        for (int e = 1 + (int)(next() % 8); e > 0; e--) {
            size_t at = (size_t)(next() % (len + 1));
            if (next() % 2 && len) {
                buf[at % len] = (char)next();
            } else {
                const char *w = words[next() % N_WORDS];
                size_t n = strlen(w);
                if (len + n < cap) {
                    memmove(buf + at + n, buf + at, len - at);
                    memcpy(buf + at, w, n);
                    len += n;
                }
            }
        }
        return len;
    }
    /* random statements after a preamble that defines some names */
    const char *pre = "material m\ntexture t constant 1 1 1\n";
    len = strlen(pre);
    memcpy(buf, pre, len);
    for (int lines = 1 + (int)(next() % 10); lines > 0; lines--) {
        int toks = 1 + (int)(next() % 16);
        for (int k = 0; k < toks && len + 64 < cap; k++) {
            const char *w = k == 0 ? words[next() % N_KEYWORDS] : words[next() % N_WORDS];
            size_t n = strlen(w);
            memcpy(buf + len, w, n);
            len += n;
            buf[len++] = next() % 10 ? ' ' : (next() % 2 ? '\t' : '\n');
        }
        if (len < cap)
            buf[len++] = '\n';
    }
    return len;
}

int main(int argc, char **argv)
{
    long iterations = 100000;
    int files = 0;
    rt_log_set_level(RT_LOG_QUIET);
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-n") == 0 && i + 1 < argc) {
            iterations = atol(argv[++i]);
        } else if (strcmp(argv[i], "-seed") == 0 && i + 1 < argc) {
            rng = strtoull(argv[++i], NULL, 10) * 2654435761u + 1;
        } else {
            FILE *f = fopen(argv[i], "rb");
            if (!f) {
                perror(argv[i]);
                return 2;
            }
            static uint8_t data[1 << 20];
            size_t n = fread(data, 1, sizeof data, f);
            fclose(f);
            check_one(data, n);
            files++;
        }
    }
    if (files) {
        printf("%d file(s) ok\n", files);
        return 0;
    }
    static char buf[1 << 16];
    long parsed = 0;
    for (long it = 0; it < iterations; it++) {
        size_t len = generate(buf, sizeof buf);
        rt_scene s;
        rt_error err;
        rt_scene_init(&s);
        parsed += rt_scene_parse_string(&s, buf, len, "x", "scenes", &err) == RT_OK;
        rt_scene_free(&s);
        check_one((const uint8_t *)buf, len);
    }
    printf("%ld inputs, %ld parsed without error, no crash\n", iterations, parsed);
    return 0;
}
#endif
