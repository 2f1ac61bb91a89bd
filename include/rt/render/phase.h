/* rt/render/phase.h - the Henyey-Greenstein phase function: how light
 * scattering in a participating medium spreads around its direction of
 * travel (Henyey and Greenstein 1941, "Diffuse radiation in the galaxy",
 * ApJ 93).
 *
 *   // a path travelling along d scatters at a point of a medium with
 *   // anisotropy g (-1 < g < 1: back, 0: isotropic, forward):
 *   float pdf;
 *   rt_vec3 d_out = rt_hg_sample(g, d, u1, u2, &pdf);   // pdf = rt_hg_pdf(g, dot(d, d_out))
 *   // value = pdf: HG is sampled exactly, so the throughput's weight
 *   // value / pdf is 1 (times the medium's albedo)
 *
 * Directions are directions of travel: cos_theta = dot(d_in, d_out), so
 * g > 0 keeps light going the way it went (fog, clouds: 0.7-0.9) and the
 * mean cosine of the scattered direction is g. The value is per steradian
 * and integrates to 1 over the sphere; it is symmetric in d_in and d_out,
 * so light sampling at a scattering event uses the same function.
 */
#ifndef RT_PHASE_H
#define RT_PHASE_H

#include "rt/base/vec.h"

/* |g| is kept to RT_HG_G_MAX so that the lobe stays a finite function. */
#define RT_HG_G_MAX 0.999f

/* The phase function's value (= its pdf) for cos_theta = dot(d_in, d_out). */
float rt_hg_pdf(float g, float cos_theta);

/* The cosine of a scattering angle drawn with density rt_hg_pdf (times
 * 2 pi, the azimuth being uniform), from u in [0,1). */
float rt_hg_sample_cos(float g, float u);

/* A scattered direction of travel for a unit d_in, from (u1, u2) in
 * [0,1)^2; *pdf receives rt_hg_pdf(g, dot(d_in, result)). */
rt_vec3 rt_hg_sample(float g, rt_vec3 d_in, float u1, float u2, float *pdf);

#endif
