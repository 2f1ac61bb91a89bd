/* scene_parse.c - the rt scene text format, v1 (docs/scene-format.md).
 *
 * Algorithm: a single pass over the text. A small hand-written lexer splits
 * the (copied) text into logical statements: `#` starts a comment that runs
 * to the end of the line, a line whose last token ends in `\` continues onto
 * the next one, tokens are separated by blanks and may be double-quoted (for
 * paths with spaces). Each token keeps its 1-based line and column so every
 * error can name `file:line:column` of the offending token, the way pbrt's
 * scene parser reports `FileLoc`s. The first token of a statement is looked
 * up in the settings table (settings.h: `samples`, `resolution`, ... are read,
 * range-checked and stored by it, and located here) or in a table of
 * keywords; each handler consumes its arguments through a cursor (get_float,
 * get_int, get_word ...) that produces the uniform "expected X for Y, got 'Z'"
 * messages, then appends records to the scene's flat tables (scene.h). Names
 * (materials, textures) are resolved at once, so a name must be defined
 * before it is used; `camera gltf N` is resolved after the last statement,
 * when every model's cameras are known.
 *
 * Material keys: one table (mat_keys). The keys of the glTF PBR-next
 * extensions are the KHR_materials_* properties in snake_case with the
 * extensions' schema ranges (Khronos glTF extension registry: clearcoat,
 * specular, sheen, anisotropy, iridescence, dispersion,
 * diffuse_transmission), so a material written with them is the one the
 * glTF loader makes from the same JSON.
 *
 * Numbers: decimal only ([+-]digits[.digits][e[+-]digits], number.h),
 * finite, and within float range; the whole token must be used, so `1.0x`,
 * `nan`, `inf` and `0x10` are all rejected.
 *
 * On failure the scene is rolled back to where it was before the call
 * (rt_scene_rollback): no half-parsed scene. The parser's own memory is
 * released on every path.
 */
#include "rt/io/scene_parse.h"

#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/base/near_miss.h"
#include "rt/base/number.h"
#include "rt/io/gltf.h"
#include "rt/io/image_load.h"
#include "rt/io/mesh_io.h"
#include "rt/io/nanovdb.h"
#include "rt/io/environment_image.h"
#include "rt/render/settings.h"
#include "rt/scene/instance.h"
#include "rt/scene/subsurface.h"
#include "rt/scene/texture.h"

#define MAX_SCENE_BYTES ((size_t)256 << 20) /* 256 MiB of text keeps line and column in an int */
#define MAX_PATH_LEN 4096

/* ------------------------------------------------------------ tokens */

typedef struct tok {
    const char *s; /* NUL-terminated, inside the parser's copy of the text */
    int line, col; /* 1-based position of the token's first character */
    int end_col;   /* column just past its last character (quotes included) */
    bool quoted;
} tok;

typedef struct name_entry {
    char name[64];
    uint32_t index; /* into the scene's materials or textures */
    int line;       /* where it was defined */
} name_entry;

/* Names defined in this file, with an open-addressing hash index (FNV-1a,
 * linear probing) so scenes with many materials stay linear time. */
typedef struct name_table {
    name_entry *items;
    size_t count, cap;
    uint32_t *slots; /* item index + 1, 0 = empty; power-of-two size */
    size_t nslots;
} name_table;

/* A model line's load (outside objects), by what shapes its geometry:
 * the file and the glTF options but the transform. A later line of the
 * same load places it again as an instance (st_model). */
typedef struct model_load {
    char *path; /* resolved, owned */
    rt_gltf_options opt; /* scene, pose and animation; animation_name owned; no transform, catalog or flatten */
    size_t t0, nt, v0, nv;  /* its triangles and vertices in the scene, in world space by `placed` */
    rt_mat4 placed;         /* the first line's transform */
    bool instanceable;      /* only triangles (no lights, cameras, emitters, objects of its own) */
    bool animated;          /* its pose follows the frame time */
    uint32_t object;        /* the object it became, RT_NONE until a second line */
    int line;
} model_load;

typedef struct parser {
    rt_scene *s;
    rt_settings *settings; /* the setting statements' values; NULL: checked, not kept */
    const char *name; /* file name for messages */
    const char *dir;  /* directory relative paths resolve against ("" = the current one) */
    rt_error *err;
    rt_scene_parse_options pose; /* the frame time model lines are posed at */

    /* the current statement */
    tok *toks;
    size_t ntok, tok_cap;
    size_t pos; /* cursor into toks */

    name_table materials, textures, objects, media;
    int scene_medium_line;    /* line of the `scene_medium` statement, 0 = none yet */
    /* an open `object NAME` block: its statement, and the triangles and
     * vertices before it (rt/scene/instance.h) */
    bool in_object;
    tok object_name;
    size_t object_t0, object_v0;
    uint32_t default_material; /* made on first use by a mesh without a material */
    model_load *models; /* the model lines' loads */
    size_t model_count, model_cap;
    /* textures standing in for a missing image (rt_texture_missing): a data
     * slot given one is left empty instead */
    uint32_t *missing_tex;
    size_t missing_count, missing_cap;

    int setting_line[RT_SETTINGS_MAX]; /* by settings-table index: where it was given, 0 = not yet */
    int camera_line;          /* line of the `camera` statement, 0 = none yet */
    bool camera_gltf;         /* `camera gltf N` given: resolve after parsing */
    long long camera_gltf_index;
    tok camera_gltf_tok;
} parser;

/* ------------------------------------------------------------ errors */

/* Length of the valid UTF-8 sequence at s (1..4), or 0 when it is not one. */
static int utf8_len(const unsigned char *s)
{
    unsigned c = s[0], min;
    int n;
    if (c < 0x80)
        return 1;
    if ((c & 0xe0) == 0xc0)
        n = 2, min = 0x80;
    else if ((c & 0xf0) == 0xe0)
        n = 3, min = 0x800;
    else if ((c & 0xf8) == 0xf0)
        n = 4, min = 0x10000;
    else
        return 0;
    unsigned cp = c & (0x7fu >> n);
    for (int i = 1; i < n; i++) {
        if ((s[i] & 0xc0) != 0x80) /* also stops at the NUL */
            return 0;
        cp = (cp << 6) | (s[i] & 0x3fu);
    }
    if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
        return 0;
    return n;
}

/* Writes 'token' for messages: shortened when long, bytes that are not
 * UTF-8 written as \xNN so messages stay printable. size >= 16. */
static const char *show(const tok *t, char *buf, size_t size)
{
    const unsigned char *s = (const unsigned char *)t->s;
    size_t o = 0, limit = size - 6; /* room for "...'" and the NUL */
    buf[o++] = '\'';
    while (*s) {
        int n = utf8_len(s);
        size_t need = n ? (size_t)n : 4;
        if (o + need > limit) {
            memcpy(buf + o, "...", 3);
            o += 3;
            break;
        }
        if (n) {
            memcpy(buf + o, s, (size_t)n);
            o += (size_t)n;
            s += n;
        } else {
            snprintf(buf + o, 5, "\\x%02x", *s);
            o += 4;
            s++;
        }
    }
    buf[o++] = '\'';
    buf[o] = '\0';
    return buf;
}

/* An error at token t, or at the end of the statement when t is NULL. */
static rt_result perr(parser *p, rt_result code, const tok *t, const char *fmt, ...) RT_PRINTF(4, 5);
static rt_result perr(parser *p, rt_result code, const tok *t, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int line = 0, col = 0;
    if (t) {
        line = t->line;
        col = t->col;
    } else if (p->ntok > 0) {
        line = p->toks[p->ntok - 1].line;
        col = p->toks[p->ntok - 1].end_col;
    }
    return rt_fail(p->err, code, "%s:%d:%d: %s", p->name, line, col, msg);
}

/* A loader's error, prefixed with the scene location; keeps the loader's code. */
static rt_result loader_err(parser *p, const tok *t, rt_result code, const rt_error *inner)
{
    return rt_fail(p->err, code, "%s:%d:%d: %s", p->name, t->line, t->col, inner->message);
}

static rt_result nomem(parser *p, const tok *t)
{
    return perr(p, RT_ERR_NOMEM, t, "out of memory");
}

/* Out of memory placing one more instance (the table grows by doubling):
 * the count placed and the bytes they take (rt/scene/instance.h), for
 * --max-memory's user. */
static rt_result instance_nomem(parser *p, const tok *t)
{
    size_t n = p->s->instance_count;
    return perr(p, RT_ERR_NOMEM, t, "out of memory for more than %zu instances (%zu bytes each, %zu bytes)", n,
                (size_t)RT_INSTANCE_BYTES, n * (size_t)RT_INSTANCE_BYTES);
}

/* ------------------------------------------------------------ cursor */

static const tok *peek(const parser *p)
{
    return p->pos < p->ntok ? &p->toks[p->pos] : NULL;
}

static const tok *prev(const parser *p)
{
    return &p->toks[p->pos - 1];
}

static bool peek_is(const parser *p, const char *word)
{
    const tok *t = peek(p);
    return t && !t->quoted && strcmp(t->s, word) == 0;
}

static rt_result got_eol(parser *p, const char *expected)
{
    return perr(p, RT_ERR_PARSE, NULL, "expected %s, got end of line", expected);
}

/* Any token (a name, a path, a keyword). */
static rt_result get_word(parser *p, const char *what, const tok **out)
{
    const tok *t = peek(p);
    if (!t)
        return got_eol(p, what);
    p->pos++;
    *out = t;
    return RT_OK;
}

static rt_result get_float(parser *p, const char *what, float *out)
{
    const tok *t = peek(p);
    char b[80];
    if (!t)
        return perr(p, RT_ERR_PARSE, NULL, "expected a number for %s, got end of line", what);
    rt_number_status st = t->quoted ? RT_NUMBER_BAD : rt_parse_float(t->s, out);
    if (st == RT_NUMBER_RANGE)
        return perr(p, RT_ERR_INVALID, t, "%s is out of range (beyond +-3.4e38), got %s", what, show(t, b, sizeof b));
    if (st != RT_NUMBER_OK)
        return perr(p, RT_ERR_PARSE, t, "expected a number for %s, got %s", what, show(t, b, sizeof b));
    p->pos++;
    return RT_OK;
}

/* A number within [lo, hi]. */
static rt_result get_float_in(parser *p, const char *what, float lo, float hi, float *out)
{
    rt_result r = get_float(p, what, out);
    if (r != RT_OK)
        return r;
    if (*out < lo || *out > hi) {
        const tok *t = prev(p);
        char b[80];
        if (hi >= FLT_MAX)
            return perr(p, RT_ERR_INVALID, t, "%s must be >= %g, got %s", what, (double)lo, show(t, b, sizeof b));
        if (lo <= -FLT_MAX)
            return perr(p, RT_ERR_INVALID, t, "%s must be <= %g, got %s", what, (double)hi, show(t, b, sizeof b));
        return perr(p, RT_ERR_INVALID, t, "%s must be between %g and %g, got %s", what, (double)lo, (double)hi,
                    show(t, b, sizeof b));
    }
    return RT_OK;
}

/* A number > lo. */
static rt_result get_float_above(parser *p, const char *what, float lo, float *out)
{
    rt_result r = get_float(p, what, out);
    if (r != RT_OK)
        return r;
    if (!(*out > lo)) {
        const tok *t = prev(p);
        char b[80];
        return perr(p, RT_ERR_INVALID, t, "%s must be > %g, got %s", what, (double)lo, show(t, b, sizeof b));
    }
    return RT_OK;
}

static rt_result get_int(parser *p, const char *what, long long lo, long long hi, long long *out)
{
    const tok *t = peek(p);
    char b[80];
    if (!t)
        return perr(p, RT_ERR_PARSE, NULL, "expected an integer for %s, got end of line", what);
    long long v = 0;
    rt_number_status st = t->quoted ? RT_NUMBER_BAD : rt_parse_int(t->s, &v);
    if (st == RT_NUMBER_BAD)
        return perr(p, RT_ERR_PARSE, t, "expected an integer for %s, got %s", what, show(t, b, sizeof b));
    p->pos++;
    if (st == RT_NUMBER_RANGE || v < lo || v > hi)
        return perr(p, RT_ERR_INVALID, t, "%s must be between %lld and %lld, got %s", what, lo, hi,
                    show(t, b, sizeof b));
    *out = v;
    return RT_OK;
}

/* An RGB colour, each component in [0, hi]. */
static rt_result get_color_in(parser *p, const char *what, float hi, rt_vec3 *out)
{
    static const char *comp[3] = {"red", "green", "blue"};
    float v[3];
    for (int i = 0; i < 3; i++) {
        char w[256];
        snprintf(w, sizeof w, "%s (%s)", what, comp[i]);
        rt_result r = get_float_in(p, w, 0.0f, hi, &v[i]);
        if (r != RT_OK)
            return r;
    }
    *out = rt_v3(v[0], v[1], v[2]);
    return RT_OK;
}

/* Three numbers; `what` names the whole ("the sphere centre"). */
static rt_result get_vec3(parser *p, const char *what, rt_vec3 *out)
{
    static const char axis[3] = {'x', 'y', 'z'};
    float v[3];
    for (int i = 0; i < 3; i++) {
        char w[256];
        snprintf(w, sizeof w, "%s (%c)", what, axis[i]);
        rt_result r = get_float(p, w, &v[i]);
        if (r != RT_OK)
            return r;
    }
    *out = rt_v3(v[0], v[1], v[2]);
    return RT_OK;
}

/* An RGB colour, each component >= 0. */
static rt_result get_color(parser *p, const char *what, rt_vec3 *out)
{
    return get_color_in(p, what, FLT_MAX, out);
}

/* One of a list of words; `choices` is "a|b|c" for the message. */
static rt_result get_choice(parser *p, const char *what, const char *const *words, int n, const char *choices,
                            int *out)
{
    const tok *t = peek(p);
    char b[80];
    if (!t)
        return perr(p, RT_ERR_PARSE, NULL, "expected %s (%s), got end of line", what, choices);
    for (int i = 0; i < n && !t->quoted; i++) {
        if (strcmp(t->s, words[i]) == 0) {
            p->pos++;
            *out = i;
            return RT_OK;
        }
    }
    return perr(p, RT_ERR_PARSE, t, "expected %s (%s), got %s", what, choices, show(t, b, sizeof b));
}

