/* mesh_ply.c - Stanford PLY meshes: ascii, binary_little_endian and
 * binary_big_endian.
 *
 * Reference: Greg Turk, "The PLY Polygon File Format" (1994), and the
 * property names real files use (MeshLab, Blender, the Stanford scans).
 *
 * Algorithm: the header is parsed into a table of elements, each with its
 * properties (scalar type, or list count type + item type). Before anything
 * is allocated the header's counts are checked against the bytes that follow
 * it: every element instance needs at least the size of its scalars and list
 * counts (binary) or two characters per property (ascii), so a header that
 * claims billions of vertices in a small file fails at once. The body is then
 * read element by element in file order through one reader that knows the
 * encoding; unknown elements and properties, lists included, are read and
 * dropped.
 *   vertex:    x y z; nx ny nz (smooth shading); u v, s t, texture_u texture_v
 *              or texture_s texture_t (v flipped, see mesh_buffer.c); red green
 *              blue [alpha] (integers divided by their type's maximum, so
 *              uchar / 255; floats as they are) -> vertex colours.
 *   face:      list vertex_indices (or vertex_index) of any length,
 *              triangulated by rt_mesh_triangulate (fan, concave quads and
 *              ear clipping; a plain fan if the faces come before the
 *              vertices); lists shorter than 3 are skipped with a warning
 *              and counted.
 *   tristrips: list vertex_indices; -1 (or an unsigned type's maximum)
 *              ends a strip and starts the next;
 *              the winding alternates within each strip (even triangles
 *              (a, b, c), odd ones (b, a, c)); triangles that repeat an index
 *              (the stitching between strips) are dropped silently.
 * Triangles that repeat a vertex index in faces are skipped and counted.
 * Errors name "path:line: ..." (ascii) or "path: byte N: ..." (binary).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_buffer.h"
#include "mesh_readers.h"
#include "mesh_text.h"
#include "rt/base/log.h"
#include "rt/base/alloc.h"

typedef enum ply_type { PT_NONE = 0, PT_I8, PT_U8, PT_I16, PT_U16, PT_I32, PT_U32, PT_F32, PT_F64 } ply_type;
static const int type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};

enum ply_format { PF_ASCII = 0, PF_LE, PF_BE };

enum ply_role {
    R_SKIP = 0,
    R_X, R_Y, R_Z, R_NX, R_NY, R_NZ, R_U, R_V, R_R, R_G, R_B, R_A,
    R_INDICES, /* the list a face or tristrips element is made of */
};

enum ply_kind { K_OTHER = 0, K_VERTEX, K_FACE, K_STRIPS };

typedef struct ply_prop {
    char name[64];
    ply_type type;       /* scalar type, or the list's item type */
    ply_type count_type; /* PT_NONE for a scalar */
    int role;
} ply_prop;

typedef struct ply_elem {
    char name[64];
    uint64_t count;
    size_t first_prop, nprops;
    int kind;
} ply_elem;

typedef struct ply_reader {
    const char *path;
    const unsigned char *data;
    size_t size, pos;
    int format;
    long line; /* ascii: current line */
    rt_error *err;
} ply_reader;

/* ------------------------------------------------------------- errors */

RT_PRINTF(2, 3) static bool fail_at(ply_reader *r, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (r->format == PF_ASCII)
        rt_fail(r->err, RT_ERR_PARSE, "%s:%ld: %s", r->path, r->line, msg);
    else
        rt_fail(r->err, RT_ERR_PARSE, "%s: byte %zu: %s", r->path, r->pos, msg);
    return false;
}

/* ------------------------------------------------------------ values */

static ply_type parse_type(const char *t, size_t n)
{
    static const struct { const char *name; ply_type type; } names[] = {
        {"char", PT_I8},   {"int8", PT_I8},     {"uchar", PT_U8},   {"uint8", PT_U8},     {"short", PT_I16},
        {"int16", PT_I16}, {"ushort", PT_U16},  {"uint16", PT_U16}, {"int", PT_I32},      {"int32", PT_I32},
        {"uint", PT_U32},  {"uint32", PT_U32},  {"float", PT_F32},  {"float32", PT_F32},  {"double", PT_F64},
        {"float64", PT_F64},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strlen(names[i].name) == n && memcmp(names[i].name, t, n) == 0)
            return names[i].type;
    return PT_NONE;
}

