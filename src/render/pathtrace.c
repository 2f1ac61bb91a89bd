/* pathtrace.c - the `path` integrator: unidirectional path tracing with
 * next-event estimation and multiple importance sampling.
 *
 * Estimator (Kajiya 1986, "The Rendering Equation"; the structure of pbrt
 * v3's PathIntegrator, Pharr, Jakob, Humphreys, ch. 14.5): from the camera,
 * at each surface vertex x with throughput beta,
 *   - emission seen along the ray is added, beta Le, weighted by MIS
 *     against light sampling when the emitter could have been light-sampled
 *     from the previous vertex;
 *   - next-event estimation: every rt_light is sampled once (rectangular
 *     area lights uniformly in solid angle, pdf 1 / solid angle, others
 *     uniformly by area, pdf d^2 / (A cos theta_l), rt/render/light.h;
 *     point, spot and directional lights are deltas, weight 1), and, with
 *     a light table (rt/render/light.h), one emissive primitive chosen in
 *     proportion to its power (area x mean emitted radiance) and a
 *     direction uniform in its solid angle (triangles, Arvo 1995) or a
 *     uniform point on it (quads, spheres, triangles too small or too
 *     large in solid angle),
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
 * path survives with q = min(w, 0.95) and beta /= q, which keeps the
 * estimator unbiased; rr_depth 0 is adaptive (pbrt-v4's rule): from the
 * first bounce, whenever w has fallen below 1, the path survives with
 * q = w. The weight w is the max channel of beta times eta_scale, the
 * product of (n_t / n_i)^2 over the refractions of a bsdf dielectric the
 * path took (whose weights scale radiance by (n_i / n_t)^2, a change of
 * units, not a loss): pbrt-v4's etaScale (Pharr, Jakob, Humphreys, 4th
 * ed., 13.1.4) and Mitsuba 3's max(throughput) eta^2, so a path inside
 * glass is judged as it will be once it leaves (issue 30). Thin-walled
 * and glTF transmission leave radiance unscaled and eta_scale at 1.
 * settings.max_depth caps the scattering events of a path (0 = no cap).
 *
 * Media (rt/render/medium.h): the path carries a stack of the dielectric
 * objects it is inside (Schmidt and Budge 2002's nested dielectrics). Each
 * segment is attenuated by Beer-Lambert absorption exp(-sigma_a d) of the
 * medium it ran through (a glTF KHR_materials_volume object: the segment
 * ending on its back); a false intersection (a lower-priority medium's
 * surface inside a higher-priority one) is passed straight through
 * without counting as a bounce (rt_path_vertex_begin returns
 * RT_VERTEX_PASS); a true one refracts between the current medium's index
 * and the next one's, and a transmitted sample pushes or pops the stack.
 *
 * Area lights are pure emitters: their visible quad emits from its front
 * and reflects nothing. Shadow rays pass alpha cut-outs and blended
 * surfaces (times 1 - alpha), and smooth thin-walled panes (glTF
 * transmission without a volume, roughness 0) times the weight of their
 * straight-through delta lobe (rt_path_shadow); a BSDF-sampled path that
 * takes that lobe passes the pane without making it the vertex its MIS
 * weights refer to (prev_p, prev_pdf, prev_delta stay), so light beyond
 * it is weighed against the light sampling of the vertex before, whose
 * shadow ray passed the same pane (as pbrt-v4 skips interface materials,
 * keeping the previous interaction for MIS; a pass is no bounce for
 * max_depth). Other refractive
 * (transmissive) surfaces block them: light through glass that bends or
 * blurs arrives by BSDF sampling. Alpha blending on camera
 * and bounce rays is stochastic: the surface is kept with probability alpha.
 * All random numbers come from the rng handed in, so images do not depend
 * on the thread count; every contribution is checked finite. The light,
 * BSDF and roulette decisions take their numbers from the scene's sampler
 * (settings.sampler, rt/render/sampler.h: stratified over the pixel's
 * samples, or the rng's stream for `independent`), in dimensions fixed by
 * the bounce and the decision (path_dim); alpha blending draws from the
 * rng's stream.
 */
