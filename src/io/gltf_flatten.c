/* gltf_flatten.c - the last pass of the glTF loader (gltf_doc.h): the
 * chosen scene's nodes visited with their world matrices (parent * local,
 * TRS = T * R * S), every triangle primitive of every mesh instance into
 * the scene's vertex and triangle tables (strips and fans converted with
 * the spec's vertex orders; positions by M, normals by M's inverse
 * transpose, tangents by M with w flipped by sign(det M), and winding
 * flipped with it), then materials, cameras and lights. A mesh used more
 * than once (gltf_instances.c decides) goes in once, in its own space, as
 * an object, and each use adds an instance (rt/scene/instance.h) instead
 * of a copy; EXT_mesh_gpu_instancing nodes place their mesh once per
 * instance, either way.
 * Source: Khronos glTF 2.0 specification ("Meshes", "Nodes and
 * Hierarchy", "Cameras"), KHR_lights_punctual, EXT_mesh_gpu_instancing.
 */
#include "gltf_doc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/log.h"
#include "rt/scene/instance.h"
#include "rt/scene/subsurface.h"
#include "rt/scene/texture.h"

rt_result gl_scratch(gl_doc *d, int slot, size_t floats, float **out)
{
    if (!rt_grow((void **)&d->scratch[slot], &d->scratch_cap[slot], floats ? floats : 1, sizeof(float)))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu vertex values", d->path, floats);
    *out = d->scratch[slot];
    return RT_OK;
}

static bool is_triangles(int mode) { return mode == 4 || mode == 5 || mode == 6; }

static size_t prim_triangles(const gl_doc *d, const gl_prim *p)
{
    size_t n = p->indices != RT_NONE ? d->accessors[p->indices].count : d->accessors[p->attr[ATTR_POSITION]].count;
    if (p->mode == 4)
        return n / 3;
    return n >= 3 ? n - 2 : 0;
}

/* How the visited nodes place their meshes: per mesh, flattened
 * (RT_NONE) or an object (GL_OBJECT_PLANNED, then GL_OBJECT_COUNTED once
 * its geometry is counted, then its object index once emitted); per visit,
 * an EXT_mesh_gpu_instancing node's transforms (NULL: the node once). */
#define GL_OBJECT_COUNTED (RT_NONE - 2u)
typedef struct gl_placements {
    uint32_t *mesh_object;
    rt_mat4 **gpu;
    size_t *gpu_count;
    size_t instances; /* instances the objects' uses will add */
} gl_placements;

static void free_placements(gl_placements *pl, size_t visits)
{
    for (size_t v = 0; pl->gpu && v < visits; v++)
        free(pl->gpu[v]);
    free(pl->gpu);
    free(pl->gpu_count);
    free(pl->mesh_object);
}

/* How many times visit v places its mesh. */
static size_t placements_of(const gl_placements *pl, size_t v) { return pl->gpu[v] ? pl->gpu_count[v] : 1; }

static rt_result make_placements(gl_doc *d, const rt_gltf_options *opt, gl_placements *pl)
{
    pl->mesh_object = rt_alloc(d->mesh_count ? d->mesh_count : 1, sizeof *pl->mesh_object);
    pl->gpu = rt_alloc(d->visit_count ? d->visit_count : 1, sizeof *pl->gpu);
    pl->gpu_count = rt_alloc(d->visit_count ? d->visit_count : 1, sizeof *pl->gpu_count);
    if (!pl->mesh_object || !pl->gpu || !pl->gpu_count)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu nodes", d->path, d->visit_count);
    rt_result r = gl_plan_objects(d, opt, pl->mesh_object);
    for (size_t v = 0; v < d->visit_count && r == RT_OK; v++) {
        uint32_t ni = d->visits[v].node;
        const gl_node *n = &d->nodes[ni];
        if (n->mesh == RT_NONE)
            continue;
        if (n->gpu_tok >= 0) {
            r = gl_gpu_instances(d, ni, &pl->gpu[v], &pl->gpu_count[v]);
            if (r == RT_OK && !pl->gpu[v])
                pl->gpu_count[v] = 0;
        }
        if (r == RT_OK && pl->mesh_object[n->mesh] != RT_NONE)
            pl->instances += placements_of(pl, v);
    }
    return r;
}

