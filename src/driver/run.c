/* run.c - one render of the `rt` command, from a prepared scene to its
 * files and exit status (run.h): the kd-tree, the job's part plan
 * (rt/job/part_job.h), the framebuffer and AOV images, the progress line,
 * the tev stream and the window (the driver's watchers, fed by the
 * renderer's progress callback), the render itself (motion-blur slices
 * through rt/job/slices.h; with --window again at each new camera), and
 * the result written where it belongs: a part, the output, or
 * NAME.partial.EXT for an incomplete tiled image or a stopped frame of
 * --frames (with its part, rt_job_options.stop_part). */
#include "run.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "memory_budget.h"
#include "prepare.h"
#include "progress.h"
#include "rt/accel/kdtree.h"
#include "rt/base/clock.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/image/tonemap.h"
#include "rt/job/motion.h"
#include "rt/job/output.h"
#include "rt/job/part_job.h"
#include "rt/job/slices.h"
#include "rt/render/camera_control.h"
#include "rt/render/render.h"
#include "tev.h"
#include "viewer.h"
#include "window.h"

/* One render's state: what it renders, what it holds (freed by run_free). */
typedef struct run {
    const args *a;
    rt_job_options jo;
    rt_scene *scene;
    const rt_settings *settings; /* how to render it: the render's own (run_one's) */
    const char *output;
    progress_view *view;
    double t_start;
    const run_signals *sig;
    rt_kdtree tree;
    rt_part_job pj;
    rt_framebuffer fb;
    rt_job_aovs aov;
    window_view window;
    tev_stream tev;
    viewer session;
    rt_render_options ro;
    rt_render_stats rs;
    rt_kdtree_kept *kept; /* objects' trees shared with earlier frames and the motion slices; NULL: none */
    bool have_tree, have_pj, have_fb, have_aov;
} run;

/* A frame finished and written to output: the image and part an earlier
 * stop of it left (NAME.partial.EXT, and NAME.part.exr with its sidecar
 * when it keeps one) are stale now, and would be taken for a stopped
 * frame; removed. */
static void remove_stopped(const char *output, const char *stop_part)
{
    char p[1100];
    if (rt_path_tagged(output, "partial", NULL, p, sizeof p))
        unlink(p);
    if (!stop_part)
        return;
    snprintf(p, sizeof p, "%s.json", stop_part);
    unlink(p); /* the sidecar first: a part without one is no part */
    unlink(stop_part);
}

/* What a result's files are, said once they are all in place. */
enum { SAID_MAIN, SAID_PART_OUT, SAID_STOP_PART, SAID_COUNT };
typedef char said_lines[SAID_COUNT][4600];

/* write_result for an image, into the batch: the output, or
 * NAME.partial.EXT for an incomplete tiled image or a stopped frame; what
 * to say once the batch is placed goes into said; 2 on an error, else 0.
 * A frame stopped early is not the finished frame: its image goes to
 * NAME.partial.EXT and its sums to the part that resumes it (stop_part);
 * *finished_frame says that a frame was finished, whose stop leftovers the
 * caller removes once the batch is placed. */
