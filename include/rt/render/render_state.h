/* rt/render/render_state.h - what a tracing thread reads: the scene, its
 * kd-tree and constants derived from them, and its own ray counter.
 *
 *   rt_trace_ctx ctx;
 *   rt_trace_ctx_init(&ctx, &scene, &tree);
 *   ctx.ray_count = &my_counter;                   // optional
 *   rt_hit hit;
 *   if (rt_trace(&ctx, &ray, &hit)) ...            // closest hit, counted
 */
#ifndef RT_RENDER_STATE_H
#define RT_RENDER_STATE_H

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/scene/scene.h"

/* What a tracing thread reads: the scene, its tree, and derived constants. */
typedef struct rt_trace_ctx {
    const rt_scene *scene;
    const rt_kdtree *tree;
    float scale;              /* largest absolute scene coordinate: sizes ray offsets */
    bool shadows_need_shading; /* some material is transmissive or alpha-tested */
    rt_vec3 ambient;          /* whitted ambient radiance (settings.ambient_light or the environment's mean) */
    uint64_t *ray_count;      /* per-thread counter of rays traced */
    /* path tracer: the scene's emitter table (rt/render/light.h), built once
     * before the workers start and shared read-only; NULL (rt_trace_ctx_init's
     * value) = emissive primitives are found by BSDF sampling only */
    const struct rt_light_table *light_table;
} rt_trace_ctx;

void rt_trace_ctx_init(rt_trace_ctx *ctx, const rt_scene *scene, const rt_kdtree *tree);

/* Closest hit, counted. */
bool rt_trace(const rt_trace_ctx *ctx, const rt_ray *ray, rt_hit *hit);

#endif
