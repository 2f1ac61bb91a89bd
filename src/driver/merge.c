/* merge.c - `rt merge PART... -o OUT [--exposure EV] [--tonemap NAME]
 * [--half]`: the parts of one render (docs/farm.md) into its image.
 *
 * Every part must be of the same render as the first (part_mismatch: rt
 * version, scene hash, size, samples, seed, settings). Parts with the same
 * region are sample ranges of it: sorted by their first sample they must
 * cover 0 .. spp exactly once, and their sums are folded in that order as
 * the render folds its sample blocks (rt/render/sample_block.h): 0 plus
 * each part's fold, then each block it keeps apart. That is a single
 * render's sum exactly when every range starts at a block edge (or 0) and
 * keeps its blocks apart; else equal to it up to float summation order
 * (docs/farm.md states the bound). The regions must tile the image
 * exactly once. A pixel is then resolved as in src/render/render.c, sum *
 * (1 / count), so region parts give a single render's bytes exactly, and
 * written through the same atomic writer with the same exposure (the
 * scene's, from the sidecars, times 2^--exposure) and tone curve. Any
 * problem names the part at fault; nothing is written then. */
#include "commands.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "output.h"
#include "part.h"
#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/number.h"
#include "rt/image/tonemap.h"
#include "rt/io/image_write.h"
#include "rt/io/part.h"

static const char usage[] =
    "usage: rt merge PART... -o OUT [--exposure EV] [--tonemap NAME] [--half]\n"
    "\n"
    "Merges the parts of one render (rt --part, --crop, --spp-range: PART.exr or PART.pfm with\n"
    "PART.json beside it) into its image OUT (.png, .pfm, .hdr or .exr). Regions must tile the\n"
    "image exactly once; the sample ranges of a region must cover all its samples exactly once.\n"
    "\n"
    "options:\n"
    "  -o, --output OUT  the merged image\n"
    "  --exposure EV     8-bit output: x 2^EV on top of the scene's exposure (default 0)\n"
    "  --tonemap NAME    8-bit output: clamp (default), filmic, aces or agx\n"
    "  --half            EXR output in 16-bit half floats\n"
    "\n"
    "exit status: 0 written, 2 bad input (parts that do not make one image; nothing is written)\n";

typedef struct merge_state {
    rt_part *parts;
    int count;
    int *group;      /* per part: its region's group */
    int groups;
} merge_state;

static bool same_region(const rt_part_info *a, const rt_part_info *b)
{
    return a->x0 == b->x0 && a->y0 == b->y0 && a->x1 == b->x1 && a->y1 == b->y1;
}

static int by_first_sample(const void *x, const void *y, const rt_part *parts)
{
    const rt_part_info *a = &parts[*(const int *)x].info, *b = &parts[*(const int *)y].info;
    return a->s_begin < b->s_begin ? -1 : a->s_begin > b->s_begin;
}

/* Insertion sort of the indices by first sample (few parts; qsort has no context). */
static void sort_group(int *idx, int n, const rt_part *parts)
{
    for (int i = 1; i < n; i++)
        for (int k = i; k > 0 && by_first_sample(&idx[k - 1], &idx[k], parts) > 0; k--) {
            int t = idx[k];
            idx[k] = idx[k - 1];
            idx[k - 1] = t;
        }
}

/* 2 when some pixel has no owner: the message names the box the missing
 * pixels span (a missing band of --part I/N is that band), their number and
 * the first; else 0. */
static int report_gap(const int *owner, int W, int H, FILE *errs)
{
    int x0 = W, y0 = H, x1 = -1, y1 = -1;
    size_t missing = 0, first = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if (owner[(size_t)y * (size_t)W + (size_t)x] < 0) {
                if (!missing++)
                    first = (size_t)y * (size_t)W + (size_t)x;
                x0 = x < x0 ? x : x0;
                x1 = x > x1 ? x : x1;
                y0 = y < y0 ? y : y0;
                y1 = y > y1 ? y : y1;
            }
    if (!missing)
        return 0;
    size_t box = (size_t)(x1 + 1 - x0) * (size_t)(y1 + 1 - y0);
    fprintf(errs,
            "rt: merge: a part is missing: no part covers %s [%d, %d) x [%d, %d) of the %dx%d image (%zu pixel%s, the "
            "first (%zu, %zu))\n",
            missing == box ? "the region" : "pixels in", x0, x1 + 1, y0, y1 + 1, W, H, missing, missing == 1 ? "" : "s",
            first % (size_t)W, first / (size_t)W);
    return 2;
}

/* Checks that the parts fit together and sums them into sum/good and the
 * layers' sums (whole image); 0 or 2 (the message printed). */
