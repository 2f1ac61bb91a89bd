/* bsdf.c - the lobes of every BSDF kind for the path tracer (see
 * rt/render/bsdf.h): Lambert, the glTF metallic-roughness BSDF and its
 * extensions' layers, the conductor, the dielectric and the plastic;
 * evaluation, pdf and importance sampling, built from the GGX and Fresnel
 * terms of rt/render/microfacet.h. One closed kind (rt_bsdf_kind) picks the
 * lobes: lobe_probs, rt_bsdf_eval and rt_bsdf_sample_dir switch over it,
 * the glTF, dielectric and plastic kinds sharing one dielectric interface
 * over a base, the conductor and the layered glTF BSDF with functions of
 * their own. The material at a hit becomes one of these in material_eval.c.
 *
 * Sources:
 * - The BRDF: glTF 2.0 specification, appendix B "BRDF Implementation",
 *   in its normative form (B.3.5: mix(dielectric_brdf, metal_brdf,
 *   metallic), metal_brdf = conductor_fresnel(base, specular),
 *   dielectric_brdf = fresnel_mix(ior, diffuse, specular), Schlick's F on
 *   |V.H|), with KHR_materials_ior (F0 from the index) and
 *   KHR_materials_transmission (the dielectric base lobe split between
 *   diffuse and a BTDF).
 * - Exact Fresnel equations for a dielectric (Born and Wolf, "Principles of
 *   Optics", 7th ed., 1.5.2), used for transmissive surfaces.
 * - GGX / Trowbridge-Reitz distribution and its Smith Lambda: Walter,
 *   Marschner, Li, Torrance 2007, "Microfacet Models for Refraction through
 *   Rough Surfaces" (EGSR); height-correlated masking-shadowing: Heitz 2014,
 *   "Understanding the Masking-Shadowing Function in Microfacet-Based
 *   BRDFs" (JCGT 3(2)), eq. 99: G2 = 1 / (1 + Lambda(wo) + Lambda(wi)).
 * - Sampling visible normals: Heitz 2018, "Sampling the GGX Distribution
 *   of Visible Normals" (JCGT 7(4)), listing 1; its pdf D_wo(h) / (4 wo.h)
 *   = G1(wo) D(h) / (4 wo.z) for reflection.
 * - Conductor: exact unpolarised Fresnel for a complex index (Born and
 *   Wolf, 14.2; the closed form of pbrt-v3, Pharr, Jakob, Humphreys, 8.2.1);
 *   anisotropic GGX D and Lambda (Heitz 2014, eqs. 85, 86) and the
 *   separable Smith term G1 G1 (eq. 98) as the `smith separable` option;
 *   anisotropic VNDF sampling (Heitz 2018, the stretch by (ax, ay)).
 * - Energy compensation of rough conductors: C. Kulla and A. Conty,
 *   "Revisiting Physically Based Shading at Imageworks" (SIGGRAPH 2017
 *   course "Physically Based Shading in Theory and Practice"): the lobe
 *   (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)) restores the energy
 *   single scattering loses with F = 1, times F_avg^2 E_avg / (1 - F_avg
 *   (1 - E_avg)) for the Fresnel-weighted sum over the extra bounces; E
 *   and E_avg from rt/render/ggx_albedo.h. For rough glass the same
 *   course's dielectric extension: E(mu, alpha, eta) of reflection and
 *   refraction together from both sides, the lobe split between
 *   reflection and transmission so that the transmitted part obeys the
 *   reciprocity of refraction, n_o^2 f(wo, wi) = n_t^2 f(wi, wo)
 *   (Veach 1997, 5.2), derived in docs/shading.md, section 14.
 * - Cosine sampling of the diffuse lobe (rt/sampling.h).
 * - Choosing one lobe by its estimated weight and returning the mixture pdf
 *   is one-sample MIS over the lobes with the balance heuristic (Veach 1997,
 *   ch. 9.2.4), so rt_bsdf_eval's pdf is exactly the sampling density.
 *
 * The transmission lobe refracts through a GGX microfacet normal sampled
 * from the visible normals (Walter et al. 2007's rough dielectric BTDF,
 * with the same alpha; the macro normal, i.e. a smooth dielectric, at
 * roughness 0, where the reflection is a mirror too), Snell's law with the
 * material's ior. It is sampled only, never evaluated: transmitted rays are not light-sampled, so an
 * emitter they hit counts in full (no MIS). Radiance is not rescaled by
 * eta^2 across the interface (it cancels for paths that leave the object
 * again). Every result is finite: grazing
 * directions give zero, never a division by zero.
 */
#include "rt/render/bsdf.h"

#include "rt/render/bsdf_clearcoat.h"
#include "rt/render/bsdf_iridescence.h"
#include "rt/render/bsdf_sheen.h"
#include "rt/render/ggx_albedo.h"
#include "rt/render/microfacet.h"
#include "rt/render/sampling.h"

/* The dielectric Fresnel Fd at a (micro)facet seen at cosine c from wo:
 * the exact equations for a transmissive surface (glass: reflection and
 * refraction share one F, 1 past the critical angle), glTF's Schlick with
 * the index's F0 for an opaque one. */
static inline float fresnel_dielectric(const rt_bsdf *b, float c)
{
    if (b->transmission > 0.0f || b->kind == RT_BSDF_KIND_PLASTIC)
        return rt_fresnel_exact(c, b->eta);
    return b->f0 + (1.0f - b->f0) * rt_schlick_weight(c);
}

