/* rt/render/aov.h - arbitrary output values: per-pixel images beside the
 * beauty one, for denoisers and compositing.
 *
 *   albedo    the first non-specular surface's reflectance (diffuse + specular
 *             tint), seen through perfect mirrors and glass, as OIDN wants it;
 *             with the path integrator in a scene with media, a collision in
 *             a medium before that surface gives the medium's
 *             single-scattering albedo sigma_s / sigma_t instead
 *   normal    that surface's shading normal (world space, facing the ray);
 *             zero for a collision in a medium (OIDN's "no surface")
 *   depth     distance along the camera ray to the first surface (0: none),
 *             or to the collision in a medium
 *   position  world position of the first surface (or of that collision)
 *   variance  the variance of the pixel's mean (sample variance of the
 *             luminance / samples)
 *   spp       samples that counted (NaN/Inf samples are dropped)
 * Each is the average over the pixel's samples, with random numbers of its
 * own, so the beauty image is unchanged and the AOVs are bit-identical for
 * any thread count, like the image.
 *
 *   rt_aov_buffers aov = {.albedo = calloc(w * h * 3, 4), .normal = ...};  // NULL: not wanted
 *   render options .aov = &aov;
 */
#ifndef RT_AOV_H
#define RT_AOV_H

#include "rt/render/trace.h"
#include "rt/render/sampling.h"

typedef struct rt_aov_buffers {
    float *albedo, *normal, *position; /* 3 floats a pixel, or NULL */
    float *depth, *variance, *spp;     /* 1 float a pixel, or NULL */
} rt_aov_buffers;

/* What one camera sample sees for the AOVs. */
typedef struct rt_aov_sample {
    rt_vec3 albedo, normal, position;
    float depth;
} rt_aov_sample;

/* Traces a camera ray for the AOVs: through up to 8 perfect mirrors and
 * smooth glass (roughness ~0, metallic or transmissive) to the first other
 * surface. Zero everywhere on a miss. */
void rt_aov_trace(const rt_trace_ctx *ctx, rt_ray ray, rt_rng *rng, rt_aov_sample *out);

/* The pixel's AOVs from its sums over `good` samples: the means, and the
 * variance of the mean luminance from lum_sum and lum_sq (the sums of the
 * samples' luminance and its square). The renderer after each pass and a
 * merge of parts resolve AOVs through this one function. */
void rt_aov_resolve(rt_aov_buffers *aov, size_t pixel, const rt_aov_sample *s, uint32_t good, float lum_sum,
                    double lum_sq);

#endif
