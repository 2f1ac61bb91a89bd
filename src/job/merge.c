/* merge.c - the parts of one render into its image (rt/job/merge.h,
 * docs/farm.md).
 *
 * Every part must be of the same render as the first (rt_part_mismatch:
 * rt version, scene hash, size, samples, seed, settings). Parts with the
 * same region are sample ranges of it: sorted by their first sample they
 * must cover 0 .. spp exactly once, and their sums are folded in that order
 * by the renderer's own fold step (rt_sample_fold,
 * rt/render/sample_block.h): 0 plus each part's fold, then each block it
 * keeps apart. That is a single render's sum exactly when every range
 * starts at a block edge (or 0) and keeps its blocks apart; else equal to
 * it up to float summation order (docs/farm.md states the bound). The
 * regions must tile the image exactly once. A pixel is then resolved by the
 * renderer's rt_sample_resolve and its AOVs by rt_aov_resolve, so region
 * parts give a single render's bytes exactly. Any problem names the part
 * at fault. A part's file is keyed by (device, inode) and its region by
 * its corners in hash indexes (rt/base/key_index.h), and the fold order
 * is one sort, so thousands of parts cost no pairwise step. */
#include "rt/job/merge.h"

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/render/sample_block.h"

static inline rt_vec3 load3(const float *f) { return rt_v3(f[0], f[1], f[2]); }

/* A part's place in the fold: its region's group, then its first sample. */
typedef struct fold_order {
    int group, s_begin, part;
} fold_order;

static int by_group_then_sample(const void *x, const void *y)
{
    const fold_order *a = x, *b = y;
    if (a->group != b->group)
        return a->group < b->group ? -1 : 1;
    if (a->s_begin != b->s_begin)
        return a->s_begin < b->s_begin ? -1 : 1;
    return (a->part > b->part) - (a->part < b->part);
}

/* 2 when some pixel has no owner: the message names the box the missing
 * pixels span (a missing band of --part I/N is that band), their number and
 * the first; else 0. */
static int report_gap(const int *owner, int W, int H, rt_error *err)
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
    rt_fail(err, RT_ERR_INVALID, "a part is missing: no part covers %s [%d, %d) x [%d, %d) of the %dx%d image (%zu pixel%s, the "
            "first (%zu, %zu))",
            missing == box ? "the region" : "pixels in", x0, x1 + 1, y0, y1 + 1, W, H, missing, missing == 1 ? "" : "s",
            first % (size_t)W, first / (size_t)W);
    return 2;
}

/* Checks that the parts fit together and folds them into sum/good and the
 * layers' sums (whole image); 0 or 2 (the message in err). */
