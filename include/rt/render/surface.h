/* rt/render/surface.h - what every integrator needs at a hit: the surface record,
 * material lookups, light sampling and shadow transmittance.
 *
 * Plain functions over the scene's tables (no virtual materials or lights):
 *
 *   rt_surface sf;
 *   rt_surface_at(&ctx, &ray, &hit, &sf);          // point, normals, uv, material
 *   rt_vec4 base = rt_surface_base_color(&ctx, &sf);
 *   rt_light_sample ls;
 *   if (rt_light_sample_at(&ctx, light, sf.p, u, &ls)) {
 *       rt_vec3 tr = rt_shadow_transmittance(&ctx, &sf, ls.wi, ls.dist);
 *       ...
 *   }
 *
 * Conventions: sf.ng is the unit geometric normal turned to face the
 * incoming ray; sf.n is the shading normal (interpolated, normal-mapped) on
 * the same side; sf.front says whether the ray hit the side the geometric
 * normal (triangle winding, quad cross(u, v), sphere outward) points to.
 */
#ifndef RT_SURFACE_H
#define RT_SURFACE_H

#include <stdatomic.h>

#include "rt/accel/intersect.h"
#include "rt/accel/kdtree.h"
#include "rt/scene/scene.h"

/* What a tracing thread reads: the scene, its tree, and derived constants. */
typedef struct rt_trace_ctx {
    const rt_scene *scene;
    const rt_kdtree *tree;
    float scale;              /* largest absolute scene coordinate: sizes ray offsets */
    bool shadows_need_shading; /* some material is transmissive or alpha-tested */
    rt_vec3 ambient;          /* whitted ambient radiance (settings.ambient_light or the environment's mean) */
    uint64_t *ray_count;      /* per-thread counter of rays traced */
    /* path tracer: the scene's emitter table (rt/path.h), built once before
     * the workers start and shared read-only; NULL (rt_trace_ctx_init's
     * value) = emissive primitives are found by BSDF sampling only */
    const struct rt_light_table *light_table;
} rt_trace_ctx;

void rt_trace_ctx_init(rt_trace_ctx *ctx, const rt_scene *scene, const rt_kdtree *tree);

/* Closest hit, counted. */
bool rt_trace(const rt_trace_ctx *ctx, const rt_ray *ray, rt_hit *hit);

typedef struct rt_surface {
    rt_vec3 p;            /* hit point */
    rt_vec3 ng;           /* geometric normal facing the ray */
    rt_vec3 n;            /* shading normal, same side as ng */
    rt_vec3 t, b;         /* shading tangent frame (t, b, n); b = cross(n, t) * sign */
    rt_vec2 uv0, uv1;     /* rt convention: (0,0) top-left of a texture */
    rt_vec4 vertex_color;
    rt_vec3 wo;           /* unit direction back along the ray */
    bool front;
    uint32_t material;
    uint32_t prim;
} rt_surface;

void rt_surface_at(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf);

/* Base colour (linear RGB, alpha) = factor x texture x vertex colour. */
rt_vec4 rt_surface_base_color(const rt_trace_ctx *ctx, const rt_surface *sf);
/* Emitted radiance towards sf.wo (zero on the back of one-sided emitters). */
rt_vec3 rt_surface_emission(const rt_trace_ctx *ctx, const rt_surface *sf);
/* True when the material's alpha cuts the surface away here (MASK below
 * cutoff); for BLEND, *coverage receives alpha (1 for opaque). */
bool rt_surface_cut_away(const rt_trace_ctx *ctx, const rt_surface *sf, float *coverage);
/* Point to start a secondary ray from, on the side of direction d. */
rt_vec3 rt_surface_spawn(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 d);

typedef struct rt_light_sample {
    rt_vec3 wi;       /* unit direction from the point to the light */
    float dist;       /* distance to the sampled light point, INFINITY for directional */
    rt_vec3 li;       /* incident radiance divided by the sampling pdf (solid angle) */
} rt_light_sample;

/* Samples light l as seen from point p with a 2D sample u. False when the
 * light contributes nothing there (behind a one-sided area light, outside a
 * spot cone). */
bool rt_light_sample_at(const rt_trace_ctx *ctx, const rt_light *l, rt_vec3 p, rt_vec2 u, rt_light_sample *ls);

/* Fraction of light arriving along wi from distance dist: 0 when blocked,
 * 1 when clear, and in between through transmissive or alpha-blended
 * surfaces (coloured by their transmission colour). */
rt_vec3 rt_shadow_transmittance(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist);

/* Radiance arriving from the environment along direction d. */
rt_vec3 rt_environment(const rt_trace_ctx *ctx, rt_vec3 d);

#endif
