/* bsdf_iridescence.c - thin-film interference Fresnel for
 * KHR_materials_iridescence (see rt/render/bsdf_iridescence.h).
 *
 * Sources: the KHR_materials_iridescence specification (Khronos,
 * ratified), "Material Interfaces", "Phase Shift" and "Analytic Spectral
 * Integration": two interfaces with Schlick reflectances R12 (outside to
 * film) and R23 (film to base, the base index from its F0), the optical
 * path difference 2 n_film d cos(theta_2), phase shifts of 0 or pi, the
 * Airy sum to the second order with the XYZ sensitivity of each order as
 * Gaussians in Fourier space, then XYZ to linear Rec.709. After L. Belcour
 * and P. Barla 2017, "A Practical Extension to Microfacet Theory for the
 * Modeling of Varying Iridescence" (ACM TOG 36(4), SIGGRAPH), section 4.
 * The film's optical path uses the refracted cosine (theta_2, inside the
 * film), as Belcour and Barla's derivation does.
 */
#include "rt/render/bsdf_iridescence.h"

#include <math.h>

static float sq(float x) { return x * x; }

static float ior_to_f0(float transmitted, float incident) { return sq((transmitted - incident) / (transmitted + incident)); }

static float schlick1(float f0, float c)
{
    float x = 1.0f - rt_clampf(c, 0.0f, 1.0f);
    float x2 = x * x;
    return f0 + (1.0f - f0) * x2 * x2 * x;
}

/* The spectral sensitivity of one interference order, XYZ to Rec.709. */
static rt_vec3 sensitivity(float opd, rt_vec3 shift)
{
    const double two_pi = 6.283185307179586;
    double phase = two_pi * (double)opd * 1.0e-9;
    const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13};
    const double pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06};
    const double var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
    const double sh[3] = {shift.x, shift.y, shift.z};
    double xyz[3];
    for (int i = 0; i < 3; i++)
        xyz[i] = val[i] * sqrt(two_pi * var[i]) * cos(pos[i] * phase + sh[i]) * exp(-phase * phase * var[i]);
    xyz[0] += 9.7470e-14 * sqrt(two_pi * 4.5282e+09) * cos(2.2399e+06 * phase + sh[0]) * exp(-4.5282e+09 * phase * phase);
    for (int i = 0; i < 3; i++)
        xyz[i] /= 1.0685e-7;
    return rt_v3((float)(3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2]),
                 (float)(-0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2]),
                 (float)(0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2]));
}

rt_vec3 rt_iridescence_fresnel(float outside_ior, float film_ior, rt_vec3 base_f0, float thickness_nm, float cos_t)
{
    float c1 = rt_clampf(cos_t, 0.0f, 1.0f);
    base_f0 = rt_vmin(rt_vmax(base_f0, rt_v3s(0.0f)), rt_v3s(0.9999f));
    if (!(thickness_nm > 0.0f) || !(film_ior > 0.0f) || !(outside_ior > 0.0f))
        return rt_v3(schlick1(base_f0.x, c1), schlick1(base_f0.y, c1), schlick1(base_f0.z, c1));
    float n_film = film_ior;
    float sin2_2 = sq(outside_ior / n_film) * (1.0f - c1 * c1);
    if (sin2_2 >= 1.0f)
        return rt_v3s(1.0f); /* total internal reflection into the film */
    float c2 = sqrtf(1.0f - sin2_2);
    /* first interface */
    float r12 = schlick1(ior_to_f0(n_film, outside_ior), c1);
    float t121 = 1.0f - r12;
    float phi12 = n_film < outside_ior ? RT_PI : 0.0f;
    float phi21 = RT_PI - phi12;
    /* second interface: the base's index from its F0 (air above assumed) */
    float f0[3] = {base_f0.x + 1e-4f, base_f0.y + 1e-4f, base_f0.z + 1e-4f};
    float r23[3], phi23[3];
    for (int i = 0; i < 3; i++) {
        float sf = sqrtf(fminf(f0[i], 0.9999f));
        float base_ior = (1.0f + sf) / (1.0f - sf);
        r23[i] = schlick1(ior_to_f0(base_ior, n_film), c2);
        phi23[i] = base_ior < n_film ? RT_PI : 0.0f;
    }
    float opd = 2.0f * n_film * thickness_nm * c2;
    rt_vec3 phi = rt_v3(phi21 + phi23[0], phi21 + phi23[1], phi21 + phi23[2]);
    float out[3];
    for (int i = 0; i < 3; i++) {
        float r123 = rt_clampf(r12 * r23[i], 1e-5f, 0.9999f);
        float sr = sqrtf(r123);
        float rs = sq(t121) * r23[i] / (1.0f - r123);
        float I = r12 + rs; /* the m = 0 term */
        float cm = rs - t121;
        for (int m = 1; m <= 2; m++) {
            cm *= sr;
            rt_vec3 sm = sensitivity((float)m * opd, rt_scale(phi, (float)m));
            float smi = i == 0 ? sm.x : (i == 1 ? sm.y : sm.z);
            I += cm * 2.0f * smi;
        }
        out[i] = fmaxf(I, 0.0f);
    }
    return rt_v3(out[0], out[1], out[2]);
}