/* The nodes of the chosen scene in depth-first order with world matrices. */
static rt_result collect_visits(gl_doc *d, const rt_gltf_options *opt)
{
    uint32_t scene = d->default_scene;
    if (opt && opt->use_scene_index) {
        if (opt->scene_index < 0 || (size_t)opt->scene_index >= d->scene_count)
            return rt_fail(d->err, RT_ERR_INVALID, "%s: scene %d requested, the file has %zu scenes", d->path,
                           opt->scene_index, d->scene_count);
        scene = (uint32_t)opt->scene_index;
    } else if (scene == RT_NONE && d->scene_count > 0) {
        scene = 0;
    }
    /* roots: the scene's nodes, or every parentless node when there is no scene */
    size_t root_count = 0;
    uint32_t *roots = rt_alloc(d->node_count, sizeof(uint32_t));
    uint32_t *stack = rt_alloc(d->node_count, sizeof(uint32_t));
    d->visits = rt_alloc(d->node_count, sizeof(gl_visit));
    d->visit_of = rt_alloc(d->node_count, sizeof(uint32_t));
    if (!roots || !stack || !d->visits || !d->visit_of) {
        free(roots);
        free(stack);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu nodes", d->path, d->node_count);
    }
    if (scene != RT_NONE) {
        for (uint32_t k = 0; k < d->scenes[scene].count; k++)
            roots[root_count++] = d->scene_nodes[d->scenes[scene].first + k];
    } else {
        for (size_t i = 0; i < d->node_count; i++)
            if (d->nodes[i].parent == RT_NONE)
                roots[root_count++] = (uint32_t)i;
    }
    rt_mat4 top = opt && opt->use_transform ? opt->transform : rt_mat4_identity();
    /* Depth-first with an explicit stack; a visit's world matrix is its
     * parent's (already visited) times its local matrix. The hierarchy is a
     * forest with unique scene roots (validated), so each node is visited at
     * most once and the stack never holds more than node_count entries.
     */
    for (size_t r = 0; r < root_count; r++) {
        size_t sp = 0;
        uint32_t root = roots[r];
        stack[sp++] = root;
        while (sp > 0) {
            uint32_t n = stack[--sp];
            const gl_node *node = &d->nodes[n];
            rt_mat4 parent = n == root ? top : d->visits[d->visit_of[node->parent]].world;
            d->visit_of[n] = (uint32_t)d->visit_count;
            gl_visit *vis = &d->visits[d->visit_count++];
            vis->node = n;
            vis->world = rt_mat4_mul(parent, node->local);
            for (uint32_t c = node->child_count; c-- > 0;)
                stack[sp++] = d->children[node->first_child + c];
        }
    }
    free(roots);
    free(stack);
    return RT_OK;
}