static rt_result get_bool(parser *p, const char *what, bool *out)
{
    static const char *const words[] = {"false", "true"};
    int i = 0;
    rt_result r = get_choice(p, what, words, 2, "true|false", &i);
    *out = i == 1;
    return r;
}

static rt_result expect_end(parser *p, const char *stmt)
{
    const tok *t = peek(p);
    char b[80];
    if (t)
        return perr(p, RT_ERR_PARSE, t, "unexpected %s after the end of the %s statement", show(t, b, sizeof b),
                    stmt);
    return RT_OK;
}

/* ------------------------------------------------------------ names and paths */

static uint32_t name_hash(const char *s)
{
    uint32_t h = 2166136261u;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 16777619u;
    return h;
}

static name_entry *name_find(name_table *t, const char *name)
{
    if (!t->nslots)
        return NULL;
    size_t mask = t->nslots - 1;
    for (size_t i = name_hash(name) & mask;; i = (i + 1) & mask) {
        uint32_t k = t->slots[i];
        if (k == 0)
            return NULL;
        if (strcmp(t->items[k - 1].name, name) == 0)
            return &t->items[k - 1];
    }
}

static void name_slot_insert(name_table *t, uint32_t item)
{
    size_t mask = t->nslots - 1;
    size_t i = name_hash(t->items[item].name) & mask;
    while (t->slots[i])
        i = (i + 1) & mask;
    t->slots[i] = item + 1;
}

static bool name_add(name_table *t, const char *name, uint32_t index, int line)
{
    if (t->count >= UINT32_MAX / 4 || !rt_grow((void **)&t->items, &t->cap, t->count + 1, sizeof *t->items))
        return false;
    if ((t->count + 1) * 2 > t->nslots) { /* keep the load under 1/2 */
        size_t n = t->nslots ? t->nslots * 2 : 64;
        uint32_t *slots = rt_alloc(n, sizeof *slots);
        if (!slots)
            return false;
        free(t->slots);
        t->slots = slots;
        t->nslots = n;
        for (size_t i = 0; i < t->count; i++)
            name_slot_insert(t, (uint32_t)i);
    }
    name_entry *e = &t->items[t->count];
    memset(e, 0, sizeof *e);
    snprintf(e->name, sizeof e->name, "%s", name);
    e->index = index;
    e->line = line;
    name_slot_insert(t, (uint32_t)t->count);
    t->count++;
    return true;
}

static void name_table_free(name_table *t)
{
    free(t->items);
    free(t->slots);
}

/* Words that follow a name in `mesh`/`model` and so cannot be names. */
static bool reserved_word(const char *s)
{
    static const char *const words[] = {"translate", "rotate", "scale", "material_override", "scene"};
    for (size_t i = 0; i < sizeof words / sizeof *words; i++)
        if (strcmp(s, words[i]) == 0)
            return true;
    return false;
}

/* Checks a new material or texture name. */
static rt_result check_new_name(parser *p, const tok *t, name_table *table, const char *kind)
{
    char b[80];
    size_t n = strlen(t->s);
    if (n == 0)
        return perr(p, RT_ERR_INVALID, t, "a %s name must not be empty", kind);
    if (n >= sizeof(((name_entry *)0)->name))
        return perr(p, RT_ERR_INVALID, t, "%s name %s is too long (at most %d characters)", kind,
                    show(t, b, sizeof b), (int)sizeof(((name_entry *)0)->name) - 1);
    if (strncmp(t->s, "__", 2) == 0)
        return perr(p, RT_ERR_INVALID, t, "%s names starting with '__' are reserved, got %s", kind,
                    show(t, b, sizeof b));
    if (reserved_word(t->s))
        return perr(p, RT_ERR_INVALID, t, "%s is a keyword and cannot be a %s name", show(t, b, sizeof b), kind);
    const name_entry *e = name_find(table, t->s);
    if (e)
        return perr(p, RT_ERR_INVALID, t, "%s %s is already defined on line %d", kind, show(t, b, sizeof b),
                    e->line);
    return RT_OK;
}

/* The defined name closest to `word` (edit distance under 3), for "did
 * you mean"; NULL when none is that close. Names the scene holds from other
 * loaders count too, except the internal "__" ones. */
static const char *closest_name(const parser *p, const name_table *table, bool scene_materials, const char *word)
{
    rt_near_miss n = rt_near_miss_of(word);
    for (size_t i = 0; i < table->count; i++)
        rt_near_miss_consider(&n, table->items[i].name);
    for (size_t i = 0; scene_materials && i < p->s->material_count; i++) {
        const char *name = p->s->materials[i].name;
        if (strncmp(name, "__", 2) != 0)
            rt_near_miss_consider(&n, name);
    }
    return n.best;
}

/* A material by name: those defined in this file first, then any other in
 * the scene (for example from an OBJ's MTL file loaded earlier). */
static rt_result get_material(parser *p, const char *what, uint32_t *out)
{
    const tok *t = peek(p);
    char b[80];
    if (!t)
        return perr(p, RT_ERR_PARSE, NULL, "expected a material name for %s, got end of line", what);
    p->pos++;
    const name_entry *e = name_find(&p->materials, t->s);
    if (e) {
        *out = e->index;
        return RT_OK;
    }
    uint32_t m = strncmp(t->s, "__", 2) == 0 ? RT_NONE : rt_scene_find_material(p->s, t->s);
    if (m != RT_NONE) {
        *out = m;
        return RT_OK;
    }
    const char *near = closest_name(p, &p->materials, true, t->s);
    if (near)
        return perr(p, RT_ERR_INVALID, t, "undefined material %s for %s (did you mean '%s'?)", show(t, b, sizeof b),
                    what, near);
    return perr(p, RT_ERR_INVALID, t, "undefined material %s for %s (define it with 'material' before use)",
                show(t, b, sizeof b), what);
}

/* A participating medium by name (`medium` lines before this one). */
static rt_result get_medium(parser *p, const char *what, uint32_t *out)
{
    const tok *t = peek(p);
    char b[80];
    if (!t)
        return perr(p, RT_ERR_PARSE, NULL, "expected a medium name for %s, got end of line", what);
    p->pos++;
    uint32_t m = rt_scene_find_medium(p->s, t->s);
    if (m != RT_NONE) {
        *out = m;
        return RT_OK;
    }
    const char *near = closest_name(p, &p->media, false, t->s);
    if (near)
        return perr(p, RT_ERR_INVALID, t, "undefined medium %s for %s (did you mean '%s'?)", show(t, b, sizeof b),
                    what, near);
    return perr(p, RT_ERR_INVALID, t, "undefined medium %s for %s (define it with 'medium' before use)",
                show(t, b, sizeof b), what);
}

/* Joins the scene's directory and a relative path. */
static rt_result resolve_path(parser *p, const tok *t, char *out, size_t size)
{
    if (t->s[0] == '\0')
        return perr(p, RT_ERR_INVALID, t, "expected a file name, got an empty string");
    if (!rt_path_join(p->dir, t->s, out, size))
        return perr(p, RT_ERR_LIMIT, t, "file path is too long (at most %zu characters)", size - 1);
    return RT_OK;
}

/* Loads an image file named by token t and makes an image texture for it
 * (repeat, bilinear unless changed by the caller). */
/* An image texture for the file named by t. A file that does not exist is
 * a warning and the missing-texture checker (rt/scene/texture.h); *missing
 * says so, for the caller to record once the texture has its index. */
static rt_result image_texture(parser *p, const tok *t, rt_texture *tex, bool *missing)
{
    char path[MAX_PATH_LEN];
    *missing = false;
    rt_result r = resolve_path(p, t, path, sizeof path);
    if (r != RT_OK)
        return r;
    rt_error inner = {0};
    uint32_t img = RT_NONE;
    r = rt_image_load_file(p->s, path, &img, &inner);
    if (r != RT_OK && rt_image_file_missing(path)) {
        rt_warn("%s:%d:%d: image '%s' not found; %s", p->name, t->line, t->col, path, RT_MISSING_TEXTURE_NOTE);
        *tex = rt_texture_missing();
        *missing = true;
        return RT_OK;
    }
    if (r != RT_OK)
        return loader_err(p, t, r, &inner);
    if (img >= p->s->image_count)
        return perr(p, RT_ERR_INVALID, t, "image loader returned no image for '%s'", path);
    *tex = rt_texture_image(img);
    return RT_OK;
}

static bool note_missing(parser *p, uint32_t texture)
{
    if (!rt_grow((void **)&p->missing_tex, &p->missing_cap, p->missing_count + 1, sizeof *p->missing_tex))
        return false;
    p->missing_tex[p->missing_count++] = texture;
    return true;
}

static bool is_missing(const parser *p, uint32_t texture)
{
    for (size_t i = 0; i < p->missing_count; i++)
        if (p->missing_tex[i] == texture)
            return true;
    return false;
}

/* A texture for a material slot: a texture name, or a file path (then an
 * image texture with default sampling is made). */
static rt_result get_texture_ref(parser *p, const char *what, uint32_t *out)
{
    const tok *t = NULL;
    char b[80];
    char w[256];
    snprintf(w, sizeof w, "a texture name or image file for %s", what);
    rt_result r = get_word(p, w, &t);
    if (r != RT_OK)
        return r;
    const name_entry *e = name_find(&p->textures, t->s);
    if (e) {
        *out = e->index;
        return RT_OK;
    }
    const char *near = strchr(t->s, '.') || strchr(t->s, '/') ? NULL : closest_name(p, &p->textures, false, t->s);
    if (near)
        return perr(p, RT_ERR_INVALID, t, "undefined texture %s for %s (did you mean '%s'?)", show(t, b, sizeof b),
                    what, near);
    if (!strchr(t->s, '.') && !strchr(t->s, '/'))
        return perr(p, RT_ERR_INVALID, t,
                    "undefined texture %s for %s (define it with 'texture' before use, or give an image file)",
                    show(t, b, sizeof b), what);
    rt_texture tex;
    bool missing;
    r = image_texture(p, t, &tex, &missing);
    if (r != RT_OK)
        return r;
    uint32_t id = rt_scene_add_texture(p->s, &tex);
    if (id == RT_NONE || (missing && !note_missing(p, id)))
        return nomem(p, t);
    *out = id;
    return RT_OK;
}

/* ------------------------------------------------------------ settings */

/* A setting statement (`samples 64`, `resolution 640 480`, ...): the settings
 * table reads, checks and stores the words after the keyword; this adds the
 * location of the word at fault, and warns when a setting is given twice. */
static rt_result st_setting(parser *p, const rt_setting *def, const tok *kw)
{
    const char *words[RT_SETTING_MAX_WORDS];
    bool quoted[RT_SETTING_MAX_WORDS];
    size_t first = p->pos, n = 0;
    for (; n < RT_SETTING_MAX_WORDS && first + n < p->ntok; n++) {
        words[n] = p->toks[first + n].s;
        quoted[n] = p->toks[first + n].quoted;
    }
    rt_setting_value v;
    rt_setting_problem pb;
    rt_result r = rt_setting_read(def, words, quoted, n, &v, &pb);
    if (r == RT_OK) {
        p->pos = first + v.words;
        if ((r = expect_end(p, def->name)) != RT_OK)
            return r;
        r = rt_setting_store(p->settings, &p->s->environment, def, &v, p->dir, &pb);
    }
    if (r == RT_OK && def->type == RT_SETTING_ENVIRONMENT) { /* the table keeps the name; the image is io's */
        rt_error inner = {0};
        if ((r = rt_environment_image_load(p->s, &inner)) != RT_OK) {
            pb = (rt_setting_problem){.code = r, .word = 0, .got = false};
            snprintf(pb.message, sizeof pb.message, "%s", inner.message);
        }
    }
    if (r != RT_OK) {
        const tok *t = pb.word < n ? &p->toks[first + pb.word] : NULL; /* NULL: a word is missing */
        char b[80];
        if (pb.got)
            return perr(p, r, t, "%s, got %s", pb.message, t ? show(t, b, sizeof b) : "end of line");
        if (t) /* a loader's message may be long: not through perr's buffer */
            return rt_fail(p->err, r, "%s:%d:%d: %s", p->name, t->line, t->col, pb.message);
        return perr(p, r, NULL, "%s", pb.message);
    }
    size_t which = (size_t)(def - rt_settings_table);
    if (p->setting_line[which])
        rt_warn("%s:%d:%d: '%s' was already set on line %d; the later value wins", p->name, kw->line, kw->col,
                kw->s, p->setting_line[which]);
    p->setting_line[which] = kw->line;
    return RT_OK;
}

/* ------------------------------------------------------------ camera */

