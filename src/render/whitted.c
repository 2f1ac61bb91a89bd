/* whitted.c - the `whitted` integrator: classic recursive ray tracing.
 *
 * Model (Whitted 1980, "An Improved Illumination Model for Shaded Display",
 * CACM 23(6), with Phong 1975 local shading and Hall's adaptive tree
 * pruning), specified exactly in docs/shading.md. At a hit with base colour
 * B (material colour x texture x vertex colour), mirror reflectivity R,
 * transmission T, transmission colour Tc and Fresnel reflectance F:
 *
 *   L = Le + (1-R)(1-T) [ ka B A + kd B / pi * sum_l E_l (n.l) ]
 *          + ks / pi * sum_l E_l (r_l.v)^shininess
 *          + (R + (1-R) T F) L(reflected) + (1-R) T (1-F) Tc L(refracted)
 *
 * E_l is light l's irradiance on a surface facing it (point I/d^2,
 * directional E, area lights averaged over shadow_samples stratified
 * points), times the shadow transmittance (rt_shadow_transmittance: clear,
 * blocked, or filtered by transmissive surfaces, the old renderer's "cheap
 * caustics"). A is the ambient radiance (ctx->state->ambient). The 1/pi makes
 * kd = 1, ka = ks = 0 exactly the `direct` integrator's Lambert.
 *
 * Diffuse bounces: while level < diffuse_bounces the ambient term ka B A is
 * replaced by kd B times the mean radiance of diffuse_rays cosine-
 * distributed rays (correlated multi-jittered over the hemisphere), each
 * traced at level + 1; the last level uses the ambient term.
 *
 * Refraction: exact unpolarised Fresnel (rt_fresnel_dielectric), Snell's
 * law, total internal reflection. Rays carry a stack of the media they are
 * in (rt_medium_stack) under the path tracer's rules (medium.c: Schmidt and
 * Budge 2002, "Simple Nested Dielectrics in Ray Traced Images", JGT 7(1)),
 * every transmissive material being a medium: the current medium is the
 * highest `priority` one, a surface inside a higher-priority medium is a
 * false intersection the ray passes straight through, and a true one
 * refracts between the two media's indices (a glass ball in water: 1.33 ->
 * 1.5, not 1 -> 1.5; outside everything, the object's exterior_ior).
 *
 * glTF extensions (docs/gltf.md, "Material mapping"): a clearcoat c adds
 * a mirror of weight c F_coat(n.v) (Schlick, F0 = 0.04) over the rest,
 * i.e. R becomes R + (1 - R) c F_coat; KHR_materials_specular scales ks at
 * load (the glTF loader and the scene parser's specular_factor and
 * specular_color keys alike); sheen, anisotropy, iridescence and diffuse transmission are
 * path-tracer effects this model leaves out.
 *
 * Recursion: reflection/refraction up to settings.max_bounce events; a
 * branch whose accumulated weight is below 1/1024 is not traced (Hall and
 * Greenberg 1983). Every value stays finite: degenerate normals, grazing
 * angles and zero-length directions all fall back to safe choices.
 */
#include "rt/render/whitted.h"

#include <string.h>

#include "rt/render/bsdf_clearcoat.h"
#include "rt/render/environment.h"
#include "rt/render/light.h"

#define MIN_WEIGHT (1.0f / 1024.0f)
#define MAX_NESTING 1024 /* recursion guard: max_bounce <= 256 plus index-matched crossings */

/* ------------------------------------------------------------ optics */

