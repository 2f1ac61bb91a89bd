/* frame.c - the view a job renders (rt/job/frame.h): the camera chosen
 * among the loaded models' (or the file's, or none: framed from the scene's
 * bounds, rt_scene_frame_camera), fitted to the image's aspect ratio, its
 * parts replaced as the options say, and the render's limits checked. The
 * messages name the command-line flags the options come from. */
#include "rt/job/frame.h"

#include <stdio.h>
#include <string.h>

#include "rt/render/camera.h"
#include "rt/render/limits.h"
#include "rt/render/settings.h"

int rt_job_width_for_aspect(int height, float aspect_ratio)
{
    double w = (double)height * aspect_ratio + 0.5;
    return w < 1.0 ? 1 : (w > (double)RT_MAX_IMAGE_SIDE ? RT_MAX_IMAGE_SIDE : (int)w);
}

/* Look-from, look-at, up and field of view over the file's or the framed
 * camera; a camera they leave degenerate is an error naming them. */
static rt_result apply_pose(rt_scene *scene, const rt_settings *set, const rt_job_options *a, rt_error *err)
{
    if (!a->has_look_from && !a->has_look_at && !a->has_up && !a->has_fov)
        return RT_OK;
    rt_camera *c = &scene->camera;
    char given[512] = "", v[128];
    if (a->has_look_from) {
        snprintf(v, sizeof v, " --look-from %g,%g,%g", a->look_from.x, a->look_from.y, a->look_from.z);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_look_at) {
        snprintf(v, sizeof v, " --look-at %g,%g,%g", a->look_at.x, a->look_at.y, a->look_at.z);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_up) {
        snprintf(v, sizeof v, " --up %g,%g,%g", a->up.x, a->up.y, a->up.z);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_fov) {
        snprintf(v, sizeof v, " --fov %g", a->fov);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_look_from)
        c->position = a->look_from;
    if (a->has_look_at)
        c->look_at = a->look_at;
    if (a->has_up)
        c->up = a->up;
    if (a->has_fov)
        c->vfov_deg = a->fov;
    if (a->has_look_from || a->has_look_at)
        c->focus_distance = 0.0f; /* the distance to look_at, which moved */
    rt_camera_frame cf;
    if (!rt_camera_frame_init(&cf, c, set->width, set->height))
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: the camera is degenerate (the position equals the point looked at, or up is parallel "
                       "to the view direction)",
                       given + 1);
    scene->camera_set = true;
    return RT_OK;
}

rt_result rt_job_frame(rt_scene *scene, rt_settings *set, const rt_job_options *o, const char *name, rt_error *err)
{
    if (o->use_camera) {
        if (o->camera < 0 || (size_t)o->camera >= scene->camera_count)
            return rt_fail(err, RT_ERR_INVALID, "--camera %d: the loaded models have %zu camera%s", o->camera,
                           scene->camera_count, scene->camera_count == 1 ? "" : "s");
        scene->camera = scene->cameras[o->camera];
        scene->camera_set = true;
    }
    if (o->camera_auto) { /* ignore the file's camera: frame the scene below */
        scene->camera_set = false;
        scene->camera.aspect_ratio = 0.0f;
    }
    /* a camera made for another aspect ratio: keep the height, fit the width */
    if (o->fit_aspect && scene->camera_set && scene->camera.aspect_ratio > 0.0f)
        set->width = rt_job_width_for_aspect(set->height, scene->camera.aspect_ratio);
    bool camera_from_input = scene->camera_set;
    if (!scene->camera_set && o->frame_extent) /* one camera for every frame of a sequence */
        rt_scene_frame_camera_extent(scene, o->frame_extent);
    else if (!scene->camera_set)
        rt_scene_frame_camera(scene, (float)set->width / (float)(set->height > 0 ? set->height : 1));
    rt_result r = apply_pose(scene, set, o, err);
    if (r != RT_OK)
        return r;
    return rt_render_check_limits(scene, set, name, camera_from_input, err);
}
