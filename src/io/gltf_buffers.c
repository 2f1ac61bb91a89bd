/* gltf_buffers.c - the bytes behind a glTF document (gltf_doc.h):
 * buffers from files beside the .gltf, base64 data: URIs or the GLB BIN
 * chunk, their real sizes checked against byteLength; accessor elements
 * as floats or unsigned integers (normalized integers by the spec's
 * formulas, sparse accessors applied); and compressed geometry,
 * EXT_meshopt_compression views (rt/io/meshopt.h) and
 * KHR_draco_mesh_compression primitives (rt/io/draco.h), decoded into
 * views of their own within a per-load budget.
 * Sources: Khronos glTF 2.0 specification ("Accessors", "Animations" for
 * the normalized integer formulas), the two extension specifications.
 */
#include "gltf_doc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/io/base64.h"
#include "rt/io/draco.h"
#include "rt/io/meshopt.h"

static int hexval(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* Decodes a data: URI (base64 only) into a fresh buffer. */
rt_result gl_decode_data_uri(gl_doc *d, int tok, const char *uri, size_t len, const char *what, uint8_t **out,
                             size_t *out_len)
{
    const char *comma = memchr(uri, ',', len);
    if (!comma)
        return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: data: URI without a ','", what);
    size_t head = (size_t)(comma - uri);
    if (head < 12 || memcmp(comma - 7, ";base64", 7) != 0)
        return gl_fail_at(d, tok, RT_ERR_UNSUPPORTED, "%s: only base64 data: URIs are supported", what);
    const char *b = comma + 1;
    size_t blen = len - head - 1;
    uint8_t *buf = malloc(rt_base64_max_decoded(blen));
    if (!buf)
        return gl_fail_at(d, tok, RT_ERR_NOMEM, "%s: out of memory decoding %zu base64 characters", what, blen);
    size_t n, bad;
    if (rt_base64_decode(b, blen, buf, &n, &bad) != RT_OK) {
        free(buf);
        if (bad >= blen)
            return gl_fail_at(d, tok, RT_ERR_PARSE, "%s: bad base64 in data: URI (length %zu is not a multiple of 4)",
                              what, blen);
        unsigned char c = (unsigned char)b[bad];
        return gl_fail_at(d, tok, RT_ERR_PARSE, "%s: bad base64 in data: URI: character %zu is '%c' (0x%02X)", what,
                          head + 1 + bad, c >= 32 && c < 127 ? c : '?', c);
    }
    *out = buf;
    *out_len = n;
    return RT_OK;
}

/* Resolves a relative file URI against the .gltf's directory. */
rt_result gl_uri_to_path(gl_doc *d, int tok, const char *uri, const char *what, char **out)
{
    size_t len = strlen(uri);
    for (const char *p = uri; *p && *p != '/'; p++)
        if (*p == ':')
            return gl_fail_at(d, tok, RT_ERR_UNSUPPORTED, "%s: URI \"%.200s\" has a scheme; only relative paths and "
                              "data: URIs are supported", what, uri);
    if (uri[0] == '/' || uri[0] == '\0')
        return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: URI \"%.200s\" is not a relative path", what, uri);
    size_t dl = strlen(d->dir);
    char *path = malloc(dl + len + 1);
    if (!path)
        return gl_fail_at(d, tok, RT_ERR_NOMEM, "%s: out of memory", what);
    memcpy(path, d->dir, dl);
    size_t o = dl;
    for (size_t i = 0; i < len; i++) {
        if (uri[i] == '%') {
            int h = i + 2 < len ? hexval(uri[i + 1]) : -1, l = i + 2 < len ? hexval(uri[i + 2]) : -1;
            if (h < 0 || l < 0 || (h == 0 && l == 0)) {
                free(path);
                return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: bad percent-encoding in URI \"%.200s\"", what, uri);
            }
            path[o++] = (char)(h * 16 + l);
            i += 2;
        } else {
            path[o++] = uri[i];
        }
    }
    path[o] = '\0';
    *out = path;
    return RT_OK;
}

/* The decoded string of token t in a fresh buffer. */
rt_result gl_token_string(gl_doc *d, int t, const char *what, char **out)
{
    size_t cap = (size_t)(d->j.tok[t].end - d->j.tok[t].start) * 4 + 1; /* \uXXXX never grows */
    char *s = malloc(cap);
    if (!s)
        return gl_fail_at(d, t, RT_ERR_NOMEM, "%s: out of memory", what);
    if (rt_json_string(&d->j, t, s, cap) < 0) {
        free(s);
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: bad string", what);
    }
    *out = s;
    return RT_OK;
}

