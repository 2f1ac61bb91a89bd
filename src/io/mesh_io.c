/* mesh_io.c - mesh loading entry point and what the OBJ, PLY and OFF readers
 * share: whole-file reading, locale-free number parsing, the local mesh
 * buffer and the transform-and-append step.
 *
 * Dispatch is by the file's extension, case-insensitive: .obj, .ply, .off.
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
 *
 * Float parsing: decimal digits are accumulated into a 64-bit integer m with a
 * decimal exponent e. When m <= 2^53 and |e| <= 22, m and 10^|e| are exact
 * doubles and one IEEE multiply or divide gives the correctly rounded double
 * (Clinger, "How to Read Floating Point Numbers Accurately", PLDI 1990). That
 * double rounds to the correctly rounded float unless it lies exactly on a
 * midpoint between two floats (any midpoint strictly between the true value
 * and the double would be a closer double), so only that case, subnormal or
 * huge results and long mantissas fall back to strtof on a bounded copy.
 * rt never calls setlocale(), so strtof sees the "C" locale's '.'.
 */
#include "rt/io/mesh_io.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"
#include "rt/base/file.h"

/* ------------------------------------------------------------ dispatch */

static int ascii_lower(int c) { return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c; }

rt_result rt_mesh_load(rt_scene *s, const char *path, const rt_mat4 *transform, uint32_t material,
                       bool override_material, rt_mesh_load_stats *stats, rt_error *err)
{
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (!path)
        return rt_fail(err, RT_ERR_INVALID, "mesh: no path given");
    if (rt_path_has_ext(path, ".obj"))
        return rt_obj_load(s, path, transform, material, override_material, stats, err);
    if (rt_path_has_ext(path, ".ply"))
        return rt_ply_load(s, path, transform, material, override_material, stats, err);
    if (rt_path_has_ext(path, ".off"))
        return rt_off_load(s, path, transform, material, override_material, stats, err);
    const char *ext = rt_path_ext(path);
    if (!*ext)
        return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: no file extension; meshes must be .obj, .ply or .off", path);
    return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: unknown mesh format '%s' (expected .obj, .ply or .off)", path,
                   ext);
}

bool rt_warn_once_first(rt_warn_once *w, const char *key, size_t len)
{
    const size_t keep = sizeof w->seen[0] - 1;
    if (len > keep)
        len = keep;
    for (int i = 0; i < w->count; i++)
        if (strlen(w->seen[i]) == len && memcmp(w->seen[i], key, len) == 0)
            return false;
    if (w->count >= (int)(sizeof w->seen / sizeof w->seen[0]))
        return false;
    memcpy(w->seen[w->count], key, len);
    w->seen[w->count][len] = 0;
    w->count++;
    return true;
}

/* ------------------------------------------------------------- numbers */

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

const char *rt_mesh_parse_int(const char *p, const char *end, int64_t *out)
{
    bool neg = false;
    if (p < end && (*p == '-' || *p == '+')) {
        neg = *p == '-';
        p++;
    }
    if (p >= end || !is_digit(*p))
        return NULL;
    uint64_t v = 0;
    while (p < end && is_digit(*p)) {
        v = v * 10 + (uint64_t)(*p - '0');
        if (v > ((uint64_t)1 << 62))
            return NULL; /* far beyond any count or index we accept */
        p++;
    }
    *out = neg ? -(int64_t)v : (int64_t)v;
    return p;
}

