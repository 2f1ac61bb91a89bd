/* rt/render/environment.h - what rays that leave the scene see: the
 * environment image (a latitude-longitude map) or the constant background,
 * and the one latitude-longitude mapping every part of rt uses (environment
 * lookups, its importance sampling in the light table, sphere UVs).
 *
 *   rt_vec3 L = rt_environment(scene, ray_dir);     // radiance along a direction
 *   rt_vec3 A = rt_environment_mean(scene);         // mean radiance over the sphere
 *   rt_vec2 uv = rt_latlong_from_dir(d);            // unit d -> (u, v) in [0,1]^2
 *   rt_vec3 d = rt_latlong_to_dir(uv);              // and back
 *
 * Mapping: u = 0.5 + atan2(x, z) / 2pi, v = acos(y) / pi, so +y (v = 0) is the
 * top row of the image, -z the left and right edges and +z its centre
 * column. The environment's radiance is its texel (linear, never sRGB
 * decoded) times environment.environment_strength; without an image it is
 * environment.background times the strength.
 */
#ifndef RT_ENVIRONMENT_H
#define RT_ENVIRONMENT_H

#include "rt/base/vec.h"
#include "rt/scene/scene.h"

/* Unit direction to latitude-longitude coordinates. */
static inline rt_vec2 rt_latlong_from_dir(rt_vec3 d)
{
    float u = 0.5f + atan2f(d.x, d.z) * (0.5f * RT_INV_PI);
    float v = acosf(rt_clampf(d.y, -1.0f, 1.0f)) * RT_INV_PI;
    return rt_v2(u, v);
}

/* Latitude-longitude coordinates to a unit direction (the inverse). */
static inline rt_vec3 rt_latlong_to_dir(rt_vec2 uv)
{
    float theta = uv.y * RT_PI, phi = (uv.x - 0.5f) * 2.0f * RT_PI;
    float st = sinf(theta);
    return rt_v3(st * sinf(phi), cosf(theta), st * cosf(phi));
}

/* Radiance arriving from the environment along direction d (any length). */
rt_vec3 rt_environment(const rt_scene *s, rt_vec3 d);

/* Mean radiance of the environment over the sphere: the background for a
 * constant one; for an image, a 64 x 32 grid of lookups at cell centres
 * weighted by sin(theta), the solid angle of each latitude band
 * (non-finite texels skipped). */
rt_vec3 rt_environment_mean(const rt_scene *s);

#endif