static int write_image(run *rn, bool stopped, const char *reason, const char *why, rt_write_batch *batch,
                       said_lines said, bool *finished_frame, rt_error *err)
{
    const args *a = rn->a;
    const rt_settings *set = rn->settings;
    const rt_part_job *pj = &rn->pj;
    const rt_framebuffer *fb = &rn->fb;
    const char *output = rn->output, *stop_part = rn->jo.stop_part;
    const rt_render_stats rs = rn->rs;
    char partial[1100], what[160], kept[1200];
    const char *target = output;
    bool frame = a->has_frames; /* (an image: a part output is write_result's) */
    /* what the output holds when the result goes elsewhere: --preview has written over it */
    snprintf(kept, sizeof kept, rn->view->previews > 0 ? "%s holds the last live preview (--preview)" : "%s left as it was",
             output);
    bool to_side = rs.partial || (frame && stopped);
    if (to_side) {
        rt_path_tagged(output, "partial", NULL, partial, sizeof partial); /* where an incomplete image goes */
        target = partial;
    }
    if (rs.partial)
        snprintf(what, sizeof what, "%d of %d tiles at %d spp%s", rs.tiles_done, rs.tiles_total, set->samples, why);
    else
        snprintf(what, sizeof what, "%d of %d spp%s", pj->s_begin + rs.samples_done, set->samples, why);
    if (rs.partial && rs.tiles_done == 0) {
        fprintf(stderr, "rt: stopped before any %s finished (%s); nothing written, %s\n",
                rs.passes ? "pass" : "tile", reason ? reason : "?", kept);
        return 0;
    }
    if (rt_job_output_write(&rn->jo, set, &rn->fb, &rn->aov, target, batch, err) != RT_OK ||
        (to_side && !rs.partial && stop_part &&
         rt_part_job_write(pj, stop_part, rs.samples_done, batch, err) != RT_OK))
        return 2;
    if (a->log_level >= RT_LOG_NORMAL || stopped) {
        char extras[2048]; /* the AOV files (or layers) too */
        rt_job_output_extras(&rn->jo, &rn->aov, target, extras, sizeof extras);
        snprintf(said[SAID_MAIN], sizeof said[0], "rt: wrote %s%s: %dx%d, %s; %.2f s (render %.2f s)%s%s\n", target,
                 extras, fb->width, fb->height, what, rt_now_seconds() - rn->t_start, rs.seconds, to_side ? "; " : "",
                 to_side ? kept : "");
    }
    if (to_side && stop_part)
        snprintf(said[SAID_STOP_PART], sizeof said[0],
                 "rt: wrote %s and %s.json: the frame's samples 0:%d of %d, resumed by rendering the frame again\n",
                 stop_part, stop_part, pj->s_begin + rs.samples_done, set->samples);
    *finished_frame = frame && !to_side;
    return 0;
}

/* Writes a render's result (rt_render returned r with stats rs) where its
 * state says: a part (pj->to_part), or the image (write_image), and
 * --part-out's part, all as one batch: none replaces an earlier file unless
 * every one was written; says so; returns the exit status (128 + the
 * signal that stopped it, 2 on an error, else 0: also when the window was
 * closed). */
