/* scene_parse.c - PLACEHOLDER until the scene parser lands. */
#include "rt/scene_parse.h"

const char rt_default_scene_text[] = "";

rt_result rt_scene_parse_file(rt_scene *s, const char *path, rt_error *err)
{
    (void)s;
    return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: the scene parser is not built yet", path);
}

rt_result rt_scene_parse_string(rt_scene *s, const char *text, size_t len, const char *name, const char *dir,
                                rt_error *err)
{
    (void)s; (void)text; (void)len; (void)dir;
    return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: the scene parser is not built yet", name);
}
