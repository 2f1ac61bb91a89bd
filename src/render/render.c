/* render.c - the tile queue and its worker threads, the pixel loop, passes
 * over the whole image, time limits, and progress reports to the caller
 * (which draws them: src/driver/progress.c).
 *
 * Pixel estimate: the box-filtered average of `samples` radiance samples at
 * correlated multi-jittered positions in the pixel (Kensler 2013), so any
 * sample count is stratified. A sample that comes back NaN or infinite is
 * dropped and counted (it shows a bug, not light); the pixel averages the
 * rest. settings.clamp, when set, caps a sample's luminance.
 *
 * A pixel's sum is kept in blocks of RT_SAMPLE_BLOCK (64) samples by sample
 * index (rt/render/sample_block.h): the float sum of the current block's good
 * samples in sample order, and the fold of the blocks before it, which
 * takes the block in when a sample index crosses a block edge; the pixel is
 * (fold + block) * (1 / good). Up to 64 samples that is 0 + b_0: the plain
 * sequential sum, bit for bit; above, the blocks let a range of samples
 * rendered elsewhere be folded in at its place (docs/farm.md).
 *
 * Passes keep per pixel the fold, the block sum and the count (28 bytes);
 * a pass adds its samples in sample order with the same operations the tile
 * loop uses (add_sample below serves both, and the wavefront path), and the
 * image is resolved after each pass, so a pass split cannot change a bit.
 * (The build's -std=c11 keeps GCC from contracting a*b+c into an FMA.)
 * Workers are started for each pass and joined at its end: the join is the
 * barrier that keeps two passes off one pixel, and a start costs far less
 * than a pass.
 */
#include "rt/render/render.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/base/alloc.h"
#include "rt/base/clock.h"
#include "rt/base/log.h"
#include "rt/render/aov.h"
#include "rt/render/camera.h"
#include "rt/render/integrator.h"
#include "rt/render/pathtrace.h"
#include "rt/render/volpath.h"
#include "rt/render/sampling.h"
#include "rt/render/wavefront.h"
#include "rt/scene/validate.h"

struct rt_render_job {
    const rt_scene *scene;
    const rt_settings *settings;  /* how to render it */
    rt_framebuffer *fb;           /* the region's pixels */
    rt_camera_frame camera;
    int width, height;            /* the whole image (settings) */
    int rx0, ry0, rw, rh;         /* the region rendered: [rx0, rx0 + rw) x [ry0, ry0 + rh) */
    int tile_size, tiles_x, tiles_y, tiles_total;
    uint32_t spp;                 /* settings.samples */
    uint32_t s_begin, s_end;      /* the samples this render adds: [s_begin, s_end) */
    bool passes;                  /* pass mode: accumulate into sum/good */
    uint32_t s0, s1;              /* passes: this pass's samples [s0, s1) */
    rt_render_accum *accum;       /* NULL, or the caller's sums and counts, continued */
    float *sum;                   /* passes: per pixel, RGB fold of the finished blocks (pixel_sum.fold) */
    float *block;                 /* passes: per pixel, RGB sum of the current block's good samples */
    uint32_t *good;               /* passes: per pixel, how many samples were good */
    int samples_done;             /* passes: samples in fb (read by progress reports) */
    double deadline;              /* tiles: take no tile after this time; 0 = none */
    atomic_int time_up;           /* tiles: a worker saw the deadline pass */
    atomic_int next_tile;
    atomic_int tiles_done;
    atomic_uchar *tile_finished;  /* per tile: 1 once its pixels are final (this pass) */
    atomic_int *cancel;
    const rt_render_state *state; /* prepared once, read by every worker */
    rt_radiance_fn radiance;      /* the scene's integrator */
    bool wavefront;               /* ... run as batches of paths (rt/render/wavefront.h) */
    int batch_size;               /* wavefront: paths per worker (0 = the default) */
    rt_aov_buffers *aov;          /* NULL = none */
    rt_aov_sample *aov_sum;       /* with aov: per pixel, the sums of its good samples' AOVs */
    double *lum_sq;               /* with aov: per pixel, the sum of its good samples' squared luminance */
    pthread_mutex_t lock;         /* guards running; done signals it falling */
    pthread_cond_t done;
    int running;                  /* workers of this pass still going */
};
typedef struct rt_render_job rt_render_job;

typedef struct worker {
    pthread_t thread;
    rt_render_job *job;
    uint64_t rays, camera_rays, bad_samples;
    rt_wavefront *wf;             /* wavefront integrators: this worker's batch (NULL: one path at a time) */
    float *wf_out;                /* its radiance per sample of a chunk, WAVE_CHUNK x 3 */
} worker;

