/* environment.c - radiance from the environment: a latitude-longitude
 * image looked up through the scene's texture table, or the constant
 * background, and its mean over the sphere (the whitted integrator's
 * default ambient light, docs/shading.md).
 *
 * The mapping is the common equirectangular one (as in pbrt-v3's
 * InfiniteAreaLight, with y up); rt/render/environment.h states it.
 */
#include "rt/render/environment.h"

#include "rt/scene/texture.h"

rt_vec3 rt_environment(const rt_scene *s, rt_vec3 d)
{
    const rt_scene_environment *st = &s->environment;
    if (st->environment_texture != RT_NONE) {
        rt_vec4 c = rt_texture_sample(s, st->environment_texture, rt_latlong_from_dir(rt_normalize(d)), false);
        return rt_scale(rt_v3(c.x, c.y, c.z), st->environment_strength);
    }
    return rt_scale(st->background, st->environment_strength);
}

rt_vec3 rt_environment_mean(const rt_scene *s)
{
    const rt_scene_environment *st = &s->environment;
    if (st->environment_texture == RT_NONE)
        return rt_scale(st->background, st->environment_strength);
    enum { NU = 64, NV = 32 };
    double sum[3] = {0, 0, 0}, wsum = 0;
    for (int j = 0; j < NV; j++) {
        float v = ((float)j + 0.5f) / (float)NV;
        float w = sinf(v * RT_PI);
        for (int i = 0; i < NU; i++) {
            float u = ((float)i + 0.5f) / (float)NU;
            rt_vec4 c = rt_texture_sample(s, st->environment_texture, rt_v2(u, v), false);
            if (!(isfinite(c.x) && isfinite(c.y) && isfinite(c.z)))
                continue;
            sum[0] += (double)(w * c.x);
            sum[1] += (double)(w * c.y);
            sum[2] += (double)(w * c.z);
            wsum += (double)w;
        }
    }
    if (!(wsum > 0.0))
        return rt_v3s(0);
    rt_vec3 mean = rt_v3((float)(sum[0] / wsum), (float)(sum[1] / wsum), (float)(sum[2] / wsum));
    return rt_scale(mean, st->environment_strength);
}