#include "rt/render/pathtrace.h"

#include "rt/render/emitter_sample.h"
#include "rt/render/environment.h"
#include "rt/render/medium.h"
#include "rt/render/sampler.h"

/* The sampler dimensions of a vertex: a fixed layout per bounce (the
 * vertex after `bounces` scatterings uses dims bounces * stride + slot),
 * so every sample of a pixel takes each decision from the same stratified
 * dimension, whatever its path did before, and the wavefront needs no
 * per-lane counter. With a stratified sampler and AVX2, the first read of a
 * bounce computes its first RT_SAMPLER_BLOCK (8) dimensions at once into
 * the path's cache (rt/render/sampler_block.h: the same bits as one at a time),
 * which the bounce's other reads find there; with more than 3 lights the
 * lights past the third fill blocks of 8 of their own in turn (then the
 * first block is computed again for the environment, emitter and BSDF). */
enum { DIM_BSDF, DIM_LOBE_RR, DIM_ENV, DIM_EMIT_PICK, DIM_EMIT, DIM_LIGHT0 };

static inline uint32_t path_stride(const rt_trace_ctx *ctx)
{
    return DIM_LIGHT0 + (uint32_t)ctx->state->scene->light_count;
}

static inline uint32_t path_dim(const rt_trace_ctx *ctx, const rt_path_state *ps, uint32_t slot)
{
    return (uint32_t)ps->bounces * path_stride(ctx) + slot;
}

/* The 2D value of slot `slot` of bounce `bounce`. */
static inline rt_vec2 path_2d_of(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, int bounce, uint32_t slot)
{
    const rt_settings *st = ctx->state->settings;
    rt_sampler_kind kind = (rt_sampler_kind)st->sampler;
    uint32_t dim0 = (uint32_t)bounce * path_stride(ctx);
    if (kind != RT_SAMPLER_INDEPENDENT && rt_sampler_block_usable()) {
        uint32_t first = slot - slot % RT_SAMPLER_BLOCK; /* past 8 slots (3 lights), the block of 8 it falls in */
        return rt_sampler_cache_2d(&ps->samples, kind, rng->key, rng->index, (uint32_t)st->samples, dim0 + first,
                                   slot - first);
    }
    return rt_sample_2d(kind, (uint32_t)st->samples, rng, dim0 + slot);
}

static inline rt_vec2 path_2d(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, uint32_t slot)
{
    return path_2d_of(ctx, ps, rng, ps->bounces, slot);
}

/* A 1D value: Sobol's is the x of the dimension's 2D value
 * (rt_sampler_1d), so it reads the cache; CMJ's and the stream's are apart. */
static inline float path_1d(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, uint32_t slot)
{
    const rt_settings *st = ctx->state->settings;
    if (st->sampler == RT_SAMPLER_SOBOL && rt_sampler_block_usable())
        return path_2d(ctx, ps, rng, slot).x;
    return rt_sample_1d((rt_sampler_kind)st->sampler, (uint32_t)st->samples, rng, path_dim(ctx, ps, slot));
}

/* A record for a light from the light table in direction d (world, above
 * the geometric surface) with light-sampling density pdf_l, weighted against
 * BSDF sampling by the power heuristic; the radiance is *Le or, for Le NULL,
 * the environment in d. False when it cannot contribute. */
static bool light_table_record(const rt_trace_ctx *ctx, const rt_bsdf *b, rt_vec3 wo, rt_vec3 d, const rt_vec3 *Le,
                               float pdf_l, float dist, rt_nee_record *rec)
{
    rt_vec3 wi = rt_bsdf_to_local(b, d);
    float pdf_b;
    rt_vec3 f = rt_bsdf_eval(b, wo, wi, &pdf_b);
    float w = rt_mis_power(pdf_l, pdf_b);
    if (!(rt_max3(f) > 0.0f && w > 0.0f))
        return false;
    rec->fl = rt_mul(f, Le ? *Le : rt_environment(ctx->state->scene, d));
    rec->cos = wi.z;
    rec->w = w;
    rec->pdf = pdf_l;
    rec->wi = d;
    rec->dist = dist;
    return true;
}

