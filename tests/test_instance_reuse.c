/* test_instance_reuse.c - what instancing lets rt build or load once
 * (issue 27): animated and motion-blurred instances, which node animation
 * moves by their transforms while the objects' kd-trees are built once
 * and kept (rt_kdtree_kept, rt/accel/kdtree.h), for --frames and for the
 * slices of an open shutter; and scene-file `model` lines that load one
 * file twice, which place the first load again as instances.
 *
 * The glTF file is written here: one small mesh (a UV sphere) used by four
 * nodes, two of them under an animated parent (rotation about y), one
 * animated itself (translation and scale), one mirrored; and a ground quad
 * used once (world geometry). At several times the instanced load, its
 * tree built with a kept set, must give the hits of a fresh build bit for
 * bit and those of the flattened load within the transforms' rounding,
 * with one object tree built over all the times. The rt command's
 * --frames and a scene with an open shutter over the model say the same
 * in their -v lines, and render the flattened load's images within float
 * rounding. The model lines' file is the same mesh and ground without the
 * animation, each used once.
 */
#include "test_util.h"
#include "test_tree_mesh.h"
#include "test_fixture.h"
#include <math.h>
#include <sys/wait.h>
#include <unistd.h>
#include "rt/accel/kdtree.h"
#include "rt/io/gltf.h"
#include "rt/io/image_read.h"
#include "rt/io/scene_parse.h"
#include "rt/image/framebuffer.h"
#include "rt/scene/instance.h"
#include "rt/scene/scene.h"
#include "rt/scene/validate.h"

static char tmp_dir[256];

static int setup(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "instreuse") ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

static const char *tmp_path(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmp_dir, name);
    return buf[k];
}

/* ------------------------------------------------- the animated file */

enum { NV = TEST_TREE_NV, NT = TEST_TREE_NT };

/* anim.gltf and anim.bin: the mesh, the ground, the animation (keys at
 * 0, 1 and 2 s, LINEAR). */
static void write_animated(void)
{
    static float pos[NV][3], nrm[NV][3];
    static uint32_t idx[3 * NT];
    test_tree_mesh(pos, nrm, idx);
    const float gpos[4][3] = {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}};
    const float gnrm[4][3] = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
    const uint32_t gidx[6] = {0, 2, 1, 0, 3, 2};
    const float times[3] = {0, 1, 2};
    float rots[3][4];
    const float angles[3] = {0.0f, 1.0f, 2.6f};
    for (int k = 0; k < 3; k++)
        rots[k][0] = 0, rots[k][1] = sinf(0.5f * angles[k]), rots[k][2] = 0, rots[k][3] = cosf(0.5f * angles[k]);
    const float moves[3][3] = {{-2, 0, 0}, {0, 1, 0}, {2, 0.2f, -1}};
    const float scales[3][3] = {{1, 1, 1}, {1.5f, 0.6f, 1.5f}, {0.8f, 1.2f, 0.8f}};
    struct {
        const void *p;
        size_t n;
    } parts[] = {{pos, sizeof pos},   {nrm, sizeof nrm},     {idx, sizeof idx},     {gpos, sizeof gpos},
                 {gnrm, sizeof gnrm}, {gidx, sizeof gidx},   {times, sizeof times}, {rots, sizeof rots},
                 {moves, sizeof moves}, {scales, sizeof scales}};
    enum { NPARTS = sizeof parts / sizeof parts[0] };
    size_t off[NPARTS], total = 0;
    FILE *fp = fopen(tmp_path("anim.bin"), "wb");
    assert_non_null(fp);
    for (int i = 0; i < NPARTS; i++) { /* every part a multiple of 4 bytes */
        off[i] = total;
        assert_int_equal(fwrite(parts[i].p, 1, parts[i].n, fp), parts[i].n);
        total += parts[i].n;
    }
    fclose(fp);
    char js[8192];
    size_t j = 0;