static bool is_float_type(ply_type t) { return t == PT_F32 || t == PT_F64; }

/* Loads an n-byte unsigned integer stored little- or big-endian (the shift
 * forms compile to plain loads and byte swaps). */
static inline uint64_t load_bytes(const unsigned char *p, int n, bool big)
{
    switch (n) {
    case 1: return p[0];
    case 2: return big ? (uint64_t)p[0] << 8 | p[1] : (uint64_t)p[1] << 8 | p[0];
    case 4:
        return big ? (uint64_t)((uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3])
                   : (uint64_t)((uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0]);
    default: {
        uint64_t v = 0;
        if (big)
            for (int i = 0; i < n; i++)
                v = (v << 8) | p[i];
        else
            for (int i = n; i-- > 0;)
                v = (v << 8) | p[i];
        return v;
    }
    }
}

/* Binary: one value of type t as int64 (integers) or double (floats). */
static inline bool bin_value(ply_reader *r, ply_type t, int64_t *iv, double *dv)
{
    int n = type_size[t];
    if (r->size - r->pos < (size_t)n)
        return fail_at(r, "unexpected end of file (file is %zu bytes)", r->size);
    uint64_t u = load_bytes(r->data + r->pos, n, r->format == PF_BE);
    r->pos += (size_t)n;
    switch (t) {
    case PT_I8: *iv = (int8_t)(uint8_t)u; break;
    case PT_U8: *iv = (int64_t)u; break;
    case PT_I16: *iv = (int16_t)(uint16_t)u; break;
    case PT_U16: *iv = (int64_t)u; break;
    case PT_I32: *iv = (int32_t)(uint32_t)u; break;
    case PT_U32: *iv = (int64_t)u; break;
    case PT_F32: {
        uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, 4);
        *dv = f;
        return true;
    }
    case PT_F64: memcpy(dv, &u, 8); return true;
    default: r->pos -= (size_t)n; return fail_at(r, "internal: bad type");
    }
    *dv = (double)*iv;
    return true;
}

/* Decodes one binary value whose bytes are known to be in the file. */
static inline double bin_decode(const unsigned char *q, ply_type t, bool big, int64_t *iv)
{
    uint64_t u = load_bytes(q, type_size[t], big);
    switch (t) {
    case PT_I8: *iv = (int8_t)(uint8_t)u; break;
    case PT_I16: *iv = (int16_t)(uint16_t)u; break;
    case PT_I32: *iv = (int32_t)(uint32_t)u; break;
    case PT_F32: {
        uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, 4);
        *iv = 0;
        return f;
    }
    case PT_F64: {
        double d;
        memcpy(&d, &u, 8);
        *iv = 0;
        return d;
    }
    default: *iv = (int64_t)u; break; /* unsigned types */
    }
    return (double)*iv;
}

/* Ascii: the next whitespace-separated token (newlines counted). */
static bool ascii_token(ply_reader *r, const char **tok, const char **tend)
{
    const char *d = (const char *)r->data;
    size_t i = r->pos;
    for (;;) {
        while (i < r->size && (rt_mesh_is_space(d[i]) || d[i] == '\n')) {
            if (d[i] == '\n')
                r->line++;
            i++;
        }
        if (i >= r->size) {
            r->pos = i;
            return fail_at(r, "unexpected end of file");
        }
        break;
    }
    size_t j = i;
    while (j < r->size && !rt_mesh_is_space(d[j]) && d[j] != '\n')
        j++;
    *tok = d + i;
    *tend = d + j;
    r->pos = j;
    return true;
}

