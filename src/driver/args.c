/* args.c - the `rt` command line (args.h): one table of flags drives the
 * parsing and the --help text; the flags that set scene settings take their
 * ranges, help and defaults from the settings table (settings.h), so the
 * command line, the scene format and --help cannot disagree.
 *
 * Conventions (GNU getopt_long's, without its global state): short and long
 * forms, `--name=value`, a one-letter flag's value in the same word (`-s4`,
 * `-r320x240`), `--` ends the flags. A value that looks like a flag (`-s -o`)
 * is not taken as a value; a lone `-` or a negative number is. Other
 * renderers' names are aliases in the table (pbrt-v4's --spp, --outfile,
 * --nthreads; Mitsuba's -D for --set); an unknown flag is refused with the
 * nearest name (rt/base/near_miss.h, as the scene parser does).
 */
#include "args.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "rt/base/log.h"
#include "rt/base/near_miss.h"
#include "rt/base/number.h"
#include "rt/image/denoise.h"
#include "rt/image/tonemap.h"
#include "rt/io/environment_image.h"
#include "rt/job/part.h"
#include "rt/render/render.h"
#include "tev.h"

typedef enum flag_kind {
    FLAG_OUTPUT,
    FLAG_THREADS,
    FLAG_SETTING, /* sets the scene setting `setting` */
    FLAG_SET,     /* --set KEY=VALUE: any scene setting */
    FLAG_QUIET,
    FLAG_VERBOSE,
    FLAG_CAMERA,
    FLAG_VARIANT,
    FLAG_LOOK_FROM,
    FLAG_LOOK_AT,
    FLAG_UP,
    FLAG_FOV,
    FLAG_FRAME_TIME,
    FLAG_ANIMATION,
    FLAG_TILE,
    FLAG_PREVIEW,
    FLAG_PASSES,
    FLAG_TIME_LIMIT,
    FLAG_DISPLAY_SERVER,
    FLAG_WINDOW,
    FLAG_INFO,
    FLAG_MAX_MEMORY,
    FLAG_EXPOSURE,
    FLAG_TONEMAP,
    FLAG_HALF,
    FLAG_FLATTEN,
    FLAG_DENOISE,
    FLAG_DENOISE_QUALITY,
    FLAG_AOV,
    FLAG_CROP,
    FLAG_PART,
    FLAG_SPP_RANGE,
    FLAG_RESUME,
    FLAG_PART_OUT,
    FLAG_FRAMES,
    FLAG_FPS,
    FLAG_ONLY_FRAMES,
    FLAG_HELP,
    FLAG_VERSION,
} flag_kind;

/* How a plain flag stores its value in args, checked against its range:
 * the table says it, args_parse does it for every such flag alike. */
typedef enum store_kind {
    STORE_NONE,    /* the flag's own code (parse_view_flag, parse_output_flag, parse_part_flag, ...) */
    STORE_TEXT,    /* the value as given, into a const char * */
    STORE_TRUE,    /* no value: the bool becomes true */
    STORE_INT,     /* an integer in [min, max] into an int */
    STORE_FLOAT,   /* a number in the range into a float */
    STORE_SECONDS, /* a number in the range into a double */
} store_kind;

typedef struct flag_store {
    store_kind kind;
    size_t field;            /* offsetof(args, ...) */
    bool marks;              /* also sets the bool at `given` */
    size_t given;
    double min, max;         /* the range; above_min/below_max: exclusive at that end */
    bool above_min, below_max;
    const char *wants;       /* the message's "NAME wants WANTS, got 'VALUE'" */
} flag_store;

typedef struct flag {
    const char *short_name; /* "-s", or NULL */
    const char *long_name;  /* "--samples" */
    const char *value;      /* what it takes, for --help ("N"); NULL = no value */
    flag_kind kind;
    const char *setting;    /* FLAG_SETTING: the name in the settings table */
    const char *help;       /* lines for --help; FLAG_SETTING: the table's */
    flag_store store;       /* a plain flag: where its value goes */
    const char *alias;      /* another long name other renderers use ("--spp", pbrt's), or NULL */
} flag;

#define ARG(f) offsetof(args, f)
#define SETS_TEXT(f) .store = {STORE_TEXT, ARG(f), false, 0, 0, 0, false, false, NULL}
#define SETS_TRUE(f) .store = {STORE_TRUE, ARG(f), false, 0, 0, 0, false, false, NULL}
#define OWN .store = {STORE_NONE, 0, false, 0, 0, 0, false, false, NULL}


