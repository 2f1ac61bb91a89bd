/* settings.c - the one table of render settings (settings.h) and what it
 * drives: reading and checking a setting's words, storing them into
 * rt_settings, and the texts for help and documentation (the defaults are
 * rt_settings_default()'s, scene.c, beside the struct they fill). It knows
 * no scene and reads no file: the environment's image file is a name here,
 * loaded by io (rt/io/environment_image.h).
 *
 * The table follows yocto-gl's habit of one parameter table behind both the
 * scene format and the command line. Messages keep the scene parser's
 * wording ("expected an integer for samples per pixel", "the exposure must be
 * > 0"); the caller adds the location (file:line:col, or the flag).
 */
#include "rt/render/settings.h"

#include <float.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "rt/base/file.h"
#include "rt/base/number.h"
#include "rt/render/integrator.h"

#define MAX_PATH_LEN 4096 /* the scene format's limit on file paths */

_Static_assert(sizeof(rt_integrator) == sizeof(int), "enum settings are stored as int");

#define FIELD(f) offsetof(rt_settings, f)
#define FIELD_SIZE(f) sizeof(((rt_settings *)0)->f)

static const char *const onoff_words[] = {"off", "on", NULL};
/* in rt_sampler_kind order (rt/scene/scene.h) */
static const char *const sampler_words[] = {"independent", "cmj", "sobol", NULL};

/* Table order is the order of --help and of the scene parser's "did you mean" search. */
const rt_setting rt_settings_table[] = {
    {.name = "resolution", .args = "W H", .type = RT_SETTING_SIZE, .field = FIELD(width), .field2 = FIELD(height),
     .min = 1, .max = RT_MAX_IMAGE_SIDE, .what = "the image",
     .help = "image width and height in pixels"},
    {.name = "samples", .args = "N", .type = RT_SETTING_INT, .field = FIELD(samples), .min = 1,
     .max = RT_MAX_SAMPLES, .what = "samples per pixel", .help = "samples per pixel"},
    {.name = "integrator", .args = "NAME", .type = RT_SETTING_ENUM, .field = FIELD(integrator), .words = rt_integrator_words, .what = "an integrator",
     .help = "light transport: direct light only, Whitted ray tracing or path tracing"},
    {.name = "max_bounce", .args = "N", .type = RT_SETTING_INT, .field = FIELD(max_bounce), .min = 0, .max = 256, .what = "max_bounce", .help = "whitted: mirror and refraction recursion depth"},
    {.name = "max_depth", .args = "N", .type = RT_SETTING_INT, .field = FIELD(max_depth), .min = 0, .max = 1024, .what = "max_depth", .help = "path: the most scattering events a path may have; 0 = no cap"},
    {.name = "rr_depth", .args = "N", .type = RT_SETTING_INT, .field = FIELD(rr_depth), .min = 0, .max = 1024, .what = "rr_depth",
     .help = "path: Russian roulette from this many bounces on; 0 = adaptive (once the throughput is below 1)"},
    {.name = "motion_steps", .args = "K", .type = RT_SETTING_INT, .field = FIELD(motion_steps), .min = 1,
     .max = 256, .what = "motion_steps",
     .help = "motion blur: poses (each with its own kd-tree) over the camera's shutter when models are animated"},
    {.name = "sampler", .args = "NAME", .type = RT_SETTING_ENUM, .field = FIELD(sampler), .words = sampler_words, .what = "a sampler",
     .help = "path: the random numbers of light, BSDF and roulette decisions: a stream per sample, or stratified over the pixel's samples (cmj, sobol)"},
    {.name = "energy_compensation", .args = "MODE", .type = RT_SETTING_ENUM, .field = FIELD(energy_compensation), .words = onoff_words, .what = "energy_compensation",
     .help = "path: restore the energy rough conductors lose to multiple scattering (Kulla-Conty 2017)"},
    {.name = "diffuse_bounces", .args = "N", .type = RT_SETTING_INT, .field = FIELD(diffuse_bounces), .min = 0,
     .max = 64, .what = "diffuse_bounces", .help = "whitted: levels of indirect diffuse light"},
    {.name = "diffuse_rays", .args = "N", .type = RT_SETTING_INT, .field = FIELD(diffuse_rays), .min = 1,
     .max = 65536, .what = "diffuse_rays", .help = "whitted: cosine-distributed rays per diffuse level"},
    {.name = "shadow_samples", .args = "N", .type = RT_SETTING_INT, .field = FIELD(shadow_samples), .min = 1,
     .max = 65536, .what = "shadow_samples", .help = "samples per area light per shading point"},
    {.name = "seed", .args = "N", .type = RT_SETTING_UINT32, .field = FIELD(seed), .min = 0, .max = UINT32_MAX, .what = "the seed", .help = "a random seed"},
    {.name = "background", .args = "R G B", .type = RT_SETTING_COLOR, .field = FIELD(background), .min = 0,
     .max = FLT_MAX, .what = "the background colour",
     .help = "radiance of rays that leave the scene, linear RGB"},
    {.name = "ambient_light", .args = "R G B", .type = RT_SETTING_COLOR, .field = FIELD(ambient_light),
     .marks_given = true, .given = FIELD(ambient_light_set), .min = 0, .max = FLT_MAX,
     .what = "the ambient light colour",
     .help = "whitted: the ambient radiance materials reflect; unset = the background's"},
    {.name = "exposure", .args = "X", .type = RT_SETTING_FLOAT, .field = FIELD(exposure), .min = 0, .max = FLT_MAX,
     .above_min = true, .what = "the exposure",
     .help = "linear scale applied before writing 8-bit output"},
    {.name = "clamp", .args = "X", .type = RT_SETTING_FLOAT, .field = FIELD(clamp), .min = 0, .max = FLT_MAX, .what = "the clamp", .help = "maximum sample luminance, against fireflies; 0 = no clamp"},
    {.name = "ray_offset", .args = "X", .type = RT_SETTING_FLOAT, .field = FIELD(ray_offset), .min = 0,
     .max = FLT_MAX, .what = "the ray offset",
     .help = "extra offset of secondary rays in scene units, on top of the automatic one"},
    {.name = "environment", .args = "FILE [strength S]", .type = RT_SETTING_ENVIRONMENT,
     .field = FIELD(environment_texture), .field2 = FIELD(environment_strength), .min = 0, .max = FLT_MAX, .what = "environment",
     .help = "latitude-longitude environment image in place of the background, scaled by S"},
    {.name = "output", .args = "FILE", .type = RT_SETTING_STRING, .field = FIELD(output), .min = 1,
     .max = FIELD_SIZE(output) - 1, .what = "an output file name",
     .help = "default output image name, used when the driver gets no -o"},
};
const size_t rt_settings_count = sizeof rt_settings_table / sizeof *rt_settings_table;
_Static_assert(sizeof rt_settings_table / sizeof *rt_settings_table <= RT_SETTINGS_MAX, "raise RT_SETTINGS_MAX");

