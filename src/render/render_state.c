/* render_state.c - the constants every tracing thread reads, derived once
 * from the scene: the scale that sizes ray offsets (Waechter and Binder,
 * Ray Tracing Gems ch. 6, via rt_offset_ray_origin), whether shadow rays
 * must look at the surfaces they cross, and the whitted integrator's
 * ambient radiance (docs/shading.md); and the counted closest-hit query.
 */
#include "rt/render/render_state.h"

#include <string.h>

#include "rt/render/environment.h"

/* The whitted integrator's ambient radiance: the scene's ambient_light when
 * given, else the mean radiance of the environment over the sphere. */
static rt_vec3 ambient_radiance(const rt_scene *scene)
{
    const rt_settings *st = &scene->settings;
    return st->ambient_light_set ? st->ambient_light : rt_environment_mean(scene);
}

void rt_trace_ctx_init(rt_trace_ctx *ctx, const rt_scene *scene, const rt_kdtree *tree)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->scene = scene;
    ctx->tree = tree;
    rt_box b = tree ? tree->bounds : rt_scene_bounds(scene);
    float scale = 0.0f;
    if (!rt_box_is_empty(b)) {
        scale = fmaxf(rt_max3(rt_vmax(rt_v3(fabsf(b.lo.x), fabsf(b.lo.y), fabsf(b.lo.z)),
                                      rt_v3(fabsf(b.hi.x), fabsf(b.hi.y), fabsf(b.hi.z)))), 0.0f);
    }
    ctx->scale = (isfinite(scale) && scale > 1e-30f) ? scale : 1.0f;
    for (size_t i = 0; i < scene->material_count; i++) {
        const rt_material *m = &scene->materials[i];
        if (m->transmission > 0.0f || m->alpha_mode != RT_ALPHA_OPAQUE)
            ctx->shadows_need_shading = true;
    }
    ctx->ambient = ambient_radiance(scene);
}

bool rt_trace(const rt_trace_ctx *ctx, const rt_ray *ray, rt_hit *hit)
{
    if (ctx->ray_count)
        (*ctx->ray_count)++;
    return rt_kdtree_intersect(ctx->tree, ray, hit);
}