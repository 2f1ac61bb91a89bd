/* rt/image/flip.h - NVIDIA's FLIP image difference evaluator, LDR and HDR.
 *
 * FLIP models what a viewer sees when flipping between a reference and a
 * candidate image at a given viewing distance (pixels per degree of visual
 * angle): per-pixel errors in [0, 1], 0 for identical pixels. LDR-FLIP takes
 * sRGB-encoded images in [0, 1] (what a PNG holds); HDR-FLIP takes linear
 * radiance, tone maps both images over a range of exposures chosen from the
 * reference and keeps each pixel's largest LDR-FLIP error. Mean values agree
 * with NVIDIA's flip-evaluator 1.7 to well under 1e-3 (docs/compare.md).
 *
 *   // LDR-FLIP of two linear renders, as their PNGs would show them:
 *   rt_flip_srgb_encode(cand, cand_srgb, w * h);   // clamps to [0,1], encodes
 *   rt_flip_srgb_encode(ref, ref_srgb, w * h);
 *   rt_flip_options opt = {0};                     // zero = FLIP's defaults
 *   double ldr;
 *   if (rt_flip_ldr(cand_srgb, ref_srgb, w, h, &opt, NULL, &ldr, &err) != RT_OK) ...
 *
 *   // HDR-FLIP of the linear images, with a per-pixel error map:
 *   float *map = malloc(w * h * sizeof *map);
 *   double hdr;
 *   rt_flip_hdr(cand, ref, w, h, &opt, map, &hdr, NULL, &err);
 *
 * Images are interleaved RGB floats, 3 a pixel, row-major, the same size;
 * the error map is one float a pixel. The candidate comes first, as in
 * `rt compare CANDIDATE REFERENCE`. Non-finite input values are refused
 * (RT_ERR_INVALID). Working memory is about 60 bytes a pixel, freed before
 * returning. Single-threaded; no state is kept between calls.
 */
#ifndef RT_IMAGE_FLIP_H
#define RT_IMAGE_FLIP_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"

/* FLIP's default viewing condition: 0.7 m from a 0.7 m wide monitor of 3840
 * pixels, 3840 * pi / 180 = 67.02 pixels per degree. */
#define RT_FLIP_DEFAULT_PPD 67.020645f

typedef enum rt_flip_tonemapper {
    RT_FLIP_TONEMAP_ACES = 0, /* Narkowicz's fit of the ACES filmic curve (FLIP's default) */
    RT_FLIP_TONEMAP_HABLE,    /* Hable's Uncharted 2 curve */
    RT_FLIP_TONEMAP_REINHARD, /* c / (1 + luminance) */
} rt_flip_tonemapper;

typedef struct rt_flip_options {
    float ppd;                     /* pixels per degree; 0 = RT_FLIP_DEFAULT_PPD */
    rt_flip_tonemapper tonemapper; /* HDR-FLIP only */
    bool fixed_exposure;           /* HDR-FLIP: use start/stop_exposure below, not the automatic range */
    float start_exposure, stop_exposure; /* in stops (log2 of the scale factor) */
    int exposures;                 /* HDR-FLIP: 0 = max(2, ceil(stop - start)) */
} rt_flip_options;

/* The exposures HDR-FLIP used (the automatic ones unless fixed). */
typedef struct rt_flip_exposure {
    float start, stop;
    int count;
} rt_flip_exposure;

/* LDR-FLIP of sRGB-encoded images (values outside [0, 1] are clamped).
 * error_map (w * h floats) and mean may each be NULL. */
rt_result rt_flip_ldr(const float *candidate_srgb, const float *reference_srgb, int width, int height,
                      const rt_flip_options *options, float *error_map, double *mean, rt_error *err);

/* HDR-FLIP of linear RGB images (non-negative). error_map, mean and used may
 * each be NULL. */
rt_result rt_flip_hdr(const float *candidate, const float *reference, int width, int height,
                      const rt_flip_options *options, float *error_map, double *mean, rt_flip_exposure *used,
                      rt_error *err);

/* Clamps linear RGB to [0, 1] and applies the sRGB transfer function
 * (IEC 61966-2-1); `pixels` RGB triples; in place when srgb == linear. */
void rt_flip_srgb_encode(const float *linear, float *srgb, size_t pixels);

/* The magma colour map that FLIP shows error maps with: an error in [0, 1]
 * (clamped) to an sRGB-encoded colour in [0, 1]. */
void rt_flip_magma(float error, float srgb[3]);

#endif
