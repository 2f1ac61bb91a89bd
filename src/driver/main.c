/* main.c - the `rt` command: a subcommand (compare, convert, merge:
 * commands.h), or the flags parsed (args.c) and one render (run.c: load
 * and prepare the scene, build the kd-tree, render, write), or one a frame
 * with --frames A:B (frames.c; one automatic camera for the sequence:
 * frames_camera.c). The library does the work: loading (io),
 * the render (render), parts, motion slices, merges and outputs (job). A
 * part of a render spread over machines (--part, --crop, --spp-range,
 * --resume, --part-out: docs/farm.md) renders its region and samples and
 * writes its sums; `rt merge` (cmd_merge.c) puts parts together.
 *
 * Exit status: 0 on success (also when --time-limit stopped the render),
 * 2 for bad input (flags, scene files, models, images, an unwritable
 * output), 128 + the signal when Ctrl-C (130) or SIGTERM (143) stopped it.
 * A render stopped early keeps what it has: in passes (also every render
 * with --time-limit) the whole image at the samples reached goes to the
 * output; a tiled render's finished tiles go to NAME.partial.EXT, never
 * over the output; a frame of --frames goes to NAME.partial.EXT with the
 * part NAME.part.exr that its next run resumes. A second signal ends the
 * process at once and removes the temporary file of a write under way.
 * Every failure says what and where on stderr, and never leaves a partial
 * file over an existing image. The process runs under a memory budget
 * (memory_budget.c).
 */
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "rt/base/clock.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/io/image_write.h"
#include "rt/job/options.h"
#include "rt/job/output.h"
#include "rt/job/part.h"

#include "args.h"
#include "commands.h"
#include "frames.h"
#include "frames_camera.h"
#include "info.h"
#include "input.h"
#include "memory_budget.h"
#include "run.h"

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

/* What the output flags need, checked before anything loads: the denoiser's
 * library, a part's default name (NAME.part.exr, into part_default), the
 * frames' default pattern (NAME.%04d.png, a part's NAME.%04d.part.exr),
 * and --part-out's format and path. 0, or 2 with the message said. */
static int check_outputs(args *a, char *part_default, size_t size)
{
    rt_error err = {0};
    rt_job_options jo;
    args_job_options(a, &jo);
    if (rt_job_output_check(&jo, &err) != RT_OK) {
        fprintf(stderr, "rt: %s\n", err.message);
        return 2;
    }
    if (a->has_frames && !a->output) { /* frames go to NAME.%04d.png (a part's: NAME.%04d.part.exr) */
        char name[1024], part[1100];
        input_default_output(NULL, a->input, name, sizeof name);
        bool fits = args_output_is_part(a) ? rt_path_tagged(name, "part", ".exr", part, sizeof part) &&
                                                 frames_default_pattern(part, part_default, size)
                                           : frames_default_pattern(name, part_default, size);
        if (!fits) {
            fprintf(stderr, "rt: --frames: the default name of the frames (from %s) is too long; give -o\n", name);
            return 2;
        }
        a->output = part_default;
    } else if (args_output_is_part(a) && !a->output) { /* a part goes to NAME.part.exr */
        char name[1024];
        input_default_output(NULL, a->input, name, sizeof name);
        rt_path_tagged(name, "part", ".exr", part_default, size);
        a->output = part_default;
    }
    if (a->part_out && (!rt_part_path_ok(a->part_out) || rt_part_check_paths(a->part_out, &err) != RT_OK)) {
        fprintf(stderr, "rt: --part-out %s: %s\n", a->part_out,
                rt_part_path_ok(a->part_out) ? err.message : "a part is written as .exr or .pfm");
        return 2;
    }
    return 0;
}

/* A frame's resumable part when it is stopped (NAME.part.exr beside the
 * frame NAME) into a->stop_part, and a->resume set to it when an earlier
 * run left one there (its sidecar is there); not for part outputs (a
 * stopped part is its own part) nor for what a part cannot keep (--denoise,
 * the variance and spp AOVs: such a frame is only kept apart, as
 * NAME.partial.EXT). false when the name does not fit. */