static rt_result emit_primitive(gl_doc *d, rt_scene *s, uint32_t node, uint32_t pi, const rt_mat4 *M,
                                const rt_mat4 *top, uint32_t material, size_t vbase)
{
    rt_result r = RT_OK;
    uint32_t mesh = d->nodes[node].mesh;
    const gl_prim *p = &d->prims[d->meshes[mesh].first + pi];
    const gl_accessor *pos = &d->accessors[p->attr[ATTR_POSITION]];
    size_t vcount = pos->count;
    rt_vertices *V = &s->vertices;
    float *f = NULL;
    /* posed: morph weights and, for a skinned node, a matrix per vertex */
    float mw[64];
    bool morph = d->posed && p->target_count > 0;
    rt_mat4 *vm = NULL;
    if (morph) {
        if (p->target_count > 64)
            return gl_fail_at(d, p->tok, RT_ERR_LIMIT, "meshes[%u].primitives[%u]: over 64 morph targets", mesh, pi);
        if ((r = gl_morph_weights(d, node, p->target_count, mw)) != RT_OK)
            return r;
    }
    if (d->posed && d->nodes[node].skin != RT_NONE && p->joints[0] != RT_NONE && p->weights[0] != RT_NONE)
        r = gl_skin_matrices(d, p, node, M, top, vcount, &vm);
    if (r != RT_OK)
        return r;

    if ((r = gl_scratch(d, ATTR_POSITION, vcount * 3, &f)) != RT_OK)
        return r;
    if ((r = gl_read_floats(d, p->attr[ATTR_POSITION], f)) != RT_OK)
        return r;
    if (morph)
        r = gl_apply_morph(d, p, mw, 0, f, 3, vcount);
    if (r != RT_OK)
        return r;
    for (size_t i = 0; i < vcount; i++) {
        rt_vec3 q = rt_v3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
        if (!rt_finite3(q))
            return gl_fail_at(d, pos->tok, RT_ERR_INVALID,
                              "accessors[%u] (POSITION of meshes[%u].primitives[%u]): element %zu is not finite "
                              "(%g, %g, %g)",
                              p->attr[ATTR_POSITION], mesh, pi, i, (double)q.x, (double)q.y, (double)q.z);
        V->position[vbase + i] = rt_mat4_point(vm ? &vm[i] : M, q);
    }
    float det = rt_mat4_det3(vm && vcount ? &vm[0] : M);
    rt_mat4 N;
    bool have_n = p->attr[ATTR_NORMAL] != RT_NONE && rt_mat4_normal_matrix(M, &N);
    uint8_t flags = 0;
    if (have_n) {
        if ((r = gl_scratch(d, ATTR_NORMAL, vcount * 3, &f)) != RT_OK)
            return r;
        if ((r = gl_read_floats(d, p->attr[ATTR_NORMAL], f)) != RT_OK)
            return r;
        if (morph)
            r = gl_apply_morph(d, p, mw, 1, f, 3, vcount);
        if (r != RT_OK)
            return r;
        for (size_t i = 0; i < vcount; i++) {
            rt_vec3 n = rt_v3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
            rt_mat4 Ni;
            const rt_mat4 *NM = &N;
            if (vm)
                NM = rt_mat4_normal_matrix(&vm[i], &Ni) ? &Ni : &N;
            V->normal[vbase + i] = rt_finite3(n) ? rt_normalize(rt_mat4_vector(NM, n)) : rt_v3s(0);
        }
        flags |= RT_TRI_SMOOTH;
        if (p->attr[ATTR_TANGENT] != RT_NONE) {
            if ((r = gl_scratch(d, ATTR_TANGENT, vcount * 4, &f)) != RT_OK)
                return r;
            if ((r = gl_read_floats(d, p->attr[ATTR_TANGENT], f)) != RT_OK)
                return r;
            if (morph)
                r = gl_apply_morph(d, p, mw, 2, f, 4, vcount);
            if (r != RT_OK)
                return r;
            float sign = det < 0 ? -1.0f : 1.0f;
            for (size_t i = 0; i < vcount; i++) {
                rt_vec3 t = rt_mat4_vector(vm ? &vm[i] : M, rt_v3(f[4 * i], f[4 * i + 1], f[4 * i + 2]));
                t = rt_finite3(t) ? rt_normalize(t) : rt_v3s(0);
                float w = f[4 * i + 3] < 0 ? -sign : sign;
                V->tangent[vbase + i] = rt_v4(t.x, t.y, t.z, w);
            }
            flags |= RT_TRI_TANGENT;
        }
    }
    for (int k = ATTR_TEXCOORD_0; k <= ATTR_TEXCOORD_1; k++) {
        if (p->attr[k] == RT_NONE)
            continue;
        if ((r = gl_scratch(d, k, vcount * 2, &f)) != RT_OK)
            return r;
        if ((r = gl_read_floats(d, p->attr[k], f)) != RT_OK)
            return r;
        rt_vec2 *uv = k == ATTR_TEXCOORD_0 ? V->uv0 : V->uv1;
        for (size_t i = 0; i < vcount; i++)
            uv[vbase + i] = rt_v2(f[2 * i], f[2 * i + 1]);
        if (k == ATTR_TEXCOORD_0)
            flags |= RT_TRI_UV;
    }
    if (p->attr[ATTR_COLOR_0] != RT_NONE) {
        const gl_accessor *ca = &d->accessors[p->attr[ATTR_COLOR_0]];
        size_t nc = (size_t)ca->ncomp;
        if ((r = gl_scratch(d, ATTR_COLOR_0, vcount * nc, &f)) != RT_OK)
            return r;
        if ((r = gl_read_floats(d, p->attr[ATTR_COLOR_0], f)) != RT_OK)
            return r;
        for (size_t i = 0; i < vcount; i++)
            V->color[vbase + i] = rt_v4(f[nc * i], f[nc * i + 1], f[nc * i + 2], nc == 4 ? f[nc * i + 3] : 1.0f);
        flags |= RT_TRI_COLOR;
    }

    /* triangles */
    size_t icount = vcount;
    const uint32_t *idx = NULL;
    if (p->indices != RT_NONE) {
        icount = d->accessors[p->indices].count;
        if (!rt_grow((void **)&d->idx_scratch, &d->idx_cap, icount, sizeof(uint32_t)))
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu indices", d->path, icount);
        if ((r = gl_read_uints(d, p->indices, d->idx_scratch)) != RT_OK)
            return r;
        idx = d->idx_scratch;
        for (size_t i = 0; i < icount; i++)
            if (idx[i] >= vcount)
                return gl_fail_at(d, d->accessors[p->indices].tok, RT_ERR_INVALID,
                                  "accessors[%u] (indices of meshes[%u].primitives[%u]): element %zu is %u, past the "
                                  "vertex count %zu",
                                  p->indices, mesh, pi, i, idx[i], vcount);
    }
    size_t ntri = prim_triangles(d, p);
    if (p->mode == 4 && icount % 3)
        rt_warn("%s: meshes[%u].primitives[%u]: %zu indices are not a multiple of 3; the last %zu are ignored",
                d->path, mesh, pi, icount, icount % 3);
    rt_triangles *T = &s->triangles;
    bool flip = det < 0;
    for (size_t t = 0; t < ntri; t++) {
        size_t a, b, c;
        if (p->mode == 4) { a = 3 * t; b = 3 * t + 1; c = 3 * t + 2; }
        else if (p->mode == 5) { a = t; b = t + 1 + (t % 2); c = t + 2 - (t % 2); }
        else { a = t + 1; b = t + 2; c = 0; }
        uint32_t va = (uint32_t)vbase + (idx ? idx[a] : (uint32_t)a);
        uint32_t vb = (uint32_t)vbase + (idx ? idx[b] : (uint32_t)b);
        uint32_t vc = (uint32_t)vbase + (idx ? idx[c] : (uint32_t)c);
        size_t o = T->count++;
        T->index[3 * o] = va;
        T->index[3 * o + 1] = flip ? vc : vb;
        T->index[3 * o + 2] = flip ? vb : vc;
        T->material[o] = material;
        T->flags[o] = flags;
    }
    return RT_OK;
}