static int write_result(run *rn, rt_result r, rt_error *err)
{
    const args *a = rn->a;
    const rt_settings *set = rn->settings;
    const rt_part_job *pj = &rn->pj;
    const char *output = rn->output;
    progress_view *view = rn->view;
    const rt_render_stats rs = rn->rs;
    int status = 0;
    progress_clear(view); /* the lines below start on a line of their own */
    if (r != RT_OK && r != RT_ERR_INTERRUPTED) {
        memory_budget_report(err, &a->budget);
        return 2;
    }
    int sig = atomic_load(rn->sig->interrupted);
    if (r == RT_ERR_INTERRUPTED && sig)
        status = 128 + sig;
    const char *reason = r != RT_ERR_INTERRUPTED ? (rs.time_limited ? "time limit" : NULL)
                         : sig == SIGTERM        ? "terminated"
                         : sig                   ? "interrupted"
                                                 : "window closed";
    char why[32] = "";
    if (reason)
        snprintf(why, sizeof why, ", %s", reason);
    bool stopped = r == RT_ERR_INTERRUPTED || rs.time_limited;
    said_lines said = {"", "", ""};
    bool finished_frame = false;
    rt_write_batch batch;
    rt_write_batch_init(&batch, rn->sig->temp);
    if (pj->to_part) {
        if (rs.partial) {
            fprintf(stderr, "rt: stopped before any %s finished (%s); no part written, %s left as it was%s\n",
                    rs.passes ? "pass" : "tile", reason ? reason : "?", output,
                    rs.passes ? "" : " (a tiled part keeps nothing when stopped: render parts in --passes N)");
        } else if (rt_part_job_write(pj, output, rs.samples_done, &batch, err) != RT_OK) {
            status = 2;
        } else if (a->log_level >= RT_LOG_NORMAL || stopped) {
            snprintf(said[SAID_MAIN], sizeof said[0],
                     "rt: wrote %s and %s.json: part [%d, %d) x [%d, %d) of %dx%d, samples %d:%d of %d%s; "
                     "%.2f s (render %.2f s)\n",
                     output, output, pj->region.x0, pj->region.x1, pj->region.y0, pj->region.y1, set->width,
                     set->height, pj->part_begin, pj->s_begin + rs.samples_done, set->samples, why,
                     rt_now_seconds() - rn->t_start, rs.seconds);
        }
    } else if (write_image(rn, stopped, reason, why, &batch, said, &finished_frame, err) != 0) {
        status = 2;
    }
    if (status != 2 && a->part_out) {
        if (rs.partial)
            fprintf(stderr, "rt: %s: no part written: %s\n", a->part_out,
                    rs.passes ? "no pass finished"
                              : "a render in tiles keeps no part when stopped (--passes 0 asked for tiles)");
        else if (rt_part_job_write(pj, a->part_out, rs.samples_done, &batch, err) != RT_OK)
            status = 2;
        else if (a->log_level >= RT_LOG_NORMAL || stopped)
            snprintf(said[SAID_PART_OUT], sizeof said[0], "rt: wrote %s and %s.json: samples %d:%d of %d\n",
                     a->part_out, a->part_out, pj->part_begin, pj->s_begin + rs.samples_done, set->samples);
    }
    if (status == 2)
        rt_write_batch_discard(&batch);
    else if (rt_write_batch_commit(&batch, err) != RT_OK)
        status = 2;
    if (status == 2) {
        memory_budget_report(err, &a->budget);
        return 2;
    }
    if (finished_frame)
        remove_stopped(output, rn->jo.stop_part); /* what a stop of this frame left */
    for (int k = 0; k < SAID_COUNT; k++)
        fputs(said[k], stderr);
    return status;
}

static void run_free(run *rn)
{
    progress_view *view = rn->view;
    if (view->tev)
        tev_stream_close(&rn->tev);
    view->tev = NULL;
    if (view->window)
        window_close(&rn->window);
    view->window = NULL;
    view->viewer = NULL;
    if (rn->have_aov)
        rt_job_aovs_free(&rn->aov);
    if (rn->have_fb)
        rt_framebuffer_free(&rn->fb);
    if (rn->have_pj)
        rt_part_job_free(&rn->pj); /* also whatever a failed --resume had taken from its part */
    if (rn->have_tree)
        rt_kdtree_free(&rn->tree);
}

/* A failure before rendering: the progress line cleared, err said; 2. */
static int run_failed(run *rn, rt_error *err)
{
    progress_clear(rn->view);
    memory_budget_report(err, &rn->a->budget);
    return 2;
}

/* A part output that is not a part's format, or AOVs in a part that is not
 * .exr: the message; 2. Else 0. */
static int check_part_outputs(run *rn)
{
    const rt_part_job *pj = &rn->pj;
    const char *output = rn->output;
    if (pj->to_part && !rt_part_path_ok(output)) {
        progress_clear(rn->view);
        fprintf(stderr, "rt: %s: a part is written as .exr or .pfm (with %s.json beside it), not as an 8-bit image\n",
                output, output);
        return 2;
    }
    const char *part_out = rn->a->part_out;
    const char *aov_part = pj->info.layer_count == 0                            ? NULL
                           : pj->to_part && !rt_path_has_ext(output, ".exr")    ? output
                           : part_out && !rt_path_has_ext(part_out, ".exr")      ? part_out
                                                                                 : NULL;
    if (aov_part) {
        progress_clear(rn->view);
        fprintf(stderr, "rt: %s: a part with AOVs is written as .exr (their sums are layers of it)\n", aov_part);
        return 2;
    }
    return 0;
}

/* The kd-tree, the part plan, the framebuffer, the AOV images and the
 * window; 0, or 2 with the message said. */
