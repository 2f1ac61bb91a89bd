/* test_scene_parse.c - the scene text format (src/scene_parse.c).
 *
 * Every error kind is checked for its exact "file:line:col" and a message
 * substring; the built-in default scene and every file in scenes/ parse with
 * the expected table counts; values land in the right fields; comments,
 * continuations, quotes and CRLF work; a mesh's translate/rotate/scale give
 * the composed transform; and a few thousand mutated scenes parse or fail
 * without crashing or leaking (run under `make asan`).
 */
#include "test_util.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>

#include "rt/base/log.h"
#include "rt/io/scene_parse.h"
#include "rt/io/environment_image.h"
#include "rt/render/settings.h"

static char tmp_dir[64]; /* this run's scratch directory (test_make_dir) */

static int setup(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "scene_parse") ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

/* tmp_dir/rel, in one of 8 static buffers (the last 8 stay valid). */
static const char *tmp_path(const char *rel)
{
    static char buf[8][128];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmp_dir, rel);
    return buf[k];
}

/* Parses text as "t.txt" (relative paths resolve against tmp_dir), its
 * settings into *set (defaults first; NULL: checked, not kept). */
static rt_result parse_settings(rt_scene *s, rt_settings *set, const char *text, rt_error *err)
{
    rt_scene_init(s);
    if (set)
        rt_settings_default(set);
    memset(err, 0, sizeof *err);
    return rt_scene_parse_string(s, set, text, strlen(text), "t.txt", tmp_dir, err);
}

static rt_result parse(rt_scene *s, const char *text, rt_error *err)
{
    return parse_settings(s, NULL, text, err);
}

/* Parses text that must fail with `code`, a message starting with
 * "t.txt:LINE:COL: " and containing `part`; a failure names `origin` and
 * `line` (the test's line, or the table and row). */
#define expect_error(text, code, where, part) expect_error_at(text, code, where, part, "test line", __LINE__)
static void expect_error_at(const char *text, rt_result code, const char *where, const char *part, const char *origin,
                            int line)
{
    rt_scene s;
    rt_error err;
    rt_result r = parse(&s, text, &err);
    char prefix[64];
    snprintf(prefix, sizeof prefix, "t.txt:%s: ", where);
    if (r != code || strncmp(err.message, prefix, strlen(prefix)) != 0 || !strstr(err.message, part)) {
        print_error("%s %d: for %s\n  expected code %d, '%s...%s'\n  got      code %d, '%s'\n", origin, line, text,
                    code, prefix, part, r, err.message);
        rt_scene_free(&s);
        fail();
    }
    rt_scene_free(&s);
}

/* A scene text that must fail: the code, "LINE:COL" and a part of the
 * message (expect_error), one row of a table of such cases. */
typedef struct error_case {
    const char *text;
    rt_result code;
    const char *where, *part;
} error_case;

/* Every row of a table of error cases fails as it says; a failure names the
 * table and the row. */
#define expect_errors(cases) expect_errors_in(cases, sizeof cases / sizeof cases[0], #cases)
static void expect_errors_in(const error_case *cases, size_t n, const char *table)
{
    for (size_t i = 0; i < n; i++)
        expect_error_at(cases[i].text, cases[i].code, cases[i].where, cases[i].part, table, (int)i);
}

static void expect_ok_settings(const char *text, rt_scene *s, rt_settings *set)
{
    rt_error err;
    rt_result r = parse_settings(s, set, text, &err);
    if (r != RT_OK) {
        print_error("unexpected error %d: %s\n", r, err.message);
        rt_scene_free(s);
        fail();
    }
}

static void expect_ok(const char *text, rt_scene *s)
{
    expect_ok_settings(text, s, NULL);
}

/* A parse that must succeed: its message is shown when it does not. */
static void assert_parsed(rt_result r, const rt_error *err)
{
    if (r != RT_OK)
        print_error("%s\n", err->message);
    assert_int_equal(r, RT_OK);
}

static void assert_vec3(rt_vec3 v, float x, float y, float z)
{
    assert_float_equal(v.x, x, 1e-5);
    assert_float_equal(v.y, y, 1e-5);
    assert_float_equal(v.z, z, 1e-5);
}

/* ------------------------------------------------------------ scenes */

/* docs/scene-format.md, whole, in a static buffer (one at a time). */
static char *read_scene_format_doc(void)
{
    FILE *f = fopen("docs/scene-format.md", "rb");
    assert_non_null(f);
    static char doc[1 << 17];
    size_t n = fread(doc, 1, sizeof doc - 1, f);
    fclose(f);
    doc[n] = '\0';
    return doc;
}

/* The section of docs/scene-format.md that starts at `heading`, up to the
 * next "## " heading (read_scene_format_doc's buffer, cut there). */
static const char *scene_format_doc_section(const char *heading)
{
    char *sec = strstr(read_scene_format_doc(), heading);
    assert_non_null(sec);
    char *end = strstr(sec + 1, "\n## ");
    if (end)
        *end = '\0';
    return sec;
}


static void check_cornell(const rt_scene *s, const rt_settings *set)
{
    assert_int_equal(s->material_count, 4); /* white, red, green, the area light's */
    assert_int_equal(s->quads.count, 11);   /* 5 walls, 5 box faces, the light */
    assert_int_equal(s->spheres.count, 1);
    assert_int_equal(s->triangles.count, 0);
    assert_int_equal(s->light_count, 1);
    assert_true(s->camera_set);
    assert_int_equal(set->width, 512);
    assert_int_equal(set->height, 512);
    assert_int_equal(set->integrator, RT_INTEGRATOR_DIRECT);
    const rt_light *l = &s->lights[0];
    assert_int_equal(l->kind, RT_LIGHT_AREA);
    assert_int_equal(l->quad, 10);
    /* the light faces down, into the box */
    rt_vec3 n = rt_cross(l->edge_u, l->edge_v);
    assert_true(n.y < 0 && n.x == 0 && n.z == 0);
    /* every wall faces into the box: its normal points at the box centre */
    rt_vec3 centre = rt_v3(0, 1, 0);
    for (size_t i = 0; i < 5; i++) {
        const rt_quads *q = &s->quads;
        rt_vec3 p = rt_v3(q->px[i], q->py[i], q->pz[i]);
        rt_vec3 qn = rt_cross(rt_v3(q->ux[i], q->uy[i], q->uz[i]), rt_v3(q->vx[i], q->vy[i], q->vz[i]));
        assert_true(rt_dot(qn, rt_sub(centre, p)) > 0);
    }
    /* red is on the left (-x) as seen by the camera, green on the right */
    uint32_t red = rt_scene_find_material(s, "red"), green = rt_scene_find_material(s, "green");
    assert_int_equal(s->quads.material[3], red);
    assert_int_equal(s->quads.material[4], green);
    assert_true(s->quads.px[3] < 0 && s->quads.px[4] > 0);
    rt_vec3 fwd = rt_sub(s->camera.look_at, s->camera.position);
    rt_vec3 right = rt_cross(fwd, s->camera.up);
    assert_true(right.x > 0);
}

static void test_default_scene(void **state)
{
    (void)state;
    rt_scene s;
    rt_error err;
    rt_scene_init(&s);
    rt_settings set;
    rt_settings_default(&set);
    rt_result r = rt_scene_parse_string(&s, &set, rt_default_scene_text, strlen(rt_default_scene_text), "<default>", NULL,
                                        &err);
    assert_parsed(r, &err);
    check_cornell(&s, &set);
    assert_string_equal(set.output, ""); /* the driver writes out.png */
    rt_scene_free(&s);
}

/* scenes/cornell.txt is the default scene plus its output name. */
static void test_cornell_file_matches_default(void **state)
{
    (void)state;
    rt_scene a, b;
    rt_error err;
    rt_scene_init(&a);
    rt_scene_init(&b);
    rt_settings seta, setb;
    rt_settings_default(&seta);
    rt_settings_default(&setb);
    assert_int_equal(rt_scene_parse_string(&a, &seta, rt_default_scene_text, strlen(rt_default_scene_text), "<default>",
                                           NULL, &err),
                     RT_OK);
    rt_result r = rt_scene_parse_file(&b, &setb, "scenes/cornell.txt", &err);
    assert_parsed(r, &err);
    check_cornell(&b, &setb);
    assert_string_equal(setb.output, "cornell.png");
    assert_int_equal(a.quads.count, b.quads.count);
    for (size_t i = 0; i < a.quads.count; i++) {
        assert_float_equal(a.quads.px[i], b.quads.px[i], 0);
        assert_float_equal(a.quads.uz[i], b.quads.uz[i], 0);
        assert_float_equal(a.quads.vy[i], b.quads.vy[i], 0);
        assert_int_equal(a.quads.material[i], b.quads.material[i]);
    }
    assert_float_equal(a.spheres.radius[0], b.spheres.radius[0], 0);
    assert_memory_equal(&a.camera, &b.camera, sizeof a.camera);
    assert_memory_equal(&a.lights[0], &b.lights[0], sizeof a.lights[0]);
    for (size_t i = 0; i < a.material_count; i++)
        assert_memory_equal(&a.materials[i], &b.materials[i], sizeof a.materials[i]);
    memset(setb.output, 0, sizeof setb.output);
    assert_memory_equal(&seta, &setb, sizeof seta);
    rt_scene_free(&a);
    rt_scene_free(&b);
}

/* Every scene file shipped in scenes/ parses (whoever wrote it), each with
 * something in it; a loader that says RT_ERR_UNSUPPORTED fails like any
 * other error. */
static void test_all_scene_files(void **state)
{
    (void)state;
    DIR *d = opendir("scenes");
    assert_non_null(d);
    struct dirent *e;
    int parsed = 0;
    while ((e = readdir(d)) != NULL) {
        size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 4, ".txt") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "scenes/%s", e->d_name);
        rt_scene s;
        rt_error err;
        rt_scene_init(&s);
        rt_result r = rt_scene_parse_file(&s, NULL, path, &err);
        if (r != RT_OK)
            fail_msg("%s: %s", path, err.message);
        if (rt_scene_prim_count(&s) == 0)
            fail_msg("%s: no primitives", path);
        parsed++;
        rt_scene_free(&s);
    }
    closedir(d);
    assert_true(parsed >= 10); /* scenes/ holds 11: the folder was read */
}