#define J(...) (j += (size_t)snprintf(js + j, sizeof js - j, __VA_ARGS__))
    J("{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"buffers\":[{\"uri\":\"anim.bin\",\"byteLength\":%zu}],", total);
    J("\"bufferViews\":[");
    for (int i = 0; i < NPARTS; i++)
        J("%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", i ? "," : "", off[i], parts[i].n);
    J("],\"accessors\":[");
    J("{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\",\"min\":[-0.4,0,-0.3],"
      "\"max\":[0.4,1,0.3]},",
      NV);
    J("{\"bufferView\":1,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},", NV);
    J("{\"bufferView\":2,\"componentType\":5125,\"count\":%d,\"type\":\"SCALAR\"},", 3 * NT);
    J("{\"bufferView\":3,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[-4,0,-4],\"max\":[4,0,4]},");
    J("{\"bufferView\":4,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},");
    J("{\"bufferView\":5,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"},");
    J("{\"bufferView\":6,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\",\"min\":[0],\"max\":[2]},");
    J("{\"bufferView\":7,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},");
    J("{\"bufferView\":8,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},");
    J("{\"bufferView\":9,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],");
    J("\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.3,0.7,0.3,1],\"metallicFactor\":0}},"
      "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.5,0.4,1],\"metallicFactor\":0}}],");
    J("\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":0}]},"
      "{\"primitives\":[{\"attributes\":{\"POSITION\":3,\"NORMAL\":4},\"indices\":5,\"material\":1}]}],");
    J("\"nodes\":[{\"children\":[1,2,3]},{\"mesh\":0,\"translation\":[1.5,0,0]},"
      "{\"mesh\":0,\"translation\":[-1.5,0,0.5],\"scale\":[-1,1,1]},"
      "{\"mesh\":0,\"translation\":[0,0.3,1.5],\"rotation\":[0.25881905,0,0,0.96592583]},"
      "{\"mesh\":0},{\"mesh\":1,\"translation\":[0,-0.01,0]}],");
    J("\"animations\":[{\"samplers\":[{\"input\":6,\"output\":7,\"interpolation\":\"LINEAR\"},"
      "{\"input\":6,\"output\":8,\"interpolation\":\"LINEAR\"},{\"input\":6,\"output\":9,\"interpolation\":\"LINEAR\"}],"
      "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"rotation\"}},"
      "{\"sampler\":1,\"target\":{\"node\":4,\"path\":\"translation\"}},"
      "{\"sampler\":2,\"target\":{\"node\":4,\"path\":\"scale\"}}]}],");
    J("\"scenes\":[{\"nodes\":[0,4,5]}]}");
#undef J
    assert_true(j < sizeof js);
    test_write_file(tmp_path("anim.gltf"), js, j);
}

/* single.gltf (over anim.bin): the mesh once, turned, and the ground;
 * lamp.gltf: the same with an emissive mesh. */
static void write_single(void)
{
    write_animated();
    for (int lamp = 0; lamp < 2; lamp++) {
        char js[4096];
        size_t j = 0;
        size_t whole_len = 0;
        char *whole = test_slurp(tmp_path("anim.gltf"), &whole_len);
        char *cut = strstr(whole, "\"materials\"");
        assert_non_null(cut);
        *cut = 0; /* asset, buffers, views and accessors as they are */
        j = (size_t)snprintf(js, sizeof js, "%s", whole);
        free(whole);
        j += (size_t)snprintf(
            js + j, sizeof js - j,
            "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.3,0.7,0.3,1],\"metallicFactor\":0}%s},"
            "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.5,0.4,1],\"metallicFactor\":0}}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":0}]},"
            "{\"primitives\":[{\"attributes\":{\"POSITION\":3,\"NORMAL\":4},\"indices\":5,\"material\":1}]}],"
            "\"nodes\":[{\"mesh\":0,\"rotation\":[0.25881905,0,0,0.96592583]},{\"mesh\":1,\"scale\":[0.2,1,0.2]}],"
            "\"scenes\":[{\"nodes\":[0,1]}]}",
            lamp ? ",\"emissiveFactor\":[1,0.8,0.6]" : "");
        assert_true(j < sizeof js);
        test_write_file(tmp_path(lamp ? "lamp.gltf" : "single.gltf"), js, j);
    }
}

static void load_at(rt_scene *s, float time, bool flatten)
{
    rt_scene_init(s);
    rt_gltf_options opt = {0};
    opt.use_time = true;
    opt.time = time;
    opt.flatten_instances = flatten;
    rt_gltf_stats st;
    rt_error err = {0};
    if (rt_gltf_load(s, tmp_path("anim.gltf"), &opt, &st, &err) != RT_OK)
        fail_msg("anim.gltf: %s", err.message);
    assert_true(st.animated);
    assert_int_equal(rt_scene_validate(s, &err), RT_OK);
}

/* A ray from around the box towards a point inside it. */
static rt_ray box_ray(test_rng *g, rt_box b)
{
    rt_vec3 c = rt_scale(rt_add(b.lo, b.hi), 0.5f), e = rt_sub(b.hi, b.lo);
    rt_vec3 target = rt_v3(b.lo.x + e.x * test_rng_float(g), b.lo.y + e.y * test_rng_float(g),
                           b.lo.z + e.z * test_rng_float(g));
    float a = 6.2831853f * test_rng_float(g), h = 0.1f + 0.8f * test_rng_float(g);
    float r = 0.8f * (e.x + e.z);
    rt_vec3 o = rt_add(c, rt_v3(r * cosf(a), r * h, r * sinf(a)));
    return rt_ray_make(o, rt_sub(target, o), 0.0f, INFINITY);
}