const rt_setting *rt_setting_find(const char *name)
{
    for (size_t i = 0; i < rt_settings_count; i++)
        if (strcmp(rt_settings_table[i].name, name) == 0)
            return &rt_settings_table[i];
    return NULL;
}

/* ------------------------------------------------------------ fields */

static void *field_of(rt_settings *st, size_t offset)
{
    return (char *)st + offset;
}

static const void *const_field_of(const rt_settings *st, size_t offset)
{
    return (const char *)st + offset;
}

/* Writes an already checked value into its field(s); the environment's
 * file name by store_environment() instead. */
static void store_value(rt_settings *st, const rt_setting *def, const rt_setting_value *v)
{
    switch (def->type) {
    case RT_SETTING_INT:
    case RT_SETTING_ENUM:
        *(int *)field_of(st, def->field) = (int)v->i[0];
        break;
    case RT_SETTING_UINT32:
        *(uint32_t *)field_of(st, def->field) = (uint32_t)v->i[0];
        break;
    case RT_SETTING_SIZE:
        *(int *)field_of(st, def->field) = (int)v->i[0];
        *(int *)field_of(st, def->field2) = (int)v->i[1];
        break;
    case RT_SETTING_FLOAT:
        *(float *)field_of(st, def->field) = v->f[0];
        break;
    case RT_SETTING_COLOR:
        *(rt_vec3 *)field_of(st, def->field) = rt_v3(v->f[0], v->f[1], v->f[2]);
        break;
    case RT_SETTING_STRING:
        memcpy(field_of(st, def->field), v->text, strlen(v->text) + 1);
        break;
    case RT_SETTING_ENVIRONMENT: /* store_environment() */
        break;
    }
}

