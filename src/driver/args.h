/* args.h - the `rt` command line (driver-private): flags in, one record out.
 *
 * Every flag has a short and/or long form (`-s 64`, `-s64`, `--samples 64`,
 * `--samples=64`, and aliases such as `--spp 64`); a flag missing its value
 * says so rather than taking the next flag as its value. The flags that set scene settings (-s, -r, --seed,
 * --integrator, and --set KEY=VALUE for any setting) go through the settings
 * table (rt/render/settings.h): they are checked while parsing, so a bad value
 * is refused before anything is loaded, and applied after loading, in the
 * order given, so a later flag wins.
 *
 *   args a;
 *   int status = args_parse(&a, argc, argv);   // prints --help, --version and flag errors itself
 *   if (status != ARGS_OK)
 *       return status;                          // 0 after --help or --version, 2 after a bad flag
 *   ... load the scene ...
 *   if (args_apply_settings(&a, &scene, &settings, &err) != RT_OK) ...   // "--set environment=sky.hdr: ..."
 */
#ifndef RT_DRIVER_ARGS_H
#define RT_DRIVER_ARGS_H

#include <stdbool.h>
#include <stddef.h>

#include "memory_budget.h"
#include "rt/base/error.h"
#include "rt/base/log.h"
#include "rt/image/denoise.h"
#include "rt/image/tonemap.h"
#include "rt/scene/scene.h"
#include "rt/job/options.h"
#include "rt/render/settings.h"

#define ARGS_OK (-1)

#define ARGS_MAX_SETTINGS 64 /* setting flags on one command line */
#define ARGS_MAX_INPUTS 256  /* files one --info reports */


/* One setting flag as given: `-s 64`, `--set samples=64`. */
typedef struct setting_flag {
    const char *flag;          /* as typed, for messages: "-s", "--samples", "--set" */
    const char *arg;           /* its argument as typed: "64", "samples=64" */
    const rt_setting *setting; /* what it sets */
    const char *value;         /* the setting's value text: "64" */
} setting_flag;

typedef struct args {
    const char *input;      /* the scene or model; NULL = the built-in scene */
    const char *output;     /* -o; NULL = the scene's `output`, else INPUT-NAME.png */
    const char *info_path;  /* --info FILE: print what it contains and exit */
    const char *more_inputs[ARGS_MAX_INPUTS]; /* with --info, the files after the first input */
    size_t more_input_count;
    int threads;            /* -t; 0 = all cores */
    int tile;               /* --tile; 0 = the default */
    int camera;             /* --camera N; -1 = none */
    bool camera_auto;       /* --camera auto: frame the model, ignoring its cameras */
    const char *variant;    /* --variant NAME: the glTF material variant; NULL = the default materials */
    /* --look-from, --look-at, --up, --fov: each replaces one part of the
     * camera (after --camera and automatic framing) */
    bool has_look_from, has_look_at, has_up, has_fov;
    rt_vec3 look_from, look_at, up;
    float fov;
    bool posed;             /* --frame-time or --animation: pose an animated glTF */
    float frame_time;       /* --frame-time seconds (0 with --animation alone) */
    int animation;          /* --animation N (0 = the first) */
    const char *animation_name; /* --animation NAME: the glTF animation of that name; NULL = by index */
    double preview_seconds; /* --preview; 0 = no live view */
    int pass_samples;       /* --passes: rt_render_options.pass_samples (0 = the integrator's, -1 = tiles) */
    double time_limit;      /* --time-limit seconds; 0 = none */
    const char *display_server; /* --display-server HOST:PORT (tev); NULL = none */
    bool window;            /* --window */
    rt_log_level log_level; /* -q, -v */
    memory_budget budget;   /* --max-memory, else the default (not applied yet) */
    float exposure_ev;      /* --exposure: stops for 8-bit output, on top of the scene's */
    rt_tonemap tonemap;     /* --tonemap: the curve for 8-bit output */
    bool half;              /* --half: EXR in half floats */
    bool flatten;           /* --flatten: glTF meshes used more than once flattened, no instances */
    bool denoise;           /* --denoise: Intel Open Image Denoise on the render */
    rt_denoise_quality denoise_quality; /* --denoise-quality; RT_DENOISE_DEFAULT: RT_OIDN_QUALITY, else balanced */
    unsigned aovs;          /* --aov: bit k for rt_aov_names[k] */
    /* parts of a render spread over machines (docs/farm.md) */
    bool has_crop;          /* --crop X0 Y0 X1 Y1 */
    int crop[4];
    int part_index, part_count; /* --part I/N; part_count 0 = none */
    bool has_spp_range;     /* --spp-range A:B */
    int spp_begin, spp_end;
    const char *resume;     /* --resume PART: continue that part */
    const char *part_out;   /* --part-out FILE: also write the render as a part */
    bool has_frames;        /* --frames A:B: frames A .. B-1, the output a %04d pattern */
    int frame_begin, frame_end;
    double fps;             /* --fps; 24 unless given */
    bool has_only_frames;   /* --only-frames C:D: render frames C .. D-1 of A:B only (framed for all of A:B) */
    int only_begin, only_end;
    const char *stop_part;  /* not a flag: with --frames, where a stopped frame's part goes (NAME.part.exr) */
    const rt_frame_extent *frame_extent; /* not a flag: with --frames, the sequence's automatic framing */
    setting_flag settings[ARGS_MAX_SETTINGS];
    size_t setting_count;
} args;


/* Parses argv into *a. Returns ARGS_OK to go on, else the exit status. */
int args_parse(args *a, int argc, char **argv);
/* True when a flag sets the setting called `name` (e.g. "resolution"). */
bool args_sets(const args *a, const char *name);
/* True when the output is a part rather than an image: --part or
 * --spp-range given, or --crop with no -o or an -o of a part's format
 * (.exr, .pfm; --crop -o x.png is the cropped image); --resume decides
 * later, from the part it continues. */
bool args_output_is_part(const args *a);
/* The job's options (rt/job/options.h) from the flags. */
void args_job_options(const args *a, rt_job_options *o);
/* Applies the setting flags to the loaded scene, in command-line order. */
rt_result args_apply_settings(const args *a, rt_scene *s, rt_settings *settings, rt_error *err);

#endif
