/* camera.c - pinhole and thin-lens camera rays (see rt/camera.h for the
 * exact convention). Thin lens: the origin is sampled on a disk of radius
 * aperture/2 around the eye and the ray aimed at the point the pinhole ray
 * reaches on the plane of focus (pbrt, section 6.2.3). Pixel samples:
 * correlated multi-jittered positions (Kensler 2013, rt/render/sampling.h),
 * or for the path tracer its Sobol sampler's (rt/render/sampler.h; film and
 * lens in one rt/render/sampler_block.h block when the CPU has AVX2). */
#include "rt/render/camera.h"

#include "rt/render/sampler.h"
#include "rt/render/sampling.h"
#include "rt/render/sampler_block.h"

bool rt_camera_frame_init(rt_camera_frame *cf, const rt_camera *cam, int width, int height)
{
    rt_vec3 f = rt_sub(cam->look_at, cam->position);
    float dist = rt_length(f);
    f = rt_normalize(f);
    rt_vec3 r = rt_cross(f, cam->up);
    bool ok = dist > 0.0f && rt_length(r) > 1e-6f && cam->vfov_deg > 0.0f && cam->vfov_deg < 180.0f &&
              width > 0 && height > 0 && rt_finite3(cam->position) && rt_finite3(f);
    if (!ok) {
        /* keep the frame usable (a valid camera looking down -z) */
        f = rt_v3(0, 0, -1);
        r = rt_v3(1, 0, 0);
        dist = 1.0f;
    }
    r = rt_normalize(r);
    cf->origin = cam->position;
    cf->forward = f;
    cf->right = r;
    cf->up = rt_cross(r, f);
    float fov = ok ? cam->vfov_deg : 40.0f;
    cf->tan_half = tanf(0.5f * fov * (RT_PI / 180.0f));
    cf->aspect = (float)(width > 0 ? width : 1) / (float)(height > 0 ? height : 1);
    cf->lens_radius = cam->aperture > 0.0f ? 0.5f * cam->aperture : 0.0f;
    cf->focus_distance = cam->focus_distance > 0.0f ? cam->focus_distance : dist;
    cf->inv_width = 1.0f / (float)(width > 0 ? width : 1);
    cf->inv_height = 1.0f / (float)(height > 0 ? height : 1);
    cf->sampler = RT_SAMPLER_CMJ;
    return ok;
}

rt_ray rt_camera_ray(const rt_camera_frame *cf, float film_x, float film_y, rt_vec2 lens_sample)
{
    float sx = (2.0f * film_x * cf->inv_width - 1.0f) * cf->tan_half * cf->aspect;
    float sy = (1.0f - 2.0f * film_y * cf->inv_height) * cf->tan_half;
    rt_vec3 d = rt_add(cf->forward, rt_add(rt_scale(cf->right, sx), rt_scale(cf->up, sy)));
    if (cf->lens_radius > 0.0f) {
        /* the pinhole ray d (forward component 1) reaches the focus plane at d * focus */
        rt_vec3 focus = rt_madd(cf->origin, d, cf->focus_distance);
        rt_vec2 lens = rt_sample_disk(lens_sample);
        rt_vec3 o = rt_add(cf->origin, rt_add(rt_scale(cf->right, lens.x * cf->lens_radius),
                                              rt_scale(cf->up, lens.y * cf->lens_radius)));
        return rt_ray_make(o, rt_normalize(rt_sub(focus, o)), 0.0f, INFINITY);
    }
    return rt_ray_make(cf->origin, rt_normalize(d), 0.0f, INFINITY);
}

rt_ray rt_camera_pixel_sample(const rt_camera_frame *cf, int width, uint32_t seed, uint32_t spp, int x, int y,
                              uint32_t s, rt_rng *rng)
{
    uint64_t pixel = (uint64_t)y * (uint64_t)width + (uint64_t)x;
    if (cf->sampler == RT_SAMPLER_SOBOL) {
        *rng = rt_rng_for_sample(seed, pixel, s);
        rt_vec2 j = rt_v2(0.5f, 0.5f), lens = rt_v2(0.5f, 0.5f);
        if (rt_sampler_block_usable() && (spp > 1 || cf->lens_radius > 0.0f)) {
            /* film and lens are consecutive dimensions: one block (in lanes) for both */
            float bx[RT_SAMPLER_BLOCK], by[RT_SAMPLER_BLOCK];
            rt_sampler_block(RT_SAMPLER_SOBOL, rng->key, s, spp, RT_SAMPLER_DIM_FILM, bx, by);
            if (spp > 1)
                j = rt_v2(bx[0], by[0]);
            if (cf->lens_radius > 0.0f)
                lens = rt_v2(bx[RT_SAMPLER_DIM_LENS - RT_SAMPLER_DIM_FILM], by[RT_SAMPLER_DIM_LENS - RT_SAMPLER_DIM_FILM]);
        } else {
            if (spp > 1)
                j = rt_sampler_2d(RT_SAMPLER_SOBOL, rng->key, s, spp, RT_SAMPLER_DIM_FILM);
            if (cf->lens_radius > 0.0f)
                lens = rt_sampler_2d(RT_SAMPLER_SOBOL, rng->key, s, spp, RT_SAMPLER_DIM_LENS);
        }
        return rt_camera_ray(cf, (float)x + j.x, (float)y + j.y, lens);
    }
    uint32_t pattern = (uint32_t)rt_mix64(pixel ^ ((uint64_t)seed << 40));
    rt_vec2 j = spp > 1 ? rt_cmj_sample(s, spp, pattern) : rt_v2(0.5f, 0.5f);
    /* a pinhole camera reads no lens point: skip its pattern (half the CMJ work) */
    rt_vec2 lens = cf->lens_radius > 0.0f ? rt_cmj_sample(s, spp, pattern ^ 0x68bc21ebu) : rt_v2(0.5f, 0.5f);
    *rng = rt_rng_for_sample(seed, pixel, s);
    return rt_camera_ray(cf, (float)x + j.x, (float)y + j.y, lens);
}
