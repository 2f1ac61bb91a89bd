/* rt/render/render_state.h - preparing the render state (its type and the
 * tracing context are in rt/render/trace.h): derived once from the scene
 * and its kd-tree before the workers start, then shared read-only by
 * every thread. Preparing calls the light table's build and the material
 * evaluation, so it sits above them; what reads the state sits below.
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

#include "rt/base/error.h"
#include "rt/render/trace.h"

/* What an integrator may need prepared beyond the constants every one gets. */
enum rt_prepare {
    RT_PREPARE_LIGHT_TABLE = 1, /* the table of emitters to sample by power (rt/render/light.h) */
};

/* Derives the state from scene and tree (which it points to, not copies);
 * `prepare` (RT_PREPARE_* bits) adds what an integrator needs. Fails only
 * when out of memory. */
rt_result rt_render_state_prepare(rt_render_state *rs, const rt_scene *scene, const rt_kdtree *tree,
                                  unsigned prepare, rt_error *err);
void rt_render_state_free(rt_render_state *rs);

#endif
