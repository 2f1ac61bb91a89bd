/* emitter_sample.c - next-event estimation towards the light table's
 * emissive primitives (rt/render/emitter_sample.h): the surface path
 * tracer's and the volumetric path tracer's one way to pick an emitter by
 * power, draw a point on it (uniform in the solid angle of a triangle seen
 * large, Arvo 1995, "Stratified sampling of spherical triangles"; uniform
 * by area otherwise, pbrt-v3 14.2) and say the density of that choice.
 */
#include "rt/render/emitter_sample.h"

#include <math.h>

#include "rt/render/sampler.h"

/* Barycentric weights (of vertices 1 and 2) of where the ray from p along
 * w meets the plane of triangle (a, b, c), clamped onto the triangle; false
 * when w runs parallel to it. */
static bool tri_barycentric(rt_vec3 a, rt_vec3 b, rt_vec3 c, rt_vec3 p, rt_vec3 w, float *u, float *v)
{
    rt_vec3 e1 = rt_sub(b, a), e2 = rt_sub(c, a), pv = rt_cross(w, e2);
    float det = rt_dot(e1, pv);
    if (!(fabsf(det) > 0.0f))
        return false;
    rt_vec3 tv = rt_sub(p, a), qv = rt_cross(tv, e1);
    float bu = rt_clampf(rt_dot(tv, pv) / det, 0.0f, 1.0f), bv = rt_clampf(rt_dot(w, qv) / det, 0.0f, 1.0f);
    if (bu + bv > 1.0f) {
        float k = 1.0f / (bu + bv);
        bu *= k;
        bv *= k;
    }
    *u = bu;
    *v = bv;
    return isfinite(bu) && isfinite(bv);
}

bool rt_emitter_sample_at(const rt_trace_ctx *ctx, rt_vec3 p, float ul, rt_vec2 u, rt_emitter_sample *es)
{
    const rt_scene *s = ctx->state->scene;
    const rt_light_table *t = ctx->state->light_table;
    size_t k = rt_light_table_pick(t, ul);
    uint32_t prim = t->prim[k], local;
    rt_hit h;
    h.prim = prim;
    h.inst = 0; /* emitters are world geometry (the light table holds no object's triangles) */
    rt_vec3 q;
    float solid = 0.0f; /* the solid angle when sampled by it, else 0 (by area) */
    switch (rt_prim_kind_of(s, prim, &local)) {
    case RT_PRIM_TRIANGLE: {
        rt_vec3 a = rt_tri_vertex(s, local, 0), bb = rt_tri_vertex(s, local, 1), c = rt_tri_vertex(s, local, 2);
        rt_sph_tri st;
        if (rt_tri_solid(a, bb, c, t->prim_sel[prim] / t->prim_pdf[prim], p, &st)) {
            solid = st.S;
            if (!tri_barycentric(a, bb, c, p, rt_sph_tri_sample(&st, u), &h.u, &h.v))
                return false;
        } else {
            float su = sqrtf(u.x);
            h.u = u.y * su;        /* weight of vertex 1 */
            h.v = 1.0f - su;       /* weight of vertex 2 */
        }
        q = rt_add(rt_add(rt_scale(a, 1.0f - h.u - h.v), rt_scale(bb, h.u)), rt_scale(c, h.v));
        break;
    }
    case RT_PRIM_SPHERE: {
        float z = 1.0f - 2.0f * u.x, r = sqrtf(rt_fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * RT_PI * u.y;
        const rt_spheres *sp = &s->spheres;
        float sn, cs;
        rt_sincosf(phi, &sn, &cs);
        q = rt_madd(rt_v3(sp->cx[local], sp->cy[local], sp->cz[local]), rt_v3(r * cs, r * sn, z),
                    fabsf(sp->radius[local]));
        h.u = h.v = 0.0f;
        break;
    }
    case RT_PRIM_QUAD:
    default: {
        const rt_quads *qd = &s->quads;
        h.u = u.x;
        h.v = u.y;
        q = rt_add(rt_v3(qd->px[local], qd->py[local], qd->pz[local]),
                   rt_add(rt_scale(rt_v3(qd->ux[local], qd->uy[local], qd->uz[local]), u.x),
                          rt_scale(rt_v3(qd->vx[local], qd->vy[local], qd->vz[local]), u.y)));
        break;
    }
    }
    rt_vec3 d = rt_sub(q, p);
    float d2 = rt_length2(d);
    if (!(d2 > 0.0f && isfinite(d2)))
        return false;
    float dist = sqrtf(d2);
    rt_vec3 wdir = rt_scale(d, 1.0f / dist);
    h.t = dist;
    rt_ray r = rt_ray_make(p, wdir, 0.0f, INFINITY);
    rt_surface se;
    rt_surface_at_emitter(ctx, &r, &h, &se); /* its ng and emission */
    float cos_l = fabsf(rt_dot(se.ng, wdir));
    es->Le = rt_surface_emission(ctx, &se);
    es->pdf = solid > 0.0f ? t->prim_sel[prim] / solid : t->prim_pdf[prim] * d2 / cos_l;
    es->wi = wdir;
    es->dist = dist;
    es->prim = prim;
    return rt_max3(es->Le) > 0.0f && cos_l > 0.0f && es->pdf > 0.0f && isfinite(es->pdf);
}

float rt_emitter_pdf(const rt_trace_ctx *ctx, uint32_t prim, rt_vec3 from, rt_vec3 dir, float d2, rt_vec3 ng)
{
    const rt_scene *s = ctx->state->scene;
    const rt_light_table *t = ctx->state->light_table;
    if (!(t && prim < t->prim_count && t->prim_pdf[prim] > 0.0f))
        return 0.0f;
    rt_sph_tri st;
    float cos_l = fabsf(rt_dot(ng, dir));
    float pa = t->prim_pdf[prim];
    uint32_t ti;
    if (rt_prim_kind_of(s, prim, &ti) == RT_PRIM_TRIANGLE &&
        rt_tri_solid(rt_tri_vertex(s, ti, 0), rt_tri_vertex(s, ti, 1), rt_tri_vertex(s, ti, 2),
                     t->prim_sel[prim] / pa, from, &st))
        return t->prim_sel[prim] / st.S;
    return cos_l > 0.0f ? pa * d2 / cos_l : 0.0f;
}
