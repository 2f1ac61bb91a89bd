/* gltf_pose.c - a glTF scene posed at a time (gltf_doc.h): the
 * animation channels sampled (rt/io/gltf_animation.h: STEP, LINEAR with
 * slerp, CUBICSPLINE) into node translations, rotations, scales and morph
 * weights; the per-vertex skin matrices of a primitive (joint world
 * matrices times inverse bind matrices, blended by the weights); and morph
 * target displacements added to positions, normals and tangents.
 * Source: Khronos glTF 2.0 specification ("Animations", "Skins",
 * "Morph Targets").
 */
#include "gltf_doc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/io/gltf_animation.h"

/* Accessor ai as floats in a fresh buffer (the caller frees it), checked:
 * ncomp components per element, `count` elements (SIZE_MAX: any), finite. */
static rt_result posing_floats(gl_doc *d, uint32_t ai, int ncomp, size_t count, const char *what, float **out)
{
    *out = NULL;
    if (ai >= d->accessor_count)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: %s: accessor %u is out of range (the file has %zu)", d->path, what,
                       ai, d->accessor_count);
    const gl_accessor *a = &d->accessors[ai];
    if (a->ncomp != ncomp)
        return gl_fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%u] (%s): expected %d components per element, not %d",
                          ai, what, ncomp, a->ncomp);
    if (count != SIZE_MAX && a->count != count)
        return gl_fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%u] (%s): has %zu elements, expected %zu", ai, what,
                          a->count, count);
    float *f = rt_alloc(a->count * (size_t)ncomp, sizeof(float));
    if (!f)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for %s", d->path, what);
    rt_result r = gl_read_floats(d, ai, f);
    if (r != RT_OK) {
        free(f);
        return r;
    }
    for (size_t i = 0; i < a->count * (size_t)ncomp; i++)
        if (!isfinite(f[i])) {
            free(f);
            return gl_fail_at(d, a->tok, RT_ERR_INVALID, "accessors[%u] (%s): element %zu is not finite", ai, what,
                              i / (size_t)ncomp);
        }
    *out = f;
    return RT_OK;
}

/* Morph target count of a node's mesh (that of its first primitive; the
 * spec requires all primitives of a mesh to have the same). */
static uint32_t node_targets(const gl_doc *d, uint32_t node)
{
    const gl_node *n = &d->nodes[node];
    return n->mesh == RT_NONE ? 0 : d->prims[d->meshes[n->mesh].first].target_count;
}

