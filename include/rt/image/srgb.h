/* rt/image/srgb.h - the sRGB transfer function (IEC 61966-2-1): display
 * values in [0, 1] to linear and back, and a table for 8-bit codes.
 *
 *   float lin = rt_srgb_to_linear(0.5f);          // 0.214
 *   float enc = rt_linear_to_srgb(lin);           // 0.5, clamped to [0, 1]
 *   float lin8 = rt_srgb8_to_linear[code];        // an 8-bit code, no pow()
 */
#ifndef RT_SRGB_H
#define RT_SRGB_H

/* sRGB-encoded c to linear. */
float rt_srgb_to_linear(float c);
/* Linear c to sRGB-encoded, clamped to [0, 1] (NaN gives 0). */
float rt_linear_to_srgb(float c);

/* rt_srgb_to_linear(code / 255) for every 8-bit code, from the formula. */
extern const float rt_srgb8_to_linear[256];

#endif