rt_fresnel rt_fresnel_dielectric(float cos_i, float n1, float n2)
{
    rt_fresnel f;
    memset(&f, 0, sizeof f);
    double ci = cos_i > 1.0f ? 1.0 : (cos_i > 0.0f ? (double)cos_i : 0.0);
    double a = n1, b = n2;
    if (!(a > 0.0) || !(b > 0.0) || !isfinite(a) || !isfinite(b)) {
        f.rs = f.rp = f.r = 1.0f;
        f.tir = true;
        return f;
    }
    if (a == b) { /* no interface: straight through */
        f.ts = f.tp = f.t = 1.0f;
        f.cos_t = (float)ci;
        return f;
    }
    double eta = a / b;
    double sin2_t = eta * eta * (1.0 - ci * ci);
    if (sin2_t >= 1.0 || ci <= 0.0) { /* total internal reflection, or grazing */
        f.rs = f.rp = f.r = 1.0f;
        f.tir = sin2_t >= 1.0;
        return f;
    }
    double ct = sqrt(1.0 - sin2_t);
    double rs = (a * ci - b * ct) / (a * ci + b * ct);
    double rp = (b * ci - a * ct) / (b * ci + a * ct);
    double ts = 2.0 * a * ci / (a * ci + b * ct);
    double tp = 2.0 * a * ci / (b * ci + a * ct);
    double k = (b * ct) / (a * ci); /* ratio of beam cross-sections times impedances */
    f.rs = (float)(rs * rs);
    f.rp = (float)(rp * rp);
    f.ts = (float)(k * ts * ts);
    f.tp = (float)(k * tp * tp);
    f.r = (float)(0.5 * (rs * rs + rp * rp));
    f.t = (float)(0.5 * k * (ts * ts + tp * tp));
    f.cos_t = (float)ct;
    return f;
}

bool rt_refract(rt_vec3 d, rt_vec3 n, float n1, float n2, rt_vec3 *t)
{
    if (n1 == n2) {
        *t = d;
        return true;
    }
    float eta = n1 / n2;
    float ci = -rt_dot(d, n);
    float sin2_t = eta * eta * fmaxf(0.0f, 1.0f - ci * ci);
    if (!(sin2_t < 1.0f))
        return false;
    float ct = sqrtf(1.0f - sin2_t);
    *t = rt_normalize(rt_add(rt_scale(d, eta), rt_scale(n, eta * ci - ct)));
    return rt_finite3(*t);
}

float rt_medium_ior(const rt_scene *s, const rt_medium_stack *m)
{
    uint32_t mat = m && m->depth > 0 ? rt_medium_current(m, s->materials) : RT_NONE;
    RT_DCHECK(mat == RT_NONE || mat < s->material_count);
    return mat == RT_NONE ? 1.0f : s->materials[mat].ior;
}

/* whitted's media: every transmissive surface (the path tracer's are the
 * bsdf dielectric ones, which the parser makes transmissive) */
static bool is_medium(const rt_material *m) { return m->transmission > 0.0f; }

/* ------------------------------------------------------------ integrator */

typedef struct wctx {
    const rt_trace_ctx *ctx;
    rt_rng *rng;
    int max_bounce, diffuse_levels, diffuse_rays, shadow_samples;
    int nesting; /* current recursion depth of trace(), capped at MAX_NESTING */
} wctx;

static rt_vec3 trace(wctx *w, rt_ray r, const rt_medium_stack *med, int depth, int level, float weight,
                     bool diffuse_ray);