static void test_spheres_scene(void **state)
{
    (void)state;
    rt_scene s;
    rt_error err;
    rt_scene_init(&s);
    rt_result r = rt_scene_parse_file(&s, NULL, "scenes/spheres.txt", &err);
    assert_parsed(r, &err);
    assert_int_equal(s.spheres.count, 5);
    assert_int_equal(s.quads.count, 1);
    assert_int_equal(s.light_count, 2);
    assert_int_equal(s.lights[0].kind, RT_LIGHT_POINT);
    assert_int_equal(s.lights[1].kind, RT_LIGHT_DIRECTIONAL);
    assert_int_equal(s.texture_count, 1);
    assert_int_equal(s.textures[0].kind, RT_TEX_CHECKER);
    uint32_t floor = rt_scene_find_material(&s, "floor");
    assert_int_not_equal(floor, RT_NONE);
    assert_int_equal(s.materials[floor].base_color_tex.texture, 0);
    rt_scene_free(&s);
}

/* textures.txt loads an image twice (one decode), an OBJ and a glTF model. */
static void test_textures_scene(void **state)
{
    (void)state;
    rt_scene s;
    rt_error err;
    rt_scene_init(&s);
    rt_result r = rt_scene_parse_file(&s, NULL, "scenes/textures.txt", &err);
    assert_parsed(r, &err);
    assert_int_equal(s.image_count, 2);     /* uvgrid.png once, bumps.png */
    assert_int_equal(s.camera_count, 1);    /* box.gltf's camera, not selected */
    assert_vec3(s.camera.position, 0, 2.4f, 6);
    assert_int_equal(s.light_count, 2);
    assert_int_equal(s.quads.count, 3);     /* floor, wall, the area light */
    /* torus 24 x 12 quads = 576 triangles, the glTF cube 12, one triangle */
    assert_int_equal(s.triangles.count, 576 + 12 + 1);
    uint32_t brass = rt_scene_find_material(&s, "brass");
    assert_int_not_equal(brass, RT_NONE);
    assert_int_not_equal(s.materials[brass].normal_tex.texture, RT_NONE);
    rt_scene_free(&s);
}

/* The complete example in docs/scene-format.md parses as written. */
static void test_docs_example(void **state)
{
    (void)state;
    const char *sec = strstr(read_scene_format_doc(), "## 9. A complete example");
    assert_non_null(sec);
    const char *start = strstr(sec, "```\n");
    assert_non_null(start);
    start += 4;
    const char *end = strstr(start, "```");
    assert_non_null(end);
    rt_scene s;
    rt_error err;
    rt_scene_init(&s);
    rt_settings set;
    rt_settings_default(&set);
    rt_result r = rt_scene_parse_string(&s, &set, start, (size_t)(end - start), "docs/scene-format.md#example", "scenes",
                                        &err);
    assert_parsed(r, &err);
    assert_int_equal(s.light_count, 4);
    assert_int_equal(s.spheres.count, 2);
    assert_int_equal(set.integrator, RT_INTEGRATOR_WHITTED);
    assert_string_equal(set.output, "example.png");
    assert_true(s.triangles.count > 500);
    rt_scene_free(&s);
}

/* `camera gltf N` takes a camera from the models, wherever the model line is. */
static void test_camera_gltf(void **state)
{
    (void)state;
    rt_scene s;
    rt_error err;
    rt_scene_init(&s);
    const char *text = "camera gltf 0\nmodel ../assets/box.gltf\n";
    rt_result r = rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", "scenes", &err);
    assert_parsed(r, &err);
    assert_int_equal(s.camera_count, 1);
    assert_true(s.camera_set);
    assert_memory_equal(&s.camera, &s.cameras[0], sizeof s.camera);
    assert_vec3(s.camera.position, 1.2f, 1.4f, 3.2f); /* the node's translation (tools/gen_assets.py) */
    rt_scene_free(&s);

    rt_scene_init(&s);
    text = "model ../assets/box.gltf\ncamera gltf 1\n";
    assert_int_equal(rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", "scenes", &err), RT_ERR_INVALID);
    assert_string_equal(err.message, "t.txt:2:13: camera gltf 1: the loaded models have 1 camera");
    rt_scene_free(&s);

    /* a model's transform moves its triangles: the unit cube, scaled 2 and moved up 5 */
    rt_scene_init(&s);
    text = "model ../assets/box.gltf translate 0 5 0 scale 2\n";
    assert_int_equal(rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", "scenes", &err), RT_OK);
    rt_box b = rt_scene_bounds(&s);
    assert_float_equal(b.lo.y, 4, 1e-4);
    assert_float_equal(b.hi.y, 6, 1e-4);
    rt_scene_free(&s);
}

/* ------------------------------------------------------------ values */

static void test_settings_values(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    expect_ok_settings("resolution 640 480\n"
              "samples 64\n"
              "integrator whitted\n"
              "max_bounce 7\n"
              "diffuse_bounces 2\n"
              "diffuse_rays 32\n"
              "shadow_samples 9\n"
              "seed 4294967295\n"
              "background 0.1 0.2 0.3\n"
              "ambient_light 0.05 0.04 0.03\n"
              "exposure 1.5\n"
              "clamp 10\n"
              "ray_offset 0.001\n"
              "output \"my render.png\"\n",
              &s, &set);
    const rt_settings *st = &set;
    assert_int_equal(st->width, 640);
    assert_int_equal(st->height, 480);
    assert_int_equal(st->samples, 64);
    assert_int_equal(st->integrator, RT_INTEGRATOR_WHITTED);
    assert_int_equal(st->max_bounce, 7);
    assert_int_equal(st->diffuse_bounces, 2);
    assert_int_equal(st->diffuse_rays, 32);
    assert_int_equal(st->shadow_samples, 9);
    assert_int_equal(st->seed, 4294967295u);
    assert_vec3(s.environment.background, 0.1f, 0.2f, 0.3f);
    assert_true(s.environment.ambient_light_set);
    assert_vec3(s.environment.ambient_light, 0.05f, 0.04f, 0.03f);
    assert_float_equal(st->exposure, 1.5, 0);
    assert_float_equal(st->clamp, 10, 0);
    assert_float_equal(st->ray_offset, 0.001, 1e-9);
    assert_string_equal(st->output, "my render.png");
    assert_int_equal(s.environment.environment_texture, RT_NONE);
    assert_false(s.camera_set);
    rt_scene_free(&s);

    /* defaults stay when nothing is said */
    expect_ok_settings("# nothing but a comment\n", &s, &set);
    rt_settings def;
    rt_settings_default(&def);
    assert_memory_equal(&set, &def, sizeof def);
    rt_scene_free(&s);

    expect_ok_settings("integrator path\n", &s, &set);
    assert_int_equal(set.integrator, RT_INTEGRATOR_PATH);
    rt_scene_free(&s);
}

/* The settings table's defaults are the documented ones (they were written
 * out in rt_settings_default() before the table). */
static void test_settings_table_defaults(void **state)
{
    (void)state;
    rt_settings d;
    memset(&d, 0x5a, sizeof d);
    rt_settings_default(&d);
    assert_int_equal(d.width, 512);
    assert_int_equal(d.height, 512);
    assert_int_equal(d.samples, 1);
    assert_int_equal(d.integrator, RT_INTEGRATOR_DIRECT);
    assert_int_equal(d.max_bounce, 1);
    assert_int_equal(d.max_depth, 0);
    assert_int_equal(d.diffuse_bounces, 0);
    assert_int_equal(d.diffuse_rays, 128);
    assert_int_equal(d.shadow_samples, 16);
    assert_true(d.ray_offset == 0.0f && d.clamp == 0.0f && d.exposure == 1.0f);
    assert_int_equal(d.seed, 0);
    assert_string_equal(d.output, "");
    rt_scene_environment e;
    memset(&e, 0x5a, sizeof e);
    rt_scene_environment_default(&e);
    assert_vec3(e.background, 0, 0, 0);
    assert_int_equal(e.environment_texture, RT_NONE);
    assert_true(e.environment_strength == 1.0f);
    assert_false(e.ambient_light_set);
    assert_vec3(e.ambient_light, 0, 0, 0);

    /* every entry is found by its name, and a default written out parses back to it */
    for (size_t i = 0; i < rt_settings_count; i++) {
        const rt_setting *def = &rt_settings_table[i];
        assert_ptr_equal(rt_setting_find(def->name), def);
        char dflt[128], text[256];
        rt_setting_default_text(def, dflt, sizeof dflt);
        if (def->marks_given || def->type == RT_SETTING_STRING || def->type == RT_SETTING_ENVIRONMENT)
            continue; /* "unset", "none" */
        snprintf(text, sizeof text, "%s %s\n", def->name, dflt);
        rt_scene sc;
        rt_settings setc;
        expect_ok_settings(text, &sc, &setc);
        assert_memory_equal(&setc, &d, sizeof d);
        assert_memory_equal(&sc.environment, &e, sizeof e);
        rt_scene_free(&sc);
    }
    assert_null(rt_setting_find("sampels"));
    rt_setting_problem pb;
    assert_int_equal(rt_settings_check(&d, &e, &pb), RT_OK);
    d.samples = RT_MAX_SAMPLES + 1;
    assert_int_equal(rt_settings_check(&d, &e, &pb), RT_ERR_INVALID);
    assert_string_equal(pb.message, "samples per pixel must be between 1 and 1048576, got 1048577");
    rt_settings_default(&d);
    e.background.y = -1.0f;
    assert_int_equal(rt_settings_check(&d, &e, &pb), RT_ERR_INVALID);
    assert_string_equal(pb.message, "the background colour (green) must be >= 0, got -1");
}

/* The command-line form of a value (--set, -r): words at blanks or commas,
 * WxH for a resolution, checked like a scene line, messages complete. */
static void test_settings_text_form(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    rt_settings set;
    rt_settings_default(&set);
    rt_setting_problem pb;
    const rt_setting *res = rt_setting_find("resolution");
    static const char *const sizes[] = {"640x480", "640X480", "640 480", "640,480", " 640 , 480 "};
    for (size_t i = 0; i < sizeof sizes / sizeof *sizes; i++) {
        set.width = set.height = 1;
        assert_int_equal(rt_setting_set(&set, &s.environment, res, sizes[i], &pb), RT_OK);
        assert_int_equal(set.width, 640);
        assert_int_equal(set.height, 480);
    }
    assert_int_equal(rt_setting_set(&set, &s.environment, res, "640", &pb), RT_ERR_PARSE);
    assert_string_equal(pb.message, "expected an integer for the image height, got nothing");
    assert_int_equal(rt_setting_set(&set, &s.environment, res, "0x5", &pb), RT_ERR_INVALID);
    assert_string_equal(pb.message, "the image width must be between 1 and 32768, got '0'");
    assert_int_equal(rt_setting_set(&set, &s.environment, res, "640x480x2", &pb), RT_ERR_PARSE);
    assert_string_equal(pb.message, "expected an integer for the image height, got '480x2'");
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("samples"), "4 5", &pb), RT_ERR_PARSE);
    assert_string_equal(pb.message, "unexpected '5' after the end of the value");
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("samples"), "", &pb), RT_ERR_PARSE);
    assert_string_equal(pb.message, "expected an integer for samples per pixel, got nothing");
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("integrator"), "magic", &pb), RT_ERR_PARSE);
    assert_string_equal(pb.message, "expected an integrator (direct|whitted|path|path_scalar), got 'magic'");

    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("background"), "0.1,0.2 0.3", &pb), RT_OK);
    assert_vec3(s.environment.background, 0.1f, 0.2f, 0.3f);
    assert_false(s.environment.ambient_light_set);
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("ambient_light"), "1 2 3", &pb), RT_OK);
    assert_true(s.environment.ambient_light_set);
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("output"), "a b,c.png", &pb), RT_OK);
    assert_string_equal(set.output, "a b,c.png");
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("output"), "", &pb), RT_ERR_INVALID);
    assert_string_equal(pb.message, "expected an output file name, got an empty string");
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("seed"), "4294967295", &pb), RT_OK);
    assert_int_equal(set.seed, 4294967295u);

    /* a NULL scene only checks */
    assert_int_equal(rt_setting_set(NULL, NULL, rt_setting_find("exposure"), "0", &pb), RT_ERR_INVALID);
    assert_string_equal(pb.message, "the exposure must be > 0, got '0'");
    assert_int_equal(rt_setting_set(NULL, NULL, rt_setting_find("environment"), "no-such.hdr strength 2", &pb), RT_OK);
    assert_int_equal(rt_setting_set(NULL, NULL, rt_setting_find("environment"), "sky.hdr strength -1", &pb),
                     RT_ERR_INVALID);
    assert_string_equal(pb.message, "the environment strength must be >= 0, got '-1'");
    /* the table keeps the environment's file name; io loads the image (relative to the current directory) */
    assert_int_equal(rt_setting_set(&set, &s.environment, rt_setting_find("environment"), tmp_path("no-such.hdr"), &pb), RT_OK);
    assert_string_equal(s.environment.environment_file, tmp_path("no-such.hdr"));
    assert_int_equal(s.environment.environment_texture, RT_NONE);
    rt_error err = {0};
    assert_int_equal(rt_environment_image_load(&s, &err), RT_ERR_IO);
    assert_non_null(strstr(err.message, "no-such.hdr"));
    assert_int_equal(s.environment.environment_texture, RT_NONE);
    rt_scene_free(&s);
}

