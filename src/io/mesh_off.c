/* mesh_off.c - Geomview OFF meshes (and the COFF, NOFF, STOFF, CNOFF...
 * variants).
 *
 * Reference: the Geomview manual, "OFF Files" (geomview.org/docs/html/OFF.html).
 *
 *   [ST][C][N]OFF            header keyword (the counts may follow on the same line)
 *   NVertices NFaces [NEdges]
 *   x y z [nx ny nz] [r g b [a]] [s t]     one line per vertex
 *   n i1 i2 ... in [colour]                one line per face, 0-based indices
 *
 * Algorithm: the file is read whole and walked line by line; '#' starts a
 * comment and blank lines are skipped. The counts are checked against the
 * bytes left before anything is allocated (a vertex line takes at least 6
 * bytes, a face line 8). Vertex colours (C) become vertex colours (values
 * above 1 are taken as 0..255), normals (N) smooth shading, texture
 * coordinates (ST) UVs with v flipped (see mesh_buffer.c). Faces are
 * triangulated by rt_mesh_triangulate (fans, concave quads, ear clipping);
 * per-face colours are ignored; faces with fewer than
 * 3 vertices and triangles that repeat a vertex are skipped and counted.
 * 4OFF, nOFF and binary OFF are refused. Errors name "path:line:col".
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_buffer.h"
#include "mesh_readers.h"
#include "mesh_text.h"
#include "rt/base/log.h"
#include "rt/base/alloc.h"

typedef struct off_lines {
    const char *path;
    const char *p, *end;
    long line;
    const char *ls, *le; /* current line, comment cut off */
} off_lines;

/* Advances to the next line with something on it; false at end of file. */
static bool next_line(off_lines *L)
{
    while (L->p < L->end) {
        const char *nl = memchr(L->p, '\n', (size_t)(L->end - L->p));
        const char *eol = nl ? nl : L->end;
        L->line++;
        L->ls = L->p;
        L->p = nl ? nl + 1 : L->end;
        const char *h = memchr(L->ls, '#', (size_t)(eol - L->ls));
        L->le = h ? h : eol;
        const char *q = L->ls;
        while (q < L->le && rt_mesh_is_space(*q))
            q++;
        if (q < L->le)
            return true;
    }
    return false;
}

static rt_result bad_token(const off_lines *L, rt_error *err, const char *tok, const char *te, const char *what)
{
    return rt_fail(err, RT_ERR_PARSE, "%s:%ld:%d: %s '%.*s'", L->path, L->line, (int)(tok - L->ls) + 1, what,
                   (int)(te - tok > 40 ? 40 : te - tok), tok);
}

/* Reads up to max integers from [p, le); returns the count or -1 (err filled). */
static int read_ints(const off_lines *L, const char *p, int64_t *out, int max, rt_error *err)
{
    int n = 0;
    for (p = rt_mesh_skip_space(p, L->le); p < L->le && n < max; p = rt_mesh_skip_space(p, L->le)) {
        const char *te = rt_mesh_token_end(p, L->le);
        const char *q = rt_mesh_parse_int(p, te, &out[n]);
        if (!q || q != te) {
            bad_token(L, err, p, te, "expected an integer, got");
            return -1;
        }
        n++;
        p = te;
    }
    return n;
}

/* What the header says: the [ST][C][N] prefixes and the two counts. */
typedef struct off_header {
    bool st, col, nrm; /* texture coordinates, colours, normals on each vertex line */
    uint64_t nv, nf;
} off_header;

/* The [ST][C][N]OFF keyword and the counts after it (on its line or the
 * next), checked against the bytes left. */
