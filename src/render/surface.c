/* surface.c - the surface record at a hit and the material lookups on it:
 * point, normals, tangent frame, UVs and vertex colour, normal mapping,
 * base colour, emission, alpha cut-outs, and where secondary rays start.
 *
 * Surface points are reconstructed from the primitive (barycentrics on a
 * triangle, projection onto a sphere, (s, t) on a quad) rather than from
 * org + t * dir, which keeps them on the surface to float precision
 * (Waechter and Binder, Ray Tracing Gems ch. 6); secondary rays then leave
 * through rt_offset_ray_origin.
 *
 * Tangent frames follow glTF: the bitangent is cross(n, t) * w and points
 * towards decreasing v (the top of the texture image), so a normal map's +Y
 * (green) is "up" in the image. Without vertex tangents the frame comes
 * from the UV derivatives of the primitive (dP/du), with w recording a
 * mirrored UV layout.
 */
#include "rt/render/surface.h"

#include "rt/render/environment.h"
#include "rt/scene/instance.h"
#include "rt/scene/texture.h"

/* Tangent from UV derivatives: t = dP/du, and the handedness sign w such
 * that cross(n, t) * w points along -dP/dv (towards the top of the image). */
static void tangent_from_uv(rt_vec3 e1, rt_vec3 e2, rt_vec2 d1, rt_vec2 d2, rt_vec3 n, rt_vec3 *t, float *w)
{
    float det = d1.x * d2.y - d2.x * d1.y;
    if (fabsf(det) < 1e-20f || !isfinite(det)) {
        rt_vec3 b;
        rt_onb(n, t, &b);
        *w = 1.0f;
        return;
    }
    float inv = 1.0f / det;
    rt_vec3 dpdu = rt_scale(rt_sub(rt_scale(e1, d2.y), rt_scale(e2, d1.y)), inv);
    rt_vec3 dpdv = rt_scale(rt_sub(rt_scale(e2, d1.x), rt_scale(e1, d2.x)), inv);
    *t = dpdu;
    *w = rt_dot(rt_cross(n, dpdu), dpdv) > 0.0f ? -1.0f : 1.0f;
}

static rt_vec3 orthonormal_tangent(rt_vec3 n, rt_vec3 t)
{
    rt_vec3 o = rt_sub(t, rt_scale(n, rt_dot(n, t)));
    float l2 = rt_length2(o);
    if (!(l2 > 1e-24f) || !isfinite(l2)) {
        rt_vec3 b;
        rt_onb(n, &o, &b);
        return o;
    }
    return rt_scale(o, 1.0f / sqrtf(l2));
}

/* One tangent-space normal-map component from a texel value c in [0, 1].
 * Float and procedural textures use glTF's n = 2c - 1. 8-bit images use the
 * signed-normalised reading centred on code 128 (128 -> 0, 255 -> +1,
 * 0 -> -1, linear on each side; differs from 2c - 1 by at most 1/255), so
 * the conventional flat colour (128, 128, 255) is exactly (0, 0, 1). Values
 * within 1e-4 of 0 (float rounding in bilinear weights) are 0. */
static inline float normal_map_component(float c, bool unorm8)
{
    float x;
    if (unorm8) {
        float code = c * 255.0f;
        x = code >= 128.0f ? (code - 128.0f) * (1.0f / 127.0f) : (code - 128.0f) * (1.0f / 128.0f);
    } else {
        x = 2.0f * c - 1.0f;
    }
    return fabsf(x) < 1e-4f ? 0.0f : x;
}

static rt_vec2 slot_uv(const rt_surface *sf, const rt_texture_slot *slot)
{
    return rt_texture_slot_uv(slot, slot->texcoord == 1 ? sf->uv1 : sf->uv0);
}

#if defined(__GNUC__)
#define SURFACE_INLINE static inline __attribute__((always_inline)) /* one copy per caller, `frame` folded */
#else
#define SURFACE_INLINE static inline
#endif

/* A secondary ray's origin leaving p on the side of unit normal `side`. */
static inline rt_vec3 spawn_origin(const rt_trace_ctx *ctx, rt_vec3 p, rt_vec3 side)
{
    rt_vec3 o = rt_offset_ray_origin(p, side, ctx->state->scale);
    float extra = ctx->state->settings->ray_offset;
    return extra > 0.0f ? rt_madd(o, side, extra) : o;
}

