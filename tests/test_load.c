/* test_load.c - loading as a whole: rt_read_file and the path helpers
 * (src/base/file.c), the dispatch of rt_load (src/io/load.c) by content and
 * by extension, what for_render adds, and the one undo of a failed load
 * (rt_scene_mark_of / rt_scene_rollback, src/scene/scene.c) through every
 * loader: each test loads a valid file, then a broken one into the same
 * scene, and checks that every table count, the vertex attribute arrays,
 * the camera and the settings are exactly as they were. The broken files
 * fail late, after the loader has appended images, textures, materials,
 * vertices or settings, so the rollback has something to undo. Run under
 * `make asan` this also shows that rolled-back images free their pixels.
 */
#include "test_util.h"

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <unistd.h>

#include "rt/base/file.h"
#include "rt/io/gltf.h"
#include "rt/io/load.h"
#include "rt/io/mesh_io.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/scene.h"

/* ------------------------------------------------------------ helpers */

static char tmp_dir[256];

static int setup_tmp(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "load") ? 0 : -1;
}

static int teardown_tmp(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

static const char *tpath(const char *name)
{
    static char buf[4][600];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmp_dir, name);
    return buf[k];
}

static void write_text(const char *name, const char *text) { test_write_file(tpath(name), text, strlen(text)); }

/* Copies a file of the repository into the temporary directory. */
static void copy_in(const char *from, const char *name)
{
    char *bytes;
    size_t size;
    rt_error err = {0};
    assert_int_equal(rt_read_file(from, 0, &bytes, &size, &err), RT_OK);
    test_write_file(tpath(name), bytes, size);
    free(bytes);
}

/* The scene as a mark sees it must equal `before`. (The environment and
 * camera are compared as bytes: both come from plain struct copies.) */
static void assert_unchanged(const rt_scene *s, const rt_scene_mark *before)
{
    rt_scene_mark now = rt_scene_mark_of(s);
    assert_int_equal(now.materials, before->materials);
    assert_int_equal(now.textures, before->textures);
    assert_int_equal(now.images, before->images);
    assert_int_equal(now.lights, before->lights);
    assert_int_equal(now.cameras, before->cameras);
    assert_int_equal(now.vertices, before->vertices);
    assert_int_equal(now.triangles, before->triangles);
    assert_int_equal(now.spheres, before->spheres);
    assert_int_equal(now.quads, before->quads);
    assert_int_equal(now.vertex_attrs, before->vertex_attrs);
    assert_int_equal(now.camera_set, before->camera_set);
    assert_memory_equal(&now.camera, &before->camera, sizeof now.camera);
    assert_memory_equal(&now.environment, &before->environment, sizeof now.environment);
}

static void expect_failure(rt_result r, const rt_error *err, const char *needle)
{
    if (r == RT_OK || !strstr(err->message, needle))
        fprintf(stderr, "expected a failure with '%s', got %d: '%s'\n", needle, r, err->message);
    assert_int_not_equal(r, RT_OK);
    assert_non_null(strstr(err->message, needle));
}

/* --------------------------------------------------------- files, paths */

static void test_read_file(void **state)
{
    (void)state;
    rt_error err = {0};
    char *bytes;
    size_t size;
    write_text("ten.txt", "0123456789");
    assert_int_equal(rt_read_file(tpath("ten.txt"), 0, &bytes, &size, &err), RT_OK);
    assert_int_equal(size, 10);
    assert_memory_equal(bytes, "0123456789", 11); /* with its NUL */
    free(bytes);
    assert_int_equal(rt_read_file(tpath("ten.txt"), 10, &bytes, &size, &err), RT_OK);
    free(bytes);
    /* over the caller's limit: refused before reading */
    assert_int_equal(rt_read_file(tpath("ten.txt"), 9, &bytes, &size, &err), RT_ERR_LIMIT);
    assert_null(bytes);
    assert_int_equal(size, 0);
    assert_non_null(strstr(err.message, "ten.txt: file is over the limit of 9 bytes"));
    write_text("empty.txt", "");
    assert_int_equal(rt_read_file(tpath("empty.txt"), 0, &bytes, &size, &err), RT_OK);
    assert_int_equal(size, 0);
    assert_int_equal(bytes[0], 0);
    free(bytes);
    assert_int_equal(rt_read_file(tpath("missing.txt"), 0, &bytes, &size, &err), RT_ERR_IO);
    assert_non_null(strstr(err.message, "missing.txt: cannot open: "));
    assert_int_equal(rt_read_file(tmp_dir, 0, &bytes, &size, &err), RT_ERR_IO);
    assert_non_null(strstr(err.message, ": is a directory"));
    assert_int_equal(rt_read_file("/dev/null", 0, &bytes, &size, &err), RT_ERR_IO); /* a device */
    assert_non_null(strstr(err.message, "/dev/null: not a regular file"));

    /* a pipe: read to its end, its limit checked as it goes */
    for (int limit = 0; limit < 2; limit++) {
        int fds[2];
        assert_int_equal(pipe(fds), 0);
        assert_int_equal(write(fds[1], "piped bytes", 11), 11);
        close(fds[1]);
        char path[64];
        snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
        rt_result r = rt_read_file(path, limit ? 5 : 0, &bytes, &size, &err);
        close(fds[0]);
        if (limit) {
            assert_int_equal(r, RT_ERR_LIMIT);
        } else {
            assert_int_equal(r, RT_OK);
            assert_int_equal(size, 11);
            assert_string_equal(bytes, "piped bytes");
            free(bytes);
        }
    }
}