static bool ascii_value(ply_reader *r, ply_type t, int64_t *iv, double *dv)
{
    const char *tok = NULL, *te = NULL;
    if (!ascii_token(r, &tok, &te))
        return false;
    int len = (int)(te - tok > 40 ? 40 : te - tok);
    if (is_float_type(t)) {
        float f;
        bool nonfinite;
        const char *q = rt_mesh_parse_float(tok, te, &f, &nonfinite);
        if (!q || q != te)
            return fail_at(r, "%s '%.*s'", nonfinite ? "number is not finite:" : "malformed number", len, tok);
        *dv = f;
        return true;
    }
    const char *q = rt_mesh_parse_int(tok, te, iv);
    if (!q || q != te) {
        /* some writers print integers as "3.0" */
        float f;
        bool nonfinite;
        q = rt_mesh_parse_float(tok, te, &f, &nonfinite);
        /* range first: converting an out-of-range (or NaN) float to an integer is undefined */
        if (!q || q != te || !(f >= -2147483648.0f && f <= 4294967295.0f) || f != (float)(int64_t)f)
            return fail_at(r, "malformed integer '%.*s'", len, tok);
        *iv = (int64_t)f;
    }
    static const int64_t lo[] = {0, -128, 0, -32768, 0, INT32_MIN, 0};
    static const int64_t hi[] = {0, 127, 255, 32767, 65535, INT32_MAX, UINT32_MAX};
    if (*iv < lo[t] || *iv > hi[t])
        return fail_at(r, "integer %.*s out of range for its type", len, tok);
    *dv = (double)*iv;
    return true;
}

static inline bool read_value(ply_reader *r, ply_type t, int64_t *iv, double *dv)
{
    return r->format == PF_ASCII ? ascii_value(r, t, iv, dv) : bin_value(r, t, iv, dv);
}

/* A list's length, checked against the bytes left before anything loops over
 * or allocates for it: binary items take their size, ascii ones at least two
 * characters (the last may end the file). */
static bool read_count(ply_reader *r, ply_type ct, ply_type item, int64_t *n)
{
    double d;
    size_t at = r->pos;
    if (!read_value(r, ct, n, &d))
        return false;
    if (*n < 0) {
        r->pos = at;
        return fail_at(r, "negative list length %lld", (long long)*n);
    }
    size_t left = r->size - r->pos;
    size_t fit = r->format == PF_ASCII ? (left + 1) / 2 : left / (size_t)type_size[item];
    if ((uint64_t)*n > fit) {
        r->pos = at;
        return fail_at(r, "list of %lld entries runs past the end of the file", (long long)*n);
    }
    return true;
}

/* Reads and drops one property value (a whole list for list properties). */
static bool skip_prop(ply_reader *r, const ply_prop *p)
{
    int64_t iv;
    double dv;
    if (p->count_type == PT_NONE)
        return read_value(r, p->type, &iv, &dv);
    int64_t n;
    if (!read_count(r, p->count_type, p->type, &n))
        return false;
    if (r->format != PF_ASCII) {
        r->pos += (size_t)n * (size_t)type_size[p->type]; /* read_count checked it fits */
        return true;
    }
    for (int64_t i = 0; i < n; i++)
        if (!read_value(r, p->type, &iv, &dv))
            return false;
    return true;
}

/* ------------------------------------------------------------ header */

typedef struct ply_file {
    ply_elem *elems; size_t nelem, elemcap;
    ply_prop *props; size_t nprop, propcap;
} ply_file;

static bool word_eq(const char *a, size_t n, const char *w) { return strlen(w) == n && memcmp(a, w, n) == 0; }

static int vertex_role(const char *n, size_t l)
{
    static const struct { const char *name; int role; } roles[] = {
        {"x", R_X}, {"y", R_Y}, {"z", R_Z}, {"nx", R_NX}, {"ny", R_NY}, {"nz", R_NZ},
        {"u", R_U}, {"v", R_V}, {"s", R_U}, {"t", R_V}, {"texture_u", R_U}, {"texture_v", R_V},
        {"texture_s", R_U}, {"texture_t", R_V}, {"red", R_R}, {"green", R_G}, {"blue", R_B}, {"alpha", R_A},
        {"diffuse_red", R_R}, {"diffuse_green", R_G}, {"diffuse_blue", R_B},
    };
    for (size_t i = 0; i < sizeof roles / sizeof roles[0]; i++)
        if (word_eq(n, l, roles[i].name))
            return roles[i].role;
    return R_SKIP;
}

static void copy_name(char *dst, size_t size, const char *src, size_t n)
{
    if (n >= size)
        n = size - 1;
    memcpy(dst, src, n);
    dst[n] = 0;
}

