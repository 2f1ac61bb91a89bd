/* input.h - the `rt` command's input and its default output name
 * (driver-private).
 *
 * The input is a path, NULL for the built-in Cornell box, or "-" for
 * standard input (read whole and loaded from memory as "<stdin>": scene
 * text, or glTF or a mesh by its content).
 *
 *   rt_load_info info;
 *   if (input_load(&scene, a.input, &lo, &info, &err) != RT_OK) ...
 *   rt_info("scene: %s", input_name(a.input));   // "<built-in scene>", "<stdin>" or the path
 *   char out[1024];
 *   input_default_output(&scene, a.input, out, sizeof out);   // the scene's `output`, else NAME.png
 */
#ifndef RT_DRIVER_INPUT_H
#define RT_DRIVER_INPUT_H

#include <stddef.h>

#include "rt/base/error.h"
#include "rt/io/load.h"
#include "rt/scene/scene.h"

/* rt_load for a path or the built-in scene; standard input for "-" (a
 * terminal there is refused, RT_ERR_IO). */
rt_result input_load(rt_scene *s, const char *input, const rt_load_options *lo, rt_load_info *info, rt_error *err);
/* The name messages use for an input. */
const char *input_name(const char *input);
/* The output when -o is not given: the scene's `output` (s may be NULL),
 * else the input's base name with .png in the current directory, out.png
 * for the built-in scene and standard input. */
void input_default_output(const rt_scene *s, const char *input, char *out, size_t size);

#endif
