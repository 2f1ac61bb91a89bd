/* part_job.c - a render job's side of parts (rt/job/part_job.h,
 * docs/farm.md): the region and samples the part options ask for, the identity of a render that every
 * part of it carries (the FNV-1a hash of the input's bytes, the settings
 * that change pixels as "key value" lines with floats in C99 hexadecimal
 * so they compare exactly, the image size, the samples, the seed, rt's
 * version), and --resume's check that a part belongs to this render. */
#include "rt/job/part_job.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/job/part_split.h"
#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/render/aov.h"
#include "rt/render/integrator.h"

/* Appends "key value\n" to the settings text. */
static void line(char *buf, size_t size, const char *fmt, ...) RT_PRINTF(3, 4);
static void line(char *buf, size_t size, const char *fmt, ...)
{
    size_t n = strlen(buf);
    if (n + 1 >= size)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + n, size - n, fmt, ap);
    va_end(ap);
    n = strlen(buf);
    if (n + 1 < size) {
        buf[n] = '\n';
        buf[n + 1] = 0;
    }
}

static void settings_text(const rt_scene *scene, const rt_settings *s, char *buf, size_t size)
{
    const rt_scene_environment *e = &scene->environment;
    const rt_camera *c = &scene->camera;
    buf[0] = 0;
    line(buf, size, "resolution %d %d", s->width, s->height);
    line(buf, size, "samples %d", s->samples);
    line(buf, size, "seed %u", (unsigned)s->seed);
    line(buf, size, "integrator %s", rt_integrator_name(s->integrator));
    line(buf, size, "max_bounce %d", s->max_bounce);
    line(buf, size, "max_depth %d", s->max_depth);
    line(buf, size, "rr_depth %d", s->rr_depth);
    line(buf, size, "sampler %d", s->sampler);
    line(buf, size, "diffuse_bounces %d", s->diffuse_bounces);
    line(buf, size, "diffuse_rays %d", s->diffuse_rays);
    line(buf, size, "shadow_samples %d", s->shadow_samples);
    line(buf, size, "ray_offset %a", (double)s->ray_offset);
    line(buf, size, "clamp %a", (double)s->clamp);
    line(buf, size, "background %a %a %a", (double)e->background.x, (double)e->background.y,
         (double)e->background.z);
    const char *env = "none";
    if (e->environment_texture != RT_NONE && e->environment_texture < scene->texture_count &&
        scene->textures[e->environment_texture].image < scene->image_count)
        env = rt_path_basename(scene->images[scene->textures[e->environment_texture].image].name);
    line(buf, size, "environment %s strength %a", env, (double)e->environment_strength);
    if (e->ambient_light_set)
        line(buf, size, "ambient_light %a %a %a", (double)e->ambient_light.x, (double)e->ambient_light.y,
             (double)e->ambient_light.z);
    line(buf, size, "camera.position %a %a %a", (double)c->position.x, (double)c->position.y, (double)c->position.z);
    line(buf, size, "camera.look_at %a %a %a", (double)c->look_at.x, (double)c->look_at.y, (double)c->look_at.z);
    line(buf, size, "camera.up %a %a %a", (double)c->up.x, (double)c->up.y, (double)c->up.z);
    line(buf, size, "camera.fov %a", (double)c->vfov_deg);
    line(buf, size, "camera.aperture %a", (double)c->aperture);
    line(buf, size, "camera.focus_distance %a", (double)c->focus_distance);
    if (c->shutter_close > c->shutter_open) /* motion blur: the shutter and its slices change pixels */
        line(buf, size, "camera.shutter %a %a motion_steps %d", (double)c->shutter_open, (double)c->shutter_close,
             s->motion_steps);
}

rt_result rt_part_identity(const rt_scene *scene, const rt_settings *s, const char *input, rt_part_info *info,
                           rt_error *err)
{
    memset(info, 0, sizeof *info);
    snprintf(info->version, sizeof info->version, "%s", RT_VERSION);
    if (input && strcmp(input, "-") == 0)
        return rt_fail(err, RT_ERR_INVALID,
                       "<stdin>: a part needs its scene in a file, which every machine reads and whose hash the "
                       "parts compare (standard input cannot be read twice)");
    if (input) {
        char *bytes;
        size_t size;
        rt_result r = rt_read_file(input, 0, &bytes, &size, err);
        if (r != RT_OK)
            return r;
        info->scene_hash = rt_fnv1a64(bytes, size, RT_FNV1A64_INIT);
        free(bytes);
        snprintf(info->scene, sizeof info->scene, "%s", input);
    } else {
        static const char builtin[] = "rt built-in Cornell box";
        info->scene_hash = rt_fnv1a64(builtin, sizeof builtin - 1, RT_FNV1A64_INIT);
        snprintf(info->scene, sizeof info->scene, "<built-in scene>");
    }
    settings_text(scene, s, info->settings, sizeof info->settings);
    info->width = s->width;
    info->height = s->height;
    info->spp = s->samples;
    info->seed = s->seed;
    info->exposure = s->exposure;
    info->x1 = s->width;
    info->y1 = s->height;
    info->s_end = s->samples;
    return RT_OK;
}