static int run_setup(run *rn)
{
    const args *a = rn->a;
    rt_error err = {0};
    char prims[64];
    snprintf(prims, sizeof prims, "(%zu primitives)", rt_scene_prim_count(rn->scene));
    progress_phase(rn->view, "kd-tree", prims);
    rt_kdtree_params par = {0};
    par.kept = rn->kept;
    size_t built0 = rn->kept ? rn->kept->built : 0, taken0 = rn->kept ? rn->kept->taken : 0;
    if (rt_kdtree_build(&rn->tree, rn->scene, &par, &err) != RT_OK)
        return run_failed(rn, &err);
    rn->have_tree = true;
    const rt_kdtree_stats *ts = &rn->tree.stats;
    rt_info("kd-tree: built in %.1f ms: %zu nodes, %zu leaves (%zu empty), %zu references, depth %d; "
            "%zu 64-byte nodes of 3 levels, %.1f MiB",
            ts->build_ms, ts->nodes, ts->leaves, ts->empty_leaves, ts->prim_refs, ts->depth, ts->wide_nodes,
            (double)ts->bytes / (1024.0 * 1024.0));
    if (rn->tree.object_count)
        rt_info("kd-tree: objects' trees: %zu built, %zu kept from earlier builds",
                rn->kept ? rn->kept->built - built0 : rn->tree.object_count, rn->kept ? rn->kept->taken - taken0 : 0);
    rn->have_pj = true;
    if (rt_part_job_init(&rn->pj, &rn->jo, rn->scene, rn->settings, &rn->tree, &err) != RT_OK)
        return run_failed(rn, &err);
    if (check_part_outputs(rn) != 0)
        return 2;
    const rt_part_job *pj = &rn->pj;
    if (pj->to_part)
        rt_info("part: pixels [%d, %d) x [%d, %d), samples %d:%d", pj->region.x0, pj->region.x1, pj->region.y0,
                pj->region.y1, pj->s_begin, pj->s_end);
    if (rt_framebuffer_init(&rn->fb, pj->region.x1 - pj->region.x0, pj->region.y1 - pj->region.y0, &err) != RT_OK)
        return run_failed(rn, &err);
    rn->have_fb = true;
    if (rt_job_aovs_init(&rn->aov, &rn->jo, rn->fb.width, rn->fb.height, &err) != RT_OK)
        return run_failed(rn, &err);
    rn->have_aov = true;
    if (a->window) {
        char why[512], title[1100];
        progress_phase(rn->view, "window", NULL); /* SDL takes a while to start: not the kd-tree's time */
        snprintf(title, sizeof title, "rt: %s", rn->output);
        if (!window_open(&rn->window, rn->fb.width, rn->fb.height, title, why, sizeof why)) {
            progress_clear(rn->view);
            fprintf(stderr, "rt: --window: cannot open a window: %s\n", why);
            return 2;
        }
        rn->view->window = &rn->window;
    }
    return 0;
}

/* Ctrl-C and SIGTERM from here on stop the render; the progress line, the
 * live preview and the tev stream set up. */
static void run_watch(run *rn)
{
    const args *a = rn->a;
    progress_view *view = rn->view;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = rn->sig->handler;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    bool to_part = rn->pj.to_part;
    view->preview_path = a->preview_seconds > 0.0 && !to_part ? rn->output : NULL;
    if (a->preview_seconds > 0.0 && to_part)
        rt_warn("--preview: a part's output holds sums, not an image; no preview is written");
    view->preview_seconds = a->preview_seconds;
    view->exposure = rn->settings->exposure;
    view->time_limit = a->time_limit;
    view->temp = rn->sig->temp;
    if (a->display_server) {
        const char *base = strrchr(rn->output, '/');
        rt_image_layer layers[RT_AOV_COUNT];
        int nl = rt_job_aovs_layers(&rn->aov, layers, RT_AOV_COUNT); /* --aov: extra layers in tev */
        tev_stream_open(&rn->tev, a->display_server, base ? base + 1 : rn->output, rn->fb.width, rn->fb.height,
                        layers, nl);
        view->tev = &rn->tev;
    }
}

