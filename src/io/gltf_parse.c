/* gltf_parse.c - the second pass of the glTF loader (gltf_doc.h): the
 * JSON document, tokenized once (json.c), mapped into flat tables
 * of records with a count each (buffers, bufferViews, accessors with
 * sparse storage, meshes and primitives with morph targets and Draco
 * streams, nodes, scenes, cameras, KHR_lights_punctual lights, skins,
 * animations); cross references stay indices for gltf_check.c. Every
 * field is read through the typed readers of gltf_doc.c, whose messages
 * name the JSON path and the byte. Materials are gltf_material.c's.
 * Source: Khronos glTF 2.0 specification, the sections of each object.
 */
#include "gltf_doc.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/log.h"
#include "rt/io/gltf_animation.h"
#include "rt/io/meshopt.h"

static const struct { const char *name; bool supported; } known_extensions[] = {
    {"KHR_materials_emissive_strength", true}, {"KHR_texture_transform", true},
    {"KHR_materials_transmission", true},      {"KHR_materials_ior", true},
    {"KHR_materials_volume", true},            {"KHR_materials_unlit", true},
    {"KHR_lights_punctual", true},             {"KHR_mesh_quantization", true},
    {"KHR_xmp", true},                         {"KHR_xmp_json_ld", true}, /* metadata only */
    {"KHR_materials_clearcoat", true},         {"KHR_materials_specular", true},
    {"KHR_materials_sheen", true},             {"KHR_materials_anisotropy", true},
    {"KHR_materials_iridescence", true},       {"KHR_materials_dispersion", true},
    {"KHR_materials_diffuse_transmission", true}, {"KHR_materials_variants", true},
    {"EXT_meshopt_compression", true},         {"KHR_draco_mesh_compression", true},
    {"EXT_texture_webp", true},                {"EXT_mesh_gpu_instancing", true},
    {"KHR_materials_volume_scatter", true},
};

static bool extension_supported(const gl_doc *d, int t)
{
    for (size_t i = 0; i < sizeof known_extensions / sizeof known_extensions[0]; i++)
        if (rt_json_key_is(&d->j, t, known_extensions[i].name))
            return known_extensions[i].supported;
    return false;
}

static rt_result check_extensions(gl_doc *d)
{
    rt_result r;
    char name[128];
    int req = rt_json_get(&d->j, 0, "extensionsRequired");
    if (req >= 0) {
        if ((r = gl_expect_array(d, req, "glTF", "extensionsRequired")) != RT_OK)
            return r;
        for (int i = 0, e = req + 1; i < d->j.tok[req].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
            if ((r = gl_get_string(d, "glTF", "extensionsRequired", e, name, sizeof name)) != RT_OK)
                return r;
            if (!extension_supported(d, e))
                return gl_fail_at(d, e, RT_ERR_UNSUPPORTED, "required extension %s is not supported", name);
        }
    }
    int used = rt_json_get(&d->j, 0, "extensionsUsed");
    if (used >= 0) {
        if ((r = gl_expect_array(d, used, "glTF", "extensionsUsed")) != RT_OK)
            return r;
        for (int i = 0, e = used + 1; i < d->j.tok[used].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
            if ((r = gl_get_string(d, "glTF", "extensionsUsed", e, name, sizeof name)) != RT_OK)
                return r;
            if (!extension_supported(d, e))
                rt_warn("%s: extension %s is not supported; ignored", d->path, name);
        }
    }
    return RT_OK;
}

static rt_result parse_asset(gl_doc *d, int t)
{
    rt_result r;
    if ((r = gl_expect_object(d, t, "asset")) != RT_OK)
        return r;
    int v = rt_json_get(&d->j, t, "version");
    char buf[32];
    if (v < 0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "asset.version is missing");
    if ((r = gl_get_string(d, "asset", "version", v, buf, sizeof buf)) != RT_OK)
        return r;
    int minv = rt_json_get(&d->j, t, "minVersion");
    char mbuf[32];
    if (minv >= 0) {
        if ((r = gl_get_string(d, "asset", "minVersion", minv, mbuf, sizeof mbuf)) != RT_OK)
            return r;
        if (strcmp(mbuf, "2.0") != 0)
            return gl_fail_at(d, minv, RT_ERR_UNSUPPORTED, "asset.minVersion %s is not supported (only 2.0)", mbuf);
    } else if (buf[0] != '2' || buf[1] != '.') {
        return gl_fail_at(d, v, RT_ERR_UNSUPPORTED, "glTF version %s is not supported (only 2.x)", buf);
    }
    return RT_OK;
}

static rt_result parse_buffers(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "buffers", sizeof(gl_buffer), (void **)&d->buffers, &d->buffer_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "buffers[%d]", i);
        gl_buffer *b = &d->buffers[i];
        b->uri = -1;
        b->tok = e;
        b->byte_length = SIZE_MAX;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "uri")) {
                if (jtype(d, v) != RT_JSON_STRING)
                    return gl_fail_at(d, v, RT_ERR_INVALID, "%s.uri: expected a string", where);
                b->uri = v;
            } else if (KEY(k, "byteLength")) {
                if ((r = gl_get_size(d, where, "byteLength", v, &b->byte_length)) != RT_OK)
                    return r;
            } else if (KEY(k, "extensions")) {
                int mo = rt_json_get(&d->j, v, "EXT_meshopt_compression");
                int fb = mo >= 0 ? rt_json_get(&d->j, mo, "fallback") : -1;
                if (fb >= 0)
                    r = gl_get_bool(d, where, "extensions.EXT_meshopt_compression.fallback", fb, &b->fallback);
                if (r != RT_OK)
                    return r;
            }
        }
        if (b->byte_length == SIZE_MAX || b->byte_length == 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: byteLength is missing or 0", where);
    }
    return RT_OK;
}

