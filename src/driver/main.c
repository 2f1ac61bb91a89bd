/* main.c - the `rt` command: the pipeline, one step a line. Parse the flags
 * (args.c), load the scene or model, validate it, apply the setting flags,
 * frame the camera and check the limits, build the kd-tree, render on all
 * cores (progress.c draws the progress bar and the live preview), write the
 * image. A part of a render spread over machines (--part, --crop,
 * --spp-range, --resume, --part-out: part.c, docs/farm.md) renders its
 * region and samples and writes its sums; `rt merge` (merge.c) puts parts
 * together. --frames A:B runs the whole pipeline once a frame, each posed
 * at its time (frames.c).
 * With --window the render loops: a move of the window's camera
 * (viewer.c) cancels it and it starts again at the new camera from sample
 * 0; a finished render is written at once, and closing the window
 * mid-render writes the image at the samples reached ("window closed").
 *
 * Exit status: 0 on success (also when --time-limit stopped the render),
 * 2 for bad input (flags, scene files, models, images, an unwritable
 * output), 128 + the signal when Ctrl-C (130) or SIGTERM (143) stopped it.
 * A render stopped early keeps what it has: in passes the whole image at
 * the samples reached goes to the output; a tiled render's finished tiles
 * go to NAME.partial.EXT, never over the output. A second signal ends the
 * process at once and removes the temporary file of a write under way.
 * Every failure says what and where on stderr, and never leaves a partial
 * file over an existing image. The process runs under a memory budget
 * (memory_budget.c).
 */
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rt/base/clock.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/render/camera.h"
#include "rt/image/tonemap.h"
#include "rt/accel/kdtree.h"
#include "rt/io/framebuffer.h"
#include "rt/io/load.h"
#include "rt/render/integrator.h"
#include "rt/render/limits.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"
#include "rt/render/settings.h"
#include "rt/scene/validate.h"

#include "args.h"
#include "commands.h"
#include "memory_budget.h"
#include "frames.h"
#include "info.h"
#include "input.h"
#include "rt/job/motion.h"
#include "rt/job/slices.h"
#include "rt/job/output.h"
#include "rt/job/part_job.h"
#include "progress.h"
#include "tev.h"
#include "viewer.h"
#include "window.h"

/* What the signal handler shares with the render: the first signal's
 * number, the render's cancel flag (raised by the first signal, and by
 * the window when its camera moves or it closes), and the temporary file
 * of an image write under way. */
static atomic_int interrupted;
static atomic_int render_stop;
static rt_write_temp write_temp;

static void on_signal(int sig)
{
    int expected = 0;
    if (atomic_compare_exchange_strong(&interrupted, &expected, sig)) {
        atomic_store(&render_stop, 1);
    } else {
        /* the second signal: leave at once, leaving no temporary file */
        if (write_temp.active)
            unlink(write_temp.path);
        signal(sig, SIG_DFL);
        raise(sig);
    }
}

/* --look-from, --look-at, --up, --fov over the file's or the framed camera;
 * a camera they leave degenerate is an error naming them. */
static rt_result apply_pose_flags(rt_scene *scene, const args *a, rt_error *err)
{
    if (!a->has_look_from && !a->has_look_at && !a->has_up && !a->has_fov)
        return RT_OK;
    rt_camera *c = &scene->camera;
    char given[512] = "", v[128];
    if (a->has_look_from) {
        snprintf(v, sizeof v, " --look-from %g,%g,%g", a->look_from.x, a->look_from.y, a->look_from.z);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_look_at) {
        snprintf(v, sizeof v, " --look-at %g,%g,%g", a->look_at.x, a->look_at.y, a->look_at.z);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_up) {
        snprintf(v, sizeof v, " --up %g,%g,%g", a->up.x, a->up.y, a->up.z);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_fov) {
        snprintf(v, sizeof v, " --fov %g", a->fov);
        strncat(given, v, sizeof given - strlen(given) - 1);
    }
    if (a->has_look_from)
        c->position = a->look_from;
    if (a->has_look_at)
        c->look_at = a->look_at;
    if (a->has_up)
        c->up = a->up;
    if (a->has_fov)
        c->vfov_deg = a->fov;
    if (a->has_look_from || a->has_look_at)
        c->focus_distance = 0.0f; /* the distance to look_at, which moved */
    rt_camera_frame cf;
    if (!rt_camera_frame_init(&cf, c, scene->settings.width, scene->settings.height))
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: the camera is degenerate (the position equals the point looked at, or up is parallel "
                       "to the view direction)",
                       given + 1);
    scene->camera_set = true;
    return RT_OK;
}

