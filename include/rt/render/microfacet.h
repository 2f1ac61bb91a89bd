/* rt/render/microfacet.h - the microfacet and Fresnel building blocks every
 * lobe is made of: the GGX (Trowbridge-Reitz) distribution, its Smith
 * masking-shadowing terms, sampling its visible normals, and the Fresnel
 * reflectances (exact dielectric, exact conductor, Schlick). A leaf: it
 * knows vectors only, no material, surface or scene.
 *
 * Local frame: z is the normal, directions unit.
 *
 *   float D  = rt_ggx_d(h, alpha);                      // isotropic
 *   float G2 = rt_ggx_g2(wo, wi, alpha);                // height-correlated
 *   float Da = rt_ggx_d_xy(h, ax, ay);                  // anisotropic (ax along x)
 *   rt_vec3 h = rt_ggx_sample_vndf_xy(wo, ax, ay, u);   // a visible normal
 *   float F  = rt_fresnel_exact(cos_i, eta);            // glass, eta = n_i / n_t
 *   rt_vec3 Fc = rt_fresnel_conductor(cos_i, eta, k);   // metal, eta + i k
 *   rt_vec3 Fs = rt_fresnel_schlick(f0, cos_i);
 *
 * The small terms are inline (they sit in every lobe's inner loop); the
 * rest are in src/render/microfacet.c with their sources. Every result is
 * finite: grazing or degenerate directions give 0 (D, G, pdf) or 1 (F).
 */
#ifndef RT_MICROFACET_H
#define RT_MICROFACET_H

#include <stdbool.h>

#include "rt/base/vec.h"

/* D(h), 0 below the surface; h unit, stable to alpha 1e-4. Both terms
 * are evaluated from the tangent components: sin^2 = x^2 + y^2 is exact
 * near the normal, where 1 - cos^2 (and the textbook k = cos^2 (a^2 - 1)
 * + 1) cancels to nothing in single precision once alpha^2 falls below
 * the float epsilon. D = a^2 / (pi (a^2 cos^2 + sin^2)^2) then keeps full
 * relative precision down to alpha 1e-4 and below (a peak of 3e7). */
static inline float rt_ggx_d(rt_vec3 h, float alpha)
{
    if (!(h.z > 0.0f))
        return 0.0f;
    float a2 = alpha * alpha;
    float s2 = h.x * h.x + h.y * h.y;
    float k = a2 * (h.z * h.z) + s2;
    float d = a2 / (RT_PI * k * k);
    return isfinite(d) ? d : 0.0f;
}

/* Smith Lambda(w); INFINITY at or below the horizon. */
static inline float rt_ggx_lambda(rt_vec3 w, float alpha)
{
    float c2 = w.z * w.z;
    float s2 = w.x * w.x + w.y * w.y;
    if (!(c2 > 0.0f))
        return INFINITY;
    float t2 = alpha * alpha * s2 / c2; /* alpha^2 tan^2 theta */
    /* sqrt(1 + t2) - 1 without cancellation for small t2 */
    return 0.5f * t2 / (sqrtf(1.0f + t2) + 1.0f);
}

/* 1 / (1 + Lambda) */
static inline float rt_ggx_g1(rt_vec3 w, float alpha)
{
    float l = rt_ggx_lambda(w, alpha);
    return isfinite(l) ? 1.0f / (1.0f + l) : 0.0f;
}

/* height-correlated 1 / (1 + L(wo) + L(wi)) */
static inline float rt_ggx_g2(rt_vec3 wo, rt_vec3 wi, float alpha)
{
    float lo = rt_ggx_lambda(wo, alpha), li = rt_ggx_lambda(wi, alpha);
    if (!isfinite(lo) || !isfinite(li))
        return 0.0f;
    return 1.0f / (1.0f + lo + li);
}

/* Anisotropic GGX (alpha ax along x, ay along y; Heitz 2014, eq. 85 and
 * 86): D = 1 / (pi ax ay ((x/ax)^2 + (y/ay)^2 + z^2)^2), Lambda with
 * alpha^2 tan^2 = (ax^2 x^2 + ay^2 y^2) / z^2; the isotropic forms when
 * ax = ay. */
