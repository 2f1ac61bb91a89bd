/* mesh_obj.c - Wavefront OBJ meshes with MTL materials.
 *
 * Reference: the Wavefront OBJ and MTL specifications (Alias|Wavefront,
 * "Advanced Visualizer" manual, appendices B1 and B2), plus what real
 * exporters write (Blender, MeshLab, 3ds Max, the Cornell box files).
 *
 * Algorithm: one pass over the file held in memory, line by line.
 *   v/vt/vn append to raw attribute arrays (v may carry an "x y z r g b"
 *   vertex colour, as MeshLab writes). A face corner "v", "v/vt", "v//vn" or
 *   "v/vt/vn" (1-based, negative = relative to the end so far) becomes one
 *   output vertex per distinct (v, vt, vn) triple, found again through an
 *   open-addressing hash table (material names likewise), so adversarial
 *   files stay linear. Polygons are triangulated by
 *   rt_mesh_triangulate (mesh_buffer.c): fans for convex ones, the right diagonal
 *   for concave quads, ear clipping for other concave polygons. Triangles
 *   that repeat a position are dropped and counted in stats.skipped_faces.
 *   usemtl names are resolved after the whole file (and every mtllib) is read,
 *   so statement order does not matter; faces before any usemtl, and faces
 *   whose name is unknown (warning), use the caller's material.
 *   Each MTL material becomes an rt_material "<objfile>:<name>" starting
 *   from rt_material_default(): Kd colour, Ks luminance as specular, Ns
 *   shininess, Ni ior, d (or 1 - Tr) alpha, Ke emission, Tf transmission
 *   colour, Pr/Pm roughness/metallic; illum 3/5 = mirror (reflectivity from
 *   Ks, 1 when Ks is absent), illum 4/6/7 = refracting glass; map_Kd (sRGB
 *   base colour) and map_Bump/bump/norm (normal map, -bm scale). Ka above 1
 *   with no Ke is taken as emission (old Embree-style Cornell files mark the
 *   light that way). Other texture options are skipped with a warning. A
 *   texture file that does not exist follows the missing-texture rule
 *   (rt/scene/texture.h: a warning at the map line, the magenta checker for
 *   map_Kd, no normal map); one that exists but does not decode is an error.
 *   Unknown statements are warned about once per keyword per file.
 *   Smoothing groups (`s N`): faces without vn in a group other than 0/off
 *   get generated vertex normals, the area-weighted sum of the face normals
 *   of that group around each position (vertices are split per group), and
 *   smooth shading. Faces with vn use them. `o` and `g` are accepted and
 *   otherwise ignored.
 * Errors: "path:line:col: ..." for malformed numbers, indices out of range,
 * faces with fewer than 3 corners. A missing MTL or texture is a warning.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mesh_buffer.h"
#include "mesh_readers.h"
#include "mesh_text.h"
#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/io/image_load.h"
#include "rt/scene/texture.h"

#define OBJ_NAME_MAX 128
#define OBJ_PATH_MAX 4096

typedef struct obj_mtl {
    char name[OBJ_NAME_MAX];
    rt_vec3 kd, ks, ke, ka, tf;
    float ns, ni, alpha, pr, pm, bump_scale;
    int illum;
    bool has_kd, has_ks, has_ke, has_ka, has_tf, has_ns, has_ni, has_alpha, has_pr, has_pm;
    char *map_kd, *map_bump; /* resolved texture paths (malloc'd) or NULL */
    long map_kd_line, map_bump_line; /* where they were given */
    uint32_t file;           /* index into obj_parser.mtl_files, for messages */
    long line;
} obj_mtl;

typedef struct obj_slot { /* a name used by usemtl */
    char name[OBJ_NAME_MAX];
    long line;
    uint32_t material; /* scene index once resolved */
} obj_slot;

/* ------------------------------------------------------ hash tables */

