/* gltf.c - glTF 2.0 (.gltf, .glb) loader for static scenes.
 *
 * Built the way cgltf (jkuhlmann/cgltf) is built, in four passes, each in
 * files of its own (gltf_doc.h lists them); this file holds the
 * entry points, the first pass and gl_load, which runs the others:
 *   1. read   the file; a GLB is split into its JSON and BIN chunks after
 *             checking the 12-byte header and every chunk length against the
 *             file size (glTF 2.0 spec, "GLB File Format Specification").
 *   2. map    the JSON (tokenized once, see json.c) into flat tables
 *             of records with a count each: buffers, bufferViews, accessors,
 *             meshes/primitives, nodes, scenes, materials, textures,
 *             samplers, images, cameras, KHR_lights_punctual lights. Cross
 *             references stay indices.
 *   3. check  every index against its table, every accessor against its
 *             bufferView and every bufferView against its buffer (with
 *             overflow-safe arithmetic), the node graph for shared children,
 *             cycles and depth; only then are buffers read (files relative to
 *             the .gltf, base64 data: URIs, the GLB BIN chunk) and their real
 *             sizes checked against byteLength. Nothing is allocated from a
 *             count that has not been checked against the bytes behind it
 *             (or, for accessors without a bufferView, against a fixed cap).
 *   4. flatten the chosen scene: node world matrices (parent * local, TRS =
 *             T * R * S), every triangle primitive of every mesh instance
 *             into the scene's vertex and triangle tables (strips and fans
 *             converted with the spec's vertex orders), materials, textures
 *             (images decoded once through rt/io/image_load.h), cameras and lights.
 *
 * Transforms: positions by the world matrix M; normals by the inverse
 * transpose (rt_mat4_normal_matrix); tangents by M's upper 3x3, with the
 * bitangent sign w multiplied by sign(det M): with n' ~ M^-T n and
 * t' ~ M t, cross(n', t') points along sign(det M) * M cross(n, t), so a
 * mirroring transform must flip w to keep bitangent = w * cross(n, t).
 * A negative determinant also flips triangle winding (spec, "Meshes"), so
 * the geometric normal keeps agreeing with the shading normal.
 *
 * Sources: Khronos glTF 2.0 specification (sections "Accessors" with
 * sparse accessors and data alignment, "Animations" for the normalized
 * integer formulas, "Meshes" for primitive modes and winding, "Materials",
 * "Samplers", "GLB File Format Specification"); extension specs KHR_texture_transform,
 * KHR_materials_{emissive_strength,transmission,ior,volume,unlit},
 * KHR_lights_punctual, KHR_mesh_quantization. docs/gltf.md lists what is
 * supported and how glTF materials map to rt_material.
 */
#include "rt/io/gltf.h"

#include "gltf_doc.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/file.h"
#include "rt/base/log.h"

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Splits a GLB into its JSON and BIN chunks (spec: "GLB File Format Specification"). */
static rt_result split_glb(gl_doc *d)
{
    const uint8_t *f = d->bytes;
    size_t size = d->file_size;
    if (size < 12)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: byte 0: file is %zu bytes, too short for the 12-byte GLB header",
                       d->path, size);
    uint32_t version = rd32(f + 4), length = rd32(f + 8);
    if (version != 2)
        return rt_fail(d->err, RT_ERR_UNSUPPORTED, "%s: byte 4: GLB version %u (only version 2 is supported)",
                       d->path, version);
    if (length > size)
        return rt_fail(d->err, RT_ERR_INVALID,
                       "%s: byte 8: header length %u runs past the end of the file (%zu bytes): truncated?", d->path,
                       length, size);
    if (length < 20)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: byte 8: header length %u leaves no room for the JSON chunk",
                       d->path, length);
    if (length < size)
        rt_warn("%s: %zu bytes after the GLB's declared length %u are ignored", d->path, size - length, length);
    size_t off = 12;
    int chunk = 0;
    while (off < length) {
        if (length - off < 8)
            return rt_fail(d->err, RT_ERR_INVALID,
                           "%s: byte %zu: chunk header runs past the end of the file (%u bytes)", d->path, off, length);
        uint32_t clen = rd32(f + off), ctype = rd32(f + off + 4);
        if (clen > length - off - 8)
            return rt_fail(d->err, RT_ERR_INVALID,
                           "%s: byte %zu: chunk length %u runs past the end of the file (%u bytes)", d->path, off, clen,
                           length);
        const uint8_t *data = f + off + 8;
        if (chunk == 0) {
            if (ctype != 0x4E4F534Au)
                return rt_fail(d->err, RT_ERR_INVALID,
                               "%s: byte %zu: the first chunk must be JSON (type 0x4E4F534A), got 0x%08X", d->path,
                               off + 4, ctype);
            d->json_text = (const char *)data;
            d->json_len = clen;
            d->json_base = off + 8;
        } else if (ctype == 0x004E4942u) {
            if (chunk != 1)
                return rt_fail(d->err, RT_ERR_INVALID, "%s: byte %zu: the BIN chunk must be the second chunk", d->path,
                               off + 4);
            d->bin = data;
            d->bin_size = clen;
        } else if (ctype == 0x4E4F534Au) {
            return rt_fail(d->err, RT_ERR_INVALID, "%s: byte %zu: a second JSON chunk", d->path, off + 4);
        } /* unknown chunk types are skipped, as the spec says */
        off += 8 + (size_t)clen;
        off = (off + 3) & ~(size_t)3; /* chunks are 4-byte aligned */
        chunk++;
    }
    return RT_OK;
}

