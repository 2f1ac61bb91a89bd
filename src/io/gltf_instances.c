/* gltf_instances.c - which glTF meshes the loader keeps once as objects
 * and places by instances (rt/scene/instance.h), and the instance
 * transforms of EXT_mesh_gpu_instancing nodes.
 *
 * A mesh becomes an object when the chosen scene uses it more than once
 * (two or more nodes, or one node with EXT_mesh_gpu_instancing) and its
 * shape is the same at every use: no node using it is skinned or
 * morphed at a pose time (those are flattened per node, as before), and
 * none of its primitives emits light (emitters stay world triangles, so
 * the light table can sample them). Everything else is flattened as
 * before, so a file without repeated meshes loads exactly as it did.
 *
 * EXT_mesh_gpu_instancing (Khronos glTF extension registry, "Vendor"
 * extensions): a node with a mesh carries accessors TRANSLATION (VEC3
 * float), ROTATION (VEC4 float, or normalized byte or short: a
 * quaternion x y z w) and SCALE (VEC3 float), all optional and all of one
 * count; instance k's transform is the node's world matrix times
 * T_k * R_k * S_k, and the node's own, uninstanced, mesh is not drawn.
 * Quaternions are renormalised as node rotations are (gltf_parse.c).
 */
#include "gltf_doc.h"

#include <math.h>
#include <stdlib.h>

#include "rt/base/alloc.h"
#include "rt/base/log.h"

static const char *const gpu_names[3] = {"TRANSLATION", "ROTATION", "SCALE"};

/* True when a primitive's material emits light (a lamp stays world
 * geometry, for the light table). */
static bool prim_emits(const gl_doc *d, const gl_prim *p)
{
    if (p->material == RT_NONE || p->material >= d->material_count)
        return false;
    const rt_material *m = &d->materials[p->material].m;
    return (m->emission.x > 0.0f || m->emission.y > 0.0f || m->emission.z > 0.0f) && m->emission_strength > 0.0f;
}

rt_result gl_plan_objects(gl_doc *d, const rt_gltf_options *opt, uint32_t *mesh_object)
{
    /* mesh_object[m]: RT_NONE = flatten; GL_OBJECT_PLANNED = an object, not yet emitted */
    uint32_t *uses = rt_alloc(d->mesh_count ? d->mesh_count : 1, sizeof *uses);
    bool *varies = rt_alloc(d->mesh_count ? d->mesh_count : 1, sizeof *varies);
    if (!uses || !varies) {
        free(uses);
        free(varies);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu meshes", d->path, d->mesh_count);
    }
    for (size_t m = 0; m < d->mesh_count; m++) {
        uses[m] = 0;
        varies[m] = false;
        mesh_object[m] = RT_NONE;
    }
    for (size_t v = 0; v < d->visit_count; v++) {
        const gl_node *n = &d->nodes[d->visits[v].node];
        if (n->mesh == RT_NONE)
            continue;
        uses[n->mesh] += n->gpu_tok >= 0 ? 2u : 1u; /* an instancing node: a use that repeats */
        if (uses[n->mesh] > 2)
            uses[n->mesh] = 2;
        if (d->posed && (n->skin != RT_NONE || n->pose_weight_count > 0))
            varies[n->mesh] = true;
    }
    bool flatten = opt && opt->flatten_instances;
    for (size_t m = 0; m < d->mesh_count; m++) {
        const gl_mesh *me = &d->meshes[m];
        bool ok = !flatten && uses[m] >= 2 && !varies[m];
        for (uint32_t k = 0; ok && k < me->count; k++) {
            const gl_prim *p = &d->prims[me->first + k];
            if (prim_emits(d, p) || (d->posed && p->target_count > 0))
                ok = false;
        }
        if (ok)
            mesh_object[m] = GL_OBJECT_PLANNED;
    }
    free(uses);
    free(varies);
    return RT_OK;
}

/* Checks attribute a of node ni's EXT_mesh_gpu_instancing accessor: its
 * type and component type as the extension allows them. */