/* Samples a wavefront chunk holds at most: the cancel flag is read between
 * chunks, and the radiance buffer is WAVE_CHUNK x 12 bytes a worker. */
enum { WAVE_CHUNK = 16384 };

/* A pixel's running sum: the fold of its finished sample blocks, the sum of
 * the current block's good samples, and how many samples were good. */
typedef struct pixel_sum {
    rt_vec3 fold, block;
    uint32_t good;
} pixel_sum;

/* Sample s starts a block: the block so far goes into the fold (and, for
 * the caller's kept blocks, into its plane). Up to the first edge the fold
 * is 0 + 0. */
static void fold_block(const rt_render_job *job, size_t local, uint32_t s, pixel_sum *p)
{
    const rt_render_accum *acc = job->accum;
    if (acc && acc->kept) {
        int64_t j = (int64_t)(s / RT_SAMPLE_BLOCK) - 1 - acc->kept_first; /* the block that ended, as a plane */
        if (j >= 0 && j < acc->kept_count) {
            float *k = acc->kept + ((size_t)j * (size_t)job->rw * (size_t)job->rh + local) * 3;
            k[0] = p->block.x;
            k[1] = p->block.y;
            k[2] = p->block.z;
        }
    }
    p->fold = rt_sample_fold(p->fold, p->block);
    p->block = rt_v3s(0);
}

/* Adds radiance sample L, sample s of pixel (x, y) of the whole image
 * (`local`: its index in the region's buffers), to *p: the one place a
 * pixel's arithmetic happens, for tiles and passes, one path at a time or
 * a wavefront, alike; samples come in sample order. */
static inline void add_sample(const rt_render_job *job, worker *w, rt_trace_ctx *ctx, int x, int y, size_t local,
                              uint32_t s, rt_vec3 L, pixel_sum *p)
{
    const rt_settings *st = job->settings;
    uint64_t pixel = (uint64_t)y * (uint64_t)job->width + (uint64_t)x;
    if (s % RT_SAMPLE_BLOCK == 0)
        fold_block(job, local, s, p);
    if (!rt_finite3(L) || L.x < 0.0f || L.y < 0.0f || L.z < 0.0f) {
        w->bad_samples++;
        return;
    }
    if (st->clamp > 0.0f) {
        float lum = rt_luminance(L);
        if (lum > st->clamp)
            L = rt_scale(L, st->clamp / lum);
    }
    p->block = rt_add(p->block, L);
    p->good++;
    if (job->aov) { /* own random numbers: the image stays as it was */
        rt_rng unused;
        rt_ray ray = rt_camera_pixel_sample(&job->camera, job->width, st->seed, job->spp, x, y, s, &unused);
        rt_rng arng = rt_rng_for_sample(st->seed ^ 0xa0f5eed5u, pixel, s);
        rt_aov_sample a;
        rt_aov_trace(ctx, ray, &arng, &a);
        rt_aov_sample *acc = &job->aov_sum[local];
        acc->albedo = rt_add(acc->albedo, a.albedo);
        acc->normal = rt_add(acc->normal, a.normal);
        acc->position = rt_add(acc->position, a.position);
        acc->depth += a.depth;
        job->lum_sq[local] += (double)rt_luminance(L) * (double)rt_luminance(L);
    }
}

/* Adds samples [s0, s1) of pixel (x, y) to *p_io, in sample order, one
 * path at a time. */
static inline void add_samples(const rt_render_job *job, worker *w, rt_trace_ctx *ctx, int x, int y, size_t local,
                               uint32_t s0, uint32_t s1, pixel_sum *p_io)
{
    const rt_settings *st = job->settings;
    pixel_sum p = *p_io;
    for (uint32_t s = s0; s < s1; s++) {
        rt_rng rng;
        rt_ray ray = rt_camera_pixel_sample(&job->camera, job->width, st->seed, job->spp, x, y, s, &rng);
        w->camera_rays++;
        rt_vec3 L = job->radiance(ctx, &ray, &rng);
        add_sample(job, w, ctx, x, y, local, s, L, &p);
    }
    *p_io = p;
}

/* The pixel's sum: the fold with the current block taken in (the fold
 * alone, exactly, when that block is still empty of samples). */
static inline rt_vec3 pixel_total(const pixel_sum *p)
{
    return rt_sample_fold(p->fold, p->block);
}