static uint64_t mix64(uint64_t x)
{
    /* splitmix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators", 2014) */
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

static uint64_t hash_str(const char *s)
{
    uint64_t h = 1469598103934665603ull; /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ull;
    return mix64(h);
}

/* Names (the first member of records in an array) to record indices, by open
 * addressing, so that many distinct usemtl/newmtl names stay linear. */
typedef struct name_map {
    uint32_t *tab;
    size_t cap, count;
} name_map;

static const char *rec_name(const void *base, size_t stride, uint32_t i) { return (const char *)base + i * stride; }

static uint32_t name_map_find(const name_map *m, const char *name, const void *base, size_t stride)
{
    if (!m->cap)
        return RT_NONE;
    for (size_t h = (size_t)hash_str(name) & (m->cap - 1);; h = (h + 1) & (m->cap - 1)) {
        uint32_t i = m->tab[h];
        if (i == RT_NONE || strcmp(rec_name(base, stride, i), name) == 0)
            return i;
    }
}

/* Maps the record's name to index i (replacing an earlier record of that name). */
static bool name_map_put(name_map *m, uint32_t i, const void *base, size_t stride)
{
    if (2 * (m->count + 1) > m->cap) {
        size_t cap = m->cap ? 2 * m->cap : 64;
        uint32_t *tab = rt_alloc(cap, sizeof *tab);
        if (!tab)
            return false;
        memset(tab, 0xff, cap * sizeof *tab);
        for (size_t k = 0; k < m->cap; k++) {
            uint32_t j = m->tab[k];
            if (j == RT_NONE)
                continue;
            size_t h = (size_t)hash_str(rec_name(base, stride, j)) & (cap - 1);
            while (tab[h] != RT_NONE)
                h = (h + 1) & (cap - 1);
            tab[h] = j;
        }
        free(m->tab);
        m->tab = tab;
        m->cap = cap;
    }
    const char *name = rec_name(base, stride, i);
    size_t h = (size_t)hash_str(name) & (m->cap - 1);
    while (m->tab[h] != RT_NONE && strcmp(rec_name(base, stride, m->tab[h]), name) != 0)
        h = (h + 1) & (m->cap - 1);
    if (m->tab[h] == RT_NONE)
        m->count++;
    m->tab[h] = i;
    return true;
}

typedef struct obj_parser {
    const char *path;
    char dir[OBJ_PATH_MAX];
    rt_error *err;
    /* raw attributes */
    rt_vec3 *v; rt_vec3 *vc; size_t nv, vcap;
    rt_vec2 *vt; size_t nvt, vtcap;
    rt_vec3 *vn; size_t nvn, vncap;
    /* output vertices: (v, vt, vn) triples, chained per position */
    uint32_t *ov, *ot, *on, *osg; size_t nout, outcap;
    uint32_t *vhash; size_t vhcap, nhashed; /* open addressing over output vertices with vt/vn/group */
    uint32_t *plain; /* per position: its output vertex for bare "v" corners, or RT_NONE */
    bool any_t, any_n, any_sg;
    uint32_t cur_sg; /* current smoothing group, 0 = off */
    /* face scratch */
    uint32_t *corner_out, *corner_v, *corner_t, *corner_n; size_t ccap;
    uint32_t *tri_out; size_t tcap; /* triangulation of the current face */
    /* materials */
    obj_mtl *mtls; size_t nmtl, mtlcap;
    char **mtl_files; size_t nfiles, filecap; /* MTL paths, for messages */
    obj_slot *slots; size_t nslot, slotcap; /* slot 0 = the caller's material */
    name_map mtl_names, slot_names;
    uint32_t cur_slot;
    bool override_material;
    rt_warn_once warned;
    rt_mesh_buf *buf; /* the output (the dispatcher's) */
} obj_parser;

/* ----------------------------------------------------------- lines */

typedef struct line_ctx {
    const char *file; /* for messages */
    long line;
    const char *start; /* of the line, for columns */
} line_ctx;

static int col_of(const line_ctx *lc, const char *at) { return (int)(at - lc->start) + 1; }

static bool kw_is(const char *k, size_t klen, const char *want)
{
    size_t n = strlen(want);
    return klen == n && memcmp(k, want, n) == 0;
}

/* MTL keywords are matched without case: exporters write map_kd, Map_Kd, KD. */
static bool kw_is_ci(const char *k, size_t klen, const char *want)
{
    size_t n = strlen(want);
    if (klen != n)
        return false;
    for (size_t i = 0; i < n; i++) {
        char a = k[i], b = want[i];
        if (a >= 'A' && a <= 'Z')
            a = (char)(a - 'A' + 'a');
        if (b >= 'A' && b <= 'Z')
            b = (char)(b - 'A' + 'a');
        if (a != b)
            return false;
    }
    return true;
}

/* The rest of a line, trimmed, as a bounded C string. false if it does not fit. */
static bool rest_string(const char *p, const char *end, char *out, size_t size)
{
    p = rt_mesh_skip_space(p, end);
    while (end > p && rt_mesh_is_space(end[-1]))
        end--;
    size_t n = (size_t)(end - p);
    if (n >= size)
        return false;
    memcpy(out, p, n);
    out[n] = 0;
    /* embedded NUL bytes would cut the string short; that only shortens it */
    return true;
}

/* Parses up to max floats from [p, end); returns how many, or -1 after filling err. */
static int parse_floats(const line_ctx *lc, const char *p, const char *end, float *out, int max, rt_error *err)
{
    int n = 0;
    for (;;) {
        p = rt_mesh_skip_space(p, end);
        if (p >= end)
            return n;
        const char *te = rt_mesh_token_end(p, end);
        if (n == max) {
            rt_fail(err, RT_ERR_PARSE, "%s:%ld:%d: unexpected '%.*s' (at most %d numbers here)", lc->file, lc->line,
                    col_of(lc, p), (int)(te - p > 40 ? 40 : te - p), p, max);
            return -1;
        }
        bool nonfinite;
        const char *q = rt_mesh_parse_float(p, te, &out[n], &nonfinite);
        if (!q || q != te) {
            rt_fail(err, RT_ERR_PARSE, "%s:%ld:%d: %s '%.*s'", lc->file, lc->line, col_of(lc, p),
                    nonfinite ? "number is not finite:" : "malformed number", (int)(te - p > 40 ? 40 : te - p), p);
            return -1;
        }
        n++;
        p = te;
    }
}

static void warn_unknown(rt_warn_once *w, const line_ctx *lc, const char *k, size_t klen)
{
    if (rt_warn_once_first(w, k, klen))
        rt_warn("%s:%ld: ignoring unsupported statement '%.*s' (warned once per file)", lc->file, lc->line,
                (int)(klen > 40 ? 40 : klen), k);
}

/* Calls fn(ctx, lc, p, eol) for each non-blank, non-comment line; stops on failure. */
typedef rt_result (*line_fn)(void *ctx, line_ctx *lc, const char *p, const char *eol);

static rt_result for_each_line(const char *file, const char *data, size_t size, line_fn fn, void *ctx)
{
    const char *p = data, *end = data + size;
    line_ctx lc = {file, 0, data};
    while (p < end) {
        lc.line++;
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            eol = end;
        const char *next = eol < end ? eol + 1 : end;
        lc.start = p;
        const char *q = rt_mesh_skip_space(p, eol);
        if (q < eol && *q != '#') {
            rt_result r = fn(ctx, &lc, q, eol);
            if (r != RT_OK)
                return r;
        }
        p = next;
    }
    return RT_OK;
}

/* Cuts a line at a comment: '#' anywhere for numeric statements. */
static const char *cut_comment(const char *p, const char *eol)
{
    const char *h = memchr(p, '#', (size_t)(eol - p));
    return h ? h : eol;
}

/* For names and file names: only a '#' after whitespace starts a comment. */
static const char *cut_comment_ws(const char *p, const char *eol)
{
    for (const char *q = p; q < eol; q++)
        if (*q == '#' && (q == p || rt_mesh_is_space(q[-1])))
            return q;
    return eol;
}

/* dir + rel (rel alone when absolute). Files written on Windows name paths
 * with '\\': those become '/' in rel first. false when too long. */
static bool obj_join(const char *dir, char *rel, char *out, size_t size)
{
    for (char *c = rel; *c; c++)
        if (*c == '\\')
            *c = '/';
    return rt_path_join(dir, rel, out, size);
}

/* ------------------------------------------------------------- MTL */

typedef struct mtl_ctx {
    obj_parser *op;
    uint32_t file; /* index into op->mtl_files */
    const char *mtl_path;
    char mtl_dir[OBJ_PATH_MAX];
    obj_mtl *cur;
    rt_warn_once warned;
} mtl_ctx;

static rt_result mtl_color(mtl_ctx *mc, line_ctx *lc, const char *kw, size_t kl, const char *p, const char *eol,
                           rt_vec3 *out, bool *has)
{
    const char *q = rt_mesh_skip_space(p, eol);
    const char *te = rt_mesh_token_end(q, eol);
    if (kw_is(q, (size_t)(te - q), "spectral") || kw_is(q, (size_t)(te - q), "xyz")) {
        warn_unknown(&mc->warned, lc, q, (size_t)(te - q));
        return RT_OK;
    }
    float f[3];
    int n = parse_floats(lc, p, cut_comment(p, eol), f, 3, mc->op->err);
    if (n < 0)
        return mc->op->err->code;
    if (n != 1 && n != 3)
        return rt_fail(mc->op->err, RT_ERR_PARSE, "%s:%ld: '%.*s' needs 1 or 3 numbers, got %d", lc->file, lc->line,
                       (int)kl, kw, n);
    *out = n == 1 ? rt_v3s(f[0]) : rt_v3(f[0], f[1], f[2]);
    *has = true;
    return RT_OK;
}

static rt_result mtl_scalar(mtl_ctx *mc, line_ctx *lc, const char *kw, size_t kl, const char *p, const char *eol,
                            float *out)
{
    float f[1];
    int n = parse_floats(lc, p, cut_comment(p, eol), f, 1, mc->op->err);
    if (n < 0)
        return mc->op->err->code;
    if (n != 1)
        return rt_fail(mc->op->err, RT_ERR_PARSE, "%s:%ld: '%.*s' needs a number", lc->file, lc->line, (int)kl, kw);
    *out = f[0];
    return RT_OK;
}

/* A texture statement: options, then a file name (the rest of the line). */
static rt_result mtl_map(mtl_ctx *mc, line_ctx *lc, const char *kw, size_t kl, const char *p, const char *eol,
                         char **path_out, long *line_out, float *bump_scale)
{
    eol = cut_comment_ws(p, eol);
    for (;;) {
        p = rt_mesh_skip_space(p, eol);
        if (p >= eol || *p != '-')
            break;
        const char *te = rt_mesh_token_end(p, eol);
        size_t ol = (size_t)(te - p);
        int min_args = 1, max_args = 1;
        if (kw_is(p, ol, "-o") || kw_is(p, ol, "-s") || kw_is(p, ol, "-t"))
            max_args = 3;
        else if (kw_is(p, ol, "-mm"))
            min_args = max_args = 2;
        else if (!(kw_is(p, ol, "-bm") || kw_is(p, ol, "-blendu") || kw_is(p, ol, "-blendv") ||
                   kw_is(p, ol, "-boost") || kw_is(p, ol, "-cc") || kw_is(p, ol, "-clamp") ||
                   kw_is(p, ol, "-imfchan") || kw_is(p, ol, "-texres") || kw_is(p, ol, "-type")))
            min_args = max_args = 0; /* unknown option: skip the option word alone */
        bool is_bm = kw_is(p, ol, "-bm");
        const char *opt = p;
        p = te;
        for (int a = 0; a < max_args; a++) {
            const char *q = rt_mesh_skip_space(p, eol);
            const char *qe = rt_mesh_token_end(q, eol);
            if (q >= eol)
                break;
            float f;
            bool nonfinite;
            const char *r = rt_mesh_parse_float(q, qe, &f, &nonfinite);
            bool numeric = r && r == qe;
            if (a >= min_args && !numeric)
                break; /* optional numeric arguments end at the first non-number */
            if (is_bm) {
                if (!numeric)
                    return rt_fail(mc->op->err, RT_ERR_PARSE, "%s:%ld:%d: -bm needs a number", lc->file, lc->line,
                                   col_of(lc, q));
                *bump_scale = f;
            }
            p = qe;
        }
        if (!is_bm && rt_warn_once_first(&mc->warned, opt, ol))
            rt_warn("%s:%ld: ignoring texture option '%.*s' (warned once per file)", lc->file, lc->line, (int)ol, opt);
    }
    char rel[OBJ_PATH_MAX];
    if (!rest_string(p, eol, rel, sizeof rel))
        return rt_fail(mc->op->err, RT_ERR_LIMIT, "%s:%ld: texture file name too long", lc->file, lc->line);
    if (!rel[0]) {
        rt_warn("%s:%ld: '%.*s' without a file name; ignored", lc->file, lc->line, (int)kl, kw);
        return RT_OK;
    }
    char full[OBJ_PATH_MAX];
    if (!obj_join(mc->mtl_dir, rel, full, sizeof full))
        return rt_fail(mc->op->err, RT_ERR_LIMIT, "%s:%ld: texture path too long", lc->file, lc->line);
    char *copy = strdup(full);
    if (!copy)
        return rt_fail(mc->op->err, RT_ERR_NOMEM, "%s: out of memory", lc->file);
    free(*path_out);
    *path_out = copy;
    *line_out = lc->line;
    return RT_OK;
}

static rt_result mtl_line(void *ctx, line_ctx *lc, const char *p, const char *eol)
{
    mtl_ctx *mc = ctx;
    obj_parser *op = mc->op;
    const char *ke = rt_mesh_token_end(p, eol);
    const char *kw = p;
    size_t kl = (size_t)(ke - p);
    p = ke;
    if (kw_is_ci(kw, kl, "newmtl")) {
        if (op->nmtl >= (size_t)RT_NONE - 1 ||
            !rt_grow((void **)&op->mtls, &op->mtlcap, op->nmtl + 1, sizeof *op->mtls))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for materials", lc->file);
        obj_mtl *m = &op->mtls[op->nmtl++];
        memset(m, 0, sizeof *m);
        m->bump_scale = 1.0f;
        m->alpha = 1.0f;
        m->illum = -1;
        if (!rest_string(p, cut_comment_ws(p, eol), m->name, sizeof m->name))
            return rt_fail(op->err, RT_ERR_LIMIT, "%s:%ld: material name longer than %d bytes", lc->file, lc->line,
                           OBJ_NAME_MAX - 1);
        if (!m->name[0])
            return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld: newmtl without a name", lc->file, lc->line);
        m->file = mc->file;
        m->line = lc->line;
        mc->cur = m;
        if (!name_map_put(&op->mtl_names, (uint32_t)(op->nmtl - 1), op->mtls, sizeof *op->mtls))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for materials", lc->file);
        return RT_OK;
    }
    obj_mtl *m = mc->cur;
    if (!m) {
        if (rt_warn_once_first(&mc->warned, "(before newmtl)", 15))
            rt_warn("%s:%ld: statement before any newmtl; ignored (warned once per file)", lc->file, lc->line);
        return RT_OK;
    }
    if (kw_is_ci(kw, kl, "Kd"))
        return mtl_color(mc, lc, kw, kl, p, eol, &m->kd, &m->has_kd);
    if (kw_is_ci(kw, kl, "Ks"))
        return mtl_color(mc, lc, kw, kl, p, eol, &m->ks, &m->has_ks);
    if (kw_is_ci(kw, kl, "Ke"))
        return mtl_color(mc, lc, kw, kl, p, eol, &m->ke, &m->has_ke);
    if (kw_is_ci(kw, kl, "Ka"))
        return mtl_color(mc, lc, kw, kl, p, eol, &m->ka, &m->has_ka);
    if (kw_is_ci(kw, kl, "Tf"))
        return mtl_color(mc, lc, kw, kl, p, eol, &m->tf, &m->has_tf);
    rt_result r;
    if (kw_is_ci(kw, kl, "Ns")) {
        m->has_ns = true;
        return mtl_scalar(mc, lc, kw, kl, p, eol, &m->ns);
    }
    if (kw_is_ci(kw, kl, "Ni")) {
        m->has_ni = true;
        return mtl_scalar(mc, lc, kw, kl, p, eol, &m->ni);
    }
    if (kw_is_ci(kw, kl, "Pr")) {
        m->has_pr = true;
        return mtl_scalar(mc, lc, kw, kl, p, eol, &m->pr);
    }
    if (kw_is_ci(kw, kl, "Pm")) {
        m->has_pm = true;
        return mtl_scalar(mc, lc, kw, kl, p, eol, &m->pm);
    }
    if (kw_is_ci(kw, kl, "d")) {
        /* "d -halo f" is an old variant: take the factor */
        const char *q = rt_mesh_skip_space(p, eol);
        if (kw_is(q, (size_t)(rt_mesh_token_end(q, eol) - q), "-halo"))
            p = rt_mesh_token_end(q, eol);
        m->has_alpha = true;
        return mtl_scalar(mc, lc, kw, kl, p, eol, &m->alpha);
    }
    if (kw_is_ci(kw, kl, "Tr")) {
        float tr;
        if ((r = mtl_scalar(mc, lc, kw, kl, p, eol, &tr)) != RT_OK)
            return r;
        m->has_alpha = true;
        m->alpha = 1.0f - tr;
        return RT_OK;
    }
    if (kw_is_ci(kw, kl, "illum")) {
        float f;
        if ((r = mtl_scalar(mc, lc, kw, kl, p, eol, &f)) != RT_OK)
            return r;
        if (!(f >= 0.0f && f <= 10.0f) || f != (float)(int)f)
            return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld: illum must be an integer 0..10", lc->file, lc->line);
        m->illum = (int)f;
        return RT_OK;
    }
    if (kw_is_ci(kw, kl, "map_Kd"))
        return mtl_map(mc, lc, kw, kl, p, eol, &m->map_kd, &m->map_kd_line, &m->bump_scale);
    if (kw_is_ci(kw, kl, "map_Bump") || kw_is_ci(kw, kl, "bump") || kw_is_ci(kw, kl, "norm") ||
        kw_is_ci(kw, kl, "map_Norm"))
        return mtl_map(mc, lc, kw, kl, p, eol, &m->map_bump, &m->map_bump_line, &m->bump_scale);
    warn_unknown(&mc->warned, lc, kw, kl);
    return RT_OK;
}

/* Loads one MTL file into op->mtls. A missing file is a warning. */
static rt_result load_mtl(obj_parser *op, const char *mtl_path, const line_ctx *at)
{
    char *data;
    size_t size;
    rt_error e = {0};
    if (rt_read_file(mtl_path, 0, &data, &size, &e) != RT_OK) {
        if (e.code == RT_ERR_NOMEM)
            return rt_fail(op->err, e.code, "%s", e.message);
        rt_warn("%s:%ld: %s; its materials fall back to the default", at->file, at->line, e.message);
        return RT_OK;
    }
    char *copy = strdup(mtl_path);
    if (!copy || !rt_grow((void **)&op->mtl_files, &op->filecap, op->nfiles + 1, sizeof *op->mtl_files)) {
        free(copy);
        free(data);
        return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory", mtl_path);
    }
    op->mtl_files[op->nfiles] = copy;
    mtl_ctx mc;
    memset(&mc, 0, sizeof mc);
    mc.op = op;
    mc.file = (uint32_t)op->nfiles++;
    mc.mtl_path = mtl_path;
    rt_path_dirname(mtl_path, mc.mtl_dir, sizeof mc.mtl_dir);
    rt_result r = for_each_line(mtl_path, data, size, mtl_line, &mc);
    free(data);
    return r;
}

/* -------------------------------------------------------------- OBJ */

static bool grow_raw(void **p, size_t *cap, size_t need, size_t elem)
{
    return rt_grow(p, cap, need, elem) != 0;
}

static rt_result obj_vertex(obj_parser *op, line_ctx *lc, const char *p, const char *eol)
{
    float f[7];
    int n = parse_floats(lc, p, cut_comment(p, eol), f, 7, op->err);
    if (n < 0)
        return op->err->code;
    if (n < 3)
        return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld: 'v' needs 3 coordinates, got %d", lc->file, lc->line, n);
    if (op->nv >= (size_t)RT_NONE - 1)
        return rt_fail(op->err, RT_ERR_LIMIT, "%s:%ld: too many vertices", lc->file, lc->line);
    if (op->nv >= op->vcap) {
        /* grow v, plain and vc together; vcap only moves once all have */
        size_t c = op->vcap ? op->vcap * 2 : 1024;
        void *a;
        if (!(a = rt_realloc_array(op->v, c, sizeof *op->v)))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for vertices", lc->file);
        op->v = a;
        if (!(a = rt_realloc_array(op->plain, c, sizeof *op->plain)))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for vertices", lc->file);
        op->plain = a;
        if (op->vc) {
            if (!(a = rt_realloc_array(op->vc, c, sizeof *op->vc)))
                return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for vertices", lc->file);
            op->vc = a;
        }
        op->vcap = c;
    }
    size_t i = op->nv++;
    op->v[i] = rt_v3(f[0], f[1], f[2]);
    op->plain[i] = RT_NONE;
    if (n >= 6) {
        if (!op->vc) {
            if (!(op->vc = rt_alloc(op->vcap, sizeof *op->vc)))
                return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for vertex colours", lc->file);
            for (size_t k = 0; k < i; k++)
                op->vc[k] = rt_v3s(1.0f);
        }
        int c = n == 7 ? 4 : 3; /* x y z w r g b */
        op->vc[i] = rt_v3(f[c], f[c + 1], f[c + 2]);
    } else if (op->vc) {
        op->vc[i] = rt_v3s(1.0f);
    }
    return RT_OK;
}

/* Resolves a 1-based or negative OBJ index against count; RT_NONE + err when out of range. */
static uint32_t resolve_index(obj_parser *op, const line_ctx *lc, const char *at, int64_t idx, size_t count,
                              const char *what)
{
    int64_t r = idx > 0 ? idx - 1 : (int64_t)count + idx;
    if (idx == 0 || r < 0 || (uint64_t)r >= count) {
        rt_fail(op->err, RT_ERR_INVALID, "%s:%ld:%d: %s index %lld out of range (%zu defined so far)", lc->file,
                lc->line, col_of(lc, at), what, (long long)idx, count);
        return RT_NONE;
    }
    return (uint32_t)r;
}

static size_t vertex_hash(uint32_t v, uint32_t t, uint32_t n, uint32_t sg)
{
    return (size_t)mix64(((uint64_t)v << 32 | t) ^ mix64((uint64_t)n << 32 | sg));
}

/* The output vertex for a (v, vt, vn, smoothing group) key, made on first
 * use; an open-addressing table finds it again. sg is 0 except for faces
 * without normals in a smoothing group, whose normals are generated. */
static uint32_t new_output_vertex(obj_parser *op, uint32_t v, uint32_t t, uint32_t n, uint32_t sg)
{
    if (op->nout >= (size_t)RT_NONE - 1)
        return RT_NONE;
    if (op->nout >= op->outcap) {
        size_t c = op->outcap ? op->outcap * 2 : 1024;
        uint32_t **arrays[] = {&op->ov, &op->ot, &op->on, &op->osg};
        for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) {
            uint32_t *a = rt_realloc_array(*arrays[i], c, sizeof **arrays[i]);
            if (!a)
                return RT_NONE; /* outcap unchanged: the grown arrays are merely larger */
            *arrays[i] = a;
        }
        op->outcap = c;
    }
    uint32_t o = (uint32_t)op->nout++;
    op->ov[o] = v;
    op->ot[o] = t;
    op->on[o] = n;
    op->osg[o] = sg;
    if (t != RT_NONE) op->any_t = true;
    if (n != RT_NONE) op->any_n = true;
    if (sg) op->any_sg = true;
    return o;
}

