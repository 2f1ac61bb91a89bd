/* tangents.c - per-vertex tangents for normal-mapped meshes without them.
 *
 * Algorithm (Lengyel 2001, "Computing Tangent Space Basis Vectors for an
 * Arbitrary Mesh", with the handedness of the glTF / MikkTSpace convention):
 * for each triangle with UV deltas (du1, dv1), (du2, dv2) along its edges
 * e1, e2, solve e1 = du1 dP/du + dv1 dP/dv, e2 = du2 dP/du + dv2 dP/dv for
 * dP/du and dP/dv. The triangle's handedness is -1 when cross(n, dP/du)
 * points along +dP/dv (so that the bitangent cross(n, t) * w always points
 * towards decreasing v, the top of the image), else +1; n is the
 * triangle's outside normal (its vertex normals' sum for smooth triangles,
 * as in surface.c). Two passes over the triangles: the first votes each
 * vertex's sign (area-weighted, +1 on a tie), the second sums unit dP/du
 * times area from the triangles that agree with the vertex's sign, so a
 * mirrored-UV seam does not cancel its tangents out. Each vertex then
 * subtracts the normal component (Gram-Schmidt) and normalises; a vertex
 * with no usable direction (degenerate UVs all round) gets an arbitrary
 * tangent perpendicular to its normal (Duff et al. 2017).
 */
#include "rt/scene/tangents.h"

#include "rt/base/alloc.h"

#include <stdlib.h>
#include <string.h>

static bool eligible(const rt_scene *s, size_t tri)
{
    uint8_t f = s->triangles.flags[tri];
    uint32_t m = s->triangles.material[tri];
    return (f & RT_TRI_UV) && !(f & RT_TRI_TANGENT) && m < s->material_count &&
           s->materials[m].normal_tex.texture != RT_NONE;
}

typedef struct tri_frame {
    rt_vec3 dpdu; /* unit */
    rt_vec3 nface; /* unit outside normal */
    float area;
    float sign;
    bool ok;
} tri_frame;

static tri_frame frame_of(const rt_scene *s, size_t tri)
{
    tri_frame f;
    memset(&f, 0, sizeof f);
    const uint32_t *idx = &s->triangles.index[3 * tri];
    const rt_vertices *vx = &s->vertices;
    rt_vec3 a = vx->position[idx[0]], b = vx->position[idx[1]], c = vx->position[idx[2]];
    rt_vec3 e1 = rt_sub(b, a), e2 = rt_sub(c, a);
    rt_vec2 t0 = vx->uv0[idx[0]], t1 = vx->uv0[idx[1]], t2 = vx->uv0[idx[2]];
    float du1 = t1.x - t0.x, dv1 = t1.y - t0.y, du2 = t2.x - t0.x, dv2 = t2.y - t0.y;
    rt_vec3 nf = rt_cross(e1, e2);
    float len = rt_length(nf);
    if (!(len > 0.0f) || !isfinite(len))
        return f;
    f.area = 0.5f * len;
    nf = rt_scale(nf, 1.0f / len);
    if (s->triangles.flags[tri] & RT_TRI_SMOOTH) {
        rt_vec3 ns = rt_add(rt_add(vx->normal[idx[0]], vx->normal[idx[1]]), vx->normal[idx[2]]);
        if (rt_dot(ns, nf) < 0.0f)
            nf = rt_neg(nf);
    }
    f.nface = nf;
    float det = du1 * dv2 - du2 * dv1;
    if (!(fabsf(det) > 1e-20f) || !isfinite(det))
        return f;
    float inv = 1.0f / det;
    rt_vec3 dpdu = rt_scale(rt_sub(rt_scale(e1, dv2), rt_scale(e2, dv1)), inv);
    rt_vec3 dpdv = rt_scale(rt_sub(rt_scale(e2, du1), rt_scale(e1, du2)), inv);
    float lu = rt_length(dpdu);
    if (!(lu > 0.0f) || !isfinite(lu) || !rt_finite3(dpdv))
        return f;
    f.dpdu = rt_scale(dpdu, 1.0f / lu);
    f.sign = rt_dot(rt_cross(nf, dpdu), dpdv) > 0.0f ? -1.0f : 1.0f;
    f.ok = true;
    return f;
}

