/* render_state.c - the render state every tracing thread reads, derived
 * once from the scene before the workers start: the scale that sizes ray
 * offsets (Waechter and Binder, Ray Tracing Gems ch. 6, via
 * rt_offset_ray_origin), whether shadow rays must look at the surfaces
 * they cross, the whitted integrator's ambient radiance (docs/shading.md),
 * the light table when the integrator samples emitters, and what each
 * material needs of a surface record (rt_material_needs). Readers see it
 * through rt/render/trace.h.
 */
#include "rt/render/render_state.h"

#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/render/environment.h"
#include "rt/render/light.h"
#include "rt/render/material_eval.h"

/* The whitted integrator's ambient radiance: the scene's ambient_light when
 * given, else the mean radiance of the environment over the sphere. */
static rt_vec3 ambient_radiance(const rt_scene *scene)
{
    const rt_settings *st = &scene->settings;
    return st->ambient_light_set ? st->ambient_light : rt_environment_mean(scene);
}

rt_result rt_render_state_prepare(rt_render_state *rs, const rt_scene *scene, const rt_kdtree *tree,
                                  unsigned prepare, rt_error *err)
{
    memset(rs, 0, sizeof *rs);
    rs->scene = scene;
    rs->tree = tree;
    rt_box b = tree ? tree->bounds : rt_scene_bounds(scene);
    float scale = 0.0f;
    if (!rt_box_is_empty(b)) {
        scale = fmaxf(rt_max3(rt_vmax(rt_v3(fabsf(b.lo.x), fabsf(b.lo.y), fabsf(b.lo.z)),
                                      rt_v3(fabsf(b.hi.x), fabsf(b.hi.y), fabsf(b.hi.z)))), 0.0f);
    }
    rs->scale = (isfinite(scale) && scale > 1e-30f) ? scale : 1.0f;
    rs->material_needs = rt_alloc(scene->material_count + 1, 1);
    if (!rs->material_needs)
        return rt_fail(err, RT_ERR_NOMEM, "out of memory preparing the render");
    for (size_t i = 0; i < scene->material_count; i++) {
        const rt_material *m = &scene->materials[i];
        if (m->transmission > 0.0f || m->alpha_mode != RT_ALPHA_OPAQUE)
            rs->shadows_need_shading = true;
        rs->material_needs[i] = rt_material_needs(m);
    }
    rs->ambient = ambient_radiance(scene);
    if (prepare & RT_PREPARE_LIGHT_TABLE) {
        rs->light_table = rt_alloc(1, sizeof *rs->light_table);
        rt_result r = rs->light_table ? rt_light_table_build(rs->light_table, scene, err)
                                      : rt_fail(err, RT_ERR_NOMEM, "out of memory preparing the render");
        if (r != RT_OK) { /* one way out, which frees what was taken (material_needs leaked here before) */
            free(rs->light_table);
            rs->light_table = NULL;
            free(rs->material_needs);
            rs->material_needs = NULL;
            return r;
        }
    }
    return RT_OK;
}

void rt_render_state_free(rt_render_state *rs)
{
    if (!rs)
        return;
    rt_light_table_free(rs->light_table);
    free(rs->light_table);
    free(rs->material_needs);
    memset(rs, 0, sizeof *rs);
}
