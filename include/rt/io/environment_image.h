/* rt/io/environment_image.h - the `environment` setting's image, loaded.
 *
 * The settings table (rt/render/settings.h) stores the environment's file
 * name in settings.environment_file and leaves environment_texture at
 * RT_NONE; this reads the file into the scene's image table (once per
 * name) and points environment_texture at a texture over it, repeating in
 * longitude and clamped at the poles. The scene parser calls it for an
 * `environment` line, the command line's driver after --set environment=.
 *
 *   if (rt_environment_image_load(&scene, &err) != RT_OK)   // nothing to do: RT_OK
 *       fprintf(stderr, "%s\n", err.message);                // names the file
 */
#ifndef RT_ENVIRONMENT_IMAGE_H
#define RT_ENVIRONMENT_IMAGE_H

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* Loads settings.environment_file when it names a file and
 * environment_texture is RT_NONE; RT_OK when there is nothing to load. On
 * an error the scene's tables may hold the image (the caller rolls back);
 * environment_texture stays RT_NONE. */
rt_result rt_environment_image_load(rt_scene *s, rt_error *err);

#endif