/* ----------------------------------------------------------- the tests */

/* Five times of the animation: the instances move, the object's tree is
 * built once and taken at the other four; the hits are a fresh build's,
 * bit for bit, and the flattened load's within rounding. */
static void test_frames_keep_object_trees(void **state)
{
    (void)state;
    write_animated();
    rt_kdtree_kept kept;
    rt_kdtree_kept_init(&kept);
    rt_kdtree_params par = {0};
    par.kept = &kept;
    const float times[] = {0.0f, 0.4f, 1.0f, 1.7f, 2.5f};
    rt_mat4 first_move = rt_mat4_identity();
    for (size_t f = 0; f < sizeof times / sizeof times[0]; f++) {
        rt_scene si, sf;
        load_at(&si, times[f], false);
        load_at(&sf, times[f], true);
        assert_int_equal(si.object_count, 1);
        assert_int_equal(si.instance_count, 4);
        assert_int_equal(si.triangles.count, NT + 2);
        assert_int_equal(sf.instance_count, 0);
        assert_int_equal(sf.triangles.count, 4 * NT + 2);
        if (f == 0)
            first_move = si.instances[0].to_world;
        else /* the animated parent turned its children */
            assert_true(memcmp(&first_move, &si.instances[0].to_world, sizeof first_move) != 0);
        rt_kdtree tk, tn, tf;
        rt_error err = {0};
        assert_int_equal(rt_kdtree_build(&tk, &si, &par, &err), RT_OK);
        assert_int_equal(rt_kdtree_build(&tn, &si, NULL, &err), RT_OK);
        assert_int_equal(rt_kdtree_build(&tf, &sf, NULL, &err), RT_OK);
        assert_true(tk.objects_kept && !tn.objects_kept);
        assert_int_equal(kept.built, 1); /* the first frame's, and no other */
        assert_int_equal(kept.taken, f);
        test_rng g = {1000 + (uint64_t)f};
        rt_box b = rt_scene_bounds(&sf);
        int hits = 0, agree = 0;
        enum { N = 2000 };
        for (int k = 0; k < N; k++) {
            rt_ray r = box_ray(&g, b);
            rt_hit hk, hn, hf;
            bool fk = rt_kdtree_intersect(&tk, &r, &hk), fn = rt_kdtree_intersect(&tn, &r, &hn);
            bool ff = rt_kdtree_intersect(&tf, &r, &hf);
            assert_int_equal(fk, fn);
            assert_int_equal(rt_kdtree_occluded(&tk, &r), fk);
            if (fk) {
                assert_true(hk.t == hn.t && hk.u == hn.u && hk.v == hn.v);
                assert_int_equal(hk.prim, hn.prim);
                assert_int_equal(hk.inst, hn.inst);
                hits++;
            }
            if (fk == ff && (!fk || fabsf(hk.t - hf.t) <= 1e-4f * hf.t))
                agree++;
        }
        print_message("t = %g s: %d of %d rays hit; %d agree with the flattened load\n", (double)times[f], hits, N,
                      agree);
        assert_true(hits > N / 4);
        assert_true(agree >= N * 995 / 1000); /* the rest graze an edge, decided by rounding */
        rt_kdtree_free(&tk);
        rt_kdtree_free(&tn);
        rt_kdtree_free(&tf);
        rt_kdtree_kept_trim(&kept);
        assert_int_equal(kept.count, 1);
        rt_scene_free(&si);
        rt_scene_free(&sf);
    }
    rt_kdtree_kept_free(&kept);
}

/* An object is taken only when its triangles are the same bits and the
 * build parameters shape its tree alike; a trim frees what the last
 * builds did not use. */
