/* test_gltf.c - the glTF 2.0 loader against the Khronos sample models (the
 * manifest's triangle counts and world bounds), small hand-written files with
 * exact expected triangles, and broken files that must fail cleanly with a
 * message naming the file and the problem. */
#include "test_util.h"

#include <dirent.h>
#include <math.h>
#include <time.h>
#include <unistd.h>

#include "rt/base/log.h"
#include "rt/io/base64.h"
#include "rt/io/gltf.h"
#include "rt/io/json.h"
#include "rt/scene/instance.h"
#include "rt/scene/scene.h"

/* ------------------------------------------------------------ helpers */

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static char tmp_dir[256];

static int setup_tmp(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "gltf") ? 0 : -1;
}

static int teardown_tmp(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

static const char *tmp_path(const char *name)
{
    static char buf[600];
    snprintf(buf, sizeof buf, "%s/%s", tmp_dir, name);
    return buf;
}

static void write_text(const char *name, const char *text) { test_write_file(tmp_path(name), text, strlen(text)); }

/* Loads a file into a fresh scene; returns the result, keeps the error. */
/* The flattening loader these tests check: every use of a mesh in world
 * triangles (test_instance.c checks the objects and instances). */
static rt_result load(const char *path, rt_scene *s, rt_gltf_stats *st, rt_error *err)
{
    rt_scene_init(s);
    memset(err, 0, sizeof *err);
    rt_gltf_options opt = {0};
    opt.flatten_instances = true;
    return rt_gltf_load(s, path, &opt, st, err);
}

/* The same file loaded with instancing places as many triangles as the
 * flattened load holds: its world triangles plus the instances'. */
static void check_instanced_count(const char *file, size_t flattened)
{
    rt_scene s;
    rt_scene_init(&s);
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(rt_gltf_load(&s, file, NULL, &st, &err), RT_OK);
    size_t world = s.triangles.count - rt_scene_object_triangles(&s) + rt_scene_instanced_triangles(&s);
    if (world != flattened)
        fprintf(stderr, "%s: instanced load places %zu triangles, flattened %zu\n", file, world, flattened);
    assert_int_equal(world, flattened);
    assert_int_equal(st.instanced_triangles, rt_scene_instanced_triangles(&s));
    rt_scene_free(&s);
}

/* Expects failure with `code` and a message containing the file name and `what`. */
static void expect_fail(const char *name, rt_result code, const char *what)
{
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    rt_result r = load(tmp_path(name), &s, &st, &err);
    test_expect_failure(r, &err, code, name, what);
    assert_int_equal(s.triangles.count, 0);
    assert_int_equal(s.vertices.count, 0);
    rt_scene_free(&s);
}

/* ---------------------------------------------------- manifest models */

typedef struct manifest_row {
    char path[128];
    long triangles;
    double lo[3], hi[3];
} manifest_row;

static long parse_count(const char *cell)
{
    const char *own = strstr(cell, "own parser:");
    const char *p = own ? own + 11 : cell;
    while (*p && !(*p >= '0' && *p <= '9'))
        p++;
    long v = 0;
    for (; (*p >= '0' && *p <= '9') || *p == ','; p++)
        if (*p != ',')
            v = v * 10 + (*p - '0');
    return v;
}

/* Reads the rows of the manifest tables that describe glTF/GLB files. */
static int read_manifest(manifest_row *rows, int max)
{
    FILE *f = fopen(test_shared_path("assets/MANIFEST.md"), "r");
    if (!f)
        return -1;
    char line[8192];
    int n = 0;
    while (fgets(line, sizeof line, f) && n < max) {
        if (strncmp(line, "| `gltf/", 8) != 0 && strncmp(line, "| `meshes/", 10) != 0)
            continue;
        char *cells[12] = {0};
        int nc = 0;
        for (char *p = line; *p && nc < 12; p++)
            if (*p == '|') {
                *p = 0;
                cells[nc++] = p + 1;
            }
        if (nc < 9)
            continue;
        manifest_row *r = &rows[n];
        const char *a = strchr(cells[0], '`');
        const char *b = a ? strchr(a + 1, '`') : NULL;
        if (!a || !b || (size_t)(b - a - 1) >= sizeof r->path)
            continue;
        memcpy(r->path, a + 1, (size_t)(b - a - 1));
        r->path[b - a - 1] = 0;
        r->triangles = parse_count(cells[4]);
        if (sscanf(cells[6], " (%lf, %lf, %lf) / (%lf, %lf, %lf)", &r->lo[0], &r->lo[1], &r->lo[2], &r->hi[0],
                   &r->hi[1], &r->hi[2]) != 6)
            continue;
        n++;
    }
    fclose(f);
    return n;
}

static void check_against_row(const char *file, const manifest_row *row, const rt_scene *s, const rt_gltf_stats *st)
{
    if ((long)st->triangles != row->triangles)
        fprintf(stderr, "%s: %zu triangles, manifest says %ld\n", file, st->triangles, row->triangles);
    assert_int_equal(st->triangles, row->triangles);
    assert_int_equal(s->triangles.count, row->triangles);
    double diag = sqrt((row->hi[0] - row->lo[0]) * (row->hi[0] - row->lo[0]) +
                       (row->hi[1] - row->lo[1]) * (row->hi[1] - row->lo[1]) +
                       (row->hi[2] - row->lo[2]) * (row->hi[2] - row->lo[2]));
    const float lo[3] = {st->bounds.lo.x, st->bounds.lo.y, st->bounds.lo.z};
    const float hi[3] = {st->bounds.hi.x, st->bounds.hi.y, st->bounds.hi.z};
    for (int k = 0; k < 3; k++) {
        /* the manifest has 4 significant digits */
        double tl = 1e-3 * diag + 5e-4 * fabs(row->lo[k]), th = 1e-3 * diag + 5e-4 * fabs(row->hi[k]);
        if (fabs(lo[k] - row->lo[k]) > tl || fabs(hi[k] - row->hi[k]) > th)
            fprintf(stderr, "%s: bounds (%g %g %g)/(%g %g %g), manifest (%g %g %g)/(%g %g %g)\n", file, lo[0], lo[1],
                    lo[2], hi[0], hi[1], hi[2], row->lo[0], row->lo[1], row->lo[2], row->hi[0], row->hi[1],
                    row->hi[2]);
        assert_true(fabs(lo[k] - row->lo[k]) <= tl);
        assert_true(fabs(hi[k] - row->hi[k]) <= th);
    }
}

/* Finds the model file (*.gltf / *.glb) in a directory. */
static int find_model(const char *dir, char *out, size_t cap)
{
    DIR *dd = opendir(dir);
    if (!dd)
        return 0;
    struct dirent *e;
    int found = 0;
    while ((e = readdir(dd)) && !found) {
        const char *dot = strrchr(e->d_name, '.');
        if (dot && (strcmp(dot, ".gltf") == 0 || strcmp(dot, ".glb") == 0)) {
            snprintf(out, cap, "%.3800s/%.255s", dir, e->d_name);
            found = 1;
        }
    }
    closedir(dd);
    return found;
}

static void test_manifest_models(void **state)
{
    (void)state;
    test_require_shared();
    static manifest_row rows[128];
    int n = read_manifest(rows, 128);
    assert_true(n >= 30); /* 33 glTF models + 2 meshes when this was written */
    static const char *variants[] = {"glTF", "glTF-Binary", "glTF-Embedded"};
    int files = 0;
    for (int i = 0; i < n; i++) {
        const manifest_row *row = &rows[i];
        rt_scene first;
        int have_first = 0;
        char first_file[4200] = "";
        if (strncmp(row->path, "meshes/", 7) == 0) {
            /* "meshes/igea/" holds igea.glb */
            char name[128], file[4200];
            snprintf(name, sizeof name, "%s", row->path + 7);
            name[strcspn(name, "/")] = 0;
            char rel[512];
            snprintf(rel, sizeof rel, "assets/%.120s%.120s.glb", row->path, name);
            snprintf(file, sizeof file, "%s", test_shared_path(rel));
            rt_scene s;
            rt_gltf_stats st;
            rt_error err;
            rt_result r = load(file, &s, &st, &err);
            if (r != RT_OK)
                fprintf(stderr, "%s: %s\n", file, err.message);
            assert_int_equal(r, RT_OK);
            check_against_row(file, row, &s, &st);
            rt_scene_free(&s);
            files++;
            continue;
        }
        for (int v = 0; v < 3; v++) {
            char rel[512], dir[4200], file[4200];
            snprintf(rel, sizeof rel, "assets/%.120s%s", row->path, variants[v]);
            snprintf(dir, sizeof dir, "%s", test_shared_path(rel));
            if (!find_model(dir, file, sizeof file))
                continue;
            rt_scene s;
            rt_gltf_stats st;
            rt_error err;
            double t0 = now_seconds();
            rt_result r = load(file, &s, &st, &err);
            double t1 = now_seconds();
            if (r != RT_OK)
                fprintf(stderr, "%s: %s\n", file, err.message);
            assert_int_equal(r, RT_OK);
            if (st.triangles > 500000)
                fprintf(stderr, "note: %s: %zu triangles loaded in %.3f s\n", file, st.triangles, t1 - t0);
            check_against_row(file, row, &s, &st);
            if (!have_first && st.triangles <= 500000)
                check_instanced_count(file, st.triangles);
            files++;
            if (!have_first) {
                first = s;
                have_first = 1;
                snprintf(first_file, sizeof first_file, "%s", file);
                continue;
            }
            /* the variants of a model load to identical triangle buffers */
            if (s.vertices.count != first.vertices.count ||
                memcmp(s.vertices.position, first.vertices.position, s.vertices.count * sizeof(rt_vec3)) != 0 ||
                memcmp(s.triangles.index, first.triangles.index, s.triangles.count * 3 * sizeof(uint32_t)) != 0)
                fprintf(stderr, "%s and %s differ\n", file, first_file);
            assert_int_equal(s.vertices.count, first.vertices.count);
            assert_memory_equal(s.vertices.position, first.vertices.position, s.vertices.count * sizeof(rt_vec3));
            assert_memory_equal(s.triangles.index, first.triangles.index, s.triangles.count * 3 * sizeof(uint32_t));
            assert_int_equal(s.material_count, first.material_count);
            assert_int_equal(s.texture_count, first.texture_count);
            rt_scene_free(&s);
        }
        if (have_first)
            rt_scene_free(&first);
    }
    fprintf(stderr, "note: %d glTF files checked against the manifest\n", files);
    assert_true(files >= 80);
}

/* Spot checks of what the sample models exercise beyond geometry. */
static void test_sample_features(void **state)
{
    (void)state;
    test_require_shared();
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    /* Cameras: one perspective camera kept, the orthographic one skipped */
    assert_int_equal(load(test_shared_path("assets/gltf/Cameras/glTF/Cameras.gltf"), &s, &st, &err), RT_OK);
    assert_int_equal(st.cameras, 1);
    assert_int_equal(s.camera_count, 1);
    rt_scene_free(&s);
    /* DamagedHelmet: 5 textures, full PBR material */
    assert_int_equal(load(test_shared_path("assets/gltf/DamagedHelmet/glTF-Binary/DamagedHelmet.glb"), &s, &st, &err),
                     RT_OK);
    assert_int_equal(st.textures, 5);
    assert_int_equal(st.images, 5);
    assert_int_equal(s.material_count, 1);
    const rt_material *m = &s.materials[0];
    assert_true(m->base_color_tex.texture != RT_NONE && m->normal_tex.texture != RT_NONE &&
                m->occlusion_tex.texture != RT_NONE && m->emissive_tex.texture != RT_NONE &&
                m->metal_rough_tex.texture != RT_NONE);
    assert_true(s.images[s.textures[m->base_color_tex.texture].image].width > 0);
    assert_true(s.triangles.flags[0] & RT_TRI_SMOOTH);
    assert_true(s.triangles.flags[0] & RT_TRI_UV);
    rt_scene_free(&s);
    /* TextureSettingsTest: 9 textures over 3 images (decoded once) with wrap modes */
    assert_int_equal(load(test_shared_path("assets/gltf/TextureSettingsTest/glTF/TextureSettingsTest.gltf"), &s, &st,
                          &err), RT_OK);
    assert_int_equal(st.textures, 9);
    assert_int_equal(st.images, 3);
    assert_int_equal(s.image_count, 3);
    int wraps[3] = {0, 0, 0};
    for (size_t i = 0; i < s.texture_count; i++) {
        wraps[s.textures[i].wrap_s]++;
        wraps[s.textures[i].wrap_t]++;
    }
    assert_true(wraps[RT_WRAP_REPEAT] > 0 && wraps[RT_WRAP_CLAMP] > 0 && wraps[RT_WRAP_MIRROR] > 0);
    rt_scene_free(&s);
    /* vertex colours and tangents */
    assert_int_equal(load(test_shared_path("assets/gltf/BoxVertexColors/glTF/BoxVertexColors.gltf"), &s, &st, &err),
                     RT_OK);
    assert_non_null(s.vertices.color);
    assert_true(s.triangles.flags[0] & RT_TRI_COLOR);
    rt_scene_free(&s);
    assert_int_equal(load(test_shared_path("assets/gltf/Suzanne/glTF/Suzanne.gltf"), &s, &st, &err), RT_OK);
    assert_non_null(s.vertices.tangent);
    assert_true(s.triangles.flags[0] & RT_TRI_TANGENT);
    assert_float_equal(fabsf(s.vertices.tangent[0].w), 1.0f, 1e-6);
    rt_scene_free(&s);
    /* TEXCOORD_1 used by a texture */
    assert_int_equal(load(test_shared_path("assets/gltf/MultiUVTest/glTF-Binary/MultiUVTest.glb"), &s, &st, &err),
                     RT_OK);
    assert_non_null(s.vertices.uv1);
    int uses_uv1 = 0;
    for (size_t i = 0; i < s.material_count; i++)
        uses_uv1 |= s.materials[i].base_color_tex.texcoord == 1 || s.materials[i].emissive_tex.texcoord == 1;
    assert_true(uses_uv1);
    rt_scene_free(&s);
    /* KHR_materials_emissive_strength, transmission + volume + ior */
    assert_int_equal(load(test_shared_path("assets/gltf/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb"), &s,
                          &st, &err), RT_OK);
    float max_strength = 0;
    for (size_t i = 0; i < s.material_count; i++)
        max_strength = fmaxf(max_strength, s.materials[i].emission_strength);
    assert_true(max_strength > 1.0f);
    rt_scene_free(&s);
    assert_int_equal(load(test_shared_path("assets/gltf/TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb"),
                          &s, &st, &err), RT_OK);
    int transmissive = 0, volume = 0;
    for (size_t i = 0; i < s.material_count; i++) {
        transmissive += s.materials[i].transmission > 0;
        volume += s.materials[i].thickness > 0;
    }
    assert_true(transmissive > 0 && volume > 0);
    rt_scene_free(&s);
    /* MultipleScenes: "scene": 1 is the default (2 triangles); scene 0 has 1 */
    assert_int_equal(load(test_shared_path("assets/gltf/MultipleScenes/glTF/MultipleScenes.gltf"), &s, &st, &err),
                     RT_OK);
    assert_int_equal(st.triangles, 2);
    rt_scene_free(&s);
    rt_scene_init(&s);
    rt_gltf_options opt = {0};
    opt.flatten_instances = true;
    opt.use_scene_index = true;
    opt.scene_index = 0;
    assert_int_equal(rt_gltf_load(&s, test_shared_path("assets/gltf/MultipleScenes/glTF/MultipleScenes.gltf"), &opt,
                                  &st, &err), RT_OK);
    assert_int_equal(st.triangles, 1);
    rt_scene_free(&s);
}

/* ------------------------------------------------- focused small files */

/* A tiny glTF with one buffer given as base64 and the rest of the JSON. */
static void write_gltf(const char *name, const void *bin, size_t n, const char *rest)
{
    char *b64 = test_base64(bin, n);
    size_t cap = strlen(b64) + strlen(rest) + 512;
    char *text = malloc(cap);
    snprintf(text, cap,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
             "\"uri\":\"data:application/octet-stream;base64,%s\"}],%s}",
             n, b64, rest);
    write_text(name, text);
    free(text);
    free(b64);
}

/* write_gltf with a chain of `len` nodes, each the child of the one before,
 * the last holding a one-triangle mesh of the buffer's 3 positions. */
static void write_node_chain(const char *name, const void *bin, size_t n, int len)
{
    size_t cap = (size_t)len * 24 + 256;
    char *nodes = malloc(cap);
    size_t o = (size_t)snprintf(nodes, cap, "\"nodes\":[");
    for (int i = 0; i < len; i++)
        o += (size_t)snprintf(nodes + o, cap - o, i + 1 < len ? "{\"children\":[%d]}," : "{\"mesh\":0}", i + 1);
    snprintf(nodes + o, cap - o, "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]");
    write_gltf(name, bin, n, nodes);
    free(nodes);
}

static void assert_vec3(rt_vec3 a, float x, float y, float z)
{
    assert_float_equal(a.x, x, 1e-5);
    assert_float_equal(a.y, y, 1e-5);
    assert_float_equal(a.z, z, 1e-5);
}

/* Interleaved POSITION + NORMAL (stride 24), u8 indices. */
static void test_interleaved_u8(void **state)
{
    (void)state;
    struct { float p[3], n[3]; } v[4] = {
        {{0, 0, 0}, {0, 0, 1}}, {{1, 0, 0}, {0, 0, 1}}, {{1, 1, 0}, {0, 0, 1}}, {{0, 1, 0}, {0, 0, 1}}};
    uint8_t buf[96 + 8];
    memcpy(buf, v, 96);
    const uint8_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(buf + 96, idx, 6);
    buf[102] = buf[103] = 0;
    write_gltf("inter.gltf", buf, 104,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":96,\"byteStride\":24},"
               "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":6}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
               "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
               "{\"bufferView\":1,\"componentType\":5121,\"count\":6,\"type\":\"SCALAR\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load(tmp_path("inter.gltf"), &s, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 2);
    const uint32_t want[6] = {0, 1, 2, 0, 2, 3};
    assert_memory_equal(s.triangles.index, want, sizeof want);
    for (int i = 0; i < 4; i++) {
        assert_vec3(s.vertices.position[i], v[i].p[0], v[i].p[1], v[i].p[2]);
        assert_vec3(s.vertices.normal[i], 0, 0, 1);
    }
    assert_true(s.triangles.flags[0] & RT_TRI_SMOOTH);
    assert_int_equal(s.material_count, 1); /* the default material */
    assert_float_equal(s.materials[0].metallic, 1.0f, 0);
    assert_float_equal(s.materials[0].roughness, 1.0f, 0);
    assert_vec3(s.materials[0].color, 1, 1, 1);
    rt_scene_free(&s);
}

/* A sparse accessor over a base, and one over zeros (no bufferView). */
static void test_sparse(void **state)
{
    (void)state;
    uint8_t buf[256] = {0};
    float pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    memcpy(buf, pos, 36);
    uint16_t sidx[2] = {1, 2}; /* at 36 */
    memcpy(buf + 36, sidx, 4);
    float sval[2][3] = {{5, 0, 0}, {0, 7, 0}}; /* at 40 */
    memcpy(buf + 40, sval, 24);
    write_gltf("sparse.gltf", buf, 64,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":4},"
               "{\"buffer\":0,\"byteOffset\":40,\"byteLength\":24}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
               "\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":1,\"componentType\":5123},"
               "\"values\":{\"bufferView\":2}}},"
               "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
               "\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":1,\"componentType\":5123},"
               "\"values\":{\"bufferView\":2}}}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]},"
               "{\"primitives\":[{\"attributes\":{\"POSITION\":1}}]}],"
               "\"nodes\":[{\"mesh\":0},{\"mesh\":1}],\"scenes\":[{\"nodes\":[0,1]}]");
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load(tmp_path("sparse.gltf"), &s, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 2);
    assert_vec3(s.vertices.position[0], 0, 0, 0);
    assert_vec3(s.vertices.position[1], 5, 0, 0);
    assert_vec3(s.vertices.position[2], 0, 7, 0);
    assert_vec3(s.vertices.position[3], 0, 0, 0);
    assert_vec3(s.vertices.position[4], 5, 0, 0);
    assert_vec3(s.vertices.position[5], 0, 7, 0);
    assert_false(s.triangles.flags[0] & RT_TRI_SMOOTH); /* no NORMAL: flat */
    rt_scene_free(&s);
}

/* Strip and fan: the spec's vertex orders, exactly. */
static void test_strip_fan(void **state)
{
    (void)state;
    float pos[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}};
    write_gltf("modes.gltf", pos, sizeof pos,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":60}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":5,\"type\":\"VEC3\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":5},"
               "{\"attributes\":{\"POSITION\":0},\"mode\":6},{\"attributes\":{\"POSITION\":0},\"mode\":1}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scene\":0,\"scenes\":[{\"nodes\":[0]}]");
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load(tmp_path("modes.gltf"), &s, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 6);
    assert_int_equal(st.primitives, 2);
    /* strip: {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}; fan: {v_{i+1}, v_{i+2}, v_0}; the fan's vertices start at 5 */
    const uint32_t want[18] = {0, 1, 2, 1, 3, 2, 2, 3, 4, 6, 7, 5, 7, 8, 5, 8, 9, 5};
    assert_memory_equal(s.triangles.index, want, sizeof want);
    rt_scene_free(&s);
}