/* docs/scene-format.md's materials table (section 5) has a row for every
 * material key the parser knows: a row whose first cell names it
 * (`KEY ...` or `KEY`, maybe after another key of the same row). */
static void test_material_keys_in_docs(void **state)
{
    (void)state;
    const char *sec = scene_format_doc_section("\n## 5. Materials\n");
    int missing = 0;
    for (size_t i = 0; rt_scene_material_key(i); i++) {
        const char *key = rt_scene_material_key(i);
        bool found = false;
        for (const char *row = strstr(sec, "\n| `"); row && !found; row = strstr(row + 1, "\n| `")) {
            const char *cell_end = strstr(row + 3, " |");
            char a[96], b[96];
            snprintf(a, sizeof a, "`%s ", key);
            snprintf(b, sizeof b, "`%s`", key);
            const char *x = strstr(row, a), *y = strstr(row, b);
            found = (x && x < cell_end) || (y && y < cell_end);
        }
        if (!found) {
            print_error("docs/scene-format.md section 5 has no row for material key `%s`\n", key);
            missing++;
        }
    }
    assert_true(rt_scene_material_key(0) != NULL);
    assert_int_equal(missing, 0);
}

/* docs/scene-format.md's settings table lists every setting of the table,
 * written as `name words`, with the table's default and allowed values. */
static void test_settings_table_in_docs(void **state)
{
    (void)state;
    const char *sec = scene_format_doc_section("\n## 2. Settings\n");
    int missing = 0;
    for (size_t i = 0; i < rt_settings_count; i++) {
        const rt_setting *def = &rt_settings_table[i];
        char head[128], range[128], dflt[128], row[2048];
        snprintf(head, sizeof head, "\n| `%s %s` |", def->name, def->args);
        rt_setting_range_text(def, range, sizeof range);
        rt_setting_default_text(def, dflt, sizeof dflt);
        const char *r = strstr(sec, head);
        if (!r) {
            print_error("docs/scene-format.md section 2 has no row for `%s %s`\n", def->name, def->args);
            missing++;
            continue;
        }
        /* the row's cells, with \| unescaped: statement, argument, default, allowed, field */
        size_t k = 0;
        for (const char *c = r + 1; *c && *c != '\n' && k + 1 < sizeof row; c++) {
            if (c[0] == '\\' && c[1] == '|')
                continue;
            row[k++] = *c == '|' && c[-1] != '\\' ? '\t' : *c;
        }
        row[k] = '\0';
        char *cells[8] = {0};
        int ncell = 0;
        for (char *c = strtok(row, "\t"); c && ncell < 8; c = strtok(NULL, "\t"))
            cells[ncell++] = c;
        assert_true(ncell >= 4);
        char quoted[140];
        snprintf(quoted, sizeof quoted, " `%s`", dflt);
        char plain[140];
        snprintf(plain, sizeof plain, " %s", dflt);
        if (strncmp(cells[2], quoted, strlen(quoted)) != 0 && strncmp(cells[2], plain, strlen(plain)) != 0) {
            print_error("docs: `%s` default is '%s', the table says '%s'\n", def->name, cells[2], dflt);
            missing++;
        }
        if (!strstr(cells[3], range)) {
            print_error("docs: `%s` allows '%s', the table says '%s'\n", def->name, cells[3], range);
            missing++;
        }
    }
    assert_int_equal(missing, 0);
}

static void test_camera_values(void **state)
{
    (void)state;
    rt_scene s;
    expect_ok("camera fov 30 look_at 1 2 3 position 4 5 6 up 0 0 1 aperture 0.1 focus 7.5\n", &s);
    assert_true(s.camera_set);
    assert_vec3(s.camera.position, 4, 5, 6);
    assert_vec3(s.camera.look_at, 1, 2, 3);
    assert_vec3(s.camera.up, 0, 0, 1);
    assert_float_equal(s.camera.vfov_deg, 30, 0);
    assert_float_equal(s.camera.aperture, 0.1, 1e-7);
    assert_float_equal(s.camera.focus_distance, 7.5, 0);
    assert_true(s.camera.shutter_open == 0 && s.camera.shutter_close == 0); /* no motion blur */
    rt_scene_free(&s);
    expect_ok("camera position 0 0 5 look_at 0 0 0 shutter -0.01 0.02\n", &s);
    assert_float_equal(s.camera.shutter_open, -0.01, 1e-9);
    assert_float_equal(s.camera.shutter_close, 0.02, 1e-9);
    rt_scene_free(&s);

    /* up, fov, aperture and focus have defaults */
    expect_ok("camera position 0 0 5 look_at 0 0 0\n", &s);
    assert_vec3(s.camera.up, 0, 1, 0);
    assert_float_equal(s.camera.vfov_deg, 40, 0);
    assert_float_equal(s.camera.aperture, 0, 0);
    assert_float_equal(s.camera.focus_distance, 0, 0);
    rt_scene_free(&s);
}