/* A view's EXT_meshopt_compression object: where its compressed bytes are
 * and how they decode (rt/io/meshopt.h). */
static rt_result parse_meshopt_view(gl_doc *d, const char *view, int t, gl_view *bv)
{
    rt_result r = RT_OK;
    char where[96];
    snprintf(where, sizeof where, "%s.extensions.EXT_meshopt_compression", view);
    if ((r = gl_expect_object(d, t, where)) != RT_OK)
        return r;
    bv->meshopt = true;
    bv->mo_tok = t;
    bv->mo_buffer = RT_NONE;
    bv->mo_length = bv->mo_stride = bv->mo_count = SIZE_MAX;
    bv->mo_mode = -1;
    bv->mo_filter = RT_MESHOPT_FILTER_NONE;
    char name[32];
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "buffer")) r = gl_get_index(d, where, "buffer", v, &bv->mo_buffer);
        else if (KEY(k, "byteOffset")) r = gl_get_size(d, where, "byteOffset", v, &bv->mo_offset);
        else if (KEY(k, "byteLength")) r = gl_get_size(d, where, "byteLength", v, &bv->mo_length);
        else if (KEY(k, "byteStride")) r = gl_get_size(d, where, "byteStride", v, &bv->mo_stride);
        else if (KEY(k, "count")) r = gl_get_size(d, where, "count", v, &bv->mo_count);
        else if (KEY(k, "mode")) {
            if ((r = gl_get_string(d, where, "mode", v, name, sizeof name)) != RT_OK)
                return r;
            if ((bv->mo_mode = rt_meshopt_mode_from_name(name)) < 0)
                return gl_fail_at(d, v, RT_ERR_INVALID, "%s.mode \"%s\" is not ATTRIBUTES, TRIANGLES or INDICES", where,
                                  name);
        } else if (KEY(k, "filter")) {
            if ((r = gl_get_string(d, where, "filter", v, name, sizeof name)) != RT_OK)
                return r;
            if ((bv->mo_filter = rt_meshopt_filter_from_name(name)) < 0)
                return gl_fail_at(d, v, RT_ERR_INVALID,
                                  "%s.filter \"%s\" is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL", where, name);
        }
        if (r != RT_OK)
            return r;
    }
    if (bv->mo_buffer == RT_NONE || bv->mo_length == SIZE_MAX || bv->mo_stride == SIZE_MAX ||
        bv->mo_count == SIZE_MAX || bv->mo_mode < 0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: needs buffer, byteLength, byteStride, count and mode", where);
    const char *why = rt_meshopt_check((rt_meshopt_mode)bv->mo_mode, (rt_meshopt_filter)bv->mo_filter,
                                       bv->mo_count, bv->mo_stride);
    if (why)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: %s", where, why);
    return RT_OK;
}

static rt_result parse_views(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "bufferViews", sizeof(gl_view), (void **)&d->views, &d->view_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "bufferViews[%d]", i);
        gl_view *bv = &d->views[i];
        bv->buffer = RT_NONE;
        bv->length = SIZE_MAX;
        bv->tok = e;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "buffer")) r = gl_get_index(d, where, "buffer", v, &bv->buffer);
            else if (KEY(k, "byteOffset")) r = gl_get_size(d, where, "byteOffset", v, &bv->offset);
            else if (KEY(k, "byteLength")) r = gl_get_size(d, where, "byteLength", v, &bv->length);
            else if (KEY(k, "byteStride")) {
                if ((r = gl_get_size(d, where, "byteStride", v, &bv->stride)) != RT_OK)
                    return r;
                if (bv->stride < 4 || bv->stride > 252 || bv->stride % 4)
                    return gl_fail_at(d, v, RT_ERR_INVALID, "%s.byteStride %zu must be a multiple of 4 in [4, 252]",
                                      where, bv->stride);
            } else if (KEY(k, "extensions")) {
                int mo = rt_json_get(&d->j, v, "EXT_meshopt_compression");
                if (mo >= 0)
                    r = parse_meshopt_view(d, where, mo, bv);
                if (r != RT_OK)
                    return r;
            }
            if (r != RT_OK)
                return r;
        }
        if (bv->buffer == RT_NONE)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: buffer is missing", where);
        if (bv->length == SIZE_MAX || bv->length == 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: byteLength is missing or 0", where);
    }
    return RT_OK;
}

static rt_result parse_sparse(gl_doc *d, const char *where, int t, gl_accessor *a)
{
    rt_result r = RT_OK;
    char w[80];
    snprintf(w, sizeof w, "%s.sparse", where);
    if ((r = gl_expect_object(d, t, w)) != RT_OK)
        return r;
    bool have_count = false, have_idx = false, have_val = false;
    a->sp_idx_view = a->sp_val_view = RT_NONE;
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "count")) {
            if ((r = gl_get_size(d, w, "count", v, &a->sparse_count)) != RT_OK)
                return r;
            have_count = true;
        } else if (KEY(k, "indices")) {
            char wi[96];
            snprintf(wi, sizeof wi, "%s.indices", w);
            if ((r = gl_expect_object(d, v, wi)) != RT_OK)
                return r;
            have_idx = true;
            a->sp_idx_ctype = 0;
            for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                 k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                if (KEY(k2, "bufferView")) r = gl_get_index(d, wi, "bufferView", v2, &a->sp_idx_view);
                else if (KEY(k2, "byteOffset")) r = gl_get_size(d, wi, "byteOffset", v2, &a->sp_idx_offset);
                else if (KEY(k2, "componentType")) r = gl_get_int(d, wi, "componentType", v2, &a->sp_idx_ctype);
                if (r != RT_OK)
                    return r;
            }
            if (a->sp_idx_ctype != GL_UNSIGNED_BYTE && a->sp_idx_ctype != GL_UNSIGNED_SHORT &&
                a->sp_idx_ctype != GL_UNSIGNED_INT)
                return gl_fail_at(d, v, RT_ERR_INVALID, "%s: componentType must be 5121, 5123 or 5125", wi);
        } else if (KEY(k, "values")) {
            char wv[96];
            snprintf(wv, sizeof wv, "%s.values", w);
            if ((r = gl_expect_object(d, v, wv)) != RT_OK)
                return r;
            have_val = true;
            for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                 k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                if (KEY(k2, "bufferView")) r = gl_get_index(d, wv, "bufferView", v2, &a->sp_val_view);
                else if (KEY(k2, "byteOffset")) r = gl_get_size(d, wv, "byteOffset", v2, &a->sp_val_offset);
                if (r != RT_OK)
                    return r;
            }
        }
    }
    if (!have_count || !have_idx || !have_val || a->sp_idx_view == RT_NONE || a->sp_val_view == RT_NONE)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: needs count, indices.bufferView and values.bufferView", w);
    if (a->sparse_count == 0 || a->sparse_count > a->count)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s.count %zu must be in [1, accessor count %zu]", w, a->sparse_count,
                          a->count);
    return RT_OK;
}

