/* trace.c - a tracing thread's context and its counted closest-hit query
 * (see rt/render/trace.h): the kd-tree's traversal (rt/accel/kdtree.h),
 * counting the rays each thread traces and the hits it finds.
 */
#include "rt/render/trace.h"

void rt_trace_ctx_init(rt_trace_ctx *ctx, const rt_render_state *state)
{
    ctx->state = state;
    ctx->ray_count = NULL;
    ctx->hit_count = NULL;
}

bool rt_trace(const rt_trace_ctx *ctx, const rt_ray *ray, rt_hit *hit)
{
    if (ctx->ray_count)
        (*ctx->ray_count)++;
    bool found = rt_kdtree_intersect(ctx->state->tree, ray, hit);
    if (ctx->hit_count && found)
        (*ctx->hit_count)++;
    return found;
}