/* In --help order. */
static const flag flags[] = {
    {"-o", "--output", "FILE", FLAG_OUTPUT, NULL,
     "output image: .png (8-bit sRGB), .pfm (linear float), .hdr (Radiance), .exr (OpenEXR)\n"
     "default: the scene's `output`, else INPUT-NAME.png in this directory", SETS_TEXT(output), .alias = "--outfile"},
    {NULL, "--exposure", "EV", FLAG_EXPOSURE, NULL,
     "exposure in stops for 8-bit output (x 2^EV, on top of the scene's `exposure`); float outputs stay linear", .store = {STORE_FLOAT, ARG(exposure_ev), false, 0, -64, 64, false, false, "stops of exposure from -64 to 64"}},
    {NULL, "--tonemap", "NAME", FLAG_TONEMAP, NULL, "tone curve for 8-bit output: clamp (default), filmic, aces or agx", OWN},
    {NULL, "--half", NULL, FLAG_HALF, NULL, "EXR output in 16-bit half floats (default 32-bit float)", SETS_TRUE(half)},
    {NULL, "--denoise", NULL, FLAG_DENOISE, NULL,
     "denoise the render with Intel Open Image Denoise (install it with 'make denoiser'), on -t threads", SETS_TRUE(denoise)},
    {NULL, "--denoise-quality", "NAME", FLAG_DENOISE_QUALITY, NULL,
     "the denoiser's quality with --denoise: fast, balanced (default) or high (the same as RT_OIDN_QUALITY=NAME; "
     "the flag wins)", OWN},
    {NULL, "--aov", "LIST", FLAG_AOV, NULL,
     "extra images, comma-separated: albedo, normal, depth, position, variance, spp; layers of an .exr output, "
     "else files NAME.albedo.pfm ...", OWN},
    {"-t", "--threads", "N", FLAG_THREADS, NULL, "render threads", .store = {STORE_INT, ARG(threads), false, 0, 1, 1024, false, false, "a thread count from 1 to 1024"}, .alias = "--nthreads"},
    {"-s", "--samples", "N", FLAG_SETTING, "samples", NULL, OWN, .alias = "--spp"},
    {"-r", "--resolution", "WxH", FLAG_SETTING, "resolution", NULL, OWN},
    {"-q", "--quiet", NULL, FLAG_QUIET, NULL, "quiet: no progress bar, no warnings", OWN},
    {"-v", "--verbose", NULL, FLAG_VERBOSE, NULL, "verbose: scene statistics, kd-tree build, render time, rays per second", OWN},
    {NULL, "--integrator", "NAME", FLAG_SETTING, "integrator", NULL, OWN},
    {NULL, "--seed", "N", FLAG_SETTING, "seed", NULL, OWN},
    {"-D", "--set", "KEY=VALUE", FLAG_SET, NULL,
     "set any scene setting listed below, as a scene file would (repeatable; -D as in Mitsuba)", OWN},
    {NULL, "--camera", "N|auto", FLAG_CAMERA, NULL,
     "use camera N of the loaded glTF models, or 'auto': frame the whole scene automatically, ignoring the file's "
     "camera", OWN},
    {NULL, "--flatten", NULL, FLAG_FLATTEN, NULL,
     "no instances from glTF: every use of a mesh becomes world triangles, and a scene's model lines load "
     "their file at every line, as before instancing (to compare; docs/gltf.md, Instancing)", SETS_TRUE(flatten)},
    {NULL, "--variant", "NAME", FLAG_VARIANT, NULL,
     "show a glTF model's material variant NAME (KHR_materials_variants); default: the file's default materials", OWN},
    {NULL, "--look-from", "X,Y,Z", FLAG_LOOK_FROM, NULL, "camera position (replaces the file's or the automatic one)", OWN},
    {NULL, "--look-at", "X,Y,Z", FLAG_LOOK_AT, NULL, "point the camera looks at", OWN},
    {NULL, "--up", "X,Y,Z", FLAG_UP, NULL, "camera up direction", OWN},
    {NULL, "--fov", "DEG", FLAG_FOV, NULL, "vertical field of view in degrees, between 0 and 180", .store = {STORE_FLOAT, ARG(fov), true, ARG(has_fov), 0, 180, true, true, "a field of view in degrees between 0 and 180 (exclusive)"}},
    {NULL, "--frame-time", "SECONDS", FLAG_FRAME_TIME, NULL,
     "pose an animated glTF (given directly or on a scene's model lines) at this time: its animation, skins and "
     "morph targets (default: the file's static pose)", .store = {STORE_FLOAT, ARG(frame_time), true, ARG(posed), -1e7, 1e7, false, false, "seconds (a finite number, at most 1e7 in size)"}},
    {NULL, "--animation", "N|NAME", FLAG_ANIMATION, NULL, "which glTF animation --frame-time and --frames play: its index or its name (default 0, the first)", OWN},
    {NULL, "--tile", "N", FLAG_TILE, NULL, "tile size in pixels (default 32)", .store = {STORE_INT, ARG(tile), false, 0, 1, 4096, false, false, "a tile size from 1 to 4096"}},
    {NULL, "--preview", "SECONDS", FLAG_PREVIEW, NULL,
     "live view: rewrite the output with the finished tiles every SECONDS", .store = {STORE_SECONDS, ARG(preview_seconds), false, 0, 0.1, 3600, false, false, "seconds between updates (0.1 to 3600)"}},
    {NULL, "--passes", "N", FLAG_PASSES, NULL,
     "render in passes of N samples per pixel over the whole image; 0 = tile by tile\n"
     "(default: passes of 4 for path, for parts and with --time-limit, tiles for direct and whitted)", .store = {STORE_INT, ARG(pass_samples), false, 0, 0, 1 << 20, false, false, "samples per pixel a pass from 0 (tiles) to 1048576"}},
    {NULL, "--time-limit", "SECONDS", FLAG_TIME_LIMIT, NULL,
     "stop after the pass that crosses SECONDS of rendering and write the whole image at the samples reached (in passes with every integrator; --passes 0: the tiles in hand, to NAME.partial.EXT)", .store = {STORE_SECONDS, ARG(time_limit), false, 0, 0, 1e7, true, false, "seconds (more than 0, at most 1e7)"}},
    {NULL, "--display-server", "HOST:PORT", FLAG_DISPLAY_SERVER, NULL,
     "stream the image as it renders to the tev viewer listening there (tev's default: 127.0.0.1:14158)", OWN},
    {NULL, "--window", NULL, FLAG_WINDOW, NULL,
     "show the image in a window as it renders (SDL2); it stays up after the render until closed (Esc, q)", SETS_TRUE(window)},
    {NULL, "--info", "FILE", FLAG_INFO, NULL,
     "print what a scene or model contains and how it would render (key: value lines) and exit; "
     "more files may follow (rt --info a.glb b.txt), one block each", SETS_TEXT(info_path)},
    {NULL, "--max-memory", "SIZE", FLAG_MAX_MEMORY, NULL, "memory budget, e.g. 4G or 512M; 'none' for no limit", OWN},
    {NULL, "--crop", "X0 Y0 X1 Y1", FLAG_CROP, NULL,
     "render only pixels X0 <= x < X1, Y0 <= y < Y1: with -o NAME.png (or .hdr) the cropped image, as pbrt's "
     "--pixelbounds; with no -o or -o NAME.exr (.pfm) a part (docs/farm.md): sums and counts with a NAME.json "
     "sidecar, for rt merge (--part-out FILE writes one beside a cropped image)", OWN},
    {NULL, "--part", "I/N", FLAG_PART, NULL,
     "render part I (0 .. N-1) of N bands of rows of similar cost, as a part (docs/farm.md)", OWN},
    {NULL, "--spp-range", "A:B", FLAG_SPP_RANGE, NULL,
     "render only samples A .. B-1 of every pixel (of the -s samples), as a part (docs/farm.md)", OWN},
    {NULL, "--resume", "PART", FLAG_RESUME, NULL,
     "continue a part (one stopped by --time-limit or Ctrl-C) to all samples: exactly the sums a straight render "
     "makes", SETS_TEXT(resume)},
    {NULL, "--part-out", "FILE", FLAG_PART_OUT, NULL,
     "also write the render as a part FILE (.exr or .pfm, with FILE.json), e.g. to --resume it after a stop", SETS_TEXT(part_out)},
    {NULL, "--frames", "A:B", FLAG_FRAMES, NULL,
     "render frames A .. B-1 of an animated glTF or scene (--animation), each on its own at time frame / fps; "
     "-o names them with %04d or #### (default NAME.%04d.png); a stopped frame goes to NAME.partial.EXT and "
     "NAME.part.exr, resumed by the next run", OWN},
    {NULL, "--fps", "F", FLAG_FPS, NULL, "frames per second for --frames (default 24)", .store = {STORE_SECONDS, ARG(fps), false, 0, 0, 10000, true, false, "frames per second (more than 0, at most 10000)"}},
    {NULL, "--only-frames", "C:D", FLAG_ONLY_FRAMES, NULL,
     "render only frames C .. D-1 of the --frames A:B sequence (a machine's share of it), with the automatic "
     "camera framed for all of A:B", OWN},
    {"-h", "--help", NULL, FLAG_HELP, NULL, "this text", OWN},
    {NULL, "--version", NULL, FLAG_VERSION, NULL, "print the version", OWN},
};
#define FLAG_COUNT (sizeof flags / sizeof *flags)