static rt_result parse_accessors(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "accessors", sizeof(gl_accessor), (void **)&d->accessors,
                            &d->accessor_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "accessors[%d]", i);
        gl_accessor *a = &d->accessors[i];
        a->view = RT_NONE;
        a->count = SIZE_MAX;
        a->tok = e;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        int sparse = -1;
        char type[16] = "";
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "bufferView")) r = gl_get_index(d, where, "bufferView", v, &a->view);
            else if (KEY(k, "byteOffset")) r = gl_get_size(d, where, "byteOffset", v, &a->offset);
            else if (KEY(k, "componentType")) r = gl_get_int(d, where, "componentType", v, &a->ctype);
            else if (KEY(k, "normalized")) r = gl_get_bool(d, where, "normalized", v, &a->normalized);
            else if (KEY(k, "count")) r = gl_get_size(d, where, "count", v, &a->count);
            else if (KEY(k, "type")) r = gl_get_string(d, where, "type", v, type, sizeof type);
            else if (KEY(k, "sparse")) sparse = v;
            if (r != RT_OK)
                return r;
        }
        if (gl_comp_size(a->ctype) == 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: componentType %d is not one of 5120 5121 5122 5123 5125 5126",
                              where, a->ctype);
        static const struct { const char *n; int comp, rows, cols; } types[] = {
            {"SCALAR", 1, 1, 1}, {"VEC2", 2, 2, 1}, {"VEC3", 3, 3, 1}, {"VEC4", 4, 4, 1},
            {"MAT2", 4, 2, 2},   {"MAT3", 9, 3, 3}, {"MAT4", 16, 4, 4}};
        for (size_t k = 0; k < sizeof types / sizeof types[0]; k++)
            if (strcmp(type, types[k].n) == 0) {
                a->ncomp = types[k].comp;
                a->rows = types[k].rows;
                a->cols = types[k].cols;
            }
        if (a->ncomp == 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: type \"%s\" is not SCALAR, VECn or MATn", where, type);
        if (a->count == SIZE_MAX || a->count == 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: count is missing or 0", where);
        if (a->normalized && (a->ctype == GL_FLOAT || a->ctype == GL_UNSIGNED_INT))
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: normalized is not allowed for componentType %d", where,
                              a->ctype);
        if (sparse >= 0)
            r = parse_sparse(d, where, sparse, a);
        if (r != RT_OK)
            return r;
    }
    return RT_OK;
}

/* A primitive's KHR_draco_mesh_compression object: the view holding the
 * compressed mesh and the unique ids of the attributes rt reads. */
static rt_result parse_draco_prim(gl_doc *d, const char *prim, int t, gl_prim *pr)
{
    rt_result r = RT_OK;
    char where[128];
    snprintf(where, sizeof where, "%s.extensions.KHR_draco_mesh_compression", prim);
    if ((r = gl_expect_object(d, t, where)) != RT_OK)
        return r;
    pr->draco_tok = t;
    int attrs = -1;
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "bufferView")) r = gl_get_index(d, where, "bufferView", v, &pr->draco_view);
        else if (KEY(k, "attributes")) attrs = v;
        if (r != RT_OK)
            return r;
    }
    if (pr->draco_view == RT_NONE || attrs < 0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: needs bufferView and attributes", where);
    char wa[160];
    snprintf(wa, sizeof wa, "%s.attributes", where);
    if ((r = gl_expect_object(d, attrs, wa)) != RT_OK)
        return r;
    for (int k2_n = 0, k2 = attrs + 1, v2 = attrs + 2; k2_n < d->j.tok[attrs].size && v2 < d->j.count;
         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
        for (int a = 0; a < ATTR_COUNT; a++)
            if (KEY(k2, gl_attr_names[a]))
                r = gl_get_index(d, wa, gl_attr_names[a], v2, &pr->draco_id[a]);
        if (r != RT_OK)
            return r;
    }
    if (pr->draco_id[ATTR_POSITION] == RT_NONE)
        return gl_fail_at(d, attrs, RT_ERR_INVALID, "%s: POSITION is missing", wa);
    return RT_OK;
}