static rt_result st_camera(parser *p, const tok *kw)
{
    rt_result r;
    if (p->camera_line)
        return perr(p, RT_ERR_INVALID, kw, "the camera is already set on line %d", p->camera_line);
    if (peek_is(p, "gltf")) {
        p->pos++;
        long long n = 0;
        if ((r = get_int(p, "the glTF camera index", 0, INT_MAX, &n)) != RT_OK)
            return r;
        p->camera_gltf_tok = *prev(p);
        if ((r = expect_end(p, "camera")) != RT_OK)
            return r;
        p->camera_gltf = true;
        p->camera_gltf_index = n;
        p->camera_line = kw->line;
        return RT_OK;
    }
    rt_camera c = {0};
    c.up = rt_v3(0, 1, 0);
    c.vfov_deg = 40.0f;
    enum { K_POSITION, K_LOOK_AT, K_UP, K_FOV, K_APERTURE, K_FOCUS, K_SHUTTER, K_COUNT };
    static const char *const keys[K_COUNT] = {"position", "look_at", "up", "fov", "aperture", "focus", "shutter"};
    const tok *seen[K_COUNT] = {0};
    while (peek(p)) {
        const tok *key = peek(p);
        int k = 0;
        if ((r = get_choice(p, "a camera key", keys, K_COUNT, "position|look_at|up|fov|aperture|focus|shutter",
                            &k)) != RT_OK)
            return r;
        if (seen[k])
            return perr(p, RT_ERR_INVALID, key, "camera key '%s' is given twice (first at column %d)", keys[k],
                        seen[k]->col);
        seen[k] = key;
        switch (k) {
        case K_POSITION: r = get_vec3(p, "the camera position", &c.position); break;
        case K_LOOK_AT: r = get_vec3(p, "the camera look_at point", &c.look_at); break;
        case K_UP: r = get_vec3(p, "the camera up vector", &c.up); break;
        case K_FOV:
            r = get_float_above(p, "the camera field of view", 0.0f, &c.vfov_deg);
            if (r == RT_OK && !(c.vfov_deg < 180.0f)) {
                char b[80];
                r = perr(p, RT_ERR_INVALID, prev(p), "the camera field of view must be below 180 degrees, got %s",
                         show(prev(p), b, sizeof b));
            }
            break;
        case K_APERTURE: r = get_float_in(p, "the camera aperture", 0.0f, FLT_MAX, &c.aperture); break;
        case K_SHUTTER:
            if ((r = get_float_in(p, "the shutter's opening time in seconds", -1e7f, 1e7f, &c.shutter_open)) ==
                    RT_OK &&
                (r = get_float_in(p, "the shutter's closing time in seconds", -1e7f, 1e7f, &c.shutter_close)) ==
                    RT_OK &&
                c.shutter_close < c.shutter_open)
                r = perr(p, RT_ERR_INVALID, prev(p), "the shutter closes (%g s) before it opens (%g s)",
                         (double)c.shutter_close, (double)c.shutter_open);
            break;
        default: r = get_float_in(p, "the camera focus distance", 0.0f, FLT_MAX, &c.focus_distance); break;
        }
        if (r != RT_OK)
            return r;
    }
    if (!seen[K_POSITION])
        return perr(p, RT_ERR_PARSE, NULL, "expected 'position X Y Z' in the camera statement, got end of line");
    if (!seen[K_LOOK_AT])
        return perr(p, RT_ERR_PARSE, NULL, "expected 'look_at X Y Z' in the camera statement, got end of line");
    rt_vec3 dir = rt_sub(c.look_at, c.position);
    if (!(rt_length2(dir) > 0.0f))
        return perr(p, RT_ERR_INVALID, seen[K_LOOK_AT], "the camera look_at point equals its position");
    /* past ~1.8e19 the squared length overflows and the direction cannot
     * be normalised: say so rather than blame the up vector */
    if (!(rt_length2(dir) < FLT_MAX))
        return perr(p, RT_ERR_INVALID, seen[K_LOOK_AT],
                    "the camera look_at point is too far from its position (over 1e19 in float arithmetic)");
    if (!(rt_length2(c.up) > 0.0f))
        return perr(p, RT_ERR_INVALID, seen[K_UP], "the camera up vector is zero");
    if (!(rt_length(rt_cross(rt_normalize(dir), rt_normalize(c.up))) > 1e-6f))
        return perr(p, RT_ERR_INVALID, seen[K_UP] ? seen[K_UP] : kw,
                    "the camera up vector is parallel to the view direction%s",
                    seen[K_UP] ? "" : " (give 'up X Y Z')");
    p->s->camera = c;
    p->s->camera_set = true;
    p->camera_line = kw->line;
    return RT_OK;
}

/* ------------------------------------------------------------ textures */

static rt_result st_texture(parser *p, const tok *kw)
{
    (void)kw;
    const tok *name = NULL;
    rt_result r;
    if ((r = get_word(p, "a texture name", &name)) != RT_OK ||
        (r = check_new_name(p, name, &p->textures, "texture")) != RT_OK)
        return r;
    static const char *const kinds[] = {"image", "checker", "constant"};
    int kind = 0;
    if ((r = get_choice(p, "a texture kind", kinds, 3, "image|checker|constant", &kind)) != RT_OK)
        return r;
    rt_texture tex;
    bool missing = false;
    if (kind == 0) {
        const tok *file = NULL;
        if ((r = get_word(p, "an image file", &file)) != RT_OK)
            return r;
        bool have_wrap = false, have_filter = false;
        int wrap = 0, filter = 0;
        while (peek(p)) {
            const tok *key = peek(p);
            static const char *const opts[] = {"wrap", "filter"};
            int o = 0;
            if ((r = get_choice(p, "an image texture option", opts, 2, "wrap|filter", &o)) != RT_OK)
                return r;
            if (o == 0) {
                static const char *const wraps[] = {"repeat", "clamp", "mirror"};
                if (have_wrap)
                    return perr(p, RT_ERR_INVALID, key, "'wrap' is given twice");
                have_wrap = true;
                if ((r = get_choice(p, "a wrap mode", wraps, 3, "repeat|clamp|mirror", &wrap)) != RT_OK)
                    return r;
            } else {
                static const char *const filters[] = {"bilinear", "nearest"};
                if (have_filter)
                    return perr(p, RT_ERR_INVALID, key, "'filter' is given twice");
                have_filter = true;
                if ((r = get_choice(p, "a filter", filters, 2, "bilinear|nearest", &filter)) != RT_OK)
                    return r;
            }
        }
        if ((r = image_texture(p, file, &tex, &missing)) != RT_OK)
            return r;
        static const rt_wrap wrap_values[] = {RT_WRAP_REPEAT, RT_WRAP_CLAMP, RT_WRAP_MIRROR};
        tex.wrap_s = tex.wrap_t = wrap_values[wrap];
        tex.filter = filter == 0 ? RT_FILTER_BILINEAR : RT_FILTER_NEAREST;
    } else if (kind == 1) {
        rt_vec3 a, b;
        float scale = 8.0f;
        if ((r = get_color(p, "the first checker colour", &a)) != RT_OK ||
            (r = get_color(p, "the second checker colour", &b)) != RT_OK)
            return r;
        if (peek_is(p, "scale")) {
            p->pos++;
            if ((r = get_float_above(p, "the checker scale", 0.0f, &scale)) != RT_OK)
                return r;
        }
        if ((r = expect_end(p, "texture")) != RT_OK)
            return r;
        tex = rt_texture_checker(rt_v4(a.x, a.y, a.z, 1), rt_v4(b.x, b.y, b.z, 1), scale);
    } else {
        rt_vec3 c;
        if ((r = get_color(p, "the constant texture colour", &c)) != RT_OK || (r = expect_end(p, "texture")) != RT_OK)
            return r;
        tex = rt_texture_constant(rt_v4(c.x, c.y, c.z, 1));
    }
    uint32_t id = rt_scene_add_texture(p->s, &tex);
    if (id == RT_NONE || !name_add(&p->textures, name->s, id, name->line) || (missing && !note_missing(p, id)))
        return nomem(p, name);
    return RT_OK;
}

/* ------------------------------------------------------------ materials */

typedef enum mat_kind {
    MK_FLOAT, MK_INT, MK_COLOR, MK_BOOL, MK_TEXTURE, MK_ALPHA_MODE, MK_DISTANCE, MK_UV, MK_BSDF,
    MK_METAL,    /* a named metal: sets eta and k */
    MK_GGX,      /* GGX alpha, isotropic (one value: alpha_u = alpha_v) or two values (offset 1) */
    MK_SMITH,
    MK_COLOR01,    /* an RGB colour with each component in [0, 1] */
    MK_THICKNESS,  /* iridescence_thickness MIN MAX: two numbers >= 0 */
    MK_MEDIUM,     /* the name of a medium defined before (interior, exterior) */
} mat_kind;

typedef struct mat_key {
    const char *key;
    const char *alias; /* another accepted spelling, or NULL */
    mat_kind kind;
    size_t offset;     /* into rt_material (MK_UV: 0 = uv_scale, 1 = uv_offset) */
    float lo, hi;      /* MK_FLOAT, MK_INT range */
} mat_key;

#define MOFF(f) offsetof(rt_material, f)
#define XTEX(k) (offsetof(rt_material, ext_tex) + (size_t)(k) * sizeof(rt_texture_slot))
static const mat_key mat_keys[] = {
    {"color", "base_color", MK_COLOR, MOFF(color), 0, 0},
    {"alpha", NULL, MK_FLOAT, MOFF(alpha), 0, 1},
    {"ambient", NULL, MK_FLOAT, MOFF(ambient), 0, FLT_MAX},
    {"diffuse", NULL, MK_FLOAT, MOFF(diffuse), 0, FLT_MAX},
    {"specular", NULL, MK_FLOAT, MOFF(specular), 0, FLT_MAX},
    {"shininess", NULL, MK_FLOAT, MOFF(shininess), 0, FLT_MAX},
    {"reflect", "reflectivity", MK_FLOAT, MOFF(reflectivity), 0, 1},
    {"transmission", NULL, MK_FLOAT, MOFF(transmission), 0, 1},
    {"transmission_color", NULL, MK_COLOR, MOFF(transmission_color), 0, 0},
    {"ior", NULL, MK_FLOAT, MOFF(ior), 0.01f, 100},
    {"metallic", NULL, MK_FLOAT, MOFF(metallic), 0, 1},
    {"roughness", NULL, MK_FLOAT, MOFF(roughness), 0, 1},
    {"emission", NULL, MK_COLOR, MOFF(emission), 0, 0},
    {"emission_strength", NULL, MK_FLOAT, MOFF(emission_strength), 0, FLT_MAX},
    {"normal_scale", NULL, MK_FLOAT, MOFF(normal_scale), -FLT_MAX, FLT_MAX},
    {"occlusion_strength", NULL, MK_FLOAT, MOFF(occlusion_strength), 0, 1},
    {"alpha_mode", NULL, MK_ALPHA_MODE, MOFF(alpha_mode), 0, 0},
    {"alpha_cutoff", NULL, MK_FLOAT, MOFF(alpha_cutoff), 0, 1},
    {"double_sided", NULL, MK_BOOL, MOFF(double_sided), 0, 0},
    {"unlit", NULL, MK_BOOL, MOFF(unlit), 0, 0},
    {"bsdf", NULL, MK_BSDF, MOFF(bsdf), 0, 0},
    {"eta", NULL, MK_COLOR, MOFF(eta), 0, 0},
    {"k", NULL, MK_COLOR, MOFF(k), 0, 0},
    {"metal", NULL, MK_METAL, 0, 0, 0},
    {"ggx_alpha", NULL, MK_GGX, 0, 0, 0},
    {"ggx_alpha_uv", NULL, MK_GGX, 1, 0, 0},
    {"smith", NULL, MK_SMITH, MOFF(smith), 0, 0},
    {"exterior_ior", NULL, MK_FLOAT, MOFF(exterior_ior), 0.01f, 100},
    {"priority", NULL, MK_INT, MOFF(priority), 0, 1000},
    {"interior", NULL, MK_MEDIUM, MOFF(interior_medium), 0, 0},
    {"exterior", NULL, MK_MEDIUM, MOFF(exterior_medium), 0, 0},
    {"absorption", NULL, MK_COLOR, MOFF(absorption), 0, 0},
    {"thickness", NULL, MK_FLOAT, MOFF(thickness), 0, FLT_MAX},
    {"thin_walled", NULL, MK_BOOL, MOFF(thin_walled), 0, 0},
    {"attenuation_color", NULL, MK_COLOR, MOFF(attenuation_color), 0, 0},
    {"attenuation_distance", NULL, MK_DISTANCE, MOFF(attenuation_distance), 0, 0},
    {"subsurface_albedo", NULL, MK_COLOR01, MOFF(subsurface_albedo), 0, 0},
    {"subsurface_radius", NULL, MK_COLOR, MOFF(subsurface_radius), 0, 0},
    {"subsurface_g", NULL, MK_FLOAT, MOFF(subsurface_g), -RT_MEDIUM_G_MAX, RT_MEDIUM_G_MAX},
    {"texture", "base_color_texture", MK_TEXTURE, MOFF(base_color_tex), 0, 0},
    {"normal_map", "normal_texture", MK_TEXTURE, MOFF(normal_tex), 0, 0},
    {"metallic_roughness_map", "metallic_roughness_texture", MK_TEXTURE, MOFF(metal_rough_tex), 0, 0},
    {"occlusion_map", "occlusion_texture", MK_TEXTURE, MOFF(occlusion_tex), 0, 0},
    {"emission_map", "emission_texture", MK_TEXTURE, MOFF(emissive_tex), 0, 0},
    {"transmission_map", "transmission_texture", MK_TEXTURE, MOFF(transmission_tex), 0, 0},
    /* the glTF PBR-next extensions (KHR_materials_*), named after their
     * properties; ranges are the extensions' schemas' (as gltf.c checks) */
    {"clearcoat", NULL, MK_FLOAT, MOFF(clearcoat), 0, 1},
    {"clearcoat_roughness", NULL, MK_FLOAT, MOFF(clearcoat_roughness), 0, 1},
    {"clearcoat_normal_scale", NULL, MK_FLOAT, MOFF(clearcoat_normal_scale), -FLT_MAX, FLT_MAX},
    {"clearcoat_map", "clearcoat_texture", MK_TEXTURE, XTEX(RT_XTEX_CLEARCOAT), 0, 0},
    {"clearcoat_roughness_map", "clearcoat_roughness_texture", MK_TEXTURE, XTEX(RT_XTEX_CLEARCOAT_ROUGHNESS), 0, 0},
    {"clearcoat_normal_map", "clearcoat_normal_texture", MK_TEXTURE, XTEX(RT_XTEX_CLEARCOAT_NORMAL), 0, 0},
    {"specular_factor", NULL, MK_FLOAT, MOFF(specular_weight), 0, 1},
    {"specular_color", NULL, MK_COLOR, MOFF(specular_color), 0, 0},
    {"specular_map", "specular_texture", MK_TEXTURE, XTEX(RT_XTEX_SPECULAR), 0, 0},
    {"specular_color_map", "specular_color_texture", MK_TEXTURE, XTEX(RT_XTEX_SPECULAR_COLOR), 0, 0},
    {"sheen_color", NULL, MK_COLOR01, MOFF(sheen_color), 0, 0},
    {"sheen_roughness", NULL, MK_FLOAT, MOFF(sheen_roughness), 0, 1},
    {"sheen_color_map", "sheen_color_texture", MK_TEXTURE, XTEX(RT_XTEX_SHEEN_COLOR), 0, 0},
    {"sheen_roughness_map", "sheen_roughness_texture", MK_TEXTURE, XTEX(RT_XTEX_SHEEN_ROUGHNESS), 0, 0},
    {"anisotropy_strength", NULL, MK_FLOAT, MOFF(anisotropy), 0, 1},
    {"anisotropy_rotation", NULL, MK_FLOAT, MOFF(anisotropy_rotation), -FLT_MAX, FLT_MAX},
    {"anisotropy_map", "anisotropy_texture", MK_TEXTURE, XTEX(RT_XTEX_ANISOTROPY), 0, 0},
    {"iridescence", NULL, MK_FLOAT, MOFF(iridescence), 0, 1},
    {"iridescence_ior", NULL, MK_FLOAT, MOFF(iridescence_ior), 1, FLT_MAX},
    {"iridescence_thickness", NULL, MK_THICKNESS, MOFF(iridescence_thickness_min), 0, FLT_MAX},
    {"iridescence_map", "iridescence_texture", MK_TEXTURE, XTEX(RT_XTEX_IRIDESCENCE), 0, 0},
    {"iridescence_thickness_map", "iridescence_thickness_texture", MK_TEXTURE, XTEX(RT_XTEX_IRIDESCENCE_THICKNESS), 0, 0},
    {"dispersion", NULL, MK_FLOAT, MOFF(dispersion), 0, FLT_MAX},
    {"diffuse_transmission", NULL, MK_FLOAT, MOFF(diffuse_transmission), 0, 1},
    {"diffuse_transmission_color", NULL, MK_COLOR01, MOFF(diffuse_transmission_color), 0, 0},
    {"diffuse_transmission_map", "diffuse_transmission_texture", MK_TEXTURE, XTEX(RT_XTEX_DIFFUSE_TRANSMISSION), 0, 0},
    {"diffuse_transmission_color_map", "diffuse_transmission_color_texture", MK_TEXTURE,
     XTEX(RT_XTEX_DIFFUSE_TRANSMISSION_COLOR), 0, 0},
    {"uv_scale", NULL, MK_UV, 0, 0, 0},
    {"uv_offset", NULL, MK_UV, 1, 0, 0},
};
#undef MOFF
#undef XTEX
#define MAT_KEY_COUNT (sizeof mat_keys / sizeof *mat_keys)

