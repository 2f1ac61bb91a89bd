/* limits.c - the caps a scene must fit before it is rendered
 * (rt/render/limits.h): the kd-tree's primitive payload, the settings
 * table's ranges, the size of whitted's diffuse-gather tree, a usable
 * camera. Plain checks, no source beyond rt's own limits. */
#include "rt/render/limits.h"

#include "rt/accel/kdtree.h"
#include "rt/base/log.h"
#include "rt/render/camera.h"
#include "rt/render/integrator.h"
#include "rt/render/settings.h"

/* The kd-tree's primitive ids are the 30 payload bits of its references
 * (RT_KD_PAYLOAD), one value kept free. */
#define MAX_PRIMITIVES ((size_t)RT_KD_PAYLOAD - 1)

rt_result rt_render_check_limits(const rt_scene *s, const char *name, bool camera_required, rt_error *err)
{
    size_t prims = rt_scene_prim_count(s);
    if (prims > MAX_PRIMITIVES)
        return rt_fail(err, RT_ERR_LIMIT, "%s: %zu primitives (triangles %zu, spheres %zu, quads %zu), over the limit of %zu",
                       name, prims, s->triangles.count, s->spheres.count, s->quads.count, MAX_PRIMITIVES);
    const rt_settings *set = &s->settings;
    rt_setting_problem pb;
    if (rt_settings_check(set, &pb) != RT_OK)
        return rt_fail(err, RT_ERR_LIMIT, "%s: %s", name, pb.message);
    const rt_integrator_info *in = rt_integrator_info_of(set->integrator);
    if (in && in->diffuse_tree && set->diffuse_bounces > 0 && set->diffuse_rays > 1) {
        double rays = 1.0;
        for (int i = 0; i < set->diffuse_bounces && rays <= RT_MAX_DIFFUSE_TREE; i++)
            rays *= (double)set->diffuse_rays;
        if (rays > RT_MAX_DIFFUSE_TREE)
            return rt_fail(err, RT_ERR_LIMIT,
                           "%s: diffuse_rays %d with diffuse_bounces %d would trace over %.0f rays per camera sample "
                           "(diffuse_rays ^ diffuse_bounces); lower one of them",
                           name, set->diffuse_rays, set->diffuse_bounces, RT_MAX_DIFFUSE_TREE);
    }
    rt_camera_frame cf;
    if (!rt_camera_frame_init(&cf, &s->camera, set->width, set->height)) {
        if (camera_required)
            return rt_fail(err, RT_ERR_INVALID,
                           "%s: the camera is degenerate (position equal to look_at, up parallel to the view, a field of "
                           "view outside 0..180 degrees, or a value that is not finite)",
                           name);
        rt_warn("%s: could not frame the model automatically (its bounds are empty or not finite); looking down -z",
                name);
    }
    return RT_OK;
}
