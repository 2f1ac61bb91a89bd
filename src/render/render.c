/* render.c - the tile queue and its worker threads, the pixel loop, and
 * progress reports to the caller (which draws them: src/driver/progress.c).
 *
 * Pixel estimate: the box-filtered average of `samples` radiance samples at
 * correlated multi-jittered positions in the pixel (Kensler 2013), so any
 * sample count is stratified. A sample that comes back NaN or infinite is
 * dropped and counted (it shows a bug, not light); the pixel averages the
 * rest. settings.clamp, when set, caps a sample's luminance.
 */
#include "rt/render/render.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rt/base/alloc.h"
#include "rt/base/log.h"
#include "rt/render/aov.h"
#include "rt/render/camera.h"
#include "rt/render/integrator.h"
#include "rt/render/sampling.h"
#include "rt/scene/validate.h"

int rt_cpu_count(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (n > 1024 ? 1024 : (int)n) : 1;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct rt_render_job {
    const rt_scene *scene;
    rt_framebuffer *fb;
    rt_camera_frame camera;
    int tile_size, tiles_x, tiles_y, tiles_total;
    atomic_int next_tile;
    atomic_int tiles_done;
    atomic_uchar *tile_finished; /* per tile: 1 once its pixels are final */
    atomic_int *cancel;
    const rt_render_state *state; /* prepared once, read by every worker */
    rt_radiance_fn radiance;      /* the scene's integrator */
    rt_aov_buffers *aov;          /* NULL = none */
};
typedef struct rt_render_job rt_render_job;

typedef struct worker {
    pthread_t thread;
    rt_render_job *job;
    uint64_t rays, camera_rays, bad_samples;
} worker;

/* The pixel's AOVs: means over its `good` samples; the variance of the mean
 * luminance from the sample variance, sum of L^2 - (sum L)^2 / n over n - 1. */
static void aov_store(rt_aov_buffers *aov, uint64_t pixel, const rt_aov_sample *s, uint32_t good, float lum_sum,
                      double lum_sq)
{
    float inv = good ? 1.0f / (float)good : 0.0f;
    const rt_vec3 *v3[3] = {&s->albedo, &s->normal, &s->position};
    float *dst3[3] = {aov->albedo, aov->normal, aov->position};
    for (int k = 0; k < 3; k++)
        if (dst3[k]) {
            dst3[k][3 * pixel] = v3[k]->x * inv;
            dst3[k][3 * pixel + 1] = v3[k]->y * inv;
            dst3[k][3 * pixel + 2] = v3[k]->z * inv;
        }
    if (aov->depth)
        aov->depth[pixel] = s->depth * inv;
    if (aov->spp)
        aov->spp[pixel] = (float)good;
    if (aov->variance) {
        double n = (double)good, var = 0.0;
        if (good > 1)
            var = (lum_sq - (double)lum_sum * (double)lum_sum / n) / (n - 1.0) / n;
        aov->variance[pixel] = (float)(var > 0.0 ? var : 0.0);
    }
}

/* Renders one tile; false when cancelled part-way (the tile then stays
 * unfinished and is cleared to black). The cancel flag is read once a
 * pixel, so Ctrl-C is answered within a pixel's samples, not a tile's. */
static bool render_tile(rt_render_job *job, worker *w, rt_trace_ctx *ctx, int tile)
{
    const rt_settings *st = &job->scene->settings;
    int tx = tile % job->tiles_x, ty = tile / job->tiles_x;
    int x0 = tx * job->tile_size, y0 = ty * job->tile_size;
    int x1 = x0 + job->tile_size, y1 = y0 + job->tile_size;
    if (x1 > job->fb->width) x1 = job->fb->width;
    if (y1 > job->fb->height) y1 = job->fb->height;
    uint32_t spp = st->samples > 0 ? (uint32_t)st->samples : 1;
    for (int y = y0; y < y1; y++) {
        for (int x = x0; x < x1; x++) {
            if (job->cancel && atomic_load_explicit(job->cancel, memory_order_relaxed))
                return false;
            uint64_t pixel = (uint64_t)y * (uint64_t)job->fb->width + (uint64_t)x;
            uint32_t pattern = (uint32_t)rt_mix64(pixel ^ ((uint64_t)st->seed << 40));
            rt_vec3 sum = rt_v3s(0);
            uint32_t good = 0;
            rt_aov_sample aov_sum = {rt_v3s(0), rt_v3s(0), rt_v3s(0), 0.0f};
            double lum_sq = 0.0;
            for (uint32_t s = 0; s < spp; s++) {
                rt_vec2 j = spp > 1 ? rt_cmj_sample(s, spp, pattern) : rt_v2(0.5f, 0.5f);
                rt_vec2 lens = rt_cmj_sample(s, spp, pattern ^ 0x68bc21ebu);
                rt_ray ray = rt_camera_ray(&job->camera, (float)x + j.x, (float)y + j.y, lens);
                rt_rng rng = rt_rng_for_sample(st->seed, pixel, s);
                w->camera_rays++;
                rt_vec3 L = job->radiance(ctx, &ray, &rng);
                if (!rt_finite3(L) || L.x < 0.0f || L.y < 0.0f || L.z < 0.0f) {
                    w->bad_samples++;
                    continue;
                }
                if (st->clamp > 0.0f) {
                    float lum = rt_luminance(L);
                    if (lum > st->clamp)
                        L = rt_scale(L, st->clamp / lum);
                }
                sum = rt_add(sum, L);
                good++;
                if (job->aov) { /* own random numbers: the image stays as it was */
                    rt_rng arng = rt_rng_for_sample(st->seed ^ 0xa0f5eed5u, pixel, s);
                    rt_aov_sample a;
                    rt_aov_trace(ctx, ray, &arng, &a);
                    aov_sum.albedo = rt_add(aov_sum.albedo, a.albedo);
                    aov_sum.normal = rt_add(aov_sum.normal, a.normal);
                    aov_sum.position = rt_add(aov_sum.position, a.position);
                    aov_sum.depth += a.depth;
                    lum_sq += (double)rt_luminance(L) * (double)rt_luminance(L);
                }
            }
            if (job->aov)
                aov_store(job->aov, pixel, &aov_sum, good, rt_luminance(sum), lum_sq);
            if (good)
                sum = rt_scale(sum, 1.0f / (float)good);
            float *px = job->fb->rgb + 3 * pixel;
            px[0] = sum.x;
            px[1] = sum.y;
            px[2] = sum.z;
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
    for (;;) {
        if (job->cancel && atomic_load(job->cancel))
            break;
        int tile = atomic_fetch_add(&job->next_tile, 1);
        if (tile >= job->tiles_total)
            break;
        if (!render_tile(job, w, &ctx, tile))
            break;
        atomic_store(&job->tile_finished[tile], 1);
        atomic_fetch_add(&job->tiles_done, 1);
    }
    return NULL;
}

rt_tile rt_render_progress_tile(const rt_render_progress *p, int index)
{
    const rt_render_job *job = p->job;
    rt_tile t;
    int tx = index % job->tiles_x, ty = index / job->tiles_x;
    t.x0 = tx * job->tile_size;
    t.y0 = ty * job->tile_size;
    t.x1 = t.x0 + job->tile_size < job->fb->width ? t.x0 + job->tile_size : job->fb->width;
    t.y1 = t.y0 + job->tile_size < job->fb->height ? t.y0 + job->tile_size : job->fb->height;
    t.finished = atomic_load(&job->tile_finished[index]) != 0;
    return t;
}

rt_result rt_render(const rt_scene *scene, const rt_kdtree *tree, const rt_render_options *options,
                    rt_framebuffer *fb, rt_render_stats *stats, rt_error *err)
{
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    if (options)
        opt = *options;
    rt_render_stats st;
    memset(&st, 0, sizeof st);
    const rt_settings *set = &scene->settings;
    RT_DCHECK(rt_scene_validate(scene, NULL) == RT_OK);
    if (fb->width != set->width || fb->height != set->height || !fb->rgb)
        return rt_fail(err, RT_ERR_INVALID, "framebuffer is %dx%d but the scene asks for %dx%d", fb->width,
                       fb->height, set->width, set->height);
    const rt_integrator_info *integrator = rt_integrator_info_of(set->integrator);
    if (!integrator)
        return rt_fail(err, RT_ERR_INVALID, "integrator %d is not one of the %zu rt knows", (int)set->integrator,
                       rt_integrator_count());

    rt_render_job job;
    memset(&job, 0, sizeof job);
    job.scene = scene;
    job.fb = fb;
    job.cancel = opt.cancel;
    rt_camera_frame_init(&job.camera, &scene->camera, fb->width, fb->height);
    job.tile_size = opt.tile_size > 0 ? (opt.tile_size < 65536 ? opt.tile_size : 65536) : 32;
    job.tiles_x = (int)(((int64_t)fb->width + job.tile_size - 1) / job.tile_size);
    job.tiles_y = (int)(((int64_t)fb->height + job.tile_size - 1) / job.tile_size);
    if ((int64_t)job.tiles_x * job.tiles_y > (int64_t)(1 << 26))
        return rt_fail(err, RT_ERR_LIMIT, "%dx%d image in %d-pixel tiles makes %lld tiles, over the limit of %d; use larger tiles",
                       fb->width, fb->height, job.tile_size, (long long)job.tiles_x * job.tiles_y, 1 << 26);
    job.tiles_total = job.tiles_x * job.tiles_y;
    atomic_init(&job.next_tile, 0);
    atomic_init(&job.tiles_done, 0);
    job.tile_finished = rt_alloc((size_t)job.tiles_total, sizeof *job.tile_finished);
    int nthreads = opt.threads > 0 ? opt.threads : rt_cpu_count();
    if (nthreads > 1024)
        nthreads = 1024;
    worker *workers = rt_alloc((size_t)nthreads, sizeof *workers);
    if (!job.tile_finished || !workers) {
        free(job.tile_finished);
        free(workers);
        return rt_fail(err, RT_ERR_NOMEM, "out of memory setting up %d render threads", nthreads);
    }
    for (int t = 0; t < job.tiles_total; t++)
        atomic_init(&job.tile_finished[t], 0);
    /* what the integrator reads, derived once, before the workers start */
    rt_render_state state;
    rt_result sr = rt_render_state_prepare(&state, scene, tree, integrator->prepare, err);
    if (sr != RT_OK) {
        free(job.tile_finished);
        free(workers);
        return sr;
    }
    job.state = &state;
    job.radiance = integrator->radiance;
    job.aov = options ? options->aov : NULL;

    double t0 = now_seconds();
    int started = 0;
    for (int i = 0; i < nthreads; i++) {
        workers[i].job = &job;
        if (pthread_create(&workers[i].thread, NULL, worker_main, &workers[i]) != 0)
            break;
        started++;
    }
    if (started < nthreads) /* out of memory for stacks, or a process limit: fewer threads, same image */
        rt_warn("could start only %d of %d render threads%s", started, nthreads,
                started ? "" : "; rendering on the main thread");
    if (started == 0) {
        /* no threads could be started: render on this one */
        workers[0].job = &job;
        worker_main(&workers[0]);
    }
    rt_render_progress progress;
    memset(&progress, 0, sizeof progress);
    progress.tiles_total = job.tiles_total;
    progress.fb = fb;
    progress.job = &job;
    if (started > 0) {
        while (atomic_load(&job.tiles_done) < job.tiles_total) {
            if (job.cancel && atomic_load(job.cancel))
                break;
            struct timespec ts = {0, 50 * 1000 * 1000};
            nanosleep(&ts, NULL);
            if (opt.progress) {
                progress.tiles_done = atomic_load(&job.tiles_done);
                progress.elapsed = now_seconds() - t0;
                opt.progress(&progress, opt.progress_user);
            }
        }
        for (int i = 0; i < started; i++)
            pthread_join(workers[i].thread, NULL);
    }
    st.seconds = now_seconds() - t0;
    st.tiles_total = job.tiles_total;
    st.tiles_done = atomic_load(&job.tiles_done);
    st.threads = started > 0 ? started : 1;
    for (int i = 0; i < nthreads; i++) {
        st.rays += workers[i].rays;
        st.camera_rays += workers[i].camera_rays;
        st.bad_samples += workers[i].bad_samples;
    }
    if (opt.progress) {
        progress.tiles_done = st.tiles_done;
        progress.elapsed = st.seconds;
        progress.final = true;
        opt.progress(&progress, opt.progress_user);
    }
    st.interrupted = st.tiles_done < job.tiles_total;
    if (st.interrupted) {
        /* clear tiles that were started but not finished: a partial tile is worse than a black one */
        for (int t = 0; t < job.tiles_total; t++) {
            if (atomic_load(&job.tile_finished[t]))
                continue;
            int tx = t % job.tiles_x, ty = t / job.tiles_x;
            for (int y = ty * job.tile_size; y < (ty + 1) * job.tile_size && y < fb->height; y++)
                for (int x = tx * job.tile_size; x < (tx + 1) * job.tile_size && x < fb->width; x++)
                    memset(fb->rgb + 3 * ((size_t)y * (size_t)fb->width + (size_t)x), 0, 3 * sizeof(float));
        }
    }
    free(job.tile_finished);
    free(workers);
    rt_render_state_free(&state);
    if (stats)
        *stats = st;
    if (st.interrupted)
        return rt_fail(err, RT_ERR_INTERRUPTED, "render interrupted: %d of %d tiles finished", st.tiles_done,
                       st.tiles_total);
    return RT_OK;
}
