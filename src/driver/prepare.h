/* prepare.h - the loaded scene as the `rt` flags want it (driver-private).
 *
 *   char output[1024];
 *   bool animated;
 *   if (prepare_scene(&scene, &a, output, sizeof output, &animated, &err) != RT_OK) ...  // exit status 2
 */
#ifndef RT_DRIVER_PREPARE_H
#define RT_DRIVER_PREPARE_H

#include <stdbool.h>
#include <stddef.h>

#include "args.h"

/* Loads a->input into scene (rolled back on failure), validates it, applies
 * the setting and camera flags, checks the limits, and chooses and checks
 * the output path (into output); *animated when the input follows the
 * frame time. */
rt_result prepare_scene(rt_scene *scene, const args *a, char *output, size_t size, bool *animated, rt_error *err);
/* The same for the same input at another time (a motion slice): the first
 * load's warnings are not said again (-v keeps its lines). */
rt_result prepare_scene_again(rt_scene *scene, const args *a, char *output, size_t size, bool *animated,
                              rt_error *err);

#endif
