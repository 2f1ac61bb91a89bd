/* gltf_check.c - the third pass of the glTF loader (gltf_doc.h):
 * every index against its table, every accessor against its bufferView and
 * every bufferView against its buffer with overflow-safe arithmetic, the
 * compressed views and primitives, the node graph (shared children,
 * cycles, depth) and the scenes' roots, all before any buffer is read.
 * Nothing is allocated later from a count that has not been checked here.
 * Source: Khronos glTF 2.0 specification ("Accessors", "Buffers and
 * Buffer Views", "Nodes and Hierarchy").
 */
#include "gltf_doc.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "rt/base/alloc.h"
#include "rt/scene/texture.h"

/* An index into a table of `count` records: RT_NONE (absent) or in range.
 * The message names the reference, "what" formatted from fmt. */
static rt_result check_index(gl_doc *d, uint32_t idx, size_t count, int tok, const char *table, const char *fmt, ...)
    RT_PRINTF(6, 7);

static rt_result check_index(gl_doc *d, uint32_t idx, size_t count, int tok, const char *table, const char *fmt, ...)
{
    if (idx == RT_NONE || (size_t)idx < count)
        return RT_OK;
    char what[160];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return gl_fail_at(d, tok, RT_ERR_INVALID, "%s %u is out of range (the file has %zu %s)", what, (unsigned)idx, count,
                      table);
}

/* Does [offset, offset + count * stride - stride + elem) fit in length? */
static bool span_fits(size_t offset, size_t count, size_t stride, size_t elem, size_t length)
{
    if (offset > length || elem > length - offset)
        return false;
    if (count <= 1)
        return true;
    size_t room = length - offset - elem;
    return stride == 0 ? true : (count - 1) <= room / stride;
}

/* An EXT_meshopt_compression view: its source inside a buffer with data,
 * its decoded size its byteLength; a plain view of a fallback buffer
 * without data has nothing to read. */
rt_result gl_validate_meshopt_view(gl_doc *d, size_t i)
{
    rt_result r;
    gl_view *v = &d->views[i];
    const gl_buffer *b = &d->buffers[v->buffer];
    if (!v->meshopt) {
        if (b->fallback && b->uri < 0)
            return gl_fail_at(d, v->tok, RT_ERR_INVALID,
                              "bufferViews[%zu] reads buffer %u, an EXT_meshopt_compression fallback with no data", i,
                              v->buffer);
        return RT_OK;
    }
    if ((r = check_index(d, v->mo_buffer, d->buffer_count, v->mo_tok, "buffers",
                         "bufferViews[%zu].extensions.EXT_meshopt_compression.buffer", i)) != RT_OK)
        return r;
    const gl_buffer *src = &d->buffers[v->mo_buffer];
    if (src->fallback)
        return gl_fail_at(d, v->mo_tok, RT_ERR_INVALID,
                          "bufferViews[%zu]: compressed data in buffer %u, which is a fallback buffer", i, v->mo_buffer);
    if (!span_fits(v->mo_offset, 1, 0, v->mo_length, src->byte_length))
        return gl_fail_at(d, v->mo_tok, RT_ERR_INVALID,
                          "bufferViews[%zu]: compressed byteOffset %zu + byteLength %zu runs past buffer %u (%zu bytes)",
                          i, v->mo_offset, v->mo_length, v->mo_buffer, src->byte_length);
    if (v->mo_count > v->length / v->mo_stride || v->mo_count * v->mo_stride != v->length)
        return gl_fail_at(d, v->mo_tok, RT_ERR_INVALID,
                          "bufferViews[%zu]: count %zu x byteStride %zu is not the view's byteLength %zu", i, v->mo_count,
                          v->mo_stride, v->length);
    return RT_OK;
}

/* Draco primitives: triangles with indices, and every accessor they fill
 * marked (such accessors need no bufferView, so the limit on all-zero
 * accessors does not apply to them). */
