/* flip.c - LDR-FLIP and HDR-FLIP, the image difference evaluators of
 *
 *   P. Andersson, J. Nilsson, T. Akenine-Moller, M. Oskarsson, K. Astrom and
 *   M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating Images",
 *   Proc. ACM Comput. Graph. Interact. Tech. 3(2) (HPG 2020), and
 *   P. Andersson, J. Nilsson, P. Shirley and T. Akenine-Moller, "Visualizing
 *   Errors in Rendered High Dynamic Range Images", Eurographics 2021 (short
 *   papers), for HDR-FLIP,
 *
 * written from the papers, with the details that decide the numbers (the
 * separable filters, their radii and normalisation, border handling, the
 * exposure range) checked against NVIDIA's reference implementation so that
 * the means agree with flip-evaluator 1.7 (docs/compare.md).
 *
 * LDR-FLIP, per pixel, for sRGB inputs decoded to linear RGB in [0, 1]:
 *  1. Colour pipeline. Linear RGB -> CIE XYZ (D65) -> YCxCz, the opponent
 *     space of Zhang and Wandell's S-CIELAB (linear in XYZ, normalised by the
 *     D65 white). Each channel is filtered with a contrast sensitivity
 *     function given as Gaussians in the spatial domain,
 *     g(x) = a sqrt(pi / b) exp(-pi^2 x^2 / b), x in degrees (x = pixels /
 *     ppd): achromatic a = 1, b = 0.0047; red-green a = 1, b = 0.0053;
 *     blue-yellow the sum of a = 34.1, b = 0.04 and a = 13.5, b = 0.025. The
 *     filters reach 3 standard deviations of the widest Gaussian,
 *     r = ceil(3 sqrt(0.04 / (2 pi^2)) ppd) pixels, are normalised to sum to
 *     one, and are applied separably (the blue-yellow sum of two 2D Gaussians
 *     as two separable passes whose 1D kernels carry the square roots of the
 *     weights); image borders are extended by clamping. The filtered colour
 *     goes back to linear RGB, is clamped to [0, 1], then to CIELAB, and the
 *     Hunt effect is modelled by scaling a* and b* by 0.01 L*.
 *     The colour error is the HyAB distance |dL| + ||d(a, b)||, raised to
 *     q_c = 0.7 and mapped to [0, 1] piecewise linearly: errors below
 *     p_c c_max (p_c = 0.4, c_max = the error between pure green and pure
 *     blue) to [0, p_t = 0.95], the rest to [p_t, 1].
 *  2. Feature pipeline, on the unfiltered luminance Y / Y_white: edges and
 *     points are detected with the first and second derivatives of a
 *     Gaussian of standard deviation 0.5 w ppd pixels (w = 0.082 degrees),
 *     radius ceil(3 sd); each kernel's positive and negative weights are
 *     normalised to sum to +1 and -1 (the Gaussian itself to 1). The feature
 *     error is (max(|edge_r - edge_c|, |point_r - point_c|) / sqrt 2)^q_f,
 *     q_f = 0.5, with edge and point the gradient magnitudes.
 *  3. FLIP = colour error ^ (1 - feature error).
 * The mean FLIP is the mean over pixels (accumulated in double here).
 *
 * HDR-FLIP: the reference's exposure range is found from its luminances
 * (ITU-R BT.709 weights): with x_max the input at which the tone mapper
 * reaches 0.85, start = log2(x_max / Y_max) and stop = log2(x_max /
 * Y_median) (the upper median); max(2, ceil(stop - start)) exposures are
 * spaced evenly from start to stop. At each exposure e both images are
 * scaled by 2^e, tone mapped (per channel, ACES by default: Narkowicz's
 * rational fit of the ACES curve with its 0.6 pre-exposure cancelled),
 * clamped to [0, 1] and compared with LDR-FLIP as linear RGB; each pixel
 * keeps its largest error. Where the reference implementation would divide
 * by zero (a reference whose median, or every, luminance is 0) rt uses the
 * smallest non-zero luminance for the median, and exposure 0 for an
 * all-black reference.
 */
#include "rt/image/flip.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define FLIP_PI 3.14159265358979f