/* A primitive's morph targets: POSITION, NORMAL, TANGENT displacements. */
static rt_result parse_targets(gl_doc *d, const char *prim, int t, gl_prim *pr)
{
    rt_result r = RT_OK;
    if ((r = gl_expect_array(d, t, prim, "targets")) != RT_OK)
        return r;
    pr->first_target = (uint32_t)d->target_count;
    pr->target_count = (uint32_t)jsize(d, t);
    pr->targets = pr->target_count > 0;
    static const char *const names[3] = {"POSITION", "NORMAL", "TANGENT"};
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[96];
        snprintf(where, sizeof where, "%s.targets[%d]", prim, i);
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        if (!rt_grow((void **)&d->targets, &d->target_cap, d->target_count + 1, sizeof(gl_target)))
            return gl_fail_at(d, e, RT_ERR_NOMEM, "out of memory for morph targets");
        gl_target *g = &d->targets[d->target_count++];
        g->attr[0] = g->attr[1] = g->attr[2] = RT_NONE;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            for (int a = 0; a < 3; a++)
                if (KEY(k, names[a]))
                    r = gl_get_index(d, where, names[a], v, &g->attr[a]);
            if (r != RT_OK)
                return r;
        }
    }
    return RT_OK;
}

static rt_result parse_meshes(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "meshes", sizeof(gl_mesh), (void **)&d->meshes, &d->mesh_count)) != RT_OK)
        return r;
    /* count primitives first so they live in one table */
    size_t total = 0;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "meshes[%d]", i);
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        int p = rt_json_get(&d->j, e, "primitives");
        if (p < 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: primitives is missing", where);
        if ((r = gl_expect_array(d, p, where, "primitives")) != RT_OK)
            return r;
        if (jsize(d, p) == 0)
            return gl_fail_at(d, p, RT_ERR_INVALID, "%s.primitives is empty", where);
        total += (size_t)jsize(d, p);
    }
    d->prims = rt_alloc(total, sizeof(gl_prim));
    if (!d->prims)
        return gl_fail_at(d, t, RT_ERR_NOMEM, "out of memory for %zu primitives", total);
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        gl_mesh *m = &d->meshes[i];
        m->tok = e;
        m->weights = rt_json_get(&d->j, e, "weights");
        int p = rt_json_get(&d->j, e, "primitives");
        m->first = (uint32_t)d->prim_count;
        m->count = (uint32_t)jsize(d, p);
        for (int pi = 0, pe = p + 1; pi < d->j.tok[p].size && pe < d->j.count; pi++, pe = rt_json_skip(&d->j, pe)) {
            char where[64];
            snprintf(where, sizeof where, "meshes[%d].primitives[%d]", i, pi);
            gl_prim *pr = &d->prims[d->prim_count++];
            pr->tok = pe;
            pr->mode = 4;
            pr->indices = pr->material = pr->draco_view = RT_NONE;
            pr->variants_tok = -1;
            for (int a = 0; a < ATTR_COUNT; a++)
                pr->attr[a] = pr->draco_id[a] = RT_NONE;
            pr->joints[0] = pr->joints[1] = pr->weights[0] = pr->weights[1] = RT_NONE;
            if ((r = gl_expect_object(d, pe, where)) != RT_OK)
                return r;
            bool have_attrs = false;
            for (int k_n = 0, k = pe + 1, v = pe + 2; k_n < d->j.tok[pe].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "indices")) r = gl_get_index(d, where, "indices", v, &pr->indices);
                else if (KEY(k, "material")) r = gl_get_index(d, where, "material", v, &pr->material);
                else if (KEY(k, "mode")) {
                    if ((r = gl_get_int(d, where, "mode", v, &pr->mode)) != RT_OK)
                        return r;
                    if (pr->mode < 0 || pr->mode > 6)
                        return gl_fail_at(d, v, RT_ERR_INVALID, "%s.mode %d is not in [0, 6]", where, pr->mode);
                } else if (KEY(k, "targets")) {
                    if ((r = parse_targets(d, where, v, pr)) != RT_OK)
                        return r;
                } else if (KEY(k, "extensions")) {
                    int dr = rt_json_get(&d->j, v, "KHR_draco_mesh_compression");
                    if (dr >= 0)
                        r = parse_draco_prim(d, where, dr, pr);
                    if (r != RT_OK)
                        return r;
                    /* KHR_materials_variants: the mappings are checked in apply_variant */
                    int x = rt_json_get(&d->j, v, "KHR_materials_variants");
                    if (jtype(d, v) == RT_JSON_OBJECT && x >= 0) {
                        char wx[128];
                        snprintf(wx, sizeof wx, "%s.extensions.KHR_materials_variants", where);
                        if ((r = gl_expect_object(d, x, wx)) != RT_OK)
                            return r;
                        int mp = rt_json_get(&d->j, x, "mappings");
                        if (mp < 0)
                            return gl_fail_at(d, x, RT_ERR_INVALID, "%s: mappings is missing", wx);
                        if ((r = gl_expect_array(d, mp, wx, "mappings")) != RT_OK)
                            return r;
                        pr->variants_tok = mp;
                    }
                } else if (KEY(k, "attributes")) {
                    char wa[96];
                    snprintf(wa, sizeof wa, "%s.attributes", where);
                    if ((r = gl_expect_object(d, v, wa)) != RT_OK)
                        return r;
                    have_attrs = true;
                    for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                        for (int a = 0; a < ATTR_COUNT; a++)
                            if (KEY(k2, gl_attr_names[a]))
                                r = gl_get_index(d, wa, gl_attr_names[a], v2, &pr->attr[a]);
                        if (r != RT_OK)
                            return r;
                        static const char *const skin_attrs[4] = {"JOINTS_0", "JOINTS_1", "WEIGHTS_0", "WEIGHTS_1"};
                        for (int a = 0; a < 4; a++)
                            if (KEY(k2, skin_attrs[a]))
                                r = gl_get_index(d, wa, skin_attrs[a], v2,
                                                 a < 2 ? &pr->joints[a] : &pr->weights[a - 2]);
                        if (r != RT_OK)
                            return r;
                    }
                }
                if (r != RT_OK)
                    return r;
            }
            if (!have_attrs)
                return gl_fail_at(d, pe, RT_ERR_INVALID, "%s: attributes is missing", where);
        }
    }
    return RT_OK;
}

