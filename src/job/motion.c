/* motion.c - time slices of a motion-blurred render (rt/job/motion.h). The
 * shutter's box filter, [open, close], is integrated by stratifying time
 * into K equal slices, each at its midpoint (the midpoint rule), and the
 * pixel's samples are split between them in equal contiguous runs of
 * sample indices, so every slice gets exactly its share of every pixel.
 * Cook, Porter and Carpenter, "Distributed ray tracing" (SIGGRAPH 1984),
 * for time as one more dimension of a pixel's samples; pbrt-v4 (section
 * 5.1) for the shutter interval relative to the frame. */
#include "rt/job/motion.h"

bool rt_motion_shutter_open(const rt_camera *c) { return c->shutter_close > c->shutter_open; }

int rt_motion_slices(const rt_camera *c, int steps, int samples)
{
    if (!rt_motion_shutter_open(c))
        return 0;
    int k = steps < samples ? steps : samples;
    return k < 1 ? 1 : k;
}

double rt_motion_time(double frame, const rt_camera *c, int k, int slices)
{
    double open = c->shutter_open, close = c->shutter_close;
    return frame + open + ((double)k + 0.5) * (close - open) / (double)slices;
}

void rt_motion_samples(int k, int slices, int samples, int *begin, int *end)
{
    *begin = (int)((long long)k * samples / slices);
    *end = (int)((long long)(k + 1) * samples / slices);
}