/* True when the camera's look_at is only a direction: a glTF camera's
 * point 1 unit ahead (rt_gltf), not moved by --look-at. The window then
 * orbits about the model's depth instead (rt_camera_depth). */
static bool look_at_means_nothing(const run *rn)
{
    const rt_scene *scene = rn->scene;
    if (rn->jo.has_look_at)
        return false;
    for (size_t k = 0; k < scene->camera_count; k++)
        if (memcmp(&scene->cameras[k].look_at, &scene->camera.look_at, sizeof scene->camera.look_at) == 0)
            return true;
    return false;
}

/* The render's options from the flags and the part plan; the window's
 * viewer session. */
static void run_options(run *rn)
{
    const args *a = rn->a;
    const rt_scene *scene = rn->scene;
    const rt_settings *set = rn->settings;
    progress_view *view = rn->view;
    rt_render_options *ro = &rn->ro;
    memset(ro, 0, sizeof *ro);
    ro->threads = a->threads;
    ro->tile_size = a->tile;
    /* a time limit renders in passes with every integrator, so that it
     * leaves a whole image at the samples reached (tiles would leave some
     * finished and the rest black) */
    ro->pass_samples = rt_job_pass_samples(a->pass_samples, rn->pj.need_accum || a->time_limit > 0.0, set->integrator);
    ro->time_limit = a->time_limit;
    ro->cancel = rn->sig->stop;
    ro->progress = view->bar || view->preview_path || view->tev || view->window ? progress_report : NULL;
    ro->progress_user = view;
    ro->aov = rt_job_aovs_for_render(&rn->aov);
    ro->region = rn->pj.region;
    ro->sample_begin = rn->pj.s_begin;
    ro->sample_end = rn->pj.s_end;
    ro->accum = rn->pj.need_accum ? &rn->pj.accum : NULL;
    /* depth of field and motion blur (an open shutter) blur albedo and normal with noise */
    rn->aov.noisy_aux = scene->camera.aperture > 0.0f || scene->camera.shutter_close > scene->camera.shutter_open;
    memset(&rn->rs, 0, sizeof rn->rs);
    rn->session = (viewer){.window = &rn->window, .cancel = rn->sig->stop, .output = rn->output,
                           .image = {.exposure = set->exposure * rt_exposure_scale(a->exposure_ev),
                                     .tonemap = a->tonemap, .half = a->half},
                           .temp = rn->sig->temp, .samples_total = set->samples};
    if (a->window) {
        rt_box b = rt_scene_bounds(scene);
        float diag = rt_box_diagonal(b), d = rt_length(rt_sub(scene->camera.look_at, scene->camera.position));
        rn->window.exposure = rn->session.image.exposure;
        rn->window.tonemap = a->tonemap;
        window_set_camera(&rn->window, &scene->camera, isfinite(diag) && diag > 0.0f ? 0.02f * diag : 0.05f * d,
                          look_at_means_nothing(rn) ? rt_camera_depth(&scene->camera, scene, &rn->tree) : 0.0f);
        rn->window.interactive = !rn->pj.need_accum; /* kept sums (a part, --part-out, --resume): the camera stays */
        view->viewer = &rn->session;
    }
}

/* What the job's motion slices (rt/job/slices.h) ask the driver: a slice's
 * scene loaded and prepared from the flags at its time, and the progress
 * line told of each slice. */
static rt_result load_slice(void *user, rt_scene *slice, float time, rt_error *err)
{
    const run *rn = user;
    args ak = *rn->a;
    ak.posed = true;
    ak.frame_time = time;
    char out[1024];
    bool animated = false;
    rt_settings settings; /* the same as the render's: the slices render with rn->settings */
    rt_settings_default(&settings);
    return prepare_scene_again(slice, &settings, &ak, out, sizeof out, &animated, err);
}

