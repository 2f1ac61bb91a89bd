/* mesh_internal.h - what the OBJ, PLY and OFF readers share (private to
 * src/mesh_*.c; the public interface is include/rt/mesh_io.h).
 *
 * Every reader parses into an rt_mesh_buf (local arrays), and only when the
 * whole file has parsed does rt_mesh_commit() transform the buffer and append
 * it to the scene in bulk. So a file that fails half way leaves the scene's
 * geometry untouched, and the scene arrays grow once per file.
 */
#ifndef RT_MESH_INTERNAL_H
#define RT_MESH_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/io/mesh_io.h"
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

/* Transforms the buffer (positions by the matrix, normals by the normal
 * matrix then normalised, winding flipped when the matrix mirrors) and
 * appends it to the scene. Triangle materials must already be scene indices.
 * Fills stats (may be NULL) with the triangles and vertices added. On failure
 * the scene's geometry is unchanged. */
rt_result rt_mesh_commit(rt_scene *s, rt_mesh_buf *b, const rt_mat4 *transform, const char *path,
                         rt_mesh_load_stats *stats, rt_error *err);

/* Number parsing on [p, end) without locale or allocation. Both return the
 * position after the number, or NULL when no number starts at p. Floats are
 * correctly rounded (a fast exact path, else strtof on a bounded copy).
 * *nonfinite is set when the text is a number but not a finite float
 * ("nan", "inf", 1e39); then the return value is still NULL. */
const char *rt_mesh_parse_float(const char *p, const char *end, float *out, bool *nonfinite);
const char *rt_mesh_parse_int(const char *p, const char *end, int64_t *out);

/* Triangulates a polygon of n corners whose positions are pos[vidx[k]]
 * (pos may be NULL when the positions are not known yet: plain fan). Writes
 * 3 * (n - 2) corner numbers (0..n-1) into out and returns n - 2 (0 when
 * n < 3). Convex polygons are fans from corner 0; quads take the diagonal
 * that keeps both halves facing the same way; non-convex polygons of up to
 * RT_MESH_EARCLIP_MAX corners are ear-clipped in the plane of their Newell
 * normal, with a work bound that falls back to a fan. */
#define RT_MESH_EARCLIP_MAX 128
size_t rt_mesh_triangulate(const rt_vec3 *pos, const uint32_t *vidx, size_t n, uint32_t *out);

/* Warn once per keyword per file: a small set of keywords already warned about. */
typedef struct rt_warn_once {
    char seen[32][24];
    int count;
} rt_warn_once;
/* True the first time `key` (len bytes) is seen; false after (and when full). */
bool rt_warn_once_first(rt_warn_once *w, const char *key, size_t len);

static inline bool rt_mesh_is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
/* The first non-space character at or after p (end when none). */
static inline const char *rt_mesh_skip_space(const char *p, const char *end)
{
    while (p < end && rt_mesh_is_space(*p))
        p++;
    return p;
}
/* The end of the token starting at p. */
static inline const char *rt_mesh_token_end(const char *p, const char *end)
{
    while (p < end && !rt_mesh_is_space(*p))
        p++;
    return p;
}

#endif
