/* mesh_buffer.h - the mesh under construction: what every mesh reader
 * (OBJ, PLY, OFF) fills, and the one step that appends it to the scene.
 * Private to src/io; below the readers, which depend on nothing else of the
 * mesh code (mesh_text.h aside), and below the dispatcher (mesh_io.c),
 * which makes the buffer, hands it to a reader and commits it.
 *
 *   rt_mesh_buf b = {0};
 *   rt_mesh_buf_reserve_vertices(&b, n);      // positions; rt_mesh_buf_enable for normals, UVs, colours
 *   b.pos[b.nv++] = p;  ...
 *   rt_mesh_buf_add_triangle(&b, 0, 1, 2, material, RT_TRI_SMOOTH);
 *   if (rt_mesh_commit(scene, &b, transform, "bunny.ply", &err) != RT_OK) ...
 *   rt_mesh_buf_free(&b);
 *
 * Geometry reaches the scene only through rt_mesh_commit, once the whole
 * file has parsed, so the scene's arrays grow once per file.
 */
#ifndef RT_MESH_BUFFER_H
#define RT_MESH_BUFFER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* A mesh under construction. nrm/uv/col are NULL until a reader needs them
 * (rt_mesh_buf_enable); missing values are zero normals, zero UVs and white. */
typedef struct rt_mesh_buf {
    size_t nv, vcap;
    rt_vec3 *pos, *nrm;
    rt_vec2 *uv;
    rt_vec4 *col;
    size_t nt, tcap;
    uint32_t *idx;  /* 3 per triangle */
    uint32_t *mat;  /* per triangle; the reader's meaning until commit */
    uint8_t *flags; /* RT_TRI_* */
    size_t skipped; /* faces dropped (counted into stats.skipped_faces) */
} rt_mesh_buf;

enum { RT_MESH_NRM = 1, RT_MESH_UV = 2, RT_MESH_COL = 4 };

void rt_mesh_buf_free(rt_mesh_buf *b);
/* Room for `need` vertices / triangles in total. false = out of memory or over
 * the uint32 index range. */
bool rt_mesh_buf_reserve_vertices(rt_mesh_buf *b, size_t need);
bool rt_mesh_buf_reserve_triangles(rt_mesh_buf *b, size_t need);
/* Makes the optional arrays exist (RT_MESH_* bits), filled with defaults. */
bool rt_mesh_buf_enable(rt_mesh_buf *b, unsigned what);
/* Appends one triangle (room must have been reserved or is grown here). */
bool rt_mesh_buf_add_triangle(rt_mesh_buf *b, uint32_t a, uint32_t c1, uint32_t c2, uint32_t mat, uint8_t flags);

/* Transforms the buffer (positions by the matrix, NULL = identity; normals
 * by the normal matrix then normalised; winding flipped when the matrix
 * mirrors) and appends it to the scene. Triangle materials are scene
 * indices; one the scene does not have (RT_NONE) becomes a default material
 * "<file>:default", added once. `name` names the file in messages. A buffer
 * without triangles appends nothing (a warning). On failure the caller rolls
 * the scene back (rt_scene_rollback). */
rt_result rt_mesh_commit(rt_scene *s, rt_mesh_buf *b, const rt_mat4 *transform, const char *name, rt_error *err);

/* Triangulates a polygon of n corners whose positions are pos[vidx[k]]
 * (pos may be NULL when the positions are not known yet: plain fan). Writes
 * 3 * (n - 2) corner numbers (0..n-1) into out and returns n - 2 (0 when
 * n < 3). Convex polygons are fans from corner 0; quads take the diagonal
 * that keeps both halves facing the same way; non-convex polygons of up to
 * RT_MESH_EARCLIP_MAX corners are ear-clipped in the plane of their Newell
 * normal, with a work bound that falls back to a fan. */
#define RT_MESH_EARCLIP_MAX 128
size_t rt_mesh_triangulate(const rt_vec3 *pos, const uint32_t *vidx, size_t n, uint32_t *out);

#endif
