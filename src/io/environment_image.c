/* environment_image.c - the `environment` setting's file into the scene:
 * an image through the image table's loader (decoded once per name) and a
 * texture over it that repeats in longitude and stops at the poles, the
 * lat-long mapping of render/environment.c (rt/io/environment_image.h).
 */
#include "rt/io/environment_image.h"

#include "rt/io/image_load.h"
#include "rt/scene/texture.h"

rt_result rt_environment_image_load(rt_scene *s, rt_error *err)
{
    rt_settings *st = &s->settings;
    if (st->environment_file[0] == '\0' || st->environment_texture != RT_NONE)
        return RT_OK;
    uint32_t img = RT_NONE;
    rt_result r = rt_image_load_file(s, st->environment_file, &img, err);
    if (r != RT_OK)
        return r;
    if (img >= s->image_count)
        return rt_fail(err, RT_ERR_INVALID, "image loader returned no image for '%s'", st->environment_file);
    rt_texture tex = rt_texture_image(img);
    tex.wrap_s = RT_WRAP_REPEAT; /* longitude wraps around */
    tex.wrap_t = RT_WRAP_CLAMP;  /* latitude stops at the poles */
    uint32_t id = rt_scene_add_texture(s, &tex);
    if (id == RT_NONE)
        return rt_fail(err, RT_ERR_NOMEM, "out of memory");
    st->environment_texture = id;
    return RT_OK;
}
