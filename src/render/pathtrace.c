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
 *     directional lights are deltas, weight 1), and, with a light table,
 *     one emissive primitive chosen in proportion to its power (area x mean
 *     emitted radiance) and a uniform point on it, and one direction of the
 *     environment image drawn in proportion to luminance x sin(theta)
 *     (piecewise constant over its latitude-longitude cells, pbrt-v3
 *     14.2.4);
 *   - the BSDF (rt/bsdf.h) samples the next direction, beta *= f cos / pdf.
 * Light and BSDF samples are combined with the power heuristic (Veach 1997,
 * "Robust Monte Carlo Methods for Light Transport Simulation", ch. 9,
 * beta = 2), so a BSDF-sampled ray that hits a light counts with weight
 * pdf_bsdf^2 / (pdf_bsdf^2 + pdf_light^2) and the light sample with the
 * complement. Emitters that are not light-sampled (emissive primitives
 * and environment images without a table, a constant background) count in
 * full on BSDF hits.
 *
 * Russian roulette (Arvo and Kirk 1990) from RT_PATH_RR_START bounces: the
 * path survives with q = min(max channel of beta, 0.95) and beta /= q, which
 * keeps the estimator unbiased. settings.max_depth caps the scattering
 * events of a path (0 = no cap).
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

#include <stdlib.h>
#include <string.h>

#include "rt/render/bsdf.h"

/* ------------------------------------------------------------ light table */