/* Parses the header; on success r->pos is the first body byte. */
static bool parse_header(ply_reader *r, ply_file *pf)
{
    const char *d = (const char *)r->data;
    size_t pos = 0;
    bool have_format = false;
    int body_format = PF_ASCII;
    rt_warn_once warned;
    memset(&warned, 0, sizeof warned);
    r->format = PF_ASCII; /* header errors are reported by line */
    r->line = 0;
    for (;;) {
        if (pos >= r->size) {
            r->pos = pos;
            return fail_at(r, "header has no end_header line");
        }
        const char *nl = memchr(d + pos, '\n', r->size - pos);
        size_t eol = nl ? (size_t)(nl - d) : r->size;
        size_t next = nl ? eol + 1 : r->size;
        r->line++;
        const char *p = d + pos, *e = d + eol;
        while (e > p && (e[-1] == '\r' || rt_mesh_is_space(e[-1])))
            e--;
        /* split into up to 6 words */
        const char *w[6];
        size_t wl[6];
        int nw = 0;
        for (const char *q = p; q < e && nw < 6;) {
            while (q < e && rt_mesh_is_space(*q))
                q++;
            if (q >= e)
                break;
            const char *s = q;
            while (q < e && !rt_mesh_is_space(*q))
                q++;
            w[nw] = s;
            wl[nw] = (size_t)(q - s);
            nw++;
        }
        pos = next;
        if (r->line == 1) {
            if (nw != 1 || !word_eq(w[0], wl[0], "ply"))
                return fail_at(r, "not a PLY file (the first line must be 'ply')");
            continue;
        }
        if (nw == 0)
            continue;
        if (word_eq(w[0], wl[0], "end_header")) {
            if (!have_format)
                return fail_at(r, "header has no format line");
            r->pos = next;
            r->format = body_format;
            r->line++; /* ascii bodies start on the next line */
            return true;
        }
        if (word_eq(w[0], wl[0], "comment") || word_eq(w[0], wl[0], "obj_info"))
            continue;
        if (word_eq(w[0], wl[0], "format")) {
            if (nw < 2)
                return fail_at(r, "format line needs a format");
            if (word_eq(w[1], wl[1], "ascii"))
                body_format = PF_ASCII;
            else if (word_eq(w[1], wl[1], "binary_little_endian"))
                body_format = PF_LE;
            else if (word_eq(w[1], wl[1], "binary_big_endian"))
                body_format = PF_BE;
            else
                return fail_at(r, "unknown format '%.*s'", (int)(wl[1] > 40 ? 40 : wl[1]), w[1]);
            have_format = true;
            continue;
        }
        if (word_eq(w[0], wl[0], "element")) {
            if (nw != 3)
                return fail_at(r, "expected 'element <name> <count>'");
            int64_t count;
            const char *q = rt_mesh_parse_int(w[2], w[2] + wl[2], &count);
            if (!q || q != w[2] + wl[2] || count < 0)
                return fail_at(r, "bad element count '%.*s'", (int)(wl[2] > 40 ? 40 : wl[2]), w[2]);
            if (pf->nelem >= 1024 || !rt_grow((void **)&pf->elems, &pf->elemcap, pf->nelem + 1, sizeof *pf->elems))
                return fail_at(r, "too many elements");
            ply_elem *el = &pf->elems[pf->nelem++];
            memset(el, 0, sizeof *el);
            copy_name(el->name, sizeof el->name, w[1], wl[1]);
            el->count = (uint64_t)count;
            el->first_prop = pf->nprop;
            el->kind = word_eq(w[1], wl[1], "vertex")      ? K_VERTEX
                       : word_eq(w[1], wl[1], "face")      ? K_FACE
                       : word_eq(w[1], wl[1], "tristrips") ? K_STRIPS
                                                           : K_OTHER;
            continue;
        }
        if (word_eq(w[0], wl[0], "property")) {
            if (!pf->nelem)
                return fail_at(r, "property before any element");
            ply_elem *el = &pf->elems[pf->nelem - 1];
            ply_prop pr;
            memset(&pr, 0, sizeof pr);
            const char *name;
            size_t nl2;
            if (nw >= 2 && word_eq(w[1], wl[1], "list")) {
                if (nw != 5)
                    return fail_at(r, "expected 'property list <count type> <item type> <name>'");
                pr.count_type = parse_type(w[2], wl[2]);
                pr.type = parse_type(w[3], wl[3]);
                if (pr.count_type == PT_NONE || pr.type == PT_NONE || is_float_type(pr.count_type))
                    return fail_at(r, "bad list types '%.*s %.*s'", (int)(wl[2] > 20 ? 20 : wl[2]), w[2],
                                   (int)(wl[3] > 20 ? 20 : wl[3]), w[3]);
                name = w[4];
                nl2 = wl[4];
                if ((el->kind == K_FACE || el->kind == K_STRIPS) &&
                    (word_eq(name, nl2, "vertex_indices") || word_eq(name, nl2, "vertex_index"))) {
                    if (is_float_type(pr.type))
                        return fail_at(r, "vertex index list with a float item type");
                    pr.role = R_INDICES;
                }
            } else {
                if (nw != 3)
                    return fail_at(r, "expected 'property <type> <name>'");
                pr.type = parse_type(w[1], wl[1]);
                if (pr.type == PT_NONE)
                    return fail_at(r, "unknown property type '%.*s'", (int)(wl[1] > 40 ? 40 : wl[1]), w[1]);
                name = w[2];
                nl2 = wl[2];
                if (el->kind == K_VERTEX)
                    pr.role = vertex_role(name, nl2);
            }
            copy_name(pr.name, sizeof pr.name, name, nl2);
            /* "x" twice: which one is the position? (only properties rt
             * reads are compared, so this stays cheap for wide headers) */
            if (pr.role != R_SKIP)
                for (size_t k = el->first_prop; k < pf->nprop; k++)
                    if (pf->props[k].role == pr.role && strcmp(pf->props[k].name, pr.name) == 0)
                        return fail_at(r, "property '%s' given twice in element '%s'", pr.name, el->name);
            if (pf->nprop >= 65536 || !rt_grow((void **)&pf->props, &pf->propcap, pf->nprop + 1, sizeof *pf->props))
                return fail_at(r, "too many properties");
            pf->props[pf->nprop++] = pr;
            el->nprops++;
            continue;
        }
        if (rt_warn_once_first(&warned, w[0], wl[0]))
            rt_warn("%s:%ld: ignoring unknown header line '%.*s'", r->path, r->line, (int)(wl[0] > 40 ? 40 : wl[0]),
                    w[0]);
    }
}