static void test_paths(void **state)
{
    (void)state;
    assert_true(rt_path_has_ext("dir/Model.GLB", ".glb"));
    assert_true(rt_path_has_ext("a.tar.gz", ".gz"));
    assert_false(rt_path_has_ext("a.tar.gz", ".tar"));
    assert_false(rt_path_has_ext("x.glb/model", ".glb"));
    assert_false(rt_path_has_ext("mesh.objx", ".obj"));
    assert_false(rt_path_has_ext("noext", ".obj"));
    assert_string_equal(rt_path_ext("dir.d/mesh.obj"), ".obj");
    assert_string_equal(rt_path_ext("dir.d/mesh"), "");
    assert_string_equal(rt_path_basename("a/b/mesh.obj"), "mesh.obj");
    assert_string_equal(rt_path_basename("mesh.obj"), "mesh.obj");
    char out[16];
    assert_true(rt_path_dirname("a/b/mesh.obj", out, sizeof out));
    assert_string_equal(out, "a/b/");
    assert_true(rt_path_dirname("/mesh.obj", out, sizeof out));
    assert_string_equal(out, "/");
    assert_true(rt_path_dirname("mesh.obj", out, sizeof out));
    assert_string_equal(out, "");
    assert_false(rt_path_dirname("a-long-directory/m", out, sizeof out));
    assert_string_equal(out, "");
    assert_true(rt_path_join("a/b/", "t.png", out, sizeof out));
    assert_string_equal(out, "a/b/t.png");
    assert_true(rt_path_join("a/b", "t.png", out, sizeof out));
    assert_string_equal(out, "a/b/t.png");
    assert_true(rt_path_join("", "t.png", out, sizeof out));
    assert_string_equal(out, "t.png");
    assert_true(rt_path_join("a/b/", "/abs/t.png", out, sizeof out));
    assert_string_equal(out, "/abs/t.png");
    assert_true(rt_path_join("a/", "0123456789abc", out, sizeof out)); /* 15 bytes + NUL */
    assert_false(rt_path_join("a/", "0123456789abcd", out, sizeof out));
}

/* ------------------------------------------------------------- dispatch */