rt_vec2 rt_path_light_u(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, size_t i)
{
    return path_2d(ctx, ps, rng, DIM_LIGHT0 + (uint32_t)i);
}

bool rt_path_nee_light(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, const rt_bsdf *b,
                       rt_vec3 wo, rt_rng *rng, size_t i, rt_nee_record *rec)
{
    rt_vec2 u = rt_path_light_u(ctx, ps, rng, i);
    return rt_path_nee_light_at(ctx, &ctx->state->scene->lights[i], sf->p, b, wo, u, rec);
}

bool rt_path_nee_light_at(const rt_trace_ctx *ctx, const rt_light *l, rt_vec3 p, const rt_bsdf *b, rt_vec3 wo,
                          rt_vec2 u, rt_nee_record *rec)
{
    rt_light_sample ls;
    if (!rt_light_sample_at(ctx, l, p, u, &ls))
        return false;
    if (!(rt_dot(ls.wi, b->ng) > 0.0f))
        return false; /* below the geometric surface */
    rt_vec3 wi = rt_bsdf_to_local(b, ls.wi);
    float pdf_b;
    rt_vec3 f = rt_bsdf_eval(b, wo, wi, &pdf_b);
    if (!(rt_max3(f) > 0.0f))
        return false;
    float w = 1.0f;
    if (l->kind == RT_LIGHT_AREA && l->quad != RT_NONE)
        w = rt_mis_power(ls.pdf, pdf_b);
    if (!(w > 0.0f))
        return false;
    rec->fl = rt_mul(f, ls.li);
    rec->cos = wi.z;
    rec->w = w;
    rec->pdf = 1.0f; /* ls.li is already divided by it */
    rec->wi = ls.wi;
    rec->dist = ls.dist;
    return true;
}

rt_vec3 rt_path_shadow(const rt_trace_ctx *ctx, const rt_path_state *ps, const rt_surface *sf,
                       const rt_nee_record *rec)
{
    bool thin = rt_medium_current(&ps->media, ctx->state->scene->materials) == RT_NONE;
    return rt_shadow_path_transmittance(ctx, sf, rec->wi, rec->dist, thin);
}

bool rt_path_env_sample(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, rt_vec3 *d, float *pdf_l)
{
    if (!rt_path_samples_env(ctx))
        return false;
    rt_vec2 u = path_2d(ctx, ps, rng, DIM_ENV);
    return rt_light_table_sample_env(ctx->state->light_table, u, d, pdf_l);
}

bool rt_path_nee_env(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_bsdf *b, rt_vec3 wo, rt_rng *rng,
                     rt_nee_record *rec)
{
    rt_vec3 d;
    float pdf_l;
    if (rt_path_env_sample(ctx, ps, rng, &d, &pdf_l) && rt_dot(d, b->ng) > 0.0f)
        return light_table_record(ctx, b, wo, d, NULL, pdf_l, INFINITY, rec);
    return false;
}

bool rt_path_nee_emitter(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, const rt_bsdf *b,
                         rt_vec3 wo, rt_rng *rng, rt_nee_record *rec)
{
    if (!rt_path_samples_emitters(ctx))
        return false;
    float ul = path_1d(ctx, ps, rng, DIM_EMIT_PICK);
    rt_vec2 u = path_2d(ctx, ps, rng, DIM_EMIT);
    rt_emitter_sample es;
    if (rt_emitter_sample_at(ctx, sf->p, ul, u, &es) && rt_dot(es.wi, b->ng) > 0.0f)
        return light_table_record(ctx, b, wo, es.wi, &es.Le, es.pdf, es.dist, rec);
    return false;
}

