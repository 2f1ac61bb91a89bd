/* light.c - light arriving at a surface point: sampling the scene's
 * lights, shadow transmittance, and the path tracer's table of emitters.
 *
 * Area lights that are rectangles are sampled uniformly by the solid angle
 * they subtend (Urena, Fajardo and King 2013, rt/render/spherical.h; pdf
 * 1 / solid angle) from points that see them large (nearer the centre than
 * the diameter, or an estimate A cos / d^2 from the centre of at least
 * 0.1 sr) when the exact solid angle is
 * within pbrt-v4's range (3e-4 to 6.22 sr); other parallelograms, and
 * rectangles seen small or outside the range, are sampled uniformly by
 * area and converted to solid angle (pdf = d^2 / (A cos theta_l)).
 * Emissive triangles of the table likewise (Arvo 1995, spherical
 * triangles; rt_tri_solid, seen large when area / d^2 from the centroid
 * is at least 0.1). The decision is a function of the
 * point alone, so the pdf of a BSDF-sampled hit on the light (MIS) is
 * evaluated from the previous vertex by the same code. Spot cones use
 * glTF's smooth falloff (KHR_lights_punctual) and its recommended range
 * window.
 *
 * The light table (pbrt-v3, Pharr, Jakob, Humphreys, ch. 14.2 and 14.5):
 * emissive primitives are picked in proportion to their power (area x
 * mean emitted radiance, twice for double-sided ones) from a cumulative
 * distribution; the environment image by luminance x sin(theta),
 * piecewise constant over its latitude-longitude cells (pbrt-v3 14.2.4,
 * "Infinite Area Lights"): a row, then a cell within the row, then a
 * uniform point in the cell.
 */
#include "rt/render/light.h"

#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/render/environment.h"
#include "rt/render/material_eval.h"
#include "rt/render/spherical.h"

/* The unit direction and the distance from p to the point q on a light,
 * into ls, and their squared distance; false when they coincide. */
static bool toward(rt_vec3 p, rt_vec3 q, rt_light_sample *ls, float *d2)
{
    rt_vec3 d = rt_sub(q, p);
    *d2 = rt_length2(d);
    if (!(*d2 > 0.0f))
        return false;
    float dist = sqrtf(*d2);
    ls->wi = rt_scale(d, 1.0f / dist);
    ls->dist = dist;
    return true;
}

/* Solid-angle sampling costs about 400 instructions a sample more than
 * area sampling (the set-up's square roots and atan2, the sampler's sin and
 * cos) and gains little where the light is small and far, which area
 * sampling already does nearly uniformly in solid angle: below an
 * estimated 0.1 sr it is left to area sampling. On the shared Cornell box
 * this keeps the efficiency level (0.1 sr: 1.00x; every point: 0.91x) and
 * with its lamp 20 units above the tall block it gives 1.74x
 * (docs/performance.md, "Solid-angle light sampling"). */
#define SOLID_ANGLE_MIN_ESTIMATE 0.1f

/* Whether p sees a planar emitter (n its normal times its area, d from p
 * to its centre, size2 the square of its diameter) from the front and
 * large: nearer its centre than its diameter (where the estimate below
 * fails: a point close to the plane near an edge sees a large solid angle
 * at a grazing angle to the centre), or under an estimated solid angle
 * (n . -d) / |d|^3 of at least SOLID_ANGLE_MIN_ESTIMATE. */
static inline bool looks_large(rt_vec3 n, rt_vec3 d, float size2)
{
    float nd = -rt_dot(n, d), d2 = rt_length2(d);
    return nd > 0.0f && (d2 <= size2 || nd >= SOLID_ANGLE_MIN_ESTIMATE * d2 * sqrtf(d2));
}

/* Area light l (n = edge_u x edge_v) set up for solid-angle sampling from
 * p: true when p sees it from the front and large (looks_large), it is a
 * rectangle (edges perpendicular to 1e-5), and its solid angle is in the
 * range where that is used. rt_light_sample_at and rt_area_light_pdf both
 * decide by it. */