static rt_result check_gpu_accessor(gl_doc *d, uint32_t ni, int a)
{
    const gl_node *n = &d->nodes[ni];
    uint32_t ai = n->gpu_attr[a];
    if (ai >= d->accessor_count)
        return gl_fail_at(d, n->gpu_tok, RT_ERR_INVALID,
                          "nodes[%u].extensions.EXT_mesh_gpu_instancing.attributes.%s: accessor %u does not exist "
                          "(%zu accessors)",
                          ni, gpu_names[a], ai, d->accessor_count);
    const gl_accessor *ac = &d->accessors[ai];
    int want = a == 1 ? 4 : 3;
    bool ctype_ok = ac->ctype == GL_FLOAT ||
                    (a == 1 && ac->normalized && (ac->ctype == GL_BYTE || ac->ctype == GL_SHORT));
    if (ac->ncomp != want || ac->rows != want || !ctype_ok)
        return gl_fail_at(d, ac->tok, RT_ERR_INVALID,
                          "nodes[%u].extensions.EXT_mesh_gpu_instancing.attributes.%s: accessor %u must be %s of %s",
                          ni, gpu_names[a], ai, a == 1 ? "VEC4" : "VEC3",
                          a == 1 ? "FLOAT, or normalized BYTE or SHORT" : "FLOAT");
    return RT_OK;
}

rt_result gl_gpu_instances(gl_doc *d, uint32_t ni, rt_mat4 **out, size_t *count)
{
    const gl_node *n = &d->nodes[ni];
    *out = NULL;
    *count = 0;
    size_t cnt = 0;
    int first = -1;
    rt_result r;
    for (int a = 0; a < 3; a++) {
        if (n->gpu_attr[a] == RT_NONE)
            continue;
        if ((r = check_gpu_accessor(d, ni, a)) != RT_OK)
            return r;
        size_t c = d->accessors[n->gpu_attr[a]].count;
        if (first < 0) {
            first = a;
            cnt = c;
        } else if (c != cnt) {
            return gl_fail_at(d, n->gpu_tok, RT_ERR_INVALID,
                              "nodes[%u].extensions.EXT_mesh_gpu_instancing.attributes: %s has %zu elements but %s "
                              "has %zu (all must have the same count)",
                              ni, gpu_names[first], cnt, gpu_names[a], c);
        }
    }
    if (first < 0) { /* no attributes: one instance, the node itself */
        cnt = 1;
    }
    float *f[3] = {NULL, NULL, NULL};
    rt_mat4 *m = rt_alloc(cnt ? cnt : 1, sizeof *m);
    if (!m)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu instances", d->path, cnt);
    for (int a = 0; a < 3; a++) {
        if (n->gpu_attr[a] == RT_NONE)
            continue;
        f[a] = rt_alloc(cnt ? cnt * 4 : 1, sizeof(float));
        if (!f[a]) {
            r = rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %zu instances", d->path, cnt);
            goto done;
        }
        if ((r = gl_read_floats(d, n->gpu_attr[a], f[a])) != RT_OK)
            goto done;
    }
    r = RT_OK;
    for (size_t k = 0; k < cnt; k++) {
        float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
        for (int c = 0; c < 3; c++) {
            if (f[0]) t[c] = f[0][3 * k + (size_t)c];
            if (f[2]) s[c] = f[2][3 * k + (size_t)c];
        }
        for (int c = 0; c < 4 && f[1]; c++)
            q[c] = f[1][4 * k + (size_t)c];
        for (int a = 0; a < 3; a++) {
            int nc = a == 1 ? 4 : 3;
            const float *v = a == 0 ? t : a == 1 ? q : s;
            for (int c = 0; c < nc; c++)
                if (!isfinite(v[c])) {
                    r = gl_fail_at(d, d->accessors[n->gpu_attr[a]].tok, RT_ERR_INVALID,
                                   "nodes[%u].extensions.EXT_mesh_gpu_instancing.attributes.%s (accessor %u): "
                                   "element %zu is not finite",
                                   ni, gpu_names[a], n->gpu_attr[a], k);
                    goto done;
                }
        }
        double q2 = (double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3];
        rt_vec4 qu = rt_v4(0, 0, 0, 0); /* a zero quaternion: a zero matrix, refused as singular */
        if (q2 > 1e-12) {
            float sc = (float)(1.0 / sqrt(q2));
            qu = rt_v4(q[0] * sc, q[1] * sc, q[2] * sc, q[3] * sc);
        }
        rt_mat4 R = rt_mat4_quat(qu);
        if (!(q2 > 1e-12))
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    R.m[i][j] = 0.0f;
        m[k] = rt_mat4_mul(rt_mat4_translate(rt_v3(t[0], t[1], t[2])),
                           rt_mat4_mul(R, rt_mat4_scale(rt_v3(s[0], s[1], s[2]))));
    }
done:
    for (int a = 0; a < 3; a++)
        free(f[a]);
    if (r != RT_OK) {
        free(m);
        return r;
    }
    *out = m;
    *count = cnt;
    return RT_OK;
}
