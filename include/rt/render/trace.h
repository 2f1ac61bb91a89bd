/* rt/render/trace.h - what a tracing thread reads: the render state, which
 * rt_render_state_prepare (rt/render/render_state.h) derives once from the
 * scene and its kd-tree before the workers start and which every thread
 * then shares read-only, and each thread's tracing context, which points at
 * it and counts the rays it traces.
 *
 *   ... in each thread, for a prepared state rs:
 *       rt_trace_ctx ctx;
 *       rt_trace_ctx_init(&ctx, &rs);
 *       ctx.ray_count = &my_counter;               // optional
 *       if (rt_trace(&ctx, &ray, &hit)) ...        // closest hit, counted
 *
 * The state's type lives here, below everything that reads it (the
 * surface record, light sampling, the integrators); preparing it, which
 * calls those, sits above them.
 */
#ifndef RT_TRACE_H
#define RT_TRACE_H

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/scene/scene.h"

typedef struct rt_render_state {
    const rt_scene *scene;
    const rt_kdtree *tree;     /* may be NULL for code that only builds surface records (tests) */
    float scale;               /* largest absolute scene coordinate: sizes ray offsets */
    bool shadows_need_shading; /* some material is transmissive or alpha-tested */
    rt_vec3 ambient;           /* whitted ambient radiance (settings.ambient_light or the environment's mean) */
    /* RT_PREPARE_LIGHT_TABLE: the scene's emitter table; NULL otherwise, and
     * then the path tracer finds emissive primitives by BSDF sampling only */
    struct rt_light_table *light_table;
    /* per material (scene->materials order), RT_MATERIAL_* bits: what the
     * surface record and the path tracer's vertex need of it, derived once
     * (rt_material_needs, rt/render/material_eval.h) instead of at every hit */
    uint8_t *material_needs;
} rt_render_state;

/* The bits of rt_render_state.material_needs. */
enum rt_material_need {
    RT_MATERIAL_TEXTURED = 1, /* some texture slot is set: surface records need its UVs */
    RT_MATERIAL_FRAME = 2,    /* it reads the tangent frame (rt_surface_material_reads_frame, rt/render/material_eval.h) */
    RT_MATERIAL_EMITS = 4,    /* some emission channel is > 0: rt_surface_emission may be nonzero */
};

/* One tracing thread's view: the shared state, and its own ray counter. */
typedef struct rt_trace_ctx {
    const rt_render_state *state;
    uint64_t *ray_count; /* rays this thread traced; NULL = not counted */
    uint64_t *hit_count; /* of them, rays rt_trace found a hit for (a surface to shade); NULL = not counted */
} rt_trace_ctx;

void rt_trace_ctx_init(rt_trace_ctx *ctx, const rt_render_state *state);

/* Closest hit, counted. */
bool rt_trace(const rt_trace_ctx *ctx, const rt_ray *ray, rt_hit *hit);

#endif
