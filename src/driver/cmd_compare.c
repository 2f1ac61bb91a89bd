/* cmd_compare.c - `rt compare CANDIDATE REFERENCE`: how far a render is from a
 * reference, as the error metrics of rt/image/compare.h and the LDR-FLIP and
 * HDR-FLIP means of rt/image/flip.h (Andersson et al., "FLIP: A Difference
 * Evaluator for Alternating Images", HPG 2020; "Visualizing Errors in
 * Rendered High Dynamic Range Images", Eurographics 2021), printed as
 * key: value lines, with thresholds that set the exit status so that a
 * script or test can gate on them (docs/compare.md). */
#include "commands.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rt/base/number.h"
#include "rt/base/file.h"
#include "rt/image/compare.h"
#include "rt/image/flip.h"
#include "rt/image/srgb.h"
#include "rt/io/image_write.h"
#include "rt/io/image_read.h"
#include "rt/job/part_image.h"

static const char usage[] =
    "usage: rt compare CANDIDATE REFERENCE [options]\n"
    "\n"
    "Compares a linear RGB image (PFM, EXR or HDR, as rt -o NAME.pfm writes) with a reference\n"
    "of the same size and prints, as key: value lines:\n"
    "  MSE, RMSE, relMSE (mean (c - r)^2 / (r^2 + 0.01)), MAE, each image's mean R G B,\n"
    "  LDR-FLIP (both images clamped to [0,1] and sRGB-encoded, as their PNGs)\n"
    "  and HDR-FLIP (the linear images over FLIP's automatic exposure range, ACES).\n"
    "\n"
    "options:\n"
    "  --max-rmse X          fail (exit 1) when RMSE > X\n"
    "  --max-flip X          fail when LDR-FLIP > X\n"
    "  --max-hdr-flip X      fail when HDR-FLIP > X\n"
    "  --error-map FILE      write the LDR-FLIP error map: .png in FLIP's magma colours,\n"
    "                        .pfm, .hdr or .exr as the raw error in [0,1]\n"
    "  --hdr-error-map FILE  the same for HDR-FLIP\n"
    "  --ppd N               pixels per degree of visual angle (default 67.02: 0.7 m\n"
    "                        from a 0.7 m wide 3840-pixel monitor)\n"
    "\n"
    "exit status: 0 every threshold holds, 1 a threshold fails, 2 bad input\n";

typedef struct compare_args {
    const char *candidate, *reference;
    double max_rmse, max_flip, max_hdr_flip; /* NAN: not given */
    const char *error_map, *hdr_error_map;
    float ppd;
} compare_args;

/* A threshold: a plain decimal number >= 0 (rt/base/number.h, the syntax
 * every numeric flag takes: no hexadecimal, blanks, inf or nan). */
static bool parse_number(const char *s, double *out)
{
    double v;
    if (rt_parse_double(s, &v) != RT_NUMBER_OK || v < 0)
        return false;
    *out = v;
    return true;
}

/* 0: parsed; 1: --help printed; 2: bad arguments (message on errs). */
static int parse_args(int argc, char **argv, compare_args *a, FILE *out, FILE *errs)
{
    a->candidate = a->reference = NULL;
    a->max_rmse = a->max_flip = a->max_hdr_flip = NAN;
    a->error_map = a->hdr_error_map = NULL;
    a->ppd = 0.0f;
    int positional = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            fputs(usage, out);
            return 1;
        }
        double *number = NULL;
        const char **path = NULL;
        bool ppd = false;
        if (strcmp(arg, "--max-rmse") == 0)
            number = &a->max_rmse;
        else if (strcmp(arg, "--max-flip") == 0)
            number = &a->max_flip;
        else if (strcmp(arg, "--max-hdr-flip") == 0)
            number = &a->max_hdr_flip;
        else if (strcmp(arg, "--error-map") == 0)
            path = &a->error_map;
        else if (strcmp(arg, "--hdr-error-map") == 0)
            path = &a->hdr_error_map;
        else if (strcmp(arg, "--ppd") == 0)
            ppd = true;
        else if (arg[0] == '-' && arg[1] != '\0') {
            fprintf(errs, "rt: compare: unknown option %s\nrt: see 'rt compare --help'\n", arg);
            return 2;
        } else {
            if (positional == 0)
                a->candidate = arg;
            else if (positional == 1)
                a->reference = arg;
            else {
                fprintf(errs, "rt: compare: one candidate and one reference, not also %s\n", arg);
                return 2;
            }
            positional++;
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(errs, "rt: compare: %s needs a value\n", arg);
            return 2;
        }
        const char *value = argv[++i];
        if (path) {
            *path = value;
        } else {
            double v;
            if (!parse_number(value, &v) || (ppd && (v <= 0 || v > 10000))) {
                fprintf(errs, "rt: compare: %s %s: expected a %s number\n", arg, value,
                        ppd ? "positive (at most 10000)" : "non-negative");
                return 2;
            }
            if (ppd)
                a->ppd = (float)v;
            else
                *number = v;
        }
    }
    if (positional != 2) {
        fprintf(errs, "rt: compare: expected CANDIDATE and REFERENCE images\n%s", usage);
        return 2;
    }
    return 0;
}