/* The loaded scene as the flags want it: setting flags applied, --camera
 * chosen, a glTF camera fitted to the image, the camera framed when the
 * input has none, the limits checked, the output path chosen and checked. */
static rt_result prepare(rt_scene *scene, const args *a, char *output, size_t size, bool *animated, rt_error *err)
{
    rt_load_info info;
    rt_load_options lo = {.for_render = true,
                          .use_time = a->posed,
                          .time = a->frame_time,
                          .animation = a->animation,
                          .variant = a->variant};
    rt_result r;
    /* -o is checked before the load, which may take long, and so is a
     * model's default output (models have no `output` line); a scene's own
     * `output` can only be checked after the load */
    if (a->output && (r = rt_output_check(a->output, err)) != RT_OK)
        return r;
    if (!a->output && !args_sets(a, "output") && a->input && strcmp(a->input, "-") != 0 &&
        !rt_load_is_scene_name(a->input)) {
        input_default_output(NULL, a->input, output, size);
        if ((r = rt_output_check(output, err)) != RT_OK)
            return r;
    }
    if ((r = input_load(scene, a->input, &lo, &info, err)) != RT_OK)
        return r;
    *animated = info.animated;
    if ((r = rt_scene_validate(scene, err)) != RT_OK) { /* from here on the tables are trusted */
        rt_error inner = *err;
        return rt_fail(err, inner.code, "%s: %s", input_name(a->input), inner.message);
    }
    if (rt_scene_prim_count(scene) == 0)
        rt_warn("%s: nothing to render (no spheres, quads, triangles or meshes); the image will show only the "
                "background",
                input_name(a->input));
    if ((r = args_apply_settings(a, scene, err)) != RT_OK)
        return r;
    rt_settings *set = &scene->settings;
    if (a->camera >= 0) {
        if ((size_t)a->camera >= scene->camera_count)
            return rt_fail(err, RT_ERR_INVALID, "--camera %d: the loaded models have %zu camera%s", a->camera,
                           scene->camera_count, scene->camera_count == 1 ? "" : "s");
        scene->camera = scene->cameras[a->camera];
        scene->camera_set = true;
    }
    if (a->camera_auto) { /* ignore the file's camera: frame the scene below */
        scene->camera_set = false;
        scene->camera.aspect_ratio = 0.0f;
    }
    /* a glTF camera made for another aspect ratio: keep the height, fit the width */
    if (!args_sets(a, "resolution") && a->input && info.kind == RT_LOAD_GLTF && scene->camera_set &&
        scene->camera.aspect_ratio > 0.0f)
        set->width = input_width_for_aspect(set->height, scene->camera.aspect_ratio);
    bool camera_from_input = scene->camera_set;
    if (!scene->camera_set)
        rt_scene_frame_camera(scene);
    if ((r = apply_pose_flags(scene, a, err)) != RT_OK)
        return r;
    if ((r = rt_render_check_limits(scene, input_name(a->input), camera_from_input, err)) != RT_OK)
        return r;

    if (a->output)
        snprintf(output, size, "%s", a->output);
    else
        input_default_output(scene, a->input, output, size);
    if ((r = rt_output_check(output, err)) != RT_OK ||
        (r = rt_output_check_size(output, set->width, set->height, err)) != RT_OK)
        return r;
    /* rt convert and rt merge refuse these; a render keeps them for the window */
    rt_image_format fmt = RT_FORMAT_PNG;
    rt_output_format(output, &fmt, NULL);
    if (fmt != RT_FORMAT_PNG && (a->exposure_ev != 0.0f || a->tonemap != RT_TONEMAP_CLAMP))
        rt_warn("%s holds the linear radiance: --exposure and --tonemap shape 8-bit output (.png)%s", output,
                a->window ? " and the window" : " only");
    if (fmt != RT_FORMAT_EXR && a->half)
        rt_warn("%s: --half is for .exr output; ignored", output);
    if (!a->input && a->log_level >= RT_LOG_NORMAL)
        fprintf(stderr, "rt: no input given; rendering the built-in Cornell box to %s (rt --help for usage)\n",
                output);

    rt_info("scene: %s (loaded in %.1f ms)", input_name(a->input), info.load_ms);
    rt_info("  triangles %zu, spheres %zu, quads %zu, vertices %zu", scene->triangles.count, scene->spheres.count,
            scene->quads.count, scene->vertices.count);
    rt_info("  materials %zu, textures %zu, images %zu, lights %zu", scene->material_count, scene->texture_count,
            scene->image_count, scene->light_count);
    rt_info("  %dx%d, %d samples per pixel, integrator %s", set->width, set->height, set->samples,
            rt_integrator_name(set->integrator));
    return RT_OK;
}

