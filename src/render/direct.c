/* direct.c - the `direct` integrator: emission plus direct light at a
 * Lambertian surface, and one ray towards the environment.
 *
 * Direct lighting at a Lambertian surface: for a point light of intensity I
 * at distance r, L = albedo / pi * I * cos(theta) / r^2; for an area light
 * of radiance Le the estimator averages Le * A * cos(theta) * cos(theta_l) /
 * d^2 over stratified points on it (uniform area sampling); directional
 * lights give albedo / pi * E * cos(theta). The environment is sampled with
 * one cosine-distributed ray, whose pdf cancels the cosine and the 1/pi.
 * Alpha-tested surfaces are stepped through; blended ones mixed by alpha.
 */
#include "rt/render/direct.h"

#include "rt/render/environment.h"
#include "rt/render/light.h"

rt_vec3 rt_direct_lambert(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 albedo, rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    rt_vec3 sum = rt_v3s(0);
    if (rt_max3(albedo) <= 0.0f)
        return sum;
    int area_samples = ctx->state->settings->shadow_samples > 0 ? ctx->state->settings->shadow_samples : 1;
    uint32_t pattern = rt_rng_u32(rng);
    for (size_t i = 0; i < s->light_count; i++) {
        const rt_light *l = &s->lights[i];
        int n = l->kind == RT_LIGHT_AREA ? area_samples : 1;
        rt_vec3 acc = rt_v3s(0);
        for (int k = 0; k < n; k++) {
            rt_vec2 u = n > 1 ? rt_cmj_sample((uint32_t)k, (uint32_t)n, pattern + (uint32_t)i)
                              : rt_v2(rt_rng_float(rng), rt_rng_float(rng));
            rt_light_sample ls;
            if (!rt_light_sample_at(ctx, l, sf->p, u, &ls))
                continue;
            float cos_n = rt_dot(sf->n, ls.wi);
            if (cos_n <= 0.0f || rt_dot(sf->ng, ls.wi) <= 0.0f)
                continue; /* light behind the shading or the geometric surface */
            rt_vec3 tr = rt_shadow_transmittance(ctx, sf, ls.wi, ls.dist);
            if (rt_max3(tr) <= 0.0f)
                continue;
            acc = rt_add(acc, rt_scale(rt_mul(ls.li, tr), cos_n));
        }
        sum = rt_add(sum, rt_scale(acc, 1.0f / (float)n));
    }
    sum = rt_scale(rt_mul(sum, albedo), RT_INV_PI);
    /* environment light: one cosine-weighted ray */
    rt_vec3 env_probe = rt_environment(s, sf->n);
    if (s->environment.environment_texture != RT_NONE || rt_max3(env_probe) > 0.0f) {
        rt_vec3 h = rt_sample_cosine_hemisphere(rt_v2(rt_rng_float(rng), rt_rng_float(rng)));
        rt_vec3 d = rt_add(rt_add(rt_scale(sf->t, h.x), rt_scale(sf->b, h.y)), rt_scale(sf->n, h.z));
        if (rt_dot(d, sf->ng) > 0.0f) {
            rt_vec3 tr = rt_shadow_transmittance(ctx, sf, d, INFINITY);
            sum = rt_add(sum, rt_mul(rt_mul(albedo, tr), rt_environment(s, d)));
        }
    }
    return sum;
}

rt_vec3 rt_radiance_direct(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    rt_ray r = *ray;
    rt_vec3 result = rt_v3s(0), weight = rt_v3s(1);
    int layers = 32;
    for (;;) {
        rt_surface sf;
        float coverage;
        rt_surface_walk found = rt_trace_surface(ctx, &r, &layers, NULL, &sf, &coverage);
        if (found == RT_WALK_MISS)
            return rt_add(result, rt_mul(weight, rt_environment(ctx->state->scene, r.dir)));
        if (found == RT_WALK_TOO_DEEP)
            break;
        rt_vec4 base = rt_surface_base_color(ctx, &sf);
        rt_vec3 L = rt_surface_emission(ctx, &sf);
        L = rt_add(L, rt_direct_lambert(ctx, &sf, rt_v3(base.x, base.y, base.z), rng));
        result = rt_add(result, rt_mul(weight, rt_scale(L, coverage)));
        if (coverage >= 1.0f)
            break;
        weight = rt_scale(weight, 1.0f - coverage); /* and on to what lies behind */
    }
    return result;
}
