/* harness.c - see harness.h. Every input but an image goes through
 * rt_load_memory, the dispatch `rt` uses, named as a file in a private
 * temporary directory (one per process), where the files an input refers
 * to (a glTF's buffer.bin, an OBJ's m.mtl) are written first. */
#include "harness.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt/io/draco.h"
#include "rt/io/exr.h"
#include "rt/image/framebuffer.h"
#include "rt/io/image_load.h"
#include "rt/io/image_read.h"
#include "rt/io/json.h"
#include "rt/io/nanovdb.h"
#include "rt/io/load.h"
#include "rt/io/meshopt.h"
#include "rt/job/merge.h"
#include "rt/job/output.h"
#include "rt/job/part.h"
#include "rt/render/volume.h"
#include "rt/scene/scene.h"
#include "rt/scene/texture.h"

const char *const rt_fuzz_targets[] = {"scene", "gltf",    "glb",   "gltf_bin", "obj",        "ply",  "off",
                                       "image", "exr",     "meshopt", "draco", "part", "image_file", "pose",
                                       "json",  "nvdb",    "merge",   NULL};

static char dir[64];

static void remove_temp_dir(void)
{
    static const char *const files[] = {"buffer.bin", "m.mtl",      "p.exr",  "p.exr.json", "fuzz.img",   "m0.exr",
                                        "m0.exr.json", "m1.exr",  "m1.exr.json", "m2.exr", "m2.exr.json", "m3.exr",
                                        "m3.exr.json", NULL};
    char path[256];
    for (int i = 0; files[i]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        unlink(path);
    }
    rmdir(dir);
}

static const char *temp_dir(void)
{
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "%s/rt-fuzz-XXXXXX", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
        if (!mkdtemp(dir)) {
            perror("rt-fuzz: mkdtemp");
            abort();
        }
        atexit(remove_temp_dir);
    }
    return dir;
}

static void write_temp(const char *name, const uint8_t *data, size_t size, char *path, size_t path_size)
{
    snprintf(path, path_size, "%s/%s", temp_dir(), name);
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror("rt-fuzz: fopen");
        abort();
    }
    if (size)
        fwrite(data, 1, size, f);
    fclose(f);
}

/* Splits "u32 length, first part, second part". */
static void split(const uint8_t *data, size_t size, size_t *first)
{
    if (size < 4) {
        *first = 0;
        return;
    }
    uint32_t n = (uint32_t)data[0] | (uint32_t)data[1] << 8 | (uint32_t)data[2] << 16 | (uint32_t)data[3] << 24;
    *first = n < size - 4 ? n : size - 4;
}

/* Loads one input the way rt does (rt_load_memory: by content, then by the
 * extension of name), as a file of that name in the temporary directory. */
static void load(const char *name, const uint8_t *data, size_t size)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", temp_dir(), name);
    rt_scene s;
    rt_scene_init(&s);
    rt_settings set; /* the settings statements are stored too */
    rt_settings_default(&set);
    rt_error err;
    rt_load_memory(&s, &set, data, size, path, NULL, NULL, &err);
    rt_scene_free(&s);
}

/* A part as the `part` target takes it: u32 length, the sidecar (its
 * "@HASH@" replaced by the image's FNV-1a, so the fuzzer gets past the
 * hash check), the image; written as `name` and name.json. path: name's. */
static void write_part(const char *name, const uint8_t *data, size_t size, char *path, size_t path_size)
{
    size_t n;
    split(data, size, &n);
    const uint8_t *json = size >= 4 ? data + 4 : data, *img = json + n;
    size_t img_size = size >= 4 ? size - 4 - n : 0;
    char side[64];
    snprintf(side, sizeof side, "%s.json", name);
    char hash[17];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)rt_fnv1a64(img, img_size, RT_FNV1A64_INIT));
    char *text = malloc(n + 17);
    if (!text)
        abort();
    size_t o = 0;
    for (size_t i = 0; i < n;) {
        if (i + 6 <= n && memcmp(json + i, "@HASH@", 6) == 0) {
            memcpy(text + o, hash, 16);
            o += 16;
            i += 6;
            memcpy(text + o, json + i, n - i);
            o += n - i;
            break;
        }
        text[o++] = (char)json[i++];
    }
    write_temp(side, (const uint8_t *)text, o, path, path_size);
    free(text);
    write_temp(name, img, img_size, path, path_size);
}