/* ------------------------------------------------------------ reading */

static rt_result problem(rt_setting_problem *pb, rt_result code, size_t word, bool got, const char *fmt, ...)
    RT_PRINTF(5, 6);
static rt_result problem(rt_setting_problem *pb, rt_result code, size_t word, bool got, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(pb->message, sizeof pb->message, fmt, ap);
    va_end(ap);
    pb->code = code;
    pb->word = word;
    pb->got = got;
    return code;
}

/* The words a value is read from; a quoted word is text, never a number or keyword. */
typedef struct words {
    const char *const *w;
    const bool *quoted;
    size_t count;
} words;

static bool literal(const words *ws, size_t i)
{
    return !ws->quoted || !ws->quoted[i];
}

static rt_result read_int(const words *ws, size_t i, const char *what, double lo, double hi, long long *out,
                          rt_setting_problem *pb)
{
    if (i >= ws->count)
        return problem(pb, RT_ERR_PARSE, i, true, "expected an integer for %s", what);
    rt_number_status st = literal(ws, i) ? rt_parse_int(ws->w[i], out) : RT_NUMBER_BAD;
    if (st == RT_NUMBER_BAD)
        return problem(pb, RT_ERR_PARSE, i, true, "expected an integer for %s", what);
    if (st == RT_NUMBER_RANGE || (double)*out < lo || (double)*out > hi)
        return problem(pb, RT_ERR_INVALID, i, true, "%s must be between %lld and %lld", what, (long long)lo,
                       (long long)hi);
    return RT_OK;
}

/* The message for a float outside [lo, hi] (or not above lo). */
static rt_result float_range_problem(rt_setting_problem *pb, size_t i, bool got, const char *what, double lo,
                                     double hi, bool above)
{
    if (above)
        return problem(pb, RT_ERR_INVALID, i, got, "%s must be > %g", what, lo);
    if (hi >= FLT_MAX)
        return problem(pb, RT_ERR_INVALID, i, got, "%s must be >= %g", what, lo);
    if (lo <= -FLT_MAX)
        return problem(pb, RT_ERR_INVALID, i, got, "%s must be <= %g", what, hi);
    return problem(pb, RT_ERR_INVALID, i, got, "%s must be between %g and %g", what, lo, hi);
}

static bool float_in_range(float v, double lo, double hi, bool above)
{
    return above ? (double)v > lo && (double)v <= hi : (double)v >= lo && (double)v <= hi;
}

static rt_result read_float(const words *ws, size_t i, const char *what, double lo, double hi, bool above,
                            float *out, rt_setting_problem *pb)
{
    if (i >= ws->count)
        return problem(pb, RT_ERR_PARSE, i, true, "expected a number for %s", what);
    rt_number_status st = literal(ws, i) ? rt_parse_float(ws->w[i], out) : RT_NUMBER_BAD;
    if (st == RT_NUMBER_RANGE)
        return problem(pb, RT_ERR_INVALID, i, true, "%s is out of range (beyond +-3.4e38)", what);
    if (st == RT_NUMBER_BAD)
        return problem(pb, RT_ERR_PARSE, i, true, "expected a number for %s", what);
    if (!float_in_range(*out, lo, hi, above))
        return float_range_problem(pb, i, true, what, lo, hi, above);
    return RT_OK;
}

static size_t word_count(const char *const *list)
{
    size_t n = 0;
    while (list[n])
        n++;
    return n;
}

/* "direct|whitted|path" */
static void join_words(const char *const *list, const char *sep, char *buf, size_t size)
{
    size_t o = 0;
    buf[0] = 0;
    for (size_t i = 0; list[i] && o < size; i++) {
        int n = snprintf(buf + o, size - o, "%s%s", i ? sep : "", list[i]);
        if (n < 0)
            break;
        o += (size_t)n;
    }
}

static const char *const color_parts[3] = {"red", "green", "blue"};