/* ------------------------------------------------------------ one vertex */

bool rt_path_start(const rt_trace_ctx *ctx, const rt_ray *ray, rt_path_state *ps)
{
    (void)ctx;
    rt_ray r = *ray;
    float len = rt_length(r.dir);
    if (!(len > 0.0f) || !isfinite(len))
        return false;
    r.dir = rt_scale(r.dir, 1.0f / len);
    r.tmin *= len;
    r.tmax *= len;
    ps->r = r;
    ps->L = rt_v3s(0.0f);
    ps->beta = rt_v3s(1.0f);
    ps->eta_scale = 1.0f;
    ps->prev_delta = true; /* the camera "samples" its ray: no MIS */
    ps->prev_pdf = 0.0f;   /* BSDF pdf of the ray just traced */
    ps->prev_p = r.org;
    ps->bounces = 0;
    ps->passes = 0;
    rt_medium_stack_init(&ps->media);
    ps->skips = RT_PATH_HARD_LIMIT;
    rt_sampler_cache_clear(&ps->samples); /* a new sample: the cache holds none of its values */
    return true;
}

void rt_path_miss(const rt_trace_ctx *ctx, rt_path_state *ps)
{
    float w = 1.0f; /* MIS against environment sampling, when the table does it */
    if (!ps->prev_delta && ctx->state->light_table && ctx->state->light_table->env_w > 0)
        w = rt_mis_power(ps->prev_pdf, rt_light_table_env_pdf(ctx->state->light_table, ps->r.dir));
    ps->L = rt_path_add_finite(ps->L, rt_scale(rt_mul(ps->beta, rt_environment(ctx->state->scene, ps->r.dir)), w));
}

rt_path_vertex rt_path_vertex_begin(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, rt_bsdf *b,
                                    rt_vec3 *wo)
{
    const rt_scene *s = ctx->state->scene;
    int max_depth = ctx->state->settings->max_depth > 0 ? ctx->state->settings->max_depth : RT_PATH_HARD_LIMIT;
    if (max_depth > RT_PATH_HARD_LIMIT)
        max_depth = RT_PATH_HARD_LIMIT;
    const rt_material *m = &s->materials[sf->material];
    /* Beer-Lambert absorption of the medium the segment ran through
     * (r.tmin is the hit distance, dir is unit) */
    uint32_t medium = rt_medium_of_segment(&ps->media, s->materials, sf->material, sf->front);
    if (medium != RT_NONE)
        ps->beta = rt_mul(ps->beta, rt_medium_transmittance(s->materials, medium, ps->r.tmin));
    if (rt_medium_false_hit(&ps->media, s->materials, sf->material, sf->front)) {
        /* an interface inside a higher-priority medium: straight on */
        rt_medium_cross(&ps->media, s->materials, sf->material, sf->front);
        if (--ps->skips < 0)
            return RT_VERTEX_STOP;
        ps->r = rt_ray_make(rt_surface_spawn(ctx, sf, ps->r.dir), ps->r.dir, 0.0f, INFINITY);
        return RT_VERTEX_PASS;
    }
    /* emission, MIS-weighted when it could have been light-sampled */
    rt_vec3 Le = (ctx->state->material_needs[sf->material] & RT_MATERIAL_EMITS) ? rt_surface_emission(ctx, sf)
                                                                                 : rt_v3s(0.0f);
    /* area lights' quads have emissive materials: look only those up */
    bool emissive = rt_max3(rt_scale(m->emission, m->emission_strength)) > 0.0f;
    uint32_t light = emissive ? rt_area_light_of_prim(s, ctx->state->light_table, sf->prim) : RT_NONE;
    if (rt_max3(Le) > 0.0f) {
        float w = 1.0f;
        if (!ps->prev_delta) {
            float d2 = rt_length2(rt_sub(sf->p, ps->prev_p));
            float pdf_l;
            if (light != RT_NONE)
                pdf_l = rt_area_light_pdf(&s->lights[light], ps->prev_p, ps->r.dir, sqrtf(d2));
            else /* the density rt_path_nee_emitter drew from at prev_p */
                pdf_l = rt_emitter_pdf(ctx, sf->prim, ps->prev_p, ps->r.dir, d2, sf->ng);
            if (pdf_l > 0.0f && isfinite(pdf_l))
                w = rt_mis_power(ps->prev_pdf, pdf_l);
        }
        ps->L = rt_path_add_finite(ps->L, rt_scale(rt_mul(ps->beta, Le), w));
    }
    if (light != RT_NONE)
        return RT_VERTEX_STOP; /* an area light's quad reflects nothing */
    if (m->unlit) {
        rt_vec4 c = rt_surface_base_color(ctx, sf);
        ps->L = rt_path_add_finite(ps->L, rt_mul(ps->beta, rt_v3(c.x, c.y, c.z)));
        return RT_VERTEX_STOP;
    }
    if (ps->bounces - ps->passes >= max_depth || ps->bounces >= 2 * RT_PATH_HARD_LIMIT)
        return RT_VERTEX_STOP;
    rt_bsdf_from_surface(ctx, sf, b);
    if (rt_medium_is_medium(m)) { /* the index ratio to the medium beyond */
        float eta = rt_medium_outside_ior(&ps->media, s->materials, sf->material, sf->front) / m->ior;
        rt_bsdf_set_eta(b, sf->front ? eta : 1.0f / eta);
    }
    *wo = rt_bsdf_to_local(b, sf->wo);
    if (b->kind != RT_BSDF_KIND_LAMBERT) /* (Lambert has nothing to cache) */
        rt_bsdf_set_wo(b, *wo); /* the light samples and the next direction share wo */
    return wo->z > 0.0f ? RT_VERTEX_SHADE : RT_VERTEX_STOP;
}