static const char ply_text[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
static const char off_text[] = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";

static void test_kind_of(void **state)
{
    (void)state;
    static const struct {
        const char *bytes, *name;
        rt_load_kind kind;
    } cases[] = {
        {"glTF\2\0\0\0", "model.txt", RT_LOAD_GLTF},   /* GLB magic over the name */
        {"{\"asset\": {}}", "mesh.obj", RT_LOAD_GLTF}, /* JSON */
        {"\xEF\xBB\xBF \n{}", "x", RT_LOAD_GLTF},      /* JSON after a byte order mark and blanks */
        {ply_text, "scene.txt", RT_LOAD_MESH},
        {"ply\r\nformat ascii 1.0\r\n", "x", RT_LOAD_MESH},
        {off_text, "scene.txt", RT_LOAD_MESH},
        {"COFF 3 1 0\n", "x", RT_LOAD_MESH},
        {"STCNOFF\n", "x", RT_LOAD_MESH},
        {"4OFF\n", "x", RT_LOAD_MESH}, /* the OFF reader then says it is not supported */
        {"OFFICE\n", "x.txt", RT_LOAD_SCENE},
        {"plywood 1\n", "x", RT_LOAD_SCENE},
        {"# a scene\n", "m.GLTF", RT_LOAD_GLTF}, /* no magic: the extension, in any case */
        {"# a scene\n", "m.glb", RT_LOAD_GLTF},
        {"v 0 0 0\n", "m.Obj", RT_LOAD_MESH},
        {"# a scene\n", "m.ply", RT_LOAD_MESH},
        {"# a scene\n", "m.off", RT_LOAD_MESH},
        {"# a scene\n", "scene.txt", RT_LOAD_SCENE},
        {"# a scene\n", "scene", RT_LOAD_SCENE},
        {"", "m.stl", RT_LOAD_UNKNOWN},   /* not parsed as scene text: refused, naming the formats */
        {"solid cube\n", "cube.STL", RT_LOAD_UNKNOWN},
        {"# a scene\n", "scene.rt", RT_LOAD_SCENE},
        {"# a scene\n", "scene.Scene", RT_LOAD_SCENE},
        {"v 0 0 0\n", "<stdin>", RT_LOAD_MESH}, /* a nameless input that starts like an OBJ */
        {"# exported\n\n  mtllib a.mtl\n", "<stdin>", RT_LOAD_MESH},
        {"vertices 3\n", "<stdin>", RT_LOAD_SCENE},
        {"v 0 0 0\n", "scene.txt", RT_LOAD_SCENE}, /* a named scene file stays scene text */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        rt_load_kind k = rt_load_kind_of(cases[i].bytes, strlen(cases[i].bytes) + (cases[i].bytes[0] == 'g' ? 4 : 0),
                                         cases[i].name);
        if (k != cases[i].kind)
            fprintf(stderr, "case %zu (%s): got %s\n", i, cases[i].name, rt_load_kind_name(k));
        assert_int_equal(k, cases[i].kind);
    }
    assert_int_equal(rt_load_kind_of(NULL, 0, "a.glb"), RT_LOAD_GLTF);
    assert_int_equal(rt_load_kind_of(NULL, 0, NULL), RT_LOAD_SCENE);
    assert_string_equal(rt_load_kind_name(RT_LOAD_MESH), "mesh");
    assert_true(rt_load_is_scene_name("a/b.d/scene"));
    assert_false(rt_load_is_scene_name("cube.stl"));
    assert_int_equal(rt_mesh_format_of(ply_text, strlen(ply_text), "m.off"), RT_MESH_PLY);
    assert_int_equal(rt_mesh_format_of(off_text, strlen(off_text), "m.ply"), RT_MESH_OFF);
    assert_int_equal(rt_mesh_format_of("v 0 0 0\n", 8, "m.OBJ"), RT_MESH_OBJ);
    assert_int_equal(rt_mesh_format_of("v 0 0 0\n", 8, "m.stl"), RT_MESH_UNKNOWN);
}

static void test_load_by_content(void **state)
{
    (void)state;
    rt_error err = {0};
    rt_load_info info;
    /* a PLY named .txt loads as a mesh, with the material "default" first */
    write_text("ply-named.txt", ply_text);
    rt_scene s;
    rt_scene_init(&s);
    assert_int_equal(rt_load(&s, NULL, tpath("ply-named.txt"), NULL, &info, &err), RT_OK);
    assert_int_equal(info.kind, RT_LOAD_MESH);
    assert_int_equal(info.meshes, 1);
    assert_int_equal(info.primitives, 1);
    assert_int_equal(s.triangles.count, 1);
    assert_int_equal(s.material_count, 1);
    assert_string_equal(s.materials[0].name, "default");
    assert_int_equal(s.triangles.material[0], 0);
    assert_int_equal(s.light_count, 0); /* not for_render */
    rt_scene_free(&s);

    /* the mesh dispatcher reads content first as well, and keeps its old
     * messages for names no reader takes */
    write_text("off-named.stl", off_text);
    rt_scene_init(&s);
    assert_int_equal(rt_mesh_load(&s, tpath("off-named.stl"), NULL, NULL, &err), RT_OK);
    assert_int_equal(s.triangles.count, 2);
    assert_int_equal(rt_mesh_load(&s, tpath("missing.stl"), NULL, NULL, &err), RT_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.message, "unknown mesh format '.stl'"));
    assert_int_equal(rt_mesh_load(&s, tpath("missing.obj"), NULL, NULL, &err), RT_ERR_IO);
    assert_non_null(strstr(err.message, "missing.obj: cannot open"));
    rt_scene_free(&s);

    /* a glTF named .dat, from memory, with its counts */
    char *bytes;
    size_t size;
    assert_int_equal(rt_read_file("assets/box.gltf", 0, &bytes, &size, &err), RT_OK);
    rt_scene_init(&s);
    assert_int_equal(rt_load_memory(&s, NULL, bytes, size, tpath("box.dat"), NULL, &info, &err), RT_OK);
    free(bytes);
    assert_int_equal(info.kind, RT_LOAD_GLTF);
    assert_int_equal(info.meshes, 1);
    assert_int_equal(info.primitives, 1);
    assert_int_equal(info.nodes, 2);
    assert_int_equal(s.camera_count, 1);
    assert_false(s.camera_set); /* not for_render */
    rt_scene_free(&s);

    /* an unknown extension is refused with the formats named; a nameless
     * OBJ loads from memory */
    write_text("cube.stl", "solid cube\nfacet normal 0 0 1\n");
    rt_scene_init(&s);
    expect_failure(rt_load(&s, NULL, tpath("cube.stl"), NULL, NULL, &err), &err, "cube.stl: unknown input format '.stl'");
    assert_non_null(strstr(err.message, ".gltf, .glb"));
    assert_null(strstr(err.message, "unknown keyword"));
    static const char obj[] = "# from a pipe\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_int_equal(rt_load_memory(&s, NULL, obj, sizeof obj - 1, "<stdin>", NULL, &info, &err), RT_OK);
    assert_int_equal(info.kind, RT_LOAD_MESH);
    assert_int_equal(s.triangles.count, 1);
    rt_scene_free(&s);

    /* the built-in scene */
    rt_scene_init(&s);
    assert_int_equal(rt_load(&s, NULL, NULL, NULL, &info, &err), RT_OK);
    assert_int_equal(info.kind, RT_LOAD_SCENE);
    assert_int_equal(info.meshes + info.primitives + info.nodes, 0);
    assert_int_equal(s.spheres.count, 1);
    assert_int_equal(s.quads.count, 11);
    assert_true(info.load_ms >= 0.0);
    rt_scene_free(&s);

    /* a missing file: the read error, and the kind its name suggests */
    rt_scene_init(&s);
    assert_int_equal(rt_load(&s, NULL, tpath("missing.glb"), NULL, &info, &err), RT_ERR_IO);
    assert_int_equal(info.kind, RT_LOAD_GLTF);
    assert_non_null(strstr(err.message, "missing.glb: cannot open: "));
    rt_scene_free(&s);
}

