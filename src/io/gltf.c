/* gltf.c - glTF 2.0 (.gltf, .glb) loader for static scenes.
 *
 * Built the way cgltf (jkuhlmann/cgltf) is built, in four passes:
 *   1. read   the file; a GLB is split into its JSON and BIN chunks after
 *             checking the 12-byte header and every chunk length against the
 *             file size (glTF 2.0 spec, "GLB File Format Specification").
 *   2. map    the JSON (tokenized once by jsmn, see json.c) into flat tables
 *             of records with a count each: buffers, bufferViews, accessors,
 *             meshes/primitives, nodes, scenes, materials, textures,
 *             samplers, images, cameras, KHR_lights_punctual lights. Cross
 *             references stay indices.
 *   3. check  every index against its table, every accessor against its
 *             bufferView and every bufferView against its buffer (with
 *             overflow-safe arithmetic), the node graph for shared children,
 *             cycles and depth; only then are buffers read (files relative to
 *             the .gltf, base64 data: URIs, the GLB BIN chunk) and their real
 *             sizes checked against byteLength. Nothing is allocated from a
 *             count that has not been checked against the bytes behind it
 *             (or, for accessors without a bufferView, against a fixed cap).
 *   4. flatten the chosen scene: node world matrices (parent * local, TRS =
 *             T * R * S), every triangle primitive of every mesh instance
 *             into the scene's vertex and triangle tables (strips and fans
 *             converted with the spec's vertex orders), materials, textures
 *             (images decoded once through texture.c), cameras and lights.
 *
 * Transforms: positions by the world matrix M; normals by the inverse
 * transpose (rt_mat4_normal_matrix); tangents by M's upper 3x3, with the
 * bitangent sign w multiplied by sign(det M): with n' ~ M^-T n and
 * t' ~ M t, cross(n', t') points along sign(det M) * M cross(n, t), so a
 * mirroring transform must flip w to keep bitangent = w * cross(n, t).
 * A negative determinant also flips triangle winding (spec, "Meshes"), so
 * the geometric normal keeps agreeing with the shading normal.
 *
 * Sources: Khronos glTF 2.0 specification (sections "Accessors" with
 * sparse accessors and data alignment, "Animations" for the normalized
 * integer formulas, "Meshes" for primitive modes and winding, "Materials",
 * "Samplers", "GLB File Format Specification"); extension specs KHR_texture_transform,
 * KHR_materials_{emissive_strength,transmission,ior,volume,unlit},
 * KHR_lights_punctual, KHR_mesh_quantization. docs/gltf.md lists what is
 * supported and how glTF materials map to rt_material.
 */
#include "rt/io/gltf.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/io/base64.h"
#include "rt/io/draco.h"
#include "rt/io/gltf_animation.h"
#include "rt/io/image_load.h"
#include "rt/io/json.h"
#include "rt/io/meshopt.h"
#include "rt/scene/texture.h"

#define GL_MAX_DEPTH 1024                    /* node hierarchy levels */
#define GL_MAX_VERTICES ((size_t)1 << 25)    /* per load: 32M vertices */
#define GL_MAX_ZEROS ((size_t)1 << 22)       /* elements of accessors without a bufferView, per accessor and
                                                per load (instances included): such data costs no file bytes */
#define GL_MAX_TRIANGLES ((size_t)1 << 25)   /* per load: 32M triangles */
#define GL_MAX_FILE ((size_t)0x7fffffff)     /* .gltf, .glb, .bin: 2 GiB */
#define GL_MAX_DECODED ((size_t)1 << 30)     /* per load: bytes decoded from meshopt and Draco streams */

enum { GL_BYTE = 5120, GL_UNSIGNED_BYTE = 5121, GL_SHORT = 5122, GL_UNSIGNED_SHORT = 5123,
       GL_UNSIGNED_INT = 5125, GL_FLOAT = 5126 };

enum { ATTR_POSITION = 0, ATTR_NORMAL, ATTR_TANGENT, ATTR_TEXCOORD_0, ATTR_TEXCOORD_1, ATTR_COLOR_0, ATTR_COUNT };
static const char *const attr_names[ATTR_COUNT] = {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1",
                                                   "COLOR_0"};

/* ------------------------------------------------------------- records */

typedef struct gl_buffer {
    size_t byte_length;
    int uri;              /* string token, -1 = none (GLB BIN chunk) */
    const uint8_t *data;  /* after loading: at least byte_length bytes */
    uint8_t *owned;
    bool fallback;        /* EXT_meshopt_compression: may have no data, only decoded views use it */
    int tok;
} gl_buffer;

typedef struct gl_view {
    uint32_t buffer;
    size_t offset, length, stride; /* stride 0 = tightly packed */
    uint8_t *decoded;              /* EXT_meshopt_compression or Draco: the view's bytes, owned */
    bool meshopt;                  /* the fields below hold its compressed source */
    uint32_t mo_buffer;
    size_t mo_offset, mo_length, mo_stride, mo_count;
    int mo_mode, mo_filter, mo_tok;
    int tok;
} gl_view;

typedef struct gl_accessor {
    uint32_t view;       /* RT_NONE = all zeros */
    size_t offset, count;
    int ctype;
    int ncomp, rows, cols; /* VEC3: 3, 3, 1; MAT3: 9, 3, 3 */
    bool normalized;
    size_t sparse_count; /* 0 = not sparse */
    uint32_t sp_idx_view, sp_val_view;
    size_t sp_idx_offset, sp_val_offset;
    int sp_idx_ctype;
    bool draco;          /* filled by a KHR_draco_mesh_compression primitive */
    int tok;
} gl_accessor;

typedef struct gl_prim {
    int mode;
    uint32_t indices, material;
    uint32_t attr[ATTR_COUNT];
    bool targets;
    uint32_t first_target, target_count; /* morph targets, into doc.targets */
    uint32_t joints[2], weights[2];      /* JOINTS_0/1, WEIGHTS_0/1 accessors, RT_NONE = absent */
    uint32_t draco_view;          /* KHR_draco_mesh_compression: RT_NONE = not compressed */
    uint32_t draco_id[ATTR_COUNT]; /* its attribute unique ids, RT_NONE = not in the stream */
    int draco_tok;
    int tok;
    int variants_tok;       /* extensions.KHR_materials_variants.mappings, or -1 */
} gl_prim;

typedef struct gl_mesh { uint32_t first, count; int weights; int tok; } gl_mesh; /* weights: token, -1 = none */

/* A morph target: its POSITION, NORMAL and TANGENT displacement accessors. */
typedef struct gl_target { uint32_t attr[3]; } gl_target;

/* Animations: channels and samplers of every animation in two tables. */
typedef enum { PATH_TRANSLATION, PATH_ROTATION, PATH_SCALE, PATH_WEIGHTS } gl_path;
typedef struct gl_channel { uint32_t sampler, node; int path; int tok; } gl_channel; /* sampler: of its animation */
typedef struct gl_asampler { uint32_t input, output; int interp; int tok; } gl_asampler;
typedef struct gl_anim { uint32_t first_channel, channel_count, first_sampler, sampler_count; int tok; } gl_anim;
typedef struct gl_skin { uint32_t first_joint, joint_count, ibm; int tok; } gl_skin; /* joints in doc.skin_joints */

typedef struct gl_node {
    uint32_t mesh, camera, light, skin;
    uint32_t first_child, child_count; /* into doc.children */
    uint32_t parent;
    rt_mat4 local;
    bool has_matrix;                 /* else local = T * R * S of the fields below */
    float tr[3], rot[4], sc[3];
    int weights;                     /* token of its morph weights, -1 = none */
    float *pose_weights;             /* when posed: its morph weights (pose_weight_count), owned */
    uint32_t pose_weight_count;
    int tok;
} gl_node;

typedef struct gl_scene { uint32_t first, count; int tok; } gl_scene; /* into doc.scene_nodes */

typedef struct gl_texture { uint32_t source, sampler; bool other_source; int tok; } gl_texture;
typedef struct gl_sampler { int mag, min, wrap_s, wrap_t; int tok; } gl_sampler;
typedef struct gl_image { int uri; uint32_t view; int tok; } gl_image;

typedef struct gl_camera {
    bool perspective;
    float yfov, aspect, znear, zfar;
    int tok;
} gl_camera;

typedef struct gl_light {
    rt_light_kind kind;
    rt_vec3 color;
    float intensity, range, inner, outer;
    int tok;
} gl_light;

typedef struct gl_material { rt_material m; int tok; } gl_material; /* slot.texture = glTF texture index */

/* One visited node of the chosen scene with its world matrix. */
typedef struct gl_visit { uint32_t node; rt_mat4 world; } gl_visit;

typedef struct gl_doc {
    const char *path;
    char *dir;            /* directory of the .gltf with its trailing '/', or "" */
    rt_error *err;
    const uint8_t *bytes; /* the whole .gltf/.glb */
    size_t file_size;
    const char *json_text;
    size_t json_len, json_base;
    const uint8_t *bin;   /* GLB BIN chunk */
    size_t bin_size;
    bool glb;
    rt_json j;

    gl_buffer *buffers;     size_t buffer_count;
    gl_view *views;         size_t view_count;
    gl_accessor *accessors; size_t accessor_count;
    gl_mesh *meshes;        size_t mesh_count;
    gl_prim *prims;         size_t prim_count;
    gl_node *nodes;         size_t node_count;
    uint32_t *children;     size_t children_count;
    gl_scene *scenes;       size_t scene_count;
    uint32_t *scene_nodes;  size_t scene_nodes_count;
    gl_material *materials; size_t material_count;
    gl_texture *textures;   size_t texture_count;
    gl_sampler *samplers;   size_t sampler_count;
    gl_image *images;       size_t image_count;
    gl_camera *cameras;     size_t camera_count;
    gl_light *lights;       size_t light_count;
    gl_skin *skins;         size_t skin_count;
    uint32_t *skin_joints;  size_t skin_joints_count, skin_joints_cap;
    gl_target *targets;     size_t target_count, target_cap;
    gl_anim *anims;         size_t anim_count;
    gl_channel *channels;   size_t channel_count, channel_cap;
    gl_asampler *asamplers; size_t asampler_count, asampler_cap;
    bool posed;             /* rt_gltf_options.use_time: animation, skins and morphs applied */
    bool animated;          /* posed by an animation that has channels */
    rt_mat4 *skin_scratch;  size_t skin_scratch_cap; /* per-vertex skin matrices of one primitive */
    size_t decoded_bytes;   /* meshopt and Draco output so far (GL_MAX_DECODED) */
    uint32_t default_scene; /* RT_NONE = absent */
    int variants_tok;       /* extensions.KHR_materials_variants.variants (names), or -1 */

    /* flattening */
    gl_visit *visits;       size_t visit_count;
    uint32_t *visit_of;     /* node -> its visit (valid once visited) */
    uint32_t *image_map;    /* glTF image -> scene image, RT_NONE = not loaded yet */
    uint32_t *texture_map;  /* glTF texture -> scene texture */
    bool *texture_missing;  /* its image file does not exist: the missing-texture rule (rt/scene/texture.h) */
    float *scratch[ATTR_COUNT];
    size_t scratch_cap[ATTR_COUNT];
    uint32_t *idx_scratch;
    size_t idx_cap;
} gl_doc;

/* ------------------------------------------------------------- errors */

static rt_result fail_at(gl_doc *d, int tok, rt_result code, const char *fmt, ...) RT_PRINTF(4, 5);
static rt_result fail_at(gl_doc *d, int tok, rt_result code, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (tok >= 0 && tok < d->j.count)
        return rt_fail(d->err, code, "%s: byte %zu: %s", d->path, d->json_base + (size_t)d->j.tok[tok].start, msg);
    return rt_fail(d->err, code, "%s: %s", d->path, msg);
}

/* ------------------------------------------------------- JSON helpers */

static int jtype(const gl_doc *d, int t) { return t >= 0 && t < d->j.count ? d->j.tok[t].type : 0; }
static int jsize(const gl_doc *d, int t) { return t >= 0 && t < d->j.count ? d->j.tok[t].size : 0; }

/* Checks that t is an object whose keys are all strings followed by a value. */
static rt_result expect_object(gl_doc *d, int t, const char *where)
{
    if (jtype(d, t) != RT_JSON_OBJECT)
        return fail_at(d, t, RT_ERR_INVALID, "%s: expected an object", where);
    int k = t + 1;
    for (int n = 0; n < d->j.tok[t].size; n++) {
        if (k + 1 >= d->j.count || d->j.tok[k].type != RT_JSON_STRING || d->j.tok[k].size != 1)
            return fail_at(d, k < d->j.count ? k : t, RT_ERR_PARSE, "%s: expected \"key\": value", where);
        k = rt_json_skip(&d->j, k + 1);
    }
    return RT_OK;
}

static rt_result expect_array(gl_doc *d, int t, const char *where, const char *key)
{
    if (jtype(d, t) != RT_JSON_ARRAY)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an array", where, key);
    return RT_OK;
}

#define KEY(k, s) rt_json_key_is(&d->j, (k), (s))

static rt_result get_num(gl_doc *d, const char *where, const char *key, int t, double *v)
{
    if (!rt_json_number(&d->j, t, v))
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected a number", where, key);
    return RT_OK;
}

static rt_result get_index(gl_doc *d, const char *where, const char *key, int t, uint32_t *out)
{
    double v;
    if (!rt_json_number(&d->j, t, &v) || v < 0 || v != floor(v) || v > 4294967294.0)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an index (a non-negative integer)", where, key);
    *out = (uint32_t)v;
    return RT_OK;
}

static rt_result get_size(gl_doc *d, const char *where, const char *key, int t, size_t *out)
{
    double v;
    if (!rt_json_number(&d->j, t, &v) || v < 0 || v != floor(v) || v > 9007199254740992.0 || v > (double)SIZE_MAX)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected a non-negative integer", where, key);
    *out = (size_t)v;
    return RT_OK;
}

static rt_result get_int(gl_doc *d, const char *where, const char *key, int t, int *out)
{
    double v;
    if (!rt_json_number(&d->j, t, &v) || v != floor(v) || v < -2147483647.0 || v > 2147483647.0)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an integer", where, key);
    *out = (int)v;
    return RT_OK;
}

static rt_result get_float(gl_doc *d, const char *where, const char *key, int t, float *out)
{
    rt_result r;
    double v;
    if ((r = get_num(d, where, key, t, &v)) != RT_OK)
        return r;
    if (fabs(v) > FLT_MAX)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: number out of float range", where, key);
    *out = (float)v;
    return RT_OK;
}

static rt_result get_floats(gl_doc *d, const char *where, const char *key, int t, float *out, int n)
{
    rt_result r;
    if (jtype(d, t) != RT_JSON_ARRAY || jsize(d, t) != n)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an array of %d numbers", where, key, n);
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e))
        if ((r = get_float(d, where, key, e, &out[i])) != RT_OK)
            return r;
    return RT_OK;
}

static rt_result get_bool(gl_doc *d, const char *where, const char *key, int t, bool *out)
{
    if (!rt_json_bool(&d->j, t, out))
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected true or false", where, key);
    return RT_OK;
}

static rt_result get_string(gl_doc *d, const char *where, const char *key, int t, char *buf, size_t cap)
{
    if (rt_json_string(&d->j, t, buf, cap) < 0)
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected a string (at most %zu bytes, valid escapes)", where,
                       key, cap - 1);
    return RT_OK;
}

/* Allocates one zeroed record per element of array token t. */
static rt_result alloc_table(gl_doc *d, int t, const char *key, size_t elem, void **out, size_t *count)
{
    rt_result r;
    if ((r = expect_array(d, t, "glTF", key)) != RT_OK)
        return r;
    if (*out)
        return fail_at(d, t, RT_ERR_INVALID, "%s appears twice", key);
    size_t n = (size_t)jsize(d, t);
    void *p = rt_alloc(n, elem);
    if (!p)
        return fail_at(d, t, RT_ERR_NOMEM, "out of memory for %zu %s", n, key);
    *out = p;
    *count = n;
    return RT_OK;
}

/* --------------------------------------------------------- file I/O */

/* Reads a file the document names (an external buffer). */
static rt_result read_file(gl_doc *d, const char *path, const char *what, uint8_t **data, size_t *size)
{
    rt_error inner = {0};
    char *bytes;
    if (rt_read_file(path, GL_MAX_FILE, &bytes, size, &inner) != RT_OK)
        return rt_fail(d->err, inner.code, "%s: %s%s", d->path, what, inner.message);
    *data = (uint8_t *)bytes;
    return RT_OK;
}

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Splits a GLB into its JSON and BIN chunks (spec: "GLB File Format Specification"). */
static rt_result split_glb(gl_doc *d)
{
    const uint8_t *f = d->bytes;
    size_t size = d->file_size;
    if (size < 12)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: byte 0: file is %zu bytes, too short for the 12-byte GLB header",
                       d->path, size);
    uint32_t version = rd32(f + 4), length = rd32(f + 8);
    if (version != 2)
        return rt_fail(d->err, RT_ERR_UNSUPPORTED, "%s: byte 4: GLB version %u (only version 2 is supported)",
                       d->path, version);
    if (length > size)
        return rt_fail(d->err, RT_ERR_INVALID,
                       "%s: byte 8: header length %u runs past the end of the file (%zu bytes): truncated?", d->path,
                       length, size);
    if (length < 20)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: byte 8: header length %u leaves no room for the JSON chunk",
                       d->path, length);
    if (length < size)
        rt_warn("%s: %zu bytes after the GLB's declared length %u are ignored", d->path, size - length, length);
    size_t off = 12;
    int chunk = 0;
    while (off < length) {
        if (length - off < 8)
            return rt_fail(d->err, RT_ERR_INVALID,
                           "%s: byte %zu: chunk header runs past the end of the file (%u bytes)", d->path, off, length);
        uint32_t clen = rd32(f + off), ctype = rd32(f + off + 4);
        if (clen > length - off - 8)
            return rt_fail(d->err, RT_ERR_INVALID,
                           "%s: byte %zu: chunk length %u runs past the end of the file (%u bytes)", d->path, off, clen,
                           length);
        const uint8_t *data = f + off + 8;
        if (chunk == 0) {
            if (ctype != 0x4E4F534Au)
                return rt_fail(d->err, RT_ERR_INVALID,
                               "%s: byte %zu: the first chunk must be JSON (type 0x4E4F534A), got 0x%08X", d->path,
                               off + 4, ctype);
            d->json_text = (const char *)data;
            d->json_len = clen;
            d->json_base = off + 8;
        } else if (ctype == 0x004E4942u) {
            if (chunk != 1)
                return rt_fail(d->err, RT_ERR_INVALID, "%s: byte %zu: the BIN chunk must be the second chunk", d->path,
                               off + 4);
            d->bin = data;
            d->bin_size = clen;
        } else if (ctype == 0x4E4F534Au) {
            return rt_fail(d->err, RT_ERR_INVALID, "%s: byte %zu: a second JSON chunk", d->path, off + 4);
        } /* unknown chunk types are skipped, as the spec says */
        off += 8 + (size_t)clen;
        off = (off + 3) & ~(size_t)3; /* chunks are 4-byte aligned */
        chunk++;
    }
    return RT_OK;
}

/* ----------------------------------------------------------- parsing */

static const struct { const char *name; bool supported; } known_extensions[] = {
    {"KHR_materials_emissive_strength", true}, {"KHR_texture_transform", true},
    {"KHR_materials_transmission", true},      {"KHR_materials_ior", true},
    {"KHR_materials_volume", true},            {"KHR_materials_unlit", true},
    {"KHR_lights_punctual", true},             {"KHR_mesh_quantization", true},
    {"KHR_xmp", true},                         {"KHR_xmp_json_ld", true}, /* metadata only */
    {"KHR_materials_clearcoat", true},         {"KHR_materials_specular", true},
    {"KHR_materials_sheen", true},             {"KHR_materials_anisotropy", true},
    {"KHR_materials_iridescence", true},       {"KHR_materials_dispersion", true},
    {"KHR_materials_diffuse_transmission", true}, {"KHR_materials_variants", true},
    {"EXT_meshopt_compression", true},         {"KHR_draco_mesh_compression", true},
    {"EXT_texture_webp", true},
};

static bool extension_supported(const gl_doc *d, int t)
{
    for (size_t i = 0; i < sizeof known_extensions / sizeof known_extensions[0]; i++)
        if (rt_json_key_is(&d->j, t, known_extensions[i].name))
            return known_extensions[i].supported;
    return false;
}

static rt_result check_extensions(gl_doc *d)
{
    rt_result r;
    char name[128];
    int req = rt_json_get(&d->j, 0, "extensionsRequired");
    if (req >= 0) {
        if ((r = expect_array(d, req, "glTF", "extensionsRequired")) != RT_OK)
            return r;
        for (int i = 0, e = req + 1; i < d->j.tok[req].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
            if ((r = get_string(d, "glTF", "extensionsRequired", e, name, sizeof name)) != RT_OK)
                return r;
            if (!extension_supported(d, e))
                return fail_at(d, e, RT_ERR_UNSUPPORTED, "required extension %s is not supported", name);
        }
    }
    int used = rt_json_get(&d->j, 0, "extensionsUsed");
    if (used >= 0) {
        if ((r = expect_array(d, used, "glTF", "extensionsUsed")) != RT_OK)
            return r;
        for (int i = 0, e = used + 1; i < d->j.tok[used].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
            if ((r = get_string(d, "glTF", "extensionsUsed", e, name, sizeof name)) != RT_OK)
                return r;
            if (!extension_supported(d, e))
                rt_warn("%s: extension %s is not supported; ignored", d->path, name);
        }
    }
    return RT_OK;
}

