/* rt/render/wavefront.h - the wavefront path tracer: the `path` integrator
 * run over a batch of paths at once, stage by stage, instead of one path
 * from camera to end (docs/path-tracer.md, "Wavefront").
 *
 *   rt_wavefront *wf = rt_wavefront_new(1024, &state);   // per worker; NULL: out of memory
 *   rt_wavefront_work wk = {&camera, width, seed, spp, x0, x1, y0, first, count, s0, s1};
 *   float *out = ...;                                    // 3 x count x (s1 - s0) floats
 *   rt_wavefront_radiance(wf, &ctx, &wk, out);
 *   // out[3 * (i * (s1 - s0) + (s - s0))] .. + 2: the radiance of sample s of
 *   // pixel first + i of the rectangle (row-major, columns x0 .. x1 - 1, from row y0)
 *   rt_wavefront_free(wf);
 *
 * Each radiance is bit for bit what rt_radiance_path (rt/render/pathtrace.h)
 * returns for the same camera sample (rt_camera_pixel_sample): the paths
 * take the same steps with their own random streams, so the result does not
 * depend on the batch size, on which lane a path runs in, or on how the
 * pixels are split into work. rt_render uses it for every integrator whose
 * table line asks for it (`path`; `path_scalar` is the one-path-at-a-time
 * reference).
 */
#ifndef RT_WAVEFRONT_H
#define RT_WAVEFRONT_H

#include <stddef.h>
#include <stdint.h>

#include "rt/render/camera.h"
#include "rt/render/trace.h"

#define RT_WAVEFRONT_BATCH 1024 /* default paths in flight per worker (docs/performance.md measures 256-4096) */

typedef struct rt_wavefront rt_wavefront;

/* Pixels first .. first + count - 1 of a rectangle (row-major, columns
 * x0 .. x1 - 1, rows from y0), samples s0 .. s1 - 1 of spp of each. */
typedef struct rt_wavefront_work {
    const rt_camera_frame *camera;
    int width;        /* the image's width (pixel index y * width + x) */
    uint32_t seed;    /* settings.seed */
    uint32_t spp;     /* samples per pixel of the whole render (the pixel pattern's size) */
    int x0, x1, y0;
    uint32_t first, count;
    uint32_t s0, s1;
} rt_wavefront_work;

/* What went as coherent groups so far (counted over the wavefront's life):
 * camera rays traced as screen tiles (kdtree_frustum.h), and shadow rays
 * traced as bundles. The images do not depend on it; tests read it to see
 * the tiles were used. */
typedef struct rt_wavefront_stats {
    uint64_t tiles, tile_rays;     /* frustum calls on camera rays, rays in them */
    uint64_t bundles, bundle_rays; /* frustum calls on shadow rays, rays in them */
} rt_wavefront_stats;

rt_wavefront_stats rt_wavefront_stats_of(const rt_wavefront *wf);

/* Room for batch paths (0: RT_WAVEFRONT_BATCH) and their light samples in
 * the scene of `state` (fewer paths when its lights would need more than
 * 2^18 light-sample records: about 20 MB); NULL when out of memory. */
rt_wavefront *rt_wavefront_new(size_t batch, const rt_render_state *state);
void rt_wavefront_free(rt_wavefront *wf);

/* The radiance of every sample of the work into out (see above). */
void rt_wavefront_radiance(rt_wavefront *wf, const rt_trace_ctx *ctx, const rt_wavefront_work *work, float *out);

#endif