static void test_for_render(void **state)
{
    (void)state;
    rt_error err = {0};
    rt_load_options opt = {.for_render = true};
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    write_text("tri.ply", ply_text);
    assert_int_equal(rt_load(&s, &set, tpath("tri.ply"), &opt, NULL, &err), RT_OK);
    assert_int_equal(set.samples, 64);
    assert_int_equal(set.integrator, RT_INTEGRATOR_PATH);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.lights[0].kind, RT_LIGHT_DIRECTIONAL);
    assert_false(s.camera_set); /* framed by the driver later */
    rt_scene_free(&s);

    rt_scene_init(&s);

    rt_settings_default(&set);
    assert_int_equal(rt_load(&s, &set, "assets/box.gltf", &opt, NULL, &err), RT_OK);
    assert_true(s.camera_set);
    assert_memory_equal(&s.camera, &s.cameras[0], sizeof s.camera);
    assert_int_equal(s.light_count, 1);
    rt_scene_free(&s);

    /* a scene file keeps its own lights and samples */
    rt_scene_init(&s);
    rt_settings_default(&set);
    assert_int_equal(rt_load(&s, &set, "scenes/cornell.txt", &opt, NULL, &err), RT_OK);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.lights[0].kind, RT_LIGHT_AREA);
    rt_scene_free(&s);
}

/* ------------------------------------------------------------- rollback */