static rt_result parse_asset(gl_doc *d, int t)
{
    rt_result r;
    if ((r = expect_object(d, t, "asset")) != RT_OK)
        return r;
    int v = rt_json_get(&d->j, t, "version");
    char buf[32];
    if (v < 0)
        return fail_at(d, t, RT_ERR_INVALID, "asset.version is missing");
    if ((r = get_string(d, "asset", "version", v, buf, sizeof buf)) != RT_OK)
        return r;
    int minv = rt_json_get(&d->j, t, "minVersion");
    char mbuf[32];
    if (minv >= 0) {
        if ((r = get_string(d, "asset", "minVersion", minv, mbuf, sizeof mbuf)) != RT_OK)
            return r;
        if (strcmp(mbuf, "2.0") != 0)
            return fail_at(d, minv, RT_ERR_UNSUPPORTED, "asset.minVersion %s is not supported (only 2.0)", mbuf);
    } else if (buf[0] != '2' || buf[1] != '.') {
        return fail_at(d, v, RT_ERR_UNSUPPORTED, "glTF version %s is not supported (only 2.x)", buf);
    }
    return RT_OK;
}

static rt_result parse_buffers(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "buffers", sizeof(gl_buffer), (void **)&d->buffers, &d->buffer_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "buffers[%d]", i);
        gl_buffer *b = &d->buffers[i];
        b->uri = -1;
        b->tok = e;
        b->byte_length = SIZE_MAX;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "uri")) {
                if (jtype(d, v) != RT_JSON_STRING)
                    return fail_at(d, v, RT_ERR_INVALID, "%s.uri: expected a string", where);
                b->uri = v;
            } else if (KEY(k, "byteLength")) {
                if ((r = get_size(d, where, "byteLength", v, &b->byte_length)) != RT_OK)
                    return r;
            } else if (KEY(k, "extensions")) {
                int mo = rt_json_get(&d->j, v, "EXT_meshopt_compression");
                int fb = mo >= 0 ? rt_json_get(&d->j, mo, "fallback") : -1;
                if (fb >= 0)
                    r = get_bool(d, where, "extensions.EXT_meshopt_compression.fallback", fb, &b->fallback);
                if (r != RT_OK)
                    return r;
            }
        }
        if (b->byte_length == SIZE_MAX || b->byte_length == 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: byteLength is missing or 0", where);
    }
    return RT_OK;
}

/* A view's EXT_meshopt_compression object: where its compressed bytes are
 * and how they decode (rt/io/meshopt.h). */
static rt_result parse_meshopt_view(gl_doc *d, const char *view, int t, gl_view *bv)
{
    rt_result r = RT_OK;
    char where[96];
    snprintf(where, sizeof where, "%s.extensions.EXT_meshopt_compression", view);
    if ((r = expect_object(d, t, where)) != RT_OK)
        return r;
    bv->meshopt = true;
    bv->mo_tok = t;
    bv->mo_buffer = RT_NONE;
    bv->mo_length = bv->mo_stride = bv->mo_count = SIZE_MAX;
    bv->mo_mode = -1;
    bv->mo_filter = RT_MESHOPT_FILTER_NONE;
    char name[32];
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "buffer")) r = get_index(d, where, "buffer", v, &bv->mo_buffer);
        else if (KEY(k, "byteOffset")) r = get_size(d, where, "byteOffset", v, &bv->mo_offset);
        else if (KEY(k, "byteLength")) r = get_size(d, where, "byteLength", v, &bv->mo_length);
        else if (KEY(k, "byteStride")) r = get_size(d, where, "byteStride", v, &bv->mo_stride);
        else if (KEY(k, "count")) r = get_size(d, where, "count", v, &bv->mo_count);
        else if (KEY(k, "mode")) {
            if ((r = get_string(d, where, "mode", v, name, sizeof name)) != RT_OK)
                return r;
            if ((bv->mo_mode = rt_meshopt_mode_from_name(name)) < 0)
                return fail_at(d, v, RT_ERR_INVALID, "%s.mode \"%s\" is not ATTRIBUTES, TRIANGLES or INDICES", where,
                               name);
        } else if (KEY(k, "filter")) {
            if ((r = get_string(d, where, "filter", v, name, sizeof name)) != RT_OK)
                return r;
            if ((bv->mo_filter = rt_meshopt_filter_from_name(name)) < 0)
                return fail_at(d, v, RT_ERR_INVALID,
                               "%s.filter \"%s\" is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL", where, name);
        }
        if (r != RT_OK)
            return r;
    }
    if (bv->mo_buffer == RT_NONE || bv->mo_length == SIZE_MAX || bv->mo_stride == SIZE_MAX ||
        bv->mo_count == SIZE_MAX || bv->mo_mode < 0)
        return fail_at(d, t, RT_ERR_INVALID, "%s: needs buffer, byteLength, byteStride, count and mode", where);
    const char *why = rt_meshopt_check((rt_meshopt_mode)bv->mo_mode, (rt_meshopt_filter)bv->mo_filter,
                                       bv->mo_count, bv->mo_stride);
    if (why)
        return fail_at(d, t, RT_ERR_INVALID, "%s: %s", where, why);
    return RT_OK;
}

static rt_result parse_views(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "bufferViews", sizeof(gl_view), (void **)&d->views, &d->view_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "bufferViews[%d]", i);
        gl_view *bv = &d->views[i];
        bv->buffer = RT_NONE;
        bv->length = SIZE_MAX;
        bv->tok = e;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "buffer")) r = get_index(d, where, "buffer", v, &bv->buffer);
            else if (KEY(k, "byteOffset")) r = get_size(d, where, "byteOffset", v, &bv->offset);
            else if (KEY(k, "byteLength")) r = get_size(d, where, "byteLength", v, &bv->length);
            else if (KEY(k, "byteStride")) {
                if ((r = get_size(d, where, "byteStride", v, &bv->stride)) != RT_OK)
                    return r;
                if (bv->stride < 4 || bv->stride > 252 || bv->stride % 4)
                    return fail_at(d, v, RT_ERR_INVALID, "%s.byteStride %zu must be a multiple of 4 in [4, 252]",
                                   where, bv->stride);
            } else if (KEY(k, "extensions")) {
                int mo = rt_json_get(&d->j, v, "EXT_meshopt_compression");
                if (mo >= 0)
                    r = parse_meshopt_view(d, where, mo, bv);
                if (r != RT_OK)
                    return r;
            }
            if (r != RT_OK)
                return r;
        }
        if (bv->buffer == RT_NONE)
            return fail_at(d, e, RT_ERR_INVALID, "%s: buffer is missing", where);
        if (bv->length == SIZE_MAX || bv->length == 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: byteLength is missing or 0", where);
    }
    return RT_OK;
}

static size_t comp_size(int ct)
{
    switch (ct) {
    case GL_BYTE: case GL_UNSIGNED_BYTE: return 1;
    case GL_SHORT: case GL_UNSIGNED_SHORT: return 2;
    case GL_UNSIGNED_INT: case GL_FLOAT: return 4;
    }
    return 0;
}

/* Element size with the spec's column padding for matrices ("Data Alignment"). */
static size_t elem_size(const gl_accessor *a)
{
    size_t cs = comp_size(a->ctype);
    if (a->cols > 1) {
        size_t col = ((size_t)a->rows * cs + 3) & ~(size_t)3;
        return col * (size_t)a->cols;
    }
    return (size_t)a->ncomp * cs;
}

static rt_result parse_sparse(gl_doc *d, const char *where, int t, gl_accessor *a)
{
    rt_result r = RT_OK;
    char w[80];
    snprintf(w, sizeof w, "%s.sparse", where);
    if ((r = expect_object(d, t, w)) != RT_OK)
        return r;
    bool have_count = false, have_idx = false, have_val = false;
    a->sp_idx_view = a->sp_val_view = RT_NONE;
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "count")) {
            if ((r = get_size(d, w, "count", v, &a->sparse_count)) != RT_OK)
                return r;
            have_count = true;
        } else if (KEY(k, "indices")) {
            char wi[96];
            snprintf(wi, sizeof wi, "%s.indices", w);
            if ((r = expect_object(d, v, wi)) != RT_OK)
                return r;
            have_idx = true;
            a->sp_idx_ctype = 0;
            for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                 k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                if (KEY(k2, "bufferView")) r = get_index(d, wi, "bufferView", v2, &a->sp_idx_view);
                else if (KEY(k2, "byteOffset")) r = get_size(d, wi, "byteOffset", v2, &a->sp_idx_offset);
                else if (KEY(k2, "componentType")) r = get_int(d, wi, "componentType", v2, &a->sp_idx_ctype);
                if (r != RT_OK)
                    return r;
            }
            if (a->sp_idx_ctype != GL_UNSIGNED_BYTE && a->sp_idx_ctype != GL_UNSIGNED_SHORT &&
                a->sp_idx_ctype != GL_UNSIGNED_INT)
                return fail_at(d, v, RT_ERR_INVALID, "%s: componentType must be 5121, 5123 or 5125", wi);
        } else if (KEY(k, "values")) {
            char wv[96];
            snprintf(wv, sizeof wv, "%s.values", w);
            if ((r = expect_object(d, v, wv)) != RT_OK)
                return r;
            have_val = true;
            for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                 k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                if (KEY(k2, "bufferView")) r = get_index(d, wv, "bufferView", v2, &a->sp_val_view);
                else if (KEY(k2, "byteOffset")) r = get_size(d, wv, "byteOffset", v2, &a->sp_val_offset);
                if (r != RT_OK)
                    return r;
            }
        }
    }
    if (!have_count || !have_idx || !have_val || a->sp_idx_view == RT_NONE || a->sp_val_view == RT_NONE)
        return fail_at(d, t, RT_ERR_INVALID, "%s: needs count, indices.bufferView and values.bufferView", w);
    if (a->sparse_count == 0 || a->sparse_count > a->count)
        return fail_at(d, t, RT_ERR_INVALID, "%s.count %zu must be in [1, accessor count %zu]", w, a->sparse_count,
                       a->count);
    return RT_OK;
}

static rt_result parse_accessors(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "accessors", sizeof(gl_accessor), (void **)&d->accessors, &d->accessor_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "accessors[%d]", i);
        gl_accessor *a = &d->accessors[i];
        a->view = RT_NONE;
        a->count = SIZE_MAX;
        a->tok = e;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        int sparse = -1;
        char type[16] = "";
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "bufferView")) r = get_index(d, where, "bufferView", v, &a->view);
            else if (KEY(k, "byteOffset")) r = get_size(d, where, "byteOffset", v, &a->offset);
            else if (KEY(k, "componentType")) r = get_int(d, where, "componentType", v, &a->ctype);
            else if (KEY(k, "normalized")) r = get_bool(d, where, "normalized", v, &a->normalized);
            else if (KEY(k, "count")) r = get_size(d, where, "count", v, &a->count);
            else if (KEY(k, "type")) r = get_string(d, where, "type", v, type, sizeof type);
            else if (KEY(k, "sparse")) sparse = v;
            if (r != RT_OK)
                return r;
        }
        if (comp_size(a->ctype) == 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: componentType %d is not one of 5120 5121 5122 5123 5125 5126",
                           where, a->ctype);
        static const struct { const char *n; int comp, rows, cols; } types[] = {
            {"SCALAR", 1, 1, 1}, {"VEC2", 2, 2, 1}, {"VEC3", 3, 3, 1}, {"VEC4", 4, 4, 1},
            {"MAT2", 4, 2, 2},   {"MAT3", 9, 3, 3}, {"MAT4", 16, 4, 4}};
        for (size_t k = 0; k < sizeof types / sizeof types[0]; k++)
            if (strcmp(type, types[k].n) == 0) {
                a->ncomp = types[k].comp;
                a->rows = types[k].rows;
                a->cols = types[k].cols;
            }
        if (a->ncomp == 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: type \"%s\" is not SCALAR, VECn or MATn", where, type);
        if (a->count == SIZE_MAX || a->count == 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: count is missing or 0", where);
        if (a->normalized && (a->ctype == GL_FLOAT || a->ctype == GL_UNSIGNED_INT))
            return fail_at(d, e, RT_ERR_INVALID, "%s: normalized is not allowed for componentType %d", where, a->ctype);
        if (sparse >= 0)
            r = parse_sparse(d, where, sparse, a);
        if (r != RT_OK)
            return r;
    }
    return RT_OK;
}

/* A primitive's KHR_draco_mesh_compression object: the view holding the
 * compressed mesh and the unique ids of the attributes rt reads. */
static rt_result parse_draco_prim(gl_doc *d, const char *prim, int t, gl_prim *pr)
{
    rt_result r = RT_OK;
    char where[128];
    snprintf(where, sizeof where, "%s.extensions.KHR_draco_mesh_compression", prim);
    if ((r = expect_object(d, t, where)) != RT_OK)
        return r;
    pr->draco_tok = t;
    int attrs = -1;
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "bufferView")) r = get_index(d, where, "bufferView", v, &pr->draco_view);
        else if (KEY(k, "attributes")) attrs = v;
        if (r != RT_OK)
            return r;
    }
    if (pr->draco_view == RT_NONE || attrs < 0)
        return fail_at(d, t, RT_ERR_INVALID, "%s: needs bufferView and attributes", where);
    char wa[160];
    snprintf(wa, sizeof wa, "%s.attributes", where);
    if ((r = expect_object(d, attrs, wa)) != RT_OK)
        return r;
    for (int k2_n = 0, k2 = attrs + 1, v2 = attrs + 2; k2_n < d->j.tok[attrs].size && v2 < d->j.count;
         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
        for (int a = 0; a < ATTR_COUNT; a++)
            if (KEY(k2, attr_names[a]))
                r = get_index(d, wa, attr_names[a], v2, &pr->draco_id[a]);
        if (r != RT_OK)
            return r;
    }
    if (pr->draco_id[ATTR_POSITION] == RT_NONE)
        return fail_at(d, attrs, RT_ERR_INVALID, "%s: POSITION is missing", wa);
    return RT_OK;
}

/* A primitive's morph targets: POSITION, NORMAL, TANGENT displacements. */
static rt_result parse_targets(gl_doc *d, const char *prim, int t, gl_prim *pr)
{
    rt_result r = RT_OK;
    if ((r = expect_array(d, t, prim, "targets")) != RT_OK)
        return r;
    pr->first_target = (uint32_t)d->target_count;
    pr->target_count = (uint32_t)jsize(d, t);
    pr->targets = pr->target_count > 0;
    static const char *const names[3] = {"POSITION", "NORMAL", "TANGENT"};
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[96];
        snprintf(where, sizeof where, "%s.targets[%d]", prim, i);
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        if (!rt_grow((void **)&d->targets, &d->target_cap, d->target_count + 1, sizeof(gl_target)))
            return fail_at(d, e, RT_ERR_NOMEM, "out of memory for morph targets");
        gl_target *g = &d->targets[d->target_count++];
        g->attr[0] = g->attr[1] = g->attr[2] = RT_NONE;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            for (int a = 0; a < 3; a++)
                if (KEY(k, names[a]))
                    r = get_index(d, where, names[a], v, &g->attr[a]);
            if (r != RT_OK)
                return r;
        }
    }
    return RT_OK;
}

static rt_result parse_meshes(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "meshes", sizeof(gl_mesh), (void **)&d->meshes, &d->mesh_count)) != RT_OK)
        return r;
    /* count primitives first so they live in one table */
    size_t total = 0;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "meshes[%d]", i);
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        int p = rt_json_get(&d->j, e, "primitives");
        if (p < 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: primitives is missing", where);
        if ((r = expect_array(d, p, where, "primitives")) != RT_OK)
            return r;
        if (jsize(d, p) == 0)
            return fail_at(d, p, RT_ERR_INVALID, "%s.primitives is empty", where);
        total += (size_t)jsize(d, p);
    }
    d->prims = rt_alloc(total, sizeof(gl_prim));
    if (!d->prims)
        return fail_at(d, t, RT_ERR_NOMEM, "out of memory for %zu primitives", total);
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        gl_mesh *m = &d->meshes[i];
        m->tok = e;
        m->weights = rt_json_get(&d->j, e, "weights");
        int p = rt_json_get(&d->j, e, "primitives");
        m->first = (uint32_t)d->prim_count;
        m->count = (uint32_t)jsize(d, p);
        for (int pi = 0, pe = p + 1; pi < d->j.tok[p].size && pe < d->j.count; pi++, pe = rt_json_skip(&d->j, pe)) {
            char where[64];
            snprintf(where, sizeof where, "meshes[%d].primitives[%d]", i, pi);
            gl_prim *pr = &d->prims[d->prim_count++];
            pr->tok = pe;
            pr->mode = 4;
            pr->indices = pr->material = pr->draco_view = RT_NONE;
            pr->variants_tok = -1;
            for (int a = 0; a < ATTR_COUNT; a++)
                pr->attr[a] = pr->draco_id[a] = RT_NONE;
            pr->joints[0] = pr->joints[1] = pr->weights[0] = pr->weights[1] = RT_NONE;
            if ((r = expect_object(d, pe, where)) != RT_OK)
                return r;
            bool have_attrs = false;
            for (int k_n = 0, k = pe + 1, v = pe + 2; k_n < d->j.tok[pe].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "indices")) r = get_index(d, where, "indices", v, &pr->indices);
                else if (KEY(k, "material")) r = get_index(d, where, "material", v, &pr->material);
                else if (KEY(k, "mode")) {
                    if ((r = get_int(d, where, "mode", v, &pr->mode)) != RT_OK)
                        return r;
                    if (pr->mode < 0 || pr->mode > 6)
                        return fail_at(d, v, RT_ERR_INVALID, "%s.mode %d is not in [0, 6]", where, pr->mode);
                } else if (KEY(k, "targets")) {
                    if ((r = parse_targets(d, where, v, pr)) != RT_OK)
                        return r;
                } else if (KEY(k, "extensions")) {
                    int dr = rt_json_get(&d->j, v, "KHR_draco_mesh_compression");
                    if (dr >= 0)
                        r = parse_draco_prim(d, where, dr, pr);
                    if (r != RT_OK)
                        return r;
                    /* KHR_materials_variants: the mappings are checked in apply_variant */
                    int x = rt_json_get(&d->j, v, "KHR_materials_variants");
                    if (jtype(d, v) == RT_JSON_OBJECT && x >= 0) {
                        char wx[128];
                        snprintf(wx, sizeof wx, "%s.extensions.KHR_materials_variants", where);
                        if ((r = expect_object(d, x, wx)) != RT_OK)
                            return r;
                        int mp = rt_json_get(&d->j, x, "mappings");
                        if (mp < 0)
                            return fail_at(d, x, RT_ERR_INVALID, "%s: mappings is missing", wx);
                        if ((r = expect_array(d, mp, wx, "mappings")) != RT_OK)
                            return r;
                        pr->variants_tok = mp;
                    }
                } else if (KEY(k, "attributes")) {
                    char wa[96];
                    snprintf(wa, sizeof wa, "%s.attributes", where);
                    if ((r = expect_object(d, v, wa)) != RT_OK)
                        return r;
                    have_attrs = true;
                    for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                        for (int a = 0; a < ATTR_COUNT; a++)
                            if (KEY(k2, attr_names[a]))
                                r = get_index(d, wa, attr_names[a], v2, &pr->attr[a]);
                        if (r != RT_OK)
                            return r;
                        static const char *const skin_attrs[4] = {"JOINTS_0", "JOINTS_1", "WEIGHTS_0", "WEIGHTS_1"};
                        for (int a = 0; a < 4; a++)
                            if (KEY(k2, skin_attrs[a]))
                                r = get_index(d, wa, skin_attrs[a], v2,
                                              a < 2 ? &pr->joints[a] : &pr->weights[a - 2]);
                        if (r != RT_OK)
                            return r;
                    }
                }
                if (r != RT_OK)
                    return r;
            }
            if (!have_attrs)
                return fail_at(d, pe, RT_ERR_INVALID, "%s: attributes is missing", where);
        }
    }
    return RT_OK;
}

/* glTF matrices are column-major; rt_mat4 is m[row][col]. */
static rt_mat4 mat_from_gltf(const float *c)
{
    rt_mat4 r;
    for (int row = 0; row < 4; row++)
        for (int col = 0; col < 4; col++)
            r.m[row][col] = c[col * 4 + row];
    return r;
}

/* Items of a table that each hold an optional array of indices under
 * `member` ("children" of nodes, "nodes" of scenes) share one flat array.
 * The first pass checks the items and arrays and allocates room for all
 * their indices; read_index_list then fills it item by item. */
