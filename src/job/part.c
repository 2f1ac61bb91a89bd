/* part.c - a part's image and JSON sidecar out and in (rt/job/part.h,
 * docs/farm.md). The image holds the exact float sums and counts the render
 * kept (not their ratio): the fold of the first sample blocks and the sums
 * of the blocks kept apart (rt/render/sample_block.h), so a merge can fold
 * and resolve pixels with the very operations of a single render. Integrity: the sidecar carries FNV-1a 64
 * hashes (Fowler, Noll, Vo; the parameters of the IETF draft
 * draft-eastlake-fnv) of the image files, of the scene's bytes and of the
 * settings text; reading checks the ones it can. JSON (RFC 8259) through
 * the jsmn walker of rt/io/json.h. Also what parts are compared by (two
 * parts are of one render when their identities match) and their AOV
 * layers to and from the renderer's AOV sums. */
#include "rt/job/part.h"

#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/io/exr.h"
#include "rt/io/image_read.h"
#include "rt/io/json.h"
#include "rt/job/options.h"
#include "rt/render/aov.h"

#define SIDECAR_MAX_BYTES (1u << 20)

uint64_t rt_fnv1a64(const void *data, size_t size, uint64_t h)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

bool rt_part_path_ok(const char *path) { return rt_path_has_ext(path, ".exr") || rt_path_has_ext(path, ".pfm"); }

bool rt_part_sidecar_path(const char *path, char *out, size_t size)
{
    int n = snprintf(out, size, "%s.json", path);
    return n > 0 && (size_t)n < size;
}

/* The counts file of a PFM part: NAME.count.pfm. */
static bool count_path(const char *path, char *out, size_t size)
{
    return rt_path_tagged(path, "count", NULL, out, size);
}

/* Block j's name: the EXR layer "block.J", and a PFM part's file NAME.block.J.pfm. */
static void block_name(int j, char *out, size_t size) { snprintf(out, size, "block.%d", j); }

static bool block_path(const char *path, int j, char *out, size_t size)
{
    char tag[32];
    block_name(j, tag, sizeof tag);
    return rt_path_tagged(path, tag, NULL, out, size);
}

bool rt_part_blocks_ok(int s_begin, int s_end, int first, int count)
{
    int last = (s_end - 1) / RT_SAMPLE_BLOCK;
    if (count < 1 || count > RT_PART_MAX_BLOCKS || first < 0 || first + count - 1 != last)
        return false;
    return count == 1 || (long long)first * RT_SAMPLE_BLOCK == s_begin;
}

/* The hash of a file written in batch b, read back before it is renamed into place. */
static rt_result hash_file(const rt_write_batch *b, const char *path, uint64_t *h, rt_error *err)
{
    char *bytes;
    size_t size;
    rt_result r = rt_write_batch_read(b, path, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    *h = rt_fnv1a64(bytes, size, RT_FNV1A64_INIT);
    free(bytes);
    return RT_OK;
}

/* ------------------------------------------------------------ writing */

typedef struct text {
    char *buf;
    size_t len, cap;
    bool failed;
} text;

static void put(text *t, const char *fmt, ...) RT_PRINTF(2, 3);
static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    for (;;) {
        va_start(ap, fmt);
        int n = vsnprintf(t->buf ? t->buf + t->len : NULL, t->buf ? t->cap - t->len : 0, fmt, ap);
        va_end(ap);
        if (n < 0) {
            t->failed = true;
            return;
        }
        if (t->buf && t->len + (size_t)n < t->cap) {
            t->len += (size_t)n;
            return;
        }
        size_t cap = (t->cap ? t->cap * 2 : 4096) + (size_t)n;
        char *nb = realloc(t->buf, cap);
        if (!nb) {
            t->failed = true;
            return;
        }
        t->buf = nb;
        t->cap = cap;
    }
}

/* A JSON string: quotes, backslashes and control bytes escaped. */
static void put_string(text *t, const char *s)
{
    put(t, "\"");
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            put(t, "\\%c", c);
        else if (c == '\n')
            put(t, "\\n");
        else if (c < 0x20)
            put(t, "\\u%04x", c);
        else
            put(t, "%c", c);
    }
    put(t, "\"");
}

static rt_result write_files(const char *path, const rt_part_info *info, const float *sum,
                             const float *const *blocks, const uint32_t *good, const float *const *layers,
                             rt_write_batch *batch, rt_error *err);

