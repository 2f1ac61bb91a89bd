/* rt/render/render.h - rendering an image: a pthread pool over a queue of
 * tiles, tile by tile or in passes over the whole image.
 *
 * The image is cut into square tiles; worker threads take the next tile from
 * an atomic counter until none are left. Each pixel's samples use random
 * streams seeded from (seed, pixel, sample), so the image is bit-identical
 * for any thread count and tile size. What the scene's integrator needs
 * (rt_render_state) is prepared once before the workers start. The scene
 * must have passed rt_scene_validate (rt/scene/validate.h).
 *
 *   rt_render_options opt = {0};       // zero = defaults: all cores, 32px tiles,
 *   opt.threads = 4;                   //   the integrator's pass size, no time limit
 *   rt_render_stats st;
 *   rt_render(&scene, &settings, &tree, &opt, &fb, &st, &err);
 *
 * Two ways to spend the samples:
 * - Tiles: each tile gets all its samples, then the next tile. A finished
 *   tile is final; an interrupted render has some tiles done, others black.
 * - Passes (opt.pass_samples > 0): every pixel gets pass_samples samples a
 *   pass (the last pass what is left), passes repeat until settings.samples.
 *   After each pass fb holds the whole image at the samples done so far, so
 *   stopping early (cancel, opt.time_limit) still leaves a complete image.
 *   Per pixel the samples are summed in sample order in the same float
 *   arithmetic as tiles (the block sums, their fold and the counts of good
 *   samples are kept between passes, 28 bytes a pixel), so the final image
 *   is bit-identical to the tiled one.
 * The default is the integrator's (rt_integrator_info.pass_samples): passes
 * of 4 for `path`, which takes hundreds of samples and is worth watching
 * converge; tiles for `direct` and `whitted`, which are usually rendered
 * with a few samples (one pass would be the whole render) and then need no
 * accumulation buffer (28 bytes a pixel) and no sweep over the image each
 * pass.
 *
 * Parts of an image (docs/farm.md): opt.region renders a rectangle of the
 * image into a framebuffer of the rectangle's size, opt.sample_begin/end a
 * range of each pixel's samples; both give exactly the samples (and so the
 * bits) the whole render has there, since the random streams depend only on
 * (seed, pixel of the whole image, sample, settings.samples). opt.accum hands
 * in and out the per-pixel sums and counts a merge or a resume needs.
 *
 * opt.time_limit stops after the pass that crosses it (tiles: each worker
 * finishes the tile in hand and takes no more); stats say how far it got.
 *
 * Progress: the calling thread waits for the workers; with opt.progress set
 * it calls it about every 50 ms, after each pass, and once more when they
 * are done (p->final). The finished tiles' pixels may be read from inside
 * the call (a live preview); in pass mode every tile counts as finished once
 * a pass is done (fb then holds the image at p->samples_done):
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

#include "rt/base/cpu.h" /* rt_cpu_count: the default thread count */
#include "rt/base/error.h"
#include "rt/image/framebuffer.h"
#include "rt/accel/kdtree.h"
#include "rt/render/sample_block.h" /* RT_SAMPLE_BLOCK: how a pixel's sum is kept */
#include "rt/render/settings.h"
#include "rt/scene/scene.h"

/* One tile of the image: its pixels [x0, x1) x [y0, y1), and whether
 * they are final. */
typedef struct rt_tile {
    int x0, y0, x1, y1;
    bool finished;
} rt_tile;

/* A progress report, valid only during the call it is passed to. */
typedef struct rt_render_progress {
    int tiles_done, tiles_total;  /* passes: of the pass under way */
    bool passes;                  /* rendering in passes */
    int samples_done;             /* passes: samples per pixel in fb (complete passes) */
    int samples_total;            /* settings.samples (of a sample range: its length) */
    int pass_samples;             /* passes: samples per pixel of the pass under way */
    double elapsed;               /* seconds since the workers started */
    bool final;                   /* the last report: the workers have stopped */
    const rt_framebuffer *fb;     /* the image; only finished tiles' pixels are final */
    const struct rt_render_job *job; /* rt_render's own: read through rt_render_progress_tile */
} rt_render_progress;

