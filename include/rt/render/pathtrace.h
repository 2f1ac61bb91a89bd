/* rt/render/pathtrace.h - the `path` integrator: unidirectional path tracing of the
 * glTF material model (rt/render/bsdf.h) with next-event estimation, multiple
 * importance sampling and Russian roulette. docs/path-tracer.md has the
 * estimator, its validation against Mitsuba 3, and the settings.
 *
 *   rt_vec3 L = rt_radiance_path(&ctx, &ray, &rng);   // via rt_radiance()
 *
 * Lights sampled at every path vertex: every rt_light (point, spot,
 * directional, area) and, when the render state holds a light table
 * (rt/render/light.h; its line in the integrator table asks for
 * RT_PREPARE_LIGHT_TABLE, so rt_render builds one), one emissive primitive
 * (triangle, quad or sphere with an emissive material) chosen by power, and
 * the environment image by its luminance:
 *
 *   rt_render_state rs;
 *   rt_render_state_prepare(&rs, &scene, &tree, RT_PREPARE_LIGHT_TABLE, &err);
 *   ... in each worker: rt_trace_ctx_init(&ctx, &rs); L = rt_radiance_path(&ctx, &ray, &rng);
 *   rt_render_state_free(&rs);                           // after the render
 *
 * Without a table (prepared without RT_PREPARE_LIGHT_TABLE) the image is
 * the same in expectation: emissive primitives are then found only by
 * BSDF-sampled rays and counted in full (noisier for small bright
 * emitters).
 */
#ifndef RT_PATHTRACE_H
#define RT_PATHTRACE_H

#include "rt/render/bsdf.h"
#include "rt/render/light.h"
#include "rt/render/material_eval.h"
#include "rt/render/medium.h"
#include "rt/render/sampling.h"
#include "rt/render/sampler_block.h"

#define RT_PATH_HARD_LIMIT 1024 /* bounces when max_depth is 0 (unlimited): a guard, never reached in practice */
#define RT_PATH_LAYERS 257      /* surfaces a path segment may step past (alpha cut-outs) plus one */

/* The scalar path tracer (integrator `path_scalar`, and the reference the
 * wavefront `path` is tested against): one path at a time. */