/* merge: a byte whose low two bits + 1 are the number of parts, then each
 * part as a u32 length and that many bytes of a `part` input (the last
 * takes what is left); read and merged as `rt merge` does (same render,
 * the same file twice, regions tiling the image, sample ranges, then the
 * fold and resolve into the image and its AOVs). */
static void fuzz_merge(const uint8_t *data, size_t size)
{
    if (size < 1)
        return;
    int parts = data[0] % 4 + 1;
    data++;
    size--;
    rt_merge m;
    rt_error err;
    if (rt_merge_init(&m, parts, &err) != RT_OK)
        return;
    bool ok = true;
    for (int k = 0; k < parts && ok; k++) {
        size_t n;
        split(data, size, &n);
        if (k == parts - 1)
            n = size >= 4 ? size - 4 : 0;
        const uint8_t *part = size >= 4 ? data + 4 : data;
        char name[24], path[256];
        snprintf(name, sizeof name, "m%d.exr", k);
        write_part(name, part, n, path, sizeof path);
        ok = rt_merge_add(&m, path, &err) == RT_OK;
        data = part + n;
        size = size >= 4 ? size - 4 - n : 0;
    }
    if (ok && rt_merge_check_cover(&m, &err) == RT_OK) {
        const rt_part_info *first = &m.parts[0].info;
        rt_framebuffer fb;
        rt_job_options o;
        memset(&o, 0, sizeof o);
        for (int l = 0; l < first->layer_count; l++) {
            rt_aov_kind kind;
            if (rt_aov_by_name(first->layer_name[l], strlen(first->layer_name[l]), &kind))
                o.aovs |= 1u << kind;
        }
        rt_job_aovs aov;
        memset(&aov, 0, sizeof aov);
        if (rt_framebuffer_init(&fb, first->width, first->height, &err) == RT_OK) {
            if (rt_job_aovs_init(&aov, &o, first->width, first->height, &err) == RT_OK)
                (void)rt_merge_image(&m, &fb, rt_job_aovs_for_render(&aov), &err);
            rt_job_aovs_free(&aov);
            rt_framebuffer_free(&fb);
        }
    }
    rt_merge_free(&m);
}

/* meshopt: mode, filter, stride / 4 - 1 (or the index size), count (u16
 * little-endian), then the stream; shapes the extension forbids are
 * refused by rt_meshopt_check as in a glTF file. */
static void fuzz_meshopt(const uint8_t *data, size_t size)
{
    if (size < 5)
        return;
    rt_meshopt_mode mode = (rt_meshopt_mode)(data[0] % 3);
    rt_meshopt_filter filter = (rt_meshopt_filter)(data[1] % 4);
    size_t stride = mode == RT_MESHOPT_ATTRIBUTES ? ((size_t)data[2] % 64 + 1) * 4 : (data[2] & 1 ? 4 : 2);
    size_t count = (size_t)data[3] | (size_t)data[4] << 8;
    if (rt_meshopt_check(mode, filter, count, stride))
        return;
    uint8_t *dst = malloc(count * stride);
    if (dst)
        rt_meshopt_decode(dst, count, stride, data + 5, size - 5, mode, filter);
    free(dst);
}

/* draco: a Draco stream, decoded, then its indices and the attributes of
 * unique ids 0..7 read as a glTF loader reads them. */
static void fuzz_draco(const uint8_t *data, size_t size)
{
    char why[200];
    rt_draco_mesh *m = rt_draco_decode(data, size, why, sizeof why);
    if (!m)
        return;
    size_t faces = rt_draco_faces(m), points = rt_draco_points(m);
    if (faces <= ((size_t)1 << 22) && points <= ((size_t)1 << 22)) {
        uint32_t *idx = malloc((3 * faces + 1) * sizeof *idx);
        float *vals = malloc((4 * points + 1) * sizeof *vals);
        if (idx && vals) {
            rt_draco_indices(m, idx);
            for (uint32_t id = 0; id < 8; id++) {
                int n = rt_draco_components(m, id);
                if (n > 0)
                    rt_draco_attribute(m, id, n < 4 ? n : 4, vals);
            }
        }
        free(idx);
        free(vals);
    }
    rt_draco_free(m);
}