static int assemble(const merge_state *m, float *sum, uint32_t *good, float *const *layer, FILE *errs)
{
    const rt_part *P = m->parts;
    const rt_part_info *first = &P[0].info;
    int W = first->width, H = first->height;
    int *owner = rt_alloc((size_t)W * (size_t)H, sizeof *owner);
    int *idx = rt_alloc((size_t)m->count, sizeof *idx);
    if (!owner || !idx) {
        free(owner);
        free(idx);
        fprintf(errs, "rt: merge: out of memory for a %dx%d image\n", W, H);
        return 2;
    }
    for (size_t i = 0; i < (size_t)W * (size_t)H; i++)
        owner[i] = -1;
    int status = 0;
    for (int g = 0; g < m->groups && status == 0; g++) {
        int n = 0;
        for (int i = 0; i < m->count; i++)
            if (m->group[i] == g)
                idx[n++] = i;
        sort_group(idx, n, P);
        const rt_part_info *r = &P[idx[0]].info;
        /* the sample ranges: 0 .. spp, each sample once */
        int at = 0;
        for (int k = 0; k < n && status == 0; k++) {
            const rt_part_info *q = &P[idx[k]].info;
            if (q->s_begin < at) {
                fprintf(errs, "rt: merge: %s: samples %d:%d overlap samples %d:%d of %s (same region [%d, %d) x [%d, %d))\n",
                        P[idx[k]].path, q->s_begin, q->s_end, P[idx[k - 1]].info.s_begin, P[idx[k - 1]].info.s_end,
                        P[idx[k - 1]].path, r->x0, r->x1, r->y0, r->y1);
                status = 2;
            } else if (q->s_begin > at) {
                fprintf(errs, "rt: merge: samples %d:%d of region [%d, %d) x [%d, %d) are in no part (missing before %s, "
                              "which starts at sample %d)\n",
                        at, q->s_begin, r->x0, r->x1, r->y0, r->y1, P[idx[k]].path, q->s_begin);
                status = 2;
            }
            at = q->s_end;
        }
        if (status == 0 && at != first->spp) {
            fprintf(errs, "rt: merge: samples %d:%d of region [%d, %d) x [%d, %d) are in no part (the last, %s, ends at "
                          "sample %d of %d)\n",
                    at, first->spp, r->x0, r->x1, r->y0, r->y1, P[idx[n - 1]].path, at, first->spp);
            status = 2;
        }
        /* the region: no pixel another region has; then the sums, in sample order */
        int rw = r->x1 - r->x0;
        for (int y = r->y0; y < r->y1 && status == 0; y++)
            for (int x = r->x0; x < r->x1; x++) {
                size_t px = (size_t)y * (size_t)W + (size_t)x;
                if (owner[px] >= 0) {
                    fprintf(errs, "rt: merge: %s: region [%d, %d) x [%d, %d) overlaps region [%d, %d) x [%d, %d) of %s "
                                  "at pixel (%d, %d)\n",
                            P[idx[0]].path, r->x0, r->x1, r->y0, r->y1, P[owner[px]].info.x0, P[owner[px]].info.x1,
                            P[owner[px]].info.y0, P[owner[px]].info.y1, P[owner[px]].path, x, y);
                    status = 2;
                    break;
                }
                owner[px] = idx[0];
                size_t local = (size_t)(y - r->y0) * (size_t)rw + (size_t)(x - r->x0);
                size_t np = (size_t)rw * (size_t)(r->y1 - r->y0);
                /* the render's fold: 0 + each part's fold, then its blocks, in sample order */
                float f[3] = {0.0f, 0.0f, 0.0f};
                uint32_t c = 0;
                for (int k = 0; k < n; k++) {
                    const rt_part *q = &P[idx[k]];
                    for (int ch = 0; ch < 3; ch++) {
                        f[ch] += q->sum[3 * local + (size_t)ch];
                        for (int b = 0; b < q->info.block_count; b++)
                            f[ch] += q->blocks[((size_t)b * np + local) * 3 + (size_t)ch];
                    }
                    c += q->good[local];
                }
                sum[3 * px] = f[0];
                sum[3 * px + 1] = f[1];
                sum[3 * px + 2] = f[2];
                good[px] = c;
                for (int l = 0; l < first->layer_count; l++) {
                    size_t ch = (size_t)first->layer_channels[l];
                    for (size_t q = 0; q < ch; q++) {
                        float v = P[idx[0]].layer[l][ch * local + q];
                        for (int k = 1; k < n; k++)
                            v += P[idx[k]].layer[l][ch * local + q];
                        layer[l][ch * px + q] = v;
                    }
                }
            }
    }
    if (status == 0)
        status = report_gap(owner, W, H, errs);
    free(owner);
    free(idx);
    return status;
}