/* A key of the glTF extensions: its field lies among the extension fields
 * of rt_material (clearcoat .. ext_tex). */
static bool mat_key_is_ext(const mat_key *mk)
{
    return mk->kind != MK_UV && mk->offset >= offsetof(rt_material, clearcoat) &&
           mk->offset < offsetof(rt_material, extended);
}

/* A texture slot that holds a colour: a missing image there shows the
 * missing-texture checker; in a data slot it is left out. The extensions'
 * colour maps are tints of a layer and count as data, as in the glTF
 * loader (docs/gltf.md). */
static bool mat_key_is_colour_slot(const mat_key *mk)
{
    return mk->offset == offsetof(rt_material, base_color_tex) || mk->offset == offsetof(rt_material, emissive_tex);
}

const char *rt_scene_material_key(size_t i)
{
    return i < MAT_KEY_COUNT ? mat_keys[i].key : NULL;
}

static size_t mat_key_index(const char *key)
{
    size_t i = 0;
    while (i < MAT_KEY_COUNT && strcmp(mat_keys[i].key, key) != 0)
        i++;
    RT_DCHECK(i < MAT_KEY_COUNT);
    return i;
}

/* `metal NAME`: a named conductor's complex IOR (rt_metals) into m. */
static rt_result get_metal(parser *p, const char *what, rt_material *m)
{
    rt_result r;
    const char *names[16];
    char choices[128] = "";
    RT_DCHECK(rt_metal_count <= 16);
    for (size_t i = 0; i < rt_metal_count; i++) {
        names[i] = rt_metals[i].name;
        snprintf(choices + strlen(choices), sizeof choices - strlen(choices), "%s%s", i ? "|" : "",
                 rt_metals[i].name);
    }
    int i = 0;
    r = get_choice(p, what, names, (int)rt_metal_count, choices, &i);
    if (r == RT_OK) {
        m->eta = rt_metals[i].eta;
        m->k = rt_metals[i].k;
    }
    return r;
}

/* The material key `key` names: its index in mat_keys, or the error
 * naming the nearest key. */
static rt_result find_mat_key(parser *p, const tok *key, size_t *index)
{
    char b[80];
    size_t k = 0;
    while (k < MAT_KEY_COUNT && strcmp(key->s, mat_keys[k].key) != 0 &&
           !(mat_keys[k].alias && strcmp(key->s, mat_keys[k].alias) == 0))
        k++;
    if (k == MAT_KEY_COUNT || key->quoted) {
        rt_near_miss n = rt_near_miss_of(key->s);
        for (size_t i = 0; i < MAT_KEY_COUNT; i++)
            rt_near_miss_consider(&n, mat_keys[i].key);
        if (n.best)
            return perr(p, RT_ERR_PARSE, key, "expected a material key, got %s (did you mean '%s'?)",
                        show(key, b, sizeof b), n.best);
        return perr(p, RT_ERR_PARSE, key,
                    "expected a material key (color, alpha, ambient, diffuse, specular, shininess, reflect, "
                    "transmission, ior, metallic, roughness, emission, texture, normal_map, ... see "
                    "docs/scene-format.md), got %s",
                    show(key, b, sizeof b));
    }
    *index = k;
    return RT_OK;
}

/* The value of material key mk, read into m (uv: the uv_scale and
 * uv_offset pairs, which apply to every slot once all keys are read). */
static rt_result read_mat_value(parser *p, const mat_key *mk, rt_material *m, float uv[4])
{
    rt_result r = RT_OK;
    char what[96];
    snprintf(what, sizeof what, "material %s", mk->key);
    void *field = (char *)m + mk->offset;
    switch (mk->kind) {
    case MK_FLOAT: r = get_float_in(p, what, mk->lo, mk->hi, (float *)field); break;
    case MK_INT: {
        long long v = 0;
        r = get_int(p, what, (long long)mk->lo, (long long)mk->hi, &v);
        if (r == RT_OK)
            *(int *)field = (int)v;
        break;
    }
    case MK_COLOR: r = get_color(p, what, (rt_vec3 *)field); break;
    case MK_COLOR01: r = get_color_in(p, what, 1.0f, (rt_vec3 *)field); break;
    case MK_THICKNESS: {
        char w[128];
        snprintf(w, sizeof w, "%s (minimum, nm)", what);
        r = get_float_in(p, w, 0.0f, FLT_MAX, &m->iridescence_thickness_min);
        if (r == RT_OK) {
            snprintf(w, sizeof w, "%s (maximum, nm)", what);
            r = get_float_in(p, w, 0.0f, FLT_MAX, &m->iridescence_thickness_max);
        }
        break;
    }
    case MK_BOOL: r = get_bool(p, what, (bool *)field); break;
    case MK_ALPHA_MODE: {
        static const char *const modes[] = {"opaque", "mask", "blend"};
        static const rt_alpha_mode values[] = {RT_ALPHA_OPAQUE, RT_ALPHA_MASK, RT_ALPHA_BLEND};
        int i = 0;
        r = get_choice(p, what, modes, 3, "opaque|mask|blend", &i);
        if (r == RT_OK)
            *(rt_alpha_mode *)field = values[i];
        break;
    }
    case MK_BSDF: {
        static const char *const models[] = {"gltf", "lambert", "conductor", "dielectric", "plastic", "null"};
        static const rt_bsdf_model values[] = {RT_BSDF_GLTF,       RT_BSDF_LAMBERT, RT_BSDF_CONDUCTOR,
                                               RT_BSDF_DIELECTRIC, RT_BSDF_PLASTIC, RT_BSDF_NULL};
        int i = 0;
        r = get_choice(p, what, models, 6, "gltf|lambert|conductor|dielectric|plastic|null", &i);
        if (r == RT_OK)
            *(rt_bsdf_model *)field = values[i];
        break;
    }
    case MK_METAL: r = get_metal(p, what, m); break;
    case MK_MEDIUM: r = get_medium(p, what, (uint32_t *)field); break;
    case MK_GGX:
        r = get_float_in(p, what, 0.0f, 1.0f, &m->alpha_u);
        if (r == RT_OK && mk->offset == 1)
            r = get_float_in(p, what, 0.0f, 1.0f, &m->alpha_v);
        else if (r == RT_OK)
            m->alpha_v = m->alpha_u;
        break;
    case MK_SMITH: {
        static const char *const terms[] = {"correlated", "separable"};
        static const rt_smith values[] = {RT_SMITH_CORRELATED, RT_SMITH_SEPARABLE};
        int i = 0;
        r = get_choice(p, what, terms, 2, "correlated|separable", &i);
        if (r == RT_OK)
            *(rt_smith *)field = values[i];
        break;
    }
    case MK_DISTANCE:
        if (peek_is(p, "inf")) {
            p->pos++;
            *(float *)field = INFINITY;
        } else {
            r = get_float_above(p, what, 0.0f, (float *)field);
        }
        break;
    case MK_TEXTURE: {
        rt_texture_slot *slot = field;
        r = get_texture_ref(p, what, &slot->texture);
        /* a missing image: the checker for colour, nothing for data */
        if (r == RT_OK && !mat_key_is_colour_slot(mk) && is_missing(p, slot->texture))
            slot->texture = RT_NONE;
        break;
    }
    case MK_UV: {
        float *pair = &uv[mk->offset * 2];
        char w[256];
        snprintf(w, sizeof w, "%s (u)", what);
        r = get_float(p, w, &pair[0]);
        if (r == RT_OK) {
            snprintf(w, sizeof w, "%s (v)", what);
            r = get_float(p, w, &pair[1]);
        }
        break;
    }
    }
    return r;
}

/* The subsurface keys (rt/scene/subsurface.h): under a dielectric
 * boundary, a radius above 0 in every channel, not beside an interior
 * medium of its own. */
static rt_result check_subsurface_keys(parser *p, const rt_material *m, const tok *const *seen)
{
    static const char *const keys[] = {"subsurface_albedo", "subsurface_radius", "subsurface_g"};
    const tok *first = NULL;
    for (int i = 0; i < 3 && !first; i++)
        first = seen[mat_key_index(keys[i])];
    if (!first)
        return RT_OK;
    const tok *radius = seen[mat_key_index("subsurface_radius")];
    if (m->bsdf != RT_BSDF_DIELECTRIC)
        return perr(p, RT_ERR_INVALID, first, "material key '%s' needs 'bsdf dielectric' (the boundary it walks under)",
                    first->s);
    if (!radius)
        return perr(p, RT_ERR_INVALID, first, "material key '%s' needs 'subsurface_radius R G B' (the mean free path)",
                    first->s);
    if (!(m->subsurface_radius.x > 0.0f && m->subsurface_radius.y > 0.0f && m->subsurface_radius.z > 0.0f))
        return perr(p, RT_ERR_INVALID, radius, "material subsurface_radius must be above 0 in every channel");
    if (seen[mat_key_index("interior")])
        return perr(p, RT_ERR_INVALID, seen[mat_key_index("interior")],
                    "material key 'interior' does not go with 'subsurface_radius' (the subsurface keys make the "
                    "interior medium)");
    return RT_OK;
}

/* The keys that need a particular bsdf, and the pairs given either one way
 * or the other (seen: the token of each key given, NULL if not). */
static rt_result check_mat_keys(parser *p, const rt_material *m, const tok *const *seen)
{
    rt_result r;
    /* the conductor's keys: only with bsdf conductor, one way each */
    const tok *k_metal = NULL, *k_eta = NULL, *k_alpha = NULL, *k_alpha_uv = NULL;
    for (size_t i = 0; i < MAT_KEY_COUNT; i++) {
        const mat_key *mk = &mat_keys[i];
        bool complex_ior = mk->kind == MK_COLOR && (mk->offset == offsetof(rt_material, eta) ||
                                                    mk->offset == offsetof(rt_material, k));
        bool exterior = mk->kind == MK_FLOAT && mk->offset == offsetof(rt_material, exterior_ior);
        bool absorbs = mk->kind == MK_COLOR && mk->offset == offsetof(rt_material, absorption);
        bool media_key = mk->kind == MK_MEDIUM || (mk->kind == MK_INT && mk->offset == offsetof(rt_material, priority));
        if (!seen[i])
            continue;
        if (m->bsdf == RT_BSDF_NULL && !media_key && mk->kind != MK_BSDF)
            return perr(p, RT_ERR_INVALID, seen[i],
                        "material key '%s' does not go with 'bsdf null' (a boundary only: interior, exterior, "
                        "priority)", mk->key);
        if (media_key && m->bsdf != RT_BSDF_DIELECTRIC && m->bsdf != RT_BSDF_NULL)
            return perr(p, RT_ERR_INVALID, seen[i], "material key '%s' needs 'bsdf dielectric' or 'bsdf null'",
                        mk->key);
        if (media_key)
            continue;
        if (mat_key_is_ext(mk) && m->bsdf != RT_BSDF_GLTF)
            return perr(p, RT_ERR_INVALID, seen[i],
                        "material key '%s' (a glTF material extension) needs 'bsdf gltf', the default", mk->key);
        if (absorbs && m->bsdf != RT_BSDF_DIELECTRIC)
            return perr(p, RT_ERR_INVALID, seen[i], "material key '%s' needs 'bsdf dielectric'", mk->key);
        if (exterior && m->bsdf != RT_BSDF_DIELECTRIC && m->bsdf != RT_BSDF_PLASTIC)
            return perr(p, RT_ERR_INVALID, seen[i], "material key '%s' needs 'bsdf dielectric' or 'bsdf plastic'",
                        mk->key);
        if (!(complex_ior || mk->kind == MK_METAL || mk->kind == MK_GGX || mk->kind == MK_SMITH))
            continue;
        bool any = mk->kind == MK_GGX && mk->offset == 0; /* ggx_alpha: conductor, dielectric or plastic */
        if (m->bsdf != RT_BSDF_CONDUCTOR && !(any && (m->bsdf == RT_BSDF_DIELECTRIC || m->bsdf == RT_BSDF_PLASTIC)))
            return perr(p, RT_ERR_INVALID, seen[i], "material key '%s' needs 'bsdf conductor'%s", mk->key,
                        any ? ", 'bsdf dielectric' or 'bsdf plastic'" : "");
        if (mk->kind == MK_METAL)
            k_metal = seen[i];
        else if (complex_ior && !k_eta)
            k_eta = seen[i];
        else if (mk->kind == MK_GGX)
            *(mk->offset ? &k_alpha_uv : &k_alpha) = seen[i];
    }
    if ((r = check_subsurface_keys(p, m, seen)) != RT_OK)
        return r;
    if (m->bsdf == RT_BSDF_NULL && m->interior_medium == RT_NONE) {
        const tok *at = seen[mat_key_index("bsdf")];
        return perr(p, RT_ERR_INVALID, at, "'bsdf null' needs 'interior MEDIUM' (the medium it bounds)");
    }
    if (k_metal && k_eta)
        return perr(p, RT_ERR_INVALID, k_eta, "material key '%s': give either 'metal NAME' or 'eta' and 'k', not both",
                    k_eta->s);
    if (k_alpha && k_alpha_uv)
        return perr(p, RT_ERR_INVALID, k_alpha_uv, "give either 'ggx_alpha' or 'ggx_alpha_uv', not both");
    return RT_OK;
}