/* Reads a PFM, EXR, HDR (or 8-bit) image, or a part resolved into its
 * region's picture (rt/job/part_image.h); fails with a message naming the
 * file, including for non-finite values, which no metric can take. */
static bool read_image(const char *path, rt_framebuffer *fb, FILE *errs)
{
    rt_error err = {0};
    rt_part_info info;
    bool part = false;
    if (rt_image_or_part_read(path, fb, &info, &part, &err) != RT_OK) {
        fprintf(errs, "rt: compare: %s\n", err.message);
        return false;
    }
    if (part)
        fprintf(errs, "rt: compare: %s is a part: pixels [%d, %d) x [%d, %d) of %dx%d, samples %d:%d of %d; "
                      "compared as sum / count\n",
                path, info.x0, info.x1, info.y0, info.y1, info.width, info.height, info.s_begin, info.s_end,
                info.spp);
    size_t n = (size_t)fb->width * (size_t)fb->height * 3;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(fb->rgb[i])) {
            size_t p = i / 3;
            fprintf(errs, "rt: compare: %s: pixel (%zu, %zu) is not a finite number\n", path,
                    p % (size_t)fb->width, p / (size_t)fb->width);
            rt_framebuffer_free(fb);
            return false;
        }
    return true;
}

/* Writes an error map: .png through the magma colour map, else the raw values. */
static bool write_error_map(const char *path, const float *map, int w, int h, FILE *errs)
{
    rt_error err = {0};
    rt_framebuffer fb;
    if (rt_framebuffer_init(&fb, w, h, &err) != RT_OK) {
        fprintf(errs, "rt: compare: %s: %s\n", path, err.message);
        return false;
    }
    bool png = rt_path_has_ext(path, ".png");
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        float *px = fb.rgb + 3 * i;
        if (png) {
            float srgb[3];
            rt_flip_magma(map[i], srgb);
            for (int k = 0; k < 3; k++)
                px[k] = rt_srgb_to_linear(srgb[k]); /* the PNG writer encodes it back */
        } else {
            px[0] = px[1] = px[2] = map[i];
        }
    }
    bool ok = rt_framebuffer_write(&fb, path, 1.0f, &err) == RT_OK;
    if (!ok)
        fprintf(errs, "rt: compare: %s\n", err.message);
    rt_framebuffer_free(&fb);
    return ok;
}

/* True when the threshold (if given) holds; prints why not. NaN values fail. */
static bool within(const char *what, double value, const char *flag, double limit, FILE *errs)
{
    if (isnan(limit) || value <= limit)
        return true;
    fprintf(errs, "rt: compare: %s %.6g is over %s %.6g\n", what, value, flag, limit);
    return false;
}