static void test_rollback_unit(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_scene_init(&s);
    rt_settings_default(&set);
    rt_material m;
    rt_material_default(&m, "kept");
    assert_int_not_equal(rt_scene_add_material(&s, &m), RT_NONE);
    assert_int_not_equal(rt_scene_add_vertices(&s, 3), RT_NONE);
    assert_true(rt_scene_enable_attr(&s, RT_ATTR_COLOR));
    rt_scene_mark mark = rt_scene_mark_of(&s);
    assert_int_equal(mark.vertex_attrs, RT_ATTR_COLOR);

    /* append to every table, enable the other attributes, change the view */
    assert_int_not_equal(rt_scene_add_material(&s, &m), RT_NONE);
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = img.height = 1;
    img.rgba8 = calloc(4, 1);
    snprintf(img.name, sizeof img.name, "pixels");
    assert_int_not_equal(rt_scene_add_image(&s, &img), RT_NONE); /* freed by the rollback (asan checks) */
    rt_texture tex;
    memset(&tex, 0, sizeof tex);
    assert_int_not_equal(rt_scene_add_texture(&s, &tex), RT_NONE);
    rt_light l;
    memset(&l, 0, sizeof l);
    assert_int_not_equal(rt_scene_add_light(&s, &l), RT_NONE);
    assert_int_not_equal(rt_scene_add_camera(&s, &s.camera), RT_NONE);
    assert_true(rt_scene_enable_attr(&s, RT_ATTR_UV1 | RT_ATTR_TANGENT));
    uint32_t v = rt_scene_add_vertices(&s, 3);
    assert_int_not_equal(rt_scene_add_triangle(&s, v, v + 1, v + 2, 0, 0), RT_NONE);
    assert_int_not_equal(rt_scene_add_sphere(&s, rt_v3(0, 0, 0), 1, 0), RT_NONE);
    assert_int_not_equal(rt_scene_add_quad(&s, rt_v3(0, 0, 0), rt_v3(1, 0, 0), rt_v3(0, 1, 0), 0), RT_NONE);
    set.samples = 77;
    snprintf(set.output, sizeof set.output, "changed.png");
    s.camera.vfov_deg = 10;
    s.camera_set = true;

    rt_scene_rollback(&s, &mark);
    assert_unchanged(&s, &mark);
    assert_null(s.vertices.uv1);
    assert_null(s.vertices.tangent);
    assert_non_null(s.vertices.color);
    assert_string_equal(s.materials[0].name, "kept");
    /* the tables still work after a rollback */
    assert_int_equal(rt_scene_add_vertices(&s, 2), 3);
    assert_int_equal(rt_scene_add_sphere(&s, rt_v3(0, 0, 0), 1, 0), 0);
    rt_scene_free(&s);
}

/* A scene with something in every table, from scenes/textures.txt (images,
 * textures, materials, a mesh, a glTF model, lights, quads). */