/* What the chosen scene will add: vertices and triangles (within the
 * loader's limits), the vertex attributes it uses, whether a primitive
 * lacks a material; skipped primitives are warned about once. */
typedef struct gl_totals {
    size_t verts, tris;
    unsigned attrs;    /* RT_ATTR_* */
    bool need_default; /* a primitive without a material */
} gl_totals;

static rt_result count_geometry(gl_doc *d, rt_gltf_stats *st, gl_totals *t, gl_placements *pl)
{
    size_t zeros = 0;
    bool warned_modes = false, warned_skin = false, warned_pos = false;
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        if (n->skin != RT_NONE && !warned_skin && !d->posed) {
            rt_warn("%s: skins and morph targets are not applied; meshes are loaded in their rest pose "
                        "(pose them at a time: --frame-time)", d->path);
            warned_skin = true;
        }
        if (n->mesh == RT_NONE)
            continue;
        const gl_mesh *m = &d->meshes[n->mesh];
        /* geometry added: an object's once, a flattened mesh's at every placement */
        size_t reps = placements_of(pl, v);
        uint32_t *obj = &pl->mesh_object[n->mesh];
        size_t copies = *obj == RT_NONE ? reps : *obj == GL_OBJECT_PLANNED ? 1 : 0;
        if (*obj == GL_OBJECT_PLANNED)
            *obj = GL_OBJECT_COUNTED;
        for (uint32_t k = 0; k < m->count; k++) {
            const gl_prim *p = &d->prims[m->first + k];
            if (p->targets && !warned_skin && !d->posed) {
                rt_warn("%s: skins and morph targets are not applied; meshes are loaded in their rest pose "
                        "(pose them at a time: --frame-time)", d->path);
                warned_skin = true;
            }
            if (!is_triangles(p->mode)) {
                if (!warned_modes)
                    rt_warn("%s: points and lines primitives (modes 0-3) are skipped", d->path);
                warned_modes = true;
                continue;
            }
            if (p->attr[ATTR_POSITION] == RT_NONE) {
                if (!warned_pos)
                    rt_warn("%s: primitives without POSITION are skipped", d->path);
                warned_pos = true;
                continue;
            }
            const gl_accessor *pa = &d->accessors[p->attr[ATTR_POSITION]];
            if (copies > 0 && pa->count > (GL_MAX_VERTICES + 1) / copies)
                return rt_fail(d->err, RT_ERR_LIMIT,
                               "%s: the scene has over %zu vertices or triangles (flattened copies included; an "
                               "instanced mesh counts once); over the loader's limit",
                               d->path, GL_MAX_VERTICES);
            t->verts += pa->count * copies;
            if (pa->view == RT_NONE && (zeros += pa->count * copies) > GL_MAX_ZEROS)
                return rt_fail(d->err, RT_ERR_LIMIT,
                               "%s: over %zu vertices come from accessors without a bufferView (instancing "
                               "included); over the loader's limit",
                               d->path, GL_MAX_ZEROS);
            t->tris += prim_triangles(d, p) * copies;
            if (t->verts > GL_MAX_VERTICES || t->tris > GL_MAX_TRIANGLES)
                return rt_fail(d->err, RT_ERR_LIMIT,
                               "%s: the scene has over %zu vertices or triangles (flattened copies included; an "
                               "instanced mesh counts once); over the loader's limit",
                               d->path, GL_MAX_VERTICES);
            if (p->material == RT_NONE)
                t->need_default = true;
            if (p->attr[ATTR_TEXCOORD_1] != RT_NONE) t->attrs |= RT_ATTR_UV1;
            if (p->attr[ATTR_TANGENT] != RT_NONE && p->attr[ATTR_NORMAL] != RT_NONE) t->attrs |= RT_ATTR_TANGENT;
            if (p->attr[ATTR_COLOR_0] != RT_NONE) t->attrs |= RT_ATTR_COLOR;
            st->primitives += reps;
        }
        st->meshes += reps;
    }
    return RT_OK;
}