rt_vec3 rt_radiance_path(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

/* ---- the steps of one path, shared by rt_radiance_path and the wavefront
 * tracer (rt/render/wavefront.h), so both run the same arithmetic in the
 * same order and draw the same random numbers:
 *
 *   rt_path_state ps;
 *   if (!rt_path_start(ctx, ray, &ps)) return 0;
 *   loop: trace ps.r (the alpha walk, rt_trace_surface, with rng);
 *         miss: rt_path_miss(ctx, &ps), stop; too deep: stop;
 *         switch (rt_path_vertex_begin(ctx, &ps, &sf, &b, &wo)): STOP: stop; PASS: loop;
 *         records from rt_path_nee_light (each light in order; all take &ps), rt_path_nee_env,
 *         rt_path_nee_emitter; sum = rt_path_nee_add(sum, &rec, rt_path_shadow(ctx, &ps, &sf, &rec))
 *         in that order;
 *         ps.L = rt_path_add_finite(ps.L, ps.beta * sum);
 *         if (!rt_path_vertex_end(ctx, &ps, &sf, &b, wo, rng)) stop;
 *   L = finite(ps.L) ? ps.L : 0
 */
typedef struct rt_path_state {
    rt_ray r;          /* the ray to trace next (unit direction) */
    rt_vec3 L, beta;   /* radiance so far, throughput */
    float eta_scale;   /* the product of (n_t / n_i)^2 over the refractions whose weight scaled beta by
                        * (n_i / n_t)^2 (bsdf dielectric): beta * eta_scale is the throughput without
                        * that change of units, what the roulette weighs (1 outside, pbrt-v4's etaScale) */
    bool prev_delta;   /* the last scattering was a delta lobe (or the camera): no MIS */
    float prev_pdf;    /* BSDF pdf of the ray just traced */
    rt_vec3 prev_p;    /* where it left from */
    /* (a pass straight through a smooth thin-walled surface, which shadow
     * rays take too, leaves the three above as they were: the light
     * reached beyond it is weighed against the light sampling of the
     * vertex before) */
    int bounces;       /* vertices scattered at, passes included: they pick the sampler dimensions */
    int passes;        /* of which passes straight through thin surfaces: max_depth counts bounces - passes */
    rt_medium_stack media; /* the dielectrics it is inside (rt/render/medium.h) */
    int skips;         /* false intersections it may still pass */
    rt_sampler_cache samples; /* the stratified sampler's values of the current bounce (rt/render/sampler_block.h) */
} rt_path_state;

/* What rt_path_vertex_begin found at a surface. */
typedef enum rt_path_vertex {
    RT_VERTEX_STOP = 0, /* the path ends here (emission added) */
    RT_VERTEX_SHADE,    /* shade it: light sampling, then rt_path_vertex_end */
    RT_VERTEX_PASS      /* a false intersection of nested media: ps->r goes straight on, trace it again */
} rt_path_vertex;

/* One light sample at a vertex, before its shadow ray: it adds
 * fl cos vis w / pdf (fl = f x radiance) when the shadow ray from the
 * vertex along wi over dist has visibility vis. */
typedef struct rt_nee_record {
    rt_vec3 fl;
    float cos, w, pdf;
    rt_vec3 wi;
    float dist;
} rt_nee_record;

static inline rt_vec3 rt_path_add_finite(rt_vec3 acc, rt_vec3 c)
{
    return rt_finite3(c) ? rt_add(acc, rt_vmax(c, rt_v3s(0.0f))) : acc;
}

/* false for a degenerate camera ray (radiance 0). */
bool rt_path_start(const rt_trace_ctx *ctx, const rt_ray *ray, rt_path_state *ps);
/* ps.r left the scene: the environment, MIS-weighted. */
void rt_path_miss(const rt_trace_ctx *ctx, rt_path_state *ps);
/* At a surface ps.r reached: the medium's absorption, a false intersection
 * passed (RT_VERTEX_PASS), emission (MIS), then the BSDF *b with the index
 * ratio of the media on both sides and local *wo (RT_VERTEX_SHADE). */
rt_path_vertex rt_path_vertex_begin(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, rt_bsdf *b,
                                    rt_vec3 *wo);
/* Light i, the environment image, one emitter of the table at the path's
 * current vertex (ps: its bounce picks the sampler dimensions, its cache holds them): each draws
 * its random numbers and fills *rec when it can contribute. */
bool rt_path_nee_light(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, const rt_bsdf *b,
                       rt_vec3 wo, rt_rng *rng, size_t i, rt_nee_record *rec);
/* rt_path_nee_light in its two halves: the 2D value light i's sample
 * draws, and the record of light l's sample from point p with that value
 * (the wavefront draws first and computes the records later, in lanes). */
rt_vec2 rt_path_light_u(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, size_t i);
bool rt_path_nee_light_at(const rt_trace_ctx *ctx, const rt_light *l, rt_vec3 p, const rt_bsdf *b, rt_vec3 wo,
                          rt_vec2 u, rt_nee_record *rec);
bool rt_path_nee_env(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_bsdf *b, rt_vec3 wo, rt_rng *rng,
                     rt_nee_record *rec);
/* rt_path_nee_env's first half: the environment's sample (direction d,
 * pdf_l), drawn as it draws it; false when there is none. */
bool rt_path_env_sample(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, rt_vec3 *d, float *pdf_l);
bool rt_path_nee_emitter(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, const rt_bsdf *b,
                         rt_vec3 wo, rt_rng *rng, rt_nee_record *rec);
/* What the shadow ray of record rec, made at the path's current vertex
 * sf, lets through (rt_shadow_path_transmittance): alpha as a path steps
 * past it and, outside every medium (rt_medium_current is none, so no
 * absorption is left out), smooth thin-walled surfaces by their
 * straight-through lobe, which rt_path_vertex_end then passes without
 * taking the vertex as the one to weigh light against. */
rt_vec3 rt_path_shadow(const rt_trace_ctx *ctx, const rt_path_state *ps, const rt_surface *sf,
                       const rt_nee_record *rec);
/* One light-sampling term, f cos tr w / pdf times the radiance, for the
 * transmittance tr of its shadow ray; zero when the shadow ray is blocked
 * (tr 0). A grey tr (every scene without thin transmission) is one factor. */
static inline rt_vec3 rt_path_nee_add(rt_vec3 sum, const rt_nee_record *rec, rt_vec3 tr)
{
    if (tr.x == tr.y && tr.y == tr.z) {
        float vis = tr.x;
        if (!(vis > 0.0f))
            return sum;
        return rt_path_add_finite(sum, rt_scale(rec->fl, rec->cos * vis * rec->w / rec->pdf));
    }
    if (!(rt_max3(tr) > 0.0f))
        return sum;
    return rt_path_add_finite(sum, rt_scale(rt_mul(rec->fl, tr), rec->cos * rec->w / rec->pdf));
}
/* Whether rt_path_nee_env / rt_path_nee_emitter can make a record in this
 * render (a light table with an environment / with emitters): when not,
 * they return false at once, drawing nothing, so a caller may skip them. */
static inline bool rt_path_samples_env(const rt_trace_ctx *ctx)
{
    const rt_light_table *t = ctx->state->light_table;
    return t && t->env_w > 0;
}
static inline bool rt_path_samples_emitters(const rt_trace_ctx *ctx)
{
    const rt_light_table *t = ctx->state->light_table;
    return t && t->count;
}
/* BSDF sampling, Russian roulette, the next ray in ps->r; false when the
 * path ends. The roulette (rt_path_rr_probability) weighs max channel of
 * beta x eta_scale: a path inside a dense dielectric is not killed for the
 * 1 / eta^2 its radiance carries there. */
bool rt_path_vertex_end(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, const rt_bsdf *b,
                        rt_vec3 wo, rt_rng *rng);

/* The parts of rt_path_vertex_end, for the wavefront's lanes
 * (rt/render/shade_lanes.h), which sample a BSDF kind over many paths at
 * once in between: rt_path_vertex_end is
 *   rt_path_bsdf_draw_of; bs = rt_bsdf_sample_dir(b, wo, d.u, d.ulobe); wi = normalize(to world);
 *   the geometric side test; beta *= bs.weight (finite, positive); the medium crossed;
 *   rt_path_vertex_advance(..., wi, bs.pdf, bs.delta, pass).
 * The random numbers of the BSDF sample, drawn as rt_path_vertex_end
 * draws them (the roulette's may be drawn later, by rt_path_vertex_advance). */
typedef struct rt_path_bsdf_draw {
    rt_vec2 u;        /* the direction's */
    float ulobe;      /* the lobe choice's */
    rt_vec2 ulr;      /* lobe choice (x) and roulette (y), when have_lr */
    bool have_lr, stratified;
    int lr_bounce;    /* the bounce whose dimension the roulette reads */
} rt_path_bsdf_draw;
void rt_path_bsdf_draw_of(const rt_trace_ctx *ctx, rt_path_state *ps, rt_rng *rng, rt_bsdf_kind kind,
                          rt_path_bsdf_draw *d);
/* After ps->beta took the sample's weight: the vertex becomes the one MIS
 * refers to (unless a pass), the bounce counts, the roulette plays, and
 * ps->r leaves along wi (world, unit); false when the roulette ends it. */
bool rt_path_vertex_advance(const rt_trace_ctx *ctx, rt_path_state *ps, const rt_surface *sf, rt_rng *rng,
                            rt_path_bsdf_draw *d, rt_vec3 wi, float pdf, bool delta, bool pass);

/* The probability that Russian roulette lets the path continue once its
 * bounce ps->bounces is sampled (beta, eta_scale updated): 1 when the
 * roulette does not play. It weighs w = max channel of beta x eta_scale
 * (exactly max channel of beta when eta_scale is 1, as on every path that
 * never refracted through a bsdf dielectric): min(w, 0.95) from rr_depth
 * bounces on; for rr_depth 0 (adaptive), w whenever w is below 1. */
static inline float rt_path_rr_probability(const rt_path_state *ps, int rr_depth)
{
    float w = rt_max3(ps->beta) * ps->eta_scale;
    if (rr_depth == 0)
        return w < 1.0f ? w : 1.0f;
    return ps->bounces >= rr_depth ? rt_fminf(w, 0.95f) : 1.0f;
}

/* Power heuristic with exponent 2 (Veach 1997, ch. 9): a^2 / (a^2 + b^2). */
static inline float rt_mis_power(float a, float b)
{
    if (!(a > 0.0f))
        return 0.0f;
    if (isinf(a))
        return 1.0f;
    float a2 = a * a, b2 = b * b;
    float w = a2 / (a2 + b2);
    return isfinite(w) ? w : (a > b ? 1.0f : 0.0f);
}

#endif
