/* rt/render/render.h - rendering an image: a pthread pool over a queue of
 * tiles.
 *
 * The image is cut into square tiles; worker threads take the next tile from
 * an atomic counter until none are left. Each pixel's samples use random
 * streams seeded from (seed, pixel, sample), so the image is bit-identical
 * for any thread count. What the scene's integrator needs (rt_render_state)
 * is prepared once before the workers start. The scene must have passed
 * rt_scene_validate (rt/scene/validate.h).
 *
 *   rt_render_options opt = {0};       // zero = defaults: all cores, 32px tiles
 *   opt.threads = 4;
 *   rt_render_stats st;
 *   rt_render(&scene, &tree, &opt, &fb, &st, &err);
 *
 * Progress: the calling thread waits for the workers; with opt.progress set
 * it calls it about every 50 ms, and once more when they are done
 * (p->final), with the tiles done so far. The finished tiles' pixels may be
 * read from inside the call (a live preview):
 *
 *   static void show(const rt_render_progress *p, void *user)
 *   {
 *       for (int i = 0; i < p->tiles_total; i++) {
 *           rt_tile t = rt_render_progress_tile(p, i);
 *           if (t.finished) ... p->fb->rgb over [t.x0, t.x1) x [t.y0, t.y1) is final ...
 *       }
 *   }
 *   opt.progress = show;
 *   opt.progress_user = &my_view;
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

/* One tile of the image: its pixels [x0, x1) x [y0, y1), and whether
 * they are final. */
typedef struct rt_tile {
    int x0, y0, x1, y1;
    bool finished;
} rt_tile;

/* A progress report, valid only during the call it is passed to. */
typedef struct rt_render_progress {
    int tiles_done, tiles_total;
    double elapsed;               /* seconds since the workers started */
    bool final;                   /* the last report: the workers have stopped */
    const rt_framebuffer *fb;     /* the image; only finished tiles' pixels are final */
    const struct rt_render_job *job; /* rt_render's own: read through rt_render_progress_tile */
} rt_render_progress;

typedef void (*rt_render_progress_fn)(const rt_render_progress *p, void *user);

/* Tile `index` (0 .. tiles_total - 1, row by row) of a progress report. */
rt_tile rt_render_progress_tile(const rt_render_progress *p, int index);

typedef struct rt_render_options {
    int threads;               /* 0 = one per core */
    int tile_size;             /* 0 = 32 */
    atomic_int *cancel;        /* set non-zero (e.g. from a signal handler) to stop */
    rt_render_progress_fn progress; /* NULL = no reports; called from the calling thread */
    void *progress_user;       /* handed to progress */
    struct rt_aov_buffers *aov; /* NULL = no AOVs; else the images to fill (rt/render/aov.h) */
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