/* The metrics and FLIP of two images of one size, printed; the status. */
static int compare_images(const compare_args *a, const rt_framebuffer *cand, const rt_framebuffer *ref, FILE *out,
                          FILE *errs)
{
    const int w = ref->width, h = ref->height;
    const size_t pixels = (size_t)w * (size_t)h;
    rt_error err = {0};
    rt_metrics m;
    if (rt_image_metrics(cand->rgb, ref->rgb, w, h, &m, &err) != RT_OK) {
        fprintf(errs, "rt: compare: %s\n", err.message);
        return 2;
    }

    /* LDR-FLIP of the sRGB encodings, then HDR-FLIP of the linear images; one map buffer for both. */
    rt_flip_options opt = {0};
    opt.ppd = a->ppd;
    double ldr = 0, hdr = 0;
    float *srgb = malloc(pixels * 6 * sizeof *srgb), *map = malloc(pixels * sizeof *map);
    int status = 2;
    if (!srgb || !map) {
        fprintf(errs, "rt: compare: out of memory for two %dx%d images\n", w, h);
        goto done;
    }
    rt_flip_srgb_encode(cand->rgb, srgb, pixels);
    rt_flip_srgb_encode(ref->rgb, srgb + 3 * pixels, pixels);
    if (rt_flip_ldr(srgb, srgb + 3 * pixels, w, h, &opt, map, &ldr, &err) != RT_OK) {
        fprintf(errs, "rt: compare: %s\n", err.message);
        goto done;
    }
    if (a->error_map && !write_error_map(a->error_map, map, w, h, errs))
        goto done;
    if (rt_flip_hdr(cand->rgb, ref->rgb, w, h, &opt, map, &hdr, NULL, &err) != RT_OK) {
        fprintf(errs, "rt: compare: %s\n", err.message);
        goto done;
    }
    if (a->hdr_error_map && !write_error_map(a->hdr_error_map, map, w, h, errs))
        goto done;

    fprintf(out, "MSE: %.6g\n", m.mse);
    fprintf(out, "RMSE: %.6g\n", m.rmse);
    fprintf(out, "relMSE: %.6g\n", m.relmse);
    fprintf(out, "MAE: %.6g\n", m.mae);
    fprintf(out, "mean (candidate): %.6g %.6g %.6g\n", m.mean_candidate[0], m.mean_candidate[1],
            m.mean_candidate[2]);
    fprintf(out, "mean (reference): %.6g %.6g %.6g\n", m.mean_reference[0], m.mean_reference[1],
            m.mean_reference[2]);
    fprintf(out, "LDR-FLIP: %.6f\n", ldr);
    fprintf(out, "HDR-FLIP: %.6f\n", hdr);
    fflush(out);

    bool ok = within("RMSE", m.rmse, "--max-rmse", a->max_rmse, errs);
    ok &= within("LDR-FLIP", ldr, "--max-flip", a->max_flip, errs);
    ok &= within("HDR-FLIP", hdr, "--max-hdr-flip", a->max_hdr_flip, errs);
    status = ok ? 0 : 1;
done:
    free(srgb);
    free(map);
    return status;
}

int rt_cmd_compare_to(int argc, char **argv, FILE *out, FILE *errs)
{
    compare_args a;
    int parsed = parse_args(argc, argv, &a, out, errs);
    if (parsed)
        return parsed == 1 ? 0 : 2;

    /* outputs are checked before any work, as rt does for renders */
    rt_error err = {0};
    const char *outputs[2] = {a.error_map, a.hdr_error_map};
    for (int i = 0; i < 2; i++) {
        if (outputs[i] && rt_output_check(outputs[i], &err) != RT_OK) {
            fprintf(errs, "rt: compare: %s\n", err.message);
            return 2;
        }
        /* an error map over an image being compared would replace it */
        const char *input = rt_same_file(outputs[i], a.candidate) ? a.candidate
                            : rt_same_file(outputs[i], a.reference) ? a.reference
                                                                    : NULL;
        if (input) {
            fprintf(errs, "rt: compare: the error map %s is the image %s; write it to another file\n", outputs[i],
                    input);
            return 2;
        }
    }
    if (a.error_map && a.hdr_error_map && strcmp(a.error_map, a.hdr_error_map) == 0) {
        fprintf(errs, "rt: compare: --error-map and --hdr-error-map both name %s\n", a.error_map);
        return 2;
    }

    rt_framebuffer cand = {0}, ref = {0};
    int status = 2;
    if (read_image(a.candidate, &cand, errs) && read_image(a.reference, &ref, errs)) {
        if (cand.width != ref.width || cand.height != ref.height)
            fprintf(errs, "rt: compare: %s is %dx%d but the reference %s is %dx%d\n", a.candidate, cand.width,
                    cand.height, a.reference, ref.width, ref.height);
        else
            status = compare_images(&a, &cand, &ref, out, errs);
    }
    rt_framebuffer_free(&cand);
    rt_framebuffer_free(&ref);
    return status;
}

int rt_cmd_compare(int argc, char **argv) { return rt_cmd_compare_to(argc, argv, stdout, stderr); }