/* ------------------------------------------------------------ --help */

#define HELP_COLUMN 26
#define HELP_WIDTH 100

/* Prints text from column `at` on, wrapped at HELP_WIDTH with continuation
 * lines starting at `indent`; a '\n' in text starts a new line. */
static void print_wrapped(FILE *f, const char *text, int at, int indent)
{
    int col = at;
    for (const char *c = text; *c;) {
        if (*c == '\n' || *c == ' ') {
            bool forced = *c == '\n';
            c++;
            size_t next = strcspn(c, " \n");
            if (forced || col + 1 + (int)next > HELP_WIDTH) {
                fprintf(f, "\n%*s", indent, "");
                col = indent;
            } else {
                fputc(' ', f);
                col++;
            }
            continue;
        }
        size_t n = strcspn(c, " \n");
        fprintf(f, "%.*s", (int)n, c);
        col += (int)n;
        c += n;
    }
    fputc('\n', f);
}

static void usage(FILE *f)
{
    fprintf(f, "usage: rt [options] [SCENE.txt | MODEL.gltf | MODEL.glb | MESH.obj | MESH.ply | MESH.off | -]\n"
               "       rt compare CANDIDATE REFERENCE [--max-rmse X] [--max-flip X] ...  (docs/compare.md)\n"
               "       rt convert IN OUT [--exposure EV] [--tonemap NAME] [--half]  (docs/hdr.md)\n"
               "       rt merge PART... -o OUT [--exposure EV] [--tonemap NAME] [--half]  (docs/farm.md)\n"
               "\n"
               "Renders a scene to an image. With no input, renders the built-in Cornell box to out.png;\n"
               "'-' reads a scene, glTF or mesh from standard input. A model given directly renders with\n"
               "the path tracer at 64 samples per pixel; a scene file keeps its own settings (defaults below).\n"
               "\n"
               "options (a value may also follow '=', as in --samples=64; the setting flags -s, -r,\n"
               "--integrator, --seed and --set override the scene, the later flag winning):\n");
    for (size_t i = 0; i < FLAG_COUNT; i++) {
        const flag *fl = &flags[i];
        char names[64], text[512];
        snprintf(names, sizeof names, "%s%s%s%s%s%s%s", fl->short_name ? fl->short_name : "  ",
                 fl->short_name ? ", " : "  ", fl->long_name, fl->alias ? ", " : "", fl->alias ? fl->alias : "",
                 fl->value ? " " : "", fl->value ? fl->value : "");
        if (fl->kind == FLAG_SETTING) {
            const rt_setting *def = rt_setting_find(fl->setting);
            char range[128], dflt[128];
            rt_setting_range_text(def, range, sizeof range);
            rt_setting_default_text(def, dflt, sizeof dflt);
            snprintf(text, sizeof text, "%s (%s; default %s)", def->help, range, dflt);
        } else if (fl->kind == FLAG_THREADS) {
            int n = rt_cpu_count();
            snprintf(text, sizeof text, "%s (default: %d, every CPU this process may use)", fl->help, n);
        } else if (fl->kind == FLAG_MAX_MEMORY) {
            char budget[32];
            memory_budget_format(memory_budget_default(), budget, sizeof budget);
            snprintf(text, sizeof text, "%s\n(default: 75%% of physical memory, here %s)", fl->help, budget);
        } else {
            snprintf(text, sizeof text, "%s", fl->help);
        }
        if ((int)strlen(names) >= HELP_COLUMN - 3) /* a long name: its help on the next line */
            fprintf(f, "  %s\n%*s", names, HELP_COLUMN, "");
        else
            fprintf(f, "  %-*s", HELP_COLUMN - 2, names);
        print_wrapped(f, text, HELP_COLUMN, HELP_COLUMN);
    }
    fprintf(f, "\nsettings (a scene file's setting statements; --set KEY=VALUE gives any of them, its words\n"
               "separated by blanks or commas: --set background=0.1,0.2,0.3 --set resolution=640x480):\n");
    int width = 0;
    for (size_t i = 0; i < rt_settings_count; i++) {
        int w = (int)(strlen(rt_settings_table[i].name) + 1 + strlen(rt_settings_table[i].args));
        width = w > width ? w : width;
    }
    for (size_t i = 0; i < rt_settings_count; i++) {
        const rt_setting *def = &rt_settings_table[i];
        char head[128], range[128], dflt[128], text[512];
        snprintf(head, sizeof head, "%s %s", def->name, def->args);
        rt_setting_range_text(def, range, sizeof range);
        rt_setting_default_text(def, dflt, sizeof dflt);
        snprintf(text, sizeof text, "%s (%s; default %s)", def->help, range, dflt);
        fprintf(f, "  %-*s  ", width, head);
        print_wrapped(f, text, width + 4, width + 6);
    }
    fprintf(f, "\n"
               "Scene format: docs/scene-format.md; limits and exit codes: docs/robustness.md.\n"
               "Exit status: 0 ok, 2 bad input (or over a limit), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM).\n");
}