int rt_cmd_merge_to(int argc, char **argv, FILE *out, FILE *errs)
{
    const char *dst = NULL;
    float ev = 0.0f;
    bool ev_given = false, tm_given = false, half = false;
    rt_tonemap tm = RT_TONEMAP_CLAMP;
    const char **inputs = rt_alloc((size_t)(argc > 0 ? argc : 1), sizeof *inputs);
    if (!inputs) {
        fprintf(errs, "rt: merge: out of memory\n");
        return 2;
    }
    int n = 0, status = 0;
    for (int i = 1; i < argc && status == 0; i++) {
        const char *a = argv[i];
        bool takes = strcmp(a, "--exposure") == 0 || strcmp(a, "--tonemap") == 0 || strcmp(a, "-o") == 0 ||
                     strcmp(a, "--output") == 0;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            fputs(usage, out);
            free(inputs);
            return 0;
        } else if (takes && i + 1 >= argc) {
            fprintf(errs, "rt: merge: %s needs a value\n%s", a, usage);
            status = 2;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            dst = argv[++i];
        } else if (strcmp(a, "--exposure") == 0) {
            const char *v = argv[++i];
            if (rt_parse_float(v, &ev) != RT_NUMBER_OK || !(ev >= -64.0f && ev <= 64.0f)) {
                fprintf(errs, "rt: merge: --exposure wants stops from -64 to 64, got '%s'\n", v);
                status = 2;
            }
            ev_given = true;
        } else if (strcmp(a, "--tonemap") == 0) {
            const char *v = argv[++i];
            if (!rt_tonemap_parse(v, &tm)) {
                fprintf(errs, "rt: merge: --tonemap wants one of %s, got '%s'\n", RT_TONEMAP_NAMES, v);
                status = 2;
            }
            tm_given = true;
        } else if (strcmp(a, "--half") == 0) {
            half = true;
        } else if (a[0] == '-' && a[1]) {
            fprintf(errs, "rt: merge: unknown option '%s'\n%s", a, usage);
            status = 2;
        } else {
            inputs[n++] = a;
        }
    }
    if (status == 0 && (!dst || n == 0)) {
        fprintf(errs, "rt: merge: needs at least one PART and -o OUT\n%s", usage);
        status = 2;
    }
    rt_error err = {0};
    rt_image_format fmt = RT_FORMAT_PNG;
    if (status == 0 && (rt_output_format(dst, &fmt, &err) != RT_OK || rt_output_check(dst, &err) != RT_OK)) {
        fprintf(errs, "rt: merge: %s\n", err.message);
        status = 2;
    }
    if (status == 0 && fmt != RT_FORMAT_PNG && (ev_given || tm_given)) {
        fprintf(errs, "rt: merge: %s: --exposure and --tonemap shape 8-bit output (.png); float images stay linear\n",
                dst);
        status = 2;
    }
    if (status == 0 && fmt != RT_FORMAT_EXR && half) {
        fprintf(errs, "rt: merge: %s: --half is for .exr output\n", dst);
        status = 2;
    }
    merge_state m = {0};
    m.parts = status == 0 ? rt_alloc((size_t)n, sizeof *m.parts) : NULL;
    m.group = status == 0 ? rt_alloc((size_t)n, sizeof *m.group) : NULL;
    if (status == 0 && (!m.parts || !m.group)) {
        fprintf(errs, "rt: merge: out of memory for %d parts\n", n);
        status = 2;
    }
    for (int i = 0; i < n && status == 0; i++) {
        if (rt_part_read(inputs[i], &m.parts[i], &err) != RT_OK) {
            fprintf(errs, "rt: merge: %s\n", err.message);
            status = 2;
            break;
        }
        m.count = i + 1;
        char why[1200];
        if (i > 0 && part_mismatch(&m.parts[i].info, &m.parts[0].info, why, sizeof why)) {
            fprintf(errs, "rt: merge: %s: not a part of the same render as %s: %s\n", m.parts[i].path,
                    m.parts[0].path, why);
            status = 2;
            break;
        }
        char side[4200];
        rt_part_sidecar_path(m.parts[i].path, side, sizeof side);
        if (rt_same_file(dst, m.parts[i].path) || rt_same_file(dst, side)) {
            fprintf(errs, "rt: merge: %s: the output is one of the part's own files; write the image elsewhere\n", dst);
            status = 2;
            break;
        }
        for (int k = 0; k < i && status == 0; k++) { /* the same file, by the same name or another */
            if (strcmp(m.parts[k].path, m.parts[i].path) == 0 || rt_same_file(m.parts[k].path, m.parts[i].path)) {
                if (strcmp(m.parts[k].path, m.parts[i].path) == 0)
                    fprintf(errs, "rt: merge: %s is given twice\n", m.parts[i].path);
                else
                    fprintf(errs, "rt: merge: %s is given twice (also as %s)\n", m.parts[i].path, m.parts[k].path);
                status = 2;
            }
        }
        m.group[i] = -1;
        for (int k = 0; k < i && m.group[i] < 0; k++)
            if (same_region(&m.parts[k].info, &m.parts[i].info))
                m.group[i] = m.group[k];
        if (m.group[i] < 0)
            m.group[i] = m.groups++;
    }
    rt_framebuffer fb = {0};
    float *sum = NULL;
    uint32_t *good = NULL;
    float *layer[RT_PART_MAX_LAYERS] = {NULL};
    output_aovs aov;
    memset(&aov, 0, sizeof aov);
    args oa; /* what output_write reads: the AOVs, the tone flags */
    memset(&oa, 0, sizeof oa);
    oa.exposure_ev = ev;
    oa.tonemap = tm;
    oa.half = half;
    if (status == 0) {
        const rt_part_info *first = &m.parts[0].info;
        size_t np = (size_t)first->width * (size_t)first->height;
        sum = rt_alloc(np, 3 * sizeof(float));
        good = rt_alloc(np, sizeof(uint32_t));
        bool ok = sum && good;
        for (int l = 0; l < first->layer_count; l++) {
            layer[l] = rt_alloc(np, (size_t)first->layer_channels[l] * sizeof(float));
            ok = ok && layer[l];
            for (int k = 0; k < AOV_COUNT; k++)
                if (strcmp(aov_names[k], first->layer_name[l]) == 0)
                    oa.aovs |= 1u << k;
        }
        if (!ok || rt_framebuffer_init(&fb, first->width, first->height, &err) != RT_OK ||
            output_aovs_init(&aov, &oa, first->width, first->height, &err) != RT_OK) {
            fprintf(errs, "rt: merge: out of memory for a %dx%d image\n", first->width, first->height);
            status = 2;
        }
    }
    if (status == 0)
        status = assemble(&m, sum, good, layer, errs);
    if (status == 0) {
        const rt_part_info *first = &m.parts[0].info;
        /* the resolve of src/render/render.c, operation for operation:
         * sum * (1 / good) for the image, sum * (1 / good or 0) for the AOVs */
        rt_aov_sample *acc = rt_alloc((size_t)fb.width, sizeof *acc);
        if (!acc) {
            fprintf(errs, "rt: merge: out of memory\n");
            status = 2;
        }
        for (int y = 0; y < fb.height && status == 0; y++) {
            size_t row = (size_t)y * (size_t)fb.width;
            const float *rows[RT_PART_MAX_LAYERS] = {NULL};
            for (int l = 0; l < first->layer_count; l++)
                rows[l] = layer[l] + row * (size_t)first->layer_channels[l];
            layers_to_aov(first, rows, acc, (size_t)fb.width);
            for (size_t x = 0; x < (size_t)fb.width; x++) {
                size_t i = row + x;
                float inv = good[i] ? 1.0f / (float)good[i] : 1.0f;
                for (int c = 0; c < 3; c++)
                    fb.rgb[3 * i + (size_t)c] = good[i] ? sum[3 * i + (size_t)c] * inv : sum[3 * i + (size_t)c];
                float ainv = good[i] ? 1.0f / (float)good[i] : 0.0f;
                const rt_vec3 *v3[3] = {&acc[x].albedo, &acc[x].normal, &acc[x].position};
                float *dst3[3] = {aov.buf.albedo, aov.buf.normal, aov.buf.position};
                for (int k = 0; k < 3; k++)
                    if (dst3[k]) {
                        dst3[k][3 * i] = v3[k]->x * ainv;
                        dst3[k][3 * i + 1] = v3[k]->y * ainv;
                        dst3[k][3 * i + 2] = v3[k]->z * ainv;
                    }
                if (aov.buf.depth)
                    aov.buf.depth[i] = acc[x].depth * ainv;
            }
        }
        free(acc);
        rt_settings set;
        memset(&set, 0, sizeof set);
        set.exposure = first->exposure;
        if (status == 0 && output_write(&oa, &set, &fb, &aov, dst, NULL, &err) != RT_OK) {
            fprintf(errs, "rt: merge: %s\n", err.message);
            status = 2;
        } else {
            fprintf(errs, "rt: wrote %s: %dx%d from %d part%s (%d region%s), %d spp\n", dst, fb.width, fb.height, n,
                    n == 1 ? "" : "s", m.groups, m.groups == 1 ? "" : "s", m.parts[0].info.spp);
        }
    }
    rt_framebuffer_free(&fb);
    output_aovs_free(&aov);
    for (int l = 0; l < RT_PART_MAX_LAYERS; l++)
        free(layer[l]);
    free(sum);
    free(good);
    for (int i = 0; i < m.count; i++)
        rt_part_free(&m.parts[i]);
    free(m.parts);
    free(m.group);
    free(inputs);
    return status;
}

int rt_cmd_merge(int argc, char **argv) { return rt_cmd_merge_to(argc, argv, stdout, stderr); }
