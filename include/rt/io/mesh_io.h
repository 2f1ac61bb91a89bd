/* rt/mesh_io.h - triangle meshes from OBJ (+MTL), PLY and OFF files.
 *
 * rt_mesh_load() reads the file (rt_read_file) and rt_mesh_load_memory()
 * takes its bytes; both pick the reader by content (a PLY's "ply" line, an
 * OFF header keyword), then by extension (.obj, .ply, .off, any case; see
 * rt_mesh_format_of), and append the mesh to the scene's tables with the
 * options' transform applied (positions by the matrix, normals by its
 * inverse transpose, winding flipped when it mirrors). Materials come from
 * the file where the format has them (OBJ's MTL; PLY vertex colours);
 * `material` is used for faces without one, or for all faces when
 * `override_material` is set.
 *
 *   rt_mat4 m = rt_mat4_translate(rt_v3(0, 1, 0));
 *   rt_mesh_options opt = {.transform = &m, .material = mat};   // zero = identity, material 0, file materials
 *   if (rt_mesh_load(&scene, "bunny.ply", &opt, &stats, &err) != RT_OK) ...
 *
 * Errors name the file and the line (text formats) or byte offset (binary
 * PLY). Nothing asserts on input.
 *
 * Conventions (details at the top of src/io/mesh_buffer.c and each reader):
 *   - All or nothing: on failure the scene is exactly as before the call
 *     (rt_scene_rollback), MTL materials and their images included.
 *   - Non-finite numbers (nan, inf, overflow) in vertex data are errors.
 *   - UVs are stored with v flipped (v' = 1 - v): OBJ/PLY/OFF put v = 0 at
 *     the bottom of the image, rt (like glTF) at the top.
 *   - Polygons: convex ones become fans, concave quads take the right
 *     diagonal, other concave polygons (up to 128 corners) are ear-clipped;
 *     triangles that repeat a vertex are dropped and counted in
 *     skipped_faces. OBJ smoothing groups generate normals for faces
 *     without vn.
 *   - OBJ: each MTL material becomes a scene material "<objfile>:<name>";
 *     faces before any usemtl, or naming an unknown material, use
 *     `material`; a missing MTL or texture is a warning.
 *   - A `material` the scene does not have (RT_NONE, or 0 in a scene without
 *     materials) gets a default material "<file>:default" added (once per
 *     load). stats.materials counts every material a load added.
 */
#ifndef RT_MESH_IO_H
#define RT_MESH_IO_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* Zero means defaults: identity transform, the scene's material 0 (or a
 * default material when the scene has none) for faces without their own,
 * and the file's materials kept. */
typedef enum rt_mesh_format { RT_MESH_UNKNOWN = 0, RT_MESH_OBJ, RT_MESH_PLY, RT_MESH_OFF } rt_mesh_format;

typedef struct rt_mesh_options {
    const rt_mat4 *transform; /* NULL = identity */
    uint32_t material;        /* scene material for faces without one; RT_NONE = "<file>:default" */
    bool override_material;   /* every face takes `material` (OBJ then reads no MTL) */
    rt_mesh_format format;    /* RT_MESH_UNKNOWN = by content, then name (rt_mesh_format_of); else this reader */
} rt_mesh_options;

typedef struct rt_mesh_load_stats {
    size_t triangles, vertices, materials, skipped_faces;
} rt_mesh_load_stats;

/* The format of a mesh file: by content first (bytes may be NULL to skip
 * it): "ply" on the first line is PLY, an [ST][C][N][4|n]OFF keyword at the
 * start is OFF; then by the extension of name (NULL to skip it): .obj,
 * .ply, .off in any case. OBJ has no magic. */
rt_mesh_format rt_mesh_format_of(const void *bytes, size_t size, const char *name);

/* Reads the mesh file at path and appends it to s. options and stats may be
 * NULL. */
rt_result rt_mesh_load(rt_scene *s, const char *path, const rt_mesh_options *options, rt_mesh_load_stats *stats,
                       rt_error *err);

/* The same for a file held in memory (size bytes at bytes, not kept). name
 * stands for the file in messages and picks the format when the content
 * does not; OBJ's mtllib files resolve against its directory. */
rt_result rt_mesh_load_memory(rt_scene *s, const void *bytes, size_t size, const char *name,
                              const rt_mesh_options *options, rt_mesh_load_stats *stats, rt_error *err);

#endif
