/* rt/render/render_state.h - what the integrators read while rendering:
 * the render state, prepared once from the scene and its kd-tree before
 * the workers start and then shared read-only by every thread, and each
 * thread's tracing context, which points at it.
 *
 *   rt_render_state rs;
 *   if (rt_render_state_prepare(&rs, &scene, &tree, RT_PREPARE_LIGHT_TABLE, &err) != RT_OK) ...
 *   ... in each thread:
 *       rt_trace_ctx ctx;
 *       rt_trace_ctx_init(&ctx, &rs);
 *       ctx.ray_count = &my_counter;               // optional
 *       if (rt_trace(&ctx, &ray, &hit)) ...        // closest hit, counted
 *   rt_render_state_free(&rs);                     // once the threads are done
 *
 * rt_render prepares what the scene's integrator asks for in its line of
 * the integrator table (rt/render/integrator.h). The scene must have passed
 * rt_scene_validate (rt/scene/validate.h); the tree may be NULL for code
 * that only builds surface records (tests).
 */
#ifndef RT_RENDER_STATE_H
#define RT_RENDER_STATE_H

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* What an integrator may need prepared beyond the constants every one gets. */
enum rt_prepare {
    RT_PREPARE_LIGHT_TABLE = 1, /* the table of emitters to sample by power (rt/render/light.h) */
};

typedef struct rt_render_state {
    const rt_scene *scene;
    const rt_kdtree *tree;
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

/* Derives the state from scene and tree (which it points to, not copies);
 * `prepare` (RT_PREPARE_* bits) adds what an integrator needs. Fails only
 * when out of memory. */
rt_result rt_render_state_prepare(rt_render_state *rs, const rt_scene *scene, const rt_kdtree *tree,
                                  unsigned prepare, rt_error *err);
void rt_render_state_free(rt_render_state *rs);

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