/* Nested transforms, a mirrored node (winding flipped, tangent w flipped), options->transform. */
static void test_transforms(void **state)
{
    (void)state;
    uint8_t buf[36 + 36 + 48];
    float pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    float nrm[3][3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    float tan[3][4] = {{1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}};
    memcpy(buf, pos, 36);
    memcpy(buf + 36, nrm, 36);
    memcpy(buf + 72, tan, 48);
    /* node 0: translate (10,0,0), child node 1: rotate 90 deg about Z, scale 2;
     * node 2: mirror x (scale -1,1,1) */
    write_gltf("xf.gltf", buf, sizeof buf,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":120}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
               "{\"bufferView\":0,\"byteOffset\":36,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
               "{\"bufferView\":0,\"byteOffset\":72,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2}}]}],"
               "\"nodes\":[{\"translation\":[10,0,0],\"children\":[1]},"
               "{\"mesh\":0,\"rotation\":[0,0,0.70710678,0.70710678],\"scale\":[2,2,2]},"
               "{\"mesh\":0,\"matrix\":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}],"
               "\"scenes\":[{\"nodes\":[0,2]}]");
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load(tmp_path("xf.gltf"), &s, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 2);
    assert_int_equal(st.nodes, 3);
    /* instance 1: p' = (10,0,0) + Rz90 * 2p */
    assert_vec3(s.vertices.position[0], 10, 0, 0);
    assert_vec3(s.vertices.position[1], 10, 2, 0);
    assert_vec3(s.vertices.position[2], 8, 0, 0);
    assert_vec3(s.vertices.normal[0], 0, 0, 1);
    assert_vec3(rt_v3(s.vertices.tangent[0].x, s.vertices.tangent[0].y, s.vertices.tangent[0].z), 0, 1, 0);
    assert_float_equal(s.vertices.tangent[0].w, 1, 0);
    const uint32_t t0[3] = {0, 1, 2};
    assert_memory_equal(s.triangles.index, t0, sizeof t0);
    /* instance 2 (mirrored): x negated, winding flipped, w flipped, normal still +z */
    assert_vec3(s.vertices.position[4], -1, 0, 0);
    const uint32_t t1[3] = {3, 5, 4};
    assert_memory_equal(s.triangles.index + 3, t1, sizeof t1);
    assert_vec3(s.vertices.normal[4], 0, 0, 1);
    assert_vec3(rt_v3(s.vertices.tangent[4].x, s.vertices.tangent[4].y, s.vertices.tangent[4].z), -1, 0, 0);
    assert_float_equal(s.vertices.tangent[4].w, -1, 0);
    /* the geometric normal of the flipped triangle agrees with the shading normal */
    rt_vec3 a = rt_tri_vertex(&s, 1, 0), b = rt_tri_vertex(&s, 1, 1), c = rt_tri_vertex(&s, 1, 2);
    assert_true(rt_cross(rt_sub(b, a), rt_sub(c, a)).z > 0);
    rt_scene_free(&s);

    /* options->transform on top of the node transforms */
    rt_scene_init(&s);
    rt_gltf_options opt = {0};
    opt.flatten_instances = true;
    opt.use_transform = true;
    opt.transform = rt_mat4_translate(rt_v3(0, 0, 5));
    assert_int_equal(rt_gltf_load(&s, tmp_path("xf.gltf"), &opt, &st, &err), RT_OK);
    assert_vec3(s.vertices.position[1], 10, 2, 5);
    assert_vec3(s.vertices.position[4], -1, 0, 5);
    assert_float_equal(st.bounds.lo.z, 5, 1e-6);
    rt_scene_free(&s);
}

/* KHR_texture_transform, material fields, texture + sampler, camera, light. */
static void test_material_camera_light(void **state)
{
    (void)state;
    /* a 1x1 white image (binary PPM, which stb_image reads), next to the .gltf */
    static const char ppm[] = "P6\n1 1\n255\n\xff\xff\xff";
    test_write_file(tmp_path("white pixel.ppm"), ppm, sizeof ppm - 1);
    float pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    write_gltf("mat.gltf", pos, sizeof pos,
               "\"extensionsUsed\":[\"KHR_texture_transform\",\"KHR_lights_punctual\",\"KHR_materials_unlit\","
               "\"EXT_made_up\"],"
               "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"spot\",\"color\":[1,0.5,0.25],"
               "\"intensity\":20,\"range\":9,\"spot\":{\"innerConeAngle\":0.1,\"outerConeAngle\":0.5}}]}},"
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
               "\"images\":[{\"uri\":\"white%20pixel.ppm\"}],"
               "\"samplers\":[{\"magFilter\":9728,\"wrapS\":33071,\"wrapT\":33648}],"
               "\"textures\":[{\"source\":0,\"sampler\":0}],"
               "\"materials\":[{\"name\":\"red\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,0.5],"
               "\"metallicFactor\":0,\"roughnessFactor\":0.5,"
               "\"baseColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":"
               "{\"offset\":[0.5,0.25],\"rotation\":1.5707963,\"scale\":[2,3],\"texCoord\":1}}}},"
               "\"emissiveFactor\":[0.1,0.2,0.3],\"alphaMode\":\"MASK\",\"alphaCutoff\":0.3,\"doubleSided\":true,"
               "\"normalTexture\":{\"index\":0,\"scale\":0.7},"
               "\"extensions\":{\"KHR_materials_unlit\":{},\"KHR_materials_ior\":{\"ior\":1.33},"
               "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}}],"
               "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
               "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,5]},"
               "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}},\"translation\":[1,2,3],"
               "\"rotation\":[-0.70710678,0,0,0.70710678]}],"
               "\"scenes\":[{\"nodes\":[0,1,2]}]");
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    rt_result r = load(tmp_path("mat.gltf"), &s, &st, &err);
    if (r != RT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(r, RT_OK);
    assert_int_equal(s.material_count, 1);
    const rt_material *m = &s.materials[0];
    assert_string_equal(m->name, "red");
    assert_vec3(m->color, 1, 0, 0);
    assert_float_equal(m->alpha, 0.5f, 0);
    assert_float_equal(m->metallic, 0, 0);
    assert_float_equal(m->roughness, 0.5f, 0);
    assert_vec3(m->emission, 0.1f, 0.2f, 0.3f);
    assert_float_equal(m->emission_strength, 4, 0);
    assert_int_equal(m->alpha_mode, RT_ALPHA_MASK);
    assert_float_equal(m->alpha_cutoff, 0.3f, 1e-7);
    assert_true(m->double_sided);
    assert_true(m->unlit);
    assert_float_equal(m->ior, 1.33f, 1e-6);
    assert_float_equal(m->normal_scale, 0.7f, 1e-7);
    assert_int_equal(m->base_color_tex.texcoord, 1);
    /* T(0.5,0.25) * R(pi/2) * S(2,3), R = [cos sin; -sin cos]: [0 3 0.5; -2 0 0.25] */
    const float want[6] = {0, 3, 0.5f, -2, 0, 0.25f};
    for (int k = 0; k < 6; k++)
        assert_float_equal(m->base_color_tex.uv_transform[k], want[k], 1e-6);
    assert_int_equal(m->normal_tex.texcoord, 0);
    assert_float_equal(m->normal_tex.uv_transform[0], 1, 0);
    assert_int_equal(s.texture_count, 1);
    assert_int_equal(s.image_count, 1);
    assert_int_equal(m->base_color_tex.texture, 0);
    assert_int_equal(s.textures[0].wrap_s, RT_WRAP_CLAMP);
    assert_int_equal(s.textures[0].wrap_t, RT_WRAP_MIRROR);
    assert_int_equal(s.textures[0].filter, RT_FILTER_NEAREST);
    assert_int_equal(s.images[0].width, 1);
    /* camera at (0,0,5) looking down -Z with +Y up, vfov = yfov in degrees */
    assert_int_equal(s.camera_count, 1);
    assert_vec3(s.cameras[0].position, 0, 0, 5);
    assert_vec3(rt_sub(s.cameras[0].look_at, s.cameras[0].position), 0, 0, -1);
    assert_vec3(s.cameras[0].up, 0, 1, 0);
    assert_float_equal(s.cameras[0].vfov_deg, 0.5f * 180.0f / RT_PI, 1e-4);
    /* spot light at (1,2,3), rotated -90 deg about X: -Z becomes -Y */
    assert_int_equal(s.light_count, 1);
    const rt_light *l = &s.lights[0];
    assert_int_equal(l->kind, RT_LIGHT_SPOT);
    assert_vec3(l->position, 1, 2, 3);
    assert_vec3(l->direction, 0, -1, 0);
    assert_vec3(l->color, 1, 0.5f, 0.25f);
    assert_float_equal(l->intensity, 20, 0);
    assert_float_equal(l->range, 9, 0);
    assert_float_equal(l->inner_cone, 0.1f, 1e-7);
    assert_float_equal(l->outer_cone, 0.5f, 1e-7);
    assert_int_equal(st.cameras, 1);
    assert_int_equal(st.lights, 1);
    rt_scene_free(&s);
}

/* A GLB built by the test: JSON chunk + BIN chunk, quantized (normalized u16) UVs and u8 colours. */
static size_t make_glb(uint8_t *out, const char *json, const void *bin, size_t bin_len)
{
    size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, bp = (bin_len + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jp + (bin ? 8 + bp : 0);
    uint32_t h[3] = {0x46546C67u, 2, (uint32_t)total};
    memcpy(out, h, 12);
    uint32_t c0[2] = {(uint32_t)jp, 0x4E4F534Au};
    memcpy(out + 12, c0, 8);
    memcpy(out + 20, json, jl);
    memset(out + 20 + jl, ' ', jp - jl);
    if (bin) {
        uint32_t c1[2] = {(uint32_t)bp, 0x004E4942u};
        memcpy(out + 20 + jp, c1, 8);
        memcpy(out + 28 + jp, bin, bin_len);
        memset(out + 28 + jp + bin_len, 0, bp - bin_len);
    }
    return total;
}

static const char *glb_json =
    "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":60}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":12},"
    "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
    "{\"bufferView\":1,\"componentType\":5123,\"normalized\":true,\"count\":3,\"type\":\"VEC2\"},"
    "{\"bufferView\":2,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC4\"}],"
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"COLOR_0\":2}}]}],"
    "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";

static size_t glb_bin(uint8_t *bin)
{
    float pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    uint16_t uv[6] = {0, 0, 65535, 0, 0, 32768};
    uint8_t col[12] = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0};
    memcpy(bin, pos, 36);
    memcpy(bin + 36, uv, 12);
    memcpy(bin + 48, col, 12);
    return 60;
}

static void test_glb_quantized(void **state)
{
    (void)state;
    uint8_t bin[64], glb[2048];
    size_t n = make_glb(glb, glb_json, bin, glb_bin(bin));
    test_write_file(tmp_path("q.glb"), glb, n);
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    /* from memory: same result as from the file below */
    rt_scene_init(&s);
    assert_int_equal(rt_gltf_load_memory(&s, glb, n, "in-memory.glb", NULL, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 1);
    rt_scene_free(&s);
    rt_scene_init(&s);
    assert_int_not_equal(rt_gltf_load_memory(&s, glb, 0, "in-memory.glb", NULL, &st, &err), RT_OK);
    assert_non_null(strstr(err.message, "in-memory.glb"));
    rt_scene_free(&s);
    assert_int_equal(load(tmp_path("q.glb"), &s, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 1);
    assert_float_equal(s.vertices.uv0[1].x, 1.0f, 0);
    assert_float_equal(s.vertices.uv0[2].y, 32768.0f / 65535.0f, 1e-7);
    assert_non_null(s.vertices.color);
    assert_float_equal(s.vertices.color[1].y, 1.0f, 0);
    assert_float_equal(s.vertices.color[1].w, 128.0f / 255.0f, 1e-7);
    assert_true(s.triangles.flags[0] & RT_TRI_COLOR);
    assert_true(s.triangles.flags[0] & RT_TRI_UV);
    rt_scene_free(&s);
}

/* ---------------------------------------------------------- broken files */

static const char *tri_rest =
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
    "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";

static void test_broken_glb(void **state)
{
    (void)state;
    uint8_t bin[64], glb[2048];
    size_t n = make_glb(glb, glb_json, bin, glb_bin(bin));
    /* truncated: the header's length is past the end */
    test_write_file(tmp_path("trunc.glb"), glb, n - 10);
    expect_fail("trunc.glb", RT_ERR_INVALID, "byte 8: header length");
    test_write_file(tmp_path("tiny.glb"), glb, 7);
    expect_fail("tiny.glb", RT_ERR_INVALID, "too short");
    /* wrong magic */
    uint8_t bad[2048];
    memcpy(bad, glb, n);
    memcpy(bad, "gLTF", 4);
    test_write_file(tmp_path("magic.glb"), bad, n);
    expect_fail("magic.glb", RT_ERR_INVALID, "magic");
    /* wrong version */
    memcpy(bad, glb, n);
    bad[4] = 1;
    test_write_file(tmp_path("v1.glb"), bad, n);
    expect_fail("v1.glb", RT_ERR_UNSUPPORTED, "version 1");
    /* chunk length past the end */
    memcpy(bad, glb, n);
    uint32_t huge = 999999;
    memcpy(bad + 12, &huge, 4);
    test_write_file(tmp_path("chunk.glb"), bad, n);
    expect_fail("chunk.glb", RT_ERR_INVALID, "byte 12: chunk length 999999 runs past the end of the file");
    /* BIN chunk shorter than the buffer's byteLength */
    size_t m = make_glb(bad, glb_json, bin, 40);
    test_write_file(tmp_path("shortbin.glb"), bad, m);
    expect_fail("shortbin.glb", RT_ERR_INVALID, "byteLength is 60 but only 40 bytes");
}

static void test_broken_json(void **state)
{
    (void)state;
    /* file, its text, the result and a part of the message */
    static const struct {
        const char *name, *text;
        rt_result code;
        const char *what;
    } bad[] = {
        {"json.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}", RT_ERR_PARSE, "byte "},
        {"json2.gltf", "{\"asset\":{\"version\":\"2.0\"}, nodes: []}", RT_ERR_PARSE, "byte 28"},
        {"json3.gltf", "{\"asset\":{\"version\":\"2.0\"}} {}", RT_ERR_PARSE, "after the top-level"},
        {"empty.gltf", "", RT_ERR_PARSE, "empty JSON"},
        {"noasset.gltf", "{\"nodes\":[]}", RT_ERR_INVALID, "asset is missing"},
        {"type.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":\"zero\"}]}", RT_ERR_INVALID,
         "nodes[0].mesh: expected an index"},
        {"dup.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{}],\"nodes\":[{},{}]}", RT_ERR_INVALID,
         "nodes appears twice"},
        {"req.gltf", "{\"asset\":{\"version\":\"2.0\"},\"extensionsRequired\":[\"KHR_texture_basisu\"]}",
         RT_ERR_UNSUPPORTED, "required extension KHR_texture_basisu"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        write_text(bad[i].name, bad[i].text);
        expect_fail(bad[i].name, bad[i].code, bad[i].what);
    }
}

/* Writes name: a glTF whose one buffer, of 36 bytes, is at uri, followed
 * by the members in `more` and then those in `rest`. */
static void write_gltf_at_uri(const char *name, const char *uri, const char *more, const char *rest)
{
    char text[2048];
    snprintf(text, sizeof text, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],%s%s}",
             uri, more, rest);
    write_text(name, text);
}

static void test_broken_data(void **state)
{
    (void)state;
    float pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    /* accessor past its bufferView */
    write_gltf("acc.gltf", pos, sizeof pos,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    expect_fail("acc.gltf", RT_ERR_INVALID, "accessors[0]: byteOffset 4 + 3 elements of 12 bytes");
    /* bufferView past its buffer */
    write_gltf("view.gltf", pos, sizeof pos,
               "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":8,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]");
    expect_fail("view.gltf", RT_ERR_INVALID, "bufferViews[0]: byteOffset 8 + byteLength 36 runs past buffer 0");
    /* index past the vertex count */
    uint8_t buf[40];
    memcpy(buf, pos, 36);
    buf[36] = 0, buf[37] = 1, buf[38] = 7, buf[39] = 0;
    write_gltf("idx.gltf", buf, 40,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":3}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
               "{\"bufferView\":1,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    expect_fail("idx.gltf", RT_ERR_INVALID, "element 2 is 7, past the vertex count 3");
    /* NaN positions */
    float nan_pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}};
    write_gltf("nan.gltf", nan_pos, sizeof nan_pos, tri_rest);
    expect_fail("nan.gltf", RT_ERR_INVALID, "accessors[0] (POSITION of meshes[0].primitives[0]): element 2 is not finite");
    /* missing .bin */
    write_gltf_at_uri("nobin.gltf", "nope.bin", "", tri_rest);
    expect_fail("nobin.gltf", RT_ERR_IO, "nope.bin");
    /* external .bin that works, then one that is too short */
    test_write_file(tmp_path("ok.bin"), pos, sizeof pos);
    write_gltf_at_uri("extbin.gltf", "ok.bin", "", tri_rest);
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load(tmp_path("extbin.gltf"), &s, &st, &err), RT_OK);
    assert_int_equal(s.triangles.count, 1);
    rt_scene_free(&s);
    test_write_file(tmp_path("short.bin"), pos, 20);
    write_gltf_at_uri("shortbin.gltf", "short.bin", "", tri_rest);
    expect_fail("shortbin.gltf", RT_ERR_INVALID, "byteLength is 36 but only 20 bytes");
    /* bad base64 */
    write_gltf_at_uri("b64.gltf",
                      "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA*AAAAAAAAAAAAA", "",
                      tri_rest);
    expect_fail("b64.gltf", RT_ERR_PARSE, "bad base64");
    /* unreadable image: not an image at all, and a missing file */
    test_write_file(tmp_path("garbage.png"), "this is not a png", 17);
    write_gltf_at_uri("img.gltf", "ok.bin", "\"images\":[{\"uri\":\"garbage.png\"}],\"textures\":[{\"source\":0}],",
                      tri_rest);
    expect_fail("img.gltf", RT_ERR_INVALID, "garbage.png");
    /* a missing image file is the missing-texture rule (rt/scene/texture.h),
     * not an error: the base colour gets the magenta checker, the normal
     * map is left out */
    write_gltf_at_uri("img2.gltf", "ok.bin",
                      "\"images\":[{\"uri\":\"missing.png\"}],\"textures\":[{\"source\":0},{\"source\":0}],"
                      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}},"
                      "\"normalTexture\":{\"index\":1}}],",
                      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
                      "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    {
        assert_int_equal(load(tmp_path("img2.gltf"), &s, &st, &err), RT_OK);
        assert_int_equal(s.material_count, 1);
        assert_int_equal(s.image_count, 0);
        uint32_t t = s.materials[0].base_color_tex.texture;
        assert_true(t < s.texture_count);
        assert_int_equal(s.textures[t].kind, RT_TEX_CHECKER);
        assert_float_equal(s.textures[t].color_a.x, 1.0, 0);
        assert_float_equal(s.textures[t].color_a.y, 0.0, 0);
        assert_float_equal(s.textures[t].color_a.z, 1.0, 0);
        assert_int_equal(s.materials[0].normal_tex.texture, RT_NONE);
        rt_scene_free(&s);
    }
    /* node cycle, and an out-of-range index */
    write_gltf("cycle.gltf", pos, sizeof pos,
               "\"nodes\":[{\"children\":[1]},{\"children\":[2]},{\"children\":[0]}]");
    expect_fail("cycle.gltf", RT_ERR_INVALID, "cycle");
    /* COLOR_0 as plain (not normalized) bytes breaks the attribute table */
    write_gltf("color.gltf", pos, sizeof pos,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
               "{\"bufferView\":0,\"componentType\":5121,\"count\":3,\"type\":\"VEC4\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"COLOR_0\":1}}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    expect_fail("color.gltf", RT_ERR_INVALID, "attributes.COLOR_0: accessor 1 has componentType 5121");
    /* a chain of 1025 nodes is fine (depth 1024), 1026 is over the limit */
    for (int len = 1025; len <= 1026; len++) {
        write_node_chain("deep.gltf", pos, sizeof pos, len);
        if (len == 1025) {
            assert_int_equal(load(tmp_path("deep.gltf"), &s, &st, &err), RT_OK);
            assert_int_equal(st.triangles, 1);
            assert_int_equal(st.nodes, 1025);
            rt_scene_free(&s);
        } else {
            expect_fail("deep.gltf", RT_ERR_LIMIT, "more than 1024 levels deep");
        }
    }
    /* 100 000 nodes (2.4 MB): the JSON tokenizer once scanned back over every
     * token at each '}', so this took minutes (30 000 nodes: 7.8 s); with
     * parent links it is a fraction of a second and still the depth error */
    write_node_chain("many-nodes.gltf", pos, sizeof pos, 100000);
    expect_fail("many-nodes.gltf", RT_ERR_LIMIT, "nodes[1025] is more than 1024 levels deep");
    write_gltf("range.gltf", pos, sizeof pos,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]");
    expect_fail("range.gltf", RT_ERR_INVALID, "accessors[0].bufferView 3 is out of range (the file has 1 bufferViews)");
    /* a lying count without a bufferView must not allocate gigabytes */
    write_gltf("zeros.gltf", pos, sizeof pos,
               "\"accessors\":[{\"componentType\":5126,\"count\":4000000000,\"type\":\"VEC3\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    expect_fail("zeros.gltf", RT_ERR_LIMIT, "over the limit");
    /* ... nor can instancing a zero accessor under the per-accessor cap */
    write_gltf("zeros2.gltf", pos, sizeof pos,
               "\"accessors\":[{\"componentType\":5126,\"count\":3000000,\"type\":\"VEC3\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
               "\"nodes\":[{\"mesh\":0},{\"mesh\":0}],\"scenes\":[{\"nodes\":[0,1]}]");
    expect_fail("zeros2.gltf", RT_ERR_LIMIT, "without a bufferView (instancing included)");
    /* a failed load leaves an existing scene untouched */
    rt_scene_init(&s);
    uint32_t m = rt_scene_add_material(&s, &(rt_material){.name = "keep"});
    assert_int_equal(m, 0);
    assert_int_not_equal(rt_gltf_load(&s, tmp_path("nan.gltf"), NULL, NULL, &err), RT_OK);
    assert_int_equal(s.material_count, 1);
    assert_int_equal(s.triangles.count, 0);
    rt_scene_free(&s);
}

/* Every prefix and many byte flips of a valid GLB fail cleanly or load (ASan checks the rest). */
static void test_mutations(void **state)
{
    (void)state;
    uint8_t bin[64], glb[2048], mut[2048];
    size_t n = make_glb(glb, glb_json, bin, glb_bin(bin));
    rt_log_level level = rt_log_get_level();
    rt_log_set_level(RT_LOG_QUIET);
    test_rng rng = {0x9E3779B97F4A7C15ull};
    int ok = 0;
    for (size_t len = 0; len < n; len += 7) {
        test_write_file(tmp_path("m.glb"), glb, len);
        rt_scene s;
        rt_error err;
        rt_scene_init(&s);
        assert_int_not_equal(rt_gltf_load(&s, tmp_path("m.glb"), NULL, NULL, &err), RT_OK);
        assert_true(strstr(err.message, "m.glb") != NULL);
        rt_scene_free(&s);
    }
    for (int it = 0; it < 3000; it++) {
        memcpy(mut, glb, n);
        int flips = 1 + (int)(test_rng_next(&rng) % 4);
        for (int k = 0; k < flips; k++)
            mut[test_rng_next(&rng) % n] = (uint8_t)test_rng_next(&rng);
        rt_scene s;
        rt_error err;
        rt_scene_init(&s);
        if (rt_gltf_load_memory(&s, mut, n, "mutant.glb", NULL, NULL, &err) == RT_OK)
            ok++;
        else
            assert_true(strstr(err.message, "mutant.glb") != NULL);
        rt_scene_free(&s);
    }
    rt_log_set_level(level);
    assert_true(ok > 0); /* flips in the BIN chunk still load */
}

static void test_base64_json_units(void **state)
{
    (void)state;
    uint8_t out[16];
    size_t n, bad;
    assert_int_equal(rt_base64_decode("TWFu", 4, out, &n, &bad), RT_OK);
    assert_int_equal(n, 3);
    assert_memory_equal(out, "Man", 3);
    assert_int_equal(rt_base64_decode("TWE=", 4, out, &n, &bad), RT_OK);
    assert_int_equal(n, 2);
    assert_int_equal(rt_base64_decode("TQ==", 4, out, &n, &bad), RT_OK);
    assert_int_equal(n, 1);
    assert_int_equal(rt_base64_decode("TW-u", 4, out, &n, &bad), RT_ERR_PARSE);
    assert_int_equal(bad, 2);
    assert_int_equal(rt_base64_decode("TWF", 3, out, &n, &bad), RT_ERR_PARSE);
    assert_int_equal(rt_base64_decode("T=Fu", 4, out, &n, &bad), RT_ERR_PARSE);
    assert_int_equal(rt_base64_decode("TR==", 4, out, &n, &bad), RT_ERR_PARSE); /* stray bits */
    rt_json j;
    rt_error err;
    const char *text = "{\"a\":[1,2.5e1,{\"b\":\"x\\u00e9\\n\"}],\"c\":true}";
    assert_int_equal(rt_json_parse(&j, text, strlen(text), "t", 0, &err), RT_OK);
    int a = rt_json_get(&j, 0, "a");
    assert_true(a > 0);
    assert_int_equal(j.tok[a].size, 3);
    double v;
    assert_true(rt_json_number(&j, a + 2, &v));
    assert_float_equal(v, 25.0, 0);
    int b = rt_json_get(&j, a + 3, "b");
    char s[16];
    assert_int_equal(rt_json_string(&j, b, s, sizeof s), 4);
    assert_string_equal(s, "x\xc3\xa9\n");
    bool t;
    assert_true(rt_json_bool(&j, rt_json_get(&j, 0, "c"), &t) && t);
    assert_int_equal(rt_json_skip(&j, 0), j.count);
    rt_json_free(&j);
}

/* rt_json_parse of text into a fresh rt_json: expects code and, on an
 * error, a message naming "t.json" and containing what. */
static void expect_json(const char *text, size_t len, rt_result code, const char *what)
{
    rt_json j;
    rt_error err;
    rt_result r = rt_json_parse(&j, text, len, "t.json", 0, &err);
    if (code == RT_OK) {
        if (r != RT_OK)
            fail_msg("%.40s...: %s", text, err.message);
        assert_int_equal(rt_json_skip(&j, 0), j.count);
        rt_json_free(&j);
        return;
    }
    test_expect_failure(r, &err, code, "t.json", what);
}

/* Nested arrays `depth` deep as the value of "a": {"a":[[...]]}. */
static char *nested_json(size_t depth, size_t *len)
{
    char *t = malloc(2 * depth + 16);
    size_t n = (size_t)sprintf(t, "{\"a\":");
    memset(t + n, '[', depth);
    n += depth;
    memset(t + n, ']', depth);
    n += depth;
    t[n++] = '}';
    t[n] = '\0';
    *len = n;
    return t;
}

/* Issue 25, class 3: the tokenizer keeps a stack of open containers, so
 * deep nesting is linear (jsmn's parent-link walk made a 600 KB file of
 * nested arrays take 104 s), and nesting over RT_JSON_MAX_DEPTH is refused
 * with the byte where it goes over, before tokens for the rest are made. */
static void test_json_nesting_and_grammar(void **state)
{
    (void)state;
    size_t len;
    char *t = nested_json(RT_JSON_MAX_DEPTH - 1, &len); /* + the top-level object */
    expect_json(t, len, RT_OK, NULL);
    free(t);
    t = nested_json(RT_JSON_MAX_DEPTH, &len);
    char want[64];
    snprintf(want, sizeof want, "t.json: byte %d: JSON nested deeper than %d", 5 + RT_JSON_MAX_DEPTH - 1,
             RT_JSON_MAX_DEPTH);
    expect_json(t, len, RT_ERR_LIMIT, want);
    free(t);
    /* 600 KB of nested arrays (104 s with jsmn): refused at the byte where
     * the cap is passed, before a token of the rest is made. Times are
     * measured by hand, not asserted here (the suite also runs under
     * sanitizers): docs/robustness.md has the figures. */
    t = nested_json(300000, &len);
    expect_json(t, len, RT_ERR_LIMIT, want);
    free(t);
    /* 2 MB of legal nesting, 255 deep, 4000 times over */
    size_t block = 2 * (RT_JSON_MAX_DEPTH - 1) + 1, copies = 4000;
    char *big = malloc(copies * block + 16);
    size_t n = (size_t)sprintf(big, "{\"a\":");
    for (size_t c = 0; c < copies; c++) {
        big[n++] = c ? ',' : '[';
        memset(big + n, '[', RT_JSON_MAX_DEPTH - 2);
        n += RT_JSON_MAX_DEPTH - 2;
        memset(big + n, ']', RT_JSON_MAX_DEPTH - 2);
        n += RT_JSON_MAX_DEPTH - 2;
    }
    big[n++] = ']';
    big[n++] = '}';
    expect_json(big, n, RT_OK, NULL);
    free(big);
    /* glTF extras 100 000 levels deep: the loader's error names the file and byte */
    t = nested_json(100000, &len);
    char *doc = malloc(len + 64);
    snprintf(doc, len + 64, "{\"asset\":{\"version\":\"2.0\"},\"extras\"%s", t + 4);
    write_text("deep-extras.gltf", doc);
    snprintf(want, sizeof want, "byte %d: JSON nested deeper than %d", 36 + RT_JSON_MAX_DEPTH - 1, RT_JSON_MAX_DEPTH);
    expect_fail("deep-extras.gltf", RT_ERR_LIMIT, want);
    free(doc);
    free(t);
    /* RFC 8259's grammar: what jsmn let through is refused with its byte */
    static const struct { const char *text, *what; } bad[] = {
        {"{\"a\":1 \"b\":2}", "byte 7: invalid JSON"},  /* no comma */
        {"{\"a\":[1,]}", "byte 8: invalid JSON"},         /* trailing comma */
        {"{\"a\":1,}", "byte 7: invalid JSON"},
        {"{\"a\"}", "byte 4: invalid JSON"},              /* no value */
        {"{\"a\":}", "byte 5: invalid JSON"},
        {"{1:2}", "byte 1: invalid JSON"},                /* key not a string */
        {"{\"a\":[1}", "byte 7: invalid JSON"},           /* mismatched bracket */
        {"{\"a\":\"\\x\"}", "byte 6: bad escape"},
        {"{\"a\":\"\\u12g4\"}", "byte 6: bad \\u escape"},
        {"{\"a\":\"open", "byte 5: JSON ends early"},
        {"{\"a\":[[1]", "JSON ends early"},
        {"{\"a\":@}", "byte 5: invalid JSON"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        expect_json(bad[i].text, strlen(bad[i].text), RT_ERR_PARSE, bad[i].what);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_base64_json_units),
        cmocka_unit_test(test_json_nesting_and_grammar),
        cmocka_unit_test(test_interleaved_u8),
        cmocka_unit_test(test_sparse),
        cmocka_unit_test(test_strip_fan),
        cmocka_unit_test(test_transforms),
        cmocka_unit_test(test_material_camera_light),
        cmocka_unit_test(test_glb_quantized),
        cmocka_unit_test(test_broken_glb),
        cmocka_unit_test(test_broken_json),
        cmocka_unit_test(test_broken_data),
        cmocka_unit_test(test_mutations),
        cmocka_unit_test(test_manifest_models),
        cmocka_unit_test(test_sample_features),
    };
    return cmocka_run_group_tests(tests, setup_tmp, teardown_tmp);
}
