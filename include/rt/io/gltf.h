/* rt/gltf.h - glTF 2.0 (.gltf, .glb) into the scene's tables.
 *
 * Our own loader on the jsmn tokenizer, built the way cgltf is built: the
 * JSON is tokenized once, mapped to flat arrays of records (buffers,
 * bufferViews, accessors, meshes, nodes, materials, ...) with index cross
 * references, validated, then flattened into the scene: every triangle
 * primitive of the chosen scene with each node's world transform applied,
 * except meshes used more than once (two nodes, or EXT_mesh_gpu_instancing),
 * which are kept once in their own space and placed by instances
 * (rt/scene/instance.h; docs/gltf.md says which).
 *
 *   rt_gltf_options opt = {0};          // zero = defaults: default scene
 *   if (rt_gltf_load(&scene, "helmet.glb", &opt, &stats, &err) != RT_OK) ...
 */
#ifndef RT_GLTF_H
#define RT_GLTF_H

#include <stdbool.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* What a glTF file offers besides its geometry, for `rt --info`: its
 * animations (name, length in seconds) and material variants, appended by
 * each file loaded with rt_gltf_options.catalog (a scene file's model lines
 * too); the counts are whole, the names the first RT_GLTF_CATALOG_MAX. */
#define RT_GLTF_CATALOG_MAX 32
typedef struct rt_gltf_catalog {
    int animations;
    char animation_name[RT_GLTF_CATALOG_MAX][64]; /* "" when unnamed */
    float animation_seconds[RT_GLTF_CATALOG_MAX]; /* its last key time; -1 when its key times cannot be read */
    int variants;
    char variant_name[RT_GLTF_CATALOG_MAX][64];
} rt_gltf_catalog;

typedef struct rt_gltf_options {
    int scene_index;       /* which glTF scene, when use_scene_index; otherwise the file's default */
    bool use_scene_index;
    rt_mat4 transform;     /* applied on top of the node transforms */
    bool use_transform;    /* false = identity */
    const char *variant;   /* KHR_materials_variants: the variant to show, by name; NULL = the default materials */
    bool use_time;         /* pose at `time`: the animation's channels, skins and morph weights */
    float time;            /* seconds on the animation's clock (clamped to its keys) */
    int animation;         /* which animation, when use_time (0 = the first) */
    const char *animation_name; /* when use_time: the animation with this `name` instead (NULL = by index) */
    bool animation_optional; /* a file without animations ignores `animation` (the scene format's model
                              * lines take the driver's --animation so) instead of failing */
    rt_gltf_catalog *catalog; /* not NULL: the file's animations and variants appended to it */
    bool flatten_instances; /* every use of every mesh flattened into world triangles, none kept as an
                             * object with instances (rt/scene/instance.h): the loader as it was before */
} rt_gltf_options;

/* What one load added. meshes/primitives count instances (a mesh used by
 * two nodes counts twice; only triangle primitives); nodes = nodes of the
 * chosen scene; images = glTF images decoded for this file; cameras =
 * perspective cameras appended to scene->cameras (the first one of this file
 * is scene->cameras[camera_count - cameras]). */
typedef struct rt_gltf_stats {
    size_t triangles, meshes, primitives, materials, textures, images, cameras, lights, nodes;
    size_t objects, instances, instanced_triangles; /* meshes kept once, their placements, the triangles placed */
    rt_box bounds;         /* world bounds of the vertices the loaded triangles use */
    bool animated;         /* posed by an animation with channels: another time may give another pose */
} rt_gltf_stats;

/* Appends the chosen scene of the glTF at path (read with rt_read_file) to
 * s. options and stats may be NULL. On failure s is left exactly as it was
 * (rt_scene_rollback) and err names the file, the byte offset when there is
 * one, and the problem. Supported features, limits and the material
 * mapping: docs/gltf.md. */
rt_result rt_gltf_load(rt_scene *s, const char *path, const rt_gltf_options *options, rt_gltf_stats *stats,
                       rt_error *err);

/* The same from a .gltf or .glb already in memory (size bytes at data, not
 * copied, not kept). `name` stands for the file in messages, and relative
 * URIs (external .bin and images) resolve against its directory. Handy for
 * fuzzing and for assets packed in other files. */
rt_result rt_gltf_load_memory(rt_scene *s, const void *data, size_t size, const char *name,
                              const rt_gltf_options *options, rt_gltf_stats *stats, rt_error *err);

#endif