/* Items of a table that each hold an optional array of indices under
 * `member` ("children" of nodes, "nodes" of scenes) share one flat array.
 * The first pass checks the items and arrays and allocates room for all
 * their indices; read_index_list then fills it item by item. */
static rt_result alloc_index_lists(gl_doc *d, int t, const char *table, const char *member, uint32_t **out)
{
    rt_result r;
    size_t total = 0;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "%s[%d]", table, i);
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        int a = rt_json_get(&d->j, e, member);
        if (a >= 0) {
            if ((r = gl_expect_array(d, a, where, member)) != RT_OK)
                return r;
            total += (size_t)jsize(d, a);
        }
    }
    *out = rt_alloc(total, sizeof(uint32_t));
    if (!*out)
        return gl_fail_at(d, t, RT_ERR_NOMEM, "out of memory for %zu %s of %s", total, member, table);
    return RT_OK;
}

/* Appends item e's indices to list (*used so far) and counts them in *n. */
static rt_result read_index_list(gl_doc *d, int e, const char *where, const char *member, uint32_t *list, size_t *used,
                                 uint32_t *n)
{
    rt_result r;
    int a = rt_json_get(&d->j, e, member); /* the token the counting pass saw, even if the key is repeated */
    if (a < 0)
        return RT_OK;
    for (int i = 0, x = a + 1; i < d->j.tok[a].size && x < d->j.count; i++, x = rt_json_skip(&d->j, x)) {
        uint32_t index;
        if ((r = gl_get_index(d, where, member, x, &index)) != RT_OK)
            return r;
        list[(*used)++] = index;
        (*n)++;
    }
    return RT_OK;
}

/* A node's EXT_mesh_gpu_instancing (its `extensions` object at ext): the
 * accessors of its TRANSLATION, ROTATION and SCALE attributes (others,
 * such as _ID, are ignored); gltf_instances.c checks and reads them. */
static rt_result parse_gpu_instancing(gl_doc *d, gl_node *n, const char *where, int ext)
{
    static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
    int g = rt_json_get(&d->j, ext, "EXT_mesh_gpu_instancing");
    if (g < 0)
        return RT_OK;
    rt_result r;
    if ((r = gl_expect_object(d, g, where)) != RT_OK)
        return r;
    n->gpu_tok = g;
    int at = rt_json_get(&d->j, g, "attributes");
    if (at < 0)
        return RT_OK;
    if ((r = gl_expect_object(d, at, where)) != RT_OK)
        return r;
    for (int a = 0; a < 3; a++) {
        char field[96];
        snprintf(field, sizeof field, "extensions.EXT_mesh_gpu_instancing.attributes.%s", names[a]);
        int x = rt_json_get(&d->j, at, names[a]);
        if (x >= 0 && (r = gl_get_index(d, where, field, x, &n->gpu_attr[a])) != RT_OK)
            return r;
    }
    return RT_OK;
}

static rt_result parse_nodes(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "nodes", sizeof(gl_node), (void **)&d->nodes, &d->node_count)) != RT_OK)
        return r;
    if ((r = alloc_index_lists(d, t, "nodes", "children", &d->children)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "nodes[%d]", i);
        gl_node *n = &d->nodes[i];
        n->tok = e;
        n->mesh = n->camera = n->light = n->skin = n->parent = RT_NONE;
        n->first_child = (uint32_t)d->children_count;
        n->weights = -1;
        n->gpu_attr[0] = n->gpu_attr[1] = n->gpu_attr[2] = RT_NONE;
        n->gpu_tok = -1;
        bool have_matrix = false, have_trs = false;
        float matrix[16], tr[3] = {0, 0, 0}, rot[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1};
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "mesh")) r = gl_get_index(d, where, "mesh", v, &n->mesh);
            else if (KEY(k, "camera")) r = gl_get_index(d, where, "camera", v, &n->camera);
            else if (KEY(k, "skin")) r = gl_get_index(d, where, "skin", v, &n->skin);
            else if (KEY(k, "matrix")) {
                if ((r = gl_get_floats(d, where, "matrix", v, matrix, 16)) != RT_OK)
                    return r;
                have_matrix = true;
            } else if (KEY(k, "translation")) {
                if ((r = gl_get_floats(d, where, "translation", v, tr, 3)) != RT_OK)
                    return r;
                have_trs = true;
            } else if (KEY(k, "rotation")) {
                if ((r = gl_get_floats(d, where, "rotation", v, rot, 4)) != RT_OK)
                    return r;
                have_trs = true;
            } else if (KEY(k, "scale")) {
                if ((r = gl_get_floats(d, where, "scale", v, sc, 3)) != RT_OK)
                    return r;
                have_trs = true;
            } else if (KEY(k, "weights")) {
                n->weights = v;
            } else if (KEY(k, "extensions")) {
                int l = rt_json_get(&d->j, v, "KHR_lights_punctual");
                if (l >= 0) {
                    if ((r = gl_expect_object(d, l, where)) != RT_OK)
                        return r;
                    int li = rt_json_get(&d->j, l, "light");
                    if (li >= 0)
                        r = gl_get_index(d, where, "extensions.KHR_lights_punctual.light", li, &n->light);
                    if (r != RT_OK)
                        return r;
                }
                if ((r = parse_gpu_instancing(d, n, where, v)) != RT_OK)
                    return r;
            }
            if (r != RT_OK)
                return r;
        }
        if ((r = read_index_list(d, e, where, "children", d->children, &d->children_count, &n->child_count)) != RT_OK)
            return r;
        memcpy(n->tr, tr, sizeof tr);
        memcpy(n->sc, sc, sizeof sc);
        n->has_matrix = have_matrix;
        if (have_matrix) {
            if (have_trs)
                rt_warn("%s: %s has both matrix and TRS; using the matrix", d->path, where);
            n->local = gl_mat_from_gltf(matrix);
        } else {
            double q2 = (double)rot[0] * rot[0] + (double)rot[1] * rot[1] + (double)rot[2] * rot[2] +
                        (double)rot[3] * rot[3];
            rt_vec4 q = rt_v4(0, 0, 0, 1);
            if (q2 > 1e-12) {
                float s = (float)(1.0 / sqrt(q2)); /* exporters round; renormalise */
                q = rt_v4(rot[0] * s, rot[1] * s, rot[2] * s, rot[3] * s);
            } else {
                rt_warn("%s: %s.rotation is a zero quaternion; using identity", d->path, where);
            }
            n->rot[0] = q.x; n->rot[1] = q.y; n->rot[2] = q.z; n->rot[3] = q.w;
            n->local = rt_mat4_mul(rt_mat4_translate(rt_v3(tr[0], tr[1], tr[2])),
                                   rt_mat4_mul(rt_mat4_quat(q), rt_mat4_scale(rt_v3(sc[0], sc[1], sc[2]))));
        }
    }
    return RT_OK;
}

