/* rt/render/emitter_sample.h - next-event estimation towards the light
 * table's emissive primitives (triangles, spheres and quads that are not
 * `light area`): one picked in proportion to its power and a point on it,
 * seen from any point (a surface or a point in a medium), and the density
 * of that sampling for multiple importance sampling when a BSDF or phase
 * sample hits the primitive instead.
 *
 *   rt_emitter_sample es;
 *   if (rt_path_samples_emitters(&ctx) && rt_emitter_sample_at(&ctx, p, ul, u, &es)) {
 *       ... es.Le arrives along es.wi from es.dist away, drawn with
 *       ... solid-angle density es.pdf (visibility not tested)
 *   }
 *   float pdf = rt_emitter_pdf(&ctx, hit_prim, prev_p, dir, d2, hit_ng);   // 0: not in the table
 *
 * Triangles that a point sees large are sampled uniformly in solid angle
 * (rt_tri_solid, Arvo 1995), everything else uniformly by area (pdf
 * d^2 / (A cos theta_l)). The light table (rt/render/light.h) must exist
 * and hold at least one emitter for rt_emitter_sample_at.
 */
#ifndef RT_EMITTER_SAMPLE_H
#define RT_EMITTER_SAMPLE_H

#include "rt/render/light.h"

typedef struct rt_emitter_sample {
    rt_vec3 wi;   /* unit direction from the point to the sampled point */
    float dist;   /* distance to it */
    rt_vec3 Le;   /* radiance it emits towards the point */
    float pdf;    /* solid-angle density of the sample (the pick included) */
    uint32_t prim;
} rt_emitter_sample;

/* An emitter picked by ul (by power) and a point on it by u, seen from p;
 * false when it sends nothing towards p (its back, a degenerate sample). */
bool rt_emitter_sample_at(const rt_trace_ctx *ctx, rt_vec3 p, float ul, rt_vec2 u, rt_emitter_sample *es);

/* The solid-angle density with which rt_emitter_sample_at from `from`
 * draws unit direction dir onto primitive prim, met at squared distance
 * d2 with geometric normal ng; 0 when prim is not in the light table. */
float rt_emitter_pdf(const rt_trace_ctx *ctx, uint32_t prim, rt_vec3 from, rt_vec3 dir, float d2, rt_vec3 ng);

#endif