/* What a caller needs of the record: everything (rt_surface_at), the
 * frame only where the material reads it (rt_surface_at_shading), or what
 * emission reads (rt_surface_at_emitter: no shading normal, normal map,
 * tangent frame or vertex colour). */
typedef enum surface_need { NEED_ALL, NEED_SHADING, NEED_EMISSION } surface_need;

/* A vertex's position, normal and tangent in the world: as stored, or
 * (an instance's object, xf) moved by the instance the way the glTF loader
 * flattens a node (gltf_flatten.c): positions by to_world, normals by the
 * normal matrix and renormalised, tangents by to_world and renormalised,
 * their sign w flipped by a mirroring transform. */
SURFACE_INLINE rt_vec3 vertex_position(const rt_vertices *vx, const rt_instance *xf, uint32_t v)
{
    return xf ? rt_mat4_point(&xf->to_world, vx->position[v]) : vx->position[v];
}
SURFACE_INLINE rt_vec3 vertex_normal(const rt_vertices *vx, const rt_instance *xf, uint32_t v)
{
    if (!xf)
        return vx->normal[v];
    rt_vec3 n = vx->normal[v];
    return rt_finite3(n) && rt_length2(n) > 0.0f ? rt_normalize(rt_mat4_vector(&xf->normal, n)) : n;
}
SURFACE_INLINE rt_vec4 vertex_tangent(const rt_vertices *vx, const rt_instance *xf, uint32_t v)
{
    if (!xf)
        return vx->tangent[v];
    rt_vec4 q = vx->tangent[v];
    rt_vec3 t = rt_mat4_vector(&xf->to_world, rt_v3(q.x, q.y, q.z));
    t = rt_finite3(t) && rt_length2(t) > 0.0f ? rt_normalize(t) : rt_v3s(0);
    return rt_v4(t.x, t.y, t.z, xf->mirror ? -q.w : q.w);
}

/* The triangle part of surface_at: point, geometric and interpolated
 * normals, UVs, vertex colour and the tangent (t, w) where `frame`. *t and
 * *w come in as surface_at's defaults and are left alone without a frame.
 * xf: the instance the triangle was hit through (NULL: world geometry);
 * a mirroring one reverses the winding as flattening does (corners 1 and
 * 2 swapped, and with them the barycentrics). */