static rt_result alloc_index_lists(gl_doc *d, int t, const char *table, const char *member, uint32_t **out)
{
    rt_result r;
    size_t total = 0;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "%s[%d]", table, i);
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        int a = rt_json_get(&d->j, e, member);
        if (a >= 0) {
            if ((r = expect_array(d, a, where, member)) != RT_OK)
                return r;
            total += (size_t)jsize(d, a);
        }
    }
    *out = rt_alloc(total, sizeof(uint32_t));
    if (!*out)
        return fail_at(d, t, RT_ERR_NOMEM, "out of memory for %zu %s of %s", total, member, table);
    return RT_OK;
}

/* Appends item e's indices to list (*used so far) and counts them in *n. */
static rt_result read_index_list(gl_doc *d, int e, const char *where, const char *member, uint32_t *list, size_t *used,
                                 uint32_t *n)
{
    rt_result r;
    int a = rt_json_get(&d->j, e, member); /* the token the counting pass saw, even if the key is repeated */
    if (a < 0)
        return RT_OK;
    for (int i = 0, x = a + 1; i < d->j.tok[a].size && x < d->j.count; i++, x = rt_json_skip(&d->j, x)) {
        uint32_t index;
        if ((r = get_index(d, where, member, x, &index)) != RT_OK)
            return r;
        list[(*used)++] = index;
        (*n)++;
    }
    return RT_OK;
}

static rt_result parse_nodes(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "nodes", sizeof(gl_node), (void **)&d->nodes, &d->node_count)) != RT_OK)
        return r;
    if ((r = alloc_index_lists(d, t, "nodes", "children", &d->children)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "nodes[%d]", i);
        gl_node *n = &d->nodes[i];
        n->tok = e;
        n->mesh = n->camera = n->light = n->skin = n->parent = RT_NONE;
        n->first_child = (uint32_t)d->children_count;
        n->weights = -1;
        bool have_matrix = false, have_trs = false;
        float matrix[16], tr[3] = {0, 0, 0}, rot[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1};
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "mesh")) r = get_index(d, where, "mesh", v, &n->mesh);
            else if (KEY(k, "camera")) r = get_index(d, where, "camera", v, &n->camera);
            else if (KEY(k, "skin")) r = get_index(d, where, "skin", v, &n->skin);
            else if (KEY(k, "matrix")) {
                if ((r = get_floats(d, where, "matrix", v, matrix, 16)) != RT_OK)
                    return r;
                have_matrix = true;
            } else if (KEY(k, "translation")) {
                if ((r = get_floats(d, where, "translation", v, tr, 3)) != RT_OK)
                    return r;
                have_trs = true;
            } else if (KEY(k, "rotation")) {
                if ((r = get_floats(d, where, "rotation", v, rot, 4)) != RT_OK)
                    return r;
                have_trs = true;
            } else if (KEY(k, "scale")) {
                if ((r = get_floats(d, where, "scale", v, sc, 3)) != RT_OK)
                    return r;
                have_trs = true;
            } else if (KEY(k, "weights")) {
                n->weights = v;
            } else if (KEY(k, "extensions")) {
                int l = rt_json_get(&d->j, v, "KHR_lights_punctual");
                if (l >= 0) {
                    if ((r = expect_object(d, l, where)) != RT_OK)
                        return r;
                    int li = rt_json_get(&d->j, l, "light");
                    if (li >= 0)
                        r = get_index(d, where, "extensions.KHR_lights_punctual.light", li, &n->light);
                    if (r != RT_OK)
                        return r;
                }
            }
            if (r != RT_OK)
                return r;
        }
        if ((r = read_index_list(d, e, where, "children", d->children, &d->children_count, &n->child_count)) != RT_OK)
            return r;
        memcpy(n->tr, tr, sizeof tr);
        memcpy(n->sc, sc, sizeof sc);
        n->has_matrix = have_matrix;
        if (have_matrix) {
            if (have_trs)
                rt_warn("%s: %s has both matrix and TRS; using the matrix", d->path, where);
            n->local = mat_from_gltf(matrix);
        } else {
            double q2 = (double)rot[0] * rot[0] + (double)rot[1] * rot[1] + (double)rot[2] * rot[2] +
                        (double)rot[3] * rot[3];
            rt_vec4 q = rt_v4(0, 0, 0, 1);
            if (q2 > 1e-12) {
                float s = (float)(1.0 / sqrt(q2)); /* exporters round; renormalise */
                q = rt_v4(rot[0] * s, rot[1] * s, rot[2] * s, rot[3] * s);
            } else {
                rt_warn("%s: %s.rotation is a zero quaternion; using identity", d->path, where);
            }
            n->rot[0] = q.x; n->rot[1] = q.y; n->rot[2] = q.z; n->rot[3] = q.w;
            n->local = rt_mat4_mul(rt_mat4_translate(rt_v3(tr[0], tr[1], tr[2])),
                                   rt_mat4_mul(rt_mat4_quat(q), rt_mat4_scale(rt_v3(sc[0], sc[1], sc[2]))));
        }
    }
    return RT_OK;
}

static rt_result parse_scenes(gl_doc *d, int t)
{
    rt_result r;
    if ((r = alloc_table(d, t, "scenes", sizeof(gl_scene), (void **)&d->scenes, &d->scene_count)) != RT_OK)
        return r;
    if ((r = alloc_index_lists(d, t, "scenes", "nodes", &d->scene_nodes)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "scenes[%d]", i);
        gl_scene *sc = &d->scenes[i];
        sc->tok = e;
        sc->first = (uint32_t)d->scene_nodes_count;
        if ((r = read_index_list(d, e, where, "nodes", d->scene_nodes, &d->scene_nodes_count, &sc->count)) != RT_OK)
            return r;
    }
    return RT_OK;
}

/* A textureInfo: index, texCoord, KHR_texture_transform. */
static rt_result parse_texinfo(gl_doc *d, const char *where, const char *key, int t, rt_texture_slot *slot,
                               float *extra, const char *extra_key)
{
    rt_result r = RT_OK;
    char w[128];
    snprintf(w, sizeof w, "%s.%s", where, key);
    if ((r = expect_object(d, t, w)) != RT_OK)
        return r;
    uint32_t index = RT_NONE;
    int texcoord = 0;
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "index")) r = get_index(d, w, "index", v, &index);
        else if (KEY(k, "texCoord")) r = get_int(d, w, "texCoord", v, &texcoord);
        else if (extra_key && KEY(k, extra_key)) r = get_float(d, w, extra_key, v, extra);
        else if (KEY(k, "extensions")) {
            int x = rt_json_get(&d->j, v, "KHR_texture_transform");
            if (x < 0)
                continue;
            char wx[200];
            snprintf(wx, sizeof wx, "%s.extensions.KHR_texture_transform", w);
            if ((r = expect_object(d, x, wx)) != RT_OK)
                return r;
            float off[2] = {0, 0}, scale[2] = {1, 1}, rot = 0;
            for (int k2_n = 0, k2 = x + 1, v2 = x + 2; k2_n < d->j.tok[x].size && v2 < d->j.count;
                 k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                if (KEY(k2, "offset")) r = get_floats(d, wx, "offset", v2, off, 2);
                else if (KEY(k2, "scale")) r = get_floats(d, wx, "scale", v2, scale, 2);
                else if (KEY(k2, "rotation")) r = get_float(d, wx, "rotation", v2, &rot);
                else if (KEY(k2, "texCoord")) r = get_int(d, wx, "texCoord", v2, &texcoord);
                if (r != RT_OK)
                    return r;
            }
            /* matrix = T(offset) * R(rotation) * S(scale) with R, row-major,
             * = [cos sin; -sin cos]: u' = u cos + v sin, v' = -u sin + v cos.
             * This is the direction Babylon.js, three.js, Cesium, Blender and
             * the TextureTransformTest sample agree on ("counter-clockwise" in
             * glTF's v-down UV space); the README's GLSL listing, read as
             * GLSL's column-major, rotates the other way (KhronosGroup/glTF
             * issue 1563). */
            float c = cosf(rot), s = sinf(rot);
            slot->uv_transform[0] = c * scale[0];
            slot->uv_transform[1] = s * scale[1];
            slot->uv_transform[2] = off[0];
            slot->uv_transform[3] = -s * scale[0];
            slot->uv_transform[4] = c * scale[1];
            slot->uv_transform[5] = off[1];
        }
        if (r != RT_OK)
            return r;
    }
    if (index == RT_NONE)
        return fail_at(d, t, RT_ERR_INVALID, "%s: index is missing", w);
    if (texcoord < 0)
        return fail_at(d, t, RT_ERR_INVALID, "%s: texCoord %d is negative", w, texcoord);
    if (texcoord > 1) {
        rt_warn("%s: %s uses TEXCOORD_%d; only sets 0 and 1 are loaded, using 0", d->path, w, texcoord);
        texcoord = 0;
    }
    slot->texture = index;
    slot->texcoord = (uint8_t)texcoord;
    return RT_OK;
}

/* Phong fields from the metallic-roughness model, for the whitted
 * integrator (docs/gltf.md, "Material mapping"). */
static void derive_phong(rt_material *m)
{
    float metal = rt_clampf(m->metallic, 0, 1), rough = rt_clampf(m->roughness, 0, 1);
    float f0 = 0.04f + (1.0f - 0.04f) * metal;       /* mean normal-incidence reflectance */
    m->diffuse = 0.8f * (1.0f - metal) + 0.2f * metal; /* metals keep a little colour */
    m->specular = f0 * (1.0f - 0.5f * rough);
    /* KHR_materials_specular scales the dielectric's share of the highlight */
    rt_vec3 sc = m->specular_color;
    if (m->specular_weight != 1.0f || sc.x != 1.0f || sc.y != 1.0f || sc.z != 1.0f) {
        sc = rt_vmin(rt_scale(sc, 0.04f), rt_v3s(1.0f));
        float fd = m->specular_weight * (sc.x + sc.y + sc.z) / 3.0f;
        m->specular = (fd + (1.0f - fd) * metal) * (1.0f - 0.5f * rough);
    }
    float a = rough * rough;                          /* GGX alpha */
    float a2 = a * a;
    m->shininess = a2 > 1e-6f ? rt_clampf(2.0f / a2 - 2.0f, 1.0f, 4096.0f) : 4096.0f;
    float smooth = (1.0f - rough) * (1.0f - rough);
    m->reflectivity = metal * smooth;
}

/* A factor of a material extension that must lie in [lo, hi]. */
static rt_result get_ranged(gl_doc *d, const char *where, const char *key, int t, float lo, float hi, float *out)
{
    rt_result r;
    if ((r = get_float(d, where, key, t, out)) != RT_OK)
        return r;
    if (!(*out >= lo && *out <= hi))
        return fail_at(d, t, RT_ERR_INVALID, "%s.%s %g is outside [%g, %g]", where, key, (double)*out, (double)lo,
                       (double)hi);
    return RT_OK;
}

/* An RGB factor with every component in [lo, hi]. */
static rt_result get_color_ranged(gl_doc *d, const char *where, const char *key, int t, float lo, float hi,
                                  rt_vec3 *out)
{
    rt_result r;
    float c[3];
    if ((r = get_floats(d, where, key, t, c, 3)) != RT_OK)
        return r;
    for (int i = 0; i < 3; i++)
        if (!(c[i] >= lo && c[i] <= hi))
            return fail_at(d, t, RT_ERR_INVALID, "%s.%s component %d (%g) is outside [%g, %g]", where, key, i,
                           (double)c[i], (double)lo, (double)hi);
    *out = rt_v3(c[0], c[1], c[2]);
    return RT_OK;
}

/* The PBR-next material extensions (KHR_materials_clearcoat, specular,
 * sheen, anisotropy, iridescence, dispersion, diffuse_transmission), each
 * into its fields of the material table; *known is false for any other
 * key. Ranges are the extensions' schemas'. */
static rt_result parse_material_ext(gl_doc *d, const char *wx, int k2, int v2, rt_material *m, bool *known)
{
    rt_result r = RT_OK;
    char we[160];
    float big = 3.0e38f;
    *known = true;
    if (KEY(k2, "KHR_materials_clearcoat")) {
        snprintf(we, sizeof we, "%s.KHR_materials_clearcoat", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "clearcoatFactor")) r = get_ranged(d, we, "clearcoatFactor", v3, 0, 1, &m->clearcoat);
            else if (KEY(k3, "clearcoatRoughnessFactor"))
                r = get_ranged(d, we, "clearcoatRoughnessFactor", v3, 0, 1, &m->clearcoat_roughness);
            else if (KEY(k3, "clearcoatTexture"))
                r = parse_texinfo(d, we, "clearcoatTexture", v3, &m->ext_tex[RT_XTEX_CLEARCOAT], NULL, NULL);
            else if (KEY(k3, "clearcoatRoughnessTexture"))
                r = parse_texinfo(d, we, "clearcoatRoughnessTexture", v3, &m->ext_tex[RT_XTEX_CLEARCOAT_ROUGHNESS],
                                  NULL, NULL);
            else if (KEY(k3, "clearcoatNormalTexture"))
                r = parse_texinfo(d, we, "clearcoatNormalTexture", v3, &m->ext_tex[RT_XTEX_CLEARCOAT_NORMAL],
                                  &m->clearcoat_normal_scale, "scale");
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_specular")) {
        snprintf(we, sizeof we, "%s.KHR_materials_specular", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "specularFactor")) r = get_ranged(d, we, "specularFactor", v3, 0, 1, &m->specular_weight);
            else if (KEY(k3, "specularColorFactor"))
                r = get_color_ranged(d, we, "specularColorFactor", v3, 0, big, &m->specular_color);
            else if (KEY(k3, "specularTexture"))
                r = parse_texinfo(d, we, "specularTexture", v3, &m->ext_tex[RT_XTEX_SPECULAR], NULL, NULL);
            else if (KEY(k3, "specularColorTexture"))
                r = parse_texinfo(d, we, "specularColorTexture", v3, &m->ext_tex[RT_XTEX_SPECULAR_COLOR], NULL,
                                  NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_sheen")) {
        snprintf(we, sizeof we, "%s.KHR_materials_sheen", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "sheenColorFactor")) r = get_color_ranged(d, we, "sheenColorFactor", v3, 0, 1, &m->sheen_color);
            else if (KEY(k3, "sheenRoughnessFactor"))
                r = get_ranged(d, we, "sheenRoughnessFactor", v3, 0, 1, &m->sheen_roughness);
            else if (KEY(k3, "sheenColorTexture"))
                r = parse_texinfo(d, we, "sheenColorTexture", v3, &m->ext_tex[RT_XTEX_SHEEN_COLOR], NULL, NULL);
            else if (KEY(k3, "sheenRoughnessTexture"))
                r = parse_texinfo(d, we, "sheenRoughnessTexture", v3, &m->ext_tex[RT_XTEX_SHEEN_ROUGHNESS], NULL,
                                  NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_anisotropy")) {
        snprintf(we, sizeof we, "%s.KHR_materials_anisotropy", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "anisotropyStrength")) r = get_ranged(d, we, "anisotropyStrength", v3, 0, 1, &m->anisotropy);
            else if (KEY(k3, "anisotropyRotation"))
                r = get_ranged(d, we, "anisotropyRotation", v3, -big, big, &m->anisotropy_rotation);
            else if (KEY(k3, "anisotropyTexture"))
                r = parse_texinfo(d, we, "anisotropyTexture", v3, &m->ext_tex[RT_XTEX_ANISOTROPY], NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_iridescence")) {
        snprintf(we, sizeof we, "%s.KHR_materials_iridescence", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "iridescenceFactor")) r = get_ranged(d, we, "iridescenceFactor", v3, 0, 1, &m->iridescence);
            else if (KEY(k3, "iridescenceIor"))
                r = get_ranged(d, we, "iridescenceIor", v3, 1, big, &m->iridescence_ior);
            else if (KEY(k3, "iridescenceThicknessMinimum"))
                r = get_ranged(d, we, "iridescenceThicknessMinimum", v3, 0, big, &m->iridescence_thickness_min);
            else if (KEY(k3, "iridescenceThicknessMaximum"))
                r = get_ranged(d, we, "iridescenceThicknessMaximum", v3, 0, big, &m->iridescence_thickness_max);
            else if (KEY(k3, "iridescenceTexture"))
                r = parse_texinfo(d, we, "iridescenceTexture", v3, &m->ext_tex[RT_XTEX_IRIDESCENCE], NULL, NULL);
            else if (KEY(k3, "iridescenceThicknessTexture"))
                r = parse_texinfo(d, we, "iridescenceThicknessTexture", v3,
                                  &m->ext_tex[RT_XTEX_IRIDESCENCE_THICKNESS], NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_dispersion")) {
        snprintf(we, sizeof we, "%s.KHR_materials_dispersion", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        int s = rt_json_get(&d->j, v2, "dispersion");
        if (s >= 0)
            r = get_ranged(d, we, "dispersion", s, 0, big, &m->dispersion);
        if (r != RT_OK)
            return r;
    } else if (KEY(k2, "KHR_materials_diffuse_transmission")) {
        snprintf(we, sizeof we, "%s.KHR_materials_diffuse_transmission", wx);
        if ((r = expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "diffuseTransmissionFactor"))
                r = get_ranged(d, we, "diffuseTransmissionFactor", v3, 0, 1, &m->diffuse_transmission);
            else if (KEY(k3, "diffuseTransmissionColorFactor"))
                r = get_color_ranged(d, we, "diffuseTransmissionColorFactor", v3, 0, 1,
                                     &m->diffuse_transmission_color);
            else if (KEY(k3, "diffuseTransmissionTexture"))
                r = parse_texinfo(d, we, "diffuseTransmissionTexture", v3,
                                  &m->ext_tex[RT_XTEX_DIFFUSE_TRANSMISSION], NULL, NULL);
            else if (KEY(k3, "diffuseTransmissionColorTexture"))
                r = parse_texinfo(d, we, "diffuseTransmissionColorTexture", v3,
                                  &m->ext_tex[RT_XTEX_DIFFUSE_TRANSMISSION_COLOR], NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else {
        *known = false;
    }
    return RT_OK;
}

static rt_result parse_materials(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "materials", sizeof(gl_material), (void **)&d->materials, &d->material_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "materials[%d]", i);
        gl_material *gm = &d->materials[i];
        rt_material *m = &gm->m;
        gm->tok = e;
        char name[64];
        snprintf(name, sizeof name, "material%d", i);
        rt_material_default(m, name);
        m->color = rt_v3s(1);
        m->metallic = 1;
        m->roughness = 1;
        m->double_sided = false;
        m->transmission_color = rt_v3s(1);
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "name")) {
                if (rt_json_string(&d->j, v, m->name, sizeof m->name) < 0) /* long names: keep the default */
                    snprintf(m->name, sizeof m->name, "%s", name);
            } else if (KEY(k, "pbrMetallicRoughness")) {
                char wp[80];
                snprintf(wp, sizeof wp, "%s.pbrMetallicRoughness", where);
                if ((r = expect_object(d, v, wp)) != RT_OK)
                    return r;
                for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                     k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                    if (KEY(k2, "baseColorFactor")) {
                        float c[4];
                        if ((r = get_floats(d, wp, "baseColorFactor", v2, c, 4)) != RT_OK)
                            return r;
                        m->color = rt_v3(c[0], c[1], c[2]);
                        m->alpha = c[3];
                    } else if (KEY(k2, "metallicFactor")) r = get_float(d, wp, "metallicFactor", v2, &m->metallic);
                    else if (KEY(k2, "roughnessFactor")) r = get_float(d, wp, "roughnessFactor", v2, &m->roughness);
                    else if (KEY(k2, "baseColorTexture"))
                        r = parse_texinfo(d, wp, "baseColorTexture", v2, &m->base_color_tex, NULL, NULL);
                    else if (KEY(k2, "metallicRoughnessTexture"))
                        r = parse_texinfo(d, wp, "metallicRoughnessTexture", v2, &m->metal_rough_tex, NULL, NULL);
                    if (r != RT_OK)
                        return r;
                }
            } else if (KEY(k, "normalTexture")) {
                if ((r = parse_texinfo(d, where, "normalTexture", v, &m->normal_tex, &m->normal_scale, "scale")) != RT_OK)
                    return r;
            } else if (KEY(k, "occlusionTexture")) {
                if ((r = parse_texinfo(d, where, "occlusionTexture", v, &m->occlusion_tex, &m->occlusion_strength,
                                       "strength")) != RT_OK)
                    return r;
            } else if (KEY(k, "emissiveTexture")) {
                if ((r = parse_texinfo(d, where, "emissiveTexture", v, &m->emissive_tex, NULL, NULL)) != RT_OK)
                    return r;
            } else if (KEY(k, "emissiveFactor")) {
                float c[3];
                if ((r = get_floats(d, where, "emissiveFactor", v, c, 3)) != RT_OK)
                    return r;
                m->emission = rt_v3(c[0], c[1], c[2]);
            } else if (KEY(k, "alphaMode")) {
                char mode[16];
                if ((r = get_string(d, where, "alphaMode", v, mode, sizeof mode)) != RT_OK)
                    return r;
                if (strcmp(mode, "OPAQUE") == 0) m->alpha_mode = RT_ALPHA_OPAQUE;
                else if (strcmp(mode, "MASK") == 0) m->alpha_mode = RT_ALPHA_MASK;
                else if (strcmp(mode, "BLEND") == 0) m->alpha_mode = RT_ALPHA_BLEND;
                else
                    return fail_at(d, v, RT_ERR_INVALID, "%s.alphaMode \"%s\" is not OPAQUE, MASK or BLEND", where,
                                   mode);
            } else if (KEY(k, "alphaCutoff")) {
                if ((r = get_float(d, where, "alphaCutoff", v, &m->alpha_cutoff)) != RT_OK)
                    return r;
            } else if (KEY(k, "doubleSided")) {
                if ((r = get_bool(d, where, "doubleSided", v, &m->double_sided)) != RT_OK)
                    return r;
            } else if (KEY(k, "extras")) {
                /* extras are free-form: only an object with "bsdf": "lambertian"
                 * means something to rt (a pure Lambertian surface, as the
                 * shared reference scenes use); anything else is ignored */
                int b = rt_json_get(&d->j, v, "bsdf");
                char bsdf[16];
                if (b >= 0 && rt_json_string(&d->j, b, bsdf, sizeof bsdf) >= 0 && strcmp(bsdf, "lambertian") == 0)
                    m->bsdf = RT_BSDF_LAMBERT;
            } else if (KEY(k, "extensions")) {
                char wx[96];
                snprintf(wx, sizeof wx, "%s.extensions", where);
                if ((r = expect_object(d, v, wx)) != RT_OK)
                    return r;
                for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                     k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                    char we[160];
                    bool known;
                    if ((r = parse_material_ext(d, wx, k2, v2, m, &known)) != RT_OK)
                        return r;
                    if (known)
                        continue;
                    if (KEY(k2, "KHR_materials_emissive_strength")) {
                        snprintf(we, sizeof we, "%s.KHR_materials_emissive_strength", wx);
                        if ((r = expect_object(d, v2, we)) != RT_OK)
                            return r;
                        int s = rt_json_get(&d->j, v2, "emissiveStrength");
                        if (s >= 0)
                            r = get_float(d, we, "emissiveStrength", s, &m->emission_strength);
                        if (r != RT_OK)
                            return r;
                    } else if (KEY(k2, "KHR_materials_transmission")) {
                        snprintf(we, sizeof we, "%s.KHR_materials_transmission", wx);
                        if ((r = expect_object(d, v2, we)) != RT_OK)
                            return r;
                        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
                             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
                            if (KEY(k3, "transmissionFactor"))
                                r = get_float(d, we, "transmissionFactor", v3, &m->transmission);
                            else if (KEY(k3, "transmissionTexture"))
                                r = parse_texinfo(d, we, "transmissionTexture", v3, &m->transmission_tex, NULL, NULL);
                            if (r != RT_OK)
                                return r;
                        }
                    } else if (KEY(k2, "KHR_materials_ior")) {
                        snprintf(we, sizeof we, "%s.KHR_materials_ior", wx);
                        if ((r = expect_object(d, v2, we)) != RT_OK)
                            return r;
                        int s = rt_json_get(&d->j, v2, "ior");
                        if (s >= 0)
                            r = get_float(d, we, "ior", s, &m->ior);
                        if (r != RT_OK)
                            return r;
                    } else if (KEY(k2, "KHR_materials_volume")) {
                        snprintf(we, sizeof we, "%s.KHR_materials_volume", wx);
                        if ((r = expect_object(d, v2, we)) != RT_OK)
                            return r;
                        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
                             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
                            if (KEY(k3, "thicknessFactor")) r = get_float(d, we, "thicknessFactor", v3, &m->thickness);
                            else if (KEY(k3, "attenuationDistance"))
                                r = get_float(d, we, "attenuationDistance", v3, &m->attenuation_distance);
                            else if (KEY(k3, "attenuationColor")) {
                                float c[3];
                                if ((r = get_floats(d, we, "attenuationColor", v3, c, 3)) != RT_OK)
                                    return r;
                                m->attenuation_color = rt_v3(c[0], c[1], c[2]);
                            }
                            if (r != RT_OK)
                                return r;
                        }
                        if (!(m->attenuation_distance > 0))
                            return fail_at(d, v2, RT_ERR_INVALID, "%s.attenuationDistance must be positive", we);
                    } else if (KEY(k2, "KHR_materials_unlit")) {
                        m->unlit = true;
                    }
                }
            }
        }
        /* transmitted light is tinted by the base colour (KHR_materials_transmission) */
        m->transmission_color = m->color;
        /* KHR_materials_volume: thickness 0 (or no volume) is thin-walled */
        m->thin_walled = !(m->thickness > 0.0f);
        m->extended = rt_material_extended(m);
        derive_phong(m);
    }
    return RT_OK;
}