static void slice_loading(void *user, int k, int slices, float time)
{
    char detail[64];
    snprintf(detail, sizeof detail, "slice %d of %d, t = %g s", k + 1, slices, (double)time);
    progress_phase(((const run *)user)->view, "motion", detail);
}

static void slice_rendering(void *user, int tiles_total)
{
    progress_restart(((const run *)user)->view, tiles_total);
}

/* Motion blur: the slices into the job's sums, then the result written. */
static int run_slices(run *rn, int slices)
{
    const args *a = rn->a;
    rt_error err = {0};
    rt_part_job *pj = &rn->pj;
    if (!pj->need_accum && rt_part_job_accum(pj, rn->ro.aov != NULL, &err) != RT_OK) {
        progress_clear(rn->view);
        memory_budget_report(&err, &a->budget);
        return 2;
    }
    rn->ro.accum = &pj->accum;
    rt_job_slices plan = {.slices = slices, .frame_time = a->posed ? a->frame_time : 0.0f,
                          .s_begin = pj->s_begin, .s_end = pj->s_end, .pass_samples = rn->ro.pass_samples,
                          .time_limit = a->time_limit, .load = load_slice, .loading = slice_loading,
                          .rendering = slice_rendering, .user = rn, .kept = rn->kept};
    rt_result r = rt_job_render_slices(rn->scene, rn->settings, &rn->tree, &plan, &rn->ro, &rn->fb, &rn->rs, &err);
    return r == RT_ERR_NOMEM ? 2 : write_result(rn, r, &err);
}

/* One render, or with --window one a camera (a move cancels the render,
 * which starts again from sample 0, docs/watching.md); the result written. */
static int run_renders(run *rn)
{
    const args *a = rn->a;
    const run_signals *sig = rn->sig;
    rt_error err = {0};
    rt_scene shown = *rn->scene; /* the scene at the window's camera */
    bool written = false;
    rt_result r;
    int status = 0;
    for (;;) {
        r = rt_render(&shown, rn->settings, &rn->tree, &rn->ro, &rn->fb, &rn->rs, &err);
        if (!a->window || atomic_load(sig->interrupted) || (r != RT_OK && r != RT_ERR_INTERRUPTED))
            break;
        if (r == RT_OK) { /* finished (or the time limit): written now, then the window waits */
            status = write_result(rn, r, &err);
            written = true;
            if (status == 2 || !viewer_wait(&rn->session, &rn->fb, rn->rs.samples_done, sig->interrupted))
                break;
        } else if (!rn->session.moved) {
            break; /* the window was closed */
        }
        shown.camera = rn->window.camera;
        rn->session.moved = false;
        written = false;
        atomic_store(sig->stop, 0);
        if (atomic_load(sig->interrupted)) /* a signal since the check above */
            atomic_store(sig->stop, 1);
        progress_restart(rn->view, rn->rs.tiles_total);
        rt_info("window: the camera moved; rendering again from sample 0");
    }
    if (!written)
        status = write_result(rn, r, &err);
    return status;
}

/* Builds the kd-tree, renders (the signals stop the workers, as does
 * --time-limit; with --window, again at each new camera) and writes the
 * image; the exit status. t_start: when the run began, for the wall time in
 * the "wrote" line. */
static int render_and_write(rt_scene *scene, const rt_settings *settings, const args *a, int slices,
                            const char *output, progress_view *view, double t_start, const run_signals *sig,
                            rt_kdtree_kept *kept)
{
    run rn;
    memset(&rn, 0, sizeof rn);
    rn.a = a;
    rn.kept = kept;
    args_job_options(a, &rn.jo);
    rn.jo.stop_part = a->stop_part;
    rn.scene = scene;
    rn.settings = settings;
    rn.output = output;
    rn.view = view;
    rn.t_start = t_start;
    rn.sig = sig;
    int status = run_setup(&rn);
    if (status == 0) {
        run_watch(&rn);
        run_options(&rn);
        status = slices > 1 ? run_slices(&rn, slices) : run_renders(&rn);
        const rt_render_stats *rs = &rn.rs;
        rt_info("render: %.3f s on %d threads, %s, %llu camera rays, %llu rays, %.2f Mrays/s", rs->seconds,
                rs->threads, rs->passes ? "passes" : "tiles", (unsigned long long)rs->camera_rays,
                (unsigned long long)rs->rays, rs->seconds > 0 ? 1e-6 * (double)rs->rays / rs->seconds : 0.0);
        if (rs->bad_samples)
            rt_warn("%llu NaN/Inf samples were dropped", (unsigned long long)rs->bad_samples);
    }
    run_free(&rn);
    return status;
}