static bool emissive_material(const rt_scene *s, uint32_t m, float *power)
{
    if (m >= s->material_count)
        return false;
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

static uint32_t prim_material_of(const rt_scene *s, uint32_t prim)
{
    uint32_t i;
    switch (rt_prim_kind_of(s, prim, &i)) {
    case RT_PRIM_TRIANGLE: return s->triangles.material[i];
    case RT_PRIM_SPHERE: return s->spheres.material[i];
    case RT_PRIM_QUAD:
    default: return s->quads.material[i];
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
    free(t->quad_light);
    free(t->env_row_cdf);
    free(t->env_col_cdf);
    free(t->env_cell);
    memset(t, 0, sizeof *t);
}

/* Latitude-longitude mapping of rt_environment (shade.c):
 * u = 0.5 + atan2(x, z) / 2pi, v = acos(y) / pi. */
static rt_vec3 latlong_dir(float u, float v)
{
    float theta = v * RT_PI, phi = (u - 0.5f) * 2.0f * RT_PI;
    float st = sinf(theta);
    return rt_v3(st * sinf(phi), cosf(theta), st * cosf(phi));
}

/* The environment's sampling distribution: luminance (the largest over the
 * cell) x sin(theta) per cell of a grid at the image's resolution (at most
 * 1024 x 512), piecewise constant in (u, v) (pbrt-v3 14.2.4, "Infinite Area Lights"). false =
 * out of memory. */
static bool build_env(rt_light_table *t, const rt_scene *s)
{
    const rt_settings *st = &s->settings;
    uint32_t tex = st->environment_texture;
    if (tex == RT_NONE || tex >= s->texture_count || !(st->environment_strength > 0.0f))
        return true;
    int w = 256, h = 128;
    const rt_texture *tx = &s->textures[tex];
    if (tx->kind == RT_TEX_IMAGE && tx->image < s->image_count) {
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
    rt_trace_ctx c;
    memset(&c, 0, sizeof c);
    c.scene = s;
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
                    rt_vec3 e = rt_environment(&c, latlong_dir(uu, vv));
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
    float sin_t = sqrtf(fmaxf(0.0f, 1.0f - d.y * d.y));
    if (!(sin_t > 0.0f))
        return 0.0f;
    float u = 0.5f + atan2f(d.x, d.z) * (0.5f * RT_INV_PI);
    float v = acosf(rt_clampf(d.y, -1.0f, 1.0f)) * RT_INV_PI;
    int i = (int)(u * (float)t->env_w), j = (int)(v * (float)t->env_h);
    i = i < 0 ? 0 : (i >= t->env_w ? t->env_w - 1 : i);
    j = j < 0 ? 0 : (j >= t->env_h ? t->env_h - 1 : j);
    float p = t->env_cell[(size_t)j * (size_t)t->env_w + (size_t)i] * (float)t->env_w * (float)t->env_h /
              (2.0f * RT_PI * RT_PI * sin_t);
    return isfinite(p) ? p : 0.0f;
}

/* A direction from the environment's distribution and its solid-angle
 * pdf; false when it falls on a pole. */
static bool env_sample(const rt_light_table *t, rt_vec2 u, rt_vec3 *d, float *pdf)
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
    *d = latlong_dir(uu, vv);
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
    t->quad_light = rt_alloc(nq ? nq : 1, sizeof *t->quad_light);
    if (!t->prim_pdf || !t->quad_light)
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
        if (emissive_material(s, prim_material_of(s, (uint32_t)p), &pw) && prim_area(s, (uint32_t)p) > 0.0f)
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
        if (!emissive_material(s, prim_material_of(s, (uint32_t)p), &pw) || !((a = prim_area(s, (uint32_t)p)) > 0.0f))
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
    }
    t->cdf[k - 1] = 1.0f;
    free(w);
    return RT_OK;
nomem:
    rt_light_table_free(t);
    return rt_fail(err, RT_ERR_NOMEM, "out of memory building the emitter table (%zu primitives)", np);
}

/* Index of the first cdf entry above u. */
static size_t table_pick(const rt_light_table *t, float u)
{
    size_t lo = 0, hi = t->count - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (t->cdf[mid] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* --------------------------------------------------------------- helpers */

/* The area light whose visible quad primitive `prim` is, or RT_NONE. */
static uint32_t light_of_prim(const rt_trace_ctx *ctx, uint32_t prim)
{
    const rt_scene *s = ctx->scene;
    uint32_t q;
    if (rt_prim_kind_of(s, prim, &q) != RT_PRIM_QUAD)
        return RT_NONE;
    const rt_light_table *t = ctx->light_table;
    if (t && q < t->quad_count)
        return t->quad_light[q];
    for (size_t i = 0; i < s->light_count; i++)
        if (s->lights[i].kind == RT_LIGHT_AREA && s->lights[i].quad == q)
            return (uint32_t)i;
    return RT_NONE;
}

/* Solid-angle pdf of sampling area light l towards direction d (unit) from
 * a point at distance dist; 0 when seen from behind. */
static float area_light_pdf(const rt_light *l, rt_vec3 d, float dist)
{
    rt_vec3 nl = rt_cross(l->edge_u, l->edge_v);
    float area = rt_length(nl);
    if (!(area > 0.0f))
        return 0.0f;
    float cos_l = -rt_dot(nl, d) / area;
    if (!(cos_l > 0.0f))
        return 0.0f;
    float p = dist * dist / (area * cos_l);
    return isfinite(p) ? p : 0.0f;
}

/* Fraction of light that reaches sf->p from distance dist along wi:
 * 0 behind opaque or refractive surfaces, through alpha cut-outs, scaled by
 * 1 - alpha through blended surfaces. */
static float visibility(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist)
{
    rt_vec3 o = rt_surface_spawn(ctx, sf, wi);
    /* stop just short of the emitter, measured from the offset origin */
    float tmax = isfinite(dist) ? rt_dot(rt_sub(rt_madd(sf->p, wi, dist), o), wi) * (1.0f - 1e-4f) : INFINITY;
    rt_ray r = rt_ray_make(o, wi, 0.0f, tmax);
    if (ctx->ray_count)
        (*ctx->ray_count)++;
    if (!ctx->shadows_need_shading)
        return rt_kdtree_occluded(ctx->tree, &r) ? 0.0f : 1.0f;
    const rt_scene *s = ctx->scene;
    float v = 1.0f;
    for (int layer = 0; layer < 64; layer++) {
        rt_hit h;
        if (!rt_kdtree_intersect(ctx->tree, &r, &h))
            return v;
        uint32_t mi = prim_material_of(s, h.prim);
        const rt_material *m = mi < s->material_count ? &s->materials[mi] : NULL;
        if (!m || (m->alpha_mode == RT_ALPHA_OPAQUE))
            return 0.0f;
        rt_surface s2;
        rt_surface_at(ctx, &r, &h, &s2);
        float coverage;
        if (!rt_surface_cut_away(ctx, &s2, &coverage)) {
            if (m->transmission > 0.0f || coverage >= 1.0f)
                return 0.0f;
            v *= 1.0f - coverage;
        }
        if (!(v > 0.0f))
            return 0.0f;
        r.tmin = h.t;
    }
    return 0.0f;
}

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
    float vis = visibility(ctx, sf, d, dist);
    if (!(vis > 0.0f))
        return rt_v3s(0.0f);
    return rt_scale(rt_mul(f, Le ? *Le : rt_environment(ctx, d)), wi.z * vis * w / pdf_l);
}

/* Light sampled at one vertex: sum over rt_lights plus one table emitter,
 * each f cos Le / pdf_light times its MIS weight. */
static rt_vec3 next_event(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_bsdf *b, rt_vec3 wo,
                          rt_rng *rng)
{
    const rt_scene *s = ctx->scene;
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
            w = rt_mis_power(area_light_pdf(l, ls.wi, ls.dist), pdf_b);
        if (!(w > 0.0f))
            continue;
        float vis = visibility(ctx, sf, ls.wi, ls.dist);
        if (!(vis > 0.0f))
            continue;
        sum = add_finite(sum, rt_scale(rt_mul(f, ls.li), wi.z * vis * w));
    }
    const rt_light_table *t = ctx->light_table;
    if (t && t->env_w > 0) {
        rt_vec2 u = rt_v2(rt_rng_float(rng), rt_rng_float(rng));
        rt_vec3 d;
        float pdf_l;
        if (env_sample(t, u, &d, &pdf_l) && rt_dot(d, b->ng) > 0.0f)
            sum = add_finite(sum, light_table_term(ctx, sf, b, wo, d, NULL, pdf_l, INFINITY));
    }
    if (t && t->count) {
        float ul = rt_rng_float(rng);
        rt_vec2 u = rt_v2(rt_rng_float(rng), rt_rng_float(rng));
        size_t k = table_pick(t, ul);
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
    const rt_scene *s = ctx->scene;
    int max_depth = s->settings.max_depth > 0 ? s->settings.max_depth : RT_PATH_HARD_LIMIT;
    if (max_depth > RT_PATH_HARD_LIMIT)
        max_depth = RT_PATH_HARD_LIMIT;
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
    int bounces = 0, layers = 0;
    for (;;) {
        rt_hit hit;
        if (!rt_trace(ctx, &r, &hit)) {
            float w = 1.0f; /* MIS against environment sampling, when the table does it */
            if (!prev_delta && ctx->light_table && ctx->light_table->env_w > 0)
                w = rt_mis_power(prev_pdf, rt_light_table_env_pdf(ctx->light_table, r.dir));
            L = add_finite(L, rt_scale(rt_mul(beta, rt_environment(ctx, r.dir)), w));
            break;
        }
        rt_surface sf;
        rt_surface_at(ctx, &r, &hit, &sf);
        float coverage;
        bool cut = rt_surface_cut_away(ctx, &sf, &coverage);
        if (!cut && coverage < 1.0f && rt_rng_float(rng) >= coverage)
            cut = true; /* stochastic alpha blending */
        if (cut) {
            if (++layers > 256)
                break;
            r.tmin = hit.t;
            continue;
        }
        layers = 0;
        /* emission, MIS-weighted when it could have been light-sampled */
        rt_vec3 Le = rt_surface_emission(ctx, &sf);
        const rt_material *m = s->material_count ? &s->materials[sf.material] : NULL;
        /* area lights' quads have emissive materials: look only those up */
        bool emissive = m && rt_max3(rt_scale(m->emission, m->emission_strength)) > 0.0f;
        uint32_t light = emissive ? light_of_prim(ctx, sf.prim) : RT_NONE;
        if (rt_max3(Le) > 0.0f) {
            float w = 1.0f;
            if (!prev_delta) {
                float d2 = rt_length2(rt_sub(sf.p, prev_p));
                float pdf_l = 0.0f;
                if (light != RT_NONE) {
                    pdf_l = area_light_pdf(&s->lights[light], r.dir, sqrtf(d2));
                } else if (ctx->light_table && sf.prim < ctx->light_table->prim_count) {
                    float cos_l = fabsf(rt_dot(sf.ng, r.dir));
                    float pa = ctx->light_table->prim_pdf[sf.prim];
                    pdf_l = (pa > 0.0f && cos_l > 0.0f) ? pa * d2 / cos_l : 0.0f;
                }
                if (pdf_l > 0.0f && isfinite(pdf_l))
                    w = rt_mis_power(prev_pdf, pdf_l);
            }
            L = add_finite(L, rt_scale(rt_mul(beta, Le), w));
        }
        if (light != RT_NONE)
            break; /* an area light's quad reflects nothing */
        if (m && m->unlit) {
            rt_vec4 c = rt_surface_base_color(ctx, &sf);
            L = add_finite(L, rt_mul(beta, rt_v3(c.x, c.y, c.z)));
            break;
        }
        if (bounces >= max_depth)
            break;
        rt_bsdf b;
        rt_bsdf_from_surface(ctx, &sf, &b);
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
        prev_delta = bs.delta;
        prev_pdf = bs.pdf;
        prev_p = sf.p;
        bounces++;
        if (bounces >= RT_PATH_RR_START) {
            float q = fminf(rt_max3(beta), 0.95f);
            if (rt_rng_float(rng) >= q)
                break;
            beta = rt_scale(beta, 1.0f / q);
        }
        r = rt_ray_make(rt_surface_spawn(ctx, &sf, wi), wi, 0.0f, INFINITY);
    }
    return rt_finite3(L) ? L : rt_v3s(0.0f);
}
