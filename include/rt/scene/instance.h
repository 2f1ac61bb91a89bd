/* rt/scene/instance.h - objects (geometry kept once, in its own space) and
 * instances (affine placements of an object) in the scene's tables.
 *
 * A loader appends an object's triangles and vertices as usual, in object
 * space, then declares them an object and places it any number of times:
 *
 *   size_t t0 = s->triangles.count, v0 = s->vertices.count;
 *   ... rt_scene_add_vertices / rt_scene_add_triangle in object space ...
 *   uint32_t obj = rt_scene_add_object(s, t0, s->triangles.count - t0, v0, s->vertices.count - v0);
 *   if (rt_instance_check_transform(&to_world) == RT_INSTANCE_OK)
 *       rt_scene_add_instance(s, obj, &to_world);
 *
 * The object's triangles get RT_TRI_OBJECT: the kd-tree builds one tree
 * per object over them (rt/accel/kdtree.h) and puts each instance, by its
 * world box, in the top level; they are never part of the world geometry
 * themselves (rt_scene_bounds, the light table and the top-level tree skip
 * them). A hit on an instance reports the object's triangle id and the
 * instance (rt_hit.inst = instance + 1); the surface record transforms
 * that triangle's vertices, normals and tangents by the instance the way
 * the glTF loader flattens a node (positions by to_world, normals by its
 * inverse transpose, tangents by to_world with w flipped and the winding
 * reversed when the transform mirrors), so an instanced scene renders as
 * its flattened copy does, within the rounding of the transforms.
 * Rollback (rt_scene_mark) truncates both tables.
 */
#ifndef RT_INSTANCE_H
#define RT_INSTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "rt/base/vec.h"
#include "rt/scene/scene.h"

/* Triangles [first_triangle, +triangle_count) over vertices
 * [first_vertex, +vertex_count), in object space. */
typedef struct rt_object {
    size_t first_triangle, triangle_count;
    size_t first_vertex, vertex_count;
    rt_box bounds; /* of the vertices its triangles use, object space */
} rt_object;

/* One placement of an object. */
typedef struct rt_instance {
    uint32_t object;
    bool mirror;        /* det(to_world) < 0: winding and tangent sign flip */
    rt_mat4 to_world;   /* object -> world, affine (row 3 is 0 0 0 1) */
    rt_mat4 to_object;  /* its inverse: rays go into object space by it */
    rt_mat4 normal;     /* rt_mat4_normal_matrix(to_world): normals to world */
    rt_box bounds;      /* world box of the object's box's corners */
} rt_instance;

/* The bytes one instance costs at render time (its record, its share of the
 * top-level tree): what --max-memory counts against the instance count. */
#define RT_INSTANCE_BYTES ((size_t)sizeof(rt_instance) + 96u)

/* Declares the triangles and vertices an object (flags them
 * RT_TRI_OBJECT, computes its bounds); its index, or RT_NONE when out of
 * memory or the ranges are not in the tables. Objects stay in the order
 * of their vertices: one over vertices before the last object's goes
 * before it (its index is then not the last, and the instances of the
 * objects after it are renumbered; an index kept by the caller shifts by
 * one from the returned index on). */
uint32_t rt_scene_add_object(rt_scene *s, size_t first_triangle, size_t triangle_count, size_t first_vertex,
                             size_t vertex_count);
/* Whether to_world can place an object: RT_INSTANCE_NOT_FINITE (an
 * infinity or NaN), RT_INSTANCE_NOT_AFFINE (bottom row other than
 * 0 0 0 1), RT_INSTANCE_SINGULAR (a zero scale, a flattened axis:
 * determinant 0), else RT_INSTANCE_OK; rt_instance_check_name says it in
 * words for messages. */
typedef enum rt_instance_check {
    RT_INSTANCE_OK = 0, RT_INSTANCE_NOT_FINITE, RT_INSTANCE_NOT_AFFINE, RT_INSTANCE_SINGULAR
} rt_instance_check;
rt_instance_check rt_instance_check_transform(const rt_mat4 *to_world);
const char *rt_instance_check_name(rt_instance_check c);
/* to_world's inverse (to_world must check RT_INSTANCE_OK): the adjugate
 * over the determinant in double, rounded once to float. */
rt_mat4 rt_instance_inverse(const rt_mat4 *to_world);
/* Places object `object` by to_world (which must check RT_INSTANCE_OK);
 * the instance's index, or RT_NONE when out of memory or it does not. */
uint32_t rt_scene_add_instance(rt_scene *s, uint32_t object, const rt_mat4 *to_world);

/* Room for n more instances at once (a loader that knows its count: one
 * allocation, and a failure before anything is added); false when out of
 * memory. */
bool rt_scene_reserve_instances(rt_scene *s, size_t n);

/* Triangles the instances place (sum over instances of their object's
 * triangle count), and the objects' own (unique) triangles. */
size_t rt_scene_instanced_triangles(const rt_scene *s);
size_t rt_scene_object_triangles(const rt_scene *s);

#endif