/* Sum over lights of E * (n.l) into *D and E * (r.v)^shininess into *S. */
static void direct_phong(wctx *w, const rt_surface *sf, int area_samples, float shininess, bool want_spec,
                         rt_vec3 *D, rt_vec3 *S)
{
    const rt_trace_ctx *ctx = w->ctx;
    const rt_scene *s = ctx->state->scene;
    rt_vec3 dsum = rt_v3s(0), ssum = rt_v3s(0);
    uint32_t pattern = rt_rng_u32(w->rng);
    for (size_t i = 0; i < s->light_count; i++) {
        const rt_light *l = &s->lights[i];
        int n = l->kind == RT_LIGHT_AREA ? area_samples : 1;
        rt_vec3 dacc = rt_v3s(0), sacc = rt_v3s(0);
        for (int k = 0; k < n; k++) {
            rt_vec2 u = n > 1 ? rt_cmj_sample((uint32_t)k, (uint32_t)n, pattern + (uint32_t)i)
                              : rt_v2(rt_rng_float(w->rng), rt_rng_float(w->rng));
            rt_light_sample ls;
            if (!rt_light_sample_at(ctx, l, sf->p, u, &ls))
                continue;
            float cos_n = rt_dot(sf->n, ls.wi);
            if (cos_n <= 0.0f || rt_dot(sf->ng, ls.wi) <= 0.0f)
                continue;
            rt_vec3 tr = rt_shadow_transmittance(ctx, sf, ls.wi, ls.dist);
            if (rt_max3(tr) <= 0.0f)
                continue;
            rt_vec3 e = rt_mul(ls.li, tr);
            dacc = rt_add(dacc, rt_scale(e, cos_n));
            if (want_spec) {
                rt_vec3 refl = rt_sub(rt_scale(sf->n, 2.0f * cos_n), ls.wi);
                float rv = rt_dot(refl, sf->wo);
                if (rv > 0.0f) {
                    float p = powf(fminf(rv, 1.0f), shininess);
                    if (p > 0.0f && isfinite(p))
                        sacc = rt_add(sacc, rt_scale(e, p));
                }
            }
        }
        float inv = 1.0f / (float)n;
        dsum = rt_add(dsum, rt_scale(dacc, inv));
        ssum = rt_add(ssum, rt_scale(sacc, inv));
    }
    *D = dsum;
    *S = ssum;
}

/* Mean radiance of diffuse_rays cosine-distributed rays about sf->n. */
static rt_vec3 gather_diffuse(wctx *w, const rt_surface *sf, const rt_medium_stack *med, int depth, int level,
                              float weight)
{
    int n = w->diffuse_rays;
    uint32_t pattern = rt_rng_u32(w->rng);
    rt_vec3 sum = rt_v3s(0);
    for (int k = 0; k < n; k++) {
        rt_vec3 h = rt_sample_cosine_hemisphere(rt_cmj_sample((uint32_t)k, (uint32_t)n, pattern));
        rt_vec3 d = rt_add(rt_add(rt_scale(sf->t, h.x), rt_scale(sf->b, h.y)), rt_scale(sf->n, h.z));
        if (!(rt_dot(d, sf->ng) > 0.0f) || !rt_finite3(d))
            continue; /* below the geometric surface: it sees the surface itself */
        d = rt_normalize(d);
        rt_ray r = rt_ray_make(rt_surface_spawn(w->ctx, sf, d), d, 0.0f, INFINITY);
        sum = rt_add(sum, trace(w, r, med, depth, level + 1, weight, true));
    }
    return rt_scale(sum, 1.0f / (float)n);
}