static rt_result validate_draco_prims(gl_doc *d)
{
    rt_result r;
    for (size_t p = 0; p < d->prim_count; p++) {
        gl_prim *pr = &d->prims[p];
        if (pr->draco_view == RT_NONE)
            continue;
        char name[64];
        gl_prim_name(d, p, name, sizeof name);
        if ((r = check_index(d, pr->draco_view, d->view_count, pr->draco_tok, "bufferViews",
                             "%s.extensions.KHR_draco_mesh_compression.bufferView", name)) != RT_OK)
            return r;
        if (pr->mode != 4 || pr->indices == RT_NONE)
            return gl_fail_at(d, pr->draco_tok, RT_ERR_UNSUPPORTED,
                              "%s: a KHR_draco_mesh_compression primitive must be indexed triangles (mode 4 with "
                              "indices)", name);
        if ((r = check_index(d, pr->indices, d->accessor_count, pr->tok, "accessors", "%s.indices", name)) != RT_OK)
            return r;
        d->accessors[pr->indices].draco = true;
        for (int k = 0; k < ATTR_COUNT; k++) {
            if (pr->draco_id[k] == RT_NONE)
                continue;
            if (pr->attr[k] == RT_NONE)
                return gl_fail_at(d, pr->draco_tok, RT_ERR_INVALID,
                                  "%s: KHR_draco_mesh_compression.attributes.%s has no accessor in the "
                                  "primitive's attributes",
                                  name, gl_attr_names[k]);
            if ((r = check_index(d, pr->attr[k], d->accessor_count, pr->tok, "accessors", "%s.attributes.%s", name,
                                 gl_attr_names[k])) != RT_OK)
                return r;
            d->accessors[pr->attr[k]].draco = true;
        }
    }
    return RT_OK;
}

/* Each bufferView within its buffer, a compressed view within its source. */
static rt_result check_views(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->view_count; i++) {
        const gl_view *v = &d->views[i];
        if ((r = check_index(d, v->buffer, d->buffer_count, v->tok, "buffers", "bufferViews[%zu].buffer", i)) != RT_OK)
            return r;
        size_t blen = d->buffers[v->buffer].byte_length;
        if (!span_fits(v->offset, 1, 0, v->length, blen))
            return gl_fail_at(d, v->tok, RT_ERR_INVALID,
                              "bufferViews[%zu]: byteOffset %zu + byteLength %zu runs past buffer %u (%zu bytes)", i,
                              v->offset, v->length, v->buffer, blen);
        if ((r = gl_validate_meshopt_view(d, i)) != RT_OK)
            return r;
    }
    return RT_OK;
}

/* Each accessor within its bufferView (or under the zero-fill cap), its
 * sparse indices and values within theirs. */
static rt_result check_accessors(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->accessor_count; i++) {
        gl_accessor *a = &d->accessors[i];
        size_t es = gl_elem_size(a);
        if (a->view != RT_NONE) {
            if ((r = check_index(d, a->view, d->view_count, a->tok, "bufferViews", "accessors[%zu].bufferView",
                                 i)) != RT_OK)
                return r;
            const gl_view *v = &d->views[a->view];
            size_t stride = v->stride ? v->stride : es;
            if (stride < es)
                return gl_fail_at(d, a->tok, RT_ERR_INVALID,
                                  "accessors[%zu]: bufferView %u has byteStride %zu, less than the element size %zu", i,
                                  a->view, v->stride, es);
            if (!span_fits(a->offset, a->count, stride, es, v->length))
                return gl_fail_at(d, a->tok, RT_ERR_INVALID,
                                  "accessors[%zu]: byteOffset %zu + %zu elements of %zu bytes (stride %zu) run past "
                                  "bufferView %u (%zu bytes)",
                                  i, a->offset, a->count, es, stride, a->view, v->length);
        } else if (a->count > GL_MAX_ZEROS && !a->draco) {
            return gl_fail_at(d, a->tok, RT_ERR_LIMIT,
                              "accessors[%zu]: count %zu without a bufferView is over the limit %zu", i, a->count,
                              GL_MAX_ZEROS);
        }
        if (a->sparse_count) {
            if ((r = check_index(d, a->sp_idx_view, d->view_count, a->tok, "bufferViews",
                                 "accessors[%zu].sparse.indices.bufferView", i)) != RT_OK)
                return r;
            if ((r = check_index(d, a->sp_val_view, d->view_count, a->tok, "bufferViews",
                                 "accessors[%zu].sparse.values.bufferView", i)) != RT_OK)
                return r;
            size_t ics = gl_comp_size(a->sp_idx_ctype);
            if (!span_fits(a->sp_idx_offset, a->sparse_count, ics, ics, d->views[a->sp_idx_view].length))
                return gl_fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%zu].sparse.indices run past bufferView %u", i,
                                  a->sp_idx_view);
            if (!span_fits(a->sp_val_offset, a->sparse_count, es, es, d->views[a->sp_val_view].length))
                return gl_fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%zu].sparse.values run past bufferView %u", i,
                                  a->sp_val_view);
        }
    }
    return RT_OK;
}

/* Each primitive's material, indices and attributes: in range, of the
 * types the spec allows, the attributes of one count. */