static bool area_light_solid(const rt_light *l, rt_vec3 n, rt_vec3 p, rt_sph_rect *r)
{
    rt_vec3 d = rt_sub(rt_madd(rt_madd(l->position, l->edge_u, 0.5f), l->edge_v, 0.5f), p);
    float lu = rt_length2(l->edge_u), lv = rt_length2(l->edge_v), uv = rt_dot(l->edge_u, l->edge_v);
    if (!looks_large(n, d, lu + lv))
        return false;
    if (!(uv * uv <= 1e-10f * lu * lv))
        return false; /* not a rectangle */
    return rt_sph_rect_init(r, l->position, l->edge_u, l->edge_v, p) && rt_sph_in_range(r->S);
}

/* The solid-angle pdf of uniform area sampling of an area light (n =
 * edge_u x edge_v, area = |n|) towards unit direction d at distance dist;
 * 0 from behind. */
static inline float area_light_area_pdf(rt_vec3 n, float area, rt_vec3 d, float dist)
{
    if (!(area > 0.0f))
        return 0.0f;
    float cos_l = -rt_dot(n, d) / area;
    if (!(cos_l > 0.0f))
        return 0.0f;
    float p = dist * dist / (area * cos_l);
    return isfinite(p) ? p : 0.0f;
}

bool rt_light_sample_at(const rt_trace_ctx *ctx, const rt_light *l, rt_vec3 p, rt_vec2 u, rt_light_sample *ls)
{
    (void)ctx;
    rt_vec3 power = rt_scale(l->color, l->intensity);
    switch (l->kind) {
    case RT_LIGHT_POINT:
    case RT_LIGHT_SPOT: {
        float d2;
        if (!toward(p, l->position, ls, &d2))
            return false;
        const float dist = ls->dist;
        float atten = 1.0f / d2;
        if (l->kind == RT_LIGHT_SPOT) {
            float cd = rt_dot(rt_normalize(l->direction), rt_neg(ls->wi));
            float co = cosf(l->outer_cone), ci = cosf(l->inner_cone);
            float x = ci > co ? rt_clampf((cd - co) / (ci - co), 0.0f, 1.0f) : (cd >= co ? 1.0f : 0.0f);
            atten *= x * x;
        }
        if (l->range > 0.0f) { /* glTF's recommended smooth window */
            float r = dist / l->range, r4 = r * r * r * r;
            float win = rt_clampf(1.0f - r4, 0.0f, 1.0f);
            atten *= win * win;
        }
        if (!(atten > 0.0f))
            return false;
        ls->li = rt_scale(power, atten);
        return true;
    }
    case RT_LIGHT_DIRECTIONAL:
        ls->wi = rt_neg(rt_normalize(l->direction));
        ls->dist = INFINITY;
        ls->li = power;
        return rt_length2(ls->wi) > 0.0f;
    case RT_LIGHT_AREA:
    default: {
        rt_vec3 nl = rt_cross(l->edge_u, l->edge_v);
        float area = rt_length(nl);
        if (!(area > 0.0f))
            return false;
        rt_sph_rect sr;
        bool solid = area_light_solid(l, nl, p, &sr);
        rt_vec3 n = nl;
        nl = rt_scale(nl, 1.0f / area);
        if (solid) { /* uniform in solid angle: radiance x S */
            float dist;
            ls->wi = rt_sph_rect_sample(&sr, u, &dist);
            ls->dist = dist;
            if (!(dist > 0.0f && isfinite(dist)) || !(-rt_dot(nl, ls->wi) > 0.0f))
                return false;
            ls->li = rt_scale(power, sr.S);
            ls->pdf = 1.0f / sr.S;
            return true;
        }
        rt_vec3 q = rt_add(l->position, rt_add(rt_scale(l->edge_u, u.x), rt_scale(l->edge_v, u.y)));
        float d2;
        if (!toward(p, q, ls, &d2))
            return false;
        float cos_l = -rt_dot(nl, ls->wi);
        if (!(cos_l > 0.0f))
            return false; /* behind the one-sided emitter */
        ls->li = rt_scale(power, area * cos_l / d2);
        ls->pdf = area_light_area_pdf(n, area, ls->wi, ls->dist);
        return true;
    }
    }
}