/* Materials: one per glTF material, its texture slots mapped to the scene's
 * textures (+ a default for primitives without one, when need_default). */
static rt_result add_materials(gl_doc *d, rt_scene *s, rt_gltf_stats *st, bool need_default, uint32_t *mat_base,
                               uint32_t *default_mat)
{
    *mat_base = (uint32_t)s->material_count;
    for (size_t i = 0; i < d->material_count; i++) {
        rt_material m = d->materials[i].m;
        rt_texture_slot *slots[] = {&m.base_color_tex, &m.metal_rough_tex, &m.normal_tex,
                                    &m.occlusion_tex,  &m.emissive_tex,    &m.transmission_tex};
        for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++) {
            if (slots[k]->texture == RT_NONE)
                continue;
            /* a missing image: the checker for colour (base colour, emission), nothing for data */
            bool colour = slots[k] == &m.base_color_tex || slots[k] == &m.emissive_tex;
            uint32_t t = slots[k]->texture;
            slots[k]->texture = d->texture_missing[t] && !colour ? RT_NONE : d->texture_map[t];
        }
        for (int k = 0; k < RT_XTEX_COUNT; k++) { /* the extensions' maps: left out when missing */
            uint32_t t = m.ext_tex[k].texture;
            if (t != RT_NONE)
                m.ext_tex[k].texture = d->texture_missing[t] ? RT_NONE : d->texture_map[t];
        }
        /* KHR_materials_volume_scatter: the medium inside (rt/scene/subsurface.h) */
        if (!rt_subsurface_attach(s, &m) || rt_scene_add_material(s, &m) == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding materials", d->path);
        st->materials++;
    }
    *default_mat = RT_NONE;
    if (!need_default)
        return RT_OK;
    rt_material m;
    rt_material_default(&m, "gltf_default");
    m.color = rt_v3s(1);
    m.metallic = 1;
    m.roughness = 1;
    m.double_sided = false;
    m.transmission_color = m.color;
    gl_derive_phong(&m);
    *default_mat = rt_scene_add_material(s, &m);
    if (*default_mat == RT_NONE)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding materials", d->path);
    st->materials++;
    return RT_OK;
}

