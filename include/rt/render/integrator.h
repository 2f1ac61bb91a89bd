/* rt/render/integrator.h - the integrator table: every integrator's name,
 * radiance function and what it needs prepared, in one place; and the
 * radiance along a camera ray by the scene's integrator.
 *
 *   rt_integrator id;
 *   if (!rt_integrator_by_name("path", &id)) ...      // the scene's and the CLI's words
 *   const char *name = rt_integrator_name(id);          // "path"
 *   const rt_integrator_info *in = rt_integrator_info_of(id);
 *   rt_render_state_prepare(&rs, &scene, &tree, in->prepare, &err);
 *   rt_vec3 L = in->radiance(&ctx, &ray, &rng);        // or rt_radiance(&ctx, &ray, &rng)
 *
 * The integrators (an id, settings.integrator, is a line of the table):
 * direct   emission + direct light with a Lambertian BRDF (direct.c,
 *          rt/render/direct.h).
 * whitted  Phong, mirrors, refraction with exact Fresnel through nested
 *          media, shadows through glass, diffuse bounces (whitted.c,
 *          rt/render/whitted.h; the model is specified in docs/shading.md).
 * path     physically based path tracing of glTF materials with
 *          next-event estimation and MIS (pathtrace.c, rt/render/pathtrace.h,
 *          docs/path-tracer.md), rendered as a wavefront of paths in
 *          batches (wavefront.c, rt/render/wavefront.h).
 * path_scalar  the same path tracer one path at a time: the reference
 *          the wavefront is tested against (the same bytes).
 *
 * Adding one: a file with its radiance function (and a header declaring
 * it), and one line in the table in integrator.c. Its name then works in
 * scene files, on the command line and in `rt --help`.
 */
#ifndef RT_INTEGRATOR_H
#define RT_INTEGRATOR_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/render/render_state.h" /* RT_PREPARE_*: what an integrator asks to be prepared */
#include "rt/render/sampling.h"
#include "rt/render/surface.h"

/* Radiance arriving along a camera ray. Called from every worker thread at
 * once: it may only read the context's state and write through its rng. */
typedef rt_vec3 (*rt_radiance_fn)(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

typedef struct rt_integrator_info {
    const char *name;        /* the word in scene files (`integrator NAME`) and for --integrator */
    rt_radiance_fn radiance;
    unsigned prepare;        /* RT_PREPARE_* bits (rt/render/render_state.h): what the render state must hold */
    int pass_samples;        /* rt_render's default: samples per pixel a pass; 0 = tile by tile */
    bool wavefront;          /* rt_render traces batches of paths (rt/render/wavefront.h), same radiance */
    bool film_sampler;       /* the camera's film and lens samples come from the `sampler` setting */
    bool diffuse_tree;       /* traces diffuse_rays ^ diffuse_bounces rays a camera sample (a checked limit) */
    bool for_models;         /* the one a bare glTF model or mesh gets (rt_integrator_for_models) */
} rt_integrator_info;

/* Every name in table order, NULL-terminated: the words of the `integrator`
 * setting (rt/render/settings.h) and of --integrator. */
extern const char *const rt_integrator_words[];

/* Number of integrators; ids are 0 .. count - 1. */
size_t rt_integrator_count(void);
/* The table line of id, NULL when there is none. */
const rt_integrator_info *rt_integrator_info_of(rt_integrator id);
/* The integrator a bare model gets (rt_load's for_render): its line says so. */
rt_integrator rt_integrator_for_models(void);
/* Name to id; false for an unknown name. */
bool rt_integrator_by_name(const char *name, rt_integrator *id);
/* Id to name; NULL for an unknown id. */
const char *rt_integrator_name(rt_integrator id);
/* Every name, in table order, into buf (truncated to size): separated by
 * sep, the last two by last_sep ("|", "|" gives "direct|whitted|path";
 * ", ", " or " gives "direct, whitted or path"). */
void rt_integrator_list(char *buf, size_t size, const char *sep, const char *last_sep);

/* Radiance along a camera ray by the scene's integrator (a valid id). */
rt_vec3 rt_radiance(const rt_trace_ctx *ctx, const rt_ray *ray, rt_rng *rng);

#endif
