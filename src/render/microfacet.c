/* microfacet.c - the GGX and Fresnel building blocks that are not inline
 * in rt/render/microfacet.h: sampling the visible normals, the reflection
 * pdf of that sampling, and the exact Fresnel reflectances.
 *
 * Sources:
 * - GGX / Trowbridge-Reitz distribution and its Smith Lambda: Walter,
 *   Marschner, Li, Torrance 2007, "Microfacet Models for Refraction through
 *   Rough Surfaces" (EGSR); height-correlated masking-shadowing: Heitz 2014,
 *   "Understanding the Masking-Shadowing Function in Microfacet-Based
 *   BRDFs" (JCGT 3(2)), eq. 99: G2 = 1 / (1 + Lambda(wo) + Lambda(wi));
 *   anisotropic D and Lambda, eqs. 85, 86; the separable G1 G1, eq. 98.
 * - Sampling visible normals: Heitz 2018, "Sampling the GGX Distribution
 *   of Visible Normals" (JCGT 7(4)), listing 1, with the stretch by
 *   (ax, ay) for anisotropy; its pdf D_wo(h) / (4 wo.h) = G1(wo) D(h) /
 *   (4 wo.z) for reflection.
 * - Exact Fresnel equations for a dielectric (Born and Wolf, "Principles of
 *   Optics", 7th ed., 1.5.2) and for a conductor of complex index (Born and
 *   Wolf, 14.2; the closed form of pbrt-v3, Pharr, Jakob, Humphreys, 8.2.1).
 * - The hemispherical average of the dielectric Fresnel by the midpoint
 *   rule, and its value from the denser side by reciprocity.
 */
#include "rt/render/microfacet.h"

rt_vec3 rt_ggx_sample_vndf_xy(rt_vec3 wo, float ax, float ay, rt_vec2 u)
{
    /* stretch the view direction to the hemisphere configuration */
    rt_vec3 vh = rt_normalize(rt_v3(ax * wo.x, ay * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    rt_vec3 t1 = lensq > 1e-14f ? rt_scale(rt_v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(lensq)) : rt_v3(1, 0, 0);
    rt_vec3 t2 = rt_cross(vh, t1);
    /* a point on the projected area of the hemisphere */
    float r = sqrtf(u.x), phi = 2.0f * RT_PI * u.y;
    float sn, cs;
    rt_sincosf(phi, &sn, &cs);
    float p1 = r * cs, p2 = r * sn;
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(rt_fmaxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    rt_vec3 nh = rt_add(rt_add(rt_scale(t1, p1), rt_scale(t2, p2)),
                        rt_scale(vh, sqrtf(rt_fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2))));
    /* unstretch */
    rt_vec3 ne = rt_v3(ax * nh.x, ay * nh.y, rt_fmaxf(1e-7f, nh.z));
    return rt_normalize(ne);
}

rt_vec3 rt_ggx_sample_vndf(rt_vec3 wo, float alpha, rt_vec2 u) { return rt_ggx_sample_vndf_xy(wo, alpha, alpha, u); }

float rt_ggx_reflect_pdf(rt_vec3 wo, rt_vec3 wi, float alpha)
{
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
        return 0.0f;
    rt_vec3 h = rt_add(wo, wi);
    float l2 = rt_length2(h);
    if (!(l2 > 1e-20f))
        return 0.0f;
    h = rt_scale(h, 1.0f / sqrtf(l2));
    float p = rt_ggx_g1(wo, alpha) * rt_ggx_d(h, alpha) / (4.0f * wo.z);
    return isfinite(p) ? p : 0.0f;
}

/* Exact unpolarised Fresnel reflectance of a conductor, eta + i k relative
 * to the outside, one channel (the closed form of pbrt-v3, 8.2.1, after
 * Born and Wolf 14.2). */
static float fresnel_conductor1(float c, float eta, float k)
{
    c = rt_clampf(c, 0.0f, 1.0f);
    float c2 = c * c, s2 = 1.0f - c2;
    float eta2 = eta * eta, k2 = k * k;
    float t0 = eta2 - k2 - s2;
    float a2b2 = sqrtf(rt_fmaxf(0.0f, t0 * t0 + 4.0f * eta2 * k2));
    float t1 = a2b2 + c2;
    float a = sqrtf(rt_fmaxf(0.0f, 0.5f * (a2b2 + t0)));
    float t2 = 2.0f * c * a;
    float rs = (t1 - t2) / (t1 + t2);
    float t3 = c2 * a2b2 + s2 * s2;
    float t4 = t2 * s2;
    float rp = rs * (t3 - t4) / (t3 + t4);
    float f = 0.5f * (rs + rp);
    return isfinite(f) ? rt_clampf(f, 0.0f, 1.0f) : 1.0f;
}

rt_vec3 rt_fresnel_conductor(float cos_i, rt_vec3 eta, rt_vec3 k)
{
    return rt_v3(fresnel_conductor1(cos_i, eta.x, k.x), fresnel_conductor1(cos_i, eta.y, k.y),
                 fresnel_conductor1(cos_i, eta.z, k.z));
}

float rt_fresnel_exact(float cos_i, float eta)
{
    float ci = rt_clampf(cos_i, 0.0f, 1.0f);
    float sin2_t = eta * eta * (1.0f - ci * ci);
    if (!(sin2_t < 1.0f))
        return 1.0f; /* total internal reflection (or a NaN input) */
    float ct = sqrtf(1.0f - sin2_t);
    float rs = (eta * ci - ct) / (eta * ci + ct);
    float rp = (ci - eta * ct) / (ci + eta * ct);
    float f = 0.5f * (rs * rs + rp * rp);
    return isfinite(f) ? rt_clampf(f, 0.0f, 1.0f) : 1.0f;
}

float rt_fresnel_diffuse_reflectance(float eta)
{
    /* seen from the denser side: by reciprocity what does not reflect
     * inside is what enters from outside, shrunk by the solid angle ratio,
     * Fdr(eta) = 1 - (1 - Fdr(1 / eta)) / eta^2 (no kink to integrate) */
    if (eta > 1.0f)
        return 1.0f - (1.0f - rt_fresnel_diffuse_reflectance(1.0f / eta)) / (eta * eta);
    /* integral of F(c) 2c dc, midpoint rule (F is smooth from outside:
     * 64 points are within 2e-5) */
    enum { N = 64 };
    float sum = 0.0f;
    for (int i = 0; i < N; i++) {
        float c = ((float)i + 0.5f) / N;
        sum += rt_fresnel_exact(c, eta) * 2.0f * c;
    }
    return sum / N;
}