/* Tile `tile` of the region, in the region's (fb's) coordinates. */
static void tile_bounds(const rt_render_job *job, int tile, int *x0, int *y0, int *x1, int *y1)
{
    int tx = tile % job->tiles_x, ty = tile / job->tiles_x;
    *x0 = tx * job->tile_size;
    *y0 = ty * job->tile_size;
    *x1 = *x0 + job->tile_size < job->rw ? *x0 + job->tile_size : job->rw;
    *y1 = *y0 + job->tile_size < job->rh ? *y0 + job->tile_size : job->rh;
}

static inline rt_vec3 load3(const float *f) { return rt_v3(f[0], f[1], f[2]); }

static inline void store3(float *f, rt_vec3 v)
{
    f[0] = v.x;
    f[1] = v.y;
    f[2] = v.z;
}

/* A pixel's running sum before its samples (`pixel`: its index in the
 * region): passes continue the accumulated one, tiles start from zero or
 * from the caller's sums. */
static void pixel_begin(const rt_render_job *job, size_t pixel, pixel_sum *p)
{
    p->fold = p->block = rt_v3s(0);
    p->good = 0;
    if (job->passes) {
        p->fold = load3(job->sum + 3 * pixel);
        p->block = load3(job->block + 3 * pixel);
        p->good = job->good[pixel];
    } else if (job->accum) { /* continue the caller's sums */
        p->fold = load3(job->accum->sum + 3 * pixel);
        p->block = load3(job->accum->block + 3 * pixel);
        p->good = job->accum->good[pixel];
    }
}

/* ... and after them: passes keep the sums, tiles write the pixel (and the
 * caller's sums). */
static void pixel_end(rt_render_job *job, size_t pixel, const pixel_sum *p)
{
    if (job->passes) {
        store3(job->sum + 3 * pixel, p->fold);
        store3(job->block + 3 * pixel, p->block);
        job->good[pixel] = p->good;
        return;
    }
    if (job->accum) {
        store3(job->accum->sum + 3 * pixel, p->fold);
        store3(job->accum->block + 3 * pixel, p->block);
        job->accum->good[pixel] = p->good;
    }
    rt_vec3 sum = pixel_total(p);
    uint32_t good = p->good;
    if (job->aov)
        rt_aov_resolve(job->aov, pixel, &job->aov_sum[pixel], good, rt_luminance(sum), job->lum_sq[pixel]);
    sum = rt_sample_resolve(sum, good);
    float *px = job->fb->rgb + 3 * pixel;
    px[0] = sum.x;
    px[1] = sum.y;
    px[2] = sum.z;
}

static inline bool cancelled(const rt_render_job *job)
{
    return job->cancel && atomic_load_explicit(job->cancel, memory_order_relaxed);
}

/* render_tile for a wavefront integrator: the tile's pixels (region
 * coordinates [x0, x1) x [y0, y1)) in chunks of at most WAVE_CHUNK samples
 * (a pixel with more samples than that in chunks of its samples), each
 * traced as one wavefront, then added pixel by pixel in sample order exactly
 * as the one-path-at-a-time loop adds them. */