rt_result rt_scene_generate_tangents(rt_scene *s, rt_error *err)
{
    size_t ntri = s->triangles.count, nv = s->vertices.count;
    size_t want = 0;
    for (size_t i = 0; i < ntri; i++)
        want += eligible(s, i);
    if (want == 0 || nv == 0)
        return RT_OK;

    float *vote = rt_alloc(nv, sizeof *vote);
    rt_vec3 *tacc = rt_alloc(nv, sizeof *tacc);
    rt_vec3 *nacc = rt_alloc(nv, sizeof *nacc);
    uint8_t *state = rt_alloc(nv, sizeof *state); /* 1 = touched by an eligible triangle, 2 = locked */
    if (!vote || !tacc || !nacc || !state || !rt_scene_enable_attr(s, RT_ATTR_TANGENT)) {
        free(vote); free(tacc); free(nacc); free(state);
        return rt_fail(err, RT_ERR_NOMEM, "out of memory generating tangents for %zu triangles", want);
    }
    const rt_vertices *vx = &s->vertices;
    /* vertices whose tangents came from a file stay as they are */
    for (size_t i = 0; i < ntri; i++)
        if (s->triangles.flags[i] & RT_TRI_TANGENT)
            for (int k = 0; k < 3; k++)
                state[s->triangles.index[3 * i + (size_t)k]] = 2;
    /* pass 1: handedness votes */
    for (size_t i = 0; i < ntri; i++) {
        if (!eligible(s, i))
            continue;
        tri_frame f = frame_of(s, i);
        for (int k = 0; k < 3; k++) {
            uint32_t v = s->triangles.index[3 * i + (size_t)k];
            if (state[v] == 2)
                continue;
            state[v] = 1;
            nacc[v] = rt_add(nacc[v], rt_scale(f.nface, f.area));
            if (f.ok)
                vote[v] += f.sign * f.area;
        }
    }
    /* pass 2: tangents from the triangles that agree with the vertex's sign */
    for (size_t i = 0; i < ntri; i++) {
        if (!eligible(s, i))
            continue;
        tri_frame f = frame_of(s, i);
        if (!f.ok)
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t v = s->triangles.index[3 * i + (size_t)k];
            if (state[v] != 1)
                continue;
            float sign = vote[v] < 0.0f ? -1.0f : 1.0f;
            if (sign == f.sign)
                tacc[v] = rt_add(tacc[v], rt_scale(f.dpdu, f.area));
        }
    }
    /* orthonormalise against the vertex normal */
    for (size_t v = 0; v < nv; v++) {
        if (state[v] != 1)
            continue;
        rt_vec3 n = vx->normal[v];
        if (!(rt_length2(n) > 1e-24f) || !rt_finite3(n))
            n = nacc[v];
        n = rt_normalize(n);
        if (!(rt_length2(n) > 0.5f) || !rt_finite3(n))
            n = rt_v3(0, 0, 1);
        rt_vec3 t = rt_sub(tacc[v], rt_scale(n, rt_dot(n, tacc[v])));
        float l2 = rt_length2(t);
        if (l2 > 1e-24f && isfinite(l2)) {
            t = rt_scale(t, 1.0f / sqrtf(l2));
        } else {
            rt_vec3 b;
            rt_onb(n, &t, &b);
        }
        s->vertices.tangent[v] = rt_v4(t.x, t.y, t.z, vote[v] < 0.0f ? -1.0f : 1.0f);
    }
    /* triangles whose three corners now have tangents use them */
    for (size_t i = 0; i < ntri; i++) {
        if (!eligible(s, i))
            continue;
        bool all = true;
        for (int k = 0; k < 3; k++) {
            rt_vec4 q = s->vertices.tangent[s->triangles.index[3 * i + (size_t)k]];
            if (!(q.x * q.x + q.y * q.y + q.z * q.z > 0.0f))
                all = false;
        }
        if (all)
            s->triangles.flags[i] |= RT_TRI_TANGENT;
    }
    free(vote);
    free(tacc);
    free(nacc);
    free(state);
    return RT_OK;
}
