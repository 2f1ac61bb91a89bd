/* run.h - one render of the `rt` command, from the flags to its files and
 * exit status (driver-private): load and prepare (prepare.h), motion-blur
 * slices when the shutter is open over animated models, the kd-tree, the
 * job's part plan and outputs (rt/job/), the progress line, the window and
 * the tev stream, the render, and the result written.
 *
 *   static atomic_int interrupted, stop;   // the signal handler's
 *   static rt_write_temp temp;
 *   run_signals sig = {&interrupted, &stop, &temp, on_signal};
 *   int status = run_one(&scene, &a, rt_now_seconds(), &sig, NULL);   // 0, 2, or 128 + a signal
 */
#ifndef RT_DRIVER_RUN_H
#define RT_DRIVER_RUN_H

#include <stdatomic.h>

#include "args.h"
#include "rt/accel/kdtree.h"
#include "rt/io/image_write.h"
#include "rt/scene/scene.h"

/* What a render shares with the process's signal handler: the first
 * signal's number, the render's cancel flag (also raised by the window),
 * the temporary file of an image write under way, and the handler that
 * the render installs for SIGINT and SIGTERM once it starts. */
typedef struct run_signals {
    atomic_int *interrupted;
    atomic_int *stop;
    rt_write_temp *temp;
    void (*handler)(int sig);
} run_signals;

/* Loads, prepares (posed at a->frame_time when a->posed), renders and
 * writes one image (or part) into the initialised scene; the exit status.
 * kept: the objects' trees of earlier frames (rt_kdtree_kept), taken where
 * the objects are the same and trimmed to this frame's after it; NULL: the
 * trees are this render's (its motion slices still share them). */
int run_one(rt_scene *scene, const args *a, double t_start, const run_signals *sig, rt_kdtree_kept *kept);

#endif