static bool render_tile_wavefront(rt_render_job *job, worker *w, rt_trace_ctx *ctx, int x0, int y0, int x1, int y1)
{
    uint32_t s0 = job->passes ? job->s0 : job->s_begin, s1 = job->passes ? job->s1 : job->s_end;
    uint32_t ns = s1 - s0, tw = (uint32_t)(x1 - x0);
    uint32_t npx = tw * (uint32_t)(y1 - y0);
    uint32_t per_chunk = ns >= WAVE_CHUNK ? 1 : WAVE_CHUNK / ns;
    rt_wavefront_work wk = {&job->camera, job->width, job->settings->seed, job->spp, x0 + job->rx0,
                            x1 + job->rx0, y0 + job->ry0, 0, 0, 0, 0};
    for (uint32_t p = 0; p < npx; p += per_chunk) {
        if (cancelled(job))
            return false;
        wk.first = p;
        wk.count = npx - p < per_chunk ? npx - p : per_chunk;
        if (wk.count > 1 || ns <= WAVE_CHUNK) {
            wk.s0 = s0;
            wk.s1 = s1;
            rt_wavefront_radiance(w->wf, ctx, &wk, w->wf_out);
            w->camera_rays += (uint64_t)wk.count * ns;
            for (uint32_t i = 0; i < wk.count; i++) {
                int x = x0 + (int)((p + i) % tw), y = y0 + (int)((p + i) / tw);
                size_t pixel = (size_t)y * (size_t)job->rw + (size_t)x;
                pixel_sum ps;
                pixel_begin(job, pixel, &ps);
                const float *o = w->wf_out + 3 * (size_t)i * ns;
                for (uint32_t s = s0; s < s1; s++, o += 3)
                    add_sample(job, w, ctx, x + job->rx0, y + job->ry0, pixel, s, rt_v3(o[0], o[1], o[2]), &ps);
                pixel_end(job, pixel, &ps);
            }
            continue;
        }
        /* one pixel, its samples in chunks */
        int x = x0 + (int)(p % tw), y = y0 + (int)(p / tw);
        size_t pixel = (size_t)y * (size_t)job->rw + (size_t)x;
        pixel_sum ps;
        pixel_begin(job, pixel, &ps);
        for (uint32_t sa = s0; sa < s1; sa += WAVE_CHUNK) {
            if (cancelled(job))
                return false;
            wk.s0 = sa;
            wk.s1 = s1 - sa < WAVE_CHUNK ? s1 : sa + WAVE_CHUNK;
            rt_wavefront_radiance(w->wf, ctx, &wk, w->wf_out);
            w->camera_rays += wk.s1 - wk.s0;
            const float *o = w->wf_out;
            for (uint32_t s = wk.s0; s < wk.s1; s++, o += 3)
                add_sample(job, w, ctx, x + job->rx0, y + job->ry0, pixel, s, rt_v3(o[0], o[1], o[2]), &ps);
        }
        pixel_end(job, pixel, &ps);
    }
    return true;
}

/* Renders one tile (tiles: all its samples into fb; passes: this pass's
 * samples into sum/good); false when cancelled part-way (the tile then
 * stays unfinished). The cancel flag is read once a pixel (a wavefront
 * chunk), so Ctrl-C is answered within a pixel's samples, not a tile's. */
static bool render_tile(rt_render_job *job, worker *w, rt_trace_ctx *ctx, int tile)
{
    int x0, y0, x1, y1;
    tile_bounds(job, tile, &x0, &y0, &x1, &y1);
    if (w->wf)
        return render_tile_wavefront(job, w, ctx, x0, y0, x1, y1);
    uint32_t s0 = job->passes ? job->s0 : job->s_begin, s1 = job->passes ? job->s1 : job->s_end;
    for (int y = y0; y < y1; y++) {
        for (int x = x0; x < x1; x++) {
            if (cancelled(job))
                return false;
            size_t pixel = (size_t)y * (size_t)job->rw + (size_t)x;
            pixel_sum ps;
            pixel_begin(job, pixel, &ps);
            add_samples(job, w, ctx, x + job->rx0, y + job->ry0, pixel, s0, s1, &ps);
            pixel_end(job, pixel, &ps);
        }
    }
    return true;
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    rt_render_job *job = w->job;
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, job->state);
    ctx.ray_count = &w->rays;
    if (job->wavefront && !w->wf) { /* kept across passes; out of memory: one path at a time, same image */
        w->wf = rt_wavefront_new((size_t)job->batch_size, job->state);
        w->wf_out = w->wf ? rt_alloc(WAVE_CHUNK, 3 * sizeof *w->wf_out) : NULL;
        if (!w->wf_out) {
            rt_wavefront_free(w->wf);
            w->wf = NULL;
        }
    }
    for (;;) {
        if (job->cancel && atomic_load(job->cancel))
            break;
        if (job->deadline > 0.0 && rt_now_seconds() >= job->deadline) {
            atomic_store(&job->time_up, 1);
            break;
        }
        int tile = atomic_fetch_add(&job->next_tile, 1);
        if (tile >= job->tiles_total)
            break;
        if (!render_tile(job, w, &ctx, tile))
            break;
        atomic_store(&job->tile_finished[tile], 1);
        atomic_fetch_add(&job->tiles_done, 1);
    }
    pthread_mutex_lock(&job->lock);
    job->running--;
    pthread_cond_signal(&job->done);
    pthread_mutex_unlock(&job->lock);
    return NULL;
}

rt_tile rt_render_progress_tile(const rt_render_progress *p, int index)
{
    const rt_render_job *job = p->job;
    rt_tile t;
    tile_bounds(job, index, &t.x0, &t.y0, &t.x1, &t.y1);
    t.finished = job->passes ? job->samples_done > 0 : atomic_load(&job->tile_finished[index]) != 0;
    return t;
}

/* Runs the workers over the tile queue once (a whole tiled render, or one
 * pass), reporting progress about every 50 ms; returns the threads that
 * could be started (0: the work was done on this thread). */