static uint32_t output_vertex(obj_parser *op, uint32_t v, uint32_t t, uint32_t n, uint32_t sg)
{
    if (t == RT_NONE && n == RT_NONE && sg == 0) {
        /* a bare "f 1 2 3" corner: one vertex per position, a direct table */
        if (op->plain[v] == RT_NONE)
            op->plain[v] = new_output_vertex(op, v, t, n, sg);
        return op->plain[v];
    }
    if (2 * (op->nhashed + 1) > op->vhcap) {
        size_t cap = op->vhcap ? 2 * op->vhcap : 4096;
        uint32_t *tab = rt_alloc(cap, sizeof *tab);
        if (!tab)
            return RT_NONE;
        memset(tab, 0xff, cap * sizeof *tab);
        for (size_t o = 0; o < op->nout; o++) {
            if (op->ot[o] == RT_NONE && op->on[o] == RT_NONE && op->osg[o] == 0)
                continue; /* in the direct table */
            size_t h = vertex_hash(op->ov[o], op->ot[o], op->on[o], op->osg[o]) & (cap - 1);
            while (tab[h] != RT_NONE)
                h = (h + 1) & (cap - 1);
            tab[h] = (uint32_t)o;
        }
        free(op->vhash);
        op->vhash = tab;
        op->vhcap = cap;
    }
    size_t h = vertex_hash(v, t, n, sg) & (op->vhcap - 1);
    for (;; h = (h + 1) & (op->vhcap - 1)) {
        uint32_t o = op->vhash[h];
        if (o == RT_NONE)
            break;
        if (op->ov[o] == v && op->ot[o] == t && op->on[o] == n && op->osg[o] == sg)
            return o;
    }
    uint32_t o = new_output_vertex(op, v, t, n, sg);
    if (o != RT_NONE) {
        op->vhash[h] = o;
        op->nhashed++;
    }
    return o;
}

