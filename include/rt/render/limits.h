/* rt/render/limits.h - what a render can be asked for, checked before any
 * large allocation: call it once a scene is loaded, validated and its
 * camera set, before building the kd-tree.
 *
 *   if (rt_render_check_limits(&scene, "scene.txt", camera_from_file, &err) != RT_OK)
 *       ... err names the file and the limit: RT_ERR_LIMIT, or RT_ERR_INVALID
 *           for a degenerate camera the file gave ...
 *
 * The limits: the primitive count the kd-tree can index (RT_KD_PAYLOAD,
 * rt/accel/kdtree.h); every setting in the range of the settings table (the
 * parser and the flags check what they read; this catches what loaders
 * set); a `whitted` diffuse-gather tree of at most RT_MAX_DIFFUSE_TREE rays
 * a camera sample (diffuse_rays ^ diffuse_bounces); a camera that frames
 * the image. A degenerate camera is an error when it came from the input
 * (`camera_required`), else a warning (an automatic framing of empty or
 * infinite bounds looks down -z).
 */
#ifndef RT_RENDER_LIMITS_H
#define RT_RENDER_LIMITS_H

#include <stdbool.h>

#include "rt/base/error.h"
#include "rt/render/settings.h"
#include "rt/scene/scene.h"

/* whitted: rays one camera sample may spawn through diffuse gathering;
 * more is a render that never ends. */
#define RT_MAX_DIFFUSE_TREE ((double)(1 << 24))

/* RT_OK, or the first limit `s` rendered with `settings` breaks, its message starting "name: ". */
rt_result rt_render_check_limits(const rt_scene *s, const rt_settings *settings, const char *name,
                                 bool camera_required, rt_error *err);

#endif
