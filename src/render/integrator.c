/* integrator.c - the integrator table and lookups in it: names for the
 * scene format and the command line, the radiance function rt_render's
 * workers call, and what each needs in the render state.
 */
#include "rt/render/integrator.h"

#include <stdio.h>
#include <string.h>

#include "rt/render/direct.h"
#include "rt/render/pathtrace.h"
#include "rt/render/whitted.h"

/* One line an integrator: id, name, radiance function, what it needs
 * prepared, samples per pixel in each of rt_render's passes (0 = tile by
 * tile; rt/render/render.h says why direct and whitted stay tiled), whether
 * rt_render runs it as a wavefront of paths (rt/render/wavefront.h: the
 * same radiance as the function, batch by batch), whether the camera takes
 * its film and lens samples from the `sampler` setting (else from correlated
 * multi-jittering), whether it traces a tree of diffuse_rays ^
 * diffuse_bounces rays per camera sample (rt_render_check_limits bounds it),
 * and whether it is the one a bare model gets (rt_integrator_for_models).
 * The built-in ids (rt_integrator in rt/scene/scene.h) are pinned to their
 * lines; a new integrator takes the next number. */
#define INTEGRATORS(X)                                                                                                 \
    X(RT_INTEGRATOR_DIRECT, "direct", rt_radiance_direct, 0, 0, false, false, false, false)                            \
    X(RT_INTEGRATOR_WHITTED, "whitted", rt_radiance_whitted, 0, 0, false, false, true, false)                          \
    X(RT_INTEGRATOR_PATH, "path", rt_radiance_path, RT_PREPARE_LIGHT_TABLE, 4, true, true, false, true)                \
    X(RT_INTEGRATOR_PATH_SCALAR, "path_scalar", rt_radiance_path, RT_PREPARE_LIGHT_TABLE, 4, false, true, false, false)

#define AS_INFO(id, name, fn, prepare, pass, wave, film, tree, models) [id] = {name, fn, prepare, pass, wave, film, tree, models},
#define AS_WORD(id, name, fn, prepare, pass, wave, film, tree, models) [id] = name,
static const rt_integrator_info integrators[] = {INTEGRATORS(AS_INFO)};
const char *const rt_integrator_words[] = {INTEGRATORS(AS_WORD) NULL};
#undef AS_INFO
#undef AS_WORD

enum { INTEGRATOR_COUNT = sizeof integrators / sizeof integrators[0] };

size_t rt_integrator_count(void)
{
    return INTEGRATOR_COUNT;
}

const rt_integrator_info *rt_integrator_info_of(rt_integrator id)
{
    return (size_t)id < INTEGRATOR_COUNT ? &integrators[id] : NULL;
}

rt_integrator rt_integrator_for_models(void)
{
    for (size_t i = 0; i < INTEGRATOR_COUNT; i++)
        if (integrators[i].for_models)
            return (rt_integrator)i;
    return RT_INTEGRATOR_DIRECT;
}

bool rt_integrator_by_name(const char *name, rt_integrator *id)
{
    for (size_t i = 0; name && i < INTEGRATOR_COUNT; i++) {
        if (strcmp(name, integrators[i].name) == 0) {
            *id = (rt_integrator)i;
            return true;
        }
    }
    return false;
}

const char *rt_integrator_name(rt_integrator id)
{
    const rt_integrator_info *in = rt_integrator_info_of(id);
    return in ? in->name : NULL;
}

void rt_integrator_list(char *buf, size_t size, const char *sep, const char *last_sep)
{
    if (!size)
        return;
    buf[0] = '\0';
    size_t n = 0;
    for (size_t i = 0; i < INTEGRATOR_COUNT && n < size; i++) {
        const char *between = i == 0 ? "" : (i + 1 == INTEGRATOR_COUNT ? last_sep : sep);
        int k = snprintf(buf + n, size - n, "%s%s", between, integrators[i].name);
        if (k < 0)
            break;
        n += (size_t)k;
    }
}

rt_vec3 rt_radiance(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng)
{
    const rt_integrator_info *in = rt_integrator_info_of(ctx->state->scene->settings.integrator);
    RT_DCHECK(in != NULL);
    return in->radiance(ctx, ray, rng);
}