static rt_result obj_face(obj_parser *op, line_ctx *lc, const char *p, const char *eol)
{
    eol = cut_comment(p, eol);
    size_t nc = 0;
    bool all_t = true, all_n = true, any_n = false;
    for (;;) {
        p = rt_mesh_skip_space(p, eol);
        if (p >= eol)
            break;
        const char *te = rt_mesh_token_end(p, eol);
        const char *tok = p;
        int64_t iv, it = 0, in = 0;
        const char *q = rt_mesh_parse_int(p, te, &iv);
        if (!q)
            return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld:%d: malformed face corner '%.*s'", lc->file, lc->line,
                           col_of(lc, tok), (int)(te - tok > 40 ? 40 : te - tok), tok);
        bool has_t = false, has_n = false;
        if (q < te && *q == '/') {
            q++;
            if (q < te && *q != '/') {
                if (!(q = rt_mesh_parse_int(q, te, &it)))
                    goto bad_corner;
                has_t = true;
            }
            if (q < te && *q == '/') {
                q++;
                if (q < te) {
                    if (!(q = rt_mesh_parse_int(q, te, &in)))
                        goto bad_corner;
                    has_n = true;
                }
            }
        }
        if (q != te)
            goto bad_corner;
        uint32_t v = resolve_index(op, lc, tok, iv, op->nv, "vertex");
        if (v == RT_NONE)
            return op->err->code;
        uint32_t t = RT_NONE, n = RT_NONE;
        if (has_t && (t = resolve_index(op, lc, tok, it, op->nvt, "texture coordinate")) == RT_NONE)
            return op->err->code;
        if (has_n && (n = resolve_index(op, lc, tok, in, op->nvn, "normal")) == RT_NONE)
            return op->err->code;
        all_t = all_t && has_t;
        all_n = all_n && has_n;
        any_n = any_n || has_n;
        if (nc >= op->ccap) {
            size_t c = op->ccap ? op->ccap * 2 : 64;
            uint32_t **arrays[] = {&op->corner_out, &op->corner_v, &op->corner_t, &op->corner_n};
            for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) {
                uint32_t *a = rt_realloc_array(*arrays[i], c, sizeof **arrays[i]);
                if (!a)
                    return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for a face", lc->file);
                *arrays[i] = a;
            }
            op->ccap = c;
        }
        op->corner_v[nc] = v;
        op->corner_t[nc] = t;
        op->corner_n[nc] = n;
        nc++;
        p = te;
        continue;
    bad_corner:
        return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld:%d: malformed face corner '%.*s' (expected v, v/vt, v//vn or v/vt/vn)",
                       lc->file, lc->line, col_of(lc, tok), (int)(te - tok > 40 ? 40 : te - tok), tok);
    }
    if (nc < 3)
        return rt_fail(op->err, RT_ERR_INVALID, "%s:%ld: face has %zu vertices; at least 3 are needed", lc->file,
                       lc->line, nc);
    /* a face without normals in a smoothing group gets generated ones */
    uint32_t sg = any_n ? 0 : op->cur_sg;
    for (size_t k = 0; k < nc; k++) {
        uint32_t o = output_vertex(op, op->corner_v[k], op->corner_t[k], op->corner_n[k], sg);
        if (o == RT_NONE)
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for face vertices", lc->file);
        op->corner_out[k] = o;
    }
    uint8_t flags = (uint8_t)((all_t ? RT_TRI_UV : 0) | (all_n || sg ? RT_TRI_SMOOTH : 0));
    if (op->tcap < 3 * (nc - 2)) {
        size_t c = op->tcap;
        if (!grow_raw((void **)&op->tri_out, &c, 3 * (nc - 2), sizeof *op->tri_out))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for a face", lc->file);
        op->tcap = c;
    }
    size_t nt = rt_mesh_triangulate(op->v, op->corner_v, nc, op->tri_out);
    if (!rt_mesh_buf_reserve_triangles(op->buf, op->buf->nt + nt))
        return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for triangles", lc->file);
    const uint32_t *cv = op->corner_v, *co = op->corner_out, *tri = op->tri_out;
    for (size_t k = 0; k < nt; k++) {
        uint32_t a = tri[3 * k], b = tri[3 * k + 1], c = tri[3 * k + 2];
        if (cv[a] == cv[b] || cv[b] == cv[c] || cv[a] == cv[c]) {
            op->buf->skipped++;
            continue;
        }
        rt_mesh_buf_add_triangle(op->buf, co[a], co[b], co[c], op->cur_slot, flags);
    }
    return RT_OK;
}