static rt_result check_primitives(gl_doc *d)
{
    rt_result r;
    for (size_t m = 0; m < d->mesh_count; m++) {
        for (uint32_t p = 0; p < d->meshes[m].count; p++) {
            const gl_prim *pr = &d->prims[d->meshes[m].first + p];
            if ((r = check_index(d, pr->material, d->material_count, pr->tok, "materials",
                                 "meshes[%zu].primitives[%u].material", m, p)) != RT_OK)
                return r;
            if ((r = check_index(d, pr->indices, d->accessor_count, pr->tok, "accessors",
                                 "meshes[%zu].primitives[%u].indices", m, p)) != RT_OK)
                return r;
            if (pr->indices != RT_NONE) {
                const gl_accessor *a = &d->accessors[pr->indices];
                if (a->ncomp != 1 || a->normalized ||
                    (a->ctype != GL_UNSIGNED_BYTE && a->ctype != GL_UNSIGNED_SHORT && a->ctype != GL_UNSIGNED_INT))
                    return gl_fail_at(d, pr->tok, RT_ERR_INVALID,
                                      "meshes[%zu].primitives[%u].indices: accessor %u must be SCALAR of unsigned "
                                      "byte, short or int",
                                      m, p, pr->indices);
            }
            size_t count = 0;
            for (int k = 0; k < ATTR_COUNT; k++) {
                uint32_t ai = pr->attr[k];
                if ((r = check_index(d, ai, d->accessor_count, pr->tok, "accessors",
                                     "meshes[%zu].primitives[%u].attributes.%s", m, p,
                                     gl_attr_names[k])) != RT_OK)
                    return r;
                if (ai == RT_NONE)
                    continue;
                const gl_accessor *a = &d->accessors[ai];
                /* types and component types of the spec's attribute table,
                 * widened by KHR_mesh_quantization (accepted whether or not
                 * the file declares it) */
                bool ok = a->cols == 1, ct = false;
                bool f = a->ctype == GL_FLOAT, n = a->normalized;
                bool s8s16 = a->ctype == GL_BYTE || a->ctype == GL_SHORT;
                bool u8u16 = a->ctype == GL_UNSIGNED_BYTE || a->ctype == GL_UNSIGNED_SHORT;
                switch (k) {
                case ATTR_POSITION: ok = ok && a->ncomp == 3; ct = f || s8s16 || u8u16; break;
                case ATTR_NORMAL: ok = ok && a->ncomp == 3; ct = f || (s8s16 && n); break;
                case ATTR_TANGENT: ok = ok && a->ncomp == 4; ct = f || (s8s16 && n); break;
                case ATTR_TEXCOORD_0: case ATTR_TEXCOORD_1: ok = ok && a->ncomp == 2; ct = f || s8s16 || u8u16; break;
                case ATTR_COLOR_0: ok = ok && (a->ncomp == 3 || a->ncomp == 4); ct = f || (u8u16 && n); break;
                }
                if (!ok)
                    return gl_fail_at(d, pr->tok, RT_ERR_INVALID,
                                      "meshes[%zu].primitives[%u].attributes.%s: accessor %u has the wrong type", m, p,
                                      gl_attr_names[k], ai);
                if (!ct)
                    return gl_fail_at(d, pr->tok, RT_ERR_INVALID,
                                      "meshes[%zu].primitives[%u].attributes.%s: accessor %u has componentType %d%s, "
                                      "which this attribute does not allow",
                                      m, p, gl_attr_names[k], ai, a->ctype, n ? " (normalized)" : "");
                if (count && a->count != count)
                    return gl_fail_at(d, pr->tok, RT_ERR_INVALID,
                                      "meshes[%zu].primitives[%u].attributes.%s: accessor %u has %zu elements, the "
                                      "others %zu",
                                      m, p, gl_attr_names[k], ai, a->count, count);
                count = a->count;
            }
        }
    }
    return RT_OK;
}

/* Morph targets: every primitive of a mesh has the same number of them
 * (the spec's rule; the posing code sizes one weights array per mesh), and
 * the mesh's `weights`, when given, has one weight per target. Animated
 * weights and node weights are checked against the same count (check_nodes,
 * gltf_pose.c). */
