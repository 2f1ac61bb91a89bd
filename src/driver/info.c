/* info.c - `rt --info FILE...` (info.h): what each file contains (the
 * counts as loaded, bounds, images, its cameras, animations and material
 * variants) and how `rt FILE` with the same flags would render it (camera
 * and its pose, resolution, samples, integrator, output), as `key: value`
 * lines, one block a file. The render half is the render's own
 * preparation (prepare.c) run with the flags, so every flag that changes
 * the render (-r, -s, --integrator, --set, -o, --camera, --look-from ...,
 * --variant, --frame-time) shows in it; nothing is rendered. */
#include "info.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rt/base/file.h"
#include "rt/io/gltf.h"
#include "rt/io/load.h"
#include "rt/render/integrator.h"
#include "rt/scene/instance.h"
#include "rt/scene/scene.h"

#include "input.h"
#include "memory_budget.h"
#include "prepare.h"

static void print_vec(const char *key, rt_vec3 v) { printf("%s: %.9g %.9g %.9g\n", key, v.x, v.y, v.z); }

/* The file as it is: counts, bounds, images, cameras, lights, and the
 * animations (with their frames at --fps) and variants it offers. */
static void print_contents(const char *path, const rt_scene *s, const rt_load_info *info, const rt_gltf_catalog *c,
                           double fps)
{
    rt_box b = rt_scene_bounds(s);
    printf("file: %s\n", input_name(path));
    printf("format: %s\n", rt_load_kind_name(info->kind));
    printf("triangles: %zu\n", s->triangles.count);
    printf("vertices: %zu\n", s->vertices.count);
    printf("spheres: %zu\n", s->spheres.count);
    printf("quads: %zu\n", s->quads.count);
    /* instancing: triangles above are the unique ones (an object's once) */
    printf("instances: %zu\n", s->instance_count);
    printf("instanced_triangles: %zu\n", rt_scene_instanced_triangles(s));
    if (rt_box_is_empty(b))
        printf("bounds: none\n");
    else
        printf("bounds: %.9g %.9g %.9g %.9g %.9g %.9g\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    if (info->kind != RT_LOAD_SCENE) {
        printf("meshes: %zu\n", info->meshes);
        printf("primitives: %zu\n", info->primitives);
    }
    if (info->kind == RT_LOAD_GLTF)
        printf("nodes: %zu\n", info->nodes);
    printf("materials: %zu\n", s->material_count);
    printf("textures: %zu\n", s->texture_count);
    printf("images: %zu\n", s->image_count);
    for (size_t i = 0; i < s->image_count; i++)
        printf("image.%zu: %dx%d %s\n", i, s->images[i].width, s->images[i].height, s->images[i].name);
    printf("cameras: %zu\n", s->camera_count);
    for (size_t i = 0; i < s->camera_count; i++) { /* --camera N */
        const rt_camera *k = &s->cameras[i];
        printf("camera.%zu: position %.9g %.9g %.9g look_at %.9g %.9g %.9g fov %.9g\n", i, k->position.x,
               k->position.y, k->position.z, k->look_at.x, k->look_at.y, k->look_at.z, k->vfov_deg);
    }
    printf("lights: %zu\n", s->light_count);
    printf("animations: %d\n", c->animations);
    for (int i = 0; i < c->animations && i < RT_GLTF_CATALOG_MAX; i++) { /* --animation N, --frames 0:F */
        float t = c->animation_seconds[i];
        printf("animation.%d: %s%s%s", i, c->animation_name[i][0] ? "'" : "(unnamed)",
               c->animation_name[i], c->animation_name[i][0] ? "'" : "");
        if (t < 0.0f)
            printf(", length unknown\n");
        else
            printf(", %.6g s, frames 0:%d at %g fps\n", (double)t, (int)floor((double)t * fps + 1e-6) + 1, fps);
    }
    printf("variants: %d\n", c->variants);
    for (int i = 0; i < c->variants && i < RT_GLTF_CATALOG_MAX; i++) /* --variant NAME */
        printf("variant.%d: %s\n", i, c->variant_name[i]);
}