void rt_path_bsdf_draw_of(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, rt_bsdf_kind kind,
                          rt_path_bsdf_draw *d)
{
    /* the lobe choice and the roulette share a 2D dimension, computed
     * once and only when read: a Lambertian BSDF (one lobe) ignores ulobe
     * and most paths end before the roulette. `independent` draws both from
     * the stream, in call order. */
    d->stratified = ctx->state->settings->sampler != RT_SAMPLER_INDEPENDENT;
    d->lr_bounce = ps->bounces; /* the roulette reads it after ps->bounces++ */
    d->ulr = rt_v2(0.0f, 0.0f);
    d->have_lr = false;
    d->ulobe = 0.0f;
    if (!d->stratified) {
        d->ulobe = rt_rng_float(rng);
    } else if (kind != RT_BSDF_KIND_LAMBERT) {
        d->ulr = path_2d_of(ctx, ps, rng, d->lr_bounce, DIM_LOBE_RR);
        d->have_lr = true;
        d->ulobe = d->ulr.x;
    }
    d->u = path_2d(ctx, ps, rng, DIM_BSDF);
}

bool rt_path_vertex_advance(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, rt_rng *rng,
                            rt_path_bsdf_draw *d, rt_vec3 wi, float pdf, bool delta, bool pass)
{
    if (pass) {
        ps->passes++;
    } else {
        ps->prev_delta = delta;
        ps->prev_pdf = pdf;
        ps->prev_p = sf->p;
    }
    ps->bounces++;
    float q = rt_path_rr_probability(ps, ctx->state->settings->rr_depth);
    if (q < 1.0f) {
        if (d->stratified && !d->have_lr)
            d->ulr = path_2d_of(ctx, ps, rng, d->lr_bounce, DIM_LOBE_RR);
        if ((d->stratified ? d->ulr.y : rt_rng_float(rng)) >= q)
            return false;
        ps->beta = rt_scale(ps->beta, 1.0f / q);
    }
    ps->r = rt_ray_make(rt_surface_spawn(ctx, sf, wi), wi, 0.0f, INFINITY);
    return true;
}

