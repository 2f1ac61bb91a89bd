/* test_instance.c - instancing (rt/scene/instance.h, the two-level
 * kd-tree of rt/accel/kdtree.h, the glTF loader's objects and
 * EXT_mesh_gpu_instancing): the instanced tree against brute force over
 * every instance's triangles (same t bits), against the flattened load of
 * the same file (same hits and surfaces within the transforms' rounding,
 * images within float rounding), 10,000 instances through
 * EXT_mesh_gpu_instancing, malformed instancing data (a clear error
 * naming the file and the field, or the documented skip), and the scene
 * format's `object` ... `end` / `instance` lines. The GLB files
 * are written here: a small UV sphere placed on a grid, rotated about y,
 * scaled, some mirrored.
 */
#include "test_util.h"
#include "test_tree_mesh.h"
#include "test_fixture.h"
#include <fcntl.h>
#include <math.h>
#include <unistd.h>
#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_frustum.h"
#include "rt/accel/kdtree_packet.h"
#include "rt/accel/kdtree_batch.h"
#include "rt/accel/kdtree_stream.h"
#include "rt/image/framebuffer.h"
#include "rt/io/gltf.h"
#include "rt/io/load.h"
#include "rt/io/scene_parse.h"
#include "rt/render/render.h"
#include "rt/scene/instance.h"
#include "rt/scene/scene.h"
#include "rt/scene/validate.h"

static char tmp_dir[256];

static int setup(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "instance") ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

static const char *tmp_path(const char *name)
{
    static char buf[512];
    snprintf(buf, sizeof buf, "%s/%s", tmp_dir, name);
    return buf;
}

/* ------------------------------------------------------- the GLB writer */

/* What the field's file holds, and the faults to put in it. */
typedef struct field {
    int n;            /* placements */
    bool nodes;       /* one node per placement (core glTF) instead of EXT_mesh_gpu_instancing */
    int rotation;     /* 0 float, 1 normalized short, 2 normalized byte */
    int scale_short;  /* the SCALE accessor has this many fewer elements */
    int nan_at;       /* this instance's translation is NaN (-1: none) */
    int zero_at;      /* this instance's scale is 0 0 0 (-1: none) */
    int flat_at;      /* this instance's scale is 1 0 1: singular (-1: none) */
    bool rotation_vec3; /* ROTATION declared VEC3 */
} field;

enum { NV = TEST_TREE_NV, NT = TEST_TREE_NT };

typedef struct buf {
    unsigned char *p;
    size_t n, cap;
} buf;

static size_t put(buf *b, const void *data, size_t n)
{
    while (b->n % 4)
        b->p[b->n++] = 0;
    size_t off = b->n;
    if (b->n + n > b->cap) {
        b->cap = 2 * (b->n + n);
        b->p = realloc(b->p, b->cap);
        assert_non_null(b->p);
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
    return off;
}

/* Placement k: grid position, yaw, scale (every 7th mirrored in x). */
static void placement(int k, int n, float t[3], float q[4], float s[3])
{
    int side = (int)ceil(sqrt((double)n));
    t[0] = (float)(k % side) * 1.3f - 0.65f * (float)(side - 1);
    t[1] = (float)((k * 7) % 5) * 0.05f;
    t[2] = (float)(k / side) * 1.3f - 0.65f * (float)(side - 1);
    float yaw = 0.37f * (float)k;
    q[0] = 0.0f, q[1] = sinf(0.5f * yaw), q[2] = 0.0f, q[3] = cosf(0.5f * yaw);
    float sc = 0.7f + 0.1f * (float)(k % 6);
    s[0] = k % 7 == 3 ? -sc : sc, s[1] = sc, s[2] = sc;
}

static void write_field(const char *name, const field *f)
{
    float pos[NV][3], nrm[NV][3];
    uint32_t idx[3 * NT];
    test_tree_mesh(pos, nrm, idx);
    buf b = {malloc(1024), 0, 1024};
    assert_non_null(b.p);
    size_t o_pos = put(&b, pos, sizeof pos), o_nrm = put(&b, nrm, sizeof nrm), o_idx = put(&b, idx, sizeof idx);
    size_t n = (size_t)f->n;
    float *T = malloc(12 * n + 4), *Q = malloc(16 * n + 4), *S = malloc(12 * n + 4);
    int16_t *Q16 = malloc(8 * n + 4);
    int8_t *Q8 = malloc(4 * n + 4);
    assert_true(T && Q && S && Q16 && Q8);
    for (size_t k = 0; k < n; k++) {
        placement((int)k, f->n, T + 3 * k, Q + 4 * k, S + 3 * k);
        for (int c = 0; c < 4; c++) {
            Q16[4 * k + (size_t)c] = (int16_t)lrintf(Q[4 * k + (size_t)c] * 32767.0f);
            Q8[4 * k + (size_t)c] = (int8_t)lrintf(Q[4 * k + (size_t)c] * 127.0f);
        }
        if ((int)k == f->nan_at)
            T[3 * k] = NAN;
        if ((int)k == f->zero_at)
            S[3 * k] = S[3 * k + 1] = S[3 * k + 2] = 0.0f;
        if ((int)k == f->flat_at)
            S[3 * k + 1] = 0.0f;
    }
    size_t o_t = put(&b, T, 12 * n), o_s = put(&b, S, 12 * n);
    size_t o_q = f->rotation == 0 ? put(&b, Q, 16 * n) : f->rotation == 1 ? put(&b, Q16, 8 * n) : put(&b, Q8, 4 * n);
    size_t qbytes = f->rotation == 0 ? 16 * n : f->rotation == 1 ? 8 * n : 4 * n;
    while (b.n % 4)
        b.p[b.n++] = 0;

    size_t jcap = 4096 + (f->nodes ? n * 200 : 0);
    char *js = malloc(jcap);
    assert_non_null(js);
    size_t j = 0;
#define J(...) (j += (size_t)snprintf(js + j, jcap - j, __VA_ARGS__))
    J("{\"asset\":{\"version\":\"2.0\"},\"scene\":0,");
    J("\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.4,0.7,0.3,1],\"metallicFactor\":0}}],");
    J("\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":0}]}],");
    J("\"buffers\":[{\"byteLength\":%zu}],", b.n);
    J("\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,"
      "\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},",
      o_pos, sizeof pos, o_nrm, sizeof nrm, o_idx, sizeof idx);
    J("{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
      "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],",
      o_t, 12 * n, o_s, 12 * n, o_q, qbytes);
    J("\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\",\"min\":[-0.4,0,-0.3],"
      "\"max\":[0.4,1,0.3]},{\"bufferView\":1,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
      "{\"bufferView\":2,\"componentType\":5125,\"count\":%d,\"type\":\"SCALAR\"},",
      NV, NV, 3 * NT);
    J("{\"bufferView\":3,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},", n);
    J("{\"bufferView\":4,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},", n - (size_t)f->scale_short);
    J("{\"bufferView\":5,\"componentType\":%d,\"count\":%zu,\"type\":\"%s\"%s}],",
      f->rotation == 0 ? 5126 : f->rotation == 1 ? 5122 : 5120, f->rotation_vec3 ? n * 4 / 3 : n,
      f->rotation_vec3 ? "VEC3" : "VEC4", f->rotation ? ",\"normalized\":true" : "");
    if (f->nodes) {
        J("\"nodes\":[");
        for (size_t k = 0; k < n; k++)
            J("%s{\"mesh\":0,\"translation\":[%.9g,%.9g,%.9g],\"rotation\":[%.9g,%.9g,%.9g,%.9g],"
              "\"scale\":[%.9g,%.9g,%.9g]}",
              k ? "," : "", (double)T[3 * k], (double)T[3 * k + 1], (double)T[3 * k + 2], (double)Q[4 * k],
              (double)Q[4 * k + 1], (double)Q[4 * k + 2], (double)Q[4 * k + 3], (double)S[3 * k],
              (double)S[3 * k + 1], (double)S[3 * k + 2]);
        J("],\"scenes\":[{\"nodes\":[");
        for (size_t k = 0; k < n; k++)
            J("%s%zu", k ? "," : "", k);
        J("]}]}");
    } else {
        J("\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\"],");
        J("\"nodes\":[{\"mesh\":0,\"translation\":[0,0.25,0],\"extensions\":{\"EXT_mesh_gpu_instancing\":"
          "{\"attributes\":{\"TRANSLATION\":3,\"SCALE\":4,\"ROTATION\":5}}}}],\"scenes\":[{\"nodes\":[0]}]}");
    }
