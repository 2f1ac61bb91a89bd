/* gltf_doc.c - what every pass of the glTF loader reads the document with
 * (gltf_doc.h): errors located at a token ("file: byte N: ..."), the files
 * a document names, the typed JSON field readers whose messages name the
 * JSON path and the byte, accessor component and element sizes (with the
 * spec's column padding), glTF's column-major matrices, and the name of a
 * primitive for messages. It calls no pass: the passes (gltf_parse.c,
 * gltf_material.c, gltf_check.c, gltf_buffers.c, gltf_pose.c,
 * gltf_flatten.c) and gl_load (gltf.c) stand above it.
 * Source: Khronos glTF 2.0 specification ("Accessors", "Data Alignment").
 */
#include "gltf_doc.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"

rt_result gl_fail_at(gl_doc *d, int tok, rt_result code, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (tok >= 0 && tok < d->j.count)
        return rt_fail(d->err, code, "%s: byte %zu: %s", d->path, d->json_base + (size_t)d->j.tok[tok].start, msg);
    return rt_fail(d->err, code, "%s: %s", d->path, msg);
}

/* Reads a file the document names (an external buffer). */
rt_result gl_read_file(gl_doc *d, const char *path, const char *what, uint8_t **data, size_t *size)
{
    rt_error inner = {0};
    char *bytes;
    if (rt_read_file(path, GL_MAX_FILE, &bytes, size, &inner) != RT_OK)
        return rt_fail(d->err, inner.code, "%s: %s%s", d->path, what, inner.message);
    *data = (uint8_t *)bytes;
    return RT_OK;
}

const char *const gl_attr_names[ATTR_COUNT] = {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1",
                                            "COLOR_0"};

/* Checks that t is an object whose keys are all strings followed by a value. */
rt_result gl_expect_object(gl_doc *d, int t, const char *where)
{
    if (jtype(d, t) != RT_JSON_OBJECT)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: expected an object", where);
    int k = t + 1;
    for (int n = 0; n < d->j.tok[t].size; n++) {
        if (k + 1 >= d->j.count || d->j.tok[k].type != RT_JSON_STRING || d->j.tok[k].size != 1)
            return gl_fail_at(d, k < d->j.count ? k : t, RT_ERR_PARSE, "%s: expected \"key\": value", where);
        k = rt_json_skip(&d->j, k + 1);
    }
    return RT_OK;
}

rt_result gl_expect_array(gl_doc *d, int t, const char *where, const char *key)
{
    if (jtype(d, t) != RT_JSON_ARRAY)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an array", where, key);
    return RT_OK;
}

static rt_result get_num(gl_doc *d, const char *where, const char *key, int t, double *v)
{
    if (!rt_json_number(&d->j, t, v))
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected a number", where, key);
    return RT_OK;
}

rt_result gl_get_index(gl_doc *d, const char *where, const char *key, int t, uint32_t *out)
{
    double v;
    if (!rt_json_number(&d->j, t, &v) || v < 0 || v != floor(v) || v > 4294967294.0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an index (a non-negative integer)", where, key);
    *out = (uint32_t)v;
    return RT_OK;
}

rt_result gl_get_size(gl_doc *d, const char *where, const char *key, int t, size_t *out)
{
    double v;
    if (!rt_json_number(&d->j, t, &v) || v < 0 || v != floor(v) || v > 9007199254740992.0 || v > (double)SIZE_MAX)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected a non-negative integer", where, key);
    *out = (size_t)v;
    return RT_OK;
}

rt_result gl_get_int(gl_doc *d, const char *where, const char *key, int t, int *out)
{
    double v;
    if (!rt_json_number(&d->j, t, &v) || v != floor(v) || v < -2147483647.0 || v > 2147483647.0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an integer", where, key);
    *out = (int)v;
    return RT_OK;
}

rt_result gl_get_float(gl_doc *d, const char *where, const char *key, int t, float *out)
{
    rt_result r;
    double v;
    if ((r = get_num(d, where, key, t, &v)) != RT_OK)
        return r;
    if (fabs(v) > FLT_MAX)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: number out of float range", where, key);
    *out = (float)v;
    return RT_OK;
}

rt_result gl_get_floats(gl_doc *d, const char *where, const char *key, int t, float *out, int n)
{
    rt_result r;
    if (jtype(d, t) != RT_JSON_ARRAY || jsize(d, t) != n)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected an array of %d numbers", where, key, n);
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e))
        if ((r = gl_get_float(d, where, key, e, &out[i])) != RT_OK)
            return r;
    return RT_OK;
}

