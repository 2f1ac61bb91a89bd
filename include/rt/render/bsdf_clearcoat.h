/* rt/render/bsdf_clearcoat.h - the KHR_materials_clearcoat layer: a
 * colourless dielectric coat of index 1.5 (F0 = 4%) with its own GGX
 * roughness and normal over the rest of the glTF material.
 *
 *   rt_vec3 wo_c = ...;                                  // wo in the coat's frame (z = coat normal)
 *   float pdf;
 *   float f = rt_clearcoat_brdf(wo_c, wi_c, alpha, &pdf); // F(wo.h) D G2 / (4 cos cos), VNDF pdf
 *   rt_vec3 wi_c = rt_clearcoat_sample(wo_c, alpha, u);  // a reflection by its visible normals
 *   base weight = min(1 - c F(cos_o), 1 - c F(cos_i))      // what the coat lets through, both ways
 *
 * Alpha at least RT_BSDF_MIN_ALPHA; a coat of roughness 0 is a delta mirror
 * of weight c F(cos_o) handled by bsdf.c. */
#ifndef RT_BSDF_CLEARCOAT_H
#define RT_BSDF_CLEARCOAT_H

#include "rt/base/vec.h"

#define RT_CLEARCOAT_IOR 1.5f
/* Schlick's Fresnel of the coat, F0 = ((1.5 - 1) / (1.5 + 1))^2 = 0.04. */
float rt_clearcoat_fresnel(float cos_t);
/* The coat's microfacet lobe (no cosine, no coat weight) and, in *pdf (may
 * be NULL), the density rt_clearcoat_sample draws wi with. */
float rt_clearcoat_brdf(rt_vec3 wo, rt_vec3 wi, float alpha, float *pdf);
/* A reflected direction from u in [0,1)^2 (visible normals, Heitz 2018). */
rt_vec3 rt_clearcoat_sample(rt_vec3 wo, float alpha, rt_vec2 u);

#endif
