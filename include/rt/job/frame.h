/* rt/job/frame.h - the view a job renders, from a loaded and validated
 * scene and the job's options: a loaded model's camera or the scene framed
 * automatically, a camera made for another aspect ratio fitted to the
 * image, the camera parts the options replace (look-from, look-at, up,
 * field of view), and the limits checked (rt_render_check_limits).
 *
 *   rt_job_options o = {.camera_auto = true};
 *   if (rt_job_frame(&scene, &o, "bunny.obj", &err) != RT_OK) ...   // messages name "bunny.obj"
 */
#ifndef RT_JOB_FRAME_H
#define RT_JOB_FRAME_H

#include "rt/base/error.h"
#include "rt/job/options.h"
#include "rt/scene/scene.h"

/* The camera and image size as the options say, then the limits; name is
 * the input's name for messages. A camera the options leave degenerate is
 * an error naming them; so is a camera index the models do not have. */
rt_result rt_job_frame(rt_scene *scene, const rt_job_options *o, const char *name, rt_error *err);

/* The width that gives an image of `height` the aspect ratio, within the
 * image size limits. */
int rt_job_width_for_aspect(int height, float aspect_ratio);

#endif