/* The defaults that depend on the bsdf and on which keys were given, the
 * UV transform on every slot, and what the path tracer layers. */
static void finish_material(rt_material *m, const tok *const *seen, const float uv[4])
{
    /* a null boundary is no surface: cut away everywhere for the
     * integrators that do not trace media (their rays and shadow rays pass
     * it), an index of 1 on both sides for nested dielectrics in it */
    if (m->bsdf == RT_BSDF_NULL) {
        m->alpha_mode = RT_ALPHA_MASK;
        m->alpha_cutoff = 2.0f;
        m->ior = 1.0f;
        m->exterior_ior = 1.0f;
    }
    /* glass transmits: whitted refracts it, shadow rays treat it as glass */
    if (m->bsdf == RT_BSDF_DIELECTRIC && !seen[mat_key_index("transmission")])
        m->transmission = 1.0f;
    /* conductors and dielectrics are smooth unless given a roughness (as in
     * pbrt-v4 and Mitsuba 3), not glTF's rough default */
    if ((m->bsdf == RT_BSDF_DIELECTRIC || m->bsdf == RT_BSDF_CONDUCTOR || m->bsdf == RT_BSDF_PLASTIC) &&
        !seen[mat_key_index("roughness")])
        m->roughness = 0.0f;
    /* whitted: KHR_materials_specular scales the Phong specular weight by
     * what it does to the dielectric's F0 (as the glTF loader's mapping
     * does, docs/gltf.md), unless `specular` itself is given */
    if ((seen[mat_key_index("specular_factor")] || seen[mat_key_index("specular_color")]) &&
        !seen[mat_key_index("specular")]) {
        rt_vec3 sc = rt_vmin(m->specular_color, rt_v3s(25.0f)); /* F0 = min(0.04 specular_color, 1) */
        m->specular *= m->specular_weight * (sc.x + sc.y + sc.z) / 3.0f;
    }
    /* uv_scale / uv_offset apply to every slot: uv' = uv * scale + offset */
    rt_texture_slot *slots[6 + RT_XTEX_COUNT] = {&m->base_color_tex, &m->metal_rough_tex, &m->normal_tex,
                                                 &m->occlusion_tex,  &m->emissive_tex,    &m->transmission_tex};
    for (int i = 0; i < RT_XTEX_COUNT; i++)
        slots[6 + i] = &m->ext_tex[i];
    for (size_t i = 0; i < sizeof slots / sizeof *slots; i++) {
        float *t = slots[i]->uv_transform;
        t[0] = uv[0]; t[1] = 0; t[2] = uv[2];
        t[3] = 0; t[4] = uv[1]; t[5] = uv[3];
    }
    /* the extensions' keys: the path tracer layers them as the glTF loader's */
    m->extended = rt_material_extended(m);
}

static rt_result st_material(parser *p, const tok *kw)
{
    (void)kw;
    const tok *name = NULL;
    rt_result r;
    if ((r = get_word(p, "a material name", &name)) != RT_OK ||
        (r = check_new_name(p, name, &p->materials, "material")) != RT_OK)
        return r;
    rt_material m;
    rt_material_default(&m, name->s);
    const tok *seen[MAT_KEY_COUNT] = {0};
    float uv[4] = {1, 1, 0, 0}; /* scale u, v; offset u, v */
    while (peek(p)) {
        const tok *key = peek(p);
        p->pos++;
        size_t k = 0;
        if ((r = find_mat_key(p, key, &k)) != RT_OK)
            return r;
        if (seen[k])
            return perr(p, RT_ERR_INVALID, key, "material key '%s' is given twice (first at column %d)",
                        mat_keys[k].key, seen[k]->col);
        seen[k] = key;
        if ((r = read_mat_value(p, &mat_keys[k], &m, uv)) != RT_OK)
            return r;
    }
    if ((r = check_mat_keys(p, &m, seen)) != RT_OK)
        return r;
    finish_material(&m, seen, uv);
    m.subsurface = seen[mat_key_index("subsurface_radius")] != NULL;
    if (!rt_subsurface_attach(p->s, &m))
        return nomem(p, name);
    uint32_t id = rt_scene_add_material(p->s, &m);
    if (id == RT_NONE || !name_add(&p->materials, name->s, id, name->line))
        return nomem(p, name);
    return RT_OK;
}

/* ------------------------------------------------------------ primitives */

static rt_result st_sphere(parser *p, const tok *kw)
{
    (void)kw;
    rt_vec3 c;
    float radius = 0;
    uint32_t m = 0;
    rt_result r;
    if ((r = get_vec3(p, "the sphere centre", &c)) != RT_OK ||
        (r = get_float_above(p, "the sphere radius", 0.0f, &radius)) != RT_OK ||
        (r = get_material(p, "the sphere", &m)) != RT_OK || (r = expect_end(p, "sphere")) != RT_OK)
        return r;
    if (rt_scene_add_sphere(p->s, c, radius, m) == RT_NONE)
        return nomem(p, kw);
    return RT_OK;
}

static rt_result st_quad(parser *p, const tok *kw)
{
    rt_vec3 c, u, v;
    uint32_t m = 0;
    rt_result r;
    if ((r = get_vec3(p, "the quad corner", &c)) != RT_OK || (r = get_vec3(p, "the quad edge u", &u)) != RT_OK ||
        (r = get_vec3(p, "the quad edge v", &v)) != RT_OK || (r = get_material(p, "the quad", &m)) != RT_OK ||
        (r = expect_end(p, "quad")) != RT_OK)
        return r;
    rt_vec3 n = rt_cross(u, v);
    if (!(rt_length2(n) < FLT_MAX))
        return perr(p, RT_ERR_INVALID, kw, "the quad is too large: its normal overflows float arithmetic");
    if (!(rt_length2(n) > 0.0f))
        return perr(p, RT_ERR_INVALID, kw, "degenerate quad: its edges are zero or parallel");
    if (rt_scene_add_quad(p->s, c, u, v, m) == RT_NONE)
        return nomem(p, kw);
    return RT_OK;
}

static rt_result st_triangle(parser *p, const tok *kw)
{
    rt_vec3 a, b, c;
    uint32_t m = 0;
    rt_result r;
    if ((r = get_vec3(p, "the triangle's first vertex", &a)) != RT_OK ||
        (r = get_vec3(p, "the triangle's second vertex", &b)) != RT_OK ||
        (r = get_vec3(p, "the triangle's third vertex", &c)) != RT_OK ||
        (r = get_material(p, "the triangle", &m)) != RT_OK || (r = expect_end(p, "triangle")) != RT_OK)
        return r;
    rt_vec3 n = rt_cross(rt_sub(b, a), rt_sub(c, a));
    if (!(rt_length2(n) < FLT_MAX))
        return perr(p, RT_ERR_INVALID, kw, "the triangle is too large: its normal overflows float arithmetic");
    if (!(rt_length2(n) > 0.0f))
        return perr(p, RT_ERR_INVALID, kw, "degenerate triangle: its vertices are collinear");
    n = rt_normalize(n);
    uint32_t v0 = rt_scene_add_vertices(p->s, 3);
    if (v0 == RT_NONE)
        return nomem(p, kw);
    rt_vertices *vs = &p->s->vertices;
    const rt_vec3 pos[3] = {a, b, c};
    const rt_vec2 uv[3] = {{0, 0}, {1, 0}, {0, 1}};
    for (int i = 0; i < 3; i++) {
        vs->position[v0 + i] = pos[i];
        vs->normal[v0 + i] = n;
        vs->uv0[v0 + i] = uv[i];
    }
    if (rt_scene_add_triangle(p->s, v0, v0 + 1, v0 + 2, m, RT_TRI_UV) == RT_NONE)
        return nomem(p, kw);
    return RT_OK;
}

/* translate / rotate / scale options of `mesh` and `model`, composed as
 * T * Rz * Ry * Rx * S (scale first, then rotate about x, y, z, then
 * translate). Returns RT_OK and leaves unknown words for the caller. */
typedef struct xform {
    const tok *translate_tok, *rotate_tok, *scale_tok;
    rt_vec3 translate, rotate, scale;
} xform;

/* Tries to read one transform option; *taken tells whether it did. */
static rt_result get_xform_option(parser *p, xform *x, const char *stmt, bool *taken)
{
    const tok *key = peek(p);
    rt_result r = RT_OK;
    char what[64];
    *taken = false;
    if (!key || key->quoted)
        return RT_OK;
    if (strcmp(key->s, "translate") == 0) {
        if (x->translate_tok)
            return perr(p, RT_ERR_INVALID, key, "'translate' is given twice");
        p->pos++;
        x->translate_tok = key;
        snprintf(what, sizeof what, "the %s translation", stmt);
        r = get_vec3(p, what, &x->translate);
    } else if (strcmp(key->s, "rotate") == 0) {
        if (x->rotate_tok)
            return perr(p, RT_ERR_INVALID, key, "'rotate' is given twice");
        p->pos++;
        x->rotate_tok = key;
        snprintf(what, sizeof what, "the %s rotation in degrees", stmt);
        r = get_vec3(p, what, &x->rotate);
    } else if (strcmp(key->s, "scale") == 0) {
        if (x->scale_tok)
            return perr(p, RT_ERR_INVALID, key, "'scale' is given twice");
        p->pos++;
        x->scale_tok = key;
        snprintf(what, sizeof what, "the %s scale", stmt);
        float s = 0;
        if ((r = get_float(p, what, &s)) != RT_OK)
            return r;
        x->scale = rt_v3s(s);
        /* `scale X Y Z` when a number follows */
        float tmp;
        const tok *t = peek(p);
        if (t && !t->quoted && rt_parse_float(t->s, &tmp) != RT_NUMBER_BAD) {
            snprintf(what, sizeof what, "the %s scale (y)", stmt);
            if ((r = get_float(p, what, &x->scale.y)) != RT_OK)
                return r;
            snprintf(what, sizeof what, "the %s scale (z)", stmt);
            if ((r = get_float(p, what, &x->scale.z)) != RT_OK)
                return r;
        }
        if (x->scale.x == 0.0f || x->scale.y == 0.0f || x->scale.z == 0.0f)
            return perr(p, RT_ERR_INVALID, key, "the %s scale must not be zero", stmt);
    } else {
        return RT_OK;
    }
    *taken = r == RT_OK;
    return r;
}

static rt_mat4 xform_matrix(const xform *x)
{
    rt_mat4 m = rt_mat4_scale(x->scale_tok ? x->scale : rt_v3s(1));
    if (x->rotate_tok) {
        m = rt_mat4_mul(rt_mat4_rotate_axis(0, x->rotate.x), m);
        m = rt_mat4_mul(rt_mat4_rotate_axis(1, x->rotate.y), m);
        m = rt_mat4_mul(rt_mat4_rotate_axis(2, x->rotate.z), m);
    }
    return rt_mat4_mul(rt_mat4_translate(x->translate_tok ? x->translate : rt_v3s(0)), m);
}

static rt_result st_mesh(parser *p, const tok *kw)
{
    const tok *file = NULL;
    rt_result r;
    char b[80];
    if ((r = get_word(p, "a mesh file (.obj, .ply or .off)", &file)) != RT_OK)
        return r;
    xform x = {0};
    uint32_t material = RT_NONE;
    const tok *mat_tok = NULL, *override_tok = NULL;
    bool first = true;
    while (peek(p)) {
        bool taken = false;
        if ((r = get_xform_option(p, &x, "mesh", &taken)) != RT_OK)
            return r;
        if (!taken) {
            const tok *t = peek(p);
            if (peek_is(p, "material_override")) {
                if (override_tok)
                    return perr(p, RT_ERR_INVALID, t, "'material_override' is given twice");
                override_tok = t;
                p->pos++;
            } else if (first) {
                mat_tok = t;
                if ((r = get_material(p, "the mesh", &material)) != RT_OK)
                    return r;
            } else {
                return perr(p, RT_ERR_PARSE, t,
                            "expected a mesh option (translate, rotate, scale, material_override), got %s%s",
                            show(t, b, sizeof b), mat_tok ? "" : " (the material must come right after the file)");
            }
        }
        first = false;
    }
    if (override_tok && !mat_tok)
        return perr(p, RT_ERR_INVALID, override_tok, "'material_override' needs a material after the mesh file");
    if (material == RT_NONE) {
        if (p->default_material == RT_NONE) {
            rt_material m;
            rt_material_default(&m, "__default");
            p->default_material = rt_scene_add_material(p->s, &m);
            if (p->default_material == RT_NONE)
                return nomem(p, kw);
        }
        material = p->default_material;
    }
    char path[MAX_PATH_LEN];
    if ((r = resolve_path(p, file, path, sizeof path)) != RT_OK)
        return r;
    rt_mat4 m = xform_matrix(&x);
    rt_error inner = {0};
    rt_mesh_load_stats stats = {0};
    rt_mesh_options opt = {.transform = &m, .material = material, .override_material = override_tok != NULL};
    r = rt_mesh_load(p->s, path, &opt, &stats, &inner);
    if (r != RT_OK)
        return loader_err(p, file, r, &inner);
    rt_info("%s:%d: mesh %s: %zu triangles, %zu vertices, %zu materials", p->name, kw->line, path, stats.triangles,
            stats.vertices, stats.materials);
    return RT_OK;
}

