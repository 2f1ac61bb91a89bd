/* rt/integrator.h - radiance along a camera ray, by the scene's integrator.
 *
 *   rt_vec3 L = rt_radiance(&ctx, &ray, &rng);
 *
 * direct   emission + direct light from every light (area lights with
 *          settings.shadow_samples stratified samples) with a Lambertian
 *          BRDF (albedo / pi), shadows through transmissive and alpha-tested
 *          surfaces, and one cosine-sampled ray towards a non-black
 *          environment. The foundation's integrator: exact for its scenes.
 * whitted  Phong, mirrors, refraction with exact Fresnel through nested
 *          media, shadows through glass, diffuse bounces (whitted.c,
 *          rt/whitted.h; the model is specified in docs/shading.md).
 * path     physically based path tracing of glTF materials with
 *          next-event estimation and MIS (pathtrace.c, rt/render/pathtrace.h,
 *          docs/path-tracer.md).
 */
#ifndef RT_INTEGRATOR_H
#define RT_INTEGRATOR_H

#include "rt/render/sampling.h"
#include "rt/render/surface.h"

rt_vec3 rt_radiance(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);
rt_vec3 rt_radiance_direct(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

/* Direct light from every light at a Lambertian surface of albedo `albedo`,
 * shared by the integrators. */
rt_vec3 rt_direct_lambert(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 albedo, rt_rng *rng);

#endif