static bool frame_stop_part(args *a, const char *name, char *part, size_t size)
{
    a->stop_part = NULL;
    a->resume = NULL;
    if (args_output_is_part(a) || a->denoise || (a->aovs & ((1u << RT_AOV_VARIANCE) | (1u << RT_AOV_SPP))))
        return true;
    char sidecar[1200];
    if (!rt_path_tagged(name, "part", ".exr", part, size) ||
        snprintf(sidecar, sizeof sidecar, "%s.json", part) >= (int)sizeof sidecar)
        return false;
    a->stop_part = part;
    if (access(sidecar, F_OK) == 0) {
        a->resume = part;
        if (a->log_level >= RT_LOG_NORMAL)
            fprintf(stderr, "rt: %s: a stopped render of this frame; resuming it\n", part);
    }
    return true;
}

/* --frames A:B: one render a frame, named from the -o (and --part-out)
 * pattern, posed at the frame's time; the first failure ends the run. A
 * frame stopped early goes to NAME.partial.EXT with the part NAME.part.exr,
 * which the next run of that frame resumes (run.c). */
static int render_frames(args *a, const run_signals *sig)
{
    const char *pattern = a->output;
    if (!pattern || !frames_pattern_ok(pattern)) {
        fprintf(stderr, "rt: --frames %d:%d: -o must name the frames with one %%d or %%0Nd (e.g. -o out.%%04d.png), "
                        "got %s%s%s\n",
                a->frame_begin, a->frame_end, pattern ? "'" : "", pattern ? pattern : "no -o", pattern ? "'" : "");
        return 2;
    }
    if (a->resume) {
        fprintf(stderr, "rt: --frames resumes a stopped frame from its NAME.part.exr itself; drop --resume\n");
        return 2;
    }
    const char *part_pattern = a->part_out && frames_pattern_ok(a->part_out) ? a->part_out : NULL;
    char name[1100], part_name[1100], stop_part[1200];
    /* one automatic camera for the whole sequence A:B, whichever share of
     * it this run renders */
    rt_frame_extent extent;
    bool framed = false;
    rt_error err = {0};
    if (frames_camera_extent(a, &extent, &framed, &err) != RT_OK) {
        memory_budget_report(&err, &a->budget);
        return 2;
    }
    a->frame_extent = framed ? &extent : NULL;
    int first = a->has_only_frames ? a->only_begin : a->frame_begin;
    int end = a->has_only_frames ? a->only_end : a->frame_end;
    int status = 0;
    rt_kdtree_kept kept; /* the objects' trees, built once while node animation only moves their instances */
    rt_kdtree_kept_init(&kept);
    for (int f = first; f < end && status == 0; f++) {
        if (!frames_name(pattern, f, name, sizeof name) ||
            (part_pattern && !frames_name(part_pattern, f, part_name, sizeof part_name))) {
            fprintf(stderr, "rt: -o %s: the name of frame %d is too long\n", pattern, f);
            return 2;
        }
        a->output = name;
        if (!frame_stop_part(a, name, stop_part, sizeof stop_part)) {
            fprintf(stderr, "rt: -o %s: the name of frame %d is too long\n", pattern, f);
            return 2;
        }
        if (part_pattern)
            a->part_out = part_name;
        a->frame_time = (float)frames_time(f, a->fps); /* an animated glTF posed at the frame's time */
        a->posed = true;
        rt_scene scene;
        rt_scene_init(&scene);
        status = run_one(&scene, a, rt_now_seconds(), sig, &kept);
        rt_scene_free(&scene);
    }
    rt_kdtree_kept_free(&kept);
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
    char part_default[1100];
    if ((status = check_outputs(&a, part_default, sizeof part_default)) != 0)
        return status;
    run_signals sig = {&interrupted, &render_stop, &write_temp, on_signal};
    if (a.has_frames)
        return render_frames(&a, &sig);
    rt_scene scene;
    rt_scene_init(&scene);
    status = run_one(&scene, &a, t_start, &sig, NULL);
    rt_scene_free(&scene);
    return status;
}
