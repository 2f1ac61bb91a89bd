/* rt/render/volpath.h - the volumetric path tracer: the `path` integrator
 * for scenes with participating media (a `scene_medium`, a material's
 * `interior`/`exterior` medium, a `bsdf null` boundary; rt_scene_has_media).
 * rt_render dispatches to it in place of the surface path tracer and its
 * wavefront for such scenes; scenes without media never reach it.
 *
 *   rt_vec3 L = rt_radiance_volpath(&ctx, &ray, &rng);   // same contract as rt_radiance_path
 *   if (rt_volpath_aov_event(&ctx, &ray, &rng, &albedo, &p)) ...  // the AOVs' first event
 *
 * docs/media.md has the estimator (pbrt-v4's VolPathIntegrator: the
 * null-scattering path integral of Miller, Georgiev and Jarosz 2019 with a
 * hero channel and spectral MIS in RGB), what it reuses of the surface path
 * tracer and what it leaves out.
 */
#ifndef RT_VOLPATH_H
#define RT_VOLPATH_H

#include "rt/render/sampling.h"
#include "rt/render/surface.h"

rt_vec3 rt_radiance_volpath(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

/* For the denoiser's AOVs (rt/render/aov.h): whether the camera ray's
 * first event is a collision in a medium (delta tracking in a channel the
 * rng picks, through null boundaries, from the medium the camera is in)
 * before any surface; then *albedo is that medium's single-scattering
 * albedo sigma_s / sigma_t and *p where it happened. */
bool rt_volpath_aov_event(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng, rt_vec3 *albedo, rt_vec3 *p);

#endif
