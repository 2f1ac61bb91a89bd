/* rt/job/slices.h - a motion-blurred render (rt/job/motion.h) as K renders
 * into the same sums: slice 0 with the scene and tree given, each later
 * slice loaded by the caller at its time (sharing slice 0's decoded images,
 * rt_scene_share_images), given its own kd-tree, rendered over its run of
 * samples, and freed; a stop (the cancel flag, the time limit) ends the run
 * at the samples reached.
 *
 *   rt_job_slices plan = {.slices = K, .frame_time = t, .s_begin = 0, .s_end = spp,
 *                         .load = load_at, .user = &mine};   // load_at(user, scene, time, err)
 *   ro.accum = &sums;                                        // the sums the slices share
 *   r = rt_job_render_slices(&scene, &settings, &tree, &plan, &ro, &fb, &stats, &err);
 */
#ifndef RT_JOB_SLICES_H
#define RT_JOB_SLICES_H

#include "rt/accel/kdtree.h"
#include "rt/base/error.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"

typedef struct rt_job_slices {
    int slices;         /* K, from rt_motion_slices */
    float frame_time;   /* the frame's time (0 when not posed) */
    int s_begin, s_end; /* the job's samples (a part's range) */
    int pass_samples;   /* rt_job_pass_samples' answer for the job (0: the integrator's) */
    double time_limit;  /* seconds for all slices; 0 = none */
    /* Loads and prepares slice k's scene at `time` into `slice` (which
     * already holds slice 0's images): the caller's loading (its settings
     * are the job's: every slice renders with `settings`). */
    rt_result (*load)(void *user, rt_scene *slice, float time, rt_error *err);
    /* Told when slice k (k > 0) starts loading, and when it starts
     * rendering with this many tiles; NULL = not told. */
    void (*loading)(void *user, int k, int slices, float time);
    void (*rendering)(void *user, int tiles_total);
    void *user;
    /* The objects' trees slice 0's tree was built with (rt_kdtree_kept):
     * later slices take them and rebuild only the top level; NULL: every
     * slice builds its whole tree. */
    rt_kdtree_kept *kept;
} rt_job_slices;

/* Samples a pass for rt_render_options.pass_samples (0: the integrator's
 * default; -1: tiles): `asked` when not 0; else a render that may stop
 * (it keeps sums: a part, a resumed part; or it has a time limit) goes in
 * passes of 4 even where the integrator would tile, so that a stop keeps
 * the passes it finished and a whole image (pixels are the same for any
 * pass split). */
int rt_job_pass_samples(int asked, bool may_stop, rt_integrator integrator);

/* Renders the slices with settings into ro->accum's sums (ro's sample range and pass
 * samples are set per slice); *rs sums the slices' statistics, samples_done
 * counting from plan->s_begin. */
rt_result rt_job_render_slices(rt_scene *scene, const rt_settings *settings, const rt_kdtree *tree,
                               const rt_job_slices *plan,
                               rt_render_options *ro, rt_framebuffer *fb, rt_render_stats *rs, rt_error *err);

#endif