rt_result gl_load_buffers(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->buffer_count; i++) {
        gl_buffer *b = &d->buffers[i];
        char what[48];
        snprintf(what, sizeof what, "buffers[%zu]", i);
        size_t have = 0;
        if (b->uri < 0 && b->fallback && !(d->glb && i == 0 && d->bin)) {
            continue; /* no data: only compressed views refer to it (validate_meshopt_view) */
        } else if (b->uri < 0) {
            if (!d->glb || i != 0 || !d->bin)
                return gl_fail_at(d, b->tok, RT_ERR_INVALID, "%s has no uri and there is no GLB BIN chunk", what);
            b->data = d->bin;
            have = d->bin_size;
        } else {
            char *uri;
            if ((r = gl_token_string(d, b->uri, what, &uri)) != RT_OK)
                return r;
            if (strncmp(uri, "data:", 5) == 0) {
                r = gl_decode_data_uri(d, b->uri, uri, strlen(uri), what, &b->owned, &have);
            } else {
                char *path = NULL;
                r = gl_uri_to_path(d, b->uri, uri, what, &path);
                if (r == RT_OK) {
                    char w2[64];
                    snprintf(w2, sizeof w2, "%s: ", what);
                    r = gl_read_file(d, path, w2, &b->owned, &have);
                }
                free(path);
            }
            free(uri);
            if ((r = r) != RT_OK)
                return r;
            b->data = b->owned;
        }
        if (have < b->byte_length)
            return gl_fail_at(d, b->tok, RT_ERR_INVALID, "%s: byteLength is %zu but only %zu bytes of data exist", what,
                              b->byte_length, have);
    }
    return RT_OK;
}

static inline float comp_float(const uint8_t *p, int ct, bool norm)
{
    switch (ct) {
    case GL_FLOAT: { float f; memcpy(&f, p, 4); return f; }
    case GL_BYTE: { float v = (float)(int8_t)p[0]; return norm ? fmaxf(v / 127.0f, -1.0f) : v; }
    case GL_UNSIGNED_BYTE: return norm ? p[0] / 255.0f : (float)p[0];
    case GL_SHORT: { int16_t v; memcpy(&v, p, 2); return norm ? fmaxf(v / 32767.0f, -1.0f) : (float)v; }
    case GL_UNSIGNED_SHORT: { uint16_t v; memcpy(&v, p, 2); return norm ? v / 65535.0f : (float)v; }
    case GL_UNSIGNED_INT: { uint32_t v; memcpy(&v, p, 4); return (float)v; }
    }
    return 0.0f;
}

static inline uint32_t comp_uint(const uint8_t *p, int ct)
{
    switch (ct) {
    case GL_UNSIGNED_BYTE: return p[0];
    case GL_UNSIGNED_SHORT: { uint16_t v; memcpy(&v, p, 2); return v; }
    case GL_UNSIGNED_INT: { uint32_t v; memcpy(&v, p, 4); return v; }
    }
    return 0;
}

const uint8_t *gl_view_ptr(const gl_doc *d, uint32_t view, size_t offset)
{
    const gl_view *v = &d->views[view];
    if (v->decoded)
        return v->decoded + offset;
    return d->buffers[v->buffer].data + v->offset + offset;
}

/* Reads the sparse index k, checking order and range. */
static rt_result sparse_index(gl_doc *d, uint32_t ai, size_t k, size_t *prev, size_t *out)
{
    const gl_accessor *a = &d->accessors[ai];
    size_t cs = gl_comp_size(a->sp_idx_ctype);
    size_t idx = comp_uint(gl_view_ptr(d, a->sp_idx_view, a->sp_idx_offset) + k * cs, a->sp_idx_ctype);
    if (idx >= a->count || (k > 0 && idx <= *prev))
        return gl_fail_at(d, a->tok, RT_ERR_INVALID,
                          "accessors[%u].sparse.indices: element %zu is %zu (must increase and be below %zu)", ai, k,
                          idx, a->count);
    *prev = idx;
    *out = idx;
    return RT_OK;
}