/* Every triangle primitive of node `node`'s mesh by M (vertices from
 * *vbase on, which it advances). */
static rt_result emit_mesh(gl_doc *d, rt_scene *s, uint32_t node, const rt_mat4 *M, const rt_mat4 *top,
                           uint32_t mat_base, uint32_t default_mat, size_t *vbase)
{
    const gl_mesh *m = &d->meshes[d->nodes[node].mesh];
    for (uint32_t k = 0; k < m->count; k++) {
        const gl_prim *p = &d->prims[m->first + k];
        if (!is_triangles(p->mode) || p->attr[ATTR_POSITION] == RT_NONE)
            continue;
        uint32_t mat = p->material == RT_NONE ? default_mat : mat_base + p->material;
        rt_result r;
        if ((r = emit_primitive(d, s, node, k, M, top, mat, *vbase)) != RT_OK)
            return r;
        *vbase += d->accessors[p->attr[ATTR_POSITION]].count;
    }
    return RT_OK;
}

/* Visit v's uses of an object mesh: the object itself the first time
 * (its primitives in object space), then one instance per placement.
 * A transform that is singular (a zero scale) places nothing, with a
 * warning; one that is not finite is an error. */
static rt_result place_object(gl_doc *d, rt_scene *s, rt_gltf_stats *st, gl_placements *pl, size_t v,
                              uint32_t mat_base, uint32_t default_mat, size_t *vbase)
{
    uint32_t ni = d->visits[v].node, mesh = d->nodes[ni].mesh;
    uint32_t *obj = &pl->mesh_object[mesh];
    rt_result r;
    if (*obj == GL_OBJECT_COUNTED) {
        size_t t0 = s->triangles.count, v0 = *vbase;
        rt_mat4 id = rt_mat4_identity();
        if ((r = emit_mesh(d, s, ni, &id, &id, mat_base, default_mat, vbase)) != RT_OK)
            return r;
        *obj = rt_scene_add_object(s, t0, s->triangles.count - t0, v0, *vbase - v0);
        if (*obj == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding meshes[%u] as an object", d->path, mesh);
        st->objects++;
    }
    size_t reps = placements_of(pl, v), skipped = 0;
    const char *why = NULL;
    for (size_t k = 0; k < reps; k++) {
        rt_mat4 W = pl->gpu[v] ? rt_mat4_mul(d->visits[v].world, pl->gpu[v][k]) : d->visits[v].world;
        rt_instance_check c = rt_instance_check_transform(&W);
        if (c == RT_INSTANCE_NOT_FINITE)
            return gl_fail_at(d, pl->gpu[v] ? d->nodes[ni].gpu_tok : d->nodes[ni].tok, RT_ERR_INVALID,
                              "nodes[%u]%s: instance %zu's transform is not finite", ni,
                              pl->gpu[v] ? ".extensions.EXT_mesh_gpu_instancing" : "", k);
        if (c != RT_INSTANCE_OK) {
            why = rt_instance_check_name(c);
            skipped++;
            continue;
        }
        if (rt_scene_add_instance(s, *obj, &W) == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory placing instance %zu of nodes[%u]", d->path, k, ni);
        st->instances++;
        st->instanced_triangles += s->objects[*obj].triangle_count;
    }
    if (skipped)
        rt_warn("%s: nodes[%u]%s: %zu of %zu instances skipped, their transform is %s", d->path, ni,
                pl->gpu[v] ? ".extensions.EXT_mesh_gpu_instancing" : "", skipped, reps, why);
    return RT_OK;
}

/* Every triangle primitive of every visited node into the scene's tables
 * reserved at once (objects once, with their instances), and the bounds of
 * the vertices they use. */
static rt_result add_geometry(gl_doc *d, rt_scene *s, rt_gltf_stats *st, const gl_totals *t, const rt_mat4 *top,
                              uint32_t mat_base, uint32_t default_mat, gl_placements *pl)
{
    if (t->attrs && !rt_scene_enable_attr(s, t->attrs))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for vertex attributes", d->path);
    size_t tri_first = s->triangles.count, inst_first = s->instance_count;
    if (!rt_scene_reserve_triangles(s, t->tris))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu triangles", d->path, t->tris);
    if (pl->instances && !rt_scene_reserve_instances(s, pl->instances))
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu instances (%zu bytes each, %zu bytes)",
                       d->path, pl->instances, RT_INSTANCE_BYTES, pl->instances * RT_INSTANCE_BYTES);
    size_t vbase = s->vertices.count;
    if (t->verts && rt_scene_add_vertices(s, t->verts) == RT_NONE)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu vertices", d->path, t->verts);
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        if (n->mesh == RT_NONE)
            continue;
        rt_result r = RT_OK;
        if (pl->mesh_object[n->mesh] != RT_NONE) {
            r = place_object(d, s, st, pl, v, mat_base, default_mat, &vbase);
        } else if (!pl->gpu[v]) {
            r = emit_mesh(d, s, d->visits[v].node, &d->visits[v].world, top, mat_base, default_mat, &vbase);
        } else {
            for (size_t k = 0; k < pl->gpu_count[v] && r == RT_OK; k++) {
                rt_mat4 W = rt_mat4_mul(d->visits[v].world, pl->gpu[v][k]);
                r = emit_mesh(d, s, d->visits[v].node, &W, top, mat_base, default_mat, &vbase);
            }
        }
        if (r != RT_OK)
            return r;
    }
    st->triangles = s->triangles.count - tri_first;
    /* bounds of the vertices world triangles use (positions are finite:
     * plain compares, no fminf calls, which cost more than the rest of the
     * load), and of the instances */
    rt_box b = rt_box_empty();
    const uint32_t *ix = s->triangles.index;
    for (size_t k = 3 * tri_first; k < 3 * s->triangles.count; k++) {
        if (st->objects && (s->triangles.flags[k / 3] & RT_TRI_OBJECT))
            continue;
        rt_vec3 q = s->vertices.position[ix[k]];
        b.lo.x = q.x < b.lo.x ? q.x : b.lo.x; b.hi.x = q.x > b.hi.x ? q.x : b.hi.x;
        b.lo.y = q.y < b.lo.y ? q.y : b.lo.y; b.hi.y = q.y > b.hi.y ? q.y : b.hi.y;
        b.lo.z = q.z < b.lo.z ? q.z : b.lo.z; b.hi.z = q.z > b.hi.z ? q.z : b.hi.z;
    }
    for (size_t i = inst_first; i < s->instance_count; i++)
        b = rt_box_union(b, s->instances[i].bounds);
    st->bounds = b;
    return RT_OK;
}