/* Writes a render's result (rt_render returned r with stats rs) where its
 * state says: a part (pj->to_part), the output, or NAME.partial.EXT for an
 * incomplete tiled image, and --part-out's part; says so; returns the exit
 * status (128 + the signal that stopped it, 2 on an error, else 0: also
 * when the window was closed). */
static int write_result(const args *a, const rt_settings *set, const rt_part_job *pj, rt_result r,
                        const rt_render_stats *rsp, rt_framebuffer *fb, rt_job_aovs *aov, const char *output,
                        progress_view *view, double t_start, rt_error *err)
{
    rt_job_options jo;
    args_job_options(a, &jo);
    const rt_render_stats rs = *rsp;
    int status = 0;
    if (r != RT_OK && r != RT_ERR_INTERRUPTED) {
        progress_clear(view);
        memory_budget_report(err, &a->budget);
        return 2;
    }
    int sig = atomic_load(&interrupted);
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
    char partial[1100], what[160];
    const char *target = output;
    if (pj->to_part) {
        if (rs.partial) {
            fprintf(stderr, "rt: stopped before any %s finished (%s); no part written, %s left as it was%s\n",
                    rs.passes ? "pass" : "tile", reason ? reason : "?", output,
                    rs.passes ? "" : " (a tiled part keeps nothing when stopped: render parts in --passes N)");
        } else if (rt_part_job_write(pj, output, rs.samples_done, &write_temp, err) != RT_OK) {
            memory_budget_report(err, &a->budget);
            status = 2;
        } else if (a->log_level >= RT_LOG_NORMAL || stopped) {
            fprintf(stderr, "rt: wrote %s and %s.json: part [%d, %d) x [%d, %d) of %dx%d, samples %d:%d of %d%s; "
                            "%.2f s (render %.2f s)\n",
                    output, output, pj->region.x0, pj->region.x1, pj->region.y0, pj->region.y1, set->width,
                    set->height, pj->part_begin, pj->s_begin + rs.samples_done, set->samples, why,
                    rt_now_seconds() - t_start, rs.seconds);
        }
    } else {
        if (rs.partial) {
            rt_path_tagged(output, "partial", NULL, partial, sizeof partial); /* where an incomplete image goes */
            target = partial;
            snprintf(what, sizeof what, "%d of %d tiles at %d spp%s", rs.tiles_done, rs.tiles_total, set->samples,
                     why);
        } else {
            snprintf(what, sizeof what, "%d of %d spp%s", pj->s_begin + rs.samples_done, set->samples, why);
        }
        if (rs.partial && rs.tiles_done == 0) {
            fprintf(stderr, "rt: stopped before any %s finished (%s); nothing written, %s left as it was\n",
                    rs.passes ? "pass" : "tile", reason ? reason : "?", output);
        } else if (rt_job_output_write(&jo, set, fb, aov, target, &write_temp, err) != RT_OK) {
            memory_budget_report(err, &a->budget);
            status = 2;
        } else if (a->log_level >= RT_LOG_NORMAL || stopped) {
            fprintf(stderr, "rt: wrote %s: %dx%d, %s; %.2f s (render %.2f s)%s%s%s\n", target, fb->width, fb->height,
                    what, rt_now_seconds() - t_start, rs.seconds, rs.partial ? "; " : "", rs.partial ? output : "",
                    rs.partial ? " left as it was" : "");
        }
    }
    if (status != 2 && a->part_out) {
        if (rs.partial)
            fprintf(stderr, "rt: %s: no part written: %s\n", a->part_out,
                    rs.passes ? "no pass finished"
                              : "a render in tiles keeps no part when stopped (--passes 0 asked for tiles)");
        else if (rt_part_job_write(pj, a->part_out, rs.samples_done, &write_temp, err) != RT_OK) {
            memory_budget_report(err, &a->budget);
            status = 2;
        } else if (a->log_level >= RT_LOG_NORMAL || stopped)
            fprintf(stderr, "rt: wrote %s and %s.json: samples %d:%d of %d\n", a->part_out, a->part_out,
                    pj->part_begin, pj->s_begin + rs.samples_done, set->samples);
    }
    return status;
}

