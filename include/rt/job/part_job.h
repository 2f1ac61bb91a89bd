/* rt/job/part_job.h - a render job's side of parts (docs/farm.md): what a
 * render with a crop, a band (--part), a sample range, a resumed part or
 * a part output renders, the per-pixel sums it keeps, and the part it
 * writes; and the identity every part of a render carries.
 *
 *   rt_part_job pj;
 *   if (rt_part_job_init(&pj, &options, &scene, &settings, &tree, &err) != RT_OK) ...  // after the kd-tree
 *   ro.region = pj.region; ro.sample_begin = pj.s_begin; ro.sample_end = pj.s_end;
 *   ro.accum = pj.need_accum ? &pj.accum : NULL;
 *   ... render into a framebuffer of the region's size ...
 *   rt_part_job_write(&pj, "p.exr", stats.samples_done, &batch, &err);   // then rt_write_batch_commit
 *   rt_part_job_free(&pj);
 */
#ifndef RT_JOB_PART_JOB_H
#define RT_JOB_PART_JOB_H

#include <stdbool.h>

#include "rt/job/options.h"
#include "rt/accel/kdtree.h"
#include "rt/job/part.h"
#include "rt/render/render.h"

typedef struct rt_part_job {
    bool to_part;            /* the output is a part, not an image */
    rt_render_region region; /* the pixels rendered (the whole image unless a crop or a band) */
    int s_begin, s_end;      /* the samples this run adds */
    int part_begin;          /* the first sample the sums hold (a resumed part's; else s_begin) */
    bool need_accum;         /* sums kept: a part output, options.part_out, stop_part or resume */
    bool keep_blocks;        /* the part keeps each sample block apart (part_begin a block edge past 0) */
    rt_render_accum accum;   /* region-sized; zeros, or the resumed part's sums (and kept blocks) */
    rt_part_info info;       /* what the parts written are parts of (with the AOV layers) */
} rt_part_job;

/* The identity of a render (scene hash, settings text, size, samples, seed,
 * version) into info; the region and samples are left for the caller. */
rt_result rt_part_identity(const rt_scene *scene, const rt_settings *settings, const char *input, rt_part_info *info,
                           rt_error *err);

/* Plans the render from the options (and the part options.resume names),
 * checks them against the scene, allocates the sums. After a failure too,
 * pj is released with rt_part_job_free (which may be called again). The
 * messages name the command-line flags the options come from. */
rt_result rt_part_job_init(rt_part_job *pj, const rt_job_options *a, const rt_scene *scene,
                           const rt_settings *settings, const rt_kdtree *tree,
                           rt_error *err);
void rt_part_job_free(rt_part_job *pj);
/* Zeroed sums (and AOV sums when aov) for a render that is not a part but
 * is made of several rt_render calls into the same sums (motion blur's
 * slices); need_accum stays false. */
rt_result rt_part_job_accum(rt_part_job *pj, bool aov, rt_error *err);

/* Writes the sums as a part at path covering samples [part_begin, s_begin +
 * samples_done) into batch (rt_part_write: NULL places the files at once). */
rt_result rt_part_job_write(const rt_part_job *pj, const char *path, int samples_done, rt_write_batch *batch,
                            rt_error *err);

#endif