/* -------------------------------------------------------------- body */

/* An element's properties (NULL when it has none: no arithmetic on NULL). */
static const ply_prop *elem_props(const ply_file *pf, const ply_elem *el)
{
    return el->nprops ? pf->props + el->first_prop : NULL;
}

typedef struct ply_load {
    ply_reader r;
    ply_file pf;
    rt_mesh_buf *b;
    uint64_t nverts; /* declared size of the vertex element */
    uint32_t material;
    uint8_t tri_flags;
    uint32_t *scratch; /* one face's vertex indices */
    size_t scap;
    uint32_t *tri; /* its triangulation */
    size_t tcap;
    rt_warn_once warned;
} ply_load;

static const double int_max[] = {1, 127.0, 255.0, 32767.0, 65535.0, 2147483647.0, 4294967295.0, 1, 1};

static void store_vertex(rt_mesh_buf *b, size_t v, const float *val, bool nrm, bool uv, bool col)
{
    b->pos[v] = rt_v3(val[R_X], val[R_Y], val[R_Z]);
    if (nrm)
        b->nrm[v] = rt_v3(val[R_NX], val[R_NY], val[R_NZ]);
    if (uv)
        b->uv[v] = rt_v2(val[R_U], 1.0f - val[R_V]);
    if (col)
        b->col[v] = rt_v4(val[R_R], val[R_G], val[R_B], val[R_A]);
}