/* prepare() for the same input at another time (a motion slice): its
 * warnings were the first load's, so they are not said again (-v keeps
 * its lines). */
static rt_result prepare_again(rt_scene *scene, const args *a, char *output, size_t size, bool *animated,
                               rt_error *err)
{
    rt_log_level level = rt_log_get_level();
    if (level == RT_LOG_NORMAL)
        rt_log_set_level(RT_LOG_QUIET);
    rt_result r = prepare(scene, a, output, size, animated, err);
    rt_log_set_level(level);
    return r;
}

/* What the job's motion slices (rt/job/slices.h) ask the driver: a slice's
 * scene loaded and prepared from the flags at its time, and the progress
 * line told of each slice. */
typedef struct slice_loader {
    const args *a;
    progress_view *view;
} slice_loader;

static rt_result load_slice(void *user, rt_scene *slice, float time, rt_error *err)
{
    const slice_loader *sl = user;
    args ak = *sl->a;
    ak.posed = true;
    ak.frame_time = time;
    char out[1024];
    bool animated = false;
    return prepare_again(slice, &ak, out, sizeof out, &animated, err);
}

static void slice_loading(void *user, int k, int slices, float time)
{
    char detail[64];
    snprintf(detail, sizeof detail, "slice %d of %d, t = %g s", k + 1, slices, (double)time);
    progress_phase(((const slice_loader *)user)->view, "motion", detail);
}

static void slice_rendering(void *user, int tiles_total)
{
    progress_restart(((const slice_loader *)user)->view, tiles_total);
}

/* Builds the kd-tree, renders (Ctrl-C and SIGTERM stop the workers, as
 * does --time-limit; with --window, again at each new camera) and writes
 * the image; returns the exit status.
 * t_start: when the run began, for the wall time in the "wrote" line. */