/* ------------------------------------------------------------ parsing */

static int fail_usage(const char *fmt, ...) RT_PRINTF(1, 2);
static int fail_usage(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "rt: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\nrt: see 'rt --help'\n");
    va_end(ap);
    return 2;
}

/* `-o`, `--output`, but not `-`, `-5` or `-.5` (values). */
static bool looks_like_flag(const char *s)
{
    return s[0] == '-' && s[1] != 0 && !(s[1] >= '0' && s[1] <= '9') && s[1] != '.';
}

/* True when name (NUL-terminated or not) is exactly the len bytes at a. */
static bool name_is(const char *name, const char *a, size_t len)
{
    return name && strlen(name) == len && strncmp(a, name, len) == 0;
}

/* The flag named by a[0, len): its short or long name, or its alias. */
static const flag *find_flag(const char *a, size_t len)
{
    for (size_t i = 0; i < FLAG_COUNT; i++) {
        const flag *fl = &flags[i];
        if (name_is(fl->short_name, a, len) || name_is(fl->long_name, a, len) || name_is(fl->alias, a, len))
            return fl;
    }
    return NULL;
}

/* True when `-spp`, `-samples`: a long name typed with one dash (pbrt-v3's
 * and Blender's habit), which must not read as -s with the value "pp". */
static bool find_flag_dashed(const char *a)
{
    char dashed[64];
    snprintf(dashed, sizeof dashed, "-%s", a);
    const flag *fl = find_flag(dashed, strcspn(dashed, "="));
    return fl && (name_is(fl->long_name, dashed, strcspn(dashed, "=")) || fl->alias);
}

/* An unknown flag a[0, len), refused with the long name closest to it
 * (rt/base/near_miss.h), as the scene parser does for keywords: `--sampels`
 * -> '--samples', `-spp` -> '--spp'. */
static int unknown_flag(const char *a, size_t len)
{
    char word[64];
    snprintf(word, sizeof word, "%s%.*s", a[1] == '-' ? "" : "-", (int)(len < 60 ? len : 60), a);
    rt_near_miss n = rt_near_miss_of(word);
    for (size_t i = 0; i < FLAG_COUNT && strlen(word) >= 5; i++) { /* not for `-x`: every short word is near one */
        rt_near_miss_consider(&n, flags[i].long_name);
        if (flags[i].alias)
            rt_near_miss_consider(&n, flags[i].alias);
    }
    if (n.best)
        return fail_usage("unknown option '%.*s' (did you mean '%s'?)", (int)len, a, n.best);
    return fail_usage("unknown option '%.*s'", (int)len, a);
}

/* An integer flag value in [lo, hi]. */
static bool int_value(const char *s, long long lo, long long hi, int *out)
{
    long long v = 0;
    if (rt_parse_int(s, &v) != RT_NUMBER_OK || v < lo || v > hi)
        return false;
    *out = (int)v;
    return true;
}

/* What a setting flag accepts, for its error message: "samples per pixel
 * from 1 to 1048576", "WIDTHxHEIGHT with sides from 1 to 32768", "direct,
 * whitted or path". */