static const double pow10_exact[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                       1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static bool word_at(const char *p, const char *end, const char *w)
{
    for (; *w; w++, p++)
        if (p >= end || ascii_lower((unsigned char)*p) != *w)
            return false;
    return true;
}

const char *rt_mesh_parse_float(const char *p, const char *end, float *out, bool *nonfinite)
{
    const char *start = p;
    *nonfinite = false;
    bool neg = false;
    if (p < end && (*p == '-' || *p == '+')) {
        neg = *p == '-';
        p++;
    }
    if (p < end && (word_at(p, end, "nan") || word_at(p, end, "inf"))) {
        *nonfinite = true;
        return NULL;
    }
    uint64_t m = 0;
    int digits = 0;     /* significant digits kept in m */
    long exp10 = 0;
    bool any = false, inexact = false;
    while (p < end && is_digit(*p)) {
        any = true;
        if (digits < 19) {
            m = m * 10 + (uint64_t)(*p - '0');
            if (m)
                digits++;
        } else {
            exp10++;
            if (*p != '0')
                inexact = true;
        }
        p++;
    }
    if (p < end && *p == '.') {
        p++;
        while (p < end && is_digit(*p)) {
            any = true;
            if (digits < 19) {
                m = m * 10 + (uint64_t)(*p - '0');
                if (m)
                    digits++;
                exp10--;
            } else if (*p != '0') {
                inexact = true;
            }
            p++;
        }
    }
    if (!any)
        return NULL;
    if (p < end && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        bool eneg = false;
        if (q < end && (*q == '-' || *q == '+')) {
            eneg = *q == '-';
            q++;
        }
        if (q < end && is_digit(*q)) {
            long e = 0;
            while (q < end && is_digit(*q)) {
                if (e < 100000)
                    e = e * 10 + (*q - '0');
                q++;
            }
            exp10 += eneg ? -e : e;
            p = q;
        } /* else: a bare 'e' is not part of the number; the caller sees it */
    }
    if (m == 0) {
        *out = neg ? -0.0f : 0.0f;
        return p;
    }
    if (!inexact && m <= ((uint64_t)1 << 53) && exp10 >= -22 && exp10 <= 22) {
        double d = (double)m;
        d = exp10 < 0 ? d / pow10_exact[-exp10] : d * pow10_exact[exp10];
        if (d >= (double)FLT_MIN && d <= (double)FLT_MAX) {
            uint64_t bits;
            memcpy(&bits, &d, sizeof bits);
            /* a double on a float midpoint has exactly bit 28 set below the float's 24 bits */
            if ((bits & 0x1FFFFFFFu) != 0x10000000u) {
                float f = (float)d;
                *out = neg ? -f : f;
                return p;
            }
        }
    }
    /* slow path: strtof on a bounded NUL-terminated copy */
    char buf[512];
    size_t len = (size_t)(p - start);
    if (len >= sizeof buf)
        return NULL;
    memcpy(buf, start, len);
    buf[len] = 0;
    char *e = NULL;
    errno = 0;
    float f = strtof(buf, &e);
    if (e != buf + len)
        return NULL;
    if (!isfinite(f)) {
        *nonfinite = true;
        return NULL;
    }
    *out = f;
    return p;
}

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

static bool grow_to(void **p, size_t cap, size_t elem)
{
    void *q = rt_realloc_array(*p, cap, elem);
    if (!q)
        return false;
    *p = q;
    return true;
}

static size_t next_cap(size_t cap, size_t need)
{
    size_t c = cap ? cap : 256;
    while (c < need) {
        if (c > SIZE_MAX / 4)
            return need;
        c *= 2;
    }
    return c;
}

bool rt_mesh_buf_reserve_vertices(rt_mesh_buf *b, size_t need)
{
    if (need <= b->vcap)
        return true;
    if (need >= RT_NONE)
        return false;
    size_t c = next_cap(b->vcap, need);
    if (c >= RT_NONE)
        c = need;
    if (!grow_to((void **)&b->pos, c, sizeof *b->pos))
        return false;
    if (b->nrm && !grow_to((void **)&b->nrm, c, sizeof *b->nrm))
        return false;
    if (b->uv && !grow_to((void **)&b->uv, c, sizeof *b->uv))
        return false;
    if (b->col && !grow_to((void **)&b->col, c, sizeof *b->col))
        return false;
    b->vcap = c;
    return true;
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
    size_t c = next_cap(b->tcap, need);
    if (c >= RT_NONE)
        c = need;
    if (!grow_to((void **)&b->idx, c, 3 * sizeof *b->idx) || !grow_to((void **)&b->mat, c, sizeof *b->mat) ||
        !grow_to((void **)&b->flags, c, sizeof *b->flags))
        return false;
    b->tcap = c;
    return true;
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

rt_result rt_mesh_commit(rt_scene *s, rt_mesh_buf *b, const rt_mat4 *transform, const char *path,
                         rt_mesh_load_stats *stats, rt_error *err)
{
    rt_mat4 m = transform ? *transform : rt_mat4_identity();
    rt_mat4 nm;
    if (!mat_finite(&m))
        return rt_fail(err, RT_ERR_INVALID, "%s: mesh transform has non-finite entries", path);
    if (!rt_mat4_normal_matrix(&m, &nm))
        return rt_fail(err, RT_ERR_INVALID, "%s: mesh transform is singular (a scale of 0?)", path);
    bool flip = rt_mat4_det3(&m) < 0.0f;
    bool identity = memcmp(&m, &(rt_mat4){{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}}, sizeof m) == 0;

    if (!identity) {
        for (size_t i = 0; i < b->nv; i++) {
            rt_vec3 p = rt_mat4_point(&m, b->pos[i]);
            if (!rt_finite3(p))
                return rt_fail(err, RT_ERR_INVALID, "%s: vertex %zu is not finite after the mesh transform", path,
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
        return rt_fail(err, RT_ERR_LIMIT, "%s: the scene would have over 2^32 triangles", path);
    if (b->nt == 0) {
        /* a point cloud, or every face skipped: nothing to add */
        rt_warn("%s: no triangles in the file", path);
        if (stats)
            stats->skipped_faces += b->skipped;
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
            char name[sizeof dm.name];
            snprintf(name, sizeof name, "%.50s:default", rt_path_basename(path));
            rt_material_default(&dm, name);
            if ((fallback = rt_scene_add_material(s, &dm)) == RT_NONE)
                return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for a material", path);
        }
        b->mat[t] = fallback;
    }
    if (!rt_scene_reserve_triangles(s, b->nt))
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %zu triangles", path, b->nt);
    if (b->col && !rt_scene_enable_attr(s, RT_ATTR_COLOR))
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for vertex colours", path);
    uint32_t first = rt_scene_add_vertices(s, b->nv);
    if (first == RT_NONE)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %zu vertices (or over 2^32)", path, b->nv);
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
    if (stats) {
        stats->triangles += b->nt;
        stats->vertices += b->nv;
        stats->skipped_faces += b->skipped;
    }
    return RT_OK;
}
