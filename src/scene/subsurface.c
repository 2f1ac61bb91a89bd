/* subsurface.c - a material's random-walk subsurface parameters as a
 * homogeneous medium inside it (rt/scene/subsurface.h). Sources: Cycles'
 * random walk (Blender 2.8x subsurface_random_walk_remap) and
 * Christensen and Burley, "Approximate reflectance profiles for efficient
 * subsurface scattering" (Pixar technical memo 2015) for the radius's
 * scale s(A); van de Hulst's albedo of a semi-infinite medium as inverted
 * by the KHR_materials_volume_scatter draft (KhronosGroup glTF pull
 * request 2453) after Kulla and Conty, "Revisiting physically based
 * shading at Imageworks" (SIGGRAPH 2017 course), for the single-scattering
 * albedo;
 * similarity theory (Wyman, Patterson and Bigio 1989; Zhao, Wu, Ramamoorthi
 * and Bala, "High-order similarity relations in radiative transfer",
 * SIGGRAPH 2014) for the anisotropy.
 */
#include "rt/scene/subsurface.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }

float rt_subsurface_single_albedo(float A)
{
    A = clamp01(A);
    float r = 4.09712f + 4.20863f * A - sqrtf(9.59217f + 41.6808f * A + 17.7126f * A * A);
    return clamp01(1.0f - r * r);
}

float rt_subsurface_radius_scale(float A)
{
    A = clamp01(A);
    return 1.9f - A + 3.5f * (A - 0.8f) * (A - 0.8f);
}

static float ch(rt_vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

bool rt_subsurface_medium(const rt_material *m, rt_medium_def *out)
{
    if (!m->subsurface || m->thin_walled)
        return false;
    float g = m->subsurface_g;
    g = g > RT_MEDIUM_G_MAX ? RT_MEDIUM_G_MAX : (g < -RT_MEDIUM_G_MAX ? -RT_MEDIUM_G_MAX : g);
    bool from_radius = rt_max3(m->subsurface_radius) > 0.0f;
    if (!from_radius && !(isfinite(m->attenuation_distance) && m->attenuation_distance > 0.0f))
        return false; /* glTF: no attenuation, no medium */
    float sa[3], ss[3];
    for (int k = 0; k < 3; k++) {
        float A = clamp01(ch(m->subsurface_albedo, k));
        float sigma_t, alpha = rt_subsurface_single_albedo(A);
        if (from_radius) {
            float d = ch(m->subsurface_radius, k);
            sigma_t = d > 0.0f ? 1.0f / fmaxf(d * rt_subsurface_radius_scale(A), 1e-16f) : 0.0f;
        } else {
            float c = fmaxf(ch(m->attenuation_color, k), 1e-6f);
            sigma_t = -logf(c) / m->attenuation_distance;
        }
        ss[k] = sigma_t * alpha;
        sa[k] = fmaxf(sigma_t - ss[k], 0.0f);
        if (from_radius) /* the same reduced scattering sigma_s (1 - g) as the isotropic medium */
            ss[k] /= 1.0f - g;
    }
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%.40s (subsurface)", m->name);
    out->kind = RT_MEDIUM_HOMOGENEOUS;
    out->sigma_a = rt_v3(sa[0], sa[1], sa[2]);
    out->sigma_s = rt_v3(ss[0], ss[1], ss[2]);
    out->g = g;
    out->index_to_world = out->world_to_index = rt_mat4_identity();
    return rt_finite3(out->sigma_a) && rt_finite3(out->sigma_s);
}

bool rt_subsurface_attach(rt_scene *s, rt_material *m)
{
    rt_medium_def md;
    if (!rt_subsurface_medium(m, &md))
        return true;
    uint32_t id = rt_scene_add_medium(s, &md);
    if (id == RT_NONE)
        return false;
    m->interior_medium = id;
    if (!(rt_max3(m->subsurface_radius) > 0.0f))
        m->attenuation_distance = INFINITY; /* glTF: the medium's extinction now */
    return true;
}
