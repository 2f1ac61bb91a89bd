/* load.c - rt_load: one input (scene text, glTF, OBJ/PLY/OFF) into the
 * scene, through the reader its content or extension names (rt/io/load.h).
 *
 * Content before extension, so that a file named for the wrong format still
 * loads: the GLB magic and JSON's opening brace are glTF (glTF 2.0
 * specification, "GLB File Format Specification" and "JSON Schema"), PLY and
 * OFF headers are meshes (rt_mesh_format_of); only then do .gltf/.glb and
 * .obj/.ply/.off decide. The scene text format has no magic
 * (docs/scene-format.md): it is what .txt, .rt and .scene files hold, and
 * a name without an extension (standard input is "<stdin>"), unless such a
 * nameless input starts like an OBJ (its first statement is v, vn, vt, f,
 * o, g, mtllib or usemtl, none of them a scene keyword). Any other
 * extension is refused with the list of formats, rather than parsed as
 * scene text ("cube.stl: unknown keyword 'solid'" helped nobody).
 *
 * The whole load is one undo unit: the scene is marked first and rolled
 * back on any error, including the default material a mesh gets, the
 * default light and the tangents that for_render adds.
 */
#include "rt/io/load.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/base/clock.h"
#include "rt/base/file.h"
#include "rt/io/gltf.h"
#include "rt/io/mesh_io.h"
#include "rt/io/scene_parse.h"
#include "rt/render/integrator.h"
#include "rt/scene/tangents.h"

