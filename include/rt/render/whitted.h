/* rt/render/whitted.h - the classic ray tracer: Phong shading, mirrors, refraction
 * with exact Fresnel, shadows through glass, diffuse bounces.
 *
 *   rt_vec3 L = rt_radiance_whitted(&ctx, &ray, &rng);
 *
 * The shading model and its energy split are specified exactly in
 * docs/shading.md; rt_radiance() dispatches here for `integrator whitted`.
 * The optics are exposed for tests and for other integrators:
 *
 *   rt_fresnel f = rt_fresnel_dielectric(cos_i, 1.0f, 1.5f);  // f.r + f.t == 1
 *   rt_vec3 t;
 *   if (rt_refract(d, n, 1.0f, 1.5f, &t)) ...                   // Snell's law
 */
#ifndef RT_WHITTED_H
#define RT_WHITTED_H

#include "rt/render/medium.h"
#include "rt/render/sampling.h"
#include "rt/render/surface.h"

/* Exact Fresnel equations for a smooth dielectric interface (Born and Wolf,
 * "Principles of Optics", 1.5.2), light going from index n1 into n2 at
 * incidence cosine cos_i in [0, 1]. Power coefficients: rs, rp reflectance
 * and ts, tp transmittance for s- and p-polarised light, computed from their
 * own amplitude formulas (so rs + ts == 1 is a check, not an identity);
 * r, t: unpolarised (the mean of s and p). tir: total internal reflection
 * (then r = 1, t = 0, cos_t = 0). */
typedef struct rt_fresnel {
    float rs, rp, ts, tp;
    float r, t;
    float cos_t; /* cosine of the refraction angle */
    bool tir;
} rt_fresnel;

rt_fresnel rt_fresnel_dielectric(float cos_i, float n1, float n2);

/* Refracts unit direction d at a surface with unit normal n on the incident
 * side (dot(d, n) < 0) from index n1 into n2 (Snell: n1 sin i = n2 sin t).
 * False on total internal reflection. n1 == n2 gives d unchanged. */
bool rt_refract(rt_vec3 d, rt_vec3 n, float n1, float n2, rt_vec3 *t);

/* The media a ray is inside (rt_medium_stack of rt/render/medium.h),
 * oldest first, as material indices, under the path tracer's rules
 * (priorities, false intersections, overflow drops the outermost), every
 * transmissive material being a medium. The index of refraction a ray
 * travels in is the current medium's (highest priority, ties: the last
 * entered), 1 (vacuum/air) when empty. */
float rt_medium_ior(const rt_scene *s, const rt_medium_stack *m);

rt_vec3 rt_radiance_whitted(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);
/* The same for a ray that starts inside the given media (NULL = air). */
rt_vec3 rt_radiance_whitted_in(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng,
                               const rt_medium_stack *start);

#endif
