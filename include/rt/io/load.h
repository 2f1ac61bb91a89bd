/* rt/load.h - one entry point for every input rt reads: a scene file, a glTF
 * model or an OBJ/PLY/OFF mesh, the way the `rt` command, the benchmarks and
 * the fuzzers load them.
 *
 *   rt_scene scene;
 *   rt_scene_init(&scene);
 *   rt_load_options opt = {.for_render = true};   // zero = load the file as it is
 *   rt_load_info info;
 *   if (rt_load(&scene, &settings, "bunny.ply", &opt, &info, &err) != RT_OK) {
 *       fprintf(stderr, "rt: %s\n", err.message);   // the scene is as it was before the call
 *       ...
 *   }
 *   printf("%s in %.1f ms\n", rt_load_kind_name(info.kind), info.load_ms);
 *
 * The file is read once (rt_read_file) and goes to a reader by its content
 * first, then by its extension (rt_load_kind_of):
 *   glTF   the GLB magic "glTF", or JSON (its first character is '{'); else
 *          the extension .gltf or .glb          -> rt_gltf_load_memory
 *   mesh   a PLY or OFF header; else .obj, .ply or .off (any case); else,
 *          for a name without an extension ("<stdin>"), content that
 *          starts like an OBJ (v, vn, vt, f, o, g, mtllib, usemtl)
 *                                               -> rt_mesh_load_memory
 *   scene  .txt, .rt, .scene or no extension    -> rt_scene_parse_string
 *   anything else (.stl, .fbx, ...) is refused: RT_ERR_UNSUPPORTED, with a
 *   message naming the formats rt reads
 * A NULL path loads the built-in scene (rt_default_scene_text).
 *
 * A mesh gets a material "default" (added first) for faces the file gives
 * none. With for_render, a bare model also gets what rendering it needs:
 * the path tracer at 64 samples per pixel (rt_load_model_settings), a soft
 * sky, a directional key light when it brings no lights,
 * the first glTF camera as the view; and every input gets per-vertex
 * tangents where normal maps need them (rt_scene_generate_tangents). On any
 * error the scene is rolled back to where it was (rt_scene_rollback).
 */
#ifndef RT_LOAD_H
#define RT_LOAD_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"
#include "rt/render/settings.h"
#include "rt/scene/scene.h"

typedef enum rt_load_kind { RT_LOAD_SCENE = 0, RT_LOAD_GLTF, RT_LOAD_MESH, RT_LOAD_UNKNOWN } rt_load_kind;

typedef struct rt_load_options {
    bool for_render; /* add lighting, integrator, samples, the first camera and tangents (above); false = as the file is */
    const char *variant; /* glTF KHR_materials_variants: the variant's name (rt --variant); NULL = default materials */
    bool use_time;   /* a glTF input is posed at `time` by its animation `animation` (rt_gltf_options) */
    float time;
    int animation;
    struct rt_gltf_catalog *catalog; /* not NULL: the glTF inputs' animations and variants (rt/io/gltf.h, rt --info) */
    const char *animation_name; /* the animation of this name instead (NULL = by index); a scene file's model lines
                                 * without their own `animation` take it */
    bool flatten_instances; /* glTF: no objects and instances, every mesh use flattened (rt_gltf_options) */
} rt_load_options;

/* What one load found (what `rt --info` prints beside the scene's counts). */
typedef struct rt_load_info {
    rt_load_kind kind;
    double load_ms;     /* reading, parsing and the for_render additions */
    size_t meshes;      /* glTF: mesh instances; a mesh file: 1; a scene file: 0 */
    size_t primitives;  /* glTF: triangle primitives (instances); a mesh file: 1; a scene file: 0 */
    size_t nodes;       /* glTF: nodes of the chosen scene; otherwise 0 */
    bool animated;      /* posed by an animation (a glTF, or a scene file's model line): another time may differ */
} rt_load_info;

/* Appends the input at path (NULL = the built-in scene) to s; a scene
 * file's setting statements, or for_render's settings for a model, go to
 * settings (NULL: not kept). options and info may be NULL. A failed load
 * leaves the scene and the settings as they were. */
rt_result rt_load(rt_scene *s, rt_settings *settings, const char *path, const rt_load_options *options,
                  rt_load_info *info, rt_error *err);

/* The same for an input held in memory (size bytes at bytes, not kept);
 * name stands for the file in messages, picks the reader when the content
 * does not, and relative paths in the input resolve against its directory. */
rt_result rt_load_memory(rt_scene *s, rt_settings *settings, const void *bytes, size_t size, const char *name,
                         const rt_load_options *options, rt_load_info *info, rt_error *err);

/* The reader an input goes to: by content (bytes may be NULL to skip it),
 * then by the extension of name (NULL to skip it); see the top of this
 * file. */
rt_load_kind rt_load_kind_of(const void *bytes, size_t size, const char *name);

/* The settings a glTF model or a mesh rendered on its own gets (for_render
 * does this to the load's settings and the scene's environment): its
 * samples and integrator (set NULL: none), and its sky. */
void rt_load_model_settings(rt_settings *set, rt_scene_environment *env);

/* True when name is read as scene text unless its content says otherwise:
 * .txt, .rt, .scene, no extension, or NULL. */
bool rt_load_is_scene_name(const char *name);

/* "scene", "gltf", "mesh" or "unknown". */
const char *rt_load_kind_name(rt_load_kind kind);

#endif