/* The shadow ray towards a light sample (rt/render/light.h). */
rt_ray rt_shadow_ray(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist)
{
    rt_vec3 o = rt_surface_spawn(ctx, sf, wi);
    if (!isfinite(dist))
        return rt_ray_make(o, wi, 0.0f, INFINITY);
    /* Aimed from the offset origin at the sampled point itself, and
     * stopped just short of it (area lights are geometry too). Along wi
     * from o, the ray would meet the light's plane off the point, short of
     * dist by the offset over the cosine there: from a surface facing a
     * light close above it, most rays ran into the light's own quad and
     * counted as shadowed (test_shadow_rays_reach_the_light). */
    rt_vec3 to = rt_sub(rt_madd(sf->p, wi, dist), o);
    float len = rt_length(to);
    if (!(len > 0.0f))
        return rt_ray_make(o, wi, 0.0f, 0.0f);
    return rt_ray_make(o, rt_scale(to, 1.0f / len), 0.0f, len * (1.0f - 1e-4f));
}

/* What passes a surface a shadow ray met (material m, hit h), under the
 * plain rule (direct, whitted: transmissive surfaces pass their
 * transmission colour, cut-outs pass, blended surfaces 1 - alpha) or the
 * path tracer's (path: only cut-outs, the share of blended surfaces a path
 * steps past and, with thin_passes, smooth thin-walled panes' straight-
 * through lobe); zero where it blocks. */
static rt_vec3 plain_pass(const rt_trace_ctx *ctx, const rt_ray *r, const rt_hit *h, const rt_material *m)
{
    bool transmits = m->transmission > 0.0f;
    rt_vec3 glass = rt_scale(m->transmission_color, m->transmission);
    if (m->alpha_mode == RT_ALPHA_OPAQUE) /* no surface record needed */
        return transmits ? glass : rt_v3s(0);
    rt_surface s2;
    rt_surface_at(ctx, r, h, &s2);
    float coverage;
    if (rt_surface_cut_away(ctx, &s2, &coverage))
        return rt_v3s(1);
    if (transmits)
        return glass;
    return coverage < 1.0f ? rt_v3s(1.0f - coverage) : rt_v3s(0);
}

/* What a path that reached surface s2 along the shadow ray would carry on
 * along it: the straight-through lobe's weight, under the path tracer's own
 * tests (rt_path_vertex_begin: a lit surface seen from above its frame;
 * rt_path_vertex_end: the direction leaves through the geometric surface);
 * zero for anything else. */
static rt_vec3 straight_through(const rt_trace_ctx *ctx, const rt_surface *s2)
{
    const rt_material *m = &ctx->state->scene->materials[s2->material];
    if (m->unlit)
        return rt_v3s(0.0f);
    rt_bsdf b;
    rt_bsdf_from_surface(ctx, s2, &b);
    rt_vec3 wo = rt_bsdf_to_local(&b, s2->wo);
    rt_vec3 w = rt_bsdf_straight_through(&b, wo);
    if (!(rt_max3(w) > 0.0f))
        return rt_v3s(0.0f);
    rt_vec3 wi = rt_normalize(rt_bsdf_to_world(&b, rt_normalize(rt_neg(wo))));
    return rt_dot(wi, s2->ng) < 0.0f ? w : rt_v3s(0.0f);
}

static rt_vec3 path_pass(const rt_trace_ctx *ctx, const rt_ray *r, const rt_hit *h, const rt_material *m,
                         bool thin_passes)
{
    /* (the glTF BSDF is thin-walled only with transmission: material_eval.c) */
    bool may_pass = thin_passes && m->bsdf == RT_BSDF_GLTF && m->thin_walled && m->transmission > 0.0f;
    if (m->alpha_mode == RT_ALPHA_OPAQUE && !may_pass)
        return rt_v3s(0); /* no surface record needed */
    rt_surface s2;
    rt_surface_at(ctx, r, h, &s2);
    float coverage = 1.0f;
    if (m->alpha_mode != RT_ALPHA_OPAQUE && rt_surface_cut_away(ctx, &s2, &coverage))
        return rt_v3s(1);
    /* kept with probability coverage (stochastic blending), which a path
     * then scatters on; the rest it steps past */
    rt_vec3 pass = may_pass ? straight_through(ctx, &s2) : rt_v3s(0);
    bool passes = rt_max3(pass) > 0.0f;
    if (coverage < 1.0f)
        return passes ? rt_add(rt_v3s(1.0f - coverage), rt_scale(pass, coverage)) : rt_v3s(1.0f - coverage);
    return passes ? pass : rt_v3s(0);
}

