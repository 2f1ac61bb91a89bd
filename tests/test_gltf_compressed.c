/* test_gltf_compressed.c - compressed glTF (docs/gltf.md): EXT_meshopt_compression,
 * KHR_draco_mesh_compression and EXT_texture_webp.
 *
 * The files under tests/corpus/glb/compressed-*.glb were made from shared
 * sample models by the standard tools (tools/gen_compressed_assets.sh:
 * gltfpack, gltf-transform). Each must decode to its original's triangle
 * count and bounds, within the quantization step where the tool quantized,
 * and its textures to the original's size and nearly its pixels; every
 * vertex keeps its normal and UV (within the quantization). Originals come
 * from the shared assets (that test skips, saying so, without them; the
 * compressed files alone are still checked against the counts below).
 * The decoders are also checked on their own: a meshopt round trip through
 * the library's encoder, and broken streams refused with a clear error. */
#include "test_util.h"

#include <math.h>

#include <meshoptimizer.h>

#include "rt/io/draco.h"
#include "rt/io/gltf.h"
#include "rt/io/meshopt.h"
#include "rt/io/webp.h"
#include "rt/scene/scene.h"

static const char *corpus(const char *name)
{
    static char buf[256];
    snprintf(buf, sizeof buf, "tests/corpus/glb/%s", name);
    return buf;
}

static rt_result load(const char *path, rt_scene *s, rt_gltf_stats *st, rt_error *err)
{
    rt_scene_init(s);
    memset(err, 0, sizeof *err);
    memset(st, 0, sizeof *st);
    return rt_gltf_load(s, path, NULL, st, err);
}

typedef struct case_ {
    const char *file;     /* in tests/corpus/glb */
    const char *original; /* under the shared assets */
    size_t triangles;
    double tolerance;     /* on bounds, in units of the original's extent (quantization step) */
} case_;

