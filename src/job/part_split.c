/* part_split.c - cutting an image into N bands of similar cost for
 * `--part I/N` (rt/job/part_split.h, docs/farm.md).
 *
 * Cost estimate: the image is covered by a grid of square blocks (side B,
 * chosen so there are at most about 4096 blocks); in every block four
 * pixels (the centres of its quarters) trace one sample each with the
 * scene's own integrator (sample 0 of a 1-spp render, seeded as a render
 * is), and the block's cost is what the rays they traced cost, counted by
 * the trace context: 1 a ray, and HIT_COST more for a ray that found a
 * surface (a shading; rays that escape the scene are cheap, so counting
 * rays alone gives the band of an empty sky too little). Rays and hits,
 * not seconds: the count is the same on every
 * machine and every run, so each machine of a farm computes the same
 * bands without talking to the others. A row costs what its block row
 * costs. The bands are then cut at the rows where the running cost crosses
 * k/N of the total (integer arithmetic), each band kept at least one row
 * long. Bands of whole rows keep each part one rectangle.
 *
 * This takes one sample at ~16k pixels on one thread: for the path tracer
 * about as long as rendering a 128x128 image at 1 spp.
 */
#include "rt/job/part_split.h"

#include <stdint.h>
#include <stdlib.h>

#include "rt/base/alloc.h"
#include "rt/render/camera.h"
#include "rt/render/integrator.h"
#include "rt/render/render_state.h"
#include "rt/render/sampling.h"

#define MAX_BLOCKS 4096
/* What a ray that finds a surface costs on top of a ray (1): the surface's
 * shading and the deeper walk through the tree to it. Measured (CPU time
 * of the 4 parts, docs/farm.md): a sample of empty background ~0.14-0.16
 * us, a sample that hits ~0.8-0.9 us with its shadow rays, 5.6-5.9 times;
 * of 0, 2, 3, 4, 6 and 8, 4 kept the worst part nearest the mean over the
 * five scenes measured (a dense corner wants more, a direct-lit floor less). */
#define HIT_COST 4

/* Where a cut between bands goes: at row `want`, but after the previous
 * cut (every band at least one row) and leaving a row for each of the
 * `left` cuts still to come, this one included. */
static int place_cut(int want, int prev, int rows, int left)
{
    int cut = want < prev + 1 ? prev + 1 : want;
    return cut > rows - left ? rows - left : cut;
}

rt_result rt_part_split(const rt_scene *scene, const rt_kdtree *tree, int index, int count, rt_render_region *band,
                     rt_error *err)
{
    const rt_settings *set = &scene->settings;
    int W = set->width, H = set->height;
    if (count < 1 || index < 0 || index >= count)
        return rt_fail(err, RT_ERR_INVALID, "--part %d/%d: I counts from 0 to N - 1", index, count);
    if (count > H)
        return rt_fail(err, RT_ERR_INVALID, "--part %d/%d: the image has only %d rows, fewer than %d parts", index,
                       count, H, count);
    if (count == 1) {
        *band = (rt_render_region){0, 0, W, H};
        return RT_OK;
    }
    int B = 4;
    while ((int64_t)((W + B - 1) / B) * ((H + B - 1) / B) > MAX_BLOCKS)
        B *= 2;
    int by = (H + B - 1) / B, bx = (W + B - 1) / B;
    uint64_t *row_cost = rt_alloc((size_t)by, sizeof *row_cost);
    if (!row_cost)
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for the cost estimate of --part");
    const rt_integrator_info *integ = rt_integrator_info_of(set->integrator);
    rt_render_state state;
    rt_result r = integ ? rt_render_state_prepare(&state, scene, tree, integ->prepare, err)
                        : rt_fail(err, RT_ERR_INVALID, "unknown integrator");
    if (r != RT_OK) {
        free(row_cost);
        return r;
    }
    rt_camera_frame cam;
    rt_camera_frame_init(&cam, &scene->camera, W, H);
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &state);
    uint64_t rays = 0, hits = 0;
    ctx.ray_count = &rays;
    ctx.hit_count = &hits;
    for (int j = 0; j < by; j++) {
        uint64_t before = rays + HIT_COST * hits;
        for (int i = 0; i < bx; i++)
            for (int q = 0; q < 4; q++) {
                int x = i * B + (q & 1 ? 3 * B / 4 : B / 4), y = j * B + (q & 2 ? 3 * B / 4 : B / 4);
                x = x < W ? x : W - 1;
                y = y < H ? y : H - 1;
                uint64_t pixel = (uint64_t)y * (uint64_t)W + (uint64_t)x;
                rt_ray ray = rt_camera_ray(&cam, (float)x + 0.5f, (float)y + 0.5f, rt_v2(0.5f, 0.5f));
                rt_rng rng = rt_rng_for_sample(set->seed, pixel, 0);
                uint64_t at = rays;
                (void)integ->radiance(&ctx, &ray, &rng);
                if (rays == at)
                    rays++; /* an integrator that traced nothing: the sample still costs */
            }
        row_cost[j] = rays + HIT_COST * hits - before;
    }
    rt_render_state_free(&state);
    /* every image row costs its block row's cost */
    uint64_t total = 0;
    for (int y = 0; y < H; y++)
        total += row_cost[y / B];
    int start = 0, end = H;
    uint64_t run = 0;
    int cut_prev = 0, k = 1;
    for (int y = 0; y < H && k < count; y++) {
        run += row_cost[y / B];
        /* the cut after row y once the running cost reaches k/N of the total */
        while (k < count && run * (uint64_t)count >= total * (uint64_t)k) {
            int cut = place_cut(y + 1, cut_prev, H, count - k);
            if (k == index)
                start = cut;
            if (k == index + 1)
                end = cut;
            cut_prev = cut;
            k++;
        }
    }
    /* cuts the running cost never reached (a zero total): the last rows, one each */
    for (; k < count; k++) {
        int cut = place_cut(cut_prev + 1, cut_prev, H, count - k);
        if (k == index)
            start = cut;
        if (k == index + 1)
            end = cut;
        cut_prev = cut;
    }
    free(row_cost);
    *band = (rt_render_region){0, start, W, end};
    return RT_OK;
}
