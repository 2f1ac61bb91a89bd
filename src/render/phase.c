/* phase.c - the Henyey-Greenstein phase function, its value and its exact
 * inverse-CDF sampling (see rt/render/phase.h). The formulas are the
 * standard ones (Pharr, Jakob, Humphreys, "Physically Based Rendering",
 * 4th ed., section 11.3.1), written for directions of travel.
 */
#include "rt/render/phase.h"

#include <math.h>

static float clamp_g(float g)
{
    return rt_clampf(g, -RT_HG_G_MAX, RT_HG_G_MAX);
}

float rt_hg_pdf(float g, float cos_theta)
{
    g = clamp_g(g);
    float denom = 1.0f + g * g - 2.0f * g * cos_theta;
    denom = rt_fmaxf(denom, 1e-12f);
    return (1.0f - g * g) / (4.0f * RT_PI * denom * sqrtf(denom));
}

float rt_hg_sample_cos(float g, float u)
{
    g = clamp_g(g);
    float c;
    if (fabsf(g) < 1e-3f) {
        c = 1.0f - 2.0f * u; /* isotropic: the expansion below loses every digit */
    } else {
        /* invert the CDF of cos_theta: P(cos <= c) = u */
        float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
        c = (1.0f + g * g - s * s) / (2.0f * g);
    }
    return rt_clampf(c, -1.0f, 1.0f);
}

rt_vec3 rt_hg_sample(float g, rt_vec3 d_in, float u1, float u2, float *pdf)
{
    float c = rt_hg_sample_cos(g, u1);
    float s = sqrtf(rt_fmaxf(0.0f, 1.0f - c * c));
    float sp, cp;
    rt_sincosf(2.0f * RT_PI * u2, &sp, &cp);
    rt_vec3 t, b;
    rt_onb(d_in, &t, &b);
    rt_vec3 d = rt_add(rt_add(rt_scale(t, s * cp), rt_scale(b, s * sp)), rt_scale(d_in, c));
    d = rt_normalize(d);
    if (pdf)
        *pdf = rt_hg_pdf(g, rt_dot(d_in, d));
    return d;
}