static const case_ cases[] = {
    {"compressed-duck-gltfpack-cc.glb", "assets/gltf/Duck/glTF-Binary/Duck.glb", 4212, 2e-4},
    {"compressed-duck-draco.glb", "assets/gltf/Duck/glTF-Binary/Duck.glb", 4212, 2e-3},
    {"compressed-boxtextured-gltfpack-c-noq.glb", "assets/gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12, 0},
    {"compressed-boxtextured-draco.glb", "assets/gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12, 2e-3},
    {"compressed-boxtextured-meshopt.glb", "assets/gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12, 2e-4},
    {"compressed-boxtextured-webp.glb", "assets/gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12, 0},
    {"compressed-boxvertexcolors-draco.glb", "assets/gltf/BoxVertexColors/glTF-Binary/BoxVertexColors.glb", 12, 2e-3},
};

static double extent(const rt_box *b)
{
    double dx = b->hi.x - b->lo.x, dy = b->hi.y - b->lo.y, dz = b->hi.z - b->lo.z;
    return fmax(dx, fmax(dy, dz));
}

/* Mean absolute difference of two RGBA8 images of one size, in [0, 255]. */
static double image_diff(const rt_image *a, const rt_image *b)
{
    double sum = 0;
    size_t n = (size_t)a->width * (size_t)a->height * 4;
    for (size_t i = 0; i < n; i++)
        sum += fabs((double)a->rgba8[i] - (double)b->rgba8[i]);
    return sum / (double)n;
}

/* The UV of each vertex as its material's base colour texture sees it
 * (through the KHR_texture_transform that quantizing tools add), in a new
 * array of 2 floats a vertex. */
static float *texture_uvs(const rt_scene *s)
{
    float *uv = calloc(2 * s->vertices.count + 1, sizeof *uv);
    assert_non_null(uv);
    for (size_t t = 0; t < s->triangles.count; t++) {
        const float *m = s->materials[s->triangles.material[t]].base_color_tex.uv_transform;
        for (int k = 0; k < 3; k++) {
            uint32_t v = s->triangles.index[3 * t + (size_t)k];
            rt_vec2 u = s->vertices.uv0[v];
            uv[2 * v] = m[0] * u.x + m[1] * u.y + m[2];
            uv[2 * v + 1] = m[3] * u.x + m[4] * u.y + m[5];
        }
    }
    return uv;
}

/* Every vertex of a has one in b at the same place (within pos_tol) with
 * the same normal (cosine >= 0.99: 8-bit normals are within 0.01) and, when
 * `uv`, the same texture UV (within 0.005: 10 bits or more): the attributes
 * survived. The closest vertex by all three counts (a cube's corner holds
 * three vertices, one a face). */
static void assert_vertices_in(const rt_scene *a, const rt_scene *b, double pos_tol, bool uv, const char *what)
{
    assert_non_null(a->vertices.normal);
    assert_non_null(b->vertices.normal);
    float *ua = texture_uvs(a), *ub = texture_uvs(b);
    for (size_t i = 0; i < a->vertices.count; i++) {
        rt_vec3 p = a->vertices.position[i], n = a->vertices.normal[i];
        double best = INFINITY, dp = 0, cosn = 0, duv = 0;
        for (size_t j = 0; j < b->vertices.count; j++) {
            rt_vec3 q = b->vertices.position[j], m = b->vertices.normal[j];
            double d = rt_length(rt_sub(p, q)), c = rt_dot(n, m), u = 0;
            if (uv)
                u = fabs(ua[2 * i] - ub[2 * j]) + fabs(ua[2 * i + 1] - ub[2 * j + 1]);
            double score = d / (pos_tol + 1e-9) + 100.0 * (1.0 - c) + u / 0.005;
            if (score < best)
                best = score, dp = d, cosn = c, duv = u;
        }
        if (dp > pos_tol + 1e-6 || cosn < 0.99 || duv > 0.005)
            fail_msg("%s: vertex %zu (%g %g %g): the nearest has position off by %g (tolerance %g), normal cosine %g, "
                     "UV off by %g",
                     what, i, p.x, p.y, p.z, dp, pos_tol, cosn, duv);
    }
    free(ua);
    free(ub);
}

/* The compressed files alone decode to their originals' triangle counts. */
static void test_decodes_counts(void **state)
{
    (void)state;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        rt_scene s;
        rt_gltf_stats st;
        rt_error err;
        rt_result r = load(corpus(cases[c].file), &s, &st, &err);
        if (r != RT_OK)
            fprintf(stderr, "%s: %s\n", cases[c].file, err.message);
        assert_int_equal(r, RT_OK);
        assert_int_equal(st.triangles, cases[c].triangles);
        rt_scene_free(&s);
    }
}

static void test_decodes_like_original(void **state)
{
    (void)state;
    test_require_shared();
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        rt_scene s, o;
        rt_gltf_stats st, ost;
        rt_error err;
        rt_result r = load(corpus(cases[c].file), &s, &st, &err);
        if (r != RT_OK)
            fprintf(stderr, "%s: %s\n", cases[c].file, err.message);
        assert_int_equal(r, RT_OK);
        assert_int_equal(st.triangles, cases[c].triangles);
        {
            assert_int_equal(load(test_shared_path(cases[c].original), &o, &ost, &err), RT_OK);
            assert_int_equal(st.triangles, ost.triangles);
            double tol = cases[c].tolerance * extent(&ost.bounds);
            const float *lo = &st.bounds.lo.x, *hi = &st.bounds.hi.x, *olo = &ost.bounds.lo.x,
                        *ohi = &ost.bounds.hi.x;
            for (int k = 0; k < 3; k++) {
                if (fabs(lo[k] - olo[k]) > tol || fabs(hi[k] - ohi[k]) > tol)
                    fprintf(stderr, "%s: axis %d bounds %g..%g, original %g..%g (tolerance %g)\n", cases[c].file, k,
                            lo[k], hi[k], olo[k], ohi[k], tol);
                assert_true(fabs(lo[k] - olo[k]) <= tol);
                assert_true(fabs(hi[k] - ohi[k]) <= tol);
            }
            assert_int_equal(s.image_count, o.image_count);
            for (size_t i = 0; i < s.image_count; i++) {
                assert_int_equal(s.images[i].width, o.images[i].width);
                assert_int_equal(s.images[i].height, o.images[i].height);
                /* lossless codecs keep the pixels; WebP is lossy but close */
                assert_true(image_diff(&s.images[i], &o.images[i]) < 4.0);
            }
            if (o.vertices.color) { /* vertex colours survive Draco (normalized integers read as [0, 1]) */
                assert_non_null(s.vertices.color);
                double ms = 0, mo = 0;
                for (size_t v = 0; v < s.vertices.count; v++)
                    ms += s.vertices.color[v].x + s.vertices.color[v].y + s.vertices.color[v].z;
                for (size_t v = 0; v < o.vertices.count; v++)
                    mo += o.vertices.color[v].x + o.vertices.color[v].y + o.vertices.color[v].z;
                assert_true(fabs(ms / (double)s.vertices.count - mo / (double)o.vertices.count) < 0.02);
            }
            /* normals and UVs, both ways */
            bool uv = (o.triangles.flags[0] & RT_TRI_UV) != 0;
            assert_int_equal((s.triangles.flags[0] & RT_TRI_UV) != 0, uv);
            double pos_tol = fmax(cases[c].tolerance, 1e-6) * extent(&ost.bounds);
            assert_vertices_in(&o, &s, pos_tol, uv, cases[c].file);
            assert_vertices_in(&s, &o, pos_tol, uv, cases[c].file);
            rt_scene_free(&o);
        }
        rt_scene_free(&s);
    }
}

/* Lossless meshopt (gltfpack -c -noq) gives the original's vertices exactly. */
static void test_meshopt_lossless_exact(void **state)
{
    (void)state;
    test_require_shared();
    rt_scene s, o;
    rt_gltf_stats st, ost;
    rt_error err;
    assert_int_equal(load(corpus("compressed-boxtextured-gltfpack-c-noq.glb"), &s, &st, &err), RT_OK);
    assert_int_equal(load(test_shared_path("assets/gltf/BoxTextured/glTF-Binary/BoxTextured.glb"), &o, &ost, &err),
                     RT_OK);
    assert_memory_equal(&st.bounds, &ost.bounds, sizeof st.bounds);
    /* the same set of positions (gltfpack may reorder vertices) */
    for (size_t i = 0; i < o.vertices.count; i++) {
        bool found = false;
        for (size_t j = 0; j < s.vertices.count && !found; j++)
            found = memcmp(&o.vertices.position[i], &s.vertices.position[j], sizeof(rt_vec3)) == 0;
        assert_true(found);
    }
    rt_scene_free(&s);
    rt_scene_free(&o);
}

/* The meshopt module alone: a round trip through the library's encoder, and
 * a truncated stream refused. */
static void test_meshopt_round_trip(void **state)
{
    (void)state;
    enum { N = 300, STRIDE = 16 };
    static uint8_t verts[N * STRIDE], back[N * STRIDE];
    uint64_t x = 0x9E3779B97F4A7C15ull;
    for (size_t i = 0; i < sizeof verts; i++) {
        x ^= x << 13; x ^= x >> 7; x ^= x << 17;
        verts[i] = (uint8_t)(i % 7 == 0 ? x : i / STRIDE); /* some structure, some noise */
    }
    size_t bound = meshopt_encodeVertexBufferBound(N, STRIDE);
    uint8_t *enc = malloc(bound);
    size_t n = meshopt_encodeVertexBuffer(enc, bound, verts, N, STRIDE);
    assert_true(n > 0);
    assert_null(rt_meshopt_decode(back, N, STRIDE, enc, n, RT_MESHOPT_ATTRIBUTES, RT_MESHOPT_FILTER_NONE));
    assert_memory_equal(back, verts, sizeof verts);
    assert_non_null(rt_meshopt_decode(back, N, STRIDE, enc, n / 2, RT_MESHOPT_ATTRIBUTES, RT_MESHOPT_FILTER_NONE));
    /* shapes the extension forbids are refused before the library sees them */
    assert_non_null(rt_meshopt_check(RT_MESHOPT_ATTRIBUTES, RT_MESHOPT_FILTER_NONE, N, 6));
    assert_non_null(rt_meshopt_check(RT_MESHOPT_TRIANGLES, RT_MESHOPT_FILTER_NONE, 4, 4));
    assert_non_null(rt_meshopt_check(RT_MESHOPT_INDICES, RT_MESHOPT_FILTER_NONE, 4, 3));
    assert_non_null(rt_meshopt_check(RT_MESHOPT_ATTRIBUTES, RT_MESHOPT_FILTER_QUATERNION, 4, 16));
    assert_non_null(rt_meshopt_check(RT_MESHOPT_TRIANGLES, RT_MESHOPT_FILTER_OCTAHEDRAL, 3, 4));
    assert_null(rt_meshopt_check(RT_MESHOPT_ATTRIBUTES, RT_MESHOPT_FILTER_OCTAHEDRAL, 4, 8));
    /* indices */
    static const unsigned tri[] = {0, 1, 2, 2, 1, 3, 3, 1, 4};
    unsigned tri_back[9];
    size_t ib = meshopt_encodeIndexBufferBound(9, 5);
    uint8_t *ienc = malloc(ib);
    size_t in = meshopt_encodeIndexBuffer(ienc, ib, tri, 9);
    assert_null(rt_meshopt_decode(tri_back, 9, 4, ienc, in, RT_MESHOPT_TRIANGLES, RT_MESHOPT_FILTER_NONE));
    /* the codec may rotate a triangle's corners; the triangles stay */
    for (int t = 0; t < 3; t++) {
        unsigned a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
        const unsigned *g = &tri_back[3 * t];
        assert_true((g[0] == a && g[1] == b && g[2] == c) || (g[0] == b && g[1] == c && g[2] == a) ||
                    (g[0] == c && g[1] == a && g[2] == b));
    }
    free(enc);
    free(ienc);
}

/* Reads a corpus file into memory. */
static uint8_t *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *buf = malloc((size_t)n);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *size = (size_t)n;
    return buf;
}

static uint8_t *find(uint8_t *hay, size_t n, const char *needle)
{
    size_t k = strlen(needle);
    for (size_t i = 0; i + k <= n; i++)
        if (memcmp(hay + i, needle, k) == 0)
            return hay + i;
    return NULL;
}

/* Loads bytes as `name`; expects failure with a message naming it and `what`. */
static void expect_fail_memory(const uint8_t *data, size_t size, const char *name, rt_result code, const char *what)
{
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    rt_result r = rt_gltf_load_memory(&s, data, size, name, NULL, NULL, &err);
    test_expect_failure(r, &err, code, name, what);
    assert_int_equal(s.triangles.count, 0);
    rt_scene_free(&s);
}

static void test_broken_streams(void **state)
{
    (void)state;
    size_t n;
    /* Draco: the stream's magic broken */
    uint8_t *g = slurp(corpus("compressed-boxtextured-draco.glb"), &n);
    uint8_t *magic = find(g, n, "DRACO");
    assert_non_null(magic);
    magic[0] = 'X';
    expect_fail_memory(g, n, "bad-draco.glb", RT_ERR_INVALID, "KHR_draco_mesh_compression");
    /* Draco: garbage after the header: an error or a mesh with the wrong counts, never a crash */
    magic[0] = 'D';
    for (uint8_t *p = magic + 16; p < g + n && p < magic + 200; p++)
        *p ^= 0x5A;
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    rt_result r = rt_gltf_load_memory(&s, g, n, "noisy-draco.glb", NULL, NULL, &err);
    if (r != RT_OK)
        assert_non_null(strstr(err.message, "noisy-draco.glb"));
    rt_scene_free(&s);
    free(g);

    /* meshopt: a mode the extension does not have */
    g = slurp(corpus("compressed-boxtextured-meshopt.glb"), &n);
    uint8_t *mode = find(g, n, "\"ATTRIBUTES\"");
    assert_non_null(mode);
    memcpy(mode, "\"ATTRIBUTEZ\"", 12);
    expect_fail_memory(g, n, "bad-mode.glb", RT_ERR_INVALID, "is not ATTRIBUTES, TRIANGLES or INDICES");
    memcpy(mode, "\"ATTRIBUTES\"", 12);
    /* meshopt: the compressed bytes broken (every byte of the BIN chunk) */
    uint8_t *bin = find(g, n, "BIN");
    assert_non_null(bin);
    memset(bin + 4, 0xFF, n - (size_t)(bin + 4 - g));
    expect_fail_memory(g, n, "bad-stream.glb", RT_ERR_INVALID, "EXT_meshopt_compression: the compressed stream");
    free(g);
}

/* KHR_texture_basisu without a decoder: used with a fallback source, the
 * fallback is read and the texture stays; required, a clear error. */
static void test_basisu_fallback(void **state)
{
    (void)state;
    char dir[64];
    assert_true(test_make_dir(dir, sizeof dir, "basisu"));
    /* a 1x1 PNG fallback image as a data URI, one triangle */
    static const char png1x1[] = "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJRU5ErkJggg==";
    /* positions: (0,0,0) (1,0,0) (0,1,0) as little-endian floats, base64 */
    static const char pos[] = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
    char json[2048], path[128];
    for (int required = 0; required < 2; required++) {
        snprintf(json, sizeof json,
                 "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_texture_basisu\"]%s,"
                 "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"images\":[{\"uri\":\"data:image/png;base64,%s\"},{\"uri\":\"tex.ktx2\"}],"
                 "\"textures\":[{\"source\":0,\"extensions\":{\"KHR_texture_basisu\":{\"source\":1}}}],"
                 "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
                 "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
                 required ? ",\"extensionsRequired\":[\"KHR_texture_basisu\"]" : "", pos, png1x1);
        snprintf(path, sizeof path, "%s/basisu%d.gltf", dir, required);
        test_write_file(path, json, strlen(json));
        rt_scene s;
        rt_gltf_stats st;
        rt_error err;
        rt_result r = load(path, &s, &st, &err);
        if (required) {
            assert_int_equal(r, RT_ERR_UNSUPPORTED);
            assert_non_null(strstr(err.message, "KHR_texture_basisu"));
            assert_non_null(strstr(err.message, "basisu1.gltf"));
        } else {
            if (r != RT_OK)
                fprintf(stderr, "%s\n", err.message);
            assert_int_equal(r, RT_OK);
            assert_int_equal(st.triangles, 1);
            assert_int_equal(s.image_count, 1); /* the PNG fallback */
        }
        rt_scene_free(&s);
    }
    test_remove_dir(dir);
}

/* WebP images on their own: the size check comes before decoding. */
static void test_webp_limits(void **state)
{
    (void)state;
    size_t n;
    uint8_t *g = slurp(corpus("compressed-boxtextured-webp.glb"), &n);
    uint8_t *riff = find(g, n, "RIFF");
    assert_non_null(riff);
    size_t left = n - (size_t)(riff - g);
    assert_true(rt_webp_is(riff, left));
    uint8_t *px;
    int w, h;
    rt_error err;
    assert_int_equal(rt_webp_decode(riff, left, "t.webp", 64, 1u << 20, &px, &w, &h, &err), RT_ERR_LIMIT);
    assert_non_null(strstr(err.message, "t.webp"));
    assert_int_equal(rt_webp_decode(riff, left, "t.webp", 4096, 1u << 20, &px, &w, &h, &err), RT_OK);
    assert_int_equal(w, 256);
    assert_int_equal(h, 256);
    free(px);
    assert_int_equal(rt_webp_decode(riff, 20, "short.webp", 4096, 1u << 20, &px, &w, &h, &err), RT_ERR_INVALID);
    free(g);
}

/* Issue 25, class 7: a Draco stream (sequential encoding, 3 points, one
 * face) whose GENERIC attribute (unique id 1) is DT_BOOL with the bytes 0,
 * 1 and 7. Converting it through draco's ConvertValue loaded 7 as a C++
 * bool (UBSan: invalid bool load); booleans are read as bytes, any nonzero
 * byte is 1. */
static void test_draco_bool_attribute_as_bytes(void **state)
{
    (void)state;
    static const unsigned char stream[] = {
        0x44, 0x52, 0x41, 0x43, 0x4f, 0x02, 0x02, 0x01, 0x00, 0x00, 0x00, 0x01, 0x03, 0x01, 0x00, 0x01,
        0x02, 0x01, 0x02, 0x00, 0x09, 0x03, 0x00, 0x00, 0x04, 0x0b, 0x01, 0x00, 0x01, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x01, 0x07};
    char why[200];
    rt_draco_mesh *m = rt_draco_decode(stream, sizeof stream, why, sizeof why);
    if (!m)
        fail_msg("decode: %s", why);
    assert_int_equal(rt_draco_points(m), 3);
    assert_int_equal(rt_draco_components(m, 1), 1);
    float v[3] = {-1, -1, -1};
    assert_true(rt_draco_attribute(m, 1, 1, v));
    assert_float_equal(v[0], 0.0f, 0);
    assert_float_equal(v[1], 1.0f, 0);
    assert_float_equal(v[2], 1.0f, 0);
    float v4[12];
    assert_true(rt_draco_attribute(m, 1, 4, v4)); /* padded as glTF reads a narrower attribute */
    assert_float_equal(v4[8], 1.0f, 0);
    rt_draco_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_decodes_counts),
        cmocka_unit_test(test_decodes_counts),
        cmocka_unit_test(test_decodes_like_original), cmocka_unit_test(test_meshopt_lossless_exact),
        cmocka_unit_test(test_meshopt_round_trip),    cmocka_unit_test(test_broken_streams),
        cmocka_unit_test(test_draco_bool_attribute_as_bytes),
        cmocka_unit_test(test_basisu_fallback),       cmocka_unit_test(test_webp_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