/* `object NAME`: the triangles, meshes and models up to `end` form an
 * object, kept in its own space and placed only by `instance` lines. */
static rt_result st_object(parser *p, const tok *kw)
{
    const tok *name = NULL;
    rt_result r;
    if (p->in_object)
        return perr(p, RT_ERR_INVALID, kw, "objects do not nest: object '%s' (line %d) has no 'end' before this",
                    p->object_name.s, p->object_name.line);
    if ((r = get_word(p, "an object name", &name)) != RT_OK ||
        (r = check_new_name(p, name, &p->objects, "object")) != RT_OK || (r = expect_end(p, "object")) != RT_OK)
        return r;
    p->in_object = true;
    p->object_name = *name;
    p->object_t0 = p->s->triangles.count;
    p->object_v0 = p->s->vertices.count;
    return RT_OK;
}

/* `end`: closes the open object. */
static rt_result st_end(parser *p, const tok *kw)
{
    rt_result r;
    if (!p->in_object)
        return perr(p, RT_ERR_PARSE, kw, "'end' without an open 'object'");
    if ((r = expect_end(p, "end")) != RT_OK)
        return r;
    size_t nt = p->s->triangles.count - p->object_t0;
    if (nt == 0)
        return perr(p, RT_ERR_INVALID, &p->object_name, "object '%s' holds no triangles", p->object_name.s);
    uint32_t id = rt_scene_add_object(p->s, p->object_t0, nt, p->object_v0, p->s->vertices.count - p->object_v0);
    if (id == RT_NONE || !name_add(&p->objects, p->object_name.s, id, p->object_name.line))
        return nomem(p, kw);
    p->in_object = false;
    return RT_OK;
}

/* `instance NAME [translate X Y Z] [rotate X Y Z] [scale S | SX SY SZ]`:
 * one placement of an object, by the transform of `mesh` and `model`. */
static rt_result st_instance(parser *p, const tok *kw)
{
    const tok *name = NULL;
    rt_result r;
    char b[80];
    if (p->in_object)
        return perr(p, RT_ERR_INVALID, kw, "instances do not nest: 'instance' inside object '%s' (line %d)",
                    p->object_name.s, p->object_name.line);
    if ((r = get_word(p, "an object name", &name)) != RT_OK)
        return r;
    const name_entry *e = name_find(&p->objects, name->s);
    if (!e) {
        const char *near = closest_name(p, &p->objects, false, name->s);
        if (near)
            return perr(p, RT_ERR_INVALID, name, "undefined object %s (did you mean '%s'?)", show(name, b, sizeof b),
                        near);
        return perr(p, RT_ERR_INVALID, name, "undefined object %s (define it with 'object' ... 'end' before use)",
                    show(name, b, sizeof b));
    }
    xform x = {0};
    while (peek(p)) {
        bool taken = false;
        if ((r = get_xform_option(p, &x, "instance", &taken)) != RT_OK)
            return r;
        if (!taken)
            return perr(p, RT_ERR_PARSE, peek(p), "expected an instance option (translate, rotate, scale), got %s",
                        show(peek(p), b, sizeof b));
    }
    rt_mat4 m = xform_matrix(&x);
    rt_instance_check c = rt_instance_check_transform(&m);
    if (c != RT_INSTANCE_OK)
        return perr(p, RT_ERR_INVALID, kw, "the instance's transform is %s", rt_instance_check_name(c));
    if (rt_scene_add_instance(p->s, e->index, &m) == RT_NONE)
        return instance_nomem(p, kw);
    return RT_OK;
}

/* The pose options of a `model` line: `time T`, `time_offset T`,
 * `animation NAME|INDEX`; *taken tells whether one was read. */
typedef struct model_pose {
    const tok *time_tok, *offset_tok, *anim_tok;
    float time, offset;
} model_pose;

static rt_result get_pose_option(parser *p, model_pose *m, bool *taken)
{
    const tok *key = peek(p);
    rt_result r = RT_OK;
    *taken = false;
    if (!key || key->quoted)
        return RT_OK;
    if (strcmp(key->s, "time") == 0 || strcmp(key->s, "time_offset") == 0) {
        bool fixed = key->s[4] == 0;
        const tok **slot = fixed ? &m->time_tok : &m->offset_tok;
        if (*slot)
            return perr(p, RT_ERR_INVALID, key, "'%s' is given twice", key->s);
        if (fixed ? m->offset_tok != NULL : m->time_tok != NULL)
            return perr(p, RT_ERR_INVALID, key,
                        "give 'time' (a fixed pose) or 'time_offset' (the frame time plus an offset), not both");
        p->pos++;
        *slot = key;
        r = get_float_in(p, fixed ? "the model's animation time in seconds" : "the model's time offset in seconds",
                         -1e7f, 1e7f, fixed ? &m->time : &m->offset);
    } else if (strcmp(key->s, "animation") == 0) {
        if (m->anim_tok)
            return perr(p, RT_ERR_INVALID, key, "'animation' is given twice");
        p->pos++;
        r = get_word(p, "an animation name or index", &m->anim_tok);
    } else {
        return RT_OK;
    }
    *taken = r == RT_OK;
    return r;
}

/* A model line's pose into the loader's options: posed when the render
 * has a frame time or the line gives any pose option (the frame time is
 * then 0 when the render has none); `time` fixes the pose, `time_offset`
 * adds to the frame time. */
static rt_result apply_pose(parser *p, const model_pose *m, rt_gltf_options *opt)
{
    opt->use_time = p->pose.use_time || m->time_tok || m->offset_tok || m->anim_tok;
    if (!opt->use_time)
        return RT_OK;
    float frame = p->pose.use_time ? p->pose.time : 0.0f;
    opt->time = m->time_tok ? m->time : frame + (m->offset_tok ? m->offset : 0.0f);
    opt->animation = p->pose.animation;
    opt->animation_name = p->pose.animation_name;
    opt->animation_optional = true;
    if (m->anim_tok) {
        long long n = 0;
        opt->animation_optional = false;
        if (!m->anim_tok->quoted && rt_parse_int(m->anim_tok->s, &n) == RT_NUMBER_OK) {
            if (n < 0 || n > INT_MAX)
                return perr(p, RT_ERR_INVALID, m->anim_tok, "an animation index counts from 0, got %s", m->anim_tok->s);
            opt->animation = (int)n;
            opt->animation_name = NULL;
        } else {
            opt->animation_name = m->anim_tok->s;
        }
    }
    return RT_OK;
}

/* Whether two loads of a file give the same geometry: the glTF options
 * that shape it (the transform aside). */
static bool same_model_options(const rt_gltf_options *a, const rt_gltf_options *b)
{
    if (a->use_scene_index != b->use_scene_index || (a->use_scene_index && a->scene_index != b->scene_index) ||
        a->use_time != b->use_time)
        return false;
    if (!a->use_time)
        return true;
    return memcmp(&a->time, &b->time, sizeof a->time) == 0 && a->animation == b->animation &&
           a->animation_optional == b->animation_optional &&
           (a->animation_name && b->animation_name ? strcmp(a->animation_name, b->animation_name) == 0
                                                   : a->animation_name == b->animation_name);
}

static model_load *find_model(parser *p, const char *path, const rt_gltf_options *opt)
{
    for (size_t i = 0; i < p->model_count; i++)
        if (strcmp(p->models[i].path, path) == 0 && same_model_options(&p->models[i].opt, opt))
            return &p->models[i];
    return NULL;
}

/* True when triangles [t0, t0 + nt) use an emissive material (a lamp
 * stays world geometry, for the light table). */
static bool range_emits(const rt_scene *s, size_t t0, size_t nt)
{
    for (size_t t = t0; t < t0 + nt; t++) {
        uint32_t mi = s->triangles.material[t];
        if (mi >= s->material_count)
            continue;
        const rt_material *m = &s->materials[mi];
        if ((m->emission.x > 0.0f || m->emission.y > 0.0f || m->emission.z > 0.0f) && m->emission_strength > 0.0f)
            return true;
    }
    return false;
}

/* Notes a model line's load (its scene counts before it in `before`) for
 * the lines after it; false when out of memory. */
static bool record_model(parser *p, const char *path, const rt_gltf_options *opt, const rt_scene_mark *before,
                         bool animated, int line)
{
    rt_scene *s = p->s;
    if (!rt_grow((void **)&p->models, &p->model_cap, p->model_count + 1, sizeof *p->models))
        return false;
    model_load m;
    memset(&m, 0, sizeof m);
    m.path = strdup(path);
    m.opt.use_scene_index = opt->use_scene_index;
    m.opt.scene_index = opt->scene_index;
    m.opt.use_time = opt->use_time;
    m.opt.time = opt->time;
    m.opt.animation = opt->animation;
    m.opt.animation_optional = opt->animation_optional;
    m.opt.animation_name = opt->animation_name ? strdup(opt->animation_name) : NULL;
    if (!m.path || (opt->animation_name && !m.opt.animation_name)) {
        free(m.path);
        free((char *)m.opt.animation_name);
        return false;
    }
    m.t0 = before->triangles;
    m.nt = s->triangles.count - before->triangles;
    m.v0 = before->vertices;
    m.nv = s->vertices.count - before->vertices;
    m.placed = opt->use_transform ? opt->transform : rt_mat4_identity();
    m.instanceable = m.nt > 0 && s->object_count == before->objects && s->instance_count == before->instances &&
                     s->light_count == before->lights && s->camera_count == before->cameras &&
                     !range_emits(s, m.t0, m.nt) && rt_instance_check_transform(&m.placed) == RT_INSTANCE_OK;
    m.animated = animated;
    m.object = RT_NONE;
    m.line = line;
    p->models[p->model_count++] = m;
    return true;
}

/* A second (or later) line of a load: the first load's triangles become
 * an object, in the space of the first line's transform, placed where
 * they are (identity) and by this line's transform times the first's
 * inverse. */
static rt_result place_model_again(parser *p, const tok *kw, model_load *m, const rt_mat4 *to_world)
{
    rt_scene *s = p->s;
    if (m->object == RT_NONE) {
        uint32_t id = rt_scene_add_object(s, m->t0, m->nt, m->v0, m->nv);
        if (id == RT_NONE)
            return nomem(p, kw);
        for (size_t i = 0; i < p->objects.count; i++) /* objects after it moved up one */
            if (p->objects.items[i].index >= id)
                p->objects.items[i].index++;
        for (size_t i = 0; i < p->model_count; i++)
            if (p->models[i].object != RT_NONE && p->models[i].object >= id)
                p->models[i].object++;
        m->object = id;
        rt_mat4 same = rt_mat4_identity();
        if (rt_scene_add_instance(s, id, &same) == RT_NONE)
            return instance_nomem(p, kw);
    }
    rt_mat4 rel = rt_mat4_mul(*to_world, rt_instance_inverse(&m->placed));
    rt_instance_check c = rt_instance_check_transform(&rel);
    if (c != RT_INSTANCE_OK)
        return perr(p, RT_ERR_INVALID, kw, "the model's transform relative to line %d's is %s", m->line,
                    rt_instance_check_name(c));
    if (rt_scene_add_instance(s, m->object, &rel) == RT_NONE)
        return instance_nomem(p, kw);
    return RT_OK;
}

static rt_result st_model(parser *p, const tok *kw)
{
    const tok *file = NULL;
    rt_result r;
    char b[80];
    if ((r = get_word(p, "a glTF file (.gltf or .glb)", &file)) != RT_OK)
        return r;
    xform x = {0};
    model_pose pose = {0};
    rt_gltf_options opt = {0};
    opt.flatten_instances = p->in_object || p->pose.flatten_instances; /* an object holds triangles; instances
                                                                          * do not nest */
    const tok *scene_tok = NULL;
    while (peek(p)) {
        bool taken = false;
        if ((r = get_xform_option(p, &x, "model", &taken)) != RT_OK)
            return r;
        if (!taken && (r = get_pose_option(p, &pose, &taken)) != RT_OK)
            return r;
        if (taken)
            continue;
        const tok *t = peek(p);
        if (peek_is(p, "scene")) {
            if (scene_tok)
                return perr(p, RT_ERR_INVALID, t, "'scene' is given twice");
            scene_tok = t;
            p->pos++;
            long long n = 0;
            if ((r = get_int(p, "the glTF scene index", 0, INT_MAX, &n)) != RT_OK)
                return r;
            opt.scene_index = (int)n;
            opt.use_scene_index = true;
        } else {
            return perr(p, RT_ERR_PARSE, t,
                        "expected a model option (translate, rotate, scale, scene, time, time_offset, animation), "
                        "got %s",
                        show(t, b, sizeof b));
        }
    }
    char path[MAX_PATH_LEN];
    if ((r = resolve_path(p, file, path, sizeof path)) != RT_OK)
        return r;
    if ((r = apply_pose(p, &pose, &opt)) != RT_OK)
        return r;
    opt.catalog = p->pose.catalog;
    opt.use_transform = x.translate_tok || x.rotate_tok || x.scale_tok;
    opt.transform = opt.use_transform ? xform_matrix(&x) : rt_mat4_identity();
    bool share = !p->in_object && !p->pose.flatten_instances; /* the same file and pose again: an instance */
    model_load *again = share ? find_model(p, path, &opt) : NULL;
    if (again && again->instanceable) {
        if ((r = place_model_again(p, kw, again, &opt.transform)) != RT_OK)
            return r;
        if (again->animated && !pose.time_tok && p->pose.animated)
            *p->pose.animated = true;
        rt_info("%s:%d: model %s: placed again as an instance of line %d's load (%zu triangles)", p->name, kw->line,
                path, again->line, again->nt);
        return RT_OK;
    }
    rt_scene_mark before = rt_scene_mark_of(p->s);
    rt_error inner = {0};
    rt_gltf_stats stats;
    memset(&stats, 0, sizeof stats);
    r = rt_gltf_load(p->s, path, &opt, &stats, &inner);
    if (r != RT_OK)
        return loader_err(p, file, r, &inner);
    if (share && !again && !record_model(p, path, &opt, &before, stats.animated, kw->line))
        return nomem(p, kw);
    if (stats.animated && !pose.time_tok && p->pose.animated) /* its pose follows the frame time */
        *p->pose.animated = true;
    rt_info("%s:%d: model %s: %zu triangles, %zu materials, %zu cameras%s", p->name, kw->line, path, stats.triangles,
            stats.materials, stats.cameras, opt.use_time ? ", posed" : "");
    return RT_OK;
}

