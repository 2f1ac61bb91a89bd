/* harness.c - see harness.h. Inputs that loaders read by path are written
 * to a private temporary directory (one per process) first. */
#include "harness.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt/io/gltf.h"
#include "rt/io/mesh_io.h"
#include "rt/scene/scene.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/texture.h"

const char *const rt_fuzz_targets[] = {"scene", "gltf", "glb", "gltf_bin", "obj", "ply", "off", "image", NULL};

static char dir[64];

static void remove_temp_dir(void)
{
    static const char *const files[] = {"buffer.bin", "m.mtl", "fuzz.obj", "fuzz.ply", "fuzz.off", NULL};
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

static void load_mesh(const char *name, const uint8_t *data, size_t size)
{
    char path[256];
    write_temp(name, data, size, path, sizeof path);
    rt_scene s;
    rt_scene_init(&s);
    rt_material m;
    rt_material_default(&m, "fuzz");
    uint32_t mi = rt_scene_add_material(&s, &m);
    rt_mesh_options opt = {.material = mi};
    rt_error err;
    rt_mesh_load_stats st;
    rt_mesh_load(&s, path, &opt, &st, &err);
    rt_scene_free(&s);
}

int rt_fuzz_run(const char *target, const uint8_t *data, size_t size)
{
    rt_scene s;
    rt_error err;
    char path[256];
    if (strcmp(target, "scene") == 0) {
        rt_scene_init(&s);
        rt_scene_parse_string(&s, (const char *)data, size, "fuzz.txt", temp_dir(), &err);
        rt_scene_free(&s);
    } else if (strcmp(target, "gltf") == 0 || strcmp(target, "glb") == 0) {
        rt_scene_init(&s);
        snprintf(path, sizeof path, "%s/fuzz.%s", temp_dir(), target);
        rt_gltf_load_memory(&s, data, size, path, NULL, NULL, &err);
        rt_scene_free(&s);
    } else if (strcmp(target, "gltf_bin") == 0) {
        size_t n;
        split(data, size, &n);
        char bin[256];
        write_temp("buffer.bin", data + 4 + n, size >= 4 ? size - 4 - n : 0, bin, sizeof bin);
        rt_scene_init(&s);
        snprintf(path, sizeof path, "%s/fuzz.gltf", temp_dir());
        rt_gltf_load_memory(&s, size >= 4 ? data + 4 : data, n, path, NULL, NULL, &err);
        rt_scene_free(&s);
    } else if (strcmp(target, "obj") == 0) {
        size_t n;
        split(data, size, &n);
        char mtl[256];
        write_temp("m.mtl", data + 4 + n, size >= 4 ? size - 4 - n : 0, mtl, sizeof mtl);
        load_mesh("fuzz.obj", size >= 4 ? data + 4 : data, n);
    } else if (strcmp(target, "ply") == 0) {
        load_mesh("fuzz.ply", data, size);
    } else if (strcmp(target, "off") == 0) {
        load_mesh("fuzz.off", data, size);
    } else if (strcmp(target, "image") == 0) {
        rt_scene_init(&s);
        uint32_t img;
        rt_image_load_memory(&s, data, size, "fuzz.img", &img, &err);
        rt_scene_free(&s);
    } else {
        return -1;
    }
    return 0;
}
