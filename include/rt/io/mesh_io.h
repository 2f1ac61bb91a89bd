/* rt/mesh_io.h - triangle meshes from OBJ (+MTL), PLY and OFF files.
 *
 * rt_mesh_load() picks the reader by the file's extension and appends the
 * mesh to the scene's tables with `transform` applied (positions by the
 * matrix, normals by its inverse transpose, winding flipped when it
 * mirrors). Materials come from the file where the format has them (OBJ's
 * MTL; PLY vertex colours); `material` is used for faces without one, or
 * for all faces when `override_material` is set.
 *
 *   rt_mat4 m = rt_mat4_translate(rt_v3(0, 1, 0));
 *   if (rt_mesh_load(&scene, "bunny.ply", &m, mat, false, &err) != RT_OK) ...
 *
 * Errors name the file and the line (text formats) or byte offset (binary
 * PLY). Nothing asserts on input.
 *
 * Conventions (details at the top of src/mesh_io.c and each reader):
 *   - All or nothing: on failure no vertex or triangle of the file is in the
 *     scene (nor are its MTL materials).
 *   - Non-finite numbers (nan, inf, overflow) in vertex data are errors.
 *   - UVs are stored with v flipped (v' = 1 - v): OBJ/PLY/OFF put v = 0 at
 *     the bottom of the image, rt (like glTF) at the top.
 *   - Polygons: convex ones become fans, concave quads take the right
 *     diagonal, other concave polygons (up to 128 corners) are ear-clipped;
 *     triangles that repeat a vertex are dropped and counted in
 *     skipped_faces. OBJ smoothing groups generate normals for faces
 *     without vn.
 *   - OBJ: each MTL material becomes a scene material "<objfile>:<name>"
 *     (stats.materials counts them); faces before any usemtl, or naming an
 *     unknown material, use `material`; a missing MTL or texture is a warning.
 *   - A `material` the scene does not have (RT_NONE) gets a default material
 *     "<file>:default" added (once per load).
 */
#ifndef RT_MESH_IO_H
#define RT_MESH_IO_H

#include <stdbool.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

typedef struct rt_mesh_load_stats {
    size_t triangles, vertices, materials, skipped_faces;
} rt_mesh_load_stats;

rt_result rt_mesh_load(rt_scene *s, const char *path, const rt_mat4 *transform, uint32_t material,
                       bool override_material, rt_mesh_load_stats *stats, rt_error *err);

/* The format readers, also callable directly. */
rt_result rt_obj_load(rt_scene *s, const char *path, const rt_mat4 *transform, uint32_t material,
                      bool override_material, rt_mesh_load_stats *stats, rt_error *err);
rt_result rt_ply_load(rt_scene *s, const char *path, const rt_mat4 *transform, uint32_t material,
                      bool override_material, rt_mesh_load_stats *stats, rt_error *err);
rt_result rt_off_load(rt_scene *s, const char *path, const rt_mat4 *transform, uint32_t material,
                      bool override_material, rt_mesh_load_stats *stats, rt_error *err);

#endif
