/* mesh_buffer.c - the mesh under construction (mesh_buffer.h): its arrays
 * and their growth, polygon triangulation, and the transform-and-append step
 * every mesh reader ends with.
 *
 * Conventions every reader follows (see include/rt/mesh_io.h):
 *   - The file is read into memory once and parsed in place; no per-token
 *     allocation. Geometry goes into an rt_mesh_buf and is appended to the
 *     scene only when the whole file has parsed (rt_mesh_commit), so a bad
 *     file leaves the scene's geometry as it was.
 *   - Non-finite numbers (nan, inf, overflow) in any vertex attribute are
 *     errors naming the line or byte offset, never silently kept.
 *   - Texture coordinates are stored with v flipped (v' = 1 - v): OBJ, PLY
 *     and OFF put v = 0 at the bottom of the image, rt (like glTF) at the top.
 *   - Transform: positions by the matrix, normals by the inverse transpose of
 *     its 3x3 (rt_mat4_normal_matrix) then renormalised, and triangle winding
 *     reversed when det3 < 0 so that the geometric normal cross(e1, e2) keeps
 *     pointing outwards. A singular or non-finite matrix is an error.
 */
#include "mesh_buffer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/log.h"

/* ------------------------------------------------------ triangulation */

/* Ear clipping: repeatedly cut off a convex corner whose triangle holds no
 * other corner (Meisters, "Polygons have ears", Amer. Math. Monthly 82, 1975;
 * Eberly, "Triangulation by Ear Clipping", Geometric Tools 2002). Works in
 * 2D after dropping the largest axis of the Newell normal. false = convex
 * (the caller's fan is then exact) or nothing sensible to do. */
static bool ear_clip(const rt_vec3 *pos, const uint32_t *vidx, size_t n, uint32_t *out)
{
    rt_vec3 nn = rt_v3s(0);
    for (size_t i = 0; i < n; i++) {
        rt_vec3 a = pos[vidx[i]], b = pos[vidx[(i + 1) % n]];
        nn.x += (a.y - b.y) * (a.z + b.z);
        nn.y += (a.z - b.z) * (a.x + b.x);
        nn.z += (a.x - b.x) * (a.y + b.y);
    }
    int axis = fabsf(nn.x) > fabsf(nn.y) ? (fabsf(nn.x) > fabsf(nn.z) ? 0 : 2) : (fabsf(nn.y) > fabsf(nn.z) ? 1 : 2);
    float along = rt_axis(nn, axis);
    if (!(fabsf(along) > 0.0f) || !isfinite(along))
        return false;
    int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    float flip = along < 0.0f ? -1.0f : 1.0f; /* make the polygon counter-clockwise in (u, v) */
    float px[RT_MESH_EARCLIP_MAX], py[RT_MESH_EARCLIP_MAX];
    for (size_t i = 0; i < n; i++) {
        px[i] = flip * rt_axis(pos[vidx[i]], ua);
        py[i] = rt_axis(pos[vidx[i]], va);
    }
#define CROSS2(a, b, c) ((px[b] - px[a]) * (py[c] - py[a]) - (py[b] - py[a]) * (px[c] - px[a]))
    bool convex = true;
    for (size_t i = 0; i < n && convex; i++)
        convex = CROSS2(i, (i + 1) % n, (i + 2) % n) >= 0.0f;
    if (convex)
        return false;
    uint8_t ring[RT_MESH_EARCLIP_MAX];
    for (size_t i = 0; i < n; i++)
        ring[i] = (uint8_t)i;
    size_t m = n, nt = 0, i = 0, since_ear = 0;
    size_t budget = 8 * n * n; /* inner-loop steps before giving up on ears */
    while (m > 3) {
        size_t ia = (i + m - 1) % m, ic = (i + 1) % m;
        int a = ring[ia], b = ring[i], c = ring[ic];
        bool ear = CROSS2(a, b, c) > 0.0f;
        for (size_t j = 0; ear && j < m; j++) {
            int q = ring[j];
            if (q == a || q == b || q == c)
                continue;
            if ((px[q] == px[a] && py[q] == py[a]) || (px[q] == px[b] && py[q] == py[b]) ||
                (px[q] == px[c] && py[q] == py[c]))
                continue; /* a repeated corner (a bridged hole) does not block */
            if (CROSS2(a, b, q) >= 0.0f && CROSS2(b, c, q) >= 0.0f && CROSS2(c, a, q) >= 0.0f)
                ear = false;
        }
        if (budget < m)
            break;
        budget -= m;
        if (ear) {
            out[3 * nt] = (uint32_t)a;
            out[3 * nt + 1] = (uint32_t)b;
            out[3 * nt + 2] = (uint32_t)c;
            nt++;
            memmove(ring + i, ring + i + 1, m - i - 1);
            m--;
            if (i >= m)
                i = 0;
            since_ear = 0;
            continue;
        }
        i = (i + 1) % m;
        if (++since_ear > m)
            break; /* no ear left (self-intersecting or degenerate): fan the rest */
    }
#undef CROSS2
    for (size_t k = 1; k + 1 < m; k++) {
        out[3 * nt] = ring[0];
        out[3 * nt + 1] = ring[k];
        out[3 * nt + 2] = ring[k + 1];
        nt++;
    }
    return true;
}