/* Loads, prepares (posed at a->frame_time when a->posed), renders and
 * writes one image (or part); the exit status. */
int run_one(rt_scene *scene, const args *a, double t_start, const run_signals *sig, rt_kdtree_kept *kept)
{
    rt_error err = {0};
    char output[1024];
    progress_view view;
    progress_view_init(&view, a->log_level >= RT_LOG_NORMAL && isatty(2));
    progress_phase(&view, "load", a->input ? a->input : "the built-in scene");
    bool animated = false;
    rt_settings settings; /* this render's: the scene file's, the model defaults, the flags */
    rt_settings_default(&settings);
    if (prepare_scene(scene, &settings, a, output, sizeof output, &animated, &err) != RT_OK) {
        progress_clear(&view);
        memory_budget_report(&err, &a->budget);
        progress_view_free(&view);
        return 2;
    }
    /* an open shutter over animated models: motion blur in time slices, the
     * first posed here at its time (a static scene renders as it is) */
    int slices = rt_motion_slices(&scene->camera, settings.motion_steps, settings.samples);
    if (slices && a->window) {
        rt_warn("--window shows the shutter's midpoint; motion blur is rendered without --window");
        slices = 1;
    }
    if (slices && (animated || !a->posed)) {
        args a0 = *a;
        a0.posed = true;
        a0.frame_time = (float)rt_motion_time(a->posed ? a->frame_time : 0.0f, &scene->camera, 0, slices);
        rt_scene s0; /* loaded again at slice 0's time, keeping the decoded images */
        rt_scene_init(&s0);
        rt_settings settings0;
        rt_settings_default(&settings0);
        size_t n = scene->image_count;
        if (!rt_scene_share_images(&s0, scene) ||
            prepare_scene_again(&s0, &settings0, &a0, output, sizeof output, &animated, &err) != RT_OK) {
            if (s0.image_count < n)
                rt_fail(&err, RT_ERR_NOMEM, "out of memory for the images of motion slice 1");
            rt_scene_free(&s0);
            progress_clear(&view);
            memory_budget_report(&err, &a->budget);
            progress_view_free(&view);
            return 2;
        }
        if (animated) {
            rt_scene_free(scene); /* s0 holds the images too */
            *scene = s0;
            settings = settings0;
        } else { /* nothing follows the time: the scene as first loaded, unblurred */
            rt_scene_free(&s0);
        }
        if (animated && slices > 1 && (a->aovs & ((1u << RT_AOV_VARIANCE) | (1u << RT_AOV_SPP)))) {
            progress_clear(&view);
            fprintf(stderr, "rt: --aov variance and spp are not kept over the slices of a motion-blurred render "
                            "(the camera's shutter is open over animated models)\n");
            progress_view_free(&view);
            return 2;
        }
    }
    /* motion slices share the objects' trees: each later slice builds only its top level */
    rt_kdtree_kept own;
    rt_kdtree_kept_init(&own);
    rt_kdtree_kept *share = kept ? kept : animated && slices > 1 ? &own : NULL;
    int status =
        render_and_write(scene, &settings, a, animated ? slices : 1, output, &view, t_start, sig, share);
    if (kept)
        rt_kdtree_kept_trim(kept); /* this frame's trees, for the next */
    rt_kdtree_kept_free(&own);
    progress_view_free(&view);
    return status;
}