/* Where the render's camera comes from, as the flags and the file say. */
static void print_camera_source(const args *a, const rt_scene *as_is, const rt_load_info *info)
{
    if (a->camera_auto)
        printf("camera: auto (framed to the bounds; --camera auto)");
    else if (a->camera >= 0)
        printf("camera: gltf camera %d (--camera %d)", a->camera, a->camera);
    else if (as_is->camera_set)
        printf("camera: scene file");
    else if (info->kind == RT_LOAD_GLTF && as_is->camera_count)
        printf("camera: gltf camera 0");
    else
        printf("camera: auto (framed to the bounds)");
    const char *flags[4] = {a->has_look_from ? "--look-from" : NULL, a->has_look_at ? "--look-at" : NULL,
                            a->has_up ? "--up" : NULL, a->has_fov ? "--fov" : NULL};
    int n = 0;
    for (int i = 0; i < 4; i++)
        if (flags[i])
            printf("%s%s", n++ ? ", " : ", then ", flags[i]);
    printf("\n");
}

/* The other settings the flags set (--set KEY=VALUE, --seed), each once,
 * as the last flag naming it gives it: `setting.exposure: 2 (--set)`. */
static void print_setting_flags(const args *a)
{
    static const char *const shown[] = {"resolution", "samples", "integrator", "output"};
    for (size_t i = 0; i < a->setting_count; i++) {
        const setting_flag *f = &a->settings[i];
        bool later = false, listed = false;
        for (size_t j = i + 1; j < a->setting_count && !later; j++)
            later = a->settings[j].setting == f->setting;
        for (size_t k = 0; k < sizeof shown / sizeof *shown; k++)
            listed = listed || strcmp(f->setting->name, shown[k]) == 0;
        if (!later && !listed)
            printf("setting.%s: %s (%s)\n", f->setting->name, f->value, f->flag);
    }
}

/* --info for one input: one `key: value` line per figure, for people and
 * scripts. The contents are the file's own (loaded as it is); the render
 * lines are what `rt FILE` with these flags would render. */
static int print_info(const char *path, const args *a)
{
    const memory_budget *budget = &a->budget;
    rt_scene s;
    rt_scene_init(&s);
    rt_settings loaded;
    rt_settings_default(&loaded);
    rt_error err = {0};
    rt_load_info info;
    rt_gltf_catalog catalog;
    memset(&catalog, 0, sizeof catalog);
    rt_load_options lo = {.use_time = a->posed, .time = a->frame_time, .animation = a->animation,
                          .animation_name = a->animation_name, .variant = a->variant, .catalog = &catalog,
                          .flatten_instances = a->flatten};
    rt_result r = input_load(&s, &loaded, path, &lo, &info, &err);
    if (r != RT_OK) {
        memory_budget_report(&err, budget);
        rt_scene_free(&s);
        return 2;
    }
    print_contents(path, &s, &info, &catalog, a->fps);

    /* how it would render: the render's own preparation, with the flags */
    args ak = *a;
    ak.input = path;
    char part_name[1100];
    if (args_output_is_part(a) && !a->output) { /* a part goes to NAME.part.exr, as main.c says */
        char name[1024];
        input_default_output(NULL, path, name, sizeof name);
        rt_path_tagged(name, "part", ".exr", part_name, sizeof part_name);
        ak.output = part_name;
    }
    rt_scene rs;
    rt_scene_init(&rs);
    rt_settings set;
    rt_settings_default(&set);
    char output[1024];
    bool animated = false;
    r = prepare_scene_again(&rs, &set, &ak, output, sizeof output, &animated, &err);
    if (r != RT_OK) {
        memory_budget_report(&err, budget);
        rt_scene_free(&rs);
        rt_scene_free(&s);
        return 2;
    }
    print_camera_source(a, &s, &info);
    print_vec("camera.position", rs.camera.position);
    print_vec("camera.look_at", rs.camera.look_at);
    print_vec("camera.up", rs.camera.up);
    printf("camera.fov: %.9g\n", rs.camera.vfov_deg);
    if (a->posed && a->animation_name)
        printf("pose: animation '%s' at %g s\n", a->animation_name, (double)a->frame_time);
    else if (a->posed)
        printf("pose: animation %d at %g s\n", a->animation, (double)a->frame_time);
    printf("resolution: %dx%d\n", set.width, set.height);
    printf("samples: %d\n", set.samples);
    printf("integrator: %s\n", rt_integrator_name(set.integrator));
    printf("output: %s\n", output);
    print_setting_flags(a);
    printf("load_ms: %.3f\n", info.load_ms);
    rt_scene_free(&rs);
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