size_t rt_mesh_triangulate(const rt_vec3 *pos, const uint32_t *vidx, size_t n, uint32_t *out)
{
    if (n < 3)
        return 0;
    if (pos && n == 4) {
        /* concave quad: if the 0-2 diagonal gives halves facing opposite ways, use 1-3 */
        rt_vec3 p0 = pos[vidx[0]], p1 = pos[vidx[1]], p2 = pos[vidx[2]], p3 = pos[vidx[3]];
        rt_vec3 n1 = rt_cross(rt_sub(p1, p0), rt_sub(p2, p0));
        rt_vec3 n2 = rt_cross(rt_sub(p2, p0), rt_sub(p3, p0));
        static const uint32_t d02[6] = {0, 1, 2, 0, 2, 3}, d13[6] = {1, 2, 3, 1, 3, 0};
        memcpy(out, rt_dot(n1, n2) < 0.0f ? d13 : d02, sizeof d02);
        return 2;
    }
    if (pos && n >= 5 && n <= RT_MESH_EARCLIP_MAX && ear_clip(pos, vidx, n, out))
        return n - 2;
    for (size_t k = 1; k + 1 < n; k++) {
        out[3 * (k - 1)] = 0;
        out[3 * (k - 1) + 1] = (uint32_t)k;
        out[3 * (k - 1) + 2] = (uint32_t)(k + 1);
    }
    return n - 2;
}

/* --------------------------------------------------------- mesh buffer */

void rt_mesh_buf_free(rt_mesh_buf *b)
{
    free(b->pos); free(b->nrm); free(b->uv); free(b->col);
    free(b->idx); free(b->mat); free(b->flags);
    memset(b, 0, sizeof *b);
}

/* The vertex arrays share vcap, the triangle arrays tcap; indices are
 * uint32, so neither count may reach RT_NONE. */
bool rt_mesh_buf_reserve_vertices(rt_mesh_buf *b, size_t need)
{
    if (need <= b->vcap)
        return true;
    if (need >= RT_NONE)
        return false;
    void **arrays[4] = {(void **)&b->pos};
    size_t sizes[4] = {sizeof *b->pos};
    int n = 1;
    if (b->nrm) arrays[n] = (void **)&b->nrm, sizes[n++] = sizeof *b->nrm;
    if (b->uv) arrays[n] = (void **)&b->uv, sizes[n++] = sizeof *b->uv;
    if (b->col) arrays[n] = (void **)&b->col, sizes[n++] = sizeof *b->col;
    return rt_soa_reserve(arrays, sizes, n, &b->vcap, need);
}

bool rt_mesh_buf_enable(rt_mesh_buf *b, unsigned what)
{
    size_t cap = b->vcap ? b->vcap : 1;
    if ((what & RT_MESH_NRM) && !b->nrm) {
        if (!(b->nrm = rt_alloc(cap, sizeof *b->nrm)))
            return false;
    }
    if ((what & RT_MESH_UV) && !b->uv) {
        if (!(b->uv = rt_alloc(cap, sizeof *b->uv)))
            return false;
    }
    if ((what & RT_MESH_COL) && !b->col) {
        if (!(b->col = rt_alloc(cap, sizeof *b->col)))
            return false;
        for (size_t i = 0; i < cap; i++)
            b->col[i] = rt_v4(1, 1, 1, 1);
    }
    if (!b->vcap) { /* keep vcap consistent with the arrays just made */
        if (!b->pos && !(b->pos = rt_alloc(1, sizeof *b->pos)))
            return false;
        if (!rt_mesh_buf_reserve_vertices(b, 1))
            return false;
        if (b->col)
            b->col[0] = rt_v4(1, 1, 1, 1);
    }
    return true;
}

bool rt_mesh_buf_reserve_triangles(rt_mesh_buf *b, size_t need)
{
    if (need <= b->tcap)
        return true;
    if (need >= RT_NONE)
        return false;
    void **arrays[] = {(void **)&b->idx, (void **)&b->mat, (void **)&b->flags};
    const size_t sizes[] = {3 * sizeof *b->idx, sizeof *b->mat, sizeof *b->flags};
    return rt_soa_reserve(arrays, sizes, 3, &b->tcap, need);
}

bool rt_mesh_buf_add_triangle(rt_mesh_buf *b, uint32_t a, uint32_t c1, uint32_t c2, uint32_t mat, uint8_t flags)
{
    if (b->nt >= b->tcap && !rt_mesh_buf_reserve_triangles(b, b->nt + 1))
        return false;
    size_t i = b->nt++;
    b->idx[3 * i] = a;
    b->idx[3 * i + 1] = c1;
    b->idx[3 * i + 2] = c2;
    b->mat[i] = mat;
    b->flags[i] = flags;
    return true;
}