static int assemble(const rt_merge *m, float *sum, uint32_t *good, float *const *layer, rt_error *err)
{
    const rt_part *P = m->parts;
    const rt_part_info *first = &P[0].info;
    int W = first->width, H = first->height;
    int *owner = rt_alloc((size_t)W * (size_t)H, sizeof *owner);
    int *idx = rt_alloc((size_t)m->count, sizeof *idx);
    fold_order *order = rt_alloc((size_t)m->count, sizeof *order);
    if (!owner || !idx || !order) {
        free(owner);
        free(idx);
        free(order);
        rt_fail(err, RT_ERR_NOMEM, "out of memory for a %dx%d image", W, H);
        return 2;
    }
    for (size_t i = 0; i < (size_t)W * (size_t)H; i++)
        owner[i] = -1;
    /* the parts by group, each group's by first sample: one sort, no pass over the parts a group */
    for (int i = 0; i < m->count; i++)
        order[i] = (fold_order){m->group[i], P[i].info.s_begin, i};
    qsort(order, (size_t)m->count, sizeof *order, by_group_then_sample);
    int status = 0;
    for (int at_part = 0; at_part < m->count && status == 0;) {
        int n = 0, g = order[at_part].group;
        while (at_part < m->count && order[at_part].group == g)
            idx[n++] = order[at_part++].part;
        const rt_part_info *r = &P[idx[0]].info;
        /* the sample ranges: 0 .. spp, each sample once */
        int at = 0;
        for (int k = 0; k < n && status == 0; k++) {
            const rt_part_info *q = &P[idx[k]].info;
            if (q->s_begin < at) {
                rt_fail(err, RT_ERR_INVALID, "%s: samples %d:%d overlap samples %d:%d of %s (same region [%d, %d) x [%d, %d))",
                        P[idx[k]].path, q->s_begin, q->s_end, P[idx[k - 1]].info.s_begin, P[idx[k - 1]].info.s_end,
                        P[idx[k - 1]].path, r->x0, r->x1, r->y0, r->y1);
                status = 2;
            } else if (q->s_begin > at) {
                rt_fail(err, RT_ERR_INVALID, "samples %d:%d of region [%d, %d) x [%d, %d) are in no part (missing before %s, "
                              "which starts at sample %d)",
                        at, q->s_begin, r->x0, r->x1, r->y0, r->y1, P[idx[k]].path, q->s_begin);
                status = 2;
            }
            at = q->s_end;
        }
        if (status == 0 && at != first->spp) {
            rt_fail(err, RT_ERR_INVALID, "samples %d:%d of region [%d, %d) x [%d, %d) are in no part (the last, %s, ends at "
                          "sample %d of %d)",
                    at, first->spp, r->x0, r->x1, r->y0, r->y1, P[idx[n - 1]].path, at, first->spp);
            status = 2;
        }
        /* the region: no pixel another region has; then the sums, in sample order */
        int rw = r->x1 - r->x0;
        for (int y = r->y0; y < r->y1 && status == 0; y++)
            for (int x = r->x0; x < r->x1; x++) {
                size_t px = (size_t)y * (size_t)W + (size_t)x;
                if (owner[px] >= 0) {
                    rt_fail(err, RT_ERR_INVALID, "%s: region [%d, %d) x [%d, %d) overlaps region [%d, %d) x [%d, %d) of %s "
                                  "at pixel (%d, %d)",
                            P[idx[0]].path, r->x0, r->x1, r->y0, r->y1, P[owner[px]].info.x0, P[owner[px]].info.x1,
                            P[owner[px]].info.y0, P[owner[px]].info.y1, P[owner[px]].path, x, y);
                    status = 2;
                    break;
                }
                owner[px] = idx[0];
                size_t local = (size_t)(y - r->y0) * (size_t)rw + (size_t)(x - r->x0);
                size_t np = (size_t)rw * (size_t)(r->y1 - r->y0);
                /* the render's fold: 0 + each part's fold, then its blocks, in sample order */
                rt_vec3 f = rt_v3s(0.0f);
                uint32_t c = 0;
                for (int k = 0; k < n; k++) {
                    const rt_part *q = &P[idx[k]];
                    f = rt_sample_fold(f, load3(q->sum + 3 * local));
                    for (int b = 0; b < q->info.block_count; b++)
                        f = rt_sample_fold(f, load3(q->blocks + ((size_t)b * np + local) * 3));
                    c += q->good[local];
                }
                sum[3 * px] = f.x;
                sum[3 * px + 1] = f.y;
                sum[3 * px + 2] = f.z;
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
        status = report_gap(owner, W, H, err);
    free(owner);
    free(idx);
    free(order);
    return status;
}

rt_result rt_merge_init(rt_merge *m, int capacity, rt_error *err)
{
    memset(m, 0, sizeof *m);
    size_t cap = (size_t)(capacity > 0 ? capacity : 1);
    m->parts = rt_alloc(cap, sizeof *m->parts);
    m->group = rt_alloc(cap, sizeof *m->group);
    m->file_id = rt_alloc(cap, sizeof *m->file_id);
    m->cap = capacity;
    if (!m->parts || !m->group || !m->file_id || !rt_key_index_init(&m->files, cap) ||
        !rt_key_index_init(&m->regions, cap)) {
        rt_merge_free(m);
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for %d parts", capacity);
    }
    return RT_OK;
}

rt_result rt_merge_add(rt_merge *m, const char *path, rt_error *err)
{
    if (m->count >= m->cap)
        return rt_fail(err, RT_ERR_LIMIT, "%s: room for %d parts only", path, m->cap);
    int i = m->count;
    rt_result r = rt_part_read(path, &m->parts[i], err);
    if (r != RT_OK)
        return r;
    m->count = i + 1;
    const rt_part *p = &m->parts[i];
    /* the same file, by the same name or another: keyed by (device, inode) */
    if (!rt_file_id(p->path, m->file_id[i]))
        return rt_fail(err, RT_ERR_IO, "%s: cannot stat: %s", p->path, strerror(errno));
    int first = rt_key_index_add(&m->files, m->file_id[i], i);
    if (first >= 0 && strcmp(m->parts[first].path, p->path) == 0)
        return rt_fail(err, RT_ERR_INVALID, "%s is given twice", p->path);
    if (first >= 0)
        return rt_fail(err, RT_ERR_INVALID, "%s is given twice (also as %s)", p->path, m->parts[first].path);
    char why[1200];
    if (i > 0 && rt_part_mismatch(&p->info, &m->parts[0].info, why, sizeof why))
        return rt_fail(err, RT_ERR_INVALID, "%s: not a part of the same render as %s: %s", p->path,
                       m->parts[0].path, why);
    /* parts of one region are sample ranges of it: one group a region */
    const rt_part_info *q = &p->info;
    uint64_t region[2] = {(uint64_t)(uint32_t)q->x0 << 32 | (uint32_t)q->y0,
                          (uint64_t)(uint32_t)q->x1 << 32 | (uint32_t)q->y1};
    int g = rt_key_index_add(&m->regions, region, m->groups);
    if (g < 0)
        m->covered += (uint64_t)(q->x1 - q->x0) * (uint64_t)(q->y1 - q->y0);
    m->group[i] = g >= 0 ? g : m->groups++;
    return RT_OK;
}

rt_result rt_merge_check_cover(const rt_merge *m, rt_error *err)
{
    if (m->count < 1)
        return rt_fail(err, RT_ERR_INVALID, "no parts to merge");
    const rt_part_info *first = &m->parts[0].info;
    uint64_t pixels = (uint64_t)first->width * (uint64_t)first->height;
    /* the gap report needs an int a pixel: fine when the parts hold a good share of the image */
    if (m->covered < pixels && pixels > 4 * m->covered + ((uint64_t)1 << 20))
        return rt_fail(err, RT_ERR_INVALID,
                       "parts are missing: the regions of the %d part%s given cover %llu of the %dx%d image's %llu "
                       "pixels",
                       m->count, m->count == 1 ? "" : "s", (unsigned long long)m->covered, first->width,
                       first->height, (unsigned long long)pixels);
    return RT_OK;
}

/* fb and the AOV images from the folded sums, pixel by pixel as the
 * renderer resolves them. */
static rt_result resolve(const rt_merge *m, const float *sum, const uint32_t *good, float *const *layer,
                         rt_framebuffer *fb, rt_aov_buffers *aov, rt_error *err)
{
    const rt_part_info *first = &m->parts[0].info;
    rt_aov_sample *acc = rt_alloc((size_t)fb->width, sizeof *acc);
    if (!acc)
        return rt_fail(err, RT_ERR_NOMEM, "out of memory");
    for (int y = 0; y < fb->height; y++) {
        size_t row = (size_t)y * (size_t)fb->width;
        const float *rows[RT_PART_MAX_LAYERS] = {NULL};
        for (int l = 0; l < first->layer_count; l++)
            rows[l] = layer[l] + row * (size_t)first->layer_channels[l];
        rt_part_layers_to_aov(first, rows, acc, (size_t)fb->width);
        for (size_t x = 0; x < (size_t)fb->width; x++) {
            size_t i = row + x;
            rt_vec3 v = rt_sample_resolve(load3(sum + 3 * i), good[i]);
            fb->rgb[3 * i] = v.x;
            fb->rgb[3 * i + 1] = v.y;
            fb->rgb[3 * i + 2] = v.z;
            if (aov) /* parts carry no luminance sums: no variance AOV from a merge */
                rt_aov_resolve(aov, i, &acc[x], good[i], 0.0f, 0.0);
        }
    }
    free(acc);
    return RT_OK;
}

rt_result rt_merge_image(const rt_merge *m, rt_framebuffer *fb, rt_aov_buffers *aov, rt_error *err)
{
    rt_result c = rt_merge_check_cover(m, err);
    if (c != RT_OK)
        return c;
    const rt_part_info *first = &m->parts[0].info;
    size_t np = (size_t)first->width * (size_t)first->height;
    float *sum = rt_alloc(np, 3 * sizeof(float));
    uint32_t *good = rt_alloc(np, sizeof(uint32_t));
    float *layer[RT_PART_MAX_LAYERS] = {NULL};
    bool ok = sum && good;
    for (int l = 0; l < first->layer_count; l++) {
        layer[l] = rt_alloc(np, (size_t)first->layer_channels[l] * sizeof(float));
        ok = ok && layer[l];
    }
    rt_result r = RT_OK;
    if (!ok)
        r = rt_fail(err, RT_ERR_NOMEM, "out of memory for a %dx%d image", first->width, first->height);
    else if (assemble(m, sum, good, layer, err) != 0)
        r = err && err->code != RT_OK ? err->code : RT_ERR_INVALID;
    else
        r = resolve(m, sum, good, layer, fb, aov, err);
    for (int l = 0; l < RT_PART_MAX_LAYERS; l++)
        free(layer[l]);
    free(sum);
    free(good);
    return r;
}

void rt_merge_free(rt_merge *m)
{
    for (int i = 0; m->parts && i < m->count; i++)
        rt_part_free(&m->parts[i]);
    free(m->parts);
    free(m->group);
    free(m->file_id);
    rt_key_index_free(&m->files);
    rt_key_index_free(&m->regions);
    memset(m, 0, sizeof *m);
}