static void test_kept_only_when_same(void **state)
{
    (void)state;
    const char *a = "material g color 0.5 0.5 0.5\nobject o\n triangle 0 0 0  1 0 0  0 1 0 g\n"
                    " triangle 0 0 0  0 0 1  0 1 0 g\nend\ninstance o\ninstance o translate 2 0 0\n";
    const char *b = "material g color 0.5 0.5 0.5\nobject o\n triangle 0 0 0  1 0 0  0 1 0 g\n"
                    " triangle 0 0 0  0 0 1.5  0 1 0 g\nend\ninstance o translate 0 1 0\n";
    rt_scene sa, sb;
    rt_error err = {0};
    rt_scene_init(&sa);
    rt_scene_init(&sb);
    assert_int_equal(rt_scene_parse_string(&sa, NULL, a, strlen(a), "a.txt", "", &err), RT_OK);
    assert_int_equal(rt_scene_parse_string(&sb, NULL, b, strlen(b), "b.txt", "", &err), RT_OK);
    rt_kdtree_kept kept;
    rt_kdtree_kept_init(&kept);
    rt_kdtree_params par = {0};
    par.kept = &kept;
    rt_kdtree t;
    assert_int_equal(rt_kdtree_build(&t, &sa, &par, &err), RT_OK);
    rt_kdtree_free(&t);
    assert_int_equal(rt_kdtree_build(&t, &sb, &par, &err), RT_OK); /* one corner moved: built */
    rt_kdtree_free(&t);
    assert_int_equal(kept.built, 2);
    assert_int_equal(kept.taken, 0);
    assert_int_equal(rt_kdtree_build(&t, &sa, &par, &err), RT_OK); /* the first again: taken */
    rt_kdtree_free(&t);
    assert_int_equal(kept.taken, 1);
    par.max_depth = 3; /* another tree for the same triangles */
    assert_int_equal(rt_kdtree_build(&t, &sa, &par, &err), RT_OK);
    rt_kdtree_free(&t);
    assert_int_equal(kept.built, 3);
    par.max_depth = 0;
    par.threads = 1; /* the thread count does not shape a tree */
    assert_int_equal(rt_kdtree_build(&t, &sb, &par, &err), RT_OK);
    rt_kdtree_free(&t);
    assert_int_equal(kept.built, 3);
    assert_int_equal(kept.taken, 2);
    assert_int_equal(kept.count, 3);
    rt_kdtree_kept_trim(&kept); /* all three used since the start */
    assert_int_equal(kept.count, 3);
    assert_int_equal(rt_kdtree_build(&t, &sb, &par, &err), RT_OK);
    rt_kdtree_free(&t);
    rt_kdtree_kept_trim(&kept); /* only b's was used since */
    assert_int_equal(kept.count, 1);
    rt_kdtree_kept_free(&kept);
    rt_scene_free(&sa);
    rt_scene_free(&sb);
}

/* --------------------------------------------------- model lines again */

/* Parses scene text whose paths resolve in the scratch directory. */
static void parse(rt_scene *s, const char *text, bool flatten)
{
    rt_scene_init(s);
    rt_scene_parse_options opt = {0};
    opt.flatten_instances = flatten;
    rt_error err = {0};
    if (rt_scene_parse_string_with(s, NULL, text, strlen(text), "models.txt", tmp_dir, &opt, &err) != RT_OK)
        fail_msg("%s", err.message);
    assert_int_equal(rt_scene_validate(s, &err), RT_OK);
}

/* Renders of two scenes agree within float rounding: 99% of the values
 * within 1e-3 relative, the means within 1e-4. */
static void assert_framebuffers_close(const rt_framebuffer *a, const rt_framebuffer *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    size_t n = (size_t)a->width * (size_t)a->height * 3, close = 0;
    double sa = 0.0, sb = 0.0;
    for (size_t i = 0; i < n; i++) {
        sa += a->rgb[i];
        sb += b->rgb[i];
        if (fabsf(a->rgb[i] - b->rgb[i]) <= 1e-3f * fmaxf(1.0f, fabsf(b->rgb[i])))
            close++;
    }
    print_message("%zu of %zu values within 1e-3, means %.6f and %.6f\n", close, n, sa / (double)n, sb / (double)n);
    assert_true(sa > 0.0);
    assert_true(close >= n * 99 / 100);
    assert_true(fabs(sa - sb) <= 1e-4 * fabs(sb));
}

/* Three lines of one file and pose: one load, an object and three
 * instances (the first line's own transform included); a fourth line
 * with another pose option is loaded again; --flatten loads every line.
 * Hits and images are the flattened scene's within rounding. */