rt_result rt_part_check_paths(const char *path, rt_error *err)
{
    char side[4200], cpath[4200];
    if (!rt_part_path_ok(path))
        return rt_fail(err, RT_ERR_INVALID, "%s: a part is written as .exr or .pfm", path);
    if (!rt_part_sidecar_path(path, side, sizeof side) || !count_path(path, cpath, sizeof cpath))
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    rt_result r = rt_output_check(path, err);
    if (r == RT_OK)
        r = rt_output_check_file(side, err);
    if (r == RT_OK && rt_path_has_ext(path, ".pfm"))
        r = rt_output_check_file(cpath, err);
    return r;
}

rt_result rt_part_write(const char *path, const rt_part_info *info, const float *sum, const float *const *blocks,
                        const uint32_t *good, const float *const *layers, rt_write_batch *batch, rt_error *err)
{
    if (batch)
        return write_files(path, info, sum, blocks, good, layers, batch, err);
    rt_write_batch own;
    rt_write_batch_init(&own, NULL);
    rt_result r = write_files(path, info, sum, blocks, good, layers, &own, err);
    if (r != RT_OK) {
        rt_write_batch_discard(&own);
        return r;
    }
    return rt_write_batch_commit(&own, err);
}

/* Every file of the part into the batch: the image(s), then the sidecar. */
static rt_result write_files(const char *path, const rt_part_info *info, const float *sum,
                             const float *const *blocks, const uint32_t *good, const float *const *layers,
                             rt_write_batch *batch, rt_error *err)
{
    char side[4200], cpath[4200], bpath[4200];
    if (!rt_part_path_ok(path))
        return rt_fail(err, RT_ERR_INVALID, "%s: a part is written as .exr or .pfm", path);
    if (!rt_part_sidecar_path(path, side, sizeof side) || !count_path(path, cpath, sizeof cpath))
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    if (info->layer_count < 0 || info->layer_count > RT_PART_MAX_LAYERS ||
        (info->layer_count > 0 && !rt_path_has_ext(path, ".exr")))
        return rt_fail(err, RT_ERR_INVALID, "%s: a part with AOVs is written as .exr", path);
    int bfirst = info->block_first, bcount = info->block_count;
    if (!rt_part_blocks_ok(info->s_begin, info->s_end, bfirst, bcount))
        return rt_fail(err, RT_ERR_INVALID, "%s: samples %d:%d cannot keep blocks %d..%d apart", path, info->s_begin,
                       info->s_end, bfirst, bfirst + bcount - 1);
    if (!block_path(path, bfirst + bcount - 1, bpath, sizeof bpath))
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    int w = info->x1 - info->x0, h = info->y1 - info->y0;
    size_t n = (size_t)w * (size_t)h;
    float *counts = rt_alloc(n, sizeof(float));
    if (!counts)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the counts", path);
    for (size_t i = 0; i < n; i++)
        counts[i] = (float)good[i];
    rt_framebuffer fb = {w, h, (float *)sum};
    bool exr = rt_path_has_ext(path, ".exr");
    rt_result r = RT_OK;
    uint64_t image_hash = 0, count_hash = 0, block_hash[RT_PART_MAX_BLOCKS] = {0};
    char bname[RT_PART_MAX_BLOCKS][24];
    for (int k = 0; k < bcount; k++)
        block_name(bfirst + k, bname[k], sizeof bname[k]);
    if (exr) {
        rt_image_layer layer[1 + RT_PART_MAX_BLOCKS + RT_PART_MAX_LAYERS] = {{"count", 1, counts}};
        int nl = 1;
        for (int k = 0; k < bcount; k++)
            layer[nl++] = (rt_image_layer){bname[k], 3, blocks[k]};
        for (int k = 0; k < info->layer_count; k++)
            layer[nl++] = (rt_image_layer){info->layer_name[k], info->layer_channels[k], layers[k]};
        rt_image_options opt = {.layers = layer, .layer_count = nl};
        r = rt_framebuffer_write_batched(&fb, path, &opt, batch, err);
    } else {
        float *grey = rt_alloc(n, 3 * sizeof(float));
        if (!grey) {
            free(counts);
            return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the counts", path);
        }
        for (size_t i = 0; i < n; i++)
            grey[3 * i] = grey[3 * i + 1] = grey[3 * i + 2] = counts[i];
        rt_framebuffer cfb = {w, h, grey};
        rt_image_options opt = {0};
        r = rt_framebuffer_write_batched(&cfb, cpath, &opt, batch, err);
        free(grey);
        if (r == RT_OK)
            r = hash_file(batch, cpath, &count_hash, err);
        for (int k = 0; k < bcount && r == RT_OK; k++) {
            rt_framebuffer bfb = {w, h, (float *)blocks[k]};
            block_path(path, bfirst + k, bpath, sizeof bpath);
            r = rt_framebuffer_write_batched(&bfb, bpath, &opt, batch, err);
            if (r == RT_OK)
                r = hash_file(batch, bpath, &block_hash[k], err);
        }
        if (r == RT_OK)
            r = rt_framebuffer_write_batched(&fb, path, &opt, batch, err);
    }
    free(counts);
    if (r == RT_OK)
        r = hash_file(batch, path, &image_hash, err);
    if (r != RT_OK)
        return r;

    text t = {0};
    put(&t, "{\n  \"rt_part\": %d,\n  \"rt_version\": ", RT_PART_FORMAT);
    put_string(&t, info->version);
    put(&t, ",\n  \"image\": ");
    put_string(&t, rt_path_basename(path));
    put(&t, ",\n  \"image_fnv1a64\": \"%016" PRIx64 "\",\n", image_hash);
    if (!exr) {
        put(&t, "  \"count_image\": ");
        put_string(&t, rt_path_basename(cpath));
        put(&t, ",\n  \"count_fnv1a64\": \"%016" PRIx64 "\",\n  \"block_fnv1a64\": [", count_hash);
        for (int k = 0; k < bcount; k++)
            put(&t, "%s\"%016" PRIx64 "\"", k ? ", " : "", block_hash[k]);
        put(&t, "],\n");
    }
    put(&t, "  \"scene\": ");
    put_string(&t, info->scene);
    put(&t, ",\n  \"scene_fnv1a64\": \"%016" PRIx64 "\",\n", info->scene_hash);
    put(&t, "  \"settings_fnv1a64\": \"%016" PRIx64 "\",\n  \"settings\": ",
        rt_fnv1a64(info->settings, strlen(info->settings), RT_FNV1A64_INIT));
    put_string(&t, info->settings);
    put(&t, ",\n  \"width\": %d,\n  \"height\": %d,\n  \"region\": [%d, %d, %d, %d],\n", info->width, info->height,
        info->x0, info->y0, info->x1, info->y1);
    put(&t, "  \"spp\": %d,\n  \"samples\": [%d, %d],\n  \"blocks\": [%d, %d],\n  \"seed\": %" PRIu32 ",\n",
        info->spp, info->s_begin, info->s_end, bfirst, bcount, info->seed);
    put(&t, "  \"exposure\": \"%a\",\n  \"layers\": [", (double)info->exposure);
    for (int k = 0; k < info->layer_count; k++) {
        put(&t, "%s[", k ? ", " : "");
        put_string(&t, info->layer_name[k]);
        put(&t, ", %d]", info->layer_channels[k]);
    }
    put(&t, "]\n}\n");
    if (t.failed) {
        free(t.buf);
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the sidecar", side);
    }
    r = rt_file_write_batched(side, t.buf, t.len, batch, err);
    free(t.buf);
    return r;
}