/* Decodes accessor ai into out (count * ncomp floats), sparse applied. */
rt_result gl_read_floats(gl_doc *d, uint32_t ai, float *out)
{
    rt_result r;
    const gl_accessor *a = &d->accessors[ai];
    size_t n = (size_t)a->ncomp, cs = gl_comp_size(a->ctype), es = gl_elem_size(a);
    if (a->view == RT_NONE) {
        memset(out, 0, a->count * n * sizeof *out);
    } else {
        size_t stride = d->views[a->view].stride ? d->views[a->view].stride : es;
        const uint8_t *p = gl_view_ptr(d, a->view, a->offset);
        if (a->ctype == GL_FLOAT) {
            if (stride == es)
                memcpy(out, p, a->count * es);
            else
                for (size_t i = 0; i < a->count; i++)
                    memcpy(out + i * n, p + i * stride, es);
        } else {
            for (size_t i = 0; i < a->count; i++)
                for (size_t c = 0; c < n; c++)
                    out[i * n + c] = comp_float(p + i * stride + c * cs, a->ctype, a->normalized);
        }
    }
    if (a->sparse_count) {
        const uint8_t *vals = gl_view_ptr(d, a->sp_val_view, a->sp_val_offset);
        size_t prev = 0, idx;
        for (size_t k = 0; k < a->sparse_count; k++) {
            if ((r = sparse_index(d, ai, k, &prev, &idx)) != RT_OK)
                return r;
            for (size_t c = 0; c < n; c++)
                out[idx * n + c] = comp_float(vals + k * es + c * cs, a->ctype, a->normalized);
        }
    }
    return RT_OK;
}

/* Decodes an index accessor into out (count values), sparse applied. */
rt_result gl_read_uints(gl_doc *d, uint32_t ai, uint32_t *out)
{
    rt_result r;
    const gl_accessor *a = &d->accessors[ai];
    size_t cs = gl_comp_size(a->ctype);
    if (a->view == RT_NONE) {
        memset(out, 0, a->count * sizeof *out);
    } else {
        size_t stride = d->views[a->view].stride ? d->views[a->view].stride : cs;
        const uint8_t *p = gl_view_ptr(d, a->view, a->offset);
        switch (a->ctype) {
        case GL_UNSIGNED_BYTE:
            for (size_t i = 0; i < a->count; i++) out[i] = p[i * stride];
            break;
        case GL_UNSIGNED_SHORT:
            for (size_t i = 0; i < a->count; i++) { uint16_t v; memcpy(&v, p + i * stride, 2); out[i] = v; }
            break;
        default:
            if (stride == 4)
                memcpy(out, p, a->count * 4);
            else
                for (size_t i = 0; i < a->count; i++) memcpy(&out[i], p + i * stride, 4);
        }
    }
    if (a->sparse_count) {
        const uint8_t *vals = gl_view_ptr(d, a->sp_val_view, a->sp_val_offset);
        size_t prev = 0, idx;
        for (size_t k = 0; k < a->sparse_count; k++) {
            if ((r = sparse_index(d, ai, k, &prev, &idx)) != RT_OK)
                return r;
            out[idx] = comp_uint(vals + k * cs, a->ctype);
        }
    }
    return RT_OK;
}

/* Counts bytes about to be decoded against the per-load limit. */
static rt_result decoded_budget(gl_doc *d, int tok, size_t bytes)
{
    if (bytes > GL_MAX_DECODED - d->decoded_bytes)
        return gl_fail_at(d, tok, RT_ERR_LIMIT, "decompressed data would pass the limit of %zu bytes per file",
                          GL_MAX_DECODED);
    d->decoded_bytes += bytes;
    return RT_OK;
}

/* EXT_meshopt_compression: every compressed view decoded into its own
 * bytes, which view_ptr then reads in place of the (fallback) buffer. */
rt_result gl_decode_meshopt_views(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->view_count; i++) {
        gl_view *v = &d->views[i];
        if (!v->meshopt)
            continue;
        if ((r = decoded_budget(d, v->mo_tok, v->length)) != RT_OK)
            return r;
        v->decoded = malloc(v->length);
        if (!v->decoded)
            return gl_fail_at(d, v->mo_tok, RT_ERR_NOMEM, "out of memory for %zu decompressed bytes", v->length);
        const gl_buffer *src = &d->buffers[v->mo_buffer];
        const char *why = rt_meshopt_decode(v->decoded, v->mo_count, v->mo_stride, src->data + v->mo_offset,
                                            v->mo_length, (rt_meshopt_mode)v->mo_mode,
                                            (rt_meshopt_filter)v->mo_filter);
        if (why)
            return gl_fail_at(d, v->mo_tok, RT_ERR_INVALID, "bufferViews[%zu]: EXT_meshopt_compression: %s", i, why);
    }
    return RT_OK;
}

/* Points accessor a at decoded bytes (owned by a new view), as plain
 * unsigned ints or floats. An accessor fills once: two Draco primitives
 * sharing one would each claim it. */