static void test_model_lines_share_a_load(void **state)
{
    (void)state;
    write_single();
    const char *text = "camera position 0 7 9 look_at 0 0.3 0 fov 45\n"
                       "light directional -0.3 -1 -0.4  1 1 1  3\nbackground 0.3 0.35 0.4\n"
                       "model single.gltf translate 0 0 -2 rotate 0 10 0\n"
                       "model single.gltf translate 3 0 0 rotate 0 30 0 scale 1.2\n"
                       "model single.gltf translate -3 0 1 scale -1 1 1\n"
                       "model single.gltf translate 0 0 2.5 time 0\n";
    rt_scene si, sf;
    parse(&si, text, false);
    parse(&sf, text, true);
    assert_int_equal(si.object_count, 1);
    assert_int_equal(si.instance_count, 3);
    assert_int_equal(si.triangles.count, 2 * (NT + 2)); /* the shared load, and the line with `time` */
    assert_int_equal(rt_scene_instanced_triangles(&si), 3 * (NT + 2));
    assert_true(si.instances[2].mirror);
    assert_int_equal(sf.object_count, 0);
    assert_int_equal(sf.instance_count, 0);
    assert_int_equal(sf.triangles.count, 4 * (NT + 2));
    rt_kdtree ti, tf;
    rt_error err = {0};
    assert_int_equal(rt_kdtree_build(&ti, &si, NULL, &err), RT_OK);
    assert_int_equal(rt_kdtree_build(&tf, &sf, NULL, &err), RT_OK);
    test_rng g = {4242};
    rt_box b = rt_scene_bounds(&sf);
    int hits = 0, agree = 0;
    enum { N = 3000 };
    for (int k = 0; k < N; k++) {
        rt_ray r = box_ray(&g, b);
        rt_hit hi, hf;
        bool fi = rt_kdtree_intersect(&ti, &r, &hi), ff = rt_kdtree_intersect(&tf, &r, &hf);
        hits += fi;
        if (fi == ff && (!fi || fabsf(hi.t - hf.t) <= 1e-4f * hf.t))
            agree++;
    }
    print_message("model lines: %d of %d rays hit; %d agree with the flattened scene\n", hits, N, agree);
    assert_true(hits > N / 6);
    assert_true(agree >= N * 995 / 1000);
    rt_kdtree_free(&ti);
    rt_kdtree_free(&tf);
    rt_settings set;
    rt_settings_default(&set);
    set.width = 64;
    set.height = 48;
    set.samples = 4;
    set.integrator = RT_INTEGRATOR_PATH;
    rt_framebuffer fi, ff;
    test_render_scene(&si, &set, 2, 0, &fi);
    test_render_scene(&sf, &set, 2, 0, &ff);
    assert_framebuffers_close(&fi, &ff);
    rt_framebuffer_free(&fi);
    rt_framebuffer_free(&ff);
    rt_scene_free(&si);
    rt_scene_free(&sf);
}

/* The first load becomes an object only at the second line, after an
 * `object` block made an object over later vertices: it goes before that
 * one (objects stay in vertex order) and `instance` still places the
 * block's object. A model that emits light is loaded at every line (its
 * triangles stay world geometry, for the light table). */
static void test_model_lines_order_and_lamps(void **state)
{
    (void)state;
    write_single();
    const char *text = "material g color 0.5 0.5 0.5\n"
                       "model single.gltf\n"
                       "object blk\n triangle 0 0 0  1 0 0  0 1 0 g\nend\n"
                       "model single.gltf translate 4 0 0\n"
                       "instance blk translate 0 2 0\n"
                       "model lamp.gltf\nmodel lamp.gltf translate 0 0 4\n";
    rt_scene s;
    parse(&s, text, false);
    assert_int_equal(s.object_count, 2);
    assert_int_equal(s.instance_count, 3);
    assert_true(s.objects[0].first_vertex < s.objects[1].first_vertex);
    assert_int_equal(s.objects[0].triangle_count, NT + 2); /* the model's, before the block's */
    assert_int_equal(s.objects[1].triangle_count, 1);
    size_t placed[2] = {0, 0};
    for (size_t i = 0; i < s.instance_count; i++)
        placed[s.instances[i].object]++;
    assert_int_equal(placed[0], 2);
    assert_int_equal(placed[1], 1); /* the block's, renumbered */
    /* the lamp twice, world geometry both times */
    assert_int_equal(s.triangles.count, (NT + 2) + 1 + 2 * (NT + 2));
    rt_scene_frame_camera(&s, 1.0f);
    rt_scene_free(&s);
}

/* ---------------------------------------------------------- the limits */

/* NAME.glb: a grid of w x h quads (2 w h triangles) placed n times by
 * EXT_mesh_gpu_instancing (TRANSLATION only, a row of copies). */