static rt_result parse_scenes(gl_doc *d, int t)
{
    rt_result r;
    if ((r = gl_alloc_table(d, t, "scenes", sizeof(gl_scene), (void **)&d->scenes, &d->scene_count)) != RT_OK)
        return r;
    if ((r = alloc_index_lists(d, t, "scenes", "nodes", &d->scene_nodes)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "scenes[%d]", i);
        gl_scene *sc = &d->scenes[i];
        sc->tok = e;
        sc->first = (uint32_t)d->scene_nodes_count;
        if ((r = read_index_list(d, e, where, "nodes", d->scene_nodes, &d->scene_nodes_count, &sc->count)) != RT_OK)
            return r;
    }
    return RT_OK;
}

static rt_result parse_cameras(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "cameras", sizeof(gl_camera), (void **)&d->cameras, &d->camera_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "cameras[%d]", i);
        gl_camera *c = &d->cameras[i];
        c->tok = e;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        char type[16] = "";
        int persp = -1;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "type")) r = gl_get_string(d, where, "type", v, type, sizeof type);
            else if (KEY(k, "perspective")) persp = v;
            if (r != RT_OK)
                return r;
        }
        if (strcmp(type, "perspective") == 0) {
            c->perspective = true;
            if (persp < 0)
                return gl_fail_at(d, e, RT_ERR_INVALID, "%s: perspective is missing", where);
            char wp[64];
            snprintf(wp, sizeof wp, "%s.perspective", where);
            if ((r = gl_expect_object(d, persp, wp)) != RT_OK)
                return r;
            c->yfov = -1;
            /* the schema: aspectRatio, znear and zfar each > 0 when given, and zfar > znear */
            int at[3] = {-1, -1, -1};
            for (int k_n = 0, k = persp + 1, v = persp + 2; k_n < d->j.tok[persp].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "yfov")) r = gl_get_float(d, wp, "yfov", v, &c->yfov);
                else if (KEY(k, "aspectRatio")) r = gl_get_float(d, wp, "aspectRatio", at[0] = v, &c->aspect);
                else if (KEY(k, "znear")) r = gl_get_float(d, wp, "znear", at[1] = v, &c->znear);
                else if (KEY(k, "zfar")) r = gl_get_float(d, wp, "zfar", at[2] = v, &c->zfar);
                if (r != RT_OK)
                    return r;
            }
            if (!(c->yfov > 0 && c->yfov < RT_PI))
                return gl_fail_at(d, persp, RT_ERR_INVALID, "%s.yfov must be in (0, pi)", wp);
            static const char *const names[3] = {"aspectRatio", "znear", "zfar"};
            const float got[3] = {c->aspect, c->znear, c->zfar};
            for (int q = 0; q < 3; q++)
                if (at[q] >= 0 && !(got[q] > 0))
                    return gl_fail_at(d, at[q], RT_ERR_INVALID, "%s.%s %g must be greater than 0", wp, names[q],
                                      (double)got[q]);
            if (at[1] >= 0 && at[2] >= 0 && !(c->zfar > c->znear))
                return gl_fail_at(d, at[2], RT_ERR_INVALID, "%s.zfar %g must be greater than znear %g", wp,
                                  (double)c->zfar, (double)c->znear);
        } else if (strcmp(type, "orthographic") != 0) {
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: type \"%s\" is not perspective or orthographic", where, type);
        }
    }
    return RT_OK;
}

