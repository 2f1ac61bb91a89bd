/* rt/render/bsdf.h - the path tracer's scattering functions: Lambert and the glTF
 * metallic-roughness model (GGX microfacets, height-correlated Smith
 * masking-shadowing, Schlick Fresnel), with a smooth dielectric
 * transmission lobe for KHR_materials_transmission.
 *
 * Everything works in the local shading frame: z is the shading normal on
 * the side the light leaves towards (wo.z > 0), x and y the tangents.
 *
 *   rt_bsdf b;
 *   rt_bsdf_from_surface(&ctx, &sf, &b);              // material + textures at a hit (material_eval.h)
 *   // or rt_bsdf_make(&b, n, base, metallic, roughness, ior, transmission, lambert) and the like
 *   rt_vec3 wo = rt_bsdf_to_local(&b, sf.wo);
 *   float pdf;
 *   rt_vec3 f = rt_bsdf_eval(&b, wo, wi, &pdf);       // f (no cosine), pdf of rt_bsdf_sample
 *   rt_bsdf_sample s;
 *   if (rt_bsdf_sample_dir(&b, wo, u, ulobe, &s))     // s.weight = f cos / pdf
 *       ... rt_bsdf_to_world(&b, s.wi) ...
 *
 * Model, for base colour B, metallic m, roughness r, alpha = r^2, index of
 * refraction eta, transmission T: the normative form of the glTF 2.0
 * specification (appendix B.3.5, with KHR_materials_ior and
 * KHR_materials_transmission), the mix by metallic of a metal BRDF and a
 * dielectric one:
 *
 *   metal      = conductor_fresnel(f0 = B, specular)      = Fm specular
 *   dielectric = fresnel_mix(ior, base, layer = specular) = (1 - Fd) base + Fd specular
 *   base       = (1 - T) B / pi + T btdf
 *   f          = lerp(dielectric, metal, m)
 *              = (1 - m)(1 - Fd)(1 - T) B / pi  +  lerp(Fd, Fm, m) D V   (+ transmission)
 *   Fm         = B + (1 - B)(1 - |wo.h|)^5               (Schlick on the base colour)
 *   Fd         = F0 + (1 - F0)(1 - |wo.h|)^5, F0 = ((eta - 1) / (eta + 1))^2,
 *                or, for a transmissive surface (T > 0), the exact
 *                unpolarised Fresnel equations (rt_fresnel_exact), 1 past
 *                the critical angle
 *
 * with D the GGX (Trowbridge-Reitz) distribution and V = G2 / (4 |n.wo|
 * |n.wi|), G2 the height-correlated Smith masking-shadowing term. The
 * spec's "simplified" single-F0 form, F = Schlick(lerp(F0, B, m)) on both
 * lobes, has the same specular lobe (Schlick is linear in F0) but darkens
 * the diffuse lobe of partly metallic texels by (1 - F) instead of
 * (1 - m)(1 - Fd); rt no longer uses it. The transmitted share
 * (1 - m)(1 - Fd) T B refracts through a GGX microfacet (Walter et al.
 * 2007), sampled only (a "delta" sample: not light-sampled, no MIS).
 * Roughness exactly 0 is a true delta interface: mirror reflection and
 * refraction about the normal, both sampled only, so rt_bsdf_eval holds
 * just the diffuse lobe. RT_BSDF_KIND_LAMBERT is exactly B / pi.
 *
 * RT_BSDF_KIND_CONDUCTOR is a metal of complex index
 * eta + i k per channel: f = F_conductor(wo.h) D G2 / (4 cos_o cos_i) with
 * anisotropic GGX (alpha along t and b), G2 height-correlated or
 * separable; alpha 0 is a delta mirror of weight F_conductor(cos_o). With
 * energy compensation (rt_bsdf_compensate) a diffuse-like lobe adds back
 * the energy single scattering loses (Kulla and Conty 2017).
 *
 * Sampling picks a lobe by its estimated share of the reflected energy at
 * wo, then samples diffuse by the cosine, specular by the distribution of
 * visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible
 * Normals", JCGT 7(4)); the pdf is the mixture of the non-delta lobes
 * (one-sample MIS over the lobes), and rt_bsdf_eval returns the same pdf.
 */
#ifndef RT_BSDF_H
#define RT_BSDF_H