SURFACE_INLINE void triangle_at(const rt_scene *s, const rt_instance *xf, uint32_t i, const rt_hit *hit,
                               rt_surface *sf, bool uv, bool frame, bool emission_only, rt_vec3 *ng_out,
                               rt_vec3 *n_out, rt_vec3 *t_io, float *w_io)
{
    rt_vec3 ng, n, t = *t_io;
    float w = *w_io;
    const uint32_t *idx = &s->triangles.index[3 * (size_t)i];
    float bu = hit->u, bv = hit->v;
    uint32_t swapped[3];
    if (xf && xf->mirror) {
        swapped[0] = idx[0], swapped[1] = idx[2], swapped[2] = idx[1];
        idx = swapped;
        bu = hit->v, bv = hit->u;
    }
    const rt_vertices *vx = &s->vertices;
    uint8_t flags = s->triangles.flags[i];
    rt_vec3 a = vertex_position(vx, xf, idx[0]), b = vertex_position(vx, xf, idx[1]),
            c = vertex_position(vx, xf, idx[2]);
    rt_vec3 e1 = rt_sub(b, a), e2 = rt_sub(c, a);
    float bw = 1.0f - bu - bv;
    sf->p = rt_add(rt_add(rt_scale(a, bw), rt_scale(b, bu)), rt_scale(c, bv));
    ng = rt_normalize(rt_cross(e1, e2));
    if (flags & RT_TRI_SMOOTH) {
        /* vertex normals define the outside: turn a triangle wound the
         * other way to agree with them (decided per triangle, so the
         * side never changes across its face) */
        rt_vec3 n0 = vertex_normal(vx, xf, idx[0]), n1 = vertex_normal(vx, xf, idx[1]),
                n2 = vertex_normal(vx, xf, idx[2]);
        rt_vec3 nsum = rt_add(rt_add(n0, n1), n2);
        if (rt_dot(nsum, ng) < 0.0f)
            ng = rt_neg(ng);
    }
    n = ng;
    if ((flags & RT_TRI_SMOOTH) && !emission_only) {
        rt_vec3 ni = rt_add(rt_add(rt_scale(vertex_normal(vx, xf, idx[0]), bw), rt_scale(vertex_normal(vx, xf, idx[1]), bu)),
                            rt_scale(vertex_normal(vx, xf, idx[2]), bv));
        if (rt_length2(ni) > 1e-20f && rt_finite3(ni))
            n = rt_normalize(ni);
    }
    rt_vec2 t0 = rt_v2(0, 0), t1 = rt_v2(1, 0), t2 = rt_v2(0, 1);
    if (uv || frame) { /* (a frame from the UVs reads them too) */
        if (flags & RT_TRI_UV) {
            t0 = vx->uv0[idx[0]], t1 = vx->uv0[idx[1]], t2 = vx->uv0[idx[2]];
            sf->uv0 = rt_v2(t0.x * bw + t1.x * bu + t2.x * bv, t0.y * bw + t1.y * bu + t2.y * bv);
        } else {
            sf->uv0 = rt_v2(bu, bv);
        }
        if (vx->uv1) {
            rt_vec2 s0 = vx->uv1[idx[0]], s1 = vx->uv1[idx[1]], s2 = vx->uv1[idx[2]];
            sf->uv1 = rt_v2(s0.x * bw + s1.x * bu + s2.x * bv, s0.y * bw + s1.y * bu + s2.y * bv);
        } else {
            sf->uv1 = sf->uv0;
        }
    } else {
        sf->uv0 = sf->uv1 = rt_v2(0, 0); /* no texture reads them */
    }
    RT_DCHECK(!(flags & RT_TRI_COLOR) || vx->color);
    RT_DCHECK(!(flags & RT_TRI_TANGENT) || vx->tangent);
    if ((flags & RT_TRI_COLOR) && !emission_only) {
        rt_vec4 c0 = vx->color[idx[0]], c1 = vx->color[idx[1]], c2 = vx->color[idx[2]];
        sf->vertex_color = rt_v4(c0.x * bw + c1.x * bu + c2.x * bv, c0.y * bw + c1.y * bu + c2.y * bv,
                                 c0.z * bw + c1.z * bu + c2.z * bv, c0.w * bw + c1.w * bu + c2.w * bv);
    }
    if (frame && (flags & RT_TRI_TANGENT)) {
        rt_vec4 q0 = vertex_tangent(vx, xf, idx[0]), q1 = vertex_tangent(vx, xf, idx[1]),
                q2 = vertex_tangent(vx, xf, idx[2]);
        t = rt_v3(q0.x * bw + q1.x * bu + q2.x * bv, q0.y * bw + q1.y * bu + q2.y * bv,
                  q0.z * bw + q1.z * bu + q2.z * bv);
        w = q0.w < 0.0f ? -1.0f : 1.0f;
    } else if (frame) {
        tangent_from_uv(e1, e2, rt_v2(t1.x - t0.x, t1.y - t0.y), rt_v2(t2.x - t0.x, t2.y - t0.y), ng, &t, &w);
    }
    *ng_out = ng;
    *n_out = n;
    *t_io = t;
    *w_io = w;
}

/* The record; the tangent frame (t, b) only when `need` is NEED_ALL or the
 * material reads it (else zero). */