static void doc_free(gl_doc *d)
{
    for (size_t i = 0; i < d->buffer_count; i++)
        free(d->buffers[i].owned);
    for (size_t i = 0; i < d->view_count; i++)
        free(d->views[i].decoded);
    for (size_t i = 0; i < d->node_count; i++)
        free(d->nodes[i].pose_weights);
    free(d->skins); free(d->skin_joints); free(d->targets); free(d->anims); free(d->channels); free(d->asamplers);
    free(d->skin_scratch);
    free(d->buffers); free(d->views); free(d->accessors); free(d->meshes); free(d->prims);
    free(d->nodes); free(d->children); free(d->scenes); free(d->scene_nodes); free(d->materials);
    free(d->textures); free(d->samplers); free(d->images); free(d->cameras); free(d->lights);
    free(d->visits); free(d->visit_of); free(d->image_map); free(d->texture_map);
    free(d->texture_missing);
    for (int k = 0; k < ATTR_COUNT; k++)
        free(d->scratch[k]);
    free(d->idx_scratch);
    rt_json_free(&d->j);
    free(d->dir);
}

/* KHR_materials_variants: checks every primitive's mappings (material and
 * variant indices in range) and, when opt->variant names one of the file's
 * variants, gives each primitive the material its mapping for that variant
 * says (primitives without one keep their own). */
rt_result gl_apply_variant(gl_doc *d, const rt_gltf_options *opt)
{
    rt_result r;
    const char *want = opt ? opt->variant : NULL;
    size_t count = d->variants_tok >= 0 ? (size_t)jsize(d, d->variants_tok) : 0;
    uint32_t chosen = RT_NONE;
    char names[512] = "";
    if (d->variants_tok >= 0) {
        for (int i = 0, e = d->variants_tok + 1; i < d->j.tok[d->variants_tok].size && e < d->j.count;
             i++, e = rt_json_skip(&d->j, e)) {
            char where[64], name[128];
            snprintf(where, sizeof where, "extensions.KHR_materials_variants.variants[%d]", i);
            if ((r = gl_expect_object(d, e, where)) != RT_OK)
                return r;
            int n = rt_json_get(&d->j, e, "name");
            if (n < 0)
                return gl_fail_at(d, e, RT_ERR_INVALID, "%s: name is missing", where);
            if ((r = gl_get_string(d, where, "name", n, name, sizeof name)) != RT_OK)
                return r;
            if (want && strcmp(want, name) == 0 && chosen == RT_NONE)
                chosen = (uint32_t)i;
            size_t used = strlen(names);
            snprintf(names + used, sizeof names - used, "%s'%s'", used ? ", " : "", name);
        }
    }
    if (want && chosen == RT_NONE)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: no material variant named '%s' (%s%s)", d->path, want,
                       count ? "the file's variants: " : "the file has no KHR_materials_variants",
                       count ? names : "");
    for (size_t p = 0; p < d->prim_count; p++) {
        gl_prim *pr = &d->prims[p];
        if (pr->variants_tok < 0)
            continue;
        uint32_t material = pr->material;
        for (int i = 0, e = pr->variants_tok + 1; i < d->j.tok[pr->variants_tok].size && e < d->j.count;
             i++, e = rt_json_skip(&d->j, e)) {
            char where[96];
            snprintf(where, sizeof where, "primitive %zu: KHR_materials_variants.mappings[%d]", p, i);
            if ((r = gl_expect_object(d, e, where)) != RT_OK)
                return r;
            uint32_t m = RT_NONE;
            int mt = rt_json_get(&d->j, e, "material"), vt = rt_json_get(&d->j, e, "variants");
            if (mt < 0 || vt < 0)
                return gl_fail_at(d, e, RT_ERR_INVALID, "%s: material or variants is missing", where);
            if ((r = gl_get_index(d, where, "material", mt, &m)) != RT_OK)
                return r;
            if (m >= d->material_count)
                return gl_fail_at(d, mt, RT_ERR_INVALID, "%s: material %u is out of range (the file has %zu materials)",
                                  where, m, d->material_count);
            if ((r = gl_expect_array(d, vt, where, "variants")) != RT_OK)
                return r;
            for (int j = 0, ve = vt + 1; j < d->j.tok[vt].size && ve < d->j.count; j++, ve = rt_json_skip(&d->j, ve)) {
                uint32_t v;
                if ((r = gl_get_index(d, where, "variants", ve, &v)) != RT_OK)
                    return r;
                if (v >= count)
                    return gl_fail_at(d, ve, RT_ERR_INVALID, "%s: variant %u is out of range (the file has %zu)", where,
                                      v, count);
                if (v == chosen)
                    material = m;
            }
        }
        pr->material = material;
    }
    return RT_OK;
}