/* ------------------------------------------------------------ lights */

static rt_result get_range_option(parser *p, rt_light *l)
{
    if (!peek_is(p, "range"))
        return RT_OK;
    p->pos++;
    return get_float_in(p, "the light range", 0.0f, FLT_MAX, &l->range);
}

static rt_result st_light(parser *p, const tok *kw)
{
    static const char *const kinds[] = {"point", "directional", "spot", "area"};
    int kind = 0;
    rt_result r;
    if ((r = get_choice(p, "a light kind", kinds, 4, "point|directional|spot|area", &kind)) != RT_OK)
        return r;
    rt_light l;
    memset(&l, 0, sizeof l);
    l.quad = RT_NONE;
    switch (kind) {
    case 0:
        l.kind = RT_LIGHT_POINT;
        if ((r = get_vec3(p, "the point light position", &l.position)) != RT_OK ||
            (r = get_color(p, "the point light colour", &l.color)) != RT_OK ||
            (r = get_float_in(p, "the point light intensity", 0.0f, FLT_MAX, &l.intensity)) != RT_OK ||
            (r = get_range_option(p, &l)) != RT_OK || (r = expect_end(p, "light point")) != RT_OK)
            return r;
        break;
    case 1: {
        l.kind = RT_LIGHT_DIRECTIONAL;
        const tok *dt = peek(p);
        if ((r = get_vec3(p, "the directional light direction", &l.direction)) != RT_OK ||
            (r = get_color(p, "the directional light colour", &l.color)) != RT_OK ||
            (r = get_float_in(p, "the directional light irradiance", 0.0f, FLT_MAX, &l.intensity)) != RT_OK ||
            (r = expect_end(p, "light directional")) != RT_OK)
            return r;
        if (!(rt_length2(l.direction) > 0.0f))
            return perr(p, RT_ERR_INVALID, dt, "the directional light direction is zero");
        l.direction = rt_normalize(l.direction);
        break;
    }
    case 2: {
        l.kind = RT_LIGHT_SPOT;
        float inner = 0, outer = 0;
        const tok *dt = NULL;
        if ((r = get_vec3(p, "the spot light position", &l.position)) != RT_OK)
            return r;
        dt = peek(p);
        if ((r = get_vec3(p, "the spot light direction", &l.direction)) != RT_OK ||
            (r = get_color(p, "the spot light colour", &l.color)) != RT_OK ||
            (r = get_float_in(p, "the spot light intensity", 0.0f, FLT_MAX, &l.intensity)) != RT_OK ||
            (r = get_float_in(p, "the spot light inner cone angle", 0.0f, 90.0f, &inner)) != RT_OK)
            return r;
        const tok *inner_tok = prev(p);
        if ((r = get_float_in(p, "the spot light outer cone angle", 0.0f, 90.0f, &outer)) != RT_OK)
            return r;
        if (!(outer > 0.0f))
            return perr(p, RT_ERR_INVALID, prev(p), "the spot light outer cone angle must be > 0, got '%s'",
                        prev(p)->s);
        if (inner > outer)
            return perr(p, RT_ERR_INVALID, inner_tok,
                        "the spot light inner cone angle (%s) must not exceed the outer one (%s)", inner_tok->s,
                        prev(p)->s);
        if ((r = get_range_option(p, &l)) != RT_OK || (r = expect_end(p, "light spot")) != RT_OK)
            return r;
        if (!(rt_length2(l.direction) > 0.0f))
            return perr(p, RT_ERR_INVALID, dt, "the spot light direction is zero");
        l.direction = rt_normalize(l.direction);
        l.inner_cone = inner * (RT_PI / 180.0f);
        l.outer_cone = outer * (RT_PI / 180.0f);
        break;
    }
    default: {
        l.kind = RT_LIGHT_AREA;
        if ((r = get_vec3(p, "the area light corner", &l.position)) != RT_OK ||
            (r = get_vec3(p, "the area light edge u", &l.edge_u)) != RT_OK ||
            (r = get_vec3(p, "the area light edge v", &l.edge_v)) != RT_OK ||
            (r = get_color(p, "the area light colour", &l.color)) != RT_OK ||
            (r = get_float_in(p, "the area light radiance", 0.0f, FLT_MAX, &l.intensity)) != RT_OK ||
            (r = expect_end(p, "light area")) != RT_OK)
            return r;
        rt_vec3 n = rt_cross(l.edge_u, l.edge_v);
        if (!(rt_length2(n) > 0.0f) || !rt_finite3(n))
            return perr(p, RT_ERR_INVALID, kw, "degenerate area light: its edges are zero or parallel");
        rt_vec3 emission = rt_scale(l.color, l.intensity);
        if (!rt_finite3(emission))
            return perr(p, RT_ERR_INVALID, kw, "area light colour times radiance overflows");
        /* the visible emitter: a quad with an emissive, black, one-sided material */
        rt_material m;
        char mname[64];
        snprintf(mname, sizeof mname, "__area_light_%zu", p->s->light_count);
        rt_material_default(&m, mname);
        m.color = rt_v3s(0.0f);
        m.ambient = m.diffuse = m.specular = 0.0f;
        m.emission = emission;
        m.emission_strength = 1.0f;
        m.double_sided = false;
        uint32_t mi = rt_scene_add_material(p->s, &m);
        if (mi == RT_NONE)
            return nomem(p, kw);
        l.quad = rt_scene_add_quad(p->s, l.position, l.edge_u, l.edge_v, mi);
        if (l.quad == RT_NONE)
            return nomem(p, kw);
        break;
    }
    }
    if (rt_scene_add_light(p->s, &l) == RT_NONE)
        return nomem(p, kw);
    return RT_OK;
}

/* ------------------------------------------------------------ media */

/* True when the three tokens after the cursor's are numbers: `scale X Y Z`. */
static bool three_numbers_follow(const parser *p)
{
    float v;
    for (size_t i = 1; i <= 3; i++) {
        if (p->pos + i >= p->ntok)
            return false;
        const tok *t = &p->toks[p->pos + i];
        if (t->quoted || rt_parse_float(t->s, &v) == RT_NUMBER_BAD)
            return false;
    }
    return true;
}

/* One coefficient key of a medium line (sigma_a, sigma_s, g, scale), read
 * into m; *taken false (nothing read) for any other word. */
static rt_result get_medium_key(parser *p, rt_medium_def *m, float *scale, const tok *seen[4], bool *taken)
{
    static const char *const keys[4] = {"sigma_a", "sigma_s", "g", "scale"};
    const tok *t = peek(p);
    *taken = false;
    int k = 0;
    while (k < 4 && strcmp(t->s, keys[k]) != 0)
        k++;
    if (k == 4 || t->quoted)
        return RT_OK;
    if (seen[k])
        return perr(p, RT_ERR_INVALID, t, "medium key '%s' is given twice (first at column %d)", keys[k],
                    seen[k]->col);
    seen[k] = t;
    p->pos++;
    *taken = true;
    switch (k) {
    case 0: return get_color(p, "the medium's sigma_a", &m->sigma_a);
    case 1: return get_color(p, "the medium's sigma_s", &m->sigma_s);
    case 2: return get_float_in(p, "the medium's g (Henyey-Greenstein)", -RT_MEDIUM_G_MAX, RT_MEDIUM_G_MAX, &m->g);
    default: return get_float_in(p, "the medium's scale", 0.0f, FLT_MAX, scale);
    }
}

/* The inverse of an affine map (the cofactors over the determinant);
 * false when it is singular. */
static bool affine_inverse(const rt_mat4 *a, rt_mat4 *out)
{
    rt_mat4 c; /* inverse transpose times |det| */
    float det = rt_mat4_det3(a);
    if (!rt_mat4_normal_matrix(a, &c) || !(fabsf(det) > 1e-30f))
        return false;
    rt_mat4 r = rt_mat4_identity();
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r.m[i][j] = c.m[j][i] / fabsf(det);
    rt_vec3 t = rt_mat4_vector(&r, rt_v3(a->m[0][3], a->m[1][3], a->m[2][3]));
    r.m[0][3] = -t.x;
    r.m[1][3] = -t.y;
    r.m[2][3] = -t.z;
    *out = r;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(r.m[i][j]))
                return false;
    return true;
}

/* `medium NAME homogeneous sigma_a R G B sigma_s R G B [g G] [scale S]` or
 * `medium NAME nanovdb FILE [grid GRIDNAME] (the same keys) [translate X Y Z]
 * [rotate X Y Z] [scale S | scale X Y Z]`: a `scale` with one number before
 * any translate or rotate scales the coefficients, any other the grid. */
static rt_result st_medium(parser *p, const tok *kw)
{
    const tok *name = NULL, *file = NULL, *grid_name = NULL;
    rt_result r;
    char b[80];
    if ((r = get_word(p, "a medium name", &name)) != RT_OK ||
        (r = check_new_name(p, name, &p->media, "medium")) != RT_OK)
        return r;
    static const char *const kinds[] = {"homogeneous", "nanovdb"};
    int kind = 0;
    if ((r = get_choice(p, "the medium kind", kinds, 2, "homogeneous|nanovdb", &kind)) != RT_OK)
        return r;
    if (kind == 1 && (r = get_word(p, "a NanoVDB file (.nvdb)", &file)) != RT_OK)
        return r;
    if (kind == 1 && peek_is(p, "grid")) {
        p->pos++;
        if ((r = get_word(p, "the grid name", &grid_name)) != RT_OK)
            return r;
    }
    rt_medium_def m;
    memset(&m, 0, sizeof m);
    snprintf(m.name, sizeof m.name, "%s", name->s);
    m.kind = kind == 1 ? RT_MEDIUM_GRID : RT_MEDIUM_HOMOGENEOUS;
    m.index_to_world = m.world_to_index = rt_mat4_identity();
    const tok *seen[4] = {0};
    float scale = 1.0f;
    xform x = {0};
    bool placing = false; /* a translate or rotate was read: `scale` is the grid's */
    while (peek(p)) {
        bool taken = false;
        bool grid_scale = peek_is(p, "scale") && (placing || seen[3] || three_numbers_follow(p));
        if (!grid_scale && !placing && (r = get_medium_key(p, &m, &scale, seen, &taken)) != RT_OK)
            return r;
        if (taken)
            continue;
        if (kind == 1 && (r = get_xform_option(p, &x, "medium", &taken)) != RT_OK)
            return r;
        if (taken) {
            placing = true;
            continue;
        }
        const tok *t = peek(p);
        return perr(p, RT_ERR_PARSE, t, "expected a medium key (sigma_a, sigma_s, g, scale%s), got %s",
                    kind == 1 ? ", translate, rotate" : "", show(t, b, sizeof b));
    }
    if (!seen[0] || !seen[1])
        return perr(p, RT_ERR_PARSE, NULL, "medium %s needs 'sigma_a R G B' and 'sigma_s R G B'",
                    show(name, b, sizeof b));
    m.sigma_a = rt_scale(m.sigma_a, scale);
    m.sigma_s = rt_scale(m.sigma_s, scale);
    if (!rt_finite3(m.sigma_a) || !rt_finite3(m.sigma_s))
        return perr(p, RT_ERR_INVALID, seen[3], "the medium's coefficients times its scale overflow");
    if (kind == 1) {
        char path[MAX_PATH_LEN];
        if ((r = resolve_path(p, file, path, sizeof path)) != RT_OK)
            return r;
        rt_error inner = {0};
        rt_mat4 index_to_world;
        r = rt_nanovdb_load(path, grid_name ? grid_name->s : NULL, &m.grid, &index_to_world, &inner);
        if (r != RT_OK)
            return loader_err(p, file, r, &inner);
        rt_mat4 place = xform_matrix(&x);
        m.index_to_world = rt_mat4_mul(place, index_to_world);
        if (!affine_inverse(&m.index_to_world, &m.world_to_index)) {
            rt_density_grid_free(&m.grid);
            return perr(p, RT_ERR_INVALID, file, "the grid's placement in the world is singular");
        }
        rt_info("%s:%d: medium %s: %s, %d x %d x %d voxels", p->name, kw->line, m.name, path, m.grid.nx, m.grid.ny,
                m.grid.nz);
    }
    uint32_t id = rt_scene_add_medium(p->s, &m); /* (takes the grid, also on failure) */
    if (id == RT_NONE || !name_add(&p->media, name->s, id, name->line))
        return nomem(p, name);
    return RT_OK;
}

/* `scene_medium NAME`: the medium the camera sits in and that fills
 * everything no boundary encloses. */