static rt_result parse_lights(gl_doc *d, int ext)
{
    rt_result r = RT_OK;
    if ((r = gl_expect_object(d, ext, "extensions")) != RT_OK)
        return r;
    int l = rt_json_get(&d->j, ext, "KHR_lights_punctual");
    if (l < 0)
        return RT_OK;
    if ((r = gl_expect_object(d, l, "extensions.KHR_lights_punctual")) != RT_OK)
        return r;
    int t = rt_json_get(&d->j, l, "lights");
    if (t < 0)
        return RT_OK;
    if ((r = gl_alloc_table(d, t, "lights", sizeof(gl_light), (void **)&d->lights, &d->light_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[64];
        snprintf(where, sizeof where, "KHR_lights_punctual.lights[%d]", i);
        gl_light *g = &d->lights[i];
        g->tok = e;
        g->color = rt_v3s(1);
        g->intensity = 1;
        g->inner = 0;
        g->outer = RT_PI / 4;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        char type[16] = "";
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "type")) r = gl_get_string(d, where, "type", v, type, sizeof type);
            else if (KEY(k, "color")) {
                float c[3] = {1, 1, 1};
                if ((r = gl_get_floats_ranged(d, where, "color", v, 3, 0, 1, c)) != RT_OK)
                    return r;
                g->color = rt_v3(c[0], c[1], c[2]);
            } else if (KEY(k, "intensity")) r = gl_get_ranged(d, where, "intensity", v, 0, GL_BIG, &g->intensity);
            else if (KEY(k, "range")) {
                /* exclusiveMinimum 0 (no range at all is said by leaving it out) */
                if ((r = gl_get_ranged(d, where, "range", v, 0, GL_BIG, &g->range)) == RT_OK && !(g->range > 0))
                    return gl_fail_at(d, v, RT_ERR_INVALID, "%s.range must be greater than 0", where);
            }
            else if (KEY(k, "spot")) {
                if ((r = gl_expect_object(d, v, where)) != RT_OK)
                    return r;
                for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                     k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                    if (KEY(k2, "innerConeAngle"))
                        r = gl_get_ranged(d, where, "spot.innerConeAngle", v2, 0, RT_PI / 2, &g->inner);
                    else if (KEY(k2, "outerConeAngle"))
                        r = gl_get_ranged(d, where, "spot.outerConeAngle", v2, 0, RT_PI / 2 + 1e-6f, &g->outer);
                    if (r != RT_OK)
                        return r;
                }
            }
            if (r != RT_OK)
                return r;
        }
        if (strcmp(type, "point") == 0) g->kind = RT_LIGHT_POINT;
        else if (strcmp(type, "spot") == 0) g->kind = RT_LIGHT_SPOT;
        else if (strcmp(type, "directional") == 0) g->kind = RT_LIGHT_DIRECTIONAL;
        else return gl_fail_at(d, e, RT_ERR_INVALID, "%s: type \"%s\" is not point, spot or directional", where, type);
        if (g->range < 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: range must be positive", where);
        if (!(g->inner >= 0 && g->inner < g->outer && g->outer <= RT_PI / 2 + 1e-6f))
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: spot cones need 0 <= inner < outer <= pi/2", where);
    }
    return RT_OK;
}

static rt_result parse_skins(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "skins", sizeof(gl_skin), (void **)&d->skins, &d->skin_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "skins[%d]", i);
        gl_skin *sk = &d->skins[i];
        sk->tok = e;
        sk->ibm = RT_NONE;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        int joints = -1;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "inverseBindMatrices")) r = gl_get_index(d, where, "inverseBindMatrices", v, &sk->ibm);
            else if (KEY(k, "joints")) joints = v;
            if (r != RT_OK)
                return r;
        }
        if (joints < 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: joints is missing", where);
        if ((r = gl_expect_array(d, joints, where, "joints")) != RT_OK)
            return r;
        if (jsize(d, joints) == 0)
            return gl_fail_at(d, joints, RT_ERR_INVALID, "%s.joints is empty", where);
        sk->first_joint = (uint32_t)d->skin_joints_count;
        for (int j = 0, je = joints + 1; j < d->j.tok[joints].size && je < d->j.count;
             j++, je = rt_json_skip(&d->j, je)) {
            if (!rt_grow((void **)&d->skin_joints, &d->skin_joints_cap, d->skin_joints_count + 1, sizeof(uint32_t)))
                return gl_fail_at(d, je, RT_ERR_NOMEM, "out of memory for joints");
            if ((r = gl_get_index(d, where, "joints", je, &d->skin_joints[d->skin_joints_count++])) != RT_OK)
                return r;
        }
        sk->joint_count = (uint32_t)(d->skin_joints_count - sk->first_joint);
    }
    return RT_OK;
}

