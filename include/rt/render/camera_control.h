/* rt/render/camera_control.h - moving a camera interactively (the --window
 * viewer): orbit, pan, dolly and walk as pure functions from one rt_camera
 * to the next, and the camera written back as a scene-file `camera` line.
 *
 *   rt_camera c = scene.camera;
 *   c = rt_camera_orbit(c, c.look_at, yaw, pitch);    // radians; distance to the pivot kept
 *   c = rt_camera_pan(c, dx, dy);                     // scene units along the image's right / up
 *   c = rt_camera_dolly(c, 0.9f);                     // 90% of the distance to look_at
 *   c = rt_camera_walk(c, fwd, right, up);            // scene units; the view direction kept
 *   float s = rt_camera_pan_scale(&c, height);        // scene units per pixel at look_at
 *   float d = rt_camera_depth(&c, &scene, &tree);     // how far ahead the model is (0: nothing ahead)
 *   if (d > 0) c = rt_camera_look_at_depth(c, d);     // orbit about the model, not a point 1 unit ahead
 *   char line[512];
 *   rt_camera_format(&c, line, sizeof line);          // "camera position ... look_at ... up ... fov ..."
 *
 * Every function returns a usable camera when given one (position !=
 * look_at, up not parallel to the view): orbit stops the view 1 degree
 * short of `up`, dolly keeps a minimum distance. The `up` vector is kept
 * as given (a turntable: yaw turns about `up`), so the horizon stays level.
 * The line holds every float with 9 significant digits, which the scene
 * parser reads back to the same float, so pasting it into a scene gives
 * the very camera (and image).
 */
#ifndef RT_CAMERA_CONTROL_H
#define RT_CAMERA_CONTROL_H

#include <stddef.h>

#include "rt/accel/kdtree.h"
#include "rt/scene/scene.h"

/* Turns position and look_at about `pivot`: yaw radians about the up axis,
 * then pitch radians about the image's right axis (positive: the camera
 * goes up, looking down more). */
rt_camera rt_camera_orbit(rt_camera c, rt_vec3 pivot, float yaw, float pitch);

/* Moves position and look_at by dx along the image's right and dy along
 * the image's up direction (scene units). */
rt_camera rt_camera_pan(rt_camera c, float dx, float dy);

/* Moves position towards look_at: the new distance is factor times the
 * old (factor < 1 comes closer), at least 1e-4 of the old one. */
rt_camera rt_camera_dolly(rt_camera c, float factor);

/* Moves position and look_at by `forward` along the view direction,
 * `right` along the image's right and `up` along the up vector. */
rt_camera rt_camera_walk(rt_camera c, float forward, float right, float up);

/* The camera with look_at moved along the view direction to `depth` scene
 * units from position (the view is kept, up to rounding); c unchanged when
 * depth is not above 0. */
rt_camera rt_camera_look_at_depth(rt_camera c, float depth);

/* How far along the view direction the scene is: the distance to the first
 * surface the ray through the image's centre meets in `tree` (built for
 * `scene`; may be NULL), else the depth of the centre of the scene's bounds
 * along the view; 0 when that is not ahead of the camera (or the scene is
 * empty). The pivot for a camera whose look_at is only a direction. */
float rt_camera_depth(const rt_camera *c, const rt_scene *scene, const rt_kdtree *tree);

/* Scene units a pixel spans at the distance of look_at, for an image
 * `height` pixels high (a pan by this per pixel keeps look_at under the
 * mouse). */
float rt_camera_pan_scale(const rt_camera *c, int height);

/* The scene-file statement for c (docs/scene-format.md, section 3):
 * position, look_at, up and fov, then aperture and focus when not zero.
 * Returns the length written (as snprintf). */
int rt_camera_format(const rt_camera *c, char *buf, size_t size);

#endif