/* The one shadow walk: from sf towards wi, short of dist (rt_shadow_ray),
 * past every surface by the rule's pass (path_rule: the path tracer's);
 * the product of what passed, zero once something blocks. */
static rt_vec3 shadow_walk(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist, bool path_rule,
                           bool thin_passes)
{
    rt_ray r = rt_shadow_ray(ctx, sf, wi, dist);
    if (ctx->ray_count)
        (*ctx->ray_count)++;
    if (!ctx->state->shadows_need_shading)
        return rt_kdtree_occluded(ctx->state->tree, &r) ? rt_v3s(0) : rt_v3s(1);
    const rt_scene *s = ctx->state->scene;
    rt_vec3 tr = rt_v3s(1);
    for (int layer = 0; layer < 64; layer++) {
        rt_hit h;
        if (!rt_kdtree_intersect(ctx->state->tree, &r, &h))
            return tr;
        uint32_t mi = rt_prim_material(s, h.prim);
        RT_DCHECK(mi < s->material_count);
        const rt_material *m = &s->materials[mi];
        rt_vec3 pass = path_rule ? path_pass(ctx, &r, &h, m, thin_passes) : plain_pass(ctx, &r, &h, m);
        if (!(rt_max3(pass) > 0.0f))
            return rt_v3s(0);
        tr = rt_mul(tr, pass); /* (times 1, exactly, past a cut-out) */
        if (rt_max3(tr) <= 0.0f)
            return rt_v3s(0);
        r.tmin = h.t; /* continue past this surface */
    }
    return rt_v3s(0);
}

rt_vec3 rt_shadow_transmittance(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist)
{
    return shadow_walk(ctx, sf, wi, dist, false, false);
}

rt_vec3 rt_shadow_path_transmittance(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist,
                                     bool thin_passes)
{
    return shadow_walk(ctx, sf, wi, dist, true, thin_passes);
}

/* ------------------------------------------------------------ light table */

static bool emissive_material(const rt_scene *s, uint32_t m, float *power)
{
    RT_DCHECK(m < s->material_count); /* rt_scene_validate */
    const rt_material *mt = &s->materials[m];
    rt_vec3 e = rt_scale(mt->emission, mt->emission_strength);
    float p = (e.x + e.y + e.z) * (1.0f / 3.0f);
    if (!(p > 0.0f) || !isfinite(p))
        return false;
    *power = mt->double_sided ? 2.0f * p : p;
    return true;
}

static float prim_area(const rt_scene *s, uint32_t prim)
{
    uint32_t i;
    switch (rt_prim_kind_of(s, prim, &i)) {
    case RT_PRIM_TRIANGLE: {
        rt_vec3 a = rt_tri_vertex(s, i, 0), b = rt_tri_vertex(s, i, 1), c = rt_tri_vertex(s, i, 2);
        return 0.5f * rt_length(rt_cross(rt_sub(b, a), rt_sub(c, a)));
    }
    case RT_PRIM_SPHERE: {
        float r = s->spheres.radius[i];
        return 4.0f * RT_PI * r * r;
    }
    case RT_PRIM_QUAD:
    default: {
        const rt_quads *q = &s->quads;
        rt_vec3 u = rt_v3(q->ux[i], q->uy[i], q->uz[i]), v = rt_v3(q->vx[i], q->vy[i], q->vz[i]);
        return rt_length(rt_cross(u, v));
    }
    }
}