static rt_result obj_usemtl(obj_parser *op, line_ctx *lc, const char *p, const char *eol)
{
    if (op->override_material)
        return RT_OK;
    char name[OBJ_NAME_MAX];
    if (!rest_string(p, cut_comment_ws(p, eol), name, sizeof name))
        return rt_fail(op->err, RT_ERR_LIMIT, "%s:%ld: material name longer than %d bytes", lc->file, lc->line,
                       OBJ_NAME_MAX - 1);
    if (!name[0]) {
        rt_warn("%s:%ld: usemtl without a name; using the default material", lc->file, lc->line);
        op->cur_slot = 0;
        return RT_OK;
    }
    uint32_t found = name_map_find(&op->slot_names, name, op->slots, sizeof *op->slots);
    if (found != RT_NONE) {
        op->cur_slot = found;
        return RT_OK;
    }
    if (op->nslot >= (size_t)RT_NONE - 1 ||
        !rt_grow((void **)&op->slots, &op->slotcap, op->nslot + 1, sizeof *op->slots))
        return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory", lc->file);
    obj_slot *sl = &op->slots[op->nslot];
    memcpy(sl->name, name, sizeof name);
    sl->line = lc->line;
    sl->material = RT_NONE;
    op->cur_slot = (uint32_t)op->nslot++;
    if (!name_map_put(&op->slot_names, op->cur_slot, op->slots, sizeof *op->slots))
        return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory", lc->file);
    return RT_OK;
}

