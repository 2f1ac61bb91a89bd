/* integrator.c - dispatch to the scene's integrator. */
#include "rt/render/integrator.h"

#include "rt/render/direct.h"
#include "rt/render/pathtrace.h"
#include "rt/render/whitted.h"

rt_vec3 rt_radiance(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    switch (ctx->scene->settings.integrator) {
    case RT_INTEGRATOR_WHITTED:
        return rt_radiance_whitted(ctx, ray, rng);
    case RT_INTEGRATOR_PATH:
        return rt_radiance_path(ctx, ray, rng);
    case RT_INTEGRATOR_DIRECT:
    default:
        return rt_radiance_direct(ctx, ray, rng);
    }
}