/* One channel of the chosen animation applied to its node at time t. */
static rt_result pose_channel(gl_doc *d, uint32_t anim, uint32_t c, float t)
{
    rt_result r;
    const gl_anim *an = &d->anims[anim];
    const gl_channel *ch = &d->channels[an->first_channel + c];
    if (ch->path < 0 || ch->node == RT_NONE)
        return RT_OK; /* a path rt does not animate, or no target node */
    char what[96];
    snprintf(what, sizeof what, "animations[%u].channels[%u]", anim, c);
    if (ch->node >= d->node_count)
        return gl_fail_at(d, ch->tok, RT_ERR_INVALID, "%s: target node %u is out of range (the file has %zu nodes)",
                          what, ch->node, d->node_count);
    gl_node *n = &d->nodes[ch->node];
    if (n->has_matrix && ch->path != PATH_WEIGHTS)
        return gl_fail_at(d, ch->tok, RT_ERR_INVALID, "%s: node %u has a matrix, which animations cannot target",
                          what, ch->node);
    const gl_asampler *sa = &d->asamplers[an->first_sampler + ch->sampler];
    int ncomp = ch->path == PATH_ROTATION ? 4 : ch->path == PATH_WEIGHTS ? (int)node_targets(d, ch->node) : 3;
    if (ncomp == 0)
        return gl_fail_at(d, ch->tok, RT_ERR_INVALID, "%s: animates the weights of node %u, whose mesh has no morph "
                          "targets", what, ch->node);
    if (ncomp > 64)
        return gl_fail_at(d, ch->tok, RT_ERR_LIMIT, "%s: over 64 morph targets", what);
    char w_in[128], w_out[128];
    snprintf(w_in, sizeof w_in, "input of %s", what);
    snprintf(w_out, sizeof w_out, "output of %s", what);
    float *times = NULL, *values = NULL;
    if ((r = posing_floats(d, sa->input, 1, SIZE_MAX, w_in, &times)) != RT_OK)
        return r;
    size_t keys = d->accessors[sa->input].count;
    for (size_t k = 1; k < keys; k++)
        if (!(times[k] > times[k - 1])) {
            double now = times[k], before = times[k - 1];
            free(times);
            return gl_fail_at(d, d->accessors[sa->input].tok, RT_ERR_INVALID,
                              "accessors[%u] (%s): key times must increase, element %zu is %g after %g", sa->input, w_in,
                              k, now, before);
        }
    size_t per = sa->interp == RT_INTERP_CUBICSPLINE ? 3 : 1;
    r = ch->path == PATH_WEIGHTS ? posing_floats(d, sa->output, 1, keys * per * (size_t)ncomp, w_out, &values)
                                 : posing_floats(d, sa->output, ncomp, keys * per, w_out, &values);
    if (r != RT_OK) {
        free(times);
        return r;
    }
    float out[64];
    rt_anim_sample((rt_interp)sa->interp, times, keys, values, ncomp, ch->path == PATH_ROTATION, t, out);
    free(times);
    free(values);
    switch (ch->path) {
    case PATH_TRANSLATION: memcpy(n->tr, out, sizeof n->tr); break;
    case PATH_ROTATION: memcpy(n->rot, out, sizeof n->rot); break;
    case PATH_SCALE: memcpy(n->sc, out, sizeof n->sc); break;
    default:
        free(n->pose_weights);
        n->pose_weights = malloc((size_t)ncomp * sizeof(float));
        if (!n->pose_weights)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
        memcpy(n->pose_weights, out, (size_t)ncomp * sizeof(float));
        n->pose_weight_count = (uint32_t)ncomp;
    }
    if (ch->path != PATH_WEIGHTS)
        n->local = rt_mat4_mul(rt_mat4_translate(rt_v3(n->tr[0], n->tr[1], n->tr[2])),
                               rt_mat4_mul(rt_mat4_quat(rt_v4(n->rot[0], n->rot[1], n->rot[2], n->rot[3])),
                                           rt_mat4_scale(rt_v3(n->sc[0], n->sc[1], n->sc[2]))));
    return RT_OK;
}

static rt_result pose_named(gl_doc *d, const rt_gltf_options *opt);

static rt_result pose_animation(gl_doc *d, uint32_t a, float time);

/* rt_gltf_options.use_time: the chosen animation's channels at the time,
 * before the world matrices are made. */
rt_result gl_pose_nodes(gl_doc *d, const rt_gltf_options *opt)
{
    d->posed = true;
    if (opt->animation_name && !(d->anim_count == 0 && opt->animation_optional))
        return pose_named(d, opt); /* (a scene's name for its models: one without animations ignores it) */
    if (d->anim_count == 0) {
        if (opt->animation > 0 && !opt->animation_optional)
            return rt_fail(d->err, RT_ERR_INVALID, "%s: animation %d requested, the file has none", d->path,
                           opt->animation);
        return RT_OK; /* skins and morph weights still pose the meshes */
    }
    if (opt->animation < 0 || (size_t)opt->animation >= d->anim_count)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: animation %d requested, the file has %zu (0 to %zu)", d->path,
                       opt->animation, d->anim_count, d->anim_count - 1);
    return pose_animation(d, (uint32_t)opt->animation, opt->time);
}

/* The animation named opt->animation_name (the first of that name); an
 * unknown name is an error listing the file's names. */