static rt_result obj_mtllib(obj_parser *op, line_ctx *lc, const char *p, const char *eol)
{
    if (op->override_material)
        return RT_OK;
    eol = cut_comment_ws(p, eol);
    char rel[OBJ_PATH_MAX], full[OBJ_PATH_MAX];
    if (!rest_string(p, eol, rel, sizeof rel) || !obj_join(op->dir, rel, full, sizeof full))
        return rt_fail(op->err, RT_ERR_LIMIT, "%s:%ld: mtllib path too long", lc->file, lc->line);
    if (!rel[0]) {
        rt_warn("%s:%ld: mtllib without a file name", lc->file, lc->line);
        return RT_OK;
    }
    /* "mtllib a.mtl b.mtl" lists several files; a single name may contain spaces */
    struct stat st;
    if (stat(full, &st) == 0 || !strpbrk(rel, " \t"))
        return load_mtl(op, full, lc);
    for (;;) {
        p = rt_mesh_skip_space(p, eol);
        if (p >= eol)
            return RT_OK;
        const char *te = rt_mesh_token_end(p, eol);
        size_t n = (size_t)(te - p);
        if (n >= sizeof rel)
            return rt_fail(op->err, RT_ERR_LIMIT, "%s:%ld: mtllib path too long", lc->file, lc->line);
        memcpy(rel, p, n);
        rel[n] = 0;
        if (!obj_join(op->dir, rel, full, sizeof full))
            return rt_fail(op->err, RT_ERR_LIMIT, "%s:%ld: mtllib path too long", lc->file, lc->line);
        rt_result r = load_mtl(op, full, lc);
        if (r != RT_OK)
            return r;
        p = te;
    }
}

