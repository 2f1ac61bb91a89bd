/* rt/render/integrator.h - radiance along a camera ray, by the scene's
 * integrator.
 *
 *   rt_vec3 L = rt_radiance(&ctx, &ray, &rng);
 *
 * direct   emission + direct light with a Lambertian BRDF (direct.c,
 *          rt/render/direct.h).
 * whitted  Phong, mirrors, refraction with exact Fresnel through nested
 *          media, shadows through glass, diffuse bounces (whitted.c,
 *          rt/render/whitted.h; the model is specified in docs/shading.md).
 * path     physically based path tracing of glTF materials with
 *          next-event estimation and MIS (pathtrace.c, rt/render/pathtrace.h,
 *          docs/path-tracer.md).
 */
#ifndef RT_INTEGRATOR_H
#define RT_INTEGRATOR_H

#include "rt/render/sampling.h"
#include "rt/render/surface.h"

rt_vec3 rt_radiance(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

#endif