static void load_valid_scene(rt_scene *s)
{
    rt_error err = {0};
    rt_scene_init(s);
    rt_result r = rt_load(s, NULL, "scenes/textures.txt", NULL, NULL, &err);
    if (r != RT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(r, RT_OK);
    assert_true(s->image_count > 0 && s->triangles.count > 0 && s->quads.count > 0 && s->light_count > 0);
}

static void test_rollback_scene_text(void **state)
{
    (void)state;
    char cwd[PATH_MAX];
    assert_non_null(getcwd(cwd, sizeof cwd));
    copy_in("assets/tiles_color.png", "tiles.png");
    char text[4 * PATH_MAX];
    /* every statement appends or sets something; the last one is broken */
    snprintf(text, sizeof text,
             "resolution 64 32\nsamples 99\nbackground 1 0 0\noutput other.png\n"
             "camera position 0 0 9 look_at 0 0 0 up 0 1 0 fov 30\n"
             "texture t image tiles.png\n"
             "material red color 1 0 0 texture t\n"
             "quad 0 0 0  1 0 0  0 1 0 red\n"
             "sphere 0 0 0 1 red\n"
             "triangle 0 0 0  1 0 0  0 1 0 red\n"
             "light point 0 5 0 1 1 1 10\n"
             "light area 0 3 0  1 0 0  0 0 1  1 1 1 5\n"
             "mesh %s/assets/torus.obj red\n"
             "model %s/assets/box.gltf\n"
             "sphere 0 0 0 oops red\n",
             cwd, cwd);
    write_text("broken.txt", text);
    rt_scene s;
    load_valid_scene(&s);
    rt_scene_mark before = rt_scene_mark_of(&s);
    rt_settings set, set_before; /* the settings the failed loads were given stay as they were too */
    rt_settings_default(&set);
    set.samples = 7;
    set_before = set;
    rt_error err = {0};
    expect_failure(rt_scene_parse_file(&s, &set, tpath("broken.txt"), &err), &err, "broken.txt:15:");
    assert_unchanged(&s, &before);
    assert_memory_equal(&set, &set_before, sizeof set);
    /* also through rt_load, and when only the end of the file can tell */
    expect_failure(rt_load(&s, &set, tpath("broken.txt"), NULL, NULL, &err), &err, "broken.txt:15:");
    assert_unchanged(&s, &before);
    assert_memory_equal(&set, &set_before, sizeof set);
    write_text("late.txt", "samples 5\nmaterial m\nsphere 0 0 0 1 m\ncamera gltf 7\n");
    expect_failure(rt_load(&s, &set, tpath("late.txt"), NULL, NULL, &err), &err, "camera gltf 7");
    assert_unchanged(&s, &before);
    assert_memory_equal(&set, &set_before, sizeof set);
    rt_scene_free(&s);
}

/* A glTF with an image texture, vertex colours and a POSITION element that
 * is not finite: it fails while copying vertices, after its image, texture
 * and material are in the scene and the colour array is enabled. */
static void write_gltf(const char *name, const char *image, bool broken)
{
    float bin[21] = {0, 0, 0, 1, 0, 0, 0, 1, 0}; /* positions, then three white RGBA colours */
    for (int i = 9; i < 21; i++)
        bin[i] = 1.0f;
    if (broken)
        bin[4] = NAN;
    char bin_name[64];
    snprintf(bin_name, sizeof bin_name, "%s.bin", name);
    test_write_file(tpath(bin_name), bin, sizeof bin);
    char json[2048];
    snprintf(json, sizeof json,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n"
             " \"nodes\": [{\"mesh\": 0}],\n"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"COLOR_0\": 1}, \"material\": 0}]}],\n"
             " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}],\n"
             " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"%s\"}],\n"
             " \"buffers\": [{\"uri\": \"%s\", \"byteLength\": 84}],\n"
             " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 48}],\n"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\",\n"
             "                \"min\": [0, 0, 0], \"max\": [1, 1, 0]},\n"
             "               {\"bufferView\": 1, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC4\"}]}\n",
             image, bin_name);
    write_text(name, json);
}

static void test_rollback_gltf(void **state)
{
    (void)state;
    copy_in("assets/uvgrid.png", "grid.png");
    copy_in("assets/bumps.png", "bumps.png");
    write_gltf("good.gltf", "grid.png", false);
    write_gltf("bad.gltf", "bumps.png", true);
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    assert_int_equal(rt_gltf_load(&s, tpath("good.gltf"), NULL, NULL, &err), RT_OK);
    assert_int_equal(s.image_count, 1);
    rt_scene_mark before = rt_scene_mark_of(&s);
    expect_failure(rt_gltf_load(&s, tpath("bad.gltf"), NULL, NULL, &err), &err, "is not finite");
    assert_unchanged(&s, &before);
    rt_settings set, set_before; /* for_render's model settings are rolled back too */
    rt_settings_default(&set);
    set_before = set;
    expect_failure(rt_load(&s, &set, tpath("bad.gltf"), &(rt_load_options){.for_render = true}, NULL, &err), &err,
                   "is not finite");
    assert_unchanged(&s, &before);
    assert_memory_equal(&set, &set_before, sizeof set);
    rt_scene_free(&s);

    /* into a scene that had no colours: the array the failed load enabled goes too */
    load_valid_scene(&s);
    before = rt_scene_mark_of(&s);
    assert_int_equal(before.vertex_attrs & RT_ATTR_COLOR, 0);
    expect_failure(rt_load(&s, NULL, tpath("bad.gltf"), NULL, NULL, &err), &err, "is not finite");
    assert_unchanged(&s, &before);
    assert_null(s.vertices.color);
    rt_scene_free(&s);
}

static void test_rollback_obj(void **state)
{
    (void)state;
    copy_in("assets/uvgrid.png", "grid.png");
    copy_in("assets/brick_color.png", "brick.png");
    write_text("good.mtl", "newmtl a\nKd 1 0 0\nmap_Kd grid.png\nnewmtl b\nKd 0 1 0\n");
    write_text("good.obj", "mtllib good.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                           "usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 2 4 3\n");
    write_text("bad.mtl", "newmtl c\nKd 0 0 1\nmap_Kd brick.png\n");
    write_text("bad.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl c\nf 1 2 3\n");
    rt_scene s;
    load_valid_scene(&s);
    rt_error err = {0};
    rt_mesh_load_stats st;
    assert_int_equal(rt_mesh_load(&s, tpath("good.obj"), NULL, &st, &err), RT_OK);
    assert_int_equal(st.materials, 2);
    assert_int_equal(st.triangles, 2);
    rt_scene_mark before = rt_scene_mark_of(&s);
    /* the MTL material, its texture and its image are in the scene when the
     * singular transform fails the commit */
    rt_mat4 flat = rt_mat4_scale(rt_v3(1, 0, 1));
    rt_mesh_options opt = {.transform = &flat};
    expect_failure(rt_mesh_load(&s, tpath("bad.obj"), &opt, &st, &err), &err, "singular");
    assert_unchanged(&s, &before);
    /* a parse error late in the file */
    write_text("bad2.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl c\nf 1 2 3\nf 1 2 9\n");
    expect_failure(rt_mesh_load(&s, tpath("bad2.obj"), NULL, &st, &err), &err, "bad2.obj:7");
    assert_unchanged(&s, &before);
    /* through rt_load, whose "default" material goes too */
    expect_failure(rt_load(&s, NULL, tpath("bad2.obj"), NULL, NULL, &err), &err, "bad2.obj:7");
    assert_unchanged(&s, &before);
    rt_scene_free(&s);
}

static void test_rollback_ply_off(void **state)
{
    (void)state;
    write_text("good.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n");
    write_text("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 7\n");
    write_text("good.off", off_text);
    write_text("bad.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 5\n");
    rt_scene s;
    load_valid_scene(&s);
    rt_error err = {0};
    assert_int_equal(rt_mesh_load(&s, tpath("good.ply"), NULL, NULL, &err), RT_OK);
    assert_int_equal(rt_mesh_load(&s, tpath("good.off"), NULL, NULL, &err), RT_OK);
    rt_scene_mark before = rt_scene_mark_of(&s);
    expect_failure(rt_mesh_load(&s, tpath("bad.ply"), NULL, NULL, &err), &err, "bad.ply");
    assert_unchanged(&s, &before);
    expect_failure(rt_mesh_load(&s, tpath("bad.off"), &(rt_mesh_options){.material = RT_NONE}, NULL, &err), &err,
                   "bad.off:7");
    assert_unchanged(&s, &before);
    /* a transform that overflows: the commit fails after the checks */
    rt_mat4 huge = rt_mat4_translate(rt_v3(3e38f, 0, 0));
    write_text("big.off", "OFF\n3 1 0\n0 0 0\n3e38 0 0\n0 1 0\n3 0 1 2\n");
    expect_failure(rt_mesh_load(&s, tpath("big.off"), &(rt_mesh_options){.transform = &huge, .material = RT_NONE},
                                NULL, &err),
                   &err, "not finite after the mesh transform");
    assert_unchanged(&s, &before);
    for (int k = 0; k < 2; k++) {
        rt_load_options opt = {.for_render = k == 1};
        expect_failure(rt_load(&s, NULL, tpath("bad.ply"), &opt, NULL, &err), &err, "bad.ply");
        assert_unchanged(&s, &before);
        expect_failure(rt_load(&s, NULL, tpath("bad.off"), &opt, NULL, &err), &err, "bad.off:7");
        assert_unchanged(&s, &before);
    }
    rt_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_read_file),          cmocka_unit_test(test_paths),
        cmocka_unit_test(test_kind_of),            cmocka_unit_test(test_load_by_content),
        cmocka_unit_test(test_for_render),         cmocka_unit_test(test_rollback_unit),
        cmocka_unit_test(test_rollback_scene_text), cmocka_unit_test(test_rollback_gltf),
        cmocka_unit_test(test_rollback_obj),       cmocka_unit_test(test_rollback_ply_off),
    };
    return cmocka_run_group_tests(tests, setup_tmp, teardown_tmp);
}