static void write_grid_field(const char *name, int w, int h, size_t n)
{
    size_t nv = (size_t)(w + 1) * (size_t)(h + 1), nt = 2 * (size_t)w * (size_t)h;
    size_t bytes = 12 * nv + 12 * nt + 12 * n;
    unsigned char *bin = malloc(bytes);
    assert_non_null(bin);
    float *pos = (float *)bin;
    uint32_t *idx = (uint32_t *)(bin + 12 * nv);
    float *tr = (float *)(bin + 12 * nv + 12 * nt);
    for (int y = 0, v = 0; y <= h; y++)
        for (int x = 0; x <= w; x++, v++)
            pos[3 * v] = (float)x / (float)w, pos[3 * v + 1] = 0.0f, pos[3 * v + 2] = (float)y / (float)h;
    for (int y = 0, k = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint32_t a = (uint32_t)(y * (w + 1) + x), b = a + (uint32_t)w + 1;
            idx[k++] = a, idx[k++] = b, idx[k++] = a + 1;
            idx[k++] = a + 1, idx[k++] = b, idx[k++] = b + 1;
        }
    for (size_t i = 0; i < n; i++)
        tr[3 * i] = 1.5f * (float)(i % 1000), tr[3 * i + 1] = 0.0f, tr[3 * i + 2] = 1.5f * (float)(i / 1000);
    char js[2048];
    int j = snprintf(js, sizeof js,
                     "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],"
                     "\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu},"
                     "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,"
                     "\"byteLength\":%zu}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,"
                     "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,0,1]},{\"bufferView\":1,\"componentType\":5125,"
                     "\"count\":%zu,\"type\":\"SCALAR\"},{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,"
                     "\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},"
                     "\"indices\":1}]}],\"nodes\":[{\"mesh\":0,\"extensions\":{\"EXT_mesh_gpu_instancing\":"
                     "{\"attributes\":{\"TRANSLATION\":2}}}}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
                     bytes, 12 * nv, 12 * nv, 12 * nt, 12 * nv + 12 * nt, 12 * n, nv, 3 * nt, n);
    assert_true(j > 0 && (size_t)j < sizeof js - 4);
    while (j % 4)
        js[j++] = ' ';
    uint32_t hdr[5] = {0x46546C67u, 2u, (uint32_t)(12 + 8 + (size_t)j + 8 + bytes), (uint32_t)j, 0x4E4F534Au};
    uint32_t bh[2] = {(uint32_t)bytes, 0x004E4942u};
    FILE *fp = fopen(tmp_path(name), "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(hdr, 4, 5, fp), 5);
    assert_int_equal(fwrite(js, 1, (size_t)j, fp), (size_t)j);
    assert_int_equal(fwrite(bh, 4, 2, fp), 2);
    assert_int_equal(fwrite(bin, 1, bytes, fp), bytes);
    fclose(fp);
    free(bin);
}

/* The loader's 2^25 limit counts unique triangles: 10,000 instances of a
 * 3,400-triangle mesh (34 M placed, over 2^25) load, and the same file
 * flattened is refused before anything is allocated. */
static void test_limit_counts_unique_triangles(void **state)
{
    (void)state;
    write_grid_field("big.glb", 34, 50, 10000);
    rt_scene s;
    rt_scene_init(&s);
    rt_gltf_options opt = {0};
    rt_gltf_stats st;
    rt_error err = {0};
    if (rt_gltf_load(&s, tmp_path("big.glb"), &opt, &st, &err) != RT_OK)
        fail_msg("big.glb: %s", err.message);
    assert_int_equal(s.triangles.count, 3400);
    assert_int_equal(s.instance_count, 10000);
    assert_int_equal(rt_scene_instanced_triangles(&s), (size_t)34000000);
    assert_true(rt_scene_instanced_triangles(&s) > ((size_t)1 << 25));
    rt_scene_free(&s);
    rt_scene_init(&s);
    opt.flatten_instances = true;
    assert_int_equal(rt_gltf_load(&s, tmp_path("big.glb"), &opt, &st, &err), RT_ERR_LIMIT);
    assert_non_null(strstr(err.message, "big.glb"));
    assert_non_null(strstr(err.message, "over the loader's limit"));
    assert_non_null(strstr(err.message, "flattened copies"));
    assert_int_equal(s.triangles.count, 0);
    rt_scene_free(&s);
}

/* ------------------------------------------------------- the rt command */

static const char *rt_bin(void)
{
    const char *b = getenv("RT_BIN");
    return b && *b ? b : "./rt";
}

/* Runs rt with args (NULL-ended), stderr into log (and stdout into out
 * when not NULL); its exit status. */
static int run_rt_out(const char *const *args, const char *log, const char *out)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *e = freopen(log, "w", stderr);
        if (!e || (out && !freopen(out, "w", stdout)))
            _exit(126);
        execv(rt_bin(), (char *const *)args);
        _exit(127);
    }
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFEXITED(st));
    if (WEXITSTATUS(st) == 127)
        fail_msg("could not run %s (build it first, or set RT_BIN)", rt_bin());
    return WEXITSTATUS(st);
}

static int run_rt(const char *const *args, const char *log) { return run_rt_out(args, log, NULL); }

static void require_rt(void)
{
    if (access(rt_bin(), X_OK) != 0) {
        fprintf(stderr, "skip: %s is not built (make rt, or set RT_BIN)\n", rt_bin());
        skip();
    }
}

/* rt --info says the unique triangles, the instances and the triangles
 * they place. */