static int run_workers(rt_render_job *job, worker *workers, int nthreads, const rt_render_options *opt,
                       rt_render_progress *progress, double t0)
{
    atomic_store(&job->next_tile, 0);
    atomic_store(&job->tiles_done, 0);
    for (int t = 0; t < job->tiles_total; t++)
        atomic_store(&job->tile_finished[t], 0);
    int started = 0;
    pthread_mutex_lock(&job->lock);
    for (int i = 0; i < nthreads; i++) {
        workers[i].job = job;
        job->running++;
        if (pthread_create(&workers[i].thread, NULL, worker_main, &workers[i]) != 0) {
            job->running--;
            break;
        }
        started++;
    }
    if (started == 0) {
        /* no threads could be started: render on this one */
        job->running = 1;
        pthread_mutex_unlock(&job->lock);
        workers[0].job = job;
        worker_main(&workers[0]);
        return 0;
    }
    while (job->running > 0) {
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        ts.tv_nsec += 50 * 1000 * 1000;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&job->done, &job->lock, &ts);
        if (job->running > 0 && opt->progress && rt_now_seconds() - t0 >= progress->elapsed + 0.045) {
            pthread_mutex_unlock(&job->lock);
            progress->tiles_done = atomic_load(&job->tiles_done);
            progress->elapsed = rt_now_seconds() - t0;
            opt->progress(progress, opt->progress_user);
            pthread_mutex_lock(&job->lock);
        }
    }
    pthread_mutex_unlock(&job->lock);
    for (int i = 0; i < started; i++)
        pthread_join(workers[i].thread, NULL);
    return started;
}

/* fb = the accumulated samples of every pixel. */
static void resolve_image(rt_render_job *job)
{
    size_t n = (size_t)job->rw * (size_t)job->rh;
    for (size_t k = 0; k < n; k++) {
        pixel_sum p = {load3(job->sum + 3 * k), load3(job->block + 3 * k), job->good[k]};
        rt_vec3 sum = pixel_total(&p);
        if (job->aov)
            rt_aov_resolve(job->aov, k, &job->aov_sum[k], p.good, rt_luminance(sum), job->lum_sq[k]);
        rt_vec3 v = rt_sample_resolve(sum, p.good);
        float *px = job->fb->rgb + 3 * k;
        px[0] = v.x;
        px[1] = v.y;
        px[2] = v.z;
    }
}

static void free_job(rt_render_job *job, worker *workers, int nthreads)
{
    for (int i = 0; workers && i < nthreads; i++) {
        rt_wavefront_free(workers[i].wf);
        free(workers[i].wf_out);
    }
    free(job->tile_finished);
    free(job->sum);
    free(job->block);
    free(job->good);
    free(job->aov_sum);
    free(job->lum_sq);
    free(workers);
}

/* The request checked: the region (the whole image when zero) inside the
 * image, fb its size, the caller's sums complete, the integrator known. */
static rt_result check_request(const rt_settings *set, const rt_render_options *opt, const rt_framebuffer *fb,
                               rt_render_region *region, const rt_integrator_info **integrator, rt_error *err)
{
    rt_render_region reg = opt->region;
    if (reg.x0 == 0 && reg.y0 == 0 && reg.x1 == 0 && reg.y1 == 0)
        reg = (rt_render_region){0, 0, set->width, set->height};
    if (reg.x0 < 0 || reg.y0 < 0 || reg.x1 > set->width || reg.y1 > set->height || reg.x0 >= reg.x1 ||
        reg.y0 >= reg.y1)
        return rt_fail(err, RT_ERR_INVALID, "region [%d, %d) x [%d, %d) is not inside the %dx%d image", reg.x0,
                       reg.x1, reg.y0, reg.y1, set->width, set->height);
    if (fb->width != reg.x1 - reg.x0 || fb->height != reg.y1 - reg.y0 || !fb->rgb)
        return rt_fail(err, RT_ERR_INVALID, "framebuffer is %dx%d but the region rendered is %dx%d", fb->width,
                       fb->height, reg.x1 - reg.x0, reg.y1 - reg.y0);
    if (opt->accum && (!opt->accum->sum || !opt->accum->block || !opt->accum->good ||
                       (opt->accum->kept && (opt->accum->kept_first < 0 || opt->accum->kept_count < 0))))
        return rt_fail(err, RT_ERR_INVALID, "the caller's sums (opt.accum) need sum, block and good arrays");
    *integrator = rt_integrator_info_of(set->integrator);
    if (!*integrator)
        return rt_fail(err, RT_ERR_INVALID, "integrator %d is not one of the %zu rt knows", (int)set->integrator,
                       rt_integrator_count());
    *region = reg;
    return RT_OK;
}