SURFACE_INLINE void surface_at(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf,
                              surface_need need)
{
    bool emission_only = need == NEED_EMISSION;
    const rt_scene *s = ctx->state->scene;
    uint32_t i;
    rt_vec3 ng, n, t = rt_v3s(0.0f);
    float w = 1.0f;
    sf->vertex_color = rt_v4(1, 1, 1, 1);
    sf->prim = hit->prim;
    rt_prim_kind kind = rt_prim_kind_of(s, hit->prim, &i);
    sf->material = kind == RT_PRIM_TRIANGLE ? s->triangles.material[i]
                   : kind == RT_PRIM_SPHERE ? s->spheres.material[i]
                                            : s->quads.material[i];
    RT_DCHECK(sf->material < s->material_count); /* rt_scene_validate */
    const rt_material *m = &s->materials[sf->material];
    uint8_t needs = ctx->state->material_needs[sf->material];
    bool frame = need == NEED_ALL || (!emission_only && (needs & RT_MATERIAL_FRAME));
    bool uv = need == NEED_ALL || (needs & RT_MATERIAL_TEXTURED);
    switch (kind) {
    case RT_PRIM_TRIANGLE: {
        if (hit->inst == 0) /* world geometry */
            triangle_at(s, NULL, i, hit, sf, uv, frame, emission_only, &ng, &n, &t, &w);
        else
            triangle_at(s, &s->instances[hit->inst - 1], i, hit, sf, uv, frame, emission_only, &ng, &n, &t, &w);
        break;
    }
    case RT_PRIM_SPHERE: {
        const rt_spheres *sp = &s->spheres;
        rt_vec3 c = rt_v3(sp->cx[i], sp->cy[i], sp->cz[i]);
        float r = sp->radius[i];
        rt_vec3 d = rt_normalize(rt_sub(rt_madd(ray->org, ray->dir, hit->t), c));
        sf->p = rt_madd(c, d, fabsf(r));
        ng = r < 0.0f ? rt_neg(d) : d;
        n = ng;
        sf->uv0 = sf->uv1 = uv ? rt_latlong_from_dir(d) : rt_v2(0, 0);
        t = rt_v3(d.z, 0.0f, -d.x); /* dP/du; zero at the poles, fixed by orthonormal_tangent */
        break;
    }
    case RT_PRIM_QUAD:
    default: {
        const rt_quads *q = &s->quads;
        rt_vec3 p = rt_v3(q->px[i], q->py[i], q->pz[i]);
        rt_vec3 eu = rt_v3(q->ux[i], q->uy[i], q->uz[i]), ev = rt_v3(q->vx[i], q->vy[i], q->vz[i]);
        sf->p = rt_add(p, rt_add(rt_scale(eu, hit->u), rt_scale(ev, hit->v)));
        ng = rt_normalize(rt_cross(eu, ev));
        n = ng;
        /* image top at the far end of edge v: uv = (s, 1 - t) */
        sf->uv0 = sf->uv1 = rt_v2(hit->u, 1.0f - hit->v);
        t = eu;
        break;
    }
    }
    sf->wo = rt_neg(rt_normalize(ray->dir));
    sf->front = rt_dot(ng, ray->dir) < 0.0f;

    rt_vec3 tt = rt_v3s(0.0f), bb = rt_v3s(0.0f);
    if (frame) {
        tt = orthonormal_tangent(n, t);
        bb = rt_scale(rt_cross(n, tt), w);
    }
    rt_vec3 n_unmapped = n;
    /* normal map, in the frame of the front face */
    if (m->normal_tex.texture != RT_NONE && !emission_only) {
        RT_DCHECK(m->normal_tex.texture < s->texture_count);
        const rt_texture *tx = &s->textures[m->normal_tex.texture];
        bool unorm8 = tx->kind == RT_TEX_IMAGE && s->images[tx->image].rgba8;
        rt_vec4 c = rt_texture_sample(s, m->normal_tex.texture, slot_uv(sf, &m->normal_tex), false);
        float x = normal_map_component(c.x, unorm8) * m->normal_scale;
        float y = normal_map_component(c.y, unorm8) * m->normal_scale;
        float z = normal_map_component(c.z, unorm8);
        rt_vec3 nm = rt_add(rt_add(rt_scale(tt, x), rt_scale(bb, y)), rt_scale(n, z));
        /* a flat texel (x = y = 0) leaves the surface exactly as unmapped */
        bool flat = x == 0.0f && y == 0.0f && z > 0.0f;
        if (!flat && rt_length2(nm) > 1e-20f && rt_finite3(nm)) {
            n = rt_normalize(nm);
            tt = orthonormal_tangent(n, tt);
            bb = rt_scale(rt_cross(n, tt), w);
        }
    }
    if (!sf->front) {
        ng = rt_neg(ng);
        n = rt_neg(n);
        n_unmapped = rt_neg(n_unmapped);
        tt = rt_neg(tt);
        bb = rt_neg(bb);
    }
    sf->ng = ng;
    sf->n = n;
    sf->n_unmapped = n_unmapped;
    sf->t = tt;
    sf->b = bb;
    sf->p_out_set = need == NEED_SHADING;
    if (sf->p_out_set)
        sf->p_out = spawn_origin(ctx, sf->p, ng);
}