static rt_result parse_textures(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "textures", sizeof(gl_texture), (void **)&d->textures, &d->texture_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "textures[%d]", i);
        gl_texture *tx = &d->textures[i];
        tx->tok = e;
        tx->source = tx->sampler = RT_NONE;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        uint32_t webp = RT_NONE;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "source")) r = get_index(d, where, "source", v, &tx->source);
            else if (KEY(k, "sampler")) r = get_index(d, where, "sampler", v, &tx->sampler);
            else if (KEY(k, "extensions")) {
                int ew = rt_json_get(&d->j, v, "EXT_texture_webp");
                int src = ew >= 0 ? rt_json_get(&d->j, ew, "source") : -1;
                if (src >= 0)
                    r = get_index(d, where, "extensions.EXT_texture_webp.source", src, &webp);
                if (r != RT_OK)
                    return r;
                tx->other_source = tx->other_source || rt_json_get(&d->j, v, "KHR_texture_basisu") >= 0 ||
                                   rt_json_get(&d->j, v, "MSFT_texture_dds") >= 0;
            }
            if (r != RT_OK)
                return r;
        }
        if (webp != RT_NONE) /* EXT_texture_webp: the WebP image replaces the fallback source */
            tx->source = webp;
    }
    return RT_OK;
}

static rt_result parse_samplers(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "samplers", sizeof(gl_sampler), (void **)&d->samplers, &d->sampler_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "samplers[%d]", i);
        gl_sampler *sm = &d->samplers[i];
        sm->tok = e;
        sm->wrap_s = sm->wrap_t = 10497;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "magFilter")) r = get_int(d, where, "magFilter", v, &sm->mag);
            else if (KEY(k, "minFilter")) r = get_int(d, where, "minFilter", v, &sm->min);
            else if (KEY(k, "wrapS")) r = get_int(d, where, "wrapS", v, &sm->wrap_s);
            else if (KEY(k, "wrapT")) r = get_int(d, where, "wrapT", v, &sm->wrap_t);
            if (r != RT_OK)
                return r;
        }
        int w[2] = {sm->wrap_s, sm->wrap_t};
        for (int k = 0; k < 2; k++)
            if (w[k] != 33071 && w[k] != 33648 && w[k] != 10497)
                return fail_at(d, e, RT_ERR_INVALID, "%s: wrap mode %d is not 33071, 33648 or 10497", where, w[k]);
        if (sm->mag != 0 && sm->mag != 9728 && sm->mag != 9729)
            return fail_at(d, e, RT_ERR_INVALID, "%s: magFilter %d is not 9728 or 9729", where, sm->mag);
    }
    return RT_OK;
}

static rt_result parse_images(gl_doc *d, int t)
{
    rt_result r;
    if ((r = alloc_table(d, t, "images", sizeof(gl_image), (void **)&d->images, &d->image_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "images[%d]", i);
        gl_image *im = &d->images[i];
        im->tok = e;
        im->uri = -1;
        im->view = RT_NONE;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "uri")) {
                if (jtype(d, v) != RT_JSON_STRING)
                    return fail_at(d, v, RT_ERR_INVALID, "%s.uri: expected a string", where);
                im->uri = v;
            } else if (KEY(k, "bufferView")) {
                if ((r = get_index(d, where, "bufferView", v, &im->view)) != RT_OK)
                    return r;
            }
        }
        if ((im->uri < 0) == (im->view == RT_NONE))
            return fail_at(d, e, RT_ERR_INVALID, "%s: needs exactly one of uri and bufferView", where);
    }
    return RT_OK;
}

static rt_result parse_cameras(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "cameras", sizeof(gl_camera), (void **)&d->cameras, &d->camera_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "cameras[%d]", i);
        gl_camera *c = &d->cameras[i];
        c->tok = e;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        char type[16] = "";
        int persp = -1;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "type")) r = get_string(d, where, "type", v, type, sizeof type);
            else if (KEY(k, "perspective")) persp = v;
            if (r != RT_OK)
                return r;
        }
        if (strcmp(type, "perspective") == 0) {
            c->perspective = true;
            if (persp < 0)
                return fail_at(d, e, RT_ERR_INVALID, "%s: perspective is missing", where);
            char wp[64];
            snprintf(wp, sizeof wp, "%s.perspective", where);
            if ((r = expect_object(d, persp, wp)) != RT_OK)
                return r;
            c->yfov = -1;
            for (int k_n = 0, k = persp + 1, v = persp + 2; k_n < d->j.tok[persp].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "yfov")) r = get_float(d, wp, "yfov", v, &c->yfov);
                else if (KEY(k, "aspectRatio")) r = get_float(d, wp, "aspectRatio", v, &c->aspect);
                else if (KEY(k, "znear")) r = get_float(d, wp, "znear", v, &c->znear);
                else if (KEY(k, "zfar")) r = get_float(d, wp, "zfar", v, &c->zfar);
                if (r != RT_OK)
                    return r;
            }
            if (!(c->yfov > 0 && c->yfov < RT_PI))
                return fail_at(d, persp, RT_ERR_INVALID, "%s.yfov must be in (0, pi)", wp);
        } else if (strcmp(type, "orthographic") != 0) {
            return fail_at(d, e, RT_ERR_INVALID, "%s: type \"%s\" is not perspective or orthographic", where, type);
        }
    }
    return RT_OK;
}

static rt_result parse_lights(gl_doc *d, int ext)
{
    rt_result r = RT_OK;
    if ((r = expect_object(d, ext, "extensions")) != RT_OK)
        return r;
    int l = rt_json_get(&d->j, ext, "KHR_lights_punctual");
    if (l < 0)
        return RT_OK;
    if ((r = expect_object(d, l, "extensions.KHR_lights_punctual")) != RT_OK)
        return r;
    int t = rt_json_get(&d->j, l, "lights");
    if (t < 0)
        return RT_OK;
    if ((r = alloc_table(d, t, "lights", sizeof(gl_light), (void **)&d->lights, &d->light_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[64];
        snprintf(where, sizeof where, "KHR_lights_punctual.lights[%d]", i);
        gl_light *g = &d->lights[i];
        g->tok = e;
        g->color = rt_v3s(1);
        g->intensity = 1;
        g->inner = 0;
        g->outer = RT_PI / 4;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        char type[16] = "";
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "type")) r = get_string(d, where, "type", v, type, sizeof type);
            else if (KEY(k, "color")) {
                float c[3];
                if ((r = get_floats(d, where, "color", v, c, 3)) != RT_OK)
                    return r;
                g->color = rt_v3(c[0], c[1], c[2]);
            } else if (KEY(k, "intensity")) r = get_float(d, where, "intensity", v, &g->intensity);
            else if (KEY(k, "range")) r = get_float(d, where, "range", v, &g->range);
            else if (KEY(k, "spot")) {
                if ((r = expect_object(d, v, where)) != RT_OK)
                    return r;
                for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                     k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                    if (KEY(k2, "innerConeAngle")) r = get_float(d, where, "spot.innerConeAngle", v2, &g->inner);
                    else if (KEY(k2, "outerConeAngle")) r = get_float(d, where, "spot.outerConeAngle", v2, &g->outer);
                    if (r != RT_OK)
                        return r;
                }
            }
            if (r != RT_OK)
                return r;
        }
        if (strcmp(type, "point") == 0) g->kind = RT_LIGHT_POINT;
        else if (strcmp(type, "spot") == 0) g->kind = RT_LIGHT_SPOT;
        else if (strcmp(type, "directional") == 0) g->kind = RT_LIGHT_DIRECTIONAL;
        else return fail_at(d, e, RT_ERR_INVALID, "%s: type \"%s\" is not point, spot or directional", where, type);
        if (g->range < 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: range must be positive", where);
        if (!(g->inner >= 0 && g->inner < g->outer && g->outer <= RT_PI / 2 + 1e-6f))
            return fail_at(d, e, RT_ERR_INVALID, "%s: spot cones need 0 <= inner < outer <= pi/2", where);
    }
    return RT_OK;
}

static rt_result parse_skins(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "skins", sizeof(gl_skin), (void **)&d->skins, &d->skin_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "skins[%d]", i);
        gl_skin *sk = &d->skins[i];
        sk->tok = e;
        sk->ibm = RT_NONE;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        int joints = -1;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "inverseBindMatrices")) r = get_index(d, where, "inverseBindMatrices", v, &sk->ibm);
            else if (KEY(k, "joints")) joints = v;
            if (r != RT_OK)
                return r;
        }
        if (joints < 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: joints is missing", where);
        if ((r = expect_array(d, joints, where, "joints")) != RT_OK)
            return r;
        if (jsize(d, joints) == 0)
            return fail_at(d, joints, RT_ERR_INVALID, "%s.joints is empty", where);
        sk->first_joint = (uint32_t)d->skin_joints_count;
        for (int j = 0, je = joints + 1; j < d->j.tok[joints].size && je < d->j.count;
             j++, je = rt_json_skip(&d->j, je)) {
            if (!rt_grow((void **)&d->skin_joints, &d->skin_joints_cap, d->skin_joints_count + 1, sizeof(uint32_t)))
                return fail_at(d, je, RT_ERR_NOMEM, "out of memory for joints");
            if ((r = get_index(d, where, "joints", je, &d->skin_joints[d->skin_joints_count++])) != RT_OK)
                return r;
        }
        sk->joint_count = (uint32_t)(d->skin_joints_count - sk->first_joint);
    }
    return RT_OK;
}

static rt_result parse_animations(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = alloc_table(d, t, "animations", sizeof(gl_anim), (void **)&d->anims, &d->anim_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "animations[%d]", i);
        gl_anim *an = &d->anims[i];
        an->tok = e;
        if ((r = expect_object(d, e, where)) != RT_OK)
            return r;
        int chans = rt_json_get(&d->j, e, "channels"), samps = rt_json_get(&d->j, e, "samplers");
        if (chans < 0 || samps < 0)
            return fail_at(d, e, RT_ERR_INVALID, "%s: needs channels and samplers", where);
        if ((r = expect_array(d, samps, where, "samplers")) != RT_OK)
            return r;
        if ((r = expect_array(d, chans, where, "channels")) != RT_OK)
            return r;
        an->first_sampler = (uint32_t)d->asampler_count;
        for (int j = 0, se = samps + 1; j < d->j.tok[samps].size && se < d->j.count;
             j++, se = rt_json_skip(&d->j, se)) {
            char w[80];
            snprintf(w, sizeof w, "%s.samplers[%d]", where, j);
            if ((r = expect_object(d, se, w)) != RT_OK)
                return r;
            if (!rt_grow((void **)&d->asamplers, &d->asampler_cap, d->asampler_count + 1, sizeof(gl_asampler)))
                return fail_at(d, se, RT_ERR_NOMEM, "out of memory for animation samplers");
            gl_asampler *sa = &d->asamplers[d->asampler_count++];
            sa->input = sa->output = RT_NONE;
            sa->interp = RT_INTERP_LINEAR;
            sa->tok = se;
            for (int k_n = 0, k = se + 1, v = se + 2; k_n < d->j.tok[se].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "input")) r = get_index(d, w, "input", v, &sa->input);
                else if (KEY(k, "output")) r = get_index(d, w, "output", v, &sa->output);
                else if (KEY(k, "interpolation")) {
                    char name[32];
                    if ((r = get_string(d, w, "interpolation", v, name, sizeof name)) != RT_OK)
                        return r;
                    if (strcmp(name, "LINEAR") == 0) sa->interp = RT_INTERP_LINEAR;
                    else if (strcmp(name, "STEP") == 0) sa->interp = RT_INTERP_STEP;
                    else if (strcmp(name, "CUBICSPLINE") == 0) sa->interp = RT_INTERP_CUBICSPLINE;
                    else
                        return fail_at(d, v, RT_ERR_INVALID,
                                       "%s.interpolation \"%s\" is not LINEAR, STEP or CUBICSPLINE", w, name);
                }
                if (r != RT_OK)
                    return r;
            }
            if (sa->input == RT_NONE || sa->output == RT_NONE)
                return fail_at(d, se, RT_ERR_INVALID, "%s: needs input and output", w);
        }
        an->sampler_count = (uint32_t)(d->asampler_count - an->first_sampler);
        an->first_channel = (uint32_t)d->channel_count;
        for (int j = 0, ce = chans + 1; j < d->j.tok[chans].size && ce < d->j.count;
             j++, ce = rt_json_skip(&d->j, ce)) {
            char w[80];
            snprintf(w, sizeof w, "%s.channels[%d]", where, j);
            if ((r = expect_object(d, ce, w)) != RT_OK)
                return r;
            if (!rt_grow((void **)&d->channels, &d->channel_cap, d->channel_count + 1, sizeof(gl_channel)))
                return fail_at(d, ce, RT_ERR_NOMEM, "out of memory for animation channels");
            gl_channel *ch = &d->channels[d->channel_count++];
            ch->sampler = ch->node = RT_NONE;
            ch->path = -1;
            ch->tok = ce;
            for (int k_n = 0, k = ce + 1, v = ce + 2; k_n < d->j.tok[ce].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "sampler")) r = get_index(d, w, "sampler", v, &ch->sampler);
                else if (KEY(k, "target")) {
                    if ((r = expect_object(d, v, w)) != RT_OK)
                        return r;
                    for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                        if (KEY(k2, "node")) r = get_index(d, w, "target.node", v2, &ch->node);
                        else if (KEY(k2, "path")) {
                            char name[32];
                            if ((r = get_string(d, w, "target.path", v2, name, sizeof name)) != RT_OK)
                                return r;
                            if (strcmp(name, "translation") == 0) ch->path = PATH_TRANSLATION;
                            else if (strcmp(name, "rotation") == 0) ch->path = PATH_ROTATION;
                            else if (strcmp(name, "scale") == 0) ch->path = PATH_SCALE;
                            else if (strcmp(name, "weights") == 0) ch->path = PATH_WEIGHTS;
                            else
                                ch->path = -2; /* "pointer" (KHR_animation_pointer) and others: not ours */
                        }
                        if (r != RT_OK)
                            return r;
                    }
                }
                if (r != RT_OK)
                    return r;
            }
            if (ch->sampler == RT_NONE || ch->path == -1)
                return fail_at(d, ce, RT_ERR_INVALID, "%s: needs sampler and target.path", w);
            if (ch->sampler >= an->sampler_count)
                return fail_at(d, ce, RT_ERR_INVALID, "%s.sampler %u is out of range (the animation has %u samplers)",
                               w, ch->sampler, an->sampler_count);
        }
        an->channel_count = (uint32_t)(d->channel_count - an->first_channel);
    }
    return RT_OK;
}

static rt_result parse_document(gl_doc *d)
{
    rt_result r = RT_OK;
    if ((r = rt_json_parse(&d->j, d->json_text, d->json_len, d->path, d->json_base, d->err)) != RT_OK)
        return r;
    if ((r = expect_object(d, 0, "glTF")) != RT_OK)
        return r;
    if ((r = check_extensions(d)) != RT_OK)
        return r;
    bool have_asset = false;
    d->default_scene = RT_NONE;
    d->variants_tok = -1;
    for (int k_n = 0, k = 1, v = 2; k_n < d->j.tok[0].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "asset")) {
            r = parse_asset(d, v);
            have_asset = true;
        }
        else if (KEY(k, "buffers")) r = parse_buffers(d, v);
        else if (KEY(k, "bufferViews")) r = parse_views(d, v);
        else if (KEY(k, "accessors")) r = parse_accessors(d, v);
        else if (KEY(k, "meshes")) r = parse_meshes(d, v);
        else if (KEY(k, "nodes")) r = parse_nodes(d, v);
        else if (KEY(k, "scenes")) r = parse_scenes(d, v);
        else if (KEY(k, "scene")) r = get_index(d, "glTF", "scene", v, &d->default_scene);
        else if (KEY(k, "materials")) r = parse_materials(d, v);
        else if (KEY(k, "textures")) r = parse_textures(d, v);
        else if (KEY(k, "samplers")) r = parse_samplers(d, v);
        else if (KEY(k, "images")) r = parse_images(d, v);
        else if (KEY(k, "cameras")) r = parse_cameras(d, v);
        else if (KEY(k, "extensions")) {
            if ((r = parse_lights(d, v)) != RT_OK)
                return r;
            int x = rt_json_get(&d->j, v, "KHR_materials_variants");
            if (x >= 0) {
                if ((r = expect_object(d, x, "extensions.KHR_materials_variants")) != RT_OK)
                    return r;
                d->variants_tok = rt_json_get(&d->j, x, "variants");
                if (d->variants_tok < 0)
                    return fail_at(d, x, RT_ERR_INVALID, "extensions.KHR_materials_variants: variants is missing");
                if ((r = expect_array(d, d->variants_tok, "extensions.KHR_materials_variants", "variants")) != RT_OK)
                    return r;
            }
        }
        else if (KEY(k, "skins")) r = parse_skins(d, v);
        else if (KEY(k, "animations")) r = parse_animations(d, v);
        if (r != RT_OK)
            return r;
    }
    if (!have_asset)
        return fail_at(d, 0, RT_ERR_INVALID, "asset is missing (not a glTF file?)");
    return RT_OK;
}