/* FLIP's constants (paper, section 4 and table 1). */
#define FLIP_QC 0.7f
#define FLIP_PC 0.4f
#define FLIP_PT 0.95f
#define FLIP_W 0.082f
#define FLIP_QF 0.5f

/* D65 white in XYZ, and its reciprocal. */
static const float white[3] = {0.950428545f, 1.000000000f, 1.088900371f};
static const float inv_white[3] = {1.052156925f, 1.000000000f, 0.918357670f};

/* ---- colour spaces --------------------------------------------------------------------------- */

static float srgb_decode(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

static float srgb_encode(float c)
{
    return c <= 0.0031308f ? c * 12.92f : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

static float clamp01(float v) { return v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v; }

/* Linear sRGB (D65) to XYZ, the matrix from the sRGB primaries in exact ratios. */
static void rgb_to_xyz(const float rgb[3], float xyz[3])
{
    xyz[0] = (10135552.0f / 24577794.0f) * rgb[0] + (8788810.0f / 24577794.0f) * rgb[1] +
             (4435075.0f / 24577794.0f) * rgb[2];
    xyz[1] = (2613072.0f / 12288897.0f) * rgb[0] + (8788810.0f / 12288897.0f) * rgb[1] +
             (887015.0f / 12288897.0f) * rgb[2];
    xyz[2] = (1425312.0f / 73733382.0f) * rgb[0] + (8788810.0f / 73733382.0f) * rgb[1] +
             (70074185.0f / 73733382.0f) * rgb[2];
}

static void xyz_to_rgb(const float xyz[3], float rgb[3])
{
    rgb[0] = 3.241003275f * xyz[0] + -1.537398934f * xyz[1] + -0.498615861f * xyz[2];
    rgb[1] = -0.969224334f * xyz[0] + 1.875930071f * xyz[1] + 0.041554224f * xyz[2];
    rgb[2] = 0.055639423f * xyz[0] + -0.204011202f * xyz[1] + 1.057148933f * xyz[2];
}

static void xyz_to_ycxcz(const float xyz[3], float out[3])
{
    float x = xyz[0] * inv_white[0], y = xyz[1] * inv_white[1], z = xyz[2] * inv_white[2];
    out[0] = 116.0f * y - 16.0f;
    out[1] = 500.0f * (x - y);
    out[2] = 200.0f * (y - z);
}

static void ycxcz_to_xyz(const float ycc[3], float xyz[3])
{
    float y = (ycc[0] + 16.0f) / 116.0f;
    xyz[0] = (y + ycc[1] / 500.0f) * white[0];
    xyz[1] = y * white[1];
    xyz[2] = (y - ycc[2] / 200.0f) * white[2];
}

static float lab_f(float t)
{
    const float delta = 6.0f / 29.0f;
    return t > delta * delta * delta ? powf(t, 1.0f / 3.0f) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
}

/* XYZ to CIELAB (D65 white) with the Hunt adjustment of a* and b*. */
static void xyz_to_lab_hunt(const float xyz[3], float lab[3])
{
    float fx = lab_f(xyz[0] * inv_white[0]), fy = lab_f(xyz[1] * inv_white[1]), fz = lab_f(xyz[2] * inv_white[2]);
    float l = 116.0f * fy - 16.0f;
    lab[0] = l;
    lab[1] = 0.01f * l * (500.0f * (fx - fy));
    lab[2] = 0.01f * l * (200.0f * (fy - fz));
}

static float hyab(const float a[3], const float b[3])
{
    float da = a[1] - b[1], db = a[2] - b[2];
    return fabsf(a[0] - b[0]) + sqrtf(da * da + db * db);
}

/* c_max: the Hunt-adjusted HyAB error between pure green and pure blue, to the power q_c. */
static float colour_cmax(void)
{
    const float green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
    float xyz[3], lg[3], lb[3];
    rgb_to_xyz(green, xyz);
    xyz_to_lab_hunt(xyz, lg);
    rgb_to_xyz(blue, xyz);
    xyz_to_lab_hunt(xyz, lb);
    return powf(hyab(lg, lb), FLIP_QC);
}

/* ---- tone mapping for HDR-FLIP --------------------------------------------------------------- */

/* (a x^2 + b x + c) / (d x^2 + e x + f) per channel. ACES: Narkowicz's fit
 * x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) with its input pre-scaled
 * by 0.6 folded in; Hable: a rational fit of Hable's filmic curve. */
static const float tonemap_coefficients[2][6] = {
    {0.6f * 0.6f * 2.51f, 0.6f * 0.03f, 0.0f, 0.6f * 0.6f * 2.43f, 0.6f * 0.59f, 0.14f},
    {0.231683f, 0.013791f, 0.0f, 0.18f, 0.3f, 0.018f},
};

static float luminance(const float rgb[3]) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }

static void tonemap(rt_flip_tonemapper tm, float rgb[3])
{
    if (tm == RT_FLIP_TONEMAP_REINHARD) {
        float s = 1.0f / (1.0f + luminance(rgb));
        for (int k = 0; k < 3; k++)
            rgb[k] *= s;
        return;
    }
    const float *t = tonemap_coefficients[tm == RT_FLIP_TONEMAP_HABLE ? 1 : 0];
    for (int k = 0; k < 3; k++) {
        float x = rgb[k];
        rgb[k] = (x * x * t[0] + x * t[1] + t[2]) / (x * x * t[3] + x * t[4] + t[5]);
    }
}

/* The input x >= 0 at which the tone mapper's output reaches 0.85 (Reinhard:
 * of the luminance), the larger root of (a - t d) x^2 + (b - t e) x + (c - t f) = 0. */
static float tonemap_x85(rt_flip_tonemapper tm)
{
    const float t = 0.85f;
    float a, b, c;
    if (tm == RT_FLIP_TONEMAP_REINHARD) { /* x / (1 + x) */
        a = 0.0f;
        b = 1.0f - t;
        c = -t;
    } else {
        const float *k = tonemap_coefficients[tm == RT_FLIP_TONEMAP_HABLE ? 1 : 0];
        a = k[0] - t * k[3];
        b = k[1] - t * k[4];
        c = k[2] - t * k[5];
    }
    if (a == 0.0f)
        return -c / b;
    float h = -0.5f * (b / a);
    return h + sqrtf(h * h - c / a);
}

/* ---- separable filters ----------------------------------------------------------------------- */

typedef struct flip_filters {
    int rs, rf;                  /* radii: spatial (CSF), feature */
    float *y, *cx, *cz1, *cz2;   /* 2 rs + 1 taps each */
    float *g, *dg, *ddg;         /* 2 rf + 1 taps each */
} flip_filters;

static void make_filters(flip_filters *f, float ppd)
{
    const float pi_sq = FLIP_PI * FLIP_PI;
    float dx = 1.0f / ppd;
    float sy = 0, scx = 0, s1 = 0, s2 = 0;
    for (int i = 0; i <= 2 * f->rs; i++) {
        float x = (float)(i - f->rs) * dx;
        float x2 = x * x;
        f->y[i] = 1.0f * sqrtf(FLIP_PI / 0.0047f) * expf(-pi_sq * x2 / 0.0047f);
        f->cx[i] = 1.0f * sqrtf(FLIP_PI / 0.0053f) * expf(-pi_sq * x2 / 0.0053f);
        /* the square roots of the weights, so that two passes give the 2D weights */
        f->cz1[i] = sqrtf(34.1f * sqrtf(FLIP_PI / 0.04f)) * expf(-pi_sq * x2 / 0.04f);
        f->cz2[i] = sqrtf(13.5f * sqrtf(FLIP_PI / 0.025f)) * expf(-pi_sq * x2 / 0.025f);
        sy += f->y[i];
        scx += f->cx[i];
        s1 += f->cz1[i];
        s2 += f->cz2[i];
    }
    /* the 2D blue-yellow filter sums to (s1^2 + s2^2), so both 1D kernels are
     * divided by its square root */
    float ny = 1.0f / sy, ncx = 1.0f / scx, ncz = 1.0f / sqrtf(s1 * s1 + s2 * s2);
    for (int i = 0; i <= 2 * f->rs; i++) {
        f->y[i] *= ny;
        f->cx[i] *= ncx;
        f->cz1[i] *= ncz;
        f->cz2[i] *= ncz;
    }

    float sd = 0.5f * FLIP_W * ppd;
    float gs = 0, dgp = 0, dgn = 0, ddgp = 0, ddgn = 0;
    for (int i = 0; i <= 2 * f->rf; i++) {
        float x = (float)(i - f->rf);
        float g = expf(-(x * x) / (2.0f * sd * sd));
        float dg = -x * g;
        float ddg = (x * x / (sd * sd) - 1.0f) * g;
        f->g[i] = g;
        f->dg[i] = dg;
        f->ddg[i] = ddg;
        gs += g;
        if (dg > 0.0f) dgp += dg; else dgn -= dg;
        if (ddg > 0.0f) ddgp += ddg; else ddgn -= ddg;
    }
    for (int i = 0; i <= 2 * f->rf; i++) {
        f->g[i] /= gs;
        f->dg[i] /= f->dg[i] > 0.0f ? dgp : dgn;
        f->ddg[i] /= f->ddg[i] > 0.0f ? ddgp : ddgn;
    }
}

/* The filters work on blocks of 8 pixels with their sums in registers (a
 * block's loops are SIMD after compilation), each pixel's taps added in
 * order; a scalar loop does the last w % 8 pixels. */
enum { LANES = 8 };

/* One row filtered horizontally: out[x] = sum_k taps[k] in[clamp(x + k - r)].
 * pad holds w + 2 r floats. */
static void filter_row(const float *in, int w, const float *taps, int r, float *restrict pad, float *restrict out)
{
    for (int i = 0; i < w + 2 * r; i++) {
        int x = i - r;
        pad[i] = in[x < 0 ? 0 : x >= w ? w - 1 : x];
    }
    int x = 0;
    for (; x + LANES <= w; x += LANES) {
        float acc[LANES] = {0};
        for (int k = 0; k <= 2 * r; k++) {
            const float t = taps[k], *p = pad + x + k;
            for (int j = 0; j < LANES; j++)
                acc[j] += t * p[j];
        }
        memcpy(out + x, acc, sizeof acc);
    }
    for (; x < w; x++) {
        float acc = 0.0f;
        for (int k = 0; k <= 2 * r; k++)
            acc += taps[k] * pad[x + k];
        out[x] = acc;
    }
}

/* Row y of a plane filtered vertically (border rows repeated). */
static void filter_column(const float *plane, int w, int h, int y, const float *taps, int r, float *restrict out)
{
    int x = 0;
    for (; x + LANES <= w; x += LANES) {
        float acc[LANES] = {0};
        for (int k = 0; k <= 2 * r; k++) {
            int yy = y + k - r;
            yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
            const float t = taps[k], *p = plane + (size_t)yy * (size_t)w + x;
            for (int j = 0; j < LANES; j++)
                acc[j] += t * p[j];
        }
        memcpy(out + x, acc, sizeof acc);
    }
    for (; x < w; x++) {
        float acc = 0.0f;
        for (int k = 0; k <= 2 * r; k++) {
            int yy = y + k - r;
            yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
            acc += taps[k] * plane[(size_t)yy * (size_t)w + (size_t)x];
        }
        out[x] = acc;
    }
}

/* ---- the LDR-FLIP core ----------------------------------------------------------------------- */

enum { REF = 0, CAND = 1 };

/* Working memory, one allocation: per image the YCxCz planes and four
 * intermediate planes (reused by the feature filters), and row buffers. */
typedef struct flip_work {
    int w, h;
    size_t n;
    flip_filters f;
    float cmax;
    float *ycc[2][3];   /* Y, Cx, Cz of the reference and the candidate */
    float *mid[2][4];   /* horizontal passes */
    float *rows[2][4];  /* vertical passes of one row */
    float *pad;
    float *scratch;     /* n floats: HDR-FLIP's per-exposure map, the median's copy */
    float *block;
} flip_work;

static rt_result work_init(flip_work *wk, int w, int h, float ppd, rt_error *err)
{
    memset(wk, 0, sizeof *wk);
    if (!(ppd > 0.0f) || !(ppd <= 10000.0f))
        return rt_fail(err, RT_ERR_INVALID, "FLIP: pixels per degree %g is out of range (0..10000]", (double)ppd);
    if (w <= 0 || h <= 0 || (size_t)w > SIZE_MAX / 128 / (size_t)h)
        return rt_fail(err, RT_ERR_INVALID, "FLIP: image size %dx%d is out of range", w, h);
    const float pi_sq = FLIP_PI * FLIP_PI;
    wk->w = w;
    wk->h = h;
    wk->n = (size_t)w * (size_t)h;
    wk->f.rs = (int)ceilf(3.0f * sqrtf(0.04f / (2.0f * pi_sq)) * ppd);
    wk->f.rf = (int)ceilf(3.0f * 0.5f * FLIP_W * ppd);
    size_t ts = 2 * (size_t)wk->f.rs + 1, tf = 2 * (size_t)wk->f.rf + 1;
    size_t rmax = (size_t)(wk->f.rs > wk->f.rf ? wk->f.rs : wk->f.rf);
    size_t wn = (size_t)w;
    /* 2 x (3 + 4) planes + scratch; 2 x 4 rows; pad; taps (w h < SIZE_MAX / 128
     * and the radii are at most 1351, so this cannot overflow) */
    size_t total = 15 * wk->n + 8 * wn + (wn + 2 * rmax) + 4 * ts + 3 * tf;
    wk->block = malloc(total * sizeof(float));
    if (!wk->block)
        return rt_fail(err, RT_ERR_NOMEM, "FLIP: out of memory for a %dx%d image", w, h);
    float *p = wk->block;
    for (int i = 0; i < 2; i++) {
        for (int c = 0; c < 3; c++, p += wk->n)
            wk->ycc[i][c] = p;
        for (int c = 0; c < 4; c++, p += wk->n)
            wk->mid[i][c] = p;
    }
    wk->scratch = p;
    p += wk->n;
    for (int i = 0; i < 2; i++)
        for (int c = 0; c < 4; c++, p += wn)
            wk->rows[i][c] = p;
    wk->pad = p;
    p += wn + 2 * rmax;
    wk->f.y = p, p += ts;
    wk->f.cx = p, p += ts;
    wk->f.cz1 = p, p += ts;
    wk->f.cz2 = p, p += ts;
    wk->f.g = p, p += tf;
    wk->f.dg = p, p += tf;
    wk->f.ddg = p;
    make_filters(&wk->f, ppd);
    wk->cmax = colour_cmax();
    return RT_OK;
}

static void work_free(flip_work *wk)
{
    free(wk->block);
    wk->block = NULL;
}

/* Stores pixel i of image `which` (linear RGB, already in [0, 1]) as YCxCz. */
static void store_ycxcz(flip_work *wk, int which, size_t i, const float rgb[3])
{
    float xyz[3], ycc[3];
    rgb_to_xyz(rgb, xyz);
    xyz_to_ycxcz(xyz, ycc);
    wk->ycc[which][0][i] = ycc[0];
    wk->ycc[which][1][i] = ycc[1];
    wk->ycc[which][2][i] = ycc[2];
}

/* LDR-FLIP of the images in wk->ycc into map (n floats). */
static void flip_core(flip_work *wk, float *map)
{
    const int w = wk->w, h = wk->h;
    const flip_filters *f = &wk->f;
    const float cmax = wk->cmax, pccmax = FLIP_PC * cmax;

    /* Colour: horizontal CSF pass of both images. */
    for (int i = 0; i < 2; i++)
        for (int y = 0; y < h; y++) {
            size_t o = (size_t)y * (size_t)w;
            filter_row(wk->ycc[i][0] + o, w, f->y, f->rs, wk->pad, wk->mid[i][0] + o);
            filter_row(wk->ycc[i][1] + o, w, f->cx, f->rs, wk->pad, wk->mid[i][1] + o);
            filter_row(wk->ycc[i][2] + o, w, f->cz1, f->rs, wk->pad, wk->mid[i][2] + o);
            filter_row(wk->ycc[i][2] + o, w, f->cz2, f->rs, wk->pad, wk->mid[i][3] + o);
        }
    /* Vertical pass row by row, then the colour error of each pixel. */
    for (int y = 0; y < h; y++) {
        for (int i = 0; i < 2; i++) {
            filter_column(wk->mid[i][0], w, h, y, f->y, f->rs, wk->rows[i][0]);
            filter_column(wk->mid[i][1], w, h, y, f->cx, f->rs, wk->rows[i][1]);
            filter_column(wk->mid[i][2], w, h, y, f->cz1, f->rs, wk->rows[i][2]);
            filter_column(wk->mid[i][3], w, h, y, f->cz2, f->rs, wk->rows[i][3]);
        }
        for (int x = 0; x < w; x++) {
            float lab[2][3];
            for (int i = 0; i < 2; i++) {
                float ycc[3] = {wk->rows[i][0][x], wk->rows[i][1][x], wk->rows[i][2][x] + wk->rows[i][3][x]};
                float xyz[3], rgb[3];
                ycxcz_to_xyz(ycc, xyz);
                xyz_to_rgb(xyz, rgb);
                for (int k = 0; k < 3; k++)
                    rgb[k] = clamp01(rgb[k]);
                rgb_to_xyz(rgb, xyz);
                xyz_to_lab_hunt(xyz, lab[i]);
            }
            float e = powf(hyab(lab[REF], lab[CAND]), FLIP_QC);
            e = e < pccmax ? e * (FLIP_PT / pccmax) : FLIP_PT + ((e - pccmax) / (cmax - pccmax)) * (1.0f - FLIP_PT);
            map[(size_t)y * (size_t)w + (size_t)x] = e;
        }
    }

    /* Features, on Y normalised to [0, 1]: horizontal pass into mid[i][0..2]
     * (first derivative, second derivative, Gaussian). */
    for (int i = 0; i < 2; i++) {
        float *yn = wk->ycc[i][0];
        for (size_t j = 0; j < wk->n; j++)
            yn[j] = yn[j] * (1.0f / 116.0f) + 16.0f / 116.0f;
        for (int y = 0; y < h; y++) {
            size_t o = (size_t)y * (size_t)w;
            filter_row(yn + o, w, f->dg, f->rf, wk->pad, wk->mid[i][0] + o);
            filter_row(yn + o, w, f->ddg, f->rf, wk->pad, wk->mid[i][1] + o);
            filter_row(yn + o, w, f->g, f->rf, wk->pad, wk->mid[i][2] + o);
        }
    }
    const float inv_sqrt2 = 1.0f / sqrtf(2.0f);
    for (int y = 0; y < h; y++) {
        for (int i = 0; i < 2; i++) {
            filter_column(wk->mid[i][0], w, h, y, f->g, f->rf, wk->rows[i][0]);   /* d/dx */
            filter_column(wk->mid[i][1], w, h, y, f->g, f->rf, wk->rows[i][1]);   /* d2/dx2 */
            filter_column(wk->mid[i][2], w, h, y, f->dg, f->rf, wk->rows[i][2]);  /* d/dy */
            filter_column(wk->mid[i][2], w, h, y, f->ddg, f->rf, wk->rows[i][3]); /* d2/dy2 */
        }
        for (int x = 0; x < w; x++) {
            float edge[2], point[2];
            for (int i = 0; i < 2; i++) {
                float dx = wk->rows[i][0][x], ddx = wk->rows[i][1][x];
                float dy = wk->rows[i][2][x], ddy = wk->rows[i][3][x];
                edge[i] = sqrtf(dx * dx + dy * dy);
                point[i] = sqrtf(ddx * ddx + ddy * ddy);
            }
            float de = fabsf(edge[REF] - edge[CAND]), dp = fabsf(point[REF] - point[CAND]);
            float fe = powf(inv_sqrt2 * (de > dp ? de : dp), FLIP_QF);
            float *m = &map[(size_t)y * (size_t)w + (size_t)x];
            *m = powf(*m, 1.0f - fe);
        }
    }
}

static double map_mean(const float *map, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++)
        s += map[i];
    return s / (double)n;
}

