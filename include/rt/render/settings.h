/* rt/render/settings.h - the one table of render settings.
 *
 * Every field of rt_settings (scene.h) that a user can set is one entry of
 * rt_settings_table: its name (the scene-format keyword and the key of the
 * driver's `--set KEY=VALUE`), its type, its field, its range and a line of
 * help; its default is what rt_settings_default() (scene.c) puts in the
 * field. The table drives the scene format's setting statements, the
 * driver's setting flags (-s, -r, --seed, --integrator, --set) and their
 * --help text, so they cannot drift apart. It lives with the renderer (its
 * `integrator` words are the integrator table's) and knows no scene.
 *
 * A setting's value is a short list of words, as written after its name in a
 * scene file (`resolution 640 480`). Reading the words checks them without
 * side effects; storing writes the fields (for `environment`, the file name
 * and the strength: io's rt_environment_image_load loads the image):
 *
 *   const rt_setting *def = rt_setting_find("samples");
 *   rt_setting_value v;
 *   rt_setting_problem pb;
 *   if (rt_setting_read(def, words, NULL, nwords, &v, &pb) != RT_OK ||
 *       rt_setting_store(&scene.settings, def, &v, scene_dir, &pb) != RT_OK)
 *       ... pb.message names what is wrong, pb.word which word ...
 *
 * From the command line the value is one string, split into words at blanks
 * and commas (`--set background=0.1,0.2,0.3`; a resolution may be `640x480`):
 *
 *   if (rt_setting_set(&scene.settings, def, "640x480", &pb) != RT_OK)  // NULL: only check
 *       fprintf(stderr, "rt: --set resolution=640x480: %s\n", pb.message);
 *
 *   for (size_t i = 0; i < rt_settings_count; i++)                // every setting, in table order
 *       puts(rt_settings_table[i].name);
 */
#ifndef RT_SETTINGS_H
#define RT_SETTINGS_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h" /* rt_settings, for now a member of the scene */

/* The limits the table (and so the scene format and every flag) enforces. */
#define RT_MAX_IMAGE_SIDE 32768      /* pixels, each side */
#define RT_MAX_SAMPLES (1 << 20)     /* samples per pixel */
#define RT_SETTINGS_MAX 64           /* room for this many table entries (parsers keep per-setting state) */
#define RT_SETTING_MAX_WORDS 3       /* the most words one setting's value takes */

typedef enum rt_setting_type {
    RT_SETTING_INT,         /* an int: one integer in [min, max] */
    RT_SETTING_UINT32,      /* a uint32_t: one integer in [min, max] */
    RT_SETTING_SIZE,        /* two ints, width (field) and height (field2), each in [min, max] */
    RT_SETTING_FLOAT,       /* a float in [min, max], or above min when above_min */
    RT_SETTING_COLOR,       /* an rt_vec3 in linear RGB: three numbers, each >= min */
    RT_SETTING_ENUM,        /* an int-sized enum: one of `words`, stored as its index */
    RT_SETTING_STRING,      /* a char array: one word of 1..max bytes (blanks allowed) */
    RT_SETTING_ENVIRONMENT, /* FILE [strength S]: the lat-long environment image's file (environment_file),
                               field the texture id (RT_NONE until loaded), field2 the strength (a float in [min, max]) */
} rt_setting_type;

typedef struct rt_setting {
    const char *name;         /* the scene-format keyword and the --set key */
    const char *args;         /* its words as written in --help and the docs: "W H", "N", "R G B" */
    rt_setting_type type;
    size_t field;             /* offsetof(rt_settings, ...) of the value */
    size_t field2;            /* SIZE: the height's; ENVIRONMENT: the strength's */
    bool marks_given;         /* also sets the bool at `given` when given (unset has a meaning) */
    size_t given;
    double min, max;          /* range (STRING: length in bytes; ENVIRONMENT: the strength's) */
    bool above_min;           /* FLOAT: must be > min rather than >= min */
    const char *const *words; /* ENUM: the words, NULL-terminated; the index is the enum value */
    const char *what;         /* the noun in messages: "samples per pixel", "the seed" */
    const char *help;         /* one line for --help */
} rt_setting;

extern const rt_setting rt_settings_table[];
extern const size_t rt_settings_count;

/* The entry called `name`, or NULL. */
const rt_setting *rt_setting_find(const char *name);

/* A value read from words, not yet stored. */
typedef struct rt_setting_value {
    size_t words;      /* how many of the words it took */
    long long i[2];    /* INT, UINT32, ENUM (the index), SIZE (width, height) */
    float f[3];        /* FLOAT, COLOR; ENVIRONMENT: f[0] is the strength */
    const char *text;  /* STRING, ENVIRONMENT's file: the caller's word, not copied */
} rt_setting_value;

/* What is wrong with a value, without a location: the caller adds one. */
typedef struct rt_setting_problem {
    rt_result code;    /* RT_ERR_PARSE: not a value of the type or missing; RT_ERR_INVALID: out of range;
                          RT_ERR_LIMIT: too long */
    size_t word;       /* the word at fault; equal to the word count when a word is missing */
    bool got;          /* the message wants ", got WORD" (or the caller's "end of line") after it */
    char message[1024];
} rt_setting_problem;

/* Reads the value from words[0..count) (`quoted` may be NULL; a quoted word
 * is never a number or a keyword). It may take fewer words than given: the
 * caller decides what extra words mean. No side effects. */
rt_result rt_setting_read(const rt_setting *def, const char *const *words, const bool *quoted, size_t count,
                          rt_setting_value *v, rt_setting_problem *pb);
/* Stores a value read by rt_setting_read into st. `environment` stores
 * its file name (a relative one resolved against dir, NULL = the current
 * directory) in st->environment_file and its strength, and sets
 * environment_texture to RT_NONE: the caller loads the image
 * (rt_environment_image_load, rt/io/environment_image.h); `output` checks
 * its length. st == NULL only checks. */
rt_result rt_setting_store(rt_settings *st, const rt_setting *def, const rt_setting_value *v, const char *dir,
                           rt_setting_problem *pb);

/* The command-line form: `text` split into words at blanks and commas (a
 * STRING takes the text whole; a SIZE also splits `640x480` or `640X480`),
 * read, checked for extra words, and stored as rt_setting_store does (an
 * environment's image is the caller's to load). st == NULL only checks.
 * pb->message is complete, with the word at fault quoted. */
rt_result rt_setting_set(rt_settings *st, const rt_setting *def, const char *text, rt_setting_problem *pb);

/* Every value in its range, as the table says (for settings that were not
 * read through it). The first one out of range is described in pb. */
rt_result rt_settings_check(const rt_settings *st, rt_setting_problem *pb);

/* For help and documentation: the allowed values ("1..1048576", "> 0",
 * "direct|whitted|path") and the default ("512 512", "direct", "none"). */
void rt_setting_range_text(const rt_setting *def, char *buf, size_t size);
void rt_setting_default_text(const rt_setting *def, char *buf, size_t size);

/* rt_settings_default() (scene.h) fills every field with its default. */

#endif