static rt_result st_scene_medium(parser *p, const tok *kw)
{
    uint32_t m = RT_NONE;
    rt_result r;
    if ((r = get_medium(p, "scene_medium", &m)) != RT_OK || (r = expect_end(p, "scene_medium")) != RT_OK)
        return r;
    if (p->scene_medium_line)
        rt_warn("%s:%d:%d: 'scene_medium' was already set on line %d; the later value wins", p->name, kw->line,
                kw->col, p->scene_medium_line);
    p->scene_medium_line = kw->line;
    p->s->environment.medium = m;
    return RT_OK;
}

/* ------------------------------------------------------------ statements */

typedef rt_result (*handler)(parser *p, const tok *kw);

typedef struct keyword {
    const char *word;
    handler fn;
} keyword;

/* The statements that are not settings (those are in the settings table). */
static const keyword keywords[] = {
    {"camera", st_camera},
    {"texture", st_texture},
    {"material", st_material},
    {"sphere", st_sphere},
    {"quad", st_quad},
    {"triangle", st_triangle},
    {"mesh", st_mesh},
    {"model", st_model},
    {"light", st_light},
    {"object", st_object},
    {"end", st_end},
    {"instance", st_instance},
    {"medium", st_medium},
    {"scene_medium", st_scene_medium},
};

/* What an object block may hold: triangles, from these statements. */
static bool allowed_in_object(const char *word)
{
    return strcmp(word, "triangle") == 0 || strcmp(word, "mesh") == 0 || strcmp(word, "model") == 0 ||
           strcmp(word, "end") == 0 || strcmp(word, "material") == 0 || strcmp(word, "texture") == 0;
}

static rt_result run_statement(parser *p)
{
    const tok *kw = &p->toks[0];
    char b[80];
    p->pos = 1;
    if (!kw->quoted) {
        const rt_setting *def = rt_setting_find(kw->s);
        if (def)
            return st_setting(p, def, kw);
        for (size_t i = 0; i < sizeof keywords / sizeof *keywords; i++) {
            if (strcmp(kw->s, keywords[i].word) != 0)
                continue;
            if (p->in_object && !allowed_in_object(kw->s))
                return perr(p, RT_ERR_INVALID, kw,
                            "'%s' inside object '%s' (line %d): an object holds triangle, mesh and model lines "
                            "(and material and texture definitions)",
                            kw->s, p->object_name.s, p->object_name.line);
            return keywords[i].fn(p, kw);
        }
    }
    rt_near_miss n = rt_near_miss_of(kw->s);
    for (size_t i = 0; i < rt_settings_count; i++)
        rt_near_miss_consider(&n, rt_settings_table[i].name);
    for (size_t i = 0; i < sizeof keywords / sizeof *keywords; i++)
        rt_near_miss_consider(&n, keywords[i].word);
    if (n.best)
        return perr(p, RT_ERR_PARSE, kw, "unknown keyword %s (did you mean '%s'?)", show(kw, b, sizeof b), n.best);
    return perr(p, RT_ERR_PARSE, kw,
                "unknown keyword %s (expected a setting, camera, texture, material, sphere, quad, triangle, mesh, "
                "model, light, object, end, instance, medium or scene_medium)",
                show(kw, b, sizeof b));
}

static bool push_tok(parser *p, const char *s, int line, int col, int end_col, bool quoted)
{
    if (!rt_grow((void **)&p->toks, &p->tok_cap, p->ntok + 1, sizeof *p->toks))
        return false;
    tok *t = &p->toks[p->ntok++];
    t->s = s;
    t->line = line;
    t->col = col;
    t->end_col = end_col;
    t->quoted = quoted;
    return true;
}

static bool blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Lexes and runs every statement in buf[0, len) (buf[len] == '\0'). */
static rt_result run(parser *p, char *buf, size_t len)
{
    size_t i = 0;
    int line = 1;
    while (i < len) {
        p->ntok = 0;
        bool more = true;
        while (more) { /* one physical line per turn */
            more = false;
            size_t ls = i;
            size_t first_on_line = p->ntok;
            while (i < len && buf[i] != '\n') {
                unsigned char c = (unsigned char)buf[i];
                if (blank((char)c)) {
                    i++;
                    continue;
                }
                if (c == '#') {
                    while (i < len && buf[i] != '\n')
                        i++;
                    break;
                }
                int col = (int)(i - ls) + 1;
                if (c < 0x20 || c == 0x7f) {
                    tok at = {"", line, col, col, false};
                    return perr(p, RT_ERR_PARSE, &at, "unexpected control character 0x%02x", c);
                }
                if (c == '"') {
                    size_t start = ++i;
                    while (i < len && buf[i] != '"' && buf[i] != '\n') {
                        unsigned char q = (unsigned char)buf[i];
                        if ((q < 0x20 && q != '\t') || q == 0x7f) {
                            tok at = {"", line, (int)(i - ls) + 1, 0, false};
                            return perr(p, RT_ERR_PARSE, &at, "unexpected control character 0x%02x", q);
                        }
                        i++;
                    }
                    if (i >= len || buf[i] != '"') {
                        tok at = {"", line, col, col, false};
                        return perr(p, RT_ERR_PARSE, &at, "unterminated quoted string");
                    }
                    buf[i++] = '\0';
                    if (i < len && !blank(buf[i]) && buf[i] != '\n' && buf[i] != '#') {
                        tok at = {"", line, (int)(i - ls) + 1, 0, false};
                        return perr(p, RT_ERR_PARSE, &at, "expected a blank after the closing quote");
                    }
                    if (!push_tok(p, buf + start, line, col, (int)(i - ls) + 1, true))
                        return perr(p, RT_ERR_NOMEM, NULL, "out of memory");
                    continue;
                }
                size_t start = i;
                while (i < len && !blank(buf[i]) && buf[i] != '\n' && buf[i] != '#') {
                    unsigned char q = (unsigned char)buf[i];
                    if (q < 0x20 || q == 0x7f) {
                        tok at = {"", line, (int)(i - ls) + 1, 0, false};
                        return perr(p, RT_ERR_PARSE, &at, "unexpected control character 0x%02x", q);
                    }
                    i++;
                }
                if (!push_tok(p, buf + start, line, col, (int)(i - ls) + 1, false))
                    return perr(p, RT_ERR_NOMEM, NULL, "out of memory");
                /* terminate in place, keeping a '#' or '\n' terminator visible */
                if (i < len && blank(buf[i]))
                    buf[i++] = '\0';
                else if (i < len) {
                    /* the terminator is '#' or '\n': shift nothing, but the
                     * token needs its NUL; store it by copying the byte */
                    char term = buf[i];
                    buf[i] = '\0';
                    if (term == '#') {
                        while (i + 1 < len && buf[i + 1] != '\n')
                            i++;
                        i++; /* now at '\n' or len */
                    } else {
                        /* term == '\n': leave i on the (now NUL) newline */
                        break;
                    }
                }
            }
            /* i is at the newline (possibly overwritten with NUL) or at len */
            if (p->ntok > first_on_line) {
                tok *last = &p->toks[p->ntok - 1];
                size_t n = strlen(last->s);
                if (!last->quoted && n > 0 && last->s[n - 1] == '\\') {
                    ((char *)last->s)[n - 1] = '\0';
                    last->end_col--;
                    if (n == 1)
                        p->ntok--;
                    more = true;
                }
            }
            if (i < len) { /* step over the newline */
                i++;
                if (line == INT_MAX)
                    return perr(p, RT_ERR_LIMIT, NULL, "too many lines");
                line++;
            }
            if (i >= len)
                more = false;
        }
        if (p->ntok > 0) {
            rt_result r = run_statement(p);
            if (r != RT_OK)
                return r;
        }
    }
    return RT_OK;
}

/* After the last statement: things that depend on the whole file. */
static rt_result finish(parser *p)
{
    if (p->in_object)
        return perr(p, RT_ERR_PARSE, &p->object_name, "object '%s' has no 'end' line", p->object_name.s);
    if (p->camera_gltf) {
        if (p->camera_gltf_index >= (long long)p->s->camera_count)
            return perr(p, RT_ERR_INVALID, &p->camera_gltf_tok,
                        "camera gltf %lld: the loaded models have %zu camera%s", p->camera_gltf_index,
                        p->s->camera_count, p->s->camera_count == 1 ? "" : "s");
        p->s->camera = p->s->cameras[p->camera_gltf_index];
        p->s->camera_set = true;
    }
    return RT_OK;
}

rt_result rt_scene_parse_string(rt_scene *s, rt_settings *settings, const char *text, size_t len, const char *name,
                                const char *dir, rt_error *err)
{
    return rt_scene_parse_string_with(s, settings, text, len, name, dir, NULL, err);
}

rt_result rt_scene_parse_string_with(rt_scene *s, rt_settings *settings, const char *text, size_t len,
                                     const char *name, const char *dir, const rt_scene_parse_options *options,
                                     rt_error *err)
{
    if (!name)
        name = "<scene>";
    if (!s || (!text && len > 0))
        return rt_fail(err, RT_ERR_INVALID, "%s: no scene or text given", name);
    if (len > MAX_SCENE_BYTES)
        return rt_fail(err, RT_ERR_LIMIT, "%s: scene text is %zu bytes, over the limit of %zu", name, len,
                       MAX_SCENE_BYTES);
    /* relative paths in the text resolve against dir, by default the directory of name */
    char name_dir[MAX_PATH_LEN];
    if (!dir) {
        if (!rt_path_dirname(name, name_dir, sizeof name_dir))
            return rt_fail(err, RT_ERR_LIMIT, "%s: path is too long", name);
        dir = name_dir;
    }
    char *buf = malloc(len + 1);
    if (!buf)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", name);
    if (len)
        memcpy(buf, text, len);
    buf[len] = '\0';
    parser p;
    memset(&p, 0, sizeof p);
    p.s = s;
    p.settings = settings;
    p.name = name;
    p.dir = dir;
    p.err = err;
    p.default_material = RT_NONE;
    if (options)
        p.pose = *options;
    /* a UTF-8 byte order mark is not part of the first statement */
    size_t skip = len >= 3 && memcmp(buf, "\xef\xbb\xbf", 3) == 0 ? 3 : 0;
    rt_scene_mark mark = rt_scene_mark_of(s); /* a failed parse leaves the scene and settings as they were */
    rt_settings settings_before;
    if (settings)
        settings_before = *settings;
    rt_result r = run(&p, buf + skip, len - skip);
    p.ntok = 0;
    if (r == RT_OK)
        r = finish(&p);
    if (r != RT_OK) {
        rt_scene_rollback(s, &mark);
        if (settings)
            *settings = settings_before;
    }
    free(p.toks);
    free(p.missing_tex);
    name_table_free(&p.materials);
    name_table_free(&p.textures);
    name_table_free(&p.objects);
    name_table_free(&p.media);
    for (size_t i = 0; i < p.model_count; i++) {
        free(p.models[i].path);
        free((char *)p.models[i].opt.animation_name);
    }
    free(p.models);
    free(buf);
    return r;
}

rt_result rt_scene_parse_file(rt_scene *s, rt_settings *settings, const char *path, rt_error *err)
{
    if (!path)
        return rt_fail(err, RT_ERR_INVALID, "no scene file given");
    char *text;
    size_t len;
    rt_result r = rt_read_file(path, MAX_SCENE_BYTES, &text, &len, err);
    if (r != RT_OK)
        return r;
    r = rt_scene_parse_string(s, settings, text, len, path, NULL, err);
    free(text);
    return r;
}

/* ------------------------------------------------------------ default scene */

/* The same scene as scenes/cornell.txt, minus its `output` line (the driver
 * writes out.png); tests check that the two agree. */
const char rt_default_scene_text[] =
    "# The Cornell box with a sphere: rt's default scene (./rt with no scene file\n"
    "# renders the same text, built into src/scene_parse.c as rt_default_scene_text).\n"
    "#\n"
    "# A 2 x 2 x 2 box: x in [-1, 1] (red wall left, green wall right), y in [0, 2]\n"
    "# (floor to ceiling), z in [-1, 1] (back wall at -1, open towards the camera).\n"
    "# Reflectances are the measured Cornell ones; one area light hangs just under\n"
    "# the ceiling. Every quad faces into the box (cross(U, V) points inwards).\n"
    "\n"
    "resolution 512 512\n"
    "samples 16\n"
    "integrator direct\n"
    "shadow_samples 16\n"
    "\n"
    "camera position 0 1 3.94 look_at 0 1 0 up 0 1 0 fov 39.3\n"
    "\n"
    "material white  color 0.73 0.73 0.73\n"
    "material red    color 0.65 0.05 0.05\n"
    "material green  color 0.12 0.45 0.15\n"
    "\n"
    "#    corner          edge u         edge v\n"
    "quad -1 0 -1         0 0 2          2 0 0          white   # floor\n"
    "quad -1 2 -1         2 0 0          0 0 2          white   # ceiling\n"
    "quad -1 0 -1         2 0 0          0 2 0          white   # back wall\n"
    "quad -1 0 -1         0 2 0          0 0 2          red     # left wall\n"
    "quad  1 0 -1         0 0 2          0 2 0          green   # right wall\n"
    "\n"
    "# A tall box turned 18 degrees, at the back on the left (no bottom face).\n"
    "quad -0.7054 1.2 -0.5062   0.1792 0 0.5516   0.5516 0 -0.1792   white   # top\n"
    "quad -0.5262 0 0.04542     0.5516 0 -0.1792  0 1.2 0            white   # front\n"
    "quad -0.7054 0 -0.5062     0 1.2 0           0.5516 0 -0.1792   white   # back\n"
    "quad -0.1538 0 -0.6854     0 1.2 0           0.1792 0 0.5516    white   # right\n"
    "quad -0.7054 0 -0.5062     0.1792 0 0.5516   0 1.2 0            white   # left\n"
    "\n"
    "# A sphere at the front on the right.\n"
    "sphere 0.4 0.35 0.3 0.35 white\n"
    "\n"
    "# A 0.5 x 0.5 light, facing down (cross(U, V) = -y), warm white.\n"
    "light area -0.25 1.98 -0.25   0.5 0 0   0 0 0.5   1 0.9 0.75 \\\n"
    "           30\n";