static rt_result check_inputs(const float *cand, const float *ref, int w, int h, rt_error *err)
{
    if (!cand || !ref)
        return rt_fail(err, RT_ERR_INVALID, "FLIP: no image given");
    if (w <= 0 || h <= 0 || (size_t)w > SIZE_MAX / 128 / (size_t)h)
        return rt_fail(err, RT_ERR_INVALID, "FLIP: image size %dx%d is out of range", w, h);
    size_t n = 3 * (size_t)w * (size_t)h;
    for (int i = 0; i < 2; i++) {
        const float *img = i ? ref : cand;
        for (size_t j = 0; j < n; j++)
            if (!isfinite(img[j]))
                return rt_fail(err, RT_ERR_INVALID, "FLIP: the %s image's pixel (%zu, %zu) is not finite",
                               i ? "reference" : "candidate", j / 3 % (size_t)w, j / 3 / (size_t)w);
    }
    return RT_OK;
}

static float options_ppd(const rt_flip_options *o) { return o && o->ppd != 0.0f ? o->ppd : RT_FLIP_DEFAULT_PPD; }

rt_result rt_flip_ldr(const float *candidate_srgb, const float *reference_srgb, int width, int height,
                      const rt_flip_options *options, float *error_map, double *mean, rt_error *err)
{
    rt_result r = check_inputs(candidate_srgb, reference_srgb, width, height, err);
    if (r != RT_OK)
        return r;
    flip_work wk;
    if ((r = work_init(&wk, width, height, options_ppd(options), err)) != RT_OK)
        return r;
    for (size_t i = 0; i < wk.n; i++)
        for (int j = 0; j < 2; j++) {
            const float *src = (j == REF ? reference_srgb : candidate_srgb) + 3 * i;
            float rgb[3];
            for (int k = 0; k < 3; k++)
                rgb[k] = clamp01(srgb_decode(src[k]));
            store_ycxcz(&wk, j, i, rgb);
        }
    float *map = error_map ? error_map : wk.scratch;
    flip_core(&wk, map);
    if (mean)
        *mean = map_mean(map, wk.n);
    work_free(&wk);
    return RT_OK;
}