static void setting_wants(const rt_setting *def, char *buf, size_t size)
{
    switch (def->type) {
    case RT_SETTING_INT:
    case RT_SETTING_UINT32:
        snprintf(buf, size, "%s from %lld to %lld", def->help, (long long)def->min, (long long)def->max);
        return;
    case RT_SETTING_SIZE:
        snprintf(buf, size, "WIDTHxHEIGHT with sides from %lld to %lld", (long long)def->min, (long long)def->max);
        return;
    case RT_SETTING_ENUM: {
        size_t o = 0;
        buf[0] = 0;
        for (size_t i = 0; def->words[i] && o < size; i++) {
            const char *sep = i == 0 ? "" : def->words[i + 1] ? ", " : " or ";
            int n = snprintf(buf + o, size - o, "%s%s", sep, def->words[i]);
            o += n > 0 ? (size_t)n : 0;
        }
        return;
    }
    default: {
        char range[128];
        rt_setting_range_text(def, range, sizeof range);
        snprintf(buf, size, "%s (%s)", def->help, range);
        return;
    }
    }
}

/* An item of a comma list, the n bytes at s, into out (cap bytes) without
 * the blanks around it (`--look-from "0, 1, 5"`); false when it does not fit. */
static bool list_item(const char *s, size_t n, char *out, size_t cap)
{
    while (n && (*s == ' ' || *s == '\t'))
        s++, n--;
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t'))
        n--;
    if (n >= cap)
        return false;
    memcpy(out, s, n);
    out[n] = 0;
    return true;
}

/* "X,Y,Z": three finite numbers separated by commas (blanks around them allowed). */
static bool vec3_value(const char *s, rt_vec3 *out)
{
    float v[3];
    char part[64];
    for (int i = 0; i < 3; i++) {
        size_t n = strcspn(s, ",");
        if ((i < 2 ? s[n] != ',' : s[n] != 0) || !list_item(s, n, part, sizeof part))
            return false;
        if (rt_parse_float(part, &v[i]) != RT_NUMBER_OK || !isfinite(v[i]))
            return false;
        s += n + (i < 2);
    }
    *out = rt_v3(v[0], v[1], v[2]);
    return true;
}

static int add_setting(args *a, const char *name, const char *arg, const rt_setting *def, const char *value)
{
    if (a->setting_count >= ARGS_MAX_SETTINGS)
        return fail_usage("%s: too many setting flags (at most %d)", name, ARGS_MAX_SETTINGS);
    a->settings[a->setting_count++] = (setting_flag){name, arg, def, value};
    return ARGS_OK;
}

/* --set KEY=VALUE */
static int parse_set(args *a, const char *name, const char *arg)
{
    const char *eq = strchr(arg, '=');
    char key[64];
    if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof key)
        return fail_usage("%s wants KEY=VALUE (a scene setting and its value, e.g. samples=64), got '%s'", name, arg);
    memcpy(key, arg, (size_t)(eq - arg));
    key[eq - arg] = 0;
    const rt_setting *def = rt_setting_find(key);
    if (!def) {
        char names[1024];
        size_t o = 0;
        for (size_t i = 0; i < rt_settings_count && o < sizeof names; i++) {
            int n = snprintf(names + o, sizeof names - o, "%s%s", i ? ", " : "", rt_settings_table[i].name);
            o += n > 0 ? (size_t)n : 0;
        }
        return fail_usage("%s %s: no setting is called '%s' (the settings: %s)", name, arg, key, names);
    }
    rt_setting_problem pb;
    if (rt_setting_set(NULL, NULL, def, eq + 1, &pb) != RT_OK)
        return fail_usage("%s %s: %s", name, arg, pb.message);
    return add_setting(a, name, arg, def, eq + 1);
}

/* A plain flag's value stored as its table line says (flag_store), or the
 * message for one out of its range. */
static int store_flag(args *a, const flag *fl, const char *name, const char *value)
{
    const flag_store *st = &fl->store;
    char *field = (char *)a + st->field;
    float v = 0.0f;
    switch (st->kind) {
    case STORE_NONE:
        return ARGS_OK;
    case STORE_TEXT:
        *(const char **)field = value;
        break;
    case STORE_TRUE:
        *(bool *)field = true;
        break;
    case STORE_INT:
        if (!int_value(value, (long long)st->min, (long long)st->max, (int *)field))
            return fail_usage("%s wants %s, got '%s'", name, st->wants, value);
        break;
    case STORE_FLOAT:
    case STORE_SECONDS: {
        bool ok = rt_parse_float(value, &v) == RT_NUMBER_OK;
        ok = ok && (st->above_min ? v > (float)st->min : v >= (float)st->min);
        ok = ok && (st->below_max ? v < (float)st->max : v <= (float)st->max);
        if (!ok)
            return fail_usage("%s wants %s, got '%s'", name, st->wants, value);
        if (st->kind == STORE_FLOAT)
            *(float *)field = v;
        else
            *(double *)field = (double)v;
        break;
    }
    }
    if (st->marks)
        *(bool *)((char *)a + st->given) = true;
    return ARGS_OK;
}

/* -s, -r, --integrator, --seed: a setting of the table, checked now,
 * applied after the load. */
static int parse_setting_flag(args *a, const flag *fl, const char *name, const char *value)
{
    const rt_setting *def = rt_setting_find(fl->setting);
    rt_setting_problem pb;
    if (rt_setting_set(NULL, NULL, def, value, &pb) != RT_OK) {
        char wants[256];
        setting_wants(def, wants, sizeof wants);
        return fail_usage("%s wants %s, got '%s'", name, wants, value);
    }
    return add_setting(a, name, value, def, value);
}