static rt_result obj_line(void *ctx, line_ctx *lc, const char *p, const char *eol)
{
    obj_parser *op = ctx;
    const char *ke = rt_mesh_token_end(p, eol);
    const char *kw = p;
    size_t kl = (size_t)(ke - p);
    p = ke;
    if (kl == 1 && kw[0] == 'v')
        return obj_vertex(op, lc, p, eol);
    if (kl == 1 && kw[0] == 'f')
        return obj_face(op, lc, p, eol);
    if (kl == 2 && kw[0] == 'v' && kw[1] == 't') {
        float f[3];
        int n = parse_floats(lc, p, cut_comment(p, eol), f, 3, op->err);
        if (n < 0)
            return op->err->code;
        if (n < 1)
            return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld: 'vt' needs at least 1 coordinate", lc->file, lc->line);
        if (op->nvt >= (size_t)RT_NONE - 1 || !grow_raw((void **)&op->vt, &op->vtcap, op->nvt + 1, sizeof *op->vt))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for texture coordinates", lc->file);
        op->vt[op->nvt++] = rt_v2(f[0], 1.0f - (n > 1 ? f[1] : 0.0f));
        return RT_OK;
    }
    if (kl == 2 && kw[0] == 'v' && kw[1] == 'n') {
        float f[3];
        int n = parse_floats(lc, p, cut_comment(p, eol), f, 3, op->err);
        if (n < 0)
            return op->err->code;
        if (n != 3)
            return rt_fail(op->err, RT_ERR_PARSE, "%s:%ld: 'vn' needs 3 numbers, got %d", lc->file, lc->line, n);
        if (op->nvn >= (size_t)RT_NONE - 1 || !grow_raw((void **)&op->vn, &op->vncap, op->nvn + 1, sizeof *op->vn))
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for normals", lc->file);
        op->vn[op->nvn++] = rt_v3(f[0], f[1], f[2]);
        return RT_OK;
    }
    if (kw_is(kw, kl, "usemtl"))
        return obj_usemtl(op, lc, p, eol);
    if (kw_is(kw, kl, "mtllib"))
        return obj_mtllib(op, lc, p, eol);
    if (kw_is(kw, kl, "s")) {
        /* "s off", "s 0" or "s <group>" */
        const char *le = cut_comment(p, eol);
        const char *q = rt_mesh_skip_space(p, le), *qe = rt_mesh_token_end(q, le);
        int64_t g = 0;
        if (kw_is(q, (size_t)(qe - q), "off") || q >= qe)
            g = 0;
        else if (rt_mesh_parse_int(q, qe, &g) != qe || g < 0 || g >= (int64_t)RT_NONE) {
            if (rt_warn_once_first(&op->warned, "s", 1))
                rt_warn("%s:%ld:%d: smoothing group '%.*s' is not 'off' or a number; taken as off (warned once)",
                        lc->file, lc->line, col_of(lc, q), (int)(qe - q > 40 ? 40 : qe - q), q);
            g = 0;
        }
        op->cur_sg = (uint32_t)g;
        return RT_OK;
    }
    if (kw_is(kw, kl, "o") || kw_is(kw, kl, "g"))
        return RT_OK;
    warn_unknown(&op->warned, lc, kw, kl);
    return RT_OK;
}

/* ------------------------------------------------------- materials */

/* The texture for a map_Kd (colour) or bump map (data) line. A file that
 * does not exist follows the missing-texture rule (rt/scene/texture.h): a
 * warning at the map line, the checker for colour, nothing for data; an
 * image that exists but does not load is an error at that line. */
static rt_result load_texture(rt_scene *s, const char *path, const char *mtl_file, long line, const char *what,
                              bool colour, uint32_t *out, rt_error *err)
{
    rt_error e = {0};
    uint32_t img;
    rt_texture tex;
    *out = RT_NONE;
    if (rt_image_load_file(s, path, &img, &e) == RT_OK) {
        tex = rt_texture_image(img);
    } else if (rt_image_file_missing(path)) {
        rt_warn("%s:%ld: %s: image '%s' not found; %s", mtl_file, line, what, path, RT_MISSING_TEXTURE_NOTE);
        if (!colour)
            return RT_OK;
        tex = rt_texture_missing();
    } else {
        return rt_fail(err, e.code, "%s:%ld: %s: %s", mtl_file, line, what, e.message);
    }
    if ((*out = rt_scene_add_texture(s, &tex)) == RT_NONE)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for textures", mtl_file);
    return RT_OK;
}

static rt_result make_material(rt_scene *s, const obj_mtl *om, const char *objname, const char *mtl_file,
                               rt_material *m, rt_error *err)
{
    /* "<objfile>:<name>", cut to fit the 64-byte name field */
    char name[sizeof m->name];
    size_t on = strlen(objname), nn = strlen(om->name), cap = sizeof name - 1;
    if (on > cap / 2 && on + 1 + nn > cap)
        on = cap - 1 - (nn < cap / 2 ? nn : cap / 2);
    size_t k = 0;
    memcpy(name, objname, on);
    k = on;
    name[k++] = ':';
    if (nn > cap - k)
        nn = cap - k;
    memcpy(name + k, om->name, nn);
    name[k + nn] = 0;
    rt_material_default(m, name);
    if (om->has_kd)
        m->color = om->kd;
    if (om->has_ks)
        m->specular = rt_clampf(rt_luminance(om->ks), 0.0f, 1.0f);
    if (om->has_ns)
        m->shininess = om->ns > 0.0f ? om->ns : 0.0f;
    if (om->has_ni && om->ni > 0.0f)
        m->ior = om->ni;
    if (om->has_alpha) {
        m->alpha = rt_clampf(om->alpha, 0.0f, 1.0f);
        if (m->alpha < 1.0f)
            m->alpha_mode = RT_ALPHA_BLEND;
    }
    if (om->has_ke)
        m->emission = om->ke;
    else if (om->has_ka && rt_max3(om->ka) > 1.0f)
        m->emission = om->ka;
    if (om->has_pr)
        m->roughness = rt_clampf(om->pr, 0.0f, 1.0f);
    if (om->has_pm)
        m->metallic = rt_clampf(om->pm, 0.0f, 1.0f);
    if (om->illum == 3 || om->illum == 5)
        m->reflectivity = om->has_ks ? rt_clampf(rt_max3(om->ks), 0.0f, 1.0f) : 1.0f;
    if (om->illum == 4 || om->illum == 6 || om->illum == 7) {
        /* glass: transparency comes from refraction, not from d */
        m->transmission = 1.0f;
        if (om->has_tf)
            m->transmission_color = om->tf;
        m->alpha = 1.0f;
        m->alpha_mode = RT_ALPHA_OPAQUE;
    }
    rt_result r;
    if (om->map_kd &&
        (r = load_texture(s, om->map_kd, mtl_file, om->map_kd_line, "map_Kd", true, &m->base_color_tex.texture,
                          err)) != RT_OK)
        return r;
    if (om->map_bump) {
        if ((r = load_texture(s, om->map_bump, mtl_file, om->map_bump_line, "normal map", false,
                              &m->normal_tex.texture, err)) != RT_OK)
            return r;
        m->normal_scale = om->bump_scale;
    }
    return RT_OK;
}