/* ---------------------------------------------------------- validation */

/* An index into a table of `count` records: RT_NONE (absent) or in range.
 * The message names the reference, "what" formatted from fmt. */
static rt_result check_index(gl_doc *d, uint32_t idx, size_t count, int tok, const char *table, const char *fmt, ...)
    RT_PRINTF(6, 7);
static rt_result check_index(gl_doc *d, uint32_t idx, size_t count, int tok, const char *table, const char *fmt, ...)
{
    if (idx == RT_NONE || (size_t)idx < count)
        return RT_OK;
    char what[160];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return fail_at(d, tok, RT_ERR_INVALID, "%s %u is out of range (the file has %zu %s)", what, (unsigned)idx, count,
                   table);
}

/* Does [offset, offset + count * stride - stride + elem) fit in length? */
static bool span_fits(size_t offset, size_t count, size_t stride, size_t elem, size_t length)
{
    if (offset > length || elem > length - offset)
        return false;
    if (count <= 1)
        return true;
    size_t room = length - offset - elem;
    return stride == 0 ? true : (count - 1) <= room / stride;
}

/* "meshes[m].primitives[k]" for the primitive at index p of doc.prims. */
static const char *prim_name(const gl_doc *d, size_t p, char *buf, size_t cap)
{
    for (size_t m = 0; m < d->mesh_count; m++)
        if (p >= d->meshes[m].first && p - d->meshes[m].first < d->meshes[m].count) {
            snprintf(buf, cap, "meshes[%zu].primitives[%zu]", m, p - d->meshes[m].first);
            return buf;
        }
    snprintf(buf, cap, "primitive %zu", p);
    return buf;
}

/* An EXT_meshopt_compression view: its source inside a buffer with data,
 * its decoded size its byteLength; a plain view of a fallback buffer
 * without data has nothing to read. */
static rt_result validate_meshopt_view(gl_doc *d, size_t i)
{
    rt_result r;
    gl_view *v = &d->views[i];
    const gl_buffer *b = &d->buffers[v->buffer];
    if (!v->meshopt) {
        if (b->fallback && b->uri < 0)
            return fail_at(d, v->tok, RT_ERR_INVALID,
                           "bufferViews[%zu] reads buffer %u, an EXT_meshopt_compression fallback with no data", i,
                           v->buffer);
        return RT_OK;
    }
    if ((r = check_index(d, v->mo_buffer, d->buffer_count, v->mo_tok, "buffers",
                              "bufferViews[%zu].extensions.EXT_meshopt_compression.buffer", i)) != RT_OK)
        return r;
    const gl_buffer *src = &d->buffers[v->mo_buffer];
    if (src->fallback)
        return fail_at(d, v->mo_tok, RT_ERR_INVALID,
                       "bufferViews[%zu]: compressed data in buffer %u, which is a fallback buffer", i, v->mo_buffer);
    if (!span_fits(v->mo_offset, 1, 0, v->mo_length, src->byte_length))
        return fail_at(d, v->mo_tok, RT_ERR_INVALID,
                       "bufferViews[%zu]: compressed byteOffset %zu + byteLength %zu runs past buffer %u (%zu bytes)",
                       i, v->mo_offset, v->mo_length, v->mo_buffer, src->byte_length);
    if (v->mo_count > v->length / v->mo_stride || v->mo_count * v->mo_stride != v->length)
        return fail_at(d, v->mo_tok, RT_ERR_INVALID,
                       "bufferViews[%zu]: count %zu x byteStride %zu is not the view's byteLength %zu", i, v->mo_count,
                       v->mo_stride, v->length);
    return RT_OK;
}

/* Draco primitives: triangles with indices, and every accessor they fill
 * marked (such accessors need no bufferView, so the limit on all-zero
 * accessors does not apply to them). */
static rt_result validate_draco_prims(gl_doc *d)
{
    rt_result r;
    for (size_t p = 0; p < d->prim_count; p++) {
        gl_prim *pr = &d->prims[p];
        if (pr->draco_view == RT_NONE)
            continue;
        char name[64];
        prim_name(d, p, name, sizeof name);
        if ((r = check_index(d, pr->draco_view, d->view_count, pr->draco_tok, "bufferViews",
                                  "%s.extensions.KHR_draco_mesh_compression.bufferView", name)) != RT_OK)
            return r;
        if (pr->mode != 4 || pr->indices == RT_NONE)
            return fail_at(d, pr->draco_tok, RT_ERR_UNSUPPORTED,
                           "%s: a KHR_draco_mesh_compression primitive must be indexed triangles (mode 4 with "
                           "indices)", name);
        if ((r = check_index(d, pr->indices, d->accessor_count, pr->tok, "accessors", "%s.indices", name)) != RT_OK)
            return r;
        d->accessors[pr->indices].draco = true;
        for (int k = 0; k < ATTR_COUNT; k++) {
            if (pr->draco_id[k] == RT_NONE)
                continue;
            if (pr->attr[k] == RT_NONE)
                return fail_at(d, pr->draco_tok, RT_ERR_INVALID,
                               "%s: KHR_draco_mesh_compression.attributes.%s has no accessor in the "
                               "primitive's attributes",
                               name, attr_names[k]);
            if ((r = check_index(d, pr->attr[k], d->accessor_count, pr->tok, "accessors", "%s.attributes.%s", name,
                                      attr_names[k])) != RT_OK)
                return r;
            d->accessors[pr->attr[k]].draco = true;
        }
    }
    return RT_OK;
}

static rt_result validate(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->view_count; i++) {
        const gl_view *v = &d->views[i];
        if ((r = check_index(d, v->buffer, d->buffer_count, v->tok, "buffers", "bufferViews[%zu].buffer", i)) != RT_OK)
            return r;
        size_t blen = d->buffers[v->buffer].byte_length;
        if (!span_fits(v->offset, 1, 0, v->length, blen))
            return fail_at(d, v->tok, RT_ERR_INVALID,
                           "bufferViews[%zu]: byteOffset %zu + byteLength %zu runs past buffer %u (%zu bytes)", i,
                           v->offset, v->length, v->buffer, blen);
        if ((r = validate_meshopt_view(d, i)) != RT_OK)
            return r;
    }
    if ((r = validate_draco_prims(d)) != RT_OK)
        return r;
    for (size_t i = 0; i < d->accessor_count; i++) {
        gl_accessor *a = &d->accessors[i];
        size_t es = elem_size(a);
        if (a->view != RT_NONE) {
            if ((r = check_index(d, a->view, d->view_count, a->tok, "bufferViews", "accessors[%zu].bufferView", i)) != RT_OK)
                return r;
            const gl_view *v = &d->views[a->view];
            size_t stride = v->stride ? v->stride : es;
            if (stride < es)
                return fail_at(d, a->tok, RT_ERR_INVALID,
                               "accessors[%zu]: bufferView %u has byteStride %zu, less than the element size %zu", i,
                               a->view, v->stride, es);
            if (!span_fits(a->offset, a->count, stride, es, v->length))
                return fail_at(d, a->tok, RT_ERR_INVALID,
                               "accessors[%zu]: byteOffset %zu + %zu elements of %zu bytes (stride %zu) run past "
                               "bufferView %u (%zu bytes)",
                               i, a->offset, a->count, es, stride, a->view, v->length);
        } else if (a->count > GL_MAX_ZEROS && !a->draco) {
            return fail_at(d, a->tok, RT_ERR_LIMIT,
                           "accessors[%zu]: count %zu without a bufferView is over the limit %zu", i, a->count,
                           GL_MAX_ZEROS);
        }
        if (a->sparse_count) {
            if ((r = check_index(d, a->sp_idx_view, d->view_count, a->tok, "bufferViews",
                                      "accessors[%zu].sparse.indices.bufferView", i)) != RT_OK)
                return r;
            if ((r = check_index(d, a->sp_val_view, d->view_count, a->tok, "bufferViews",
                                      "accessors[%zu].sparse.values.bufferView", i)) != RT_OK)
                return r;
            size_t ics = comp_size(a->sp_idx_ctype);
            if (!span_fits(a->sp_idx_offset, a->sparse_count, ics, ics, d->views[a->sp_idx_view].length))
                return fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%zu].sparse.indices run past bufferView %u", i,
                               a->sp_idx_view);
            if (!span_fits(a->sp_val_offset, a->sparse_count, es, es, d->views[a->sp_val_view].length))
                return fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%zu].sparse.values run past bufferView %u", i,
                               a->sp_val_view);
        }
    }
    for (size_t m = 0; m < d->mesh_count; m++) {
        for (uint32_t p = 0; p < d->meshes[m].count; p++) {
            const gl_prim *pr = &d->prims[d->meshes[m].first + p];
            if ((r = check_index(d, pr->material, d->material_count, pr->tok, "materials",
                                      "meshes[%zu].primitives[%u].material", m, p)) != RT_OK)
                return r;
            if ((r = check_index(d, pr->indices, d->accessor_count, pr->tok, "accessors",
                                      "meshes[%zu].primitives[%u].indices", m, p)) != RT_OK)
                return r;
            if (pr->indices != RT_NONE) {
                const gl_accessor *a = &d->accessors[pr->indices];
                if (a->ncomp != 1 || a->normalized ||
                    (a->ctype != GL_UNSIGNED_BYTE && a->ctype != GL_UNSIGNED_SHORT && a->ctype != GL_UNSIGNED_INT))
                    return fail_at(d, pr->tok, RT_ERR_INVALID,
                                   "meshes[%zu].primitives[%u].indices: accessor %u must be SCALAR of unsigned "
                                   "byte, short or int",
                                   m, p, pr->indices);
            }
            size_t count = 0;
            for (int k = 0; k < ATTR_COUNT; k++) {
                uint32_t ai = pr->attr[k];
                if ((r = check_index(d, ai, d->accessor_count, pr->tok, "accessors",
                                          "meshes[%zu].primitives[%u].attributes.%s", m, p,
                                          attr_names[k])) != RT_OK)
                    return r;
                if (ai == RT_NONE)
                    continue;
                const gl_accessor *a = &d->accessors[ai];
                /* types and component types of the spec's attribute table,
                 * widened by KHR_mesh_quantization (accepted whether or not
                 * the file declares it) */
                bool ok = a->cols == 1, ct = false;
                bool f = a->ctype == GL_FLOAT, n = a->normalized;
                bool s8s16 = a->ctype == GL_BYTE || a->ctype == GL_SHORT;
                bool u8u16 = a->ctype == GL_UNSIGNED_BYTE || a->ctype == GL_UNSIGNED_SHORT;
                switch (k) {
                case ATTR_POSITION: ok = ok && a->ncomp == 3; ct = f || s8s16 || u8u16; break;
                case ATTR_NORMAL: ok = ok && a->ncomp == 3; ct = f || (s8s16 && n); break;
                case ATTR_TANGENT: ok = ok && a->ncomp == 4; ct = f || (s8s16 && n); break;
                case ATTR_TEXCOORD_0: case ATTR_TEXCOORD_1: ok = ok && a->ncomp == 2; ct = f || s8s16 || u8u16; break;
                case ATTR_COLOR_0: ok = ok && (a->ncomp == 3 || a->ncomp == 4); ct = f || (u8u16 && n); break;
                }
                if (!ok)
                    return fail_at(d, pr->tok, RT_ERR_INVALID,
                                   "meshes[%zu].primitives[%u].attributes.%s: accessor %u has the wrong type", m, p,
                                   attr_names[k], ai);
                if (!ct)
                    return fail_at(d, pr->tok, RT_ERR_INVALID,
                                   "meshes[%zu].primitives[%u].attributes.%s: accessor %u has componentType %d%s, "
                                   "which this attribute does not allow",
                                   m, p, attr_names[k], ai, a->ctype, n ? " (normalized)" : "");
                if (count && a->count != count)
                    return fail_at(d, pr->tok, RT_ERR_INVALID,
                                   "meshes[%zu].primitives[%u].attributes.%s: accessor %u has %zu elements, the "
                                   "others %zu",
                                   m, p, attr_names[k], ai, a->count, count);
                count = a->count;
            }
        }
    }
    for (size_t i = 0; i < d->node_count; i++) {
        gl_node *n = &d->nodes[i];
        if ((r = check_index(d, n->mesh, d->mesh_count, n->tok, "meshes", "nodes[%zu].mesh", i)) != RT_OK)
            return r;
        if ((r = check_index(d, n->camera, d->camera_count, n->tok, "cameras", "nodes[%zu].camera", i)) != RT_OK)
            return r;
        if ((r = check_index(d, n->skin, d->skin_count, n->tok, "skins", "nodes[%zu].skin", i)) != RT_OK)
            return r;
        if ((r = check_index(d, n->light, d->light_count, n->tok, "lights", "nodes[%zu].KHR_lights_punctual.light", i)) != RT_OK)
            return r;
        for (uint32_t c = 0; c < n->child_count; c++) {
            uint32_t ch = d->children[n->first_child + c];
            if ((r = check_index(d, ch, d->node_count, n->tok, "nodes", "nodes[%zu].children", i)) != RT_OK)
                return r;
            if (d->nodes[ch].parent != RT_NONE)
                return fail_at(d, n->tok, RT_ERR_INVALID, "nodes[%zu]: child %u already has parent node %u", i, ch,
                               d->nodes[ch].parent);
            d->nodes[ch].parent = (uint32_t)i;
        }
    }
    /* Each node has at most one parent now. Depths by walking up to a root
     * or a node of known depth, memoised, so the whole pass is linear; a
     * walk that meets its own path is a cycle. */
    {
        const uint32_t unknown = UINT32_MAX, on_path = UINT32_MAX - 1;
        uint32_t *depth = rt_alloc(d->node_count, sizeof(uint32_t));
        uint32_t *path = rt_alloc(GL_MAX_DEPTH + 2, sizeof(uint32_t));
        if (!depth || !path) {
            free(depth);
            free(path);
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
        }
        for (size_t i = 0; i < d->node_count; i++)
            depth[i] = unknown;
        r = RT_OK;
        for (size_t i = 0; i < d->node_count && r == RT_OK; i++) {
            size_t len = 0;
            uint32_t n = (uint32_t)i;
            while (depth[n] == unknown) {
                if (len > GL_MAX_DEPTH) {
                    r = fail_at(d, d->nodes[i].tok, RT_ERR_LIMIT, "nodes[%zu] is more than %d levels deep", i,
                                GL_MAX_DEPTH);
                    break;
                }
                depth[n] = on_path;
                path[len++] = n;
                uint32_t p = d->nodes[n].parent;
                if (p == RT_NONE) {
                    n = RT_NONE;
                    break;
                }
                if (depth[p] == on_path) {
                    r = fail_at(d, d->nodes[p].tok, RT_ERR_INVALID, "nodes[%u] is its own ancestor (a cycle)", p);
                    break;
                }
                n = p;
            }
            if (r != RT_OK)
                break;
            uint32_t base = n == RT_NONE ? 0 : depth[n] + 1;
            for (size_t k = len; k-- > 0; base++) {
                if (base > GL_MAX_DEPTH) {
                    r = fail_at(d, d->nodes[i].tok, RT_ERR_LIMIT, "nodes[%zu] is more than %d levels deep", i,
                                GL_MAX_DEPTH);
                    break;
                }
                depth[path[k]] = base;
            }
        }
        free(depth);
        free(path);
        if ((r = r) != RT_OK)
            return r;
    }
    /* scene roots: in range, parentless, listed once (mark[n] = scene + 1) */
    uint32_t *mark = rt_alloc(d->node_count, sizeof(uint32_t));
    if (!mark)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    for (size_t i = 0; i < d->scene_count; i++) {
        const gl_scene *sc = &d->scenes[i];
        for (uint32_t k = 0; k < sc->count; k++) {
            uint32_t n = d->scene_nodes[sc->first + k];
            r = RT_OK;
            if (n >= d->node_count)
                r = fail_at(d, sc->tok, RT_ERR_INVALID,
                            "scenes[%zu].nodes %u is out of range (the file has %zu nodes)", i, n, d->node_count);
            else if (d->nodes[n].parent != RT_NONE)
                r = fail_at(d, sc->tok, RT_ERR_INVALID, "scenes[%zu]: node %u is not a root (its parent is node %u)",
                            i, n, d->nodes[n].parent);
            else if (mark[n] == i + 1)
                r = fail_at(d, sc->tok, RT_ERR_INVALID, "scenes[%zu]: node %u is listed twice", i, n);
            if (r != RT_OK) {
                free(mark);
                return r;
            }
            mark[n] = (uint32_t)i + 1;
        }
    }
    free(mark);
    if ((r = check_index(d, d->default_scene, d->scene_count, -1, "scenes", "scene")) != RT_OK)
        return r;
    for (size_t i = 0; i < d->material_count; i++) {
        const rt_material *m = &d->materials[i].m;
        const rt_texture_slot *slots[] = {&m->base_color_tex, &m->metal_rough_tex, &m->normal_tex,
                                          &m->occlusion_tex,  &m->emissive_tex,    &m->transmission_tex};
        for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++)
            if ((r = check_index(d, slots[k]->texture, d->texture_count, d->materials[i].tok, "textures",
                                      "materials[%zu]: texture", i)) != RT_OK)
                return r;
        for (int k = 0; k < RT_XTEX_COUNT; k++)
            if ((r = check_index(d, m->ext_tex[k].texture, d->texture_count, d->materials[i].tok, "textures",
                                      "materials[%zu].extensions: texture", i)) != RT_OK)
                return r;
    }
    for (size_t i = 0; i < d->texture_count; i++) {
        if ((r = check_index(d, d->textures[i].source, d->image_count, d->textures[i].tok, "images", "textures[%zu].source", i)) != RT_OK)
            return r;
        if ((r = check_index(d, d->textures[i].sampler, d->sampler_count, d->textures[i].tok, "samplers",
                                  "textures[%zu].sampler", i)) != RT_OK)
            return r;
    }
    for (size_t i = 0; i < d->image_count; i++)
        if ((r = check_index(d, d->images[i].view, d->view_count, d->images[i].tok, "bufferViews", "images[%zu].bufferView", i)) != RT_OK)
            return r;
    return RT_OK;
}

/* ------------------------------------------------------- URIs and data */

