/* volpath.c - the volumetric path tracer (rt/render/volpath.h): the `path`
 * integrator for scenes with participating media.
 *
 * Estimator: the null-scattering path integral (Miller, Georgiev, Jarosz,
 * "A null-scattering path integral formulation of light transport",
 * SIGGRAPH 2019) as pbrt-v4's VolPathIntegrator computes it (Pharr, Jakob,
 * Humphreys, 4th ed., 14.2), with RGB channels in place of wavelengths:
 * - one hero channel per path (uniform over R, G, B, from the sampler)
 *   samples every free flight against the majorant of its medium
 *   (rt_majorant_iter: one piece for a homogeneous medium, the grid's
 *   blocks for a grid); at a tentative collision the real coefficients
 *   choose absorption (the path ends), scattering or a null collision
 *   (it goes on) with the hero channel's probabilities;
 * - the path carries, beside its throughput beta, the ratios r_u and r_l
 *   of every channel's own path pdf (and of the light-sampling pdf) to the
 *   pdf it was sampled with, and divides each contribution by their
 *   channel average: the one-sample balance heuristic over the three
 *   channels' strategies (spectral MIS), so no channel's estimator blows
 *   up in a chromatic medium, combined with light/BSDF (phase) MIS;
 * - light sampling at every scattering event, on surfaces (the BSDF) and
 *   in media (the Henyey-Greenstein phase function, rt/render/phase.h):
 *   every light of the scene once (rt_light_sample_at), one emissive
 *   primitive of the light table by power (rt/render/emitter_sample.h)
 *   and the environment image by the light table; shadow rays pass null
 *   boundaries (aimed again at the light point past each) and
 *   alpha cut-outs and estimate the transmittance of the media between by
 *   ratio tracking with the same ratios (pbrt-v4's SampleLd, with its
 *   Russian roulette on low transmittance); other surfaces block them;
 * - media change at boundaries by the nested-media stack of
 *   rt/render/medium.h (priorities, false intersections; an index-matched
 *   smooth dielectric, as an index-matched subsurface material's
 *   boundary, is passed as a null boundary is): the medium is
 *   the interior medium of the stack's current entry, else the crossed
 *   boundary's exterior medium, else the scene's medium;
 * - Russian roulette on beta x eta_scale / average(r_u), as the surface
 *   path tracer's rule (rr_depth).
 * What it reuses unchanged: surfaces and BSDFs (rt/render/material_eval.h),
 * light sampling (rt/render/light.h, emitter_sample.h), nested
 * dielectrics' stack and absorption (rt/render/medium.h), the environment.
 * A camera inside closed boundaries starts in their medium (camera_medium).
 * What it leaves out (docs/media.md): the path draws its numbers from the
 * sample's rng stream (the hero channel from the sampler).
 */
#include "rt/render/volpath.h"

#include <math.h>

#include "rt/render/emitter_sample.h"
#include "rt/render/environment.h"
#include "rt/render/light.h"
#include "rt/render/material_eval.h"
#include "rt/render/medium.h"
#include "rt/render/pathtrace.h"
#include "rt/render/phase.h"
#include "rt/render/sampler.h"
#include "rt/render/volume.h"

#define DIM_HERO 0xffffffe0u /* the hero channel's sampler dimension, apart from the camera's and the path's */