/* The k-th smallest of v[0..n) (k < n), reordering v: Hoare's selection
 * (Wirth's formulation), expected linear time. */
static float select_kth(float *v, size_t n, size_t k)
{
    ptrdiff_t l = 0, r = (ptrdiff_t)n - 1, kk = (ptrdiff_t)k;
    while (l < r) {
        float pivot = v[kk];
        ptrdiff_t i = l, j = r;
        do {
            while (v[i] < pivot)
                i++;
            while (pivot < v[j])
                j--;
            if (i <= j) {
                float t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                j--;
            }
        } while (i <= j);
        if (j < kk)
            l = i;
        if (kk < i)
            r = j;
    }
    return v[kk];
}

/* The automatic exposure range from the reference's luminances. */
static void auto_exposure(const float *ref, size_t n, rt_flip_tonemapper tm, float *scratch, float *start, float *stop)
{
    float ymax = 0.0f, ymin_pos = INFINITY;
    for (size_t i = 0; i < n; i++) {
        float l = luminance(ref + 3 * i);
        scratch[i] = l;
        if (l > ymax)
            ymax = l;
        if (l > 0.0f && l < ymin_pos)
            ymin_pos = l;
    }
    if (!(ymax > 0.0f)) { /* an all-black reference: nothing to expose for */
        *start = *stop = 0.0f;
        return;
    }
    float median = select_kth(scratch, n, n / 2);
    if (!(median > 0.0f))
        median = ymin_pos;
    float x85 = tonemap_x85(tm);
    *start = log2f(x85 / ymax);
    *stop = log2f(x85 / median);
}