static bool read_vertices(ply_load *L, const ply_elem *el)
{
    ply_reader *r = &L->r;
    rt_mesh_buf *b = L->b;
    const ply_prop *props = elem_props(&L->pf, el);
    unsigned have = 0;
    for (size_t k = 0; k < el->nprops; k++)
        if (props[k].count_type == PT_NONE && props[k].role != R_SKIP)
            have |= 1u << props[k].role;
#define HAS(role) ((have >> (role)) & 1u)
    if (!(HAS(R_X) && HAS(R_Y) && HAS(R_Z)))
        return fail_at(r, "element 'vertex' lacks an x, y or z property");
    bool nrm = HAS(R_NX) && HAS(R_NY) && HAS(R_NZ);
    bool uv = HAS(R_U) && HAS(R_V);
    bool col = HAS(R_R) || HAS(R_G) || HAS(R_B);
#undef HAS
    unsigned attrs = (nrm ? RT_MESH_NRM : 0) | (uv ? RT_MESH_UV : 0) | (col ? RT_MESH_COL : 0);
    if (!rt_mesh_buf_enable(b, attrs) || !rt_mesh_buf_reserve_vertices(b, (size_t)el->count)) {
        rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for %llu vertices", r->path, (unsigned long long)el->count);
        return false;
    }
    L->tri_flags = (uint8_t)((nrm ? RT_TRI_SMOOTH : 0) | (uv ? RT_TRI_UV : 0) | (col ? RT_TRI_COLOR : 0));
    size_t row = 0;
    bool lists = false;
    for (size_t k = 0; k < el->nprops; k++) {
        row += (size_t)type_size[props[k].type];
        lists = lists || props[k].count_type != PT_NONE;
    }
    bool fast = r->format != PF_ASCII && !lists;
    if (fast && el->count > (r->size - r->pos) / row)
        return fail_at(r, "%llu vertices of %zu bytes run past the end of the file (%zu bytes left)",
                       (unsigned long long)el->count, row, r->size - r->pos);
    bool big = r->format == PF_BE;
    for (uint64_t i = 0; i < el->count; i++) {
        if (fast) {
            /* binary rows of scalars: fixed offsets, one bounds check for the element */
            float val[R_A + 1] = {0};
            val[R_R] = val[R_G] = val[R_B] = val[R_A] = 1.0f;
            const unsigned char *q = r->data + r->pos;
            for (size_t k = 0; k < el->nprops; k++) {
                const ply_prop *p = &props[k];
                if (p->role != R_SKIP) {
                    int64_t iv;
                    double dv = bin_decode(q, p->type, big, &iv);
                    if (p->role >= R_R && p->role <= R_A && !is_float_type(p->type))
                        dv /= int_max[p->type];
                    float f = (float)dv;
                    if (!isfinite(f)) {
                        r->pos = (size_t)(q - r->data);
                        return fail_at(r, "vertex %llu: property '%s' is not finite", (unsigned long long)i, p->name);
                    }
                    val[p->role] = f;
                }
                q += type_size[p->type];
            }
            r->pos += row;
            store_vertex(b, (size_t)i, val, nrm, uv, col);
            continue;
        }
        float val[R_A + 1] = {0};
        val[R_R] = val[R_G] = val[R_B] = val[R_A] = 1.0f;
        for (size_t k = 0; k < el->nprops; k++) {
            const ply_prop *p = &props[k];
            if (p->count_type != PT_NONE || p->role == R_SKIP) {
                if (!skip_prop(r, p))
                    return false;
                continue;
            }
            size_t at = r->pos;
            int64_t iv;
            double dv;
            if (!read_value(r, p->type, &iv, &dv))
                return false;
            if (p->role >= R_R && p->role <= R_A && !is_float_type(p->type))
                dv /= int_max[p->type];
            float f = (float)dv;
            if (!isfinite(f)) {
                r->pos = at;
                return fail_at(r, "vertex %llu: property '%s' is not finite", (unsigned long long)i, p->name);
            }
            val[p->role] = f;
        }
        store_vertex(b, (size_t)i, val, nrm, uv, col);
    }
    b->nv = (size_t)el->count;
    return true;
}

/* One vertex index of a face or strip list; restart = -1 (or the unsigned type's maximum). */
static bool read_index(ply_load *L, ply_type t, int64_t *out, bool *restart)
{
    ply_reader *r = &L->r;
    size_t at = r->pos;
    double dv;
    if (r->format != PF_ASCII) {
        /* list items: read_count has checked that the whole list is in the file */
        bin_decode(r->data + r->pos, t, r->format == PF_BE, out);
        r->pos += (size_t)type_size[t];
    } else if (!ascii_value(r, t, out, &dv)) {
        return false;
    }
    *restart = *out == -1 || ((t == PT_U16 || t == PT_U32) && *out == (int64_t)int_max[t]);
    if (!*restart && (*out < 0 || (uint64_t)*out >= L->nverts)) {
        r->pos = at;
        return fail_at(r, "vertex index %lld out of range (%llu vertices)", (long long)*out,
                       (unsigned long long)L->nverts);
    }
    return true;
}