/* Zeroed sums, block sums and counts (and AOV sums when aov) for n pixels. */
static rt_result alloc_sums(rt_part_job *pj, size_t n, bool aov, rt_error *err)
{
    pj->accum.sum = rt_alloc(n, 3 * sizeof(float));
    pj->accum.block = rt_alloc(n, 3 * sizeof(float));
    pj->accum.good = rt_alloc(n, sizeof(uint32_t));
    pj->accum.aov_sum = aov ? rt_alloc(n, sizeof *pj->accum.aov_sum) : NULL;
    if (!pj->accum.sum || !pj->accum.block || !pj->accum.good || (aov && !pj->accum.aov_sum)) {
        rt_part_job_free(pj);
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for the sums of %zu pixels", n);
    }
    memset(pj->accum.sum, 0, n * 3 * sizeof(float));
    memset(pj->accum.block, 0, n * 3 * sizeof(float));
    memset(pj->accum.good, 0, n * sizeof(uint32_t));
    if (aov)
        memset(pj->accum.aov_sum, 0, n * sizeof *pj->accum.aov_sum);
    return RT_OK;
}

/* A part from a block edge past sample 0 keeps each block's sum apart (so
 * a merge folds them in after the parts before it, exactly), when its
 * blocks up to the render's last sample are at most RT_PART_MAX_BLOCKS;
 * the render keeps the finished ones in accum.kept (n pixels each), the
 * last stays in accum.block. Else the part keeps its fold and last block,
 * and merges within the bound (docs/farm.md). */
static rt_result keep_blocks(rt_part_job *pj, size_t n, rt_error *err)
{
    int first = pj->part_begin / RT_SAMPLE_BLOCK, last = (pj->s_end - 1) / RT_SAMPLE_BLOCK;
    pj->keep_blocks = pj->part_begin > 0 && pj->part_begin % RT_SAMPLE_BLOCK == 0 && last - first < RT_PART_MAX_BLOCKS;
    if (pj->part_begin > 0 && pj->part_begin % RT_SAMPLE_BLOCK == 0 && !pj->keep_blocks)
        rt_warn("samples %d:%d span %d blocks of %d; a part keeps at most %d apart, so this one merges within the "
                "float summation bound, not to the exact bytes (split it into ranges of at most %d samples)",
                pj->part_begin, pj->s_end, last - first + 1, RT_SAMPLE_BLOCK, RT_PART_MAX_BLOCKS,
                RT_PART_MAX_BLOCKS * RT_SAMPLE_BLOCK);
    if (!pj->keep_blocks || last == first)
        return RT_OK;
    pj->accum.kept = rt_alloc(n * (size_t)(last - first), 3 * sizeof(float));
    if (!pj->accum.kept) {
        rt_part_job_free(pj);
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for %d block sums of %zu pixels", last - first, n);
    }
    pj->accum.kept_first = first;
    pj->accum.kept_count = last - first;
    return RT_OK;
}

static rt_result resume(rt_part_job *pj, const rt_job_options *a, const rt_settings *s, rt_error *err);