static float ch(rt_vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
static float avg3(rt_vec3 v) { return (v.x + v.y + v.z) * (1.0f / 3.0f); }

/* exp(-maj dt) per channel, 1 where the majorant is 0 (also for dt = inf). */
static rt_vec3 seg_tr(rt_vec3 maj, float dt)
{
    return rt_v3(maj.x > 0.0f ? expf(-maj.x * dt) : 1.0f, maj.y > 0.0f ? expf(-maj.y * dt) : 1.0f,
                 maj.z > 0.0f ? expf(-maj.z * dt) : 1.0f);
}

typedef struct vp_state {
    rt_vec3 L, beta, r_u, r_l;
    int hero;               /* the channel that samples distances */
    uint32_t medium;        /* the participating medium the path is in (scene media index), RT_NONE */
    rt_medium_stack stack;  /* the boundaries it is inside */
    bool specular;          /* the last scattering was a delta lobe (or the camera): emission counts in full */
    rt_vec3 prev_p;         /* where it scattered last */
    float eta_scale;
    int depth, skips;
} vp_state;

/* The point where a path scatters, for light sampling: a surface with its
 * BSDF, or a point in a medium with its phase function. */
typedef struct vp_vertex {
    rt_vec3 p;
    const rt_surface *sf; /* NULL: in a medium */
    const rt_bsdf *b;
    rt_vec3 wo;           /* surface: local direction towards where the path came from */
    float g;              /* medium: the phase function's anisotropy */
    rt_vec3 d;            /* medium: the direction the path travelled */
} vp_vertex;

static rt_volume volume_of(const rt_scene *s, uint32_t medium)
{
    const rt_medium_def *m = &s->media[medium];
    if (m->kind == RT_MEDIUM_GRID)
        return rt_volume_grid(m->sigma_a, m->sigma_s, m->g, &m->grid, &m->world_to_index);
    return rt_volume_homogeneous(m->sigma_a, m->sigma_s, m->g);
}

/* Materials whose surface bounds a region: their crossings go on the stack. */
static bool is_boundary(const rt_material *m)
{
    return m->bsdf == RT_BSDF_NULL || m->bsdf == RT_BSDF_DIELECTRIC || m->interior_medium != RT_NONE;
}

/* The path crosses the surface of mat (front: entering): the stack and the
 * medium beyond. */
static void cross(const rt_scene *s, rt_medium_stack *st, uint32_t *medium, uint32_t mat, bool front)
{
    if (!is_boundary(&s->materials[mat]))
        return;
    rt_medium_stack_cross(st, mat, front);
    uint32_t top = rt_medium_current(st, s->materials);
    if (top != RT_NONE) {
        *medium = s->materials[top].interior_medium;
        return;
    }
    uint32_t ext = s->materials[mat].exterior_medium;
    *medium = ext != RT_NONE ? ext : s->environment.medium;
}

/* The boundaries a camera at r's origin is inside (pbrt and Mitsuba users
 * name the camera's medium; rt finds it): the boundary surfaces along r
 * out to infinity, crossed back from there to the origin, as a path coming
 * in from outside everything would cross them. Only in scenes with a
 * bounded medium (a material with an interior medium); a walk longer than
 * RT_PATH_LAYERS surfaces leaves the scene's medium. */
static void camera_medium(const rt_trace_ctx *ctx, const rt_ray *r, vp_state *ps)
{
    const rt_scene *s = ctx->state->scene;
    size_t m = 0;
    while (m < s->material_count && s->materials[m].interior_medium == RT_NONE)
        m++;
    if (m == s->material_count)
        return;
    uint32_t mat[RT_PATH_LAYERS];
    bool front[RT_PATH_LAYERS];
    int n = 0;
    rt_ray w = rt_ray_make(r->org, r->dir, 0.0f, INFINITY);
    for (int k = 0;; k++) {
        rt_hit hit;
        if (!rt_trace(ctx, &w, &hit))
            break;
        if (k == RT_PATH_LAYERS)
            return;
        rt_surface sf;
        rt_surface_at(ctx, &w, &hit, &sf);
        if (is_boundary(&s->materials[sf.material])) {
            mat[n] = sf.material;
            front[n++] = sf.front;
        }
        w = rt_ray_make(rt_surface_spawn(ctx, &sf, r->dir), r->dir, 0.0f, INFINITY);
    }
    while (n-- > 0)
        cross(s, &ps->stack, &ps->medium, mat[n], !front[n]);
}

/* The next surface along r that the alpha keeps, null boundaries included
 * (the other integrators see them cut away); r->tmin becomes its distance. */
static rt_surface_walk next_surface(const rt_trace_ctx *ctx, rt_ray *r, rt_rng *rng, rt_surface *sf)
{
    for (int layers = RT_PATH_LAYERS; layers > 0; layers--) {
        rt_hit hit;
        if (!rt_trace(ctx, r, &hit))
            return RT_WALK_MISS;
        rt_surface_at(ctx, r, &hit, sf);
        r->tmin = hit.t;
        if (ctx->state->scene->materials[sf->material].bsdf == RT_BSDF_NULL)
            return RT_WALK_SURFACE;
        float coverage;
        bool cut = rt_surface_cut_away(ctx, sf, &coverage);
        if (!cut && coverage < 1.0f && rt_rng_float(rng) >= coverage)
            cut = true; /* stochastic alpha blending */
        if (!cut)
            return RT_WALK_SURFACE;
    }
    return RT_WALK_TOO_DEEP;
}

/* The majorant walk both trackers share (pbrt-v4's SampleT_maj): tentative
 * collisions along o + t d drawn against the hero channel's majorant,
 * piece by piece, with T_maj the majorant's transmittance since the last
 * collision the caller took (it resets T_maj to 1 when it does). */
typedef struct maj_walk {
    rt_majorant_iter it;
    rt_vec3 T_maj, maj; /* maj: the current piece's majorant */
    float t, t1;        /* the walk's position and the current piece's end */
    bool in_piece;
    int h;
} maj_walk;

static void maj_walk_init(maj_walk *w, const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_min, float t_max, int h)
{
    rt_majorant_iter_init(&w->it, v, o, d, t_min, t_max);
    w->T_maj = rt_v3s(1.0f);
    w->in_piece = false;
    w->h = h;
}

/* The next tentative collision at *t (T_maj taken up to it): true; false
 * at the end of the walk (T_maj taken up to t_max). */
static bool maj_walk_next(maj_walk *w, rt_rng *rng, float *t)
{
    for (;;) {
        if (!w->in_piece) {
            float t0;
            if (!rt_majorant_next(&w->it, &t0, &w->t1, &w->maj))
                return false;
            if (!(ch(w->maj, w->h) > 0.0f)) {
                w->T_maj = rt_mul(w->T_maj, seg_tr(w->maj, w->t1 - t0));
                continue;
            }
            w->t = t0;
            w->in_piece = true;
        }
        float tn = w->t - log1pf(-rt_rng_float(rng)) / ch(w->maj, w->h);
        if (!(tn < w->t1)) {
            w->T_maj = rt_mul(w->T_maj, seg_tr(w->maj, w->t1 - w->t));
            w->in_piece = false;
            continue;
        }
        w->T_maj = rt_mul(w->T_maj, seg_tr(w->maj, tn - w->t));
        w->t = tn;
        *t = tn;
        return true;
    }
}

typedef enum vp_flight { FLIGHT_PASS, FLIGHT_SCATTER, FLIGHT_END } vp_flight;

/* Delta tracking with null collisions over [t_min, t_max) of r (unit
 * direction) in v, in the hero channel: FLIGHT_SCATTER at *t_out (beta and
 * r_u weighted by the scattering), FLIGHT_PASS when the path reaches t_max
 * (beta, r_u, r_l weighted by the majorant's transmittance), FLIGHT_END
 * when it is absorbed or its weight vanishes. */
static vp_flight free_flight(const rt_volume *v, const rt_ray *r, float t_min, float t_max, vp_state *ps, rt_rng *rng,
                             float *t_out)
{
    const int h = ps->hero;
    maj_walk walk;
    maj_walk_init(&walk, v, r->org, r->dir, t_min, t_max, h);
    float t;
    while (maj_walk_next(&walk, rng, &t)) {
        const rt_vec3 T_maj = walk.T_maj, maj = walk.maj;
        const float mh = ch(maj, h);
        float density = rt_volume_density(v, rt_madd(r->org, r->dir, t));
        rt_vec3 sa = rt_scale(v->sigma_a, density), ss = rt_scale(v->sigma_s, density);
        float u = rt_rng_float(rng) * mh;
        if (u < ch(sa, h))
            return FLIGHT_END; /* absorbed */
        if (u < ch(sa, h) + ch(ss, h)) {
            rt_vec3 wt = rt_scale(rt_mul(T_maj, ss), 1.0f / (ch(T_maj, h) * ch(ss, h)));
            ps->beta = rt_mul(ps->beta, wt);
            ps->r_u = rt_mul(ps->r_u, wt);
            *t_out = t;
            return rt_finite3(ps->beta) && rt_finite3(ps->r_u) ? FLIGHT_SCATTER : FLIGHT_END;
        }
        rt_vec3 sn = rt_vmax(rt_sub(maj, rt_add(sa, ss)), rt_v3s(0.0f)); /* null collision */
        float pdf = ch(T_maj, h) * ch(sn, h);
        if (!(pdf > 0.0f))
            return FLIGHT_END;
        ps->beta = rt_mul(ps->beta, rt_scale(rt_mul(T_maj, sn), 1.0f / pdf));
        ps->r_u = rt_mul(ps->r_u, rt_scale(rt_mul(T_maj, sn), 1.0f / pdf));
        ps->r_l = rt_mul(ps->r_l, rt_scale(rt_mul(T_maj, maj), 1.0f / pdf));
        walk.T_maj = rt_v3s(1.0f);
        if (!(rt_max3(ps->beta) > 0.0f && rt_max3(ps->r_u) > 0.0f) || !rt_finite3(ps->beta))
            return FLIGHT_END;
    }
    const rt_vec3 T_maj = walk.T_maj;
    float th = ch(T_maj, h);
    if (!(th > 0.0f))
        return FLIGHT_END;
    rt_vec3 w = rt_scale(T_maj, 1.0f / th);
    ps->beta = rt_mul(ps->beta, w);
    ps->r_u = rt_mul(ps->r_u, w);
    ps->r_l = rt_mul(ps->r_l, w);
    return FLIGHT_PASS;
}

/* Ratio tracking over [0, t_max) of o + t d in v with the hero channel's
 * majorant, into *T and the ratios *ru, *rl (pbrt-v4's SampleLd); false
 * when the transmittance is 0. */
static bool ratio_track(const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_max, int h, rt_rng *rng, rt_vec3 *T,
                        rt_vec3 *ru, rt_vec3 *rl)
{
    maj_walk walk;
    maj_walk_init(&walk, v, o, d, 0.0f, t_max, h);
    float t;
    while (maj_walk_next(&walk, rng, &t)) {
        const rt_vec3 T_maj = walk.T_maj, maj = walk.maj;
        const float mh = ch(maj, h);
        rt_vec3 st = rt_scale(rt_volume_sigma_t(v), rt_volume_density(v, rt_madd(o, d, t)));
        rt_vec3 sn = rt_vmax(rt_sub(maj, st), rt_v3s(0.0f));
        float pdf = ch(T_maj, h) * mh;
        *T = rt_mul(*T, rt_scale(rt_mul(T_maj, sn), 1.0f / pdf));
        *rl = rt_mul(*rl, rt_scale(rt_mul(T_maj, maj), 1.0f / pdf));
        *ru = rt_mul(*ru, rt_scale(rt_mul(T_maj, sn), 1.0f / pdf));
        walk.T_maj = rt_v3s(1.0f);
        rt_vec3 tr = rt_scale(*T, 1.0f / avg3(rt_add(*rl, *ru)));
        if (rt_max3(tr) < 0.05f) { /* roulette on a faint shadow ray */
            if (rt_rng_float(rng) < 0.75f)
                return false;
            *T = rt_scale(*T, 4.0f);
        }
        if (!(rt_max3(*T) > 0.0f) || !rt_finite3(*T))
            return false;
    }
    const rt_vec3 T_maj = walk.T_maj;
    float th = ch(T_maj, h);
    if (!(th > 0.0f))
        return false;
    rt_vec3 w = rt_scale(T_maj, 1.0f / th);
    *T = rt_mul(*T, w);
    *ru = rt_mul(*ru, w);
    *rl = rt_mul(*rl, w);
    return true;
}

/* What reaches vertex vx from along unit wi over dist (INFINITY: the
 * environment) through the media and null boundaries between: false when a
 * surface blocks it. Every segment is aimed at the sampled point from its
 * own origin (offset off the boundary it crossed) and stops just short of
 * it, as rt_shadow_ray does from a surface: sent along wi from an origin
 * offset along a boundary's normal, it would meet the light's plane past
 * the point, on the light itself. */
static bool shadow(const rt_trace_ctx *ctx, const vp_state *ps, const vp_vertex *vx, rt_vec3 wi, float dist,
                   rt_rng *rng, rt_vec3 *T, rt_vec3 *ru, rt_vec3 *rl)
{
    const rt_scene *s = ctx->state->scene;
    rt_ray r;
    if (vx->sf)
        r = rt_shadow_ray(ctx, vx->sf, wi, dist);
    else
        r = rt_ray_make(vx->p, wi, 0.0f, isfinite(dist) ? dist * (1.0f - 1e-4f) : INFINITY);
    const rt_vec3 target = rt_madd(vx->p, wi, isfinite(dist) ? dist : 0.0f); /* (unused for an infinite ray) */
    rt_medium_stack st = ps->stack;
    uint32_t medium = ps->medium;
    *T = *ru = *rl = rt_v3s(1.0f);
    for (int k = 0; k < RT_PATH_LAYERS; k++) {
        rt_surface sf;
        rt_ray seg = r;
        rt_surface_walk w = next_surface(ctx, &seg, rng, &sf);
        if (w == RT_WALK_TOO_DEEP)
            return false;
        if (medium != RT_NONE) {
            rt_volume v = volume_of(s, medium);
            if (!ratio_track(&v, r.org, r.dir, w == RT_WALK_SURFACE ? seg.tmin : r.tmax, ps->hero, rng, T, ru, rl))
                return false;
        }
        if (w == RT_WALK_SURFACE) /* a dielectric's own absorption inside it (rt/render/medium.h) */
            *T = rt_mul(*T, rt_medium_transmittance(
                                s->materials, rt_medium_of_segment(&st, s->materials, sf.material, sf.front), seg.tmin));
        if (w == RT_WALK_MISS)
            return true;
        if (s->materials[sf.material].bsdf != RT_BSDF_NULL &&
            !rt_medium_index_matched(&st, s->materials, sf.material, sf.front))
            return false;
        cross(s, &st, &medium, sf.material, sf.front);
        rt_vec3 o = rt_surface_spawn(ctx, &sf, wi);
        if (!isfinite(dist)) {
            r = rt_ray_make(o, wi, 0.0f, INFINITY);
            continue;
        }
        rt_vec3 to = rt_sub(target, o);
        float len = rt_length(to);
        if (!(rt_dot(to, wi) > 0.0f && len > 0.0f))
            return true; /* the boundary lies at the light point */
        r = rt_ray_make(o, rt_scale(to, 1.0f / len), 0.0f, len * (1.0f - 1e-4f));
    }
    return false;
}

/* The scattering at vx towards unit wi times its cosine (surfaces), and
 * the density sampling it would have drawn wi with. */
static rt_vec3 vertex_f(const vp_vertex *vx, rt_vec3 wi, float *pdf)
{
    if (!vx->sf) {
        float ph = rt_hg_pdf(vx->g, rt_dot(vx->d, wi));
        *pdf = ph;
        return rt_v3s(ph);
    }
    *pdf = 0.0f;
    if (!(rt_dot(wi, vx->b->ng) > 0.0f))
        return rt_v3s(0.0f); /* below the geometric surface */
    rt_vec3 wl = rt_bsdf_to_local(vx->b, wi);
    rt_vec3 f = rt_bsdf_eval(vx->b, vx->wo, wl, pdf);
    return rt_scale(f, rt_fmaxf(wl.z, 0.0f));
}

/* One light sample's contribution (to be multiplied by beta): li is the
 * radiance over the sampling pdf pdf_l (0 for a delta light, no MIS). */
static rt_vec3 light_term(const rt_trace_ctx *ctx, const vp_state *ps, const vp_vertex *vx, rt_vec3 wi, float dist,
                          rt_vec3 li, float pdf_l, rt_rng *rng)
{
    float pdf_f;
    rt_vec3 f = vertex_f(vx, wi, &pdf_f);
    if (!(rt_max3(f) > 0.0f && rt_max3(li) > 0.0f))
        return rt_v3s(0.0f);
    rt_vec3 T, ru, rl;
    if (!shadow(ctx, ps, vx, wi, dist, rng, &T, &ru, &rl))
        return rt_v3s(0.0f);
    rt_vec3 den = rt_mul(ps->r_u, rl);
    if (pdf_l > 0.0f)
        den = rt_add(den, rt_scale(rt_mul(ps->r_u, ru), pdf_f / pdf_l));
    float a = avg3(den);
    if (!(a > 0.0f))
        return rt_v3s(0.0f);
    return rt_scale(rt_mul(rt_mul(f, T), li), 1.0f / a);
}

/* Light sampling at vx: every light of the scene, and the environment
 * image when the light table samples it. */
static rt_vec3 sample_lights(const rt_trace_ctx *ctx, const vp_state *ps, const vp_vertex *vx, rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    rt_vec3 sum = rt_v3s(0.0f);
    for (size_t i = 0; i < s->light_count; i++) {
        const rt_light *l = &s->lights[i];
        float ux = rt_rng_float(rng), uy = rt_rng_float(rng);
        rt_light_sample ls;
        if (!rt_light_sample_at(ctx, l, vx->p, rt_v2(ux, uy), &ls))
            continue;
        bool quad = l->kind == RT_LIGHT_AREA && l->quad != RT_NONE;
        sum = rt_path_add_finite(sum, light_term(ctx, ps, vx, ls.wi, ls.dist, ls.li, quad ? ls.pdf : 0.0f, rng));
    }
    if (rt_path_samples_emitters(ctx)) { /* one emissive primitive of the light table, by power */
        float ul = rt_rng_float(rng), ux = rt_rng_float(rng), uy = rt_rng_float(rng);
        rt_emitter_sample es;
        if (rt_emitter_sample_at(ctx, vx->p, ul, rt_v2(ux, uy), &es)) {
            rt_vec3 li = rt_scale(es.Le, 1.0f / es.pdf);
            sum = rt_path_add_finite(sum, light_term(ctx, ps, vx, es.wi, es.dist, li, es.pdf, rng));
        }
    }
    if (rt_path_samples_env(ctx)) {
        float ux = rt_rng_float(rng), uy = rt_rng_float(rng);
        rt_vec3 d;
        float pdf_l;
        if (rt_light_table_sample_env(ctx->state->light_table, rt_v2(ux, uy), &d, &pdf_l) && pdf_l > 0.0f) {
            rt_vec3 li = rt_scale(rt_environment(s, d), 1.0f / pdf_l);
            sum = rt_path_add_finite(sum, light_term(ctx, ps, vx, d, INFINITY, li, pdf_l, rng));
        }
    }
    return sum;
}

/* Emission Le reached by a path whose last scattering could have sampled
 * it as a light with density pdf_l (0: it could not). */
static void add_emission(vp_state *ps, rt_vec3 Le, float pdf_l)
{
    rt_vec3 den = ps->r_u;
    if (!ps->specular && pdf_l > 0.0f)
        den = rt_add(den, rt_scale(ps->r_l, pdf_l));
    float a = avg3(den);
    if (a > 0.0f)
        ps->L = rt_path_add_finite(ps->L, rt_scale(rt_mul(ps->beta, Le), 1.0f / a));
}

/* Russian roulette on the throughput the channels' average pdf ratio
 * leaves (rr_depth as the surface path tracer's); false: the path ends. */
static bool roulette(const rt_trace_ctx *ctx, vp_state *ps, rt_rng *rng)
{
    int rr_depth = ctx->state->settings->rr_depth;
    float a = avg3(ps->r_u);
    if (!(a > 0.0f) || !rt_finite3(ps->beta) || !(rt_max3(ps->beta) > 0.0f))
        return false;
    float w = rt_max3(ps->beta) * ps->eta_scale / a;
    float q = 1.0f;
    if (rr_depth == 0)
        q = ps->depth > 1 && w < 1.0f ? w : 1.0f;
    else if (ps->depth >= rr_depth)
        q = rt_fminf(w, 0.95f);
    if (q >= 1.0f)
        return true;
    if (rt_rng_float(rng) >= q)
        return false;
    ps->beta = rt_scale(ps->beta, 1.0f / q);
    return true;
}

/* The surface the path reached: emission, light sampling, the BSDF's next
 * direction into *r. False when the path ends. */
static bool surface_vertex(const rt_trace_ctx *ctx, vp_state *ps, const rt_surface *sf, rt_ray *r, int max_depth,
                           rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    const rt_material *m = &s->materials[sf->material];
    rt_vec3 Le = (ctx->state->material_needs[sf->material] & RT_MATERIAL_EMITS) ? rt_surface_emission(ctx, sf)
                                                                                 : rt_v3s(0.0f);
    bool emissive = rt_max3(rt_scale(m->emission, m->emission_strength)) > 0.0f;
    uint32_t light = emissive ? rt_area_light_of_prim(s, ctx->state->light_table, sf->prim) : RT_NONE;
    if (rt_max3(Le) > 0.0f) {
        float d2 = rt_length2(rt_sub(sf->p, ps->prev_p)), pdf_l;
        if (light != RT_NONE)
            pdf_l = rt_area_light_pdf(&s->lights[light], ps->prev_p, r->dir, sqrtf(d2));
        else /* an emitter of the light table, as sample_lights draws it */
            pdf_l = rt_emitter_pdf(ctx, sf->prim, ps->prev_p, r->dir, d2, sf->ng);
        add_emission(ps, Le, isfinite(pdf_l) ? pdf_l : 0.0f);
    }
    if (light != RT_NONE)
        return false; /* an area light's quad reflects nothing */
    if (m->unlit) {
        rt_vec4 c = rt_surface_base_color(ctx, sf);
        add_emission(ps, rt_v3(c.x, c.y, c.z), 0.0f);
        return false;
    }
    if (ps->depth++ >= max_depth)
        return false;
    rt_bsdf b;
    rt_bsdf_from_surface(ctx, sf, &b);
    if (rt_medium_is_medium(m)) { /* the index ratio to the medium beyond */
        float eta = rt_medium_outside_ior(&ps->stack, s->materials, sf->material, sf->front) / m->ior;
        rt_bsdf_set_eta(&b, sf->front ? eta : 1.0f / eta);
    }
    rt_vec3 wo = rt_bsdf_to_local(&b, sf->wo);
    if (b.kind != RT_BSDF_KIND_LAMBERT)
        rt_bsdf_set_wo(&b, wo);
    if (!(wo.z > 0.0f))
        return false;
    vp_vertex vx = {.p = sf->p, .sf = sf, .b = &b, .wo = wo};
    ps->L = rt_path_add_finite(ps->L, rt_mul(ps->beta, sample_lights(ctx, ps, &vx, rng)));
    float ux = rt_rng_float(rng), uy = rt_rng_float(rng), ulobe = rt_rng_float(rng);
    rt_bsdf_sample bs;
    if (!rt_bsdf_sample_dir(&b, wo, rt_v2(ux, uy), ulobe, &bs))
        return false;
    rt_vec3 wi = rt_normalize(rt_bsdf_to_world(&b, bs.wi));
    float side = rt_dot(wi, sf->ng);
    if (bs.wi.z > 0.0f ? !(side > 0.0f) : !(side < 0.0f))
        return false; /* the shading normal disagrees with the geometry */
    ps->beta = rt_mul(ps->beta, bs.weight);
    ps->specular = bs.delta || !(bs.pdf > 0.0f);
    ps->r_l = ps->specular ? ps->r_u : rt_scale(ps->r_u, 1.0f / bs.pdf);
    ps->prev_p = sf->p;
    if (bs.wi.z < 0.0f) { /* transmitted: into or out of what the surface bounds */
        cross(s, &ps->stack, &ps->medium, sf->material, sf->front);
        if (b.kind == RT_BSDF_KIND_DIELECTRIC && !b.thin)
            ps->eta_scale /= b.eta * b.eta;
    }
    *r = rt_ray_make(rt_surface_spawn(ctx, sf, wi), wi, 0.0f, INFINITY);
    return roulette(ctx, ps, rng);
}

rt_vec3 rt_radiance_volpath(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    const rt_scene *s = ctx->state->scene;
    const rt_settings *set = ctx->state->settings;
    int max_depth = set->max_depth > 0 && set->max_depth < RT_PATH_HARD_LIMIT ? set->max_depth : RT_PATH_HARD_LIMIT;
    rt_ray r = *ray;
    float len = rt_length(r.dir);
    if (!(len > 0.0f) || !isfinite(len))
        return rt_v3s(0.0f);
    r.dir = rt_scale(r.dir, 1.0f / len);
    r.tmin *= len;
    r.tmax *= len;
    vp_state ps = {.L = rt_v3s(0.0f), .beta = rt_v3s(1.0f), .r_u = rt_v3s(1.0f), .r_l = rt_v3s(1.0f),
                   .medium = s->environment.medium, .specular = true, .prev_p = r.org, .eta_scale = 1.0f,
                   .skips = RT_PATH_HARD_LIMIT};
    rt_medium_stack_init(&ps.stack);
    camera_medium(ctx, &r, &ps);
    float uh = rt_sample_1d((rt_sampler_kind)set->sampler, (uint32_t)set->samples, rng, DIM_HERO);
    ps.hero = uh < 1.0f / 3.0f ? 0 : (uh < 2.0f / 3.0f ? 1 : 2);
    for (;;) {
        rt_ray seg = r;
        rt_surface sf;
        rt_surface_walk w = next_surface(ctx, &seg, rng, &sf);
        if (w == RT_WALK_TOO_DEEP)
            break;
        float t_hit = w == RT_WALK_SURFACE ? seg.tmin : r.tmax;
        if (ps.medium != RT_NONE) {
            rt_volume v = volume_of(s, ps.medium);
            float t = 0.0f;
            vp_flight f = free_flight(&v, &r, r.tmin, t_hit, &ps, rng, &t);
            if (f == FLIGHT_END)
                break;
            if (f == FLIGHT_SCATTER) {
                if (ps.depth++ >= max_depth)
                    break;
                rt_vec3 p = rt_madd(r.org, r.dir, t);
                vp_vertex vx = {.p = p, .sf = NULL, .g = v.g, .d = r.dir};
                ps.L = rt_path_add_finite(ps.L, rt_mul(ps.beta, sample_lights(ctx, &ps, &vx, rng)));
                float u1 = rt_rng_float(rng), u2 = rt_rng_float(rng), pdf = 0.0f;
                rt_vec3 wi = rt_hg_sample(v.g, r.dir, u1, u2, &pdf);
                if (!(pdf > 0.0f))
                    break;
                ps.r_l = rt_scale(ps.r_u, 1.0f / pdf); /* (the phase function is sampled exactly: beta stays) */
                ps.specular = false;
                ps.prev_p = p;
                r = rt_ray_make(p, wi, 0.0f, INFINITY);
                if (!roulette(ctx, &ps, rng))
                    break;
                continue;
            }
        }
        if (w == RT_WALK_MISS) {
            const rt_light_table *lt = ctx->state->light_table;
            float pdf_l = rt_path_samples_env(ctx) ? rt_light_table_env_pdf(lt, r.dir) : 0.0f;
            add_emission(&ps, rt_environment(s, r.dir), pdf_l);
            break;
        }
        const rt_material *m = &s->materials[sf.material];
        uint32_t absorber = rt_medium_of_segment(&ps.stack, s->materials, sf.material, sf.front);
        if (absorber != RT_NONE) /* a dielectric's Beer-Lambert absorption (rt/render/medium.h) */
            ps.beta = rt_mul(ps.beta, rt_medium_transmittance(s->materials, absorber, t_hit));
        if (m->bsdf == RT_BSDF_NULL || rt_medium_index_matched(&ps.stack, s->materials, sf.material, sf.front) ||
            (is_boundary(m) && rt_medium_stack_false_hit(&ps.stack, s->materials, sf.material, sf.front))) {
            /* no surface here: straight on into the medium beyond */
            cross(s, &ps.stack, &ps.medium, sf.material, sf.front);
            if (--ps.skips < 0)
                break;
            r = rt_ray_make(rt_surface_spawn(ctx, &sf, r.dir), r.dir, 0.0f, INFINITY);
            continue;
        }
        if (!surface_vertex(ctx, &ps, &sf, &r, max_depth, rng))
            break;
    }
    return rt_finite3(ps.L) ? ps.L : rt_v3s(0.0f);
}

bool rt_volpath_aov_event(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng, rt_vec3 *albedo, rt_vec3 *p)
{
    const rt_scene *s = ctx->state->scene;
    rt_ray r = *ray;
    float len = rt_length(r.dir);
    if (!(len > 0.0f) || !isfinite(len))
        return false;
    r.dir = rt_scale(r.dir, 1.0f / len);
    r.tmin *= len;
    r.tmax *= len;
    vp_state ps = {.medium = s->environment.medium};
    rt_medium_stack_init(&ps.stack);
    camera_medium(ctx, &r, &ps);
    int h = (int)(rt_rng_float(rng) * 3.0f); /* the channel whose distances decide */
    h = h > 2 ? 2 : h;
    for (int k = 0; k < RT_PATH_LAYERS; k++) {
        rt_ray seg = r;
        rt_surface sf;
        rt_surface_walk w = next_surface(ctx, &seg, rng, &sf);
        if (w == RT_WALK_TOO_DEEP)
            return false;
        if (ps.medium != RT_NONE) { /* delta tracking to the first real collision */
            rt_volume v = volume_of(s, ps.medium);
            maj_walk walk;
            maj_walk_init(&walk, &v, r.org, r.dir, r.tmin, w == RT_WALK_SURFACE ? seg.tmin : r.tmax, h);
            float t;
            while (maj_walk_next(&walk, rng, &t)) {
                rt_vec3 q = rt_madd(r.org, r.dir, t), st = rt_volume_sigma_t(&v);
                if (rt_rng_float(rng) * ch(walk.maj, h) < ch(st, h) * rt_volume_density(&v, q)) {
                    *albedo = rt_v3(st.x > 0.0f ? v.sigma_s.x / st.x : 0.0f, st.y > 0.0f ? v.sigma_s.y / st.y : 0.0f,
                                    st.z > 0.0f ? v.sigma_s.z / st.z : 0.0f);
                    *p = q;
                    return true;
                }
            }
        }
        if (w == RT_WALK_MISS)
            return false;
        const rt_material *m = &s->materials[sf.material];
        if (!(m->bsdf == RT_BSDF_NULL ||
              (is_boundary(m) && rt_medium_stack_false_hit(&ps.stack, s->materials, sf.material, sf.front))))
            return false; /* a surface first */
        cross(s, &ps.stack, &ps.medium, sf.material, sf.front);
        r = rt_ray_make(rt_surface_spawn(ctx, &sf, r.dir), r.dir, 0.0f, INFINITY);
    }
    return false;
}