#include <stdbool.h>

#include "rt/render/ggx_albedo.h"
#include "rt/render/microfacet.h"

#define RT_BSDF_MIN_ALPHA 1e-4f /* GGX alpha floor for roughness > 0 (roughness 0 is a delta interface) */

/* Which lobes a BSDF has. A closed set: rt_bsdf_eval, rt_bsdf_sample_dir
 * and the lobe probabilities switch over it in bsdf.c (with no default, so
 * the compiler names every switch a new kind must join); the fields of
 * rt_bsdf below say which kinds read them. */
typedef enum rt_bsdf_kind {
    RT_BSDF_KIND_LAMBERT,      /* diffuse / pi */
    RT_BSDF_KIND_GLTF,         /* glTF metallic-roughness: diffuse, GGX specular, transmission (rt_bsdf_make) */
    RT_BSDF_KIND_GLTF_LAYERED, /* the same under the PBR-next extensions' layers (rt_bsdf_set_ext) */
    RT_BSDF_KIND_CONDUCTOR,    /* F(eta_c, k_c) D G2 / (4 cos cos), anisotropic GGX */
    RT_BSDF_KIND_DIELECTRIC,   /* glass of index ratio eta; refraction scales radiance by eta^2 (n_wo / n_wi)^2 */
    RT_BSDF_KIND_PLASTIC,      /* coat over Lambert: diffuse = R / (1 - R Fdr_in) / eta_in^2, times (1 - Fo)(1 - Fi) / pi */
} rt_bsdf_kind;

typedef struct rt_bsdf {
    rt_vec3 t, b, n;  /* shading frame, world space; n on the side of wo */
    rt_vec3 ng;       /* geometric normal on the side of wo */
    rt_bsdf_kind kind;
    bool delta;       /* roughness 0: mirror reflection and refraction, sampled only */
    rt_vec3 base;     /* base colour B: the metal's normal-incidence reflectance */
    rt_vec3 diffuse;  /* (1 - m) B (Lambert: the albedo) */
    float metallic;   /* m */
    float f0;         /* the dielectric's normal-incidence reflectance ((eta - 1) / (eta + 1))^2 */
    float alpha;      /* GGX alpha (at least RT_BSDF_MIN_ALPHA); along the tangent t for a conductor */
    float alpha_y;    /* GGX alpha along the bitangent b (= alpha unless anisotropic) */
    bool separable;   /* conductor: separable Smith G1 G1 instead of height-correlated */
    rt_vec3 eta_c, k_c; /* conductor: complex index relative to the outside */
    bool ms;          /* conductor or dielectric: Kulla-Conty multiple-scattering lobe (rt_bsdf_compensate) */
    float ms_alpha;   /* its table alpha, sqrt(alpha alpha_y) */
    rt_vec3 ms_scale; /* conductor: F_ms / (pi (1 - E_avg)): f_ms = ms_scale (1 - E(mu_o)) (1 - E(mu_i)) */
    float ms_x;       /* dielectric: the share of the lost energy at wo that crosses the interface */
    float ms_refl;    /* dielectric: f_ms,R = ms_refl (1 - E_o(mu_o)) (1 - E_o(mu_i)) */
    float ms_trans;   /* dielectric: f_ms,T = ms_trans (1 - E_o(mu_o)) (1 - E_t(|mu_i|)) (flux; x eta^2 for radiance) */
    rt_ggx_dielectric_cell ms_cell[2]; /* dielectric: E's table cells from wo's side (o) and the other (t) */
    float transmission; /* T */
    float eta;        /* index ratio across the surface along a transmitted ray: n_incident / n_transmitted */
    bool thin;        /* glTF transmission without a volume (thickness 0, thin-walled): light goes straight
                       * through, the microfacet reflection mirrored through the surface, no bending */
    /* The glTF PBR-next extensions over the glTF BSDF (docs/shading.md,
     * "Extension layering"); read by RT_BSDF_KIND_GLTF_LAYERED only: with
     * none on, rt_bsdf_set_ext leaves the kind RT_BSDF_KIND_GLTF (the core
     * BSDF above, bit for bit). */
    float spec_weight;     /* KHR_materials_specular: specularFactor x texture (A) */
    rt_vec3 spec_color;    /* specularColorFactor x texture: dielectric F0 = min(F0 spec_color, 1) */
    float clearcoat;       /* KHR_materials_clearcoat weight c */
    float cc_alpha;        /* the coat's GGX alpha (floored) */
    bool cc_delta;         /* coat roughness 0: a mirror coat */
    rt_vec3 cc_t, cc_b, cc_n; /* the coat's frame in the local frame (cc_n = (0,0,1) when the coat shares the shading normal) */
    rt_vec3 sheen;         /* KHR_materials_sheen colour (0: no sheen) */
    float sheen_alpha;     /* its alpha (rt_sheen_alpha) */
    float iridescence;     /* KHR_materials_iridescence factor */
    float irid_ior, irid_thickness; /* film index, thickness in nm */
    float diffuse_transmission; /* KHR_materials_diffuse_transmission factor */
    rt_vec3 dt_color;      /* its colour */
    bool dispersive;       /* KHR_materials_dispersion: refraction picks one channel's eta */
    rt_vec3 eta_rgb;       /* eta per channel (Cauchy through the Abbe number, at 656.3, 587.6, 486.1 nm) */
    /* rt_bsdf_set_wo's cache for the core BSDF (not layered): the lobe
     * probabilities at cos theta_o = wo_z (NaN: nothing cached) */
    float wo_z;
    float p_d, p_s, p_t, p_tm;
} rt_bsdf;

