/* ggx_albedo.c - lookups in the GGX albedo tables (rt/render/ggx_albedo.h)
 * and the average conductor Fresnel reflectance, the two ingredients of
 * Kulla and Conty's energy compensation (C. Kulla and A. Conty,
 * "Revisiting Physically Based Shading at Imageworks", SIGGRAPH 2017
 * course "Physically Based Shading in Theory and Practice", section on
 * multiple-scattering microfacet BSDFs), for conductors and, from both
 * sides of the interface, for rough glass. The tables come from
 * tools/ggx_albedo.c (src/render/ggx_albedo_table.c,
 * src/render/ggx_albedo_dielectric_table.c).
 */
#include "rt/render/ggx_albedo.h"

#include "rt/render/microfacet.h"

#include "ggx_albedo_table.h"

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

/* The dielectric tables' coordinates: side (0: eta < 1), the r row and
 * its weight, the alpha row and its weight. */
rt_ggx_dielectric_cell rt_ggx_dielectric_cell_of(float alpha, float eta)
{
    enum { N = RT_GGX_ALBEDO_N, NR = RT_GGX_DIELECTRIC_NR };
    rt_ggx_dielectric_cell c;
    eta = (eta > 0.0f && isfinite(eta)) ? eta : 1.0f;
    c.side = eta >= 1.0f;
    float ir2 = c.side ? 1.0f / (eta * eta) : eta * eta; /* 1 / r^2, rows uniform in it */
    float x = rt_clampf((1.0f - ir2) * (9.0f / 8.0f), 0.0f, 1.0f) * (NR - 1);
    float y = rt_clampf(isfinite(alpha) ? alpha : 1.0f, 0.0f, 1.0f) * (N - 1);
    c.k = (int)x;
    c.j = (int)y;
    if (c.k > NR - 2)
        c.k = NR - 2;
    if (c.j > N - 2)
        c.j = N - 2;
    c.fk = x - (float)c.k;
    c.fj = y - (float)c.j;
    return c;
}

static float bilerp(const float *r0, const float *r1, int i, float f, float g)
{
    float a = r0[i] + (r0[i + 1] - r0[i]) * f;
    float b = r1[i] + (r1[i + 1] - r1[i]) * f;
    return a + (b - a) * g;
}

float rt_ggx_dielectric_albedo(float mu, float alpha, float eta)
{
    rt_ggx_dielectric_cell c = rt_ggx_dielectric_cell_of(alpha, eta);
    return rt_ggx_dielectric_albedo_at(&c, mu);
}

float rt_ggx_dielectric_albedo_at(const rt_ggx_dielectric_cell *cp, float mu)
{
    enum { N = RT_GGX_ALBEDO_N };
    const rt_ggx_dielectric_cell c = *cp;
    float x = rt_clampf(isfinite(mu) ? mu : 1.0f, 0.0f, 1.0f) * N - 0.5f;
    x = rt_clampf(x, 0.0f, (float)(N - 1));
    int i = (int)x;
    if (i > N - 2)
        i = N - 2;
    float fx = x - (float)i;
    const float (*t0)[N] = rt_ggx_dielectric_table[c.side][c.k], (*t1)[N] = rt_ggx_dielectric_table[c.side][c.k + 1];
    float a = bilerp(t0[c.j], t0[c.j + 1], i, fx, c.fj);
    float b = bilerp(t1[c.j], t1[c.j + 1], i, fx, c.fj);
    return a + (b - a) * c.fk;
}

float rt_ggx_dielectric_albedo_avg(float alpha, float eta)
{
    rt_ggx_dielectric_cell c = rt_ggx_dielectric_cell_of(alpha, eta);
    return bilerp(rt_ggx_dielectric_avg_table[c.side][c.k], rt_ggx_dielectric_avg_table[c.side][c.k + 1], c.j, c.fj,
                  c.fk);
}

float rt_ggx_dielectric_ms_transmit(float alpha, float eta)
{
    eta = (eta > 0.0f && isfinite(eta)) ? eta : 1.0f;
    rt_ggx_dielectric_cell c = rt_ggx_dielectric_cell_of(alpha, eta);
    float m = bilerp(rt_ggx_dielectric_ms_table[c.k], rt_ggx_dielectric_ms_table[c.k + 1], c.j, c.fj, c.fk);
    return c.side ? m / (eta * eta) : m;
}