rt_result rt_part_job_init(rt_part_job *pj, const rt_job_options *a, const rt_scene *scene, const rt_settings *s,
                           const rt_kdtree *tree,
                           rt_error *err)
{
    memset(pj, 0, sizeof *pj);
    pj->to_part = a->output_is_part;
    pj->region = (rt_render_region){0, 0, s->width, s->height};
    pj->s_begin = 0;
    pj->s_end = s->samples;
    if (a->has_crop) { /* a part of the region, or (not output_is_part) the cropped image */
        if (a->crop[2] > s->width || a->crop[3] > s->height)
            return rt_fail(err, RT_ERR_INVALID, "--crop %d %d %d %d: the image is only %dx%d", a->crop[0], a->crop[1],
                           a->crop[2], a->crop[3], s->width, s->height);
        pj->region = (rt_render_region){a->crop[0], a->crop[1], a->crop[2], a->crop[3]};
    }
    bool any = pj->to_part || a->resume || a->part_out || a->stop_part;
    if (!any)
        return RT_OK;
    rt_result r = rt_part_identity(scene, s, a->input, &pj->info, err);
    if (r != RT_OK)
        return r;
    if (a->posed && a->animation_name) /* the pose changes pixels: frame time and animation are settings */
        line(pj->info.settings, sizeof pj->info.settings, "frame_time %a animation '%s'", (double)a->frame_time,
             a->animation_name);
    else if (a->posed)
        line(pj->info.settings, sizeof pj->info.settings, "frame_time %a animation %d", (double)a->frame_time,
             a->animation);
    if (a->part_count && (r = rt_part_split(scene, s, tree, a->part_index, a->part_count, &pj->region, err)) != RT_OK)
        return r;
    if (a->has_spp_range) {
        if (a->spp_end > s->samples)
            return rt_fail(err, RT_ERR_INVALID,
                           "--spp-range %d:%d: the render has %d samples per pixel; the range must end at or before "
                           "them (set the total with -s)",
                           a->spp_begin, a->spp_end, s->samples);
        pj->s_begin = a->spp_begin;
        pj->s_end = a->spp_end;
    }
    pj->part_begin = pj->s_begin;
    if ((pj->to_part || a->resume || a->part_out || a->stop_part) &&
        (a->denoise || (a->aovs & ((1u << RT_AOV_VARIANCE) | (1u << RT_AOV_SPP)))))
        return rt_fail(err, RT_ERR_INVALID,
                       "parts keep the albedo, normal, depth and position AOVs; not the variance or spp AOVs, nor "
                       "--denoise (merge the parts, then denoise the image)");
    /* the AOV sums a part carries: its layers, in rt_aov_names order */
    for (int k = 0; k < RT_AOV_COUNT; k++)
        if (a->aovs & (1u << k)) {
            rt_part_info *in = &pj->info;
            snprintf(in->layer_name[in->layer_count], sizeof in->layer_name[0], "%s", rt_aov_names[k]);
            in->layer_channels[in->layer_count++] = k == RT_AOV_DEPTH ? 1 : 3;
        }
    size_t n = (size_t)(pj->region.x1 - pj->region.x0) * (size_t)(pj->region.y1 - pj->region.y0);
    pj->need_accum = true;
    if (a->resume)
        return resume(pj, a, s, err);
    if ((r = alloc_sums(pj, n, pj->info.layer_count > 0, err)) != RT_OK)
        return r;
    return keep_blocks(pj, n, err);
}

/* rt_part_job_init for --resume: the region, samples and sums of the part. */
static rt_result resume(rt_part_job *pj, const rt_job_options *a, const rt_settings *s, rt_error *err)
{
    rt_result r;
    rt_part p;
    if ((r = rt_part_read(a->resume, &p, err)) != RT_OK)
        return r;
    char why[1024];
    if (rt_part_mismatch(&p.info, &pj->info, why, sizeof why)) {
        if (a->stop_part && strcmp(a->stop_part, a->resume) == 0) /* --frames found it, not the user */
            r = rt_fail(err, RT_ERR_INVALID,
                        "%s: a stopped render of this frame with other settings (%s): delete it and %s.json to "
                        "render the frame over",
                        a->resume, why, a->resume);
        else
            r = rt_fail(err, RT_ERR_INVALID, "--resume %s: the part is of another render: %s", a->resume, why);
        rt_part_free(&p);
        return r;
    }
    if (p.info.s_end >= s->samples) {
        r = rt_fail(err, RT_ERR_INVALID, "--resume %s: the part already holds samples %d:%d, all there are",
                    a->resume, p.info.s_begin, p.info.s_end);
        rt_part_free(&p);
        return r;
    }
    pj->region = (rt_render_region){p.info.x0, p.info.y0, p.info.x1, p.info.y1};
    pj->part_begin = p.info.s_begin;
    pj->s_begin = p.info.s_end;
    pj->s_end = s->samples;
    size_t np = (size_t)(p.info.x1 - p.info.x0) * (size_t)(p.info.y1 - p.info.y0);
    /* the render's state: the fold of every block but the last (the
     * part's kept blocks folded in as the render folded them), the last */
    pj->accum.sum = p.sum;
    pj->accum.good = p.good;
    p.sum = NULL;
    p.good = NULL;
    int nb = p.info.block_count;
    for (size_t i = 0; i < 3 * np; i++)
        for (int k = 0; k + 1 < nb; k++)
            pj->accum.sum[i] += p.blocks[(size_t)k * 3 * np + i];
    pj->accum.block = rt_alloc(np, 3 * sizeof(float));
    if (!pj->accum.block) {
        rt_part_free(&p);
        rt_part_job_free(pj);
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for the sums of %s", a->resume);
    }
    memcpy(pj->accum.block, p.blocks + (size_t)(nb - 1) * 3 * np, np * 3 * sizeof(float));
    bool kept = p.info.s_begin > 0 && (long long)p.info.block_first * RT_SAMPLE_BLOCK == p.info.s_begin;
    r = RT_OK;
    if (kept && (r = keep_blocks(pj, np, err)) == RT_OK && pj->keep_blocks && nb > 1)
        memcpy(pj->accum.kept, p.blocks, (size_t)(nb - 1) * np * 3 * sizeof(float));
    if (r != RT_OK) {
        rt_part_free(&p);
        return r;
    }
    if (pj->info.layer_count) {
        pj->accum.aov_sum = rt_alloc(np, sizeof *pj->accum.aov_sum);
        if (!pj->accum.aov_sum) {
            rt_part_free(&p);
            return rt_fail(err, RT_ERR_NOMEM, "out of memory for the AOV sums of %s", a->resume);
        }
        rt_part_layers_to_aov(&p.info, (const float *const *)p.layer, pj->accum.aov_sum, np);
    }
    rt_part_free(&p);
    bool whole = pj->region.x0 == 0 && pj->region.y0 == 0 && pj->region.x1 == s->width &&
                 pj->region.y1 == s->height && pj->part_begin == 0;
    pj->to_part = !whole;
    return RT_OK;
}

