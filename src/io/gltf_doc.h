/* gltf_doc.h - what the files of the glTF loader share (private to
 * src/io): the limits, the document's records and gl_doc, and each file's
 * entry points. gltf_doc.c, at the bottom, reads the document: located
 * errors, external files, the typed JSON field readers. Above it the
 * passes, in the order gl_load (gltf.c, at the top) runs them:
 *   gltf.c           read the file, split a GLB into JSON and BIN chunks
 *   gltf_parse.c     map the JSON into flat tables of records (with
 *   gltf_material.c  for materials, textures, samplers and images)
 *   gltf_check.c     check every index, span and the node graph
 *   gltf_buffers.c   read buffers; accessor data; meshopt and Draco decoding
 *   gltf_pose.c      pose nodes at a time; skin and morph matrices and weights
 *   gltf_flatten.c   the chosen scene into the scene's tables
 * gltf.c calls the passes and every pass calls gltf_doc.c; a pass calls
 * the others only downward (gltf_parse.c the material readers,
 * gltf_flatten.c the buffers, materials and pose): no circle. Every function returns at its failures in plain sight:
 * no macro hides a return or a loop.
 */
#ifndef RT_IO_GLTF_DOC_H
#define RT_IO_GLTF_DOC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/io/gltf.h"
#include "rt/io/json.h"
#include "rt/scene/scene.h"

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
extern const char *const gl_attr_names[ATTR_COUNT]; /* "POSITION", ... */

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
    /* EXT_mesh_gpu_instancing: accessors of TRANSLATION, ROTATION, SCALE
     * (RT_NONE: absent); gpu_tok the extension's token, -1 = not instanced */
    uint32_t gpu_attr[3];
    int gpu_tok;
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

static inline int jtype(const gl_doc *d, int t) { return t >= 0 && t < d->j.count ? d->j.tok[t].type : 0; }
static inline int jsize(const gl_doc *d, int t) { return t >= 0 && t < d->j.count ? d->j.tok[t].size : 0; }
/* Whether key token k is the string s (d is the gl_doc in scope). */
#define KEY(k, s) rt_json_key_is(&d->j, (k), (s))

/* gltf_doc.c: errors located in the document, external files, the JSON field readers */
/* Fails with code and a message located at token tok ("file: byte N: ..."; no byte for tok < 0). */
rt_result gl_fail_at(gl_doc *d, int tok, rt_result code, const char *fmt, ...) RT_PRINTF(4, 5);
rt_result gl_read_file(gl_doc *d, const char *path, const char *what, uint8_t **data, size_t *size);
rt_result gl_expect_object(gl_doc *d, int t, const char *where);
rt_result gl_expect_array(gl_doc *d, int t, const char *where, const char *key);
rt_result gl_get_index(gl_doc *d, const char *where, const char *key, int t, uint32_t *out);
rt_result gl_get_size(gl_doc *d, const char *where, const char *key, int t, size_t *out);
rt_result gl_get_int(gl_doc *d, const char *where, const char *key, int t, int *out);
rt_result gl_get_float(gl_doc *d, const char *where, const char *key, int t, float *out);
rt_result gl_get_floats(gl_doc *d, const char *where, const char *key, int t, float *out, int n);
/* A number, or n of them, that the schema bounds to [lo, hi] (GL_BIG for
 * no upper bound); outside is RT_ERR_INVALID naming the field and value. */
#define GL_BIG 3.0e38f
rt_result gl_get_ranged(gl_doc *d, const char *where, const char *key, int t, float lo, float hi, float *out);
rt_result gl_get_floats_ranged(gl_doc *d, const char *where, const char *key, int t, int n, float lo, float hi,
                               float *out);
rt_result gl_get_bool(gl_doc *d, const char *where, const char *key, int t, bool *out);
rt_result gl_get_string(gl_doc *d, const char *where, const char *key, int t, char *buf, size_t cap);
rt_result gl_alloc_table(gl_doc *d, int t, const char *key, size_t elem, void **out, size_t *count);
size_t gl_comp_size(int ct);
size_t gl_elem_size(const gl_accessor *a);
rt_mat4 gl_mat_from_gltf(const float *c);
const char *gl_prim_name(const gl_doc *d, size_t p, char *buf, size_t cap);

