/* rt/image/tonemap.h - exposure and tone curves for 8-bit output.
 *
 * A render holds linear radiance; an 8-bit image holds display values. The
 * way between them: scale by the exposure (2^EV times the scene's linear
 * `exposure`), map through a tone curve to display-linear [0, 1], and encode
 * with the sRGB transfer function. The curves (tonemap.c cites each):
 *   clamp   clip at 1 (rt's default: the PNGs rt always wrote)
 *   filmic  John Hable's Uncharted 2 curve, white point 11.2
 *   aces    Krzysztof Narkowicz's fit of the ACES RRT+ODT
 *   agx     Troy Sobotka's AgX, in Benjamin Wrensch's polynomial fit
 *
 *   rt_tonemap tm;
 *   if (!rt_tonemap_parse("agx", &tm)) ... unknown name ...
 *   rt_tonemap_to_srgb8(tm, exposure, rgb, pixels, bytes);   // 3 bytes a pixel
 */
#ifndef RT_TONEMAP_H
#define RT_TONEMAP_H

#include <stdbool.h>
#include <stddef.h>

typedef enum rt_tonemap { RT_TONEMAP_CLAMP = 0, RT_TONEMAP_FILMIC, RT_TONEMAP_ACES, RT_TONEMAP_AGX } rt_tonemap;

/* "clamp", "filmic", "aces", "agx" -> the curve; false for another name. */
bool rt_tonemap_parse(const char *name, rt_tonemap *out);
const char *rt_tonemap_name(rt_tonemap tm);
/* The names, comma-separated, for messages and --help. */
#define RT_TONEMAP_NAMES "clamp, filmic, aces, agx"

/* Scales stops of exposure to a linear factor: 2^ev. */
float rt_exposure_scale(float ev);

/* One linear RGB triple (already scaled by the exposure) to display-linear
 * RGB in [0, 1]. */
void rt_tonemap_rgb(rt_tonemap tm, const float in[3], float out[3]);

/* Exposure, curve and sRGB encoding of `pixels` RGB floats into 8-bit sRGB
 * (rounded to nearest). NaN and negative values give 0. */
void rt_tonemap_to_srgb8(rt_tonemap tm, float exposure, const float *rgb, size_t pixels, unsigned char *out);

#endif
