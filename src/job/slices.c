/* slices.c - a motion-blurred render as K renders over consecutive runs of
 * each pixel's samples into the same sums (rt/job/slices.h; the slices'
 * times and samples are rt/job/motion.h's). Slice 0 renders the scene and
 * kd-tree it is given; slice k > 0 is loaded by the caller at its time into
 * a scene that shares slice 0's decoded images, gets its own kd-tree, and
 * is freed after its samples; with plan->kept (rt_kdtree_kept) it takes
 * the objects' trees slice 0 built (instances moved by node animation
 * keep their objects), so a slice rebuilds only the top level. Every slice renders in passes (one pass of
 * all its samples where tiles were asked for): a stopped slice then has
 * every pixel at the same sample, which sums kept as a part can say. The
 * renderer and the kd-tree know nothing of time. */
#include "rt/job/slices.h"

#include <stdio.h>
#include <string.h>

#include "rt/base/clock.h"
#include "rt/base/log.h"
#include "rt/job/motion.h"
#include "rt/render/integrator.h"

int rt_job_pass_samples(int asked, bool may_stop, rt_integrator integrator)
{
    if (asked)
        return asked;
    if (may_stop && rt_integrator_info_of(integrator)->pass_samples <= 0)
        return 4;
    return 0;
}

/* Slice k's scene and tree: loaded at its time, sharing the images. */
static rt_result load_slice(rt_scene *scene, const rt_job_slices *plan, int k, rt_scene *sk, rt_kdtree *tk,
                            rt_error *err)
{
    float time = (float)rt_motion_time(plan->frame_time, &scene->camera, k, plan->slices);
    if (plan->loading)
        plan->loading(plan->user, k, plan->slices, time);
    rt_scene_init(sk);
    rt_result r = RT_OK;
    if (!rt_scene_share_images(sk, scene))
        r = rt_fail(err, RT_ERR_NOMEM, "out of memory for the images of motion slice %d", k + 1);
    else if ((r = plan->load(plan->user, sk, time, err)) == RT_OK) {
        rt_kdtree_params par = {0};
        par.kept = plan->kept; /* the objects' trees of slice 0: only the top level is built again */
        size_t built0 = plan->kept ? plan->kept->built : 0;
        if ((r = rt_kdtree_build(tk, sk, &par, err)) == RT_OK && tk->object_count)
            rt_info("motion: slice %d's tree built in %.1f ms; objects' trees: %zu built, %zu kept from earlier builds",
                    k + 1,
                    tk->stats.build_ms, plan->kept ? plan->kept->built - built0 : tk->object_count,
                    plan->kept ? tk->object_count - (plan->kept->built - built0) : 0);
    }
    if (r != RT_OK)
        rt_scene_free(sk);
    return r;
}

/* Adds slice statistics st (samples [b, ...)) to the run's. */
static void add_stats(rt_render_stats *rs, const rt_render_stats *st)
{
    rs->seconds += st->seconds;
    rs->rays += st->rays;
    rs->camera_rays += st->camera_rays;
    rs->bad_samples += st->bad_samples;
    rs->threads = st->threads;
    rs->passes = st->passes;
    rs->tiles_total = st->tiles_total;
    rs->tiles_done = st->tiles_done;
    rs->time_limited = st->time_limited;
}

rt_result rt_job_render_slices(rt_scene *scene, const rt_settings *settings, const rt_kdtree *tree,
                               const rt_job_slices *plan,
                               rt_render_options *ro, rt_framebuffer *fb, rt_render_stats *rs, rt_error *err)
{
    rt_result r = RT_OK;
    memset(rs, 0, sizeof *rs);
    double t0 = rt_now_seconds();
    int slices = plan->slices, done_to = plan->s_begin; /* samples [s_begin, done_to) are in the sums */
    for (int k = 0; k < slices && r == RT_OK; k++) {
        int b, e;
        rt_motion_samples(k, slices, settings->samples, &b, &e);
        b = b > plan->s_begin ? b : plan->s_begin;
        e = e < plan->s_end ? e : plan->s_end;
        if (b >= e)
            continue;
        rt_scene sk;
        rt_kdtree tk;
        bool own = k > 0;
        if (own) {
            if ((r = load_slice(scene, plan, k, &sk, &tk, err)) != RT_OK)
                break;
            if (plan->rendering)
                plan->rendering(plan->user, rs->tiles_total);
        }
        rt_render_stats st;
        memset(&st, 0, sizeof st);
        ro->sample_begin = b;
        ro->sample_end = e;
        int pass = plan->pass_samples;
        if (pass == 0)
            pass = rt_integrator_info_of(settings->integrator)->pass_samples;
        if (pass <= 0) /* tiles asked for: one pass of all the slice's samples */
            ro->pass_samples = e - b;
        if (plan->time_limit > 0.0) { /* what is left of it */
            ro->time_limit = plan->time_limit - (rt_now_seconds() - t0);
            if (ro->time_limit <= 0.0)
                ro->time_limit = 1e-9;
        }
        r = rt_render(own ? &sk : scene, settings, own ? &tk : tree, ro, fb, &st, err);
        rt_info("motion: slice %d of %d (t = %g s): samples %d:%d, %.3f s", k + 1, slices,
                rt_motion_time(plan->frame_time, &scene->camera, k, slices), b, e, st.seconds);
        if (own) {
            rt_kdtree_free(&tk);
            rt_scene_free(&sk);
        }
        add_stats(rs, &st);
        rs->partial = st.partial && done_to == plan->s_begin; /* nothing whole yet */
        done_to = st.partial ? b : b + st.samples_done;
        if (r == RT_OK && !st.time_limited && plan->time_limit > 0.0 && k + 1 < slices &&
            rt_now_seconds() - t0 >= plan->time_limit) /* a slice is a pass: stop after the one that crossed it */
            rs->time_limited = true;
        if (r == RT_OK && rs->time_limited)
            break;
    }
    rs->samples_done = done_to - plan->s_begin;
    return r;
}
