/* rt/scene/subsurface.h - random-walk subsurface scattering as a material
 * parameter set: the multiple-scattering albedo (the colour a thick slab
 * of the material looks), a mean free path per channel and a
 * Henyey-Greenstein anisotropy become a homogeneous participating medium
 * inside the material's boundary, which the volumetric path tracer walks
 * as any other medium (docs/media.md section 5).
 *
 *   rt_material m;  ... m.subsurface = true; m.subsurface_albedo = ...;
 *   m.subsurface_radius = ...;          // or 0 and attenuation_* (glTF)
 *   if (!rt_subsurface_attach(scene, &m)) ... out of memory
 *   rt_scene_add_material(scene, &m);   // m.interior_medium is the walk's medium
 *
 * The multiple-scattering albedo A becomes the single-scattering albedo
 * alpha by van de Hulst's albedo of a semi-infinite isotropic medium,
 * A = (1 - s)(1 - 0.139 s) / (1 + 1.17 s) with s = sqrt(1 - alpha),
 * inverted in closed form as KHR_materials_volume_scatter writes it
 * (after Kulla and Conty 2017):
 *   alpha = 1 - (4.09712 + 4.20863 A - sqrt(9.59217 + 41.6808 A + 17.7126 A^2))^2.
 * (Cycles' random walk uses Christensen and Burley's exponential fit of
 * the same curve, alpha = 1 - exp(A (-5.09406 + A (2.61188 - 4.31805 A)));
 * the two agree within 0.002 over [0, 1], but only this one reaches 1 at
 * A = 1, so a white material loses no energy.) The extinction:
 * - radius d given (the scene format's subsurface_radius): as Cycles'
 *   random walk (Blender 2.8x, subsurface_random_walk_remap), after
 *   Christensen and Burley ("Approximate reflectance profiles for
 *   efficient subsurface scattering", Pixar 2015):
 *   sigma_t = 1 / (d s(A)), s(A) = 1.9 - A + 3.5 (A - 0.8)^2; so d is the
 *   mean free path 1 / sigma_t up to the factor s (1.9 for a black
 *   material, about 1 for a white one). For g != 0 rt keeps the reduced
 *   scattering coefficient sigma_s (1 - g) and sigma_a of the isotropic
 *   medium (similarity theory), which is exactly van de Hulst's
 *   anisotropic inversion, (1 - alpha) / (1 - g alpha) = s^2.
 * - radius 0 (glTF KHR_materials_volume_scatter with KHR_materials_volume):
 *   sigma_t = -ln(attenuationColor) / attenuationDistance, g as given (the
 *   extension's own definition). No attenuation (distance infinite) is no
 *   medium, as the extension says.
 */
#ifndef RT_SUBSURFACE_H
#define RT_SUBSURFACE_H

#include <stdbool.h>

#include "rt/scene/scene.h"

/* The single-scattering albedo for a multiple-scattering albedo A
 * (clamped to [0, 1]): in [0, 1], increasing, 0 at 0 and 1 at 1. */
float rt_subsurface_single_albedo(float A);
/* Christensen and Burley's s(A), the radius's scale: sigma_t = 1 / (d s). */
float rt_subsurface_radius_scale(float A);

/* The medium m's subsurface parameters describe (the mapping above):
 * false when there is none (m->subsurface unset, a thin wall, no
 * attenuation). */
bool rt_subsurface_medium(const rt_material *m, rt_medium_def *out);

/* Adds the medium of m's subsurface parameters to the scene as m's
 * interior medium (from glTF: its attenuation, now the medium's, cleared);
 * nothing when there is none. False: out of memory. */
bool rt_subsurface_attach(rt_scene *s, rt_material *m);

#endif
