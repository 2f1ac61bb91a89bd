/* gltf.c - PLACEHOLDER until the glTF 2.0 loader lands. */
#include "rt/gltf.h"

rt_result rt_gltf_load(rt_scene *s, const char *path, const rt_gltf_options *options, rt_gltf_stats *stats,
                       rt_error *err)
{
    (void)s; (void)options; (void)stats;
    return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: glTF loading is not built yet", path);
}