/* The job's plan: samples, region, camera, tiles; *pass_samples is the
 * samples a pass (<= 0: tiles). */
static rt_result plan_job(rt_render_job *job, const rt_scene *scene, const rt_settings *set,
                          const rt_render_options *opt, rt_render_region reg, const rt_integrator_info *integrator,
                          rt_framebuffer *fb, int *pass_samples, rt_error *err)
{
    memset(job, 0, sizeof *job);
    job->scene = scene;
    job->settings = set;
    job->fb = fb;
    job->cancel = opt->cancel;
    job->spp = set->samples > 0 ? (uint32_t)set->samples : 1;
    job->s_begin = (uint32_t)(opt->sample_begin > 0 ? opt->sample_begin : 0);
    job->s_end = opt->sample_end > 0 ? (uint32_t)opt->sample_end : job->spp;
    if (job->s_end > job->spp || job->s_begin >= job->s_end)
        return rt_fail(err, RT_ERR_INVALID, "sample range %u:%u is not inside the %u samples per pixel",
                       job->s_begin, job->s_end, job->spp);
    job->width = set->width;
    job->height = set->height;
    job->rx0 = reg.x0;
    job->ry0 = reg.y0;
    job->rw = reg.x1 - reg.x0;
    job->rh = reg.y1 - reg.y0;
    job->accum = opt->accum;
    *pass_samples = opt->pass_samples != 0 ? opt->pass_samples : integrator->pass_samples;
    job->passes = *pass_samples > 0;
    rt_camera_frame_init(&job->camera, &scene->camera, set->width, set->height);
    if (integrator->film_sampler)
        job->camera.sampler = (rt_sampler_kind)set->sampler; /* the path tracer's film and lens: its sampler's */
    job->tile_size = opt->tile_size > 0 ? (opt->tile_size < 65536 ? opt->tile_size : 65536) : 32;
    job->tiles_x = (int)(((int64_t)job->rw + job->tile_size - 1) / job->tile_size);
    job->tiles_y = (int)(((int64_t)job->rh + job->tile_size - 1) / job->tile_size);
    if ((int64_t)job->tiles_x * job->tiles_y > (int64_t)(1 << 26))
        return rt_fail(err, RT_ERR_LIMIT, "%dx%d image in %d-pixel tiles makes %lld tiles, over the limit of %d; use larger tiles",
                       fb->width, fb->height, job->tile_size, (long long)job->tiles_x * job->tiles_y, 1 << 26);
    job->tiles_total = job->tiles_x * job->tiles_y;
    atomic_init(&job->next_tile, 0);
    atomic_init(&job->tiles_done, 0);
    atomic_init(&job->time_up, 0);
    job->aov = opt->aov;
    job->radiance = integrator->radiance;
    job->wavefront = integrator->wavefront;
    if (rt_scene_has_media(scene)) { /* participating media: the path tracer's volumetric form, one path at a time */
        if (integrator->radiance == rt_radiance_path) {
            job->radiance = rt_radiance_volpath;
            job->wavefront = false;
        } else {
            rt_warn("integrator %s ignores participating media and null boundaries (the path integrator renders "
                    "them)", integrator->name);
        }
    }
    job->batch_size = opt->batch_size > 0 ? opt->batch_size : 0;
    return RT_OK;
}

/* The job's buffers and the workers, the sums started from zero or from
 * the caller's. */