#undef J
    assert_true(j < jcap);
    while (j % 4)
        js[j++] = ' ';
    uint32_t hdr[5] = {0x46546C67u, 2u, (uint32_t)(12 + 8 + j + 8 + b.n), (uint32_t)j, 0x4E4F534Au};
    uint32_t bh[2] = {(uint32_t)b.n, 0x004E4942u};
    FILE *fp = fopen(tmp_path(name), "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(hdr, 4, 5, fp), 5);
    assert_int_equal(fwrite(js, 1, j, fp), j);
    assert_int_equal(fwrite(bh, 4, 2, fp), 2);
    assert_int_equal(fwrite(b.p, 1, b.n, fp), b.n);
    fclose(fp);
    free(js);
    free(b.p);
    free(T);
    free(Q);
    free(S);
    free(Q16);
    free(Q8);
}

static field field_of(int n)
{
    field f = {n, false, 0, 0, -1, -1, -1, false};
    return f;
}

/* Loads a file with the glTF loader (flatten: every use flattened);
 * stderr goes to a file, *warning gets its first line. */
static rt_result load(const char *name, bool flatten, rt_scene *s, rt_gltf_stats *st, rt_error *err, char *warning,
                      size_t wcap)
{
    char log[512];
    snprintf(log, sizeof log, "%s/stderr.txt", tmp_dir);
    fflush(stderr);
    int saved = dup(2);
    int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    rt_scene_init(s);
    memset(err, 0, sizeof *err);
    memset(st, 0, sizeof *st);
    rt_gltf_options opt = {0};
    opt.flatten_instances = flatten;
    rt_result r = rt_gltf_load(s, tmp_path(name), &opt, st, err);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    if (warning) {
        FILE *fp = fopen(log, "rb");
        assert_non_null(fp);
        size_t k = fread(warning, 1, wcap - 1, fp);
        warning[k] = 0;
        fclose(fp);
    }
    return r;
}

/* ----------------------------------------------------------- the rays */

/* Ray i of a set over the field: from above and from the side, towards
 * points scattered over the field's box. */
static rt_ray field_ray(test_rng *g, rt_box b)
{
    rt_vec3 c = rt_scale(rt_add(b.lo, b.hi), 0.5f), e = rt_sub(b.hi, b.lo);
    rt_vec3 target = rt_v3(b.lo.x + e.x * test_rng_float(g), b.lo.y + e.y * test_rng_float(g),
                           b.lo.z + e.z * test_rng_float(g));
    float a = 6.2831853f * test_rng_float(g), h = 0.2f + 1.2f * test_rng_float(g);
    float r = 0.8f * (e.x + e.z);
    rt_vec3 o = rt_add(c, rt_v3(r * cosf(a), r * h, r * sinf(a)));
    return rt_ray_make(o, rt_sub(target, o), 0.0f, INFINITY);
}

/* The closest hit over every instance's triangles, each tested in object
 * space on the transformed ray (what the bottom trees must find). */
static bool brute_force(const rt_scene *s, const rt_ray *ray, rt_hit *best)
{
    best->t = ray->tmax;
    best->prim = RT_NONE;
    for (size_t i = 0; i < s->instance_count; i++) {
        const rt_instance *in = &s->instances[i];
        const rt_object *o = &s->objects[in->object];
        rt_vec3 org = rt_mat4_point(&in->to_object, ray->org), dir = rt_mat4_vector(&in->to_object, ray->dir);
        for (size_t t = o->first_triangle; t < o->first_triangle + o->triangle_count; t++) {
            float th, u, v;
            if (rt_intersect_triangle(org, dir, rt_tri_vertex(s, t, 0), rt_tri_vertex(s, t, 1),
                                      rt_tri_vertex(s, t, 2), ray->tmin, best->t, &th, &u, &v)) {
                best->t = th, best->u = u, best->v = v, best->prim = (uint32_t)t, best->inst = (uint32_t)i + 1;
            }
        }
    }
    return best->prim != RT_NONE;
}

