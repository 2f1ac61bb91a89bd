/* rt/camera.h - pinhole and thin-lens cameras: film position to ray.
 *
 * Film coordinates: x in [0, width) from the left edge, y in [0, height)
 * from the top edge; the vertical field of view spans the full image height.
 * For a pinhole camera the direction is exactly
 *   d = normalize(f + (2x/W - 1) * t * aspect * r + (1 - 2y/H) * t * u)
 * with f = normalize(look_at - position), r = normalize(cross(f, up)),
 * u = cross(r, f), t = tan(vfov / 2) (the convention of the shared
 * benchmark rays and reference scenes).
 *
 *   rt_camera_frame cf;
 *   rt_camera_frame_init(&cf, &scene.camera, width, height);
 *   rt_ray r = rt_camera_ray(&cf, x + 0.5f, y + 0.5f, lens_sample);
 *   // sample s of spp of pixel (x, y) as rt_render takes it, and the path's random numbers:
 *   rt_rng rng;
 *   rt_ray r = rt_camera_pixel_sample(&cf, width, seed, spp, x, y, s, &rng);
 */
#ifndef RT_CAMERA_H
#define RT_CAMERA_H

#include "rt/accel/intersect.h"
#include "rt/render/sampler.h" /* rt_sampler_kind */
#include "rt/render/sampling.h"
#include "rt/scene/scene.h"

typedef struct rt_camera_frame {
    rt_vec3 origin, forward, right, up;
    float tan_half, aspect;
    float lens_radius, focus_distance;
    float inv_width, inv_height;
    rt_sampler_kind sampler; /* RT_SAMPLER_SOBOL: film and lens from the Sobol sampler (rt_camera_frame_init: CMJ) */
} rt_camera_frame;

/* false when the camera is degenerate (look_at == position, up parallel to
 * the view direction, fov outside (0, 180)). */
bool rt_camera_frame_init(rt_camera_frame *cf, const rt_camera *cam, int width, int height);
rt_ray rt_camera_ray(const rt_camera_frame *cf, float film_x, float film_y, rt_vec2 lens_sample);

/* Sample s of spp of pixel (x, y) of an image `width` pixels wide: the film
 * position and lens point by correlated multi-jittering (a pattern per
 * pixel and seed), or, when cf->sampler is RT_SAMPLER_SOBOL (the path
 * tracer's default), from the padded Owen-scrambled Sobol sampler
 * (rt/render/sampler.h) in dimensions of their own, so that every
 * power-of-two prefix of a pixel's samples (a pass, a --time-limit stop, a
 * motion-blur slice) covers the pixel evenly: CMJ puts the first samples of
 * a pixel in its top rows. The pixel centre when spp is 1. In *rng the sample's
 * own random stream, rt_rng_for_sample(seed, y * width + x, s). A pure
 * function of its arguments: the tile loop and the wavefront tracer both
 * take their samples here. */
rt_ray rt_camera_pixel_sample(const rt_camera_frame *cf, int width, uint32_t seed, uint32_t spp, int x, int y,
                              uint32_t s, rt_rng *rng);

#endif
