/* image_load.c - image files into the scene's image table
 * (rt/io/image_load.h): the bytes read whole (rt_read_file), decoded by
 * rt_image_decode within the texture limits, and cached by name, so a file
 * or an embedded image that several textures use is decoded once.
 */
#include "rt/io/image_load.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sys/stat.h>

#include "rt/base/file.h"
#include "rt/io/image_decode.h"

static uint32_t find_image(const rt_scene *s, const char *name)
{
    for (size_t i = 0; i < s->image_count; i++)
        if (strcmp(s->images[i].name, name) == 0)
            return (uint32_t)i;
    return RT_NONE;
}

rt_result rt_image_load_memory(rt_scene *s, const void *data, size_t size, const char *name, uint32_t *image,
                               rt_error *err)
{
    uint32_t cached = find_image(s, name);
    if (cached != RT_NONE) {
        *image = cached;
        return RT_OK;
    }
    static const rt_image_limits lim = {RT_MAX_IMAGE_DIM, RT_MAX_IMAGE_PIXELS, RT_MAX_IMAGE_PIXELS / 4};
    rt_image img;
    rt_result r = rt_image_decode(data, size, name, &lim, &img, err);
    if (r != RT_OK)
        return r;
    snprintf(img.name, sizeof img.name, "%s", name);
    uint32_t idx = rt_scene_add_image(s, &img);
    if (idx == RT_NONE) {
        free(img.rgba8);
        free(img.rgbaf);
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", name);
    }
    *image = idx;
    return RT_OK;
}

rt_result rt_image_load_file(rt_scene *s, const char *path, uint32_t *image, rt_error *err)
{
    uint32_t cached = find_image(s, path);
    if (cached != RT_NONE) {
        *image = cached;
        return RT_OK;
    }
    char *buf;
    size_t len;
    rt_result r = rt_read_file(path, (size_t)INT32_MAX, &buf, &len, err);
    if (r != RT_OK)
        return r;
    r = rt_image_load_memory(s, buf, len, path, image, err);
    free(buf);
    return r;
}

bool rt_image_file_missing(const char *path)
{
    struct stat st;
    return stat(path, &st) != 0 && (errno == ENOENT || errno == ENOTDIR);
}
