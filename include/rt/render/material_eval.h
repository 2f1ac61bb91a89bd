/* rt/render/material_eval.h - a scene material evaluated at a hit: its
 * factors times its textures into the lobe parameters of rt/render/bsdf.h
 * (which knows no material), the absorption inside it, and what a surface
 * record must hold for it.
 *
 *   rt_bsdf b;
 *   rt_bsdf_from_surface(&ctx, &sf, &b);       // material + textures at a hit
 *   rt_vec3 sigma = rt_material_absorption(m); // Beer-Lambert inside m
 *   uint8_t needs = rt_material_needs(m);      // RT_MATERIAL_* bits (rt/render/render_state.h)
 *
 * The material's kind (rt_material.bsdf) picks the lobe model: Lambert,
 * the glTF metallic-roughness BSDF (with the PBR-next extensions' layers
 * when the material has any), conductor, dielectric, plastic.
 */
#ifndef RT_MATERIAL_EVAL_H
#define RT_MATERIAL_EVAL_H

#include <stdint.h>

#include "rt/render/bsdf.h"
#include "rt/render/surface.h"

/* Builds the BSDF of a hit: material factors x textures (base colour,
 * metallic-roughness, transmission, the extensions'), frame from the
 * shading normal (the geometric one when wo lies below the shading
 * normal). Calls rt_bsdf_compensate when the scene's energy_compensation
 * is on. */
void rt_bsdf_from_surface(const rt_trace_ctx *ctx, const rt_surface *sf, rt_bsdf *b);

/* Absorption coefficient inside a material (Beer-Lambert: transmittance
 * exp(-sigma d) over a distance d travelled inside): a dielectric's
 * `absorption` plus, for a dielectric or a glTF volume (thickness > 0,
 * transmission > 0), -ln(attenuation_color) / attenuation_distance. Zero
 * when nothing absorbs. */
rt_vec3 rt_material_absorption(const rt_material *m);

/* The extensions' factors of a material (no textures: rt_bsdf_from_surface
 * multiplies those in at a hit); rt_bsdf_ext_default is that of
 * rt_material_default()'s material, the values that leave the core BSDF,
 * so the defaults live in one place (scene.c). */
void rt_bsdf_ext_of_material(const rt_material *m, rt_bsdf_ext *e);
void rt_bsdf_ext_default(rt_bsdf_ext *e);

/* Whether rt_bsdf_from_surface or the record itself reads the tangent
 * frame: a normal map, a conductor (anisotropy), the glTF extensions. */
bool rt_surface_material_reads_frame(const rt_material *m);
/* The RT_MATERIAL_* bits of m (rt/render/render_state.h), which
 * rt_render_state_prepare keeps per material. */
uint8_t rt_material_needs(const rt_material *m);

#endif