/* gltf.c: the entry points; gl_load runs the passes in order */
rt_result gl_apply_variant(gl_doc *d, const rt_gltf_options *opt);
rt_result gl_load(gl_doc *d, rt_scene *s, const rt_gltf_options *opt, rt_gltf_stats *st);

/* gltf_parse.c: the mapping of the document into records */
rt_result gl_parse_document(gl_doc *d);

/* gltf_material.c: materials, textures, samplers, images; textures into the scene */
void gl_derive_phong(rt_material *m);
rt_result gl_parse_materials(gl_doc *d, int t);
rt_result gl_parse_textures(gl_doc *d, int t);
rt_result gl_parse_samplers(gl_doc *d, int t);
rt_result gl_parse_images(gl_doc *d, int t);
rt_result gl_load_textures(gl_doc *d, rt_scene *s, rt_gltf_stats *st);

/* gltf_check.c: every index, span and graph rule, before any buffer is read */
rt_result gl_validate_meshopt_view(gl_doc *d, size_t i);
rt_result gl_validate(gl_doc *d);

/* gltf_buffers.c: buffer bytes (files, data: URIs, GLB BIN), accessor data, meshopt and Draco */
rt_result gl_decode_data_uri(gl_doc *d, int tok, const char *uri, size_t len, const char *what, uint8_t **out,
                             size_t *out_len);
rt_result gl_uri_to_path(gl_doc *d, int tok, const char *uri, const char *what, char **out);
rt_result gl_token_string(gl_doc *d, int t, const char *what, char **out);
rt_result gl_load_buffers(gl_doc *d);
const uint8_t *gl_view_ptr(const gl_doc *d, uint32_t view, size_t offset);
rt_result gl_read_floats(gl_doc *d, uint32_t ai, float *out);
rt_result gl_read_uints(gl_doc *d, uint32_t ai, uint32_t *out);
rt_result gl_decode_meshopt_views(gl_doc *d);
rt_result gl_decode_draco_prims(gl_doc *d);

/* gltf_catalog.c: the animations and variants a file offers (rt_gltf_catalog) */
void gl_catalog(gl_doc *d, rt_gltf_catalog *c);

/* gltf_pose.c: animations at a time, node world matrices, skins and morph targets */
rt_mat4 gl_node_world(const gl_doc *d, uint32_t n, const rt_mat4 *top);
rt_result gl_pose_nodes(gl_doc *d, const rt_gltf_options *opt);
rt_result gl_morph_weights(gl_doc *d, uint32_t node, uint32_t count, float *w);
rt_result gl_apply_morph(gl_doc *d, const gl_prim *p, const float *w, int slot, float *f, size_t stride,
                         size_t vcount);
rt_result gl_skin_matrices(gl_doc *d, const gl_prim *p, uint32_t node, const rt_mat4 *M, const rt_mat4 *top,
                           size_t vcount, rt_mat4 **out);

/* gltf_flatten.c: the chosen scene into the scene tables */
rt_result gl_scratch(gl_doc *d, int slot, size_t floats, float **out);
rt_result gl_flatten(gl_doc *d, rt_scene *s, const rt_gltf_options *opt, rt_gltf_stats *st);

/* gltf_instances.c: which meshes are kept once and placed by instances,
 * and EXT_mesh_gpu_instancing's transforms */
#define GL_OBJECT_PLANNED (RT_NONE - 1u) /* mesh_object: an object, not emitted yet */
/* mesh_object[m] (d->mesh_count entries): GL_OBJECT_PLANNED for a mesh to
 * keep once (used more than once, the same shape at every use, no
 * emitter), RT_NONE for one to flatten. */
rt_result gl_plan_objects(gl_doc *d, const rt_gltf_options *opt, uint32_t *mesh_object);
/* Node ni's EXT_mesh_gpu_instancing transforms T * R * S (*count of them,
 * *out owned by the caller); checks types, counts and finiteness, errors
 * naming the node, the attribute and the element. */
rt_result gl_gpu_instances(gl_doc *d, uint32_t ni, rt_mat4 **out, size_t *count);

#endif
