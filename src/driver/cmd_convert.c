/* cmd_convert.c - `rt convert IN OUT [--exposure EV] [--tonemap NAME] [--half]`:
 * an image from one format to another. IN is read whatever its format
 * (rt/io/image_read.h: EXR, PFM, HDR, PNG...); OUT's extension picks the
 * writer, as for renders (rt/io/image_write.h). Exposure and the tone curve
 * (rt/image/tonemap.h) shape 8-bit output; the float formats stay linear, so
 * asking for them with a float OUT is refused rather than ignored. A part
 * of a render (rt --crop, --part, --spp-range: its sidecar IN.json beside
 * it) is resolved into the picture it holds, its region's pixels as sum /
 * count (rt/job/part_image.h), with the scene's exposure as rt merge
 * applies it; its raw sums would be a washed-out image. */
#include "commands.h"

#include <stdbool.h>
#include <string.h>

#include "rt/base/file.h"
#include "rt/base/number.h"
#include "rt/image/tonemap.h"
#include "rt/io/image_write.h"
#include "rt/io/image_read.h"
#include "rt/job/part_image.h"

static const char usage[] =
    "usage: rt convert IN OUT [--exposure EV] [--tonemap NAME] [--half]\n"
    "\n"
    "Converts an image: IN is EXR, PFM, HDR (or PNG/JPEG), OUT is .png, .pfm, .hdr or .exr.\n"
    "Float outputs (.pfm, .hdr, .exr) keep the linear values as they are. IN may be a part\n"
    "of a render (rt --crop, --part, --spp-range; IN.json beside it): OUT is then the picture\n"
    "of its region, each pixel its sum / its count, at the scene's exposure (as rt merge).\n"
    "\n"
    "options:\n"
    "  --exposure EV    8-bit output: scale by 2^EV before the tone curve (default 0)\n"
    "  --tonemap NAME   8-bit output: clamp (default), filmic, aces or agx\n"
    "  --half           EXR output in 16-bit half floats\n"
    "\n"
    "exit status: 0 written, 2 bad input (flags, unreadable IN, unwritable OUT, OUT the same file as IN)\n";

int rt_cmd_convert_to(int argc, char **argv, FILE *out, FILE *errs)
{
    const char *in = NULL, *dst = NULL;
    float ev = 0.0f;
    bool ev_given = false, tm_given = false, half = false;
    rt_tonemap tm = RT_TONEMAP_CLAMP;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            fputs(usage, out);
            return 0;
        }
        bool takes = strcmp(a, "--exposure") == 0 || strcmp(a, "--tonemap") == 0;
        if (takes && i + 1 >= argc) {
            fprintf(errs, "rt: convert: %s needs a value\n%s", a, usage);
            return 2;
        }
        if (strcmp(a, "--exposure") == 0) {
            const char *v = argv[++i];
            if (rt_parse_float(v, &ev) != RT_NUMBER_OK || !(ev >= -64.0f && ev <= 64.0f)) {
                fprintf(errs, "rt: convert: --exposure wants stops from -64 to 64, got '%s'\n", v);
                return 2;
            }
            ev_given = true;
        } else if (strcmp(a, "--tonemap") == 0) {
            const char *v = argv[++i];
            if (!rt_tonemap_parse(v, &tm)) {
                fprintf(errs, "rt: convert: --tonemap wants one of %s, got '%s'\n", RT_TONEMAP_NAMES, v);
                return 2;
            }
            tm_given = true;
        } else if (strcmp(a, "--half") == 0) {
            half = true;
        } else if (a[0] == '-' && a[1]) {
            fprintf(errs, "rt: convert: unknown option '%s'\n%s", a, usage);
            return 2;
        } else if (!in) {
            in = a;
        } else if (!dst) {
            dst = a;
        } else {
            fprintf(errs, "rt: convert: one input and one output, please (got a third: '%s')\n", a);
            return 2;
        }
    }
    if (!in || !dst) {
        fprintf(errs, "rt: convert: needs IN and OUT\n%s", usage);
        return 2;
    }
    rt_error err = {0};
    rt_image_format fmt;
    if (rt_output_format(dst, &fmt, &err) != RT_OK || rt_output_check(dst, &err) != RT_OK) {
        fprintf(errs, "rt: convert: %s\n", err.message);
        return 2;
    }
    if (rt_same_file(in, dst)) { /* the write is atomic, but the input would be gone */
        fprintf(errs, "rt: convert: %s is the input %s; write to another file\n", dst, in);
        return 2;
    }
    if (fmt != RT_FORMAT_PNG && (ev_given || tm_given)) {
        fprintf(errs, "rt: convert: %s: --exposure and --tonemap shape 8-bit output (.png); float images stay "
                      "linear\n", dst);
        return 2;
    }
    if (fmt != RT_FORMAT_EXR && half) {
        fprintf(errs, "rt: convert: %s: --half is for .exr output\n", dst);
        return 2;
    }
    rt_framebuffer fb;
    rt_part_info info;
    bool part = false;
    if (rt_image_or_part_read(in, &fb, &info, &part, &err) != RT_OK) {
        fprintf(errs, "rt: convert: %s\n", err.message);
        return 2;
    }
    rt_image_options opt = {.exposure = (part ? info.exposure : 1.0f) * rt_exposure_scale(ev), .tonemap = tm,
                            .half = half};
    if (part)
        fprintf(errs, "rt: convert: %s is a part: pixels [%d, %d) x [%d, %d) of %dx%d, samples %d:%d of %d; "
                      "writing its %dx%d pixels as sum / count\n",
                in, info.x0, info.x1, info.y0, info.y1, info.width, info.height, info.s_begin, info.s_end, info.spp,
                fb.width, fb.height);
    int status = 0;
    if (rt_framebuffer_write_with(&fb, dst, &opt, &err) != RT_OK) {
        fprintf(errs, "rt: convert: %s\n", err.message);
        status = 2;
    }
    rt_framebuffer_free(&fb);
    return status;
}

int rt_cmd_convert(int argc, char **argv) { return rt_cmd_convert_to(argc, argv, stdout, stderr); }
