/* rt/render/direct.h - the `direct` integrator: emission + direct light
 * from every light (area lights with settings.shadow_samples stratified
 * samples) with a Lambertian BRDF (albedo / pi), shadows through
 * transmissive and alpha-tested surfaces, and one cosine-sampled ray
 * towards a non-black environment. The foundation's integrator: exact for
 * its scenes.
 *
 *   rt_vec3 L = rt_radiance_direct(&ctx, &ray, &rng);   // via rt_radiance()
 *   rt_vec3 E = rt_direct_lambert(&ctx, &sf, albedo, &rng);
 */
#ifndef RT_DIRECT_H
#define RT_DIRECT_H

#include "rt/render/sampling.h"
#include "rt/render/surface.h"

rt_vec3 rt_radiance_direct(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

/* Direct light from every light at a Lambertian surface of albedo `albedo`,
 * plus one cosine-distributed environment ray. */
rt_vec3 rt_direct_lambert(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 albedo, rt_rng *rng);

#endif
