/* rt/render/bsdf_sheen.h - the KHR_materials_sheen lobe: Conty Estevez and
 * Kulla's "Charlie" microfibre distribution with the visibility the
 * extension gives, and its directional albedo E for the albedo scaling of
 * the layers below.
 *
 *   float a = rt_sheen_alpha(sheen_roughness);          // floored alpha
 *   float f = rt_sheen_brdf(wo, wi, a);                 // D V, white sheen colour (no cosine)
 *   float e = rt_sheen_albedo(wo.z, a);                 // integral of f cos over wi
 *   f_total = sheen_color f + base (1 - max3(sheen_color) max(E(wo), E(wi)))
 *
 * Local frame: z is the normal; both directions above it, else f = 0. The
 * lobe is sampled by the cosine (bsdf.c folds it into the diffuse lobe's
 * share). */
#ifndef RT_BSDF_SHEEN_H
#define RT_BSDF_SHEEN_H

#include "rt/base/vec.h"

/* alpha = sheen roughness, floored at RT_SHEEN_MIN_ALPHA, where the
 * extension's fitted Lambda stops holding (E would exceed 1 at grazing). */
#define RT_SHEEN_MIN_ALPHA 0.07f
float rt_sheen_alpha(float roughness);
/* D(cos_h) = (2 + 1/alpha) sin^(1/alpha)(theta_h) / (2 pi). */
float rt_sheen_d(float cos_h, float alpha);
/* The extension's fitted Lambda(cos_theta). */
float rt_sheen_lambda(float cos_t, float alpha);
/* D V with V = 1 / ((1 + Lambda(wo) + Lambda(wi)) 4 cos_o cos_i). */
float rt_sheen_brdf(rt_vec3 wo, rt_vec3 wi, float alpha);
/* Directional albedo E(cos_o, alpha), bilinear in the table of
 * tools/gen_sheen_table.py. */
float rt_sheen_albedo(float cos_o, float alpha);

#endif
