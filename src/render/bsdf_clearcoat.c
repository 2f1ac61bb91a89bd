/* bsdf_clearcoat.c - the KHR_materials_clearcoat lobe (see
 * rt/render/bsdf_clearcoat.h).
 *
 * Sources: the KHR_materials_clearcoat specification (Khronos, ratified):
 * clearcoat_brdf = specular_brdf(normal = clearcoatNormal,
 * alpha = clearcoatRoughness^2), layered by fresnel_coat with ior 1.5, i.e.
 * Schlick's F with F0 = 0.04; glTF 2.0 appendix B.3 for the microfacet
 * specular_brdf (GGX D, height-correlated Smith V). The Fresnel is taken at
 * the microfacet (wo.h) inside the lobe, as appendix B's fresnel_mix does,
 * which keeps the lobe reciprocal; the layers below are scaled by what the
 * coat transmits at the macro normal (bsdf.c). GGX helpers: rt/render/microfacet.h.
 */
#include "rt/render/bsdf_clearcoat.h"

#include <math.h>

#include "rt/render/microfacet.h"

float rt_clearcoat_fresnel(float cos_t)
{
    const float r0 = (RT_CLEARCOAT_IOR - 1.0f) / (RT_CLEARCOAT_IOR + 1.0f);
    const float f0 = r0 * r0;
    float x = 1.0f - rt_clampf(cos_t, 0.0f, 1.0f);
    float x2 = x * x;
    return f0 + (1.0f - f0) * x2 * x2 * x;
}

float rt_clearcoat_brdf(rt_vec3 wo, rt_vec3 wi, float alpha, float *pdf)
{
    if (pdf)
        *pdf = 0.0f;
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
        return 0.0f;
    rt_vec3 h = rt_add(wo, wi);
    float l2 = rt_length2(h);
    if (!(l2 > 1e-20f))
        return 0.0f;
    h = rt_scale(h, 1.0f / sqrtf(l2));
    float D = rt_ggx_d(h, alpha);
    float f = rt_clearcoat_fresnel(rt_dot(wo, h)) * D * rt_ggx_g2(wo, wi, alpha) / (4.0f * wo.z * wi.z);
    if (pdf) {
        float p = rt_ggx_g1(wo, alpha) * D / (4.0f * wo.z);
        *pdf = isfinite(p) ? p : 0.0f;
    }
    return isfinite(f) ? f : 0.0f;
}

rt_vec3 rt_clearcoat_sample(rt_vec3 wo, float alpha, rt_vec2 u)
{
    rt_vec3 h = rt_ggx_sample_vndf(wo, alpha, u);
    return rt_sub(rt_scale(h, 2.0f * rt_dot(wo, h)), wo);
}