typedef void (*rt_render_progress_fn)(const rt_render_progress *p, void *user);

/* Tile `index` (0 .. tiles_total - 1, row by row) of a progress report. */
rt_tile rt_render_progress_tile(const rt_render_progress *p, int index);

/* A rectangle of the image: pixels [x0, x1) x [y0, y1). All zero = the whole image. */
typedef struct rt_render_region {
    int x0, y0, x1, y1;
} rt_render_region;


/* The caller's per-pixel sums (parts, docs/farm.md): region-sized arrays the
 * render continues (zeros for a fresh start, a stored part's values to
 * resume it) and leaves holding the samples before it plus the ones it
 * added: on return, in pass mode, up to the last whole pass (also when
 * stopped); in tile mode, exact only when no tile is missing. */
typedef struct rt_render_accum {
    float *sum;     /* 3 floats a pixel: the fold of the blocks before the current one (RT_SAMPLE_BLOCK) */
    float *block;   /* 3 floats a pixel: the current block's float sum of its good samples, in sample order */
    uint32_t *good; /* 1 a pixel: how many samples were good */
    /* NULL, or each finished block's sum kept apart as well (a part that
     * starts inside the image's samples: a merge folds them in after the
     * parts before it): blocks kept_first .. kept_first + kept_count - 1,
     * one region-sized plane of 3 floats a pixel each, block after block.
     * A pass cut short may leave later planes written: only the blocks the
     * returned samples finished are meaningful. */
    float *kept;
    int kept_first, kept_count;
    struct rt_aov_sample *aov_sum; /* NULL, or with opt.aov: the sums of the good samples' albedo, normal,
                                      position and depth (rt/render/aov.h), continued alike (one plain sum:
                                      not in blocks) */
} rt_render_accum;

typedef struct rt_render_options {
    int threads;               /* 0 = one per core */
    int tile_size;             /* 0 = 32 */
    int pass_samples;          /* samples per pixel a pass; 0 = the integrator's default, < 0 = tiles */
    double time_limit;         /* seconds; > 0: stop after the pass (tile) that crosses it */
    atomic_int *cancel;        /* set non-zero (e.g. from a signal handler) to stop */
    rt_render_progress_fn progress; /* NULL = no reports; called from the calling thread */
    void *progress_user;       /* handed to progress */
    struct rt_aov_buffers *aov; /* NULL = no AOVs; else the images to fill (rt/render/aov.h) */
    int batch_size;            /* wavefront integrators: paths in flight per worker; 0 = RT_WAVEFRONT_BATCH (same image for any) */
    rt_render_region region;   /* only these pixels (fb is their size); zero = the whole image */
    int sample_begin, sample_end; /* only samples [begin, end) of settings.samples; 0, 0 = all */
    rt_render_accum *accum;    /* NULL, or sums and counts to continue and fill (a part, a resume) */
} rt_render_options;

typedef struct rt_render_stats {
    double seconds;
    uint64_t camera_rays, rays; /* rays: every ray traced (camera, shadow, secondary) */
    uint64_t bad_samples;       /* NaN/Inf samples dropped */
    int tiles_done, tiles_total;
    int threads;
    bool passes;                /* rendered in passes */
    int pass_samples, passes_done;
    int samples_done;           /* samples per pixel this render added to every pixel of fb (0 when partial) */
    bool partial;               /* tiles: some tiles are missing (black) */
    bool interrupted;           /* stopped by cancel */
    bool time_limited;          /* stopped by the time limit */
} rt_render_stats;

/* Renders the scene's camera view into fb (which must be sized
 * settings.width x settings.height, or the region's size). When cancelled returns
 * RT_ERR_INTERRUPTED: tiles leave the finished tiles in fb (the others
 * black, stats.partial), passes the image at stats.samples_done (partial
 * when no pass finished). Stopped by the time limit it returns RT_OK with
 * stats.time_limited and the same kind of image. */
rt_result rt_render(const rt_scene *scene, const rt_settings *settings, const rt_kdtree *tree,
                    const rt_render_options *options,
                    rt_framebuffer *fb, rt_render_stats *stats, rt_error *err);


#endif