static void test_cli_info_counts(void **state)
{
    (void)state;
    require_rt();
    write_grid_field("info.glb", 34, 50, 10000);
    char log[600], out[600];
    snprintf(log, sizeof log, "%s/info.log", tmp_dir);
    snprintf(out, sizeof out, "%s/info.txt", tmp_dir);
    const char *args[] = {rt_bin(), "--info", tmp_path("info.glb"), NULL};
    assert_int_equal(run_rt_out(args, log, out), 0);
    size_t len = 0;
    char *text = test_slurp(out, &len);
    assert_non_null(strstr(text, "\ntriangles: 3400\n"));
    assert_non_null(strstr(text, "\ninstances: 10000\n"));
    assert_non_null(strstr(text, "\ninstanced_triangles: 34000000\n"));
    free(text);
}

/* More instances than --max-memory holds: the load stops before adding
 * any, naming the count and the bytes; exit status 2. */
static void test_cli_instances_over_budget(void **state)
{
    (void)state;
    require_rt();
    test_skip_in_sanitizer_build("rt does not enforce --max-memory there (memory_budget.c)");
    enum { N = 1200000 };
    write_grid_field("huge.glb", 1, 1, N);
    char log[600], want[200];
    snprintf(log, sizeof log, "%s/huge.log", tmp_dir);
    const char *args[] = {rt_bin(), tmp_path("huge.glb"), "--max-memory", "256M", "-r", "32x32", "-s", "1",
                          "-o", tmp_path("huge.png"), NULL};
    assert_int_equal(run_rt(args, log), 2);
    size_t len = 0;
    char *text = test_slurp(log, &len);
    snprintf(want, sizeof want, "out of memory for %d instances (%zu bytes each, %zu bytes)", N, RT_INSTANCE_BYTES,
             (size_t)N * RT_INSTANCE_BYTES);
    if (!strstr(text, want) || !strstr(text, "huge.glb") || !strstr(text, "--max-memory"))
        fail_msg("wanted '%s' naming the file and the budget, got: %s", want, text);
    free(text);
    assert_int_equal(access(tmp_path("huge.png"), F_OK), -1);

    /* the scene format's instance lines: the line, the count and the bytes */
    FILE *fp = fopen(tmp_path("lines.txt"), "w");
    assert_non_null(fp);
    fprintf(fp, "material g color 0.5 0.5 0.5\nobject o\n triangle 0 0 0  1 0 0  0 1 0 g\nend\n");
    for (int i = 0; i < 600000; i++)
        fprintf(fp, "instance o translate %d 0 0\n", i % 1000);
    fclose(fp);
    const char *largs[] = {rt_bin(), tmp_path("lines.txt"), "--max-memory", "64M", "-r", "32x32", "-s", "1",
                           "-o", tmp_path("lines.png"), NULL};
    assert_int_equal(run_rt(largs, log), 2);
    text = test_slurp(log, &len);
    if (!strstr(text, "lines.txt:") || !strstr(text, "out of memory for more than ") || !strstr(text, " instances (") ||
        !strstr(text, "bytes each"))
        fail_msg("wanted the line, the count and the bytes, got: %s", text);
    print_message("%s", text);
    free(text);
}

static size_t count_of(const char *text, const char *what)
{
    size_t n = 0;
    for (const char *p = text; (p = strstr(p, what)); p += strlen(what))
        n++;
    return n;
}

/* Two PFM renders agree within float rounding: 99% of the values within
 * 1e-3 relative, the means within 1e-4. */
static void assert_images_close(const char *a, const char *b)
{
    rt_framebuffer fa, fb;
    rt_error err = {0};
    assert_int_equal(rt_pfm_read(a, &fa, &err), RT_OK);
    assert_int_equal(rt_pfm_read(b, &fb, &err), RT_OK);
    assert_int_equal(fa.width, fb.width);
    assert_int_equal(fa.height, fb.height);
    size_t n = (size_t)fa.width * (size_t)fa.height * 3, close = 0;
    double sa = 0.0, sb = 0.0;
    for (size_t i = 0; i < n; i++) {
        sa += fa.rgb[i];
        sb += fb.rgb[i];
        if (fabsf(fa.rgb[i] - fb.rgb[i]) <= 1e-3f * fmaxf(1.0f, fabsf(fb.rgb[i])))
            close++;
    }
    print_message("%s vs %s: %zu of %zu values within 1e-3, means %.6f and %.6f\n", a, b, close, n, sa / (double)n,
                  sb / (double)n);
    assert_true(sa > 0.0);
    assert_true(close >= n * 99 / 100);
    assert_true(fabs(sa - sb) <= 1e-4 * fabs(sb));
    rt_framebuffer_free(&fa);
    rt_framebuffer_free(&fb);
}

/* --frames over the animation: the object's tree is built for the first
 * frame and kept for the others (rt -v says so); every frame is the
 * flattened load's within rounding. */