/* pose: the animation index, a signed 16-bit time in 1/64 s, then a .glb,
 * or (anything else) a .gltf and its buffer.bin as in gltf_bin; loaded as
 * rt loads it for --time: the animation sampled, skins and morphs applied. */
static void fuzz_pose(const uint8_t *data, size_t size)
{
    if (size < 3)
        return;
    rt_load_options opt = {0};
    opt.use_time = true;
    opt.animation = data[0] % 4;
    opt.time = (float)(int16_t)(uint16_t)(data[1] | data[2] << 8) / 64.0f;
    data += 3;
    size -= 3;
    char path[256];
    const char *name = "fuzz.glb";
    if (size < 4 || memcmp(data, "glTF", 4) != 0) {
        size_t n;
        split(data, size, &n);
        write_temp("buffer.bin", data + 4 + n, size >= 4 ? size - 4 - n : 0, path, sizeof path);
        if (size >= 4)
            data += 4;
        size = n;
        name = "fuzz.gltf";
    }
    snprintf(path, sizeof path, "%s/%s", temp_dir(), name);
    rt_scene s;
    rt_scene_init(&s);
    rt_settings set;
    rt_settings_default(&set);
    rt_error err;
    rt_load_memory(&s, &set, data, size, path, &opt, NULL, &err);
    rt_scene_free(&s);
}

/* Every token of a tokenized document read by every walker. */
static void walk_json(const rt_json *j)
{
    char buf[64];
    double v;
    bool b;
    for (int i = 0; i < j->count; i++) {
        (void)rt_json_number(j, i, &v);
        (void)rt_json_bool(j, i, &b);
        (void)rt_json_string(j, i, buf, sizeof buf);
        (void)rt_json_get(j, i, "a");
        if (rt_json_skip(j, i) > j->count)
            abort(); /* a walker must never step past the tokens */
    }
}

/* json: a mode byte, then text for rt_json_parse. Mode 0 parses the text
 * as it is; mode 1 wraps it in N arrays (N: the next two bytes, so up to
 * 65 535 deep, past RT_JSON_MAX_DEPTH) inside {"a": ... }; mode 2 repeats
 * it N times (up to 65 535, at most 2 MB) as the elements of one array:
 * the depth and size extremes a few bytes cannot reach on their own. */
/* nvdb: the bytes as a NanoVDB file; a grid that loads is walked by the
 * majorant and ratio tracking along a diagonal, as a medium would be. */
static void fuzz_nvdb(const uint8_t *data, size_t size)
{
    rt_density_grid grid;
    rt_mat4 index_to_world;
    rt_error err;
    if (rt_nanovdb_parse(data, size, "fuzz.nvdb", NULL, &grid, &index_to_world, &err) != RT_OK)
        return;
    rt_mat4 identity = rt_mat4_identity();
    rt_volume v = rt_volume_grid(rt_v3(1, 1, 1), rt_v3(1, 1, 1), 0.0f, &grid, &identity);
    rt_rng rng = rt_rng_seed(1, 2);
    rt_vec3 o = rt_v3(-1, -1, -1), d = rt_v3((float)grid.nx + 2, (float)grid.ny + 2, (float)grid.nz + 2);
    (void)rt_volume_ratio_tracking(&v, o, d, 1.0f, &rng);
    rt_density_grid_free(&grid);
}