/* Radiance leaving a (not cut-away) surface towards sf->wo. */
static rt_vec3 shade(wctx *w, const rt_surface *sf, const rt_medium_stack *med, int depth, int level,
                     float weight, bool diffuse_ray)
{
    const rt_trace_ctx *ctx = w->ctx;
    const rt_scene *s = ctx->state->scene;
    RT_DCHECK(sf->material < s->material_count); /* rt_scene_validate */
    const rt_material *m = &s->materials[sf->material];
    if (is_medium(m) && rt_medium_stack_false_hit(med, s->materials, sf->material, sf->front)) {
        /* an interface inside a higher-priority medium: straight on */
        rt_medium_stack inner = *med;
        rt_medium_stack_cross(&inner, sf->material, sf->front);
        rt_vec3 d = rt_neg(sf->wo);
        rt_ray r = rt_ray_make(rt_surface_spawn(ctx, sf, d), d, 0.0f, INFINITY);
        return trace(w, r, &inner, depth, level, weight, diffuse_ray);
    }
    rt_vec4 b4 = rt_surface_base_color(ctx, sf);
    rt_vec3 base = rt_v3(b4.x, b4.y, b4.z);
    /* after a diffuse bounce, a sampled light's own quad is not seen: its
     * light is already counted by direct sampling (and a mirror or glass
     * chain to it would be a caustic, which this model leaves out) */
    rt_vec3 L = rt_surface_emission(ctx, sf);
    if (diffuse_ray && rt_max3(L) > 0.0f && rt_area_light_of_prim(s, NULL, sf->prim) != RT_NONE)
        L = rt_v3s(0);
    if (m->unlit)
        return rt_add(L, base);

    float R = rt_clampf(m->reflectivity, 0.0f, 1.0f), T = rt_clampf(m->transmission, 0.0f, 1.0f);
    if (m->clearcoat > 0.0f) /* KHR_materials_clearcoat: a mirror of the coat's Fresnel over the rest */
        R += (1.0f - R) * rt_clampf(m->clearcoat, 0.0f, 1.0f) * rt_clearcoat_fresnel(rt_dot(sf->wo, sf->n));
    float w_local = (1.0f - R) * (1.0f - T);

    /* local Phong: ambient (or gathered indirect), diffuse, specular */
    bool want_diffuse = w_local > 0.0f && m->diffuse > 0.0f && rt_max3(base) > 0.0f;
    bool want_spec = m->specular > 0.0f;
    if (want_diffuse || want_spec) {
        int area_samples = level > 0 ? 1 : w->shadow_samples;
        rt_vec3 D, S;
        direct_phong(w, sf, area_samples, m->shininess, want_spec, &D, &S);
        if (want_diffuse)
            L = rt_add(L, rt_scale(rt_mul(base, D), w_local * m->diffuse * RT_INV_PI));
        if (want_spec)
            L = rt_add(L, rt_scale(S, m->specular * RT_INV_PI));
    }
    if (w_local > 0.0f) {
        float kd_w = weight * w_local * m->diffuse * rt_max3(base);
        if (level < w->diffuse_levels && m->diffuse > 0.0f && kd_w >= MIN_WEIGHT) {
            rt_vec3 ind = gather_diffuse(w, sf, med, depth, level, kd_w);
            L = rt_add(L, rt_scale(rt_mul(base, ind), w_local * m->diffuse));
        } else if (m->ambient > 0.0f) {
            L = rt_add(L, rt_scale(rt_mul(base, ctx->state->ambient), w_local * m->ambient));
        }
    }

    /* mirror and dielectric */
    bool can_bounce = depth < w->max_bounce;
    if ((R <= 0.0f && T <= 0.0f) || (!can_bounce && T <= 0.0f))
        return L;
    rt_vec3 d = rt_neg(sf->wo);
    rt_vec3 ns = sf->n;
    rt_vec3 rdir = rt_reflect(d, ns);
    bool geometric = false;
    if (!(rt_dot(rdir, sf->ng) > 0.0f)) { /* the shading normal sends it under the surface */
        ns = sf->ng;
        rdir = rt_reflect(d, ns);
        geometric = true;
    }
    float w_refl = R, F = 0.0f;
    bool matched = false; /* equal indices on both sides: no interface, no bounce */
    rt_vec3 w_trans = rt_v3s(0), tdir = d;
    rt_medium_stack inner = *med;
    if (T > 0.0f) {
        /* entering: from the current medium into the material; leaving:
         * from it into the medium beyond (rt/render/medium.h) */
        float beyond = rt_medium_outside_ior(med, s->materials, sf->material, sf->front);
        float n1 = sf->front ? beyond : m->ior, n2 = sf->front ? m->ior : beyond;
        rt_medium_stack_cross(&inner, sf->material, sf->front);
        matched = n1 == n2;
        float cos_i = rt_clampf(rt_dot(sf->wo, ns), 0.0f, 1.0f);
        rt_fresnel fr = rt_fresnel_dielectric(cos_i, n1, n2);
        bool ok = !fr.tir && rt_refract(d, ns, n1, n2, &tdir);
        if (ok && !(rt_dot(tdir, sf->ng) < 0.0f) && !geometric) {
            /* refracted to the wrong side by the shading normal: use the geometric one */
            ns = sf->ng;
            rdir = rt_reflect(d, ns);
            cos_i = rt_clampf(rt_dot(sf->wo, ns), 0.0f, 1.0f);
            fr = rt_fresnel_dielectric(cos_i, n1, n2);
            ok = !fr.tir && rt_refract(d, ns, n1, n2, &tdir);
        }
        if (ok && !(rt_dot(tdir, sf->ng) < 0.0f))
            ok = false;
        F = ok ? rt_clampf(fr.r, 0.0f, 1.0f) : 1.0f;
        w_refl += (1.0f - R) * T * F;
        if (ok)
            w_trans = rt_scale(m->transmission_color, (1.0f - R) * T * (1.0f - F));
    }
    if (can_bounce && w_refl > 0.0f && weight * w_refl >= MIN_WEIGHT) {
        rt_ray r = rt_ray_make(rt_surface_spawn(ctx, sf, rdir), rdir, 0.0f, INFINITY);
        L = rt_add(L, rt_scale(trace(w, r, med, depth + 1, level, weight * w_refl, diffuse_ray), w_refl));
    }
    float wt = rt_max3(w_trans);
    if ((can_bounce || matched) && wt > 0.0f && weight * wt >= MIN_WEIGHT) {
        rt_ray r = rt_ray_make(rt_surface_spawn(ctx, sf, tdir), tdir, 0.0f, INFINITY);
        int next = matched ? depth : depth + 1;
        L = rt_add(L, rt_mul(trace(w, r, &inner, next, level, weight * wt, diffuse_ray), w_trans));
    }
    return L;
}