static void test_cli_frames(void **state)
{
    (void)state;
    require_rt();
    write_animated();
    char out[600], flat[600], log[600], flog[600];
    snprintf(out, sizeof out, "%s/inst.%%d.pfm", tmp_dir);
    snprintf(flat, sizeof flat, "%s/flat.%%d.pfm", tmp_dir);
    snprintf(log, sizeof log, "%s/frames.log", tmp_dir);
    snprintf(flog, sizeof flog, "%s/flat.log", tmp_dir);
    const char *common[] = {"-v", "-r", "48x36", "-s", "4", "-t", "2", "--frames", "0:4", "--fps", "2",
                            "--look-from", "0,6,9", "--look-at", "0,0.5,0"};
    const char *args[32], *fargs[32];
    int n = 0;
    args[n++] = rt_bin();
    args[n++] = tmp_path("anim.gltf");
    for (size_t i = 0; i < sizeof common / sizeof common[0]; i++)
        args[n++] = common[i];
    memcpy(fargs, args, (size_t)n * sizeof *args);
    int m = n;
    args[n++] = "-o", args[n++] = out, args[n] = NULL;
    fargs[m++] = "--flatten", fargs[m++] = "-o", fargs[m++] = flat, fargs[m] = NULL;
    assert_int_equal(run_rt(args, log), 0);
    assert_int_equal(run_rt(fargs, flog), 0);
    size_t len = 0;
    char *text = test_slurp(log, &len);
    assert_non_null(text);
    assert_int_equal(count_of(text, "objects' trees: 1 built, 0 kept"), 1);
    assert_int_equal(count_of(text, "objects' trees: 0 built, 1 kept"), 3);
    free(text);
    for (int f = 0; f < 4; f++) {
        char a[600], b[600];
        snprintf(a, sizeof a, "%s/inst.%d.pfm", tmp_dir, f);
        snprintf(b, sizeof b, "%s/flat.%d.pfm", tmp_dir, f);
        assert_images_close(a, b);
    }
}

/* An open shutter over the animated model: the slices after the first
 * take the object's tree and build only their top level; the blurred
 * image is the flattened load's within rounding. */
static void test_cli_motion_slices(void **state)
{
    (void)state;
    require_rt();
    write_animated();
    char scene[1024];
    snprintf(scene, sizeof scene,
             "camera position 0 6 9 look_at 0 0.5 0 fov 40 shutter 0 1.5\n"
             "resolution 48 36\nsamples 8\nmotion_steps 4\nintegrator path\n"
             "light directional -0.3 -1 -0.4  1 1 1  3\nbackground 0.3 0.35 0.4\n"
             "model anim.gltf\n");
    test_write_file(tmp_path("blur.txt"), scene, strlen(scene));
    char log[600], flog[600];
    snprintf(log, sizeof log, "%s/blur.log", tmp_dir);
    snprintf(flog, sizeof flog, "%s/blurflat.log", tmp_dir);
    const char *args[] = {rt_bin(), tmp_path("blur.txt"), "-v", "-t", "2", "-o", tmp_path("blur.pfm"), NULL};
    const char *fargs[] = {rt_bin(), tmp_path("blur.txt"), "-v", "-t", "2", "--flatten", "-o",
                           tmp_path("blurflat.pfm"), NULL};
    assert_int_equal(run_rt(args, log), 0);
    assert_int_equal(run_rt(fargs, flog), 0);
    size_t len = 0;
    char *text = test_slurp(log, &len);
    assert_non_null(text);
    assert_int_equal(count_of(text, "objects' trees: 1 built, 0 kept"), 1);
    assert_int_equal(count_of(text, "objects' trees: 0 built, 1 kept from earlier builds"), 3);
    assert_int_equal(count_of(text, "motion: slice"), 4 + 3);
    free(text);
    text = test_slurp(flog, &len);
    assert_non_null(text);
    assert_int_equal(count_of(text, "objects' trees"), 0); /* --flatten reaches the scene's model lines */
    assert_int_equal(count_of(text, "motion: slice"), 4);
    free(text);
    assert_images_close(tmp_path("blur.pfm"), tmp_path("blurflat.pfm"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frames_keep_object_trees),
        cmocka_unit_test(test_kept_only_when_same),
        cmocka_unit_test(test_cli_frames),
        cmocka_unit_test(test_cli_motion_slices),
        cmocka_unit_test(test_model_lines_share_a_load),
        cmocka_unit_test(test_model_lines_order_and_lamps),
        cmocka_unit_test(test_limit_counts_unique_triangles),
        cmocka_unit_test(test_cli_info_counts),
        cmocka_unit_test(test_cli_instances_over_budget),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