static rt_result alloc_job(rt_render_job *job, worker **workers_out, int nthreads, rt_error *err)
{
    rt_framebuffer *fb = job->fb;
    job->tile_finished = rt_alloc((size_t)job->tiles_total, sizeof *job->tile_finished);
    size_t npx = (size_t)fb->width * (size_t)fb->height;
    if (job->passes) {
        job->sum = rt_alloc(npx, 3 * sizeof *job->sum);
        job->block = rt_alloc(npx, 3 * sizeof *job->block);
        job->good = rt_alloc(npx, sizeof *job->good);
    }
    if (job->aov) {
        job->aov_sum = rt_alloc(npx, sizeof *job->aov_sum);
        job->lum_sq = rt_alloc(npx, sizeof *job->lum_sq);
    }
    worker *workers = rt_alloc((size_t)nthreads, sizeof *workers);
    *workers_out = workers;
    if (!job->tile_finished || !workers || (job->passes && (!job->sum || !job->block || !job->good)) ||
        (job->aov && (!job->aov_sum || !job->lum_sq))) {
        free_job(job, workers, nthreads);
        *workers_out = NULL;
        return rt_fail(err, RT_ERR_NOMEM, "out of memory setting up %d render threads for a %dx%d image", nthreads,
                       fb->width, fb->height);
    }
    for (int t = 0; t < job->tiles_total; t++)
        atomic_init(&job->tile_finished[t], 0);
    if (job->aov && job->accum && job->accum->aov_sum) /* the AOV sums continue the caller's too */
        memcpy(job->aov_sum, job->accum->aov_sum, npx * sizeof *job->aov_sum);
    if (job->passes) {
        if (job->accum) { /* continue the caller's sums; they get them back after each whole pass */
            memcpy(job->sum, job->accum->sum, npx * 3 * sizeof *job->sum);
            memcpy(job->block, job->accum->block, npx * 3 * sizeof *job->block);
            memcpy(job->good, job->accum->good, npx * sizeof *job->good);
        } else {
            memset(job->sum, 0, npx * 3 * sizeof *job->sum);
            memset(job->block, 0, npx * 3 * sizeof *job->block);
            memset(job->good, 0, npx * sizeof *job->good);
        }
        memset(fb->rgb, 0, npx * 3 * sizeof *fb->rgb);
    }
    return RT_OK;
}

/* Tiles: every tile once with all of its samples. Returns the threads
 * started; *cancelled when stopped by the cancel flag (not the time). */
static int render_tiles(rt_render_job *job, worker *workers, int nthreads, const rt_render_options *opt,
                        rt_render_progress *progress, double t0, rt_render_stats *st, bool *cancelled)
{
    rt_framebuffer *fb = job->fb;
    size_t npx = (size_t)fb->width * (size_t)fb->height;
    job->deadline = opt->time_limit > 0.0 ? t0 + opt->time_limit : 0.0;
    int started = run_workers(job, workers, nthreads, opt, progress, t0);
    if (job->aov && job->accum && job->accum->aov_sum)
        memcpy(job->accum->aov_sum, job->aov_sum, npx * sizeof *job->aov_sum);
    st->tiles_done = atomic_load(&job->tiles_done);
    st->partial = st->tiles_done < job->tiles_total;
    st->samples_done = st->partial ? 0 : (int)(job->s_end - job->s_begin);
    *cancelled = st->partial && !atomic_load(&job->time_up);
    st->time_limited = st->partial && !*cancelled;
    if (st->partial) {
        /* clear tiles that were started but not finished: a partial tile is worse than a black one */
        for (int t = 0; t < job->tiles_total; t++) {
            if (atomic_load(&job->tile_finished[t]))
                continue;
            int x0, y0, x1, y1;
            tile_bounds(job, t, &x0, &y0, &x1, &y1);
            for (int y = y0; y < y1; y++)
                memset(fb->rgb + 3 * ((size_t)y * (size_t)job->rw + (size_t)x0), 0,
                       3 * sizeof(float) * (size_t)(x1 - x0));
        }
    }
    return started;
}

/* Passes of pass_samples over the whole image, each resolved into fb and
 * handed back to the caller's sums when whole. Returns the most threads a
 * pass started; *cancelled as for render_tiles. */
static int render_passes(rt_render_job *job, worker *workers, int nthreads, const rt_render_options *opt,
                         rt_render_progress *progress, double t0, int pass_samples, rt_render_stats *st,
                         bool *cancelled)
{
    size_t npx = (size_t)job->fb->width * (size_t)job->fb->height;
    int started = 0;
    for (uint32_t s0 = job->s_begin; s0 < job->s_end;) {
        if (job->cancel && atomic_load(job->cancel)) {
            *cancelled = true;
            break;
        }
        job->s0 = s0;
        job->s1 = job->s_end - s0 > (uint32_t)pass_samples ? s0 + (uint32_t)pass_samples : job->s_end;
        progress->pass_samples = (int)(job->s1 - job->s0);
        int n = run_workers(job, workers, nthreads, opt, progress, t0);
        started = n > started ? n : started;
        if (atomic_load(&job->tiles_done) < job->tiles_total) {
            *cancelled = true; /* the pass was cut short: fb keeps the last whole pass */
            break;
        }
        resolve_image(job);
        if (job->accum) {
            memcpy(job->accum->sum, job->sum, npx * 3 * sizeof *job->sum);
            memcpy(job->accum->block, job->block, npx * 3 * sizeof *job->block);
            memcpy(job->accum->good, job->good, npx * sizeof *job->good);
        }
        if (job->aov && job->accum && job->accum->aov_sum)
            memcpy(job->accum->aov_sum, job->aov_sum, npx * sizeof *job->aov_sum);
        job->samples_done = (int)(job->s1 - job->s_begin);
        st->passes_done++;
        s0 = job->s1;
        if (opt->progress && s0 < job->s_end) {
            progress->tiles_done = job->tiles_total;
            progress->samples_done = job->samples_done;
            progress->elapsed = rt_now_seconds() - t0;
            opt->progress(progress, opt->progress_user);
        }
        if (opt->time_limit > 0.0 && s0 < job->s_end && rt_now_seconds() - t0 >= opt->time_limit) {
            st->time_limited = true;
            break;
        }
    }
    st->samples_done = job->samples_done;
    st->partial = job->samples_done == 0;
    st->tiles_done = st->partial ? 0 : job->tiles_total;
    return started;
}