/* Radiance arriving along r: the nearest surface, stepping through
 * alpha-cut surfaces and mixing alpha-blended ones with what lies behind. */
static rt_vec3 trace(wctx *w, rt_ray r, const rt_medium_stack *med, int depth, int level, float weight,
                     bool diffuse_ray)
{
    const rt_trace_ctx *ctx = w->ctx;
    rt_vec3 result = rt_v3s(0);
    float cov_weight = 1.0f;
    if (w->nesting >= MAX_NESTING)
        return result;
    w->nesting++;
    int layers = 32;
    for (;;) {
        rt_surface sf;
        float coverage;
        rt_surface_walk found = rt_trace_surface(ctx, &r, &layers, NULL, &sf, &coverage);
        if (found == RT_WALK_MISS)
            result = rt_add(result, rt_scale(rt_environment(ctx->state->scene, r.dir), cov_weight));
        if (found != RT_WALK_SURFACE)
            break;
        rt_vec3 L = shade(w, &sf, med, depth, level, weight * cov_weight * coverage, diffuse_ray);
        result = rt_add(result, rt_scale(L, cov_weight * coverage));
        if (coverage >= 1.0f)
            break;
        cov_weight *= 1.0f - coverage; /* and on to what lies behind */
    }
    w->nesting--;
    /* never hand back a non-finite or negative value */
    if (!rt_finite3(result))
        return rt_v3s(0);
    return rt_vmax(result, rt_v3s(0));
}

rt_vec3 rt_radiance_whitted_in(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng, const rt_medium_stack *start)
{
    const rt_settings *st = ctx->state->settings;
    wctx w;
    w.ctx = ctx;
    w.rng = rng;
    w.max_bounce = st->max_bounce > 0 ? st->max_bounce : 0;
    w.diffuse_levels = st->diffuse_bounces > 0 ? st->diffuse_bounces : 0;
    w.diffuse_rays = st->diffuse_rays > 0 ? st->diffuse_rays : 1;
    w.shadow_samples = st->shadow_samples > 0 ? st->shadow_samples : 1;
    w.nesting = 0;
    rt_medium_stack med;
    memset(&med, 0, sizeof med);
    if (start)
        med = *start;
    if (med.depth < 0 || med.depth > RT_MEDIUM_STACK_MAX)
        med.depth = 0;
    rt_ray r = *ray;
    r.dir = rt_normalize(r.dir);
    if (!rt_finite3(r.dir) || !(rt_length2(r.dir) > 0.0f))
        return rt_v3s(0);
    /* t is measured along the unit direction now */
    float len = rt_length(ray->dir);
    r.tmin = ray->tmin * len;
    r.tmax = ray->tmax * len;
    return trace(&w, r, &med, 0, 0, 1.0f, false);
}

rt_vec3 rt_radiance_whitted(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    return rt_radiance_whitted_in(ctx, ray, rng, NULL);
}