rt_result rt_setting_read(const rt_setting *def, const char *const *w, const bool *quoted, size_t count,
                          rt_setting_value *v, rt_setting_problem *pb)
{
    const words ws = {w, quoted, count};
    char what[256];
    rt_result r = RT_OK;
    memset(v, 0, sizeof *v);
    switch (def->type) {
    case RT_SETTING_INT:
    case RT_SETTING_UINT32:
        r = read_int(&ws, 0, def->what, def->min, def->max, &v->i[0], pb);
        v->words = 1;
        break;
    case RT_SETTING_SIZE:
        snprintf(what, sizeof what, "%s width", def->what);
        if ((r = read_int(&ws, 0, what, def->min, def->max, &v->i[0], pb)) != RT_OK)
            break;
        snprintf(what, sizeof what, "%s height", def->what);
        r = read_int(&ws, 1, what, def->min, def->max, &v->i[1], pb);
        v->words = 2;
        break;
    case RT_SETTING_FLOAT:
        r = read_float(&ws, 0, def->what, def->min, def->max, def->above_min, &v->f[0], pb);
        v->words = 1;
        break;
    case RT_SETTING_COLOR:
        for (size_t i = 0; i < 3 && r == RT_OK; i++) {
            snprintf(what, sizeof what, "%s (%s)", def->what, color_parts[i]);
            r = read_float(&ws, i, what, def->min, def->max, false, &v->f[i], pb);
        }
        v->words = 3;
        break;
    case RT_SETTING_ENUM: {
        char choices[256];
        join_words(def->words, "|", choices, sizeof choices);
        v->words = 1;
        if (count > 0 && literal(&ws, 0))
            for (size_t i = 0; def->words[i]; i++)
                if (strcmp(w[0], def->words[i]) == 0) {
                    v->i[0] = (long long)i;
                    return RT_OK;
                }
        return problem(pb, RT_ERR_PARSE, 0, true, "expected %s (%s)", def->what, choices);
    }
    case RT_SETTING_STRING:
        if (count < 1)
            return problem(pb, RT_ERR_PARSE, 0, true, "expected %s", def->what);
        v->text = w[0];
        v->words = 1;
        break;
    case RT_SETTING_ENVIRONMENT: {
        if (count < 1)
            return problem(pb, RT_ERR_PARSE, 0, true, "expected an %s image file", def->what);
        v->text = w[0];
        rt_settings d; /* the strength when the line gives none: the default's */
        rt_settings_default(&d);
        v->f[0] = *(const float *)const_field_of(&d, def->field2);
        v->words = 1;
        if (count > 1 && literal(&ws, 1) && strcmp(w[1], "strength") == 0) {
            snprintf(what, sizeof what, "the %s strength", def->what);
            r = read_float(&ws, 2, what, def->min, def->max, false, &v->f[0], pb);
            v->words = 3;
        }
        break;
    }
    }
    return r;
}

/* ------------------------------------------------------------ storing */

/* The environment: the file name (relative to dir) and the strength; the
 * image is not loaded yet (environment_texture is RT_NONE until io's
 * rt_environment_image_load). Problems are about word 0, the file. */
static rt_result store_environment(rt_settings *st, const rt_setting *def, const rt_setting_value *v,
                                   const char *dir, rt_setting_problem *pb)
{
    char path[MAX_PATH_LEN];
    if (v->text[0] == '\0')
        return problem(pb, RT_ERR_INVALID, 0, false, "expected a file name, got an empty string");
    if (!rt_path_join(dir ? dir : "", v->text, path, sizeof path))
        return problem(pb, RT_ERR_LIMIT, 0, false, "file path is too long (at most %zu characters)", sizeof path - 1);
    if (!st)
        return RT_OK;
    memcpy(st->environment_file, path, strlen(path) + 1);
    *(uint32_t *)field_of(st, def->field) = RT_NONE;
    *(float *)field_of(st, def->field2) = v->f[0];
    return RT_OK;
}

rt_result rt_setting_store(rt_settings *st, const rt_setting *def, const rt_setting_value *v, const char *dir,
                           rt_setting_problem *pb)
{
    if (def->type == RT_SETTING_STRING) {
        size_t n = strlen(v->text);
        if (n == 0)
            return problem(pb, RT_ERR_INVALID, 0, false, "expected %s, got an empty string", def->what);
        if ((double)n > def->max)
            return problem(pb, RT_ERR_LIMIT, 0, false, "%s is too long (at most %zu characters)", def->what,
                           (size_t)def->max);
    }
    if (def->type == RT_SETTING_ENVIRONMENT)
        return store_environment(st, def, v, dir, pb);
    if (!st)
        return RT_OK;
    store_value(st, def, v);
    if (def->marks_given)
        *(bool *)field_of(st, def->given) = true;
    return RT_OK;
}

