/* rt/render/pathtrace.h - the `path` integrator: unidirectional path tracing of the
 * glTF material model (rt/render/bsdf.h) with next-event estimation, multiple
 * importance sampling and Russian roulette. docs/path-tracer.md has the
 * estimator, its validation against Mitsuba 3, and the settings.
 *
 *   rt_vec3 L = rt_radiance_path(&ctx, &ray, &rng);   // via rt_radiance()
 *
 * Lights sampled at every path vertex: every rt_light (point, spot,
 * directional, area) and, when the render state holds a light table
 * (rt/render/light.h; its line in the integrator table asks for
 * RT_PREPARE_LIGHT_TABLE, so rt_render builds one), one emissive primitive
 * (triangle, quad or sphere with an emissive material) chosen by power, and
 * the environment image by its luminance:
 *
 *   rt_render_state rs;
 *   rt_render_state_prepare(&rs, &scene, &tree, RT_PREPARE_LIGHT_TABLE, &err);
 *   ... in each worker: rt_trace_ctx_init(&ctx, &rs); L = rt_radiance_path(&ctx, &ray, &rng);
 *   rt_render_state_free(&rs);                           // after the render
 *
 * Without a table (prepared without RT_PREPARE_LIGHT_TABLE) the image is
 * the same in expectation: emissive primitives are then found only by
 * BSDF-sampled rays and counted in full (noisier for small bright
 * emitters).
 */
#ifndef RT_PATHTRACE_H
#define RT_PATHTRACE_H

#include "rt/render/light.h"
#include "rt/render/sampling.h"

#define RT_PATH_HARD_LIMIT 1024 /* bounces when max_depth is 0 (unlimited): a guard, never reached in practice */

rt_vec3 rt_radiance_path(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

/* Power heuristic with exponent 2 (Veach 1997, ch. 9): a^2 / (a^2 + b^2). */
static inline float rt_mis_power(float a, float b)
{
    if (!(a > 0.0f))
        return 0.0f;
    if (isinf(a))
        return 1.0f;
    float a2 = a * a, b2 = b * b;
    float w = a2 / (a2 + b2);
    return isfinite(w) ? w : (a > b ? 1.0f : 0.0f);
}

#endif