/* ------------------------------------------------------------- commit */

static bool mat_finite(const rt_mat4 *m)
{
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(m->m[i][j]))
                return false;
    return true;
}

rt_result rt_mesh_commit(rt_scene *s, rt_mesh_buf *b, const rt_mat4 *transform, const char *name, rt_error *err)
{
    rt_mat4 m = transform ? *transform : rt_mat4_identity();
    rt_mat4 nm;
    if (!mat_finite(&m))
        return rt_fail(err, RT_ERR_INVALID, "%s: mesh transform has non-finite entries", name);
    if (!rt_mat4_normal_matrix(&m, &nm))
        return rt_fail(err, RT_ERR_INVALID, "%s: mesh transform is singular (a scale of 0?)", name);
    bool flip = rt_mat4_det3(&m) < 0.0f;
    bool identity = memcmp(&m, &(rt_mat4){{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}}, sizeof m) == 0;

    if (!identity) {
        for (size_t i = 0; i < b->nv; i++) {
            rt_vec3 p = rt_mat4_point(&m, b->pos[i]);
            if (!rt_finite3(p))
                return rt_fail(err, RT_ERR_INVALID, "%s: vertex %zu is not finite after the mesh transform", name,
                               i + 1);
            b->pos[i] = p;
        }
    }
    if (b->nrm)
        for (size_t i = 0; i < b->nv; i++) {
            rt_vec3 n = identity ? b->nrm[i] : rt_mat4_vector(&nm, b->nrm[i]);
            n = rt_normalize(n);
            b->nrm[i] = rt_finite3(n) ? n : rt_v3s(0);
        }
    for (size_t t = 0; t < b->nt; t++) {
        uint32_t *ix = b->idx + 3 * t;
        if (flip) {
            uint32_t tmp = ix[1];
            ix[1] = ix[2];
            ix[2] = tmp;
        }
        if (b->flags[t] & RT_TRI_SMOOTH) {
            /* smooth shading needs a usable normal at every corner */
            if (!b->nrm || rt_length2(b->nrm[ix[0]]) == 0.0f || rt_length2(b->nrm[ix[1]]) == 0.0f ||
                rt_length2(b->nrm[ix[2]]) == 0.0f)
                b->flags[t] &= (uint8_t)~RT_TRI_SMOOTH;
        }
        if (!b->uv)
            b->flags[t] &= (uint8_t)~RT_TRI_UV;
        if (!b->col)
            b->flags[t] &= (uint8_t)~RT_TRI_COLOR;
    }

    if (s->triangles.count + b->nt >= RT_NONE)
        return rt_fail(err, RT_ERR_LIMIT, "%s: the scene would have over 2^32 triangles", name);
    if (b->nt == 0) {
        /* a point cloud, or every face skipped: nothing to add */
        rt_warn("%s: no triangles in the file", name);
        return RT_OK;
    }
    /* a material index the scene does not have (RT_NONE from a caller with no default)
     * becomes a default material, added once */
    uint32_t fallback = RT_NONE;
    for (size_t t = 0; t < b->nt; t++) {
        if (b->mat[t] < s->material_count)
            continue;
        if (fallback == RT_NONE) {
            rt_material dm;
            char mname[sizeof dm.name];
            snprintf(mname, sizeof mname, "%.50s:default", rt_path_basename(name));
            rt_material_default(&dm, mname);
            if ((fallback = rt_scene_add_material(s, &dm)) == RT_NONE)
                return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for a material", name);
        }
        b->mat[t] = fallback;
    }
    if (!rt_scene_reserve_triangles(s, b->nt))
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %zu triangles", name, b->nt);
    if (b->col && !rt_scene_enable_attr(s, RT_ATTR_COLOR))
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for vertex colours", name);
    uint32_t first = rt_scene_add_vertices(s, b->nv);
    if (first == RT_NONE)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %zu vertices (or over 2^32)", name, b->nv);
    rt_vertices *v = &s->vertices;
    memcpy(v->position + first, b->pos, b->nv * sizeof *b->pos);
    if (b->nrm)
        memcpy(v->normal + first, b->nrm, b->nv * sizeof *b->nrm);
    if (b->uv)
        memcpy(v->uv0 + first, b->uv, b->nv * sizeof *b->uv);
    if (b->col)
        memcpy(v->color + first, b->col, b->nv * sizeof *b->col);
    rt_triangles *tr = &s->triangles;
    size_t t0 = tr->count;
    for (size_t t = 0; t < b->nt; t++) {
        tr->index[3 * (t0 + t)] = first + b->idx[3 * t];
        tr->index[3 * (t0 + t) + 1] = first + b->idx[3 * t + 1];
        tr->index[3 * (t0 + t) + 2] = first + b->idx[3 * t + 2];
    }
    memcpy(tr->material + t0, b->mat, b->nt * sizeof *b->mat);
    memcpy(tr->flags + t0, b->flags, b->nt);
    tr->count += b->nt;
    return RT_OK;
}