rt_result rt_part_job_accum(rt_part_job *pj, bool aov, rt_error *err)
{
    size_t n = (size_t)(pj->region.x1 - pj->region.x0) * (size_t)(pj->region.y1 - pj->region.y0);
    return alloc_sums(pj, n, aov, err);
}

void rt_part_job_free(rt_part_job *pj)
{
    free(pj->accum.sum);
    free(pj->accum.block);
    free(pj->accum.good);
    free(pj->accum.kept);
    free(pj->accum.aov_sum);
    memset(&pj->accum, 0, sizeof pj->accum);
}

rt_result rt_part_job_write(const rt_part_job *pj, const char *path, int samples_done, rt_write_batch *batch,
                            rt_error *err)
{
    rt_part_info info = pj->info;
    info.x0 = pj->region.x0;
    info.y0 = pj->region.y0;
    info.x1 = pj->region.x1;
    info.y1 = pj->region.y1;
    info.s_begin = pj->part_begin;
    info.s_end = pj->s_begin + samples_done;
    size_t n = (size_t)(info.x1 - info.x0) * (size_t)(info.y1 - info.y0);
    float *layers[RT_PART_MAX_LAYERS] = {NULL};
    rt_result r = RT_OK;
    /* the blocks: kept apart, each (the fold written is then 0), or the last one after the fold */
    const float *blocks[RT_PART_MAX_BLOCKS];
    const float *fold = pj->accum.sum;
    float *zeros = NULL;
    info.block_first = (info.s_end - 1) / RT_SAMPLE_BLOCK;
    info.block_count = 1;
    if (pj->keep_blocks) {
        info.block_first = info.s_begin / RT_SAMPLE_BLOCK;
        info.block_count = (info.s_end - 1) / RT_SAMPLE_BLOCK - info.block_first + 1;
        for (int k = 0; k + 1 < info.block_count; k++)
            blocks[k] = pj->accum.kept + (size_t)k * n * 3;
        if (!(zeros = rt_alloc(n, 3 * sizeof(float))))
            r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the part's sums", path);
        else
            memset(zeros, 0, n * 3 * sizeof(float));
        fold = zeros;
    }
    blocks[info.block_count - 1] = pj->accum.block;
    for (int k = 0; k < info.layer_count && r == RT_OK; k++)
        if (!(layers[k] = rt_alloc(n, (size_t)info.layer_channels[k] * sizeof(float))))
            r = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the AOV layers", path);
    if (r == RT_OK) {
        rt_part_aov_to_layers(&info, pj->accum.aov_sum, layers, n);
        r = rt_part_write(path, &info, fold, blocks, pj->accum.good, (const float *const *)layers, batch, err);
    }
    free(zeros);
    for (int k = 0; k < info.layer_count; k++)
        free(layers[k]);
    return r;
}
