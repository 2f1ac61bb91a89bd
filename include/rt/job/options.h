/* rt/job/options.h - what a render job is asked for beyond the scene's
 * settings: the input it came from, threads, the pose, the output's tone
 * and AOVs, and the part of a render spread over machines (docs/farm.md).
 * The `rt` driver fills it from its flags; a program of its own fills it
 * directly (zero is a plain render of the whole image to one file).
 *
 *   rt_job_options o = {.input = "scene.txt", .aovs = 1u << RT_AOV_ALBEDO};
 *   o.part_index = 2, o.part_count = 8, o.output_is_part = true;   // --part 3/8
 */
#ifndef RT_JOB_OPTIONS_H
#define RT_JOB_OPTIONS_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/vec.h"
#include "rt/image/denoise.h"
#include "rt/image/tonemap.h"
#include "rt/scene/scene.h"

#define RT_VERSION "0.1.0" /* rt's version, which every part carries */

/* The AOVs a job can write, in bit order (rt/render/aov.h says what each holds). */
typedef enum rt_aov_kind {
    RT_AOV_ALBEDO,
    RT_AOV_NORMAL,
    RT_AOV_DEPTH,
    RT_AOV_POSITION,
    RT_AOV_VARIANCE,
    RT_AOV_SPP,
    RT_AOV_COUNT
} rt_aov_kind;
/* Their names: "albedo", "normal", ... (--aov, EXR layers, file names). */
extern const char *const rt_aov_names[RT_AOV_COUNT];
/* The AOV whose name is the len bytes at name (not NUL-terminated: an
 * item of a comma list); false when none is. */
bool rt_aov_by_name(const char *name, size_t len, rt_aov_kind *out);

typedef struct rt_job_options {
    const char *input;      /* the scene or model file (its bytes: a part's identity); NULL = built-in, "-" = stdin */
    int threads;            /* 0 = all cores */
    bool posed;             /* posed at frame_time with animation (an animated glTF) */
    float frame_time;
    int animation;
    const char *animation_name; /* the animation by its name; NULL = by index */
    /* the view (rt_job_frame) */
    bool use_camera;        /* camera `camera` of the loaded models' cameras */
    int camera;
    bool camera_auto;       /* frame the scene, ignoring the file's camera */
    bool fit_aspect;        /* a camera made for another aspect ratio (glTF) keeps the height, fits the width */
    const rt_frame_extent *frame_extent; /* the framing covers these poses (rt --frames), not only the scene's; NULL = none */
    bool has_look_from, has_look_at, has_up, has_fov; /* each replaces one part of the camera */
    rt_vec3 look_from, look_at, up;
    float fov;
    /* output */
    float exposure_ev;      /* stops for 8-bit output, on top of the scene's exposure */
    rt_tonemap tonemap;     /* the curve for 8-bit output */
    bool half;              /* EXR in half floats */
    bool denoise;           /* Intel Open Image Denoise on the render */
    rt_denoise_quality denoise_quality;
    unsigned aovs;          /* bit k: rt_aov_names[k] is written */
    /* parts of a render spread over machines */
    bool output_is_part;    /* the output is a part (a crop, a band or a sample range), not an image */
    bool has_crop;          /* crop: [x0, y0, x1, y1): a part's region, or without output_is_part the image's */
    int crop[4];
    int part_index, part_count; /* band part_index of part_count of similar cost; part_count 0 = none */
    bool has_spp_range;     /* samples [spp_begin, spp_end) only */
    int spp_begin, spp_end;
    const char *resume;     /* a part to continue; NULL = none */
    const char *part_out;   /* also write the render as this part; NULL = none */
    const char *stop_part;  /* a render stopped early (signal, time limit) writes this part to resume it (rt
                             * --frames: NAME.part.exr); the sums are kept as for part_out. NULL = none */
} rt_job_options;

#endif
