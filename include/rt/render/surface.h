/* rt/render/surface.h - what every integrator needs at a hit: the surface
 * record and the material lookups on it.
 *
 * Plain functions over the scene's tables (no virtual materials):
 *
 *   rt_surface sf;
 *   rt_surface_at(&ctx, &ray, &hit, &sf);          // point, normals, tangent frame, uv, material
 *   rt_surface_at_shading(&ctx, &ray, &hit, &sf);  // the same, the frame only where the material reads it
 *   rt_surface_at_emitter(&ctx, &ray, &hit, &sf);  // what rt_surface_emission reads, no more
 *   // or: the first surface along a ray that its alpha does not cut away
 *   int layers = 32;
 *   float coverage;
 *   if (rt_trace_surface(&ctx, &ray, &layers, NULL, &sf, &coverage) == RT_WALK_SURFACE) ...
 *   rt_vec4 base = rt_surface_base_color(&ctx, &sf);
 *   rt_vec3 Le = rt_surface_emission(&ctx, &sf);
 *   rt_ray next = rt_ray_make(rt_surface_spawn(&ctx, &sf, d), d, 0.0f, INFINITY);
 *
 * Conventions: sf.ng is the unit geometric normal turned to face the
 * incoming ray; sf.n is the shading normal (interpolated, normal-mapped) on
 * the same side; sf.front says whether the ray hit the side the geometric
 * normal (triangle winding, quad cross(u, v), sphere outward) points to.
 */
#ifndef RT_SURFACE_H
#define RT_SURFACE_H

#include "rt/render/trace.h"
#include "rt/render/sampling.h"

typedef struct rt_surface {
    rt_vec3 p;            /* hit point */
    rt_vec3 ng;           /* geometric normal facing the ray */
    rt_vec3 n;            /* shading normal, same side as ng */
    rt_vec3 n_unmapped;   /* the shading normal before the material's normal map (the
                           * interpolated one), same side: a clearcoat's normal when
                           * the coat has no normal map of its own */
    rt_vec3 t, b;         /* shading tangent frame (t, b, n); b = cross(n, t) * sign */
    rt_vec2 uv0, uv1;     /* rt convention: (0,0) top-left of a texture */
    rt_vec4 vertex_color;
    rt_vec3 wo;           /* unit direction back along the ray */
    bool front;
    uint32_t material;
    uint32_t prim;
    bool p_out_set;       /* p_out holds rt_surface_spawn's origin for directions on ng's side */
    rt_vec3 p_out;        /* (rt_surface_at_shading sets it: a shaded hit's bounce and shadow rays mostly leave there) */
} rt_surface;

/* The material of primitive `prim` (an id of the scene's one primitive id
 * space: triangles, spheres, quads). */
static inline uint32_t rt_prim_material(const rt_scene *s, uint32_t prim)
{
    uint32_t i;
    switch (rt_prim_kind_of(s, prim, &i)) {
    case RT_PRIM_TRIANGLE: return s->triangles.material[i];
    case RT_PRIM_SPHERE: return s->spheres.material[i];
    case RT_PRIM_QUAD:
    default: return s->quads.material[i];
    }
}

void rt_surface_at(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf);
/* The same record without the tangent frame (sf->t, sf->b zero) unless the
 * material reads it (RT_MATERIAL_FRAME of rt_material_needs), and without UVs
 * (uv0, uv1 zero) when it has no texture: for the path tracer, whose BSDF
 * builds its own frame about the shading normal, so a hit builds one
 * frame, not two. Every other field is rt_surface_at's, bit for bit. */
void rt_surface_at_shading(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf);
/* Only what rt_surface_emission reads, for a point sampled on an emitter:
 * p, ng, front, wo, material and prim are rt_surface_at's, bit for bit,
 * and uv0, uv1 too when the material has a texture (else zero); n =
 * n_unmapped = ng (no interpolated or mapped normal), t = b = 0,
 * vertex_color (1, 1, 1, 1). */
void rt_surface_at_emitter(const rt_trace_ctx *ctx, const rt_ray *ray, const rt_hit *hit, rt_surface *sf);
/* Base colour (linear RGB, alpha) = factor x texture x vertex colour. */
rt_vec4 rt_surface_base_color(const rt_trace_ctx *ctx, const rt_surface *sf);
/* Emitted radiance towards sf.wo (zero on the back of one-sided emitters). */
rt_vec3 rt_surface_emission(const rt_trace_ctx *ctx, const rt_surface *sf);
/* True when the material's alpha cuts the surface away here (MASK below
 * cutoff); for BLEND, *coverage receives alpha (1 for opaque). */
bool rt_surface_cut_away(const rt_trace_ctx *ctx, const rt_surface *sf, float *coverage);
/* Point to start a secondary ray from, on the side of direction d. */
rt_vec3 rt_surface_spawn(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 d);

/* What rt_trace_surface found along a ray. */
typedef enum rt_surface_walk {
    RT_WALK_SURFACE = 0, /* a surface the alpha keeps */
    RT_WALK_MISS,        /* the ray left the scene (the environment is seen along r->dir) */
    RT_WALK_TOO_DEEP,    /* every layer the budget allowed was cut away */
} rt_surface_walk;

/* The alpha cut-out walk every integrator uses for camera and bounce rays:
 * traces *r and steps past surfaces that rt_surface_cut_away removes
 * (MASK below the cutoff, BLEND at alpha 0) until one is kept; with
 * blend_rng, also steps past a BLEND surface with probability 1 - alpha
 * (stochastic blending). Each trace spends one of *layers_left. For a kept
 * surface, *sf is its record, *coverage its blend alpha (1 when opaque)
 * and r->tmin its distance, so tracing r again continues behind it. */
rt_surface_walk rt_trace_surface(const rt_trace_ctx *ctx, rt_ray *r, int *layers_left, rt_rng *blend_rng,
                                 rt_surface *sf, float *coverage);

#endif