/* Perspective cameras and KHR_lights_punctual lights of the visited nodes,
 * placed by their world matrices. */
static rt_result add_cameras_and_lights(gl_doc *d, rt_scene *s, rt_gltf_stats *st)
{
    bool warned_ortho = false;
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        const rt_mat4 *W = &d->visits[v].world;
        rt_vec3 origin = rt_mat4_point(W, rt_v3s(0));
        rt_vec3 fwd = rt_normalize(rt_mat4_vector(W, rt_v3(0, 0, -1)));
        if (n->camera != RT_NONE) {
            const gl_camera *gc = &d->cameras[n->camera];
            if (!gc->perspective) {
                if (!warned_ortho)
                    rt_warn("%s: orthographic cameras are not supported; skipped", d->path);
                warned_ortho = true;
            } else {
                rt_camera c = {0};
                c.position = origin;
                c.look_at = rt_add(origin, fwd);
                c.up = rt_normalize(rt_mat4_vector(W, rt_v3(0, 1, 0)));
                c.vfov_deg = gc->yfov * (180.0f / RT_PI);
                c.aspect_ratio = isfinite(gc->aspect) && gc->aspect > 0.0f ? gc->aspect : 0.0f;
                if (rt_scene_add_camera(s, &c) == RT_NONE)
                    return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding cameras", d->path);
                st->cameras++;
            }
        }
        if (n->light != RT_NONE) {
            const gl_light *gl = &d->lights[n->light];
            rt_light l;
            memset(&l, 0, sizeof l);
            l.kind = gl->kind;
            l.color = gl->color;
            l.intensity = gl->intensity;
            l.position = origin;
            l.direction = fwd;
            l.inner_cone = gl->inner;
            l.outer_cone = gl->outer;
            l.range = gl->range;
            l.quad = RT_NONE;
            if (rt_scene_add_light(s, &l) == RT_NONE)
                return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding lights", d->path);
            st->lights++;
        }
    }
    return RT_OK;
}