rt_result gl_load(gl_doc *d, rt_scene *s, const rt_gltf_options *opt, rt_gltf_stats *st)
{
    rt_result r;
    size_t dir_size = strlen(d->path) + 1;
    d->dir = malloc(dir_size);
    if (!d->dir)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    rt_path_dirname(d->path, d->dir, dir_size);
    if (d->file_size > GL_MAX_FILE)
        return rt_fail(d->err, RT_ERR_LIMIT, "%s: file is over the limit of %zu bytes", d->path, GL_MAX_FILE);
    if (d->file_size >= 4 && memcmp(d->bytes, "glTF", 4) == 0) {
        d->glb = true;
        if ((r = split_glb(d)) != RT_OK)
            return r;
    } else {
        if (rt_path_has_ext(d->path, ".glb"))
            return rt_fail(d->err, RT_ERR_INVALID, "%s: byte 0: bad magic (expected \"glTF\" for a .glb file)",
                           d->path);
        d->json_text = (const char *)d->bytes;
        d->json_len = d->file_size;
        if (d->json_len >= 3 && memcmp(d->json_text, "\xEF\xBB\xBF", 3) == 0) { /* UTF-8 byte order mark */
            d->json_text += 3;
            d->json_len -= 3;
            d->json_base = 3;
        }
    }
    if ((r = gl_parse_document(d)) != RT_OK)
        return r;
    if ((r = gl_apply_variant(d, opt)) != RT_OK)
        return r;
    if ((r = gl_validate(d)) != RT_OK)
        return r;
    if ((r = gl_load_buffers(d)) != RT_OK)
        return r;
    if ((r = gl_decode_meshopt_views(d)) != RT_OK)
        return r;
    if ((r = gl_decode_draco_prims(d)) != RT_OK)
        return r;
    if (opt && opt->catalog)
        gl_catalog(d, opt->catalog);
    return gl_flatten(d, s, opt, st);
}

static rt_result load_doc(rt_scene *s, const char *path, const void *data, size_t size,
                          const rt_gltf_options *options, rt_gltf_stats *stats, rt_error *err)
{
    rt_error local_err;
    gl_doc d;
    memset(&d, 0, sizeof d);
    d.path = path;
    d.err = err ? err : &local_err;
    d.bytes = data;
    d.file_size = size;
    rt_gltf_stats st;
    memset(&st, 0, sizeof st);
    st.bounds = rt_box_empty();
    rt_scene_mark mark = rt_scene_mark_of(s); /* a failed load leaves the scene as it was */
    rt_result r = gl_load(&d, s, options, &st);
    doc_free(&d);
    if (r != RT_OK) {
        rt_scene_rollback(s, &mark);
        return r;
    }
    if (stats)
        *stats = st;
    return RT_OK;
}

rt_result rt_gltf_load(rt_scene *s, const char *path, const rt_gltf_options *options, rt_gltf_stats *stats,
                       rt_error *err)
{
    if (!path)
        return rt_fail(err, RT_ERR_IO, "rt_gltf_load: no path");
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(path, GL_MAX_FILE, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    r = rt_gltf_load_memory(s, bytes, size, path, options, stats, err);
    free(bytes);
    return r;
}

rt_result rt_gltf_load_memory(rt_scene *s, const void *data, size_t size, const char *name,
                              const rt_gltf_options *options, rt_gltf_stats *stats, rt_error *err)
{
    static const uint8_t empty[1] = {0};
    if (!data && size)
        return rt_fail(err, RT_ERR_INVALID, "%s: no data", name ? name : "<memory>");
    return load_doc(s, name ? name : "<memory>", size ? data : empty, size, options, stats, err);
}
