/* rt/texture.h - textures (an image of the scene's table + a sampler, or a
 * procedural pattern) and texture lookups. Image files come into the table
 * through rt/io/image_load.h.
 *
 *   uint32_t img;  // from rt_image_load_file (rt/io/image_load.h)
 *   rt_texture tex = rt_texture_image(img);  // repeat, bilinear
 *   uint32_t t = rt_scene_add_texture(&scene, &tex);
 *   rt_vec4 c = rt_texture_sample(&scene, t, uv, true);  // sRGB colour -> linear
 */
#ifndef RT_TEXTURE_H
#define RT_TEXTURE_H

#include <stdbool.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* Missing textures, one rule for every format (docs/scene-format.md,
 * docs/gltf.md): an image file that does not exist is a warning naming
 * where it was asked for, not an error. A colour map (base colour,
 * emission) gets rt_texture_missing() in its place, a magenta and black
 * checker that no one mistakes for the real thing; a data map (normal,
 * metallic-roughness, occlusion, transmission) is left out, so the
 * material's factors apply alone. An image that exists but cannot be read
 * or decoded stays an error. */
rt_texture rt_texture_missing(void); /* magenta / black, 8 squares per UV unit */
#define RT_MISSING_TEXTURE_NOTE "a magenta checker stands in for a colour map; a normal or other data map is left out"

rt_texture rt_texture_image(uint32_t image);       /* repeat, bilinear */
rt_texture rt_texture_constant(rt_vec4 color);
rt_texture rt_texture_checker(rt_vec4 a, rt_vec4 b, float squares_per_unit);

/* Samples texture t at uv. srgb: decode the texel from sRGB to linear (colour
 * slots); data slots (normal, metal-rough, occlusion) pass false. Alpha is
 * never decoded. */
rt_vec4 rt_texture_sample(const rt_scene *s, uint32_t t, rt_vec2 uv, bool srgb);
/* Applies a slot's UV transform. */
rt_vec2 rt_texture_slot_uv(const rt_texture_slot *slot, rt_vec2 uv);

#endif
