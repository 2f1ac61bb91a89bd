/* rt/scene_parse.h - the rt scene text format (docs/scene-format.md).
 *
 * Line-based: one statement a line, `#` starts a comment. Errors name
 * file:line:column and what was expected.
 *
 *   rt_scene s;
 *   rt_scene_init(&s);
 *   if (rt_scene_parse_file(&s, "scenes/cornell.txt", &err) != RT_OK) {
 *       fprintf(stderr, "rt: %s\n", err.message);   // "scenes/cornell.txt:12:8: expected a number, got 'x'"
 *       ...
 *   }
 */
#ifndef RT_SCENE_PARSE_H
#define RT_SCENE_PARSE_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"
#include "rt/render/settings.h"
#include "rt/scene/scene.h"

/* Parses a scene file into s, its setting statements (`samples`,
 * `resolution`, ...: how to render) into settings (NULL: checked, not
 * kept); relative paths in it (meshes, textures, models) are relative to
 * the file's directory. A failed parse leaves both as they were. */
rt_result rt_scene_parse_file(rt_scene *s, rt_settings *settings, const char *path, rt_error *err);
/* Parses scene text held in memory (the reader rt_load uses); `name` is
 * used in messages, and relative paths resolve against `dir`, or against
 * the directory of `name` when dir is NULL ("" = the current directory). */
rt_result rt_scene_parse_string(rt_scene *s, rt_settings *settings, const char *text, size_t len, const char *name,
                                const char *dir, rt_error *err);

/* The time at which `model` lines pose their glTF animations (the driver's
 * --frame-time / --frames and --animation): zero = no frame time, so a
 * model line without `time`, `time_offset` or `animation` loads the static
 * pose, as before; a line's own options override (docs/scene-format.md,
 * section 6). */
typedef struct rt_scene_parse_options {
    bool use_time;   /* the render has a frame time */
    float time;      /* its seconds */
    int animation;   /* the animation a line without `animation` plays (a model without animations ignores it) */
    const char *animation_name; /* the same by name, instead of the index; NULL = by index */
    bool *animated;  /* out, may be NULL: set true when a model line's pose follows the frame time (an animation
                      * with channels, no fixed `time`), so that another time may give another pose */
    struct rt_gltf_catalog *catalog; /* not NULL: the model lines' animations and variants (rt/io/gltf.h) */
    bool flatten_instances; /* model lines flatten every mesh use, and a file loaded twice is loaded twice
                             * (rt_gltf_options.flatten_instances; rt --flatten) */
} rt_scene_parse_options;

/* rt_scene_parse_string with model lines posed at options' time (NULL =
 * none); the reader rt_load uses. */
rt_result rt_scene_parse_string_with(rt_scene *s, rt_settings *settings, const char *text, size_t len,
                                     const char *name, const char *dir, const rt_scene_parse_options *options,
                                     rt_error *err);

/* The material keys of the format (`color`, `clearcoat`, ...), by index:
 * NULL past the last (for the docs test and tools). */
const char *rt_scene_material_key(size_t i);

/* The built-in default scene (a Cornell box with a sphere), in the same format. */
extern const char rt_default_scene_text[];

#endif