static int hexval(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* Decodes a data: URI (base64 only) into a fresh buffer. */
static rt_result decode_data_uri(gl_doc *d, int tok, const char *uri, size_t len, const char *what, uint8_t **out,
                                 size_t *out_len)
{
    const char *comma = memchr(uri, ',', len);
    if (!comma)
        return fail_at(d, tok, RT_ERR_INVALID, "%s: data: URI without a ','", what);
    size_t head = (size_t)(comma - uri);
    if (head < 12 || memcmp(comma - 7, ";base64", 7) != 0)
        return fail_at(d, tok, RT_ERR_UNSUPPORTED, "%s: only base64 data: URIs are supported", what);
    const char *b = comma + 1;
    size_t blen = len - head - 1;
    uint8_t *buf = malloc(rt_base64_max_decoded(blen));
    if (!buf)
        return fail_at(d, tok, RT_ERR_NOMEM, "%s: out of memory decoding %zu base64 characters", what, blen);
    size_t n, bad;
    if (rt_base64_decode(b, blen, buf, &n, &bad) != RT_OK) {
        free(buf);
        if (bad >= blen)
            return fail_at(d, tok, RT_ERR_PARSE, "%s: bad base64 in data: URI (length %zu is not a multiple of 4)",
                           what, blen);
        unsigned char c = (unsigned char)b[bad];
        return fail_at(d, tok, RT_ERR_PARSE, "%s: bad base64 in data: URI: character %zu is '%c' (0x%02X)", what,
                       head + 1 + bad, c >= 32 && c < 127 ? c : '?', c);
    }
    *out = buf;
    *out_len = n;
    return RT_OK;
}

/* Resolves a relative file URI against the .gltf's directory. */
static rt_result uri_to_path(gl_doc *d, int tok, const char *uri, const char *what, char **out)
{
    size_t len = strlen(uri);
    for (const char *p = uri; *p && *p != '/'; p++)
        if (*p == ':')
            return fail_at(d, tok, RT_ERR_UNSUPPORTED, "%s: URI \"%.200s\" has a scheme; only relative paths and "
                           "data: URIs are supported", what, uri);
    if (uri[0] == '/' || uri[0] == '\0')
        return fail_at(d, tok, RT_ERR_INVALID, "%s: URI \"%.200s\" is not a relative path", what, uri);
    size_t dl = strlen(d->dir);
    char *path = malloc(dl + len + 1);
    if (!path)
        return fail_at(d, tok, RT_ERR_NOMEM, "%s: out of memory", what);
    memcpy(path, d->dir, dl);
    size_t o = dl;
    for (size_t i = 0; i < len; i++) {
        if (uri[i] == '%') {
            int h = i + 2 < len ? hexval(uri[i + 1]) : -1, l = i + 2 < len ? hexval(uri[i + 2]) : -1;
            if (h < 0 || l < 0 || (h == 0 && l == 0)) {
                free(path);
                return fail_at(d, tok, RT_ERR_INVALID, "%s: bad percent-encoding in URI \"%.200s\"", what, uri);
            }
            path[o++] = (char)(h * 16 + l);
            i += 2;
        } else {
            path[o++] = uri[i];
        }
    }
    path[o] = '\0';
    *out = path;
    return RT_OK;
}

/* The decoded string of token t in a fresh buffer. */
static rt_result token_string(gl_doc *d, int t, const char *what, char **out)
{
    size_t cap = (size_t)(d->j.tok[t].end - d->j.tok[t].start) * 4 + 1; /* \uXXXX never grows */
    char *s = malloc(cap);
    if (!s)
        return fail_at(d, t, RT_ERR_NOMEM, "%s: out of memory", what);
    if (rt_json_string(&d->j, t, s, cap) < 0) {
        free(s);
        return fail_at(d, t, RT_ERR_INVALID, "%s: bad string", what);
    }
    *out = s;
    return RT_OK;
}

static rt_result load_buffers(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->buffer_count; i++) {
        gl_buffer *b = &d->buffers[i];
        char what[48];
        snprintf(what, sizeof what, "buffers[%zu]", i);
        size_t have = 0;
        if (b->uri < 0 && b->fallback && !(d->glb && i == 0 && d->bin)) {
            continue; /* no data: only compressed views refer to it (validate_meshopt_view) */
        } else if (b->uri < 0) {
            if (!d->glb || i != 0 || !d->bin)
                return fail_at(d, b->tok, RT_ERR_INVALID, "%s has no uri and there is no GLB BIN chunk", what);
            b->data = d->bin;
            have = d->bin_size;
        } else {
            char *uri;
            if ((r = token_string(d, b->uri, what, &uri)) != RT_OK)
                return r;
            if (strncmp(uri, "data:", 5) == 0) {
                r = decode_data_uri(d, b->uri, uri, strlen(uri), what, &b->owned, &have);
            } else {
                char *path = NULL;
                r = uri_to_path(d, b->uri, uri, what, &path);
                if (r == RT_OK) {
                    char w2[64];
                    snprintf(w2, sizeof w2, "%s: ", what);
                    r = read_file(d, path, w2, &b->owned, &have);
                }
                free(path);
            }
            free(uri);
            if ((r = r) != RT_OK)
                return r;
            b->data = b->owned;
        }
        if (have < b->byte_length)
            return fail_at(d, b->tok, RT_ERR_INVALID, "%s: byteLength is %zu but only %zu bytes of data exist", what,
                           b->byte_length, have);
    }
    return RT_OK;
}

/* ---------------------------------------------------------- accessors */

static inline float comp_float(const uint8_t *p, int ct, bool norm)
{
    switch (ct) {
    case GL_FLOAT: { float f; memcpy(&f, p, 4); return f; }
    case GL_BYTE: { float v = (float)(int8_t)p[0]; return norm ? fmaxf(v / 127.0f, -1.0f) : v; }
    case GL_UNSIGNED_BYTE: return norm ? p[0] / 255.0f : (float)p[0];
    case GL_SHORT: { int16_t v; memcpy(&v, p, 2); return norm ? fmaxf(v / 32767.0f, -1.0f) : (float)v; }
    case GL_UNSIGNED_SHORT: { uint16_t v; memcpy(&v, p, 2); return norm ? v / 65535.0f : (float)v; }
    case GL_UNSIGNED_INT: { uint32_t v; memcpy(&v, p, 4); return (float)v; }
    }
    return 0.0f;
}

static inline uint32_t comp_uint(const uint8_t *p, int ct)
{
    switch (ct) {
    case GL_UNSIGNED_BYTE: return p[0];
    case GL_UNSIGNED_SHORT: { uint16_t v; memcpy(&v, p, 2); return v; }
    case GL_UNSIGNED_INT: { uint32_t v; memcpy(&v, p, 4); return v; }
    }
    return 0;
}

static const uint8_t *view_ptr(const gl_doc *d, uint32_t view, size_t offset)
{
    const gl_view *v = &d->views[view];
    if (v->decoded)
        return v->decoded + offset;
    return d->buffers[v->buffer].data + v->offset + offset;
}

/* Reads the sparse index k, checking order and range. */
static rt_result sparse_index(gl_doc *d, uint32_t ai, size_t k, size_t *prev, size_t *out)
{
    const gl_accessor *a = &d->accessors[ai];
    size_t cs = comp_size(a->sp_idx_ctype);
    size_t idx = comp_uint(view_ptr(d, a->sp_idx_view, a->sp_idx_offset) + k * cs, a->sp_idx_ctype);
    if (idx >= a->count || (k > 0 && idx <= *prev))
        return fail_at(d, a->tok, RT_ERR_INVALID,
                       "accessors[%u].sparse.indices: element %zu is %zu (must increase and be below %zu)", ai, k,
                       idx, a->count);
    *prev = idx;
    *out = idx;
    return RT_OK;
}

/* Decodes accessor ai into out (count * ncomp floats), sparse applied. */
static rt_result read_floats(gl_doc *d, uint32_t ai, float *out)
{
    rt_result r;
    const gl_accessor *a = &d->accessors[ai];
    size_t n = (size_t)a->ncomp, cs = comp_size(a->ctype), es = elem_size(a);
    if (a->view == RT_NONE) {
        memset(out, 0, a->count * n * sizeof *out);
    } else {
        size_t stride = d->views[a->view].stride ? d->views[a->view].stride : es;
        const uint8_t *p = view_ptr(d, a->view, a->offset);
        if (a->ctype == GL_FLOAT) {
            if (stride == es)
                memcpy(out, p, a->count * es);
            else
                for (size_t i = 0; i < a->count; i++)
                    memcpy(out + i * n, p + i * stride, es);
        } else {
            for (size_t i = 0; i < a->count; i++)
                for (size_t c = 0; c < n; c++)
                    out[i * n + c] = comp_float(p + i * stride + c * cs, a->ctype, a->normalized);
        }
    }
    if (a->sparse_count) {
        const uint8_t *vals = view_ptr(d, a->sp_val_view, a->sp_val_offset);
        size_t prev = 0, idx;
        for (size_t k = 0; k < a->sparse_count; k++) {
            if ((r = sparse_index(d, ai, k, &prev, &idx)) != RT_OK)
                return r;
            for (size_t c = 0; c < n; c++)
                out[idx * n + c] = comp_float(vals + k * es + c * cs, a->ctype, a->normalized);
        }
    }
    return RT_OK;
}

/* Decodes an index accessor into out (count values), sparse applied. */
static rt_result read_uints(gl_doc *d, uint32_t ai, uint32_t *out)
{
    rt_result r;
    const gl_accessor *a = &d->accessors[ai];
    size_t cs = comp_size(a->ctype);
    if (a->view == RT_NONE) {
        memset(out, 0, a->count * sizeof *out);
    } else {
        size_t stride = d->views[a->view].stride ? d->views[a->view].stride : cs;
        const uint8_t *p = view_ptr(d, a->view, a->offset);
        switch (a->ctype) {
        case GL_UNSIGNED_BYTE:
            for (size_t i = 0; i < a->count; i++) out[i] = p[i * stride];
            break;
        case GL_UNSIGNED_SHORT:
            for (size_t i = 0; i < a->count; i++) { uint16_t v; memcpy(&v, p + i * stride, 2); out[i] = v; }
            break;
        default:
            if (stride == 4)
                memcpy(out, p, a->count * 4);
            else
                for (size_t i = 0; i < a->count; i++) memcpy(&out[i], p + i * stride, 4);
        }
    }
    if (a->sparse_count) {
        const uint8_t *vals = view_ptr(d, a->sp_val_view, a->sp_val_offset);
        size_t prev = 0, idx;
        for (size_t k = 0; k < a->sparse_count; k++) {
            if ((r = sparse_index(d, ai, k, &prev, &idx)) != RT_OK)
                return r;
            out[idx] = comp_uint(vals + k * cs, a->ctype);
        }
    }
    return RT_OK;
}

/* ------------------------------------------------ compressed geometry */

/* Counts bytes about to be decoded against the per-load limit. */
static rt_result decoded_budget(gl_doc *d, int tok, size_t bytes)
{
    if (bytes > GL_MAX_DECODED - d->decoded_bytes)
        return fail_at(d, tok, RT_ERR_LIMIT, "decompressed data would pass the limit of %zu bytes per file",
                       GL_MAX_DECODED);
    d->decoded_bytes += bytes;
    return RT_OK;
}

/* EXT_meshopt_compression: every compressed view decoded into its own
 * bytes, which view_ptr then reads in place of the (fallback) buffer. */
static rt_result decode_meshopt_views(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->view_count; i++) {
        gl_view *v = &d->views[i];
        if (!v->meshopt)
            continue;
        if ((r = decoded_budget(d, v->mo_tok, v->length)) != RT_OK)
            return r;
        v->decoded = malloc(v->length);
        if (!v->decoded)
            return fail_at(d, v->mo_tok, RT_ERR_NOMEM, "out of memory for %zu decompressed bytes", v->length);
        const gl_buffer *src = &d->buffers[v->mo_buffer];
        const char *why = rt_meshopt_decode(v->decoded, v->mo_count, v->mo_stride, src->data + v->mo_offset,
                                            v->mo_length, (rt_meshopt_mode)v->mo_mode,
                                            (rt_meshopt_filter)v->mo_filter);
        if (why)
            return fail_at(d, v->mo_tok, RT_ERR_INVALID, "bufferViews[%zu]: EXT_meshopt_compression: %s", i, why);
    }
    return RT_OK;
}

/* Points accessor a at decoded bytes (owned by a new view), as plain
 * unsigned ints or floats. An accessor fills once: two Draco primitives
 * sharing one would each claim it. */
static rt_result fill_accessor(gl_doc *d, uint32_t ai, int tok, void *bytes, size_t length, int ctype)
{
    gl_accessor *a = &d->accessors[ai];
    if (!a->draco) {
        free(bytes);
        return fail_at(d, tok, RT_ERR_UNSUPPORTED, "accessors[%u] is filled by two KHR_draco_mesh_compression "
                       "primitives", ai);
    }
    gl_view *views = realloc(d->views, (d->view_count + 1) * sizeof *views);
    if (!views) {
        free(bytes);
        return fail_at(d, tok, RT_ERR_NOMEM, "out of memory");
    }
    d->views = views;
    gl_view *v = &d->views[d->view_count];
    memset(v, 0, sizeof *v);
    v->buffer = RT_NONE;
    v->length = length;
    v->decoded = bytes;
    v->tok = tok;
    a->view = (uint32_t)d->view_count++;
    a->offset = 0;
    a->ctype = ctype;
    a->normalized = false;
    a->sparse_count = 0;
    a->draco = false;
    return RT_OK;
}

/* One KHR_draco_mesh_compression primitive's indices and attributes from
 * its decoded mesh, checked against the counts its accessors declare. */
static rt_result fill_from_draco(gl_doc *d, size_t p, const rt_draco_mesh *m)
{
    rt_result r;
    const gl_prim *pr = &d->prims[p];
    int tok = pr->draco_tok;
    char name[64];
    size_t faces = rt_draco_faces(m), points = rt_draco_points(m);
    size_t nidx = d->accessors[pr->indices].count;
    if (faces > SIZE_MAX / 3 || faces * 3 != nidx)
        return fail_at(d, tok, RT_ERR_INVALID,
                       "%s: the Draco mesh has %zu triangles, the indices accessor %u has %zu indices",
                       prim_name(d, p, name, sizeof name), faces, pr->indices, nidx);
    if ((r = decoded_budget(d, tok, nidx * sizeof(uint32_t))) != RT_OK)
        return r;
    uint32_t *idx = malloc((nidx ? nidx : 1) * sizeof *idx);
    if (!idx)
        return fail_at(d, tok, RT_ERR_NOMEM, "out of memory for %zu indices", nidx);
    rt_draco_indices(m, idx);
    for (size_t k = 0; k < nidx; k++)
        if (idx[k] >= points) {
            uint32_t bad = idx[k];
            free(idx);
            return fail_at(d, tok, RT_ERR_INVALID, "%s: a Draco triangle names point %u of %zu",
                           prim_name(d, p, name, sizeof name), bad, points);
        }
    if ((r = fill_accessor(d, pr->indices, tok, idx, nidx * sizeof *idx, GL_UNSIGNED_INT)) != RT_OK)
        return r;
    for (int k = 0; k < ATTR_COUNT; k++) {
        if (pr->draco_id[k] == RT_NONE)
            continue;
        uint32_t ai = pr->attr[k];
        const gl_accessor *a = &d->accessors[ai];
        if (points != a->count)
            return fail_at(d, tok, RT_ERR_INVALID, "%s: the Draco mesh has %zu points, accessor %u (%s) "
                           "has %zu", prim_name(d, p, name, sizeof name), points, ai, attr_names[k], a->count);
        int have = rt_draco_components(m, pr->draco_id[k]);
        if (have == 0)
            return fail_at(d, tok, RT_ERR_INVALID, "%s: %s is attribute %u, which the Draco mesh does "
                           "not have", prim_name(d, p, name, sizeof name), attr_names[k], pr->draco_id[k]);
        size_t n = points * (size_t)a->ncomp;
        if ((r = decoded_budget(d, tok, n * sizeof(float))) != RT_OK)
            return r;
        float *vals = malloc((n ? n : 1) * sizeof *vals);
        if (!vals)
            return fail_at(d, tok, RT_ERR_NOMEM, "out of memory for %zu values", n);
        if (!rt_draco_attribute(m, pr->draco_id[k], a->ncomp, vals)) {
            free(vals);
            return fail_at(d, tok, RT_ERR_INVALID, "%s: Draco attribute %u (%s) cannot be read as "
                           "%d floats", prim_name(d, p, name, sizeof name), pr->draco_id[k], attr_names[k], a->ncomp);
        }
        if ((r = fill_accessor(d, ai, tok, vals, n * sizeof *vals, GL_FLOAT)) != RT_OK)
            return r;
    }
    return RT_OK;
}

static rt_result decode_draco_prims(gl_doc *d)
{
    for (size_t p = 0; p < d->prim_count; p++) {
        const gl_prim *pr = &d->prims[p];
        if (pr->draco_view == RT_NONE)
            continue;
        char why[200], name[64];
        rt_draco_mesh *m = rt_draco_decode(view_ptr(d, pr->draco_view, 0), d->views[pr->draco_view].length, why,
                                           sizeof why);
        if (!m)
            return fail_at(d, pr->draco_tok, RT_ERR_INVALID, "%s: KHR_draco_mesh_compression: %s",
                           prim_name(d, p, name, sizeof name), why);
        rt_result r = fill_from_draco(d, p, m);
        rt_draco_free(m);
        if ((r = r) != RT_OK)
            return r;
    }
    return RT_OK;
}

static rt_result scratch(gl_doc *d, int slot, size_t floats, float **out)
{
    if (!rt_grow((void **)&d->scratch[slot], &d->scratch_cap[slot], floats ? floats : 1, sizeof(float)))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu vertex values", d->path, floats);
    *out = d->scratch[slot];
    return RT_OK;
}

/* ------------------------------------------------------------ flatten */

static bool is_triangles(int mode) { return mode == 4 || mode == 5 || mode == 6; }

static size_t prim_triangles(const gl_doc *d, const gl_prim *p)
{
    size_t n = p->indices != RT_NONE ? d->accessors[p->indices].count : d->accessors[p->attr[ATTR_POSITION]].count;
    if (p->mode == 4)
        return n / 3;
    return n >= 3 ? n - 2 : 0;
}

/* ------------------------------------------------------------- posing */

/* Accessor ai as floats in a fresh buffer (the caller frees it), checked:
 * ncomp components per element, `count` elements (SIZE_MAX: any), finite. */
static rt_result posing_floats(gl_doc *d, uint32_t ai, int ncomp, size_t count, const char *what, float **out)
{
    *out = NULL;
    if (ai >= d->accessor_count)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: %s: accessor %u is out of range (the file has %zu)", d->path, what,
                       ai, d->accessor_count);
    const gl_accessor *a = &d->accessors[ai];
    if (a->ncomp != ncomp)
        return fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%u] (%s): expected %d components per element, not %d",
                       ai, what, ncomp, a->ncomp);
    if (count != SIZE_MAX && a->count != count)
        return fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%u] (%s): has %zu elements, expected %zu", ai, what,
                       a->count, count);
    float *f = rt_alloc(a->count * (size_t)ncomp, sizeof(float));
    if (!f)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %s", d->path, what);
    rt_result r = read_floats(d, ai, f);
    if (r != RT_OK) {
        free(f);
        return r;
    }
    for (size_t i = 0; i < a->count * (size_t)ncomp; i++)
        if (!isfinite(f[i])) {
            free(f);
            return fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%u] (%s): element %zu is not finite", ai, what,
                           i / (size_t)ncomp);
        }
    *out = f;
    return RT_OK;
}

/* Morph target count of a node's mesh (that of its first primitive; the
 * spec requires all primitives of a mesh to have the same). */
static uint32_t node_targets(const gl_doc *d, uint32_t node)
{
    const gl_node *n = &d->nodes[node];
    return n->mesh == RT_NONE ? 0 : d->prims[d->meshes[n->mesh].first].target_count;
}

/* One channel of the chosen animation applied to its node at time t. */
static rt_result pose_channel(gl_doc *d, uint32_t anim, uint32_t c, float t)
{
    rt_result r;
    const gl_anim *an = &d->anims[anim];
    const gl_channel *ch = &d->channels[an->first_channel + c];
    if (ch->path < 0 || ch->node == RT_NONE)
        return RT_OK; /* a path rt does not animate, or no target node */
    char what[96];
    snprintf(what, sizeof what, "animations[%u].channels[%u]", anim, c);
    if (ch->node >= d->node_count)
        return fail_at(d, ch->tok, RT_ERR_INVALID, "%s: target node %u is out of range (the file has %zu nodes)",
                       what, ch->node, d->node_count);
    gl_node *n = &d->nodes[ch->node];
    if (n->has_matrix && ch->path != PATH_WEIGHTS)
        return fail_at(d, ch->tok, RT_ERR_INVALID, "%s: node %u has a matrix, which animations cannot target",
                       what, ch->node);
    const gl_asampler *sa = &d->asamplers[an->first_sampler + ch->sampler];
    int ncomp = ch->path == PATH_ROTATION ? 4 : ch->path == PATH_WEIGHTS ? (int)node_targets(d, ch->node) : 3;
    if (ncomp == 0)
        return fail_at(d, ch->tok, RT_ERR_INVALID, "%s: animates the weights of node %u, whose mesh has no morph "
                       "targets", what, ch->node);
    if (ncomp > 64)
        return fail_at(d, ch->tok, RT_ERR_LIMIT, "%s: over 64 morph targets", what);
    char w_in[128], w_out[128];
    snprintf(w_in, sizeof w_in, "input of %s", what);
    snprintf(w_out, sizeof w_out, "output of %s", what);
    float *times = NULL, *values = NULL;
    if ((r = posing_floats(d, sa->input, 1, SIZE_MAX, w_in, &times)) != RT_OK)
        return r;
    size_t keys = d->accessors[sa->input].count;
    for (size_t k = 1; k < keys; k++)
        if (!(times[k] > times[k - 1])) {
            double now = times[k], before = times[k - 1];
            free(times);
            return fail_at(d, d->accessors[sa->input].tok, RT_ERR_INVALID,
                           "accessors[%u] (%s): key times must increase, element %zu is %g after %g", sa->input, w_in,
                           k, now, before);
        }
    size_t per = sa->interp == RT_INTERP_CUBICSPLINE ? 3 : 1;
    r = ch->path == PATH_WEIGHTS ? posing_floats(d, sa->output, 1, keys * per * (size_t)ncomp, w_out, &values)
                                 : posing_floats(d, sa->output, ncomp, keys * per, w_out, &values);
    if (r != RT_OK) {
        free(times);
        return r;
    }
    float out[64];
    rt_anim_sample((rt_interp)sa->interp, times, keys, values, ncomp, ch->path == PATH_ROTATION, t, out);
    free(times);
    free(values);
    switch (ch->path) {
    case PATH_TRANSLATION: memcpy(n->tr, out, sizeof n->tr); break;
    case PATH_ROTATION: memcpy(n->rot, out, sizeof n->rot); break;
    case PATH_SCALE: memcpy(n->sc, out, sizeof n->sc); break;
    default:
        free(n->pose_weights);
        n->pose_weights = malloc((size_t)ncomp * sizeof(float));
        if (!n->pose_weights)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
        memcpy(n->pose_weights, out, (size_t)ncomp * sizeof(float));
        n->pose_weight_count = (uint32_t)ncomp;
    }
    if (ch->path != PATH_WEIGHTS)
        n->local = rt_mat4_mul(rt_mat4_translate(rt_v3(n->tr[0], n->tr[1], n->tr[2])),
                               rt_mat4_mul(rt_mat4_quat(rt_v4(n->rot[0], n->rot[1], n->rot[2], n->rot[3])),
                                           rt_mat4_scale(rt_v3(n->sc[0], n->sc[1], n->sc[2]))));
    return RT_OK;
}