rt_result gl_get_ranged(gl_doc *d, const char *where, const char *key, int t, float lo, float hi, float *out)
{
    rt_result r;
    float v = 0;
    if ((r = gl_get_float(d, where, key, t, &v)) != RT_OK)
        return r;
    if (!(v >= lo && v <= hi))
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s %g is outside [%g, %g]", where, key, (double)v, (double)lo,
                          (double)hi);
    *out = v;
    return RT_OK;
}

rt_result gl_get_floats_ranged(gl_doc *d, const char *where, const char *key, int t, int n, float lo, float hi,
                               float *out)
{
    rt_result r;
    float c[16] = {0};
    if (n < 1 || n > 16)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: bad component count", where, key);
    if ((r = gl_get_floats(d, where, key, t, c, n)) != RT_OK)
        return r;
    for (int i = 0; i < n; i++)
        if (!(c[i] >= lo && c[i] <= hi))
            return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s component %d (%g) is outside [%g, %g]", where, key, i,
                              (double)c[i], (double)lo, (double)hi);
    memcpy(out, c, (size_t)n * sizeof *out);
    return RT_OK;
}

rt_result gl_get_bool(gl_doc *d, const char *where, const char *key, int t, bool *out)
{
    if (!rt_json_bool(&d->j, t, out))
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected true or false", where, key);
    return RT_OK;
}

rt_result gl_get_string(gl_doc *d, const char *where, const char *key, int t, char *buf, size_t cap)
{
    if (rt_json_string(&d->j, t, buf, cap) < 0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.%s: expected a string (at most %zu bytes, valid escapes)", where,
                          key, cap - 1);
    return RT_OK;
}

/* Allocates one zeroed record per element of array token t. */
rt_result gl_alloc_table(gl_doc *d, int t, const char *key, size_t elem, void **out, size_t *count)
{
    rt_result r;
    if ((r = gl_expect_array(d, t, "glTF", key)) != RT_OK)
        return r;
    if (*out)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s appears twice", key);
    size_t n = (size_t)jsize(d, t);
    void *p = rt_alloc(n, elem);
    if (!p)
        return gl_fail_at(d, t, RT_ERR_NOMEM, "out of memory for %zu %s", n, key);
    *out = p;
    *count = n;
    return RT_OK;
}

size_t gl_comp_size(int ct)
{
    switch (ct) {
    case GL_BYTE: case GL_UNSIGNED_BYTE: return 1;
    case GL_SHORT: case GL_UNSIGNED_SHORT: return 2;
    case GL_UNSIGNED_INT: case GL_FLOAT: return 4;
    }
    return 0;
}

/* Element size with the spec's column padding for matrices ("Data Alignment"). */
size_t gl_elem_size(const gl_accessor *a)
{
    size_t cs = gl_comp_size(a->ctype);
    if (a->cols > 1) {
        size_t col = ((size_t)a->rows * cs + 3) & ~(size_t)3;
        return col * (size_t)a->cols;
    }
    return (size_t)a->ncomp * cs;
}

/* glTF matrices are column-major; rt_mat4 is m[row][col]. */
rt_mat4 gl_mat_from_gltf(const float *c)
{
    rt_mat4 r;
    for (int row = 0; row < 4; row++)
        for (int col = 0; col < 4; col++)
            r.m[row][col] = c[col * 4 + row];
    return r;
}


/* "meshes[m].primitives[k]" for the primitive at index p of doc.prims. */
const char *gl_prim_name(const gl_doc *d, size_t p, char *buf, size_t cap)
{
    for (size_t m = 0; m < d->mesh_count; m++)
        if (p >= d->meshes[m].first && p - d->meshes[m].first < d->meshes[m].count) {
            snprintf(buf, cap, "meshes[%zu].primitives[%zu]", m, p - d->meshes[m].first);
            return buf;
        }
    snprintf(buf, cap, "primitive %zu", p);
    return buf;
}