static rt_result read_header(off_lines *L, rt_error *err, off_header *h)
{
    const char *path = L->path;
    if (!next_line(L))
        return rt_fail(err, RT_ERR_PARSE, "%s: empty file, expected an OFF header", path);
    const char *kw = rt_mesh_skip_space(L->ls, L->le), *kwe = rt_mesh_token_end(kw, L->le);
    h->st = h->col = h->nrm = false;
    const char *k = kw;
    if (kwe - k >= 2 && k[0] == 'S' && k[1] == 'T') { h->st = true; k += 2; }
    if (k < kwe && *k == 'C') { h->col = true; k++; }
    if (k < kwe && *k == 'N') { h->nrm = true; k++; }
    if (k < kwe && (*k == '4' || *k == 'n'))
        return rt_fail(err, RT_ERR_UNSUPPORTED, "%s:%ld:1: '%.*s': 4D and n-dimensional OFF are not supported", path,
                       L->line, (int)(kwe - kw > 40 ? 40 : kwe - kw), kw);
    if (kwe - k != 3 || memcmp(k, "OFF", 3) != 0)
        return bad_token(L, err, kw, kwe, "not an OFF file: expected [ST][C][N]OFF, got");
    /* counts: on the header line or the next line */
    const char *cp = rt_mesh_skip_space(kwe, L->le);
    if (cp < L->le && rt_mesh_token_end(cp, L->le) - cp == 6 && memcmp(cp, "BINARY", 6) == 0)
        return rt_fail(err, RT_ERR_UNSUPPORTED, "%s:%ld: binary OFF is not supported", path, L->line);
    if (cp >= L->le) {
        if (!next_line(L))
            return rt_fail(err, RT_ERR_PARSE, "%s:%ld: expected the vertex and face counts", path, L->line);
        cp = L->ls;
    }
    int64_t cnt[3];
    int nc = read_ints(L, cp, cnt, 3, err);
    if (nc < 0)
        return err->code;
    if (nc < 2 || cnt[0] < 0 || cnt[1] < 0)
        return rt_fail(err, RT_ERR_PARSE, "%s:%ld: expected 'vertices faces [edges]' counts", path, L->line);
    h->nv = (uint64_t)cnt[0];
    h->nf = (uint64_t)cnt[1];
    uint64_t left = (uint64_t)(L->end - L->p);
    if (h->nv > left / 6 + 1 || h->nf > left / 8 + 1 || h->nv * 6 + h->nf * 8 > left + 16)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s:%ld: counts (%llu vertices, %llu faces) do not fit in the %llu bytes left", path, L->line,
                       (unsigned long long)h->nv, (unsigned long long)h->nf, (unsigned long long)left);
    if (h->nv >= RT_NONE)
        return rt_fail(err, RT_ERR_LIMIT, "%s:%ld: too many vertices", path, L->line);
    return RT_OK;
}

/* Vertex i: one line of position [normal] [colour] [uv]. */
static rt_result read_vertex(off_lines *L, rt_error *err, const off_header *h, uint64_t i, rt_mesh_buf *b)
{
    const char *path = L->path;
    int need = 3 + (h->nrm ? 3 : 0) + (h->st ? 2 : 0);
    if (!next_line(L))
        return rt_fail(err, RT_ERR_PARSE, "%s:%ld: file ends after %llu of %llu vertices", path, L->line,
                       (unsigned long long)i, (unsigned long long)h->nv);
    float f[16];
    int n = 0;
    for (const char *p = rt_mesh_skip_space(L->ls, L->le); p < L->le && n < 16; p = rt_mesh_skip_space(p, L->le)) {
        const char *te = rt_mesh_token_end(p, L->le);
        bool nonfinite;
        const char *q = rt_mesh_parse_float(p, te, &f[n], &nonfinite);
        if (!q || q != te)
            return bad_token(L, err, p, te, nonfinite ? "number is not finite:" : "malformed number");
        n++;
        p = te;
    }
    int ncol = h->col ? n - need : 0;
    if ((!h->col && n != need) || (h->col && ncol != 3 && ncol != 4))
        return rt_fail(err, RT_ERR_PARSE, "%s:%ld: vertex %llu has %d numbers, expected %d%s (one vertex a line)", path, L->line,
                       (unsigned long long)i, n, need, h->col ? " plus 3 or 4 colour components" : "");
    size_t v = (size_t)i;
    b->pos[v] = rt_v3(f[0], f[1], f[2]);
    int at = 3;
    if (h->nrm) {
        b->nrm[v] = rt_v3(f[3], f[4], f[5]);
        at = 6;
    }
    if (h->col) {
        rt_vec4 c = rt_v4(f[at], f[at + 1], f[at + 2], ncol == 4 ? f[at + 3] : 1.0f);
        if (c.x > 1.0f || c.y > 1.0f || c.z > 1.0f || c.w > 1.0f)
            c = rt_v4(c.x / 255.0f, c.y / 255.0f, c.z / 255.0f, ncol == 4 ? c.w / 255.0f : 1.0f);
        b->col[v] = c;
        at += ncol;
    }
    if (h->st)
        b->uv[v] = rt_v2(f[at], 1.0f - f[at + 1]);
    return RT_OK;
}

/* Face i's vertex indices into *face (grown as needed), their count in *n;
 * the rest of the line (a face colour) is ignored. */