static rt_result pose_named(gl_doc *d, const rt_gltf_options *opt);
static rt_result pose_animation(gl_doc *d, uint32_t a, float time);

/* rt_gltf_options.use_time: the chosen animation's channels at the time,
 * before the world matrices are made. */
static rt_result pose_nodes(gl_doc *d, const rt_gltf_options *opt)
{
    d->posed = true;
    if (opt->animation_name)
        return pose_named(d, opt);
    if (d->anim_count == 0) {
        if (opt->animation > 0 && !opt->animation_optional)
            return rt_fail(d->err, RT_ERR_INVALID, "%s: animation %d requested, the file has none", d->path,
                           opt->animation);
        return RT_OK; /* skins and morph weights still pose the meshes */
    }
    if (opt->animation < 0 || (size_t)opt->animation >= d->anim_count)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: animation %d requested, the file has %zu (0 to %zu)", d->path,
                       opt->animation, d->anim_count, d->anim_count - 1);
    return pose_animation(d, (uint32_t)opt->animation, opt->time);
}

/* The animation named opt->animation_name (the first of that name); an
 * unknown name is an error listing the file's names. */
static rt_result pose_named(gl_doc *d, const rt_gltf_options *opt)
{
    char names[512] = "", name[128];
    for (uint32_t a = 0; a < d->anim_count; a++) {
        int t = rt_json_get(&d->j, d->anims[a].tok, "name");
        if (t < 0 || rt_json_string(&d->j, t, name, sizeof name) < 0)
            snprintf(name, sizeof name, "(%u, unnamed)", a);
        else if (strcmp(name, opt->animation_name) == 0)
            return pose_animation(d, a, opt->time);
        size_t n = strlen(names);
        if (n + strlen(name) + 8 < sizeof names)
            snprintf(names + n, sizeof names - n, "%s'%s'", n ? ", " : "", name);
        else if (n + 5 < sizeof names && !strstr(names, "..."))
            snprintf(names + n, sizeof names - n, ", ...");
    }
    if (d->anim_count == 0)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: animation '%s' requested, the file has none", d->path,
                       opt->animation_name);
    return rt_fail(d->err, RT_ERR_INVALID, "%s: no animation named '%s' (the file has %s)", d->path,
                   opt->animation_name, names);
}

/* Every channel of animation a at time t. */
static rt_result pose_animation(gl_doc *d, uint32_t a, float time)
{
    rt_result r;
    d->animated = d->anims[a].channel_count > 0;
    for (uint32_t c = 0; c < d->anims[a].channel_count; c++)
        if ((r = pose_channel(d, a, c, time)) != RT_OK)
            return r;
    return RT_OK;
}

/* The nodes of the chosen scene in depth-first order with world matrices. */
static rt_result collect_visits(gl_doc *d, const rt_gltf_options *opt)
{
    uint32_t scene = d->default_scene;
    if (opt && opt->use_scene_index) {
        if (opt->scene_index < 0 || (size_t)opt->scene_index >= d->scene_count)
            return rt_fail(d->err, RT_ERR_INVALID, "%s: scene %d requested, the file has %zu scenes", d->path,
                           opt->scene_index, d->scene_count);
        scene = (uint32_t)opt->scene_index;
    } else if (scene == RT_NONE && d->scene_count > 0) {
        scene = 0;
    }
    /* roots: the scene's nodes, or every parentless node when there is no scene */
    size_t root_count = 0;
    uint32_t *roots = rt_alloc(d->node_count, sizeof(uint32_t));
    uint32_t *stack = rt_alloc(d->node_count, sizeof(uint32_t));
    d->visits = rt_alloc(d->node_count, sizeof(gl_visit));
    d->visit_of = rt_alloc(d->node_count, sizeof(uint32_t));
    if (!roots || !stack || !d->visits || !d->visit_of) {
        free(roots);
        free(stack);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu nodes", d->path, d->node_count);
    }
    if (scene != RT_NONE) {
        for (uint32_t k = 0; k < d->scenes[scene].count; k++)
            roots[root_count++] = d->scene_nodes[d->scenes[scene].first + k];
    } else {
        for (size_t i = 0; i < d->node_count; i++)
            if (d->nodes[i].parent == RT_NONE)
                roots[root_count++] = (uint32_t)i;
    }
    rt_mat4 top = opt && opt->use_transform ? opt->transform : rt_mat4_identity();
    /* Depth-first with an explicit stack; a visit's world matrix is its
     * parent's (already visited) times its local matrix. The hierarchy is a
     * forest with unique scene roots (validated), so each node is visited at
     * most once and the stack never holds more than node_count entries.
     */
    for (size_t r = 0; r < root_count; r++) {
        size_t sp = 0;
        uint32_t root = roots[r];
        stack[sp++] = root;
        while (sp > 0) {
            uint32_t n = stack[--sp];
            const gl_node *node = &d->nodes[n];
            rt_mat4 parent = n == root ? top : d->visits[d->visit_of[node->parent]].world;
            d->visit_of[n] = (uint32_t)d->visit_count;
            gl_visit *vis = &d->visits[d->visit_count++];
            vis->node = n;
            vis->world = rt_mat4_mul(parent, node->local);
            for (uint32_t c = node->child_count; c-- > 0;)
                stack[sp++] = d->children[node->first_child + c];
        }
    }
    free(roots);
    free(stack);
    return RT_OK;
}

/* The morph weights of a posed node's mesh: animated, else the node's
 * `weights`, else the mesh's, else zeros. */
static rt_result morph_weights(gl_doc *d, uint32_t node, uint32_t count, float *w)
{
    const gl_node *n = &d->nodes[node];
    memset(w, 0, count * sizeof *w);
    if (n->pose_weights) {
        memcpy(w, n->pose_weights, count * sizeof *w);
        return RT_OK;
    }
    int tok = n->weights >= 0 ? n->weights : d->meshes[n->mesh].weights;
    if (tok < 0)
        return RT_OK;
    char where[48];
    snprintf(where, sizeof where, n->weights >= 0 ? "nodes[%u]" : "meshes[%u]", n->weights >= 0 ? node : n->mesh);
    return get_floats(d, where, "weights", tok, w, (int)count);
}

/* Adds the weighted morph target displacements of one attribute (slot 0
 * POSITION, 1 NORMAL, 2 TANGENT) to f (stride floats a vertex, xyz first). */
static rt_result apply_morph(gl_doc *d, const gl_prim *p, const float *w, int slot, float *f, size_t stride,
                             size_t vcount)
{
    rt_result r;
    static const char *const names[3] = {"POSITION", "NORMAL", "TANGENT"};
    for (uint32_t k = 0; k < p->target_count; k++) {
        uint32_t ai = d->targets[p->first_target + k].attr[slot];
        if (w[k] == 0.0f || ai == RT_NONE)
            continue;
        char what[64];
        snprintf(what, sizeof what, "%s of morph target %u", names[slot], k);
        float *delta;
        if ((r = posing_floats(d, ai, 3, vcount, what, &delta)) != RT_OK)
            return r;
        for (size_t i = 0; i < vcount; i++)
            for (size_t c = 0; c < 3; c++)
                f[i * stride + c] += w[k] * delta[3 * i + c];
        free(delta);
    }
    return RT_OK;
}

/* World matrix of any node (joints need not be in the chosen scene). */
static rt_mat4 node_world(const gl_doc *d, uint32_t n, const rt_mat4 *top)
{
    rt_mat4 m = d->nodes[n].local;
    for (uint32_t p = d->nodes[n].parent; p != RT_NONE; p = d->nodes[p].parent)
        m = rt_mat4_mul(d->nodes[p].local, m);
    return rt_mat4_mul(*top, m);
}

/* Per-vertex skin matrices of a primitive of a skinned node (glTF 2.0,
 * 3.7.3 "Skins"): joint matrix j = world(joint j) * inverseBind(j); a
 * vertex's matrix is the sum over its JOINTS_n / WEIGHTS_n sets of weight x
 * joint matrix. The mesh node's own transform does not apply. A vertex whose
 * weights sum to 0 keeps the node's transform M. */
static rt_result skin_matrices(gl_doc *d, const gl_prim *p, uint32_t node, const rt_mat4 *M, const rt_mat4 *top,
                               size_t vcount, rt_mat4 **out)
{
    const gl_skin *sk = &d->skins[d->nodes[node].skin];
    char what[64];
    snprintf(what, sizeof what, "inverseBindMatrices of skins[%u]", d->nodes[node].skin);
    float *ibm = NULL;
    rt_result r;
    if (sk->ibm != RT_NONE && (r = posing_floats(d, sk->ibm, 16, SIZE_MAX, what, &ibm)) != RT_OK)
        return r;
    if (ibm && d->accessors[sk->ibm].count < sk->joint_count) {
        free(ibm);
        return fail_at(d, sk->tok, RT_ERR_INVALID, "skins[%u]: %u joints but %zu inverseBindMatrices",
                       d->nodes[node].skin, sk->joint_count, d->accessors[sk->ibm].count);
    }
    rt_mat4 *jm = rt_alloc(sk->joint_count, sizeof *jm);
    if (!jm) {
        free(ibm);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for joints", d->path);
    }
    for (uint32_t j = 0; j < sk->joint_count; j++) {
        uint32_t jn = d->skin_joints[sk->first_joint + j];
        if (jn >= d->node_count) {
            free(ibm);
            free(jm);
            return fail_at(d, sk->tok, RT_ERR_INVALID, "skins[%u].joints: node %u is out of range (the file has %zu)",
                           d->nodes[node].skin, jn, d->node_count);
        }
        jm[j] = rt_mat4_mul(node_world(d, jn, top), ibm ? mat_from_gltf(ibm + 16 * j) : rt_mat4_identity());
    }
    free(ibm);
    r = RT_OK;
    if (!rt_grow((void **)&d->skin_scratch, &d->skin_scratch_cap, vcount ? vcount : 1, sizeof(rt_mat4))) {
        free(jm);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for skinning", d->path);
    }
    rt_mat4 *vm = d->skin_scratch;
    memset(vm, 0, vcount * sizeof *vm);
    float *wsum = rt_alloc(vcount ? vcount : 1, sizeof(float));
    if (!wsum)
        r = rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for skinning", d->path);
    for (int set = 0; set < 2 && r == RT_OK; set++) {
        if (p->joints[set] == RT_NONE || p->weights[set] == RT_NONE)
            continue;
        float *js = NULL, *ws = NULL;
        snprintf(what, sizeof what, "JOINTS_%d", set);
        r = posing_floats(d, p->joints[set], 4, vcount, what, &js);
        snprintf(what, sizeof what, "WEIGHTS_%d", set);
        if (r == RT_OK)
            r = posing_floats(d, p->weights[set], 4, vcount, what, &ws);
        for (size_t i = 0; i < vcount && r == RT_OK; i++)
            for (int c = 0; c < 4; c++) {
                float w = ws[4 * i + c], jf = js[4 * i + c];
                if (w == 0.0f)
                    continue;
                if (!(jf >= 0) || jf >= (float)sk->joint_count) {
                    r = fail_at(d, d->accessors[p->joints[set]].tok, RT_ERR_INVALID,
                                "accessors[%u] (JOINTS_%d): element %zu names joint %g of %u", p->joints[set], set, i,
                                (double)jf, sk->joint_count);
                    break;
                }
                const rt_mat4 *J = &jm[(uint32_t)jf];
                for (int a = 0; a < 4; a++)
                    for (int b = 0; b < 4; b++)
                        vm[i].m[a][b] += w * J->m[a][b];
                wsum[i] += w;
            }
        free(js);
        free(ws);
    }
    for (size_t i = 0; i < vcount && r == RT_OK; i++)
        if (wsum[i] == 0.0f)
            vm[i] = *M;
    free(wsum);
    free(jm);
    *out = r == RT_OK ? vm : NULL;
    return r;
}

static rt_result emit_primitive(gl_doc *d, rt_scene *s, uint32_t node, uint32_t pi, const rt_mat4 *M,
                                const rt_mat4 *top, uint32_t material, size_t vbase)
{
    rt_result r = RT_OK;
    uint32_t mesh = d->nodes[node].mesh;
    const gl_prim *p = &d->prims[d->meshes[mesh].first + pi];
    const gl_accessor *pos = &d->accessors[p->attr[ATTR_POSITION]];
    size_t vcount = pos->count;
    rt_vertices *V = &s->vertices;
    float *f = NULL;
    /* posed: morph weights and, for a skinned node, a matrix per vertex */
    float mw[64];
    bool morph = d->posed && p->target_count > 0;
    rt_mat4 *vm = NULL;
    if (morph) {
        if (p->target_count > 64)
            return fail_at(d, p->tok, RT_ERR_LIMIT, "meshes[%u].primitives[%u]: over 64 morph targets", mesh, pi);
        if ((r = morph_weights(d, node, p->target_count, mw)) != RT_OK)
            return r;
    }
    if (d->posed && d->nodes[node].skin != RT_NONE && p->joints[0] != RT_NONE && p->weights[0] != RT_NONE)
        r = skin_matrices(d, p, node, M, top, vcount, &vm);
    if (r != RT_OK)
        return r;

    if ((r = scratch(d, ATTR_POSITION, vcount * 3, &f)) != RT_OK)
        return r;
    if ((r = read_floats(d, p->attr[ATTR_POSITION], f)) != RT_OK)
        return r;
    if (morph)
        r = apply_morph(d, p, mw, 0, f, 3, vcount);
    if (r != RT_OK)
        return r;
    for (size_t i = 0; i < vcount; i++) {
        rt_vec3 q = rt_v3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
        if (!rt_finite3(q))
            return fail_at(d, pos->tok, RT_ERR_INVALID,
                           "accessors[%u] (POSITION of meshes[%u].primitives[%u]): element %zu is not finite "
                           "(%g, %g, %g)",
                           p->attr[ATTR_POSITION], mesh, pi, i, (double)q.x, (double)q.y, (double)q.z);
        V->position[vbase + i] = rt_mat4_point(vm ? &vm[i] : M, q);
    }
    float det = rt_mat4_det3(vm && vcount ? &vm[0] : M);
    rt_mat4 N;
    bool have_n = p->attr[ATTR_NORMAL] != RT_NONE && rt_mat4_normal_matrix(M, &N);
    uint8_t flags = 0;
    if (have_n) {
        if ((r = scratch(d, ATTR_NORMAL, vcount * 3, &f)) != RT_OK)
            return r;
        if ((r = read_floats(d, p->attr[ATTR_NORMAL], f)) != RT_OK)
            return r;
        if (morph)
            r = apply_morph(d, p, mw, 1, f, 3, vcount);
        if (r != RT_OK)
            return r;
        for (size_t i = 0; i < vcount; i++) {
            rt_vec3 n = rt_v3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
            rt_mat4 Ni;
            const rt_mat4 *NM = &N;
            if (vm)
                NM = rt_mat4_normal_matrix(&vm[i], &Ni) ? &Ni : &N;
            V->normal[vbase + i] = rt_finite3(n) ? rt_normalize(rt_mat4_vector(NM, n)) : rt_v3s(0);
        }
        flags |= RT_TRI_SMOOTH;
        if (p->attr[ATTR_TANGENT] != RT_NONE) {
            if ((r = scratch(d, ATTR_TANGENT, vcount * 4, &f)) != RT_OK)
                return r;
            if ((r = read_floats(d, p->attr[ATTR_TANGENT], f)) != RT_OK)
                return r;
            if (morph)
                r = apply_morph(d, p, mw, 2, f, 4, vcount);
            if (r != RT_OK)
                return r;
            float sign = det < 0 ? -1.0f : 1.0f;
            for (size_t i = 0; i < vcount; i++) {
                rt_vec3 t = rt_mat4_vector(vm ? &vm[i] : M, rt_v3(f[4 * i], f[4 * i + 1], f[4 * i + 2]));
                t = rt_finite3(t) ? rt_normalize(t) : rt_v3s(0);
                float w = f[4 * i + 3] < 0 ? -sign : sign;
                V->tangent[vbase + i] = rt_v4(t.x, t.y, t.z, w);
            }
            flags |= RT_TRI_TANGENT;
        }
    }
    for (int k = ATTR_TEXCOORD_0; k <= ATTR_TEXCOORD_1; k++) {
        if (p->attr[k] == RT_NONE)
            continue;
        if ((r = scratch(d, k, vcount * 2, &f)) != RT_OK)
            return r;
        if ((r = read_floats(d, p->attr[k], f)) != RT_OK)
            return r;
        rt_vec2 *uv = k == ATTR_TEXCOORD_0 ? V->uv0 : V->uv1;
        for (size_t i = 0; i < vcount; i++)
            uv[vbase + i] = rt_v2(f[2 * i], f[2 * i + 1]);
        if (k == ATTR_TEXCOORD_0)
            flags |= RT_TRI_UV;
    }
    if (p->attr[ATTR_COLOR_0] != RT_NONE) {
        const gl_accessor *ca = &d->accessors[p->attr[ATTR_COLOR_0]];
        size_t nc = (size_t)ca->ncomp;
        if ((r = scratch(d, ATTR_COLOR_0, vcount * nc, &f)) != RT_OK)
            return r;
        if ((r = read_floats(d, p->attr[ATTR_COLOR_0], f)) != RT_OK)
            return r;
        for (size_t i = 0; i < vcount; i++)
            V->color[vbase + i] = rt_v4(f[nc * i], f[nc * i + 1], f[nc * i + 2], nc == 4 ? f[nc * i + 3] : 1.0f);
        flags |= RT_TRI_COLOR;
    }

    /* triangles */
    size_t icount = vcount;
    const uint32_t *idx = NULL;
    if (p->indices != RT_NONE) {
        icount = d->accessors[p->indices].count;
        if (!rt_grow((void **)&d->idx_scratch, &d->idx_cap, icount, sizeof(uint32_t)))
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu indices", d->path, icount);
        if ((r = read_uints(d, p->indices, d->idx_scratch)) != RT_OK)
            return r;
        idx = d->idx_scratch;
        for (size_t i = 0; i < icount; i++)
            if (idx[i] >= vcount)
                return fail_at(d, d->accessors[p->indices].tok, RT_ERR_INVALID,
                               "accessors[%u] (indices of meshes[%u].primitives[%u]): element %zu is %u, past the "
                               "vertex count %zu",
                               p->indices, mesh, pi, i, idx[i], vcount);
    }
    size_t ntri = prim_triangles(d, p);
    if (p->mode == 4 && icount % 3)
        rt_warn("%s: meshes[%u].primitives[%u]: %zu indices are not a multiple of 3; the last %zu are ignored",
                d->path, mesh, pi, icount, icount % 3);
    rt_triangles *T = &s->triangles;
    bool flip = det < 0;
    for (size_t t = 0; t < ntri; t++) {
        size_t a, b, c;
        if (p->mode == 4) { a = 3 * t; b = 3 * t + 1; c = 3 * t + 2; }
        else if (p->mode == 5) { a = t; b = t + 1 + (t % 2); c = t + 2 - (t % 2); }
        else { a = t + 1; b = t + 2; c = 0; }
        uint32_t va = (uint32_t)vbase + (idx ? idx[a] : (uint32_t)a);
        uint32_t vb = (uint32_t)vbase + (idx ? idx[b] : (uint32_t)b);
        uint32_t vc = (uint32_t)vbase + (idx ? idx[c] : (uint32_t)c);
        size_t o = T->count++;
        T->index[3 * o] = va;
        T->index[3 * o + 1] = flip ? vc : vb;
        T->index[3 * o + 2] = flip ? vb : vc;
        T->material[o] = material;
        T->flags[o] = flags;
    }
    return RT_OK;
}

/* Image ii into the scene. An external file that does not exist is a
 * warning naming the image's JSON path, and *missing (then *out is
 * RT_NONE); any other failure is an error. */