static rt_result fill_accessor(gl_doc *d, uint32_t ai, int tok, void *bytes, size_t length, int ctype)
{
    gl_accessor *a = &d->accessors[ai];
    if (!a->draco) {
        free(bytes);
        return gl_fail_at(d, tok, RT_ERR_UNSUPPORTED, "accessors[%u] is filled by two KHR_draco_mesh_compression "
                          "primitives", ai);
    }
    gl_view *views = realloc(d->views, (d->view_count + 1) * sizeof *views);
    if (!views) {
        free(bytes);
        return gl_fail_at(d, tok, RT_ERR_NOMEM, "out of memory");
    }
    d->views = views;
    gl_view *v = &d->views[d->view_count];
    memset(v, 0, sizeof *v);
    v->buffer = RT_NONE;
    v->length = length;
    v->decoded = bytes;
    v->tok = tok;
    a->view = (uint32_t)d->view_count++;
    a->offset = 0;
    a->ctype = ctype;
    a->normalized = false;
    a->sparse_count = 0;
    a->draco = false;
    return RT_OK;
}

/* One KHR_draco_mesh_compression primitive's indices and attributes from
 * its decoded mesh, checked against the counts its accessors declare. */
static rt_result fill_from_draco(gl_doc *d, size_t p, const rt_draco_mesh *m)
{
    rt_result r;
    const gl_prim *pr = &d->prims[p];
    int tok = pr->draco_tok;
    char name[64];
    size_t faces = rt_draco_faces(m), points = rt_draco_points(m);
    size_t nidx = d->accessors[pr->indices].count;
    if (faces > SIZE_MAX / 3 || faces * 3 != nidx)
        return gl_fail_at(d, tok, RT_ERR_INVALID,
                          "%s: the Draco mesh has %zu triangles, the indices accessor %u has %zu indices",
                          gl_prim_name(d, p, name, sizeof name), faces, pr->indices, nidx);
    if ((r = decoded_budget(d, tok, nidx * sizeof(uint32_t))) != RT_OK)
        return r;
    uint32_t *idx = malloc((nidx ? nidx : 1) * sizeof *idx);
    if (!idx)
        return gl_fail_at(d, tok, RT_ERR_NOMEM, "out of memory for %zu indices", nidx);
    rt_draco_indices(m, idx);
    for (size_t k = 0; k < nidx; k++)
        if (idx[k] >= points) {
            uint32_t bad = idx[k];
            free(idx);
            return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: a Draco triangle names point %u of %zu",
                              gl_prim_name(d, p, name, sizeof name), bad, points);
        }
    if ((r = fill_accessor(d, pr->indices, tok, idx, nidx * sizeof *idx, GL_UNSIGNED_INT)) != RT_OK)
        return r;
    for (int k = 0; k < ATTR_COUNT; k++) {
        if (pr->draco_id[k] == RT_NONE)
            continue;
        uint32_t ai = pr->attr[k];
        const gl_accessor *a = &d->accessors[ai];
        if (points != a->count)
            return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: the Draco mesh has %zu points, accessor %u (%s) "
                              "has %zu", gl_prim_name(d, p, name, sizeof name), points, ai, gl_attr_names[k], a->count);
        int have = rt_draco_components(m, pr->draco_id[k]);
        if (have == 0)
            return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: %s is attribute %u, which the Draco mesh does "
                              "not have", gl_prim_name(d, p, name, sizeof name), gl_attr_names[k], pr->draco_id[k]);
        size_t n = points * (size_t)a->ncomp;
        if ((r = decoded_budget(d, tok, n * sizeof(float))) != RT_OK)
            return r;
        float *vals = malloc((n ? n : 1) * sizeof *vals);
        if (!vals)
            return gl_fail_at(d, tok, RT_ERR_NOMEM, "out of memory for %zu values", n);
        if (!rt_draco_attribute(m, pr->draco_id[k], a->ncomp, vals)) {
            free(vals);
            return gl_fail_at(d, tok, RT_ERR_INVALID, "%s: Draco attribute %u (%s) cannot be read as "
                              "%d floats", gl_prim_name(d, p, name,
                                                        sizeof name), pr->draco_id[k], gl_attr_names[k], a->ncomp);
        }
        if ((r = fill_accessor(d, ai, tok, vals, n * sizeof *vals, GL_FLOAT)) != RT_OK)
            return r;
    }
    return RT_OK;
}

rt_result gl_decode_draco_prims(gl_doc *d)
{
    for (size_t p = 0; p < d->prim_count; p++) {
        const gl_prim *pr = &d->prims[p];
        if (pr->draco_view == RT_NONE)
            continue;
        char why[200], name[64];
        rt_draco_mesh *m = rt_draco_decode(gl_view_ptr(d, pr->draco_view, 0), d->views[pr->draco_view].length, why,
                                           sizeof why);
        if (!m)
            return gl_fail_at(d, pr->draco_tok, RT_ERR_INVALID, "%s: KHR_draco_mesh_compression: %s",
                              gl_prim_name(d, p, name, sizeof name), why);
        rt_result r = fill_from_draco(d, p, m);
        rt_draco_free(m);
        if ((r = r) != RT_OK)
            return r;
    }
    return RT_OK;
}