static void fuzz_json(const uint8_t *data, size_t size)
{
    if (size < 3)
        return;
    int mode = data[0] % 3;
    size_t n = (size_t)data[1] | (size_t)data[2] << 8;
    const char *body = (const char *)data + 3;
    size_t blen = size - 3, len = 0;
    if (mode == 2 && n * (blen + 1) > ((size_t)1 << 21))
        n = ((size_t)1 << 21) / (blen + 1); /* 2 MB at most: size, not allocation, is what is tested */
    char *text;
    if (mode == 0) {
        text = malloc(blen + 1);
        if (!text)
            return;
        memcpy(text, body, blen);
        len = blen;
    } else {
        size_t cap = 8 + (mode == 1 ? 2 * n + blen : n * (blen + 1));
        text = malloc(cap);
        if (!text)
            return;
        memcpy(text, "{\"a\":[", 6);
        len = 6;
        for (size_t i = 0; i < n; i++) {
            if (mode == 1) {
                text[len++] = '[';
            } else {
                if (i)
                    text[len++] = ',';
                memcpy(text + len, body, blen);
                len += blen;
            }
        }
        if (mode == 1) {
            memcpy(text + len, body, blen);
            len += blen;
            memset(text + len, ']', n);
            len += n;
        }
        text[len++] = ']';
        text[len++] = '}';
    }
    rt_json j;
    rt_error err;
    if (rt_json_parse(&j, text, len, "fuzz.json", 0, &err) == RT_OK) {
        walk_json(&j);
        rt_json_free(&j);
    }
    free(text);
}

int rt_fuzz_run(const char *target, const uint8_t *data, size_t size)
{
    char path[256];
    if (strcmp(target, "scene") == 0) {
        load("fuzz.txt", data, size);
    } else if (strcmp(target, "gltf") == 0) {
        load("fuzz.gltf", data, size);
    } else if (strcmp(target, "glb") == 0) {
        load("fuzz.glb", data, size);
    } else if (strcmp(target, "gltf_bin") == 0) {
        size_t n;
        split(data, size, &n);
        write_temp("buffer.bin", data + 4 + n, size >= 4 ? size - 4 - n : 0, path, sizeof path);
        load("fuzz.gltf", size >= 4 ? data + 4 : data, n);
    } else if (strcmp(target, "obj") == 0) {
        size_t n;
        split(data, size, &n);
        write_temp("m.mtl", data + 4 + n, size >= 4 ? size - 4 - n : 0, path, sizeof path);
        load("fuzz.obj", size >= 4 ? data + 4 : data, n);
    } else if (strcmp(target, "ply") == 0) {
        load("fuzz.ply", data, size);
    } else if (strcmp(target, "off") == 0) {
        load("fuzz.off", data, size);
    } else if (strcmp(target, "image") == 0) {
        rt_scene s;
        rt_scene_init(&s);
        rt_error err;
        uint32_t img;
        rt_image_load_memory(&s, data, size, "fuzz.img", &img, &err);
        rt_scene_free(&s);
    } else if (strcmp(target, "image_file") == 0) {
        /* an image file as rt compare and rt convert read it: PFM too */
        write_temp("fuzz.img", data, size, path, sizeof path);
        rt_framebuffer fb;
        rt_error err;
        if (rt_image_read(path, &fb, &err) == RT_OK)
            rt_framebuffer_free(&fb);
    } else if (strcmp(target, "part") == 0) {
        write_part("p.exr", data, size, path, sizeof path);
        rt_part part;
        rt_error err;
        if (rt_part_read(path, &part, &err) == RT_OK)
            rt_part_free(&part);
    } else if (strcmp(target, "merge") == 0) {
        fuzz_merge(data, size);
    } else if (strcmp(target, "exr") == 0) {
        rt_error err;
        float *rgba = NULL;
        int w, h;
        if (rt_exr_decode(data, size, "fuzz.exr", 4096, (uint64_t)1 << 22, &rgba, &w, &h, &err) == RT_OK)
            free(rgba);
    } else if (strcmp(target, "meshopt") == 0) {
        fuzz_meshopt(data, size);
    } else if (strcmp(target, "draco") == 0) {
        fuzz_draco(data, size);
    } else if (strcmp(target, "pose") == 0) {
        fuzz_pose(data, size);
    } else if (strcmp(target, "json") == 0) {
        fuzz_json(data, size);
    } else if (strcmp(target, "nvdb") == 0) {
        fuzz_nvdb(data, size);
    } else {
        return -1;
    }
    return 0;
}