rt_result rt_render(const rt_scene *scene, const rt_settings *settings, const rt_kdtree *tree,
                    const rt_render_options *options, rt_framebuffer *fb, rt_render_stats *stats, rt_error *err)
{
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    if (options)
        opt = *options;
    rt_render_stats st;
    memset(&st, 0, sizeof st);
    RT_DCHECK(rt_scene_validate(scene, NULL) == RT_OK);
    rt_render_region reg = {0, 0, 0, 0};
    const rt_integrator_info *integrator = NULL;
    rt_result r = check_request(settings, &opt, fb, &reg, &integrator, err);
    rt_render_job job;
    int pass_samples = 0;
    if (r != RT_OK || (r = plan_job(&job, scene, settings, &opt, reg, integrator, fb, &pass_samples, err)) != RT_OK)
        return r;
    int nthreads = opt.threads > 0 ? opt.threads : rt_cpu_count();
    if (nthreads > 1024)
        nthreads = 1024;
    worker *workers;
    if ((r = alloc_job(&job, &workers, nthreads, err)) != RT_OK)
        return r;
    /* what the integrator reads, derived once, before the workers start */
    rt_render_state state;
    if ((r = rt_render_state_prepare(&state, scene, settings, tree, integrator->prepare, err)) != RT_OK) {
        free_job(&job, workers, nthreads);
        return r;
    }
    job.state = &state;
    pthread_mutex_init(&job.lock, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&job.done, &ca);
    pthread_condattr_destroy(&ca);

    rt_render_progress progress;
    memset(&progress, 0, sizeof progress);
    progress.tiles_total = job.tiles_total;
    progress.passes = job.passes;
    progress.samples_total = (int)(job.s_end - job.s_begin);
    progress.fb = fb;
    progress.job = &job;

    double t0 = rt_now_seconds();
    bool cancelled = false;
    int started = job.passes ? render_passes(&job, workers, nthreads, &opt, &progress, t0, pass_samples, &st,
                                             &cancelled)
                             : render_tiles(&job, workers, nthreads, &opt, &progress, t0, &st, &cancelled);
    st.seconds = rt_now_seconds() - t0;
    st.tiles_total = job.tiles_total;
    st.threads = started > 0 ? started : 1;
    st.passes = job.passes;
    st.pass_samples = job.passes ? pass_samples : 0;
    st.interrupted = cancelled;
    for (int i = 0; i < nthreads; i++) {
        st.rays += workers[i].rays;
        st.camera_rays += workers[i].camera_rays;
        st.bad_samples += workers[i].bad_samples;
    }
    if (opt.progress) {
        progress.tiles_done = st.tiles_done;
        progress.samples_done = st.samples_done;
        progress.elapsed = st.seconds;
        progress.final = true;
        opt.progress(&progress, opt.progress_user);
    }
    pthread_cond_destroy(&job.done);
    pthread_mutex_destroy(&job.lock);
    free_job(&job, workers, nthreads);
    rt_render_state_free(&state);
    if (stats)
        *stats = st;
    if (st.interrupted) {
        if (st.passes)
            return rt_fail(err, RT_ERR_INTERRUPTED, "render interrupted: %d of %d samples per pixel done",
                           st.samples_done, (int)(job.s_end - job.s_begin));
        return rt_fail(err, RT_ERR_INTERRUPTED, "render interrupted: %d of %d tiles finished", st.tiles_done,
                       st.tiles_total);
    }
    return RT_OK;
}