static rt_result pose_named(gl_doc *d, const rt_gltf_options *opt)
{
    char names[512] = "", name[128];
    for (uint32_t a = 0; a < d->anim_count; a++) {
        int t = rt_json_get(&d->j, d->anims[a].tok, "name");
        if (t < 0 || rt_json_string(&d->j, t, name, sizeof name) < 0)
            snprintf(name, sizeof name, "(%u, unnamed)", a);
        else if (strcmp(name, opt->animation_name) == 0)
            return pose_animation(d, a, opt->time);
        size_t n = strlen(names);
        if (n + strlen(name) + 8 < sizeof names)
            snprintf(names + n, sizeof names - n, "%s'%s'", n ? ", " : "", name);
        else if (n + 5 < sizeof names && !strstr(names, "..."))
            snprintf(names + n, sizeof names - n, ", ...");
    }
    if (d->anim_count == 0)
        return rt_fail(d->err, RT_ERR_INVALID, "%s: animation '%s' requested, the file has none", d->path,
                       opt->animation_name);
    return rt_fail(d->err, RT_ERR_INVALID, "%s: no animation named '%s' (the file has %s)", d->path,
                   opt->animation_name, names);
}

/* Every channel of animation a at time t. */
static rt_result pose_animation(gl_doc *d, uint32_t a, float time)
{
    rt_result r;
    d->animated = d->anims[a].channel_count > 0;
    for (uint32_t c = 0; c < d->anims[a].channel_count; c++)
        if ((r = pose_channel(d, a, c, time)) != RT_OK)
            return r;
    return RT_OK;
}

/* The morph weights of a posed node's mesh: animated, else the node's
 * `weights`, else the mesh's, else zeros. */
rt_result gl_morph_weights(gl_doc *d, uint32_t node, uint32_t count, float *w)
{
    const gl_node *n = &d->nodes[node];
    memset(w, 0, count * sizeof *w);
    if (n->pose_weights) {
        /* equal since gl_validate's check_morph_counts; min() keeps the copy in bounds regardless */
        memcpy(w, n->pose_weights, (count < n->pose_weight_count ? count : n->pose_weight_count) * sizeof *w);
        return RT_OK;
    }
    int tok = n->weights >= 0 ? n->weights : d->meshes[n->mesh].weights;
    if (tok < 0)
        return RT_OK;
    char where[48];
    snprintf(where, sizeof where, n->weights >= 0 ? "nodes[%u]" : "meshes[%u]", n->weights >= 0 ? node : n->mesh);
    return gl_get_floats(d, where, "weights", tok, w, (int)count);
}

/* Adds the weighted morph target displacements of one attribute (slot 0
 * POSITION, 1 NORMAL, 2 TANGENT) to f (stride floats a vertex, xyz first). */
rt_result gl_apply_morph(gl_doc *d, const gl_prim *p, const float *w, int slot, float *f, size_t stride,
                         size_t vcount)
{
    rt_result r;
    static const char *const names[3] = {"POSITION", "NORMAL", "TANGENT"};
    for (uint32_t k = 0; k < p->target_count; k++) {
        uint32_t ai = d->targets[p->first_target + k].attr[slot];
        if (w[k] == 0.0f || ai == RT_NONE)
            continue;
        char what[64];
        snprintf(what, sizeof what, "%s of morph target %u", names[slot], k);
        float *delta;
        if ((r = posing_floats(d, ai, 3, vcount, what, &delta)) != RT_OK)
            return r;
        for (size_t i = 0; i < vcount; i++)
            for (size_t c = 0; c < 3; c++)
                f[i * stride + c] += w[k] * delta[3 * i + c];
        free(delta);
    }
    return RT_OK;
}

/* World matrix of any node (joints need not be in the chosen scene). */
rt_mat4 gl_node_world(const gl_doc *d, uint32_t n, const rt_mat4 *top)
{
    rt_mat4 m = d->nodes[n].local;
    for (uint32_t p = d->nodes[n].parent; p != RT_NONE; p = d->nodes[p].parent)
        m = rt_mat4_mul(d->nodes[p].local, m);
    return rt_mat4_mul(*top, m);
}

/* Per-vertex skin matrices of a primitive of a skinned node (glTF 2.0,
 * 3.7.3 "Skins"): joint matrix j = world(joint j) * inverseBind(j); a
 * vertex's matrix is the sum over its JOINTS_n / WEIGHTS_n sets of weight x
 * joint matrix. The mesh node's own transform does not apply. A vertex whose
 * weights sum to 0 keeps the node's transform M. */