static rt_result read_face(off_lines *L, rt_error *err, uint64_t nv, uint64_t i, uint32_t **face, size_t *fcap,
                           int64_t *count)
{
    const char *path = L->path;
    const char *p = rt_mesh_skip_space(L->ls, L->le), *te = rt_mesh_token_end(p, L->le);
    int64_t n;
    const char *q = rt_mesh_parse_int(p, te, &n);
    if (!q || q != te || n < 0)
        return bad_token(L, err, p, te, "expected a face's vertex count, got");
    if ((uint64_t)n > (uint64_t)(L->le - L->ls))
        return rt_fail(err, RT_ERR_PARSE, "%s:%ld: face %llu claims %lld vertices, more than the line holds", path,
                       L->line, (unsigned long long)i, (long long)n);
    if ((size_t)n > *fcap && !rt_grow((void **)face, fcap, (size_t)n, sizeof **face))
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
    p = te;
    for (int64_t j = 0; j < n; j++) {
        p = rt_mesh_skip_space(p, L->le);
        te = rt_mesh_token_end(p, L->le);
        int64_t v;
        q = p < L->le ? rt_mesh_parse_int(p, te, &v) : NULL;
        if (p >= L->le)
            return rt_fail(err, RT_ERR_PARSE, "%s:%ld: face %llu has %lld of its %lld vertex indices", path, L->line,
                           (unsigned long long)i, (long long)j, (long long)n);
        if (!q || q != te)
            return bad_token(L, err, p, te, "expected a vertex index, got");
        if (v < 0 || (uint64_t)v >= nv)
            return rt_fail(err, RT_ERR_INVALID, "%s:%ld:%d: vertex index %lld out of range (%llu vertices)", path,
                           L->line, (int)(p - L->ls) + 1, (long long)v, (unsigned long long)nv);
        (*face)[j] = (uint32_t)v;
        p = te;
    }
    *count = n;
    return RT_OK;
}

rt_result rt_off_parse(const rt_mesh_input *in, rt_mesh_buf *b)
{
    /* OFF has no materials: every face takes in->material */
    const char *path = in->name;
    rt_error *err = in->err;
    rt_result r = RT_OK;
    uint32_t *face = NULL, *tri = NULL;
    size_t fcap = 0, tcap = 0;
    off_lines L = {path, in->bytes, in->bytes + in->size, 0, in->bytes, in->bytes};

    off_header h = {0};
    if ((r = read_header(&L, err, &h)) != RT_OK)
        return r;
    unsigned attrs = (h.nrm ? RT_MESH_NRM : 0) | (h.st ? RT_MESH_UV : 0) | (h.col ? RT_MESH_COL : 0);
    if (!rt_mesh_buf_enable(b, attrs) || !rt_mesh_buf_reserve_vertices(b, (size_t)h.nv) ||
        !rt_mesh_buf_reserve_triangles(b, (size_t)h.nf))
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
    uint8_t flags = (uint8_t)((h.nrm ? RT_TRI_SMOOTH : 0) | (h.st ? RT_TRI_UV : 0) | (h.col ? RT_TRI_COLOR : 0));

    for (uint64_t i = 0; i < h.nv; i++)
        if ((r = read_vertex(&L, err, &h, i, b)) != RT_OK)
            return r;
    b->nv = (size_t)h.nv;

    bool warned_short = false;
    for (uint64_t i = 0; i < h.nf; i++) {
        if (!next_line(&L)) {
            r = rt_fail(err, RT_ERR_PARSE, "%s:%ld: file ends after %llu of %llu faces", path, L.line,
                        (unsigned long long)i, (unsigned long long)h.nf);
            goto done;
        }
        int64_t n = 0;
        if ((r = read_face(&L, err, h.nv, i, &face, &fcap, &n)) != RT_OK)
            goto done;
        if (n < 3) {
            b->skipped++;
            if (!warned_short) {
                warned_short = true;
                rt_warn("%s:%ld: face with %lld vertices skipped (warned once)", path, L.line, (long long)n);
            }
            continue;
        }
        if (3 * ((size_t)n - 2) > tcap && !rt_grow((void **)&tri, &tcap, 3 * ((size_t)n - 2), sizeof *tri)) {
            r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
            goto done;
        }
        size_t nt = rt_mesh_triangulate(b->pos, face, (size_t)n, tri);
        for (size_t j = 0; j < nt; j++) {
            uint32_t ca = face[tri[3 * j]], cb = face[tri[3 * j + 1]], cc = face[tri[3 * j + 2]];
            if (ca == cb || cb == cc || ca == cc) {
                b->skipped++;
                continue;
            }
            if (!rt_mesh_buf_add_triangle(b, ca, cb, cc, in->material, flags)) {
                r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for triangles", path);
                goto done;
            }
        }
    }
done:
    free(face);
    free(tri);
    return r;
}
