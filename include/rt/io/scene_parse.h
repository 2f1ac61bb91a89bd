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

#include <stddef.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* Parses a scene file; relative paths in it (meshes, textures, models) are
 * relative to the file's directory. */
rt_result rt_scene_parse_file(rt_scene *s, const char *path, rt_error *err);
/* Parses scene text held in memory (the reader rt_load uses); `name` is
 * used in messages, and relative paths resolve against `dir`, or against
 * the directory of `name` when dir is NULL ("" = the current directory). */
rt_result rt_scene_parse_string(rt_scene *s, const char *text, size_t len, const char *name, const char *dir,
                                rt_error *err);

/* The material keys of the format (`color`, `clearcoat`, ...), by index:
 * NULL past the last (for the docs test and tools). */
const char *rt_scene_material_key(size_t i);

/* The built-in default scene (a Cornell box with a sphere), in the same format. */
extern const char rt_default_scene_text[];

#endif