static bool read_faces(ply_load *L, const ply_elem *el, uint64_t e)
{
    ply_reader *r = &L->r;
    rt_mesh_buf *b = L->b;
    const ply_prop *props = elem_props(&L->pf, el);
    /* an element without properties holds no bytes, so check_counts cannot
     * bound its count: it has no faces to read (and nothing to reserve) */
    if (el->nprops == 0)
        return true;
    if (!rt_mesh_buf_reserve_triangles(b, b->nt + (size_t)el->count)) {
        rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for %llu faces", r->path, (unsigned long long)el->count);
        return false;
    }
    bool strips = el->kind == K_STRIPS;
    for (uint64_t i = 0; i < el->count; i++) {
        bool used = false;
        for (size_t k = 0; k < el->nprops; k++) {
            const ply_prop *p = &props[k];
            if (p->role != R_INDICES || used) {
                if (!skip_prop(r, p))
                    return false;
                continue;
            }
            used = true;
            int64_t n;
            if (!read_count(r, p->count_type, p->type, &n))
                return false;
            if (strips) {
                int have = 0, parity = 0;
                uint32_t a = 0, c1 = 0;
                if (n > 2 && !rt_mesh_buf_reserve_triangles(b, b->nt + (size_t)n - 2)) {
                    rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for a strip of %lld", r->path, (long long)n);
                    return false;
                }
                for (int64_t j = 0; j < n; j++) {
                    int64_t v;
                    bool restart;
                    if (!read_index(L, p->type, &v, &restart))
                        return false;
                    if (restart) {
                        have = parity = 0;
                        continue;
                    }
                    uint32_t c2 = (uint32_t)v;
                    if (have < 2) {
                        if (have == 0)
                            a = c2;
                        else
                            c1 = c2;
                        have++;
                        continue;
                    }
                    if (a != c1 && c1 != c2 && a != c2) {
                        bool ok = parity ? rt_mesh_buf_add_triangle(b, c1, a, c2, L->material, L->tri_flags)
                                         : rt_mesh_buf_add_triangle(b, a, c1, c2, L->material, L->tri_flags);
                        if (!ok) {
                            rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for triangles", r->path);
                            return false;
                        }
                    }
                    parity ^= 1;
                    a = c1;
                    c1 = c2;
                }
                continue;
            }
            if ((size_t)n > L->scap) {
                size_t cap = L->scap;
                if (!rt_grow((void **)&L->scratch, &cap, (size_t)n, sizeof *L->scratch)) {
                    rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for a face of %lld", r->path, (long long)n);
                    return false;
                }
                L->scap = cap;
            }
            for (int64_t j = 0; j < n; j++) {
                int64_t v;
                bool restart;
                if (!read_index(L, p->type, &v, &restart))
                    return false;
                if (restart)
                    return fail_at(r, "face %llu: vertex index %lld out of range", (unsigned long long)i,
                                   (long long)v);
                L->scratch[j] = (uint32_t)v;
            }
            if (n < 3) {
                b->skipped++;
                if (rt_warn_once_first(&L->warned, "short face", 10))
                    rt_warn("%s: face %llu has %lld vertices; skipping faces with fewer than 3 (warned once)",
                            r->path, (unsigned long long)i, (long long)n);
                continue;
            }
            if (3 * ((size_t)n - 2) > L->tcap) {
                size_t cap = L->tcap;
                if (!rt_grow((void **)&L->tri, &cap, 3 * ((size_t)n - 2), sizeof *L->tri)) {
                    rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for a face of %lld", r->path, (long long)n);
                    return false;
                }
                L->tcap = cap;
            }
            /* positions are known when the vertex element came first */
            const rt_vec3 *pos = b->nv == L->nverts ? b->pos : NULL;
            const uint32_t *s = L->scratch;
            size_t nt = rt_mesh_triangulate(pos, s, (size_t)n, L->tri);
            for (size_t j = 0; j < nt; j++) {
                uint32_t ca = s[L->tri[3 * j]], cb = s[L->tri[3 * j + 1]], cc = s[L->tri[3 * j + 2]];
                if (ca == cb || cb == cc || ca == cc) {
                    b->skipped++;
                    continue;
                }
                if (!rt_mesh_buf_add_triangle(b, ca, cb, cc, L->material, L->tri_flags)) {
                    rt_fail(r->err, RT_ERR_NOMEM, "%s: out of memory for triangles", r->path);
                    return false;
                }
            }
        }
        if (!used && i == 0 && rt_warn_once_first(&L->warned, "no indices", 10))
            rt_warn("%s: element %llu '%s' has no vertex_indices list; its faces are ignored", r->path,
                    (unsigned long long)e, el->name);
    }
    return true;
}

