/* rt/job/motion.h - motion blur over the camera's shutter (docs/gltf.md,
 * "Motion blur"): the shutter [open, close] (seconds from the frame time)
 * is cut into K equal slices; slice k is the scene posed at its midpoint,
 * with its own kd-tree, and renders the samples
 * [k S / K, (k+1) S / K) of every pixel into the same sums, so the image
 * is the shutter's box filter to K steps and has the bytes of any other
 * split (threads, tiles, passes, parts) of the same samples.
 *
 *   int K = rt_motion_slices(&scene.camera, scene.settings.motion_steps, scene.settings.samples);
 *   for (int k = 0; k < K; k++) {
 *       double t = rt_motion_time(frame_time, &scene.camera, k, K);   // pose slice k here
 *       int s0, s1;
 *       rt_motion_samples(k, K, scene.settings.samples, &s0, &s1);    // ... and render these samples
 *   }
 */
#ifndef RT_JOB_MOTION_H
#define RT_JOB_MOTION_H

#include <stdbool.h>

#include "rt/scene/scene.h"

/* True when the camera's shutter is open for a while (close > open). */
bool rt_motion_shutter_open(const rt_camera *c);
/* The number of slices: 0 when the shutter is not open, else the
 * `motion_steps` setting, at most the samples per pixel (every slice gets
 * one sample at least). */
int rt_motion_slices(const rt_camera *c, int steps, int samples);
/* The time of slice k of K: frame + open + (k + 1/2) (close - open) / K, so
 * K = 1 is the shutter's midpoint. */
double rt_motion_time(double frame, const rt_camera *c, int k, int slices);
/* The samples [*begin, *end) slice k of K renders: k S / K to (k+1) S / K
 * (rounded down), which together cover 0 .. S-1 once. */
void rt_motion_samples(int k, int slices, int samples, int *begin, int *end);

#endif