rt_result gl_flatten(gl_doc *d, rt_scene *s, const rt_gltf_options *opt, rt_gltf_stats *st)
{
    rt_result r = RT_OK;
    if (opt && opt->use_time)
        r = gl_pose_nodes(d, opt);
    if (r != RT_OK)
        return r;
    st->animated = d->animated;
    if ((r = collect_visits(d, opt)) != RT_OK)
        return r;
    rt_mat4 top = opt && opt->use_transform ? opt->transform : rt_mat4_identity();
    st->nodes = d->visit_count;

    gl_totals t = {0};
    gl_placements pl = {0};
    if ((r = make_placements(d, opt, &pl)) == RT_OK)
        r = count_geometry(d, st, &t, &pl);
    if (r == RT_OK && (s->vertices.count + t.verts >= RT_NONE || s->triangles.count + t.tris >= RT_NONE))
        r = rt_fail(d->err, RT_ERR_LIMIT, "%s: the scene would exceed 2^32 vertices or triangles", d->path);
    if (r == RT_OK)
        r = gl_load_textures(d, s, st);
    uint32_t mat_base = 0, default_mat = RT_NONE;
    if (r == RT_OK)
        r = add_materials(d, s, st, t.need_default, &mat_base, &default_mat);
    if (r == RT_OK)
        r = add_geometry(d, s, st, &t, &top, mat_base, default_mat, &pl);
    free_placements(&pl, d->visit_count);
    if (r != RT_OK)
        return r;
    return add_cameras_and_lights(d, s, st);
}