/* ------------------------------------------------------------ the command-line form */

rt_result rt_setting_set(rt_settings *st, const rt_setting *def, const char *text, rt_setting_problem *pb)
{
    char buf[MAX_PATH_LEN + 64];
    char *w[RT_SETTING_MAX_WORDS + 1] = {0};
    size_t n = 0, len = strlen(text);
    if (len >= sizeof buf)
        return problem(pb, RT_ERR_LIMIT, 0, false, "the value is too long (at most %zu characters)", sizeof buf - 1);
    memcpy(buf, text, len + 1);
    if (def->type == RT_SETTING_STRING) {
        w[n++] = buf;
    } else {
        /* blanks and commas separate words; one more word than a value takes is enough to see extras */
        for (char *c = buf; *c && n < RT_SETTING_MAX_WORDS + 1;) {
            while (*c == ' ' || *c == '\t' || *c == ',')
                *c++ = 0;
            if (!*c)
                break;
            w[n++] = c;
            while (*c && *c != ' ' && *c != '\t' && *c != ',')
                c++;
        }
        if (def->type == RT_SETTING_SIZE && n == 1) { /* 640x480 */
            char *x = strpbrk(w[0], "xX");
            if (x) {
                *x = 0;
                w[n++] = x + 1;
            }
        }
    }
    rt_setting_value v;
    rt_result r = rt_setting_read(def, (const char *const *)w, NULL, n, &v, pb);
    if (r == RT_OK && v.words < n)
        r = problem(pb, RT_ERR_PARSE, v.words, false, "unexpected '%s' after the end of the value", w[v.words]);
    if (r == RT_OK)
        r = rt_setting_store(st, def, &v, NULL, pb);
    if (r != RT_OK && pb->got) {
        size_t m = strlen(pb->message);
        if (pb->word < n)
            snprintf(pb->message + m, sizeof pb->message - m, ", got '%s'", w[pb->word]);
        else
            snprintf(pb->message + m, sizeof pb->message - m, ", got nothing");
        pb->got = false;
    }
    return r;
}

/* ------------------------------------------------------------ checks and texts */

rt_result rt_settings_check(const rt_settings *st, rt_setting_problem *pb)
{
    char what[256];
    for (size_t k = 0; k < rt_settings_count; k++) {
        const rt_setting *def = &rt_settings_table[k];
        switch (def->type) {
        case RT_SETTING_INT:
        case RT_SETTING_SIZE:
            for (int i = 0; i < (def->type == RT_SETTING_SIZE ? 2 : 1); i++) {
                int v = *(const int *)const_field_of(st, i ? def->field2 : def->field);
                if (def->type == RT_SETTING_SIZE)
                    snprintf(what, sizeof what, "%s %s", def->what, i ? "height" : "width");
                else
                    snprintf(what, sizeof what, "%s", def->what);
                if ((double)v < def->min || (double)v > def->max)
                    return problem(pb, RT_ERR_INVALID, 0, false, "%s must be between %lld and %lld, got %d", what,
                                   (long long)def->min, (long long)def->max, v);
            }
            break;
        case RT_SETTING_UINT32: {
            uint32_t v = *(const uint32_t *)const_field_of(st, def->field);
            if ((double)v < def->min || (double)v > def->max)
                return problem(pb, RT_ERR_INVALID, 0, false, "%s must be between %lld and %lld, got %u", def->what,
                               (long long)def->min, (long long)def->max, (unsigned)v);
            break;
        }
        case RT_SETTING_ENUM: {
            int v = *(const int *)const_field_of(st, def->field);
            if (v < 0 || (size_t)v >= word_count(def->words))
                return problem(pb, RT_ERR_INVALID, 0, false, "%s: no such value %d", def->name, v);
            break;
        }
        case RT_SETTING_FLOAT:
        case RT_SETTING_COLOR:
        case RT_SETTING_ENVIRONMENT: {
            const float *v = (const float *)const_field_of(st, def->type == RT_SETTING_ENVIRONMENT ? def->field2
                                                                                                  : def->field);
            bool above = def->type == RT_SETTING_FLOAT && def->above_min;
            for (int i = 0; i < (def->type == RT_SETTING_COLOR ? 3 : 1); i++) {
                if (def->type == RT_SETTING_COLOR)
                    snprintf(what, sizeof what, "%s (%s)", def->what, color_parts[i]);
                else if (def->type == RT_SETTING_ENVIRONMENT)
                    snprintf(what, sizeof what, "the %s strength", def->what);
                else
                    snprintf(what, sizeof what, "%s", def->what);
                if (!float_in_range(v[i], def->min, def->max, above)) {
                    float_range_problem(pb, 0, false, what, def->min, def->max, above);
                    size_t m = strlen(pb->message);
                    snprintf(pb->message + m, sizeof pb->message - m, ", got %g", (double)v[i]);
                    return pb->code;
                }
            }
            break;
        }
        case RT_SETTING_STRING: {
            const char *v = (const char *)const_field_of(st, def->field);
            if ((double)strnlen(v, (size_t)def->max + 1) > def->max)
                return problem(pb, RT_ERR_LIMIT, 0, false, "%s is too long (at most %zu characters)", def->what,
                               (size_t)def->max);
            break;
        }
        }
    }
    return RT_OK;
}

