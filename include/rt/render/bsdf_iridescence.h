/* rt/render/bsdf_iridescence.h - the KHR_materials_iridescence thin-film
 * Fresnel: a film of index film_ior and thickness d (nm) between the
 * outside and a base of normal-incidence reflectance F0, integrated over
 * the visible spectrum in closed form (Belcour and Barla 2017, as the
 * extension gives it), in linear Rec.709 RGB.
 *
 *   rt_vec3 fi = rt_iridescence_fresnel(1.0f, 1.3f, f0, 400.0f, wo_dot_h);
 *   F = lerp(F_schlick, fi, iridescence_factor)
 *
 * Thickness 0 (no film) returns Schlick's Fresnel of the base. */
#ifndef RT_BSDF_IRIDESCENCE_H
#define RT_BSDF_IRIDESCENCE_H

#include "rt/base/vec.h"

rt_vec3 rt_iridescence_fresnel(float outside_ior, float film_ior, rt_vec3 base_f0, float thickness_nm,
                               float cos_t);

#endif
