/* ggx_albedo.c - lookups in the GGX albedo tables (rt/render/ggx_albedo.h)
 * and the average conductor Fresnel reflectance, the two ingredients of
 * Kulla and Conty's energy compensation (C. Kulla and A. Conty,
 * "Revisiting Physically Based Shading at Imageworks", SIGGRAPH 2017
 * course "Physically Based Shading in Theory and Practice", section on
 * multiple-scattering microfacet BSDFs). The tables come from
 * tools/ggx_albedo.c (src/render/ggx_albedo_table.c).
 */
#include "rt/render/ggx_albedo.h"

#include "rt/render/bsdf.h"

float rt_ggx_albedo(float mu, float alpha)
{
    enum { N = RT_GGX_ALBEDO_N };
    float x = rt_clampf(isfinite(mu) ? mu : 1.0f, 0.0f, 1.0f) * N - 0.5f;
    float y = rt_clampf(isfinite(alpha) ? alpha : 1.0f, 0.0f, 1.0f) * (N - 1);
    x = rt_clampf(x, 0.0f, (float)(N - 1));
    int i = (int)x, j = (int)y;
    if (i > N - 2)
        i = N - 2;
    if (j > N - 2)
        j = N - 2;
    float fx = x - (float)i, fy = y - (float)j;
    const float *r0 = rt_ggx_albedo_table[j], *r1 = rt_ggx_albedo_table[j + 1];
    float a = r0[i] + (r0[i + 1] - r0[i]) * fx;
    float b = r1[i] + (r1[i + 1] - r1[i]) * fx;
    return a + (b - a) * fy;
}

float rt_ggx_albedo_avg(float alpha)
{
    enum { N = RT_GGX_ALBEDO_N };
    float y = rt_clampf(isfinite(alpha) ? alpha : 1.0f, 0.0f, 1.0f) * (N - 1);
    int j = (int)y;
    if (j > N - 2)
        j = N - 2;
    float fy = y - (float)j;
    return rt_ggx_albedo_avg_table[j] + (rt_ggx_albedo_avg_table[j + 1] - rt_ggx_albedo_avg_table[j]) * fy;
}

rt_vec3 rt_fresnel_conductor_avg(rt_vec3 eta, rt_vec3 k)
{
    enum { M = 16 };
    rt_vec3 sum = rt_v3s(0.0f);
    for (int i = 0; i < M; i++)
        sum = rt_add(sum, rt_fresnel_conductor(sqrtf(((float)i + 0.5f) / M), eta, k));
    return rt_scale(sum, 1.0f / M);
}
