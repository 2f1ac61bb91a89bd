/* aov.c - the auxiliary images a denoiser wants (rt/render/aov.h): along
 * the camera ray, step through perfect specular surfaces (mirror
 * reflection, or refraction by Snell's law through smooth glass, total
 * internal reflection falling back to the mirror) to the first surface with
 * a non-delta lobe, and report its albedo and shading normal; depth and
 * position are the first hit's. This follows Intel Open Image Denoise's
 * guidance for its albedo and normal inputs ("for perfect specular
 * surfaces ... the albedo/normal of the next hit"). With participating
 * media (the path integrator), a camera ray whose first event is a
 * collision in a medium reports the medium's single-scattering albedo,
 * a zero normal and the collision's position and distance. */
#include "rt/render/aov.h"

#include <math.h>
#include <string.h>

#include "rt/render/material_eval.h"
#include "rt/render/surface.h"
#include "rt/render/volpath.h"
#include "rt/render/whitted.h"

#define AOV_MAX_SPECULAR 8
/* GGX alpha at or below which a lobe counts as a perfect mirror here */
#define AOV_DELTA_ALPHA (4.0f * RT_BSDF_MIN_ALPHA)

static float clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

void rt_aov_trace(const rt_trace_ctx *ctx, rt_ray ray, rt_rng *rng, rt_aov_sample *out)
{
    memset(out, 0, sizeof *out);
    rt_integrator in = ctx->state->settings->integrator;
    if ((in == RT_INTEGRATOR_PATH || in == RT_INTEGRATOR_PATH_SCALAR) && rt_scene_has_media(ctx->state->scene)) {
        /* a collision in a medium first: its single-scattering albedo, and
         * no normal (OIDN's "no surface here": a point in a medium faces
         * nowhere, and the zero weakens the normal guide in a pixel as much
         * as the medium hides the surfaces behind it) */
        rt_vec3 p;
        if (rt_volpath_aov_event(ctx, &ray, rng, &out->albedo, &p)) {
            out->position = p;
            out->depth = rt_length(rt_sub(p, ray.org));
            return;
        }
    }
    int layers = 16;
    for (int bounce = 0; bounce <= AOV_MAX_SPECULAR; bounce++) {
        rt_surface sf;
        float coverage = 1.0f;
        if (rt_trace_surface(ctx, &ray, &layers, rng, &sf, &coverage) != RT_WALK_SURFACE)
            return;
        if (bounce == 0) {
            out->position = sf.p;
            out->depth = ray.tmin * sqrtf(rt_dot(ray.dir, ray.dir));
        }
        rt_bsdf b;
        rt_bsdf_from_surface(ctx, &sf, &b);
        /* smooth metal or glass of the metallic-roughness model, or the
         * whitted model's mostly-mirror (reflect) and glass (transmission) */
        const rt_material *m = &ctx->state->scene->materials[sf.material];
        bool metal_mirror = (!(b.kind == RT_BSDF_KIND_LAMBERT) && b.alpha <= AOV_DELTA_ALPHA && rt_luminance(b.diffuse) < 1e-4f) ||
                            m->reflectivity >= 0.5f;
        bool glass = (!(b.kind == RT_BSDF_KIND_LAMBERT) && b.alpha <= AOV_DELTA_ALPHA && b.transmission > 0.999f) || m->transmission >= 0.5f;
        if ((!metal_mirror && !glass) || bounce == AOV_MAX_SPECULAR) {
            /* the specular lobe's reflectance at normal incidence: a
             * conductor's Fresnel, else the dielectric F0 mixed towards the
             * base colour by metallic (the glTF model's metal part) */
            rt_vec3 spec = (b.kind == RT_BSDF_KIND_CONDUCTOR) ? rt_fresnel_conductor(1.0f, b.eta_c, b.k_c)
                                       : rt_add(rt_scale(b.base, b.metallic), rt_v3s((1.0f - b.metallic) * b.f0));
            if (b.kind == RT_BSDF_KIND_LAMBERT)
                spec = rt_v3s(0.0f);
            out->albedo = rt_v3(clamp01(b.diffuse.x + spec.x), clamp01(b.diffuse.y + spec.y),
                                clamp01(b.diffuse.z + spec.z));
            /* an emitter: its colour (the emission over its largest
             * component), so the denoiser keeps the light's edge */
            rt_vec3 e = rt_surface_emission(ctx, &sf);
            float emax = fmaxf(e.x, fmaxf(e.y, e.z));
            if (emax > 0.0f)
                out->albedo = rt_scale(e, 1.0f / emax);
            out->normal = sf.n;
            return;
        }
        rt_vec3 d = rt_normalize(ray.dir), next;
        float ior = m->ior > 0.0f ? m->ior : 1.5f;
        if (!glass || !rt_refract(d, sf.n, sf.front ? 1.0f : ior, sf.front ? ior : 1.0f, &next))
            next = rt_reflect(d, sf.n);
        next = rt_normalize(next);
        ray.org = rt_surface_spawn(ctx, &sf, next);
        ray.dir = next;
        ray.tmin = 0.0f;
        ray.tmax = INFINITY;
    }
}

/* The pixel's AOVs: means over its `good` samples; the variance of the mean
 * luminance from the sample variance, sum of L^2 - (sum L)^2 / n over n - 1.
 * Reads the accumulated sums only, so it may run after every pass. */
void rt_aov_resolve(rt_aov_buffers *aov, size_t pixel, const rt_aov_sample *s, uint32_t good, float lum_sum,
                      double lum_sq)
{
    float inv = good ? 1.0f / (float)good : 0.0f;
    const rt_vec3 *v3[3] = {&s->albedo, &s->normal, &s->position};
    float *dst3[3] = {aov->albedo, aov->normal, aov->position};
    for (int k = 0; k < 3; k++)
        if (dst3[k]) {
            dst3[k][3 * pixel] = v3[k]->x * inv;
            dst3[k][3 * pixel + 1] = v3[k]->y * inv;
            dst3[k][3 * pixel + 2] = v3[k]->z * inv;
        }
    if (aov->depth)
        aov->depth[pixel] = s->depth * inv;
    if (aov->spp)
        aov->spp[pixel] = (float)good;
    if (aov->variance) {
        double n = (double)good, var = 0.0;
        if (good > 1)
            var = (lum_sq - (double)lum_sum * (double)lum_sum / n) / (n - 1.0) / n;
        aov->variance[pixel] = (float)(var > 0.0 ? var : 0.0);
    }
}