/* JSON text may start with a UTF-8 byte order mark and white space. */
static bool starts_like_json(const unsigned char *p, size_t size)
{
    size_t i = size >= 3 && memcmp(p, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
    while (i < size && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n'))
        i++;
    return i < size && p[i] == '{';
}

/* The first word of the first line that is not blank or a comment is an
 * OBJ statement that the scene format does not have. */
static bool starts_like_obj(const unsigned char *p, size_t size)
{
    static const char *const words[] = {"v", "vn", "vt", "f", "o", "g", "mtllib", "usemtl"};
    size_t i = 0;
    for (;;) {
        while (i < size && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n'))
            i++;
        if (i < size && p[i] == '#') {
            while (i < size && p[i] != '\n')
                i++;
            continue;
        }
        break;
    }
    size_t n = 0;
    while (i + n < size && p[i + n] != ' ' && p[i + n] != '\t' && p[i + n] != '\r' && p[i + n] != '\n')
        n++;
    for (size_t k = 0; n && k < sizeof words / sizeof *words; k++)
        if (strlen(words[k]) == n && memcmp(p + i, words[k], n) == 0)
            return true;
    return false;
}

bool rt_load_is_scene_name(const char *name)
{
    return !name || !*rt_path_ext(name) || rt_path_has_ext(name, ".txt") || rt_path_has_ext(name, ".rt") ||
           rt_path_has_ext(name, ".scene");
}

rt_load_kind rt_load_kind_of(const void *bytes, size_t size, const char *name)
{
    const unsigned char *p = bytes;
    if (p && ((size >= 4 && memcmp(p, "glTF", 4) == 0) || starts_like_json(p, size)))
        return RT_LOAD_GLTF;
    if (p && rt_mesh_format_of(p, size, NULL) != RT_MESH_UNKNOWN)
        return RT_LOAD_MESH;
    if (name && (rt_path_has_ext(name, ".gltf") || rt_path_has_ext(name, ".glb")))
        return RT_LOAD_GLTF;
    if (name && rt_mesh_format_of(NULL, 0, name) != RT_MESH_UNKNOWN)
        return RT_LOAD_MESH;
    if (!rt_load_is_scene_name(name))
        return RT_LOAD_UNKNOWN;
    if (name && p && !*rt_path_ext(name) && starts_like_obj(p, size))
        return RT_LOAD_MESH;
    return RT_LOAD_SCENE;
}

const char *rt_load_kind_name(rt_load_kind kind)
{
    switch (kind) {
    case RT_LOAD_SCENE: return "scene";
    case RT_LOAD_GLTF: return "gltf";
    case RT_LOAD_MESH: return "mesh";
    case RT_LOAD_UNKNOWN: return "unknown";
    }
    return "unknown";
}

/* A model has no integrator line: it gets the path tracer, which shows its
 * PBR materials as they are (the direct integrator draws every material
 * matte) and samples the sky by importance, at 64 samples per pixel, the
 * fewest that looked clean on the shared bunny and MetalRoughSpheres models
 * (256x256 against 512-spp renders: bunny RMSE 0.0099 and LDR-FLIP 0.0076
 * at 64 spp against 0.0138 / 0.0099 at 32 and 0.048 / 0.049 for direct at
 * 16; MetalRoughSpheres LDR-FLIP 0.0138 at 64, 0.0168 at 32, 0.148 direct). */
void rt_load_model_settings(rt_settings *set, rt_scene_environment *env)
{
    if (set) {
        set->samples = 64;
        set->integrator = rt_integrator_for_models();
    }
    env->background = rt_v3(0.55f, 0.6f, 0.7f);
}

/* Lighting and sampling for a bare model: a soft sky, a key light from
 * above when the model brings no lights, the path tracer and enough
 * samples for a clean image. */
static bool add_default_lighting(rt_scene *s, rt_settings *settings)
{
    rt_load_model_settings(settings, &s->environment);
    if (s->light_count == 0) {
        rt_light sun;
        memset(&sun, 0, sizeof sun);
        sun.kind = RT_LIGHT_DIRECTIONAL;
        sun.color = rt_v3(1.0f, 0.96f, 0.9f);
        sun.intensity = 2.5f;
        sun.direction = rt_normalize(rt_v3(-0.4f, -1.0f, -0.6f));
        sun.quad = RT_NONE;
        if (rt_scene_add_light(s, &sun) == RT_NONE)
            return false;
    }
    return true;
}

/* The reader for kind, then what for_render adds to that kind. */
static rt_result load_kind(rt_scene *s, rt_settings *settings, const void *bytes, size_t size, const char *name,
                           rt_load_kind kind, const rt_load_options *opt, rt_load_info *info, rt_error *err)
{
    rt_result r;
    switch (kind) {
    case RT_LOAD_GLTF: {
        rt_gltf_stats gs;
        memset(&gs, 0, sizeof gs);
        rt_gltf_options go = {
            .use_time = opt->use_time, .time = opt->time, .animation = opt->animation,
            .animation_name = opt->animation_name, .variant = opt->variant, .catalog = opt->catalog,
            .flatten_instances = opt->flatten_instances};
        r = rt_gltf_load_memory(s, bytes, size, name, &go, &gs, err);
        info->meshes = gs.meshes;
        info->primitives = gs.primitives;
        info->nodes = gs.nodes;
        info->animated = gs.animated;
        if (r == RT_OK && opt->for_render) {
            if (!add_default_lighting(s, settings))
                r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory adding the default light", name);
            if (s->camera_count) {
                s->camera = s->cameras[0];
                s->camera_set = true;
            }
        }
        return r;
    }
    case RT_LOAD_MESH: {
        rt_material m;
        rt_material_default(&m, "default");
        rt_mesh_options mo = {.material = rt_scene_add_material(s, &m)};
        if (rt_mesh_format_of(bytes, size, name) == RT_MESH_UNKNOWN) /* a nameless OBJ (rt_load_kind_of) */
            mo.format = RT_MESH_OBJ;
        r = mo.material == RT_NONE ? rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", name)
                                   : rt_mesh_load_memory(s, bytes, size, name, &mo, NULL, err);
        info->meshes = info->primitives = r == RT_OK ? 1 : 0;
        if (r == RT_OK && opt->for_render && !add_default_lighting(s, settings))
            r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory adding the default light", name);
        return r;
    }
    case RT_LOAD_UNKNOWN:
        return rt_fail(err, RT_ERR_UNSUPPORTED,
                       "%s: unknown input format '%s' (rt reads scene text: .txt, .rt, .scene or no extension; glTF: "
                       ".gltf, .glb; meshes: .obj, .ply, .off)",
                       name, rt_path_ext(name));
    case RT_LOAD_SCENE:
        break;
    }
    rt_scene_parse_options po = {
        .use_time = opt->use_time, .time = opt->time, .animation = opt->animation,
        .animation_name = opt->animation_name, .animated = &info->animated, .catalog = opt->catalog,
        .flatten_instances = opt->flatten_instances};
    return rt_scene_parse_string_with(s, settings, bytes, size, name, NULL, &po, err);
}

/* Marks the scene, loads, adds tangents for rendering, and rolls back on
 * any error. t0 is when the load began (reading included). */
static rt_result load_marked(rt_scene *s, rt_settings *settings, const void *bytes, size_t size, const char *name,
                             rt_load_kind kind, const rt_load_options *options, rt_load_info *info, double t0,
                             rt_error *err)
{
    static const rt_load_options defaults = {0};
    if (!options)
        options = &defaults;
    bool for_render = options->for_render;
    rt_scene_mark mark = rt_scene_mark_of(s);
    rt_settings settings_before;
    if (settings)
        settings_before = *settings;
    if (options->variant && kind != RT_LOAD_GLTF) {
        info->load_ms = 1e3 * rt_now_seconds() - t0;
        return rt_fail(err, RT_ERR_INVALID, "%s: --variant picks a glTF model's material variant; this is not a glTF file",
                       name ? name : "the built-in scene");
    }
    rt_result r = load_kind(s, settings, bytes, size, name, kind, options, info, err);
    if (r == RT_OK && for_render) /* normal-mapped meshes without tangents get per-vertex ones */
        r = rt_scene_generate_tangents(s, err);
    if (r != RT_OK) {
        rt_scene_rollback(s, &mark);
        if (settings)
            *settings = settings_before;
    }
    info->load_ms = 1e3 * rt_now_seconds() - t0;
    return r;
}

rt_result rt_load_memory(rt_scene *s, rt_settings *settings, const void *bytes, size_t size, const char *name,
                         const rt_load_options *options, rt_load_info *info, rt_error *err)
{
    double t0 = 1e3 * rt_now_seconds();
    rt_load_info local_info;
    if (!info)
        info = &local_info;
    memset(info, 0, sizeof *info);
    if (!name)
        name = "<memory>";
    if (!bytes && size)
        return rt_fail(err, RT_ERR_INVALID, "%s: no data", name);
    info->kind = rt_load_kind_of(bytes, size, name);
    return load_marked(s, settings, size ? bytes : "", size, name, info->kind, options, info, t0, err);
}

rt_result rt_load(rt_scene *s, rt_settings *settings, const char *path, const rt_load_options *options,
                  rt_load_info *info, rt_error *err)
{
    double t0 = 1e3 * rt_now_seconds();
    rt_load_info local_info;
    if (!info)
        info = &local_info;
    memset(info, 0, sizeof *info);
    if (!path)
        return load_marked(s, settings, rt_default_scene_text, strlen(rt_default_scene_text), "<built-in scene>",
                           RT_LOAD_SCENE, options, info, t0, err);
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(path, 0, &bytes, &size, err);
    if (r != RT_OK) {
        info->kind = rt_load_kind_of(NULL, 0, path);
        info->load_ms = 1e3 * rt_now_seconds() - t0;
        return r;
    }
    info->kind = rt_load_kind_of(bytes, size, path);
    r = load_marked(s, settings, bytes, size, path, info->kind, options, info, t0, err);
    free(bytes);
    return r;
}