rt_result rt_flip_hdr(const float *candidate, const float *reference, int width, int height,
                      const rt_flip_options *options, float *error_map, double *mean, rt_flip_exposure *used,
                      rt_error *err)
{
    rt_result r = check_inputs(candidate, reference, width, height, err);
    if (r != RT_OK)
        return r;
    rt_flip_tonemapper tm = options ? options->tonemapper : RT_FLIP_TONEMAP_ACES;
    if (tm != RT_FLIP_TONEMAP_ACES && tm != RT_FLIP_TONEMAP_HABLE && tm != RT_FLIP_TONEMAP_REINHARD)
        return rt_fail(err, RT_ERR_INVALID, "FLIP: unknown tone mapper %d", (int)tm);
    flip_work wk;
    if ((r = work_init(&wk, width, height, options_ppd(options), err)) != RT_OK)
        return r;

    float start, stop;
    if (options && options->fixed_exposure) {
        start = options->start_exposure;
        stop = options->stop_exposure;
        if (!isfinite(start) || !isfinite(stop) || start > stop) {
            work_free(&wk);
            return rt_fail(err, RT_ERR_INVALID, "FLIP: exposure range %g..%g is not a range", (double)start,
                           (double)stop);
        }
    } else {
        auto_exposure(reference, wk.n, tm, wk.scratch, &start, &stop);
    }
    int count = options && options->exposures > 0 ? options->exposures : 0;
    if (count == 0) {
        float c = ceilf(stop - start);
        count = c > 2.0f ? (c < 1000.0f ? (int)c : 1000) : 2;
    }
    if (used) {
        used->start = start;
        used->stop = stop;
        used->count = count;
    }

    float *map = error_map ? error_map : wk.scratch;
    float *one = error_map ? wk.scratch : NULL;
    if (!one) { /* no caller map: the running maximum needs a plane of its own */
        one = malloc(wk.n * sizeof *one);
        if (!one) {
            work_free(&wk);
            return rt_fail(err, RT_ERR_NOMEM, "FLIP: out of memory for a %dx%d image", width, height);
        }
    }
    for (size_t i = 0; i < wk.n; i++)
        map[i] = 0.0f;
    float step = count > 1 ? (stop - start) / (float)(count - 1) : 0.0f;
    for (int e = 0; e < count; e++) {
        float scale = powf(2.0f, start + (float)e * step);
        for (size_t i = 0; i < wk.n; i++)
            for (int j = 0; j < 2; j++) {
                const float *src = (j == REF ? reference : candidate) + 3 * i;
                float rgb[3] = {src[0] * scale, src[1] * scale, src[2] * scale};
                tonemap(tm, rgb);
                for (int k = 0; k < 3; k++)
                    rgb[k] = clamp01(rgb[k]);
                store_ycxcz(&wk, j, i, rgb);
            }
        flip_core(&wk, one);
        for (size_t i = 0; i < wk.n; i++)
            if (one[i] > map[i])
                map[i] = one[i];
    }
    if (mean)
        *mean = map_mean(map, wk.n);
    if (!error_map)
        free(one);
    work_free(&wk);
    return RT_OK;
}