static inline float rt_ggx_d_xy(rt_vec3 h, float ax, float ay)
{
    if (ax == ay)
        return rt_ggx_d(h, ax);
    if (!(h.z > 0.0f))
        return 0.0f;
    float x = h.x / ax, y = h.y / ay;
    float k = x * x + y * y + h.z * h.z;
    float d = 1.0f / (RT_PI * ax * ay * k * k);
    return isfinite(d) ? d : 0.0f;
}

static inline float rt_ggx_lambda_xy(rt_vec3 w, float ax, float ay)
{
    if (ax == ay)
        return rt_ggx_lambda(w, ax);
    float c2 = w.z * w.z;
    if (!(c2 > 0.0f))
        return INFINITY;
    float t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / c2;
    return 0.5f * t2 / (sqrtf(1.0f + t2) + 1.0f);
}

static inline float rt_ggx_g1_xy(rt_vec3 w, float ax, float ay)
{
    float l = rt_ggx_lambda_xy(w, ax, ay);
    return isfinite(l) ? 1.0f / (1.0f + l) : 0.0f;
}

/* Smith G2: height-correlated 1 / (1 + L(wo) + L(wi)) (Heitz 2014, eq.
 * 99), or separable G1(wo) G1(wi) (eq. 98, as older renderers use). */
static inline float rt_ggx_g2_xy(rt_vec3 wo, rt_vec3 wi, float ax, float ay, bool separable)
{
    float lo = rt_ggx_lambda_xy(wo, ax, ay), li = rt_ggx_lambda_xy(wi, ax, ay);
    if (!isfinite(lo) || !isfinite(li))
        return 0.0f;
    return separable ? 1.0f / ((1.0f + lo) * (1.0f + li)) : 1.0f / (1.0f + lo + li);
}

/* A visible normal for wo (wo.z > 0) from u in [0,1)^2 (Heitz 2018),
 * isotropic and anisotropic. */
rt_vec3 rt_ggx_sample_vndf(rt_vec3 wo, float alpha, rt_vec2 u);
rt_vec3 rt_ggx_sample_vndf_xy(rt_vec3 wo, float ax, float ay, rt_vec2 u);
/* pdf of reflecting wo into wi by VNDF sampling: G1(wo) D(h) / (4 wo.z). */
float rt_ggx_reflect_pdf(rt_vec3 wo, rt_vec3 wi, float alpha);

/* Schlick's weight (1 - c)^5, c clamped to [0, 1]. */
static inline float rt_schlick_weight(float c)
{
    float x = 1.0f - rt_clampf(c, 0.0f, 1.0f);
    float x2 = x * x;
    return x2 * x2 * x;
}

/* Schlick's Fresnel f0 + (1 - f0)(1 - c)^5 per channel. */
static inline rt_vec3 rt_fresnel_schlick(rt_vec3 f0, float c)
{
    float w = rt_schlick_weight(c);
    return rt_add(f0, rt_scale(rt_sub(rt_v3s(1.0f), f0), w));
}

/* Exact unpolarised Fresnel reflectance of a smooth dielectric interface
 * (Born and Wolf, Principles of Optics, 1.5.2) at incident cosine cos_i,
 * eta = n_incident / n_transmitted; 1 past the critical angle. */
float rt_fresnel_exact(float cos_i, float eta);
/* Exact unpolarised Fresnel reflectance of a conductor of complex index
 * eta + i k (per channel, relative to the outside) at incident cosine cos_i. */
rt_vec3 rt_fresnel_conductor(float cos_i, rt_vec3 eta, rt_vec3 k);
/* Hemispherical (cosine-weighted) average of the exact Fresnel reflectance
 * at an interface of index ratio eta = n_incident / n_transmitted:
 * the internal diffuse reflectance for eta > 1. */
float rt_fresnel_diffuse_reflectance(float eta);

#endif