rt_result gl_skin_matrices(gl_doc *d, const gl_prim *p, uint32_t node, const rt_mat4 *M, const rt_mat4 *top,
                           size_t vcount, rt_mat4 **out)
{
    const gl_skin *sk = &d->skins[d->nodes[node].skin];
    char what[64];
    snprintf(what, sizeof what, "inverseBindMatrices of skins[%u]", d->nodes[node].skin);
    float *ibm = NULL;
    rt_result r;
    if (sk->ibm != RT_NONE && (r = posing_floats(d, sk->ibm, 16, SIZE_MAX, what, &ibm)) != RT_OK)
        return r;
    if (ibm && d->accessors[sk->ibm].count < sk->joint_count) {
        free(ibm);
        return gl_fail_at(d, sk->tok, RT_ERR_INVALID, "skins[%u]: %u joints but %zu inverseBindMatrices",
                          d->nodes[node].skin, sk->joint_count, d->accessors[sk->ibm].count);
    }
    rt_mat4 *jm = rt_alloc(sk->joint_count, sizeof *jm);
    if (!jm) {
        free(ibm);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for joints", d->path);
    }
    for (uint32_t j = 0; j < sk->joint_count; j++) {
        uint32_t jn = d->skin_joints[sk->first_joint + j];
        if (jn >= d->node_count) {
            free(ibm);
            free(jm);
            return gl_fail_at(d, sk->tok, RT_ERR_INVALID,
                              "skins[%u].joints: node %u is out of range (the file has %zu)",
                              d->nodes[node].skin, jn, d->node_count);
        }
        jm[j] = rt_mat4_mul(gl_node_world(d, jn, top), ibm ? gl_mat_from_gltf(ibm + 16 * j) : rt_mat4_identity());
    }
    free(ibm);
    r = RT_OK;
    if (!rt_grow((void **)&d->skin_scratch, &d->skin_scratch_cap, vcount ? vcount : 1, sizeof(rt_mat4))) {
        free(jm);
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for skinning", d->path);
    }
    rt_mat4 *vm = d->skin_scratch;
    memset(vm, 0, vcount * sizeof *vm);
    float *wsum = rt_alloc(vcount ? vcount : 1, sizeof(float));
    if (!wsum)
        r = rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory for skinning", d->path);
    for (int set = 0; set < 2 && r == RT_OK; set++) {
        if (p->joints[set] == RT_NONE || p->weights[set] == RT_NONE)
            continue;
        float *js = NULL, *ws = NULL;
        snprintf(what, sizeof what, "JOINTS_%d", set);
        r = posing_floats(d, p->joints[set], 4, vcount, what, &js);
        snprintf(what, sizeof what, "WEIGHTS_%d", set);
        if (r == RT_OK)
            r = posing_floats(d, p->weights[set], 4, vcount, what, &ws);
        for (size_t i = 0; i < vcount && r == RT_OK; i++)
            for (int c = 0; c < 4; c++) {
                float w = ws[4 * i + c], jf = js[4 * i + c];
                if (w == 0.0f)
                    continue;
                if (!(jf >= 0) || jf >= (float)sk->joint_count) {
                    r = gl_fail_at(d, d->accessors[p->joints[set]].tok, RT_ERR_INVALID,
                                   "accessors[%u] (JOINTS_%d): element %zu names joint %g of %u", p->joints[set], set, i,
                                   (double)jf, sk->joint_count);
                    break;
                }
                const rt_mat4 *J = &jm[(uint32_t)jf];
                for (int a = 0; a < 4; a++)
                    for (int b = 0; b < 4; b++)
                        vm[i].m[a][b] += w * J->m[a][b];
                wsum[i] += w;
            }
        free(js);
        free(ws);
    }
    for (size_t i = 0; i < vcount && r == RT_OK; i++)
        if (wsum[i] == 0.0f)
            vm[i] = *M;
    free(wsum);
    free(jm);
    *out = r == RT_OK ? vm : NULL;
    return r;
}