void rt_setting_range_text(const rt_setting *def, char *buf, size_t size)
{
    switch (def->type) {
    case RT_SETTING_INT:
    case RT_SETTING_UINT32:
        snprintf(buf, size, "%lld..%lld", (long long)def->min, (long long)def->max);
        return;
    case RT_SETTING_SIZE:
        snprintf(buf, size, "%lld..%lld each", (long long)def->min, (long long)def->max);
        return;
    case RT_SETTING_FLOAT:
        if (def->above_min)
            snprintf(buf, size, "> %g", def->min);
        else if (def->max >= FLT_MAX)
            snprintf(buf, size, ">= %g", def->min);
        else
            snprintf(buf, size, "%g..%g", def->min, def->max);
        return;
    case RT_SETTING_COLOR:
        snprintf(buf, size, "each >= %g", def->min);
        return;
    case RT_SETTING_ENUM:
        join_words(def->words, "|", buf, size);
        return;
    case RT_SETTING_STRING:
        snprintf(buf, size, "%lld..%lld bytes", (long long)def->min, (long long)def->max);
        return;
    case RT_SETTING_ENVIRONMENT:
        snprintf(buf, size, "S >= %g", def->min);
        return;
    }
    buf[0] = 0;
}

void rt_setting_default_text(const rt_setting *def, char *buf, size_t size)
{
    rt_settings defaults;
    rt_settings_default(&defaults);
    const rt_settings *d = &defaults;
    if (def->marks_given) {
        snprintf(buf, size, "unset");
        return;
    }
    switch (def->type) {
    case RT_SETTING_INT:
    case RT_SETTING_ENUM: {
        int v = *(const int *)const_field_of(d, def->field);
        if (def->type == RT_SETTING_ENUM)
            snprintf(buf, size, "%s", def->words[v]);
        else
            snprintf(buf, size, "%d", v);
        return;
    }
    case RT_SETTING_UINT32:
        snprintf(buf, size, "%u", (unsigned)*(const uint32_t *)const_field_of(d, def->field));
        return;
    case RT_SETTING_SIZE:
        snprintf(buf, size, "%d %d", *(const int *)const_field_of(d, def->field),
                 *(const int *)const_field_of(d, def->field2));
        return;
    case RT_SETTING_FLOAT:
        snprintf(buf, size, "%g", (double)*(const float *)const_field_of(d, def->field));
        return;
    case RT_SETTING_COLOR: {
        const rt_vec3 *c = (const rt_vec3 *)const_field_of(d, def->field);
        snprintf(buf, size, "%g %g %g", (double)c->x, (double)c->y, (double)c->z);
        return;
    }
    case RT_SETTING_STRING:
        snprintf(buf, size, "none");
        return;
    case RT_SETTING_ENVIRONMENT:
        snprintf(buf, size, "none, strength %g", (double)*(const float *)const_field_of(d, def->field2));
        return;
    }
    buf[0] = 0;
}