typedef struct rt_bsdf_sample {
    rt_vec3 wi;       /* local direction */
    rt_vec3 weight;   /* f |cos| / pdf, or the delta lobe's weight / its probability */
    float pdf;        /* solid-angle pdf; 0 for a delta sample */
    bool delta;       /* transmission or a mirror reflection: sampled only, never light-sampled, so no MIS */
} rt_bsdf_sample;

/* A BSDF from plain parameters, frame n (unit) with ng = n (tests; a hit's
 * BSDF comes from rt_bsdf_from_surface, rt/render/material_eval.h). */
void rt_bsdf_make(rt_bsdf *b, rt_vec3 n, rt_vec3 base, float metallic, float roughness, float ior,
                  float transmission, bool lambert);
/* A dielectric (bsdf dielectric): eta = n_wo / n_wi, GGX alpha (0: smooth). */
void rt_bsdf_make_dielectric(rt_bsdf *b, rt_vec3 n, float eta, float alpha);
/* Re-aims a dielectric at another medium beyond its surface (nested
 * media, rt/render/medium.h): eta = n_wo / n_wi, F0 from it. */
void rt_bsdf_set_eta(rt_bsdf *b, float eta);
/* A plastic (bsdf plastic): Lambertian reflectance R under a dielectric
 * coat, eta = n_outside / n_coat, coat GGX alpha (0: smooth). */
void rt_bsdf_make_plastic(rt_bsdf *b, rt_vec3 n, rt_vec3 R, float eta, float alpha);
/* A conductor (bsdf conductor) the same way: GGX alphas along x and y of
 * the frame (both 0: a delta mirror). */
void rt_bsdf_make_conductor(rt_bsdf *b, rt_vec3 n, rt_vec3 eta, rt_vec3 k, float alpha_x, float alpha_y,
                            bool separable);
/* The pieces the make functions are built of, for the material
 * evaluation: the frame (n unit, ng the geometric normal on its side; t, b
 * from rt_onb), then one model's parameters, which leave the frame alone:
 * Lambert of albedo base, the glTF metallic-roughness BSDF, a conductor
 * (separable: Smith G1 G1 instead of height-correlated). */
void rt_bsdf_set_frame(rt_bsdf *b, rt_vec3 n, rt_vec3 ng);
void rt_bsdf_set_lambert(rt_bsdf *b, rt_vec3 base);
void rt_bsdf_set_gltf(rt_bsdf *b, rt_vec3 base, float metallic, float roughness, float ior, float transmission);
void rt_bsdf_set_conductor(rt_bsdf *b, rt_vec3 eta, rt_vec3 k, float ax, float ay, bool separable);