static rt_result parse_animations(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "animations", sizeof(gl_anim), (void **)&d->anims, &d->anim_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "animations[%d]", i);
        gl_anim *an = &d->anims[i];
        an->tok = e;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        int chans = rt_json_get(&d->j, e, "channels"), samps = rt_json_get(&d->j, e, "samplers");
        if (chans < 0 || samps < 0)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: needs channels and samplers", where);
        if ((r = gl_expect_array(d, samps, where, "samplers")) != RT_OK)
            return r;
        if ((r = gl_expect_array(d, chans, where, "channels")) != RT_OK)
            return r;
        an->first_sampler = (uint32_t)d->asampler_count;
        for (int j = 0, se = samps + 1; j < d->j.tok[samps].size && se < d->j.count;
             j++, se = rt_json_skip(&d->j, se)) {
            char w[80];
            snprintf(w, sizeof w, "%s.samplers[%d]", where, j);
            if ((r = gl_expect_object(d, se, w)) != RT_OK)
                return r;
            if (!rt_grow((void **)&d->asamplers, &d->asampler_cap, d->asampler_count + 1, sizeof(gl_asampler)))
                return gl_fail_at(d, se, RT_ERR_NOMEM, "out of memory for animation samplers");
            gl_asampler *sa = &d->asamplers[d->asampler_count++];
            sa->input = sa->output = RT_NONE;
            sa->interp = RT_INTERP_LINEAR;
            sa->tok = se;
            for (int k_n = 0, k = se + 1, v = se + 2; k_n < d->j.tok[se].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "input")) r = gl_get_index(d, w, "input", v, &sa->input);
                else if (KEY(k, "output")) r = gl_get_index(d, w, "output", v, &sa->output);
                else if (KEY(k, "interpolation")) {
                    char name[32];
                    if ((r = gl_get_string(d, w, "interpolation", v, name, sizeof name)) != RT_OK)
                        return r;
                    if (strcmp(name, "LINEAR") == 0) sa->interp = RT_INTERP_LINEAR;
                    else if (strcmp(name, "STEP") == 0) sa->interp = RT_INTERP_STEP;
                    else if (strcmp(name, "CUBICSPLINE") == 0) sa->interp = RT_INTERP_CUBICSPLINE;
                    else
                        return gl_fail_at(d, v, RT_ERR_INVALID,
                                          "%s.interpolation \"%s\" is not LINEAR, STEP or CUBICSPLINE", w, name);
                }
                if (r != RT_OK)
                    return r;
            }
            if (sa->input == RT_NONE || sa->output == RT_NONE)
                return gl_fail_at(d, se, RT_ERR_INVALID, "%s: needs input and output", w);
        }
        an->sampler_count = (uint32_t)(d->asampler_count - an->first_sampler);
        an->first_channel = (uint32_t)d->channel_count;
        for (int j = 0, ce = chans + 1; j < d->j.tok[chans].size && ce < d->j.count;
             j++, ce = rt_json_skip(&d->j, ce)) {
            char w[80];
            snprintf(w, sizeof w, "%s.channels[%d]", where, j);
            if ((r = gl_expect_object(d, ce, w)) != RT_OK)
                return r;
            if (!rt_grow((void **)&d->channels, &d->channel_cap, d->channel_count + 1, sizeof(gl_channel)))
                return gl_fail_at(d, ce, RT_ERR_NOMEM, "out of memory for animation channels");
            gl_channel *ch = &d->channels[d->channel_count++];
            ch->sampler = ch->node = RT_NONE;
            ch->path = -1;
            ch->tok = ce;
            for (int k_n = 0, k = ce + 1, v = ce + 2; k_n < d->j.tok[ce].size && v < d->j.count;
                 k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
                if (KEY(k, "sampler")) r = gl_get_index(d, w, "sampler", v, &ch->sampler);
                else if (KEY(k, "target")) {
                    if ((r = gl_expect_object(d, v, w)) != RT_OK)
                        return r;
                    for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
                         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                        if (KEY(k2, "node")) r = gl_get_index(d, w, "target.node", v2, &ch->node);
                        else if (KEY(k2, "path")) {
                            char name[32];
                            if ((r = gl_get_string(d, w, "target.path", v2, name, sizeof name)) != RT_OK)
                                return r;
                            if (strcmp(name, "translation") == 0) ch->path = PATH_TRANSLATION;
                            else if (strcmp(name, "rotation") == 0) ch->path = PATH_ROTATION;
                            else if (strcmp(name, "scale") == 0) ch->path = PATH_SCALE;
                            else if (strcmp(name, "weights") == 0) ch->path = PATH_WEIGHTS;
                            else
                                ch->path = -2; /* "pointer" (KHR_animation_pointer) and others: not ours */
                        }
                        if (r != RT_OK)
                            return r;
                    }
                }
                if (r != RT_OK)
                    return r;
            }
            if (ch->sampler == RT_NONE || ch->path == -1)
                return gl_fail_at(d, ce, RT_ERR_INVALID, "%s: needs sampler and target.path", w);
            if (ch->sampler >= an->sampler_count)
                return gl_fail_at(d, ce, RT_ERR_INVALID,
                                  "%s.sampler %u is out of range (the animation has %u samplers)",
                                  w, ch->sampler, an->sampler_count);
        }
        an->channel_count = (uint32_t)(d->channel_count - an->first_channel);
    }
    return RT_OK;
}

rt_result gl_parse_document(gl_doc *d)
{
    rt_result r = RT_OK;
    if ((r = rt_json_parse(&d->j, d->json_text, d->json_len, d->path, d->json_base, d->err)) != RT_OK)
        return r;
    if ((r = gl_expect_object(d, 0, "glTF")) != RT_OK)
        return r;
    if ((r = check_extensions(d)) != RT_OK)
        return r;
    bool have_asset = false;
    d->default_scene = RT_NONE;
    d->variants_tok = -1;
    for (int k_n = 0, k = 1, v = 2; k_n < d->j.tok[0].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "asset")) {
            r = parse_asset(d, v);
            have_asset = true;
        }
        else if (KEY(k, "buffers")) r = parse_buffers(d, v);
        else if (KEY(k, "bufferViews")) r = parse_views(d, v);
        else if (KEY(k, "accessors")) r = parse_accessors(d, v);
        else if (KEY(k, "meshes")) r = parse_meshes(d, v);
        else if (KEY(k, "nodes")) r = parse_nodes(d, v);
        else if (KEY(k, "scenes")) r = parse_scenes(d, v);
        else if (KEY(k, "scene")) r = gl_get_index(d, "glTF", "scene", v, &d->default_scene);
        else if (KEY(k, "materials")) r = gl_parse_materials(d, v);
        else if (KEY(k, "textures")) r = gl_parse_textures(d, v);
        else if (KEY(k, "samplers")) r = gl_parse_samplers(d, v);
        else if (KEY(k, "images")) r = gl_parse_images(d, v);
        else if (KEY(k, "cameras")) r = parse_cameras(d, v);
        else if (KEY(k, "extensions")) {
            if ((r = parse_lights(d, v)) != RT_OK)
                return r;
            int x = rt_json_get(&d->j, v, "KHR_materials_variants");
            if (x >= 0) {
                if ((r = gl_expect_object(d, x, "extensions.KHR_materials_variants")) != RT_OK)
                    return r;
                d->variants_tok = rt_json_get(&d->j, x, "variants");
                if (d->variants_tok < 0)
                    return gl_fail_at(d, x, RT_ERR_INVALID, "extensions.KHR_materials_variants: variants is missing");
                if ((r = gl_expect_array(d, d->variants_tok, "extensions.KHR_materials_variants", "variants")) != RT_OK)
                    return r;
            }
        }
        else if (KEY(k, "skins")) r = parse_skins(d, v);
        else if (KEY(k, "animations")) r = parse_animations(d, v);
        if (r != RT_OK)
            return r;
    }
    if (!have_asset)
        return gl_fail_at(d, 0, RT_ERR_INVALID, "asset is missing (not a glTF file?)");
    return RT_OK;
}