static void test_material_values(void **state)
{
    (void)state;
    rt_scene s;
    expect_ok("texture wood checker 1 0 0 0 0 1 scale 4\n"
              "texture flat constant 0.5 0.5 1\n"
              "material m color 0.1 0.2 0.3 alpha 0.5 ambient 0.25 diffuse 0.6 specular 0.7 shininess 50 \\\n"
              "  reflect 0.3 transmission 0.9 transmission_color 0.9 0.8 0.7 ior 1.33 metallic 1 roughness 0.2 \\\n"
              "  emission 1 2 3 emission_strength 4 normal_map flat normal_scale 0.5 texture wood \\\n"
              "  double_sided false unlit true occlusion_strength 0.75 alpha_mode mask alpha_cutoff 0.25 \\\n"
              "  thickness 0.1 attenuation_color 0.5 0.6 0.7 attenuation_distance 2 \\\n"
              "  metallic_roughness_map wood occlusion_map flat emission_map wood transmission_map flat \\\n"
              "  uv_scale 2 3 uv_offset 0.5 0.25\n"
              "material plain\n"
              "material glass reflectivity 0.1 base_color 1 1 1 attenuation_distance inf alpha_mode blend\n",
              &s);
    assert_int_equal(s.material_count, 3);
    assert_int_equal(s.texture_count, 2);
    const rt_material *m = &s.materials[0];
    assert_string_equal(m->name, "m");
    assert_vec3(m->color, 0.1f, 0.2f, 0.3f);
    assert_float_equal(m->alpha, 0.5, 0);
    assert_float_equal(m->ambient, 0.25, 0);
    assert_float_equal(m->diffuse, 0.6, 1e-7);
    assert_float_equal(m->specular, 0.7, 1e-7);
    assert_float_equal(m->shininess, 50, 0);
    assert_float_equal(m->reflectivity, 0.3, 1e-7);
    assert_float_equal(m->transmission, 0.9, 1e-7);
    assert_vec3(m->transmission_color, 0.9f, 0.8f, 0.7f);
    assert_float_equal(m->ior, 1.33, 1e-6);
    assert_float_equal(m->metallic, 1, 0);
    assert_float_equal(m->roughness, 0.2, 1e-7);
    assert_vec3(m->emission, 1, 2, 3);
    assert_float_equal(m->emission_strength, 4, 0);
    assert_int_equal(m->normal_tex.texture, 1);
    assert_float_equal(m->normal_scale, 0.5, 0);
    assert_int_equal(m->base_color_tex.texture, 0);
    assert_false(m->double_sided);
    assert_true(m->unlit);
    assert_float_equal(m->occlusion_strength, 0.75, 0);
    assert_int_equal(m->alpha_mode, RT_ALPHA_MASK);
    assert_float_equal(m->alpha_cutoff, 0.25, 0);
    assert_float_equal(m->thickness, 0.1, 1e-7);
    assert_vec3(m->attenuation_color, 0.5f, 0.6f, 0.7f);
    assert_float_equal(m->attenuation_distance, 2, 0);
    assert_int_equal(m->metal_rough_tex.texture, 0);
    assert_int_equal(m->occlusion_tex.texture, 1);
    assert_int_equal(m->emissive_tex.texture, 0);
    assert_int_equal(m->transmission_tex.texture, 1);
    const float uvt[6] = {2, 0, 0.5f, 0, 3, 0.25f};
    for (int i = 0; i < 6; i++) {
        assert_float_equal(m->base_color_tex.uv_transform[i], uvt[i], 0);
        assert_float_equal(m->transmission_tex.uv_transform[i], uvt[i], 0);
    }
    /* textures */
    assert_int_equal(s.textures[0].kind, RT_TEX_CHECKER);
    assert_float_equal(s.textures[0].checker_scale, 4, 0);
    assert_float_equal(s.textures[0].color_a.x, 1, 0);
    assert_float_equal(s.textures[0].color_b.z, 1, 0);
    assert_int_equal(s.textures[1].kind, RT_TEX_CONSTANT);
    assert_float_equal(s.textures[1].color_a.z, 1, 0);
    /* a material with nothing said has rt_material_default()'s values */
    rt_material def;
    rt_material_default(&def, "plain");
    assert_memory_equal(&s.materials[1], &def, sizeof def);
    /* aliases and inf */
    const rt_material *g = &s.materials[2];
    assert_float_equal(g->reflectivity, 0.1, 1e-7);
    assert_vec3(g->color, 1, 1, 1);
    assert_true(isinf(g->attenuation_distance));
    assert_int_equal(g->alpha_mode, RT_ALPHA_BLEND);
    rt_scene_free(&s);
}

static void test_primitive_values(void **state)
{
    (void)state;
    rt_scene s;
    expect_ok("material a\nmaterial b color 1 0 0\n"
              "sphere 1 2 3 0.5 b\n"
              "quad 0 0 0  1 0 0  0 2 0  a\n"
              "triangle 0 0 0  1 0 0  0 1 0  b\n",
              &s);
    assert_int_equal(s.spheres.count, 1);
    assert_float_equal(s.spheres.cx[0], 1, 0);
    assert_float_equal(s.spheres.cy[0], 2, 0);
    assert_float_equal(s.spheres.cz[0], 3, 0);
    assert_float_equal(s.spheres.radius[0], 0.5, 0);
    assert_int_equal(s.spheres.material[0], 1);
    assert_int_equal(s.quads.count, 1);
    assert_float_equal(s.quads.ux[0], 1, 0);
    assert_float_equal(s.quads.vy[0], 2, 0);
    assert_int_equal(s.quads.material[0], 0);
    assert_int_equal(s.triangles.count, 1);
    assert_int_equal(s.vertices.count, 3);
    assert_int_equal(s.triangles.material[0], 1);
    assert_int_equal(s.triangles.flags[0], RT_TRI_UV);
    assert_vec3(rt_tri_vertex(&s, 0, 1), 1, 0, 0);
    assert_vec3(rt_tri_vertex(&s, 0, 2), 0, 1, 0);
    assert_float_equal(s.vertices.uv0[1].x, 1, 0);
    assert_float_equal(s.vertices.uv0[2].y, 1, 0);
    assert_vec3(s.vertices.normal[0], 0, 0, 1);
    rt_scene_free(&s);
}

static void test_light_values(void **state)
{
    (void)state;
    rt_scene s;
    expect_ok("light point 1 2 3  1 0.5 0.25  100\n"
              "light directional 0 -2 0  1 1 1  3\n"
              "light spot 0 5 0  0 -1 0  1 1 1  50  20 30 range 10\n"
              "light area 0 2 0  1 0 0  0 0 1  1 0.5 0  8\n",
              &s);
    assert_int_equal(s.light_count, 4);
    const rt_light *l = s.lights;
    assert_int_equal(l[0].kind, RT_LIGHT_POINT);
    assert_vec3(l[0].position, 1, 2, 3);
    assert_vec3(l[0].color, 1, 0.5f, 0.25f);
    assert_float_equal(l[0].intensity, 100, 0);
    assert_int_equal(l[0].quad, RT_NONE);
    assert_int_equal(l[1].kind, RT_LIGHT_DIRECTIONAL);
    assert_vec3(l[1].direction, 0, -1, 0); /* normalised */
    assert_float_equal(l[1].intensity, 3, 0);
    assert_int_equal(l[2].kind, RT_LIGHT_SPOT);
    assert_vec3(l[2].direction, 0, -1, 0);
    assert_float_equal(l[2].inner_cone, 20 * RT_PI / 180, 1e-6);
    assert_float_equal(l[2].outer_cone, 30 * RT_PI / 180, 1e-6);
    assert_float_equal(l[2].range, 10, 0);
    /* the area light made a visible quad with an emissive material */
    assert_int_equal(l[3].kind, RT_LIGHT_AREA);
    assert_float_equal(l[3].intensity, 8, 0);
    assert_int_equal(l[3].quad, 0);
    assert_int_equal(s.quads.count, 1);
    assert_float_equal(s.quads.py[0], 2, 0);
    assert_float_equal(s.quads.vz[0], 1, 0);
    const rt_material *m = &s.materials[s.quads.material[0]];
    assert_string_equal(m->name, "__area_light_3");
    assert_vec3(m->emission, 8, 4, 0);
    assert_vec3(m->color, 0, 0, 0);
    assert_false(m->double_sided);
    rt_scene_free(&s);
}

/* ------------------------------------------------------------ lexing */

static void test_comments_and_continuations(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    expect_ok_settings("# a comment line\n"
              "   # an indented one\n"
              "\n"
              "material m#comment right after a token\n"
              "sphere 1 2 \\\n"
              "   3 \\  # a comment after the backslash\n"
              "   4 m   # the end of the first sphere\n"
              "sphere 0 0 0 \\\n"
              "\\\n"
              "1 m\n"
              "samples 8\\\n"
              "\t\t# the statement ends here, so the samples line is complete\n"
              "sphere\t5 5 5 1 m",
              &s, &set); /* no final newline */
    assert_int_equal(s.spheres.count, 3);
    assert_float_equal(s.spheres.cz[0], 3, 0);
    assert_float_equal(s.spheres.radius[0], 4, 0);
    assert_float_equal(s.spheres.radius[1], 1, 0);
    assert_int_equal(set.samples, 8);
    assert_float_equal(s.spheres.cx[2], 5, 0);
    rt_scene_free(&s);

    /* CRLF line endings and quoted names */
    expect_ok("material \"a b\" color 1 1 1\r\nsphere 0 0 0 1 \"a b\"\r\n", &s);
    assert_int_equal(s.spheres.count, 1);
    assert_string_equal(s.materials[0].name, "a b");
    rt_scene_free(&s);

    /* a UTF-8 byte order mark is skipped */
    expect_ok_settings("\xef\xbb\xbfsamples 3\n", &s, &set);
    assert_int_equal(set.samples, 3);
    rt_scene_free(&s);

    /* empty input */
    expect_ok("", &s);
    assert_int_equal(rt_scene_prim_count(&s), 0);
    rt_scene_free(&s);
}

/* ------------------------------------------------------------ errors */

