/* rt/render.h - rendering an image: a pthread pool over a queue of tiles.
 *
 * The image is cut into square tiles; worker threads take the next tile from
 * an atomic counter until none are left. Each pixel's samples use random
 * streams seeded from (seed, pixel, sample), so the image is bit-identical
 * for any thread count. The calling thread draws the progress bar and, when
 * asked, writes a live preview of the finished tiles.
 *
 *   rt_render_options opt = {0};       // zero = defaults: all cores, 32px tiles
 *   opt.threads = 4;
 *   rt_render_stats st;
 *   rt_render(&scene, &tree, &opt, &fb, &st, &err);
 */
#ifndef RT_RENDER_H
#define RT_RENDER_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/io/framebuffer.h"
#include "rt/accel/kdtree.h"
#include "rt/scene/scene.h"

typedef struct rt_render_options {
    int threads;               /* 0 = one per core */
    int tile_size;             /* 0 = 32 */
    bool progress;             /* progress bar on stderr (only drawn on a terminal) */
    atomic_int *cancel;        /* set non-zero (e.g. from a signal handler) to stop */
    const char *preview_path;  /* live view: rewrite this image with the finished tiles */
    double preview_seconds;    /* ... this often (0 = 2 s) */
} rt_render_options;

typedef struct rt_render_stats {
    double seconds;
    uint64_t camera_rays, rays; /* rays: every ray traced (camera, shadow, secondary) */
    uint64_t bad_samples;       /* NaN/Inf samples dropped */
    int tiles_done, tiles_total;
    int threads;
    bool interrupted;
} rt_render_stats;

/* Renders the scene's camera view into fb (which must be sized
 * settings.width x settings.height). On interruption returns
 * RT_ERR_INTERRUPTED with the finished tiles in fb (the others black). */
rt_result rt_render(const rt_scene *scene, const rt_kdtree *tree, const rt_render_options *options,
                    rt_framebuffer *fb, rt_render_stats *stats, rt_error *err);

int rt_cpu_count(void);

#endif