/* --camera, --animation, --variant, --look-from, --look-at, --up. */
static int parse_view_flag(args *a, const flag *fl, const char *name, const char *value)
{
    if (fl->kind == FLAG_ANIMATION) { /* an index, or the animation's name */
        a->posed = true;
        a->animation = 0;
        a->animation_name = NULL;
        if (*value >= '0' && *value <= '9') {
            if (!int_value(value, 0, 1000000, &a->animation))
                return fail_usage("%s wants an animation index (0 = the first) or name, got '%s'", name, value);
        } else if (*value) {
            a->animation_name = value;
        } else {
            return fail_usage("%s wants an animation index (0 = the first) or name", name);
        }
        return ARGS_OK;
    }
    if (fl->kind == FLAG_CAMERA) {
        a->camera_auto = strcmp(value, "auto") == 0;
        a->camera = -1;
        if (!a->camera_auto && !int_value(value, 0, INT32_MAX, &a->camera))
            return fail_usage("%s wants a camera index (0, 1, ...) or 'auto', got '%s'", name, value);
        return ARGS_OK;
    }
    if (fl->kind == FLAG_VARIANT) {
        if (!*value)
            return fail_usage("%s wants the name of a material variant", name);
        a->variant = value;
        return ARGS_OK;
    }
    rt_vec3 v;
    if (!vec3_value(value, &v))
        return fail_usage("%s wants three numbers X,Y,Z (e.g. 0,1,5), got '%s'", name, value);
    if (fl->kind == FLAG_UP && v.x == 0.0f && v.y == 0.0f && v.z == 0.0f)
        return fail_usage("%s wants a direction, got the zero vector '%s'", name, value);
    if (fl->kind == FLAG_LOOK_FROM)
        a->look_from = v, a->has_look_from = true;
    else if (fl->kind == FLAG_LOOK_AT)
        a->look_at = v, a->has_look_at = true;
    else
        a->up = v, a->has_up = true;
    return ARGS_OK;
}

/* --aov LIST: names of rt_aov_names, comma-separated. */
static int parse_aovs(args *a, const char *name, const char *value)
{
    const char *s = value;
    while (*s) {
        size_t n = strcspn(s, ",");
        char item[32];
        rt_aov_kind k;
        bool fits = list_item(s, n, item, sizeof item);
        if (!fits || !rt_aov_by_name(item, strlen(item), &k))
            return fail_usage("%s: unknown AOV '%.*s' (albedo, normal, depth, position, variance, spp)", name,
                              fits ? (int)strlen(item) : (int)n, fits ? item : s);
        a->aovs |= 1u << k;
        s += n + (s[n] == ',');
    }
    if (!a->aovs)
        return fail_usage("%s wants a list such as albedo,normal", name);
    return ARGS_OK;
}

/* --tonemap, --denoise-quality, --aov, --display-server, --max-memory. */
static int parse_output_flag(args *a, const flag *fl, const char *name, const char *value)
{
    char host[256], port[16];
    switch (fl->kind) {
    case FLAG_TONEMAP:
        if (!rt_tonemap_parse(value, &a->tonemap))
            return fail_usage("%s wants one of %s, got '%s'", name, RT_TONEMAP_NAMES, value);
        return ARGS_OK;
    case FLAG_DENOISE_QUALITY:
        if (!rt_denoise_quality_parse(value, &a->denoise_quality))
            return fail_usage("%s wants %s, got '%s'", name, RT_DENOISE_QUALITY_NAMES, value);
        return ARGS_OK;
    case FLAG_AOV:
        return parse_aovs(a, name, value);
    case FLAG_DISPLAY_SERVER:
        if (!tev_parse_address(value, host, sizeof host, port, sizeof port))
            return fail_usage("%s wants HOST:PORT with a port from 1 to 65535 (e.g. 127.0.0.1:14158), got '%s'", name,
                              value);
        a->display_server = value;
        return ARGS_OK;
    default: /* FLAG_MAX_MEMORY */
        if (!memory_budget_parse(value, &a->budget.bytes))
            return fail_usage("%s wants a size such as 4G, 512M or 'none', got '%s'", name, value);
        if (a->budget.bytes && a->budget.bytes < (64ull << 20))
            return fail_usage("%s: '%s' is below the 64M rt needs to start", name, value);
        a->budget.from_flag = true;
        return ARGS_OK;
    }
}

/* "A:B" (or "A/B" for --part) into *lo, *hi, each checked against its
 * range; false when it is not two integers so. */
static bool int_pair(const char *value, char sep, long long lo_min, long long lo_max, long long hi_min,
                     long long hi_max, int *lo, int *hi)
{
    const char *mid = strchr(value, sep);
    char first[32];
    if (!mid || (size_t)(mid - value) >= sizeof first)
        return false;
    memcpy(first, value, (size_t)(mid - value));
    first[mid - value] = 0;
    return int_value(first, lo_min, lo_max, lo) && int_value(mid + 1, hi_min, hi_max, hi);
}

/* --crop X0 Y0 X1 Y1 (four words, pbrt's habit, or X0,Y0,X1,Y1); *i moves
 * past the words it takes. */