/* Adds the MTL materials to the scene and resolves every usemtl slot. */
static rt_result resolve_materials(obj_parser *op, rt_scene *s, uint32_t material)
{
    const char *objname = rt_path_basename(op->path);
    uint32_t *ids = op->nmtl ? rt_alloc(op->nmtl, sizeof *ids) : NULL;
    if (op->nmtl && !ids)
        return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for materials", op->path);
    for (size_t i = 0; i < op->nmtl; i++) {
        rt_material m;
        rt_result r = make_material(s, &op->mtls[i], objname, op->mtl_files[op->mtls[i].file], &m, op->err);
        if (r != RT_OK) {
            free(ids);
            return r;
        }
        if ((ids[i] = rt_scene_add_material(s, &m)) == RT_NONE) {
            free(ids);
            return rt_fail(op->err, RT_ERR_NOMEM, "%s: out of memory for materials", op->path);
        }
    }
    op->slots[0].material = material;
    size_t unknown = 0;
    for (size_t k = 1; k < op->nslot; k++) {
        obj_slot *sl = &op->slots[k];
        sl->material = material;
        /* the last definition of a name wins (name_map_put replaces) */
        uint32_t i = name_map_find(&op->mtl_names, sl->name, op->mtls, sizeof *op->mtls);
        if (i != RT_NONE)
            sl->material = ids[i];
        else if (++unknown <= 8)
            rt_warn("%s:%ld: usemtl '%s': no such material in the MTL files; using the default material", op->path,
                    sl->line, sl->name);
    }
    if (unknown > 8)
        rt_warn("%s: %zu more unknown usemtl names use the default material", op->path, unknown - 8);
    free(ids);
    return RT_OK;
}

/* ------------------------------------------------------------ load */

static void obj_free(obj_parser *op)
{
    free(op->v); free(op->vc); free(op->vt); free(op->vn);
    free(op->ov); free(op->ot); free(op->on); free(op->vhash); free(op->plain);
    for (size_t i = 0; i < op->nmtl; i++) {
        free(op->mtls[i].map_kd);
        free(op->mtls[i].map_bump);
    }
    for (size_t i = 0; i < op->nfiles; i++)
        free(op->mtl_files[i]);
    free(op->mtl_files);
    free(op->mtl_names.tab); free(op->slot_names.tab);
    free(op->corner_out); free(op->corner_v); free(op->corner_t); free(op->corner_n); free(op->tri_out);
    free(op->osg);
    free(op->mtls); free(op->slots);
}

rt_result rt_obj_parse(const rt_mesh_input *in, rt_mesh_buf *b)
{
    const char *path = in->name;
    rt_error *err = in->err;
    rt_scene *s = in->scene;
    obj_parser *op = calloc(1, sizeof *op);
    if (!op)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
    rt_result r = RT_OK;
    op->path = path;
    op->err = err;
    op->buf = b;
    op->override_material = in->override_material;
    rt_path_dirname(path, op->dir, sizeof op->dir);
    if (!rt_grow((void **)&op->slots, &op->slotcap, 1, sizeof *op->slots)) {
        r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    op->nslot = 1;
    memset(&op->slots[0], 0, sizeof op->slots[0]);

    r = for_each_line(path, in->bytes, in->size, obj_line, op);
    if (r != RT_OK)
        goto done;

    if (!in->override_material && (r = resolve_materials(op, s, in->material)) != RT_OK)
        goto done;

    /* output vertices from the (v, vt, vn) triples */
    unsigned attrs = (op->any_n || op->any_sg ? RT_MESH_NRM : 0) | (op->any_t ? RT_MESH_UV : 0) |
                     (op->vc ? RT_MESH_COL : 0);
    if (!rt_mesh_buf_enable(b, attrs) || !rt_mesh_buf_reserve_vertices(b, op->nout)) {
        r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %zu vertices", path, op->nout);
        goto done;
    }
    for (size_t o = 0; o < op->nout; o++) {
        b->pos[o] = op->v[op->ov[o]];
        if (b->nrm)
            b->nrm[o] = op->on[o] != RT_NONE ? op->vn[op->on[o]] : rt_v3s(0);
        if (b->uv)
            b->uv[o] = op->ot[o] != RT_NONE ? op->vt[op->ot[o]] : rt_v2(0, 0);
        if (b->col) {
            rt_vec3 c = op->vc[op->ov[o]];
            b->col[o] = rt_v4(c.x, c.y, c.z, 1.0f);
        }
    }
    b->nv = op->nout;
    if (op->any_sg) {
        /* smoothing groups: area-weighted sums of the face normals around each
         * (position, group) vertex; triangles of one face share the group */
        for (size_t t = 0; t < b->nt; t++) {
            const uint32_t *ix = b->idx + 3 * t;
            if (!op->osg[ix[0]])
                continue;
            rt_vec3 p0 = b->pos[ix[0]], p1 = b->pos[ix[1]], p2 = b->pos[ix[2]];
            rt_vec3 fn = rt_cross(rt_sub(p1, p0), rt_sub(p2, p0));
            for (int k = 0; k < 3; k++)
                b->nrm[ix[k]] = rt_add(b->nrm[ix[k]], fn);
        }
    }
    for (size_t t = 0; t < b->nt; t++) {
        b->mat[t] = in->override_material ? in->material : op->slots[b->mat[t]].material;
        if (op->vc)
            b->flags[t] |= RT_TRI_COLOR;
    }
done:
    obj_free(op);
    free(op);
    return r;
}