static void test_errors_syntax(void **state)
{
    (void)state;
    static const error_case cases[] = {
        {"bogus 1 2\n", RT_ERR_PARSE, "1:1", "unknown keyword 'bogus'"},
        {"# c\n\n  sampels 4\n", RT_ERR_PARSE, "3:3", "did you mean 'samples'?"},
        {"material m\nsphere 0 0 0 abc m\n", RT_ERR_PARSE, "2:14",
         "expected a number for the sphere radius, got 'abc'"},
        {"material m\nsphere 0 0 0\n", RT_ERR_PARSE, "2:13",
         "expected a number for the sphere radius, got end of line"},
        {"material m\nsphere 0 0 0 1.0x m\n", RT_ERR_PARSE, "2:14", "got '1.0x'"},
        {"material m\nsphere 0 0 nan 1 m\n", RT_ERR_PARSE, "2:12",
         "expected a number for the sphere centre (z), got 'nan'"},
        {"material m\nsphere inf 0 0 1 m\n", RT_ERR_PARSE, "2:8", "got 'inf'"},
        {"material m\nsphere 0x10 0 0 1 m\n", RT_ERR_PARSE, "2:8", "got '0x10'"},
        {"material m\nsphere 1e39 0 0 1 m\n", RT_ERR_INVALID, "2:8",
         "the sphere centre (x) is out of range (beyond +-3.4e38), got '1e39'"},
        {"material m\nsphere 0 0 0 1 m scale 1e309\n", RT_ERR_PARSE, "2:18", "unexpected 'scale'"},
        {"mesh a.obj scale 2 1e309 1\n", RT_ERR_INVALID, "1:20", "the mesh scale (y) is out of range"},
        /* bytes that are not UTF-8 are escaped in messages; UTF-8 is kept */
        {"sampl\xe9s 3\n", RT_ERR_PARSE, "1:1", "unknown keyword 'sampl\\xe9s' (did you mean 'samples'?)"},
        {"material m color 1 1 1\nsphere 0 0 0 1 \xc3\xa9t\xc3\xa9\n", RT_ERR_INVALID, "2:16",
         "undefined material '\xc3\xa9t\xc3\xa9'"},
        {"material m colour 1 1 1\n", RT_ERR_PARSE, "1:12",
         "expected a material key, got 'colour' (did you mean 'color'?)"},
        {"material m\nsphere . 0 0 1 m\n", RT_ERR_PARSE, "2:8", "got '.'"},
        {"material m\nsphere 1e 0 0 1 m\n", RT_ERR_PARSE, "2:8", "got '1e'"},
        {"material m\nsphere 0 0 0 1 m extra\n", RT_ERR_PARSE, "2:18",
         "unexpected 'extra' after the end of the sphere statement"},
        {"samples 4.5\n", RT_ERR_PARSE, "1:9", "expected an integer for samples per pixel, got '4.5'"},
        {"samples\n", RT_ERR_PARSE, "1:8", "expected an integer for samples per pixel, got end of line"},
        {"resolution 640\n", RT_ERR_PARSE, "1:15", "expected an integer for the image height, got end of line"},
        {"integrator fancy\n", RT_ERR_PARSE, "1:12",
         "expected an integrator (direct|whitted|path|path_scalar), got 'fancy'"},
        {"material m\nsphere 0 0 0 1 m\nsphere 1 2 \\\n  3 x m\n", RT_ERR_PARSE, "4:5",
         "expected a number for the sphere radius, got 'x'"},
        {"material \"unterminated\n", RT_ERR_PARSE, "1:10", "unterminated quoted string"},
        {"material \"a\"b\n", RT_ERR_PARSE, "1:13", "expected a blank after the closing quote"},
        {"samples \"4\"\n", RT_ERR_PARSE, "1:9", "expected an integer for samples per pixel, got '4'"},
        {"integrator \"path\"\n", RT_ERR_PARSE, "1:12", "expected an integrator (direct|whitted|path|path_scalar)"},
        {"samples 4\x01\n", RT_ERR_PARSE, "1:10", "unexpected control character 0x01"},
        {"samples 4\n\x7f", RT_ERR_PARSE, "2:1", "unexpected control character 0x7f"},
    };
    expect_errors(cases);
    {
        const char text[] = "samples 4\n  \0 x\n";
        rt_scene s;
        rt_error err;
        rt_scene_init(&s);
        assert_int_equal(rt_scene_parse_string(&s, NULL, text, sizeof text - 1, "t.txt", NULL, &err), RT_ERR_PARSE);
        assert_non_null(strstr(err.message, "t.txt:2:3: unexpected control character 0x00"));
        rt_scene_free(&s);
    }
    static const error_case cases2[] = {
        {"camera position 0 0 5 look_at 0 0 0 zoom 3\n", RT_ERR_PARSE, "1:37",
         "expected a camera key (position|look_at|up|fov|aperture|focus|shutter), got 'zoom'"},
        {"light laser 0 0 0\n", RT_ERR_PARSE, "1:7",
         "expected a light kind (point|directional|spot|area), got 'laser'"},
        {"light point 0 0 0 1 1 1\n", RT_ERR_PARSE, "1:24",
         "expected a number for the point light intensity, got end of line"},
        {"material m shiny 3\n", RT_ERR_PARSE, "1:12", "expected a material key"},
        {"material m double_sided maybe\n", RT_ERR_PARSE, "1:25",
         "expected material double_sided (true|false), got 'maybe'"},
        {"texture t image\n", RT_ERR_PARSE, "1:16", "expected an image file, got end of line"},
        {"texture t marble\n", RT_ERR_PARSE, "1:11", "expected a texture kind (image|checker|constant), got 'marble'"},
        {"texture t checker 1 1 1 0 0 0 scale\n", RT_ERR_PARSE, "1:36",
         "expected a number for the checker scale, got end of line"},
        {"texture t checker 1 1 1 0 0 0 size 2\n", RT_ERR_PARSE, "1:31",
         "unexpected 'size' after the end of the texture statement"},
        {"material m\nmesh a.obj m spin 3\n", RT_ERR_PARSE, "2:14",
         "expected a mesh option (translate, rotate, scale, material_override), got 'spin'"},
        {"material m\nmesh a.obj scale 1 2\n", RT_ERR_PARSE, "2:21",
         "expected a number for the mesh scale (z), got end of line"},
        {"model a.gltf rotate 1 2\n", RT_ERR_PARSE, "1:24",
         "expected a number for the model rotation in degrees (z), got end of line"},
        {"model a.gltf twist\n", RT_ERR_PARSE, "1:14", "expected a model option"},
        {"mesh\n", RT_ERR_PARSE, "1:5", "expected a mesh file (.obj, .ply or .off), got end of line"},
    };
    expect_errors(cases2);
    /* a very long bad token is shortened in the message */
    char big[2048];
    memset(big, 'x', sizeof big);
    memcpy(big, "samples ", 8);
    big[sizeof big - 2] = '\n';
    big[sizeof big - 1] = '\0';
    expect_error(big, RT_ERR_PARSE, "1:9", "got 'xxxx");
}

/* bsdf conductor: a named metal, eta/k, isotropic and anisotropic alpha,
 * the Smith term; and the keys' errors. */
static void test_conductor_material(void **state)
{
    (void)state;
    rt_scene s;
    expect_ok("material au bsdf conductor metal Au roughness 0.3\n"
              "material c bsdf conductor eta 0.2 0.9 1.1 k 3 2.5 2 ggx_alpha_uv 0.3 0.05 smith separable\n"
              "material d bsdf conductor ggx_alpha 0.01\n",
              &s);
    assert_int_equal(s.material_count, 3);
    const rt_material *m = &s.materials[0];
    assert_int_equal(m->bsdf, RT_BSDF_CONDUCTOR);
    assert_string_equal(rt_metals[1].name, "Au");
    assert_vec3(m->eta, rt_metals[1].eta.x, rt_metals[1].eta.y, rt_metals[1].eta.z);
    assert_vec3(m->k, rt_metals[1].k.x, rt_metals[1].k.y, rt_metals[1].k.z);
    assert_true(m->alpha_u < 0.0f && m->smith == RT_SMITH_CORRELATED);
    m = &s.materials[1];
    assert_vec3(m->eta, 0.2f, 0.9f, 1.1f);
    assert_vec3(m->k, 3, 2.5f, 2);
    assert_float_equal(m->alpha_u, 0.3, 1e-7);
    assert_float_equal(m->alpha_v, 0.05, 1e-7);
    assert_int_equal(m->smith, RT_SMITH_SEPARABLE);
    m = &s.materials[2];
    assert_vec3(m->eta, rt_metals[0].eta.x, rt_metals[0].eta.y, rt_metals[0].eta.z); /* Cu by default */
    assert_float_equal(m->alpha_u, 0.01, 1e-7);
    assert_float_equal(m->alpha_v, 0.01, 1e-7);
    rt_scene_free(&s);
    static const error_case cases[] = {
        {"material m metal Au\n", RT_ERR_INVALID, "1:12", "material key 'metal' needs 'bsdf conductor'"},
        {"material m bsdf conductor metal Zz\n", RT_ERR_PARSE, "1:33",
         "expected material metal (Cu|Au|Ag|Al|Ti|Pt|Fe|CuZn|Cr|Ni|W), got 'Zz'"},
        {"material m bsdf conductor metal Au k 1 1 1\n", RT_ERR_INVALID, "1:36",
         "give either 'metal NAME' or 'eta' and 'k', not both"},
        {"material m bsdf conductor ggx_alpha 0.1 ggx_alpha_uv 0.1 0.2\n", RT_ERR_INVALID, "1:41",
         "give either 'ggx_alpha' or 'ggx_alpha_uv', not both"},
        {"material m bsdf conductor ggx_alpha_uv 0.1 2\n", RT_ERR_INVALID, "1:44",
         "material ggx_alpha_uv must be between 0 and 1, got '2'"},
        {"material m bsdf conductor smith maybe\n", RT_ERR_PARSE, "1:33",
         "expected material smith (correlated|separable), got 'maybe'"},
        {"material m bsdf conductor eta 1 -1 1\n", RT_ERR_INVALID, "1:33", "material eta (green) must be >= 0"},
    };
    expect_errors(cases);
    /* bsdf dielectric: transmissive and smooth by default */
    expect_ok("material g bsdf dielectric ior 1.33 exterior_ior 1.1 absorption 0.1 0.2 0.3\n"
              "material r bsdf dielectric ggx_alpha 0.2 transmission 0.5\n",
              &s);
    m = &s.materials[0];
    assert_int_equal(m->bsdf, RT_BSDF_DIELECTRIC);
    assert_float_equal(m->transmission, 1, 0);
    assert_float_equal(m->roughness, 0, 0);
    assert_float_equal(m->exterior_ior, 1.1, 1e-6);
    assert_vec3(m->absorption, 0.1f, 0.2f, 0.3f);
    assert_float_equal(s.materials[1].alpha_u, 0.2, 1e-7);
    assert_float_equal(s.materials[1].transmission, 0.5, 0);
    rt_scene_free(&s);
    expect_error("material m absorption 1 1 1\n", RT_ERR_INVALID, "1:12", "material key 'absorption' needs 'bsdf dielectric'");
    /* nested media: an integer priority, dielectrics only */
    expect_ok("material w bsdf dielectric ior 1.33 priority 7\n", &s);
    assert_int_equal(s.materials[0].priority, 7);
    rt_scene_free(&s);
    static const error_case cases2[] = {
        {"material m bsdf plastic priority 1\n", RT_ERR_INVALID, "1:25",
         "material key 'priority' needs 'bsdf dielectric'"},
        {"material m bsdf dielectric priority 1.5\n", RT_ERR_PARSE, "1:37",
         "expected an integer for material priority, got '1.5'"},
        {"material m bsdf dielectric priority -1\n", RT_ERR_INVALID, "1:37",
         "material priority must be between 0 and 1000, got '-1'"},
        {"material m bsdf conductor exterior_ior 1.2\n", RT_ERR_INVALID, "1:27",
         "material key 'exterior_ior' needs 'bsdf dielectric'"},
        {"material m ggx_alpha 0.1\n", RT_ERR_INVALID, "1:12",
         "material key 'ggx_alpha' needs 'bsdf conductor', 'bsdf dielectric' or 'bsdf plastic'"},
    };
    expect_errors(cases2);
    expect_ok("material p bsdf plastic color 0.5 0.1 0.1 ior 1.6 exterior_ior 1.1 ggx_alpha 0.1\n", &s);
    assert_int_equal(s.materials[0].bsdf, RT_BSDF_PLASTIC);
    assert_float_equal(s.materials[0].exterior_ior, 1.1, 1e-6);
    assert_float_equal(s.materials[0].roughness, 0, 0);
    assert_float_equal(s.materials[0].transmission, 0, 0);
    rt_scene_free(&s);
    expect_error("material m bsdf dielectric smith separable\n", RT_ERR_INVALID, "1:28",
                 "material key 'smith' needs 'bsdf conductor'");
}

