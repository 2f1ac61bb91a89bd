/* test_mesh_io.c - OBJ/MTL, PLY and OFF readers.
 *
 * Small files are written by the tests into a fresh directory under /tmp and
 * loaded back; every feature is checked against the values written. The
 * shared scans (igea, the Stanford bunny, both Cornell boxes) are checked
 * against the triangle counts and AABBs in assets/MANIFEST.md.
 */
#include "test_util.h"

#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <time.h>
#include <unistd.h>

#include "../src/io/mesh_buffer.h"
#include "../src/io/mesh_text.h"
#include "rt/base/log.h"
#include "rt/io/mesh_io.h"
#include "rt/scene/texture.h"

static char tmpdir[256];

static const char *tpath(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
    return buf[k];
}

static void write_text(const char *name, const char *text) { test_write_file(tpath(name), text, strlen(text)); }

typedef struct loaded {
    rt_scene s;
    rt_error err;
    rt_mesh_load_stats st;
    rt_result r;
    uint32_t def; /* the caller's material */
} loaded;

static void load(loaded *l, const char *path, const rt_mat4 *m)
{
    rt_scene_init(&l->s);
    memset(&l->err, 0, sizeof l->err);
    rt_material mat;
    rt_material_default(&mat, "caller");
    l->def = rt_scene_add_material(&l->s, &mat);
    rt_mesh_options opt = {.transform = m, .material = l->def};
    l->r = rt_mesh_load(&l->s, path, &opt, &l->st, &l->err);
}

static void load_ok(loaded *l, const char *path, const rt_mat4 *m)
{
    load(l, path, m);
    if (l->r != RT_OK)
        fprintf(stderr, "unexpected failure: %s\n", l->err.message);
    assert_int_equal(l->r, RT_OK);
}

/* Loads and expects failure with code, and `needle` in the message. */
static void load_fail(const char *path, rt_result code, const char *needle)
{
    loaded l;
    load(&l, path, NULL);
    if (l.r != code || !strstr(l.err.message, needle))
        fprintf(stderr, "expected %s with '%s', got %s: '%s'\n", rt_result_name(code), needle, rt_result_name(l.r),
                l.err.message);
    assert_int_equal(l.r, code);
    assert_non_null(strstr(l.err.message, needle));
    assert_int_equal(l.s.triangles.count, 0); /* nothing half-loaded */
    assert_int_equal(l.s.vertices.count, 0);
    rt_scene_free(&l.s);
}

static rt_vec3 tri_v(const rt_scene *s, size_t t, int k) { return rt_tri_vertex(s, t, k); }

static void assert_vec3(rt_vec3 a, float x, float y, float z, float tol)
{
    if (fabsf(a.x - x) > tol || fabsf(a.y - y) > tol || fabsf(a.z - z) > tol)
        fprintf(stderr, "got (%g %g %g), expected (%g %g %g)\n", a.x, a.y, a.z, x, y, z);
    assert_true(fabsf(a.x - x) <= tol && fabsf(a.y - y) <= tol && fabsf(a.z - z) <= tol);
}