static bool skip_element(ply_load *L, const ply_elem *el)
{
    ply_reader *r = &L->r;
    const ply_prop *props = elem_props(&L->pf, el);
    if (el->nprops == 0) /* no bytes, however large the count: no loop over it */
        return true;
    bool lists = false;
    size_t row = 0;
    for (size_t k = 0; k < el->nprops; k++) {
        lists = lists || props[k].count_type != PT_NONE;
        row += (size_t)type_size[props[k].type];
    }
    if (el->nprops == 0)
        return true;
    if (r->format != PF_ASCII && !lists) {
        if (el->count > (r->size - r->pos) / row)
            return fail_at(r, "element '%s' runs past the end of the file", el->name);
        r->pos += (size_t)el->count * row;
        return true;
    }
    for (uint64_t i = 0; i < el->count; i++)
        for (size_t k = 0; k < el->nprops; k++)
            if (!skip_prop(r, &props[k]))
                return false;
    return true;
}

/* The header's counts against the bytes after it, before any allocation. */
static bool check_counts(ply_load *L)
{
    ply_reader *r = &L->r;
    uint64_t left = r->size - r->pos, need = 0;
    for (size_t e = 0; e < L->pf.nelem; e++) {
        const ply_elem *el = &L->pf.elems[e];
        uint64_t per = 0;
        const ply_prop *props = elem_props(&L->pf, el);
        for (size_t k = 0; k < el->nprops; k++)
            per += r->format == PF_ASCII ? 2u
                   : (uint64_t)type_size[props[k].count_type != PT_NONE ? props[k].count_type : props[k].type];
        if (per == 0 || el->count == 0)
            continue;
        uint64_t room = r->format == PF_ASCII ? left + 1 : left; /* the last ascii value may end the file */
        if (el->count > room / per || (need += el->count * per) > room)
            return fail_at(r, "header claims %llu '%s' elements, more than the %llu bytes after the header can hold",
                           (unsigned long long)el->count, el->name, (unsigned long long)left);
    }
    return true;
}

rt_result rt_ply_parse(const rt_mesh_input *in, rt_mesh_buf *b)
{
    /* PLY has no materials: every face takes in->material */
    const char *path = in->name;
    rt_error *err = in->err;
    rt_result res = RT_OK;
    ply_load L;
    memset(&L, 0, sizeof L);
    L.r.path = path;
    L.r.data = (const unsigned char *)in->bytes;
    L.r.size = in->size;
    L.r.err = err;
    L.b = b;
    L.material = in->material;
    bool ok = parse_header(&L.r, &L.pf) && check_counts(&L);
    size_t vert_elem = SIZE_MAX;
    for (size_t e = 0; ok && e < L.pf.nelem; e++) {
        ply_elem *el = &L.pf.elems[e];
        if (el->kind != K_VERTEX)
            continue;
        if (vert_elem == SIZE_MAX) {
            vert_elem = e;
            if (el->count >= RT_NONE)
                ok = fail_at(&L.r, "%llu vertices is over the limit of 2^32 - 1", (unsigned long long)el->count);
            L.nverts = el->count;
        } else {
            el->kind = K_OTHER;
            rt_warn("%s: a second 'vertex' element is ignored", path);
        }
    }
    if (ok && vert_elem == SIZE_MAX)
        ok = fail_at(&L.r, "no 'vertex' element");
    for (size_t e = 0; ok && e < L.pf.nelem; e++) {
        const ply_elem *el = &L.pf.elems[e];
        switch (el->kind) {
        case K_VERTEX: ok = read_vertices(&L, el); break;
        case K_FACE:
        case K_STRIPS: ok = read_faces(&L, el, e); break;
        default: ok = skip_element(&L, el); break;
        }
    }
    if (ok) {
        /* flags were set per triangle from the vertex element; if faces came first, set them now */
        for (size_t t = 0; t < b->nt; t++)
            b->flags[t] = L.tri_flags;
    } else {
        res = err->code ? err->code : RT_ERR_PARSE;
    }
    free(L.pf.elems);
    free(L.pf.props);
    free(L.scratch);
    free(L.tri);
    return res;
}