static int render_and_write(rt_scene *scene, const args *a, int slices, const char *output,
                            progress_view *view, double t_start)
{
    rt_job_options jo;
    args_job_options(a, &jo);
    const rt_settings *set = &scene->settings;
    rt_error err = {0};
    rt_kdtree tree;
    char prims[64];
    snprintf(prims, sizeof prims, "(%zu primitives)", rt_scene_prim_count(scene));
    progress_phase(view, "kd-tree", prims);
    if (rt_kdtree_build(&tree, scene, NULL, &err) != RT_OK) {
        progress_clear(view);
        memory_budget_report(&err, &a->budget);
        return 2;
    }
    rt_info("kd-tree: built in %.1f ms: %zu nodes, %zu leaves (%zu empty), %zu references, depth %d; "
            "%zu 64-byte nodes of 3 levels, %.1f MiB",
            tree.stats.build_ms, tree.stats.nodes, tree.stats.leaves, tree.stats.empty_leaves, tree.stats.prim_refs,
            tree.stats.depth, tree.stats.wide_nodes, (double)tree.stats.bytes / (1024.0 * 1024.0));

    rt_part_job pj;
    if (rt_part_job_init(&pj, &jo, scene, &tree, &err) != RT_OK) {
        rt_part_job_free(&pj); /* whatever a failed --resume had taken from its part */
        progress_clear(view);
        memory_budget_report(&err, &a->budget);
        rt_kdtree_free(&tree);
        return 2;
    }
    if (pj.to_part && !rt_part_path_ok(output)) {
        progress_clear(view);
        fprintf(stderr, "rt: %s: a part is written as .exr or .pfm (with %s.json beside it), not as an 8-bit image\n",
                output, output);
        rt_part_job_free(&pj);
        rt_kdtree_free(&tree);
        return 2;
    }
    const char *aov_part = pj.info.layer_count == 0                            ? NULL
                           : pj.to_part && !rt_path_has_ext(output, ".exr")    ? output
                           : a->part_out && !rt_path_has_ext(a->part_out, ".exr") ? a->part_out
                                                                                 : NULL;
    if (aov_part) {
        progress_clear(view);
        fprintf(stderr, "rt: %s: a part with AOVs is written as .exr (their sums are layers of it)\n", aov_part);
        rt_part_job_free(&pj);
        rt_kdtree_free(&tree);
        return 2;
    }
    if (pj.to_part)
        rt_info("part: pixels [%d, %d) x [%d, %d), samples %d:%d", pj.region.x0, pj.region.x1, pj.region.y0,
                pj.region.y1, pj.s_begin, pj.s_end);

    rt_framebuffer fb;
    if (rt_framebuffer_init(&fb, pj.region.x1 - pj.region.x0, pj.region.y1 - pj.region.y0, &err) != RT_OK) {
        progress_clear(view);
        memory_budget_report(&err, &a->budget);
        rt_part_job_free(&pj);
        rt_kdtree_free(&tree);
        return 2;
    }

    rt_job_aovs aov;
    if (rt_job_aovs_init(&aov, &jo, fb.width, fb.height, &err) != RT_OK) {
        progress_clear(view);
        memory_budget_report(&err, &a->budget);
        rt_framebuffer_free(&fb);
        rt_part_job_free(&pj);
        rt_kdtree_free(&tree);
        return 2;
    }

    window_view window;
    if (a->window) {
        char why[512], title[1100];
        snprintf(title, sizeof title, "rt: %s", output);
        if (!window_open(&window, fb.width, fb.height, title, why, sizeof why)) {
            progress_clear(view);
            fprintf(stderr, "rt: --window: cannot open a window: %s\n", why);
            rt_job_aovs_free(&aov);
            rt_framebuffer_free(&fb);
            rt_part_job_free(&pj);
            rt_kdtree_free(&tree);
            return 2;
        }
        view->window = &window;
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    view->preview_path = a->preview_seconds > 0.0 && !pj.to_part ? output : NULL;
    if (a->preview_seconds > 0.0 && pj.to_part)
        rt_warn("--preview: a part's output holds sums, not an image; no preview is written");
    view->preview_seconds = a->preview_seconds;
    view->exposure = set->exposure;
    view->time_limit = a->time_limit;
    view->temp = &write_temp;
    tev_stream tev;
    if (a->display_server) {
        const char *base = strrchr(output, '/');
        rt_image_layer layers[RT_AOV_COUNT];
        int nl = rt_job_aovs_layers(&aov, layers, RT_AOV_COUNT); /* --aov: extra layers in tev */
        tev_stream_open(&tev, a->display_server, base ? base + 1 : output, fb.width, fb.height, layers, nl);
        view->tev = &tev;
    }
    rt_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.threads = a->threads;
    ro.tile_size = a->tile;
    ro.pass_samples = rt_job_pass_samples(a->pass_samples, pj.need_accum, scene->settings.integrator);
    ro.time_limit = a->time_limit;
    ro.cancel = &render_stop;
    ro.progress = view->bar || view->preview_path || view->tev || view->window ? progress_report : NULL;
    ro.progress_user = view;
    ro.aov = rt_job_aovs_for_render(&aov);
    ro.region = pj.region;
    ro.sample_begin = pj.s_begin;
    ro.sample_end = pj.s_end;
    ro.accum = pj.need_accum ? &pj.accum : NULL;
    /* depth of field and motion blur (an open shutter) blur albedo and normal with noise */
    aov.noisy_aux = scene->camera.aperture > 0.0f || scene->camera.shutter_close > scene->camera.shutter_open;
    rt_render_stats rs;
    memset(&rs, 0, sizeof rs);
    /* --window: the scene at the window's camera; a camera move cancels the
     * render, which starts again from sample 0 (docs/watching.md) */
    rt_scene shown = *scene;
    viewer session = {.window = &window, .cancel = &render_stop, .output = output,
                      .image = {.exposure = set->exposure * rt_exposure_scale(a->exposure_ev),
                                .tonemap = a->tonemap, .half = a->half},
                      .temp = &write_temp, .samples_total = set->samples};
    if (a->window) {
        rt_box b = rt_scene_bounds(scene);
        float diag = rt_box_diagonal(b), d = rt_length(rt_sub(scene->camera.look_at, scene->camera.position));
        window.exposure = session.image.exposure;
        window.tonemap = a->tonemap;
        window_set_camera(&window, &scene->camera, isfinite(diag) && diag > 0.0f ? 0.02f * diag : 0.05f * d);
        window.interactive = !pj.need_accum; /* kept sums (a part, --part-out, --resume): the camera stays */
        view->viewer = &session;
    }
    bool written = false;
    rt_result r;
    int status = 0;
    if (slices > 1) { /* motion blur: the slices after the first, each posed and with its own tree */
        if (!pj.need_accum && rt_part_job_accum(&pj, ro.aov != NULL, &err) != RT_OK) {
            progress_clear(view);
            memory_budget_report(&err, &a->budget);
            r = RT_ERR_NOMEM;
        } else {
            ro.accum = &pj.accum;
            slice_loader sl = {a, view};
            rt_job_slices plan = {.slices = slices, .frame_time = a->posed ? a->frame_time : 0.0f,
                                  .s_begin = pj.s_begin, .s_end = pj.s_end, .pass_samples = ro.pass_samples,
                                  .time_limit = a->time_limit, .load = load_slice, .loading = slice_loading,
                                  .rendering = slice_rendering, .user = &sl};
            r = rt_job_render_slices(scene, &tree, &plan, &ro, &fb, &rs, &err);
        }
        status = r == RT_ERR_NOMEM ? 2 : write_result(a, set, &pj, r, &rs, &fb, &aov, output, view, t_start, &err);
        written = true;
    }
    for (; slices <= 1;) {
        r = rt_render(&shown, &tree, &ro, &fb, &rs, &err);
        if (!a->window || atomic_load(&interrupted) || (r != RT_OK && r != RT_ERR_INTERRUPTED))
            break;
        if (r == RT_OK) { /* finished (or the time limit): written now, then the window waits */
            status = write_result(a, set, &pj, r, &rs, &fb, &aov, output, view, t_start, &err);
            written = true;
            if (status == 2 || !viewer_wait(&session, &fb, rs.samples_done, &interrupted))
                break;
        } else if (!session.moved) {
            break; /* the window was closed */
        }
        shown.camera = window.camera;
        session.moved = false;
        written = false;
        atomic_store(&render_stop, 0);
        if (atomic_load(&interrupted)) /* a signal since the check above */
            atomic_store(&render_stop, 1);
        progress_restart(view, rs.tiles_total);
        rt_info("window: the camera moved; rendering again from sample 0");
    }
    if (!written)
        status = write_result(a, set, &pj, r, &rs, &fb, &aov, output, view, t_start, &err);
    rt_info("render: %.3f s on %d threads, %s, %llu camera rays, %llu rays, %.2f Mrays/s", rs.seconds, rs.threads,
            rs.passes ? "passes" : "tiles", (unsigned long long)rs.camera_rays, (unsigned long long)rs.rays,
            rs.seconds > 0 ? 1e-6 * (double)rs.rays / rs.seconds : 0.0);
    if (rs.bad_samples)
        rt_warn("%llu NaN/Inf samples were dropped", (unsigned long long)rs.bad_samples);
    if (view->tev)
        tev_stream_close(&tev);
    view->tev = NULL;
    if (view->window)
        window_close(&window);
    view->window = NULL;
    view->viewer = NULL;
    rt_job_aovs_free(&aov);
    rt_framebuffer_free(&fb);
    rt_part_job_free(&pj);
    rt_kdtree_free(&tree);
    return status;
}

/* Loads, prepares (posed at a->frame_time when a->posed), renders and
 * writes one image (or part); the exit status. */
static int render_one(rt_scene *scene, const args *a, double t_start)
{
    rt_error err = {0};
    char output[1024];
    progress_view view;
    progress_view_init(&view, a->log_level >= RT_LOG_NORMAL && isatty(2));
    progress_phase(&view, "load", a->input ? a->input : "the built-in scene");
    bool animated = false;
    if (prepare(scene, a, output, sizeof output, &animated, &err) != RT_OK) {
        progress_clear(&view);
        memory_budget_report(&err, &a->budget);
        progress_view_free(&view);
        return 2;
    }
    /* an open shutter over animated models: motion blur in time slices, the
     * first posed here at its time (a static scene renders as it is) */
    int slices = rt_motion_slices(&scene->camera, scene->settings.motion_steps, scene->settings.samples);
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
        size_t n = scene->image_count;
        if (!rt_scene_share_images(&s0, scene) ||
            prepare_again(&s0, &a0, output, sizeof output, &animated, &err) != RT_OK) {
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
    int status = render_and_write(scene, a, animated ? slices : 1, output, &view, t_start);
    progress_view_free(&view);
    return status;
}

int main(int argc, char **argv)
{
    double t_start = rt_now_seconds();
    if (argc > 1 && strcmp(argv[1], "compare") == 0)
        return rt_cmd_compare(argc - 1, argv + 1);
    if (argc > 1 && strcmp(argv[1], "convert") == 0)
        return rt_cmd_convert(argc - 1, argv + 1);
    if (argc > 1 && strcmp(argv[1], "merge") == 0)
        return rt_cmd_merge(argc - 1, argv + 1);
    args a;
    int status = args_parse(&a, argc, argv);
    if (status != ARGS_OK)
        return status;
    rt_log_set_level(a.log_level);
    memory_budget_apply(&a.budget);
    if (a.info_path)
        return info_print(&a);

    rt_error err = {0};
    rt_job_options jo;
    args_job_options(&a, &jo);
    if (rt_job_output_check(&jo, &err) != RT_OK) {
        fprintf(stderr, "rt: %s\n", err.message);
        return 2;
    }
    rt_scene scene;
    rt_scene_init(&scene);
    char part_default[1100];
    if (args_output_is_part(&a) && !a.output) { /* a part goes to NAME.part.exr */
        char name[1024];
        input_default_output(NULL, a.input, name, sizeof name);
        rt_path_tagged(name, "part", ".exr", part_default, sizeof part_default);
        a.output = part_default;
    }
    if (a.part_out && (!rt_part_path_ok(a.part_out) || rt_output_check(a.part_out, &err) != RT_OK)) {
        fprintf(stderr, "rt: --part-out %s: %s\n", a.part_out,
                rt_part_path_ok(a.part_out) ? err.message : "a part is written as .exr or .pfm");
        return 2;
    }
    if (!a.has_frames) {
        status = render_one(&scene, &a, t_start);
        rt_scene_free(&scene);
        return status;
    }
    /* --frames A:B: one render a frame, named from the pattern; the first failure ends the run */
    const char *pattern = a.output;
    if (!pattern || !frames_pattern_ok(pattern)) {
        fprintf(stderr, "rt: --frames %d:%d: -o must name the frames with one %%d or %%0Nd (e.g. -o out.%%04d.png), "
                        "got %s%s%s\n",
                a.frame_begin, a.frame_end, pattern ? "'" : "", pattern ? pattern : "no -o", pattern ? "'" : "");
        rt_scene_free(&scene);
        return 2;
    }
    const char *part_pattern = a.part_out && frames_pattern_ok(a.part_out) ? a.part_out : NULL;
    char name[1100], part_name[1100];
    status = 0;
    for (int f = a.frame_begin; f < a.frame_end && status == 0; f++) {
        if (!frames_name(pattern, f, name, sizeof name) ||
            (part_pattern && !frames_name(part_pattern, f, part_name, sizeof part_name))) {
            fprintf(stderr, "rt: -o %s: the name of frame %d is too long\n", pattern, f);
            status = 2;
            break;
        }
        a.output = name;
        if (part_pattern)
            a.part_out = part_name;
        a.frame_time = (float)frames_time(f, a.fps); /* an animated glTF posed at the frame's time */
        a.posed = true;
        rt_scene_free(&scene);
        rt_scene_init(&scene);
        status = render_one(&scene, &a, rt_now_seconds());
    }
    rt_scene_free(&scene);
    return status;
}