void rt_light_table_free(rt_light_table *t)
{
    if (!t)
        return;
    free(t->prim);
    free(t->cdf);
    free(t->area);
    free(t->prim_pdf);
    free(t->prim_sel);
    free(t->quad_light);
    free(t->env_row_cdf);
    free(t->env_col_cdf);
    free(t->env_cell);
    memset(t, 0, sizeof *t);
}

/* The environment's sampling distribution: luminance (the largest over the
 * cell) x sin(theta) per cell of a grid at the image's resolution (at most
 * 1024 x 512), piecewise constant in (u, v) (pbrt-v3 14.2.4, "Infinite Area Lights"). false =
 * out of memory. */
static bool build_env(rt_light_table *t, const rt_scene *s)
{
    const rt_scene_environment *st = &s->environment;
    uint32_t tex = st->environment_texture;
    if (tex == RT_NONE || !(st->environment_strength > 0.0f))
        return true;
    RT_DCHECK(tex < s->texture_count);
    int w = 256, h = 128;
    const rt_texture *tx = &s->textures[tex];
    if (tx->kind == RT_TEX_IMAGE) {
        w = s->images[tx->image].width;
        h = s->images[tx->image].height;
        w = w < 1 ? 1 : (w > 1024 ? 1024 : w);
        h = h < 1 ? 1 : (h > 512 ? 512 : h);
    }
    size_t n = (size_t)w * (size_t)h;
    t->env_row_cdf = rt_alloc((size_t)h, sizeof *t->env_row_cdf);
    t->env_col_cdf = rt_alloc(n, sizeof *t->env_col_cdf);
    t->env_cell = rt_alloc(n, sizeof *t->env_cell);
    double *row = rt_alloc((size_t)h, sizeof *row);
    if (!t->env_row_cdf || !t->env_col_cdf || !t->env_cell || !row) {
        free(row);
        return false;
    }
    double total = 0.0;
    for (int j = 0; j < h; j++) {
        float v = ((float)j + 0.5f) / (float)h;
        float sin_t = sinf(v * RT_PI);
        double acc = 0.0;
        float *cdf = t->env_col_cdf + (size_t)j * (size_t)w, *cell = t->env_cell + (size_t)j * (size_t)w;
        for (int i = 0; i < w; i++) {
            /* the largest of 3 x 3 lookups over the cell: bilinear
             * filtering spreads a bright texel into its neighbours' cells */
            float lum = 0.0f;
            for (int b = 0; b < 3; b++)
                for (int a = 0; a < 3; a++) {
                    float uu = ((float)i + 0.5f * (float)a) / (float)w;
                    float vv = ((float)j + 0.5f * (float)b) / (float)h;
                    rt_vec3 e = rt_environment(s, rt_latlong_to_dir(rt_v2(uu, vv)));
                    float l = rt_luminance(rt_vmax(e, rt_v3s(0.0f)));
                    if (l > lum && isfinite(l))
                        lum = l;
                }
            double wgt = (double)lum * (double)sin_t;
            if (!(wgt > 0.0) || !isfinite(wgt))
                wgt = 0.0;
            acc += wgt;
            cell[i] = (float)wgt;
            cdf[i] = (float)acc;
        }
        for (int i = 0; i < w; i++)
            cdf[i] = acc > 0.0 ? (float)(cdf[i] / acc) : (float)(i + 1) / (float)w;
        cdf[w - 1] = 1.0f;
        row[j] = acc;
        total += acc;
    }
    if (!(total > 0.0) || !isfinite(total)) { /* a black environment: nothing to sample */
        free(row);
        free(t->env_row_cdf);
        free(t->env_col_cdf);
        free(t->env_cell);
        t->env_row_cdf = t->env_col_cdf = t->env_cell = NULL;
        return true;
    }
    double acc = 0.0;
    for (int j = 0; j < h; j++) {
        acc += row[j];
        t->env_row_cdf[j] = (float)(acc / total);
        for (int i = 0; i < w; i++)
            t->env_cell[(size_t)j * (size_t)w + (size_t)i] = (float)(t->env_cell[(size_t)j * (size_t)w + (size_t)i] / total);
    }
    t->env_row_cdf[h - 1] = 1.0f;
    t->env_w = w;
    t->env_h = h;
    free(row);
    return true;
}