/* ----------------------------------------------------------- the tests */

/* The instanced tree finds exactly brute force's hits (same t bits, same
 * instance and triangle), closest and any, single rays and batches, on
 * both traversals; and the surface at each hit is the flattened load's. */
static void test_instanced_hits(void **state)
{
    (void)state;
    field f = field_of(60);
    write_field("field.glb", &f);
    rt_scene si, sf;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load("field.glb", false, &si, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(si.object_count, 1);
    assert_int_equal(si.instance_count, 60);
    assert_int_equal(si.triangles.count, NT);
    assert_int_equal(st.instances, 60);
    assert_int_equal(st.instanced_triangles, 60 * NT);
    assert_int_equal(rt_scene_instanced_triangles(&si), 60 * NT);
    assert_int_equal(load("field.glb", true, &sf, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(sf.instance_count, 0);
    assert_int_equal(sf.triangles.count, 60 * NT);
    /* the instances' boxes (their object's box, transformed) hold the flattened geometry */
    rt_box bi = rt_scene_bounds(&si), bf = rt_scene_bounds(&sf);
    assert_true(bi.lo.x <= bf.lo.x && bi.lo.y <= bf.lo.y && bi.lo.z <= bf.lo.z);
    assert_true(bi.hi.x >= bf.hi.x && bi.hi.y >= bf.hi.y && bi.hi.z >= bf.hi.z);

    for (int portable = 0; portable < 2; portable++) {
        rt_kdtree_params par = {0};
        par.portable = portable;
        rt_kdtree ti, tf;
        assert_int_equal(rt_kdtree_build(&ti, &si, &par, &err), RT_OK);
        assert_int_equal(rt_kdtree_build(&tf, &sf, &par, &err), RT_OK);
        assert_int_equal(ti.instance_count, 60);
        test_rng g = {12345};
        enum { N = 3000 };
        static float ox[N], oy[N], oz[N], dx[N], dy[N], dz[N], tmin[N], tmax[N], ht[N], hu[N], hv[N];
        static uint32_t hp[N], hi[N];
        static uint8_t blocked[N];
        int hits = 0, agree = 0;
        for (int k = 0; k < N; k++) {
            rt_ray r = field_ray(&g, bf);
            ox[k] = r.org.x, oy[k] = r.org.y, oz[k] = r.org.z, dx[k] = r.dir.x, dy[k] = r.dir.y, dz[k] = r.dir.z;
            tmin[k] = 0.0f, tmax[k] = INFINITY;
            rt_hit h, b, hflat;
            bool found = rt_kdtree_intersect(&ti, &r, &h);
            bool want = brute_force(&si, &r, &b);
            assert_int_equal(found, want);
            assert_int_equal(rt_kdtree_occluded(&ti, &r), want);
            if (!found)
                continue;
            hits++;
            assert_true(h.t == b.t); /* the same bits */
            if (h.inst != b.inst || h.prim != b.prim)
                continue; /* a tie at a shared edge: either is right */
            assert_true(h.u == b.u && h.v == b.v);
            /* the flattened load: instance k's copy of triangle j is k * NT + j */
            bool ff = rt_kdtree_intersect(&tf, &r, &hflat);
            assert_true(ff);
            assert_true(fabsf(hflat.t - h.t) <= 1e-4f * h.t);
            if (hflat.prim == (h.inst - 1) * NT + h.prim)
                agree++;
        }
        print_message("%s: %d of %d rays hit; %d of them the flattened copy's triangle\n",
                      portable ? "portable" : "AVX2", hits, N, agree);
        assert_true(hits > N / 4);
        assert_true(agree >= hits * 99 / 100); /* the rest: ties on edges, decided by rounding */
        rt_ray_batch rb = {ox, oy, oz, dx, dy, dz, tmin, tmax};
        rt_hit_batch hb = {ht, hu, hv, hp, hi};
        assert_int_equal(rt_kdtree_intersect_batch(&ti, &rb, NULL, N, &hb), (size_t)hits);
        assert_int_equal(rt_kdtree_occluded_batch(&ti, &rb, NULL, N, blocked), (size_t)hits);
        for (int k = 0; k < N; k++) {
            rt_ray r = rt_ray_make(rt_v3(ox[k], oy[k], oz[k]), rt_v3(dx[k], dy[k], dz[k]), 0.0f, INFINITY);
            rt_hit h;
            if (rt_kdtree_intersect(&ti, &r, &h)) {
                assert_true(hp[k] == h.prim && hi[k] == h.inst && ht[k] == h.t);
                assert_int_equal(blocked[k], 1);
            } else {
                assert_int_equal(hp[k], RT_NONE);
            }
        }
        /* packets and frustum tiles enter instances as sub-packets, with the
         * single walk's answers (test_instanced_packets_streams: more) */
        for (int k = 0; k < 40; k++) {
            /* a tile of 8x8 coherent rays from one point, towards a small patch of the field */
            rt_ray rays[64];
            rt_hit ph[64], fh[64];
            rt_ray c = field_ray(&g, bf);
            rt_vec3 e = rt_sub(bf.hi, bf.lo);
            for (int j = 0; j < 64; j++) {
                rt_vec3 off = rt_v3(e.x * 0.02f * (float)(j % 8 - 4), e.y * 0.02f * (float)(j / 8 - 4), 0.0f);
                rays[j] = rt_ray_make(c.org, rt_add(c.dir, off), 0.0f, INFINITY);
            }
            unsigned p16 = rt_kdtree_intersect16(&ti, rays, 16, ph), o16 = rt_kdtree_occluded16(&ti, rays, 16);
            uint64_t f64 = rt_kdtree_intersect_frustum(&ti, rays, 64, fh), fo64 = rt_kdtree_occluded_frustum(&ti, rays, 64);
            for (int j = 0; j < 64; j++) {
                rt_hit h;
                bool found = rt_kdtree_intersect(&ti, &rays[j], &h);
                assert_int_equal((f64 >> j) & 1, found);
                assert_int_equal((fo64 >> j) & 1, found);
                if (found)
                    assert_true(fh[j].t == h.t && fh[j].prim == h.prim && fh[j].inst == h.inst);
                if (j < 16) {
                    assert_int_equal((p16 >> j) & 1, found);
                    assert_int_equal((o16 >> j) & 1, found);
                    if (found)
                        assert_true(ph[j].t == h.t && ph[j].prim == h.prim && ph[j].inst == h.inst);
                }
            }
        }
        rt_kdtree_free(&ti);
        rt_kdtree_free(&tf);
    }
    rt_scene_free(&si);
    rt_scene_free(&sf);
}

/* A mesh shared by nodes is kept once: instances and the flattened load
 * agree, the mirrored placements included; normals rotated and flipped
 * as flattening makes them. */
static void test_shared_mesh_nodes(void **state)
{
    (void)state;
    field f = field_of(14);
    f.nodes = true;
    write_field("nodes.glb", &f);
    rt_scene si, sf;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load("nodes.glb", false, &si, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(si.instance_count, 14);
    assert_int_equal(si.object_count, 1);
    assert_true(si.instances[3].mirror && !si.instances[2].mirror);
    assert_int_equal(load("nodes.glb", true, &sf, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(sf.triangles.count, 14 * NT);
    /* a vertex through instance k equals the flattened copy's (within rounding) */
    for (size_t k = 0; k < 14; k++) {
        const rt_instance *in = &si.instances[k];
        for (uint32_t t = 0; t < NT; t++) {
            /* the flattened copy's corners (winding flipped when mirrored) */
            size_t ft = k * NT + t;
            for (int c = 0; c < 3; c++) {
                int oc = in->mirror && c > 0 ? 3 - c : c;
                rt_vec3 p = rt_mat4_point(&in->to_world, rt_tri_vertex(&si, t, oc));
                rt_vec3 q = rt_tri_vertex(&sf, ft, c);
                assert_true(rt_length(rt_sub(p, q)) < 1e-5f);
                /* the world normal: by the normal matrix, renormalised */
                rt_vec3 n = rt_normalize(rt_mat4_vector(&in->normal, si.vertices.normal[si.triangles.index[3 * t + (size_t)oc]]));
                rt_vec3 m = sf.vertices.normal[sf.triangles.index[3 * ft + (size_t)c]];
                assert_true(rt_length(rt_sub(n, m)) < 1e-5f);
            }
        }
    }
    rt_scene_free(&si);
    rt_scene_free(&sf);
}

/* Renders of the instanced and the flattened load agree within float
 * rounding of the transforms: the same paths, values equal to 1e-3
 * relative (99% of them: room for the odd path that grazes an edge; all
 * of them when written), means to 1e-4. */
static void render(rt_scene *s, const rt_camera *cam, rt_framebuffer *fb)
{
    rt_settings set;
    rt_settings_default(&set);
    set.width = 64;
    set.height = 48;
    set.samples = 4;
    set.integrator = RT_INTEGRATOR_PATH;
    s->camera = *cam;
    s->camera_set = true;
    rt_light l;
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_DIRECTIONAL;
    l.color = rt_v3s(1);
    l.intensity = 3.0f;
    l.direction = rt_normalize(rt_v3(-0.3f, -1.0f, -0.4f));
    l.quad = RT_NONE;
    assert_int_not_equal(rt_scene_add_light(s, &l), RT_NONE);
    s->environment.background = rt_v3(0.3f, 0.35f, 0.4f);
    test_render_scene(s, &set, 2, 0, fb);
}

static void test_instanced_image(void **state)
{
    (void)state;
    field f = field_of(25);
    write_field("image.glb", &f);
    rt_scene si, sf;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load("image.glb", false, &si, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(load("image.glb", true, &sf, &st, &err, NULL, 0), RT_OK);
    rt_framebuffer a, b;
    rt_scene_frame_camera(&sf, 64.0f / 48.0f); /* one camera for both: the instanced bounds are boxes */
    rt_camera cam = sf.camera;
    render(&si, &cam, &a);
    render(&sf, &cam, &b);
    size_t n = (size_t)a.width * (size_t)a.height * 3, close = 0;
    double sa = 0.0, sb = 0.0;
    for (size_t i = 0; i < n; i++) {
        sa += a.rgb[i];
        sb += b.rgb[i];
        if (fabsf(a.rgb[i] - b.rgb[i]) <= 1e-3f * fmaxf(1.0f, fabsf(b.rgb[i])))
            close++;
    }
    print_message("instanced vs flattened image: %zu of %zu values within 1e-3, means %.6f and %.6f\n", close, n,
                  sa / (double)n, sb / (double)n);
    assert_true(close >= n * 99 / 100);
    assert_true(fabs(sa - sb) <= 1e-4 * fabs(sb));
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
    rt_scene_free(&si);
    rt_scene_free(&sf);
}

/* 10,000 instances through EXT_mesh_gpu_instancing (rotations as
 * normalized shorts): one object, 10,000 instances, the tree's hits are
 * brute force's. */
static void test_ten_thousand(void **state)
{
    (void)state;
    field f = field_of(10000);
    f.rotation = 1;
    write_field("many.glb", &f);
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load("many.glb", false, &s, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(s.instance_count, 10000);
    assert_int_equal(s.triangles.count, NT);
    assert_int_equal(st.instanced_triangles, (size_t)10000 * NT);
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_kdtree t;
    assert_int_equal(rt_kdtree_build(&t, &s, NULL, &err), RT_OK);
    test_rng g = {99};
    rt_box b = rt_scene_bounds(&s);
    int hits = 0;
    for (int k = 0; k < 150; k++) {
        rt_ray r = field_ray(&g, b);
        rt_hit h, want;
        bool found = rt_kdtree_intersect(&t, &r, &h);
        assert_int_equal(found, brute_force(&s, &r, &want));
        if (found) {
            hits++;
            assert_true(h.t == want.t);
        }
    }
    assert_true(hits > 50);
    /* the byte rotations load as well (the same placements, coarser) */
    f.rotation = 2;
    f.n = 100;
    write_field("bytes.glb", &f);
    rt_scene s2;
    assert_int_equal(load("bytes.glb", false, &s2, &st, &err, NULL, 0), RT_OK);
    assert_int_equal(s2.instance_count, 100);
    rt_scene_free(&s2);
    rt_kdtree_free(&t);
    rt_scene_free(&s);
}

/* Malformed instancing data: an error naming the file and the field, and
 * the scene as it was; zero and singular scales are skipped with a
 * warning that says so. */
static void test_malformed(void **state)
{
    (void)state;
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    char warning[1024];
    field f = field_of(10);
    f.scale_short = 1;
    write_field("counts.glb", &f);
    assert_int_equal(load("counts.glb", false, &s, &st, &err, NULL, 0), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "counts.glb"));
    assert_non_null(strstr(err.message, "nodes[0].extensions.EXT_mesh_gpu_instancing.attributes"));
    assert_non_null(strstr(err.message, "same count"));
    assert_int_equal(s.triangles.count, 0);
    assert_int_equal(s.instance_count, 0);
    rt_scene_free(&s);

    f = field_of(10);
    f.nan_at = 4;
    write_field("nan.glb", &f);
    assert_int_equal(load("nan.glb", false, &s, &st, &err, NULL, 0), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "nan.glb"));
    assert_non_null(strstr(err.message, "attributes.TRANSLATION"));
    assert_non_null(strstr(err.message, "element 4 is not finite"));
    rt_scene_free(&s);
    /* ... and flattened the same */
    assert_int_equal(load("nan.glb", true, &s, &st, &err, NULL, 0), RT_ERR_INVALID);
    rt_scene_free(&s);

    f = field_of(10);
    f.rotation_vec3 = true;
    write_field("vec3.glb", &f);
    assert_int_equal(load("vec3.glb", false, &s, &st, &err, NULL, 0), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "attributes.ROTATION"));
    assert_non_null(strstr(err.message, "VEC4"));
    rt_scene_free(&s);

    f = field_of(10);
    f.zero_at = 2;
    f.flat_at = 6;
    write_field("zero.glb", &f);
    assert_int_equal(load("zero.glb", false, &s, &st, &err, warning, sizeof warning), RT_OK);
    assert_int_equal(s.instance_count, 8);
    assert_non_null(strstr(warning, "zero.glb"));
    assert_non_null(strstr(warning, "2 of 10 instances skipped"));
    assert_non_null(strstr(warning, "singular"));
    rt_scene_free(&s);
}

/* Rollback: a failed load after instances were added leaves none. */
static void test_rollback(void **state)
{
    (void)state;
    field f = field_of(5);
    write_field("ok.glb", &f);
    rt_scene s;
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load("ok.glb", false, &s, &st, &err, NULL, 0), RT_OK);
    rt_scene_mark m = rt_scene_mark_of(&s);
    assert_int_equal(rt_gltf_load(&s, tmp_path("ok.glb"), NULL, &st, &err), RT_OK);
    assert_int_equal(s.instance_count, 10);
    assert_int_equal(s.object_count, 2);
    rt_scene_rollback(&s, &m);
    assert_int_equal(s.instance_count, 5);
    assert_int_equal(s.object_count, 1);
    rt_scene_free(&s);
}

/* The scene format's `object NAME` ... `end` and `instance NAME ...`:
 * one object, three placements (one mirrored), hits as brute force finds
 * them; and the errors, each naming the line. */
static void test_scene_objects(void **state)
{
    (void)state;
    const char *text = "material g color 0.3 0.7 0.3\n"
                       "object tree\n"
                       "  triangle -0.5 0 0  0.5 0 0  0 1.5 0 g\n"
                       "  triangle 0 0 -0.5  0 0 0.5  0 1.5 0 g\n"
                       "end\n"
                       "instance tree\n"
                       "instance tree translate 2 0 0 rotate 0 45 0 scale 1.5\n"
                       "instance tree translate -2 0 1 scale -1 1 1\n"
                       "sphere 0 -100 0 99.9 g\n";
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    assert_int_equal(rt_scene_parse_string(&s, NULL, text, strlen(text), "objects.txt", "", &err), RT_OK);
    assert_int_equal(s.object_count, 1);
    assert_int_equal(s.instance_count, 3);
    assert_int_equal(s.triangles.count, 2);
    assert_true(s.instances[2].mirror);
    rt_vec3 p = rt_mat4_point(&s.instances[1].to_world, rt_v3(0, 1.5f, 0));
    assert_true(fabsf(p.x - 2.0f) < 1e-6f && fabsf(p.y - 2.25f) < 1e-6f);
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_kdtree t;
    assert_int_equal(rt_kdtree_build(&t, &s, NULL, &err), RT_OK);
    test_rng g = {7};
    int hits = 0;
    for (int k = 0; k < 2000; k++) {
        rt_ray r = rt_ray_make(rt_v3(8.0f * test_rng_float(&g) - 4.0f, 3.0f * test_rng_float(&g), 6.0f),
                               rt_v3(0.2f * test_rng_float(&g) - 0.1f, -0.1f * test_rng_float(&g), -1.0f), 0.0f,
                               INFINITY);
        rt_hit h, want;
        bool b = brute_force(&s, &r, &want);
        bool found = rt_kdtree_intersect(&t, &r, &h);
        if (found && h.inst == 0)
            continue; /* the ground sphere, which brute_force does not test */
        if (b && found) {
            hits++;
            assert_true(h.t == want.t && h.inst == want.inst);
        } else {
            assert_false(b && (!found || h.t > want.t));
        }
    }
    assert_true(hits > 100);
    rt_kdtree_free(&t);
    rt_scene_free(&s);

    const struct {
        const char *text, *message;
    } bad[] = {
        {"material g color 1 1 1\nobject a\n sphere 0 0 0 1 g\nend\n", "objects.txt:3:2: 'sphere' inside object 'a'"},
        {"material g color 1 1 1\nobject a\n triangle 0 0 0 1 0 0 0 1 0 g\n", "objects.txt:2:8: object 'a' has no 'end'"},
        {"end\n", "objects.txt:1:1: 'end' without an open 'object'"},
        {"object a\nend\n", "object 'a' holds no triangles"},
        {"material g color 1 1 1\nobject tree\n triangle 0 0 0 1 0 0 0 1 0 g\nend\ninstance tre\n",
         "objects.txt:5:10: undefined object 'tre' (did you mean 'tree'?)"},
        {"material g color 1 1 1\nobject a\n triangle 0 0 0 1 0 0 0 1 0 g\nend\ninstance a scale 0\n",
         "must not be zero"},
        {"material g color 1 1 1\nobject a\n triangle 0 0 0 1 0 0 0 1 0 g\n instance a\nend\n", "'instance' inside object 'a'"},
        {"material g color 1 1 1\nobject a\n triangle 0 0 0 1 0 0 0 1 0 g\nend\nobject a\n", "object 'a' is already defined on line 2"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        rt_scene_init(&s);
        memset(&err, 0, sizeof err);
        rt_result r = rt_scene_parse_string(&s, NULL, bad[i].text, strlen(bad[i].text), "objects.txt", "", &err);
        if (r == RT_OK || !strstr(err.message, bad[i].message))
            fail_msg("case %zu: %d '%s', wanted '%s'", i, (int)r, err.message, bad[i].message);
        assert_int_equal(s.object_count, 0);
        assert_int_equal(s.instance_count, 0);
        rt_scene_free(&s);
    }
}

/* Many objects: their trees are built side by side on several threads
 * (kdtree_instances.c) and are the same, array for array, as built on
 * one; the hits too. */
static void test_parallel_object_builds(void **state)
{
    (void)state;
    char *text = malloc(1 << 16);
    assert_non_null(text);
    size_t n = (size_t)snprintf(text, 1 << 16, "material g color 0.5 0.5 0.5\n");
    test_rng g = {31};
    for (int o = 0; o < 24; o++) {
        n += (size_t)snprintf(text + n, (1 << 16) - n, "object o%d\n", o);
        for (int k = 0; k <= o % 7; k++) {
            float x = test_rng_float(&g), y = test_rng_float(&g), z = test_rng_float(&g);
            n += (size_t)snprintf(text + n, (1 << 16) - n, " triangle %g %g %g  %g %g %g  %g %g %g g\n", x, y, z,
                                  x + 0.3, y, z + 0.1, x, y + 0.4, z + 0.2);
        }
        n += (size_t)snprintf(text + n, (1 << 16) - n, "end\ninstance o%d translate %d 0 %d\n", o, o % 6, o / 6);
    }
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    assert_int_equal(rt_scene_parse_string(&s, NULL, text, n, "many.txt", "", &err), RT_OK);
    free(text);
    assert_int_equal(s.object_count, 24);
    rt_kdtree a, b;
    rt_kdtree_params p1 = {0}, p4 = {0};
    p1.threads = 1;
    p4.threads = 4;
    assert_int_equal(rt_kdtree_build(&a, &s, &p1, &err), RT_OK);
    assert_int_equal(rt_kdtree_build(&b, &s, &p4, &err), RT_OK);
    assert_int_equal(a.object_count, 24);
    assert_int_equal(b.object_count, 24);
    for (size_t o = 0; o < 24; o++) {
        const rt_kdtree *x = &a.objects[o], *y = &b.objects[o];
        assert_int_equal(x->wide_count, y->wide_count);
        assert_int_equal(x->prim_id_count, y->prim_id_count);
        assert_int_equal(x->root, y->root);
        assert_memory_equal(x->wide, y->wide, x->wide_count * sizeof *x->wide);
        assert_memory_equal(x->prim_ids, y->prim_ids, x->prim_id_count * sizeof *x->prim_ids);
    }
    rt_box bb = rt_scene_bounds(&s);
    for (int k = 0; k < 500; k++) {
        rt_ray r = field_ray(&g, bb);
        rt_hit ha, hb, want;
        bool fa = rt_kdtree_intersect(&a, &r, &ha), fb = rt_kdtree_intersect(&b, &r, &hb);
        assert_int_equal(fa, brute_force(&s, &r, &want));
        assert_int_equal(fa, fb);
        if (fa)
            assert_true(ha.t == hb.t && ha.t == want.t && ha.prim == hb.prim && ha.inst == hb.inst);
    }
    rt_kdtree_free(&a);
    rt_kdtree_free(&b);
    rt_scene_free(&s);
}

/* ------------------------------------- packets and streams in instances */

/* A scene whose top level mixes world triangles, spheres and instances
 * of three objects (some mirrored, rotated, scaled), from the scene
 * format: leaves with instances beside other primitives. */
static void mixed_scene(rt_scene *s)
{
    size_t cap = 1 << 17, n = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    test_rng g = {77};
    n += (size_t)snprintf(text + n, cap - n, "material g color 0.5 0.5 0.5\n");
    for (int o = 0; o < 3; o++) { /* a cluster of triangles */
        n += (size_t)snprintf(text + n, cap - n, "object o%d\n", o);
        for (int k = 0; k < 40 + 30 * o; k++) {
            float x = test_rng_float(&g), y = test_rng_float(&g), z = test_rng_float(&g);
            n += (size_t)snprintf(text + n, cap - n, " triangle %g %g %g  %g %g %g  %g %g %g g\n", x, y, z,
                                  x + 0.2 + 0.1 * test_rng_float(&g), y, z + 0.1, x, y + 0.3, z + 0.2);
        }
        n += (size_t)snprintf(text + n, cap - n, "end\n");
    }
    for (int k = 0; k < 150; k++)
        n += (size_t)snprintf(text + n, cap - n, "instance o%d translate %g %g %g rotate %d %d %d scale %s%g 1 1\n",
                              k % 3, (double)(k % 12) * 1.1, (double)(k % 5) * 0.3, (double)(k / 12) * 1.1,
                              (k * 37) % 360, (k * 53) % 360, (k * 11) % 90, k % 5 == 2 ? "-" : "",
                              0.6 + 0.1 * (k % 7));
    for (int k = 0; k < 30; k++) { /* world geometry among them */
        float x = 13.0f * test_rng_float(&g), y = 1.5f * test_rng_float(&g), z = 14.0f * test_rng_float(&g);
        n += (size_t)snprintf(text + n, cap - n, "triangle %g %g %g  %g %g %g  %g %g %g g\n", x, y, z, x + 0.7, y,
                              z, x, y + 0.6, z + 0.3);
        if (k % 3 == 0)
            n += (size_t)snprintf(text + n, cap - n, "sphere %g %g %g %g g\n", x + 0.3, y, z - 0.4, 0.25);
    }
    assert_true(n < cap);
    rt_scene_init(s);
    rt_error err = {0};
    assert_int_equal(rt_scene_parse_string(s, NULL, text, n, "mixed.txt", "", &err), RT_OK);
    free(text);
    assert_int_equal(s->object_count, 3);
    assert_int_equal(s->instance_count, 150);
}

/* Brute force over everything: the world triangles (those of no object)
 * and spheres, and every instance's triangles on the transformed ray. */
static bool brute_force_all(const rt_scene *s, const rt_ray *ray, rt_hit *best)
{
    rt_ray r = *ray;
    rt_hit b;
    bool any = brute_force(s, &r, &b);
    if (any)
        r.tmax = b.t;
    for (size_t t = 0; t < s->triangles.count; t++) {
        bool in_object = false;
        for (size_t o = 0; o < s->object_count; o++)
            if (t >= s->objects[o].first_triangle && t < s->objects[o].first_triangle + s->objects[o].triangle_count)
                in_object = true;
        float th, u, v;
        if (!in_object && rt_intersect_triangle(r.org, r.dir, rt_tri_vertex(s, t, 0), rt_tri_vertex(s, t, 1),
                                                rt_tri_vertex(s, t, 2), r.tmin, r.tmax, &th, &u, &v)) {
            r.tmax = th, b.t = th, b.u = u, b.v = v, b.prim = (uint32_t)t, b.inst = 0, any = true;
        }
    }
    const rt_spheres *sp = &s->spheres;
    for (size_t i = 0; i < sp->count; i++) {
        float th;
        if (rt_intersect_sphere(r.org, r.dir, rt_v3(sp->cx[i], sp->cy[i], sp->cz[i]), sp->radius[i], r.tmin, r.tmax,
                                &th)) {
            r.tmax = th, b.t = th, b.u = b.v = 0.0f, b.prim = (uint32_t)(s->triangles.count + i), b.inst = 0;
            any = true;
        }
    }
    *best = b;
    return any;
}

/* A hit against the single walk's: the same bits (t, prim, inst, u, v),
 * or, where two primitives tie at exactly the same t, the other one. */
static void assert_same_hit(const rt_scene *s, const rt_ray *ray, const rt_hit *got, const rt_hit *want)
{
    assert_true(got->t == want->t);
    if (got->prim == want->prim && got->inst == want->inst) {
        assert_true(got->u == want->u && got->v == want->v);
        return;
    }
    /* a tie: the other primitive must be hit at the same t */
    assert_true(got->prim < s->triangles.count);
    rt_vec3 org = ray->org, dir = ray->dir;
    if (got->inst) {
        const rt_mat4 *x = &s->instances[got->inst - 1].to_object;
        org = rt_mat4_point(x, org), dir = rt_mat4_vector(x, dir);
    }
    float th, u, v;
    assert_true(rt_intersect_triangle(org, dir, rt_tri_vertex(s, got->prim, 0), rt_tri_vertex(s, got->prim, 1),
                                      rt_tri_vertex(s, got->prim, 2), ray->tmin, INFINITY, &th, &u, &v));
    assert_true(th == got->t && u == got->u && v == got->v);
}

enum { TILES = 48, TILE = 64, PS_N = TILES * TILE };

/* The rays: TILES tiles of 8x8 coherent rays (one origin, towards a patch
 * of the scene; every third tile's rays end at the patch, tmax 1), then
 * as many incoherent ones (random origins around the box, random targets,
 * every third ending at its target). */
static void packet_rays(rt_box b, rt_ray *coh, rt_ray *inc)
{
    test_rng g = {4242};
    rt_vec3 e = rt_sub(b.hi, b.lo);
    for (int k = 0; k < TILES; k++) {
        rt_ray c = field_ray(&g, b);
        float step = 0.004f + 0.02f * test_rng_float(&g);
        for (int j = 0; j < TILE; j++) {
            rt_vec3 off = rt_v3(e.x * step * (float)(j % 8 - 4), e.y * step * (float)(j / 8 - 4), e.z * step * 0.5f);
            coh[k * TILE + j] = rt_ray_make(c.org, rt_add(c.dir, off), 0.0f, k % 3 == 1 ? 1.0f : INFINITY);
        }
    }
    for (int k = 0; k < PS_N; k++) {
        inc[k] = field_ray(&g, b);
        if (k % 3 == 1)
            inc[k].tmax = 1.0f;
    }
}

/* Every traversal of rays through the instanced tree t against the single
 * walk (and that against brute force): packets of 8 and 16, frustum tiles,
 * the wavefront batch, streams at every width the CPU has, two chunk
 * sizes; closest and any hit. */
static void check_packets_streams(const rt_scene *s, const rt_kdtree *t, const rt_ray *rays, int n, bool tiles,
                                  bool brute)
{
    rt_hit *want = malloc((size_t)n * sizeof *want), *got = malloc((size_t)n * sizeof *got);
    bool *hit = malloc((size_t)n * sizeof *hit);
    float *f = malloc((size_t)n * 11 * sizeof *f);
    uint32_t *hp = malloc((size_t)n * 2 * sizeof *hp);
    uint8_t *blocked = malloc((size_t)n);
    assert_true(want && got && hit && f && hp && blocked);
    int hits = 0, through = 0;
    for (int k = 0; k < n; k++) {
        hit[k] = rt_kdtree_intersect(t, &rays[k], &want[k]);
        rt_hit b;
        if (brute) /* (once a scene: the other traversal is held to this one) */
            assert_int_equal(brute_force_all(s, &rays[k], &b), hit[k]);
        if (hit[k]) {
            assert_true(!brute || b.t == want[k].t);
            hits++;
            through += want[k].inst != 0;
        }
    }
    assert_true(hits > n / 5);
    assert_true(through > hits / 2);
    /* packets of 8 and 16, closest and any */
    for (int w = 8; w <= 16; w += 8)
        for (int k0 = 0; k0 < n; k0 += w) {
            int m = n - k0 < w ? n - k0 : w;
            unsigned pm = w == 8 ? rt_kdtree_intersect8(t, rays + k0, m, got + k0)
                                 : rt_kdtree_intersect16(t, rays + k0, m, got + k0);
            unsigned om = w == 8 ? rt_kdtree_occluded8(t, rays + k0, m) : rt_kdtree_occluded16(t, rays + k0, m);
            for (int j = 0; j < m; j++) {
                assert_int_equal(pm >> j & 1u, hit[k0 + j]);
                assert_int_equal(om >> j & 1u, hit[k0 + j]);
                if (hit[k0 + j])
                    assert_same_hit(s, &rays[k0 + j], &got[k0 + j], &want[k0 + j]);
            }
        }
    /* frustum tiles */
    for (int k0 = 0; k0 < n; k0 += RT_KD_FRUSTUM_MAX) {
        int m = n - k0 < RT_KD_FRUSTUM_MAX ? n - k0 : RT_KD_FRUSTUM_MAX;
        uint64_t fm = rt_kdtree_intersect_frustum(t, rays + k0, m, got + k0);
        uint64_t fo = rt_kdtree_occluded_frustum(t, rays + k0, m);
        for (int j = 0; j < m; j++) {
            assert_int_equal(fm >> j & 1u, hit[k0 + j]);
            assert_int_equal(fo >> j & 1u, hit[k0 + j]);
            if (hit[k0 + j])
                assert_same_hit(s, &rays[k0 + j], &got[k0 + j], &want[k0 + j]);
        }
    }
    /* the batch and the streams, from structure-of-arrays */
    float *ox = f, *oy = f + n, *oz = f + 2 * n, *dx = f + 3 * n, *dy = f + 4 * n, *dz = f + 5 * n, *tmin = f + 6 * n,
          *tmax = f + 7 * n, *ht = f + 8 * n, *hu = f + 9 * n, *hv = f + 10 * n;
    for (int k = 0; k < n; k++) {
        ox[k] = rays[k].org.x, oy[k] = rays[k].org.y, oz[k] = rays[k].org.z;
        dx[k] = rays[k].dir.x, dy[k] = rays[k].dir.y, dz[k] = rays[k].dir.z;
        tmin[k] = rays[k].tmin, tmax[k] = rays[k].tmax;
    }
    rt_ray_batch rb = {ox, oy, oz, dx, dy, dz, tmin, tmax};
    rt_hit_batch hb = {ht, hu, hv, hp, hp + n};
    for (int pass = -1; pass < 6; pass++) {
        rt_kd_stream_params sp = {0};
        sp.lanes = pass < 0 ? 0 : 4 << (pass % 3);
        sp.chunk = pass >= 3 ? 200 : 0;
        if (pass >= 0 && !rt_kd_stream_lanes_supported(sp.lanes))
            continue;
        memset(hp, 0xab, (size_t)n * 2 * sizeof *hp);
        size_t c = pass < 0 ? rt_kdtree_intersect_batch(t, &rb, NULL, (size_t)n, &hb)
                            : rt_kdtree_intersect_stream(t, &rb, (size_t)n, &hb, &sp);
        assert_int_equal(c, (size_t)hits);
        size_t o = pass < 0 ? rt_kdtree_occluded_batch(t, &rb, NULL, (size_t)n, blocked)
                            : rt_kdtree_occluded_stream(t, &rb, (size_t)n, blocked, &sp);
        assert_int_equal(o, (size_t)hits);
        for (int k = 0; k < n; k++) {
            assert_int_equal(blocked[k], hit[k]);
            if (!hit[k]) {
                assert_int_equal(hb.prim[k], RT_NONE);
                continue;
            }
            rt_hit h = {ht[k], hu[k], hv[k], hb.prim[k], hb.inst[k]};
            assert_same_hit(s, &rays[k], &h, &want[k]);
        }
    }
    print_message("%s rays: %d of %d hit, %d through instances\n", tiles ? "coherent" : "incoherent", hits, n,
                  through);
    free(want);
    free(got);
    free(hit);
    free(f);
    free(hp);
    free(blocked);
}

/* Packets, frustum tiles and streams walk the top level together and enter
 * instances as sub-packets and sub-streams: every answer is the single
 * walk's (same t bits, instance, triangle, barycentrics) and brute
 * force's t, on coherent tiles and incoherent rays, on the glTF field
 * (instances only) and a scene-format scene mixing instances of three
 * objects with world triangles and spheres, both traversals. */
static void test_instanced_packets_streams(void **state)
{
    (void)state;
    field f = field_of(100);
    write_field("field100.glb", &f);
    rt_scene scenes[2];
    rt_gltf_stats st;
    rt_error err;
    assert_int_equal(load("field100.glb", false, &scenes[0], &st, &err, NULL, 0), RT_OK);
    assert_int_equal(scenes[0].instance_count, 100);
    mixed_scene(&scenes[1]);
    rt_ray *coh = malloc(PS_N * sizeof *coh), *inc = malloc(PS_N * sizeof *inc);
    assert_true(coh && inc);
    for (int sc = 0; sc < 2; sc++) {
        packet_rays(rt_scene_bounds(&scenes[sc]), coh, inc);
        for (int portable = 0; portable < 2; portable++) {
            rt_kdtree_params par = {0};
            par.portable = portable;
            rt_kdtree t;
            assert_int_equal(rt_kdtree_build(&t, &scenes[sc], &par, &err), RT_OK);
            assert_true(t.instance_count > 0);
            check_packets_streams(&scenes[sc], &t, coh, PS_N, true, !portable);
            check_packets_streams(&scenes[sc], &t, inc, PS_N, false, !portable);
            rt_kdtree_free(&t);
        }
        rt_scene_free(&scenes[sc]);
    }
    free(coh);
    free(inc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_instanced_hits),  cmocka_unit_test(test_shared_mesh_nodes),
        cmocka_unit_test(test_instanced_image), cmocka_unit_test(test_ten_thousand),
        cmocka_unit_test(test_malformed),       cmocka_unit_test(test_rollback),
        cmocka_unit_test(test_scene_objects),   cmocka_unit_test(test_parallel_object_builds),
        cmocka_unit_test(test_instanced_packets_streams),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
