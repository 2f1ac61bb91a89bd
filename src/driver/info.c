/* info.c - `rt --info FILE...` (info.h): what each file contains (the
 * counts as loaded, bounds, images, cameras, lights) and how `rt FILE`
 * would render it (camera, resolution, samples, integrator, output), as
 * `key: value` lines, one block a file. */
#include "info.h"

#include <stdio.h>

#include "rt/io/load.h"
#include "rt/job/frame.h"
#include "rt/render/integrator.h"
#include "rt/scene/instance.h"
#include "rt/scene/scene.h"

#include "input.h"

static void print_vec(const char *key, rt_vec3 v) { printf("%s: %.9g %.9g %.9g\n", key, v.x, v.y, v.z); }

/* --info for one input: one `key: value` line per figure, for people and
 * scripts. The counts are the file's own (loaded as it is); the settings
 * and camera are what `rt FILE` would render with, before any flag. */
static int print_info(const char *path, const args *a)
{
    const memory_budget *budget = &a->budget;
    rt_scene s;
    rt_scene_init(&s);
    rt_settings loaded; /* the file's own settings */
    rt_settings_default(&loaded);
    rt_error err = {0};
    rt_load_info info;
    rt_load_options lo = {
        .use_time = a->posed, .time = a->frame_time, .animation = a->animation, .flatten_instances = a->flatten};
    rt_result r = input_load(&s, &loaded, path, &lo, &info, &err);
    if (r != RT_OK) {
        memory_budget_report(&err, budget);
        rt_scene_free(&s);
        return 2;
    }
    rt_box b = rt_scene_bounds(&s);
    printf("file: %s\n", input_name(path));
    printf("format: %s\n", rt_load_kind_name(info.kind));
    printf("triangles: %zu\n", s.triangles.count);
    printf("vertices: %zu\n", s.vertices.count);
    printf("spheres: %zu\n", s.spheres.count);
    printf("quads: %zu\n", s.quads.count);
    /* instancing: triangles above are the unique ones (an object's once) */
    printf("instances: %zu\n", s.instance_count);
    printf("instanced_triangles: %zu\n", rt_scene_instanced_triangles(&s));
    if (rt_box_is_empty(b))
        printf("bounds: none\n");
    else
        printf("bounds: %.9g %.9g %.9g %.9g %.9g %.9g\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    if (info.kind != RT_LOAD_SCENE) {
        printf("meshes: %zu\n", info.meshes);
        printf("primitives: %zu\n", info.primitives);
    }
    if (info.kind == RT_LOAD_GLTF)
        printf("nodes: %zu\n", info.nodes);
    printf("materials: %zu\n", s.material_count);
    printf("textures: %zu\n", s.texture_count);
    printf("images: %zu\n", s.image_count);
    for (size_t i = 0; i < s.image_count; i++)
        printf("image.%zu: %dx%d %s\n", i, s.images[i].width, s.images[i].height, s.images[i].name);
    printf("cameras: %zu\n", s.camera_count);
    printf("lights: %zu\n", s.light_count);

    /* how it would render */
    rt_settings set = loaded;
    if (info.kind != RT_LOAD_SCENE)
        rt_load_model_settings(&set, &s.environment);
    const rt_camera *cam = NULL;
    if (s.camera_set) {
        printf("camera: scene file\n");
        cam = &s.camera;
    } else if (info.kind == RT_LOAD_GLTF && s.camera_count) {
        printf("camera: gltf camera 0\n");
        cam = &s.cameras[0];
        if (cam->aspect_ratio > 0.0f) /* the width follows the camera's aspect ratio */
            set.width = rt_job_width_for_aspect(set.height, cam->aspect_ratio);
    } else {
        printf("camera: auto (framed to the bounds)\n");
    }
    if (cam) {
        print_vec("camera.position", cam->position);
        print_vec("camera.look_at", cam->look_at);
        print_vec("camera.up", cam->up);
        printf("camera.fov: %.9g\n", cam->vfov_deg);
    }
    char output[1024];
    input_default_output(&set, path, output, sizeof output);
    printf("resolution: %dx%d\n", set.width, set.height);
    printf("samples: %d\n", set.samples);
    printf("integrator: %s\n", rt_integrator_name(set.integrator));
    printf("output: %s\n", output);
    printf("load_ms: %.3f\n", info.load_ms);
    rt_scene_free(&s);
    return 0;
}

/* --info FILE [FILE...]: one block each, a blank line between; exit 2 when
 * any of them failed to load (the others are still reported). */
int info_print(const args *a)
{
    int status = print_info(a->info_path, a);
    const char *rest[ARGS_MAX_INPUTS + 1];
    size_t n = 0;
    if (a->input)
        rest[n++] = a->input;
    for (size_t i = 0; i < a->more_input_count; i++)
        rest[n++] = a->more_inputs[i];
    for (size_t i = 0; i < n; i++) {
        printf("\n");
        fflush(stdout);
        if (print_info(rest[i], a) != 0)
            status = 2;
    }
    return status;
}