static inline float mean3(rt_vec3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

/* The specular lobe's Fresnel: the glTF mix by metallic of the metal's
 * conductor_fresnel (Schlick on the base colour) and the dielectric's Fd. */
static inline rt_vec3 fresnel_specular(const rt_bsdf *b, float c, float fd)
{
    rt_vec3 fm = b->metallic > 0.0f ? rt_fresnel_schlick(b->base, c) : rt_v3s(0.0f);
    return rt_lerp3(rt_v3s(fd), fm, b->metallic);
}

void rt_bsdf_set_frame(rt_bsdf *b, rt_vec3 n, rt_vec3 ng)
{
    b->n = n;
    b->ng = ng;
    rt_onb(n, &b->t, &b->b);
}

/* An albedo clamped to finite, non-negative values. */
static inline rt_vec3 clean_base(rt_vec3 base)
{
    base = rt_vmax(base, rt_v3s(0.0f));
    return rt_finite3(base) ? base : rt_v3s(0.0f);
}

/* A BSDF of this kind, with none of its options (thin, compensation,
 * separable Smith) on and no cached wo (rt_bsdf_set_wo). */
static inline void set_kind(rt_bsdf *b, rt_bsdf_kind kind)
{
    b->kind = kind;
    b->wo_z = NAN;
    b->thin = false;
    b->ms = false;
    b->separable = false;
}

/* The Lambert BSDF of albedo base (clamped to finite, non-negative):
 * what set_params sets for lambert, without its other parameters. */
void rt_bsdf_set_lambert(rt_bsdf *b, rt_vec3 base)
{
    base = clean_base(base);
    set_kind(b, RT_BSDF_KIND_LAMBERT);
    b->base = base;
    b->alpha_y = 1.0f;
    b->diffuse = base;
    b->metallic = 0.0f;
    b->f0 = 0.0f;
    b->alpha = 1.0f;
    b->delta = false;
    b->transmission = 0.0f;
    b->eta = 1.0f;
}

static void set_params(rt_bsdf *b, rt_vec3 base, float metallic, float roughness, float ior, float transmission,
                       bool lambert)
{
    if (lambert) {
        rt_bsdf_set_lambert(b, base);
        return;
    }
    base = clean_base(base);
    metallic = isfinite(metallic) ? rt_clampf(metallic, 0.0f, 1.0f) : 0.0f;
    roughness = isfinite(roughness) ? rt_clampf(roughness, 0.0f, 1.0f) : 1.0f;
    transmission = isfinite(transmission) ? rt_clampf(transmission, 0.0f, 1.0f) : 0.0f;
    if (!(ior > 0.0f) || !isfinite(ior))
        ior = 1.5f;
    set_kind(b, RT_BSDF_KIND_GLTF);
    b->base = base;
    float r0 = (ior - 1.0f) / (ior + 1.0f);
    b->diffuse = rt_scale(base, 1.0f - metallic);
    b->metallic = metallic;
    b->f0 = r0 * r0;
    b->delta = roughness == 0.0f;
    b->alpha = b->alpha_y = rt_fmaxf(roughness * roughness, RT_BSDF_MIN_ALPHA);
    b->transmission = transmission;
    b->eta = 1.0f / ior;
}

void rt_bsdf_make(rt_bsdf *b, rt_vec3 n, rt_vec3 base, float metallic, float roughness, float ior,
                  float transmission, bool lambert)
{
    rt_bsdf_set_frame(b, n, n);
    set_params(b, base, metallic, roughness, ior, transmission, lambert);
}

void rt_bsdf_set_gltf(rt_bsdf *b, rt_vec3 base, float metallic, float roughness, float ior, float transmission)
{
    set_params(b, base, metallic, roughness, ior, transmission, false);
}

void rt_bsdf_set_conductor(rt_bsdf *b, rt_vec3 eta, rt_vec3 k, float ax, float ay, bool separable)
{
    set_params(b, rt_v3s(0.0f), 0.0f, 1.0f, 1.5f, 0.0f, false);
    b->kind = RT_BSDF_KIND_CONDUCTOR;
    b->eta_c = rt_finite3(eta) ? rt_vmax(eta, rt_v3s(0.0f)) : rt_v3s(1.0f);
    b->k_c = rt_finite3(k) ? rt_vmax(k, rt_v3s(0.0f)) : rt_v3s(0.0f);
    ax = isfinite(ax) ? rt_clampf(ax, 0.0f, 1.0f) : 1.0f;
    ay = isfinite(ay) ? rt_clampf(ay, 0.0f, 1.0f) : 1.0f;
    b->delta = ax == 0.0f && ay == 0.0f;
    b->alpha = rt_fmaxf(ax, RT_BSDF_MIN_ALPHA);
    b->alpha_y = rt_fmaxf(ay, RT_BSDF_MIN_ALPHA);
    b->separable = separable;
}

void rt_bsdf_make_conductor(rt_bsdf *b, rt_vec3 n, rt_vec3 eta, rt_vec3 k, float alpha_x, float alpha_y,
                            bool separable)
{
    rt_bsdf_set_frame(b, n, n);
    rt_bsdf_set_conductor(b, eta, k, alpha_x, alpha_y, separable);
}

static void dielectric_compensate(rt_bsdf *b);

void rt_bsdf_compensate(rt_bsdf *b)
{
    b->wo_z = NAN;
    if (b->kind == RT_BSDF_KIND_DIELECTRIC) {
        dielectric_compensate(b);
        return;
    }
    if (b->kind != RT_BSDF_KIND_CONDUCTOR || b->delta || b->separable)
        return;
    float alpha = sqrtf(b->alpha * b->alpha_y);
    float ea = rt_ggx_albedo_avg(alpha);
    if (!(1.0f - ea > 1e-5f))
        return; /* a near-mirror loses nothing */
    rt_vec3 fa = rt_fresnel_conductor_avg(b->eta_c, b->k_c);
    rt_vec3 one = rt_v3s(1.0f);
    rt_vec3 fms = rt_div(rt_scale(rt_mul(fa, fa), ea), rt_sub(one, rt_scale(fa, 1.0f - ea)));
    rt_vec3 scale = rt_scale(fms, 1.0f / (RT_PI * (1.0f - ea)));
    if (!rt_finite3(scale))
        return;
    b->ms = true;
    b->ms_alpha = alpha;
    b->ms_scale = scale;
}

void rt_bsdf_make_dielectric(rt_bsdf *b, rt_vec3 n, float eta, float alpha)
{
    rt_bsdf_set_frame(b, n, n);
    set_params(b, rt_v3s(1.0f), 0.0f, 1.0f, 1.5f, 1.0f, false);
    eta = (eta > 0.0f && isfinite(eta)) ? eta : 1.0f;
    float r0 = (eta - 1.0f) / (eta + 1.0f);
    b->f0 = r0 * r0;
    b->eta = eta;
    alpha = isfinite(alpha) ? rt_clampf(alpha, 0.0f, 1.0f) : 1.0f;
    b->delta = alpha == 0.0f;
    b->alpha = b->alpha_y = rt_fmaxf(alpha, RT_BSDF_MIN_ALPHA);
    b->kind = RT_BSDF_KIND_DIELECTRIC;
}

void rt_bsdf_set_eta(rt_bsdf *b, float eta)
{
    b->wo_z = NAN;
    eta = (eta > 0.0f && isfinite(eta)) ? eta : 1.0f;
    float r0 = (eta - 1.0f) / (eta + 1.0f);
    b->f0 = r0 * r0;
    bool changed = eta != b->eta;
    b->eta = eta;
    if (changed && b->ms && b->kind == RT_BSDF_KIND_DIELECTRIC)
        dielectric_compensate(b); /* E and the split depend on eta */
}

/* Kulla and Conty's lobe for rough glass, from the side o of wo to either
 * side (t the other one), in flux form (docs/shading.md, section 14):
 *   f_R = (1 - x_o) (1 - E_o(mu_o)) (1 - E_o(mu_i)) / (pi (1 - Eavg_o))
 *   f_T = T_o (1 - E_o(mu_o)) (1 - E_t(mu_i)) / (pi (1 - Eavg_o) (1 - Eavg_t))
 * with T_o = rt_ggx_dielectric_ms_transmit and x_o = T_o / (1 - Eavg_o):
 * together they integrate to 1 - E_o(mu_o), the energy single scattering
 * loses, f_R is symmetric and n_o^2 T_o = n_t^2 T_t makes f_T reciprocal
 * across the interface. */
static void dielectric_compensate(rt_bsdf *b)
{
    b->ms = false;
    if (b->delta || b->kind != RT_BSDF_KIND_DIELECTRIC)
        return;
    float alpha = b->alpha, eta = b->eta;
    float lo = 1.0f - rt_ggx_dielectric_albedo_avg(alpha, eta);
    float lt = 1.0f - rt_ggx_dielectric_albedo_avg(alpha, 1.0f / eta);
    if (!(lo > 1e-5f) || !(lt > 1e-5f))
        return; /* a near-mirror interface loses nothing */
    float t = rt_ggx_dielectric_ms_transmit(alpha, eta);
    float x = rt_clampf(t / lo, 0.0f, 1.0f);
    float refl = (1.0f - x) / (RT_PI * lo), trans = x / (RT_PI * lt);
    if (!isfinite(refl) || !isfinite(trans))
        return;
    b->ms = true;
    b->ms_alpha = alpha;
    b->ms_x = x;
    b->ms_refl = refl;
    b->ms_trans = trans;
    b->ms_cell[0] = rt_ggx_dielectric_cell_of(alpha, eta);
    b->ms_cell[1] = rt_ggx_dielectric_cell_of(alpha, 1.0f / eta);
}

float rt_bsdf_ms_transmit(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi)
{
    if (!b->ms || b->kind != RT_BSDF_KIND_DIELECTRIC || !(wo.z > 0.0f) || !(wi.z < 0.0f))
        return 0.0f;
    return b->ms_trans * (1.0f - rt_ggx_dielectric_albedo_at(&b->ms_cell[0], wo.z)) *
           (1.0f - rt_ggx_dielectric_albedo_at(&b->ms_cell[1], -wi.z));
}

void rt_bsdf_make_plastic(rt_bsdf *b, rt_vec3 n, rt_vec3 R, float eta, float alpha)
{
    rt_bsdf_set_frame(b, n, n);
    set_params(b, R, 0.0f, 1.0f, 1.5f, 0.0f, false);
    eta = (eta > 0.0f && isfinite(eta)) ? eta : 1.0f;
    float r0 = (eta - 1.0f) / (eta + 1.0f);
    b->f0 = r0 * r0;
    b->eta = eta;
    b->kind = RT_BSDF_KIND_PLASTIC;
    alpha = isfinite(alpha) ? rt_clampf(alpha, 0.0f, 1.0f) : 1.0f;
    b->delta = alpha == 0.0f;
    b->alpha = b->alpha_y = rt_fmaxf(alpha, RT_BSDF_MIN_ALPHA);
    /* light entering the coat (1 - Fi), bouncing between base and coat
     * (the geometric series 1 / (1 - R Fdr_in), Fdr_in the coat's internal
     * diffuse reflectance) and leaving (1 - Fo) loses 1 / eta_in^2 of its
     * radiance to the wider cone outside (Weidlich and Wilkie 2007;
     * Mitsuba's plastic) */
    float inv_eta2 = eta * eta; /* (n_outside / n_coat)^2 */
    float fdr_in = rt_fresnel_diffuse_reflectance(1.0f / eta);
    rt_vec3 d = b->base;
    b->diffuse = rt_v3(d.x / (1.0f - d.x * fdr_in), d.y / (1.0f - d.y * fdr_in), d.z / (1.0f - d.z * fdr_in));
    b->diffuse = rt_scale(b->diffuse, inv_eta2);
    if (!rt_finite3(b->diffuse))
        b->diffuse = rt_v3s(0.0f);
}

/* Lobe probabilities of the layered glTF BSDF (the extensions' section below). */
typedef struct layered_probs {
    float d, s, c, t, dt; /* diffuse (with sheen), specular, coat, refraction, diffuse transmission */
} layered_probs;
static layered_probs layered_lobe_probs(const rt_bsdf *b, rt_vec3 wo);
static rt_vec3 layered_eval(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi, const layered_probs *p, float *pdf);

/* The conductor's lobes: the specular one, and with compensation the
 * multiple-scattering lobe, sampled as a diffuse one, by the share of
 * their albedos at wo. */
static void conductor_lobe_probs(const rt_bsdf *b, rt_vec3 wo, float *p_diffuse, float *p_specular)
{
    *p_specular = 1.0f;
    if (b->ms) { /* the lobes' albedos at wo: about F E(mu_o) and F_ms (1 - E(mu_o)) */
        float e = rt_ggx_albedo(wo.z, b->ms_alpha);
        float ws = mean3(rt_fresnel_conductor(wo.z, b->eta_c, b->k_c)) * e;
        float wm = mean3(b->ms_scale) * RT_PI * (1.0f - rt_ggx_albedo_avg(b->ms_alpha)) * (1.0f - e);
        float pm = (ws + wm > 0.0f) ? wm / (ws + wm) : 0.0f;
        *p_diffuse = isfinite(pm) ? rt_clampf(pm, 0.0f, 0.95f) : 0.0f;
        *p_specular = 1.0f - *p_diffuse;
    }
}

/* The lobes of a dielectric interface over a base (the glTF BSDF, the
 * dielectric, the plastic): diffuse, specular, refraction, and a
 * compensated dielectric's transmitted multiple-scattering lobe apart
 * (*p_ms_transmit; its reflected lobe is the diffuse one). */
static void dielectric_lobe_probs(const rt_bsdf *b, rt_vec3 wo, float *p_diffuse, float *p_specular,
                                  float *p_transmit, float *p_ms_transmit)
{
    /* F at the macro normal estimates each lobe's share. A delta interface
     * uses it exactly; a rough one floors both shares, so every lobe that
     * can contribute at some microfacet stays sampleable (inside glass past
     * the critical angle Fd is 1 at the normal, yet tilted facets still
     * transmit) */
    float fd = fresnel_dielectric(b, wo.z);
    rt_vec3 F = fresnel_specular(b, wo.z, fd);
    float ws = mean3(F), td = 1.0f - fd;
    if (b->kind == RT_BSDF_KIND_PLASTIC) /* the diffuse lobe's albedo: (1 - Fo) diffuse (1 - Fdr_out), about (1 - Fo) diffuse */
        td *= 1.0f - b->f0;
    if (!b->delta) {
        ws = rt_fmaxf(ws, 0.02f);
        td = rt_fmaxf(td, 0.1f);
    }
    float wd = mean3(b->diffuse) * td;
    float wt = wd * b->transmission;
    wd *= 1.0f - b->transmission;
    float sum = ws + wd + wt;
    if (!(sum > 0.0f) || !isfinite(sum))
        return;
    *p_diffuse = wd / sum;
    *p_specular = ws / sum;
    *p_transmit = wt / sum;
    if (b->ms) { /* rough glass: single scattering keeps E(mu_o), the lobe the rest */
        float pm = 1.0f - rt_ggx_dielectric_albedo_at(&b->ms_cell[0], wo.z);
        pm = isfinite(pm) ? rt_clampf(pm, 0.0f, 0.95f) : 0.0f;
        *p_diffuse = pm * (1.0f - b->ms_x);
        *p_ms_transmit = pm * b->ms_x;
        *p_specular *= 1.0f - pm;
        *p_transmit *= 1.0f - pm;
    }
}


/* The lobe probabilities by the BSDF's kind, with a compensated
 * dielectric's transmitted multiple-scattering lobe apart (*p_ms_transmit). */
static void lobe_probs(const rt_bsdf *b, rt_vec3 wo, float *p_diffuse, float *p_specular, float *p_transmit,
                       float *p_ms_transmit)
{
    *p_diffuse = *p_specular = *p_transmit = *p_ms_transmit = 0.0f;
    switch (b->kind) {
    case RT_BSDF_KIND_LAMBERT:
        *p_diffuse = mean3(b->diffuse) > 0.0f ? 1.0f : 0.0f;
        return;
    case RT_BSDF_KIND_GLTF_LAYERED: {
        layered_probs p = layered_lobe_probs(b, wo);
        *p_diffuse = p.d;
        *p_specular = p.s + p.c;
        *p_transmit = p.t + p.dt;
        return;
    }
    case RT_BSDF_KIND_CONDUCTOR:
        conductor_lobe_probs(b, wo, p_diffuse, p_specular);
        return;
    case RT_BSDF_KIND_GLTF:
    case RT_BSDF_KIND_DIELECTRIC:
    case RT_BSDF_KIND_PLASTIC:
        dielectric_lobe_probs(b, wo, p_diffuse, p_specular, p_transmit, p_ms_transmit);
        return;
    }
}

/* lobe_probs, from rt_bsdf_set_wo's cache when it holds this wo (the core
 * BSDF's probabilities depend on wo only through wo.z). */
static inline void lobe_probs_at(const rt_bsdf *b, rt_vec3 wo, float *pd, float *ps, float *pt, float *ptm)
{
    if (wo.z == b->wo_z && b->kind != RT_BSDF_KIND_GLTF_LAYERED) {
        *pd = b->p_d, *ps = b->p_s, *pt = b->p_t, *ptm = b->p_tm;
        return;
    }
    lobe_probs(b, wo, pd, ps, pt, ptm);
}

void rt_bsdf_set_wo(rt_bsdf *b, rt_vec3 wo)
{
    b->wo_z = NAN;
    if (b->kind == RT_BSDF_KIND_GLTF_LAYERED || b->kind == RT_BSDF_KIND_LAMBERT || !(wo.z > 0.0f))
        return; /* layered: probabilities of the whole wo; Lambert: nothing to cache */
    lobe_probs(b, wo, &b->p_d, &b->p_s, &b->p_t, &b->p_tm);
    b->wo_z = wo.z;
}

void rt_bsdf_lobe_probs(const rt_bsdf *b, rt_vec3 wo, float *p_diffuse, float *p_specular, float *p_transmit)
{
    float ptm;
    lobe_probs(b, wo, p_diffuse, p_specular, p_transmit, &ptm);
    *p_transmit += ptm;
}

/* The conductor's f and pdf (non-delta lobes), given its lobe probabilities. */
static rt_vec3 conductor_eval(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi, float pd, float ps, float *pdf)
{
    *pdf = 0.0f;
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
        return rt_v3s(0.0f);
    if (b->delta)
        return rt_v3s(0.0f);
    rt_vec3 h = rt_add(wo, wi);
    float l2 = rt_length2(h);
    if (!(l2 > 1e-20f)) /* opposite directions: both grazing */
        return rt_v3s(0.0f);
    h = rt_scale(h, 1.0f / sqrtf(l2));
    float voh = rt_dot(wo, h);
    /* F(wo.h) D G2 / (4 cos_o cos_i), VNDF pdf G1(wo) D / (4 cos_o) */
    float D = rt_ggx_d_xy(h, b->alpha, b->alpha_y);
    float spec = D * rt_ggx_g2_xy(wo, wi, b->alpha, b->alpha_y, b->separable) / (4.0f * wo.z * wi.z);
    float pv = rt_ggx_g1_xy(wo, b->alpha, b->alpha_y) * D / (4.0f * wo.z);
    if (!isfinite(spec) || !isfinite(pv))
        return rt_v3s(0.0f);
    *pdf = ps * pv;
    rt_vec3 f = rt_scale(rt_fresnel_conductor(voh, b->eta_c, b->k_c), spec);
    if (b->ms) {
        float m = (1.0f - rt_ggx_albedo(wo.z, b->ms_alpha)) * (1.0f - rt_ggx_albedo(wi.z, b->ms_alpha));
        f = rt_add(f, rt_scale(b->ms_scale, m));
        *pdf += pd * wi.z * RT_INV_PI;
    }
    return f;
}

/* The dielectric interface's f and pdf (glTF, dielectric, plastic; the
 * non-delta lobes), given its lobe probabilities. */
static rt_vec3 dielectric_eval(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi, float pd, float ps, float *pdf)
{
    *pdf = 0.0f;
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
        return rt_v3s(0.0f);
    rt_vec3 h = rt_add(wo, wi);
    float l2 = rt_length2(h);
    if (!(l2 > 1e-20f)) /* opposite directions: both grazing */
        return rt_v3s(0.0f);
    h = rt_scale(h, 1.0f / sqrtf(l2));
    float voh = rt_dot(wo, h);
    float fd = fresnel_dielectric(b, voh);
    /* diffuse: the dielectric's fresnel_mix leaves 1 - Fd to the base;
     * under a plastic's coat, what enters at wi and leaves at wo */
    float tdiff = b->kind == RT_BSDF_KIND_PLASTIC ? (1.0f - fresnel_dielectric(b, wo.z)) * (1.0f - fresnel_dielectric(b, wi.z))
                             : (1.0f - fd) * (1.0f - b->transmission);
    rt_vec3 f = rt_scale(b->diffuse, tdiff * RT_INV_PI);
    float p = pd * wi.z * RT_INV_PI;
    if (!b->delta) {
        rt_vec3 F = fresnel_specular(b, voh, fd);
        float D = rt_ggx_d(h, b->alpha);
        float G = rt_ggx_g2(wo, wi, b->alpha);
        float spec = D * G / (4.0f * wo.z * wi.z);
        if (!isfinite(spec))
            spec = 0.0f;
        f = rt_add(f, rt_scale(F, spec));
        if (ps > 0.0f) {
            float pv = rt_ggx_g1(wo, b->alpha) * D / (4.0f * wo.z);
            if (isfinite(pv))
                p += ps * pv;
        }
        if (b->ms) /* rough glass: the reflected multiple-scattering lobe, sampled as diffuse */
            f = rt_add(f, rt_v3s(b->ms_refl * (1.0f - rt_ggx_dielectric_albedo_at(&b->ms_cell[0], wo.z)) *
                                 (1.0f - rt_ggx_dielectric_albedo_at(&b->ms_cell[0], wi.z))));
    }
    *pdf = p;
    return f;
}

/* Lambert's probability of its one lobe: 1, or 0 for a black surface
 * (lobe_probs' value). */
static inline float lambert_prob(const rt_bsdf *b) { return mean3(b->diffuse) > 0.0f ? 1.0f : 0.0f; }

rt_vec3 rt_bsdf_eval(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi, float *pdf)
{
    float dummy, *p = pdf ? pdf : &dummy;
    float pd, ps, pt, ptm;
    switch (b->kind) {
    case RT_BSDF_KIND_LAMBERT: /* one cosine lobe, without the other lobes' bookkeeping */
        *p = 0.0f;
        if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
            return rt_v3s(0.0f);
        *p = lambert_prob(b) * wi.z * RT_INV_PI;
        return rt_scale(b->diffuse, RT_INV_PI);
    case RT_BSDF_KIND_GLTF_LAYERED: {
        layered_probs lp = layered_lobe_probs(b, wo);
        return layered_eval(b, wo, wi, &lp, p);
    }
    case RT_BSDF_KIND_CONDUCTOR:
        lobe_probs_at(b, wo, &pd, &ps, &pt, &ptm);
        return conductor_eval(b, wo, wi, pd, ps, p);
    case RT_BSDF_KIND_GLTF:
    case RT_BSDF_KIND_DIELECTRIC:
    case RT_BSDF_KIND_PLASTIC:
        lobe_probs_at(b, wo, &pd, &ps, &pt, &ptm);
        return dielectric_eval(b, wo, wi, pd, ps, p);
    }
    return rt_v3s(0.0f);
}

static bool delta_sample(rt_bsdf_sample *s, rt_vec3 wi, rt_vec3 w)
{
    s->wi = wi;
    s->weight = w;
    s->pdf = 0.0f;
    s->delta = true;
    return rt_finite3(wi) && rt_finite3(w) && rt_max3(w) > 0.0f;
}

/* Transmission through a thin-walled surface (KHR_materials_volume with
 * thickness 0: both interfaces of an infinitely thin sheet in one): the
 * microfacet reflection of wo (the macro normal's mirror when delta)
 * mirrored through the surface plane, so a smooth sheet passes light
 * straight on (wi = -wo) and a rough one blurs it as it blurs reflections;
 * weight c (1 - F(wo.h)) T G2 / G1 times `scale` (the share above it). */
static bool thin_transmit(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, rt_vec3 c, float scale, rt_bsdf_sample *s)
{
    rt_vec3 h = b->delta ? rt_v3(0.0f, 0.0f, 1.0f) : rt_ggx_sample_vndf(wo, b->alpha, u);
    float ci = rt_dot(wo, h);
    if (!(ci > 0.0f))
        return false;
    rt_vec3 r = rt_sub(rt_scale(h, 2.0f * ci), wo);
    if (!(r.z > 0.0f))
        return false;
    float g = b->delta ? 1.0f : rt_ggx_g2(wo, r, b->alpha) / rt_ggx_g1(wo, b->alpha);
    float f = b->transmission > 0.0f ? rt_fresnel_exact(ci, b->eta) : 0.0f;
    rt_vec3 wi = rt_normalize(rt_v3(r.x, r.y, -r.z));
    return delta_sample(s, wi, rt_scale(c, (1.0f - f) * g * b->transmission * scale));
}

/* ------------------------------------------------ extension layering
 *
 * The glTF material with the PBR-next extensions, as the extensions
 * define its layers (docs/shading.md, "Extension layering"):
 *
 *   Fd   = spec_weight rt_fresnel_schlick(min(F0 spec_color, 1), v.h)      KHR_materials_specular
 *          (the exact Fresnel times spec_color for a transmissive surface),
 *          mixed with the thin film's Fresnel by the iridescence factor
 *   Fm   = rt_fresnel_schlick(B, v.h), mixed with the film's Fresnel the same way
 *   base = (1 - m)(1 - max3(Fd)) ((1 - T)(1 - dt) B / pi + ...) + lerp(Fd, Fm, m) D V
 *          with D, V anisotropic GGX (alpha along t = mix(alpha, 1, s^2))
 *   sheen_layer = sheen f_sheen + base (1 - max3(sheen) max(E(wo), E(wi)))
 *   f    = sheen_layer min(1 - c Fc(n_c.wo), 1 - c Fc(n_c.wi)) + c f_coat
 *
 * The two albedo-scaling factors take the larger loss of the two
 * directions, so f stays reciprocal (the extensions' non-normative
 * shading uses wo only). Diffuse transmission (dt) and the refraction lobe
 * are sampled only (delta samples), as transmission is. */

/* KHR_materials_dispersion: the index at wavelength lambda (nm) from the
 * index n_d at 587.6 nm and the Abbe number V = 20 / dispersion, Cauchy's
 * n = A + B / lambda^2 through the Abbe definition (the extension's
 * max(n_d + (n_d - 1) / V (523655 / lambda^2 - 1.5168), 1)). */
static float dispersed_ior(float n_d, float dispersion, float lambda)
{
    float v_inv = dispersion / 20.0f;
    return fmaxf(n_d + (n_d - 1.0f) * v_inv * (523655.0f / (lambda * lambda) - 1.5168f), 1.0f);
}

static float clamp01(float x) { return isfinite(x) ? rt_clampf(x, 0.0f, 1.0f) : 0.0f; }

void rt_bsdf_set_ext(rt_bsdf *b, const rt_bsdf_ext *e)
{
    b->wo_z = NAN;
    if (b->kind != RT_BSDF_KIND_GLTF && b->kind != RT_BSDF_KIND_GLTF_LAYERED)
        return; /* the extensions extend the glTF BSDF only */
    b->spec_weight = clamp01(e->spec_weight);
    b->spec_color = rt_finite3(e->spec_color) ? rt_vmax(e->spec_color, rt_v3s(0.0f)) : rt_v3s(1.0f);
    b->clearcoat = clamp01(e->clearcoat);
    float cr = clamp01(e->clearcoat_roughness);
    b->cc_delta = cr == 0.0f;
    b->cc_alpha = fmaxf(cr * cr, RT_BSDF_MIN_ALPHA);
    rt_vec3 cn = e->clearcoat_normal;
    if (!rt_finite3(cn) || !(cn.z > 0.05f))
        cn = rt_v3(0.0f, 0.0f, 1.0f);
    b->cc_n = rt_normalize(cn);
    if (cn.x == 0.0f && cn.y == 0.0f) {
        b->cc_t = rt_v3(1.0f, 0.0f, 0.0f);
        b->cc_b = rt_v3(0.0f, 1.0f, 0.0f);
    } else {
        rt_onb(b->cc_n, &b->cc_t, &b->cc_b);
    }
    b->sheen = rt_finite3(e->sheen_color) ? rt_vmin(rt_vmax(e->sheen_color, rt_v3s(0.0f)), rt_v3s(1.0f)) : rt_v3s(0.0f);
    b->sheen_alpha = rt_sheen_alpha(e->sheen_roughness);
    b->iridescence = clamp01(e->iridescence);
    b->irid_ior = isfinite(e->iridescence_ior) && e->iridescence_ior >= 1.0f ? e->iridescence_ior : 1.3f;
    b->irid_thickness = isfinite(e->iridescence_thickness) ? fmaxf(e->iridescence_thickness, 0.0f) : 0.0f;
    b->diffuse_transmission = clamp01(e->diffuse_transmission);
    b->dt_color = rt_finite3(e->diffuse_transmission_color)
                      ? rt_vmin(rt_vmax(e->diffuse_transmission_color, rt_v3s(0.0f)), rt_v3s(1.0f))
                      : rt_v3s(1.0f);
    float s = clamp01(e->anisotropy);
    if (s > 0.0f) { /* KHR_materials_anisotropy: alpha along t grows to 1 with s^2 */
        float a = b->delta ? 0.0f : b->alpha;
        b->alpha = fmaxf(a + (1.0f - a) * s * s, RT_BSDF_MIN_ALPHA);
        b->delta = false;
    }
    /* dispersion: R, G, B at the Fraunhofer C, d and F lines, on the side
     * b->eta says (n_i / n_t: below 1 entering the denser material) */
    b->dispersive = false;
    if (isfinite(e->dispersion) && e->dispersion > 0.0f && b->transmission > 0.0f && b->eta > 0.0f &&
        b->eta != 1.0f) {
        bool entering = b->eta < 1.0f;
        float n_d = entering ? 1.0f / b->eta : b->eta;
        float n[3] = {dispersed_ior(n_d, e->dispersion, 656.3f), n_d, dispersed_ior(n_d, e->dispersion, 486.1f)};
        for (int k = 0; k < 3; k++)
            n[k] = entering ? 1.0f / n[k] : n[k];
        b->eta_rgb = rt_v3(n[0], n[1], n[2]);
        b->dispersive = true;
    }
    bool layered = b->dispersive || b->spec_weight != 1.0f || b->spec_color.x != 1.0f || b->spec_color.y != 1.0f ||
                 b->spec_color.z != 1.0f || b->clearcoat > 0.0f || rt_max3(b->sheen) > 0.0f || s > 0.0f ||
                 b->iridescence > 0.0f || b->diffuse_transmission > 0.0f;
    b->kind = layered ? RT_BSDF_KIND_GLTF_LAYERED : RT_BSDF_KIND_GLTF;
}

static inline rt_vec3 to_coat(const rt_bsdf *b, rt_vec3 w)
{
    return rt_v3(rt_dot(w, b->cc_t), rt_dot(w, b->cc_b), rt_dot(w, b->cc_n));
}

/* The dielectric and metal Fresnel of the layered glTF BSDF at cosine c
 * (v.h or, for the lobe estimates, n.v): *fd_max is max3(Fd), what the
 * dielectric's base loses. */
static rt_vec3 layered_fresnel(const rt_bsdf *b, float c, float *fd_max)
{
    rt_vec3 fd;
    rt_vec3 f0 = rt_vmin(rt_scale(b->spec_color, b->f0), rt_v3s(1.0f));
    if (b->transmission > 0.0f)
        fd = rt_vmin(rt_scale(b->spec_color, rt_fresnel_exact(c, b->eta)), rt_v3s(1.0f));
    else
        fd = rt_fresnel_schlick(f0, c);
    rt_vec3 fm = b->metallic > 0.0f ? rt_fresnel_schlick(b->base, c) : rt_v3s(0.0f);
    if (b->iridescence > 0.0f) {
        rt_vec3 fi = rt_iridescence_fresnel(1.0f, b->irid_ior, f0, b->irid_thickness, c);
        fd = rt_lerp3(fd, rt_vmin(fi, rt_v3s(1.0f)), b->iridescence);
        if (b->metallic > 0.0f)
            fm = rt_lerp3(fm, rt_vmin(rt_iridescence_fresnel(1.0f, b->irid_ior, b->base, b->irid_thickness, c),
                                      rt_v3s(1.0f)),
                          b->iridescence);
    }
    fd = rt_scale(fd, b->spec_weight);
    *fd_max = rt_max3(fd);
    return rt_lerp3(fd, fm, b->metallic);
}

/* The sheen layer's scaling of what lies under it, at one direction. */
static inline float sheen_scale(const rt_bsdf *b, float c)
{
    float s = rt_max3(b->sheen);
    return s > 0.0f ? 1.0f - s * rt_sheen_albedo(c, b->sheen_alpha) : 1.0f;
}

static inline float coat_scale(const rt_bsdf *b, float c)
{
    return b->clearcoat > 0.0f ? 1.0f - b->clearcoat * rt_clearcoat_fresnel(c) : 1.0f;
}

static layered_probs layered_lobe_probs(const rt_bsdf *b, rt_vec3 wo)
{
    layered_probs p = {0, 0, 0, 0, 0};
    float fd_max;
    rt_vec3 F = layered_fresnel(b, wo.z, &fd_max);
    float co = coat_scale(b, to_coat(b, wo).z), so = sheen_scale(b, wo.z);
    float ws = mean3(F) * co * so, td = 1.0f - fd_max;
    float wc = b->clearcoat * rt_clearcoat_fresnel(to_coat(b, wo).z);
    if (!b->delta) { /* floors as the core BSDF's, for lobes that can reflect at all */
        if (b->spec_weight > 0.0f || b->metallic > 0.0f)
            ws = fmaxf(ws, 0.02f);
        td = fmaxf(td, 0.1f);
    }
    if (!b->cc_delta && b->clearcoat > 0.0f)
        wc = fmaxf(wc, 0.02f);
    float wbase = mean3(b->diffuse) * td * co * so;
    float wsheen = co * mean3(b->sheen) * rt_sheen_albedo(wo.z, b->sheen_alpha);
    float wt = wbase * b->transmission;
    wbase *= 1.0f - b->transmission;
    float wdt = wbase * b->diffuse_transmission * mean3(b->dt_color);
    wbase *= 1.0f - b->diffuse_transmission;
    float wd = wbase + wsheen;
    float sum = wd + ws + wc + wt + wdt;
    if (!(sum > 0.0f) || !isfinite(sum))
        return p;
    p.d = wd / sum;
    p.s = ws / sum;
    p.c = wc / sum;
    p.t = wt / sum;
    p.dt = wdt / sum;
    return p;
}

static rt_vec3 layered_eval(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi, const layered_probs *p, float *pdf)
{
    *pdf = 0.0f;
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
        return rt_v3s(0.0f);
    rt_vec3 h = rt_add(wo, wi);
    float l2 = rt_length2(h);
    if (!(l2 > 1e-20f))
        return rt_v3s(0.0f);
    h = rt_scale(h, 1.0f / sqrtf(l2));
    float voh = rt_dot(wo, h);
    float fd_max;
    rt_vec3 F = layered_fresnel(b, voh, &fd_max);
    /* the base: diffuse under the dielectric, the specular lobe */
    float tdiff = (1.0f - fd_max) * (1.0f - b->transmission) * (1.0f - b->diffuse_transmission);
    rt_vec3 f = rt_scale(b->diffuse, tdiff * RT_INV_PI);
    float pr = p->d * wi.z * RT_INV_PI;
    if (!b->delta) {
        float D = rt_ggx_d_xy(h, b->alpha, b->alpha_y);
        float spec = D * rt_ggx_g2_xy(wo, wi, b->alpha, b->alpha_y, false) / (4.0f * wo.z * wi.z);
        if (isfinite(spec))
            f = rt_add(f, rt_scale(F, spec));
        float pv = rt_ggx_g1_xy(wo, b->alpha, b->alpha_y) * D / (4.0f * wo.z);
        if (p->s > 0.0f && isfinite(pv))
            pr += p->s * pv;
    }
    /* sheen over the base */
    if (rt_max3(b->sheen) > 0.0f) {
        float sc = fminf(sheen_scale(b, wo.z), sheen_scale(b, wi.z));
        f = rt_add(rt_scale(f, sc), rt_scale(b->sheen, rt_sheen_brdf(wo, wi, b->sheen_alpha)));
    }
    /* the coat over both */
    if (b->clearcoat > 0.0f) {
        rt_vec3 co = to_coat(b, wo), ci = to_coat(b, wi);
        float cs = fminf(coat_scale(b, co.z), coat_scale(b, ci.z));
        f = rt_scale(f, cs);
        if (!b->cc_delta) {
            float pc;
            float fc = b->clearcoat * rt_clearcoat_brdf(co, ci, b->cc_alpha, &pc);
            f = rt_add(f, rt_v3s(fc));
            pr += p->c * pc;
        }
    }
    *pdf = isfinite(pr) ? pr : 0.0f;
    return rt_finite3(f) ? f : rt_v3s(0.0f);
}

/* A sampled direction wi (unit, above the surface) whose BSDF value f and
 * pdf the sampler's mixture evaluated: the sample's weight f cos / pdf, or
 * false when the pdf or the weight is unusable. The end of both samplers. */
static inline bool finish_sample(rt_vec3 wi, rt_vec3 f, float pdf, rt_bsdf_sample *s)
{
    if (!(pdf > 0.0f) || !isfinite(pdf))
        return false;
    rt_vec3 w = rt_scale(f, wi.z / pdf);
    if (!rt_finite3(w))
        return false;
    s->wi = wi;
    s->weight = w;
    s->pdf = pdf;
    s->delta = false;
    return true;
}

static bool layered_sample(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, float ulobe, rt_bsdf_sample *s)
{
    layered_probs p = layered_lobe_probs(b, wo);
    float total = p.d + p.s + p.c + p.t + p.dt;
    if (!(total > 0.0f))
        return false;
    rt_vec3 co = to_coat(b, wo);
    float over = coat_scale(b, co.z) * sheen_scale(b, wo.z); /* what reaches the base from wo */
    float fd_max;
    if (ulobe >= p.d + p.s + p.c + p.t && p.dt > 0.0f) {
        /* diffuse transmission: a cosine lobe on the other side */
        rt_vec3 wi = rt_sample_cosine_hemisphere(u);
        wi.z = -wi.z;
        layered_fresnel(b, wo.z, &fd_max);
        float w = (1.0f - fd_max) * (1.0f - b->transmission) * b->diffuse_transmission * over / p.dt;
        return delta_sample(s, rt_normalize(wi), rt_scale(rt_mul(b->dt_color, rt_v3s(1.0f - b->metallic)), w));
    }
    if (ulobe >= p.d + p.s + p.c && p.t > 0.0f) {
        /* refraction, as the core BSDF's, under the coat and sheen; a
         * dispersive one refracts one channel, picked uniformly by the rest
         * of ulobe, with its own eta and 3 times its weight (the others 0) */
        if (b->thin)
            return thin_transmit(b, wo, u, b->diffuse, over / p.t, s);
        rt_vec3 h = b->delta ? rt_v3(0.0f, 0.0f, 1.0f) : rt_ggx_sample_vndf(wo, b->alpha, u);
        float eta = b->eta, ci = rt_dot(wo, h);
        rt_vec3 channel = rt_v3s(1.0f);
        if (b->dispersive) {
            float r = (ulobe - (p.d + p.s + p.c)) / p.t;
            int k = r < 1.0f / 3.0f ? 0 : (r < 2.0f / 3.0f ? 1 : 2);
            eta = k == 0 ? b->eta_rgb.x : (k == 1 ? b->eta_rgb.y : b->eta_rgb.z);
            channel = rt_v3(k == 0 ? 3.0f : 0.0f, k == 1 ? 3.0f : 0.0f, k == 2 ? 3.0f : 0.0f);
        }
        if (!(ci > 0.0f))
            return false;
        float sin2_t = eta * eta * fmaxf(0.0f, 1.0f - ci * ci);
        if (sin2_t >= 1.0f)
            return false;
        float ct = sqrtf(1.0f - sin2_t);
        rt_vec3 wi = rt_add(rt_scale(wo, -eta), rt_scale(h, eta * ci - ct));
        if (!(wi.z < 0.0f))
            return false;
        wi = rt_normalize(wi);
        layered_fresnel(b, ci, &fd_max);
        float g = b->delta ? 1.0f : rt_ggx_g2(wo, wi, b->alpha) / rt_ggx_g1(wo, b->alpha);
        rt_vec3 w = rt_mul(b->diffuse, channel);
        return delta_sample(s, wi, rt_scale(w, (1.0f - fd_max) * g * b->transmission * over / p.t));
    }
    if (ulobe >= p.d + p.s && p.c > 0.0f && b->cc_delta) {
        /* a mirror coat: reflect about the coat normal */
        rt_vec3 wi = rt_sub(rt_scale(b->cc_n, 2.0f * co.z), wo);
        if (!(wi.z > 0.0f))
            return false;
        return delta_sample(s, wi, rt_v3s(b->clearcoat * rt_clearcoat_fresnel(co.z) / p.c));
    }
    if (ulobe >= p.d && ulobe < p.d + p.s && b->delta) {
        /* the base's mirror (roughness 0) under the coat and sheen */
        rt_vec3 F = layered_fresnel(b, wo.z, &fd_max);
        rt_vec3 wi = rt_v3(-wo.x, -wo.y, wo.z);
        float cs = fminf(coat_scale(b, co.z), coat_scale(b, to_coat(b, wi).z));
        float ss = sheen_scale(b, wo.z);
        return delta_sample(s, wi, rt_scale(F, cs * ss / p.s));
    }
    rt_vec3 wi;
    if (ulobe < p.d || (b->delta && ulobe < p.d + p.s)) {
        wi = rt_sample_cosine_hemisphere(u);
    } else if (ulobe < p.d + p.s) {
        rt_vec3 h = rt_ggx_sample_vndf_xy(wo, b->alpha, b->alpha_y, u);
        wi = rt_sub(rt_scale(h, 2.0f * rt_dot(wo, h)), wo);
    } else {
        rt_vec3 wc = rt_clearcoat_sample(co, b->cc_alpha, u);
        wi = rt_add(rt_add(rt_scale(b->cc_t, wc.x), rt_scale(b->cc_b, wc.y)), rt_scale(b->cc_n, wc.z));
    }
    if (!(wi.z > 0.0f) || !rt_finite3(wi))
        return false;
    wi = rt_normalize(wi);
    float pdf;
    rt_vec3 f = layered_eval(b, wo, wi, &p, &pdf);
    return finish_sample(wi, f, pdf, s);
}

/* Lambert: the general path's steps for one cosine lobe of probability 1. */
static bool lambert_sample(const rt_bsdf *b, rt_vec2 u, rt_bsdf_sample *s)
{
    if (!(lambert_prob(b) > 0.0f))
        return false;
    rt_vec3 wi = rt_sample_cosine_hemisphere(u);
    if (!(wi.z > 0.0f) || !rt_finite3(wi))
        return false;
    wi = rt_normalize(wi);
    if (!(wi.z > 0.0f))
        return false; /* eval_lobes' test */
    return finish_sample(wi, rt_scale(b->diffuse, RT_INV_PI), 1.0f * wi.z * RT_INV_PI, s);
}

static bool conductor_sample(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, float ulobe, rt_bsdf_sample *s)
{
    float pd, ps, pt, ptm;
    lobe_probs_at(b, wo, &pd, &ps, &pt, &ptm);
    if (!(pd + ps + pt + ptm > 0.0f))
        return false;
    if (b->delta)
        return delta_sample(s, rt_v3(-wo.x, -wo.y, wo.z), rt_fresnel_conductor(wo.z, b->eta_c, b->k_c));
    rt_vec3 wi;
    if (ulobe < pd || !(ps > 0.0f)) {
        wi = rt_sample_cosine_hemisphere(u);
    } else {
        rt_vec3 h = rt_ggx_sample_vndf_xy(wo, b->alpha, b->alpha_y, u);
        wi = rt_sub(rt_scale(h, 2.0f * rt_dot(wo, h)), wo);
    }
    if (!(wi.z > 0.0f) || !rt_finite3(wi))
        return false;
    wi = rt_normalize(wi);
    float pdf;
    rt_vec3 f = conductor_eval(b, wo, wi, pd, ps, &pdf);
    return finish_sample(wi, f, pdf, s);
}

/* The dielectric interface (glTF, dielectric, plastic): its compensation's
 * transmitted lobe, refraction (thin or bending), a delta mirror, or the
 * diffuse and specular lobes. */
static bool dielectric_sample(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, float ulobe, rt_bsdf_sample *s)
{
    float pd, ps, pt, ptm;
    lobe_probs_at(b, wo, &pd, &ps, &pt, &ptm);
    if (!(pd + ps + pt + ptm > 0.0f))
        return false;
    if (ptm > 0.0f && ulobe >= pd + ps + pt) {
        /* rough glass: the transmitted multiple-scattering lobe, by the
         * cosine below the surface; sampled only, as refraction is */
        rt_vec3 c = rt_sample_cosine_hemisphere(u);
        rt_vec3 wi = rt_v3(c.x, c.y, -c.z);
        float f = rt_bsdf_ms_transmit(b, wo, wi);
        return c.z > 0.0f && delta_sample(s, wi, rt_v3s(f * RT_PI * b->eta * b->eta / ptm));
    }
    if (pt > 0.0f && ulobe >= pd + ps && b->thin)
        return thin_transmit(b, wo, u, b->diffuse, 1.0f / pt, s);
    if (pt > 0.0f && ulobe >= pd + ps) {
        /* refraction through a microfacet: the macro normal for a delta
         * interface, else a visible normal (Heitz 2018); the weight
         * f |cos| / pdf of Walter et al.'s BTDF with that sampling is
         * (1 - Fd) T c_diff G2 / G1(wo) */
        rt_vec3 h = b->delta ? rt_v3(0.0f, 0.0f, 1.0f) : rt_ggx_sample_vndf(wo, b->alpha, u);
        float eta = b->eta;
        float ci = rt_dot(wo, h);
        if (!(ci > 0.0f))
            return false;
        float sin2_t = eta * eta * rt_fmaxf(0.0f, 1.0f - ci * ci);
        if (sin2_t >= 1.0f)
            return false; /* total internal reflection: F = 1, the reflection lobe carries it */
        float ct = sqrtf(1.0f - sin2_t);
        rt_vec3 wi = rt_add(rt_scale(wo, -eta), rt_scale(h, eta * ci - ct));
        if (!(wi.z < 0.0f))
            return false; /* the microfacet sends it back out */
        wi = rt_normalize(wi);
        float fd = fresnel_dielectric(b, ci);
        float g = b->delta ? 1.0f : rt_ggx_g2(wo, wi, b->alpha) / rt_ggx_g1(wo, b->alpha);
        float scale = b->kind == RT_BSDF_KIND_DIELECTRIC ? eta * eta : 1.0f; /* L / n^2 is invariant */
        return delta_sample(s, wi, rt_scale(b->diffuse, (1.0f - fd) * g * b->transmission * scale / pt));
    }
    if (b->delta && ps > 0.0f && ulobe >= pd) {
        /* mirror reflection about the normal: weight F / (its probability) */
        float fd = fresnel_dielectric(b, wo.z);
        return delta_sample(s, rt_v3(-wo.x, -wo.y, wo.z), rt_scale(fresnel_specular(b, wo.z, fd), 1.0f / ps));
    }
    rt_vec3 wi;
    if (ulobe < pd || b->delta || !(ps > 0.0f)) {
        wi = rt_sample_cosine_hemisphere(u);
    } else {
        rt_vec3 h = rt_ggx_sample_vndf_xy(wo, b->alpha, b->alpha_y, u);
        wi = rt_sub(rt_scale(h, 2.0f * rt_dot(wo, h)), wo);
    }
    if (!(wi.z > 0.0f) || !rt_finite3(wi))
        return false;
    wi = rt_normalize(wi);
    float pdf;
    rt_vec3 f = dielectric_eval(b, wo, wi, pd, ps, &pdf);
    return finish_sample(wi, f, pdf, s);
}

bool rt_bsdf_sample_dir(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, float ulobe, rt_bsdf_sample *s)
{
    if (!(wo.z > 0.0f))
        return false;
    switch (b->kind) {
    case RT_BSDF_KIND_LAMBERT:
        return lambert_sample(b, u, s);
    case RT_BSDF_KIND_GLTF_LAYERED:
        return layered_sample(b, wo, u, ulobe, s);
    case RT_BSDF_KIND_CONDUCTOR:
        return conductor_sample(b, wo, u, ulobe, s);
    case RT_BSDF_KIND_GLTF:
    case RT_BSDF_KIND_DIELECTRIC:
    case RT_BSDF_KIND_PLASTIC:
        return dielectric_sample(b, wo, u, ulobe, s);
    }
    return false;
}
