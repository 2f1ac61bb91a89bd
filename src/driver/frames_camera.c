/* frames_camera.c - the automatic camera of a --frames sequence
 * (frames_camera.h): each frame of the range loaded posed at its time (the
 * images decoded once, shared between the loads as motion slices share
 * them), its settings flags applied for the image's aspect ratio, and its
 * points gathered into one rt_frame_extent (rt/scene/scene.h). */
#include "frames_camera.h"

#include <string.h>

#include "frames.h"
#include "input.h"
#include "rt/io/load.h"
#include "rt/render/settings.h"
#include "rt/scene/validate.h"

/* Frame f's scene and settings, loaded and checked as prepare.c loads them. */
static rt_result load_frame(const args *a, int f, rt_scene *s, rt_settings *set, rt_load_info *info, rt_error *err)
{
    rt_load_options lo = {.for_render = true,
                          .use_time = true,
                          .time = (float)frames_time(f, a->fps),
                          .animation = a->animation,
                          .animation_name = a->animation_name,
                          .variant = a->variant};
    rt_settings_default(set);
    rt_result r = input_load(s, set, a->input, &lo, info, err);
    if (r == RT_OK && (r = rt_scene_validate(s, err)) != RT_OK) {
        rt_error inner = *err;
        return rt_fail(err, inner.code, "%s: %s", input_name(a->input), inner.message);
    }
    return r == RT_OK ? args_apply_settings(a, s, set, err) : r;
}

rt_result frames_camera_extent(const args *a, rt_frame_extent *e, bool *used, rt_error *err)
{
    *used = false;
    if (a->camera >= 0 || (a->input && strcmp(a->input, "-") == 0)) /* a chosen camera; stdin is read once */
        return RT_OK;
    rt_scene first;
    rt_scene_init(&first);
    rt_settings set;
    rt_load_info info;
    rt_result r = load_frame(a, a->frame_begin, &first, &set, &info, err);
    if (r != RT_OK || !info.animated || (first.camera_set && !a->camera_auto)) {
        rt_scene_free(&first);
        return r;
    }
    rt_frame_extent_init(e, (float)set.width / (float)(set.height > 0 ? set.height : 1));
    rt_frame_extent_add(e, &first);
    for (int f = a->frame_begin + 1; f < a->frame_end && r == RT_OK; f++) {
        rt_scene s;
        rt_scene_init(&s);
        if (!rt_scene_share_images(&s, &first))
            r = rt_fail(err, RT_ERR_NOMEM, "out of memory for the images of frame %d", f);
        else if ((r = load_frame(a, f, &s, &set, &info, err)) == RT_OK)
            rt_frame_extent_add(e, &s);
        rt_scene_free(&s);
    }
    rt_scene_free(&first);
    *used = r == RT_OK;
    return r;
}
