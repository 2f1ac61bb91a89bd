/* cmd_merge.c - `rt merge PART... -o OUT [--exposure EV] [--tonemap NAME]
 * [--half]`: the parts of one render (docs/farm.md) into its image. The
 * flags and the output are this file's; reading the parts, checking that
 * they make one image, and the fold and resolve of their sums are the job
 * stage's (rt/job/merge.h). Written through the same atomic writer with
 * the same exposure (the scene's, from the sidecars, times 2^--exposure)
 * and tone curve as a render. Any problem names the part at fault;
 * nothing is written then. */
#include "commands.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt/job/output.h"
#include "rt/job/part_job.h"
#include "rt/base/alloc.h"
#include "rt/base/file.h"
#include "rt/base/number.h"
#include "rt/image/tonemap.h"
#include "rt/io/image_write.h"
#include "rt/job/merge.h"

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
    rt_merge m;
    if (status == 0 && rt_merge_init(&m, n, &err) != RT_OK) {
        fprintf(errs, "rt: merge: %s\n", err.message);
        status = 2;
    }
    if (status != 0)
        memset(&m, 0, sizeof m);
    /* the output over a part's image or sidecar: the output's identity once, each part's as it is read */
    uint64_t dst_id[2], side_id[2];
    bool dst_exists = status == 0 && rt_file_id(dst, dst_id);
    for (int i = 0; i < n && status == 0; i++) {
        if (rt_merge_add(&m, inputs[i], &err) != RT_OK) { /* also a part given twice */
            fprintf(errs, "rt: merge: %s\n", err.message);
            status = 2;
            break;
        }
        char side[4200];
        rt_part_sidecar_path(m.parts[i].path, side, sizeof side);
        if (dst_exists && ((dst_id[0] == m.file_id[i][0] && dst_id[1] == m.file_id[i][1]) ||
                           (rt_file_id(side, side_id) && dst_id[0] == side_id[0] && dst_id[1] == side_id[1]))) {
            fprintf(errs, "rt: merge: %s: the output is one of the part's own files; write the image elsewhere\n", dst);
            status = 2;
        }
    }
    rt_framebuffer fb = {0};
    rt_job_aovs aov;
    memset(&aov, 0, sizeof aov);
    rt_job_options oa; /* what the output reads: the AOVs, the tone flags */
    memset(&oa, 0, sizeof oa);
    oa.exposure_ev = ev;
    oa.tonemap = tm;
    oa.half = half;
    if (status == 0 && rt_merge_check_cover(&m, &err) != RT_OK) { /* before the image is allocated */
        fprintf(errs, "rt: merge: %s\n", err.message);
        status = 2;
    }
    if (status == 0) {
        const rt_part_info *first = &m.parts[0].info;
        for (int l = 0; l < first->layer_count; l++) {
            rt_aov_kind k;
            if (rt_aov_by_name(first->layer_name[l], strlen(first->layer_name[l]), &k))
                oa.aovs |= 1u << k;
        }
        if (rt_framebuffer_init(&fb, first->width, first->height, &err) != RT_OK ||
            rt_job_aovs_init(&aov, &oa, first->width, first->height, &err) != RT_OK) {
            fprintf(errs, "rt: merge: out of memory for a %dx%d image\n", first->width, first->height);
            status = 2;
        }
    }
    if (status == 0 && rt_merge_image(&m, &fb, rt_job_aovs_for_render(&aov), &err) != RT_OK) {
        fprintf(errs, "rt: merge: %s\n", err.message);
        status = 2;
    }
    if (status == 0) {
        rt_settings set;
        memset(&set, 0, sizeof set);
        set.exposure = m.parts[0].info.exposure;
        if (rt_job_output_write(&oa, &set, &fb, &aov, dst, NULL, &err) != RT_OK) {
            fprintf(errs, "rt: merge: %s\n", err.message);
            status = 2;
        } else {
            fprintf(errs, "rt: wrote %s: %dx%d from %d part%s (%d region%s), %d spp\n", dst, fb.width, fb.height, n,
                    n == 1 ? "" : "s", m.groups, m.groups == 1 ? "" : "s", m.parts[0].info.spp);
        }
    }
    rt_framebuffer_free(&fb);
    rt_job_aovs_free(&aov);
    rt_merge_free(&m);
    free(inputs);
    return status;
}

int rt_cmd_merge(int argc, char **argv) { return rt_cmd_merge_to(argc, argv, stdout, stderr); }