static rt_result check_morph_counts(gl_doc *d)
{
    for (size_t m = 0; m < d->mesh_count; m++) {
        const gl_mesh *me = &d->meshes[m];
        uint32_t targets = me->count ? d->prims[me->first].target_count : 0;
        for (uint32_t p = 1; p < me->count; p++) {
            const gl_prim *pr = &d->prims[me->first + p];
            if (pr->target_count != targets)
                return gl_fail_at(d, pr->tok, RT_ERR_INVALID,
                                  "meshes[%zu].primitives[%u]: has %u morph targets, primitives[0] %u (every "
                                  "primitive of a mesh must have the same number)",
                                  m, p, pr->target_count, targets);
        }
        if (me->weights >= 0 && (d->j.tok[me->weights].type != RT_JSON_ARRAY ||
                                 d->j.tok[me->weights].size != (int)targets))
            return gl_fail_at(d, me->weights, RT_ERR_INVALID,
                              "meshes[%zu].weights: expected an array of %u numbers, one per morph target", m,
                              targets);
    }
    return RT_OK;
}

/* A node's `weights`: one per morph target of its mesh. */
static rt_result check_node_weights(gl_doc *d, size_t i)
{
    const gl_node *n = &d->nodes[i];
    if (n->weights < 0)
        return RT_OK;
    if (n->mesh == RT_NONE)
        return gl_fail_at(d, n->weights, RT_ERR_INVALID, "nodes[%zu].weights: the node has no mesh", i);
    const gl_mesh *me = &d->meshes[n->mesh];
    uint32_t targets = me->count ? d->prims[me->first].target_count : 0;
    if (d->j.tok[n->weights].type != RT_JSON_ARRAY || d->j.tok[n->weights].size != (int)targets)
        return gl_fail_at(d, n->weights, RT_ERR_INVALID,
                          "nodes[%zu].weights: expected an array of %u numbers, one per morph target of mesh %u", i,
                          targets, n->mesh);
    return RT_OK;
}

/* Each node's references in range; children linked to their one parent. */
static rt_result check_nodes(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->node_count; i++) {
        gl_node *n = &d->nodes[i];
        if ((r = check_index(d, n->mesh, d->mesh_count, n->tok, "meshes", "nodes[%zu].mesh", i)) != RT_OK)
            return r;
        if ((r = check_node_weights(d, i)) != RT_OK)
            return r;
        if ((r = check_index(d, n->camera, d->camera_count, n->tok, "cameras", "nodes[%zu].camera", i)) != RT_OK)
            return r;
        if ((r = check_index(d, n->skin, d->skin_count, n->tok, "skins", "nodes[%zu].skin", i)) != RT_OK)
            return r;
        if ((r = check_index(d, n->light, d->light_count, n->tok, "lights", "nodes[%zu].KHR_lights_punctual.light",
                             i)) != RT_OK)
            return r;
        for (uint32_t c = 0; c < n->child_count; c++) {
            uint32_t ch = d->children[n->first_child + c];
            if ((r = check_index(d, ch, d->node_count, n->tok, "nodes", "nodes[%zu].children", i)) != RT_OK)
                return r;
            if (d->nodes[ch].parent != RT_NONE)
                return gl_fail_at(d, n->tok, RT_ERR_INVALID, "nodes[%zu]: child %u already has parent node %u", i, ch,
                                  d->nodes[ch].parent);
            d->nodes[ch].parent = (uint32_t)i;
        }
    }
    return RT_OK;
}

/* Each node has at most one parent (check_nodes). Depths by walking up to
 * a root or a node of known depth, memoised, so the whole pass is linear;
 * a walk that meets its own path is a cycle. */
static rt_result check_depths(gl_doc *d)
{
    const uint32_t unknown = UINT32_MAX, on_path = UINT32_MAX - 1;
    uint32_t *depth = rt_alloc(d->node_count, sizeof(uint32_t));
    uint32_t *path = rt_alloc(GL_MAX_DEPTH + 2, sizeof(uint32_t));
    if (!depth || !path) {
        free(depth);
        free(path);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    }
    for (size_t i = 0; i < d->node_count; i++)
        depth[i] = unknown;
    rt_result r = RT_OK;
    for (size_t i = 0; i < d->node_count && r == RT_OK; i++) {
        size_t len = 0;
        uint32_t n = (uint32_t)i;
        while (depth[n] == unknown) {
            if (len > GL_MAX_DEPTH) {
                r = gl_fail_at(d, d->nodes[i].tok, RT_ERR_LIMIT, "nodes[%zu] is more than %d levels deep", i,
                               GL_MAX_DEPTH);
                break;
            }
            depth[n] = on_path;
            path[len++] = n;
            uint32_t p = d->nodes[n].parent;
            if (p == RT_NONE) {
                n = RT_NONE;
                break;
            }
            if (depth[p] == on_path) {
                r = gl_fail_at(d, d->nodes[p].tok, RT_ERR_INVALID, "nodes[%u] is its own ancestor (a cycle)", p);
                break;
            }
            n = p;
        }
        if (r != RT_OK)
            break;
        uint32_t base = n == RT_NONE ? 0 : depth[n] + 1;
        for (size_t k = len; k-- > 0; base++) {
            if (base > GL_MAX_DEPTH) {
                r = gl_fail_at(d, d->nodes[i].tok, RT_ERR_LIMIT, "nodes[%zu] is more than %d levels deep", i,
                               GL_MAX_DEPTH);
                break;
            }
            depth[path[k]] = base;
        }
    }
    free(depth);
    free(path);
    return r;
}