static void test_errors_values(void **state)
{
    (void)state;
    static const error_case cases[] = {
        {"material m\nsphere 0 0 0 -1 m\n", RT_ERR_INVALID, "2:14", "the sphere radius must be > 0, got '-1'"},
        {"material m\nsphere 0 0 0 0 m\n", RT_ERR_INVALID, "2:14", "the sphere radius must be > 0"},
        {"resolution 0 100\n", RT_ERR_INVALID, "1:12", "the image width must be between 1 and 32768, got '0'"},
        {"resolution 100 32769\n", RT_ERR_INVALID, "1:16", "the image height must be between 1 and 32768"},
        {"resolution 99999999999999999999999 1\n", RT_ERR_INVALID, "1:12", "between 1 and 32768"},
        {"samples 0\n", RT_ERR_INVALID, "1:9", "samples per pixel must be between 1 and 1048576, got '0'"},
        {"samples 1048577\n", RT_ERR_INVALID, "1:9", "between 1 and 1048576"},
        {"samples -3\n", RT_ERR_INVALID, "1:9", "between 1 and 1048576, got '-3'"},
        {"max_bounce -1\n", RT_ERR_INVALID, "1:12", "max_bounce must be between 0 and 256"},
        {"diffuse_rays 0\n", RT_ERR_INVALID, "1:14", "diffuse_rays must be between 1 and 65536"},
        {"shadow_samples 0\n", RT_ERR_INVALID, "1:16", "shadow_samples must be between 1"},
        {"diffuse_bounces 65\n", RT_ERR_INVALID, "1:17", "diffuse_bounces must be between 0 and 64"},
        {"seed 4294967296\n", RT_ERR_INVALID, "1:6", "the seed must be between 0 and 4294967295"},
        {"exposure 0\n", RT_ERR_INVALID, "1:10", "the exposure must be > 0"},
        {"clamp -1\n", RT_ERR_INVALID, "1:7", "the clamp must be >= 0"},
        {"ray_offset -0.1\n", RT_ERR_INVALID, "1:12", "the ray offset must be >= 0"},
        {"background 0 -1 0\n", RT_ERR_INVALID, "1:14", "the background colour (green) must be >= 0"},
        {"ambient_light 0 0 -1\n", RT_ERR_INVALID, "1:19", "the ambient light colour (blue) must be >= 0"},
        {"ambient_light 0 0\n", RT_ERR_PARSE, "1:18",
         "expected a number for the ambient light colour (blue), got end of line"},
        {"material m alpha 1.5\n", RT_ERR_INVALID, "1:18", "material alpha must be between 0 and 1, got '1.5'"},
        {"material m color 1 1 -1\n", RT_ERR_INVALID, "1:22", "material color (blue) must be >= 0"},
        {"material m ior 0\n", RT_ERR_INVALID, "1:16", "material ior must be between 0.01 and 100"},
        {"material m roughness 2\n", RT_ERR_INVALID, "1:22", "material roughness must be between 0 and 1"},
        {"material m attenuation_distance 0\n", RT_ERR_INVALID, "1:33", "material attenuation_distance must be > 0"},
        {"material m color 1 1 1 alpha 1 color 0 0 0\n", RT_ERR_INVALID, "1:32",
         "material key 'color' is given twice (first at column 12)"},
        {"material m reflect 0.5 reflectivity 0.5\n", RT_ERR_INVALID, "1:24", "'reflect' is given twice"},
        {"camera position 0 0 0 look_at 0 0 0\n", RT_ERR_INVALID, "1:23",
         "the camera look_at point equals its position"},
        {"camera position 0 5 0 look_at 0 0 0\n", RT_ERR_INVALID, "1:1",
         "the camera up vector is parallel to the view direction"},
        {"camera position 0 0 5 look_at 0 0 0 up 0 0 0\n", RT_ERR_INVALID, "1:37", "the camera up vector is zero"},
        {"camera position 0 0 5 look_at 0 0 0 fov 180\n", RT_ERR_INVALID, "1:41",
         "field of view must be below 180 degrees"},
        {"camera position 0 0 5 look_at 0 0 0 fov 0\n", RT_ERR_INVALID, "1:41", "the camera field of view must be > 0"},
        {"camera position 0 0 5 fov 3\n", RT_ERR_PARSE, "1:28", "expected 'look_at X Y Z'"},
        {"camera look_at 0 0 5 fov 3\n", RT_ERR_PARSE, "1:27", "expected 'position X Y Z'"},
        {"camera position 0 0 5 look_at 0 0 0 position 1 1 1\n", RT_ERR_INVALID, "1:37",
         "camera key 'position' is given twice (first at column 8)"},
        {"camera position 0 0 5 look_at 0 0 0\n\ncamera position 0 0 5 look_at 0 0 1\n", RT_ERR_INVALID, "3:1",
         "the camera is already set on line 1"},
        {"camera gltf -1\n", RT_ERR_INVALID, "1:13", "the glTF camera index must be between 0"},
        {"# no models\ncamera gltf 0\n", RT_ERR_INVALID, "2:13", "camera gltf 0: the loaded models have 0 cameras"},
        {"material m\nquad 0 0 0  1 0 0  2 0 0  m\n", RT_ERR_INVALID, "2:1", "degenerate quad"},
        {"material m\ntriangle 0 0 0  1 1 1  2 2 2  m\n", RT_ERR_INVALID, "2:1", "degenerate triangle"},
    };
    expect_errors(cases);
    /* sizes whose squares overflow a float: the triangle used to load with a
     * zero normal (rt_normalize of an infinite length), the camera and the
     * quad were blamed on the up vector and on parallel edges */
    static const error_case cases2[] = {
        {"material m\ntriangle 0 0 0  1e10 0 0  0 1e10 0  m\n", RT_ERR_INVALID, "2:1",
         "the triangle is too large: its normal overflows float arithmetic"},
        {"material m\ntriangle 0 0 0  3e38 0 0  0 3e38 0  m\n", RT_ERR_INVALID, "2:1", "the triangle is too large"},
        {"material m\nquad 0 0 0  1e10 0 0  0 1e10 0  m\n", RT_ERR_INVALID, "2:1",
         "the quad is too large: its normal overflows float arithmetic"},
        {"camera position 3e38 0 5 look_at -3e38 0 0 up 0 1 0\n", RT_ERR_INVALID, "1:26",
         "the camera look_at point is too far from its position"},
        {"camera position 1e20 0 0 look_at 0 0 0 up 0 1 0\n", RT_ERR_INVALID, "1:26",
         "the camera look_at point is too far from its position"},
        {"light directional 0 0 0  1 1 1  1\n", RT_ERR_INVALID, "1:19", "the directional light direction is zero"},
        {"light point 0 0 0  1 1 1  -5\n", RT_ERR_INVALID, "1:27", "the point light intensity must be >= 0"},
        {"light spot 0 0 0  0 -1 0  1 1 1  1  40 30\n", RT_ERR_INVALID, "1:37",
         "inner cone angle (40) must not exceed the outer one (30)"},
        {"light spot 0 0 0  0 -1 0  1 1 1  1  10 95\n", RT_ERR_INVALID, "1:40",
         "the spot light outer cone angle must be between 0 and 90"},
        {"light area 0 0 0  1 0 0  2 0 0  1 1 1  1\n", RT_ERR_INVALID, "1:1", "degenerate area light"},
        {"material m\nmesh a.obj scale 0\n", RT_ERR_INVALID, "2:12", "the mesh scale must not be zero"},
        {"material m\nmesh a.obj m scale 1 scale 2\n", RT_ERR_INVALID, "2:22", "'scale' is given twice"},
        {"mesh a.obj material_override\n", RT_ERR_INVALID, "1:12", "'material_override' needs a material"},
        {"output \"\"\n", RT_ERR_INVALID, "1:8", "expected an output file name, got an empty string"},
    };
    expect_errors(cases2);
    char longname[700];
    memset(longname, 'a', sizeof longname);
    memcpy(longname, "output ", 7);
    longname[sizeof longname - 1] = '\0';
    expect_error(longname, RT_ERR_LIMIT, "1:8", "output file name is too long");
}

static void test_errors_names(void **state)
{
    (void)state;
    static const error_case cases[] = {
        {"sphere 0 0 0 1 steel\n", RT_ERR_INVALID, "1:16", "undefined material 'steel' for the sphere"},
        {"material m\nquad 0 0 0 1 0 0 0 1 0 n\n", RT_ERR_INVALID, "2:24", "undefined material 'n' for the quad"},
        {"material m\nsphere 0 0 0 1\n", RT_ERR_PARSE, "2:15",
         "expected a material name for the sphere, got end of line"},
        {"# first\nmaterial red color 1 0 0\nmaterial blue\nmaterial red color 0.9 0 0\n", RT_ERR_INVALID, "4:10",
         "material 'red' is already defined on line 2"},
        {"texture t constant 1 1 1\n\ntexture t constant 0 0 0\n", RT_ERR_INVALID, "3:9",
         "texture 't' is already defined on line 1"},
        {"material m texture wood\n", RT_ERR_INVALID, "1:20", "undefined texture 'wood' for material texture"},
        {"material m normal_map bumps\n", RT_ERR_INVALID, "1:23", "undefined texture 'bumps'"},
        {"material __area_light_0\n", RT_ERR_INVALID, "1:10", "names starting with '__' are reserved"},
        {"sphere 0 0 0 1 __area_light_0\n", RT_ERR_INVALID, "1:16", "undefined material '__area_light_0'"},
        {"material scale\n", RT_ERR_INVALID, "1:10", "'scale' is a keyword and cannot be a material name"},
        {"material aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n", RT_ERR_INVALID, "1:10",
         "is too long (at most 63 characters)"},
        {"material \"\"\n", RT_ERR_INVALID, "1:10", "a material name must not be empty"},
        {"material\n", RT_ERR_PARSE, "1:9", "expected a material name, got end of line"},
        /* a material must be defined before it is used */
        {"sphere 0 0 0 1 late\nmaterial late\n", RT_ERR_INVALID, "1:16", "undefined material 'late'"},
        /* a near miss is named, like an unknown keyword's */
        {"material steel color 0.5 0.5 0.5\nmaterial glass ior 1.5\nsphere 0 0 0 1 stel\n", RT_ERR_INVALID, "3:16",
         "undefined material 'stel' for the sphere (did you mean 'steel'?)"},
        {"material steel\nsphere 0 0 0 1 Glass\n", RT_ERR_INVALID, "2:16",
         "undefined material 'Glass' for the sphere (define it with 'material' before use)"},
        {"texture wood constant 1 1 1\nmaterial m texture wod\n", RT_ERR_INVALID, "2:20",
         "undefined texture 'wod' for material texture (did you mean 'wood'?)"},
    };
    expect_errors(cases);
}