/* Adds Kulla and Conty's (2017) multiple-scattering lobe to a rough
 * conductor (height-correlated Smith; nothing for a delta or separable
 * one): f_ms = F_ms (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)),
 * F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)) per channel, with the
 * tables of rt/render/ggx_albedo.h at alpha = sqrt(alpha_x alpha_y).
 * Sampled by the cosine with the probability of its share of the albedo.
 * To a rough dielectric (rt_bsdf_make_dielectric) it adds the same lobe
 * with E from the dielectric tables, split between a reflected lobe and
 * a transmitted one (docs/shading.md, section 14): the reflected part is
 * evaluated (light-sampled, MIS) with the cosine-sampled pdf, the
 * transmitted part is sampled only, as the refraction is;
 * rt_bsdf_set_eta recomputes it for another medium beyond.
 * rt_bsdf_from_surface calls it when the scene's energy_compensation is on. */
void rt_bsdf_compensate(rt_bsdf *b);
/* A compensated dielectric's transmitted multiple-scattering lobe f_ms,T
 * (flux form, without the eta^2 of radiance) from wo (above) to wi
 * (below the surface); 0 without compensation. For tests: n_o^2 f(wo, wi)
 * = n_t^2 f(wi, wo) seen from the other side. */
float rt_bsdf_ms_transmit(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi);

/* The glTF PBR-next extensions' parameters at a point (rt_bsdf_set_ext);
 * a material's come from rt_bsdf_ext_of_material, the defaults that leave
 * the core BSDF from rt_bsdf_ext_default (rt/render/material_eval.h). */
typedef struct rt_bsdf_ext {
    float spec_weight;          /* KHR_materials_specular: specularFactor */
    rt_vec3 spec_color;         /* specularColorFactor */
    float clearcoat, clearcoat_roughness; /* KHR_materials_clearcoat */
    rt_vec3 clearcoat_normal;   /* the coat's normal in the local frame ((0,0,1): the shading normal) */
    rt_vec3 sheen_color;        /* KHR_materials_sheen */
    float sheen_roughness;
    float anisotropy;           /* KHR_materials_anisotropy strength, along the frame's x (b->t) */
    float iridescence, iridescence_ior, iridescence_thickness; /* thickness in nm */
    float diffuse_transmission; /* KHR_materials_diffuse_transmission */
    rt_vec3 diffuse_transmission_color;
    float dispersion;           /* KHR_materials_dispersion: 20 / Abbe number (needs transmission) */
} rt_bsdf_ext;
/* Puts the extensions' layers over a glTF BSDF from rt_bsdf_make or
 * rt_bsdf_from_surface (anything else is left as it is); with the default
 * parameters b stays the core BSDF. */
void rt_bsdf_set_ext(rt_bsdf *b, const rt_bsdf_ext *e);

/* Computes once what rt_bsdf_eval and rt_bsdf_sample_dir need at this wo
 * whatever wi is (the lobe probabilities), for a vertex that evaluates
 * several light samples and draws one direction from one wo: call it after
 * the last change to b (rt_bsdf_set_eta, rt_bsdf_compensate, rt_bsdf_set_ext
 * forget it). The results are the same, bit for bit, with or without it. */
void rt_bsdf_set_wo(rt_bsdf *b, rt_vec3 wo);

static inline rt_vec3 rt_bsdf_to_local(const rt_bsdf *b, rt_vec3 w)
{
    return rt_v3(rt_dot(w, b->t), rt_dot(w, b->b), rt_dot(w, b->n));
}
static inline rt_vec3 rt_bsdf_to_world(const rt_bsdf *b, rt_vec3 w)
{
    return rt_add(rt_add(rt_scale(b->t, w.x), rt_scale(b->b, w.y)), rt_scale(b->n, w.z));
}

/* f(wo, wi) for the non-delta lobes (not times the cosine); *pdf (may be
 * NULL) receives the pdf rt_bsdf_sample_dir draws wi with. Zero when wo
 * or wi is below the surface. */
rt_vec3 rt_bsdf_eval(const rt_bsdf *b, rt_vec3 wo, rt_vec3 wi, float *pdf);
/* Draws wi from u (2D) and ulobe (lobe choice); false when nothing is
 * scattered (black material, wo below the surface, a zero pdf). */
bool rt_bsdf_sample_dir(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, float ulobe, rt_bsdf_sample *s);
/* Probability that rt_bsdf_sample_dir picks each lobe at wo (for tests). */
void rt_bsdf_lobe_probs(const rt_bsdf *b, rt_vec3 wo, float *p_diffuse, float *p_specular, float *p_transmit);

#endif