/* Runs fn with stderr captured into a file; returns how many times needle appears. */
static int count_in_stderr(void (*fn)(void *), void *arg, const char *needle)
{
    const char *cap = tpath("stderr.txt");
    fflush(stderr);
    int saved = dup(2);
    int fd = open(cap, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    fn(arg);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    FILE *f = fopen(cap, "rb");
    assert_non_null(f);
    static char text[65536];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    int count = 0;
    for (const char *p = text; (p = strstr(p, needle)); p += strlen(needle))
        count++;
    return count;
}

/* ------------------------------------------------------------------ OBJ */

static void test_obj_polygons(void **state)
{
    (void)state;
    write_text("poly.obj", "# quad and pentagon\n"
                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                           "v 0 0 1\nv 1 0 1\nv 1.5 0.5 1\nv 1 1 1\nv 0 1 1\n"
                           "f 1 2 3 4\n"
                           "f 5 6 7 8 9\n");
    loaded l;
    load_ok(&l, tpath("poly.obj"), NULL);
    assert_int_equal(l.s.triangles.count, 2 + 3);
    assert_int_equal(l.st.triangles, 5);
    assert_int_equal(l.st.vertices, 9);
    /* fan from the first corner, winding kept */
    assert_vec3(tri_v(&l.s, 0, 0), 0, 0, 0, 0);
    assert_vec3(tri_v(&l.s, 0, 1), 1, 0, 0, 0);
    assert_vec3(tri_v(&l.s, 0, 2), 1, 1, 0, 0);
    assert_vec3(tri_v(&l.s, 1, 2), 0, 1, 0, 0);
    float area = 0;
    for (size_t t = 2; t < 5; t++) {
        rt_vec3 n = rt_cross(rt_sub(tri_v(&l.s, t, 1), tri_v(&l.s, t, 0)), rt_sub(tri_v(&l.s, t, 2), tri_v(&l.s, t, 0)));
        assert_true(n.z > 0);
        area += 0.5f * rt_length(n);
    }
    assert_float_equal(area, 1.25f, 1e-5); /* unit square plus a triangle of area 0.25 */
    for (size_t t = 0; t < 5; t++) {
        assert_int_equal(l.s.triangles.material[t], l.def);
        assert_int_equal(l.s.triangles.flags[t], 0); /* no normals, no UVs: flat, generated UVs */
    }
    rt_scene_free(&l.s);
}

static void test_obj_concave_quad(void **state)
{
    (void)state;
    /* an arrowhead: corner 3 is the reflex one, so the 0-2 fan diagonal lies outside */
    write_text("concave.obj", "v 0 1 0\nv 0 0 0\nv 1 0 0\nv 0.5 0.3 0\nf 1 2 3 4\n");
    loaded l;
    load_ok(&l, tpath("concave.obj"), NULL);
    assert_int_equal(l.s.triangles.count, 2);
    float area = 0;
    for (size_t t = 0; t < 2; t++) {
        rt_vec3 n = rt_cross(rt_sub(tri_v(&l.s, t, 1), tri_v(&l.s, t, 0)), rt_sub(tri_v(&l.s, t, 2), tri_v(&l.s, t, 0)));
        assert_true(n.z > 0); /* both halves face the polygon's way */
        area += 0.5f * rt_length(n);
    }
    assert_float_equal(area, 0.4f, 1e-6); /* the shoelace area of the arrowhead */
    rt_scene_free(&l.s);
}

/* Random star-shaped (hence simple, mostly concave) polygons in random planes:
 * a correct triangulation has n - 2 triangles, all facing the polygon's way,
 * whose areas add up to the polygon's. A fan gets this wrong for most of them. */
static void test_triangulate_concave(void **state)
{
    (void)state;
    test_rng rng = {77};
    rt_vec3 pos[64];
    uint32_t vidx[64], tri[3 * 62];
    for (int iter = 0; iter < 2000; iter++) {
        size_t n = 5 + (size_t)(test_rng_next(&rng) % 60);
        rt_mat4 rot = rt_mat4_mul(rt_mat4_rotate_axis(0, 360.0f * test_rng_float(&rng)),
                                  rt_mat4_rotate_axis(1, 360.0f * test_rng_float(&rng)));
        bool reverse = test_rng_next(&rng) & 1;
        double area2d = 0;
        float px[64], py[64];
        for (size_t i = 0; i < n; i++) {
            float ang = 2.0f * RT_PI * ((float)i + 0.1f + 0.8f * test_rng_float(&rng)) / (float)n;
            float rad = 0.3f + 0.7f * test_rng_float(&rng);
            size_t k = reverse ? n - 1 - i : i;
            px[k] = rad * cosf(ang);
            py[k] = rad * sinf(ang);
        }
        for (size_t i = 0; i < n; i++) {
            area2d += 0.5 * ((double)px[i] * py[(i + 1) % n] - (double)px[(i + 1) % n] * py[i]);
            pos[i] = rt_mat4_point(&rot, rt_v3(px[i], py[i], 0.0f));
            vidx[i] = (uint32_t)i;
        }
        rt_vec3 normal = rt_mat4_vector(&rot, rt_v3(0, 0, area2d > 0 ? 1.0f : -1.0f));
        size_t nt = rt_mesh_triangulate(pos, vidx, n, tri);
        assert_int_equal(nt, n - 2);
        double sum = 0;
        for (size_t t = 0; t < nt; t++) {
            for (int c = 0; c < 3; c++)
                assert_true(tri[3 * t + (size_t)c] < n);
            rt_vec3 a = pos[tri[3 * t]], b = pos[tri[3 * t + 1]], c = pos[tri[3 * t + 2]];
            rt_vec3 cr = rt_cross(rt_sub(b, a), rt_sub(c, a));
            assert_true(rt_dot(cr, normal) >= -1e-6f); /* same way as the polygon */
            sum += 0.5 * rt_length(cr);
        }
        if (fabs(sum - fabs(area2d)) > 1e-4 * fabs(area2d))
            fprintf(stderr, "n=%zu: triangles cover %g, polygon %g\n", n, sum, fabs(area2d));
        assert_true(fabs(sum - fabs(area2d)) <= 1e-4 * fabs(area2d));
    }
    /* an L-shaped hexagon through the OBJ reader */
    write_text("ell.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 3 4 5 6 1 2\n");
    loaded l;
    load_ok(&l, tpath("ell.obj"), NULL);
    assert_int_equal(l.s.triangles.count, 4);
    float area = 0;
    for (size_t t = 0; t < 4; t++) {
        rt_vec3 cr = rt_cross(rt_sub(tri_v(&l.s, t, 1), tri_v(&l.s, t, 0)), rt_sub(tri_v(&l.s, t, 2), tri_v(&l.s, t, 0)));
        assert_true(cr.z >= 0);
        area += 0.5f * rt_length(cr);
    }
    assert_float_equal(area, 3.0f, 1e-6);
    rt_scene_free(&l.s);
}

static void test_obj_negative_indices_and_forms(void **state)
{
    (void)state;
    write_text("forms.obj", "o thing\ng a b\ns 1\n"
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                            "vt 0 0\nvt 1 0\nvt 0 1\n"
                            "vn 0 0 2\nvn 0 0 1\nvn 0 0 1\n"
                            "f -3/-3/-3 -2/-2/-2 -1/-1/-1\n" /* v/vt/vn, relative */
                            "f 1//1 2//2 3//3\n"             /* v//vn */
                            "g other\ns off\n"
                            "f 1/1 2/2 3/3\n"                /* v/vt */
                            "f 1 2 3\n"                      /* v */
                            "f 1/1/1 2/2/2 3/3/3\n");        /* same triple as the first face: shared vertices */
    loaded l;
    load_ok(&l, tpath("forms.obj"), NULL);
    const rt_scene *s = &l.s;
    assert_int_equal(s->triangles.count, 5);
    assert_int_equal(s->triangles.flags[0], RT_TRI_SMOOTH | RT_TRI_UV);
    assert_int_equal(s->triangles.flags[1], RT_TRI_SMOOTH);
    assert_int_equal(s->triangles.flags[2], RT_TRI_UV);
    assert_int_equal(s->triangles.flags[3], 0);
    assert_int_equal(s->triangles.flags[4], RT_TRI_SMOOTH | RT_TRI_UV);
    /* four distinct (v, vt, vn) combinations per position: 4 x 3 vertices, the last face reuses the first's */
    assert_int_equal(s->vertices.count, 12);
    for (int k = 0; k < 3; k++)
        assert_int_equal(s->triangles.index[12 + k], s->triangles.index[k]);
    const uint32_t *ix = s->triangles.index;
    /* normals normalised; v flipped in UVs */
    assert_vec3(s->vertices.normal[ix[0]], 0, 0, 1, 1e-6f);
    rt_vec2 uv = s->vertices.uv0[ix[2]];
    assert_float_equal(uv.x, 0.0f, 0);
    assert_float_equal(uv.y, 0.0f, 0); /* vt 0 1 -> (0, 0): top-left */
    uv = s->vertices.uv0[ix[1]];
    assert_float_equal(uv.x, 1.0f, 0);
    assert_float_equal(uv.y, 1.0f, 0);
    assert_vec3(s->vertices.position[ix[1]], 1, 0, 0, 0);
    rt_scene_free(&l.s);
}

static void test_obj_smoothing_groups(void **state)
{
    (void)state;
    /* a roof: two faces over the edge A-B, facing (0,-1,1) and (0,1,1) */
    const char *verts = "v 0 0 0\nv 1 0 0\nv 0 1 1\nv 0 -1 1\n";
    char text[256];
    snprintf(text, sizeof text, "%ss 1\nf 1 2 3\nf 2 1 4\n", verts);
    write_text("sg1.obj", text);
    loaded l;
    load_ok(&l, tpath("sg1.obj"), NULL);
    const rt_scene *s = &l.s;
    assert_int_equal(s->vertices.count, 4);
    assert_int_equal(s->triangles.flags[0], RT_TRI_SMOOTH);
    assert_int_equal(s->triangles.flags[1], RT_TRI_SMOOTH);
    float h = sqrtf(0.5f);
    assert_vec3(s->vertices.normal[s->triangles.index[0]], 0, 0, 1, 1e-6f);  /* A: the average */
    assert_vec3(s->vertices.normal[s->triangles.index[2]], 0, -h, h, 1e-6f); /* C: its face's */
    rt_scene_free(&l.s);

    snprintf(text, sizeof text, "%ss 1\nf 1 2 3\ns 2\nf 2 1 4\n", verts);
    write_text("sg2.obj", text);
    load_ok(&l, tpath("sg2.obj"), NULL);
    assert_int_equal(l.s.vertices.count, 6); /* A and B split between the groups */
    assert_vec3(l.s.vertices.normal[l.s.triangles.index[0]], 0, -h, h, 1e-6f);
    assert_vec3(l.s.vertices.normal[l.s.triangles.index[4]], 0, h, h, 1e-6f);
    rt_scene_free(&l.s);

    snprintf(text, sizeof text, "%ss 1\ns off\nf 1 2 3\nf 2 1 4\n", verts);
    write_text("sg3.obj", text);
    load_ok(&l, tpath("sg3.obj"), NULL);
    assert_int_equal(l.s.vertices.count, 4);
    assert_int_equal(l.s.triangles.flags[0], 0);
    rt_scene_free(&l.s);
}

/* The missing-texture rule (rt/scene/texture.h): a map_Kd whose file does
 * not exist gets the magenta checker, a missing bump map is left out, and
 * an image that exists but is not one is an error naming the map_Kd line. */
static void test_obj_missing_texture(void **state)
{
    (void)state;
    write_text("miss.mtl", "newmtl a\nKd 1 1 1\nmap_Kd gone.png\nmap_Bump gone_n.png\n");
    write_text("miss.obj", "mtllib miss.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    loaded l;
    load_ok(&l, tpath("miss.obj"), NULL);
    uint32_t a = rt_scene_find_material(&l.s, "miss.obj:a");
    assert_true(a != RT_NONE);
    uint32_t t = l.s.materials[a].base_color_tex.texture;
    assert_true(t < l.s.texture_count);
    assert_int_equal(l.s.textures[t].kind, RT_TEX_CHECKER);
    assert_float_equal(l.s.textures[t].color_a.x, 1.0, 0);
    assert_float_equal(l.s.textures[t].color_a.y, 0.0, 0);
    assert_int_equal(l.s.materials[a].normal_tex.texture, RT_NONE);
    assert_int_equal(l.s.image_count, 0);
    rt_scene_free(&l.s);
    write_text("junk.png", "not an image");
    write_text("junk.mtl", "newmtl a\nKd 1 1 1\n\nmap_Kd junk.png\n");
    write_text("junk.obj", "mtllib junk.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    load_fail(tpath("junk.obj"), RT_ERR_INVALID, "junk.mtl:4: map_Kd: ");
}

static void test_obj_mtl(void **state)
{
    (void)state;
    /* a 2x2 PPM texture that stb_image reads */
    static const unsigned char ppm[] = "P6\n2 2\n255\n\xff\x00\x00\x00\xff\x00\x00\x00\xff\xff\xff\xff";
    test_write_file(tpath("tex.ppm"), ppm, sizeof ppm - 1);
    write_text("mats.mtl", "# materials\n"
                           "newmtl red\n  Kd 0.8 0.1 0.05  # comment\n  Ks 0.5 0.5 0.5\n  Ns 64\n  Ni 1.33\n  d 0.5\n"
                           "  ke 1 2 3\n  map_Kd -s 1 1 1 tex.ppm\n  map_bump -bm 0.25 tex.ppm\n" /* keywords without case */
                           "newmtl glass\n  Kd 1 1 1\n  Ni 1.5\n  illum 7\n  Tf 0.9 1 0.9\n  Tr 0.75\n"
                           "newmtl mirror\n  illum 3\n  Ks 0.6 0.7 0.8\n"
                           "newmtl lamp\n  Ka 20 20 20\n"
                           "newmtl fade\n  Tr 0.25\n  Pr 0.3\n  Pm 1\n");
    write_text("mats.obj", "mtllib mats.mtl\n"
                           "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                           "f 1 2 3\n" /* before usemtl: caller's material */
                           "usemtl red\nf 1 2 3\n"
                           "usemtl glass\nf 1 2 3\n"
                           "usemtl mirror\nf 1 2 3\n"
                           "usemtl lamp\nf 1 2 3\n"
                           "usemtl fade\nf 1 2 3\n"
                           "usemtl red\nf 1 2 3\n");
    loaded l;
    load_ok(&l, tpath("mats.obj"), NULL);
    rt_scene *s = &l.s;
    assert_int_equal(s->triangles.count, 7);
    assert_int_equal(l.st.materials, 5);
    assert_int_equal(s->triangles.material[0], l.def);
    uint32_t red = rt_scene_find_material(s, "mats.obj:red");
    uint32_t glass = rt_scene_find_material(s, "mats.obj:glass");
    uint32_t mirror = rt_scene_find_material(s, "mats.obj:mirror");
    uint32_t lamp = rt_scene_find_material(s, "mats.obj:lamp");
    uint32_t fade = rt_scene_find_material(s, "mats.obj:fade");
    assert_true(red != RT_NONE && glass != RT_NONE && mirror != RT_NONE && lamp != RT_NONE && fade != RT_NONE);
    assert_int_equal(s->triangles.material[1], red);
    assert_int_equal(s->triangles.material[2], glass);
    assert_int_equal(s->triangles.material[3], mirror);
    assert_int_equal(s->triangles.material[4], lamp);
    assert_int_equal(s->triangles.material[5], fade);
    assert_int_equal(s->triangles.material[6], red);
    const rt_material *m = &s->materials[red];
    assert_vec3(m->color, 0.8f, 0.1f, 0.05f, 0);
    assert_float_equal(m->specular, 0.5f, 1e-6);
    assert_float_equal(m->shininess, 64.0f, 0);
    assert_float_equal(m->ior, 1.33f, 0);
    assert_float_equal(m->alpha, 0.5f, 0);
    assert_int_equal(m->alpha_mode, RT_ALPHA_BLEND);
    assert_vec3(m->emission, 1, 2, 3, 0);
    assert_float_equal(m->normal_scale, 0.25f, 0);
    assert_true(m->base_color_tex.texture != RT_NONE && m->base_color_tex.texture < s->texture_count);
    assert_true(m->normal_tex.texture != RT_NONE && m->normal_tex.texture < s->texture_count);
    const rt_texture *tex = &s->textures[m->base_color_tex.texture];
    assert_int_equal(tex->kind, RT_TEX_IMAGE);
    assert_int_equal(s->images[tex->image].width, 2);
    /* the same file is decoded once */
    assert_int_equal(s->textures[m->normal_tex.texture].image, tex->image);
    /* texel (0,0) is red: UV (0,0) is the image's top-left, sampled as sRGB colour */
    rt_vec4 c = rt_texture_sample(s, m->base_color_tex.texture, rt_v2(0.25f, 0.25f), true);
    assert_true(c.x > 0.99f && c.y < 0.01f);
    m = &s->materials[glass];
    assert_float_equal(m->transmission, 1.0f, 0);
    assert_float_equal(m->ior, 1.5f, 0);
    assert_vec3(m->transmission_color, 0.9f, 1, 0.9f, 0);
    assert_float_equal(m->alpha, 1.0f, 0); /* glass is transparent by refraction, not alpha */
    m = &s->materials[mirror];
    assert_float_equal(m->reflectivity, 0.8f, 0);
    m = &s->materials[lamp];
    assert_vec3(m->emission, 20, 20, 20, 0);
    m = &s->materials[fade];
    assert_float_equal(m->alpha, 0.75f, 0);
    assert_float_equal(m->roughness, 0.3f, 1e-7);
    assert_float_equal(m->metallic, 1.0f, 0);
    rt_scene_free(&l.s);

    /* override: every face gets the caller's material and no MTL is read */
    rt_scene_init(&l.s);
    rt_material d;
    rt_material_default(&d, "only");
    uint32_t only = rt_scene_add_material(&l.s, &d);
    rt_mesh_options only_opt = {.material = only, .override_material = true};
    assert_int_equal(rt_mesh_load(&l.s, tpath("mats.obj"), &only_opt, &l.st, &l.err), RT_OK);
    assert_int_equal(l.s.material_count, 1);
    for (size_t t = 0; t < l.s.triangles.count; t++)
        assert_int_equal(l.s.triangles.material[t], only);
    rt_scene_free(&l.s);
}

static void load_warn_file(void *arg)
{
    loaded *l = arg;
    load(l, tpath("warn.obj"), NULL);
}

static void test_obj_warnings(void **state)
{
    (void)state;
    write_text("warn.obj", "mtllib missing.mtl\n"
                           "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                           "frobnicate 1\nfrobnicate 2\ncurv 1 2\nfrobnicate 3\n"
                           "usemtl nosuch\n"
                           "f 1 2 3\n");
    loaded l;
    assert_int_equal(count_in_stderr(load_warn_file, &l, "'frobnicate'"), 1);
    assert_int_equal(l.r, RT_OK);
    assert_int_equal(l.s.triangles.count, 1);
    assert_int_equal(l.s.triangles.material[0], l.def); /* unknown usemtl: the caller's */
    rt_scene_free(&l.s);
    assert_int_equal(count_in_stderr(load_warn_file, &l, "missing.mtl"), 1);
    rt_scene_free(&l.s);
    assert_int_equal(count_in_stderr(load_warn_file, &l, "nosuch"), 1);
    rt_scene_free(&l.s);
}

/* Many distinct material names and many (v, vt) combinations on one
 * position: each usemtl and each (v, vt) pair counted once. That they stay
 * fast (hash tables, not linear searches) is timed by make bench-load. */
static void test_obj_many_names(void **state)
{
    (void)state;
    const int n = 30000;
    size_t cap = (size_t)n * 64 + 256, len = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    len += (size_t)snprintf(text + len, cap - len, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(text + len, cap - len, "vt %d 0\nusemtl m%d\nf 1/%d 2/1 3/1\n", i, i, i + 1);
    test_write_file(tpath("many.obj"), text, len);
    free(text);
    loaded l;
    rt_log_set_level(RT_LOG_QUIET); /* 30000 unknown-material warnings */
    load_ok(&l, tpath("many.obj"), NULL);
    rt_log_set_level(RT_LOG_NORMAL);
    assert_int_equal(l.s.triangles.count, (size_t)n);
    assert_int_equal(l.s.vertices.count, (size_t)n + 2);
    rt_scene_free(&l.s);
}

static void test_obj_errors(void **state)
{
    (void)state;
    write_text("e1.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
    load_fail(tpath("e1.obj"), RT_ERR_INVALID, "e1.obj:5:");
    write_text("e2.obj", "v 0 0 0\nv 1 0 zero\n");
    load_fail(tpath("e2.obj"), RT_ERR_PARSE, "e2.obj:2:7: malformed number 'zero'");
    write_text("e3.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
    load_fail(tpath("e3.obj"), RT_ERR_INVALID, "e3.obj:4:");
    write_text("e4.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n");
    load_fail(tpath("e4.obj"), RT_ERR_INVALID, "e4.obj:4:3: vertex index -4 out of range");
    write_text("e5.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    load_fail(tpath("e5.obj"), RT_ERR_INVALID, "e5.obj:4:");
    write_text("e6.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/2 2/1 3/1\n");
    load_fail(tpath("e6.obj"), RT_ERR_INVALID, "texture coordinate index 2 out of range");
    write_text("e7.obj", "v 0 0 nan\n");
    load_fail(tpath("e7.obj"), RT_ERR_PARSE, "e7.obj:1:7: number is not finite");
    write_text("e8.obj", "v 0 0 1e39\n");
    load_fail(tpath("e8.obj"), RT_ERR_PARSE, "not finite");
    write_text("e9.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2 3\n");
    load_fail(tpath("e9.obj"), RT_ERR_PARSE, "e9.obj:4:3: malformed face corner");
    load_fail(tpath("does-not-exist.obj"), RT_ERR_IO, "does-not-exist.obj");
    write_text("bad.mtl", "newmtl a\nKd 1 x 1\n");
    write_text("e10.obj", "mtllib bad.mtl\nv 0 0 0\n");
    load_fail(tpath("e10.obj"), RT_ERR_PARSE, "bad.mtl:2:");
}

static void test_dispatch(void **state)
{
    (void)state;
    write_text("upper.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    loaded l;
    load_ok(&l, tpath("upper.OBJ"), NULL);
    assert_int_equal(l.s.triangles.count, 1);
    rt_scene_free(&l.s);
    /* no caller material: a default one is made, once */
    rt_scene_init(&l.s);
    rt_mesh_options none = {.material = RT_NONE}, none_override = {.material = RT_NONE, .override_material = true};
    assert_int_equal(rt_mesh_load(&l.s, tpath("upper.OBJ"), &none, &l.st, &l.err), RT_OK);
    assert_int_equal(rt_mesh_load(&l.s, tpath("upper.OBJ"), &none_override, NULL, &l.err), RT_OK);
    assert_int_equal(l.s.material_count, 2);
    assert_string_equal(l.s.materials[0].name, "upper.OBJ:default");
    assert_int_equal(l.s.triangles.material[0], 0);
    assert_int_equal(l.s.triangles.material[1], 1);
    rt_scene_free(&l.s);
    write_text("mesh.stl", "solid\n");
    load_fail(tpath("mesh.stl"), RT_ERR_UNSUPPORTED, "unknown mesh format '.stl'");
    load_fail(tpath("noext"), RT_ERR_UNSUPPORTED, "no file extension");
}

static void test_transform(void **state)
{
    (void)state;
    write_text("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 1\nf 1//1 2//1 3//1\n");
    /* world = translate(1,2,3) * scale(-2, 1, 3): a mirror in x */
    rt_mat4 m = rt_mat4_mul(rt_mat4_translate(rt_v3(1, 2, 3)), rt_mat4_scale(rt_v3(-2, 1, 3)));
    loaded l;
    load_ok(&l, tpath("tri.obj"), &m);
    const rt_scene *s = &l.s;
    assert_int_equal(s->triangles.count, 1);
    rt_vec3 a = tri_v(s, 0, 0), b = tri_v(s, 0, 1), c = tri_v(s, 0, 2);
    /* the corners are the transformed ones, with the last two swapped */
    assert_vec3(a, 1, 2, 3, 0);
    assert_vec3(b, 1, 3, 3, 0);
    assert_vec3(c, -1, 2, 3, 0);
    /* the geometric normal cross(e1, e2) still points along the transformed normal (here +z) */
    rt_vec3 ng = rt_cross(rt_sub(b, a), rt_sub(c, a));
    assert_true(ng.z > 0 && fabsf(ng.x) < 1e-6f && fabsf(ng.y) < 1e-6f);
    /* vertex normal: inverse transpose of diag(-2,1,3) on (1,0,1), normalised = (-1/2, 0, 1/3) / |.| */
    float len = sqrtf(0.25f + 1.0f / 9.0f);
    assert_vec3(s->vertices.normal[s->triangles.index[0]], -0.5f / len, 0, (1.0f / 3.0f) / len, 1e-6f);
    rt_scene_free(&l.s);

    /* without the mirror the winding is kept */
    m = rt_mat4_scale(rt_v3(2, 2, 2));
    load_ok(&l, tpath("tri.obj"), &m);
    assert_vec3(tri_v(&l.s, 0, 1), 2, 0, 0, 0);
    rt_scene_free(&l.s);

    /* a singular transform is refused */
    m = rt_mat4_scale(rt_v3(1, 0, 1));
    load(&l, tpath("tri.obj"), &m);
    assert_int_equal(l.r, RT_ERR_INVALID);
    assert_non_null(strstr(l.err.message, "singular"));
    assert_int_equal(l.s.triangles.count, 0);
    rt_scene_free(&l.s);
}

/* ------------------------------------------------------------------ PLY */

/* A small mesh in every PLY encoding: vertices with an unknown scalar and an
 * unknown list, uchar colours; a quad and a triangle; an unknown element in
 * between. */
typedef struct ply_out {
    unsigned char buf[4096];
    size_t n;
    int format; /* 0 ascii, 1 LE, 2 BE */
} ply_out;

static void put_raw(ply_out *o, const void *p, size_t n, bool swap)
{
    assert_true(o->n + n <= sizeof o->buf);
    for (size_t i = 0; i < n; i++)
        o->buf[o->n + i] = ((const unsigned char *)p)[swap ? n - 1 - i : i];
    o->n += n;
}

static void put_text(ply_out *o, const char *t) { put_raw(o, t, strlen(t), false); }

static void put_f(ply_out *o, float f)
{
    if (o->format == 0) {
        char t[32];
        snprintf(t, sizeof t, "%.9g ", f);
        put_text(o, t);
    } else
        put_raw(o, &f, 4, o->format == 2);
}

static void put_i(ply_out *o, long v, int size)
{
    if (o->format == 0) {
        char t[32];
        snprintf(t, sizeof t, "%ld ", v);
        put_text(o, t);
        return;
    }
    unsigned char b[4];
    for (int i = 0; i < size; i++)
        b[i] = (unsigned char)((unsigned long)v >> (8 * i));
    put_raw(o, b, (size_t)size, o->format == 2); /* b is little-endian */
}

static void put_eol(ply_out *o)
{
    if (o->format == 0)
        put_text(o, "\n");
}

static const float ply_pos[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0.25f, 1.0f / 3.0f}};
static const int ply_col[5][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {128, 128, 128}, {255, 255, 255}};

static size_t make_ply(ply_out *o, int format)
{
    static const char *fmt[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    o->n = 0;
    o->format = format;
    char head[1024];
    snprintf(head, sizeof head,
             "ply\nformat %s 1.0\ncomment made by test_mesh_io\n"
             "element vertex 5\nproperty float x\nproperty float32 y\nproperty float z\n"
             "property int16 quality\nproperty list uint8 int32 tags\n"
             "property uchar red\nproperty uint8 green\nproperty uchar blue\n"
             "element edge 2\nproperty int vertex1\nproperty int vertex2\n"
             "element face 2\nproperty list uchar int vertex_indices\nproperty uchar flags\n"
             "end_header\n",
             fmt[format]);
    put_text(o, head);
    for (int v = 0; v < 5; v++) {
        put_f(o, ply_pos[v][0]);
        put_f(o, ply_pos[v][1]);
        put_f(o, ply_pos[v][2]);
        put_i(o, -7 * v, 2);
        put_i(o, v % 3, 1);
        for (int k = 0; k < v % 3; k++)
            put_i(o, 1000 + k, 4);
        for (int k = 0; k < 3; k++)
            put_i(o, ply_col[v][k], 1);
        put_eol(o);
    }
    for (int e = 0; e < 2; e++) {
        put_i(o, e, 4);
        put_i(o, e + 1, 4);
        put_eol(o);
    }
    put_i(o, 4, 1);
    for (int k = 0; k < 4; k++)
        put_i(o, k, 4);
    put_i(o, 9, 1);
    put_eol(o);
    put_i(o, 3, 1);
    put_i(o, 0, 4);
    put_i(o, 1, 4);
    put_i(o, 4, 4);
    put_i(o, 9, 1);
    put_eol(o);
    return o->n;
}

static void test_ply_encodings(void **state)
{
    (void)state;
    static const char *names[] = {"m_ascii.ply", "m_le.ply", "m_be.ply"};
    loaded l[3];
    for (int f = 0; f < 3; f++) {
        ply_out o;
        make_ply(&o, f);
        test_write_file(tpath(names[f]), o.buf, o.n);
        load_ok(&l[f], tpath(names[f]), NULL);
        const rt_scene *s = &l[f].s;
        assert_int_equal(s->triangles.count, 3);
        assert_int_equal(s->vertices.count, 5);
        assert_non_null(s->vertices.color);
        for (int v = 0; v < 5; v++) {
            assert_vec3(s->vertices.position[v], ply_pos[v][0], ply_pos[v][1], ply_pos[v][2], 0);
            for (int k = 0; k < 3; k++)
                assert_float_equal((&s->vertices.color[v].x)[k], ply_col[v][k] / 255.0f, 1e-7);
            assert_float_equal(s->vertices.color[v].w, 1.0f, 0);
        }
        static const uint32_t want[9] = {0, 1, 2, 0, 2, 3, 0, 1, 4};
        for (int k = 0; k < 9; k++)
            assert_int_equal(s->triangles.index[k], want[k]);
        for (int t = 0; t < 3; t++) {
            assert_int_equal(s->triangles.flags[t], RT_TRI_COLOR);
            assert_int_equal(s->triangles.material[t], l[f].def);
        }
    }
    /* identical buffers, bit for bit */
    for (int f = 1; f < 3; f++) {
        assert_memory_equal(l[0].s.vertices.position, l[f].s.vertices.position, 5 * sizeof(rt_vec3));
        assert_memory_equal(l[0].s.vertices.color, l[f].s.vertices.color, 5 * sizeof(rt_vec4));
        assert_memory_equal(l[0].s.triangles.index, l[f].s.triangles.index, 9 * sizeof(uint32_t));
    }
    for (int f = 0; f < 3; f++)
        rt_scene_free(&l[f].s);

    /* truncated binary: the error names the byte offset */
    for (int f = 1; f < 3; f++) {
        ply_out o;
        make_ply(&o, f);
        test_write_file(tpath("trunc.ply"), o.buf, o.n - 3);
        load_fail(tpath("trunc.ply"), RT_ERR_PARSE, ": byte ");
        /* every cut is refused cleanly (none of them can be a valid file) */
        rt_log_set_level(RT_LOG_QUIET);
        for (size_t cut = 0; cut < o.n; cut++) {
            test_write_file(tpath("trunc.ply"), o.buf, cut);
            loaded t;
            load(&t, tpath("trunc.ply"), NULL);
            assert_int_not_equal(t.r, RT_OK);
            rt_scene_free(&t.s);
        }
        rt_log_set_level(RT_LOG_NORMAL);
    }
    /* truncated ascii: a line number */
    {
        ply_out o;
        make_ply(&o, 0);
        test_write_file(tpath("trunc_a.ply"), o.buf, o.n - 6);
        load_fail(tpath("trunc_a.ply"), RT_ERR_PARSE, "trunc_a.ply:28: ");
    }
}

/* Every scalar type name and alias, in both byte orders. */
static void test_ply_types(void **state)
{
    (void)state;
    for (int f = 1; f < 3; f++) {
        ply_out o;
        o.n = 0;
        o.format = f;
        put_text(&o, f == 1 ? "ply\nformat binary_little_endian 1.0\n" : "ply\nformat binary_big_endian 1.0\n");
        put_text(&o, "element vertex 3\nproperty char x\nproperty int16 y\nproperty float64 z\n"
                     "property ushort red\nproperty uint8 green\nproperty int blue\nproperty uint32 junk\n"
                     "property short j2\nproperty int8 j3\nproperty uint j4\nproperty float32 j5\n"
                     "element face 1\nproperty list ushort uint16 vertex_index\nend_header\n");
        static const long xs[3] = {-128, 127, 0}, ys[3] = {-32768, 0, 32767};
        static const double zs[3] = {0.1, -2.5e10, 1e-300};
        for (int v = 0; v < 3; v++) {
            put_i(&o, xs[v], 1);
            put_i(&o, ys[v], 2);
            double z = zs[v];
            put_raw(&o, &z, 8, f == 2);
            put_i(&o, 65535 * v / 2, 2);
            put_i(&o, 255, 1);
            put_i(&o, 2147483647, 4);
            put_i(&o, 7, 4);
            put_i(&o, -3, 2);
            put_i(&o, -1, 1);
            put_i(&o, 9, 4);
            put_f(&o, 1.5f);
        }
        put_i(&o, 3, 2);
        put_i(&o, 2, 2);
        put_i(&o, 1, 2);
        put_i(&o, 0, 2);
        test_write_file(tpath("types.ply"), o.buf, o.n);
        loaded l;
        load_ok(&l, tpath("types.ply"), NULL);
        const rt_scene *s = &l.s;
        for (int v = 0; v < 3; v++) {
            assert_vec3(s->vertices.position[v], (float)xs[v], (float)ys[v], (float)zs[v], 0);
            assert_float_equal(s->vertices.color[v].x, (float)((double)(65535 * v / 2) / 65535.0), 1e-7);
            assert_float_equal(s->vertices.color[v].y, 1.0f, 0);
            assert_float_equal(s->vertices.color[v].z, 1.0f, 0);
        }
        assert_int_equal(s->triangles.count, 1);
        assert_int_equal(s->triangles.index[0], 2);
        assert_int_equal(s->triangles.index[2], 0);
        rt_scene_free(&l.s);
    }
}

static void test_ply_strips_normals_uv(void **state)
{
    (void)state;
    write_text("strips.ply", "ply\nformat ascii 1.0\n"
                             "element vertex 8\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "property float nx\nproperty float ny\nproperty float nz\n"
                             "property float s\nproperty float t\n"
                             "property float red\nproperty float green\nproperty float blue\n"
                             "element tristrips 1\nproperty list int int vertex_indices\n"
                             "end_header\n"
                             "0 0 0 0 0 3 0 0 0.5 0.25 2\n1 0 0 0 0 1 1 0 1 1 1\n0 1 0 0 0 1 0 1 1 1 1\n"
                             "1 1 0 0 0 1 1 1 1 1 1\n0 2 0 0 0 1 0 1 1 1 1\n1 2 0 0 0 1 1 1 1 1 1\n"
                             "5 5 5 0 0 1 0 0 1 1 1\n6 5 5 0 0 1 0 0 1 1 1\n"
                             "14 0 1 2 3 4 5 -1 6 7 -1 1 1 2 3\n");
    loaded l;
    load_ok(&l, tpath("strips.ply"), NULL);
    const rt_scene *s = &l.s;
    /* strip 0 1 2 3 4 5 zigzags up the ladder: (0,1,2) (2,1,3) (2,3,4) (4,3,5), odd ones swapped;
       strip 6 7 is too short; strip 1 1 2 3: (1,1,2) repeats an index and is dropped, then the odd (2,1,3) */
    static const uint32_t want[] = {0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5, 2, 1, 3};
    assert_int_equal(s->triangles.count, 5);
    for (int k = 0; k < 15; k++)
        assert_int_equal(s->triangles.index[k], want[k]);
    /* every triangle of the strip faces +z: winding alternates correctly */
    for (size_t t = 0; t < 5; t++) {
        rt_vec3 n = rt_cross(rt_sub(tri_v(s, t, 1), tri_v(s, t, 0)), rt_sub(tri_v(s, t, 2), tri_v(s, t, 0)));
        assert_true(n.z > 0);
        assert_int_equal(s->triangles.flags[t], RT_TRI_SMOOTH | RT_TRI_UV | RT_TRI_COLOR);
    }
    assert_vec3(s->vertices.normal[0], 0, 0, 1, 0);
    assert_float_equal(s->vertices.uv0[1].x, 1.0f, 0);
    assert_float_equal(s->vertices.uv0[1].y, 1.0f, 0); /* t = 0 -> v = 1 */
    assert_float_equal(s->vertices.uv0[2].y, 0.0f, 0);
    /* float colours are taken as they are */
    assert_float_equal(s->vertices.color[0].x, 0.5f, 0);
    assert_float_equal(s->vertices.color[0].y, 0.25f, 0);
    assert_float_equal(s->vertices.color[0].z, 2.0f, 0);
    rt_scene_free(&l.s);
}

static void test_ply_errors(void **state)
{
    (void)state;
    /* a header that lies about its counts fails before allocating */
    write_text("lie.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                          "property float x\nproperty float y\nproperty float z\nend_header\n0123456789");
    load_fail(tpath("lie.ply"), RT_ERR_PARSE, "header claims 4000000000 'vertex' elements");
    write_text("lie2.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 18446744073709551\n"
                           "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    load_fail(tpath("lie2.ply"), RT_ERR_PARSE, "header claims");
    /* a list claiming 4 billion entries in a small file */
    static const unsigned char big_list[] = "ply\nformat binary_little_endian 1.0\nelement vertex 0\n"
                                            "property float x\nproperty float y\nproperty float z\n"
                                            "element face 1\nproperty list uint int vertex_indices\nend_header\n"
                                            "\xff\xff\xff\xf0\x00\x00\x00\x00";
    test_write_file(tpath("biglist.ply"), big_list, sizeof big_list - 1);
    load_fail(tpath("biglist.ply"), RT_ERR_PARSE, "runs past the end of the file");
    write_text("badidx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    load_fail(tpath("badidx.ply"), RT_ERR_PARSE, "badidx.ply:13: vertex index 3 out of range");
    write_text("nan.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\n0 nan 0\n");
    load_fail(tpath("nan.ply"), RT_ERR_PARSE, "nan.ply:8: number is not finite");
    static const unsigned char nanbin[] = "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
                                          "property float y\nproperty float z\nend_header\n"
                                          "\x00\x00\x00\x00\x7f\xc0\x00\x00\x00\x00\x00\x00";
    test_write_file(tpath("nanbin.ply"), nanbin, sizeof nanbin - 1);
    load_fail(tpath("nanbin.ply"), RT_ERR_PARSE, "byte 116: vertex 0: property 'y' is not finite");
    write_text("noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n");
    load_fail(tpath("noxyz.ply"), RT_ERR_PARSE, "lacks an x, y or z");
    write_text("nohead.ply", "ply\nformat ascii 1.0\nelement vertex 1\n");
    load_fail(tpath("nohead.ply"), RT_ERR_PARSE, "no end_header");
    write_text("notply.ply", "solid cube\n");
    load_fail(tpath("notply.ply"), RT_ERR_PARSE, "not a PLY file");
    write_text("badtype.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n");
    load_fail(tpath("badtype.ply"), RT_ERR_PARSE, "badtype.ply:4: unknown property type 'float128'");
    /* a second 'x' used to be read silently (the later one won) */
    write_text("dupx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n"
                           "0 0 0 0\n1 1 0 0\n0 0 1 0\n3 0 1 2\n");
    load_fail(tpath("dupx.ply"), RT_ERR_PARSE, "dupx.ply:5: property 'x' given twice in element 'vertex'");
}

static void test_ply_faces_first_and_crlf(void **state)
{
    (void)state;
    write_text("order.ply", "ply\r\nformat ascii 1.0\r\nelement face 1\r\nproperty list uchar uint vertex_index\r\n"
                            "element vertex 3\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\n"
                            "end_header\r\n3 2 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n");
    loaded l;
    load_ok(&l, tpath("order.ply"), NULL);
    assert_int_equal(l.s.triangles.count, 1);
    assert_vec3(tri_v(&l.s, 0, 0), 0, 1, 0, 0);
    rt_scene_free(&l.s);
}

/* ------------------------------------------------------------------ OFF */

static void test_off(void **state)
{
    (void)state;
    write_text("a.off", "OFF # a square and a triangle\n"
                        "# comment line\n\n"
                        "5 2 0\n"
                        "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                        "0.5 0.5 2 # apex\n"
                        "4 0 1 2 3 255 0 0\n" /* face colour, ignored */
                        "3 0 1 4\n");
    loaded l;
    load_ok(&l, tpath("a.off"), NULL);
    assert_int_equal(l.s.triangles.count, 3);
    assert_vec3(tri_v(&l.s, 2, 2), 0.5f, 0.5f, 2, 0);
    for (size_t k = 0; k < 3; k++)
        assert_int_equal(l.s.triangles.flags[k] & RT_TRI_COLOR, 0);
    rt_scene_free(&l.s);

    write_text("c.off", "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n");
    load_ok(&l, tpath("c.off"), NULL);
    assert_non_null(l.s.vertices.color);
    assert_float_equal(l.s.vertices.color[0].x, 1.0f, 0);
    assert_float_equal(l.s.vertices.color[1].y, 1.0f, 0);
    assert_int_equal(l.s.triangles.flags[0], RT_TRI_COLOR);
    rt_scene_free(&l.s);

    write_text("n.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 2\n3 0 1 2\n");
    load_ok(&l, tpath("n.off"), NULL);
    assert_int_equal(l.s.triangles.flags[0], RT_TRI_SMOOTH);
    assert_vec3(l.s.vertices.normal[2], 0, 0, 1, 0);
    rt_scene_free(&l.s);

    write_text("e1.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    load_fail(tpath("e1.off"), RT_ERR_INVALID, "e1.off:6:7: vertex index 3 out of range");
    write_text("e2.off", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n");
    load_fail(tpath("e2.off"), RT_ERR_PARSE, "e2.off:4:3: malformed number 'x'");
    write_text("e3.off", "OFF\n3000000000 1 0\n0 0 0\n");
    load_fail(tpath("e3.off"), RT_ERR_INVALID, "do not fit");
    write_text("e4.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n");
    load_fail(tpath("e4.off"), RT_ERR_PARSE, "file ends after 0 of 1 faces");
    write_text("e6.off", "OFF\n3 1 0\n0 0 0 1 0 0 0 1 0\n3 0 1 2\n");
    load_fail(tpath("e6.off"), RT_ERR_PARSE, "e6.off:3: vertex 0 has 9 numbers, expected 3");
    write_text("e5.off", "PLY\n");
    load_fail(tpath("e5.off"), RT_ERR_PARSE, "not an OFF file");
}

/* ------------------------------------------------------------- numbers */

static void test_float_parser(void **state)
{
    (void)state;
    test_rng rng = {0x9E3779B97F4A7C15ull};
    char buf[64];
    for (int i = 0; i < 200000; i++) {
        /* random decimal strings with 1..12 significant digits and exponents both ways */
        int digits = 1 + (int)(test_rng_next(&rng) % 12);
        int point = (int)(test_rng_next(&rng) % (unsigned)(digits + 1));
        int n = 0;
        if (test_rng_next(&rng) & 1)
            buf[n++] = '-';
        for (int d = 0; d < digits; d++) {
            if (d == point && d > 0)
                buf[n++] = '.';
            buf[n++] = (char)('0' + test_rng_next(&rng) % 10);
        }
        if (test_rng_next(&rng) % 4 == 0)
            n += snprintf(buf + n, sizeof buf - (size_t)n, "e%d", (int)(test_rng_next(&rng) % 80) - 40);
        buf[n] = 0;
        float want = strtof(buf, NULL), got = -1;
        bool nonfinite;
        const char *e = rt_mesh_parse_float(buf, buf + n, &got, &nonfinite);
        if (!isfinite(want)) {
            assert_null(e);
            assert_true(nonfinite);
            continue;
        }
        if (!e || memcmp(&got, &want, 4) != 0)
            fprintf(stderr, "'%s': got %.9g want %.9g\n", buf, got, want);
        assert_non_null(e);
        assert_ptr_equal(e, buf + n);
        assert_memory_equal(&got, &want, 4);
    }
    /* hard cases: float midpoints, long mantissas, subnormals, limits */
    static const char *hard[] = {"16777217", "16777219", "0.1", "3.4028235e38", "3.4028236e38", "1.17549435e-38",
                                 "1e-45", "7e-46", "0.000000000000000000000000000000000000000000001",
                                 "123456789012345678901234567890", "1.00000005960464477539062500000001",
                                 "1.000000059604644775390625", "-0", "+5", "2.5E+3", "9007199254740993",
                                 "4.9406564584124654e-324", "1e400", "0.30000001192092896"};
    for (size_t i = 0; i < sizeof hard / sizeof hard[0]; i++) {
        const char *t = hard[i];
        float want = strtof(t, NULL), got = 0;
        bool nonfinite;
        const char *e = rt_mesh_parse_float(t, t + strlen(t), &got, &nonfinite);
        if (!isfinite(want)) {
            assert_null(e);
            continue;
        }
        assert_ptr_equal(e, t + strlen(t));
        if (memcmp(&got, &want, 4) != 0)
            fprintf(stderr, "'%s': got %.9g want %.9g\n", t, got, want);
        assert_memory_equal(&got, &want, 4);
    }
    bool nf;
    float f;
    static const char abc[] = "abc", dot[] = ".", minf[] = "-inf";
    assert_null(rt_mesh_parse_float(abc, abc + 3, &f, &nf));
    assert_null(rt_mesh_parse_float(dot, dot + 1, &f, &nf));
    assert_null(rt_mesh_parse_float(minf, minf + 4, &f, &nf));
    assert_true(nf);
    const char *t = "1.5e";
    assert_ptr_equal(rt_mesh_parse_float(t, t + 4, &f, &nf), t + 3); /* a bare 'e' is left to the caller */
}

/* ------------------------------------------------------ garbage inputs */

static void test_garbage(void **state)
{
    (void)state;
    /* random mutations of small valid files: any result but a crash, a leak or a half-load */
    ply_out o;
    make_ply(&o, 1);
    static unsigned char seeds[3][4096];
    size_t seed_n[3];
    memcpy(seeds[0], o.buf, o.n);
    seed_n[0] = o.n;
    const char *obj = "mtllib mats.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nusemtl red\nf 1/1/1 2/1/1 3/1/1\n"
                      "f -1 -2 -3\n";
    memcpy(seeds[1], obj, strlen(obj));
    seed_n[1] = strlen(obj);
    const char *off = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 1 2\n";
    memcpy(seeds[2], off, strlen(off));
    seed_n[2] = strlen(off);
    static const char *names[3] = {"g.ply", "g.obj", "g.off"};
    static const char tokens[] = "-/ \n0123456789.e#vf";
    test_rng rng = {12345};
    rt_log_set_level(RT_LOG_QUIET);
    for (int iter = 0; iter < 1500; iter++) {
        int k = iter % 3;
        unsigned char b[4096];
        size_t n = seed_n[k];
        memcpy(b, seeds[k], n);
        int edits = 1 + (int)(test_rng_next(&rng) % 4);
        for (int e = 0; e < edits; e++) {
            size_t at = (size_t)(test_rng_next(&rng) % n);
            uint64_t what = test_rng_next(&rng) % 3;
            if (what == 0)
                b[at] = (unsigned char)test_rng_next(&rng);
            else if (what == 1)
                b[at] = (unsigned char)tokens[test_rng_next(&rng) % (sizeof tokens - 1)];
            else
                n = at + 1; /* truncate */
        }
        test_write_file(tpath(names[k]), b, n);
        loaded l;
        load(&l, tpath(names[k]), NULL);
        if (l.r != RT_OK) {
            assert_int_equal(l.s.triangles.count, 0);
            assert_true(l.err.message[0] != 0);
        }
        for (size_t t = 0; t < l.s.triangles.count; t++)
            for (int c = 0; c < 3; c++)
                assert_true(l.s.triangles.index[3 * t + (size_t)c] < l.s.vertices.count);
        rt_scene_free(&l.s);
    }
    rt_log_set_level(RT_LOG_NORMAL);
}

/* -------------------------------------------------------- shared assets */

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

/* The manifest gives 4 significant digits: allow half a unit in the 4th digit of
 * each figure, plus 1e-4 of the box's extent. */
static void check_coord(float got, float want, float extent)
{
    float half_digit = want == 0.0f ? 0.0f : 0.5f * powf(10.0f, floorf(log10f(fabsf(want))) - 3.0f);
    float tol = 1e-4f * extent + half_digit;
    if (fabsf(got - want) > tol)
        fprintf(stderr, "AABB coordinate %.7g, manifest %.4g (tolerance %.2g)\n", got, want, tol);
    assert_true(fabsf(got - want) <= tol);
}

static void check_box(rt_box b, const float lo[3], const float hi[3])
{
    float extent = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
    for (int k = 0; k < 3; k++) {
        check_coord((&b.lo.x)[k], lo[k], extent);
        check_coord((&b.hi.x)[k], hi[k], extent);
    }
}

static void test_shared_meshes(void **state)
{
    (void)state;
    test_require_shared();
    struct {
        const char *path;
        size_t tris;
        float lo[3], hi[3];
    } cases[] = {
        {"assets/meshes/igea/igea.ply", 268686, {-0.03456f, -0.04967f, -0.04954f}, {0.03456f, 0.04967f, 0.04954f}},
        {"assets/meshes/stanford-bunny/stanford-bunny.obj", 69451, {-0.09469f, 0.03299f, -0.06187f},
         {0.06101f, 0.1873f, 0.0588f}},
        {"assets/cornell/mcguire-williams/CornellBox-Original.obj", 36, {-1.02f, 0, -1.04f}, {1, 1.99f, 0.99f}},
        {"assets/cornell/cornell-data-mm/cornell_box.obj", 36, {0, 0, 0}, {556, 548.8f, 559.2f}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        loaded l;
        double t0 = now_ms();
        load_ok(&l, test_shared_path(cases[i].path), NULL);
        double t1 = now_ms();
        fprintf(stderr, "note: %s: %zu triangles, %zu vertices in %.1f ms\n", cases[i].path, l.st.triangles,
                l.st.vertices, t1 - t0);
        assert_int_equal(l.s.triangles.count, cases[i].tris);
        check_box(rt_scene_bounds(&l.s), cases[i].lo, cases[i].hi);
        if (i == 2) {
            /* the McGuire box: 8 materials; the light emits Ke 17 12 4; the short box's faces come
               before its usemtl and so are the left wall's red (a quirk of the file, kept) */
            assert_int_equal(l.st.materials, 8);
            uint32_t light = rt_scene_find_material(&l.s, "CornellBox-Original.obj:light");
            uint32_t left = rt_scene_find_material(&l.s, "CornellBox-Original.obj:leftWall");
            assert_true(light != RT_NONE && left != RT_NONE);
            assert_vec3(l.s.materials[light].emission, 17, 12, 4, 0);
            assert_int_equal(l.s.triangles.material[35], light);
            size_t red = 0;
            for (size_t t = 0; t < 36; t++)
                red += l.s.triangles.material[t] == left;
            assert_int_equal(red, 2 + 12);
        }
        if (i == 3) {
            uint32_t light = rt_scene_find_material(&l.s, "cornell_box.obj:light");
            assert_true(light != RT_NONE);
            assert_vec3(l.s.materials[light].emission, 20, 20, 20, 0); /* Ka 20 20 20, no Ke */
        }
        rt_scene_free(&l.s);
    }
}

/* ----------------------------------------------------------------- main */

int main(void)
{
    if (!test_make_dir(tmpdir, sizeof tmpdir, "mesh_io")) {
        perror("mkdtemp");
        return 1;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_polygons),
        cmocka_unit_test(test_obj_concave_quad),
        cmocka_unit_test(test_triangulate_concave),
        cmocka_unit_test(test_obj_negative_indices_and_forms),
        cmocka_unit_test(test_obj_smoothing_groups),
        cmocka_unit_test(test_obj_mtl),
        cmocka_unit_test(test_obj_missing_texture),
        cmocka_unit_test(test_obj_warnings),
        cmocka_unit_test(test_obj_many_names),
        cmocka_unit_test(test_obj_errors),
        cmocka_unit_test(test_dispatch),
        cmocka_unit_test(test_transform),
        cmocka_unit_test(test_ply_encodings),
        cmocka_unit_test(test_ply_types),
        cmocka_unit_test(test_ply_strips_normals_uv),
        cmocka_unit_test(test_ply_errors),
        cmocka_unit_test(test_ply_faces_first_and_crlf),
        cmocka_unit_test(test_off),
        cmocka_unit_test(test_float_parser),
        cmocka_unit_test(test_garbage),
        cmocka_unit_test(test_shared_meshes),
    };
    int failed = cmocka_run_group_tests_name("mesh_io", tests, NULL, NULL);
    test_remove_dir(tmpdir);
    return failed;
}
