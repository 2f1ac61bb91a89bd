/* frames_camera.h - the automatic camera of a `--frames A:B` sequence
 * (driver-private; docs/farm.md, "Frames"): one camera for every frame of
 * A .. B-1, framing every pose of the animation over them, so the shot
 * neither zooms nor jitters from frame to frame. It depends on the whole
 * range A:B only, never on the frames one run renders of it
 * (--only-frames), so machines that share out the frames frame alike.
 *
 *   rt_frame_extent e;
 *   bool used;
 *   if (frames_camera_extent(&a, &e, &used, &err) != RT_OK) ...   // loads each frame's pose once
 *   a.frame_extent = used ? &e : NULL;                             // rt_job_frame frames from it
 */
#ifndef RT_DRIVER_FRAMES_CAMERA_H
#define RT_DRIVER_FRAMES_CAMERA_H

#include <stdbool.h>

#include "args.h"
#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* The extent of the scene posed at every frame of a->frame_begin ..
 * a->frame_end (time frame / fps) into *e, and *used true, when the view
 * is framed automatically (no camera in the input, or --camera auto) and
 * the input is animated; else *used false (a still scene frames as one
 * render does, and a camera of the input or --camera N is kept). */
rt_result frames_camera_extent(const args *a, rt_frame_extent *e, bool *used, rt_error *err);

#endif
