/* rt/tangents.h - per-vertex tangent frames for normal-mapped meshes that
 * come without tangents.
 *
 *   if (rt_scene_generate_tangents(&scene, &err) != RT_OK) ...  // after loading
 *
 * Every triangle whose material has a normal map, whose vertex UVs are
 * meaningful (RT_TRI_UV) and which has no tangents of its own
 * (RT_TRI_TANGENT unset) gets vertex tangents: xyz = the area-weighted mean
 * of its triangles' dP/du, Gram-Schmidt orthogonalised against the vertex
 * normal; w = the handedness (+1 or -1) such that cross(n, t) * w points
 * towards decreasing v (the top of the image: glTF's convention, the one
 * surface.c reads). A vertex shared by triangles of opposite handedness (a
 * mirrored-UV seam) takes the majority sign, weighted by area, +1 on a tie,
 * and its tangent sums only the triangles of that sign. The function sets
 * RT_ATTR_TANGENT on the scene and RT_TRI_TANGENT on the triangles it
 * served; vertices used by triangles that already had tangents are left
 * alone. Idempotent: a second call finds nothing to do.
 */
#ifndef RT_TANGENTS_H
#define RT_TANGENTS_H

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* Fails only when out of memory (the scene is then unchanged). */
rt_result rt_scene_generate_tangents(rt_scene *s, rt_error *err);

#endif