static rt_result load_image(gl_doc *d, rt_scene *s, uint32_t ii, uint32_t *out, bool *missing)
{
    *missing = false;
    if (d->image_map[ii] != RT_NONE) {
        *out = d->image_map[ii];
        return RT_OK;
    }
    const gl_image *im = &d->images[ii];
    char what[48];
    snprintf(what, sizeof what, "images[%u]", ii);
    rt_error inner = {0};
    rt_result r = RT_OK;
    uint32_t img = RT_NONE;
    char label[300];
    if (im->view != RT_NONE) {
        const gl_view *v = &d->views[im->view];
        snprintf(label, sizeof label, "bufferView %u", im->view);
        char name[300];
        snprintf(name, sizeof name, "%.250s#image%u", d->path, ii);
        r = rt_image_load_memory(s, view_ptr(d, im->view, 0), v->length, name, &img, &inner);
    } else {
        char *uri;
        if ((r = token_string(d, im->uri, what, &uri)) != RT_OK)
            return r;
        snprintf(label, sizeof label, "\"%.200s%s\"", uri, strlen(uri) > 200 ? "..." : "");
        if (strncmp(uri, "data:", 5) == 0) {
            uint8_t *bytes = NULL;
            size_t n = 0;
            snprintf(label, sizeof label, "data: URI");
            r = decode_data_uri(d, im->uri, uri, strlen(uri), what, &bytes, &n);
            if (r == RT_OK) {
                char name[300];
                snprintf(name, sizeof name, "%.250s#image%u", d->path, ii);
                r = rt_image_load_memory(s, bytes, n, name, &img, &inner);
            } else {
                inner = *d->err;
            }
            free(bytes);
        } else {
            char *path = NULL;
            r = uri_to_path(d, im->uri, uri, what, &path);
            if (r == RT_OK)
                r = rt_image_load_file(s, path, &img, &inner);
            else
                inner = *d->err;
            if (r != RT_OK && path && rt_image_file_missing(path)) {
                rt_warn("%s: %s (%s): image '%s' not found; %s", d->path, what, label, path,
                        RT_MISSING_TEXTURE_NOTE);
                *missing = true;
                *out = RT_NONE;
                r = RT_OK;
            }
            free(path);
            if (*missing) {
                free(uri);
                return RT_OK;
            }
        }
        free(uri);
    }
    if (r != RT_OK) {
        if (strncmp(inner.message, d->path, strlen(d->path)) == 0)
            return rt_fail(d->err, r, "%s", inner.message); /* already names the file and the image */
        return fail_at(d, im->tok, r, "%s (%s): %s", what, label, inner.message);
    }
    d->image_map[ii] = img;
    *out = img;
    return RT_OK;
}

static rt_result load_textures(gl_doc *d, rt_scene *s, rt_gltf_stats *st)
{
    rt_result r;
    d->image_map = rt_alloc(d->image_count, sizeof(uint32_t));
    d->texture_map = rt_alloc(d->texture_count, sizeof(uint32_t));
    d->texture_missing = rt_alloc(d->texture_count, sizeof(bool));
    if (!d->image_map || !d->texture_map || !d->texture_missing)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    for (size_t i = 0; i < d->image_count; i++)
        d->image_map[i] = RT_NONE;
    for (size_t i = 0; i < d->texture_count; i++) {
        const gl_texture *gt = &d->textures[i];
        d->texture_map[i] = RT_NONE;
        d->texture_missing[i] = false;
        if (gt->source == RT_NONE) {
            rt_warn("%s: textures[%zu] has no source rt can read%s; left untextured", d->path, i,
                    gt->other_source ? " (KHR_texture_basisu / KTX2 and DDS images are not supported)" : "");
            continue;
        }
        bool fresh = d->image_map[gt->source] == RT_NONE, missing;
        uint32_t img = RT_NONE;
        if ((r = load_image(d, s, gt->source, &img, &missing)) != RT_OK)
            return r;
        if (fresh && !missing)
            st->images++;
        d->texture_missing[i] = missing;
        rt_texture tex = missing ? rt_texture_missing() : rt_texture_image(img);
        if (gt->sampler != RT_NONE) {
            const gl_sampler *sm = &d->samplers[gt->sampler];
            int w[2] = {sm->wrap_s, sm->wrap_t};
            rt_wrap wrap[2];
            for (int k = 0; k < 2; k++)
                wrap[k] = w[k] == 33071 ? RT_WRAP_CLAMP : w[k] == 33648 ? RT_WRAP_MIRROR : RT_WRAP_REPEAT;
            tex.wrap_s = wrap[0];
            tex.wrap_t = wrap[1];
            tex.filter = sm->mag == 9728 ? RT_FILTER_NEAREST : RT_FILTER_BILINEAR;
        }
        uint32_t ti = rt_scene_add_texture(s, &tex);
        if (ti == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding textures", d->path);
        d->texture_map[i] = ti;
        st->textures++;
    }
    return RT_OK;
}

static rt_result flatten(gl_doc *d, rt_scene *s, const rt_gltf_options *opt, rt_gltf_stats *st)
{
    rt_result r = RT_OK;
    if (opt && opt->use_time)
        r = pose_nodes(d, opt);
    if (r != RT_OK)
        return r;
    st->animated = d->animated;
    if ((r = collect_visits(d, opt)) != RT_OK)
        return r;
    rt_mat4 top = opt && opt->use_transform ? opt->transform : rt_mat4_identity();
    st->nodes = d->visit_count;

    /* Count what the scene will hold, then reserve it all at once. */
    size_t verts = 0, tris = 0, zeros = 0;
    unsigned attrs = 0;
    bool need_default = false, warned_modes = false, warned_skin = false, warned_pos = false;
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        if (n->skin != RT_NONE && !warned_skin && !d->posed) {
            rt_warn("%s: skins and morph targets are not applied; meshes are loaded in their rest pose "
                        "(pose them at a time: --frame-time)", d->path);
            warned_skin = true;
        }
        if (n->mesh == RT_NONE)
            continue;
        const gl_mesh *m = &d->meshes[n->mesh];
        for (uint32_t k = 0; k < m->count; k++) {
            const gl_prim *p = &d->prims[m->first + k];
            if (p->targets && !warned_skin && !d->posed) {
                rt_warn("%s: skins and morph targets are not applied; meshes are loaded in their rest pose "
                        "(pose them at a time: --frame-time)", d->path);
                warned_skin = true;
            }
            if (!is_triangles(p->mode)) {
                if (!warned_modes)
                    rt_warn("%s: points and lines primitives (modes 0-3) are skipped", d->path);
                warned_modes = true;
                continue;
            }
            if (p->attr[ATTR_POSITION] == RT_NONE) {
                if (!warned_pos)
                    rt_warn("%s: primitives without POSITION are skipped", d->path);
                warned_pos = true;
                continue;
            }
            const gl_accessor *pa = &d->accessors[p->attr[ATTR_POSITION]];
            verts += pa->count;
            if (pa->view == RT_NONE && (zeros += pa->count) > GL_MAX_ZEROS)
                return rt_fail(d->err, RT_ERR_LIMIT,
                               "%s: over %zu vertices come from accessors without a bufferView (instancing "
                               "included); over the loader's limit",
                               d->path, GL_MAX_ZEROS);
            tris += prim_triangles(d, p);
            if (verts > GL_MAX_VERTICES || tris > GL_MAX_TRIANGLES)
                return rt_fail(d->err, RT_ERR_LIMIT,
                               "%s: the scene has over %zu vertices or triangles (instancing included); over the "
                               "loader's limit",
                               d->path, GL_MAX_VERTICES);
            if (p->material == RT_NONE)
                need_default = true;
            if (p->attr[ATTR_TEXCOORD_1] != RT_NONE) attrs |= RT_ATTR_UV1;
            if (p->attr[ATTR_TANGENT] != RT_NONE && p->attr[ATTR_NORMAL] != RT_NONE) attrs |= RT_ATTR_TANGENT;
            if (p->attr[ATTR_COLOR_0] != RT_NONE) attrs |= RT_ATTR_COLOR;
            st->primitives++;
        }
        st->meshes++;
    }
    if (s->vertices.count + verts >= RT_NONE || s->triangles.count + tris >= RT_NONE)
        return rt_fail(d->err, RT_ERR_LIMIT, "%s: the scene would exceed 2^32 vertices or triangles", d->path);

    if ((r = load_textures(d, s, st)) != RT_OK)
        return r;

    /* materials: one per glTF material (+ a default for primitives without one) */
    uint32_t mat_base = (uint32_t)s->material_count;
    for (size_t i = 0; i < d->material_count; i++) {
        rt_material m = d->materials[i].m;
        rt_texture_slot *slots[] = {&m.base_color_tex, &m.metal_rough_tex, &m.normal_tex,
                                    &m.occlusion_tex,  &m.emissive_tex,    &m.transmission_tex};
        for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++) {
            if (slots[k]->texture == RT_NONE)
                continue;
            /* a missing image: the checker for colour (base colour, emission), nothing for data */
            bool colour = slots[k] == &m.base_color_tex || slots[k] == &m.emissive_tex;
            uint32_t t = slots[k]->texture;
            slots[k]->texture = d->texture_missing[t] && !colour ? RT_NONE : d->texture_map[t];
        }
        for (int k = 0; k < RT_XTEX_COUNT; k++) { /* the extensions' maps: left out when missing */
            uint32_t t = m.ext_tex[k].texture;
            if (t != RT_NONE)
                m.ext_tex[k].texture = d->texture_missing[t] ? RT_NONE : d->texture_map[t];
        }
        if (rt_scene_add_material(s, &m) == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding materials", d->path);
        st->materials++;
    }
    uint32_t default_mat = RT_NONE;
    if (need_default) {
        rt_material m;
        rt_material_default(&m, "gltf_default");
        m.color = rt_v3s(1);
        m.metallic = 1;
        m.roughness = 1;
        m.double_sided = false;
        m.transmission_color = m.color;
        derive_phong(&m);
        default_mat = rt_scene_add_material(s, &m);
        if (default_mat == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding materials", d->path);
        st->materials++;
    }

    /* geometry */
    if (attrs && !rt_scene_enable_attr(s, attrs))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for vertex attributes", d->path);
    size_t tri_first = s->triangles.count;
    if (!rt_scene_reserve_triangles(s, tris))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu triangles", d->path, tris);
    size_t vbase = s->vertices.count;
    if (verts && rt_scene_add_vertices(s, verts) == RT_NONE)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu vertices", d->path, verts);
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        if (n->mesh == RT_NONE)
            continue;
        const gl_mesh *m = &d->meshes[n->mesh];
        for (uint32_t k = 0; k < m->count; k++) {
            const gl_prim *p = &d->prims[m->first + k];
            if (!is_triangles(p->mode) || p->attr[ATTR_POSITION] == RT_NONE)
                continue;
            uint32_t mat = p->material == RT_NONE ? default_mat : mat_base + p->material;
            if ((r = emit_primitive(d, s, d->visits[v].node, k, &d->visits[v].world, &top, mat, vbase)) != RT_OK)
                return r;
            vbase += d->accessors[p->attr[ATTR_POSITION]].count;
        }
    }
    st->triangles = s->triangles.count - tri_first;
    /* bounds of the vertices triangles use (positions are finite: plain
     * compares, no fminf calls, which cost more than the rest of the load) */
    rt_box b = rt_box_empty();
    const uint32_t *ix = s->triangles.index;
    for (size_t k = 3 * tri_first; k < 3 * s->triangles.count; k++) {
        rt_vec3 q = s->vertices.position[ix[k]];
        b.lo.x = q.x < b.lo.x ? q.x : b.lo.x; b.hi.x = q.x > b.hi.x ? q.x : b.hi.x;
        b.lo.y = q.y < b.lo.y ? q.y : b.lo.y; b.hi.y = q.y > b.hi.y ? q.y : b.hi.y;
        b.lo.z = q.z < b.lo.z ? q.z : b.lo.z; b.hi.z = q.z > b.hi.z ? q.z : b.hi.z;
    }
    st->bounds = b;

    /* cameras and lights */
    bool warned_ortho = false;
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        const rt_mat4 *W = &d->visits[v].world;
        rt_vec3 origin = rt_mat4_point(W, rt_v3s(0));
        rt_vec3 fwd = rt_normalize(rt_mat4_vector(W, rt_v3(0, 0, -1)));
        if (n->camera != RT_NONE) {
            const gl_camera *gc = &d->cameras[n->camera];
            if (!gc->perspective) {
                if (!warned_ortho)
                    rt_warn("%s: orthographic cameras are not supported; skipped", d->path);
                warned_ortho = true;
            } else {
                rt_camera c = {0};
                c.position = origin;
                c.look_at = rt_add(origin, fwd);
                c.up = rt_normalize(rt_mat4_vector(W, rt_v3(0, 1, 0)));
                c.vfov_deg = gc->yfov * (180.0f / RT_PI);
                c.aspect_ratio = isfinite(gc->aspect) && gc->aspect > 0.0f ? gc->aspect : 0.0f;
                if (rt_scene_add_camera(s, &c) == RT_NONE)
                    return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding cameras", d->path);
                st->cameras++;
            }
        }
        if (n->light != RT_NONE) {
            const gl_light *gl = &d->lights[n->light];
            rt_light l;
            memset(&l, 0, sizeof l);
            l.kind = gl->kind;
            l.color = gl->color;
            l.intensity = gl->intensity;
            l.position = origin;
            l.direction = fwd;
            l.inner_cone = gl->inner;
            l.outer_cone = gl->outer;
            l.range = gl->range;
            l.quad = RT_NONE;
            if (rt_scene_add_light(s, &l) == RT_NONE)
                return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding lights", d->path);
            st->lights++;
        }
    }
    return RT_OK;
}

/* -------------------------------------------------------------- entry */

static void doc_free(gl_doc *d)
{
    for (size_t i = 0; i < d->buffer_count; i++)
        free(d->buffers[i].owned);
    for (size_t i = 0; i < d->view_count; i++)
        free(d->views[i].decoded);
    for (size_t i = 0; i < d->node_count; i++)
        free(d->nodes[i].pose_weights);
    free(d->skins); free(d->skin_joints); free(d->targets); free(d->anims); free(d->channels); free(d->asamplers);
    free(d->skin_scratch);
    free(d->buffers); free(d->views); free(d->accessors); free(d->meshes); free(d->prims);
    free(d->nodes); free(d->children); free(d->scenes); free(d->scene_nodes); free(d->materials);
    free(d->textures); free(d->samplers); free(d->images); free(d->cameras); free(d->lights);
    free(d->visits); free(d->visit_of); free(d->image_map); free(d->texture_map);
    free(d->texture_missing);
    for (int k = 0; k < ATTR_COUNT; k++)
        free(d->scratch[k]);
    free(d->idx_scratch);
    rt_json_free(&d->j);
    free(d->dir);
}

/* KHR_materials_variants: checks every primitive's mappings (material and
 * variant indices in range) and, when opt->variant names one of the file's
 * variants, gives each primitive the material its mapping for that variant
 * says (primitives without one keep their own). */
static rt_result apply_variant(gl_doc *d, const rt_gltf_options *opt)
{
    rt_result r;
    const char *want = opt ? opt->variant : NULL;
    size_t count = d->variants_tok >= 0 ? (size_t)jsize(d, d->variants_tok) : 0;
    uint32_t chosen = RT_NONE;
    char names[512] = "";
    if (d->variants_tok >= 0) {
        for (int i = 0, e = d->variants_tok + 1; i < d->j.tok[d->variants_tok].size && e < d->j.count;
             i++, e = rt_json_skip(&d->j, e)) {
            char where[64], name[128];
            snprintf(where, sizeof where, "extensions.KHR_materials_variants.variants[%d]", i);
            if ((r = expect_object(d, e, where)) != RT_OK)
                return r;
            int n = rt_json_get(&d->j, e, "name");
            if (n < 0)
                return fail_at(d, e, RT_ERR_INVALID, "%s: name is missing", where);
            if ((r = get_string(d, where, "name", n, name, sizeof name)) != RT_OK)
                return r;
            if (want && strcmp(want, name) == 0 && chosen == RT_NONE)
                chosen = (uint32_t)i;
            size_t used = strlen(names);
            snprintf(names + used, sizeof names - used, "%s'%s'", used ? ", " : "", name);
        }
    }
    if (want && chosen == RT_NONE)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: no material variant named '%s' (%s%s)", d->path, want,
                       count ? "the file's variants: " : "the file has no KHR_materials_variants",
                       count ? names : "");
    for (size_t p = 0; p < d->prim_count; p++) {
        gl_prim *pr = &d->prims[p];
        if (pr->variants_tok < 0)
            continue;
        uint32_t material = pr->material;
        for (int i = 0, e = pr->variants_tok + 1; i < d->j.tok[pr->variants_tok].size && e < d->j.count;
             i++, e = rt_json_skip(&d->j, e)) {
            char where[96];
            snprintf(where, sizeof where, "primitive %zu: KHR_materials_variants.mappings[%d]", p, i);
            if ((r = expect_object(d, e, where)) != RT_OK)
                return r;
            uint32_t m = RT_NONE;
            int mt = rt_json_get(&d->j, e, "material"), vt = rt_json_get(&d->j, e, "variants");
            if (mt < 0 || vt < 0)
                return fail_at(d, e, RT_ERR_INVALID, "%s: material or variants is missing", where);
            if ((r = get_index(d, where, "material", mt, &m)) != RT_OK)
                return r;
            if (m >= d->material_count)
                return fail_at(d, mt, RT_ERR_INVALID, "%s: material %u is out of range (the file has %zu materials)",
                               where, m, d->material_count);
            if ((r = expect_array(d, vt, where, "variants")) != RT_OK)
                return r;
            for (int j = 0, ve = vt + 1; j < d->j.tok[vt].size && ve < d->j.count; j++, ve = rt_json_skip(&d->j, ve)) {
                uint32_t v;
                if ((r = get_index(d, where, "variants", ve, &v)) != RT_OK)
                    return r;
                if (v >= count)
                    return fail_at(d, ve, RT_ERR_INVALID, "%s: variant %u is out of range (the file has %zu)", where,
                                   v, count);
                if (v == chosen)
                    material = m;
            }
        }
        pr->material = material;
    }
    return RT_OK;
}

static rt_result load(gl_doc *d, rt_scene *s, const rt_gltf_options *opt, rt_gltf_stats *st)
{
    rt_result r;
    size_t dir_size = strlen(d->path) + 1;
    d->dir = malloc(dir_size);
    if (!d->dir)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    rt_path_dirname(d->path, d->dir, dir_size);
    if (d->file_size > GL_MAX_FILE)
        return rt_fail(d->err, RT_ERR_LIMIT, "%s: file is over the limit of %zu bytes", d->path, GL_MAX_FILE);
    if (d->file_size >= 4 && memcmp(d->bytes, "glTF", 4) == 0) {
        d->glb = true;
        if ((r = split_glb(d)) != RT_OK)
            return r;
    } else {
        if (rt_path_has_ext(d->path, ".glb"))
            return rt_fail(d->err, RT_ERR_INVALID, "%s: byte 0: bad magic (expected \"glTF\" for a .glb file)",
                           d->path);
        d->json_text = (const char *)d->bytes;
        d->json_len = d->file_size;
        if (d->json_len >= 3 && memcmp(d->json_text, "\xEF\xBB\xBF", 3) == 0) { /* UTF-8 byte order mark */
            d->json_text += 3;
            d->json_len -= 3;
            d->json_base = 3;
        }
    }
    if ((r = parse_document(d)) != RT_OK)
        return r;
    if ((r = apply_variant(d, opt)) != RT_OK)
        return r;
    if ((r = validate(d)) != RT_OK)
        return r;
    if ((r = load_buffers(d)) != RT_OK)
        return r;
    if ((r = decode_meshopt_views(d)) != RT_OK)
        return r;
    if ((r = decode_draco_prims(d)) != RT_OK)
        return r;
    return flatten(d, s, opt, st);
}

static rt_result load_doc(rt_scene *s, const char *path, const void *data, size_t size,
                          const rt_gltf_options *options, rt_gltf_stats *stats, rt_error *err)
{
    rt_error local_err;
    gl_doc d;
    memset(&d, 0, sizeof d);
    d.path = path;
    d.err = err ? err : &local_err;
    d.bytes = data;
    d.file_size = size;
    rt_gltf_stats st;
    memset(&st, 0, sizeof st);
    st.bounds = rt_box_empty();
    rt_scene_mark mark = rt_scene_mark_of(s); /* a failed load leaves the scene as it was */
    rt_result r = load(&d, s, options, &st);
    doc_free(&d);
    if (r != RT_OK) {
        rt_scene_rollback(s, &mark);
        return r;
    }
    if (stats)
        *stats = st;
    return RT_OK;
}

rt_result rt_gltf_load(rt_scene *s, const char *path, const rt_gltf_options *options, rt_gltf_stats *stats,
                       rt_error *err)
{
    if (!path)
        return rt_fail(err, RT_ERR_IO, "rt_gltf_load: no path");
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(path, GL_MAX_FILE, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    r = rt_gltf_load_memory(s, bytes, size, path, options, stats, err);
    free(bytes);
    return r;
}

rt_result rt_gltf_load_memory(rt_scene *s, const void *data, size_t size, const char *name,
                              const rt_gltf_options *options, rt_gltf_stats *stats, rt_error *err)
{
    static const uint8_t empty[1] = {0};
    if (!data && size)
        return rt_fail(err, RT_ERR_INVALID, "%s: no data", name ? name : "<memory>");
    return load_doc(s, name ? name : "<memory>", size ? data : empty, size, options, stats, err);
}
