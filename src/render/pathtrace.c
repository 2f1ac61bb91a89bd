/* pathtrace.c - the `path` integrator: unidirectional path tracing with
 * next-event estimation and multiple importance sampling.
 *
 * Estimator (Kajiya 1986, "The Rendering Equation"; the structure of pbrt
 * v3's PathIntegrator, Pharr, Jakob, Humphreys, ch. 14.5): from the camera,
 * at each surface vertex x with throughput beta,
 *   - emission seen along the ray is added, beta Le, weighted by MIS
 *     against light sampling when the emitter could have been light-sampled
 *     from the previous vertex;
 *   - next-event estimation: every rt_light is sampled once (area lights
 *     uniformly by area, pdf d^2 / (A cos theta_l); point, spot and
 *     directional lights are deltas, weight 1), and, with a light table
 *     (rt/render/light.h), one emissive primitive chosen in proportion to
 *     its power (area x mean emitted radiance) and a uniform point on it,
 *     and one direction of the environment image drawn in proportion to
 *     luminance x sin(theta) (piecewise constant over its
 *     latitude-longitude cells, pbrt-v3 14.2.4);
 *   - the BSDF (rt/render/bsdf.h) samples the next direction, beta *= f cos / pdf.
 * Light and BSDF samples are combined with the power heuristic (Veach 1997,
 * "Robust Monte Carlo Methods for Light Transport Simulation", ch. 9,
 * beta = 2), so a BSDF-sampled ray that hits a light counts with weight
 * pdf_bsdf^2 / (pdf_bsdf^2 + pdf_light^2) and the light sample with the
 * complement. Emitters that are not light-sampled (emissive primitives
 * and environment images without a table, a constant background) count in
 * full on BSDF hits.
 *
 * Russian roulette (Arvo and Kirk 1990) from settings.rr_depth bounces: the
 * path survives with q = min(max channel of beta, 0.95) and beta /= q, which
 * keeps the estimator unbiased; rr_depth 0 is adaptive (pbrt-v4's rule):
 * from the first bounce, whenever the max channel of beta has fallen below
 * 1, the path survives with q = that channel. settings.max_depth caps the scattering
 * events of a path (0 = no cap).
 *
 * Media (rt/render/medium.h): the path carries a stack of the dielectric
 * objects it is inside (Schmidt and Budge 2002's nested dielectrics). Each
 * segment is attenuated by Beer-Lambert absorption exp(-sigma_a d) of the
 * medium it ran through (a glTF KHR_materials_volume object: the segment
 * ending on its back); a false intersection (a lower-priority medium's
 * surface inside a higher-priority one) is passed straight through
 * without counting as a bounce; a true one refracts between the current
 * medium's index and the next one's, and a transmitted sample pushes or
 * pops the stack.
 *
 * Area lights are pure emitters: their visible quad emits from its front
 * and reflects nothing. Shadow rays pass alpha cut-outs and blended
 * surfaces (times 1 - alpha); refractive (transmissive) surfaces block them,
 * light through glass arrives by BSDF sampling. Alpha blending on camera
 * and bounce rays is stochastic: the surface is kept with probability alpha.
 * All random numbers come from the rng handed in, so images do not depend
 * on the thread count; every contribution is checked finite.
 */
#include "rt/render/pathtrace.h"

#include "rt/render/bsdf.h"
#include "rt/render/environment.h"
#include "rt/render/medium.h"

static inline rt_vec3 add_finite(rt_vec3 acc, rt_vec3 c)
{
    return rt_finite3(c) ? rt_add(acc, rt_vmax(c, rt_v3s(0.0f))) : acc;
}

/* One sample of a light from the light table in direction d (world, above
 * the geometric surface) with light-sampling density pdf_l, weighted against
 * BSDF sampling by the power heuristic: f cos vis w / pdf_l times the
 * radiance, which is *Le or, for Le NULL, the environment in d (looked up
 * only when the sample counts). */