/* Many names: the hash index grows and still finds every name and duplicate. */
static void test_many_names(void **state)
{
    (void)state;
    enum { N = 3000 };
    size_t cap = (size_t)N * 64 + 256, len = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    for (int i = 0; i < N; i++)
        len += (size_t)snprintf(text + len, cap - len, "material m%d color 0 0 %d\n", i, i % 2);
    for (int i = N - 1; i >= 0; i -= 7)
        len += (size_t)snprintf(text + len, cap - len, "sphere 0 0 0 1 m%d\n", i);
    rt_scene s;
    expect_ok(text, &s);
    assert_int_equal(s.material_count, N);
    for (size_t k = 0; k < s.spheres.count; k++)
        assert_int_equal(s.spheres.material[k], N - 1 - 7 * (int)k);
    rt_scene_free(&s);
    len += (size_t)snprintf(text + len, cap - len, "material m1234\n");
    char where[32];
    snprintf(where, sizeof where, "%d:10", N + (N + 6) / 7 + 1);
    expect_error(text, RT_ERR_INVALID, where, "material 'm1234' is already defined on line 1235");
    free(text);
}

/* ------------------------------------------------------------ files */

/* A 2x2 binary PPM that stb_image reads. */
static void write_ppm(const char *path)
{
    const unsigned char ppm[] = {'P', '6', '\n', '2', ' ', '2', '\n', '2', '5', '5', '\n',
                                 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    test_write_file(path, ppm, sizeof ppm);
}

static void test_textures_from_files(void **state)
{
    (void)state;
    write_ppm(tmp_path("tex.ppm"));
    rt_scene s;
    expect_ok("texture t image tex.ppm wrap mirror filter nearest\n"
              "texture u image tex.ppm\n"
              "material a texture t\n"
              "material b texture tex.ppm normal_map u\n"
              "environment tex.ppm strength 2.5\n",
              &s);
    assert_int_equal(s.image_count, 1); /* one file, decoded once */
    assert_int_equal(s.images[0].width, 2);
    assert_int_equal(s.texture_count, 4); /* t, u, b's file texture, the environment */
    assert_int_equal(s.textures[0].kind, RT_TEX_IMAGE);
    assert_int_equal(s.textures[0].wrap_s, RT_WRAP_MIRROR);
    assert_int_equal(s.textures[0].wrap_t, RT_WRAP_MIRROR);
    assert_int_equal(s.textures[0].filter, RT_FILTER_NEAREST);
    assert_int_equal(s.textures[1].wrap_s, RT_WRAP_REPEAT);
    assert_int_equal(s.textures[1].filter, RT_FILTER_BILINEAR);
    assert_int_equal(s.materials[0].base_color_tex.texture, 0);
    assert_int_equal(s.materials[1].base_color_tex.texture, 2);
    assert_int_equal(s.textures[2].kind, RT_TEX_IMAGE);
    assert_int_equal(s.textures[2].image, 0);
    assert_int_equal(s.materials[1].normal_tex.texture, 1);
    assert_int_equal(s.environment.environment_texture, 3);
    assert_float_equal(s.environment.environment_strength, 2.5, 0);
    rt_scene_free(&s);

    /* loader errors keep their message, prefixed with the scene location */
    rt_error err;
    rt_scene_init(&s);
    test_write_file(tmp_path("garbage.png"), "not an image", 12);
    const char *text = "material m texture garbage.png\n";
    assert_int_equal(rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", tmp_dir, &err), RT_ERR_INVALID);
    assert_true(strncmp(err.message, "t.txt:1:20: ", 12) == 0);
    assert_non_null(strstr(err.message, tmp_path("garbage.png")));
    rt_scene_free(&s);
    /* a missing image is a warning and the missing-texture rule: the
     * magenta checker in colour slots, nothing in data slots */
    rt_scene_init(&s);
    text = "texture t image nothing.jpg\n"
           "material m texture missing.png normal_map missing.png emission_map t metallic_roughness_map t\n";
    assert_int_equal(rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", tmp_dir, &err), RT_OK);
    const rt_material *mm = &s.materials[rt_scene_find_material(&s, "m")];
    for (int k = 0; k < 2; k++) {
        uint32_t t = k ? mm->emissive_tex.texture : mm->base_color_tex.texture;
        assert_true(t < s.texture_count);
        assert_int_equal(s.textures[t].kind, RT_TEX_CHECKER);
        assert_float_equal(s.textures[t].color_a.x, 1.0, 0);
        assert_float_equal(s.textures[t].color_a.y, 0.0, 0);
    }
    assert_int_equal(mm->normal_tex.texture, RT_NONE);
    assert_int_equal(mm->metal_rough_tex.texture, RT_NONE);
    assert_int_equal(s.image_count, 0);
    rt_scene_free(&s);
    expect_error("environment sky.hdr\n", RT_ERR_IO, "1:13", tmp_path("sky.hdr"));
    static const error_case cases[] = {
        {"texture t image tex.ppm wrap sideways\n", RT_ERR_PARSE, "1:30",
         "expected a wrap mode (repeat|clamp|mirror), got 'sideways'"},
        {"texture t image tex.ppm filter cubic\n", RT_ERR_PARSE, "1:32", "expected a filter (bilinear|nearest)"},
        {"texture t image tex.ppm wrap clamp wrap clamp\n", RT_ERR_INVALID, "1:36", "'wrap' is given twice"},
    };
    expect_errors(cases);
    /* the glTF loader's error, whatever its code, comes with the scene location */
    rt_scene_init(&s);
    text = "model missing.gltf\n";
    assert_int_not_equal(rt_scene_parse_string(&s, NULL, text, strlen(text), "t.txt", tmp_dir, &err), RT_OK);
    assert_true(strncmp(err.message, "t.txt:1:7: ", 11) == 0);
    assert_non_null(strstr(err.message, "missing.gltf"));
    rt_scene_free(&s);
}

/* Relative paths resolve against the scene file's directory. */
static void test_paths_relative_to_scene_file(void **state)
{
    (void)state;
    mkdir(tmp_path("sub"), 0777);
    write_ppm(tmp_path("sub/tex.ppm"));
    const char *scene = "material m texture tex.ppm\nsphere 0 0 0 1 m\n";
    test_write_file(tmp_path("sub/scene.txt"), scene, strlen(scene));
    rt_scene s;
    rt_error err;
    rt_scene_init(&s);
    rt_result r = rt_scene_parse_file(&s, NULL, tmp_path("sub/scene.txt"), &err);
    assert_parsed(r, &err);
    assert_int_equal(s.image_count, 1);
    assert_string_equal(s.images[0].name, tmp_path("sub/tex.ppm"));
    rt_scene_free(&s);

    /* errors in a file name the file */
    const char *bad = "material m\n\nsphere 0 0 0 r m\n";
    test_write_file(tmp_path("sub/bad.txt"), bad, strlen(bad));
    rt_scene_init(&s);
    assert_int_equal(rt_scene_parse_file(&s, NULL, tmp_path("sub/bad.txt"), &err), RT_ERR_PARSE);
    char want[256];
    snprintf(want, sizeof want, "%s:3:14: expected a number for the sphere radius, got 'r'", tmp_path("sub/bad.txt"));
    assert_string_equal(err.message, want);
    rt_scene_free(&s);

    rt_scene_init(&s);
    assert_int_equal(rt_scene_parse_file(&s, NULL, tmp_path("no/such/scene.txt"), &err), RT_ERR_IO);
    snprintf(want, sizeof want, "%s: cannot open", tmp_path("no/such/scene.txt"));
    assert_non_null(strstr(err.message, want));
    rt_scene_free(&s);
}

/* mesh ... translate rotate scale: positions go through T * Rz * Ry * Rx * S. */
static void test_mesh_transform(void **state)
{
    (void)state;
    const char *off = "OFF\n3 1 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n";
    test_write_file(tmp_path("tri.off"), off, strlen(off));
    rt_scene s;
    rt_error err;
    const char *text = "material m color 1 0 0\n"
                       "mesh tri.off m translate 10 20 30 rotate 90 0 90 scale 2 3 4 material_override\n";
    rt_result r = parse(&s, text, &err);
    assert_parsed(r, &err);
    assert_int_equal(s.triangles.count, 1);
    assert_int_equal(s.triangles.material[0], 0);
    /* by hand: scale (2,3,4); Rx 90: (x,y,z) -> (x,-z,y); Rz 90: (x,y,z) -> (-y,x,z); then translate.
     * (1,0,0) -> (2,0,0) -> (2,0,0) -> (0,2,0) -> (10,22,30)
     * (0,1,0) -> (0,3,0) -> (0,0,3) -> (0,0,3) -> (10,20,33)
     * (0,0,1) -> (0,0,4) -> (0,-4,0) -> (4,0,0) -> (14,20,30) */
    rt_vec3 want[3] = {{10, 22, 30}, {10, 20, 33}, {14, 20, 30}};
    for (int k = 0; k < 3; k++) {
        rt_vec3 p = rt_tri_vertex(&s, 0, k);
        int found = 0;
        for (int j = 0; j < 3; j++)
            found |= rt_length(rt_sub(p, want[j])) < 1e-4f;
        assert_true(found);
    }
    rt_scene_free(&s);

    /* a uniform scale and a mesh without a material (gets a default one) */
    r = parse(&s, "mesh tri.off scale 2\n", &err);
    assert_parsed(r, &err);
    assert_int_equal(s.triangles.count, 1);
    rt_box b = rt_scene_bounds(&s);
    assert_vec3(b.hi, 2, 2, 2);
    rt_scene_free(&s);

    expect_error("mesh nothing.obj\n", RT_ERR_IO, "1:6", tmp_path("nothing.obj"));
}

/* ------------------------------------------------------------ robustness */

/* Mutated scenes (byte flips, insertions, deletions, truncations, spliced
 * tokens) must parse or fail cleanly; under ASan/UBSan this also checks
 * memory safety and leaks. Every failure names the file. */
static void test_mutations_do_not_crash(void **state)
{
    (void)state;
    static const char *const pieces[] = {" ", "\n", "\\\n", "#", "\"", "0", "-1", "1e9", "nan", "1.5.2", "x",
                                         "material", "sphere", "light area", "camera gltf 0", "texture", "\t",
                                         "mesh", "quad", "99999999999999999999", "scale", "\r\n", "\x01"};
    const char *base = rt_default_scene_text;
    size_t base_len = strlen(base);
    test_rng rng = {0x5eed5eedu};
    char *buf = malloc(base_len + 1024);
    assert_non_null(buf);
    int failures = 0;
    rt_log_level level = rt_log_get_level();
    rt_log_set_level(RT_LOG_QUIET); /* mutations repeat settings: no warnings */
    for (int iter = 0; iter < 3000; iter++) {
        size_t len = base_len;
        memcpy(buf, base, len);
        int edits = 1 + (int)(test_rng_next(&rng) % 6);
        for (int e = 0; e < edits; e++) {
            size_t at = len ? (size_t)(test_rng_next(&rng) % len) : 0;
            switch (test_rng_next(&rng) % 4) {
            case 0: /* flip a byte */
                if (len)
                    buf[at] = (char)(test_rng_next(&rng) & 0xff);
                break;
            case 1: { /* insert a piece */
                const char *p = pieces[test_rng_next(&rng) % (sizeof pieces / sizeof *pieces)];
                size_t n = strlen(p);
                if (len + n < base_len + 1000) {
                    memmove(buf + at + n, buf + at, len - at);
                    memcpy(buf + at, p, n);
                    len += n;
                }
                break;
            }
            case 2: { /* delete a run */
                size_t n = (size_t)(test_rng_next(&rng) % 16);
                if (at + n > len)
                    n = len - at;
                memmove(buf + at, buf + at + n, len - at - n);
                len -= n;
                break;
            }
            default: /* truncate */
                len = at;
                break;
            }
        }
        rt_scene s;
        rt_error err;
        memset(&err, 0, sizeof err);
        rt_scene_init(&s);
        rt_result r = rt_scene_parse_string(&s, NULL, buf, len, "m.txt", tmp_dir, &err);
        if (r != RT_OK) {
            failures++;
            assert_true(strncmp(err.message, "m.txt:", 6) == 0);
        }
        rt_scene_free(&s);
    }
    free(buf);
    rt_log_set_level(level);
    assert_true(failures > 100); /* the mutations did reach the error paths */
}

/* Participating media (issue 28): the `medium` lines, `scene_medium`, the
 * materials that bound media, and their errors. */
static void test_media(void **state)
{
    (void)state;
    rt_scene s;
    expect_ok("medium fog homogeneous sigma_a 0.1 0.2 0.3 sigma_s 1 2 3 g 0.5 scale 2\n"
              "medium milk homogeneous sigma_s 4 4 4 sigma_a 0 0 0\n"
              "scene_medium fog\n"
              "material box bsdf null interior milk priority 2\n"
              "material glass bsdf dielectric ior 1.33 interior milk exterior fog\n"
              "material plain color 0.5 0.5 0.5\n",
              &s);
    assert_int_equal(s.medium_count, 2);
    assert_string_equal(s.media[0].name, "fog");
    assert_int_equal(s.media[0].kind, RT_MEDIUM_HOMOGENEOUS);
    assert_vec3(s.media[0].sigma_a, 0.2f, 0.4f, 0.6f); /* times the scale */
    assert_vec3(s.media[0].sigma_s, 2, 4, 6);
    assert_float_equal(s.media[0].g, 0.5f, 0);
    assert_float_equal(s.media[1].g, 0.0f, 0);
    assert_int_equal(s.environment.medium, 0);
    assert_int_equal(s.materials[0].bsdf, RT_BSDF_NULL);
    assert_int_equal(s.materials[0].interior_medium, 1);
    assert_int_equal(s.materials[0].exterior_medium, RT_NONE);
    assert_int_equal(s.materials[0].priority, 2);
    assert_int_equal(s.materials[0].alpha_mode, RT_ALPHA_MASK); /* invisible to integrators without media */
    assert_float_equal(s.materials[0].ior, 1.0f, 0);
    assert_int_equal(s.materials[1].interior_medium, 1);
    assert_int_equal(s.materials[1].exterior_medium, 0);
    assert_int_equal(s.materials[2].interior_medium, RT_NONE);
    assert_true(rt_scene_has_media(&s));
    rt_scene_free(&s);
    expect_ok("material plain color 0.5 0.5 0.5\nmedium unused homogeneous sigma_a 1 1 1 sigma_s 1 1 1\n", &s);
    assert_int_equal(s.environment.medium, RT_NONE);
    assert_false(rt_scene_has_media(&s)); /* defined, not used: the surface path tracer renders it */
    rt_scene_free(&s);

    static const error_case cases[] = {
        {"medium f homogeneous sigma_a 1 1 1\n", RT_ERR_PARSE, "1:35", "needs 'sigma_a R G B' and 'sigma_s R G B'"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 -1 1\n", RT_ERR_INVALID, "1:46", "sigma_s (green)"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1 g 1\n", RT_ERR_INVALID, "1:52", "g (Henyey-Greenstein)"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1 scale -2\n", RT_ERR_INVALID, "1:56", "scale"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_a 1 1 1\n", RT_ERR_INVALID, "1:36", "given twice"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1 translate 0 0 0\n", RT_ERR_PARSE, "1:50",
         "expected a medium key (sigma_a, sigma_s, g, scale), got 'translate'"},
        {"medium f foggy sigma_a 1 1 1\n", RT_ERR_PARSE, "1:10", "homogeneous|nanovdb"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1\nmedium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1\n",
         RT_ERR_INVALID, "2:8", "already defined on line 1"},
        {"medium f nanovdb missing.nvdb sigma_a 1 1 1 sigma_s 1 1 1\n", RT_ERR_IO, "1:18", "missing.nvdb"},
        {"scene_medium fog\n", RT_ERR_INVALID, "1:14", "undefined medium 'fog'"},
        {"medium fog homogeneous sigma_a 1 1 1 sigma_s 1 1 1\nscene_medium fgo\n", RT_ERR_INVALID, "2:14",
         "did you mean 'fog'?"},
        {"medium fog homogeneous sigma_a 1 1 1 sigma_s 1 1 1\nscene_medium fog fog\n", RT_ERR_PARSE, "2:18", ""},
        {"material m bsdf null\n", RT_ERR_INVALID, "1:12", "'bsdf null' needs 'interior MEDIUM'"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1\nmaterial m bsdf null interior f color 1 0 0\n",
         RT_ERR_INVALID, "2:33", "does not go with 'bsdf null'"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1\nmaterial m interior f\n", RT_ERR_INVALID, "2:12",
         "needs 'bsdf dielectric' or 'bsdf null'"},
        {"material m bsdf dielectric interior nothing\n", RT_ERR_INVALID, "1:37", "undefined medium 'nothing'"},
        /* subsurface scattering (rt/scene/subsurface.h) */
        {"material m subsurface_radius 1 1 1\n", RT_ERR_INVALID, "1:12", "needs 'bsdf dielectric'"},
        {"material m bsdf dielectric subsurface_albedo 1 1 1\n", RT_ERR_INVALID, "1:28", "needs 'subsurface_radius"},
        {"material m bsdf dielectric subsurface_radius 1 0 1\n", RT_ERR_INVALID, "1:28", "above 0 in every channel"},
        {"material m bsdf dielectric subsurface_radius 1 nan 1\n", RT_ERR_PARSE, "1:48", ""},
        {"material m bsdf dielectric subsurface_radius 1 1 1 subsurface_albedo 1.5 1 1\n", RT_ERR_INVALID, "1:70",
         "subsurface_albedo"},
        {"material m bsdf dielectric subsurface_radius 1 1 1 subsurface_g 1\n", RT_ERR_INVALID, "1:65", "subsurface_g"},
        {"medium f homogeneous sigma_a 1 1 1 sigma_s 1 1 1\n"
         "material m bsdf dielectric interior f subsurface_radius 1 1 1\n",
         RT_ERR_INVALID, "2:28", "'interior' does not go with 'subsurface_radius'"},
    };
    expect_errors(cases);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_scene),
        cmocka_unit_test(test_cornell_file_matches_default),
        cmocka_unit_test(test_all_scene_files),
        cmocka_unit_test(test_spheres_scene),
        cmocka_unit_test(test_textures_scene),
        cmocka_unit_test(test_docs_example),
        cmocka_unit_test(test_camera_gltf),
        cmocka_unit_test(test_settings_values),
        cmocka_unit_test(test_settings_table_defaults),
        cmocka_unit_test(test_settings_text_form),
        cmocka_unit_test(test_settings_table_in_docs),
        cmocka_unit_test(test_material_keys_in_docs),
        cmocka_unit_test(test_camera_values),
        cmocka_unit_test(test_material_values),
        cmocka_unit_test(test_primitive_values),
        cmocka_unit_test(test_light_values),
        cmocka_unit_test(test_comments_and_continuations),
        cmocka_unit_test(test_errors_syntax),
        cmocka_unit_test(test_conductor_material),
        cmocka_unit_test(test_errors_values),
        cmocka_unit_test(test_errors_names),
        cmocka_unit_test(test_many_names),
        cmocka_unit_test(test_textures_from_files),
        cmocka_unit_test(test_paths_relative_to_scene_file),
        cmocka_unit_test(test_mesh_transform),
        cmocka_unit_test(test_mutations_do_not_crash),
        cmocka_unit_test(test_media),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