/* ------------------------------------------------------------ reading */

static rt_result bad(rt_error *err, const char *side, const char *what)
{
    return rt_fail(err, RT_ERR_INVALID, "%s: %s", side, what);
}

static bool get_int(const rt_json *j, int obj, const char *key, long long lo, long long hi, long long *out)
{
    int i = rt_json_get(j, obj, key);
    double v;
    if (i < 0 || !rt_json_number(j, i, &v) || v != floor(v) || v < (double)lo || v > (double)hi)
        return false;
    *out = (long long)v;
    return true;
}

static bool get_string(const rt_json *j, int obj, const char *key, char *out, size_t cap)
{
    int i = rt_json_get(j, obj, key);
    return i >= 0 && rt_json_string(j, i, out, cap) >= 0;
}

/* Exactly 16 hex digits (strtoull alone takes blanks, a sign and "0x"). */
static bool hex16(const char *s, uint64_t *out)
{
    uint64_t v = 0;
    for (int i = 0; i < 16; i++) {
        char c = s[i];
        int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (d < 0)
            return false;
        v = v << 4 | (uint64_t)d;
    }
    if (s[16] != 0)
        return false;
    *out = v;
    return true;
}

static bool get_hash(const rt_json *j, int obj, const char *key, uint64_t *out)
{
    char s[32];
    return get_string(j, obj, key, s, sizeof s) && hex16(s, out);
}