static int parse_crop(args *a, const char *name, const char *value, int argc, char **argv, int *i)
{
    const char *w[4] = {value, NULL, NULL, NULL};
    char buf[128];
    int nw = 1;
    if (strchr(value, ',')) {
        snprintf(buf, sizeof buf, "%s", value);
        char *c = buf;
        for (nw = 0; nw < 4 && c; nw++) {
            w[nw] = c;
            c = strchr(c, ',');
            if (c)
                *c++ = 0;
            list_item(w[nw], strlen(w[nw]), (char *)w[nw], strlen(w[nw]) + 1); /* "0, 0, 64, 32" */
        }
        if (c)
            nw = 5;
    } else {
        while (nw < 4 && *i + 1 < argc && !looks_like_flag(argv[*i + 1]))
            w[nw++] = argv[++*i];
    }
    bool ok = nw == 4;
    for (int k = 0; k < 4 && ok; k++)
        ok = int_value(w[k], 0, 32768, &a->crop[k]);
    if (!ok || a->crop[0] >= a->crop[2] || a->crop[1] >= a->crop[3])
        return fail_usage("%s wants four pixel bounds X0 Y0 X1 Y1 with X0 < X1 and Y0 < Y1 (half-open: "
                          "--crop 0 0 64 32 is the top-left 64x32 pixels)",
                          name);
    a->has_crop = true;
    return ARGS_OK;
}

/* --crop, --part, --spp-range, --frames. */
static int parse_part_flag(args *a, const flag *fl, const char *name, const char *value, int argc, char **argv,
                           int *i)
{
    switch (fl->kind) {
    case FLAG_CROP:
        return parse_crop(a, name, value, argc, argv, i);
    case FLAG_PART:
        if (!strchr(value, '/') || strchr(value, '/') - value >= 32)
            return fail_usage("%s wants I/N (part I of N, I from 0 to N-1), got '%s'", name, value);
        if (!int_pair(value, '/', 0, 32767, 1, 32768, &a->part_index, &a->part_count) ||
            a->part_index >= a->part_count)
            return fail_usage("%s wants I/N with N from 1 to 32768 and I from 0 to N-1 (parts count from 0), "
                              "got '%s'",
                              name, value);
        return ARGS_OK;
    case FLAG_SPP_RANGE:
        if (!strchr(value, ':') || strchr(value, ':') - value >= 32)
            return fail_usage("%s wants A:B (samples A to B-1), got '%s'", name, value);
        if (!int_pair(value, ':', 0, RT_MAX_SAMPLES - 1, 1, RT_MAX_SAMPLES, &a->spp_begin, &a->spp_end) ||
            a->spp_begin >= a->spp_end)
            return fail_usage("%s wants A:B with 0 <= A < B <= %d (samples A to B-1), got '%s'", name,
                              RT_MAX_SAMPLES, value);
        a->has_spp_range = true;
        return ARGS_OK;
    default: { /* FLAG_FRAMES, FLAG_ONLY_FRAMES */
        bool only = fl->kind == FLAG_ONLY_FRAMES;
        if (!strchr(value, ':') || strchr(value, ':') - value >= 32)
            return fail_usage("%s wants A:B (frames A to B-1), got '%s'", name, value);
        if (!int_pair(value, ':', 0, 99999999, 1, 100000000, only ? &a->only_begin : &a->frame_begin,
                      only ? &a->only_end : &a->frame_end) ||
            (only ? a->only_begin >= a->only_end : a->frame_begin >= a->frame_end))
            return fail_usage("%s wants A:B with 0 <= A < B <= 100000000 (frames A to B-1), got '%s'", name, value);
        *(only ? &a->has_only_frames : &a->has_frames) = true;
        return ARGS_OK;
    }
    }
}

/* One flag (its value taken): the table's plain store, or its own code.
 * Returns ARGS_OK, or the exit status (0 after --help and --version). */
static int parse_flag(args *a, const flag *fl, const char *name, const char *value, int argc, char **argv, int *i)
{
    switch (fl->kind) {
    case FLAG_HELP:
        usage(stdout);
        return 0;
    case FLAG_VERSION:
        printf("rt %s\n", RT_VERSION);
        return 0;
    case FLAG_SETTING:
        return parse_setting_flag(a, fl, name, value);
    case FLAG_SET:
        return parse_set(a, name, value);
    case FLAG_QUIET:
        a->log_level = RT_LOG_QUIET;
        return ARGS_OK;
    case FLAG_VERBOSE:
        a->log_level = RT_LOG_VERBOSE;
        return ARGS_OK;
    case FLAG_CAMERA:
    case FLAG_ANIMATION:
    case FLAG_VARIANT:
    case FLAG_LOOK_FROM:
    case FLAG_LOOK_AT:
    case FLAG_UP:
        return parse_view_flag(a, fl, name, value);
    case FLAG_TONEMAP:
    case FLAG_DENOISE_QUALITY:
    case FLAG_AOV:
    case FLAG_DISPLAY_SERVER:
    case FLAG_MAX_MEMORY:
        return parse_output_flag(a, fl, name, value);
    case FLAG_CROP:
    case FLAG_PART:
    case FLAG_SPP_RANGE:
    case FLAG_FRAMES:
    case FLAG_ONLY_FRAMES:
        return parse_part_flag(a, fl, name, value, argc, argv, i);
    default: {
        int r = store_flag(a, fl, name, value);
        if (r == ARGS_OK && fl->kind == FLAG_PASSES && a->pass_samples == 0)
            a->pass_samples = -1; /* rt_render's "tiles" */
        return r;
    }
    }
}

/* Flags that do not go together, once all are read. */
static int check_combinations(const args *a)
{
    if (a->denoise_quality != RT_DENOISE_DEFAULT && !a->denoise)
        return fail_usage("--denoise-quality goes with --denoise (rt --denoise --denoise-quality high ...)");
    if (a->part_count && a->has_crop)
        return fail_usage("--part and --crop both choose the region; give one of them");
    if (a->has_only_frames && (!a->has_frames || a->only_begin < a->frame_begin || a->only_end > a->frame_end))
        return fail_usage("--only-frames %d:%d: a share of the --frames A:B sequence, within it%s", a->only_begin,
                          a->only_end, a->has_frames ? "" : " (no --frames given)");
    if (a->has_frames && a->posed && a->frame_time != 0.0f)
        return fail_usage("--frames sets each frame's time (frame / fps); drop --frame-time");
    if (a->resume && (a->part_count || a->has_crop || a->has_spp_range))
        return fail_usage("--resume takes the region and samples from the part it continues; drop --part, --crop "
                          "and --spp-range");
    if (!a->info_path && a->more_input_count)
        return fail_usage("only one input file, please (got a second: '%s'); --info takes several",
                          a->more_inputs[0]);
    return ARGS_OK;
}

