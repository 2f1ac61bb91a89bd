/* rt/texture.h - images (decoded once, cached by name) and texture lookups.
 *
 * Images are decoded by rt_image_decode (rt/io/image_decode.h: OpenEXR,
 * WebP, and PNG, JPEG, HDR and the rest of what stb_image reads, chosen by
 * content) within RT_MAX_IMAGE_DIM and RT_MAX_IMAGE_PIXELS: a header whose
 * size is over the limit is refused before any pixel memory is allocated.
 * Loading the same file twice returns the same image index.
 *
 *   uint32_t img;
 *   if (rt_image_load_file(&scene, "wood.png", &img, &err) != RT_OK) ...
 *   rt_texture tex = rt_texture_image(img);  // repeat, bilinear
 *   uint32_t t = rt_scene_add_texture(&scene, &tex);
 *   rt_vec4 c = rt_texture_sample(&scene, t, uv, true);  // sRGB colour -> linear
 */
#ifndef RT_TEXTURE_H
#define RT_TEXTURE_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

#define RT_MAX_IMAGE_DIM 32768          /* per side */
#define RT_MAX_IMAGE_PIXELS (1u << 28)  /* 268M texels, 1 GiB as RGBA8 */

/* Loads (or finds in the cache) an image file; path is used as given. */
rt_result rt_image_load_file(rt_scene *s, const char *path, uint32_t *image, rt_error *err);
/* Decodes an image held in memory (a glTF bufferView or data: URI); `name`
 * identifies it for the cache and for messages ("model.glb#image2"). */
rt_result rt_image_load_memory(rt_scene *s, const void *data, size_t size, const char *name, uint32_t *image,
                               rt_error *err);

/* Missing textures, one rule for every format (docs/scene-format.md,
 * docs/gltf.md): an image file that does not exist is a warning naming
 * where it was asked for, not an error. A colour map (base colour,
 * emission) gets rt_texture_missing() in its place, a magenta and black
 * checker that no one mistakes for the real thing; a data map (normal,
 * metallic-roughness, occlusion, transmission) is left out, so the
 * material's factors apply alone. An image that exists but cannot be read
 * or decoded stays an error. */
bool rt_image_file_missing(const char *path); /* true when path does not exist (ENOENT, ENOTDIR) */
rt_texture rt_texture_missing(void);          /* magenta / black, 8 squares per UV unit */
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

/* sRGB transfer function and its inverse (IEC 61966-2-1). */
float rt_srgb_to_linear(float c);
float rt_linear_to_srgb(float c);

#endif