bool rt_path_vertex_end(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, const rt_bsdf *b,
                        rt_vec3 wo, rt_rng *rng)
{
    /* continue the path by sampling the BSDF */
    rt_path_bsdf_draw d;
    rt_path_bsdf_draw_of(ctx, ps, rng, b->kind, &d);
    rt_bsdf_sample bs;
    if (!rt_bsdf_sample_dir(b, wo, d.u, d.ulobe, &bs))
        return false;
    rt_vec3 wi = rt_normalize(rt_bsdf_to_world(b, bs.wi));
    float side = rt_dot(wi, sf->ng);
    if (bs.wi.z > 0.0f ? !(side > 0.0f) : !(side < 0.0f))
        return false; /* the shading normal disagrees with the geometry: no light leaks */
    /* straight through a smooth thin surface, outside every medium: the
     * shadow rays of the vertex before passed it too (rt_path_shadow), so
     * light beyond is weighed against theirs, from there */
    bool pass = bs.straight && rt_medium_current(&ps->media, ctx->state->scene->materials) == RT_NONE;
    rt_vec3 beta = rt_mul(ps->beta, bs.weight);
    ps->beta = beta;
    if (!rt_finite3(beta) || !(rt_max3(beta) > 0.0f))
        return false;
    if (bs.wi.z < 0.0f) { /* transmitted: into or out of the medium */
        rt_medium_cross(&ps->media, ctx->state->scene->materials, sf->material, sf->front);
        if (b->kind == RT_BSDF_KIND_DIELECTRIC && !b->thin) /* the weight held (n_i / n_t)^2 = b->eta^2: undo it for the roulette */
            ps->eta_scale /= b->eta * b->eta;
    }
    return rt_path_vertex_advance(ctx, ps, sf, rng, &d, wi, bs.pdf, bs.delta, pass);
}

/* ------------------------------------------------------------ integrator */

rt_vec3 rt_radiance_path(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    rt_path_state ps;
    if (!rt_path_start(ctx, ray, &ps))
        return rt_v3s(0.0f);
    for (;;) {
        int layers = RT_PATH_LAYERS;
        rt_surface sf;
        float coverage;
        rt_surface_walk found = rt_trace_surface(ctx, &ps.r, &layers, rng, &sf, &coverage);
        if (found == RT_WALK_MISS)
            rt_path_miss(ctx, &ps);
        if (found != RT_WALK_SURFACE)
            break;
        rt_bsdf b;
        rt_vec3 wo;
        rt_path_vertex v = rt_path_vertex_begin(ctx, &ps, &sf, &b, &wo);
        if (v == RT_VERTEX_PASS)
            continue;
        if (v == RT_VERTEX_STOP)
            break;
        /* next-event estimation: every light, the environment, one emitter */
        rt_vec3 sum = rt_v3s(0.0f);
        rt_nee_record rec;
        for (size_t i = 0; i < s->light_count; i++)
            if (rt_path_nee_light(ctx, &ps, &sf, &b, wo, rng, i, &rec))
                sum = rt_path_nee_add(sum, &rec, rt_path_shadow(ctx, &ps, &sf, &rec));
        if (rt_path_nee_env(ctx, &ps, &b, wo, rng, &rec))
            sum = rt_path_nee_add(sum, &rec, rt_path_shadow(ctx, &ps, &sf, &rec));
        if (rt_path_nee_emitter(ctx, &ps, &sf, &b, wo, rng, &rec))
            sum = rt_path_nee_add(sum, &rec, rt_path_shadow(ctx, &ps, &sf, &rec));
        ps.L = rt_path_add_finite(ps.L, rt_mul(ps.beta, sum));
        if (!rt_path_vertex_end(ctx, &ps, &sf, &b, wo, rng))
            break;
    }
    return rt_finite3(ps.L) ? ps.L : rt_v3s(0.0f);
}