/* An array of n integers in [lo, hi]. */
static bool get_ints(const rt_json *j, int obj, const char *key, int n, long long lo, long long hi, int *out)
{
    int i = rt_json_get(j, obj, key);
    if (i < 0 || j->tok[i].type != RT_JSON_ARRAY || j->tok[i].size != n)
        return false;
    for (int k = 0; k < n; k++) {
        double v;
        if (!rt_json_number(j, i + 1 + k, &v) || v != floor(v) || v < (double)lo || v > (double)hi)
            return false;
        out[k] = (int)v;
    }
    return true;
}

/* A finite float written with %a (exact). */
static bool float_text(const char *s, float *out)
{
    char *end = NULL;
    *out = strtof(s, &end);
    return end != s && *end == 0 && isfinite(*out);
}

/* The AOVs a part carries as layers (what rt_part_job writes): the sums
 * of albedo, normal, depth and position; not variance or spp. */
static bool layer_kind_ok(rt_aov_kind k)
{
    return k == RT_AOV_ALBEDO || k == RT_AOV_NORMAL || k == RT_AOV_DEPTH || k == RT_AOV_POSITION;
}

/* The sidecar's fields into info; the image hashes into the rest. */
static rt_result read_sidecar(const char *side, rt_part_info *info, uint64_t *image_hash, uint64_t *count_hash,
                              uint64_t *block_hash, bool *has_count, rt_error *err)
{
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(side, SIDECAR_MAX_BYTES, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    rt_json j;
    r = rt_json_parse(&j, bytes, size, side, 0, err);
    if (r != RT_OK) {
        free(bytes);
        return r;
    }
    /* a key given twice: which one counts is anybody's guess (RFC 8259 4), so neither */
    for (int a = 1, ka = 0; r == RT_OK && ka < j.tok[0].size && a < j.count; ka++, a = rt_json_skip(&j, a + 1))
        for (int b = 1, kb = 0; kb < ka && b < a; kb++, b = rt_json_skip(&j, b + 1))
            if (j.tok[a].end - j.tok[a].start == j.tok[b].end - j.tok[b].start &&
                memcmp(bytes + j.tok[a].start, bytes + j.tok[b].start, (size_t)(j.tok[a].end - j.tok[a].start)) == 0) {
                r = rt_fail(err, RT_ERR_INVALID, "%s: byte %d: key \"%.*s\" given twice", side, j.tok[a].start - 1,
                            j.tok[a].end - j.tok[a].start, bytes + j.tok[a].start);
                break;
            }
    if (r != RT_OK) {
        rt_json_free(&j);
        free(bytes);
        return r;
    }
    memset(info, 0, sizeof *info);
    long long fmt, w, h, spp, seed;
    int reg[4], smp[2], blk[2] = {0, 0};
    char expo[64];
    uint64_t settings_hash = 0;
    *has_count = rt_json_get(&j, 0, "count_fnv1a64") >= 0;
    if (!get_int(&j, 0, "rt_part", 1, 1000, &fmt))
        r = bad(err, side, "not a part sidecar (no \"rt_part\" format number)");
    else if (fmt != RT_PART_FORMAT)
        r = rt_fail(err, RT_ERR_INVALID,
                    "%s: part format %lld, this rt reads format %d only%s", side, fmt, RT_PART_FORMAT,
                    fmt < RT_PART_FORMAT ? " (an older rt's part, before sums in sample blocks: render it again)" : "");
    else if (!get_string(&j, 0, "rt_version", info->version, sizeof info->version))
        r = bad(err, side, "\"rt_version\" missing or not a string");
    else if (!get_hash(&j, 0, "image_fnv1a64", image_hash))
        r = bad(err, side, "\"image_fnv1a64\" missing or not 16 hex digits");
    else if (*has_count && !get_hash(&j, 0, "count_fnv1a64", count_hash))
        r = bad(err, side, "\"count_fnv1a64\" not 16 hex digits");
    else if (!get_string(&j, 0, "scene", info->scene, sizeof info->scene))
        r = bad(err, side, "\"scene\" missing or not a string");
    else if (!get_hash(&j, 0, "scene_fnv1a64", &info->scene_hash))
        r = bad(err, side, "\"scene_fnv1a64\" missing or not 16 hex digits");
    else if (!get_hash(&j, 0, "settings_fnv1a64", &settings_hash))
        r = bad(err, side, "\"settings_fnv1a64\" missing or not 16 hex digits");
    else if (!get_string(&j, 0, "settings", info->settings, sizeof info->settings))
        r = bad(err, side, "\"settings\" missing, not a string or too long");
    else if (rt_fnv1a64(info->settings, strlen(info->settings), RT_FNV1A64_INIT) != settings_hash)
        r = bad(err, side, "\"settings\" do not match \"settings_fnv1a64\" (the sidecar was edited or damaged)");
    else if (!get_int(&j, 0, "width", 1, 32768, &w) || !get_int(&j, 0, "height", 1, 32768, &h))
        r = bad(err, side, "\"width\" and \"height\" must be integers from 1 to 32768");
    else if (!get_ints(&j, 0, "region", 4, 0, 32768, reg) || reg[0] >= reg[2] || reg[1] >= reg[3] || reg[2] > w ||
             reg[3] > h)
        r = bad(err, side, "\"region\" must be [x0, y0, x1, y1] with x0 < x1 <= width and y0 < y1 <= height");
    else if (!get_int(&j, 0, "spp", 1, 1 << 20, &spp))
        r = bad(err, side, "\"spp\" must be an integer from 1 to 1048576");
    else if (!get_ints(&j, 0, "samples", 2, 0, 1 << 20, smp) || smp[0] >= smp[1] || smp[1] > spp)
        r = bad(err, side, "\"samples\" must be [begin, end] with begin < end <= spp");
    else if (!get_ints(&j, 0, "blocks", 2, 0, 1 << 20, blk))
        r = bad(err, side, "\"blocks\" must be [first, count]");
    else if (!rt_part_blocks_ok(smp[0], smp[1], blk[0], blk[1]))
        r = bad(err, side, "\"blocks\" [first, count] must end with the block of the last sample and be that one "
                           "block, or every block from the first sample on, at most 64");
    else if (!get_int(&j, 0, "seed", 0, UINT32_MAX, &seed))
        r = bad(err, side, "\"seed\" must be an integer from 0 to 4294967295");
    else if (!get_string(&j, 0, "exposure", expo, sizeof expo) || !float_text(expo, &info->exposure))
        r = bad(err, side, "\"exposure\" missing or not a number");
    int bi = r == RT_OK && *has_count ? rt_json_get(&j, 0, "block_fnv1a64") : -1;
    if (r == RT_OK && *has_count) {
        if (bi < 0 || j.tok[bi].type != RT_JSON_ARRAY || j.tok[bi].size != blk[1])
            r = bad(err, side, "\"block_fnv1a64\" must list a hash for each block");
        for (int k = 0, e = bi + 1; r == RT_OK && k < blk[1]; k++, e = rt_json_skip(&j, e)) {
            char hex[32];
            if (rt_json_string(&j, e, hex, sizeof hex) != 16 || !hex16(hex, &block_hash[k]))
                r = bad(err, side, "\"block_fnv1a64\" entries must be 16 hex digits");
        }
    }
    int li = r == RT_OK ? rt_json_get(&j, 0, "layers") : -1;
    if (r == RT_OK && li >= 0) {
        if (j.tok[li].type != RT_JSON_ARRAY || j.tok[li].size > RT_PART_MAX_LAYERS)
            r = bad(err, side, "\"layers\" must be an array of at most 4 [name, channels] pairs");
        int e = li + 1, last = -1;
        for (int k = 0; r == RT_OK && k < j.tok[li].size; k++, e = rt_json_skip(&j, e)) {
            double ch = 0;
            rt_aov_kind kind = RT_AOV_COUNT;
            if (j.tok[e].type != RT_JSON_ARRAY || j.tok[e].size != 2 ||
                rt_json_string(&j, e + 1, info->layer_name[k], sizeof info->layer_name[k]) <= 0 ||
                !rt_aov_by_name(info->layer_name[k], strlen(info->layer_name[k]), &kind) || !layer_kind_ok(kind) ||
                (int)kind <= last || !rt_json_number(&j, e + 2, &ch) || ch != (kind == RT_AOV_DEPTH ? 1 : 3))
                r = bad(err, side, "\"layers\" entries must be [\"albedo\", 3], [\"normal\", 3], [\"depth\", 1] or "
                                   "[\"position\", 3], each at most once and in that order");
            last = (int)kind;
            info->layer_channels[k] = (int)ch;
            info->layer_count = k + 1;
        }
    }
    if (r == RT_OK) {
        info->width = (int)w;
        info->height = (int)h;
        info->x0 = reg[0];
        info->y0 = reg[1];
        info->x1 = reg[2];
        info->y1 = reg[3];
        info->spp = (int)spp;
        info->s_begin = smp[0];
        info->s_end = smp[1];
        info->block_first = blk[0];
        info->block_count = blk[1];
        info->seed = (uint32_t)seed;
    }
    rt_json_free(&j);
    free(bytes);
    return r;
}

/* The image at path, checked against its hash: an EXR's `count` named
 * channels, else a PFM's three. An EXR's header may not claim more than
 * the sidecar's region (rw x rh) before pixels are allocated; a PFM's
 * size is checked against its bytes by rt_pfm_read. */
static rt_result read_image(const char *path, uint64_t want, bool exr, const char *const *names, int count, int rw,
                            int rh, float **px, int *w, int *h, rt_error *err)
{
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(path, 0, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    if (rt_fnv1a64(bytes, size, RT_FNV1A64_INIT) != want) {
        free(bytes);
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: the image's bytes do not match the hash in its sidecar (truncated, damaged, or from "
                       "another render)",
                       path);
    }
    if (exr) {
        r = rt_exr_decode_channels_sized(bytes, size, path, rw, rh, names, count, px, err);
        *w = rw;
        *h = rh;
        free(bytes);
        return r;
    }
    free(bytes);
    rt_framebuffer fb;
    if ((r = rt_pfm_read(path, &fb, err)) != RT_OK)
        return r;
    *px = fb.rgb;
    *w = fb.width;
    *h = fb.height;
    return RT_OK;
}

rt_result rt_part_read(const char *path, rt_part *part, rt_error *err)
{
    memset(part, 0, sizeof *part);
    char image[4096], side[4200], cpath[4200];
    size_t len = strlen(path);
    if (len >= sizeof image)
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    memcpy(image, path, len + 1);
    if (rt_path_has_ext(image, ".json"))
        image[len - 5] = 0;
    snprintf(part->path, sizeof part->path, "%s", image);
    if (!rt_part_path_ok(image))
        return rt_fail(err, RT_ERR_INVALID, "%s: not a part (a part is a .exr or .pfm image with a .json sidecar)",
                       path);
    if (!rt_part_sidecar_path(image, side, sizeof side) || !count_path(image, cpath, sizeof cpath))
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    uint64_t image_hash = 0, count_hash = 0, block_hash[RT_PART_MAX_BLOCKS] = {0};
    bool has_count = false;
    rt_part_info *info = &part->info;
    rt_result r = read_sidecar(side, info, &image_hash, &count_hash, block_hash, &has_count, err);
    if (r != RT_OK)
        return r;
    bool exr = rt_path_has_ext(image, ".exr");
    if (!exr && !has_count)
        return rt_fail(err, RT_ERR_INVALID, "%s: a .pfm part's sidecar must name \"count_fnv1a64\"", side);
    if (!exr && info->layer_count)
        return rt_fail(err, RT_ERR_INVALID, "%s: a .pfm part cannot have layers", side);
    int rw = info->x1 - info->x0, rh = info->y1 - info->y0, w = 0, h = 0, nb = info->block_count;
    size_t n = (size_t)rw * (size_t)rh;
    float *px = NULL, *cpx = NULL, *bpx[RT_PART_MAX_BLOCKS] = {NULL};
    /* EXR channels: R, G, B, count.Y, then each block's, then each layer's */
    char names_buf[4 + 3 * (RT_PART_MAX_BLOCKS + RT_PART_MAX_LAYERS)][40];
    const char *names[4 + 3 * (RT_PART_MAX_BLOCKS + RT_PART_MAX_LAYERS)] = {"R", "G", "B", "count.Y"};
    int nc = 4;
    for (int k = 0; k < nb; k++)
        for (int c = 0; c < 3; c++, nc++) {
            snprintf(names_buf[nc], sizeof names_buf[nc], "block.%d.%c", info->block_first + k, "RGB"[c]);
            names[nc] = names_buf[nc];
        }
    int layers_at = nc;
    for (int k = 0; k < info->layer_count; k++)
        for (int c = 0; c < info->layer_channels[k]; c++, nc++) {
            snprintf(names_buf[nc], sizeof names_buf[nc], "%s.%s", info->layer_name[k],
                     info->layer_channels[k] == 1 ? "Y" : c == 0 ? "R" : c == 1 ? "G" : "B");
            names[nc] = names_buf[nc];
        }
    r = read_image(image, image_hash, exr, names, nc, rw, rh, &px, &w, &h, err);
    if (r == RT_OK && (w != rw || h != rh))
        r = rt_fail(err, RT_ERR_INVALID, "%s: the image is %dx%d but its sidecar's region is %dx%d", image, w, h, rw,
                    rh);
    /* a .pfm part's counts and blocks beside it */
    for (int k = -1; r == RT_OK && !exr && k < nb; k++) {
        char bpath[4200];
        int cw = 0, ch = 0;
        const char *file = k < 0 ? cpath : bpath;
        if (k >= 0 && !block_path(image, info->block_first + k, bpath, sizeof bpath)) {
            r = rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
            break;
        }
        r = read_image(file, k < 0 ? count_hash : block_hash[k], false, NULL, 0, rw, rh, k < 0 ? &cpx : &bpx[k], &cw,
                       &ch, err);
        if (r == RT_OK && (cw != rw || ch != rh))
            r = rt_fail(err, RT_ERR_INVALID, "%s: the image is %dx%d but its sidecar's region is %dx%d", file, cw,
                        ch, rw, rh);
    }
    if (r == RT_OK) {
        part->sum = rt_alloc(n, 3 * sizeof(float));
        part->blocks = rt_alloc(n * (size_t)nb, 3 * sizeof(float));
        part->good = rt_alloc(n, sizeof(uint32_t));
        bool ok = part->sum && part->blocks && part->good;
        for (int k = 0; k < info->layer_count; k++) {
            part->layer[k] = rt_alloc(n, (size_t)info->layer_channels[k] * sizeof(float));
            ok = ok && part->layer[k];
        }
        if (!ok)
            r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for a %dx%d part", image, rw, rh);
    }
    float most = (float)(info->s_end - info->s_begin);
    for (size_t i = 0; i < n && r == RT_OK; i++) {
        const float *s = exr ? px + (size_t)nc * i : px + 3 * i;
        float c = exr ? s[3] : cpx[3 * i];
        float v[3 * (1 + RT_PART_MAX_BLOCKS)]; /* the fold, then each block */
        for (int k = 0; k <= nb; k++)
            for (int q = 0; q < 3; q++)
                v[3 * k + q] = k == 0 ? s[q] : exr ? s[4 + 3 * (k - 1) + q] : bpx[k - 1][3 * i + (size_t)q];
        bool sums_ok = true;
        for (int q = 0; q < 3 * (1 + nb); q++)
            sums_ok = sums_ok && v[q] >= 0.0f && isfinite(v[q]);
        if (!(c >= 0.0f && c <= most && c == floorf(c)) || !sums_ok) {
            r = rt_fail(err, RT_ERR_INVALID,
                        "%s: pixel (%zu, %zu) of the part holds a sum or count no render makes (sums are finite and "
                        ">= 0, counts whole numbers up to %d)",
                        image, i % (size_t)rw + (size_t)info->x0, i / (size_t)rw + (size_t)info->y0,
                        info->s_end - info->s_begin);
            break;
        }
        memcpy(part->sum + 3 * i, v, 3 * sizeof(float));
        for (int k = 0; k < nb; k++)
            memcpy(part->blocks + ((size_t)k * n + i) * 3, v + 3 * (k + 1), 3 * sizeof(float));
        part->good[i] = (uint32_t)c;
        for (int k = 0, at = layers_at; k < info->layer_count; at += info->layer_channels[k], k++)
            for (int q = 0; q < info->layer_channels[k]; q++) {
                float lv = s[at + q];
                if (!isfinite(lv)) {
                    r = rt_fail(err, RT_ERR_INVALID, "%s: layer %s of pixel (%zu, %zu) is not finite", image,
                                info->layer_name[k], i % (size_t)rw + (size_t)info->x0,
                                i / (size_t)rw + (size_t)info->y0);
                    break;
                }
                part->layer[k][(size_t)info->layer_channels[k] * i + (size_t)q] = lv;
            }
    }
    free(px);
    free(cpx);
    for (int k = 0; k < nb; k++)
        free(bpx[k]);
    if (r != RT_OK)
        rt_part_free(part);
    return r;
}

void rt_part_free(rt_part *part)
{
    free(part->sum);
    free(part->blocks);
    free(part->good);
    part->sum = NULL;
    part->blocks = NULL;
    part->good = NULL;
    for (int k = 0; k < RT_PART_MAX_LAYERS; k++) {
        free(part->layer[k]);
        part->layer[k] = NULL;
    }
}

/* ------------------------------------------------------------ identity and AOV layers */

/* The first line where two settings texts differ, into a and b. */
static void first_difference(const char *x, const char *y, char *a, char *b, size_t size)
{
    while (*x || *y) {
        size_t nx = strcspn(x, "\n"), ny = strcspn(y, "\n");
        if (nx != ny || memcmp(x, y, nx) != 0) {
            snprintf(a, size, "%.*s", (int)nx, x);
            snprintf(b, size, "%.*s", (int)ny, y);
            return;
        }
        x += nx + (x[nx] == '\n');
        y += ny + (y[ny] == '\n');
    }
    a[0] = b[0] = 0;
}

/* The first layer whose name or channel count differs (the whole layout a
 * merge reads: names alone let a 1-channel layer be read as 3), or -1. */
static int layout_difference(const rt_part_info *a, const rt_part_info *b)
{
    for (int k = 0; k < a->layer_count && k < RT_PART_MAX_LAYERS; k++)
        if (a->layer_channels[k] != b->layer_channels[k] ||
            strncmp(a->layer_name[k], b->layer_name[k], sizeof a->layer_name[k]) != 0)
            return k;
    return -1;
}

const char *rt_part_mismatch(const rt_part_info *a, const rt_part_info *b, char *buf, size_t size)
{
    int k;
    if (strcmp(a->version, b->version) != 0)
        snprintf(buf, size, "rendered by rt %s, not rt %s", a->version, b->version);
    else if (a->scene_hash != b->scene_hash)
        snprintf(buf, size, "another scene file (%s, FNV-1a %016llx; not %s, %016llx)", a->scene,
                 (unsigned long long)a->scene_hash, b->scene, (unsigned long long)b->scene_hash);
    else if (a->width != b->width || a->height != b->height)
        snprintf(buf, size, "image size %dx%d, not %dx%d", a->width, a->height, b->width, b->height);
    else if (a->spp != b->spp)
        snprintf(buf, size, "%d samples per pixel, not %d", a->spp, b->spp);
    else if (a->seed != b->seed)
        snprintf(buf, size, "seed %u, not %u", (unsigned)a->seed, (unsigned)b->seed);
    else if (a->layer_count != b->layer_count)
        snprintf(buf, size, "other AOVs (%d layer%s, not %d)", a->layer_count, a->layer_count == 1 ? "" : "s",
                 b->layer_count);
    else if ((k = layout_difference(a, b)) >= 0)
        snprintf(buf, size, "other AOVs (layer %d is %s of %d channel%s, not %s of %d)", k + 1, a->layer_name[k],
                 a->layer_channels[k], a->layer_channels[k] == 1 ? "" : "s", b->layer_name[k], b->layer_channels[k]);
    else if (strcmp(a->settings, b->settings) != 0) {
        char x[256], y[256];
        first_difference(a->settings, b->settings, x, y, sizeof x);
        snprintf(buf, size, "other settings: '%s', not '%s'", x, y);
    } else
        return NULL;
    return buf;
}

/* Component q of the AOV a layer holds (name: albedo, normal, position, depth). */
static float *aov_field(rt_aov_sample *s, const char *name, int q)
{
    rt_vec3 *v = strcmp(name, "albedo") == 0   ? &s->albedo
                 : strcmp(name, "normal") == 0 ? &s->normal
                 : strcmp(name, "position") == 0 ? &s->position
                                                 : NULL;
    if (!v)
        return &s->depth;
    return q == 0 ? &v->x : q == 1 ? &v->y : &v->z;
}

void rt_part_aov_to_layers(const rt_part_info *info, const rt_aov_sample *sums, float *const *layers, size_t n)
{
    for (int k = 0; k < info->layer_count; k++) {
        int c = info->layer_channels[k];
        for (size_t i = 0; i < n; i++) {
            rt_aov_sample s = sums[i];
            for (int q = 0; q < c; q++)
                layers[k][(size_t)c * i + (size_t)q] = *aov_field(&s, info->layer_name[k], q);
        }
    }
}

void rt_part_layers_to_aov(const rt_part_info *info, const float *const *layers, rt_aov_sample *sums, size_t n)
{
    for (int k = 0; k < info->layer_count; k++) {
        int c = info->layer_channels[k];
        for (size_t i = 0; i < n; i++)
            for (int q = 0; q < c; q++)
                *aov_field(&sums[i], info->layer_name[k], q) = layers[k][(size_t)c * i + (size_t)q];
    }
}