/* Scene roots: in range, parentless, listed once (mark[n] = scene + 1). */
static rt_result check_scene_roots(gl_doc *d)
{
    uint32_t *mark = rt_alloc(d->node_count, sizeof(uint32_t));
    if (!mark)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    for (size_t i = 0; i < d->scene_count; i++) {
        const gl_scene *sc = &d->scenes[i];
        for (uint32_t k = 0; k < sc->count; k++) {
            uint32_t n = d->scene_nodes[sc->first + k];
            rt_result r = RT_OK;
            if (n >= d->node_count)
                r = gl_fail_at(d, sc->tok, RT_ERR_INVALID,
                               "scenes[%zu].nodes %u is out of range (the file has %zu nodes)", i, n, d->node_count);
            else if (d->nodes[n].parent != RT_NONE)
                r = gl_fail_at(d, sc->tok, RT_ERR_INVALID, "scenes[%zu]: node %u is not a root (its parent is node %u)",
                               i, n, d->nodes[n].parent);
            else if (mark[n] == i + 1)
                r = gl_fail_at(d, sc->tok, RT_ERR_INVALID, "scenes[%zu]: node %u is listed twice", i, n);
            if (r != RT_OK) {
                free(mark);
                return r;
            }
            mark[n] = (uint32_t)i + 1;
        }
    }
    free(mark);
    return RT_OK;
}

/* Every texture a material names, every image a texture names, every
 * bufferView an image names: in range. */
static rt_result check_textures(gl_doc *d)
{
    rt_result r;
    for (size_t i = 0; i < d->material_count; i++) {
        const rt_material *m = &d->materials[i].m;
        const rt_texture_slot *slots[] = {&m->base_color_tex, &m->metal_rough_tex, &m->normal_tex,
                                          &m->occlusion_tex,  &m->emissive_tex,    &m->transmission_tex};
        for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++)
            if ((r = check_index(d, slots[k]->texture, d->texture_count, d->materials[i].tok, "textures",
                                 "materials[%zu]: texture", i)) != RT_OK)
                return r;
        for (int k = 0; k < RT_XTEX_COUNT; k++)
            if ((r = check_index(d, m->ext_tex[k].texture, d->texture_count, d->materials[i].tok, "textures",
                                 "materials[%zu].extensions: texture", i)) != RT_OK)
                return r;
    }
    for (size_t i = 0; i < d->texture_count; i++) {
        if ((r = check_index(d, d->textures[i].source, d->image_count, d->textures[i].tok, "images",
                             "textures[%zu].source", i)) != RT_OK)
            return r;
        if ((r = check_index(d, d->textures[i].sampler, d->sampler_count, d->textures[i].tok, "samplers",
                             "textures[%zu].sampler", i)) != RT_OK)
            return r;
    }
    for (size_t i = 0; i < d->image_count; i++)
        if ((r = check_index(d, d->images[i].view, d->view_count, d->images[i].tok, "bufferViews",
                             "images[%zu].bufferView", i)) != RT_OK)
            return r;
    return RT_OK;
}

rt_result gl_validate(gl_doc *d)
{
    rt_result r;
    if ((r = check_views(d)) != RT_OK)
        return r;
    if ((r = validate_draco_prims(d)) != RT_OK)
        return r;
    if ((r = check_accessors(d)) != RT_OK)
        return r;
    if ((r = check_primitives(d)) != RT_OK)
        return r;
    if ((r = check_morph_counts(d)) != RT_OK)
        return r;
    if ((r = check_nodes(d)) != RT_OK)
        return r;
    if ((r = check_depths(d)) != RT_OK)
        return r;
    if ((r = check_scene_roots(d)) != RT_OK)
        return r;
    if ((r = check_index(d, d->default_scene, d->scene_count, -1, "scenes", "scene")) != RT_OK)
        return r;
    return check_textures(d);
}