static rt_vec3 light_table_term(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_bsdf *b, rt_vec3 wo, rt_vec3 d,
                                const rt_vec3 *Le, float pdf_l, float dist)
{
    rt_vec3 wi = rt_bsdf_to_local(b, d);
    float pdf_b;
    rt_vec3 f = rt_bsdf_eval(b, wo, wi, &pdf_b);
    float w = rt_mis_power(pdf_l, pdf_b);
    if (!(rt_max3(f) > 0.0f && w > 0.0f))
        return rt_v3s(0.0f);
    float vis = rt_shadow_visibility(ctx, sf, d, dist);
    if (!(vis > 0.0f))
        return rt_v3s(0.0f);
    return rt_scale(rt_mul(f, Le ? *Le : rt_environment(ctx->state->scene, d)), wi.z * vis * w / pdf_l);
}

/* Light sampled at one vertex: sum over rt_lights plus one table emitter,
 * each f cos Le / pdf_light times its MIS weight. */
static rt_vec3 next_event(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_bsdf *b, rt_vec3 wo,
                          rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    rt_vec3 sum = rt_v3s(0.0f);
    for (size_t i = 0; i < s->light_count; i++) {
        const rt_light *l = &s->lights[i];
        rt_vec2 u = rt_v2(rt_rng_float(rng), rt_rng_float(rng));
        rt_light_sample ls;
        if (!rt_light_sample_at(ctx, l, sf->p, u, &ls))
            continue;
        if (!(rt_dot(ls.wi, b->ng) > 0.0f))
            continue; /* below the geometric surface */
        rt_vec3 wi = rt_bsdf_to_local(b, ls.wi);
        float pdf_b;
        rt_vec3 f = rt_bsdf_eval(b, wo, wi, &pdf_b);
        if (!(rt_max3(f) > 0.0f))
            continue;
        float w = 1.0f;
        if (l->kind == RT_LIGHT_AREA && l->quad != RT_NONE)
            w = rt_mis_power(rt_area_light_pdf(l, ls.wi, ls.dist), pdf_b);
        if (!(w > 0.0f))
            continue;
        float vis = rt_shadow_visibility(ctx, sf, ls.wi, ls.dist);
        if (!(vis > 0.0f))
            continue;
        sum = add_finite(sum, rt_scale(rt_mul(f, ls.li), wi.z * vis * w));
    }
    const rt_light_table *t = ctx->state->light_table;
    if (t && t->env_w > 0) {
        rt_vec2 u = rt_v2(rt_rng_float(rng), rt_rng_float(rng));
        rt_vec3 d;
        float pdf_l;
        if (rt_light_table_sample_env(t, u, &d, &pdf_l) && rt_dot(d, b->ng) > 0.0f)
            sum = add_finite(sum, light_table_term(ctx, sf, b, wo, d, NULL, pdf_l, INFINITY));
    }
    if (t && t->count) {
        float ul = rt_rng_float(rng);
        rt_vec2 u = rt_v2(rt_rng_float(rng), rt_rng_float(rng));
        size_t k = rt_light_table_pick(t, ul);
        uint32_t prim = t->prim[k], local;
        rt_hit h;
        h.prim = prim;
        rt_vec3 q;
        switch (rt_prim_kind_of(s, prim, &local)) {
        case RT_PRIM_TRIANGLE: {
            float su = sqrtf(u.x);
            h.u = u.y * su;        /* weight of vertex 1 */
            h.v = 1.0f - su;       /* weight of vertex 2 */
            rt_vec3 a = rt_tri_vertex(s, local, 0), bb = rt_tri_vertex(s, local, 1), c = rt_tri_vertex(s, local, 2);
            q = rt_add(rt_add(rt_scale(a, 1.0f - h.u - h.v), rt_scale(bb, h.u)), rt_scale(c, h.v));
            break;
        }
        case RT_PRIM_SPHERE: {
            float z = 1.0f - 2.0f * u.x, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * RT_PI * u.y;
            const rt_spheres *sp = &s->spheres;
            q = rt_madd(rt_v3(sp->cx[local], sp->cy[local], sp->cz[local]),
                        rt_v3(r * cosf(phi), r * sinf(phi), z), fabsf(sp->radius[local]));
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
        rt_vec3 d = rt_sub(q, sf->p);
        float d2 = rt_length2(d);
        if (d2 > 0.0f && isfinite(d2)) {
            float dist = sqrtf(d2);
            rt_vec3 wdir = rt_scale(d, 1.0f / dist);
            h.t = dist;
            rt_ray r = rt_ray_make(sf->p, wdir, 0.0f, INFINITY);
            rt_surface se;
            rt_surface_at(ctx, &r, &h, &se);
            float cos_l = fabsf(rt_dot(se.ng, wdir));
            rt_vec3 Le = rt_surface_emission(ctx, &se);
            float pdf_l = t->prim_pdf[prim] * d2 / cos_l;
            if (rt_max3(Le) > 0.0f && cos_l > 0.0f && pdf_l > 0.0f && isfinite(pdf_l) &&
                rt_dot(wdir, b->ng) > 0.0f)
                sum = add_finite(sum, light_table_term(ctx, sf, b, wo, wdir, &Le, pdf_l, dist));
        }
    }
    return sum;
}

/* ------------------------------------------------------------ integrator */

rt_vec3 rt_radiance_path(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    int max_depth = s->settings.max_depth > 0 ? s->settings.max_depth : RT_PATH_HARD_LIMIT;
    if (max_depth > RT_PATH_HARD_LIMIT)
        max_depth = RT_PATH_HARD_LIMIT;
    int rr_depth = s->settings.rr_depth;
    rt_ray r = *ray;
    float len = rt_length(r.dir);
    if (!(len > 0.0f) || !isfinite(len))
        return rt_v3s(0.0f);
    r.dir = rt_scale(r.dir, 1.0f / len);
    r.tmin *= len;
    r.tmax *= len;
    rt_vec3 L = rt_v3s(0.0f), beta = rt_v3s(1.0f);
    bool prev_delta = true;     /* the camera "samples" its ray: no MIS */
    float prev_pdf = 0.0f;      /* BSDF pdf of the ray just traced */
    rt_vec3 prev_p = r.org;
    int bounces = 0;
    rt_medium_stack media;
    rt_medium_stack_init(&media);
    int skips = RT_PATH_HARD_LIMIT; /* false intersections a path may pass */
    for (;;) {
        int layers = 257; /* up to 256 cut-away surfaces per path segment */
        rt_surface sf;
        float coverage;
        rt_surface_walk found = rt_trace_surface(ctx, &r, &layers, rng, &sf, &coverage);
        if (found == RT_WALK_MISS) {
            float w = 1.0f; /* MIS against environment sampling, when the table does it */
            if (!prev_delta && ctx->state->light_table && ctx->state->light_table->env_w > 0)
                w = rt_mis_power(prev_pdf, rt_light_table_env_pdf(ctx->state->light_table, r.dir));
            L = add_finite(L, rt_scale(rt_mul(beta, rt_environment(s, r.dir)), w));
        }
        if (found != RT_WALK_SURFACE)
            break;
        const rt_material *m = &s->materials[sf.material];
        /* Beer-Lambert absorption of the medium the segment ran through
         * (r.tmin is the hit distance, dir is unit) */
        uint32_t medium = rt_medium_of_segment(&media, s->materials, sf.material, sf.front);
        if (medium != RT_NONE)
            beta = rt_mul(beta, rt_medium_transmittance(s->materials, medium, r.tmin));
        if (rt_medium_false_hit(&media, s->materials, sf.material, sf.front)) {
            /* an interface inside a higher-priority medium: straight on */
            rt_medium_cross(&media, s->materials, sf.material, sf.front);
            if (--skips < 0)
                break;
            r = rt_ray_make(rt_surface_spawn(ctx, &sf, r.dir), r.dir, 0.0f, INFINITY);
            continue;
        }
        /* emission, MIS-weighted when it could have been light-sampled */
        rt_vec3 Le = rt_surface_emission(ctx, &sf);
        /* area lights' quads have emissive materials: look only those up */
        bool emissive = rt_max3(rt_scale(m->emission, m->emission_strength)) > 0.0f;
        uint32_t light = emissive ? rt_area_light_of_prim(s, ctx->state->light_table, sf.prim) : RT_NONE;
        if (rt_max3(Le) > 0.0f) {
            float w = 1.0f;
            if (!prev_delta) {
                float d2 = rt_length2(rt_sub(sf.p, prev_p));
                float pdf_l = 0.0f;
                if (light != RT_NONE) {
                    pdf_l = rt_area_light_pdf(&s->lights[light], r.dir, sqrtf(d2));
                } else if (ctx->state->light_table && sf.prim < ctx->state->light_table->prim_count) {
                    float cos_l = fabsf(rt_dot(sf.ng, r.dir));
                    float pa = ctx->state->light_table->prim_pdf[sf.prim];
                    pdf_l = (pa > 0.0f && cos_l > 0.0f) ? pa * d2 / cos_l : 0.0f;
                }
                if (pdf_l > 0.0f && isfinite(pdf_l))
                    w = rt_mis_power(prev_pdf, pdf_l);
            }
            L = add_finite(L, rt_scale(rt_mul(beta, Le), w));
        }
        if (light != RT_NONE)
            break; /* an area light's quad reflects nothing */
        if (m->unlit) {
            rt_vec4 c = rt_surface_base_color(ctx, &sf);
            L = add_finite(L, rt_mul(beta, rt_v3(c.x, c.y, c.z)));
            break;
        }
        if (bounces >= max_depth)
            break;
        rt_bsdf b;
        rt_bsdf_from_surface(ctx, &sf, &b);
        if (rt_medium_is_medium(m)) { /* the index ratio to the medium beyond */
            float eta = rt_medium_outside_ior(&media, s->materials, sf.material, sf.front) / m->ior;
            rt_bsdf_set_eta(&b, sf.front ? eta : 1.0f / eta);
        }
        rt_vec3 wo = rt_bsdf_to_local(&b, sf.wo);
        if (!(wo.z > 0.0f))
            break;
        L = add_finite(L, rt_mul(beta, next_event(ctx, &sf, &b, wo, rng)));
        /* continue the path by sampling the BSDF */
        float ulobe = rt_rng_float(rng);
        rt_vec2 u = rt_v2(rt_rng_float(rng), rt_rng_float(rng));
        rt_bsdf_sample bs;
        if (!rt_bsdf_sample_dir(&b, wo, u, ulobe, &bs))
            break;
        rt_vec3 wi = rt_normalize(rt_bsdf_to_world(&b, bs.wi));
        float side = rt_dot(wi, sf.ng);
        if (bs.wi.z > 0.0f ? !(side > 0.0f) : !(side < 0.0f))
            break; /* the shading normal disagrees with the geometry: no light leaks */
        beta = rt_mul(beta, bs.weight);
        if (!rt_finite3(beta) || !(rt_max3(beta) > 0.0f))
            break;
        if (bs.wi.z < 0.0f) /* transmitted: into or out of the medium */
            rt_medium_cross(&media, s->materials, sf.material, sf.front);
        prev_delta = bs.delta;
        prev_pdf = bs.pdf;
        prev_p = sf.p;
        bounces++;
        if (rr_depth == 0 ? rt_max3(beta) < 1.0f : bounces >= rr_depth) {
            float q = rr_depth == 0 ? rt_max3(beta) : fminf(rt_max3(beta), 0.95f);
            if (rt_rng_float(rng) >= q)
                break;
            beta = rt_scale(beta, 1.0f / q);
        }
        r = rt_ray_make(rt_surface_spawn(ctx, &sf, wi), wi, 0.0f, INFINITY);
    }
    return rt_finite3(L) ? L : rt_v3s(0.0f);
}
