/* mesh_off.c - placeholder while the reader is written. */
#include "rt/mesh_io.h"

rt_result rt_off_load(rt_scene *s, const char *path, const rt_mat4 *transform, uint32_t material,
                      bool override_material, rt_mesh_load_stats *stats, rt_error *err)
{
    (void)s; (void)transform; (void)material; (void)override_material; (void)stats;
    return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: not built yet", path);
}
