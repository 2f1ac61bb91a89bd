/* rt/io/image_load.h - image files into the scene's image table, each
 * decoded once (by rt_image_decode, rt/io/image_decode.h: OpenEXR, WebP,
 * and PNG, JPEG, HDR and the rest of what stb_image reads, chosen by
 * content) and cached by name, within RT_MAX_IMAGE_DIM and
 * RT_MAX_IMAGE_PIXELS: a header whose size is over the limit is refused
 * before any pixel memory is allocated. Loading the same file twice returns
 * the same image index.
 *
 *   uint32_t img;
 *   if (rt_image_load_file(&scene, "wood.png", &img, &err) != RT_OK) {
 *       if (rt_image_file_missing("wood.png")) ... warn, rt_texture_missing() ...
 *   }
 *   rt_texture tex = rt_texture_image(img);  // rt/scene/texture.h
 */
#ifndef RT_IMAGE_LOAD_H
#define RT_IMAGE_LOAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

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

/* True when path does not exist (ENOENT, ENOTDIR): the missing-texture rule
 * of rt/scene/texture.h, a warning and not an error. */
bool rt_image_file_missing(const char *path);

#endif