void rt_surface_at(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf)
{
    surface_at(ctx, ray, hit, sf, NEED_ALL);
}

void rt_surface_at_shading(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf)
{
    surface_at(ctx, ray, hit, sf, NEED_SHADING);
}

void rt_surface_at_emitter(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf)
{
    surface_at(ctx, ray, hit, sf, NEED_EMISSION);
}

rt_vec4 rt_surface_base_color(const rt_trace_ctx *ctx, const rt_surface *sf)
{
    const rt_scene *s = ctx->state->scene;
    RT_DCHECK(sf->material < s->material_count);
    const rt_material *m = &s->materials[sf->material];
    rt_vec4 c = rt_v4(m->color.x, m->color.y, m->color.z, m->alpha);
    if (m->base_color_tex.texture != RT_NONE) {
        rt_vec4 tx = rt_texture_sample(s, m->base_color_tex.texture, slot_uv(sf, &m->base_color_tex), true);
        c = rt_v4(c.x * tx.x, c.y * tx.y, c.z * tx.z, c.w * tx.w);
    }
    rt_vec4 v = sf->vertex_color;
    return rt_v4(c.x * v.x, c.y * v.y, c.z * v.z, c.w * v.w);
}

rt_vec3 rt_surface_emission(const rt_trace_ctx *ctx, const rt_surface *sf)
{
    const rt_scene *s = ctx->state->scene;
    RT_DCHECK(sf->material < s->material_count);
    const rt_material *m = &s->materials[sf->material];
    if (!(m->emission.x > 0.0f || m->emission.y > 0.0f || m->emission.z > 0.0f))
        return rt_v3s(0);
    if (!sf->front && !m->double_sided)
        return rt_v3s(0);
    rt_vec3 e = rt_scale(m->emission, m->emission_strength);
    if (m->emissive_tex.texture != RT_NONE) {
        rt_vec4 tx = rt_texture_sample(s, m->emissive_tex.texture, slot_uv(sf, &m->emissive_tex), true);
        e = rt_mul(e, rt_v3(tx.x, tx.y, tx.z));
    }
    return e;
}

bool rt_surface_cut_away(const rt_trace_ctx *ctx, const rt_surface *sf, float *coverage)
{
    *coverage = 1.0f;
    const rt_scene *s = ctx->state->scene;
    RT_DCHECK(sf->material < s->material_count);
    const rt_material *m = &s->materials[sf->material];
    if (m->alpha_mode == RT_ALPHA_OPAQUE)
        return false;
    float a = rt_surface_base_color(ctx, sf).w;
    if (m->alpha_mode == RT_ALPHA_MASK)
        return a < m->alpha_cutoff;
    *coverage = rt_clampf(a, 0.0f, 1.0f);
    return a <= 0.0f;
}

rt_vec3 rt_surface_spawn(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 d)
{
    bool out = rt_dot(d, sf->ng) >= 0.0f;
    if (out && sf->p_out_set)
        return sf->p_out; /* computed once for the record */
    return spawn_origin(ctx, sf->p, out ? sf->ng : rt_neg(sf->ng));
}
rt_surface_walk rt_trace_surface(const rt_trace_ctx *ctx, rt_ray *r, int *layers_left, rt_rng *blend_rng,
                                 rt_surface *sf, float *coverage)
{
    while (*layers_left > 0) {
        (*layers_left)--;
        rt_hit hit;
        if (!rt_trace(ctx, r, &hit))
            return RT_WALK_MISS;
        rt_surface_at(ctx, r, &hit, sf);
        bool cut = rt_surface_cut_away(ctx, sf, coverage);
        if (!cut && blend_rng && *coverage < 1.0f && rt_rng_float(blend_rng) >= *coverage)
            cut = true; /* stochastic alpha blending */
        r->tmin = hit.t;
        if (!cut)
            return RT_WALK_SURFACE;
    }
    return RT_WALK_TOO_DEEP;
}
