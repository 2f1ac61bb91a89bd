/* prepare.c - the `rt` command's flags applied to a scene (prepare.h): the
 * input loaded (input.c), validated, the setting flags applied (args.c),
 * the view framed by the job stage from the camera flags (rt_job_frame:
 * --camera, a glTF camera fitted to the image, framing, --look-from,
 * --look-at, --up, --fov, the limits), the output path chosen and checked,
 * and the -v lines about the scene. */
#include "prepare.h"

#include <stdio.h>
#include <string.h>

#include "input.h"
#include "rt/base/log.h"
#include "rt/image/tonemap.h"
#include "rt/io/image_write.h"
#include "rt/io/load.h"
#include "rt/job/frame.h"
#include "rt/job/output.h"
#include "rt/job/part.h"
#include "rt/render/integrator.h"
#include "rt/scene/instance.h"
#include "rt/scene/validate.h"

/* The loaded scene as the flags want it: setting flags applied, the view
 * framed (rt_job_frame), the output path chosen and checked. */
rt_result prepare_scene(rt_scene *scene, rt_settings *set, const args *a, char *output, size_t size, bool *animated,
                        rt_error *err)
{
    rt_load_info info;
    rt_load_options lo = {.for_render = true,
                          .use_time = a->posed,
                          .time = a->frame_time,
                          .animation = a->animation,
                          .animation_name = a->animation_name,
                          .variant = a->variant,
                          .flatten_instances = a->flatten};
    rt_result r;
    /* -o is checked before the load, which may take long, and so is a
     * model's default output (models have no `output` line); a scene's own
     * `output` can only be checked after the load */
    if (a->output && (r = rt_output_check(a->output, err)) != RT_OK)
        return r;
    if (!a->output && !args_sets(a, "output") && a->input && strcmp(a->input, "-") != 0 &&
        !rt_load_is_scene_name(a->input)) {
        input_default_output(NULL, a->input, output, size);
        if ((r = rt_output_check(output, err)) != RT_OK)
            return r;
    }
    if ((r = input_load(scene, set, a->input, &lo, &info, err)) != RT_OK)
        return r;
    *animated = info.animated;
    if ((r = rt_scene_validate(scene, err)) != RT_OK) { /* from here on the tables are trusted */
        rt_error inner = *err;
        return rt_fail(err, inner.code, "%s: %s", input_name(a->input), inner.message);
    }
    if (rt_scene_prim_count(scene) == 0)
        rt_warn("%s: nothing to render (no spheres, quads, triangles or meshes); the image will show only the "
                "background",
                input_name(a->input));
    if ((r = args_apply_settings(a, scene, set, err)) != RT_OK)
        return r;
    rt_job_options jo;
    args_job_options(a, &jo);
    jo.fit_aspect = !args_sets(a, "resolution") && a->input && info.kind == RT_LOAD_GLTF;
    jo.frame_extent = a->frame_extent;
    if ((r = rt_job_frame(scene, set, &jo, input_name(a->input), err)) != RT_OK)
        return r;

    if (a->output)
        snprintf(output, size, "%s", a->output);
    else
        input_default_output(set, a->input, output, size);
    /* every file the render will write (AOV files, NAME.partial.EXT, a part's sidecar) before it starts */
    if ((r = rt_output_check(output, err)) != RT_OK ||
        (r = args_output_is_part(a) ? rt_part_check_paths(output, err) : rt_job_output_check_paths(&jo, output, err)) !=
            RT_OK ||
        (r = rt_output_check_size(output, set->width, set->height, err)) != RT_OK ||
        (a->stop_part && (r = rt_part_check_paths(a->stop_part, err)) != RT_OK)) /* a stopped frame's part */
        return r;
    /* rt convert and rt merge refuse these; a render keeps them for the window */
    rt_image_format fmt = RT_FORMAT_PNG;
    rt_output_format(output, &fmt, NULL);
    if (fmt != RT_FORMAT_PNG && (a->exposure_ev != 0.0f || a->tonemap != RT_TONEMAP_CLAMP))
        rt_warn("%s holds the linear radiance: --exposure and --tonemap shape 8-bit output (.png)%s", output,
                a->window ? " and the window" : " only");
    if (fmt != RT_FORMAT_EXR && a->half)
        rt_warn("%s: --half is for .exr output; ignored", output);
    if (!a->input)
        rt_note("no input given; rendering the built-in Cornell box to %s (rt --help for usage)", output);

    rt_info("scene: %s (loaded in %.1f ms)", input_name(a->input), info.load_ms);
    rt_info("  triangles %zu, spheres %zu, quads %zu, vertices %zu", scene->triangles.count, scene->spheres.count,
            scene->quads.count, scene->vertices.count);
    if (scene->instance_count)
        rt_info("  instances %zu of %zu objects, placing %zu triangles", scene->instance_count, scene->object_count,
                rt_scene_instanced_triangles(scene));
    rt_info("  materials %zu, textures %zu, images %zu, lights %zu", scene->material_count, scene->texture_count,
            scene->image_count, scene->light_count);
    rt_info("  %dx%d, %d samples per pixel, integrator %s", set->width, set->height, set->samples,
            rt_integrator_name(set->integrator));
    return RT_OK;
}

/* prepare_scene() for the same input at another time (a motion slice): its
 * warnings were the first load's, so they are not said again (-v keeps
 * its lines). */
rt_result prepare_scene_again(rt_scene *scene, rt_settings *set, const args *a, char *output, size_t size,
                              bool *animated, rt_error *err)
{
    rt_log_level level = rt_log_get_level();
    if (level == RT_LOG_NORMAL)
        rt_log_set_level(RT_LOG_QUIET);
    rt_result r = prepare_scene(scene, set, a, output, size, animated, err);
    rt_log_set_level(level);
    return r;
}