/* Index of the first of n cumulative values above u. */
static size_t cdf_pick(const float *cdf, size_t n, float u)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (cdf[mid] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

float rt_light_table_env_pdf(const rt_light_table *t, rt_vec3 d)
{
    if (!t || t->env_w <= 0)
        return 0.0f;
    float sin_t = sqrtf(rt_fmaxf(0.0f, 1.0f - d.y * d.y));
    if (!(sin_t > 0.0f))
        return 0.0f;
    rt_vec2 uv = rt_latlong_from_dir(d);
    int i = (int)(uv.x * (float)t->env_w), j = (int)(uv.y * (float)t->env_h);
    i = i < 0 ? 0 : (i >= t->env_w ? t->env_w - 1 : i);
    j = j < 0 ? 0 : (j >= t->env_h ? t->env_h - 1 : j);
    float p = t->env_cell[(size_t)j * (size_t)t->env_w + (size_t)i] * (float)t->env_w * (float)t->env_h /
              (2.0f * RT_PI * RT_PI * sin_t);
    return isfinite(p) ? p : 0.0f;
}

bool rt_light_table_sample_env(const rt_light_table *t, rt_vec2 u, rt_vec3 *d, float *pdf)
{
    size_t h = (size_t)t->env_h, w = (size_t)t->env_w;
    size_t j = cdf_pick(t->env_row_cdf, h, u.y);
    float r0 = j ? t->env_row_cdf[j - 1] : 0.0f, r1 = t->env_row_cdf[j];
    float fv = r1 > r0 ? rt_clampf((u.y - r0) / (r1 - r0), 0.0f, 0x1.fffffep-1f) : 0.5f;
    const float *cdf = t->env_col_cdf + j * w;
    size_t i = cdf_pick(cdf, w, u.x);
    float c0 = i ? cdf[i - 1] : 0.0f, c1 = cdf[i];
    float fu = c1 > c0 ? rt_clampf((u.x - c0) / (c1 - c0), 0.0f, 0x1.fffffep-1f) : 0.5f;
    float uu = ((float)i + fu) / (float)w, vv = ((float)j + fv) / (float)h;
    float sin_t = sinf(vv * RT_PI);
    if (!(sin_t > 1e-6f))
        return false;
    *d = rt_latlong_to_dir(rt_v2(uu, vv));
    *pdf = t->env_cell[j * w + i] * (float)w * (float)h / (2.0f * RT_PI * RT_PI * sin_t);
    return *pdf > 0.0f && isfinite(*pdf) && rt_finite3(*d);
}

rt_result rt_light_table_build(rt_light_table *t, const rt_scene *s, rt_error *err)
{
    memset(t, 0, sizeof *t);
    size_t np = rt_scene_prim_count(s), nq = s->quads.count;
    t->prim_count = np;
    t->quad_count = nq;
    t->prim_pdf = rt_alloc(np ? np : 1, sizeof *t->prim_pdf);
    t->prim_sel = rt_alloc(np ? np : 1, sizeof *t->prim_sel);
    t->quad_light = rt_alloc(nq ? nq : 1, sizeof *t->quad_light);
    if (!t->prim_pdf || !t->prim_sel || !t->quad_light)
        goto nomem;
    for (size_t q = 0; q < nq; q++)
        t->quad_light[q] = RT_NONE;
    for (size_t l = 0; l < s->light_count; l++)
        if (s->lights[l].kind == RT_LIGHT_AREA && s->lights[l].quad < nq)
            t->quad_light[s->lights[l].quad] = (uint32_t)l;
    size_t quad0 = s->triangles.count + s->spheres.count;
    size_t n = 0;
    for (size_t p = 0; p < np; p++) {
        float pw;
        if (p >= quad0 && t->quad_light[p - quad0] != RT_NONE)
            continue;
        if (p < s->triangles.count && (s->triangles.flags[p] & RT_TRI_OBJECT))
            continue; /* an object's triangle: in object space, not sampled (instances are not lights) */
        if (emissive_material(s, rt_prim_material(s, (uint32_t)p), &pw) && prim_area(s, (uint32_t)p) > 0.0f)
            n++;
    }
    if (!build_env(t, s))
        goto nomem;
    t->count = n;
    if (n == 0)
        return RT_OK;
    t->prim = rt_alloc(n, sizeof *t->prim);
    t->cdf = rt_alloc(n, sizeof *t->cdf);
    t->area = rt_alloc(n, sizeof *t->area);
    double *w = rt_alloc(n, sizeof *w);
    if (!t->prim || !t->cdf || !t->area || !w) {
        free(w);
        goto nomem;
    }
    double total = 0.0;
    size_t k = 0;
    for (size_t p = 0; p < np && k < n; p++) {
        float pw, a;
        if (p >= quad0 && t->quad_light[p - quad0] != RT_NONE)
            continue;
        if (p < s->triangles.count && (s->triangles.flags[p] & RT_TRI_OBJECT))
            continue; /* an object's triangle: in object space, not sampled (instances are not lights) */
        if (!emissive_material(s, rt_prim_material(s, (uint32_t)p), &pw) || !((a = prim_area(s, (uint32_t)p)) > 0.0f))
            continue;
        t->prim[k] = (uint32_t)p;
        t->area[k] = a;
        w[k] = (double)pw * (double)a;
        if (!isfinite(w[k]))
            w[k] = 0.0;
        total += w[k];
        k++;
    }
    t->count = k;
    if (!(total > 0.0) || !isfinite(total)) { /* nothing usable: behave as without a table */
        free(w);
        t->count = 0;
        return RT_OK;
    }
    double acc = 0.0;
    for (size_t i = 0; i < k; i++) {
        acc += w[i];
        t->cdf[i] = (float)(acc / total);
        t->prim_pdf[t->prim[i]] = (float)(w[i] / total / (double)t->area[i]);
        t->prim_sel[t->prim[i]] = (float)(w[i] / total);
    }
    t->cdf[k - 1] = 1.0f;
    free(w);
    return RT_OK;
nomem:
    rt_light_table_free(t);
    return rt_fail(err, RT_ERR_NOMEM, "out of memory building the emitter table (%zu primitives)", np);
}

size_t rt_light_table_pick(const rt_light_table *t, float u)
{
    return cdf_pick(t->cdf, t->count, u);
}

uint32_t rt_area_light_of_prim(const rt_scene *s, const rt_light_table *t, uint32_t prim)
{
    uint32_t q;
    if (rt_prim_kind_of(s, prim, &q) != RT_PRIM_QUAD)
        return RT_NONE;
    if (t && q < t->quad_count)
        return t->quad_light[q];
    for (size_t i = 0; i < s->light_count; i++)
        if (s->lights[i].kind == RT_LIGHT_AREA && s->lights[i].quad == q)
            return (uint32_t)i;
    return RT_NONE;
}

float rt_area_light_pdf(const rt_light *l, rt_vec3 p, rt_vec3 d, float dist)
{
    rt_sph_rect sr;
    rt_vec3 n = rt_cross(l->edge_u, l->edge_v);
    if (area_light_solid(l, n, p, &sr))
        return -rt_dot(n, d) > 0.0f ? 1.0f / sr.S : 0.0f;
    return area_light_area_pdf(n, rt_length(n), d, dist);
}

bool rt_tri_solid(rt_vec3 a, rt_vec3 b, rt_vec3 c, float area, rt_vec3 p, rt_sph_tri *st)
{
    /* seen large: area / d^2 from the centroid (an upper bound of the
     * estimate that looks_large uses, without the normal) */
    rt_vec3 d = rt_sub(rt_scale(rt_add(rt_add(a, b), c), 1.0f / 3.0f), p);
    if (!(area >= SOLID_ANGLE_MIN_ESTIMATE * rt_length2(d)))
        return false;
    return rt_sph_tri_init(st, a, b, c, p) && rt_sph_in_range(st->S);
}