void rt_flip_srgb_encode(const float *linear, float *srgb, size_t pixels)
{
    for (size_t i = 0; i < 3 * pixels; i++)
        srgb[i] = srgb_encode(clamp01(linear[i]));
}

/* Matplotlib's magma (van der Walt and Smith, CC0), sampled at entries 0,
 * 16, ..., 240 and 255 of its 256; interpolated linearly in between. */
static const float magma_knots[17][3] = {
    {0.001462f, 0.000466f, 0.013866f}, {0.039608f, 0.031090f, 0.133515f}, {0.113094f, 0.065492f, 0.276784f},
    {0.211718f, 0.061992f, 0.418647f}, {0.316654f, 0.071690f, 0.485380f}, {0.414709f, 0.110431f, 0.504662f},
    {0.512831f, 0.148179f, 0.507648f}, {0.613617f, 0.181811f, 0.498536f}, {0.716387f, 0.214982f, 0.475290f},
    {0.816914f, 0.255895f, 0.436461f}, {0.904281f, 0.319610f, 0.388137f}, {0.960949f, 0.418323f, 0.359630f},
    {0.986700f, 0.535582f, 0.382210f}, {0.996096f, 0.653659f, 0.446213f}, {0.996898f, 0.769591f, 0.534892f},
    {0.992440f, 0.884330f, 0.640099f}, {0.987053f, 0.991438f, 0.749504f},
};

void rt_flip_magma(float error, float srgb[3])
{
    float t = (isnan(error) ? 0.0f : clamp01(error)) * 255.0f;
    int k = t >= 240.0f ? 15 : (int)(t / 16.0f);
    float k0 = 16.0f * (float)k, k1 = k == 15 ? 255.0f : k0 + 16.0f;
    float u = (t - k0) / (k1 - k0);
    for (int c = 0; c < 3; c++)
        srgb[c] = magma_knots[k][c] + u * (magma_knots[k + 1][c] - magma_knots[k][c]);
}