int args_parse(args *a, int argc, char **argv)
{
    memset(a, 0, sizeof *a);
    a->camera = -1;
    a->log_level = RT_LOG_NORMAL;
    a->budget.bytes = memory_budget_default();
    a->fps = 24.0;
    bool flags_ended = false;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (flags_ended || !looks_like_flag(arg)) {
            if (!a->input)
                a->input = arg;
            else if (a->more_input_count < ARGS_MAX_INPUTS)
                a->more_inputs[a->more_input_count++] = arg;
            else
                return fail_usage("too many input files (--info reports at most %d at once)", ARGS_MAX_INPUTS);
            continue;
        }
        if (strcmp(arg, "--") == 0) {
            flags_ended = true;
            continue;
        }
        /* --name=value */
        const char *eq = strncmp(arg, "--", 2) == 0 ? strchr(arg, '=') : NULL;
        size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
        const flag *fl = find_flag(arg, len);
        const char *attached = NULL; /* -s4, -r320x240, -Dsamples=4: a short flag's value in the same word */
        if (!fl && arg[1] != '-' && !find_flag_dashed(arg)) {
            fl = find_flag(arg, 2);
            attached = fl && fl->value ? arg + 2 : NULL;
        }
        if (!fl || (fl->short_name && !fl->value && arg[1] != '-' && len > 2))
            return unknown_flag(arg, len);
        /* the name as typed, for messages (kept: a setting flag's message comes after the load) */
        const char *name = attached ? fl->short_name : !eq ? arg : name_is(fl->alias, arg, len) ? fl->alias : fl->long_name;
        const char *value = NULL;
        if (fl->value) {
            if (attached)
                value = attached;
            else if (eq)
                value = eq + 1;
            else if (i + 1 < argc && !looks_like_flag(argv[i + 1]))
                value = argv[++i];
            else
                return fail_usage("option %s needs a value (%s %s)", name, name, fl->value);
        } else if (eq) {
            return fail_usage("option %s takes no value, got '%s'", name, arg);
        }
        int r = parse_flag(a, fl, name, value, argc, argv, &i);
        if (r != ARGS_OK)
            return r;
    }
    return check_combinations(a);
}

/* --crop with -o naming an image format (.png, .hdr) is the cropped image,
 * as pbrt-v4's --pixelbounds gives it; with .exr, .pfm or no -o, a part. */
static bool crop_is_image(const args *a) { return a->has_crop && a->output && !rt_part_path_ok(a->output); }

bool args_output_is_part(const args *a)
{
    return (a->has_crop && !crop_is_image(a)) || a->part_count > 0 || a->has_spp_range;
}

bool args_sets(const args *a, const char *name)
{
    for (size_t i = 0; i < a->setting_count; i++)
        if (strcmp(a->settings[i].setting->name, name) == 0)
            return true;
    return false;
}

void args_job_options(const args *a, rt_job_options *o)
{
    *o = (rt_job_options){.input = a->input,
                          .threads = a->threads,
                          .posed = a->posed,
                          .frame_time = a->frame_time,
                          .animation = a->animation,
                          .animation_name = a->animation_name,
                          .use_camera = a->camera >= 0,
                          .camera = a->camera,
                          .camera_auto = a->camera_auto,
                          .has_look_from = a->has_look_from,
                          .has_look_at = a->has_look_at,
                          .has_up = a->has_up,
                          .has_fov = a->has_fov,
                          .look_from = a->look_from,
                          .look_at = a->look_at,
                          .up = a->up,
                          .fov = a->fov,
                          .exposure_ev = a->exposure_ev,
                          .tonemap = a->tonemap,
                          .half = a->half,
                          .denoise = a->denoise,
                          .denoise_quality = a->denoise_quality,
                          .aovs = a->aovs,
                          .output_is_part = args_output_is_part(a),
                          .has_crop = a->has_crop,
                          .crop = {a->crop[0], a->crop[1], a->crop[2], a->crop[3]},
                          .part_index = a->part_index,
                          .part_count = a->part_count,
                          .has_spp_range = a->has_spp_range,
                          .spp_begin = a->spp_begin,
                          .spp_end = a->spp_end,
                          .resume = a->resume,
                          .part_out = a->part_out};
}

rt_result args_apply_settings(const args *a, rt_scene *s, rt_settings *settings, rt_error *err)
{
    for (size_t i = 0; i < a->setting_count; i++) {
        const setting_flag *sf = &a->settings[i];
        rt_setting_problem pb;
        if (rt_setting_set(settings, &s->environment, sf->setting, sf->value, &pb) != RT_OK)
            return rt_fail(err, pb.code, "%s %s: %s", sf->flag, sf->arg, pb.message);
        rt_error inner = {0};
        rt_result r = rt_environment_image_load(s, &inner); /* --set environment=FILE: its image */
        if (r != RT_OK)
            return rt_fail(err, r, "%s %s: %s", sf->flag, sf->arg, inner.message);
    }
    return RT_OK;
}
